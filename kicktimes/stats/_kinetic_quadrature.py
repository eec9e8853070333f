r"""Quadrature kernels of the conditioned kinetic rate (:mod:`kicktimes.stats.kinetic`).

Plain floats and arrays in and out; ``kap`` is the *unit-speed* angular momentum
``L / |v|`` of a disk (its caustic radius with sign), ``c`` its speed, ``rho = 1 - r`` the
radius the centres live in, ``sig = 2 r`` the contact distance. ``x, w`` are
Gauss-Legendre nodes and weights on ``[-1, 1]``. The derivation and every substitution
are in ``docs/kinetic.md``.

Disk 1 sits at ``x1 = (R1, 0)``, the partner at ``x2 = x1 + sig (cos phi, sin phi)``;
``u = cos phi`` is the inner variable, both signs of ``sin phi`` are summed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["conditional_rates", "invariant_partner_rates"]


@njit(cache=True)
def _pieces(a1, rho, cuts):
    """``z = sqrt(R1 - a1)`` at the ends of ``[a1, rho]`` and at the ``cuts`` inside it, in
    order."""
    edges = np.empty(cuts.size + 2)
    edges[0] = 0.0
    m = 1
    for c in cuts:
        if a1 < c < rho:
            edges[m] = math.sqrt(c - a1)
            m += 1
    edges[m] = math.sqrt(rho - a1)
    return np.sort(edges[: m + 1])


@njit(cache=True)
def _radial_node(lo, hi, a1, xj, wj):
    """Node ``R1``, ``z^2 = R1 - a1`` and the weight of ``2 pi R1 p1(R1) dR1`` up to
    ``1 / sqrt(rho^2 - kap1^2)``, on the piece ``lo <= z <= hi`` of ``z = sqrt(R1 - a1)``.

    ``R1 = a1 + z^2`` removes the caustic's inverse square root, ``R1 dR1 / sqrt(R1^2 -
    a1^2) = 2 R1 dz / sqrt(R1 + a1)``, also when a breakpoint lies just beyond the caustic;
    the cosine map ``z = lo + (hi - lo) sin^2(theta / 2)`` absorbs the square-root (and
    logarithmic) behaviour of the inner integral at the breakpoints."""
    theta = 0.5 * math.pi * (xj + 1.0)
    z = lo + (hi - lo) * math.sin(0.5 * theta) ** 2
    big = a1 + z * z
    weight = 0.25 * math.pi * (hi - lo) * math.sin(theta) * wj
    return big, z * z, weight * 2.0 * big / math.sqrt(big + a1)


@njit(cache=True)
def _pair_flux(one_m, one_p, u_mc, big1, dm, b1, t1, kap2, sig, c1, c2):
    """Sum of ``(c1 u1.n - c2 u2.n)^+`` over the 4 pairs of radial signs and both signs
    of ``sin phi``, divided by 4 (the sign average), at ``u = cos phi``.

    Only differences that are known exactly come in: ``one_m = 1 - u``, ``one_p = 1 + u``,
    ``u_mc = u - cL`` (``2 sig R1 u_mc = R2^2 - kap2^2``) and ``dm = R1 - sig``; ``b1, t1`` are
    the radial and tangential components of disk 1's unit velocity at ``R1``."""
    u = 0.5 * (one_p - one_m)
    sin_phi = math.sqrt(one_m * one_p)
    gap2 = 2.0 * sig * big1 * u_mc
    r2sq = kap2 * kap2 + gap2
    big2 = math.sqrt(r2sq)
    b2 = math.sqrt(gap2) / big2
    # e_R2.n = (R1 u + sig) / R2 with R1 u + sig = R1 (1 + u) - (R1 - sig): no cancellation
    # when the partner passes near the table's centre
    cos2 = min(max((big1 * one_p - dm) / big2, -1.0), 1.0)
    rad2 = b2 * cos2  # radial part of u2.n, times s2
    tan2 = kap2 * big1 * sin_phi / r2sq  # tangential part of u2.n at sin(phi) > 0
    total = 0.0
    for mirror in (1.0, -1.0):
        a = c1 * t1 * mirror * sin_phi - c2 * tan2 * mirror
        for s1 in (1.0, -1.0):
            for s2 in (1.0, -1.0):
                f = a + s1 * c1 * b1 * u - s2 * c2 * rad2
                if f > 0.0:
                    total += f
    return 0.25 * total


@njit(cache=True)
def _inner(big1, dm, dp, b1, t1, kap2, c1, c2, rho, sig, x, w):
    r"""``\int d phi p2(R2) flux`` over the circle of contact, up to the factor
    ``sig / (2 pi sqrt(rho^2 - kap2^2) sqrt(2 sig R1))`` (applied by the caller);
    ``dm = R1 - sig``, ``dp = R1 + sig``.

    In ``u = cos phi`` the weight is ``du / sqrt((1 - u)(1 + u)(u - cL))``; the arc where the
    partner's centre lies on its annulus ``|kap2| <= R2 <= rho`` is ``cL <= u <= cR``. Each
    end of ``[max(cL, -1), min(cR, 1)]`` has an inverse square root on it or just outside:
    ``u = cL`` and ``u = -1`` (a distance ``dl = |cL + 1|`` apart) on the left, ``u = 1``
    (``dr = 1 - min(cR, 1)`` beyond the end) on the right. Each half is mapped by
    ``u - lo = dl sinh^2 t`` (``hi - u = dr sinh^2 t``), which makes both roots smooth
    whatever their distance, so the caustic and the rim of the partner's annulus cost no
    accuracy (``hi - u = s^2`` when ``dr = 0``, the contact circle inside the table).
    ``1 +- cL`` and ``1 +- cR`` are formed as products of differences of the radii, so they
    keep their digits where the contact circle touches the caustic or the rim."""
    two_sr = 2.0 * sig * big1
    a2 = abs(kap2)
    adm = abs(dm)
    cl_p = (a2 - adm) * (a2 + adm) / two_sr  # 1 + cL
    cl_m = (dp - a2) * (dp + a2) / two_sr  # 1 - cL
    cr_p = (rho - adm) * (rho + adm) / two_sr  # 1 + cR
    cr_m = (dp - rho) * (dp + rho) / two_sr  # 1 - cR
    if cl_m <= 0.0 or cr_p <= 0.0:
        return 0.0  # the contact circle misses the annulus
    spread = (rho - a2) * (rho + a2) / two_sr  # cR - cL
    width = min(min(spread, cr_p), min(cl_m, 2.0))  # min(cR, 1) - max(cL, -1)
    half = 0.5 * width
    lo_m = min(cl_m, 2.0)  # 1 - lo
    hi_p = min(cr_p, 2.0)  # 1 + hi
    hi_mc = min(spread, cl_m)  # hi - cL
    d_l = max(abs(cl_p), 1e-300)
    d_r = max(cr_m, 0.0)
    total = 0.0
    # left half: du / sqrt((1 + u)(u - cL)) = 2 dt
    t_max = math.asinh(math.sqrt(half / d_l))
    for j in range(x.size):
        t = 0.5 * t_max * (x[j] + 1.0)
        sh2 = d_l * math.sinh(t) ** 2
        ch2 = d_l * math.cosh(t) ** 2
        if cl_p > 0.0:
            u_mc, one_p = sh2, ch2
        else:
            one_p, u_mc = sh2, ch2
        one_m = lo_m - sh2
        f = _pair_flux(one_m, one_p, u_mc, big1, dm, b1, t1, kap2, sig, c1, c2)
        total += w[j] * t_max * f / math.sqrt(one_m)
    # right half: du / sqrt(1 - u) = 2 sqrt(dr) sinh t dt  (= 2 ds when dr = 0)
    if d_r > 0.0:
        s_max = math.asinh(math.sqrt(half / d_r))
    else:
        s_max = math.sqrt(half)
    for j in range(x.size):
        s = 0.5 * s_max * (x[j] + 1.0)
        if d_r > 0.0:
            gap = d_r * math.sinh(s) ** 2
            one_m = d_r * math.cosh(s) ** 2
            jac = 2.0 * math.sqrt(d_r) * math.sinh(s)
        else:
            gap = s * s
            one_m = gap
            jac = 2.0
        one_p = hi_p - gap
        u_mc = hi_mc - gap
        f = _pair_flux(one_m, one_p, u_mc, big1, dm, b1, t1, kap2, sig, c1, c2)
        total += w[j] * 0.5 * s_max * jac * f / math.sqrt(one_p * u_mc)
    return total


@njit(cache=True)
def conditional_rate(r, kap1, kap2, c1, c2, x, w):
    """Collision rate of two free orbits with unit-speed angular momenta ``kap1, kap2``
    and speeds ``c1, c2``, uniform independent phases (one pair of values)."""
    rho = 1.0 - r
    sig = 2.0 * r
    a1 = abs(kap1)
    a2 = abs(kap2)
    cuts = np.array([a2 - sig, a2 + sig, sig - a2, rho - sig, sig - rho])
    edges = _pieces(a1, rho, cuts)
    norm = sig / (2.0 * math.pi * math.sqrt((rho - a2) * (rho + a2)))
    norm /= math.sqrt((rho - a1) * (rho + a1))
    total = 0.0
    for k in range(edges.size - 1):
        lo, hi = edges[k], edges[k + 1]
        if hi <= lo:
            continue
        for j in range(x.size):
            big1, z2, weight = _radial_node(lo, hi, a1, x[j], w[j])
            b1 = math.sqrt(z2 * (2.0 * a1 + z2)) / big1
            t1 = kap1 / big1
            # R1 -+ sig from z^2 = R1 - a1, exact where a breakpoint meets the caustic
            dm = (a1 - sig) + z2
            dp = (a1 + sig) + z2
            inner = _inner(big1, dm, dp, b1, t1, kap2, c1, c2, rho, sig, x, w)
            total += weight * inner / math.sqrt(2.0 * sig * big1)
    return norm * total


@njit(cache=True)
def conditional_rates(r, kap1, kap2, c1, c2, x, w):
    """:func:`conditional_rate` over flat arrays of equal length."""
    out = np.empty(kap1.size)
    for i in range(kap1.size):
        out[i] = conditional_rate(r[i], kap1[i], kap2[i], c1[i], c2[i], x, w)
    return out


@njit(cache=True)
def _uniform_flux(v):
    """``E[(v - cos theta)^+]`` over a uniform angle ``theta``: the approach speed
    against a unit velocity of uniform direction (``h(1) = 1``, ``h(0) = 1 / pi``)."""
    if v >= 1.0:
        return v
    if v <= -1.0:
        return 0.0
    return ((math.pi - math.acos(v)) * v + math.sqrt((1.0 - v) * (1.0 + v))) / math.pi


@njit(cache=True)
def invariant_partner_rate(r, kap1, c1, c2, x, w):
    """Collision rate of a free orbit (``kap1``, speed ``c1``, uniform phase) with a
    partner drawn from the invariant law: centre uniform in ``|x| <= rho``, velocity of
    speed ``c2`` and uniform direction. Equal to the ``f``-average of
    :func:`conditional_rate` over the partner's angular momentum."""
    rho = 1.0 - r
    sig = 2.0 * r
    a1 = abs(kap1)
    edges = _pieces(a1, rho, np.array([rho - sig, sig - rho]))
    total = 0.0
    for k in range(edges.size - 1):
        lo, hi = edges[k], edges[k + 1]
        for j in range(x.size):
            big1, z2, weight = _radial_node(lo, hi, a1, x[j], w[j])
            b1 = math.sqrt(z2 * (2.0 * a1 + z2)) / big1
            t1 = kap1 / big1
            # the partner's centre inside the table: |phi| >= phi_a, where cos(phi_a) = cR;
            # the integrand is smooth in phi there
            dm = abs((a1 - sig) + z2)
            dp = (a1 + sig) + z2
            cr_p = (rho - dm) * (rho + dm) / (2.0 * sig * big1)  # 1 + cR
            if cr_p <= 0.0:
                continue
            cr_m = (dp - rho) * (dp + rho) / (2.0 * sig * big1)  # 1 - cR
            # pi - phi_a = 2 asin(sqrt((1 + cR) / 2)), accurate for a short arc
            half = math.asin(math.sqrt(min(0.5 * cr_p, 1.0))) if cr_m > 0.0 else 0.5 * math.pi
            inner = 0.0
            for m in range(x.size):
                phi = math.pi - half * (x[m] + 1.0)
                cos_phi = math.cos(phi)
                sin_phi = math.sin(phi)
                f = 0.0
                for mirror in (1.0, -1.0):
                    for s1 in (1.0, -1.0):
                        v = c1 * (s1 * b1 * cos_phi + t1 * mirror * sin_phi)
                        f += c2 * _uniform_flux(v / c2)
                inner += w[m] * half * 0.5 * f
            total += weight * inner
    norm = sig / (math.pi * rho * rho * math.sqrt((rho - a1) * (rho + a1)))
    return norm * total


@njit(cache=True)
def invariant_partner_rates(r, kap1, c1, c2, x, w):
    """:func:`invariant_partner_rate` over flat arrays of equal length."""
    out = np.empty(kap1.size)
    for i in range(kap1.size):
        out[i] = invariant_partner_rate(r[i], kap1[i], c1[i], c2[i], x, w)
    return out
