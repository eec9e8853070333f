"""The small-r study's figure: the stretching per perturbation against ln(1/r) beside the
theory, and the kicked / two-disk ratio against r beside the theory and its limit."""

from __future__ import annotations

import numpy as np

from kicktimes.studies.small_r.tables import KICKED

__all__ = ["small_r_figure"]

NAMES = {"two_particle": "two disks", **KICKED}
COLOURS = {"two_particle": "black", "poisson": "tab:blue", "uniform_kinetic": "tab:cyan",
           "poisson_scatter": "tab:red", "poisson_kinetic": "tab:orange"}
#: where the theory's asymptotic ratio is drawn to (ln(1/r); r = 1e-10)
FAR_LN = float(np.log(1e10))
MARKERS = {"two_particle": "o", "poisson": "s", "uniform_kinetic": "D",
           "poisson_scatter": "^", "poisson_kinetic": "v"}


def small_r_figure(meas, theory, ratios):
    """A 2 x 2 figure: per collision rule (rows), the stretching per perturbation against
    ln(1/r) (measured with 95 % intervals, the theory as lines) and the kicked / two-disk
    FTLE ratio against ln(1/r) (measured, the theory's ratio as lines, dotted beyond the
    sweep to r = 1e-10 by the theory's asymptotic form, its limit r -> 0 dashed, the ±5 %
    band around 1 shaded)."""
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
        far = np.linspace(np.log(1 / th["radius"].min()), FAR_LN, 50)
        low = th[th["radius"] == th["radius"].min()].set_index("system")
        for k, system in enumerate(KICKED):
            a = rr[rr["system"] == system].sort_values("radius")
            x = np.log(1 / a["radius"]) + 0.12 * (k - 1.5)
            right.errorbar(x, a["ratio"], yerr=[a["ratio"] - a["ratio_ci_low"],
                                                a["ratio_ci_high"] - a["ratio"]],
                           fmt=MARKERS[system], color=COLOURS[system], ms=5, capsize=2, lw=0,
                           elinewidth=1, label=NAMES[system])
            right.plot(np.log(1 / a["radius"]), a["predicted_ratio"], "-",
                       color=COLOURS[system], lw=1, alpha=0.8)
            # beyond the sweep: the theory's own asymptotic form b ln(1/r) + a, with the
            # constants a of its smallest radius (the theory is that form; nothing fitted)
            kick, two = low.loc[system], low.loc["two_particle"]
            right.plot(far, (kick["slope"] * far + kick["intercept"])
                       / (two["slope"] * far + two["intercept"]), ":",
                       color=COLOURS[system], lw=1)
        for level in sorted(set(rr["limit"])):
            right.axhline(level, ls="--", color="0.4", lw=1)
            right.annotate(f"limit r → 0: {level:g}", (FAR_LN, level), xytext=(-4, 3),
                           textcoords="offset points", fontsize=8, color="0.3", ha="right")
        right.set_xlabel("ln(1/r)")
        right.set_ylabel("kicked / two-disk FTLE")
        right.set_ylim(0, 1.12)
        right.set_title(f"{rule} rule: FTLE ratio (lines: theory, dotted beyond the sweep; "
                        "band: ±5 %)", fontsize=9)
        top = right.secondary_xaxis("top", functions=(lambda x: x, lambda x: x))
        ticks = [np.log(10.0 ** k) for k in (2, 4, 6, 8, 10)]
        top.set_xticks(ticks, [f"r = 1e-{k}" for k in (2, 4, 6, 8, 10)], fontsize=7)
        right.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7, loc="upper left")
    axes[0, 1].legend(fontsize=7, loc="center right", bbox_to_anchor=(1.0, 0.72))
    fig.tight_layout()
    return fig
