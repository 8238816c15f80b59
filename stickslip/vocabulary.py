"""The package's vocabulary: one name, one dtype and one unit for every column of every table it produces.

The tables that analyses write (``event-table`` files), the results database (its SQLAlchemy models take
their column docs from here), the DataFrames of the public API (each carries ``attrs["units"]``, column ->
unit) and the CSV of the command line all name a quantity the same way: an interface is ``interface``
(the paper's a, 1 = lowest), blocks per interface are ``blocks`` (the ``fem`` parameter and file attribute
``N``: SQLite's column names ignore case, so ``N`` cannot sit beside ``n``), booleans are ``bool``
(``multi``, never 0/1 or a ``single`` beside it). A quantity measured both in the lab and in the model keeps
the lab's name for the lab's units and carries the model's unit in its name in the numerical tables:
``dmu`` is the friction drop of a lab or virtual slip [1], ``dmu_sig0`` the drop of an interface's stress in
the finite-element model [sig0] (the paper's Δμ_a of the numerics); ``time`` is a lab clock [s], ``t`` the
model's [time]; likewise ``T`` / ``T_fe``, ``B_a`` / ``B_a_sig0``, ``mu_before`` / ``mu_before_sig0``.

Units: ``s``, ``mm``, ``N``, ... (SI-based lab units); ``sig0``, ``eps0``, ``gamma0`` (the model's stress,
strain and lever-rotation units, docs/fem.md); ``time``, ``length``, ``G/h^2``, ... (the model's units, as
the ``fem`` parameters write them); ``1`` a dimensionless number (a count, a fraction, a friction
coefficient); ``""`` no quantity (an identifier, an index, a label, a flag, a text).

docs/database.md documents the database's columns with these docs and units, and
tests/test_vocabulary.py holds the writers, the database schema, the API and that page to them.
"""

import dataclasses
import json
import re

import numpy as np
import pandas as pd

__all__ = ["Quantity", "QUANTITIES", "PATTERNS", "RENAMED", "UnitFrame", "quantity", "unit", "units", "with_units",
           "dtype_matches", "typed", "missing_as_na", "expand_json"]


@dataclasses.dataclass(frozen=True)
class Quantity:
    """One column's meaning.

    Attributes
    ----------
    dtype : {"bool", "int64", "float64", "str", "datetime", "object"}
        Its type in a DataFrame (an integer or boolean column with missing values is pandas' nullable
        ``Int64`` / ``boolean``; ``datetime``: timezone-aware, UTC).
    unit : str
        Its unit (module docstring); ``""`` for no quantity.
    doc : str
        What it is, in one line.
    """

    dtype: str
    unit: str
    doc: str


def _q(dtype, unit, doc):
    return Quantity(dtype, unit, doc)


_ID, _LABEL = "", ""

#: Every column name of the package's tables -> its quantity.
QUANTITIES = {
    # --- identity and provenance of a run (database table ``runs``, :func:`stickslip.study` ``runs()``)
    "run_id": _q("str", _ID, "run id: 16 hexadecimal characters (a simulation's file stem)"),
    "kind": _q("str", _LABEL, "what the row is: a plugin kind (solver, analysis, figure, mesh), an increment's "
                              "class (initial, load, micro, single, multi) or a sequence's (single, multi)"),
    "plugin": _q("str", _LABEL, "the plugin that ran"),
    "plugin_version": _q("str", _LABEL, "the plugin's algorithm version"),
    "code_hash": _q("str", _ID, "hash of the code the job ran: its plugin, what it imports, the parts it chose"),
    "package_version": _q("str", _LABEL, "the stickslip version that ran"),
    "git_commit": _q("str", _ID, "the git commit of the code (missing outside a git tree)"),
    "git_dirty": _q("bool", _LABEL, "tracked files differed from the commit"),
    "params": _q("str", _LABEL, "every parameter, defaults filled (JSON; the API expands it into params.<name>)"),
    "seed": _q("int64", _ID, "seed of every random stream (a realisation id)"),
    "threads": _q("int64", "1", "threads the job used"),
    "python_version": _q("str", _LABEL, "Python version"),
    "numpy_version": _q("str", _LABEL, "numpy version"),
    "numba_version": _q("str", _LABEL, "numba version"),
    "h5py_version": _q("str", _LABEL, "h5py version"),
    "versions": _q("str", _LABEL, "every library version (JSON)"),
    "host": _q("str", _LABEL, "machine name"),
    "started_at": _q("datetime", _LABEL, "start of the job (UTC; ISO 8601 text in the database)"),
    "finished_at": _q("datetime", _LABEL, "end of the job (UTC; ISO 8601 text in the database)"),
    "wall_time_s": _q("float64", "s", "wall time of the plugin call, without Python's start-up"),
    "peak_memory_mib": _q("float64", "MiB", "peak resident memory of the job process"),
    "record_path": _q("str", _LABEL, "the provenance record (JSON file)"),
    # --- files (database table ``artifacts``)
    "id": _q("int64", _ID, "row number"),
    "direction": _q("str", _LABEL, "input or output"),
    "role": _q("str", _LABEL, "the file's role: output, pdf, png, mesh, simulation, analysis:<name>, format:<name>"),
    "path": _q("str", _LABEL, "a file, relative to the workflow directory"),
    "sha256": _q("str", _ID, "content hash of the file"),
    "bytes": _q("int64", "B", "size of the file"),
    "format": _q("str", _LABEL, "the file's format (fem-run, timeseries, event-table, ...)"),
    "made_by": _q("str", _ID, "run id of the job that wrote an input file (lineage)"),
    # --- a simulation's parameters (database table ``simulations``)
    "solver": _q("str", _LABEL, "the solver plugin: fem, lever, rate-state-lever, ..."),
    "source": _q("str", _LABEL, "numerical or experimental (lab or virtual experiment): the simulation format's"),
    "protocol": _q("str", _LABEL, "driving protocol of the lever: stack or individual"),
    "n": _q("int64", "1", "number of driven slabs / interfaces"),
    "driven_slab": _q("int64", _ID, "the slab driven alone in the individual protocol, 0 in the stack "
                                    "(the lever parameter and file attribute a)"),
    "plates": _q("int64", "1", "elastic plates of the finite-element stack"),
    "blocks": _q("int64", "1", "blocks per interface (the fem parameter and file attribute N)"),
    "k_drive": _q("float64", "G/h^2", "drive spring stiffness per unit volume (fem)"),
    "phi": _q("float64", "1", "rigidity ratio Phi = K / K_s of the drive (fem)"),
    "regime": _q("str", _LABEL, "driving regime: stiff or compliant (fem, from Phi)"),
    "temperature": _q("float64", "G eps0^2 h^2", "thermal activation of a fem run (0: the athermal protocol)"),
    "attempt_rate": _q("float64", "1/time", "attempt rate of a thermal fem run"),
    "drive_rate": _q("float64", "eps0/time", "drive rate of a thermal fem run"),
    "junction_strengthening": _q("float64", "eps0 / (G eps0^2 h^2)", "junction aging of a fem run: widening of a "
                                                                     "well per unit junction depth (0: no aging)"),
    "junction_glass_temperature": _q("float64", "G eps0^2 h^2", "scale T_g of the junction depths of a fem run "
                                                                "with aging"),
    "junction_attempt_rate": _q("float64", "1/time", "attempt rate of the junction redraws of a fem run with aging"),
    # --- slip events (``event-table`` files' table slip_events, database table ``slip_events``)
    "analysis": _q("str", _LABEL, "the analysis plugin"),
    "analysis_run_id": _q("str", _ID, "run id of the analysis run"),
    "simulation_run_id": _q("str", _ID, "run id of the analysed simulation (from the lineage)"),
    "event": _q("int64", _ID, "event index within the run, from 0"),
    "interface": _q("int64", _ID, "interface (slab) a, 1 = lowest"),
    "multi": _q("bool", _LABEL, "more than one interface slipped in the event"),
    "slip": _q("float64", "mm", "slip dR of the interface (experimental)"),
    "dmu": _q("float64", "1", "drop of friction coefficient of the interface (experimental)"),
    "dmu_sig0": _q("float64", "sig0", "drop of the interface's volume-averaged stress (numerical; the paper's "
                                      "Delta mu_a of the model)"),
    "time": _q("float64", "s", "time of the slip on the recording's clock (experimental)"),
    "t": _q("float64", "time", "time on the model's clock (numerical; failures and holds: since the kick or the "
                               "hold's start)"),
    "increment": _q("int64", _ID, "increment of the run (numerical)"),
    "extra": _q("str", _LABEL, "the event table's further columns (JSON; the API expands it into columns)"),
    "t_start": _q("float64", "s", "first frame of the slip's bracket"),
    "t_end": _q("float64", "s", "last frame of the slip's bracket"),
    "dF": _q("float64", "N", "force drop of the event on the lever"),
    "T": _q("float64", "s", "waiting time since the interface's previous slip (experimental)"),
    "T_fe": _q("float64", "time", "waiting time since the interface's previous slip (numerical)"),
    "slip_from_dF": _q("float64", "mm", "the slip that the lever's kinematics infers from dF (single slips)"),
    "B_a": _q("float64", "1", "aging rate of the slip, dmu / ln(T / T0) (experimental)"),
    "B_a_sig0": _q("float64", "sig0", "aging rate of the slip, dmu_sig0 / ln(T_fe / T0) (numerical)"),
    "drift": _q("float64", "mm", "creep of the interface since its previous slip"),
    "slow_slip_before": _q("bool", _LABEL, "the drift before the slip exceeds slow_slip_drift"),
    "dgamma": _q("float64", "gamma0", "lever rotation since the interface's previous slip (numerical)"),
    "hold": _q("float64", "time", "part of T_fe during which the drive was held (numerical)"),
    "mu_before_sig0": _q("float64", "sig0", "the interface's stress before the slip, its peak (numerical)"),
    "wait_drive": _q("float64", "eps0", "imposed drive since the interface's previous slip (numerical): the "
                                        "waiting time in units of 1/drive_rate"),
    "rise_sig0": _q("float64", "sig0", "rise of the interface's stress in the load steps since its previous slip "
                                       "(numerical)"),
    "recovered_sig0": _q("float64", "sig0", "the peak minus the stress the interface's previous slip left "
                                            "(numerical)"),
    "interrupted_sig0": _q("float64", "sig0", "stress the interface lost in other events since its previous slip "
                                              "(numerical)"),
    # --- periodicity of a run's slip events (table periodicity, database table ``run_periodicity``)
    "n_slips": _q("int64", "1", "number of slips (steady-state slip events of a run; of an interface)"),
    "n_multi": _q("int64", "1", "number of multi-slips (s > 1; of an interface: its slips in multi-slips)"),
    "n_spanning": _q("int64", "1", "number of system-spanning slips (s = n)"),
    "interval_cv": _q("float64", "1", "coefficient of variation of the shear increment between consecutive slip "
                                      "events"),
    "drop_cv": _q("float64", "1", "coefficient of variation of the macroscopic stress drops of the slip events"),
    "multi_fraction": _q("float64", "1", "fraction of slip events that are multi-slips, rho(s > 1)"),
    "spanning_fraction": _q("float64", "1", "fraction of slip events in which every interface slips"),
    "alternation_cv": _q("float64", "1", "coefficient of variation of the number of single slips between "
                                         "consecutive multi-slips"),
    "runs_z": _q("float64", "1", "Wald-Wolfowitz runs statistic of the order of single and multi slips"),
    "dt_scale": _q("float64", "1", "time step of a fem run, in units of the paper's (fem parameter)"),
    # --- figures (database table ``figures``)
    "figure": _q("str", _LABEL, "figure name (fig3, ...)"),
    "pdf": _q("str", _LABEL, "the figure's PDF file"),
    "png": _q("str", _LABEL, "the figure's PNG file"),
    "key": _q("str", _LABEL, "schema_version or package_version"),
    "value": _q("str", _LABEL, "its value (text)"),
    # --- a fem run's increments (run files, stickslip.fem.observables) and the numerical-events tables
    "kick": _q("bool", _LABEL, "the increment is an event: a kick and a minimisation (else an elastic load step)"),
    "yield_element": _q("bool", _LABEL, "the kick's whole-element fallback"),
    "gamma": _q("float64", "gamma0", "lever rotation"),
    "epsd": _q("float64", "eps0", "equivalent strain of the whole stack"),
    "sigd": _q("float64", "sig0", "equivalent stress of the whole stack"),
    "lever_target": _q("float64", "length", "drive target at the lever's drive height (free lever)"),
    "lever_position": _q("float64", "length", "the lever's position at its drive height (free lever)"),
    "hop_block": _q("int64", _ID, "the block that hopped (thermal run; -1 for none)"),
    "hop_direction": _q("int64", _ID, "direction of a well hop, +1 / -1 (a thermal run's increments; failures)"),
    "failed_hops": _q("int64", "1", "hops over a barrier that failed (thermal run)"),
    "held": _q("float64", "time", "time of the increment during which the drive was held (thermal run)"),
    "s": _q("int64", "1", "number of interfaces that slipped in the event"),
    "steady": _q("bool", _LABEL, "at or after the steady state"),
    "interfaces": _q("str", _LABEL, "the interfaces that slipped, e.g. \"1,3\""),
    "sigma_before": _q("float64", "sig0", "macroscopic stress Sigma before the kick"),
    "sigma_after": _q("float64", "sig0", "macroscopic stress Sigma after the minimisation"),
    "dsigma": _q("float64", "sig0", "macroscopic stress drop of the event, sigma_before - sigma_after"),
    "first_increment": _q("int64", _ID, "first increment of a run of single or of multi slips"),
    "last_increment": _q("int64", _ID, "last increment of that run"),
    "length": _q("int64", "1", "number of slip events in the run of slips"),
    "block": _q("int64", _ID, "block of the interface, 0 ... N - 1 from the left"),
    # --- experiment-events: slips and interfaces of a recording
    "driven": _q("bool", _LABEL, "the interface can slip (stack: a <= n; individual: the driven slab)"),
    "R_tot": _q("float64", "mm", "total sliding of the interface over the analysed record"),
    "dR_sum": _q("float64", "mm", "sum of the interface's detected slips"),
    "R_slow": _q("float64", "1", "fraction of the sliding made by slow slip, 1 - dR_sum / R_tot"),
    # --- ground truth of a virtual experiment (stickslip.solvers.lever, rate_state_lever)
    "mu_before": _q("float64", "1", "friction coefficient of the interface before the slip"),
    "mu_after": _q("float64", "1", "friction coefficient of the interface after the slip"),
    "age": _q("float64", "s", "age of the interface's contacts at the slip"),
    "excess": _q("float64", "1", "friction beyond the interface's strength when it slipped"),
    "triggered": _q("bool", _LABEL, "the slip was triggered by another interface's slip"),
    "creep_before": _q("float64", "mm", "creep of the interface since its previous slip"),
    "V_max": _q("float64", "mm/s", "peak slip rate of the slip"),
    "theta_before": _q("float64", "s", "rate-and-state contact age theta before the slip"),
    "slippable": _q("bool", _LABEL, "the interface can slip in this protocol"),
    "slab": _q("int64", _ID, "the physical slab at this position (rate-state-lever)"),
    "mu_d": _q("float64", "1", "dynamic friction coefficient of the interface (lever)"),
    "B": _q("float64", "1", "aging rate put into the interface (lever)"),
    "creep_velocity": _q("float64", "mm/s", "creep velocity of the interface (lever, after the scaling with n)"),
    "a_rs": _q("float64", "1", "rate-and-state direct effect a of the interface"),
    "b": _q("float64", "1", "rate-and-state evolution effect b of the interface"),
    "D_c": _q("float64", "mm", "rate-and-state critical slip distance of the interface"),
    "mu0": _q("float64", "1", "rate-and-state reference friction of the interface"),
    "K_c": _q("float64", "N/mm", "linear-stability boundary N (b - a) / D_c of the interface"),
    "slip_total": _q("float64", "mm", "sum of the interface's slips"),
    "creep_total": _q("float64", "mm", "slow slip of the interface over the run"),
    "R_total": _q("float64", "mm", "R_a at the end minus at the start, noise-free"),
    # --- the aging fit's bins (stickslip.experiment.aging.AgingFit)
    "T_low": _q("float64", "s", "lower edge of a bin of waiting times"),
    "T_high": _q("float64", "s", "upper edge of a bin of waiting times"),
    "dmu_mean": _q("float64", "1", "mean friction drop of the bin's slips"),
    "dmu_std": _q("float64", "1", "standard deviation of the friction drops of the bin's slips"),
    "count": _q("int64", "1", "slips in the bin"),
    # --- the plugins and formats (stickslip.plugins, stickslip.plugin_params)
    "name": _q("str", _LABEL, "name of a plugin, a format or a parameter"),
    "version": _q("str", _LABEL, "version of a plugin or a format"),
    "summary": _q("str", _LABEL, "one line: what the plugin does or the format holds"),
    "consumes": _q("object", _LABEL, "the formats an analysis reads (a tuple)"),
    "produces": _q("str", _LABEL, "the format a solver or analysis writes"),
    "inputs": _q("object", _LABEL, "a figure's input categories (a tuple)"),
    "replay": _q("bool", _LABEL, "the solver replays events (FemRun.failures)"),
    "module": _q("str", _LABEL, "the Python module"),
    "describe": _q("str", _LABEL, "\"module:function\" giving the database's simulation columns of a file"),
    "unstamped": _q("int64", _LABEL, "the version a file without format attributes is read as"),
    "type": _q("str", _LABEL, "a parameter's type"),
    "default": _q("object", _LABEL, "a parameter's default"),
    "unit": _q("str", _LABEL, "a parameter's unit"),
    "doc": _q("str", _LABEL, "a parameter's description"),
}

#: Column families: ``<prefix><number>`` -> quantity (``{}`` is the layer, the interface or a parameter name).
PATTERNS = {
    "epsd_{}": _q("float64", "eps0", "equivalent strain of layer {} (0 the bottom plate, odd the interfaces)"),
    "sigd_{}": _q("float64", "sig0", "equivalent stress of layer {}"),
    "ubar_{}": _q("float64", "length", "mean x-displacement of layer {}"),
    "fxdrive_{}": _q("float64", "length", "elongation of the drive spring of layer {}"),
    "S_a{}": _q("int64", "1", "net well hops of interface {}'s blocks since the previous increment"),
    "A_a{}": _q("int64", "1", "blocks of interface {} that changed well since the previous increment"),
    "mu_a{}": _q("float64", "sig0", "volume-averaged equivalent stress of interface {}"),
}

_PATTERNS = [(re.compile("^" + re.escape(name).replace(r"\{\}", r"(\d+)") + "$"), q) for name, q in PATTERNS.items()]

#: Names this vocabulary replaced (schema 7 of the database, event-table 2, front-table 3): old -> new, by table.
RENAMED = {
    "slip_events": {"dmu": "dmu_sig0 (numerical rows)", "time": "t (thermal-events)", "T": "T_fe (thermal-events)",
                    "B_a": "B_a_sig0 (thermal-events)", "mu_before": "mu_before_sig0 (thermal-events)",
                    "dR_from_dF": "slip_from_dF"},
    "simulations": {"a": "driven_slab"},
    "run_periodicity": {"slips": "n_slips", "multi": "n_multi", "spanning": "n_spanning"},
    "slips (numerical-events)": {"single": "multi (negated)"},
    "slip_interfaces": {"a": "interface", "dmu": "dmu_sig0", "single": "multi (negated)"},
    "slips (experiment-events)": {"a": "interface", "t": "time", "dR": "slip", "dR_from_dF": "slip_from_dF"},
    "interfaces": {"a": "interface"},
    "failures": {"a": "interface", "direction": "hop_direction"},
    "truth": {"a": "interface", "dR": "slip"},
}


def quantity(name):
    """The quantity of a column name, or None if the vocabulary does not know it.

    Parameters
    ----------
    name : str
        A column name; ``params.<name>`` (a plugin parameter in :func:`stickslip.study`'s ``runs()``) is
        not a vocabulary name (its unit is the plugin's).

    Returns
    -------
    Quantity or None
    """
    if name in QUANTITIES:
        return QUANTITIES[name]
    for pattern, found in _PATTERNS:
        match = pattern.match(str(name))
        if match:
            return dataclasses.replace(found, doc=found.doc.format(match.group(1)))
    return None


def unit(name):
    """The unit of a column name (module docstring), or None if the vocabulary does not know it."""
    found = quantity(name)
    return None if found is None else found.unit


def units(columns):
    """Column -> unit for every column (None for a name the vocabulary does not know)."""
    return {str(column): unit(column) for column in columns}


def dtype_matches(dtype, expected):
    """Whether a pandas dtype is the vocabulary's ``expected`` one (nullable forms and text included).

    Parameters
    ----------
    dtype : numpy.dtype or pandas extension dtype
    expected : str
        A :attr:`Quantity.dtype`.

    Returns
    -------
    bool
    """
    if expected == "object":
        return True
    if expected == "str":
        return pd.api.types.is_string_dtype(dtype) or dtype == object
    if expected == "datetime":
        return isinstance(dtype, pd.DatetimeTZDtype) and str(dtype.tz) == "UTC"
    kind = {"bool": pd.api.types.is_bool_dtype, "int64": pd.api.types.is_integer_dtype,
            "float64": pd.api.types.is_float_dtype}[expected]
    return bool(kind(dtype))


def _column_units(columns, inputs, method):
    """The unit of each of ``columns`` (the result of a pandas operation on ``inputs``) from the inputs' units.

    A column keeps the unit it had in the input it came from: by its name, or, for a merge's columns renamed with
    a suffix, by the name it had there (the left input's columns come first, in their order); a column that the
    inputs give different units (a concat of two tables that disagree) has none (None); a column no input knows
    (a new one) has the vocabulary's unit of its name.
    """
    tables = [obj.attrs.get("units") or {} for obj in inputs]
    found = {}
    if method == "merge" and len(inputs) == 2:  # the left table's columns first, in order, some with a suffix
        for name, source in zip(map(str, columns), map(str, inputs[0].columns)):
            if name.startswith(source) and source in tables[0]:
                found[name] = tables[0][source]
    for name in map(str, columns):
        if name in found:
            continue
        given = {table[name] for table in tables if name in table}
        if not given:  # a merge's suffixed column of the right table: its longest name that starts this one
            stems = sorted((source for table in tables[::-1] for source in table
                            if name.startswith(source) and name != source), key=len, reverse=True)
            given = {next(table[stems[0]] for table in tables[::-1] if stems[0] in table)} if stems else set()
        found[name] = given.pop() if len(given) == 1 else None if given else unit(name)
    return found


class UnitFrame(pd.DataFrame):
    """A pandas DataFrame whose ``attrs["units"]`` (column -> unit) follows its columns through pandas' operations.

    Every table of the package's API is one. pandas keeps ``attrs`` through an operation on one table, and drops
    them in a ``merge``, ``join`` or ``concat`` of tables whose ``attrs`` differ; here each column of the result
    keeps the unit of the column it came from (:func:`_column_units`), so ``runs.merge(events, ...)`` and
    ``pd.concat([fem_events, lab_events])`` carry the units of all their columns, and a renamed column keeps its
    unit. The data and dtypes are pandas'
    own (plain float64, Int64, ...): no unit-aware arithmetic (pint-pandas) and no other array library (xarray).
    The result of a merge or concat is a ``UnitFrame`` where the left or first table is one.
    """

    _metadata = []

    @property
    def _constructor(self):
        return UnitFrame

    def __finalize__(self, other, method=None, **kwargs):
        super().__finalize__(other, method, **kwargs)
        inputs = getattr(other, "input_objs", None) or ([other] if isinstance(other, pd.DataFrame) else [])
        inputs = [obj for obj in inputs if isinstance(obj, (pd.DataFrame, pd.Series))]
        if any("units" in obj.attrs for obj in inputs):
            self.attrs["units"] = _column_units(self.columns, inputs, method)
        return self

    def __setitem__(self, key, value):
        """pandas' ``frame[key] = value``; a new column gets the vocabulary's unit of its name (None if unknown)."""
        super().__setitem__(key, value)
        units = self.attrs.get("units")
        if units is not None:
            for name in map(str, self.columns):
                units.setdefault(name, unit(name))

    def rename(self, *args, **kwargs):
        """pandas' ``rename``; a renamed column keeps its unit."""
        columns, units = list(self.columns), dict(self.attrs.get("units", {}))
        result = super().rename(*args, **kwargs)
        renamed = self if result is None else result  # inplace=True
        if units and len(renamed.columns) == len(columns):
            renamed.attrs["units"] = {str(new): units.get(str(old), unit(new))
                                      for old, new in zip(columns, renamed.columns)}
        return result


def with_units(frame, extra=None):
    """``frame`` as a :class:`UnitFrame` with ``attrs["units"]``: every column's unit (the vocabulary's; ``extra`` first).

    Parameters
    ----------
    frame : pandas.DataFrame
        Returned if a UnitFrame already (its units set), else a UnitFrame of the same data.
    extra : Mapping[str, str], optional
        Units of columns outside the vocabulary (a plugin's parameters).

    Returns
    -------
    UnitFrame
    """
    extra = dict(extra or {})
    frame = frame if isinstance(frame, UnitFrame) else UnitFrame(frame)
    frame.attrs["units"] = {str(c): extra[c] if c in extra else unit(c) for c in frame.columns}
    return frame


def _cast(values, dtype):
    """``values`` (a Series) as ``dtype`` if that loses nothing (missing values kept as missing), else unchanged."""
    present = values.dropna()
    if dtype == "datetime":
        if present.empty or not all(isinstance(v, str) for v in present):
            return values
        return pd.to_datetime(values, utc=True, format="ISO8601")
    if dtype == "float64":
        return values.astype("float64") if all(_is_number(v) for v in present) else values
    if dtype in ("bool", "int64"):
        numbers = present.to_numpy()
        if not all(_is_number(v) for v in numbers):
            return values
        integers = all(isinstance(v, (bool, int, np.bool_, np.integer)) for v in numbers)
        if dtype == "bool" and not integers and len(present) == len(values):
            return values  # floats without a missing value are no SQL boolean (an average named like a column)
        numbers = numbers.astype(float)
        if dtype == "bool" and not np.isin(numbers, (0, 1)).all():
            return values
        if dtype == "int64" and not (np.isfinite(numbers) & (numbers == np.round(numbers))).all():
            return values
        if len(present) == len(values):
            return values.astype(np.int64) if dtype == "int64" else values.astype(float).astype(bool)
        return values.astype("Float64").astype({"bool": "boolean", "int64": "Int64"}[dtype])
    return values


def _is_number(value):
    return isinstance(value, (bool, int, float, np.bool_, np.integer, np.floating))


def typed(frame):
    """``frame`` with every column of the vocabulary in its dtype, where that loses nothing.

    Integers and booleans with missing values become pandas' nullable ``Int64`` / ``boolean``, ISO 8601 text of
    a ``datetime`` quantity a UTC datetime; a column whose values do not fit (e.g. an average an SQL query
    named ``multi``) is left as it is.

    Parameters
    ----------
    frame : pandas.DataFrame
        Changed in place and returned.

    Returns
    -------
    pandas.DataFrame
    """
    for column in frame.columns:
        found = quantity(column)
        if found is not None and not dtype_matches(frame[column].dtype, found.dtype):
            frame[column] = _cast(frame[column], found.dtype)
    return frame


#: The nullable dtype of a column with missing values, by its values' kind (numpy's dtype.kind).
_NULLABLE = {"f": "Float64", "i": "Int64", "u": "Int64", "b": "boolean"}


def missing_as_na(frame):
    """``frame`` with one spelling of a missing value, ``pd.NA``, in every column that has one.

    A column with missing values takes pandas' nullable dtype (``Float64``, ``Int64``, ``boolean``; text:
    ``string``), whose missing value is ``pd.NA`` (``pd.isna``; ``to_numpy()`` gives NaN in a float array);
    other columns (lists, mixed values) keep their dtype with ``pd.NA`` for ``None`` and NaN; datetimes keep
    ``NaT``, pandas' missing datetime. Columns without missing values are left as they are. ``frame`` (a
    pandas DataFrame) is changed in place and returned.
    """
    for column in frame.columns:
        values = frame[column]
        missing = values.isna()
        if not missing.any() or isinstance(values.dtype, pd.DatetimeTZDtype) or values.dtype.kind == "M":
            continue
        if isinstance(values.dtype, pd.api.extensions.ExtensionDtype) and values.dtype.na_value is pd.NA:
            continue  # Int64, boolean, Float64, string already
        present = values[~missing]
        if values.dtype.kind in _NULLABLE:
            frame[column] = values.astype(_NULLABLE[values.dtype.kind])
        elif pd.api.types.is_string_dtype(values.dtype) and all(isinstance(v, str) for v in present):
            frame[column] = values.astype("string")
        else:
            frame[column] = values.astype(object).where(~missing, pd.NA)
    return frame


def _decoded(text):
    if text is None or (isinstance(text, float) and np.isnan(text)):
        return {}
    return json.loads(text)


def expand_json(frame, column, prefix=""):
    """Replace a column of JSON objects by one column per key (``prefix`` + key), in the order first seen.

    A key whose name is taken by another column becomes ``<column>.<key>``.

    Parameters
    ----------
    frame : pandas.DataFrame
    column : str
        Its cells: JSON text of an object, or missing.
    prefix : str, optional

    Returns
    -------
    pandas.DataFrame
        A new frame; the expanded columns after the others, missing values where a row lacks a key.
        Lists stay lists.
    """
    decoded = [_decoded(text) for text in frame[column]]
    keys = list(dict.fromkeys(key for row in decoded for key in row))
    kept = frame.drop(columns=[column])
    if not keys:
        return kept
    wide = pd.DataFrame.from_records([{key: row.get(key) for key in keys} for row in decoded], index=frame.index,
                                     columns=keys)
    wide = wide.infer_objects()
    for key in keys:
        if wide[key].dtype == object and all(isinstance(v, bool) or v is None for v in wide[key]):
            wide[key] = wide[key].astype("boolean")
        elif wide[key].dtype == object and all(isinstance(v, int) and not isinstance(v, bool) or v is None
                                               for v in wide[key]):
            wide[key] = wide[key].astype("Int64")
    names = [prefix + key if prefix + key not in kept.columns else f"{column}.{key}" for key in keys]
    return pd.concat([kept, wide.set_axis(names, axis=1)], axis=1)
