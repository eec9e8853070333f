"""The N-disk engine in the periodic square box (issue 51): `simulate_disks(..., box=L)`.

The oracle is a brute-force event-driven simulator written here from the physics, not
from the engine: one global clock, every pair under its nine nearest images at every
event, positions wrapped into [0, L) after each flight, NumPy only.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

import kicktimes as kt
from kicktimes.billiard import box_side
from kicktimes.billiard.many_disks import engine_run
from kicktimes.stats import enskog_frequency

ELASTIC = 1
SHIFTS = np.array([(a, b) for a in (-1.0, 0.0, 1.0) for b in (-1.0, 0.0, 1.0)])


# --- the brute-force reference ------------------------------------------------------------
def next_contact(x, v, radii, box):
    """``(dt, i, j, image)``: the earliest contact of an approaching pair, over all pairs
    and the nine images ``x_j + box * shift`` of the second disk."""
    n = x.shape[0]
    i, j = np.triu_indices(n, 1)
    d = (x[i] - x[j])[:, None, :] - box * SHIFTS[None, :, :]  # (pairs, images, 2)
    w = (v[i] - v[j])[:, None, :]
    b = (d * w).sum(axis=2)
    ww = (w * w).sum(axis=2)
    sig = (radii[i] + radii[j])[:, None]
    c = (d * d).sum(axis=2) - sig * sig
    disc = b * b - ww * c
    ok = (b < 0.0) & (disc > 0.0)
    t = np.full(b.shape, np.inf)
    t[ok] = np.maximum(c[ok] / (-b[ok] + np.sqrt(disc[ok])), 0.0)
    p, s = np.unravel_index(int(np.argmin(t)), t.shape)
    return float(t[p, s]), int(i[p]), int(j[p]), SHIFTS[s]


def brute_force_box(state, radii, box, n_pp, masses=None):
    """The first ``n_pp`` disk-disk collisions ``(time, i, j)`` of the elastic rule in the
    periodic box, and the state at the last one."""
    x = np.array(state, dtype=float)[:, :2].copy()
    v = np.array(state, dtype=float)[:, 2:].copy()
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (x.shape[0],))
    m = np.ones(x.shape[0]) if masses is None else np.asarray(masses, dtype=float)
    t = 0.0
    log = []
    while len(log) < n_pp:
        dt, i, j, image = next_contact(x, v, radii, box)
        x = np.mod(x + v * dt, box)
        t += dt
        d = x[i] - (x[j] + box * image)
        d -= box * np.round(d / box)
        n = d / np.linalg.norm(d)
        p = (v[i] - v[j]) @ n
        v[i] -= 2.0 * m[j] / (m[i] + m[j]) * p * n
        v[j] += 2.0 * m[i] / (m[i] + m[j]) * p * n
        log.append((t, i, j))
    return np.array(log), np.column_stack([x, v])


def test_the_reference_finds_a_contact_across_the_edge():
    # two disks 0.1 apart through the edge x = 0 = L, approaching: contact at (0.1 - 0.06) / 2
    state = np.array([[0.05, 0.5, -1.0, 0.0], [0.95, 0.5, 1.0, 0.0]])
    log, end = brute_force_box(state, 0.03, 1.0, 1)
    assert log[0, 0] == pytest.approx(0.02, abs=1e-15)
    np.testing.assert_allclose(end[:, 2], [1.0, -1.0])


# --- the engine against the reference -------------------------------------------------------
@pytest.mark.parametrize("n, unequal", [(8, False), (13, True), (20, False)])
def test_the_engine_makes_the_brute_force_collision_sequence(n, unequal):
    rng = np.random.default_rng(n)
    radii = rng.uniform(0.05, 0.08, n) if unequal else np.full(n, 0.07)
    masses = rng.uniform(0.5, 2.0, n) if unequal else None
    box = 1.0
    state = kt.initial_state(n, radii, rng=n, rule="elastic", masses=masses, box=box)
    compared = 0
    worst = 0.0
    # windows of 25 collisions, each from the engine's state at the last one's time:
    # rounding differences (1e-16) grow by chaos, not over the window
    while compared < 200:
        log, _ = brute_force_box(state, radii, box, 26, masses)
        # (the run ends between the 25th and the 26th)
        t_end = 0.5 * (log[-2, 0] + log[-1, 0])
        log = log[:-1]
        run = kt.simulate_disks(state, radii, t_max=t_end, rule="elastic", masses=masses,
                                box=box)
        assert run.n_pp == len(log)
        assert (run.pp_i == log[:, 1]).all() and (run.pp_j == log[:, 2]).all()
        worst = max(worst, float(np.abs(run.pp_times - log[:, 0]).max()))
        compared += len(log)
        state = run.final_state
    assert worst < 1e-9


def test_a_window_of_50_collisions_matches_the_reference_in_one_piece():
    # in one piece, without restarts: rounding differences of 1e-16 grow by the chaos of
    # the disks (measured: beyond 1e-9 after 30-90 collisions of 8-20 disks, the pairs
    # after 60-180), so one piece is 50 collisions of 20 disks; the 200 above are windows
    n, r, box = 20, 0.05, 1.0
    state = kt.initial_state(n, r, rng=2, rule="elastic", box=box)
    log, _ = brute_force_box(state, r, box, 51)
    run = kt.simulate_disks(state, r, t_max=0.5 * (log[-2, 0] + log[-1, 0]), rule="elastic",
                            box=box)
    log = log[:-1]
    assert run.n_pp == 50
    assert (run.pp_i == log[:, 1]).all() and (run.pp_j == log[:, 2]).all()
    np.testing.assert_allclose(run.pp_times, log[:, 0], rtol=0, atol=1e-9)


# --- crossing the edge ----------------------------------------------------------------------
def test_a_disk_crosses_the_edge_and_comes_back_on_the_other_side():
    state = np.array([[0.9, 0.95, 0.6, 0.8]])
    run = kt.simulate_disks(state, 0.05, t_max=1.0, box=1.0)
    np.testing.assert_allclose(run.final_state[0], [0.5, 0.75, 0.6, 0.8], atol=1e-14)
    assert run.engine["cell_crossings"] >= 2
    assert run.n_wall == 0


def test_two_disks_collide_through_the_edge():
    # touching through x = 0: the engine sees the image, not the far disk
    state = np.array([[0.05, 0.5, -1.0, 0.0], [0.95, 0.5, 1.0, 0.0], [0.5, 0.1, 0.0, 1.0]])
    run = kt.simulate_disks(state, 0.03, t_max=0.03, rule="elastic", box=1.0)
    assert run.n_pp == 1
    assert (run.pp_i[0], run.pp_j[0]) == (0, 1)
    assert run.pp_times[0] == pytest.approx(0.02, abs=1e-14)
    np.testing.assert_allclose(run.final_state[:2, 2], [1.0, -1.0], atol=1e-14)
    # at 0.02 the contact (0.03 and 0.97), then 0.01 back apart
    np.testing.assert_allclose(run.final_state[:2, 0], [0.04, 0.96], atol=1e-14)


# --- invariants -----------------------------------------------------------------------------
def test_energy_and_total_momentum_are_conserved_over_a_long_elastic_run():
    n, box = 500, 1.0
    rng = np.random.default_rng(5)
    masses = rng.uniform(0.5, 2.0, n)
    state = kt.initial_state(n, None, packing=0.3, box=box, rule="elastic", masses=masses,
                             rng=5)
    r = math.sqrt(0.3 * box * box / (math.pi * n))
    run = kt.simulate_disks(state, r, t_max=40.0, rule="elastic", masses=masses, box=box)
    assert run.n_pp > 3 * 10**5
    e0 = np.sum(masses * (state[:, 2] ** 2 + state[:, 3] ** 2))
    e1 = np.sum(masses * (run.final_state[:, 2] ** 2 + run.final_state[:, 3] ** 2))
    p1 = (masses[:, None] * run.final_state[:, 2:]).sum(axis=0)
    assert abs(e1 / e0 - 1.0) < 1e-12
    # the initial momentum is 0 (initial_state); |p| per disk ~ 1
    assert np.abs((masses[:, None] * state[:, 2:]).sum(axis=0)).max() < 1e-12
    assert np.abs(p1).max() < 1e-9


@pytest.mark.parametrize("rule", [0, ELASTIC])
def test_no_overlap_at_any_event_and_at_the_end(rule):
    # (the debug observer checks every disk after every event: O(n) per event)
    n, phi, box = 150, 0.5, 1.0
    state = kt.initial_state(n, None, packing=phi, box=box, rng=9,
                             rule="mirror" if rule == 0 else "elastic")
    r = math.sqrt(phi * box * box / (math.pi * n))
    out = engine_run(state, np.full(n, r), rule, 3.0, debug=True, box=box, cap_hint=10**6)
    overlap, outside, checks = out["debug"]
    assert checks > 2 * 10**4
    assert overlap < 1e-12 and outside < 1e-12
    end = out["final_state"]
    assert ((end[:, :2] >= 0.0) & (end[:, :2] < box)).all()
    pairs = cKDTree(end[:, :2], boxsize=box).query_pairs(2.0 * r * (1.0 - 1e-12))
    assert len(pairs) == 0


# --- initial states -------------------------------------------------------------------------
def test_initial_states_in_the_box_reach_packing_0_3_at_2000_disks():
    n, phi, box = 2000, 0.3, 1.0
    s = kt.initial_state(n, None, packing=phi, box=box, rule="elastic", rng=1)
    r = math.sqrt(phi * box * box / (math.pi * n))
    assert n * math.pi * r * r / box ** 2 == pytest.approx(0.3)
    assert ((s[:, :2] >= 0.0) & (s[:, :2] < box)).all()
    assert len(cKDTree(s[:, :2], boxsize=box).query_pairs(2.0 * r * (1 - 1e-12))) == 0
    np.testing.assert_allclose(s[:, 2:].sum(axis=0), 0.0, atol=1e-10)
    assert np.sum(s[:, 2:] ** 2) == pytest.approx(n)
    # uniform: each quarter of the box holds a quarter of the centres (binomial, 5 sigma)
    q = np.histogram2d(s[:, 0], s[:, 1], bins=2, range=[[0, box], [0, box]])[0]
    assert np.abs(q - n / 4).max() < 5 * math.sqrt(n * 0.25 * 0.75)


def test_dense_box_states_are_grown_without_overlap():
    n, phi = 300, 0.6
    s = kt.initial_state(n, 0.02, packing=phi, box=1.0, rng=2)
    r = math.sqrt(phi / (math.pi * n))
    assert len(cKDTree(s[:, :2], boxsize=1.0).query_pairs(2.0 * r * (1 - 1e-12))) == 0


def test_box_side_gives_the_packing():
    L = box_side(2000, 0.01, packing=0.3)
    assert 2000 * math.pi * 0.01 ** 2 / L ** 2 == pytest.approx(0.3, rel=1e-14)


# --- Enskog-Henderson -----------------------------------------------------------------------
def box_frequency(n, phi, collisions_per_disk, blocks=10, seed=1):
    """``(measured / Enskog-Henderson, its standard error)`` of the collision frequency in
    the box (elastic, kT = 1/2), after 20 collisions per disk of equilibration."""
    box = 1.0
    r = math.sqrt(phi * box * box / (math.pi * n))
    nu = enskog_frequency(r, n, rule="elastic", area=box * box, kT=0.5)
    s = kt.initial_state(n, r, box=box, rule="elastic", rng=seed)
    s = kt.simulate_disks(s, r, t_max=20.0 / nu, rule="elastic", box=box).final_state
    t_max = collisions_per_disk / nu
    run = kt.simulate_disks(s, r, t_max=t_max, rule="elastic", box=box)
    assert run.kT == pytest.approx(0.5, rel=1e-12)
    counts = np.histogram(run.pp_times, bins=blocks, range=(0.0, t_max))[0]
    per = 2.0 * counts / (n * t_max / blocks) / nu
    return run.collision_frequency / nu, per.std(ddof=1) / math.sqrt(blocks)


def test_the_box_collision_frequency_is_enskog_hendersons_within_1_5_percent():
    # 2000 disks at packing 0.3, 400 collisions each (8e5 collisions, about 1 s)
    ratio, se = box_frequency(2000, 0.3, 400)
    assert 3.0 * se <= 0.015
    assert abs(ratio - 1.0) <= 0.015


# --- the record and bad input ---------------------------------------------------------------
def test_the_box_is_recorded_and_written(tmp_path):
    import json

    import pyarrow.parquet as pq

    s = kt.initial_state(50, 0.03, box=1.0, rng=1)
    run = kt.simulate_disks(s, 0.03, t_max=1.0, box=1.0)
    assert run.box == 1.0 and "box=1.0" in repr(run)
    run.to_parquet(tmp_path / "b.parquet")
    meta = json.loads(pq.read_table(tmp_path / "b.parquet").schema.metadata[b"kicktimes"])
    assert meta["box"] == 1.0
    circle = kt.simulate_disks(kt.initial_state(50, 0.03, rng=1), 0.03, t_max=0.5)
    assert circle.box is None and circle.meta["box"] is None


def test_bad_box_input_names_the_argument():
    s = kt.initial_state(50, 0.03, box=1.0, rng=1)
    with pytest.raises(ValueError, match="holes"):
        kt.simulate_disks(s, 0.03, t_max=1.0, box=1.0, holes=[[0.0, 0.1]])
    with pytest.raises(ValueError, match="log_walls"):
        kt.simulate_disks(s, 0.03, t_max=1.0, box=1.0, log_walls=True)
    with pytest.raises(ValueError, match="box"):
        kt.simulate_disks(s, 0.03, t_max=1.0, box=0.15)
    with pytest.raises(ValueError, match="box must"):
        kt.simulate_disks(s, 0.03, t_max=1.0, box=-1.0)
    bad = s.copy()
    bad[3, 0] = 1.2
    with pytest.raises(ValueError, match="disk 3's centre .* outside the box"):
        kt.simulate_disks(bad, 0.03, t_max=1.0, box=1.0)
    over = np.array([[0.01, 0.5, 1.0, 0.0], [0.99, 0.5, 1.0, 0.0]])
    with pytest.raises(ValueError, match="disks 0 and 1 overlap"):
        kt.simulate_disks(over, 0.03, t_max=1.0, box=1.0)
    with pytest.raises(ValueError, match=r"box / 6"):
        kt.initial_state(10, 0.1, box=0.5)
    with pytest.raises(ValueError, match="box must be at least 3 cells"):
        kt.initial_state(2, None, packing=0.5, box=0.5)
