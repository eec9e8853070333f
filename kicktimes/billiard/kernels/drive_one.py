"""The kicked-disk driver: one event loop, with the observers a caller switches on.

As `kicktimes.billiard.kernels.drive_two`, for the event step of
`kicktimes.billiard.kernels.one`: the **simulation** (``cnt[SIM_ON]``: samples, boundary
log, the kicks applied and the scattering kicks' log) and the **tangent vectors** (``tan``,
or ``None``, compiled out) share one event sequence. Entry points:
`simulate_one_kernel`, `simulate_tangent_one_kernel` (the one pass) and
`tangent_one_kernel` (the FTLE alone).

Boundary collisions, the frequent events, run on a tuple of locals (registers) and touch
no array but the output; a kick writes the state back to ``st``, applies the kick there
(`kick_step`, `scatter_step`) and reloads it. Only boundary collisions count towards a
stall (`kicktimes.billiard.kernels.observe.stalled`): simultaneous kicks are the user's and
there are finitely many.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kicktimes.billiard import geometry as geo
from kicktimes.billiard.kernels import observe as ob
from kicktimes.billiard.kernels import one
from kicktimes.billiard.kernels import tangent as tg
from kicktimes.billiard.scatter import scatter_tangent

__all__ = ["drive", "simulate_one_kernel", "simulate_tangent_one_kernel", "tangent_one_kernel"]

# the int64 carry array ``cnt`` of the loop, and the tangent half's ``tgi`` and ``tgf``
N_KICKS, N_B, K, SIM_ON, N_KICKS_RUN = range(5)


@njit(cache=True)
def drive(st, ev, rho, kicks, angles, kick_mode, kick_u, sp, unit_speed, t_end, mode, tau, logs,
          stimes, samples, cnt, next_s, fin, tan, kinetic, holes, uni=None, table=None):
    """Run the event loop from ``st``/``ev``; returns `ob.DONE`, or `ob.FULL` when the boundary
    log is full (see `kicktimes.billiard.kernels.drive_two.drive`).

    Kicks at ``kicks`` (sorted) with ``angles``; scattering kicks (``kick_mode ==
    one.SCATTER``) take ``kick_u[i]`` and ``sp`` and log to ``klog[i]``.
    ``logs = (bt, bx, by, bs, klog)``; ``fin = [t_end, x, y, vx, vy]``, the run's final
    state; ``tan = (U, log_scale, tgi, tgf, max_events, n_orth, n_steps)`` or ``None``.
    ``kinetic = (e, rates, l_first, dl, c_first, dc)`` or ``None``: kinetic kicks, whose
    times the loop writes into ``kicks`` as it goes: after kick ``i`` the next comes
    `one.kinetic_delay` later, with the number ``e[i + 1]``. ``holes = (arcs, escape)`` or
    ``None``: the table's holes, and ``uni`` (or ``None``) the uniform samples of a
    paper-sampled run, both as in `kicktimes.billiard.kernels.drive_two.drive`.
    ``table``: ``None`` (the circle ``|q| = rho``, the code the loop always had) or a
    table tuple ``(kind, p0, p1, p2, q0, q1, q2)`` (`kicktimes.billiard.kernels.one`,
    "the kicked disk in any table"), with ``ev = [tb, w1, w2]``: its wall contacts go
    through `one.table_wall_step` and the tangent map through
    `tangent.curved_wall_tangent` with the contact's normal and curvature.
    """
    bt, bx, by, bs, klog = logs
    s = one.load(st, ev)
    ik = cnt[N_KICKS]
    n_b = cnt[N_B]
    k = cnt[K]
    if tan is None:
        sim_on = True
        tan_on = False
    else:
        sim_on = cnt[SIM_ON] != 0
        tan_on = tan[2][tg.TAN_ON] != 0
        U, log_scale, tgi, tgf, max_ev_tan, n_orth, n_steps = tan
        m = U.shape[0]
        i_loop, n_loop, n_ev, n_same, n_resc, n_pert, tk, t_prev, tan_code = tg.load_carry(
            tgi, tgf)
    uni_on = False
    if uni is not None:
        u_times, u_samples, ku, uni_on, u_limit = ob.load_uniform(uni)
    w1 = 0.0
    w2 = 0.0
    inv_v2 = 0.0
    if table is not None:
        # the hit's "where" and the squared speed the contacts keep
        w1 = ev[1]
        w2 = ev[2]
        inv_v2 = 1.0 / st[6]
    scatter = kick_mode == one.SCATTER
    nk = kicks.shape[0]
    ns = stimes.shape[0]
    b_cap = bt.shape[0]
    ns_next = next_s[0]
    status = ob.FULL
    while True:
        is_kick, dte = one.next_event(s, one.next_kick(kicks, ik))
        t = s[one.S_T]
        if sim_on:
            k, ns_next = ob.sample_flight(stimes, samples, k, ns_next, t, dte, s[one.S_X],
                                       s[one.S_Y], s[one.S_VX], s[one.S_VY], mode, tau)
            if (mode == 2 and k >= ns) or t + dte > t_end:
                sim_on = False
                cnt[N_KICKS_RUN] = ik
                if mode == 2:
                    t_end = stimes[ns - 1]
                f = one.fly(s, t_end)
                fin[0] = t_end
                fin[1] = f[one.S_X]
                fin[2] = f[one.S_Y]
                fin[3] = f[one.S_VX]
                fin[4] = f[one.S_VY]
            elif (holes is not None and not is_kick
                  and ob.in_hole(s[one.S_X] + s[one.S_VX] * dte, s[one.S_Y] + s[one.S_VY] * dte,
                                 holes[0])):
                # the disk escapes at this wall contact: the run ends there
                sim_on = False
                cnt[N_KICKS_RUN] = ik
                f = one.advance(s, dte)
                t_end = f[one.S_T]
                holes[1][0] = t_end
                holes[1][1] = 0.0
                fin[0] = t_end
                fin[1] = f[one.S_X]
                fin[2] = f[one.S_Y]
                fin[3] = f[one.S_VX]
                fin[4] = f[one.S_VY]
                if tan is not None and tan_on:
                    # the tangent vectors end with the run: the FTLE up to the escape
                    tg.end_step(U, log_scale, t_end - t, n_orth)
                    t_prev = t_end
                    tan_on = False
        if uni is not None and uni_on:
            # the uniform samples of the same flight (see drive_two.drive)
            ku, u_limit, uni_on = ob.sample_uniform_flight(
                u_times, u_samples, ku, u_limit, uni_on, sim_on, t, dte, s[one.S_X], s[one.S_Y],
                s[one.S_VX], s[one.S_VY], tau, fin[0])
        if tan is not None:
            # the tangent vectors' step ends before the next event
            # (the kicked disk's tangent vectors have one step in mode 1: no Gram-Schmidt,
            # and a later step ends at min(t_prev + tau, next event))
            while tan_on and not t + dte <= tk:
                if dte != dte:
                    tan_code = 3
                    tan_on = False
                    break
                t_prev = tk
                i_loop += 1
                if i_loop == n_loop:
                    # no Gram-Schmidt (an int64, not a literal 0: a literal would
                    # compile end_step a second time)
                    tg.end_step(U, log_scale, t_prev - t, np.int64(0))
                    tan_on = False
                    break
                tk = min(t_prev + tau, t + dte)
        if not (sim_on or tan_on or uni_on):
            status = ob.DONE
            break
        if not is_kick and sim_on and n_b >= b_cap:
            break
        if tan is not None and tan_on:
            tan_code, n_ev, n_same = tg.guard(dte, n_ev, n_same, max_ev_tan)
            tan_on = tan_code == 0
            if tan_on:
                tg.tangent_flight(U, dte)
        ux = s[one.S_VX]
        uy = s[one.S_VY]
        if is_kick:
            one.store(st, ev, s)
            if scatter:
                row = klog[ik]
                if table is None:
                    one.scatter_step(st, ev, dte, rho, kicks[ik], kick_u[ik, 0], kick_u[ik, 1],
                                     sp, row)
                else:
                    one.table_scatter_step(st, ev, dte, table, kicks[ik], kick_u[ik, 0],
                                           kick_u[ik, 1], sp, row)
                # (a partner missed by round-off leaves the disk and the vectors unchanged)
                if tan is not None and tan_on and (row[4] != 0.0 or row[5] != 0.0):
                    for j in range(m):
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3] = scatter_tangent(
                            ux, uy, row[6], row[7], row[4], row[5], sp[0], int(sp[1]), sp[6],
                            U[j, 0], U[j, 1], U[j, 2], U[j, 3])
                        n_resc += tg.renormalize(U, log_scale, j)
            else:
                if table is None:
                    one.kick_step(st, ev, dte, rho, kicks[ik], angles[ik], kick_mode)
                else:
                    one.table_kick_step(st, ev, dte, table, kicks[ik], angles[ik], kick_mode)
                if tan is not None and tan_on:
                    for j in range(m):
                        U[j, 2], U[j, 3] = tg.kick_tangent(U[j, 2], U[j, 3], ux, uy, st[3], st[4],
                                                           angles[ik], kick_mode)
                        n_resc += tg.renormalize(U, log_scale, j)
            s = one.load(st, ev)
            if table is not None:
                w1 = ev[1]
                w2 = ev[2]
                inv_v2 = 1.0 / st[6]
            if tan is not None and tan_on:
                n_pert += 1
            if kinetic is not None and ik + 1 < nk:
                kicks[ik + 1] = kicks[ik] + one.kinetic_delay(
                    st, kinetic[0][ik + 1], kinetic[1], kinetic[2], kinetic[3], kinetic[4],
                    kinetic[5])
            ik += 1
        elif table is None:
            s, sin_theta = one.wall_step(s, dte, rho, unit_speed)
            if tan is not None and tan_on and (ux != s[one.S_VX] or uy != s[one.S_VY]):
                for j in range(m):
                    U[j, 0], U[j, 1], U[j, 2], U[j, 3] = tg.wall_tangent(
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3], s[one.S_X], s[one.S_Y], ux, uy,
                        s[one.S_VX], s[one.S_VY], rho)
            if sim_on:
                bs[n_b] = sin_theta
                bt[n_b] = s[one.S_T]
                bx[n_b] = s[one.S_X]
                by[n_b] = s[one.S_Y]
                n_b += 1
        else:
            s, w1, w2, sin_theta, nx, ny, kappa = one.table_wall_step(s, dte, table, w1, w2,
                                                                     inv_v2)
            if tan is not None and tan_on and (ux != s[one.S_VX] or uy != s[one.S_VY]):
                for j in range(m):
                    U[j, 0], U[j, 1], U[j, 2], U[j, 3] = tg.curved_wall_tangent(
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3], ux, uy, s[one.S_VX], s[one.S_VY],
                        nx, ny, kappa)
                    # a chaotic table stretches at every contact, not only at kicks (the
                    # norm tested on scalars: renormalize's array argument costs reference
                    # counting at every contact)
                    nn = (U[j, 0] * U[j, 0] + U[j, 1] * U[j, 1] + U[j, 2] * U[j, 2]
                          + U[j, 3] * U[j, 3])
                    if nn > tg.BIG2 or (nn < 1.0 / tg.BIG2 and nn > 0.0):
                        n_resc += tg.renormalize(U, log_scale, j)
            if sim_on:
                bs[n_b] = sin_theta
                bt[n_b] = s[one.S_T]
                bx[n_b] = s[one.S_X]
                by[n_b] = s[one.S_Y]
                n_b += 1
        if sim_on and mode == 2 and k < ns:
            k, ns_next = ob.sample_at_event(stimes, samples, k, s[one.S_T], s[one.S_X], s[one.S_Y],
                                         tau)
    one.store(st, ev, s)
    if table is not None:
        ev[1] = w1
        ev[2] = w2
    cnt[N_KICKS] = ik
    cnt[N_B] = n_b
    cnt[K] = k
    cnt[SIM_ON] = 1 if sim_on else 0
    next_s[0] = ns_next
    if uni is not None:
        ob.store_uniform(uni, ku, uni_on, u_limit)
    if tan is not None:
        tg.store_carry(tgi, tgf, tan_on, i_loop, n_ev, n_same, n_resc, n_pert, tk, t_prev,
                       tan_code)
    return status


@njit(cache=True)
def _run(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap, kick_u, sp,
         max_events, stall_dt, sim, tan, kinetic, holes, uni=None, table=None):
    """Allocate the logs, run `drive` to its end, growing the boundary log when full.

    With ``kinetic`` (see `drive`) the first kick's time is set here, from the initial
    state; ``kicks`` must then be a writable buffer, one entry per number in ``e``.

    ``table``: see `drive` (``None``: the circle).

    Returns ``(logs, stimes, samples, cnt, fin, tan, status)``.
    """
    if table is None:
        ev = np.empty(1)
        ev[0] = geo.boundary_hit_time(st[1], st[2], st[3], st[4], rho)
    else:
        ev = np.empty(3)
        one.table_hit(st, ev, table)
    if kinetic is not None and kicks.shape[0] > 0:
        kicks[0] = st[0] + one.kinetic_delay(st, kinetic[0][0], kinetic[1], kinetic[2],
                                             kinetic[3], kinetic[4], kinetic[5])
    unit_speed = one.unit_speed_of(st, kick_mode, sp)
    klog = np.zeros((kicks.shape[0] if kick_mode == one.SCATTER else 0, 9))
    bt, bx, by, bs = ob.new_boundary_log(min(b_cap, max_events + 1) if sim else 0)
    stimes, samples = ob.new_samples(n_steps + 1 if mode > 0 and sim else 0)
    cnt = np.zeros(5, dtype=np.int64)
    cnt[SIM_ON] = 1 if sim else 0
    next_s = np.zeros(1)
    fin = np.empty(5)
    if tan is not None:
        tg.start(tan, mode, n_steps, tau,
                 st[0] + one.next_event(one.load(st, ev), one.next_kick(kicks, 0))[1])
    t_end = t_max if mode < 2 else np.inf
    status = ob.DONE
    while True:
        loop = drive(st, ev, rho, kicks, angles, kick_mode, kick_u, sp, unit_speed, t_end, mode,
                     tau, (bt, bx, by, bs, klog), stimes, samples, cnt, next_s, fin, tan,
                     kinetic, holes, uni, table)
        if loop == ob.DONE:
            break
        # a full boundary log
        if ob.stalled(bt, cnt[N_B], stall_dt):
            status = ob.STALLED
            break
        room = max_events - cnt[N_B]
        if room <= 0:
            status = ob.OVER_BUDGET
            break
        bt, bx, by, bs = ob.grow_boundary_log(bt, bx, by, bs, bt.shape[0] + room)
    if status == ob.DONE and ob.stalled(bt, cnt[N_B], stall_dt):
        status = ob.STALLED
    if sim and status == ob.DONE:
        for i in range(5):
            st[i] = fin[i]
        st[5] = 0.0
    return (bt, bx, by, bs, klog), stimes, samples, cnt, fin, tan, status


@njit(cache=True)
def simulate_one_kernel(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap,
                        kick_u, sp, max_events, stall_dt, kinetic=None, holes=None, table=None):
    """Run the kicked one-disk billiard (``mode``: 0 none, 1 uniform, 2 paper sampling).

    ``st`` is ``[t, x, y, vx, vy, clock compensation, squared speed]``. Scattering kicks
    (``kick_mode == 2``) take their random numbers from ``kick_u`` (shape (n_kicks, 2))
    and their parameters from ``sp`` (see `kicktimes.billiard.kernels.one.scatter_step`).
    Stops early with status `ob.OVER_BUDGET` after ``max_events`` boundary collisions or
    `ob.STALLED`. Returns ``(b_time, b_x, b_y, b_sin, sample_times, samples,
    n_kicks_applied, t_end, kick_log, status)``; ``kick_log`` has one row per applied
    scattering kick (else none). ``kinetic``: kinetic kicks (see `drive`), whose times the
    run writes into ``kicks``. ``holes``: the table's holes (rows ``[centre angle,
    half-width]``, or ``None``); then an 11th item ``escape = [t, 0]`` (``[inf, -1]``: no
    escape), and the run ends at the escape. ``table``: ``None`` (the circle) or a table
    tuple (see `drive`; not with holes or kinetic kicks).
    """
    return _simulate(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap, kick_u,
                     sp, max_events, stall_dt, None, kinetic, holes, None, table)[0]


@njit(cache=True)
def _simulate(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap, kick_u, sp,
              max_events, stall_dt, tan, kinetic, holes, uni=None, table=None):
    """`_run` with the simulation on, and its output as `simulate_one_kernel` returns it;
    also the tangent half (``tan``, or ``None``); ``uni``: see `drive` (not with holes)."""
    escape = np.array([np.inf, -1.0])
    # (two calls, not a conditional argument: numba compiles the holes out when absent)
    if holes is None:
        logs, stimes, samples, cnt, fin, tan, status = _run(
            st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap, kick_u, sp,
            max_events, stall_dt, True, tan, kinetic, None, uni, table)
    else:
        logs, stimes, samples, cnt, fin, tan, status = _run(
            st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap, kick_u, sp,
            max_events, stall_dt, True, tan, kinetic, (holes, escape), None, table)
    bt, bx, by, bs, klog = logs
    n = cnt[N_B]
    n_applied = cnt[N_KICKS_RUN] if status == ob.DONE else cnt[N_KICKS]
    t_end = fin[0] if status == ob.DONE else (t_max if mode < 2 else np.inf)
    k = cnt[K] if escape[1] >= 0.0 else stimes.shape[0]
    return (bt[:n], bx[:n], by[:n], bs[:n], stimes[:k], samples[:k], n_applied, t_end,
            klog[:n_applied], status, escape), tan


@njit(cache=True)
def simulate_tangent_one_kernel(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau,
                                b_cap, kick_u, sp, max_events, stall_dt, U, max_ev_tan,
                                kinetic=None, holes=None, uniform=False, table=None):
    """`simulate_one_kernel` and `tangent_one_kernel` in one pass.

    Arguments as theirs (``mode`` 1 or 2); ``uniform`` (``mode == 2``, no holes): also the
    run's uniform samples at ``k tau`` over its duration, bitwise those of a uniform run
    with the kicks it applied; ``table``: see `drive`. Returns ``(b_time, b_x, b_y, b_sin,
    sample_times, samples, n_kicks_applied, t_end, kick_log, status, log_scale, n_rescaled,
    n_kicks_tangent, t_end_tangent, status_tangent, escape, uniform_times,
    uniform_samples)``.
    """
    on = uniform and mode == 2 and holes is None
    u_times, u_samples = ob.new_samples(n_steps + 2 if on else 0)
    u_cnt = np.zeros(3, dtype=np.int64)
    u_cnt[1] = 1 if on else 0
    u_cnt[2] = -1
    out, tan = _simulate(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau, b_cap,
                         kick_u, sp, max_events, stall_dt,
                         tg.tangent_state(U, mode, n_steps, tau, max_ev_tan, np.int64(0)),
                         kinetic, holes, (u_times, u_samples, u_cnt), table)
    _, log_scale, tgi, tgf, _, _, _ = tan
    ku = u_cnt[0]
    return (out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7], out[8], out[9],
            log_scale, tgi[tg.N_RESC], tgi[tg.N_PERT], tgf[tg.T_PREV], tgi[tg.TAN_STATUS],
            out[10], u_times[:ku], u_samples[:ku])


@njit(cache=True)
def tangent_one_kernel(st, rho, kicks, angles, kick_mode, mode, n_steps, tau, U, max_events,
                       kick_u, sp, kinetic=None, table=None):
    """Carry the tangent vectors ``U`` (m, 4) along the kicked one-disk trajectory.

    As `kicktimes.billiard.kernels.drive_two.tangent_two_kernel`; kicks at ``kicks``
    (sorted times) with ``angles`` are applied with `tg.kick_tangent` (a tie with a boundary
    collision goes to the boundary first). Scattering kicks (``kick_mode == 2``, numbers
    ``kick_u``, parameters ``sp``) are linearised by
    `kicktimes.billiard.scatter.scatter_tangent`: a disk-disk collision with a partner
    whose deviation is zero. ``table``: see `drive` (``None``: the circle).

    Returns ``(log_scale, n_rescaled, n_kicks, t_end, status)``.
    """
    tan = tg.tangent_state(U, mode, n_steps, tau, max_events, np.int64(0))
    _run(st, rho, kicks, angles, kick_mode, 0.0, mode, n_steps, tau, 0, kick_u, sp, max_events,
         0.0, False, tan, kinetic, None, None, table)
    _, log_scale, tgi, tgf, _, _, _ = tan
    # the state flies on to the end, as the vectors did
    dt = tgf[tg.T_PREV] - st[0]
    st[1] += st[3] * dt
    st[2] += st[4] * dt
    st[0] = tgf[tg.T_PREV]
    return log_scale, tgi[tg.N_RESC], tgi[tg.N_PERT], tgf[tg.T_PREV], tgi[tg.TAN_STATUS]
