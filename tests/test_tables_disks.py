"""The N-disk engine in a stadium and an ellipse (issue 63): two disks against a NumPy event
loop, invariants (no centre leaves the table, speeds and energy kept), the circle bitwise
unchanged, the wall log and the tangent observer in a table, the pressure, bad input, and
the collision frequency against Enskog-Henderson in the stadium's bulk."""

import math

import numpy as np
import pandas as pd
import pytest

import kicktimes as kt
from kicktimes.billiard import many_disks as md
from kicktimes.billiard.kernels import tables as kt_tables
from kicktimes.billiard.many_disks import engine_run
from kicktimes.stats import enskog_frequency
from kicktimes.tables import Circle, Ellipse, Stadium

MIRROR, ELASTIC = 0, 1
TABLES = [Stadium(1.0), Ellipse(1.5, 1.0)]


def _radius(table, n, packing):
    """The radius of ``n`` disks at ``packing`` = disks' area over the table's area."""
    return math.sqrt(packing * table.area(0.0) / (math.pi * n))


# --- two disks against a plain NumPy event loop -----------------------------------------------
def _reference(state, r, table, t_max, rule):
    """Disk-disk collision times ``(t, i, j)`` of a global-clock NumPy loop: every pair and
    every wall at every event, the wall through `kernels.tables` (`hit`, `contact`,
    `bounce`), the pair's contact time the root of its quadratic."""
    kind, p0, p1, p2 = table.kernel(r)
    x = np.array(state, dtype=float)[:, :2].copy()
    v = np.array(state, dtype=float)[:, 2:].copy()
    n = x.shape[0]
    t = 0.0
    log = []
    while True:
        hits = [kt_tables.hit(kind, p0, p1, p2, *x[k], *v[k]) for k in range(n)]
        kw = int(np.argmin([h[0] for h in hits]))
        tw = hits[kw][0]
        tp, pi, pj = np.inf, -1, -1
        for i in range(n):
            for j in range(i + 1, n):
                d, w = x[i] - x[j], v[i] - v[j]
                b, ww, c = d @ w, w @ w, d @ d - 4.0 * r * r
                if b < 0.0 and b * b - ww * c > 0.0:
                    tk = max(c / (-b + math.sqrt(b * b - ww * c)), 0.0)
                    if tk < tp:
                        tp, pi, pj = tk, i, j
        dt = min(tw, tp)
        if t + dt > t_max:
            return np.array(log).reshape(-1, 3)
        x += v * dt
        t += dt
        if tw <= tp:
            cx, cy, nx, ny, _ = kt_tables.contact(kind, p0, p1, p2, *x[kw], *v[kw],
                                                  hits[kw][1], hits[kw][2])
            x[kw] = cx, cy
            v[kw] = kt_tables.bounce(*v[kw], nx, ny)
        else:
            nrm = (x[pi] - x[pj]) / np.linalg.norm(x[pi] - x[pj])
            if rule == "mirror":
                v[pi] -= 2.0 * (v[pi] @ nrm) * nrm
                v[pj] -= 2.0 * (v[pj] @ nrm) * nrm
            else:
                p = (v[pi] - v[pj]) @ nrm
                v[pi] -= p * nrm
                v[pj] += p * nrm
            log.append((t, pi, pj))


def _two_disk_state(table, r, rng):
    from kicktimes.tables import uniform_state

    while True:
        a = uniform_state(table, r, rng=rng)
        b = uniform_state(table, r, rng=rng)
        if np.hypot(*(a[:2] - b[:2])) > 2.0 * r + 1e-6:
            return np.array([a, b])


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("table", TABLES, ids=repr)
def test_two_disks_in_a_table_agree_with_a_numpy_event_loop_event_by_event(table, rule):
    # chaos: round-off grows some 10-100 fold per collision of two disks this size (a
    # 1e-16 difference of the delayed flights is 1e-8 after four or five), so the first
    # collisions are compared: the first two to 1e-8, the first five to 1e-6
    r = 0.25
    gen = np.random.default_rng(5)
    first, worst, total = 0.0, 0.0, 0
    for _ in range(8):
        state = _two_disk_state(table, r, gen)
        if rule == "elastic":
            state[:, 2:] *= gen.uniform(0.5, 1.5, (2, 1))
        ref = _reference(state, r, table, 40.0, rule)
        run = kt.simulate_disks(state, r, t_max=40.0, rule=rule, table=table)
        assert run.n_pp == len(ref) or min(run.n_pp, len(ref)) >= 5
        k = min(len(ref), run.n_pp, 5)
        if k < 2:  # (a state may meet rarely: a bouncing-ball orbit of the stadium)
            continue
        np.testing.assert_array_equal(run.pp_i[:k], ref[:k, 1])
        first = max(first, np.abs(run.pp_times[:2] - ref[:2, 0]).max())
        worst = max(worst, np.abs(run.pp_times[:k] - ref[:k, 0]).max())
        total += k
    assert total >= 25
    assert first < 1e-8 and worst < 1e-6


# --- invariants -------------------------------------------------------------------------------
@pytest.mark.parametrize("rule", [MIRROR, ELASTIC])
@pytest.mark.parametrize("table", TABLES, ids=repr)
def test_no_overlap_no_centre_outside_and_speeds_kept_at_every_event(table, rule):
    n, phi = 200, 0.4
    r = _radius(table, n, phi)
    state = kt.initial_state(n, None, packing=phi, table=table, rng=11,
                             rule="mirror" if rule == MIRROR else "elastic")
    e0 = float(np.sum(state[:, 2:] ** 2))
    out = engine_run(state, np.full(n, r), rule, 8.0, debug=True, cap_hint=10**5,
                     sample=np.arange(n), tau=0.1, table=table)
    overlap, outside, checks = out["debug"]
    assert out["n_pp_total"] > 10_000 and out["n_wall"] > 1000
    assert checks == out["n_pp_total"] + out["n_wall"] + out["crossings"] + out["stale"]
    assert overlap < 1e-12 and outside < 1e-12
    assert table.contains(out["final_state"][:, :2], r).all()
    assert table.contains(out["samples"], r).all()
    v2 = out["final_state"][:, 2] ** 2 + out["final_state"][:, 3] ** 2
    if rule == MIRROR:
        assert np.abs(np.sqrt(v2) - 1.0).max() < 1e-12
    else:
        assert abs(v2.sum() / e0 - 1.0) < 1e-12


@pytest.mark.parametrize("table", [None, Circle()], ids=repr)
def test_the_circle_is_bitwise_the_same_with_table_none_or_circle(table):
    n, r = 80, 0.04
    state = kt.initial_state(n, r, rng=3)
    assert np.array_equal(state, kt.initial_state(n, r, rng=3, table=table))
    plain = kt.simulate_disks(state, r, t_max=5.0)
    run = kt.simulate_disks(state, r, t_max=5.0, table=table, log_walls=True)
    assert run.table == Circle() and plain.table == Circle()
    np.testing.assert_array_equal(plain.pp_times, run.pp_times)
    np.testing.assert_array_equal(plain.final_state, run.final_state)


@pytest.mark.parametrize("table", TABLES, ids=repr)
def test_renumbering_the_disks_in_a_table_changes_no_event(monkeypatch, table):
    # the pending wall contacts ("where") must move with their disks at a renumbering
    n = 60
    r = _radius(table, n, 0.3)
    state = kt.initial_state(n, None, packing=0.3, table=table, rng=8)

    def run(sweeps, min_disks):
        monkeypatch.setattr(md, "REORDER_SWEEPS", sweeps)
        monkeypatch.setattr(md, "REORDER_MIN_DISKS", min_disks)
        return kt.simulate_disks(state, r, t_max=10.0, table=table, log_walls=True)

    plain, renumbered = run(10, 10**9), run(1 / n, 0)
    assert plain.n_pp > 500
    pd.testing.assert_frame_equal(plain.collisions, renumbered.collisions)
    pd.testing.assert_frame_equal(plain.walls, renumbered.walls)
    np.testing.assert_array_equal(plain.final_state, renumbered.final_state)


@pytest.mark.parametrize("table", TABLES, ids=repr)
def test_the_wall_log_gives_each_contacts_birkhoff_coordinates(table):
    n = 40
    r = _radius(table, n, 0.2)
    state = kt.initial_state(n, None, packing=0.2, table=table, rng=4)
    run = kt.simulate_disks(state, r, t_max=40.0, table=table, sample=[0, 3], log_walls=True)
    w = run.walls
    assert len(w) > 20 and set(w.disk) <= {0, 3}
    assert ((w.s >= 0.0) & (w.s < table.perimeter(r))).all()
    assert (np.abs(w.sin_theta) <= 1.0).all()
    # each logged contact lies on the centre's curve
    t, d, x, y, _ = run.wall_log
    kind, p0, p1, p2 = table.kernel(r)
    from kicktimes.billiard.kernels.disk_walls import outside

    assert max(abs(outside(kind, p0, p1, p2, a, b)) for a, b in zip(x, y, strict=True)) < 1e-12


def test_the_tangent_observer_in_a_stadium_matches_finite_differences():
    table, n = Stadium(0.5), 8
    r = _radius(table, n, 0.15)
    state = kt.initial_state(n, None, packing=0.15, table=table, rng=6)
    radii = np.full(n, r)
    u = np.random.default_rng(2).normal(size=(n, 4))
    u[:, 2:] -= (np.sum(u[:, 2:] * state[:, 2:], axis=1) / 1.0)[:, None] * state[:, 2:]
    u /= np.linalg.norm(u)
    t, eps = 1.5, 1e-8
    out = engine_run(state, radii, MIRROR, t, tangent=u, segment=t,
                     on_segment=lambda *a: None, table=table)
    assert out["n_wall"] > 5 and out["n_pp_total"] > 5

    def end(s):
        s = s.copy()
        s[:, 2:] /= np.hypot(s[:, 2], s[:, 3])[:, None]
        return engine_run(s, radii, MIRROR, t, table=table)["final_state"]

    fd = (end(state + eps * u) - end(state - eps * u)) / (2.0 * eps)
    assert np.abs(out["tangent"] - fd).max() < 1e-4 * np.abs(fd).max()


def test_the_bulk_and_wall_pressures_in_a_stadium():
    table, n, phi = Stadium(1.0), 2000, 0.3
    r = _radius(table, n, phi)
    state = kt.initial_state(n, None, packing=phi, table=table, rule="elastic", rng=9)
    run = kt.simulate_disks(state, r, t_max=3.0, rule="elastic", table=table)
    p = run.pressure()
    assert p.packing == pytest.approx(phi, rel=1e-12)
    assert abs(p.z_bulk / p.henderson - 1.0) < 0.03
    assert abs(p.z_wall / p.z_virial - 1.0) < 0.05
    assert "Stadium(a=1.0)" in run.summary()


# --- bad input --------------------------------------------------------------------------------
def test_bad_tables_and_options_name_the_argument():
    table = Ellipse(1.5, 1.0)
    r = 0.05
    state = kt.initial_state(20, r, table=table, rng=1)
    with pytest.raises(TypeError, match="table"):
        kt.simulate_disks(state, r, t_max=1.0, table="stadium")
    with pytest.raises(TypeError, match="table"):
        kt.initial_state(20, r, table=1.0)
    with pytest.raises(ValueError, match="table"):
        kt.simulate_disks(state, r, t_max=1.0, table=table, box=2.0)
    with pytest.raises(ValueError, match="table"):
        kt.initial_state(20, r, table=Circle(), box=2.0)
    with pytest.raises(ValueError, match="holes"):
        kt.simulate_disks(state, r, t_max=1.0, table=table, holes=[(0.0, 0.1)])
    with pytest.raises(ValueError, match=r"r must lie in \(0.0, 0.666"):
        kt.simulate_disks(state[:1], 0.7, t_max=1.0, table=table)
    with pytest.raises(ValueError, match="one radius"):
        kt.simulate_disks(state, np.linspace(0.04, 0.05, 20), t_max=1.0, table=table)
    with pytest.raises(ValueError, match="bulk_radius"):
        kt.simulate_disks(state, r, t_max=1.0, table=table, bulk_radius=0.96)
    with pytest.raises(ValueError, match="outside"):
        kt.simulate_disks(np.array([[1.46, 0.0, 1.0, 0.0]]), r, t_max=1.0, table=table)
    with pytest.raises(ValueError, match="packing"):
        kt.initial_state(2000, None, packing=0.8, table=Ellipse(1.5, 1.0))


# --- kinetic theory: Enskog-Henderson in the stadium's bulk --------------------------------------
def _bulk_ratio(table, n, phi, per_disk, seed, r_bulk=0.6):
    """Measured / Enskog-Henderson collision frequency in the stadium's bulk: the centres
    within ``r_bulk`` of its segment ``[-a, a] x {0}`` (area ``pi r_b^2 + 4 a r_b``, the
    wall at least ``1 - r_bulk - r`` away), the collisions whose contact point lies there
    per unit time over half the time-averaged number of centres there, against Enskog's
    frequency at the region's own density (as tests/test_disks.py does in the circle)."""
    r = _radius(table, n, phi)
    state = kt.initial_state(n, None, packing=phi, table=table, rng=seed)
    t_max = per_disk / enskog_frequency(r, n, area=table.area(0.0))
    out = engine_run(state, np.full(n, r), MIRROR, t_max, contacts=True, sample=np.arange(n),
                     tau=t_max / 40, cap_hint=10**6, table=table)

    def inside(q):
        return np.hypot(np.maximum(np.abs(q[..., 0]) - table.a, 0.0), q[..., 1]) < r_bulk

    cx, cy = out["contacts"]
    hits = np.count_nonzero(inside(np.stack([cx, cy], axis=-1)))
    n_b = float(inside(out["samples"]).sum(axis=1).mean())
    area = math.pi * r_bulk ** 2 + 4.0 * table.a * r_bulk
    nu = 2.0 * hits / (t_max * n_b)
    k = int(round(n_b))
    return nu / enskog_frequency(r, k, area=area * k / n_b)


def _frequency_interval(ratios):
    """Mean and its 95 % t interval over independent states."""
    from scipy.stats import t as student

    m = float(np.mean(ratios))
    h = float(student.ppf(0.975, len(ratios) - 1) * np.std(ratios, ddof=1)
              / math.sqrt(len(ratios)))
    return m, m - h, m + h


def test_the_stadiums_bulk_collision_frequency_is_enskog_hendersons():
    ratios = [_bulk_ratio(Stadium(1.0), 2000, 0.3, 40.0, seed) for seed in (1, 2, 3)]
    m, lo, hi = _frequency_interval(ratios)
    assert abs(m - 1.0) < 0.015 and lo > 0.97 and hi < 1.03


@pytest.mark.full
def test_the_stadiums_bulk_collision_frequency_is_enskog_hendersons_to_1_5_percent():
    ratios = [_bulk_ratio(Stadium(1.0), 2000, 0.3, 200.0, seed) for seed in range(10, 26)]
    m, lo, hi = _frequency_interval(ratios)
    assert 0.985 < lo and hi < 1.015, (m, lo, hi)


def test_the_engine_s_tangent_stays_finite_over_long_flights_in_the_stadium():
    """One disk in Stadium(1): no collisions, so the stadium's arcs do all the stretching
    (about 0.43 per unit time, e^1300 over the run); the engine shrinks the rows at a wall
    contact as at a collision, so the vector stays finite and non-zero, and its growth is
    the free disk's exponent."""
    table, r, t = Stadium(1.0), 0.01, 3000.0
    state = np.array([[-0.8, 0.3, 0.6, 0.8]])
    u = np.array([[1.0, 0.0, 0.0, 0.0]])
    seen = []
    out = engine_run(state, np.full(1, r), MIRROR, t, tangent=u, segment=t,
                     on_segment=lambda u, v, lg: seen.append((u.copy(), lg)), table=table)
    tan = out["tangent"]
    assert np.isfinite(tan).all() and np.abs(tan).max() > 0.0
    (u_end, lg), = seen
    lam = (lg + math.log(np.linalg.norm(u_end))) / t
    assert 0.3 < lam < 0.6
