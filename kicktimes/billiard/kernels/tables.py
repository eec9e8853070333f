"""Wall contacts of a disk's centre in the circle, the stadium and the ellipse (numba kernels).

A disk of radius ``r`` keeps its centre inside the table's inner parallel curve at distance
``r`` (docs/tables.md). Each table is a ``kind`` code and three floats ``(p0, p1, p2)``:

* ``CIRCLE`` ``(rho, 0, 0)``: the circle ``|q| = rho = 1 - r``;
* ``STADIUM`` ``(a, rho, 0)``: the stadium of semicircles of radius ``rho = 1 - r`` centred
  at ``(+-a, 0)`` joined by the segments ``y = +-rho``, ``|x| <= a``;
* ``ELLIPSE`` ``(A, B, r)``: the parallel curve ``C(t) = P(t) - r N(t)`` of the ellipse
  ``P(t) = (A cos t, B sin t)``, ``N(t) = (B cos t, A sin t) / h``,
  ``h = sqrt(B^2 cos^2 t + A^2 sin^2 t)``; so ``C(t) = ((A - r B / h) cos t,
  (B - r A / h) sin t)``, smooth and convex for ``r < B^2 / A``.

`hit` returns the time to the next contact and a "where" ``(w1, w2)`` (the stadium's piece;
the ellipse's normal at the contact), `contact` puts a centre advanced by that
time back on the wall and gives the outward unit normal and the curvature of the centre's
curve there, `bounce` reflects (or, at a grazing contact, lets the disk slide on, as
`kicktimes.billiard.geometry.graze` does in the circle). `boundary_coordinates` gives the
arc length along the centre's curve and ``sin`` of the angle to the normal.

Every kernel takes and returns plain floats, so numba keeps the event loop in registers.
The circle's time is `kicktimes.billiard.geometry.boundary_hit_time` itself.
"""

from __future__ import annotations

import math

from numba import njit

from kicktimes.billiard import geometry as geo

__all__ = ["CIRCLE", "ELLIPSE", "STADIUM", "boundary_coordinates", "bounce", "circle_contact",
           "contact",
           "ellipse_arc_length", "ellipse_hit", "ellipse_normal", "ellipse_parameter", "hit",
           "stadium_contact", "stadium_hit", "wall_time"]

CIRCLE, STADIUM, ELLIPSE = 0, 1, 2
INF = math.inf
#: the stadium's pieces (the ``w1`` of its contacts)
TOP, LEFT, BOTTOM, RIGHT = 0, 1, 2, 3
#: Newton iterations of the ellipse's fast path before the bracketed fallback
_NEWTON_MAX = 8
#: the fast path's last Newton step: below it the root is within ~(g''/2g') d^2 ~ 1e-14
_NEWTON_TOL = 1e-7
_TWO_PI = 2.0 * math.pi


# --- the stadium ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def stadium_hit(x, y, vx, vy, a, rho):
    """``(t, piece)``: time until a centre at ``(x, y)`` moving with ``(vx, vy)`` reaches the
    stadium's wall, and the piece it reaches (``TOP``, ``LEFT``, ``BOTTOM``, ``RIGHT``).

    The stadium is convex and lies in the strip ``|y| <= rho``: if the strip's exit point
    ``X = x + vx t_s`` (``t_s = (+-rho - y) / vy``) has ``|X| <= a`` it is on a segment and
    is the contact; otherwise the contact is on the arc on the side of ``X`` (``X > a``: the
    right one), the exit root of its circle (`geometry.boundary_hit_time`, cancellation-free,
    0 for a centre a hair outside moving outward). At a join both rules give the same time
    to round-off (the arc and the segment are tangent there), so no classification error
    can cost more than round-off.
    """
    if vx == 0.0 and vy == 0.0:
        return INF, -1
    if vy != 0.0:
        ts = ((rho if vy > 0.0 else -rho) - y) / vy
        if ts < 0.0:
            ts = 0.0
        xs = x + vx * ts
        if -a <= xs <= a:
            return ts, TOP if vy > 0.0 else BOTTOM
        right = xs > a
    else:
        right = vx > 0.0
    cx = a if right else -a
    return geo.boundary_hit_time(x - cx, y, vx, vy, rho), RIGHT if right else LEFT


@njit(cache=True, error_model="numpy")
def stadium_contact(x, y, vx, vy, a, rho, piece):
    """``(x, y, nx, ny, kappa)``: the contact on ``piece`` put back on the wall, the outward
    unit normal and the curvature (0 on a segment, ``1 / rho`` on an arc).

    A segment's contact moves along the flight onto ``y = +-rho``; an arc's by one Newton
    step along the flight onto its circle (as `kicktimes.billiard.kernels.one.wall_event`
    does in the circle), or radially if the flight is tangent to the wall.
    """
    if piece == TOP or piece == BOTTOM:
        yw = rho if piece == TOP else -rho
        if vy != 0.0:
            x -= vx * ((y - yw) / vy)
        return x, yw, 0.0, 1.0 if piece == TOP else -1.0, 0.0
    cx = a if piece == RIGHT else -a
    px, py, nx, ny, kappa = circle_contact(x - cx, y, vx, vy, rho)
    return px + cx, py, nx, ny, kappa


@njit(cache=True, error_model="numpy")
def circle_contact(x, y, vx, vy, rho):
    """``(x, y, nx, ny, kappa)`` of a contact with the circle ``|x| = rho`` centred at the
    origin: the centre put back on the circle by one Newton step along the flight (as
    `kicktimes.billiard.kernels.one.wall_event` does), or radially if the flight is
    (nearly) tangent to it, the outward normal ``x / rho`` and the curvature ``1 / rho``.
    The circle table's contact, and the stadium's on its arcs (shifted to the arc's
    centre)."""
    xv = x * vx + y * vy
    vv = vx * vx + vy * vy
    gz = geo.GRAZE_THRESHOLD * rho
    if xv > 0.0 and xv * xv >= gz * gz * vv:
        e = (x * x + y * y - rho * rho) / (2.0 * xv)
        x -= vx * e
        y -= vy * e
    else:
        k = 1.5 - 0.5 * (x * x + y * y) / (rho * rho)
        x *= k
        y *= k
    return x, y, x / rho, y / rho, 1.0 / rho


# --- the ellipse ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def _ellipse_g(c, s, x, y, wx, wy, A, B, r):
    """``(g, g', Cx, Cy)`` at ``t`` (``c = cos t``, ``s = sin t``): ``g = (C(t) - q).w``
    and its derivative ``C'(t).w``, ``C' = (1 - r kappa) P'``, ``kappa = A B / h^3``."""
    ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
    rih = r * ih
    cx = (A - B * rih) * c
    cy = (B - A * rih) * s
    f = 1.0 - A * B * rih * ih * ih
    return ((cx - x) * wx + (cy - y) * wy, f * (B * c * wy - A * s * wx), cx, cy)


@njit(cache=True, error_model="numpy")
def _rotate(c, s, d):
    """``(cos, sin)`` of ``t + d + O(d^3)`` from those of ``t``, of norm 1 to ``O(d^8)``.

    Newton's iteration converges quadratically with any step ``d (1 + O(d^2))``, so small
    steps rotate by ``(1 - d^2 / 2, d)`` and renormalise with one Newton step of the norm
    (no trigonometry, no square root); large ones (a poor start) rotate exactly.
    """
    if abs(d) < 0.1:
        cd = 1.0 - 0.5 * d * d
        c2 = c * cd - s * d
        s2 = s * cd + c * d
        k = 1.5 - 0.5 * (c2 * c2 + s2 * s2)
        return c2 * k, s2 * k
    sd = math.sin(d)
    cd = math.cos(d)
    return c * cd - s * sd, s * cd + c * sd


@njit(cache=True, error_model="numpy")
def _ellipse_bracketed(x, y, vx, vy, A, B, r):
    """The exit root by safeguarded Newton on its bracket (the fallback of `ellipse_hit`).

    With ``w = (vy, -vx)``, ``g(t) = (C(t) - q).w`` is largest at ``t_w``, where the normal
    is along ``w`` (``t_w = atan2(B w_y, A w_x)``), smallest at ``t_w + pi``, and decreases
    in between, on the arc whose normals turn through ``+v``: the arc of the exit. Bisection
    keeps the bracket, Newton steps inside it speed the end up.
    """
    wx = vy
    wy = -vx
    lo = math.atan2(B * wy, A * wx)
    hi = lo + math.pi
    t = 0.5 * (lo + hi)
    for _ in range(200):
        c = math.cos(t)
        s = math.sin(t)
        g, gp, _, _ = _ellipse_g(c, s, x, y, wx, wy, A, B, r)
        if g > 0.0:
            lo = t
        else:
            hi = t
        if hi - lo <= 4e-16 * (abs(lo) + 1.0):
            break
        tn = t - g / gp if gp < 0.0 else 0.5 * (lo + hi)
        if not (lo < tn < hi):
            tn = 0.5 * (lo + hi)
        if abs(tn - t) < 1e-15 * (1.0 + abs(t)):
            t = tn
            break
        t = tn
    return math.cos(t), math.sin(t)


@njit(cache=True, error_model="numpy")
def _ellipse_hit(x, y, vx, vy, A, B, r):
    """``(t, cos u, sin u, 1 / h)``: time until the centre reaches the ellipse's parallel
    curve, the curve parameter ``u`` of the contact and ``1 / h(u)``.

    The contact solves ``g(u) = (C(u) - q).w = 0`` with ``w = (vy, -vx)`` perpendicular to
    the flight, on the arc where the normal turns through ``+v`` (``N.v > 0``: the exit,
    not the entry behind). Fast path: the flight's exit from the ellipse of semi-axes
    ``(A - r, B - r)`` (exact at the four vertices) gives a start, Newton's iteration on
    ``u`` (rotating ``(cos u, sin u)`` by the step, `_rotate`: no trigonometry) converges
    quadratically (2 to 4 evaluations); it is accepted if the step fell below ``1e-10`` and
    the root is an exit.
    Otherwise (near-tangent flights, where the entry and exit roots merge) the bracketed
    root of `_ellipse_bracketed`. Then ``t = (C(u) - q).v / |v|^2``, the foot of ``C(u)``
    on the flight line, so the advanced centre ``q + v t`` is within round-off of the wall.
    """
    vv = vx * vx + vy * vy
    if vv == 0.0:
        return INF, 1.0, 0.0, 1.0 / B
    wx = vy
    wy = -vx
    ial = 1.0 / (A - r)
    ibe = 1.0 / (B - r)
    X = x * ial
    Y = y * ibe
    VX = vx * ial
    VY = vy * ibe
    # the first guess: the exit from the scaled unit circle (the ellipse of the start)
    t0 = geo.boundary_hit_time(X, Y, VX, VY, 1.0)
    c = X + VX * t0
    s = Y + VY * t0
    nrm2 = c * c + s * s
    ok = False
    if nrm2 > 0.0:
        # on the unit circle up to round-off unless the flight missed the start's ellipse
        if abs(nrm2 - 1.0) < 1e-4:
            inrm = 1.5 - 0.5 * nrm2
        else:
            inrm = 1.0 / math.sqrt(nrm2)
        c *= inrm
        s *= inrm
        for _ in range(_NEWTON_MAX):
            # Halley's step (cubic convergence: one evaluation fewer than Newton's from
            # this start): g' = f P'.w and g'' = f' P'.w - f P.w, with f = 1 - r kappa,
            # f' = 3 A B r h' / h^4, h' = (A^2 - B^2) sin t cos t / h
            ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
            rih = r * ih
            ih3 = ih * ih * ih
            f = 1.0 - A * B * rih * ih * ih
            g = ((A - B * rih) * c - x) * wx + ((B - A * rih) * s - y) * wy
            pw = B * c * wy - A * s * wx
            gp = f * pw
            gpp = 3.0 * A * B * (A * A - B * B) * s * c * rih * ih3 * ih * pw - f * (
                A * c * wx + B * s * wy)
            den = 2.0 * gp * gp - g * gpp
            if not den > 0.0:
                break
            d = -2.0 * g * gp / den
            c, s = _rotate(c, s, d)
            if abs(d) < _NEWTON_TOL:  # quadratic convergence: now within ~(g''/2g') d^2
                ok = True
                break
        # the exit, not the entry: the normal (B c, A s) / h along the flight
        if ok and (B * c * vx + A * s * vy) < 0.0:
            ok = False
    if not ok:
        c, s = _ellipse_bracketed(x, y, vx, vy, A, B, r)
    k = 1.5 - 0.5 * (c * c + s * s)
    c *= k
    s *= k
    ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
    rih = r * ih
    cx = (A - B * rih) * c
    cy = (B - A * rih) * s
    t = ((cx - x) * vx + (cy - y) * vy) / vv
    if t < 0.0:
        t = 0.0
    return t, c, s, ih


@njit(cache=True, error_model="numpy")
def ellipse_hit(x, y, vx, vy, A, B, r):
    """``(t, cos u, sin u)``: time until the centre reaches the ellipse's parallel curve and
    the curve parameter ``u`` of the contact (`_ellipse_hit`)."""
    t, c, s, _ = _ellipse_hit(x, y, vx, vy, A, B, r)
    return t, c, s


@njit(cache=True, error_model="numpy")
def ellipse_normal(c, s, A, B, r):
    """``(nx, ny, kappa)`` at the parameter ``(cos u, sin u) = (c, s)``: the outward unit
    normal ``N = (B c, A s) / h`` and the curvature of the centre's curve,
    ``kappa / (1 - r kappa)`` with the ellipse's ``kappa = A B / h^3``."""
    ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
    k = A * B * ih * ih * ih
    return B * c * ih, A * s * ih, k / (1.0 - r * k)


@njit(cache=True, error_model="numpy")
def ellipse_parameter(x, y, A, B, r):
    """``(cos u, sin u)`` of the point of the centre's curve nearest to ``(x, y)`` (for a
    point on the curve: its parameter). Newton on ``(q - C(u)).C'(u) = 0`` from the
    parameter of ``(x / (A - r), y / (B - r))``; the centre's curve is convex, so the foot
    point is unique near the curve."""
    c = x / (A - r)
    s = y / (B - r)
    nrm = math.sqrt(c * c + s * s)
    if nrm == 0.0:
        return 1.0, 0.0
    c /= nrm
    s /= nrm
    for _ in range(50):
        h = math.sqrt(B * B * c * c + A * A * s * s)
        cx = (A - r * B / h) * c
        cy = (B - r * A / h) * s
        f = 1.0 - r * A * B / (h * h * h)
        tx = -A * s * f
        ty = B * c * f
        # F = (q - C).C', F' ~ -|C'|^2 (the curvature term vanishes on the curve)
        d = ((x - cx) * tx + (y - cy) * ty) / (tx * tx + ty * ty)
        c, s = _rotate(c, s, d)
        k = 1.5 - 0.5 * (c * c + s * s)
        c *= k
        s *= k
        if abs(d) < 1e-15:
            break
    return c, s


@njit(cache=True, error_model="numpy")
def _carlson_rf(x, y, z):
    """Carlson's ``R_F(x, y, z)`` by duplication (relative error below 1e-16)."""
    for _ in range(100):
        sx = math.sqrt(x)
        sy = math.sqrt(y)
        sz = math.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        mu = (x + y + z) / 3.0
        dx = (mu - x) / mu
        dy = (mu - y) / mu
        dz = (mu - z) / mu
        if max(abs(dx), abs(dy), abs(dz)) < 0.0008:
            break
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 + (e2 / 24.0 - 0.1 - 3.0 * e3 / 44.0) * e2 + e3 / 14.0) / math.sqrt(mu)


@njit(cache=True, error_model="numpy")
def _carlson_rd(x, y, z):
    """Carlson's ``R_D(x, y, z)`` by duplication (relative error below 1e-16)."""
    total = 0.0
    fac = 1.0
    for _ in range(100):
        sx = math.sqrt(x)
        sy = math.sqrt(y)
        sz = math.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        total += fac / (sz * (z + lam))
        fac *= 0.25
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        ave = 0.2 * (x + y + 3.0 * z)
        dx = (ave - x) / ave
        dy = (ave - y) / ave
        dz = (ave - z) / ave
        if max(abs(dx), abs(dy), abs(dz)) < 0.0005:
            break
    c1 = 3.0 / 14.0
    c2 = 1.0 / 6.0
    c3 = 9.0 / 22.0
    c4 = 3.0 / 26.0
    c5 = 0.25 * c3
    c6 = 1.5 * c4
    ea = dx * dy
    eb = dz * dz
    ec = ea - eb
    ed = ea - 6.0 * eb
    ee = ed + ec + ec
    return 3.0 * total + fac * (1.0 + ed * (-c1 + c5 * ed - c6 * dz * ee)
                                + dz * (c2 * ee + dz * (-c3 * ec + dz * c4 * ea))) / (
        ave * math.sqrt(ave))


@njit(cache=True, error_model="numpy")
def _elliptic_e(phi, m):
    """Legendre's incomplete ``E(phi | m)`` for ``|phi| <= pi / 2``."""
    sp = math.sin(phi)
    cp = math.cos(phi)
    q = 1.0 - m * sp * sp
    return sp * _carlson_rf(cp * cp, q, 1.0) - m / 3.0 * sp * sp * sp * _carlson_rd(
        cp * cp, q, 1.0)


@njit(cache=True, error_model="numpy")
def ellipse_arc_length(c, s, A, B, r):
    """Arc length along the centre's curve from ``u = 0`` (the point ``(A - r, 0)``)
    counter-clockwise to the parameter ``(cos u, sin u) = (c, s)``.

    ``s(u) = int_0^u |C'| = S(u) - r phi(u)``: ``S(u) = A [E(u - pi/2 | m) + E(m)]`` the
    ellipse's arc length (``m = 1 - B^2 / A^2``, Carlson's symmetric integrals) and
    ``phi(u)`` the angle the normal has turned (``|C'| = (1 - r kappa) |P'|`` and
    ``kappa |P'| = phi'``).
    """
    m = 1.0 - (B / A) * (B / A)
    u = math.atan2(s, c)
    if u < 0.0:
        u += _TWO_PI
    phi = math.atan2(A * s, B * c)
    if phi < 0.0:
        phi += _TWO_PI
    half = 0.0
    if u >= math.pi:
        u -= math.pi
        half = 2.0 * A * _elliptic_e(0.5 * math.pi, m)
    ecomp = _elliptic_e(0.5 * math.pi, m)
    return half + A * (_elliptic_e(u - 0.5 * math.pi, m) + ecomp) - r * phi


# --- every table ---------------------------------------------------------------------------

@njit(cache=True, error_model="numpy")
def hit(kind, p0, p1, p2, x, y, vx, vy):
    """``(t, w1, w2)``: time to the next wall contact and where: nothing for the circle,
    ``(piece, 0)`` for the stadium, the outward unit normal for the ellipse."""
    if kind == CIRCLE:
        return geo.boundary_hit_time(x, y, vx, vy, p0), 0.0, 0.0
    if kind == STADIUM:
        t, piece = stadium_hit(x, y, vx, vy, p0, p1)
        return t, float(piece), 0.0
    t, c, s, ih = _ellipse_hit(x, y, vx, vy, p0, p1, p2)
    # the outward normal (B c, A s) / h: the contact needs it at once, so it is made here,
    # where 1 / h is known (`contact` recovers the curvature from it off the critical path)
    return t, p1 * c * ih, p0 * s * ih


@njit(cache=True, error_model="numpy")
def wall_time(kind, p0, p1, p2, x, y, vx, vy):
    """Time until the centre at ``(x, y)`` with velocity ``(vx, vy)`` reaches the wall."""
    return hit(kind, p0, p1, p2, x, y, vx, vy)[0]


@njit(cache=True, error_model="numpy")
def contact(kind, p0, p1, p2, x, y, vx, vy, w1, w2):
    """``(x, y, nx, ny, kappa)`` at a contact found by `hit` (the centre advanced by its
    time): the centre put back on the wall, the outward unit normal, the curvature of the
    centre's curve (positive: the wall curves towards the inside)."""
    if kind == CIRCLE:
        return circle_contact(x, y, vx, vy, p0)
    if kind == STADIUM:
        return stadium_contact(x, y, vx, vy, p0, p1, int(w1))
    # w = the normal N = (B c, A s) / h, so 1 / h = sqrt((N_x / B)^2 + (N_y / A)^2)
    ex = w1 * (1.0 / p1)  # (1 / B, 1 / A: loop invariants, hoisted out of a driver's loop)
    ey = w2 * (1.0 / p0)
    ih = math.sqrt(ex * ex + ey * ey)
    k = p0 * p1 * ih * ih * ih
    return x, y, w1, w2, k / (1.0 - p2 * k)


@njit(cache=True, error_model="numpy")
def bounce(vx, vy, nx, ny):
    """Outgoing velocity at a contact with outward normal ``n``: the specular reflection,
    or, when the flight makes an angle below ``GRAZE_ANGLE / 2`` with the wall (or moves
    along or into it), the grazing rule of `kicktimes.billiard.geometry.graze` with the
    local normal: ``v' = |v| (-sin(delta) n + s cos(delta) t)``, ``t = (-ny, nx)``,
    ``s = sign(v.t)``. Without it a flight tangent to a curved wall (or along a segment
    into the stadium's join) would meet the wall again at once, forever."""
    vn = vx * nx + vy * ny
    vv = vx * vx + vy * vy
    if vn > 0.0 and vn * vn >= geo.GRAZE_THRESHOLD * geo.GRAZE_THRESHOLD * vv:
        return vx - 2.0 * vn * nx, vy - 2.0 * vn * ny
    sp = math.sqrt(vv)
    sg = 1.0 if -vx * ny + vy * nx >= 0.0 else -1.0
    return (sp * (-geo.SIN_GRAZE * nx - sg * geo.COS_GRAZE * ny),
            sp * (-geo.SIN_GRAZE * ny + sg * geo.COS_GRAZE * nx))


@njit(cache=True, error_model="numpy")
def boundary_coordinates(kind, p0, p1, p2, x, y, vx, vy):
    """``(s, sin_theta)`` of a centre on the wall moving with ``(vx, vy)``: the arc length
    along the centre's curve, counter-clockwise from its rightmost point (``[0, L)``), and
    ``sin_theta = v.t / |v|`` with ``t`` the counter-clockwise unit tangent (the same for
    the incoming and the outgoing velocity: ``(s, sin_theta)`` are Birkhoff's coordinates).
    In the circle ``sin_theta`` is `kicktimes.billiard.geometry.sin_theta_at`."""
    sp = math.sqrt(vx * vx + vy * vy)
    if kind == CIRCLE:
        rho = p0
        u = math.atan2(y, x)
        if u < 0.0:
            u += _TWO_PI
        return rho * u, (x * vy - y * vx) / (rho * sp)
    if kind == STADIUM:
        a = p0
        rho = p1
        half = 0.5 * math.pi * rho
        if x > a:
            u = math.atan2(y, x - a)
            s = rho * u if u >= 0.0 else 3.0 * half + 4.0 * a + rho * (u + 0.5 * math.pi)
            nx = (x - a) / rho
            ny = y / rho
        elif x < -a:
            u = math.atan2(y, x + a)
            if u < 0.0:
                u += _TWO_PI
            s = half + 2.0 * a + rho * (u - 0.5 * math.pi)
            nx = (x + a) / rho
            ny = y / rho
        elif y > 0.0:
            s = half + (a - x)
            nx = 0.0
            ny = 1.0
        else:
            s = 3.0 * half + 2.0 * a + (x + a)
            nx = 0.0
            ny = -1.0
        return s, (-vx * ny + vy * nx) / sp
    c, s = ellipse_parameter(x, y, p0, p1, p2)
    nx, ny, _ = ellipse_normal(c, s, p0, p1, p2)
    return ellipse_arc_length(c, s, p0, p1, p2), (-vx * ny + vy * nx) / sp
