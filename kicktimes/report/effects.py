r"""Effect sizes with 95 % confidence intervals and the verdict rules of the Findings.

Every comparison of the report is a ratio (a kicked system over the two-particle system,
or an observed rate over the kinetic rate) with a 95 % confidence interval, and every
verdict follows one printed rule (:func:`ratio_rule`, :data:`SHARE_RULE`), so no verdict
is typed by hand. The record and the rules are those of every page kicktimes writes
(:mod:`kicktimes.stats.findings`; ``kicktimes analyze`` states its findings with them):
an :class:`Effect` is a :class:`kicktimes.stats.Finding` with the compared system.

The bootstrap resamples initial conditions: the same IC index is the same initial
condition in every system and at every radius (the paper's design), so one resample of IC
indices is applied to all systems and radii at once (a paired, clustered bootstrap).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from kicktimes.stats import resample_counts
from kicktimes.stats.findings import (
    SHARE_RULE,
    Finding,
    clopper_pearson,
    effect_statement,
    ratio_rule,
    ratio_verdict,
    share_verdict,
)

__all__ = [
    "Effect",
    "ratio_rule",
    "SHARE_RULE",
    "BUILT_IN",
    "ratio_verdict",
    "share_verdict",
    "paired_ratio",
    "store_ratio",
    "clopper_pearson",
]

#: appended to a verdict whose agreement is guaranteed by how the kicked system is built
BUILT_IN = "built in"


@dataclass(frozen=True)
class Effect(Finding):
    """A finding of the report (:class:`kicktimes.stats.Finding`): an effect size, its
    95 % CI, how the CI was computed and the verdict, for one kicked ``system`` against
    the two-particle one (or for the store, ``system=""``).

    Attributes
    ----------
    question : str
        The question answered (e.g. ``"FTLE"``).
    system : str
        The kicked system compared with the two-particle one, or ``""``.
    quantity : str
        What ``estimate`` is (e.g. ``"ratio of means, kicked / two-particle"``).
    estimate, ci_low, ci_high : float
        The effect and its 95 % confidence interval.
    verdict : str
        From the printed rule; ``"… (built in)"`` when the agreement holds by construction.
    rule : str
        The rule that turned the interval into the verdict.
    method : str
        How the interval was computed.
    detail : str
        The supporting numbers (per radius, medians, predictions).
    statement : str
        One sentence, derived from the rest: question, effect, CI and verdict.
    """

    statement: str = field(init=False, default="")
    system: str = ""

    def __post_init__(self):
        from kicktimes.report.figures import system_label

        who = f", {system_label(self.system)} vs two-particle" if self.system else ""
        text = effect_statement(self.question + who, self.quantity, self.estimate, self.ci_low,
                                self.ci_high, self.method, self.verdict)
        object.__setattr__(self, "statement", text)

    @classmethod
    def of_ratio(cls, question, system, quantity, overall, *, tolerance, detail="", method=None,
                 verdict=None):
        """The Effect of a ratio and its bootstrap CI, ``overall`` as :func:`paired_ratio`
        returns it: the verdict of :func:`ratio_verdict` (unless ``verdict`` is given) under
        the printed :func:`ratio_rule`, the method "paired bootstrap over N ICs" (unless
        ``method`` is given)."""
        low, high = overall["ci_low"], overall["ci_high"]
        return cls(
            question=question,
            system=system,
            quantity=quantity,
            estimate=overall["ratio"],
            ci_low=low,
            ci_high=high,
            verdict=verdict or ratio_verdict(low, high, tolerance),
            rule=ratio_rule(tolerance),
            method=method or f"paired bootstrap over {overall['n_ics']} ICs",
            detail=detail,
        )


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
        counts = resample_counts(n, n_boot, rng)
        if resamples is not None:
            resamples[(n, n_boot)] = counts
    with np.errstate(invalid="ignore", divide="ignore"):
        point = x.sum(axis=1) / y.sum(axis=1)
        boot = (counts @ x.T) / (counts @ y.T)  # (n_boot, n_radii)
    point = np.where(ok.any(axis=1), point, np.nan)
    a = (1 - level) / 2 * 100
    usable = np.isfinite(point)
    finite_boot = np.where(np.isfinite(boot), boot, np.nan)
    low = high = np.full(radii.size, np.nan)
    if n_boot:
        with warnings.catch_warnings():
            # a radius without any usable resample gives an all-NaN column: its CI is NaN
            warnings.simplefilter("ignore", RuntimeWarning)
            low = np.nanpercentile(finite_boot, a, axis=0)
            high = np.nanpercentile(finite_boot, 100 - a, axis=0)
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


def store_ratio(ctx, numerator, denominator):
    """:func:`paired_ratio` under the store's bootstrap: the Findings' stream
    (``ctx.boot_rng()``), ``ctx.n_boot`` resamples, shared by every ratio of the store
    (``ctx.resamples``)."""
    return paired_ratio(numerator, denominator, rng=ctx.boot_rng(), n_boot=ctx.n_boot,
                        resamples=ctx.resamples)


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
