"""docs/results/disks.md: one answer to "Poisson?" from every statistic against its null.

A Poisson process gives every statistic its null value; a departure shows in some of
them. So the page's "Poisson" / "not Poisson" (`poisson_answer`) reads each statistic of a
row against the same statistic on Poisson streams shaped like the runs
(`kicktimes.studies.disks.versus_null`, `kicktimes.stats.null_verdict`, each with its
margin stated in advance, `MARGINS`):

* ``D``: the dispersion index of the tagged disk's counts in K mean intervals, pooled over
  the runs of one N (the spread of rates across runs is in it, and in its null);
* ``KS share``: the share of tagged disks whose first K collision times reject uniform
  times, against the share its null streams reject through the same pipeline;
* ``gamma shape``: the shape of a gamma renewal fit to the pooled intervals;
* ``hazard bins``: the hazard of the next collision in every bin of the time since the
  last (`versus_null.bin_rows`), each against its null's;
* ``ΔAIC``: the exponential's AIC excess over the best renewal model
  (`kicktimes.studies.disks.renewal`), departing when it exceeds what a gamma shape at its
  margin would give on as many intervals (`versus_null.aic_margin`), at its null when it is
  at most 2;
* ``replicate``: the independent replicate's D (the ``seed`` control) against the null D.

`poisson_answer`: **Poisson** when every statistic is at its null; **not Poisson** when at
least one departs beyond its margin (the answer then names the statistics that do not
depart, with their numbers); **not resolved** otherwise (none departs, some intervals are
wider than their margins allow; the answer names them and the runs that would resolve
them, `kicktimes.stats.equivalence_sample_size`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import format_interval
from kicktimes.studies.disks.versus_null import (
    EDGE_VERDICTS,
    MARGINS,
    aic_margin,
    edge_null_verdict,
)

__all__ = ["ANSWER_RULE", "ANSWER_STATISTICS", "answer_table", "diff_text", "family_table",
           "opening_lines", "poisson_answer", "summary_lines"]

#: the statistics `poisson_answer` reads, in the page's order and words
ANSWER_STATISTICS = ("D", "KS share", "gamma shape", "hazard bins", "ΔAIC", "replicate D")
#: the answer's rule, printed once on the page
ANSWER_RULE = (
    "Poisson: every statistic at its null (the 95 % CI of statistic − null inside ± its "
    "margin); not Poisson: at least one departs (its CI entirely beyond its margin), the "
    "others named with their numbers; not resolved: none departs and at least one CI is "
    "wider than its margin allows. A finding the independent replicate (seed 1042) changes "
    "counts as inconclusive (D, KS share, gamma shape, each hazard bin and ΔAIC are also "
    "computed on it)")

_DEPARTS = ("above its null", "below its null")


def poisson_answer(verdicts) -> tuple[str, list, list]:
    """The combined reading of a row's statistics.

    Parameters
    ----------
    verdicts : dict
        Statistic name -> its `kicktimes.stats.null_verdict` (``"at its null"``,
        ``"above its null"``, ``"below its null"`` or ``"inconclusive"``).

    Returns
    -------
    (str, list, list)
        The answer (``"Poisson"``, ``"not Poisson"``, ``"not resolved"``), the statistics
        that give it (those that depart, for "not Poisson"; every one, for "Poisson"; the
        inconclusive ones, for "not resolved") and the others (those that disagree or do
        not resolve it).

    Examples
    --------
    >>> poisson_answer({"D": "at its null", "KS share": "at its null"})
    ('Poisson', ['D', 'KS share'], [])
    >>> poisson_answer({"D": "at its null", "hazard bins": "below its null"})
    ('not Poisson', ['hazard bins'], ['D'])
    >>> poisson_answer({"D": "at its null", "KS share": "inconclusive"})
    ('not resolved', ['KS share'], ['D'])
    """
    if not verdicts:
        raise ValueError("verdicts: give at least one statistic's verdict")
    bad = {v for v in verdicts.values()} - {"at its null", "inconclusive", *_DEPARTS,
                                             *EDGE_VERDICTS}
    if bad:
        raise ValueError(f"verdicts: unknown verdicts {sorted(bad)}")
    departs = [s for s, v in verdicts.items() if v in _DEPARTS]
    if departs:
        return "not Poisson", departs, [s for s in verdicts if s not in departs]
    at = [s for s, v in verdicts.items() if v == "at its null"]
    if len(at) == len(verdicts):
        return "Poisson", at, []
    return "not resolved", [s for s in verdicts if s not in at], at


def _signed(x):
    return f"{x:+.3f}".replace("-", "−")


def diff_text(est, low, high, margin=None) -> str:
    """``"+0.005 [−0.084, +0.096]"``: a difference and its interval, signed, to three
    decimals (every margin of the page is at least 0.01, so the third decimal places both
    ends against it).

    Examples
    --------
    >>> diff_text(0.00512, -0.0837, 0.0956)
    '+0.005 [−0.084, +0.096]'
    """
    return " ".join([_signed(est), f"[{_signed(low)}, {_signed(high)}]"])


def _aic_verdict(delta, n_intervals):
    if not np.isfinite(delta):
        return "inconclusive"
    if delta > aic_margin(n_intervals):
        return "above its null"
    return "at its null" if delta <= 2.0 else "inconclusive"


def _bins_verdict(bins):
    """The hazard bins' reading: departs when any bin departs, at its null when every bin
    is, else inconclusive; with the text of the bins that depart (or of the widest)."""
    v = bins["verdict"]
    dep = bins[v.isin(_DEPARTS)]
    if not dep.empty:
        r = dep.loc[(dep["diff"]).abs().idxmax()]
        side = "above its null" if r["diff"] > 0 else "below its null"
        text = (f"{len(dep)} of {len(bins)} bins depart, e.g. [{r['t_low']:g}, "
                f"{r['t_high']:g}): "
                + diff_text(r["diff"], r["diff_low"], r["diff_high"], MARGINS["hazard_first"]))
        return side, text
    if v.eq("at its null").all():
        return "at its null", f"all {len(bins)} bins at their null"
    n_at = int(v.eq("at its null").sum())
    return "inconclusive", f"{n_at} of {len(bins)} bins at their null, none departs"


def _match(table, r):
    """The row(s) of ``table`` at ``r``'s geometry, rule and N (empty when none)."""
    if table is None or table.empty:
        return pd.DataFrame()
    return table[(table["geometry"] == r["geometry"]) & (table["rule"] == r["rule"])
                 & (table["n_disks"] == r["n_disks"])]


def _is_finding(verdict) -> bool:
    """Whether a verdict is one the answer reads as a finding (at its null, or departing):
    only those can be changed by the replicate; the others are not read as findings."""
    return verdict == "at its null" or verdict in _DEPARTS


def _replicated_bins(b, seed_b):
    """``b`` (hazard bins of one row) with the verdict of every bin whose replicate bin
    (``seed_b``, the same bin of the seed store against its own null) gives another verdict
    set to inconclusive."""
    rep = seed_b.set_index("t_low")["verdict"]
    same = b["t_low"].map(rep).eq(b["verdict"]).to_numpy()
    return b.assign(verdict=np.where(same, b["verdict"], "inconclusive"))


def answer_table(vn, bins, renewal=None, replicate=None, *, seed_vn=None, seed_bins=None,
                 seed_renewal=None) -> pd.DataFrame:
    """One row per geometry, rule and N: each statistic of `ANSWER_STATISTICS` against its
    null (``<name>_verdict`` and ``<name>_text``), the answer of `poisson_answer`
    (``answer``), its statistics (``by``), the others (``others``) and the statistics whose
    verdict the replicate changes (``replicate_changed``).

    Parameters
    ----------
    vn : DataFrame
        `kicktimes.studies.disks.versus_null.versus_null` rows of the primary sweeps.
    bins : DataFrame
        Their hazard bins (`versus_null`'s second table).
    renewal : DataFrame, optional
        `kicktimes.studies.disks.renewal.renewal_models` rows (``delta_aic_exponential``,
        ``n_intervals``); without it the ΔAIC is not read.
    replicate : DataFrame, optional
        Per geometry, rule and N the replicate's D against the primary's null
        (``replicate_diff``, ``_low``, ``_high``); without it the replicate is not read.
    seed_vn, seed_bins, seed_renewal : DataFrame, optional
        The same three tables of the independent replicate (the ``seed`` control), each
        against its own null. A statistic whose replicate verdict differs (for the hazard,
        bin by bin) counts as inconclusive in the answer: a verdict that a replicate
        changes is not read as a finding.
    """
    out = []
    keys = ["geometry", "rule", "n_disks"]
    for _, r in vn.iterrows():
        row = {k: r[k] for k in keys}
        texts, verdicts, changed = {}, {}, []
        sv = _match(seed_vn, r)
        for name, s in (("D", "d"), ("KS share", "ks"), ("gamma shape", "gamma")):
            verdicts[name] = r[f"{s}_verdict"]
            texts[name] = (f"{name} {format_interval(r[s], r[f'{s}_low'], r[f'{s}_high'])}, "
                           f"null {r[f'null_{s}']:.4g}: "
                           + diff_text(r[f"{s}_diff"], r[f"{s}_diff_low"],
                                       r[f"{s}_diff_high"], MARGINS[s]))
            if not sv.empty:
                q = sv.iloc[0]
                rep = diff_text(q[f"{s}_diff"], q[f"{s}_diff_low"], q[f"{s}_diff_high"])
                texts[name] += f" (replicate {rep} {_short(q[f'{s}_verdict'])})"
                if _is_finding(verdicts[name]) and q[f"{s}_verdict"] != verdicts[name]:
                    changed.append(name)
        b = _match(bins, r)
        if not b.empty:
            verdicts["hazard bins"], texts["hazard bins"] = _bins_verdict(b)
            sb = _match(seed_bins, r)
            if not sb.empty:
                kept = _replicated_bins(b, sb)
                v, t = _bins_verdict(kept)
                n_dep = int(b["verdict"].isin(_DEPARTS).sum())
                if n_dep:
                    n_kept = int(kept["verdict"].isin(_DEPARTS).sum())
                    texts["hazard bins"] += f"; the replicate keeps {n_kept} of the {n_dep}"
                if _is_finding(verdicts["hazard bins"]) and v != verdicts["hazard bins"]:
                    changed.append("hazard bins")
        if renewal is not None and not renewal.empty:
            g = _match(renewal, r)
            if not g.empty:
                delta, n_iv = float(g.iloc[0]["delta_aic_exponential"]), int(
                    g.iloc[0]["n_intervals"])
                verdicts["ΔAIC"] = _aic_verdict(delta, n_iv)
                texts["ΔAIC"] = f"ΔAIC {delta:.3g} (margin {aic_margin(n_iv):.3g})"
                row["delta_aic_exponential"], row["aic_margin"] = delta, aic_margin(n_iv)
                sg = _match(seed_renewal, r)
                if not sg.empty:
                    d2, n2 = float(sg.iloc[0]["delta_aic_exponential"]), int(
                        sg.iloc[0]["n_intervals"])
                    row["replicate_delta_aic"] = d2
                    texts["ΔAIC"] += f" (replicate {d2:.3g})"
                    if _is_finding(verdicts["ΔAIC"]) and _aic_verdict(d2, n2) != verdicts["ΔAIC"]:
                        changed.append("ΔAIC")
        if replicate is not None and not replicate.empty:
            g = _match(replicate, r)
            if not g.empty:
                q = g.iloc[0]
                verdicts["replicate D"] = edge_null_verdict(
                    q["replicate_diff_low"], q["replicate_diff_high"], MARGINS["d"])
                texts["replicate D"] = (
                    f"replicate D {q['replicate_d']:.4g}, null {r['null_d']:.4g}: "
                    + diff_text(q["replicate_diff"], q["replicate_diff_low"],
                                q["replicate_diff_high"], MARGINS["d"]))
        read = {k: ("inconclusive" if k in changed else v) for k, v in verdicts.items()}
        answer, by, others = poisson_answer(read)
        for name in ANSWER_STATISTICS:
            if name in verdicts:
                row[f"{name}_verdict"], row[f"{name}_text"] = verdicts[name], texts[name]
        row.update(answer=answer, by="; ".join(by), others="; ".join(others),
                   replicate_changed="; ".join(changed),
                   d_n_needed=r.get("d_n_needed", np.nan), n_runs=int(r["n_runs"]))
        out.append(row)
    return pd.DataFrame(out)


def _largest_n(table):
    """Each geometry and rule's row at its largest N, in the table's order of families."""
    return table.loc[table.groupby(["geometry", "rule"], sort=False)["n_disks"].idxmax()]


def _short(verdict):
    return {"at its null": "at null", "above its null": "above", "below its null": "below",
            "inconclusive": "inconcl.", EDGE_VERDICTS[0]: "above ≤ margin",
            EDGE_VERDICTS[1]: "below ≤ margin"}.get(verdict, verdict)


def _answer_cell(a):
    """The answer with the statistics that give it and those that disagree (at their null
    while the answer is "not Poisson")."""
    by = [x for x in str(a["by"]).split("; ") if x]
    others = [x for x in str(a["others"]).split("; ") if x]
    changed = [x for x in str(a.get("replicate_changed", "") or "").split("; ") if x]
    moved = f"; changed by the replicate: {', '.join(changed)}" if changed else ""
    if a["answer"] == "not Poisson":
        against = [x for x in others if a.get(f"{x}_verdict") == "at its null"
                   and x not in changed]
        names = "" if not others else f"{', '.join(by)}, "
        return (f"**not Poisson** (by {names}{len(by)} of {len(by) + len(others)}; "
                + (f"at its null: {', '.join(against)}" if against else "none at its null")
                + f"{moved})")
    if a["answer"] == "not resolved":
        return f"**not resolved** (none departs; {len(by)} not at their null{moved})"
    return f"**{a['answer']}**"


def summary_lines(answers, vn) -> list:
    """The first table: at the largest N, per geometry and rule, D beside its null, the
    other statistics' verdicts and the answer."""
    head = ["geometry, rule", "D (null D): D − null D", "KS share − null", "gamma shape − null",
            "hazard bins − null", "ΔAIC, exponential", "answer"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    big = _largest_n(answers)
    for _, a in big.iterrows():
        r = vn[(vn["geometry"] == a["geometry"]) & (vn["rule"] == a["rule"])
               & (vn["n_disks"] == a["n_disks"])].iloc[0]

        def cell(s, r=r):
            return (diff_text(r[f"{s}_diff"], r[f"{s}_diff_low"], r[f"{s}_diff_high"],
                              MARGINS[s]) + f" {_short(r[f'{s}_verdict'])}")

        out.append("| " + " | ".join([
            f"{a['geometry']}, {a['rule']}, N = {int(a['n_disks'])}",
            f"{format_interval(r['d'], r['d_low'], r['d_high'])} "
            f"(null {format_interval(r['null_d'], r['null_d_low'], r['null_d_high'])}): "
            + cell("d"),
            cell("ks"), cell("gamma"),
            f"{a.get('hazard bins_text', '—')} {_short(a.get('hazard bins_verdict', ''))}",
            f"{a.get('delta_aic_exponential', np.nan):.3g} (margin "
            f"{a.get('aic_margin', np.nan):.3g}) {_short(a.get('ΔAIC_verdict', '—'))}",
            _answer_cell(a)]) + " |")
    return out


def family_table(vn) -> list:
    """D − null D at every N (rows) for every geometry and rule (columns), with verdicts."""
    fams = list(dict.fromkeys(zip(vn["geometry"], vn["rule"], strict=True)))
    head = ["N", *[f"{g}, {r}" for g, r in fams]]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for n in sorted(set(vn["n_disks"])):
        cells = []
        for g, rule in fams:
            r = vn[(vn["geometry"] == g) & (vn["rule"] == rule) & (vn["n_disks"] == n)]
            if r.empty:
                cells.append("—")
                continue
            r = r.iloc[0]
            cells.append(diff_text(r["d_diff"], r["d_diff_low"], r["d_diff_high"],
                                   MARGINS["d"]) + f" {_short(r['d_verdict'])}")
        out.append(f"| {n} | " + " | ".join(cells) + " |")
    return out


def _holds_from(ns, ok):
    ok = np.asarray(ok, dtype=bool)
    return next((int(ns[m]) for m in range(len(ns)) if ok[m:].all()), None)


def opening_lines(answers, vn, boltz_d, rate_line) -> list:
    """The page's first screen: five one-line answers, each a number, its interval and its
    caveat, from the computed tables."""
    big = _largest_n(answers)
    n_max = int(big["n_disks"].max())
    counts = big["answer"].value_counts()
    # the example of the answer: the first row that is not Poisson, with its strongest
    # departing statistic
    lines = ["# From two disks to a gas (generated)", ""]
    ex = big[big["answer"] == "not Poisson"]
    ex_text = ""
    if not ex.empty:
        e = ex.iloc[0]
        first = e["by"].split("; ")[0]
        base, _, rep = str(e[f"{first}_text"]).partition(" (replicate ")
        ex_text = (f"; e.g. {e['geometry']}, {e['rule']}: {base} {e[f'{first}_verdict']}"
                   + (f" (replicate {rep}" if rep else ""))
    cols = [f"{name}_verdict" for name in ANSWER_STATISTICS if f"{name}_verdict" in big]
    verdicts = big[cols].to_numpy().ravel()
    verdicts = verdicts[pd.notna(verdicts)]
    n_inc = int((verdicts == "inconclusive").sum())
    n_edge = int(np.isin(verdicts, EDGE_VERDICTS).sum())
    changed = [(f"{a['geometry']}, {a['rule']}", x) for _, a in big.iterrows()
               for x in str(a.get("replicate_changed", "") or "").split("; ") if x]
    moved = (f"; {len(changed)} changed by the replicate, so not read (answer column)"
             if changed else "")
    lines.append(
        f"1. **Poisson at N = {n_max}?** not Poisson at {int(counts.get('not Poisson', 0))} "
        f"of {len(big)} geometry × rule, not resolved at "
        f"{int(counts.get('not resolved', 0))}, Poisson at {int(counts.get('Poisson', 0))}"
        f"{ex_text}. Caveat: of {verdicts.size} single verdicts {n_inc} are inconclusive, "
        f"{n_edge} beyond their null, size unresolved{moved}.")
    froms = {}
    for (g, r), d in vn.groupby(["geometry", "rule"], sort=False):
        d = d.sort_values("n_disks")
        froms[g, r] = _holds_from(d["n_disks"].to_numpy(), d["d_verdict"].eq("at its null"))
    found = [f"{g}, {r} from N = {n}" for (g, r), n in froms.items() if n]
    inc = vn[vn["d_verdict"] == "inconclusive"]
    if (inc["n_disks"] == n_max).any():
        inc = inc[inc["n_disks"] == n_max]
    worst = inc.sort_values("d_n_needed").tail(1)
    w_text = ""
    if not worst.empty:
        w = worst.iloc[0]
        w_text = (f"; e.g. {w['geometry']}, {w['rule']}, N = {int(w['n_disks'])}: D − null "
                  + diff_text(w["d_diff"], w["d_diff_low"], w["d_diff_high"], MARGINS["d"])
                  + f", needs ≈ {int(w['d_n_needed'])} runs (has {int(w['n_runs'])}) if "
                  "it is 0")
    lines.append(
        "2. **From which N is D at its null?** " + ("; ".join(found) if found else
                                                     "at no geometry and rule from any N")
        + f" (within ±{MARGINS['d']:g}). Caveat: elsewhere not resolved at this size"
        + w_text + ".")
    head = vn[(vn["geometry"] == vn["geometry"].iloc[0])
              & (vn["rule"] == vn["rule"].iloc[0])].sort_values("n_disks")
    lo, hi = head.iloc[0], head.iloc[-1]
    lines.append(
        f"3. **D − null D, {lo['geometry']}, {lo['rule']}:** "
        + diff_text(lo["d_diff"], lo["d_diff_low"], lo["d_diff_high"], MARGINS["d"])
        + f" at N = {int(lo['n_disks'])} → "
        + diff_text(hi["d_diff"], hi["d_diff_low"], hi["d_diff_high"], MARGINS["d"])
        + f" at N = {int(hi['n_disks'])}. Caveat: the null D itself goes "
        f"{lo['null_d']:.3g} → {hi['null_d']:.3g} (the spread of rates across runs).")
    if boltz_d is not None and not boltz_d.empty:
        at = boltz_d[(boltz_d["n_disks"] == n_max) & (boltz_d["rule"] == "elastic")]
    if boltz_d is not None and not boltz_d.empty and not at.empty:
        n_at = int(at["verdict"].eq("at its null").sum())
        n_dep = int(at["verdict"].isin(_DEPARTS).sum())
        e = at.loc[(at["diff_high"] - at["diff_low"]).idxmin()]
        lines.append(
            f"4. **Elastic D against linear Boltzmann's (N = {n_max}):** within "
            f"±{MARGINS['d']:g} at {n_at} of {len(at)}, departs at {n_dep}; e.g. "
            f"{e['geometry']}: gas − Boltzmann "
            + diff_text(e["diff"], e["diff_low"], e["diff_high"], MARGINS["d"])
            + ". Caveat: the intervals are wider than the margin.")
    lines.append(f"5. {rate_line}")
    return [*lines, ""]
