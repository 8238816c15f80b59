"""The one place where numba compilation options are set.

Every kernel of the package is compiled with :func:`njit` from this module, so
that tests and benchmarks can change the options in one place.

Environment variables
---------------------
STICKSLIP_NUMBA_CACHE
    ``0`` disables the on-disk cache (default ``1``: compiled kernels are cached
    so that a second process does not recompile).
NUMBA_NUM_THREADS
    Number of threads of the parallel kernels (numba's own variable; the
    Snakemake rules set it from the rule's ``threads``).

Notes
-----
``fastmath`` stays off: reordering floating-point operations would break the
bit-identical reproducibility promised for the same parameters and seed.
"""

import os

import numba

CACHE = os.environ.get("STICKSLIP_NUMBA_CACHE", "1") != "0"

NJIT_OPTIONS = {"cache": CACHE, "nogil": True, "fastmath": False, "error_model": "numpy"}


def njit(*args, parallel=False, **kwargs):
    """Compile a function with the package's numba options.

    Parameters
    ----------
    *args
        Forwarded to :func:`numba.njit` (a function, or a signature).
    parallel : bool, optional
        Compile with ``parallel=True`` (use ``numba.prange`` loops inside).
    **kwargs
        Overrides of :data:`NJIT_OPTIONS`.

    Returns
    -------
    callable
        The compiled dispatcher, or a decorator when called without a function.
    """
    options = {**NJIT_OPTIONS, "parallel": parallel, **kwargs}
    return numba.njit(*args, **options)


def set_num_threads(threads):
    """Set the number of numba threads, bounded by what numba was started with.

    Parameters
    ----------
    threads : int
        Requested number of threads (>= 1).

    Returns
    -------
    int
        The number of threads actually in use.
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    used = min(int(threads), numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(used)
    return used
