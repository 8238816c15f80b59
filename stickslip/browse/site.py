"""The pages of a study: written once from its database, records and files, then only read.

:func:`build_site` writes a static site (Jinja2 templates in ``templates/``, the script and style in ``static/``):

- ``index.html``: the study's figures, and its runs as a table that filters and sorts in the browser, each
  column headed by its name in the package's vocabulary and its unit (:mod:`stickslip.vocabulary`);
- ``runs/{run_id}.html``: one run's parameters with their units, its provenance record (code hash, commit,
  versions, host, times, its inputs and outputs with their sha256, each linked to the run that made it) and
  arithmetic, the runs that used it; for a simulation its increments plotted and its slip events;
- ``figures/{figure}.html``: the figure, its database row, code hash and commit, the runs and events it was drawn
  from (links), the command that rebuilds it and the Python that returns its data.

Everything comes from the study's read-only queries (:class:`stickslip.study_results.StudyResults`) and its files;
the site holds no form and no script that sends anything, and the pages load nothing from elsewhere.
"""

import dataclasses
import json
import math
import shutil
from importlib import resources
from pathlib import Path

import jinja2
import pandas as pd

from .. import registry
from ..h5io import FileFormatError
from ..provenance.query import RUN_COLUMNS
from ..provenance.record import read_record
from ..runs import open_run
from ..vocabulary import quantity

__all__ = ["build_site", "EVENT_COLUMNS", "Column"]

#: The columns of a run's slip events on its page (those the run has).
EVENT_COLUMNS = ("event", "interface", "multi", "slip", "dmu", "dmu_sig0", "time", "t", "increment", "T", "T_fe",
                 "dF", "B_a", "dgamma", "analysis_run_id")

#: Rows of a run's events shown on its page at most (the Python on the page returns them all).
MAX_EVENT_ROWS = 2000


class Column:
    """A table column's heading: its name, unit (None: unknown) and what it is (the vocabulary's doc)."""

    def __init__(self, name, unit=None, doc=""):
        found = quantity(name)
        self.name = name
        self.unit = unit if unit is not None else (found.unit if found is not None else None)
        self.doc = doc or (found.doc if found is not None else "")

    @property
    def heading(self):
        """``name [unit]``: the unit where there is one (``1``: a dimensionless number)."""
        return f"{self.name} [{self.unit}]" if self.unit else self.name


def _text(value):
    """A cell's text: floats to 6 significant digits, missing values empty, datetimes in UTC to the second."""
    if value is None or value is pd.NA or value is pd.NaT:
        return ""
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.6g}"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, pd.Timestamp):
        return value.strftime("%Y-%m-%d %H:%M:%S UTC")
    if isinstance(value, (list, dict)):
        return json.dumps(value)
    return str(value)


def _cells(frame, columns, links=None):
    """Rows of ``frame`` as cells ``{"text", "href"}``; ``links``: column -> function of the value -> href or None."""
    links = links or {}
    rows = []
    for record in frame[columns].itertuples(index=False, name=None):
        rows.append([{"text": _text(value), "href": links[name](value) if name in links and _text(value) else None}
                     for name, value in zip(columns, record)])
    return rows


def _run_link(known):
    return lambda run_id: f"../runs/{run_id}.html" if run_id in known else None


def _plugin_units(kind, plugin):
    """Parameter name -> (unit, doc) of a plugin's parameters; empty for one that is not installed."""
    try:
        declared = registry.get(kind, plugin).params
    except (registry.PluginError, KeyError):
        return {}
    return {f.name: (f.metadata.get("unit", ""), f.metadata.get("doc", "")) for f in dataclasses.fields(declared)}


def _plot_run(run, output):
    """Plot a simulation's increments (fem: the stack's stress against its strain; a recording: the lever's force and
    the slabs' positions against time) into ``output`` (PNG). Returns the caption."""
    from matplotlib.figure import Figure  # drawn without pyplot: no backend chosen, no window

    figure = Figure(figsize=(7, 3.2), dpi=90, layout="constrained")
    if run.format == "fem-run":
        increments = run.increments
        ax = figure.add_subplot()
        ax.plot(increments["epsd"], increments["sigd"], lw=0.8, color="#2c7fb8")
        kicks = increments[increments["kick"]]
        ax.plot(kicks["epsd"], kicks["sigd"], ".", ms=2, color="#e66101", label="events (kick and minimisation)")
        ax.set_xlabel("epsd [eps0]")
        ax.set_ylabel("sigd [sig0]")
        ax.legend(loc="lower right", fontsize=8)
        caption = (f"The stack's equivalent stress sigd against its strain epsd over the run's {len(increments)} "
                   "stored increments (run.increments); the events' increments in orange.")
    else:
        record = run.record
        force, positions = figure.subplots(1, 2)
        force.plot(record.t_F, record.F, lw=0.5, color="#2c7fb8")
        force.set_xlabel("time [s]")
        force.set_ylabel("F [N]")
        for column in range(record.x.shape[1]):
            positions.plot(record.t_x, record.x[:, column], lw=0.7, label=f"slab {column + 1}")
        positions.set_xlabel("time [s]")
        positions.set_ylabel("x [mm]")
        positions.legend(fontsize=7, ncols=2)
        caption = "The lever's force F and every slab's position x against time (run.record)."
    figure.savefig(output)
    return caption


def _record(study, row):
    """The provenance record of a runs row (read from its file; None where it is gone)."""
    path = Path(row["record_path"])
    path = path if path.is_absolute() else study.root.parent.parent / path
    try:
        return read_record(path)
    except FileFormatError:
        return None


class _Site:
    """What every page needs: the study's tables, read once."""

    def __init__(self, study):
        self.study = study
        self.runs = study.runs(wide=True)
        self.figures = study.figures()
        self.events = study.events()
        self.artifacts = study.sql("SELECT run_id, direction, role, path, sha256, bytes, format, made_by "
                                   "FROM artifacts ORDER BY run_id, direction, role, path")
        self.known = set(self.runs["run_id"])
        self.figure_of = dict(zip(self.figures["run_id"], self.figures["figure"]))
        environment = jinja2.Environment(loader=jinja2.PackageLoader("stickslip.browse", "templates"),
                                         autoescape=True, undefined=jinja2.StrictUndefined)
        self.templates = environment

    def render(self, template, output, **context):
        output.parent.mkdir(parents=True, exist_ok=True)
        output.write_text(self.templates.get_template(template).render(study=self.study.name, **context),
                          encoding="utf-8")

    def used_by(self, run_id):
        """The runs that read an output of ``run_id`` (analyses, figures)."""
        rows = self.artifacts[(self.artifacts["direction"] == "input") & (self.artifacts["made_by"] == run_id)]
        return sorted(set(rows["run_id"]))

    def files(self, run_id, direction):
        rows = self.artifacts[(self.artifacts["run_id"] == run_id) & (self.artifacts["direction"] == direction)]
        columns = ["role", "path", "format", "bytes", "sha256", "made_by"]
        return [Column(name) for name in columns], _cells(rows, columns, {"made_by": _run_link(self.known)})

    def python(self, *lines):
        return "\n".join(["import stickslip", f'study = stickslip.study("{self.study.name}")', *lines])


def _index(site, destination):
    columns = [name for name in RUN_COLUMNS if name in site.runs.columns]
    units = site.runs.attrs["units"]
    headings = [Column(name, units.get(name)) for name in columns]
    rows = _cells(site.runs, columns, {"run_id": lambda run_id: f"runs/{run_id}.html"})
    figures = [{"name": name, "href": f"figures/{name}.html", "png": f"figures/{name}.png"}
               for name in site.figures["figure"]]
    kinds = site.runs["kind"].value_counts().to_dict()
    site.render("index.html", destination / "index.html", headings=headings, rows=rows, figures=figures,
                kinds=kinds, database=str(site.study.database), root="")


def _parameters(row, record):
    params = record["params"] if record is not None else {}
    units = _plugin_units(row["kind"], row["plugin"])
    headings = [Column("name"), Column("value"), Column("unit"), Column("doc")]
    rows = [[{"text": name, "href": None}, {"text": _text(value), "href": None},
             {"text": units.get(name, ("", ""))[0], "href": None}, {"text": units.get(name, ("", ""))[1], "href": None}]
            for name, value in params.items()]
    return headings, rows


def _run_page(site, row, destination):
    run_id = row["run_id"]
    record = _record(site.study, row)
    page = {"run_id": run_id, "kind": row["kind"], "plugin": row["plugin"], "version": row["plugin_version"],
            "figure": site.figure_of.get(run_id)}
    parameters = _parameters(row, record)
    provenance = [(Column(name).heading, _text(row[name])) for name in
                  ("code_hash", "package_version", "git_commit", "git_dirty", "seed", "threads", "host",
                   "python_version", "numpy_version", "numba_version", "h5py_version", "started_at", "finished_at",
                   "wall_time_s", "peak_memory_mib", "record_path")]
    arithmetic = json.dumps(record.get("arithmetic"), indent=1, sort_keys=True) if record is not None else ""
    inputs, outputs = site.files(run_id, "input"), site.files(run_id, "output")
    users = [{"run_id": other, "href": f"{other}.html", "what": _what(site, other)} for other in site.used_by(run_id)]
    plot, events, python = None, None, site.python(f'runs = study.runs(run_id="{run_id}", wide=True)')
    if row["kind"] == "solver" and isinstance(row["path"], str):
        path = Path(row["path"])
        path = path if path.is_absolute() else site.study.root.parent.parent / path
        python = site.python(f'run = study.open_run("{run_id}")          # run.increments, run.header, run.params',
                             f'events = study.events(run_id="{run_id}")  # the slip events below')
        try:
            with open_run(path) as run:
                caption = _plot_run(run, destination / "runs" / f"{run_id}.png")
            plot = {"src": f"{run_id}.png", "caption": caption}
        except FileFormatError as error:
            plot = {"src": None, "caption": f"not plotted: {error}"}
        own = site.events[site.events["simulation_run_id"] == run_id]
        columns = [name for name in EVENT_COLUMNS if name in own.columns and own[name].notna().any()]
        units = site.events.attrs["units"]
        events = {"count": len(own), "shown": min(len(own), MAX_EVENT_ROWS),
                  "headings": [Column(name, units.get(name)) for name in columns],
                  "rows": _cells(own.head(MAX_EVENT_ROWS), columns, {"analysis_run_id": lambda other: f"{other}.html"})}
    site.render("run.html", destination / "runs" / f"{run_id}.html", page=page, parameters=parameters,
                provenance=provenance, arithmetic=arithmetic, inputs=inputs, outputs=outputs, users=users, plot=plot,
                events=events, python=python, root="../")


def _what(site, run_id):
    row = site.runs[site.runs["run_id"] == run_id].iloc[0]
    return f"{row['kind']} {row['plugin']}"


def _figure_page(site, row, destination, rebuild):
    name, run_id = row["figure"], row["run_id"]
    png = site.study.root.parent.parent / row["png"]
    image = None
    if png.is_file():
        shutil.copyfile(png, destination / "figures" / f"{name}.png")
        image = f"{name}.png"
    database = [(Column(column, site.figures.attrs["units"].get(column)).heading, _text(row[column]))
                for column in site.figures.columns]
    inputs = site.artifacts[(site.artifacts["run_id"] == run_id) & (site.artifacts["direction"] == "input")]
    simulations = sorted(set(inputs.loc[inputs["role"] == "simulation", "made_by"].dropna()))
    analyses = sorted(set(inputs.loc[inputs["role"] != "simulation", "made_by"].dropna()))
    counts = site.events.groupby("simulation_run_id").size().to_dict()

    def entries(ids):
        return [{"run_id": other, "href": f"../runs/{other}.html" if other in site.known else None,
                 "what": _what(site, other) if other in site.known else "not in the database",
                 "events": counts.get(other, 0)} for other in ids]

    ids = ", ".join(f'"{other}"' for other in simulations)
    python = site.python(f"runs = study.runs(run_id=[{ids}])", f"events = study.events(run_id=[{ids}])",
                         "simulations = list(study.open_runs(runs))  # each run's increments, states, ...")
    site.render("figure.html", destination / "figures" / f"{name}.html", name=name, run_id=run_id, image=image,
                database=database, simulations=entries(simulations), analyses=entries(analyses),
                rebuild=rebuild(name), python=python, root="../")


def build_site(study, destination, *, rebuild=None, progress=None):
    """Write the pages of a study into ``destination`` (made if missing; its old pages replaced).

    Parameters
    ----------
    study : stickslip.study_results.StudyResults
    destination : str or os.PathLike
    rebuild : Callable[[str], str], optional
        The command that redraws a figure, from its name; default: ``snakemake --cores 2 [--configfile FILE]
        --forcerun figure_<name>`` with the study's config.
    progress : Callable[[str], None], optional
        Receives a line per part written.

    Returns
    -------
    pathlib.Path
        ``destination / "index.html"``.
    """
    destination = Path(destination)
    for part in ("runs", "figures", "static"):
        shutil.rmtree(destination / part, ignore_errors=True)
        (destination / part).mkdir(parents=True)
    say = progress or (lambda line: None)
    site = _Site(study)
    if rebuild is None:
        config = ""
        if study.config_file is not None:
            config_file = Path(study.config_file)
            try:
                config_file = config_file.resolve().relative_to(study.workdir.path.resolve())
            except ValueError:
                pass
            config = f" --configfile {config_file.as_posix()}"
        rebuild = lambda name: f"snakemake --cores 2{config} --forcerun figure_{name.replace('-', '_').replace('@', '_')}"  # noqa: E731
    for name in ("browse.css", "browse.js"):
        (destination / "static" / name).write_bytes(resources.files("stickslip.browse").joinpath("static", name)
                                                    .read_bytes())
    _index(site, destination)
    say(f"index: {len(site.runs)} runs, {len(site.figures)} figures")
    for _, row in site.figures.iterrows():
        _figure_page(site, row, destination, rebuild)
    say(f"{len(site.figures)} figure pages")
    for index in range(len(site.runs)):
        _run_page(site, site.runs.iloc[index], destination)
    say(f"{len(site.runs)} run pages")
    return destination / "index.html"

