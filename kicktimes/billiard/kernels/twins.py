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

Kicked twins share the reference's kick times and angles (common random numbers), or take
their own angles at the shared times (`ftle_one_kernel`'s ``twin_angles``).

The reference and every twin advance through the event steps of
`kicktimes.billiard.kernels.two` and `.one` in their array form (`two.process_event_at`,
`one.process_wall_at`, `one.kick_step`, ...), so they compute the bits the simulators do.
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

from kicktimes.billiard.geometry import boundary_hit_time
from kicktimes.billiard.kernels import one, two
from kicktimes.billiard.kernels.tangent import guard

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


# The per-sample work below is written out rather than calling a helper per sample: a numba
# call with array arguments (or an inlined helper taking arrays) costs about as much as the
# rest of a sample's work, and there are 25 000 samples per run. Array-taking kernels are
# called only per event.


@njit(cache=True)
def _ftle(st0, rho, mode, n_steps, tau, track, offsets, measure, d0, max_defer, max_events, pair,
          kick, kinetic, renorm, wall=None, table=None):
    """Benettin FTLE of either system: ``pair = (sigma, rule)`` for two disks (``kick`` is
    ``None``), ``kick = (kicks, angles, kick_mode, kick_u, sp)`` for the kicked disk
    (``pair`` is ``None``); the other system's code is compiled out. ``kinetic`` (or
    ``None``): kinetic kicks, whose times the reference writes into ``kicks`` as it applies
    them (`kicktimes.billiard.kernels.drive_one.drive`); the twins, which lag the reference
    within a sample, find them written.

    Row 0 of the trajectory arrays is the reference, rows ``1..m`` the twins: each sample
    first advances the reference (no flight on: its positions at ``t_k`` are interpolated),
    then each twin, flown on to ``t_k``, measured against it and renormalised.
    ``renorm=False``: the twins are never renormalised (eq. (4) of Ranković & Porter read
    literally): ``log_sum`` sums ``log(d_k / d0)`` over every sample ``k``, ``n_renorm``
    counts the samples, and a separation of exactly 0 makes the sum ``-inf``.
    ``wall`` (two disks only; ``None``: the unit circle): another table's ``(kind, p0, p1,
    p2)`` (`kicktimes.billiard.kernels.tables`), each row's next wall contacts' "where" in
    ``wh``. ``table`` (the kicked disk only): ``None``, the circle, or a table tuple of
    `kicktimes.billiard.kernels.one` (then ``ev`` rows are ``[tb, w1, w2]`` and every
    trajectory keeps its own speed ``sqrt(v2)`` at its contacts).
    """
    m = offsets.shape[0]
    nst = st0.shape[0]
    two_disks = kick is None
    n_disks = 2 if two_disks else 1
    o = 1 + 4 * track
    traj = np.empty((m + 1, nst))
    for j in range(m + 1):
        # element copy, not traj[j] = st0: numba compiles row assignment with a formatted
        # shape-mismatch message (seconds of compile time)
        for c in range(nst):
            traj[j, c] = st0[c]
        if j > 0:
            traj[j, o] += offsets[j - 1, 0]
            traj[j, o + 1] += offsets[j - 1, 1]
    # per trajectory: event times, and the event counts and hash of the sequence
    if pair is not None:
        sigma, rule = pair
        unit_speed = rule == 0
        ev = np.empty((m + 1, 3))
        cnt = np.zeros((m + 1, 5), dtype=np.int64)
        if wall is None:
            for j in range(m + 1):
                two.init_events(traj[j], ev[j], rho, sigma)
        else:
            wh = np.zeros((m + 1, 4))
            for j in range(m + 1):
                two.table_init_events(traj[j], ev[j], wh[j], rho, sigma, wall)
    if kick is not None:
        kicks, angles, kick_mode, kick_u, sp, twin_angles = kick
        nk = kicks.shape[0]
        own_angles = twin_angles.shape[0] > 0
        unit_speed = one.unit_speed_of(st0, kick_mode, sp)
        # the partner of each scattering kick: centre and velocity at the kick time
        partners = np.zeros((nk if kick_mode == one.SCATTER else 0, 4))
        row = np.empty(9)
        cnt = np.zeros((m + 1, 3), dtype=np.int64)
        if table is None:
            ev = np.empty((m + 1, 1))
            for j in range(m + 1):
                ev[j, 0] = boundary_hit_time(traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4],
                                             rho)
        else:
            ev = np.empty((m + 1, 3))
            for j in range(m + 1):
                one.table_hit(traj[j], ev[j], table)
        if kinetic is not None and nk > 0:
            kicks[0] = st0[0] + one.kinetic_delay(st0, kinetic[0][0], kinetic[1], kinetic[2],
                                                  kinetic[3], kinetic[4], kinetic[5])
    ref = traj[0]
    # the columns of ev that are times from now (a table's "where" is not)
    n_times = ev.shape[1]
    if table is not None:
        n_times = 1
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
        # (each system's code sits under a test of its own argument against None, which
        # numba resolves at compile time: the other system's code is not compiled)
        if mode == 1:
            tk = k * tau
        else:
            if pair is not None:
                dtn = min(ev[0, 0], min(ev[0, 1], ev[0, 2]))
            if kick is not None:
                # (as one.next_event, on the rows in place: a row view per event costs
                # reference counting)
                dtn = ev[0, 0]
                if cnt[0, 0] < nk and kicks[cnt[0, 0]] - ref[0] < dtn:
                    dtn = kicks[cnt[0, 0]] - ref[0]
            tk = min(t_prev + tau, ref[0] + dtn)
        for j in range(m + 1):
            # every event of trajectory j at a time <= tk
            while True:
                if pair is not None:
                    ke = 0
                    dt = ev[j, 0]
                    if ev[j, 1] < dt:
                        ke = 1
                        dt = ev[j, 1]
                    if ev[j, 2] < dt:
                        ke = 2
                        dt = ev[j, 2]
                if kick is not None:
                    ik = cnt[j, 0]
                    is_kick = False
                    dt = ev[j, 0]
                    if ik < nk and kicks[ik] - traj[j, 0] < dt:
                        is_kick = True
                        dt = kicks[ik] - traj[j, 0]
                if not traj[j, 0] + dt <= tk:
                    status = 3 if dt != dt else 0
                    break
                status, n_ev, n_same = guard(dt, n_ev, n_same, max_events)
                if status != 0:
                    break
                if pair is not None:
                    if wall is None:
                        two.process_event_at(traj, ev, j, ke, rho, sigma, rule)
                    else:
                        two.table_process_event_at(traj, ev, wh, j, ke, rho, sigma, rule, wall)
                    if ke == 2:
                        cnt[j, 0] += 1
                    else:
                        cnt[j, 1] += 1
                        cnt[j, 2 + ke] += 1
                    cnt[j, 4] = (cnt[j, 4] * 4 + ke + 1) % HASH_MOD
                if kick is not None and not is_kick:
                    # reference and twins reflect with the general-speed formula
                    if table is None:
                        one.process_wall_at(traj, ev, j, dt, rho, np.bool_(False))
                    else:
                        one.process_table_wall_at(traj, ev, j, dt, table)
                    cnt[j, 1] += 1
                    cnt[j, 2] = (cnt[j, 2] * 4 + 1) % HASH_MOD
                if kick is not None and is_kick:
                    hit = True
                    if kick_mode != one.SCATTER:
                        angle = angles[ik] if j == 0 or not own_angles else twin_angles[j - 1, ik]
                        if table is None:
                            one.kick_step(traj[j], ev[j], dt, rho, kicks[ik], angle, kick_mode)
                        else:
                            one.table_kick_step(traj[j], ev[j], dt, table, kicks[ik], angle,
                                                kick_mode)
                    elif j == 0:
                        if table is None:
                            one.scatter_step(traj[j], ev[j], dt, rho, kicks[ik], kick_u[ik, 0],
                                             kick_u[ik, 1], sp, row)
                        else:
                            one.table_scatter_step(traj[j], ev[j], dt, table, kicks[ik],
                                                   kick_u[ik, 0], kick_u[ik, 1], sp, row)
                        # the kick does not move the centre: the partner touches it along n
                        partners[ik, 0] = ref[1] + sp[0] * row[4]
                        partners[ik, 1] = ref[2] + sp[0] * row[5]
                        partners[ik, 2] = row[6]
                        partners[ik, 3] = row[7]
                    else:
                        # a missed partner is a different event sequence: defer, then force
                        if table is None:
                            hit = one.twin_scatter_step(traj[j], ev[j], dt, rho, kicks[ik],
                                                        partners[ik], sp)
                        else:
                            hit = one.table_twin_scatter_step(traj[j], ev[j], dt, table,
                                                              kicks[ik], partners[ik], sp)
                    if kinetic is not None and j == 0 and ik + 1 < nk:
                        kicks[ik + 1] = kicks[ik] + one.kinetic_delay(
                            ref, kinetic[0][ik + 1], kinetic[1], kinetic[2], kinetic[3],
                            kinetic[4], kinetic[5])
                    cnt[j, 0] += 1
                    cnt[j, 2] = (cnt[j, 2] * 4 + (4 if hit else 2)) % HASH_MOD
            if status != 0:
                break
            if j == 0:
                # the reference's centres at tk
                ds = tk - ref[0]
                for i in range(n_disks):
                    q = 1 + 4 * i
                    pos[2 * i] = ref[q] + ref[q + 2] * ds
                    pos[2 * i + 1] = ref[q + 1] + ref[q + 3] * ds
                continue
            # fly the twin on to tk
            dt = tk - traj[j, 0]
            for i in range(n_disks):
                q = 1 + 4 * i
                traj[j, q] += traj[j, q + 2] * dt
                traj[j, q + 1] += traj[j, q + 3] * dt
            for c in range(n_times):
                ev[j, c] -= dt
            traj[j, 0] = tk
            traj[j, nst - 2] = 0.0  # the clock's compensation
            d = _separation(traj[j, o] - pos[2 * track], traj[j, o + 1] - pos[2 * track + 1],
                            measure[j - 1])
            i = j - 1
            if not renorm:
                # the raw separation at this sample; the twin flies on unchanged
                log_sum[i] += math.log(d / d0) if d > 0.0 else -math.inf
                n_renorm[i] += 1
                t_last[i] = tk
                n_pert[i] = cnt[0, 0]
                continue
            same = True
            for c in range(cnt.shape[1]):
                if cnt[j, c] != cnt[0, c]:
                    same = False
            if not (d > 0.0 and (same or n_defer_now[i] >= max_defer)):
                n_defer_now[i] += 1
                n_deferred[i] += 1
                continue
            if not same:
                n_forced[i] += 1
                for c in range(cnt.shape[1]):
                    cnt[j, c] = cnt[0, c]
            log_sum[i] += math.log(d / m_plus[i])
            n_renorm[i] += 1
            t_last[i] = tk
            n_pert[i] = cnt[0, 0]
            n_defer_now[i] = 0
            # scale the whole difference by f, no component beyond d0
            big = d
            for i2 in range(n_disks):
                q = 1 + 4 * i2
                ex = traj[j, q] - pos[2 * i2]
                ey = traj[j, q + 1] - pos[2 * i2 + 1]
                big = max(big, math.sqrt(ex * ex + ey * ey))
            f = d0 / big
            m_plus[i] = d * f
            for i2 in range(n_disks):
                q = 1 + 4 * i2
                a, b, c2, d2 = _rescaled(traj[j, q], traj[j, q + 1], traj[j, q + 2],
                                         traj[j, q + 3], pos[2 * i2], pos[2 * i2 + 1],
                                         ref[q + 2], ref[q + 3], f, unit_speed)
                traj[j, q] = a
                traj[j, q + 1] = b
                traj[j, q + 2] = c2
                traj[j, q + 3] = d2
            if pair is not None:
                traj[j, 10] = two.pair_energy(traj[j, 3], traj[j, 4], traj[j, 7], traj[j, 8],
                                              rho[2], rho[3])
                if wall is None:
                    two.init_events(traj[j], ev[j], rho, sigma)
                else:
                    two.table_init_events(traj[j], ev[j], wh[j], rho, sigma, wall)
            if kick is not None and table is None:
                ev[j, 0] = boundary_hit_time(traj[j, 1], traj[j, 2], traj[j, 3], traj[j, 4],
                                             rho)
            if kick is not None and table is not None:
                # the twin's own speed is the one its contacts keep from now on
                traj[j, 6] = traj[j, 3] * traj[j, 3] + traj[j, 4] * traj[j, 4]
                one.table_hit(traj[j], ev[j], table)
        t_prev = tk
        if status != 0:
            break
    return log_sum, n_renorm, n_forced, n_deferred, t_last, n_pert, status


@njit(cache=True)
def ftle_two_kernel(st0, rho, sigma, rule, mode, n_steps, tau, track, offsets, measure, d0,
                    max_defer, max_events, renorm, wall=None):
    """Benettin FTLE for the two-disk billiard with ``len(offsets)`` twins (``renorm``:
    renormalise them, or measure the raw separations, see `_ftle`).

    Returns ``(log_sum, n_renorm, n_forced, n_deferred, t_last, n_pert, status)``; the
    first five per twin, ``n_pert[j]`` the reference's disk-disk collisions up to
    ``t_last[j]``. ``wall``: another table's ``(kind, p0, p1, p2)`` (``None``: the unit
    circle).
    """
    if wall is None:
        return _ftle(st0, rho, mode, n_steps, tau, track, offsets, measure, d0, max_defer,
                     max_events, (sigma, rule), None, None, renorm)
    return _ftle(st0, rho, mode, n_steps, tau, track, offsets, measure, d0, max_defer,
                 max_events, (sigma, rule), None, None, renorm, wall)


@njit(cache=True)
def ftle_one_kernel(st0, rho, kicks, angles, kick_mode, mode, n_steps, tau, offsets, measure, d0,
                    max_defer, max_events, kick_u, sp, kinetic, renorm, twin_angles, table=None):
    """Benettin FTLE for the kicked one-disk billiard.

    Twins share the kick times and angles (common random numbers), or, when
    ``twin_angles`` (shape ``(len(offsets), len(kicks))``) has rows, each twin takes its
    own angles at the shared times (not with scattering or kinetic kicks). Returns as
    `ftle_two_kernel`, ``n_pert`` counting the kicks applied. Scattering kicks
    (``kick_mode == 2``, numbers ``kick_u``, parameters ``sp`` as in
    `kicktimes.billiard.kernels.one.scatter_step`): the reference draws the partner, placed
    in contact with it, and every twin meets that same partner at its own contact time, or
    misses it. ``kinetic``: kinetic kicks or ``None`` (see `_ftle`); ``renorm``: as in
    `ftle_two_kernel`. ``table``: ``None`` (the circle) or a table tuple of
    `kicktimes.billiard.kernels.one` (the kicked disk in a stadium or an ellipse).
    """
    return _ftle(st0, rho, mode, n_steps, tau, 0, offsets, measure, d0, max_defer, max_events,
                 None, (kicks, angles, kick_mode, kick_u, sp, twin_angles), kinetic, renorm,
                 None, table)
