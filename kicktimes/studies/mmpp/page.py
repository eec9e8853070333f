"""``mmpp.md``: the pooled MMPP fits, their residual checks and the refractory dip."""

from __future__ import annotations

import numpy as np

from kicktimes.render.pages import header, simulations_source
from kicktimes.render.provenance import Source
from kicktimes.stats import (
    compare_point_processes,
    fit_mmpp,
    format_interval,
    rejection_verdict,
)
from kicktimes.stats.findings import clopper_pearson
from kicktimes.studies.mmpp.compute import STICKY_FACTOR
from kicktimes.studies.mmpp.tables import (
    DIP,
    EARLY_EDGES,
    N_MC,
    PER_RUN_STARTS,
    RENEWAL,
    SHARE_MARGIN,
    TESTS,
    analyse,
    battery,
    choice_rows,
    edge_null_verdict,
    mmpp_bin_hazard,
    mmpp_dip,
    null_rows,
)

__all__ = ["SOURCES", "TABLES", "answers", "write_page"]

#: the page's tables, relative to the page
POOLED = "mmpp/mmpp_billiard_pooled.csv"
RESIDUALS = "mmpp/mmpp_billiard_residuals.csv"
DIP_TABLE = "mmpp/mmpp_billiard_dip.csv"
CHOICE = "mmpp/mmpp_billiard_choice.csv"
NULL = "mmpp/mmpp_billiard_null.csv"
TABLES = (POOLED, RESIDUALS, DIP_TABLE, CHOICE, NULL)

#: the page's closing table: the columns it quotes and the functions that computed them
SOURCES = (
    Source(POOLED, "n_runs, n_sticky, t_max, aic_poisson_minus_mmpp, "
           + ", ".join(f"aic_{law}_minus_mmpp" for law in RENEWAL), analyse),
    Source(POOLED, "n_events, rate_low, rate_high, share_high, mean_stay_high, "
           "mean_stay_low, n_best_starts, n_starts", fit_mmpp),
    Source(RESIDUALS, "n_windows, share", battery),
    Source(RESIDUALS, "ci_low, ci_high", clopper_pearson),
    Source(DIP_TABLE, "observed, ci_low, ci_high, boot_low, boot_high, verdict, min_bin_low, "
           "min_bin_high, min_observed, min_ci_low, min_ci_high, min_boot_low, "
           "min_boot_high, min_verdict", analyse),
    Source(DIP_TABLE, "mmpp", mmpp_dip),
    Source(DIP_TABLE, "min_mmpp", mmpp_bin_hazard),
    Source(CHOICE, "n_runs, n_best_billiard, share_billiard, n_best_shuffled, share_shuffled, "
           "share_beats_poisson", compare_point_processes),
    Source(CHOICE, "ci_low_billiard, ci_high_billiard, ci_low_shuffled, ci_high_shuffled",
           clopper_pearson),
    Source(CHOICE, "difference, diff_low, diff_high, n_to_resolve", choice_rows),
    Source(CHOICE, "verdict", edge_null_verdict),
    Source(NULL, "share, null_share, difference, diff_low, diff_high, n_to_resolve",
           null_rows),
    Source(NULL, "null_ci_low, null_ci_high", clopper_pearson),
    Source(NULL, "verdict", edge_null_verdict),
    Source(NULL, "null_vs_alpha", rejection_verdict),
)


def _pts(x):
    return f"{100 * x:+.1f}"


def _diff(row):
    """``+33.1 [25.4, 40.3] pts, above its null`` (and the size that would resolve it)."""
    text = (f"{_pts(row.difference)} [{_pts(row.diff_low)}, {_pts(row.diff_high)}] pts, "
            f"{row.verdict}")
    if row.verdict == "inconclusive":
        text += f" (~{int(row.n_to_resolve)} runs would resolve it)"
    return text


def answers(pooled, dip, choice, nulls) -> list[str]:
    """The page's first screen: at most five one-line answers, each one number with its
    95 % interval, its verdict against its own null and its caveat."""
    lines = []
    for c in choice.itertuples():
        p = pooled.set_index("rule").loc[c.rule]
        between = max(p.mean_stay_high, p.mean_stay_low) > p.t_max
        lines.append(
            f"- **Are a run's intervals dependent? ({c.rule} rule)** The MMPP-2 is AIC-best "
            "among Poisson, renewal laws and MMPP-2 (each run fitted alone) in "
            f"{100 * c.share_billiard:.1f} % [{100 * c.ci_low_billiard:.1f}, "
            f"{100 * c.ci_high_billiard:.1f}] of {c.n_runs} runs vs "
            f"{100 * c.share_shuffled:.1f} % on the same runs' intervals shuffled: "
            f"{_diff(c)}; this rests on within-run fits against shuffles, not on the pooled "
            "ΔAIC" + (", which here counts differences between runs (mean stay "
                      f"{max(p.mean_stay_high, p.mean_stay_low):.0f} > t_max)" if between
                      else "") + ".")
    per = nulls[nulls["fit"] == "per run"]
    if len(per):
        worst = per.iloc[int(np.argmax(per["diff_low"].to_numpy()))]
        counts = per["verdict"].value_counts()
        lines.append(
            f"- **Per-run MMPP-2 residuals against their calibrated null** (windows simulated "
            "from each run's fit, fitted the same way; null levels "
            f"{100 * per['null_share'].min():.1f}–{100 * per['null_share'].max():.1f} %, not "
            f"α): worst {worst.rule} {worst.test} {100 * worst.share:.1f} % vs "
            f"{100 * worst.null_share:.1f} %, {_diff(worst)}; over {len(per)} (rule, test) "
            "cells " + ", ".join(f"{k} at {v}" for k, v in counts.items()) + ".")
    pool = nulls[(nulls["fit"] == "pooled") & (nulls["states"] == 2)]
    if len(pool):
        worst = pool.iloc[int(np.argmax(pool["diff_low"].to_numpy()))]
        counts = pool.groupby("rule", sort=False)["verdict"].apply(
            lambda v: (v == "above its null").sum())
        lines.append(
            f"- **One pooled MMPP-2 per rule** ({worst.rule}, {worst.test}): rejects "
            f"{100 * worst.share:.1f} % of windows vs {100 * worst.null_share:.1f} % on "
            f"windows simulated from it: {_diff(worst)}; above its null at "
            + ", ".join(f"{v} of {len(TESTS)} tests ({k})" for k, v in counts.items()) + ".")
    d = dip.set_index("rule")
    if "mirror" in d.index:
        m = d.loc["mirror"]
        lines.append(
            f"- **Refractory dip (mirror rule)**: hazard in [0, {DIP:g}) after a collision "
            f"over the rate {format_interval(m.observed, m.ci_low, m.ci_high, edges=(1.0,))} "
            f"(bootstrap over runs [{m.boot_low:.3f}, {m.boot_high:.3f}]) vs the fitted "
            f"MMPP-2's {m.mmpp:.3f}: {m.verdict}; no MMPP can fall below 1 there.")
    return lines[:5]


def write_page(pooled, resid, dip, choice, nulls, params, command, seconds, source):
    """The lines of ``mmpp.md`` from the five tables of `analyse` (all rules);
    ``params`` the study's `Params`, ``source`` the name of its cache, ``seconds`` the
    build's."""
    lines = header("MMPP fits to the two-disk collision times", command,
                   [simulations_source("mmpp", source)])
    lines += answers(pooled, dip, choice, nulls)
    lines += ["", "Verdicts: a share is read against its own null, the same share on null data "
              "treated the same way (the runs' intervals shuffled; windows simulated from the "
              "fit and refitted), by the 95 % CI of share − null share (bootstrap over "
              f"runs): at its null when it lies in [−{100 * SHARE_MARGIN:g}, "
              f"{100 * SHARE_MARGIN:g}] points (a margin stated in advance, half of α), above "
              "/ below its null when wholly beyond, above / below its null, size unresolved, "
              "when it straddles a margin edge but excludes 0, inconclusive when it "
              "contains 0 and straddles an edge, only then with the runs that would resolve the "
              "margin (`mmpp_billiard_null.csv`, `mmpp_billiard_choice.csv`). Every residual "
              "share is read this way, against its own null share, never against α: the "
              "null shares of the fits are not α.", "",
              f"Definitions and the fit: [../mmpp.md](../mmpp.md). {params.n_ics} paper ICs at "
              f"r = {params.radius:g}, t_max = {params.t_max:g}, per collision rule; runs faster "
              f"than {STICKY_FACTOR:g} Γ(r) (sticky) left out. Residual checks: the "
              "time-rescaled windows through the Poisson battery, share of windows rejected "
              f"at α = 0.05 ({N_MC} Monte Carlo samples). Runs fitted alone: {PER_RUN_STARTS} "
              "EM starts each.",
              "", "**Pooled fits** (MMPP-2; AIC differences of the other models on the same "
              "windows, positive where the MMPP-2 fits better; the renewal models treat the "
              "first gap, from t = 0, as a renewal interval and censor the last, the MMPP "
              "starts each window from its stationary law):", "",
              "| rule | runs (sticky) | events | rates low / high | time in high state | "
              "mean stay high / low | ΔAIC Poisson | " + " | ".join(
                  f"ΔAIC {law}" for law in RENEWAL) + " | starts at the best |",
              "|---|---|---|---|---|---|---|" + "---|" * len(RENEWAL) + "---|"]
    for p in pooled.itertuples():
        lines.append(f"| {p.rule} | {p.n_runs} ({p.n_sticky}) | {p.n_events} | "
                     f"{p.rate_low:.4f} / {p.rate_high:.4f} | {100 * p.share_high:.1f} % | "
                     f"{p.mean_stay_high:.1f} / {p.mean_stay_low:.1f} | "
                     f"{p.aic_poisson_minus_mmpp:.1f} | " + " | ".join(
                         f"{getattr(p, f'aic_{law}_minus_mmpp'):.1f}" for law in RENEWAL)
                     + f" | {p.n_best_starts}/{p.n_starts} |")
    lines += ["", "**Time-rescaling residuals** (`mmpp_billiard_residuals.csv`). The per-run "
              "fits are checked on the run they were fitted to (in sample), the pooled fits "
              "on every window. The Cox twins of the post-collision states, the other model "
              "of the clustering, are on [mechanism.md](mechanism.md).", "",
              "| rule | fit | " + " | ".join(TESTS) + " |", "|---|---|" + "---|" * len(TESTS)]
    null = nulls.set_index(["rule", "fit", "states", "test"])
    for (rule, fit, k), g in resid.groupby(["rule", "fit", "states"], sort=False, observed=True):
        g = g.set_index("test")
        model = "Poisson" if k == 1 else "MMPP-2"
        label = f"{fit}, {model} ({int(g['n_windows'].iloc[0])} windows)"
        lines.append(f"| {rule} | {label} | " + " | ".join(
            f"{100 * g.loc[t, 'share']:.1f} % [{100 * g.loc[t, 'ci_low']:.1f}, "
            f"{100 * g.loc[t, 'ci_high']:.1f}] (null "
            f"{100 * null.loc[(rule, fit, k, t), 'null_share']:.1f} %), "
            f"{null.loc[(rule, fit, k, t), 'verdict']}" for t in TESTS) + " |")
    lines += ["", "Each share's verdict is that of share − null share in the table below: the "
              "null's share is that of windows simulated from the same fit and refitted, so a "
              "share far from α can still sit at its null, and one near α can lie above it.",
              "",
              "**Residuals against their calibrated null** (`mmpp_billiard_null.csv`: share − "
              "null share in percentage points; the null's own share beside it):", "",
              "| rule | fit | " + " | ".join(TESTS) + " |", "|---|---|" + "---|" * len(TESTS)]
    for (rule, fit, k), g in nulls.groupby(["rule", "fit", "states"], sort=False,
                                           observed=True):
        g = g.set_index("test")
        model = "Poisson" if k == 1 else "MMPP-2"
        lines.append(f"| {rule} | {fit}, {model} | " + " | ".join(
            f"{_pts(g.loc[t, 'difference'])} [{_pts(g.loc[t, 'diff_low'])}, "
            f"{_pts(g.loc[t, 'diff_high'])}] (null {100 * g.loc[t, 'null_share']:.1f} %), "
            f"{g.loc[t, 'verdict']}" for t in TESTS) + " |")
    lines += ["", "**Model choice per run** (`mmpp_billiard_choice.csv`; the MMPP-2 AIC-best "
              "among Poisson, the renewal laws and the MMPP-2, each run fitted alone, against "
              "the same run with its intervals in random order, which keeps their law and "
              "removes any dependence):", "",
              "| rule | runs | MMPP-2 AIC-best | on shuffled intervals | difference | "
              "MMPP-2 beats Poisson |", "|---|---|---|---|---|---|"]
    for c in choice.itertuples():
        lines.append(f"| {c.rule} | {c.n_runs} | {100 * c.share_billiard:.1f} % "
                     f"[{100 * c.ci_low_billiard:.1f}, {100 * c.ci_high_billiard:.1f}] | "
                     f"{100 * c.share_shuffled:.1f} % [{100 * c.ci_low_shuffled:.1f}, "
                     f"{100 * c.ci_high_shuffled:.1f}] | {_diff(c)} | "
                     f"{100 * c.share_beats_poisson:.1f} % |")
    lines += [""]
    lines += ["", f"**The refractory dip**: the hazard of the next collision in [0, {DIP:g}) "
              "after a collision over the pooled rate, observed (Garwood interval, which treats "
              "every interval as independent, and a 95 % bootstrap interval over runs) against "
              "the fitted MMPP-2's (exact) and a Poisson process's (1) "
              "(`mmpp_billiard_dip.csv`). The ICs are those of the mechanism study's paper-IC "
              f"groups (seed {params.seed}, drawn at r = {params.radius:g} under each rule) and "
              "the hazard is the same `kicktimes.stats.interval_hazard` of the intervals after "
              "a collision, sticky runs left out, so at r = 0.02 the observed value is the one on "
              "[mechanism.md](mechanism.md). Another IC draw of the same size can move the "
              "dip by more than the Garwood interval (it ignores the differences between "
              "runs); the bootstrap over runs includes them. The first bin alone can miss the "
              "dip: the whole early hazard is read too, over the bins "
              + ", ".join(f"[{a:g}, {b:g})" for a, b in zip(EARLY_EDGES[:-1], EARLY_EDGES[1:],
                                                           strict=True))
              + " (those of [mechanism.md](mechanism.md)), with its minimum, the bin where it "
              "falls and the MMPP-2's exact mean hazard in that bin (the interval of the "
              "minimum is its bin's own, not adjusted for picking the lowest of several "
              "bins; the bootstrap holds the bin fixed).", ""]
    for d in dip.itertuples():
        observed = format_interval(d.observed, d.ci_low, d.ci_high, edges=(d.mmpp,))
        burst = (f"the MMPP-2 predicts a hazard above the rate (a burst right after a "
                 f"collision, {d.mmpp:.3f}) where " if d.mmpp > 1 else
                 f"the MMPP-2 predicts {d.mmpp:.3f}; ")
        deficit = ("the data show a deficit (the observed interval lies below 1)"
                   if max(d.ci_high, d.boot_high) < 1 else
                   "the observed interval is not below 1")
        lines.append(f"- {d.rule} rule, first bin [0, {DIP:g}): observed {observed} "
                     f"(bootstrap over runs [{d.boot_low:.3f}, {d.boot_high:.3f}]); "
                     f"{burst}{deficit}: {d.verdict}.")
        low = format_interval(d.min_observed, d.min_ci_low, d.min_ci_high,
                              edges=(d.min_mmpp, 1.0))
        below = ("below 1" if max(d.min_ci_high, d.min_boot_high) < 1 else "not below 1")
        lines.append(f"- {d.rule} rule, the whole early hazard: its minimum over t < "
                     f"{EARLY_EDGES[-1]:g} falls in [{d.min_bin_low:g}, {d.min_bin_high:g}), "
                     f"observed {low} (bootstrap over runs [{d.min_boot_low:.3f}, "
                     f"{d.min_boot_high:.3f}], {below}); the MMPP-2 predicts "
                     f"{d.min_mmpp:.3f} there: {d.min_verdict}.")
    for p in pooled.itertuples():
        if max(p.mean_stay_high, p.mean_stay_low) > p.t_max:
            lines.append(f"- {p.rule} rule: the longer mean stay in a state "
                         f"({max(p.mean_stay_high, p.mean_stay_low):.0f}, high / low "
                         f"{p.mean_stay_high:.0f} / {p.mean_stay_low:.0f}) exceeds t_max = "
                         f"{p.t_max:g}, so a run mostly stays in one state: the two "
                         "\"states\" are then differences between runs, not clustering in "
                         "time.")
    lines += ["", f"Built in {seconds:.0f} s.", ""]
    return lines
