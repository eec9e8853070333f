r"""Escape through holes in the wall: does the kicked disk escape like the two disks?

Only for a store whose experiment has holes (docs/escape.md); other stores get no section
and pay nothing. Every run of the sweep ends at its escape, and the store holds one
``escape_time`` row per (radius, IC, system), ``inf`` when nothing escaped by the run's end.

**Censoring.** A run that does not escape is right-censored at its end, its ``t_max`` row
(under the paper's sampling each run has its own end). The kicked systems follow disk 0
alone; in the two-disk system the run ends at the first escape of either disk, so disk 0's
escape is the event and an earlier escape of disk 1 censors it at that time (competing
risks; the ``escaped_disk`` row says which disk left). A store written before that row
existed records only the first escape of either disk: its two-disk curve is that event,
drawn and tabulated as such, and the comparison with the one-disk systems is not made
(their events differ: two disks leave about twice as fast as one).

**Statistics.** Per (radius, system) the Kaplan–Meier survival with pointwise 95 %
intervals (`kicktimes.stats.escape_survival`) and, beyond ``t_min``, the censored
maximum-likelihood fits of an exponential tail (rate γ) and an algebraic one (exponent α),
each with its exact 95 % interval and AIC (`kicktimes.stats.fit_escape_tail`). The tail law
is the one whose AIC is lower by more than `AIC_MARGIN`, "undecided" otherwise.

**Verdict** per (radius, kicked system), against the two-disk system at that radius:
"not like" when one tail is decidedly exponential and the other decidedly algebraic;
otherwise an equivalence test on the ratio of the shared law's parameter (α when at least
one tail is algebraic and none exponential, γ otherwise), kicked / two disks. Its 95 %
interval combines the two exact intervals, each read as normal on the log scale
(:math:`\sigma = \ln(hi / lo) / (2 \cdot 1.96)`, added in quadrature); the verdict is
`kicktimes.stats.ratio_verdict` with the margin `MARGIN` (10 %), fixed in advance: "like"
when the whole interval lies within it, "not like" when it lies entirely outside
(lower or higher), "inconclusive" otherwise. Overlapping intervals are never taken as
agreement. The section's first line combines the verdicts (:func:`escape_answer`).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from kicktimes.render.figures import (
    SYSTEMS,
    check_frame,
    plain_log_ticks,
    shared_legend,
    survival_steps,
    system_label,
    system_style,
)
from kicktimes.render.pages import number_text
from kicktimes.report.context import Section
from kicktimes.report.store import REFERENCE
from kicktimes.stats import MARGIN, MIN_AT_RISK

__all__ = [
    "AIC_MARGIN",
    "ESCAPE_ROWS",
    "T_MIN_FRACTION",
    "escape_answer",
    "escape_comparison",
    "escape_curves",
    "escape_figure",
    "escape_runs",
    "escape_table",
    "sections",
]

#: the store's escape rows: the escape section's, not diagnostics to summarise
ESCAPE_ROWS = ("escape_time", "escaped_disk")
#: default ``t_min`` of the tail fits: this fraction of the experiment's horizon n_steps·tau
T_MIN_FRACTION = 1 / 20
#: AIC difference beyond which a tail law is decided (one parameter each)
AIC_MARGIN = 2.0
_RUN_COLUMNS = ["radius", "ic", "system", "time", "horizon", "other_disk", "followed"]


def escape_runs(results) -> pd.DataFrame:
    """Per (radius, IC, system) the followed disk's escape time and the run's horizon.

    Parameters
    ----------
    results : pandas.DataFrame
        The store's tidy rows (``radius, ic, system, diagnostic, value``) with
        ``escape_time`` and ``t_max`` rows, and for the two-disk system optionally
        ``escaped_disk`` (0, 1, or -1 for none).

    Returns
    -------
    pandas.DataFrame
        ``radius, ic, system, time, horizon, other_disk, followed``: ``time`` the escape
        time (``inf``: censored at ``horizon``, the run's end), ``other_disk`` True where
        disk 1 left the two-disk table first (disk 0 censored there), ``followed``
        ``"disk 0"``, or ``"either disk"`` for two-disk runs of a store without
        ``escaped_disk`` rows. Empty without ``escape_time`` rows.
    """
    check_frame("results", results, ["radius", "ic", "system", "diagnostic", "value"],
                allow_empty=True)
    diag = results["diagnostic"].astype(str)
    key = ["radius", "ic", "system"]

    def rows(name, column):
        part = results.loc[(diag == name).to_numpy(), [*key, "value"]]
        part = part.astype({"system": str})
        return part.rename(columns={"value": column})

    esc = rows("escape_time", "time")
    if esc.empty:
        return pd.DataFrame(columns=_RUN_COLUMNS)
    runs = esc.merge(rows("t_max", "horizon"), on=key, how="left", validate="one_to_one")
    if runs["horizon"].isna().any():
        bad = runs[runs["horizon"].isna()].iloc[0]
        raise ValueError(f"results: the escape_time row of (radius {bad.radius:g}, IC "
                         f"{bad.ic}, {bad.system}) has no t_max row (its horizon)")
    runs = runs.merge(rows("escaped_disk", "disk"), on=key, how="left", validate="one_to_one")
    two = (runs["system"] == REFERENCE).to_numpy()
    known = runs["disk"].notna().to_numpy()
    runs["other_disk"] = two & known & (runs["disk"] == 1).to_numpy()
    runs.loc[runs["other_disk"], "time"] = math.inf
    runs["followed"] = np.where(two & ~known, "either disk", "disk 0")
    runs = runs.drop(columns="disk").sort_values(key, kind="stable", ignore_index=True)
    return runs[_RUN_COLUMNS]


def escape_curves(runs) -> pd.DataFrame:
    """Kaplan–Meier survival per (radius, system) of :func:`escape_runs`' table: columns
    ``radius, system, time, survival, ci_low, ci_high, n_at_risk`` and ``end``, the
    group's last observed time (its longest horizon); no rows for a (radius, system)
    without escapes."""
    from kicktimes.stats import escape_survival

    check_frame("runs", runs, ["radius", "system", "time", "horizon"])
    parts = []
    for (r, system), g in runs.groupby(["radius", "system"], sort=True, observed=True):
        horizon = g["horizon"].to_numpy(float)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # log of S = 0 or 1 in the bands
            km = escape_survival(g["time"].to_numpy(float), horizon)
        if len(km):
            parts.append(km.assign(radius=r, system=system, end=horizon.max()))
    columns = ["radius", "system", "time", "survival", "ci_low", "ci_high", "n_at_risk",
               "end"]
    if not parts:
        return pd.DataFrame(columns=columns)
    return pd.concat(parts, ignore_index=True)[columns]


def _survival_at(km, t, horizon_max):
    """The Kaplan–Meier survival at ``t``: 1 before the first escape, NaN beyond the
    longest horizon (not observed)."""
    if t > horizon_max:
        return math.nan
    before = km["survival"].to_numpy(float)[km["time"].to_numpy(float) <= t]
    return float(before[-1]) if before.size else 1.0


def _tail_law(aic_exp_minus_alg):
    if not np.isfinite(aic_exp_minus_alg):
        return "n/a"
    if aic_exp_minus_alg < -AIC_MARGIN:
        return "exponential"
    return "algebraic" if aic_exp_minus_alg > AIC_MARGIN else "undecided"


def escape_table(runs, *, t_min, curves=None) -> pd.DataFrame:
    r"""Per (radius, system): counts, survival at two times, and the tail fits.

    Parameters
    ----------
    runs : pandas.DataFrame
        :func:`escape_runs`' table.
    t_min : float
        Where the tail fits start (> 0), in time units.
    curves : pandas.DataFrame, optional
        :func:`escape_curves` of ``runs`` (computed when not given).

    Returns
    -------
    pandas.DataFrame
        ``radius, system, followed, n, escaped, other_disk_escaped, t_min,
        survival_t_min, survival_10_t_min`` (Kaplan–Meier; NaN beyond the longest
        horizon), ``n_tail, tail_escaped`` (runs alive at ``t_min``, of them escaped),
        ``rate, rate_low, rate_high`` (exponential tail, 95 % CI), ``alpha, alpha_low,
        alpha_high`` (algebraic tail), ``aic_exp_minus_alg`` and ``tail_law``
        (exponential, algebraic or undecided: :data:`AIC_MARGIN`), ``note`` (why a fit is
        missing).
    """
    from kicktimes.stats import fit_escape_tail

    check_frame("runs", runs, _RUN_COLUMNS)
    if isinstance(t_min, bool) or not isinstance(t_min, int | float | np.floating):
        raise TypeError(f"t_min must be a number, got {type(t_min).__name__}")
    if not (math.isfinite(t_min) and t_min > 0):
        raise ValueError(f"t_min must be positive and finite, got {float(t_min)}")
    curves = escape_curves(runs) if curves is None else curves
    rows = []
    for (r, system), g in runs.groupby(["radius", "system"], sort=True, observed=True):
        time, horizon = g["time"].to_numpy(float), g["horizon"].to_numpy(float)
        km = curves[(curves["radius"] == r) & (curves["system"] == system)]
        row = {"radius": r, "system": system, "followed": g["followed"].iloc[0],
               "n": len(g), "escaped": int(np.isfinite(time).sum()),
               "other_disk_escaped": int(g["other_disk"].sum()), "t_min": float(t_min),
               "survival_t_min": _survival_at(km, t_min, horizon.max()),
               "survival_10_t_min": _survival_at(km, 10 * t_min, horizon.max())}
        fit = dict.fromkeys(("n_tail", "tail_escaped", "rate", "rate_low", "rate_high",
                             "alpha", "alpha_low", "alpha_high", "aic_exp_minus_alg"),
                            math.nan)
        note = ""
        try:
            tail = fit_escape_tail(time, horizon, t_min=t_min)
        except ValueError as exc:
            note = str(exc)
        else:
            fit.update(n_tail=tail.n_tail, tail_escaped=tail.n_escaped, rate=tail.rate,
                       rate_low=tail.rate_ci[0], rate_high=tail.rate_ci[1], alpha=tail.alpha,
                       alpha_low=tail.alpha_ci[0], alpha_high=tail.alpha_ci[1],
                       aic_exp_minus_alg=tail.aic_exponential - tail.aic_algebraic)
            if tail.n_escaped == 0:
                note = f"no escape beyond t_min = {t_min:g}: the intervals are upper bounds"
        rows.append({**row, **fit, "tail_law": _tail_law(fit["aic_exp_minus_alg"]),
                     "note": note})
    out = pd.DataFrame(rows)
    # the report's system order (two disks first), radius-major
    rank = {s: k for k, s in enumerate(SYSTEMS)}
    order = sorted(range(len(out)), key=lambda k: (out["radius"].iloc[k],
                                                    rank.get(out["system"].iloc[k], len(rank)),
                                                    out["system"].iloc[k]))
    return out.iloc[order].reset_index(drop=True)


def _compared(law, law_two):
    """The parameter two tails are compared on: α when at least one is algebraic and
    neither exponential, γ otherwise."""
    laws = {law, law_two}
    return "alpha" if "algebraic" in laws and "exponential" not in laws else "rate"


def escape_comparison(table) -> pd.DataFrame:
    """Each kicked system against the two-disk system, per radius.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`escape_table`'s rows (with the two-disk system's).

    Returns
    -------
    pandas.DataFrame
        ``radius, system, tail_law, tail_law_two_particle, compared`` (``rate`` or
        ``alpha``), ``estimate, low, high`` and the same of the two-disk system
        (``..._two_particle``), ``ci_overlap``, the ``ratio`` kicked / two disks with
        ``ratio_low``, ``ratio_high``, and ``verdict``: ``like``, ``not like``,
        ``inconclusive`` or ``n/a`` with its ``reason`` (the module's rules).
    """
    from kicktimes.stats import format_interval, ratio_verdict

    check_frame("table", table, ["radius", "system", "followed", "tail_law", "rate",
                                 "rate_low", "rate_high", "alpha", "alpha_low",
                                 "alpha_high"], allow_empty=True)
    rows = []
    for r, g in table.groupby("radius", sort=True, observed=True):
        ref = g[g["system"] == REFERENCE]
        if ref.empty:
            continue
        ref = ref.iloc[0]
        for _, row in g[g["system"] != REFERENCE].iterrows():
            compared = _compared(row["tail_law"], ref["tail_law"])
            out = {"radius": r, "system": row["system"], "tail_law": row["tail_law"],
                   "tail_law_two_particle": ref["tail_law"], "compared": compared}
            for suffix, src in (("", row), ("_two_particle", ref)):
                out.update({f"estimate{suffix}": src[compared],
                            f"low{suffix}": src[f"{compared}_low"],
                            f"high{suffix}": src[f"{compared}_high"]})
            overlap = bool(out["low"] <= out["high_two_particle"]
                           and out["low_two_particle"] <= out["high"])
            ratio, ratio_low, ratio_high = _ratio(out)
            if ref["followed"] != "disk 0":
                verdict, reason = "n/a", ("the store does not record which disk left the "
                                          "two-disk table")
            elif not (np.isfinite(out["estimate"]) and np.isfinite(out["estimate_two_particle"])):
                verdict, reason = "n/a", "a tail fit is missing (no run alive at t_min)"
            elif {row["tail_law"], ref["tail_law"]} == {"exponential", "algebraic"}:
                verdict, reason = "not like", "one tail is exponential, the other algebraic"
            else:
                name = "γ" if compared == "rate" else "α"
                rv = ratio_verdict(ratio_low, ratio_high, tolerance=MARGIN)
                verdict = {"lower": "not like", "higher": "not like",
                           "inconclusive": "inconclusive"}.get(rv, "like")
                reason = (f"ratio of {name} {format_interval(ratio, ratio_low, ratio_high)}: "
                          f"{rv}")
            rows.append({**out, "ci_overlap": overlap, "ratio": ratio, "ratio_low": ratio_low,
                         "ratio_high": ratio_high, "verdict": verdict, "reason": reason})
    columns = ["radius", "system", "tail_law", "tail_law_two_particle", "compared",
               "estimate", "low", "high", "estimate_two_particle", "low_two_particle",
               "high_two_particle", "ci_overlap", "ratio", "ratio_low", "ratio_high",
               "verdict", "reason"]
    return pd.DataFrame(rows, columns=columns)


def _ratio(out):
    """Kicked / two-disk ratio of the compared parameter with its 95 % interval (the two
    exact intervals combined on the log scale); NaNs when an interval is missing."""
    ends = (out["low"], out["high"], out["low_two_particle"], out["high_two_particle"])
    est, ref = out["estimate"], out["estimate_two_particle"]
    if not all(np.isfinite(v) and v > 0 for v in (*ends, est, ref)):
        return math.nan, math.nan, math.nan
    sd = math.hypot(math.log(out["high"] / out["low"]),
                    math.log(out["high_two_particle"] / out["low_two_particle"])) / (2 * 1.96)
    ratio = est / ref
    return ratio, ratio * math.exp(-1.96 * sd), ratio * math.exp(1.96 * sd)


def _case(row):
    """One comparison with its numbers, for the answer's text."""
    name = "γ" if row.compared == "rate" else "α"
    if row.reason.startswith("one tail"):
        numbers = f"{row.tail_law} tail against the two disks' {row.tail_law_two_particle}"
    else:
        numbers = (f"{name} = {number_text(row.estimate)} [{number_text(row.low)}, "
                   f"{number_text(row.high)}] against "
                   f"{number_text(row.estimate_two_particle)} "
                   f"[{number_text(row.low_two_particle)}, "
                   f"{number_text(row.high_two_particle)}], {row.reason}")
    return f"r = {row.radius:g}, {system_label(row.system)}: {numbers}"


def _cases(rows, limit=6):
    text = "; ".join(_case(row) for row in rows.head(limit).itertuples())
    more = len(rows) - limit
    return text + (f"; and {more} more (table escape_comparison)" if more > 0 else "")


def escape_answer(comparison) -> str:
    """The computed one-line answer to "does the kicked disk escape like the two disks?".

    "Yes" when every (radius, kicked system) compared is "like" (the equivalence test),
    "No" when every one is "not like", "Undecided" when none is either (every ratio's
    interval straddles an edge of the band), and otherwise "It depends on the radius",
    "... on the kicked system" or "... on the radius and the kicked system" (whichever
    splits the verdicts cleanly), with the numbers of the cases that differ.
    Comparisons that could not be made ("n/a") are named.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> rng = np.random.default_rng(0)
    >>> rows = [(0.02, ic, system, name, value)
    ...         for system in ("two_particle", "poisson")
    ...         for ic, t in enumerate(rng.exponential(40.0, 20000))
    ...         for name, value in (("escape_time", t), ("t_max", t), ("escaped_disk", 0.0))
    ...         if name != "escaped_disk" or system == "two_particle"]
    >>> results = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])
    >>> table = escape_table(escape_runs(results), t_min=10.0)
    >>> escape_answer(escape_comparison(table))[:55]
    'Does the kicked disk escape like the two disks? Yes: at'
    """
    check_frame("comparison", comparison, ["radius", "system", "verdict", "reason"],
                allow_empty=True)
    question = "Does the kicked disk escape like the two disks? "
    if comparison.empty:
        return question + "Not computed: the store has no kicked system and two-disk system " \
                          "to compare."
    made = comparison[comparison["verdict"] != "n/a"]
    if made.empty:
        reasons = sorted(set(comparison["reason"]))
        return question + "Not computed: " + "; ".join(reasons) + "."
    like = made["verdict"] == "like"
    unlike = made["verdict"] == "not like"
    where = f"{made['radius'].nunique()} radii × {made['system'].nunique()} kicked systems"
    if like.all():
        answer = (f"Yes: at every radius every kicked system's escape tail matches the two "
                  f"disks' (same tail law, the ratio's 95 % interval within {100 * MARGIN:g} "
                  f"%; {where}).")
    elif unlike.all():
        answer = ("No: no kicked system escapes like the two disks at any radius ("
                  + _cases(made) + ").")
    elif not (like.any() or unlike.any()):
        answer = (f"Undecided: every ratio's 95 % interval straddles an edge of the "
                  f"±{100 * MARGIN:g} % band (" + _cases(made) + ").")
    else:
        by_radius = (made.groupby("radius", observed=True)["verdict"].nunique() == 1).all()
        by_system = (made.groupby("system", observed=True)["verdict"].nunique() == 1).all()
        if by_radius and not by_system:
            yes = sorted(made.loc[like, "radius"].unique())
            on = f"the radius: like at r = {', '.join(f'{r:g}' for r in yes)}"
        elif by_system and not by_radius:
            yes = made.loc[like, "system"].unique()
            on = f"the kicked system: like for {', '.join(system_label(s) for s in yes)}"
        else:
            on = f"the radius and the kicked system: like in {int(like.sum())} of {len(made)}"
        answer = f"It depends on {on}; not like or inconclusive for {_cases(made[~like])}."
    if {"tail_law", "tail_law_two_particle"} <= set(made.columns):
        weak = made[like & ((made["tail_law"] == "undecided")
                            | (made["tail_law_two_particle"] == "undecided"))]
        if len(weak):
            answer += (f" {len(weak)} of the {int(like.sum())} 'like' verdicts compare a tail "
                       "whose law AIC leaves undecided (few escapes beyond t_min): weak "
                       "evidence.")
    skipped = comparison[comparison["verdict"] == "n/a"]
    if len(skipped):
        answer += (f" Not compared: {len(skipped)} (radius, system) pairs ("
                   + "; ".join(sorted(set(skipped["reason"]))) + ").")
    return question + answer


def escape_figure(curves, *, t_min=None):
    """Kaplan–Meier survival of every system, one log-log panel per radius.

    Parameters
    ----------
    curves : pandas.DataFrame
        :func:`escape_curves`' table.
    t_min : float, optional
        Where the tail fits start (a dotted vertical line).

    Returns
    -------
    matplotlib.figure.Figure
        Per radius a panel; per system its survival (steps, up to the system's last
        observed time ``end``) with its pointwise 95 % band, in the report's system
        colours, the two-disk system drawn thicker, while `kicktimes.stats.MIN_AT_RISK`
        runs or more are at risk (where ``curves`` has ``n_at_risk``); beyond, a thin grey dotted
        line without a band. The time axis starts at 1/1000 of the longest horizon
        (earlier, S is near 1).
    """
    check_frame("curves", curves, ["radius", "system", "time", "survival", "ci_low",
                                   "ci_high", "end"])
    radii = sorted(curves["radius"].unique())
    ncol = min(len(radii), 3)
    nrow = math.ceil(len(radii) / ncol)
    fig = Figure(figsize=(4.2 * ncol, 3.6 * nrow + 0.8), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrow, ncol, sharex=True, sharey=True, squeeze=False)
                         ).ravel()
    present = set(curves["system"])
    order = [s for s in SYSTEMS if s in present] + sorted(present - set(SYSTEMS))
    t_hi = float(curves["end"].max())
    t_lo = max(0.8 * float(curves["time"].min()), 1e-3 * t_hi)
    positive = curves["survival"].to_numpy(float)
    floor = max(0.5 * float(positive[positive > 0].min()) if (positive > 0).any() else 1e-3,
                1e-4)
    for ax, r in zip(axes, radii, strict=False):
        for k, system in enumerate(order):
            km = curves[(curves["radius"] == r) & (curves["system"] == system)]
            if km.empty:
                continue
            style = system_style(system, k)
            two = system == REFERENCE
            # from S = 1 at the left edge, held up to the system's last observed time
            survival_steps(ax, km.assign(time=np.maximum(km["time"], t_lo)),
                           color=style["color"], label=system_label(system),
                           line={"linewidth": 2.0 if two else 1.2, "zorder": 3 if two else 2},
                           start=t_lo, end=km["end"].iloc[0], clip=floor,
                           gid=f"few_at_risk_{system}")
        if t_min is not None:
            ax.axvline(t_min, color="0.4", linestyle=":", linewidth=1.0,
                       label="t_min (tail fits start)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(t_lo, t_hi)
        ax.set_ylim(floor, 1.15)
        ax.set_title(f"r = {r:g}", fontsize="medium")
        ax.grid(True, which="major", color="0.9", linewidth=0.6)
    for ax in axes[len(radii):]:
        ax.set_axis_off()
    for ax in axes[:len(radii)]:
        plain_log_ticks(ax.xaxis)
        plain_log_ticks(ax.yaxis)
    for ax in axes[(nrow - 1) * ncol:]:
        ax.set_xlabel("time t (time units)")
    for ax in axes[::ncol]:
        ax.set_ylabel("survival S(t) = P(no escape by t)")
    shared_legend(fig, list(axes[:len(radii)]))
    return fig


def sections(ctx):
    """The escape section, for a store whose experiment has holes (none otherwise)."""
    holes = tuple(getattr(ctx.exp, "holes", ()) or ())
    if not holes:
        return []
    runs = escape_runs(ctx.results)
    if runs.empty:
        return []
    t_min = ctx.escape_t_min
    if t_min is None:
        t_min = T_MIN_FRACTION * ctx.exp.horizon
    curves = escape_curves(runs)
    table = escape_table(runs, t_min=t_min, curves=curves)
    comparison = escape_comparison(table)
    sec = Section("escape", "Escape through the holes", answers_first=True)
    sec.text(escape_answer(comparison))
    sec.fold()
    widths = ", ".join(f"centre {c:g} rad, half-width {h:g} rad" for c, h in holes)
    either = (runs["followed"] == "either disk").any()
    censoring = (
        "This store does not record which disk left the two-disk table (its sweep predates "
        "the escaped_disk row): the two-disk curve is the first escape of either disk, and "
        "it is not compared with the one-disk systems."
        if either else
        "The kicked systems follow disk 0; in the two-disk system disk 0's escape is the "
        "event and an earlier escape of disk 1, which ends the run, censors it "
        f"({int(runs['other_disk'].sum())} runs)."
    )
    origin = ("the report's escape_t_min" if ctx.escape_t_min is not None
              else "the default, 1/20 of the horizon n_steps·tau")
    sec.text(
        f"Holes: {widths}. Every run ends at its escape; a run that does not escape is "
        "censored at its end (its t_max). " + censoring + " Survival: Kaplan–Meier with "
        f"pointwise 95 % intervals. Tails beyond t_min = {number_text(t_min)} ({origin}): censored "
        "maximum-likelihood fits of an exponential tail S ∝ exp(−γt) and an algebraic one "
        "S ∝ t^−α with exact 95 % intervals; the tail law is the one whose AIC is lower by "
        f"more than {AIC_MARGIN:g}, undecided otherwise. A kicked system escapes like the "
        "two disks at a radius when the tail laws do not conflict (exponential against "
        "algebraic) and the 95 % interval of the ratio of the shared parameter (α when a "
        f"tail is algebraic, γ otherwise) lies within ±{100 * MARGIN:g} % (an equivalence "
        "test, its margin fixed in advance); not like when the interval lies wholly outside "
        "the band or the tail laws conflict; inconclusive otherwise. Overlapping intervals "
        "of the two parameters (column ci_overlap) are not read as agreement."
    )
    sec.table("escape_comparison", comparison, "Each kicked system against the two disks")
    sec.table("escape_tails", table, "Escape per radius and system")
    sec.figure(
        "fig11_escape_survival",
        escape_figure(curves, t_min=t_min),
        "Survival S(t) of the escape time per radius (log-log): Kaplan–Meier steps with "
        "pointwise 95 % bands, the two-disk system ("
        + ("the first escape of either disk" if either else
           "disk 0's escape; disk 1's censors it")
        + ") drawn thicker; the dotted line is t_min, where the tail fits start. Each curve "
        f"is drawn with its band while at least {MIN_AT_RISK} runs are at risk, then thin, "
        "grey and dotted: there a step is one of a handful of runs"
        + ("" if either else ", and the two-disk risk set is emptied by disk 1's escapes, "
           "which would read as physics")
        + ". An exponential tail bends down on these axes, an algebraic one is a straight "
        "line.",
    )
    sec.table("escape_survival", curves, "Kaplan–Meier survival curves", show=False)
    return [sec]
