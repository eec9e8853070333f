"""The small-r study's figure: per collision rule, the stretching per perturbation beside
the theory, their difference in nats, and the kicked / two-disk ratio beside the theory."""

from __future__ import annotations

import numpy as np

from kicktimes.studies.small_r.tables import KICKED

__all__ = ["SHOWN", "small_r_figure"]

#: the systems drawn (the kinetic-rate kicks give the same values: in the CSVs)
SHOWN = ("two_particle", "poisson", "poisson_scatter")
NAMES = {"two_particle": "two disks", **KICKED}
COLOURS = {"two_particle": "black", "poisson": "tab:blue", "poisson_scatter": "tab:red"}
MARKERS = {"two_particle": "o", "poisson": "s", "poisson_scatter": "^"}


def _bars(ax, x, y, lo, hi, system, label=None, **kw):
    ax.errorbar(x, y, yerr=[y - lo, hi - y], fmt=MARKERS[system], color=COLOURS[system],
                ms=4, capsize=3, lw=0, elinewidth=1.2, label=label, **kw)


def small_r_figure(meas, compare, ratios):
    """A figure with one row per collision rule and three panels, all against ln(1/r):
    the stretching per perturbation (simulation with 95 % intervals, theory as lines);
    measured - theory in nats (95 % intervals: bootstrap over ICs and the theory's Monte
    Carlo error); the kicked / two-disk FTLE ratio (simulation, theory as lines, the limit
    r -> 0 of each kick law marked at the right edge, the ±5 % band around 1 shaded)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rules = [u for u in ("mirror", "elastic") if u in set(meas["rule"])]
    fig, axes = plt.subplots(len(rules), 3, figsize=(15, 4.3 * len(rules)), squeeze=False)
    for ax in axes[1:, 1]:                      # one y scale for the rules' differences
        ax.sharey(axes[0, 1])
    x_all = np.log(1 / meas["radius"])
    span = (x_all.min() - 0.3, x_all.max() + 0.3)
    for row, rule in zip(axes, rules, strict=True):
        left, mid, right = row
        m = meas[meas["rule"] == rule]
        c = compare[compare["rule"] == rule]
        rr = ratios[ratios["rule"] == rule]
        for k, system in enumerate(SHOWN):
            a = m[m["system"] == system].sort_values("radius")
            t = c[c["system"] == system].sort_values("radius")
            x = np.log(1 / a["radius"].to_numpy())
            _bars(left, x, a["stretch"].to_numpy(), a["ci_low"].to_numpy(),
                  a["ci_high"].to_numpy(), system, f"{NAMES[system]}, simulation")
            left.plot(x, t["predicted"], "-", color=COLOURS[system], lw=1, alpha=0.7,
                      label=f"{NAMES[system]}, theory")
            _bars(mid, np.log(1 / t["radius"].to_numpy()) + 0.08 * (k - 1),
                  t["difference"].to_numpy(), t["difference_ci_low"].to_numpy(),
                  t["difference_ci_high"].to_numpy(), system, NAMES[system])
            if system != "two_particle":
                q = rr[rr["system"] == system].sort_values("radius")
                xq = np.log(1 / q["radius"].to_numpy())
                _bars(right, xq, q["ratio"].to_numpy(), q["ratio_ci_low"].to_numpy(),
                      q["ratio_ci_high"].to_numpy(), system, f"{NAMES[system]}, simulation")
                right.plot(xq, q["predicted_ratio"], "-", color=COLOURS[system], lw=1,
                           alpha=0.7, label=f"{NAMES[system]}, theory")
                limit = float(q["limit"].iloc[0])
                right.annotate(f"→ {limit:g} as r → 0", (span[1], limit), xytext=(-2, 0),
                               textcoords="offset points", ha="right", va="center",
                               fontsize=8, color=COLOURS[system])
        left.set_ylabel("λ/Γ (nats per perturbation)")
        left.set_title(f"{rule} rule: stretching per perturbation", fontsize=10)
        left.legend(fontsize=7, loc="upper left")
        mid.axhline(0.0, color="0.5", lw=0.8)
        mid.set_ylabel("simulation − theory (nats)")
        mid.set_title(f"{rule} rule: simulation − theory", fontsize=10)
        mid.legend(fontsize=7, loc="upper right")
        right.axhspan(0.95, 1.05, color="0.9", zorder=0)
        right.set_ylim(0.1, 1.08)
        right.set_ylabel("kicked / two-disk FTLE")
        right.set_title(f"{rule} rule: FTLE ratio (band: ±5 %)", fontsize=10)
        right.legend(fontsize=7, loc="center left", bbox_to_anchor=(0.0, 0.62))
        for ax in row:
            ax.set_xlim(*span)
            ax.set_xlabel("ln(1/r)")
            ax.grid(alpha=0.3)
            top = ax.secondary_xaxis("top")
            ticks = [k for k in (1e-2, 1e-3, 1e-4) if span[0] < np.log(1 / k) < span[1]]
            top.set_xticks([np.log(1 / k) for k in ticks], [f"r = {k:g}" for k in ticks],
                           fontsize=7)
    fig.tight_layout()
    return fig
