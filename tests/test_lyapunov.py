"""Finite-time Lyapunov exponents (Benettin twins)."""

import numpy as np
import pytest

from kicktimes import initial_conditions, simulate_one_particle, simulate_two_particle
from kicktimes.diagnostics import lyapunov


@pytest.fixture(scope="module")
def ics():
    return initial_conditions(6, 0.03, seed=3)


def test_unkicked_one_particle_exponent_tends_to_zero(ics):
    short = np.mean([lyapunov(ic[0], 0.03, n_steps=2500, tau=0.2).lam for ic in ics])
    long = np.mean([lyapunov(ic[0], 0.03, n_steps=25000, tau=0.2).lam for ic in ics])
    assert long < short
    assert 0 <= long < 0.01


def test_two_particle_exponent_is_positive_and_stable_to_halving_d0(ics):
    lam = np.array([lyapunov(ic, 0.03, n_steps=10000, tau=0.2).lam for ic in ics])
    lam_half = np.array([lyapunov(ic, 0.03, n_steps=10000, tau=0.2, d0=1e-4).lam for ic in ics])
    assert (lam > 0.1).all()
    assert abs(lam.mean() - lam_half.mean()) < 0.1 * lam.mean()


def test_paper_variant_is_the_maximum_of_its_parts(ics):
    res = lyapunov(ics[0], 0.03, n_steps=5000, tau=0.2, variant="paper")
    assert res.variant == "paper"
    assert res.lam == max(res.lam_x, res.lam_y)
    assert np.isnan(lyapunov(ics[0], 0.03, n_steps=100, tau=0.2).lam_x)


@pytest.mark.parametrize("sampling", ["uniform", "paper"])
def test_both_sampling_modes_give_positive_two_particle_exponents(ics, sampling):
    res = lyapunov(ics[1], 0.03, n_steps=10000, tau=0.2, sampling=sampling)
    assert res.lam > 0.05
    assert res.n_renorm > 0.5 * 10000
    if sampling == "paper":
        assert res.total_time < 10000 * 0.2


def test_kicks_make_the_one_particle_billiard_chaotic_only_with_shared_angles(ics):
    rng = np.random.default_rng(1)
    kicks = np.sort(rng.uniform(0, 2000, 40))
    res = lyapunov(ics[0, 0], 0.03, n_steps=10000, tau=0.2, kicks=kicks, rng=2)
    unkicked = lyapunov(ics[0, 0], 0.03, n_steps=10000, tau=0.2)
    # kicks randomise the direction but are shared: the exponent stays finite and small
    assert np.isfinite(res.lam) and res.n_forced < 0.01 * res.n_renorm
    assert res.lam != unkicked.lam


def test_independent_twin_kicks_separate_the_twins_at_every_kick(ics):
    kicks = np.sort(np.random.default_rng(3).uniform(0, 2000, 40))
    shared = lyapunov(ics[1, 0], 0.03, n_steps=10000, tau=0.2, kicks=kicks, rng=5)
    indep = lyapunov(ics[1, 0], 0.03, n_steps=10000, tau=0.2, kicks=kicks, rng=5,
                     twin_kicks="independent")
    # each independent kick adds about log(O(1) / d0) ~ 7 over 2000 time units
    assert indep.lam > shared.lam + 0.05
    with pytest.raises(ValueError, match="twin_kicks must be one of"):
        lyapunov(ics[1, 0], 0.03, n_steps=10, tau=0.2, twin_kicks="some")


def test_run_objects_are_accepted_and_reuse_their_kicks(ics):
    run = simulate_one_particle(ics[0, 0], 0.03, n_steps=2000, tau=0.2,
                                kicks=np.array([10.0, 20.0, 30.0]), rng=4)
    a = lyapunov(run)
    b = lyapunov(ics[0, 0], 0.03, n_steps=2000, tau=0.2, kicks=run.kick_times,
                 kick_angles=run.kick_angles)
    assert a == b
    two = simulate_two_particle(ics[0], 0.03, n_steps=2000, tau=0.2)
    assert lyapunov(two) == lyapunov(ics[0], 0.03, n_steps=2000, tau=0.2)


def test_a_run_longer_than_its_samples_is_accepted(ics):
    run = simulate_one_particle(ics[0, 0], 0.03, t_max=100.0, n_steps=300, tau=0.3,
                                kicks=np.array([10.0, 95.0]), rng=1)
    res = lyapunov(run)
    assert res.total_time <= 90.0 and np.isfinite(res.lam)


def test_results_are_deterministic(ics):
    assert lyapunov(ics[2], 0.03, n_steps=3000, tau=0.2) == lyapunov(ics[2], 0.03, n_steps=3000,
                                                                     tau=0.2)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(n_steps=10, tau=0.2, variant="max"), "variant must be one of"),
        (dict(n_steps=10, tau=0.2, d0=0.0), "d0 must lie in"),
        (dict(tau=0.2), "n_steps"),
        (dict(n_steps=10, tau=0.2, kicks=[1.0]), "one-disk"),
    ],
)
def test_bad_arguments_raise(ics, kwargs, match):
    with pytest.raises(ValueError, match=match):
        lyapunov(ics[0], 0.03, **kwargs)


@pytest.mark.slow
def test_two_particle_exponent_at_r_003_with_paper_scale_runs():
    ics = initial_conditions(50, 0.03, seed=8)
    lam = np.array([lyapunov(ic, 0.03, n_steps=25000, tau=0.2).lam for ic in ics])
    lam_half = np.array([lyapunov(ic, 0.03, n_steps=25000, tau=0.2, d0=1e-4).lam for ic in ics])
    sem = lam.std(ddof=1) / np.sqrt(len(lam))
    assert lam.mean() > 10 * sem
    assert abs(lam.mean() - lam_half.mean()) < 4 * sem
