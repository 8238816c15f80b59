"""Progress of long work: log lines at an interval, a live bar on a terminal, the fem loop's counts."""

import fcntl
import io
import os
import pty
import re
import struct
import subprocess
import sys
import termios

import h5py
import pytest

from stickslip import progress, registry
from stickslip.events.extraction import classify_increments
from stickslip.formats.fem_run import read_increments
from stickslip.plugin_params import parse_params

from conftest import python_path

FEM = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "drive": "fixed-lever", "nchunk": 200,
       "relaxation": "exact"}


def test_a_log_gets_whole_lines_with_count_total_rate_and_time_left(monkeypatch):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "1e-9")
    stream = io.StringIO()
    with progress.bar(4, desc="work", unit="step", stream=stream) as bar:
        for done in range(4):
            bar.set_postfix_str(f"found {done}", refresh=False)
            bar.update(1)
    text = stream.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert lines[0].startswith("work: 0/4 step (0%)")
    assert re.match(r"work: 4/4 step \(100%\) \[00:00 elapsed, 00:00 left, +[0-9.]+ step/s, found 3\]$", lines[-1])
    assert [int(re.match(r"work: (\d)/4", line)[1]) for line in lines[1:]] == [1, 2, 3, 4, 4]


def test_a_log_gets_no_line_within_the_interval_but_always_the_last(monkeypatch):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "3600")
    stream = io.StringIO()
    assert list(progress.iterate(range(1000), desc="runs", unit="run", stream=stream)) == list(range(1000))
    assert stream.getvalue().splitlines() == [
        line for line in stream.getvalue().splitlines() if line.startswith(("runs: 0/1000", "runs: 1000/1000"))]
    assert len(stream.getvalue().splitlines()) == 2


def test_an_unknown_total_shows_count_and_rate_without_time_left(monkeypatch):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "1e-9")
    stream = io.StringIO()
    with progress.bar(None, desc="work", unit="step", stream=stream) as bar:
        bar.update(7)
    assert re.match(r"work: 7 step \[00:00 elapsed, +[0-9.]+ step/s\]$", stream.getvalue().splitlines()[-1])
    assert "left" not in stream.getvalue()


@pytest.mark.parametrize("value", ["0", "-3", "often"])
def test_a_bad_interval_names_the_variable(monkeypatch, value):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, value)
    with pytest.raises(ValueError, match=f"{progress.INTERVAL_VARIABLE}: expected a number of seconds > 0, got '{value}'"):
        progress.log_interval()


def test_a_terminal_gets_a_live_bar_redrawn_in_place():
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    stream = Terminal()
    with progress.bar(3, desc="work", unit="step", stream=stream) as bar:
        bar.update(3)
    assert "\r" in stream.getvalue() and "3/3" in stream.getvalue() and "|" in stream.getvalue()
    assert " step/s" in stream.getvalue()
    stream = Terminal()
    with progress.bar(desc="work", unit="increment", stream=stream) as bar:  # no total: count and unit apart
        bar.update(149)
    assert "149 increment" in stream.getvalue() and "149increment" not in stream.getvalue()


def test_a_notebook_cell_gets_a_live_bar_as_a_terminal_does():
    # a Jupyter kernel's output stream (ipykernel.iostream.OutStream) is no TTY; the bar is live there too
    Cell = type("OutStream", (io.StringIO,), {"__module__": "ipykernel.iostream"})
    stream = Cell()
    with progress.bar(3, desc="work", unit="step", stream=stream) as bar:
        bar.update(3)
    assert "\r" in stream.getvalue() and "3/3" in stream.getvalue() and "|" in stream.getvalue()
    assert "elapsed" not in stream.getvalue()  # not the log's lines

def _fem(output, **values):
    plugin = registry.get("solver", "fem")
    plugin.run(parse_params(plugin.params, {**FEM, **values}), output, threads=1, inputs={})


def _slip_events(output):
    return int(classify_increments(read_increments(output), FEM["N"])["kind"].isin(["single", "multi"]).sum())


def test_fem_loop_reports_increments_and_the_slip_events_of_the_event_extraction(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "3600")
    output = tmp_path / "run.h5"
    _fem(output, max_increments=120)
    total = _slip_events(output)
    assert re.match(rf"fem increments: 0/120 increment \(0%\) .*, slips 0\]$", capsys.readouterr().err.splitlines()[0])
    # as if killed after increment 60: the run resumes there, and the count goes on from what the file holds
    with h5py.File(output, "r+") as file:
        file.attrs["nstored"] = 61
        file.attrs["completed"] = False
    stored = _slip_events(output)
    assert 0 < stored < total
    _fem(output, max_increments=120)
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("fem increments:")]
    assert re.match(rf"fem increments: 60/120 increment \(50%\) .*, slips {stored}\]$", lines[0])
    assert re.match(rf"fem increments: 120/120 increment \(100%\) .*, slips {total}\]$", lines[-1])
    assert _slip_events(output) == total


def test_simulate_shows_a_bar_on_a_terminal(tmp_path):
    """``stickslip simulate`` with its stderr on a pseudo-terminal: tqdm's bar, redrawn with carriage returns."""
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # 24 rows, 100 columns
    env = {**os.environ, "PYTHONPATH": python_path()}
    result = subprocess.run([sys.executable, "-m", "stickslip", "simulate", "--solver", "lever", "--param",
                             "duration=600", "-o", str(tmp_path / "lab.h5")],
                            stderr=follower, stdout=subprocess.PIPE, env=env, timeout=300, check=False)
    os.close(follower)
    shown = b""
    while True:
        try:
            chunk = os.read(leader, 65536)
        except OSError:
            break
        if not chunk:
            break
        shown += chunk
    os.close(leader)
    assert result.returncode == 0
    assert b"\r" in shown and re.search(rb"virtual experiment: 100%\|#*\| 600/600", shown.replace(b"\xe2\x96\x88", b"#"))


def test_an_early_error_prints_the_progress_line_once(tmp_path, capsys):
    from stickslip.cli import main

    assert main(["analyze-experiment", str(tmp_path / "absent.h5"), "-o", str(tmp_path / "slips.csv")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == ["analyze-experiment: 0/1 run (0%) [00:00 elapsed, ? left, ? run/s]",
                   f"stickslip: error: {tmp_path / 'absent.h5'}: no such file"]
