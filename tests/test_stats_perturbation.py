"""The stretching per perturbation (kicktimes.stats.stretching_per_perturbation)."""

from __future__ import annotations

import numpy as np

from kicktimes import stats


def test_it_is_the_mean_ftle_over_the_pooled_rate():
    # runs of 100 and 300 time units with 10 and 90 perturbations: pooled rate 100/400
    s = stats.stretching_per_perturbation([0.2, 0.4], [10.0, 90.0], [100.0, 300.0])
    assert s == (0.2 + 0.4) / 2 / (100.0 / 400.0)


def test_a_missing_value_is_left_out_and_no_perturbation_gives_nan():
    s = stats.stretching_per_perturbation([0.3, np.nan], [20.0, np.nan], [100.0, np.nan])
    assert s == 0.3 / 0.2
    assert np.isnan(stats.stretching_per_perturbation([0.3], [0.0], [100.0]))


def test_resamples_along_the_last_axis_give_one_value_each():
    rng = np.random.default_rng(1)
    lam, n, t = rng.uniform(0.1, 1, 20), rng.poisson(30, 20).astype(float), np.full(20, 50.0)
    idx = stats.resample_indices(20, n_boot=7, rng=2, with_identity=True)
    s = stats.stretching_per_perturbation(lam[idx], n[idx], t[idx])
    assert s.shape == (8,)
    assert s[0] == stats.stretching_per_perturbation(lam, n, t)
    for b in range(8):
        assert s[b] == np.mean(lam[idx[b]]) / (n[idx[b]].sum() / t[idx[b]].sum())
