"""Output-file safety: nothing already stored is lost, nothing half-written is left where a result belongs.

Every writer of the package goes through these modules (import them from the module, the package
itself exports nothing):

- :mod:`.atomic`: :func:`~.atomic.atomic_output` (write under a temporary name, rename on success;
  temporaries of killed writers removed) and :func:`~.atomic.check_output` (fail before a long
  computation if the output cannot be written);
- :mod:`.space`: :func:`~.space.check_free_space` for a writer that appends in place;
- :mod:`.lock`: :func:`~.lock.writer_lock`, one writer per file;
- :mod:`.torn_chunk`: :func:`~.torn_chunk.committed_rows`, the rows of a chunk whose in-place
  rewrite a killed appender tore, kept where the chunk's old checksum proves them;
- :mod:`.write_guard`: the file object through which HDF5 writes a new file, so that a full disk is
  an error (:class:`~.errors.OutputError`), never a crash;
- :mod:`.errors`: :class:`~.errors.OutputError`.

HDF5 reading and writing itself (reproducible bytes, tables, checksums) is :mod:`stickslip.h5io`.
"""
