"""``mmpp.md``: the pooled MMPP fits, their residual checks and the refractory dip."""

from __future__ import annotations

from kicktimes.render.pages import header, simulations_source
from kicktimes.render.provenance import Source
from kicktimes.stats import fit_mmpp, format_interval, rejection_rule, rejection_verdict
from kicktimes.stats.findings import clopper_pearson
from kicktimes.studies.mmpp.compute import STICKY_FACTOR
from kicktimes.studies.mmpp.tables import (
    DIP,
    EARLY_EDGES,
    N_MC,
    RENEWAL,
    TESTS,
    analyse,
    battery,
    mmpp_bin_hazard,
    mmpp_dip,
)

__all__ = ["SOURCES", "TABLES", "write_page"]

#: the page's tables, relative to the page
POOLED = "mmpp/mmpp_billiard_pooled.csv"
RESIDUALS = "mmpp/mmpp_billiard_residuals.csv"
DIP_TABLE = "mmpp/mmpp_billiard_dip.csv"
TABLES = (POOLED, RESIDUALS, DIP_TABLE)

#: the page's closing table: the columns it quotes and the functions that computed them
SOURCES = (
    Source(POOLED, "n_runs, n_sticky, t_max, aic_poisson_minus_mmpp, "
           + ", ".join(f"aic_{law}_minus_mmpp" for law in RENEWAL), analyse),
    Source(POOLED, "n_events, rate_low, rate_high, share_high, mean_stay_high, "
           "mean_stay_low, n_best_starts, n_starts", fit_mmpp),
    Source(RESIDUALS, "n_windows, share", battery),
    Source(RESIDUALS, "ci_low, ci_high", clopper_pearson),
    Source(RESIDUALS, "verdict", rejection_verdict),
    Source(DIP_TABLE, "observed, ci_low, ci_high, boot_low, boot_high, verdict, min_bin_low, "
           "min_bin_high, min_observed, min_ci_low, min_ci_high, min_boot_low, "
           "min_boot_high, min_verdict", analyse),
    Source(DIP_TABLE, "mmpp", mmpp_dip),
    Source(DIP_TABLE, "min_mmpp", mmpp_bin_hazard),
)


def write_page(pooled, resid, dip, params, command, seconds, source):
    """The lines of ``mmpp.md`` from the three tables of `analyse` (all rules);
    ``params`` the study's `Params`, ``source`` the name of its cache, ``seconds`` the
    build's."""
    lines = header("MMPP fits to the two-disk collision times", command,
                   [simulations_source("mmpp", source)])
    lines += [f"Definitions and the fit: [../mmpp.md](../mmpp.md). {params.n_ics} paper ICs at "
              f"r = {params.radius:g}, t_max = {params.t_max:g}, per collision rule; runs faster "
              f"than {STICKY_FACTOR:g} Γ(r) (sticky) left out. Residual checks: the "
              "time-rescaled windows through the Poisson battery, share of windows rejected "
              f"at α = 0.05 ({N_MC} Monte Carlo samples); verdicts: {rejection_rule(0.05)}.",
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
    n_w = int(resid["n_windows"].min())
    k5 = round(0.05 * n_w)
    cp_lo, cp_hi = clopper_pearson(k5, n_w)
    for (rule, fit, k), g in resid.groupby(["rule", "fit", "states"], sort=False, observed=True):
        g = g.set_index("test")
        model = "Poisson" if k == 1 else "MMPP-2"
        label = f"{fit}, {model} ({int(g['n_windows'].iloc[0])} windows)"
        lines.append(f"| {rule} | {label} | " + " | ".join(
            f"{100 * g.loc[t, 'share']:.1f} % [{100 * g.loc[t, 'ci_low']:.1f}, "
            f"{100 * g.loc[t, 'ci_high']:.1f}] {g.loc[t, 'verdict']}" for t in TESTS) + " |")
    lines += ["", f"No verdict above can be nominal at this number of windows: even exactly "
              f"{k5} rejections of {n_w} ({100 * k5 / n_w:.1f} %) have the Clopper–Pearson "
              f"interval [{100 * cp_lo:.2f}, {100 * cp_hi:.2f}] %, which does not lie inside "
              "[2.5, 7.5] %; the test has no power to confirm the nominal size here, and "
              "\"inconclusive\" includes fits that hold.", ""]
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
