"""Code version of a plugin: a hash of the package sources it runs.

The workflow puts :func:`code_hash` of each plugin in the ``params`` of its
rule, so that Snakemake reruns exactly the jobs whose code changed: a change in
``stickslip/fem/`` reruns the ``fem`` simulations and what depends on them, not
the ``lever`` ones. The hash covers the plugin's module and every module of the
package that it imports, directly or through other package modules (found by
reading the import statements, without importing anything), plus the
``__init__.py`` of every package on the way (they run on import). The imports of the package's own
``stickslip/__init__.py`` are not followed (its file is hashed): it binds the public API
(:mod:`stickslip.api`) for notebooks and scripts, which no plugin runs, and following it would put
that API's modules (the analyses' readers, the database's queries) into every plugin's hash, so that
an edit of the event extraction would rerun the ``fem`` simulations.

Imports made by name at run time (``importlib.import_module("...")``) are not
seen; plugins do not use them. A third-party plugin (a module outside the
package) is hashed by its own source file.
"""

import ast
import hashlib
import importlib.util
from functools import lru_cache
from pathlib import Path

__all__ = ["module_sources", "code_hash"]

PACKAGE = "stickslip"
ROOT = Path(__file__).resolve().parent.parent


def _module_file(name):
    """Return the source file of package module ``name`` (dotted), or None if it is not one."""
    parts = name.split(".")
    if parts[0] != PACKAGE:
        return None
    base = ROOT.joinpath(*parts[1:])
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _package_inits(name):
    """Return the ``__init__.py`` files run when importing ``name``: its parent packages."""
    parts = name.split(".")
    files = []
    for depth in range(1, len(parts)):
        init = ROOT.joinpath(*parts[1:depth]) / "__init__.py"
        if init.is_file():
            files.append(init)
    return files


def _imported_names(path, name):
    """Return the dotted names of the modules that the source at ``path`` (module ``name``) imports."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    package = name if is_package else name.rpartition(".")[0]
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base_parts = package.split(".")
                base_parts = base_parts[:len(base_parts) - (node.level - 1)]
                base = ".".join(base_parts + ([node.module] if node.module else []))
            else:
                base = node.module
            names.append(base)
            # `from package import submodule` imports the submodule too.
            names.extend(f"{base}.{alias.name}" for alias in node.names)
    return names


@lru_cache(maxsize=None)
def module_sources(module):
    """Return the package source files that importing ``module`` runs.

    Parameters
    ----------
    module : str
        Dotted module name, e.g. ``"stickslip.solvers.lever"``; outside the
        package, only the module's own file is returned.

    Returns
    -------
    tuple[pathlib.Path, ...]
        Sorted absolute paths.

    Raises
    ------
    ValueError
        If ``module`` has no source file.
    """
    start = _module_file(module)
    if start is None:
        spec = importlib.util.find_spec(module)
        if spec is None or not spec.origin or not Path(spec.origin).is_file():
            raise ValueError(f"module {module!r} has no source file to hash")
        return (Path(spec.origin).resolve(),)
    seen = {}
    pending = [(module, start)]
    while pending:
        name, path = pending.pop()
        if path in seen:
            continue
        seen[path] = name
        for init in _package_inits(name):
            pending.append((init.parent.relative_to(ROOT.parent).as_posix().replace("/", "."), init))
        if path == ROOT / "__init__.py":
            continue  # the public API's imports: see the module's docstring
        for imported in _imported_names(path, name):
            source = _module_file(imported)
            if source is not None:
                pending.append((imported, source))
    return tuple(sorted(seen))


def code_hash(module):
    """Return a hash of the sources that importing ``module`` runs.

    Parameters
    ----------
    module : str
        Dotted module name inside the package.

    Returns
    -------
    str
        16 hexadecimal characters; it changes when any of :func:`module_sources`
        changes (content or file name).

    Notes
    -----
    Cost: parses each source once per process (the file list is cached); the
    sources are hashed again only when one of them changed (size or modification
    time), so the workflow, which asks once per job, hashes each plugin once.
    """
    sources = module_sources(module)
    stamp = tuple((path, path.stat().st_mtime_ns, path.stat().st_size) for path in sources)
    cached = _hashes.get(module)
    if cached is None or cached[0] != stamp:
        digest = hashlib.sha256()
        for path in sources:
            digest.update((path.relative_to(ROOT.parent).as_posix() if path.is_relative_to(ROOT) else path.name)
                          .encode())
            digest.update(b"\0")
            digest.update(path.read_bytes())
            digest.update(b"\0")
        cached = _hashes[module] = (stamp, digest.hexdigest()[:16])
    return cached[1]


#: code_hash by module: (the sources' paths, modification times and sizes, the hash).
_hashes = {}
