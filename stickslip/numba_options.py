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

numba's on-disk cache has four defects, worked around here on import:

- Entries for types of other programs: a kernel compiled for a type defined outside the
  package (a law registered by a user's module or notebook) is cached beside the package's own
  entries, and numba unpickles a function's whole index on every load: a process that cannot
  import that module then fails with ``ModuleNotFoundError`` in any kernel of that function.
  :func:`tolerate_foreign_entries` reads such an index as empty (a cache miss: the kernel is
  compiled and the index rewritten with this process's entries).
- Stale callees: numba keys a cached kernel by its own source file only, so a kernel
  that calls (and inlines) code of another module, e.g. an interface law
  (:mod:`stickslip.fem.laws`) or a backend's plate operator, would keep running the old
  code after that module changed. :func:`key_cache_on_subpackage` keys every kernel of
  the package on all the sources of its subpackage (``stickslip/fem/**`` for the fem
  kernels) and on this module.

and two that hit Snakemake jobs sharing one cache directory:

- Concurrent writers: each process reads a function's index, picks the first free
  data-file number and writes both, so two processes compiling different
  signatures can pair one signature's index entry with the other's machine code.
  :func:`serialise_cache_writes` makes each index update and its data file one
  critical section under an exclusive lock.
- A cached caller of a ``parallel=True`` kernel can lose the hook that starts the
  threading layer (numba issues #8578 and #9938): a caller compiled in a process
  that loaded the parallel kernel from the cache is cached without it, and a later
  process whose first kernel is that caller calls the threading layer's
  unresolved symbols (address 0) and dies with SIGSEGV. This crashed the
  ``front-dynamics`` jobs of fresh default studies (their first kernel is
  ``compute_force``). :func:`start_threading_layer` starts the threading layer
  before any kernel is loaded.
"""

import fcntl
import functools
import hashlib
import os
from pathlib import Path

import numba
from numba.core import caching

CACHE = os.environ.get("STICKSLIP_NUMBA_CACHE", "1") != "0"

NJIT_OPTIONS = {"cache": CACHE, "nogil": True, "fastmath": False, "error_model": "numpy"}


def cache_lock_path(cache_file):
    """The lock file of one function's on-disk cache (beside its index ``*.nbi``)."""
    return cache_file._index_path + ".lock"


def serialise_cache_writes():
    """Make numba's cache writes (index and data file of one entry) exclusive across processes.

    Wraps ``numba.core.caching.IndexDataCacheFile.save`` (numba pinned in environment.txt) in
    an ``fcntl.flock`` on :func:`cache_lock_path`: the index is re-read, extended and
    written, and the data file written, while no other process can do the same for that
    function. Idempotent.
    """
    save = caching.IndexDataCacheFile.save
    if getattr(save, "serialised", False):
        return

    def locked_save(self, key, data):
        os.makedirs(self._cache_path, exist_ok=True)
        with open(cache_lock_path(self), "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                save(self, key, data)
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    locked_save.serialised = True
    caching.IndexDataCacheFile.save = locked_save


def tolerate_foreign_entries():
    """Read a cache index that names a type this process cannot import as empty (a cache miss).

    Wraps ``numba.core.caching.IndexDataCacheFile._load_index`` (numba pinned in environment.txt):
    unpickling an entry whose type lives in a module this process cannot import (or that no longer
    defines it) raises ``ImportError`` or ``AttributeError``; the index is then treated as absent.
    Idempotent.
    """
    load = caching.IndexDataCacheFile._load_index
    if getattr(load, "tolerant", False):
        return

    def tolerant_load(self):
        try:
            return load(self)
        except (ImportError, AttributeError):
            return {}

    tolerant_load.tolerant = True
    caching.IndexDataCacheFile._load_index = tolerant_load


def start_threading_layer():
    """Start numba's threading layer, so that the symbols of parallel kernels resolve on a cache load.

    Must run before the first cached kernel is loaded (here: on import of this module,
    which every kernel module imports to get :func:`njit`). ``NUMBA_NUM_THREADS`` must be
    set before, as :func:`stickslip.workflow_api.prepare_environment` does. Idempotent.

    Returns
    -------
    int
        The number of threads numba uses.
    """
    return numba.get_num_threads()  # launches the threading layer on the first call


#: The package's directory: kernels defined below it are keyed on their subpackage's sources.
PACKAGE_DIR = Path(__file__).resolve().parent


@functools.lru_cache(maxsize=None)
def _sources_digest(directory, stamps):
    digest = hashlib.sha256()
    for path, _ in stamps:
        digest.update(os.path.relpath(path, directory).encode())
        digest.update(Path(path).read_bytes())
    return digest.hexdigest()


def subpackage_digest(path, package_dir=PACKAGE_DIR):
    """sha256 of the sources a kernel defined in ``path`` may depend on (hex).

    The sources are every ``*.py`` below the top-level subpackage of the package that holds
    ``path`` (``stickslip/fem/`` for ``stickslip/fem/laws/cusp.py``; the file's own directory
    if it lies directly in the package) and this module. Memoised on the files' modification
    times and sizes, so an edit while the process runs is seen.

    Parameters
    ----------
    path : str or pathlib.Path
        A source file below ``package_dir``.
    package_dir : pathlib.Path, optional
        The package's directory (default :data:`PACKAGE_DIR`).

    Returns
    -------
    str
    """
    package_dir = Path(package_dir).resolve()
    relative = Path(path).resolve().relative_to(package_dir)
    directory = package_dir / relative.parts[0] if len(relative.parts) > 1 else package_dir
    files = sorted(set(directory.rglob("*.py")) | {Path(__file__).resolve()})
    stamps = tuple((str(f), (f.stat().st_mtime_ns, f.stat().st_size)) for f in files)
    return _sources_digest(str(directory), stamps)


def key_cache_on_subpackage():
    """Key the cached kernels of the package on their subpackage's sources (:func:`subpackage_digest`).

    Wraps ``get_source_stamp`` of numba's file-backed cache locators (numba pinned in
    environment.txt): for a kernel defined below :data:`PACKAGE_DIR` the stamp becomes the
    pair (numba's own stamp of its file, the subpackage's digest), so any change of a module it
    may inline recompiles it. Kernels of other packages keep numba's stamp. Idempotent.
    """
    mixin = caching._SourceFileBackedLocatorMixin
    stamp = mixin.get_source_stamp
    if getattr(stamp, "keyed_on_subpackage", False):
        return

    def keyed_stamp(self):
        own = stamp(self)
        path = Path(self._py_file).resolve()
        if PACKAGE_DIR not in path.parents:
            return own
        return own, subpackage_digest(path)

    keyed_stamp.keyed_on_subpackage = True
    mixin.get_source_stamp = keyed_stamp


key_cache_on_subpackage()
tolerate_foreign_entries()
serialise_cache_writes()
start_threading_layer()


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
