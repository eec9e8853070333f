"""Specification of the kick-schedule API (kicktimes.schedules)."""

from __future__ import annotations

import json
import math
import os
import pickle
import sys
import types

import numpy as np
import pytest
import scipy.stats as st
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as hs

from kicktimes import schedules
from kicktimes.cli import main
from kicktimes.schedules import Bootstrap, Poisson, Renewal, Replay
from kicktimes.schedules._distributions import _equilibrium_sampler


def run_like(pp_times, t_max):
    """Duck-typed stand-in for a TwoParticleRun."""
    return types.SimpleNamespace(pp_times=np.asarray(pp_times, dtype=float), t_max=t_max)


def first_kicks(schedule, n, t_max=60.0, seed=0):
    """First kick time and kick counts in (0, 0.5] and (0, 5] over n independent samples."""
    rng = np.random.default_rng(seed)
    first = np.empty(n)
    counts = np.empty((n, 2))
    for i in range(n):
        times = schedule.sample(t_max, rng=rng)
        first[i] = times[0]
        counts[i] = np.searchsorted(times, [0.5, 5.0], side="right")
    return first, counts


def gamma_equilibrium_cdf(a, scale):
    """F_e(x) = E[min(X, x)] / E[X] = (x S(x) + a scale F_{a+1}(x)) / (a scale) for gamma."""

    def cdf(x):
        x = np.asarray(x, dtype=float)
        sf = st.gamma.sf(x, a, scale=scale)
        return (x * sf + a * scale * st.gamma.cdf(x, a + 1, scale=scale)) / (a * scale)

    return cdf


def pareto_equilibrium_cdf(b, xm):
    """F_e(x) = x / E[X] below xm, 1 - (x / xm)^(1 - b) / b above (E[X] = b xm / (b - 1))."""

    def cdf(x):
        x = np.asarray(x, dtype=float)
        below = x * (b - 1) / (b * xm)
        above = 1.0 - (np.maximum(x, xm) / xm) ** (1.0 - b) / b
        return np.where(x < xm, below, above)

    return cdf


class _Hyperexp(st.rv_continuous):
    """A two-phase hyperexponential with only _pdf/_cdf (no _rvs, no _ppf): generic scipy."""

    def _pdf(self, x):
        return 0.3 * np.exp(-x) + 0.7 * 5.0 * np.exp(-5.0 * x)

    def _cdf(self, x):
        return 1.0 - 0.3 * np.exp(-x) - 0.7 * np.exp(-5.0 * x)


hyperexp_test = _Hyperexp(a=0.0, name="hyperexp_test")


# ------------------------------------------------------------------------------ Poisson
def test_poisson_intervals_are_exponential_with_the_given_rate():
    times = Poisson(2.0).sample(5000.0, rng=11)
    intervals = np.diff(np.concatenate([[0.0], times]))
    assert intervals.size > 9000
    assert st.kstest(intervals, st.expon(scale=0.5).cdf).pvalue > 0.01
    # the same test has power against a 5 % error in the rate
    assert st.kstest(intervals, st.expon(scale=0.5 * 1.05).cdf).pvalue < 1e-3


def test_poisson_interval_ks_pvalues_are_uniform_across_seeds():
    pvalues = [
        st.kstest(np.diff(Poisson(1.0).sample(300.0, rng=seed)), "expon").pvalue
        for seed in range(60)
    ]
    assert st.kstest(pvalues, "uniform").pvalue > 0.01


def test_poisson_counts_in_windows_have_index_of_dispersion_one():
    times = Poisson(1.0).sample(20000.0, rng=3)
    counts = np.histogram(times, bins=np.arange(0.0, 20000.0 + 1e-9, 10.0))[0]
    n = counts.size
    dispersion = counts.var(ddof=1) / counts.mean()
    # (n - 1) D is chi-square(n - 1) for Poisson counts
    p = st.chi2.sf((n - 1) * dispersion, n - 1)
    assert 0.001 < p < 0.999, dispersion
    assert abs(counts.mean() - 10.0) < 4 * math.sqrt(10.0 / n)


def test_index_of_dispersion_detects_regular_gamma_kicks():
    # a gamma(4) renewal process has asymptotic dispersion 1/a = 0.25: the statistic above
    # is not blind to non-Poisson counts
    times = Renewal(st.gamma(4.0, scale=0.25)).sample(20000.0, rng=3)
    counts = np.histogram(times, bins=np.arange(0.0, 20000.0 + 1e-9, 10.0))[0]
    assert 0.2 < counts.var(ddof=1) / counts.mean() < 0.32


def test_poisson_rate_zero_gives_no_kicks():
    times = Poisson(0).sample(1e9, rng=1)
    assert times.dtype == np.float64 and times.shape == (0,)
    assert Poisson(0.0).mean_interval == math.inf


def test_poisson_from_run_uses_collisions_per_unit_time():
    run = run_like([0.5, 2.0, 7.5, 9.0], 10.0)
    assert Poisson.from_run(run) == Poisson(0.4)
    assert Poisson.from_run(run_like([], 10.0)) == Poisson(0.0)
    pooled = Poisson.from_runs([run, run_like([1.0], 30.0)])
    assert pooled.rate == pytest.approx(5 / 40)


# ------------------------------------------------------------------------------ Renewal
def test_renewal_gamma_reproduces_interval_mean_and_variance():
    a, scale = 2.0, 0.5  # mean 1, variance 0.5, fourth central moment 3 a (a + 2) scale^4
    times = Renewal(st.gamma(a, scale=scale)).sample(2e5, rng=5)
    x = np.diff(np.concatenate([[0.0], times]))
    n = x.size
    assert abs(x.mean() - 1.0) < 4 * math.sqrt(0.5 / n)
    mu4 = 3 * a * (a + 2) * scale**4
    assert abs(x.var() - 0.5) < 4 * math.sqrt((mu4 - 0.25) / n)
    assert st.kstest(x, st.gamma(a, scale=scale).cdf).pvalue > 0.01


@pytest.mark.parametrize(
    "dist",
    [st.gamma(2.0, scale=0.5), st.weibull_min(1.5, scale=1.2), st.halfnorm(scale=0.8)],
    ids=["gamma", "weibull", "halfnorm-generic"],
)
def test_stationary_first_interval_has_equilibrium_mean(dist):
    m1, m2, m3 = (dist.moment(k) for k in (1, 2, 3))
    eq_mean = m2 / (2 * m1)  # E[X_e] = E[X^2] / (2 E[X])
    eq_sd = math.sqrt(m3 / (3 * m1) - eq_mean**2)  # E[X_e^2] = E[X^3] / (3 E[X])
    n = 6000
    first, counts = first_kicks(Renewal(dist, stationary=True), n)
    assert abs(first.mean() - eq_mean) < 4 * eq_sd / math.sqrt(n)
    # stationary from t = 0: the mean count in (0, t] is t / E[X] even for small t
    assert abs(counts[:, 0].mean() - 0.5 / m1) < 4 * counts[:, 0].std() / math.sqrt(n)
    assert abs(counts[:, 1].mean() - 5.0 / m1) < 4 * counts[:, 1].std() / math.sqrt(n)


def test_ordinary_renewal_first_interval_has_the_interval_mean():
    dist = st.gamma(2.0, scale=0.5)
    first, _ = first_kicks(Renewal(dist), 4000)
    assert abs(first.mean() - 1.0) < 4 * math.sqrt(0.5 / 4000)


@pytest.mark.parametrize("method", ["auto", "pinv", "quad"])
def test_equilibrium_sampler_follows_the_equilibrium_cdf(method):
    dist = st.gamma(2.0, scale=0.5)
    draw = _equilibrium_sampler(dist, 1.0, method=method)
    rng = np.random.default_rng(4)
    n = 150 if method == "quad" else 5000
    sample = np.array([draw(rng) for _ in range(n)])
    cdf = gamma_equilibrium_cdf(2.0, 0.5)
    assert st.kstest(sample, cdf).pvalue > 0.01
    # and not the interval law itself
    if method != "quad":
        assert st.kstest(sample, dist.cdf).pvalue < 1e-3


@pytest.mark.parametrize(
    "dist, equilibrium",
    [
        (st.lomax(3.0, scale=2.0), st.lomax(2.0, scale=2.0)),
        (st.expon(scale=0.7), st.expon(scale=0.7)),
        (st.weibull_min(1.0, scale=0.7), st.expon(scale=0.7)),
        (st.pareto(2.5, scale=1.5), types.SimpleNamespace(cdf=pareto_equilibrium_cdf(2.5, 1.5))),
    ],
    ids=["lomax", "expon", "weibull-c1", "pareto"],
)
def test_closed_form_equilibrium_laws(dist, equilibrium):
    draw = _equilibrium_sampler(dist, float(dist.mean()))
    rng = np.random.default_rng(9)
    sample = np.array([draw(rng) for _ in range(4000)])
    assert st.kstest(sample, equilibrium.cdf).pvalue > 0.01


def test_hyperexponential_equilibrium_reweights_components_by_their_means():
    hyperexpon = pytest.importorskip("kicktimes.stats.distributions").hyperexpon
    dist = hyperexpon(0.4, 5.0, 0.5, scale=2.0)
    w = (0.4 / 5.0) / (0.4 / 5.0 + 0.6 / 0.5)  # p_i / lam_i, renormalised
    draw = _equilibrium_sampler(dist, float(dist.mean()))
    rng = np.random.default_rng(9)
    sample = np.array([draw(rng) for _ in range(4000)])
    assert st.kstest(sample, hyperexpon(w, 5.0, 0.5, scale=2.0).cdf).pvalue > 0.01
    assert st.kstest(sample, dist.cdf).pvalue < 1e-3


def test_lognormal_equilibrium_matches_generic_inversion():
    dist = st.lognorm(0.8, scale=1.5)
    rng = np.random.default_rng(2)
    closed = _equilibrium_sampler(dist, float(dist.mean()))
    pinv = _equilibrium_sampler(dist, float(dist.mean()), method="pinv")
    a = np.array([closed(rng) for _ in range(4000)])
    b = np.array([pinv(rng) for _ in range(4000)])
    assert st.ks_2samp(a, b).pvalue > 0.01


def test_stationary_renewal_needs_a_finite_mean():
    with pytest.raises(ValueError, match=r"lomax.*stationary"):
        Renewal(st.lomax(0.8), stationary=True)


def test_infinite_mean_intervals_sample_quickly():
    times = Renewal(st.lomax(0.5)).sample(1e12, rng=1)
    assert 0 < times.size < 10**7
    assert np.all(np.diff(times) >= 0) and times[-1] <= 1e12


def test_generic_scipy_family_is_sampled_by_inversion_of_its_pdf():
    schedule = Renewal(hyperexp_test())
    times = schedule.sample(2e4, rng=8)
    x = np.diff(np.concatenate([[0.0], times]))
    assert st.kstest(x, hyperexp_test.cdf).pvalue > 0.01


def test_renewal_from_a_real_fit_round_trips_through_json():
    fit_renewal = pytest.importorskip("kicktimes.stats").fit_renewal
    x = st.gamma(2.0, scale=0.5).rvs(size=400, random_state=1)
    for model in ("gamma", "hyperexponential"):
        fit = fit_renewal(x, model)
        schedule = Renewal.from_fit(fit, stationary=True)
        assert schedule == Renewal(fit.dist, stationary=True)
        assert schedules.from_json(schedule.to_json()) == schedule
        assert schedule.sample(50.0, rng=1).size > 0
    tail = fit_renewal(x, "powerlaw", x_min=1.0, min_tail=10)
    with pytest.raises(ValueError, match="tail fit"):
        Renewal(tail)


def test_renewal_accepts_a_fit_result():
    fit = types.SimpleNamespace(dist=st.gamma(2.0, scale=0.5), model="gamma", aic=1.0)
    assert Renewal(fit) == Renewal(st.gamma(2.0, scale=0.5))
    assert Renewal.from_fit(fit, stationary=True) == Renewal(fit.dist, stationary=True)
    with pytest.raises(TypeError, match="fit"):
        Renewal.from_fit(types.SimpleNamespace(dist="gamma"))


def test_zero_length_intervals_give_tied_kicks_inside_the_window():
    times = Renewal(st.gamma(0.005)).sample(50.0, rng=1)
    assert np.any(np.diff(times) == 0)  # gamma(0.005) draws underflow to 0.0
    assert times[0] > 0 and np.all(np.diff(times) >= 0)


# ------------------------------------------------------------------------ Replay, Bootstrap
def test_replay_returns_exactly_the_given_times():
    times = np.sort(np.random.default_rng(0).uniform(0, 100, 500))
    replay = Replay(times)
    out = replay.sample(50.0, rng=1)
    assert np.array_equal(out, times[times <= 50.0])
    assert np.array_equal(out, replay.sample(50.0, rng=2))  # rng is ignored
    assert np.array_equal(replay.sample(times[-1]), times)
    out[:] = -1.0  # a copy: the schedule cannot be modified through it
    assert np.array_equal(replay.sample(50.0), times[times <= 50.0])


def test_replay_from_run_keeps_the_window():
    run = run_like([0.5, 2.0, 7.5, 9.0], 10.0)
    replay = Replay.from_run(run)
    assert replay == Replay([0.5, 2.0, 7.5, 9.0], t_max=10.0)
    assert np.array_equal(replay.sample(10.0), run.pp_times)
    with pytest.raises(ValueError, match="exceeds the replayed window"):
        replay.sample(10.5)


def test_bootstrap_draws_only_observed_intervals():
    observed = np.array([0.25, 0.5, 1.0, 2.0])  # dyadic: cumulative sums are exact
    times = Bootstrap(observed).sample(2000.0, rng=6)
    steps = np.diff(np.concatenate([[0.0], times]))
    values, counts = np.unique(steps, return_counts=True)
    assert set(values) == set(observed)
    assert st.chisquare(counts).pvalue > 0.001  # each observed interval equally likely


def test_bootstrap_of_arbitrary_intervals_stays_within_rounding_of_them():
    observed = np.random.default_rng(1).exponential(size=50)
    steps = np.diff(Bootstrap(observed).sample(500.0, rng=2))
    gap = np.abs(steps[:, None] - observed[None, :]).min(axis=1)
    assert gap.max() < 1e-10


def test_bootstrap_from_run_drops_first_time_and_censored_tail():
    run = run_like([1.0, 1.5, 3.5, 4.0], 100.0)
    assert Bootstrap.from_run(run) == Bootstrap([0.5, 2.0, 0.5])
    pooled = Bootstrap.from_runs([run, run_like([2.0, 7.0], 10.0)])
    assert pooled == Bootstrap([0.5, 2.0, 0.5, 5.0])
    with pytest.raises(ValueError, match="run.pp_times"):
        Bootstrap.from_run(run_like([1.0], 10.0))


def test_stationary_bootstrap_first_interval_has_equilibrium_mean():
    observed = np.array([0.5, 1.0, 4.0])
    first, _ = first_kicks(Bootstrap(observed, stationary=True), 6000)
    eq_mean = (observed**2).sum() / (2 * observed.sum())
    eq_sd = math.sqrt((observed**3).sum() / (3 * observed.sum()) - eq_mean**2)
    assert abs(first.mean() - eq_mean) < 4 * eq_sd / math.sqrt(6000)


def test_bootstrap_allows_zero_intervals_but_not_only_zeros():
    times = Bootstrap([0.0] * 50 + [1.0]).sample(3.0, rng=0)
    assert times.size > 100 and np.any(np.diff(times) == 0)
    # leading kicks at exactly 0 are moved to "0+", the smallest positive double
    assert times[0] == np.nextafter(0.0, 1.0) and np.all(times > 0)
    with pytest.raises(ValueError, match="intervals"):
        Bootstrap([0.0, 0.0])


# -------------------------------------------------------------------- reproducibility
ALL_SCHEDULES = [
    Poisson(1.5),
    Renewal(st.gamma(2.0, scale=0.5)),
    Renewal(st.weibull_min(0.7), stationary=True),
    Replay([0.1, 0.2, 3.0, 7.25], t_max=10.0),
    Bootstrap([0.3, 1.1, 0.05, 2.0], stationary=True),
]
IDS = ["poisson", "renewal", "stationary-weibull", "replay", "bootstrap"]


@pytest.mark.parametrize("schedule", ALL_SCHEDULES, ids=IDS)
def test_sample_is_reproducible_from_a_seed(schedule):
    a = schedule.sample(10.0, rng=42)
    b = schedule.sample(10.0, rng=np.random.default_rng(42))
    assert np.array_equal(a, b)
    assert a.dtype == np.float64 and a.flags.writeable
    assert np.all(a > 0) and np.all(a <= 10.0) and np.all(np.diff(a) >= 0)
    if not isinstance(schedule, Replay):
        assert not np.array_equal(a, schedule.sample(10.0, rng=43))


@settings(max_examples=25, deadline=None)
@given(seed=hs.integers(0, 2**32), t1=hs.floats(1e-3, 3000.0), extra=hs.floats(0.0, 3000.0))
def test_shorter_horizon_is_a_prefix_of_a_longer_one(seed, t1, extra):
    for schedule in (Poisson(2.0), Renewal(st.gamma(0.5), stationary=True)):
        short = schedule.sample(t1, rng=seed)
        long = schedule.sample(t1 + extra, rng=seed)
        assert np.array_equal(short, long[long <= t1])


def test_a_million_kicks_are_generated():
    times = Poisson(1.0).sample(1.05e6, rng=0)
    assert 10**6 < times.size < 1.1 * 10**6


def test_max_kicks_guards_against_runaway_samples():
    with pytest.raises(ValueError, match="max_kicks"):
        Poisson(1e9).sample(1e6, rng=0)
    with pytest.raises(ValueError, match="max_kicks"):
        Renewal(st.lomax(0.5)).sample(1e12, rng=0, max_kicks=10)


# ------------------------------------------------------------------ values and JSON
@pytest.mark.parametrize("schedule", ALL_SCHEDULES, ids=IDS)
def test_json_round_trip_is_exact(schedule):
    text = schedule.to_json()
    again = schedules.from_json(text)
    assert again == schedule and hash(again) == hash(schedule)
    assert type(schedule).from_json(text) == schedule
    assert again.to_json() == text
    assert pickle.loads(pickle.dumps(schedule)) == schedule
    assert json.loads(text)["kicktimes_schedule"] == 1


def test_json_keeps_awkward_floats_exactly():
    schedule = Bootstrap([0.1, 1 / 3, 1e-300, 2.0**-1074, 123456.789e10])
    assert schedules.from_json(schedule.to_json()) == schedule
    assert schedules.from_json(Poisson(1 / 3).to_json()).rate == 1 / 3


def test_reprs_are_readable():
    assert repr(Poisson(0.5)) == "Poisson(rate=0.5)"
    assert repr(Renewal(st.gamma(2, scale=0.5), stationary=True)) == (
        "Renewal(dist=gamma(a=2.0, scale=0.5), stationary=True)"
    )
    assert repr(Replay([0.5, 1.25], t_max=2)) == "Replay(times=[0.5, 1.25], t_max=2.0)"
    long = repr(Bootstrap(np.arange(1.0, 101.0)))
    assert long.startswith("Bootstrap(intervals=<100 intervals in [1, 100], mean 50.5>")
    assert len(long) < 100


def test_equality_compares_values():
    assert Renewal(st.gamma(2, scale=0.5)) == Renewal(st.gamma(a=2.0, loc=0, scale=0.5))
    assert Renewal(st.gamma(2, 0, 0.5)) == Renewal(st.gamma(2, scale=0.5))
    assert Renewal(st.gamma(2, scale=0.5)) != Renewal(st.gamma(2, scale=0.5), stationary=True)
    assert Renewal(st.gamma(2)) != Renewal(st.weibull_min(2))
    assert Replay([1.0, 2.0]) == Replay(np.array([1.0, 2.0]))
    assert Replay([1.0, 2.0]) != Replay([1.0, 2.0], t_max=3.0)
    assert Bootstrap([1.0, 2.0]) != Bootstrap([2.0, 1.0])  # order drives the resampling
    assert Poisson(1.0) != Renewal(st.expon())
    assert len({Poisson(1.0), Poisson(1.0), Poisson(2.0)}) == 2


def test_schedules_are_immutable():
    replay = Replay([1.0, 2.0])
    with pytest.raises(ValueError):
        replay.times[0] = 5.0
    with pytest.raises(AttributeError):
        replay.t_max = 3.0


def test_from_json_rejects_malformed_text():
    with pytest.raises(ValueError, match="not valid JSON"):
        schedules.from_json("{")
    with pytest.raises(ValueError, match="unknown schedule type"):
        schedules.from_json('{"kicktimes_schedule": 1, "type": "hawkes"}')
    with pytest.raises(ValueError, match="fields"):
        schedules.from_json('{"kicktimes_schedule": 1, "type": "poisson", "rte": 1}')
    with pytest.raises(ValueError, match="kicktimes_schedule"):
        schedules.from_json('{"type": "poisson", "rate": 1}')
    with pytest.raises(ValueError, match="'poisson'"):
        Renewal.from_json(Poisson(1.0).to_json())
    with pytest.raises(ValueError, match="unknown distribution name 'nosuch'"):
        schedules.from_json(
            '{"kicktimes_schedule": 1, "type": "renewal", "stationary": false,'
            ' "dist": {"name": "nosuch", "args": [], "kwds": {}}}'
        )


def test_unregistered_distribution_cannot_be_serialised():
    with pytest.raises(ValueError, match="hyperexp_test"):
        Renewal(hyperexp_test()).to_json()


def test_names_resolve_in_kicktimes_stats_distributions(monkeypatch):
    fake = types.ModuleType("kicktimes.stats.distributions")
    fake.hyperexp_test = hyperexp_test
    monkeypatch.setitem(sys.modules, "kicktimes.stats.distributions", fake)
    assert schedules.resolve_distribution("gamma") is st.gamma
    assert schedules.resolve_distribution("hyperexp_test") is hyperexp_test
    schedule = Renewal(hyperexp_test(scale=2.0), stationary=True)
    assert schedules.from_json(schedule.to_json()) == schedule


# ------------------------------------------------------------------------- file I/O
@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_kick_times_round_trip_through_files(tmp_path, suffix):
    schedule = Renewal(st.gamma(2.0, scale=0.5), stationary=True)
    times = schedule.sample(500.0, rng=1)
    times[0] = 0.1  # a value with no short binary form
    path = schedules.write_kick_times(
        times, tmp_path / f"kicks{suffix}", t_max=500.0, schedule=schedule, seed=1
    )
    back, meta = schedules.read_kick_times(path, with_metadata=True)
    assert np.array_equal(back, times)
    assert meta["t_max"] == 500.0 and meta["seed"] == 1 and meta["n_kicks"] == times.size
    assert schedules.from_dict(meta["schedule"]) == schedule
    extra = [f"kicks{suffix}.json"] if suffix == ".csv" else []  # the CSV's metadata sidecar
    assert sorted(os.listdir(tmp_path)) == [f"kicks{suffix}", *extra]  # no stray temp file


def test_csv_of_kick_times_is_plain_for_any_reader(tmp_path):
    import pandas as pd

    path = schedules.write_kick_times([0.1, 2.5], tmp_path / "kicks.csv", t_max=3.0, seed=4)
    frame = pd.read_csv(path)
    assert list(frame.columns) == ["kick_time"] and frame["kick_time"].tolist() == [0.1, 2.5]
    meta = json.loads((tmp_path / "kicks.csv.json").read_text())
    assert meta["t_max"] == 3.0 and meta["seed"] == 4 and meta["n_kicks"] == 2


def test_csv_with_the_old_comment_line_is_still_read(tmp_path):
    meta = {"format": "kicktimes.kick_times/1", "n_kicks": 2, "t_max": 3.0, "seed": 4}
    (tmp_path / "old.csv").write_text(
        "# kicktimes metadata: " + json.dumps(meta) + "\nkick_time\n0.5\n1.5\n"
    )
    times, back = schedules.read_kick_times(tmp_path / "old.csv", with_metadata=True)
    assert times.tolist() == [0.5, 1.5] and back == meta


def test_a_stale_sidecar_is_refused(tmp_path):
    path = schedules.write_kick_times([0.1, 2.5], tmp_path / "kicks.csv")
    path.write_text("kick_time\n0.5\n")  # rewritten by hand, sidecar not
    with pytest.raises(ValueError, match="stale"):
        schedules.read_kick_times(path)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_empty_kick_times_round_trip(tmp_path, suffix):
    path = schedules.write_kick_times(Poisson(0).sample(5.0), tmp_path / f"k{suffix}")
    assert schedules.read_kick_times(path).shape == (0,)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_failed_write_leaves_the_old_file_and_no_temp(tmp_path, suffix, monkeypatch):
    path = schedules.write_kick_times([1.0, 2.0], tmp_path / f"k{suffix}")

    def broken_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        schedules.write_kick_times([3.0, 4.0, 5.0], path)
    monkeypatch.undo()
    assert np.array_equal(schedules.read_kick_times(path), [1.0, 2.0])
    extra = [f"k{suffix}.json"] if suffix == ".csv" else []
    assert sorted(os.listdir(tmp_path)) == [f"k{suffix}", *extra]


def test_foreign_and_damaged_time_files(tmp_path):
    (tmp_path / "pp.csv").write_text("particle,time\n0,0.5\n0,1.5\n")
    assert np.array_equal(schedules.read_kick_times(tmp_path / "pp.csv"), [0.5, 1.5])
    (tmp_path / "bad.csv").write_text("kick_time\n2.0\n1.0\n")
    with pytest.raises(ValueError, match="sorted"):
        schedules.read_kick_times(tmp_path / "bad.csv")
    (tmp_path / "nan.csv").write_text("kick_time\n1.0\nnan\n")
    with pytest.raises(ValueError, match="finite"):
        schedules.read_kick_times(tmp_path / "nan.csv")
    (tmp_path / "two.csv").write_text("a,b\n1,2\n")
    with pytest.raises(ValueError, match="column"):
        schedules.read_kick_times(tmp_path / "two.csv")


# ------------------------------------------------------------------------- bad input
BAD = [
    (lambda: Poisson(-1.0), ValueError, "rate"),
    (lambda: Poisson(float("nan")), ValueError, "rate"),
    (lambda: Poisson(math.inf), ValueError, "rate"),
    (lambda: Poisson("1"), TypeError, "rate"),
    (lambda: Poisson(True), TypeError, "rate"),
    (lambda: Poisson(1.0).sample(0.0), ValueError, "t_max"),
    (lambda: Poisson(1.0).sample(math.nan), ValueError, "t_max"),
    (lambda: Poisson(1.0).sample(math.inf), ValueError, "t_max"),
    (lambda: Poisson(1.0).sample(10.0, rng=1.5), TypeError, "rng"),
    (lambda: Poisson(1.0).sample(10.0, rng=-1), ValueError, "rng"),
    (lambda: Poisson(1.0).sample(10.0, max_kicks=0), ValueError, "max_kicks"),
    (lambda: Renewal(st.norm()), ValueError, "support"),
    (lambda: Renewal(st.gamma(2, loc=-1)), ValueError, "support"),
    (lambda: Renewal(st.gamma(-1.0)), ValueError, "invalid parameters"),
    (lambda: Renewal(st.gamma(2, scale=-1.0)), ValueError, "invalid parameters"),
    (lambda: Renewal(st.gamma(math.nan)), ValueError, "finite"),
    (lambda: Renewal(st.gamma([1.0, 2.0])), ValueError, "scalar"),
    (lambda: Renewal(st.gamma), TypeError, "frozen"),
    (lambda: Renewal(st.poisson(2.0)), TypeError, "continuous"),
    (lambda: Renewal("gamma"), TypeError, "dist"),
    (lambda: Renewal(st.gamma(2), stationary="yes"), TypeError, "stationary"),
    (lambda: Replay([2.0, 1.0]), ValueError, "sorted"),
    (lambda: Replay([0.0, 1.0]), ValueError, "> 0"),
    (lambda: Replay([-1.0, 1.0]), ValueError, "> 0"),
    (lambda: Replay([1.0, math.nan]), ValueError, "finite"),
    (lambda: Replay([[1.0, 2.0]]), ValueError, "one-dimensional"),
    (lambda: Replay(["a"]), TypeError, "times"),
    (lambda: Replay([1.0, 5.0], t_max=4.0), ValueError, "t_max"),
    (lambda: Bootstrap([]), ValueError, "intervals"),
    (lambda: Bootstrap([1.0, -0.5]), ValueError, ">= 0"),
    (lambda: Bootstrap([1.0, math.inf]), ValueError, "finite"),
    (lambda: Poisson.from_run(object()), TypeError, "pp_times"),
    (lambda: Poisson.from_run(run_like([1.0, 11.0], 10.0)), ValueError, "run.pp_times"),
    (lambda: Poisson.from_run(run_like([1.0], 0.0)), ValueError, "run.t_max"),
    (lambda: Poisson.from_runs([]), ValueError, "runs"),
    (lambda: schedules.write_kick_times([1.0], "k.txt"), ValueError, "csv or .parquet"),
    (lambda: schedules.write_kick_times([2.0, 1.0], "k.csv"), ValueError, "sorted"),
    (lambda: schedules.write_kick_times([2.0], "k.csv", t_max=1.0), ValueError, "t_max"),
    (lambda: schedules.write_kick_times([1.0], "k.csv", seed=1.5), TypeError, "seed"),
    (lambda: schedules.from_spec("hawkes"), ValueError, "model"),
    (lambda: schedules.from_spec("poisson", {"mean": 1}), ValueError, "rate"),
    (lambda: schedules.from_spec("poisson", {"rate": "x"}), ValueError, "rate"),
    (lambda: schedules.from_spec("renewal", {"a": 2}), ValueError, "dist"),
    (lambda: schedules.from_spec("renewal", {"b": 2}, dist="gamma"), ValueError, "valid"),
    (lambda: schedules.from_spec("renewal", {}, dist="gamma"), ValueError, "missing"),
    (lambda: schedules.from_spec("poisson", {"rate": 1}, dist="gamma"), ValueError, "dist"),
    (lambda: schedules.from_spec("replay"), ValueError, "times"),
    (lambda: schedules.resolve_distribution("nosuch"), ValueError, "nosuch"),
]


@pytest.mark.parametrize("call, error, match", BAD, ids=[f"bad{i}" for i in range(len(BAD))])
def test_bad_input_raises_a_named_error(call, error, match):
    with pytest.raises(error, match=match):
        call()


# --------------------------------------------------------------------- spec and CLI
def test_from_spec_builds_each_model(tmp_path):
    assert schedules.from_spec("poisson", {"rate": "0.5"}) == Poisson(0.5)
    assert schedules.from_spec(
        "renewal", {"a": 2, "scale": 0.5}, dist="gamma", stationary=True
    ) == Renewal(st.gamma(2, scale=0.5), stationary=True)
    times = [0.5, 1.5, 4.0]
    assert schedules.from_spec("bootstrap", times=times) == Bootstrap([1.0, 2.5])
    assert schedules.from_spec("replay", times=times, window=5.0) == Replay(times, t_max=5.0)
    path = schedules.write_kick_times(times, tmp_path / "t.parquet", t_max=6.0)
    assert schedules.from_spec("replay", times=path) == Replay(times, t_max=6.0)


def test_cli_writes_a_reproducible_poisson_schedule(tmp_path):
    out = tmp_path / "kicks.parquet"
    args = ["schedule", "poisson", "-p", "rate=0.5", "--t-max", "1000", "--seed", "7"]
    result = CliRunner().invoke(main, [*args, "-o", str(out)])
    assert result.exit_code == 0, result.output
    times, meta = schedules.read_kick_times(out, with_metadata=True)
    assert np.array_equal(times, Poisson(0.5).sample(1000.0, rng=7))
    assert f"{times.size} kicks" in result.output and "mean interval" in result.output
    assert meta["seed"] == 7 and schedules.from_dict(meta["schedule"]) == Poisson(0.5)


def test_cli_renewal_bootstrap_replay_and_json(tmp_path):
    runner = CliRunner()
    base = ["--t-max", "200", "--seed", "3", "-o"]
    renewal = ["renewal", "--dist", "gamma", "-p", "a=2", "-p", "scale=0.5", "--stationary"]
    result = runner.invoke(main, ["schedule", *renewal, *base, str(tmp_path / "r.csv")])
    assert result.exit_code == 0, result.output
    expected = Renewal(st.gamma(2, scale=0.5), stationary=True).sample(200.0, rng=3)
    assert np.array_equal(schedules.read_kick_times(tmp_path / "r.csv"), expected)

    source = ["--input", str(tmp_path / "r.csv")]
    result = runner.invoke(main, ["schedule", "bootstrap", *source, *base, str(tmp_path / "b.csv")])
    assert result.exit_code == 0, result.output
    result = runner.invoke(main, ["schedule", "replay", *source, *base, str(tmp_path / "p.csv")])
    assert np.array_equal(schedules.read_kick_times(tmp_path / "p.csv"), expected)

    (tmp_path / "s.json").write_text(Poisson(2.0).to_json())
    json_args = ["schedule", "json", "--input", str(tmp_path / "s.json")]
    result = runner.invoke(main, [*json_args, *base, str(tmp_path / "j.csv")])
    assert result.exit_code == 0, result.output
    assert np.array_equal(
        schedules.read_kick_times(tmp_path / "j.csv"), Poisson(2.0).sample(200.0, rng=3)
    )


@pytest.mark.parametrize(
    "args, message",
    [
        (["poisson", "-p", "rate=-1"], "rate must lie in [0.0, inf)"),
        (["poisson", "-p", "rate"], "NAME=VALUE"),
        (["renewal", "-p", "a=2"], "needs dist"),
        (["renewal", "--dist", "norm"], "support"),
        (["replay"], "needs times"),
    ],
)
def test_cli_reports_bad_input(tmp_path, args, message):
    out = str(tmp_path / "x.csv")
    result = CliRunner().invoke(main, ["schedule", *args, "--t-max", "10", "-o", out])
    assert result.exit_code == 2
    assert message in result.output
    assert not os.path.exists(out)


def test_poisson_with_a_subnormal_rate_has_no_kick_and_no_overflow_warning():
    # found by the property test: 1 / rate overflows to inf, an interval beyond any window
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        times = Poisson(1e-310).sample(1e6, rng=np.random.default_rng(0))
    assert times.size == 0 and times.dtype == np.float64


# ------------------------------------------------------------- the same on every CPU
@pytest.mark.reproducibility
@pytest.mark.parametrize(("name", "schedule", "digest"), [
    ("poisson", Poisson(0.5), "333b3601705abbd0"),
    ("exponential", Renewal(st.expon(scale=2.0)), "333b3601705abbd0"),
    ("stationary-exponential", Renewal(st.expon(scale=2.0), stationary=True),
     "013a49080f3f7cb9"),
    ("gamma", Renewal(st.gamma(2.0, scale=1.0)), "36104d644ff9de32"),
    ("stationary-gamma", Renewal(st.gamma(2.0, scale=1.0), stationary=True),
     "e3540186fbe910a6"),
])
def test_cpu_independent_schedules_keep_their_digests(name, schedule, digest):
    # these samplers use only arithmetic on numpy's bit stream (ziggurat exponential,
    # Marsaglia-Tsang gamma): the same times on every CPU, BLAS and libm variant
    # (docs/architecture.md, Reproducibility; CI runs this under foreign ones)
    import hashlib

    times = schedule.sample(20000.0, rng=1)
    assert hashlib.sha256(times.tobytes()).hexdigest()[:16] == digest


@pytest.mark.reproducibility
def test_kick_angles_keep_their_digests():
    import hashlib

    from kicktimes.billiard.one_particle import draw_kick_angles

    rng = np.random.default_rng(2)
    uniform = draw_kick_angles(5000, "uniform", 0.0, rng)
    gaussian = draw_kick_angles(5000, "gaussian", 0.3, rng)
    assert hashlib.sha256(uniform.tobytes()).hexdigest()[:16] == "c5ae088860a68d96"
    assert hashlib.sha256(gaussian.tobytes()).hexdigest()[:16] == "7d56a2638fc08980"
