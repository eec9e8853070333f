"""The event step of the two-disk billiard: find the next event, advance, resolve.

This module is the only place where two disks in the table move and collide. Every
driver (`kicktimes.billiard.kernels.drive_two`: the simulation with its samples and logs,
the tangent vectors, the one pass of both; `kicktimes.billiard.kernels.twins`: Benettin's
twin trajectories) applies events through `step` (state in registers) or its array form
`process_event` (state in ``st``/``ev``), so they compute the same bits.

The state is a tuple of 13 floats (numba keeps it in registers; `S_*` name the fields)::

    s = (t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp)

``t`` the clock and ``comp`` its Kahan compensation; the centres and velocities of disk 0
and disk 1; ``tb0``, ``tb1``, ``tpp`` the times *from now* to the next boundary collision
of each disk and to the next disk-disk collision (``inf`` if none). Event times are kept
relative to the clock: absolute times lose digits as it grows (at ``t ~ 1e6`` their
spacing is ``1e-10``, enough to make disks overlap).

The array form: ``st = [t, x0, y0, vx0, vy0, x1, y1, vx1, vy1, comp, e0]`` (``e0`` the
initial kinetic energy, the anchor of the elastic rule) and ``ev = [tb0, tb1, tpp]``.

The disks may differ in size and mass: ``rho = (rho0, rho1, k0, k1)`` (`table`), the room
left to each centre ``1 - r_i`` and the elastic rule's momentum-exchange factors, and
``sigma = r0 + r1``, the contact distance (equal disks: ``rho0 = rho1``, ``k0 = k1 = 1``,
``sigma = 2 r``, the same arithmetic bit for bit).

An event is ``k`` = 0 or 1 (boundary collision of that disk) or 2 (disk-disk). The
arithmetic (docs/architecture.md, "The physics, precisely"):

* boundary (`wall_event`): the contact is put back on ``|x| = rho`` (one Newton step of
  ``1/sqrt``), the velocity reflected (or slid on, at a grazing contact,
  `kicktimes.billiard.geometry.graze`) and the next boundary time is the chord
  ``2 (x.v) / |v|^2``;
* disk-disk (`pair_event`): the rule's velocity map along the contact normal, then both
  boundary times afresh;
* after either, the elastic rule's velocities are anchored to ``e0`` (`anchor_energy`)
  and the disk-disk time is recomputed (both events change the relative motion).

Compiled with ``error_model="numpy"`` (no zero test before each division; see
`kicktimes.billiard.geometry`): every divisor is a non-zero radius, a contact distance
``2 r``, a speed of a disk at a wall, or the initial energy, which the input checks make
positive.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.geometry import (
    GRAZE_THRESHOLD,
    SIN_GRAZE,
    boundary_hit_time,
    collide_elastic,
    collide_mirror,
    graze,
    pair_hit_time,
    reflect,
)
from kicktimes.billiard.kernels import tables as tb

__all__ = ["PAIR", "table", "advance", "anchor_energy", "mass_factors", "pair_energy", "disk",
           "init_events", "load", "next_event", "pair_event", "process_event", "process_event_at",
           "resolve", "step", "store", "table_arc_lengths", "table_init_events",
           "table_process_event_at", "table_resolve", "table_step", "table_wall_event",
           "wall_event"]

#: fields of the state tuple
(S_T, S_COMP, S_X0, S_Y0, S_VX0, S_VY0, S_X1, S_Y1, S_VX1, S_VY1, S_TB0, S_TB1,
 S_TPP) = range(13)
#: the event code of a disk-disk collision (0 and 1 are the boundary of that disk)
PAIR = 2


@njit(cache=True, inline="always", error_model="numpy")
def wall_event(x, y, vx, vy, rho, rule):
    """Boundary collision of a disk at ``(x, y)`` on ``|x| = rho`` (up to the flight's round-off).

    Returns ``(x, y, vx, vy, t_next, sin_theta)``: the contact put back on the circle, the
    outgoing velocity, the time from now to the disk's next boundary collision and the
    incoming ``sin_theta``.
    """
    # The contact lies on |x| = rho: remove the flight's round-off with one Newton
    # step of 1/sqrt (|x|^2 = rho^2 (1 + e), e ~ 1e-16, so the error is O(e^2)).
    scale = 1.5 - 0.5 * (x * x + y * y) / (rho * rho)
    x *= scale
    y *= scale
    vv = vx * vx + vy * vy
    if rule == 0:
        # The mirror rule keeps unit speeds: skip the square root, and stop the
        # round-off of 10^6 reflections from drifting the speed (one Newton step).
        sv = 1.5 - 0.5 * vv
        vx *= sv
        vy *= sv
        vv = 1.0
        sp = 1.0
        sin_theta = (x * vy - y * vx) / rho
    else:
        sp = math.sqrt(vv)
        sin_theta = (x * vy - y * vx) / (rho * sp)
    xv = x * vx + y * vy
    # |x.v| <= rho |v| sin(delta)/2: grazing or tangent (see graze)
    gz = GRAZE_THRESHOLD * rho * sp
    if xv > gz:
        vx, vy = reflect(vx, vy, x / rho, y / rho)
        # from a point on the circle the next boundary hit is the chord, the exact
        # root of the quadratic with c = 0: t = -2 (x.v') / |v|^2 = 2 (x.v) / |v|^2
        t_next = 2.0 * xv / vv
    elif xv >= -gz:
        # reflecting would make no progress (a chord of length ~0): slide on
        vx, vy = graze(x, y, vx, vy, rho, sp)
        t_next = 2.0 * rho * SIN_GRAZE / sp
    else:
        # Never reflect a disk that is already moving inward (only a perturbed twin of
        # a Lyapunov computation can get here): it would turn it outward, into a
        # negative chord time.
        t_next = boundary_hit_time(x, y, vx, vy, rho)
    return x, y, vx, vy, t_next, sin_theta


def table(rho0, rho1, m0=1.0, m1=1.0) -> tuple:
    """The disks' table ``(rho0, rho1, k0, k1)`` the kernels take as ``rho``: the room
    left to each centre and the elastic rule's momentum-exchange factors
    ``k0 = 2 m1 / (m0 + m1)``, ``k1 = 2 m0 / (m0 + m1)`` (1 and 1 for equal masses)."""
    k0, k1 = mass_factors(float(m0), float(m1))
    return (float(rho0), float(rho1), k0, k1)


@njit(cache=True, error_model="numpy")
def mass_factors(m0, m1):
    """The elastic rule's momentum-exchange factors of disks of masses ``m0`` and ``m1``:
    ``(k0, k1) = (2 m1 / (m0 + m1), 2 m0 / (m0 + m1))``, ``(1, 1)`` for equal masses."""
    return 2.0 * m1 / (m0 + m1), 2.0 * m0 / (m0 + m1)


@njit(cache=True, error_model="numpy")
def pair_energy(vx0, vy0, vx1, vy1, k0=1.0, k1=1.0):
    """Twice the pair's kinetic energy in the kernels' units: ``|v0|^2 + |v1|^2`` for
    equal masses, ``k1 |v0|^2 + k0 |v1|^2`` (proportional to ``m0 |v0|^2 + m1 |v1|^2``)
    with the mass factors of `mass_factors`; the anchor of the elastic rule."""
    if k0 == 1.0 and k1 == 1.0:
        return vx0 * vx0 + vy0 * vy0 + vx1 * vx1 + vy1 * vy1
    return k1 * (vx0 * vx0 + vy0 * vy0) + k0 * (vx1 * vx1 + vy1 * vy1)


@njit(cache=True, error_model="numpy")
def pair_event(x0, y0, vx0, vy0, x1, y1, vx1, vy1, rule, k0=1.0, k1=1.0):
    """Velocities ``(vx0, vy0, vx1, vy1)`` after a disk-disk collision of disks in contact.

    The elastic rule with masses: ``v0' = v0 - k0 (w.n) n``, ``v1' = v1 + k1 (w.n) n``
    (``k0 = 2 m1 / (m0 + m1)``, ``k1 = 2 m0 / (m0 + m1)``; `table`)."""
    dx = x0 - x1
    dy = y0 - y1
    dd = math.sqrt(dx * dx + dy * dy)
    nx = dx / dd
    ny = dy / dd
    if rule == 0:
        a, b, c, d = collide_mirror(vx0, vy0, vx1, vy1, nx, ny)
        s1 = 1.5 - 0.5 * (a * a + b * b)
        s2 = 1.5 - 0.5 * (c * c + d * d)
        return a * s1, b * s1, c * s2, d * s2
    if k0 == 1.0 and k1 == 1.0:
        return collide_elastic(vx0, vy0, vx1, vy1, nx, ny)
    p = (vx0 - vx1) * nx + (vy0 - vy1) * ny
    return vx0 - k0 * p * nx, vy0 - k0 * p * ny, vx1 + k1 * p * nx, vy1 + k1 * p * ny


@njit(cache=True, error_model="numpy")
def anchor_energy(vx0, vy0, vx1, vy1, e0, k0=1.0, k1=1.0):
    """The four velocity components rescaled to kinetic energy ``e0`` (one Newton step).

    Correcting each event relative to the previous one would let the rounding bias of
    10^6 events accumulate to 1e-10; anchoring to the initial value does not. With masses
    the energy is ``k1 |v0|^2 + k0 |v1|^2`` (proportional to ``m0 |v0|^2 + m1 |v1|^2``).
    """
    f = 1.5 - 0.5 * pair_energy(vx0, vy0, vx1, vy1, k0, k1) / e0
    return vx0 * f, vy0 * f, vx1 * f, vy1 * f


@njit(cache=True, inline="always", error_model="numpy")
def next_event(s):
    """``(k, dt)``: the next event (0, 1: boundary of that disk; 2: disk-disk) and its
    time from now; a tie goes to the lower code."""
    k = 0
    dt = s[S_TB0]
    if s[S_TB1] < dt:
        k = 1
        dt = s[S_TB1]
    if s[S_TPP] < dt:
        k = PAIR
        dt = s[S_TPP]
    return k, dt


@njit(cache=True, inline="always", error_model="numpy")
def advance(s, dt):
    """Free flight of both disks for ``dt``; the clock is summed with Kahan compensation."""
    t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp = s
    x0 += vx0 * dt
    y0 += vy0 * dt
    x1 += vx1 * dt
    y1 += vy1 * dt
    tb0 -= dt
    tb1 -= dt
    tpp -= dt
    yk = dt - comp
    tn = t + yk
    comp = (tn - t) - yk
    return (tn, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp)


@njit(cache=True, inline="always", error_model="numpy")
def resolve(s, k, rho, sigma, rule, e0):
    """Apply event ``k`` to disks in contact; returns ``(s, sin_theta)`` (the incoming
    ``sin_theta`` of a boundary collision, 0 for a disk-disk collision). ``rho = (rho0,
    rho1, k0, k1)`` (`table`): the room left to each disk's centre, ``1 - r_i``, and the
    elastic rule's mass factors; ``sigma = r0 + r1``."""
    t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp = s
    sin_theta = 0.0
    if k < PAIR:
        # one call site for both disks: half the code of two
        if k == 0:
            x, y, vx, vy = x0, y0, vx0, vy0
        else:
            x, y, vx, vy = x1, y1, vx1, vy1
        x, y, vx, vy, tb, sin_theta = wall_event(x, y, vx, vy, rho[0] if k == 0 else rho[1],
                                                  rule)
        if k == 0:
            x0, y0, vx0, vy0, tb0 = x, y, vx, vy, tb
        else:
            x1, y1, vx1, vy1, tb1 = x, y, vx, vy, tb
    else:
        vx0, vy0, vx1, vy1 = pair_event(x0, y0, vx0, vy0, x1, y1, vx1, vy1, rule, rho[2],
                                         rho[3])
        tb0 = boundary_hit_time(x0, y0, vx0, vy0, rho[0])
        tb1 = boundary_hit_time(x1, y1, vx1, vy1, rho[1])
    if rule != 0:
        vx0, vy0, vx1, vy1 = anchor_energy(vx0, vy0, vx1, vy1, e0, rho[2], rho[3])
    # both kinds of event change the pair's relative motion
    tpp = pair_hit_time(x0 - x1, y0 - y1, vx0 - vx1, vy0 - vy1, sigma)
    return (t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp), sin_theta


@njit(cache=True, inline="always", error_model="numpy")
def step(s, k, dt, rho, sigma, rule, e0):
    """Fly ``dt`` to event ``k`` and apply it: `advance` then `resolve`."""
    return resolve(advance(s, dt), k, rho, sigma, rule, e0)


@njit(cache=True, inline="always", error_model="numpy")
def disk(s, i):
    """``(x, y, vx, vy)`` of disk ``i`` in the state tuple ``s`` (a select, not an index:
    an index that varies from event to event would compile to a jump table)."""
    if i == 0:
        return s[S_X0], s[S_Y0], s[S_VX0], s[S_VY0]
    return s[S_X1], s[S_Y1], s[S_VX1], s[S_VY1]


@njit(cache=True, inline="always", error_model="numpy")
def init_events(st, ev, rho, sigma):
    """Fill ``ev`` with the times from now to the next events of the state ``st``
    (``rho = (rho0, rho1)``, ``sigma = r0 + r1``)."""
    ev[0] = boundary_hit_time(st[1], st[2], st[3], st[4], rho[0])
    ev[1] = boundary_hit_time(st[5], st[6], st[7], st[8], rho[1])
    ev[2] = pair_hit_time(st[1] - st[5], st[2] - st[6], st[3] - st[7], st[4] - st[8], sigma)


@njit(cache=True, inline="always", error_model="numpy")
def load(st, ev):
    """The state tuple of the arrays ``st``, ``ev``."""
    return (st[0], st[9], st[1], st[2], st[3], st[4], st[5], st[6], st[7], st[8], ev[0], ev[1],
            ev[2])


@njit(cache=True, inline="always", error_model="numpy")
def store(st, ev, s):
    """Write the state tuple ``s`` back to the arrays ``st``, ``ev``."""
    st[0] = s[S_T]
    st[9] = s[S_COMP]
    st[1], st[2], st[3], st[4] = disk(s, 0)
    st[5], st[6], st[7], st[8] = disk(s, 1)
    ev[0] = s[S_TB0]
    ev[1] = s[S_TB1]
    ev[2] = s[S_TPP]


@njit(cache=True, error_model="numpy")
def process_event(st, ev, k, rho, sigma, rule):
    """`step` on the arrays ``st``, ``ev``: fly to event ``k`` and apply it; returns the
    incoming ``sin_theta``. For the drivers that keep many trajectories (the twins)."""
    s, sin_theta = step(load(st, ev), k, ev[k], rho, sigma, rule, st[10])
    store(st, ev, s)
    return sin_theta


@njit(cache=True, error_model="numpy")
def process_event_at(traj, ev, j, k, rho, sigma, rule):
    """`process_event` on row ``j`` of the 2-D arrays ``traj``, ``ev`` (the twins' form:
    a row view per event would cost reference counting on every event)."""
    s = (traj[j, 0], traj[j, 9], traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4], traj[j, 5],
         traj[j, 6], traj[j, 7], traj[j, 8], ev[j, 0], ev[j, 1], ev[j, 2])
    s, sin_theta = step(s, k, ev[j, k], rho, sigma, rule, traj[j, 10])
    traj[j, 0] = s[S_T]
    traj[j, 9] = s[S_COMP]
    traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4] = disk(s, 0)
    traj[j, 5], traj[j, 6], traj[j, 7], traj[j, 8] = disk(s, 1)
    ev[j, 0] = s[S_TB0]
    ev[j, 1] = s[S_TB1]
    ev[j, 2] = s[S_TPP]
    return sin_theta


@njit(cache=True, inline="always", error_model="numpy")
def fly(s, t_end):
    """The state flown freely to the time ``t_end`` (no event before it), clock exactly
    ``t_end`` and its compensation reset."""
    t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp = s
    dt = t_end - t
    return (t_end, 0.0, x0 + vx0 * dt, y0 + vy0 * dt, vx0, vy0, x1 + vx1 * dt, y1 + vy1 * dt,
            vx1, vy1, tb0 - dt, tb1 - dt, tpp - dt)


# --- two disks in another table (the stadium, the ellipse) ---------------------------------
#
# The table path: ``wall = (kind, p0, p1, p2)`` of `kicktimes.billiard.kernels.tables` (both
# disks equal: one centre's curve). Each disk's next wall contact carries a "where" (the
# stadium's piece, the ellipse's normal, `tables.hit`), kept beside the state tuple in
# ``wh = (w1_0, w2_0, w1_1, w2_1)``. The circle never comes here: the drivers take ``wall``
# as ``None`` for it and numba compiles this path out, so the circle's loop is the one it
# always had.

@njit(cache=True, inline="always", error_model="numpy")
def table_wall_event(x, y, vx, vy, w1, w2, wall, rule):
    """Wall contact of a disk at ``(x, y)`` (advanced to the contact `tables.hit` found at
    ``(w1, w2)``) on the table ``wall = (kind, p0, p1, p2)``.

    The contact is put back on the wall (`tables.contact`), the velocity reflected or slid
    on at a grazing contact (`tables.bounce`), the speed kept by one Newton step of
    ``|v'|^2`` towards the incoming ``|v|^2`` (1 under the mirror rule), and the next contact
    found (`tables.hit`). Returns ``(x, y, vx, vy, t_next, w1, w2, sin_theta, nx, ny,
    kappa)``: ``sin_theta = v.t / |v|`` (``t = (-ny, nx)`` the counter-clockwise tangent:
    Birkhoff's coordinate, as the circle's ``(x vy - y vx) / (rho |v|)``), the outward
    normal and the curvature of the centre's curve at the contact (for the tangent map).
    """
    kind, p0, p1, p2 = wall
    x, y, nx, ny, kappa = tb.contact(kind, p0, p1, p2, x, y, vx, vy, w1, w2)
    vv = 1.0 if rule == 0 else vx * vx + vy * vy
    sin_theta = (vy * nx - vx * ny) if rule == 0 else (vy * nx - vx * ny) / math.sqrt(vv)
    wx, wy = tb.bounce(vx, vy, nx, ny)
    f = 1.5 - 0.5 * (wx * wx + wy * wy) / vv
    wx *= f
    wy *= f
    t_next, w1, w2 = tb.hit(kind, p0, p1, p2, x, y, wx, wy)
    return x, y, wx, wy, t_next, w1, w2, sin_theta, nx, ny, kappa


@njit(cache=True, inline="always", error_model="numpy")
def table_resolve(s, wh, k, rho, sigma, rule, e0, wall):
    """`resolve` in the table ``wall``: returns ``(s, wh, sin_theta, nx, ny, kappa)``, the
    wall contact's normal and curvature (zeros for a disk-disk collision)."""
    t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp = s
    a0, b0, a1, b1 = wh
    sin_theta = 0.0
    nx = 0.0
    ny = 0.0
    kappa = 0.0
    kind, p0, p1, p2 = wall
    if k < PAIR:
        if k == 0:
            x, y, vx, vy, wa, wb = x0, y0, vx0, vy0, a0, b0
        else:
            x, y, vx, vy, wa, wb = x1, y1, vx1, vy1, a1, b1
        x, y, vx, vy, tbk, wa, wb, sin_theta, nx, ny, kappa = table_wall_event(
            x, y, vx, vy, wa, wb, wall, rule)
        if k == 0:
            x0, y0, vx0, vy0, tb0, a0, b0 = x, y, vx, vy, tbk, wa, wb
        else:
            x1, y1, vx1, vy1, tb1, a1, b1 = x, y, vx, vy, tbk, wa, wb
    else:
        vx0, vy0, vx1, vy1 = pair_event(x0, y0, vx0, vy0, x1, y1, vx1, vy1, rule, rho[2],
                                         rho[3])
        tb0, a0, b0 = tb.hit(kind, p0, p1, p2, x0, y0, vx0, vy0)
        tb1, a1, b1 = tb.hit(kind, p0, p1, p2, x1, y1, vx1, vy1)
    if rule != 0:
        vx0, vy0, vx1, vy1 = anchor_energy(vx0, vy0, vx1, vy1, e0, rho[2], rho[3])
    tpp = pair_hit_time(x0 - x1, y0 - y1, vx0 - vx1, vy0 - vy1, sigma)
    return ((t, comp, x0, y0, vx0, vy0, x1, y1, vx1, vy1, tb0, tb1, tpp), (a0, b0, a1, b1),
            sin_theta, nx, ny, kappa)


@njit(cache=True, inline="always", error_model="numpy")
def table_step(s, wh, k, dt, rho, sigma, rule, e0, wall):
    """`step` in the table ``wall``: fly ``dt`` to event ``k`` and apply it
    (`table_resolve`)."""
    return table_resolve(advance(s, dt), wh, k, rho, sigma, rule, e0, wall)


@njit(cache=True, inline="always", error_model="numpy")
def table_init_events(st, ev, wh, rho, sigma, wall):
    """`init_events` in the table ``wall``; the wall contacts' "where" into ``wh`` (4,)."""
    kind, p0, p1, p2 = wall
    ev[0], wh[0], wh[1] = tb.hit(kind, p0, p1, p2, st[1], st[2], st[3], st[4])
    ev[1], wh[2], wh[3] = tb.hit(kind, p0, p1, p2, st[5], st[6], st[7], st[8])
    ev[2] = pair_hit_time(st[1] - st[5], st[2] - st[6], st[3] - st[7], st[4] - st[8], sigma)


@njit(cache=True, error_model="numpy")
def table_process_event_at(traj, ev, wh, j, k, rho, sigma, rule, wall):
    """`process_event_at` in the table ``wall`` (``wh`` (m, 4): each row's "where")."""
    s = (traj[j, 0], traj[j, 9], traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4], traj[j, 5],
         traj[j, 6], traj[j, 7], traj[j, 8], ev[j, 0], ev[j, 1], ev[j, 2])
    w = (wh[j, 0], wh[j, 1], wh[j, 2], wh[j, 3])
    s, w, sin_theta, _, _, _ = table_step(s, w, k, ev[j, k], rho, sigma, rule, traj[j, 10],
                                          wall)
    traj[j, 0] = s[S_T]
    traj[j, 9] = s[S_COMP]
    traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4] = disk(s, 0)
    traj[j, 5], traj[j, 6], traj[j, 7], traj[j, 8] = disk(s, 1)
    ev[j, 0] = s[S_TB0]
    ev[j, 1] = s[S_TB1]
    ev[j, 2] = s[S_TPP]
    wh[j, 0], wh[j, 1], wh[j, 2], wh[j, 3] = w
    return sin_theta


@njit(cache=True, error_model="numpy")
def table_arc_lengths(kind, p0, p1, p2, x, y):
    """Arc length along the centre's curve (`tables.boundary_coordinates`'s ``s``, in
    ``[0, L)``) of each logged contact ``(x[i], y[i])``."""
    out = np.empty(x.shape[0])
    for i in range(x.shape[0]):
        out[i] = tb.boundary_coordinates(kind, p0, p1, p2, x[i], y[i], 1.0, 0.0)[0]
    return out
