"""The science page's sections: Markdown lines from the tables, every number from a row.

Every comparative word comes from a verdict of :mod:`kicktimes.stats` (`ratio_verdict`)
or from `kicktimes.render.pages.trend_verdict`, never typed.
"""

from __future__ import annotations

import math

from kicktimes.render.pages import ratio_text
from kicktimes.render.provenance import Source
from kicktimes.stats import format_interval
from kicktimes.studies.science.decorrelation import (
    closest_kick_law,
    decorrelation,
    prediction_against_measurement,
)
from kicktimes.studies.science.rates import STICKY_FACTOR, rate_relaxation, sticky_orbits
from kicktimes.studies.science.stretching import KICKED, stretching
from kicktimes.studies.science.twins import twin_table

__all__ = ["SOURCES", "decorrelation_lines", "store_lines", "stretching_lines", "twin_lines"]

#: the closing table of ``science.md``: every CSV the study writes beside it (the same
#: twelve at every scale), the columns the page quotes and the function that computes them
SOURCES = (
    Source("science_stretching.csv", "stretch_per_perturbation, ci_low, ci_high, ratio, "
           "ratio_ci_low, ratio_ci_high, verdict", stretching),
    Source("science_stretching_fits.csv", "intercept, slope, intercept_ci_low, "
           "intercept_ci_high, slope_ci_low, slope_ci_high, local_slope_min, "
           "local_slope_max", stretching),
    Source("science_stretching_trend.csv", "quantity, slope_per_ln_inv_r, ci_low, ci_high, "
           "verdict", stretching),
    Source("science_independent_twins.csv", "lam, ci_low, ci_high, per_kick, "
           "predicted_per_kick, over_predicted, over_predicted_ci_low, "
           "over_predicted_ci_high, two_disk_per_collision, ratio, ratio_ci_low, "
           "ratio_ci_high", twin_table),
    Source("science_decorrelation.csv", "perturbation, correlation, ci_low, ci_high, n_pairs",
           decorrelation),
    Source("science_decorrelation_by_angle.csv", "all", decorrelation),
    Source("science_decorrelation_prediction.csv", "predicted, predicted_ci_low, "
           "predicted_ci_high, measured, measured_ci_low, measured_ci_high, "
           "measured_over_predicted, quotient_ci_low, quotient_ci_high, quotient_verdict",
           prediction_against_measurement),
    Source("science_closest.csv", "ratio, ci_low, ci_high, verdict, closest, disjoint_under",
           closest_kick_law),
    Source("science_rate_count.csv", "count_over_kinetic, ci_low, ci_high, verdict",
           rate_relaxation),
    Source("science_rate_windows.csv", "rate_over_kinetic, ci_low, ci_high, verdict",
           rate_relaxation),
    Source("science_rate_relaxation.csv", "all", rate_relaxation),
    Source("science_sticky.csv", "n_sticky, n_runs, share_runs, n_ics_sticky, "
           "median_interval_sticky, median_max_abs_L_sticky, median_max_abs_L_all, "
           "share_all_ics_below_sticky_max", sticky_orbits),
)


def _fmt(x, lo, hi, digits=3):
    return f"{x:.{digits}g} [{lo:.{digits}g}, {hi:.{digits}g}]"


def _iv(x, lo, hi, edges=()):
    """An interval printed so that its rounding keeps its side of each of ``edges``."""
    return format_interval(x, lo, hi, edges=edges)


def stretching_lines(exp, per_radius, fits, trend):
    """Section 1: the stretching per perturbation of the FTLE sweep ``exp``."""
    two = per_radius[per_radius["system"] == "two_particle"].set_index("radius")
    f = fits.set_index("system")
    lo_r, hi_r = min(exp.radii), max(exp.radii)
    lines = [
        "## 1. Stretching per perturbation, per measured radius", "",
        f"FTLE sweep `{exp.name}`: {exp.n_ics} paper ICs at {len(exp.radii)} radii from "
        f"{lo_r:g} to {hi_r:g}, {exp.n_steps} collision-truncated steps of τ = {exp.tau:g}. "
        "Stretching per perturbation s = mean λ over ICs / pooled perturbation rate (nats); "
        "intervals: 95 % bootstrap over ICs, the same resampled ICs for every system and "
        f"radius (`science_stretching.csv`). Two-disk, per disk-disk collision: "
        + "; ".join(f"r = {r:g}: {_iv(g.stretch_per_perturbation, g.ci_low, g.ci_high)}"
                    for r, g in two.iloc[::-1].iterrows()) + ".", "",
        "The least-squares line s = a + b ln(1/r) over the measured range ln(1/r) = "
        f"{f.loc['two_particle', 'ln_inv_r_min']:.2f}–{f.loc['two_particle', 'ln_inv_r_max']:.2f}"
        " (`science_stretching_fits.csv`) is a summary of that range, not a law: its local "
        "slopes between adjacent radii run from "
        f"{f.loc['two_particle', 'local_slope_min']:.2f} to "
        f"{f.loc['two_particle', 'local_slope_max']:.2f} for the two disks, and the stretching "
        "at a radius is a + b ln(1/r), never b ln(1/r) alone. It is not extrapolated.", "",
        "| system | intercept a | slope b | local slopes |", "|---|---|---|---|"]
    for s, g in f.iterrows():
        a = _iv(g.intercept, g.intercept_ci_low, g.intercept_ci_high)
        b = _iv(g.slope, g.slope_ci_low, g.slope_ci_high)
        lines.append(f"| {s} | {a} | {b} | {g.local_slope_min:.2f} to "
                     f"{g.local_slope_max:.2f} |")
    lines += ["", "Since the kicks come at the two-disk collision rate, the FTLE ratio "
              "λ_kicked / λ_two equals s_kicked / s_two. Per radius (verdicts by "
              "`ratio_verdict`, 10 % margin):", "",
              "| r | " + " | ".join(f"{KICKED[s]} / two-disk" for s in KICKED) + " |",
              "|---|" + "---|" * len(KICKED)]
    kicked = per_radius[per_radius["system"] != "two_particle"]
    for r in sorted(kicked["radius"].unique(), reverse=True):
        cells = []
        for s in KICKED:
            g = kicked[(kicked["system"] == s) & (kicked["radius"] == r)].iloc[0]
            cells.append(ratio_text(g.ratio, g.ratio_ci_low, g.ratio_ci_high))
        lines.append(f"| {r:g} | " + " | ".join(cells) + " |")
    lines.append("")
    t = trend.set_index(["system", "quantity"])
    for s, name in KICKED.items():
        g = kicked[kicked["system"] == s].set_index("radius")
        verdicts = g["verdict"].value_counts()
        tr, tc = t.loc[(s, "ratio")], t.loc[(s, "abs_log_ratio")]
        closer = {"falls": "closer to 1 at smaller r", "rises": "further from 1 at smaller r",
                  "no trend detected": "no trend of the distance from 1 detected"}[tc.verdict]
        lines.append(
            f"- {name}: the ratio is {g.loc[hi_r, 'ratio']:.3f} at r = {hi_r:g} and "
            f"{g.loc[lo_r, 'ratio']:.3f} at r = {lo_r:g}; its least-squares slope against "
            f"ln(1/r) is {_iv(tr.slope_per_ln_inv_r, tr.ci_low, tr.ci_high, (0.0,))} per "
            f"unit ln(1/r) ({tr.verdict} as r decreases), and that of |ln ratio| is "
            f"{_iv(tc.slope_per_ln_inv_r, tc.ci_low, tc.ci_high, (0.0,))} ({closer}). "
            f"Verdicts over the {len(g)} radii: "
            + ", ".join(f"{v} at {k}" for v, k in zip(verdicts.to_numpy(), verdicts.index,
                                                       strict=True)) + ".")
    lines += ["", "The paper's expectation that the kicked disk agrees better for smaller disks. "
              "Agreement is decided per radius by the equivalence verdict; a direction is "
              "claimed only when the two trend measures above agree (both slope intervals "
              "exclude 0, the ratio moving towards 1 and |ln ratio| falling, or both away); "
              "where they disagree no direction is claimed:", ""]
    for s, name in KICKED.items():
        g = kicked[kicked["system"] == s].set_index("radius")
        tr, tc = t.loc[(s, "ratio")], t.loc[(s, "abs_log_ratio")]
        side = 1 if bool((g["ratio"] < 1).all()) else -1 if bool((g["ratio"] > 1).all()) else 0
        toward = {1: "rises", -1: "falls"}.get(side)
        away = {1: "falls", -1: "rises"}.get(side)
        agree = ((tr.verdict == toward and tc.verdict == "falls")
                 or (tr.verdict == away and tc.verdict == "rises")
                 or (tr.verdict == tc.verdict == "no trend detected"))
        if not agree:
            trend_txt = (f"the two trend measures disagree (ratio: {tr.verdict}; |ln ratio|: "
                         f"{tc.verdict}), so no direction is claimed")
        elif tc.verdict == "falls":
            trend_txt = (f"the ratio {tr.verdict} from {g.loc[hi_r, 'ratio']:.3f} at "
                         f"r = {hi_r:g} to "
                         f"{g.loc[lo_r, 'ratio']:.3f} at r = {lo_r:g}, towards 1 (both trend "
                         "measures agree)")
        elif tc.verdict == "rises":
            trend_txt = "the ratio moves away from 1 as r decreases (both trend measures agree)"
        else:
            trend_txt = "no trend detected by either measure"
        n_within = int(g["verdict"].str.startswith("within").sum())
        counts = g["verdict"].value_counts()
        lines.append(f"- {name}: {trend_txt}; within 10 % of the two-disk value at {n_within} "
                     f"of {len(g)} radii (" + ", ".join(
                         f"{k} at {v}/{len(g)}" for k, v in counts.items())
                     + f"), down to r = {lo_r:g}; the expectation of agreement "
                     + ("is met at no measured radius." if n_within == 0 else
                        f"is met at {n_within} of {len(g)} radii."))
    lines += ["", f"What happens below r = {lo_r:g} is not measured here. "
              "[scatter.md](scatter.md) gives the same quantity (mean FTLE of the scatter-kicked "
              "disk over the mean two-disk FTLE, ratio of means over ICs) at family A's radii "
              "from another sample: its first 40 paper ICs drawn with seed 1, its own kick "
              "draws and its sticky orbits (FTLE below a quarter of the radius's median) left "
              "out, against the 100 ICs drawn with seed 11 here, all kept; where the two "
              "pages' intervals differ at a shared radius, that is the difference of the "
              "samples, not of the definition.", "",
              "![stretching](science_stretching.png)", "",
              "**Left:** stretching per perturbation against ln(1/r) (top axis: r), 95 % "
              "intervals over ICs. **Right:** the kicked / two-disk ratio per radius with its "
              "interval; grey: the ±10 % band of the equivalence test.", ""]
    return lines


def twin_lines(twins, exp, *, n_ics=8, n_steps=3000):
    """Section 2: the twins with independent kick angles (``n_ics`` ICs, ``n_steps``
    steps of the sweep's tau each)."""
    tau, d0 = exp.tau, exp.d0
    lines = ["## 2. Twins with independent kick angles", "",
             "A twin that draws its own kick angles is thrown O(1) away from the reference at "
             "every kick. A first estimate, O(τ) of position separation renormalised to d0 "
             f"every τ, gives λ ≈ Γ ln(τ/d0) = {math.log(tau / d0):.2f} Γ at the paper's "
             f"τ = {tau:g}, d0 = {d0:g}. Simulated (Benettin on (x, y, vx, vy), {n_ics} paper "
             f"ICs, {n_steps} steps of τ, Poisson kicks at Γ(r); "
             "`science_independent_twins.csv`); the "
             "ratio's interval is the twin's interval over the two-disk stretching's "
             "interval, ends divided crosswise (conservative):", ""]
    for row in twins.itertuples():
        lines.append(
            f"- r = {row.radius:g}: λ = {_fmt(row.lam, row.ci_low, row.ci_high)}, "
            f"{row.per_kick:.2f} nats per kick against the estimate's "
            f"{row.predicted_per_kick:.2f}: measured / predicted "
            + ratio_text(row.over_predicted, row.over_predicted_ci_low,
                         row.over_predicted_ci_high) +
            f"; against {row.two_disk_per_collision:.2f} per collision for the two disks: "
            f"ratio {ratio_text(row.ratio, row.ratio_ci_low, row.ratio_ci_high)}.")
    lines += ["", "The first estimate is a prediction per kick; the verdicts above say whether "
              f"the simulated twins agree with it to 10 % ({n_ics} ICs per radius).", "",
              "Twins that do not share their kicks measure the kick's O(1) randomisation "
              "of the direction, not a stretching; kicktimes' twins share the kicks (common "
              "random numbers).", ""]
    return lines


def decorrelation_lines(dec, compare, closest, *, n_ics=40, t_max=20000.0):
    """Section 3: the decorrelation per single perturbation (``n_ics`` ICs, runs of
    ``t_max``), the prediction beside the measurement, the closest kick law."""
    t_text = f"{t_max:,.0f}".replace(",", " ")
    lines = ["## 3. Decorrelation per single perturbation", "",
             "Correlation of the boundary angle θ at the wall hit before and the wall hit "
             f"after exactly one perturbation ({n_ics} paper ICs, T = {t_text} per run; "
             "kicked runs "
             "at their two-disk run's collision rate; `science_decorrelation.csv`):", ""]
    for (rule, r), g in dec.groupby(["rule", "radius"], sort=False, observed=True):
        lines.append(f"- {rule} rule, r = {r:g}: " + "; ".join(
            f"{row.perturbation} {_fmt(row.correlation, row.ci_low, row.ci_high)} "
            f"({row.n_pairs} pairs)" for row in g.itertuples()) + ".")
    lines += ["", "With as many perturbations per wall hit in both systems, 1 − R₁ scales as "
              "1 − (correlation across one perturbation), which predicts the kicked / "
              "two-disk ratio of 1 − R₁. The prediction beside the ratio measured in the "
              "family store (control primary, `science_decorrelation_prediction.csv`); "
              "measured / predicted has the interval of the two intervals combined on the "
              "log scale, and its verdict says whether the prediction agrees with the "
              "measurement to 10 %:", "",
              "| rule | r | kick | predicted | measured (store) | measured / predicted |",
              "|---|---|---|---|---|---|"]
    for row in compare.itertuples():
        lines.append(
            f"| {row.rule} | {row.radius:g} | {KICKED[row.system]} | "
            f"{format_interval(row.predicted, row.predicted_ci_low, row.predicted_ci_high)} | "
            f"{ratio_text(row.measured, row.measured_ci_low, row.measured_ci_high)} "
            f"(`{row.family}`) | "
            f"{ratio_text(row.measured_over_predicted, row.quotient_ci_low, row.quotient_ci_high)}"
            " |")
    agree = compare["quotient_verdict"].str.startswith("within").sum()
    off = compare["quotient_verdict"].isin(["lower", "higher"]).sum()
    failing = compare[compare["quotient_verdict"].isin(["lower", "higher"])]
    rules = ", ".join(f"{n} under the {rule} rule"
                      for rule, n in failing["rule"].value_counts(sort=False).items())
    lines += ["", f"The one-collision model agrees to 10 % in {agree} of {len(compare)} rows. "
              + (f"It fails: {off} of {len(compare)} rows lie outside its 10 % band (verdict "
                 f"lower or higher) and falsify it ({rules}); the others are inconclusive."
                 if off else "No row falsifies it; the inconclusive rows cannot confirm it."),
              "",
              "Which kick law comes closest to the two-disk value (pooled findings, control "
              "primary; distance from 1: |ln ratio|, its interval the image of the ratio's; "
              "the closest group is the law with the lowest upper distance and every law whose "
              "distance interval reaches below it; `science_closest.csv`):", ""]
    for (family, diag), g in closest.groupby(["family", "diagnostic"], sort=False, observed=True):
        best, rest = g[g["closest"]], g[~g["closest"]]

        def cells(part):
            return ", ".join(f"{s} {format_interval(x, lo, hi)}" for s, x, lo, hi in
                             zip(part["system"], part["ratio"], part["ci_low"], part["ci_high"],
                                 strict=True))

        none_agree = not best["verdict"].str.startswith("within").any()
        if not len(rest):
            lines.append(f"- `{family}`, {diag}: no law is closest (distance intervals "
                         f"overlap): {cells(best)}.")
            continue
        name = (f"{best['system'].iloc[0]} comes closest" if len(best) == 1 else
                "nearer to 1 than the rest (distance intervals separate them); their own "
                "intervals overlap under the primary setting, which does not make them equal")
        if none_agree:
            name += " and none agrees (verdicts: " + ", ".join(
                sorted(set(best["verdict"]))) + ")"
        apart = [(s, d) for s, d in zip(best["system"], best["disjoint_under"], strict=True)
                 if isinstance(d, str) and d]
        differ = "".join(f"; {s}'s interval is disjoint from the best law's under {d}"
                         for s, d in apart)
        lines.append(f"- `{family}`, {diag}: {name}: {cells(best)}{differ}; further from 1: "
                     f"{cells(rest)}.")
    lines += ["", "Binned by θ before: `science_decorrelation_by_angle.csv`.", ""]
    return lines


def store_lines(whole, windows, sticky):
    """Sections 4 and 5: the collision rate over the run and the sticky orbits."""
    lines = ["## 4. The collision rate over the run", "",
             "Ensemble disk-disk collision rate of the paper's ICs over the kinetic rate "
             "Γ(r): per radius over the whole run, count / Γ(r)T with a 95 % bootstrap "
             "interval over ICs and its `ratio_verdict` (`science_rate_count.csv`); in ten "
             "equal windows of the shortest run, averaged over radii, with a 95 % bootstrap "
             "interval over ICs and its `ratio_verdict` (`science_rate_windows.csv`; per "
             "radius: `science_rate_relaxation.csv`):", ""]
    for fam, g in whole.groupby("family", sort=False, observed=True):
        w = windows[windows["family"] == fam].set_index("window")
        counts = g["verdict"].value_counts()
        wv = w["verdict"].value_counts()
        est, lo_w, hi_w = w["rate_over_kinetic"], w["ci_low"], w["ci_high"]
        lines.append(
            f"- `{fam}`: first window {ratio_text(est.iloc[0], lo_w.iloc[0], hi_w.iloc[0])}"
            f", windows 2–{len(w)} {w['rate_over_kinetic'].iloc[1:].min():.3f}–"
            f"{w['rate_over_kinetic'].iloc[1:].max():.3f}, last "
            f"{ratio_text(est.iloc[-1], lo_w.iloc[-1], hi_w.iloc[-1])}"
            "; window verdicts: " + ", ".join(f"{k} at {v} of {len(w)}" for k, v in wv.items())
            + f"; over the whole run {g['count_over_kinetic'].min():.3f}–"
            f"{g['count_over_kinetic'].max():.3f} over the radii, verdicts: " + ", ".join(
                f"{k} at {v} of {len(g)} radii" for k, v in counts.items()) + ".")
    lines += ["", "Whether the rate relaxes to Γ(r) is read from the window verdicts only: a "
              "family whose later windows are not within 10 % of 1 is not said to relax."]
    lines += ["", "## 5. The sticky orbits", "",
              f"A run is sticky when its two-disk collision rate exceeds {STICKY_FACTOR:g} "
              "Γ(r) (`science_sticky.csv`).", ""]
    for row in sticky.itertuples():
        lines.append(
            f"- `{row.family}`: {row.n_sticky} of {row.n_runs} runs "
            f"({100 * row.share_runs:.1f} %), from {row.n_ics_sticky} ICs; they collide every "
            f"{row.median_interval_sticky:.2f} time units (median). The larger initial "
            f"angular momentum |x v_y − y v_x| of the two disks has median "
            f"{row.median_max_abs_L_sticky:.3f} over the sticky ICs against "
            f"{row.median_max_abs_L_all:.3f} over all ICs "
            f"({100 * row.share_all_ics_below_sticky_max:.1f} % of all ICs are as radial as "
            "the least radial sticky one).")
    lines += ["", "No name is given to these orbits: small |L| is not specific to them where a "
              "large share of all ICs is as radial as the least radial sticky one. The "
              "definition here is by the collision rate; [scatter.md](scatter.md) flags a "
              "different set, two-disk orbits whose FTLE is below a quarter of their radius's "
              "median (by the exponent, not the rate).", ""]
    return lines
