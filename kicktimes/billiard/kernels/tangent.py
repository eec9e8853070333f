"""The linearised event maps: how a tangent vector crosses each event of the kernel layer.

A tangent vector ``(dq, dv)`` is a first-order deviation of the phase-space state. It is
carried along the reference trajectory exactly: free flight ``dq += dv t``; at each event
the linearised event map (docs/lyapunov.md), written here once as scalar functions of the
reference state at the event (contact position, incoming and outgoing velocities), beside
the events themselves (`kicktimes.billiard.kernels.two`, `.one`):

* `wall_tangent`: specular reflection at the table's wall ``|q| = rho`` (curvature term),
  the circle's case of `curved_wall_tangent` (a wall of any local curvature);
* `pair_tangent`: disk-disk collision, rule 0 (mirror) or 1 (elastic); a partner whose
  state is fixed (a "scatter" kick off a virtual disk,
  `kicktimes.billiard.scatter.scatter_tangent`) is the case ``dq2 = dv2 = 0``;
* `kick_tangent`: a kick at a given time (mode 0: the direction is redrawn, independent
  of the state; mode 1: rotation by a shared angle).

Every map includes the variation of the collision time ``dtau = -(n.dq_rel)/(n.v_rel)``
(Dellago, Posch & Hoover, Phys. Rev. E 53, 1485 (1996)).

Layouts: two disks ``U[j] = [dx0, dy0, dvx0, dvy0, dx1, dy1, dvx1, dvy1]`` (as ``st[1:9]``),
one disk ``U[j] = [dx, dy, dvx, dvy]`` (as ``st[1:5]``). Also here: the free flight of the
tangent vectors (`tangent_flight`), their rescaling (`renormalize`, `gram_schmidt`) and
the guard of the tangent loops (`event_guard`, status codes 0 ok, 1 event budget
exhausted, 2 more than ``MAX_SAME_INSTANT`` events at one instant, 3 a non-finite event
time).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["BIG", "MAX_SAME_INSTANT", "curved_wall_tangent", "end_step", "event_guard",
           "gram_schmidt", "guard", "kick_tangent", "load_carry", "pair_tangent",
           "renormalize", "start", "step_end", "store_carry", "tangent_flight",
           "tangent_state", "wall_tangent"]

#: the tangent half of a driver carries its position between calls in ``tgi`` (int64) and
#: ``tgf`` (float64), at these indices; ``tgi[FRESH_PARTNER]`` (1: disk 1's deviation set
#: to zero just before each disk-disk collision, the scatter model's view of the two
#: disks, `kicktimes.billiard.kernels.drive_two.fresh_partner_tangent_two_kernel`) is set
#: at the start and never changes
TAN_ON, I_LOOP, N_LOOP, N_EV, N_SAME, N_RESC, N_PERT, TAN_STATUS, FRESH_PARTNER = range(9)
TK, T_PREV = range(2)

MAX_SAME_INSTANT = 1000
# Keep tangent norms inside [1/BIG, BIG]: far from overflow, and rescaling is rare (a
# log per rescaling instead of one per sample, which would cost as much as the simulation).
# The norm is checked after disk-disk collisions and kicks only: wall reflections in the
# circle only shear (polynomial growth), so they cannot overflow between two checks.
BIG = 1e100
BIG2 = BIG * BIG


@njit(cache=True, inline="always")
def curved_wall_tangent(dqx, dqy, dvx, dvy, vx, vy, wx, wy, nx, ny, kappa):
    """Tangent vector across a reflection at a wall of curvature ``kappa``, outward normal
    ``n``, incoming velocity ``v`` and outgoing ``w``.

    The map of every table's wall (the circle's `wall_tangent` is the case ``kappa = 1 /
    rho``, ``n = q / rho``; the normal turns as ``dn = kappa u`` along the wall):
    ``dtau = -(n.dq)/(n.v)``, ``u = dq + v dtau`` (``u.n = 0``),
    ``dq' = dq + (v - w) dtau``, ``dv' = R dv - 2 kappa [(v.u) n + (v.n) u]``,
    ``R = I - 2 n n^T`` (Dellago, Posch & Hoover, Phys. Rev. E 53, 1485 (1996)). A flat
    wall (``kappa = 0``) only mirrors ``dv``. NaN at an exactly tangent contact.
    """
    vn = vx * nx + vy * ny
    if vn == 0.0:
        return math.nan, math.nan, math.nan, math.nan
    dtau = -(nx * dqx + ny * dqy) / vn
    ux = dqx + vx * dtau
    uy = dqy + vy * dtau
    k = 2.0 * kappa
    vu = vx * ux + vy * uy
    dvn = 2.0 * (dvx * nx + dvy * ny)
    return (dqx + (vx - wx) * dtau, dqy + (vy - wy) * dtau,
            dvx - dvn * nx - k * (vu * nx + vn * ux), dvy - dvn * ny - k * (vu * ny + vn * uy))



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
    (``2 (1 / rho)`` is ``2 / rho`` to the bit: scaling by two is exact, so this is the
    circle's map exactly as it was written before the curved walls shared it.)
    """
    return curved_wall_tangent(dqx, dqy, dvx, dvy, vx, vy, wx, wy, x / rho, y / rho,
                               1.0 / rho)


@njit(cache=True)
def pair_tangent(a0, a1, a2, a3, b0, b1, b2, b3, x1, y1, x2, y2, v1x, v1y, v2x, v2y,
                 w1x, w1y, w2x, w2y, rule, k0=1.0, k1=1.0):
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
      ``c = (dv_1 - dv_2).n + g.m``; with masses (``v_1' = v1 - k0 (g.n) n``,
      ``v_2' = v2 + k1 (g.n) n``) the two corrections carry ``k0`` and ``k1``.
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
    elif k0 == 1.0 and k1 == 1.0:
        c = (a2 - b2) * nx + (a3 - b3) * ny + gx * mx + gy * my
        pa2 = a2 - c * nx - gn * mx
        pa3 = a3 - c * ny - gn * my
        pb2 = b2 + c * nx + gn * mx
        pb3 = b3 + c * ny + gn * my
    else:
        c = (a2 - b2) * nx + (a3 - b3) * ny + gx * mx + gy * my
        pa2 = a2 - k0 * (c * nx + gn * mx)
        pa3 = a3 - k0 * (c * ny + gn * my)
        pb2 = b2 + k1 * (c * nx + gn * mx)
        pb3 = b3 + k1 * (c * ny + gn * my)
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
def event_guard(dt, n_ev, n_same, max_events):
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
def renormalize(U, log_scale, j):
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
def gram_schmidt(U, log_scale):
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


@njit(cache=True, inline="always")
def tangent_flight(U, dt):
    """Free flight of the tangent vectors for ``dt``: ``dq += dv dt`` for each disk (rows of
    one disk, ``(dx, dy, dvx, dvy)``, or of two)."""
    for j in range(U.shape[0]):
        U[j, 0] += U[j, 2] * dt
        U[j, 1] += U[j, 3] * dt
        if U.shape[1] == 8:
            U[j, 4] += U[j, 6] * dt
            U[j, 5] += U[j, 7] * dt


@njit(cache=True)
def tangent_state(U, mode, n_steps, tau, max_events, n_orth):
    """The tangent half of a driver (`kicktimes.billiard.kernels.drive_two.drive`):
    ``(U, log_scale, tgi, tgf, max_events, n_orth, n_steps)`` at the start; the driver sets
    the first step's end from the initial state."""
    tgi = np.zeros(9, dtype=np.int64)
    tgi[TAN_ON] = 1
    tgi[N_LOOP] = max(1, n_orth) if mode == 1 else n_steps
    return (U, np.zeros(U.shape[0]), tgi, np.zeros(2), max_events, n_orth, n_steps)


@njit(cache=True)
def start(tan, mode, n_steps, tau, t_next_event):
    """Set the end of the tangent half's first step, the next event being at
    ``t_next_event``."""
    tan[3][TK] = step_end(0, tan[2][N_LOOP], mode, n_steps, tau, 0.0, t_next_event)


@njit(cache=True, inline="always")
def load_carry(tgi, tgf):
    """The tangent half's position between driver calls: ``(i_loop, n_loop, n_ev, n_same,
    n_resc, n_pert, tk, t_prev, status)``."""
    return (tgi[I_LOOP], tgi[N_LOOP], tgi[N_EV], tgi[N_SAME], tgi[N_RESC], tgi[N_PERT], tgf[TK],
            tgf[T_PREV], tgi[TAN_STATUS])


@njit(cache=True, inline="always")
def store_carry(tgi, tgf, tan_on, i_loop, n_ev, n_same, n_resc, n_pert, tk, t_prev, status):
    """Write the tangent half's position back (see `load_carry`)."""
    tgi[TAN_STATUS] = status
    tgi[TAN_ON] = 1 if tan_on else 0
    tgi[I_LOOP] = i_loop
    tgi[N_EV] = n_ev
    tgi[N_SAME] = n_same
    tgi[N_RESC] = n_resc
    tgi[N_PERT] = n_pert
    tgf[TK] = tk
    tgf[T_PREV] = t_prev


@njit(cache=True, inline="always")
def step_end(i_loop, n_loop, mode, n_steps, tau, t_prev, t_next_event):
    """The end time of the tangent vectors' step ``i_loop`` of ``n_loop``.

    ``mode`` 1: ``n_loop`` equal parts of ``n_steps * tau`` (the last exactly at it);
    ``mode`` 2: the paper's collision-truncated step ``min(t_prev + tau, next event)``.
    """
    if mode == 1:
        if i_loop == n_loop - 1:
            return n_steps * tau
        return (i_loop + 1) * (n_steps * tau / n_loop)
    return min(t_prev + tau, t_next_event)


@njit(cache=True)
def end_step(U, log_scale, dt, n_orth):
    """The end of the tangent vectors' last step, ``dt`` after the last event: they fly on
    to it, and with ``n_orth > 0`` are orthonormalised a last time (`gram_schmidt`).

    The step ends themselves are crossed in the drivers' event loops, written out there:
    a helper for them, inlined or called at every sample, measured 5-20 % slower
    (benchmarks/bench_kernels.py).
    """
    tangent_flight(U, dt)
    if n_orth > 0:
        gram_schmidt(U, log_scale)


@njit(cache=True, inline="always")
def guard(dt, n_ev, n_same, max_events):
    """`event_guard` with its common case inline: ``(status, n_ev, n_same)`` after one
    more event ``dt`` from now."""
    n_ev += 1
    if dt > 0.0 and n_ev <= max_events:
        return 0, n_ev, np.int64(0)
    code, n_same = event_guard(dt, n_ev, np.int64(n_same), max_events)
    return code, n_ev, n_same
