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
# # From two disks to a gas
#
# Two hard disks in a circular table collide at times that are far from Poisson under the
# paper's mirror rule: the disks' conserved state sets a rate that every collision resets,
# and a disk returns after a round trip to the wall. In a dilute gas, molecular chaos makes
# a tagged disk's collisions uncorrelated, yet its rate still depends on its speed
# (Visco, van Wijland & Trizac 2008). This notebook follows a tagged disk from N = 2 disks
# to a gas with the N-disk engine (`kicktimes.simulate_disks`):
#
# 1. a `DisksExperiment` sweep over N at a fixed packing, under both rules, into a store;
# 2. the collision frequency against Enskog–Henderson kinetic theory;
# 3. the Poisson battery on each tagged disk's first K collisions, and the index of
#    dispersion of their counts;
# 4. the hazard of the next collision against the time since the last one;
# 5. under the elastic rule, the speed-conditioned rescaling: how much of the non-Poisson
#    statistics the speed carries.
#
# Every conclusion is printed from the computed table through the verdict rules of
# `kicktimes.stats`.
#
# **Size.** `KICKTIMES_NOTEBOOK_SIZE`: `"small"` (default; N = 2, 10, 100 with 60 tagged
# disks each (at least 4 runs), seconds once the engine is compiled), `"test"` (N = 2, 10
# with 20 tagged disks: what the default test suite runs) or `"full"`
# (the presets of docs/results/disks.md at packing 0.2: N = 2 .. 1000, about 4000 tagged
# disks per N; a few minutes).

# %%
import os
import tempfile
import time

import matplotlib.pyplot as plt
import pandas as pd
from IPython.display import display

from kicktimes.experiment import DISKS_PRESETS, DisksExperiment, run_experiment
from kicktimes.stats import format_interval
from kicktimes.studies.disks import (
    disks_hazard,
    disks_table,
    hazard_figure,
    rates_figure,
    rejection_figure,
)
from kicktimes.studies.disks.versus_null import versus_null

# %matplotlib inline
SIZE = os.environ.get("KICKTIMES_NOTEBOOK_SIZE", "small")
if SIZE not in ("test", "small", "full"):
    raise ValueError(f"KICKTIMES_NOTEBOOK_SIZE must be 'test', 'small' or 'full', got {SIZE!r}")
t_start = time.perf_counter()
if SIZE in ("test", "small"):
    n_disks, n_tagged, min_runs = ((2, 10), 20, 2) if SIZE == "test" else ((2, 10, 100), 60, 4)
    experiments = [DisksExperiment(name=f"gas-{rule}", n_disks=n_disks, packing=0.2,
                                   rule=rule, n_tagged=n_tagged, min_runs=min_runs, seed=1)
                   for rule in ("mirror", "elastic")]
else:
    experiments = [DISKS_PRESETS["disks-phi0.2-mirror"], DISKS_PRESETS["disks-phi0.2-elastic"]]
for exp in experiments:
    print(exp.summary())

# %% [markdown]
# ## 1. The sweeps
#
# Each N gets independent runs from equilibrated states (`kicktimes.initial_state`); a few
# disks of each run are tagged and their collision times stored, with, under the elastic
# rule, the speed of each interval (read from position samples). The store resumes like
# every kicktimes sweep.

# %%
folder = tempfile.mkdtemp()
stores = [run_experiment(exp, os.path.join(folder, exp.name), workers=1, progress=False)
          for exp in experiments]
stores[0].collisions.head()

# %% [markdown]
# ## 2.–5. The table: one row per (rule, N)

# %%
table = pd.concat([disks_table(st, n_boot=499, n_mc=199) for st in stores], ignore_index=True)
hazard = pd.concat([disks_hazard(st) for st in stores], ignore_index=True)
# D is read against its null stream's D (Poisson at each run's rate, shaped like the runs),
# never against 1: `versus_null` pairs the two by run
null = pd.concat([versus_null(st, n_boot=199)[0] for st in stores], ignore_index=True)
cols = ["rule", "n_disks", "rate_enskog", "rate_enskog_verdict", "reject_uniformity_ks",
        "hazard_first"]
display(table[cols].round(3))
display(null[["rule", "n_disks", "d", "null_d", "d_diff", "d_verdict"]].round(3))

# %%
fig = rates_figure(table)
plt.show()

# %%
fig = rejection_figure(table)
plt.show()

# %%
fig = hazard_figure(hazard, table, n_shown=tuple(n for n in (2, 3, 10, 100, 1000)
                                                 if n in set(table["n_disks"])))
plt.show()

# %% [markdown]
# ## What the numbers say

# %%
lines = []
for row, d in zip(table.itertuples(index=False), null.itertuples(index=False), strict=True):
    r = row._asdict()
    text = (f"{r['rule']}, N = {r['n_disks']}: rate/Enskog "
            f"{format_interval(r['rate_enskog'], r['rate_enskog_low'], r['rate_enskog_high'])}"
            f" ({r['rate_enskog_verdict']}); uniform-times rejections "
            f"{100 * r['reject_uniformity_ks']:.1f} % [{100 * r['reject_uniformity_ks_low']:.1f},"
            f" {100 * r['reject_uniformity_ks_high']:.1f}] % (the null streams': "
            f"{100 * d.null_ks:.1f} %); D = {format_interval(d.d, d.d_low, d.d_high)}, its "
            f"null {d.null_d:.3g}: D − null D "
            f"{format_interval(d.d_diff, d.d_diff_low, d.d_diff_high, edges=())} ({d.d_verdict})")
    lines.append(text)
print("\n".join(lines))
print(f"\nnotebook computed in {time.perf_counter() - t_start:.1f} s")
