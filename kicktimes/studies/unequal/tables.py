"""The unequal-disks study's statistics: per size ratio, the collision rate against the
kinetic rate, the Poisson battery, the rate dispersion across ICs and the kicked / two-disk FTLE
ratios, each with its 95 % bootstrap interval over ICs."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import (
    D_MARGIN,
    kinetic_rate,
    null_verdict,
    percentile_interval,
    poisson_group,
    rejection_verdict,
    resample_indices,
)
from kicktimes.stats.findings import clopper_pearson
from kicktimes.studies.unequal.compute import KINDS, R0

__all__ = ["D_MARGIN", "FINE_MARGIN", "N_NULL", "dispersion_ci", "dispersion_null",
           "ks_interval", "ratio_ci", "size_ratio_table"]

#: Monte Carlo draws of the null of the rate dispersion across ICs (Poisson counts shaped
#: like the runs)
N_NULL = 4000
#: the margin the FTLE ratios must resolve, stated in advance: half the smallest effect
#: the page means to detect, the partner radius of the scattering kicks (own-size against
#: the other disk's size: about 10 % at the largest ratio); `kicktimes.stats.MARGIN`
#: (10 %) is as large as that effect
FINE_MARGIN = 0.05


def dispersion_null(windows, rate, rng, n=N_NULL):
    """The rate dispersion across ICs :math:`s_N^2 / \\bar N` (var / mean of the
    whole-run counts over ICs; not the within-run D of counts in windows) of Poisson counts
    shaped like the runs (one count per run length of ``windows`` at the common ``rate``):
    its mean over ``n`` draws, the value the runs' is read against (`null_verdict`), and
    its 2.5 and 97.5 % percentiles."""
    mean = rate * np.asarray(windows, float)
    counts = rng.poisson(mean, size=(n, mean.size)).astype(float)
    d = counts.var(1, ddof=1) / counts.mean(1)
    lo, hi = percentile_interval(d)
    return float(d.mean()), lo, hi


def ratio_ci(x, y, rng, n_boot=2000):
    """Ratio of means ``sum x / sum y`` and its percentile bootstrap CI over pairs."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    idx = resample_indices(x.size, n_boot=n_boot, rng=rng)
    boot = x[idx].sum(1) / y[idx].sum(1)
    return x.sum() / y.sum(), *np.quantile(boot, [0.025, 0.975])


def dispersion_ci(counts, rng, n_boot=2000):
    """95 % bootstrap interval of the rate dispersion across ICs, var / mean of the counts."""
    counts = np.asarray(counts, float)
    b = counts[resample_indices(counts.size, n_boot=n_boot, rng=rng)]
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
    Three streams from ``seed``, as the published table drew them: one for the battery and
    the ratios (per ratio: the battery, the rate ratio, then the FTLE ratios disk by disk,
    partner before own), one for the dispersion intervals (added to the table later,
    from the same per-IC counts), and one for the null of the rate dispersion across ICs
    (`dispersion_null`), against which it is read (``d_minus_null``, its interval the
    bootstrap interval of the rate dispersion less the null's mean, ``d_verdict`` its
    `null_verdict` with `D_MARGIN`); the KS share has its Clopper-Pearson interval
    (``ks_low``, ``ks_high``) and its `rejection_verdict` against α = 0.05, exact for the
    uniformity test given the number of collisions.
    """
    rng = np.random.default_rng(seed)
    disp_rng = np.random.default_rng(seed)
    null_rng = np.random.default_rng((seed, 1))
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
        # D against its own null (Poisson counts in the same windows at the pooled rate),
        # the KS share against α, which the conditional uniformity test has exactly
        d0, d0_lo, d0_hi = dispersion_null(windows, counts.sum() / np.sum(windows), null_rng)
        row.update({"d_null": d0, "d_null_low": d0_lo, "d_null_high": d0_hi,
                    "d_minus_null": row["dispersion_index"] - d0,
                    "d_minus_null_low": row["disp_low"] - d0,
                    "d_minus_null_high": row["disp_high"] - d0})
        row["d_verdict"] = null_verdict(row["d_minus_null_low"], row["d_minus_null_high"],
                                        margin=D_MARGIN)
        row["ks_low"], row["ks_high"] = clopper_pearson(
            int(round(row["ks_reject_share"] * len(times))), len(times))
        row["ks_verdict"] = rejection_verdict(row["ks_low"], row["ks_high"], alpha=0.05)
        rows.append(row)
    return pd.DataFrame(rows)
