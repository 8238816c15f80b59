"""Fig. 6: P(B_a) of interface 1 for every n, the spread of B_a against n, an example of slow
slip, and the slow-slip fraction R_slow against n."""

import dataclasses

import numpy as np

from .. import registry
from ..experiment.aging import spread_of_aging_rate
from ..params import param
from .experimental_data import EVENTS, example_run, load_interfaces, load_slips
from .plotting import a_style, label_panels, linear_edges
from .experimental_panels import distributions_by_n, single_slips, slow_slip_fraction_panel
from .style import interface_color, plt, save_figure

VERSION = "1"


@dataclasses.dataclass(frozen=True)
class Fig6Params:
    """The run and interface of the slow-slip example (panel c), and the binning of P(B_a)."""

    n_example: int = param(5, "driven slabs of the run shown in panel (c)", minimum=1)
    a_example: int = param(2, "interface shown in panel (c)", minimum=1)
    duration: float = param(600.0, "length of the excerpt of panel (c), at the end of the run", unit="s",
                            exclusive_minimum=0)
    bins: int = param(25, "bins of P(B_a)", minimum=2)


def spread_panel(ax, slips):
    """std(B_a) per interface against n, normalised by the interface driven alone."""
    table = spread_of_aging_rate(slips)
    for a, part in table.groupby("a"):
        part = part[np.isfinite(part["std_normalised"])]
        if len(part) > 1:
            ax.plot(part["n"], part["std_normalised"], markersize=4, **a_style(a))
    ax.axhline(1.0, color="grey", linewidth=0.5)
    ax.set_xlabel("$n$")
    ax.set_ylabel(r"$\mathrm{std}(B_a) / \mathrm{std}(B_a)_{n=1}$")
    ax.set_xticks(sorted(table["n"].unique()))
    ax.legend(fontsize=6.5, frameon=False)


def slow_slip_example(ax, record, slips, a, duration):
    """R_a(t) - R_a(t_0) over the last ``duration`` of a run, with the part done by detected slips.

    The measured position (colour of ``a``) and the cumulated detected slips (black steps): the gap
    between them is slow slip.
    """
    t_from = max(record.t_x[0], record.t_x[-1] - duration)
    window = record.t_x >= t_from
    R = record.R[window, a - 1]
    t = record.t_x[window]
    ax.plot(t, R - R[0], color=interface_color(a), linewidth=1.0, label=rf"$R_{a}(t) - R_{a}(t_0)$")
    own = slips[(slips["a"] == a) & (slips["t_start"] >= t_from)]
    steps = np.concatenate([[0.0], np.cumsum(own["dR"].to_numpy())])
    times = np.concatenate([[t_from], own["t"].to_numpy(), [t[-1]]])
    ax.step(times, np.append(steps, steps[-1]), where="post", color="black", linewidth=0.8,
            label=r"$\sum \Delta R_a$ (slip events)")
    total = R[-1] - R[0]
    ax.annotate("", xy=(t[-1], total), xytext=(t[-1], 0.0),
                arrowprops={"arrowstyle": "<->", "color": "grey", "linewidth": 0.8})
    ax.text(t[-1], total / 2, r" $R_\mathrm{tot}$", va="center", ha="left", fontsize=7, color="grey")
    ax.set_xlabel("$t$ (s)")
    ax.set_ylabel(rf"$R_{a}(t) - R_{a}(t_0)$ (mm)")
    ax.text(0.03, 0.97, f"$n = {record.n}$, $a = {a}$", transform=ax.transAxes, ha="left", va="top", fontsize=8)
    ax.legend(fontsize=6.5, frameon=False, loc="lower right")


@registry.register("figure", "fig6", VERSION, Fig6Params, inputs=(EVENTS,))
def run(params, inputs, output):
    """Fig. 6: P(B_a) for a = 1, std(B_a) vs n, slow-slip example, R_slow vs n."""
    slips = load_slips(inputs[EVENTS])
    record, run_slips = example_run(slips, inputs[EVENTS], n=params.n_example)
    fig, axes = plt.subplots(2, 2, figsize=(7.0, 5.4), layout="constrained")
    one = single_slips(slips, "stack")
    edges = linear_edges(one.loc[one["a"] == 1, "B_a"], params.bins)
    distributions_by_n(axes[0, 0], slips, 1, "B_a", edges, individual=False)
    axes[0, 0].legend(fontsize=6.5, title="$a = 1$", title_fontsize=6.5, frameon=False)
    spread_panel(axes[0, 1], slips)
    slow_slip_example(axes[1, 0], record, run_slips, params.a_example, params.duration)
    slow_slip_fraction_panel(axes[1, 1], load_interfaces(inputs[EVENTS]))
    axes[1, 1].legend(fontsize=6.5, frameon=False)
    label_panels(axes)
    save_figure(fig, output)
