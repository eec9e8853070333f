r"""Collision rates across ICs: per-IC rates, the index of dispersion and the test of a
common rate (the Monte Carlo p-value, the one the text promises)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from kicktimes.render.figures import check_frame, plain_log_ticks, x_axis
from kicktimes.render.pages import number_text
from kicktimes.report.context import Section
from kicktimes.report.counts import counts_by_radius, experiment_kinetic, kinetic_rate_of

__all__ = ["rate_heterogeneity", "sections"]


def _p_label(p):
    """A p-value as a tick label: ``"p < 10⁻³⁰⁰"`` where the asymptotic χ² p-value
    underflowed to 0, ``"p < 10⁻ᵏ"`` below 10⁻³, else ``"p = "`` and 1 significant figure."""
    if not np.isfinite(p):
        return ""
    if p <= 0:
        return "p < 10⁻³⁰⁰"
    if p < 1e-3:
        sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
        return "p < 10" + str(int(math.floor(math.log10(p))) + 1).translate(sup)
    return f"p = {p:.1g}"


def _p_row(ax, at, p, test, where):
    """The p-values of a common rate on a second x axis on top of ``ax`` (never over a
    marker), read horizontally: one sentence when every label is the same (``p < 10⁻³⁰⁰``
    at every radius of a paper store: the χ² tail underflows double precision) or every p
    lies below 10⁻³ (the largest as the bound, and how many underflow), else a
    short label per position (without the ``p``), every second one raised when there are
    more than 6, so that neighbours do not collide."""
    labels = [_p_label(v).removeprefix("p ").removeprefix("= ") for v in p]
    top = ax.secondary_xaxis("top")
    shown = {lab for lab in labels if lab}
    if len(shown) == 1 and all(labels):
        (only,) = shown
        top.set_xticks([])
        note = " (below double precision)" if only.endswith("⁻³⁰⁰") else ""
        top.set_xlabel(f"p of a common rate ({test}): p {only} at every {where}{note}",
                       fontsize="small")
        return
    finite = np.asarray(p, float)[np.isfinite(np.asarray(p, float))]
    if finite.size and (finite < 1e-3).all():
        # every p below 10⁻³: one bound for all (the largest), no row of labels to collide
        bound = _p_label(float(finite.max())).removeprefix("p ")
        floor = int((finite <= 0).sum())
        top.set_xticks([])
        top.set_xlabel(f"p of a common rate ({test}): p {bound} at every {where}"
                       + (f"\n(< 10⁻³⁰⁰, below double precision, at {floor} of {finite.size})"
                          if floor else ""), fontsize="small")
        return
    if len(at) > 6:
        labels = [lab + ("\n" if k % 2 else "") for k, lab in enumerate(labels)]
    top.set_xticks(at, labels, fontsize="x-small")
    top.set_xlabel(f"p of a common rate ({test}; < 10⁻³⁰⁰: below double precision)",
                   fontsize="small")


def rate_heterogeneity(collisions, *, homogeneity=None, rule="mirror", max_points=4000,
                       x="radius", xlabel=None, kinetic=None, sticky="auto"):
    r"""Collision rates across ICs: per-IC rates and their dispersion, per radius.

    Parameters
    ----------
    collisions : pandas.DataFrame
        One row per (radius, IC): ``radius``, ``n_pp``, ``t_window``.
    homogeneity : pandas.DataFrame, optional
        Indexed or keyed by ``radius`` with a column ``pvalue_mc`` (used when present)
        or ``pvalue``: the p-value of the test that every IC at that radius has the same
        rate (the Pearson dispersion test of
        :func:`kicktimes.stats.test_poisson_ensemble`); printed on top of panel (b).
    rule : {"mirror", "elastic"} or None
        Rule of the kinetic-theory rate (None: no kinetic curve; a rule needs
        ``x="radius"``).
    max_points : int
        At most this many per-IC points are drawn per radius (every k-th IC in index
        order; the summaries use all).
    x, xlabel : str, optional
        The column of both tables drawn along x and its axis label (default: the disk
        radius; e.g. the group of `kicktimes analyze`; labels are drawn at 0, 1, ...).

    Returns
    -------
    matplotlib.figure.Figure
        (a) per-IC rates ``n_pp / t_window`` (log axis; ICs without collisions at the
        bottom edge as ▽), the pooled rate :math:`\sum N / \sum T`, the median and the
        kinetic rate; (b) the index of dispersion of the counts, variance / mean
        (1 for a common Poisson rate and equal windows), with the p-values.

    Other Parameters
    ----------------
    kinetic : callable, optional
        The kinetic rate as a function of the radius (e.g. ``Experiment.kinetic_rate``
        for unequal disks); default that of equal disks under ``rule``.
    sticky : "auto", array_like of bool or None
        Which rows of ``collisions`` are sticky runs (a disk pair trapped in repeated
        collisions), left out of the second dispersion curve of panel (b). ``"auto"``
        (default): :func:`kicktimes.report.counts.sticky_ics` under ``rule`` when
        ``rule`` is given, ``x="radius"`` and the table has an ``ic`` column, else none;
        None: no sticky-excluded curve.

    Notes
    -----
    A few sticky ICs drive the index of dispersion at a radius to 100 or more; the curve
    without them shows the dispersion of the rest. Tick labels of p-values below 10⁻³
    read ``< 10⁻ᵏ``, and an asymptotic p-value that underflows to 0 reads ``< 10⁻³⁰⁰``;
    when every position has the same label, one sentence on top says so instead.
    """

    axis = x_axis(x, xlabel)
    df = check_frame("collisions", collisions, [x, "n_pp", "t_window"])
    if rule is not None and x != "radius":
        raise ValueError(f"rule needs x='radius' (the kinetic rate is one of the radius), got "
                         f"x={x!r}; pass rule=None")
    hom = homogeneity
    if hom is not None:
        if not isinstance(hom, pd.DataFrame):
            raise TypeError(f"homogeneity must be a DataFrame, got {type(hom).__name__}")
        if x not in hom.columns:
            hom = hom.rename_axis(x).reset_index()
        if "pvalue" not in hom.columns and "pvalue_mc" not in hom.columns:
            raise ValueError("homogeneity must have a column 'pvalue' or 'pvalue_mc'")
        df, hom, axis = axis.positions(collisions=df, homogeneity=hom)
        hom = hom.set_index(x)
    else:
        df, axis = axis.positions(collisions=df)
    table = counts_by_radius(df, x=x)
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 1:
        raise ValueError(f"max_points must be a positive integer, got {max_points!r}")
    rate = df["n_pp"].to_numpy(float) / df["t_window"].to_numpy(float)
    positive = rate[rate > 0]
    floor = 0.5 * positive.min() if positive.size else 1e-6
    fig = Figure(figsize=(11.0, 4.4), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    radii = table.index.to_numpy()
    jitter = 0.25 * axis.step(radii, single=0.004)
    rng = np.random.default_rng(0)  # jitter only: the figure is reproducible
    nouns = axis.nouns
    zero_labelled = False
    for k, r in enumerate(radii):
        sel = np.flatnonzero(df[x].to_numpy() == r)
        sel = sel[:: max(1, math.ceil(sel.size / max_points))]
        y = rate[sel]
        xs = r + rng.uniform(-jitter, jitter, sel.size)
        lab = f"per-{nouns.one} rate" if k == 0 else None
        ax1.plot(
            xs[y > 0],
            y[y > 0],
            linestyle="none",
            marker=".",
            markersize=2,
            alpha=0.4,
            color="tab:blue",
            label=lab,
            rasterized=True,
        )
        if (y == 0).any():
            ax1.plot(
                xs[y == 0],
                np.full((y == 0).sum(), floor),
                linestyle="none",
                marker="v",
                markersize=3,
                color="tab:red",
                label=None if zero_labelled
                else f"{nouns.one} without {nouns.event}s (at the floor)",
            )
            zero_labelled = True
    grouped = df.groupby(x, observed=True)
    pooled = grouped["n_pp"].sum() / grouped["t_window"].sum()
    median = pd.Series(rate, index=df.index).groupby(df[x], observed=True).median()
    ax1.plot(pooled.index, pooled.to_numpy(), marker="o", color="black", linestyle=axis.line,
             label="pooled ΣN/ΣT")
    ax1.plot(
        median.index,
        median.to_numpy(),
        marker="_",
        markersize=12,
        linestyle="none",
        color="tab:green",
        label=f"median over {nouns.many}",
    )
    grid = np.linspace(radii.min(), radii.max(), 100) if radii.size > 1 else radii
    if rule is not None:  # None: sequences from elsewhere (kicktimes analyze), no Γ(r)
        ax1.plot(
            grid,
            kinetic_rate_of(grid, rule, kinetic),
            color="grey",
            linestyle=":",
            label=f"kinetic theory Γ(r) ({rule})",
        )
    ax1.set_yscale("log")
    axis.draw(ax1)
    ax1.set_ylabel(f"{nouns.event} rate (1 / time unit)")
    ax1.set_title(f"(a) rates of the individual {nouns.many}")
    ax1.legend(fontsize="x-small")
    dispersion = grouped["n_pp"].var(ddof=1) / grouped["n_pp"].mean()
    ax2.plot(
        dispersion.index.to_numpy(),
        dispersion.to_numpy(),
        marker="o",
        color="black",
        linestyle=axis.line,
        label=f"variance / mean of counts, all {nouns.many}",
    )
    flag = _sticky_flags(df, sticky, rule, x, kinetic)
    curves = [dispersion]
    if flag is not None:
        rest = df[~flag].groupby(x, observed=True)["n_pp"]
        without = (rest.var(ddof=1) / rest.mean()).reindex(dispersion.index)
        n_out = pd.Series(flag, index=df.index).groupby(df[x], observed=True).sum()
        ax2.plot(
            without.index.to_numpy(),
            without.to_numpy(),
            marker="s",
            markerfacecolor="none",
            color="tab:orange",
            linestyle="--" if axis.line != "none" else "none",
            label=_sticky_label(df, flag, nouns)
            + (" (−k: left out at that radius)" if n_out.any() else ""),
            gid="sticky_excluded",
        )
        for at, k in n_out.items():
            if k:
                ax2.annotate(f"−{int(k)}", (at, without.get(at, np.nan)), xytext=(0, -9),
                             textcoords="offset points", ha="center", fontsize="xx-small",
                             color="tab:orange")
        curves.append(without)
    ax2.axhline(1.0, color="grey", linestyle=":", label="Poisson, common rate")
    ax2.set_yscale("log")
    # log axis: only positive, finite dispersions set the range (0 when all counts agree)
    shown = pd.concat(curves).to_numpy(float)
    shown = shown[np.isfinite(shown) & (shown > 0)]
    lo = float(min(shown.min(), 1.0)) if shown.size else 1.0
    hi = float(max(shown.max(), 1.0)) if shown.size else 1.0
    ax2.set_ylim(lo / 1.5, hi * 1.5)
    plain_log_ticks(ax2.yaxis)
    if hom is not None:
        # the Monte Carlo p-value is exact but floored at 1/(n_mc + 1): where it sits at its
        # floor (every radius of a paper store) the labels would all read that floor, so
        # the asymptotic chi-square p-value is shown, which can be as small as it is
        column = "pvalue" if "pvalue" in hom.columns else "pvalue_mc"
        p = hom[column].reindex(dispersion.index)
        _p_row(ax2, dispersion.index.to_numpy(), p.to_numpy(float),
               "Monte Carlo" if column == "pvalue_mc" else "Pearson χ², asymptotic",
               x)
    axis.draw(ax2)
    ax2.set_ylabel(f"index of dispersion of counts across {nouns.many}")
    ax2.set_title("(b) over-dispersion")
    # below the axes: inside, the long entries covered the curves and the Poisson level
    ax2.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.14),
               frameon=False)
    plain_log_ticks(ax1.yaxis)
    return fig


def _sticky_label(df, flag, nouns):
    """The legend of the sticky-excluded curve: the (radius, IC) runs left out and, where
    the table has ICs, how many distinct ICs they come from (one IC is sticky at several
    radii: 12 runs may be 4 ICs)."""
    n_runs = int(flag.sum())
    if not n_runs:
        return f"without sticky {nouns.many} (none: the same curve)"
    if "ic" not in df.columns:
        return f"without the {n_runs} sticky {nouns.many if n_runs > 1 else nouns.one}"
    n_ics = int(df.loc[flag, "ic"].nunique())
    runs = "run" if n_runs == 1 else "runs"
    return (f"without the {n_runs} sticky {runs} (radius, {nouns.one}) "
            f"of {n_ics} {nouns.one if n_ics == 1 else nouns.many}")


def _sticky_flags(df, sticky, rule, x, kinetic):
    """Per row of ``df``, whether it is a sticky run (None: no sticky-excluded curve)."""
    if sticky is None:
        return None
    if isinstance(sticky, str):
        if sticky != "auto":
            raise ValueError(f"sticky must be 'auto', None or booleans, got {sticky!r}")
        if rule is None or x != "radius" or "ic" not in df.columns:
            return None
        from kicktimes.report.counts import sticky_ics

        return sticky_ics(df, rule, kinetic=kinetic)["sticky"].to_numpy(bool)
    flag = np.asarray(sticky, dtype=bool)
    if flag.shape != (len(df),):
        raise ValueError(f"sticky must have one flag per row ({len(df)}), got {flag.shape}")
    return flag


def sections(ctx):
    """Rate heterogeneity, from the homogeneity tests the Poisson section ran."""
    exp = ctx.exp
    het = ctx.found.homogeneity
    if het is None or het.empty:
        return []
    alpha, n_mc = ctx.alpha, ctx.n_mc
    sec = Section("heterogeneity", "Rate heterogeneity across ICs")
    sec.figure(
        "fig10_rate_heterogeneity",
        rate_heterogeneity(ctx.store.collisions, homogeneity=het, rule=exp.rule,
                           kinetic=experiment_kinetic(exp)),
        "(a) Disk-disk collision rate n_pp / t_window of every IC, the pooled and median rates "
        f"and the kinetic rate ({exp.rule}); (b) index of dispersion of the counts across ICs, "
        "of all ICs (black) and without the sticky runs (orange, collision rate above 5 times "
        "the kinetic rate; a run is one IC at one radius, and one IC can be sticky at several "
        "radii: the legend counts both; −k: the runs left out at that radius); "
        "on top, the asymptotic p-value of the Pearson χ² test of a common rate (given the "
        "total; < 10⁻³⁰⁰: below double precision; one sentence when it is the same at every "
        "radius); the Monte Carlo p-value, exact but floored at 1/(n_mc + 1), is in the text.",
    )
    sec.text(
        f"A common rate across ICs is rejected at α = {alpha:g} at "
        f"{int((het['pvalue_mc'] < alpha).sum())}/{len(het)} radii (Pearson χ² given the total, "
        f"Monte Carlo p-value at resolution 1/{n_mc + 1}; the asymptotic χ² p-value, in the "
        f"table, rejects at {int((het['pvalue'] < alpha).sum())}); the index of dispersion of "
        f"the counts ranges from {number_text(het['dispersion_index'].min())} to "
        f"{number_text(het['dispersion_index'].max())} (1 for a common Poisson rate); "
        f"{int(het['n_flagged_fdr'].sum())} (IC, radius) pairs have a rate incompatible with "
        "the pooled one after FDR control. The median per-IC rate is "
        f"{number_text((het['median_rate'] / het['kinetic_rate']).min())} to "
        f"{number_text((het['median_rate'] / het['kinetic_rate']).max())} times the kinetic rate."
    )
    sec.table("rate_homogeneity", het, "Rate homogeneity per radius")
    return [sec]
