"""kicktimes.stats.dilute: the tagged disk of a dilute gas (linear Boltzmann process)."""

import numpy as np
import pytest
from scipy import integrate

from kicktimes.stats import dilute_tagged_times, speed_rate_factor

RATE, WINDOW, RUNS = 2.0, 100.0, 6000


@pytest.fixture(scope="module")
def elastic():
    return dilute_tagged_times("elastic", RATE, WINDOW, n_runs=RUNS, rng=np.random.default_rng(3),
                               speeds=True)


def _maxwell_moment(power, kT=0.5):
    """<(lambda(v) / nu)^power> over the 2-D Maxwellian speed density (v / kT) e^(-v^2/2kT)."""
    def f(v):
        return speed_rate_factor(np.array([v]), kT=kT)[0] ** power * v / kT * np.exp(
            -v * v / (2 * kT))

    return integrate.quad(f, 0.0, 20.0)[0]


def test_stationary_mean_rate_is_nu(elastic):
    times, speeds = elastic
    n = sum(t.size for t in times)
    # Poisson-like error of the total count, inflated by the Cox overdispersion (< 1.5)
    assert abs(n / (RUNS * WINDOW) / RATE - 1) < 3 * 1.5 / np.sqrt(n)
    # the time average of lambda(v) over the streams' own speeds is nu, too
    total = sum(float(np.sum(speed_rate_factor(s) * np.diff(np.r_[0.0, t, WINDOW])))
                for t, s in zip(times, speeds, strict=True))
    assert abs(total / (RUNS * WINDOW) - 1) < 0.01


def test_rate_after_a_collision_is_above_nu(elastic):
    _, speeds = elastic
    after = np.concatenate([speed_rate_factor(s[1:-1]) for s in speeds])
    expected = _maxwell_moment(2) / _maxwell_moment(1)   # <lambda^2> / <lambda> over nu
    assert expected > 1.05
    assert abs(after.mean() / expected - 1) < 0.01
    assert after.mean() > 1.04


def test_long_window_dispersion_above_one(elastic):
    times, _ = elastic
    counts = np.array([np.searchsorted(t, WINDOW) for t in times], float)
    d = counts.var(ddof=1) / counts.mean()
    # a Poisson D of 6000 streams has a standard error of sqrt(2 / 6000) = 0.018; the
    # dilute gas gives about 1.12 in windows of 100 to 400 mean intervals
    assert d > 1.0 + 3 * np.sqrt(2 / RUNS)


def test_mirror_streams_are_poisson():
    times, speeds = dilute_tagged_times("mirror", RATE, WINDOW, n_runs=4000, rng=7, speeds=True)
    counts = np.array([np.searchsorted(t, 150.0 / RATE) for t in times], float)
    d = counts.var(ddof=1) / counts.mean()
    assert abs(d - 1) < 3 * np.sqrt(2 / 4000)            # D = 1 within 0.067
    assert all(np.all(s == 1.0) and s.size == t.size + 1 for t, s in zip(times, speeds,
                                                                         strict=True))
    gaps = np.concatenate([np.diff(np.r_[0.0, t]) for t in times]) * RATE
    assert abs(gaps.mean() - 1) < 0.01 and abs(gaps.std() - 1) < 0.02   # exponential


def test_elastic_streams_are_sorted_and_reproducible():
    a = dilute_tagged_times("elastic", 1.0, 20.0, n_runs=5, rng=11)
    b = dilute_tagged_times("elastic", 1.0, 20.0, n_runs=5, rng=11)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert all(np.all(np.diff(x) > 0) and (x.size == 0 or x[-1] <= 20.0) for x in a)


@pytest.mark.parametrize("kwargs, error, word", [
    ({"rule": "soft"}, ValueError, "rule"),
    ({"rate": 0.0}, ValueError, "rate"),
    ({"rate": "1"}, TypeError, "rate"),
    ({"t_window": -1.0}, ValueError, "t_window"),
    ({"n_runs": 0}, ValueError, "n_runs"),
    ({"n_runs": 2.0}, TypeError, "n_runs"),
    ({"kT": float("nan")}, ValueError, "kT"),
])
def test_bad_arguments(kwargs, error, word):
    args = {"rule": "elastic", "rate": 1.0, "t_window": 1.0, "n_runs": 2, "rng": 0}
    args.update(kwargs)
    with pytest.raises(error, match=word):
        dilute_tagged_times(**args)
