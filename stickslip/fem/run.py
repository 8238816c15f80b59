"""The increment loop of the event-driven protocol, appending to the simulation file, with resume.

Increment 0 is the unloaded state. Then, alternately: an elastic load step to
the brink of yielding (odd increments), and a kick followed by minimisation
(even increments). If a kick's minimisation ends with no well index changed
(the kicked point fell back), the previous increment is restored and the kick
redone so that a whole element yields (``yield_element``). The run stops, and
is marked completed, when a block comes within ``margin`` wells of the end of
its yield strains (during a minimisation, or after a load step), or after
``max_increments`` increments; with unbounded yield strains and ``max_increments``
0, when an increment leaves a block within ``margin`` wells of the end of its
first ``nchunk`` wells (where the paper's code stops; that increment is not
stored). Every increment is appended and committed; a run
ended in any way (exception, SIGINT, SIGTERM, SIGKILL) resumes from its last
committed increment and gives the same file, byte for byte, as an uninterrupted
run. Progress (increments, slip events so far, increments/s, time left when
``max_increments`` bounds the run) goes to stderr through :mod:`stickslip.progress`.
Reference: shared/reference-model.md, section 8c.
"""

import json
import sys
from pathlib import Path

import numpy as np

from .. import progress
from ..formats.fem_run import RunFile, append_increment, check_arithmetic, create_file, rewrite
from ..h5io import FileFormatError, UnreadableFileError, open_file, read_table
from ..output_safety.atomic import atomic_output
from ..output_safety.lock import writer_lock
from ..output_safety.overwrite import changed_values, set_aside
from ..output_safety.space import check_free_space
from ..plugin_params import params_to_dict
from .backends import backend_arithmetic
from .observables import Observer, observable_columns
from .parameters import stored_params
from .simulation import Simulation
from .stiffness import driving_regime, stiffness_ratio

__all__ = ["simulate_to_file"]

#: Free space kept beyond one increment's chunks [B]: HDF5 crashes if a write for lack of space
#: fails in the file appended to, so the loop stops cleanly (OutputError) before the disk is full.
FREE_SPACE_MARGIN = 4 * 2**20


def _row(observer, increment, previous_index, columns):
    row = {"increment": increment, **columns}
    row.update(observer.observe(previous_index))
    return row


class _Progress:
    """Progress of the increment loop: increments stored and slip events so far.

    A slip event is an increment in which every one of the ``N`` blocks of some interface
    changed well (``A_a == N``, :mod:`stickslip.events.extraction`).
    """

    def __init__(self, file, params, increment):
        self.N = params.N
        self.slips = self._slips(file, 0)
        self.bar = progress.bar(params.max_increments or None, desc="fem increments", unit="increment",
                                initial=increment, postfix=f"slips {self.slips}")

    def _slips(self, file, first):
        table = file["increments"]
        A = [table[name][first:] for name in json.loads(table.attrs["columns"]) if name.startswith("A_a")]
        return int(np.count_nonzero(np.any(np.asarray(A) == self.N, axis=0)))

    def stored(self, file, increment):
        """Count increment ``increment``, just appended to ``file``."""
        self.slips += self._slips(file, increment)
        self.bar.set_postfix_str(f"slips {self.slips}", refresh=False)
        self.bar.update(1)


def _header(simulation, observer, producer):
    """Root attributes of the run file: the fields of :data:`stickslip.formats.fem_run.HEADER`, then ``fem``'s own
    (the protocol's last)."""
    p, c = simulation.params, simulation.constants
    phi = stiffness_ratio(p.k_drive, p.N, p.G)
    return {"solver": producer[0], "solver_version": producer[1], "params": params_to_dict(p),
            "N": p.N, "plates": p.plates, "n_interfaces": p.plates - 1, "k_drive": p.k_drive, "drive": p.drive,
            "seed": p.seed, "nchunk": p.nchunk, "eps0": p.eps0, "sig0": c["sig0"], "gamma0": observer.gamma0,
            "c_s": c["c_s"], "h": c["h"], "dt": c["dt"], "alpha": c["alpha"], "H": c["H"],
            "phi": phi, "regime": driving_regime(phi), **simulation.protocol.header}


def _create(path, params, mesh, backend, producer):
    simulation = Simulation(params, mesh, backend)
    observer = Observer(simulation)
    protocol = simulation.protocol
    columns = observable_columns(observer.nlayer, observer.n_interfaces, simulation.model.free_lever)
    with atomic_output(path) as tmp:
        with open_file(tmp, "w") as file:
            create_file(file, _header(simulation, observer, producer), mesh, simulation.loading.response,
                        columns + list(protocol.columns), protocol.columns, protocol.state_fields,
                        arithmetic=backend_arithmetic(backend.name))
            append_increment(file, simulation.stack.stored(),
                             _row(observer, 0, observer.well_index(),
                                  {"kick": True, "yield_element": False, **protocol.initial_row()}))


def _stored(output, params):
    """Whether ``output`` holds a completed run; an unreadable file is moved aside (with a message).

    Returns
    -------
    bool or None
        ``completed`` of the stored run, None if there is none (any more).
    """
    if not output.exists():
        return None
    try:
        with open_file(output) as file:
            stored = stored_params(file)
            completed = bool(file.attrs["completed"])
    except UnreadableFileError as error:
        aside = set_aside(output, "unreadable")
        print(f"stickslip: {error}; moved it to {aside}, starting the run over", file=sys.stderr)
        return None
    if params_to_dict(stored) != params_to_dict(params):
        raise FileFormatError(f"{output}: exists with other parameters: "
                              f"{changed_values(params_to_dict(stored), params_to_dict(params))}; remove it or use "
                              f"another output")
    return completed


def simulate_to_file(params, output, mesh, backend, *, producer):
    """Run (or resume, or skip if completed) one simulation into ``output``.

    While the run is going, ``output`` is appended in SWMR mode (readable meanwhile,
    e.g. by ``stickslip increments``), one committed increment at a time. However
    the run ends (an exception, SIGINT, SIGTERM, SIGKILL), the next call rewrites
    the file from its committed increments (:func:`stickslip.formats.fem_run.rewrite`) and resumes;
    a file that HDF5 cannot open is moved aside with a message and the run starts
    over. A disk that fills up ends the run before an increment is written
    (:data:`FREE_SPACE_MARGIN`); it resumes when rerun with space. A finished run is rewritten once more, so that the file has the same bytes
    however often the run was interrupted.

    Parameters
    ----------
    params : FemParams
    output : str or pathlib.Path
        Simulation file; created if absent, resumed if present and incomplete.
    mesh : stickslip.mesh.LayeredMesh
        Used when the file is created (a resumed file uses its own stored mesh).
    backend
        How the numbers are computed (:func:`.backends.make_backend`); must be the backend that
        ``params.backend`` names (a backend of other round-off must not write under another's run id).
    producer : tuple[str, str]
        Name and version of the solver plugin, recorded in the file.

    Returns
    -------
    int
        Number of increments stored by this call.

    Raises
    ------
    FileFormatError
        If ``output`` exists with other parameters, is not a simulation file, or
        another process is writing it.
    OutputError
        If the disk is (nearly) full, or ``output`` cannot be written.
    """
    output = Path(output)
    if backend.name != params.backend:
        raise ValueError(f"backend {backend.name!r} given for a run whose parameter 'backend' is {params.backend!r}")
    with writer_lock(output):
        completed = _stored(output, params)
        if completed:
            return 0
        if completed is None:
            _create(output, params, mesh, backend, producer)
        else:
            rewrite(output, **check_arithmetic(output, backend_arithmetic(backend.name)))
        new, reason = _increments(params, output, backend)
        rewrite(output, completed=True, stop_reason=reason)
        return new


def _increments(params, output, backend):
    """Append increments to ``output`` until the run stops; return (number appended, stop reason)."""
    with open_file(output, "r+") as file:
        file.swmr_mode = True
        run = RunFile(file)
        simulation = Simulation(params, run.mesh, backend, response=run.linear_response(),
                                table=read_table(file, "increments", rows=run.nstored))
        stack, protocol = simulation.stack, simulation.protocol
        increment = run.nstored - 1
        stack.restore(run.state(increment))
        observer = Observer(simulation)
        previous_index = observer.well_index()
        new = 0
        reason = ""
        report = _Progress(file, params, increment)
        needed = 2 * run.increment_bytes() + FREE_SPACE_MARGIN
        last_well = params.nchunk + 1 - params.margin if stack.extend and not params.max_increments else None
        while not reason:
            if params.max_increments and increment >= params.max_increments:
                reason = "max_increments"
                break
            increment += 1
            columns = protocol.step(params.margin, increment)
            if columns is None:
                reason = "margin"
                break
            if last_well is not None and stack.well_index().max() >= last_well:
                reason = "margin"
                break
            check_free_space(output, needed, FREE_SPACE_MARGIN)
            row = _row(observer, increment, previous_index, columns)
            append_increment(file, stack.stored(), row)
            protocol.stored(row)
            previous_index = observer.well_index()
            new += 1
            report.stored(file, increment)
        report.bar.close()
        return new, reason
