"""Two disks in the stadium and the ellipse (docs/tables.md, "Two disks in a table").

The simulator, the initial conditions, the FTLE (tangent against renormalised twins), the
boundary map, the record of the table, the circle's bits, and bad input. The 10^6-bounce
runs are ``full``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.billiard.kernels import tables as tk
from kicktimes.billiard.runs import read_run
from kicktimes.diagnostics import (
    Tangent,
    Twin,
    autocorrelation,
    boundary_angles,
    boundary_map,
    lyapunov,
    recurrence_rate,
)
from kicktimes.tables import Circle, Ellipse, Stadium, free_run

R = 0.05
TABLES = [Stadium(1.0), Ellipse(1.5, 1.0)]
IDS = ["stadium", "ellipse"]


def _energy(v):
    return float((v ** 2).sum())


def _check_run(run, table, r, ic, rule):
    """Every logged contact, sample and the end state inside; energy (mirror: each speed)
    kept to 1e-12 at every disk-disk collision and at the end."""
    log = run.boundary_log
    assert table.contains(np.column_stack([log.x, log.y]), r).all()
    if run.samples.shape[0]:
        assert table.contains(run.samples, r).all()
    assert table.contains(run.final_state[:, :2], r).all()
    v_end = run.final_state[:, 2:]
    e0 = _energy(ic[:, 2:])
    if rule == "mirror":
        assert np.abs(np.hypot(v_end[:, 0], v_end[:, 1]) - 1.0).max() < 1e-12
    assert abs(_energy(v_end) - e0) < 1e-12 * e0
    if run.pp_log.shape[0]:
        post = run.pp_log[:, 8:12]
        e = (post ** 2).sum(axis=1)
        assert np.abs(e - e0).max() < 1e-12 * e0
        if rule == "mirror":
            assert np.abs(np.hypot(post[:, 0], post[:, 1]) - 1.0).max() < 1e-12
            assert np.abs(np.hypot(post[:, 2], post[:, 3]) - 1.0).max() < 1e-12
    # the disks never overlap at a collision (contact distance 2 r to round-off)
    if run.pp_log.shape[0]:
        d = np.hypot(run.pp_log[:, 0] - run.pp_log[:, 2], run.pp_log[:, 1] - run.pp_log[:, 3])
        assert np.abs(d - 2 * r).max() < 1e-9
    # in time order (two events a rounding apart may swap by an ulp of the clock)
    assert (np.diff(log.time) >= -1e-12).all()


@pytest.mark.parametrize("table", TABLES, ids=IDS)
@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_energy_kept_and_disks_stay_inside(table, rule):
    ic = initial_conditions(1, R, rng=3, method="uniform", rule=rule, table=table)[0]
    run = simulate_two_particle(ic, R, t_max=2e4, rule=rule, table=table, n_steps=20000,
                                tau=1.0, log_collisions=True)
    assert run.n_boundary > 10**4 and run.n_pp > 100
    _check_run(run, table, R, ic, rule)


@pytest.mark.full
@pytest.mark.parametrize("table", TABLES, ids=IDS)
@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_energy_kept_over_a_million_wall_bounces(table, rule):
    ic = initial_conditions(1, R, rng=4, method="uniform", rule=rule, table=table)[0]
    # two unit-speed disks make 2 / mean_free_time wall contacts per unit time; under the
    # elastic rule the speeds are shared, the mean speed is below 1, hence the 20 % margin
    t_max = 1.2e6 * table.mean_free_time(R) / 2
    run = simulate_two_particle(ic, R, t_max=t_max, rule=rule, table=table, n_steps=10**5,
                                tau=t_max / 10**5, log_collisions=True)
    assert run.n_boundary >= 10**6
    _check_run(run, table, R, ic, rule)


def _near_joins_and_grazing(a, r):
    """ICs started at the stadium's joins and sliding along its walls."""
    rho = 1.0 - r
    eps = 1e-12
    c, s = math.cos(1e-5), math.sin(1e-5)
    return [
        # along the top segment into the right join; a disk at the left join grazing out
        np.array([[a - 0.3, rho - eps, 1.0, 0.0], [-a - 1e-9, -rho + eps, -1.0, 0.0]]),
        # at the joins exactly, moving almost along the wall
        np.array([[a, rho, c, -s], [-a, -rho, -c, s]]),
        # near the arcs' grazing contacts, just inside, tangent to the wall
        np.array([[a + rho - eps, 0.0, 0.0, 1.0], [-a - rho + eps, 0.0, 0.0, -1.0]]),
    ]


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_starts_at_the_stadium_joins_and_grazing_stay_inside(rule):
    table = Stadium(1.0)
    for ic in _near_joins_and_grazing(1.0, R):
        run = simulate_two_particle(ic, R, t_max=2000.0, rule=rule, table=table,
                                    n_steps=4000, tau=0.5, log_collisions=True)
        _check_run(run, table, R, ic, rule)


def test_grazing_starts_in_the_ellipse_stay_inside():
    # a disk started tangent to the ellipse's wall slides on along it (the grazing rule):
    # a whispering-gallery orbit of chords 2e-4, 10^4 contacts per unit time, until the
    # other disk meets it
    table = Ellipse(1.5, 1.0)
    kind, A, B, r = table.kernel(R)
    ics = []
    for u in (0.0, 0.5 * math.pi, 1.0):
        # on the centre's curve, moving along its tangent (and a hair inward)
        c, s = math.cos(u), math.sin(u)
        h = math.sqrt(B * B * c * c + A * A * s * s)
        x, y = (A - r * B / h) * c, (B - r * A / h) * s
        nx, ny, _ = tk.ellipse_normal(c, s, A, B, r)
        x, y = x - 1e-12 * nx, y - 1e-12 * ny
        tx, ty = -ny, nx
        ics.append(np.array([[x, y, tx, ty], [-x, -y, -tx, -ty]]))
    for ic in ics:
        run = simulate_two_particle(ic, R, t_max=20.0, table=table, n_steps=200, tau=0.1,
                                    max_events=10**7)
        assert run.n_boundary > 10**5
        _check_run(run, table, R, ic, "mirror")


@pytest.mark.parametrize("table", TABLES, ids=IDS)
def test_boundary_coordinates_of_the_first_contact(table):
    # disk 0's first event is a wall contact before any disk-disk collision: the same
    # contact as the free disk's, with the Birkhoff coordinates of the table kernels
    for ic in initial_conditions(20, R, rng=5, method="uniform", table=table):
        run = simulate_two_particle(ic, R, t_max=5.0, table=table)
        b = run.boundary
        first = b[b.particle == 0].iloc[0]
        if run.n_pp and run.pp_times[0] < first.time:
            continue
        free = free_run(table, ic[0], R, n_bounces=1)
        assert first.time == pytest.approx(free.times[0], rel=1e-12)
        s, sin_theta = tk.boundary_coordinates(*table.kernel(R), *free.positions[0],
                                               *free.velocities[0])
        assert first.arc == pytest.approx(s, abs=1e-10)
        assert first.sin_theta == pytest.approx(sin_theta, abs=1e-12)
        assert first.s == pytest.approx(2 * math.pi * s / table.perimeter(R), abs=1e-10)
    assert ((b.arc >= 0) & (b.arc < table.perimeter(R))).all()
    assert ((b.s >= 0) & (b.s < 2 * math.pi)).all()
    assert (b.sin_theta.abs() <= 1).all()


def test_the_run_records_its_table_and_reads_it_back(tmp_path):
    table = Ellipse(1.5, 1.0)
    ic = initial_conditions(1, R, rng=6, method="uniform", table=table)[0]
    run = simulate_two_particle(ic, R, t_max=100.0, table=table, n_steps=100, tau=1.0)
    assert run.table == table and run.meta["table"] == {"name": "Ellipse", "a": 1.5, "b": 1.0}
    assert "table: Ellipse(a=1.5, b=1.0)" in run.summary()
    run.to_parquet(tmp_path / "run.parquet")
    back = read_run(tmp_path / "run.parquet")
    assert back.table == table
    assert back.boundary.equals(run.boundary)
    # the circle's record has no table field
    circle = simulate_two_particle(initial_conditions(1, R, rng=6)[0], R, t_max=10.0)
    assert circle.table == Circle() and "table" not in circle.meta
    assert list(circle.boundary.columns) == ["time", "particle", "s", "sin_theta"]


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("sampling", ["uniform", "paper"])
def test_the_circle_table_is_the_circle_bit_for_bit(rule, sampling):
    ic = initial_conditions(1, R, rng=7, method="uniform", rule=rule)[0]
    kw = dict(rule=rule, sampling=sampling, n_steps=500, tau=0.3, log_collisions=True)
    runs = [simulate_two_particle(ic, R, **kw),
            simulate_two_particle(ic, R, table=None, **kw),
            simulate_two_particle(ic, R, table=Circle(), **kw)]
    for other in runs[1:]:
        for name in ("pp_times", "pp_log", "sample_times", "samples", "final_state"):
            assert np.array_equal(getattr(runs[0], name), getattr(other, name))
        for a, b in zip(runs[0].boundary_log, other.boundary_log, strict=True):
            assert np.array_equal(a, b)
        assert other.meta == runs[0].meta
    lams = [lyapunov(ic, R, n_steps=500, tau=0.3, rule=rule, sampling=sampling, table=t).lam
            for t in (None, Circle())]
    assert lams[0] == lams[1]


@pytest.mark.parametrize("table", TABLES, ids=IDS)
def test_initial_conditions_draw_in_the_table(table):
    for rule in ("mirror", "elastic"):
        ics = initial_conditions(200, R, rng=8, method="uniform", rule=rule, table=table)
        assert table.contains(ics[..., :2], R).all()
        gap = np.hypot(ics[:, 0, 0] - ics[:, 1, 0], ics[:, 0, 1] - ics[:, 1, 1])
        assert (gap >= 2 * R).all()
        speeds = (ics[..., 2:] ** 2).sum(axis=-1)
        if rule == "mirror":
            assert np.allclose(speeds, 1.0)
        else:
            assert np.allclose(speeds.sum(axis=1), 2.0)
        # the blocks do not change the ICs
        assert np.array_equal(
            initial_conditions(3, R, rng=8, method="uniform", rule=rule, table=table,
                               start=5), ics[5:8])
    # uniform in the region: the mean of x^2 against the region's (a Monte Carlo of
    # contains over the bounding box)
    gen = np.random.default_rng(0)
    hx = 2.0 - R if isinstance(table, Stadium) else 1.5 - R
    hy = 1.0 - R
    q = gen.uniform(-1, 1, size=(200000, 2)) * [hx, hy]
    q = q[table.contains(q, R)]
    ics = initial_conditions(4000, R, rng=9, method="uniform", table=table)
    x2 = (ics[..., 0] ** 2).mean()
    assert x2 == pytest.approx((q[:, 0] ** 2).mean(), rel=0.03)


@pytest.mark.parametrize("table", TABLES, ids=IDS)
def test_tangent_ftle_agrees_with_renormalised_twins(table):
    # 4 invariant ICs over T = 400 (about 40 disk-disk collisions at r = 0.05): Benettin
    # twins at d0 = 1e-10 renormalised every 0.05 (and every 0.1) against the tangent FTLE
    # of the same runs. The twins' noise is the change between the two schedules; the
    # tangent-twin gap is within three times it plus 1e-3 (relative), IC by IC.
    horizon = 400.0
    for rule in ("mirror", "elastic"):
        for ic in initial_conditions(4, R, rng=10, method="uniform", rule=rule, table=table):
            fine, coarse = 8000, 4000
            tangent = lyapunov(ic, R, n_steps=fine, tau=horizon / fine, rule=rule,
                               table=table).lam
            twin = lyapunov(ic, R, n_steps=fine, tau=horizon / fine, rule=rule, table=table,
                            method=Twin(d0=1e-10)).lam
            twin2 = lyapunov(ic, R, n_steps=coarse, tau=horizon / coarse, rule=rule,
                             table=table, method=Twin(d0=1e-10)).lam
            assert tangent > 0.05
            gap = abs(twin - tangent) / tangent
            noise = abs(twin - twin2) / tangent
            assert gap < 3 * noise + 1e-3, (rule, tangent, twin, twin2)


@pytest.mark.parametrize("table", TABLES, ids=IDS)
def test_lyapunov_of_a_run_takes_its_table_and_one_pass_is_the_run(table):
    ic = initial_conditions(1, R, rng=11, method="uniform", table=table)[0]
    run = simulate_two_particle(ic, R, n_steps=2000, tau=0.2, table=table)
    res = lyapunov(run)
    assert res.lam == lyapunov(ic, R, n_steps=2000, tau=0.2, table=table).lam
    # (the IC lies outside the unit circle: the run's table is what made it valid)
    with pytest.raises(ValueError, match="outside the table"):
        lyapunov(ic, R, n_steps=2000, tau=0.2)
    res2, run2 = lyapunov(ic, R, n_steps=2000, tau=0.2, table=table,
                          method=Tangent(return_run=True))
    assert res2 == res and run2.table == table
    for name in ("pp_times", "samples", "final_state"):
        assert np.array_equal(getattr(run, name), getattr(run2, name))
    assert np.array_equal(run.boundary_log.sin_theta, run2.boundary_log.sin_theta)


@pytest.mark.parametrize("table", TABLES, ids=IDS)
def test_recurrence_and_autocorrelation_of_table_runs(table):
    ic = initial_conditions(1, R, rng=12, method="uniform", table=table)[0]
    run = simulate_two_particle(ic, R, n_steps=3000, tau=0.5, table=table)
    rr = recurrence_rate(run, eps=0.05)
    assert rr == recurrence_rate(run.samples, eps=0.05) and 1 / 3001 < rr < 1
    theta = boundary_angles(run)
    b = run.boundary
    own = b[b.particle == run.track]
    assert np.array_equal(theta, np.arcsin(own.sin_theta.to_numpy()))
    assert abs(autocorrelation(theta, 1)) < 1
    pts = boundary_map(run)
    assert pts.shape == (len(own), 2)
    assert np.array_equal(pts[:, 0], own.arc.to_numpy() / table.perimeter(R))
    assert ((pts[:, 0] >= 0) & (pts[:, 0] < 1)).all()
    assert 0 < recurrence_rate(pts, eps=0.02) < 1
    # the circle's boundary map is the polar angle over 2 pi
    circle = simulate_two_particle(initial_conditions(1, R, rng=12)[0], R, t_max=50.0)
    cb = circle.boundary[circle.boundary.particle == 0]
    assert np.array_equal(boundary_map(circle)[:, 0], cb.s.to_numpy() / (2 * math.pi))


def test_bad_input():
    ic = initial_conditions(1, R, rng=13, method="uniform", table=Stadium(1.0))[0]
    with pytest.raises(TypeError, match="table"):
        simulate_two_particle(ic, R, t_max=1.0, table="stadium")
    with pytest.raises(TypeError, match="table"):
        initial_conditions(1, R, method="uniform", table=1.0)
    with pytest.raises(TypeError, match="table"):
        lyapunov(ic, R, n_steps=10, tau=0.1, table=object())
    # the ellipse refuses r >= b^2 / a
    with pytest.raises(ValueError, match=r"r must lie in \(0.0, 0.5\)"):
        simulate_two_particle(ic, 0.5, t_max=1.0, table=Ellipse(2.0, 1.0))
    with pytest.raises(ValueError, match=r"r must lie in \(0.0, 0.333"):
        initial_conditions(1, 0.4, method="uniform", table=Ellipse(3.0, 1.0))
    with pytest.raises(ValueError, match=r"r must lie in \(0.0, 0.333"):
        lyapunov(ic, 0.4, n_steps=10, tau=0.1, table=Ellipse(3.0, 1.0))
    with pytest.raises(ValueError, match="method"):
        initial_conditions(1, R, method="paper", table=Stadium(1.0))
    with pytest.raises(ValueError, match="holes"):
        simulate_two_particle(ic, R, t_max=1.0, table=Stadium(1.0), holes=[[0.0, 0.1]])
    with pytest.raises(ValueError, match="holes"):
        lyapunov(ic, R, n_steps=10, tau=0.1, table=Stadium(1.0), holes=[[0.0, 0.1]])
    with pytest.raises(ValueError, match="^r: two disks"):
        simulate_two_particle(ic, (0.05, 0.04), t_max=1.0, table=Stadium(1.0))
    with pytest.raises(ValueError, match="r_max"):
        initial_conditions(1, (0.05, 0.04), method="uniform", table=Stadium(1.0))
    # a centre outside the table
    out = ic.copy()
    out[0, :2] = (2.0, 0.0)
    with pytest.raises(ValueError, match="disk 0's centre"):
        simulate_two_particle(out, R, t_max=1.0, table=Stadium(1.0))
    with pytest.raises(ValueError, match="disk 0's centre"):
        simulate_two_particle(out, R, t_max=1.0, table=Ellipse(2.0, 1.0))
    # inside the stadium but outside the circle: accepted in the stadium only
    ic2 = np.array([[1.5, 0.0, 1.0, 0.0], [-1.5, 0.0, -1.0, 0.0]])
    assert simulate_two_particle(ic2, R, t_max=1.0, table=Stadium(1.0)).n_boundary >= 2
    with pytest.raises(ValueError, match="ic"):
        simulate_two_particle(ic2, R, t_max=1.0)


def test_the_tangent_ftle_survives_long_flights_between_collisions_in_the_stadium():
    """Each stadium contact stretches the tangent vector (lambda ~ 0.43 per unit time): it is
    renormalised at the wall too, or a long flight between the disks' collisions overflows
    its squared norm and the renormalised vector is exactly 0 (this IC did, at T ~ 2596)."""
    table, r = Stadium(1.0), 0.01
    ic = initial_conditions(1, r, rng=63, method="uniform", table=table)[0]
    res = lyapunov(ic, r, n_steps=100, tau=50.0, table=table)
    assert res.reason is None and math.isfinite(res.lam)
    assert 0.35 < res.lam < 0.6  # at least the free disk's stretching
    assert res.n_renorm > res.n_perturbations // 10
