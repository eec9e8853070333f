"""The two-disk driver: one event loop, with the observers a caller switches on.

`drive` runs the event step of `kicktimes.billiard.kernels.two` and composes around it:

* the **simulation** (``cnt[SIM_ON]``): samples of the tracked disk on the free flights
  (`kicktimes.billiard.kernels.observe`), the boundary log, the disk-disk times and,
  with ``log_pp``, their collision log, up to the run's end (``t_max``, or ``n_steps``
  collision-truncated steps);
* the **tangent vectors** (``tan``, or ``None``): the linearised event maps of
  `kicktimes.billiard.kernels.tangent` after each event, over the tangent's own steps
  (its step ends ``min(t_prev + tau, t + dt_next)`` can differ from the sample times in
  the last bit), with Gram-Schmidt at ``n_orth`` times for the spectrum;
* the **continuation** (``cont``, or ``None``): after a paper-sampled window that ends
  before ``t_continue``, the disk-disk times on to it (a fresh run to ``t_max =
  t_continue`` logs the same).

An observer passed as ``None`` is compiled out (numba prunes the branches on an argument
that is ``None``), so the simulation alone runs the loop it always had. All observers see
one event sequence; each stops recording at its own end and the loop runs until the
longest is done. Three entry points: `simulate_two_kernel`, `simulate_tangent_two_kernel`
(the one pass of a sweep) and `tangent_two_kernel` (the FTLE and the spectrum alone).

Status codes: the simulation's `DONE`, `STALLED`, `OVER_BUDGET`
(`kicktimes.billiard.kernels.observe`); the tangent half's as `tangent.event_guard`'s
(0 ok, 1 budget, 2 stuck at one instant, 3 non-finite time). A simulation error stops the
loop at once; a tangent error only stops the tangent half. A contact exactly tangent to
the wall makes `wall_tangent` return NaN: the tangent half carries it to its end, where
`kicktimes.diagnostics.lyapunov` reports the exponent as undefined.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kicktimes.billiard.kernels import observe as ob
from kicktimes.billiard.kernels import tangent as tg
from kicktimes.billiard.kernels import two

__all__ = ["drive", "fresh_partner_tangent_two_kernel", "simulate_tangent_two_kernel",
           "simulate_two_kernel", "tangent_two_kernel"]

# the int64 carry array ``cnt`` of the loop (its position between calls)
N_PP, N_B, K, SIM_ON, N_PP_RUN, CONT_ON, N_B_CONT, CONT_STATUS = range(8)
# ... and the tangent half's: ``tgi`` (int64) and ``tgf`` (float64)


@njit(cache=True, error_model="numpy")
def drive(st, ev, phys, t_end, mode, tau, track, logs, stimes, samples, cnt, next_s, fin, tan,
          cont, holes, uni=None, wall=None):
    """Run the event loop from ``st``/``ev``; returns `ob.DONE`, or `ob.FULL` when a log is full.

    ``phys = (rho, sigma, rule)`` with ``rho = (rho0, rho1)``, one per disk;
    ``logs = (pp, bt, bp, bx, by, bs, ppl, log_pp)``;
    ``stimes``, ``samples`` the sample buffers; ``cnt``, ``next_s`` (the next sample time)
    and ``fin`` (the simulation's final state ``[t_end, x0, .., vy1]``) carry the loop's
    position between calls. ``tan = (U, log_scale, tgi, tgf, max_events, n_orth,
    n_steps)`` or ``None``; ``cont = (t_continue, max_events)`` or ``None``.
    ``holes = (arcs, escape)`` or ``None``: the table's holes (`observe.in_hole`); a disk
    whose wall contact lies in one escapes there and the simulation ends, its time and
    disk written to ``escape = [t, disk]`` (the simulation alone: no tangent, no
    continuation).
    ``uni = (u_times, u_samples, u_cnt)`` or ``None``: the uniform samples of a
    paper-sampled run (`observe.sample_uniform`) at ``k tau`` over the run's duration
    ``T``, recorded in this loop as a uniform run to ``t_max = T`` records them; ``u_cnt =
    [k, on, limit]`` (``limit`` -1 until ``T`` is known).
    ``wall = ((kind, p0, p1, p2), wh)`` or ``None`` (the unit circle): another table
    (`kicktimes.billiard.kernels.tables`, equal disks), its wall events through
    `two.table_step` and the tangent map at a wall of the contact's curvature
    (`tangent.curved_wall_tangent`); ``wh`` (4,) carries both disks' "where" of their next
    contact between calls.

    The state lives in a tuple of locals for the whole loop (numba keeps it in registers;
    kept in arrays, every event stored and reloaded it, since numba cannot prove that the
    output buffers do not alias it). `ob.FULL` returns before anything of the event is
    counted: the caller grows the buffer and calls again.
    """
    rho, sigma, rule = phys
    pp, bt, bp, bx, by, bs, ppl, log_pp = logs
    e0 = st[10]
    s = two.load(st, ev)
    n_pp = cnt[N_PP]
    n_b = cnt[N_B]
    k = cnt[K]
    # an observer passed as None is compiled out: the simulation alone is always on
    sim_on = True
    tan_on = False
    cont_on = False
    if cont is not None:
        sim_on = cnt[SIM_ON] != 0
        cont_on = cnt[CONT_ON] != 0
    n_b_cont = cnt[N_B_CONT]
    if tan is not None:
        sim_on = cnt[SIM_ON] != 0
        tan_on = tan[2][tg.TAN_ON] != 0
        U, log_scale, tgi, tgf, max_ev_tan, n_orth, n_steps = tan
        m = U.shape[0]
        i_loop, n_loop, n_ev, n_same, n_resc, n_pert, tk, t_prev, tan_code = tg.load_carry(
            tgi, tgf)
        # set at the start and never changed: read once, not at every collision
        fresh_partner = tgi[tg.FRESH_PARTNER] != 0
    uni_on = False
    if uni is not None:
        u_times, u_samples, ku, uni_on, u_limit = ob.load_uniform(uni)
    # the table path's "where" of both disks' next wall contacts, and the last contact's
    # normal and curvature (for the tangent map); unused (compiled out) in the circle
    wh = (0.0, 0.0, 0.0, 0.0)
    if wall is not None:
        wh = (wall[1][0], wall[1][1], wall[1][2], wall[1][3])
    cnx = 0.0
    cny = 0.0
    ckap = 0.0
    ns = stimes.shape[0]
    pp_cap = pp.shape[0]
    b_cap = bt.shape[0]
    ns_next = next_s[0]
    status = ob.FULL
    while True:
        ke, dte = two.next_event(s)
        t = s[two.S_T]
        if sim_on:
            x, y, vx, vy = two.disk(s, track)
            k, ns_next = ob.sample_flight(stimes, samples, k, ns_next, t, dte, x, y, vx, vy, mode,
                                       tau)
            if (mode == 2 and k >= ns) or t + dte > t_end:
                sim_on = False
                cnt[N_PP_RUN] = n_pp
                if mode == 2:
                    t_end = stimes[ns - 1]
                f = two.fly(s, t_end)
                fin[0] = t_end
                fin[1], fin[2], fin[3], fin[4] = two.disk(f, 0)
                fin[5], fin[6], fin[7], fin[8] = two.disk(f, 1)
                if cont is not None:
                    # continued only if the sampled window ends before t_continue; its
                    # budget counts every event from t = 0, as a run to t_continue's does
                    cont_on = mode == 2 and not t_end >= cont[0]
                    n_b_cont = n_b
            elif holes is not None and ke != two.PAIR:
                x, y, vx, vy = two.disk(s, ke)
                if ob.in_hole(x + vx * dte, y + vy * dte, holes[0]):
                    # the disk escapes at this wall contact: the run ends there
                    sim_on = False
                    cnt[N_PP_RUN] = n_pp
                    f = two.advance(s, dte)
                    t_end = f[two.S_T]
                    holes[1][0] = t_end
                    holes[1][1] = ke
                    fin[0] = t_end
                    fin[1], fin[2], fin[3], fin[4] = two.disk(f, 0)
                    fin[5], fin[6], fin[7], fin[8] = two.disk(f, 1)
                    if tan is not None and tan_on:
                        # the tangent vectors end with the run: the FTLE up to the escape
                        tg.end_step(U, log_scale, t_end - t, n_orth)
                        t_prev = t_end
                        tan_on = False
        if uni is not None and uni_on:
            # the uniform samples of the same flight; once the run has ended at T = fin[0],
            # up to floor(T / tau) steps, and no flight beyond the one a run to T ends in
            x, y, vx, vy = two.disk(s, track)
            ku, u_limit, uni_on = ob.sample_uniform_flight(u_times, u_samples, ku, u_limit,
                                                           uni_on, sim_on, t, dte, x, y, vx, vy,
                                                           tau, fin[0])
        if tan is not None:
            # the tangent vectors' step ends before the next event
            while tan_on and not t + dte <= tk:
                if dte != dte:
                    tan_code = 3
                    tan_on = False
                    break
                t_prev = tk
                i_loop += 1
                if i_loop == n_loop:
                    tg.end_step(U, log_scale, t_prev - t, n_orth)
                    tan_on = False
                    break
                if n_orth > 0:
                    tg.gram_schmidt(U, log_scale)
                tk = tg.step_end(i_loop, n_loop, mode, n_steps, tau, t_prev, t + dte)
        if cont is not None and cont_on:
            # the run to t_continue stops at the first event after it
            if t + dte > cont[0]:
                cont_on = False
            elif n_pp + n_b_cont >= cont[1]:
                cnt[CONT_STATUS] = ob.OVER_BUDGET
                cont_on = False
        if not (sim_on or tan_on or cont_on or uni_on):
            status = ob.DONE
            break
        # a full buffer: return before anything of this event is counted
        if ke == two.PAIR:
            if (sim_on or cont_on) and n_pp >= pp_cap:
                break
            if sim_on and log_pp:
                ppl[n_pp, 4] = s[two.S_VX0]
                ppl[n_pp, 5] = s[two.S_VY0]
                ppl[n_pp, 6] = s[two.S_VX1]
                ppl[n_pp, 7] = s[two.S_VY1]
        elif sim_on and n_b >= b_cap:
            break
        if tan is not None and tan_on:
            tan_code, n_ev, n_same = tg.guard(dte, n_ev, n_same, max_ev_tan)
            tan_on = tan_code == 0
            if tan_on:
                tg.tangent_flight(U, dte)
        before = s
        if wall is None:
            s, sin_theta = two.step(s, ke, dte, rho, sigma, rule, e0)
        else:
            s, wh, sin_theta, cnx, cny, ckap = two.table_step(s, wh, ke, dte, rho, sigma, rule,
                                                              e0, wall[0])
        t = s[two.S_T]
        if ke == two.PAIR:
            if tan is not None and tan_on:
                n_pert += 1
                if fresh_partner:
                    for j in range(m):
                        for i in range(4, 8):
                            U[j, i] = 0.0
                for j in range(m):
                    (U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4], U[j, 5], U[j, 6],
                     U[j, 7]) = tg.pair_tangent(
                        U[j, 0], U[j, 1], U[j, 2], U[j, 3], U[j, 4], U[j, 5], U[j, 6], U[j, 7],
                        s[two.S_X0], s[two.S_Y0], s[two.S_X1], s[two.S_Y1],
                        before[two.S_VX0], before[two.S_VY0], before[two.S_VX1],
                        before[two.S_VY1], s[two.S_VX0], s[two.S_VY0], s[two.S_VX1],
                        s[two.S_VY1], rule, rho[2], rho[3])
                    n_resc += tg.renormalize(U, log_scale, j)
            if sim_on or cont_on:
                pp[n_pp] = t
                if sim_on and log_pp:
                    ppl[n_pp, 0] = s[two.S_X0]
                    ppl[n_pp, 1] = s[two.S_Y0]
                    ppl[n_pp, 2] = s[two.S_X1]
                    ppl[n_pp, 3] = s[two.S_Y1]
                    ppl[n_pp, 8] = s[two.S_VX0]
                    ppl[n_pp, 9] = s[two.S_VY0]
                    ppl[n_pp, 10] = s[two.S_VX1]
                    ppl[n_pp, 11] = s[two.S_VY1]
                n_pp += 1
        else:
            x, y, wx, wy = two.disk(s, ke)
            if tan is not None and tan_on:
                _, _, vx, vy = two.disk(before, ke)
                if wall is not None:
                    # the table's wall: its normal and curvature at this contact
                    c = 4 * ke
                    for j in range(m):
                        (U[j, c], U[j, c + 1], U[j, c + 2], U[j, c + 3]) = (
                            tg.curved_wall_tangent(U[j, c], U[j, c + 1], U[j, c + 2],
                                                   U[j, c + 3], vx, vy, wx, wy, cnx, cny,
                                                   ckap))
                        # a chaotic table stretches at every contact, not only at the disks'
                        # collisions: without this a long flight between them overflows the
                        # squared norm (the vector then renormalises to exactly 0)
                        n_resc += tg.renormalize(U, log_scale, j)
                elif vx != wx or vy != wy:
                    # (a disk already moving inward is not reflected: identity map)
                    c = 4 * ke
                    for j in range(m):
                        (U[j, c], U[j, c + 1], U[j, c + 2], U[j, c + 3]) = tg.wall_tangent(
                            U[j, c], U[j, c + 1], U[j, c + 2], U[j, c + 3], x, y, vx, vy, wx,
                            wy, rho[0] if ke == 0 else rho[1])
            if sim_on:
                bt[n_b] = t
                bp[n_b] = ke
                bx[n_b] = x
                by[n_b] = y
                bs[n_b] = sin_theta
                n_b += 1
            elif cont is not None and cont_on:
                n_b_cont += 1
        if sim_on and mode == 2 and k < ns:
            # the paper's step is cut short by this collision: sample at it
            x, y, _, _ = two.disk(s, track)
            k, ns_next = ob.sample_at_event(stimes, samples, k, t, x, y, tau)
    two.store(st, ev, s)
    if wall is not None:
        wall[1][0], wall[1][1], wall[1][2], wall[1][3] = wh
    cnt[N_PP] = n_pp
    cnt[N_B] = n_b
    cnt[K] = k
    cnt[SIM_ON] = 1 if sim_on else 0
    cnt[CONT_ON] = 1 if cont_on else 0
    cnt[N_B_CONT] = n_b_cont
    next_s[0] = ns_next
    if uni is not None:
        ob.store_uniform(uni, ku, uni_on, u_limit)
    if tan is not None:
        tg.store_carry(tgi, tgf, tan_on, i_loop, n_ev, n_same, n_resc, n_pert, tk, t_prev,
                       tan_code)
    return status


@njit(cache=True, error_model="numpy")
def _run(st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
         stall_dt, log_pp, sim, tan, cont, holes, uni=None, wall=None):
    """Allocate the logs, run `drive` to its end, growing them when full.

    ``sim``: record the simulation; ``tan`` (`tg.tangent_state`, or ``None``): carry tangent
    vectors; ``cont``: the continuation; ``uni``: the uniform samples; ``wall``: another table (see
    `drive`).
    Returns ``(logs, stimes, samples, cnt, fin, tan, status)``.
    """
    ev = np.empty(3)
    if wall is None:
        two.init_events(st, ev, rho, sigma)
    else:
        two.table_init_events(st, ev, wall[1], rho, sigma, wall[0])
    pp = np.empty(min(pp_cap, max_events + 1) if sim else 0)
    ppl = np.empty((pp.shape[0] if log_pp else 0, 12))
    bt, bx, by, bs = ob.new_boundary_log(min(b_cap, max_events + 1) if sim else 0)
    bp = np.empty(bt.shape[0], dtype=np.int8)
    stimes, samples = ob.new_samples(n_steps + 1 if mode > 0 and sim else 0)
    cnt = np.zeros(8, dtype=np.int64)
    cnt[SIM_ON] = 1 if sim else 0
    next_s = np.zeros(1)
    fin = np.empty(9)
    if tan is not None:
        tg.start(tan, mode, n_steps, tau, st[0] + two.next_event(two.load(st, ev))[1])
    t_end = t_max if mode < 2 else np.inf
    phys = (rho, sigma, rule)
    status = ob.DONE
    while True:
        logs = (pp, bt, bp, bx, by, bs, ppl, log_pp)
        if wall is None:
            loop = drive(st, ev, phys, t_end, mode, tau, track, logs, stimes, samples, cnt,
                         next_s, fin, tan, cont, holes, uni)
        else:
            loop = drive(st, ev, phys, t_end, mode, tau, track, logs, stimes, samples, cnt,
                         next_s, fin, tan, cont, holes, uni, wall)
        if cnt[SIM_ON] != 0:
            # budget and stalls are checked only here, when a log is full: nothing in the
            # hot loop
            if ob.stalled(pp, cnt[N_PP], stall_dt) or ob.stalled(bt, cnt[N_B], stall_dt):
                status = ob.STALLED
                break
            room = max_events - cnt[N_PP] - cnt[N_B]
            if room <= 0:
                status = ob.OVER_BUDGET
                break
            if cnt[N_PP] >= pp.shape[0]:
                limit = pp.shape[0] + room
                pp = ob.grow_to(pp, limit)
                if log_pp:
                    ppl = ob.grow_rows_to(ppl, limit)
            if cnt[N_B] >= bt.shape[0]:
                limit = bt.shape[0] + room
                bp = ob.grow_to(bp, limit)
                bt, bx, by, bs = ob.grow_boundary_log(bt, bx, by, bs, limit)
        elif loop == ob.FULL:
            # the continuation's times (its budget is checked in the loop)
            pp = ob.grow_to(pp, pp.shape[0] + max_events + 1)
        else:
            break
    n_pp_run = cnt[N_PP_RUN] if status == ob.DONE else cnt[N_PP]
    # the last stall test, on the run's own logs
    if status == ob.DONE and (ob.stalled(pp, n_pp_run, stall_dt)
                              or ob.stalled(bt, cnt[N_B], stall_dt)):
        status = ob.STALLED
    if sim and status == ob.DONE:
        for i in range(9):
            st[i] = fin[i]
        st[9] = 0.0
    logs = (pp, bt, bp, bx, by, bs, ppl, log_pp)
    return logs, stimes, samples, cnt, fin, tan, status


@njit(cache=True, error_model="numpy")
def simulate_two_kernel(st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap,
                        max_events, stall_dt, log_pp=False, holes=None, wall=None):
    """Run the two-disk billiard, logging every event and sampling the tracked disk.

    ``st`` is ``[t, x0, y0, vx0, vy0, x1, y1, vx1, vy1, clock compensation, energy]``.
    ``mode``: 0 no samples (run to ``t_max``), 1 uniform samples at ``k tau`` (run to
    ``t_max``), 2 the paper's collision-truncated steps (run until ``n_steps`` are done).
    Samples are interpolated along the free flight, inside the event loop. The run stops
    early with status `ob.OVER_BUDGET` after ``max_events`` collisions, or `ob.STALLED` (see
    `kicktimes.billiard.kernels.observe.stalled`); ``st`` then holds the state where it
    stopped.

    Returns ``(pp_times, b_time, b_part, b_x, b_y, b_sin, sample_times, samples, t_end,
    pp_log, status, escape)``; ``pp_log`` has a row per disk-disk collision if ``log_pp``,
    else none. ``holes`` (an array of rows ``[centre angle, half-width]``, or ``None``):
    the table's holes; ``escape = [t, disk]`` of the first escape (``[inf, -1]``: none),
    where the run then ends (its samples stop there). ``wall`` (``(kind, p0, p1, p2)`` of
    `kicktimes.billiard.kernels.tables`, or ``None``: the unit circle): another table, for
    equal disks of room ``rho[0]`` (no holes).
    """
    escape = np.array([np.inf, -1.0])
    # (separate calls, not a conditional argument: numba compiles the holes and the table
    # out when absent)
    if wall is not None:
        logs, stimes, samples, cnt, fin, _, status = _run(
            st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
            stall_dt, log_pp, True, None, None, None, None, (wall, np.zeros(4)))
    elif holes is None:
        logs, stimes, samples, cnt, fin, _, status = _run(
            st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
            stall_dt, log_pp, True, None, None, None)
    else:
        logs, stimes, samples, cnt, fin, _, status = _run(
            st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
            stall_dt, log_pp, True, None, None, (holes, escape))
    pp, bt, bp, bx, by, bs, ppl, _ = logs
    n_pp = cnt[N_PP]
    n_b = cnt[N_B]
    t_end = fin[0] if status == ob.DONE else (t_max if mode < 2 else np.inf)
    # views, not copies: the buffers are at most about twice the size needed
    k = cnt[K] if escape[1] >= 0.0 else stimes.shape[0]
    return (pp[:n_pp], bt[:n_b], bp[:n_b], bx[:n_b], by[:n_b], bs[:n_b], stimes[:k], samples[:k],
            t_end, ppl[: n_pp if log_pp else 0], status, escape)


@njit(cache=True, error_model="numpy")
def simulate_tangent_two_kernel(st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap,
                                b_cap, max_events, stall_dt, U, max_ev_tan, t_continue,
                                holes=None, uniform=False, wall=None):
    """`simulate_two_kernel` (without the collision log) and `tangent_two_kernel` in one pass.

    The simulation's arguments are `simulate_two_kernel`'s, ``U`` (m, 8) and
    ``max_ev_tan`` are `tangent_two_kernel`'s (``n_orth = 0``; ``mode`` 1 or 2, the
    tangent vectors run over the same ``n_steps`` and ``tau``). ``t_continue``: with
    ``mode == 2``, continue to it when the sampled window ends before it (``0``: never).
    ``uniform`` (``mode == 2``, no holes): also the run's uniform samples, at ``k tau``
    over its duration, bitwise those of a uniform run to the same end.
    ``st`` ends as `simulate_two_kernel` leaves it; ``U`` as `tangent_two_kernel` does.

    Returns ``(pp_times, n_pp_run, b_time, b_part, b_x, b_y, b_sin, sample_times, samples,
    t_end, status, log_scale, n_rescaled, n_pp_tangent, t_end_tangent, status_tangent,
    status_continuation, escape, uniform_times, uniform_samples)``: ``pp_times[:n_pp_run]``
    are the run's disk-disk times, ``pp_times`` with the continuation's after them; the
    uniform samples are empty unless ``uniform``. ``wall``: another table (as in
    `simulate_two_kernel`; no holes).
    """
    tan = tg.tangent_state(U, mode, n_steps, tau, max_ev_tan, np.int64(0))
    escape = np.array([np.inf, -1.0])
    on = uniform and mode == 2 and holes is None
    u_times, u_samples = ob.new_samples(n_steps + 2 if on else 0)
    u_cnt = np.zeros(3, dtype=np.int64)
    u_cnt[1] = 1 if on else 0
    u_cnt[2] = -1
    if wall is not None:
        logs, stimes, samples, cnt, fin, tan, status = _run(
            st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
            stall_dt, False, True, tan, (t_continue, max_events), None,
            (u_times, u_samples, u_cnt), (wall, np.zeros(4)))
    elif holes is None:
        logs, stimes, samples, cnt, fin, tan, status = _run(
            st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
            stall_dt, False, True, tan, (t_continue, max_events), None,
            (u_times, u_samples, u_cnt))
    else:
        logs, stimes, samples, cnt, fin, tan, status = _run(
            st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap, max_events,
            stall_dt, False, True, tan, None, (holes, escape))
    pp, bt, bp, bx, by, bs, _, _ = logs
    _, log_scale, tgi, tgf, _, _, _ = tan
    n_pp_run = cnt[N_PP_RUN] if status == ob.DONE else cnt[N_PP]
    n_b = cnt[N_B]
    t_end = fin[0] if status == ob.DONE else (t_max if mode < 2 else np.inf)
    k = cnt[K] if escape[1] >= 0.0 else stimes.shape[0]
    ku = u_cnt[0]
    return (pp[: cnt[N_PP]], n_pp_run, bt[:n_b], bp[:n_b], bx[:n_b], by[:n_b], bs[:n_b],
            stimes[:k], samples[:k], t_end, status, log_scale, tgi[tg.N_RESC], tgi[tg.N_PERT],
            tgf[tg.T_PREV], tgi[tg.TAN_STATUS], cnt[CONT_STATUS], escape, u_times[:ku],
            u_samples[:ku])


@njit(cache=True, error_model="numpy")
def tangent_two_kernel(st, rho, sigma, rule, mode, n_steps, tau, U, max_events, n_orth,
                       wall=None):
    """Carry the tangent vectors ``U`` (m, 8) along the two-disk trajectory from ``st``.

    ``mode`` 1: up to ``n_steps * tau``; mode 2: through ``n_steps`` of the paper's
    collision-truncated steps (``t_k = min(t_{k-1} + tau, next event)``). Events at
    times ``<= t_end`` are applied, then everything flies on to ``t_end``. ``U`` and ``st``
    are updated in place; ``U[j]`` is rescaled now and then and ``log_scale[j]`` collects
    the logarithms of the factors taken out. With ``n_orth > 0`` (mode 1 only) the rows are
    re-orthonormalised by Gram-Schmidt at ``n_orth`` equally spaced times, the last at
    ``t_end`` (for the spectrum: then ``log_scale[j]`` sums ``log |R_jj|``).

    ``wall``: another table (as in `simulate_two_kernel`).

    Returns ``(log_scale, n_rescaled, n_pp, t_end, status)``.
    """
    tan = tg.tangent_state(U, mode, n_steps, tau, max_events, n_orth)
    if wall is None:
        _run(st, rho, sigma, rule, 0.0, mode, n_steps, tau, 0, 0, 0, max_events, 0.0, False,
             False, tan, None, None)
    else:
        _run(st, rho, sigma, rule, 0.0, mode, n_steps, tau, 0, 0, 0, max_events, 0.0, False,
             False, tan, None, None, None, (wall, np.zeros(4)))
    _, log_scale, tgi, tgf, _, _, _ = tan
    # the state flies on to the end, as the vectors did
    dt = tgf[tg.T_PREV] - st[0]
    for o in (1, 5):
        st[o] += st[o + 2] * dt
        st[o + 1] += st[o + 3] * dt
    st[0] = tgf[tg.T_PREV]
    return log_scale, tgi[tg.N_RESC], tgi[tg.N_PERT], tgf[tg.T_PREV], tgi[tg.TAN_STATUS]


@njit(cache=True, error_model="numpy")
def fresh_partner_tangent_two_kernel(st, rho, sigma, n_steps, tau, U, max_events):
    """`tangent_two_kernel` (the paper's steps, the mirror rule) with disk 1's deviation set
    to zero just before every disk-disk collision: the two disks as the scatter model sees
    them, where each collision meets a partner that carries no memory of the earlier ones
    (docs/scatter.md). The same event loop (`drive`), with the tangent observer's
    ``FRESH_PARTNER`` switch on. Returns ``(log_scale, n_rescaled, n_pp, t_end,
    status)``."""
    # (int64 arguments, not literals: the loop and its helpers compile once for every
    # tangent kernel)
    mirror, paper = np.int64(0), np.int64(2)
    tan = tg.tangent_state(U, paper, n_steps, tau, max_events, np.int64(0))
    tan[2][tg.FRESH_PARTNER] = 1
    _run(st, rho, sigma, mirror, 0.0, paper, n_steps, tau, 0, 0, 0, max_events, 0.0, False,
         False, tan, None, None)
    _, log_scale, tgi, tgf, _, _, _ = tan
    return log_scale, tgi[tg.N_RESC], tgi[tg.N_PERT], tgf[tg.T_PREV], tgi[tg.TAN_STATUS]

