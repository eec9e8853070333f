"""The paper's claims, one row each: its words, the reproduction by its protocol, the verdict.

The FTLE and autocorrelation claims come from this study's tables
(`kicktimes.studies.protocol.tables`); the recurrence and collision-count claims from the
findings tables of the paper study (``family_*_findings.csv`` and
``family_*_findings_by_radius.csv`` of ``kicktimes reproduce --study paper``), whose
``paper_sampling`` control is the paper's own sampling.

"Decided by" names the choices that change the verdict when switched alone, away from
the paper's protocol; empty when none does.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.stats import format_interval, ratio_verdict, robust_verdict
from kicktimes.stats.findings import share_verdict
from kicktimes.studies.protocol.tables import PAPER_READING, reading_label

__all__ = ["claims_table", "SWITCHES"]

_RENORMALISED = ("renormalised", "paper", "shared", "uniform")
#: the paper's "small radii" of Fig. 7 (its bottom panel) are not given; kicktimes takes
#: r <= 0.014, the lower third of family A's radii
SMALL_RADIUS = 0.014
#: the single switches away from the paper's reading, named by what they change
SWITCHES = (
    ("estimator → renormalised", ("renormalised", "paper", "shared", "uniform")),
    ("measure → norm", ("literal", "norm", "shared", "uniform")),
    ("twin kicks → independent", ("literal", "paper", "independent", "uniform")),
    ("N(0, 1) new direction", ("literal", "paper", "shared", "normal")),
    ("N(0, 1) rotation", ("literal", "paper", "shared", "gaussian")),
)


def _row(claim, words, figure, family, system, quantity, protocol, est, other_name, other,
         robust, decided_by):
    return {
        "claim": claim, "paper_says": words, "figure": figure, "family": family,
        "system": system, "quantity": quantity, "paper_protocol": protocol,
        "estimate": est[0], "ci_low": est[1], "ci_high": est[2], "verdict": est[3],
        "other_reading": other_name, "other_estimate": other[0], "other_ci_low": other[1],
        "other_ci_high": other[2], "other_verdict": other[3], "robust": bool(robust),
        "decided_by": decided_by,
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
                get(_RENORMALISED), robust, "; ".join(changes))


def _r1_claim(r1_tab, panel, system, words, figure):
    by = r1_tab[(r1_tab["family"] == panel) & (r1_tab["system"] == system)
                ].set_index("diagnostic")

    def get(d):
        r = by.loc[d]
        return r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]

    paper, other = get("r1"), get("one_minus_r1")
    return _row(f"ACF, {system}", words, figure, panel, system,
                "R₁ ratio kicked / two-disk", "R₁ (the paper's Fig. 8)", paper,
                "1 − R₁ (decorrelation)", other, False,
                "quantity (R₁ → 1 − R₁)" if paper[3] != other[3] else "")


def _findings(findings_dir, name):
    path = Path(findings_dir) / name
    if not path.exists():
        raise FileNotFoundError(f"findings_dir: {path} is missing")
    return pd.read_csv(path)


def _family_claim(findings_dir, family, diagnostic, system, control, claim, words, figure,
                  quantity):
    frame = _findings(findings_dir, f"{family}_findings.csv")
    sel = frame[(frame["diagnostic"] == diagnostic) & (frame["system"] == system)]
    by = sel.set_index("control")

    def get(c):
        r = by.loc[c]
        return r["estimate"], r["ci_low"], r["ci_high"], r["verdict"]

    paper = get(control)
    others = [c for c in by.index if c != control]
    changes = [c for c in others if by.loc[c, "verdict"] != paper[3]]
    primary = "primary" if control != "primary" else others[0]
    return _row(claim, words, figure, family, system, quantity, control, paper, primary,
                get(primary), bool(by.loc[control, "robust"]),
                f"controls ({len(changes)} of {len(others)})" if changes else "")


def _verdict_counts(verdicts) -> str:
    """``"higher at 3 of 4 radii; inconclusive at 1"``: the per-radius verdicts, counted."""
    counts = pd.Series(list(verdicts)).value_counts()
    parts = [f"{v} at {n}" + (f" of {len(verdicts)} radii" if k == 0 else "")
             for k, (v, n) in enumerate(counts.items())]
    return "; ".join(parts)


def _radius_claim(findings_dir, family, diagnostic, system, radii, claim, words, figure,
                  quantity):
    """The per-radius ratios at ``radii`` under the paper's sampling and under uniform-time
    samples (the paper study's ``primary`` recurrence rows): the lowest and highest ratio
    (``estimate`` the median) and the per-radius verdicts, counted."""
    frame = _findings(findings_dir, f"{family}_findings_by_radius.csv")
    sel = frame[(frame["diagnostic"] == diagnostic) & (frame["system"] == system)
                & frame["radius"].isin(radii)]

    def summary(control):
        part = sel[sel["control"] == control].sort_values("radius")
        verdicts = [ratio_verdict(lo, hi) for lo, hi in zip(part["ci_low"], part["ci_high"],
                                                            strict=True)]
        return (part["ratio"].median(), part["ratio"].min(), part["ratio"].max(),
                _verdict_counts(verdicts), verdicts, part)

    paper, uniform = summary("paper_sampling"), summary("primary")
    robust = (paper[4] == uniform[4]
              and not ((paper[5]["ci_low"] > 1).any() and (uniform[5]["ci_high"] < 1).any()))
    row = _row(f"{claim} (r = {min(radii):g}–{max(radii):g})", words, figure, family, system,
               quantity, "paper_sampling", paper[:4], "uniform_sampling", uniform[:4],
               robust, "" if robust else "sampling (paper's steps → uniform)")
    # a range over radii, not an interval: the per-radius CIs are in the findings table
    row.update(range_low=paper[1], range_high=paper[2], other_range_low=uniform[1],
               other_range_high=uniform[2], ci_low=math.nan, ci_high=math.nan,
               other_ci_low=math.nan, other_ci_high=math.nan, range=True,
               interval=f"{paper[1]:.3g}–{paper[2]:.3g}",
               other_interval=f"{uniform[1]:.3g}–{uniform[2]:.3g}")
    return row


def _closer(ratios, panel, reading):
    """|log R_poisson| - |log R_actual| under ``reading``: point and 95 % CI (negative:
    the Poisson kicks are closer to the two-disk value)."""
    _, op, dp = ratios.ratio(panel, "poisson", reading)
    _, oa, da = ratios.ratio(panel, "actual", reading)
    point = abs(math.log(op["ratio"])) - abs(math.log(oa["ratio"]))
    with np.errstate(invalid="ignore", divide="ignore"):
        diff = np.abs(np.log(dp)) - np.abs(np.log(da))
    lo, hi = np.percentile(diff[np.isfinite(diff)], [2.5, 97.5])
    verdict = {"below": "Poisson closer", "above": "actual closer"}.get(
        share_verdict(lo, hi, 0.0), "inconclusive")
    return point, float(lo), float(hi), verdict


def _angle_ratio(ratios, panel, system, angle, estimator):
    """R(N(0, 1) reading) / R(uniform) under ``estimator``: point, 95 % CI, verdict."""
    _, o1, d1 = ratios.ratio(panel, system, (estimator, "paper", "shared", angle))
    _, o0, d0 = ratios.ratio(panel, system, (estimator, "paper", "shared", "uniform"))
    with np.errstate(invalid="ignore", divide="ignore"):
        q = d1 / d0
    lo, hi = np.percentile(q[np.isfinite(q)], [2.5, 97.5])
    return o1["ratio"] / o0["ratio"], float(lo), float(hi), ratio_verdict(lo, hi)


def claims_table(ratios, ratio_tab, r1_tab, findings_dir, panels) -> pd.DataFrame:
    """One row per claim of the paper: its words and figure, the reproduction by the
    paper's protocol (estimate, 95 % CI, verdict), the other reading, whether the verdict
    is robust, and the choices that decide it. Rows over several radii (``range``: the
    recurrence rate per radius) give the median ratio as ``estimate``, the lowest and
    highest as ``range_low`` / ``range_high`` (no CI), and the per-radius verdicts counted.
    ``findings_dir``: the paper study's findings tables at the same scale, or ``None`` (no
    recurrence and count rows)."""
    a, b = panels[0], panels[1]
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
    small = [r for r in a.radii if r <= SMALL_RADIUS]
    large = [r for r in a.radii if r > SMALL_RADIUS]
    with_findings = findings_dir is not None
    for system in ("poisson", "actual") if with_findings else ():
        rows.append(_radius_claim(findings_dir, a.name, "rr_offdiag@0.001", system, small,
                                  f"RR, small radii, {system}", "very good agreement", "7",
                                  "RR ratio kicked / two-disk (ε = 0.001), per radius"))
    for system in ("poisson", "actual") if with_findings else ():
        rows.append(_radius_claim(findings_dir, a.name, "rr_offdiag@0.001", system, large,
                                  f"RR, larger radii, {system}", "two-disk RR balloons", "7",
                                  "RR ratio kicked / two-disk (ε = 0.001), per radius"))
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
            verdict == alt[3] and verdict != "inconclusive",
            "estimator → renormalised" if verdict != alt[3] else ""))
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
                robust, "" if robust else f"estimator → renormalised ({why})"))
    for p in panels if with_findings else ():
        rows.append(_family_claim(
            findings_dir, p.name, "counts", "two_particle", "primary", "Counts vs radius",
            "linear fit reasonably good", "5",
            "counts / kinetic theory Γ(r)T (linear in r)"))
    for row in rows:
        if not row.get("range"):
            row["interval"] = format_interval(row["estimate"], row["ci_low"], row["ci_high"])
            row["other_interval"] = format_interval(row["other_estimate"],
                                                    row["other_ci_low"], row["other_ci_high"])
            row["range"] = False
    return pd.DataFrame(rows)
