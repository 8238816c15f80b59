"""Slip statistics against the rigidity ratio Phi: multi-slip fraction, stress drops, crossover.

The runs of a Phi sweep (``numerical-events`` files, any N) are pooled by (n, Phi) over
seeds (Phi to three significant digits). Per point: the number of steady-state slip
events ``m`` and of multi-slips ``k``; the multi-slip fraction ``p = k / m`` with its
counting error, the Wilson score interval at one standard deviation (never outside [0, 1],
not empty at ``k = 0`` or ``k = m``); the mean of Delta mu_a over every slipping interface
of every slip event with its standard error ``std / sqrt(m_a)``, and the width (standard
deviation) with ``std / sqrt(2 (m_a - 1))``. The crossover Phi is where the multi-slip fraction
first passes 0.5 going up in Phi, interpolated linearly in ``log10 Phi``.
"""

import math

import numpy as np
import pandas as pd

__all__ = ["SWEEP_COLUMNS", "wilson_interval", "sweep_table", "crossover"]

#: Columns of :func:`sweep_table`.
SWEEP_COLUMNS = ("n", "phi", "N", "seeds", "slips", "multi", "multi_fraction", "multi_low", "multi_high",
                 "dmu_count", "dmu_mean", "dmu_mean_error", "dmu_width", "dmu_width_error")


def wilson_interval(k, m, z=1.0):
    """Wilson score interval of a binomial fraction ``k / m`` (``z`` standard deviations).

    Returns
    -------
    tuple[float, float]
        (low, high); (nan, nan) if ``m == 0``.
    """
    if m == 0:
        return math.nan, math.nan
    p = k / m
    centre = (p + z * z / (2 * m)) / (1 + z * z / m)
    half = z * math.sqrt(p * (1 - p) / m + z * z / (4 * m * m)) / (1 + z * z / m)
    return centre - half, centre + half


def _point(n, phi, files):
    slips = pd.concat([f.tables["slips"] for f in files], ignore_index=True)
    per = pd.concat([f.tables["slip_interfaces"] for f in files], ignore_index=True)
    m = len(slips)
    k = int((slips["s"] > 1).sum()) if m else 0
    low, high = wilson_interval(k, m)
    dmu = per["dmu_sig0"].to_numpy(dtype=float) if len(per) else np.empty(0)
    count = dmu.size
    std = float(np.std(dmu, ddof=1)) if count > 1 else math.nan
    return {"n": n, "phi": phi, "N": ",".join(str(v) for v in sorted({int(f.attrs["N"]) for f in files})),
            "seeds": len(files), "slips": m, "multi": k, "multi_fraction": k / m if m else math.nan,
            "multi_low": low, "multi_high": high, "dmu_count": count,
            "dmu_mean": float(dmu.mean()) if count else math.nan,
            "dmu_mean_error": std / math.sqrt(count) if count > 1 else math.nan,
            "dmu_width": std, "dmu_width_error": std / math.sqrt(2 * (count - 1)) if count > 1 else math.nan}


def sweep_table(files, phi_of):
    """Pool runs by (n, Phi) and compute the sweep statistics (module doc).

    Parameters
    ----------
    files : Iterable[stickslip.events.analysis_files.AnalysisFile]
        ``numerical-events`` files with tables ``slips`` and ``slip_interfaces``.
    phi_of : Callable[[dict], float]
        Phi of a file from its attributes.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`SWEEP_COLUMNS`, sorted by n then Phi.
    """
    groups = {}
    for item in files:
        phi = float(f"{phi_of(item.attrs):.3g}")
        groups.setdefault((int(item.attrs["n_interfaces"]), phi), []).append(item)
    rows = [_point(n, phi, group) for (n, phi), group in sorted(groups.items())]
    return pd.DataFrame(rows, columns=list(SWEEP_COLUMNS))


def crossover(table, n, level=0.5):
    """Phi at which the multi-slip fraction of ``n`` interfaces first passes ``level`` (rising Phi).

    Parameters
    ----------
    table : pandas.DataFrame
        Output of :func:`sweep_table`.
    n : int
    level : float, optional

    Returns
    -------
    float
        Interpolated linearly in ``log10 Phi`` between the two points that bracket it;
        NaN if the fraction does not pass ``level`` (or there are fewer than two points).
    """
    rows = table[(table["n"] == n) & (table["slips"] > 0)].sort_values("phi")
    phi, p = rows["phi"].to_numpy(dtype=float), rows["multi_fraction"].to_numpy(dtype=float)
    for i in range(1, phi.size):
        if p[i - 1] < level <= p[i]:
            x0, x1 = math.log10(phi[i - 1]), math.log10(phi[i])
            return 10 ** (x0 + (level - p[i - 1]) / (p[i] - p[i - 1]) * (x1 - x0))
    return math.nan
