"""The unequal-disks study's statistics: per size ratio, the collision rate against the
kinetic rate, the Poisson battery, the dispersion index and the kicked / two-disk FTLE
ratios, each with its 95 % bootstrap interval over ICs."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import kinetic_rate, percentile_interval, poisson_group, resample_indices
from kicktimes.stats.findings import clopper_pearson
from kicktimes.studies.unequal.compute import KINDS, R0

__all__ = ["dispersion_ci", "ks_interval", "ratio_ci", "size_ratio_table"]


def ratio_ci(x, y, rng, n_boot=2000):
    """Ratio of means ``sum x / sum y`` and its percentile bootstrap CI over pairs."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    idx = resample_indices(x.size, n_boot, rng)
    boot = x[idx].sum(1) / y[idx].sum(1)
    return x.sum() / y.sum(), *np.quantile(boot, [0.025, 0.975])


def dispersion_ci(counts, rng, n_boot=2000):
    """95 % bootstrap interval over ICs of the dispersion index var / mean of the counts."""
    counts = np.asarray(counts, float)
    b = counts[resample_indices(counts.size, n_boot, rng)]
    return percentile_interval(b.var(1, ddof=1) / b.mean(1))


def ks_interval(row, n):
    """Clopper-Pearson interval of a table row's KS rejection share over ``n`` runs."""
    return clopper_pearson(round(row["ks_reject_share"] * n), n)


def size_ratio_table(runs_by_r1, seed) -> pd.DataFrame:
    """``size_ratio.csv``: one row per size ratio from its `size_ratio_runs` table.

    Parameters
    ----------
    runs_by_r1 : dict
        Disk 1's radius -> its `size_ratio_runs` table, in the order of the rows.
    seed : int
        Seeds the Monte Carlo of the Poisson battery and the bootstraps.

    Notes
    -----
    Two streams from ``seed``, as the published table drew them: one for the battery and
    the ratios (per ratio: the battery, the rate ratio, then the FTLE ratios disk by disk,
    partner before own), and one for the dispersion intervals (added to the table later,
    from the same per-IC counts).
    """
    rng = np.random.default_rng(seed)
    disp_rng = np.random.default_rng(seed)
    rows = []
    for r1, runs in runs_by_r1.items():
        gamma = kinetic_rate((R0, r1))
        times = [np.asarray(t, float) for t in runs["pp_times"]]
        windows = runs["t_max"].to_list()
        counts = np.array([t.size for t in times])
        group = poisson_group(times, windows, rng=rng)
        rej = group.rejections.set_index("test")
        rate_ratio = ratio_ci(counts, gamma * np.asarray(windows), rng)
        row = {"r0": R0, "r1": r1, "size_ratio": r1 / R0, "kinetic_rate": gamma,
               "rate_ratio": rate_ratio[0], "rate_low": rate_ratio[1],
               "rate_high": rate_ratio[2],
               "ks_reject_share": float(rej.loc["uniformity_ks", "rate"]),
               "dispersion_index": float(group.homogeneity["dispersion_index"])}
        for disk in (0, 1):
            lam = runs[f"lam_disk{disk}"].to_numpy()
            for kind in KINDS:
                est, lo, hi = ratio_ci(runs[f"kicked_{kind}_disk{disk}"].to_numpy(), lam, rng)
                row[f"ftle_{kind}_ratio_disk{disk}"] = est
                row[f"ftle_{kind}_low_disk{disk}"] = lo
                row[f"ftle_{kind}_high_disk{disk}"] = hi
            row[f"ftle_two_disk{disk}"] = float(np.mean(lam))
        row["disp_low"], row["disp_high"] = dispersion_ci(counts, disp_rng)
        rows.append(row)
    return pd.DataFrame(rows)
