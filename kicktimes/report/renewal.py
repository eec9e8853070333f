r"""Renewal-model comparison of the disk-disk collision intervals (per IC and pooled).

Intervals: the inner intervals are complete, the time from the last collision to the end
of the window is right-censored, the first time (a forward recurrence time) is dropped.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from kicktimes.render.figures import check_frame, finite, x_axis
from kicktimes.render.pages import percent_text
from kicktimes.report.context import Section
from kicktimes.report.effects import Effect
from kicktimes.report.poisson import binomial_ci, subsample
from kicktimes.stats import SHARE_RULE, clopper_pearson, share_verdict
from kicktimes.stats.analyze import MIN_INTERVALS

__all__ = ["model_comparison", "sections", "effects"]


def model_comparison(per_ic, pooled, *, models=None, x="radius", xlabel=None):
    r"""Renewal-model comparison per radius: per IC (AIC-best shares) and pooled (ΔAIC).

    Parameters
    ----------
    per_ic : pandas.DataFrame
        One row per (radius, IC) with ``radius`` and ``best_model`` (the AIC-best
        renewal model of that IC's intervals).
    pooled : pandas.DataFrame
        ``radius, model, delta_aic``: ΔAIC = AIC - min AIC of each model on the
        intervals pooled over ICs at that radius.
    models : sequence of str, optional
        Models and their order (default: those present).
    x, xlabel : str, optional
        The column of both tables drawn along x and its axis label (default: the disk
        radius; e.g. the group of `kicktimes analyze`; labels are drawn at 0, 1, ...).

    One of the two tables may be empty (e.g. no IC has enough intervals for a fit of
    its own): its panel then says so.

    Returns
    -------
    matplotlib.figure.Figure
        (a) one bar per model and radius: the share of ICs for which the model is
        AIC-best, with its Clopper-Pearson 95 % interval (:func:`binomial_ci`), and the
        number n of ICs fitted under each radius's tick (``x="radius"``, at most 20
        radii), else on top of each group; also in the title when more than four groups
        all have the same n; (b) pooled ΔAIC per model on a log
        axis of ΔAIC + 1 labelled in ΔAIC, with the usual ΔAIC = 2 and 10 guides.
    """
    axis = x_axis(x, xlabel)
    per_ic = check_frame("per_ic", per_ic, [x, "best_model"], allow_empty=True)
    pooled = check_frame("pooled", pooled, [x, "model", "delta_aic"], allow_empty=True)
    if per_ic.empty and pooled.empty:
        raise ValueError("per_ic and pooled must not both be empty")
    per_ic, pooled, axis = axis.positions(per_ic=per_ic, pooled=pooled)
    delta = finite("pooled['delta_aic']", pooled["delta_aic"], allow_nan=True)
    if (delta < 0).any():
        raise ValueError("pooled['delta_aic'] must be non-negative (AIC - min AIC)")
    if models is None:
        models = list(dict.fromkeys([*pooled["model"], *per_ic["best_model"]]))
    colour = {m: f"C{k}" for k, m in enumerate(models)}
    # panel (a) holds one bar per model and x value: wider with many x values
    n_x = max(per_ic[x].nunique(), 1)
    wide_a = min(2.0, max(1.0, n_x * max(len(models), 1) / 24))
    fig = Figure(figsize=(5.5 * (1 + wide_a), 4.6), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2, width_ratios=[wide_a, 1])
    counts = pd.crosstab(per_ic[x], per_ic["best_model"]).reindex(
        columns=models, fill_value=0
    )
    total = counts.sum(axis=1)
    share = counts.div(total, axis=0)
    r = share.index.to_numpy()
    # one bar per model beside the others (not stacked: a stacked share has no interval
    # of its own), each with its Clopper-Pearson 95 % interval
    width = 0.8 * axis.step(r, single=0.01)
    bar = width / max(len(models), 1)
    for k, m in enumerate(models):
        at = r + (k - (len(models) - 1) / 2) * bar
        low, high = binomial_ci(counts[m].to_numpy(), total.to_numpy())
        y = share[m].to_numpy()
        ax1.bar(at, y, width=bar, color=colour[m], label=m,
                yerr=np.vstack([y - low, high - y]),
                error_kw={"elinewidth": 0.9, "capsize": 2.0, "ecolor": "black"})
        # a share of 0 has no bar: a dash in the model's colour says which interval it is
        zero = y == 0
        ax1.plot(at[zero], y[zero], linestyle="none", marker="o", markersize=3.5,
                 color=colour[m], clip_on=False, zorder=4)
    # n on top of each group, or once in the title when every one of many groups has the
    # same n (twelve "n = 12" run into each other)
    same_n = r.size > 4 and total.nunique() == 1
    for at, n in zip(r, total, strict=True):
        if not same_n and not (x == "radius" and r.size <= 20):  # else under the ticks
            ax1.text(at, 1.02, f"n = {int(n)}", ha="center", va="bottom", fontsize="x-small")
    for ax, empty in ((ax1, per_ic.empty), (ax2, pooled.empty)):
        if empty:
            ax.text(
                0.5,
                0.5,
                "no sample with enough intervals",
                transform=ax.transAxes,
                ha="center",
                va="center",
            )
    ax1.set_ylim(-0.02, 1.12)  # a share of 0: a dot on the axis, in the model's colour
    axis.draw(ax1)
    if x == "radius" and r.size <= 20:
        # a tick under every group of bars, with the number of ICs behind its shares: a
        # share of n = 12 moves by 1/12 per IC, and the axis should say so
        ax1.set_xticks(r, [f"{v:g}\nn = {int(n)}" for v, n in zip(r, total, strict=True)],
                       fontsize="small")
    nouns = axis.nouns
    ax1.set_ylabel(f"share of {nouns.many} where the model is AIC-best")
    where = (f"n = {int(total.iloc[0])} {nouns.many} fitted at every "
             + ("radius" if x == "radius" else (xlabel or x))
             if same_n else f"n = number of {nouns.many} fitted, "
             + ("under each radius" if x == "radius" and r.size <= 20 else "on top"))
    ax1.set_title(f"(a) per {nouns.one}: share ± Clopper-Pearson 95 %\n({where})",
                  fontsize="medium")
    for m in models:
        part = pooled[pooled["model"] == m].sort_values(x)
        if len(part):
            ax2.plot(
                part[x],
                part["delta_aic"] + 1.0,
                marker="o",
                markersize=4,
                linestyle=axis.line,
                color=colour[m],
                label=m,
            )
    # a log axis of ΔAIC + 1, labelled in ΔAIC: 0 (the best model) is the bottom line, and
    # no label of 0 sits below one of 1 (a symmetric-log axis reads so)
    for level in (2.0, 10.0):
        ax2.axhline(level + 1.0, color="grey", linestyle=":", linewidth=0.8)
        ax2.annotate(
            f"ΔAIC = {level:g}",
            (0.01, level + 1.0),
            xycoords=("axes fraction", "data"),
            fontsize="x-small",
            color="grey",
            va="bottom",
        )
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ax2.set_yscale("log")
    top = float(np.nanmax(delta)) if delta.size and np.isfinite(delta).any() else 10.0
    ax2.set_ylim(0.8, max(30.0, 2.0 * (top + 1.0)))
    ticks = [1.0, 3.0, 11.0] + [10.0**k + 1.0 for k in range(2, 8) if 10.0**k < 2 * top + 2]
    ax2.yaxis.set_major_locator(FixedLocator(ticks))
    ax2.yaxis.set_minor_locator(NullLocator())
    ax2.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v - 1.0:g}"))
    ax2.axhline(1.0, color="grey", linewidth=0.8, zorder=0)
    ax2.annotate("ΔAIC = 0: the best model", (0.01, 1.0), xycoords=("axes fraction", "data"),
                 fontsize="x-small", color="grey", va="bottom")
    axis.draw(ax2)
    ax2.set_ylabel("ΔAIC = AIC − min AIC (pooled intervals;\nlog scale of ΔAIC + 1)")
    ax2.set_title(f"(b) intervals pooled over {nouns.many}")
    # one legend for both panels, outside the axes: it never covers data
    handles = [Patch(color=colour[m], label=m) for m in models]
    fig.legend(handles=handles, loc="outside lower center", ncol=len(models), fontsize="small")
    return fig


def _compare_job(job):
    """AIC comparison of the renewal models on one sample (runs in a worker process)."""
    from kicktimes import stats

    complete, censored = job
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # optimiser chatter; failed fits are in 'note'
        return stats.compare_models(complete, censored=censored)


def sections(ctx):
    """Per-IC and pooled AIC comparisons of the renewal models."""
    from kicktimes import stats

    coll = ctx.store.collisions
    max_ics_model_fits, max_pooled_intervals = ctx.max_ics_model_fits, ctx.max_pooled_intervals
    notes, pmap = ctx.notes, ctx.pmap
    per_rows, pooled_rows, best_rows = [], [], []
    jobs, meta = [], []
    for r, part in coll.groupby("radius", observed=True):
        part = part.sort_values("ic")
        # pooled: whole ICs in index order until the interval budget is used
        n_used, iv = stats.pooled_intervals(
            [np.asarray(t, float) for t in part["pp_times"]],
            part["t_window"].to_numpy(float),
            part["n_pp"].to_numpy(),
            max_intervals=max_pooled_intervals,
        )
        if iv.complete.size >= MIN_INTERVALS:
            jobs.append((iv.complete, iv.censored))
            meta.append(("pooled", {"radius": r, "n_ics_used": n_used}))
        if n_used < len(part):
            notes.append(
                f"Pooled renewal fits at r = {r:g}: the first {n_used} of {len(part)} "
                f"ICs (≈{max_pooled_intervals} intervals)."
            )
        for row in subsample(part, max_ics_model_fits).itertuples():
            iv = stats.intervals_from_times(np.asarray(row.pp_times, float), row.t_window)
            base = {"radius": r, "ic": int(row.ic), "n_intervals": int(iv.complete.size)}
            if iv.complete.size < MIN_INTERVALS:
                note = f"fewer than {MIN_INTERVALS} intervals"
                best_rows.append({**base, "best_model": None, "note": note})
            else:
                jobs.append((iv.complete, iv.censored))
                meta.append(("ic", base))
                # the calibration: a Poisson sequence with the same number of collisions
                # in the same window (times uniform given N), fitted the same way
                rng = ctx.rng(6, int(round(r * 1e6)), int(row.ic))
                null_times = np.sort(rng.uniform(0.0, row.t_window, int(row.n_pp)))
                null = stats.intervals_from_times(null_times, row.t_window)
                jobs.append((null.complete, null.censored))
                meta.append(("null", base))
    pooled_cols = ("loglik", "k", "aic", "delta_aic", "weight", "n", "n_censored", "note")
    for (kind, base), table in zip(meta, pmap(_compare_job, jobs), strict=True):
        if kind == "pooled":
            for model, t in table.iterrows():
                pooled_rows.append({**base, "model": model, **{c: t[c] for c in pooled_cols}})
            continue
        if kind == "null":
            best_rows[-1]["null_best_model"] = table.index[0]
            best_rows[-1]["null_best_aic"] = float(table["aic"].min())
            continue
        # the best AIC, on the conditional footing of kicktimes.stats.compare_point_processes:
        # the MMPP section (report/mmpp.py) sets the MMPP-2 against it
        best_rows.append({**base, "best_model": table.index[0], "best_aic": float(
            table["aic"].min()), "note": ""})
        for model, t in table.iterrows():
            per_rows.append(
                {
                    **base,
                    "model": model,
                    "aic": t["aic"],
                    "delta_aic": t["delta_aic"],
                    "weight": t["weight"],
                    "note": t["note"],
                }
            )
    n_per_radius = coll.groupby("radius", observed=True)["ic"].nunique()
    if (n_per_radius > max_ics_model_fits).any():
        notes.append(
            f"Per-IC renewal-model comparison: the first {max_ics_model_fits} ICs (by "
            "index) per radius (each comparison fits 6 censored models)."
        )
    best = pd.DataFrame(best_rows).sort_values(["radius", "ic"], ignore_index=True)
    per_ic = pd.DataFrame(per_rows)
    pooled = pd.DataFrame(pooled_rows)
    sec = Section("renewal", "Renewal-model comparison of the collision intervals")
    sec.text(
        "Intervals: the inner intervals t_{k+1} - t_k are complete, the time from the last "
        "collision to the end of the window is right-censored, the first time t_1 (a forward "
        "recurrence time) is dropped. Models (censored maximum likelihood): "
        + ", ".join(stats.FULL_SAMPLE_MODELS)
        + "; ranked by AIC."
    )
    fitted = best[best["best_model"].notna()]
    if pooled.empty:
        pooled = pd.DataFrame(columns=["radius", "model", "aic", "delta_aic"])
    share = pd.crosstab(fitted["radius"], fitted["best_model"])
    share_long = share.stack().rename("n_best").reset_index()
    share_long = share_long.rename(columns={"best_model": "model"})
    share_long["n_ics_fitted"] = share_long["radius"].map(share.sum(axis=1))
    share_long["share"] = share_long["n_best"] / share_long["n_ics_fitted"]
    share_long["ci_low"], share_long["ci_high"] = binomial_ci(
        share_long["n_best"], share_long["n_ics_fitted"]
    )
    if fitted.empty and pooled.empty:
        sec.text(f"No sample has {MIN_INTERVALS} or more intervals: no renewal fit.")
    else:
        sec.figure(
            "fig09_renewal_model_comparison",
            model_comparison(fitted, pooled, models=list(stats.FULL_SAMPLE_MODELS)),
            "(a) Per IC: share of ICs for which each renewal model has the lowest AIC, with "
            "Clopper-Pearson 95 % intervals; " + _small_n_words(fitted, share_long, coll, ctx)
            + " (b) Intervals pooled over ICs: ΔAIC of each model (0 = best; 2 and 10 "
            "guides).",
        )
    if fitted.empty:
        sec.text(
            f"No IC among those fitted per radius has {MIN_INTERVALS} or more "
            "intervals: no per-IC comparison."
        )
    else:
        exp_share = fitted.groupby("radius", observed=True)["best_model"].apply(
            lambda b: (b == "exponential").mean()
        )
        sec.text(
            f"Per IC, the exponential (Poisson) model is AIC-best for "
            f"{percent_text(exp_share.mean())} "
            f"of the fitted ICs on average over radii (from {percent_text(exp_share.min())} to "
            f"{percent_text(exp_share.max())}); {len(best) - len(fitted)} ICs had fewer than "
            f"{MIN_INTERVALS} intervals and were not fitted."
        )
    if not pooled.empty:
        best_pooled = pooled.loc[pooled.groupby("radius", observed=True)["aic"].idxmin()]
        best_pooled = best_pooled.set_index("radius")["model"]
        d_exp = pooled[pooled["model"] == "exponential"].set_index("radius")["delta_aic"]
        top = best_pooled.value_counts()
        sec.text(
            "Pooled over ICs, the best model is "
            + ", ".join(f"{m} at {c}/{len(best_pooled)} radii" for m, c in top.items())
            + f"; the exponential's pooled ΔAIC ranges from {d_exp.min():.3g} to "
            f"{d_exp.max():.3g}. A pooled sample mixes ICs with different rates, so it is "
            "heavier-tailed than each IC (a mixture of exponentials is hyperexponential): "
            "compare with the rate heterogeneity."
        )
    sec.table("renewal_best_share", share_long, "Per IC: AIC-best model shares")
    sec.table("renewal_pooled", pooled, "Pooled intervals: model comparison")
    sec.table("renewal_per_ic", per_ic, "Per IC: every model", show=False)
    sec.table("renewal_best_per_ic", best, "Per IC: best model", show=False)
    ctx.found.renewal_best = best
    ctx.found.renewal_pooled = pooled
    return [sec]


def _small_n_words(fitted, share_long, coll, ctx):
    """The caption's words on how few ICs stand behind each share of fig09 (a)."""
    n_fit = fitted.groupby("radius", observed=True)["ic"].nunique()
    n_all = coll.groupby("radius", observed=True)["ic"].nunique()
    if n_fit.empty or n_all.empty:
        return "no IC had enough intervals for the comparison"
    lo, hi = int(n_fit.min()), int(n_fit.max())
    n = str(lo) if lo == hi else f"{lo}–{hi}"
    width = (share_long["ci_high"] - share_long["ci_low"]).to_numpy(float)
    return (
        f"n = {n} ICs fitted per radius (under each tick; of {int(n_all.min())}"
        + (f"–{int(n_all.max())}" if n_all.max() != n_all.min() else "")
        + f" ICs, the first {ctx.max_ics_model_fits} by index: each comparison fits six "
        f"censored models), so one IC moves a share by 1/{hi} or more, and the 95 % "
        f"intervals are {width.min():.2f} to {width.max():.2f} wide: read a share at one "
        "radius, or the gap between two bars, against them; the share pooled over radii "
        "and its Poisson-twin level are in the statements CSV."
    )


def effects(ctx):
    """Share of fitted ICs whose AIC-best renewal model is the exponential."""
    best = ctx.found.renewal_best
    if best is None:
        return []
    fitted = best[best["best_model"].notna()]
    if fitted.empty:
        return []
    share = calibrated_share(ctx, fitted, fitted["best_model"] == "exponential",
                             fitted["null_best_model"] == "exponential", rng=ctx.rng(7),
                             under="under Poisson times")
    verdict = {
        "above": "the exponential is AIC-best more often than under Poisson",
        "below": "the exponential is AIC-best less often than Poisson times would make it",
        "inconclusive": "as often as under Poisson: no evidence against it from AIC",
    }[share.pop("verdict")]
    level = share.pop("level")
    others = fitted["best_model"].value_counts()
    detail = ", ".join(f"{m} {c}" for m, c in others.items())
    pooled = ctx.found.renewal_pooled
    if pooled is not None and not pooled.empty:
        best = pooled.groupby("radius", observed=True)["aic"].idxmin()
        winners = pooled.loc[best, "model"].value_counts()
        detail += "; pooled over ICs (a mixture of rates): " + ", ".join(
            f"{m} best at {c} radii" for m, c in winners.items()
        )
    return [
        Effect(
            question="Which renewal model?",
            system="",
            quantity="share of fitted ICs whose AIC-best model is the exponential",
            verdict=verdict,
            detail=(f"under Poisson times {percent_text(level)} of the same fits pick the "
                    "exponential; AIC-best counts: " + detail),
            **share,
        )
    ]


def calibrated_share(ctx, fitted, hit, null_hit, *, rng, under, what="fits") -> dict:
    """A share of fitted ICs against its level on their Poisson twins, as `Effect` fields.

    ``hit`` / ``null_hit``: booleans per row of ``fitted`` (one row per fitted (radius,
    IC)), on the data and on the IC's Poisson twin (the same numbers of collisions and
    windows, fitted the same way: the level a Poisson process would give). Returns
    ``estimate``, ``ci_low``, ``ci_high`` (bootstrap clustered on ICs), ``rule``,
    ``method``, and ``level`` and the ``verdict`` key of `share_verdict` for the caller
    to word.
    """
    from kicktimes.report.poisson import clustered_share

    hit, null_hit = np.asarray(hit, bool), np.asarray(null_hit, bool)
    n = len(fitted)
    level = float(null_hit.mean())
    lvl_low, lvl_high = clopper_pearson(int(null_hit.sum()), n)
    flags = fitted.assign(p=np.where(hit, 0.0, 1.0))
    low, high = clustered_share(flags, "p", 0.5, rng=rng, n_boot=ctx.n_boot)
    return {
        "estimate": int(hit.sum()) / n, "ci_low": low, "ci_high": high,
        "rule": SHARE_RULE.format(level=level) + (
            f" (level: the share {under} with the same numbers of collisions and windows, by "
            f"simulation: {level:.3g} [{lvl_low:.3g}, {lvl_high:.3g}])"),
        "method": f"bootstrap clustered on {fitted['ic'].nunique()} ICs ({n} {what})",
        "level": level, "verdict": share_verdict(low, high, level=level),
    }
