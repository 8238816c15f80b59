"""A third-party plugin set for the tests: a spring-block slider, registered through entry points.

A block on a frictional surface is pulled through a spring of stiffness ``k``
whose end moves at speed ``V``. It sticks until the spring force reaches the
static threshold of the current contact, ``F_s (1 + disorder u)`` with ``u``
uniform in [-1, 1] drawn from ``seed``; it then slides against the dynamic
friction ``F_d`` under Newton's law (velocity Verlet) until it stops. Without
damping and with the drive at rest, a slip is half an oscillation about the
dynamic equilibrium, of amplitude ``2 (F_threshold - F_d) / k``; the moving
drive adds a small correction, known in closed form (:func:`slip_amplitude`),
which the tests compare with the integrated slips.

Registered kinds: format ``toy-block`` (the solver's output), solver
``toy-spring-block``, analysis ``toy-slips`` (it produces the package's ``event-table``
format, so the results database ingests its slips with no edit), figure ``toy-force``. The test suite installs this module with a distribution whose
``entry_points.txt`` names it in the groups ``stickslip.solvers``,
``stickslip.analyses`` and ``stickslip.figures``.
"""

import dataclasses
import math

import numpy as np
import pandas as pd

from stickslip import formats, h5io
from stickslip.figures.style import plt, save_figure
from stickslip.formats.analysis_file import write_analysis_file
from stickslip.formats.event_table import read_slip_events, slip_events_table
from stickslip.plugin_params import param
from stickslip.registry import register

formats.register_format(formats.Format("toy-block", 1, __name__,
                                       "a spring-block history: t [s], x [mm], F [N]",
                                       source="numerical", describe=f"{__name__}:describe"))


def describe(path):
    """The database's simulation columns of a toy-block file: its seed."""
    with h5io.open_file(path) as file:
        formats.check(file, "toy-block")
        return {"seed": int(file.attrs["seed"])}


@dataclasses.dataclass(frozen=True)
class BlockParams:
    """Spring-block parameters (lab units: mm, N, s)."""

    k: float = param(1.0, "spring stiffness", unit="N/mm", exclusive_minimum=0)
    m: float = param(1e-3, "block mass", unit="N s^2/mm", exclusive_minimum=0)
    V: float = param(0.1, "drive speed", unit="mm/s", exclusive_minimum=0)
    F_s: float = param(1.0, "mean static friction threshold", unit="N", exclusive_minimum=0)
    F_d: float = param(0.6, "dynamic friction", unit="N", minimum=0)
    disorder: float = param(0.2, "relative spread of the static threshold", minimum=0, maximum=0.9)
    slips: int = param(8, "number of slips to simulate", minimum=1)
    steps_per_slip: int = param(2000, "time steps per slip", minimum=10)
    seed: int = param(0, "seed of the thresholds", minimum=0)

    def check(self):
        """The block must be able to stick after a slip: F_d below every threshold."""
        from stickslip.plugin_params import ParameterError

        if self.F_d >= self.F_s * (1 - self.disorder):
            raise ParameterError("parameter 'F_d': must be below F_s (1 - disorder)")


def thresholds(params):
    """Static thresholds of the successive contacts [N], shape (slips,)."""
    u = np.random.default_rng(params.seed).uniform(-1.0, 1.0, params.slips)
    return params.F_s * (1.0 + params.disorder * u)


def slip_amplitude(threshold, params):
    """Exact slip of the block [mm] when it starts at spring force ``threshold`` [N].

    In the frame of the drive, ``xi = V t - x`` oscillates about ``F_d / k`` with
    angular frequency ``w = sqrt(k / m)``, from ``xi = threshold / k`` at speed
    ``V``; the block stops at phase ``theta = 2 pi - 2 atan(A w / V)`` with
    ``A = (threshold - F_d) / k``, having slid
    ``V theta / w - A (cos theta - 1) - V sin(theta) / w``.
    """
    w = math.sqrt(params.k / params.m)
    A = (np.asarray(threshold) - params.F_d) / params.k
    theta = 2.0 * math.pi - 2.0 * np.arctan(A * w / params.V)
    return params.V * theta / w - A * (np.cos(theta) - 1.0) - params.V * np.sin(theta) / w


def simulate(params):
    """Return the sampled history: time [s], block position x [mm], spring force F [N]."""
    period = 2.0 * math.pi * math.sqrt(params.m / params.k)
    dt = 0.5 * period / params.steps_per_slip
    t, x = 0.0, 0.0
    times, positions = [0.0], [0.0]
    for threshold in thresholds(params):
        # stick: the drive loads the spring until the force reaches the threshold
        t = (threshold / params.k + x) / params.V
        times.append(t)
        positions.append(x)
        # slip: velocity Verlet with kinetic friction opposing the motion, until the block stops
        v = 0.0
        force = params.k * (params.V * t - x) - params.F_d
        while True:
            v_half = v + 0.5 * dt * force / params.m
            x += dt * v_half
            t += dt
            force = params.k * (params.V * t - x) - params.F_d
            v = v_half + 0.5 * dt * force / params.m
            if v <= 0.0:
                break
            times.append(t)
            positions.append(x)
        times.append(t)
        positions.append(x)
    times, positions = np.asarray(times), np.asarray(positions)
    return times, positions, params.k * (params.V * times - positions)


@register("solver", "toy-spring-block", "1", BlockParams, produces="toy-block")
def run_solver(params, output, *, threads, inputs):
    """Spring-block slider with random static thresholds (test plugin)."""
    t, x, F = simulate(params)
    with h5io.open_file(output, "w") as file:
        formats.stamp(file, "toy-block")
        h5io.write_dataset(file, "t", t)
        h5io.write_dataset(file, "x", x)
        h5io.write_dataset(file, "F", F)
        h5io.write_attrs(file, dataclasses.asdict(params))
        h5io.write_dataset(file, "thresholds", thresholds(params))


@dataclasses.dataclass(frozen=True)
class SlipParams:
    """Slip detection."""

    threshold: float = param(1e-3, "smallest slip", unit="mm", exclusive_minimum=0)


@register("analysis", "toy-slips", "1", SlipParams, consumes=("toy-block",), produces="event-table")
def run_analysis(params, input, output):
    """Slips of a spring-block run: one row per slip (test plugin)."""
    with h5io.open_file(input) as file:
        formats.check(file, "toy-block")
        t, x = file["t"][...], file["x"][...]
    moving = np.diff(x) > 0
    starts = np.flatnonzero(moving & ~np.r_[False, moving[:-1]])
    ends = np.flatnonzero(moving & ~np.r_[moving[1:], False]) + 1
    dR = x[ends] - x[starts]
    keep = dR >= params.threshold
    table = pd.DataFrame({"event": np.arange(keep.sum()), "interface": np.ones(keep.sum(), dtype=np.int64),
                          "multi": np.zeros(keep.sum(), dtype=bool), "time": t[starts][keep], "slip": dR[keep]})
    write_analysis_file(output, "event-table", analysis="toy-slips", version="1", params=params, input=input,
                        attrs={}, tables={"slip_events": slip_events_table(table)})


@dataclasses.dataclass(frozen=True)
class ForceFigureParams:
    """Figure options."""

    width: float = param(4.0, "figure width", unit="inch", exclusive_minimum=0)


@register("figure", "toy-force", "1", ForceFigureParams, inputs=("analysis:toy-slips",))
def run_figure(params, inputs, output):
    """Spring force against time of every spring-block run, slips marked (test plugin)."""
    fig, ax = plt.subplots(figsize=(params.width, 3))
    for item in inputs["analysis:toy-slips"]:
        with h5io.open_file(item.parent) as file:  # the run the slips were found in (lineage)
            ax.plot(file["t"][...], file["F"][...], lw=0.8)
        slips = read_slip_events(item)
        ax.plot(slips["time"], np.zeros(len(slips)), "k|")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("F (N)")
    save_figure(fig, output)
