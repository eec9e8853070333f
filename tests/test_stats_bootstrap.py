"""The bootstrap clustered on runs (kicktimes.stats.bootstrap): the draws, the interval,
its coverage on data with a known answer, and bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from kicktimes import stats


def test_the_indices_are_the_generators_integers_with_the_identity_first():
    idx = stats.resample_indices(7, n_boot=50, rng=np.random.default_rng(3))
    np.testing.assert_array_equal(idx, np.random.default_rng(3).integers(0, 7, size=(50, 7)))
    with_id = stats.resample_indices(7, n_boot=50, rng=3, with_identity=True)
    np.testing.assert_array_equal(with_id[0], np.arange(7))
    np.testing.assert_array_equal(with_id[1:], idx)
    assert idx.min() >= 0 and idx.max() <= 6


def test_chunks_draw_the_same_stream_when_chunk_times_n_is_even():
    whole = stats.resample_indices(6, n_boot=25, rng=1)
    np.testing.assert_array_equal(stats.resample_indices(6, n_boot=25, rng=1, chunk=4), whole)
    # an odd chunk * n splits numpy's pairs of 32-bit draws: chunk is part of the definition
    one_at_a_time = stats.resample_indices(5, n_boot=4, rng=2, chunk=1)
    rng = np.random.default_rng(2)
    np.testing.assert_array_equal(one_at_a_time, [rng.integers(0, 5, 5) for _ in range(4)])


def test_the_percentile_interval_is_numpys_over_the_finite_replicates():
    rng = np.random.default_rng(4)
    v = rng.normal(size=1001)
    lo, hi = stats.percentile_interval(np.append(v, [np.nan, np.inf]), level=0.9)
    a = (1 - 0.9) / 2 * 100  # the documented formula, to the last bit
    assert (lo, hi) == (np.percentile(v, a), np.percentile(v, 100 - a))
    assert np.isnan(stats.percentile_interval([np.nan, np.inf])).all()


def test_the_interval_covers_a_known_mean_at_its_level():
    # clustered data: each run's value is the mean of its own 20 exponential events, so the
    # true mean is 1; 400 experiments of 60 runs, 95 % intervals: coverage 0.95 +- 3 SE
    rng = np.random.default_rng(5)
    hits = 0
    for _ in range(400):
        runs = rng.exponential(1.0, size=(60, 20)).mean(axis=1)
        res = stats.cluster_bootstrap(lambda idx, x=runs: x[idx].mean(axis=1), runs.size,
                                      n_boot=399, rng=rng)
        hits += res.ci_low <= 1.0 <= res.ci_high
    se = np.sqrt(0.95 * 0.05 / 400)
    assert abs(hits / 400 - 0.95) < 3 * se + 0.01  # the percentile interval's small-n bias


def test_a_paired_ratio_keeps_the_pairing():
    rng = np.random.default_rng(6)
    y = rng.exponential(1.0, 40)
    exact = stats.ratio_of_means(2.0 * y, y, rng=0)
    assert (exact.estimate, exact.ci_low, exact.ci_high) == (2.0, 2.0, 2.0)
    noisy = stats.ratio_of_means(2.0 * y + rng.normal(0, 0.1, 40), y, n_boot=499, rng=1)
    assert noisy.ci_low < noisy.estimate < noisy.ci_high
    assert 1.8 < noisy.ci_low and noisy.ci_high < 2.2
    assert "percentile interval, 499 resamples of 40 clusters" in noisy.summary()


def test_several_statistics_are_resampled_together():
    x = np.arange(10.0)
    res = stats.cluster_bootstrap(
        lambda idx: np.stack([x[idx].mean(axis=1), 2 * x[idx].mean(axis=1)], axis=1),
        x.size, n_boot=200, rng=2)
    np.testing.assert_allclose(res.estimate, [4.5, 9.0])
    np.testing.assert_allclose(res.replicates[:, 1], 2 * res.replicates[:, 0])
    np.testing.assert_allclose(res.ci_high, [res.ci_high[0], 2 * res.ci_high[0]])


@pytest.mark.parametrize("kwargs, match", [
    ({"n_clusters": 0}, "n_clusters"),
    ({"n_boot": 0}, "n_boot"),
    ({"level": 1.5}, "level"),
    ({"chunk": 0}, "chunk"),
    ({"rng": -1}, "rng"),
])
def test_bad_arguments_are_refused_naming_them(kwargs, match):
    args = {"n_clusters": 5, "n_boot": 10, "rng": 0} | kwargs
    with pytest.raises(ValueError, match=match):
        stats.cluster_bootstrap(lambda idx: idx.mean(axis=1), args.pop("n_clusters"), **args)
    with pytest.raises(ValueError, match="same length"):
        stats.ratio_of_means([1.0, 2.0], [1.0])


def test_the_counts_are_the_generators_multinomial_and_count_like_the_indices():
    counts = stats.resample_counts(9, n_boot=300, rng=4)
    ref = np.random.default_rng(4).multinomial(9, np.full(9, 1 / 9), size=300)
    np.testing.assert_array_equal(counts, ref)
    assert counts.dtype == float and (counts.sum(axis=1) == 9).all()
    # the same law as the indices: each cluster is drawn once per resample on average
    assert abs(counts.mean() - 1.0) < 1e-12
    idx = stats.resample_indices(9, n_boot=300, rng=5)
    assert abs(np.bincount(idx.ravel(), minlength=9).mean() / 300 - 1.0) < 1e-12


def test_no_resample_is_an_empty_array_and_draws_nothing():
    rng = np.random.default_rng(8)
    assert stats.resample_counts(5, n_boot=0, rng=rng).shape == (0, 5)
    assert stats.resample_indices(5, n_boot=0, rng=rng).shape == (0, 5)
    assert stats.resample_indices(5, n_boot=0, rng=rng, chunk=2, with_identity=True).shape == (1, 5)
    assert rng.integers(0, 100) == np.random.default_rng(8).integers(0, 100)


@pytest.mark.parametrize("shape", [(200, 300), (999, 7), (40, 5, 4), (1000, 1)])
def test_the_all_finite_fast_path_is_nanpercentile_to_the_bit(shape):
    from kicktimes.stats import percentile_interval

    rng = np.random.default_rng(len(shape))
    v = rng.standard_normal(shape) * 1e3
    for axis in range(v.ndim):
        low, high = percentile_interval(v, axis=axis)
        ref_low, ref_high = np.nanpercentile(v, [2.5, 97.5], axis=axis)
        assert np.array_equal(low, ref_low) and np.array_equal(high, ref_high)
    w = v.copy()
    w.flat[::7] = np.nan  # the slow path keeps dropping the non-finite replicates
    low, high = percentile_interval(w, axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a column of NaN only (flat[::7])
        ref_low, ref_high = np.nanpercentile(w, [2.5, 97.5], axis=0)
    np.testing.assert_array_equal(low, ref_low)
    np.testing.assert_array_equal(high, ref_high)
