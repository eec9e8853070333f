"""The pressure of the N-disk engine (issue 51): `DisksRun.pressure`, `henderson_z`.

Three estimates of Z = PA/(NkT): the wall's impulse (the table), the collisional virial
(an exact identity with the wall's in the table; the pressure itself in the periodic box)
and the central region's own virial and density (against Henderson's equation of state at
the region's packing). Errors come from consecutive blocks of one run, after an
equilibration run; each run is long enough that the margin is at least three standard
errors, asserted before the margin.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import kicktimes as kt
from kicktimes.billiard.many_disks import engine_run
from kicktimes.stats import contact_value, enskog_frequency, henderson_z


# --- Henderson's equation of state ------------------------------------------------------------
def test_henderson_z_is_the_virial_equation_with_hendersons_contact_value():
    phi = np.linspace(0.0, 0.7, 15)
    np.testing.assert_allclose(henderson_z(phi), 1.0 + 2.0 * phi * contact_value(phi),
                               rtol=1e-14)
    assert henderson_z(0.0) == 1.0
    # its second virial coefficient: Z = 1 + 2 phi + O(phi^2) (B2 = 2 a, a = pi sigma^2 / 4)
    assert (henderson_z(1e-6) - 1.0) / 1e-6 == pytest.approx(2.0, rel=1e-5)
    with pytest.raises(ValueError, match="packing"):
        henderson_z(0.95)
    with pytest.raises(ValueError, match="packing"):
        henderson_z(-0.1)


# --- the engine's sums, exactly -------------------------------------------------------------
def test_a_head_on_collision_adds_sigma_times_the_impulse_to_the_virial():
    # equal masses at -+1 along x, r = 0.05: contact at t = 0.05, |dp| = 2, sigma = 0.1
    state = np.array([[0.4, 0.5, 1.0, 0.0], [0.6, 0.5, -1.0, 0.0]])
    out = engine_run(state, np.full(2, 0.05), 1, 0.1, box=1.0, pressure_samples=2)
    t, count, wall, virial, region = out["pressure_log"][-1]
    assert (t, count, wall) == (0.1, 2, 0.0)
    assert virial == pytest.approx(0.2, abs=1e-15) and region == virial


def test_a_radial_wall_hit_adds_twice_the_momentum_to_the_wall_impulse():
    # from the centre at speed 1, mass 3: hits |x| = 0.9 at t = 0.9, dp = 2 m = 6
    state = np.array([[0.0, 0.0, 1.0, 0.0]])
    out = engine_run(state, np.full(1, 0.1), 1, 1.0, masses=np.array([3.0]),
                     pressure_samples=2, bulk_radius=0.5)
    t, count, wall, virial, region = out["pressure_log"][-1]
    assert wall == pytest.approx(6.0, abs=1e-12) and virial == 0.0
    # at t = 1 the centre is at x = 0.8: outside the central 0.5
    assert count == 0 and out["pressure_log"][0, 1] == 1


@pytest.mark.parametrize("box", [None, 1.0])
def test_stopping_to_count_the_region_changes_no_event(box):
    n = 300
    s = kt.initial_state(n, None, packing=0.3, rng=6, box=box)
    r = math.sqrt(0.3 / n) if box is None else math.sqrt(0.3 / (math.pi * n))
    plain = engine_run(s, np.full(n, r), 0, 3.0, box=box)
    stops = engine_run(s, np.full(n, r), 0, 3.0, box=box, pressure_samples=37)
    assert stops["pressure_log"].shape == (38, 5)
    for key in ("pp_times", "pp_i", "pp_j", "final_state"):
        assert np.array_equal(plain[key], stops[key])
    np.testing.assert_array_equal(plain["sums"], stops["pressure_log"][-1, 2:])


# --- the table: wall = virial, bulk = Henderson ------------------------------------------
def table_pressure(n, phi, per_disk, *, rule="elastic", seed=1, blocks=20):
    """A run of ``per_disk`` collisions per disk in the table after 20 of equilibration:
    ``(pressure, (wall / virial - 1, its standard error from the blocks))``."""
    r = math.sqrt(phi / n)
    s = kt.initial_state(n, r, rng=seed, rule=rule)
    nu = enskog_frequency(r, n, rule=rule, kT=0.5)
    s = kt.simulate_disks(s, r, t_max=20.0 / nu, rule=rule).final_state
    run = kt.simulate_disks(s, r, t_max=per_disk / nu, rule=rule)
    p = run.pressure(blocks=blocks)
    # the difference's own error: block by block (the two are correlated)
    ratios = []
    log = run.pressure_log
    edges = np.linspace(0, log.shape[0] - 1, blocks + 1).round().astype(int)
    rho = 1.0 - r
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        dt = log[b, 0] - log[a, 0]
        z_w = rho * (log[b, 2] - log[a, 2]) / (2.0 * dt * n * p.kT)
        z_v = 1.0 + (log[b, 3] - log[a, 3]) / (2.0 * dt * n * p.kT)
        ratios.append(z_w / z_v - 1.0)
    return p, (p.z_wall / p.z_virial - 1.0, np.std(ratios, ddof=1) / math.sqrt(blocks))


@pytest.fixture(scope="module")
def table_3000():
    # 3000 disks at packing 0.3, 1000 collisions each (3e6 collisions: 2-6 s)
    return table_pressure(3000, 0.3, 1000)


def test_wall_and_virial_pressures_agree_within_1_percent_at_3000_disks(table_3000):
    p, (d, se) = table_3000
    assert 3.0 * se <= 0.01
    # equivalence: the 95 % interval of the difference inside the 1 % margin
    assert abs(d) + 1.96 * se <= 0.01
    assert p.z_virial > 1.5


def test_the_bulk_pressure_is_hendersons_within_2_percent_at_3000_disks(table_3000):
    p, _ = table_3000
    rel, se = p.z_bulk / p.henderson - 1.0, p.se_bulk / p.henderson
    assert 3.0 * se <= 0.02
    assert abs(rel) + 1.96 * se <= 0.02
    # the region's packing is its own: the wall's layer holds disks of the whole's 0.3
    assert 0.29 < p.bulk_packing < 0.32


def test_the_mirror_rule_keeps_the_virial_identity_with_the_wall():
    # no momentum conservation, but the virial theorem with the wall holds (both disks'
    # r . dp): 500 disks, 1000 collisions each
    p, (d, se) = table_pressure(500, 0.3, 1000, rule="mirror")
    assert p.kT == pytest.approx(0.5)
    assert 3.0 * se <= 0.02
    assert abs(d) + 1.96 * se <= 0.02


# --- the box: the virial is Henderson's -----------------------------------------------------
def test_the_box_virial_pressure_is_hendersons_within_1_percent():
    n, phi, box = 2000, 0.3, 1.0
    r = math.sqrt(phi / (math.pi * n))
    nu = enskog_frequency(r, n, rule="elastic", area=box * box, kT=0.5)
    s = kt.initial_state(n, r, box=box, rule="elastic", rng=2)
    s = kt.simulate_disks(s, r, t_max=20.0 / nu, rule="elastic", box=box).final_state
    run = kt.simulate_disks(s, r, t_max=400.0 / nu, rule="elastic", box=box)
    p = run.pressure(blocks=20)
    assert p.packing == pytest.approx(0.3) and p.henderson == pytest.approx(henderson_z(0.3))
    assert math.isnan(p.z_wall) and p.z_bulk == p.z_virial
    rel, se = p.z_virial / p.henderson - 1.0, p.se_virial / p.henderson
    assert 3.0 * se <= 0.01
    assert abs(rel) + 1.96 * se <= 0.01


# --- the record and bad input ---------------------------------------------------------------
def test_the_pressure_log_starts_at_zero_and_its_sums_grow():
    s = kt.initial_state(200, 0.03, rng=4, rule="elastic")
    run = kt.simulate_disks(s, 0.03, t_max=3.0, rule="elastic")
    log = run.pressure_log
    assert log[0, 0] == 0.0 and log[-1, 0] == 3.0 and log.shape[0] >= 3
    assert (np.diff(log[:, 0]) > 0).all()
    # elastic pair virials and wall impulses are positive
    assert (np.diff(log[:, 2:], axis=0) >= 0).all()
    assert 0 < log[:, 1].max() <= 200
    assert "Z virial" in run.pressure(blocks=2).summary()


def test_bad_pressure_requests_name_the_argument():
    s = kt.initial_state(100, 0.03, box=1.0, rng=1)
    run = kt.simulate_disks(s, 0.03, t_max=1.0, box=1.0)
    with pytest.raises(ValueError, match="rule"):
        run.pressure(blocks=2)
    radii = np.r_[np.full(50, 0.03), np.full(50, 0.04)]
    u = kt.initial_state(100, radii, rng=1, rule="elastic")
    with pytest.raises(ValueError, match="^r: "):
        kt.simulate_disks(u, radii, t_max=1.0, rule="elastic").pressure(blocks=2)
    e = kt.initial_state(100, 0.03, rng=1, rule="elastic")
    run = kt.simulate_disks(e, 0.03, t_max=1.0, rule="elastic")
    with pytest.raises(ValueError, match="blocks"):
        run.pressure(blocks=1)
    with pytest.raises(TypeError, match="blocks"):
        run.pressure(blocks=2.0)
    with pytest.raises(ValueError, match="bulk_radius"):
        kt.simulate_disks(e, 0.03, t_max=1.0, rule="elastic", bulk_radius=0.99)
    leaky = kt.simulate_disks(e, 0.03, t_max=5.0, rule="elastic", holes=[[0.0, 1.0]])
    assert leaky.escaped.size > 0
    with pytest.raises(ValueError, match="holes"):
        leaky.pressure(blocks=2)


# --- the command line -----------------------------------------------------------------------
def test_the_command_line_prints_the_pressures_beside_hendersons(tmp_path):
    from click.testing import CliRunner

    from kicktimes.cli import main

    result = CliRunner().invoke(main, ["simulate", "--disks", "500", "--packing", "0.3",
                                       "--rule", "elastic", "--t-max", "2",
                                       "--out", str(tmp_path / "c")])
    assert result.exit_code == 0, result.output
    for word in ("\n  wall ", "\n  virial ", "\n  bulk ", "Henderson"):
        assert word in result.output
    result = CliRunner().invoke(main, ["simulate", "--disks", "500", "--packing", "0.3",
                                       "--rule", "elastic", "--t-max", "2", "--box", "1",
                                       "--out", str(tmp_path / "b")])
    assert result.exit_code == 0, result.output
    assert "\n  virial " in result.output and "\n  wall " not in result.output
    assert "the periodic box" in result.output
    bad = CliRunner().invoke(main, ["simulate", "--disks", "5", "--packing", "0.5",
                                    "--box", "0.1", "--out", str(tmp_path / "x")])
    assert bad.exit_code != 0 and "--box" in bad.output
