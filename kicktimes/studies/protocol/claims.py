"""The paper's claims, one row each: its words, the reproduction by its protocol, the verdict.

The FTLE, autocorrelation and recurrence claims come from this study's tables
(`kicktimes.studies.protocol.tables`); the collision-count claims from the findings tables
of the paper study (``family_*_findings.csv`` of ``kicktimes reproduce --study paper``).

"Decided by" names the choices that change the verdict when switched alone, away from
the paper's protocol; empty when none does. "reproduces?" comes from the verdict by the
paper's protocol through `kicktimes.studies.protocol.verdicts.reproduces`, by the claim's
``kind``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.stats import (
    equivalence_sample_size,
    format_interval,
    percentile_interval,
    ratio_verdict,
    robust_verdict,
)
from kicktimes.studies.protocol.tables import PAPER_READING, reading_label
from kicktimes.studies.protocol.verdicts import (
    CLOSER_MARGIN,
    balloon_verdict,
    closer_verdict,
    reproduces,
)

__all__ = ["claims_table", "SMALL_RADIUS", "SWITCHES"]

#: the paper's "small radii" of Fig. 7 (its bottom panel) are not given; kicktimes takes
#: r <= 0.014, the lower third of family A's radii
SMALL_RADIUS = 0.014

_RENORMALISED = ("renormalised", "paper", "shared", "uniform")
#: the single switches away from the paper's reading, named by what they change
SWITCHES = (
    ("estimator → renormalised", ("renormalised", "paper", "shared", "uniform")),
    ("measure → norm", ("literal", "norm", "shared", "uniform")),
    ("twin kicks → independent", ("literal", "paper", "independent", "uniform")),
    ("N(0, 1) new direction", ("literal", "paper", "shared", "normal")),
    ("N(0, 1) rotation", ("literal", "paper", "shared", "gaussian")),
)


def _row(claim, words, figure, family, system, quantity, protocol, est, other_name, other,
         robust, decided_by, kind):
    return {
        "claim": claim, "paper_says": words, "figure": figure, "family": family,
        "system": system, "quantity": quantity, "paper_protocol": protocol,
        "estimate": est[0], "ci_low": est[1], "ci_high": est[2], "verdict": est[3],
        "other_reading": other_name, "other_estimate": other[0], "other_ci_low": other[1],
        "other_ci_high": other[2], "other_verdict": other[3], "robust": bool(robust),
        "decided_by": decided_by, "kind": kind,
    }


def _ftle_claim(ratio_tab, panel, system, claim, words, figure):
    by = ratio_tab[(ratio_tab["family"] == panel) & (ratio_tab["system"] == system)
                   ].set_index("control")

    def get(reading):
        r = by.loc[reading_label(reading)]
        return r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]

    paper = get(PAPER_READING)
    changes = []
    for name, reading in SWITCHES:
        other = get(reading)
        if other[3] != paper[3]:
            changes.append(name)
        elif not robust_verdict([paper[3], other[3]], [paper[1], other[1]],
                                [paper[2], other[2]])[0]:
            changes.append(f"{name} (direction)")
    robust = bool(by.loc[reading_label(PAPER_READING), "robust"])
    return _row(claim, words, figure, panel, system, "FTLE ratio kicked / two-disk",
                reading_label(PAPER_READING), paper, reading_label(_RENORMALISED),
                get(_RENORMALISED), robust, "; ".join(changes), "agreement")


def _r1_claim(r1_tab, panel, system, words, figure):
    by = r1_tab[(r1_tab["family"] == panel) & (r1_tab["system"] == system)
                ].set_index("diagnostic")

    def get(d):
        r = by.loc[d]
        return r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]

    paper, other = get("r1"), get("one_minus_r1")
    return _row(f"ACF, {system}", words, figure, panel, system,
                "R₁ ratio kicked / two-disk, t ≤ nτ", "R₁ (the paper's Fig. 8)", paper,
                "1 − R₁ over t ≤ nτ (decorrelation)", other, False,
                "quantity (R₁ → 1 − R₁)" if paper[3] != other[3] else "", "agreement")


def _rr_claim(rr_tab, panel, system, subset, words):
    sel = rr_tab[(rr_tab["family"] == panel.name) & (rr_tab["system"] == system)
                 & (rr_tab["control"] == subset)].set_index("diagnostic")
    if sel.empty:  # no radius of the panel in this subset
        return None
    paper, other = sel.loc["rr_with_diagonal"], sel.loc["rr_offdiag"]
    small = subset == "small_radii"

    def get(r):
        # the balloon is a sign (the two-disk RR above the kicked one), not an agreement
        verdict = r["verdict"] if small else balloon_verdict(r["ci_low"], r["ci_high"])
        return r["estimate"], r["ci_low"], r["ci_high"], verdict

    est, alt = get(paper), get(other)
    kind = "agreement" if small else "balloon"
    if not paper["figure"].startswith("Fig. 7"):
        kind = "not_in_paper"
    return _row(f"RR, {'small' if small else 'larger'} radii, {system}", words,
                paper["figure"].removeprefix("Fig. "), panel.name, system,
                f"RR ratio kicked / two-disk (ε = 0.001), r = {paper['radii']}",
                "with the main diagonal, the paper's steps", est, "off the diagonal", alt,
                False, "quantity (with → without the diagonal)" if est[3] != alt[3] else "",
                kind)


def _findings(findings_dir, name):
    path = Path(findings_dir) / name
    if not path.exists():
        raise FileNotFoundError(f"findings_dir: {path} is missing")
    return pd.read_csv(path)


def _finding(findings_dir, family, diagnostic, system):
    """The paper study's rows of one diagnostic and system, by control."""
    frame = _findings(findings_dir, f"{family}_findings.csv")
    sel = frame[(frame["diagnostic"] == diagnostic) & (frame["system"] == system)]
    if sel.empty:
        raise ValueError(f"findings_dir: {family}_findings.csv has no {diagnostic} row of "
                         f"{system}")
    return sel.set_index("control")


def _get(by, control):
    r = by.loc[control]
    return r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]


def _controls_note(by, control="primary"):
    """"controls (k of n)": how many of the paper study's other controls change its
    verdict; empty when none does."""
    others = [c for c in by.index if c != control]
    changes = [c for c in others if by.loc[c, "verdict"] != by.loc[control, "verdict"]]
    return f"controls ({len(changes)} of {len(others)})" if changes else ""


def _decided(est, other, switch, note):
    """"Decided by" of a row whose other reading is another test: ``switch`` when both
    readings ran and their verdicts differ, then the controls' ``note``."""
    ran = np.isfinite(est[0]) and np.isfinite(other[0])
    return "; ".join(x for x in (switch if ran and est[3] != other[3] else "", note) if x)


def _fig4_claim(fig4_tab, findings_dir, panel):
    """Fig. 4: the paper's least-squares line (slope of the Poisson kick times on the
    collision times), beside the other reading of its conclusion, the share of runs whose
    collision times reject uniformity (the paper study's findings)."""
    sel = fig4_tab[fig4_tab["family"] == panel.name] if not fig4_tab.empty else fig4_tab
    if sel.empty:
        est, kind = (math.nan, math.nan, math.nan, "not run"), "not_tested"
        radius = min(panel.radii)
    else:
        r = sel.iloc[0]
        est, kind, radius = (r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]), \
            "agreement", r["radius"]
    other, note = (math.nan, math.nan, math.nan, "not read"), ""
    if findings_dir is not None:
        by = _finding(findings_dir, panel.name, "reject@uniformity_ks", "two_particle")
        other, note = _get(by, "primary"), _controls_note(by)
    return _row("Poisson kick times (fit)", "high-quality linear fit: Poisson a reasonable "
                "approximation", "4", panel.name, "poisson",
                f"slope of Poisson kick times on collision times, r = {radius:g}",
                "least-squares line, per IC", est,
                "share of runs rejecting uniform collision times (α = 0.05, every radius)",
                other, False, _decided(est, other, "reading (fit → uniformity test)", note),
                kind)


def _fig5_claim(line_tab, findings_dir, panel):
    """Fig. 5: the paper's least-squares line through the mean counts against r, beside
    the other reading, the counts over kinetic theory's Γ(r)T (the paper study's)."""
    sel = line_tab[line_tab["family"] == panel.name] if not line_tab.empty else line_tab
    if sel.empty:
        est, kind = (math.nan, math.nan, math.nan, "not run"), "not_tested"
    else:
        r = sel.iloc[0]
        est, kind = (r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]), "line_fit"
    other, note = (math.nan, math.nan, math.nan, "not read"), ""
    if findings_dir is not None:
        by = _finding(findings_dir, panel.name, "counts", "two_particle")
        other, note = _get(by, "primary"), _controls_note(by)
    return _row("Counts vs radius (line)", "linear fit reasonably good", "5", panel.name,
                "two_particle", "RMS relative residual of the mean counts about their line",
                "least-squares line of mean counts on r", est,
                "counts / kinetic theory Γ(r)T (the paper study's)", other, False,
                _decided(est, other, "reading (line → kinetic theory)", note), kind)


def _closer(ratios, panel, reading):
    """|log R_poisson| - |log R_actual| under ``reading``: point, 95 % CI and verdict
    (`kicktimes.studies.protocol.verdicts.closer_verdict`, margin `CLOSER_MARGIN`;
    negative: the Poisson kicks are closer to the two-disk value). An inconclusive
    verdict names the ICs at which the margin would be resolved
    (`kicktimes.stats.equivalence_sample_size` from the resamples' standard error)."""
    _, op, dp = ratios.ratio(panel, "poisson", reading)
    _, oa, da = ratios.ratio(panel, "actual", reading)
    point = abs(math.log(op["ratio"])) - abs(math.log(oa["ratio"]))
    with np.errstate(invalid="ignore", divide="ignore"):
        diff = np.abs(np.log(dp)) - np.abs(np.log(da))
    lo, hi = percentile_interval(diff)
    verdict = closer_verdict(lo, hi)
    if verdict == "inconclusive":
        n = equivalence_sample_size(float(np.nanstd(diff)), int(op["n_ics"]), margin=CLOSER_MARGIN)
        verdict = f"inconclusive ({n} ICs would resolve it)"
    return point, float(lo), float(hi), verdict


def _angle_ratio(ratios, panel, system, angle, estimator):
    """R(N(0, 1) reading) / R(uniform) under ``estimator``: point, 95 % CI, verdict."""
    _, o1, d1 = ratios.ratio(panel, system, (estimator, "paper", "shared", angle))
    _, o0, d0 = ratios.ratio(panel, system, (estimator, "paper", "shared", "uniform"))
    with np.errstate(invalid="ignore", divide="ignore"):
        q = d1 / d0
    lo, hi = percentile_interval(q)
    return o1["ratio"] / o0["ratio"], float(lo), float(hi), ratio_verdict(lo, hi)


def claims_table(ratios, ratio_tab, r1_tab, rr_tab, findings_dir, panels, *,
                 line_tab=None, fig4_tab=None) -> pd.DataFrame:
    """One row per claim of the paper: its words and figure, the reproduction by the
    paper's protocol (estimate, 95 % CI, verdict), the other reading, whether the verdict
    is robust, the choices that decide it, and "reproduces?" (`verdicts.reproduces`).
    ``findings_dir``: the paper study's findings tables at the same scale, or ``None``
    (their readings then say "not read"); ``line_tab`` / ``fig4_tab``: the Fig. 5 and
    Fig. 4 lines (`tables.count_line_table`, `tables.fig4_table`), or ``None`` (the
    paper's protocol is then "not tested" there)."""
    a, b = panels[0], panels[1]
    empty = pd.DataFrame(columns=["family"])
    line_tab = empty if line_tab is None else line_tab
    fig4_tab = empty if fig4_tab is None else fig4_tab
    rows = [
        _ftle_claim(ratio_tab, a.name, "poisson", "FTLE, Poisson kicks",
                    "a good approximation", "6 top"),
        _ftle_claim(ratio_tab, a.name, "actual", "FTLE, actual kicks",
                    "the same order of magnitude", "6 top"),
        _ftle_claim(ratio_tab, b.name, "actual", "FTLE, actual kicks",
                    "an excellent approximation", "6 bottom"),
        _ftle_claim(ratio_tab, b.name, "poisson", "FTLE, Poisson kicks",
                    "also very similar", "6 bottom"),
    ]
    for p in panels:
        for subset, words in (("small_radii", "very good agreement (small radii)"),
                              ("larger_radii", "a two-disk balloon (ratio < 1)")):
            for system in ("poisson", "actual"):
                row = _rr_claim(rr_tab, p, system, subset, words)
                if row is not None:
                    rows.append(row)
    for p, figure, words in ((a, "8 top", "excellent agreement"),
                             (b, "8 bottom", "good agreement")):
        for system in ("poisson", "actual"):
            rows.append(_r1_claim(r1_tab, p.name, system, words, figure))
    for p in panels:
        point, lo, hi, verdict = _closer(ratios, p.name, PAPER_READING)
        alt = _closer(ratios, p.name, _RENORMALISED)
        rows.append(_row(
            "Poisson vs actual", "Poisson sometimes better", f"Sec. IV, {p.figure[5:]}",
            p.name, "poisson − actual", "|log R_Poisson| − |log R_actual| (FTLE)",
            reading_label(PAPER_READING), (point, lo, hi, verdict),
            reading_label(_RENORMALISED), alt,
            verdict == alt[3] and not verdict.startswith("inconclusive"),
            "estimator → renormalised" if verdict != alt[3] else "", "poisson_better"))
    for p in panels:
        for angle, name in (("normal", "new direction"), ("gaussian", "rotation")):
            lit = _angle_ratio(ratios, p.name, "poisson", angle, "literal")
            ren = _angle_ratio(ratios, p.name, "poisson", angle, "renormalised")
            robust, why = robust_verdict([lit[3], ren[3]], [lit[1], ren[1]],
                                         [lit[2], ren[2]])
            rows.append(_row(
                f"N(0, 1) as {name}", "similar qualitative results", f"Sec. IV A, {p.figure[5:]}",
                p.name, "poisson", "FTLE ratio R(N(0, 1)) / R(uniform)",
                f"literal/paper/shared/{angle}", lit, f"renormalised/paper/shared/{angle}", ren,
                robust, "" if robust else f"estimator → renormalised ({why})", "agreement"))
    rows += [_fig4_claim(fig4_tab, findings_dir, p) for p in panels]
    rows += [_fig5_claim(line_tab, findings_dir, p) for p in panels]
    out = pd.DataFrame(rows)
    out["reproduces"] = [reproduces(k, v) for k, v in zip(out["kind"], out["verdict"],
                                                         strict=True)]
    out["interval"] = [format_interval(e, lo, hi) for e, lo, hi in
                       zip(out["estimate"], out["ci_low"], out["ci_high"], strict=True)]
    out["other_interval"] = [format_interval(e, lo, hi) for e, lo, hi in zip(
        out["other_estimate"], out["other_ci_low"], out["other_ci_high"], strict=True)]
    return out
