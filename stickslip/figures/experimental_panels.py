"""Panels that several experimental figures draw: distributions per ``n``, the aging plot, the
slow-slip fraction and position time series.

Every function draws on a given :class:`matplotlib.axes.Axes` and sets its labels; colours follow
:func:`stickslip.figures.style.interface_color` for interfaces and
:func:`stickslip.figures.style.n_color` for ``n``; the interface driven alone is black.
"""

import numpy as np
import pandas as pd
from matplotlib.ticker import NullFormatter

from ..experiment import aging, kinematics
from .plotting import a_style, hollow, individual_style, n_style, plot_against_n, plot_density
from .style import interface_color

__all__ = ["LABELS", "single_slips", "distributions_by_n", "aging_panel",
           "disorder_law_lines", "slow_slip_fraction_panel", "positions_panel"]

#: Axis labels of the slip quantities (with units).
LABELS = {"dF": r"$\Delta F$ (N)", "dmu": r"$\Delta\mu_a$", "T": r"$T_a$ (s)", "B_a": r"$B_a$",
          "slip": r"$\Delta R_a$ (mm)", "slip_from_dF": r"$\Delta R_a(\Delta F)$ (mm)"}


def single_slips(slips, protocol=None):
    """The slips of single-interface events (``multi`` False), optionally of one protocol."""
    keep = ~slips["multi"].to_numpy(dtype=bool)
    if protocol is not None:
        keep &= (slips["protocol"] == protocol).to_numpy()
    return slips[keep]


def distributions_by_n(ax, slips, a, column, edges, *, individual=True, logarithmic=False):
    """``P(column)`` of the single slips of interface ``a``: one line per ``n`` (``gid`` "n=<n>"), the
    interface driven alone in black (``gid`` "reference"; every seed's slips pooled).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    slips : pandas.DataFrame
        Slips of all runs (:func:`~stickslip.figures.experimental_data.load_slips`).
    a : int
        Interface.
    column : str
        Quantity (a key of :data:`LABELS`).
    edges : numpy.ndarray
        Bin edges (in units of ``column``).
    individual : bool
        Also draw the individual-protocol slips of ``a``.
    logarithmic : bool
        Show the density of ``log10(column)`` on a logarithmic axis (for quantities spread over
        decades, such as ``T_a``; ``edges`` then logarithmic).
    """
    single = single_slips(slips)
    groups = [(stack_n, n_style(stack_n), {"gid": f"n={stack_n}"}) for stack_n in
              sorted(single.loc[(single["protocol"] == "stack") & (single["interface"] == a), "n"].unique())]
    if individual:
        groups.append((None, individual_style(), {"linestyle": "--", "gid": "reference"}))
    for n, style, extra in groups:
        part = single[(single["interface"] == a) & ((single["protocol"] == "individual") if n is None
                                            else (single["protocol"] == "stack") & (single["n"] == n))]
        plot_density(ax, part[column], edges, logarithmic=logarithmic, **style, **extra)
    name = LABELS[column].split(" (")[0]
    ax.set_xlabel(LABELS[column])
    if logarithmic:
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_ylabel(f"$P(\\log_{{10}} {name.strip('$')})$")
    else:
        ax.set_ylabel(f"$P$({name})")


def aging_panel(ax, slips, *, color_by="interface", t0=aging.T0, fit=True):
    """``dmu_a`` against ``T_a`` (semi-logarithmic), with log-binned means and the aging fit.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    slips : pandas.DataFrame
        Slips to show (single slips with a waiting time are used).
    color_by : {"interface", "n"}
        Colour by interface (marker by ``n``) or by ``n`` (marker by interface).
    t0 : float
        Aging time scale [s].
    fit : bool
        Draw the binned means (black, error bar = standard deviation), the paper's fit through the
        origin (dotted) and the fit with a free intercept ``c`` (dashed, if there are three bins).

    Returns
    -------
    stickslip.experiment.aging.AgingFit or None
        The fit through the origin.
    """
    data = single_slips(slips)
    data = data[np.isfinite(data["T"].to_numpy(dtype=float)) & np.isfinite(data["dmu"].to_numpy(dtype=float))]
    other = "n" if color_by == "interface" else "interface"
    for key in sorted(data[color_by].unique()):
        for second in sorted(data[other].unique()):
            part = data[(data[color_by] == key) & (data[other] == second)]
            if part.empty:
                continue
            colour = (a_style if color_by == "interface" else n_style)(key)["color"]
            marker = (n_style if color_by == "interface" else a_style)(second)["marker"]
            ax.plot(part["T"], part["dmu"], linestyle="none", marker=marker, markersize=2.5, alpha=0.35,
                    color=colour, markeredgewidth=0)
    # Legend proxies: colours, then markers.
    for key in sorted(data[color_by].unique()):
        style = (a_style if color_by == "interface" else n_style)(key)
        ax.plot([], [], linestyle="none", marker="o", color=style["color"], label=style["label"], markersize=4)
    for second in sorted(data[other].unique()):
        style = (n_style if color_by == "interface" else a_style)(second)
        ax.plot([], [], linestyle="none", marker=style["marker"], color="grey", label=style["label"], markersize=4)
    ax.set_xscale("log")
    ax.set_xlabel(LABELS["T"])
    ax.set_ylabel(LABELS["dmu"])
    if not fit or data.empty:
        return None
    try:
        result = aging.fit_aging(data["T"], data["dmu"], t0=t0)
    except ValueError:
        return None
    bins = result.bins
    ax.errorbar(bins["T"], bins["dmu_mean"], yerr=bins["dmu_std"], color="black", marker="s", markersize=4,
                linestyle="none", capsize=2, zorder=5)
    T = np.logspace(np.log10(max(t0, bins["T_low"].min())), np.log10(bins["T_high"].max()), 50)
    ax.plot(T, result(T, t0), color="black", linestyle=":", zorder=6,
            label=rf"$B = {result.B:.3f} \pm {result.B_error:.3f}$")
    try:
        free = aging.fit_aging(data["T"], data["dmu"], t0=t0, fit="intercept")
    except ValueError:
        return result
    ax.plot(T, free(T, t0), color="black", linestyle="--", linewidth=0.8, zorder=6,
            label=rf"$B = {free.B:.3f} \pm {free.B_error:.3f}$, $c = {free.c:.3f} \pm {free.c_error:.3f}$")
    return result


def disorder_law_lines(ax, slips, T_range):
    """Disorder law of the individual protocol, ``dmu_a = (d mu_a/dt) T_a``, one line per run
    constants (black, solid); runs with equal loading rates share a line."""
    alone = slips[slips["protocol"] == "individual"]
    rates = {round(float(kinematics.mu_loading_rate(a, 1, "individual", k_spring=K, h=h, H=H, V=V,
                                                    normal_force=N)), 12)
             for a, K, h, H, V, N in alone[["interface", "k_spring", "h", "H", "V", "normal_force"]].drop_duplicates()
             .itertuples(index=False)}
    T = np.linspace(*T_range, 50)
    for index, rate in enumerate(sorted(rates)):
        ax.plot(T, rate * T, color="black", linewidth=1.2,
                label=r"$\Delta\mu_a = K T_a h \dot\gamma / N$" if index == 0 else None)


def slow_slip_fraction_panel(ax, interfaces, shuffled=None):
    """``R_slow`` against ``n`` per interface: mean over the runs, error bars = standard error of that
    mean (over the runs: the seeds), lines only between neighbouring ``n``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    interfaces : pandas.DataFrame
        :func:`~stickslip.figures.experimental_data.load_interfaces` of the stack runs in order.
    shuffled : pandas.DataFrame, optional
        The same of runs with the slabs shuffled (the paper's control): drawn open at ``n + 0.3``
        (``gid`` "shuffled"), per interface (position), with their slab order in the legend.

    Returns
    -------
    pandas.DataFrame
        What is drawn: ``a``, ``n``, ``mean``, ``sem``, ``runs``, ``shuffled``.
    """
    drawn = []
    for table, is_shuffled in ((interfaces, False), (shuffled, True)):
        if table is None or table.empty:
            continue
        stack = table[(table["protocol"] == "stack") & table["driven"].to_numpy(dtype=bool)]
        for a, part in stack.groupby("interface"):
            summary = part.groupby("n")["R_slow"].agg(mean="mean", sem="sem", runs="size").reset_index()
            drawn.append(summary.assign(a=a, shuffled=is_shuffled))
            style = a_style(a)
            if is_shuffled:
                ax.errorbar(summary["n"] + 0.3, summary["mean"], yerr=summary["sem"].fillna(0.0), linestyle="none",
                            capsize=2, gid="shuffled", **{**hollow(style, 5.0), "label": None})
            else:
                plot_against_n(ax, summary["n"] + 0.06 * (a - 3), summary["mean"], summary["sem"].fillna(0.0),
                               markersize=4, **style)
        if is_shuffled:
            orders = sorted(stack["slab_order"].unique())
            ax.plot([], [], linestyle="none", **{**hollow({"color": "grey", "marker": "o"}, 5.0),
                                                  "label": f"shuffled ({'; '.join(orders)}), at $n + 0.3$"})
    ax.axhline(0.0, color="grey", linewidth=0.5)
    ax.set_xlabel("$n$")
    ax.set_ylabel(r"$R_\mathrm{slow}$")
    ax.set_xticks(sorted(interfaces["n"].unique()))
    columns = ["a", "n", "mean", "sem", "runs", "shuffled"]
    return pd.concat(drawn, ignore_index=True)[columns] if drawn else pd.DataFrame(columns=columns)


def positions_panel(ax, record, interfaces, t_range):
    """``R_i(t) - R_i(t_0)`` of the interfaces ``interfaces`` over ``t_range`` (``t_0`` its start).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    record : stickslip.experiment.timeseries.ExperimentRecord
    interfaces : iterable of int
    t_range : tuple of float
        ``(t_0, t_1)`` [s].
    """
    window = (record.t_x >= t_range[0]) & (record.t_x <= t_range[1])
    R = record.R[window]
    for i in interfaces:
        ax.plot(record.t_x[window], R[:, i - 1] - R[0, i - 1], color=interface_color(i), linewidth=1.0,
                label=f"$i = {i}$")
    ax.set_xlabel("$t$ (s)")
    ax.set_ylabel(r"$R_i(t) - R_i(t_0)$ (mm)")
