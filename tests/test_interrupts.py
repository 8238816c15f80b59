"""Ctrl-C and SIGTERM end a job at any moment, numba's compilation included.

A workflow job is started with an empty numba cache, so that its first kernel compiles, and
interrupted while it compiles: inside a finaliser (as when the signal lands in one of llvmlite's
``__del__`` methods, which run all the time during compilation: there Python ignores the exception
and the job used to run on to its end), and outside one. Interrupts while the job steps are tested
with the kill/resume tests (tests/test_fem_kill.py).
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from conftest import FEM_REFERENCE_CASE
from stickslip.formats.fem_run import read_run_attrs
from stickslip.termination import interrupts_raised
from stickslip.workflow_api import partial_path

#: A workflow job (tests/test_fem_kill.py) with a listener on numba's first compilation: it says
#: "compiling" on stdout and, for the moment "finaliser", drops an object whose __del__ says
#: "finalising" and then runs for 2 s within the compilation.
JOB = textwrap.dedent("""
    import json, os, sys, time
    from numba.core import event

    class Finaliser:
        def __del__(self):
            os.write(1, b"finalising\\n")
            end = time.monotonic() + 2.0
            while time.monotonic() < end:
                pass

    class FirstCompilation(event.Listener):
        started = False

        def on_start(self, ev):
            if not FirstCompilation.started:
                FirstCompilation.started = True
                os.write(1, b"compiling\\n")
                if sys.argv[2] == "finaliser":
                    Finaliser()

        def on_end(self, ev):
            pass

    event.register("numba:compile", FirstCompilation())
    from stickslip.workflow_api import run_simulation
    output = sys.argv[1]
    run_simulation("fem", sys.argv[3], output, output + ".json", output + ".log", inputs={}, threads=1)
""")


@pytest.mark.slow
@pytest.mark.parametrize("moment, signum, line", [("finaliser", signal.SIGINT, "finalising"),
                                                  ("finaliser", signal.SIGTERM, "finalising"),
                                                  ("compilation", signal.SIGINT, "compiling")])
def test_an_interrupt_during_compilation_ends_the_job_promptly(tmp_path, moment, signum, line):
    output = tmp_path / "sim" / "fem" / "run.h5"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache"), "NUMBA_NUM_THREADS": "1"}
    job = subprocess.Popen([sys.executable, "-c", JOB, str(output), moment, json.dumps(FEM_REFERENCE_CASE)],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        while (said := job.stdout.readline().strip()) != line:
            assert said, f"the job ended before '{line}': {job.communicate()[1][-2000:]}"
        job.send_signal(signum)
        sent = time.monotonic()
        _, err = job.communicate(timeout=60)  # the whole compilation takes 30-100 s: it must not run on
    finally:
        job.kill()
    assert time.monotonic() - sent < 20, "the job went on after the interrupt"
    assert job.returncode != 0, err[-2000:]  # a failed job (Snakemake deletes its outputs)
    log = output.with_suffix(".h5.log").read_text()
    assert log.rstrip().endswith("KeyboardInterrupt" if signum == signal.SIGINT else "terminated by SIGTERM"), log
    assert "Exception ignored" not in log + err
    assert not output.exists() and not output.with_suffix(".h5.json").exists()  # nothing where Snakemake looks
    partial = partial_path(output)
    assert not partial.exists() or not read_run_attrs(partial)["completed"]  # resumed by the rerun


def test_a_signal_that_finds_a_finaliser_running_is_raised_after_it(tmp_path):
    events = []

    class Finaliser:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGINT)  # arrives while __del__ runs
            events.append("finaliser ran to its end")

    with pytest.raises(KeyboardInterrupt), interrupts_raised():
        Finaliser()
        events.append("after the finaliser")
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            pass
    assert events == ["finaliser ran to its end", "after the finaliser"]
    assert time.monotonic() < deadline  # raised at once, not after the loop
