"""Exact tangent-space FTLE: event maps against finite differences, agreement with twins."""

import math

import numpy as np
import pytest

from kicktimes import initial_conditions, schedules
from kicktimes.billiard import KickLaw
from kicktimes.billiard.geometry import boundary_hit_time
from kicktimes.billiard.kernels import two
from kicktimes.billiard.kernels.drive_one import tangent_one_kernel
from kicktimes.billiard.kernels.drive_two import tangent_two_kernel
from kicktimes.billiard.kernels.twins import ftle_one_kernel
from kicktimes.diagnostics import Tangent, Twin, lyapunov
from kicktimes.diagnostics.spectrum import lyapunov_spectrum

R = 0.05
RHO, SIG = 1.0 - R, 2.0 * R
RHO2 = (RHO, RHO, 1.0, 1.0)  # the two-disk kernels' table (kernels.two.table)


# ---------------------------------------------------------------- helpers: the event maps
def two_state(ic):
    ic = np.asarray(ic, dtype=float)
    st = np.zeros(11)
    st[1:9] = ic.ravel()
    st[10] = (ic[:, 2:] ** 2).sum()
    return st


def flow_two(st0, t_end, rule, U=None):
    """State (and tangent vectors) at ``t_end`` through the kernel actually used."""
    st = st0.copy()
    U = np.zeros((1, 8)) if U is None else U.copy()
    out = tangent_two_kernel(st, RHO2, SIG, rule, 1, 1, t_end, U, 10**6, 0)
    assert out[4] == 0
    return st, U, out


def first_events_two(st0, rule):
    """(kind of the first event, its time, time of the second event)."""
    st = st0.copy()
    ev = np.empty(3)
    two.init_events(st, ev, RHO2, SIG)
    k1, t1 = two.next_event(two.load(st, ev))
    two.process_event(st, ev, k1, RHO2, SIG, rule)
    _, dt2 = two.next_event(two.load(st, ev))
    return k1, t1, t1 + dt2


def directions_two(st, rule):
    """Perturbation directions: positions, and velocities (rotations only for the mirror
    rule, which keeps each speed at 1)."""
    dirs = [np.eye(8)[i] for i in (0, 1, 4, 5)]
    if rule == 0:
        for o in (2, 6):
            d = np.zeros(8)
            d[o], d[o + 1] = -st[o + 2], st[o + 1]
            dirs.append(d)
    else:
        dirs += [np.eye(8)[i] for i in (2, 3, 6, 7)]
    return np.array(dirs)


def assert_tangent_matches_finite_differences_two(st0, t_end, rule, h=1e-6):
    dirs = directions_two(st0, rule)
    _, U, _ = flow_two(st0, t_end, rule, U=dirs)
    for d, tangent in zip(dirs, U, strict=True):
        ends = []
        for s in (1.0, -1.0):
            st = st0.copy()
            st[1:9] += s * h * d
            st[10] = st[3] ** 2 + st[4] ** 2 + st[7] ** 2 + st[8] ** 2
            ends.append(flow_two(st, t_end, rule)[0][1:9])
        fd = (ends[0] - ends[1]) / (2 * h)
        assert np.linalg.norm(tangent - fd) <= 1e-6 * np.linalg.norm(tangent), (d, tangent, fd)


def one_state(s):
    st = np.zeros(7)
    st[1:5] = s
    st[6] = s[2] ** 2 + s[3] ** 2
    return st


def flow_one(st0, t_end, kicks, angles, mode, U=None):
    st = st0.copy()
    U = np.zeros((1, 4)) if U is None else U.copy()
    out = tangent_one_kernel(st, RHO, kicks, angles, mode, 1, 1, t_end, U, 10**6, NO_SCATTER,
                             NO_PARTNER)
    assert out[4] == 0
    return st, U, out


def assert_tangent_matches_finite_differences_one(st0, t_end, kicks, angles, mode, h=1e-6):
    dirs = np.eye(4)
    _, U, _ = flow_one(st0, t_end, kicks, angles, mode, U=dirs)
    for d, tangent in zip(dirs, U, strict=True):
        ends = []
        for s in (1.0, -1.0):
            st = st0.copy()
            st[1:5] += s * h * d
            st[6] = st[3] ** 2 + st[4] ** 2
            ends.append(flow_one(st, t_end, kicks, angles, mode)[0][1:5])
        fd = (ends[0] - ends[1]) / (2 * h)
        assert np.linalg.norm(tangent - fd) <= 1e-6 * np.linalg.norm(tangent), (d, tangent, fd)


# ------------------------------------------------------- one event: tangent == Jacobian
@pytest.mark.parametrize("rule", [0, 1])
def test_wall_reflection_tangent_map_is_the_finite_difference_jacobian(rule):
    a, b = 0.7, 2.1
    ic = [[0.3, -0.2, math.cos(a), math.sin(a)], [-0.4, 0.1, math.cos(b), math.sin(b)]]
    st0 = two_state(ic)
    kind, t1, t2 = first_events_two(st0, rule)
    assert kind < 2
    _, _, out = flow_two(st0, 0.5 * (t1 + t2), rule)
    assert out[2] == 0  # no disk-disk collision in the interval
    assert_tangent_matches_finite_differences_two(st0, 0.5 * (t1 + t2), rule)


def oblique_pair_ic(tc=0.2, phi=0.5, a=0.3, b=math.pi + 0.9):
    """Two disks meeting at time ``tc`` at the table's centre, contact normal at ``phi``."""
    n = np.array([math.cos(phi), math.sin(phi)])
    v1 = np.array([math.cos(a), math.sin(a)])
    v2 = np.array([math.cos(b), math.sin(b)])
    assert (v1 - v2) @ n > 0.3  # approaching, far from grazing
    q1 = -0.5 * SIG * n - v1 * tc
    q2 = 0.5 * SIG * n - v2 * tc
    return two_state([[*q1, *v1], [*q2, *v2]])


@pytest.mark.parametrize("rule", [0, 1])
def test_disk_disk_collision_tangent_map_is_the_finite_difference_jacobian(rule):
    st0 = oblique_pair_ic()
    kind, t1, t2 = first_events_two(st0, rule)
    assert kind == 2 and t1 == pytest.approx(0.2)
    t_end = 0.5 * (t1 + t2)
    _, _, out = flow_two(st0, t_end, rule)
    assert out[2] == 1
    assert_tangent_matches_finite_differences_two(st0, t_end, rule)


def test_mirror_and_elastic_collision_maps_differ():
    st0 = oblique_pair_ic()
    _, t1, _ = first_events_two(st0, 0)
    U0 = np.eye(8)[[0]]
    _, u_mirror, _ = flow_two(st0, t1 + 0.05, 0, U=U0)
    _, u_elastic, _ = flow_two(st0, t1 + 0.05, 1, U=U0)
    assert np.linalg.norm(u_mirror - u_elastic) > 0.1 * np.linalg.norm(u_mirror)


@pytest.mark.parametrize(("mode", "angle"), [(0, 2.5), (1, 0.4)])
def test_kick_tangent_map_is_the_finite_difference_jacobian(mode, angle):
    s = np.array([0.1, -0.2, 0.8, 0.6])
    st0 = one_state(s)
    t_wall = boundary_hit_time(*s, RHO)
    kicks, angles = np.array([0.3 * t_wall]), np.array([angle])
    # the kick alone, then a kick followed by a wall reflection
    assert_tangent_matches_finite_differences_one(st0, 0.6 * t_wall, kicks, angles, mode)
    assert_tangent_matches_finite_differences_one(st0, 0.5 * t_wall + 0.4, kicks, angles, mode)


def test_non_unit_speed_survives_a_uniform_kick_as_a_speed_deviation():
    st0 = one_state(np.array([0.1, -0.2, 1.6, 1.2]))  # speed 2
    kicks, angles = np.array([0.05]), np.array([1.0])
    assert_tangent_matches_finite_differences_one(st0, 0.1, kicks, angles, 0)
    # a velocity deviation along v (a speed change) is kept, one across v is erased
    _, U, _ = flow_one(st0, 0.1, kicks, angles, 0, U=np.array([[0, 0, 0.8, 0.6],
                                                                [0, 0, -0.6, 0.8]]))
    assert np.hypot(U[0, 2], U[0, 3]) == pytest.approx(1.0)
    assert np.hypot(U[1, 2], U[1, 3]) < 1e-15


# ------------------------------------------------------------ against the twin method
R_AGREE = 0.03
NO_SCATTER = np.zeros((0, 2))  # kernels' scatter arguments when kicks are not scattering
NO_PARTNER = np.zeros(4)
STEPS = dict(n_steps=10000, tau=0.2)

SYSTEMS = {
    "two-disk mirror": lambda ic, **kw: lyapunov(ic, R_AGREE, **(STEPS | kw)),
    "two-disk elastic": lambda ic, **kw: lyapunov(ic, R_AGREE, rule="elastic", **(STEPS | kw)),
    "kicked uniform": lambda ic, **kw: lyapunov(ic[0], R_AGREE, kicks=schedules.Poisson(0.05),
                                                rng=7, **(STEPS | kw)),
    "kicked gaussian": lambda ic,
    **kw: lyapunov(ic[0], R_AGREE, kicks=KickLaw(schedules.Poisson(0.05), angle="gaussian"),
                                                 rng=7, **(STEPS | kw)),
}


@pytest.fixture(scope="module")
def ics20():
    return initial_conditions(20, R_AGREE, rng=5)


@pytest.mark.parametrize("system", list(SYSTEMS))
def test_tangent_agrees_with_the_twin_at_small_d0_on_every_ic(ics20, system):
    fn = SYSTEMS[system]
    for ic in ics20:
        tangent = fn(ic)
        twin = fn(ic, method=Twin(d0=1e-8))
        assert tangent.method == "tangent" and twin.method == "twin"
        assert tangent.n_perturbations == twin.n_perturbations > 0
        assert abs(tangent.lam - twin.lam) <= 0.02 * abs(twin.lam), (tangent, twin)


@pytest.mark.parametrize("system", list(SYSTEMS))
def test_twin_exponent_does_not_depend_on_d0_on_average(ics20, system):
    fn = SYSTEMS[system]
    big = np.mean([fn(ic, method=Twin(d0=2e-4)).lam for ic in ics20])
    small = np.mean([fn(ic, method=Twin(d0=2e-6)).lam for ic in ics20])
    assert abs(big - small) <= 0.05 * small


def test_paper_variant_tangent_vectors_agree_with_the_paper_twins(ics20):
    for ic in ics20[:3]:
        tangent = lyapunov(ic, R_AGREE, **STEPS, method=Tangent(variant="paper"))
        twin = lyapunov(ic, R_AGREE, **STEPS, method=Twin(variant="paper", d0=1e-8))
        assert tangent.lam == max(tangent.lam_x, tangent.lam_y)
        for a, b in ((tangent.lam_x, twin.lam_x), (tangent.lam_y, twin.lam_y)):
            assert abs(a - b) <= 0.02 * abs(b)


@pytest.mark.parametrize("sampling", ["uniform", "paper"])
def test_paper_sampling_ends_where_the_twin_ends(ics20, sampling):
    tangent = lyapunov(ics20[0], R_AGREE, sampling=sampling, **STEPS)
    twin = lyapunov(ics20[0], R_AGREE, sampling=sampling, method=Twin(d0=1e-8), **STEPS)
    assert tangent.total_time == twin.total_time
    assert abs(tangent.lam - twin.lam) <= 0.02 * twin.lam


# ------------------------------------------------------------------- integrable billiard
def test_unkicked_disk_exponent_decays_like_log_t_over_t(ics20):
    horizons = [500, 2500, 12500, 62500]
    for ic in ics20[:4]:
        lams = [lyapunov(ic[0], R_AGREE, n_steps=n, tau=0.2).lam for n in horizons]
        assert all(a > b for a, b in zip(lams, lams[1:], strict=False))  # decreasing
        # the integrable billiard shears: |dq(T)| grows at most linearly, |dq(T)| <= 1 + 2 T
        for lam, n in zip(lams, horizons, strict=True):
            t = 0.2 * n
            assert 0.0 < lam <= math.log(1.0 + 2.0 * t) / t


def test_unkicked_disk_exponent_is_below_the_round_off_driven_twin(ics20):
    # d0 = 1e-14 is refused by lyapunov(); the twin kernel shows why
    for ic in ics20[:4]:
        st = np.zeros(7)
        st[1:5] = ic[0]
        st[6] = 1.0
        for n in (2500, 25000):
            tangent = lyapunov(ic[0], R_AGREE, n_steps=n, tau=0.2).lam
            out = ftle_one_kernel(st.copy(), 1.0 - R_AGREE, np.empty(0), np.empty(0), 0, 1, n,
                                  0.2, np.array([[1e-14, 0.0]]), np.array([0]), 1e-14, 10,
                                  10**8, NO_SCATTER, NO_PARTNER, None, True,
                                  np.empty((0, 0)))
            twin_tiny = out[0][0] / out[4][0]
            assert tangent < 0.75 * twin_tiny


def test_unkicked_disk_ensemble_mean_is_below_the_default_twin(ics20):
    for n in (2500, 25000):
        tangent = np.mean([lyapunov(ic[0], R_AGREE, n_steps=n, tau=0.2).lam for ic in ics20])
        twin = np.mean([lyapunov(ic[0], R_AGREE, n_steps=n, tau=0.2, method="twin").lam
                        for ic in ics20])
        assert tangent < twin


# ----------------------------------------------------------- stretching per perturbation
def test_disk_disk_collisions_stretch_more_than_kicks_by_about_log_one_over_r():
    r = 0.02
    ics = initial_conditions(12, r, rng=9)
    two = [lyapunov(ic, r, **STEPS) for ic in ics]
    kicked = [lyapunov(ic[0], r, **STEPS, rng=i, kicks=schedules.Poisson(
        res.n_perturbations / res.total_time)) for i, (ic, res) in enumerate(zip(ics, two,
                                                                                  strict=True))]
    per_pp = np.median([res.lam_per_perturbation for res in two])
    per_kick = np.median([res.lam_per_perturbation for res in kicked])
    assert 0.5 * math.log(1 / r) < per_pp - per_kick < 1.5 * math.log(1 / r)
    # hence the kicked exponent is well below the two-disk one at the same rate
    assert np.median([k.lam / t.lam for k, t in zip(kicked, two, strict=True)]) < 0.6


def test_lam_per_perturbation_is_lam_times_time_over_count(ics20):
    res = lyapunov(ics20[1], R_AGREE, **STEPS)
    assert res.lam_per_perturbation == pytest.approx(res.lam * res.total_time
                                                     / res.n_perturbations)
    assert math.isnan(lyapunov(ics20[1, 0], R_AGREE, **STEPS).lam_per_perturbation)


# ----------------------------------------------------------------------------- slow
@pytest.mark.slow
@pytest.mark.parametrize("system", list(SYSTEMS))
def test_tangent_agrees_with_the_twin_at_paper_scale(system):
    ics = initial_conditions(50, R_AGREE, rng=12)
    steps = dict(n_steps=25000, tau=0.2)
    fn = SYSTEMS[system]
    for ic in ics:
        tangent = fn(ic, **steps)
        twin = fn(ic, method=Twin(d0=1e-8), **steps)
        assert abs(tangent.lam - twin.lam) <= 0.02 * abs(twin.lam)


# ------------------------------------------------------------------------- the spectrum
@pytest.mark.parametrize("rule", ["elastic", "mirror"])
def test_spectrum_top_exponent_is_the_ftle_and_phase_volume_is_conserved(ics20, rule):
    t = 2000.0
    for ic in ics20[:3]:
        spec = lyapunov_spectrum(ic, R_AGREE, t_max=t, rule=rule).exponents
        lam = lyapunov(ic, R_AGREE, n_steps=10000, tau=0.2, rule=rule).lam
        assert spec[0] == pytest.approx(lam, rel=0.02)
        assert spec[0] > 0.05
        assert abs(spec.sum()) < 1e-6  # both rules preserve phase-space volume
        if rule == "elastic":  # symplectic: lambda_1 = -lambda_8 (no such theorem for mirror)
            assert spec[0] + spec[-1] == pytest.approx(0.0, abs=0.01 * spec[0])
        # time translation (and, elastic: energy, rotation, angular momentum) give zeros
        small = np.abs(spec) < 5 * math.log(t) / t
        assert small.sum() >= (4 if rule == "elastic" else 3)


def test_elastic_spectrum_comes_in_pairs_summing_to_zero(ics20):
    spec = lyapunov_spectrum(ics20[0], R_AGREE, t_max=2000.0, rule="elastic").exponents
    np.testing.assert_allclose(spec + spec[::-1], 0.0, atol=1e-3)
    assert spec[1] > 10 * abs(spec[2])  # two positive exponents, well above the zeros


# ------------------------------------------ one pass: simulation and tangent vectors together
def _two_args(ic, r, *, mode, n_steps, tau, max_events=None, rule="mirror"):
    from kicktimes.billiard.two_particle import kernel_args

    return kernel_args(np.asarray(ic, dtype=float), r, rule, mode,
                       n_steps * tau if mode == 1 else None, n_steps, tau, 0, max_events)


@pytest.mark.parametrize("mode", [1, 2])
def test_one_pass_kernel_carries_every_tangent_vector_as_the_tangent_kernel(mode):
    from kicktimes.billiard.kernels.drive_two import (
        simulate_tangent_two_kernel,
        simulate_two_kernel,
    )

    ic = initial_conditions(1, R, rng=21, rule="elastic")[0]
    args = _two_args(ic, R, mode=mode, n_steps=600, tau=0.3, rule="elastic")
    U, U_ref = np.eye(8), np.eye(8)
    out = simulate_tangent_two_kernel(*(a.copy() if isinstance(a, np.ndarray) else a
                                        for a in args), U, 10**6, 0.0)
    ref = tangent_two_kernel(two_state(ic), RHO2, SIG, 1, mode, 600, 0.3, U_ref, 10**6, 0)
    assert U.tobytes() == U_ref.tobytes()
    np.testing.assert_array_equal(out[11], ref[0])
    assert out[12:16] == (ref[1], ref[2], ref[3], ref[4])
    sim = simulate_two_kernel(*args, False)
    assert out[0].tobytes() == sim[0].tobytes() and out[1] == sim[0].size
    assert out[7].tobytes() == sim[6].tobytes() and out[8].tobytes() == sim[7].tobytes()
    assert out[9] == sim[8] and out[10] == sim[10] == 0


def test_an_exhausted_tangent_budget_stops_only_the_tangent_half():
    from kicktimes.billiard.kernels.drive_two import (
        simulate_tangent_two_kernel,
        simulate_two_kernel,
    )

    ic = initial_conditions(1, R, rng=22)[0]
    args = _two_args(ic, R, mode=2, n_steps=500, tau=0.3)
    out = simulate_tangent_two_kernel(*(a.copy() if isinstance(a, np.ndarray) else a
                                        for a in args), np.eye(8)[[0]], 50, 0.0)
    sim = simulate_two_kernel(*args, False)
    assert out[15] == 1 and out[10] == 0  # the FTLE's budget error; the run completes
    assert out[0].tobytes() == sim[0].tobytes() and out[8].tobytes() == sim[7].tobytes()


def test_the_continuation_has_the_event_budget_of_a_run_to_t_continue():
    from kicktimes import simulate_two_particle
    from kicktimes.billiard.kernels.drive_two import simulate_tangent_two_kernel

    ic = initial_conditions(1, R, rng=23)[0]
    run = simulate_two_particle(ic, R, sampling="paper", n_steps=500, tau=0.3)
    budget = run.n_pp + run.n_boundary + 5  # enough for the run, not for its continuation
    with pytest.raises(ValueError, match="max_events"):
        simulate_two_particle(ic, R, t_max=150.0, max_events=budget)
    args = _two_args(ic, R, mode=2, n_steps=500, tau=0.3, max_events=budget)
    out = simulate_tangent_two_kernel(*args, np.eye(8)[[0]], 10**6, 150.0)
    assert out[10] == 0 and out[16] == 3  # run DONE, continuation OVER_BUDGET
    assert out[1] == run.n_pp and out[0].size + run.n_boundary <= budget + 1
