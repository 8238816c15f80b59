"""SI figure "Slow slip": R_i(t) of a stack of five with the frames detected as slips, the
smoothed velocities with the detection threshold, and the slow-slip fraction against n with the
shuffled-slab control."""

import dataclasses

import numpy as np

from .. import registry
from ..experiment import detection
from ..plugin_params import param
from .experimental_data import EVENTS, excerpt, load_interfaces, median_run
from .plotting import label_panels, legend_outside
from .experimental_panels import positions_panel, slow_slip_fraction_panel
from .style import interface_color, plt, save_figure

VERSION = "2"  # 2: the run with the median R_slow; error bars = standard errors; the shuffled control


@dataclasses.dataclass(frozen=True)
class FigsSlowSlipParams:
    """The runs and excerpt of panels (a) and (b)."""

    n_example: int = param(5, "driven slabs of the runs among which panels (a), (b) show the one with the median "
                              "R_slow of a_example", minimum=1)
    a_example: int = param(2, "interface whose R_slow chooses the run of panels (a), (b)", minimum=1)
    t_from: float = param(5400.0, "start of the excerpt (the run's last stretch if it is shorter)", unit="s",
                          minimum=0)
    duration: float = param(300.0, "length of the excerpt", unit="s", exclusive_minimum=0)


def _slip_frames(slips, n_frames, a):
    """Frames of interface ``a`` inside a detected slip bracket, as a boolean mask [n_frames]."""
    inside = np.zeros(n_frames, dtype=bool)
    for first, last in slips.loc[slips["a"] == a, ["i_start", "i_end"]].itertuples(index=False):
        inside[first:last + 1] = True
    return inside


def draw(params, inputs):
    """The figure (not saved): what :func:`run` writes; the tests read its plotted data."""
    events = inputs[EVENTS]
    interfaces = load_interfaces(events)
    record, _, R_slow, (rank, count) = median_run(interfaces, events, n=params.n_example, a=params.a_example)
    t_range = excerpt(record, params.t_from, params.duration)
    # Detection re-run on the record (same defaults as the analysis) to mark frames and velocities.
    slips = detection.detect_slips(record.t_x, record.R)
    velocity = detection.running_average(detection.frame_velocity(record.t_x, record.R))
    t_velocity = 0.5 * (record.t_x[1:] + record.t_x[:-1])
    fig, axes = plt.subplots(1, 3, figsize=(11.5, 3.3), layout="constrained")
    positions_panel(axes[0], record, range(1, record.n + 1), t_range)
    window = (record.t_x >= t_range[0]) & (record.t_x <= t_range[1])
    R = record.R[window]
    for a in range(1, record.n + 1):
        marked = _slip_frames(slips, record.t_x.size, a)[window]
        axes[0].plot(record.t_x[window][marked], R[marked, a - 1] - R[0, a - 1], linestyle="none", marker=".",
                     markersize=2.5, color="black")
    axes[0].plot([], [], linestyle="none", marker=".", color="black", label="slip frames")
    axes[0].text(0.02, 0.97, f"$n = {record.n}$, median $R_\\mathrm{{slow}}$ of $a = {params.a_example}$: "
                 f"{R_slow:.3f}\n({rank} of {count} runs)", transform=axes[0].transAxes, ha="left", va="top",
                 fontsize=6.5)
    legend_outside(axes[0])
    shown = (t_velocity >= t_range[0]) & (t_velocity <= t_range[1])
    for a in range(1, record.n + 1):
        axes[1].plot(t_velocity[shown], velocity[shown, a - 1], color=interface_color(a), linewidth=0.6,
                     label=f"$i = {a}$")
    axes[1].axhline(detection.VELOCITY_THRESHOLD, color="black", linestyle="--", linewidth=0.8,
                    label=f"{detection.VELOCITY_THRESHOLD} mm/s")
    axes[1].set_ylim(-detection.VELOCITY_THRESHOLD, 5 * detection.VELOCITY_THRESHOLD)  # slips leave the top
    axes[1].set_xlabel("$t$ (s)")
    axes[1].set_ylabel(r"$\dot R_i$, 5-frame average (mm/s)")
    legend_outside(axes[1])
    every = load_interfaces(events, shuffled=True)
    slow_slip_fraction_panel(axes[2], interfaces, every[every["shuffled"].to_numpy(dtype=bool)])
    legend_outside(axes[2])
    label_panels(axes)
    return fig


@registry.register("figure", "figS-slow-slip", VERSION, FigsSlowSlipParams, inputs=(EVENTS,),
                   summary="SI slow slip: (a) R_i(t) with the frames detected as slips and (b) smoothed velocities "
                           "with the threshold, of the stack run of n_example with the median R_slow of a_example; "
                           "(c) R_slow against n, mean over the runs, error bars: standard error of that mean over "
                           "the runs (seeds); open markers at n + 0.3: the slabs shuffled (the paper's control)")
def run(params, inputs, output):
    """SI slow slip: R_i(t) with detected slip frames, smoothed velocities and threshold, R_slow vs n."""
    save_figure(draw(params, inputs), output)
