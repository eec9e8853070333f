"""The N-disk engine (issue 40): its calendar and cells alone, agreement with the two-disk
simulator and with a brute-force reference, invariants, robustness, kinetic theory."""

import math
import os
import sys

import numpy as np
import pandas as pd
import pytest

import kicktimes as kt
from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.billiard import many_disks as md
from kicktimes.billiard.kernels import calendar as cal
from kicktimes.billiard.kernels import cells
from kicktimes.billiard.many_disks import engine_run
from kicktimes.stats import enskog_frequency

sys.path.insert(0, os.path.dirname(__file__))
import _disks_reference as ref  # noqa: E402

MIRROR, ELASTIC = 0, 1


# --- the calendar and the cells alone ----------------------------------------------------
def test_the_calendar_always_gives_the_earliest_event():
    rng = np.random.default_rng(1)
    for n in (1, 7, 300):
        times = rng.exponential(1.0, n)
        times[rng.random(n) < 0.1] = np.inf
        q = cal.new_calendar(n, 1.0 / n)
        cal.build(*q, times)
        now = 0.0
        for _ in range(3000):
            i, t = cal.top(*q)
            finite = times[np.isfinite(times)]
            if finite.size == 0:
                assert i == -1
                break
            assert t == finite.min() and times[i] == t
            now = t
            # the disk done gets a later event (sometimes far, sometimes none), another one
            # any time from now on
            new = now + rng.exponential(1.0) * (300.0 if rng.random() < 0.01 else 1.0)
            new = np.inf if rng.random() < 0.01 else new
            cal.update(*q, i, new)
            times[i] = new
            k = int(rng.integers(n))
            if np.isfinite(times[k]):
                times[k] = now + rng.exponential(0.3)
                cal.update(*q, k, times[k])


def test_a_cell_crossing_is_the_first_edge_the_centre_reaches():
    m, w = cells.grid(1000, 0.01)
    assert w >= 0.02 and m <= math.ceil(2 * math.sqrt(1000))
    rng = np.random.default_rng(2)
    for _ in range(200):
        x, y = rng.uniform(-0.9, 0.9, 2)
        a = rng.uniform(0, 2 * np.pi)
        vx, vy = math.cos(a), math.sin(a)
        c = cells.cell_of(x, y, m, w)
        dt, cn = cells.crossing(x, y, vx, vy, c, m, w)
        # just before: still in c; just after: in cn, a neighbour of c
        assert cells.cell_of(x + vx * dt * (1 - 1e-9), y + vy * dt * (1 - 1e-9), m, w) == c
        assert cells.cell_of(x + vx * (dt + 1e-9), y + vy * (dt + 1e-9), m, w) == cn
        assert abs(cn - c) in (1, m)


def test_cell_lists_insert_and_remove_in_any_order():
    head = np.full(4, -1, dtype=np.int32)
    links = np.zeros((5, 2), dtype=np.int32)
    for i in range(5):
        cells.insert(head, links, 0, 1, i, i % 2)
    for i in (2, 0, 4):
        cells.remove(head, links, 0, 1, i, i % 2)

    def members(c):
        out, k = [], head[c]
        while k >= 0:
            out.append(int(k))
            k = links[k, 0]
        return sorted(out)

    assert members(0) == [] and members(1) == [1, 3]


# --- two disks: the two-disk simulator, event by event ------------------------------------
def _states_along(ic, r, rule, n, dt, masses=None):
    """States of a two-disk run at times dt, 2 dt, ..., n dt."""
    return [simulate_two_particle(ic, r, t_max=k * dt, rule=rule, masses=masses).final_state
            for k in range(1, n + 1)]


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("r", [0.05, 0.2, (0.08, 0.15)])
def test_two_disks_agree_with_the_two_disk_simulator_event_by_event(rule, r):
    masses = (1.0, 2.5) if rule == "elastic" and isinstance(r, tuple) else None
    rr = list(r) if isinstance(r, tuple) else r
    worst = 0.0
    for ic in initial_conditions(3, max(np.atleast_1d(r)), rng=5, rule=rule, method="uniform"):
        for state in _states_along(ic, r, rule, 8, 23.7, masses):
            two = simulate_two_particle(state, r, t_max=150.0, rule=rule, masses=masses)
            many = kt.simulate_disks(state, rr, t_max=150.0, rule=rule, masses=masses)
            assert two.n_pp >= 2 and many.n_pp >= 2
            worst = max(worst, np.abs(two.pp_times[:2] - many.pp_times[:2]).max())
    assert worst < 1e-8


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_two_disk_collision_counts_agree_within_their_standard_error(rule):
    # whole runs agree only statistically (chaos): the mean counts of many ICs
    r, t_max = 0.1, 400.0
    ics = initial_conditions(40, r, rng=9, rule=rule, method="uniform")
    a = np.array([simulate_two_particle(ic, r, t_max=t_max, rule=rule).n_pp for ic in ics])
    b = np.array([kt.simulate_disks(ic, r, t_max=t_max, rule=rule).n_pp for ic in ics])
    diff = b - a
    se = diff.std(ddof=1) / math.sqrt(len(diff))
    assert abs(diff.mean()) <= 3.0 * se + 1e-12


# --- N <= 20: the brute-force reference, event by event ------------------------------------
@pytest.mark.parametrize("n, rule, unequal", [(3, "mirror", False), (8, "elastic", False),
                                              (12, "mirror", True), (20, "elastic", True)])
def test_the_brute_force_reference_gives_the_same_next_collisions(n, rule, unequal):
    rng = np.random.default_rng(n)
    radii = rng.uniform(0.04, 0.09, n) if unequal else np.full(n, 0.07)
    masses = rng.uniform(0.5, 2.0, n) if rule == "elastic" and unequal else None
    state = kt.initial_state(n, radii, rng=n, rule=rule, masses=masses)
    compared = 0
    worst = 0.0
    window = 4.0 if n > 5 else 40.0
    for _ in range(12):
        run = kt.simulate_disks(state, radii, t_max=window, rule=rule, masses=masses)
        log, _ = ref.simulate(state, radii, window, rule=rule, masses=masses, n_pp=3)
        k = min(3, len(log))
        assert run.n_pp >= k
        assert (run.pp_i[:k] == log[:k, 1]).all() and (run.pp_j[:k] == log[:k, 2]).all()
        worst = max(worst, np.abs(run.pp_times[:k] - log[:k, 0]).max(initial=0.0))
        compared += k
        # on along the long run: the state at t = 1.7, 3.4, ...
        state = kt.simulate_disks(state, radii, t_max=1.7, rule=rule, masses=masses).final_state
    assert compared >= 24 and worst < 1e-8


def test_the_brute_force_reference_agrees_over_a_window():
    # a whole window of 20 disks: every collision, and the state at its end
    n = 20
    state = kt.initial_state(n, 0.08, rng=4)
    run = kt.simulate_disks(state, 0.08, t_max=1.5)
    log, end = ref.simulate(state, 0.08, 1.5)
    assert run.n_pp == len(log) > 15
    assert (run.pp_i == log[:, 1]).all() and (run.pp_j == log[:, 2]).all()
    np.testing.assert_allclose(run.pp_times, log[:, 0], rtol=0, atol=1e-8)
    np.testing.assert_allclose(run.final_state, end, rtol=0, atol=1e-7)


# --- invariants ---------------------------------------------------------------------------
def _debug_run(state, radii, rule, t_max, masses=None):
    out = engine_run(state, radii, rule, t_max, masses=masses, debug=True,
                     cap_hint=10**5)
    return out


def test_no_overlap_and_no_disk_outside_at_any_event_mirror_unit_speeds():
    n, phi = 150, 0.5
    state = kt.initial_state(n, None, packing=phi, rng=11)
    radii = np.full(n, math.sqrt(phi / n))
    out = _debug_run(state, radii, MIRROR, 8.0)
    overlap, outside, checks = out["debug"]
    assert checks == out["n_pp_total"] + out["n_wall"] + out["crossings"] + out["stale"]
    assert out["n_pp_total"] > 20_000
    assert overlap < 1e-12 and outside < 1e-12
    speeds = np.hypot(out["final_state"][:, 2], out["final_state"][:, 3])
    assert np.abs(speeds - 1.0).max() < 1e-14


def test_elastic_runs_conserve_energy_and_total_angular_momentum():
    n = 60
    rng = np.random.default_rng(3)
    radii = rng.uniform(0.03, 0.06, n)
    masses = rng.uniform(0.5, 3.0, n)
    state = kt.initial_state(n, radii, rng=3, rule="elastic", masses=masses)
    out = _debug_run(state, radii, ELASTIC, 200.0, masses)
    overlap, outside, _ = out["debug"]
    assert overlap < 1e-12 and outside < 1e-12 and out["n_pp_total"] > 20_000
    s0, s1 = state, out["final_state"]

    def energy(s):
        return float(np.sum(masses * (s[:, 2] ** 2 + s[:, 3] ** 2)))

    def angular(s):
        return float(np.sum(masses * (s[:, 0] * s[:, 3] - s[:, 1] * s[:, 2])))

    assert abs(energy(s1) / energy(s0) - 1.0) < 1e-12
    assert abs(angular(s1) - angular(s0)) < 1e-10 * energy(s0)


def test_no_overlap_or_stall_at_packing_0_6():
    n, phi = 400, 0.6
    state = kt.initial_state(n, None, packing=phi, rng=6)
    r = math.sqrt(phi / n)
    run = kt.simulate_disks(state, r, t_max=8.0)
    assert run.n_pp > 100_000
    t = run.pp_times
    assert (np.diff(t) >= 0).all() and t[-1] > 7.9
    # every disk keeps colliding (none lost, none stuck)
    assert np.bincount(np.concatenate([run.pp_i, run.pp_j]), minlength=n).min() > 100
    from scipy.spatial import cKDTree

    end = run.final_state
    assert not cKDTree(end[:, :2]).query_pairs(2 * r * (1 - 1e-10))
    assert (np.hypot(end[:, 0], end[:, 1]) <= 1 - r + 1e-12).all()


@pytest.mark.slow
def test_no_overlap_lost_collision_or_stall_over_1e8_collisions_at_packing_0_6():
    n, phi = 1000, 0.6
    state = kt.initial_state(n, None, packing=phi, rng=7)
    r = math.sqrt(phi / n)
    nu = enskog_frequency(r, n)
    t_max = 1e8 / (0.5 * n * nu)
    out = engine_run(state, np.full(n, r), MIRROR, t_max, log=False)
    assert out["status"] == 0
    from scipy.spatial import cKDTree

    end = out["final_state"]
    assert not cKDTree(end[:, :2]).query_pairs(2 * r * (1 - 1e-10))


# --- holes, samples, wall log ----------------------------------------------------------------
def test_disks_escape_through_holes_and_the_rest_go_on():
    n = 40
    state = kt.initial_state(n, 0.04, rng=8)
    run = kt.simulate_disks(state, 0.04, t_max=30.0, holes=[(0.0, 0.4)], sample=[0, 1],
                            tau=0.5, log_walls=True)
    esc = run.escape_times
    assert 5 < np.isfinite(esc).sum() < n
    out = run.escaped
    assert (np.diff(esc[out]) >= 0).all()
    # an escaped disk stops on the wall, inside the hole, and collides no more
    for k in out[:5]:
        x, y = run.final_state[k, :2]
        assert abs(math.hypot(x, y) - 0.96) < 1e-12 and abs(math.atan2(y, x)) <= 0.4
        assert (run.collision_times(int(k)) <= esc[k]).all()
    # the run went on after the first escape
    assert (run.pp_times > esc[out[0]]).sum() > 10
    assert run.walls is not None and set(run.walls.disk) <= {0, 1}
    assert run.samples.shape == (61, 2, 2)


@pytest.mark.parametrize("observers", [False, True])
def test_renumbering_the_disks_in_space_changes_no_event(monkeypatch, observers):
    # the engine renumbers its disks by cell as they diffuse (kd.relabel, from 2048 disks
    # on); renumbering after every collision must leave every output as it was, bitwise
    n, r = 60, 0.04
    state = kt.initial_state(n, r, rng=8)
    kw = dict(holes=[(0.0, 0.1)], sample=[0, 5, 17], tau=0.5, log_walls=True) if observers \
        else {}

    def run(sweeps, min_disks):
        monkeypatch.setattr(md, "REORDER_SWEEPS", sweeps)
        monkeypatch.setattr(md, "REORDER_MIN_DISKS", min_disks)
        return kt.simulate_disks(state, r, t_max=20.0, **kw)

    plain, renumbered = run(10, 10**9), run(1 / n, 0)
    assert plain.n_pp > 500
    pd.testing.assert_frame_equal(plain.collisions, renumbered.collisions)
    np.testing.assert_array_equal(plain.final_state, renumbered.final_state)
    if observers:
        assert np.isfinite(plain.escape_times).sum() > 5
        np.testing.assert_array_equal(plain.escape_times, renumbered.escape_times)
        pd.testing.assert_frame_equal(plain.walls, renumbered.walls)
        np.testing.assert_array_equal(plain.samples, renumbered.samples)


def test_samples_are_the_positions_at_k_tau():
    state = kt.initial_state(30, 0.05, rng=12)
    run = kt.simulate_disks(state, 0.05, t_max=2.0, sample=[3, 7], tau=0.25)
    for k, t in enumerate(run.sample_times):
        if t == 0:
            np.testing.assert_allclose(run.samples[k], state[[3, 7], :2])
            continue
        at = kt.simulate_disks(state, 0.05, t_max=float(t)).final_state
        np.testing.assert_allclose(run.samples[k], at[[3, 7], :2], atol=1e-9)


def test_collisions_are_sorted_by_time_with_i_below_j():
    state = kt.initial_state(200, None, packing=0.3, rng=13)
    run = kt.simulate_disks(state, math.sqrt(0.3 / 200), t_max=2.0)
    df = run.collisions
    assert list(df.columns) == ["time", "i", "j"]
    assert (df.i < df.j).all() and df.time.is_monotonic_increasing
    k = int(df.i.iloc[0])
    assert run.collision_times(k)[0] == df.time.iloc[0]
    assert run.n_events == run.n_pp + run.n_wall


# --- initial states -----------------------------------------------------------------------
@pytest.mark.parametrize("phi", [0.1, 0.45, 0.7])
def test_initial_states_have_the_packing_asked_and_no_overlap(phi):
    n = 300
    s = kt.initial_state(n, None, packing=phi, rng=1)
    r = math.sqrt(phi / n)
    from scipy.spatial import cKDTree

    assert not cKDTree(s[:, :2]).query_pairs(2 * r * (1 - 1e-12))
    assert (np.hypot(s[:, 0], s[:, 1]) <= 1 - r + 1e-12).all()
    np.testing.assert_allclose(np.hypot(s[:, 2], s[:, 3]), 1.0, atol=1e-15)
    kt.simulate_disks(s, r, t_max=0.1)  # accepted as is


def test_elastic_initial_states_lie_on_the_energy_shell():
    m = np.linspace(1.0, 4.0, 50)
    s = kt.initial_state(50, 0.05, rng=2, rule="elastic", masses=m)
    assert abs(np.sum(m * (s[:, 2] ** 2 + s[:, 3] ** 2)) - 50.0) < 1e-10


def test_initial_positions_are_close_to_uniform():
    # the relaxation: the density in the inner half of the room is its area's share
    n = 2000
    s = kt.initial_state(n, None, packing=0.1, rng=3)
    rho = 1.0 - math.sqrt(0.1 / n)
    inner = (np.hypot(s[:, 0], s[:, 1]) < rho / math.sqrt(2)).mean()
    assert abs(inner - 0.5) < 4 * math.sqrt(0.25 / n)


# --- kinetic theory: Enskog with Henderson's contact value -----------------------------------
def test_the_whole_table_collision_frequency_is_enskogs_within_4_percent():
    n, phi = 3000, 0.2
    r = math.sqrt(phi / n)
    state = kt.initial_state(n, r, rng=21)
    run = kt.simulate_disks(state, r, t_max=1.0)
    assert abs(run.collision_frequency / enskog_frequency(r, n) - 1.0) < 0.04


def _bulk_ratio(n, phi, t_max, seed, rule="mirror", r_bulk=0.6):
    """Measured / Enskog collision frequency in the bulk ``|x| < r_bulk``: the collisions
    whose contact point lies there, per unit area and time, over ``n_b nu(n_b) / 2``."""
    r = math.sqrt(phi / n)
    state = kt.initial_state(n, r, rng=seed, rule=rule)
    out = engine_run(state, np.full(n, r), MIRROR if rule == "mirror" else ELASTIC, t_max,
                     contacts=True, sample=np.arange(n), tau=t_max / 40, cap_hint=10**6)
    cx, cy = out["contacts"]
    area = math.pi * r_bulk ** 2
    hits = np.count_nonzero(np.hypot(cx, cy) < r_bulk)
    inside = (np.hypot(out["samples"][..., 0], out["samples"][..., 1]) < r_bulk).sum(axis=1)
    n_b = float(inside.mean())
    nu = 2.0 * hits / (t_max * n_b)
    return nu / enskog_frequency(r, int(round(n_b)), area=area, rule=rule), n_b


def test_the_bulk_collision_frequency_is_enskogs_within_2_percent():
    ratio, _ = _bulk_ratio(3000, 0.25, 1.0, 31)
    assert abs(ratio - 1.0) < 0.02


@pytest.mark.slow
@pytest.mark.parametrize("phi", [0.05, 0.1, 0.2, 0.3, 0.4])
def test_bulk_and_whole_table_frequencies_against_enskog_henderson(phi):
    n = 3000
    r = math.sqrt(phi / n)
    ratio, _ = _bulk_ratio(n, phi, 40.0 / enskog_frequency(r, n), 41)
    assert abs(ratio - 1.0) < 0.02
    if 0.1 <= phi <= 0.3:
        state = kt.initial_state(n, r, rng=42)
        run = kt.simulate_disks(state, r, t_max=40.0 / enskog_frequency(r, n))
        assert abs(run.collision_frequency / enskog_frequency(r, n) - 1.0) < 0.04


def test_elastic_bulk_frequency_uses_the_maxwellian_mean_relative_speed():
    ratio, _ = _bulk_ratio(3000, 0.2, 1.0, 32, rule="elastic")
    assert abs(ratio - 1.0) < 0.03


# --- bad input ----------------------------------------------------------------------------
def test_bad_input_names_the_argument():
    s = kt.initial_state(10, 0.05, rng=0)
    bad = s.copy()
    bad[4, :2] = bad[7, :2] + [0.05, 0.0]
    with pytest.raises(ValueError, match="disks 4 and 7 overlap"):
        kt.simulate_disks(bad, 0.05, t_max=1.0)
    bad = s.copy()
    bad[2, :2] = [0.97, 0.0]
    with pytest.raises(ValueError, match="disk 2's centre .* outside the table"):
        kt.simulate_disks(bad, 0.05, t_max=1.0)
    with pytest.raises(ValueError, match="cannot exist"):
        kt.simulate_disks(s, 0.31, t_max=1.0)
    with pytest.raises(ValueError, match="t_max"):
        kt.simulate_disks(s, 0.05, t_max=-1.0)
    with pytest.raises(ValueError, match="t_max=1000000000000.0: .* memory"):
        kt.simulate_disks(kt.initial_state(1000, 0.02, rng=0), 0.02, t_max=1e12)
    with pytest.raises(ValueError, match="speed must be 1"):
        kt.simulate_disks(s * [1, 1, 2, 2], 0.05, t_max=1.0)
    with pytest.raises(ValueError, match="masses apply to rule='elastic'"):
        kt.simulate_disks(s, 0.05, t_max=1.0, masses=np.ones(10))
    with pytest.raises(ValueError, match="sample"):
        kt.simulate_disks(s, 0.05, t_max=1.0, sample=[10])
    with pytest.raises(ValueError, match="max_events"):
        kt.simulate_disks(s, 0.05, t_max=100.0, max_events=10)
    with pytest.raises(ValueError, match="shape"):
        kt.simulate_disks(s[:, :3], 0.05, t_max=1.0)
    with pytest.raises(TypeError, match="log_walls"):
        kt.simulate_disks(s, 0.05, t_max=1.0, log_walls=1)
    with pytest.raises(ValueError, match="packing must lie in"):
        kt.initial_state(100, None, packing=0.8)
    with pytest.raises(ValueError, match="cannot exist"):
        kt.initial_state(100, None, packing=0.95)
    with pytest.raises(ValueError, match="n_disks"):
        kt.initial_state(0, 0.1)


# --- the command line ------------------------------------------------------------------------
def test_the_command_line_writes_the_log_and_prints_enskogs_frequency(tmp_path):
    import pyarrow.parquet as pq
    from click.testing import CliRunner

    from kicktimes.cli import main

    out = tmp_path / "d"
    result = CliRunner().invoke(main, ["simulate", "--disks", "500", "--packing", "0.2",
                                       "--t-max", "1", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "Enskog-Henderson" in result.output
    table = pq.read_table(out / "disks.parquet")
    assert table.column_names == ["time", "i", "j"] and table.num_rows > 1000
    assert b"kicktimes" in table.schema.metadata
    bad = CliRunner().invoke(main, ["simulate", "--disks", "500", "--packing", "0.8",
                                    "--out", str(out)])
    assert bad.exit_code != 0 and "--packing must lie in (0.0, 0.7]" in bad.output


# --- the disks' numbering in space -------------------------------------------------------------
def test_cell_order_is_a_permutation_with_the_escaped_last():
    m = 5
    rng = np.random.default_rng(3)
    c = rng.integers(-1, m * m, size=200)
    order = cells.cell_order(c, m)
    assert sorted(order.tolist()) == list(range(200))
    ranked = c[order]
    n_out = int((c < 0).sum())
    assert n_out > 0 and (ranked[-n_out:] < 0).all() and (ranked[:-n_out] >= 0).all()
    # the disks of one cell are contiguous: as many runs of equal cells as cells
    seen = ranked[:-n_out]
    assert 1 + np.count_nonzero(np.diff(seen)) == np.unique(seen).size
