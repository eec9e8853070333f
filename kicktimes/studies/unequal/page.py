"""``unequal.md``: the size-ratio table, a verdict beside every ratio."""

from __future__ import annotations

import pandas as pd

from kicktimes.experiment import preset
from kicktimes.render.pages import header, simulations_source
from kicktimes.render.provenance import Source
from kicktimes.stats import (
    MARGIN,
    clopper_pearson,
    format_interval,
    null_reading,
    null_verdict,
    poisson_group,
    ratio_reading,
    rejection_verdict,
)
from kicktimes.studies.unequal.compute import KINDS, R0
from kicktimes.studies.unequal.tables import (
    D_MARGIN,
    FINE_MARGIN,
    KS_NULL_STREAMS,
    RATE_MARGIN,
    dispersion_ci,
    dispersion_null,
    ks_interval,
    ks_null,
    ratio_ci,
    size_ratio_table,
)

__all__ = ["DISPERSION_NAME", "FIGURE", "SOURCES", "TABLE", "answers", "write_page"]

#: the page's name of the var / mean of whole-run counts over ICs (the CSV's
#: ``dispersion_index``, ``d_null``, ``d_minus_null``): not the README's within-run D of
#: counts in windows, nor disks.md's D across tagged disks
DISPERSION_NAME = "rate dispersion across ICs"

#: the table and the figure, relative to the page
TABLE = "size_ratio/size_ratio.csv"
FIGURE = "size_ratio/size_ratio.png"

#: the page's closing table: the columns it quotes and the functions that computed them
SOURCES = tuple(Source(TABLE, columns, computed_by) for columns, computed_by in (
    ("size_ratio", size_ratio_table),
    ("rate_ratio, rate_low, rate_high", ratio_ci),
    (", ".join(f"ftle_{kind}_{part}_disk{disk}" for disk in (0, 1) for kind in KINDS
               for part in ("ratio", "low", "high")), ratio_ci),
    ("ks_reject_share, dispersion_index", poisson_group),
    ("disp_low, disp_high", dispersion_ci),
    ("d_null, d_null_low, d_null_high", dispersion_null),
    ("d_minus_null, d_minus_null_low, d_minus_null_high", size_ratio_table),
    ("d_verdict", null_verdict),
    ("ks_low, ks_high", clopper_pearson),
    ("ks_null, ks_null_low, ks_null_high", ks_null),
    ("ks_verdict", rejection_verdict),
))

#: the FTLE columns of the table: (estimate, low, high) per disk and partner
_FTLE = [(f"ftle_{kind}_ratio_disk{d}", f"ftle_{kind}_low_disk{d}", f"ftle_{kind}_high_disk{d}")
         for d in (0, 1) for kind in KINDS]


def _at(table, column, pick):
    """The row of ``table`` where ``column`` is smallest (``pick="min"``) or largest."""
    k = table[column].idxmin() if pick == "min" else table[column].idxmax()
    return table.loc[k]


def _fine(lo, hi):
    """`ratio_reading` at :data:`FINE_MARGIN`, naming that margin once."""
    said = ratio_reading(lo, hi, tolerance=FINE_MARGIN)
    return said if "margin" in said else f"{said} at the {100 * FINE_MARGIN:g} % margin"


def _ftle(row, c):
    lo, hi = row[c[1]], row[c[2]]
    text = (f"{format_interval(row[c[0]], lo, hi, edges=(0.9, 0.95, 1.0, 1.05, 1.1))}, "
            f"{_fine(lo, hi)} (10 %: {ratio_reading(lo, hi, tolerance=MARGIN)})")
    if hi < 1 or lo > 1:
        text += (f", a real {'deficit' if hi < 1 else 'excess'} of "
                 f"{100 * abs(1 - row[c[0]]):.1f} %")
    return text


def _apart(row, a, b):
    return bool(row[a[2]] < row[b[1]] or row[b[2]] < row[a[1]])


def _d_cell(row):
    if "d_minus_null" not in row:
        return "n/a"
    text = format_interval(row["d_minus_null"], row["d_minus_null_low"],
                           row["d_minus_null_high"], edges=())
    reading = null_reading(row['d_minus_null_low'], row['d_minus_null_high'], margin=D_MARGIN)
    return f"{text}, {reading}"


def _ks_design_caveat(params) -> str:
    """The KS answer's caveat: this page's design beside the README's (family A's), whose
    share differs by design, as the test's power grows with the collisions per run."""
    fam = preset("family_a")
    return (f"; caveat: {params.n_ics} invariant ICs per ratio over {params.n_steps} steps of "
            f"{params.tau:g}, not the README's share (family A: {fam.n_ics} {fam.ic_method} "
            f"ICs at each of {len(fam.radii)} radii, {fam.n_steps} steps of {fam.tau:g}): the "
            "runs hold other numbers of collisions, and the test's power grows with them")


def answers(table, params=None) -> list[str]:
    """The page's first screen: at most five one-line answers, each one number with its
    95 % interval, its verdict against its own null and its caveat; ``params`` (the
    study's `Params`) adds the KS answer's design caveat."""
    n = len(table)

    def count(verdicts):
        return ", ".join(f"{k} at {v}" for k, v in pd.Series(verdicts).value_counts().items())

    rate_v = [ratio_reading(lo, hi, tolerance=RATE_MARGIN)
              for lo, hi in zip(table["rate_low"], table["rate_high"], strict=True)]
    rate_v_wide = [ratio_reading(lo, hi, tolerance=MARGIN)
                   for lo, hi in zip(table["rate_low"], table["rate_high"], strict=True)]
    worst = table.loc[(table["rate_ratio"] - 1).abs().idxmax()]
    ks = _at(table, "ks_reject_share", "min")
    d = _at(table, "d_minus_null", "min")
    large = table.iloc[-1]
    d_reads = [null_reading(lo, hi, margin=D_MARGIN) for lo, hi in zip(
        table["d_minus_null_low"], table["d_minus_null_high"], strict=True)]
    small_v = [ratio_reading(lo, hi) for lo, hi in zip(table[_FTLE[0][1]], table[_FTLE[0][2]],
                                                        strict=True)]
    return [
        f"- **Collision rate / kinetic Γ(r0, r1)** at r1 / r0 = {worst.size_ratio:g} (the "
        f"furthest from 1): {format_interval(worst.rate_ratio, worst.rate_low, worst.rate_high)}"
        f"; at ±{100 * RATE_MARGIN:g} %: {count(rate_v)} of {n} ratios"
        + (": kinetic theory holds for unequal disks." if all(
            v.startswith("within") for v in rate_v) else
           f"; caveat: at ±{100 * MARGIN:g} % {count(rate_v_wide)} of {n}, so kinetic "
           f"theory holds to {100 * MARGIN:g} % but is not confirmed to "
           f"{100 * RATE_MARGIN:g} % at this size."),
        f"- **KS rejections of uniform collision times** at r1 / r0 = {ks.size_ratio:g} (the "
        f"fewest): {100 * ks.ks_reject_share:.1f} % [{100 * ks.ks_low:.1f}, "
        f"{100 * ks.ks_high:.1f}] of runs against its null streams' "
        + (f"{100 * ks.ks_null:.1f} % [{100 * ks.ks_null_low:.1f}, {100 * ks.ks_null_high:.1f}]"
           if "ks_null" in table else "α = 0.05")
        + f" (Poisson at each run's rate and window, the same test): "
        f"{count(table['ks_verdict'])} of {n} ratios"
        + (_ks_design_caveat(params) if params is not None else "") + ".",
        f"- **{DISPERSION_NAME[0].upper()}{DISPERSION_NAME[1:]} − its null** (var / mean "
        f"of the whole-run counts over ICs) at r1 / r0 = {d.size_ratio:g} (the smallest): "
        f"{format_interval(d.d_minus_null, d.d_minus_null_low, d.d_minus_null_high, edges=())} "
        f"({format_interval(d.dispersion_index, d.disp_low, d.disp_high, edges=(1.0,))}, "
        f"null {d.d_null:.3f}, Poisson counts over the same runs): "
        f"{count(d_reads)} of {n} ratios; caveat: a spread of rates between ICs, not the "
        "within-run D of counts in windows.",
        f"- **Small disk's FTLE, kicked / two disks** at r1 / r0 = {large.size_ratio:g}: "
        f"{_ftle(large, _FTLE[0])}; caveat: at the 10 % margin {count(small_v)} of {n} ratios.",
        f"- **Large disk's FTLE, kicked / two disks, by the partner radius** at r1 / r0 = "
        f"{large.size_ratio:g}: with the other disk as scattering partner {_ftle(large, _FTLE[2])}"
        f", with an own-size partner {format_interval(*(large[c] for c in _FTLE[3]))}, "
        f"{_fine(large[_FTLE[3][1]], large[_FTLE[3][2]])}" + (
            ": the two partners' intervals lie apart." if _apart(large, _FTLE[2], _FTLE[3])
            else "; the two partners' intervals overlap."),
    ]


def write_page(table, params, command, source):
    """The lines of ``unequal.md``: the size-ratio table (`size_ratio_table`) with a
    verdict beside every ratio; ``params`` the study's `Params`, ``source`` the name of its
    cache."""
    lines = header("Unequal disks: the size ratio", command,
                   [simulations_source("unequal", source, f"`{TABLE}`")])
    lines += answers(table, params)
    lines += ["", f"Verdicts: a ratio is within {100 * MARGIN:g} % when its whole 95 % CI lies "
              f"in [{1 - MARGIN:g}, {1 + MARGIN:g}], higher / lower when wholly beyond, "
              "inconclusive otherwise; a CI that excludes 1 but crosses a band edge reads "
              "\"below (above) 1, size unresolved\", a real difference; the "
              "FTLE ratios are first read at the FTLE's own margin, "
              f"{100 * FINE_MARGIN:g} % (`margin_of(\"ftle\")`, common to every page), the "
              f"collision rate at the counts' {100 * RATE_MARGIN:g} % (`margin_of(\"counts\")`"
              ", the README's). A share of runs rejected is read "
              "against the share of Poisson streams shaped like the runs (each run's rate and "
              f"window, {KS_NULL_STREAMS} per run) that the same test rejects; the "
              f"{DISPERSION_NAME} (var / mean of the "
              "whole-run counts over ICs; not the README's within-run D of counts in windows, "
              "nor disks.md's D across tagged disks) is read against the same statistic on "
              f"Poisson counts (the difference within ±{D_MARGIN:g}: at its null; wholly "
              "beyond: above / below).",
              "",
              f"Definitions and methods: [../unequal.md](../unequal.md). Disk 0 keeps "
              f"r0 = {R0:g}; {params.n_ics} invariant ICs per ratio, {params.n_steps} steps of "
              f"{params.tau:g}, mirror rule; the kicked disk gets scattering kicks at Poisson "
              "times at its IC's own collision rate. Ratios of means with 95 % bootstrap "
              "intervals over ICs.", "",
              "The four FTLE columns are ratios of the **finite-time Lyapunov exponent** "
              "(tangent FTLE of the named disk, mean over ICs): the kicked disk's over the "
              "same disk's in the two-disk system, with the partner radius of the scattering "
              "kicks as named. KS rejections: share of the two-disk runs whose collision "
              "times reject uniformity at α = 0.05 (Clopper–Pearson interval; its null: "
              "`ks_null`); rate dispersion across ICs: variance / mean of the whole-run "
              "collision counts over ICs (near 1 for a Poisson process), with a 95 % "
              "bootstrap interval over ICs, and its difference from its null (the mean of the "
              "same statistic on Poisson counts over the same runs at the pooled rate) with "
              "its verdict"
              + ("" if "disp_low" in table else " where the per-IC counts are stored (not "
                 "for this table)") + ".", "",
              "| r1 / r0 | rate / Γ(r0, r1) | KS rejections | rate dispersion across ICs | small "
              "disk FTLE, partner r1 | own-size partner | large disk FTLE, partner r0 | "
              "own-size partner | rate dispersion across ICs − null |",
              "|---|---|---|---|---|---|---|---|---|"]
    cols = [("ftle_partner_ratio_disk0", "ftle_partner_low_disk0", "ftle_partner_high_disk0"),
            ("ftle_own_ratio_disk0", "ftle_own_low_disk0", "ftle_own_high_disk0"),
            ("ftle_partner_ratio_disk1", "ftle_partner_low_disk1", "ftle_partner_high_disk1"),
            ("ftle_own_ratio_disk1", "ftle_own_low_disk1", "ftle_own_high_disk1")]

    def cell(row, c):  # the FTLE at FINE_MARGIN; the rate at RATE_MARGIN
        margin = RATE_MARGIN if c[0] == "rate_ratio" else FINE_MARGIN
        return (f"{format_interval(row[c[0]], row[c[1]], row[c[2]])}, "
                f"{ratio_reading(row[c[1]], row[c[2]], tolerance=margin)}")

    for _, row in table.iterrows():
        rate = cell(row, ("rate_ratio", "rate_low", "rate_high"))
        ks_lo, ks_hi = ks_interval(row, params.n_ics)
        disp = (format_interval(row["dispersion_index"], row["disp_low"], row["disp_high"],
                                edges=(1.0,)) if "disp_low" in row else
                f"{row['dispersion_index']:.1f} (no interval)")
        lines.append(f"| {row['size_ratio']:g} | {rate}"
                     f" | {100 * row['ks_reject_share']:.1f} % [{100 * ks_lo:.1f}, "
                     f"{100 * ks_hi:.1f}] | {disp} | "
                     + " | ".join(cell(row, c) for c in cols) + " | "
                     + _d_cell(row) + " |")
    lines.append("")
    for c, name in ((("rate_ratio", "rate_low", "rate_high"), "collision rate / kinetic rate"),
                    (cols[0], "small disk, partner of the other disk's size"),
                    (cols[2], "large disk, partner of the other disk's size")):
        margin = RATE_MARGIN if c[0] == "rate_ratio" else FINE_MARGIN
        v = [ratio_reading(lo, hi, tolerance=margin) for lo, hi in zip(table[c[1]], table[c[2]],
                                                             strict=True)]
        counts = pd.Series(v).value_counts()
        odd = [f"ratio {x:g}: {vv}" for x, vv in zip(table["size_ratio"], v, strict=True)
               if vv != counts.index[0]]
        lines.append(f"- {name}: {counts.index[0]} at {counts.iloc[0]} of {len(v)} ratios"
                     + (f" (not at {', '.join(odd)})" if odd else "") + ".")
    lines += ["", f"![size ratio]({FIGURE})", ""]
    return lines
