"""Unequal disks: radii (r0, r1) in the simulator, the FTLE, the ICs and the kinetic rate."""

import numpy as np
import pytest

from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.diagnostics import Twin, lyapunov
from kicktimes.stats import kinetic_rate

RADII = (0.01, 0.025)


def test_the_kinetic_rate_of_unequal_disks_matches_a_monte_carlo_of_its_definition():
    # independent: the contact measure 2 pi sigma L and the volume |Q| by sampling the
    # centres uniformly in their own disks (4e6 pairs: ~0.1 % standard error)
    rng = np.random.default_rng(0)
    r0, r1 = RADII
    a, b, sigma, n = 1 - r0, 1 - r1, r0 + r1, 4_000_000

    def disk(radius):
        u, t = np.sqrt(rng.random(n)) * radius, rng.random(n) * 2 * np.pi
        return u * np.cos(t), u * np.sin(t)

    x0, y0 = disk(a)
    x1, y1 = disk(b)
    volume = (np.pi * a * a) * (np.pi * b * b) * np.mean(np.hypot(x0 - x1, y0 - y1) >= sigma)
    phi = rng.random(n) * 2 * np.pi
    lens = np.pi * a * a * np.mean(np.hypot(x0 + sigma * np.cos(phi),
                                            y0 + sigma * np.sin(phi)) <= b)
    monte_carlo = 2 * np.pi * sigma * lens * (4 / np.pi**2) / volume
    assert kinetic_rate(RADII) == pytest.approx(monte_carlo, rel=5e-3)
    assert kinetic_rate(RADII) == pytest.approx(kinetic_rate(RADII[::-1]), rel=1e-12)
    assert kinetic_rate((0.02, 0.02)) == pytest.approx(kinetic_rate(0.02), rel=1e-12)


def test_the_mean_count_from_invariant_ics_is_the_kinetic_count():
    ics = initial_conditions(2000, RADII, rng=3, method="uniform")
    t_max = 1000.0
    counts = np.array([simulate_two_particle(ic, RADII, t_max=t_max).n_pp for ic in ics])
    z = (counts.mean() - kinetic_rate(RADII) * t_max) / (counts.std(ddof=1) / np.sqrt(2000))
    assert abs(z) < 3.5


def test_each_disk_keeps_to_its_own_table_and_they_touch_at_r0_plus_r1():
    ic = initial_conditions(1, max(RADII), rng=4)[0]
    run = simulate_two_particle(ic, RADII, t_max=3000.0, log_collisions=True)
    log = run.boundary_log
    for disk, r in enumerate(RADII):
        mine = log.particle == disk
        assert np.abs(np.hypot(log.x[mine], log.y[mine]) - (1 - r)).max() < 1e-12
    gap = np.hypot(run.pp_log[:, 0] - run.pp_log[:, 2], run.pp_log[:, 1] - run.pp_log[:, 3])
    assert run.n_pp > 20 and np.abs(gap - sum(RADII)).max() < 1e-12
    # equal radii given as a pair run the equal-disk arithmetic, bit for bit
    same = simulate_two_particle(ic, (0.02, 0.02), t_max=500.0)
    ref = simulate_two_particle(ic, 0.02, t_max=500.0)
    assert same.pp_times.tobytes() == ref.pp_times.tobytes()
    assert same.final_state.tobytes() == ref.final_state.tobytes()


def test_the_tangent_ftle_of_unequal_disks_agrees_with_a_small_twin():
    ic = initial_conditions(1, max(RADII), rng=4)[0]
    tangent = lyapunov(ic, RADII, n_steps=3000, tau=0.3)
    twin = lyapunov(ic, RADII, n_steps=3000, tau=0.3, method=Twin(d0=1e-9))
    assert tangent.lam > 0 and twin.lam == pytest.approx(tangent.lam, rel=1e-3)


@pytest.mark.parametrize("r, match", [((0.01, 0.6), r"r\[1\]"), ((0.01, 0.02, 0.03), "pair"),
                                      ((0.0, 0.02), r"r\[0\]")])
def test_bad_radii_are_refused(r, match):
    ic = initial_conditions(1, 0.03, rng=1)[0]
    with pytest.raises(ValueError, match=match):
        simulate_two_particle(ic, r, t_max=10.0)


MASSES = (1.0, 3.0)


def test_collisions_with_masses_conserve_momentum_and_energy():
    ic = initial_conditions(1, 0.03, rng=2, method="uniform", rule="elastic")[0]
    run = simulate_two_particle(ic, 0.03, t_max=3000.0, rule="elastic", masses=MASSES,
                                log_collisions=True)
    log, (m0, m1) = run.pp_log, MASSES
    before = m0 * log[:, 4:6] + m1 * log[:, 6:8]
    after = m0 * log[:, 8:10] + m1 * log[:, 10:12]
    energy = m0 * (log[:, 8:10] ** 2).sum(1) + m1 * (log[:, 10:12] ** 2).sum(1)
    assert run.n_pp > 100 and np.abs(after - before).max() < 1e-13
    start = m0 * (ic[0, 2:] ** 2).sum() + m1 * (ic[1, 2:] ** 2).sum()
    assert np.abs(energy - start).max() < 1e-12
    assert run.masses == (0.5, 1.5)  # normalised to (m0 + m1) / 2 = 1


def test_the_mean_count_with_masses_is_the_kinetic_count_with_masses():
    ics = initial_conditions(2000, RADII, rng=5, method="uniform", rule="elastic",
                             masses=MASSES)
    t_max = 1000.0
    counts = np.array([simulate_two_particle(ic, RADII, t_max=t_max, rule="elastic",
                                             masses=MASSES).n_pp for ic in ics])
    gamma = kinetic_rate(RADII, rule="elastic", masses=MASSES)
    z = (counts.mean() - gamma * t_max) / (counts.std(ddof=1) / np.sqrt(counts.size))
    assert abs(z) < 3.5 and gamma > kinetic_rate(RADII, rule="elastic")


def test_the_tangent_ftle_with_masses_agrees_with_a_small_twin():
    ic = initial_conditions(1, 0.03, rng=2, method="uniform", rule="elastic")[0]
    kw = {"n_steps": 3000, "tau": 0.3, "rule": "elastic", "masses": MASSES}
    tangent = lyapunov(ic, RADII, **kw)
    twin = lyapunov(ic, RADII, method=Twin(d0=1e-9), **kw)
    assert tangent.lam > 0 and twin.lam == pytest.approx(tangent.lam, rel=1e-3)


@pytest.mark.parametrize("masses, rule, match", [
    ((1.0, 2.0), "mirror", "rule='elastic'"), ((1.0, 0.0), "elastic", r"masses\[1\]"),
    ((1.0,), "elastic", "pair")])
def test_bad_masses_are_refused(masses, rule, match):
    ic = initial_conditions(1, 0.03, rng=2, method="uniform", rule=rule)[0]
    with pytest.raises(ValueError, match=match):
        simulate_two_particle(ic, 0.03, t_max=10.0, rule=rule, masses=masses)


def test_unequal_disks_replay_in_50_digit_arithmetic():
    # an independent event-driven replay at 50 significant digits (mpmath): every event
    # time of the first 60 events equals the simulator's to 1e-11
    import mpmath as mp

    mp.mp.dps = 50
    # two disks aimed at each other off-centre, then a few dozen wall and pair events
    ic = np.array([[-0.3, 0.0, 0.6, 0.8], [0.3, 0.012, -1.0, 0.0]])
    run = simulate_two_particle(ic, RADII, t_max=60.0)
    sim = np.sort(np.concatenate([run.boundary_log.time, run.pp_times]))[:60]
    rho = [1 - mp.mpf(RADII[0]), 1 - mp.mpf(RADII[1])]
    sigma = mp.mpf(RADII[0]) + mp.mpf(RADII[1])
    x = [[mp.mpf(float(v)) for v in ic[i, :2]] for i in range(2)]
    v = [[mp.mpf(float(c)) for c in ic[i, 2:]] for i in range(2)]

    def dot(a, b):
        return a[0] * b[0] + a[1] * b[1]

    def wall_time(p, u, radius):
        b, c = dot(p, u), dot(p, p) - radius**2
        return (-b + mp.sqrt(b * b - dot(u, u) * c)) / dot(u, u)

    def pair_time():
        d = [x[0][k] - x[1][k] for k in range(2)]
        w = [v[0][k] - v[1][k] for k in range(2)]
        b, c = dot(d, w), dot(d, d) - sigma**2
        disc = b * b - dot(w, w) * c
        return mp.inf if b >= 0 or disc <= 0 else c / (-b + mp.sqrt(disc))

    def reflect(u, n):
        p = 2 * dot(u, n)
        return [u[0] - p * n[0], u[1] - p * n[1]]

    t, times = mp.mpf(0), []
    for _ in range(60):
        candidates = [wall_time(x[0], v[0], rho[0]), wall_time(x[1], v[1], rho[1]), pair_time()]
        k = min(range(3), key=lambda i: candidates[i])
        dt = candidates[k]
        x = [[x[i][c] + v[i][c] * dt for c in range(2)] for i in range(2)]
        t += dt
        times.append(t)
        if k < 2:
            n = [x[k][0] / rho[k], x[k][1] / rho[k]]
            v[k] = reflect(v[k], n)
        else:
            d = [x[0][c] - x[1][c] for c in range(2)]
            norm = mp.sqrt(dot(d, d))
            n = [d[0] / norm, d[1] / norm]
            v = [reflect(v[0], n), reflect(v[1], n)]
    exact = np.array([float(s) for s in times])
    assert run.n_pp >= 1 and sim.size == 60
    np.testing.assert_allclose(sim, exact, rtol=1e-11, atol=1e-11)
