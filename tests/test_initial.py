"""Initial-condition ensembles and the exact kinetic-theory check of the simulator."""

import numpy as np
import pytest

from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.stats import kinetic_rate


@pytest.mark.parametrize("method", ["paper", "uniform"])
def test_ics_are_valid_at_r_max_and_have_unit_speeds(method):
    r_max = 0.03
    ics = initial_conditions(500, r_max, seed=4, method=method)
    assert ics.shape == (500, 2, 4)
    assert (np.hypot(ics[:, :, 0], ics[:, :, 1]) <= 1 - r_max).all()
    gap = np.hypot(ics[:, 0, 0] - ics[:, 1, 0], ics[:, 0, 1] - ics[:, 1, 1])
    assert (gap >= 2 * r_max).all()
    np.testing.assert_allclose(np.hypot(ics[:, :, 2], ics[:, :, 3]), 1.0, atol=1e-15)


def test_ic_i_does_not_depend_on_chunking():
    whole = initial_conditions(40, 0.02, seed=9)
    parts = np.concatenate([initial_conditions(n, 0.02, seed=9, start=s)
                            for s, n in [(0, 7), (7, 20), (27, 13)]])
    assert np.array_equal(whole, parts)
    assert not np.array_equal(whole, initial_conditions(40, 0.02, seed=10))


def test_paper_method_draws_distance_uniform_not_area_uniform():
    ics = initial_conditions(4000, 0.01, seed=1, method="paper")
    dist = np.hypot(ics[:, 0, 0], ics[:, 0, 1])
    # distance uniform on (0, 0.99): median ~0.495; area-uniform would give ~0.70
    assert abs(np.median(dist) - 0.495) < 0.03


def test_uniform_method_is_area_uniform():
    ics = initial_conditions(4000, 0.01, seed=1, method="uniform")
    dist = np.hypot(ics[:, 0, 0], ics[:, 0, 1])
    assert abs(np.median(dist) - 0.99 / np.sqrt(2)) < 0.03


def test_elastic_invariant_measure_has_total_energy_two():
    ics = initial_conditions(300, 0.02, seed=2, method="uniform", rule="elastic")
    np.testing.assert_allclose((ics[:, :, 2:] ** 2).sum(axis=(1, 2)), 2.0)
    speeds = np.hypot(ics[:, :, 2], ics[:, :, 3])
    assert speeds.std() > 0.1  # speeds vary, unlike the mirror rule


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(n=0, r_max=0.02), "n must be an integer >= 1"),
        (dict(n=3, r_max=0.5), "r_max must lie in"),
        (dict(n=3, r_max=0.02, method="grid"), "method must be one of"),
        (dict(n=3, r_max=0.02, seed=-1), "seed must be an integer >= 0"),
        (dict(n=3, r_max=0.02, rule="soft"), "rule must be one of"),
    ],
)
def test_bad_arguments_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        initial_conditions(**kwargs)


def assert_mean_count_matches_kinetic_theory(rule, r, n, t_max, seed):
    # E[N(T)] = Gamma T exactly for ICs drawn from the invariant measure (docs/architecture.md)
    ics = initial_conditions(n, r, seed=seed, method="uniform", rule=rule)
    counts = np.array([simulate_two_particle(ic, r, t_max=t_max, rule=rule).n_pp for ic in ics])
    expected = kinetic_rate(r, rule=rule) * t_max
    sem = counts.std(ddof=1) / np.sqrt(n)
    assert abs(counts.mean() - expected) < 3 * sem, (counts.mean(), expected, sem)


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("r", [0.02, 0.05])
def test_collision_rate_matches_kinetic_theory_under_the_invariant_measure(rule, r):
    assert_mean_count_matches_kinetic_theory(rule, r, n=600, t_max=100.0, seed=123)


@pytest.mark.slow
@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("r", [0.01, 0.02, 0.05])
def test_collision_rate_matches_kinetic_theory_with_many_ics(rule, r):
    assert_mean_count_matches_kinetic_theory(rule, r, n=20000, t_max=200.0, seed=7)


# ------------------------------------------------------------- every radius, bounded time
@pytest.mark.parametrize(("method", "rule", "r_max", "digest"), [
    ("paper", "mirror", 0.03, "b221778024b3b778"),
    ("paper", "mirror", 0.1, "08695fc9bd669d3e"),
    ("uniform", "mirror", 0.03, "c6ae7170f08b0360"),
    ("uniform", "elastic", 0.03, "430e73daf4219840"),
    ("uniform", "mirror", 0.1, "5d265b106d2b7e6d"),
    ("uniform", "elastic", 0.1, "68632eb16803941c"),
])
def test_the_paper_radii_give_the_same_ensembles_bit_for_bit(method, rule, r_max, digest):
    # digests of the ensembles drawn before the feasibility fallback existed (commit 2874fcf)
    import hashlib

    ics = initial_conditions(200, r_max, seed=2026, method=method, rule=rule)
    assert hashlib.sha256(ics.tobytes()).hexdigest()[:16] == digest


@pytest.mark.parametrize("method", ["paper", "uniform"])
@pytest.mark.parametrize("r_max", [0.34, 0.4, 0.45, 0.49, 0.4999, 0.5 - 1e-9])
def test_every_radius_up_to_one_half_gives_valid_ics_in_bounded_time(method, r_max):
    import time

    t0 = time.perf_counter()
    ics = initial_conditions(20, r_max, seed=1, method=method, rule="elastic")
    assert time.perf_counter() - t0 < 5.0
    assert (np.hypot(ics[:, :, 0], ics[:, :, 1]) <= 1 - r_max).all()
    gap = np.hypot(ics[:, 0, 0] - ics[:, 1, 0], ics[:, 0, 1] - ics[:, 1, 1])
    assert (gap >= 2 * r_max).all()


def test_the_issue_example_returns():
    ic = initial_conditions(1, 0.4, seed=1)[0]
    assert np.hypot(ic[0, 0] - ic[1, 0], ic[0, 1] - ic[1, 1]) >= 0.8


def test_radii_too_close_to_one_half_are_refused_with_the_reason():
    with pytest.raises(ValueError, match=r"r_max must lie in .*diametrically opposite"):
        initial_conditions(1, 0.5 - 1e-12)


def test_the_direct_pair_sampler_matches_joint_rejection():
    # at r_max = 0.45 rejection still works (acceptance ~ 3 %): the direct sampler that takes
    # over after N_TRY rejections must draw from the same law
    from scipy.stats import ks_2samp

    from kicktimes.billiard.initial import _uniform_pair

    r = 0.45
    rng = np.random.default_rng(3)
    direct = np.array([_uniform_pair(rng, r) for _ in range(400)])  # (400, 2 xy, 2 disks)
    rej = initial_conditions(400, r, seed=5, method="uniform")
    d_direct = np.hypot(direct[:, 0, 0], direct[:, 1, 0])
    d_rej = np.hypot(rej[:, 0, 0], rej[:, 0, 1])
    assert ks_2samp(d_direct, d_rej).pvalue > 1e-3
    gap_direct = np.hypot(direct[:, 0, 0] - direct[:, 0, 1], direct[:, 1, 0] - direct[:, 1, 1])
    gap_rej = np.hypot(rej[:, 0, 0] - rej[:, 1, 0], rej[:, 0, 1] - rej[:, 1, 1])
    assert ks_2samp(gap_direct, gap_rej).pvalue > 1e-3
