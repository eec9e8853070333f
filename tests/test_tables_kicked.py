"""The kicked disk in a stadium and an ellipse (docs/tables.md, "The kicked disk in a table").

`simulate_one_particle(..., table=...)` and `lyapunov(..., table=...)`: the circle is
bitwise the default, every centre stays in its table, the speed is kept, the Birkhoff
coordinates are the table kernels', the FTLE without kicks is the free table's and with
kicks the tangent map agrees with renormalised twins; the refusals name their argument.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from kicktimes import schedules, simulate_one_particle
from kicktimes.billiard import KickLaw
from kicktimes.billiard.kernels import one
from kicktimes.billiard.kernels import tables as tk
from kicktimes.billiard.runs import read_run
from kicktimes.diagnostics import Tangent, Twin, lyapunov
from kicktimes.tables import Circle, Ellipse, Stadium, free_run, table_lyapunov, uniform_state

R = 0.02
TABLES = [Stadium(1.0), Ellipse(1.5, 1.0)]
LAWS = {
    "uniform": KickLaw(schedules.Poisson(0.5)),
    "normal": KickLaw(schedules.Poisson(0.5), angle="normal", sigma=1.0),
    "gaussian": KickLaw(schedules.Poisson(0.5), angle="gaussian", sigma=0.3),
    "scatter": KickLaw(schedules.Poisson(0.5), angle="scatter"),
    "elastic": KickLaw(schedules.Poisson(0.5), angle="scatter", rule="elastic",
                       partner_radius=0.03, partner_mass=2.0),
}


def _ids(table):
    return repr(table)


def _assert_inside(table, run, r):
    """Every logged contact, every sample and the end state keep the disk in the table."""
    log = run.boundary_log
    assert table.contains(np.c_[log.x, log.y], r).all()
    if run.samples.size:
        assert table.contains(run.samples, r).all()
    assert table.contains(run.final_state[:2], r)


def _speed_kept(run, n_check=None):
    """The largest relative change of the speed between kicks, from the logged contacts'
    neighbours: the end state's speed against the last kick's (or the start's)."""
    speed0 = math.hypot(*run.ic[2:])
    if run.kick_angle == "scatter" and run.rule == "elastic" and run.n_kicks:
        speed0 = math.hypot(*run.kick_log_array[-1, 2:4])
    return abs(math.hypot(*run.final_state[2:]) / speed0 - 1.0)


# --- the circle is the default, to the bit ---------------------------------------------------

@pytest.mark.parametrize("law", ["uniform", "gaussian", "scatter"])
def test_circle_table_is_the_default_to_the_bit(law):
    st = np.array([0.1, 0.2, 0.6, 0.8])
    kw = dict(t_max=200.0, kicks=LAWS[law], rng=3, n_steps=200, tau=1.0)
    a = simulate_one_particle(st, R, **kw)
    b = simulate_one_particle(st, R, table=Circle(), **kw)
    assert a.table == b.table == Circle()
    for x, y in zip(a.boundary_log, b.boundary_log, strict=True):
        assert np.array_equal(x, y)
    assert np.array_equal(a.samples, b.samples) and np.array_equal(a.final_state, b.final_state)
    assert "table" not in a.meta  # circle records are unchanged
    la = lyapunov(st, R, n_steps=200, tau=1.0, kicks=LAWS[law], rng=3)
    lb = lyapunov(st, R, n_steps=200, tau=1.0, kicks=LAWS[law], rng=3, table=Circle())
    assert la == lb


# --- the table's events ----------------------------------------------------------------------

@pytest.mark.parametrize("table", TABLES, ids=_ids)
def test_unkicked_contacts_are_the_free_runs_bitwise(table):
    # the same kernels in the same order: simulate_one_particle without kicks makes the
    # contacts of kicktimes.tables.free_run, to the bit, and logs their Birkhoff coordinates
    st = uniform_state(table, R, rng=4)
    run = simulate_one_particle(st, R, t_max=300.0, table=table)
    free = free_run(table, st, R, n_bounces=run.n_boundary, tangent=False)
    log = run.boundary_log
    assert np.array_equal(log.time, free.times)
    assert np.array_equal(np.c_[log.x, log.y], free.positions)
    sb = free.boundary_coordinates()
    assert np.allclose(run.boundary["s"], sb[:, 0], rtol=0, atol=1e-12)
    assert np.allclose(run.boundary["sin_theta"], sb[:, 1], rtol=0, atol=1e-12)
    # the ellipse is integrable: the focal product (in place of the circle's angular
    # momentum) is the same at every contact; the stadium's sin_theta is not conserved
    assert 0.0 <= run.boundary["s"].min() and run.boundary["s"].max() < table.perimeter(R)


@pytest.mark.parametrize("table", TABLES, ids=_ids)
@pytest.mark.parametrize("law", sorted(LAWS))
def test_kicked_disk_stays_inside_and_keeps_its_speed(table, law):
    st = uniform_state(table, R, rng=5)
    run = simulate_one_particle(st, R, t_max=4000.0, kicks=LAWS[law], rng=6, table=table,
                                n_steps=4000, tau=1.0)
    assert run.n_boundary > 1500 and run.n_kicks > 1500
    _assert_inside(table, run, R)
    assert _speed_kept(run) < 1e-12
    assert run.table == table and f"table: {table!r}" in run.summary()
    assert np.all(np.abs(run.boundary["sin_theta"]) <= 1.0)
    assert np.all(np.diff(run.boundary["time"]) >= 0.0)


@pytest.mark.parametrize("table", TABLES, ids=_ids)
def test_paper_sampling_and_replayed_kicks(table):
    st = uniform_state(table, R, rng=7)
    run = simulate_one_particle(st, R, kicks=schedules.Poisson(0.3), rng=2, table=table,
                                sampling="paper", n_steps=3000, tau=0.5)
    _assert_inside(table, run, R)
    again = simulate_one_particle(st, R, kicks=KickLaw.from_run(run), table=table,
                                  sampling="paper", n_steps=3000, tau=0.5)
    assert np.array_equal(again.samples, run.samples)
    replay = simulate_one_particle(st, R, t_max=run.t_max,
                                   kicks=schedules.Replay(run.kick_times), rng=1, table=table)
    assert np.array_equal(replay.kick_times, run.kick_times)
    _assert_inside(table, replay, R)


def test_states_at_the_stadium_joins_and_grazing_stay_inside():
    table, a, rho = Stadium(1.0), 1.0, 1.0 - R
    eps = 1e-13
    states = [
        [a, rho - eps, 1.0, 0.0],                      # at the join, along the segment
        [-a, -rho, -1.0, 0.0],                         # on the other join, exactly
        [0.3, rho, 1.0, 1e-9],                         # on a segment, grazing outward
        [0.0, rho - 1e-12, math.cos(1e-7), math.sin(1e-7)],
        [a + rho * math.cos(0.3), rho * math.sin(0.3), -math.sin(0.3), math.cos(0.3)],
        [0.0, 0.0, 0.0, 1.0],                          # the bouncing-ball orbit
    ]
    for st in states:
        run = simulate_one_particle(st, R, t_max=2000.0, kicks=schedules.Poisson(0.2), rng=8,
                                    table=table, n_steps=2000, tau=1.0)
        _assert_inside(table, run, R)
        assert _speed_kept(run) < 1e-12
        free = simulate_one_particle(st, R, t_max=2000.0, table=table)
        _assert_inside(table, free, R)


def test_near_grazing_in_the_ellipse_stays_inside():
    table = Ellipse(2.0, 1.0)
    r = 0.3  # a strongly curved centre's curve (max radius b^2/a = 0.5)
    kind, p0, p1, p2 = table.kernel(r)
    for t in (0.0, 0.4, math.pi / 2):
        c, s = math.cos(t), math.sin(t)
        nx, ny, _ = tk.ellipse_normal(c, s, p0, p1, p2)
        ih = 1.0 / math.hypot(p1 * c, p0 * s)
        x, y = (p0 - p2 * p1 * ih) * c, (p1 - p2 * p0 * ih) * s
        for ang in (1e-9, 1e-6, 1e-3):
            v = (-ny * math.cos(ang) + nx * math.sin(ang), nx * math.cos(ang) + ny * math.sin(ang))
            x_in, y_in = x - 1e-13 * nx, y - 1e-13 * ny
            run = simulate_one_particle([x_in, y_in, *v], r, t_max=500.0, table=table,
                                        kicks=schedules.Poisson(0.5), rng=9, n_steps=500,
                                        tau=1.0)
            _assert_inside(table, run, r)
            assert _speed_kept(run) < 1e-12


def test_partner_outside_flag_is_the_tables():
    gen = np.random.default_rng(10)
    for table in TABLES:
        r1 = 0.05
        kind, p0, p1, p2 = table.kernel(R)
        _, q0, q1, q2 = table.kernel(r1)
        tab = (kind, p0, p1, p2, q0, q1, q2)
        pts = gen.uniform(-2.2, 2.2, size=(2000, 2))
        flags = np.array([one.table_outside(tab, x, y) for x, y in pts])
        assert np.array_equal(flags, ~table.contains(pts, r1))


def test_run_records_its_table_in_parquet(tmp_path):
    table = Ellipse(1.5, 1.0)
    st = uniform_state(table, R, rng=11)
    run = simulate_one_particle(st, R, t_max=50.0, kicks=schedules.Poisson(0.2), rng=1,
                                table=table, n_steps=50, tau=1.0)
    assert run.meta["table"] == {"name": "Ellipse", "a": 1.5, "b": 1.0}
    run.to_parquet(tmp_path / "run.parquet")
    back = read_run(tmp_path / "run.parquet")
    assert back.table == table
    assert np.array_equal(back.boundary["s"], run.boundary["s"])


# --- the FTLE --------------------------------------------------------------------------------

@pytest.mark.parametrize("table", TABLES, ids=_ids)
def test_unkicked_ftle_is_the_free_tables(table):
    # the same events as table_lyapunov's free disk (above: bitwise the same contacts);
    # only the start vector differs (along x here, random off the flow there), which moves
    # log|u(T)| by O(1): |difference| < 5 / T
    horizon = 3000.0
    for seed in (1, 2):
        st = uniform_state(table, R, rng=seed)
        res = lyapunov(st, R, n_steps=3000, tau=horizon / 3000, table=table)
        n = free_run(table, st, R, t_max=horizon, tangent=False).n_bounces
        free = table_lyapunov(table, st, R, n_bounces=n, rng=seed)
        assert math.isfinite(res.lam)
        assert abs(res.lam - free.exponent) < 5.0 / horizon
    if isinstance(table, Stadium):
        assert res.lam > 0.3  # chaotic (about 0.45 at a = 1)


@pytest.mark.parametrize("table", TABLES, ids=_ids)
def test_kicked_tangent_ftle_agrees_with_renormalised_twins(table):
    # Poisson kicks at rate 0.5, three invariant states, horizon 400: the twins at
    # d0 = 1e-9 renormalised every 0.05 (and 0.1) time units against the tangent FTLE of the
    # same run. The twins' noise is the change between the two schedules; the
    # tangent-twin gap is inside three times it plus 1e-4 of the exponent.
    law = KickLaw(schedules.Poisson(0.5))
    for seed in (1, 2, 3):
        st = uniform_state(table, R, rng=20 + seed)
        tangent = lyapunov(st, R, n_steps=400, tau=1.0, kicks=law, rng=seed, table=table).lam
        fine = lyapunov(st, R, n_steps=8000, tau=0.05, kicks=law, rng=seed, table=table,
                        method=Twin(d0=1e-9)).lam
        coarse = lyapunov(st, R, n_steps=4000, tau=0.1, kicks=law, rng=seed, table=table,
                          method=Twin(d0=1e-9)).lam
        assert tangent > 0.0
        noise = abs(fine - coarse)
        assert abs(fine - tangent) < 3.0 * noise + 1e-4 * tangent


@pytest.mark.parametrize("table", TABLES, ids=_ids)
def test_scatter_kicks_tangent_against_twins(table):
    law = KickLaw(schedules.Poisson(0.5), angle="scatter")
    st = uniform_state(table, R, rng=30)
    tangent = lyapunov(st, R, n_steps=300, tau=1.0, kicks=law, rng=4, table=table).lam
    twin = lyapunov(st, R, n_steps=6000, tau=0.05, kicks=law, rng=4, table=table,
                    method=Twin(d0=1e-9)).lam
    assert abs(twin - tangent) < 0.02 * tangent


def test_lyapunov_takes_the_table_from_the_run():
    table = Stadium(0.5)
    st = uniform_state(table, R, rng=12)
    law = KickLaw(schedules.Poisson(0.5))
    res, run = lyapunov(st, R, n_steps=500, tau=1.0, kicks=law, rng=1, table=table,
                        method=Tangent(return_run=True))
    assert run.table == table
    same = simulate_one_particle(st, R, t_max=500.0, kicks=law, rng=1, table=table,
                                 n_steps=500, tau=1.0)
    assert np.array_equal(same.samples, run.samples)
    assert lyapunov(run) == res
    with pytest.raises(ValueError, match="table"):
        lyapunov(run, table=Stadium(1.0))


# --- bad input -------------------------------------------------------------------------------

def test_bad_input_names_its_argument():
    st = [0.1, 0.2, 0.6, 0.8]
    with pytest.raises(TypeError, match="table"):
        simulate_one_particle(st, R, t_max=1.0, table="stadium")
    with pytest.raises(TypeError, match="table"):
        lyapunov(st, R, n_steps=10, tau=0.1, table=1.0)
    with pytest.raises(ValueError, match=r"r must lie in \(0.0, 0.5\)"):
        simulate_one_particle(st, 0.6, t_max=1.0, table=Ellipse(2.0, 1.0))
    with pytest.raises(ValueError, match=r"r must lie"):
        lyapunov(st, 0.6, n_steps=10, tau=0.1, table=Ellipse(2.0, 1.0))
    kinetic = schedules.KineticRate(R)
    with pytest.raises(ValueError, match="kicks"):
        simulate_one_particle(st, R, t_max=1.0, kicks=kinetic, rng=1, table=Stadium(1.0))
    with pytest.raises(ValueError, match="kicks"):
        lyapunov(st, R, n_steps=10, tau=0.1, kicks=kinetic, rng=1, table=Stadium(1.0))
    with pytest.raises(ValueError, match="holes"):
        simulate_one_particle(st, R, t_max=1.0, holes=[[0.0, 0.1]], table=Stadium(1.0))
    with pytest.raises(ValueError, match="holes"):
        lyapunov(st, R, n_steps=10, tau=0.1, holes=[[0.0, 0.1]], table=Ellipse(1.5, 1.0))
    with pytest.raises(ValueError, match="state"):
        simulate_one_particle([1.99, 0.0, 1.0, 0.0], R, t_max=1.0, table=Stadium(1.0))
    with pytest.raises(ValueError, match="partner_radius"):
        simulate_one_particle(st, 0.1, t_max=1.0, table=Ellipse(3.0, 1.0),
                              kicks=KickLaw([0.5], angle="scatter", partner_radius=0.4))


def test_a_stadium_state_outside_the_circle_is_accepted():
    st = [1.5, 0.0, 0.0, 1.0]  # outside the unit circle, inside Stadium(1)
    run = simulate_one_particle(st, R, t_max=10.0, table=Stadium(1.0))
    assert run.n_boundary > 0
    with pytest.raises(ValueError, match="state"):
        simulate_one_particle(st, R, t_max=10.0)


# --- 10^6 bounces ----------------------------------------------------------------------------

@pytest.mark.full
@pytest.mark.parametrize("table", TABLES, ids=_ids)
@pytest.mark.parametrize("law", ["uniform", "gaussian", "scatter"])
def test_million_bounces_keep_the_speed_and_the_table(table, law):
    st = uniform_state(table, R, rng=40)
    horizon = 1.05e6 * table.mean_free_time(R)
    kicks = (KickLaw(schedules.Poisson(0.2), angle=law, sigma=0.3) if law == "gaussian"
             else KickLaw(schedules.Poisson(0.2), angle=law))
    run = simulate_one_particle(st, R, t_max=horizon, kicks=kicks, rng=41, table=table,
        n_steps=10**5, tau=horizon / 10**5)
    assert run.n_boundary >= 10**6
    _assert_inside(table, run, R)
    assert _speed_kept(run) < 1e-12
