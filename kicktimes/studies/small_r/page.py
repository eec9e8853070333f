"""The Markdown of ``small_r.md``: the answers first, then the tables behind them."""

from __future__ import annotations

import math

import numpy as np

from kicktimes._results import format_interval
from kicktimes.render.provenance import Source
from kicktimes.stats import margin_of
from kicktimes.studies.small_r.sweep import seconds_per_ic
from kicktimes.studies.small_r.tables import (
    KICKED,
    against_theory,
    findings,
    measured,
    rate_check,
    ratio_table,
    slopes,
    theory_table,
)

__all__ = ["SOURCES", "answers", "body"]

SOURCES = (
    Source("small_r_measured.csv", "stretch, ci_low, ci_high, ratio, ratio_ci_low, "
           "ratio_ci_high, perturbations_per_ic", measured),
    Source("small_r_theory.csv", "stretch, se, ci_low, ci_high, slope, intercept, "
           "rate_over_kinetic", theory_table),
    Source("small_r_against_theory.csv", "measured, predicted, difference, "
           "difference_ci_low, difference_ci_high, measured_over_predicted, ci_low, "
           "ci_high, verdict", against_theory),
    Source("small_r_slopes.csv", "slope, ci_low, ci_high, theory_slope", slopes),
    Source("small_r_ratios.csv", "ratio, ratio_ci_low, ratio_ci_high, predicted_ratio, "
           "measured_over_predicted, quotient_ci_low, quotient_ci_high, quotient_verdict, "
           "limit", ratio_table),
    Source("small_r_rate_check.csv", "count_over_kinetic, ci_low, ci_high, per_ic_min, "
           "per_ic_max", rate_check),
    Source("small_r_seed_replicate.csv", "difference, difference_ci_low, difference_ci_high, "
           "count_over_kinetic, count_ci_low, count_ci_high", against_theory),
    Source("small_r_findings.csv", "estimate, ci_low, ci_high, verdict, verdict_at_margin, "
           "robust", findings),
    Source("small_r_cost.csv", "seconds_per_ic, collisions_per_ic", seconds_per_ic),
)

TOL = margin_of("ftle")
MAIN = ("two_particle", "poisson", "poisson_scatter")
#: the radius the theory's asymptotic form is evaluated at, to show how slowly the limit is
#: approached (the theory is that form; its constants a are those of the smallest radius)
FAR = 1e-10


def _pct(x):
    return f"{100 * x:g} %"


def _ci(row, est, lo, hi, digits=3):
    return format_interval(row[est], row[lo], row[hi], edges=(1 - TOL, 1.0, 1 + TOL),
                           digits=digits)


def _name(system):
    return "two disks" if system == "two_particle" else KICKED[system]


def _nats(row, est="difference", lo="difference_ci_low", hi="difference_ci_high"):
    return f"{row[est]:+.3f} [{row[lo]:+.3f}, {row[hi]:+.3f}]"


def _far_ratio(theory, rule, system):
    """The theory's kicked / two-disk ratio at r = `FAR` from its asymptotic form."""
    low = theory[(theory["rule"] == rule) & (theory["radius"] == theory["radius"].min())]
    low = low.set_index("system")
    x = math.log(1 / FAR)
    k, two = low.loc[system], low.loc["two_particle"]
    return (k["slope"] * x + k["intercept"]) / (two["slope"] * x + two["intercept"])


def _gap(row, key="ratio"):
    """``2.8 % [2.7, 2.9]``: 1 - the ratio, as a percentage with its interval."""
    lo, hi = 1 - row[f"{key}_ci_high"], 1 - row[f"{key}_ci_low"]
    return f"{100 * (1 - row[key]):.1f} % [{100 * lo:.1f}, {100 * hi:.1f}]"


def _span(values, slope, b):
    """``"1.998–2.002"``: the range of ``values`` over the systems of theory slope ``b``."""
    picked = [v for k, v in values.items() if slope.loc[k, "theory_slope"] == b]
    return f"{min(picked):.3f}–{max(picked):.3f}"


def _robust_summary(robust):
    """Per kicked system of the page (`MAIN`): the radii robust at each verdict, and those
    not robust."""
    parts = []
    for system in MAIN[1:]:
        g = robust[(robust["system"] == system) & (robust["control"] == "primary")]
        by = {}
        for _, x in g.iterrows():
            key = x["verdict_at_margin"] if x["robust"] else "not robust"
            by.setdefault(key, []).append(f"{x['radius']:g}")
        parts.append(f"{KICKED[system]}: " + ", ".join(
            f"{k} at r = {'/'.join(v)}" for k, v in by.items()))
    return "; ".join(parts)


def answers(ratios, compare, robust, slope, theory, smallest, replicate) -> list[str]:
    """At most five one-line answers, each with its number, interval and caveat."""
    at = ratios[ratios["radius"] == smallest].set_index(["rule", "system"])
    uni_m, uni_e = at.loc[("mirror", "poisson")], at.loc[("elastic", "poisson")]
    sca_m, sca_e = at.loc[("mirror", "poisson_scatter")], at.loc[("elastic", "poisson_scatter")]
    rep = replicate.set_index(["rule", "system"])
    rep_scatter = rep.loc[("elastic", "poisson_scatter")]
    at_rep = ratios[(ratios["radius"] == rep_scatter["radius"]) & (ratios["rule"] == "elastic")
                    & (ratios["system"] == "poisson_scatter")].iloc[0]
    lines = [
        f"- **Uniform kicks: by the theory, the premise fails as r → 0.** The kicked / "
        f"two-disk FTLE ratio tends to {uni_m['limit']:g} (a uniform kick stretches by a "
        f"factor ∝ 1/r, a collision by ∝ 1/r²); at r = {smallest:g} it is "
        f"{_ci(uni_m, 'ratio', 'ratio_ci_low', 'ratio_ci_high', 4)} (mirror rule; theory "
        f"{uni_m['predicted_ratio']:.4f}, measured / theory "
        f"{_ci(uni_m, 'measured_over_predicted', 'quotient_ci_low', 'quotient_ci_high', 5)}) "
        f"and {_ci(uni_e, 'ratio', 'ratio_ci_low', 'ratio_ci_high')} (elastic; theory "
        f"{uni_e['predicted_ratio']:.3f}); caveat: the approach is like 1/ln(1/r), the "
        f"theory's ratio is still {_far_ratio(theory, 'mirror', 'poisson'):.2f} at "
        f"r = {FAR:g} (mirror).",
        f"- **Scattering kicks: by the theory, the premise holds as r → 0.** The ratio tends "
        f"to {sca_m['limit']:g}; at r = {smallest:g} it is below 1 by {_gap(sca_m)} (mirror; "
        f"theory {100 * (1 - sca_m['predicted_ratio']):.1f} %, measured / theory "
        f"{_ci(sca_m, 'measured_over_predicted', 'quotient_ci_low', 'quotient_ci_high', 5)}) "
        f"and {_gap(sca_e)} (elastic; theory {100 * (1 - sca_e['predicted_ratio']):.1f} %); "
        f"caveat: the gap closes like 1/ln(1/r) (theory at r = {FAR:g}: "
        f"{100 * (1 - _far_ratio(theory, 'mirror', 'poisson_scatter')):.1f} % mirror, "
        f"{100 * (1 - _far_ratio(theory, 'elastic', 'poisson_scatter')):.1f} % elastic); "
        f"the elastic ratio moves with the ICs: at r = {rep_scatter['radius']:g} "
        f"{_ci(at_rep, 'ratio', 'ratio_ci_low', 'ratio_ci_high')}, its seed replicate "
        f"{_ci(rep_scatter, 'ratio', 'ratio_ci_low', 'ratio_ci_high')}, theory "
        f"{at_rep['predicted_ratio']:.3f}.",
    ]
    sl = slope.set_index(["rule", "system"])
    window = theory[(theory["radius"] >= slope["r_min"].min())
                    & (theory["radius"] <= slope["r_max"].max())]
    th_slope = {k: np.polyfit(np.log(1 / g["radius"]), g["stretch"], 1)[0]
                for k, g in window.groupby(["rule", "system"])}
    off = max(abs(sl.loc[k, "slope"] / th_slope[k] - 1) for k in th_slope)
    coll = sl[sl["theory_slope"] == 2]
    kick = sl[sl["theory_slope"] == 1]
    lines.append(
        f"- **The slopes that set the limits, measured**: over r = {slope['r_min'].min():g}–"
        f"{slope['r_max'].max():g}, λ/Γ rises by {coll['slope'].min():.3f}–"
        f"{coll['slope'].max():.3f} per unit ln(1/r) for collisions and scattering kicks and "
        f"{kick['slope'].min():.3f}–{kick['slope'].max():.3f} for uniform kicks, against the "
        f"theory's 2 and 1 (its own over the same radii {_span(th_slope, sl, 2)} and "
        f"{_span(th_slope, sl, 1)}; `small_r_slopes.csv`); caveat: they differ from the "
        f"theory's by up to {100 * off:.1f} %, several intervals exclude it (the finite-r gaps "
        "shrink across the window), so the limits 1/2 and 1 are the theory's, not measured.")
    small = compare[(compare["radius"] <= 1e-3) & compare["system"].isin(MAIN)]
    worst = small.loc[small["difference"].abs().idxmax()]
    within = small["verdict"].str.startswith("within")
    excl = (small["difference_ci_low"] > 0) | (small["difference_ci_high"] < 0)
    large = compare[(compare["radius"] > 1e-3) & compare["system"].isin(MAIN)]
    far = large.loc[large["difference"].abs().idxmax()]
    lines.append(
        f"- **Theory against simulation**: at r ≤ 1e-3 simulation − theory lies within "
        f"{small['difference'].min():+.2f} to {small['difference'].max():+.2f} nats per "
        f"perturbation, {int(excl.sum())} of {len(small)} cells excluding 0 "
        f"({int(within.sum())} within ±{_pct(TOL)}, a margin of 0.5–0.8 nats here); "
        f"largest {_nats(worst)} ({worst['rule']}, {_name(worst['system'])}, "
        f"r = {worst['radius']:g}{_replicated(worst, replicate)}); caveat: the gap does not "
        "vanish like r, and at "
        f"r = {far['radius']:g} it reaches {_nats(far)} ({far['rule']}, {_name(far['system'])}).")
    lines.append(
        f"- **Controls** (verdict against 1 at ±{_pct(TOL)}, robust = every control agrees): "
        f"{_robust_summary(robust)}; over the collision rule and the paired median at every "
        "radius, and at r = 1e-3 also a seed replicate, the paper's ICs and a ten times "
        "shorter horizon; caveat: no run was sticky, so that control tests nothing here.")
    return lines


def _difference_table(compare, rule):
    c = compare[compare["rule"] == rule]
    lines = [f"**{rule} rule**, simulation − theory (nats per perturbation):", "",
             "| r | " + " | ".join(_name(s) for s in MAIN) + " |", "|---|---|---|---|"]
    for r in sorted(c["radius"].unique()):
        cells = [_nats(c[(c["radius"] == r) & (c["system"] == s)].iloc[0]) for s in MAIN]
        lines.append(f"| {r:g} | " + " | ".join(cells) + " |")
    return lines + [""]


def _ratio_rows(ratios, rule):
    rr = ratios[ratios["rule"] == rule]
    lines = [f"**{rule} rule**, measured (theory):", "",
             "| r | " + " | ".join(KICKED[s] for s in MAIN[1:]) + " |", "|---|---|---|"]
    for r in sorted(rr["radius"].unique()):
        cells = []
        for s in MAIN[1:]:
            row = rr[(rr["radius"] == r) & (rr["system"] == s)].iloc[0]
            cells.append(f"{_ci(row, 'ratio', 'ratio_ci_low', 'ratio_ci_high')} "
                         f"({row['predicted_ratio']:.3f})")
        lines.append(f"| {r:g} | " + " | ".join(cells) + " |")
    return lines + [""]


def _replicated(row, replicate):
    """``"; its seed replicate -0.042 [...]"`` where the seed replicate has the cell."""
    hit = replicate[(replicate["rule"] == row["rule"]) & (replicate["system"] == row["system"])
                    & (replicate["radius"] == row["radius"])]
    return f"; its seed replicate {_nats(hit.iloc[0])}" if len(hit) else ""


def _replicate_text(replicate):
    """The seed replicate's two-disk gap to the theory and collision count, per rule."""
    two = replicate[replicate["system"] == "two_particle"]
    return "; ".join(
        f"{x['rule']}: simulation − theory {_nats(x)} nats, collisions over Γ(r)T "
        f"{_ci(x, 'count_over_kinetic', 'count_ci_low', 'count_ci_high')}"
        for _, x in two.iterrows())


def body(meas, theory, compare, ratios, robust, rates, replicate, cost, *, n_ics,
         collisions) -> list[str]:
    """The sections after the answers."""
    lines = ["How to read it: intervals are 95 % percentile-bootstrap intervals over ICs "
             "(the theory's: its Monte Carlo error); a ratio is read by `ratio_verdict` "
             f"against the FTLE's ±{_pct(TOL)} band around 1 (`margin_of(\"ftle\")`), an "
             "equivalence test ([definitions](../definitions.md)). The derivation: "
             "[docs/small_r.md](../small_r.md).", ""]
    two = theory[theory["system"] == "two_particle"]
    lines += ["## 1. The stretching per perturbation: simulation and theory", "",
              f"Tangent-space FTLE of {n_ics} invariant-measure ICs per radius and rule, each "
              f"run for {collisions} / Γ(r) time units (about {collisions} collisions or "
              "kicks; the counts per IC in `small_r_measured.csv`), five systems: the two "
              "disks, and the disk kicked by uniform new directions or by scattering off "
              "a virtual partner, each at the IC's own two-disk rate or at the kinetic rate "
              "of its own orbit. λ/Γ = mean λ over ICs / pooled perturbation rate. Theory: "
              "`kicktimes.diagnostics.low_density.stretching_theory`, λ/Γ = b ln(1/r) + a, "
              "b = 2 for collisions and scattering kicks and 1 for uniform kicks, a by Monte "
              "Carlo of the rank-one maps, nothing fitted. The radii share the ICs' seed, so "
              "their errors are correlated (the seed replicate is in §3).", ""]
    for rule in ("mirror", "elastic"):
        lines += _difference_table(compare, rule)
    kin = compare[~compare["system"].isin(MAIN) & (compare["radius"] <= 1e-3)]
    lines += [f"The kinetic-rate kicks (not shown): simulation − theory "
              f"{kin['difference'].min():+.2f} to {kin['difference'].max():+.2f} nats at "
              "r ≤ 1e-3 and their ratios as the constant-rate kicks' "
              "(`small_r_against_theory.csv`, `small_r_ratios.csv`). The theory's constants "
              "a and the chains' collision rate over the kinetic rate Γ(r), "
              f"{two['rate_over_kinetic'].min():.3f}–{two['rate_over_kinetic'].max():.3f}, "
              "are in `small_r_theory.csv`. The simulations' own two-disk collisions over "
              "Γ(r)T, 1 exactly for invariant ICs (`small_r_rate_check.csv`): "
              + "; ".join(f"{u} {_ci(g.iloc[0], 'count_over_kinetic', 'ci_low', 'ci_high')} "
                          f"at r = {g.iloc[0]['radius']:g} (per IC "
                          f"{g.iloc[0]['per_ic_min']:.2f}–{g.iloc[0]['per_ic_max']:.2f})"
                          for u, g in rates[rates["radius"] == rates["radius"].min()]
                          .groupby("rule")) + ". The seed replicate at r = "
              f"{replicate['radius'].iloc[0]:g} (other ICs; `small_r_seed_replicate.csv`), "
              "two disks: " + _replicate_text(replicate) + ".", ""]
    lines += ["## 2. The kicked / two-disk FTLE ratio against r", "",
              "Paired bootstrap over ICs; in parentheses the theory's ratio "
              "(`small_r_ratios.csv`, with measured / theory and its verdict).", ""]
    for rule in ("mirror", "elastic"):
        lines += _ratio_rows(ratios, rule)
    q = ratios["quotient_verdict"].str.startswith("within")
    lines += [f"Measured / theory ratio within ±{_pct(TOL)}: {int(q.sum())} of {len(ratios)} "
              "cells, all those outside at r ≥ 0.01. The limits r → 0 are 1/2 for uniform "
              "and 1 for scattering kicks, under both rules and both kick rates.", "",
              "![small r](small_r.png)", "",
              "**Left:** λ/Γ against ln(1/r), simulation (95 % intervals) and theory (lines). "
              "**Middle:** simulation − theory in nats, with the theory's Monte Carlo error "
              "in the interval. **Right:** the kicked / two-disk FTLE ratio, the theory's "
              "ratio (lines), each kick law's limit r → 0 marked at the right edge, the ±5 % "
              "band shaded. The kinetic-rate kicks coincide with the constant-rate ones and "
              "are left out.", ""]
    lines += ["## 3. Controls", "",
              "Every kicked / two-disk ratio under the other collision rule and the paired "
              "median of the per-IC ratios at every radius, and at r = 1e-3 under a seed "
              "replicate, the paper's ICs (drawn at r) and a horizon of a tenth "
              "(`small_r_findings.csv`; robust: every control's verdict at the margin is the "
              "primary's, in the same direction). No run was sticky (rate above 5 Γ), so the "
              "sticky-run control has no rows. Paper vs uniform-time sampling does not "
              "apply: the tangent FTLE does not sample the flow.", ""]
    for system in MAIN[1:]:
        g = robust[robust["system"] == system]
        at = g[g["radius"] == g["radius"][g["control"] == "seed"].min()]
        cells = "; ".join(f"{x['control']} {_ci(x, 'estimate', 'ci_low', 'ci_high')}"
                          for _, x in at.iterrows())
        lines.append(f"- {KICKED[system]} at r = {at['radius'].iloc[0]:g}: {cells}.")
    lines += ["", "## 4. Cost", "",
              "CPU seconds per IC (all five systems; the stores' own task timings, "
              "`small_r_cost.csv`; the sweep's wall time in [benchmarks](../benchmarks.md)):",
              "", "| rule | " + " | ".join(f"r = {r:g}" for r in sorted(cost["radius"].unique()))
              + " |", "|---|" + "---|" * cost["radius"].nunique()]
    for rule in ("mirror", "elastic"):
        c = cost[cost["rule"] == rule].sort_values("radius")
        if not c.empty:
            lines.append(f"| {rule} | " + " | ".join(f"{x:.2g}" for x in c["seconds_per_ic"])
                         + " |")
    return lines + [""]

