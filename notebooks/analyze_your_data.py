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
# # Analyse your own collision times
#
# kicktimes' statistics work on any event times, not only on its own simulations. The input
# is a tidy table, one row per event: a `sequence` id and a `time`; each sequence needs an
# observation window `[t_start, t_end]` (columns, a second table, or one window for all),
# and may carry covariates (radius, density, temperature, ...).
#
# This notebook
#
# 1. builds such a table from synthetic sequences with known properties,
# 2. shows the one-line errors bad input gets,
# 3. runs `kicktimes.stats.analyze` and reads its findings and tables,
# 4. writes the HTML page of `kicktimes analyze`,
# 5. if the `billiards` package is installed (`pip install kicktimes[outside]`), analyses
#    collision times of disks in a box from that independent simulator, against the 2D
#    kinetic-theory (Enskog) rate.
#
# **Size.** `KICKTIMES_NOTEBOOK_SIZE`: `small` (default), `test` (fewer and shorter
# sequences: what the default test suite runs) or `full`.

# %%
import os
import tempfile
import time

import numpy as np
import pandas as pd

from kicktimes import stats
from kicktimes.report.analyze_page import write_analysis

SIZE = os.environ.get("KICKTIMES_NOTEBOOK_SIZE", "small")
SIZES = {"test": (4, 60.0), "small": (6, 100.0), "full": (40, 1000.0)}  # sequences per group, T
if SIZE not in SIZES:
    raise ValueError(f"KICKTIMES_NOTEBOOK_SIZE must be one of {sorted(SIZES)}, got {SIZE!r}")
N_PER_GROUP, T_END = SIZES[SIZE]
SMALL = SIZE != "full"
rng = np.random.default_rng(2024)
t_start = time.perf_counter()

# %% [markdown]
# ## 1. A tidy table
# Two kinds of sequences at two "densities": Poisson sequences whose rate is proportional
# to the density, and nearly regular ones (gamma intervals of shape 4). The window table
# also lists one sequence that saw no event at all: it counts (a zero is an observation).

# %%
rows, windows = [], []
for density in (1.0, 2.0):
    for k in range(N_PER_GROUP):
        name = f"poisson-d{density:g}-{k}"
        t = np.sort(rng.uniform(0, T_END, rng.poisson(density * T_END)))
        rows += [(name, x) for x in t]
        windows.append((name, 0.0, T_END, density, 0))
for k in range(N_PER_GROUP):
    name = f"regular-{k}"
    t = np.cumsum(rng.gamma(4.0, 1 / 4.0, size=int(1.5 * T_END)))
    rows += [(name, x) for x in t[t < T_END]]
    windows.append((name, 0.0, T_END, 1.0, 1))
windows.append(("silent", 0.0, T_END, 1.0, 0))
events = pd.DataFrame(rows, columns=["sequence", "time"])
windows = pd.DataFrame(windows, columns=["sequence", "t_start", "t_end", "density", "regular"])
events.head()

# %% [markdown]
# ## 2. Bad input: one line naming the column and the row

# %%
bad = events.copy()
bad.loc[3, "time"] = bad.loc[2, "time"]  # a repeated time
for label, frame, kwargs in [
    ("duplicate time", bad, {"windows": windows}),
    ("time outside the window", events, {"window": (0.0, T_END / 2)}),
    ("no window at all", events, {}),
]:
    try:
        stats.analyze(frame, **kwargs)
    except ValueError as exc:
        print(f"{label}: {exc}")

# %% [markdown]
# ## 3. The analysis
# Grouped by the `regular` flag: group 0 holds the Poisson sequences (and the silent one),
# group 1 the regular ones. The count regressions use every numeric covariate.

# %%
res = stats.analyze(events, windows=windows, group="regular", rng=1, max_fits_per_group=3)
print(res.summary())

# %%
res.poisson.pivot(index="test", columns="group", values="combined_pvalue")

# %%
res.renewal_pooled[["group", "model", "delta_aic", "weight"]]

# %%
res.regressions.query("term == 'slope'")

# %%
res.skipped.head(10)

# %% [markdown]
# ## 4. The page `kicktimes analyze` writes
# The same as `kicktimes analyze events.csv --windows windows.csv --group regular --out DIR`.

# %%
out = tempfile.mkdtemp()
path = write_analysis(res, out, dpi=60)
sorted(os.listdir(out))[:8]

# %% [markdown]
# ## 5. An outside simulator: disks in a box (`billiards` package)
# `analysis/outside_billiards.py` runs the GPL `billiards` package (imported, not copied),
# converts its collision log to one sequence per disk and gives each sequence the
# kinetic-theory rate per disk as a covariate (the 2D Enskog frequency
# $2 n\sigma g(\sigma)\langle|v_{rel}|\rangle$ with the walls and the finite number of
# disks kept; see the script's notes). `reference="kinetic_rate"` compares the observed
# rates with it.

# %%
try:
    import billiards  # noqa: F401

    HAVE_BILLIARDS = True
except ImportError:
    HAVE_BILLIARDS = False
    print("billiards is not installed: pip install kicktimes[outside]")

if HAVE_BILLIARDS:
    import importlib.util
    from pathlib import Path

    here = Path.cwd() if (Path.cwd() / "analysis").is_dir() else Path.cwd().parent
    script = next(
        (
            p / "analysis" / "outside_billiards.py"
            for p in (here, *here.parents)
            if (p / "analysis" / "outside_billiards.py").is_file()
        ),
        None,
    )
    if script is None:  # the notebook runs outside the repository
        import kicktimes

        script = Path(kicktimes.__file__).parents[1] / "analysis" / "outside_billiards.py"
    spec = importlib.util.spec_from_file_location("outside_billiards", script)
    outside = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(outside)
    ev, seqs = outside.generate(
        boxes=(0.45, 0.95) if SMALL else (0.45, 0.65, 0.95, 1.4),
        n_runs=1 if SMALL else 4,
        collisions_per_disk=60.0 if SMALL else 1000.0,
    )
    box = stats.analyze(
        ev,
        windows=seqs,
        covariates=["density", "kinetic_rate"],
        group="density",
        reference="kinetic_rate",
        rng=0,
        max_fits_per_group=2,
    )
    print(box.summary())

# %%
print(f"\nnotebook computed in {time.perf_counter() - t_start:.1f} s")
