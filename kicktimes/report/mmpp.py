r"""Clustered collision times: the two-state Markov-modulated Poisson process (MMPP-2) in
the "which model?" comparison, per IC, calibrated on Poisson twins.

A renewal model has independent intervals; the collision times are not independent (the
Poisson battery's Ljung-Box and dispersion rejections). An MMPP-2 lets a hidden two-state
Markov chain switch the collision rate. Per fitted IC (those of the renewal section, with
at least `MIN_EVENTS` collisions) it is set against Poisson and every renewal model on one
likelihood, that of the events after the window's first given it
(`kicktimes.stats.compare_point_processes`, the renewal fits' own footing): the renewal
section's AICs and the MMPP-2's conditional AIC. The full-likelihood fit that comparison
starts from (`kicktimes.stats.fit_mmpp`'s, returned with ``return_fits``) gives the rates and
switching rates: one fit per IC, not two. AIC is not calibrated
for an MMPP against Poisson (the switching rates are not identified when the rates are
equal), so the level of every share is the share on the IC's Poisson twin, the renewal
section's: as many uniform times in the same window, fitted the same way.

The same comparison for outside data (`kicktimes analyze --mmpp`, independent sequences)
uses the parametric-bootstrap likelihood-ratio test of MMPP-2 against Poisson
(`kicktimes.stats.mmpp_lr_test`) per sequence, Fisher-combined per group.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from kicktimes.render.figures import check_frame, x_axis
from kicktimes.render.pages import percent_text
from kicktimes.report.context import Section
from kicktimes.report.effects import Effect
from kicktimes.stats import MMPP_MIN_EVENTS, clopper_pearson

__all__ = ["MIN_EVENTS", "fit_job", "mmpp_comparison", "sections", "effects"]

#: the fewest events of a sequence fitted by an MMPP-2: `kicktimes.stats.MMPP_MIN_EVENTS`
#: (the sweep's ``mmpp`` system and the MMPP study use the same)
MIN_EVENTS = MMPP_MIN_EVENTS
#: EM starts of each fit (the comparison's and the parameters'), each run to convergence:
#: `kicktimes.stats.fit_mmpp`'s search with 5 structured starts and one random (issue 39:
#: on its 132 two-disk fits, 2 stayed short of the optimum by more than 0.01 (up to 0.63)
#: and none by more than 1, as with 8; with the default 12, none; main's default fit: 10
#: and 6). 6, not 12, keeps the stage's time what it was with main's 4 (docs/benchmarks.md)
N_STARTS = 6
_PARAMS = ("rate_low", "rate_high", "switch_low", "switch_high", "stationary_rate")


def fit_job(job):
    """One sequence's MMPP-2 against Poisson (runs in a worker process).

    ``job = (times, window, seed, with_params)``. Returns a dict: ``mmpp_aic`` and
    ``poisson_aic`` on the conditional footing of `kicktimes.stats.compare_point_processes`
    (NaN and ``note`` when the fit fails) and, with ``with_params``, the full-likelihood
    fit's ``rate_low``, ``rate_high``, ``switch_low``, ``switch_high`` (rates of leaving
    the low and the high state), ``stationary_rate`` and its warnings in ``note``: the
    fit the comparison itself made (``return_fits``), not a second one.
    """
    from kicktimes import stats

    times, window, seed, with_params = job
    out = {"mmpp_aic": math.nan, "poisson_aic": math.nan, "note": ""}
    rng = np.random.default_rng(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # degenerate fits are named in their notes
        try:
            table, fits = stats.compare_point_processes(
                times, window, models=[], n_states=(2,), n_starts=N_STARTS, rng=rng,
                return_fits=True)
        except ValueError as exc:
            return {**out, "note": str(exc)}
        out["mmpp_aic"] = float(table.loc["mmpp2", "aic"])
        out["poisson_aic"] = float(table.loc["poisson", "aic"])
        out["note"] = str(table.loc["mmpp2", "note"])
        if with_params and "mmpp2" in fits:
            fit = fits["mmpp2"]
            q = fit.generator
            out.update(rate_low=float(fit.rates[0]), rate_high=float(fit.rates[1]),
                       switch_low=float(-q[0, 0]), switch_high=float(-q[1, 1]),
                       stationary_rate=fit.stationary_rate, note="; ".join(fit.warnings))
    return out


def _share_rows(per_ic, x):
    """Per ``x``: how often the MMPP-2 is AIC-best (of all models) and beats Poisson, on the
    data and on the twins, with Clopper-Pearson intervals."""
    rows = []
    for at, part in per_ic.groupby(x, sort=True, observed=True):
        row = {x: at, "n_fitted": len(part)}
        for name, column in (("best", "mmpp_best"), ("beats_poisson", "mmpp_beats_poisson"),
                             ("null_best", "null_mmpp_best"),
                             ("null_beats_poisson", "null_mmpp_beats_poisson"),
                             ("lr_reject", "lr_reject")):
            if column not in part:
                continue
            flags = part[column].dropna().astype(bool)
            k, n = int(flags.sum()), len(flags)
            lo, hi = clopper_pearson(k, n)
            row.update({f"share_{name}": k / n if n else math.nan, f"{name}_low": lo,
                        f"{name}_high": hi})
        rows.append(row)
    return pd.DataFrame(rows)


def mmpp_comparison(per_ic, *, x="radius", xlabel=None, alpha=None):
    r"""How often an MMPP-2 describes the collision times best, and what it fits.

    Parameters
    ----------
    per_ic : pandas.DataFrame
        One row per fitted sequence: ``x``, ``rate`` (events / window), the booleans
        ``mmpp_best`` (the MMPP-2 has the lowest AIC of every model) and
        ``mmpp_beats_poisson`` (its AIC is below Poisson's), optionally the same for the
        Poisson twin (``null_mmpp_best``, ``null_mmpp_beats_poisson``), and the fitted
        ``rate_low``, ``rate_high``, ``switch_low``, ``switch_high``.
        With a boolean column ``lr_reject`` (the bootstrap LR test rejects Poisson at
        ``alpha``, `kicktimes analyze --mmpp`), its share is drawn in (a) too, with the
        level ``alpha``.
    x, xlabel : str, optional
        The column drawn along x and its label (default: the disk radius).
    alpha : float, optional
        The LR test's level (drawn with ``lr_reject``).

    Returns
    -------
    matplotlib.figure.Figure
        (a) per x, the share of sequences whose AIC-best model is the MMPP-2 and the
        share where it beats Poisson, with 95 % Clopper-Pearson intervals, and the same
        shares on Poisson twins (the level, open markers); (b) the fitted low and high
        rates over the sequence's rate :math:`n/T`; (c) the mean sojourns
        :math:`1/q` in the low and the high state, in mean intervals :math:`T/n`
        (medians and quartiles over the sequences where the MMPP-2 beats Poisson).
    """
    axis = x_axis(x, xlabel)
    need = [x, "rate", "mmpp_best", "mmpp_beats_poisson", *_PARAMS[:4]]
    per_ic = check_frame("per_ic", per_ic, need)
    (per_ic, axis) = axis.positions(per_ic=per_ic)
    shares = _share_rows(per_ic, x)
    fig = Figure(figsize=(13.0, 4.3), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(1, 3)
    at = shares[x].to_numpy(float)
    dx = 0.08 * axis.step(at, single=1.0 if axis.labels is not None else 0.01)
    kinds = [("best", "MMPP-2 is AIC-best", "tab:brown", "o"),
             ("beats_poisson", "MMPP-2 beats Poisson", "tab:blue", "s")]
    if "share_lr_reject" in shares:
        kinds.append(("lr_reject", "LR test rejects Poisson", "tab:green", "^"))
        if alpha is not None:
            ax1.axhline(alpha, color="tab:green", linestyle=":", linewidth=0.8,
                        label=f"α = {alpha:g} (the LR test's level)")
    for k, (name, label, colour, marker) in enumerate(kinds):
        shift = (k - 0.5 * (len(kinds) - 1)) * dx
        y = shares[f"share_{name}"].to_numpy(float)
        err = np.vstack([y - shares[f"{name}_low"], shares[f"{name}_high"] - y])
        ax1.errorbar(at + shift, y, yerr=np.clip(err, 0, None), color=colour, marker=marker,
                     linestyle=axis.line, capsize=2,
                     label=f"{label} (data; bars: 95 % Clopper-Pearson interval)")
        if f"share_null_{name}" in shares:
            y0 = shares[f"share_null_{name}"].to_numpy(float)
            ax1.plot(at + shift, y0, color=colour, marker=marker, markerfacecolor="white",
                     linestyle=":" if axis.labels is None else "none",
                     label=f"{label} (Poisson twins: the level)")
    ax1.set_ylim(-0.02, 1.02)
    ax1.set_ylabel("share of fitted sequences")
    ax1.set_title("(a) MMPP-2 against Poisson and renewal (AIC)")
    axis.draw(ax1)
    clustered = per_ic[per_ic["mmpp_beats_poisson"].astype(bool)]
    panels = ((ax2, ("rate_low", "rate_high"), lambda d, c: d[c] / d["rate"],
               "fitted rate / sequence rate n/T", "(b) rates of the two states"),
              (ax3, ("switch_low", "switch_high"), lambda d, c: d["rate"] / d[c],
               "mean sojourn 1/q (mean intervals T/n)", "(c) time in each state"))
    for ax, columns, value, ylabel, title in panels:
        bounds, drawn = [], []
        for k, (column, colour) in enumerate(zip(columns, ("tab:cyan", "tab:red"),
                                                 strict=True)):
            rows = []
            for pos, part in clustered.groupby(x, sort=True, observed=True):
                v = value(part, column).to_numpy(float)
                v = v[np.isfinite(v) & (v > 0)]
                if v.size:
                    rows.append((pos, *np.percentile(v, [25, 50, 75])))
            if not rows:
                continue
            pos, q1, med, q3 = np.array(rows).T
            state = "low" if k == 0 else "high"
            ax.errorbar(pos + (k - 0.5) * dx, med, yerr=[med - q1, q3 - med], color=colour,
                        marker="o", capsize=2, linestyle=axis.line,
                        label=f"{state}-rate state (median; bars: quartiles)")
            bounds.append((q1.min(), q3.max()))
            drawn.append((pos + (k - 0.5) * dx, q1, q3, colour))
        if clustered.empty:
            ax.text(0.5, 0.5, "no sequence where the MMPP-2 beats Poisson",
                    transform=ax.transAxes, ha="center", va="center")
        else:
            ax.axhline(1.0, color="0.5", linewidth=0.8, zorder=0)
            # a silent state (rate ~ 0) or an instant stay would stretch the axis over
            # decades: quartiles beyond 1/100 .. 1000 leave the panel
            lo, hi = min(b[0] for b in bounds), max(b[1] for b in bounds)
            ax.set_ylim(max(0.7 * lo, 1e-2), min(1.4 * hi, 1e3))
            _log_axis(ax)
            _mark_clipped(ax, drawn)
            # the number of sequences behind each median, in a row above the axes
            counts = clustered.groupby(x, sort=True, observed=True).size()
            for pos, n in counts.items():
                ax.annotate(f"{n}", (pos, 1), xycoords=("data", "axes fraction"),
                            xytext=(0, 5), textcoords="offset points", ha="center",
                            va="bottom", fontsize="x-small", color="0.35",
                            annotation_clip=False)
        ax.set_ylabel(ylabel)
        # above the row of counts
        ax.set_title(title + ("\n(n sequences above each radius)" if len(clustered) else ""),
                     fontsize="medium", pad=16 if len(clustered) else 6)
        axis.draw(ax)
        ax.set_xlim(ax1.get_xlim())  # the same positions as (a), whichever have points
    handles = ax1.get_legend_handles_labels()[0]
    for state, colour in (("low", "tab:cyan"), ("high", "tab:red")):
        handles.append(Line2D([], [], color=colour, marker="o", linestyle="-",
                              label=f"(b, c) {state}-rate state: median, bars: quartiles"))
    handles.append(Line2D([], [], color="0.3", marker="^", linestyle="none",
                          label="(b, c) a quartile beyond the axis: arrow and value"))
    fig.legend(handles=handles, loc="outside lower center", ncol=2, fontsize="x-small")
    return fig


def _mark_clipped(ax, drawn):
    """Mark every quartile bar end beyond the y limits: an arrow at the edge, pointing
    out, with the end's value beside it (a silent state or an instant stay gives ends
    decades away, which the limits leave out, but never silently)."""
    low, high = ax.get_ylim()
    for pos, q1, q3, colour in drawn:
        for x0, a, b in zip(pos, q1, q3, strict=True):
            for end, beyond, edge in ((b, b > high, 1.0), (a, a < low, 0.0)):
                if not beyond:
                    continue
                up = edge == 1.0
                ax.plot([x0], [edge], transform=ax.get_xaxis_transform(), clip_on=False,
                        marker="^" if up else "v", color=colour, markersize=6,
                        linestyle="none")
                ax.annotate(f"{end:.3g}", (x0, edge), xycoords=("data", "axes fraction"),
                            xytext=(4, -2 if up else 2), textcoords="offset points",
                            ha="left", va="top" if up else "bottom", fontsize="xx-small",
                            color=colour)


def _log_axis(ax):
    """A log y axis with plain labels at 1-2-5 steps (never more than about 8)."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ax.set_yscale("log")
    lo, hi = ax.get_ylim()
    decades = range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1)
    for steps in ((1, 2, 5), (1, 3), (1,)):
        ticks = [m * 10.0**e for e in decades for m in steps if lo <= m * 10.0**e <= hi]
        if len(ticks) <= 8:
            break
    ax.yaxis.set_major_locator(FixedLocator(ticks))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def _twin(ctx, r, ic, window, n_pp):
    """The renewal section's Poisson twin of an IC: as many uniform times in its window."""
    rng = ctx.rng(6, int(round(r * 1e6)), int(ic))
    return np.sort(rng.uniform(0.0, window, int(n_pp)))


def sections(ctx):
    """The MMPP-2 per fitted IC of the renewal section, against Poisson and the renewal
    models, with its Poisson twin."""
    best = ctx.found.renewal_best
    sec = Section("mmpp", "Clustered collisions: a Markov-modulated Poisson model")
    sec.text(
        "A two-state Markov-modulated Poisson process (MMPP-2): a hidden Markov chain "
        "switches the collision rate between a low and a high value, so collisions cluster "
        "and successive intervals are correlated, which no renewal model allows. Per IC "
        "fitted in the renewal section with at least "
        f"{MIN_EVENTS} collisions, it is set against Poisson and every renewal model on one "
        "likelihood, that of the collisions after the window's first given it (the renewal "
        "fits' own footing; kicktimes.stats.compare_point_processes), by AIC. AIC is not "
        "calibrated for an MMPP against Poisson, so each share has as its level the share on "
        "the IC's Poisson twin (the renewal section's: as many uniform times in the same "
        "window, fitted the same way). The rates and switching rates are those of the "
        "full-likelihood fit behind the comparison (kicktimes.stats.fit_mmpp's search with "
        f"{N_STARTS} starts, each run to convergence, stationary start), which reached the "
        "optimum of 64 independent starts within 0.01 in 130 of 132 fits of the two-disk "
        "test sets and within 1 in all (docs/mmpp.md)."
    )
    if best is None or "best_aic" not in best:
        sec.text("No renewal comparison per IC: no MMPP fit.")
        return [sec]
    coll = ctx.store.collisions.set_index(["radius", "ic"])
    fitted = best[best["best_model"].notna()]
    fitted = fitted[[int(coll.loc[(r, ic), "n_pp"]) >= MIN_EVENTS
                     for r, ic in zip(fitted["radius"], fitted["ic"], strict=True)]]
    jobs, keys = [], []
    for row in fitted.itertuples():
        c = coll.loc[(row.radius, row.ic)]
        times, window = np.asarray(c["pp_times"], float), float(c["t_window"])
        seed = int(ctx.rng(10, int(round(row.radius * 1e6)), int(row.ic)).integers(2**63))
        jobs.append((times, window, seed, True))
        jobs.append((_twin(ctx, row.radius, row.ic, window, c["n_pp"]), window, seed, False))
        keys.append((row.radius, row.ic, int(c["n_pp"]), window))
    out = list(ctx.pmap(fit_job, jobs))
    rows = []
    for k, (r, ic, n_pp, window) in enumerate(keys):
        data, null = out[2 * k], out[2 * k + 1]
        b = fitted[(fitted["radius"] == r) & (fitted["ic"] == ic)].iloc[0]
        rows.append({
            "radius": r, "ic": ic, "n_pp": n_pp, "rate": n_pp / window,
            **{p: data.get(p, math.nan) for p in _PARAMS},
            "mmpp_aic": data["mmpp_aic"], "poisson_aic": data["poisson_aic"],
            "best_renewal_model": b["best_model"], "best_renewal_aic": b["best_aic"],
            "mmpp_best": data["mmpp_aic"] < b["best_aic"],
            "mmpp_beats_poisson": data["mmpp_aic"] < data["poisson_aic"],
            "null_mmpp_best": null["mmpp_aic"] < b["null_best_aic"],
            "null_mmpp_beats_poisson": null["mmpp_aic"] < null["poisson_aic"],
            "note": data["note"],
        })
    per_ic = pd.DataFrame(rows)
    ctx.found.mmpp = per_ic
    n_small = int(best["best_model"].notna().sum()) - len(fitted)
    if n_small:
        ctx.notes.append(f"MMPP-2 fits: {n_small} of the ICs fitted in the renewal section "
                         f"have fewer than {MIN_EVENTS} collisions and are left out.")
    if per_ic.empty:
        sec.text(f"No fitted IC has {MIN_EVENTS} or more collisions: no MMPP fit.")
        return [sec]
    ok = per_ic[np.isfinite(per_ic["mmpp_aic"])]
    sec.figure(
        "fig09b_mmpp_comparison",
        mmpp_comparison(ok),
        "(a) Per radius, the share of fitted ICs whose AIC-best model (Poisson, the renewal "
        "models, MMPP-2; one conditional likelihood) is the MMPP-2, and the share where the "
        "MMPP-2 beats Poisson, with 95 % Clopper-Pearson intervals; open markers: the same "
        "on the ICs' Poisson twins (the level). (b) The fitted low and high collision rates "
        "over the IC's rate n/T; (c) the mean time in each state (1/q) in mean collision "
        "intervals T/n; medians and quartiles (bars) over the ICs where the MMPP-2 beats "
        "Poisson, their number written above the x axis; a quartile beyond the axis is "
        "marked by an arrow at the edge with its value.",
    )
    shares = _share_rows(ok, "radius")
    clustered = ok[ok["mmpp_beats_poisson"]]
    text = (f"The MMPP-2 is AIC-best for {percent_text(ok['mmpp_best'].mean())} of the {len(ok)} "
            f"fitted "
            f"ICs ({percent_text(ok['null_mmpp_best'].mean())} of their Poisson twins) and beats "
            f"Poisson for {percent_text(ok['mmpp_beats_poisson'].mean())} "
            f"({percent_text(ok['null_mmpp_beats_poisson'].mean())} of the twins).")
    if len(clustered):
        ratio = clustered["rate_high"] / clustered["rate_low"]
        text += (f" Where it beats Poisson, the high rate is a median "
                 f"{np.nanmedian(ratio):.3g} times the low one, and a stay lasts a median "
                 f"{np.nanmedian(clustered['rate'] / clustered['switch_low']):.3g} (low) and "
                 f"{np.nanmedian(clustered['rate'] / clustered['switch_high']):.3g} (high) "
                 "mean collision intervals.")
    sec.text(text)
    sec.table("mmpp_shares", shares, "MMPP-2: shares per radius")
    sec.table("mmpp_per_ic", per_ic, "MMPP-2 per IC", show=False)
    return [sec]


def effects(ctx):
    """Share of fitted ICs whose AIC-best model, MMPP-2 included, is the MMPP-2."""
    per_ic = ctx.found.mmpp
    if per_ic is None or per_ic.empty:
        return []
    ok = per_ic[np.isfinite(per_ic["mmpp_aic"])]
    if ok.empty:
        return []
    from kicktimes.report.renewal import calibrated_share

    share = calibrated_share(ctx, ok, ok["mmpp_best"], ok["null_mmpp_best"], rng=ctx.rng(11),
                             under="on Poisson twins",
                             what=f"fits with >= {MIN_EVENTS} collisions")
    verdict = {
        "above": "the MMPP-2 is AIC-best more often than on Poisson times: the intervals are "
                 "not independent, and an MMPP-2 fits them better by AIC than any renewal "
                 "model (though no MMPP can make the refractory dip after a collision: "
                 "mmpp.md)",
        "below": "the MMPP-2 is AIC-best less often than on Poisson times",
        "inconclusive": "as often as on Poisson times: no evidence for clustering from AIC",
    }[share.pop("verdict")]
    share.pop("level")
    others = ok.loc[~ok["mmpp_best"], "best_renewal_model"].value_counts()
    return [
        Effect(
            question="Which model, with a Markov-modulated Poisson process (MMPP-2)?",
            system="",
            quantity="share of fitted ICs whose AIC-best model (Poisson, renewal models, "
                     "MMPP-2) is the MMPP-2",
            verdict=verdict,
            detail=(f"the MMPP-2 beats Poisson for "
                    f"{percent_text(ok['mmpp_beats_poisson'].mean())} of "
                    f"the ICs ({percent_text(ok['null_mmpp_beats_poisson'].mean())} of the twins); "
                    "AIC-best otherwise: " + ", ".join(f"{m} {c}" for m, c in others.items())),
            **share,
        )
    ]
