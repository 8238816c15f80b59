"""Plugin parameters: typed dataclasses that give defaults, validation and docs.

Every plugin declares one frozen dataclass whose fields all have defaults and
are made with :func:`param`. That one declaration feeds:

- :func:`parse_params`: a mapping (config section, ``KEY=VALUE`` strings) to a
  validated instance, with errors that name the field and what was expected;
- :func:`params_to_dict`: the defaults-filled, JSON-safe form used for run ids,
  provenance records and HDF5 attributes;
- :func:`json_schema`: the JSON-Schema of the section in the workflow config;
- :func:`describe`: the rows of ``stickslip plugins --params``.

Supported field types: ``int``, ``float``, ``bool``, ``str`` and tuples
``tuple[int, ...]``, ``tuple[float, ...]`` (written ``1,2,3`` on a command line).
A dataclass may define ``check(self)``, called after the per-field checks, for
conditions that involve several fields; it raises :class:`ParameterError`.

A parameter renamed keeps its old name as an alias: the dataclass's ``RENAMED`` (a ``ClassVar``, old name -> new
name) maps a value given under the old name to the new one, with a :class:`RenamedParameterWarning` (the config's
schema accepts it too); a value given under both names is refused.

A field added to a plugin after runs were made is declared with ``extension=True``:
while it has its default it is left out of :func:`params_to_dict`, so the run ids,
stored parameters and files of the runs made before it keep their bytes (its default
must reproduce what those runs did); any other value is stored and keyed as usual.
A field that only matters when another extension field is set (e.g. the attempt rate
of a thermal run, which matters only at a finite temperature) is declared with
``extension="<that field>"``: it is left out while both it and that field have their
defaults, and stored (with the run id keyed on it) as soon as either has another value.
"""

import dataclasses
import difflib
import math
import typing
import warnings
from collections.abc import Iterable, Mapping

__all__ = [
    "ParameterError",
    "ParameterWarning",
    "RenamedParameterWarning",
    "param",
    "parse_params",
    "parse_value",
    "did_you_mean",
    "parse_assignments",
    "params_to_dict",
    "json_schema",
    "describe",
    "value_range",
]


class ParameterError(ValueError):
    """A parameter name or value is not acceptable; the message says which and why."""


class ParameterWarning(UserWarning):
    """Parameters that the method represents but outside the regime where it was studied; the message says which."""


class RenamedParameterWarning(ParameterWarning, FutureWarning):
    """A parameter given under its old name (a dataclass's ``RENAMED``): it is mapped to the new one.

    A ``FutureWarning``: shown by default, as Python shows warnings meant for the users of a package.
    """


def _renamed(cls, values, owner):
    """``values`` (a dict, changed in place) with every old name of ``cls.RENAMED`` replaced by its new one."""
    for old, new in getattr(cls, "RENAMED", {}).items():
        if old not in values:
            continue
        where = f" of {owner}" if owner else ""
        if new in values:
            raise ParameterError(f"parameter '{old}'{where} is '{new}' now; give '{new}' alone")
        warnings.warn(f"parameter '{old}'{where} is called '{new}' now (the old name is mapped, and will go)",
                      RenamedParameterWarning, stacklevel=4)
        values[new] = values.pop(old)
    return values


def param(default, doc, *, unit="", choices=None, minimum=None, maximum=None, exclusive_minimum=None,
          extension=False):
    """Declare one plugin parameter.

    Parameters
    ----------
    default
        Default value (immutable: tuples, not lists).
    doc : str
        One-line description, shown by ``stickslip plugins --params``.
    unit : str, optional
        Physical unit ("" for dimensionless or not applicable).
    choices : sequence or Mapping, optional
        The allowed values. A mapping (a plugin's registry, name -> class) is kept as it is, so that
        what is registered later is allowed too; ``stickslip plugins --params`` then shows each name
        with its class's ``summary``.
    minimum, maximum : float, optional
        Inclusive bounds (for tuples: of every element).
    exclusive_minimum : float, optional
        Exclusive lower bound (for tuples: of every element).
    extension : bool or str, optional
        The field was added after runs were made: at its default it is left out of
        :func:`params_to_dict` (run ids, stored parameters), so those runs keep their ids.
        The name of another field: left out only while that field is at its default too.

    Returns
    -------
    dataclasses.Field
    """
    if choices is not None and not isinstance(choices, Mapping):
        choices = tuple(choices)
    meta = {"doc": doc, "unit": unit, "choices": choices,
            "minimum": minimum, "maximum": maximum, "exclusive_minimum": exclusive_minimum,
            "extension": extension if isinstance(extension, str) else bool(extension)}
    return dataclasses.field(default=default, metadata=meta)


def _field_types(cls):
    hints = typing.get_type_hints(cls)
    return {f.name: hints[f.name] for f in dataclasses.fields(cls)}


def _element_type(annotation):
    """Return (is_tuple, scalar type) of a supported annotation."""
    if typing.get_origin(annotation) is tuple:
        args = typing.get_args(annotation)
        if len(args) != 2 or args[1] is not Ellipsis or args[0] not in (int, float):
            raise TypeError(f"unsupported parameter type {annotation!r}")
        return True, args[0]
    if annotation not in (int, float, bool, str):
        raise TypeError(f"unsupported parameter type {annotation!r}")
    return False, annotation


_TRUE = {"true", "yes", "1", "on"}
_FALSE = {"false", "no", "0", "off"}


def _convert_scalar(name, value, kind):
    expected = {int: "an integer", float: "a number", bool: "true or false", str: "a string"}[kind]
    if kind is bool:
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.strip().lower() in _TRUE | _FALSE:
            return value.strip().lower() in _TRUE
        raise ParameterError(f"parameter '{name}': expected {expected}, got {value!r}")
    if kind is str:
        if isinstance(value, str):
            return value
        raise ParameterError(f"parameter '{name}': expected {expected}, got {value!r}")
    if isinstance(value, (bool, bytes, bytearray)):
        raise ParameterError(f"parameter '{name}': expected {expected}, got {value!r}")
    try:
        if kind is int:
            if isinstance(value, float):
                if not value.is_integer():
                    raise ValueError
                return int(value)
            return int(str(value).strip()) if isinstance(value, str) else int(value)
        converted = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"parameter '{name}': expected {expected}, got {value!r}") from None
    if not math.isfinite(converted):
        raise ParameterError(f"parameter '{name}': expected a finite number, got {value!r}")
    return converted


def _check_bounds(name, value, meta):
    if meta["choices"] is not None and value not in meta["choices"]:
        allowed = ", ".join(repr(c) for c in meta["choices"])
        raise ParameterError(f"parameter '{name}': {value!r} is not allowed; expected one of {allowed}")
    if meta["minimum"] is not None and value < meta["minimum"]:
        raise ParameterError(f"parameter '{name}': expected a value >= {meta['minimum']}, got {value!r}")
    if meta["maximum"] is not None and value > meta["maximum"]:
        raise ParameterError(f"parameter '{name}': expected a value <= {meta['maximum']}, got {value!r}")
    if meta["exclusive_minimum"] is not None and value <= meta["exclusive_minimum"]:
        raise ParameterError(
            f"parameter '{name}': expected a value > {meta['exclusive_minimum']}, got {value!r}")


def _convert(name, value, annotation, meta):
    is_tuple, kind = _element_type(annotation)
    if not is_tuple:
        converted = _convert_scalar(name, value, kind)
        _check_bounds(name, converted, meta)
        return converted
    if isinstance(value, str):
        text = value.strip()
        if text[:1] + text[-1:] in ("[]", "()"):  # the YAML and Python forms: [1e3, 1e6]
            text = text[1:-1]
        items = [item for item in text.split(",") if item.strip()]
    elif isinstance(value, Iterable) and not isinstance(value, (bytes, bytearray)):
        items = list(value)
    else:
        items = [value]
    try:
        converted = tuple(_convert_scalar(name, item, kind) for item in items)
    except ParameterError as error:
        raise ParameterError(f"{error} (a list: comma-separated, e.g. {name}=1e3,1e6 or {name}=[1e3,1e6])") from None
    for item in converted:
        _check_bounds(name, item, meta)
    return converted


def parse_params(cls, values=None, *, owner=""):
    """Build a validated parameter instance from a mapping, filling defaults.

    Parameters
    ----------
    cls : type
        A parameter dataclass made with :func:`param` fields.
    values : Mapping[str, object], optional
        Values by field name; strings are converted to the field's type.
    owner : str, optional
        Name of the plugin, used in error messages (e.g. "solver 'fem'").

    Returns
    -------
    object
        An instance of ``cls``.

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the allowed names), a value of the
        wrong type or out of range (the message names the field and the expectation),
        or a failed ``check()``.
    """
    values = _renamed(cls, dict(values or {}), owner)
    types = _field_types(cls)
    unknown = sorted(set(values) - set(types))
    if unknown:
        where = f" of {owner}" if owner else ""
        raise ParameterError(
            f"unknown parameter{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))}{where}"
            f"{did_you_mean(unknown[0], types)}; allowed: {', '.join(types)}")
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name in values:
            kwargs[f.name] = _convert(f.name, values[f.name], types[f.name], f.metadata)
    instance = cls(**kwargs)
    check = getattr(instance, "check", None)
    if check is not None:
        check()
    return instance


def parse_value(cls, name, value, *, owner=""):
    """One parameter's value converted and checked as :func:`parse_params` checks it (without ``check()``).

    Parameters
    ----------
    cls : type
        A parameter dataclass.
    name : str
        One of its fields.
    value : object
        The value (a string is converted to the field's type).
    owner : str, optional
        The plugin, for messages.

    Returns
    -------
    object

    Raises
    ------
    ParameterError
        If ``cls`` has no such field, or the value does not fit it.
    """
    name = next(iter(_renamed(cls, {name: value}, owner)))
    types = _field_types(cls)
    if name not in types:
        where = f" of {owner}" if owner else ""
        raise ParameterError(f"unknown parameter {name!r}{where}{did_you_mean(name, types)}")
    field = next(f for f in dataclasses.fields(cls) if f.name == name)
    return _convert(name, value, types[name], field.metadata)


def parse_assignments(assignments):
    """Split ``KEY=VALUE`` strings into a mapping (values stay strings).

    Parameters
    ----------
    assignments : Iterable[str]

    Returns
    -------
    dict[str, str]

    Raises
    ------
    ParameterError
        If an item has no ``=`` or an empty key, or a key is given twice.
    """
    values = {}
    for item in assignments or ():
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ParameterError(f"expected KEY=VALUE, got {item!r}")
        if key in values:
            raise ParameterError(f"parameter '{key}' is given twice")
        values[key] = value.strip()
    return values


def did_you_mean(name, choices):
    """`` (did you mean 'x'?)`` for the choice closest to a misspelt ``name``; empty if none is close.

    Parameters
    ----------
    name : str
    choices : Iterable[str]

    Returns
    -------
    str
    """
    close = difflib.get_close_matches(name, list(choices), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def params_to_dict(instance, *, every=False):
    """Return the parameters as a JSON-safe dict (tuples become lists), in field order.

    Fields declared with ``extension=True`` are left out while they have their default; those
    declared with ``extension="<field>"`` while that field has its default too; ``every=True``: none is.
    """
    fields = {f.name: f for f in dataclasses.fields(instance)}

    def at_default(name):
        return getattr(instance, name) == fields[name].default

    def left_out(f):
        extension = f.metadata.get("extension")
        if not extension:
            return False
        return at_default(f.name) and (extension is True or at_default(extension))

    return {f.name: list(v) if isinstance(v := getattr(instance, f.name), tuple) else v
            for f in fields.values() if every or not left_out(f)}


_JSON_TYPES = {int: "integer", float: "number", bool: "boolean", str: "string"}


def json_schema(cls):
    """Return the JSON-Schema (as a dict) of a parameter dataclass, with defaults.

    Parameters
    ----------
    cls : type
        A parameter dataclass.

    Returns
    -------
    dict
        ``{"type": "object", "properties": ..., "additionalProperties": False}``.
    """
    properties = {}
    for f in dataclasses.fields(cls):
        annotation = _field_types(cls)[f.name]
        is_tuple, kind = _element_type(annotation)
        scalar = {"type": _JSON_TYPES[kind]}
        meta = f.metadata
        if meta.get("choices") is not None:
            scalar["enum"] = list(meta["choices"])
        for key in ("minimum", "maximum"):
            if meta.get(key) is not None:
                scalar[key] = meta[key]
        if meta.get("exclusive_minimum") is not None:
            scalar["exclusiveMinimum"] = meta["exclusive_minimum"]
        prop = {"type": "array", "items": scalar} if is_tuple else scalar
        prop["default"] = list(f.default) if is_tuple else f.default
        unit = f" [{meta['unit']}]" if meta.get("unit") else ""
        prop["description"] = meta.get("doc", "") + unit
        properties[f.name] = prop
    for old, new in getattr(cls, "RENAMED", {}).items():  # accepted, mapped by parse_params; no default to fill in
        properties[old] = {**{k: v for k, v in properties[new].items() if k != "default"}, "deprecated": True,
                           "description": f"the old name of {new}"}
    return {"type": "object", "properties": properties, "additionalProperties": False}


def describe(cls):
    """Return one row per parameter: (name, type, default, unit, doc).

    Parameters
    ----------
    cls : type
        A parameter dataclass.

    Returns
    -------
    list[tuple[str, str, object, str, str]]
    """
    rows = []
    for f in dataclasses.fields(cls):
        annotation = _field_types(cls)[f.name]
        type_name = getattr(annotation, "__name__", str(annotation))
        if typing.get_origin(annotation) is tuple:
            type_name = f"tuple[{typing.get_args(annotation)[0].__name__}]"
        doc = f.metadata.get("doc", "")
        choices = f.metadata.get("choices")
        if isinstance(choices, Mapping):
            listed = "; ".join(f"{name}: {entry.summary}" if getattr(entry, "summary", "") else name
                               for name, entry in choices.items())
            doc += f" (one of: {listed})"
        elif choices is not None:
            doc += f" (one of: {', '.join(map(str, choices))})"
        bounds = value_range(f.metadata)
        if bounds:
            doc += f" (range: {bounds})"
        rows.append((f.name, type_name, f.default, f.metadata.get("unit", ""), doc))
    return rows


def value_range(meta):
    """The bounds of a parameter (for a tuple: of every element) as text, e.g. ``> 0, <= 8``; "" if it has none.

    Parameters
    ----------
    meta : Mapping
        A field's metadata (:func:`param`).

    Returns
    -------
    str
    """
    bounds = [(">=", meta.get("minimum")), (">", meta.get("exclusive_minimum")), ("<=", meta.get("maximum"))]
    return ", ".join(f"{sign} {value if isinstance(value, int) else format(value, 'g')}" for sign, value in bounds
                     if value is not None)
