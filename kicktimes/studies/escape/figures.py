"""The escape study's figure: Kaplan-Meier survival per system, one panel per radius."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from kicktimes.render.figures import system_style
from kicktimes.stats import kinetic_rate
from kicktimes.studies.escape.compute import LABELS, RADII, SYSTEMS

__all__ = ["MIN_AT_RISK", "survival_figure", "thin_from"]

#: a Kaplan-Meier curve is drawn as measured while at least this many runs are at risk;
#: beyond, where a few runs make each step (for the two disks: where disk 1's escapes have
#: censored most of disk 0's runs), it is drawn thin and grey, without its band
MIN_AT_RISK = 50


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


def thin_from(km, floor=MIN_AT_RISK):
    """The first time of a Kaplan-Meier table (`kicktimes.stats.escape_survival`) at which
    fewer than ``floor`` runs are at risk (inf: never).

    Parameters
    ----------
    km : pandas.DataFrame
        ``time, survival, ci_low, ci_high, n_at_risk``.
    floor : int
        The least number of runs at risk of a step drawn as measured.

    Returns
    -------
    float

    Examples
    --------
    >>> import pandas as pd
    >>> thin_from(pd.DataFrame({"time": [1.0, 2.0, 3.0], "n_at_risk": [80, 50, 49]}))
    3.0
    """
    if isinstance(floor, bool) or not isinstance(floor, int) or floor < 1:
        raise ValueError(f"floor must be a positive integer, got {floor!r}")
    below = km.loc[km["n_at_risk"] < floor, "time"]
    return float(below.iloc[0]) if len(below) else float("inf")


def survival_figure(curves):
    """Kaplan-Meier survival of disk 0's escape per system, one log-log panel per radius
    (``curves``: `escape_tables`' third value); returns a `matplotlib.figure.Figure`.

    Each curve is drawn with its 95 % band while at least :data:`MIN_AT_RISK` runs are at
    risk, beyond that (:func:`thin_from`) as a thin grey dotted line without a band: the
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
            # as measured up to the first step made by fewer than MIN_AT_RISK runs at risk,
            # holding its value up to that step's time; from there thin and grey (from the
            # held value, so the two parts meet)
            cut = thin_from(km)
            kept = km[km["time"] < cut]
            rest = km[km["time"] >= cut]
            if len(kept) and len(rest):
                kept = pd.concat([kept, kept.iloc[[-1]].assign(time=cut)])
                rest = pd.concat([kept.iloc[[-1]], rest])
            line = _LINES.get(system, _LINES[None])
            ax.step(kept["time"], kept["survival"], where="post",
                    color=styles[system]["color"], label=LABELS[system], **line)
            ax.fill_between(kept["time"], kept["ci_low"], kept["ci_high"], step="post",
                            color=styles[system]["color"], alpha=0.12, linewidth=0, zorder=1)
            if len(rest):
                ax.step(rest["time"], rest["survival"], where="post", color="0.6",
                        linewidth=0.8, linestyle=":", zorder=1, gid=f"few_at_risk_{system}")
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
