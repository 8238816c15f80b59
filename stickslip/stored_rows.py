"""Which rows of an HDF5 dataset its file stores: a chunk that was never written is damage, not zeros.

HDF5 reads a chunk that was never written (never allocated in the file) as the dataset's fill value, and a
dataset's shape is one number in its header: a file whose growable datasets were resized beyond what was
written reads as rows of zeros. :func:`first_unstored_row` asks the file's chunk index (or, for a contiguous
dataset, its storage) which of the selected rows the file holds, without reading any of them, so that a
reader refuses such rows instead of returning them (:func:`stickslip.h5io.read_array`).

Rows inside a chunk that was written are stored: a chunk holds whole rows, written when its first row was
(later rows of a chunk being appended to are the fill value until they are written, which the writer's own
count of rows, ``nstored`` of :mod:`stickslip.formats.fem_run`, says).
"""

import itertools
import math

import h5py
import numpy as np

__all__ = ["first_unstored_row", "data_elsewhere"]

#: Chunks looked up one by one in the chunk index (each a few tens of microseconds); more are counted by one
#: pass over the index.
_PROBES = 8


def data_elsewhere(dataset):
    """Why the data of ``dataset`` are not in its file (a virtual dataset, external raw files), or "" if they are.

    Parameters
    ----------
    dataset : h5py.Dataset

    Returns
    -------
    str
    """
    plist = dataset.id.get_create_plist()
    if plist.get_layout() == h5py.h5d.VIRTUAL:
        return "is a virtual dataset (its data would be read from other files)"
    if plist.get_external_count():
        return "stores its data in external files"
    return ""


def first_unstored_row(dataset, start=0, stop=None):
    """The first row of ``dataset[start:stop]`` whose data its file does not store, or None if it stores them all.

    Parameters
    ----------
    dataset : h5py.Dataset
    start, stop : int, optional
        Rows along the first axis (default: all of them).

    Returns
    -------
    int or None
        A row ``start <= row < stop`` in a chunk that was never written (chunked layout), or ``start`` for a
        contiguous dataset whose storage was never allocated; None if every selected row is stored (and for a
        scalar, an empty selection or a compact dataset).

    Notes
    -----
    Cost: up to :data:`_PROBES` lookups in the chunk index; beyond, counting the written chunks (one pass over
    the index) and, only where not every chunk of the dataset was written, listing them (about 4 us a chunk).
    """
    shape = dataset.shape
    stop = shape[0] if stop is None and shape else stop
    if not shape or stop <= start or dataset.size == 0:
        return None
    layout = dataset.id.get_create_plist().get_layout()
    if layout == h5py.h5d.CONTIGUOUS:
        return start if dataset.id.get_storage_size() == 0 else None
    if layout != h5py.h5d.CHUNKED:
        return None
    rows, chunks = dataset.chunks[0], dataset.chunks
    across = [range(0, n, c) for n, c in zip(shape[1:], chunks[1:])]  # chunk origins along the other axes
    per_row = math.prod(len(origins) for origins in across)
    first, last = start // rows, (stop - 1) // rows
    needed = (last - first + 1) * per_row
    if needed <= _PROBES:
        for index in range(first, last + 1):
            for origin in itertools.product(*across):
                if dataset.id.get_chunk_info_by_coord((index * rows, *origin)).byte_offset is None:
                    return max(start, index * rows)
        return None
    written = dataset.id.get_num_chunks()
    if written == math.ceil(shape[0] / rows) * per_row:
        return None
    return _first_gap(dataset, first, last, per_row, start)


def _first_gap(dataset, first, last, per_row, start):
    """The first row of chunk rows ``first ... last`` whose chunks are not all written, or None (from the index)."""
    rows = dataset.chunks[0]
    found = []
    dataset.id.chunk_iter(lambda info: found.append(info.chunk_offset[0] // rows))
    index = np.asarray(found, dtype=np.int64)
    index, counts = np.unique(index[(index >= first) & (index <= last)], return_counts=True)
    complete = index[counts == per_row]
    expected = np.arange(first, first + complete.size)
    gaps = np.flatnonzero(complete != expected)
    if complete.size == last - first + 1:
        return None
    missing = int(expected[gaps[0]]) if gaps.size else first + complete.size
    return max(start, missing * rows)
