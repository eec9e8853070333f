"""Scattering kicks: a kick that *is* a disk-disk collision with a virtual partner.

At a kick the disk (centre ``x``, velocity ``v``, radius ``r0``) collides with a partner
disk of radius ``r1`` (default ``r0``) drawn from the two-disk system's own collision
statistics (docs/scatter.md, docs/unequal.md):

* the partner's velocity ``u`` is at angle ``D`` from ``v``. Its speed is ``|v|`` under the
  mirror rule and ``sqrt((2 e0 - m0 |v|^2) / m1)`` under the elastic rule (the pair then
  has the two-disk system's kinetic energy ``e0``; masses normalised to
  ``(m0 + m1) / 2 = 1``, so equal masses are ``m0 = m1 = 1``). The ``"weighted"`` partner
  law gives ``D`` the density ``p(D) ~ |v - u(D)|`` on ``(-pi, pi)``, the flux weight of
  the collision kernel; ``"uniform"`` draws ``D`` uniformly (the issue's literal wording);
* the contact normal ``n`` (from the disk's centre towards the partner's) makes the angle
  ``phi = arcsin(b)`` with ``w = v - u``, ``b`` uniform on ``(-1, 1)``, i.e. density
  ``cos(phi) / 2`` on ``(-pi/2, pi/2)``: the kernel ``(w.n)^+`` of kinetic theory (it does
  not depend on the radii: they only set the contact distance);
* the collision follows the rule (``"mirror"``: ``v' = v - 2 (v.n) n``; ``"elastic"``:
  ``v' = v - k0 (w.n) n`` with ``k0 = 2 m1 / (m0 + m1) = m1``, and the partner would leave
  with ``u' = u + m0 (w.n) n``: momentum ``m0 v + m1 u`` and energy kept). The partner
  sits at ``x + sigma n``, ``sigma = r0 + r1``, with velocity ``u``, which is all a
  Lyapunov twin needs to meet the same partner.

Each kick consumes two numbers ``(a, b)`` uniform on ``(-1, 1)``, drawn outside the kernels
(`draw_scatter_uniforms`), so that reference, twins and tangent vectors see the same
partner and runs are reproducible.

All kernels take and return plain floats (numba inlines them into the event loops). With
the defaults (``r1 = r0``, ``m0 = m1 = 1``) every factor is exactly 1.0 or the old
operand, so the arithmetic is bitwise that of the equal-disk kicks.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Columns of a scattering-kick log (`scatter_kick`'s ``out``; the runs' `kick_log`)
KICK_LOG_COLUMNS = ("vx", "vy", "vx_post", "vy_post", "nx", "ny", "ux", "uy", "outside")

__all__ = ["KICK_LOG_COLUMNS", "PARTNER_LAWS", "collide_with_partner", "draw_partner",
           "draw_scatter_uniforms", "partner_angle", "scatter_kick", "scatter_tangent",
           "twin_meets_partner"]

PARTNER_LAWS = {"weighted": 0, "uniform": 1}

# 20-point Gauss-Legendre rule on [-1, 1], used twice (two panels) for the elastic
# partner law, whose CDF has no elementary closed form (an incomplete elliptic integral).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(20)


def draw_scatter_uniforms(n: int, rng: np.random.Generator) -> np.ndarray:
    """The random numbers of ``n`` scattering kicks, shape ``(n, 2)``, uniform on (-1, 1).

    Column 0 fixes the partner's direction, column 1 the contact normal.
    """
    return rng.uniform(-1.0, 1.0, size=(n, 2))


@njit(cache=True)
def _flux_cdf(d, c, e):
    """``int_0^d sqrt(c + e sin^2(x/2)) dx`` by two Gauss-Legendre panels."""
    total = 0.0
    h = 0.25 * d
    for p in range(2):
        mid = (2 * p + 1) * h
        for i in range(_GL_X.shape[0]):
            s = math.sin(0.5 * (mid + h * _GL_X[i]))
            total += _GL_W[i] * math.sqrt(c + e * s * s)
    return total * h


@njit(cache=True)
def partner_angle(a, sv, su, law):
    """Angle ``D`` from ``v`` to the partner's velocity ``u``, from ``a`` uniform on (-1, 1).

    ``law`` 0 (weighted): density ``~ |v - u| = sqrt((sv - su)^2 + 4 sv su sin^2(D/2))``.
    For equal speeds this is ``~ |sin(D/2)|`` with the inverse CDF
    ``|D| = 2 arccos(1 - |a|)``; otherwise the CDF is inverted by safeguarded Newton steps.
    ``law`` 1 (uniform): ``D = pi a``. The sign of ``D`` is the sign of ``a``.
    """
    if law == 1:
        return math.pi * a
    q = abs(a)
    sign = 1.0 if a >= 0.0 else -1.0
    c = (sv - su) * (sv - su)
    e = 4.0 * sv * su
    if c <= 1e-14 * e:
        return sign * 2.0 * math.acos(1.0 - q)
    if e == 0.0:
        return math.pi * a  # one of the disks at rest: |v - u| does not depend on D
    target = q * _flux_cdf(math.pi, c, e)
    lo = 0.0
    hi = math.pi
    d = q * math.pi
    for _ in range(60):
        f = _flux_cdf(d, c, e) - target
        if f > 0.0:
            hi = d
        else:
            lo = d
        s = math.sin(0.5 * d)
        step = f / math.sqrt(c + e * s * s)
        d_new = d - step
        if not (lo < d_new < hi):
            d_new = 0.5 * (lo + hi)  # Newton left the bracket: bisect
        if abs(d_new - d) <= 1e-13:
            d = d_new
            break
        d = d_new
    return sign * d


@njit(cache=True)
def collide_with_partner(vx, vy, ux, uy, nx, ny, rule, k0):
    """The disk's velocity after meeting a partner with velocity ``u`` along normal ``n``.

    ``rule`` 0 (mirror): ``v' = v - 2 (v.n) n``; 1 (elastic):
    ``v' = v - k0 ((v - u).n) n`` with ``k0 = 2 m1 / (m0 + m1)`` (1 for equal masses).
    """
    if rule == 0:
        p = 2.0 * (vx * nx + vy * ny)
    else:
        p = k0 * ((vx - ux) * nx + (vy - uy) * ny)
    return vx - p * nx, vy - p * ny


@njit(cache=True)
def draw_partner(vx, vy, a, b, rule, e0, law, m0, m1):
    """Partner velocity ``u`` and contact normal ``n`` of one kick, from ``(a, b)``.

    Elastic rule: the partner's speed is ``sqrt((2 e0 - m0 |v|^2) / m1)`` (masses
    normalised to ``(m0 + m1) / 2 = 1``; ``m0 = m1 = 1`` for equal masses). Returns
    ``(ux, uy, nx, ny)``; ``n`` is ``(0, 0)`` if ``w = v - u`` vanishes (no collision:
    ``u = v`` exactly, an event of probability zero).
    """
    sv = math.sqrt(vx * vx + vy * vy)
    if rule == 0:
        su = sv
    else:
        su = math.sqrt(max((2.0 * e0 - m0 * sv * sv) / m1, 0.0))
    d = partner_angle(a, sv, su, law)
    if sv > 0.0:
        cx = vx / sv
        cy = vy / sv
    else:
        cx = 1.0
        cy = 0.0
    cd = math.cos(d)
    sd = math.sin(d)
    ux = su * (cd * cx - sd * cy)
    uy = su * (sd * cx + cd * cy)
    wx = vx - ux
    wy = vy - uy
    ww = math.sqrt(wx * wx + wy * wy)
    if ww == 0.0:
        return ux, uy, 0.0, 0.0
    wx /= ww
    wy /= ww
    # phi = arcsin(b) has density cos(phi)/2: the collision kernel (w.n)^+ over n
    sp = b
    cp = math.sqrt(max(1.0 - b * b, 0.0))
    nx = cp * wx - sp * wy
    ny = sp * wx + cp * wy
    return ux, uy, nx, ny


@njit(cache=True)
def twin_meets_partner(x, y, vx, vy, px, py, ux, uy, sigma, rule, k0):
    """A twin at ``(x, v)`` meets the partner at ``p`` (velocity ``u``) at the kick time.

    The kick is a map of the state at the kick time: the twin's straight relative line
    ``d(s) = (x - p) + (v - u) s`` enters the contact circle ``|d| = sigma`` at
    ``s1 = (-(d.w) - sqrt((d.w)^2 - |w|^2 (|d|^2 - sigma^2))) / |w|^2`` (of either
    sign: a twin displaced towards the partner touches it slightly earlier); the twin
    collides there with ``n = -d(s1) / sigma`` and is carried back to the kick time,
    ``x' = x + (v - v') s1``. For the reference ``s1 = 0``. Returns
    ``(x', y', vx', vy', hit)``; ``hit`` is False (state unchanged) if the line misses.
    ``sigma = r0 + r1`` is the contact distance, ``k0`` the elastic mass factor
    (`collide_with_partner`).
    """
    dx = x - px
    dy = y - py
    wx = vx - ux
    wy = vy - uy
    ww = wx * wx + wy * wy
    bb = dx * wx + dy * wy
    disc = bb * bb - ww * (dx * dx + dy * dy - sigma * sigma)
    if ww == 0.0 or disc < 0.0:
        return x, y, vx, vy, False
    s1 = (-bb - math.sqrt(disc)) / ww
    nx = -(dx + wx * s1) / sigma
    ny = -(dy + wy * s1) / sigma
    nn = math.sqrt(nx * nx + ny * ny)
    nx /= nn
    ny /= nn
    if wx * nx + wy * ny <= 0.0:
        return x, y, vx, vy, False  # tangent line from outside: a graze, not a collision
    vx2, vy2 = collide_with_partner(vx, vy, ux, uy, nx, ny, rule, k0)
    return x + (vx - vx2) * s1, y + (vy - vy2) * s1, vx2, vy2, True


@njit(cache=True)
def scatter_tangent(vx, vy, ux, uy, nx, ny, sigma, rule, k0, dx, dy, dvx, dvy):
    """Linearised scattering kick: the tangent vector ``(dx, dv)`` through the collision.

    The partner's deviation is zero. With ``w = v - u`` and ``n`` the reference normal,
    the contact time shifts by ``dt = -(n.dx) / (n.w)``, the normal by
    ``dn = -(dx + w dt) / sigma``, and

    * ``dx' = dx + (v - v') dt``
    * mirror: ``dv' = dv - 2 (n.dv) n - 2 [(v.dn) n + (v.n) dn]``
    * elastic: ``dv' = dv - k0 (n.dv) n - k0 [(w.dn) n + (w.n) dn]``, ``k0 = 2 m1 / (m0 + m1)``

    (the Dellago-Posch-Hoover collision map for a partner without deviation; ``sigma =
    r0 + r1`` the contact distance). Returns
    ``(dx', dy', dvx', dvy')``.
    """
    wx = vx - ux
    wy = vy - uy
    wn = wx * nx + wy * ny
    dt = -(dx * nx + dy * ny) / wn
    dnx = -(dx + wx * dt) / sigma
    dny = -(dy + wy * dt) / sigma
    vx2, vy2 = collide_with_partner(vx, vy, ux, uy, nx, ny, rule, k0)
    if rule == 0:
        g = 2.0
        an = vx * nx + vy * ny
        adn = vx * dnx + vy * dny
    else:
        g = k0
        an = wn
        adn = wx * dnx + wy * dny
    ndv = nx * dvx + ny * dvy
    dvx2 = dvx - g * ndv * nx - g * (adn * nx + an * dnx)
    dvy2 = dvy - g * ndv * ny - g * (adn * ny + an * dny)
    return dx + (vx - vx2) * dt, dy + (vy - vy2) * dt, dvx2, dvy2


@njit(cache=True)
def scatter_kick(st, a, b, sigma, rho1, rule, e0, law, m0, m1, out):
    """Apply a scattering kick to the one-disk state ``st = [t, x, y, vx, vy, c, v2]``.

    ``sigma = r0 + r1`` is the contact distance, ``rho1 = 1 - r1`` the partner's room,
    ``m0, m1`` the normalised masses (`draw_partner`; the elastic factor is ``k0 = m1``).
    Fills ``out`` (length 9, the `KICK_LOG_COLUMNS`): pre- and post-kick velocity,
    normal, partner velocity, and 1.0 if the partner's centre ``x + sigma n`` lies outside
    its room (``|x + sigma n| > rho1``: a virtual partner, allowed; docs/scatter.md).
    """
    vx = st[3]
    vy = st[4]
    ux, uy, nx, ny = draw_partner(vx, vy, a, b, rule, e0, law, m0, m1)
    out[0] = vx
    out[1] = vy
    out[4] = nx
    out[5] = ny
    out[6] = ux
    out[7] = uy
    px = st[1] + sigma * nx
    py = st[2] + sigma * ny
    out[8] = 1.0 if px * px + py * py > rho1 * rho1 else 0.0
    if nx != 0.0 or ny != 0.0:
        # normalised masses: k0 = 2 m1 / (m0 + m1) = m1
        vx, vy = collide_with_partner(vx, vy, ux, uy, nx, ny, rule, m1)
    st[3] = vx
    st[4] = vy
    st[6] = vx * vx + vy * vy
    out[2] = vx
    out[3] = vy
