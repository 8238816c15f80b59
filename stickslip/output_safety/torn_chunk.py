"""The committed rows of a chunk whose rewrite a killed writer tore, recovered only where its old checksum proves them.

A file appended one row at a time (:func:`stickslip.formats.fem_run.append_increment`) rewrites the
last chunk of each growable dataset in place at every append. A process killed (SIGKILL) inside
that write can leave the chunk torn: Linux checks for a fatal signal between the pages of a write
to the page cache, so the chunk keeps the new bytes up to a page boundary and the old ones after
it, the old fletcher32 checksum at its end included. HDF5 then refuses the whole chunk, although
the rows committed before that append are the same in the old bytes and the new.

:func:`committed_rows` takes the chunk's bytes as they lie, rebuilds the chunk as it stood before
the append (the committed rows, then the dataset's fill value) and accepts the committed rows only
if HDF5's own fletcher32 of that chunk is the checksum the chunk ends with. Damage of any other
kind (a flipped bit among the committed rows, a chunk no append touched) fails that test, so it
is still refused.
"""

import io

import h5py
import numpy as np

__all__ = ["committed_rows"]

#: Bytes of the fletcher32 checksum that ends a chunk.
_CHECKSUM_BYTES = 4


def committed_rows(dataset, first_row, committed):
    """The rows ``first_row ... min(committed, chunk end) - 1`` of a torn chunk, or None where that is unproven.

    Parameters
    ----------
    dataset : h5py.Dataset
        A growable dataset (unlimited first axis) whose chunks span its other axes whole, with the
        fletcher32 filter and no other.
    first_row : int
        The first row of the chunk (a multiple of ``dataset.chunks[0]``).
    committed : int
        Rows of the dataset committed before the append that was torn; the chunk held them and the
        fill value after them before that append.

    Returns
    -------
    numpy.ndarray or None
        Shape ``(min(committed, first_row + chunks[0]) - first_row, *dataset.shape[1:])``, dtype of
        the dataset; None if the chunk is not such a torn chunk (its bytes with the fill value after
        the committed rows do not give the checksum they end with) or the dataset is not of that kind.
    """
    rows = dataset.chunks[0]
    kept = min(committed, first_row + rows) - first_row
    if (kept <= 0 or first_row % rows or dataset.maxshape[0] is not None
            or tuple(dataset.chunks[1:]) != tuple(dataset.shape[1:])
            or not dataset.fletcher32 or dataset.compression or dataset.shuffle or dataset.scaleoffset is not None):
        return None
    mask, stored = dataset.id.read_direct_chunk((first_row,) + (0,) * (dataset.ndim - 1))
    data_bytes = int(np.prod(dataset.chunks)) * dataset.dtype.itemsize
    if mask or len(stored) != data_bytes + _CHECKSUM_BYTES:
        return None
    before = np.frombuffer(stored[:data_bytes], dtype=dataset.dtype).reshape(dataset.chunks).copy()
    before[kept:] = dataset.fillvalue
    if _fletcher32_chunk(before, dataset.fillvalue)[data_bytes:] != stored[data_bytes:]:
        return None
    return before[:kept]


def _fletcher32_chunk(data, fillvalue):
    """The bytes HDF5 stores for ``data`` as one chunk with the fletcher32 filter (data, then checksum)."""
    with h5py.File(io.BytesIO(), "w") as scratch:
        chunk = scratch.create_dataset("chunk", data=data, chunks=data.shape, fletcher32=True, fillvalue=fillvalue)
        return chunk.id.read_direct_chunk((0,) * data.ndim)[1]
