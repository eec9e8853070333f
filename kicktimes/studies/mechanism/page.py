"""The page ``mechanism.md`` from the numbers tables of both collision rules.

Reads the ``mechanism_numbers.csv`` of each rule (`kicktimes.studies.mechanism.run`
writes them) and writes the page: every number from a row, every comparative word from a
verdict (`kicktimes.stats.ratio_verdict` for a hazard against the rate it should equal,
disjoint 95 % intervals for "above chance"), closed by the table of where its numbers come
from (`sources`). Definitions and methods stay in docs/mechanism.md.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from kicktimes.render.pages import header, write_results_page
from kicktimes.render.provenance import Source
from kicktimes.stats import MARGIN, format_interval, ratio_rule, ratio_verdict
from kicktimes.studies.mechanism.analysis import analyse, hazard_profile_rows
from kicktimes.studies.mechanism.figures import NORMALISED_YLIM

__all__ = ["load", "rule_section", "sources", "summary", "write_page"]

GROUPS = (("paper", 0.01), ("paper", 0.02), ("uniform", 0.01), ("uniform", 0.02))
LABEL = {"paper": "paper ICs", "uniform": "invariant ICs"}
TESTS = (("uniformity_ks", "uniformity KS rejections"),
         ("exponential_ad", "exponential AD rejections"),
         ("dispersion_index_nonsticky", "dispersion index, sticky runs left out"))
MODELS = (("cox_sequence", "in sample: Cox twin replaying the run's own states"),
          ("cox_markov_oos", "out of sample: rate chain fitted on the other half of the ICs"),
          ("cox_iid", "rates drawn independently from the group's pooled states"))


def load(folder):
    """The numbers of one rule, indexed by (method, radius, quantity)."""
    path = Path(folder) / "mechanism_numbers.csv"
    if not path.is_file():
        raise ValueError(f"folders: {path} is missing (the study writes it: "
                         "kicktimes reproduce --study mechanism)")
    tab = pd.read_csv(path)
    if "rule" not in tab:
        raise ValueError(f"folders: {path} has no rule column (written before issue 41)")
    return tab


def _get(tab, method, r, quantity):
    m = tab[(tab["method"] == method) & (tab["radius"] == r) & (tab["quantity"] == quantity)]
    if len(m) != 1:
        raise ValueError(f"folders: no single row {quantity!r} for {method}, r = {r:g}")
    return m.iloc[0]


def _iv(row, edges=()):
    if not math.isfinite(row["estimate"]):
        return "n/a"
    if not (math.isfinite(row["ci_low"]) and math.isfinite(row["ci_high"])):
        return f"{row['estimate']:.3g}"
    return format_interval(row["estimate"], row["ci_low"], row["ci_high"], edges=edges)


def _hazard_cell(row):
    """A hazard over its reference rate (1), with the ratio verdict against it."""
    if not math.isfinite(row["estimate"]):
        return "no interval ends there"
    return f"{_iv(row, (0.9, 1.0, 1.1))}, {ratio_verdict(row['ci_low'], row['ci_high'], MARGIN)}"


def _bins_cell(row):
    """``k of n: [a, b), ...`` from a ``hazard_nonsticky_bins_lower`` row."""
    of, _, where = row["note"].partition(": ")
    return f"{int(row['estimate'])} {of.split(' bins')[0]}: {where}"


#: the observed row of each explained quantity and the Poisson value it is measured from
OBSERVED = {"uniformity_ks": ("observed_reject_uniformity_ks", 0.05),
            "exponential_ad": ("observed_reject_exponential_ad", 0.05),
            "dispersion_index_nonsticky": ("observed_dispersion_index_nonsticky", 1.0)}


def _excess(tab, m, r, test):
    """Whether the observed value's 95 % interval lies above the Poisson value (an excess
    to explain; a gap inside its own noise is not decomposed)."""
    name, base = OBSERVED[test]
    row = _get(tab, m, r, name)
    return bool(row["ci_low"] > base)


def _explained_cell(tab, m, r, test, model):
    if not _excess(tab, m, r, test):
        return "no excess to explain"
    return _iv(_get(tab, m, r, f"explained_{test}_by_{model}"))


def _above_chance(share, chance):
    if share["ci_low"] > chance["ci_high"]:
        return "above chance"
    if share["ci_high"] < chance["ci_low"]:
        return "below chance"
    return "not distinguished from chance (intervals overlap)"


def rule_section(tab, figures):
    """The section of one rule; ``figures`` is its folder relative to the page."""
    rule = tab["rule"].iloc[0]
    run = tab[tab["method"] == "run"].set_index("quantity")["estimate"]
    groups = [g for g in GROUPS if ((tab["method"] == g[0]) & (tab["radius"] == g[1])).any()]
    head = "| | " + " | ".join(f"{LABEL[m]}, r = {r:g}" for m, r in groups) + " |"
    sep = "|---|" + "---|" * len(groups)

    def line(label, fn):
        return f"| {label} | " + " | ".join(fn(m, r) for m, r in groups) + " |"

    g = lambda m, r, q: _get(tab, m, r, q)  # noqa: E731
    lines = [f"## The {rule} rule", "",
             f"{int(run['n_ics'])} ICs per group, `t_max = {run['t_max']:g}`, "
             f"{int(run['twins'])} twin ensembles per model, seed {int(run['seed'])}; "
             "collisions per group: " + ", ".join(
                 f"{int(g(m, r, 'n_collisions')['estimate'])}" for m, r in groups) + ".", "",
             "**Hazard of the next collision** (sticky runs left out; over the group's pooled "
             "rate, 95 % Garwood intervals, which treat every interval as independent and "
             "leave out the differences between runs; verdicts against 1 by "
             "`ratio_verdict`. The whole early hazard is read, every bin up to t = 4 (the "
             "refractory time and the wall round trips): its minimum, the bin where it falls "
             "(the Garwood interval is that bin's own, not adjusted for picking the lowest of "
             "several), and how many bins lie below the rate each by its own interval, beside "
             "the first bin alone. At r = 0.02, paper ICs, the first bin and the minimum are "
             "the refractory dip of [mmpp.md](mmpp.md): the same ICs, the same "
             "`kicktimes.stats.interval_hazard`; that page gives a bootstrap interval over runs "
             "beside them; every bin is in the table, rows `hazard_nonsticky_bin_*`):", "",
             head, sep,
             line("in [0, 0.5) after a collision (first bin)",
                  lambda m, r: _hazard_cell(g(m, r, "hazard_nonsticky_first_bin_over_rate"))),
             line("minimum over t < 4 (bin)", lambda m, r: _hazard_cell(
                 g(m, r, "hazard_nonsticky_min_over_rate"))
                 + f" ({g(m, r, 'hazard_nonsticky_min_over_rate')['note']})"),
             line("bins below the rate, t < 4", lambda m, r: _bins_cell(
                 g(m, r, "hazard_nonsticky_bins_lower"))),
             line("peak (bin)", lambda m, r: f"{_iv(g(m, r, 'hazard_nonsticky_peak_over_rate'))}"
                  f" ({g(m, r, 'hazard_nonsticky_peak_over_rate')['note']})"),
             line("in [3, 4)", lambda m, r: _hazard_cell(
                 g(m, r, "hazard_nonsticky_dip_over_rate"))),
             "", "**Γ-rescaled hazard** (each interval times the predicted rate Γ of the state "
             "it starts in" + (", conditioned on the speeds as well as on the angular momenta"
                               if rule == "elastic" else "")
             + "; all runs; 1 at every rescaled time if the phase-averaged rate held):", "",
             head, sep,
             line("overall rate",
                  lambda m, r: f"{g(m, r, 'rescaled_hazard_rate')['estimate']:.3f}"),
             line("rescaled t in [0.2, 1)", lambda m, r: _hazard_cell(
                 g(m, r, "rescaled_hazard_0.2_1"))),
             line("rescaled t in [1, 5)", lambda m, r: _hazard_cell(
                 g(m, r, "rescaled_hazard_1_5"))),
             line("rescaled t > 5", lambda m, r: _hazard_cell(g(m, r, "rescaled_hazard_late"))),
             "", f"![hazard]({figures}/mechanism_hazard.png)", "",
             f"![rescaled hazard]({figures}/mechanism_hazard_normalised.png)", "",
             "**The hazard** (top, raw time, one y scale over the four panels; open black: "
             "all runs, red: sticky runs left out; the hyperexponential fit and the mixture "
             "over post-collision L are smooth laws that miss the data below t ≈ 10, the "
             "refractory dip and the wall round-trip peak, and follow them only beyond) and "
             "**the hazard after removing the rate differences** (bottom, the same y range "
             f"{NORMALISED_YLIM[0]:g}–{NORMALISED_YLIM[1]:g} under both rules: green, "
             "intervals in units of the run's own mean interval; blue, intervals times Γ of "
             "the state they start in), 95 % intervals.",
             "", "**Re-collisions** (at most one wall hit of each disk since the previous "
             "collision; sticky runs left out; bootstrap over runs) against randomly placed "
             "events at each run's rate (\"above chance\": the two 95 % intervals are "
             "disjoint):", "", head, sep,
             line("share", lambda m, r: _iv(g(m, r, "recollision_share_nonsticky"))),
             line("chance level", lambda m, r: _iv(
                 g(m, r, "recollision_share_poisson_null_nonsticky"))),
             line("verdict", lambda m, r: _above_chance(
                 g(m, r, "recollision_share_nonsticky"),
                 g(m, r, "recollision_share_poisson_null_nonsticky"))),
             "", "**The Poisson battery** (share of runs rejected at α = 0.05, "
             "Clopper–Pearson; dispersion index of the counts, bootstrap over ICs) and the "
             "share of its excess over a Poisson process that each twin model reproduces, "
             "(twin − Poisson) / (observed − Poisson), bootstrap over ICs; given only where "
             "the observed value's interval lies above the Poisson value (0.05, or 1 for the "
             "dispersion index), otherwise \"no excess to explain\":", "", head, sep,
             line("uniformity KS, observed", lambda m, r: _iv(
                 g(m, r, "observed_reject_uniformity_ks"))),
             line("exponential AD, observed", lambda m, r: _iv(
                 g(m, r, "observed_reject_exponential_ad"))),
             line("dispersion index (no sticky), observed", lambda m, r: _iv(
                 g(m, r, "observed_dispersion_index_nonsticky")))]
    for model, label in MODELS:
        for test, tlabel in TESTS:
            lines.append(line(f"explained, {tlabel}: {label}", lambda m, r, test=test,
                              model=model: _explained_cell(tab, m, r, test, model)))
    lines += ["", f"![battery]({figures}/mechanism_battery.png)", "",
              "**The Poisson battery on the twins** (bars: the twins' 95 % range over the "
              "ensembles; observed: Clopper–Pearson).", "", _carry(tab, groups, rule), ""]
    return lines


def _groups_of(tab):
    return [g for g in GROUPS if ((tab["method"] == g[0]) & (tab["radius"] == g[1])).any()]


def _count(tab, quantity, verdict):
    """``"k of n groups"`` whose ``quantity`` gets ``verdict`` from `ratio_verdict`."""
    groups = _groups_of(tab)
    k = sum(ratio_verdict(_get(tab, m, r, quantity)["ci_low"],
                          _get(tab, m, r, quantity)["ci_high"], MARGIN) == verdict
            for m, r in groups)
    return f"{k} of {len(groups)}"


def _share_sides(rows):
    """How many explained shares' 95 % intervals lie below 1, contain 1, lie above 1."""
    below = sum(x["ci_high"] < 1 for x in rows)
    above = sum(x["ci_low"] > 1 for x in rows)
    return f"CI below 1 in {below}, containing 1 in {len(rows) - below - above}, above 1 in {above}"


def _explained_range(tab, test, model):
    groups = [g for g in _groups_of(tab) if _excess(tab, *g, test)]
    rows = [_get(tab, m, r, f"explained_{test}_by_{model}") for m, r in groups]
    rows = [x for x in rows if math.isfinite(x["estimate"])]
    if not rows:
        return "no group with an excess"
    v = [x["estimate"] for x in rows]
    span = f"{v[0]:.2f}" if len(v) == 1 else f"{min(v):.2f}–{max(v):.2f}"
    return f"{span} ({len(v)} groups; {_share_sides(rows)})"


def summary(tabs):
    """The first table: what carries the non-Poisson statistics under each rule, as counts
    of groups whose verdict says so and ranges of explained shares."""
    rules = [t["rule"].iloc[0] for t in tabs]
    rows = [
        ("hazard minimum over t < 4 after a collision lower than the rate (refractory dip, "
         "wherever it falls)", lambda t: _count(t, "hazard_nonsticky_min_over_rate", "lower")),
        ("hazard in [0, 0.5) after a collision (the first bin alone) lower than the rate",
         lambda t: _count(t, "hazard_nonsticky_first_bin_over_rate", "lower")),
        ("re-collisions above chance", lambda t: str(sum(
            _above_chance(_get(t, m, r, "recollision_share_nonsticky"),
                          _get(t, m, r, "recollision_share_poisson_null_nonsticky"))
            == "above chance" for m, r in _groups_of(t))) + f" of {len(_groups_of(t))}"),
        ("Γ-rescaled hazard in [1, 5) within 10 % of 1",
         lambda t: _count(t, "rescaled_hazard_1_5", "within 10 %")),
        ("Γ-rescaled hazard beyond rescaled t = 5 lower than 1",
         lambda t: _count(t, "rescaled_hazard_late", "lower")),
    ]
    for test, label in TESTS:
        rows.append((f"explained out of sample (rate chain), {label}",
                     lambda t, test=test: _explained_range(t, test, "cox_markov_oos")))
        rows.append((f"explained in sample (run's own states), {label}",
                     lambda t, test=test: _explained_range(t, test, "cox_sequence")))
    lines = ["## What carries the non-Poisson statistics, per rule", "",
             "Counts of the four groups (IC family × radius) whose verdict, in the tables "
             "below, says so; explained shares only over the groups whose observed value "
             "lies above the Poisson value.", "",
             "| | " + " | ".join(f"{r} rule" for r in rules) + " |",
             "|---|" + "---|" * len(rules)]
    for label, fn in rows:
        lines.append(f"| {label} | " + " | ".join(fn(t) for t in tabs) + " |")
    return lines + ["", "A share is read as falling short of the excess only where its 95 % "
                    "interval lies below 1, and as overshooting it (the twins departing from "
                    "Poisson more often than the runs) only where the interval lies above 1; "
                    "an interval containing 1 does not tell either. In sample and out of "
                    "sample are two estimates side by side; neither bounds the other.", ""]


def _carry(tab, groups, rule):
    """What carries the non-Poisson statistics under this rule: sentences from the rows."""
    def rng(q, test=None):
        rows = [_get(tab, m, r, q) for m, r in groups
                if test is None or _excess(tab, m, r, test)]
        rows = [x for x in rows if math.isfinite(x["estimate"])]
        v = [x["estimate"] for x in rows]
        if not v:
            return "n/a (no group with an excess to explain)" if test else "n/a"
        n = (f" ({len(v)} of {len(groups)} groups with an excess; {_share_sides(rows)})"
             if test else "")
        return (f"{v[0]:.2f}" if len(v) == 1 else f"{min(v):.2f}–{max(v):.2f}") + n

    late = [_get(tab, m, r, "rescaled_hazard_late") for m, r in groups]
    late_v = {ratio_verdict(x["ci_low"], x["ci_high"], MARGIN) for x in late
              if math.isfinite(x["estimate"])} or {"no interval ends there"}
    first = [_get(tab, m, r, "hazard_nonsticky_first_bin_over_rate") for m, r in groups]
    first_v = {ratio_verdict(x["ci_low"], x["ci_high"], MARGIN) for x in first}
    low = [_get(tab, m, r, "hazard_nonsticky_min_over_rate") for m, r in groups]
    low_v = {ratio_verdict(x["ci_low"], x["ci_high"], MARGIN) for x in low}
    bins = sorted({x["note"] for x in low})
    return (f"Read from the rows above ({rule} rule): over t < 4 after a collision the "
            f"hazard falls to {rng('hazard_nonsticky_min_over_rate')} × the rate at its "
            f"minimum ({'; '.join(bins)}; verdicts: {', '.join(sorted(low_v))}); in the first "
            f"half time unit alone it is {rng('hazard_nonsticky_first_bin_over_rate')} × the "
            f"rate (verdicts: {', '.join(sorted(first_v))}); at rescaled t > 5 the Γ-rescaled "
            f"hazard is {rng('rescaled_hazard_late')} (verdicts: {', '.join(sorted(late_v))}). "
            "The Cox twins that replay each run's own states reproduce "
            f"{rng('explained_uniformity_ks_by_cox_sequence', 'uniformity_ks')} of the excess "
            "uniformity-KS rejections and "
            f"{rng('explained_exponential_ad_by_cox_sequence', 'exponential_ad')} of the "
            "excess exponential-AD rejections (in sample); the rate chain "
            "fitted on the other half of the ICs reproduces "
            f"{rng('explained_uniformity_ks_by_cox_markov_oos', 'uniformity_ks')} and "
            f"{rng('explained_exponential_ad_by_cox_markov_oos', 'exponential_ad')} (out "
            "of sample); each share's interval is in the table above.")


def sources(folders):
    """The page's closing table, per rule's folder in ``folders`` (relative to the page;
    which rules, and so which CSVs, is the run's): the columns of its
    ``mechanism_numbers.csv`` the page quotes and the functions that computed them. The
    rows the page quotes come from `analyse`, except the early hazard read bin by bin
    (its minimum, the bins below the rate), from `hazard_profile_rows`; the rows
    ``method == "run"`` are the run's sizes."""
    return tuple(Source(f"{folder}/mechanism_numbers.csv", "estimate, ci_low, ci_high, note",
                        fn) for folder in folders for fn in (analyse, hazard_profile_rows))


def write_page(tables, folders, path, *, command):
    """Write the page to ``path`` from the numbers ``tables`` of the rules, whose tables
    and figures lie in ``folders`` (relative to the page's folder, e.g.
    ``"mechanism/elastic"``); ``command`` is the one its "Generated" line names. The
    page closes with the table of its `sources`."""
    lines = header("Why the collision times are not Poisson: the mechanism, computed", command,
                   [f"the direct simulations of `kicktimes.studies.mechanism` under the "
                    f"{t['rule'].iloc[0]} rule ([table]({f}/mechanism_numbers.csv))"
                    for t, f in zip(tables, folders, strict=True)])
    lines += ["Definitions and methods: [../mechanism.md](../mechanism.md). Two radii "
              "(0.01, 0.02) × two IC families (the paper's, the invariant measure), the same "
              "ICs at both radii. Verdicts of a hazard against the rate it should equal: "
              f"{ratio_rule(MARGIN)}.", ""]
    lines += summary(tables)
    for tab, folder in zip(tables, folders, strict=True):
        lines += rule_section(tab, folder)
    return write_results_page(path, lines, sources(folders))
