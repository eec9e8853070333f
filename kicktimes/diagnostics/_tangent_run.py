"""One pass per trajectory: the simulation's full output and the tangent FTLE in one event loop.

`simulate_tangent_two_kernel` returns everything `simulate_two_kernel` returns (samples,
boundary log, disk-disk times, final state) *and* what `tangent_two_kernel` returns (the
tangent vectors ``U`` carried along, their log-scales), from a single run of the event
loop; `simulate_tangent_one_kernel` does the same for the kicked disk
(`simulate_one_kernel` and `tangent_one_kernel`). Both halves are bitwise what the two
separate kernels compute: the events are applied by the same scalar functions, in the
same order, and each half keeps its own notion of where the run ends:

* the simulation ends where `simulate_two_kernel` does (``t_max``, or after ``n_steps``
  collision-truncated steps, whose ends are the sample times ``t_{k-1} + tau`` or the
  Kahan-summed clock at a collision);
* the tangent vectors end where `tangent_two_kernel` does: its step ends are
  ``min(t_prev + tau, t + dt_next)``, which can differ from the sample times in the last
  bit, so its end time (``LyapunovResult.total_time``) and the events it applies are
  tracked separately. Both are prefixes of the same event sequence: the loop runs until
  the longer one is done, and each half stops recording at its own end.

With ``t_continue > t_end`` (paper sampling) the two-disk loop then goes on, without
samples, boundary log or tangent work, until the next event would come after
``t_continue``, and appends the further disk-disk times: the times a fresh
``simulate_two_kernel`` run to ``t_max = t_continue`` logs (its event sequence is the
same; the sweep kicks the actual-time billiard with them).

Status codes: the simulation's as in `kicktimes.billiard.two_particle` (`DONE`, `STALLED`,
`OVER_BUDGET`), the tangent half's as in `kicktimes.diagnostics._tangent` (0 ok, 1
budget, 2 stuck at one instant, 3 non-finite time); a simulation error stops the loop at
once (the simulation would have raised first), a tangent error only stops the tangent
half (the simulation's errors take precedence, as when the two ran one after the other).
A contact exactly tangent to the wall, where the linearised dynamics is singular, makes
`wall_tangent` return NaN (it raised ZeroDivisionError): the tangent half carries the NaN
to its end, where `kicktimes.diagnostics.lyapunov` reports the exponent as undefined.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kicktimes.billiard.geometry import boundary_hit_time, pair_hit_time
from kicktimes.billiard.one_particle import (
    SCATTER,
    kick_one,
    process_scatter_one,
    wall_event_one,
)
from kicktimes.billiard.scatter import scatter_tangent
from kicktimes.billiard.two_particle import (
    DONE,
    FULL,
    OVER_BUDGET,
    STALLED,
    _grow_to,
    _stalled,
    anchor_energy,
    init_events_two,
    pair_event,
    wall_event,
)
from kicktimes.diagnostics._tangent import (
    _budget,
    _renormalise,
    kick_tangent,
    pair_tangent,
    wall_tangent,
)

# indices of the int64 carry array ``cnt`` of the loops (their position between calls)
N_PP, N_B, K, SIM_ON, N_PP_RUN, CONT_ON, N_B_CONT, N_KICKS_RUN, CONT_STATUS = range(9)
# ... and of the tangent half's: ``tgi`` (int64) and ``tgf`` (float64)
TAN_ON, I_LOOP, N_LOOP, N_EV, N_SAME, N_RESC, N_PERT, TAN_STATUS = range(8)
TK, T_PREV = range(2)


@njit(cache=True)
def _pass_loop_two(st, ev, rho, sigma, rule, t_end, mode, tau, track, pp, bt, bp, bx, by, bs,
                   stimes, samples, cnt, next_s, fin, U, log_scale, tgi, tgf, max_ev_tan,
                   t_continue, max_events):
    """`_event_loop_two` and `tangent_two_kernel`'s loop in one; returns `DONE` or `FULL`.

    The state lives in locals as in `_event_loop_two` (same arithmetic, same bits); the
    tangent maps are applied after each event from the contact and the velocities before
    and after it, as in `tangent_two_kernel`. At the simulation's end its final state
    (flown on to ``t_end``, as `finish_at` does) goes to ``fin``. `FULL` means that a
    buffer of the simulation (or the continuation's ``pp``) is full: the caller grows it
    and calls again.
    """
    t = st[0]
    x0 = st[1]
    y0 = st[2]
    vx0 = st[3]
    vy0 = st[4]
    x1 = st[5]
    y1 = st[6]
    vx1 = st[7]
    vy1 = st[8]
    comp = st[9]
    e0 = st[10]
    tb0 = ev[0]
    tb1 = ev[1]
    tpp = ev[2]
    n_pp = cnt[N_PP]
    n_b = cnt[N_B]
    k = cnt[K]
    sim_on = cnt[SIM_ON] != 0
    cont_on = cnt[CONT_ON] != 0
    n_b_cont = cnt[N_B_CONT]
    tan_on = tgi[TAN_ON] != 0
    i_loop = tgi[I_LOOP]
    n_loop = tgi[N_LOOP]
    n_ev = tgi[N_EV]
    n_same = tgi[N_SAME]
    n_resc = tgi[N_RESC]
    n_pert = tgi[N_PERT]
    tk = tgf[TK]
    t_prev = tgf[T_PREV]
    m = U.shape[0]
    ns = stimes.shape[0]
    pp_cap = pp.shape[0]
    b_cap = bt.shape[0]
    ns_next = next_s[0]
    status = FULL
    while True:
        ke = 0
        dte = tb0
        if tb1 < dte:
            ke = 1
            dte = tb1
        if tpp < dte:
            ke = 2
            dte = tpp
        if sim_on:
            # _event_loop_two: samples strictly before the next event, then its end test
            while k < ns and ns_next - t < dte:
                ds = ns_next - t
                stimes[k] = ns_next
                if track == 0:
                    samples[k, 0] = x0 + vx0 * ds
                    samples[k, 1] = y0 + vy0 * ds
                else:
                    samples[k, 0] = x1 + vx1 * ds
                    samples[k, 1] = y1 + vy1 * ds
                k += 1
                ns_next = k * tau if mode == 1 else ns_next + tau
            if (mode == 2 and k >= ns) or t + dte > t_end:
                sim_on = False
                cnt[N_PP_RUN] = n_pp
                if mode == 2:
                    t_end = stimes[ns - 1]
                # finish_at: fly to t_end
                dt = t_end - t
                fin[0] = t_end
                fin[1] = x0 + vx0 * dt
                fin[2] = y0 + vy0 * dt
                fin[3] = vx0
                fin[4] = vy0
                fin[5] = x1 + vx1 * dt
                fin[6] = y1 + vy1 * dt
                fin[7] = vx1
                fin[8] = vy1
                # _actual_times: continued only if the sampled window ends before t_continue;
                # its budget counts every event from t = 0, as a run to t_continue's does
                cont_on = mode == 2 and not t_end >= t_continue
                n_b_cont = n_b
        if tan_on:
            # tangent_two_kernel: the step ends before the next event
            while not t + dte <= tk:
                if dte != dte:
                    tgi[TAN_STATUS] = 3
                    tan_on = False
                    break
                t_prev = tk
                i_loop += 1
                if i_loop == n_loop:
                    dt = t_prev - t
                    for j in range(m):
                        U[j, 0] += U[j, 2] * dt
                        U[j, 1] += U[j, 3] * dt
                        U[j, 4] += U[j, 6] * dt
                        U[j, 5] += U[j, 7] * dt
                    tan_on = False
                    break
                tk = min(t_prev + tau, t + min(tb0, min(tb1, tpp)))
        if cont_on:
            # the run to t_continue stops at the first event after it
            if t + dte > t_continue:
                cont_on = False
            elif n_pp + n_b_cont >= max_events:
                cnt[CONT_STATUS] = OVER_BUDGET
                cont_on = False
        if not (sim_on or tan_on or cont_on):
            status = DONE
            break
        # a full buffer: return before anything of this event is counted
        if ke == 2:
            if (sim_on or cont_on) and n_pp >= pp_cap:
                break
        elif sim_on and n_b >= b_cap:
            break
        if tan_on:
            n_ev += 1
            if dte > 0.0 and n_ev <= max_ev_tan:
                n_same = 0
            else:
                # the rare path: simultaneous events, a NaN time, or the budget used up
                code, n_same = _budget(dte, n_ev, np.int64(n_same), max_ev_tan)
                if code != 0:
                    tgi[TAN_STATUS] = code
                    tan_on = False
            if tan_on:
                for j in range(m):
                    U[j, 0] += U[j, 2] * dte
                    U[j, 1] += U[j, 3] * dte
                    U[j, 4] += U[j, 6] * dte
                    U[j, 5] += U[j, 7] * dte
        v0x = vx0
        v0y = vy0
        v1x = vx1
        v1y = vy1
        # free flight to the event (drift_two): relative event times, Kahan clock
        x0 += vx0 * dte
        y0 += vy0 * dte
        x1 += vx1 * dte
        y1 += vy1 * dte
        tb0 -= dte
        tb1 -= dte
        tpp -= dte
        yk = dte - comp
        tn = t + yk
        comp = (tn - t) - yk
        t = tn
        sin_theta = 0.0
        if ke < 2:
            if ke == 0:
                x, y, vx, vy = x0, y0, vx0, vy0
            else:
                x, y, vx, vy = x1, y1, vx1, vy1
            x, y, vx, vy, tb, sin_theta = wall_event(x, y, vx, vy, rho, rule)
            if ke == 0:
                x0, y0, vx0, vy0, tb0 = x, y, vx, vy, tb
            else:
                x1, y1, vx1, vy1, tb1 = x, y, vx, vy, tb
        else:
            vx0, vy0, vx1, vy1 = pair_event(x0, y0, vx0, vy0, x1, y1, vx1, vy1, rule)
            tb0 = boundary_hit_time(x0, y0, vx0, vy0, rho)
            tb1 = boundary_hit_time(x1, y1, vx1, vy1, rho)
        if rule != 0:
            vx0, vy0, vx1, vy1 = anchor_energy(vx0, vy0, vx1, vy1, e0)
        tpp = pair_hit_time(x0 - x1, y0 - y1, vx0 - vx1, vy0 - vy1, sigma)
        if ke == 2:
            if tan_on:
                n_pert += 1
                for j in range(m):
                    (U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4], U[j, 5], U[j, 6],
                     U[j, 7]) = pair_tangent(U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4],
                                             U[j, 5], U[j, 6], U[j, 7], x0, y0, x1, y1, v0x,
                                             v0y, v1x, v1y, vx0, vy0, vx1, vy1, rule)
                    n_resc += _renormalise(U, log_scale, j)
            if sim_on or cont_on:
                pp[n_pp] = t
                n_pp += 1
        else:
            if tan_on:
                if ke == 0:
                    vx, vy, wx, wy, x, y = v0x, v0y, vx0, vy0, x0, y0
                else:
                    vx, vy, wx, wy, x, y = v1x, v1y, vx1, vy1, x1, y1
                if vx != wx or vy != wy:
                    # (a disk already moving inward is not reflected: identity map)
                    o = 4 * ke
                    for j in range(m):
                        (U[j, o], U[j, o + 1], U[j, o + 2], U[j, o + 3]) = wall_tangent(
                            U[j, o], U[j, o + 1], U[j, o + 2], U[j, o + 3], x, y, vx, vy, wx,
                            wy, rho)
            if sim_on:
                bt[n_b] = t
                bp[n_b] = ke
                bx[n_b] = x1 if ke else x0
                by[n_b] = y1 if ke else y0
                bs[n_b] = sin_theta
                n_b += 1
            elif cont_on:
                n_b_cont += 1
        if sim_on and mode == 2 and k < ns:
            # the paper's step is cut short by this collision: sample at it
            stimes[k] = t
            samples[k, 0] = x1 if track else x0
            samples[k, 1] = y1 if track else y0
            k += 1
            ns_next = t + tau
    st[0] = t
    st[1] = x0
    st[2] = y0
    st[3] = vx0
    st[4] = vy0
    st[5] = x1
    st[6] = y1
    st[7] = vx1
    st[8] = vy1
    st[9] = comp
    ev[0] = tb0
    ev[1] = tb1
    ev[2] = tpp
    cnt[N_PP] = n_pp
    cnt[N_B] = n_b
    cnt[K] = k
    cnt[SIM_ON] = 1 if sim_on else 0
    cnt[CONT_ON] = 1 if cont_on else 0
    cnt[N_B_CONT] = n_b_cont
    tgi[TAN_ON] = 1 if tan_on else 0
    tgi[I_LOOP] = i_loop
    tgi[N_EV] = n_ev
    tgi[N_SAME] = n_same
    tgi[N_RESC] = n_resc
    tgi[N_PERT] = n_pert
    tgf[TK] = tk
    tgf[T_PREV] = t_prev
    next_s[0] = ns_next
    return status


@njit(cache=True)
def simulate_tangent_two_kernel(st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap,
                                b_cap, max_events, stall_dt, U, max_ev_tan, t_continue):
    """`simulate_two_kernel` (without the collision log) and `tangent_two_kernel` in one pass.

    The simulation's arguments are `simulate_two_kernel`'s, ``U`` (m, 8) and
    ``max_ev_tan`` are `tangent_two_kernel`'s (``n_orth = 0``; ``mode`` 1 or 2, the
    tangent vectors run over the same ``n_steps`` and ``tau``). ``t_continue``: with
    ``mode == 2``, continue to it when the sampled window ends before it (``0``: never).
    ``st`` ends as `simulate_two_kernel` leaves it; ``U`` as `tangent_two_kernel` does.

    Returns ``(pp_times, n_pp_run, b_time, b_part, b_x, b_y, b_sin, sample_times, samples,
    t_end, status, log_scale, n_rescaled, n_pp_tangent, t_end_tangent, status_tangent,
    status_continuation)``: ``pp_times[:n_pp_run]`` are the run's disk-disk times,
    ``pp_times`` with the continuation's after them.
    """
    ev = np.empty(3)
    init_events_two(st, ev, rho, sigma)
    pp = np.empty(min(pp_cap, max_events + 1))
    b_cap = min(b_cap, max_events + 1)
    bt = np.empty(b_cap)
    bp = np.empty(b_cap, dtype=np.int8)
    bx = np.empty(b_cap)
    by = np.empty(b_cap)
    bs = np.empty(b_cap)
    ns = n_steps + 1
    stimes = np.empty(ns)
    samples = np.empty((ns, 2))
    cnt = np.zeros(9, dtype=np.int64)
    cnt[SIM_ON] = 1
    next_s = np.zeros(1)
    fin = np.empty(9)
    m = U.shape[0]
    log_scale = np.zeros(m)
    tgi = np.zeros(8, dtype=np.int64)
    tgi[TAN_ON] = 1
    tgi[N_LOOP] = 1 if mode == 1 else n_steps
    tgf = np.zeros(2)
    if mode == 1:
        tgf[TK] = n_steps * tau
    else:
        tgf[TK] = min(0.0 + tau, st[0] + min(ev[0], min(ev[1], ev[2])))
    t_end = t_max if mode < 2 else np.inf
    status = DONE
    while True:
        loop = _pass_loop_two(st, ev, rho, sigma, rule, t_end, mode, tau, track, pp, bt, bp,
                              bx, by, bs, stimes, samples, cnt, next_s, fin, U, log_scale, tgi,
                              tgf, max_ev_tan, t_continue, max_events)
        if cnt[SIM_ON] != 0:
            # as simulate_two_kernel, at the same points: a buffer of the run is full
            if _stalled(pp, cnt[N_PP], stall_dt) or _stalled(bt, cnt[N_B], stall_dt):
                status = STALLED
                break
            room = max_events - cnt[N_PP] - cnt[N_B]
            if room <= 0:
                status = OVER_BUDGET
                break
            if cnt[N_PP] >= pp.shape[0]:
                pp = _grow_to(pp, pp.shape[0] + room)
            if cnt[N_B] >= bt.shape[0]:
                limit = bt.shape[0] + room
                bt = _grow_to(bt, limit)
                bp = _grow_to(bp, limit)
                bx = _grow_to(bx, limit)
                by = _grow_to(by, limit)
                bs = _grow_to(bs, limit)
        elif loop == FULL:
            # the continuation's times (its budget is checked in the loop)
            pp = _grow_to(pp, pp.shape[0] + max_events + 1)
        else:
            break
    n_pp_run = cnt[N_PP_RUN] if status == DONE else cnt[N_PP]
    n_b = cnt[N_B]
    if status == DONE:
        # simulate_two_kernel's last stall test, on the run's own logs
        if _stalled(pp, n_pp_run, stall_dt) or _stalled(bt, n_b, stall_dt):
            status = STALLED
        else:
            for i in range(9):
                st[i] = fin[i]
            st[9] = 0.0
            t_end = fin[0]
        return (pp[: cnt[N_PP]], n_pp_run, bt[:n_b], bp[:n_b], bx[:n_b], by[:n_b], bs[:n_b], stimes,
            samples, t_end, status, log_scale, tgi[N_RESC], tgi[N_PERT], tgf[T_PREV],
            tgi[TAN_STATUS], cnt[CONT_STATUS])


@njit(cache=True)
def _pass_loop_one(st, ev, rho, kicks, angles, kick_mode, unit_speed, t_end, mode, tau, bt, bx,
                   by, bs, stimes, samples, cnt, next_s, fin, kick_u, sp, klog, U, log_scale,
                   tgi, tgf, max_ev_tan):
    """`_event_loop_one` and `tangent_one_kernel`'s loop in one (see `_pass_loop_two`).

    ``cnt = [n_kicks, n_b, k, sim_on, -, -, -, n_kicks_run, -]`` (indices as the two-disk
    loop's); ``fin = [t_end, x, y, vx, vy]``, the run's final state.
    """
    t = st[0]
    x = st[1]
    y = st[2]
    vx = st[3]
    vy = st[4]
    comp = st[5]
    tb = ev[0]
    ik = cnt[N_PP]
    n_b = cnt[N_B]
    k = cnt[K]
    sim_on = cnt[SIM_ON] != 0
    tan_on = tgi[TAN_ON] != 0
    i_loop = tgi[I_LOOP]
    n_loop = tgi[N_LOOP]
    n_ev = tgi[N_EV]
    n_same = tgi[N_SAME]
    n_resc = tgi[N_RESC]
    tk = tgf[TK]
    t_prev = tgf[T_PREV]
    m = U.shape[0]
    nk = kicks.shape[0]
    ns = stimes.shape[0]
    b_cap = bt.shape[0]
    ns_next = next_s[0]
    scatter = kick_mode == SCATTER
    status = FULL
    while True:
        # the next event; a tie goes to the boundary
        is_kick = False
        dte = tb
        if ik < nk:
            dk = kicks[ik] - t
            if dk < dte:
                is_kick = True
                dte = dk
        if sim_on:
            while k < ns and ns_next - t < dte:
                ds = ns_next - t
                stimes[k] = ns_next
                samples[k, 0] = x + vx * ds
                samples[k, 1] = y + vy * ds
                k += 1
                ns_next = k * tau if mode == 1 else ns_next + tau
            if (mode == 2 and k >= ns) or t + dte > t_end:
                sim_on = False
                cnt[N_KICKS_RUN] = ik
                if mode == 2:
                    t_end = stimes[ns - 1]
                dt = t_end - t  # finish_one_at
                fin[0] = t_end
                fin[1] = x + vx * dt
                fin[2] = y + vy * dt
                fin[3] = vx
                fin[4] = vy
        if tan_on:
            while not t + dte <= tk:
                if dte != dte:
                    tgi[TAN_STATUS] = 3
                    tan_on = False
                    break
                t_prev = tk
                i_loop += 1
                if i_loop == n_loop:
                    dt = t_prev - t
                    for j in range(m):
                        U[j, 0] += U[j, 2] * dt
                        U[j, 1] += U[j, 3] * dt
                    tgi[N_PERT] = ik
                    tan_on = False
                    break
                tk = min(t_prev + tau, t + dte)
        if not (sim_on or tan_on):
            status = DONE
            break
        if not is_kick and sim_on and n_b >= b_cap:
            break
        if tan_on:
            n_ev += 1
            if dte > 0.0 and n_ev <= max_ev_tan:
                n_same = 0
            else:
                code, n_same = _budget(dte, n_ev, np.int64(n_same), max_ev_tan)
                if code != 0:
                    tgi[TAN_STATUS] = code
                    tan_on = False
            if tan_on:
                for j in range(m):
                    U[j, 0] += U[j, 2] * dte
                    U[j, 1] += U[j, 3] * dte
        ux = vx
        uy = vy
        if is_kick:
            st[0] = t
            st[1] = x
            st[2] = y
            st[3] = vx
            st[4] = vy
            st[5] = comp
            ev[0] = tb
            if scatter:
                row = klog[ik]
                process_scatter_one(st, ev, dte, rho, kicks[ik], kick_u[ik, 0], kick_u[ik, 1],
                                    sp, row)
                if tan_on and (row[4] != 0.0 or row[5] != 0.0):
                    for j in range(m):
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3] = scatter_tangent(
                            ux, uy, row[6], row[7], row[4], row[5], sp[0], int(sp[1]), U[j, 0],
                            U[j, 1], U[j, 2], U[j, 3])
                        n_resc += _renormalise(U, log_scale, j)
            else:
                kick_one(st, ev, dte, rho, kicks[ik], angles[ik], kick_mode)
                if tan_on:
                    for j in range(m):
                        U[j, 2], U[j, 3] = kick_tangent(U[j, 2], U[j, 3], ux, uy, st[3], st[4],
                                                        angles[ik], kick_mode)
                        n_resc += _renormalise(U, log_scale, j)
            t = st[0]
            x = st[1]
            y = st[2]
            vx = st[3]
            vy = st[4]
            comp = st[5]
            tb = ev[0]
            ik += 1
        else:
            # free flight (drift_one): relative event time, Kahan clock
            x += vx * dte
            y += vy * dte
            tb -= dte
            yk = dte - comp
            tn = t + yk
            comp = (tn - t) - yk
            t = tn
            x, y, vx, vy, tb, sin_theta = wall_event_one(x, y, vx, vy, rho, unit_speed)
            if tan_on and (ux != vx or uy != vy):
                for j in range(m):
                    U[j, 0], U[j, 1], U[j, 2], U[j, 3] = wall_tangent(
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3], x, y, ux, uy, vx, vy, rho)
            if sim_on:
                bs[n_b] = sin_theta
                bt[n_b] = t
                bx[n_b] = x
                by[n_b] = y
                n_b += 1
        if sim_on and mode == 2 and k < ns:
            stimes[k] = t
            samples[k, 0] = x
            samples[k, 1] = y
            k += 1
            ns_next = t + tau
    st[0] = t
    st[1] = x
    st[2] = y
    st[3] = vx
    st[4] = vy
    st[5] = comp
    ev[0] = tb
    cnt[N_PP] = ik
    cnt[N_B] = n_b
    cnt[K] = k
    cnt[SIM_ON] = 1 if sim_on else 0
    tgi[TAN_ON] = 1 if tan_on else 0
    tgi[I_LOOP] = i_loop
    tgi[N_EV] = n_ev
    tgi[N_SAME] = n_same
    tgi[N_RESC] = n_resc
    tgf[TK] = tk
    tgf[T_PREV] = t_prev
    next_s[0] = ns_next
    return status


@njit(cache=True)
def simulate_tangent_one_kernel(st, rho, kicks, angles, kick_mode, t_max, mode, n_steps, tau,
                                b_cap, kick_u, sp, max_events, stall_dt, U, max_ev_tan):
    """`simulate_one_kernel` and `tangent_one_kernel` in one pass (see the module).

    Arguments as theirs (``mode`` 1 or 2). Returns ``(b_time, b_x, b_y, b_sin,
    sample_times, samples, n_kicks_applied, t_end, kick_log, status, log_scale, n_rescaled,
    n_kicks_tangent, t_end_tangent, status_tangent)``.
    """
    ev = np.empty(1)
    ev[0] = boundary_hit_time(st[1], st[2], st[3], st[4], rho)
    unit_speed = (abs(st[3] * st[3] + st[4] * st[4] - 1.0) < 1e-12
                  and not (kick_mode == SCATTER and sp[1] != 0.0))
    klog = np.zeros((kicks.shape[0] if kick_mode == SCATTER else 0, 9))
    b_cap = min(b_cap, max_events + 1)
    bt = np.empty(b_cap)
    bx = np.empty(b_cap)
    by = np.empty(b_cap)
    bs = np.empty(b_cap)
    ns = n_steps + 1
    stimes = np.empty(ns)
    samples = np.empty((ns, 2))
    cnt = np.zeros(9, dtype=np.int64)
    cnt[SIM_ON] = 1
    next_s = np.zeros(1)
    fin = np.empty(5)
    m = U.shape[0]
    log_scale = np.zeros(m)
    tgi = np.zeros(8, dtype=np.int64)
    tgi[TAN_ON] = 1
    tgi[N_LOOP] = 1 if mode == 1 else n_steps
    tgf = np.zeros(2)
    if mode == 1:
        tgf[TK] = n_steps * tau
    else:
        dtn = ev[0]
        if kicks.shape[0] > 0 and kicks[0] - st[0] < dtn:
            dtn = kicks[0] - st[0]
        tgf[TK] = min(0.0 + tau, st[0] + dtn)
    t_end = t_max if mode < 2 else np.inf
    status = DONE
    while True:
        loop = _pass_loop_one(st, ev, rho, kicks, angles, kick_mode, unit_speed, t_end, mode,
                              tau, bt, bx, by, bs, stimes, samples, cnt, next_s, fin, kick_u, sp,
                              klog, U, log_scale, tgi, tgf, max_ev_tan)
        if loop == DONE:
            break
        # a full boundary log: as simulate_one_kernel
        if _stalled(bt, cnt[N_B], stall_dt):
            status = STALLED
            break
        room = max_events - cnt[N_B]
        if room <= 0:
            status = OVER_BUDGET
            break
        limit = bt.shape[0] + room
        bt = _grow_to(bt, limit)
        bx = _grow_to(bx, limit)
        by = _grow_to(by, limit)
        bs = _grow_to(bs, limit)
    n = cnt[N_B]
    n_applied = cnt[N_KICKS_RUN] if status == DONE else cnt[N_PP]
    if status == DONE:
        if _stalled(bt, n, stall_dt):
            status = STALLED
        else:
            for i in range(5):
                st[i] = fin[i]
            st[5] = 0.0
            t_end = fin[0]
    return (bt[:n], bx[:n], by[:n], bs[:n], stimes, samples, n_applied, t_end,
            klog[:n_applied], status, log_scale, tgi[N_RESC], tgi[N_PERT], tgf[T_PREV],
            tgi[TAN_STATUS])
