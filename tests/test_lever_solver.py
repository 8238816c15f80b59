"""The ``lever`` solver plugin: file content, determinism, command line, parameter errors, speed."""

import hashlib
import json
import time

import h5py
import numpy as np
import pytest

from stickslip import registry
from stickslip.cli import main
from stickslip.experiment.timeseries import read_timeseries, read_truth
from stickslip.plugin_params import ParameterError, parse_params
from stickslip.experiment.virtual.model import simulate
from stickslip.solvers.lever import LeverParams


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_cli_writes_a_valid_time_series_with_truth(tmp_path):
    output = tmp_path / "RUN.h5"
    assert main(["simulate", "--solver", "lever", "--param", "n=3", "--param", "seed=1",
                 "--param", "duration=1200", "-o", str(output)]) == 0
    record = read_timeseries(output)
    assert (record.n, record.n_slabs, record.protocol, record.a) == (3, 5, "stack", 0)
    assert record.t_x.size == 1200 * 5 + 1 and record.t_F.size == 1200 * 50 + 1
    truth, interfaces = read_truth(output), read_truth(output, "interfaces")
    assert set(truth["a"]) == {1, 2, 3}
    assert list(interfaces["n_slips"]) == [int((truth["a"] == a).sum()) for a in range(1, 6)]
    with h5py.File(output) as f:
        assert json.loads(f.attrs["params"])["n"] == 3 and f.attrs["seed"] == 1


def test_same_seed_same_bytes_other_seed_other_slips(tmp_path):
    plugin = registry.get("solver", "lever")
    for name, seed in (("a.h5", 4), ("b.h5", 4), ("c.h5", 5)):
        params = parse_params(LeverParams, {"n": 2, "seed": seed, "duration": 900})
        plugin.run(params, tmp_path / name, threads=1, inputs={})
    assert digest(tmp_path / "a.h5") == digest(tmp_path / "b.h5")
    assert not read_truth(tmp_path / "a.h5")["t_start"].equals(read_truth(tmp_path / "c.h5")["t_start"])


def test_sensor_noise_does_not_change_the_slips():
    quiet = simulate(parse_params(LeverParams, {"n": 3, "duration": 900, "position_noise": 0, "force_noise": 0}))
    noisy = simulate(parse_params(LeverParams, {"n": 3, "duration": 900}))
    assert quiet[1].equals(noisy[1])
    residual = noisy[0].x - quiet[0].x
    assert residual.std() == pytest.approx(0.002, rel=0.05)
    assert (noisy[0].F - quiet[0].F).std() == pytest.approx(0.01, rel=0.05)


@pytest.mark.parametrize("values, message", [
    ({"n": 6}, "parameter 'n': expected a value <= n_slabs=5"),
    ({"driven_slab": 2}, "parameter 'driven_slab': must be 0 for the stack protocol"),
    ({"protocol": "individual"}, "parameter 'driven_slab': expected 1..n_slabs=5 for the individual protocol"),
    ({"protocol": "individual", "driven_slab": 2, "n": 3}, "parameter 'n': must be 1 for the individual protocol"),
    ({"B": "0.05,0.04"}, "parameter 'B': expected 1 or n_slabs=5 values, got 2"),
    ({"B": "0.001", "n": 5, "strength_offset": 0}, "parameter 'B': the weakest healing during a slip"),
    ({"protocol": "sideways"}, "parameter 'protocol'"),
])
def test_parameter_errors_name_the_field(values, message):
    with pytest.raises(ParameterError, match=message):
        parse_params(LeverParams, values)


def test_cli_reports_bad_parameters_in_one_line(tmp_path, capsys):
    assert main(["simulate", "--solver", "lever", "--param", "n=7", "-o", str(tmp_path / "x.h5")]) == 2
    assert "parameter 'n'" in capsys.readouterr().err


@pytest.mark.slow
def test_a_full_run_takes_well_under_a_second():
    params = parse_params(LeverParams, {"n": 5, "seed": 3})
    simulate(params)
    start = time.process_time()  # CPU time: the wall time of the shared machine depends on the others' load
    record, truth, _ = simulate(params)
    elapsed = time.process_time() - start
    print(f"lever n=5, 6000 s: {elapsed:.3f} CPU s, {len(truth)} slips")
    assert record.t_F[-1] == 6000.0 and len(truth) > 300
    assert elapsed < 1.5  # measured 0.31 CPU s (benchmarks/virtual_cost.py); wall time 1.4 s at load 14
    assert np.all(np.isfinite(record.F))


@pytest.mark.parametrize("threads", ["0", "-1", "two"])
def test_a_thread_count_below_one_is_a_usage_error(threads, tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["simulate", "--solver", "lever", "--threads", threads, "-o", str(tmp_path / "x.h5")])
    assert stop.value.code == 2
    assert f"argument --threads: expected an integer >= 1, got '{threads}'" in capsys.readouterr().err
    assert not (tmp_path / "x.h5").exists()
