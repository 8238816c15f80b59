"""Benchmark of the package's HDF5 output: the cost of fletcher32 checksums and of the write guard.

Usage::

    python benchmarks/bench_output.py --repeat 5

Three workloads, each with and without the ``fletcher32`` checksum (:func:`stickslip.h5io.write_dataset`):

- ``timeseries``: a lever recording (the default lever run, 6000 s: 300001 force samples and
  30001 frames of 5 slabs, gzip) written through :func:`stickslip.output_safety.atomic.atomic_output`, then read back.
- ``fem-append``: 400 increments of the paper's ``N = 1458``, 2 plates (``u``: 23 334 doubles a
  row, chunk one row) appended and flushed one at a time, as :func:`stickslip.formats.fem_run.append_increment` does.
- ``fem-copy``: those rows copied by :func:`stickslip.h5io.copy_file` (the rewrite on resume and
  completion), through the write guard (the package's writer of new files) and through HDF5's
  own file driver (``sec2``, what new files were written with before).

Prints the median wall time of each and, last, the ratios ``with/without checksums`` and
``guard/sec2``. Load on the machine distorts the times, not much the ratios.
"""

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from stickslip import h5io
from stickslip.output_safety.atomic import atomic_output


def timed(function, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def timeseries(directory, checksum):
    rng = np.random.default_rng(0)
    series = {"t_F": np.arange(300001) * 0.02, "F": rng.normal(size=300001),
              "t_x": np.arange(30001) * 0.2, "x": rng.normal(size=(30001, 5))}
    path = directory / "lab.h5"

    def run():
        with atomic_output(path) as tmp, h5io.open_file(tmp, "w") as file:
            for name, values in series.items():
                h5io.write_dataset(file, name, values, compression="gzip", compression_opts=4, shuffle=True,
                                   fletcher32=checksum)
        with h5io.open_file(path) as file:
            for name in series:
                h5io.read_array(file[name])

    return run


def fem_append(directory, checksum, rows=400, ndof=23334):
    path = directory / "run.h5"
    row = np.random.default_rng(1).normal(size=ndof)

    def run():
        with h5io.open_file(path, "w") as file:
            h5io.write_dataset(file, "u", np.zeros((0, ndof)), maxshape=(None, ndof), chunks=(1, ndof),
                               fletcher32=checksum)
        with h5io.open_file(path, "r+") as file:
            file.swmr_mode = True
            u = file["u"]
            for i in range(rows):
                u.resize(i + 1, axis=0)
                u[i] = row
                file.flush()

    return run


def fem_copy(directory, guard):
    source = directory / "run.h5"
    target = directory / "copy.h5"

    def run():
        with h5io.open_file(source) as src:
            if guard:
                out = h5io.open_file(target, "w")
            else:
                out = h5py.File(target, "w", libver=h5io.LIBVER, track_order=False)
            with out:
                h5io.copy_file(src, out, rows=src["u"].shape[0])

    return run


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    results = {}
    with tempfile.TemporaryDirectory() as name:
        directory = Path(name)
        for checksum in (True, False):
            results["timeseries", checksum] = timed(timeseries(directory, checksum), args.repeat)
            results["fem-append", checksum] = timed(fem_append(directory, checksum), args.repeat)
        for guard in (True, False):  # copies the file of the last fem-append (no checksums)
            results["fem-copy", guard] = timed(fem_copy(directory, guard), args.repeat)
    for (workload, flag), seconds in results.items():
        label = ("checksums" if flag else "no checksums") if workload != "fem-copy" else ("guard" if flag else "sec2")
        print(f"{workload:11s} {label:13s} {seconds * 1e3:9.1f} ms")
    print(" ".join(f"{w}_checksum_ratio={results[w, True] / results[w, False]:.3f}"
                   for w in ("timeseries", "fem-append"))
          + f" copy_guard_ratio={results['fem-copy', True] / results['fem-copy', False]:.3f}")


if __name__ == "__main__":
    main()
