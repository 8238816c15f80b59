"""Thermal parameters at the edges of what the method represents: refused or warned, with the regime's limit.

The audit: ``temperature=1e-320`` ended in a ZeroDivisionError traceback, ``temperature=1e6`` and
``drive_rate=1e300`` ran without a word, ``hold_delay`` without ``hold_times`` made a new run id
with the same increments, a list parameter written as in YAML was refused without a hint, and a
resume with other parameters did not name each of them.
"""

import subprocess
import sys
import warnings

import pytest

from stickslip.cli import main
from stickslip.fem.parameters import REACH_REGIME, FemParams, thermal_reach
from stickslip.plugin_params import ParameterError, ParameterWarning, parse_params

THERMAL = {"temperature": "1e-3", "drive_rate": "2e-8", "yield_strains": "extend"}


def _params(**changes):
    return parse_params(FemParams, {**THERMAL, **changes})


@pytest.mark.parametrize("changes, message", [
    ({"temperature": "1e-320"}, "parameter 'temperature': 9.99989e-321 reaches a barrier of "),
    ({"temperature": "1e6"}, "parameter 'temperature': 1e+06 reaches a barrier of "),
    ({"drive_rate": "1e300"}, "parameter 'drive_rate': 1e+300 eps0/time drives a stick-slip cycle"),
    ({"drive_rate": "1e-320"}, "parameter 'drive_rate': 9.99989e-321 eps0/time drives a stick-slip cycle"),
    ({"hold_delay": "0.1"}, "parameter 'hold_delay': 0.1 is used only with hold_times"),
])
def test_thermal_parameters_outside_the_method_are_refused_naming_the_limit(changes, message):
    with pytest.raises(ParameterError) as refused:
        _params(**changes)
    text = str(refused.value)
    assert text.startswith(message) and "\n" not in text, text
    if "hold_delay" not in changes:
        assert "Limits of the regime" in text and "expected" in text


def test_the_limits_are_the_thermal_reach_and_the_studies_stay_inside():
    # T ln(nu t_cycle), t_cycle = 0.2 eps0 / drive_rate: the thermal study's points are in the regime
    assert thermal_reach(1e-3, 1.0, 2e-8) == pytest.approx(1e-3 * 16.118, rel=1e-4)
    for drive_rate in ("2e-11", "2e-8", "2e-5"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            _params(drive_rate=drive_rate)
    with pytest.warns(ParameterWarning, match=f"beyond the regime T ln\\(nu t_cycle\\) <= {REACH_REGIME:g}"):
        _params(temperature="3e-3")  # the docs: flips take over at 3e-3 and 2e-8
    _params(hold_times="1e3,1e6", hold_delay="0.1")  # a delay with holds is fine


def test_list_parameters_take_the_yaml_form_and_a_wrong_one_shows_the_syntax(capsys):
    assert _params(hold_times="[1e3, 1e6]").hold_times == (1e3, 1e6)
    with pytest.raises(ParameterError, match=r"\(a list: comma-separated, e.g. hold_times=1e3,1e6 or "):
        _params(hold_times="1e3;1e6")


def test_the_cli_prints_the_regime_warning_as_one_line(tmp_path):
    args = [sys.executable, "-m", "stickslip", "simulate", "--solver", "fem", "-o", str(tmp_path / "run.h5"), "--param", "N=9", "--param",
            "temperature=3e-3", "--param", "drive_rate=2e-8", "--param", "yield_strains=extend", "--param",
            "max_increments=1", "--param", "relaxation=exact"]
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    lines = [line for line in done.stderr.splitlines() if "warning" in line]
    assert len(lines) == 1 and lines[0].startswith("stickslip: warning: parameters 'temperature', 'drive_rate': ")


def test_a_resume_with_other_parameters_names_every_one(tmp_path, capsys):
    output = tmp_path / "run.h5"
    base = ["simulate", "--solver", "fem", "-o", str(output), "--param", "N=9", "--param", "yield_strains=extend",
            "--param", "max_increments=1", "--param", "relaxation=exact"]
    assert main(base + ["--param", "temperature=1e-3", "--param", "drive_rate=2e-8", "--param", "hold_times=1e3",
                        "--param", "attempt_rate=2", "--param", "hold_delay=0.1"]) == 0
    capsys.readouterr()
    assert main(base + ["--param", "temperature=1.5e-3", "--param", "drive_rate=2e-7"]) == 2
    error = capsys.readouterr().err
    for name in ("temperature = 0.001 (this run: 0.0015)", "drive_rate = 2e-08 (this run: 2e-07)",
                 "attempt_rate = 2.0 (this run: 1.0)", "hold_times = [1000.0] (this run: [])",
                 "hold_delay = 0.1 (this run: 0.0)"):
        assert name in error, error
