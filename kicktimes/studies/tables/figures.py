"""The tables study's figure: per kicked system, the kicked / two-disk FTLE ratio against
the radius in each table, under each collision rule."""

from __future__ import annotations

from kicktimes.stats import margin_of
from kicktimes.studies.tables.compare import KICKED

__all__ = ["tables_figure"]

COLOURS = {"circle": "black", "ellipse": "tab:green", "stadium": "tab:red"}
MARKERS = {"mirror": "o", "elastic": "s"}


def tables_figure(curves):
    """One panel per kicked system: the ratio per radius (primary control; mirror rule
    filled, elastic open) with its 95 % interval (bootstrap clustered on ICs), one colour
    per table, the FTLE's margin around 1 shaded. ``curves`` is `compare.findings`'s
    second table."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tol = margin_of("ftle")
    c = curves[(curves["diagnostic"] == "ftle") & (curves["control"] == "primary")]
    fig, axes = plt.subplots(1, len(KICKED), figsize=(13.5, 4.2), sharey=True)
    tables = [t for t in COLOURS if t in set(c["table"])]
    for ax, (system, name) in zip(axes, KICKED.items(), strict=True):
        for k, table in enumerate(tables):
            for j, rule in enumerate(("mirror", "elastic")):
                g = c[(c["system"] == system) & (c["table"] == table)
                      & (c["rule"] == rule)].sort_values("radius")
                if g.empty:
                    continue
                x = g["radius"].to_numpy() * (1 + 0.04 * (k - 1) + 0.015 * j)
                y = g["ratio"].to_numpy()
                ax.errorbar(x, y, yerr=[y - g["ci_low"].to_numpy(), g["ci_high"].to_numpy() - y],
                            fmt=MARKERS[rule] + "-", color=COLOURS[table], ms=5, capsize=3,
                            lw=0.8, mfc=COLOURS[table] if rule == "mirror" else "white",
                            label=f"{table}, {rule}")
        ax.axhspan(1 - tol, 1 + tol, color="0.9", zorder=0)
        ax.axhline(1.0, color="0.5", lw=0.8)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("disk radius r")
        ax.set_xticks([0.01, 0.02, 0.03])
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("kicked / two-disk FTLE")
    axes[0].set_ylim(0.0, 1.12)
    axes[0].legend(fontsize=7, loc="lower left", ncol=3)
    fig.suptitle(f"The kicked disk's FTLE over the two disks' in each table "
                 f"(95 % intervals; band: ±{100 * tol:g} %)", fontsize=11)
    fig.tight_layout()
    return fig
