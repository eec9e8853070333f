"""Poisson / IID tests of event sequences and ensembles (kicktimes.stats)."""

from __future__ import annotations

import inspect
import math

import numpy as np
import pandas as pd
import pytest
import scipy.stats
from _references import ljung_box_numpy
from statsmodels.sandbox.stats.runs import runstest_1samp
from statsmodels.stats.diagnostic import acorr_ljungbox

from kicktimes import stats
from kicktimes.stats import iid_tests

T = 100.0


def poisson_sequences(k, rate, rng, t_window=T):
    return [np.sort(rng.uniform(0, t_window, rng.poisson(rate * t_window))) for _ in range(k)]


def renewal_sequences(draw, k, t_window=T):
    """Renewal processes with a renewal at 0; ``draw(size)`` gives unit-mean intervals."""
    out = []
    for _ in range(k):
        t = np.cumsum(draw(int(3 * t_window) + 50))
        assert t[-1] > t_window
        out.append(t[t <= t_window])
    return out


def ear1_sequences(k, rho, rng, t_window=T):
    """Exponential autoregressive EAR(1) intervals (Gaver & Lewis): Exp(1) marginals,
    lag-k correlation rho**k, so only the serial-dependence tests can see them."""
    out = []
    for _ in range(k):
        t = np.cumsum(stats.ear1_intervals(int(3 * t_window) + 50, rho, rng=rng))
        out.append(t[t <= t_window])
    return out


def rejection_rates(sequences, rng, **kw):
    ens = stats.test_poisson_ensemble(sequences, T, rng=rng, **kw)
    p = ens.per_sequence[[f"p_{name}" for name in stats.TESTS]]
    return (p < 0.05).mean().rename(lambda c: c[2:])


# --- intervals ---------------------------------------------------------------------------


def test_intervals_drop_the_forward_recurrence_time_and_censor_the_last_one():
    iv = stats.intervals_from_times([1.0, 1.5, 3.0], 4.0)
    np.testing.assert_allclose(iv.complete, [0.5, 1.5])
    np.testing.assert_allclose(iv.censored, [1.0])
    kept = stats.intervals_from_times([1.0, 1.5, 3.0], 4.0, first="keep")
    np.testing.assert_allclose(kept.complete, [1.0, 0.5, 1.5])
    end = stats.intervals_from_times([1.0, 4.0], 4.0)
    np.testing.assert_allclose(end.complete, [3.0])
    assert end.censored.size == 0  # an event at T leaves no censored interval


def test_intervals_still_unpack_for_one_release_with_a_deprecation_warning():
    iv = stats.intervals_from_times([1.0, 4.0], 4.0)
    with pytest.warns(DeprecationWarning, match=r"\.complete, \.censored"):
        complete, censored = iv
    with pytest.warns(DeprecationWarning, match="Intervals as a tuple"):
        assert iv[0] is iv.complete and len(iv) == 2
    np.testing.assert_allclose(complete, [3.0])
    assert censored is iv.censored


def test_intervals_of_empty_windows_and_of_ensembles():
    assert stats.intervals_from_times([], 5.0).complete.size == 0
    assert stats.intervals_from_times([], 5.0).censored.size == 0
    np.testing.assert_allclose(stats.intervals_from_times([], 5.0, first="keep").censored, [5.0])
    pooled = stats.intervals_from_times([[1.0, 2.0], [0.5, 2.5, 3.0]], [3.0, 4.0])
    np.testing.assert_allclose(pooled.complete, [1.0, 2.0, 0.5])
    np.testing.assert_allclose(pooled.censored, [1.0, 1.0])


@pytest.mark.parametrize(
    ("times", "window", "match"),
    [
        ([2.0, 1.0], 5.0, "strictly increasing"),
        ([1.0, 1.0], 5.0, "strictly increasing"),
        ([1.0, 6.0], 5.0, "window"),
        ([-1.0, 1.0], 5.0, "window"),
        ([1.0, np.nan], 5.0, "finite"),
        ([1.0], -5.0, "t_window"),
        ([1.0], np.inf, "t_window"),
    ],
)
def test_bad_event_times_are_rejected_with_a_clear_message(times, window, match):
    with pytest.raises(ValueError, match=match):
        stats.intervals_from_times(times, window)
    with pytest.raises(ValueError, match=match):
        stats.test_poisson(times, window)


def test_bad_options_are_rejected():
    t = np.sort(np.random.default_rng(0).uniform(0, T, 100))
    with pytest.raises(ValueError, match="first"):
        stats.intervals_from_times(t, T, first="censor")
    with pytest.raises(ValueError, match="n_mc"):
        stats.test_poisson(t, T, n_mc=5)
    with pytest.raises(ValueError, match=r"n_mc must be an integer in \[19, 10000000\]"):
        stats.test_poisson(t, T, n_mc=10**9)  # a null held whole in memory: 7.5 GiB
    with pytest.raises(ValueError, match="lags"):
        stats.test_poisson(t, T, lags=0)
    with pytest.raises(TypeError, match="rng"):
        stats.test_poisson(t, T, rng=1.5)
    with pytest.raises(ValueError, match="windows"):
        stats.test_poisson_ensemble([t, t], [T, T, T])
    with pytest.raises(ValueError, match="combine"):
        stats.test_poisson_ensemble([t], T, combine="average")
    with pytest.raises(ValueError, match="sequences"):
        stats.test_poisson_ensemble([], T)


# --- single sequence ---------------------------------------------------------------------


def test_too_few_events_give_nan_rows_with_a_reason_not_a_crash():
    res = stats.test_poisson([1.0, 2.0, 3.5], 10.0, rng=0)
    assert list(res.index) == list(stats.TESTS)
    assert not math.isnan(res.loc["uniformity_ks", "pvalue"])
    for name in ("exponential_ks", "ljung_box", "runs", "dispersion"):
        assert math.isnan(res.loc[name, "pvalue"])
        assert "needs at least" in res.loc[name, "note"]
    empty = stats.test_poisson([], 10.0, rng=0)
    assert empty["pvalue"].isna().all()
    assert (empty["note"] == "no events in the window").all()


def test_statistics_agree_with_scipy_and_statsmodels():
    rng = np.random.default_rng(1)
    t = np.sort(rng.uniform(0, T, 120))
    res = stats.test_poisson(t, T, rng=2)
    x = np.diff(t)
    ks = scipy.stats.kstest(t / T, "uniform")
    assert res.loc["uniformity_ks", "statistic"] == pytest.approx(ks.statistic)
    assert res.loc["uniformity_ks", "pvalue"] == pytest.approx(ks.pvalue, rel=1e-6)
    lags = res.attrs["lags"]
    lb = acorr_ljungbox(x, lags=[lags])["lb_stat"].iloc[0]
    assert res.loc["ljung_box", "statistic"] == pytest.approx(lb)
    lil = scipy.stats.kstest(x, scipy.stats.expon(scale=x.mean()).cdf).statistic
    assert res.loc["exponential_ks", "statistic"] == pytest.approx(lil)
    assert res.loc["exponential_ad", "statistic"] == pytest.approx(
        iid_tests.exponential_ad(x[None])[0]
    )
    counts = np.histogram(t, bins=res.attrs["n_bins"], range=(0, T))[0]
    assert res.loc["dispersion", "statistic"] == pytest.approx(counts.var(ddof=1) / counts.mean())
    laplace = (t.mean() / T - 0.5) * math.sqrt(12 * t.size)
    assert res.loc["laplace_trend", "statistic"] == pytest.approx(laplace)
    # The runs p-value is exact; statsmodels' normal approximation is close to it.
    exact = stats.test_poisson(t, T, rng=2, randomize=False).loc["runs", "pvalue"]
    assert exact == pytest.approx(runstest_1samp(x, cutoff="median")[1], abs=0.08)


def test_anderson_darling_statistic_matches_scipy():
    x = np.random.default_rng(3).exponential(2.0, 80)
    # scipy >= 1.17 asks for the p-value method (a FutureWarning without it); before, none
    method = ({"method": "interpolate"}
              if "method" in inspect.signature(scipy.stats.anderson).parameters else {})
    ad = scipy.stats.anderson(x, "expon", **method).statistic
    assert iid_tests.exponential_ad(x[None])[0] == pytest.approx(ad)


@pytest.mark.parametrize("m", [6, 7, 8, 9, 15, 16, 17, 127, 128, 129, 130, 300, 1031])
def test_compiled_ljung_box_is_bitwise_the_numpy_expression(m):
    # numpy sums rows pairwise (blocks of <= 128 on 8 accumulators, recursive halving
    # beyond): the kernel must follow it on both sides of every block boundary
    rng = np.random.default_rng(m)
    x = rng.standard_exponential((5, m)) * 10.0 ** rng.uniform(-3, 3, (5, m))
    for lags in (1, 3, 5):
        got = iid_tests.ljung_box(x, lags)
        assert np.array_equal(got, ljung_box_numpy(x, lags))
        assert iid_tests.ljung_box(x[2], lags) == ljung_box_numpy(x[2], lags)
    assert np.isnan(iid_tests.ljung_box(np.full((2, m), 0.5), 2)).all()  # constant rows


def test_runs_null_law_is_normalised_and_matches_permutations():
    r, pmf = iid_tests.runs_pmf(12, 9)
    assert pmf.sum() == pytest.approx(1.0)
    rng = np.random.default_rng(4)
    labels = np.array([1] * 12 + [0] * 9)
    sims = np.array([1 + np.count_nonzero(np.diff(rng.permutation(labels))) for _ in range(20000)])
    empirical = np.array([np.mean(sims == v) for v in r])
    assert np.abs(empirical - pmf).max() < 0.01
    mean = 1 + 2 * 12 * 9 / 21
    assert (r * pmf).sum() == pytest.approx(mean)


def test_randomised_pvalues_of_discrete_statistics_have_exact_size():
    rng = np.random.default_rng(5)
    # A very discrete statistic: values 0..3 only.
    null = rng.integers(0, 4, 999).astype(float)
    obs = rng.integers(0, 4, 20000).astype(float)
    p_rand = iid_tests.mc_pvalue(obs, null, u=rng.uniform(size=obs.size))
    p_cons = iid_tests.mc_pvalue(obs, null)
    assert np.mean(p_rand <= 0.1) == pytest.approx(0.1, abs=0.012)
    assert np.mean(p_cons <= 0.1) < 0.02  # the conservative p-value wastes the level
    two = iid_tests.mc_pvalue(obs, null, two_sided=True, u=rng.uniform(size=obs.size))
    assert np.mean(two <= 0.2) == pytest.approx(0.2, abs=0.015)
    # Runs: the randomised exact p-value is uniform.
    r, pmf = iid_tests.runs_pmf(20, 20)
    draws = rng.choice(r, size=20000, p=pmf)
    p = np.array([iid_tests.runs_pvalue(v, 20, 20, rng.uniform()) for v in draws])
    assert np.mean(p <= 0.05) == pytest.approx(0.05, abs=0.006)


# --- size and power ------------------------------------------------------------------------


def test_every_test_holds_its_size_on_poisson_sequences():
    rng = np.random.default_rng(6)
    k = 800
    rates = rejection_rates(poisson_sequences(k, 1.0, rng), rng)
    se = math.sqrt(0.05 * 0.95 / k)
    for name, rate in rates.items():
        assert abs(rate - 0.05) < 3 * se, (name, rate)


@pytest.mark.slow
def test_every_test_holds_its_size_on_many_poisson_sequences():
    rng = np.random.default_rng(7)
    k = 10000
    # Separate calls of 1000 sequences: fresh Monte Carlo nulls keep replicates
    # nearly independent, so the binomial standard error applies.
    rates = (
        sum(rejection_rates(poisson_sequences(1000, 1.0, rng), rng, n_mc=1999) for _ in range(10))
        / 10
    )
    se = math.sqrt(0.05 * 0.95 / k)
    for name, rate in rates.items():
        assert abs(rate - 0.05) < 3 * se, (name, rate)


def test_size_holds_for_short_sequences_too():
    # About 25 events: the conditional Monte Carlo nulls are exact at any n.
    rng = np.random.default_rng(8)
    seqs = poisson_sequences(1200, 0.25, rng)
    rates = rejection_rates(seqs, rng)
    se = math.sqrt(0.05 * 0.95 / 1200)
    for name in ("uniformity_ks", "exponential_ks", "exponential_ad", "ljung_box", "runs"):
        assert abs(rates[name] - 0.05) < 3 * se, (name, rates[name])


def test_weibull_renewal_intervals_are_detected():
    rng = np.random.default_rng(9)
    law = scipy.stats.weibull_min(0.6)
    rates = rejection_rates(
        renewal_sequences(lambda n: law.rvs(n, random_state=rng) / law.mean(), 150), rng
    )
    assert rates["exponential_ks"] > 0.9
    assert rates["exponential_ad"] > 0.9
    assert rates["dispersion"] > 0.6
    assert rates["ljung_box"] < 0.15  # renewal: no serial dependence to see


def test_lognormal_renewal_intervals_are_detected():
    rng = np.random.default_rng(10)
    sigma = 1.5
    draw = lambda n: rng.lognormal(-(sigma**2) / 2, sigma, n)  # noqa: E731 (unit mean)
    rates = rejection_rates(renewal_sequences(draw, 150), rng)
    assert rates["exponential_ad"] > 0.9
    assert rates["exponential_ks"] > 0.9


def test_serially_correlated_exponential_intervals_are_detected():
    rng = np.random.default_rng(11)
    rates = rejection_rates(ear1_sequences(150, 0.6, rng), rng)
    assert rates["ljung_box"] > 0.8
    assert rates["runs"] > 0.8
    assert rates["exponential_ks"] < 0.35  # marginals are exponential


# --- ensembles -------------------------------------------------------------------------------


def test_ensemble_flags_a_clockwork_sequence_and_a_rate_outlier():
    rng = np.random.default_rng(12)
    seqs = poisson_sequences(60, 1.0, rng)
    seqs[7] = np.arange(0.5, T, 1.0) + rng.uniform(-0.05, 0.05, 100)  # nearly periodic
    seqs[21] = np.sort(rng.uniform(0, T, 200))  # twice the common rate
    ens = stats.test_poisson_ensemble(seqs, T, rng=13)
    assert ens.reject.loc[7, "exponential_ks"] and ens.reject.loc[7, "dispersion"]
    assert ens.reject.loc[21, "rate"]
    # FDR control: false discoveries among the 58 Poisson sequences stay rare.
    flagged = ens.reject.drop(index=[7, 21])[list(stats.TESTS)]
    assert flagged.to_numpy().sum() <= 2
    assert ens.combined.loc["exponential_ad", "n_reject_fdr"] >= 1
    assert ens.rate_homogeneity.loc["pearson", "pvalue_mc"] < 0.01
    assert "Rate homogeneity" in ens.summary()
    assert isinstance(ens.per_sequence, pd.DataFrame) and len(ens.per_sequence) == 60


def test_rate_homogeneity_holds_its_level_and_detects_two_rates():
    from kicktimes.stats.ensemble import _rate_tests

    rng = np.random.default_rng(14)
    windows = rng.uniform(50, 150, 40)
    p_mc, p_asy = [], []
    for _ in range(600):
        table, _ = _rate_tests(rng.poisson(1.0 * windows), windows, 99, rng)
        p_mc.append(table.loc["pearson", "pvalue_mc"])
        p_asy.append(table.loc["likelihood_ratio", "pvalue"])
    se = math.sqrt(0.1 * 0.9 / 600)
    assert abs(np.mean(np.asarray(p_mc) <= 0.1) - 0.1) < 3 * se
    assert abs(np.mean(np.asarray(p_asy) <= 0.1) - 0.1) < 3 * se
    rates = np.where(np.arange(40) % 2 == 0, 1.0, 1.4)
    seqs = [
        np.sort(rng.uniform(0, w, rng.poisson(lam * w)))
        for w, lam in zip(windows, rates, strict=True)
    ]
    ens = stats.test_poisson_ensemble(seqs, windows, rng=rng)
    assert ens.rate_homogeneity.loc["pearson", "pvalue"] < 1e-4


def test_combined_pvalues_are_not_significant_for_a_poisson_ensemble():
    rng = np.random.default_rng(15)
    ens = stats.test_poisson_ensemble(poisson_sequences(300, 1.0, rng), T, rng=rng)
    assert (ens.combined["pvalue"] > 0.001).all()
    assert (ens.combined["n_sequences"] == 300).all()


def test_ensemble_refines_monte_carlo_pvalues_to_flag_a_lone_outlier():
    # Among 300 sequences one clockwork sequence needs p < 0.05/300 to pass BH,
    # below the 1/(n_mc + 1) floor of 199 samples: the refinement must resolve it.
    rng = np.random.default_rng(16)
    seqs = poisson_sequences(300, 1.0, rng)
    seqs[5] = np.arange(0.5, T, 1.0) + rng.uniform(-0.05, 0.05, 100)
    coarse = stats.test_poisson_ensemble(seqs, T, rng=17, n_mc=199, n_mc_max=199)
    fine = stats.test_poisson_ensemble(seqs, T, rng=17, n_mc=199)
    assert not coarse.reject.loc[5, "exponential_ad"]
    assert fine.reject.loc[5, "exponential_ad"] and fine.reject.loc[5, "dispersion"]
    assert fine.per_sequence.loc[5, "p_exponential_ad"] < 0.05 / 300


def test_a_clockwork_sequence_is_rejected_and_degenerate_tests_say_why():
    res = stats.test_poisson(np.arange(1.0, 100.0), T, rng=18)
    assert res.loc["exponential_ad", "pvalue"] <= 0.001
    assert res.loc["dispersion", "pvalue"] <= 0.01
    for name in ("ljung_box", "runs"):  # all intervals exactly equal: undefined
        assert math.isnan(res.loc[name, "pvalue"])
        assert "degenerate" in res.loc[name, "note"]


def test_compiled_uniformity_ks_equals_scipy_exact_ks_on_every_branch():
    # n from 2 to 160 and beyond covers every branch of scipy's exact law (Ruben-Gambino,
    # Durbin matrix, Pomeranz, Miller, Pelz-Good); the compiled Pomeranz branch may differ
    # in the last bits of the CDF only (a p-value near 0 is 1 - CDF: absolute error).
    from kicktimes.stats.poisson import pomeranz_cdf, uniformity_ks

    rng = np.random.default_rng(21)
    for n in [*range(2, 161, 3), 200, 1000]:
        u = np.sort(rng.uniform(size=(5, n)) ** rng.uniform(0.6, 1.5, size=(5, 1)), axis=1)
        d, p = uniformity_ks(u)
        ref = scipy.stats.ks_1samp(u, scipy.stats.uniform.cdf, axis=-1, method="exact")
        np.testing.assert_array_equal(d, ref.statistic)
        np.testing.assert_allclose(p, ref.pvalue, rtol=1e-10, atol=1e-14)
    # the kernel on its own, inside the Pomeranz region (0.754693 < n x^2 <= 4)
    for n, x in [(10, 0.3), (50, 0.2), (140, 0.1), (77, 0.15)]:
        assert abs(pomeranz_cdf(n, x) - scipy.stats.kstwo.cdf(x, n)) < 1e-13


# ------------------------------------------------------------------ shared Monte Carlo nulls


@pytest.mark.parametrize("test", ["exponential_ks", "exponential_ad", "ljung_box", "dispersion"])
def test_null_bank_is_a_function_of_its_key(test):
    # the first `size` values do not depend on how the null grew nor on other keys
    kw = {"lags": 3, "n_bins": 4}
    grown = stats.MonteCarloNulls(5)
    grown.sample(test, 31, 0, **kw)
    grown.sample("exponential_ks", 17, 50)  # another key in between
    a = grown.sample(test, 31, 99, **kw).copy()
    b = grown.sample(test, 31, 250, **kw)
    fresh = stats.MonteCarloNulls(5).sample(test, 31, 250, **kw)
    np.testing.assert_array_equal(b[:99], a)
    np.testing.assert_array_equal(b, fresh)
    # the key's own stream, drawn in one go
    key = (stats.poisson.MC_TESTS.index(test), 31, 3 if test == "ljung_box" else 0,
           4 if test == "dispersion" else 2)
    stream = np.random.default_rng(
        np.random.SeedSequence(5, spawn_key=(stats.poisson._NULL_DOMAIN, *key)))
    np.testing.assert_array_equal(
        fresh, iid_tests.simulate_null(test, 31, 250, stream, **kw))
    assert not b.flags.writeable
    other_seed = stats.MonteCarloNulls(6).sample(test, 31, 250, **kw)
    assert not np.array_equal(other_seed, fresh)


def test_null_bank_makes_groups_independent_of_the_grouping():
    # with the nulls from one bank (and no refinement, no randomised ties) a sequence's
    # Monte Carlo p-values do not depend on which other sequences share its call
    rng = np.random.default_rng(3)
    seqs = poisson_sequences(40, 0.4, rng)
    kw = {"n_mc": 99, "n_mc_max": 99, "randomize": False, "rng": 1}
    whole = stats.test_poisson_ensemble(seqs, T, nulls=stats.MonteCarloNulls(8), **kw)
    bank = stats.MonteCarloNulls(8)
    halves = pd.concat([
        stats.test_poisson_ensemble(seqs[:25], T, nulls=bank, **kw).per_sequence,
        stats.test_poisson_ensemble(seqs[25:], T, nulls=bank, **kw).per_sequence,
    ], ignore_index=True)
    for test in ("exponential_ks", "exponential_ad", "ljung_box", "dispersion"):
        np.testing.assert_array_equal(halves[f"p_{test}"].to_numpy(),
                                      whole.per_sequence[f"p_{test}"].to_numpy())


def test_null_bank_tests_keep_their_size():
    # shared nulls make p-values of equal n dependent, not invalid: under Poisson every
    # Monte Carlo test rejects about alpha of the sequences (500 sequences, binomial
    # 99.9 % band around 0.05 is about [0.024, 0.083])
    rng = np.random.default_rng(11)
    seqs = poisson_sequences(500, 0.5, rng)
    res = stats.test_poisson_ensemble(seqs, T, n_mc=199, rng=2, nulls=stats.MonteCarloNulls(4))
    for test in ("exponential_ks", "exponential_ad", "ljung_box", "dispersion"):
        share = float((res.per_sequence[f"p_{test}"] < 0.05).mean())
        assert 0.02 <= share <= 0.09, (test, share)


def test_null_bank_bad_input():
    with pytest.raises(TypeError, match="nulls"):
        stats.test_poisson_ensemble([np.array([1.0, 2.0, 3.0])], 5.0, nulls=3)
    with pytest.raises(ValueError, match="seed"):
        stats.MonteCarloNulls(-1)
    with pytest.raises(ValueError, match="test"):
        stats.MonteCarloNulls(1).sample("runs", 20, 10)
    with pytest.raises(ValueError, match="n_events"):
        stats.MonteCarloNulls(1).sample("exponential_ks", 0, 10)
