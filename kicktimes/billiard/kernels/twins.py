"""The twin driver: Benettin's twin-trajectory FTLE (``lyapunov(..., method="twin")``).

A twin starts ``d0`` away from the reference in the tracked disk's position. At every
sample time ``t_k`` the separation ``d_k`` of the tracked disk's centres is measured,
``log(d_k / d0)`` is added to a running sum and the twin's whole phase-space difference is
scaled by ``f = d0 / max(d_k, |dx_i| for every disk i)`` (positions of every disk;
velocity differences linearly, then renormalised to the rescaled speed, which scales the
velocity *angle* difference to first order). The guard in ``f`` never blows a component
up beyond ``d0``; the sum then telescopes over the actual growth factors
``log(d_k / d_{k-1}^+)``, ``d^+`` the separation right after the previous rescaling.

Billiard flows are discontinuous. When the reference and the twin straddle a collision
at ``t_k`` (one has processed it, the other not yet), the renormalisation is *deferred*
to the next sample at which both have processed the same sequence of events (event
counts and an order-sensitive hash). After ``max_defer`` consecutive deferrals it is
*forced* (the twin has left the reference) and its logarithm counted (``n_forced``).

Kicked twins share the reference's kick times and angles (common random numbers).

The reference and every twin advance through the event steps of
`kicktimes.billiard.kernels.two` and `.one` in their array form (`two.process_event`,
`one.process_wall`, `one.kick_step`, ...), so they compute the bits the simulators do.
The per-sample work (event selection, counters, renormalisation) is written out in each
kernel, on scalars and 2-D arrays indexed in place: a helper taking arrays, called per
sample and twin, costs numba's reference counting on every call (measured: 2-5x slower).

Every event loop has a budget: the kernels return a status (0 ok, 1 event budget
exhausted, 2 too many events at one instant, 3 a non-finite event time) for the Python
layer to turn into an error naming the input.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.geometry import boundary_hit_time, pair_hit_time
from kicktimes.billiard.kernels import one, two
from kicktimes.billiard.kernels.tangent import event_guard

__all__ = ["HASH_MOD", "ftle_one_kernel", "ftle_two_kernel"]

HASH_MOD = 2305843009213693951  # 2**61 - 1, keeps seq_hash * 8 inside int64


@njit(cache=True)
def _rescaled(x, y, vx, vy, px, py, vx_ref, vy_ref, f, unit_speed):
    """A twin disk scaled towards the reference disk (at ``px, py``) by ``f``.

    Positions scale linearly; the velocity difference scales linearly and the result is
    renormalised to the rescaled speed (first order: the angle difference scales by f).
    Scalar in, scalar out, so numba inlines it in the per-sample loop.
    """
    x = px + (x - px) * f
    y = py + (y - py) * f
    wx = vx_ref + (vx - vx_ref) * f
    wy = vy_ref + (vy - vy_ref) * f
    if unit_speed:
        speed = 1.0
    else:
        s_ref = math.sqrt(vx_ref * vx_ref + vy_ref * vy_ref)
        s_tw = math.sqrt(vx * vx + vy * vy)
        speed = s_ref + (s_tw - s_ref) * f
    norm = math.sqrt(wx * wx + wy * wy)
    if norm > 0.0:
        wx *= speed / norm
        wy *= speed / norm
    else:
        wx, wy = vx, vy
    return x, y, wx, wy


@njit(cache=True)
def _separation(dx, dy, measure):
    if measure == 0:
        return math.sqrt(dx * dx + dy * dy)
    if measure == 1:
        return abs(dx)
    return abs(dy)


# The per-sample loops below are written out rather than calling a helper per sample: a
# numba call with array arguments costs ~50 ns, as much as the rest of a sample's work,
# and there are 25 000 samples per run. Array-taking kernels are called only per event.


@njit(cache=True)
def ftle_two_kernel(st0, rho, sigma, rule, mode, n_steps, tau, track, offsets, measure, d0,
                    max_defer, max_events):
    """Benettin FTLE for the two-disk billiard with ``len(offsets)`` twins.

    Returns ``(log_sum, n_renorm, n_forced, n_deferred, t_last, n_pert, status)``; the
    first five per twin, ``n_pert[j]`` the reference's disk-disk collisions up to
    ``t_last[j]``.
    """
    m = offsets.shape[0]
    nst = st0.shape[0]
    ref = st0.copy()
    ev_ref = np.empty(3)
    two.init_events(ref, ev_ref, rho, sigma)
    cnt_ref = np.zeros(5, dtype=np.int64)
    tw = np.empty((m, nst))
    ev_tw = np.empty((m, 3))
    cnt_tw = np.zeros((m, 5), dtype=np.int64)
    o = 1 + 4 * track
    for j in range(m):
        # element copy, not tw[j] = st0: numba compiles row assignment with a formatted
        # shape-mismatch message (seconds of compile time)
        for c in range(st0.shape[0]):
            tw[j, c] = st0[c]
        tw[j, o] += offsets[j, 0]
        tw[j, o + 1] += offsets[j, 1]
        two.init_events(tw[j], ev_tw[j], rho, sigma)
    log_sum = np.zeros(m)
    n_renorm = np.zeros(m, dtype=np.int64)
    n_forced = np.zeros(m, dtype=np.int64)
    n_deferred = np.zeros(m, dtype=np.int64)
    n_defer_now = np.zeros(m, dtype=np.int64)
    t_last = np.zeros(m)
    m_plus = np.full(m, d0)  # measured separation right after the last renormalisation
    n_pert = np.zeros(m, dtype=np.int64)
    pos = np.empty(4)
    t_prev = 0.0
    n_ev = 0
    n_same = 0
    status = 0
    for k in range(1, n_steps + 1):
        if mode == 1:
            tk = k * tau
        else:
            tk = min(t_prev + tau, ref[0] + min(ev_ref[0], min(ev_ref[1], ev_ref[2])))
        # the reference: every event at time <= tk, no flight on (positions interpolated)
        while True:
            ke, dt = two.next_event(two.load(ref, ev_ref))
            if not ref[0] + dt <= tk:
                status = 3 if dt != dt else 0
                break
            n_ev += 1
            if dt > 0.0 and n_ev <= max_events:
                n_same = 0
            else:
                status, n_same = event_guard(dt, n_ev, np.int64(n_same), max_events)
                if status != 0:
                    break
            two.process_event(ref, ev_ref, ke, rho, sigma, rule)
            if ke == 2:
                cnt_ref[0] += 1
            else:
                cnt_ref[1] += 1
                cnt_ref[2 + ke] += 1
            cnt_ref[4] = (cnt_ref[4] * 4 + ke + 1) % HASH_MOD
        if status != 0:
            break
        ds = tk - ref[0]
        for i in range(2):
            q = 1 + 4 * i
            pos[2 * i] = ref[q] + ref[q + 2] * ds
            pos[2 * i + 1] = ref[q + 1] + ref[q + 3] * ds
        for j in range(m):
            while True:
                ke = 0
                dt = ev_tw[j, 0]
                if ev_tw[j, 1] < dt:
                    ke = 1
                    dt = ev_tw[j, 1]
                if ev_tw[j, 2] < dt:
                    ke = 2
                    dt = ev_tw[j, 2]
                if not tw[j, 0] + dt <= tk:
                    status = 3 if dt != dt else 0
                    break
                n_ev += 1
                if dt > 0.0 and n_ev <= max_events:
                    n_same = 0
                else:
                    status, n_same = event_guard(dt, n_ev, np.int64(n_same), max_events)
                    if status != 0:
                        break
                two.process_event(tw[j], ev_tw[j], ke, rho, sigma, rule)
                if ke == 2:
                    cnt_tw[j, 0] += 1
                else:
                    cnt_tw[j, 1] += 1
                    cnt_tw[j, 2 + ke] += 1
                cnt_tw[j, 4] = (cnt_tw[j, 4] * 4 + ke + 1) % HASH_MOD
            if status != 0:
                break
            # fly the twin on to tk
            dt = tk - tw[j, 0]
            tw[j, 1] += tw[j, 3] * dt
            tw[j, 2] += tw[j, 4] * dt
            tw[j, 5] += tw[j, 7] * dt
            tw[j, 6] += tw[j, 8] * dt
            ev_tw[j, 0] -= dt
            ev_tw[j, 1] -= dt
            ev_tw[j, 2] -= dt
            tw[j, 0] = tk
            tw[j, 9] = 0.0
            d = _separation(tw[j, o] - pos[2 * track], tw[j, o + 1] - pos[2 * track + 1],
                            measure[j])
            same = True
            for c in range(5):
                if cnt_tw[j, c] != cnt_ref[c]:
                    same = False
            if d > 0.0 and (same or n_defer_now[j] >= max_defer):
                if not same:
                    n_forced[j] += 1
                    for c in range(5):
                        cnt_tw[j, c] = cnt_ref[c]
                log_sum[j] += math.log(d / m_plus[j])
                n_renorm[j] += 1
                t_last[j] = tk
                n_pert[j] = cnt_ref[0]
                n_defer_now[j] = 0
                big = d
                for i in range(2):
                    q = 1 + 4 * i
                    ex = tw[j, q] - pos[2 * i]
                    ey = tw[j, q + 1] - pos[2 * i + 1]
                    big = max(big, math.sqrt(ex * ex + ey * ey))
                f = d0 / big
                m_plus[j] = d * f
                for i in range(2):
                    q = 1 + 4 * i
                    a, b, c2, d2 = _rescaled(tw[j, q], tw[j, q + 1], tw[j, q + 2], tw[j, q + 3],
                                             pos[2 * i], pos[2 * i + 1], ref[q + 2], ref[q + 3],
                                             f, rule == 0)
                    tw[j, q] = a
                    tw[j, q + 1] = b
                    tw[j, q + 2] = c2
                    tw[j, q + 3] = d2
                tw[j, 10] = (tw[j, 3] * tw[j, 3] + tw[j, 4] * tw[j, 4] + tw[j, 7] * tw[j, 7]
                             + tw[j, 8] * tw[j, 8])
                ev_tw[j, 0] = boundary_hit_time(tw[j, 1], tw[j, 2], tw[j, 3], tw[j, 4], rho)
                ev_tw[j, 1] = boundary_hit_time(tw[j, 5], tw[j, 6], tw[j, 7], tw[j, 8], rho)
                ev_tw[j, 2] = pair_hit_time(tw[j, 1] - tw[j, 5], tw[j, 2] - tw[j, 6],
                                            tw[j, 3] - tw[j, 7], tw[j, 4] - tw[j, 8], sigma)
            else:
                n_defer_now[j] += 1
                n_deferred[j] += 1
        t_prev = tk
        if status != 0:
            break
    return log_sum, n_renorm, n_forced, n_deferred, t_last, n_pert, status


@njit(cache=True)
def ftle_one_kernel(st0, rho, kicks, angles, kick_mode, mode, n_steps, tau, offsets, measure, d0,
                    max_defer, max_events, kick_u, sp):
    """Benettin FTLE for the kicked one-disk billiard.

    Twins share the kick times and angles (common random numbers). Returns as
    `ftle_two_kernel`, ``n_pert`` counting the kicks applied. Scattering kicks
    (``kick_mode == 2``, numbers ``kick_u``, parameters ``sp`` as in
    `kicktimes.billiard.kernels.one.scatter_step`): the reference draws the partner, placed
    in contact with it, and every twin meets that same partner at its own contact time, or
    misses it.
    """
    m = offsets.shape[0]
    nk = kicks.shape[0]
    scatter = kick_mode == one.SCATTER
    unit_speed = (abs(st0[3] * st0[3] + st0[4] * st0[4] - 1.0) < 1e-12
                  and not (scatter and sp[1] != 0.0))
    # the reference and the twins reflect with the general-speed formula (np.bool_: a bool
    # variable, not the literal False, so that wall_one compiles one signature)
    no_shortcut = np.bool_(False)
    # the partner of each scattering kick: centre and velocity at the kick time
    partners = np.zeros((nk if scatter else 0, 4))
    row = np.empty(9)
    ref = st0.copy()
    ev_ref = np.empty(1)
    ev_ref[0] = boundary_hit_time(ref[1], ref[2], ref[3], ref[4], rho)
    cnt_ref = np.zeros(3, dtype=np.int64)
    tw = np.empty((m, st0.shape[0]))
    ev_tw = np.empty((m, 1))
    cnt_tw = np.zeros((m, 3), dtype=np.int64)
    for j in range(m):
        # element copy, not tw[j] = st0: numba compiles row assignment with a formatted
        # shape-mismatch message (seconds of compile time)
        for c in range(st0.shape[0]):
            tw[j, c] = st0[c]
        tw[j, 1] += offsets[j, 0]
        tw[j, 2] += offsets[j, 1]
        ev_tw[j, 0] = boundary_hit_time(tw[j, 1], tw[j, 2], tw[j, 3], tw[j, 4], rho)
    log_sum = np.zeros(m)
    n_renorm = np.zeros(m, dtype=np.int64)
    n_forced = np.zeros(m, dtype=np.int64)
    n_deferred = np.zeros(m, dtype=np.int64)
    n_defer_now = np.zeros(m, dtype=np.int64)
    t_last = np.zeros(m)
    m_plus = np.full(m, d0)
    n_pert = np.zeros(m, dtype=np.int64)
    t_prev = 0.0
    n_ev = 0
    n_same = 0
    status = 0
    for k in range(1, n_steps + 1):
        if mode == 1:
            tk = k * tau
        else:
            _, dtn = one.next_event(one.load(ref, ev_ref), kicks, cnt_ref[0])
            tk = min(t_prev + tau, ref[0] + dtn)
        while True:
            ik = cnt_ref[0]
            is_kick = False
            dt = ev_ref[0]
            if ik < nk and kicks[ik] - ref[0] < dt:
                is_kick = True
                dt = kicks[ik] - ref[0]
            if not ref[0] + dt <= tk:
                status = 3 if dt != dt else 0
                break
            n_ev += 1
            if dt > 0.0 and n_ev <= max_events:
                n_same = 0
            else:
                status, n_same = event_guard(dt, n_ev, np.int64(n_same), max_events)
                if status != 0:
                    break
            if is_kick and scatter:
                one.scatter_step(ref, ev_ref, dt, rho, kicks[ik], kick_u[ik, 0],
                                    kick_u[ik, 1], sp, row)
                # the kick does not move the centre: the partner touches it along n
                partners[ik, 0] = ref[1] + sp[0] * row[4]
                partners[ik, 1] = ref[2] + sp[0] * row[5]
                partners[ik, 2] = row[6]
                partners[ik, 3] = row[7]
                cnt_ref[0] += 1
                cnt_ref[2] = (cnt_ref[2] * 4 + 4) % HASH_MOD
            elif is_kick:
                one.kick_step(ref, ev_ref, dt, rho, kicks[ik], angles[ik], kick_mode)
                cnt_ref[0] += 1
                cnt_ref[2] = (cnt_ref[2] * 4 + 4) % HASH_MOD
            else:
                one.process_wall(ref, ev_ref, dt, rho, no_shortcut)
                cnt_ref[1] += 1
                cnt_ref[2] = (cnt_ref[2] * 4 + 1) % HASH_MOD
        if status != 0:
            break
        ds = tk - ref[0]
        px = ref[1] + ref[3] * ds
        py = ref[2] + ref[4] * ds
        for j in range(m):
            while True:
                ik = cnt_tw[j, 0]
                is_kick = False
                dt = ev_tw[j, 0]
                if ik < nk and kicks[ik] - tw[j, 0] < dt:
                    is_kick = True
                    dt = kicks[ik] - tw[j, 0]
                if not tw[j, 0] + dt <= tk:
                    status = 3 if dt != dt else 0
                    break
                n_ev += 1
                if dt > 0.0 and n_ev <= max_events:
                    n_same = 0
                else:
                    status, n_same = event_guard(dt, n_ev, np.int64(n_same), max_events)
                    if status != 0:
                        break
                if is_kick and scatter:
                    hit = one.twin_scatter_step(tw[j], ev_tw[j], dt, rho, kicks[ik],
                                                   partners[ik], sp)
                    cnt_tw[j, 0] += 1
                    # a missed partner is a different event sequence: defer, then force
                    cnt_tw[j, 2] = (cnt_tw[j, 2] * 4 + (4 if hit else 2)) % HASH_MOD
                elif is_kick:
                    one.kick_step(tw[j], ev_tw[j], dt, rho, kicks[ik], angles[ik], kick_mode)
                    cnt_tw[j, 0] += 1
                    cnt_tw[j, 2] = (cnt_tw[j, 2] * 4 + 4) % HASH_MOD
                else:
                    one.process_wall(tw[j], ev_tw[j], dt, rho, no_shortcut)
                    cnt_tw[j, 1] += 1
                    cnt_tw[j, 2] = (cnt_tw[j, 2] * 4 + 1) % HASH_MOD
            if status != 0:
                break
            dt = tk - tw[j, 0]
            tw[j, 1] += tw[j, 3] * dt
            tw[j, 2] += tw[j, 4] * dt
            ev_tw[j, 0] -= dt
            tw[j, 0] = tk
            tw[j, 5] = 0.0
            d = _separation(tw[j, 1] - px, tw[j, 2] - py, measure[j])
            same = (cnt_tw[j, 0] == cnt_ref[0] and cnt_tw[j, 1] == cnt_ref[1]
                    and cnt_tw[j, 2] == cnt_ref[2])
            if d > 0.0 and (same or n_defer_now[j] >= max_defer):
                if not same:
                    n_forced[j] += 1
                    for c in range(3):
                        cnt_tw[j, c] = cnt_ref[c]
                log_sum[j] += math.log(d / m_plus[j])
                n_renorm[j] += 1
                t_last[j] = tk
                n_pert[j] = cnt_ref[0]
                n_defer_now[j] = 0
                ex = tw[j, 1] - px
                ey = tw[j, 2] - py
                f = d0 / max(d, math.sqrt(ex * ex + ey * ey))
                m_plus[j] = d * f
                a, b, c2, d2 = _rescaled(tw[j, 1], tw[j, 2], tw[j, 3], tw[j, 4], px, py, ref[3],
                                         ref[4], f, unit_speed)
                tw[j, 1] = a
                tw[j, 2] = b
                tw[j, 3] = c2
                tw[j, 4] = d2
                ev_tw[j, 0] = boundary_hit_time(a, b, c2, d2, rho)
            else:
                n_defer_now[j] += 1
                n_deferred[j] += 1
        t_prev = tk
        if status != 0:
            break
    return log_sum, n_renorm, n_forced, n_deferred, t_last, n_pert, status


