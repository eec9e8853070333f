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
* `cluster_bootstrap`: both, for a statistic given as a function of the indices;
* `ratio_of_means`: the paired ratio :math:`\sum x_i / \sum y_i` with its interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kicktimes._validation import check_int, check_real, check_rng

__all__ = ["ClusterBootstrap", "cluster_bootstrap", "percentile_interval", "ratio_of_means",
           "resample_counts", "resample_indices"]


def resample_indices(n_clusters, n_boot, rng=None, *, with_identity=False, chunk=None):
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
    >>> resample_indices(4, 2, rng=0, with_identity=True)
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


def resample_counts(n_clusters, n_boot, rng=None):
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
    >>> resample_counts(4, 3, rng=0).sum(axis=1).tolist()
    [4.0, 4.0, 4.0]
    """
    n = check_int("n_clusters", n_clusters, low=1)
    b = check_int("n_boot", n_boot, low=0)
    return check_rng(rng).multinomial(n, np.full(n, 1.0 / n), size=b).astype(float)


def percentile_interval(replicates, level=0.95):
    r"""Percentile interval of the finite bootstrap replicates.

    ``(p_a, p_{100-a})`` with ``a = (1 - level) / 2 * 100`` percent, `numpy.percentile`'s
    linear interpolation, over the finite values only (a resample whose statistic is
    undefined, e.g. a ratio over a resample without events, drops out).

    Parameters
    ----------
    replicates : array_like of float
        The replicates :math:`\hat\theta^*_b` (any shape; flattened).
    level : float
        Coverage, in (0, 1).

    Returns
    -------
    (float, float)
        ``(low, high)``; ``(nan, nan)`` when no replicate is finite.

    Examples
    --------
    >>> from kicktimes.stats import percentile_interval
    >>> percentile_interval([1.0, 2.0, float("nan"), 3.0, 4.0], level=0.5)
    (1.75, 3.25)
    """
    level = check_real("level", level, low=0.0, high=1.0)
    v = np.asarray(replicates, float).ravel()
    v = v[np.isfinite(v)]
    if not v.size:
        return math.nan, math.nan
    a = (1 - level) / 2 * 100
    return float(np.percentile(v, a)), float(np.percentile(v, 100 - a))


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
        np.asarray(statistic(rng.integers(0, n, size=(min(step, b - m), n))), float)
        for m in range(0, b, step)])
    if replicates.ndim == 1:
        low, high = percentile_interval(replicates, level)
        return ClusterBootstrap(float(estimate), low, high, replicates, level, n)
    bounds = np.array([percentile_interval(replicates[:, j], level)
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
