r"""The hazard of inter-event intervals against the time since the last event.

A homogeneous Poisson process has a flat hazard: whatever time has passed since the last
event, the next one comes at the same rate. A mixture of rates (a Cox process whose rate
is redrawn at every event) has a decreasing one, because the long waits are spent in the
slow states. :func:`interval_hazard` estimates the hazard per bin of elapsed time from
complete and right-censored intervals (a life table with exact exposure) and tests
whether it is flat.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
import scipy.stats as sps

from kicktimes.validation import keyword_only_after

from ._checks import check_int, check_intervals, check_real

__all__ = ["HazardTable", "interval_hazard"]


@dataclass(frozen=True, repr=False)
class HazardTable:
    """Result of :func:`interval_hazard`.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per bin ``[t_low, t_high)`` of time since the last event: ``t_low``,
        ``t_high``, ``t_mid``, ``at_risk`` (intervals still running at ``t_low``),
        ``events`` (complete intervals ending in the bin), ``exposure`` (time spent in the
        bin by all intervals), ``hazard`` (``events / exposure``) and its ``ci_low``,
        ``ci_high``.
    rate : float
        The constant hazard that fits best, ``sum(events) / sum(exposure)``: the
        exponential rate of the censored sample.
    statistic, df, pvalue : float, int, float
        Likelihood-ratio test of a flat hazard (see :func:`interval_hazard`).
    level : float
        Confidence level of the intervals.
    """

    table: pd.DataFrame
    rate: float
    statistic: float
    df: int
    pvalue: float
    level: float

    @property
    def ratio_first_to_rate(self) -> float:
        """Hazard of the first bin over the constant rate (1 for a Poisson process)."""
        return float(self.table["hazard"].iloc[0] / self.rate)

    def to_frame(self) -> pd.DataFrame:
        """The hazard per bin (`table`, a copy)."""
        return self.table.copy()

    def summary(self) -> str:
        """The table and the flatness test as text."""
        head = (f"hazard of {int(self.table['events'].sum())} intervals in "
                f"{len(self.table)} bins; constant rate {self.rate:.4g}; flat hazard: "
                f"LR = {self.statistic:.4g}, df = {self.df}, p = {self.pvalue:.3g}")
        cols = ["t_low", "t_high", "at_risk", "events", "hazard", "ci_low", "ci_high"]
        return head + "\n" + self.table[cols].to_string(float_format=lambda v: f"{v:.4g}")

    def __repr__(self) -> str:
        return (f"HazardTable(bins={len(self.table)}, rate={self.rate:.4g}, "
                f"statistic={self.statistic:.4g}, df={self.df}, pvalue={self.pvalue:.3g})")


def _edges(x, y_max, bins):
    """``bins`` bins holding equal numbers of complete intervals, from 0 to ``y_max``."""
    inner = np.quantile(x, np.arange(1, bins) / bins) if x.size else np.empty(0)
    edges = np.unique(np.concatenate([[0.0], inner, [y_max]]))
    return edges


@keyword_only_after(1, since="0.2.0", names=('censored',))
def interval_hazard(complete, *, censored=None, bins=10, edges=None,
                    level=0.95) -> HazardTable:
    r"""Piecewise-constant hazard of intervals, with exact Poisson intervals per bin and a
    test of a flat hazard.

    Parameters
    ----------
    complete : array_like
        Complete intervals (time from an event to the next one), positive.
    censored : array_like, optional
        Right-censored intervals (the interval running when observation stopped): they add
        exposure, but no event.
    bins : int, optional
        Number of bins when ``edges`` is not given: quantiles of the complete intervals,
        so that each bin holds about as many events; the last bin ends at the longest
        interval (complete or censored).
    edges : array_like, optional
        Increasing bin edges starting at 0; intervals longer than the last edge add
        exposure up to it only.
    level : float, optional
        Confidence level of the per-bin intervals.

    Returns
    -------
    HazardTable
        The per-bin table, the constant rate and the flatness test.

    Notes
    -----
    For bin :math:`j = [a_j, b_j)` the exposure is
    :math:`E_j = \sum_i \min(\max(y_i - a_j, 0), b_j - a_j)` over all intervals
    :math:`y_i`, complete or censored, and :math:`d_j` counts the complete intervals
    ending in the bin. Under a hazard constant on each bin the likelihood is
    :math:`\prod_j h_j^{d_j} e^{-h_j E_j}`, so :math:`\hat h_j = d_j / E_j` (the actuarial
    life table with exact exposure; right censoring enters as exposure without an event)
    and :math:`d_j` is Poisson given :math:`E_j`: the interval is Garwood's,
    :math:`[\chi^2_{2d_j}(\alpha/2) / 2, \chi^2_{2d_j+2}(1 - \alpha/2) / 2] / E_j`.

    A Poisson process has exponential intervals, i.e. :math:`h_j = h` for all j, with
    MLE :math:`\hat h = \sum d_j / \sum E_j`. The likelihood-ratio statistic
    :math:`G = 2 \sum_j d_j \log(\hat h_j / \hat h)` (the exposure terms cancel) is
    :math:`\chi^2_{J - 1}` under that null. The intervals are taken as independent: for
    intervals of one sequence that are serially dependent (sticky runs), the test and the
    per-bin intervals are too narrow; a bootstrap over sequences is the remedy.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> rng = np.random.default_rng(0)
    >>> flat = stats.interval_hazard(rng.exponential(2.0, 4000), bins=8)
    >>> round(flat.rate, 1), bool(flat.pvalue > 0.01)
    (0.5, True)
    >>> falling = stats.interval_hazard(rng.gamma(0.5, 4.0, 4000), bins=8)
    >>> bool(falling.pvalue < 1e-6), bool(falling.ratio_first_to_rate > 2)
    (True, True)
    """
    x = check_intervals("complete", complete, allow_empty=False)
    c = (np.empty(0) if censored is None
         else check_intervals("censored", censored, allow_zero=True))
    c = c[c > 0]
    level = check_real("level", level, low=0.0, high=1.0)
    y = np.concatenate([x, c])
    if edges is None:
        bins = check_int("bins", bins, low=1)
        edges = _edges(x, float(y.max()), bins)
    else:
        edges = np.asarray(edges, float)
        if (edges.ndim != 1 or edges.size < 2 or edges[0] != 0.0
                or not np.all(np.isfinite(edges)) or np.any(np.diff(edges) <= 0)):
            raise ValueError(f"edges must be increasing finite numbers starting at 0, "
                             f"got {edges.tolist()!r}")
    lo, hi = edges[:-1], edges[1:]
    # exposure: time each interval spends in each bin (n x J, at most a few million cells)
    exposure = np.zeros(lo.size)
    at_risk = np.zeros(lo.size, int)
    for start in range(0, y.size, 200_000):
        part = y[start:start + 200_000, None]
        exposure += np.clip(part - lo, 0.0, hi - lo).sum(axis=0)
        at_risk += (part >= lo).sum(axis=0)
    # the last bin is closed, so the longest complete interval counts as its event
    which = np.searchsorted(edges, x, side="right") - 1
    which[x == edges[-1]] = lo.size - 1
    events = np.bincount(which[(which >= 0) & (which < lo.size)], minlength=lo.size)
    alpha = 1.0 - level
    with np.errstate(divide="ignore", invalid="ignore"):
        hazard = events / exposure
        low = np.where(events > 0, sps.chi2.ppf(alpha / 2, 2 * events) / 2, 0.0) / exposure
        high = sps.chi2.ppf(1 - alpha / 2, 2 * events + 2) / 2 / exposure
    table = pd.DataFrame({
        "t_low": lo, "t_high": hi, "t_mid": (lo + hi) / 2, "at_risk": at_risk,
        "events": events, "exposure": exposure, "hazard": hazard, "ci_low": low,
        "ci_high": high,
    })
    rate = events.sum() / exposure.sum()
    used = events > 0
    stat = float(2.0 * np.sum(events[used] * np.log(hazard[used] / rate)))
    df = int((exposure > 0).sum()) - 1
    pvalue = float(sps.chi2.sf(stat, df)) if df > 0 else math.nan
    return HazardTable(table, float(rate), stat, df, pvalue, level)
