"""The science page's sections: Markdown lines from the tables, every number from a row.

Every comparative word comes from a verdict of :mod:`kicktimes.stats` (`ratio_verdict`)
or from `kicktimes.render.pages.trend_verdict`, never typed.
"""

from __future__ import annotations

import math

from kicktimes.render.provenance import Source
from kicktimes.stats import (
    MARGIN,
    equivalence_sample_size,
    format_interval,
    margin_of,
    ratio_reading,
    ratio_verdict,
    ratio_words,
    side_of,
)
from kicktimes.studies.science.decorrelation import (
    closest_kick_law,
    decorrelation,
    prediction_against_measurement,
)
from kicktimes.studies.science.rates import STICKY_FACTOR, rate_relaxation, sticky_orbits
from kicktimes.studies.science.stretching import KICKED, stretching
from kicktimes.studies.science.twins import twin_table

__all__ = ["FIRST_SCREEN_MAX", "SOURCES", "closest_cells", "decorrelation_lines",
           "first_screen", "needed_ics", "reading", "reading_text", "store_lines",
           "stretching_lines", "twin_lines"]

#: the answers a page may open with before its first table
FIRST_SCREEN_MAX = 5
Z95 = 1.959963984540054

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
    Source("science_rate_count_no_sticky.csv", "count_over_kinetic, ci_low, ci_high, verdict",
           rate_relaxation),
    Source("science_rate_windows_no_sticky.csv", "rate_over_kinetic, ci_low, ci_high, verdict",
           rate_relaxation),
    Source("science_sticky.csv", "n_sticky, n_runs, share_runs, n_ics_sticky, "
           "median_interval_sticky, median_max_abs_L_sticky, median_max_abs_L_all, "
           "share_all_ics_below_sticky_max", sticky_orbits),
)


def _fmt(x, lo, hi, digits=3):
    return f"{x:.{digits}g} [{lo:.{digits}g}, {hi:.{digits}g}]"


def _iv(x, lo, hi, edges=()):
    """An interval printed so that its rounding keeps its side of each of ``edges``."""
    return format_interval(x, lo, hi, edges=edges)


#: the margin of the collision rate over the kinetic rate: the counts' margin
#: (`kicktimes.stats.margin_of("counts")`), the README's reading of the same ratio
RATE_MARGIN = margin_of("counts")


def needed_ics(estimate, low, high, n, tolerance=MARGIN, unit="ICs"):
    """What an inconclusive ratio needs: ``"not resolved at this size; needs ≈ N ICs"``.

    N is `kicktimes.stats.equivalence_sample_size` with the standard error of the 95 %
    interval ``[low, high]`` at ``n`` units and, as margin, the distance of the estimate
    from the nearer band edge ``1 ± tolerance`` (the interval around the measured estimate
    must shrink to that distance to fall on one side of the edge).

    Examples
    --------
    >>> needed_ics(0.998, 0.913, 1.15, 100)
    'not resolved at this size; needs ≈ 400 ICs'
    """
    if not (isinstance(n, int) and n >= 1):
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    room = abs(tolerance - abs(float(estimate) - 1.0))
    if room < 1e-9:
        return "not resolved at this size: the estimate lies on the band's edge"
    se = (float(high) - float(low)) / (2 * Z95)
    return (f"not resolved at this size; needs ≈ {equivalence_sample_size(se, n, margin=room)} "
            f"{unit}")


def reading_text(x, lo, hi, tolerance=MARGIN):
    """A ratio's interval and its `ratio_words` (an inconclusive interval that excludes
    1 reads as a departure of unresolved size; one within the margin that
    excludes 1 says on which side).

    >>> reading_text(0.876, 0.815, 0.942)
    '0.876 [0.815, 0.942], below 1, size unresolved'
    >>> reading_text(1.072, 1.046, 1.099)
    '1.072 [1.046, 1.099], within 10 %, above 1'
    """
    return f"{format_interval(x, lo, hi)}, {ratio_words(lo, hi, tolerance=tolerance)}"


def _ratio_cell(x, lo, hi, n, unit="ICs", tolerance=MARGIN):
    """`reading_text`, and for an interval that contains 1 and is inconclusive the size
    that would resolve it (never for one that excludes 1: that is a departure)."""
    text = reading_text(x, lo, hi, tolerance)
    if ratio_reading(lo, hi, tolerance=tolerance) == "inconclusive" and n:
        text += f" ({needed_ics(x, lo, hi, n, tolerance=tolerance, unit=unit)})"
    return text


def _readings(frame, low="ci_low", high="ci_high", tolerance=MARGIN):
    """The `ratio_words` of every row of ``frame``."""
    return frame.apply(lambda x: ratio_words(x[low], x[high], tolerance=tolerance), axis=1)


def _verdict_counts(verdicts):
    counts = verdicts.value_counts()
    return ", ".join(f"{k} at {v}" for k, v in counts.items())


def reading():
    """How the page's verdicts are read, stated once."""
    return ["How to read it: intervals are 95 % bootstrap intervals over ICs unless said "
            "otherwise; a ratio is read by `ratio_verdict` against the 10 % band around 1 "
            f"(the FTLE's against ±{100 * margin_of('ftle'):g} %, `margin_of`) "
            "(an equivalence test, [definitions](../definitions.md)); an inconclusive "
            "interval that excludes 1 reads \"below (above) 1, size unresolved\", "
            "a real departure; one that contains 1 names the ICs that would "
            "resolve it (`equivalence_sample_size` at the measured estimate). A prediction is "
            "quoted beside its measurement; a direction is claimed only where both trend "
            "measures agree. Every per-radius value is in the CSVs linked below.", ""]


def first_screen(per_radius, trend, twins, compare, windows, whole, *, n_ics, n_dec,
                 windows_kept=None):
    """The page's opening: at most :data:`FIRST_SCREEN_MAX` one-line answers, each one
    number with its 95 % interval, where it comes from and its caveat; ``windows_kept``
    (the windows without the sticky runs) adds their last tenth to the rate's caveat."""
    lines = []
    kicked = per_radius[per_radius["system"] != "two_particle"]
    lo_r, hi_r = kicked["radius"].min(), kicked["radius"].max()
    t = trend.set_index(["system", "quantity"])
    for system, name in KICKED.items():
        g = kicked[kicked["system"] == system].set_index("radius")
        row = g.loc[lo_r]
        tr, tc = t.loc[(system, "ratio")], t.loc[(system, "abs_log_ratio")]
        agree = _trend_agrees(g, tr, tc)
        lines.append(
            f"- **{name[0].upper()}{name[1:]}, FTLE / two-disk FTLE**: "
            f"{_verdict_counts(_readings(g, 'ratio_ci_low', 'ratio_ci_high', margin_of('ftle')))}"
            f" of {len(g)} radii ({lo_r:g}–{hi_r:g}); at "
            f"r = {lo_r:g}: "
            f"{reading_text(row.ratio, row.ratio_ci_low, row.ratio_ci_high, margin_of('ftle'))}; "
            "caveat: " + (f"the ratio {tr.verdict} towards 1 as r falls (both trend measures)"
                          if agree and tc.verdict == "falls" else
                          "no direction of the trend is claimed (the two trend measures "
                          f"disagree: {tr.verdict}, {tc.verdict})" if not agree else
                          f"trend: {tr.verdict}") + f"; nothing below r = {lo_r:g}.")
    best = twins.iloc[(twins["over_predicted"].map(lambda v: abs(math.log(v)))).argmin()]
    tv = _readings(twins, "over_predicted_ci_low", "over_predicted_ci_high")
    lines.append(f"- **Twins with their own kick angles**, measured / predicted stretching "
                 f"per kick (Γ ln(τ/d0)): {_verdict_counts(tv)} of {len(twins)} radii; "
                 f"closest to 1: {reading_text(best.over_predicted, best.over_predicted_ci_low, best.over_predicted_ci_high)}"  # noqa: E501
                 f" (r = {best.radius:g}); caveat: {int(n_ics)} ICs per radius.")
    if len(compare):
        lines.append(_decorrelation_answer(compare, n_dec))
    first = windows[windows["window"] == windows["window"].min()]
    last = windows[windows["window"] == windows["window"].max()]
    fv, lv = _readings(first, tolerance=RATE_MARGIN), _readings(last, tolerance=RATE_MARGIN)
    weakest = first.iloc[first["ci_low"].argmin()]
    wv = _readings(whole, tolerance=RATE_MARGIN)
    weak = reading_text(weakest.rate_over_kinetic, weakest.ci_low, weakest.ci_high, RATE_MARGIN)
    lines.append(f"- **Collision rate / kinetic Γ(r), first tenth of the run** (at "
                 f"±{100 * RATE_MARGIN:g} %): {_verdict_counts(fv)} of {len(first)} families; "
                 f"weakest {weak} "
                 f"(`{weakest.family}`); caveat: last tenth {_verdict_counts(lv)} of "
                 f"{len(last)}; whole run per radius: {_verdict_counts(wv)} of {len(whole)}"
                 + _kept_last(windows_kept) + ".")
    if len(lines) > FIRST_SCREEN_MAX:
        raise ValueError(f"first_screen: {len(lines)} answers, at most {FIRST_SCREEN_MAX}")
    return lines + [""]


def _kept_cell(family, whole_kept, windows_kept) -> str:
    """The rate table's cell without the sticky runs: the last window and the whole run's
    range over radii with their readings."""
    w = windows_kept[windows_kept["family"] == family]
    g = whole_kept[whole_kept["family"] == family]
    if w.empty or g.empty:
        return " — |"
    last = w[w["window"] == w["window"].max()].iloc[0]
    return (f" {reading_text(last.rate_over_kinetic, last.ci_low, last.ci_high, RATE_MARGIN)}; "
            f"{g['count_over_kinetic'].min():.3f}–{g['count_over_kinetic'].max():.3f}: "
            f"{_verdict_counts(_readings(g, tolerance=RATE_MARGIN))} of {len(g)} radii |")


def _kept_last(windows_kept) -> str:
    """``"; sticky runs left out, last tenth: 1.00 [0.97, 1.03], within 10 % (`family_a`),
    ..."``: the rate's caveat from the windows without the sticky runs (empty without)."""
    if windows_kept is None or windows_kept.empty:
        return ""
    last = windows_kept[windows_kept["window"] == windows_kept["window"].max()]
    return "; sticky runs left out, last tenth: " + ", ".join(
        f"{reading_text(r.rate_over_kinetic, r.ci_low, r.ci_high, RATE_MARGIN)} "
        f"(`{r.family}`)"
        for r in last.itertuples())


def _decorrelation_answer(compare, n_dec):
    """The one-line answer on the one-collision model: on which side of 1 the quotients
    measured / predicted lie (the model over- or underpredicts), their readings by rule,
    and the quotient closest to 1 (smallest |ln quotient|) over every row."""
    lo, hi = compare["quotient_ci_low"], compare["quotient_ci_high"]
    sides = [side_of(a, b) for a, b in zip(lo, hi, strict=True)]
    reads = _readings(compare, "quotient_ci_low", "quotient_ci_high")
    parts = []
    for side, says in (("below", "overpredicts"), ("above", "underpredicts")):
        mine = [k for k, s in enumerate(sides) if s == side]
        if not mine:
            continue
        by = []
        for verdict in dict.fromkeys(reads.iloc[mine]):
            rows = [k for k in mine if reads.iloc[k] == verdict]
            rules = compare["rule"].iloc[rows].value_counts(sort=False)
            by.append(f"{verdict} in {len(rows)} ("
                      + ", ".join(f"{k} {v}" for k, v in rules.items()) + ")")
        parts.append(f"the model {says} in {len(mine)} of {len(compare)} rows "
                     f"(interval {side} 1): " + "; ".join(by))
    unresolved = sides.count(None)
    if unresolved:
        parts.append(f"{unresolved} of {len(compare)} rows not resolved at this size "
                     "(interval contains 1)")
    distance = compare["measured_over_predicted"].map(lambda v: abs(math.log(v)))
    near, far = compare.iloc[distance.argmin()], compare.iloc[distance.argmax()]

    def cell(row):
        return (reading_text(row.measured_over_predicted, row.quotient_ci_low,
                             row.quotient_ci_high)
                + f" ({row.rule}, r = {row.radius:g}, {KICKED[row.system]})")

    return ("- **One-collision decorrelation model** (predicts the kicked / two-disk "
            "1 − R₁), measurement / prediction: " + "; ".join(parts) + "; closest to 1: "
            + cell(near) + "; farthest: " + cell(far) + f"; caveat: {int(n_dec)} ICs of "
            "direct runs against the family store.")


def _trend_agrees(g, tr, tc):
    """Whether the two trend measures agree (both slopes' intervals tell the same story:
    the ratio moving towards 1 and |ln ratio| falling, or both away, or neither moving)."""
    side = 1 if bool((g["ratio"] < 1).all()) else -1 if bool((g["ratio"] > 1).all()) else 0
    toward = {1: "rises", -1: "falls"}.get(side)
    away = {1: "falls", -1: "rises"}.get(side)
    return ((tr.verdict == toward and tc.verdict == "falls")
            or (tr.verdict == away and tc.verdict == "rises")
            or (tr.verdict == tc.verdict == "no trend detected"))


def stretching_lines(exp, per_radius, fits, trend):
    """Section 1: the stretching per perturbation of the FTLE sweep ``exp``."""
    lo_r, hi_r = min(exp.radii), max(exp.radii)
    lines = [
        "## 1. Stretching per perturbation", "",
        f"FTLE sweep `{exp.name}`: {exp.n_ics} paper ICs at {len(exp.radii)} radii from "
        f"{lo_r:g} to {hi_r:g}, {exp.n_steps} collision-truncated steps of τ = {exp.tau:g}. "
        "Stretching per perturbation s = mean λ over ICs / pooled perturbation rate; the "
        "kicks come at the two-disk collision rate, so λ_kicked / λ_two = s_kicked / s_two "
        "(per radius: `science_stretching.csv`; the line s = a + b ln(1/r) over the measured "
        "range, a summary and not a law, never extrapolated: `science_stretching_fits.csv`).",
        "",
        "| r | " + " | ".join(f"{KICKED[s]} / two-disk" for s in KICKED) + " |",
        "|---|" + "---|" * len(KICKED)]
    kicked = per_radius[per_radius["system"] != "two_particle"]
    for r in sorted(kicked["radius"].unique(), reverse=True):
        cells = []
        for s in KICKED:
            g = kicked[(kicked["system"] == s) & (kicked["radius"] == r)].iloc[0]
            cells.append(_ratio_cell(g.ratio, g.ratio_ci_low, g.ratio_ci_high, exp.n_ics,
                                     tolerance=margin_of("ftle")))
        lines.append(f"| {r:g} | " + " | ".join(cells) + " |")
    lines += ["", "The paper's expectation, agreement that improves for smaller disks "
              "(slopes against ln(1/r): `science_stretching_trend.csv`):", ""]
    t = trend.set_index(["system", "quantity"])
    for s, name in KICKED.items():
        g = kicked[kicked["system"] == s].set_index("radius")
        tr, tc = t.loc[(s, "ratio")], t.loc[(s, "abs_log_ratio")]
        if not _trend_agrees(g, tr, tc):
            trend_txt = (f"the two trend measures disagree (ratio: {tr.verdict}, slope "
                         f"{_iv(tr.slope_per_ln_inv_r, tr.ci_low, tr.ci_high, (0.0,))}; "
                         f"|ln ratio|: {tc.verdict}), so no direction is claimed")
        elif tc.verdict == "falls":
            trend_txt = (f"the ratio {tr.verdict} towards 1 as r decreases, slope "
                         f"{_iv(tr.slope_per_ln_inv_r, tr.ci_low, tr.ci_high, (0.0,))} per "
                         "unit ln(1/r) (both trend measures agree)")
        elif tc.verdict == "rises":
            trend_txt = "the ratio moves away from 1 as r decreases (both trend measures agree)"
        else:
            trend_txt = "no trend detected by either measure"
        n_within = int(g["verdict"].str.startswith("within").sum())
        lines.append(f"- {name}: {trend_txt}; within {100 * margin_of('ftle'):g} % at "
                     f"{n_within} of {len(g)} radii"
                     + ("; the expectation of agreement is met at no measured radius."
                        if n_within == 0 else "."))
    lines += ["", f"What happens below r = {lo_r:g} is not measured here: "
              "[small_r.md](small_r.md) follows the ratio to r = 1e-4 on another design "
              "(invariant-measure ICs drawn at each radius, runs of about 10⁴ collisions, "
              f"where these runs of {exp.n_steps} steps of τ = {exp.tau:g} see few at the "
              "smallest radii), beside the low-density theory of its small-r limit. "
              "[scatter.md](scatter.md) measures the scatter-kick ratio on another sample "
              "(40 ICs, sticky orbits left out); differences at a shared radius are the "
              "samples'.", "",
              "![stretching](science_stretching.png)", "",
              "**Left:** stretching per perturbation against ln(1/r); **right:** the kicked / "
              f"two-disk ratio with the ±{100 * margin_of('ftle'):g} % band (the FTLE's margin, "
              "`kicktimes.stats.margin_of`); 95 % intervals over ICs.", ""]
    return lines


def twin_lines(twins, exp, *, n_ics=8, n_steps=3000):
    """Section 2: the twins with independent kick angles (``n_ics`` ICs, ``n_steps``
    steps of the sweep's tau each), the first estimate beside the measurement."""
    tau, d0 = exp.tau, exp.d0
    lines = ["## 2. Twins with independent kick angles", "",
             "A twin that draws its own kick angles is thrown O(1) away at every kick; the "
             f"first estimate λ ≈ Γ ln(τ/d0) = {math.log(tau / d0):.2f} Γ (τ = {tau:g}, "
             f"d0 = {d0:g}) against Benettin runs ({n_ics} paper ICs, {n_steps} steps of τ; "
             "`science_independent_twins.csv`; the ratio's ends divided crosswise):", ""]
    for row in twins.itertuples():
        lines.append(
            f"- r = {row.radius:g}: λ = {_fmt(row.lam, row.ci_low, row.ci_high)}, "
            f"{row.per_kick:.2f} nats per kick against the estimate's "
            f"{row.predicted_per_kick:.2f}: measured / predicted "
            + reading_text(row.over_predicted, row.over_predicted_ci_low,
                         row.over_predicted_ci_high)
            + f"; against the two disks' {row.two_disk_per_collision:.2f} per collision: "
            f"{reading_text(row.ratio, row.ratio_ci_low, row.ratio_ci_high)}.")
    lines += ["", "Such twins measure the kick's randomisation of the direction, not a "
              "stretching; kicktimes' twins share the kicks.", ""]
    return lines


def decorrelation_lines(dec, compare, closest, *, n_ics=40, t_max=20000.0):
    """Section 3: the decorrelation per single perturbation (``n_ics`` ICs, runs of
    ``t_max``), the prediction beside the measurement, the closest kick law."""
    t_text = f"{t_max:,.0f}".replace(",", " ")
    lines = ["## 3. Decorrelation per single perturbation", "",
             "The correlation of the boundary angle θ across exactly one perturbation "
             f"({n_ics} paper ICs, T = {t_text}; `science_decorrelation.csv`, by angle "
             "`science_decorrelation_by_angle.csv`) predicts the kicked / two-disk ratio of "
             "1 − R₁; beside it the ratio measured in the family store (control primary; "
             "`science_decorrelation_prediction.csv`; the quotient's interval combines both "
             "on the log scale):", "",
             "| rule | r | kick | predicted | measured (store) | measured / predicted |",
             "|---|---|---|---|---|---|"]
    for row in compare.itertuples():
        lines.append(
            f"| {row.rule} | {row.radius:g} | {KICKED[row.system]} | "
            f"{format_interval(row.predicted, row.predicted_ci_low, row.predicted_ci_high)} | "
            f"{reading_text(row.measured, row.measured_ci_low, row.measured_ci_high)} "
            f"(`{row.family}`) | "
            + _ratio_cell(row.measured_over_predicted, row.quotient_ci_low,
                          row.quotient_ci_high, n_ics, unit="ICs in both samples")
            + " |")
    lines += ["", "Which kick law comes closest to the two-disk value (distance |ln ratio|; "
              "the closest group: the lowest upper distance and every law whose distance "
              "interval reaches below it; overlapping intervals do not make laws equal; "
              "every law and control: `science_closest.csv`):", "",
              "| family | quantity | closest, each with its verdict | further from 1 |",
              "|---|---|---|---|"]
    lines += closest_cells(closest)
    lines.append("")
    return lines


def closest_cells(closest):
    """The rows of the closest-kick-law table: per (family, diagnostic), every law of the
    closest group with its own ratio and its own verdict (`reading_text` of its row, so a
    verdict can never be paired with another law), and the laws further from 1.

    Raises
    ------
    ValueError
        A row whose ``verdict`` column disagrees with `ratio_verdict` of its interval.
    """
    lines = []
    for (family, diag), g in closest.groupby(["family", "diagnostic"], sort=False, observed=True):
        best, rest = g[g["closest"]], g[~g["closest"]]
        margin = margin_of(diag)  # the findings table's margin of this diagnostic
        for row in best.itertuples():
            if ratio_verdict(row.ci_low, row.ci_high, tolerance=margin) != row.verdict:
                raise ValueError(f"closest: {family}/{diag}/{row.system} has verdict "
                                 f"{row.verdict!r}, its interval says otherwise")
        names = "; ".join(f"{row.system} "
                          f"{reading_text(row.ratio, row.ci_low, row.ci_high, margin)}"
                          for row in best.itertuples())
        lines.append(f"| `{family}` | {diag} | {names if len(rest) else 'none (all overlap)'} "
                     f"| {', '.join(rest['system']) or '—'} |")
    return lines


def store_lines(whole, windows, sticky, n_ics=None, kept=None):
    """Sections 4 and 5: the collision rate over the run and the sticky orbits;
    ``n_ics`` maps a family to its ICs (the size an inconclusive ratio is scaled from);
    ``kept`` the ``(whole, windows)`` tables without the sticky runs (a column of their
    last window and whole run)."""
    lines = ["## 4. The collision rate over the run", "",
             "Ensemble collision rate of the paper's ICs over the kinetic rate Γ(r), in ten "
             "equal windows of the shortest run averaged over radii "
             "(`science_rate_windows.csv`; per radius `science_rate_relaxation.csv`) and per "
             "radius over the whole run (`science_rate_count.csv`); the last column leaves "
             "out the sticky runs (`science_rate_*_no_sticky.csv`):", "",
             "| family | first window | last window | later windows | whole run, over radii |"
             + (" sticky runs left out: last window; whole run, over radii |" if kept else ""),
             "|---|---|---|---|---|" + ("---|" if kept else "")]
    for fam, g in whole.groupby("family", sort=False, observed=True):
        w = windows[windows["family"] == fam].set_index("window")
        n = (n_ics or {}).get(fam)

        def cell(k, n=n, w=w):
            x, lo, hi = w["rate_over_kinetic"].iloc[k], w["ci_low"].iloc[k], w["ci_high"].iloc[k]
            return (_ratio_cell(x, lo, hi, n, tolerance=RATE_MARGIN) if n else
                    reading_text(x, lo, hi, RATE_MARGIN))

        unresolved = g[_readings(g, tolerance=RATE_MARGIN) == "inconclusive"]
        need = ""
        if n and len(unresolved):
            sizes = sorted(equivalence_sample_size(
                (x.ci_high - x.ci_low) / (2 * Z95), int(n),
                margin=max(abs(RATE_MARGIN - abs(x.count_over_kinetic - 1)), 1e-9))
                for x in unresolved.itertuples())
            span = f"{sizes[0]}" if len(sizes) == 1 else f"{sizes[0]}–{sizes[-1]}"
            need = f"; the inconclusive ones not resolved at this size (need ≈ {span} ICs)"
        lines.append(
            f"| `{fam}` | {cell(0)} | {cell(len(w) - 1)} | "
            f"{w['rate_over_kinetic'].iloc[1:].min():.3f}–"
            f"{w['rate_over_kinetic'].iloc[1:].max():.3f}: "
            f"{_verdict_counts(_readings(w, tolerance=RATE_MARGIN))} of "
            f"{len(w)} windows | {g['count_over_kinetic'].min():.3f}–"
            f"{g['count_over_kinetic'].max():.3f}: "
            f"{_verdict_counts(_readings(g, tolerance=RATE_MARGIN))} of {len(g)}"
            f" radii{need} |" + (_kept_cell(fam, *kept) if kept else ""))
    lines += ["", "Every rate is read at the counts' margin, "
              f"±{100 * RATE_MARGIN:g} % (`margin_of(\"counts\")`, the README's). A family is "
              "said to relax to Γ(r) only where its later windows are within the margin; a "
              "window within it whose interval excludes 1 measures a real offset smaller "
              "than the band.", "",
              "## 5. The sticky orbits", "",
              f"A run is sticky when its collision rate exceeds {STICKY_FACTOR:g} Γ(r) "
              "(`science_sticky.csv`); small |L| is not specific to them where many ICs are "
              "as radial (see [scatter.md](scatter.md) for the set flagged by the FTLE "
              "instead):", ""]
    for row in sticky.itertuples():
        lines.append(
            f"- `{row.family}`: {row.n_sticky} of {row.n_runs} runs "
            f"({100 * row.share_runs:.1f} %) from {row.n_ics_sticky} ICs, one collision per "
            f"{row.median_interval_sticky:.2f} time units (median); median larger initial "
            f"|L| {row.median_max_abs_L_sticky:.3f} against {row.median_max_abs_L_all:.3f} "
            f"over all ICs ({100 * row.share_all_ics_below_sticky_max:.1f} % of all ICs as "
            "radial as the least radial sticky one).")
    lines.append("")
    return lines
