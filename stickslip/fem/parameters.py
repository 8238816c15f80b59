"""Parameters of the finite-element model (the ``fem`` solver), defaults as the paper's code.

Units are those of the FE model: lengths in the unit in which the block size is
``h = pi``, moduli in units of ``G`` (= 1), density ``rho`` (= 1); strains are
dimensionless. See docs/fem.md and shared/reference-model.md (section 11).
"""

import dataclasses
import math
import warnings

from .. import formats
from ..formats import fem_run
from ..plugin_params import ParameterError, ParameterWarning, param
from .backends import BACKENDS, DEFAULT_BACKEND
from .laws import INTERFACE_LAWS, make_law
from .trap_model import expected_redraws

__all__ = ["FemParams", "DRIVES", "RELAXATIONS", "SEQUENCE_ENDS", "CYCLE_STRAIN", "REACH_MIN", "REACH_REGIME",
           "REACH_MELT", "CLOCK_ATTEMPTS", "REDRAWS_MAX", "thermal_reach", "stored_params"]

#: Drive configurations: springs to a lever that rotates as prescribed, or a massless lever driven by a spring.
DRIVES = ("fixed-lever", "free-lever")

#: How a minimisation ends: by damped dynamics only (the paper's protocol), or by an exact solve
#: within the current wells once no well has changed for ``quiet_steps`` (docs/fem.md).
RELAXATIONS = ("dynamic", "exact")

#: What happens when a block nears the end of the yield strains held in memory: they are drawn further
#: (the run goes on), or the run stops (the paper's code).
SEQUENCE_ENDS = ("extend", "stop")


#: Drive of one stick-slip cycle [eps0] (docs/fem.md, "Temperature and drive rate against the apparatus").
CYCLE_STRAIN = 0.2
#: Thermal reach ``T ln(nu t_cycle)`` (barrier units) below which no barrier above round-off is crossed:
#: the thermal protocol would be the athermal one at the cost of the kinetic Monte Carlo (refused).
REACH_MIN = 1e-12
#: The regime the studies stay in (docs/fem.md, "Limits of the regime": fine at 0.023, T = 1e-3 with
#: drive_rate 2e-11; flips of two-level blocks took over at 0.030, 1e-3 with 2e-14): beyond it, warned.
REACH_REGIME = 0.025
#: Reach at which a block eps0 below its yield strain (the unit barrier) hops within a cycle: every
#: interface flows, and the event-driven method describes nothing (refused).
REACH_MELT = 1.0
#: Attempts of a thermal process in one stick-slip cycle (or hold) beyond which the clock, a double, no longer
#: tells one attempt time from the next (2^52, its resolution): such an attempt rate is refused.
CLOCK_ATTEMPTS = 2.0 ** 52
#: Redraws of one junction in a stick-slip cycle (or hold) that the trap model expects
#: (:func:`.trap_model.expected_redraws`) beyond which a run would not end (hours per cycle): refused.
REDRAWS_MAX = 1e6


def thermal_reach(temperature, attempt_rate, drive_rate):
    """The barrier crossed during one stick-slip cycle, ``T ln(nu t_cycle)`` [G eps0^2 h^2].

    Parameters
    ----------
    temperature : float
        [G eps0^2 h^2].
    attempt_rate : float
        ``nu`` [1/time].
    drive_rate : float
        [eps0/time]; a cycle lasts ``t_cycle = CYCLE_STRAIN / drive_rate``.

    Returns
    -------
    float
        The reach; ``nan`` if a cycle lasts no attempt time (``nu t_cycle <= 1``) or its length
        is not a finite number.
    """
    attempts = attempt_rate * (CYCLE_STRAIN / drive_rate)
    if not math.isfinite(attempts) or attempts <= 1.0:
        return math.nan
    return temperature * math.log(attempts)


@dataclasses.dataclass(frozen=True)
class FemParams:
    """Parameters of one simulation of the stack (see the field docs for units)."""

    N: int = param(1458, "blocks per interface (mesh: 2*3^k, or small values such as 9; a run that needs more memory "
                         "than the machine has is refused with its estimate)", minimum=3, maximum=10**6)
    plates: int = param(2, "number of elastic plates (n = plates - 1 interfaces)", minimum=2, maximum=6)
    seed: int = param(0, "realisation id; the disorder of element e of the interfaces uses pcg32 seed "
                         "seed*N*99 + e (within int64)", minimum=0, maximum=2**31 - 1)
    k_drive: float = param(1e-3, "drive spring stiffness per unit volume (1e-3 stiff, 1e-6 compliant)",
                           unit="G/h^2", minimum=1e-12, maximum=1e2)
    drive: str = param("fixed-lever", "drive configuration", choices=DRIVES)
    nchunk: int = param(6000, "random yield strains per block of the paper's code: the linear response is scaled "
                              "to the narrowest of these wells; with yield_strains = 'stop' they are all a block "
                              "has", minimum=10, maximum=10**6)
    yield_strains: str = param("extend", "'extend': a block's yield-strain sequence is unbounded (held `window` "
                                         "wells at a time, drawn further from its own generator as it advances); "
                                         "'stop': `nchunk` wells, the run stops `margin` wells before their end "
                                         "(the paper's code)", choices=SEQUENCE_ENDS)
    window: int = param(1000, "yield_strains 'extend': wells per block held in memory (widened when one event "
                              "needs more); the results do not depend on it", minimum=20, maximum=10**6)
    G: float = param(1.0, "shear modulus G = 2 mu (plates and interfaces)", unit="stress", minimum=1e-6, maximum=1e6)
    K: float = param(4.5, "bulk-like modulus K (energy K eps_m^2, eps_m = tr(eps)/2)", unit="stress",
                     minimum=1e-6, maximum=1e6)
    rho: float = param(1.0, "mass density", unit="mass/length^2", minimum=1e-6, maximum=1e6)
    eps0: float = param(5e-5, "typical yield strain (well widths 2 eps0 Weibull + eps_offset)",
                        minimum=1e-9, maximum=0.1)
    eps_offset: float = param(1e-6, "minimal well width (yield_strains 'extend': wider than the kick "
                                        "deps * eps0)", minimum=0.0, maximum=0.1)
    weibull_k: float = param(2.0, "Weibull shape parameter of the well widths", minimum=0.1, maximum=100.0)
    deps: float = param(1e-4, "kick size in equivalent strain", unit="eps0", minimum=1e-10, maximum=0.1)
    dt_scale: float = param(1.0, "time step in units of the paper's dt = h / (2 pi c) / 10 (1 = the paper's "
                                 "protocol; 2-4 keep the event statistics, not each event: docs/fem.md)", minimum=1e-3,
                          maximum=8.0)
    tol: float = param(1e-5, "minimisation: relative residual tolerance (below round-off, ~1e-15, never met: the "
                                 "run ends after max_iter steps)", exclusive_minimum=0.0, maximum=0.5)
    niter_tol: int = param(20, "minimisation: consecutive steps below tol (and non-increasing); at most max_iter",
                          minimum=1, maximum=10**7)
    max_iter: int = param(10_000_000, "minimisation: maximum time steps (then the run fails)", minimum=1,
                         maximum=10**12)
    relaxation: str = param("dynamic", "how minimisations end: 'dynamic' (damped dynamics until the residual "
                                       "criterion, the paper's protocol) or 'exact' (equilibrium of the current wells "
                                       "solved directly once no well changed for quiet_steps, accepted only if every "
                                       "Gauss point stays in its well; linear response by a direct solve)",
                            choices=RELAXATIONS)
    quiet_steps: int = param(0, "relaxation 'exact': time steps without any well change before an equilibrium "
                                "solve is tried (and between tries); 0: the time a shear wave takes to cross a "
                                "third of the interface, L / (3 c_s), about 30 N steps at dt_scale 1 (shorter "
                                "windows end events early: docs/fem.md)", minimum=0, maximum=10**9)
    margin: int = param(5, "a block within this many wells of the end of its held sequence stops the run "
                           "('stop') or makes the event be redone with more wells held ('extend'; with "
                           "max_increments 0 a block within this many wells of the end of its first nchunk wells "
                           "stops the run)", minimum=1, maximum=10**5)
    lever_height: float = param(10.0, "free lever: height of the drive spring on the lever",
                                unit="H_1 - H_0 (mid-height distance of layers 1 and 0)", minimum=1e-3, maximum=1e3)
    max_increments: int = param(0, "stop after this many increments; 0: stop where the paper's code does, when a "
                                   "block comes within `margin` wells of the end of its first `nchunk` wells (with "
                                   "'stop' the increment is aborted there; with 'extend' it is completed, not "
                                   "stored)", minimum=0, maximum=10**12)
    interface_law: str = param("cusp", "potential of the interface blocks in a well (docs/fem.md, 'Interface laws')",
                               choices=INTERFACE_LAWS, extension=True)
    law_params: tuple[float, ...] = param((), "the interface law's parameters after K and G, in the order the law "
                                              "declares them (none for the built-in laws)", extension=True)
    backend: str = param(DEFAULT_BACKEND, "how the numbers are computed; a backend of other round-off than the "
                                          "default makes its own run id", choices=BACKENDS, extension=True)
    temperature: float = param(0.0, "thermal activation of the interface blocks: 0 is the paper's athermal event-driven "
                                    "protocol; > 0 the kinetic Monte Carlo protocol with a finite drive rate "
                                    "(docs/fem.md, 'Finite temperature'); energy in units of the barrier of a block a "
                                    "strain eps0 below its yield strain, G eps0^2 h^2", unit="G eps0^2 h^2", minimum=0.0,
                               extension=True)
    attempt_rate: float = param(1.0, "temperature > 0: attempt rate nu of a block's hop over a barrier E, at rate "
                                     "nu exp(-E / temperature)", unit="1/time", exclusive_minimum=0.0,
                                extension="temperature")
    drive_rate: float = param(1e-9, "temperature > 0: rate of the imposed shear gamma (fixed lever; free lever: of the "
                                    "lever's drive target)", unit="eps0/time", exclusive_minimum=0.0,
                              extension="temperature")
    hold_times: tuple[float, ...] = param((), "temperature > 0: slide-hold-slide: after every slip event (every block "
                                              "of an interface changed well) the drive stops for the next of these "
                                              "times, cycled; empty: no holds", unit="time", minimum=0.0,
                                          extension="temperature")
    hold_delay: float = param(0.0, "temperature > 0 with hold_times: the drive's advance after a slip event at "
                                   "which the hold starts (a slip before it postpones the hold)", unit="eps0",
                              minimum=0.0, maximum=1e6, extension="temperature")
    junction_strengthening: float = param(0.0, "junction aging (docs/fem.md, 'Junction aging'): the half-width of a "
                                               "block's current well grows by this times the depth E of its contact "
                                               "junction, its centre fixed; 0: no aging (needs temperature > 0 and "
                                               "a law whose stress depends on the well's centre only, the cusp)",
                                          unit="eps0 / (G eps0^2 h^2)", minimum=0.0, maximum=1e3, extension=True)
    junction_glass_temperature: float = param(8e-3, "junction aging: scale T_g of the depths drawn, rho(E) = "
                                                    "exp(-E / T_g) / T_g, when a block enters a well and at every "
                                                    "redraw; the typical depth grows as temperature x ln t below T_g",
                                              unit="G eps0^2 h^2", exclusive_minimum=0.0,
                                              maximum=1e3, extension="junction_strengthening")
    junction_attempt_rate: float = param(1.0, "junction aging: a junction of depth E is redrawn at rest at the rate "
                                              "nu_j exp(-E / temperature)", unit="1/time", exclusive_minimum=0.0,
                                         extension="junction_strengthening")
    interface_strength: tuple[float, ...] = param((), "scale of the yield strains (every well's width and offset) of "
                                                      "each interface, bottom to top: one value for all or one per "
                                                      "interface; empty: 1 (the paper's). An interface of scale s "
                                                      "peaks and drops s times higher, its barriers s^2 times "
                                                      "(docs/fem.md, 'Interfaces of different strength')",
                                                  minimum=0.1, maximum=10.0, extension=True)

    def check(self):
        """Check conditions across fields."""
        _refuse_law_mismatch(self)
        _refuse_strength_count(self)
        if self.temperature > 0.0 and self.yield_strains != "extend":
            raise ParameterError("parameter 'yield_strains': a thermal run (temperature > 0) needs 'extend'")
        if self.hold_delay != 0.0 and not self.hold_times:
            raise ParameterError(f"parameter 'hold_delay': {self.hold_delay:g} is used only with hold_times; expected "
                                 "hold_times (e.g. hold_times=[1e3, 1e6]) or the default 0")
        if self.temperature > 0.0:
            _refuse_reach(self)
            _refuse_beyond_clock(self, "attempt_rate", self.attempt_rate)
        if self.temperature == 0.0:
            for name in ("attempt_rate", "drive_rate", "hold_times", "hold_delay"):
                field = self.__dataclass_fields__[name]
                if getattr(self, name) != field.default:
                    raise ParameterError(f"parameter '{name}': used only with temperature > 0; expected a "
                                         "temperature > 0 or the default")
        self._check_junctions()
        _refuse_inconsistent_numerics(self)
        if self.temperature > 0.0:  # warnings last: a refused run is one line
            _warn_reach(self)
            _warn_glass_temperature(self)

    def _check_junctions(self):
        if self.junction_strengthening == 0.0:
            for name in ("junction_glass_temperature", "junction_attempt_rate"):
                if getattr(self, name) != self.__dataclass_fields__[name].default:
                    raise ParameterError(f"parameter '{name}': used only with junction_strengthening > 0; expected "
                                         "junction_strengthening > 0 or the default")
            return
        if self.temperature == 0.0:
            raise ParameterError("parameter 'junction_strengthening': junction aging needs thermal activation; "
                                 "expected temperature > 0 or junction_strengthening = 0")
        if not getattr(INTERFACE_LAWS[self.interface_law], "junction_aging", False):
            aging = [name for name, law in INTERFACE_LAWS.items() if getattr(law, "junction_aging", False)]
            raise ParameterError(f"parameter 'junction_strengthening': law '{self.interface_law}' has a stress that "
                                 "depends on the well's width, so a junction cannot widen it at rest; expected "
                                 f"interface_law {' or '.join(map(repr, aging))} or junction_strengthening = 0")
        _refuse_beyond_clock(self, "junction_attempt_rate", self.junction_attempt_rate)
        _refuse_endless_redraws(self)

def _refuse_law_mismatch(params):
    """Raise ParameterError where the interface law cannot take the run's parameters, relaxation or temperature."""
    law = INTERFACE_LAWS[params.interface_law]
    try:
        make_law(law.name, params.K, params.G, params.law_params)
    except ValueError as error:
        raise ParameterError(f"parameter 'law_params': {error}") from None
    if params.relaxation == "exact" and not law.exact_relaxation:
        raise ParameterError(f"parameter 'relaxation': law '{law.name}' has a curvature that the elastic stiffness "
                             "does not bound, so 'exact' cannot converge; expected 'dynamic'")
    if params.temperature > 0.0 and not law.thermal:
        raise ParameterError(f"parameter 'temperature': law '{law.name}' is not thermal (the exact sampling of "
                             "the hops needs an exact backward barrier and barriers quasi-concave in eps_eq "
                             "within a well); expected 0")


def _refuse_strength_count(params):
    """Raise ParameterError unless ``interface_strength`` has no value, one, or one per interface."""
    if len(params.interface_strength) not in (0, 1, params.plates - 1):
        raise ParameterError(f"parameter 'interface_strength': expected one value or one per interface (plates - 1 "
                             f"= {params.plates - 1}), got {len(params.interface_strength)}")


def _refuse_inconsistent_numerics(params):
    """Raise ParameterError where the numerical parameters contradict each other (the minimisation's stop, the
    narrowest well against the kick, the wells held against the stop margin)."""
    if params.niter_tol > params.max_iter:
        raise ParameterError(f"parameter 'niter_tol': {params.niter_tol} consecutive steps cannot fit in max_iter = "
                             f"{params.max_iter} steps; expected niter_tol <= max_iter")
    if params.yield_strains == "extend" and params.eps_offset <= params.deps * params.eps0:
        raise ParameterError(f"parameter 'eps_offset': {params.eps_offset:g} lets a well be no wider than the kick "
                             f"deps * eps0 = {params.deps * params.eps0:g} (with yield_strains 'extend' any well may "
                             "be as narrow as eps_offset); expected eps_offset > deps * eps0")
    if params.nchunk <= 2 * params.margin:
        raise ParameterError(f"parameter 'nchunk': {params.nchunk} leaves no wells beyond the stop margin "
                             f"(margin = {params.margin}); expected nchunk > 2 * margin")


def _warn_glass_temperature(params):
    """Warn where junction aging's glass temperature is not above the temperature (the junctions do not age)."""
    if params.junction_strengthening > 0.0 and params.junction_glass_temperature <= params.temperature:
        warnings.warn(f"parameters 'junction_glass_temperature', 'temperature': T_g = "
                      f"{params.junction_glass_temperature:g} <= T = {params.temperature:g}: the junctions do not "
                      "age (their depth saturates at once) and are redrawn at a rate that does not decay "
                      "(docs/fem.md, 'Junction aging')", ParameterWarning, stacklevel=2)

def _stretch(params):
    """The longest stretch of a thermal run's time: a stick-slip cycle or its longest hold [time], and its name."""
    cycle = CYCLE_STRAIN / params.drive_rate
    hold = max(params.hold_times, default=0.0)
    if hold > cycle:
        return hold, f"a hold of {hold:.3g} time"
    return cycle, f"a stick-slip cycle ({CYCLE_STRAIN:g} eps0 of drive: {cycle:.3g} time)"


def _refuse_beyond_clock(params, name, rate):
    """Raise ParameterError if the attempt rate ``name`` makes more than :data:`CLOCK_ATTEMPTS` attempts in a stretch."""
    stretch, what = _stretch(params)
    if rate * stretch >= CLOCK_ATTEMPTS:
        raise ParameterError(f"parameter '{name}': {rate:g}/time makes {rate * stretch:.3g} attempts in {what}, beyond "
                             f"the resolution of the clock (2^52 steps of a double); expected < "
                             f"{CLOCK_ATTEMPTS / stretch:.3g} (docs/fem.md, 'Limits of the regime')")


def _refuse_endless_redraws(params):
    """Raise ParameterError if the junctions would be redrawn more than :data:`REDRAWS_MAX` times in a stretch."""
    p = params
    stretch, what = _stretch(p)
    redraws = expected_redraws(p.junction_attempt_rate, p.temperature, p.junction_glass_temperature, stretch)
    if redraws > REDRAWS_MAX:
        ratio = p.temperature / p.junction_glass_temperature
        raise ParameterError(f"parameter 'junction_glass_temperature': {p.junction_glass_temperature:g} at temperature "
                             f"{p.temperature:g} and junction_attempt_rate {p.junction_attempt_rate:g}/time has every "
                             f"junction redrawn ~{redraws:.3g} times in {what} (the trap model's (nu_j t)^min(1, T/T_g), "
                             f"T/T_g = {ratio:.3g}), beyond {REDRAWS_MAX:g}: the run would not end; expected a glass "
                             "temperature well above the temperature or a lower junction_attempt_rate (docs/fem.md, "
                             "'Junction aging')")


def _refuse_reach(params):
    """Raise ParameterError if the thermal reach is outside what the method represents."""
    p = params
    reach = thermal_reach(p.temperature, p.attempt_rate, p.drive_rate)
    cycle = f"a stick-slip cycle ({CYCLE_STRAIN:g} eps0 of drive)"
    if math.isnan(reach):
        raise ParameterError(f"parameter 'drive_rate': {p.drive_rate:g} eps0/time drives {cycle} in "
                             f"{CYCLE_STRAIN / p.drive_rate:.3g} time, not more than one attempt time 1/attempt_rate "
                             f"= {1.0 / p.attempt_rate:.3g} (or no finite time): thermal activation cannot act; expected "
                             f"0 < drive_rate < {CYCLE_STRAIN * p.attempt_rate:g} (docs/fem.md, 'Limits of the regime')")
    log_attempts = reach / p.temperature
    if reach < REACH_MIN:
        raise ParameterError(f"parameter 'temperature': {p.temperature:g} reaches a barrier of {reach:.3g} "
                             f"G eps0^2 h^2 in {cycle}, below {REACH_MIN:g}: no barrier above round-off is crossed; "
                             f"expected 0 (the athermal protocol) or >= {REACH_MIN / log_attempts:.3g} "
                             f"(docs/fem.md, 'Limits of the regime')")
    if reach > REACH_MELT:
        raise ParameterError(f"parameter 'temperature': {p.temperature:g} reaches a barrier of {reach:.3g} "
                             f"G eps0^2 h^2 in {cycle}, above {REACH_MELT:g} (a block eps0 below its yield strain "
                             f"hops at once: the interfaces flow); expected <= {REACH_MELT / log_attempts:.3g}, the "
                             f"studied regime T ln(nu t_cycle) <= {REACH_REGIME:g} at <= "
                             f"{REACH_REGIME / log_attempts:.3g} (docs/fem.md, 'Limits of the regime')")


def _warn_reach(params):
    """Warn if the thermal reach is beyond the regime where the studies stay."""
    p = params
    reach = thermal_reach(p.temperature, p.attempt_rate, p.drive_rate)
    log_attempts = reach / p.temperature
    if reach > REACH_REGIME:
        warnings.warn(f"parameters 'temperature', 'drive_rate': thermal reach T ln(nu t_cycle) = {reach:.3g}, beyond "
                      f"the regime T ln(nu t_cycle) <= {REACH_REGIME:g} (temperature <= "
                      f"{REACH_REGIME / log_attempts:.3g} at this drive rate) where the studies stay: flips of "
                      "two-level blocks may take over the run (docs/fem.md, 'Limits of the regime')", ParameterWarning,
                      stacklevel=2)


def stored_params(file):
    """The :class:`FemParams` of an open ``fem-run`` file (stored there as the producer's opaque JSON).

    Parameters
    ----------
    file : h5py.File

    Raises
    ------
    stickslip.h5io.FileFormatError
        If the file is not a ``fem-run`` file of the current version, or its parameters are not those of a
        :class:`FemParams` (a damaged file: the message names it).
    """
    return formats.stored_run_params(FemParams, fem_run.read_params(file), file.filename, "fem")
