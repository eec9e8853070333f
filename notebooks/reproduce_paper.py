# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Reproducing the paper's figures from an experiment store
#
# Ranković & Porter (Chaos 2013) compare three systems over a range of disk radii: the
# two-disk billiard ("Two-particle"), a one-disk billiard kicked at Poisson times with the
# rate of the two-disk run of the same IC ("Poisson"), and one kicked at that run's actual
# disk-disk collision times ("Actual"). Their two families of experiments are built into
# kicktimes as the presets `family_a` and `family_b`, with small versions `quick_a` and
# `quick_b`.
#
# This notebook runs the experiments into a temporary result store with
# `kicktimes.experiment.run_experiment`, reads it back with `load_store`, draws the paper's
# figures with `kicktimes.plots`, and builds the HTML report with `kicktimes.report`. Every
# number quoted is computed from the store.
#
# **Size.** The environment variable `KICKTIMES_NOTEBOOK_SIZE` selects the size: `"small"`
# (default; the quick experiments, well under a minute on 2 cores), `"test"` (one quick
# experiment and a lighter report: what the default test suite runs) or `"full"`
# (the paper's families A and B at full scale; expect roughly half an hour on 2 cores, or
# pass a Dask scheduler address in `SCHEDULER`). Set it before starting Jupyter, e.g.
# `KICKTIMES_NOTEBOOK_SIZE=full jupyter lab`.

# %%
import os
import tempfile
import time
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import Image, display

import kicktimes as kt
from kicktimes import plots, stats
from kicktimes.diagnostics import Twin, lyapunov
from kicktimes.experiment import Experiment, kick_rng, load_store, preset, run_experiment
from kicktimes.report import Render, Subsampling, build_report
from kicktimes.studies.protocol import (
    Ratios,
    fig6_figure,
    panels,
    per_radius_table,
    ratio_table,
    run_protocol_study,
)

# %matplotlib inline
# tqdm.auto (imported by the sweep runner even with progress=False) warns in a kernel without
# ipywidgets; the progress bar is off here, so the warning says nothing about this notebook
warnings.filterwarnings("ignore", message="IProgress not found")
SIZE = os.environ.get("KICKTIMES_NOTEBOOK_SIZE", "small")
SIZES = {
    # experiments to run; report options (ICs with their own renewal fits, Monte Carlo
    # samples of the Poisson tests, PNG resolution) and the stores it covers
    "test": dict(names=("quick_a",), report_stores=("quick_a",), fits=1, n_mc=19, dpi=40),
    "small": dict(names=("quick_a", "quick_b"), report_stores=("quick_a", "quick_b"), fits=3,
                  n_mc=99, dpi=72),
    "full": dict(names=("family_a", "family_b"), report_stores=("family_a", "family_b"),
                 fits=12, n_mc=999, dpi=150),
}
if SIZE not in SIZES:
    raise ValueError(f"KICKTIMES_NOTEBOOK_SIZE must be one of {sorted(SIZES)}, got {SIZE!r}")
P = SIZES[SIZE]
WORKERS = min(2, os.cpu_count() or 1)
SCHEDULER = None  # e.g. "tcp://host:8786" to run the sweeps on a Dask cluster
WORKDIR = Path(tempfile.mkdtemp(prefix="kicktimes-reproduce-"))
pd.set_option("display.width", 120)
pd.set_option("display.precision", 4)
t_start = time.perf_counter()
print(f"size {SIZE!r}: experiments {P['names']}; stores and report under {WORKDIR}")

# %% [markdown]
# ## 1. The experiments
#
# An `Experiment` is a frozen dataclass with the same fields as its TOML file. The paper's
# families and their small versions are built-in presets (`kicktimes presets` lists them;
# `kicktimes presets NAME` prints one as TOML, to copy and edit); the TOML reads back to
# the same experiment (the same hash, which names the store).

# %%
experiments = {}
for name in P["names"]:
    exp = preset(name)
    if Experiment.from_toml_string(exp.to_toml()).hash() != exp.hash():
        raise RuntimeError(f"the TOML of preset {name!r} does not read back to it")
    experiments[name] = exp
    print(f"--- {name} (built-in preset; `kicktimes presets {name}` prints its TOML)")
    print(exp.summary())

# %% [markdown]
# ## 2. Run the sweeps
#
# `run_experiment(exp, store)` splits the sweep into tasks (one radius × one block of ICs),
# runs them on a local process pool (or any `concurrent.futures` executor, or a Dask cluster
# with `scheduler=`), and streams each finished task to Parquet part files with a manifest.
# Rerunning on the same store resumes it. Results do not depend on the executor or the
# number of workers.

# %%
stores = {}
for name, exp in experiments.items():
    t0 = time.perf_counter()
    options = dict(scheduler=SCHEDULER) if SCHEDULER else dict(workers=WORKERS)
    run_experiment(exp, WORKDIR / f"store-{name}", progress=False, **options)
    stores[name] = load_store(WORKDIR / f"store-{name}")
    print(f"{name}: {len(exp.tasks())} tasks in {time.perf_counter() - t0:.1f} s")
    print(stores[name].summary())
store = stores[P["names"][0]]
display(store.results.head(8))
display(store.collisions.head(3))

# %% [markdown]
# ## 3. Poincaré sections and a recurrence plot (paper Figs. 1 and 2)
#
# The paper shows one IC at r = 0.02 and r = 0.014, 15 000 steps of up to 0.3 time units.
# Trajectories are not stored by a sweep (only collision times and diagnostics), so they
# are recomputed from the first experiment's IC 0 with its seed, IC method and rule.

# %%
exp = experiments[P["names"][0]]
ic0 = kt.initial_conditions(1, exp.r_max, rng=exp.seed, method=exp.ic_method, rule=exp.rule)[0]
paper_steps = dict(n_steps=15000, tau=0.3, sampling="paper", rule=exp.rule)
runs = [kt.simulate_two_particle(ic0, r, **paper_steps) for r in (0.02, 0.014)]
display(plots.poincare_panels(runs))
for run in runs:
    st = run.boundary.query("particle == 0")["sin_theta"].to_numpy()
    repeats = np.mean(np.abs(np.diff(st)) < 1e-9)
    print(
        f"r = {run.r:g}: {run.n_pp} disk-disk collisions in {run.t_max:.0f} time units; "
        f"{repeats:.0%} of disk 0's consecutive boundary collisions repeat sin(theta) "
        "(the horizontal segments)"
    )
display(plots.recurrence_plot(runs[0].samples, eps=1e-3, title="IC 0, r = 0.02, eps = 0.001"))

# %% [markdown]
# ## 4. Poisson kick times against collision times (paper Fig. 3)
#
# The k-th Poisson kick time against the k-th disk-disk collision time at r = 0.008, for
# the IC with the median number of collisions in the store. The Poisson times are the
# sweep's own (rate $n_{pp}/T$ of that IC's run, random stream
# `kick_rng(ic, radius, "poisson", rng=seed)`). A quick run has only a handful of collisions at
# this radius, so the figure is redrawn for the same IC run to the paper's family-A length
# (25 000 steps of 0.2), with Poisson times at that run's rate from the same stream.

# %%
r_times = min(exp.radii)
at_r = store.collisions.query("radius == @r_times").sort_values(["n_pp", "ic"])
row = at_r.iloc[len(at_r) // 2]  # a typical IC: the median collision count
ic_times = int(row["ic"])
for label, n_steps, tau in (("store", exp.n_steps, exp.tau), ("paper length", 25000, 0.2)):
    if label == "store":
        pp_times, t_window = row["pp_times"], row["t_window"]
    else:
        ic = kt.initial_conditions(
            1, exp.r_max, rng=exp.seed, method=exp.ic_method, rule=exp.rule, start=ic_times
        )[0]
        run = kt.simulate_two_particle(
            ic, r_times, n_steps=n_steps, tau=tau, sampling=exp.sampling, rule=exp.rule
        )
        pp_times, t_window = run.pp_times, run.t_max
    rate = len(pp_times) / t_window
    poisson_times = kt.schedules.Poisson(rate).sample(
        n_steps * tau, rng=kick_rng(ic_times, r_times, "poisson", rng=exp.seed)
    )
    fit = plots.kth_time_fit(pp_times, poisson_times)
    print(
        f"{label}: IC {ic_times} at r = {r_times:g}, {len(pp_times)} collisions in "
        f"{t_window:.0f} time units; k-th kick time = {fit.slope:.3f} x k-th collision time "
        f"{fit.intercept:+.3g}, R^2 = {fit.r_squared:.4f} (n = {fit.n})"
    )
display(plots.kick_times_vs_collision_times(pp_times, poisson_times, radius=r_times))

# %% [markdown]
# ## 5. Mean number of collisions against radius (paper Fig. 4)
#
# The paper fits a least-squares line; `stats.regress_counts` adds Poisson and
# negative-binomial regressions with a $\log T$ offset, and the kinetic-theory rate
# (exact only for ICs from the invariant measure; these are the paper's ICs).

# %%
fig, axes = plt.subplots(1, len(stores), figsize=(6 * len(stores), 4.4), layout="constrained")
for ax, (name, st) in zip(np.atleast_1d(axes), stores.items(), strict=True):
    frame = st.collisions[["radius", "n_pp", "t_window"]]
    reg = stats.regress_counts(frame.rename(columns={"n_pp": "count"}), rule=st.experiment.rule)
    plots.counts_vs_radius(frame, regression=reg, ax=ax)
    ax.set_title(name)
    slope, intercept = reg.ols.params[1], reg.ols.params[0]
    table = plots.counts_by_radius(frame)
    kinetic = stats.kinetic_rate(table.index.to_numpy(), rule=st.experiment.rule)
    ratio = table["mean_count"] / (kinetic * table["mean_t_window"])
    print(
        f"{name}: paper's line, rate = {intercept:.4g} + {slope:.4g} r (R^2 = "
        f"{reg.ols.rsquared:.3f}); Poisson log-log slope "
        f"{reg.coefficients().loc[('poisson', 'log_radius'), 'estimate']:.3f}; mean count / "
        f"kinetic theory from {ratio.min():.2f} to {ratio.max():.2f}; NB alpha {reg.alpha:.3g}"
    )

# %% [markdown]
# ## 6. The diagnostics against radius (paper Figs. 6–8)
#
# For each radius and system: the ensemble mean with the paper's error bar (± std/10, thick
# and pale) and the standard error (± std/√n, thin with caps). The FTLE is the paper's
# variant, $\max(\lambda_x, \lambda_y)$.

# %%
diagnostics = ("lyapunov", "recurrence_rate", "autocorrelation")
fig, axes = plt.subplots(
    len(stores), 3, figsize=(17, 4.4 * len(stores)), layout="constrained", squeeze=False
)
summaries = {}
for i, (name, st) in enumerate(stores.items()):
    summaries[name] = plots.diagnostic_summary(st.results, diagnostic=list(diagnostics))
    for j, diagnostic in enumerate(diagnostics):
        plots.diagnostic_vs_radius(
            summaries[name],
            diagnostic,
            ax=axes[i, j],
            title=f"{name}: {plots.DIAGNOSTIC_LABELS[diagnostic][0]}",
        )

# %%
rows = []
for name, summary in summaries.items():
    wide = summary.pivot_table(index=["diagnostic", "radius"], columns="system", values="mean")
    sem = summary.pivot_table(index=["diagnostic", "radius"], columns="system", values="sem")
    for system in ("poisson", "actual"):
        rel = (wide[system] - wide["two_particle"]) / wide["two_particle"].abs()
        z = (wide[system] - wide["two_particle"]) / np.hypot(sem[system], sem["two_particle"])
        for (diagnostic, radius), value in rel.items():
            rows.append(
                {
                    "experiment": name,
                    "diagnostic": diagnostic,
                    "radius": radius,
                    "system": system,
                    "relative_difference": value,
                    "z": z[diagnostic, radius],
                }
            )
comparison = pd.DataFrame(rows)
agg = comparison.groupby(["experiment", "diagnostic", "system"]).agg(
    median_abs_rel=("relative_difference", lambda v: np.median(np.abs(v))),
    within_2se=("z", lambda v: np.mean(np.abs(v) < 2)),
)
display(agg)
for (name, diagnostic), part in agg.groupby(level=["experiment", "diagnostic"]):
    part = part.droplevel(["experiment", "diagnostic"])
    closer = part["median_abs_rel"].idxmin()
    print(
        f"{name}, {diagnostic}: median |relative difference| to the two-disk billiard is "
        f"{part.loc['poisson', 'median_abs_rel']:.1%} for Poisson and "
        f"{part.loc['actual', 'median_abs_rel']:.1%} for Actual kicks (closer: {closer}); "
        f"within 2 standard errors at {part.loc['poisson', 'within_2se']:.0%} / "
        f"{part.loc['actual', 'within_2se']:.0%} of the radii"
    )

# %% [markdown]
# ## 6b. Fig. 6 by the paper's own eq. (4): both readings
#
# The paper's eq. (4), $\lambda_{\max}(n) = \frac{1}{\tau n}\sum_{k=1}^{n}
# \log(\lVert\delta d(k\tau)\rVert / \lVert\delta d(0)\rVert)$ with
# $\lVert\delta d(0)\rVert = 1/5000$, names Benettin's algorithm but prints no
# renormalisation. `lyapunov(..., method=Twin(variant="paper", d0=1/5000,
# renormalize=False))` computes it as printed; `renormalize=True` is Benettin's. One IC first:

# %%
panel = panels("paper" if SIZE == "full" else "quick")[0]
ic, r = panel.initial_conditions()[0], panel.radii[-1]
steps = dict(n_steps=panel.n_steps, tau=panel.tau, sampling="paper")
for renormalize in (False, True):
    res = lyapunov(
        ic, r, method=Twin(variant="paper", d0=1 / 5000, renormalize=renormalize), **steps
    )
    print(f"two disks, r = {r}: renormalize={renormalize}: {res.lam:.4g}")

# %% [markdown]
# Read as printed, the twin is never renormalised: its separation saturates at the table's
# size and eq. (4) tends to $E[\log(d/d_0)]/\tau$, the same in every system, whatever its
# stretching. The protocol study computes the three systems under every reading on both
# panels (`kicktimes reproduce --study protocol`; at the small size, 8 ICs and 1500 steps
# per panel; the paper's scale takes about 18 minutes on 2 cores and writes
# docs/results/paper.md). Left: eq. (4) as printed; right: Benettin.

# %%
t0 = time.perf_counter()
scale = "paper" if SIZE == "full" else "quick"
rows_protocol = run_protocol_study(WORKDIR / f"store-protocol-{scale}", scale, workers=WORKERS)
panel_list = panels(scale)
ratios = Ratios(rows_protocol)
fig6_figure(per_radius_table(rows_protocol, ratios, panel_list), panel_list)
plt.show()
readings = ratio_table(ratios, panel_list)
display(
    readings[
        readings["control"].isin(
            ["literal/paper/shared/uniform", "renormalised/paper/shared/uniform"]
        )
    ][["family", "system", "estimator", "estimate", "ci_low", "ci_high", "verdict"]]
)
print(f"protocol study in {time.perf_counter() - t0:.1f} s")

# %% [markdown]
# ## 7. The report
#
# `build_report(stores, out_dir)` (also `kicktimes report STORE --out DIR`) recomputes every
# table and figure from the store(s) and writes `report.html` (self-contained), a PNG and a
# PDF per figure and a CSV per table. With several stores each gets its own part (file
# names prefixed by the experiment) and the diagnostics are also drawn one panel per
# experiment. At the small size the report uses fewer per-IC renewal fits, fewer Monte Carlo
# samples and a lower PNG resolution, to stay within the CI budget.

# %%
t0 = time.perf_counter()
out = WORKDIR / "report"
html = build_report(
    [WORKDIR / f"store-{name}" for name in P["report_stores"]],
    out,
    progress=False,
    subsampling=Subsampling(max_ics_model_fits=P["fits"]),
    n_mc=P["n_mc"],
    render=Render(dpi=P["dpi"]),
    workers=WORKERS,
)
files = sorted(p.name for p in out.iterdir())
print(
    f"report built in {time.perf_counter() - t0:.1f} s: {html} ({html.stat().st_size / 1e6:.1f} MB)"
    f", {sum(f.endswith('.png') for f in files)} PNG figures, "
    f"{sum(f.endswith('.csv') for f in files)} CSV tables"
)
print("\n".join(files))
for png in sorted(out.glob("*poisson_rejection_rates.png")) + sorted(
    out.glob("*rate_heterogeneity.png")
):
    display(Image(filename=str(png)))
print(f"\nnotebook computed in {time.perf_counter() - t_start:.1f} s")
