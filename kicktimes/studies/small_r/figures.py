"""The small-r study's figure: the stretching per perturbation against ln(1/r) beside the
theory, and the kicked / two-disk ratio against r beside the theory and its limit."""

from __future__ import annotations

import numpy as np

from kicktimes.studies.small_r.tables import KICKED

__all__ = ["small_r_figure"]

NAMES = {"two_particle": "two disks", **KICKED}
COLOURS = {"two_particle": "black", "poisson": "tab:blue", "uniform_kinetic": "tab:cyan",
           "poisson_scatter": "tab:red", "poisson_kinetic": "tab:orange"}
MARKERS = {"two_particle": "o", "poisson": "s", "uniform_kinetic": "D",
           "poisson_scatter": "^", "poisson_kinetic": "v"}


def small_r_figure(meas, theory, ratios):
    """A 2 x 2 figure: per collision rule (rows), the stretching per perturbation against
    ln(1/r) (measured with 95 % intervals, the theory as lines) and the kicked / two-disk
    FTLE ratio against r (measured, the theory's ratio as lines, its limit r -> 0 dashed,
    the ±5 % band around 1 shaded)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rules = [u for u in ("mirror", "elastic") if u in set(meas["rule"])]
    fig, axes = plt.subplots(len(rules), 2, figsize=(11, 4.2 * len(rules)), squeeze=False)
    for row, rule in zip(axes, rules, strict=True):
        left, right = row
        m = meas[meas["rule"] == rule]
        th = theory[theory["rule"] == rule]
        for k, system in enumerate(NAMES):
            a = m[m["system"] == system].sort_values("radius")
            t = th[th["system"] == system].sort_values("radius")
            x = np.log(1 / a["radius"]) + 0.03 * (k - 2)
            left.errorbar(x, a["stretch"], yerr=[a["stretch"] - a["ci_low"],
                                                 a["ci_high"] - a["stretch"]],
                          fmt=MARKERS[system], color=COLOURS[system], ms=5, capsize=2,
                          label=f"{NAMES[system]} (simulation)", lw=0, elinewidth=1)
            left.plot(np.log(1 / t["radius"]), t["stretch"], "-", color=COLOURS[system],
                      lw=1, alpha=0.8)
        left.set_xlabel("ln(1/r)")
        left.set_ylabel("λ/Γ (nats per perturbation)")
        left.set_title(f"{rule} rule: stretching per perturbation (lines: theory)", fontsize=10)
        left.grid(alpha=0.3)
        right.axhspan(0.95, 1.05, color="0.9", zorder=0)
        rr = ratios[ratios["rule"] == rule]
        for k, system in enumerate(KICKED):
            a = rr[rr["system"] == system].sort_values("radius")
            x = a["radius"] * np.exp(0.04 * (k - 1.5))
            right.errorbar(x, a["ratio"], yerr=[a["ratio"] - a["ratio_ci_low"],
                                                a["ratio_ci_high"] - a["ratio"]],
                           fmt=MARKERS[system], color=COLOURS[system], ms=5, capsize=2, lw=0,
                           elinewidth=1, label=NAMES[system])
            right.plot(a["radius"], a["predicted_ratio"], "-", color=COLOURS[system], lw=1,
                       alpha=0.8)
        for level in sorted(set(rr["limit"])):
            right.axhline(level, ls="--", color="0.4", lw=1)
            right.annotate(f"limit r → 0: {level:g}", (rr["radius"].min(), level),
                           xytext=(2, 3), textcoords="offset points", fontsize=8, color="0.3")
        right.set_xscale("log")
        right.set_xlabel("r")
        right.set_ylabel("kicked / two-disk FTLE")
        right.set_ylim(0, 1.12)
        right.set_title(f"{rule} rule: FTLE ratio (lines: theory; band: ±5 %)", fontsize=10)
        right.grid(alpha=0.3, which="both")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    axes[0, 1].legend(fontsize=7, loc="center right")
    fig.tight_layout()
    return fig
