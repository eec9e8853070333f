r"""The report of a sweep: every number computed from the store, every figure re-drawn.

:func:`build_report` loads a result store (:func:`kicktimes.experiment.load_store`),
computes the tables (diagnostic summaries per radius x system, the comparison of the
kicked billiards with the two-particle one, collision counts and their regressions,
Poisson tests, renewal-model comparisons, rate heterogeneity), draws the paper's
figures with :mod:`kicktimes.plots`, and writes into ``out_dir``:

* ``report.html`` — self-contained (figures as base64 PNG, tables as HTML), with the
  experiment, its seed and rule, the kicktimes versions and the store path;
* ``<figure>.png`` and ``<figure>.pdf`` for every figure;
* ``<table>.csv`` for every table (also the per-IC tables the HTML only summarises).

Figures that need trajectories (Poincaré sections, recurrence plot) are recomputed
from the experiment's own IC 0 (``initial_conditions`` with its seed and IC method, at
its largest radius) at the experiment's radii nearest to 0.02 and 0.014; the Poisson
kick times of the "times" figure are the sweep's own (same ``kick_rng`` stream). So
every figure can be traced to the store and the experiment. See docs/report.md.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import math
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from scipy import stats as sps

from kicktimes import __version__, plots

__all__ = ["build_report", "REPORT_DOMAIN"]

#: first spawn-key word of the report's Monte Carlo streams ("rprt"), distinct from the
#: IC and kick streams of the sweep
REPORT_DOMAIN = 0x72707274
PAPER_DIAGNOSTICS = ("lyapunov", "recurrence_rate", "autocorrelation")
_POINCARE_RADII = (0.02, 0.014)
_TIMES_RADIUS = 0.008
_MIN_INTERVALS_PER_IC = 10
_FLOAT = "{:.6g}".format


# ----------------------------------------------------------------------- plumbing


class _Progress:
    """Stage reporting: a tqdm bar, a callable ``progress(stage, done, total)``, or nothing."""

    def __init__(self, progress, total):
        self.total, self.done, self.bar, self.call = total, 0, None, None
        if callable(progress):
            self.call = progress
        elif progress is None or isinstance(progress, bool):
            show = (
                progress
                if progress is not None
                else (sys.stderr.isatty() and not os.environ.get("CI"))
            )
            if show:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, desc="report", unit="stage")
        else:
            raise TypeError(
                f"progress must be None, a bool or a callable(stage, done, total), got "
                f"{type(progress).__name__}"
            )

    def step(self, stage):
        if self.bar is not None:
            self.bar.set_postfix_str(stage)
        if self.call is not None:
            self.call(stage, self.done, self.total)

    def advance(self):
        self.done += 1
        if self.bar is not None:
            self.bar.update(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


class _Mapper:
    """``map`` in this process, or on a process pool started at first use."""

    def __init__(self, workers):
        self.workers, self.pool = workers, None

    def map(self, fn, jobs):
        jobs = list(jobs)
        if self.workers == 1 or len(jobs) < 2:
            return [fn(job) for job in jobs]
        if self.pool is None:
            from concurrent.futures import ProcessPoolExecutor

            self.pool = ProcessPoolExecutor(max_workers=self.workers)
        return list(self.pool.map(fn, jobs))

    def close(self):
        if self.pool is not None:
            self.pool.shutdown()


def _check_int(name, value, low, allow_none=False):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < low:
        raise ValueError(f"{name} must be >= {low}, got {value!r}")
    return int(value)


def _rng(seed, *key):
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(REPORT_DOMAIN, *key)))


def _nearest(radii, target):
    radii = np.asarray(radii, dtype=float)
    return float(radii[np.argmin(np.abs(radii - target))])


def _pct(x):
    return "n/a" if not np.isfinite(x) else f"{100 * x:.1f}%"


def _fmt_p(p):
    if not np.isfinite(p):
        return "n/a"
    return "< 1e-300" if p == 0 else f"{p:.3g}"


def _spearman(x, y):
    """Spearman's rho and two-sided p-value (exact permutation for n <= 8), NaN when
    fewer than 3 finite points or a constant variable."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if x.size < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan, math.nan
    rho = float(sps.spearmanr(x, y).statistic)
    if x.size <= 8:
        # the t approximation is meaningless for a handful of radii (it gives p = 0 at
        # |rho| = 1); enumerate the permutations instead
        from itertools import permutations

        ry = sps.rankdata(y)
        null = [sps.spearmanr(x, ry[list(p)]).statistic for p in permutations(range(x.size))]
        return rho, float(np.mean(np.abs(null) >= abs(rho) - 1e-12))
    p = float(sps.spearmanr(x, y).pvalue)
    return rho, p if p > 0 else 2.0 / math.factorial(x.size)


def _fmt_rho(rho, p):
    return "n/a" if not np.isfinite(rho) else f"{rho:.2f}, p = {_fmt_p(p)}"


class _Section:
    """One part of the report: title, computed text, figures and tables."""

    def __init__(self, key, title):
        self.key, self.title = key, title
        self.paragraphs: list[str] = []
        self.figures: list[tuple[str, object, str]] = []  # (name, Figure, caption)
        self.tables: list[tuple[str, pd.DataFrame, str, bool]] = []  # (name, df, title, html)

    def text(self, paragraph):
        self.paragraphs.append(paragraph)

    def figure(self, name, fig, caption):
        self.figures.append((name, fig, caption))

    def table(self, name, df, title, *, show=True):
        self.tables.append((name, df, title, show))


# ----------------------------------------------------------------- trajectories


def _trajectory_sections(store, secs):
    """Poincaré sections and the recurrence plot from the experiment's own IC 0."""
    from kicktimes.billiard.initial import initial_conditions
    from kicktimes.billiard.two_particle import simulate_two_particle
    from kicktimes.diagnostics import recurrence_pairs

    exp = store.experiment
    ic = initial_conditions(1, exp.r_max, seed=exp.seed, method=exp.ic_method, rule=exp.rule)[0]
    radii = list(dict.fromkeys(_nearest(exp.radii, r) for r in _POINCARE_RADII))
    runs = {
        r: simulate_two_particle(
            ic,
            r,
            rule=exp.rule,
            sampling=exp.sampling,
            n_steps=exp.n_steps,
            tau=exp.tau,
            track=0,
            seed=exp.seed,
        )
        for r in radii
    }
    sec = _Section("poincare", "Poincaré sections of one disk")
    rows = []
    for r, run in runs.items():
        b = run.boundary
        st = b.loc[b["particle"] == 0, "sin_theta"].to_numpy()
        kept = float(np.mean(np.abs(np.diff(st)) < 1e-9)) if st.size > 1 else math.nan
        rows.append(
            {
                "radius": r,
                "ic": 0,
                "t_max": run.t_max,
                "n_pp": run.n_pp,
                "n_boundary_disk0": int(st.size),
                "share_sin_theta_kept": kept,
                "n_distinct_sin_theta": int(np.unique(np.round(st, 9)).size),
            }
        )
    table = pd.DataFrame(rows)
    sec.figure(
        "fig01_poincare_sections",
        plots.poincare_panels(list(runs.values())),
        f"Poincaré sections (s, sin θ) of disk 0 of IC 0 (drawn at r_max = {exp.r_max:g} with "
        f"seed {exp.seed}, {exp.ic_method} method), at r = "
        + " and ".join(f"{r:g}" for r in radii)
        + f"; {exp.n_steps} {exp.sampling}-sampled steps of τ = {exp.tau:g}.",
    )
    parts = [
        f"r = {row.radius:g}: {row.n_boundary_disk0} boundary collisions of disk 0 and "
        f"{row.n_pp} disk-disk collisions in t = {row.t_max:.4g}; "
        f"{_pct(row.share_sin_theta_kept)} of consecutive boundary collisions keep sin θ "
        f"(the horizontal segments of regular motion), {row.n_distinct_sin_theta} distinct "
        f"values of sin θ"
        for row in table.itertuples()
    ]
    sec.text("; ".join(parts) + ".")
    if len(radii) < len(_POINCARE_RADII):
        sec.text(
            "The experiment has no separate radius near each of the paper's 0.02 and 0.014, "
            f"so only r = {radii[0]:g} is shown."
        )
    sec.table("poincare_runs", table, "Runs behind the Poincaré sections")
    secs.append(sec)

    r_rr = _nearest(exp.radii, 0.02)
    run = runs[r_rr]
    i, j = recurrence_pairs(run.samples, exp.eps)
    n = run.samples.shape[0]
    rr = i.size / float(n) ** 2
    stored = store.results[
        (store.results["radius"] == r_rr)
        & (store.results["ic"] == 0)
        & (store.results["system"] == "two_particle")
        & (store.results["diagnostic"] == "recurrence_rate")
    ]["value"]
    sec2 = _Section("recurrence_plot", "Recurrence plot")
    sec2.figure(
        "fig02_recurrence_plot",
        plots.recurrence_plot(
            (i, j),
            n_points=n,
            tau=exp.tau if exp.sampling == "uniform" else None,
            title=f"r = {r_rr:g}, ε = {exp.eps:g}: N = {n}, RR = {rr:.4g}",
        ),
        f"Recurrence plot of disk 0's sampled centre, IC 0, r = {r_rr:g}, ε = {exp.eps:g} "
        "(L2 norm), drawn from the list of recurrent pairs (no N x N matrix).",
    )
    text = (
        f"N = {n} samples give {i.size} recurrent pairs ({i.size - n} off the main diagonal): "
        f"RR = {rr:.4g}."
    )
    if len(stored) == 1:
        same = np.isclose(float(stored.iloc[0]), rr, rtol=1e-12, atol=0)
        text += (
            f" The store's recurrence rate of this IC and radius is {float(stored.iloc[0]):.4g}"
            + (
                " (identical: the plot is the stored trajectory)."
                if same
                else " (differs: the store was computed with other settings)."
            )
        )
    sec2.text(text)
    secs.append(sec2)


# ---------------------------------------------------------------- kick times


def _times_section(store, secs):
    from kicktimes.experiment import kick_rng
    from kicktimes.schedules import Poisson

    exp = store.experiment
    coll = store.collisions
    r = _nearest(coll["radius"].unique(), _TIMES_RADIUS)
    part = coll[coll["radius"] == r].sort_values("ic")
    rows, sample = [], None
    for row in part.itertuples():
        pp = np.asarray(row.pp_times, dtype=float)
        rate = row.n_pp / row.t_window
        kicks = (
            Poisson(rate).sample(exp.horizon, kick_rng(exp.seed, int(row.ic), r, "poisson"))
            if rate > 0
            else np.empty(0)
        )
        entry = {
            "radius": r,
            "ic": int(row.ic),
            "n_pp": int(row.n_pp),
            "rate": rate,
            "n_kicks": int(kicks.size),
            "slope": math.nan,
            "intercept": math.nan,
            "r_squared": math.nan,
            "n_paired": min(pp.size, kicks.size),
        }
        if entry["n_paired"] >= 3:
            fit = plots.kth_time_fit(pp, kicks)
            entry.update(slope=fit.slope, intercept=fit.intercept, r_squared=fit.r_squared)
            if sample is None:
                sample = (int(row.ic), pp, kicks, fit)
        rows.append(entry)
    table = pd.DataFrame(rows)
    sec = _Section("times", "Poisson kick times against actual collision times")
    if sample is None:
        sec.text(f"No IC at r = {r:g} has 3 or more disk-disk collisions and kicks: no figure.")
    else:
        ic, pp, kicks, fit = sample
        sec.figure(
            "fig03_kick_times_vs_collision_times",
            plots.kick_times_vs_collision_times(pp, kicks, radius=r),
            f"k-th Poisson kick time against k-th disk-disk collision time, IC {ic}, r = {r:g} "
            "(the sweep's own Poisson kicks: rate n_pp / t_window, kick_rng stream).",
        )
        ok = table["r_squared"].notna()
        sec.text(
            f"IC {ic}"
            + (" (IC 0 has fewer than 3 collisions)" if ic != 0 else "")
            + f": slope {fit.slope:.3f}, intercept {fit.intercept:.3g}, R² = "
            f"{fit.r_squared:.4f} over {fit.n} pairs. Over the {int(ok.sum())} ICs at r = {r:g} "
            f"with at least 3 pairs: median R² = {table.loc[ok, 'r_squared'].median():.4f} "
            f"(10% quantile {table.loc[ok, 'r_squared'].quantile(0.1):.4f}), median slope "
            f"{table.loc[ok, 'slope'].median():.3f}. A high R² only says that both sequences "
            "grow roughly linearly in k (it holds for any two processes with similar rates); "
            "the Poisson tests below test the collision times themselves."
        )
    sec.table("kick_times_fit", table, "Least-squares line per IC", show=False)
    secs.append(sec)


# ------------------------------------------------------------------- counts


def _counts_section(store, secs):
    from kicktimes import stats

    exp = store.experiment
    coll = store.collisions
    table = plots.counts_by_radius(coll)
    grouped = coll.groupby("radius")
    table["pooled_rate"] = grouped["n_pp"].sum() / grouped["t_window"].sum()
    table["kinetic_rate"] = stats.kinetic_rate(table.index.to_numpy(), exp.rule)
    table["rate_over_kinetic"] = table["pooled_rate"] / table["kinetic_rate"]
    table["dispersion_index"] = grouped["n_pp"].var(ddof=1) / grouped["n_pp"].mean()
    sec = _Section("counts", "Number of disk-disk collisions against radius")
    sec.table("counts_by_radius", table.reset_index(), "Counts per radius")
    if coll["radius"].nunique() < 2:
        sec.text("One radius only: no regression on radius.")
        secs.append(sec)
        return None
    frame = coll[["radius", "n_pp", "t_window"]].rename(columns={"n_pp": "count"})
    with warnings.catch_warnings():
        # two radii leave the line no residual degree of freedom: its standard errors
        # are undefined (NaN in the table), which statsmodels warns about
        warnings.simplefilter("ignore", RuntimeWarning)
        reg = stats.regress_counts(frame, rule=exp.rule)
        coef = reg.coefficients()
        od = reg.overdispersion()
    sec.figure(
        "fig04_counts_vs_radius",
        plots.counts_vs_radius(coll, reg, rule=exp.rule),
        "Mean number of disk-disk collisions per run against radius (± s.e.m. over ICs) with "
        "the paper's least-squares line, Poisson and negative-binomial regressions and the "
        f"kinetic-theory count Γ(r)·T ({exp.rule} rule), curves at the mean window T(r).",
    )
    b1 = coef.loc[("negbin", reg.covariate)]
    sec.text(
        f"Least-squares line of the pooled rate on r: slope {reg.ols.params[1]:.4g} per unit r "
        f"per time unit, R² = {reg.ols.rsquared:.4f} over {len(table)} radii. Counts are "
        + ("over-dispersed" if od["lr_pvalue"] < 0.05 else "not significantly over-dispersed")
        + f" across ICs: Poisson Pearson dispersion {od['pearson_dispersion']:.3g}, "
        f"negative-binomial α = {od['alpha']:.3g} (LR test of α = 0: p = "
        f"{_fmt_p(od['lr_pvalue'])}); AIC Poisson {reg.poisson.aic:.6g} vs negative binomial "
        f"{reg.negbin.aic:.6g}. The negative-binomial exponent of r is {b1['estimate']:.3f} "
        f"(95% CI {b1['ci_low']:.3f} to {b1['ci_high']:.3f}; kinetic theory: about 1). The "
        f"pooled rate is {table['rate_over_kinetic'].min():.3g} to "
        f"{table['rate_over_kinetic'].max():.3g} times the kinetic-theory rate "
        f"(the {exp.ic_method} ICs are "
        + (
            "drawn from the invariant measure, so the ratio should be 1)."
            if exp.ic_method == "uniform"
            else "not from the invariant measure, so the ratio need not be 1)."
        )
    )
    sec.table("count_regression", coef.reset_index(), "Count regressions (coefficients)")
    sec.table(
        "count_overdispersion",
        od.to_frame("value").reset_index(names="quantity"),
        "Over-dispersion",
    )
    secs.append(sec)
    return reg


# -------------------------------------------------------------- diagnostics


def _comparison_table(summary):
    """Kicked systems against the two-particle one, per radius and diagnostic."""
    two = summary[summary["system"] == "two_particle"].set_index(["radius", "diagnostic"])
    rows = []
    for row in summary[summary["system"] != "two_particle"].itertuples():
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
                "difference": diff,
                "relative_difference": diff / abs(ref["mean"]) if ref["mean"] != 0 else math.nan,
                "z": diff / se if se > 0 else math.nan,
                "paper_bars_overlap": abs(diff) <= row.paper_err + ref["paper_err"],
                "sem_bars_overlap": abs(diff) <= row.sem + ref["sem"],
            }
        )
    return pd.DataFrame(rows)


def _diagnostic_sections(store, secs):
    exp = store.experiment
    summary = plots.diagnostic_summary(store.results)
    comparison = _comparison_table(summary)
    sec = _Section("diagnostic_tables", "Diagnostic summaries (all diagnostics)")
    sec.text(
        "Per radius, system and diagnostic: number of ICs n, number of finite values n_valid "
        "(undefined values, e.g. the autocorrelation of a constant angle series, are NaN in "
        "the store and left out), mean, standard deviation, standard error std/√n_valid and "
        "the paper's error bar std/10."
    )
    sec.table("diagnostics_summary", summary, "Summary", show=False)
    sec.table("diagnostics_vs_two_particle", comparison, "Kicked vs two-particle", show=False)
    secs.append(sec)
    names = [d for d in PAPER_DIAGNOSTICS if d in set(summary["diagnostic"])]
    for diagnostic in names:
        title = plots.DIAGNOSTIC_LABELS[diagnostic][0]
        if diagnostic == "lyapunov" and exp.lyapunov_variant == "paper":
            title += " (paper variant: max(λˣ, λʸ))"
        s = _Section(diagnostic, f"{title} against radius")
        s.figure(
            f"fig{5 + PAPER_DIAGNOSTICS.index(diagnostic):02d}_{diagnostic}_vs_radius",
            plots.diagnostic_vs_radius(summary, diagnostic, title=title),
            f"{title} of disk 0, mean over ICs per radius, for the three systems; thick pale "
            "bars: the paper's ± std/10; thin capped bars: ± standard error std/√n_valid.",
        )
        s.text(_diagnostic_text(summary, comparison, diagnostic))
        part = summary[summary["diagnostic"] == diagnostic]
        wide = part.pivot(
            index="radius", columns="system", values=["mean", "sem", "paper_err", "n_valid"]
        )
        wide.columns = [f"{stat}_{system}" for stat, system in wide.columns]
        s.table(f"{diagnostic}_by_radius", wide.reset_index(), f"{title}: mean per radius")
        secs.append(s)


def _diagnostic_text(summary, comparison, diagnostic):
    comp = comparison[comparison["diagnostic"] == diagnostic]
    if comp.empty:
        return "Only one system in the store: no comparison."
    out = []
    for system in ("poisson", "actual"):
        c = comp[comp["system"] == system].sort_values("radius")
        if c.empty:
            continue
        rel = c["relative_difference"].abs()
        n = len(c)
        rho, p = _spearman(c["radius"], rel)
        label = plots.SYSTEM_LABELS[system]
        out.append(
            f"{label} vs two-particle: mean |relative difference| {_pct(rel.mean())} over "
            f"{n} radii (largest {_pct(rel.max())} at r = {c.loc[rel.idxmax(), 'radius']:g}"
            f"); the difference is within two standard errors (|z| < 2) at "
            f"{int((c['z'].abs() < 2).sum())}/{n} radii; the paper's ± std/10 bars overlap at "
            f"{int(c['paper_bars_overlap'].sum())}/{n} radii, the ± s.e.m. bars at "
            f"{int(c['sem_bars_overlap'].sum())}/{n}; Spearman correlation of |relative "
            f"difference| with r: {_fmt_rho(rho, p)}"
        )
    both = comp.pivot_table(index="radius", columns="system", values="relative_difference")
    if {"poisson", "actual"} <= set(both.columns):
        closer = (both["poisson"].abs() < both["actual"].abs()).sum()
        out.append(
            f"the Poisson system is closer to the two-particle mean than the actual-time "
            f"system at {int(closer)}/{len(both)} radii"
        )
    return "; ".join(out) + "."


# ----------------------------------------------------------- Poisson tests


def _subsample(part, limit):
    ics = np.sort(part["ic"].unique())
    return part[part["ic"].isin(ics[:limit])] if limit is not None and ics.size > limit else part


def _poisson_job(job):
    """Poisson tests and rate homogeneity of one radius (runs in a worker process)."""
    from kicktimes import stats

    r, seqs, windows, alpha, n_mc, seed_key, rule = job
    ens = stats.test_poisson_ensemble(seqs, windows, alpha=alpha, n_mc=n_mc, rng=_rng(*seed_key))
    rows = []
    for test in stats.TESTS:
        p = ens.per_sequence[f"p_{test}"].to_numpy()
        ok = np.isfinite(p)
        comb = ens.combined.loc[test]
        rows.append(
            {
                "radius": r,
                "test": test,
                "n_tested": int(ok.sum()),
                "n_reject": int((p[ok] < alpha).sum()),
                "n_reject_fdr": int(comb["n_reject_fdr"]),
                "combined_pvalue": float(comb["pvalue"]),
            }
        )
    hom = ens.rate_homogeneity
    counts = np.array([t.size for t in seqs], dtype=float)
    hom_row = {
        "radius": r,
        "n_ics": len(seqs),
        "pooled_rate": counts.sum() / windows.sum(),
        "median_rate": float(np.median(counts / windows)),
        "kinetic_rate": float(stats.kinetic_rate(r, rule)),
        "dispersion_index": counts.var(ddof=1) / counts.mean() if counts.mean() > 0 else math.nan,
        "pearson_statistic": hom.loc["pearson", "statistic"],
        "df": hom.loc["pearson", "df"],
        "pvalue": hom.loc["pearson", "pvalue"],
        "pvalue_mc": hom.loc["pearson", "pvalue_mc"],
        "lr_pvalue": hom.loc["likelihood_ratio", "pvalue"],
        "n_flagged_fdr": int(ens.reject["rate"].sum()),
    }
    return rows, hom_row


def _poisson_sections(store, secs, *, alpha, n_mc, max_ics_tests, notes, pmap):
    exp = store.experiment
    coll = store.collisions
    jobs = []
    for ri, (r, part) in enumerate(coll.groupby("radius")):
        part = _subsample(part.sort_values("ic"), max_ics_tests)
        seqs = [np.asarray(t, dtype=float) for t in part["pp_times"]]
        # one Monte Carlo stream per radius: identical results for any worker count
        key = (exp.seed, 1, ri)
        jobs.append((r, seqs, part["t_window"].to_numpy(float), alpha, n_mc, key, exp.rule))
    rej_rows, hom_rows = [], []
    for rows, hom_row in pmap(_poisson_job, jobs):
        rej_rows += rows
        hom_rows.append(hom_row)
    rejections = plots.rejection_table(pd.DataFrame(rej_rows))
    homogeneity = pd.DataFrame(hom_rows)
    if max_ics_tests is not None and coll.groupby("radius")["ic"].nunique().max() > max_ics_tests:
        notes.append(
            f"Poisson tests and rate homogeneity: the first {max_ics_tests} ICs (by index) "
            "per radius."
        )
    sec = _Section("poisson_tests", "Poisson tests of the collision times, per IC")
    sec.figure(
        "fig08_poisson_rejection_rates",
        plots.poisson_rejection_rates(rejections, alpha=alpha),
        f"Share of ICs whose disk-disk collision times reject a homogeneous Poisson process at "
        f"α = {alpha:g}, per test and radius, with 95% Clopper-Pearson intervals; each test "
        f"conditions on the IC's own number of collisions (Monte Carlo nulls, n_mc = {n_mc}).",
    )
    lines = []
    for test, t in rejections.groupby("test", sort=False):
        t = t.sort_values("radius")
        rho, p = _spearman(t["radius"], t["rate"])
        lines.append(
            f"{test}: {_pct(t['rate'].iloc[0])} at r = {t['radius'].iloc[0]:g}, "
            f"{_pct(t['rate'].iloc[-1])} at r = {t['radius'].iloc[-1]:g} "
            f"(Spearman ρ with r: {_fmt_rho(rho, p)})"
        )
    above = rejections[rejections["ci_low"] > alpha]
    tested = rejections[rejections["n_tested"] > 0]
    sec.text(
        f"Under the null each test rejects {_pct(alpha)} of ICs. Rejection rates — "
        + "; ".join(lines)
        + f". The 95% interval lies above α for {len(above)} of {len(tested)} "
        f"(test, radius) cells with tested ICs; the Fisher-combined p-value is below {alpha:g} for "
        f"{int((rejections['combined_pvalue'] < alpha).sum())} of them. Tests with too few "
        "events in an IC are not run on it (n_tested counts the ICs tested)."
    )
    sec.table("poisson_tests", rejections, "Rejections per radius and test")
    secs.append(sec)

    sec2 = _Section("heterogeneity", "Rate heterogeneity across ICs")
    sec2.figure(
        "fig10_rate_heterogeneity",
        plots.rate_heterogeneity(store.collisions, homogeneity=homogeneity, rule=exp.rule),
        "(a) Disk-disk collision rate n_pp / t_window of every IC, the pooled and median rates "
        f"and the kinetic rate ({exp.rule}); (b) index of dispersion of the counts across ICs, "
        "annotated with the p-value of the Pearson test of a common rate (given the total).",
    )
    het = homogeneity
    sec2.text(
        f"A common rate across ICs is rejected at α = {alpha:g} at "
        f"{int((het['pvalue'] < alpha).sum())}/{len(het)} radii (Pearson χ²; exact Monte Carlo "
        f"p-value at resolution 1/{n_mc + 1}); the index of dispersion of the counts ranges from "
        f"{het['dispersion_index'].min():.3g} to {het['dispersion_index'].max():.3g} (1 for a "
        f"common Poisson rate); {int(het['n_flagged_fdr'].sum())} (IC, radius) pairs have a rate "
        f"incompatible with the pooled one after FDR control. The median per-IC rate is "
        f"{(het['median_rate'] / het['kinetic_rate']).min():.3g} to "
        f"{(het['median_rate'] / het['kinetic_rate']).max():.3g} times the kinetic rate."
    )
    sec2.table("rate_homogeneity", homogeneity, "Rate homogeneity per radius")
    return sec2


# ------------------------------------------------------------ renewal models


def _compare_job(job):
    """AIC comparison of the renewal models on one sample (runs in a worker process)."""
    from kicktimes import stats

    complete, censored = job
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # optimiser chatter; failed fits are in 'note'
        return stats.compare_models(complete, censored=censored)


def _renewal_section(store, *, max_ics_model_fits, max_pooled_intervals, notes, pmap):
    from kicktimes import stats

    coll = store.collisions
    per_rows, pooled_rows, best_rows = [], [], []
    jobs, meta = [], []
    for r, part in coll.groupby("radius"):
        part = part.sort_values("ic")
        # pooled: whole ICs in index order until the interval budget is used
        sizes = np.maximum(part["n_pp"].to_numpy() - 1, 0)
        used = part[np.cumsum(sizes) - sizes < max_pooled_intervals]
        iv = stats.intervals_from_times(
            [np.asarray(t, float) for t in used["pp_times"]], used["t_window"].to_numpy(float)
        )
        if iv.complete.size >= _MIN_INTERVALS_PER_IC:
            jobs.append((iv.complete, iv.censored))
            meta.append(("pooled", {"radius": r, "n_ics_used": len(used)}))
        if len(used) < len(part):
            notes.append(
                f"Pooled renewal fits at r = {r:g}: the first {len(used)} of {len(part)} "
                f"ICs (≈{max_pooled_intervals} intervals)."
            )
        for row in _subsample(part, max_ics_model_fits).itertuples():
            iv = stats.intervals_from_times(np.asarray(row.pp_times, float), row.t_window)
            base = {"radius": r, "ic": int(row.ic), "n_intervals": int(iv.complete.size)}
            if iv.complete.size < _MIN_INTERVALS_PER_IC:
                note = f"fewer than {_MIN_INTERVALS_PER_IC} intervals"
                best_rows.append({**base, "best_model": None, "note": note})
            else:
                jobs.append((iv.complete, iv.censored))
                meta.append(("ic", base))
    pooled_cols = ("loglik", "k", "aic", "delta_aic", "weight", "n", "n_censored", "note")
    for (kind, base), table in zip(meta, pmap(_compare_job, jobs), strict=True):
        if kind == "pooled":
            for model, t in table.iterrows():
                pooled_rows.append({**base, "model": model, **{c: t[c] for c in pooled_cols}})
            continue
        best_rows.append({**base, "best_model": table.index[0], "note": ""})
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
    n_per_radius = coll.groupby("radius")["ic"].nunique()
    if (n_per_radius > max_ics_model_fits).any():
        notes.append(
            f"Per-IC renewal-model comparison: the first {max_ics_model_fits} ICs (by "
            "index) per radius (each comparison fits 6 censored models)."
        )
    best = pd.DataFrame(best_rows).sort_values(["radius", "ic"], ignore_index=True)
    per_ic = pd.DataFrame(per_rows)
    pooled = pd.DataFrame(pooled_rows)
    sec = _Section("renewal", "Renewal-model comparison of the collision intervals")
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
    share_long["ci_low"], share_long["ci_high"] = plots.binomial_ci(
        share_long["n_best"], share_long["n_ics_fitted"]
    )
    if fitted.empty and pooled.empty:
        sec.text(f"No sample has {_MIN_INTERVALS_PER_IC} or more intervals: no renewal fit.")
    else:
        sec.figure(
            "fig09_renewal_model_comparison",
            plots.model_comparison(fitted, pooled, models=list(stats.FULL_SAMPLE_MODELS)),
            "(a) Per IC: share of ICs for which each renewal model has the lowest AIC; (b) "
            "intervals pooled over ICs: ΔAIC of each model (0 = best; 2 and 10 guides).",
        )
    if fitted.empty:
        sec.text(
            f"No IC among those fitted per radius has {_MIN_INTERVALS_PER_IC} or more "
            "intervals: no per-IC comparison."
        )
    else:
        exp_share = fitted.groupby("radius")["best_model"].apply(
            lambda b: (b == "exponential").mean()
        )
        sec.text(
            f"Per IC, the exponential (Poisson) model is AIC-best for {_pct(exp_share.mean())} "
            f"of the fitted ICs on average over radii (from {_pct(exp_share.min())} to "
            f"{_pct(exp_share.max())}); {len(best) - len(fitted)} ICs had fewer than "
            f"{_MIN_INTERVALS_PER_IC} intervals and were not fitted."
        )
    if not pooled.empty:
        best_pooled = pooled.loc[pooled.groupby("radius")["aic"].idxmin()]
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
    return sec


# --------------------------------------------------------------------- output


_CSS = """
body{font-family:sans-serif;max-width:70em;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ccc;margin-top:2em}
table.dataframe{border-collapse:collapse;font-size:.8em;margin:.5em 0 1em}
table.dataframe td,table.dataframe th{border:1px solid #ccc;padding:2px 6px;text-align:right}
figure{margin:1em 0}figure img{max-width:100%}figcaption{font-size:.9em;color:#444}
.meta td{padding:1px 8px;vertical-align:top}.note{background:#fff6dd;padding:.5em}
"""


def _table_html(df):
    return df.to_html(index=False, float_format=_FLOAT, na_rep="NaN", border=0)


def _write_outputs(sections, out, dpi, prefix=""):
    """Save figures (PNG + PDF) and tables (CSV); return the HTML of the sections."""
    body = []
    for sec in sections:
        body.append(f'<h3 id="{prefix}{sec.key}">{html.escape(sec.title)}</h3>')
        for name, fig, caption in sec.figures:
            name = prefix + name
            fig.savefig(out / f"{name}.png", dpi=dpi)
            fig.savefig(out / f"{name}.pdf")
            data = base64.b64encode((out / f"{name}.png").read_bytes()).decode("ascii")
            body.append(
                f'<figure><img alt="{html.escape(name)}" src="data:image/png;base64,{data}">'
                f'<figcaption>{html.escape(caption)} Files: <a href="{name}.png">PNG</a>, '
                f'<a href="{name}.pdf">PDF</a>.</figcaption></figure>'
            )
        for paragraph in sec.paragraphs:
            body.append(f"<p>{html.escape(paragraph)}</p>")
        for name, df, title, show in sec.tables:
            name = prefix + name
            df.to_csv(out / f"{name}.csv", index=False)
            link = f'<a href="{name}.csv">{name}.csv</a>'
            if show:
                body.append(f"<h4>{html.escape(title)} ({link})</h4>{_table_html(df)}")
            else:
                body.append(f"<p>{html.escape(title)}: {link} ({len(df)} rows).</p>")
        sec.figures.clear()  # drop the Figure objects: nothing stays alive
    return "\n".join(body)


def _store_header(store, notes):
    """Metadata of one store and its experiment: (HTML, parameter table)."""
    exp = store.experiment
    man = store.manifest
    meta = [
        ("experiment", f"{exp.name} (hash {man.get('experiment_hash', exp.hash())})"),
        ("description", exp.description or "—"),
        ("seed", str(exp.seed)),
        ("rule", exp.rule),
        ("IC method", f"{exp.ic_method}, {exp.n_ics} ICs drawn at r_max = {exp.r_max:g}"),
        ("steps", f"{exp.n_steps} steps of τ = {exp.tau:g} ({exp.sampling} sampling)"),
        ("kicktimes version (store)", str(man.get("kicktimes_version", "unknown"))),
        ("kicktimes version (report)", __version__),
        ("store", os.fspath(Path(store.path).resolve())),
        ("store created / updated", f"{man.get('created', '?')} / {man.get('updated', '?')}"),
        ("tasks", f"{len(exp.tasks()) - len(store.missing_tasks)}/{len(exp.tasks())} finished"),
    ]
    rows = "".join(
        f"<tr><td><b>{html.escape(k)}</b></td><td>{html.escape(v)}</td></tr>" for k, v in meta
    )
    params = pd.DataFrame(
        [
            (k, ", ".join(map(str, v)) if isinstance(v, list) else str(v))
            for k, v in exp.to_dict().items()
        ],
        columns=["parameter", "value"],
    )
    parts = [f'<table class="meta">{rows}</table>']
    if store.missing_tasks:
        parts.append(
            f'<p class="note">The store is unfinished: {len(store.missing_tasks)} tasks '
            "are missing; every number below uses the finished tasks only.</p>"
        )
    if notes:
        items = "".join(f"<li>{html.escape(n)}</li>" for n in notes)
        parts.append(f'<div class="note"><b>Subsampling (deterministic):</b><ul>{items}</ul></div>')
    parts.append("<h3>Parameters</h3>" + _table_html(params))
    return "\n".join(parts), params


def _families_section(stores):
    """The paper's layout: one panel per experiment (family) for each diagnostic."""
    sec = _Section("families", "Diagnostics against radius, all experiments")
    summaries = [plots.diagnostic_summary(st.results) for st in stores]
    for diagnostic in PAPER_DIAGNOSTICS:
        having = [
            (st, sm)
            for st, sm in zip(stores, summaries, strict=True)
            if diagnostic in set(sm["diagnostic"])
        ]
        if len(having) < 2:
            continue
        fig = Figure(figsize=(6.4, 4.0 * len(having)), layout="constrained")
        axes = np.atleast_1d(fig.subplots(len(having), 1))
        for ax, (st, sm) in zip(axes, having, strict=True):
            exp = st.experiment
            plots.diagnostic_vs_radius(
                sm,
                diagnostic,
                ax=ax,
                title=f"{exp.name}: {exp.n_ics} ICs, {exp.n_steps} steps of τ = {exp.tau:g}",
            )
        name = plots.DIAGNOSTIC_LABELS[diagnostic][0]
        sec.figure(
            f"families_{diagnostic}_vs_radius",
            fig,
            f"{name} against radius, one panel per experiment (the paper's top and bottom "
            "plots); thick pale bars ± std/10 (the paper's), thin capped bars ± std/√n_valid.",
        )
    return sec if sec.figures else None


def _analyse(
    store,
    *,
    alpha,
    n_mc,
    max_ics_tests,
    max_ics_model_fits,
    max_pooled_intervals,
    pmap,
    bar,
    timings,
):
    """Every section of one store; stage timings go to ``timings[(name, stage)]``."""
    secs, notes = [], []
    steps = [
        ("trajectories", lambda: _trajectory_sections(store, secs)),
        ("kick times", lambda: _times_section(store, secs)),
        ("counts", lambda: _counts_section(store, secs)),
        ("diagnostics", lambda: _diagnostic_sections(store, secs)),
        (
            "Poisson tests",
            lambda: _poisson_sections(
                store,
                secs,
                alpha=alpha,
                n_mc=n_mc,
                max_ics_tests=max_ics_tests,
                notes=notes,
                pmap=pmap,
            ),
        ),
        (
            "renewal models",
            lambda: _renewal_section(
                store,
                max_ics_model_fits=max_ics_model_fits,
                max_pooled_intervals=max_pooled_intervals,
                notes=notes,
                pmap=pmap,
            ),
        ),
    ]
    heterogeneity = None
    for stage, run in steps:
        bar.step(f"{store.experiment.name}: {stage}")
        t0 = time.perf_counter()
        out = run()
        if stage == "Poisson tests":
            heterogeneity = out  # shown after the renewal models
        elif stage == "renewal models":
            secs.extend([out, heterogeneity])
        timings.append((store.experiment.name, stage, time.perf_counter() - t0))
        bar.advance()
    return secs, notes


_STAGES_PER_STORE = 6


def build_report(
    store_path,
    out_dir,
    *,
    progress=None,
    alpha=0.05,
    n_mc=199,
    max_ics_tests=None,
    max_ics_model_fits=12,
    max_pooled_intervals=200_000,
    dpi=150,
    workers=None,
) -> Path:
    r"""Build the report of one or several sweeps: tables, figures, a self-contained page.

    Parameters
    ----------
    store_path : path-like or sequence of path-like
        A store written by :func:`kicktimes.experiment.run_experiment`, or several (e.g.
        the paper's two families): each gets its own part of the report, with file names
        prefixed by its experiment's name, and the diagnostics are also drawn one panel
        per experiment in one figure (the paper's top/bottom layout).
    out_dir : path-like
        Output folder (created if needed; existing files of the same names are replaced).
    progress : None, bool or callable, optional
        A tqdm bar over the stages (default: on a terminal, not under ``CI``), or a
        callable ``progress(stage, done, total)``.
    alpha : float, optional
        Level of the Poisson tests, rate-homogeneity tests and FDR control.
    n_mc : int, optional
        Monte Carlo samples of the conditional nulls of the Poisson tests (p-value
        resolution ``1/(n_mc + 1)``).
    max_ics_tests : int, optional
        Use only the first ``max_ics_tests`` ICs (by index) per radius in the Poisson
        tests (default: all).
    max_ics_model_fits : int, optional
        ICs (first by index) per radius whose intervals get a per-IC renewal-model
        comparison (6 censored fits each, ~0.4 s per IC).
    max_pooled_intervals : int, optional
        Interval budget of the pooled fits per radius (whole ICs in index order).
    dpi : int, optional
        Resolution of the PNG files.
    workers : int, optional
        Processes for the Poisson tests (one job per radius) and the renewal fits (one
        job per sample); default ``os.cpu_count()``; ``1`` computes in this process.
        The results do not depend on it.

    Returns
    -------
    pathlib.Path
        ``out_dir / "report.html"``.

    Notes
    -----
    Deterministic: the Monte Carlo streams derive from each experiment's seed
    (``SeedSequence(seed, spawn_key=(REPORT_DOMAIN, ...))``), the trajectories from its
    IC 0 and the Poisson kicks from the sweep's own ``kick_rng``. Every subsampling is
    listed in the report. Stage timings are written to ``report_timings.csv`` and the
    sweep's (summed over tasks) to ``sweep_timings.csv``.

    Examples
    --------
    >>> import tempfile
    >>> from kicktimes.experiment import Experiment, run_experiment
    >>> from kicktimes.report import build_report
    >>> exp = Experiment(name="demo", radii=[0.01, 0.02], n_ics=3, n_steps=300, tau=0.3,
    ...                  diagnostics=["recurrence_rate", "autocorrelation"])
    >>> store = tempfile.mkdtemp()
    >>> _ = run_experiment(exp, store, workers=1, progress=False)
    >>> build_report(store, tempfile.mkdtemp(), progress=False, workers=1).name
    'report.html'
    """
    from kicktimes.experiment import load_store

    if isinstance(store_path, str | os.PathLike):
        paths = [store_path]
    elif isinstance(store_path, list | tuple) and store_path:
        paths = list(store_path)
        for k, p in enumerate(paths):
            if not isinstance(p, str | os.PathLike):
                raise TypeError(f"store_path[{k}] must be a path, got {type(p).__name__}")
    else:
        raise TypeError(
            "store_path must be a path or a non-empty list of paths, got "
            f"{type(store_path).__name__}"
        )
    if not isinstance(out_dir, str | os.PathLike):
        raise TypeError(f"out_dir must be a path, got {type(out_dir).__name__}")
    alpha = plots._check_alpha(alpha)
    n_mc = _check_int("n_mc", n_mc, 19)
    max_ics_tests = _check_int("max_ics_tests", max_ics_tests, 2, allow_none=True)
    max_ics_model_fits = _check_int("max_ics_model_fits", max_ics_model_fits, 1)
    max_pooled_intervals = _check_int("max_pooled_intervals", max_pooled_intervals, 100)
    dpi = _check_int("dpi", dpi, 30)
    workers = _check_int("workers", (os.cpu_count() or 1) if workers is None else workers, 1)
    bar = _Progress(progress, 2 + _STAGES_PER_STORE * len(paths))
    pool = _Mapper(workers)
    try:
        bar.step("load store")
        t0 = time.perf_counter()
        stores = [load_store(p) for p in paths]
        for p, st in zip(paths, stores, strict=True):
            if st.results.empty or st.collisions.empty:
                raise ValueError(f"store_path: {os.fspath(p)!r} holds no finished task yet")
        names = [st.experiment.name for st in stores]
        if len(set(names)) != len(names):
            raise ValueError(
                f"store_path: the stores' experiments must have distinct names, got {names}"
            )
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        timings = [("", "load store", time.perf_counter() - t0)]
        bar.advance()
        options = dict(
            alpha=alpha,
            n_mc=n_mc,
            max_ics_tests=max_ics_tests,
            max_ics_model_fits=max_ics_model_fits,
            max_pooled_intervals=max_pooled_intervals,
        )
        analysed = [
            _analyse(st, pmap=pool.map, bar=bar, timings=timings, **options) for st in stores
        ]
        bar.step("write files")
        t0 = time.perf_counter()
        multi = len(stores) > 1
        parts, toc, sweep_rows = [], [], []
        if multi:
            families = _families_section(stores)
            if families is not None:
                parts.append(_write_outputs([families], out, dpi))
                toc.append(f'<li><a href="#{families.key}">{html.escape(families.title)}</a></li>')
        for st, (secs, notes) in zip(stores, analysed, strict=True):
            name = st.experiment.name
            prefix = f"{name}_" if multi else ""
            header, params = _store_header(st, notes)
            params.to_csv(out / f"{prefix}experiment.csv", index=False)
            (out / f"{prefix}experiment.toml").write_text(st.experiment.to_toml(), encoding="utf-8")
            sweep = st.timings.sum(numeric_only=True)
            sweep_rows += [(name, stage, float(v)) for stage, v in sweep.items()]
            body = _write_outputs(secs, out, dpi, prefix)
            parts.append(
                f'<h2 id="{prefix}experiment">Experiment {html.escape(name)}</h2>{header}{body}'
            )
            items = "".join(
                f'<li><a href="#{prefix}{s.key}">{html.escape(s.title)}</a></li>' for s in secs
            )
            toc.append(
                f'<li><a href="#{prefix}experiment">Experiment {html.escape(name)}</a>'
                f"<ul>{items}</ul></li>"
            )
        sweep_t = pd.DataFrame(sweep_rows, columns=["experiment", "stage", "seconds"])
        sweep_t.to_csv(out / "sweep_timings.csv", index=False)
        timings.append(("", "write files", time.perf_counter() - t0))
        bar.advance()
        report_t = pd.DataFrame(timings, columns=["experiment", "stage", "seconds"])
        report_t.to_csv(out / "report_timings.csv", index=False)
        title = " + ".join(names)
        page = (
            '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f"<title>kicktimes report: {html.escape(title)}</title><style>{_CSS}</style>"
            f"</head><body><h1>kicktimes report: {html.escape(title)}</h1>"
            f"<p>Built {_dt.datetime.now(_dt.timezone.utc).isoformat(timespec='seconds')} "
            f"with kicktimes {html.escape(__version__)} from "
            + ", ".join(html.escape(os.fspath(Path(st.path).resolve())) for st in stores)
            + f".</p><h2>Contents</h2><ul>{''.join(toc)}</ul>{''.join(parts)}"
            "<h2>Timings</h2><p>Report stages (seconds, this build):</p>"
            + _table_html(report_t)
            + "<p>Sweep stages (seconds, summed over tasks and workers):</p>"
            + _table_html(sweep_t)
            + "</body></html>"
        )
        path = out / "report.html"
        path.write_text(page, encoding="utf-8")
        return path
    finally:
        pool.close()
        bar.close()
