"""The unequal-disks study's statistics: per size ratio, the collision rate against the
kinetic rate, the Poisson battery, the rate dispersion across ICs and the kicked / two-disk FTLE
ratios, each with its 95 % bootstrap interval over ICs."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import (
    D_MARGIN,
    kinetic_rate,
    margin_of,
    null_verdict,
    percentile_interval,
    poisson_group,
    rejection_verdict,
    resample_indices,
)
from kicktimes.stats.findings import clopper_pearson
from kicktimes.studies.unequal.compute import KINDS, R0

__all__ = ["D_MARGIN", "FINE_MARGIN", "KS_NULL_STREAMS", "N_NULL", "RATE_MARGIN", "dispersion_ci",
           "dispersion_null", "ks_interval", "ks_null", "ratio_ci", "size_ratio_table"]

#: Monte Carlo draws of the null of the rate dispersion across ICs (Poisson counts shaped
#: like the runs)
N_NULL = 4000
#: the margin of the FTLE ratios: the FTLE's own, common to every page
#: (`kicktimes.stats.margin_of("ftle")`, fixed before this study; docs/definitions.md)
FINE_MARGIN = margin_of("ftle")
#: the margin of the collision rate over the kinetic rate: the counts' (the README's)
RATE_MARGIN = margin_of("counts")


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


#: Poisson streams per run in the null of the KS rejection share (`ks_null`)
KS_NULL_STREAMS = 20


def ks_null(counts, rng, *, alpha=0.05, n=KS_NULL_STREAMS):
    """The share of Poisson streams shaped like the runs that the uniformity KS rejects at
    ``alpha``: per run ``n`` streams at the run's own rate ``count / window`` over its window,
    i.e. a Poisson number of events of mean ``count`` placed uniformly (the test is the same
    for any window), through `kicktimes.stats.poisson.uniformity_ks`, the test of the
    runs' share, with its
    Clopper-Pearson 95 % interval. The runs' share is read against this level, not against
    ``alpha``: given the number of events the test is exact, so the level is ``alpha`` up
    to Monte Carlo noise, and the table shows it rather than assuming it. A stream with
    fewer than 2 events is not tested (as a run is not).

    Returns ``(share, low, high, n_tested)``.
    """
    from kicktimes.stats.poisson import uniformity_ks

    rejected = tested = 0
    for count in np.asarray(counts, float):
        sizes = rng.poisson(max(count, 1.0), size=n)
        for k in sizes[sizes >= 2]:
            u = np.sort(rng.uniform(0.0, 1.0, size=int(k)))
            rejected += int(uniformity_ks(u)[1] < alpha)
            tested += 1
    low, high = clopper_pearson(rejected, tested)
    return rejected / max(tested, 1), low, high, tested


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
    (``ks_low``, ``ks_high``) and its `rejection_verdict` against the share of Poisson
    streams shaped like the runs that the same test rejects (`ks_null`, a fourth stream:
    ``ks_null``, ``ks_null_low``, ``ks_null_high``).
    """
    rng = np.random.default_rng(seed)
    disp_rng = np.random.default_rng(seed)
    null_rng = np.random.default_rng((seed, 1))
    ks_rng = np.random.default_rng((seed, 2))
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
        level, level_low, level_high, _ = ks_null(counts, ks_rng)
        row.update({"ks_null": level, "ks_null_low": level_low, "ks_null_high": level_high})
        row["ks_verdict"] = rejection_verdict(row["ks_low"], row["ks_high"], alpha=level)
        rows.append(row)
    return pd.DataFrame(rows)
