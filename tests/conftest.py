"""Shared fixtures: the toy plugin distribution (entry points) and a workflow copy; test groups for pytest-xdist."""

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from stickslip import registry
from stickslip.formats.fem_run import read_increments
from stickslip.h5io import FileFormatError
from stickslip.lineage import Artifact
from stickslip.study_plan import Study

REPO = Path(__file__).resolve().parent.parent
TOY = Path(__file__).resolve().parent / "toy_plugin" / "stickslip_toy.py"
TWIN = Path(__file__).resolve().parent / "toy_plugin" / "stickslip_femtwin.py"

ENTRY_POINTS = """[stickslip.solvers]
toy = stickslip_toy
fem-twin = stickslip_femtwin

[stickslip.analyses]
toy = stickslip_toy

[stickslip.figures]
toy = stickslip_toy
"""


@pytest.fixture(scope="session")
def toy_distribution(tmp_path_factory):
    """A directory holding the toy plugin modules and their installed-distribution metadata.

    Put it on ``sys.path`` (or ``PYTHONPATH``) and the entry points make
    ``stickslip`` find the ``toy-*`` plugins, as for a ``pip install``-ed package.
    """
    root = tmp_path_factory.mktemp("site")
    shutil.copy(TOY, root / TOY.name)
    shutil.copy(TWIN, root / TWIN.name)
    info = root / "stickslip_toy-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: stickslip-toy\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(ENTRY_POINTS)
    return root


@pytest.fixture
def toy_plugins(toy_distribution, monkeypatch):
    """Make the toy plugins discoverable in this process (the registry rescans entry points)."""
    monkeypatch.syspath_prepend(str(toy_distribution))
    monkeypatch.setattr(registry, "_loaded", False)
    return toy_distribution


@pytest.fixture(scope="module")
def numba_cuda():
    """numba-cuda is installed: else skip, or fail where ``STICKSLIP_REQUIRE_CUDA_TOOLS`` is set (as .ci/run does)."""
    if importlib.util.find_spec("numba_cuda") is None:
        reason = "numba-cuda is not installed (pip install -e '.[gpu]' in a clone)"
        if os.environ.get("STICKSLIP_REQUIRE_CUDA_TOOLS"):
            pytest.fail(reason)
        pytest.skip(reason)


@pytest.fixture(autouse=True)
def numba_threads_variable():
    """Restore ``NUMBA_NUM_THREADS`` after every test.

    The workflow's job functions set it for their process (``workflow_api.prepare_environment``); in
    the test process a changed value makes numba's next compilation fail ("Cannot set
    NUMBA_NUM_THREADS to a different value once the threads have been launched"), in whichever test
    of the same process (pytest-xdist worker) compiles next.
    """
    saved = os.environ.get("NUMBA_NUM_THREADS")
    yield
    if saved is None:
        os.environ.pop("NUMBA_NUM_THREADS", None)
    else:
        os.environ["NUMBA_NUM_THREADS"] = saved


#: Test modules that share a costly session fixture, by the fixture: pytest-xdist runs each set in one worker.
SHARED = {"ci_study": ("test_workflow_smoke", "test_slurm", "test_docs_queries", "test_tutorial", "test_study_api",
                       "test_browse", "test_api_frictions"),
          "fem_reference_run": ("test_fem_reference", "test_fem_kill")}


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """CI's two workers (``pytest -n 2``, .ci/run): each test module runs in one worker, so its module fixtures
    are made once, and the modules of one :data:`SHARED` set run in one worker, so its session fixture is too.

    (pytest-xdist's own ``--dist loadgroup`` groups nothing under pytest 9: it renames node ids through an
    attribute pytest 9 no longer reads.)
    """
    from xdist.scheduler import LoadScopeScheduling

    groups = {module: fixture for fixture, modules in SHARED.items() for module in modules}

    class ModuleGroups(LoadScopeScheduling):
        def _split_scope(self, nodeid):
            module = nodeid.split("::", 1)[0]
            return groups.get(Path(module).stem, module)

    return ModuleGroups(config, log)


def pytest_collection_modifyitems(items):
    """Fail the run if a module uses a fixture of :data:`SHARED` without being listed with it."""
    for item in items:
        for fixture, modules in SHARED.items():
            if fixture in item.fixturenames and item.module.__name__ not in modules:
                raise pytest.UsageError(f"{item.module.__name__} uses the session fixture {fixture}: add it to "
                                        f"tests/conftest.py SHARED[{fixture!r}]")


def copy_workflow(destination):
    """Copy the workflow (Snakefile, workflow/, profiles/) into ``destination``; return it."""
    destination = Path(destination)
    shutil.copy(REPO / "Snakefile", destination / "Snakefile")
    shutil.copytree(REPO / "workflow", destination / "workflow",
                    ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(REPO / "profiles", destination / "profiles")
    return destination


def python_path(*extra):
    """A PYTHONPATH with ``extra`` directories first."""
    return ":".join([*map(str, extra), *sys.path[1:]])


@pytest.fixture
def toy_results(tmp_path, toy_plugins, monkeypatch):
    """Run the toy study (2 simulations, their analyses, 1 figure) through the workflow's job functions.

    Returns
    -------
    list[pathlib.Path]
        The provenance records, relative to the working directory ``tmp_path``.
    """
    from stickslip.plugin_params import parse_params
    from stickslip.workflow_api import run_analysis, run_figure, run_simulation

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NUMBA_NUM_THREADS", "1")
    records, events = [], []
    solver, analysis = registry.get("solver", "toy-spring-block"), registry.get("analysis", "toy-slips")
    for seed in (1, 2):
        values = {"seed": seed, "slips": 4}
        run = registry.run_id(solver, parse_params(solver.params, values))
        sim = Artifact(f"results/default/sim/toy-spring-block/{run}.h5", run, solver.name, solver.produces)
        run_simulation("toy-spring-block", json.dumps(values), sim.path, sim.path.with_suffix(".provenance.json"),
                       f"results/default/logs/{run}.log", inputs={}, threads=1)
        event = Artifact(f"results/default/events/toy-slips/toy-spring-block/{run}.h5",
                         registry.derived_run_id(analysis, analysis.params(), [run]), analysis.name,
                         analysis.produces, sim)
        run_analysis("toy-slips", "{}", Study.dumps(sim), event.path, event.path.with_suffix(".provenance.json"),
                     f"results/default/logs/e{run}.log")
        events.append(event)
        records += [sim.path.with_suffix(".provenance.json"), event.path.with_suffix(".provenance.json")]
    run_figure("toy-force", "{}", Study.dumps({"analysis:toy-slips": events}), "results/default/figures/toy-force.pdf",
               "results/default/figures/toy-force.provenance.json", "results/default/logs/figure.log")
    records.append(Path("results/default/figures/toy-force.provenance.json"))
    return records


#: The fem solver's reference case, the paper code's regression run (shared/reference/FixedLever_historic.h5):
#: 350 increments.
FEM_REFERENCE_CASE = {"N": 9, "plates": 2, "seed": 0, "k_drive": 1e-3, "drive": "fixed-lever", "nchunk": 200,
                      "yield_strains": "stop"}


@pytest.fixture(scope="session")
def fem_reference_run(tmp_path_factory):
    """:data:`FEM_REFERENCE_CASE` run once, uninterrupted, in this process; returns its file (read it only).

    Shared by tests/test_fem_reference.py and tests/test_fem_kill.py, which compare their own runs of the
    case with it byte for byte.
    """
    from stickslip.plugin_params import parse_params

    path = tmp_path_factory.mktemp("fem-reference") / "run.h5"
    plugin = registry.get("solver", "fem")
    plugin.run(parse_params(plugin.params, FEM_REFERENCE_CASE), path, threads=1, inputs={})
    return path


@pytest.fixture(scope="session")
def ci_study():
    """The real ci study (workflow/config/ci.yaml) run once with `snakemake --cores 2`; returns its directory.

    Shared by the smoke test and the SLURM test (which compares its own run with this one).
    """
    from test_workflow import snakemake

    directory = copy_workflow(Path(tempfile.mkdtemp(prefix="stickslip-ci-study-")))
    snakemake(directory, "--cores", "2", "--configfile", "workflow/config/ci.yaml")
    yield directory
    shutil.rmtree(directory, ignore_errors=True)


@pytest.fixture
def drawn_figures(monkeypatch):
    """The matplotlib figures that a figure plugin saves during the test, in order (read their plotted data).

    A plugin closes its figure after saving it (:func:`stickslip.figures.style.save_figure`); the
    closed figure keeps its axes, lines and texts.
    """
    from matplotlib.figure import Figure

    drawn, savefig = [], Figure.savefig

    def recording_savefig(figure, *args, **kwargs):
        if not any(figure is seen for seen in drawn):
            drawn.append(figure)
        return savefig(figure, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", recording_savefig)
    return drawn


def kill_when_stored(command, watched, increments, signum, timeout=600):
    """Start ``command``, wait until ``watched`` holds ``increments`` increments, send ``signum``.

    Returns
    -------
    (int, str, int)
        Exit status, standard error, increments stored when the signal was sent.
    """
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True, env={**os.environ, "NUMBA_NUM_THREADS": "1"})
    deadline = time.monotonic() + timeout
    stored = 0
    while time.monotonic() < deadline and process.poll() is None:
        try:
            stored = len(read_increments(watched))  # the running file is readable (SWMR)
        except FileFormatError:
            stored = 0  # not created yet
        if stored >= increments:
            break
        time.sleep(0.05)
    assert process.poll() is None, f"the run ended before {increments} increments: {process.stderr.read()}"
    if stored < increments:
        process.kill()
        process.communicate()
        pytest.fail(f"{increments} increments not stored within {timeout} s (stored {stored})")
    process.send_signal(signum)
    _, err = process.communicate(timeout=120)
    return process.returncode, err, stored


def time_to_stop(process, signum, within, what):
    """Send ``signum`` to ``process`` and return the seconds it took to end; fail if it runs ``within`` s more."""
    process.send_signal(signum)
    start = time.monotonic()
    try:
        process.wait(timeout=within)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        pytest.fail(f"{what} went on for {within} s after signal {signum}")
    return time.monotonic() - start
