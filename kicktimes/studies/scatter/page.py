"""``scatter.md``: the ratios of mean FTLE per radius, a verdict beside each."""

from __future__ import annotations

from kicktimes.render.pages import header
from kicktimes.render.provenance import Source
from kicktimes.stats import MARGIN, format_interval, ratio_verdict
from kicktimes.studies.scatter.tables import FINE_MARGIN, RATIOS, over_radii, ratio_table, sticky

__all__ = ["OVER_RADII", "SOURCES", "TABLE", "answers", "write_page"]

#: the page's tables, relative to the page
TABLE = "scatter_ratios.csv"
OVER_RADII = "scatter_over_radii.csv"

#: the page's closing table: the columns it quotes and the functions that computed them
SOURCES = (Source(TABLE, "estimate, ci_low, ci_high", ratio_table),
           Source(TABLE, "verdict", ratio_verdict),
           Source(OVER_RADII, "estimate, ci_low, ci_high, deficit, deficit_low, deficit_high, "
                  "robust, robust_fine", over_radii),
           Source(OVER_RADII, "verdict, verdict_fine", ratio_verdict))

#: what each answer line calls its ratio (`RATIOS`' labels)
_ANSWERS = ("scatter kicks / two disks", "partner tangent zeroed / two disks",
            "scatter kicks / partner tangent zeroed",
            "scatter kicks at the actual times / two disks", "uniform kicks / two disks")


def _reading(x):
    """A ratio's verdict at the fine margin, then at 10 %, and what a CI inside the band
    that excludes 1 measures."""
    text = f"{x.verdict_fine} at the {100 * FINE_MARGIN:g} % margin (10 % margin: {x.verdict})"
    if x.ci_low > 1 or x.ci_high < 1:
        side = "deficit" if x.ci_high < 1 else "excess"
        lo, hi = sorted((abs(1 - x.ci_low), abs(1 - x.ci_high)))
        text += f" (a real {side} of {100 * abs(1 - x.estimate):.1f} % [{100 * lo:.1f}, " \
                f"{100 * hi:.1f}]" + (", smaller than the 10 % margin)"
                                      if x.verdict.startswith("within") else ")")
    return text


def answers(over) -> list[str]:
    """The page's first screen: one line per ratio of `_ANSWERS` over the radii (without
    the sticky ICs), its verdict at both margins and its control (the sticky ICs)."""
    main = over[over["ics"] == "without sticky ICs"].set_index("ratio")
    other = over[over["ics"] == "all ICs"].set_index("ratio")
    edges = (1 - MARGIN, 1 - FINE_MARGIN, 1.0, 1 + FINE_MARGIN, 1 + MARGIN)
    lines = []
    for label in _ANSWERS:
        x, y = main.loc[label], other.loc[label]
        broken = [f"at {m} {b} with them" for m, ok, b in
                  ((f"{100 * FINE_MARGIN:g} %", x.robust_fine, y.verdict_fine),
                   ("10 %", x.robust, y.verdict)) if not ok]
        control = ("robust over the sticky ICs" if not broken else
                   f"depends on the sticky ICs ({'; '.join(broken)}: "
                   f"{format_interval(y.estimate, y.ci_low, y.ci_high, edges=edges)})")
        lines.append(f"- **{label[0].upper()}{label[1:]}** (FTLE, mean over {int(x.n_radii)} "
                     f"radii, {int(x.n_ics)} ICs): "
                     f"{format_interval(x.estimate, x.ci_low, x.ci_high, edges=edges)}, "
                     f"{_reading(x)}; {control}.")
    return lines


def _effect(over):
    x = over[(over["ics"] == "without sticky ICs")
             & (over["ratio"] == "partner tangent zeroed / two disks")].iloc[0]
    return (f"{100 * x.deficit:.1f} % [{100 * x.deficit_low:.1f}, "
            f"{100 * x.deficit_high:.1f}] of its exponent")


def write_page(df, tab, command, source, over):
    """The lines of ``scatter.md``: every number from ``df`` (the per-IC table,
    `scatter_runs` of every radius) through ``tab`` (its `ratio_table`) and ``over`` (its
    `over_radii`); ``source`` the name of the study's cache."""
    n_sticky = int(sticky(df).sum())
    lines = header("Scatter kicks against the two disks: the FTLE", command,
                   [f"the per-IC tables of `kicktimes.studies.scatter` (its cache `{source}`; "
                    f"family A's radii and first {df['ic'].nunique()} ICs; no store)"])
    lines += answers(over)
    lines += ["", f"Verdicts: a ratio is within {100 * MARGIN:g} % when its whole 95 % CI lies "
              f"in [{1 - MARGIN:g}, {1 + MARGIN:g}], higher / lower when wholly beyond, "
              "inconclusive otherwise; a CI inside the band that excludes 1 is a real "
              "difference smaller than the margin. The 10 % margin is not smaller than the "
              "effect this page means to resolve (zeroing the partner's tangent costs the two "
              f"disks {_effect(over)}), so every ratio is first read at a "
              f"{100 * FINE_MARGIN:g} % margin, stated in advance. Robust: the same verdict, "
              "and no CI on each side of 1, with and without the sticky ICs. Over radii: the "
              "mean of the per-radius ratios with a bootstrap "
              f"over ICs paired across radii (`{OVER_RADII}`).", ""]
    lines += [f"Definitions and methods: [../scatter.md](../scatter.md). Ratios of means over "
              "ICs with 95 % bootstrap intervals over ICs (`scatter_ratios.csv`). Sticky "
              "two-disk orbits (exponent below a quarter of the "
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
            f", {g.loc[x, 'verdict_fine']}" for x in labels) + " |")
    lines.append("")
    for label in labels:  # at the page's margin, FINE_MARGIN (the 10 % verdicts: the CSV)
        both = tab[tab["ratio"] == label]
        counts = main[main["ratio"] == label]["verdict_fine"].value_counts()
        changed = (both.pivot(index="radius", columns="ics", values="verdict_fine")
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
