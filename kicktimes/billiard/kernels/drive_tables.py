"""The free one-disk billiard in any table (`kicktimes.billiard.kernels.tables`), with its
tangent vector, and Benettin's renormalised twin for a cross-check.

The event is a wall contact: fly to it (``q += v t``, tangent ``dq += dv t``), put the
centre back on the wall (`tables.contact`), reflect (`tables.bounce`) and carry the tangent
vector across the reflection with the wall's local curvature
(`kicktimes.billiard.kernels.tangent.curved_wall_tangent`).

Status codes as in `kicktimes.billiard.kernels.tangent`: 0 ok, 2 more than
``MAX_SAME_INSTANT`` contacts at one instant, 3 a non-finite contact time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.kernels import tables
from kicktimes.billiard.kernels.tangent import BIG2, MAX_SAME_INSTANT, curved_wall_tangent

__all__ = ["free_kernel", "twin_kernel"]


@njit(cache=True)
def free_kernel(kind, p0, p1, p2, state, n_max, t_max, rec, u, tangent):
    """Run the disk ``state = [x, y, vx, vy]`` (updated in place) for ``n_max`` contacts or
    up to the time ``t_max``, whichever comes first (see `_free_loop`).

    One copy of the loop per table, its ``kind`` a constant: the compiler then drops the
    other tables' branches from the loop (a single loop dispatching on ``kind`` at every
    contact measured 1.5x slower in the ellipse, benchmarks/bench_tables.py).
    """
    if kind == tables.CIRCLE:
        return _free_loop(tables.CIRCLE, p0, p1, p2, state, n_max, t_max, rec, u, tangent)
    if kind == tables.STADIUM:
        return _free_loop(tables.STADIUM, p0, p1, p2, state, n_max, t_max, rec, u, tangent)
    return _free_loop(tables.ELLIPSE, p0, p1, p2, state, n_max, t_max, rec, u, tangent)


@njit(cache=True, inline="always")
def _free_loop(kind, p0, p1, p2, state, n_max, t_max, rec, u, tangent):
    """Run the disk ``state = [x, y, vx, vy]`` (updated in place) for ``n_max`` contacts or
    up to the time ``t_max``, whichever comes first.

    ``rec`` (``(m, 5)``): ``[t, x, y, vx, vy]`` of the first ``m`` contacts (the contact
    and the outgoing velocity). ``u`` (4,): the tangent vector ``(dq, dv)``, carried if
    ``tangent`` (updated in place, rescaled to norm 1 when it leaves ``[1e-100, 1e100]``).
    Returns ``(n, t, log_scale, status)``: contacts made, the end time, the sum of the logs
    of the rescalings (``log |u(t)| = log_scale + log |u|``).
    """
    x, y, vx, vy = state[0], state[1], state[2], state[3]
    inv_vv0 = 1.0 / (vx * vx + vy * vy)
    t = 0.0
    comp = 0.0
    log_scale = 0.0
    status = 0
    n_same = 0
    tb, w1, w2 = tables.hit(kind, p0, p1, p2, x, y, vx, vy)
    n = 0
    while n < n_max:
        if not (tb < math.inf):
            status = 3
            break
        if t + tb > t_max:
            dt = t_max - t
            x += vx * dt
            y += vy * dt
            if tangent:
                u[0] += u[2] * dt
                u[1] += u[3] * dt
            t = t_max
            break
        x += vx * tb
        y += vy * tb
        if tangent:
            u[0] += u[2] * tb
            u[1] += u[3] * tb
        yk = tb - comp
        tn = t + yk
        comp = (tn - t) - yk
        t = tn
        x, y, nx, ny, kappa = tables.contact(kind, p0, p1, p2, x, y, vx, vy, w1, w2)
        wx, wy = tables.bounce(vx, vy, nx, ny)
        # keep the speed: one Newton step of |w|^2 towards the initial |v|^2 (the normal's
        # rounding, e.g. of rho^2, is the same at every contact and would drift the speed)
        f = 1.5 - 0.5 * (wx * wx + wy * wy) * inv_vv0
        wx *= f
        wy *= f
        if tangent:
            a0, a1, a2, a3 = curved_wall_tangent(u[0], u[1], u[2], u[3], vx, vy, wx, wy,
                                                 nx, ny, kappa)
            u[0] = a0
            u[1] = a1
            u[2] = a2
            u[3] = a3
            s = a0 * a0 + a1 * a1 + a2 * a2 + a3 * a3
            if s > BIG2 or (s < 1.0 / BIG2 and s > 0.0):
                nrm = math.sqrt(s)
                log_scale += math.log(nrm)
                for i in range(4):
                    u[i] /= nrm
        vx = wx
        vy = wy
        if n < rec.shape[0]:
            rec[n, 0] = t
            rec[n, 1] = x
            rec[n, 2] = y
            rec[n, 3] = vx
            rec[n, 4] = vy
        n += 1
        tb, w1, w2 = tables.hit(kind, p0, p1, p2, x, y, vx, vy)
        if tb == 0.0:
            n_same += 1
            if n_same > MAX_SAME_INSTANT:
                status = 2
                break
        else:
            n_same = 0
    state[0] = x
    state[1] = y
    state[2] = vx
    state[3] = vy
    return n, t, log_scale, status


@njit(cache=True)
def _step(kind, p0, p1, p2, st, inv_vv0):
    """One contact of the disk ``st = [t, x, y, vx, vy, tb, w1, w2, n]`` (in place), its
    speed kept at ``1 / sqrt(inv_vv0)`` as in `free_kernel`."""
    tb = st[5]
    x = st[1] + st[3] * tb
    y = st[2] + st[4] * tb
    x, y, nx, ny, _ = tables.contact(kind, p0, p1, p2, x, y, st[3], st[4], st[6], st[7])
    vx, vy = tables.bounce(st[3], st[4], nx, ny)
    f = 1.5 - 0.5 * (vx * vx + vy * vy) * inv_vv0
    vx *= f
    vy *= f
    st[0] += tb
    st[1] = x
    st[2] = y
    st[3] = vx
    st[4] = vy
    st[5], st[6], st[7] = tables.hit(kind, p0, p1, p2, x, y, vx, vy)
    st[8] += 1.0


@njit(cache=True)
def _fly(st, dt):
    """Free flight of ``st`` for ``dt``, short of its next contact."""
    st[0] += dt
    st[1] += st[3] * dt
    st[2] += st[4] * dt
    st[5] -= dt


@njit(cache=True)
def twin_kernel(kind, p0, p1, p2, ref, twin, n_max, d0, every, max_defer):
    """Benettin's renormalised twin: the exponent's log sum over ``n_max`` contacts of the
    reference ``ref`` (``[t, x, y, vx, vy, tb, w1, w2, n]``, in place, as ``twin``).

    Every ``every`` contacts the reference flies half of its next free flight; the twin is
    advanced to the same instant, their phase-space distance ``d`` measured,
    ``log(d / d0)`` summed and the twin put back at ``d0`` along the difference (its speed
    set to the reference's). Sampling mid-flight keeps the pair away from a contact; if the
    twin has made another number of contacts (they straddle one) the renormalisation is
    deferred to the next sample, forced after ``max_defer`` deferrals. Returns
    ``(log_sum, t_last, n_last, n_forced, status)``, ``t_last`` the time of the last
    renormalisation and ``n_last`` the reference's contacts by then.
    """
    inv_vv0 = 1.0 / (ref[3] * ref[3] + ref[4] * ref[4])
    log_sum = 0.0
    t_last = 0.0
    n_last = 0.0
    n_forced = 0
    n_defer = 0
    status = 0
    for k in range(n_max):
        _step(kind, p0, p1, p2, ref, inv_vv0)
        if not (ref[5] < math.inf):
            status = 3
            break
        if (k + 1) % every != 0:
            continue
        _fly(ref, 0.5 * ref[5])
        target = ref[0]
        guard = 0
        while twin[0] + twin[5] <= target and guard < 1000:
            _step(kind, p0, p1, p2, twin, inv_vv0)
            guard += 1
        if guard >= 1000 or not (twin[5] < math.inf):
            status = 3
            break
        _fly(twin, target - twin[0])
        if twin[8] != ref[8] and n_defer < max_defer:
            n_defer += 1
            continue
        if twin[8] != ref[8]:
            n_forced += 1
            twin[8] = ref[8]
        n_defer = 0
        d2 = 0.0
        for i in range(1, 5):
            d2 += (twin[i] - ref[i]) ** 2
        d = math.sqrt(d2)
        log_sum += math.log(d / d0)
        f = d0 / d
        for i in range(1, 5):
            twin[i] = ref[i] + (twin[i] - ref[i]) * f
        sp = math.sqrt((ref[3] * ref[3] + ref[4] * ref[4]) / (twin[3] ** 2 + twin[4] ** 2))
        twin[3] *= sp
        twin[4] *= sp
        twin[0] = target
        twin[5], twin[6], twin[7] = tables.hit(kind, p0, p1, p2, twin[1], twin[2], twin[3],
                                               twin[4])
        t_last = target
        n_last = ref[8]
    return log_sum, t_last, n_last, n_forced, status


@njit(cache=True)
def twin_state(kind, p0, p1, p2, x, y, vx, vy):
    """The array ``[t, x, y, vx, vy, tb, w1, w2, n]`` of `twin_kernel` for a disk."""
    st = np.zeros(9)
    st[1] = x
    st[2] = y
    st[3] = vx
    st[4] = vy
    st[5], st[6], st[7] = tables.hit(kind, p0, p1, p2, x, y, vx, vy)
    return st
