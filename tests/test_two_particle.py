"""The two-disk simulator: invariants, records, sampling, determinism and bad input."""

import dataclasses
import math
import warnings

import numpy as np
import pytest
from numba import njit

from kicktimes import initial_conditions, read_run, simulate_two_particle
from kicktimes.billiard.kernels import two


@njit  # not cached: numba's cache does not see changes in the kernels it calls
def _invariant_violations(st, r, rule, n_events):
    """Run ``n_events`` events of the production event code and track the worst violations.

    Returns (outside, overlap, speed_error, energy_error, n_pp).
    """
    rho = 1.0 - r
    sigma = 2.0 * r
    ev = np.empty(3)
    two.init_events(st, ev, (rho, rho, 1.0, 1.0), sigma)
    e0 = st[3] ** 2 + st[4] ** 2 + st[7] ** 2 + st[8] ** 2
    outside = 0.0
    overlap = 0.0
    speed_err = 0.0
    energy_err = 0.0
    n_pp = 0
    for _ in range(n_events):
        k, _ = two.next_event(two.load(st, ev))
        two.process_event(st, ev, k, (rho, rho, 1.0, 1.0), sigma, rule)
        n_pp += k == 2
        for i in range(2):
            o = 1 + 4 * i
            outside = max(outside, math.hypot(st[o], st[o + 1]) - rho)
            if rule == 0:
                speed_err = max(speed_err, abs(math.hypot(st[o + 2], st[o + 3]) - 1.0))
        overlap = max(overlap, sigma - math.hypot(st[1] - st[5], st[2] - st[6]))
        e = st[3] ** 2 + st[4] ** 2 + st[7] ** 2 + st[8] ** 2
        energy_err = max(energy_err, abs(e - e0))
    return outside, overlap, speed_err, energy_err, n_pp


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_invariants_hold_over_a_million_events(rule):
    r = 0.05  # large disks: many disk-disk collisions per boundary collision
    method = "paper" if rule == "mirror" else "uniform"
    ic = initial_conditions(1, r, rng=11, method=method, rule=rule)[0]
    st = np.concatenate([[0.0], ic.ravel(), [0.0, (ic[:, 2:] ** 2).sum()]])
    outside, overlap, speed_err, energy_err, n_pp = _invariant_violations(
        st, r, 0 if rule == "mirror" else 1, 1_000_000
    )
    assert outside <= 1e-12
    assert overlap <= 1e-12
    assert speed_err <= 1e-12
    if rule == "elastic":
        assert energy_err <= 1e-12
    assert n_pp > 10_000  # the disks really interacted


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_sin_theta_unchanged_between_boundary_collisions_without_disk_disk_collision(rule):
    r = 0.03
    ic = initial_conditions(1, r, rng=5, method="uniform", rule=rule)[0]
    run = simulate_two_particle(ic, r, t_max=20000.0, rule=rule)
    b = run.boundary
    changed_any = False
    for p in (0, 1):
        rows = b[b.particle == p]
        t = rows.time.to_numpy()
        s = rows.sin_theta.to_numpy()
        # a disk-disk collision between consecutive boundary collisions of disk p?
        n_between = np.searchsorted(run.pp_times, t[1:]) - np.searchsorted(run.pp_times, t[:-1])
        free = n_between == 0
        assert free.sum() > 1000
        np.testing.assert_allclose(s[1:][free], s[:-1][free], rtol=0, atol=1e-12)
        changed_any |= bool((np.abs(s[1:][~free] - s[:-1][~free]) > 1e-6).any())
    assert changed_any


def test_disk_on_a_diameter_with_radial_velocity_bounces_between_antipodes():
    r = 0.01
    # disk 1 parked far off the diameter, moving along a parallel chord, never meets disk 0
    ic = [[0.2, 0.0, 1.0, 0.0], [0.0, 0.5, 1.0, 0.0]]
    run = simulate_two_particle(ic, r, t_max=10.0)
    b = run.boundary[run.boundary.particle == 0]
    rho = 1 - r
    expected = (rho - 0.2) + 2 * rho * np.arange(len(b))
    np.testing.assert_allclose(b.time, expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.sin_theta, 0.0, atol=1e-15)
    np.testing.assert_allclose(b.s.to_numpy()[::2], 0.0, atol=1e-12)
    np.testing.assert_allclose(b.s.to_numpy()[1::2], np.pi, atol=1e-12)


def test_head_on_disks_collide_at_the_hand_worked_time():
    r = 0.05
    ic = [[-0.5, 0.0, 1.0, 0.0], [0.5, 0.0, -1.0, 0.0]]
    run = simulate_two_particle(ic, r, t_max=0.6, rule="elastic")
    # gap 1.0 - 2r closes at relative speed 2
    assert run.pp_times == pytest.approx([(1.0 - 2 * r) / 2])
    # elastic head-on: the velocities are exchanged
    np.testing.assert_allclose(run.final_state[:, 2], [-1.0, 1.0], atol=1e-15)


def test_disks_starting_nearly_in_contact_collide_at_once_when_approaching():
    r = 0.02
    gap = 2 * r + 1e-13
    ic = [[-gap / 2, 0.0, 1.0, 0.0], [gap / 2, 0.0, -1.0, 0.0]]
    run = simulate_two_particle(ic, r, t_max=0.1)
    assert run.n_pp == 1 and run.pp_times[0] < 1e-12
    # and separating disks in contact do not collide
    ic = [[-gap / 2, 0.0, -1.0, 0.0], [gap / 2, 0.0, 1.0, 0.0]]
    assert simulate_two_particle(ic, r, t_max=0.1).n_pp == 0


def test_mirror_rule_is_time_reversible():
    r = 0.04
    ic = initial_conditions(1, r, rng=2)[0]
    fwd = simulate_two_particle(ic, r, t_max=30.0)
    assert fwd.n_pp >= 1
    back_ic = fwd.final_state.copy()
    back_ic[:, 2:] *= -1.0
    back = simulate_two_particle(back_ic, r, t_max=30.0)
    np.testing.assert_allclose(back.final_state[:, :2], ic[:, :2], atol=1e-8)
    np.testing.assert_allclose(-back.final_state[:, 2:], ic[:, 2:], atol=1e-8)
    np.testing.assert_allclose(30.0 - back.pp_times[::-1], fwd.pp_times, atol=1e-8)


def test_records_have_the_documented_shapes_and_ranges():
    r = 0.02
    ic = initial_conditions(1, r, rng=3)[0]
    run = simulate_two_particle(ic, r, t_max=500.0)
    assert run.pp_times.dtype == np.float64
    assert (np.diff(run.pp_times) > 0).all()
    assert ((run.pp_times > 0) & (run.pp_times <= 500.0)).all()
    b = run.boundary
    assert list(b.columns) == ["time", "particle", "s", "sin_theta"]
    assert (np.diff(b.time) >= 0).all()
    assert set(b.particle.unique()) <= {0, 1}
    assert ((b.s >= 0) & (b.s < 2 * np.pi)).all()
    assert (np.abs(b.sin_theta) <= 1).all()
    assert run.final_state.shape == (2, 4)
    assert run.sample_times.shape == (0,)


def test_final_state_continues_the_run():
    r = 0.02
    ic = initial_conditions(1, r, rng=4)[0]
    whole = simulate_two_particle(ic, r, t_max=200.0)
    first = simulate_two_particle(ic, r, t_max=120.0)
    rest = simulate_two_particle(first.final_state, r, t_max=80.0)
    np.testing.assert_allclose(np.r_[first.pp_times, 120.0 + rest.pp_times], whole.pp_times,
                               atol=1e-9)


def test_uniform_sampling_gives_n_steps_plus_one_samples_on_the_grid():
    r = 0.02
    ic = initial_conditions(1, r, rng=6)[0]
    run = simulate_two_particle(ic, r, n_steps=1000, tau=0.3, track=1)
    assert run.t_max == pytest.approx(300.0)
    np.testing.assert_allclose(run.sample_times, 0.3 * np.arange(1001))
    assert run.samples.shape == (1001, 2)
    np.testing.assert_allclose(run.samples[0], ic[1, :2])
    np.testing.assert_allclose(run.samples[-1], run.final_state[1, :2], atol=1e-12)
    assert (np.hypot(*run.samples.T) <= 1 - r + 1e-12).all()
    # unit speed: consecutive samples are at most tau apart
    assert (np.hypot(*np.diff(run.samples, axis=0).T) <= 0.3 + 1e-12).all()


def test_paper_sampling_cuts_steps_at_every_collision():
    r = 0.02
    ic = initial_conditions(1, r, rng=7)[0]
    run = simulate_two_particle(ic, r, n_steps=3000, tau=0.3, sampling="paper")
    steps = np.diff(run.sample_times)
    assert run.sample_times.shape == (3001,)
    assert (steps <= 0.3 + 1e-12).all() and (steps >= 0).all()
    assert run.t_max == pytest.approx(run.sample_times[-1])
    assert run.t_max < 3000 * 0.3
    collisions = np.sort(np.r_[run.pp_times, run.boundary.time.to_numpy()])
    # every collision ends a step, so it is a sample time
    assert np.isin(collisions, run.sample_times).all()
    # and a step is shorter than tau only when it ends at a collision
    short = steps < 0.3 - 1e-9
    assert np.isin(run.sample_times[1:][short], collisions).all()


def test_same_input_gives_identical_arrays():
    ic = initial_conditions(1, 0.02, rng=8)[0]
    a = simulate_two_particle(ic, 0.02, n_steps=500, tau=0.2)
    b = simulate_two_particle(ic, 0.02, n_steps=500, tau=0.2)
    assert np.array_equal(a.pp_times, b.pp_times)
    assert a.boundary.equals(b.boundary)
    assert np.array_equal(a.samples, b.samples)


def test_run_round_trips_through_parquet(tmp_path):
    ic = initial_conditions(1, 0.02, rng=9)[0]
    run = simulate_two_particle(ic, 0.02, n_steps=200, tau=0.3, rule="elastic")
    run = dataclasses.replace(run, seed=9)  # the IC's seed, recorded by the caller
    path = tmp_path / "run.parquet"
    run.to_parquet(path)
    back = read_run(path)
    assert back.meta == run.meta
    assert back.meta["seed"] == 9 and back.meta["rule"] == "elastic"
    assert back.meta["version"]
    assert np.array_equal(back.pp_times, run.pp_times)
    assert back.boundary.equals(run.boundary)
    assert np.array_equal(back.samples, run.samples)
    assert np.array_equal(back.ic, run.ic) and np.array_equal(back.final_state, run.final_state)
    assert [p.name for p in tmp_path.iterdir()] == ["run.parquet"]


def test_reading_a_foreign_parquet_file_is_refused(tmp_path):
    import pandas as pd

    path = tmp_path / "other.parquet"
    pd.DataFrame({"a": [1, 2]}).to_parquet(path)
    with pytest.raises(ValueError, match="not a kicktimes run"):
        read_run(path)


GOOD_IC = [[0.1, 0.2, 0.6, 0.8], [-0.3, -0.1, 0.0, 1.0]]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(r=0.0, t_max=1.0), "r must lie in"),
        (dict(r=0.5, t_max=1.0), "r must lie in"),
        (dict(r=float("nan"), t_max=1.0), "r must be finite"),
        (dict(r=0.02, t_max=0.0), "t_max must lie in"),
        (dict(r=0.02, t_max=float("inf")), "t_max must be finite"),
        (dict(r=0.02, n_steps=0, tau=0.3), "n_steps must be an integer in \\[1, "),
        (dict(r=0.02, n_steps=10, tau=-0.3), "tau must lie in"),
        (dict(r=0.02, n_steps=10), "tau must be given"),
        (dict(r=0.02, t_max=1.0, rule="sticky"), "rule must be one of"),
        (dict(r=0.02, t_max=1.0, sampling="random"), "sampling must be one of"),
        (dict(r=0.02, n_steps=10, tau=0.3, sampling="paper", t_max=3.0), "do not pass t_max"),
        (dict(r=0.02, t_max=1.0, track=2), "track must be 0 or 1"),
        (dict(r=0.02), "give t_max"),
    ],
)
def test_bad_arguments_raise_value_errors_naming_them(kwargs, match):
    with pytest.raises(ValueError, match=match):
        simulate_two_particle(GOOD_IC, **kwargs)


@pytest.mark.parametrize(
    ("ic", "match"),
    [
        ([[0.99, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]], "outside the table"),
        ([[0.0, 0.0, 1.0, 0.0], [0.03, 0.0, 1.0, 0.0]], "overlap"),
        ([[0.0, 0.0, 2.0, 0.0], [0.5, 0.0, 1.0, 0.0]], "speed must be 1"),
        ([[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 1.0, 0.0]], "speed must be 1"),
        ([[0.0, np.nan, 1.0, 0.0], [0.5, 0.0, 1.0, 0.0]], "finite"),
        ([[0.0, 0.0, 1.0, 0.0]], "shape"),
    ],
)
def test_bad_initial_conditions_raise(ic, match):
    with pytest.raises(ValueError, match=match):
        simulate_two_particle(ic, 0.02, t_max=1.0)


def test_elastic_rule_accepts_any_speeds_but_not_both_at_rest():
    ic = [[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, -1.3, 0.0]]
    run = simulate_two_particle(ic, 0.02, t_max=0.5, rule="elastic")
    assert run.pp_times == pytest.approx([(0.5 - 0.04) / 1.3])
    np.testing.assert_allclose(run.final_state[:, 2], [-1.3, 0.0], atol=1e-15)
    with pytest.raises(ValueError, match="at rest"):
        simulate_two_particle([[0, 0, 0, 0], [0.5, 0, 0, 0]], 0.02, t_max=2.0, rule="elastic")


# ------------------------------------------------------- grazing, budgets and stalls
def _invariants_hold(run, r):
    rho = 1.0 - r
    fs = run.final_state
    assert (np.hypot(fs[:, 0], fs[:, 1]) <= rho + 1e-12).all()
    assert np.hypot(*(fs[0, :2] - fs[1, :2])) >= 2 * r - 1e-12
    if run.samples.size:
        assert (np.hypot(run.samples[:, 0], run.samples[:, 1]) <= rho + 1e-12).all()
    t = run.boundary_log.time
    assert (np.diff(t) >= 0).all() and (t <= run.t_max).all()


def test_a_disk_tangent_to_the_wall_slides_on_instead_of_reflecting_forever():
    # the example: it grew buffers until MemoryError
    r = 0.05
    run = simulate_two_particle([[0.95, 0, 0, 1], [0, 0.5, 0, 1]], r, t_max=50.0)
    _invariants_hold(run, r)
    np.testing.assert_allclose(np.hypot(run.final_state[:, 2], run.final_state[:, 3]), 1.0,
                               atol=1e-12)
    first = run.boundary[run.boundary.particle == 0].iloc[:3]
    assert first.sin_theta.iloc[0] == 1.0  # the tangent contact, counter-clockwise
    # then chords of angle 2e-4: one contact every 2 rho sin(1e-4), advancing along the wall
    np.testing.assert_allclose(np.diff(first.time), 2 * 0.95 * np.sin(1e-4), rtol=1e-9)
    np.testing.assert_allclose(np.diff(first.s), 2e-4, rtol=1e-6)


def test_paper_sampling_of_a_tangent_disk_advances_the_clock():
    run = simulate_two_particle([[0.95, 0, 0, 1], [0, 0.5, 0, 1]], 0.05, n_steps=2000, tau=0.1,
                                sampling="paper")
    assert run.t_max > 0.3  # was 0.0: 2,001 reflections at one instant
    assert (np.diff(run.sample_times) > 0).all()


# disk 1 touches the wall and disk 0, both moving tangentially: under the mirror rule disk 1
# bounces between them at t = 0 (a pinch), and every paper step ends at one of those events
PINCHED = [[0.85, 0.0, 0.0, 1.0], [0.95, 0.0, 0.0, 1.0]]


def test_a_paper_run_that_covers_no_time_warns_why():
    match = r"ic: the paper-sampled run covers no time \(t_max = 0.0\): all n_steps = 5 steps"
    with pytest.warns(RuntimeWarning, match=match):
        run = simulate_two_particle(PINCHED, 0.05, n_steps=5, tau=0.3, sampling="paper")
    assert run.t_max == 0.0 and (run.sample_times == 0.0).all()
    # the same state is stuck for good: enough steps end in the stall error
    with pytest.raises(ValueError, match="ic: the run makes no progress"):
        simulate_two_particle(PINCHED, 0.05, n_steps=100_000, tau=0.3, sampling="paper")


def test_paper_runs_that_cover_time_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # the elastic pinch resolves after three events at t = 0 and then moves on
        run = simulate_two_particle(PINCHED, 0.05, n_steps=5, tau=0.3, sampling="paper",
                                    rule="elastic")
        assert run.t_max > 0.0
        # disks touching head-on collide at t = 0, and the steps after it cover time
        run = simulate_two_particle([[-0.05, 0.0, 1.0, 0.0], [0.05, 0.0, -1.0, 0.0]], 0.05,
                                    n_steps=1, tau=0.3, sampling="paper")
        assert run.t_max == 0.3


def test_a_grazing_contact_keeps_the_energy_under_the_elastic_rule():
    r = 0.05
    ic = [[0.0, -0.95, 0.6, 0.0], [0.0, 0.3, 0.0, 0.8]]
    run = simulate_two_particle(ic, r, t_max=30.0, rule="elastic")
    _invariants_hold(run, r)
    assert (run.final_state[:, 2:] ** 2).sum() == pytest.approx(1.0, abs=1e-12)


def test_the_event_budget_ends_a_run_with_an_error_naming_max_events():
    ic = initial_conditions(1, 0.05, rng=3)[0]
    with pytest.raises(ValueError, match=r"max_events=50 collisions"):
        simulate_two_particle(ic, 0.05, t_max=1000.0, max_events=50)
    assert simulate_two_particle(ic, 0.05, t_max=10.0, max_events=10**4).n_boundary > 0


def test_a_run_too_long_for_the_default_budget_is_refused_up_front():
    ic = initial_conditions(1, 0.05, rng=3)[0]
    with pytest.raises(ValueError, match=r"t_max=1000000000.0 needs about .* max_events="):
        simulate_two_particle(ic, 0.05, t_max=1e9)


def test_jammed_disks_end_in_a_clear_error_or_a_valid_run():
    # r close to 1/2: the disks only fit nearly diametrically opposite
    r = 0.4999
    ic = initial_conditions(1, r, rng=2, method="uniform", rule="elastic")[0]
    try:
        run = simulate_two_particle(ic, r, t_max=5.0, rule="elastic")
    except ValueError as exc:
        assert "max_events" in str(exc) or "no progress" in str(exc)
    else:
        _invariants_hold(run, r)


@pytest.mark.parametrize(("kwargs", "match"), [
    (dict(t_max=1e300), r"t_max must lie in \(0.0, 1000000000000.0\], got 1e\+300"),
    (dict(n_steps=10**9, tau=0.1), r"n_steps must be an integer in \[1, 100000000\]"),
    (dict(t_max=1e6, tau=1e-6), r"t_max / tau must be <= 100000000 steps"),
    (dict(n_steps=10**8, tau=1e6), r"n_steps \* tau must be <= 1e\+12"),
    (dict(t_max=10.0, max_events=0), r"max_events must be an integer >= 1"),
])
def test_time_arguments_are_range_checked(kwargs, match):
    ic = initial_conditions(1, 0.02, rng=1)[0]
    with pytest.raises(ValueError, match=match):
        simulate_two_particle(ic, 0.02, **kwargs)


@pytest.mark.parametrize("speed", [1e156, 1e-300, 1e7])
def test_speeds_outside_the_range_are_refused_naming_ic(speed):
    ic = [[0.1, 0.0, speed, 0.0], [0.0, 0.5, 0.0, 1.0]]
    with pytest.raises(ValueError, match=r"ic: disk 0 speed must be 0 or in \[1e-06, 1e\+06\]"):
        simulate_two_particle(ic, 0.02, t_max=1.0, rule="elastic")


@pytest.mark.reproducibility
def test_simulators_reproduce_the_golden_outputs_bit_for_bit():
    # tests/data/kernels_golden.npz holds every output array of 66 varied runs (both rules,
    # all samplings, radii 0.005-0.3, uniform/gaussian/scatter kicks) recorded before the
    # kernels were optimised; a speed-up must not change a single bit of them
    import importlib.util
    from pathlib import Path

    data = Path(__file__).parent / "data"
    spec = importlib.util.spec_from_file_location("kernel_cases", data / "kernel_cases.py")
    cases = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cases)
    ref = cases.load(data / "kernels_golden.npz")
    assert len(ref) == 762
    new = cases.outputs(small=True)
    differ = cases.differences(ref, new)
    import numba

    if tuple(int(v) for v in numba.__version__.split(".")[:2]) < (0, 68):
        # numba 0.60 (the oldest declared) compiles the elastic scattering kicks' Newton
        # iteration (math.sin/acos) to code that differs in the last bit: 3.9e-13 relative
        # at most on these cases. Everything else is bitwise there too.
        last_bit = [k for k in differ if "_scatter_elastic_" in k]
        for key in last_bit:
            np.testing.assert_allclose(new[key], ref[key], rtol=1e-11, atol=1e-11)
        differ = [k for k in differ if k not in last_bit]
    assert differ == []
