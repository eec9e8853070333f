"""The Markdown and the figure of ``eos.md``: the answers first, then the tables."""

from __future__ import annotations

import math

import numpy as np

from kicktimes.render.pages import markdown_table
from kicktimes.render.provenance import Source
from kicktimes.stats import EOS_MARGIN
from kicktimes.stats.eos import KOLAFA_ROTTNER_MAX
from kicktimes.studies.eos.tables import (
    KOLAFA_ROTTNER_ERROR,
    SE_MULTIPLE,
    VIRIAL_RANGE,
    contact_speed_prediction,
    coverage,
    eos_table,
    finite_size,
    frequency_table,
    halves_table,
    pooled_table,
)

__all__ = ["LIQUID_HEXATIC", "SOURCES", "answers", "body", "eos_figure"]

#: the hard-disk fluid ends at the liquid-hexatic transition, packings 0.700-0.716
#: (Bernard & Krauth, PRL 107, 155704 (2011)): the check stays below it
LIQUID_HEXATIC = (0.700, 0.716)

def _pct(ratio, low, high) -> str:
    """``"+0.012 % [-0.020, +0.044]"``: a ratio's departure from 1 in per cent."""
    return f"{100 * (ratio - 1):+.3f} % [{100 * (low - 1):+.3f}, {100 * (high - 1):+.3f}]"


def _prediction(row) -> str:
    """A pooled row's prediction in per cent: one value, or its range over the packings."""
    low, high = 100 * (row["prediction_low"] - 1), 100 * (row["prediction_high"] - 1)
    return f"{low:+.3f} %" if low == high else f"{low:+.3f} to {high:+.3f} %"


def _within(frame, column="verdict") -> int:
    return int(frame[column].str.startswith("within").sum())


def _worst(frame, ratio="ratio"):
    return frame.iloc[int(np.argmax(np.abs(frame[ratio].to_numpy() - 1)))]


def answers(eos, freq, size, halves, pool, primary) -> list[str]:
    """Five one-line answers."""
    out = []
    parts = []
    for n in sorted(eos["n"].unique(), key=lambda n: n != primary):
        g = eos[eos["n"] == n]
        r = _worst(g, "ratio_kr")
        far = _pct(r["ratio_kr"], r["ratio_kr_low"], r["ratio_kr_high"])
        parts.append(f"N = {n}: {_within(g, 'verdict_kr')} of {len(g)} within, farthest "
                     f"φ = {r['packing']:g} {far}")
    out.append("- **Z against Kolafa & Rottner's equation of state (margin 0.1 % + its "
               "accuracy):** " + "; ".join(parts) + f" ({SE_MULTIPLE:g}-SE intervals, "
               f"{100 * coverage(int(eos['states'].min())):.0f} % coverage).")
    vir = eos[(eos["n"] == primary) & (eos["reference"] == "virial")]
    if not vir.empty:
        r = vir.iloc[int(np.argmax(vir["packing"].to_numpy()))]
        tail = r["virial_b10"] / r["kolafa_rottner"] - 1
        out.append(f"- **Z against the virial series to B₁₀ (φ ≤ {VIRIAL_RANGE:g}, N = "
                   f"{primary}): {_within(vir)} of {len(vir)} within 0.1 %.** At φ = "
                   f"{r['packing']:g}, {_pct(r['ratio'], r['ratio_low'], r['ratio_high'])}, "
                   f"of which the series' own truncation is {100 * -tail:+.3f} %: there the "
                   f"test passes an engine between {100 * (tail - EOS_MARGIN):+.2f} and "
                   f"{100 * (tail + EOS_MARGIN):+.2f} % off the exact Z (against Kolafa & "
                   f"Rottner: {_pct(r['ratio_kr'], r['ratio_kr_low'], r['ratio_kr_high'])}).")
    fp = pool[pool["what"].str.startswith("frequency")]
    line = "; ".join(f"N = {int(r['n'])}: {_pct(r['ratio'], r['ratio_low'], r['ratio_high'])}"
                     f" against {_prediction(r)} predicted" for _, r in fp.iterrows())
    out.append(f"- **Velocities at contact: collision frequency over Enskog's with the "
               f"measured Z's g(σ), pooled over packings, {line}** (the frequency cancels: "
               f"this is the mean normal speed at contact against the Maxwellian at E/N; "
               f"the prediction counts the 2N − 2 degrees of freedom).")
    sp = pool[pool["what"].str.startswith("Z(N)")]
    parts = [f"Z(N = {int(r['n'])}) / Z(N = {primary}) pooled "
             f"{_pct(r['ratio'], r['ratio_low'], r['ratio_high'])}, against "
             f"{_prediction(r)} if the collisional part followed E/(N − 1)"
             for _, r in sp.iterrows()]
    open_ = size[~size["verdict"].str.startswith("within")]
    if len(open_):
        parts.append("per packing not resolved at " + ", ".join(
            f"φ = {p:g} ("
            + ("the estimate at the margin" if math.isnan(k) else f"about {int(k)} states would")
            + ")" for p, k in zip(open_["packing"], open_["states_to_resolve"], strict=True)))
    out.append("- **Finite size:** " + "; ".join(parts) + ".")
    parts = []
    for n in sorted(halves["n"].unique(), key=lambda n: n != primary):
        g = halves[halves["n"] == n]
        r = _worst(g)
        parts.append(f"N = {n}: {_within(g)} of {len(g)} within 0.1 %, farthest φ = "
                     f"{r['packing']:g} {_pct(r['ratio'], r['ratio_low'], r['ratio_high'])}")
    out.append("- **Equilibration (second half over first, paired by state):** "
               + "; ".join(parts) + ".")
    return out


def body(eos, freq, size, halves, pool, sizes, cpu, primary) -> list[str]:
    """The design, the tables and the figure."""
    kr_err = ", ".join(f"{e:.0e} of Z to φ = {top:g}" if np.isfinite(top) else
                       f"{e:.0e} above" for top, e in KOLAFA_ROTTNER_ERROR)
    lines = ["## Design", "",
             f"Hard disks in the periodic unit box, elastic rule, N = "
             f"{' and '.join(str(n) for n in sizes.sizes)} (the first the primary) at area "
             f"fractions {', '.join(f'{p:g}' for p in sizes.packings)}: per cell "
             f"{sizes.states} independent states (`kicktimes.initial_state`: random "
             f"sequential addition, growth above 0.35, relaxation), each run "
             f"{sizes.equilibrate:g} collisions per disk discarded, then "
             f"{sizes.collisions:g} per disk in two halves (`kicktimes.simulate_disks`); Z is "
             f"the collisional virial (`DisksRun.pressure`), kT = E/N. Intervals: "
             f"±{SE_MULTIPLE:g} standard errors over the states "
             f"({100 * coverage(sizes.states):.0f} % coverage, Student's t). References "
             f"(`kicktimes.stats.eos`): Kolafa & Rottner, Mol. Phys. 104, 3435 (2006), eq. "
             f"(7), fitted to φ ≤ {KOLAFA_ROTTNER_MAX:.3f}, accurate to {kr_err}; the virial "
             f"series to B₁₀ (b₃, b₄ exact; b₅–b₁₀ Clisby & McCoy, J. Stat. Phys. 122, 15 "
             f"(2006)) up to φ = {VIRIAL_RANGE:g}, which lies below Z by its tail (all "
             f"b_k > 0); Henderson's approximation, Mol. Phys. 30, 971 (1975), beside them. "
             f"Margins, stated in advance (`stats.EOS_MARGIN`, docs/definitions.md): 0.1 % of "
             f"Z, plus Kolafa & Rottner's accuracy against theirs. The check stays below the "
             f"liquid–hexatic transition ({LIQUID_HEXATIC[0]:.3f}–{LIQUID_HEXATIC[1]:.3f}). "
             f"{cpu / 60:.0f} CPU-minutes.", "",
             "![Z and the contact velocities against the packing](eos.png)", "",
             f"*Left: measured Z over Kolafa & Rottner's, minus 1, per N, ±{SE_MULTIPLE:g} SE; "
             "the shaded band is each packing's margin; dotted, the virial series to B₁₀ over "
             "the same reference (the verdicts at φ ≤ 0.4 read the points against it). "
             "Middle: the collision frequency over Enskog's with the measured Z, per N, "
             "with the degrees-of-freedom prediction √((N − 1)/N) dashed. Right: the "
             "references over Kolafa & Rottner's at the studied packings.*", "",
             "## Z per packing", ""]
    t = eos.copy()
    t["Z measured"] = [f"{z:.6f} [{lo:.6f}, {hi:.6f}]" for z, lo, hi in
                       zip(t["z"], t["z_low"], t["z_high"], strict=True)]
    t["Kolafa-Rottner Z"] = [f"{k:.6f}" for k in t["kolafa_rottner"]]
    t["Z / KR − 1"] = [f"{_pct(r, lo, hi)} {v}" for r, lo, hi, v in
                       zip(t["ratio_kr"], t["ratio_kr_low"], t["ratio_kr_high"],
                           t["verdict_kr"], strict=True)]
    t["Z / virial B₁₀ − 1"] = [f"{_pct(r, lo, hi)} {v}" if ref == "virial" else "" for
                                r, lo, hi, v, ref in
                                zip(t["ratio"], t["ratio_low"], t["ratio_high"], t["verdict"],
                                    t["reference"], strict=True)]
    t["Henderson / KR − 1"] = [f"{100 * (h - 1):+.3f} %" for h in t["henderson_over_kr"]]
    lines += markdown_table(t[["packing", "n", "Z measured", "Kolafa-Rottner Z",
                               "Z / KR − 1", "Z / virial B₁₀ − 1", "Henderson / KR − 1"]])
    lines += ["", "## Pooled over the packings, beside their predictions", ""]
    pt = pool.copy()
    pt["measured − 1"] = [_pct(r, lo, hi) for r, lo, hi in
                          zip(pt["ratio"], pt["ratio_low"], pt["ratio_high"], strict=True)]
    pt["prediction"] = [_prediction(r) for _, r in pt.iterrows()]
    lines += markdown_table(pt[["what", "n", "measured − 1", "prediction", "packings"]])
    fp = pool[pool["what"].str.startswith("frequency")]
    gaps = "; ".join(
        f"N = {int(r['n'])}: {100 * (r['ratio'] - r['prediction_low']):+.4f} % "
        f"[{100 * (r['ratio_low'] - r['prediction_low']):+.4f}, "
        f"{100 * (r['ratio_high'] - r['prediction_low']):+.4f}]" for _, r in fp.iterrows())
    zp = pool[pool["what"].str.startswith("Z(N)")]
    side = []
    for _, r in zp.iterrows():
        where = ("lies below" if r["ratio_high"] < r["prediction_low"] else "lies above" if
                 r["ratio_low"] > r["prediction_high"] else "overlaps")
        side.append(f"N = {int(r['n'])}: its interval {where} the predictions' range "
                    f"({_prediction(r)})")
    lines += ["", f"Frequency ratio measured − predicted: {gaps}. Pooled Z(N) / Z(primary): "
              + "; ".join(side) + ". Which temperature a finite box's Z should divide by "
              "(E/N or E/(N − 1)) is left open.", "",
              "## Finite size and equilibration per packing", ""]
    s = size.copy()
    s["Z(N) / Z(primary) − 1"] = [f"{_pct(r, lo, hi)} {v}" for r, lo, hi, v in
                                  zip(s["ratio"], s["ratio_low"], s["ratio_high"],
                                      s["verdict"], strict=True)]
    s["prediction (E/(N − 1))"] = [f"{100 * (p - 1):+.3f} %" for p in s["dof_prediction"]]
    lines += markdown_table(s[["packing", "n", "Z(N) / Z(primary) − 1",
                               "prediction (E/(N − 1))", "states_to_resolve"]])
    lines += [""]
    h = halves.copy()
    h["second / first half − 1"] = [f"{_pct(r, lo, hi)} {v}" for r, lo, hi, v in
                                    zip(h["ratio"], h["ratio_low"], h["ratio_high"],
                                        h["verdict"], strict=True)]
    lines += markdown_table(h[["packing", "n", "second / first half − 1",
                               "states_to_resolve"]])
    lines += ["", "Per-packing frequency ratios: `eos_frequency.csv`. `states_to_resolve`: "
              "the states at which the interval would fit the margin were the estimate to "
              "stay (`tables.states_to_resolve`; empty: the estimate is at the margin).", "",
              "## What this does not show", "",
              "- The collision count itself: the frequency ratio does not contain it. The "
              "count is checked against Enskog–Henderson in the tables "
              "(tests/test_disks.py) and against the kinetic rate for two disks.",
              "- The tables (circle, stadium, ellipse) and the mirror rule: "
              "tests/test_disks_pressure.py compares their wall, virial and bulk Z; the "
              "mirror rule has no virial origin in the box.",
              f"- Packings from the liquid–hexatic transition on "
              f"({LIQUID_HEXATIC[0]:.3f}–{LIQUID_HEXATIC[1]:.3f}).", ""]
    return lines


def eos_figure(eos, freq, primary):
    """Left: measured Z / Kolafa-Rottner - 1 per N with 3-SE bars, the margins and the
    truncated virial series; middle: the frequency ratio per N beside sqrt((N - 1)/N);
    right: Henderson and the series over Kolafa-Rottner."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from kicktimes.stats import henderson_z, kolafa_rottner_z, virial_z

    fig, (ax, fx, bx) = plt.subplots(1, 3, figsize=(14, 4.2))
    sizes = sorted(eos["n"].unique(), key=lambda n: n != primary)
    marks = {n: ("o" if n == primary else "s") for n in sizes}
    for k, n in enumerate(sizes):
        g = eos[eos["n"] == n]
        shift = 0.004 * (k - 0.5 * (len(sizes) - 1))
        ax.errorbar(g["packing"] + shift, 100 * (g["ratio_kr"] - 1),
                    yerr=[100 * (g["ratio_kr"] - g["ratio_kr_low"]),
                          100 * (g["ratio_kr_high"] - g["ratio_kr"])],
                    fmt=marks[n], ms=4, capsize=3,
                    label=f"N = {n}" + (" (primary)" if n == primary else ""))
        q = freq[freq["n"] == n]
        fx.errorbar(q["packing"] + shift, 100 * (q["ratio"] - 1),
                    yerr=[100 * (q["ratio"] - q["ratio_low"]),
                          100 * (q["ratio_high"] - q["ratio"])],
                    fmt=marks[n], ms=4, capsize=3, color=f"C{k}", label=f"N = {n}")
        fx.axhline(100 * (float(contact_speed_prediction(n)) - 1), color=f"C{k}", ls="--", lw=1,
                   label=f"√((N − 1)/N), N = {n}")
    g = eos[eos["n"] == primary].sort_values("packing")
    ax.fill_between(g["packing"], -100 * g["margin_kr"], 100 * g["margin_kr"], step="mid",
                    color="0.88", zorder=0, label="margin")
    phi = np.linspace(0.05, VIRIAL_RANGE, 60)
    ax.plot(phi, 100 * (virial_z(phi) / kolafa_rottner_z(phi) - 1), "k:", lw=1,
            label="virial series to B₁₀")
    for a in (ax, fx):
        a.axhline(0.0, color="k", lw=0.6)
        a.set_xlabel("packing φ")
    ax.set_ylabel("Z / Z(Kolafa–Rottner) − 1  (%)")
    ax.set_title(f"Z, ±{SE_MULTIPLE:g} SE")
    ax.legend(fontsize=8)
    fx.axhspan(-100 * EOS_MARGIN, 100 * EOS_MARGIN, color="0.88", zorder=0, label="±0.1 % margin")
    fx.set_ylabel("frequency / Enskog(measured Z) − 1  (%)")
    fx.set_title("velocities at contact")
    fx.legend(fontsize=7)
    lo, hi = float(eos["packing"].min()), float(eos["packing"].max())
    phi = np.linspace(lo, hi, 120)
    bx.plot(phi, 100 * (henderson_z(phi) / kolafa_rottner_z(phi) - 1),
            label="Henderson (approximation)")
    vphi = phi[phi <= VIRIAL_RANGE]
    bx.plot(vphi, 100 * (virial_z(vphi) / kolafa_rottner_z(vphi) - 1), "k:",
            label="virial series to B₁₀")
    bx.axhline(0.0, color="k", lw=0.6)
    bx.set_xlabel("packing φ")
    bx.set_ylabel("Z / Z(Kolafa–Rottner) − 1  (%)")
    bx.set_title("the references")
    bx.legend(fontsize=8)
    fig.tight_layout()
    return fig


SOURCES = (
    Source("eos_eos.csv", "z, se, z_low, z_high, coverage, virial_b10, kolafa_rottner, "
           "henderson, reference, ratio, ratio_low, ratio_high, margin, verdict, ratio_kr, "
           "ratio_kr_low, ratio_kr_high, margin_kr, verdict_kr", eos_table),
    Source("eos_frequency.csv", "ratio, se, ratio_low, ratio_high, margin, verdict, "
           "dof_prediction", frequency_table),
    Source("eos_finite_size.csv", "ratio, se, ratio_low, ratio_high, verdict, "
           "dof_prediction, states_to_resolve", finite_size),
    Source("eos_halves.csv", "ratio, se, ratio_low, ratio_high, verdict, states_to_resolve",
           halves_table),
    Source("eos_pooled.csv", "what, n, ratio, se, ratio_low, ratio_high, prediction_low, "
           "prediction_high", pooled_table),
)
