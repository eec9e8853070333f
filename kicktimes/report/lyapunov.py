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

from kicktimes.report.common import REFERENCE, Section, distinct, fmt, kicked_systems, wide
from kicktimes.report.effects import Effect, store_ratio
from kicktimes.report.figures import (
    DIAGNOSTIC_LABELS,
    radius_axis,
    system_label,
    system_style,
)
from kicktimes.report.summary import diagnostic_summary, diagnostic_vs_radius

__all__ = ["stretching_table", "stretching_figure", "sections", "effects"]


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
    per perturbation. ``stored_median`` is the median of the store's per-IC
    ``lyapunov_per_perturbation`` rows when the store has them (NaN otherwise).
    Also ``ln_inv_r`` = ln(1/r).
    """
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
            rows.append(
                {
                    "radius": r,
                    "system": system,
                    "lambda_mean": g["lam"].mean(),
                    "perturbation_rate": rate,
                    "stretch_per_perturbation": g["lam"].mean() / rate if rate > 0 else np.nan,
                    "stored_median": stored.get(r, np.nan),
                    "ln_inv_r": np.log(1 / r),
                }
            )
    return pd.DataFrame(rows)


def stretching_figure(summary, table, *, title=None):
    """(a) λ against r; (b) stretching per perturbation λ/Γ; (c) its excess in the
    two-particle system over each kicked system against ln(1/r), with the identity line.

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
        Three panels; every legend is outside the axes, below them (one for the systems
        and error bars of (a) and (b), one for the differences of (c)), so no legend
        covers a point.
    """
    fig = Figure(figsize=(14.0, 5.6), layout="constrained")  # room for the legends below
    ax1, ax2, ax3 = fig.subplots(1, 3)
    diagnostic_vs_radius(summary, "lyapunov", ax=ax1, title="(a) FTLE λ", medians=True)
    systems = [s for s in (REFERENCE, *kicked_systems(table)) if s in distinct(table, "system")]
    for k, system in enumerate(systems):
        part = table[table["system"] == system].sort_values("radius")
        style = system_style(system, k)
        ax2.plot(
            part["radius"],
            part["stretch_per_perturbation"],
            marker=style["marker"],
            color=style["color"],
            label=system_label(system),
        )
    radius_axis(ax2)
    ax2.set_ylabel("λ / Γ (nats per perturbation)")
    ax2.set_title("(b) stretching per perturbation")
    ax2.set_ylim(bottom=0)
    ref = table[table["system"] == REFERENCE].set_index("radius")
    grid = np.sort(ref["ln_inv_r"].to_numpy())
    for k, system in enumerate(systems[1:], start=1):
        part = table[table["system"] == system].set_index("radius")
        excess = (ref["stretch_per_perturbation"] - part["stretch_per_perturbation"]).dropna()
        style = system_style(system, k)
        ax3.plot(
            np.log(1 / excess.index.to_numpy()),
            excess.to_numpy(),
            linestyle="none",
            marker=style["marker"],
            color=style["color"],
            label=f"two-particle − {system_label(system)}",
        )
    if grid.size:
        span = np.array([0.0, grid.max() * 1.05])
        ax3.plot(span, span, color="grey", linestyle=":", label="ln(1/r) (identity)")
        ax3.set_xlim(0.9 * grid.min(), 1.05 * grid.max())
    # ln(1/r) is a pure number; the identity line reads it as nats per collision
    ax3.set_xlabel("ln(1/r), r the disk radius in table radii (dimensionless)")
    ax3.set_ylabel("excess λ/Γ (nats per perturbation)")
    ax3.set_title("(c) excess of a collision over a kick")
    # legends outside the axes: inside, (a)'s legend hid two-disk points at r = 0.012-0.016
    handles, labels = ax1.get_legend_handles_labels()
    legend = ax1.get_legend()
    if legend is not None:  # (a)'s proxy entries (error bars, medians) follow the systems
        texts = [t.get_text() for t in legend.get_texts()]
        extra = [(h, t) for h, t in zip(legend.legend_handles, texts, strict=True)
                 if t not in labels]
        handles += [h for h, _ in extra]
        labels += [t for _, t in extra]
        legend.remove()
    fig.legend(handles, labels, loc="outside lower left", ncol=4, fontsize="small",
               title="(a), (b)", title_fontsize="small")
    h3, l3 = ax3.get_legend_handles_labels()
    if h3:
        fig.legend(h3, l3, loc="outside lower right", ncol=1, fontsize="small",
                   title="(c)", title_fontsize="small")
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
    summary = diagnostic_summary(results, "lyapunov")
    table = stretching_table(results)
    sec.figure(
        "fig05_lyapunov_vs_radius",
        stretching_figure(summary, table),
        f"(a) {title} of disk 0, mean over ICs (filled, thick pale bars ± std/10 as in the "
        "paper, thin capped bars ± s.e.m.) and median (open, dotted); (b) stretching per "
        "perturbation λ/Γ, Γ the pooled rate of disk-disk collisions (two-particle) or kicks "
        "(kicked); (c) two-particle minus kicked stretching per perturbation against ln(1/r), "
        "the extra stretching a defocusing collision gives over a state-blind kick.",
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
            f"{fmt(ref.loc[r0, 'stretch_per_perturbation'])} nats per disk-disk collision "
            f"against {fmt(part.loc[r0, 'stretch_per_perturbation'])} per kick, an excess of "
            f"{fmt(excess.loc[r0])} nats (ln(1/r) = {fmt(np.log(1 / r0))}); least-squares "
            f"slope of the excess on ln(1/r) through 0: {fmt(slope)} (1 if the excess is "
            "ln(1/r))"
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
        detail = f"per-radius ratio {fmt(per_r['ratio'].min())} to {fmt(per_r['ratio'].max())}"
        if not ref.empty and not kick.empty:
            r0 = float(ref.index.min())
            detail += (
                f"; stretching per perturbation at r = {r0:g}: "
                f"{fmt(ref.loc[r0, 'stretch_per_perturbation'])} nats per collision vs "
                f"{fmt(kick.loc[r0, 'stretch_per_perturbation'])} per kick "
                f"(ln(1/r) = {fmt(np.log(1 / r0))})"
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
