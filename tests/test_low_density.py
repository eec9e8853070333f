"""The low-density theory of the stretching per perturbation (kicktimes.diagnostics.low_density).

Checked against independent computations: the flight's shear against the exact tangent
flow through hundreds of wall reflections; the chains' stationary measure against the
exact invariant-measure collision rate; the asymptotic form (slope b) across radii; and
the prediction against the simulators' tangent FTLE at r = 1e-3.
"""

import math

import numpy as np
import pytest

from kicktimes.billiard import KickLaw, initial_conditions
from kicktimes.billiard.kernels.tangent import wall_tangent
from kicktimes.diagnostics import lyapunov
from kicktimes.diagnostics.low_density import (
    SLOPES,
    THEORY_SYSTEMS,
    flight_shear,
    limit_ratio,
    stretching_theory,
)
from kicktimes.schedules import Poisson
from kicktimes.stats import kinetic_rate, stretching_per_perturbation


def exact_flight(q, v, dq, dv, rho, t_total):
    """The exact tangent flow of a free centre in |x| <= rho for t_total (plain NumPy:
    straight flights and `wall_tangent` at each reflection)."""
    q, v, dq, dv = (np.array(a, float) for a in (q, v, dq, dv))
    t = 0.0
    while True:
        b = q @ v
        vv = v @ v
        hit = (-b + math.sqrt(b * b - vv * (q @ q - rho * rho))) / vv
        if t + hit >= t_total:
            step = t_total - t
            return q + v * step, v, dq + dv * step, dv
        q = q + v * hit
        dq = dq + dv * hit
        n = q / np.linalg.norm(q)
        w = v - 2 * (v @ n) * n
        dq0, dq1, dv0, dv1 = wall_tangent(dq[0], dq[1], dv[0], dv[1], q[0], q[1], v[0], v[1],
                                          w[0], w[1], rho)
        dq, dv, v = np.array([dq0, dq1]), np.array([dv0, dv1]), w
        t += hit


@pytest.mark.parametrize("seed", range(6))
def test_flight_shear_is_the_long_time_limit_of_the_exact_tangent_flow(seed):
    rng = np.random.default_rng(seed)
    rho = 0.99
    q = rho * math.sqrt(rng.random()) * np.array([1.0, 0.0])
    speed = rng.uniform(0.5, 1.4)
    theta = rng.uniform(0, 2 * np.pi)
    v = speed * np.array([math.cos(theta), math.sin(theta)])
    dq, dv = rng.standard_normal(2), rng.standard_normal(2)
    kappa = (q[0] * v[1] - q[1] * v[0]) / speed
    d_c = (v @ dv) / speed
    d_kappa = ((dq[0] * v[1] - dq[1] * v[0]) + (q[0] * dv[1] - q[1] * dv[0])) / speed \
        - kappa * d_c / speed
    t_total = 3000.0
    qe, ve, dqe, _ = exact_flight(q, v, dq, dv, rho, t_total)
    pred = np.array(flight_shear(kappa, speed, d_kappa, d_c, rho, qe[0], qe[1], ve[0], ve[1]))
    # the bounded part of the flow is O(1) against the O(t) shear
    assert np.linalg.norm(dqe / t_total - pred) < 5e-3 * np.linalg.norm(pred) + 2e-3


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_two_disk_chains_collide_at_the_kinetic_rate(rule):
    # the chains' stationary measure is the invariant collision measure: their rate,
    # perturbations over time, is kinetic_rate (exact for invariant ICs)
    th = stretching_theory(1e-3, "two_particle", rule=rule, n_chains=300, n_steps=60,
                           burn_in=20, rng=3)
    assert th.rate / kinetic_rate(1e-3, rule=rule) == pytest.approx(1.0, abs=0.04)


@pytest.mark.parametrize("system", THEORY_SYSTEMS)
def test_the_slope_in_ln_one_over_r_is_b(system):
    lo = stretching_theory(1e-3, system, n_chains=60, n_steps=200, burn_in=20, rng=1)
    hi = stretching_theory(1e-5, system, n_chains=60, n_steps=200, burn_in=20, rng=2)
    slope = (hi.stretch - lo.stretch) / math.log(100.0)
    assert slope == pytest.approx(SLOPES[system], abs=0.06)
    assert hi.intercept == pytest.approx(lo.intercept, abs=0.3)


def test_limits_and_result():
    assert limit_ratio("poisson") == 0.5
    assert limit_ratio("uniform_kinetic") == 0.5
    assert limit_ratio("poisson_scatter") == 1.0
    th = stretching_theory(1e-3, "poisson", n_chains=20, n_steps=50, rng=7)
    again = stretching_theory(1e-3, "poisson", n_chains=20, n_steps=50, rng=7)
    assert th.stretch == again.stretch
    assert th.ci_low < th.stretch < th.ci_high
    assert th.stretch == pytest.approx(th.log_time + th.log_geometry, rel=1e-9)
    assert "Low-density stretching" in th.summary()


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"r": 0.0}, "r"), ({"r": 0.2}, "r"), ({"system": "actual"}, "system"),
    ({"rule": "sticky"}, "rule"), ({"n_chains": 1}, "n_chains"), ({"n_steps": 0}, "n_steps"),
])
def test_bad_input_names_the_argument(kwargs, name):
    args = {"r": 1e-3, "system": "two_particle", **kwargs}
    r, system = args.pop("r"), args.pop("system")
    with pytest.raises(ValueError, match=name):
        stretching_theory(r, system, **args)


def test_theory_against_the_simulators_at_r_1e_3():
    # tangent FTLE of invariant ICs over 3000 collisions against the prediction: within 6 %
    r, n_coll = 1e-3, 3000
    gamma = kinetic_rate(r)
    horizon = n_coll / gamma
    ics = initial_conditions(6, r, method="uniform", rng=11)
    two = [lyapunov(ic, r, n_steps=50, tau=horizon / 50) for ic in ics]
    s_two = stretching_per_perturbation([x.lam for x in two], [x.n_perturbations for x in two],
                                        [x.total_time for x in two])
    rng = np.random.default_rng(5)
    kicked = [lyapunov(ic[0], r, n_steps=50, tau=horizon / 50,
                       kicks=KickLaw(Poisson(gamma).sample(horizon, rng=rng))) for ic in ics]
    s_kick = stretching_per_perturbation([x.lam for x in kicked],
                                         [x.n_perturbations for x in kicked],
                                         [x.total_time for x in kicked])
    th_two = stretching_theory(r, "two_particle", n_chains=60, n_steps=300, rng=1)
    th_kick = stretching_theory(r, "poisson", n_chains=60, n_steps=300, rng=1)
    assert s_two / th_two.stretch == pytest.approx(1.0, abs=0.06)
    assert s_kick / th_kick.stretch == pytest.approx(1.0, abs=0.06)


def test_tangent_ftle_agrees_with_renormalised_twins_at_r_1e_3():
    # 10 invariant ICs over 1000 collisions: Benettin twins at d0 = 1e-10 renormalised 100
    # (and 50) times per collision time against the tangent FTLE of the same runs. The
    # twins' own noise is the change between the two renormalisation schedules; the
    # tangent-twin gap is inside three times it, IC by IC and on average.
    from kicktimes.diagnostics import Twin

    r = 1e-3
    gamma = kinetic_rate(r)
    horizon = 1000 / gamma
    gaps, noise = [], []
    for ic in initial_conditions(10, r, method="uniform", rng=21):
        fine, coarse = (int(horizon * gamma * k) for k in (100, 50))
        tangent = lyapunov(ic, r, n_steps=fine, tau=horizon / fine).lam
        twin = lyapunov(ic, r, n_steps=fine, tau=horizon / fine, method=Twin(d0=1e-10)).lam
        twin2 = lyapunov(ic, r, n_steps=coarse, tau=horizon / coarse,
                         method=Twin(d0=1e-10)).lam
        gaps.append((twin - tangent) / tangent)
        noise.append(abs(twin - twin2) / tangent)
    gaps, noise = np.array(gaps), np.array(noise)
    assert np.all(np.abs(gaps) < 3 * noise + 1e-3)
    assert abs(gaps.mean()) < 3 * noise.mean()
