"""Scattering kicks with a partner of another radius and mass (docs/unequal.md)."""

import math

import numpy as np
import pytest
from scipy import stats

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.billiard import KickLaw
from kicktimes.billiard.runs import read_run
from kicktimes.billiard.scatter import scatter_kick
from kicktimes.diagnostics import Tangent, Twin, lyapunov

STATE = np.array([0.1, -0.2, 0.6, 0.8])
R0 = 0.02


_LAW_FIELDS = ("rule", "e0", "partner", "partner_radius", "partner_mass")


def _run(**kw):
    law = KickLaw(schedules.Poisson(0.2), angle="scatter",
                  **{k: kw.pop(k) for k in _LAW_FIELDS if k in kw})
    return simulate_one_particle(STATE, R0, kicks=law, **{"t_max": 4000.0, "rng": 7, **kw})


@pytest.mark.parametrize("rule, extra", [("mirror", {}), ("elastic", {"partner_mass": 1.0})])
def test_the_default_partner_given_explicitly_is_bitwise_the_equal_disk_kick(rule, extra):
    own = _run(rule=rule)
    same = _run(rule=rule, partner_radius=R0, **extra)
    np.testing.assert_array_equal(own.kick_log_array, same.kick_log_array)
    np.testing.assert_array_equal(own.final_state, same.final_state)
    np.testing.assert_array_equal(own.boundary_log.time, same.boundary_log.time)


def test_a_virtual_collision_with_masses_keeps_the_pairs_momentum_and_energy():
    mass = 3.0
    run = _run(rule="elastic", partner_radius=0.05, partner_mass=mass)
    log = run.kick_log
    m0, m1 = 2.0 / (1.0 + mass), 2.0 * mass / (1.0 + mass)  # normalised: (m0 + m1) / 2 = 1
    v = log[["vx", "vy"]].to_numpy()
    v_post = log[["vx_post", "vy_post"]].to_numpy()
    u = log[["ux", "uy"]].to_numpy()
    n = log[["nx", "ny"]].to_numpy()
    wn = ((v - u) * n).sum(axis=1, keepdims=True)
    assert run.n_kicks > 500 and (wn > 0).all()  # every partner approaches
    u_post = u + m0 * wn * n  # the partner's velocity after the collision
    momentum = m0 * v + m1 * u
    np.testing.assert_allclose(m0 * v_post + m1 * u_post, momentum, rtol=0, atol=1e-13)
    energy = m0 * (v**2).sum(1) + m1 * (u**2).sum(1)
    energy_post = m0 * (v_post**2).sum(1) + m1 * (u_post**2).sum(1)
    # the partner brings the two-disk system's energy e0 = 1, and the collision keeps it
    np.testing.assert_allclose(energy, 2.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(energy_post, energy, rtol=0, atol=1e-12)


def test_the_partner_touches_at_r0_plus_r1_and_is_flagged_outside_its_own_room():
    r1 = 0.3
    sp = (R0 + r1, 1.0 - r1)
    # partners drawn around a disk at 0.5: some centres leave their room |x| <= 1 - r1
    flags = []
    for a, b in np.random.default_rng(3).uniform(-1, 1, (400, 2)):
        st = np.array([0.0, 0.5, 0.0, 0.6, 0.8, 0.0, 1.0])
        out = np.empty(9)
        scatter_kick(st, a, b, sp[0], sp[1], 0, 0.0, 0, 1.0, 1.0, out)
        nx, ny = out[4], out[5]
        assert math.hypot(nx, ny) == pytest.approx(1.0, abs=1e-14)
        px, py = 0.5 + sp[0] * nx, sp[0] * ny
        assert out[8] == float(math.hypot(px, py) > 1.0 - r1)
        flags.append(out[8])
    assert 0.1 < np.mean(flags) < 0.9


def test_a_smaller_partner_defocuses_more():
    # common random numbers: the same kicks, only the contact distance r0 + r1 differs
    base = _run(n_steps=5000, tau=0.2, t_max=None)
    law = KickLaw.from_run(base)
    kw = dict(n_steps=5000, tau=0.2)
    small = lyapunov(STATE, R0, kicks=law.replace(partner_radius=0.005), **kw)
    large = lyapunov(STATE, R0, kicks=law.replace(partner_radius=0.08), **kw)
    # per kick about log of the ratio of contact distances, ln(0.1 / 0.025) = 1.4
    per_kick = (small.lam - large.lam) * base.t_max / base.n_kicks
    assert 0.7 < per_kick < 2.1


@pytest.mark.parametrize("rule, extra", [("mirror", {}), ("elastic", {"partner_mass": 3.0})])
def test_tangent_and_twin_ftle_agree_with_a_partner_of_another_radius(rule, extra):
    run = _run(rule=rule, partner_radius=0.045, n_steps=4000, tau=0.2, t_max=None, **extra)
    tangent = lyapunov(run)
    twin = lyapunov(run, method=Twin(d0=1e-9))
    assert tangent.n_perturbations == run.n_kicks > 100 and tangent.lam > 0.05
    assert twin.lam == pytest.approx(tangent.lam, rel=0.02)
    # the one pass (run and FTLE from one event loop) is the run and the FTLE
    again, same = lyapunov(STATE, R0, kicks=KickLaw.from_run(run), n_steps=4000, tau=0.2,
                           method=Tangent(return_run=True))
    assert again == tangent
    np.testing.assert_array_equal(same.kick_log_array, run.kick_log_array)


def test_the_run_records_its_partner_and_a_file_keeps_it(tmp_path):
    run = _run(rule="elastic", partner_radius=0.04, partner_mass=2.0, t_max=100.0)
    assert (run.partner_radius, run.partner_mass) == (0.04, 2.0)
    assert "partner_radius=0.04" in repr(run)
    run.to_parquet(tmp_path / "run.parquet")
    back = read_run(tmp_path / "run.parquet")
    assert (back.partner_radius, back.partner_mass) == (0.04, 2.0)
    assert "partner_radius" not in _run(t_max=100.0).meta  # defaults: the old record


def test_elastic_kicks_with_masses_reproduce_the_collision_law_of_unequal_disks():
    radii, masses = (0.02, 0.04), (1.0, 3.0)
    ics = initial_conditions(30, radii, rng=5, method="uniform", rule="elastic",
                             masses=masses)
    v2, w2 = [], []
    for ic in ics:
        c = simulate_two_particle(ic, radii, t_max=3000.0, rule="elastic", masses=masses,
                                  log_collisions=True).collisions
        v2.append(c[["vx0", "vy0"]].to_numpy())
        w2.append(c[["vx0_post", "vy0_post"]].to_numpy())
    v2, w2 = np.concatenate(v2), np.concatenate(w2)
    kicked = simulate_one_particle(STATE, radii[0], t_max=16000.0,
                                   kicks=KickLaw(schedules.Poisson(0.5), angle="scatter",
                                                 rule="elastic", partner_radius=radii[1],
                                                 partner_mass=masses[1] / masses[0]),
                                   rng=3).kick_log
    v1 = kicked[["vx", "vy"]].to_numpy()
    w1 = kicked[["vx_post", "vy_post"]].to_numpy()
    assert v2.shape[0] > 2000 and v1.shape[0] > 4000
    change2, change1 = np.hypot(*(w2 - v2).T), np.hypot(*(w1 - v1).T)
    assert stats.ks_2samp(change2, change1).pvalue > 0.01
    assert stats.ks_2samp(np.hypot(*v2.T), np.hypot(*v1.T)).pvalue > 0.01
    # an equal-mass partner does not: the mass sets the size of the velocity change
    equal = simulate_one_particle(STATE, radii[0], t_max=16000.0,
                                  kicks=KickLaw(schedules.Poisson(0.5), angle="scatter",
                                                rule="elastic", partner_radius=radii[1]),
                                  rng=3).kick_log
    change_eq = np.hypot(*(equal[["vx_post", "vy_post"]].to_numpy()
                           - equal[["vx", "vy"]].to_numpy()).T)
    assert stats.ks_2samp(change2, change_eq).pvalue < 1e-6


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(partner_radius=0.5), ValueError, r"partner_radius must lie in \(0.0, 0.5\)"),
    (dict(partner_radius=0.0), ValueError, r"partner_radius must lie in \(0.0, 0.5\)"),
    (dict(partner_radius="big"), TypeError, "partner_radius must be a real number"),
    (dict(partner_mass=2.0), ValueError, "partner_mass applies to rule='elastic'"),
    (dict(partner_mass=-1.0, rule="elastic"), ValueError, r"partner_mass must lie in \(0.0"),
    (dict(partner_mass=math.nan, rule="elastic"), ValueError, "partner_mass must be finite"),
    (dict(partner_radius=0.03, angle="uniform"), ValueError, "angle='scatter'"),
    (dict(partner_mass=3.0, rule="elastic", e0=0.2), ValueError, r"m0 \|v\|\^2 / 2 = 0.25"),
])
def test_bad_partner_options_are_refused_naming_the_argument(kwargs, error, match):
    kw = {"angle": "scatter", **kwargs}
    with pytest.raises(error, match=match):
        simulate_one_particle(STATE, R0, t_max=10.0, kicks=KickLaw([1.0, 2.0], **kw))
    with pytest.raises(error, match=match):
        lyapunov(STATE, R0, kicks=KickLaw([1.0, 2.0], **kw), n_steps=10, tau=0.2)
