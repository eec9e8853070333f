r"""Every comparison finding under its controls, and whether its verdict survives them.

A ratio "kicked system / two-disk system" is a finding only if its verdict is the same
under every control that applies to it; otherwise it *depends on* the control that
changes it. The controls:

``primary``
    The report's setting: per radius the ratio of ensemble means
    :math:`\rho_r = \sum_i x_{ri} / \sum_i y_{ri}`, averaged over radii
    (:func:`kicktimes.report.effects.paired_ratio`).
``paired_median``
    A robust paired statistic: per radius the median over ICs of the per-IC ratio
    :math:`x_{ri} / y_{ri}`, averaged over radii. A few runs with extreme values (sticky
    orbits) cannot move it.
``sticky_excluded``
    The primary ratio without the sticky runs: a (radius, IC) pair is left out when its
    two-disk run collides faster than :data:`~kicktimes.report.counts.STICKY_FACTOR`
    times the kinetic rate :math:`\Gamma(r)` (regular orbits in which the disks bounce
    almost radially and meet near the centre).
``uniform_sampling`` / ``paper_sampling``
    Recurrence diagnostics only: the primary row of a recurrence diagnostic (RR, DET) is
    computed on the same trajectories sampled at uniform times :math:`k\tau` (the store's
    ``uniform_`` rows, ``rr_sampling = "run+uniform"``; its detail says so), and the
    paper's collision-truncated steps, whose samples sit on the rim at every wall hit and
    differ in number between the systems, are the control ``paper_sampling``. Its
    ``uniform_sampling`` row repeats the primary value under its own name, so that every
    recurrence diagnostic lists the uniform-time samples explicitly.
``invariant_ics``, ``elastic``, ``elastic+invariant_ics``
    Other experiments (`merge_control_families`): the 2 x 2 design collision rule (the
    paper's mirror rule, the elastic rule) x initial conditions (the paper's procedure, the
    invariant measure); their primary rows join the family's table under these names.

Every interval is a percentile bootstrap clustered on ICs: one resample draws IC indices
with replacement and applies them at every radius and to every system (the same IC is
the same initial condition everywhere), so the correlation of one IC across radii and
systems is kept. Verdicts use one band (:func:`kicktimes.stats.ratio_verdict`): *within 10 %*
when the whole 95 % interval lies in [0.9, 1.1], *higher* / *lower* when it lies entirely
above / below it, *inconclusive* otherwise. A comparison is *robust*
(:func:`kicktimes.stats.robust_verdict`) only when every control gives the same verdict and
no control's interval lies above 1 while another's lies below 1; otherwise it *depends on*
the first control that breaks it (the ``depends_on`` column).

The Poisson question is in the same table (:func:`poisson_rows`): per test, the share of
runs whose two-disk collision times reject it, with the verdict of
:func:`kicktimes.stats.rejection_verdict`, under the same rule x IC design.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes.report.common import REFERENCE, kicked_systems, wide
from kicktimes.report.effects import paired_ratio
from kicktimes.stats import (
    bootstrap_nanmedians,
    format_interval,
    nanmedian,
    ratio_verdict,
    rejection_verdict,
    robust_verdict,
)

__all__ = [
    "COLUMNS",
    "CONTROLS",
    "Controls",
    "compute_controls",
    "ratio_curves_figure",
    "diagnostics_of",
    "paired_median",
    "poisson_rows",
    "with_robustness",
]

#: the controls, in the order of the table (then the other experiments' controls)
CONTROLS = ("primary", "paired_median", "sticky_excluded", "uniform_sampling",
            "paper_sampling")
#: the columns of the findings table
COLUMNS = ("family", "question", "diagnostic", "system", "control", "estimate", "ci_low",
           "ci_high", "verdict", "robust", "depends_on", "n_pairs", "detail")
WITHIN = "within 10 %"
HIGHER = "higher"
LOWER = "lower"
INCONCLUSIVE = "inconclusive"
#: the question of the Poisson rows
POISSON_QUESTION = "Poisson collision times?"
#: how an interval becomes a verdict
_QUESTIONS = {
    "ftle": "FTLE",
    "rr_offdiag": "off-diagonal recurrence rate",
    "det": "determinism (DET)",
    "one_minus_r1": "decorrelation 1 − R₁ of boundary angles",
    "counts": "collision counts / kinetic theory Γ(r)T",
}


def paired_median(numerator, denominator, *, rng, n_boot=1000, level=0.95):
    r"""Median over ICs of the per-IC ratio, per radius, averaged over radii, with a CI.

    Parameters
    ----------
    numerator, denominator : pandas.Series
        Indexed by ``(radius, ic)``; a pair enters where both are finite and the
        denominator is non-zero.
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
    >>> paired_median(x, y, rng=np.random.default_rng(0))["ratio"]
    0.5
    """
    frame = pd.concat({"x": numerator, "y": denominator}, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = (frame["x"] / frame["y"]).where(lambda s: np.isfinite(s))
    table = q.unstack("ic")  # radius x ic
    values = table.to_numpy(float)
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
    idx = rng.integers(0, n, size=(n_boot, n))
    # boot_r[b] = nanmedian(values[:, idx[b]], axis=1), bit for bit, without a sort each
    boot_r = bootstrap_nanmedians(values, idx)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a resample without a finite pair
        boot = np.nanmean(boot_r[:, usable], axis=1)
        a = (1 - level) / 2 * 100
        low_r = np.nanpercentile(boot_r, a, axis=0)
        high_r = np.nanpercentile(boot_r, 100 - a, axis=0)
    boot = boot[np.isfinite(boot)]
    curve = pd.DataFrame({"radius": table.index.to_numpy(float),
                          "n_pairs": np.isfinite(values).sum(axis=1),
                          "ratio": per_radius.to_numpy(), "ci_low": low_r, "ci_high": high_r})
    return {
        "ratio": float(per_radius[usable].mean()),
        "ci_low": float(np.percentile(boot, a)) if boot.size else math.nan,
        "ci_high": float(np.percentile(boot, 100 - a)) if boot.size else math.nan,
        "n_pairs": n_pairs,
        "per_radius": curve,
    }


def diagnostics_of(results, eps):
    """The comparison diagnostics a store has: ``(name, store row, uniform row or None)``.

    ``name`` is the table's ``diagnostic`` (``ftle``, ``rr_offdiag@0.001``, ``det@0.01``,
    ``one_minus_r1``); the store rows hold the per-IC values.
    """
    have = set(results["diagnostic"].unique())
    out = []
    if "lyapunov" in have:
        out.append(("ftle", "lyapunov", None))
    for e in eps:
        tag = f"{e:g}"
        for name in ("rr_offdiag", "det"):
            row = f"{name}@{tag}"
            if row in have:
                uniform = f"uniform_{row}"
                out.append((row, row, uniform if uniform in have else None))
    if "autocorrelation" in have:
        out.append(("one_minus_r1", "autocorrelation", None))
    return out


def _row(family, diagnostic, system, control, est, low, high, n_pairs, detail):
    return {
        "family": family,
        "question": _QUESTIONS[diagnostic.split("@")[0]],
        "diagnostic": diagnostic,
        "system": system,
        "control": control,
        "estimate": est,
        "ci_low": low,
        "ci_high": high,
        "verdict": ratio_verdict(low, high),
        "robust": False,
        "depends_on": "",
        "n_pairs": int(n_pairs),
        "detail": detail,
    }


def _ratio_rows(family, diagnostic, system, x, y, sticky, *, x_uniform, y_uniform, rng,
                n_boot, resamples, curves):
    """The rows of one (diagnostic, system): every control that applies; the per-radius
    ratios and CIs of each go to ``curves``."""
    rows = []

    def add(control, per_r, tot, n_pairs, detail):
        rows.append(_row(family, diagnostic, system, control, tot["ratio"], tot["ci_low"],
                         tot["ci_high"], n_pairs, detail))
        curves.append(per_r.assign(family=family, diagnostic=diagnostic, system=system,
                                   control=control))

    # recurrence: the uniform-time samples are the primary setting, the paper's
    # collision-truncated samples a control
    paper_x, paper_y = x, y
    samples = ""
    if x_uniform is not None:
        x, y = x_uniform, y_uniform
        samples = "uniform-time samples k τ; "
    per_r, tot = paired_ratio(x, y, rng=rng, n_boot=n_boot, resamples=resamples)
    primary_detail = (samples + "ratio of means per radius, averaged over radii; per radius "
                      + ", ".join(f"{r:g}: {v:.3g}" for r, v in zip(per_r["radius"],
                                                                    per_r["ratio"], strict=True)))
    add("primary", per_r, tot, per_r["n_pairs"].sum(), primary_detail)
    med = paired_median(x, y, rng=rng, n_boot=max(200, n_boot // 2))
    add("paired_median", med["per_radius"], med, med["n_pairs"],
        samples + "median of per-IC ratios per radius, averaged over radii")
    keep = ~sticky.reindex(x.index, fill_value=False).to_numpy(bool)
    per_r, tot = paired_ratio(x[keep], y[keep], rng=rng, n_boot=n_boot, resamples=None)
    add("sticky_excluded", per_r, tot, per_r["n_pairs"].sum(),
        samples + f"{int((~keep).sum())} sticky (radius, IC) runs left out")
    if x_uniform is not None:
        rows.append({**rows[0], "control": "uniform_sampling",
                     "detail": "the primary row: samples at uniform times k τ"})
        per_r, tot = paired_ratio(paper_x, paper_y, rng=rng, n_boot=n_boot,
                                  resamples=resamples)
        add("paper_sampling", per_r, tot, per_r["n_pairs"].sum(),
            "the paper's collision-truncated samples of the same trajectories")
    return rows


@dataclass(frozen=True)
class Controls:
    """Every comparison of one store under its controls.

    Attributes
    ----------
    table : pandas.DataFrame
        The findings table, columns :data:`COLUMNS`: one row per (diagnostic, system,
        control), averaged over radii.
    curves : pandas.DataFrame
        The same per radius: ``family, diagnostic, system, control, radius, n_pairs,
        ratio, ci_low, ci_high`` (the headline figure's curves).
    """

    table: pd.DataFrame
    curves: pd.DataFrame


def compute_controls(results, collisions, *, family, eps, rule="mirror", rng, n_boot=2000,
                     resamples=None, kinetic=None) -> Controls:
    """Every comparison diagnostic of every kicked system under every control, with the
    verdict and whether it is robust, averaged over radii and per radius.

    Parameters
    ----------
    results, collisions : pandas.DataFrame
        A store's tidy tables (`kicktimes.experiment.load_store`).
    family : str
        The experiment's name (the ``family`` column).
    eps : sequence of float
        The experiment's recurrence thresholds.
    rule : {"mirror", "elastic"}
        The collision rule (for the kinetic rate that defines sticky runs).
    rng : numpy.random.Generator
        The bootstrap stream (the report seeds it: the table is deterministic).
    n_boot : int
        Bootstrap resamples of the ICs.
    resamples : dict, optional
        Shared bootstrap draws (`paired_ratio`).
    kinetic : callable, optional
        The kinetic rate as a function of the radius (array in, array out), e.g.
        ``Experiment.kinetic_rate`` for unequal disks; default
        ``kicktimes.stats.kinetic_rate(r, rule)`` (equal disks).

    Returns
    -------
    Controls
        ``table`` (columns :data:`COLUMNS`; ``robust`` is True on every row of a (family,
        diagnostic, system) exactly when all its controls give the same verdict) and
        ``curves`` (per radius).
    """
    from kicktimes.report.counts import sticky_ics

    sticky = sticky_ics(collisions, rule, kinetic=kinetic).set_index(["radius", "ic"])["sticky"]
    rows, curves = [], []
    systems = kicked_systems(results)
    for diagnostic, row, uniform in diagnostics_of(results, eps):
        table = wide(results, row)
        if diagnostic == "one_minus_r1":
            table = 1.0 - table
        table_u = wide(results, uniform) if uniform else None
        if REFERENCE not in table.columns:
            continue
        for system in systems:
            if system not in table.columns:
                continue
            rows += _ratio_rows(
                family, diagnostic, system, table[system], table[REFERENCE], sticky,
                x_uniform=None if table_u is None else table_u[system],
                y_uniform=None if table_u is None else table_u[REFERENCE],
                rng=rng, n_boot=n_boot, resamples=resamples, curves=curves,
            )
    rows += _count_rows(family, collisions, sticky, rule, kinetic, rng=rng, n_boot=n_boot,
                        resamples=resamples)
    out = with_robustness(pd.DataFrame(rows, columns=list(COLUMNS)))
    curve_cols = ["family", "diagnostic", "system", "control", "radius", "n_pairs", "ratio",
                  "ci_low", "ci_high"]
    curves = (pd.concat(curves, ignore_index=True)[curve_cols] if curves
              else pd.DataFrame(columns=curve_cols))
    return Controls(out, curves)


def with_robustness(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with ``robust`` and ``depends_on`` set per (family, diagnostic, system):
    robust when every control gives the same verdict and, for ratios, no control's CI lies
    above 1 while another's lies below 1 (:func:`kicktimes.stats.robust_verdict`; the
    Poisson rows compare shares, so only their verdicts count). ``depends_on`` names the
    first control (in table order) whose verdict differs from the primary's or whose CI
    lies on the other side of 1."""
    out = table.copy()
    if out.empty:
        return out
    robust = np.zeros(len(out), bool)
    depends = np.array([""] * len(out), dtype=object)
    for _, g in out.groupby(["family", "diagnostic", "system"], sort=False, observed=True):
        share = (g["question"] == POISSON_QUESTION).all()
        ok, _ = robust_verdict(list(g["verdict"]), g["ci_low"], g["ci_high"],
                               level=np.inf if share else 1.0)
        pos = out.index.get_indexer(g.index)
        robust[pos] = ok
        if not ok:
            depends[pos] = _deciding_control(g, share)
    out["robust"] = robust
    out["depends_on"] = depends
    return out


def _deciding_control(g: pd.DataFrame, share: bool) -> str:
    """The control a non-robust comparison depends on, most telling first: one whose CI
    lies on the other side of 1 from the primary's (from another control's, when the
    primary's straddles 1), else the one with another verdict whose estimate lies
    farthest from the primary's (on a log scale)."""
    def side(r):
        return 1 if r["ci_low"] > 1 else -1 if r["ci_high"] < 1 else 0

    first = g.iloc[0]
    others = g.iloc[1:]
    if not share:
        sides = [side(r) for _, r in g.iterrows()]
        ref = sides[0] or next((v for v in sides if v), 0)
        flipped = [r for (_, r), v in zip(g.iterrows(), sides, strict=True) if v == -ref and v]
        if ref and flipped:
            far = max(flipped, key=lambda r: abs(math.log(r["estimate"] / first["estimate"]))
                      if r["estimate"] > 0 and first["estimate"] > 0 else 0.0)
            return str(far["control"])
    changed = others[others["verdict"] != first["verdict"]]
    if changed.empty:
        changed = others
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = np.abs(np.log(changed["estimate"].to_numpy(float) / first["estimate"]))
    dist = np.where(np.isfinite(dist), dist, -1.0)
    # estimates equal to rounding (two controls that remove the same runs) tie, and the
    # tie goes to the first in table order: not to whichever rounding a library version
    # or CPU happened to give
    return str(changed["control"].iloc[int(np.flatnonzero(dist >= dist.max() - 1e-9)[0])])


def _count_rows(family, collisions, sticky, rule, kinetic, *, rng, n_boot, resamples):
    """Observed disk-disk collisions over the kinetic count Γ(r) T, under the controls."""
    from kicktimes.report.counts import kinetic_rate_of

    coll = collisions.set_index(["radius", "ic"])
    gamma = np.array([kinetic_rate_of(float(r), rule, kinetic) for r in
                      coll.index.get_level_values("radius")])
    observed = coll["n_pp"].astype(float)
    expected = pd.Series(gamma * coll["t_window"].to_numpy(float), index=coll.index)
    rows = []
    per_r, tot = paired_ratio(observed, expected, rng=rng, n_boot=n_boot, resamples=resamples)
    rows.append(_row(family, "counts", REFERENCE, "primary", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     "ΣN / Σ Γ(r)T per radius, averaged over radii; paper ICs, not the "
                     "invariant measure, so the ratio need not be 1"))
    med = paired_median(observed, expected, rng=rng, n_boot=max(200, n_boot // 2))
    rows.append(_row(family, "counts", REFERENCE, "paired_median", med["ratio"], med["ci_low"],
                     med["ci_high"], med["n_pairs"], "median of per-IC N / Γ(r)T"))
    keep = ~sticky.reindex(observed.index, fill_value=False).to_numpy(bool)
    per_r, tot = paired_ratio(observed[keep], expected[keep], rng=rng, n_boot=n_boot)
    rows.append(_row(family, "counts", REFERENCE, "sticky_excluded", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     f"{int((~keep).sum())} sticky runs left out"))
    return rows


def poisson_rows(family, rejections, per_ic, *, alpha, rng, n_boot=2000):
    """The Poisson question as rows of the findings table: per test of the battery, the
    share of (radius, IC) runs whose two-disk collision times reject it at ``alpha``.

    Rows ``diagnostic = "reject@<test>"`` pool the runs of every radius with a
    Clopper-Pearson interval; the headline test's rows (`poisson.HEADLINE_TEST`, on the
    whole window and ``"@first<n>"`` on the first `poisson.FIXED_EVENTS` collisions of
    every run that has them, the same power at every radius) have a bootstrap interval
    clustered on ICs instead (the runs of one IC at different radii share its initial
    condition). The verdict is :func:`kicktimes.stats.rejection_verdict`'s: *nominal*,
    *above nominal*, *below nominal* or *inconclusive*.

    Parameters
    ----------
    family : str
        The experiment's name.
    rejections : pandas.DataFrame
        The Poisson section's table (``radius, test, n_tested, n_reject``).
    per_ic : pandas.DataFrame
        The headline test's p-values per run (``radius, ic, p, p_fixed``).
    alpha : float
        The tests' level.
    rng : numpy.random.Generator
        The clustered bootstrap's stream.
    n_boot : int
        Its resamples.
    """
    from kicktimes.report.poisson import FIXED_EVENTS, HEADLINE_TEST, clustered_share
    from kicktimes.stats.findings import clopper_pearson

    rows = []

    def add(diagnostic, k, n, low, high, detail):
        share = k / n if n else math.nan
        rows.append({
            "family": family, "question": POISSON_QUESTION, "diagnostic": diagnostic,
            "system": REFERENCE, "control": "primary", "estimate": share, "ci_low": low,
            "ci_high": high, "verdict": rejection_verdict(low, high, alpha), "robust": False,
            "depends_on": "", "n_pairs": int(n), "detail": detail})

    totals = rejections.groupby("test", sort=False, observed=True)[["n_reject", "n_tested"]].sum()
    for test, (k, n) in totals.iterrows():
        if n == 0:
            continue
        if test == HEADLINE_TEST and per_ic is not None:
            low, high = clustered_share(per_ic, "p", alpha, rng=rng, n_boot=n_boot)
            how = "95 % CI from a bootstrap clustered on ICs"
        else:
            low, high = clopper_pearson(int(k), int(n))
            how = "Clopper-Pearson 95 % CI (runs of one IC at different radii counted apart)"
        add(f"reject@{test}", int(k), int(n), low, high,
            f"share of runs rejecting {test} at α = {alpha:g}, every radius, whole window; "
            + how)
    if per_ic is not None and np.isfinite(per_ic["p_fixed"]).any():
        p = per_ic["p_fixed"].to_numpy(float)
        ok = np.isfinite(p)
        low, high = clustered_share(per_ic, "p_fixed", alpha, rng=rng, n_boot=n_boot)
        add(f"reject@{HEADLINE_TEST}@first{FIXED_EVENTS}", int((p[ok] < alpha).sum()),
            int(ok.sum()), low, high,
            f"{HEADLINE_TEST} on the first {FIXED_EVENTS} collisions of every run that has "
            "them (the same power at every radius); 95 % CI from a bootstrap clustered on ICs")
    return rows


#: what the paper says of each diagnostic (Ranković & Porter 2013), beside the table's rows
PAPER_CLAIMS = {
    "ftle": "“very similar” λ (Fig. 6)",
    "rr_offdiag": "“excellent agreement” of RR at small r (Fig. 7)",
    "det": "not studied",
    "one_minus_r1": "similar R₁ (Fig. 8)",
}
_CONTROL_WORDS = {
    "paired_median": "paired median",
    "sticky_excluded": "sticky runs excluded",
    "uniform_sampling": "uniform-time samples",
    "paper_sampling": "the paper's samples",
    "invariant_ics": "invariant-measure ICs",
    "elastic": "the elastic rule",
    "elastic+invariant_ics": "the elastic rule with invariant-measure ICs",
}
_SHORT = {"poisson": "Poisson", "actual": "actual", "poisson_scatter": "Poisson, scatter",
          "actual_scatter": "actual, scatter", "poisson_kinetic": "kinetic rate, scatter",
          "uniform_kinetic": "kinetic rate, uniform", "mmpp": "MMPP"}
#: the rows of the first screen's table, in order: (diagnostic, label)
SCREEN_ROWS = (
    ("ftle", "FTLE λ"),
    ("rr_offdiag@0.01", "off-diagonal RR, ε = 10⁻² (uniform-time samples)"),
    ("det@0.01", "DET, ε = 10⁻² (uniform-time samples)"),
    ("rr_offdiag@0.001", "off-diagonal RR, ε = 10⁻³ (uniform-time samples)"),
    ("one_minus_r1", "1 − R₁ (lag-1 decorrelation)"),
)
_FAMILY_SHORT = {"family_a": "A", "family_b": "B"}
#: the Poisson battery's tests, as the first screen names them
_TEST_NAMES = {"uniformity_ks": "uniformity (KS)", "laplace_trend": "Laplace trend",
               "exponential_ks": "exponential-interval (KS)",
               "exponential_ad": "exponential-interval (AD)", "ljung_box": "Ljung–Box",
               "runs": "runs", "dispersion": "dispersion"}


def _ci(row):
    return format_interval(row.estimate, row.ci_low, row.ci_high)


def _fam(family):
    return _FAMILY_SHORT.get(family, family)


def screen_cell(rows: pd.DataFrame) -> str:
    """One cell of the first screen: a comparison over every control and family.

    ``"✓ lower: 0.301–0.338"`` (the verdict word and the range of the estimate over every
    control and family) when it is robust in every family with one verdict; otherwise
    ``"depends on <control>: <primary> vs <control's value>"`` (the family named when there
    are several), or ``"depends on the family"`` with both primaries.
    """
    families = list(dict.fromkeys(rows["family"]))
    primary = rows[rows["control"] == "primary"].set_index("family")
    lo, hi = rows["estimate"].min(), rows["estimate"].max()
    missing = ""
    if rows["system"].iloc[0] in ("poisson_kinetic", "uniform_kinetic"):
        missing = " (mirror rule only)"
    for fam in families:
        mine = rows[rows["family"] == fam]
        if not mine["robust"].all():
            control = mine["depends_on"].iloc[0]
            other = mine[mine["control"] == control].iloc[0]
            where = f"{_fam(fam)}: " if len(families) > 1 else ""
            flips = (mine["ci_low"] > 1).any() and (mine["ci_high"] < 1).any()
            mark = "↕ " if flips else ""
            return (f"{mark}depends on {control}: {where}{_ci(primary.loc[fam])} vs "
                    f"{_ci(other)}{missing}")
    verdicts = set(primary["verdict"])
    if len(verdicts) > 1:
        return ("depends on the family: " + "; ".join(
            f"{_fam(f)} {_ci(primary.loc[f])}" for f in families) + missing)
    if (rows["ci_low"] > 1).any() and (rows["ci_high"] < 1).any():
        return ("depends on the family: " + "; ".join(
            f"{_fam(f)} {_ci(primary.loc[f])}" for f in families) + missing)
    return f"✓ {verdicts.pop()}: {lo:.3g}–{hi:.3g}{missing}"


def overview_table(table: pd.DataFrame) -> pd.DataFrame:
    """The first screen's table: diagnostics as rows (`SCREEN_ROWS`), kick laws as columns,
    each cell :func:`screen_cell` over every control and family; the paper's claim beside."""
    comp = table[(table["system"] != REFERENCE) & (table["question"] != POISSON_QUESTION)]
    systems = [s for s in _SHORT if s in set(comp["system"])]
    out = []
    rows_wanted = [r for r in SCREEN_ROWS if r[0] in set(comp["diagnostic"])]
    for diagnostic, label in rows_wanted:
        line = {"diagnostic": label}
        for system in systems:
            rows = comp[(comp["diagnostic"] == diagnostic) & (comp["system"] == system)]
            line[_SHORT[system]] = screen_cell(rows) if not rows.empty else ""
        line["the paper"] = PAPER_CLAIMS.get(diagnostic.split("@")[0], "")
        out.append(line)
    return pd.DataFrame(out)


def _pct(row):
    return (f"{100 * row.estimate:.1f} % [{100 * row.ci_low:.1f}, {100 * row.ci_high:.1f}]")


def poisson_answer(table: pd.DataFrame, alpha=0.05) -> str:
    """The first screen's sentence on the Poisson question, with the collision rule as a
    factor: the headline test's rejection share under the mirror and the elastic rule (the
    paper's ICs) per family, whether the intervals are disjoint, and which tests reject at
    their nominal rate under the elastic rule in every family."""
    from kicktimes.report.poisson import HEADLINE_TEST

    rows = table[table["question"] == POISSON_QUESTION]
    head = rows[rows["diagnostic"] == f"reject@{HEADLINE_TEST}"]
    if head.empty:
        return ""
    families = list(dict.fromkeys(head["family"]))

    def cell(fam, control):
        r = head[(head["family"] == fam) & (head["control"] == control)]
        return r.iloc[0] if len(r) else None

    mirror = [(f, cell(f, "primary")) for f in families]
    mirror = [(f, r) for f, r in mirror if r is not None]
    above = all(r.verdict == "above nominal" for _, r in mirror)
    text = ("Under the paper's mirror rule the two-disk collision times are "
            + ("not Poisson" if above else "not shown to differ from Poisson") + " ("
            + ", ".join(f"{_pct(r)} ({_fam(f)})" for f, r in mirror)
            + f" of runs reject uniform times at α = {alpha:g}, against {100 * alpha:g} % for a "
            "Poisson process)")
    elastic = [(f, cell(f, "elastic"), cell(f, "primary")) for f in families]
    elastic = [(f, e, m) for f, e, m in elastic if e is not None and m is not None]
    if elastic:
        disjoint = all(e.ci_high < m.ci_low for _, e, m in elastic)
        shares = ", ".join(f"{_pct(e)} ({_fam(f)})" for f, e, _ in elastic)
        still = all(e.verdict == "above nominal" for _, e, _ in elastic)
        text += (f"; under the elastic rule fewer runs reject ({shares}; intervals disjoint)"
                 if disjoint else f"; under the elastic rule {shares} of runs reject")
        if still:
            text += f", still more than the nominal {100 * alpha:g} %, so not Poisson either"
        nominal = []
        for test in dict.fromkeys(rows["diagnostic"]):
            cells = rows[(rows["diagnostic"] == test) & (rows["control"] == "elastic")]
            if len(cells) == len(elastic) and (cells["verdict"] == "nominal").all():
                name = test.split("@")[1]
                nominal.append(_TEST_NAMES.get(name, name))
        if nominal:
            names = (", ".join(nominal[:-1]) + " and " + nominal[-1] if len(nominal) > 1
                     else nominal[0])
            text += (f", and the {names} test{'s' if len(nominal) > 1 else ''} reject"
                     f"{'' if len(nominal) > 1 else 's'} at the nominal rate")
    return text + "."


def ftle_answer(table: pd.DataFrame) -> str:
    """The first screen's sentence on the FTLE of the paper's kicked disk (Poisson and
    actual kicks): its verdict over every control and family, or what it depends on."""
    ftle = table[(table["diagnostic"] == "ftle") & table["system"].isin(["poisson", "actual"])]
    if ftle.empty:
        return ""
    robust = ftle["robust"].all()
    verdicts = set(ftle["verdict"])
    lo, hi = ftle["estimate"].min(), ftle["estimate"].max()
    n_controls = ftle["control"].nunique()
    if robust and verdicts == {LOWER}:
        return ("The paper's kicked disk does not reproduce the two-disk chaos: its FTLE is "
                f"{lo:.3g}–{hi:.3g} of the two-disk value, lower under all {n_controls} "
                "controls in every family.")
    if robust and verdicts == {WITHIN}:
        return ("The paper's kicked disk reproduces the two-disk FTLE within 10 % "
                f"({lo:.3g}–{hi:.3g}) under all {n_controls} controls.")
    cells = [screen_cell(ftle[ftle["system"] == s]) for s in ("poisson", "actual")]
    return (f"The paper's kicked disk's FTLE, Poisson kicks: {cells[0]}; actual kicks: "
            f"{cells[1]}.")


def first_screen(table: pd.DataFrame, shares=None) -> list[str]:
    """The Markdown lines that open a results page: at most three sentences (the Poisson
    question with the collision rule, the paper's kicked disk, how to read the table),
    then the table (:func:`overview_table`) and the list of its controls. ``shares`` is
    accepted for compatibility and unused: the Poisson numbers come from the table's rows."""
    controls = [c for c in dict.fromkeys(table["control"]) if c != "primary"]
    sentences = [poisson_answer(table), ftle_answer(table),
                 "Each cell: the kicked/two-disk ratio's range over every control (listed "
                 "below the table) and both families; ✓ with its verdict when all agree in "
                 "verdict and direction, else the control that changes it most, both numbers "
                 "(↕: above 1 under one control, below 1 under another)."]
    lines = [" ".join(s for s in sentences if s), ""]
    lines += markdown_table(overview_table(table))
    lines += ["", "Controls: " + ", ".join(_CONTROL_WORDS.get(c, c) for c in controls)
              + "; the kinetic-rate kicks under the mirror rule only."]
    return lines + [""]


def mmpp_answer(table: pd.DataFrame) -> str:
    """With the ``mmpp`` system: does clustering in the kick times bring the kicked disk
    closer? Its FTLE ratio against the Poisson kicks' (primary, per family), and its cell."""
    ftle = table[table["diagnostic"] == "ftle"]
    if "mmpp" not in set(ftle["system"]):
        return ""
    primary = ftle[ftle["control"] == "primary"].set_index(["family", "system"])["estimate"]
    pairs = [f"{fam}: {primary[fam, 'mmpp']:.2f} against {primary[fam, 'poisson']:.2f}"
             for fam in dict.fromkeys(ftle["family"])
             if (fam, "mmpp") in primary.index and (fam, "poisson") in primary.index]
    return ("Does clustering in the kick times bring the kicked disk closer? MMPP kicks (a "
            "two-state Markov-modulated Poisson process fitted to each IC's collision times) "
            "against Poisson kicks at the same mean rate, FTLE ratio to the two-disk value"
            + (f" ({'; '.join(pairs)})" if pairs else "") + ": MMPP kicks: "
            + screen_cell(ftle[ftle["system"] == "mmpp"]) + ".")


def answers(table: pd.DataFrame, poisson_share=None) -> list[str]:
    """The answers that open a report's findings: the Poisson question, the paper's kicked
    disk, and (with the ``mmpp`` system) clustered kicks."""
    return [s for s in (poisson_answer(table), ftle_answer(table), mmpp_answer(table)) if s]


def markdown_table(frame: pd.DataFrame) -> list[str]:
    """``frame`` as the lines of a GitHub Markdown table (cells' ``|`` escaped)."""
    def cell(v):
        return str(v).replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(cell(c) for c in frame.columns) + " |",
             "|" + "---|" * len(frame.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |"
              for row in frame.itertuples(index=False)]
    return lines


def poisson_share(effects) -> tuple | None:
    """``(share, ci_low, ci_high, alpha)`` of the Poisson-rejection finding, or None."""
    for e in effects:
        if e.question.startswith("Poisson"):
            return (e.estimate, e.ci_low, e.ci_high, 0.05)
    return None


#: the headline figure's panels: (diagnostic, title)
PANELS = (
    ("ftle", "FTLE λ"),
    ("rr_offdiag@0.001", "off-diagonal RR, ε = 10⁻³\n(uniform-time samples)"),
    ("rr_offdiag@0.01", "off-diagonal RR, ε = 10⁻²\n(uniform-time samples)"),
    ("det@0.01", "DET, ε = 10⁻²\n(uniform-time samples)"),
    ("one_minus_r1", "1 − R₁\n(lag-1 decorrelation)"),
)
# y ticks of the ratio panels, by how many decades the panel spans (labels never overlap)
_LOG_TICKS = (
    (4.0, (0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.1, 1.5, 2.0, 3.0)),
    (20.0, (0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0)),
    (math.inf, (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)),
)
#: the statistic of the headline figure: robust to the few sticky runs
HEADLINE_CONTROL = "paired_median"


def log_ratio_axis(ax):
    """A log y axis for ratios with plain tick labels that never overlap."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ax.set_yscale("log")
    lo, hi = ax.get_ylim()
    choice = next(t for span, t in _LOG_TICKS if hi / lo <= span)
    ax.yaxis.set_major_locator(FixedLocator([t for t in choice if lo <= t <= hi]))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def ratio_curves_figure(curves: pd.DataFrame, control=HEADLINE_CONTROL):
    """The headline figure: the ratio of each kicked system to the two-disk value against
    r, one line per kick law, one panel per diagnostic (columns) and family (rows), with
    95 % CIs (bootstrap clustered on ICs) and the ±10 % band. Every panel shares one log y
    scale, so the band has the same height everywhere. The statistic is ``control``'s
    (default the paired median of per-IC ratios, which a few sticky runs cannot move); the
    recurrence panels use uniform-time samples (the primary setting of recurrence).

    Parameters
    ----------
    curves : pandas.DataFrame
        ``Controls.curves`` of one or more stores (concatenated).
    control : str
        Which control's per-radius curves to draw.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from kicktimes.report.figures import radius_axis, system_label, system_style

    curves = curves[curves["control"] == control]
    panels = [(d, t) for d, t in PANELS if d in set(curves["diagnostic"])]
    families = list(dict.fromkeys(curves["family"]))
    systems = [s for s in _SHORT if s in set(curves["system"])]
    ncol, nrow = max(len(panels), 1), max(len(families), 1)
    fig = Figure(figsize=(3.0 * ncol, 2.9 * nrow + 0.9), layout="constrained")
    axes = fig.subplots(nrow, ncol, squeeze=False, sharey=True, sharex="row")
    shown = curves[curves["diagnostic"].isin([d for d, _ in panels])]
    values = shown[["ratio", "ci_low", "ci_high"]].to_numpy(float)
    values = values[np.isfinite(values) & (values > 0)]
    lo = min(0.8, float(values.min()) / 1.1) if values.size else 0.5
    hi = max(1.25, float(values.max()) * 1.1) if values.size else 2.0
    for f, fam in enumerate(families):
        for j, (diagnostic, title) in enumerate(panels):
            ax = axes[f, j]
            ax.axhspan(0.9, 1.1, color="0.85", zorder=0)
            ax.axhline(1.0, color="0.5", linewidth=0.8, zorder=0)
            part = curves[(curves["diagnostic"] == diagnostic) & (curves["family"] == fam)]
            for k, system in enumerate(systems):
                c = part[part["system"] == system].sort_values("radius")
                if c.empty:
                    continue
                style = system_style(system, k)
                err = np.vstack([c["ratio"] - c["ci_low"], c["ci_high"] - c["ratio"]])
                ax.errorbar(c["radius"], c["ratio"], yerr=np.clip(err, 0, None),
                            color=style["color"], marker=style["marker"], markersize=3,
                            linewidth=1.0, capsize=1.5)
            ax.set_title(f"{fam}: {title}" if j == 0 or f == 0 else title, fontsize="small")
            radius_axis(ax)
            ax.set_ylim(lo, hi)
            log_ratio_axis(ax)
        axes[f, 0].set_ylabel(f"{fam}\nkicked / two-disk\n(median of per-IC ratios)",
                              fontsize="small")
    handles = [Line2D([], [], color=system_style(s, k)["color"], marker=system_style(s, k)[
        "marker"], linestyle="-", label=system_label(s)) for k, s in enumerate(systems)]
    handles += [Line2D([], [], color="0.85", linewidth=6, label="±10 % band")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4),
               fontsize="small")
    return fig


def merge_control_families(tables):
    """Fold the findings of control experiments into their family's table.

    An experiment named ``"<family>-<control>"`` (the presets of
    `kicktimes.experiment.presets.CONTROL_PRESETS`: ``invariant_ics``, ``elastic``,
    ``elastic+invariant_ics``) is a control of ``<family>``: the primary rows of its table
    (ratios and the Poisson question) become rows of ``<family>``'s table with
    ``control = "<control>"``, and ``robust`` and ``depends_on`` are recomputed over every
    control (:func:`with_robustness`).

    Parameters
    ----------
    tables : sequence of pandas.DataFrame
        Findings tables (:data:`COLUMNS`), one per experiment.

    Returns
    -------
    dict
        ``{family: table}`` of the experiments that are not controls of another present
        one (a control whose family is absent stays a family of its own).
    """
    tables = [t for t in tables if not t.empty]
    names = {t["family"].iloc[0] for t in tables}
    out = {}
    extra = {}
    for t in tables:
        name = t["family"].iloc[0]
        family, _, control = name.partition("-")
        if control and family in names:
            rows = t[t["control"] == "primary"].assign(
                family=family, control=control,
                detail=lambda d, n=name: f"from the experiment {n}: " + d["detail"])
            extra.setdefault(family, []).append(rows)
        else:
            out[name] = t
    for family, parts in extra.items():
        merged = pd.concat([out[family], *parts], ignore_index=True)
        pair = list(zip(merged["diagnostic"], merged["system"], strict=True))
        first = {p: k for k, p in reversed(list(enumerate(pair)))}
        rank = np.array([first[p] for p in pair])
        merged = merged.iloc[np.argsort(rank, kind="stable")].reset_index(drop=True)
        out[family] = with_robustness(merged)
    return out
