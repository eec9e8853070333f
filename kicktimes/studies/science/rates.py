"""The collision rate over the run and the sticky orbits, from the paper study's stores.

`rate_relaxation`: the ensemble disk-disk collision rate of the paper's ICs over the
kinetic rate Gamma(r), per time window and per radius over the whole run, with bootstrap
intervals over ICs and their `ratio_verdict`; `sticky_orbits`: the runs whose rate
exceeds `STICKY_FACTOR` Gamma(r) and the initial angular momenta of their ICs.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes import initial_conditions
from kicktimes.stats import (
    COUNTS_MARGIN,
    STICKY_FACTOR,
    is_sticky,
    kinetic_rate,
    percentile_interval,
    ratio_verdict,
    resample_indices,
)
from kicktimes.studies.science.stretching import N_BOOT

__all__ = ["STICKY_FACTOR", "rate_relaxation", "sticky_orbits"]


def rate_relaxation(store, n_windows=10, n_boot=N_BOOT, seed=0, *, exclude_sticky=False):
    """Ensemble collision rate over the kinetic rate: per time window (the relaxation)
    and per radius over the whole run (count / Gamma(r) T) with a bootstrap interval over
    ICs and its `ratio_verdict` at the counts' margin `COUNTS_MARGIN`; with
    ``exclude_sticky`` the sticky runs (rate above
    `STICKY_FACTOR` Gamma(r), `kicktimes.stats.is_sticky`, as `sticky_orbits` counts them)
    are left out first, the control of the README's counts."""
    coll = store.collisions
    if exclude_sticky:
        gamma = np.array([kinetic_rate(float(r)) for r in coll["radius"]])
        coll = coll[~is_sticky(coll["n_pp"].to_numpy(float) / coll["t_window"].to_numpy(float),
                               gamma, factor=STICKY_FACTOR)]
    rows, whole = [], []
    rng = np.random.default_rng(seed)
    boot_sum, est_sum, n_r = np.zeros((n_boot, n_windows)), np.zeros(n_windows), 0
    for r, part in coll.groupby("radius", observed=True):
        t_end = float(part["t_window"].min())
        edges = np.linspace(0.0, t_end, n_windows + 1)
        per_ic = np.array([np.histogram(np.asarray(times, float), bins=edges)[0]
                           for times in part["pp_times"]], float)      # (ICs, windows)
        counts = per_ic.sum(0)
        width = edges[1] - edges[0]
        gamma = kinetic_rate(float(r))
        picks = resample_indices(len(per_ic), n_boot=n_boot, rng=rng)
        boot_sum += per_ic[picks].mean(1) / width / gamma
        est_sum += counts / (len(part) * width) / gamma
        n_r += 1
        for k in range(n_windows):
            rows.append({"family": store.experiment.name, "radius": r, "window": k,
                         "t_mid": 0.5 * (edges[k] + edges[k + 1]),
                         "rate_over_kinetic": counts[k] / (len(part) * width) / gamma})
        n = part["n_pp"].to_numpy(float)
        t = part["t_window"].to_numpy(float)
        picks = resample_indices(n.size, n_boot=n_boot, rng=rng)
        lo, hi = percentile_interval(n[picks].sum(1) / t[picks].sum(1) / gamma)
        whole.append({"family": store.experiment.name, "radius": r,
                      "count_over_kinetic": n.sum() / t.sum() / gamma, "ci_low": lo,
                      "ci_high": hi, "verdict": ratio_verdict(lo, hi, tolerance=COUNTS_MARGIN)})
    windows = []
    for k in range(n_windows):
        lo, hi = percentile_interval(boot_sum[:, k] / n_r)
        windows.append({"family": store.experiment.name, "window": k,
                        "rate_over_kinetic": est_sum[k] / n_r, "ci_low": lo, "ci_high": hi,
                        "verdict": ratio_verdict(lo, hi, tolerance=COUNTS_MARGIN)})
    return pd.DataFrame(rows), pd.DataFrame(whole), pd.DataFrame(windows)


def sticky_orbits(store):
    """The sticky runs (two-disk rate above STICKY_FACTOR Gamma) and their ICs' angular
    momenta L = x v_y - y v_x of both disks, against all ICs."""
    exp = store.experiment
    coll = store.collisions.copy()
    coll["rate_over_kinetic"] = [n / t / kinetic_rate(float(r)) for n, t, r in
                                 zip(coll["n_pp"], coll["t_window"], coll["radius"],
                                     strict=True)]
    # the one sticky rule (`kicktimes.stats.is_sticky`), as `rate_relaxation` leaves them out
    coll["sticky"] = is_sticky(coll["rate_over_kinetic"].to_numpy(float), 1.0,
                               factor=STICKY_FACTOR)
    ics = initial_conditions(exp.n_ics, exp.r_max, rng=exp.seed, method=exp.ic_method,
                             rule=exp.rule)
    ang = np.abs(ics[:, :, 0] * ics[:, :, 3] - ics[:, :, 1] * ics[:, :, 2])  # (n, 2)
    coll["max_abs_L"] = ang.max(axis=1)[coll["ic"].to_numpy()]
    sticky = coll[coll["sticky"]]
    interval = (sticky["t_window"] / sticky["n_pp"]).median() if len(sticky) else math.nan
    return {
        "family": exp.name,
        "n_runs": len(coll),
        "n_sticky": int(coll["sticky"].sum()),
        "share_runs": float(coll["sticky"].mean()),
        "n_ics_sticky": int(sticky["ic"].nunique()),
        "median_max_abs_L_sticky": float(sticky["max_abs_L"].median()) if len(sticky) else
        math.nan,
        "median_max_abs_L_all": float(np.median(ang.max(axis=1))),
        "share_all_ics_below_sticky_max": float(
            (ang.max(axis=1) <= sticky["max_abs_L"].max()).mean()) if len(sticky) else math.nan,
        "median_interval_sticky": float(interval),
    }
