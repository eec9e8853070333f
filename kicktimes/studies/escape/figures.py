"""The escape study's figure: Kaplan-Meier survival per system, one panel per radius."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from kicktimes.render.figures import survival_steps, system_style
from kicktimes.stats import MIN_AT_RISK, kinetic_rate
from kicktimes.studies.escape.compute import LABELS, RADII, SYSTEMS

__all__ = ["survival_figure"]

#: how each system's measured curve is drawn: the two disks thin and on top (the
#: reference every curve is read against), the uniform-kick curve that lies on it wider,
#: half transparent and below, the scatter-kick curve dashed between them, so that all
#: three show where they coincide; the controls plain
_LINES = {
    "two_particle": {"linewidth": 1.3, "linestyle": "-", "zorder": 6},
    "poisson_scatter": {"linewidth": 1.3, "linestyle": (0, (4, 2)), "zorder": 5},
    "poisson": {"linewidth": 2.6, "linestyle": "-", "alpha": 0.55, "zorder": 4},
    None: {"linewidth": 1.4, "linestyle": "-", "zorder": 3},
}


def survival_figure(curves):
    """Kaplan-Meier survival of disk 0's escape per system, one log-log panel per radius
    (``curves``: `escape_tables`' third value); returns a `matplotlib.figure.Figure`.

    Each curve is drawn with its 95 % band while at least `kicktimes.stats.MIN_AT_RISK`
    runs are at risk, beyond that (`kicktimes.stats.reliable_until`) as a thin grey dotted
    line without a band (`kicktimes.render.figures.survival_steps`): the
    two-disk curve's risk set is emptied by disk 1's escapes (partner censoring), and its
    last steps, each one of a handful of runs, would read as physics. The two-disk curve is
    drawn thin and on top, the uniform-kick curve wide and half transparent below it, the
    scatter-kick curve dashed between (``_LINES``): where they coincide, all three show."""
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
            survival_steps(ax, km, color=styles[system]["color"], label=LABELS[system],
                           line=_LINES.get(system, _LINES[None]), gid=f"few_at_risk_{system}")
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
    handles.append(Line2D([], [], color="0.6", linewidth=0.8, linestyle=":"))
    labels.append(f"any curve where fewer than {MIN_AT_RISK} runs are at risk")
    fig.legend(handles, labels, loc="outside lower center", ncol=4,
               fontsize="small")
    fig.suptitle("Escape through one hole (half-width 0.05 rad): who escapes like the two "
                 "disks?", fontsize="medium")
    return fig
