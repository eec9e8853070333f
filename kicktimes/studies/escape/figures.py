"""The escape study's figure: Kaplan-Meier survival per system, one panel per radius."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from kicktimes.report.figures import system_style
from kicktimes.stats import kinetic_rate
from kicktimes.studies.escape.compute import LABELS, RADII, SYSTEMS

__all__ = ["survival_figure"]


def survival_figure(curves):
    """Kaplan-Meier survival of disk 0's escape per system, one log-log panel per radius
    (``curves``: `escape_tables`' third value); returns a `matplotlib.figure.Figure`."""
    styles = {"two_particle": system_style("two_particle"), "poisson": system_style("poisson"),
              "poisson_scatter": system_style("poisson_scatter"),
              "free": {"color": "tab:gray", "marker": "x"},
              "poisson_small_hole": {"color": "tab:brown", "marker": "v"},
              "bursty": {"color": "tab:olive", "marker": "^"}}
    fig = Figure(figsize=(3.2 * len(RADII), 3.6), layout="constrained")
    axes = fig.subplots(1, len(RADII), sharey=True)
    for ax, r in zip(axes, RADII, strict=True):
        for system in [s for s in SYSTEMS if (r, s) in curves]:
            km = curves[(r, system)]
            if km.empty:
                continue
            ax.step(km["time"], km["survival"], where="post", color=styles[system]["color"],
                    label=LABELS[system],
                    linestyle="--" if system == "poisson_scatter" else "-",
                    linewidth={"poisson": 3.0, "poisson_scatter": 1.0}.get(system, 1.5),
                    zorder=3 if system == "poisson_scatter" else 2)
            ax.fill_between(km["time"], km["ci_low"], km["ci_high"], step="post",
                            color=styles[system]["color"], alpha=0.15, linewidth=0)
        tt = np.geomspace(50.0, 3000.0, 20)
        ax.plot(tt, 50.0 / tt * 0.5, color="k", linestyle=":", linewidth=1,
                label="slope of C / t")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 1.05)
        ax.set_xlim(10.0, 3000.0)
        ax.set_title(f"r = {r:g}, Γ(r) = {float(kinetic_rate(r)):.3f}",
                     fontsize="medium")
        ax.set_xlabel("time t")
    axes[0].set_ylabel("survival S(t) (Kaplan-Meier, 95 % CI)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=4,
               fontsize="small")
    fig.suptitle("Escape through one hole (half-width 0.05 rad): who escapes like the two "
                 "disks?", fontsize="medium")
    return fig
