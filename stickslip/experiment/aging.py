"""Aging of the interfaces from the detected slips: logarithmic aging fit, aging rate per slip,
its spread with n, slow slip, and the disorder law of individually driven interfaces.

Paper, section "Interpretation" and appendices "Aging variations", "Slow slip":

- aging law ``dmu_a = B ln(T_a / T0)``, ``T0 = 1 s``, fitted on logarithmically binned ``T_a``
  (mean and standard deviation of ``dmu_a`` per bin);
- aging rate of one slip ``B_a = dmu_a / ln(T_a / T0)``;
- slow-slip fraction ``R_slow = 1 - sum(dR_a) / R_tot`` per interface;
- a slip has no slow slip before it if its interface drifted by less than 3 um since its
  previous slip;
- individual protocol, disorder law ``dmu_a = (d mu_a / dt) T_a`` (``K T_a h gamma_dot / N``).
"""

import dataclasses

import numpy as np
import pandas as pd

__all__ = ["T0", "SLOW_SLIP_DRIFT", "FITS", "AgingFit", "log_binned", "fit_aging", "fit_aging_per_interface",
           "fit_single_slips", "aging_rate", "spread_of_aging_rate", "slow_slip_fraction", "without_slow_slip"]

#: Microscopic time scale of the aging law [s].
T0 = 1.0
#: Drift of an interface between two of its slips above which slow slip occurred [mm] (3 um).
SLOW_SLIP_DRIFT = 3e-3
#: Aging fits: the paper's line through the origin ``dmu = B ln(T/T0)``, and a free intercept
#: ``dmu = c + B ln(T/T0)``.
FITS = ("origin", "intercept")


@dataclasses.dataclass(frozen=True)
class AgingFit:
    """Result of the aging fit ``dmu = c + B ln(T / T0)`` (``c = 0`` through the origin).

    Attributes
    ----------
    B : float
        Aging rate [-].
    B_error : float
        Its standard error [-].
    c : float
        Intercept, the friction drop at ``T = T0`` [-] (0 for the fit through the origin).
    c_error : float
        Its standard error [-] (0 for the fit through the origin).
    kind : {"origin", "intercept"}
        Which fit (:data:`FITS`).
    bins : pandas.DataFrame
        One row per bin used: ``T_low``, ``T_high`` [s] (edges), ``T`` [s] (geometric mean of the
        bin's ``T``), ``dmu_mean``, ``dmu_std`` [-], ``count``.
    n_slips : int
        Number of slips in the fitted bins.
    """

    B: float
    B_error: float
    c: float
    c_error: float
    kind: str
    bins: pd.DataFrame
    n_slips: int

    def __call__(self, T, t0=T0):
        """The fitted law ``c + B ln(T / t0)`` at waiting times ``T`` [s] (any shape)."""
        return self.c + self.B * np.log(np.asarray(T, dtype=float) / t0)


def log_binned(T, values, *, bins_per_decade=4, min_count=5):
    """Mean and standard deviation of ``values`` in logarithmic bins of ``T``.

    Parameters
    ----------
    T : array_like, shape (m,)
        Waiting times [s] (> 0; NaN entries are ignored).
    values : array_like, shape (m,)
        Quantity to average, e.g. ``dmu_a``.
    bins_per_decade : int
        Bins per factor 10 of ``T``; edges at ``10**(k / bins_per_decade)`` s.
    min_count : int
        Bins with fewer entries are dropped.

    Returns
    -------
    pandas.DataFrame
        Columns ``T_low``, ``T_high``, ``T`` [s], ``dmu_mean``, ``dmu_std``, ``count``.
    """
    T = np.asarray(T, dtype=float)
    values = np.asarray(values, dtype=float)
    keep = np.isfinite(T) & np.isfinite(values) & (T > 0)
    T, values = T[keep], values[keep]
    columns = ["T_low", "T_high", "T", "dmu_mean", "dmu_std", "count"]
    if T.size == 0:
        return pd.DataFrame(columns=columns)
    index = np.floor(np.log10(T) * bins_per_decade).astype(int)
    rows = []
    for k in np.unique(index):
        member = index == k
        if member.sum() < min_count:
            continue
        rows.append((10.0 ** (k / bins_per_decade), 10.0 ** ((k + 1) / bins_per_decade),
                     float(np.exp(np.mean(np.log(T[member])))), float(values[member].mean()),
                     float(values[member].std(ddof=1)), int(member.sum())))
    return pd.DataFrame(rows, columns=columns)


def fit_aging(T, dmu, *, t0=T0, fit="origin", bins_per_decade=4, min_count=5):
    """Fit ``dmu = B ln(T / t0)`` (``fit="origin"``) or ``dmu = c + B ln(T / t0)`` (``"intercept"``)
    on logarithmically binned waiting times.

    The bin means ``y_k`` at ``x_k = mean(ln(T / t0))`` of bin ``k`` are fitted by weighted linear
    least squares, weights ``w_k = count_k / std_k**2`` (inverse variance of a bin mean), design
    matrix ``X = [x]`` (origin, the paper's fit) or ``[x, 1]`` (intercept). The covariance
    ``(X^T W X)^-1`` is scaled by the reduced chi-square ``chi2 / (m - p)`` (``m`` bins, ``p``
    parameters), so that the errors reflect the actual scatter of the bin means around the law.
    Through the origin this is ``B = sum(w x y) / sum(w x^2)``,
    ``B_error = sqrt(chi2 / (m - 1) / sum(w x^2))``.

    A strength offset (friction drop gained however short the stick, ``dmu = c + B ln T``) is
    read by the fit through the origin as extra aging: over the ``T`` range of the data the
    origin fit returns ``B + c / <x>`` roughly; the intercept fit returns ``B`` and ``c``.

    Parameters
    ----------
    T : array_like, shape (m,)
        Waiting time since the previous slip of the same interface [s].
    dmu : array_like, shape (m,)
        Friction drop of the slip [-].
    t0 : float
        Microscopic time scale [s].
    fit : {"origin", "intercept"}
        Law fitted (:data:`FITS`).
    bins_per_decade, min_count : int
        See :func:`log_binned`.

    Returns
    -------
    AgingFit

    Raises
    ------
    ValueError
        If fewer than ``p + 1`` bins hold ``min_count`` slips (2 through the origin, 3 with an
        intercept), or ``fit`` is unknown.
    """
    if fit not in FITS:
        raise ValueError(f"fit must be one of {', '.join(FITS)}; got {fit!r}")
    n_params = FITS.index(fit) + 1
    bins = log_binned(T, dmu, bins_per_decade=bins_per_decade, min_count=min_count)
    if len(bins) < n_params + 1:
        raise ValueError(f"aging fit ({fit}) needs at least {('two', 'three')[n_params - 1]} bins of {min_count} slips with a "
                         f"waiting time; got {len(bins)}")
    x = np.log(bins["T"].to_numpy() / t0)  # the geometric mean: x = mean(ln(T / t0)) per bin
    y = bins["dmu_mean"].to_numpy()
    std = np.maximum(bins["dmu_std"].to_numpy(), np.finfo(float).tiny)
    w = bins["count"].to_numpy() / std ** 2
    design = np.column_stack([x, np.ones_like(x)][:n_params])
    normal = design.T @ (w[:, None] * design)
    coefficients = np.linalg.solve(normal, design.T @ (w * y))
    chi2 = float(np.sum(w * (y - design @ coefficients) ** 2))
    errors = np.sqrt(np.diag(np.linalg.inv(normal)) * chi2 / (len(bins) - n_params))
    c, c_error = (float(coefficients[1]), float(errors[1])) if n_params == 2 else (0.0, 0.0)
    return AgingFit(B=float(coefficients[0]), B_error=float(errors[0]), c=c, c_error=c_error, kind=fit,
                    bins=bins, n_slips=int(bins["count"].sum()))


def fit_aging_per_interface(slips, *, t0=T0, fit="origin", bins_per_decade=4, min_count=5):
    """:func:`fit_aging` on the slips of each interface separately.

    Parameters
    ----------
    slips : pandas.DataFrame
        Columns ``interface``, ``T`` [s], ``dmu`` (rows with NaN are ignored).
    t0, fit, bins_per_decade, min_count
        See :func:`fit_aging`.

    Returns
    -------
    dict[int, AgingFit or ValueError]
        Per interface (sorted), the fit, or the error that says why it could not be made
        (too few bins).
    """
    results = {}
    for a, part in slips.groupby("interface", sort=True):
        try:
            results[int(a)] = fit_aging(part["T"], part["dmu"], t0=t0, fit=fit, bins_per_decade=bins_per_decade,
                                        min_count=min_count)
        except ValueError as error:
            results[int(a)] = error
    return results


def fit_single_slips(slips, *, t0=T0, fit="origin", per_interface=False):
    """The paper's aging fit of an analysed recording: :func:`fit_aging` on its single slips.

    Slips in multi-interface events are left out (their ``dmu`` is not defined: the lever
    kinematics of one slip does not apply).

    Parameters
    ----------
    slips : pandas.DataFrame
        One row per slip (:func:`stickslip.experiment.analysis.analyse_record`): columns ``interface``,
        ``multi``, ``T`` [s], ``dmu``; the slips of one or several recordings.
    t0, fit
        See :func:`fit_aging`.
    per_interface : bool, optional
        Fit each interface separately (:func:`fit_aging_per_interface`).

    Returns
    -------
    AgingFit or dict[int, AgingFit or ValueError]
        The fit over every interface, or per interface.

    Raises
    ------
    ValueError
        Over every interface: if the single slips fill too few bins (:func:`fit_aging`).
    """
    single = slips[~slips["multi"].to_numpy(dtype=bool)]
    if per_interface:
        return fit_aging_per_interface(single, t0=t0, fit=fit)
    return fit_aging(single["T"], single["dmu"], t0=t0, fit=fit)


def aging_rate(dmu, T, *, t0=T0):
    """Aging rate of each slip, ``B_a = dmu_a / ln(T_a / t0)``.

    Parameters
    ----------
    dmu : array_like, shape (m,)
        Friction drops [-].
    T : array_like, shape (m,)
        Waiting times [s].
    t0 : float
        Microscopic time scale [s].

    Returns
    -------
    numpy.ndarray, shape (m,)
        ``B_a`` [-]; NaN where ``T <= t0`` (the law has no positive rate there) or ``T`` is NaN.
    """
    T = np.asarray(T, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = np.asarray(dmu, dtype=float) / np.log(T / t0)
    return np.where(T > t0, rate, np.nan)


def _spread(valid):
    individual = valid[valid["protocol"] == "individual"].assign(n=1)
    stack = valid[valid["protocol"] == "stack"]
    has_individual = set(individual["interface"].unique())
    stack = stack[~((stack["n"] == 1) & stack["interface"].isin(has_individual))]
    table = (pd.concat([individual, stack]).groupby(["interface", "n"])["B_a"]
             .agg(std=lambda b: b.std(ddof=1), count="size").reset_index())
    reference = table[table["n"] == 1].set_index("interface")["std"]
    table["std_normalised"] = table["std"] / table["interface"].map(reference)
    return table


def spread_of_aging_rate(slips):
    """Standard deviation of ``B_a`` per interface and ``n``, normalised by its ``n = 1`` value.

    The ``n = 1`` reference of interface ``a`` is interface ``a`` driven alone: the slips of the
    "individual" protocol for ``a``, or, if there are none, of the stack with ``n = 1``
    (the same configuration for ``a = 1``). Slips of all runs are pooled (the paper's 10 runs per n).

    With a ``seed`` column and at least three seeds, the normalised standard deviation gets the
    jackknife standard error over the seeds (each seed's runs, stack and individual, left out in
    turn: ``sqrt((k - 1)/k sum_s (r_s - mean r)^2)``).

    Parameters
    ----------
    slips : pandas.DataFrame
        Columns ``interface``, ``n``, ``protocol``, ``B_a`` (NaN entries are ignored), optionally ``seed``.

    Returns
    -------
    pandas.DataFrame
        Columns ``interface``, ``n``, ``std`` (of ``B_a``), ``count``, ``std_normalised``
        (``std / std`` of the reference; NaN without reference), ``std_normalised_error`` (NaN
        without seeds). The reference rows have ``n = 1``.
    """
    valid = slips[np.isfinite(slips["B_a"].to_numpy(dtype=float))]
    table = _spread(valid)
    table["std_normalised_error"] = np.nan
    seeds = sorted(valid["seed"].dropna().unique()) if "seed" in valid.columns else []
    if len(seeds) >= 3:
        key = ["interface", "n"]
        left_out = pd.concat([_spread(valid[valid["seed"] != seed]).assign(left_out=seed) for seed in seeds])
        spread = left_out.groupby(key)["std_normalised"].agg(
            lambda r: np.sqrt((len(seeds) - 1) / len(seeds) * np.sum((r - r.mean()) ** 2)) if len(r) == len(seeds)
            else np.nan)
        table["std_normalised_error"] = table.set_index(key).index.map(spread).to_numpy(dtype=float)
    return table


def slow_slip_fraction(R_tot, dR_sum):
    """Fraction of the sliding distance covered by slow slip, ``R_slow = 1 - sum(dR_a) / R_tot``.

    Parameters
    ----------
    R_tot : array_like
        Total sliding of the interface over the analysed record [mm].
    dR_sum : array_like
        Sum of the slips detected on it [mm].

    Returns
    -------
    numpy.ndarray
        ``R_slow`` [-]; NaN where ``R_tot <= 0``.
    """
    R_tot = np.asarray(R_tot, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(R_tot > 0, 1.0 - np.asarray(dR_sum, dtype=float) / R_tot, np.nan)


def without_slow_slip(slips, *, drift=SLOW_SLIP_DRIFT):
    """The slips whose interface drifted by less than ``drift`` since its previous slip.

    Parameters
    ----------
    slips : pandas.DataFrame
        Column ``drift`` [mm]: ``R_a(t_start) - R_a(t_end of the previous slip of a)``.
    drift : float
        Threshold [mm] (3 um in the paper).

    Returns
    -------
    pandas.DataFrame
        The rows with ``drift < threshold`` (a slip without a previous one is excluded).
    """
    return slips[slips["drift"].to_numpy(dtype=float) < drift]
