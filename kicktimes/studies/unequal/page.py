"""``unequal.md``: the size-ratio table, a verdict beside every ratio."""

from __future__ import annotations

import pandas as pd

from kicktimes.render.pages import header, simulations_source
from kicktimes.render.provenance import Source
from kicktimes.stats import MARGIN, format_interval, poisson_group, ratio_rule, ratio_verdict
from kicktimes.studies.unequal.compute import KINDS, R0
from kicktimes.studies.unequal.tables import (
    dispersion_ci,
    ks_interval,
    ratio_ci,
    size_ratio_table,
)

__all__ = ["FIGURE", "SOURCES", "TABLE", "write_page"]

#: the table and the figure, relative to the page
TABLE = "size_ratio/size_ratio.csv"
FIGURE = "size_ratio/size_ratio.png"

#: the page's closing table: the columns it quotes and the functions that computed them
SOURCES = (
    Source(TABLE, "size_ratio", size_ratio_table),
    Source(TABLE, "rate_ratio, rate_low, rate_high", ratio_ci),
    Source(TABLE, ", ".join(f"ftle_{kind}_{part}_disk{disk}" for disk in (0, 1)
                            for kind in KINDS for part in ("ratio", "low", "high")), ratio_ci),
    Source(TABLE, "ks_reject_share, dispersion_index", poisson_group),
    Source(TABLE, "disp_low, disp_high", dispersion_ci),
)


def write_page(table, params, command, source):
    """The lines of ``unequal.md``: the size-ratio table (`size_ratio_table`) with a
    verdict beside every ratio; ``params`` the study's `Params`, ``source`` the name of its
    cache."""
    lines = header("Unequal disks: the size ratio", command,
                   [simulations_source("unequal", source, f"`{TABLE}`")])
    lines += [f"Definitions and methods: [../unequal.md](../unequal.md). Disk 0 keeps "
              f"r0 = {R0:g}; {params.n_ics} invariant ICs per ratio, {params.n_steps} steps of "
              f"{params.tau:g}, mirror rule; the kicked disk gets scattering kicks at Poisson "
              "times at its IC's own collision rate. Ratios of means with 95 % bootstrap "
              f"intervals over ICs; verdicts: {ratio_rule(MARGIN)}.", "",
              "The four FTLE columns are ratios of the **finite-time Lyapunov exponent** "
              "(tangent FTLE of the named disk, mean over ICs): the kicked disk's over the "
              "same disk's in the two-disk system, with the partner radius of the scattering "
              "kicks as named. KS rejections: share of the two-disk runs whose collision "
              "times reject uniformity at α = 0.05 (Clopper–Pearson interval; 0.05 for a "
              "Poisson process); dispersion: variance / mean of the collision counts over ICs "
              "(1 for a Poisson process), with a 95 % bootstrap interval over ICs"
              + ("" if "disp_low" in table else " where the per-IC counts are stored (not "
                 "for this table)") + ".", "",
              "| r1 / r0 | rate / Γ(r0, r1) | KS rejections | dispersion | small disk FTLE, "
              "partner r1 | own-size partner | large disk FTLE, partner r0 | own-size partner |",
              "|---|---|---|---|---|---|---|---|"]
    cols = [("ftle_partner_ratio_disk0", "ftle_partner_low_disk0", "ftle_partner_high_disk0"),
            ("ftle_own_ratio_disk0", "ftle_own_low_disk0", "ftle_own_high_disk0"),
            ("ftle_partner_ratio_disk1", "ftle_partner_low_disk1", "ftle_partner_high_disk1"),
            ("ftle_own_ratio_disk1", "ftle_own_low_disk1", "ftle_own_high_disk1")]

    def cell(row, c):
        return (f"{format_interval(row[c[0]], row[c[1]], row[c[2]])}, "
                f"{ratio_verdict(row[c[1]], row[c[2]], MARGIN)}")

    for _, row in table.iterrows():
        rate = cell(row, ("rate_ratio", "rate_low", "rate_high"))
        ks_lo, ks_hi = ks_interval(row, params.n_ics)
        disp = (format_interval(row["dispersion_index"], row["disp_low"], row["disp_high"],
                                edges=(1.0,)) if "disp_low" in row else
                f"{row['dispersion_index']:.1f} (no interval)")
        lines.append(f"| {row['size_ratio']:g} | {rate}"
                     f" | {100 * row['ks_reject_share']:.1f} % [{100 * ks_lo:.1f}, "
                     f"{100 * ks_hi:.1f}] | {disp} | "
                     + " | ".join(cell(row, c) for c in cols) + " |")
    lines.append("")
    for c, name in ((("rate_ratio", "rate_low", "rate_high"), "collision rate / kinetic rate"),
                    (cols[0], "small disk, partner of the other disk's size"),
                    (cols[2], "large disk, partner of the other disk's size")):
        v = [ratio_verdict(lo, hi, MARGIN) for lo, hi in zip(table[c[1]], table[c[2]],
                                                             strict=True)]
        counts = pd.Series(v).value_counts()
        odd = [f"ratio {x:g}: {vv}" for x, vv in zip(table["size_ratio"], v, strict=True)
               if vv != counts.index[0]]
        lines.append(f"- {name}: {counts.index[0]} at {counts.iloc[0]} of {len(v)} ratios"
                     + (f" (not at {', '.join(odd)})" if odd else "") + ".")
    lines += ["", f"![size ratio]({FIGURE})", ""]
    return lines
