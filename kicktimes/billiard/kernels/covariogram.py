r"""The set covariogram of a table's centre region by quadrature (numba kernels).

The centre of a disk of radius ``r`` keeps to a convex, centrally symmetric region ``D``
(the inner parallel body of the table, `kicktimes.billiard.kernels.tables`'s ``(kind, p0,
p1, p2)``). Two such centres a distance ``d`` apart in the direction ``e = e(phi)`` both lie
in ``D`` on the set ``D ∩ (D + d e)``, of area

.. math::  K(d, \phi) = \int (\ell_\phi(u) - d)^+ \, du ,

``l_phi(u)`` the length of the chord of ``D`` along ``e`` at the offset ``u`` along
``e_perp = (-sin phi, cos phi)`` (the chord and its translate by ``d e`` overlap on
``(l - d)^+``). ``D`` is convex and symmetric, so ``l_phi`` is even and concave in ``u``:
the integrand is ``l - d`` on ``|u| <= u*``, ``l(u*) = d``. The offset is written
``u = H sin theta`` (``H`` the support of ``D`` along ``e_perp``), which makes the chord
length analytic up to the tangent line (``l ~ sqrt(H - u)`` there), and the integral is
Gauss-Legendre in ``theta`` on ``[0, theta*]``, split where the line passes through one of
the stadium's joins (where the curvature of the wall jumps). The isotropic covariogram is
the average over directions, by the tables' symmetries over ``[0, pi / 2]``:

.. math::  g(d) = \frac{2}{\pi} \int_0^{\pi/2} K(d, \phi)\, d\phi ,

Gauss-Legendre again, split (stadium) at the directions where a chord of length ``d`` ends
at a join. Every piece is then smooth and the rules converge geometrically: ~1e-13
relative with the default nodes (tests/test_tables_rate.py).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.kernels.tables import CIRCLE, STADIUM

__all__ = ["chord_length", "covariogram", "overlap_area", "support"]

_HALF_PI = 0.5 * math.pi


#: the ratio of the geometric grading of a piece towards its ends (`_graded_edges`)
_GRADE = 0.15


@njit(cache=True, error_model="numpy")
def _graded_edges(a, b, levels, out):
    """Edges of the sub-intervals of ``[a, b]``, graded geometrically (ratio `_GRADE`,
    ``levels`` steps) towards both ends, so that Gauss-Legendre keeps its geometric
    convergence when a singularity of the integrand's continuation lies just beyond an end
    (the stadium: a chord's arc whose circle the line leaves just past a join). Returns how
    many edges were written (``levels = 0``: ``a, b``)."""
    if levels == 0:
        out[0] = a
        out[1] = b
        return 2
    half = 0.5 * (b - a)
    m = 0
    out[m] = a
    m += 1
    for k in range(levels, 0, -1):
        out[m] = a + half * _GRADE ** k
        m += 1
    out[m] = a + half
    m += 1
    for k in range(1, levels + 1):
        out[m] = b - half * _GRADE ** k
        m += 1
    out[m] = b
    return m + 1


@njit(cache=True, error_model="numpy")
def support(kind, p0, p1, p2, nx, ny):
    """``max_{q in D} q.n`` for a unit vector ``n``: ``rho`` (circle), ``a |n_x| + rho``
    (stadium), ``sqrt(A^2 n_x^2 + B^2 n_y^2) - r`` (the ellipse's parallel body)."""
    if kind == CIRCLE:
        return p0
    if kind == STADIUM:
        return p0 * abs(nx) + p1
    return math.sqrt(p0 * p0 * nx * nx + p1 * p1 * ny * ny) - p2


@njit(cache=True, error_model="numpy")
def _ellipse_level(A, B, r, nx, ny, u, lo, hi):
    """The parameter ``t`` in ``[lo, hi]`` where ``C(t).n = u``, ``C(t).n - u`` changing sign
    once on the bracket (safeguarded Newton with bisection)."""
    c = math.cos(lo)
    s = math.sin(lo)
    ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
    f_lo = (A - r * B * ih) * c * nx + (B - r * A * ih) * s * ny - u
    t = 0.5 * (lo + hi)
    for _ in range(100):
        c = math.cos(t)
        s = math.sin(t)
        ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
        f = (A - r * B * ih) * c * nx + (B - r * A * ih) * s * ny - u
        fp = (1.0 - r * A * B * ih * ih * ih) * (-A * s * nx + B * c * ny)
        if (f > 0.0) == (f_lo > 0.0):
            lo = t
        else:
            hi = t
        if hi - lo <= 1e-15 * (1.0 + abs(t)):
            break
        tn = t - f / fp if fp != 0.0 else 0.5 * (lo + hi)
        if not (lo < tn < hi):
            tn = 0.5 * (lo + hi)
        if abs(tn - t) < 1e-16 * (1.0 + abs(t)):
            t = tn
            break
        t = tn
    return t


@njit(cache=True, error_model="numpy")
def chord_length(kind, p0, p1, p2, ex, ey, u):
    """Length of the chord of ``D`` along the unit vector ``e`` at the offset ``u`` along
    ``e_perp = (-e_y, e_x)``: the line ``{u e_perp + s e}`` (0 if it misses ``D``)."""
    px = -ey
    py = ex
    if kind == CIRCLE:
        q = p0 * p0 - u * u
        return 2.0 * math.sqrt(q) if q > 0.0 else 0.0
    if kind == STADIUM:
        a = p0
        rho = p1
        # D = the disks of radius rho about (+-a, 0) and the rectangle between them; the
        # chord of their union (convex) is the hull of the three chords
        lo = math.inf
        hi = -math.inf
        for cx in (-a, a):
            dl = u - cx * px
            q = rho * rho - dl * dl
            if q > 0.0:
                half = math.sqrt(q)
                mid = cx * ex
                lo = min(lo, mid - half)
                hi = max(hi, mid + half)
        # the rectangle |x| <= a, |y| <= rho: x = u px + s ex, y = u py + s ey
        s0 = -math.inf
        s1 = math.inf
        ok = True
        for base, slope, half in ((u * px, ex, a), (u * py, ey, rho)):
            if slope != 0.0:
                t0 = (-half - base) / slope
                t1 = (half - base) / slope
                s0 = max(s0, min(t0, t1))
                s1 = min(s1, max(t0, t1))
            elif abs(base) > half:
                ok = False
        if ok and s1 > s0:
            lo = min(lo, s0)
            hi = max(hi, s1)
        return hi - lo if hi > lo else 0.0
    A = p0
    B = p1
    r = p2
    if abs(u) >= support(kind, p0, p1, p2, px, py):
        return 0.0
    # C(t).e_perp is largest where the normal is e_perp and decreases over the next half turn
    tn = math.atan2(B * py, A * px)
    t1 = _ellipse_level(A, B, r, px, py, u, tn, tn + math.pi)
    t2 = _ellipse_level(A, B, r, px, py, u, tn - math.pi, tn)
    s1 = 0.0
    for k in range(2):
        t = t1 if k == 0 else t2
        c = math.cos(t)
        s = math.sin(t)
        ih = 1.0 / math.sqrt(B * B * c * c + A * A * s * s)
        along = (A - r * B * ih) * c * ex + (B - r * A * ih) * s * ey
        s1 = along if k == 0 else abs(along - s1)
    return s1


@njit(cache=True, error_model="numpy")
def overlap_area(kind, p0, p1, p2, phi, d, nodes, weights, levels):
    """``K(d, phi)``: area of ``D ∩ (D + d e(phi))`` (module docstring), Gauss-Legendre
    ``(nodes, weights)`` on ``[-1, 1]`` on each smooth piece of ``theta``, graded towards
    its ends by ``levels`` steps (`_graded_edges`)."""
    ex = math.cos(phi)
    ey = math.sin(phi)
    if d <= 0.0:
        d = 0.0
    if chord_length(kind, p0, p1, p2, ex, ey, 0.0) <= d:
        return 0.0
    H = support(kind, p0, p1, p2, -ey, ex)
    # theta* by bisection: l(H sin theta) decreases on [0, pi / 2]
    lo = 0.0
    hi = _HALF_PI
    if d > 0.0:
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if chord_length(kind, p0, p1, p2, ex, ey, H * math.sin(mid)) > d:
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-16:
                break
    top = 0.5 * (lo + hi) if d > 0.0 else _HALF_PI
    # the pieces: the lines through the stadium's joins (+-a, +-rho)
    cuts = np.empty(4)
    n_cut = 0
    cuts[n_cut] = 0.0
    n_cut += 1
    if kind == STADIUM:
        for sgn in (-1.0, 1.0):
            uj = abs(-sgn * p0 * ey + p1 * ex)
            if 0.0 < uj < H:
                tj = math.asin(min(uj / H, 1.0))
                if 0.0 < tj < top:
                    cuts[n_cut] = tj
                    n_cut += 1
    cuts[n_cut] = top
    n_cut += 1
    cuts[:n_cut].sort()
    edges = np.empty(2 * levels + 2)
    total = 0.0
    for k in range(n_cut - 1):
        if cuts[k + 1] <= cuts[k]:
            continue
        n_edge = _graded_edges(cuts[k], cuts[k + 1], levels, edges)
        for m in range(n_edge - 1):
            a = edges[m]
            half = 0.5 * (edges[m + 1] - a)
            for i in range(len(nodes)):
                th = a + half * (1.0 + nodes[i])
                ell = chord_length(kind, p0, p1, p2, ex, ey, H * math.sin(th))
                total += weights[i] * half * (ell - d) * H * math.cos(th)
    return 2.0 * total  # l is even in u


@njit(cache=True, error_model="numpy")
def _stadium_breaks(a, rho, d, out):
    """The directions in ``(0, pi / 2)`` where a chord of length ``d`` ends at a join of the
    stadium: the points ``J + d e(phi)`` on the wall for the join ``J = (a, rho)``, mapped by
    the stadium's symmetries (which permute its joins). Returns how many were written."""
    cand = np.empty(8)
    n = 0
    # the top segment (y = rho, |x| <= a): phi = pi, x = a - d
    if d <= 2.0 * a:
        cand[n] = math.pi
        n += 1
    # the bottom segment (y = -rho): sin phi = -2 rho / d, |a + d cos phi| <= a
    if d >= 2.0 * rho:
        sp = -2.0 * rho / d
        cp = math.sqrt(max(1.0 - sp * sp, 0.0))
        for c in (cp, -cp):
            if abs(a + d * c) <= a:
                cand[n] = math.atan2(sp, c)
                n += 1
    # the right arc about (a, 0), x >= a: sin phi = -d / (2 rho), cos phi >= 0
    if d <= 2.0 * rho:
        sp = -d / (2.0 * rho)
        cand[n] = math.atan2(sp, math.sqrt(max(1.0 - sp * sp, 0.0)))
        n += 1
    # the left arc about (-a, 0), x <= -a: 2 a cos phi + rho sin phi = -(4 a^2 + d^2) / (2 d)
    rr = math.sqrt(4.0 * a * a + rho * rho)
    cq = -(4.0 * a * a + d * d) / (2.0 * d * rr)
    if abs(cq) <= 1.0:
        psi = math.atan2(rho, 2.0 * a)
        dq = math.acos(cq)
        for ph in (psi + dq, psi - dq):
            if a + d * math.cos(ph) <= -a:
                cand[n] = ph
                n += 1
    m = 0
    for i in range(n):
        ph = cand[i] % math.pi
        if ph > _HALF_PI:
            ph = math.pi - ph
        if 1e-14 < ph < _HALF_PI - 1e-14:
            out[m] = ph
            m += 1
    return m


@njit(cache=True, error_model="numpy")
def covariogram(kind, p0, p1, p2, d, nodes, weights, levels_theta, levels_phi):
    """The isotropic covariogram ``g(d) = (2 / pi) int_0^{pi/2} K(d, phi) dphi`` (module
    docstring) for each distance of the array ``d``: Gauss-Legendre ``(nodes, weights)`` on
    each smooth piece of ``phi`` (graded towards its ends by ``levels_phi`` steps) and of
    ``theta`` (``levels_theta``). The pieces of ``phi`` end at the stadium's join
    directions (`_stadium_breaks`) and where the central chord is ``d`` long (beyond it
    ``K = 0``)."""
    out = np.empty(len(d))
    cuts = np.empty(12)
    edges = np.empty(2 * levels_phi + 2)
    for j in range(len(d)):
        dj = d[j]
        if kind == CIRCLE:
            # no direction is special: one direction is the average
            out[j] = overlap_area(kind, p0, p1, p2, 0.0, dj, nodes, weights, levels_theta)
            continue
        n_cut = 0
        cuts[n_cut] = 0.0
        n_cut += 1
        if kind == STADIUM:
            n_cut += _stadium_breaks(p0, p1, dj, cuts[1:])
        # the central chord shortens from phi = 0 to pi / 2: where it is d long, K ends
        top = _HALF_PI
        if chord_length(kind, p0, p1, p2, 0.0, 1.0, 0.0) < dj:
            lo = 0.0
            hi = _HALF_PI
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if chord_length(kind, p0, p1, p2, math.cos(mid), math.sin(mid), 0.0) > dj:
                    lo = mid
                else:
                    hi = mid
            top = 0.5 * (lo + hi)
        m = 1
        for k in range(1, n_cut):
            if cuts[k] < top:
                cuts[m] = cuts[k]
                m += 1
        n_cut = m
        cuts[n_cut] = top
        n_cut += 1
        cuts[:n_cut].sort()
        total = 0.0
        for k in range(n_cut - 1):
            if cuts[k + 1] <= cuts[k]:
                continue
            n_edge = _graded_edges(cuts[k], cuts[k + 1], levels_phi, edges)
            for e in range(n_edge - 1):
                a = edges[e]
                half = 0.5 * (edges[e + 1] - a)
                for i in range(len(nodes)):
                    total += weights[i] * half * overlap_area(
                        kind, p0, p1, p2, a + half * (1.0 + nodes[i]), dj, nodes, weights,
                        levels_theta)
        out[j] = total / _HALF_PI
    return out
