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
# # Kick schedules: from collision times to a kicked one-disk billiard
#
# A tour of the kicktimes API along the paper's path:
#
# 1. simulate the two-disk billiard and **fit renewal models** to its disk-disk collision
#    times (`kicktimes.stats`);
# 2. **build kick schedules** from the fits and from the runs: Poisson, renewal, stationary
#    renewal, replay of the actual times, bootstrap of the observed intervals; save them as
#    JSON and the sampled times as files (`kicktimes.schedules`);
# 3. **drive the one-disk billiard** with them (`kicktimes.simulate_one_particle`);
# 4. compute the paper's **diagnostics**: recurrence rate, autocorrelation of the
#    boundary-collision angles, finite-time Lyapunov exponent with kicks shared by the
#    twin trajectories (`kicktimes.diagnostics`);
# 5. **compare** the kicked billiards with the two-disk billiard on a small ensemble at one
#    radius.
#
# **Size.** The environment variable `KICKTIMES_NOTEBOOK_SIZE` selects the size: `"small"`
# (default, about 15 s on 2 cores), `"test"` (a few seconds: what the default test suite
# runs, to check that every cell works) or `"full"` (a real study: 200 ICs of 25 000 steps,
# the paper's family-A length; a few minutes). Set it before starting Jupyter,
# e.g. `KICKTIMES_NOTEBOOK_SIZE=full jupyter lab`.

# %%
import os
import tempfile
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display
from scipy import stats as sps

import kicktimes as kt
from kicktimes import diagnostics as dg
from kicktimes import plots, schedules, stats

# %matplotlib inline
SIZE = os.environ.get("KICKTIMES_NOTEBOOK_SIZE", "small")
SIZES = {
    # ICs of the training ensemble (fits) and of the comparison, steps of the comparison runs,
    # window of the training runs, Monte Carlo samples of the goodness-of-fit tests
    "test": dict(n_train=10, train_window=2000.0, n_ics=6, n_steps=2000, gof_mc=19),
    "small": dict(n_train=40, train_window=5000.0, n_ics=30, n_steps=10000, gof_mc=99),
    "full": dict(n_train=400, train_window=50000.0, n_ics=200, n_steps=25000, gof_mc=499),
}
if SIZE not in SIZES:
    raise ValueError(f"KICKTIMES_NOTEBOOK_SIZE must be one of {sorted(SIZES)}, got {SIZE!r}")
P = SIZES[SIZE]
R = 0.02  # disk radius of the whole tour
R_MAX = 0.03  # the ICs are drawn at the largest radius of the paper's family A
TAU = 0.2
SEED = 7
t_start = time.perf_counter()
pd.set_option("display.width", 120)
pd.set_option("display.precision", 4)
print(f"size {SIZE!r}: r = {R}, {P['n_ics']} ICs x {P['n_steps']} steps of {TAU}")


def stream(*key):
    """An independent random stream for each named piece of the tour."""
    return np.random.default_rng(np.random.SeedSequence(SEED, spawn_key=key))


# %% [markdown]
# ## 1. Collision times and renewal fits
#
# A *training* ensemble of paper ICs (mirror rule, the paper's), each run for a long window,
# gives the disk-disk collision times. `stats.intervals_from_times` turns them into
# complete intervals (the first time $t_1$, a forward recurrence time, is dropped) and
# right-censored ones (the interval $T - t_n$ still running at the end of each window).

# %%
train_ics = kt.initial_conditions(P["n_train"], R_MAX, rng=SEED + 1, method="paper")
train = [kt.simulate_two_particle(ic, R, t_max=P["train_window"]) for ic in train_ics]
iv = stats.intervals_from_times([run.pp_times for run in train], [run.t_max for run in train])
print(train[0])
print(
    f"{len(train)} runs of {P['train_window']:g} time units: {iv.complete.size} complete "
    f"intervals, {iv.censored.size} censored; mean interval "
    f"{(iv.complete.sum() + iv.censored.sum()) / iv.complete.size:.2f} (kinetic theory "
    f"1/Gamma = {1 / stats.kinetic_rate(R):.2f})"
)
table = stats.compare_models(iv.complete, censored=iv.censored)
display(table[["loglik", "k", "aic", "delta_aic", "weight", "n", "n_censored"]])

# %%
fits = {
    m: stats.fit_renewal(iv.complete, m, censored=iv.censored)
    for m in ("exponential", "gamma", "weibull", "hyperexponential")
}
best = table.index[0]
fits.setdefault(best, stats.fit_renewal(iv.complete, best, censored=iv.censored))
print(fits["gamma"].summary())
gof = {
    m: stats.goodness_of_fit(fits[m], n_mc=P["gof_mc"], rng=stream(1))
    for m in ("exponential", best)
}
for m, g in gof.items():
    bound = "<=" if g.pvalue <= 1 / (g.n_mc + 1) + 1e-12 else "="
    print(
        f"goodness of fit of the {m} fit: KS = {g.statistic:.4f}, p {bound} {g.pvalue:.3g} "
        f"({g.method}, {g.n_mc} samples)"
    )
print(
    f"AIC-best model: {best} (Akaike weight {table.loc[best, 'weight']:.2f}); the exponential "
    f"(Poisson) is {table.loc['exponential', 'delta_aic']:.1f} AIC units behind; gamma shape "
    f"{fits['gamma'].params['shape']:.3f} ± {fits['gamma'].stderr['shape']:.3f} (1 = exponential)"
)

# %% [markdown]
# ## 2. Schedules
#
# A schedule is an immutable value with `sample(t_max, rng=rng)`, returning sorted kick times in
# $(0, t_{max}]$. They are built from fits (`Renewal.from_fit`, or any frozen
# `scipy.stats` distribution) and from runs (`Poisson.from_run`: the paper's per-IC rate
# $n_{pp}/T$; `Replay.from_run`: the actual collision times; `Bootstrap.from_run`:
# resampled intervals). `stationary=True` draws the first interval from the equilibrium
# law $S(x)/E[X]$, so that the kick process is stationary from $t = 0$.

# %%
two_demo = train[0]
catalogue = {
    "poisson (pooled fit)": schedules.Poisson(fits["exponential"].params["rate"]),
    "poisson (one run)": schedules.Poisson.from_run(two_demo),
    "renewal gamma": schedules.Renewal.from_fit(fits["gamma"]),
    "renewal gamma, stationary": schedules.Renewal.from_fit(fits["gamma"], stationary=True),
    f"renewal {best}, stationary": schedules.Renewal.from_fit(fits[best], stationary=True),
    "replay (one run)": schedules.Replay.from_run(two_demo),
    "bootstrap (one run)": schedules.Bootstrap.from_run(two_demo),
    "bootstrap (pooled), stationary": schedules.Bootstrap(iv.complete, stationary=True),
}
for name, s in catalogue.items():
    print(f"{name:38s} {s!r}")

# %% [markdown]
# Every schedule round-trips through JSON (`to_json` / `schedules.from_json`, exact floats),
# and stationarity shows in the mean number of kicks in a short window $(0, h]$: a
# stationary schedule gives $h / E[X]$ exactly, an ordinary renewal process started by a
# renewal at 0 gives its renewal function $M(h) = \sum_k P(S_k \le h)$ instead (for a
# gamma law with shape < 1, more kicks at first).

# %%
h = 3.0 * fits["gamma"].dist.mean()
n_draws = 4000
rows = []
for name, s in catalogue.items():
    text = s.to_json()
    if name.startswith("replay"):
        counts = np.full(n_draws, s.sample(h).size)
    else:
        rng = stream(2, len(rows))
        counts = np.array([s.sample(h, rng=rng).size for _ in range(n_draws)])
    mean_interval = getattr(s, "mean_interval", np.nan)
    rows.append(
        {
            "schedule": name,
            "json_bytes": len(text),
            "round_trip": schedules.from_json(text) == s,
            "mean_interval": mean_interval,
            "E[N(h)]": counts.mean(),
            "s.e.": counts.std(ddof=1) / np.sqrt(n_draws),
            "h/E[X]": h / mean_interval,
        }
    )
schedule_table = pd.DataFrame(rows).set_index("schedule")
display(schedule_table)
# The renewal function of the ordinary gamma process, exactly: the k-th kick time is
# gamma(k a, scale) distributed, so E[N(h)] = sum_k P(S_k <= h).
a, scale = fits["gamma"].params["shape"], fits["gamma"].params["scale"]
k = np.arange(1, 2000)
renewal_function = float(sps.gamma.cdf(h, k * a, scale=scale).sum())
exact = {
    "renewal gamma": renewal_function,
    "renewal gamma, stationary": h / fits["gamma"].dist.mean(),
}
for name, value in exact.items():
    row = schedule_table.loc[name]
    z = (row["E[N(h)]"] - value) / row["s.e."]
    z_naive = (row["E[N(h)]"] - row["h/E[X]"]) / row["s.e."]
    print(
        f"{name}: {row['E[N(h)]']:.3f} ± {row['s.e.']:.3f} kicks in (0, {h:.1f}]; exact "
        f"{value:.3f} (z = {z:+.1f}); h/E[X] = {row['h/E[X]']:.3f} (z = {z_naive:+.1f})"
    )
print(f"all schedules round-trip through JSON: {bool(schedule_table['round_trip'].all())}")

# %% [markdown]
# Sampled kick times are stored with their provenance (schedule, seed, window) in CSV or
# Parquet; the same files feed the command line (`kicktimes schedule ...`).

# %%
with tempfile.TemporaryDirectory() as tmp:
    sched = catalogue["renewal gamma, stationary"]
    times = sched.sample(1000.0, rng=3)
    path = schedules.write_kick_times(
        times, Path(tmp) / "kicks.parquet", t_max=1000.0, schedule=sched, seed=3
    )
    back, meta = schedules.read_kick_times(path, with_metadata=True)
    print(
        f"{path.name}: {meta['n_kicks']} kicks, t_max {meta['t_max']}, seed {meta['seed']}, "
        f"schedule type {meta['schedule']['type']!r}; identical after reading: "
        f"{bool(np.array_equal(back, times))}"
    )

# %% [markdown]
# ## 3. Driving the one-disk billiard
#
# `simulate_one_particle(state, r, kicks=...)` takes the tracked disk's IC (disk 0 of the
# two-disk IC) and either an array of kick times or a schedule, sampled with `rng`. A
# `"uniform"` kick replaces the velocity direction by an angle uniform on $[0, 2\pi)$ (the
# paper's choice); `"gaussian"` rotates it by $N(0, \sigma^2)$. The run records the kicks
# it applied (`run.kick_times`, `run.kick_angles`). Without kicks the disk is integrable:
# every boundary collision has the same $\sin\theta$.

# %%
ic = kt.initial_conditions(1, R_MAX, rng=SEED)[0]
steps = dict(n_steps=P["n_steps"], tau=TAU)
two = kt.simulate_two_particle(ic, R, **steps)
free = kt.simulate_one_particle(ic[0], R, **steps)
poisson_run = kt.simulate_one_particle(
    ic[0], R, kicks=schedules.Poisson.from_run(two), rng=stream(3), **steps
)
actual_run = kt.simulate_one_particle(
    ic[0], R, kicks=schedules.Replay.from_run(two), rng=stream(4), **steps
)
for name, run in (
    ("two disks", two),
    ("no kicks", free),
    ("Poisson", poisson_run),
    ("actual", actual_run),
):
    print(f"{name:10s} {run!r}")
spread = np.ptp(free.boundary["sin_theta"])
print(f"without kicks sin(theta) varies by {spread:.2e} over {free.n_boundary} boundary hits")
display(
    plots.poincare_panels(
        [two, free, poisson_run, actual_run],
        titles=[
            f"(a) two disks, disk 0 ({two.n_pp} disk-disk collisions)",
            "(b) one disk, no kicks (integrable)",
            f"(c) Poisson kicks at the run's rate ({poisson_run.n_kicks} kicks)",
            f"(d) kicks at the actual collision times ({actual_run.n_kicks} kicks)",
        ],
    )
)

# %% [markdown]
# ## 4. Diagnostics of one IC
#
# * `dg.recurrence_rate(run.samples, eps=eps)`: the share of sample pairs (main diagonal
#   included) closer than ε, counted with a cell list, never an N × N matrix;
# * `dg.autocorrelation(dg.boundary_angles(run), lag=1)`: the paper's $R_1$ of
#   $\theta = \arcsin(\sin\theta)$ at the disk's boundary collisions; NaN with a reason for
#   a constant series (the unkicked disk);
# * `dg.lyapunov(run)`: Benettin's finite-time exponent with twins $d_0 = 1/5000$ away.
#   For a kicked run the twins get the run's own kick times *and* angles (common random
#   numbers), which is the same as passing their kick law,
#   `kicks=kt.billiard.KickLaw.from_run(run)`, explicitly.

# %%
rows = []
for name, run in (
    ("two disks", two),
    ("no kicks", free),
    ("Poisson", poisson_run),
    ("actual", actual_run),
):
    curve = dg.acf_curve(dg.boundary_angles(run), 1)  # R_1 and its reason, no warning
    acf, reason = float(curve.acf[0]), curve.lag_reasons[0]
    ftle = dg.lyapunov(run)
    rows.append(
        {
            "system": name,
            "RR(1e-3)": dg.recurrence_rate(run.samples, eps=1e-3),
            "RR(1e-2)": dg.recurrence_rate(run.samples, eps=1e-2),
            "RR(1e-2), off-diagonal": dg.recurrence_rate(run.samples, eps=1e-2, theiler=1),
            "R_1": acf,
            "R_1 note": reason or "",
            "lambda": ftle.lam,
            "renormalisations": ftle.n_renorm,
            "deferred": ftle.n_deferred,
            "forced": ftle.n_forced,
        }
    )
one_ic = pd.DataFrame(rows).set_index("system")
display(one_ic)
n_samples = two.samples.shape[0]
print(
    f"N = {n_samples} samples: the main diagonal alone gives RR = 1/N = {1 / n_samples:.3g}, "
    f"so RR(1e-3) = {one_ic.loc['two disks', 'RR(1e-3)']:.3g} for the two disks is "
    f"{one_ic.loc['two disks', 'RR(1e-3)'] * n_samples:.2f} / N; off the diagonal, RR(1e-2) is "
    f"{one_ic.loc['two disks', 'RR(1e-2), off-diagonal']:.3g} (two disks) and "
    f"{one_ic.loc['no kicks', 'RR(1e-2), off-diagonal']:.3g} (the periodic unkicked disk)"
)
explicit = dg.lyapunov(
    ic[0], R, kicks=kt.billiard.KickLaw.from_run(poisson_run), **steps
)
paper_variant = dg.lyapunov(two, method=dg.Tangent(variant="paper"))
print(
    f"lyapunov(run) = {one_ic.loc['Poisson', 'lambda']:.6g} and the explicit call with the "
    f"run's kicks = {explicit.lam:.6g} (equal: {explicit.lam == one_ic.loc['Poisson', 'lambda']})"
)
print(
    f"two disks: 2-norm FTLE {one_ic.loc['two disks', 'lambda']:.4f}, the paper's "
    f"max(lambda_x, lambda_y) = {paper_variant.lam:.4f} (x {paper_variant.lam_x:.4f}, "
    f"y {paper_variant.lam_y:.4f})"
)

# %% [markdown]
# ## 5. Two disks versus kicked disks on a small ensemble
#
# For each IC of a paper ensemble at r = 0.02 (uniform sampling, $t_k = k\tau$): the
# two-disk run and four kicked one-disk runs from disk 0's IC, kicked by
#
# * **poisson**: a Poisson process at that IC's own rate $n_{pp}/T$ (the paper's "Poisson");
# * **actual**: that IC's disk-disk collision times (the paper's "Actual");
# * **renewal**: the AIC-best renewal model of the training ensemble, stationary;
# * **bootstrap**: the training ensemble's pooled intervals, resampled, stationary.
#
# Results go in a tidy table (`radius, ic, system, diagnostic, value, note`), the same
# layout as an experiment store, so `plots.diagnostic_summary` summarises it.

# %%
systems = {
    "poisson": lambda two: schedules.Poisson.from_run(two),
    "actual": lambda two: schedules.Replay.from_run(two),
    "renewal": lambda two: catalogue[f"renewal {best}, stationary"],
    "bootstrap": lambda two: catalogue["bootstrap (pooled), stationary"],
}
ics = kt.initial_conditions(P["n_ics"], R_MAX, rng=SEED + 2, method="paper")
t0 = time.perf_counter()
rows = []


def record(i, system, run, ftle):
    curve = dg.acf_curve(dg.boundary_angles(run), 1)  # R_1 and its reason, no warning
    acf, reason = float(curve.acf[0]), curve.lag_reasons[0]
    for diagnostic, value, note in (
        ("lyapunov", ftle.lam, ""),
        ("recurrence_rate", dg.recurrence_rate(run.samples, eps=1e-3), ""),
        ("autocorrelation", acf, reason or ""),
    ):
        rows.append((R, i, system, diagnostic, value, note))


for i, ic_i in enumerate(ics):
    two_i = kt.simulate_two_particle(ic_i, R, **steps)
    record(i, "two_particle", two_i, dg.lyapunov(two_i))
    for k, (system, make) in enumerate(systems.items()):
        run = kt.simulate_one_particle(ic_i[0], R, kicks=make(two_i), rng=stream(5, i, k), **steps)
        record(i, system, run, dg.lyapunov(run))
results = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value", "note"])
print(f"{P['n_ics']} ICs x 5 systems in {time.perf_counter() - t0:.1f} s")
summary = plots.diagnostic_summary(results)
display(
    summary.pivot_table(index="system", columns="diagnostic", values=["mean", "sem", "n_valid"])
)

# %% [markdown]
# The kicked runs share their ICs with the two-disk runs, so each kicked system is compared
# with the two-disk system by the **paired** differences over ICs (mean ± standard error).
#
# When reading the FTLE, remember what separates nearby trajectories. A disk-disk
# collision between two round disks *defocuses*: it multiplies a small deviation by about
# 1/r, so it stretches by about ln(1/r) nats. A state-blind kick (a new direction drawn
# whatever the state) has no such amplification: it only turns the deviation it finds.
# So the kicked FTLE is smaller, by about that much per perturbation (`lam_per_perturbation`).

# %%
wide = results.pivot_table(index=["diagnostic", "ic"], columns="system", values="value")
order = ["two_particle", *systems]
fig, axes = plt.subplots(1, 3, figsize=(13, 4), layout="constrained")
for ax, diagnostic in zip(axes, ("lyapunov", "recurrence_rate", "autocorrelation"), strict=True):
    part = summary[summary["diagnostic"] == diagnostic].set_index("system").loc[order]
    x = np.arange(len(order))
    ax.errorbar(
        x,
        part["mean"],
        yerr=part["paper_err"],
        fmt="none",
        lw=6,
        alpha=0.3,
        color="grey",
        label="± std/10 (paper's bar)",
    )
    ax.errorbar(
        x, part["mean"], yerr=part["sem"], fmt="o", capsize=3, color="black", label="mean ± s.e.m."
    )
    ax.set_xticks(x, order, rotation=30)
    ax.set_title(plots.DIAGNOSTIC_LABELS[diagnostic][0])
    ax.set_ylabel(plots.DIAGNOSTIC_LABELS[diagnostic][1])
axes[0].legend(fontsize="small")
fig.suptitle(f"r = {R}, {P['n_ics']} paper ICs, {P['n_steps']} steps of {TAU}")

paired = []
for diagnostic in ("lyapunov", "recurrence_rate", "autocorrelation"):
    w = wide.loc[diagnostic]
    for system in systems:
        d = (w[system] - w["two_particle"]).dropna()
        se = d.std(ddof=1) / np.sqrt(d.size)
        paired.append(
            {
                "diagnostic": diagnostic,
                "system": system,
                "n": d.size,
                "two_particle": w["two_particle"].mean(),
                "kicked": w[system].mean(),
                "mean_difference": d.mean(),
                "se": se,
                "z": d.mean() / se,
            }
        )
paired = pd.DataFrame(paired).set_index(["diagnostic", "system"])
display(paired)
for (diagnostic, system), row in paired.iterrows():
    verdict = "indistinguishable at 2 s.e." if abs(row["z"]) < 2 else "different"
    print(
        f"{diagnostic}: {system} {row['kicked']:.4g} vs two disks {row['two_particle']:.4g} "
        f"(paired difference {row['mean_difference']:+.3g} ± {row['se']:.2g} over "
        f"{int(row['n'])} ICs, z = {row['z']:+.1f}: {verdict})"
    )
print(f"\nnotebook computed in {time.perf_counter() - t_start:.1f} s")
