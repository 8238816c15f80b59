"""Code version of a job: a hash of the package sources that its result depends on.

The workflow puts the code hash of each job in the ``params`` of its rule, so that Snakemake's
params trigger reruns exactly the jobs whose code changed, and what depends on them
(docs/workflow.md, "What makes a job rerun"). The hash covers:

- the plugin's module and every module of the package that it imports, directly or through other
  package modules (found by reading the import statements, without importing anything), plus the
  ``__init__.py`` of every package on the way (they run on import). The imports of the package's
  own ``stickslip/__init__.py`` are not followed (its file is hashed): it binds the public API
  (:mod:`stickslip.api`) for notebooks and scripts, which no plugin runs, and following it would
  put that API's modules (the analyses' readers, the database's queries) into every plugin's
  hash, so that an edit of the event extraction would rerun the ``fem`` simulations;
- the parts that a solver's run chooses by name (its :class:`stickslip.registry.Choice` s: a
  ``fem`` run's interface law and backend), each with what it imports, and none of the parts it
  does not choose: an import of a part's module in an ``__init__.py`` (a package that re-exports
  or discovers its parts) is not followed, so a new law module, found by its package, changes no
  run's hash but the runs that choose it (:func:`plugin_code_hash`);
- of the package's vocabulary (:data:`ENTRY_TABLES`: ``QUANTITIES`` of ``stickslip/vocabulary.py``),
  the rest of its module and those entries whose name is a string in the code hashed (a column an
  analysis writes, ``"dmu_sig0"``; the database's ``_column("code_hash", ...)``): a new vocabulary
  entry changes the hash of the jobs whose code names it, and of no other.

A module of another package (a third-party plugin, law or backend) is followed the same way through
the modules of its own package and of this one; other libraries (numpy, ...) are not hashed. Imports
made by name at run time (``importlib.import_module("...")``) are not seen; plugins do not use them.
"""

import ast
import hashlib
import importlib.util
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType

__all__ = ["ENTRY_TABLES", "module_sources", "code_hash", "plugin_code_hash"]

PACKAGE = "stickslip"
ROOT = Path(__file__).resolve().parent.parent

#: Tables of named entries whose entries count only in the jobs that name them: source file (relative to the
#: package) -> the name of its module-level dict literal.
ENTRY_TABLES = {"vocabulary.py": "QUANTITIES"}


def _root(top):
    """The directory of the top-level package ``top`` (or the file of a top-level module), found without importing
    it; None if it has no source (a built-in, an extension module) or does not exist."""
    if top == PACKAGE:
        return ROOT
    spec = importlib.util.find_spec(top)
    if spec is None:
        return None
    if spec.submodule_search_locations:
        return Path(next(iter(spec.submodule_search_locations))).resolve()
    return Path(spec.origin).resolve() if spec.origin and Path(spec.origin).is_file() else None


def _module_file(name, roots):
    """Return the source file of module ``name`` (dotted) under ``roots`` (top-level name -> its :func:`_root`), or
    None if it is not one."""
    parts = name.split(".")
    root = roots.get(parts[0])
    if root is None or root.suffix == ".py":
        return root if root is not None and len(parts) == 1 else None
    base = root.joinpath(*parts[1:])
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _package_inits(name, roots):
    """Return the ``__init__.py`` files run when importing ``name``: its parent packages (with their names)."""
    parts = name.split(".")
    inits = []
    for depth in range(1, len(parts)):
        parent = ".".join(parts[:depth])
        init = _module_file(parent, roots)
        if init is not None and init.name == "__init__.py":
            inits.append((parent, init))
    return inits


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
def module_sources(module, parts=frozenset()):
    """Return the package source files that importing ``module`` runs.

    Parameters
    ----------
    module : str
        Dotted module name, e.g. ``"stickslip.solvers.lever"``, or of another package (then the modules
        of its package and of this one are followed).
    parts : frozenset[str], optional
        Modules of parts chosen by name (:class:`stickslip.registry.Choice`): an import of one of them in
        an ``__init__.py`` is not followed (module docstring).

    Returns
    -------
    Mapping[pathlib.Path, str]
        Absolute path -> dotted module name, sorted by path (read only).

    Raises
    ------
    ValueError
        If ``module`` has no source file.
    """
    roots = {top: _root(top) for top in {PACKAGE, module.partition(".")[0]}}
    start = _module_file(module, roots)
    if start is None:
        raise ValueError(f"module {module!r} has no source file to hash")
    seen = {}
    pending = [(module, start)]
    while pending:
        name, path = pending.pop()
        if path in seen:
            continue
        seen[path] = name
        pending.extend(_package_inits(name, roots))
        if path == ROOT / "__init__.py":
            continue  # the public API's imports: see the module's docstring
        for imported in _imported_names(path, name):
            source = _module_file(imported, roots)
            if source is not None and not (path.name == "__init__.py" and imported in parts):
                pending.append((imported, source))
    return MappingProxyType(dict(sorted(seen.items())))


def _stamp(path):
    status = path.stat()
    return path, status.st_mtime_ns, status.st_size


@lru_cache(maxsize=None)
def _strings(stamp):
    """The string constants of a source file (``stamp``: its path, modification time and size)."""
    path = stamp[0]
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return frozenset(node.value for node in ast.walk(tree) if isinstance(node, ast.Constant)
                     and isinstance(node.value, str))


def _entry_table_text(path, table, names):
    """The bytes of ``path`` hashed for a job that names ``names``: the dict literal ``table`` keeps those entries only.

    The text is the file with the dict literal cut out, then the source of each kept entry, in order.
    """
    data = path.read_bytes()
    tree = ast.parse(data, filename=str(path))
    literal = next(node.value for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))
                   and isinstance(node.value, ast.Dict)
                   and any(isinstance(t, ast.Name) and t.id == table
                           for t in (node.targets if isinstance(node, ast.Assign) else [node.target])))
    starts = [0]
    for line in data.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))

    def span(node):  # byte offsets: ast's column offsets count UTF-8 bytes
        return starts[node.lineno - 1] + node.col_offset, starts[node.end_lineno - 1] + node.end_col_offset

    begin, end = span(literal)
    kept = [data[span(key)[0]:span(value)[1]] for key, value in zip(literal.keys, literal.values)
            if isinstance(key, ast.Constant) and key.value in names]
    return data[:begin] + data[end:] + b"\0" + b"\n".join(kept)


def _digest(sources):
    """sha256 of the sources (path -> module name, by path), each by its module name and bytes (so that a copy of a
    package elsewhere hashes alike); an entry table by the entries that the others name."""
    tables = {ROOT / relative: table for relative, table in ENTRY_TABLES.items()}
    named = frozenset().union(*(_strings(_stamp(path)) for path in sources if path not in tables))
    digest = hashlib.sha256()
    for path in sorted(sources):
        digest.update((sources[path] + (".__init__" if path.name == "__init__.py" else "")).encode())
        digest.update(b"\0")
        digest.update(_entry_table_text(path, tables[path], named) if path in tables else path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()[:16]


def code_hash(modules, parts=frozenset()):
    """Return a hash of the sources that importing ``modules`` runs (module docstring).

    Parameters
    ----------
    modules : str or Iterable[str]
        Dotted module names (one or several).
    parts : frozenset[str], optional
        As :func:`module_sources`.

    Returns
    -------
    str
        16 hexadecimal characters; it changes when any of the sources changes (content or
        file name), an entry table (:data:`ENTRY_TABLES`) only where an entry the sources name changes.

    Notes
    -----
    Cost: parses each source once per process (the file lists are cached); the
    sources are hashed again only when one of them changed (size or modification
    time), so the workflow, which asks once per job, hashes each set of sources once.
    """
    modules = (modules,) if isinstance(modules, str) else tuple(modules)
    sources = {path: name for module in modules for path, name in module_sources(module, frozenset(parts)).items()}
    stamp = tuple(_stamp(path) for path in sorted(sources))
    cached = _hashes.get(stamp)
    if cached is None:
        cached = _hashes[stamp] = _digest(sources)
    return cached


def plugin_code_hash(plugin, params):
    """Return the code hash of one job of ``plugin`` with parameters ``params``.

    Parameters
    ----------
    plugin : stickslip.registry.Plugin
    params : object
        An instance of ``plugin.params``: it chooses the parts of ``plugin.choices``.

    Returns
    -------
    str
        :func:`code_hash` of the plugin's module and the modules of the parts it chooses, the parts it does not
        choose left out.
    """
    parts = frozenset().union(*(choice.modules() for choice in plugin.choices))
    return code_hash((plugin.module, *(choice.module(params) for choice in plugin.choices)), parts)


#: code_hash by the sources' paths, modification times and sizes.
_hashes = {}
