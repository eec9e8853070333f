r"""The bootstrap clustered on runs: the project's interval, written once.

The runs of a sweep (one per initial condition, IC) are independent; the events within
a run are not. So every interval kicktimes states resamples **whole runs**, with
replacement (the cluster bootstrap; Davison & Hinkley 1997, sec. 3.8; Cameron, Gelbach &
Miller 2008): a resample draws :math:`n` cluster indices
:math:`I_{b1}, \dots, I_{bn}` i.i.d. uniform on :math:`\{0, \dots, n-1\}`, the statistic
is recomputed on the runs it drew, and the percentile interval of the :math:`B`
replicates :math:`\hat\theta^*_b` is

.. math::

    [\hat\theta^*_{(\alpha/2)},\ \hat\theta^*_{(1-\alpha/2)}], \qquad
    \alpha = 1 - \text{level},

the quantiles of the finite replicates by linear interpolation (`numpy.percentile`).
Statistics of several systems measured on the same ICs are resampled with the **same**
indices (paired), so a ratio keeps the covariance of its numerator and denominator.

* `resample_indices`: the :math:`(B, n)` indices, drawn from ``rng`` as
  ``rng.integers(0, n, size=(B, n))`` (optionally ``chunk`` resamples per draw, and the
  identity resample first); `resample_counts`: the same resampling as counts per cluster
  (multinomial), for statistics that are matrix products;
* `percentile_interval`: the interval of the finite replicates;
* `paired_median`: the findings' robust control, the median over ICs of the per-IC ratio;
* `cluster_bootstrap`: both, for a statistic given as a function of the indices;
* `ratio_of_means`: the paired ratio :math:`\sum x_i / \sum y_i` with its interval;
* `paired_ratio`: that ratio per radius and averaged over radii, for tables indexed by
  ``(radius, ic)``, the same resampled ICs at every radius (the report's findings).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes.validation import check_int, check_real, check_rng, keyword_only_after

from .robust import bootstrap_nanmedians, nanmedian

__all__ = ["ClusterBootstrap", "cluster_bootstrap", "paired_median", "paired_ratio",
           "percentile_interval", "ratio_of_means", "resample_counts", "resample_indices"]


@keyword_only_after(1, since="0.2.0", names=('n_boot', 'rng'))
def resample_indices(n_clusters, *, n_boot, rng=None, with_identity=False, chunk=None):
    r"""Cluster indices of ``n_boot`` bootstrap resamples of ``n_clusters`` runs.

    Parameters
    ----------
    n_clusters : int
        The number of clusters (runs, ICs) :math:`n \ge 1`.
    n_boot : int
        The number of resamples :math:`B \ge 0` (0: none, an empty array).
    rng : numpy.random.Generator or int or None
        The source of the draws (a seed makes a new generator).
    with_identity : bool
        Put the identity resample ``0, 1, ..., n - 1`` first (row 0: the estimate), so that
        one call of a vectorised statistic gives the estimate and its replicates.
    chunk : int, optional
        Draw ``chunk`` resamples per call of ``rng.integers`` (default: all at once). The
        values depend on it when ``chunk * n`` is odd (numpy draws 32-bit values in
        pairs); it is part of a result's definition where a page was computed with it.

    Returns
    -------
    numpy.ndarray of int64, shape (B, n) or (1 + B, n)
        ``idx[b]``: the clusters of resample ``b``, i.i.d. uniform on
        :math:`\{0, \dots, n-1\}`.

    Examples
    --------
    >>> from kicktimes.stats import resample_indices
    >>> resample_indices(4, n_boot=2, rng=0, with_identity=True)
    array([[0, 1, 2, 3],
           [3, 2, 2, 1],
           [1, 0, 0, 0]])
    """
    n = check_int("n_clusters", n_clusters, low=1)
    b = check_int("n_boot", n_boot, low=0)
    rng = check_rng(rng)
    if chunk is None:
        idx = rng.integers(0, n, size=(b, n))
    else:
        step = check_int("chunk", chunk, low=1)
        idx = np.concatenate([rng.integers(0, n, size=(min(step, b - m), n))
                              for m in range(0, b, step)] or [np.empty((0, n), np.int64)])
    if with_identity:
        idx = np.vstack([np.arange(n), idx])
    return idx


@keyword_only_after(1, since="0.2.0")
def resample_counts(n_clusters, *, n_boot, rng=None):
    r"""How often each cluster is drawn in each of ``n_boot`` bootstrap resamples.

    The same resampling as `resample_indices`, counted: row ``b`` is multinomial with
    ``n`` trials over the ``n`` clusters, :math:`c_{bj} = \#\{k : I_{bk} = j\}`, drawn
    as ``rng.multinomial(n, [1/n] * n, size=B)``. A statistic linear in the clusters'
    sums is then one matrix product, e.g. a ratio of means ``(c @ x) / (c @ y)``.

    Parameters
    ----------
    n_clusters, n_boot : int
        :math:`n \ge 1` clusters, :math:`B \ge 0` resamples (0: none, an empty array).
    rng : numpy.random.Generator or int or None

    Returns
    -------
    numpy.ndarray of float64, shape (B, n)
        Every row sums to ``n``.

    Examples
    --------
    >>> from kicktimes.stats import resample_counts
    >>> resample_counts(4, n_boot=3, rng=0).sum(axis=1).tolist()
    [4.0, 4.0, 4.0]
    """
    n = check_int("n_clusters", n_clusters, low=1)
    b = check_int("n_boot", n_boot, low=0)
    return check_rng(rng).multinomial(n, np.full(n, 1.0 / n), size=b).astype(float)


def _tail_percent(level):
    """The percent left out on each side of a central ``level`` interval: 2.5 for 0.95.
    (1 - 0.95 is 0.050000000000000044 in binary: the percentile is 2.5 %, not 2.5 % plus
    that rounding error.)"""
    return round(50.0 * (1.0 - level), 12)


@keyword_only_after(1, since="0.2.0", names=('level',))
def percentile_interval(replicates, *, level=0.95, axis=None):
    r"""Percentile interval of the finite bootstrap replicates.

    ``(p_a, p_{100-a})`` with ``a = 50 (1 - level)`` percent (2.5 and 97.5 for the 95 %
    interval), `numpy.percentile`'s linear interpolation, over the finite values only (a
    resample whose statistic is undefined, e.g. a ratio over a resample without events,
    drops out).

    Parameters
    ----------
    replicates : array_like of float
        The replicates :math:`\hat\theta^*_b`: any shape, flattened (``axis=None``), or
        one interval per slice along the other axes (``axis``: the replicates' axis).
    level : float
        Coverage, in (0, 1).
    axis : int, optional
        The replicates' axis; then ``low`` and ``high`` are arrays over the other axes,
        each over the finite replicates of its slice (NaN where a slice has none).

    Returns
    -------
    (float, float) or (ndarray, ndarray)
        ``(low, high)``; ``(nan, nan)`` when no replicate is finite.

    Examples
    --------
    >>> from kicktimes.stats import percentile_interval
    >>> percentile_interval([1.0, 2.0, float("nan"), 3.0, 4.0], level=0.5)
    (1.75, 3.25)
    >>> low, high = percentile_interval([[1.0, 10.0], [2.0, 20.0], [3.0, 30.0]], axis=0)
    >>> low.tolist(), high.tolist()
    ([1.05, 10.5], [2.95, 29.5])
    """
    level = check_real("level", level, low=0.0, high=1.0)
    a = _tail_percent(level)
    if axis is not None:
        v = np.asarray(replicates, float)
        finite = np.isfinite(v)
        if finite.all():
            # the same numbers as nanpercentile's (tests/test_stats_bootstrap.py), which loops over
            # the slices in Python: 4x slower on the report's (200, 10^5) Q-Q band
            low, high = np.percentile(v, [a, 100.0 - a], axis=axis)
            return low, high
        v = np.where(finite, v, np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a slice without a finite value
            low, high = np.nanpercentile(v, [a, 100.0 - a], axis=axis)
        return low, high
    v = np.asarray(replicates, float).ravel()
    v = v[np.isfinite(v)]
    if not v.size:
        return math.nan, math.nan
    return float(np.percentile(v, a)), float(np.percentile(v, 100.0 - a))


@dataclass(frozen=True)
class ClusterBootstrap:
    """Result of `cluster_bootstrap` and `ratio_of_means`.

    Attributes
    ----------
    estimate : float or ndarray
        The statistic on the runs as they are (the identity resample).
    ci_low, ci_high : float or ndarray
        The percentile interval (`percentile_interval`) of the finite replicates, per
        component of the statistic.
    replicates : ndarray, shape (B,) or (B, k)
        The statistic on each resample.
    level : float
    n_clusters : int
    """

    estimate: object
    ci_low: object
    ci_high: object
    replicates: np.ndarray
    level: float
    n_clusters: int

    def summary(self) -> str:
        """One line: the estimate, its interval, the level and the resamples."""
        est, lo, hi = (np.atleast_1d(np.asarray(v, float)) for v in
                       (self.estimate, self.ci_low, self.ci_high))
        parts = [f"{e:.4g} [{a:.4g}, {b:.4g}]" for e, a, b in zip(est, lo, hi, strict=True)]
        return (f"{', '.join(parts)} ({100 * self.level:g} % percentile interval, "
                f"{len(self.replicates)} resamples of {self.n_clusters} clusters)")

    def __repr__(self) -> str:
        return f"ClusterBootstrap({self.summary()})"


def cluster_bootstrap(statistic, n_clusters, *, n_boot=999, level=0.95, rng=None,
                      chunk=None) -> ClusterBootstrap:
    r"""The bootstrap clustered on runs of a statistic given as a function of the indices.

    Parameters
    ----------
    statistic : callable
        ``statistic(idx)`` with ``idx`` an int array of shape (m, n) (each row one
        resample of the clusters) returns the statistic of each row: shape (m,) or (m, k)
        for k statistics resampled together (paired). It is called once with the identity
        resample (m = 1) and once per chunk of resamples.
    n_clusters : int
        The number of clusters :math:`n`.
    n_boot : int
        The number of resamples :math:`B`.
    level : float
        Coverage of the percentile interval.
    rng : numpy.random.Generator or int or None
        The source of the resamples (`resample_indices`).
    chunk : int, optional
        Resamples drawn and evaluated at a time (memory O(chunk n) instead of O(B n));
        see `resample_indices` for its effect on the draws.

    Returns
    -------
    ClusterBootstrap

    Examples
    --------
    The mean collision count of 5 runs:

    >>> import numpy as np
    >>> from kicktimes.stats import cluster_bootstrap
    >>> counts = np.array([3.0, 5.0, 4.0, 9.0, 4.0])
    >>> res = cluster_bootstrap(lambda idx: counts[idx].mean(axis=1), counts.size, rng=1)
    >>> float(res.estimate), res.ci_low < 5.0 < res.ci_high
    (5.0, True)
    """
    n = check_int("n_clusters", n_clusters, low=1)
    b = check_int("n_boot", n_boot, low=1)
    level = check_real("level", level, low=0.0, high=1.0)
    rng = check_rng(rng)
    estimate = np.asarray(statistic(np.arange(n)[None, :]), float)[0]
    step = b if chunk is None else check_int("chunk", chunk, low=1)
    replicates = np.concatenate([
        np.asarray(statistic(resample_indices(n, n_boot=min(step, b - m), rng=rng)), float)
        for m in range(0, b, step)])
    if replicates.ndim == 1:
        low, high = percentile_interval(replicates, level=level)
        return ClusterBootstrap(float(estimate), low, high, replicates, level, n)
    bounds = np.array([percentile_interval(replicates[:, j], level=level)
                       for j in range(replicates.shape[1])])
    return ClusterBootstrap(estimate, bounds[:, 0], bounds[:, 1], replicates, level, n)


def ratio_of_means(x, y, *, n_boot=999, level=0.95, rng=None) -> ClusterBootstrap:
    r"""The paired ratio of means :math:`\sum_i x_i / \sum_i y_i` with its cluster
    bootstrap interval (run :math:`i` gives both :math:`x_i` and :math:`y_i`, resampled
    together).

    Parameters
    ----------
    x, y : array_like of float, shape (n,)
        The paired values (e.g. two systems' FTLE on the same ICs, or the counts and the
        windows of the runs).
    n_boot, level, rng
        As in `cluster_bootstrap`.

    Returns
    -------
    ClusterBootstrap
        ``estimate = sum(x) / sum(y)``.

    Examples
    --------
    >>> from kicktimes.stats import ratio_of_means
    >>> res = ratio_of_means([2.0, 4.0, 6.0], [1.0, 2.0, 3.0], rng=0)
    >>> float(res.estimate), res.ci_low, res.ci_high
    (2.0, 2.0, 2.0)
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if x.ndim != 1 or x.shape != y.shape or not x.size:
        raise ValueError(f"x and y must be 1-d of the same length >= 1, got shapes "
                         f"{x.shape} and {y.shape}")
    return cluster_bootstrap(lambda idx: x[idx].sum(axis=1) / y[idx].sum(axis=1), x.size,
                             n_boot=n_boot, level=level, rng=rng)


def _matrix(frame, column, radii, ics):
    return frame[column].unstack("ic").reindex(index=radii, columns=ics).to_numpy(float)


def paired_ratio(numerator, denominator, *, rng, n_boot=2000, level=0.95, resamples=None,
                 interval="percentile", draws=False):
    r"""Ratio of ensemble means per radius and averaged over radii, with bootstrap CIs.

    Parameters
    ----------
    numerator, denominator : pandas.Series
        Indexed by ``(radius, ic)``; a pair enters where both are finite.
    rng : numpy.random.Generator
        The bootstrap's stream (seeded by the caller: the report is deterministic).
    n_boot : int
        Bootstrap resamples of the IC indices.
    level : float
        Confidence level of the percentile intervals.
    resamples : dict, optional
        Bootstrap draws shared between calls. The resample counts of ``n`` ICs are drawn
        from ``rng`` by the first call and kept here under ``(n, n_boot)``; later calls
        with as many ICs reuse them, so that every ratio's CI comes from the same
        resampled ICs (one joint bootstrap of the ICs), drawn once: the multinomial draw
        is most of a call's time (about 0.1 s for 2000 resamples of 1000 ICs).
    interval : {"percentile", "bca"}
        The overall ratio's interval: the bootstrap percentiles, or the bias-corrected
        and accelerated (BCa) interval (Efron 1987), whose acceleration comes from the
        jackknife over ICs: second-order accurate where per-IC values are skewed or
        heavy-tailed (sticky runs). Per-radius intervals are percentile intervals.
    draws : bool
        Also return the overall ratio of every resample (``n_boot`` values, NaN where a
        resample has no usable radius), aligned across calls that share ``resamples``:
        for statistics of several ratios at once (differences, decompositions).

    Returns
    -------
    (pandas.DataFrame, dict) or (pandas.DataFrame, dict, numpy.ndarray)
        Per radius ``radius, n_pairs, ratio, ci_low, ci_high`` and the overall
        ``{"ratio", "ci_low", "ci_high", "n_ics", "n_radii"}``; with ``draws``, the
        resamples' overall ratios.

    Notes
    -----
    Per radius :math:`\rho_r = \sum_i x_{ri} / \sum_i y_{ri}` over the paired ICs; overall
    :math:`\bar\rho = \frac{1}{R}\sum_r \rho_r` (each radius weighs the same). One
    bootstrap resample draws IC indices with replacement and applies them at every
    radius, so the correlation of one IC across radii is kept.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> idx = pd.MultiIndex.from_product([[0.01, 0.02], range(50)], names=["radius", "ic"])
    >>> y = pd.Series(np.random.default_rng(0).uniform(1, 2, 100), index=idx)
    >>> per_radius, overall = paired_ratio(0.5 * y, y, rng=np.random.default_rng(1))
    >>> round(overall["ratio"], 12), round(overall["ci_high"], 12)
    (0.5, 0.5)
    """
    if resamples is not None and not isinstance(resamples, dict):
        raise TypeError(f"resamples must be None or a dict, got {type(resamples).__name__}")
    frame = pd.concat({"x": numerator, "y": denominator}, axis=1)
    radii = np.sort(frame.index.get_level_values("radius").unique().to_numpy())
    ics = np.sort(frame.index.get_level_values("ic").unique().to_numpy())
    x, y = _matrix(frame, "x", radii, ics), _matrix(frame, "y", radii, ics)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = np.where(ok, x, 0.0), np.where(ok, y, 0.0)
    n = ics.size
    counts = None if resamples is None else resamples.get((n, n_boot))
    if counts is None:
        counts = resample_counts(n, n_boot=n_boot, rng=rng)
        if resamples is not None:
            resamples[(n, n_boot)] = counts
    with np.errstate(invalid="ignore", divide="ignore"):
        point = x.sum(axis=1) / y.sum(axis=1)
        boot = (counts @ x.T) / (counts @ y.T)  # (n_boot, n_radii)
    point = np.where(ok.any(axis=1), point, np.nan)
    a = _tail_percent(level)
    usable = np.isfinite(point)
    low = high = np.full(radii.size, np.nan)
    if n_boot:
        # a radius without any usable resample gives an all-NaN column: its CI is NaN
        low, high = percentile_interval(boot, level=level, axis=0)
    per_radius = pd.DataFrame(
        {
            "radius": radii,
            "n_pairs": ok.sum(axis=1),
            "ratio": point,
            "ci_low": low,
            "ci_high": high,
        }
    )
    if not usable.any():
        empty = {"ratio": math.nan, "ci_low": math.nan, "ci_high": math.nan, "n_ics": n,
                 "n_radii": 0}
        return (per_radius, empty, np.full(n_boot, np.nan)) if draws else (per_radius, empty)
    aligned = boot[:, usable].mean(axis=1)
    overall_boot = aligned[np.isfinite(aligned)]
    estimate = float(point[usable].mean())
    lo_q, hi_q = a, 100 - a
    if interval == "bca" and overall_boot.size:
        lo_q, hi_q = _bca_levels(overall_boot, estimate, x[usable], y[usable], level)
    elif interval not in ("percentile", "bca"):
        raise ValueError(f"interval must be 'percentile' or 'bca', got {interval!r}")
    overall = {
        "ratio": estimate,
        "ci_low": float(np.percentile(overall_boot, lo_q)) if overall_boot.size else math.nan,
        "ci_high": float(np.percentile(overall_boot, hi_q)) if overall_boot.size else math.nan,
        "n_ics": n,
        "n_radii": int(usable.sum()),
    }
    return (per_radius, overall, aligned) if draws else (per_radius, overall)


def _bca_levels(boot, estimate, x, y, level):
    r"""The percentiles (0-100) of the BCa interval of the radius-averaged ratio.

    Bias correction :math:`z_0 = \Phi^{-1}(\#\{\theta^* < \hat\theta\}/B)`; acceleration
    :math:`a = \sum_i d_i^3 / (6 (\sum_i d_i^2)^{3/2})` with :math:`d_i` the deviations of
    the leave-one-IC-out estimates from their mean (``x``, ``y``: radius x IC sums with
    unpaired entries zeroed); levels :math:`\Phi(z_0 + (z_0 + z_q)/(1 - a(z_0 + z_q)))`.
    """
    from scipy.special import ndtr, ndtri

    sx, sy = x.sum(axis=1, keepdims=True), y.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        jack = ((sx - x) / (sy - y)).mean(axis=0)  # leave IC i out, at every radius
    jack = jack[np.isfinite(jack)]
    d = jack.mean() - jack
    denom = 6.0 * (d @ d) ** 1.5
    acc = float((d**3).sum() / denom) if denom > 0 else 0.0
    below = np.mean(boot < estimate) + 0.5 * np.mean(boot == estimate)
    z0 = float(ndtri(np.clip(below, 1e-12, 1 - 1e-12)))
    out = []
    for q in ((1 - level) / 2, 1 - (1 - level) / 2):
        zq = z0 + ndtri(q)
        out.append(100.0 * float(ndtr(z0 + zq / (1.0 - acc * zq))))
    return out[0], out[1]


def paired_median(numerator, denominator, *, rng, n_boot=1000, level=0.95):
    r"""Median over ICs of the per-IC ratio, per radius, averaged over radii, with a CI.

    Parameters
    ----------
    numerator, denominator : pandas.Series
        Indexed by ``(radius, ic)``; a pair enters where both are finite and the
        denominator is non-zero. A radius where at least half of the ratios are 0 has no
        median ratio (it would be 0 whatever the other half): it is left out, and with no
        radius left the result is NaN (verdict inconclusive).
    rng : numpy.random.Generator
        The bootstrap's stream.
    n_boot : int
        Resamples of the IC indices (one resample is applied at every radius).
    level : float
        Confidence level of the percentile interval.

    Returns
    -------
    dict
        ``ratio, ci_low, ci_high, n_pairs`` and ``per_radius``, a DataFrame ``radius,
        n_pairs, ratio, ci_low, ci_high`` (per-radius medians and their intervals).

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> idx = pd.MultiIndex.from_product([[0.01, 0.02], range(9)], names=["radius", "ic"])
    >>> y = pd.Series(np.arange(1.0, 19.0), index=idx)
    >>> x = 0.5 * y
    >>> x.iloc[0] = 1e6  # one extreme run does not move a median
    >>> from kicktimes.stats import paired_median
    >>> paired_median(x, y, rng=np.random.default_rng(0))["ratio"]
    0.5
    """
    frame = pd.concat({"x": numerator, "y": denominator}, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = (frame["x"] / frame["y"]).where(lambda s: np.isfinite(s))
    table = q.unstack("ic")  # radius x ic
    values = table.to_numpy(float, copy=True)
    # a median of ratios at least half of which are 0 (a kicked run without a single
    # recurrence line, say) is 0 whatever the rest: no estimate at that radius
    finite = np.isfinite(values)
    with np.errstate(invalid="ignore", divide="ignore"):
        zero_share = (values == 0).sum(axis=1) / finite.sum(axis=1)
    values[zero_share >= 0.5] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a radius without a finite pair
        per_radius = pd.Series(nanmedian(values, axis=1), index=table.index, dtype=float)
    usable = np.isfinite(per_radius.to_numpy())
    n_pairs = int(np.isfinite(values).sum())
    if not usable.any():
        curve = pd.DataFrame({"radius": table.index.to_numpy(float), "n_pairs": 0,
                              "ratio": np.nan, "ci_low": np.nan, "ci_high": np.nan})
        return {"ratio": math.nan, "ci_low": math.nan, "ci_high": math.nan, "n_pairs": n_pairs,
                "per_radius": curve}
    n = values.shape[1]
    idx = resample_indices(n, n_boot=n_boot, rng=rng)
    # boot_r[b] = nanmedian(values[:, idx[b]], axis=1), bit for bit, without a sort each
    boot_r = bootstrap_nanmedians(values, idx)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a resample without a finite pair
        boot = np.nanmean(boot_r[:, usable], axis=1)
    low_r, high_r = percentile_interval(boot_r, level=level, axis=0)
    low, high = percentile_interval(boot, level=level)
    curve = pd.DataFrame({"radius": table.index.to_numpy(float),
                          "n_pairs": np.isfinite(values).sum(axis=1),
                          "ratio": per_radius.to_numpy(), "ci_low": low_r, "ci_high": high_r})
    return {
        "ratio": float(per_radius[usable].mean()),
        "ci_low": low,
        "ci_high": high,
        "n_pairs": n_pairs,
        "per_radius": curve,
    }
