"""Kinetic kicks: the kicked disk's kick rate is the kinetic rate of its own angular momentum."""

import numpy as np
import pytest

from kicktimes import initial_conditions, simulate_one_particle
from kicktimes.billiard import KickLaw
from kicktimes.diagnostics import Tangent, Twin, lyapunov
from kicktimes.schedules import KineticRate
from kicktimes.stats import mean_kinetic_rate

R = 0.02
RHO = 1.0 - R


@pytest.fixture(scope="module")
def kinetic():
    return KineticRate(R)


@pytest.fixture(scope="module")
def state():
    return initial_conditions(1, R, rng=11)[0, 0]


@pytest.fixture(scope="module")
def run(kinetic, state):
    return simulate_one_particle(state, R, t_max=3000.0, kicks=KickLaw(kinetic, angle="scatter"),
                                 rng=5)


def test_the_table_interpolates_the_partner_averaged_rate(kinetic):
    ell = np.array([-0.9, -0.3, 0.0, 0.41, 0.77])
    exact = mean_kinetic_rate(R, ell)
    assert np.allclose(kinetic.rate(ell), exact, rtol=2e-3)
    # the rate is even in L (a mirror image of the orbit) and largest for radial orbits
    assert np.allclose(kinetic.rate(ell), kinetic.rate(-ell), rtol=1e-9)
    assert kinetic.rate(0.0) > kinetic.rate(0.9 * RHO)


def test_each_interval_is_its_exponential_number_over_the_rate_the_previous_kick_left(
        kinetic, state, run):
    # the numbers are the generator's first draws; L between two kicks is read off the
    # boundary collisions in between (sin_theta = L / rho at unit speed, kept by the wall)
    e = np.random.default_rng(5).standard_exponential(kinetic.capacity(3000.0))
    times = run.kick_times
    ell0 = state[0] * state[3] - state[1] * state[2]
    assert times[0] == pytest.approx(e[0] / kinetic.rate(ell0), rel=1e-12)
    log = run.boundary_log
    checked = 0
    for i in range(1, times.size):
        inside = (log.time > times[i - 1]) & (log.time < times[i])
        if not inside.any():
            continue
        ell = RHO * log.sin_theta[inside][0]
        assert times[i] - times[i - 1] == pytest.approx(e[i] / kinetic.rate(ell), rel=1e-9)
        checked += 1
    assert checked >= 10


def test_a_kinetic_run_replays_bitwise_from_its_kicks(state, run):
    again = simulate_one_particle(state, R, t_max=3000.0,
                                  kicks=KickLaw(run.kick_times, angle="scatter",
                                                angles=run.kick_angles))
    assert again.boundary_log.time.tobytes() == run.boundary_log.time.tobytes()
    assert again.final_state.tobytes() == run.final_state.tobytes()


def test_the_one_pass_the_tangent_kernel_and_the_replay_give_one_exponent(kinetic, state):
    kw = {"n_steps": 4000, "tau": 0.3, "kicks": KickLaw(kinetic, angle="scatter"), "rng": 2}
    res, run = lyapunov(state, R, method=Tangent(return_run=True), **kw)
    assert res.lam == lyapunov(state, R, **kw).lam == lyapunov(run).lam
    assert res.n_perturbations == run.n_kicks > 0
    twin = lyapunov(state, R, method=Twin(d0=1e-9), **kw)
    assert twin.lam == pytest.approx(res.lam, rel=0.05)


def test_radial_orbits_are_kicked_more_often_than_orbits_near_the_rim(kinetic):
    # one kick only (its delay from the initial L): the first kick time of many draws
    rim = np.array([0.0, -0.9 * RHO, 1.0, 0.0])
    radial = np.array([0.1, 0.0, 1.0, 0.0])
    first = {}
    for name, s in (("rim", rim), ("radial", radial)):
        first[name] = np.mean([simulate_one_particle(s, R, t_max=2000.0, kicks=kinetic,
                                                     rng=seed).kick_times[0]
                               for seed in range(40)])
    assert first["radial"] < first["rim"]


@pytest.mark.parametrize("bad, match", [
    ({"rule": "elastic"}, "mirror-rule KineticRate needs unit speeds"),
    ({"angles": np.zeros((3, 2))}, "angles: kinetic kicks"),
])
def test_options_kinetic_kicks_cannot_honour_are_refused(kinetic, state, bad, match):
    with pytest.raises(ValueError, match=match):
        simulate_one_particle(state, R, t_max=10.0, kicks=KickLaw(kinetic, angle="scatter", **bad))


def test_a_table_of_another_radius_or_a_slow_disk_is_refused(kinetic, state):
    with pytest.raises(ValueError, match="tabulated for r=0.02"):
        simulate_one_particle(state, 0.03, t_max=10.0, kicks=kinetic)
    with pytest.raises(ValueError, match="unit speed"):
        simulate_one_particle(np.array([0.1, 0.2, 0.3, 0.4]), R, t_max=10.0, kicks=kinetic)
