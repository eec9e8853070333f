"""The event step of the kicked one-disk billiard: next event, advance, resolve.

The only place where the kicked disk moves, reflects and is kicked; every driver
(`kicktimes.billiard.kernels.drive_one`, `kicktimes.billiard.kernels.twins`) applies events
through these functions, so they compute the same bits.

The state is a tuple of 7 floats, ``s = (t, comp, x, y, vx, vy, tb)``: the clock and its
Kahan compensation, the centre and velocity, and the time from now to the next boundary
collision. Its array form is ``st = [t, x, y, vx, vy, comp, v2]`` (``v2`` the squared
speed, which boundary collisions and kicks keep) and ``ev = [tb]``. Kicks come from a
sorted array of times; the next one is ``kicks[ik]``.

Events: a boundary collision (`wall_step`, in registers), or a kick (array form, they are
rare): a new direction or a rotation (`kick_step`), a collision with a virtual partner
(`scatter_step`), or, for a Lyapunov twin, the reference's partner met or missed
(`twin_scatter_step`). Ties: a kick at the same instant as a boundary collision is
applied *after* the reflection (`next_event`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard import geometry as geo
from kicktimes.billiard.kernels import tables
from kicktimes.billiard.scatter import scatter_kick, twin_meets_partner

__all__ = ["KICK_ANGLES", "SCATTER", "SCATTER_PARAMS", "advance", "apply_kick", "fly", "kick_step",
           "kinetic_delay", "load", "next_event", "next_kick", "process_wall", "process_wall_at",
           "process_table_wall_at", "scatter_step", "store", "table_arc_lengths", "table_hit",
           "table_kick_step", "table_outside", "table_scatter_step", "table_twin_scatter_step",
           "table_wall_event", "table_wall_step", "twin_scatter_step", "unit_speed_of",
           "wall_event", "wall_step"]

#: kick laws and their codes in the kernels
# "normal" draws the new direction from N(0, sigma^2): a new angle, applied as "uniform"
KICK_ANGLES = {"uniform": 0, "gaussian": 1, "scatter": 2, "normal": 0}
SCATTER = KICK_ANGLES["scatter"]
#: the scattering kicks' parameter array ``sp`` (`scatter_step`), field by field
SCATTER_PARAMS = ("sigma", "rule", "e0", "law", "rho1", "m0", "m1")
#: fields of the state tuple
S_T, S_COMP, S_X, S_Y, S_VX, S_VY, S_TB = range(7)


@njit(cache=True)
def unit_speed_of(st, kick_mode, sp):
    """True if the disk keeps unit speed for the whole run: its speed is 1 and no elastic
    scattering kick can change it (the boundary collision then skips a square root)."""
    return (abs(st[3] * st[3] + st[4] * st[4] - 1.0) < 1e-12
            and not (kick_mode == SCATTER and sp[1] != 0.0))


@njit(cache=True)
def kinetic_delay(st, e, rates, l_first, dl, c_first, dc):
    """The delay ``e / rate`` of the next kick at the kinetic rate of the disk's own orbit
    (kinetic kicks): ``e`` a standard exponential number, ``rate`` interpolated in the
    table ``rates[j, i]`` of `kicktimes.schedules.KineticRate.kernel_table` (clamped to its
    ends). One row (unit speed, the mirror rule): linearly in ``L = x vy - y vx`` on the
    grid ``l_first + i dl``. More rows (the elastic rule): bilinearly in ``kappa = L / c``
    on that grid and the speed ``c = |v|`` on ``c_first + j dc``. Between kicks ``L`` and
    ``c`` are conserved (wall reflections keep them), so the delay is drawn once, right
    after a kick, from the state the kick left (an elastic scattering kick changes ``c``)."""
    ell = st[1] * st[4] - st[2] * st[3]
    n = rates.shape[1]
    if rates.shape[0] == 1:
        f = (ell - l_first) / dl
        i = min(max(int(math.floor(f)), 0), n - 2)
        w = min(max(f - i, 0.0), 1.0)
        return e / (rates[0, i] * (1.0 - w) + rates[0, i + 1] * w)
    c = math.sqrt(st[3] * st[3] + st[4] * st[4])
    f = (ell / c - l_first) / dl
    i = min(max(int(math.floor(f)), 0), n - 2)
    w = min(max(f - i, 0.0), 1.0)
    g = (c - c_first) / dc
    j = min(max(int(math.floor(g)), 0), rates.shape[0] - 2)
    u = min(max(g - j, 0.0), 1.0)
    low = rates[j, i] * (1.0 - w) + rates[j, i + 1] * w
    high = rates[j + 1, i] * (1.0 - w) + rates[j + 1, i + 1] * w
    return e / (low * (1.0 - u) + high * u)


@njit(cache=True)
def apply_kick(st, angle, kick_mode):
    """Replace the direction by ``angle`` (mode 0) or rotate it by ``angle`` (mode 1)."""
    vx = st[3]
    vy = st[4]
    if kick_mode == 0:
        speed = math.sqrt(st[6])
        st[3] = speed * math.cos(angle)
        st[4] = speed * math.sin(angle)
    else:
        c = math.cos(angle)
        s = math.sin(angle)
        st[3] = c * vx - s * vy
        st[4] = s * vx + c * vy


@njit(cache=True, inline="always")
def next_kick(kicks, ik):
    """The time of kick ``ik`` (``inf`` when all are applied)."""
    return kicks[ik] if ik < kicks.shape[0] else math.inf


@njit(cache=True, inline="always")
def next_event(s, t_kick):
    """``(is_kick, dt)``: whether the next event is the kick at ``t_kick`` (`next_kick`) and
    its time from now; a tie goes to the boundary. Scalars only: a helper taking the kick
    array, called per event, would cost reference counting on every event."""
    dk = t_kick - s[S_T]
    if dk < s[S_TB]:
        return True, dk
    return False, s[S_TB]


@njit(cache=True)
def wall_event(x, y, vx, vy, rho, unit_speed):
    """Boundary collision of the disk at ``(x, y)`` on ``|x| = rho`` (up to round-off).

    Returns ``(x, y, vx, vy, t_next, sin_theta)``: the contact put back on the circle, the
    outgoing velocity, the time to the next boundary collision and the incoming
    ``sin_theta``. Plain floats, so that the event loop keeps the state in registers.
    """
    # No Newton step on the speed here (unlike the two-disk mirror kernel): its rounding
    # bias drifts L = x vy - y vx by 6e-12 over 10^6 collisions, 40x more than without.
    vv = vx * vx + vy * vy
    xv = x * vx + y * vy
    gz = geo.GRAZE_THRESHOLD * rho
    if xv > 0.0 and xv * xv >= gz * gz * vv:
        # Put the contact back on |x| = rho with a Newton step *along the flight*: a radial
        # projection would rescale L = x vy - y vx and drift sin_theta by 1e-11 over 10^6
        # collisions; moving along v keeps L exact.
        e = (x * x + y * y - rho * rho) / (2.0 * xv)
        x -= vx * e
        y -= vy * e
        xv = x * vx + y * vy
        if unit_speed:
            sin_theta = (x * vy - y * vx) / rho
        else:
            sin_theta = (x * vy - y * vx) / (rho * math.sqrt(vv))
        vx, vy = geo.reflect(vx, vy, x / rho, y / rho)
        t_next = 2.0 * xv / vv
    elif xv * xv < gz * gz * vv:
        # Grazing or tangent: slide on (see geometry.graze). The Newton step along the flight
        # above would divide by x.v ~ 0, so project radially.
        scale = 1.5 - 0.5 * (x * x + y * y) / (rho * rho)
        x *= scale
        y *= scale
        sp = math.sqrt(vv)
        sin_theta = (x * vy - y * vx) / (rho * sp)
        vx, vy = geo.graze(x, y, vx, vy, rho, sp)
        t_next = 2.0 * rho * geo.SIN_GRAZE / sp
    else:
        # a Lyapunov twin moving inward (see kernels.two.wall_event): no reflection
        scale = 1.5 - 0.5 * (x * x + y * y) / (rho * rho)
        x *= scale
        y *= scale
        sin_theta = (x * vy - y * vx) / (rho * math.sqrt(vv))
        t_next = geo.boundary_hit_time(x, y, vx, vy, rho)
    return x, y, vx, vy, t_next, sin_theta


@njit(cache=True, inline="always")
def advance(s, dt):
    """Free flight for ``dt``; event time relative to now; Kahan-compensated clock."""
    t, comp, x, y, vx, vy, tb = s
    x += vx * dt
    y += vy * dt
    tb -= dt
    yk = dt - comp
    tn = t + yk
    comp = (tn - t) - yk
    return (tn, comp, x, y, vx, vy, tb)


@njit(cache=True, inline="always")
def wall_step(s, dt, rho, unit_speed):
    """Fly ``dt`` to the wall and geo.reflect: ``(s, sin_theta)``."""
    t, comp, x, y, vx, vy, tb = advance(s, dt)
    x, y, vx, vy, tb, sin_theta = wall_event(x, y, vx, vy, rho, unit_speed)
    return (t, comp, x, y, vx, vy, tb), sin_theta


@njit(cache=True)
def process_wall(st, ev, dt, rho, unit_speed):
    """`wall_step` on the arrays ``st``, ``ev``; returns the incoming ``sin_theta``."""
    s, sin_theta = wall_step(load(st, ev), dt, rho, unit_speed)
    store(st, ev, s)
    return sin_theta


@njit(cache=True)
def process_wall_at(traj, ev, j, dt, rho, unit_speed):
    """`process_wall` on row ``j`` of the 2-D arrays ``traj``, ``ev`` (the twins' form)."""
    s = (traj[j, 0], traj[j, 5], traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4], ev[j, 0])
    s, sin_theta = wall_step(s, dt, rho, unit_speed)
    traj[j, 0] = s[S_T]
    traj[j, 5] = s[S_COMP]
    traj[j, 1] = s[S_X]
    traj[j, 2] = s[S_Y]
    traj[j, 3] = s[S_VX]
    traj[j, 4] = s[S_VY]
    ev[j, 0] = s[S_TB]
    return sin_theta


@njit(cache=True, inline="always")
def load(st, ev):
    """The state tuple of the arrays ``st``, ``ev``."""
    return (st[0], st[5], st[1], st[2], st[3], st[4], ev[0])


@njit(cache=True, inline="always")
def store(st, ev, s):
    """Write the state tuple ``s`` back to ``st``, ``ev``."""
    st[0] = s[S_T]
    st[5] = s[S_COMP]
    st[1] = s[S_X]
    st[2] = s[S_Y]
    st[3] = s[S_VX]
    st[4] = s[S_VY]
    ev[0] = s[S_TB]


@njit(cache=True, inline="always")
def _to_kick(st, ev, dt, kick_time):
    """Fly ``dt`` to the kick and put the clock exactly on its time (the user's)."""
    store(st, ev, advance(load(st, ev), dt))
    st[0] = kick_time
    st[5] = 0.0


@njit(cache=True)
def kick_step(st, ev, dt, rho, kick_time, angle, kick_mode):
    """Fly ``dt`` to ``kick_time`` and apply a kick of ``angle`` (see `apply_kick`)."""
    _to_kick(st, ev, dt, kick_time)
    apply_kick(st, angle, kick_mode)
    ev[0] = geo.boundary_hit_time(st[1], st[2], st[3], st[4], rho)


@njit(cache=True)
def scatter_step(st, ev, dt, rho, kick_time, a, b, sp, out):
    """Fly ``dt`` to ``kick_time`` and apply a scattering kick (kicktimes.billiard.scatter).

    ``sp = [sigma = r0 + r1, rule code, e0, partner law code, rho1 = 1 - r1, m0, m1]``
    (`SCATTER_PARAMS`; the partner's radius ``r1`` and the normalised masses, ``m0 = m1 =
    1`` for equal ones); ``out`` receives the kick's log row (``runs.KICK_LOG_COLUMNS``).
    """
    _to_kick(st, ev, dt, kick_time)
    scatter_kick(st, a, b, sp[0], sp[4], int(sp[1]), sp[2], int(sp[3]), sp[5], sp[6], out)
    ev[0] = geo.boundary_hit_time(st[1], st[2], st[3], st[4], rho)


@njit(cache=True)
def twin_scatter_step(st, ev, dt, rho, kick_time, partner, sp):
    """Fly a Lyapunov twin ``dt`` to ``kick_time`` and let it meet the reference's partner.

    ``partner = [px, py, ux, uy]``: the partner's centre and velocity at the kick time,
    placed in contact with the reference (`kicktimes.billiard.scatter.twin_meets_partner`).
    Returns True if the twin hit the partner, False if it missed it (unchanged).
    """
    _to_kick(st, ev, dt, kick_time)
    x, y, vx, vy, hit = twin_meets_partner(st[1], st[2], st[3], st[4], partner[0], partner[1],
                                           partner[2], partner[3], sp[0], int(sp[1]), sp[6])
    st[1] = x
    st[2] = y
    st[3] = vx
    st[4] = vy
    st[6] = vx * vx + vy * vy
    ev[0] = geo.boundary_hit_time(x, y, vx, vy, rho)
    return hit


@njit(cache=True, inline="always")
def fly(s, t_end):
    """The state flown freely to ``t_end`` (no event before it), clock exactly ``t_end``."""
    t, comp, x, y, vx, vy, tb = s
    dt = t_end - t
    return (t_end, 0.0, x + vx * dt, y + vy * dt, vx, vy, tb - dt)


# --- the kicked disk in any table (kicktimes.billiard.kernels.tables) ----------------------
#
# The drivers take a table argument ``tab = (kind, p0, p1, p2, q0, q1, q2)`` or ``None``:
# ``None`` is the circle's code above, pruned at compile time, so the circle's loops keep
# their bits. ``(kind, p0, p1, p2)`` is the centre's curve of `kernels.tables` and
# ``(q0, q1, q2)`` the same table's curve for a scattering partner's centre (the radius
# ``r1``; only the kick log's "outside" flag reads it). In the table path the events array
# is ``ev = [tb, w1, w2]``: the time to the next contact and where it is (`tables.hit`),
# which the contact needs; a kick recomputes all three.

@njit(cache=True, inline="always")
def table_wall_event(tab, x, y, vx, vy, w1, w2, inv_v2):
    """Wall contact of the disk at ``(x, y)`` (advanced to the contact found by `tables.hit`,
    "where" ``(w1, w2)``) in the table ``tab``.

    The sequence of `kicktimes.billiard.kernels.drive_tables`: `tables.contact` puts the
    centre back on the wall, `tables.bounce` reflects (or lets a grazing disk slide on),
    one Newton step of ``|v'|^2`` towards the disk's squared speed ``1 / inv_v2`` keeps
    the speed, and `tables.hit` gives the next contact. Returns ``(x, y, vx, vy, tb, w1, w2,
    sin_theta, nx, ny, kappa)``: ``sin_theta = v.t / |v|`` of the incoming velocity, ``t =
    (-ny, nx)`` the counter-clockwise tangent (in the circle ``(x vy - y vx) / (rho |v|)``),
    ``n`` the outward normal and ``kappa`` the curvature of the centre's curve there (for
    the tangent map).
    """
    kind, p0, p1, p2 = tab[0], tab[1], tab[2], tab[3]
    x, y, nx, ny, kappa = tables.contact(kind, p0, p1, p2, x, y, vx, vy, w1, w2)
    sin_theta = (vy * nx - vx * ny) * math.sqrt(inv_v2)
    wx, wy = tables.bounce(vx, vy, nx, ny)
    f = 1.5 - 0.5 * (wx * wx + wy * wy) * inv_v2
    wx *= f
    wy *= f
    tb, w1, w2 = tables.hit(kind, p0, p1, p2, x, y, wx, wy)
    return x, y, wx, wy, tb, w1, w2, sin_theta, nx, ny, kappa


@njit(cache=True, inline="always")
def table_wall_step(s, dt, tab, w1, w2, inv_v2):
    """Fly ``dt`` to the wall of ``tab`` and reflect: ``(s, w1, w2, sin_theta, nx, ny,
    kappa)`` (see `table_wall_event`)."""
    t, comp, x, y, vx, vy, tb = advance(s, dt)
    x, y, vx, vy, tb, w1, w2, sin_theta, nx, ny, kappa = table_wall_event(
        tab, x, y, vx, vy, w1, w2, inv_v2)
    return (t, comp, x, y, vx, vy, tb), w1, w2, sin_theta, nx, ny, kappa


@njit(cache=True)
def table_hit(st, ev, tab):
    """``ev = [tb, w1, w2]`` of the state ``st`` in the table ``tab`` (`tables.hit`)."""
    ev[0], ev[1], ev[2] = tables.hit(tab[0], tab[1], tab[2], tab[3], st[1], st[2], st[3],
                                     st[4])


@njit(cache=True)
def process_table_wall_at(traj, ev, j, dt, tab):
    """`process_wall_at` in the table ``tab``: row ``j`` of ``traj`` (``[t, x, y, vx, vy,
    comp, v2]``, the speed kept at ``sqrt(v2)``) and of ``ev`` (``[tb, w1, w2]``)."""
    s = (traj[j, 0], traj[j, 5], traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4], ev[j, 0])
    s, w1, w2, sin_theta, _, _, _ = table_wall_step(s, dt, tab, ev[j, 1], ev[j, 2],
                                                    1.0 / traj[j, 6])
    traj[j, 0] = s[S_T]
    traj[j, 5] = s[S_COMP]
    traj[j, 1] = s[S_X]
    traj[j, 2] = s[S_Y]
    traj[j, 3] = s[S_VX]
    traj[j, 4] = s[S_VY]
    ev[j, 0] = s[S_TB]
    ev[j, 1] = w1
    ev[j, 2] = w2
    return sin_theta


@njit(cache=True)
def table_kick_step(st, ev, dt, tab, kick_time, angle, kick_mode):
    """`kick_step` in the table ``tab``: the next contact from `tables.hit`."""
    _to_kick(st, ev, dt, kick_time)
    apply_kick(st, angle, kick_mode)
    table_hit(st, ev, tab)


@njit(cache=True)
def table_outside(tab, x, y):
    """Whether a partner's centre ``(x, y)`` lies outside its room in the table ``tab``
    (the curve ``(kind, q0, q1, q2)`` of the partner's radius), to ``1e-12``."""
    kind, q0, q1, q2 = tab[0], tab[4], tab[5], tab[6]
    if kind == tables.CIRCLE:
        return x * x + y * y > q0 * q0
    if kind == tables.STADIUM:
        dx = max(abs(x) - q0, 0.0)
        return dx * dx + y * y > q1 * q1 * (1.0 + 2e-12)
    # the foot point's outward normal sees an inside point behind it (Ellipse.contains)
    c, s = tables.ellipse_parameter(x, y, q0, q1, q2)
    ih = 1.0 / math.sqrt(q1 * q1 * c * c + q0 * q0 * s * s)
    cx = (q0 - q2 * q1 * ih) * c
    cy = (q1 - q2 * q0 * ih) * s
    return (x - cx) * q1 * c * ih + (y - cy) * q0 * s * ih > 1e-12


@njit(cache=True)
def table_scatter_step(st, ev, dt, tab, kick_time, a, b, sp, out):
    """`scatter_step` in the table ``tab``: the partner's collision is the circle's (it
    needs no wall), its "outside" flag ``out[8]`` the table's (`table_outside`), the next
    contact from `tables.hit`. Under the mirror rule the squared speed ``st[6]`` the
    contacts keep stays the disk's initial one (the reflection off the partner rounds
    ``|v|`` by an ulp, a drift of 1e-11 over 10^5 kicks if it were the new anchor)."""
    _to_kick(st, ev, dt, kick_time)
    px = st[1]
    py = st[2]
    v2 = st[6]
    scatter_kick(st, a, b, sp[0], sp[4], int(sp[1]), sp[2], int(sp[3]), sp[5], sp[6], out)
    if sp[1] == 0.0:
        st[6] = v2
    px += sp[0] * out[4]
    py += sp[0] * out[5]
    out[8] = 1.0 if table_outside(tab, px, py) else 0.0
    table_hit(st, ev, tab)


@njit(cache=True)
def table_twin_scatter_step(st, ev, dt, tab, kick_time, partner, sp):
    """`twin_scatter_step` in the table ``tab`` (the next contact from `tables.hit`; the
    mirror rule keeps the anchor ``st[6]``, as `table_scatter_step`)."""
    _to_kick(st, ev, dt, kick_time)
    v2 = st[6]
    x, y, vx, vy, hit = twin_meets_partner(st[1], st[2], st[3], st[4], partner[0], partner[1],
                                           partner[2], partner[3], sp[0], int(sp[1]), sp[6])
    st[1] = x
    st[2] = y
    st[3] = vx
    st[4] = vy
    st[6] = v2 if sp[1] == 0.0 else vx * vx + vy * vy
    table_hit(st, ev, tab)
    return hit


@njit(cache=True)
def table_arc_lengths(kind, p0, p1, p2, x, y):
    """Arc length ``s`` along the centre's curve of each contact ``(x[i], y[i])``
    (`tables.boundary_coordinates`; ``s`` does not depend on the velocity)."""
    out = np.empty(x.shape[0])
    for i in range(x.shape[0]):
        out[i] = tables.boundary_coordinates(kind, p0, p1, p2, x[i], y[i], 1.0, 0.0)[0]
    return out
