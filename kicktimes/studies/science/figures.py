"""The figure of the science page: stretching per perturbation and its ratio per radius."""

from __future__ import annotations

import math

import numpy as np

from kicktimes.stats import margin_of

__all__ = ["LEGEND", "stretching_figure"]

LEGEND = {"two_particle": "two disks (per disk-disk collision)",
          "poisson": "uniform kick (Poisson times)",
          "poisson_scatter": "scatter kick (Poisson times)"}


def stretching_figure(per_radius, path):
    """Left: stretching per perturbation against ln(1/r) with intervals; right: the
    kicked / two-disk ratio per radius with its interval and the +-10 % band around 1."""
    from matplotlib.figure import Figure

    from kicktimes.render.figures import system_label, system_style

    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    for k, (system, g) in enumerate(per_radius.groupby("system", sort=False, observed=True)):
        st = system_style(system, k)
        err = [g["stretch_per_perturbation"] - g["ci_low"], g["ci_high"]
               - g["stretch_per_perturbation"]]
        ax.errorbar(g["ln_inv_r"], g["stretch_per_perturbation"], yerr=err, linestyle="-",
                    linewidth=0.8, marker=st["marker"], color=st["color"], capsize=2,
                    label=LEGEND.get(system, system_label(system)))
        if system != "two_particle":
            err = [g["ratio"] - g["ratio_ci_low"], g["ratio_ci_high"] - g["ratio"]]
            bx.errorbar(g["ln_inv_r"], g["ratio"], yerr=err, linestyle="-", linewidth=0.8,
                        marker=st["marker"], color=st["color"], capsize=2,
                        label=LEGEND.get(system, system_label(system)))
    top = per_radius["ln_inv_r"].max()
    for a in (ax, bx):
        a.set_xlabel("ln(1/r)   (r: disk radius / table radius)")
        sec = a.secondary_xaxis("top", functions=(lambda v: v, lambda v: v))
        ticks = [0.03, 0.01, 0.005, 0.002]
        sec.set_xticks([math.log(1 / t) for t in ticks], labels=[f"r={t:g}" for t in ticks])
        a.set_xlim(per_radius["ln_inv_r"].min() - 0.15, top + 0.15)
    ax.set_ylabel("stretching per perturbation λ/Γ (nats)")
    ax.legend(fontsize="small", loc="upper left")
    band = margin_of("ftle")  # the FTLE's margin, the findings tables' and the README's
    bx.axhspan(1 - band, 1 + band, color="0.88", label=f"±{100 * band:g} % around 1")
    bx.axhline(1.0, color="0.5", linewidth=0.8)
    # a log scale: the uniform kick's 0.3-0.4 and the scatter kick's few per cent below 1
    # both readable on one axis
    from kicktimes.report.answers import log_ratio_axis

    values = per_radius[["ratio_ci_low", "ratio_ci_high"]].to_numpy(float)
    values = values[np.isfinite(values) & (values > 0)]
    bx.set_ylim(min(0.9, values.min() / 1.05) if values.size else 0.25,
                max(1.1, values.max() * 1.03) if values.size else 1.15)
    log_ratio_axis(bx)
    bx.set_ylabel("kicked / two-disk stretching (= FTLE ratio)")
    bx.legend(fontsize="small", loc="center right")  # the empty band between the two laws
    fig.savefig(path, dpi=110)
    return fig
