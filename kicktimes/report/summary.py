r"""Ensemble summaries of the store's diagnostics and the generic "diagnostic against
radius" figure (the paper's Figs. 6-8 layout), with the kicked-vs-two-particle table.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.lines import Line2D

from kicktimes.render.figures import (
    DIAGNOSTIC_LABELS,
    PAPER_BAR,
    SEM_BAR,
    SYSTEMS,
    check_frame,
    check_radii,
    dodge,
    finite,
    new_axes,
    radius_axis,
    system_label,
    system_style,
)
from kicktimes.report.context import Section
from kicktimes.report.escape import ESCAPE_ROWS
from kicktimes.report.store import REFERENCE, distinct
from kicktimes.validation import keyword_only_after

__all__ = ["diagnostic_summary", "diagnostic_vs_radius", "comparison_table", "sections"]


@keyword_only_after(1, since="0.2.0")
def diagnostic_summary(results, *, diagnostic=None) -> pd.DataFrame:
    r"""Ensemble summary of a tidy results table, per radius x system x diagnostic.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy rows ``radius, ic, system, diagnostic, value`` (``value`` may be NaN: an
        undefined diagnostic, excluded and counted; ±inf is rejected).
    diagnostic : str or sequence of str, optional
        Keep only these diagnostics.

    Returns
    -------
    pandas.DataFrame
        Columns ``radius, system, diagnostic, n, n_valid, mean, median, std, sem,
        paper_err``: mean, median and standard deviation (ddof = 1) of the finite
        values, standard error ``std / sqrt(n_valid)`` and the paper's error bar
        ``std / 10``.
    """
    df = check_frame("results", results, ["radius", "system", "diagnostic", "value"])
    if diagnostic is not None:
        wanted = [diagnostic] if isinstance(diagnostic, str) else list(diagnostic)
        have = set(df["diagnostic"].unique())
        missing = [d for d in wanted if d not in have]
        if missing:
            raise ValueError(
                f"diagnostic {missing[0]!r} is not in results; present: {sorted(have)!r}"
            )
        df = df[df["diagnostic"].isin(wanted)]
    check_radii("results['radius']", df["radius"])
    values = finite("results['value']", df["value"], allow_nan=True)
    df = df.assign(value=values, valid=np.isfinite(values))
    g = df.groupby(["radius", "system", "diagnostic"], sort=True, observed=True)
    out = g.agg(
        n=("value", "size"),
        n_valid=("valid", "sum"),
        mean=("value", "mean"),
        median=("value", "median"),
        std=("value", "std"),
    ).reset_index()
    out["n_valid"] = out["n_valid"].astype(np.int64)
    out["sem"] = out["std"] / np.sqrt(out["n_valid"].where(out["n_valid"] > 0))
    out["paper_err"] = out["std"] / 10.0
    return out


def diagnostic_vs_radius(
    results, diagnostic, *, systems=None, ax=None, title=None, medians=False, ylabel=None
):
    r"""A diagnostic against radius for the three systems, with both kinds of error bar.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy results (see :func:`diagnostic_summary`), or that function's output.
    diagnostic : str
        ``"lyapunov"``, ``"recurrence_rate"``, ``"autocorrelation"``, ...
    systems : sequence of str, optional
        Systems to draw (default: those of ``SYSTEMS`` present in the data).
    ax : matplotlib Axes, optional
    title : str, optional
    medians : bool
        Also draw the per-IC median of each system (open markers, dotted), beside the
        mean: a few extreme ICs move a mean, not a median.
    ylabel : str, optional
        Y-axis label (default: the diagnostic's label with units).

    Returns
    -------
    matplotlib.figure.Figure
        Per system, the ensemble mean with the paper's error bar ± std/10 (thick pale
        bar, no caps) and the standard error ± std/√n_valid (thin bar with caps);
        systems are shifted slightly along r so the bars do not hide each other.
    """
    if not isinstance(diagnostic, str):
        raise TypeError(f"diagnostic must be a string, got {type(diagnostic).__name__}")
    if isinstance(results, pd.DataFrame) and {"mean", "sem", "paper_err"} <= set(results.columns):
        summary = results[results["diagnostic"] == diagnostic]
        if len(summary) == 0:
            raise ValueError(f"diagnostic {diagnostic!r} is not in the summary")
    else:
        summary = diagnostic_summary(results, diagnostic=diagnostic)
    present = [s for s in SYSTEMS if s in distinct(summary, "system")]
    present += sorted(distinct(summary, "system") - set(SYSTEMS))
    if systems is None:
        systems = present
    else:
        systems = [systems] if isinstance(systems, str) else list(systems)
        for s in systems:
            if s not in present:
                raise ValueError(f"systems: {s!r} is not in the data; present: {present!r}")
    fig, ax = new_axes(ax, (6.4, 4.4))
    radii = summary["radius"].to_numpy()
    for k, system in enumerate(systems):
        part = summary[summary["system"] == system].sort_values("radius")
        style = system_style(system, k)
        x = part["radius"].to_numpy() + dodge(radii, k, len(systems))
        y = part["mean"].to_numpy()
        ax.errorbar(
            x,
            y,
            yerr=part["paper_err"].to_numpy(),
            linestyle="none",
            color=style["color"],
            **PAPER_BAR,
        )
        ax.errorbar(
            x,
            y,
            yerr=part["sem"].to_numpy(),
            color=style["color"],
            marker=style["marker"],
            markersize=5,
            linestyle="-",
            label=system_label(system),
            **SEM_BAR,
        )
        if medians:
            ax.plot(
                x,
                part["median"].to_numpy(),
                linestyle=":",
                marker=style["marker"],
                markerfacecolor="none",
                markersize=5,
                color=style["color"],
            )
    _robust_ylim(ax, summary[summary["system"].isin(systems)], medians)
    handles, labels = ax.get_legend_handles_labels()
    handles += [
        Line2D([], [], color="grey", **PAPER_BAR),
        Line2D([], [], color="grey", linewidth=1.0, marker="_", markersize=8),
    ]
    labels += ["± std/10 (paper's bar)", "± std/√n_valid (standard error)"]
    if medians:
        handles.append(
            Line2D([], [], color="grey", linestyle=":", marker="o", markerfacecolor="none")
        )
        labels.append("median over ICs")
    ax.legend(handles, labels, fontsize="x-small")
    name, default_ylabel = DIAGNOSTIC_LABELS.get(diagnostic, (diagnostic, diagnostic))
    radius_axis(ax)
    ax.set_ylabel(ylabel if ylabel is not None else default_ylabel)
    ax.set_title(title if title is not None else name)
    return fig


def _robust_ylim(ax, summary, medians):
    """Keep a single extreme (radius, system) mean from setting the y-range.

    The limits cover every mean ± paper bar and median within 3 interquartile ranges of
    the values' quartiles; a mean beyond is drawn at the edge with its value written
    beside it (an arrow marks the clipped point), so one sticky run cannot flatten the
    other curves.
    """
    lo = summary["mean"] - summary["paper_err"]
    hi = summary["mean"] + summary["paper_err"]
    vals = np.concatenate([lo, hi] + ([summary["median"]] if medians else []))
    vals = vals[np.isfinite(vals)]
    if vals.size < 4:
        return
    q1, q3 = np.percentile(vals, [25, 75])
    iqr = q3 - q1
    top = min(vals.max(), q3 + 3 * iqr)
    bottom = max(vals.min(), q1 - 3 * iqr)
    if top >= vals.max() and bottom <= vals.min():
        return
    pad = 0.06 * (top - bottom if top > bottom else abs(top) or 1.0)
    ax.set_ylim(bottom - pad, top + pad)
    for row in summary.itertuples():
        if row.mean > top + pad or row.mean < bottom - pad:
            # in axes coordinates: the note stays at the edge if a caller moves the limits
            above = row.mean > top
            ax.annotate(f"{row.mean:.3g} ↑" if above else f"{row.mean:.3g} ↓",
                        (row.radius, 0.985 if above else 0.015),
                        xycoords=("data", "axes fraction"), xytext=(4, 0),
                        textcoords="offset points", ha="left", va="top" if above else "bottom",
                        fontsize="x-small", color="dimgrey",
                        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                              "alpha": 0.85})


def comparison_table(summary):
    """Kicked systems against the two-particle one, per radius and diagnostic.

    ``summary`` is :func:`diagnostic_summary`'s output; columns ``radius, diagnostic,
    system, mean, mean_two_particle, ratio, difference, z, median, median_two_particle,
    paper_bars_overlap, sem_bars_overlap`` (``z`` = difference / √(sem² + sem₂²)).
    """
    two = summary[summary["system"] == REFERENCE].set_index(["radius", "diagnostic"])
    rows = []
    for row in summary[summary["system"] != REFERENCE].itertuples():
        key = (row.radius, row.diagnostic)
        if key not in two.index:
            continue
        ref = two.loc[key]
        diff = row.mean - ref["mean"]
        se = math.hypot(row.sem, ref["sem"])
        rows.append(
            {
                "radius": row.radius,
                "diagnostic": row.diagnostic,
                "system": row.system,
                "mean": row.mean,
                "mean_two_particle": ref["mean"],
                "ratio": row.mean / ref["mean"] if ref["mean"] != 0 else math.nan,
                "difference": diff,
                "z": diff / se if se > 0 else math.nan,
                "median": row.median,
                "median_two_particle": ref["median"],
                "paper_bars_overlap": abs(diff) <= row.paper_err + ref["paper_err"],
                "sem_bars_overlap": abs(diff) <= row.sem + ref["sem"],
            }
        )
    return pd.DataFrame(rows)


def sections(ctx):
    """The summary and comparison tables of every diagnostic of the store (CSV only)."""
    results = ctx.results
    # the run's length, its kick rate and the mmpp system's fitted parameters describe the
    # run: not diagnostics to compare with the two-disk system; the escape rows (inf when
    # nothing escaped) are the escape section's, with their censoring
    names = pd.Series(results["diagnostic"].astype(str))
    drop = (names.isin(["t_max", "kick_rate", *ESCAPE_ROWS])
            | names.str.startswith("mmpp_"))
    diag = results[~drop.to_numpy()]
    summary = diagnostic_summary(diag)
    comparison = comparison_table(summary)
    ctx.found.summary = summary
    sec = Section("diagnostic_tables", "Diagnostic summaries (all diagnostics)")
    sec.text(
        "Per radius, system and diagnostic: number of ICs n, number of finite values n_valid "
        "(undefined values, e.g. the autocorrelation of a constant angle series, are NaN in "
        "the store and left out), mean, median, standard deviation, standard error "
        "std/√n_valid and the paper's error bar std/10. The comparison table gives, per "
        "kicked system, the ratio and difference of means to the two-particle system, "
        "z = difference / √(sem² + sem₂²), and the medians; |z| < 2 is not called agreement "
        "anywhere in this report (see the Findings for the rule)."
    )
    sec.table("diagnostics_summary", summary, "Summary", show=False)
    sec.table("diagnostics_vs_two_particle", comparison, "Kicked vs two-particle", show=False)
    return [sec]
