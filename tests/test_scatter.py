"""Scattering kicks: a kick that is a collision with a virtual partner (docs/scatter.md)."""

import math

import numpy as np
import pytest
from scipy import integrate, stats

from kicktimes import (
    initial_conditions,
    read_run,
    schedules,
    simulate_one_particle,
    simulate_two_particle,
)
from kicktimes.billiard import KickLaw
from kicktimes.billiard.scatter import (
    collide_with_partner,
    draw_partner,
    partner_angle,
    scatter_tangent,
    twin_meets_partner,
)
from kicktimes.diagnostics import Twin

STATE = np.array([0.12, -0.31, 0.6, 0.8])
R_LAW = 0.03


def _deflection(v, w):
    """Unsigned angle between the velocities before (v) and after (w), in [0, pi]."""
    return np.abs(np.arctan2(v[:, 0] * w[:, 1] - v[:, 1] * w[:, 0], (v * w).sum(axis=1)))


# --- the partner and normal laws --------------------------------------------------------


def test_weighted_partner_angle_has_density_proportional_to_sin_half_angle():
    a = np.random.default_rng(1).uniform(-1, 1, 20000)
    d = np.array([partner_angle(x, 1.0, 1.0, 0) for x in a])
    assert np.all(np.abs(d) <= np.pi) and np.array_equal(np.sign(d), np.sign(a))
    # |D| has CDF 1 - cos(|D|/2) on [0, pi]
    assert stats.kstest(np.abs(d), lambda x: 1.0 - np.cos(x / 2.0)).pvalue > 0.01
    assert stats.kstest(np.abs(d), "uniform", args=(0, np.pi)).pvalue < 1e-10


def test_weighted_partner_angle_with_unequal_speeds_inverts_the_flux_cdf():
    sv, su = 1.2, 0.5

    def cdf(x):
        dens = lambda t: math.hypot(sv - su, 2.0 * math.sqrt(sv * su) * math.sin(t / 2))  # noqa: E731
        return integrate.quad(dens, 0.0, x)[0] / integrate.quad(dens, 0.0, math.pi)[0]

    for q in (0.01, 0.3, 0.5, 0.9, 0.999):
        d = partner_angle(q, sv, su, 0)
        assert cdf(d) == pytest.approx(q, abs=1e-10)
        assert partner_angle(-q, sv, su, 0) == -d


def test_uniform_partner_angle_is_pi_times_the_uniform():
    assert partner_angle(0.25, 1.0, 1.0, 1) == pytest.approx(np.pi / 4)


def test_normal_angle_to_the_relative_velocity_has_density_cos_phi():
    rng = np.random.default_rng(2)
    phis = []
    for a, b in rng.uniform(-1, 1, (20000, 2)):
        ux, uy, nx, ny = draw_partner(0.6, 0.8, a, b, 0, 0.0, 0, 1.0, 1.0)
        wx, wy = 0.6 - ux, 0.8 - uy
        phis.append(math.atan2(wx * ny - wy * nx, wx * nx + wy * ny))
        assert math.hypot(ux, uy) == pytest.approx(1.0)
        assert wx * nx + wy * ny >= 0.0  # approaching: (v - u).n >= 0
    assert stats.kstest(phis, lambda p: (1.0 + np.sin(p)) / 2.0).pvalue > 0.01


def test_elastic_partner_has_the_energy_left_by_the_disk():
    ux, uy, _, _ = draw_partner(0.3, 0.4, 0.2, 0.1, 1, 1.0, 0, 1.0, 1.0)
    assert 0.25 + ux * ux + uy * uy == pytest.approx(2.0)


# --- the single-trajectory law: scatter kicks against real two-disk collisions ----------


def _two_disk_collisions(rule):
    # invariant ICs, so every logged collision is drawn from the collision measure;
    # disk 0 only (the two disks of one collision are not independent)
    ics = initial_conditions(30, R_LAW, rng=5, method="uniform", rule=rule)
    v, w = [], []
    for ic in ics:
        c = simulate_two_particle(ic, R_LAW, t_max=3000.0, rule=rule, log_collisions=True)
        v.append(c.collisions[["vx0", "vy0"]].to_numpy())
        w.append(c.collisions[["vx0_post", "vy0_post"]].to_numpy())
    return np.concatenate(v), np.concatenate(w)


def _scatter_kicks(rule, partner):
    run = simulate_one_particle(STATE, R_LAW,
                                t_max=16000.0,
                                kicks=KickLaw(schedules.Poisson(0.5), angle="scatter", rule=rule,
                                              partner=partner),
                                rng=3)
    log = run.kick_log
    return log[["vx", "vy"]].to_numpy(), log[["vx_post", "vy_post"]].to_numpy()


@pytest.fixture(scope="module", params=["mirror", "elastic"])
def law_samples(request):
    rule = request.param
    return rule, _two_disk_collisions(rule)


def test_collision_log_is_a_contact_and_the_rule_applied_to_its_normal(law_samples):
    rule, _ = law_samples
    ic = initial_conditions(1, R_LAW, rng=5, method="uniform", rule=rule)[0]
    c = simulate_two_particle(ic, R_LAW, t_max=2000.0, rule=rule, log_collisions=True).collisions
    assert len(c) > 20
    gap = np.hypot(c.x1 - c.x0, c.y1 - c.y0)
    np.testing.assert_allclose(gap, 2 * R_LAW, rtol=0, atol=1e-12)
    for row in c.itertuples():
        after = collide_with_partner(row.vx0, row.vy0, row.vx1, row.vy1, row.nx, row.ny,
                                     0 if rule == "mirror" else 1, 1.0)
        np.testing.assert_allclose(after, (row.vx0_post, row.vy0_post), atol=1e-9)
        # approaching before: (v0 - v1).n > 0 with n from disk 0 towards disk 1
        assert (row.vx0 - row.vx1) * row.nx + (row.vy0 - row.vy1) * row.ny > 0


def test_scatter_kicks_reproduce_the_velocity_change_at_two_disk_collisions(law_samples):
    rule, (v2, w2) = law_samples
    assert v2.shape[0] > 4000
    v1, w1 = _scatter_kicks(rule, "weighted")
    assert v1.shape[0] > 4000
    assert stats.ks_2samp(_deflection(v2, w2), _deflection(v1, w1)).pvalue > 0.01
    dv2, dv1 = np.hypot(*(w2 - v2).T), np.hypot(*(w1 - v1).T)
    assert stats.ks_2samp(dv2, dv1).pvalue > 0.01
    if rule == "elastic":
        # the pre-kick speed: collision-weighted in both systems (fast disks collide more)
        assert stats.ks_2samp(np.hypot(*v2.T), np.hypot(*v1.T)).pvalue > 0.01


def test_unweighted_uniform_partner_does_not_reproduce_the_collision_law(law_samples):
    rule, (v2, w2) = law_samples
    v1, w1 = _scatter_kicks(rule, "uniform")
    assert stats.ks_2samp(_deflection(v2, w2), _deflection(v1, w1)).pvalue < 1e-6
    # a uniform partner approaches less often head-on: smaller velocity changes
    assert np.hypot(*(w1 - v1).T).mean() < 0.95 * np.hypot(*(w2 - v2).T).mean()


def test_state_blind_uniform_kicks_do_not_reproduce_the_collision_law(law_samples):
    # a new direction uniform on [0, 2 pi) turns the velocity by |angle| ~ U(0, pi)
    _, (v2, w2) = law_samples
    assert stats.kstest(_deflection(v2, w2), "uniform", args=(0, np.pi)).pvalue < 1e-6


# --- the twin's kick map and its linearisation -------------------------------------------


#: (contact distance r0 + r1, normalised masses m0, m1): equal disks, and a partner of
#: another radius and three times the mass
PAIRS = [(0.04, 1.0, 1.0), (0.07, 0.5, 1.5)]


def _reference_collision(rule, a=0.4, b=-0.3, pair=PAIRS[0]):
    x, y, vx, vy = 0.1, -0.2, 0.6, 0.8
    e0 = 1.0
    sigma, m0, m1 = pair
    if rule == 1:
        vx, vy = 0.9, 0.3
    ux, uy, nx, ny = draw_partner(vx, vy, a, b, rule, e0, 0, m0, m1)
    return (x, y, vx, vy), (x + sigma * nx, y + sigma * ny, ux, uy), (nx, ny), sigma


@pytest.mark.parametrize("pair", PAIRS)
@pytest.mark.parametrize("rule", [0, 1])
def test_the_reference_meets_its_partner_at_the_kick_time(rule, pair):
    (x, y, vx, vy), (px, py, ux, uy), (nx, ny), sigma = _reference_collision(rule, pair=pair)
    k0 = pair[2]
    x2, y2, vx2, vy2, hit = twin_meets_partner(x, y, vx, vy, px, py, ux, uy, sigma, rule, k0)
    assert hit
    expected = collide_with_partner(vx, vy, ux, uy, nx, ny, rule, k0)
    np.testing.assert_allclose((vx2, vy2), expected, atol=1e-12)
    np.testing.assert_allclose((x2, y2), (x, y), atol=1e-12)


@pytest.mark.parametrize("pair", PAIRS)
@pytest.mark.parametrize("rule", [0, 1])
@pytest.mark.parametrize("ab", [(0.4, -0.3), (-0.9, 0.8), (0.05, 0.0)])
def test_tangent_map_is_the_jacobian_of_the_twin_kick_map(rule, ab, pair):
    z, (px, py, ux, uy), (nx, ny), sigma = _reference_collision(rule, *ab, pair=pair)
    k0 = pair[2]
    h = 1e-6
    jac_fd = np.empty((4, 4))
    jac = np.empty((4, 4))
    for i in range(4):
        e = np.zeros(4)
        e[i] = h
        plus = twin_meets_partner(*(np.array(z) + e), px, py, ux, uy, sigma, rule, k0)
        minus = twin_meets_partner(*(np.array(z) - e), px, py, ux, uy, sigma, rule, k0)
        assert plus[4] and minus[4]
        jac_fd[:, i] = (np.array(plus[:4]) - np.array(minus[:4])) / (2 * h)
        jac[:, i] = scatter_tangent(z[2], z[3], ux, uy, nx, ny, sigma, rule, k0, *(e / h))
    scale = np.abs(jac).max()
    assert np.abs(jac - jac_fd).max() <= 1e-6 * scale


def test_a_twin_off_the_partner_line_misses_it():
    (x, y, vx, vy), (px, py, ux, uy), _, sigma = _reference_collision(0)
    # move the twin sideways by more than the contact diameter
    wx, wy = vx - ux, vy - uy
    k = 3 * sigma / math.hypot(wx, wy)
    out = twin_meets_partner(x - wy * k, y + wx * k, vx, vy, px, py, ux, uy, sigma, 0, 1.0)
    assert not out[4]
    assert out[2:4] == (vx, vy)


# --- the simulator API -----------------------------------------------------------------


def test_mirror_scatter_kicks_keep_the_speed_and_change_the_direction():
    run = simulate_one_particle(STATE, 0.02, t_max=3000.0,
                                kicks=KickLaw(schedules.Poisson(0.05), angle="scatter"),
                                rng=4)
    log = run.kick_log
    assert run.n_kicks > 100 and len(log) == run.n_kicks
    np.testing.assert_allclose(np.hypot(log.vx_post, log.vy_post), 1.0, atol=1e-12)
    assert (np.abs(log.vx_post - log.vx) > 1e-6).mean() > 0.9
    # virtual partners outside the table: allowed, rare (about 4 r / (pi (1 - r)))
    assert 0.0 < log.outside.mean() < 0.1


def test_elastic_scatter_kicks_keep_the_pair_energy():
    run = simulate_one_particle(STATE, 0.02, t_max=3000.0,
                                kicks=KickLaw(schedules.Poisson(0.05), angle="scatter",
                                              rule="elastic", e0=1.0),
                                rng=4)
    log = run.kick_log
    e_before = log.vx**2 + log.vy**2 + log.ux**2 + log.uy**2
    np.testing.assert_allclose(e_before, 2.0, atol=1e-12)
    speeds = np.hypot(log.vx_post, log.vy_post)
    assert speeds.std() > 0.1 and (speeds <= math.sqrt(2.0) + 1e-12).all()


def test_same_seed_same_partners_for_both_rules_and_both_partner_laws():
    law = KickLaw(schedules.Poisson(0.05), angle="scatter")
    kw = dict(t_max=2000.0, rng=7)
    a = simulate_one_particle(STATE, 0.02, kicks=law, **kw)
    b = simulate_one_particle(STATE, 0.02, kicks=law.replace(rule="elastic"), **kw)
    c = simulate_one_particle(STATE, 0.02, kicks=law.replace(partner="uniform"), **kw)
    for other in (b, c):
        np.testing.assert_array_equal(a.kick_times, other.kick_times)
        np.testing.assert_array_equal(a.kick_angles, other.kick_angles)
    # the first kick meets the same partner normal angle relative to w; replaying the
    # recorded numbers reproduces the run exactly
    again = simulate_one_particle(STATE, 0.02, t_max=2000.0,
                                  kicks=KickLaw(a.kick_times, angle="scatter",
                                                angles=a.kick_angles),
                                  )
    np.testing.assert_array_equal(again.final_state, a.final_state)


def test_scatter_run_round_trips_through_parquet(tmp_path):
    run = simulate_one_particle(STATE, 0.02, t_max=500.0,
                                kicks=KickLaw(schedules.Poisson(0.05), angle="scatter",
                                              rule="elastic"),
                                rng=4, n_steps=100,
                                tau=5.0)
    run.to_parquet(tmp_path / "run.parquet")
    back = read_run(tmp_path / "run.parquet")
    assert back.meta == run.meta and back.meta["rule"] == "elastic"
    np.testing.assert_array_equal(back.kick_angles, run.kick_angles)
    assert back.kick_log.equals(run.kick_log)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(rule="elastic"), "angle='scatter'"),
        (dict(partner="uniform"), "angle='scatter'"),
        (dict(angle="scatter", e0=1.0), "e0"),
        (dict(angle="scatter", rule="elastic", e0=0.3), "e0"),
        (dict(angle="scatter", rule="bouncy"), "rule"),
        (dict(angle="scatter", partner="random"), "partner"),
        (dict(angle="scatter", angles=[0.1, 0.2]), r"shape \(2, 2\)"),
        (dict(angle="scatter", angles=[[0.1, 2.0], [0.0, 0.0]]), r"\[-1, 1\]"),
    ],
)
def test_bad_scatter_options_raise_naming_the_argument(kwargs, match):
    with pytest.raises(ValueError, match=match):
        simulate_one_particle(STATE, 0.02, t_max=10.0, kicks=KickLaw([1.0, 2.0], **kwargs))


def test_scatter_needs_two_disks_that_fit():
    with pytest.raises(ValueError, match="r must be < 0.5"):
        simulate_one_particle([0.0, 0.0, 1.0, 0.0], 0.6, t_max=10.0,
                              kicks=KickLaw([1.0], angle="scatter"))


# --- Lyapunov exponents of scatter-kicked runs ------------------------------------------


@pytest.fixture(scope="module")
def scatter_run():
    return simulate_one_particle(STATE, 0.02,
                                 kicks=KickLaw(schedules.Poisson(0.05), angle="scatter"),
                                 rng=11, n_steps=5000, tau=0.2)


def test_lyapunov_of_a_scatter_run_agrees_between_tangent_and_small_twin(scatter_run):
    from kicktimes.diagnostics import lyapunov

    tangent = lyapunov(scatter_run)
    twin = lyapunov(scatter_run, method=Twin(d0=1e-9))
    assert tangent.n_perturbations == scatter_run.n_kicks > 20
    assert tangent.lam > 0.05
    assert twin.lam == pytest.approx(tangent.lam, rel=0.02)


def test_scatter_kicks_stretch_more_than_state_blind_kicks(scatter_run):
    from kicktimes.diagnostics import lyapunov

    blind = lyapunov(STATE, 0.02, kicks=scatter_run.kick_times, n_steps=5000, tau=0.2, rng=1)
    assert lyapunov(scatter_run).lam > 2.0 * blind.lam


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_tangent_scatter_exponent_matches_twin_for_both_rules(rule):
    from kicktimes.diagnostics import lyapunov

    kw = dict(kicks=KickLaw(schedules.Poisson(0.05), angle="scatter", rule=rule), rng=5,
              n_steps=4000, tau=0.2)
    tangent = lyapunov(STATE, 0.02, **kw)
    twin = lyapunov(STATE, 0.02, method=Twin(d0=1e-9), **kw)
    assert twin.lam == pytest.approx(tangent.lam, rel=0.02)


def test_lyapunov_refuses_scatter_options_without_scatter_kicks():
    from kicktimes.diagnostics import lyapunov

    with pytest.raises(ValueError, match="angle='scatter'"):
        lyapunov(STATE, 0.02, kicks=KickLaw([1.0], rule="elastic"), n_steps=10, tau=0.2)


# --- scatter-kicked systems in an experiment ---------------------------------------------


def test_experiment_scatter_systems_leave_the_papers_systems_bitwise_unchanged():
    from kicktimes.experiment import Experiment, run_task

    base = dict(name="sc", radii=[0.02], n_ics=2, n_steps=300, tau=0.3, sampling="paper",
                diagnostics=["recurrence_rate", "autocorrelation"])
    paper = Experiment(**base)
    both = Experiment(**base, systems=["two_particle", "poisson", "actual", "poisson_scatter",
                                       "actual_scatter"])
    assert paper.systems == ("two_particle", "poisson", "actual")
    res_paper, coll_paper = run_task(paper, paper.tasks()[0])
    res_both, coll_both = run_task(both, both.tasks()[0])
    old = res_both[res_both.system.isin(paper.systems)].reset_index(drop=True)
    assert old.equals(res_paper)
    assert coll_both.equals(coll_paper)
    new = res_both[res_both.system.str.endswith("_scatter")]
    assert set(new.system) == {"poisson_scatter", "actual_scatter"}
    kicks = new[new.diagnostic == "n_kicks"].set_index(["ic", "system"]).value
    assert (kicks > 0).all()
    # the actual-time scatter system replays the two-disk collision times
    actual = res_both[res_both.diagnostic == "n_kicks"].set_index(["ic", "system"]).value
    for ic in (0, 1):
        assert actual[(ic, "actual_scatter")] == actual[(ic, "actual")]
