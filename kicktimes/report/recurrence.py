r"""Recurrence rates and recurrence quantification against radius (the paper's Fig. 7).

The paper's recurrence rate counts every pair (i, j), the main diagonal i = j included:
:math:`RR = 1/N + (1 - 1/N)\,RR_{\rm off}`, with :math:`RR_{\rm off}` the rate over pairs
i ≠ j. At ε = 10⁻³ the diagonal dominates (RR ≈ 1.15/N), so the paper's RR hardly
distinguishes the systems; every figure and table here shows the off-diagonal rate beside
it, at each threshold of the experiment, and DET (the share of off-diagonal recurrences on
diagonal lines of length ≥ 2) where the store has it.

Store rows (per eps ``e`` formatted ``f"{e:g}"``): ``rr@e``, ``rr_offdiag@e``, ``det@e``.
Old stores have only ``recurrence_rate`` at one ε; the off-diagonal rate is then derived
as :math:`(N\,RR - 1)/(N - 1)` with N = ``n_steps`` + 1 samples (the run's own samples),
and DET is missing.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from kicktimes.report.common import (
    REFERENCE,
    Section,
    distinct,
    eps_values,
    fmt,
    kicked_systems,
    wide,
)
from kicktimes.report.effects import Effect, store_ratio
from kicktimes.report.figures import plain_ticks, radius_axis, shared_legend
from kicktimes.report.summary import diagnostic_summary, diagnostic_vs_radius

__all__ = ["recurrence_rows", "sampling_statement", "rr_figure", "sections", "effects"]

_QUANTITIES = {
    "rr": ("paper's RR (all pairs, diagonal included)", "RR (fraction of pairs)"),
    "rr_offdiag": ("off-diagonal RR (pairs i ≠ j)", "off-diagonal RR (fraction of pairs)"),
    "det": ("DET (determinism)", "DET (share of recurrences on lines)"),
}


def n_samples(exp):
    """Samples per run behind the stored RR: the initial point and one per step."""
    return exp.n_steps + 1


def recurrence_rows(results, exp):
    """Tidy rows ``rr@e``, ``rr_offdiag@e``, ``det@e`` for every ε of the experiment.

    Returns ``(rows, notes)``: rows as in the store (``diagnostic`` = ``"rr@0.001"``...),
    taken from the store where present, else derived from ``recurrence_rate`` (old
    stores, first ε only), and the notes saying what was derived or is missing.
    """
    have = set(results["diagnostic"].unique())
    out, notes = [], []
    for k, e in enumerate(eps_values(exp)):
        tag = f"{e:g}"
        if f"rr@{tag}" in have:
            out.append(results[results["diagnostic"].isin([f"{q}@{tag}" for q in _QUANTITIES])])
            continue
        if k > 0 or "recurrence_rate" not in have:
            notes.append(f"ε = {tag}: no recurrence rows in the store.")
            continue
        rr = results[results["diagnostic"] == "recurrence_rate"]
        n = n_samples(exp)
        off = rr.assign(diagnostic=f"rr_offdiag@{tag}", value=(n * rr["value"] - 1) / (n - 1))
        out += [rr.assign(diagnostic=f"rr@{tag}"), off]
        notes.append(
            f"ε = {tag}: the store predates the off-diagonal and DET rows; the off-diagonal "
            f"rate is derived from the stored RR as (N·RR − 1)/(N − 1) with N = {n} samples, "
            "and DET is not available (rerun the sweep for it)."
        )
    rows = pd.concat(out, ignore_index=True) if out else results.iloc[:0]
    return rows, notes


def sampling_statement(exp):
    """Which samples the recurrence rate uses, in words."""
    rr_sampling = getattr(exp, "rr_sampling", "run")
    if rr_sampling == "uniform":
        return (
            f"The recurrence rates use samples at k·τ (τ = {exp.tau:g}) over each run's "
            "horizon, from a uniformly sampled re-run of the same trajectory with the same kicks."
        )
    what = (
        "the paper's collision-truncated steps (a step ends early at every collision, so "
        "samples cluster at collisions and many off-diagonal recurrences at small ε are pairs "
        "of samples taken at boundary hits on the rim)"
        if exp.sampling == "paper"
        else f"uniform steps of τ = {exp.tau:g}"
    )
    return (
        f"The recurrence rates use the run's own {n_samples(exp)} samples (initial point and "
        f"{exp.n_steps} steps): {what}."
    )


def rr_figure(rows, exp, *, radii=None, title=None):
    """Small multiples: one row per ε, columns paper's RR / off-diagonal RR / DET.

    Parameters
    ----------
    rows : pandas.DataFrame
        :func:`recurrence_rows` output.
    exp : Experiment
        For N (the 1/N guide of the main diagonal) and ε.
    radii : sequence of float, optional
        Only these radii (a zoom, as the paper's bottom panel).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if radii is not None:
        rows = rows[rows["radius"].isin(list(radii))]
    eps = [e for e in eps_values(exp) if f"rr@{e:g}" in distinct(rows, "diagnostic")]
    quantities = [
        q for q in _QUANTITIES if any(f"{q}@{e:g}" in distinct(rows, "diagnostic") for e in eps)
    ]
    fig = Figure(figsize=(4.6 * len(quantities), 3.8 * max(len(eps), 1)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(max(len(eps), 1), len(quantities), squeeze=False))
    summary = diagnostic_summary(rows) if len(rows) else None
    n = n_samples(exp)
    for i, e in enumerate(eps):
        for j, q in enumerate(quantities):
            ax = axes[i, j]
            name = f"{q}@{e:g}"
            if summary is None or name not in distinct(summary, "diagnostic"):
                ax.text(0.5, 0.5, "not in the store", transform=ax.transAxes, ha="center")
                radius_axis(ax)
                ax.set_ylabel(_QUANTITIES[q][1])
                continue
            diagnostic_vs_radius(
                summary,
                name,
                ax=ax,
                medians=True,
                title=f"{_QUANTITIES[q][0]}, ε = {e:g}",
                ylabel=_QUANTITIES[q][1],
            )
            plain_ticks(ax.yaxis)
            if q == "rr":
                # from 0: the paper's RR is mostly the diagonal 1/N, and the axis shows it
                ax.set_ylim(0.0, 1.05 * ax.get_ylim()[1])
                ax.axhline(1.0 / n, color="grey", linestyle="--", linewidth=0.8)
                ax.text(
                    0.02,
                    0.45,
                    f"dashed: 1/N = {1.0 / n:.3g}, the main diagonal alone",
                    transform=ax.transAxes,
                    fontsize="x-small",
                    color="grey",
                )
    shared_legend(fig, axes.ravel())
    if title:
        fig.suptitle(title)
    return fig


def _sticky_table(rows, sticky):
    """Mean, median and sticky-free mean per radius, system and quantity."""
    values = rows["value"].to_numpy()
    flag = None
    if sticky is not None:
        # each row's flag, looked up once (not once per group: ~700 groups at paper scale)
        flags = sticky.set_index(["radius", "ic"])["sticky"]
        where = pd.MultiIndex.from_frame(rows[["radius", "ic"]])
        flag = flags.reindex(where).fillna(False).astype(bool).to_numpy()
    out = []
    groups = rows.groupby(["radius", "system", "diagnostic"], observed=True).indices
    for (r, system, diagnostic), idx in sorted(groups.items(), key=lambda kv: kv[0]):
        # the group's values in row order as a Series: the same sums as before, bit for bit
        v = pd.Series(values[idx])
        entry = {
            "radius": r,
            "system": system,
            "quantity": diagnostic,
            "n": int(v.notna().sum()),
            "mean": v.mean(),
            "median": v.median(),
        }
        if flag is not None:
            f = flag[idx]
            entry["n_sticky"] = int(f.sum())
            entry["mean_without_sticky"] = v[~f].mean()
        out.append(entry)
    return pd.DataFrame(out)


def sections(ctx):
    """The recurrence section: RR beside the off-diagonal rate and DET at every ε."""
    exp = ctx.exp
    rows, notes = recurrence_rows(ctx.results, exp)
    ctx.found.recurrence_rows = rows
    if rows.empty:
        return []
    sec = Section("recurrence_rate", "Recurrence rate, off-diagonal rate and DET against radius")
    sec.figure(
        "fig06_recurrence_rate_vs_radius",
        rr_figure(rows, exp),
        "Per threshold ε (rows): the paper's recurrence rate (all pairs, axis from 0; "
        "dashed: 1/N, the main diagonal alone), the off-diagonal rate (pairs i ≠ j) and DET, "
        "per system: mean over ICs (filled; thick pale bars ± std/10 as in the paper, thin capped "
        "bars ± s.e.m.) and median (open, dotted). " + sampling_statement(exp),
    )
    sec.text(sampling_statement(exp))
    for note in notes:
        sec.text(note)
    table = _sticky_table(rows, ctx.found.sticky)
    n = n_samples(exp)
    for e in eps_values(exp):
        rr = table[(table["quantity"] == f"rr@{e:g}") & (table["system"] == REFERENCE)]
        if rr.empty:
            continue
        share = 1.0 / (n * rr["mean"])
        sec.text(
            f"ε = {e:g}: the two-particle RR is {fmt(rr['mean'].min() * n)}/N to "
            f"{fmt(rr['mean'].max() * n)}/N over the radii, so the main diagonal is "
            f"{fmt(100 * share.min())}–{fmt(100 * share.max())} % of it; compare the systems "
            "on the off-diagonal rate and DET, not on the paper's RR."
        )
    sec.table(
        "recurrence_by_radius",
        table,
        "Recurrence quantities per radius and system (mean, median; sticky ICs flagged)",
    )
    return [sec]


def family_figure(stores):
    """The paper's Fig. 7 layout from the first store (family A): top all radii, bottom a
    zoom on its smaller half of the radii; paper's RR and off-diagonal RR at the first ε."""
    store = stores[0]
    exp = store.experiment
    rows, _ = recurrence_rows(store.results, exp)
    e = eps_values(exp)[0]
    rows = rows[rows["diagnostic"].isin([f"rr@{e:g}", f"rr_offdiag@{e:g}"])]
    if rows.empty:
        return None
    radii = np.sort(rows["radius"].unique())
    small = radii[: max(2, (radii.size + 1) // 2)]
    summary = diagnostic_summary(rows)
    fig = Figure(figsize=(10.0, 7.6), layout="constrained")
    axes = fig.subplots(2, 2)
    for i, sel in enumerate((radii, small)):
        part = summary[summary["radius"].isin(sel)]
        for j, q in enumerate(("rr", "rr_offdiag")):
            where = "all radii" if i == 0 else f"zoom: r ≤ {sel.max():g}"
            diagnostic_vs_radius(
                part,
                f"{q}@{e:g}",
                ax=axes[i, j],
                medians=True,
                title=f"{_QUANTITIES[q][0]}\n{where}",
                ylabel=_QUANTITIES[q][1],
            )
            plain_ticks(axes[i, j].yaxis)
            if q == "rr":
                axes[i, j].set_ylim(0.0, 1.05 * axes[i, j].get_ylim()[1])
                axes[i, j].axhline(1.0 / n_samples(exp), color="grey", linestyle="--", lw=0.8)
    for ax in axes.ravel():
        ax.title.set_fontsize("medium")
    fig.suptitle(f"{exp.name}: recurrence rates at ε = {e:g} (the paper's Fig. 7 layout)",
                 fontsize="medium")
    shared_legend(fig, axes.ravel())
    return fig, (
        f"Recurrence rates of {exp.name} at ε = {e:g} in the paper's Fig. 7 layout: top all "
        f"radii, bottom a zoom on r ≤ {small.max():g}; left the paper's RR (diagonal "
        "included, axis from 0, dashed: 1/N), right the off-diagonal rate. "
        + sampling_statement(exp)
    )


def effects(ctx):
    """Off-diagonal RR and DET of each kicked system over the two-particle values."""
    rows = ctx.found.recurrence_rows
    if rows is None:
        rows, _ = recurrence_rows(ctx.results, ctx.exp)
    out = []
    for e in eps_values(ctx.exp):
        for q, question in (("rr_offdiag", "Off-diagonal RR"), ("det", "DET")):
            name = f"{q}@{e:g}"
            if name not in distinct(rows, "diagnostic"):
                continue
            values = wide(rows, name)
            for system in kicked_systems(rows):
                if system not in values.columns or REFERENCE not in values.columns:
                    continue
                per_r, tot = store_ratio(ctx, values[system], values[REFERENCE])
                med = values.groupby(level="radius").median()
                out.append(
                    Effect.of_ratio(
                        f"{question} (ε = {e:g})",
                        system,
                        "ratio of means (kicked / two-particle, averaged over radii)",
                        tot,
                        tolerance=ctx.tolerance,
                        detail=(
                            f"per-radius ratio {fmt(per_r['ratio'].min())} to "
                            f"{fmt(per_r['ratio'].max())}; ratio of per-radius medians "
                            f"{fmt((med[system] / med[REFERENCE]).min())} to "
                            f"{fmt((med[system] / med[REFERENCE]).max())}"
                        ),
                    )
                )
    return out
