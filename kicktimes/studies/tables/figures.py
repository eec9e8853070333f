"""The tables study's figure: the kicked / two-disk FTLE ratio against the radius in each
table (uniform and scattering kicks at Poisson times), and the mean FTLEs beside the free
disk's."""

from __future__ import annotations

from kicktimes.stats import margin_of
from kicktimes.studies.tables.compare import KICKED

__all__ = ["tables_figure"]

COLOURS = {"circle": "black", "ellipse": "tab:green", "stadium": "tab:red"}
MARKERS = {"mirror": "o", "elastic": "s"}
#: the ratio panels (uniform kicks at the collision times give the Poisson kicks' values
#: to within 0.02: in the CSVs)
RATIO_PANELS = ("poisson", "poisson_scatter")
SYSTEM_STYLE = {"two_particle": ("two disks", "o"), "poisson": (KICKED["poisson"], "s"),
                "poisson_scatter": (KICKED["poisson_scatter"], "^")}


def _bars(ax, x, g, est, colour, marker, filled, label):
    y = g[est].to_numpy()
    ax.errorbar(x, y, yerr=[y - g["ci_low"].to_numpy(), g["ci_high"].to_numpy() - y],
                fmt=marker + "-", color=colour, ms=5, capsize=3, lw=0.8,
                mfc=colour if filled else "white", label=label)


def tables_figure(curves, means_by_radius, free):
    """Three panels: the ratio per radius of uniform and of scattering kicks at Poisson
    times (primary control; mirror filled, elastic open; 95 % intervals, bootstrap
    clustered on ICs; the FTLE's margin around 1 shaded; each on its own y scale), and the
    mean FTLE per system and table against r under the mirror rule (log scale) with the
    free disk's as a dashed line. ``curves``: `compare.findings`'s second table;
    ``means_by_radius``: `compare.mean_ftle` per radius; ``free``: `one_disk.free_ftle`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tol = margin_of("ftle")
    c = curves[(curves["diagnostic"] == "ftle") & (curves["control"] == "primary")]
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.6))
    tables = [t for t in COLOURS if t in set(c["table"])]
    for ax, system in zip(axes[:2], RATIO_PANELS, strict=True):
        for k, table in enumerate(tables):
            for j, rule in enumerate(("mirror", "elastic")):
                g = c[(c["system"] == system) & (c["table"] == table)
                      & (c["rule"] == rule)].sort_values("radius")
                if not g.empty:
                    x = g["radius"].to_numpy() * (1 + 0.04 * (k - 1) + 0.015 * j)
                    _bars(ax, x, g, "ratio", COLOURS[table], MARKERS[rule], rule == "mirror",
                          f"{table}, {rule}")
        ax.axhspan(1 - tol, 1 + tol, color="0.9", zorder=0)
        ax.axhline(1.0, color="0.5", lw=0.8)
        ax.set_title(f"kicked / two-disk FTLE: {KICKED[system]}", fontsize=10)
        ax.set_ylabel("kicked / two-disk FTLE")
    axes[0].legend(fontsize=7, loc="center left", bbox_to_anchor=(0.0, 0.42), ncol=2)
    right = axes[2]
    m = means_by_radius[means_by_radius["rule"] == "mirror"]
    for k, table in enumerate(tables):
        for system, (name, marker) in SYSTEM_STYLE.items():
            g = m[(m["table"] == table) & (m["system"] == system)].sort_values("radius")
            x = g["radius"].to_numpy() * (1 + 0.03 * (k - 1))
            _bars(right, x, g, "ftle", COLOURS[table], marker, True,
                  name if k == 0 else None)
        f = free[(free["table"] == table) & free["radius"].isin(set(m["radius"]))]
        f = f.sort_values("radius")
        right.plot(f["radius"], f["ftle"], "--", color=COLOURS[table], lw=1.2,
                   label=f"free disk ({table})")
    right.set_yscale("log")
    right.set_ylabel("mean FTLE per unit time")
    right.set_title("mean FTLE, mirror rule (dashed: the free disk)", fontsize=10)
    right.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    for ax in axes:
        ax.set_xlabel("disk radius r")
        ax.set_xticks([0.01, 0.02, 0.03])
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig
