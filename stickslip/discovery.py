"""Finding the parts of the package that register themselves: every module of a package, every entry point of a group.

Plugins (:mod:`stickslip.registry`), interface laws (:mod:`stickslip.fem.laws`) and backends
(:mod:`stickslip.fem.backends`) register when their module is imported. The package imports every module of the
packages that hold them (:func:`import_modules`: a new module is found without an edit elsewhere) and every
module that another package names in an entry-point group (:func:`load_entry_points`, e.g. in its
``pyproject.toml``)::

    [project.entry-points."stickslip.fem.laws"]
    softening = "mypackage.softening"

This module imports nothing of the package.
"""

import importlib
import pkgutil
from importlib.metadata import entry_points

__all__ = ["PluginError", "import_modules", "load_entry_points"]


class PluginError(LookupError):
    """A plugin is malformed, registered twice, not found, or its entry point fails to load."""


def import_modules(package):
    """Import every module and sub-package directly inside ``package`` (in name order).

    Parameters
    ----------
    package : str
        Dotted name of a package, e.g. ``"stickslip.fem.laws"``.
    """
    for module in pkgutil.iter_modules(importlib.import_module(package).__path__):
        importlib.import_module(f"{package}.{module.name}")


def load_entry_points(group):
    """Import every module named in the entry-point group ``group`` of the installed distributions.

    Parameters
    ----------
    group : str
        E.g. ``"stickslip.fem.laws"``.

    Raises
    ------
    PluginError
        If one fails to import: naming the entry point, the group and the error (a broken third-party
        plugin must say so, not vanish).
    """
    for entry in entry_points(group=group):
        try:
            entry.load()
        except Exception as error:
            raise PluginError(f"entry point {entry.name!r} in group {group!r} failed to load: {error}") from error
