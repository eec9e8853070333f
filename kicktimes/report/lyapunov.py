r"""Finite-time Lyapunov exponents: λ against radius (the paper's Fig. 6), the stretching
per perturbation λ/Γ beside it, and the ln(1/r) relation between the two systems.

A disk-disk collision defocuses: a small change of the impact point is magnified by about
the inverse radius, so one collision stretches a deviation by about ln(1/r) nats more than
a state-blind kick, which only redraws a direction. With the kick rate equal to the
collision rate, that is why the kicked FTLE stays well below the two-particle one. The
figure computes both stretchings per perturbation and draws their difference against
ln(1/r).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from kicktimes.render.figures import (
    DIAGNOSTIC_LABELS,
    SCATTER_SYSTEMS,
    kick_groups,
    radius_axis,
    system_label,
    system_style,
)
from kicktimes.render.pages import number_text
from kicktimes.report.context import Section
from kicktimes.report.effects import Effect, store_ratio
from kicktimes.report.store import REFERENCE, distinct, kicked_systems, wide
from kicktimes.report.summary import diagnostic_summary, diagnostic_vs_radius
from kicktimes.stats import stretching_per_perturbation

__all__ = ["SCATTER_SYSTEMS", "stretching_table", "stretching_figure", "sections", "effects"]


def _perturbations(results, system):
    """Per (radius, ic): the number of perturbations of disk 0 in ``system``."""
    name = "n_pp" if system == REFERENCE else "n_kicks"
    part = results[(results["diagnostic"] == name) & (results["system"] == system)]
    return part.set_index(["radius", "ic"])["value"]


def stretching_table(results) -> pd.DataFrame:
    r"""Stretching per perturbation :math:`\bar\lambda / \Gamma` per radius and system.

    :math:`\Gamma = \sum_i n_i / \sum_i T_i` is the pooled perturbation rate of the system
    (disk-disk collisions of disk 0 for the two-particle system, kicks for a kicked one),
    :math:`\bar\lambda` the mean FTLE over the ICs; :math:`\bar\lambda/\Gamma` is in nats
    per perturbation, with its 95 % interval ``stretch_low, stretch_high`` from a
    bootstrap over the ICs of the radius (`kicktimes.stats.cluster_bootstrap`, 999
    resamples, seeded by the radius). ``stored_median`` is the median of the store's per-IC
    ``lyapunov_per_perturbation`` rows when the store has them (NaN otherwise).
    Also ``ln_inv_r`` = ln(1/r).
    """
    from kicktimes.stats import cluster_bootstrap

    rows = []
    for system in results["system"].unique():
        lam = results[(results["diagnostic"] == "lyapunov") & (results["system"] == system)]
        t = results[(results["diagnostic"] == "t_max") & (results["system"] == system)]
        n = _perturbations(results, system)
        if lam.empty or t.empty or n.empty:
            continue
        lam = lam.set_index(["radius", "ic"])["value"]
        t = t.set_index(["radius", "ic"])["value"]
        stored = results[
            (results["diagnostic"] == "lyapunov_per_perturbation") & (results["system"] == system)
        ]
        stored = stored.groupby("radius", observed=True)["value"].median()
        frame = pd.concat({"lam": lam, "t": t, "n": n}, axis=1).dropna()
        for r, g in frame.groupby(level="radius", observed=True):
            rate = g["n"].sum() / g["t"].sum()
            arrays = [g[c].to_numpy(float) for c in ("lam", "n", "t")]
            boot = cluster_bootstrap(
                lambda idx, a=arrays: stretching_per_perturbation(*(v[idx] for v in a), axis=1),
                len(g), n_boot=999, rng=np.random.default_rng([2013, round(r * 1e6)]))
            rows.append(
                {
                    "radius": r,
                    "system": system,
                    "lambda_mean": g["lam"].mean(),
                    "perturbation_rate": rate,
                    "stretch_per_perturbation": stretching_per_perturbation(
                        g["lam"].to_numpy(), g["n"].to_numpy(), g["t"].to_numpy()),
                    "stretch_low": boot.ci_low, "stretch_high": boot.ci_high,
                    "stored_median": stored.get(r, np.nan),
                    "ln_inv_r": np.log(1 / r),
                }
            )
    return pd.DataFrame(rows)


def stretching_figure(summary, table, *, title=None):
    r"""The FTLE against r, split by kick kind, its stretching per perturbation and the
    excess of a collision over a kick.

    Top row: λ against r with the two-particle curve and (a) the kicked systems whose kicks
    redraw the direction by the kick-angle rule ("uniform kicks"), (b) those whose kicks
    scatter (``SCATTER_SYSTEMS``), on one y scale, so no curve lies on another's; (c) the
    excess :math:`\lambda/\Gamma` of the two-particle system over each kicked system
    against :math:`\ln(1/r)`, with the identity line. Bottom row: (d), (e) the stretching
    per perturbation :math:`\lambda/\Gamma` of the same groups; the sixth cell holds the
    one legend (systems in colour and marker, the same in every panel, and the error bars).

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`~kicktimes.report.summary.diagnostic_summary` of the ``lyapunov`` rows.
    table : pandas.DataFrame
        :func:`stretching_table`.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        2 x 3 cells; the legend has its own cell, so it covers no point.
    """
    fig = Figure(figsize=(13.0, 7.6), layout="constrained")
    axes = fig.subplots(2, 3)
    present = distinct(summary, "system") | distinct(table, "system")
    systems = [s for s in (REFERENCE, *kicked_systems(table)) if s in present]
    groups = kick_groups(systems)
    letters = "ab"
    top = axes[0, :2]
    lam_systems = distinct(summary, "system")
    handles = {}
    for k, (name, members) in enumerate(groups):
        ax = top[k]
        drawn = [s for s in members if s in lam_systems]
        label = f"({letters[k]}) FTLE λ" + (f", {name}" if name else "")
        if drawn:
            diagnostic_vs_radius(summary, "lyapunov", systems=drawn, ax=ax, title=label,
                                 medians=True)
            legend = ax.get_legend()
            texts = [t.get_text() for t in legend.get_texts()]
            for h, t in zip(legend.legend_handles, texts, strict=True):
                handles.setdefault(t, h)  # the bar and median proxies
            legend.remove()
        ax.set_title(label)
    # one y scale for both groups, covering every mean, bar and median: no point is
    # clipped (nor marked as clipped), as a single group's robust limits would do
    shown = summary[summary["system"].isin([s for _, m in groups for s in m])]
    reach = np.maximum(shown["paper_err"], shown["sem"])
    ends = np.concatenate([shown["mean"] - reach, shown["mean"] + reach, shown["median"]])
    ends = ends[np.isfinite(ends)]
    for ax in top:
        for note in list(ax.texts):
            note.remove()
        if ends.size:
            pad = 0.05 * (ends.max() - ends.min() or abs(ends.max()) or 1.0)
            ax.set_ylim(ends.min() - pad, ends.max() + pad)
    if len(groups) == 1:
        top[1].set_visible(False)
    for k, (name, members) in enumerate(groups):
        ax = axes[1, k]
        for system in members:
            part = table[table["system"] == system].sort_values("radius")
            style = system_style(system, systems.index(system))
            y = part["stretch_per_perturbation"].to_numpy(float)
            err = np.vstack([y - part["stretch_low"], part["stretch_high"] - y])
            ax.errorbar(part["radius"], y, yerr=np.clip(err, 0, None), marker=style["marker"],
                        color=style["color"], markersize=4, capsize=2, linewidth=1.0,
                        label=system_label(system))
        radius_axis(ax)
        ax.set_ylabel("λ / Γ (nats per perturbation)")
        ax.set_title(f"({'de'[k]}) stretching per perturbation" + (f", {name}" if name else ""))
        ax.set_ylim(bottom=0)
    if len(groups) > 1:
        top_y = max(ax.get_ylim()[1] for ax in axes[1, :2])
        for ax in axes[1, :2]:
            ax.set_ylim(0, top_y)
    else:
        axes[1, 1].set_visible(False)
    ax3 = axes[0, 2]
    ref = table[table["system"] == REFERENCE].set_index("radius")
    grid = np.sort(ref.index.to_numpy(float))
    # against r, as every other panel, dodged by a fifth of the smallest gap
    gap = np.diff(grid).min() / 5 if grid.size > 1 else 0.0
    kicked = systems[1:]
    for k, system in enumerate(kicked, start=1):
        part = table[table["system"] == system].set_index("radius")
        excess = (ref["stretch_per_perturbation"] - part["stretch_per_perturbation"]).dropna()
        # the two 95 % half-widths in quadrature: as if the runs were independent, wider
        # than a paired interval would be for the positively correlated runs of one IC
        half = np.sqrt(((ref["stretch_high"] - ref["stretch_low"]) / 2) ** 2
                       + ((part["stretch_high"] - part["stretch_low"]) / 2) ** 2)
        half = half.reindex(excess.index).to_numpy(float)
        style = system_style(system, k)
        shift = gap * ((k - 1) / max(len(kicked) - 1, 1) - 0.5)
        ax3.errorbar(excess.index.to_numpy() + shift, excess.to_numpy(),
                     yerr=np.where(np.isfinite(half), half, 0.0), linestyle="none",
                     marker=style["marker"], markersize=5, color=style["color"], capsize=2,
                     elinewidth=0.8)
    if grid.size:
        r = np.linspace(grid.min(), grid.max(), 60)
        (identity,) = ax3.plot(r, np.log(1 / r), color="grey", linestyle=":")
        handles["ln(1/r), the guide of (c)"] = identity
    radius_axis(ax3)
    # ln(1/r) is a pure number; the guide reads it as nats per collision
    ax3.set_ylabel("excess λ/Γ (nats per perturbation)")
    ax3.set_title("(c) two-particle λ/Γ minus each kicked one\n(bars: the two 95 % CIs in "
                  "quadrature)", fontsize="medium")
    # the legend's own cell: systems first (their colour and marker in every panel)
    cell = axes[1, 2]
    cell.axis("off")
    for k, system in enumerate(systems):
        style = system_style(system, k)
        handles[system_label(system)] = Line2D([], [], color=style["color"],
                                               marker=style["marker"], markersize=5)
    order = [system_label(s) for s in systems]
    order += [t for t in handles if t not in order]
    cell.legend([handles[t] for t in order], order, loc="center", fontsize="small",
                frameon=False, title="systems (colour, marker) and bars", title_fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def sections(ctx):
    """The FTLE section: figure, stretching table, per-radius ratios."""
    results, exp = ctx.results, ctx.exp
    if "lyapunov" not in distinct(results, "diagnostic"):
        return []
    title = DIAGNOSTIC_LABELS["lyapunov"][0]
    if getattr(exp, "lyapunov_variant", "") == "paper":
        title += " (paper variant: max(λˣ, λʸ))"
    sec = Section("lyapunov", f"{title} against radius")
    summary = diagnostic_summary(results, diagnostic="lyapunov")
    table = stretching_table(results)
    sec.figure(
        "fig05_lyapunov_vs_radius",
        stretching_figure(summary, table),
        f"(a), (b) {title} of disk 0, mean over ICs (filled, thick pale bars ± std/10 as in "
        "the paper, thin capped bars ± s.e.m.) and median (open, dotted), with the "
        "two-particle curve and (a) the kicked systems whose kicks redraw the direction "
        "(uniform kicks), (b) those whose kicks scatter, on one y scale; (d), (e) stretching "
        "per perturbation λ/Γ of the same groups with 95 % bootstrap intervals over ICs, Γ "
        "the pooled rate of disk-disk collisions (two-particle, sticky runs included: they "
        "raise Γ where they occur) or kicks (kicked); (c) two-particle minus kicked "
        "stretching per perturbation against r, in each kicked system's colour and marker, "
        "with the guide ln(1/r): the extra stretching a defocusing collision gives over a "
        "state-blind kick. Systems are shifted slightly along r so that they do not hide "
        "each other.",
    )
    parts = []
    ref = table[table["system"] == REFERENCE].set_index("radius")
    for system in kicked_systems(results):
        part = table[table["system"] == system].set_index("radius")
        if part.empty or ref.empty:
            continue
        excess = ref["stretch_per_perturbation"] - part["stretch_per_perturbation"]
        r0 = float(ref.index.min())
        slope = np.nan
        ok = excess.dropna()
        if ok.size >= 2:
            x = np.log(1 / ok.index.to_numpy())
            slope = float(np.sum(x * ok.to_numpy()) / np.sum(x * x))
        parts.append(
            f"{system_label(system)}: at r = {r0:g} the stretching per perturbation is "
            f"{number_text(ref.loc[r0, 'stretch_per_perturbation'])} nats per disk-disk collision "
            f"against {number_text(part.loc[r0, 'stretch_per_perturbation'])} per kick, an excess "
            f"of {number_text(excess.loc[r0])} nats (ln(1/r) = {number_text(np.log(1 / r0))}); "
            f"least-squares slope of the excess on ln(1/r) through 0: {number_text(slope)} "
            "(1 if the excess is ln(1/r))"
        )
    if parts:
        sec.text(
            "Kick rate equals collision rate by construction, so the FTLE gap is a gap in "
            "stretching per perturbation: " + "; ".join(parts) + "."
        )
    sec.table("lyapunov_stretching", table, "FTLE and stretching per perturbation")
    wide_t = summary.pivot(index="radius", columns="system", values=["mean", "median", "sem"])
    wide_t.columns = [f"{stat}_{system}" for stat, system in wide_t.columns]
    sec.table("lyapunov_by_radius", wide_t.reset_index(), f"{title}: mean per radius")
    return [sec]


def effects(ctx):
    """FTLE of each kicked system over the two-particle FTLE."""
    results = ctx.results
    if "lyapunov" not in distinct(results, "diagnostic"):
        return []
    lam = wide(results, "lyapunov")
    table = stretching_table(results)
    out = []
    for system in kicked_systems(results):
        if system not in lam.columns or REFERENCE not in lam.columns:
            continue
        per_r, tot = store_ratio(ctx, lam[system], lam[REFERENCE])
        ref = table[table["system"] == REFERENCE].set_index("radius")
        kick = table[table["system"] == system].set_index("radius")
        detail = (f"per-radius ratio {number_text(per_r['ratio'].min())} to "
                  f"{number_text(per_r['ratio'].max())}")
        if not ref.empty and not kick.empty:
            r0 = float(ref.index.min())
            detail += (
                f"; stretching per perturbation at r = {r0:g}: "
                f"{number_text(ref.loc[r0, 'stretch_per_perturbation'])} nats per collision vs "
                f"{number_text(kick.loc[r0, 'stretch_per_perturbation'])} per kick "
                f"(ln(1/r) = {number_text(np.log(1 / r0))})"
            )
        out.append(
            Effect.of_ratio(
                "FTLE",
                system,
                "ratio of mean λ (kicked / two-particle, averaged over radii)",
                tot,
                tolerance=ctx.tolerance,
                detail=detail,
            )
        )
    return out
