"""The collision rate conditioned on the angular momenta (kicktimes.stats.kinetic).

The reference is an independent simulation of two free orbits: each centre runs on the
chords of its circular-billiard orbit, written in closed form (no event loop of the
package), and the approaching crossings of ``|x1 - x2| = 2r`` are counted exactly,
segment by segment.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from kicktimes import stats
from kicktimes.stats.counts import configuration_volume

# --- an independent free-orbit simulation ----------------------------------------------


def _chord_state(kap, speed, rho, theta0, offset, t):
    """Position and velocity at times ``t`` on the orbit of unit-speed angular momentum
    ``kap``: chords of length ``ell`` between rim points that advance by ``step``."""
    ell = 2 * math.sqrt(rho * rho - kap * kap)
    step = math.copysign(2 * math.acos(abs(kap) / rho), kap)
    travelled = speed * t + offset
    k = np.floor(travelled / ell)
    frac = travelled / ell - k
    angle = theta0 + k * step
    start = rho * np.stack([np.cos(angle), np.sin(angle)])
    end = rho * np.stack([np.cos(angle + step), np.sin(angle + step)])
    return start + frac * (end - start), speed * (end - start) / ell


def simulate_contacts(r, L1, L2, *, speeds=(1.0, 1.0), t_run, n_runs, rng):
    """Per-run rates of approaching contacts of two free orbits with uniform phases.

    ``n_runs`` independent pairs of phases (rim angle of the current chord uniform, the
    distance already run on it uniform), each followed for ``t_run``. The runs are laid
    end to end on one clock so that everything is vectorised."""
    rho, sig = 1 - r, 2 * r
    kaps = (L1 / speeds[0], L2 / speeds[1])
    breaks = [np.arange(n_runs + 1) * t_run]
    phases = []
    for kap, speed in zip(kaps, speeds, strict=True):
        ell = 2 * math.sqrt(rho * rho - kap * kap)
        theta0 = rng.uniform(0, 2 * np.pi, n_runs)
        offset = rng.uniform(0, ell, n_runs)
        phases.append((theta0, offset))
        k = np.arange(1, int(speed * t_run / ell) + 2)
        local = (k[None, :] * ell - offset[:, None]) / speed
        run_start = (np.arange(n_runs) * t_run)[:, None]
        breaks.append((run_start + local)[local < t_run])
    edges = np.unique(np.concatenate(breaks))
    dt = np.diff(edges)
    run = np.searchsorted(breaks[0], edges[:-1], side="right") - 1
    t_start = edges[:-1] - breaks[0][run]
    t_mid = t_start + 0.5 * dt
    states = [
        _chord_state(kap, speed, rho, th[run], off[run], t_mid)
        for kap, speed, (th, off) in zip(kaps, speeds, phases, strict=True)
    ]
    (x1, v1), (x2, v2) = states
    d = (x1 - 0.5 * dt * v1) - (x2 - 0.5 * dt * v2)  # separation at the segment's start
    w = v1 - v2
    dw, ww, dd = (d * w).sum(0), (w * w).sum(0), (d * d).sum(0)
    disc = dw * dw - ww * (dd - sig * sig)
    ok = (disc > 0) & (dw < 0)
    # the smaller root of |d + w t| = sig, the one where the distance falls through 2r
    hit = np.zeros_like(dt)
    hit[ok] = (dd[ok] - sig * sig) / (-dw[ok] + np.sqrt(disc[ok]))
    counted = ok & (hit >= 0) & (hit < dt)
    return np.bincount(run[counted], minlength=n_runs) / t_run


def assert_matches_simulation(r, L1, L2, *, t_run, n_runs, seed, speeds=None):
    rng = np.random.default_rng(seed)
    if speeds is None:
        rate = stats.conditional_kinetic_rate(r, L1, L2)
        sim = simulate_contacts(r, L1, L2, t_run=t_run, n_runs=n_runs, rng=rng)
    else:
        rate = stats.conditional_kinetic_rate(r, L1, L2, rule="elastic", speed1=speeds[0],
                                              speed2=speeds[1])
        sim = simulate_contacts(r, L1, L2, speeds=speeds, t_run=t_run, n_runs=n_runs,
                                rng=rng)
    mean, se = sim.mean(), sim.std(ddof=1) / math.sqrt(n_runs)
    rel_se = se / rate
    assert rel_se < 0.01, f"the simulation is too short: relative SE {rel_se:.4f}"
    assert abs(mean / rate - 1) < 0.02 + 3 * rel_se, (L1, L2, mean, se, rate)
    return mean / rate - 1, rel_se


def test_the_simulation_counts_the_invariant_rate_when_the_momenta_are_drawn_from_f():
    # The reference itself: momenta from f (centre uniform in the disk, direction uniform),
    # so the count rate is that of independent uniform centres, kinetic_rate |Q|/(pi a^2)^2.
    r, n = 0.05, 400
    rng = np.random.default_rng(11)
    rho = 1 - r
    pos = rho * np.sqrt(rng.uniform(size=(2, n)))
    L = pos * np.sin(rng.uniform(0, 2 * np.pi, size=(2, n)))
    rates = [simulate_contacts(r, a, b, t_run=40.0, n_runs=1, rng=rng)[0] for a, b in L.T]
    expected = stats.kinetic_rate(r) * configuration_volume(r) / (math.pi * rho * rho) ** 2
    se = np.std(rates, ddof=1) / math.sqrt(n)
    assert abs(np.mean(rates) - expected) < 4 * se


# --- against the simulation ----------------------------------------------------------------

GENERIC = [(0.3, -0.5), (-0.6, -0.15), (0.05, 0.8), (-0.85, 0.45), (0.9, 0.0)]


@pytest.mark.parametrize(("L1", "L2"), GENERIC)
def test_the_rate_matches_a_free_orbit_simulation(L1, L2):
    assert_matches_simulation(0.05, L1, L2, t_run=1000.0, n_runs=500, seed=1)


def test_the_elastic_rate_matches_a_free_orbit_simulation_with_unequal_speeds():
    assert_matches_simulation(0.05, 0.3, -0.4, speeds=(1.25, 0.66), t_run=1000.0,
                              n_runs=500, seed=2)


@pytest.mark.slow
@pytest.mark.parametrize("r", [0.01, 0.02])
@pytest.mark.parametrize(("L1", "L2"), [*GENERIC, (0.5, -0.46), (0.2, 0.95)])
def test_the_rate_matches_a_long_free_orbit_simulation_at_paper_radii(r, L1, L2):
    _, rel_se = assert_matches_simulation(r, L1, L2, t_run=4000.0, n_runs=1600, seed=3)
    assert rel_se < 0.005


# --- averages -------------------------------------------------------------------------------


def momentum_density(L, rho):
    """f(L) = 2 sqrt(rho^2 - L^2) / (pi rho^2)."""
    return 2 * np.sqrt(rho * rho - L * L) / (np.pi * rho * rho)


def test_the_invariant_law_of_the_angular_momentum_is_f():
    rng = np.random.default_rng(4)
    rho, n = 0.9, 1_000_000
    radius = rho * np.sqrt(rng.uniform(size=n))
    L = radius * np.sin(rng.uniform(0, 2 * np.pi, n))  # x × v, v at a uniform angle
    edges = np.linspace(-rho, rho, 19)
    counts = np.histogram(L, edges)[0]
    expected = n * np.array([integrate.quad(momentum_density, lo, hi, args=(rho,))[0]
                             for lo, hi in zip(edges[:-1], edges[1:], strict=True)])
    assert expected.sum() == pytest.approx(n, rel=1e-9)
    assert np.all(np.abs(counts - expected) < 4 * np.sqrt(expected))


def invariant_average(r, n=96):
    """The average of mean_kinetic_rate over f(L): L = rho cos(theta)."""
    rho = 1 - r
    x, w = np.polynomial.legendre.leggauss(n)
    theta = 0.5 * np.pi * (x + 1)
    weight = 0.5 * np.pi * w * momentum_density(rho * np.cos(theta), rho) * rho * np.sin(theta)
    return float(weight @ stats.mean_kinetic_rate(r, rho * np.cos(theta)))


@pytest.mark.parametrize("r", [0.005, 0.01, 0.02, 0.05])
def test_the_invariant_average_is_the_kinetic_rate_without_excluded_volume(r):
    a = 1 - r
    average = invariant_average(r)
    kinetic = stats.kinetic_rate(r)
    assert abs(average / kinetic - 1) < 0.05
    # exactly: independent phases do not exclude overlapping pairs, so the average is the
    # rate of independent uniform centres, smaller by |Q| / (pi a^2)^2 ~ 1 - 4 r^2 / a^2
    excluded = configuration_volume(r) / (np.pi * a * a) ** 2
    assert average / (kinetic * excluded) == pytest.approx(1.0, abs=1e-4)
    assert average / kinetic - 1 == pytest.approx(-4 * r * r / (a * a), rel=0.1)


@pytest.mark.parametrize("L", [0.0, 0.35, -0.8, 0.95])
def test_the_invariant_partner_is_the_f_average_of_the_conditional_rate(L):
    # Two independent routes: the partner's velocity averaged in closed form, against
    # the conditional rate integrated over L2 with the density f (Gauss-Legendre on the
    # pieces between the breakpoints of L2 -> Gamma, through the sample interface).
    r = 0.02
    rho, sig = 1 - r, 2 * r
    cuts = {abs(L) + s * sig for s in (-1, 0, 1)} | {rho - sig, sig - abs(L)}
    cuts = sorted({c for c in cuts if 0 < c < rho} | {0.0, rho})
    cuts = sorted({-c for c in cuts} | set(cuts))
    x, w = np.polynomial.legendre.leggauss(24)
    nodes, weights = [], []
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        theta = 0.5 * np.pi * (x + 1)  # cosine map: the inverse root of f's end and kinks
        nodes.append(lo + (hi - lo) * np.sin(0.5 * theta) ** 2)
        weights.append(0.25 * np.pi * (hi - lo) * np.sin(theta) * w)
    nodes, weights = np.concatenate(nodes), np.concatenate(weights)
    weights *= momentum_density(nodes, rho)
    via_sample = stats.mean_kinetic_rate(r, L, partner=nodes, partner_weights=weights)
    # (weights normalised by their sum, which is 1 up to the quadrature error)
    assert weights.sum() == pytest.approx(1.0, abs=1e-6)
    assert via_sample == pytest.approx(stats.mean_kinetic_rate(r, L), rel=1e-4)


def test_a_sample_partner_is_the_weighted_mean_of_the_conditional_rates():
    r = np.array([[0.01], [0.03]])
    L = np.array([0.0, 0.4, -0.9])
    sample = np.array([-0.7, 0.1, 0.5, 0.95])
    weights = np.array([1.0, 3.0, 0.0, 2.0])
    got = stats.mean_kinetic_rate(r, L, partner=sample, partner_weights=weights)
    assert got.shape == (2, 3)
    each = stats.conditional_kinetic_rate(r[..., None], L[None, :, None], sample)
    assert np.allclose(got, each @ weights / weights.sum(), rtol=1e-12)
    plain = stats.mean_kinetic_rate(0.01, 0.4, partner=sample)
    assert plain == pytest.approx(stats.conditional_kinetic_rate(0.01, 0.4, sample).mean())


def test_partner_strata_bound_the_cost_of_a_large_sample_at_a_small_error():
    r = 0.02
    rng = np.random.default_rng(6)
    sample = np.clip(rng.normal(0.4, 0.3, 1200), -0.97, 0.97)
    L = np.array([-0.9, 0.0, 0.4, 0.95])
    exact = stats.mean_kinetic_rate(r, L, partner=sample)
    strata = stats.mean_kinetic_rate(r, L, partner=sample, partner_strata=256)
    assert np.allclose(strata, exact, rtol=2e-3, atol=0)
    # a sample no larger than the strata is averaged exactly
    few = sample[:100]
    assert np.array_equal(stats.mean_kinetic_rate(r, L, partner=few, partner_strata=256),
                          stats.mean_kinetic_rate(r, L, partner=few))


def test_the_invariant_partner_rate_tends_to_the_small_r_law_away_from_the_rim():
    r = 0.001
    rho = 1 - r
    rates = stats.mean_kinetic_rate(r, np.array([0.0, 0.3, -0.6, 0.9]))
    assert np.allclose(rates / (16 * r / (np.pi**2 * rho**2)), 1.0, atol=5e-3)
    # a disk on the rim meets an invariant partner half as often: half of its contact
    # circle is outside the table
    on_rim = stats.mean_kinetic_rate(r, rho - 0.1 * r) / rates[0]
    assert 0.5 < on_rim < 0.55


def test_the_elastic_invariant_partner_moves_on_the_energy_circle():
    # given the disk's speed c, the partner's speed is sqrt(2 - c^2) by default
    kw = {"rule": "elastic", "speed": 1.2}
    default = stats.mean_kinetic_rate(0.02, 0.3, **kw)
    explicit = stats.mean_kinetic_rate(0.02, 0.3, partner_speed=math.sqrt(2 - 1.44), **kw)
    assert default == explicit
    # equal speeds reduce to the mirror rate, scaled: Gamma(c) = c Gamma(1) at L / c
    same = stats.mean_kinetic_rate(0.02, 0.3, rule="elastic", speed=0.8, partner_speed=0.8)
    assert same == pytest.approx(0.8 * stats.mean_kinetic_rate(0.02, 0.3 / 0.8), rel=1e-12)


# --- symmetries ----------------------------------------------------------------------------

PAIRS = np.array([(0.3, -0.5), (0.3, 0.31), (0.0, 0.7), (-0.9, 0.15), (0.6, -0.6)])


@pytest.mark.parametrize("r", [0.01, 0.05, 0.3])
def test_the_rate_is_symmetric_in_the_two_disks(r):
    # not built in: disk 1 sits on the x-axis and the contact circle is drawn around it
    L1, L2 = np.clip(PAIRS.T, -0.99 * (1 - r), 0.99 * (1 - r))
    forward = stats.conditional_kinetic_rate(r, L1, L2)
    backward = stats.conditional_kinetic_rate(r, L2, L1)
    assert np.allclose(backward, forward, rtol=5e-4, atol=0)


def test_reversing_both_rotations_leaves_the_rate_unchanged():
    L1, L2 = PAIRS.T
    assert np.allclose(stats.conditional_kinetic_rate(0.02, -L1, -L2),
                       stats.conditional_kinetic_rate(0.02, L1, L2), rtol=1e-12, atol=0)


def test_opposite_senses_on_the_same_caustic_meet_most_often():
    L2 = np.linspace(-0.9, 0.9, 37)
    rates = stats.conditional_kinetic_rate(0.01, 0.5, L2)
    assert L2[np.argmax(rates)] == pytest.approx(-0.5, abs=0.05)
    assert rates.max() > 2 * stats.mean_kinetic_rate(0.01, 0.5)


def test_equal_speeds_scale_the_mirror_rate():
    # a common speed c is a change of the time unit: Gamma(L1, L2; c, c) = c Gamma(L1/c, L2/c)
    L1, L2 = 0.3, -0.2
    elastic = stats.conditional_kinetic_rate(0.02, L1, L2, rule="elastic", speed1=0.7,
                                             speed2=0.7)
    assert elastic == pytest.approx(0.7 * stats.conditional_kinetic_rate(0.02, L1 / 0.7,
                                                                          L2 / 0.7), rel=1e-12)


def test_the_rate_broadcasts_and_keeps_scalars_scalar():
    assert isinstance(stats.conditional_kinetic_rate(0.01, 0.2, 0.3), float)
    grid = stats.conditional_kinetic_rate(np.array([0.01, 0.02])[:, None], 0.2,
                                          np.array([0.1, -0.4, 0.6]))
    assert grid.shape == (2, 3)
    assert grid[1, 2] == stats.conditional_kinetic_rate(0.02, 0.2, 0.6)


# --- quadrature -----------------------------------------------------------------------------


@pytest.mark.parametrize("r", [0.05, 0.3])
def test_coinciding_breakpoints_give_the_limit_of_nearby_orbits(r):
    # caustics exactly a contact distance apart, through the centre, at rho - 2r ...: the
    # pieces of the radial integral close up; the value must be that of a nearby pair
    rho, sig = 1 - r, 2 * r
    base = [0.0, sig, 2 * sig, rho - sig, rho - 2 * sig, 0.3, 0.5 * sig]
    pairs = {(s1 * a, b) for a in base for s1 in (1, -1)
             for b in (a + sig, a - sig, sig - a, -a, -a - sig, 0.0, rho - sig, rho - 2 * sig)}
    L1, L2 = np.array([p for p in pairs if max(abs(p[0]), abs(p[1])) < 0.999 * rho]).T
    at = stats.conditional_kinetic_rate(r, L1, L2)
    near = stats.conditional_kinetic_rate(r, L1 * (1 - 1e-9) + 1e-10, L2 * (1 - 1e-9) - 1e-10)
    assert np.all(np.isfinite(at)) and np.all(at > 0)
    assert np.allclose(at, near, rtol=1e-5, atol=0)
    assert np.allclose(stats.conditional_kinetic_rate(r, L2, L1), at, rtol=2e-3, atol=0)



def hard_cases():
    """Generic pairs and the hard ones: the partner's caustic a contact distance from the
    disk's (the breakpoints of the radial integral), both on one caustic, radial orbits,
    orbits at the rim."""
    rows = []
    for r in (0.005, 0.02, 0.1, 0.3):
        rho, sig = 1 - r, 2 * r
        for L1, L2 in [(0.3, -0.5), (0.3, -0.3), (0.3, 0.3 + sig), (-0.4, 0.4 - 0.999 * sig),
                       (0.0, 0.7), (0.6, -0.99 * rho), (0.97 * rho, 0.2), (0.2, 0.2 + 0.5 * sig)]:
            rows.append((r, *np.clip((L1, L2), -0.999 * rho, 0.999 * rho)))
    return np.array(rows).T


def test_doubling_the_nodes_changes_the_rate_by_less_than_the_stated_tolerance():
    r, L1, L2 = hard_cases()
    default = stats.conditional_kinetic_rate(r, L1, L2)
    doubled = stats.conditional_kinetic_rate(r, L1, L2, n_nodes=48)
    change = np.abs(doubled / default - 1)
    assert change[r <= 0.1].max() < 5e-4
    assert change.max() < 1e-3
    assert np.median(change) < 3e-5
    rates = stats.mean_kinetic_rate(r, L1)
    assert np.allclose(stats.mean_kinetic_rate(r, L1, n_nodes=48), rates, rtol=1e-5, atol=0)


def test_the_quadrature_error_falls_at_least_as_the_inverse_square_of_the_nodes():
    r, L1, L2 = hard_cases()
    exact = stats.conditional_kinetic_rate(r, L1, L2, n_nodes=192)
    errors = [np.abs(stats.conditional_kinetic_rate(r, L1, L2, n_nodes=n) / exact - 1)
              for n in (12, 24)]
    # order >= 2 in the worst case and in the typical one (measured: about 3)
    assert errors[1].max() < errors[0].max() / 4
    assert np.median(errors[1]) < np.median(errors[0]) / 4


# --- bad input ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"r": 0.0}, ValueError, r"r must satisfy 0 < r < 0\.5"),
        ({"r": 0.5}, ValueError, r"r must satisfy 0 < r < 0\.5"),
        ({"r": [0.01, -0.1]}, ValueError, r"r\[1\] = -0\.1"),
        ({"r": float("nan")}, ValueError, "r must be finite"),
        ({"r": "0.01"}, TypeError, "r must be a real number"),
        ({"L1": 0.99}, ValueError, r"\|L1\| < 1 - r .* got L1 = 0\.99 at r = 0\.01"),
        ({"L2": [0.1, -1.2]}, ValueError, r"L2\[1\] = -1\.2"),
        ({"L2": float("inf")}, ValueError, "L2 must be finite"),
        ({"L1": [True]}, TypeError, "L1 must be a real number"),
        ({"L1": []}, ValueError, "L1 must not be empty"),
        ({"L1": [0.1, 0.2], "L2": [0.1, 0.2, 0.3]}, ValueError, "must broadcast together"),
        ({"rule": "inelastic"}, ValueError, "rule must be one of"),
        ({"speed1": 1.0}, ValueError, "speed1 is fixed to 1 by the mirror rule"),
        ({"rule": "elastic", "speed1": 1.0}, ValueError, "rule='elastic' needs speed2"),
        ({"rule": "elastic", "speed1": 1.0, "speed2": 0.0}, ValueError,
         "speed2 must be positive"),
        ({"rule": "elastic", "speed1": 0.5, "speed2": 1.0, "L1": 0.6}, ValueError,
         r"\|L1\| < speed1 \* \(1 - r\).*speed1 = 0\.5"),
        ({"n_nodes": 2}, ValueError, "n_nodes must be an integer in"),
        ({"n_nodes": 24.0}, TypeError, "n_nodes must be an integer"),
    ],
)
def test_bad_input_to_the_conditional_rate_is_named(kwargs, error, match):
    args = {"r": 0.01, "L1": 0.2, "L2": -0.3} | kwargs
    r, L1, L2 = args.pop("r"), args.pop("L1"), args.pop("L2")
    with pytest.raises(error, match=match):
        stats.conditional_kinetic_rate(r, L1, L2, **args)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"partner": "uniform"}, ValueError, "partner must be one of"),
        ({"partner": []}, ValueError, "partner must not be empty"),
        ({"partner": [[0.1, 0.2]]}, ValueError, "partner must be 1-D"),
        ({"partner": [0.1, 0.995]}, ValueError, r"partner\[1\] = 0\.995"),
        ({"partner": [0.1], "partner_weights": [1.0, 2.0]}, ValueError,
         "one weight per partner value"),
        ({"partner": [0.1, 0.2], "partner_weights": [1.0, -1.0]}, ValueError,
         "non-negative and not all zero"),
        ({"partner_weights": [1.0]}, ValueError, "no meaning with partner='invariant'"),
        ({"partner_strata": 8}, ValueError, "no meaning with partner='invariant'"),
        ({"partner": [0.1, 0.2], "partner_strata": 1}, ValueError,
         "partner_strata must be an integer >= 2"),
        ({"partner_speed": 1.0}, ValueError, "partner_speed is fixed to 1"),
        ({"rule": "elastic"}, ValueError, "rule='elastic' needs speed"),
        ({"rule": "elastic", "speed": 1.5}, ValueError, r"speed must be < sqrt\(2\)"),
        ({"rule": "elastic", "speed": 1.0, "partner": [0.1]}, ValueError,
         "needs partner_speed"),
        ({"rule": "elastic", "speed": 1.0, "partner": [0.1], "partner_speed": [1.0, 1.0]},
         ValueError, "partner_speed must hold 1 positive"),
        ({"L": 1.0}, ValueError, r"\|L\| < 1 - r"),
    ],
)
def test_bad_input_to_the_mean_rate_is_named(kwargs, error, match):
    args = {"L": 0.2} | kwargs
    with pytest.raises(error, match=match):
        stats.mean_kinetic_rate(0.01, args.pop("L"), **args)
