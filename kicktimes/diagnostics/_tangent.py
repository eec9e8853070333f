"""Exact tangent-space propagation for the billiards (numba kernels).

A tangent vector ``(dq, dv)`` is a first-order deviation of the phase-space state. It is
carried along the reference trajectory exactly: free flight ``dq += dv t``; at each event
the linearised event map (docs/lyapunov.md). The maps are written here once, as scalar
functions of the reference state at the event (contact position, incoming and outgoing
velocities), so that the event loops below, and later event kinds, reuse them:

* `wall_tangent`: specular reflection at the table's wall ``|q| = rho`` (curvature term);
* `pair_tangent`: disk-disk collision, rule 0 (mirror) or 1 (elastic); a partner whose
  state is fixed (a "scatter" kick off a virtual disk) is the case ``dq2 = dv2 = 0``;
* `kick_tangent`: a kick at a given time (mode 0: the direction is redrawn, independent
  of the state; mode 1: rotation by a shared angle).

Every map includes the variation of the collision time ``dtau = -(n.dq_rel)/(n.v_rel)``
(Dellago, Posch & Hoover, Phys. Rev. E 53, 1485 (1996)).

Layouts: two disks ``U[j] = [dx0, dy0, dvx0, dvy0, dx1, dy1, dvx1, dvy1]`` (as ``st[1:9]``),
one disk ``U[j] = [dx, dy, dvx, dvy]`` (as ``st[1:5]``). Kernels return a status code
instead of raising, so that the Python layer can name the offending input:
0 ok, 1 event budget exhausted, 2 more than ``MAX_SAME_INSTANT`` events at one instant,
3 a non-finite event time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.geometry import boundary_hit_time
from kicktimes.billiard.one_particle import SCATTER, kick_one, process_scatter_one, wall_one
from kicktimes.billiard.scatter import scatter_tangent
from kicktimes.billiard.two_particle import init_events_two, next_event_two, process_event_two

MAX_SAME_INSTANT = 1000
# Keep tangent norms inside [1/BIG, BIG]: far from overflow, and rescaling is rare (a
# log per rescaling instead of one per sample, which would cost as much as the simulation).
# The norm is checked after disk-disk collisions and kicks only: wall reflections in the
# circle only shear (polynomial growth), so they cannot overflow between two checks.
BIG = 1e100
BIG2 = BIG * BIG


@njit(cache=True, inline="always")
def wall_tangent(dqx, dqy, dvx, dvy, x, y, vx, vy, wx, wy, rho):
    """Tangent vector across a reflection at the wall ``|q| = rho``.

    ``(x, y)`` is the contact, ``(vx, vy)`` the incoming and ``(wx, wy)`` the outgoing
    velocity; ``n = q / rho``. With ``dtau = -(n.dq)/(n.v)`` and ``u = dq + v dtau``
    (``u.n = 0``):

    ``dq' = dq + (v - w) dtau``, ``dv' = R dv - (2/rho) [(v.u) n + (v.n) u]``,
    ``R = I - 2 n n^T``.

    At a contact exactly tangent to the wall (``v.n = 0``, a disk sliding on it: the
    `kicktimes.billiard.geometry.graze` event) the contact time's variation is infinite:
    the linearised dynamics is singular there, and the result is NaN (the Python layer
    reports an undefined exponent instead of dividing by zero).
    """
    nx = x / rho
    ny = y / rho
    vn = vx * nx + vy * ny
    if vn == 0.0:
        return math.nan, math.nan, math.nan, math.nan
    dtau = -(nx * dqx + ny * dqy) / vn
    ux = dqx + vx * dtau
    uy = dqy + vy * dtau
    k = 2.0 / rho
    vu = vx * ux + vy * uy
    dvn = 2.0 * (dvx * nx + dvy * ny)
    return (dqx + (vx - wx) * dtau, dqy + (vy - wy) * dtau,
            dvx - dvn * nx - k * (vu * nx + vn * ux), dvy - dvn * ny - k * (vu * ny + vn * uy))


@njit(cache=True)
def pair_tangent(a0, a1, a2, a3, b0, b1, b2, b3, x1, y1, x2, y2, v1x, v1y, v2x, v2y,
                 w1x, w1y, w2x, w2y, rule):
    """Tangent vector across a disk-disk collision (``a``: disk 1, ``b``: disk 2).

    ``a = (dx, dy, dvx, dvy)`` of disk 1, ``b`` of disk 2; ``(x_i, y_i)`` the centres at
    contact, ``v_i`` incoming and ``w_i`` outgoing velocities. ``n = (q1 - q2)/|q1 - q2|``,
    ``g = v1 - v2``, ``dtau = -n.(dq1 - dq2) / (n.g)``, ``u_i = dq_i + v_i dtau`` and
    ``m = (u1 - u2) / |q1 - q2|`` (the variation of ``n``; ``m.n = 0``). Then
    ``dq_i' = dq_i + (v_i - w_i) dtau`` and

    * mirror (``v_i' = v_i - 2 (v_i.n) n``):
      ``dv_i' = R dv_i - 2 [(v_i.m) n + (v_i.n) m]``;
    * elastic (``v_1' = v1 - (g.n) n``, ``v_2' = v2 + (g.n) n``):
      ``dv_1' = dv_1 - c n - (g.n) m``, ``dv_2' = dv_2 + c n + (g.n) m`` with
      ``c = (dv_1 - dv_2).n + g.m``.
    """
    ex = x1 - x2
    ey = y1 - y2
    dd = math.sqrt(ex * ex + ey * ey)
    nx = ex / dd
    ny = ey / dd
    gx = v1x - v2x
    gy = v1y - v2y
    gn = gx * nx + gy * ny
    dtau = -(nx * (a0 - b0) + ny * (a1 - b1)) / gn
    mx = (a0 - b0 + gx * dtau) / dd
    my = (a1 - b1 + gy * dtau) / dd
    qa0 = a0 + (v1x - w1x) * dtau
    qa1 = a1 + (v1y - w1y) * dtau
    qb0 = b0 + (v2x - w2x) * dtau
    qb1 = b1 + (v2y - w2y) * dtau
    if rule == 0:
        v1n = v1x * nx + v1y * ny
        v1m = v1x * mx + v1y * my
        da = 2.0 * (a2 * nx + a3 * ny)
        pa2 = a2 - da * nx - 2.0 * (v1m * nx + v1n * mx)
        pa3 = a3 - da * ny - 2.0 * (v1m * ny + v1n * my)
        v2n = v2x * nx + v2y * ny
        v2m = v2x * mx + v2y * my
        db = 2.0 * (b2 * nx + b3 * ny)
        pb2 = b2 - db * nx - 2.0 * (v2m * nx + v2n * mx)
        pb3 = b3 - db * ny - 2.0 * (v2m * ny + v2n * my)
    else:
        c = (a2 - b2) * nx + (a3 - b3) * ny + gx * mx + gy * my
        pa2 = a2 - c * nx - gn * mx
        pa3 = a3 - c * ny - gn * my
        pb2 = b2 + c * nx + gn * mx
        pb3 = b3 + c * ny + gn * my
    return qa0, qa1, pa2, pa3, qb0, qb1, pb2, pb3


@njit(cache=True, inline="always")
def kick_tangent(dvx, dvy, vx, vy, wx, wy, angle, kick_mode):
    """Velocity deviation across a kick at a given time (positions are unchanged).

    ``(vx, vy)`` before, ``(wx, wy)`` after the kick. Mode 0 (new direction, drawn
    independently of the state, speed kept): only the speed deviation survives,
    ``dv' = ((v.dv)/|v|) w/|w|``. Mode 1 (rotation by ``angle``): ``dv' = R(angle) dv``.
    A kick time does not depend on the state, so there is no ``dtau`` term.
    """
    if kick_mode == 0:
        ds = (vx * dvx + vy * dvy) / math.sqrt(vx * vx + vy * vy)
        s = ds / math.sqrt(wx * wx + wy * wy)
        return wx * s, wy * s
    c = math.cos(angle)
    s = math.sin(angle)
    return c * dvx - s * dvy, s * dvx + c * dvy


@njit(cache=True)
def _budget(dt, n_ev, n_same, max_events):
    """Event-loop guard: ``(status, n_same)`` after one more event ``dt`` from now.

    Callers pass ``np.int64(n_same)``: the counter's starting value 0 would otherwise be
    typed ``Literal[int](0)`` in some loops and compile this function a second time.
    """
    if dt != dt:
        return 3, n_same
    if dt == 0.0:
        n_same += 1
        if n_same > MAX_SAME_INSTANT:
            return 2, n_same
    else:
        n_same = 0
    if n_ev > max_events:
        return 1, n_same
    return 0, n_same


@njit(cache=True)
def _renormalise(U, log_scale, j):
    """Rescale ``U[j]`` to unit norm if it left ``[1/BIG, BIG]``; returns 1 if it did."""
    s = 0.0
    for i in range(U.shape[1]):
        s += U[j, i] * U[j, i]
    if s > BIG2 or (s < 1.0 / BIG2 and s > 0.0):
        nrm = math.sqrt(s)
        log_scale[j] += math.log(nrm)
        for i in range(U.shape[1]):
            U[j, i] /= nrm
        return 1
    return 0


@njit(cache=True)
def _gram_schmidt(U, log_scale):
    """Modified Gram-Schmidt on the rows of ``U``; ``log_scale[j] += log |R_jj|``."""
    m = U.shape[0]
    for j in range(m):
        for i in range(j):
            p = 0.0
            for c in range(U.shape[1]):
                p += U[i, c] * U[j, c]
            for c in range(U.shape[1]):
                U[j, c] -= p * U[i, c]
        s = 0.0
        for c in range(U.shape[1]):
            s += U[j, c] * U[j, c]
        nrm = math.sqrt(s)
        log_scale[j] += math.log(nrm)
        for c in range(U.shape[1]):
            U[j, c] /= nrm


@njit(cache=True)
def tangent_two_kernel(st, rho, sigma, rule, mode, n_steps, tau, U, max_events, n_orth):
    """Carry the tangent vectors ``U`` (m, 8) along the two-disk trajectory from ``st``.

    ``mode`` 1: up to ``n_steps * tau``; mode 2: through ``n_steps`` of the paper's
    collision-truncated steps (``t_k = min(t_{k-1} + tau, next event)``). Events at
    times ``<= t_end`` are applied, then everything flies on to ``t_end``. ``st`` and
    ``U`` are updated in place; ``U[j]`` is rescaled now and then and
    ``log_scale[j]`` collects the logarithms of the factors taken out. With
    ``n_orth > 0`` (mode 1 only) the rows are re-orthonormalised by Gram-Schmidt at
    ``n_orth`` equally spaced times, the last at ``t_end`` (for the spectrum: then
    ``log_scale[j]`` sums ``log |R_jj|``).

    Returns ``(log_scale, n_rescaled, n_pp, t_end, status)``.
    """
    m = U.shape[0]
    ev = np.empty(3)
    init_events_two(st, ev, rho, sigma)
    log_scale = np.zeros(m)
    n_resc = 0
    n_pp = 0
    n_ev = 0
    n_same = 0
    status = 0
    n_loop = max(1, n_orth) if mode == 1 else n_steps
    t_prev = 0.0
    for i_loop in range(n_loop):
        if mode == 1:
            tk = n_steps * tau if i_loop == n_loop - 1 else (i_loop + 1) * (n_steps * tau / n_loop)
        else:
            tk = min(t_prev + tau, st[0] + min(ev[0], min(ev[1], ev[2])))
        while True:
            ke, dt = next_event_two(ev)
            if not st[0] + dt <= tk:
                if dt != dt:
                    status = 3
                break
            n_ev += 1
            if dt > 0.0 and n_ev <= max_events:
                n_same = 0
            else:
                # the rare path: simultaneous events, a NaN time, or the budget used up
                status, n_same = _budget(dt, n_ev, np.int64(n_same), max_events)
                if status != 0:
                    break
            for j in range(m):
                U[j, 0] += U[j, 2] * dt
                U[j, 1] += U[j, 3] * dt
                U[j, 4] += U[j, 6] * dt
                U[j, 5] += U[j, 7] * dt
            v0x = st[3]
            v0y = st[4]
            v1x = st[7]
            v1y = st[8]
            process_event_two(st, ev, ke, rho, sigma, rule)
            if ke == 2:
                n_pp += 1
                for j in range(m):
                    (U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4], U[j, 5], U[j, 6],
                     U[j, 7]) = pair_tangent(U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4],
                                             U[j, 5], U[j, 6], U[j, 7], st[1], st[2], st[5],
                                             st[6], v0x, v0y, v1x, v1y, st[3], st[4], st[7],
                                             st[8], rule)
                    n_resc += _renormalise(U, log_scale, j)
            else:
                o = 1 + 4 * ke
                vx = v0x if ke == 0 else v1x
                vy = v0y if ke == 0 else v1y
                if vx != st[o + 2] or vy != st[o + 3]:
                    # (a disk already moving inward is not reflected: identity map)
                    for j in range(m):
                        (U[j, o - 1], U[j, o], U[j, o + 1], U[j, o + 2]) = wall_tangent(
                            U[j, o - 1], U[j, o], U[j, o + 1], U[j, o + 2], st[o], st[o + 1],
                            vx, vy, st[o + 2], st[o + 3], rho)
        if status != 0:
            break
        if n_orth > 0 and i_loop < n_loop - 1:
            # all rows are at the time st[0] of the last event: orthonormalise there
            _gram_schmidt(U, log_scale)
        t_prev = tk
    dt = t_prev - st[0]
    for j in range(m):
        U[j, 0] += U[j, 2] * dt
        U[j, 1] += U[j, 3] * dt
        U[j, 4] += U[j, 6] * dt
        U[j, 5] += U[j, 7] * dt
    if n_orth > 0:
        _gram_schmidt(U, log_scale)
    st[1] += st[3] * dt
    st[2] += st[4] * dt
    st[5] += st[7] * dt
    st[6] += st[8] * dt
    st[0] = t_prev
    return log_scale, n_resc, n_pp, t_prev, status


@njit(cache=True)
def tangent_one_kernel(st, rho, kicks, angles, kick_mode, mode, n_steps, tau, U, max_events,
                       kick_u, sp):
    """Carry the tangent vectors ``U`` (m, 4) along the kicked one-disk trajectory.

    As `tangent_two_kernel`; kicks at ``kicks`` (sorted times) with ``angles`` are
    applied with `kick_tangent` (a tie with a boundary collision goes to the boundary
    first, as in `simulate_one_particle`). Scattering kicks (``kick_mode == 2``, numbers
    ``kick_u``, parameters ``sp`` as in `process_scatter_one`) are linearised by
    `kicktimes.billiard.scatter.scatter_tangent`: a disk-disk collision with a partner
    whose deviation is zero.

    Returns ``(log_scale, n_rescaled, n_kicks, t_end, status)``.
    """
    m = U.shape[0]
    nk = kicks.shape[0]
    scatter = kick_mode == SCATTER
    unit_speed = (abs(st[3] * st[3] + st[4] * st[4] - 1.0) < 1e-12
                  and not (scatter and sp[1] != 0.0))
    row = np.empty(9)
    ev = np.empty(1)
    ev[0] = boundary_hit_time(st[1], st[2], st[3], st[4], rho)
    log_scale = np.zeros(m)
    n_resc = 0
    ik = 0
    n_ev = 0
    n_same = 0
    status = 0
    n_loop = 1 if mode == 1 else n_steps
    t_prev = 0.0
    for _ in range(n_loop):
        if mode == 1:
            tk = n_steps * tau
        else:
            dtn = ev[0]
            if ik < nk and kicks[ik] - st[0] < dtn:
                dtn = kicks[ik] - st[0]
            tk = min(t_prev + tau, st[0] + dtn)
        while True:
            is_kick = False
            dt = ev[0]
            if ik < nk and kicks[ik] - st[0] < dt:
                is_kick = True
                dt = kicks[ik] - st[0]
            if not st[0] + dt <= tk:
                if dt != dt:
                    status = 3
                break
            n_ev += 1
            if dt > 0.0 and n_ev <= max_events:
                n_same = 0
            else:
                # the rare path: simultaneous events, a NaN time, or the budget used up
                status, n_same = _budget(dt, n_ev, np.int64(n_same), max_events)
                if status != 0:
                    break
            for j in range(m):
                U[j, 0] += U[j, 2] * dt
                U[j, 1] += U[j, 3] * dt
            vx = st[3]
            vy = st[4]
            if is_kick and scatter:
                process_scatter_one(st, ev, dt, rho, kicks[ik], kick_u[ik, 0], kick_u[ik, 1],
                                    sp, row)
                if row[4] != 0.0 or row[5] != 0.0:
                    for j in range(m):
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3] = scatter_tangent(
                            vx, vy, row[6], row[7], row[4], row[5], sp[0], int(sp[1]), U[j, 0],
                            U[j, 1], U[j, 2], U[j, 3])
                        n_resc += _renormalise(U, log_scale, j)
                ik += 1
            elif is_kick:
                kick_one(st, ev, dt, rho, kicks[ik], angles[ik], kick_mode)
                for j in range(m):
                    U[j, 2], U[j, 3] = kick_tangent(U[j, 2], U[j, 3], vx, vy, st[3], st[4],
                                                    angles[ik], kick_mode)
                    n_resc += _renormalise(U, log_scale, j)
                ik += 1
            else:
                wall_one(st, ev, dt, rho, unit_speed)
                if vx != st[3] or vy != st[4]:
                    for j in range(m):
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3] = wall_tangent(
                            U[j, 0], U[j, 1], U[j, 2], U[j, 3], st[1], st[2], vx, vy, st[3],
                            st[4], rho)
        if status != 0:
            break
        t_prev = tk
    dt = t_prev - st[0]
    for j in range(m):
        U[j, 0] += U[j, 2] * dt
        U[j, 1] += U[j, 3] * dt
    st[1] += st[3] * dt
    st[2] += st[4] * dt
    st[0] = t_prev
    return log_scale, n_resc, ik, t_prev, status
