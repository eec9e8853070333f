"""Tables beyond the circle (kicktimes.tables, docs/tables.md): wall times against a brute
force, the conserved quantities, the Lyapunov exponents, the circle against the simulators'
geometry, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kicktimes.billiard import geometry as geo
from kicktimes.billiard.kernels import tables as K
from kicktimes.tables import (
    Circle,
    Ellipse,
    Stadium,
    TableLyapunov,
    TableRun,
    free_run,
    table_lyapunov,
    uniform_state,
)

N_STATES = 10_000
#: the stadium's exponent per unit time, quoted from Benettin & Strelcyn, Phys. Rev. A 17, 773
#: (1978): see test_stadium_lyapunov_is_the_published
STADIUM_LYAPUNOV = 0.43


# --- the brute force: fine steps of "outside the centre's curve" along the flight, bisection

def _ellipse_radius(A, B, r, psi):
    """Polar radius of the ellipse's parallel curve in the directions ``psi`` (vectorised
    bisection on the curve parameter, in the quadrant of ``psi``: C(t) keeps the quadrant of
    (cos t, sin t) for r < b^2/a)."""
    psi = np.mod(psi, 2 * np.pi)
    lo = np.floor(psi / (np.pi / 2)) * (np.pi / 2)
    hi = lo + np.pi / 2
    cp, sp = np.cos(psi), np.sin(psi)
    for _ in range(56):
        t = 0.5 * (lo + hi)
        c, s = np.cos(t), np.sin(t)
        h = np.sqrt(B * B * c * c + A * A * s * s)
        cx, cy = (A - r * B / h) * c, (B - r * A / h) * s
        behind = cx * sp - cy * cp > 0  # C(t) clockwise of psi: t too small
        lo = np.where(behind, t, lo)
        hi = np.where(behind, hi, t)
    t = 0.5 * (lo + hi)
    c, s = np.cos(t), np.sin(t)
    h = np.sqrt(B * B * c * c + A * A * s * s)
    return np.hypot((A - r * B / h) * c, (B - r * A / h) * s)


def _outside(table, r, x, y):
    """> 0 outside the centre's region, <= 0 inside (a distance-like margin)."""
    if isinstance(table, Circle):
        return np.hypot(x, y) - (1 - r)
    if isinstance(table, Stadium):
        return np.hypot(np.maximum(np.abs(x) - table.a, 0.0), y) - (1 - r)
    return np.hypot(x, y) - _ellipse_radius(table.a, table.b, r, np.arctan2(y, x))


def brute_wall_times(table, r, q, v, n_steps=16, n_bisect=52):
    """Time to leave the centre's region: the first of ``n_steps`` steps across the longest
    possible flight that lands outside, then bisection. The region is convex, so the flight
    is inside up to the wall and outside after it."""
    span = 2.0 * (1.0 + getattr(table, "a", 0.0) + 1.0) / np.hypot(v[:, 0], v[:, 1])
    taus = span[:, None] * np.arange(1, n_steps + 1)[None, :] / n_steps
    out = _outside(table, r, q[:, :1] + v[:, :1] * taus, q[:, 1:] + v[:, 1:] * taus) > 0
    assert out[:, -1].all()
    k = out.argmax(axis=1)
    rows = np.arange(len(q))
    hi = taus[rows, k]
    lo = np.where(k > 0, taus[rows, np.maximum(k - 1, 0)], 0.0)
    for _ in range(n_bisect):
        mid = 0.5 * (lo + hi)
        o = _outside(table, r, q[:, 0] + v[:, 0] * mid, q[:, 1] + v[:, 1] * mid) > 0
        hi = np.where(o, mid, hi)
        lo = np.where(o, lo, mid)
    return 0.5 * (lo + hi)


def _wall_points(table, r, u):
    """Points of the centre's curve, its outward normals and tangents, at parameters
    ``u`` in [0, 1) (by arc on the circle and the ellipse's parameter; the stadium's pieces
    in proportion)."""
    if isinstance(table, Ellipse):
        A, B = table.a, table.b
        t = 2 * np.pi * u
        c, s = np.cos(t), np.sin(t)
        h = np.sqrt(B * B * c * c + A * A * s * s)
        p = np.stack([(A - r * B / h) * c, (B - r * A / h) * s], axis=1)
        n = np.stack([B * c / h, A * s / h], axis=1)
    elif isinstance(table, Stadium):
        a, rho = table.a, 1 - r
        ang = 2 * np.pi * u
        n = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        centre = np.where(n[:, :1] >= 0, a, -a) * np.array([1.0, 0.0])
        p = centre + rho * n
        # a third of the points on the segments
        seg = u < 1 / 3
        xs = a * (6 * u[seg] - 1)
        p[seg] = np.stack([xs, np.where(np.arange(seg.sum()) % 2, rho, -rho)], axis=1)
        n[seg] = np.stack([np.zeros(seg.sum()), np.sign(p[seg, 1])], axis=1)
    else:
        ang = 2 * np.pi * u
        n = np.stack([np.cos(ang), np.sin(ang)], axis=1)
        p = (1 - r) * n
    tang = np.stack([-n[:, 1], n[:, 0]], axis=1)
    return p, n, tang


def random_states(table, r, n, rng):
    """``n`` states: 60 % uniform inside, 20 % leaving the wall at small angles (1e-5 to
    1e-2 rad), 10 % inside near the wall flying almost along it, 10 % aimed at the
    stadium's joins (or, elsewhere, more uniform ones)."""
    n_u, n_g, n_n = int(0.6 * n), int(0.2 * n), int(0.1 * n)
    n_j = n - n_u - n_g - n_n
    q = np.array([uniform_state(table, r, rng=rng) for _ in range(n_u)])
    states = [q]
    # leaving the wall, grazing
    p, nrm, tan = _wall_points(table, r, rng.uniform(size=n_g))
    eps = 10 ** rng.uniform(-5, -2, n_g)
    sgn = rng.choice([-1.0, 1.0], n_g)
    v = sgn[:, None] * np.cos(eps)[:, None] * tan - np.sin(eps)[:, None] * nrm
    states.append(np.hstack([p, v]))
    # inside near the wall, nearly tangent
    p, nrm, tan = _wall_points(table, r, rng.uniform(size=n_n))
    depth = 10 ** rng.uniform(-6, -3, n_n)
    ang = rng.uniform(-1e-3, 1e-3, n_n)
    v = np.cos(ang)[:, None] * tan + np.sin(ang)[:, None] * nrm
    states.append(np.hstack([p - depth[:, None] * nrm, v]))
    if isinstance(table, Stadium):
        a, rho = table.a, 1 - r
        corner = np.stack([rng.choice([-a, a], n_j), rng.choice([-rho, rho], n_j)], axis=1)
        corner[:, 0] += rng.choice([-1, 1], n_j) * 10 ** rng.uniform(-12, -4, n_j)
        half = n_j // 2
        start = np.array([uniform_state(table, r, rng=rng)[:2] for _ in range(n_j)])
        # half aimed at the joins from inside, half sliding along a segment into them
        start[half:, 0] = rng.uniform(-a, a, n_j - half)
        start[half:, 1] = corner[half:, 1] * (1 - 1e-12)
        d = corner - start
        d[half:, 1] = np.sign(corner[half:, 1]) * 10 ** rng.uniform(-5, -3, n_j - half) \
            * np.abs(d[half:, 0])
        d /= np.hypot(d[:, 0], d[:, 1])[:, None]
        states.append(np.hstack([start, d]))
    else:
        states.append(np.array([uniform_state(table, r, rng=rng) for _ in range(n_j)]))
    return np.vstack(states)


TABLES = [(Circle(), 0.05), (Stadium(1.0), 0.05), (Stadium(0.3), 1e-9),
          (Ellipse(2.0, 1.0), 0.3), (Ellipse(1.5, 1.0), 1e-9)]


@pytest.mark.parametrize(("table", "r"), TABLES, ids=repr)
def test_wall_times_agree_with_a_brute_force(table, r):
    rng = np.random.default_rng(7)
    s = random_states(table, r, N_STATES, rng)
    kind, p0, p1, p2 = table.kernel(r)
    got = np.array([K.wall_time(kind, p0, p1, p2, *row) for row in s])
    want = brute_wall_times(table, r, s[:, :2], s[:, 2:])
    err = np.abs(got - want)
    assert err.max() < 1e-10, (err.max(), s[err.argmax()])
    # a grazing exit is short and a centre on the wall does not hit it again at once
    assert got.min() > 0


def test_ellipse_wall_time_fallback_agrees_with_the_fast_path():
    rng = np.random.default_rng(3)
    A, B, r = 2.0, 1.0, 0.3
    for _ in range(200):
        x, y, vx, vy = uniform_state(Ellipse(A, B), r, rng=rng)
        t, c, s = K.ellipse_hit(x, y, vx, vy, A, B, r)
        c2, s2 = K._ellipse_bracketed(x, y, vx, vy, A, B, r)
        assert abs(c - c2) < 1e-12 and abs(s - s2) < 1e-12


def test_the_circle_table_is_the_simulators_geometry():
    rng = np.random.default_rng(11)
    r = 0.05
    s = random_states(Circle(), r, 2000, rng)
    kind, p0, p1, p2 = Circle().kernel(r)
    got = np.array([K.wall_time(kind, p0, p1, p2, *row) for row in s])
    ref = np.array([geo.boundary_hit_time(*row, 1 - r) for row in s])
    assert np.abs(got - ref).max() <= 1e-14
    # normal and the incoming sin(theta) as the circle's kernels have them
    x, y, vx, vy = s[0]
    t = got[0]
    xc, yc, nx, ny, kappa = K.contact(kind, p0, p1, p2, x + vx * t, y + vy * t, vx, vy, 0, 0)
    assert (nx, ny) == pytest.approx(geo.boundary_normal(xc, yc), abs=1e-15)
    assert kappa == 1 / (1 - r)
    _, st = K.boundary_coordinates(kind, p0, p1, p2, xc, yc, vx, vy)
    assert st == pytest.approx(geo.sin_theta_at(xc, yc, vx, vy, 1 - r), abs=1e-15)


# --- conservation and staying inside --------------------------------------------------------

def _run_checks(table, r, n):
    st = uniform_state(table, r, rng=5)
    run = free_run(table, st, r, n_bounces=n, n_record=min(n, 10**5), tangent=False)
    assert run.n_bounces == n and run.reason == "tangent=False: no exponent"
    speeds = np.hypot(run.velocities[:, 0], run.velocities[:, 1])
    assert np.abs(speeds - 1).max() < 1e-12
    assert abs(run.speed_drift) < 1e-12
    assert table.contains(run.positions, r).all()
    assert np.all(np.diff(run.times) > 0)
    return run


@pytest.mark.parametrize(("table", "r"), TABLES, ids=repr)
def test_speed_is_kept_and_the_disk_stays_inside(table, r):
    _run_checks(table, r, 20_000)


@pytest.mark.full
@pytest.mark.parametrize(("table", "r"), TABLES, ids=repr)
def test_speed_is_kept_over_a_million_bounces(table, r):
    _run_checks(table, r, 10**6)


def _focal_product(a, b, q, v):
    c = math.sqrt(a * a - b * b)
    l1 = (q[:, 0] - c) * v[:, 1] - q[:, 1] * v[:, 0]
    l2 = (q[:, 0] + c) * v[:, 1] - q[:, 1] * v[:, 0]
    return l1 * l2


@pytest.mark.parametrize("n", [pytest.param(10**5), pytest.param(10**6, marks=pytest.mark.full)])
def test_point_particle_in_the_ellipse_keeps_the_focal_angular_momenta_product(n):
    a, b, r = 1.5, 1.0, 1e-9
    st = uniform_state(Ellipse(a, b), r, rng=9)
    run = free_run(Ellipse(a, b), st, r, n_bounces=n, tangent=False)
    prod = _focal_product(a, b, run.positions, run.velocities)
    p0 = _focal_product(a, b, st[None, :2], st[None, 2:])[0]
    assert np.abs(prod - p0).max() < 1e-8
    # and it is a real invariant: a stadium's flight does not keep it
    srun = free_run(Stadium(0.5), uniform_state(Stadium(0.5), r, rng=9), r, n_bounces=100,
                    tangent=False)
    sp = _focal_product(a, b, srun.positions, srun.velocities)
    assert np.ptp(sp) > 1e-2


# --- Lyapunov exponents ---------------------------------------------------------------------

def test_stadium_lyapunov_is_the_published():
    """The point particle's maximal exponent in the stadium of unit radius and a = 1 (the
    straight segments 2a = 2), unit speed, per unit time: lambda ~ 0.43, the value quoted
    from Benettin & Strelcyn, Phys. Rev. A 17, 773 (1978) (per bounce it is lambda times the
    mean free time pi A / L = 2.18, about 0.94). The paper's text was not reachable with the
    project's search tools: re-check its value and convention against the paper.
    Averaged over 10 orbits of 2e5 bounces (the spread of one orbit's exponent is ~1 %)."""
    table, r = Stadium(1.0), 1e-9
    rng = np.random.default_rng(2026)
    values = [table_lyapunov(table, uniform_state(table, r, rng=rng), r, n_bounces=200_000,
                             rng=rng) for _ in range(10)]
    lam = np.mean([v.exponent for v in values])
    assert lam == pytest.approx(STADIUM_LYAPUNOV, rel=0.02)
    # per bounce: the same over the mean free time pi A / L
    per = np.mean([v.per_bounce for v in values])
    assert per == pytest.approx(lam * table.mean_free_time(r), rel=0.01)


@pytest.mark.parametrize(("table", "r", "positive"), [
    (Stadium(1.0), 0.05, True), (Stadium(0.3), 0.02, True),
    (Ellipse(1.5, 1.0), 0.02, False), (Circle(), 0.05, False)], ids=repr)
def test_tangent_exponent_agrees_with_the_renormalised_twin(table, r, positive):
    st = uniform_state(table, r, rng=4)
    tan = table_lyapunov(table, st, r, n_bounces=50_000, rng=4)
    twin = table_lyapunov(table, st, r, n_bounces=50_000, method="twin", rng=4)
    assert isinstance(tan, TableLyapunov) and tan.reason is None and twin.reason is None
    if positive:
        assert tan.exponent > 0.1
        assert twin.exponent == pytest.approx(tan.exponent, rel=0.05)
    else:
        # integrable: polynomial growth only, both exponents near zero
        assert abs(tan.exponent) < 2e-3 and abs(twin.exponent) < 2e-3


def test_curved_wall_tangent_is_the_circle_s_at_constant_curvature():
    from kicktimes.billiard.kernels.tangent import curved_wall_tangent, wall_tangent

    rho = 0.95
    x, y = rho * math.cos(0.3), rho * math.sin(0.3)
    vx, vy = -0.2, 0.98
    wx, wy = geo.reflect(vx, vy, x / rho, y / rho)
    a = wall_tangent(0.1, -0.2, 0.3, 0.05, x, y, vx, vy, wx, wy, rho)
    b = curved_wall_tangent(0.1, -0.2, 0.3, 0.05, vx, vy, wx, wy, x / rho, y / rho, 1 / rho)
    assert b == pytest.approx(a, abs=1e-15)


def test_tangent_map_matches_finite_differences_in_the_ellipse():
    # the exact tangent after a few bounces against two nearby orbits (central difference)
    table, r = Ellipse(2.0, 1.0), 0.3
    st = uniform_state(table, r, rng=8)
    u = np.array([1e-7, -2e-7, 3e-7, 1e-7])
    base = free_run(table, st, r, t_max=7.0, n_record=0, tangent=False).state
    plus = free_run(table, st + u, r, t_max=7.0, n_record=0, tangent=False).state
    minus = free_run(table, st - u, r, t_max=7.0, n_record=0, tangent=False).state
    from kicktimes.billiard.kernels.drive_tables import free_kernel

    kind, p0, p1, p2 = table.kernel(r)
    s = st.copy()
    uu = u / np.linalg.norm(u)
    free_kernel(kind, p0, p1, p2, s, 10**6, 7.0, np.empty((0, 5)), uu, True)
    fd = (plus - minus) / 2 / np.linalg.norm(u)
    assert np.allclose(s, base, atol=1e-12)
    assert np.allclose(uu, fd, atol=1e-5 * max(1.0, np.abs(fd).max()))


# --- coordinates, the values, bad input -----------------------------------------------------

def test_ellipse_arc_length_is_the_integral_and_ends_at_the_perimeter():
    from scipy.integrate import quad

    A, B, r = 2.0, 1.0, 0.3
    for t in (0.3, 1.7, 3.0, 4.4, 6.0):
        def speed(u):
            c, s = math.cos(u), math.sin(u)
            h = math.sqrt(B * B * c * c + A * A * s * s)
            return (1 - r * A * B / h**3) * math.hypot(A * s, B * c)
        want = quad(speed, 0.0, t, epsabs=1e-13, epsrel=1e-13, limit=200)[0]
        assert K.ellipse_arc_length(math.cos(t), math.sin(t), A, B, r) == pytest.approx(
            want, abs=1e-12)
    end = K.ellipse_arc_length(math.cos(-1e-12), math.sin(-1e-12), A, B, r)
    assert end == pytest.approx(Ellipse(A, B).perimeter(r), abs=1e-10)


def test_boundary_coordinates_run_around_the_curve():
    for table, r in TABLES:
        run = free_run(table, uniform_state(table, r, rng=1), r, n_bounces=2000,
                       tangent=False)
        bc = run.boundary_coordinates()
        assert bc.shape == (2000, 2)
        assert (bc[:, 0] >= 0).all() and (bc[:, 0] < table.perimeter(r) + 1e-12).all()
        assert (np.abs(bc[:, 1]) <= 1).all()
    # the stadium's s is continuous across the joins
    a, rho = 1.0, 0.95
    kind, p0, p1, p2 = Stadium(a).kernel(0.05)
    s_arc, _ = K.boundary_coordinates(kind, p0, p1, p2, a + 1e-13, rho, -1.0, 0.0)
    s_seg, _ = K.boundary_coordinates(kind, p0, p1, p2, a - 1e-13, rho, -1.0, 0.0)
    assert s_arc == pytest.approx(s_seg, abs=1e-12)
    assert s_arc == pytest.approx(0.5 * math.pi * rho, abs=1e-12)


def test_areas_and_perimeters():
    assert Circle().area(0.1) == pytest.approx(math.pi * 0.81)
    assert Stadium(1.0).perimeter(0.1) == pytest.approx(2 * math.pi * 0.9 + 4)
    # the inner parallel body of the ellipse: its area by the mean free time of a run
    table, r = Ellipse(1.5, 1.0), 0.1
    run = free_run(table, uniform_state(table, r, rng=3), r, n_bounces=10, tangent=False)
    assert run.n_bounces == 10
    assert table.area(r) < math.pi * 1.5 and table.perimeter(r) < table.perimeter(0.0)


@pytest.mark.parametrize(("make", "match"), [
    (lambda: Ellipse(1.0, 1.5), "b must lie in"),
    (lambda: Ellipse(0.0, 0.0), "a must lie in"),
    (lambda: Ellipse(1.0, -1.0), "b must lie in"),
    (lambda: Ellipse(math.inf, 1.0), "a must be finite"),
    (lambda: Stadium(0.0), "a must lie in"),
    (lambda: Stadium(-1.0), "a must lie in"),
    (lambda: Ellipse(2.0, 1.0).kernel(0.5), r"r must lie in \(0.0, 0.5\).*b\^2/a"),
    (lambda: Ellipse(2.0, 1.0).kernel(0.7), r"r must lie in .*b\^2/a"),
    (lambda: Stadium(1.0).kernel(1.0), r"r must lie in \(0.0, 1.0\)"),
    (lambda: Circle().kernel(0.0), r"r must lie in"),
    (lambda: free_run(Circle(), [0.99, 0, 1, 0], 0.05, n_bounces=3), "state: the centre"),
    (lambda: free_run(Circle(), [0, 0, 0, 0], 0.05, n_bounces=3), "must move"),
    (lambda: free_run(Circle(), [0, 0, 1, 0], 0.05), "n_bounces or t_max"),
    (lambda: table_lyapunov(Circle(), [0, 0, 1, 0], 0.05, n_bounces=3, method="x"),
     "method must be one of"),
])
def test_bad_input_is_refused_naming_the_argument(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_bad_types_are_refused():
    with pytest.raises(TypeError, match="table must be"):
        free_run("circle", [0, 0, 1, 0], 0.05, n_bounces=3)
    with pytest.raises(TypeError, match="a must be a real number"):
        Stadium("1")
    with pytest.raises(TypeError, match="rng must be"):
        free_run(Circle(), [0, 0, 1, 0], 0.05, n_bounces=3, rng="x")


def test_tables_are_frozen_values_that_summarise_themselves():
    t = Ellipse(1.5, 1.0)
    assert t == Ellipse(1.5, 1.0) and hash(t) == hash(Ellipse(1.5, 1.0))
    with pytest.raises(AttributeError):
        t.a = 2.0
    assert repr(t) == "Ellipse(a=1.5, b=1.0)" and "a: 1.5" in t.summary()
    assert Circle().summary().startswith("Circle")
    run = free_run(Stadium(1.0), [0, 0, 0.6, 0.8], 0.05, n_bounces=10, rng=1)
    assert isinstance(run, TableRun) and "lyapunov" in run.summary()


@pytest.mark.parametrize(("table", "r", "state"), [
    (Stadium(1.0), 0.05, [0.0, 0.95, 1.0, 0.0]),     # along the top segment into the join
    (Stadium(1.0), 0.05, [1.0, 0.95, -1.0, 0.0]),    # from the join, along the segment
    (Stadium(1.0), 0.05, [1.95, 0.0, 0.0, 1.0]),     # tangent to the right arc
    (Ellipse(2.0, 1.0), 0.3, [1.7, 0.0, 0.0, 1.0]),  # tangent at the sharpest point
    (Ellipse(2.0, 1.0), 0.3, [0.0, 0.7, -1.0, 0.0]),  # tangent at the flattest point
    (Circle(), 0.05, [0.95, 0.0, 0.0, 1.0]),
], ids=repr)
def test_exactly_tangent_flights_slide_on_and_stay_inside(table, r, state):
    run = free_run(table, state, r, n_bounces=5000, tangent=False)
    assert run.reason == "tangent=False: no exponent" and run.n_bounces == 5000
    assert np.all(np.diff(run.times) > 0)  # no contact twice at one instant
    assert table.contains(run.positions, r).all()
    assert abs(run.speed_drift) < 1e-12
    # it moves along the wall: the contacts run over a finite stretch of it
    s = run.boundary_coordinates()[:, 0]
    assert np.ptp(s) > 0.1
