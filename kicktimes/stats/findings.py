r"""Findings: one computed statement per question, with the rule that reached its verdict.

The record (:class:`Finding`), the verdict rules (:func:`ratio_verdict`, :func:`ratio_rule`,
:func:`share_verdict`, :data:`SHARE_RULE`) and the exact binomial interval
(:func:`clopper_pearson`) are shared by every page kicktimes writes: the findings of an
:class:`~kicktimes.stats.analyze.Analysis` (:func:`findings`, ``kicktimes analyze``) and
the sweep report's (:mod:`kicktimes.report.findings`, whose effects are Findings with an
effect size and the compared system, under the report's controls).

Every statement is built from the result's tables (never typed), carries its effect size
with a 95 % interval where one exists, and a verdict reached by a rule that is printed
beside it (``Finding.rule``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats as sps

from kicktimes._results import (
    Result,
    format_interval,  # one place for result formatting
)
from kicktimes.validation import keyword_only_after

from .margins import D_MARGIN, DIAGNOSTIC_MARGINS, FINE_MARGIN, MARGIN, RR_MARGIN, margin_of

__all__ = [
    "MARGIN",
    "Finding",
    "findings",
    "findings_table",
    "ratio_verdict",
    "ratio_rule",
    "ratio_interval",
    "robust_verdict",
    "format_interval",
    "rejection_verdict",
    "rejection_rule",
    "poisson_verdict",
    "poisson_rule",
    "share_verdict",
    "SHARE_RULE",
    "clopper_pearson",
    "D_MARGIN",
    "FINE_MARGIN",
    "DIAGNOSTIC_MARGINS",
    "RR_MARGIN",
    "margin_of",
    "null_verdict",
    "null_rule",
    "equivalence_sample_size",
    "share_ratio_sample_size",
    "effect_statement",
    "format_p",
]

#: how a share's verdict is decided against a reference level ``{level}``
SHARE_RULE = (
    "above: the 95 % CI of the share lies above {level:g}; below: it lies below {level:g}; "
    "inconclusive: it contains {level:g}"
)


@keyword_only_after(0, since="0.2.0")
def ratio_rule(*, tolerance=0.1) -> str:
    """The printed rule of :func:`ratio_verdict` for a band of half-width ``tolerance``.

    >>> ratio_rule(tolerance=0.1)[:58]
    'within 10 %: the whole 95 % CI of the ratio lies in [0.9, '
    """
    p, lo, hi = f"{100 * tolerance:g}", f"{1 - tolerance:g}", f"{1 + tolerance:g}"
    return (
        f"within {p} %: the whole 95 % CI of the ratio lies in [{lo}, {hi}] (the two values "
        f"agree to {p} %, an equivalence test with a margin stated in advance; a CI inside "
        f"the band may still exclude 1, which then measures a real difference smaller than "
        f"the band); higher: the CI lies entirely above {hi}; lower: it lies entirely below "
        f"{lo}; inconclusive: the CI straddles a band edge. Robust: every control gives the "
        f"same verdict and no control's CI lies above 1 while another's lies below 1"
    )




@keyword_only_after(2, since="0.2.0")
def ratio_verdict(low, high, *, tolerance=MARGIN):
    """``"within 10 %"``, ``"higher"``, ``"lower"`` or ``"inconclusive"`` for a ratio's 95 % CI.

    The verdict of every ratio kicktimes states (:func:`ratio_rule` prints it): *within* when
    the whole interval lies in ``[1 - tolerance, 1 + tolerance]`` (an equivalence test),
    *higher* when it lies entirely above ``1 + tolerance``, *lower* when it lies entirely
    below ``1 - tolerance``, *inconclusive* otherwise (and when an endpoint is not finite).
    Decide on unrounded values; print with :func:`format_interval`.

    Examples
    --------
    >>> ratio_verdict(0.95, 1.04), ratio_verdict(0.3, 0.4), ratio_verdict(1.2, 1.9)
    ('within 10 %', 'lower', 'higher')
    >>> ratio_verdict(0.85, 1.0), ratio_verdict(0.8, 1.2, tolerance=0.25)
    ('inconclusive', 'within 25 %')
    """
    if not (np.isfinite(low) and np.isfinite(high)):
        return "inconclusive"
    if low >= 1 - tolerance and high <= 1 + tolerance:
        return f"within {100 * tolerance:g} %"
    if high < 1 - tolerance:
        return "lower"
    if low > 1 + tolerance:
        return "higher"
    return "inconclusive"


def ratio_interval(estimate, low, high, reference, ref_low, ref_high):
    r"""``(ratio, low, high)``: the ratio of two independent positive estimates and its 95 %
    interval, each estimate's interval read as ±1.96 standard errors of its logarithm and
    the two combined in quadrature,

    .. math:: \log(x/y) \pm 1.96\sqrt{s_x^2 + s_y^2}, \qquad
              s = \frac{\log(\text{high}/\text{low})}{2 \cdot 1.96}.

    For estimates from independent samples (different seeds, different runs); for paired
    ones bootstrap the ratio itself. NaN where an interval is not positive and finite.

    Examples
    --------
    >>> r, lo, hi = ratio_interval(1.1, 1.0, 1.2, 1.0, 0.95, 1.05)
    >>> round(r, 3), round(lo, 3), round(hi, 3)
    (1.1, 0.991, 1.221)
    """
    values = np.array([estimate, low, high, reference, ref_low, ref_high], float)
    if not (np.isfinite(values).all() and (values > 0).all()):
        return math.nan, math.nan, math.nan
    ratio = estimate / reference
    se = math.hypot(math.log(high / low), math.log(ref_high / ref_low)) / (2 * 1.96)
    return ratio, ratio * math.exp(-1.96 * se), ratio * math.exp(1.96 * se)


@keyword_only_after(3, since="0.2.0")
def robust_verdict(verdicts, lows, highs, *, level=1.0):
    """Whether a comparison keeps its verdict and its direction under every control.

    ``(robust, reason)``: robust when every control gives the same verdict **and** no
    control's CI lies entirely above ``level`` while another's lies entirely below it (a
    change of direction is never robust, even when both sides "differ"). ``reason`` names
    what breaks it: ``""``, ``"verdict"`` or ``"direction"``.

    Examples
    --------
    >>> robust_verdict(["lower", "lower"], [0.3, 0.31], [0.33, 0.35])
    (True, '')
    >>> robust_verdict(["higher", "lower"], [1.85, 0.75], [1.9, 0.8])
    (False, 'direction')
    >>> robust_verdict(["inconclusive", "inconclusive"], [1.08, 0.89], [1.16, 0.95])
    (False, 'direction')
    >>> robust_verdict(["within 10 %", "inconclusive"], [0.95, 0.85], [1.05, 1.0])
    (False, 'verdict')
    """
    lows, highs = np.asarray(lows, float), np.asarray(highs, float)
    if (lows > level).any() and (highs < level).any():
        return False, "direction"
    if len(set(verdicts)) > 1:
        return False, "verdict"
    return True, ""


@keyword_only_after(2, since="0.2.0")
def rejection_verdict(low, high, *, alpha, margin=0.5):
    """The verdict on a share of runs that reject a test at level ``alpha``.

    ``"nominal"`` when the 95 % CI lies in ``[alpha (1 - margin), alpha (1 + margin)]`` (an
    equivalence test: the runs reject as often as a process that satisfies the null);
    ``"above nominal"`` when it lies entirely above that band (the null fails in more runs
    than the test's size allows); ``"below nominal"`` when entirely below; ``"inconclusive"``
    otherwise.

    Examples
    --------
    >>> rejection_verdict(0.37, 0.41, alpha=0.05), rejection_verdict(0.037, 0.054, alpha=0.05)
    ('above nominal', 'nominal')
    >>> rejection_verdict(0.03, 0.09, alpha=0.05)
    'inconclusive'
    """
    if not (np.isfinite(low) and np.isfinite(high)):
        return "inconclusive"
    lo_band, hi_band = alpha * (1 - margin), alpha * (1 + margin)
    if low >= lo_band and high <= hi_band:
        return "nominal"
    if low > hi_band:
        return "above nominal"
    if high < lo_band:
        return "below nominal"
    return "inconclusive"


@keyword_only_after(0, since="0.2.0")
def rejection_rule(*, alpha=0.05, margin=0.5) -> str:
    """The printed rule of :func:`rejection_verdict`."""
    lo, hi = alpha * (1 - margin), alpha * (1 + margin)
    return (f"nominal: the 95 % CI of the share of runs rejected at α = {alpha:g} lies in "
            f"[{lo:g}, {hi:g}] (the share a process satisfying the null gives, within "
            f"{100 * margin:g} % of α); above / below nominal: it lies entirely above / below "
            "that band; inconclusive otherwise")




@keyword_only_after(2, since="0.2.0")
def null_verdict(low, high, *, margin):
    """A statistic read against its null stream: the 95 % CI ``[low, high]`` of the
    difference *statistic - its value on null streams shaped like the runs*.

    ``"at its null"`` when the whole CI lies in ``[-margin, margin]`` (an equivalence test,
    the margin stated in advance); ``"above its null"`` / ``"below its null"`` when it lies
    entirely above ``margin`` / below ``-margin``; ``"inconclusive"`` otherwise (and when an
    endpoint is not finite). A statistic whose null value is not exactly 1 (a dispersion
    index over runs of unequal rates, a hazard of binned intervals) is read this way, never
    against 1. An inconclusive CI that excludes 0 is read further by
    `kicktimes.stats.readings.null_reading` (a real departure whose size the margin does
    not resolve).

    Examples
    --------
    >>> null_verdict(0.005, 0.077, margin=D_MARGIN), null_verdict(1.2, 1.7, margin=D_MARGIN)
    ('inconclusive', 'above its null')
    >>> null_verdict(-0.06, 0.065, margin=D_MARGIN)
    'at its null'
    """
    if not (np.isfinite(low) and np.isfinite(high)):
        return "inconclusive"
    if -margin <= low and high <= margin:
        return "at its null"
    if low > margin:
        return "above its null"
    if high < -margin:
        return "below its null"
    return "inconclusive"


@keyword_only_after(0, since="0.2.0")
def null_rule(*, margin, name="D") -> str:
    """The printed rule of :func:`null_verdict` for ``name`` with ``margin``."""
    return (f"{name} is read against its null stream's {name} (the same statistic on Poisson "
            f"streams shaped like the runs): at its null when the 95 % CI of the difference "
            f"lies in [-{margin:g}, {margin:g}], above / below its null when it lies entirely "
            f"beyond {margin:g} / -{margin:g}, inconclusive otherwise")


@keyword_only_after(2, since="0.2.0", names=("margin",))
def equivalence_sample_size(se, n, *, margin, level=0.95, power=0.8):
    """The number of units (ICs, runs) at which a difference with standard error ``se`` at
    ``n`` units gets its ``level`` CI inside ``[-margin, margin]`` with probability
    ``power`` when the true difference is 0: ``se`` scales as ``1/sqrt(n)`` and the CI
    ``estimate +- z_level se`` must fit in the margin, so ``se_needed = margin / (z_level +
    z_power)`` with ``z_power = Phi^-1((1 + power) / 2)`` (the estimate may fall on either
    side) and ``n_needed = n (se / se_needed)^2``, never below ``n``.

    Examples
    --------
    >>> equivalence_sample_size(0.05, 400, margin=0.07)      # a half-width of 0.1 at 400 runs
    2145
    >>> equivalence_sample_size(0.01, 400, margin=0.07)
    400
    """
    from scipy.stats import norm

    se = float(se)
    if not (math.isfinite(se) and se > 0):
        raise ValueError(f"se must be a finite number > 0, got {se!r}")
    if not (isinstance(n, int | np.integer) and n >= 1):
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    if not (math.isfinite(margin) and margin > 0):
        raise ValueError(f"margin must be a finite number > 0, got {margin!r}")
    z = norm.ppf(0.5 + level / 2) + norm.ppf(0.5 + power / 2)
    return max(int(n), int(math.ceil(n * (se * z / margin) ** 2)))


@keyword_only_after(2, since="0.2.0", names=("null_level", "dispersion_low", "dispersion_high"))
def poisson_verdict(reject_low, reject_high, *, null_level, dispersion_low, dispersion_high,
                    margin=0.5, band=0.1, against_null=False):
    """One standard for "Poisson": a calibrated test and an effect outside a stated band.

    A stream is read against two things stated before any data: the share of runs that a
    battery test rejects, compared with ``null_level``, the share that streams satisfying
    the null reject through the same test, windows and runs (a null calibration, not the
    nominal α); and its dispersion index D (variance over mean of the counts), compared
    with the band ``[1 - band, 1 + band]``, the same equivalence margin as every ratio
    (:func:`ratio_verdict`). The verdict is

    - ``"not Poisson"``: the rejection share lies above the calibrated band
      (:func:`rejection_verdict` with ``alpha = null_level``) **and** D's CI lies entirely
      outside ``[1 - band, 1 + band]``: a calibrated test rejects and the effect is large;
    - ``"not Poisson, D within 10 %"``: the test rejects above the calibrated band but D's
      CI lies inside the band (a detectable departure that the counts do not show at the
      margin, as a ratio "within 10 %" may still exclude 1);
    - ``"Poisson within 10 %"``: the rejection share is at the calibrated level (its CI
      inside the band around ``null_level``) and D's CI lies inside the band;
    - ``"inconclusive"`` otherwise (an interval that straddles a band's edge, or a
      non-finite endpoint).

    Parameters
    ----------
    reject_low, reject_high : float
        95 % CI of the share of runs the test rejects.
    null_level : float
        The share the same test rejects on null streams shaped like the runs (e.g. the
        ``share`` column of ``docs/results/null_calibration.csv``).
    dispersion_low, dispersion_high : float
        95 % CI of the dispersion index D.
    margin : float
        Half-width of the rejection band, relative to ``null_level`` (default 0.5).
    band : float
        Half-width of D's band (default 0.1).
    against_null : bool
        ``dispersion_low, dispersion_high`` are the CI of *D minus the D of null streams
        shaped like the runs* (where the null's D is not 1), read by :func:`null_verdict`
        with `D_MARGIN` (``band`` unused): ``"not Poisson"`` when the test rejects above
        its calibrated band and D lies above (or below) its null; ``"not Poisson, D at its
        null"``; ``"Poisson (D at its null)"`` when the share is at its calibrated level and
        D at its null; ``"inconclusive"`` otherwise.

    Examples
    --------
    >>> poisson_verdict(0.37, 0.41, null_level=0.05, dispersion_low=1.31, dispersion_high=1.47)
    'not Poisson'
    >>> poisson_verdict(0.37, 0.41, null_level=0.05, dispersion_low=1.03,
    ...                 dispersion_high=1.13)   # D straddles 1.1
    'inconclusive'
    >>> poisson_verdict(0.045, 0.06, null_level=0.052, dispersion_low=0.97, dispersion_high=1.04)
    'Poisson within 10 %'
    >>> poisson_verdict(0.08, 0.11, null_level=0.05, dispersion_low=1.01, dispersion_high=1.06)
    'not Poisson, D within 10 %'
    >>> poisson_verdict(0.37, 0.41, null_level=0.05, dispersion_low=1.2, dispersion_high=1.6,
    ...                 against_null=True)   # D - null D
    'not Poisson'
    """
    rejects = rejection_verdict(reject_low, reject_high, alpha=null_level, margin=margin)
    if against_null:
        dispersion = null_verdict(dispersion_low, dispersion_high, margin=D_MARGIN)
        if rejects == "above nominal" and dispersion in ("above its null", "below its null"):
            return "not Poisson"
        if rejects == "above nominal" and dispersion == "at its null":
            return "not Poisson, D at its null"
        if rejects == "nominal" and dispersion == "at its null":
            return "Poisson (D at its null)"
        return "inconclusive"
    dispersion = ratio_verdict(dispersion_low, dispersion_high, tolerance=band)
    within = f"within {100 * band:g} %"
    if rejects == "above nominal" and dispersion in ("higher", "lower"):
        return "not Poisson"
    if rejects == "above nominal" and dispersion == within:
        return f"not Poisson, D {within}"
    if rejects == "nominal" and dispersion == within:
        return f"Poisson {within}"
    return "inconclusive"


@keyword_only_after(0, since="0.2.0")
def poisson_rule(*, margin=0.5, band=0.1, against_null=False) -> str:
    """The printed rule of :func:`poisson_verdict` (``against_null``: D read against its
    null stream's D)."""
    if against_null:
        return (f"not Poisson: the share of runs a test rejects lies above the level that "
                f"null streams shaped like the runs give through the same test, by more than "
                f"{100 * margin:g} % of that level, and D lies above (or below) the D of those "
                f"null streams by more than {D_MARGIN:g} (95 % CI of the paired difference); "
                f"not Poisson, D at its null: the test rejects so but the difference's CI lies "
                f"in [-{D_MARGIN:g}, {D_MARGIN:g}]; Poisson (D at its null): the share is at its "
                f"calibrated level and D at its null; inconclusive otherwise")
    lo, hi = f"{1 - band:g}", f"{1 + band:g}"
    return (f"not Poisson: the share of runs a test rejects lies above the level that null "
            f"streams shaped like the runs give through the same test (null calibration), by "
            f"more than {100 * margin:g} % of that level, and the 95 % CI of the dispersion "
            f"index D lies entirely outside [{lo}, {hi}]; not Poisson, D within "
            f"{100 * band:g} %: the test rejects so but D's CI lies inside [{lo}, {hi}]; "
            f"Poisson within {100 * band:g} %: the share is at the calibrated level (CI within "
            f"{100 * margin:g} % of it) and D's CI lies inside [{lo}, {hi}]; inconclusive "
            "otherwise")


@keyword_only_after(2, since="0.2.0")
def share_verdict(low, high, *, level):
    """``"above"``, ``"below"`` or ``"inconclusive"`` for a share's CI against ``level``
    (:data:`SHARE_RULE`; inconclusive when an endpoint is not finite).

    Examples
    --------
    >>> (share_verdict(0.1, 0.3, level=0.05), share_verdict(0.0, 0.02, level=0.05),
    ...  share_verdict(0.0, 0.1, level=0.05))
    ('above', 'below', 'inconclusive')
    """
    if not (np.isfinite(low) and np.isfinite(high)):
        return "inconclusive"
    if low > level:
        return "above"
    if high < level:
        return "below"
    return "inconclusive"


@keyword_only_after(1, since="0.2.0")
def share_ratio_sample_size(share, *, tolerance=0.1, power=0.8, level=0.95):
    """Runs per arm for the ratio of two equal shares to be called within ``tolerance``.

    The sample size at which the ratio of two independent shares, both equal to ``share``
    (true ratio 1), gets its ``level`` interval inside ``[1 - tolerance, 1 + tolerance]``
    (:func:`ratio_verdict`'s equivalence test) with probability at least ``power``, on the
    log scale (the delta method): ``SE(log ratio)^2 = 2 (1 - p) / (n p)`` and
    ``n = 2 (1 - p) / p * ((z_level + z_power) / log(1 + tolerance))^2`` with
    ``z_level`` the two-sided quantile and ``z_power = Phi^-1((1 + power) / 2)`` (the
    estimate may fall on either side), the band taken as symmetric at its narrower side
    ``log(1 + tolerance)``; the wider lower side ``-log(1 - tolerance)`` makes the power a
    little higher (0.85 for 0.8 at a 10 % tolerance).

    Examples
    --------
    >>> share_ratio_sample_size(0.08)
    26604
    >>> share_ratio_sample_size(0.35) < share_ratio_sample_size(0.08)
    True
    """
    from scipy.stats import norm

    p = float(share)
    if not 0 < p < 1:
        raise ValueError(f"share must lie in (0, 1), got {share!r}")
    z = norm.ppf(0.5 + level / 2) + norm.ppf(0.5 + power / 2)
    return int(math.ceil(2 * (1 - p) / p * (z / math.log1p(tolerance)) ** 2))


@keyword_only_after(2, since="0.2.0")
def clopper_pearson(k, n, *, level=0.95):
    r"""Exact (Clopper-Pearson) interval of a binomial share: ``k`` successes in ``n``.

    The one implementation kicktimes uses: the Poisson tests' rejection shares, the renewal
    models' AIC shares, the sticky and re-collision shares of every page.

    Parameters
    ----------
    k, n : int or array_like of int
        Successes and trials (broadcast together); ``0 <= k <= n``.
    level : float
        Coverage, in (0, 1).

    Returns
    -------
    (float, float) or (ndarray, ndarray)
        ``(low, high)``: floats for scalar input, arrays of the broadcast shape otherwise.

    Notes
    -----
    With :math:`a = 1 - \text{level}`: the bounds are the :math:`a/2` quantile of
    :math:`\text{Beta}(k, n - k + 1)` (0 when k = 0) and the :math:`1 - a/2` quantile of
    :math:`\text{Beta}(k + 1, n - k)` (1 when k = n); NaN when n = 0. Clopper & Pearson,
    Biometrika 26, 404 (1934). The quantiles are scipy's `beta.ppf`, the same bits as
    statsmodels' ``proportion_confint(method="beta")``; scipy's ``binomtest(...)
    .proportion_ci(method="exact")`` finds them by root finding, within about 1e-11.

    Examples
    --------
    >>> [round(v, 4) for v in clopper_pearson(3, 10)]
    [0.0667, 0.6525]
    >>> clopper_pearson(0, 10)[0], clopper_pearson(10, 10)[1]
    (0.0, 1.0)
    >>> low, high = clopper_pearson([0, 5], [0, 10])
    >>> bool(np.isnan(low[0])), round(float(high[1]), 4)
    (True, 0.8129)
    """
    if np.ndim(k) == 0 and np.ndim(n) == 0:
        if n <= 0:
            return math.nan, math.nan
        a = 1 - level
        low = 0.0 if k == 0 else float(sps.beta.ppf(a / 2, k, n - k + 1))
        high = 1.0 if k == n else float(sps.beta.ppf(1 - a / 2, k + 1, n - k))
        return low, high
    k, n = np.broadcast_arrays(np.asarray(k, dtype=float), np.asarray(n, dtype=float))
    low = np.empty(k.shape)
    high = np.empty(k.shape)
    for i in np.ndindex(k.shape):  # the scalar bounds, bit for bit
        low[i], high[i] = clopper_pearson(float(k[i]), float(n[i]), level=level)
    return low, high


@dataclass(frozen=True)
class Finding(Result):
    """One answered question: ``question``, ``verdict``, ``statement`` and the ``rule``.

    A finding that is one effect size (a share, a ratio) also carries it: ``quantity``
    (what ``estimate`` is), ``estimate`` with its 95 % interval ``ci_low``, ``ci_high``,
    the ``method`` of the interval and the supporting numbers in ``detail``; the others
    leave them empty (NaN, ``""``) and give their numbers in the statement.
    """

    _title = "Finding"
    _intervals = {"estimate": ("ci_low", "ci_high")}

    question: str
    verdict: str
    statement: str
    rule: str
    quantity: str = ""
    estimate: float = math.nan
    ci_low: float = math.nan
    ci_high: float = math.nan
    method: str = ""
    detail: str = ""

    def _field_names(self) -> tuple[str, ...]:
        own = ("question", "verdict", "statement", "rule")
        if not self.quantity:
            return own
        return (*own, "quantity", "estimate", "ci_low", "ci_high", "method", "detail")

    def sentence(self) -> str:
        """The statement, with the supporting numbers (``detail``) in parentheses."""
        return self.statement + (f" ({self.detail}.)" if self.detail else "")


def _g(x):
    return "n/a" if not np.isfinite(x) else f"{x:.3g}"


def effect_statement(subject, quantity, estimate, ci_low, ci_high, method, verdict) -> str:
    """The sentence of an effect size: ``"<subject>: <quantity> <estimate> (95 % CI <low>
    to <high>, <method>): <verdict>."`` (no interval when it is not finite).

    >>> effect_statement("FTLE", "ratio", 0.331, 0.3, 0.36, "bootstrap", "lower")
    'FTLE: ratio 0.331 (95 % CI 0.300 to 0.360, bootstrap): lower.'
    >>> effect_statement("RR", "ratio", 1.12, 1.1009, 1.13, "bootstrap", "higher")
    'RR: ratio 1.120 (95 % CI 1.101 to 1.130, bootstrap): higher.'
    """
    if np.isfinite(ci_low) and np.isfinite(ci_high):
        # enough digits that the printed interval shows its verdict (format_interval)
        est, interval = format_interval(estimate, ci_low, ci_high).split(" ", 1)
        lo, hi = interval.strip("[]").split(", ")
        return f"{subject}: {quantity} {est} (95 % CI {lo} to {hi}, {method}): {verdict}."
    ci = f" (95 % CI {_g(ci_low)} to {_g(ci_high)}, {method})" if np.isfinite(ci_low) else ""
    return f"{subject}: {quantity} {_g(estimate)}{ci}: {verdict}."


def findings_table(items, *, columns=("question", "verdict", "statement", "rule")) -> pd.DataFrame:
    """The findings as a table, one row per finding, with the given attributes as columns.

    >>> table = findings_table([Finding("Data", "—", "3 sequences.", "all counted")])
    >>> table.columns.tolist(), table.loc[0, "statement"]
    (['question', 'verdict', 'statement', 'rule'], '3 sequences.')
    """
    return pd.DataFrame([{c: getattr(f, c) for c in columns} for f in items], columns=list(columns))


def format_p(p):
    """A p-value for the text: 3 significant digits, ``"< 1e-300"`` for 0, ``"n/a"``."""
    if not np.isfinite(p):
        return "n/a"
    return "< 1e-300" if p == 0 else f"{p:.3g}"


def _v(value):
    """A group value for the text: numbers with 4 significant digits."""
    if isinstance(value, int | float | np.integer | np.floating):
        return f"{float(value):.4g}"
    return str(value)


def _label(res, g):
    """``"<group> = <value>: "`` for a statement about one group ('' without groups)."""
    return "" if res.group is None else f"{res.group} = {_v(g)}: "


def _by_group(res, verdicts: dict) -> str:
    """One verdict per group, never cut: ``"kind = a: v1; kind = b: v2"``; the verdict
    alone without groups."""
    if res.group is None:
        return next(iter(verdicts.values()))
    return "; ".join(f"{_label(res, g)}{v}" for g, v in verdicts.items())


def _input(res):
    s = res.sequences
    n_empty = int((s["n_events"] == 0).sum())
    groups = s["group"].nunique()
    text = (
        f"{len(s)} sequences in {groups} group{'s' if groups > 1 else ''}"
        + (f" (by {res.group})" if res.group else "")
        + f", {int(s['n_events'].sum())} events over a total window of "
        f"{s['t_window'].sum():.4g}; {n_empty} sequence{'s' if n_empty != 1 else ''} without "
        "events (counted in the rates and regressions, skipped by the tests and fits)"
    )
    covs = list(res.events.covariates)
    text += f"; covariates: {', '.join(covs) if covs else 'none'}"
    labels = list(getattr(res.events, "labels", ()))
    text += f"; labels: {', '.join(labels)}." if labels else "."
    verdict = (
        f"{len(s)} sequences, {int(s['n_events'].sum())} events"
        + (f", {groups} groups by {res.group}" if res.group else "")
    )
    return Finding("Data", verdict, text, "Every sequence of the input is counted.")


def _poisson(res):
    pt = res.poisson
    tested = pt[pt["n_tested"] > 0]
    n_cells = len(tested)
    cut = res.alpha / max(n_cells, 1)
    rule = (
        f"a group is not Poisson when some test's Fisher-combined p-value over its sequences "
        f"is below alpha / (tests x groups) = {cut:.3g} (Bonferroni), and consistent with "
        "Poisson otherwise; a sequence is rejected when some test rejects it after "
        "Benjamini-Hochberg FDR within its group."
    )
    if n_cells == 0:
        return Finding("Poisson?", "inconclusive", "No sequence has enough events for a test.",
                       rule)
    s = res.sequences
    verdicts, parts = {}, []
    for g in pd.unique(s["group"]):
        cells = tested[tested["group"] == g]
        mine = s[(s["group"] == g) & (s["n_events"] > 0)]
        k, n = int(mine["reject_any_fdr"].sum()), len(mine)
        if cells.empty or n == 0:
            verdicts[g] = "untested (no sequence with enough events)"
            parts.append(f"{_label(res, g)}no sequence has enough events for a test")
            continue
        lo, hi = clopper_pearson(k, n)
        share = (f"{k}/{n} sequences rejected by some test after FDR ({100 * k / n:.0f} %, "
                 f"95 % CI {100 * lo:.0f}-{100 * hi:.0f} %)")
        bad = cells[cells["combined_pvalue"] < cut].sort_values("combined_pvalue")
        if bad.empty:
            verdicts[g] = "consistent with Poisson"
            parts.append(
                f"{_label(res, g)}consistent with Poisson: none of {len(cells)} tests rejects "
                f"(smallest combined p = {format_p(cells['combined_pvalue'].min())}); {share}"
            )
        else:
            verdicts[g] = "not Poisson"
            worst = ", ".join(
                f"{r.test} p = {format_p(r.combined_pvalue)}" for r in bad.itertuples()
            )
            parts.append(
                f"{_label(res, g)}not Poisson: {len(bad)} of {len(cells)} tests reject "
                f"({worst}); {share}"
            )
    return Finding("Poisson?", _by_group(res, verdicts), "; ".join(parts) + ".", rule)


def _renewal(res):
    pooled = res.renewal_pooled
    rule = (
        "best model: lowest AIC of the censored fits; decisive when the runner-up's "
        "ΔAIC > 10, weak when < 2."
    )
    if pooled.empty or pooled["aic"].notna().sum() == 0:
        return Finding(
            "Which renewal model?", "inconclusive", "No group has enough intervals for a fit.", rule
        )
    parts, verdicts = [], {}
    for g, t in pooled.groupby("group", sort=False, observed=True):
        t = t.dropna(subset=["aic"]).sort_values("aic")
        best, runner = t.iloc[0], t.iloc[1] if len(t) > 1 else None
        gap = runner["delta_aic"] if runner is not None else math.inf
        strength = "decisive" if gap > 10 else ("weak" if gap < 2 else "clear")
        d_exp = t.loc[t["model"] == "exponential", "delta_aic"]
        second = runner["model"] if runner is not None else "—"
        d_e = float(d_exp.iloc[0]) if len(d_exp) else math.nan
        parts.append(
            f"{_label(res, g)}{best['model']} ({strength}; runner-up {second} ΔAIC = {gap:.3g}; "
            f"exponential ΔAIC = {d_e:.4g}, {int(best['n'])} intervals)"
        )
        verdicts[g] = f"{best['model']} ({strength})"
    per = res.sequences["best_model"].dropna()
    text = "Pooled intervals per group: " + "; ".join(parts) + "."
    if len(per):
        k = int((per == "exponential").sum())
        lo, hi = clopper_pearson(k, len(per))
        counts = per.value_counts()
        text += (
            f" Per sequence ({len(per)} fitted): "
            + ", ".join(f"{m} best for {c}" for m, c in counts.items())
            + f"; exponential best for {100 * k / len(per):.0f} % (95 % CI "
            f"{100 * lo:.0f}-{100 * hi:.0f} %)."
        )
    text += (
        " A pooled sample mixes sequences with different rates, which alone makes it "
        "heavier-tailed than exponential: read it with the rate heterogeneity."
    )
    return Finding("Which renewal model?", _by_group(res, verdicts), text, rule)


def _heterogeneity(res):
    het = res.heterogeneity
    ok = het[het["n_sequences"] > 1]
    cut = res.alpha / max(len(ok), 1)
    rule = (
        f"heterogeneous when the exact (Monte Carlo) Pearson p-value of a common rate within "
        f"a group is below alpha / groups = {cut:.3g}; one rate otherwise."
    )
    if ok.empty:
        return Finding(
            "One rate for all sequences?",
            "inconclusive",
            "Every group has a single sequence.",
            rule,
        )
    verdicts, parts = {}, []
    for r in ok.itertuples():
        verdicts[r.group] = "heterogeneous" if r.pvalue_mc < cut else "consistent with one rate"
        parts.append(
            f"{_label(res, r.group)}{verdicts[r.group]} (p = {format_p(r.pvalue_mc)}, index of "
            f"dispersion {r.dispersion_index:.3g}, {int(r.n_flagged_fdr)} sequences with a rate "
            "incompatible with the group's after FDR)"
        )
    text = (
        "A common rate per group (Pearson χ², exact p-value at resolution "
        f"1/{res.n_mc + 1}; an index of dispersion of 1 for a common Poisson rate): "
        + "; ".join(parts)
        + "."
    )
    return Finding("One rate for all sequences?", _by_group(res, verdicts), text, rule)


def _reference(res):
    ref = res.reference
    if ref is None or ref.empty:
        return None
    rule = "Observed / reference rate: " + ratio_rule(tolerance=0.1) + "."
    verdicts, parts = [], []
    for r in ref.itertuples():
        verdicts.append(ratio_verdict(r.ci_low, r.ci_high))
        label = "" if res.group is None else f"{res.group} = {_v(r.group)}: "
        parts.append(f"{label}{r.ratio:.3f} [{r.ci_low:.3f}, {r.ci_high:.3f}]")
    verdict = (
        verdicts[0]
        if len(set(verdicts)) == 1
        else "; ".join(f"{_label(res, r.group)}{v}" for r, v in zip(ref.itertuples(), verdicts,
                                                                      strict=True))
    )
    text = (
        f"Observed / reference rate ({res.reference_column}) with 95 % CI: "
        + "; ".join(parts)
        + "."
    )
    return Finding("Rate against the reference?", verdict, text, rule)


def _regressions(res):
    reg = res.regressions
    out = []
    for cov, t in reg.groupby("covariate", sort=False, observed=True):
        nb = t[(t["model"] == "negbin") & (t["term"] == "slope")].iloc[0]
        po = t[(t["model"] == "poisson") & (t["term"] == "slope")].iloc[0]
        main, label = nb, "negative binomial"
        if not (np.isfinite(nb["ci_low"]) and np.isfinite(nb["ci_high"])):
            # alpha -> 0 (no overdispersion): the NB Hessian is singular and the NB model
            # is the Poisson one; its interval is the Poisson GLM's
            main, label = po, "Poisson GLM; the NB fit sits at alpha = 0"
        od = res.overdispersion.set_index("covariate").loc[cov]
        lo, hi = main["ci_low"], main["ci_high"]
        if main["g"] == "log":
            what = f"rate ∝ {cov}^b: b = {main['estimate']:.3f} [{lo:.3f}, {hi:.3f}]"
        else:
            what = f"log rate = a + b {cov}: b = {main['estimate']:.4g} [{lo:.4g}, {hi:.4g}]"
        if lo > 0:
            verdict = f"the rate increases with {cov}"
        elif hi < 0:
            verdict = f"the rate decreases with {cov}"
        else:
            verdict = f"no detectable trend of the rate with {cov}"
        text = (
            f"{what} (95 % CI; {label}; Poisson GLM: {po['estimate']:.4g} "
            f"[{po['ci_low']:.4g}, {po['ci_high']:.4g}]); Poisson Pearson dispersion "
            f"{od['pearson_dispersion']:.3g}, NB alpha = {od['alpha']:.3g} (LR p = "
            f"{format_p(od['lr_pvalue'])})."
        )
        rule = (
            "increases / decreases when the 95 % CI of the slope (negative binomial, or "
            "Poisson when the NB fit has alpha = 0) excludes 0."
        )
        out.append(Finding(f"Counts against {cov}?", verdict, text, rule))
    return out


def findings(res) -> list:
    """The findings of an analysis, data first, then each question."""
    out = [_input(res), _poisson(res), _renewal(res), _heterogeneity(res)]
    ref = _reference(res)
    if ref is not None:
        out.append(ref)
    out += _regressions(res)
    return out
