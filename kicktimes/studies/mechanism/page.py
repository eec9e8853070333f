"""The page ``mechanism.md`` from the numbers tables of both collision rules.

Reads the ``mechanism_numbers.csv`` of each rule (`kicktimes.studies.mechanism.run`
writes them) and writes the page: at most five one-line answers first (`first_screen`),
then one table per rule (`rule_section`), every number from a row and every comparative
word from a verdict: `kicktimes.stats.ratio_verdict` for a hazard against the rate it
should equal, `kicktimes.stats.null_verdict` for the rate dispersion across ICs against
its Poisson null and for the early hazard against the hazard of Poisson streams at each
run's own rate (`analysis.against_null`), disjoint 95 % intervals for
"above chance". An inconclusive ratio names the size that would resolve it
(`kicktimes.stats.equivalence_sample_size`). The page closes with the table of where its
numbers come from (`sources`). Definitions and methods stay in docs/mechanism.md; the rows
the page does not quote (the hazard bin by bin, its peak, the iid twins, ...) are in the
CSVs it links.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from kicktimes.render.pages import header, write_results_page
from kicktimes.render.provenance import Source
from kicktimes.stats import (
    MARGIN,
    equivalence_sample_size,
    format_interval,
    null_reading,
    null_verdict,
    ratio_reading,
    ratio_verdict,
)
from kicktimes.studies.mechanism.analysis import (
    HAZARD_NULL_MARGIN,
    RATE_DISPERSION_MARGIN,
    against_null,
    analyse,
    hazard_profile_rows,
    poisson_null_rows,
)

__all__ = [
    "FIRST_SCREEN_MAX", "SHARE_HALF_WIDTH", "first_screen", "load", "needed_ics", "rule_section",
    "share_cell", "sources", "write_page",
]

GROUPS = (("paper", 0.01), ("paper", 0.02), ("uniform", 0.01), ("uniform", 0.02))
LABEL = {"paper": "paper ICs", "uniform": "invariant ICs"}
#: the explained shares the page quotes: (test, its label) x (model, its short label)
TESTS = (("uniformity_ks", "uniformity-KS rejections"),
         ("exponential_ad", "exponential-AD rejections"),
         ("rate_dispersion_across_ics_nonsticky", "rate dispersion across ICs"))
MODELS = (("cox_sequence", "in sample"), ("cox_markov_oos", "out of sample"))
#: the answers a page may open with before its first table
FIRST_SCREEN_MAX = 5
#: the name the page gives the var / mean of whole-run counts over ICs (not D in windows)
DISPERSION_NAME = "rate dispersion across ICs"
#: an explained share is stated only where its 95 % interval is at most twice this wide:
#: it then tells none of the excess from all of it (a share of 0 from one of 1)
SHARE_HALF_WIDTH = 0.5
#: the early hazard's first bin, named as such wherever it appears (not the README's
#: first bin in mean intervals, nor disks.md's)
FIRST_BIN = "hazard in [0, 0.5) time units after a collision"
Z95 = 1.959963984540054


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


def _groups_of(tab):
    return [g for g in GROUPS if ((tab["method"] == g[0]) & (tab["radius"] == g[1])).any()]


def _iv(row, edges=()):
    if not math.isfinite(row["estimate"]):
        return "n/a"
    if not (math.isfinite(row["ci_low"]) and math.isfinite(row["ci_high"])):
        return f"{row['estimate']:.3g}"
    return format_interval(row["estimate"], row["ci_low"], row["ci_high"], edges=edges)


def needed_ics(estimate, low, high, n, tolerance=MARGIN, center=1.0):
    """What an inconclusive ratio needs: ``"not resolved at this size; needs ≈ N ICs"``.

    N is `kicktimes.stats.equivalence_sample_size` with the standard error of the 95 %
    interval ``[low, high]`` at ``n`` ICs and, as margin, the distance of the estimate
    from the nearer band edge ``center ± tolerance`` (1 for a ratio, 0 for a difference
    from a null): the interval around the estimate must
    shrink to that distance to fall on one side of the edge (inside the band: "within";
    outside: "higher" or "lower"), at the measured estimate.

    Examples
    --------
    >>> needed_ics(1.0, 0.85, 1.15, 200)
    'not resolved at this size; needs ≈ 1231 ICs'
    >>> needed_ics(0.8, 0.55, 1.05, 200)
    'not resolved at this size; needs ≈ 3420 ICs'
    >>> needed_ics(1.1, 1.0, 1.2, 200)
    'not resolved at this size: the estimate lies on the band edge 1.1'
    """
    if not (isinstance(n, int) and n >= 1):
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    room = abs(tolerance - abs(float(estimate) - center))
    if room < 1e-9:
        edge = center + tolerance if estimate > center else center - tolerance
        return f"not resolved at this size: the estimate lies on the band edge {edge:g}"
    se = (float(high) - float(low)) / (2 * Z95)
    return f"not resolved at this size; needs ≈ {equivalence_sample_size(se, n, margin=room)} ICs"


def _ratio_cell(row, n):
    """A hazard over the rate it should equal (1), with its `ratio_verdict`; an
    inconclusive one with the size that would resolve it."""
    if not math.isfinite(row["estimate"]):
        return "no interval ends there"
    verdict = ratio_reading(row["ci_low"], row["ci_high"], tolerance=MARGIN)
    cell = f"{_iv(row, (0.9, 1.0, 1.1))}, {verdict}"
    if verdict == "inconclusive":
        cell += f" ({needed_ics(row['estimate'], row['ci_low'], row['ci_high'], n)})"
    return cell


def _hazard_null_cell(tab, m, r, stat, diff_name, n):
    """An early hazard over the rate beside its Poisson null, with `null_verdict` on the
    difference; an inconclusive one with the size that would resolve it."""
    row, diff = _get(tab, m, r, stat), _get(tab, m, r, diff_name)
    null = row["estimate"] - diff["estimate"]
    verdict = null_reading(diff["ci_low"], diff["ci_high"], margin=HAZARD_NULL_MARGIN)
    cell = f"{_iv(row, (0.9, 1.0, 1.1))} vs {null:.3f}: {verdict}"
    if verdict == "inconclusive":
        need = needed_ics(diff["estimate"], diff["ci_low"], diff["ci_high"], n,
                          HAZARD_NULL_MARGIN, center=0.0)
        cell += f" ({need})"
    return cell


def _above_chance(share, chance):
    if share["ci_low"] > chance["ci_high"]:
        return "above chance"
    if share["ci_high"] < chance["ci_low"]:
        return "below chance"
    return "not distinguished from chance (intervals overlap)"


def _dispersion_verdict(tab, m, r, *, strict=True):
    """`null_verdict` of the rate dispersion across ICs minus its null (``strict``), or
    its `null_reading` (an inconclusive interval that excludes 0 read as a departure)."""
    row = _get(tab, m, r, "rate_dispersion_minus_null")
    read = null_verdict if strict else null_reading
    return read(row["ci_low"], row["ci_high"], margin=RATE_DISPERSION_MARGIN)


def _excess(tab, m, r, test):
    """Whether the observed value lies above its null (an excess to explain; a gap
    inside its own noise is not decomposed): a rejection share's interval above the
    exact tests' level 0.05, the rate dispersion across ICs "above its null"."""
    if test == "rate_dispersion_across_ics_nonsticky":
        return _dispersion_verdict(tab, m, r) == "above its null"
    return bool(_get(tab, m, r, f"observed_reject_{test}")["ci_low"] > 0.05)


def share_cell(row, n):
    """An explained share with its interval where that interval is at most
    2 :data:`SHARE_HALF_WIDTH` wide; else ``"not resolved at this size; needs ≈ N ICs"``
    (the share is not stated: a gap inside its own noise is not decomposed), N from
    `kicktimes.stats.equivalence_sample_size` at the interval's standard error with
    margin :data:`SHARE_HALF_WIDTH`.

    >>> share_cell({"estimate": 0.41, "ci_low": 0.336, "ci_high": 0.498}, 200)
    '0.410 [0.336, 0.498]'
    >>> share_cell({"estimate": 1.69, "ci_low": 0.875, "ci_high": 12.4}, 200)
    'not resolved at this size; needs ≈ 72663 ICs'
    """
    if not (math.isfinite(row["ci_low"]) and math.isfinite(row["ci_high"])):
        return "not resolved at this size (no interval)"
    width = row["ci_high"] - row["ci_low"]
    if width <= 2 * SHARE_HALF_WIDTH:
        return _iv(row, (1.0,))
    se = width / (2 * Z95)
    return (f"not resolved at this size; needs ≈ "
            f"{equivalence_sample_size(se, n, margin=SHARE_HALF_WIDTH)} ICs")


def _share_iv(tab, m, r, test, model, n):
    if not _excess(tab, m, r, test):
        return "no excess"
    return share_cell(_get(tab, m, r, f"explained_{test}_by_{model}"), n)


def rule_section(tab, figures):
    """The section of one rule: its sizes, one table (rows: quantities; columns: the
    groups) and its three figures; ``figures`` is its folder relative to the page."""
    rule = tab["rule"].iloc[0]
    run = tab[tab["method"] == "run"].set_index("quantity")["estimate"]
    n = int(run["n_ics"])
    groups = _groups_of(tab)
    g = lambda m, r, q: _get(tab, m, r, q)  # noqa: E731

    def line(label, fn):
        return f"| {label} | " + " | ".join(fn(m, r) for m, r in groups) + " |"

    def chance(m, r):
        s, c = g(m, r, "recollision_share_nonsticky"), g(
            m, r, "recollision_share_poisson_null_nonsticky")
        return f"{_iv(s)} vs {_iv(c)}: {_above_chance(s, c)}"

    def dispersion(m, r):
        obs, null = g(m, r, "observed_rate_dispersion_across_ics_nonsticky"), g(
            m, r, "rate_dispersion_poisson_null")
        diff = g(m, r, "rate_dispersion_minus_null")
        return (f"{_iv(obs)} vs {null['estimate']:.3f}: "
                f"{_dispersion_verdict(tab, m, r, strict=False)} "
                f"(difference {_iv(diff, (0.0,))})")

    lines = [f"## The {rule} rule", "",
             f"{n} ICs per group, `t_max = {run['t_max']:g}`, {int(run['twins'])} twin "
             f"ensembles per model, seed {int(run['seed'])}; collisions per group: "
             + ", ".join(f"{int(g(m, r, 'n_collisions')['estimate'])}" for m, r in groups)
             + ".", "",
             "| | " + " | ".join(f"{LABEL[m]}, r = {r:g}" for m, r in groups) + " |",
             "|---|" + "---|" * len(groups),
             line(f"{FIRST_BIN} / rate vs its Poisson null", lambda m, r:
                  _hazard_null_cell(tab, m, r, "hazard_nonsticky_first_bin_over_rate",
                                    "hazard_first_bin_minus_null", n)),
             line("hazard minimum over t < 4 / rate vs its Poisson null", lambda m, r:
                  _hazard_null_cell(tab, m, r, "hazard_nonsticky_min_over_rate",
                                    "hazard_min_minus_null", n)
                  + f" ({g(m, r, 'hazard_nonsticky_min_over_rate')['note']} time units)"),
             line("Γ-rescaled hazard, t in [1, 5)", lambda m, r: _ratio_cell(
                 g(m, r, "rescaled_hazard_1_5"), n)),
             line("Γ-rescaled hazard, t > 5", lambda m, r: _ratio_cell(
                 g(m, r, "rescaled_hazard_late"), n)),
             line("re-collision share vs chance", chance),
             line(f"{DISPERSION_NAME} vs its Poisson null", dispersion)]
    for test, label in TESTS:
        lines.append(line(f"explained share of the excess {label}, in / out of sample",
                          lambda m, r, test=test: " / ".join(
                              _share_iv(tab, m, r, test, model, n) for model, _ in MODELS)))
    lines += ["", f"![hazard]({figures}/mechanism_hazard.png)", "",
              f"![rescaled hazard]({figures}/mechanism_hazard_normalised.png)", "",
              f"![battery]({figures}/mechanism_battery.png)", ""]
    return lines


def _cases(tabs, quantity):
    """Every (rule, method, r, row) of ``quantity`` over the rules' tables."""
    return [(t["rule"].iloc[0], m, r, _get(t, m, r, quantity)) for t in tabs
            for m, r in _groups_of(t)]


def _finite(cases):
    """The cases whose row has a finite estimate and interval (a group where no interval
    ends in the bin has none)."""
    return [c for c in cases if all(math.isfinite(c[3][k])
                                     for k in ("estimate", "ci_low", "ci_high"))]


def _where(rule, m, r):
    return f"{rule}, {LABEL[m]}, r = {r:g}"


def _tally(tabs, verdict_of, wanted):
    """``"in k of n groups under both rules"`` when every group gets ``wanted``, else
    ``"depends on the rule: mirror k of n, elastic ..."``; and whether all agree."""
    per = {t["rule"].iloc[0]: [verdict_of(t, m, r) for m, r in _groups_of(t)] for t in tabs}
    total = sum(len(v) for v in per.values())
    hits = sum(v.count(wanted) for v in per.values())
    if hits == total:
        return f"in {hits} of {total} groups, both rules", True
    return "in " + ", ".join(f"{rule} {v.count(wanted)} of {len(v)}" for rule, v in
                             per.items()) + " groups (depends on the rule)", False


def first_screen(tabs):
    """The page's opening: at most :data:`FIRST_SCREEN_MAX` one-line answers, each one
    number with its 95 % interval, where it comes from and its caveat."""
    def ratio_of(q):
        return lambda t, m, r: ratio_verdict(_get(t, m, r, q)["ci_low"],
                                             _get(t, m, r, q)["ci_high"], tolerance=MARGIN)

    lines = []
    # 1. the refractory dip: the weakest group is the one whose upper end is highest
    def null_of(name, margin):
        return lambda t, m, r: null_verdict(_get(t, m, r, name)["ci_low"],
                                            _get(t, m, r, name)["ci_high"], margin=margin)

    said, _ = _tally(tabs, null_of("hazard_min_minus_null", HAZARD_NULL_MARGIN),
                     "below its null")
    rule, m, r, diff = max(_finite(_cases(tabs, "hazard_min_minus_null")),
                           key=lambda c: c[3]["ci_high"])
    t = next(t for t in tabs if t["rule"].iloc[0] == rule)
    row = _get(t, m, r, "hazard_nonsticky_min_over_rate")
    lines.append(f"- **Refractory dip**: the hazard's minimum over t < 4 after a collision, "
                 f"over the rate, lies below its Poisson null {said}; weakest "
                 f"{_iv(row, (0.9, 1.0, 1.1))} against "
                 f"{row['estimate'] - diff['estimate']:.3f} ({_where(rule, m, r)}, "
                 f"{row['note']} time units); caveat: the interval is that bin's own, not "
                 "adjusted for picking the lowest of 7 bins.")
    # 2. re-collisions against randomly placed events
    def chance_of(t, m, r):
        return _above_chance(_get(t, m, r, "recollision_share_nonsticky"),
                             _get(t, m, r, "recollision_share_poisson_null_nonsticky"))
    said, all_above = _tally(tabs, chance_of, "above chance")
    above = [c for c in _cases(tabs, "recollision_share_nonsticky")
             if chance_of(next(t for t in tabs if t["rule"].iloc[0] == c[0]), c[1], c[2])
             == "above chance"]
    if above:
        rule, m, r, row = min(above, key=lambda c: c[3]["ci_low"])
        t = next(t for t in tabs if t["rule"].iloc[0] == rule)
        null = _get(t, m, r, "recollision_share_poisson_null_nonsticky")
        others = sorted({chance_of(t2, m2, r2) for t2 in tabs for m2, r2 in _groups_of(t2)}
                        - {"above chance"})
        lines.append(f"- **Re-collisions** (after at most one wall hit each): above chance "
                     f"{said}; weakest {_iv(row)} against chance {_iv(null)} "
                     f"({_where(rule, m, r)})"
                     + ("" if all_above else f"; the other groups: {', '.join(others)}")
                     + "; caveat: chance is randomly placed events at each run's rate.")
    # 3. the long intervals the state's rate misses
    q = "rescaled_hazard_late"
    said, _ = _tally(tabs, ratio_of(q), "lower")
    found = _finite(_cases(tabs, q))
    closest = "no interval ends there in any group"
    if found:
        rule, m, r, row = max(found, key=lambda c: c[3]["ci_high"])
        closest = f"closest to 1: {_iv(row, (0.9, 1.0, 1.1))} ({_where(rule, m, r)})"
    lines.append(f"- **Long waits**: the Γ-rescaled hazard beyond rescaled t = 5 (1 if each "
                 f"state's predicted rate held) lies below 1 {said}; {closest}; caveat: "
                 "Garwood intervals treat the pooled intervals as independent.")
    # 4. the rate dispersion across ICs against its Poisson null
    said, _ = _tally(tabs, lambda t, m, r: _dispersion_verdict(t, m, r), "above its null")
    rule, m, r, row = min(_finite(_cases(tabs, "rate_dispersion_minus_null")),
                          key=lambda c: c[3]["ci_low"])
    t = next(t for t in tabs if t["rule"].iloc[0] == rule)
    null = _get(t, m, r, "rate_dispersion_poisson_null")
    name = DISPERSION_NAME[0].upper() + DISPERSION_NAME[1:]
    lines.append(f"- **{name}** (var / mean of the whole-run counts over ICs): above its "
                 f"Poisson null {said}; smallest excess "
                 f"{_iv(row, (0.0,))} over the null {null['estimate']:.3f} "
                 f"({_where(rule, m, r)}); caveat: a spread of rates between ICs, not the "
                 "within-run D of counts in windows.")
    # 5. how much of the excess AD rejections the in-sample Cox twins reproduce
    test, model = "exponential_ad", "cox_sequence"
    parts = []
    for tb in tabs:
        rows = [(m, r, _get(tb, m, r, f"explained_{test}_by_{model}"))
                for m, r in _groups_of(tb) if _excess(tb, m, r, test)]
        short = [x for x in rows if x[2]["ci_high"] < 1]
        loose = [x for x in rows if x not in short and not (
            x[2]["ci_high"] - x[2]["ci_low"] <= 2 * SHARE_HALF_WIDTH)]
        if rows and len(short) == len(rows):
            m, r, row = max(short, key=lambda x: x[2]["estimate"])
            parts.append(f"{tb['rule'].iloc[0]}: short of it in {len(short)} of {len(rows)} "
                         f"groups, at most {_iv(row, (1.0,))} ({LABEL[m]}, r = {r:g})")
        elif rows:
            n = int(tb[tb["method"] == "run"].set_index("quantity")["estimate"]["n_ics"])
            widest = max(loose or rows, key=lambda x: x[2]["ci_high"] - x[2]["ci_low"])[2]
            said = (f"the share not resolved at this size in {len(loose)} of {len(rows)} "
                    "groups with an excess (the widest "
                    + share_cell(widest, n).removeprefix("not resolved at this size; ")
                    + ")" if loose else f"resolved in {len(rows)} of {len(rows)} groups "
                    f"with an excess, widest {share_cell(widest, n)}")
            parts.append(f"{tb['rule'].iloc[0]}: {said}; short of it (interval below 1) "
                         f"in {len(short)} of {len(rows)}")
        else:
            parts.append(f"{tb['rule'].iloc[0]}: no group with an excess")
    lines.append("- **Cox twins** replaying each run's own states, share of the excess "
                 "exponential-AD rejections they reproduce: " + "; ".join(parts)
                 + "; caveat: in sample (out of sample in the tables).")
    if len(lines) > FIRST_SCREEN_MAX:
        raise ValueError(f"first_screen: {len(lines)} answers, at most {FIRST_SCREEN_MAX}")
    return lines + [""]


def _null_gap(tabs):
    """The largest distance of the rate dispersion's Poisson null from 1 over the groups."""
    return max(abs(row["estimate"] - 1) for *_, row in _cases(
        tabs, "rate_dispersion_poisson_null"))


def reading(tabs):
    """How the verdicts are read, once (the rules are those of docs/definitions.md)."""
    return [
        "How to read it: an early hazard is over the group's pooled rate (sticky runs left "
        "out) and read against the same on Poisson streams at each run's own rate (above 1 "
        "where rates differ; `null_verdict`, margin "
        f"{HAZARD_NULL_MARGIN:g}); a Γ-rescaled hazard is read against 1, its prediction, "
        f"by `ratio_verdict` ({100 * MARGIN:g} % band, [definitions](../definitions.md)); "
        "an inconclusive interval that excludes the null value reads \"above (below) its null "
        "(1), size unresolved\", a real departure; one that contains it "
        "names the ICs that would resolve it (`equivalence_sample_size`). The first bin of "
        f"the early hazard is the {FIRST_BIN} (not the README's bin in mean intervals, nor "
        f"disks.md's). The {DISPERSION_NAME} is read against "
        "its Poisson null, the same statistic on Poisson ensembles of the same design "
        f"(`null_verdict`, margin {RATE_DISPERSION_MARGIN:g}); that null lies within "
        f"{_null_gap(tabs):.2g} of 1, the base of its explained share (twin − 1) / "
        "(observed − 1); a rejection share's base is the exact tests' 0.05. A share is "
        "given only where there is an excess and its interval is at most "
        f"{2 * SHARE_HALF_WIDTH:g} wide (else \"not resolved\" with the ICs that would resolve "
        "it), and read as short of it only where its interval lies below 1. "
        "Re-collisions: \"above chance\" when the two intervals are "
        "disjoint. Every row, the hazard bin by bin and the iid twins are in the tables "
        "linked above; definitions: [../mechanism.md](../mechanism.md).", ""]


def sources(folders):
    """The page's closing table, per rule's folder in ``folders`` (relative to the page;
    which rules, and so which CSVs, is the run's): the columns of its
    ``mechanism_numbers.csv`` the page quotes and the functions that computed them: the
    rows of `analyse`; the early hazard read bin by bin (its minimum) from
    `hazard_profile_rows`; the Poisson null of the rate dispersion across ICs from
    `poisson_null_rows` and the differences from them from `against_null`.
    The rows ``method == "run"`` are the run's sizes."""
    fns = (analyse, hazard_profile_rows, poisson_null_rows, against_null)
    return tuple(Source(f"{folder}/mechanism_numbers.csv", "estimate, ci_low, ci_high, note",
                        fn) for folder in folders for fn in fns)


def write_page(tables, folders, path, *, command):
    """Write the page to ``path`` from the numbers ``tables`` of the rules, whose tables
    and figures lie in ``folders`` (relative to the page's folder, e.g.
    ``"mechanism/elastic"``); ``command`` is the one its "Generated" line names. The
    page opens with `first_screen` and closes with the table of its `sources`."""
    lines = header("Why the collision times are not Poisson: hazard, re-collisions, twins",
                   command,
                   [f"the direct simulations of `kicktimes.studies.mechanism` under the "
                    f"{t['rule'].iloc[0]} rule ([table]({f}/mechanism_numbers.csv))"
                    for t, f in zip(tables, folders, strict=True)])
    lines += first_screen(tables)
    lines += reading(tables)
    for tab, folder in zip(tables, folders, strict=True):
        lines += rule_section(tab, folder)
    lines += ["Figures: the hazard in raw time (open: all runs, red: sticky runs left out; "
              "the smooth laws miss the dip and the wall round-trip peak below t ≈ 10), the "
              "hazard after removing the rate differences (one y range under both rules) "
              "and the battery on the twins (bars: 95 % range over the ensembles); 95 % "
              "intervals throughout.", ""]
    return write_results_page(path, lines, sources(folders))
