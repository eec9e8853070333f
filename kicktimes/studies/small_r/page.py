"""The Markdown of ``small_r.md``: the answers first, then the tables behind them."""

from __future__ import annotations

from kicktimes._results import format_interval
from kicktimes.diagnostics.low_density import SLOPES
from kicktimes.render.provenance import Source
from kicktimes.stats import margin_of
from kicktimes.studies.small_r.sweep import seconds_per_ic
from kicktimes.studies.small_r.tables import (
    KICKED,
    against_theory,
    findings,
    measured,
    ratio_table,
    theory_table,
)

__all__ = ["SOURCES", "answers", "body"]

SOURCES = (
    Source("small_r_measured.csv", "stretch, ci_low, ci_high, ratio, ratio_ci_low, "
           "ratio_ci_high, perturbations_per_ic", measured),
    Source("small_r_theory.csv", "stretch, se, ci_low, ci_high, slope, intercept, "
           "rate_over_kinetic", theory_table),
    Source("small_r_against_theory.csv", "measured, predicted, measured_over_predicted, "
           "ci_low, ci_high, verdict", against_theory),
    Source("small_r_ratios.csv", "ratio, ratio_ci_low, ratio_ci_high, ratio_verdict, "
           "predicted_ratio, predicted_ci_low, predicted_ci_high, measured_over_predicted, "
           "quotient_ci_low, quotient_ci_high, quotient_verdict, limit", ratio_table),
    Source("small_r_findings.csv", "estimate, ci_low, ci_high, verdict, verdict_at_margin, "
           "robust", findings),
    Source("small_r_cost.csv", "cpu_seconds, seconds_per_ic, collisions_per_ic",
           seconds_per_ic),
)

TOL = margin_of("ftle")


def _pct(x):
    return f"{100 * x:g} %"


def _ci(row, est, lo, hi):
    return format_interval(row[est], row[lo], row[hi], edges=(1 - TOL, 1.0, 1 + TOL))


def _limit_word(limit):
    return "holds" if limit == 1.0 else "fails"


def _name(system):
    return "two disks" if system == "two_particle" else KICKED[system]


def _intercepts(theory, systems):
    """``mirror: two disks -2.59, ...; elastic: ...``: a at the smallest radius."""
    low = theory[theory["radius"] == theory["radius"].min()].set_index(["rule", "system"])
    return "; ".join(f"{u}: " + ", ".join(f"{_name(s)} {low.loc[(u, s), 'intercept']:.2f}"
                                           for s in systems)
                     for u in sorted(set(theory["rule"])))


def _robust_text(g):
    """``robust at 5 of 6 radii; not at r = 0.03: primary ..., elastic ...``."""
    per_r = g.groupby("radius")["robust"].all()
    text = f"robust at {int(per_r.sum())} of {len(per_r)} radii"
    frail = [r for r, ok in per_r.items() if not ok]
    if not frail:
        return text
    first = g[g["radius"] == frail[0]]
    cells = "; ".join(f"{x['control']} {_ci(x, 'estimate', 'ci_low', 'ci_high')}, "
                      f"{x['verdict_at_margin']}" for _, x in first.iterrows())
    return (text + f"; not at r = {', '.join(f'{r:g}' for r in frail)} (at r = "
            f"{frail[0]:g}: {cells})")


def _sticky_text(robust):
    """How many ICs the sticky-run control left out, over its cells."""
    g = robust[robust["system"] == "poisson"].set_index(["radius", "control"])["n_ics"]
    primary = g.xs("primary", level="control")
    kept = g.xs("no_sticky", level="control")
    return (f"{int((primary - kept).sum())} of {int(primary.sum())} ICs of the primary rule "
            "(every radius)")


def answers(ratios, compare, robust, smallest) -> list[str]:
    """At most five one-line answers, each with its number, interval and caveat."""
    lines = []
    at = ratios[(ratios["radius"] == smallest) & (ratios["rule"] == "mirror")]
    for system in ("poisson", "poisson_scatter"):
        row = at[at["system"] == system].iloc[0]
        kinetic = "uniform_kinetic" if system == "poisson" else "poisson_kinetic"
        krow = at[at["system"] == kinetic].iloc[0]
        rob = robust[(robust["system"] == system)
                     & (robust["radius"] == smallest)]["robust"].all()
        lines.append(
            f"- **{KICKED[system].capitalize()}: the premise {_limit_word(row['limit'])} "
            f"as r → 0**; the kicked / two-disk FTLE ratio tends to {row['limit']:g} "
            f"(theory: {SLOPES[system]} factor{'s' if SLOPES[system] > 1 else ''} 1/r per "
            f"kick against {SLOPES['two_particle']} per collision); at r = {smallest:g} "
            f"measured {_ci(row, 'ratio', 'ratio_ci_low', 'ratio_ci_high')} "
            f"(against 1: {row['ratio_verdict']}), theory {row['predicted_ratio']:.3f}; "
            f"caveat: the limit is approached like 1/ln(1/r); kinetic-rate kicks "
            f"{_ci(krow, 'ratio', 'ratio_ci_low', 'ratio_ci_high')}; "
            + ("robust over the controls." if rob else
               "not robust over the controls (small_r_findings.csv)."))
    small = compare[compare["radius"] <= 1e-3]
    within = small["verdict"].str.startswith("within")
    outside = small[~within].assign(gap=lambda f: (f["measured_over_predicted"] - 1).abs())
    outside = outside.sort_values("gap", ascending=False)
    where = "; ".join(f"{x['rule']} {x['system']} r = {x['radius']:g}: "
                      f"{_ci(x, 'measured_over_predicted', 'ci_low', 'ci_high')} "
                      f"{x['verdict']}" for _, x in outside.head(3).iterrows())
    large = compare[compare["radius"] > 1e-3]
    worst = large.loc[(large["measured_over_predicted"] - 1).abs().idxmax()]
    lines.append(
        f"- **Theory against simulation, λ/Γ at r ≤ 1e-3**: within {_pct(TOL)} in "
        f"{int(within.sum())} of {len(small)} cells (5 systems, 2 rules, 3 radii)"
        + (f"; outside, farthest first: {where}" if len(outside) else "")
        + "; caveat: it neglects terms of relative order r, and at larger radii it fails "
        f"by up to {_ci(worst, 'measured_over_predicted', 'ci_low', 'ci_high')} "
        f"({worst['rule']}, {_name(worst['system'])}, r = {worst['radius']:g}).")
    lines.append(
        "- **What carries the answer**: the theory. The limits 1/2 and 1 are ratios of its "
        "exact slopes, which no finite sweep can show; the simulation checks its "
        "constants, at the radii above.")
    return lines


def body(meas, theory, compare, ratios, robust, cost, *, n_ics, collisions) -> list[str]:
    """The sections after the answers."""
    lines = ["How to read it: intervals are 95 % bootstrap intervals over ICs (the "
             "theory's, Monte Carlo); a ratio is read by `ratio_verdict` against the FTLE's "
             f"±{_pct(TOL)} band around 1 (`margin_of(\"ftle\")`), an equivalence test "
             "([definitions](../definitions.md)). The derivation is in "
             "[docs/small_r.md](../small_r.md).", ""]
    lines += ["## 1. The stretching per perturbation, simulation and theory", "",
              f"Tangent-space FTLE of {n_ics} invariant-measure ICs per radius and rule, each "
              f"run over {collisions} / Γ(r) time units (≈ {collisions} collisions or kicks "
              "per IC; measured counts in `small_r_measured.csv`); λ/Γ = mean λ over "
              "ICs / pooled perturbation rate. Theory: "
              "`kicktimes.diagnostics.low_density.stretching_theory`, λ/Γ = b ln(1/r) + a "
              "with b = 2 for collisions and scattering kicks, 1 for uniform kicks, and a "
              "from a Monte Carlo of the product of the rank-one maps (not fitted). Cells: "
              "measured / theory (`small_r_against_theory.csv`).", ""]
    systems = ["two_particle", *KICKED]
    for rule in ("mirror", "elastic"):
        c = compare[compare["rule"] == rule]
        if c.empty:
            continue
        lines += [f"**{rule} rule**", "",
                  "| r | " + " | ".join(_name(s) for s in systems) + " |",
                  "|---|" + "---|" * len(systems)]
        for r in sorted(c["radius"].unique()):
            cells = []
            for s in systems:
                row = c[(c["radius"] == r) & (c["system"] == s)].iloc[0]
                cells.append(f"{row['measured']:.3g} / {row['predicted']:.3g}: "
                             f"{_ci(row, 'measured_over_predicted', 'ci_low', 'ci_high')}")
            lines.append(f"| {r:g} | " + " | ".join(cells) + " |")
        lines.append("")
    two = theory[theory["system"] == "two_particle"]
    lines += ["Theory's constants a (at the smallest radius; `small_r_theory.csv`): "
              + _intercepts(theory, systems) + ". The chains' collision rate over the "
              "kinetic rate Γ(r), a check of their stationary measure: "
              f"{two['rate_over_kinetic'].min():.3f}–{two['rate_over_kinetic'].max():.3f}.",
              ""]
    lines += ["## 2. The kicked / two-disk FTLE ratio against r", "",
              "Measured ratio with its verdict against 1 (paired bootstrap), and in "
              "parentheses the theory's ratio; the quotient measured / theory and its "
              "verdict are in `small_r_ratios.csv`.", ""]
    for rule in ("mirror", "elastic"):
        rr = ratios[ratios["rule"] == rule]
        if rr.empty:
            continue
        lines += [f"**{rule} rule**", "", "| r | " + " | ".join(KICKED.values()) + " |",
                  "|---|" + "---|" * len(KICKED)]
        for r in sorted(rr["radius"].unique()):
            cells = []
            for s in KICKED:
                row = rr[(rr["radius"] == r) & (rr["system"] == s)].iloc[0]
                cells.append(f"{_ci(row, 'ratio', 'ratio_ci_low', 'ratio_ci_high')}, "
                             f"{row['ratio_verdict']} ({row['predicted_ratio']:.3f})")
            lines.append(f"| {r:g} | " + " | ".join(cells) + " |")
        lines.append("")
    q = ratios["quotient_verdict"].str.startswith("within")
    lines += [f"Measured / theory ratio within {_pct(TOL)}: {int(q.sum())} of {len(ratios)} "
              "cells. The limits (dashed in the figure) are 1/2 for uniform kicks and 1 for "
              "scattering kicks, under both rules and both kick rates.", "",
              "![small r](small_r.png)", "",
              "**Left:** λ/Γ against ln(1/r), simulation (95 % intervals) and theory (lines). "
              "**Right:** the kicked / two-disk FTLE ratio, the theory's ratio (lines), its "
              "limit r → 0 (dashed) and the ±5 % band.", ""]
    lines += ["## 3. Controls", "",
              "The ratio under the other collision rule, the paired median of the per-IC "
              "ratios, and with the sticky runs (two-disk rate above 5 Γ) left out "
              "(`small_r_findings.csv`; robust = every control gives the primary's verdict "
              "at the margin, in the same direction). Paper vs uniform-time sampling does "
              "not apply: the tangent FTLE does not sample the flow. Sticky runs: "
              + _sticky_text(robust) + ".", ""]
    for system in KICKED:
        lines.append(f"- {KICKED[system]}: {_robust_text(robust[robust['system'] == system])}.")
    lines += ["", "## 4. Cost", "",
              "CPU seconds of the sweep per radius (`small_r_cost.csv`; all five systems, "
              "one IC; the store's own timings):", "",
              "| rule | " + " | ".join(f"r = {r:g}" for r in sorted(cost["radius"].unique()))
              + " |", "|---|" + "---|" * cost["radius"].nunique()]
    for rule in ("mirror", "elastic"):
        c = cost[cost["rule"] == rule].sort_values("radius")
        if not c.empty:
            lines.append(f"| {rule} | " + " | ".join(f"{x:.2g} s" for x in c["seconds_per_ic"])
                         + " |")
    lines += ["", "The per-event cost and the ratio of radii are benchmarked in "
              "`benchmarks/bench_small_r.py` (docs/benchmarks.md).", ""]
    return lines

