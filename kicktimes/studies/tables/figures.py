"""The tables study's figure: the kicked / two-disk FTLE and RR ratios against the radius in
each table, and the mean FTLEs beside the free disk's."""

from __future__ import annotations

from kicktimes.stats import margin_of
from kicktimes.studies.tables.compare import KICKED

__all__ = ["tables_figure"]

COLOURS = {"circle": "black", "ellipse": "tab:green", "stadium": "tab:red"}
MARKERS = {"mirror": "o", "elastic": "s"}
SYSTEM_STYLE = {"two_particle": ("two disks", "o"), "poisson": (KICKED["poisson"], "s"),
                "poisson_scatter": (KICKED["poisson_scatter"], "^")}


def _bars(ax, x, g, est, colour, marker, filled, label):
    y = g[est].to_numpy()
    ax.errorbar(x, y, yerr=[y - g["ci_low"].to_numpy(), g["ci_high"].to_numpy() - y],
                fmt=marker + "-", color=colour, ms=5, capsize=3, lw=0.8,
                mfc=colour if filled else "white", label=label)


def _ratio_panel(ax, c, diagnostic, system, tables, band, title):
    """The kicked / two-disk ratio of ``diagnostic`` per radius, one colour per table."""
    for k, table in enumerate(tables):
        for j, rule in enumerate(("mirror", "elastic")):
            g = c[(c["diagnostic"] == diagnostic) & (c["system"] == system)
                  & (c["table"] == table) & (c["rule"] == rule)].sort_values("radius")
            if not g.empty:
                x = g["radius"].to_numpy() * (1 + 0.04 * (k - 1) + 0.015 * j)
                _bars(ax, x, g, "ratio", COLOURS[table], MARKERS[rule], rule == "mirror",
                      f"{table}, {rule}")
    ax.axhspan(1 - band, 1 + band, color="0.9", zorder=0)
    ax.axhline(1.0, color="0.5", lw=0.8)
    ax.set_title(title, fontsize=10)


def tables_figure(curves, means_by_radius, free):
    """Four panels against r: the kicked / two-disk FTLE ratio of uniform and of
    scattering kicks at Poisson times, the off-diagonal RR ratio (eps = 0.01, uniform-time
    samples) of uniform kicks (primary control; mirror filled, elastic open; 95 %
    intervals, bootstrap clustered on ICs; each diagnostic's margin around 1 shaded; each
    panel on its own y scale), and the mean FTLE per system and table under the mirror
    rule (log scale) with the free disk's dashed. ``curves``: `compare.findings`'s second
    table; ``means_by_radius``: `compare.mean_ftle` per radius; ``free``:
    `one_disk.free_ftle`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    c = curves[curves["control"] == "primary"]
    fig, axes = plt.subplots(2, 2, figsize=(13, 9))
    tables = [t for t in COLOURS if t in set(c["table"])]
    ftle = margin_of("ftle")
    _ratio_panel(axes[0, 0], c, "ftle", "poisson", tables, ftle,
                 f"FTLE, {KICKED['poisson']}")
    _ratio_panel(axes[0, 1], c, "ftle", "poisson_scatter", tables, ftle,
                 f"FTLE, {KICKED['poisson_scatter']}")
    _ratio_panel(axes[1, 0], c, "rr_offdiag@0.01", "poisson", tables,
                 margin_of("rr_offdiag"), f"off-diagonal RR (ε = 0.01), {KICKED['poisson']}")
    for ax in (axes[0, 0], axes[0, 1], axes[1, 0]):
        ax.set_ylabel("kicked / two-disk")
    axes[0, 0].legend(fontsize=7, loc="center left", bbox_to_anchor=(0.0, 0.42), ncol=2)
    right = axes[1, 1]
    m = means_by_radius[means_by_radius["rule"] == "mirror"]
    for k, table in enumerate(tables):
        for system, (_, marker) in SYSTEM_STYLE.items():
            g = m[(m["table"] == table) & (m["system"] == system)].sort_values("radius")
            x = g["radius"].to_numpy() * (1 + 0.03 * (k - 1))
            _bars(right, x, g, "ftle", COLOURS[table], marker, True, None)
        f = free[(free["table"] == table) & free["radius"].isin(set(m["radius"]))]
        f = f.sort_values("radius")
        right.plot(f["radius"], f["ftle"], "--", color=COLOURS[table], lw=1.2)
    keys = [Line2D([], [], color=COLOURS[t], lw=2, label=t) for t in tables]
    keys += [Line2D([], [], color="0.3", marker=mk, lw=0, label=name)
             for name, mk in SYSTEM_STYLE.values()]
    keys.append(Line2D([], [], color="0.3", ls="--", label="free disk (circle, ellipse: "
                                                           "the ln T / T floor)"))
    right.set_yscale("log")
    right.set_ylim(1e-4, 1.5)   # room below the data for the key
    right.legend(handles=keys, fontsize=7, loc="lower right", ncol=2)
    right.set_ylabel("mean FTLE per unit time")
    right.set_title("mean FTLE, mirror rule", fontsize=10)
    for ax in axes.ravel():
        ax.set_xlabel("disk radius r")
        ax.set_xticks([0.01, 0.02, 0.03])
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig
