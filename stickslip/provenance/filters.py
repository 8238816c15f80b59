"""The filters of the database's queries: one definition for ``stickslip.study(...).runs/events`` and ``stickslip db``.

A filter is a column of the database (its name, type and doc are the vocabulary's,
:mod:`stickslip.vocabulary`) or any parameter of a plugin (``backend="cpu"``, ``dt_scale=0.5``:
:func:`stickslip.params`). Values are checked before the query: a filter that does not exist, a value of the
wrong type or outside the choices (``regime="stif"``, ``source="lab"``) raises
:class:`stickslip.plugin_params.ParameterError` naming it and what is allowed, as the command line refuses it, instead
of returning an empty table. A value may be:

- one value: rows equal to it (floats: to 6 significant digits, ``phi=5e-4``);
- a list, tuple or set of values: rows equal to any of them (``n=[1, 2]``);
- a float column: a pair ``(low, high)`` tuple also means the closed range (``phi=(1e-6, 1e-3)``).

numpy scalars and arrays are taken as the Python values they hold (``n=df["n"].unique()[0]``), and an integer
column takes a float with an integer value (``n=3.0``); a value that no row can hold (``n=3.5``, ``n="3"``) is
refused, never answered with an empty table. ``a`` is the interface (the paper's a, 1 = lowest; ``events(a=1)`` is
``events(interface=1)``); the slab driven alone in the individual protocol is ``driven_slab``.

The database's text columns that name plugins (``solver``, ``analysis``, ``plugin``) are checked against the
values the database holds.
"""

import dataclasses
import inspect
import math
import numbers
from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..plugin_params import ParameterError, did_you_mean
from ..vocabulary import QUANTITIES

__all__ = ["Filter", "RUN_FILTERS", "EVENT_FILTERS", "FLOAT_DIGITS", "check", "conditions", "with_filters"]

#: Significant digits to which a float filter matches.
FLOAT_DIGITS = 6

_SOURCES = ("numerical", "experimental")
_KINDS = ("solver", "analysis", "figure", "mesh")
_PROTOCOLS = ("stack", "individual")
_REGIMES = ("stiff", "compliant")


@dataclasses.dataclass(frozen=True)
class Filter:
    """One filter: a column and the values it takes.

    Attributes
    ----------
    name : str
        The keyword (and ``--name`` on the command line, ``_`` written ``-``).
    column : str
        The database column it compares (in the query's table).
    kind : {"int", "float", "str", "bool"}
    choices : tuple or None
        Allowed values; ``"database"``: the values that the database holds in ``column``.
    help : str
        What it selects (the vocabulary's doc unless given).
    """

    name: str
    column: str
    kind: str
    choices: tuple | str | None = None
    help: str = ""

    @property
    def doc(self):
        """The help: the filter's own, else the vocabulary's doc with its unit."""
        if self.help:
            return self.help
        quantity = QUANTITIES[self.name]
        return quantity.doc + (f" [{quantity.unit}]" if quantity.unit not in ("", "1") else "")


def _column_filters(names, kind, table="s"):
    return tuple(Filter(name, f"{table}.{name}", kind) for name in names)


_PHYSICS = (
    Filter("solver", "s.solver", "str", "database"),
    Filter("source", "s.source", "str", _SOURCES),
    Filter("protocol", "s.protocol", "str", _PROTOCOLS),
    *_column_filters(("n", "driven_slab", "plates", "blocks"), "int"),
    *_column_filters(("k_drive", "phi"), "float"),
    Filter("regime", "s.regime", "str", _REGIMES),
    *_column_filters(("temperature", "attempt_rate", "drive_rate", "junction_strengthening",
                      "junction_glass_temperature", "junction_attempt_rate"), "float"),
)

#: Filters of ``runs()`` (table ``runs`` as ``r`` joined with ``simulations`` as ``s``), in signature order.
RUN_FILTERS = (
    Filter("kind", "r.kind", "str", _KINDS),
    Filter("plugin", "r.plugin", "str", "database"),
    Filter("run_id", "r.run_id", "str", help="one run (16 hexadecimal characters)"),
    *_PHYSICS,
    Filter("seed", "r.seed", "int"),
)

#: Filters of ``events()`` (view ``slip_events_full`` as ``s``), in signature order.
EVENT_FILTERS = (
    Filter("analysis", "s.analysis", "str", "database"),
    Filter("run_id", "s.simulation_run_id", "str", help="the events of one simulation (its run id)"),
    Filter("interface", "s.interface", "int"),
    Filter("multi", "s.multi", "bool"),
    *_PHYSICS,
    Filter("seed", "s.seed", "int"),
)


def _fail(name, message):
    raise ParameterError(f"filter '{name}': {message}")


def _python(value):
    """A numpy scalar (``df["n"].unique()`` hands them out) as the Python value SQLite binds; others as given.

    (sqlite3 binds a numpy integer as a blob, which equals no number: the query would return nothing.)
    """
    return value.item() if isinstance(value, np.generic) else value


def _scalar(spec, value):
    """One value checked against the filter's kind and made a Python value (ints for floats allowed; a float with
    an integer value, e.g. from a column with missing values, for ints)."""
    value = _python(value)
    if spec.kind == "int" and isinstance(value, float) and value.is_integer():
        value = int(value)
    kinds = {"int": (numbers.Integral,), "float": (numbers.Real,), "str": (str,), "bool": (bool,)}[spec.kind]
    if not isinstance(value, kinds) or (spec.kind in ("int", "float") and isinstance(value, bool)):
        expected = {"int": "an integer", "float": "a number", "str": "a string", "bool": "True or False"}[spec.kind]
        _fail(spec.name, f"expected {expected} (or a list of them), got {value!r}: no row can match it")
    if spec.kind == "float" and not math.isfinite(value):
        _fail(spec.name, f"expected a finite number, got {value!r}")
    return float(value) if spec.kind == "float" else int(value) if spec.kind == "int" else value


def _checked(spec, value, known):
    """The filter's value as (operator, values): ``in`` a list, ``range`` (low, high), checked."""
    if spec.kind == "float" and isinstance(value, tuple) and len(value) == 2:
        low, high = (_scalar(spec, item) for item in value)
        if low > high:
            _fail(spec.name, f"a range (low, high) needs low <= high, got {value!r}")
        return "range", (low, high)
    items = list(value) if isinstance(value, (list, tuple, set, frozenset, np.ndarray, pd.Series, pd.Index)) \
        else [value]
    if not items:
        _fail(spec.name, "an empty list selects nothing")
    items = [_scalar(spec, item) for item in items]
    allowed = known.get(spec.name) if spec.choices == "database" else spec.choices
    if allowed is not None:
        for item in items:
            if item not in allowed:
                where = "values in this database" if spec.choices == "database" else "expected one of"
                listed = ", ".join(map(repr, allowed)) or "none"
                _fail(spec.name, f"{item!r} is not allowed; {where}: {listed}{did_you_mean(str(item), allowed)}")
    return "in", items


def check(specs, filters, *, known=None, parameters=None):
    """Check filter values; return the conditions to apply.

    Parameters
    ----------
    specs : Sequence[Filter]
        :data:`RUN_FILTERS` or :data:`EVENT_FILTERS`.
    filters : Mapping[str, object]
        Keyword -> value; None values are not applied.
    known : Mapping[str, Sequence], optional
        The database's values of the ``choices="database"`` filters, by filter name.
    parameters : Mapping[str, list[tuple[str, object]]], optional
        Plugin parameter name -> ``[(plugin, parse(value)), ...]``: for each plugin that declares the parameter, a
        function that checks a value and returns it converted (:func:`stickslip.plugin_params.parse_value`), and its
        default. Needed only if ``filters`` names a parameter that is no column.

    Returns
    -------
    list[tuple]
        ``(Filter, operator, values)`` for columns, ``("param", name, [(plugin, value, default), ...])`` for
        plugin parameters.

    Raises
    ------
    ParameterError
        A filter that is neither a column nor a parameter of a plugin, or a value that does not fit it.
    """
    by_name = {spec.name: spec for spec in specs}
    out = []
    for name, value in filters.items():
        if value is None:
            continue
        if name == "a" and "interface" in by_name:  # the paper's a: the interface, as in S_a1, A_a1
            name = "interface"
        if name in by_name:
            out.append((by_name[name],) + _checked(by_name[name], value, known or {}))
            continue
        declared = (parameters or {}).get(name)
        if not declared:
            hint = " (the fem parameter N is the column blocks)" if name == "N" else \
                (" (a is the interface, a filter of events(); the slab driven alone in the individual protocol is "
                 "driven_slab)") if name == "a" else did_you_mean(name, by_name)
            raise ParameterError(f"unknown filter {name!r}{hint}; allowed: {', '.join(by_name)}, or a parameter "
                                 "of a plugin (stickslip.params(name))")
        if isinstance(value, (list, tuple, set, frozenset, Mapping)):
            _fail(name, f"a plugin parameter takes one value, got {value!r}")
        accepted, errors = [], []
        for plugin, parse, default in declared:
            try:
                accepted.append((plugin, parse(value), default))
            except ParameterError as error:
                errors.append(str(error))
        if not accepted:
            raise ParameterError(f"filter {errors[0][len('parameter '):]}" if errors[0].startswith("parameter ")
                                 else errors[0])
        out.append(("param", name, accepted))
    return out


def _matches(column, operator, values, spec_kind, key):
    """SQL and bound values of one condition."""
    if operator == "range":
        return f"({column} BETWEEN :{key}_0 AND :{key}_1)", {f"{key}_0": values[0], f"{key}_1": values[1]}
    if spec_kind == "float":
        parts, bound = [], {}
        for index, value in enumerate(values):
            name = f"{key}_{index}"
            parts.append(f"ABS({column} - :{name}) <= {10.0 ** -FLOAT_DIGITS} * ABS(:{name})")
            bound[name] = value
        return "(" + " OR ".join(parts) + ")", bound
    bound = {f"{key}_{index}": value for index, value in enumerate(values)}
    return f"{column} IN ({', '.join(':' + name for name in bound)})", bound


def conditions(checked, run_ids):
    """The WHERE clause of checked filters.

    Parameters
    ----------
    checked : list[tuple]
        :func:`check`'s result.
    run_ids : Sequence[str]
        The run-id columns a plugin parameter filter applies to (any of them may match: an event's simulation
        or analysis).

    Returns
    -------
    tuple[str, dict]
        ``" WHERE ..."`` (empty without filters) and the values to bind.
    """
    clauses, bound = [], {}
    for index, item in enumerate(checked):
        key = f"f{index}"
        if item[0] == "param":
            _, name, accepted = item
            parts = []
            for number, (plugin, value, default) in enumerate(accepted):
                plugin_key, value_key, default_key = f"{key}_p{number}", f"{key}_v{number}", f"{key}_d{number}"
                value_sql = f"COALESCE(json_extract(params, '$.{name}'), :{default_key})"
                if isinstance(value, float):
                    test = f"ABS({value_sql} - :{value_key}) <= {10.0 ** -FLOAT_DIGITS} * ABS(:{value_key})"
                else:
                    test = f"{value_sql} = :{value_key}"
                parts.append(f"(plugin = :{plugin_key} AND {test})")
                bound.update({plugin_key: plugin, value_key: value, default_key: default})
            selected = f"SELECT run_id FROM runs WHERE {' OR '.join(parts)}"
            clauses.append("(" + " OR ".join(f"{column} IN ({selected})" for column in run_ids) + ")")
            continue
        spec, operator, values = item
        clause, values = _matches(spec.column, operator, values, spec.kind, key)
        clauses.append(clause)
        bound.update(values)
    return (" WHERE " + " AND ".join(clauses) if clauses else ""), bound


def with_filters(specs):
    """Decorate ``method(self, **filters)`` with an explicit keyword signature and docs of ``specs``.

    ``help()``, IPython's ``?`` and tab completion show every filter; the method still receives them as
    ``**filters`` (None where not given), with plugin parameters among them. The method's own keyword-only
    parameters (``wide``) come first.
    """
    def decorate(method):
        own = [parameter for parameter in inspect.signature(method).parameters.values()
               if parameter.kind is inspect.Parameter.KEYWORD_ONLY]
        parameters = [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD), *own]
        parameters += [inspect.Parameter(spec.name, inspect.Parameter.KEYWORD_ONLY, default=None) for spec in specs]
        parameters.append(inspect.Parameter("parameters", inspect.Parameter.VAR_KEYWORD))
        method.__signature__ = inspect.Signature(parameters)
        placeholder = next(line for line in method.__doc__.splitlines() if "{filters}" in line)
        indent = placeholder[:len(placeholder) - len(placeholder.lstrip())]
        lines = [f"{indent}{spec.name} : {_TYPES[spec.kind]}, optional\n{indent}    {spec.doc}"
                 + (f" (one of {', '.join(map(repr, spec.choices))})" if isinstance(spec.choices, tuple) else "")
                 for spec in specs]
        method.__doc__ = method.__doc__.replace(placeholder, "\n".join(lines))
        return method
    return decorate


_TYPES = {"int": "int or list of int", "float": "float, list of float or (low, high)", "str": "str or list of str",
          "bool": "bool"}
