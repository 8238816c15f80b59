"""The count of Gauss points whose well changed since a checkpoint, a kernel apart from the host code that launches it.

numba's CUDA simulator replaces the ``cuda`` of a kernel's module while the kernel runs: a kernel beside host code
that calls ``cuda`` (:mod:`.state`'s device copies, from another run's thread) would break it there.
"""

from numba import cuda

__all__ = ["count_changed", "COUNT_THREADS"]

#: Threads per block of :func:`count_changed`.
COUNT_THREADS = 128


@cuda.jit
def count_changed(now, then, shift, elements, count):
    """``count[0]`` += the Gauss points of ``elements`` whose well ``now[e, q] + shift[e]`` is not ``then[e, q]``.

    ``now``, ``then`` int64 [ni, 4] wells; ``shift`` int64 [ni]; ``elements`` int64 [k]; one thread per Gauss point
    (integer atomics: the count does not depend on the order).
    """
    i = cuda.grid(1)
    if i < elements.size * 4:
        e = elements[i // 4]
        q = i % 4
        if now[e, q] + shift[e] != then[e, q]:
            cuda.atomic.add(count, 0, 1)
