"""The Markdown and the figure of ``eos.md``: the answers first, then the tables."""

from __future__ import annotations

import numpy as np

from kicktimes.render.pages import markdown_table
from kicktimes.render.provenance import Source
from kicktimes.studies.eos.tables import (
    SE_MULTIPLE,
    VIRIAL_RANGE,
    eos_table,
    finite_size,
    frequency_table,
    halves_table,
)

__all__ = ["SOURCES", "answers", "body", "eos_figure"]

SOURCES = (
    Source("eos_eos.csv", "z, se, z_low, z_high, virial_b10, kolafa_rottner, henderson, "
           "reference, ratio, ratio_low, ratio_high, margin, verdict, ratio_kr, verdict_kr",
           eos_table),
    Source("eos_frequency.csv", "ratio, se, ratio_low, ratio_high, margin, verdict",
           frequency_table),
    Source("eos_finite_size.csv", "ratio, se, ratio_low, ratio_high, verdict, "
           "states_to_resolve", finite_size),
    Source("eos_halves.csv", "ratio, se, ratio_low, ratio_high, verdict, states_to_resolve",
           halves_table),
)


def _pct(ratio, low, high, margin) -> str:
    """``"+0.012 % [-0.020, +0.044]"``: a ratio's departure from 1 in per cent."""
    return (f"{100 * (ratio - 1):+.3f} % [{100 * (low - 1):+.3f}, {100 * (high - 1):+.3f}]"
            f" (margin ±{100 * margin:.3g} %)")


def _within(frame) -> int:
    return int(frame["verdict"].str.startswith("within").sum())


def _worst(frame, ratio="ratio", low="ratio_low", high="ratio_high"):
    k = int(np.argmax(np.abs(frame[ratio].to_numpy() - 1)))
    return frame.iloc[k], ratio, low, high


def answers(eos, freq, size, halves, primary) -> list[str]:
    """At most five one-line answers."""
    p = eos[eos["n"] == primary]
    vir = p[p["reference"] == "virial"]
    kr = p[p["reference"] == "kolafa_rottner"]
    f = freq[freq["n"] == primary]
    h = halves[halves["n"] == primary]
    out = []
    if not vir.empty:
        row, *_ = _worst(vir)
        tail = row["virial_b10"] / row["kolafa_rottner"] - 1
        kr_far = _pct(row["ratio_kr"], row["ratio_kr_low"], row["ratio_kr_high"],
                      row["margin_kr"])
        out.append(f"- **Z against the virial series to B₁₀ (φ ≤ {VIRIAL_RANGE:g}), N = "
                   f"{primary}: {_within(vir)} of {len(vir)} packings within 0.1 %.** "
                   f"Farthest: φ = {row['packing']:g}, "
                   f"{_pct(row['ratio'], row['ratio_low'], row['ratio_high'], row['margin'])}"
                   f", where the truncated series lies {100 * tail:+.3f} % from Kolafa & "
                   f"Rottner's Z (its tail); against theirs {kr_far}.")
    if not kr.empty:
        row, *_ = _worst(kr)
        out.append(f"- **Z against Kolafa & Rottner's equation of state (φ ≥ 0.5), N = "
                   f"{primary}: {_within(kr)} of {len(kr)} packings within 0.1 % + their "
                   f"accuracy.** Farthest: φ = {row['packing']:g}, "
                   f"{_pct(row['ratio'], row['ratio_low'], row['ratio_high'], row['margin'])}"
                   f", {row['verdict']} ({SE_MULTIPLE:g}-SE intervals).")
    row, *_ = _worst(f)
    far = _pct(row["ratio"], row["ratio_low"], row["ratio_high"], row["margin"])
    small = freq[freq["n"] != primary]
    at_small = "; ".join(
        f"at N = {n}: {100 * (g['ratio'].min() - 1):+.3f} to {100 * (g['ratio'].max() - 1):+.3f} %"
        f", {_within(g)} of {len(g)} within" for n, g in small.groupby("n"))
    out.append(f"- **Collision frequency over Enskog's with the measured Z's g(σ), N = "
               f"{primary}: {_within(f)} of {len(f)} packings within 0.1 %.** Farthest: φ = "
               f"{row['packing']:g}, {far}" + (f" ({at_small})" if at_small else "") + ".")
    parts = []
    for n, g in size.groupby("n"):
        r, *_ = _worst(g)
        open_ = g[~g["verdict"].str.startswith("within")]
        unresolved = (f"; not resolved at {int(open_['states'].max())} states at φ = "
                      + ", ".join(f"{p:g} (about {k} would)" for p, k in
                                  zip(open_["packing"], open_["states_to_resolve"],
                                      strict=True))) if len(open_) else ""
        parts.append(f"Z(N = {n}) / Z(N = {primary}) within 0.1 % at {_within(g)} of "
                     f"{len(g)} packings, farthest φ = {r['packing']:g}: "
                     f"{_pct(r['ratio'], r['ratio_low'], r['ratio_high'], r['margin'])}"
                     + unresolved)
    r, *_ = _worst(h)
    parts.append(f"second half / first half within 0.1 % at {_within(h)} of {len(h)}, "
                 f"farthest φ = {r['packing']:g}: "
                 f"{_pct(r['ratio'], r['ratio_low'], r['ratio_high'], r['margin'])}")
    out.append("- **Finite size and equilibration, measured:** " + "; ".join(parts) + ".")
    return out


def body(eos, freq, size, halves, sizes, cpu, primary) -> list[str]:
    """The design, the tables and the figure."""
    lines = ["## Design", "",
             f"Hard disks in the periodic unit box, elastic rule, N = "
             f"{' and '.join(str(n) for n in sizes.sizes)} (the first the primary) at area "
             f"fractions {', '.join(f'{p:g}' for p in sizes.packings)}: per cell "
             f"{sizes.states} independent states (`kicktimes.initial_state`: random "
             f"sequential addition, growth above 0.35, relaxation), each run "
             f"{sizes.equilibrate:g} collisions per disk discarded, then "
             f"{sizes.collisions:g} per disk in two halves (`kicktimes.simulate_disks`); Z is "
             f"the collisional virial (`DisksRun.pressure`), kT = E/N. Intervals: "
             f"±{SE_MULTIPLE:g} standard errors over the states. References "
             f"(`kicktimes.stats.eos`): the virial series to B₁₀ (b₃, b₄ exact; b₅–b₁₀ Clisby & "
             f"McCoy, J. Stat. Phys. 122, 15 (2006)) up to φ = {VIRIAL_RANGE:g}, where its "
             f"truncation is 0.005 % (0.3) to 0.07 % (0.4) low; Kolafa & Rottner, Mol. Phys. "
             f"104, 3435 (2006), eq. (7), accurate to 10⁻⁵ up to φ = 0.65 and 10⁻⁴ near "
             f"0.70 (their fit reproduces Engel et al.'s 1024² disks at 0.698 to 0.03 %); "
             f"Henderson's approximation, Mol. Phys. 30, 971 (1975), beside them. Margins, "
             f"stated in advance (`stats.EOS_MARGIN`, docs/definitions.md): 0.1 % of Z, plus "
             f"Kolafa & Rottner's accuracy against theirs. {cpu / 60:.0f} CPU-minutes.", "",
             "![Z over the reference against the packing](eos.png)", "",
             "*Left: measured Z over Kolafa & Rottner's, minus 1, per N, with "
             f"{SE_MULTIPLE:g}-SE bars; the shaded band is the 0.1 % margin; the line is the "
             "virial series to B₁₀ over the same reference. Right: the references over "
             "Kolafa & Rottner's: Henderson's approximation and the truncated series.*", "",
             "## Z per packing", ""]
    t = eos.copy()
    t["Z measured"] = [f"{z:.6f} [{lo:.6f}, {hi:.6f}]" for z, lo, hi in
                       zip(t["z"], t["z_low"], t["z_high"], strict=True)]
    t["reference"] = np.where(t["reference"] == "virial", "virial to B₁₀",
                              "Kolafa-Rottner")
    t["Z reference"] = [f"{v:.6f}" if r == "virial to B₁₀" else f"{k:.6f}" for v, k, r in
                        zip(t["virial_b10"], t["kolafa_rottner"], t["reference"], strict=True)]
    t["measured / reference − 1"] = [_pct(r, lo, hi, m) for r, lo, hi, m in
                                     zip(t["ratio"], t["ratio_low"], t["ratio_high"],
                                         t["margin"], strict=True)]
    t["against Kolafa-Rottner"] = [f"{100 * (r - 1):+.3f} % ({v})" for r, v in
                                   zip(t["ratio_kr"], t["verdict_kr"], strict=True)]
    t["Henderson"] = [f"{h:.5f}" for h in t["henderson"]]
    lines += markdown_table(t[["packing", "n", "Z measured", "reference", "Z reference",
                               "measured / reference − 1", "verdict",
                               "against Kolafa-Rottner", "Henderson"]])
    hend = eos[eos["n"] == primary].set_index("packing")["henderson_over_kr"]
    lines += ["", "Henderson's equation (an approximation, kicktimes' reference before this "
              "check) over Kolafa & Rottner's: " + ", ".join(
                  f"{100 * (v - 1):+.3f} % at φ = {k:g}" for k, v in hend.items()) + "."]
    lines += ["", "## Collision frequency over Enskog's with the measured Z", ""]
    f = freq.copy()
    f["frequency / Enskog − 1"] = [_pct(r, lo, hi, m) for r, lo, hi, m in
                                   zip(f["ratio"], f["ratio_low"], f["ratio_high"],
                                       f["margin"], strict=True)]
    lines += markdown_table(f[["packing", "n", "frequency / Enskog − 1", "verdict"]])
    lines += ["", "## Finite size and equilibration", ""]
    s = size.copy()
    s["Z(N) / Z(primary) − 1"] = [_pct(r, lo, hi, m) for r, lo, hi, m in
                                  zip(s["ratio"], s["ratio_low"], s["ratio_high"],
                                      s["margin"], strict=True)]
    hv = halves[halves["n"] == primary].copy()
    s = s.merge(hv[["packing", "ratio", "ratio_low", "ratio_high", "margin", "verdict"]]
                .rename(columns={"verdict": "halves verdict"}), on="packing",
                suffixes=("", "_h"))
    s["second / first half − 1 (primary)"] = [
        _pct(r, lo, hi, m) for r, lo, hi, m in
        zip(s["ratio_h"], s["ratio_low_h"], s["ratio_high_h"], s["margin_h"], strict=True)]
    lines += markdown_table(s[["packing", "n", "Z(N) / Z(primary) − 1", "verdict",
                               "second / first half − 1 (primary)", "halves verdict"]])
    lines += ["", "## What this does not show", "",
              "- The tables (circle, stadium, ellipse) are not in this check; "
              "tests/test_disks_pressure.py compares their wall, virial and bulk Z.",
              "- The mirror rule has no equation of state in the box (no momentum "
              "conservation, no virial origin); its collision frequency is checked against "
              "Enskog–Henderson in tests/test_disks.py.",
              "- Packings from the liquid–hexatic transition on (0.700–0.716, Bernard & "
              "Krauth, PRL 107, 155704 (2011)) are left out; the reference fit ends at "
              "0.707.", ""]
    return lines


def eos_figure(eos, primary):
    """Left: measured Z / Kolafa-Rottner - 1 per N with 3-SE bars, the 0.1 % band and the
    truncated virial series; right: Henderson and the series over Kolafa-Rottner."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from kicktimes.stats import henderson_z, kolafa_rottner_z, virial_z

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    sizes = sorted(eos["n"].unique(), key=lambda n: n != primary)
    for k, n in enumerate(sizes):
        g = eos[eos["n"] == n]
        shift = 0.004 * (k - 0.5 * (len(sizes) - 1))
        ax.errorbar(g["packing"] + shift, 100 * (g["ratio_kr"] - 1),
                    yerr=[100 * (g["ratio_kr"] - g["ratio_kr_low"]),
                          100 * (g["ratio_kr_high"] - g["ratio_kr"])],
                    fmt="o" if n == primary else "s", ms=4, capsize=3,
                    label=f"N = {n}" + (" (primary)" if n == primary else ""))
    ax.axhspan(-0.1, 0.1, color="0.85", zorder=0, label="±0.1 % margin")
    phi = np.linspace(0.01, VIRIAL_RANGE, 60)
    ax.plot(phi, 100 * (virial_z(phi) / kolafa_rottner_z(phi) - 1), "k:", lw=1,
            label="virial series to B₁₀")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("packing φ")
    ax.set_ylabel("Z / Z(Kolafa–Rottner) − 1  (%)")
    ax.set_title(f"measured, ±{SE_MULTIPLE:g} SE")
    ax.legend(fontsize=8)
    phi = np.linspace(0.01, 0.69, 120)
    bx.plot(phi, 100 * (henderson_z(phi) / kolafa_rottner_z(phi) - 1),
            label="Henderson (approximation)")
    vphi = phi[phi <= 0.5]
    bx.plot(vphi, 100 * (virial_z(vphi) / kolafa_rottner_z(vphi) - 1), "k:",
            label="virial series to B₁₀")
    bx.axhspan(-0.1, 0.1, color="0.85", zorder=0, label="±0.1 %")
    bx.axhline(0.0, color="k", lw=0.6)
    bx.set_xlabel("packing φ")
    bx.set_ylabel("Z / Z(Kolafa–Rottner) − 1  (%)")
    bx.set_title("the references")
    bx.legend(fontsize=8)
    fig.tight_layout()
    return fig
