"""``scatter.md``: the ratios of mean FTLE per radius, a verdict beside each."""

from __future__ import annotations

from kicktimes.render.pages import header
from kicktimes.render.provenance import Source
from kicktimes.stats import format_interval, ratio_rule, ratio_verdict
from kicktimes.studies.scatter.tables import RATIOS, ratio_table, sticky

__all__ = ["SOURCES", "TABLE", "write_page"]

#: the page's table, relative to the page
TABLE = "scatter_ratios.csv"

#: the page's closing table: the columns it quotes and the functions that computed them
SOURCES = (Source(TABLE, "estimate, ci_low, ci_high", ratio_table),
           Source(TABLE, "verdict", ratio_verdict))


def write_page(df, tab, command, source):
    """The lines of ``scatter.md``: every number from ``df`` (the per-IC table,
    `scatter_runs` of every radius) through ``tab`` (its `ratio_table`); ``source`` the
    name of the study's cache."""
    n_sticky = int(sticky(df).sum())
    lines = header("Scatter kicks against the two disks: the FTLE", command,
                   [f"the per-IC tables of `kicktimes.studies.scatter` (its cache `{source}`; "
                    f"family A's radii and first {df['ic'].nunique()} ICs; no store)"])
    lines += [f"Definitions and methods: [../scatter.md](../scatter.md). Ratios of means over "
              "ICs with 95 % bootstrap intervals over ICs (`scatter_ratios.csv`); verdicts: "
              f"{ratio_rule(0.1)}. Sticky two-disk orbits (exponent below a quarter of the "
              f"radius's median): {n_sticky} (radius, IC) runs, left out in the "
              "table; the control with them is in the CSV. The scatter-kick / two-disk "
              "ratio of [science.md](science.md), section 1, is the same quantity (mean FTLE "
              "of the kicked disk over the mean two-disk FTLE, ratio of means over ICs) on "
              "another sample: 100 paper ICs drawn with seed 11 (the FTLE sweep "
              "`stretching_small_r`), its own kick draws, all ICs kept; here the first "
              f"{df['ic'].nunique()} paper ICs drawn with seed 1, sticky orbits left out. At a "
              "radius both pages measure, their intervals differ by the sample and the "
              "sticky orbits, not by the definition.", ""]
    main = tab[tab["ics"] == "without sticky ICs"]
    labels = [label for _, _, label in RATIOS]
    lines += ["| r | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for r, g in main.groupby("radius", observed=True):
        g = g.set_index("ratio")
        lines.append(f"| {r:g} | " + " | ".join(
            f"{format_interval(g.loc[x, 'estimate'], g.loc[x, 'ci_low'], g.loc[x, 'ci_high'])}"
            f", {g.loc[x, 'verdict']}" for x in labels) + " |")
    lines.append("")
    for label in labels:
        both = tab[tab["ratio"] == label]
        counts = main[main["ratio"] == label]["verdict"].value_counts()
        changed = (both.pivot(index="radius", columns="ics", values="verdict")
                   .nunique(axis=1) > 1).sum()
        lines.append(f"- {label}: " + ", ".join(
            f"{v} at {k} radi{'us' if k == 1 else 'i'}"
            for v, k in zip(counts.index, counts.to_numpy(), strict=True))
                     + f" (range {main[main['ratio'] == label]['estimate'].min():.3f}–"
                     f"{main[main['ratio'] == label]['estimate'].max():.3f}); the sticky ICs "
                     f"change the verdict at {changed} of {main['radius'].nunique()} radii.")
    fresh = main[main["ratio"] == labels[3]]["estimate"]
    gap = main[main["ratio"] == labels[0]]["estimate"]
    lines += ["", "**What the zeroed partner tangent measures.** The fourth column runs the "
              "real two-disk trajectory but sets the partner disk's tangent vector to zero "
              "just before every disk-disk collision: the deviation the partner carries into "
              "a collision (built up in its earlier collisions with the tracked disk and its "
              "flights since) is removed at every collision. It measures the exponent carried "
              "by the partner's tangent memory, not the re-collisions (returns within one wall "
              "round trip, [../mechanism.md](../mechanism.md)); zeroing changes the exponent to "
              f"{fresh.min():.3f}–{fresh.max():.3f} of the two-disk value, while the scatter "
              f"kicks reach {gap.min():.3f}–{gap.max():.3f}. The scatter kicks' gap is not "
              "decomposed here.", ""]
    return lines
