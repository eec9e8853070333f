r"""Poisson tests of the disk-disk collision times, per IC (one panel per test), and the
rate heterogeneity across ICs.

Per radius, :func:`kicktimes.stats.test_poisson_ensemble` tests every IC's collision times
(each test conditional on the IC's own number of collisions) and the hypothesis of a common
rate across ICs (Pearson χ² given the total, with an exact Monte Carlo p-value). The Monte
Carlo nulls of equal ``n`` are shared by every radius (`null_bank`).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from kicktimes.render.figures import (
    check_alpha,
    check_frame,
    dodge,
    finite,
    new_axes,
    x_axis,
)
from kicktimes.render.pages import percent_text, rho_text
from kicktimes.report.context import Section, seeded_rng
from kicktimes.report.counts import experiment_kinetic, kinetic_rate_of
from kicktimes.report.effects import Effect
from kicktimes.stats import (
    SHARE_RULE,
    clopper_pearson,
    format_interval,
    percentile_interval,
    resample_counts,
    share_verdict,
    spearman,
)
from kicktimes.stats.poisson import TEST_NULLS
from kicktimes.validation import keyword_only_after

__all__ = [
    "binomial_ci",
    "rejection_table",
    "poisson_rejection_rates",
    "sections",
    "effects",
    "HEADLINE_TEST",
    "null_bank",
]

#: the test of the Findings: given n, the times of a homogeneous Poisson process are
#: uniform on the window (exact, conditional KS); the others are listed beside it
HEADLINE_TEST = "uniformity_ks"
#: what each test checks, as panel titles
TEST_TITLES = {
    "uniformity_ks": "uniform times given N (KS)",
    "laplace_trend": "no rate trend (Laplace)",
    "exponential_ks": "exponential intervals (KS)",
    "exponential_ad": "exponential intervals (AD)",
    "ljung_box": "uncorrelated intervals (Ljung-Box)",
    "runs": "runs above/below the median",
    "dispersion": "count dispersion",
}
#: the headline test is also run on the first FIXED_EVENTS collisions of every run (the
#: first FIXED_EVENTS - 1 times, uniform on (0, t_FIXED_EVENTS) under Poisson), so that
#: rejection rates at different radii compare the same number of intervals (equal power)
FIXED_EVENTS = 30


@keyword_only_after(2, since="0.2.0")
def binomial_ci(k, n, *, level=0.95):
    """Clopper-Pearson interval of ``k`` successes in ``n`` trials (NaN where n = 0): the
    arrays of `kicktimes.stats.clopper_pearson`."""
    return clopper_pearson(k, n, level=level)


def rejection_table(rejections, *, level=0.95, x="radius") -> pd.DataFrame:
    """Add ``rate`` and Clopper-Pearson ``ci_low``/``ci_high`` to counts of rejections.

    ``rejections`` has columns ``<x>, test, n_tested, n_reject`` (``x``: the radius, or the
    column of the figure's x axis).
    """
    df = check_frame("rejections", rejections, [x, "test", "n_tested", "n_reject"])
    n = finite("rejections['n_tested']", df["n_tested"])
    k = finite("rejections['n_reject']", df["n_reject"])
    if ((k < 0) | (k > n)).any():
        raise ValueError("rejections must satisfy 0 <= n_reject <= n_tested")
    out = df.copy()
    with np.errstate(invalid="ignore", divide="ignore"):
        out["rate"] = np.where(n > 0, k / np.where(n > 0, n, 1), np.nan)
    out["ci_low"], out["ci_high"] = binomial_ci(k, n, level=level)
    if {"control_n_tested", "control_n_reject"} <= set(df.columns):
        nc, kc = df["control_n_tested"].to_numpy(float), df["control_n_reject"].to_numpy(float)
        with np.errstate(invalid="ignore", divide="ignore"):
            out["control_rate"] = np.where(nc > 0, kc / np.where(nc > 0, nc, 1), np.nan)
    return out


def poisson_rejection_rates(rejections, *, alpha=0.05, ncols=4, ax=None, x="radius",
                            xlabel=None):
    """Rejection rate of each Poisson test per radius, one panel per test (small multiples).

    Parameters
    ----------
    rejections : pandas.DataFrame
        ``radius, test, n_tested, n_reject`` (sequences tested and rejected at level
        ``alpha``); ``rate``/``ci_low``/``ci_high`` are computed when absent
        (Clopper-Pearson, :func:`rejection_table`).
    alpha : float
        The level of the tests; drawn in every panel as the rate expected if every IC
        were Poisson.
    ncols : int
        Panels per row.
    ax : matplotlib Axes, optional
        Draw every test into this one Axes instead (overlaid, slightly shifted along x,
        with a legend): a compact form for a grid of such plots.
    x, xlabel : str, optional
        The column drawn along x and its axis label (default: the disk radius; e.g. the
        group of `kicktimes analyze`; a column of labels is drawn at 0, 1, ...).

    Returns
    -------
    matplotlib.figure.Figure
        One panel per test, shared axes, rate ± 95 % Clopper-Pearson interval at each x.
    """
    alpha = check_alpha(alpha)
    axis = x_axis(x, xlabel)
    if isinstance(rejections, pd.DataFrame) and {"rate", "ci_low", "ci_high"} <= set(
        rejections.columns
    ):
        table = check_frame("rejections", rejections, [x, "test", "rate"])
    else:
        table = rejection_table(rejections, x=x)
    table, axis = axis.positions(rejections=table)
    tests = list(dict.fromkeys(table["test"]))
    if ax is not None:
        return _overlaid(table, tests, alpha, ax, axis)
    ncols = min(ncols, len(tests))
    nrows = math.ceil(len(tests) / ncols)
    fig = Figure(figsize=(3.3 * ncols, 2.9 * nrows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False))
    axes = axes.ravel()
    for k, (ax, test) in enumerate(zip(axes, tests, strict=False)):
        part = table[table["test"] == test].sort_values(x)
        _rate_bars(ax, part[x], part, color="C0",
                   linestyle=axis.line)
        if "control_rate" in part.columns and part["control_rate"].notna().any():
            ax.plot(part[x], part["control_rate"], color="grey", marker="s",
                    markersize=3, linewidth=0.8, linestyle=axis.line,
                    label="control: the sweep's Poisson kicks")
        ax.axhline(alpha, color="black", linestyle=":", linewidth=0.8)
        ax.set_title(TEST_TITLES.get(test, test.replace("_", " ")), fontsize="medium")
        ax.set_ylim(0.0, 1.0)
        if k % ncols == 0:
            ax.set_ylabel(f"share rejected at α = {alpha:g}")
        if k >= len(tests) - ncols:
            axis.draw(ax)
            ax.tick_params(axis="x", labelbottom=True)
    for ax in axes[len(tests) :]:
        ax.set_visible(False)
    nouns = axis.nouns
    handles = [Line2D([], [], color="C0", marker="o", markersize=4, linestyle=axis.line,
                      label=f"{nouns.events} (± 95 % CI)")]
    if "control_rate" in table.columns and table["control_rate"].notna().any():
        handles.append(Line2D([], [], color="grey", marker="s", markersize=3,
                              label="control: the same tests on the sweep's Poisson kick times"))
    handles.append(Line2D([], [], color="black", linestyle=":",
                          label=f"α = {alpha:g}, the share if every {nouns.one} were Poisson"))
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles),
               fontsize="small")
    fig.suptitle(f"Poisson tests of the {nouns.events}, per {nouns.one}: share of "
                 f"{nouns.many} rejected", fontsize="medium")
    return fig


def _rate_bars(ax, x, part, **style):
    """The rejection rates of ``part`` at ``x`` with their 95 % intervals."""
    rate = part["rate"].to_numpy()
    err = np.vstack([rate - part["ci_low"].to_numpy(), part["ci_high"].to_numpy() - rate])
    ax.errorbar(x, rate, yerr=err, marker="o", markersize=4, capsize=2, linewidth=1, **style)


def _overlaid(table, tests, alpha, ax, axis):
    fig, ax = new_axes(ax, (6.4, 4.4))
    xs = table[axis.column].to_numpy()
    for k, test in enumerate(tests):
        part = table[table["test"] == test].sort_values(axis.column)
        shifted = part[axis.column].to_numpy() + dodge(xs, k, len(tests))
        _rate_bars(ax, shifted, part, label=test.replace("_", " "), color=f"C{k}",
                   linestyle=axis.line)
    ax.axhline(alpha, color="black", linestyle=":",
               label=f"α = {alpha:g} (all {axis.nouns.many} Poisson)")
    ax.set_ylim(0.0, 1.0)
    axis.draw(ax)
    ax.set_ylabel(f"share of {axis.nouns.many} rejected at α = {alpha:g}")
    ax.legend(fontsize="x-small", ncol=2)
    return fig


def subsample(part, limit):
    ics = np.sort(part["ic"].unique())
    return part[part["ic"].isin(ics[:limit])] if limit is not None and ics.size > limit else part


def _control_times(seqs, windows, ics, r, control):
    """The sweep's own Poisson kick times of each IC (rate n_pp / t_window, the "poisson"
    system's stream), cut at the same window: Poisson by construction."""
    from kicktimes.experiment import kick_rng
    from kicktimes.schedules import Poisson

    exp_seed, horizon = control
    out = []
    for ic, t, w in zip(ics, seqs, windows, strict=True):
        if t.size == 0:
            out.append(np.empty(0))
            continue
        kicks = Poisson(t.size / w).sample(
            horizon, rng=kick_rng(int(ic), r, "poisson", rng=exp_seed))
        out.append(kicks[kicks <= w])
    return out


#: the first bin of the interval hazard, in units of the run's mean interval
HAZARD_BIN = 0.1


def interval_sums(seqs, windows, prefix):
    """Per run, the sufficient sums of its intervals in units of its own mean interval
    (``x = diff(t) n / w``): the first hazard bin's events and exposure
    (``x < HAZARD_BIN``; hazard = events / exposure, 1 for a Poisson process) and the
    count, sum and sum of logs of ``x`` (the gamma MLE of pooled intervals depends on
    ``mean x`` and ``mean log x`` only), as columns ``<prefix>hz_events, <prefix>hz_exposure,
    <prefix>n_x, <prefix>sum_x, <prefix>sum_log_x``."""
    cols = {k: np.zeros(len(seqs)) for k in ("hz_events", "hz_exposure", "n_x", "sum_x",
                                              "sum_log_x")}
    for k, (t, w) in enumerate(zip(seqs, windows, strict=True)):
        if t.size < 3:
            continue
        x = np.diff(t) * (t.size / w)
        x = x[x > 0]
        cols["hz_events"][k] = np.count_nonzero(x < HAZARD_BIN)
        cols["hz_exposure"][k] = np.minimum(x, HAZARD_BIN).sum()
        cols["n_x"][k], cols["sum_x"][k], cols["sum_log_x"][k] = x.size, x.sum(), np.log(x).sum()
    return {prefix + k: v for k, v in cols.items()}


#: the columns of the rate-homogeneity table, in order (`kicktimes.stats.PoissonGroup`'s
#: ``homogeneity`` with ``n_sequences`` named ``n_ics`` and the kinetic rate beside)
_HOMOGENEITY = ("dispersion_index", "pearson_statistic", "df", "pvalue", "pvalue_mc",
                "lr_pvalue", "n_flagged_fdr")


@functools.lru_cache(maxsize=4)
def null_bank(seed: int):
    """This process's `kicktimes.stats.MonteCarloNulls` of the experiments seeded ``seed``.

    The conditional nulls depend on ``n`` only, so every radius, its Poisson control and
    the other experiments with this seed (a family and its controls) share them: about
    4x fewer null draws than a stream per radius (266 distinct ``n`` in family B against
    1123 (radius, ``n``) groups). A null's values depend on the seed and its key only,
    so the tables do not depend on which process or job drew it first.
    """
    from kicktimes import stats

    return stats.MonteCarloNulls(seed)


def _poisson_job(job):
    """Poisson tests and rate homogeneity of one radius (runs in a worker process): the
    group tables of `kicktimes.stats.poisson_group`, with group = radius."""
    from kicktimes import stats
    from kicktimes.stats.poisson import uniformity_ks

    r, seqs, windows, alpha, n_mc, seed_key, kinetic_rate, ics, control = job
    nulls = null_bank(seed_key[0])
    group = stats.poisson_group(seqs, windows, alpha=alpha, n_mc=n_mc, rng=seeded_rng(*seed_key),
                                nulls=nulls)
    rows = group.rejections.drop(columns="rate")
    rows.insert(0, "radius", r)
    ctrl = None
    if control is not None:
        # the control: the same tests on the sweep's own Poisson kick times of each IC;
        # every test should reject about alpha of them
        control_seqs = _control_times(seqs, windows, ics, r, control)
        ctrl = stats.poisson_group(control_seqs, windows,
                                   alpha=alpha, n_mc=n_mc, rng=seeded_rng(*seed_key, 9),
                                   nulls=nulls)
        rows["control_n_tested"] = ctrl.rejections["n_tested"]
        rows["control_n_reject"] = ctrl.rejections["n_reject"]
    # per IC: the headline test's p-value, and the same test on the first FIXED_EVENTS
    # collisions only (NaN for runs with fewer)
    p_fixed = np.full(len(seqs), np.nan)
    long = [k for k, t in enumerate(seqs) if t.size >= FIXED_EVENTS]
    if long:
        u = np.array([seqs[k][: FIXED_EVENTS - 1] / seqs[k][FIXED_EVENTS - 1] for k in long])
        p_fixed[long] = uniformity_ks(u)[1]
    per_ic = pd.DataFrame({"radius": r, "ic": ics,
                           "p": group.ensemble.per_sequence[f"p_{HEADLINE_TEST}"].to_numpy(float),
                           "p_fixed": p_fixed,
                           "dispersion": group.ensemble.statistics["dispersion"].to_numpy(float)})
    if ctrl is not None:
        # the null calibration, run by run: the headline test's p-value and the dispersion
        # index of the IC's Poisson control stream (same window, same tests)
        per_ic["control_p"] = ctrl.ensemble.per_sequence[f"p_{HEADLINE_TEST}"].to_numpy(float)
        per_ic["control_dispersion"] = ctrl.ensemble.statistics["dispersion"].to_numpy(float)
        per_ic = per_ic.assign(**interval_sums(seqs, windows, ""),
                               **interval_sums(control_seqs, windows, "control_"))
    hom = group.homogeneity
    hom_row = {
        "radius": r,
        "n_ics": hom["n_sequences"],
        "pooled_rate": hom["pooled_rate"],
        "median_rate": hom["median_rate"],
        "kinetic_rate": kinetic_rate,
        **{name: hom[name] for name in _HOMOGENEITY},
    }
    return rows.to_dict("records"), hom_row, per_ic


def _jobs(ctx):
    exp, coll = ctx.exp, ctx.store.collisions
    jobs = []
    for ri, (r, part) in enumerate(coll.groupby("radius", observed=True)):
        part = subsample(part.sort_values("ic"), ctx.max_ics_tests)
        seqs = [np.asarray(t, dtype=float) for t in part["pp_times"]]
        # one Monte Carlo stream per radius (its ties and rate test; the nulls come from
        # the seed's shared bank): identical results for any worker count
        key = (exp.seed, 1, ri)
        # (event times from elsewhere, `kicktimes analyze`, have no kick schedules)
        control = ((exp.seed, exp.horizon) if "poisson" in getattr(exp, "systems", ()) else None)
        jobs.append((r, seqs, part["t_window"].to_numpy(float), ctx.alpha, ctx.n_mc, key,
                     float(kinetic_rate_of(r, exp.rule, experiment_kinetic(exp))),
                     part["ic"].to_numpy(), control))
    return jobs


def start(ctx):
    """Start the per-radius tests on the pool ahead of the section (they need only the
    collision times): they run while the sections before this one are computed."""
    if ctx.pstart is not None:
        ctx.pending["poisson"] = ctx.pstart(_poisson_job, _jobs(ctx))


def sections(ctx):
    """Per-IC Poisson tests at every radius (one job per radius, seeded per radius)."""
    coll = ctx.store.collisions
    alpha, n_mc, max_ics_tests = ctx.alpha, ctx.n_mc, ctx.max_ics_tests
    started = ctx.pending.pop("poisson", None)
    results = started() if started is not None else ctx.pmap(_poisson_job, _jobs(ctx))
    rej_rows, hom_rows, per_ic = [], [], []
    for rows, hom_row, ic_rows in results:
        rej_rows += rows
        hom_rows.append(hom_row)
        per_ic.append(ic_rows)
    rejections = rejection_table(pd.DataFrame(rej_rows))
    per_ic = pd.concat(per_ic, ignore_index=True)
    fixed = per_ic.groupby("radius", observed=True).agg(
        n_tested_fixed=("p_fixed", lambda p: int(np.isfinite(p).sum())),
        n_reject_fixed=("p_fixed", lambda p: int((p < alpha).sum())),
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        fixed["rate_fixed"] = fixed["n_reject_fixed"] / fixed["n_tested_fixed"]
    headline = rejections["test"] == HEADLINE_TEST
    for col in fixed.columns:
        rejections.loc[headline, col] = rejections.loc[headline, "radius"].map(fixed[col])
    homogeneity = pd.DataFrame(hom_rows)
    most_ics = coll.groupby("radius", observed=True)["ic"].nunique().max()
    if max_ics_tests is not None and most_ics > max_ics_tests:
        ctx.notes.append(
            f"Poisson tests and rate homogeneity: the first {max_ics_tests} ICs (by index) "
            "per radius."
        )
    sec = Section("poisson_tests", "Poisson tests of the collision times, per IC")
    sec.figure(
        "fig08_poisson_rejection_rates",
        poisson_rejection_rates(rejections, alpha=alpha),
        f"Share of ICs whose disk-disk collision times reject a homogeneous Poisson process at "
        f"α = {alpha:g}, one panel per test, per radius, with 95% Clopper-Pearson intervals. Each "
        "test conditions on the IC's own number of collisions; nulls: "
        + "; ".join(f"{t} {TEST_NULLS[t]}" for t in rejections["test"].unique() if t in TEST_NULLS)
        + f" (Monte Carlo with n_mc = {n_mc}).",
    )
    lines = []
    for test, t in rejections.groupby("test", sort=False, observed=True):
        t = t.sort_values("radius")
        rho, p = spearman(t["radius"], t["rate"])
        lines.append(
            f"{test}: {percent_text(t['rate'].iloc[0])} at r = {t['radius'].iloc[0]:g}, "
            f"{percent_text(t['rate'].iloc[-1])} at r = {t['radius'].iloc[-1]:g} "
            f"(Spearman ρ with r: {rho_text(rho, p)})"
        )
    above = rejections[rejections["ci_low"] > alpha]
    tested = rejections[rejections["n_tested"] > 0]
    sec.text(
        f"Under the null each test rejects {percent_text(alpha)} of ICs. Rejection rates — "
        + "; ".join(lines)
        + f". The 95% interval lies above α for {len(above)} of {len(tested)} "
        f"(test, radius) cells with tested ICs; the Fisher-combined p-value is below {alpha:g} for "
        f"{int((rejections['combined_pvalue'] < alpha).sum())} of them. Tests with too few "
        "events in an IC are not run on it (n_tested counts the ICs tested)."
    )
    if "control_rate" in rejections.columns:
        c = rejections.groupby("test", sort=False, observed=True)[
            ["control_n_reject", "control_n_tested"]].sum()
        sec.text(
            "Control: the same tests on the sweep's own Poisson kick times of each run (rate "
            "n_pp / t_window, cut at the same window; Poisson by construction) reject "
            + "; ".join(f"{TEST_TITLES.get(t, t)} "
                        f"{percent_text(row.control_n_reject / row.control_n_tested)}"
                        for t, row in c.iterrows() if row.control_n_tested > 0)
            + f" of them, against the nominal {percent_text(alpha)}."
        )
    t = rejections[headline].sort_values("radius")
    sec.text(
        f"At a fixed number of intervals ({HEADLINE_TEST} on the first {FIXED_EVENTS} "
        "collisions of every run that has them, so every radius has the same power): "
        + ", ".join(f"{percent_text(v)} at r = {r:g} ({int(n)} runs)" for r, v, n in
                    zip(t["radius"], t["rate_fixed"], t["n_tested_fixed"], strict=True))
        + "."
    )
    sec.table("poisson_tests", rejections, "Rejections per radius and test (the headline test "
              f"also at a fixed {FIXED_EVENTS} collisions: *_fixed)")
    ctx.found.rejections = rejections
    ctx.found.poisson_per_ic = per_ic
    # the headline shares' clustered CIs, computed once: the statements and the findings
    # table print the same interval
    ctx.found.poisson_cis = {
        "p": clustered_share(per_ic, "p", alpha, rng=ctx.rng(4), n_boot=ctx.n_boot),
        "p_fixed": clustered_share(per_ic, "p_fixed", alpha, rng=ctx.rng(5),
                                   n_boot=ctx.n_boot)}
    if "control_p" in per_ic.columns:
        # computed once: the calibration file and the findings print the same intervals
        ctx.found.null_referenced = null_referenced(per_ic, rng=ctx.rng(7), n_boot=ctx.n_boot)
        ctx.found.null_calibration = null_calibration(
            ctx.exp.name, rejections, per_ic, alpha=alpha, rng=ctx.rng(6), n_boot=ctx.n_boot,
            referenced=ctx.found.null_referenced)
        # the calibrated levels the findings read each share and statistic against, as a
        # table (a study writes them into its results' null_calibration.csv)
        sec.table("null_calibration", ctx.found.null_calibration, "The runs' Poisson "
                  "control streams through the same tests and statistics", show=False)
    ctx.found.homogeneity = homogeneity
    return [sec]


def clustered_share(per_ic, column, alpha, *, rng, n_boot=2000, level=0.95):
    """95 % CI of the share of runs with ``per_ic[column] < alpha``, by a bootstrap
    clustered on ICs.

    The share is :func:`clustered_mean` of the flags ``p < alpha`` over the runs whose
    ``p`` is finite (``rejections / runs tested`` of each resample, percentile CI).

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> df = pd.DataFrame({"radius": np.repeat([0.01, 0.02], 50), "ic": np.tile(range(50), 2),
    ...                    "p": np.tile(np.r_[np.zeros(10), np.ones(40)], 2)})
    >>> low, high = clustered_share(df, "p", 0.05, rng=np.random.default_rng(0))
    >>> bool(low < 0.2 < high)
    True
    """
    p = per_ic[column].to_numpy(float)
    flags = per_ic.assign(**{column: np.where(np.isfinite(p), (p < alpha).astype(float),
                                              np.nan)})
    _, low, high = clustered_mean(flags, column, rng=rng, n_boot=n_boot, level=level)
    return low, high


def clustered_mean(per_ic, column, *, rng, n_boot=2000, level=0.95):
    """``(mean, low, high)``: the mean of the finite ``per_ic[column]`` over runs and its
    percentile CI from a bootstrap clustered on ICs.

    The runs of one IC at different radii start from the same initial condition, so they
    are not independent: one resample draws IC indices with replacement and takes all
    their runs; its mean is the ratio of the sums ``sum(values) / runs`` (NaN runs left
    out). :func:`clustered_share` is this mean of the rejection flags.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> df = pd.DataFrame({"radius": np.repeat([0.01, 0.02], 50), "ic": np.tile(range(50), 2),
    ...                    "d": np.tile(np.linspace(0.5, 1.5, 50), 2)})
    >>> mean, low, high = clustered_mean(df, "d", rng=np.random.default_rng(0))
    >>> round(mean, 6), bool(low < 1.0 < high)
    (1.0, True)
    """
    table = per_ic.pivot_table(index="ic", columns="radius", values=column, dropna=False,
                                observed=True)
    v = table.to_numpy(float)
    n_runs = np.isfinite(v).sum(axis=1).astype(float)
    total = np.where(np.isfinite(v), v, 0.0).sum(axis=1)
    if n_runs.sum() == 0:
        return math.nan, math.nan, math.nan
    n = n_runs.size
    counts = resample_counts(n, n_boot=n_boot, rng=rng)
    with np.errstate(invalid="ignore", divide="ignore"):
        boot = (counts @ total) / (counts @ n_runs)
    return (float(total.sum() / n_runs.sum()), *percentile_interval(boot, level=level))


#: the statistics read against the runs' Poisson control streams (null_calibration.csv):
#: name in the null calibration -> the findings table's diagnostic
NULL_REFERENCED = {"D": "dispersion_index", "hazard, first bin": "hazard_first",
                   "gamma shape": "gamma_shape"}


def null_referenced(per_ic, *, rng, n_boot=2000, level=0.95) -> pd.DataFrame:
    """The dispersion index D, the hazard of the first interval bin and the pooled gamma
    shape of the runs' collision times and of their Poisson control streams, and the
    difference of the two, with 95 % CIs from one bootstrap clustered on ICs (the same
    resamples for the data, the null and their difference: the difference is paired).

    D is the mean over runs of each run's D; the hazard is the events over the exposure in
    ``[0, HAZARD_BIN)`` of the intervals in units of each run's mean interval, pooled
    (1 for a Poisson process); the gamma shape is the MLE of those pooled intervals
    (`kicktimes.stats.gamma_shape_mle` of their two sufficient means; 1 for exponential
    intervals). Returns one row per statistic of `NULL_REFERENCED`: ``statistic,
    value, low, high, null, null_low, null_high, excess, excess_low, excess_high,
    n_runs, n_clusters``; empty when ``per_ic`` has no control columns.
    """
    from kicktimes.stats import cluster_bootstrap, gamma_shape_mle

    if "control_dispersion" not in per_ic.columns:
        return pd.DataFrame()
    d, cd = per_ic["dispersion"].to_numpy(float), per_ic["control_dispersion"].to_numpy(float)
    columns = {"d": np.where(np.isfinite(d), d, 0.0), "d_n": np.isfinite(d).astype(float),
               "cd": np.where(np.isfinite(cd), cd, 0.0), "cd_n": np.isfinite(cd).astype(float)}
    for prefix in ("", "control_"):
        for k in ("hz_events", "hz_exposure", "n_x", "sum_x", "sum_log_x"):
            columns[prefix + k] = per_ic[prefix + k].to_numpy(float)
    by_ic = pd.DataFrame(columns).groupby(per_ic["ic"].to_numpy()).sum()
    sums = by_ic.to_numpy(float)
    col = {name: j for j, name in enumerate(by_ic.columns)}

    def statistic(idx):
        s = sums[idx].sum(axis=1)  # (m, columns)
        with np.errstate(invalid="ignore", divide="ignore"):
            out = []
            for data, null in (
                    (s[:, col["d"]] / s[:, col["d_n"]], s[:, col["cd"]] / s[:, col["cd_n"]]),
                    (s[:, col["hz_events"]] / s[:, col["hz_exposure"]],
                     s[:, col["control_hz_events"]] / s[:, col["control_hz_exposure"]]),
                    (gamma_shape_mle(s[:, col["sum_x"]] / s[:, col["n_x"]],
                                     s[:, col["sum_log_x"]] / s[:, col["n_x"]]),
                     gamma_shape_mle(s[:, col["control_sum_x"]] / s[:, col["control_n_x"]],
                                     s[:, col["control_sum_log_x"]]
                                     / s[:, col["control_n_x"]]))):
                out += [data, null, data - null]
        return np.column_stack(out)

    res = cluster_bootstrap(statistic, len(by_ic), n_boot=n_boot, level=level, rng=rng,
                            chunk=250)
    est, low, high = (np.atleast_1d(np.asarray(v, float))
                      for v in (res.estimate, res.ci_low, res.ci_high))
    rows = []
    for j, name in enumerate(NULL_REFERENCED):
        k = 3 * j
        rows.append({"statistic": name, "value": est[k], "low": low[k], "high": high[k],
                     "null": est[k + 1], "null_low": low[k + 1], "null_high": high[k + 1],
                     "excess": est[k + 2], "excess_low": low[k + 2],
                     "excess_high": high[k + 2], "n_runs": int(np.isfinite(d).sum()),
                     "n_clusters": len(by_ic)})
    return pd.DataFrame(rows)


#: the null design of the two-disk calibration
NULL_DESIGN = ("Poisson at each run's rate (the sweep's own Poisson kick times of the run's "
               "IC and radius, rate n_pp / t_window, cut at the run's window)")


def null_calibration(name, rejections, per_ic, *, alpha, rng, n_boot=2000,
                     referenced=None) -> pd.DataFrame:
    """The null calibration of the Poisson battery on one experiment's runs.

    Every run's Poisson control stream (:func:`_control_times`: Poisson by construction,
    at the run's own rate and window) went through the same tests as the run's collision
    times. One row per test: the share of control streams it rejects at ``alpha``, pooled
    over radii, with the interval the data's row has: for the headline test a bootstrap
    clustered on ICs (``per_ic["control_p"]``), for the others Clopper-Pearson on the
    counts (runs of one IC at different radii counted apart). The columns are those of
    `kicktimes.render.pages.NULL_CALIBRATION_COLUMNS` without ``study`` and ``verdict``
    (``share`` for ``value``). Then the rows of D, the first hazard bin and the gamma shape
    of the control streams (``referenced``, a :func:`null_referenced` table; computed
    with ``rng`` when not given).
    """

    totals = rejections.groupby("test", sort=False, observed=True)[
        ["control_n_reject", "control_n_tested"]].sum()
    n_ics = int(per_ic["ic"].nunique())
    rows = []
    for test, (k, n) in totals.iterrows():
        k, n = int(k), int(n)
        if n == 0:
            continue
        if test == HEADLINE_TEST:
            low, high = clustered_share(per_ic, "control_p", alpha, rng=rng, n_boot=n_boot)
            clusters = n_ics
        else:
            low, high = clopper_pearson(k, n)
            clusters = n
        rows.append({"data": name, "statistic": "rejection share", "test": test,
                     "design": NULL_DESIGN, "alpha": alpha, "n_runs": n,
                     "n_clusters": clusters, "share": k / n, "ci_low": low, "ci_high": high})
    if referenced is None:
        referenced = null_referenced(per_ic, rng=rng, n_boot=n_boot)
    for r in referenced.itertuples():
        rows.append({"data": name, "statistic": r.statistic, "test": "", "design": NULL_DESIGN,
                     "alpha": alpha, "n_runs": r.n_runs, "n_clusters": r.n_clusters,
                     "share": r.null, "ci_low": r.null_low, "ci_high": r.null_high})
    return pd.DataFrame(rows, columns=["data", "statistic", "test", "design", "alpha",
                                       "n_runs", "n_clusters", "share", "ci_low", "ci_high"])


def null_level(null, test, alpha) -> float:
    """The share of null streams that ``test`` rejects (the calibrated level of its
    verdicts), from a :func:`null_calibration` table; ``alpha`` when there is none."""
    if null is None or null.empty:
        return alpha
    shares = null[null["statistic"] == "rejection share"] if "statistic" in null else null
    if test not in set(shares["test"]):
        return alpha
    return float(shares.loc[shares["test"] == test, "share"].iloc[0])


def effects(ctx):
    """Share of (IC, radius) runs whose collision times reject a Poisson process."""
    rej = ctx.found.rejections
    if rej is None or rej.empty:
        return []
    totals = rej.groupby("test", sort=False, observed=True)[["n_reject", "n_tested"]].sum()
    if HEADLINE_TEST not in totals.index or totals.loc[HEADLINE_TEST, "n_tested"] == 0:
        return []
    k, n = (int(v) for v in totals.loc[HEADLINE_TEST])
    per_ic = ctx.found.poisson_per_ic
    low, high = ctx.found.poisson_cis["p"]
    level = null_level(ctx.found.null_calibration, HEADLINE_TEST, ctx.alpha)
    verdict = share_verdict(low, high, level=level)
    n_fixed = max(1, int(np.isfinite(per_ic["p_fixed"]).sum()))
    fixed_share = float((per_ic["p_fixed"] < ctx.alpha).sum()) / n_fixed
    f_low, f_high = ctx.found.poisson_cis["p_fixed"]
    words = {
        "above": "Poisson rejected (more rejections than null streams give)",
        "below": "fewer rejections than null streams give (conservative test)",
        "inconclusive": "consistent with Poisson at this sample size",
    }[verdict]
    others = "; ".join(
        f"{t} {percent_text(row.n_reject / row.n_tested)}"
        for t, row in totals.iterrows()
        if t != HEADLINE_TEST and row.n_tested > 0
    )
    by_r = rej[rej["test"] == HEADLINE_TEST].sort_values("radius")
    return [
        Effect(
            question="Poisson collision times?",
            system="",
            quantity=(
                f"share of runs rejected by the {HEADLINE_TEST} test at α = {ctx.alpha:g} "
                "(pooled over radii)"
            ),
            estimate=k / n,
            ci_low=low,
            ci_high=high,
            verdict=words,
            rule=SHARE_RULE.format(level=level) + (
                " (level: the share of the runs' Poisson control streams the same test "
                "rejects, null_calibration.csv)" if ctx.found.null_calibration is not None
                else " (level: α, the share under Poisson)"),
            method=(f"bootstrap clustered on {per_ic['ic'].nunique()} ICs ({n} runs at "
                    f"{per_ic['radius'].nunique()} radii)"),
            detail=(
                f"{percent_text(by_r['rate'].iloc[0])} at r = {by_r['radius'].iloc[0]:g}, "
                f"{percent_text(by_r['rate'].iloc[-1])} at r = {by_r['radius'].iloc[-1]:g}; at a "
                f"fixed {FIXED_EVENTS} collisions per run "
                f"{format_interval(100 * fixed_share, 100 * f_low, 100 * f_high)} % "
                f"({percent_text(by_r['rate_fixed'].iloc[0])} at r = "
                f"{by_r['radius'].iloc[0]:g}, {percent_text(by_r['rate_fixed'].iloc[-1])} at r = "
                f"{by_r['radius'].iloc[-1]:g}); other tests (pooled): {others}"
            ),
        )
    ]
