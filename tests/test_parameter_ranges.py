"""Every numeric parameter of every solver has a physical range; a hostile value is one line (exit 2) or a finite run.

The audit of 575c37a (issue 59, items 5, 9, 10): ``--param eps_offset=0`` ("a well is narrower than the kick"),
``k_drive``, ``G``, ``K``, ``weibull_k``, ``eps_offset`` at 1e+-300 ("no step along the linear response makes a
block yield") ended in SolverError tracebacks, ``eps0 = 1e-300`` in a ZeroDivisionError, ``window``, ``niter_tol``
and ``N`` had no upper bound (MemoryError tracebacks: 65.5 TiB asked; ``N = 1e12`` after 37 s at 1.7 GB), and
``nchunk = 1e12`` was accepted and ran with no output.

:func:`test_every_parameter_of_every_solver_walks_to_one_line_or_a_finite_run` sets every parameter of every
solver, one at a time, to NaN, +-inf, 0, a negative number, +-1e300, 1e-300 and values of the wrong type, over
parameters that keep the runs short, and runs ``stickslip simulate``: it must refuse with one line (exit 2) or
write a file whose numbers are all finite.
"""

import dataclasses
import json
import typing

import numpy as np
import pytest

from stickslip import registry
from stickslip.cli import main
from stickslip.errors import SolverError
from stickslip.fem.memory import run_memory
from stickslip.fem.parameters import FemParams
from stickslip.h5io import open_file, read_array
from stickslip.machine_memory import process_memory, size_text
from stickslip.plugin_params import ParameterError, describe, params_to_dict, parse_params, value_range

SOLVERS = ("fem", "lever", "rate-state-lever")

#: Parameters over which each solver's walk runs: a small fem stack with few wells and increments, a short record.
BASE = {"fem": {"N": "9", "plates": "2", "nchunk": "60", "yield_strains": "stop", "max_increments": "3",
                "max_iter": "200000"},
        "lever": {"duration": "20"},
        "rate-state-lever": {"duration": "20"}}

#: The values every parameter is set to (as on the command line).
HOSTILE = ("nan", "inf", "-inf", "0", "-1", "1e300", "-1e300", "1e-300", "1.5", "abc", "[1, 2]", "true", "")

#: Parameters whose upper bound is a condition with other parameters (:meth:`FemParams.check`: the thermal reach,
#: the clock's resolution), not a number of their own.
CROSS_CHECKED = {"temperature", "attempt_rate", "drive_rate", "hold_times", "junction_attempt_rate"}

#: Parameters whose range the interface law declares (each law checks its own: ``check_parameters``).
LAW_DECLARED = {"law_params"}


def _fields(solver):
    return dataclasses.fields(registry.get("solver", solver).params)


def _numeric(field):
    return field.type in (int, float, tuple[int, ...], tuple[float, ...])


def test_every_numeric_parameter_has_a_documented_range():
    for solver in SOLVERS:
        for field in filter(_numeric, _fields(solver)):
            if field.name in LAW_DECLARED:
                continue
            meta = field.metadata
            below = meta["minimum"] is not None or meta["exclusive_minimum"] is not None
            above = meta["maximum"] is not None or field.name in CROSS_CHECKED
            assert below and above, f"{solver}: {field.name} ({value_range(meta)!r})"
    rows = {row[0]: row for row in describe(FemParams)}
    assert rows["dt_scale"][4].endswith("(range: >= 0.001, <= 8)")  # what `stickslip plugins --params` shows


def _finite_output(solver, path):
    """Whether every number the run wrote is finite (the fem increments; the time series' signals)."""
    with open_file(path) as file:
        if solver == "fem":
            group = file["increments"]
            values = [read_array(group[name]) for name in json.loads(file["increments"].attrs["columns"])]
        else:
            values = [read_array(file[name]) for name in ("t_F", "F", "t_x", "x")]
    return all(np.all(np.isfinite(np.asarray(v, dtype=float))) for v in values)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """``run(solver, values) -> (exit status, stderr lines that are not progress)``, each distinct run made once."""
    made = {}
    root = tmp_path_factory.mktemp("walk")

    def run(solver, values, capsys):
        try:
            key = (solver, json.dumps(params_to_dict(parse_params(registry.get("solver", solver).params, values))))
        except ParameterError:
            key = (solver, json.dumps(values, sort_keys=True))
        if key not in made:
            output = root / f"run{len(made)}.h5"
            args = [item for name, value in values.items() for item in ("--param", f"{name}={value}")]
            capsys.readouterr()
            status = main(["simulate", "--solver", solver, *args, "-o", str(output)])
            lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("stickslip: error")
                     or not line.startswith(("stickslip:", "fem increments:", "virtual experiment:", "fem "))]
            finite = status == 0 and _finite_output(solver, output)
            made[key] = (status, lines, finite)
        return made[key]

    return run


@pytest.mark.slow
@pytest.mark.parametrize("solver, name", [(solver, field.name) for solver in SOLVERS for field in _fields(solver)])
def test_every_parameter_of_every_solver_walks_to_one_line_or_a_finite_run(runs, solver, name, capsys):
    for value in HOSTILE:
        status, lines, finite = runs(solver, {**BASE[solver], name: value}, capsys)
        case = f"--param {name}={value!r}: exit {status}, {lines}"
        if status == 2:
            assert len(lines) == 1 and lines[0].startswith("stickslip: error: "), case
        else:
            assert status == 0 and not lines and finite, case


@pytest.mark.parametrize("value", [None, [], {}, {"a": 1}, object(), b"1", 1j, True])
def test_values_of_the_wrong_python_type_are_one_line(value):
    for solver in SOLVERS:
        cls = registry.get("solver", solver).params
        for field in _fields(solver):
            if field.type is bool or (field.type is str and isinstance(value, str)):
                continue
            try:
                parse_params(cls, {**BASE[solver], field.name: value})
            except ParameterError as error:
                assert "\n" not in str(error) and f"'{field.name}'" in str(error), (solver, field.name, error)
            else:
                assert typing.get_origin(field.type) is tuple and value in ([], {}), (solver, field.name, value)


def test_the_audits_parameters_are_one_line(capsys, tmp_path):
    small = ["--param", "N=9", "--param", "max_increments=2"]
    for values in (["eps_offset=0"], ["k_drive=1e300"], ["k_drive=1e-300"], ["G=1e300"], ["K=1e-300"],
                   ["weibull_k=1e300"], ["eps_offset=1e300"], ["eps0=1e-300"], ["window=1e30"],
                   ["niter_tol=1000000000"], ["N=1000000000000"], ["nchunk=1000000000000"]):
        status = main(["simulate", "--solver", "fem", *small, *(f"--param={v}" for v in values),
                       "-o", str(tmp_path / "run.h5")])
        error = capsys.readouterr().err.strip().splitlines()
        assert status == 2 and len(error) == 1 and error[0].startswith("stickslip: error: parameter"), (values, error)
    assert not (tmp_path / "run.h5").exists()


def test_a_run_that_needs_more_memory_than_the_machine_has_is_refused_with_the_estimate(capsys, tmp_path):
    values = {"N": "100000", "plates": "6", "window": "1000000"}
    needed = sum(run_memory(parse_params(FemParams, values)).values())
    assert needed > process_memory()  # 500 000 blocks of a million wells: 3.6 TiB of yield strains
    status = main(["simulate", "--solver", "fem", *(f"--param={k}={v}" for k, v in values.items()),
                   "-o", str(tmp_path / "run.h5")])
    error = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(error) == 1 and f"the run needs at least {size_text(needed)} of memory" in error[0]
    assert "(yield strains: 3.64 TiB)" in error[0], error
    status = main(["simulate", "--solver", "lever", "--param", "duration=1e9", "-o", str(tmp_path / "lab.h5")])
    error = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(error) == 1 and "the recording needs at least" in error[0], error


def test_a_solver_that_cannot_go_on_is_a_user_error_of_the_cli(monkeypatch, capsys, tmp_path):
    from stickslip.solvers import lever

    def stuck(params):
        raise SolverError("rate-and-state integration failed at t = 1 s: step size underflow of RODAS4")

    monkeypatch.setattr(lever, "simulate", stuck)
    status = main(["simulate", "--solver", "lever", "-o", str(tmp_path / "lab.h5")])
    error = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and error == [f"stickslip: error: {tmp_path / 'lab.h5'}: solver 'lever' cannot make this run: "
                                     "rate-and-state integration failed at t = 1 s: step size underflow of RODAS4"]
