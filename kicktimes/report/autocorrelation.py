r"""Autocorrelation of the boundary angles: R_l against radius (the paper's Fig. 8), the
curves R_l over lags 1..L, the decorrelation times, and the built-in prediction.

Between two perturbations the angle θ of a disk in a circular table is conserved, so two
consecutive boundary angles differ only when a perturbation came between them. Hence
:math:`R_1 \approx 1 - n_{\rm pert}/n_{\rm boundary}`, with :math:`n_{\rm pert}` the
disk-disk collisions (two-particle) or kicks (kicked). The kicked systems are built with
the kick rate equal to the collision rate, so their lag-1 agreement with the two-particle
system is built in: the report draws this prediction beside every lag-1 value and marks
the agreement as built in, never as a confirmation.

Store rows: ``autocorrelation`` (lag ``lag``), ``acf@l`` for l = 1..``acf_max_lag``,
``decorrelation_lag``, ``tau_int``; ``n_pp``, ``n_kicks``, ``n_boundary`` for the
prediction.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from kicktimes.render.figures import (
    SEM_BAR,
    dodge,
    kick_groups,
    radius_axis,
    system_label,
    system_style,
)
from kicktimes.render.pages import number_text
from kicktimes.report.context import Section
from kicktimes.report.effects import BUILT_IN, Effect, store_ratio
from kicktimes.report.store import REFERENCE, distinct, kicked_systems, wide
from kicktimes.report.summary import diagnostic_summary
from kicktimes.stats import paired_ratio, ratio_verdict

__all__ = ["predicted_lag1", "acf_curves", "acf_differences", "acf_paired_differences",
           "crossings", "acf_figure", "lag1_ratios", "half_width95", "sections", "effects"]

_ACF = re.compile(r"^acf@(\d+)$")


def predicted_lag1(results) -> pd.DataFrame:
    r"""The built-in prediction :math:`1 - n_{\rm pert}/n_{\rm boundary}` per IC.

    Returns tidy rows ``radius, ic, system, diagnostic="predicted_lag1", value``;
    ``n_pert`` is ``n_pp`` for the two-particle system and ``n_kicks`` otherwise.
    """
    out = []
    nb = results[results["diagnostic"] == "n_boundary"].set_index(["radius", "ic", "system"])
    for system in results["system"].unique():
        name = "n_pp" if system == REFERENCE else "n_kicks"
        n = results[(results["diagnostic"] == name) & (results["system"] == system)]
        if n.empty:
            continue
        n = n.set_index(["radius", "ic", "system"])["value"]
        b = nb["value"].reindex(n.index)
        with np.errstate(invalid="ignore", divide="ignore"):
            value = np.where(b > 0, 1.0 - n / b, np.nan)
        out.append(
            pd.DataFrame({"value": value}, index=n.index)
            .reset_index()
            .assign(diagnostic="predicted_lag1")
        )
    if not out:
        return pd.DataFrame(columns=["radius", "ic", "system", "diagnostic", "value"])
    return pd.concat(out, ignore_index=True)


def half_width95(sem, n):
    """Half-width of the 95 % t interval of a mean, ``t_{0.975, n-1} · sem`` (NaN where
    n < 2).

    Parameters
    ----------
    sem : array_like
        Standard errors over ICs.
    n : array_like
        Numbers of ICs behind them.

    Returns
    -------
    numpy.ndarray
    """
    from scipy.stats import t

    n = np.asarray(n, dtype=float)
    with np.errstate(invalid="ignore"):
        q = np.where(n >= 2, t.ppf(0.975, np.maximum(n - 1, 1)), np.nan)
    return q * np.asarray(sem, dtype=float)


def acf_curves(results) -> pd.DataFrame:
    """Mean, s.e.m., 95 % interval and median of R_l per radius, system and lag.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy results with the ``acf@l`` rows.

    Returns
    -------
    pandas.DataFrame
        ``radius, system, lag, mean, median, std, count, sem, ci95``: ``ci95`` the
        half-width of the 95 % t interval of the mean over ICs (:func:`half_width95`).
    """
    part = _acf_rows(results)
    if part.empty:
        return pd.DataFrame(columns=["radius", "system", "lag", "mean", "sem", "median",
                                     "ci95"])
    g = part.groupby(["radius", "system", "lag"], observed=True)["value"]
    out = g.agg(["mean", "median", "std", "count"]).reset_index()
    out["sem"] = out["std"] / np.sqrt(out["count"].where(out["count"] > 0))
    out["ci95"] = half_width95(out["sem"], out["count"])
    return out


def _acf_rows(results):
    """The ``acf@l`` rows of ``results`` with their lag in a column ``lag`` (int)."""
    # the lag of each distinct diagnostic name, then per row through the category codes:
    # a regex per row took ~10 s on a paper store's million acf@l rows
    diag = results["diagnostic"]
    if not isinstance(diag.dtype, pd.CategoricalDtype):
        diag = diag.astype("category")
    names = diag.cat.categories.to_series(index=range(len(diag.cat.categories)))
    lag_of = names.str.extract(_ACF)[0].astype(float).to_numpy()
    lag = np.append(lag_of, np.nan)[diag.cat.codes.to_numpy()]  # code -1 (missing): NaN
    keep = np.isfinite(lag)
    return results[keep].assign(lag=lag[keep].astype(int))


def acf_differences(curves) -> pd.DataFrame:
    """Each kicked system's R_l minus the two-particle R_l, per radius and lag.

    Parameters
    ----------
    curves : pandas.DataFrame
        :func:`acf_curves` output.

    Returns
    -------
    pandas.DataFrame
        ``radius, system, lag, difference, ci95``: the difference of the means and the
        half-width of its 95 % interval, ``t · √(sem² + sem₂²)`` (Welch-like, the ICs
        of the two systems taken as independent samples; the smaller count sets the
        degrees of freedom). A difference that changes sign over the lags is a crossing.
    """
    ref = curves[curves["system"] == REFERENCE].set_index(["radius", "lag"])
    out = []
    for system in kicked_systems(curves):
        part = curves[curves["system"] == system].set_index(["radius", "lag"])
        two = ref.reindex(part.index)
        se = np.hypot(part["sem"], two["sem"])
        n = np.minimum(part["count"], two["count"])
        out.append(pd.DataFrame({
            "system": system,
            "difference": part["mean"] - two["mean"],
            "ci95": half_width95(se, n),
        }, index=part.index).reset_index())
    if not out:
        return pd.DataFrame(columns=["radius", "lag", "system", "difference", "ci95"])
    return pd.concat(out, ignore_index=True)


def acf_paired_differences(results) -> pd.DataFrame:
    r"""Each kicked system's R_l minus the two-particle R_l, paired on ICs.

    Every system of a radius starts from the same ICs, so the difference is taken per IC,
    :math:`d_{ri} = R_l^{\rm kicked}(r, i) - R_l^{\rm two}(r, i)`, and its mean over the
    ICs with both values carries the t interval of the paired differences,
    :math:`t_{0.975,\,n-1}\, s_d/\sqrt{n}`: the interval of a bootstrap clustered on ICs
    to first order, and unlike :func:`acf_differences` it keeps the covariance of the
    two systems that share an IC.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy results (the ``acf@l`` rows are read), each IC once per system.

    Returns
    -------
    pandas.DataFrame
        ``radius, lag, system, difference, ci95, n_pairs``.

    Examples
    --------
    >>> import pandas as pd
    >>> rows = pd.DataFrame({"radius": 0.01, "ic": [0, 1, 2, 0, 1, 2],
    ...                      "system": ["two_particle"] * 3 + ["poisson"] * 3,
    ...                      "diagnostic": "acf@1", "value": [0.5, 0.6, 0.7, 0.4, 0.5, 0.6]})
    >>> d = acf_paired_differences(rows)
    >>> round(float(d["difference"].iloc[0]), 12), float(d["ci95"].iloc[0])
    (-0.1, 0.0)
    """
    part = _acf_rows(results)
    columns = ["radius", "lag", "system", "difference", "ci95", "n_pairs"]
    if part.empty:
        return pd.DataFrame(columns=columns)
    table = part.pivot_table(index=["radius", "ic", "lag"], columns="system", values="value",
                             observed=True)
    if REFERENCE not in table.columns:
        return pd.DataFrame(columns=columns)
    out = []
    for system in kicked_systems(part):
        if system not in table.columns:
            continue
        d = (table[system] - table[REFERENCE]).dropna()
        g = d.groupby(level=["radius", "lag"]).agg(["mean", "std", "count"])
        out.append(pd.DataFrame({
            "system": system,
            "difference": g["mean"],
            "ci95": half_width95(g["std"] / np.sqrt(g["count"]), g["count"]),
            "n_pairs": g["count"].astype(int),
        }, index=g.index).reset_index())
    if not out:
        return pd.DataFrame(columns=columns)
    return pd.concat(out, ignore_index=True)[columns]


def crossings(differences) -> pd.DataFrame:
    """Per radius and kicked system, whether its R_l curve crosses the two-particle one.

    Parameters
    ----------
    differences : pandas.DataFrame
        The differences of the curves, as :func:`acf_differences` returns them.

    Returns
    -------
    pandas.DataFrame
        ``radius, system, sign_lag1, crosses, first_lag_other_sign, clear``: the sign of
        the lag-1 difference, whether a later lag has the other sign, the first such lag,
        and whether the crossing is clear (the 95 % intervals exclude 0 on both sides).
    """
    rows = []
    for (r, system), g in differences.groupby(["radius", "system"], observed=True):
        g = g.sort_values("lag")
        d, h = g["difference"].to_numpy(float), g["ci95"].to_numpy(float)
        if d.size == 0 or not np.isfinite(d[0]) or d[0] == 0:
            continue
        first = np.sign(d[0])
        other = np.flatnonzero(np.sign(d) == -first)
        sure = (np.abs(d) > np.nan_to_num(h, nan=np.inf))
        rows.append({
            "radius": r,
            "system": system,
            "sign_lag1": int(first),
            "crosses": bool(other.size),
            "first_lag_other_sign": int(g["lag"].iloc[other[0]]) if other.size else np.nan,
            "clear": bool(other.size and sure[0] and sure[other].any()),
        })
    return pd.DataFrame(rows, columns=["radius", "system", "sign_lag1", "crosses",
                                       "first_lag_other_sign", "clear"])


def acf_figure(curves, predicted, *, differences=None, max_panels=3):
    """R_l against l at a few radii, and each kicked system's difference to the two-disk
    curve, with the systems split by kick kind so that a panel holds at most four curves.

    Parameters
    ----------
    curves : pandas.DataFrame
        :func:`acf_curves` output.
    predicted : pandas.DataFrame
        :func:`predicted_lag1` output (the built-in lag-1 prediction).
    differences : pandas.DataFrame, optional
        The differences to draw below, :func:`acf_paired_differences` output (paired on
        ICs: what the report draws); default :func:`acf_differences` of ``curves`` (the
        two systems' ICs taken as independent).
    max_panels : int
        At most this many radii (evenly chosen, the smallest and the largest included);
        one column each. Every radius is in the curves table.

    Returns
    -------
    matplotlib.figure.Figure
        One column per radius; per kick group (`kick_groups`: the two-disk system with the
        uniform-kick systems, then with the scatter-kick systems) a row of R_l per system,
        mean with its 95 % interval over ICs as a band and the built-in lag-1 prediction as
        an open marker at l ≈ 1 (titled ``r = ..., <group>``), then a row of each kicked
        system's R_l minus the two-disk R_l with its 95 % interval and the zero line
        (titled ``r = ...: kicked − two-disk, <group>``); where the curves cross, the
        difference changes sign. The rows of a column share their y scale by kind.
    """
    from matplotlib.ticker import MaxNLocator

    if not isinstance(max_panels, int | np.integer) or max_panels < 1:
        raise ValueError(f"max_panels must be an integer >= 1, got {max_panels!r}")
    radii = _figure_radii(curves, max_panels)
    systems = [s for s in (REFERENCE, *kicked_systems(curves)) if s in distinct(curves, "system")]
    groups = kick_groups(systems)
    ncol = radii.size
    rows = 2 * len(groups)
    fig = Figure(figsize=(4.4 * ncol, 2.9 * rows + 0.8), layout="constrained")
    grid = fig.subplots(rows, ncol, squeeze=False,
                        gridspec_kw={"height_ratios": [3] * len(groups) + [2] * len(groups)})
    pred = predicted.groupby(["radius", "system"], observed=True)["value"].mean()
    diffs = acf_differences(curves) if differences is None else differences
    if "ci95" not in curves.columns:
        curves = curves.assign(ci95=half_width95(curves["sem"], curves["count"]))
    for col, r in enumerate(radii):
        for g, (name, members) in enumerate(groups):
            ax, dax = grid[g, col], grid[len(groups) + g, col]
            suffix = f", {name}" if name else ""
            for system in members:
                k = systems.index(system)
                c = curves[(curves["radius"] == r) & (curves["system"] == system)]
                c = c.sort_values("lag")
                style = system_style(system, k)
                ax.plot(c["lag"], c["mean"], color=style["color"], marker=style["marker"],
                        markersize=3, label=system_label(system))
                ax.fill_between(c["lag"], c["mean"] - c["ci95"], c["mean"] + c["ci95"],
                                color=style["color"], alpha=0.2, linewidth=0)
                if (r, system) in pred.index:
                    # beside lag 1, shifted so it does not hide the measured value
                    j = members.index(system)
                    ax.plot([1 - 0.3 + 0.2 * j], [pred[(r, system)]], linestyle="none",
                            marker=style["marker"], markerfacecolor="none", markersize=7,
                            color=style["color"])
                if system == REFERENCE:
                    continue
                d = diffs[(diffs["radius"] == r) & (diffs["system"] == system)]
                d = d.sort_values("lag")
                dax.plot(d["lag"], d["difference"], color=style["color"],
                         marker=style["marker"], markersize=3)
                dax.fill_between(d["lag"], d["difference"] - d["ci95"],
                                 d["difference"] + d["ci95"], color=style["color"],
                                 alpha=0.2, linewidth=0)
            lowest = curves.loc[curves["radius"] == r, "mean"].min()
            if lowest < np.exp(-1):  # the 1/e level only where a curve reaches it
                ax.axhline(np.exp(-1), color="grey", linestyle=":", linewidth=0.8)
            dax.axhline(0.0, color="black", linewidth=0.8)
            ax.set_title(f"r = {r:g}{suffix}", fontsize="medium")
            dax.set_title(f"r = {r:g}: kicked − two-disk{suffix}", fontsize="small")
            if col == 0:
                ax.set_ylabel(r"$R_l$ of $\theta$ (dimensionless)")
                dax.set_ylabel(r"$\Delta R_l$ (dimensionless)")
            for a in (ax, dax):
                a.xaxis.set_major_locator(MaxNLocator(integer=True))
        # one y scale per kind within a radius: the groups compare at a glance
        block = grid[: len(groups), col]
        lows, highs = zip(*(a.get_ylim() for a in block), strict=True)
        for a in block:
            a.set_ylim(min(lows), max(highs))
        grid[-1, col].set_xlabel("lag l (boundary collisions)")
    # the differences on one y scale over every radius and group: a ΔR of 0.05 is as tall
    # in every column, and the columns are read against each other
    block = grid[len(groups):, :].ravel()
    lows, highs = zip(*(a.get_ylim() for a in block), strict=True)
    for a in block:
        a.set_ylim(min(lows), max(highs))
    handles, labels = [], []
    for k, system in enumerate(systems):
        style = system_style(system, k)
        handles.append(Line2D([], [], color=style["color"], marker=style["marker"],
                              markersize=4))
        labels.append(system_label(system))
    handles += [
        Line2D([], [], color="grey", linewidth=6, alpha=0.3),
        Line2D([], [], color="grey", marker="o", markerfacecolor="none", linestyle="none"),
        Line2D([], [], color="grey", linestyle=":"),
    ]
    labels += ["95 % interval (R_l rows: of the mean; ΔR_l rows: of the paired differences)"
               if differences is not None else "95 % interval of the mean over ICs",
               "built-in prediction 1 − n_pert/n_boundary", "1/e (where reached)"]
    fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(labels)),
               fontsize="small")
    return fig


def _figure_radii(curves, max_panels):
    """At most ``max_panels`` radii of ``curves``, evenly chosen, both ends included."""
    radii = np.sort(curves["radius"].unique())
    if radii.size > max_panels:
        radii = radii[np.unique(np.linspace(0, radii.size - 1, max_panels).round().astype(int))]
    return radii


def _shown_radii(curves, max_panels=3):
    """The radii :func:`acf_figure` draws, as words (``"r = 0.008, 0.018 and 0.03"``)."""
    radii = _figure_radii(curves, max_panels)
    text = [f"{r:g}" for r in radii]
    return "r = " + (", ".join(text[:-1]) + " and " + text[-1] if len(text) > 1 else text[0])


def lag1_ratios(ctx):
    """Per radius, each kicked system's (1 − R_lag) over the two-particle value with the
    95 % interval of the store's bootstrap clustered on ICs (`effects.store_ratio`: the
    Findings' resamples, so the very ratios and intervals of the findings tables).

    Returns
    -------
    pandas.DataFrame
        ``system, radius, n_pairs, ratio, ci_low, ci_high`` (empty without the rows).
    """
    columns = ["system", "radius", "n_pairs", "ratio", "ci_low", "ci_high"]
    results = ctx.results
    if "autocorrelation" not in distinct(results, "diagnostic"):
        return pd.DataFrame(columns=columns)
    one_minus = 1.0 - wide(results, "autocorrelation")
    out = []
    for system in kicked_systems(results):
        if system not in one_minus.columns or REFERENCE not in one_minus.columns:
            continue
        per_r, _ = store_ratio(ctx, one_minus[system], one_minus[REFERENCE])
        out.append(per_r.assign(system=system))
    return pd.concat(out, ignore_index=True)[columns] if out else pd.DataFrame(columns=columns)


def _lag1_figure(summary, predicted, lag, ratios=None):
    """(a) the decorrelation per boundary collision 1 − R_lag against r, log axis, with the
    built-in prediction 1 − n_pert/n_boundary (open markers) at lag 1; (b) each kicked
    system's 1 − R_lag over the two-disk value, with the ±10 % band: the intervals of
    ``ratios`` (:func:`lag1_ratios`, bootstrap clustered on ICs) where given, else the
    delta method with the two systems' ICs taken as independent. Plotting R_lag itself
    on [0.91, 0.98] would hide the difference in 1 − R_lag that the comparison is about."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    summary = summary[summary["diagnostic"] == "autocorrelation"]
    r_l = "R₁" if lag == 1 else f"R_{lag}"
    systems = list(dict.fromkeys(summary["system"]))
    order = [s for s in (REFERENCE, *kicked_systems(summary)) if s in systems]
    fig = Figure(figsize=(11.0, 4.6), layout="constrained")
    ax, ax_ratio = fig.subplots(1, 2)
    radii = summary["radius"].to_numpy()
    pred = (predicted.groupby(["radius", "system"], observed=True)["value"].mean()
            if lag == 1 and not predicted.empty else None)
    ref = summary[summary["system"] == REFERENCE].set_index("radius")
    for k, system in enumerate(order):
        part = summary[summary["system"] == system].sort_values("radius")
        style = system_style(system, k)
        x = part["radius"].to_numpy() + dodge(radii, k, len(order))
        half = half_width95(part["sem"], part["n_valid"])
        ax.errorbar(x, 1.0 - part["mean"].to_numpy(), yerr=half,
                    color=style["color"], marker=style["marker"], markersize=5,
                    label=system_label(system), **SEM_BAR)
        if pred is not None and system in pred.index.get_level_values(1):
            p = pred.xs(system, level="system")
            ax.plot(p.index.to_numpy() + dodge(radii, k, len(order)), 1.0 - p.to_numpy(),
                    linestyle="none", marker=style["marker"], markerfacecolor="none",
                    markersize=8, color=style["color"])
        if system != REFERENCE and ratios is not None:
            mine = ratios[ratios["system"] == system].sort_values("radius")
            ratio = mine["ratio"].to_numpy(float)
            ax_ratio.errorbar(mine["radius"].to_numpy() + dodge(radii, k, len(order)), ratio,
                              yerr=[ratio - mine["ci_low"].to_numpy(float),
                                    mine["ci_high"].to_numpy(float) - ratio],
                              color=style["color"], marker=style["marker"], markersize=5,
                              **SEM_BAR)
        elif system != REFERENCE and not ref.empty:
            two = 1.0 - ref["mean"].reindex(part["radius"]).to_numpy()
            two_se = ref["sem"].reindex(part["radius"]).to_numpy()
            own = 1.0 - part["mean"].to_numpy()
            ratio = own / two
            # delta method: the relative errors of the two means add in quadrature
            se = np.abs(ratio) * np.hypot(part["sem"].to_numpy() / own, two_se / two)
            n = np.minimum(part["n_valid"].to_numpy(),
                           ref["n_valid"].reindex(part["radius"]).to_numpy())
            ax_ratio.errorbar(part["radius"].to_numpy() + dodge(radii, k, len(order)), ratio,
                              yerr=half_width95(se, n), color=style["color"],
                              marker=style["marker"], markersize=5, **SEM_BAR)
    decorrelation = 1.0 - summary["mean"].to_numpy(float)
    if np.any(np.isfinite(decorrelation) & (decorrelation > 0)):  # else a linear axis
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 3.0, 5.0, 7.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    radius_axis(ax)
    ax.set_ylabel(f"1 − {r_l} of θ (decorrelation per boundary collision)")
    ax.set_title(f"(a) 1 − {r_l}: mean, 95 % interval over ICs\nopen: built-in "
                 "1 − n_pert/n_boundary"
                 if pred is not None else f"(a) 1 − {r_l}: mean, 95 % interval over ICs",
                 fontsize="medium")
    ax_ratio.axhspan(0.9, 1.1, color="0.88", zorder=0)
    ax_ratio.axhline(1.0, color="0.5", linewidth=0.8, zorder=0)
    radius_axis(ax_ratio)
    ax_ratio.set_ylabel(f"(1 − {r_l}) kicked / (1 − {r_l}) two-disk")
    how = ("95 % bootstrap interval, ICs resampled in pairs" if ratios is not None
           else "95 % interval, delta method, ICs independent")
    ax_ratio.set_title(f"(b) ratio to the two-disk value\n{how}; grey: ±10 %",
                       fontsize="medium")
    handles, labels = ax.get_legend_handles_labels()
    if pred is not None:
        handles.append(Line2D([], [], color="grey", marker="o", markerfacecolor="none",
                              linestyle="none"))
        labels.append("built-in prediction")
    fig.legend(handles, labels, loc="outside lower center", ncol=len(labels), fontsize="small")
    return fig


def sections(ctx):
    results, exp = ctx.results, ctx.exp
    have = distinct(results, "diagnostic")
    if "autocorrelation" not in have:
        return []
    lag = getattr(exp, "lag", 1)
    predicted = predicted_lag1(results)
    summary = diagnostic_summary(results, diagnostic="autocorrelation")
    sec = Section("autocorrelation", "Autocorrelation of boundary angles")
    sec.figure(
        "fig07_autocorrelation_vs_radius",
        _lag1_figure(summary, predicted, lag, ratios=lag1_ratios(ctx)),
        f"(a) The decorrelation per boundary collision 1 − R_{lag} of disk 0's boundary "
        "angles against radius (log axis): mean over ICs with its 95 % t interval"
        + (
            "; open markers: the built-in prediction 1 − n_pert/n_boundary (disk-disk "
            "collisions or kicks per boundary collision), which the kick rate = collision "
            "rate construction makes about equal"
            if lag == 1
            else ""
        )
        + f". (b) Each kicked system's 1 − R_{lag} over the two-disk value (ratio of the "
        "means over ICs) with its 95 % percentile interval from the findings tables' "
        f"bootstrap, {ctx.n_boot} resamples of the ICs, each resample applied to both "
        "systems: the kicked and the two-disk run of an IC stay paired (they share the IC); "
        "the ±10 % band of the ratio verdicts. (The bars of panel (a) are per system and "
        "do not compare systems.) Lag 1 alone can mislead: the curves R_l cross at larger "
        "lags (fig07b).",
    )
    curves = acf_curves(results)
    # a curve needs two lags: with R_1 alone (acf_max_lag = 1, e.g. `reproduce --content
    # paper`) there is no curve to draw, and the decorrelation lag and tau_int, read off
    # the curve, say nothing (tau_int would be 1/2 + R_1, the lag undefined)
    one_lag = not curves.empty and int(curves["lag"].max()) < 2
    if curves.empty or one_lag:
        sec.text(
            (
                "The store's autocorrelation curve stops at lag 1 (acf_max_lag = 1): only "
                f"the lag-{lag} value is shown, without the curve, the decorrelation lag and "
                "τ_int; run with acf_max_lag >= 2 for them."
            )
            if one_lag
            else (
                "The store has no autocorrelation curve (rows acf@l): only the lag-"
                f"{lag} value is shown; rerun the sweep for R_l over lags and decorrelation "
                "times."
            )
        )
    else:
        paired = acf_paired_differences(results)
        sec.figure(
            "fig07b_autocorrelation_curves",
            acf_figure(curves, predicted, differences=paired),
            "R_l of the boundary angles over lags l = 1.."
            f"{int(curves['lag'].max())} at {_shown_radii(curves)} (columns; every radius is in "
            "the autocorrelation_curves table), the two-disk curve with the uniform-kick "
            "systems and with the scatter-kick systems in separate rows (mean over ICs, band: "
            "95 % t "
            "interval of that system's mean alone, which says nothing about a difference "
            "between systems), with the built-in lag-1 prediction 1 − n_pert/n_boundary (open "
            "markers at l ≈ 1) and 1/e (the decorrelation threshold); in the lower rows, "
            "each kicked system's R_l minus the two-disk R_l, the mean over ICs of the "
            "per-IC difference (the two runs of an IC share it) with the 95 % t interval of "
            "those paired differences: where the curves cross, the difference changes sign.",
        )
        cross = crossings(paired)
        if not cross.empty:
            crossing = cross[cross["crosses"]]
            clear = int(crossing["clear"].sum())
            sec.text(
                f"Crossings of the R_l curves: {len(crossing)} of {len(cross)} (radius, "
                "kicked system) pairs change the sign of the mean R_l − R_l(two-disk) between "
                f"lag 1 and lag {int(curves['lag'].max())}; {clear} of them clearly (95 % "
                "intervals of the paired per-IC differences excluding 0 at lag 1 and at a "
                "lag of the other sign)"
                + ("; at those the ranking at lag 1 reverses at larger lags, so lag 1 alone "
                   "misleads there." if clear else
                   ": every crossing is within the intervals, none shows that the ranking at "
                   "lag 1 reverses.")
                + (" Crossing, by system: " + ", ".join(
                    f"{system_label(sys_)} at r = "
                    + ", ".join(f"{r:g}" for r in g["radius"])
                    for sys_, g in crossing.groupby("system", observed=True))
            + "." if len(crossing) else "")
            )
        sec.table("autocorrelation_curves", curves, "R_l per lag", show=False)
    rows = []
    pred = predicted.groupby(["radius", "system"], observed=True)["value"].mean()
    sticky = ctx.found.sticky
    flags = sticky.set_index(["radius", "ic"])["sticky"] if sticky is not None else None
    # the decorrelation rows of each (radius, system), grouped once: filtering the whole
    # table per group and name cost seconds on a paper store
    decorrelation = {
        name: dict(
            list(results[results["diagnostic"] == name].groupby(["radius", "system"],
                                                               observed=True)["value"])
        )
        for name in (() if one_lag else ("decorrelation_lag", "tau_int"))
    }
    for (r, system), g in results[results["diagnostic"] == "autocorrelation"].groupby(
        ["radius", "system"], observed=True
    ):
        entry = {
            "radius": r,
            "system": system,
            f"R{lag}_mean": g["value"].mean(),
            f"R{lag}_median": g["value"].median(),
            "predicted_lag1": pred.get((r, system), np.nan),
        }
        for name in decorrelation:
            v = decorrelation[name].get((r, system))
            if v is not None and len(v):
                entry[f"{name}_mean"] = v.mean()
                entry[f"{name}_median"] = v.median()
                entry[f"{name}_n_undefined"] = int(v.isna().sum())
        if flags is not None:
            entry["n_sticky"] = int(
                flags.reindex(g.set_index(["radius", "ic"]).index).fillna(False).astype(bool).sum()
            )
        rows.append(entry)
    table = pd.DataFrame(rows)
    if lag == 1 and not table.empty:
        gap = (table["R1_mean"] - table["predicted_lag1"]).abs()
        sec.text(
            "R_1 against its built-in prediction 1 − n_pert/n_boundary: largest gap "
            f"{number_text(gap.max())} over all radii and systems (R_1 ranges from "
            f"{number_text(table['R1_mean'].min())} to {number_text(table['R1_mean'].max())}). "
            "Because each kicked system is given the two-particle collision rate, its lag-1 "
            "agreement with the two-particle system is built in: it is not evidence that the "
            "kicked billiard "
            "reproduces the two-particle dynamics."
        )
    if "decorrelation_lag_mean" in table.columns:
        sec.text(
            "Decorrelation: the first lag with R_l < 1/e (decorrelation_lag; undefined when "
            "not reached within the computed lags, counted in the table) and the integrated "
            "time τ_int = 1/2 + Σ R_l (truncated at the first non-positive R_l), in boundary "
            "collisions."
        )
    sec.table("autocorrelation_summary", table, "Lag-1 values, prediction and decorrelation")
    return [sec]


def effects(ctx):
    """(1 − R_1) of each kicked system over the two-particle value, marked built in."""
    results = ctx.results
    if "autocorrelation" not in distinct(results, "diagnostic") or getattr(ctx.exp, "lag", 1) != 1:
        return []
    r1 = wide(results, "autocorrelation")
    one_minus = 1.0 - r1
    pred = wide(predicted_lag1(results), "predicted_lag1")
    out = []
    for system in kicked_systems(results):
        if system not in one_minus.columns or REFERENCE not in one_minus.columns:
            continue
        _, tot = store_ratio(ctx, one_minus[system], one_minus[REFERENCE])
        detail, predicted = "", None
        if system in pred.columns and REFERENCE in pred.columns:
            _, ptot = paired_ratio(
                1 - pred[system], 1 - pred[REFERENCE], rng=ctx.boot_rng(), n_boot=0
            )
            predicted = ptot["ratio"]
            detail = (
                f"the rate-matching prediction (perturbations per boundary collision, kicked "
                f"/ two-particle) gives {number_text(predicted)}"
            )
        verdict = ratio_verdict(tot["ci_low"], tot["ci_high"], tolerance=ctx.tolerance)
        if verdict.startswith("within"):
            verdict = f"{verdict} ({BUILT_IN}: kick rate = collision rate)"
        elif predicted is not None:
            verdict = (f"{verdict} (kick rate = collision rate predicts {number_text(predicted)}: "
                       "the rates do not explain it)")
        out.append(
            Effect.of_ratio(
                "Lag-1 ACF of boundary angles",
                system,
                "ratio of 1 − R_1 (kicked / two-particle, averaged over radii)",
                tot,
                tolerance=ctx.tolerance,
                verdict=verdict,
                detail=detail,
            )
        )
    return out
