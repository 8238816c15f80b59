"""Fig. 6: P(B_a) of interface 1 for every n, the spread of B_a against n, an example of slow
slip, and the slow-slip fraction R_slow against n."""

import dataclasses

import numpy as np

from .. import registry
from ..experiment.aging import spread_of_aging_rate
from ..plugin_params import param
from .experimental_data import EVENTS, load_interfaces, load_slips, median_run
from .plotting import a_style, label_panels, legend_outside, linear_edges, plot_against_n
from .experimental_panels import distributions_by_n, single_slips, slow_slip_fraction_panel
from .style import interface_color, plt, save_figure

VERSION = "2"  # 2: (c) the run with the median R_slow; error bars = standard errors over the seeds


@dataclasses.dataclass(frozen=True)
class Fig6Params:
    """The stack and interface of the slow-slip example (panel c), and the binning of P(B_a)."""

    n_example: int = param(5, "driven slabs of the runs among which panel (c) shows the one with the median R_slow",
                           minimum=1)
    a_example: int = param(2, "interface shown in panel (c)", minimum=1)
    duration: float = param(600.0, "length of the excerpt of panel (c), at the end of the run", unit="s",
                            exclusive_minimum=0)
    bins: int = param(25, "bins of P(B_a)", minimum=2)


def spread_panel(ax, slips):
    """std(B_a) per interface against n, normalised by the interface driven alone (n = 1, every seed's
    slips pooled); error bars: jackknife standard error over the seeds; lines only between neighbouring n.

    Returns
    -------
    pandas.DataFrame
        :func:`~stickslip.experiment.aging.spread_of_aging_rate`, what is drawn.
    """
    table = spread_of_aging_rate(slips)
    for a, part in table.groupby("interface"):
        part = part[np.isfinite(part["std_normalised"])]
        if len(part) > 1:
            errors = part["std_normalised_error"].to_numpy(dtype=float)
            plot_against_n(ax, part["n"], part["std_normalised"], None if np.isnan(errors).all() else
                           np.nan_to_num(errors), markersize=4, **a_style(a))
    ax.axhline(1.0, color="grey", linewidth=0.5)
    ax.set_xlabel("$n$")
    ax.set_ylabel(r"$\mathrm{std}(B_a) / \mathrm{std}(B_a)_{n=1}$")
    ax.set_xticks(sorted(table["n"].unique()))
    legend_outside(ax)
    return table


def slow_slip_example(ax, record, slips, a, duration, note):
    """R_a(t) - R_a(t_0) over the last ``duration`` of a run, with the part done by detected slips.

    The measured position (colour of ``a``) and the cumulated detected slips (black steps): the gap
    between them is slow slip. ``note`` says which run this is (written in the panel).
    """
    t_from = max(record.t_x[0], record.t_x[-1] - duration)
    window = record.t_x >= t_from
    R = record.R[window, a - 1]
    t = record.t_x[window]
    ax.plot(t, R - R[0], color=interface_color(a), linewidth=1.0, label=rf"$R_{a}(t) - R_{a}(t_0)$")
    own = slips[(slips["interface"] == a) & (slips["t_start"] >= t_from)]
    steps = np.concatenate([[0.0], np.cumsum(own["slip"].to_numpy())])
    times = np.concatenate([[t_from], own["time"].to_numpy(), [t[-1]]])
    ax.step(times, np.append(steps, steps[-1]), where="post", color="black", linewidth=0.8,
            label=r"$\sum \Delta R_a$ (slip events)")
    total = R[-1] - R[0]
    ax.annotate("", xy=(t[-1], total), xytext=(t[-1], 0.0),
                arrowprops={"arrowstyle": "<->", "color": "grey", "linewidth": 0.8})
    ax.text(t[-1], total / 2, r" $R_\mathrm{tot}$", va="center", ha="left", fontsize=7, color="grey")
    ax.set_xlabel("$t$ (s)")
    ax.set_ylabel(rf"$R_{a}(t) - R_{a}(t_0)$ (mm)")
    ax.text(0.02, 0.97, note, transform=ax.transAxes, ha="left", va="top", fontsize=6.5)
    legend_outside(ax)


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    events = inputs[EVENTS]
    slips = load_slips(events)
    interfaces = load_interfaces(events)
    record, chosen, R_slow, (rank, count) = median_run(interfaces, events, n=params.n_example, a=params.a_example)
    run_slips = slips[slips["file"] == chosen]
    fig, axes = plt.subplots(2, 2, figsize=(8.0, 5.4), layout="constrained")
    one = single_slips(slips, "stack")
    edges = linear_edges(one.loc[one["interface"] == 1, "B_a"], params.bins)
    distributions_by_n(axes[0, 0], slips, 1, "B_a", edges, individual=False)
    legend_outside(axes[0, 0], title="$a = 1$")
    spread_panel(axes[0, 1], slips)
    seed = run_slips["seed"].iloc[0] if "seed" in run_slips.columns and len(run_slips) else None
    note = (f"$n = {params.n_example}$, median $R_\\mathrm{{slow}}$ of $a = {params.a_example}$: "
            f"{R_slow:.3f}\n({rank} of {count} runs" + (f", seed {seed})" if seed is not None else ")"))
    slow_slip_example(axes[1, 0], record, run_slips, params.a_example, params.duration, note)
    slow_slip_fraction_panel(axes[1, 1], interfaces)
    legend_outside(axes[1, 1])
    label_panels(axes)
    return fig


@registry.register("figure", "fig6", VERSION, Fig6Params, inputs=(EVENTS,),
                   summary="Fig. 6: (a) P(B_a) for a = 1 and every n; (b) std(B_a) against n, normalised by the "
                           "interface driven alone (every seed pooled), error bars: jackknife standard error over "
                           "the seeds; (c) slow slip of interface a_example in the stack run of n_example with the "
                           "median R_slow of that interface (written in the panel); (d) R_slow against n, mean "
                           "over the runs, error bars: standard error of that mean over the runs (seeds)")
def run(params, inputs, output):
    """Fig. 6: P(B_a) for a = 1, std(B_a) vs n, slow-slip example (median run), R_slow vs n."""
    save_figure(draw(params, inputs), output)
