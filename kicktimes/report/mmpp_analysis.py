r"""The MMPP-2 for outside data: ``kicktimes analyze --mmpp``.

Per group, the first ``max_fits_per_group`` sequences with at least
`~kicktimes.report.mmpp.MIN_EVENTS` events get

* the parametric-bootstrap likelihood-ratio test of a two-state Markov-modulated Poisson
  process against the homogeneous Poisson process (`kicktimes.stats.mmpp_lr_test`: the
  :math:`\chi^2` reference fails at the boundary, where the rates coincide), with the
  fitted rates and switching rates;
* the MMPP-2 in the renewal comparison: its AIC on the renewal fits' likelihood (the
  events after the first, given it; `kicktimes.stats.compare_point_processes`) against
  the sequence's renewal AICs of ``Analysis.renewal_per_sequence``.

Sequences are independent, so (as for the Poisson battery) each group's p-values are
Fisher-combined and the verdict is Bonferroni-corrected over groups.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
from scipy import stats as sps

from kicktimes.report.mmpp import MIN_EVENTS, N_STARTS

__all__ = ["COLUMNS", "analyze_mmpp", "mmpp_finding"]

#: the columns of `analyze_mmpp`'s table
COLUMNS = ("group", "sequence", "n_events", "rate", "rate_low", "rate_high", "switch_low",
           "switch_high", "stationary_rate", "lr_statistic", "lr_pvalue", "lr_reject",
           "mmpp_aic", "poisson_aic", "best_renewal_model", "best_renewal_aic", "mmpp_best",
           "mmpp_beats_poisson", "note")


def _one(times, window, n_boot, rng, alpha):
    from kicktimes import stats

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # degenerate fits are named in the note
        test = stats.mmpp_lr_test(times, window, n_boot=n_boot, n_starts=N_STARTS, rng=rng)
        table = stats.compare_point_processes(times, window, models=[], n_states=(2,),
                                              n_starts=N_STARTS, rng=rng)
    fit, q = test.mmpp, test.mmpp.generator
    return {"rate_low": float(fit.rates[0]), "rate_high": float(fit.rates[1]),
            "switch_low": float(-q[0, 0]), "switch_high": float(-q[1, 1]),
            "stationary_rate": fit.stationary_rate, "lr_statistic": test.statistic,
            "lr_pvalue": test.pvalue, "lr_reject": test.pvalue < alpha,
            "mmpp_aic": float(table.loc["mmpp2", "aic"]),
            "poisson_aic": float(table.loc["poisson", "aic"]),
            "note": "; ".join(fit.warnings)}


def analyze_mmpp(res, *, n_boot=99, max_fits_per_group=12, rng=None) -> pd.DataFrame:
    """The MMPP-2 of every fitted sequence of an analysis (see the module notes).

    Parameters
    ----------
    res : kicktimes.stats.Analysis
        The result of `kicktimes.stats.analyze` (its sequences, groups, ``alpha`` and
        renewal comparisons).
    n_boot : int, optional
        Bootstrap samples of each LR test (p-value resolution ``1 / (n_boot + 1)``;
        about 3-5 s per sequence at 99).
    max_fits_per_group : int or None, optional
        Sequences per group (first by order of appearance) with a test; None: all.
    rng : Generator or int, optional
        Seed of the fits' starts and the bootstrap (one child stream per sequence).

    Returns
    -------
    pandas.DataFrame
        One row per tested sequence, columns `COLUMNS`: the fitted rates and the rates
        of leaving the low and the high state, the LR statistic, its bootstrap p-value and
        ``lr_reject`` (p < ``res.alpha``); the conditional AICs of the MMPP-2 and of
        Poisson, the best renewal model and its AIC, ``mmpp_best`` (the MMPP-2 has the
        lowest AIC of all) and ``mmpp_beats_poisson``.
    """
    from kicktimes.validation import check_int, check_rng

    n_boot = check_int("n_boot", n_boot, low=1)
    if max_fits_per_group is not None:
        max_fits_per_group = check_int("max_fits_per_group", max_fits_per_group, low=0)
    rng = check_rng(rng)
    renewal = res.renewal_per_sequence.dropna(subset=["aic"])
    best = renewal.loc[renewal.groupby("sequence", observed=True)["aic"].idxmin()]
    best = best.set_index("sequence")
    seqs = res.sequences[res.sequences["n_events"] >= MIN_EVENTS]
    rows = []
    for g, part in seqs.groupby("group", sort=False, observed=True):
        if max_fits_per_group is not None:
            part = part.iloc[:max_fits_per_group]
        for row, stream in zip(part.itertuples(), rng.spawn(len(part)), strict=True):
            times, window = np.asarray(row.times, float), float(row.t_window)
            out = {"group": g, "sequence": row.sequence, "n_events": int(row.n_events),
                   "rate": row.n_events / window}
            try:
                out.update(_one(times, window, n_boot, stream, res.alpha))
            except ValueError as exc:
                out["note"] = f"no MMPP fit: {exc}"
            has = row.sequence in best.index
            out["best_renewal_model"] = best.loc[row.sequence, "model"] if has else None
            out["best_renewal_aic"] = float(best.loc[row.sequence, "aic"]) if has else math.nan
            rows.append(out)
    table = pd.DataFrame(rows, columns=list(COLUMNS))
    aic = table["mmpp_aic"]
    # a sequence without a renewal fit: the MMPP-2 is set against Poisson only
    renewal_aic = table["best_renewal_aic"].fillna(table["poisson_aic"])
    table["mmpp_best"] = (aic < np.fmin(renewal_aic, table["poisson_aic"])).where(aic.notna())
    table["mmpp_beats_poisson"] = (aic < table["poisson_aic"]).where(aic.notna())
    table.attrs["n_boot"] = n_boot
    return table


def mmpp_finding(res, table):
    """The analysis' finding "Clustered (MMPP-2)?" from `analyze_mmpp`'s table."""
    from kicktimes.stats.findings import Finding, clopper_pearson, format_p

    groups = list(dict.fromkeys(table["group"]))
    tested = table.dropna(subset=["lr_pvalue"])
    cut = res.alpha / max(len(groups), 1)
    rule = (f"clustered when some group's Fisher-combined bootstrap LR p-value (MMPP-2 "
            f"against Poisson) is below alpha / groups = {cut:.3g} (Bonferroni); consistent "
            "with Poisson otherwise. The MMPP-2's AIC on the renewal fits' likelihood says "
            "whether it also beats the renewal models.")
    if tested.empty:
        return Finding("Clustered (MMPP-2)?", "inconclusive",
                       f"No sequence has {MIN_EVENTS} or more events for an MMPP-2 fit.", rule)
    parts, clustered = [], False
    for g in groups:
        t = tested[tested["group"] == g]
        if t.empty:
            continue
        p = np.clip(t["lr_pvalue"].to_numpy(float), 1e-300, 1.0)
        combined = float(sps.combine_pvalues(p, method="fisher").pvalue)
        clustered |= combined < cut
        k = int(t["lr_reject"].sum())
        lo, hi = clopper_pearson(k, len(t))
        value = f"{g:g}" if isinstance(g, (int, float, np.number)) else str(g)
        label = "" if res.group is None else f"{res.group} = {value}: "
        text = (f"{label}{k} of {len(t)} sequences reject Poisson at α = {res.alpha:g} "
                f"({100 * k / len(t):.0f} %, 95 % CI {100 * lo:.0f}-{100 * hi:.0f} %; "
                f"Fisher p = {format_p(combined)}); the MMPP-2 is AIC-best against Poisson and "
                f"the renewal models for {int(t['mmpp_best'].sum())}")
        rejected = t[t["lr_reject"].astype(bool)]
        if len(rejected):
            text += (f"; where Poisson is rejected the high rate is a median "
                     f"{np.median(rejected['rate_high'] / rejected['rate_low']):.3g} times the "
                     f"low one, with mean stays of "
                     f"{np.median(1 / rejected['switch_low']):.3g} (low) and "
                     f"{np.median(1 / rejected['switch_high']):.3g} (high) time units")
        parts.append(text)
    verdict = "clustered (MMPP-2)" if clustered else "consistent with Poisson"
    n_boot = table.attrs.get("n_boot")
    resolution = "" if n_boot is None else f"; p-values at resolution 1/{n_boot + 1}"
    statement = ("Parametric-bootstrap LR test of a two-state MMPP against Poisson per "
                 f"sequence ({len(tested)} tested, {MIN_EVENTS}+ events{resolution}): "
                 + "; ".join(parts) + ".")
    return Finding("Clustered (MMPP-2)?", verdict, statement, rule)
