r"""Every comparison finding under its controls, and whether its verdict survives them.

A ratio "kicked system / two-disk system" is a finding only if its verdict is the same
under every control that applies to it; otherwise it *depends on* the control that
changes it. The controls:

``primary``
    The report's setting: per radius the ratio of ensemble means
    :math:`\rho_r = \sum_i x_{ri} / \sum_i y_{ri}`, averaged over radii
    (:func:`kicktimes.stats.paired_ratio`).
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
    differ in number between the systems, are the control ``paper_sampling`` (the
    primary row's detail names its uniform-time samples; no row repeats it, so that no
    control is counted twice).
``invariant_ics``, ``elastic``, ``elastic+invariant_ics``
    Other experiments (`merge_control_families`): the 2 x 2 design collision rule (the
    paper's mirror rule, the elastic rule) x initial conditions (the paper's procedure, the
    invariant measure); their primary rows join the family's table under these names.

Every interval is a percentile bootstrap clustered on ICs: one resample draws IC indices
with replacement and applies them at every radius and to every system (the same IC is
the same initial condition everywhere), so the correlation of one IC across radii and
systems is kept. Verdicts use each diagnostic's band (:func:`kicktimes.stats.ratio_verdict`
with :func:`kicktimes.stats.margin_of`: ±5 % for the FTLE, ±3 % for the off-diagonal RR,
±2.5 % for the counts, ±10 % otherwise): *within* when the whole 95 % interval lies in the
band, *higher* / *lower*
when it lies entirely above / below it, *inconclusive* otherwise. A comparison is *robust*
(:func:`kicktimes.stats.robust_verdict`) only when every control gives the same verdict and
no control's interval lies above 1 while another's lies below 1; otherwise it *depends on*
the first control that breaks it (the ``depends_on`` column).

The Poisson question is in the same table (:func:`poisson_rows`): per test, the share of
runs whose two-disk collision times reject it, with the verdict of
:func:`kicktimes.stats.rejection_verdict`, under the same rule x IC design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes.report.store import REFERENCE, kicked_systems, wide
from kicktimes.stats import (
    margin_of,
    paired_median,
    paired_ratio,
    ratio_verdict,
    rejection_verdict,
    robust_verdict,
)

__all__ = [
    "COLUMNS",
    "CONTROLS",
    "Controls",
    "compute_controls",
    "diagnostics_of",
    "paired_median",
    "poisson_rows",
    "with_robustness",
]

#: the controls, in the order of the table (then the other experiments' controls)
CONTROLS = ("primary", "paired_median", "sticky_excluded", "paper_sampling")
#: the columns of the findings table
COLUMNS = ("family", "question", "diagnostic", "system", "control", "estimate", "ci_low",
           "ci_high", "verdict", "margin", "verdict_at_margin", "robust", "depends_on",
           "n_pairs", "detail")
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
        # ``verdict``: the tables' common ±10 % band (`MARGIN`); ``verdict_at_margin``: the
        # diagnostic's own margin (`margin_of`), the one the pages read and robustness uses
        "verdict": ratio_verdict(low, high),
        "margin": margin_of(diagnostic),
        "verdict_at_margin": ratio_verdict(low, high, tolerance=margin_of(diagnostic)),
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
        The kinetic rate against the radius, as in `kicktimes.report.counts.sticky_ics`.

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
        ok, _ = robust_verdict(list(_read_verdicts(g)), g["ci_low"], g["ci_high"],
                               level=np.inf if share else 1.0)
        pos = out.index.get_indexer(g.index)
        robust[pos] = ok
        if not ok:
            depends[pos] = _deciding_control(g, share)
    out["robust"] = robust
    out["depends_on"] = depends
    return out


def _read_verdicts(g: pd.DataFrame) -> pd.Series:
    """The verdicts robustness reads: each row's ``verdict_at_margin`` (its diagnostic's
    own margin) where it has one, else its ``verdict`` (the Poisson rows)."""
    if "verdict_at_margin" not in g.columns:
        return g["verdict"]
    at = g["verdict_at_margin"]
    return at.where(at.notna() & (at.astype(str) != ""), g["verdict"])


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
    verdicts = _read_verdicts(g)
    changed = others[verdicts.iloc[1:].to_numpy() != verdicts.iloc[0]]
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
                     "ΣN / Σ Γ(r)T per radius, averaged over radii"))
    med = paired_median(observed, expected, rng=rng, n_boot=max(200, n_boot // 2))
    rows.append(_row(family, "counts", REFERENCE, "paired_median", med["ratio"], med["ci_low"],
                     med["ci_high"], med["n_pairs"], "median of per-IC N / Γ(r)T"))
    keep = ~sticky.reindex(observed.index, fill_value=False).to_numpy(bool)
    per_r, tot = paired_ratio(observed[keep], expected[keep], rng=rng, n_boot=n_boot)
    rows.append(_row(family, "counts", REFERENCE, "sticky_excluded", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     f"{int((~keep).sum())} sticky runs left out"))
    return rows


def poisson_rows(family, rejections, per_ic, *, alpha, rng, n_boot=2000, null=None,
                 cis=None, referenced=None):
    """The Poisson question as rows of the findings table: per test of the battery, the
    share of (radius, IC) runs whose two-disk collision times reject it at ``alpha``, read
    against the share that null streams shaped like the runs reject through the same test
    (``null``, a `kicktimes.report.poisson.null_calibration` table: the calibrated level;
    ``alpha`` without one); then the dispersion index and the one standard for "Poisson".

    Rows ``diagnostic = "reject@<test>"`` pool the runs of every radius with a
    Clopper-Pearson interval; the headline test's rows (`poisson.HEADLINE_TEST`, on the
    whole window and ``"@first<n>"`` on the first `poisson.FIXED_EVENTS` collisions of
    every run that has them, the same power at every radius) have a bootstrap interval
    clustered on ICs instead (the runs of one IC at different radii share its initial
    condition). Their verdict is :func:`kicktimes.stats.rejection_verdict`'s against the
    calibrated level: *nominal*, *above nominal*, *below nominal* or *inconclusive*.
    The row ``"dispersion_index"`` is the mean over runs of D, the variance over the mean
    of the counts in 10 equal sub-windows (1 for Poisson; bootstrap clustered on ICs),
    with :func:`kicktimes.stats.ratio_verdict`'s verdict in the 10 % band; the row
    ``"poisson@<headline test>"`` is :func:`kicktimes.stats.poisson_verdict` of the two.

    Parameters
    ----------
    family : str
        The experiment's name.
    rejections : pandas.DataFrame
        The Poisson section's table (``radius, test, n_tested, n_reject``).
    per_ic : pandas.DataFrame
        The headline test's p-values and D per run (``radius, ic, p, p_fixed,
        dispersion``).
    alpha : float
        The tests' level.
    rng : numpy.random.Generator
        The clustered bootstrap's stream.
    n_boot : int
        Its resamples.
    null : pandas.DataFrame, optional
        The null calibration of the same runs.
    cis : dict, optional
        Clustered CIs already computed, by ``per_ic`` column (``"p"``, ``"p_fixed"``), so
        that every page prints the same interval; the others are computed with ``rng``.
    referenced : pandas.DataFrame, optional
        `kicktimes.report.poisson.null_referenced` of the same runs: then D, the first
        hazard bin and the gamma shape are read against their control streams' values
        (rows ``<statistic>_excess``, the paired difference, by
        :func:`kicktimes.stats.null_verdict`), and the one standard reads D against its
        null (``against_null``).
    """
    from kicktimes.report.poisson import (
        FIXED_EVENTS,
        HEADLINE_TEST,
        clustered_mean,
        clustered_share,
        null_level,
    )
    from kicktimes.stats import poisson_verdict
    from kicktimes.stats.findings import clopper_pearson

    rows = []

    def add(diagnostic, estimate, n, low, high, verdict, detail):
        rows.append({
            "family": family, "question": POISSON_QUESTION, "diagnostic": diagnostic,
            "system": REFERENCE, "control": "primary", "estimate": estimate, "ci_low": low,
            "ci_high": high, "verdict": verdict, "robust": False,
            "depends_on": "", "n_pairs": int(n), "detail": detail})

    def calibrated(test):
        level = null_level(null, test, alpha)
        return level, (f"; read against the share of null streams the test rejects, "
                       f"{100 * level:.1f} % (null_calibration.csv)" if null is not None
                       and not null.empty else f"; read against α = {alpha:g} (no null "
                       "calibration)")

    def share_ci(column):
        if cis is not None and column in cis:
            return cis[column]
        return clustered_share(per_ic, column, alpha, rng=rng, n_boot=n_boot)

    totals = rejections.groupby("test", sort=False, observed=True)[["n_reject", "n_tested"]].sum()
    for test, (k, n) in totals.iterrows():
        if n == 0:
            continue
        if test == HEADLINE_TEST and per_ic is not None:
            low, high = share_ci("p")
            how = "95 % CI from a bootstrap clustered on ICs"
        else:
            low, high = clopper_pearson(int(k), int(n))
            how = "Clopper-Pearson 95 % CI (runs of one IC at different radii counted apart)"
        level, against = calibrated(test)
        add(f"reject@{test}", k / n, n, low, high, rejection_verdict(low, high, alpha=level),
            f"share of runs rejecting {test} at α = {alpha:g}, every radius, whole window; "
            + how + against)
    if per_ic is not None and np.isfinite(per_ic["p_fixed"]).any():
        p = per_ic["p_fixed"].to_numpy(float)
        ok = np.isfinite(p)
        low, high = share_ci("p_fixed")
        add(f"reject@{HEADLINE_TEST}@first{FIXED_EVENTS}", (p[ok] < alpha).sum() / ok.sum(),
            ok.sum(), low, high, rejection_verdict(low, high, alpha=alpha),
            f"{HEADLINE_TEST} on the first {FIXED_EVENTS} collisions of every run that has "
            "them (the same power at every radius); 95 % CI from a bootstrap clustered on "
            f"ICs; read against α = {alpha:g}")
    names = [r["diagnostic"] for r in rows]
    if (per_ic is not None and "dispersion" in per_ic.columns
            and f"reject@{HEADLINE_TEST}" in names):
        n_d = int(np.isfinite(per_ic["dispersion"].to_numpy(float)).sum())
        head = rows[names.index(f"reject@{HEADLINE_TEST}")]
        level, _ = calibrated(HEADLINE_TEST)
        if referenced is not None and len(referenced):
            from kicktimes.report.poisson import NULL_REFERENCED
            from kicktimes.stats import D_MARGIN, null_verdict

            for r in referenced.itertuples():
                margin = D_MARGIN if r.statistic == "D" else SHAPE_MARGIN
                diagnostic = NULL_REFERENCED[r.statistic]
                verdict = null_verdict(r.excess_low, r.excess_high, margin=margin)
                null_text = (f"its null (the runs' Poisson control streams) "
                             f"{r.null:.3g} [{r.null_low:.3g}, {r.null_high:.3g}]")
                add(diagnostic, r.value, n_d, r.low, r.high, verdict,
                    f"{NULL_WORDS[r.statistic]}; 95 % CI from a bootstrap clustered on ICs; "
                    f"read against {null_text} (the {diagnostic}_excess row)")
                add(f"{diagnostic}_excess", r.excess, n_d, r.excess_low, r.excess_high,
                    verdict, f"{r.statistic} minus {null_text}, paired by run; "
                    f"kicktimes.stats.null_verdict with margin {margin:g}")
            d = referenced.set_index("statistic").loc["D"]
            add(f"poisson@{HEADLINE_TEST}", head["estimate"], head["n_pairs"], head["ci_low"],
                head["ci_high"], poisson_verdict(head["ci_low"], head["ci_high"], null_level=level,
                                                 dispersion_low=d.excess_low,
                                                 dispersion_high=d.excess_high,
                                                 against_null=True),
                f"kicktimes.stats.poisson_verdict: the {HEADLINE_TEST} rejection share against "
                f"its calibrated level {100 * level:.1f} % and D − null D {d.excess:.3g} "
                f"[{d.excess_low:.3g}, {d.excess_high:.3g}] against ±{D_MARGIN:g}")
            return rows
        d, d_low, d_high = clustered_mean(per_ic, "dispersion", rng=rng, n_boot=n_boot)
        add("dispersion_index", d, n_d, d_low, d_high, ratio_verdict(d_low, d_high, tolerance=0.1),
            NULL_WORDS["D"] + "; 95 % CI from a bootstrap clustered on ICs; no null streams: "
            "verdict in the ±10 % band around 1")
        add(f"poisson@{HEADLINE_TEST}", head["estimate"], head["n_pairs"], head["ci_low"],
            head["ci_high"], poisson_verdict(head["ci_low"], head["ci_high"], null_level=level,
                                             dispersion_low=d_low, dispersion_high=d_high),
            f"kicktimes.stats.poisson_verdict: the {HEADLINE_TEST} rejection share against its "
            f"calibrated level {100 * level:.1f} % and D {d:.3g} [{d_low:.3g}, {d_high:.3g}] "
            "against [0.9, 1.1]")
    return rows


#: the margin of the first hazard bin and of the gamma shape read against their null
#: streams' values: half the 10 % equivalence margin of every ratio (docs/definitions.md)
SHAPE_MARGIN = 0.05
#: what each null-referenced statistic of the two-disk runs is
NULL_WORDS = {
    "D": "within-run dispersion index: mean over runs of D = variance / mean of the run's "
         "counts in 10 equal sub-windows of its window",
    "hazard, first bin": "hazard of the intervals in [0, 0.1) of each run's mean interval, "
                         "pooled, over the constant rate",
    "gamma shape": "shape of a gamma fit to the pooled intervals in units of each run's "
                   "mean interval"}


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
