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
# # Are disk-disk collision times Poisson?
#
# Ranković & Porter (Chaos 2013) kick a one-disk billiard at the times of a Poisson process
# whose rate is the disk-disk collision rate of the two-disk billiard, assuming that "all of
# the time intervals between particle-particle collisions have the same distribution" and are
# independent. This notebook tests that assumption on the two-disk billiard itself:
#
# 1. simulate two disks over a range of radii, with both collision rules (`"mirror"`, the
#    paper's, and `"elastic"`) and two initial-condition (IC) ensembles: the invariant
#    (Liouville) measure (`method="uniform"`) and the paper's procedure (`method="paper"`);
# 2. check the simulator against the exact kinetic-theory identity
#    $E[N(T)] = \Gamma T$ under the invariant measure;
# 3. test every IC's collision times for a homogeneous Poisson process (seven tests) and
#    summarise the ensembles (combined p-values, false discovery rate, rate homogeneity);
# 4. look at the outlier ICs of the paper's ensemble (sticky and silent orbits) and at
#    robust summaries;
# 5. compare renewal models per IC and pooled over ICs (censored likelihoods);
# 6. regress the collision counts on the radius, beside the kinetic-theory curve.
#
# Every conclusion below is printed from the computed numbers.
#
# **Size.** The environment variable `KICKTIMES_NOTEBOOK_SIZE` selects the size:
# `"small"` (default; about half a minute on 2 cores), `"test"` (two radii and small
# ensembles: what the default test suite runs) or `"full"` (a real
# study: 7 radii, 1000 ICs per ensemble, windows of 20 000 time units; tens of minutes).
# Set it before starting Jupyter, e.g. `KICKTIMES_NOTEBOOK_SIZE=full jupyter lab`.

# %%
import os
import time

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display
from scipy import stats as sps
from statsmodels.stats.multitest import multipletests

import kicktimes as kt
from kicktimes import plots, stats

# %matplotlib inline
SIZE = os.environ.get("KICKTIMES_NOTEBOOK_SIZE", "small")
SIZES = {
    # radii, ICs per (method, rule, radius), observation window T, Monte Carlo samples of the
    # conditional nulls, ICs per radius with their own renewal-model comparison, ICs of the
    # dedicated search for sticky orbits
    "test": dict(radii=(0.01, 0.03), n_ics=24, t_window=1500.0, n_mc=99, n_fit_ics=2,
                 n_search=300),
    "small": dict(radii=(0.01, 0.02, 0.03), n_ics=120, t_window=3000.0, n_mc=999, n_fit_ics=6,
                  n_search=1500),
    "full": dict(radii=(0.006, 0.008, 0.01, 0.014, 0.02, 0.026, 0.03), n_ics=1000,
                 t_window=20000.0, n_mc=999, n_fit_ics=100, n_search=20000),
}
if SIZE not in SIZES:
    raise ValueError(f"KICKTIMES_NOTEBOOK_SIZE must be one of {sorted(SIZES)}, got {SIZE!r}")
P = SIZES[SIZE]
RADII = P["radii"]
T = P["t_window"]
ALPHA = 0.05
SEED = 2013
RULES = ("mirror", "elastic")
METHODS = ("uniform", "paper")
pd.set_option("display.width", 120)
pd.set_option("display.precision", 4)
t_start = time.perf_counter()
print(f"size {SIZE!r}: radii {RADII}, {P['n_ics']} ICs per ensemble, window T = {T:g}")


def stream(*key):
    """An independent random stream for each named piece of the analysis."""
    return np.random.default_rng(np.random.SeedSequence(SEED, spawn_key=key))


# %% [markdown]
# ## 1. Simulate the ensembles
#
# * **Invariant measure** (`method="uniform"`): drawn at `r_max = r` for each radius, because
#   the measure depends on the radius (an ensemble drawn at a larger radius is *not*
#   invariant at a smaller one). Under `"mirror"` both speeds are 1 with independent uniform
#   directions; under `"elastic"` $(v_1, v_2)$ is uniform on $|v_1|^2 + |v_2|^2 = 2$.
# * **Paper** (`method="paper"`): distance from the centre uniform on (0, 1) (not
#   area-uniform), drawn once at the largest radius and reused for every radius, as in the
#   paper. The same ICs serve both rules.
#
# Each IC is observed on the window $[0, T]$ (`t_max=T`): `pp_times` holds its disk-disk
# collision times and `n_pp` their number.


# %%
def simulate_ensemble(method, rule, radius):
    r_max = radius if method == "uniform" else max(RADII)
    ics = kt.initial_conditions(P["n_ics"], r_max, rng=SEED, method=method, rule=rule)
    rows = []
    for i, ic in enumerate(ics):
        run = kt.simulate_two_particle(ic, radius, t_max=T, rule=rule)
        rows.append((method, rule, radius, i, run.t_max, run.n_pp, run.pp_times))
    return rows


t0 = time.perf_counter()
rows = [
    row
    for method in METHODS
    for rule in RULES
    for radius in RADII
    for row in simulate_ensemble(method, rule, radius)
]
collisions = pd.DataFrame(
    rows, columns=["method", "rule", "radius", "ic", "t_window", "n_pp", "pp_times"]
)
collisions["kinetic"] = [
    stats.kinetic_rate(r, rule=rule) * t
    for r, rule, t in zip(
        collisions["radius"], collisions["rule"], collisions["t_window"], strict=True
    )
]
collisions["ratio"] = collisions["n_pp"] / collisions["kinetic"]
print(
    f"{len(collisions)} two-disk runs of {T:g} time units simulated in "
    f"{time.perf_counter() - t0:.1f} s; {collisions['n_pp'].sum()} disk-disk collisions"
)
display(
    collisions.groupby(["method", "rule", "radius"])["n_pp"].describe()[
        ["count", "mean", "std", "min", "50%", "max"]
    ]
)

# %% [markdown]
# ## 2. An exact check: $E[N(T)] = \Gamma T$ under the invariant measure
#
# The kinetic-theory rate $\Gamma(r) = 4\pi r\,L(2r)\,E[(w\cdot n)^-]/|Q|$
# (`stats.kinetic_rate`) is the flux of disk pairs into contact under the invariant measure.
# Because the measure is invariant, the expected count is exactly $\Gamma T$ for every $T$
# (no asymptotics), so the invariant ensembles must agree with it within their standard
# errors. The paper's ensemble is not invariant, so it need not.

# %%
check = collisions.groupby(["method", "rule", "radius"]).agg(
    n_ics=("n_pp", "size"),
    mean_count=("n_pp", "mean"),
    sd=("n_pp", "std"),
    kinetic=("kinetic", "mean"),
)
check["sem"] = check["sd"] / np.sqrt(check["n_ics"])
check["z"] = (check["mean_count"] - check["kinetic"]) / check["sem"]
check["mean / kinetic"] = check["mean_count"] / check["kinetic"]
display(check)

inv = check.loc["uniform"]
chi2 = float((inv["z"] ** 2).sum())
p_exact = float(sps.chi2.sf(chi2, len(inv)))
worst = inv["z"].abs().idxmax()
print(
    f"Invariant-measure ICs: {len(inv)} (rule, radius) cells, largest |z| = "
    f"{inv['z'].abs().max():.2f} (at {worst[0]}, r = {worst[1]:g}); "
    f"sum of z^2 = {chi2:.2f} on {len(inv)} df, p = {p_exact:.3g}."
)
print(
    "=> the simulated counts are "
    + ("consistent" if p_exact > 0.01 else "NOT consistent")
    + " with E[N(T)] = Gamma T at the 1% level."
)
pap = check.loc["paper"]
for rule in RULES:
    part = pap.loc[rule]
    print(
        f"Paper ICs, {rule}: mean count / (Gamma T) ranges over "
        f"{part['mean / kinetic'].min():.3f}..{part['mean / kinetic'].max():.3f} "
        f"(z from {part['z'].min():+.1f} to {part['z'].max():+.1f})."
    )

# %% [markdown]
# ## 3. Poisson tests of one IC
#
# `stats.test_poisson(times, T)` runs seven tests of a homogeneous Poisson process, each
# conditional on the number of events $n$ (so the rate is not a parameter):
#
# | test | checks |
# |---|---|
# | `uniformity_ks`, `laplace_trend`, `dispersion` | event times uniform on [0, T], no clusters |
# | `exponential_ks`, `exponential_ad` | inner intervals exponential (Lilliefors-type) |
# | `ljung_box`, `runs` | inner intervals serially independent |
#
# Interval tests use the $n-1$ inner intervals: the first time $t_1$ is a forward recurrence
# time and $T - t_n$ is censored.

# %%
r_demo = RADII[len(RADII) // 2]
demo = collisions.query("method == 'uniform' and rule == 'mirror' and radius == @r_demo")
demo_times = demo.iloc[0]["pp_times"]
table = stats.test_poisson(demo_times, T, n_mc=P["n_mc"], rng=stream(1))
display(table)
low = table["pvalue"].idxmin()
print(
    f"IC 0 (invariant measure, mirror, r = {r_demo:g}): {table.attrs['n_events']} collisions, "
    f"rate {table.attrs['rate']:.4g} vs kinetic {stats.kinetic_rate(r_demo):.4g}; smallest "
    f"p-value {table.loc[low, 'pvalue']:.3g} ({low})."
)

# %% [markdown]
# ## 4. Ensembles: combined p-values, false discovery rate, rate homogeneity
#
# `stats.test_poisson_ensemble` runs the tests on every IC of an ensemble and, per test,
# combines the p-values (Fisher; the global null "every IC is Poisson"), applies
# Benjamini–Hochberg across ICs, and tests whether all ICs share one rate (Pearson and
# likelihood-ratio tests of the counts given their total, with exact Monte Carlo p-values).
#
# An IC "rejects Poisson" below when its smallest p-value over the seven tests, Bonferroni
# corrected ($p_{IC} = \min(1, 7 \min_j p_j)$, valid whatever the dependence between the
# tests), is rejected by Benjamini–Hochberg across the ICs of its ensemble at α = 0.05.

# %%
t0 = time.perf_counter()
ensembles = {}
for k, ((method, rule, radius), part) in enumerate(
    collisions.groupby(["method", "rule", "radius"], sort=False)
):
    ensembles[method, rule, radius] = stats.test_poisson_ensemble(
        list(part["pp_times"]),
        part["t_window"].to_numpy(),
        alpha=ALPHA,
        n_mc=P["n_mc"],
        n_mc_max=50 * P["n_mc"],
        rng=stream(2, k),
    )
print(f"{len(ensembles)} ensembles tested in {time.perf_counter() - t0:.1f} s")
print(ensembles["uniform", "mirror", r_demo].summary())

# %%
tests = list(stats.TESTS)
summary_rows, rejections = [], []
for (method, rule, radius), ens in ensembles.items():
    per = ens.per_sequence
    p = per[[f"p_{t}" for t in tests]].to_numpy()
    tested = np.isfinite(p).any(axis=1)
    p_ic = np.minimum(1.0, len(tests) * np.nanmin(np.where(np.isfinite(p), p, np.inf), axis=1))
    reject_ic = np.zeros(len(per), bool)
    reject_ic[tested] = multipletests(p_ic[tested], alpha=ALPHA, method="fdr_bh")[0]
    hom = ens.rate_homogeneity
    summary_rows.append(
        {
            "method": method,
            "rule": rule,
            "radius": radius,
            "n_tested": int(tested.sum()),
            "reject_any_fdr": reject_ic.sum() / max(tested.sum(), 1),
            **{
                f"{t}_fdr": ens.combined.loc[t, "n_reject_fdr"] / ens.combined.loc[t, "n_sequences"]
                for t in ("uniformity_ks", "exponential_ks", "ljung_box", "dispersion")
            },
            "fisher_p_exponential_ks": ens.combined.loc["exponential_ks", "pvalue"],
            "rate_homogeneity_p": hom.loc["pearson", "pvalue_mc"],
            "rate_homogeneity_p_chi2": hom.loc["pearson", "pvalue"],
            "rate_outliers_fdr": int(ens.reject["rate"].sum()),
        }
    )
    for t in tests:
        rejections.append(
            {
                "method": method,
                "rule": rule,
                "radius": radius,
                "test": t,
                "n_tested": int(ens.combined.loc[t, "n_sequences"]),
                "n_reject": int(ens.combined.loc[t, "n_reject_raw"]),
            }
        )
ens_summary = pd.DataFrame(summary_rows).set_index(["method", "rule", "radius"])
rejections = pd.DataFrame(rejections)
display(ens_summary)


def fmt_mc(p, n_mc=P["n_mc"]):
    """A Monte Carlo p-value, marked as a bound when it sits at the floor 1/(n_mc + 1)."""
    return f"<= {p:.2g}" if p <= 1.0 / (n_mc + 1) * (1 + 1e-9) else f"= {p:.3g}"


for (method, rule, radius), row in ens_summary.iterrows():
    print(
        f"at r={radius:g} ({rule}, {method} ICs) {row['reject_any_fdr']:.1%} of "
        f"{int(row['n_tested'])} ICs reject Poisson at alpha={ALPHA} after FDR "
        f"(exponential intervals rejected for {row['exponential_ks_fdr']:.1%}, serial "
        f"dependence for {row['ljung_box_fdr']:.1%}); common-rate test p "
        f"{fmt_mc(row['rate_homogeneity_p'])} (chi-square p = {row['rate_homogeneity_p_chi2']:.2g})"
    )

# %% [markdown]
# The raw rejection rates of each test (p < α, before any multiplicity correction) with
# 95 % Clopper–Pearson intervals. If every IC were a Poisson process each curve would sit at
# the dotted line α (the tests hold their size; see docs/size_power.md).

# %%
fig, axes = plt.subplots(2, 2, figsize=(12, 8.5), sharey=True, layout="constrained")
for i, method in enumerate(METHODS):
    for j, rule in enumerate(RULES):
        sel = rejections.query("method == @method and rule == @rule")
        plots.poisson_rejection_rates(
            sel[["radius", "test", "n_tested", "n_reject"]], alpha=ALPHA, ax=axes[i, j]
        )
        axes[i, j].set_title(f"{rule} rule, {method} ICs")
        if (i, j) != (0, 0):
            axes[i, j].get_legend().remove()

# %%
mean_rate = rejections.assign(rate=rejections["n_reject"] / rejections["n_tested"])
by_test = mean_rate.groupby(["rule", "test"])["rate"].mean().unstack("rule")
display(by_test)
for rule in RULES:
    top = by_test[rule].idxmax()
    print(
        f"{rule}: the most rejecting test is {top} (mean raw rejection rate "
        f"{by_test.loc[top, rule]:.1%} over methods and radii, nominal {ALPHA:.0%}); the "
        f"least is {by_test[rule].idxmin()} ({by_test[rule].min():.1%})."
    )

# %% [markdown]
# ## 5. Outliers: sticky and silent ICs
#
# Under the mirror rule a few of the paper's ICs (0.2-0.8 % at these radii) lock into a regular
# cycle (both disks bouncing almost radially and meeting near the centre every ~2 time units)
# with collision counts 10–40× the kinetic rate, while a few others circle in step and hardly
# ever collide. We flag an IC as **sticky** when its count exceeds 5 Γ T and as **silent**
# when it has fewer than Γ T / 5 collisions (a Poisson count with mean Γ T essentially never
# does either at these window lengths).


# %%
def outlier_kind(ratio):
    return np.where(ratio > 5.0, "sticky", np.where(ratio < 0.2, "silent", "typical"))


collisions["kind"] = outlier_kind(collisions["ratio"].to_numpy())
kinds = (
    collisions.groupby(["method", "rule", "radius"])["kind"]
    .value_counts()
    .unstack(fill_value=0)
    .reindex(columns=["typical", "sticky", "silent"], fill_value=0)
)
display(kinds)
for (method, rule), part in kinds.groupby(level=["method", "rule"]):
    n = int(part.to_numpy().sum())
    print(
        f"{method} ICs, {rule}: {int(part['sticky'].sum())} sticky and "
        f"{int(part['silent'].sum())} silent out of {n} runs"
    )

# %% [markdown]
# The main ensembles are small, so a dedicated search simulates many more paper ICs at one
# radius (cheap: the simulator is exact and event-driven) to estimate how common sticky
# orbits are.

# %%
r_search = 0.02
t0 = time.perf_counter()
search_ics = kt.initial_conditions(P["n_search"], max(RADII), rng=SEED + 1, method="paper")
search_counts = np.array(
    [kt.simulate_two_particle(ic, r_search, t_max=T).n_pp for ic in search_ics]
)
search_ratio = search_counts / (stats.kinetic_rate(r_search) * T)
search_kind = outlier_kind(search_ratio)
n_sticky = int((search_kind == "sticky").sum())
n_silent = int((search_kind == "silent").sum())
lo, hi = plots.binomial_ci(n_sticky, P["n_search"])
print(
    f"{P['n_search']} paper ICs at r = {r_search:g}, mirror, T = {T:g} "
    f"({time.perf_counter() - t0:.1f} s): {n_sticky} sticky ({n_sticky / P['n_search']:.2%}, "
    f"95% CI {lo:.2%}..{hi:.2%}), {n_silent} silent ({n_silent / P['n_search']:.2%})."
)
if n_sticky:
    print(
        f"Sticky ICs collide {np.min(search_ratio[search_kind == 'sticky']):.1f}.."
        f"{np.max(search_ratio[search_kind == 'sticky']):.1f} times the kinetic rate."
    )

# %% [markdown]
# What a sticky and a silent orbit look like: cumulative collision counts $N(t)$ beside a few
# typical ICs and the kinetic line $\Gamma t$; and the last few time units of the stickiest
# orbit (both disks' centres).

# %%
i_sticky = int(np.argmax(search_ratio))
i_silent = int(np.argmin(search_ratio))
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6), layout="constrained")
gamma = stats.kinetic_rate(r_search)
for k, i in enumerate([i for i in range(P["n_search"]) if search_kind[i] == "typical"][:5]):
    run = kt.simulate_two_particle(search_ics[i], r_search, t_max=T)
    ax1.step(
        run.pp_times,
        np.arange(1, run.n_pp + 1),
        where="post",
        color="grey",
        lw=0.8,
        label="typical ICs" if k == 0 else None,
    )
for i, colour, label in ((i_sticky, "tab:red", "stickiest"), (i_silent, "tab:blue", "most silent")):
    run = kt.simulate_two_particle(search_ics[i], r_search, t_max=T)
    # on log axes an IC without collisions has no curve: it appears in the legend only
    ax1.step(
        np.r_[run.pp_times, T],
        np.r_[np.arange(1, run.n_pp + 1), run.n_pp],
        where="post",
        color=colour,
        label=f"{label} IC ({run.n_pp} collisions)",
    )
t_grid = np.geomspace(1.0, T, 50)
ax1.plot(t_grid, gamma * t_grid, "k:", label="kinetic theory Γt")
ax1.set_xscale("log")
ax1.set_yscale("log")
ax1.set_xlabel("time t (time units)")
ax1.set_ylabel("disk-disk collisions N(t)")
ax1.set_title(f"paper ICs, mirror rule, r = {r_search:g}")
ax1.legend(fontsize="small")
tail = 10.0
for track, colour in ((0, "tab:red"), (1, "tab:purple")):
    run = kt.simulate_two_particle(
        search_ics[i_sticky], r_search, t_max=T, n_steps=int(T / 0.01), tau=0.01, track=track
    )
    keep = run.sample_times >= T - tail
    ax2.plot(*run.samples[keep].T, color=colour, lw=1, label=f"disk {track}")
ax2.add_patch(plt.Circle((0, 0), 1 - r_search, fill=False, color="black"))
ax2.set_aspect("equal")
ax2.set_xlim(-1.05, 1.05)
ax2.set_ylim(-1.05, 1.05)
ax2.set_title(f"stickiest IC: centres over the last {tail:g} time units")
ax2.legend(fontsize="small")
print(
    f"The stickiest IC collides {search_ratio[i_sticky]:.1f} times the kinetic rate "
    f"(mean interval {T / max(search_counts[i_sticky], 1):.2f} time units); the most silent "
    f"has {search_counts[i_silent]} collisions against Gamma T = {gamma * T:.1f}."
)

# %% [markdown]
# Such outliers dominate means over ICs. Robust summaries of the per-IC rates
# $n_{pp}/T$, relative to the kinetic rate Γ: the mean, the median and the 10 %-trimmed
# mean, and the share of ICs flagged as rate outliers by the per-IC binomial test (after
# FDR). The figure shows the per-IC rates and the over-dispersion of the counts for the
# paper's ensemble under the mirror rule.


# %%
def robust(part):
    rate = part["n_pp"] / part["t_window"]
    gamma = part["kinetic"].iloc[0] / part["t_window"].iloc[0]
    return pd.Series(
        {
            "mean/Γ": rate.mean() / gamma,
            "median/Γ": rate.median() / gamma,
            "trimmed10/Γ": sps.trim_mean(rate, 0.1) / gamma,
            "dispersion": part["n_pp"].var(ddof=1) / part["n_pp"].mean(),
        }
    )


robust_table = collisions.groupby(["method", "rule", "radius"])[
    ["n_pp", "t_window", "kinetic"]
].apply(robust)
robust_table["rate_outliers_fdr"] = ens_summary["rate_outliers_fdr"]
display(robust_table)
for (method, rule, radius), row in robust_table.iterrows():
    if method == "paper" and rule == "mirror":
        print(
            f"paper ICs, mirror, r={radius:g}: mean rate {row['mean/Γ']:.3f} Γ, median "
            f"{row['median/Γ']:.3f} Γ, trimmed mean {row['trimmed10/Γ']:.3f} Γ; counts "
            f"{row['dispersion']:.1f}x over-dispersed; {int(row['rate_outliers_fdr'])} ICs "
            "flagged by the rate test"
        )

sel = collisions.query("method == 'paper' and rule == 'mirror'")
homogeneity = pd.DataFrame(
    {
        "radius": list(RADII),
        "pvalue": [ens_summary.loc[("paper", "mirror", r), "rate_homogeneity_p"] for r in RADII],
    }
)
display(plots.rate_heterogeneity(sel, homogeneity=homogeneity, rule="mirror"))

# %% [markdown]
# ## 6. Renewal models, per IC and pooled
#
# Intervals come from `stats.intervals_from_times(times, T)`: the inner intervals are
# complete, the first time $t_1$ (a forward recurrence time) is dropped (`first="drop"`),
# and the last interval $T - t_n$ is right-censored and enters every likelihood as
# $\log S(T - t_n)$. `stats.compare_models` fits the six full-sample models (exponential =
# Poisson, gamma, Weibull, lognormal, Lomax, two-component hyperexponential) by censored
# maximum likelihood and ranks them by AIC.
#
# *Per IC* asks whether each IC's own collision process is Poisson; *pooled* mixes the ICs,
# and a mixture of exponentials with different rates is hyperexponential even when every IC
# is Poisson. Invariant-measure ICs here.

# %%
t0 = time.perf_counter()
per_ic_rows, pooled_rows, pooled_samples = [], [], {}
for rule in RULES:
    for radius in RADII:
        part = collisions.query("method == 'uniform' and rule == @rule and radius == @radius")
        fitted = 0
        for _, row in part.iterrows():
            iv = stats.intervals_from_times(row["pp_times"], row["t_window"])
            if iv.complete.size < 20 or fitted >= P["n_fit_ics"]:
                continue
            table = stats.compare_models(iv.complete, censored=iv.censored)
            per_ic_rows.append(
                {
                    "rule": rule,
                    "radius": radius,
                    "ic": row["ic"],
                    "n_intervals": iv.complete.size,
                    "best_model": table.index[0],
                    "delta_aic_exponential": table.loc["exponential", "delta_aic"],
                    "weight_exponential": table.loc["exponential", "weight"],
                }
            )
            fitted += 1
        iv = stats.intervals_from_times(list(part["pp_times"]), part["t_window"].to_numpy())
        pooled_samples[rule, radius] = iv
        table = stats.compare_models(iv.complete, censored=iv.censored)
        for model, trow in table.iterrows():
            pooled_rows.append(
                {
                    "rule": rule,
                    "radius": radius,
                    "model": model,
                    "delta_aic": trow["delta_aic"],
                    "weight": trow["weight"],
                    "n": trow["n"],
                    "n_censored": trow["n_censored"],
                }
            )
per_ic = pd.DataFrame(per_ic_rows)
pooled = pd.DataFrame(pooled_rows)
print(f"renewal-model comparisons in {time.perf_counter() - t0:.1f} s")
display(pooled.pivot_table(index=["rule", "radius"], columns="model", values="delta_aic"))

for rule in RULES:
    fig = plots.model_comparison(per_ic.query("rule == @rule"), pooled.query("rule == @rule"))
    fig.suptitle(f"{rule} rule, invariant-measure ICs")
    display(fig)
    for radius in RADII:
        pi = per_ic.query("rule == @rule and radius == @radius")
        po = pooled.query("rule == @rule and radius == @radius").set_index("model")
        best = po["delta_aic"].idxmin()
        print(
            f"{rule}, r={radius:g}: per IC the exponential is AIC-best for "
            f"{(pi['best_model'] == 'exponential').mean():.0%} of {len(pi)} ICs (median "
            f"Akaike weight {pi['weight_exponential'].median():.2f}); pooled over "
            f"{int(po['n'].iloc[0])} intervals the best model is {best} (weight "
            f"{po.loc[best, 'weight']:.2f}) and the exponential is "
            f"{po.loc['exponential', 'delta_aic']:.1f} AIC units behind"
        )

# %% [markdown]
# Vuong's test on the pooled intervals at the largest radius (most intervals): positive $z$
# favours the first model. The exponential is nested in the others, so its comparisons are
# reported by AIC above rather than by Vuong's normal null.

# %%
r_big = max(RADII)
vuong_rows = []
for rule in RULES:
    iv = pooled_samples[rule, r_big]
    for m1, m2 in (("hyperexponential", "lomax"), ("gamma", "weibull"), ("lognormal", "weibull")):
        v = stats.vuong(iv.complete, m1, m2, censored=iv.censored)
        vuong_rows.append(
            {
                "rule": rule,
                "model1": m1,
                "model2": m2,
                "z": v.statistic,
                "pvalue": v.pvalue,
                "preferred": v.preferred or "neither",
            }
        )
vuong_table = pd.DataFrame(vuong_rows)
display(vuong_table)
for rule in RULES:
    iv = pooled_samples[rule, r_big]
    fit = stats.fit_renewal(iv.complete, "hyperexponential", censored=iv.censored)
    rates = collisions.query("method == 'uniform' and rule == @rule and radius == @r_big")
    rates = rates["n_pp"] / rates["t_window"]
    print(fit.summary())
    print(
        f"{rule}, r={r_big:g}: pooled hyperexponential rates {fit.params['rate1']:.4g} (weight "
        f"{fit.params['p']:.2f}) and {fit.params['rate2']:.4g}; the per-IC rates n_pp/T span "
        f"{rates.quantile(0.1):.4g}..{rates.quantile(0.9):.4g} (10-90%), kinetic "
        f"{stats.kinetic_rate(r_big, rule=rule):.4g}"
    )

# %% [markdown]
# ## 7. Collision counts versus radius
#
# `stats.regress_counts` fits the paper's least-squares line (pooled rate on radius), a
# Poisson regression and a negative-binomial regression (dispersion α estimated) of the
# counts on $\log r$ with offset $\log T$. The kinetic law is nearly linear in $r$ for small
# radii ($\Gamma \approx 16 r/(\pi^2 (1-r)^2)$ under the mirror rule), so the fitted slope of
# $\log E[N]$ on $\log r$ should be close to the kinetic curve's own log-log slope.

# %%
fig, axes = plt.subplots(2, 2, figsize=(12, 8.5), layout="constrained")
regressions = {}
for i, method in enumerate(METHODS):
    for j, rule in enumerate(RULES):
        sel = collisions.query("method == @method and rule == @rule")
        frame = sel[["radius", "n_pp", "t_window"]].rename(columns={"n_pp": "count"})
        reg = stats.regress_counts(frame, rule=rule)
        regressions[method, rule] = reg
        plots.counts_vs_radius(sel[["radius", "n_pp", "t_window"]], regression=reg, ax=axes[i, j])
        axes[i, j].set_title(f"{rule} rule, {method} ICs")

grid = np.asarray(RADII)
kinetic_slope = np.polyfit(np.log(grid), np.log(stats.kinetic_rate(grid)), 1)[0]
for (method, rule), reg in regressions.items():
    coef = reg.coefficients()
    b, se = coef.loc[("poisson", "log_radius"), ["estimate", "stderr"]]
    bn, sen = coef.loc[("negbin", "log_radius"), ["estimate", "stderr"]]
    od = reg.overdispersion()
    slope_k = np.polyfit(np.log(grid), np.log(stats.kinetic_rate(grid, rule=rule)), 1)[0]
    print(
        f"{method} ICs, {rule}: log-log slope {b:.3f} ± {se:.3f} (Poisson), {bn:.3f} ± {sen:.3f} "
        f"(negative binomial), kinetic {slope_k:.3f}; NB alpha = {od['alpha']:.3g} "
        f"(LR test of alpha = 0: p = {od['lr_pvalue']:.3g}); Poisson Pearson dispersion "
        f"{od['pearson_dispersion']:.2f}"
    )
pred = regressions["uniform", "mirror"].predict(list(RADII), t_window=T)
display(pred)

# %% [markdown]
# ## 8. What the numbers say

# %%
inv_sum = ens_summary.loc["uniform"]
pap_sum = ens_summary.loc["paper"]
lines = [
    f"Size {SIZE!r}: {len(RADII)} radii, {P['n_ics']} ICs per ensemble, T = {T:g}.",
    "1. Simulator check: under the invariant measure the mean counts "
    + ("match" if p_exact > 0.01 else "do NOT match")
    + " Gamma T "
    f"(chi-square over {len(inv)} cells: p = {p_exact:.3g}; largest |z| "
    f"{inv['z'].abs().max():.2f}).",
]
for rule in RULES:
    s_inv, s_pap = inv_sum.loc[rule], pap_sum.loc[rule]
    lines.append(
        f"2. {rule}: ICs rejecting Poisson after FDR, invariant measure "
        + ", ".join(f"r={r:g}: {s_inv.loc[r, 'reject_any_fdr']:.0%}" for r in RADII)
        + "; paper ICs "
        + ", ".join(f"r={r:g}: {s_pap.loc[r, 'reject_any_fdr']:.0%}" for r in RADII)
        + "."
    )
for rule in RULES:
    po = pooled.query("rule == @rule")
    best = po.loc[po.groupby("radius")["delta_aic"].idxmin(), ["radius", "model"]]
    lines.append(
        f"3. {rule}: pooled AIC-best renewal model by radius: "
        + ", ".join(f"r={r:g}: {m}" for r, m in best.itertuples(index=False))
        + "; exponential best per IC for "
        + f"{(per_ic.query('rule == @rule')['best_model'] == 'exponential').mean():.0%} "
        + "of the ICs fitted."
    )
lines.append(
    f"4. Sticky orbits (paper ICs, mirror, r={r_search:g}): {n_sticky}/{P['n_search']} "
    f"({n_sticky / P['n_search']:.2%}); silent: {n_silent}/{P['n_search']}."
)
reg = regressions["uniform", "mirror"]
lines.append(
    f"5. Counts vs radius (invariant, mirror): Poisson log-log slope "
    f"{reg.coefficients().loc[('poisson', 'log_radius'), 'estimate']:.3f} vs kinetic "
    f"{kinetic_slope:.3f}; NB alpha {reg.alpha:.3g}."
)
print("\n".join(lines))
print(f"\nnotebook computed in {time.perf_counter() - t_start:.1f} s")
