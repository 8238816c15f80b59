"""SI figure "Slow slip": R_i(t) of a stack of five with the frames detected as slips, the
smoothed velocities with the detection threshold, and the slow-slip fraction against n."""

import dataclasses

import numpy as np

from .. import registry
from ..experiment import detection
from ..params import param
from .experimental_data import EVENTS, example_run, excerpt, load_interfaces, load_slips
from .plotting import label_panels
from .experimental_panels import positions_panel, slow_slip_fraction_panel
from .style import interface_color, plt, save_figure

VERSION = "1"


@dataclasses.dataclass(frozen=True)
class FigsSlowSlipParams:
    """The run and excerpt of panels (a) and (b)."""

    n_example: int = param(5, "driven slabs of the run shown in panels (a) and (b)", minimum=1)
    t_from: float = param(5400.0, "start of the excerpt (the run's last stretch if it is shorter)", unit="s",
                          minimum=0)
    duration: float = param(300.0, "length of the excerpt", unit="s", exclusive_minimum=0)


def _slip_frames(slips, n_frames, a):
    """Frames of interface ``a`` inside a detected slip bracket, as a boolean mask [n_frames]."""
    inside = np.zeros(n_frames, dtype=bool)
    for first, last in slips.loc[slips["a"] == a, ["i_start", "i_end"]].itertuples(index=False):
        inside[first:last + 1] = True
    return inside


@registry.register("figure", "figS-slow-slip", VERSION, FigsSlowSlipParams, inputs=(EVENTS,))
def run(params, inputs, output):
    """SI slow slip: R_i(t) with detected slip frames, smoothed velocities and threshold, R_slow vs n."""
    record, _ = example_run(load_slips(inputs[EVENTS]), inputs[EVENTS], n=params.n_example)
    t_range = excerpt(record, params.t_from, params.duration)
    # Detection re-run on the record (same defaults as the analysis) to mark frames and velocities.
    slips = detection.detect_slips(record.t_x, record.R)
    velocity = detection.running_average(detection.frame_velocity(record.t_x, record.R))
    t_velocity = 0.5 * (record.t_x[1:] + record.t_x[:-1])
    fig, axes = plt.subplots(1, 3, figsize=(10.5, 3.3), layout="constrained")
    positions_panel(axes[0], record, range(1, record.n + 1), t_range)
    window = (record.t_x >= t_range[0]) & (record.t_x <= t_range[1])
    R = record.R[window]
    for a in range(1, record.n + 1):
        marked = _slip_frames(slips, record.t_x.size, a)[window]
        axes[0].plot(record.t_x[window][marked], R[marked, a - 1] - R[0, a - 1], linestyle="none", marker=".",
                     markersize=2.5, color="black")
    axes[0].plot([], [], linestyle="none", marker=".", color="black", label="slip frames")
    axes[0].legend(fontsize=6.5, frameon=False, loc="upper left")
    shown = (t_velocity >= t_range[0]) & (t_velocity <= t_range[1])
    for a in range(1, record.n + 1):
        axes[1].plot(t_velocity[shown], velocity[shown, a - 1], color=interface_color(a), linewidth=0.6,
                     label=f"$i = {a}$")
    axes[1].axhline(detection.VELOCITY_THRESHOLD, color="black", linestyle="--", linewidth=0.8,
                    label=f"{detection.VELOCITY_THRESHOLD} mm/s")
    axes[1].set_ylim(-detection.VELOCITY_THRESHOLD, 5 * detection.VELOCITY_THRESHOLD)  # slips leave the top
    axes[1].set_xlabel("$t$ (s)")
    axes[1].set_ylabel(r"$\dot R_i$, 5-frame average (mm/s)")
    axes[1].legend(fontsize=6.5, frameon=False, loc="upper left", ncol=2)
    slow_slip_fraction_panel(axes[2], load_interfaces(inputs[EVENTS]))
    axes[2].legend(fontsize=6.5, frameon=False)
    label_panels(axes)
    save_figure(fig, output)
