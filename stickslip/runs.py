"""Simulation files opened for reading: one object per run with its header, tables and states.

:func:`open_run` picks the reader by the file's format and returns a :class:`FemRun`
(``fem-run``) or a :class:`TimeseriesRun` (``timeseries``: a ``lever`` or ``rate-state-lever``
run, or a lab recording). Each gathers what the package's readers and analyses give for one file,
and nothing else: the tables are those of the format's reader and of the analysis that the
workflow runs on that format (``numerical-events``, ``experiment-events``), computed by the same
functions, so they equal what the workflow writes. Files are opened only for reading, and every
reader checks the format and its version (a file of another one raises
:class:`stickslip.h5io.FileFormatError` naming it).

Every table is named in the package's vocabulary and carries its units in ``attrs["units"]``
(:mod:`stickslip.vocabulary`; the run file's own column names are kept for ``increments``). A run is a context
manager (``with stickslip.open_run(path) as run:``): it holds no file open between calls, and leaving the block
(or :meth:`close`) frees what it read and built (tables, mesh, the replay's model).
"""

import dataclasses
import functools
from pathlib import Path

import numpy as np

from . import formats, registry
from .events.plugin import event_tables
from .experiment.aging import fit_single_slips
from .experiment.analysis import NAME as EXPERIMENT_EVENTS
from .experiment.analysis import ExperimentEventsParams, analyse_record, experimental_slip_events
from .experiment.timeseries import read_timeseries, read_truth
from .formats.fem_run import RunFile, read_increments, read_run_attrs
from .errors import IncrementError
from .h5io import FileFormatError, attribute, open_file
from .output_safety.overwrite import root_attributes
from .plugin_params import parse_params
from .provenance.record import read_record, record_path
from .vocabulary import with_units

__all__ = ["open_run", "FemRun", "RunState", "TimeseriesRun", "READERS"]


class _Run:
    """What every run shares: a context manager that frees what the run read (the file is open only per call)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()
        return False

    def close(self):
        """Free the tables, mesh and models read or built so far; the run reads them again if used."""
        for name in self._cached:
            self.__dict__.pop(name, None)

    @property
    def provenance(self):
        """The provenance record beside the file (``<stem>.provenance.json``; a dict,
        :func:`stickslip.provenance.record.read_record`): what a workflow job or :func:`stickslip.simulate` wrote
        when it made the file (run id, plugin and version, code hash, git commit, every parameter, host, times,
        the output's sha256). None where there is none (a lab recording, a file copied without it).

        Raises
        ------
        stickslip.h5io.FileFormatError
            If the record is there but unreadable.
        """
        record = record_path(self.path)
        return read_record(record) if record.is_file() else None

    @property
    def run_id(self):
        """The run's id (16 hexadecimal characters): its record's, else the id its solver, solver version and
        parameters give (:func:`stickslip.registry.run_id`, as the workflow names its file); None for a lab
        recording or a solver that is not installed at the file's version.

        Raises
        ------
        stickslip.h5io.FileFormatError
            If the stored parameters are not those of any run of the solver (a damaged file, named).
        """
        if self.provenance is not None:
            return self.provenance["run_id"]
        try:
            plugin = registry.get("solver", self.solver) if self.solver else None
        except registry.PluginError:
            return None
        if plugin is None or str(self.header.get("solver_version")) != str(plugin.version):
            return None
        return registry.run_id(plugin, formats.stored_run_params(plugin.params, self.params, self.path, plugin.name))


@dataclasses.dataclass(frozen=True)
class RunState:
    """The state of a ``fem-run`` file at one stored increment (FE units: block size ``h``, modulus ``G``).

    Attributes
    ----------
    increment : int
    t : float
        Time [FE time].
    u : numpy.ndarray
        float64 [ndof]: displacement of every degree of freedom [FE length] (the mesh's ``dofs``).
    displacement : numpy.ndarray
        float64 [nnode, 2]: (x, y) displacement of every node of the mesh [FE length], ``u[mesh.dofs]``.
    target : numpy.ndarray
        float64 [nlayer]: drive target of every layer's mean x-displacement [FE length].
    lever_target : float
        Free lever: the drive target at the lever's drive height [FE length] (a fixed lever's targets are ``target``).
    eps, sig : numpy.ndarray
        float64 [n_interfaces, N, 4, 3]: strain (xx, yy, xy) [1] and stress [FE stress] at the 4 Gauss
        points of every interface block (interface a = 1 first, blocks left to right).
    well : numpy.ndarray
        int64 [n_interfaces, N, 4]: the well each of those Gauss points is in, counted from the start of
        its block's yield-strain sequence.
    further : dict[str, numpy.ndarray]
        The producer's further state of that increment (``fem`` with junction aging: ``junction_depth``
        float64 [n_interfaces * N] in G eps0^2 h^2, ``junction_well`` int64 [n_interfaces * N], -1: no
        junction); empty for a run without it.
    """

    increment: int
    t: float
    u: np.ndarray
    displacement: np.ndarray
    target: np.ndarray
    lever_target: float
    eps: np.ndarray
    sig: np.ndarray
    well: np.ndarray
    further: dict = dataclasses.field(default_factory=dict)


class FemRun(_Run):
    """A ``fem-run`` file (the finite-element model, :mod:`stickslip.formats.fem_run`), read only.

    Parameters
    ----------
    path : str or os.PathLike

    Attributes
    ----------
    path : pathlib.Path
    header : dict
        Every root attribute (:func:`stickslip.formats.fem_run.read_run_attrs`): ``solver``,
        ``solver_version``, ``N`` (blocks per interface), ``plates``, ``n_interfaces``, ``k_drive``
        [G/h^2], ``seed``, the units ``eps0``, ``sig0``, ``gamma0`` [deg], ``c_s`` [FE length / FE time],
        ``h`` [FE length], ``dt`` [FE time], the rigidity ratio ``phi`` and ``regime``, ``nstored``,
        ``completed``, ``stop_reason``, ``version``, ...
    params : dict
        The producer's parameters as stored (``stickslip.params("fem")`` documents them).
    solver : str
        The solver that wrote the file.

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is missing, not HDF5, or not a ``fem-run`` file of the current version.

    Notes
    -----
    Cost: opening reads the header; :attr:`increments` is read on first use; :meth:`state` and
    :meth:`failures` build the run's model once (its yield strains and stiffness, through the solver's
    ``replay``), then cost one restore or one replayed event each.
    """

    format = "fem-run"
    _cached = ("increments", "mesh", "_replay")

    def __init__(self, path):
        self.path = Path(path)
        self.header = read_run_attrs(self.path)
        self.params = self.header["params"]
        self.solver = str(self.header["solver"])

    def __repr__(self):  # the file's name, as h5py's File shows it (the whole path: .path)
        h = self.header
        return (f"<FemRun {self.path.name}: {self.solver} blocks={h['N']} plates={h['plates']} phi={h['phi']:.3g} "
                f"({h['regime']}), {h['nstored']} increments{', completed' if h['completed'] else ''}>")

    def _stored(self, increment):
        """``increment`` as an int, or IncrementError if the file does not store it."""
        stored = int(self.header["nstored"])
        if not 0 <= int(increment) < stored:
            raise IncrementError(f"{self.path}: increment {increment} is not stored (0 ... {stored - 1})")
        return int(increment)

    @functools.cached_property
    def increments(self):
        """The observables, one row per stored increment (pandas.DataFrame; read once).

        Columns (:mod:`stickslip.fem.observables`): ``increment``, ``kick`` (bool: an event, i.e. a kick
        and a minimisation; else an elastic load step), ``yield_element`` (the kick's whole-element
        fallback), ``t`` [FE time], ``gamma`` (lever rotation [gamma0]), ``epsd``, ``sigd`` (equivalent
        strain and stress of the whole stack [eps0], [sig0]), per layer ``l`` (0 the bottom plate, odd
        the interfaces) ``epsd_<l>`` [eps0], ``sigd_<l>`` [sig0], ``ubar_<l>`` (mean x-displacement
        [FE length]), ``fxdrive_<l>`` (spring elongation [FE length]), per interface ``a`` ``S_a<a>``
        (net well hops since the previous increment) and ``A_a<a>`` (blocks that changed well); a free
        lever adds ``lever_target``, ``lever_position`` [FE length]. ``attrs["units"]`` gives every column's unit.
        """
        return with_units(read_increments(self.path))

    @functools.cached_property
    def mesh(self):
        """The run's mesh (:class:`stickslip.mesh.LayeredMesh`: ``coor`` [nnode, 2], ``conn``, ``dofs``, ...)."""
        with open_file(self.path) as file:
            return RunFile(file).mesh

    @functools.cached_property
    def _replay(self):
        """The solver's replay of this file, built on first use (:func:`stickslip.registry.replay`)."""
        return registry.replay(self.solver, self.path)

    def state(self, increment):
        """The stored state of one increment, with the strain, stress and well of every interface block.

        Parameters
        ----------
        increment : int
            A stored increment (0 ... ``header["nstored"] - 1``).

        Returns
        -------
        RunState

        Raises
        ------
        stickslip.errors.IncrementError
            An ``IndexError`` (and a ``FileFormatError``): the increment is not stored.
        stickslip.h5io.FileFormatError
            If the solver that wrote the file cannot replay it.
        """
        increment = self._stored(increment)
        with open_file(self.path) as file:
            u, target, lever_target, t, *further = RunFile(file).state(increment)
        fields = self._replay.interface_state(increment)
        return RunState(increment=int(increment), t=t, u=u, displacement=u[self.mesh.dofs], target=target,
                        lever_target=lever_target, eps=fields["eps"], sig=fields["sig"], well=fields["well"],
                        further=dict(*further))

    def events(self):
        """The tables of the ``numerical-events`` analysis (what the workflow writes for this run).

        Returns
        -------
        dict[str, pandas.DataFrame]
            ``increments`` (classified: ``steady``, ``kind`` single/multi/micro/load, ...), ``slips`` (one row
            per steady-state slip event: ``increment``, ``gamma`` [gamma0], ``s`` slipping interfaces,
            ``interfaces``, ``multi``, ``sigma_before``, ``sigma_after``, ``dsigma`` [sig0]),
            ``slip_interfaces`` (one row per slip and slipping ``interface``: ``dmu_sig0`` [sig0], ...),
            ``sequences``, ``slip_events`` (:meth:`slip_events`) and ``periodicity``
            (:func:`stickslip.events.plugin.event_tables`); each with ``attrs["units"]``.

        Notes
        -----
        Cost: one pass over the increment table, computed at each call.
        """
        tables = event_tables(self.increments, int(self.header["N"]), source=str(self.path))
        return {name: with_units(table) for name, table in tables.items()}

    def slip_events(self):
        """The run's slips as the results database holds them (the ``slip_events`` table of :meth:`events`).

        Returns
        -------
        pandas.DataFrame
            One row per (steady-state slip event, slipping interface): ``event``, ``interface`` (a, 1 =
            lowest), ``multi`` (more than one interface slipped), ``dmu_sig0`` (stress drop of the interface
            [sig0]), ``increment``, ``dgamma`` [gamma0]; ``attrs["units"]``.
        """
        return self.events()["slip_events"]

    def failures(self, increment):
        """Replay one stored event and return every block failure in time order (its rupture front).

        The solver that wrote the file re-runs the event from the stored state before it and checks
        that it reproduces the stored state after it (``fem``: :meth:`stickslip.fem.replay.EventReplay.failures`).

        Parameters
        ----------
        increment : int
            A stored kick increment (``increments["kick"]``).

        Returns
        -------
        pandas.DataFrame
            ``interface`` (a, 1 = lowest), ``block`` (0 ... N-1), ``t`` (time since the kick [FE time]),
            ``hop_direction`` (+1 / -1): one row per well hop; ``attrs["units"]``.

        Raises
        ------
        stickslip.errors.IncrementError
            An ``IndexError`` (and a ``FileFormatError``): the increment is not stored.
        stickslip.h5io.FileFormatError
            If the increment is not a stored kick, or the solver cannot replay events (``fem``: a thermal run).
        """
        failures = self._replay.failures(self._stored(increment))
        return with_units(failures.rename(columns={"a": "interface", "direction": "hop_direction"}))


class TimeseriesRun(_Run):
    """A ``timeseries`` file (a virtual experiment or a lab recording, :mod:`stickslip.experiment.timeseries`), read only.

    Parameters
    ----------
    path : str or os.PathLike

    Attributes
    ----------
    path : pathlib.Path
    record : stickslip.experiment.timeseries.ExperimentRecord
        The lever force ``t_F`` [s], ``F`` [N], the slab positions ``t_x`` [s], ``x`` (n_frames x n_slabs, in
        mm), and the apparatus: ``n``, ``n_slabs``, ``protocol``, ``a`` (the driven slab: the file's attribute),
        ``normal_force`` [N], ``k_spring`` [N/mm], ``h``, ``H`` [mm], ``V`` [mm/s].
    header : dict
        Every root attribute (JSON decoded): the apparatus; a virtual run's ``solver``, ``params``, ``seed``.
    params : dict
        The producer's parameters (empty for lab data).
    solver : str or None
        The solver that wrote the file (None for lab data).

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is missing, not HDF5, not a ``timeseries`` file of the current version, or its content
        fails the format's checks; the message names the file and the item.
    """

    format = "timeseries"
    _cached = ()

    def __init__(self, path):
        self.path = Path(path)
        self.record = read_timeseries(self.path)
        with open_file(self.path) as file:
            names = tuple(file.attrs)
        self.header = root_attributes(self.path, names)
        self.params = self.header.get("params", {})
        self.solver = self.header.get("solver")

    def __repr__(self):
        r = self.record
        return (f"<TimeseriesRun {self.path.name}: {self.solver or 'lab recording'} {r.protocol} n={r.n} "
                f"{r.t_x[-1] - r.t_x[0]:.0f} s>")

    def events(self, **analysis_params):
        """The tables of the ``experiment-events`` analysis (what the workflow writes for this run).

        Parameters
        ----------
        **analysis_params
            Parameters of the slip detection (``stickslip.params("experiment-events", kind="analysis")``),
            checked as ``stickslip analyze-experiment --param`` checks them.

        Returns
        -------
        dict[str, pandas.DataFrame]
            ``slips`` (one row per slip of one interface: ``time`` [s], ``interface``, ``multi``, ``dF`` [N],
            ``dmu``, ``T`` [s], ``slip`` [mm], ``B_a``, ...: :func:`stickslip.experiment.analysis.analyse_record`,
            the CSV of ``analyze-experiment``), ``interfaces`` (``R_tot``, ``dR_sum`` [mm], ``R_slow``, ...) and
            ``slip_events`` (:meth:`slip_events`); each with ``attrs["units"]``.

        Raises
        ------
        stickslip.plugin_params.ParameterError
            A ``ValueError`` naming a bad parameter.
        """
        params = parse_params(ExperimentEventsParams, analysis_params, owner=f"analysis '{EXPERIMENT_EVENTS}'")
        slips, interfaces = analyse_record(self.record, params)
        return {name: with_units(table) for name, table in
                (("slip_events", experimental_slip_events(slips)), ("slips", slips), ("interfaces", interfaces))}

    def slip_events(self, **analysis_params):
        """The run's slips as the results database holds them (``slip_events`` of :meth:`events`).

        Returns
        -------
        pandas.DataFrame
            ``event``, ``interface`` (a), ``multi``, ``slip`` (dR) [mm], ``dmu`` [-], ``time`` [s], then
            ``dF`` [N], ``T`` [s], ``B_a``, ...; ``attrs["units"]``.
        """
        return self.events(**analysis_params)["slip_events"]

    def aging(self, fit="origin", per_interface=False, **analysis_params):
        """The paper's aging fit ``dmu = B ln(T / T0)`` on the single slips (``analyze-experiment --aging``).

        Parameters
        ----------
        fit : {"origin", "intercept"}
            Through the origin (the paper's) or with a free intercept ``c``.
        per_interface : bool
            One fit per interface.
        **analysis_params
            As for :meth:`events` (``t0``: T0 [s]).

        Returns
        -------
        stickslip.experiment.aging.AgingFit or dict[int, AgingFit or ValueError]
            ``B``, ``B_error``, ``c``, ``c_error`` [-], the bins (``T`` [s], ``dmu_mean``, ``dmu_std``,
            ``count``; ``attrs["units"]``) and ``n_slips``; per interface a dict by interface.

        Raises
        ------
        ValueError
            If the single slips fill too few bins of waiting time.
        """
        params = parse_params(ExperimentEventsParams, analysis_params, owner=f"analysis '{EXPERIMENT_EVENTS}'")
        slips, _ = analyse_record(self.record, params)
        fits = fit_single_slips(slips, t0=params.t0, fit=fit, per_interface=per_interface)

        def with_unit_bins(each):
            return dataclasses.replace(each, bins=with_units(each.bins)) if hasattr(each, "bins") else each

        return {a: with_unit_bins(each) for a, each in fits.items()} if per_interface else with_unit_bins(fits)

    def truth(self, table="truth"):
        """The ground truth of a virtual run: ``"truth"`` (one row per slip made) or ``"interfaces"``.

        Returns
        -------
        pandas.DataFrame or None
            The file's table (:mod:`stickslip.solvers.lever`) in the vocabulary's names (``interface``, ``slip``:
            the file's ``a``, ``dR``), with ``attrs["units"]``; None for lab data
            (:func:`stickslip.experiment.timeseries.read_truth`).
        """
        found = read_truth(self.path, table)
        return None if found is None else with_units(found.rename(columns={"a": "interface", "dR": "slip"}))


#: The reader of every simulation format that :func:`open_run` opens.
READERS = {FemRun.format: FemRun, TimeseriesRun.format: TimeseriesRun}


def open_run(path):
    """Open a simulation file for reading, by its format.

    Parameters
    ----------
    path : str or os.PathLike
        A ``fem-run`` or ``timeseries`` file (a lab recording without ``format`` attributes reads as
        ``timeseries``).

    Returns
    -------
    FemRun or TimeseriesRun

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is missing, not HDF5, of another format or version, or fails its reader's checks;
        the message names the file.
    """
    path = Path(path)
    with open_file(path) as file:
        found = attribute(file, "format", "str", TimeseriesRun.format, required=False)
        version = attribute(file, "format_version", "int", -1, required=False)
    if found not in READERS:
        expected = ", ".join(f"{name} version {formats.get_format(name).version}" for name in READERS)
        raise FileFormatError(f"{path}: a {found} file version {version}, expected a simulation file: {expected}")
    return READERS[found](path)
