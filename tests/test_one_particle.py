"""The kicked one-disk billiard."""

import math

import numpy as np
import pytest

from kicktimes import initial_conditions, read_run, schedules, simulate_one_particle
from kicktimes.billiard import KickLaw

STATE = np.array([0.12, -0.31, 0.6, 0.8])


def test_sin_theta_is_conserved_without_kicks_over_a_million_collisions():
    r = 0.01
    run = simulate_one_particle(STATE, r, t_max=2.0e6)
    s = run.boundary.sin_theta.to_numpy()
    assert s.size > 1_000_000
    expected = (STATE[0] * STATE[3] - STATE[1] * STATE[2]) / (1 - r)
    assert np.abs(s - expected).max() <= 1e-12
    # the centre stays on |x| = 1 - r at every contact
    log = run.boundary_log
    assert np.abs(np.hypot(log.x, log.y) - (1 - r)).max() <= 1e-12


def test_sin_theta_changes_only_across_kicks():
    rng = np.random.default_rng(2)
    kicks = np.sort(rng.uniform(0, 5000, 200))
    run = simulate_one_particle(STATE, 0.02, t_max=5000.0, kicks=kicks, rng=3)
    b = run.boundary
    t = b.time.to_numpy()
    s = b.sin_theta.to_numpy()
    kicked = np.searchsorted(kicks, t[1:]) > np.searchsorted(kicks, t[:-1])
    np.testing.assert_allclose(s[1:][~kicked], s[:-1][~kicked], rtol=0, atol=1e-12)
    assert (np.abs(s[1:][kicked] - s[:-1][kicked]) > 1e-9).mean() > 0.9
    assert run.n_kicks == 200


def test_uniform_kick_sets_the_velocity_direction_to_the_given_angle():
    run = simulate_one_particle(STATE, 0.02, t_max=0.05, kicks=KickLaw([0.01], angles=[1.0]))
    np.testing.assert_allclose(run.final_state[2:], [math.cos(1.0), math.sin(1.0)], atol=1e-15)
    np.testing.assert_allclose(
        run.final_state[:2], STATE[:2] + 0.01 * STATE[2:] + 0.04 * run.final_state[2:], atol=1e-15
    )


def test_gaussian_kick_rotates_the_velocity_and_keeps_the_speed():
    state = np.array([0.0, 0.0, 1.5, 0.0])
    run = simulate_one_particle(state, 0.02, t_max=0.1,
                                kicks=KickLaw([0.05], angle="gaussian", angles=[0.3]))
    np.testing.assert_allclose(run.final_state[2:], [1.5 * math.cos(0.3), 1.5 * math.sin(0.3)])
    run = simulate_one_particle(state, 0.02, t_max=0.1,
                                kicks=KickLaw([0.05], angle="gaussian", sigma=0.2), rng=1)
    assert run.sigma == 0.2 and run.kick_angles.shape == (1,)


def test_kick_at_the_instant_of_a_boundary_collision_comes_after_the_reflection():
    r = 0.02
    state = np.array([0.0, 0.0, 1.0, 0.0])
    t_hit = 1 - r
    # a kick exactly at the contact, pointing straight back inward
    run = simulate_one_particle(state, r, t_max=1.5, kicks=KickLaw([t_hit], angles=[np.pi]))
    b = run.boundary
    assert b.time.iloc[0] == t_hit
    assert b.sin_theta.iloc[0] == 0.0  # logged with the incoming velocity
    np.testing.assert_allclose(run.final_state, [(1 - r) - (1.5 - t_hit), 0, -1, 0], atol=1e-12)
    # a kick at the contact pointing outward: the reflection already happened, so the
    # disk is reflected again at once (a second logged collision at the same time)
    run = simulate_one_particle(state, r, t_max=1.5, kicks=KickLaw([t_hit], angles=[0.3]))
    assert run.boundary.time.iloc[1] == pytest.approx(t_hit, abs=1e-15)
    assert run.final_state[2] < 0
    # and the outcome is deterministic
    again = simulate_one_particle(state, r, t_max=1.5, kicks=KickLaw([t_hit], angles=[0.3]))
    assert np.array_equal(again.final_state, run.final_state)


def test_common_random_numbers_keep_nearby_runs_together_until_the_next_boundary_collision():
    r = 0.02
    rng = np.random.default_rng(5)
    kicks = np.sort(rng.uniform(0, 50, 30))
    a = simulate_one_particle(STATE, r, t_max=50.0, kicks=kicks, rng=7, n_steps=250, tau=0.2)
    twin = STATE + np.array([1e-6, 0, 0, 0])
    b = simulate_one_particle(twin, r, t_max=50.0,
                              kicks=KickLaw(a.kick_times, angles=a.kick_angles), n_steps=250,
                              tau=0.2)
    first_hit = a.boundary.time.iloc[0]
    early = a.sample_times < first_hit
    sep = np.hypot(*(a.samples - b.samples).T)
    assert (sep[early] <= 1e-6 * (1 + 1e-9)).all()
    # without shared angles the first kick separates them by O(1)
    c = simulate_one_particle(twin, r, t_max=50.0, kicks=a.kick_times, rng=8, n_steps=250,
                              tau=0.2)
    assert np.hypot(*(a.samples - c.samples).T).max() > 0.1


def test_schedules_drive_the_billiard_reproducibly():
    sched = schedules.Poisson(0.05)
    a = simulate_one_particle(STATE, 0.02, t_max=1000.0, kicks=sched, rng=11)
    b = simulate_one_particle(STATE, 0.02, t_max=1000.0, kicks=sched, rng=11)
    assert np.array_equal(a.kick_times, b.kick_times)
    assert np.array_equal(a.kick_angles, b.kick_angles)
    assert a.boundary.equals(b.boundary)
    assert 20 < a.n_kicks < 90
    assert ((a.kick_angles >= 0) & (a.kick_angles < 2 * np.pi)).all()


def test_paper_sampling_ends_steps_at_kicks_and_collisions():
    kicks = [1.234, 7.5]
    run = simulate_one_particle(STATE, 0.02, n_steps=200, tau=0.3, sampling="paper", kicks=kicks,
                                rng=1)
    assert np.isin(kicks, run.sample_times).all()
    assert np.isin(run.boundary.time, run.sample_times).all()
    assert (np.diff(run.sample_times) <= 0.3 + 1e-12).all()


def test_uniform_sampling_interpolates_on_the_grid():
    run = simulate_one_particle(STATE, 0.02, n_steps=100, tau=0.25)
    np.testing.assert_allclose(run.sample_times, 0.25 * np.arange(101))
    np.testing.assert_allclose(run.samples[0], STATE[:2])
    # speed 1: consecutive samples at most tau apart, and the disk stays inside
    assert (np.hypot(*np.diff(run.samples, axis=0).T) <= 0.25 + 1e-12).all()
    assert (np.hypot(*run.samples.T) <= 0.98 + 1e-12).all()


def test_run_round_trips_through_parquet(tmp_path):
    run = simulate_one_particle(STATE, 0.02, t_max=100.0,
                                kicks=KickLaw(schedules.Poisson(0.1), angle="gaussian", sigma=0.5),
                                rng=3,
                                )
    run.to_parquet(tmp_path / "one.parquet")
    back = read_run(tmp_path / "one.parquet")
    assert back.meta == run.meta
    assert np.array_equal(back.kick_times, run.kick_times)
    assert np.array_equal(back.kick_angles, run.kick_angles)
    assert back.boundary.equals(run.boundary)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(r=1.0, t_max=1.0), "r must lie in"),
        (dict(r=0.02, t_max=10.0, kicks=[2.0, 1.0]), "sorted"),
        (dict(r=0.02, t_max=10.0, kicks=[-1.0]), ">= 0"),
        (dict(r=0.02, t_max=10.0, kicks=[11.0]), r"\[0, t_max"),
        (dict(r=0.02, t_max=10.0, kicks=[np.nan]), "finite"),
    ],
)
def test_bad_arguments_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        simulate_one_particle(STATE, **kwargs)


def test_bad_states_raise():
    with pytest.raises(ValueError, match="outside the table"):
        simulate_one_particle([0.99, 0.0, 1.0, 0.0], 0.02, t_max=1.0)
    with pytest.raises(ValueError, match="non-zero"):
        simulate_one_particle([0.0, 0.0, 0.0, 0.0], 0.02, t_max=1.0)
    with pytest.raises(ValueError, match="shape"):
        simulate_one_particle(np.zeros((2, 4)), 0.02, t_max=1.0)


# ------------------------------------------------------------ grazing and bad input
def test_a_kick_onto_the_wall_tangent_slides_on():
    # the example: a kick at t = 0 turns the disk on the wall to tangent; it was
    # reflected again and again at that instant until MemoryError
    r = 0.05
    run = simulate_one_particle([0.95, 0, -1, 0], r, t_max=50.0,
                                kicks=KickLaw([0.0], angles=[math.pi / 2]))
    assert run.n_kicks == 1
    assert np.hypot(*run.final_state[:2]) <= 1 - r + 1e-12
    assert np.hypot(*run.final_state[2:]) == pytest.approx(1.0, abs=1e-12)
    # sliding: contacts every 2 rho sin(1e-4), the disk goes round at speed 1
    np.testing.assert_allclose(np.diff(run.boundary.time[:50]), 2 * 0.95 * math.sin(1e-4),
                               rtol=1e-7)
    angle = np.unwrap(run.boundary.s.to_numpy())
    assert (angle[-1] - angle[0]) * 0.95 == pytest.approx(50.0, rel=1e-3)


def test_a_tangent_initial_state_gives_sin_theta_one_and_stays_grazing():
    # at the bottom of the table moving left: clockwise, sin_theta = -1
    run = simulate_one_particle([0.0, -0.98, -1.0, 0.0], 0.02, t_max=5.0)
    assert run.boundary.sin_theta.iloc[0] == pytest.approx(-1.0, abs=1e-15)
    assert (run.boundary.sin_theta < -1 + 1e-8).all()


def test_grazing_does_not_touch_ordinary_orbits():
    # sin_theta = 0.999 (chord angle 0.045, far above 1e-4) keeps its angle exactly
    s = 0.999
    run = simulate_one_particle([0.0, 0.0, s, math.sqrt(1 - s * s)], 0.02, t_max=50.0)
    np.testing.assert_allclose(run.boundary.sin_theta.iloc[1:], run.boundary.sin_theta.iloc[1],
                               atol=1e-13)


def test_kicks_given_as_a_string_raise_a_type_error_naming_kicks():
    with pytest.raises(TypeError, match="kicks must be None, a sequence of kick times or a "
                                        "schedule .* got the string 'poisson'"):
        simulate_one_particle(STATE, 0.02, t_max=10.0, kicks="poisson")


def test_a_pandas_series_of_times_is_taken_as_times_not_as_a_schedule():
    import pandas as pd

    run = simulate_one_particle(STATE, 0.02, t_max=10.0, kicks=pd.Series([1.0, 2.0]), rng=1)
    assert run.kick_times.tolist() == [1.0, 2.0]


def test_messages_show_plain_floats():
    with pytest.raises(ValueError) as info:
        simulate_one_particle(STATE, 0.02, t_max=10.0, kicks=np.array([-2.0, 1.0]))
    assert "got -2.0" in str(info.value) and "np.float64" not in str(info.value)


@pytest.mark.parametrize(("kwargs", "match", "exc"), [
    (dict(state=[0.1, 0.0, 1e156, 0.0]), r"state: the disk's speed must be in \[1e-06", ValueError),
    (dict(state=[0.1, 0.0, 1e-300, 0.0]), r"state: the disk's speed must be in", ValueError),
    (dict(r=1 - 1e-9), r"r must lie in \(0.0, 0.999999\] for one disk", ValueError),
    (dict(t_max=1e300), r"t_max must lie in", ValueError),
    (dict(rng="seed", kicks=schedules.Poisson(1.0)), r"rng must be None, an int seed", TypeError),
])
def test_ranges_that_keep_the_arithmetic_finite(kwargs, match, exc):
    args = dict(state=STATE, r=0.02, t_max=10.0)
    args.update(kwargs)
    state, r = args.pop("state"), args.pop("r")
    with pytest.raises(exc, match=match):
        simulate_one_particle(state, r, **args)


def test_the_one_particle_event_budget():
    with pytest.raises(ValueError, match="max_events=20 collisions"):
        simulate_one_particle(STATE, 0.02, t_max=100.0, max_events=20)


def test_a_paper_run_cut_short_at_t0_by_every_kick_warns_that_it_covers_no_time():
    # found by the property tests: both paper steps end at the kicks at t = 0
    with pytest.warns(RuntimeWarning, match="covers no time"):
        run = simulate_one_particle([0.0, 0.0, 1.0, 0.0], 0.5, sampling="paper", n_steps=1,
                                    tau=1.0, kicks=[0.0, 0.0], rng=0)
    assert run.t_max == 0.0 and run.n_kicks == 2


# --- the paper's N(0, 1) kick angles, both readings ---------------------------------------


@pytest.mark.parametrize(("kick_angle", "direction"), [
    ("normal", lambda old, a: a),          # the new direction is the angle drawn
    ("gaussian", lambda old, a: old + a),  # the direction is rotated by it
])
def test_the_two_readings_of_normal_kick_angles(kick_angle, direction):
    old, a = math.pi / 2, 0.7
    state = np.array([0.0, 0.0, math.cos(old), math.sin(old)])
    run = simulate_one_particle(state, 0.02, t_max=0.02,
                                kicks=KickLaw(np.array([0.01]), angle=kick_angle, angles=[a]),
                               )
    want = direction(old, a)
    np.testing.assert_allclose(run.final_state[2:], [math.cos(want), math.sin(want)],
                               atol=1e-15)
    assert run.sigma == 1.0 and run.kick_angle == kick_angle


def test_normal_kick_angles_are_drawn_from_n_0_sigma_and_act_as_new_directions():
    from scipy import stats as sps

    from kicktimes.diagnostics import lyapunov

    state = initial_conditions(1, 0.02, rng=2)[0][0]
    kicks = np.sort(np.random.default_rng(0).uniform(0, 3000, 3000))
    run = simulate_one_particle(state, 0.02, t_max=3000.0,
                                kicks=KickLaw(kicks, angle="normal", sigma=0.5), rng=7)
    assert sps.kstest(run.kick_angles, sps.norm(scale=0.5).cdf).pvalue > 1e-3
    # the same angles as "uniform" new directions give the very same run and FTLE
    same = simulate_one_particle(state, 0.02, t_max=3000.0,
                                 kicks=KickLaw(run.kick_times, angle="uniform",
                                               angles=run.kick_angles))
    np.testing.assert_array_equal(run.final_state, same.final_state)
    short = KickLaw(kicks[kicks < 600], angles=run.kick_angles[kicks < 600])
    assert (lyapunov(state, 0.02, kicks=short.replace(angle="normal"), n_steps=3000, tau=0.2)
            == lyapunov(state, 0.02, kicks=short, n_steps=3000, tau=0.2))
