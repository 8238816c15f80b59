"""Heterogeneity along the slip path: a smooth random profile of each interface's friction level.

A slab slides ~0.2 mm per slip over a pre-roughened plate (asperities of ~25 µm, the paper), so each
stick ends on another patch of the surface. The steady friction at ``V0`` of interface ``k`` is made
a function of its slip ``delta`` since the start of the run::

    mu0_k(delta) = mu0_k (1 + epsilon g_k(delta))

with ``epsilon`` the relative amplitude and ``g_k`` a stationary Gaussian random function of zero
mean and unit variance with the Gaussian correlation ``<g(x) g(x + s)> = exp(-s^2 / (2 ell^2))``
(correlation length ``ell``), independent between interfaces.

Representation: ``g_k`` is periodic with the period :data:`PERIOD` (64 mm, ten times the ~6 mm an
interface slips in a 6000-s run, so no patch is crossed twice), a sum of Fourier modes with random
Gaussian amplitudes whose spectrum ``exp(-q^2 ell^2 / 2)`` gives that correlation, drawn by an
inverse FFT onto a grid of spacing at most ``ell / 16`` and normalised to a spatial variance of
exactly 1 over the period (mean exactly 0). Between the nodes, ``g`` and its slope are the cubic
Hermite interpolant of the exact nodal values and slopes (continuous value and slope; relative
error ~ (q spacing)^4 / 384 < 1e-5 for the modes that carry the variance): constant cost per
evaluation inside the compiled right-hand side and its analytic Jacobian, which needs
``d mu0 / d delta`` and ``d^2 mu0 / d delta^2``.
"""

import dataclasses
import math

import numpy as np

from ...numba_options import njit

__all__ = ["PERIOD", "NODES_PER_LENGTH", "PathProfiles", "slip_path", "path_stream", "random_profiles", "no_path",
           "level"]

#: Period of every profile [mm].
PERIOD = 64.0
#: Grid nodes per correlation length (at least).
NODES_PER_LENGTH = 16


def path_stream(seed):
    """The random stream of the path profiles: the third child of ``SeedSequence(seed)`` (the first
    two are the disorder and sensor streams of :func:`.model.random_streams`, left unchanged), a
    PCG64 :class:`numpy.random.Generator`."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed).spawn(3)[2]))


def random_profiles(rng, count, correlation_length):
    """Nodal values and slopes of ``count`` independent profiles ``g`` (module docstring).

    Parameters
    ----------
    rng : numpy.random.Generator
    count : int
        Number of profiles (interfaces).
    correlation_length : float
        ``ell`` [mm] (<= PERIOD / 64).

    Returns
    -------
    values : numpy.ndarray
        ``g`` at the nodes ``j * spacing``, float64 [count, nodes].
    slopes : numpy.ndarray
        ``dg/ddelta`` there [1/mm], float64 [count, nodes].
    spacing : float
        Node spacing [mm] (``PERIOD / nodes``, nodes a power of two).
    """
    nodes = 2 ** math.ceil(math.log2(NODES_PER_LENGTH * PERIOD / correlation_length))
    q = 2.0 * math.pi * np.fft.rfftfreq(nodes, d=PERIOD / nodes)       # wavenumbers [1/mm]
    spectrum = np.exp(-(q * correlation_length) ** 2 / 4.0)             # amplitude: sqrt of exp(-q^2 ell^2 / 2)
    spectrum[0] = 0.0                                                   # zero mean
    coefficients = spectrum * (rng.standard_normal((count, q.size)) + 1j * rng.standard_normal((count, q.size)))
    values = np.fft.irfft(coefficients, n=nodes, axis=1)
    slopes = np.fft.irfft(1j * q * coefficients, n=nodes, axis=1)
    scale = values.std(axis=1, keepdims=True)
    return values / scale, slopes / scale, PERIOD / nodes


@dataclasses.dataclass(frozen=True)
class PathProfiles:
    """The profiles ``g`` of every interface of a run and their relative amplitude.

    Attributes
    ----------
    relative_amplitude : float
        ``epsilon``: relative standard deviation of ``mu0`` along the path.
    values, slopes : numpy.ndarray
        Nodal values and slopes [1/mm] of ``g``, float64 [n_slabs, nodes] (:func:`random_profiles`).
    spacing : float
        Node spacing [mm].
    """

    relative_amplitude: float
    values: np.ndarray
    slopes: np.ndarray
    spacing: float

    @classmethod
    def draw(cls, seed, n_slabs, relative_amplitude, correlation_length):
        """The profiles of a run with ``seed`` (:func:`path_stream`), ``n_slabs`` interfaces, the
        relative amplitude ``epsilon`` and the correlation length ``ell`` [mm]."""
        values, slopes, spacing = random_profiles(path_stream(seed), n_slabs, correlation_length)
        return cls(float(relative_amplitude), values, slopes, spacing)

    def reordered(self, order):
        """The profiles with row ``i`` taken from row ``order[i]`` (int [n_slabs]; a shuffled stack,
        whose surfaces travel with their slabs)."""
        order = np.asarray(order, dtype=int)
        return dataclasses.replace(self, values=self.values[order], slopes=self.slopes[order])

    def arguments(self, interfaces, mu0, origin):
        """The ``path`` argument of the compiled code (:func:`slip_path`) for the 0-based ``interfaces``
        [m] with the steady friction ``mu0`` [m] at the start and the slips ``origin`` [m] [mm] where
        ``delta = 0``."""
        return slip_path(self.relative_amplitude * np.asarray(mu0, dtype=float), origin, self.values[interfaces],
                         self.slopes[interfaces], self.spacing)


def slip_path(amplitude, origin, values, slopes, spacing):
    """The profiles as the compiled code takes them (the ``path`` argument of :func:`level`): the tuple
    ``(amplitude, origin, values, slopes, spacing)`` of contiguous float64 arrays and a float.

    Parameters
    ----------
    amplitude : array_like
        ``epsilon mu0_k`` [m] (0: no heterogeneity on interface ``k``, its ``mu0`` exactly constant).
    origin : array_like
        Slip ``R_k`` [mm] at which ``delta = 0`` (the start of the run), [m].
    values, slopes, spacing
        From :func:`random_profiles`, one row per interface ([m, nodes]).
    """
    return (np.ascontiguousarray(amplitude, dtype=float), np.ascontiguousarray(origin, dtype=float),
            np.ascontiguousarray(values, dtype=float), np.ascontiguousarray(slopes, dtype=float), float(spacing))


def no_path(count):
    """The ``path`` of ``count`` interfaces without heterogeneity (:func:`slip_path` with zero amplitudes)."""
    return slip_path(np.zeros(count), np.zeros(count), np.zeros((count, 1)), np.zeros((count, 1)), 1.0)


@njit
def level(k, R, mu0, path):
    """``mu0_k`` at the slip ``R`` [mm] of interface ``k``, its slope ``d mu0_k / dR`` [1/mm] and its
    curvature ``d^2 mu0_k / dR^2`` [1/mm^2] (of the cubic Hermite interpolant: continuous value and
    slope, the curvature jumps at the nodes).

    ``path`` is from :func:`slip_path`; with a zero amplitude the result is ``(mu0[k], 0.0, 0.0)`` exactly."""
    amplitude, origin, values, slopes, spacing = path
    if amplitude[k] == 0.0:
        return mu0[k], 0.0, 0.0
    nodes = values.shape[1]
    x = (R - origin[k]) / spacing
    cell = math.floor(x)
    s = x - cell
    j = int(cell % nodes)
    j1 = (j + 1) % nodes
    g0, g1 = values[k, j], values[k, j1]
    d0, d1 = slopes[k, j] * spacing, slopes[k, j1] * spacing          # per cell
    s2, s3 = s * s, s * s * s
    g = (2 * s3 - 3 * s2 + 1) * g0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * g1 + (s3 - s2) * d1
    dg = ((6 * s2 - 6 * s) * g0 + (3 * s2 - 4 * s + 1) * d0 + (-6 * s2 + 6 * s) * g1 + (3 * s2 - 2 * s) * d1) / spacing
    d2g = ((12 * s - 6) * g0 + (6 * s - 4) * d0 + (6 - 12 * s) * g1 + (6 * s - 2) * d1) / (spacing * spacing)
    return mu0[k] + amplitude[k] * g, amplitude[k] * dg, amplitude[k] * d2g
