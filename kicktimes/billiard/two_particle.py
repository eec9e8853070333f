"""Event-driven simulation of two equal hard disks in the unit circular table.

The kernel advances from event to event (boundary collision of either disk, disk-disk
collision) with exact collision times; samples at fixed times are interpolated along the
free flight between events. Nothing is ever stepped through time and tested for overlap.

State layout used by every kernel here (flat float64 arrays, so numba keeps them in
registers and the Lyapunov twin runs can reuse the same functions):

* ``st = [t, x0, y0, vx0, vy0, x1, y1, vx1, vy1, c, e0]`` — current time, both disks,
  the Kahan compensation ``c`` of the clock and the initial kinetic energy ``e0``;
* ``ev = [tb0, tb1, tpp]`` — times *from now* to the next boundary collision of each
  disk and to the next disk-disk collision (``inf`` if none is scheduled);
* ``cnt = [n_pp, n_boundary, n_boundary_0, n_boundary_1, seq_hash]`` — event counters
  and an order-sensitive hash of the event sequence (used to tell whether a reference
  and a twin trajectory have processed the same collisions).

The kernels are compiled with ``error_model="numpy"`` (no zero test before each division;
see `kicktimes.billiard.geometry`): every divisor is a non-zero radius, a contact distance
``2 r``, a speed of a disk at a wall, or the initial energy, which the input checks make
positive.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numba import njit

from kicktimes.billiard import checks as chk
from kicktimes.billiard.checks import STALL_EVENTS
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
from kicktimes.billiard.runs import BoundaryLog, TwoParticleRun

HASH_MOD = 2305843009213693951  # 2**61 - 1, keeps seq_hash * 8 inside int64


@njit(cache=True, inline="always", error_model="numpy")
def init_events_two(st, ev, rho, sigma):
    """Fill ``ev`` with the times from now to the next events of the state ``st``."""
    ev[0] = boundary_hit_time(st[1], st[2], st[3], st[4], rho)
    ev[1] = boundary_hit_time(st[5], st[6], st[7], st[8], rho)
    ev[2] = pair_hit_time(st[1] - st[5], st[2] - st[6], st[3] - st[7], st[4] - st[8], sigma)


@njit(cache=True, inline="always", error_model="numpy")
def drift_two(st, ev, dt):
    """Free flight of both disks for ``dt``; the clock is summed with Kahan compensation.

    Event times are kept relative to the current time: absolute times lose digits as
    the clock grows (at t ~ 1e6 their spacing is 1e-10, enough to make disks overlap).
    """
    st[1] += st[3] * dt
    st[2] += st[4] * dt
    st[5] += st[7] * dt
    st[6] += st[8] * dt
    ev[0] -= dt
    ev[1] -= dt
    ev[2] -= dt
    y = dt - st[9]
    t = st[0] + y
    st[9] = (t - st[0]) - y
    st[0] = t


# inlined (numba IR): as a call, every event spilled the loop's state around it (2% of a run)
@njit(cache=True, inline="always", error_model="numpy")
def wall_event(x, y, vx, vy, rho, rule):
    """Boundary collision of a disk at ``(x, y)`` on ``|x| = rho`` (up to the flight's round-off).

    Returns ``(x, y, vx, vy, t_next, sin_theta)``: the contact put back on the circle, the
    outgoing velocity, the time from now to the disk's next boundary collision and the
    incoming ``sin_theta``. Plain floats in and out, so that the event loop keeps the state
    in registers and `process_event_two` (array state) shares the same arithmetic.
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


@njit(cache=True, error_model="numpy")
def pair_event(x0, y0, vx0, vy0, x1, y1, vx1, vy1, rule):
    """Velocities ``(vx0, vy0, vx1, vy1)`` after a disk-disk collision of disks in contact."""
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
    return collide_elastic(vx0, vy0, vx1, vy1, nx, ny)


@njit(cache=True, error_model="numpy")
def anchor_energy(vx0, vy0, vx1, vy1, e0):
    """The four velocity components rescaled to kinetic energy ``e0`` (one Newton step).

    Correcting each event relative to the previous one would let the rounding bias of
    10^6 events accumulate to 1e-10; anchoring to the initial value does not.
    """
    e = vx0 * vx0 + vy0 * vy0 + vx1 * vx1 + vy1 * vy1
    f = 1.5 - 0.5 * e / e0
    return vx0 * f, vy0 * f, vx1 * f, vy1 * f


@njit(cache=True, error_model="numpy")
def process_event_two(st, ev, k, rho, sigma, rule):
    """Fly both disks to event ``k`` and apply it; returns the incoming ``sin_theta``.

    ``k`` is 0 or 1 for a boundary collision of that disk and 2 for a disk-disk
    collision (which returns 0). Updates ``ev``. The array-state form of the event loop
    of `simulate_two_kernel`, for the Lyapunov kernels (same arithmetic, same bits).
    """
    drift_two(st, ev, ev[k])
    sin_theta = 0.0
    if k < 2:
        o = 1 + 4 * k
        x, y, vx, vy, t_next, sin_theta = wall_event(st[o], st[o + 1], st[o + 2], st[o + 3],
                                                     rho, rule)
        st[o] = x
        st[o + 1] = y
        st[o + 2] = vx
        st[o + 3] = vy
        ev[k] = t_next
    else:
        a, b, c, d = pair_event(st[1], st[2], st[3], st[4], st[5], st[6], st[7], st[8], rule)
        st[3] = a
        st[4] = b
        st[7] = c
        st[8] = d
        ev[0] = boundary_hit_time(st[1], st[2], a, b, rho)
        ev[1] = boundary_hit_time(st[5], st[6], c, d, rho)
    if rule != 0:
        st[3], st[4], st[7], st[8] = anchor_energy(st[3], st[4], st[7], st[8], st[10])
    # both kinds of event change the pair's relative motion
    ev[2] = pair_hit_time(st[1] - st[5], st[2] - st[6], st[3] - st[7], st[4] - st[8], sigma)
    return sin_theta


@njit(cache=True, inline="always", error_model="numpy")
def next_event_two(ev):
    """Index (0, 1: boundary of that disk; 2: disk-disk) and time to the next event."""
    k = 0
    dt = ev[0]
    if ev[1] < dt:
        k = 1
        dt = ev[1]
    if ev[2] < dt:
        k = 2
        dt = ev[2]
    return k, dt


@njit(cache=True, inline="always", error_model="numpy")
def finish_at(st, ev, t_end):
    """Fly to ``t_end`` (no event before it) and set the clock to exactly ``t_end``."""
    drift_two(st, ev, t_end - st[0])
    st[0] = t_end
    st[9] = 0.0


@njit(cache=True, error_model="numpy")
def _grow_to(a, limit):
    """``a`` copied into a buffer twice as long, but no longer than ``limit`` (> len(a)).

    An element loop, not ``out[:n] = a``: numba compiles array-to-slice assignment with
    its shape-mismatch error message, string formatting included (seconds of compile time).
    """
    out = np.empty(min(2 * a.shape[0] + 16, limit), dtype=a.dtype)
    for i in range(a.shape[0]):
        out[i] = a[i]
    return out


@njit(cache=True, error_model="numpy")
def _grow_rows_to(a, limit):
    """Rows of ``a`` copied into a buffer twice as long, but no longer than ``limit``."""
    out = np.empty((min(2 * a.shape[0] + 16, limit), a.shape[1]), dtype=a.dtype)
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[i, j] = a[i, j]
    return out


# status codes of the event loops
DONE, FULL, STALLED, OVER_BUDGET = 0, 1, 2, 3


@njit(cache=True, error_model="numpy")
def _stalled(times, n, stall_dt):
    """True if the last `STALL_EVENTS` of the ``n`` logged ``times`` are less than
    ``stall_dt`` apart on average: the run makes no progress (e.g. disks jammed against
    the wall). Legitimate collisions are at least a grazing chord, ``2e-4 rho / |v|``,
    apart, five orders more than ``stall_dt``."""
    if n < STALL_EVENTS:
        return False
    return times[n - 1] - times[n - STALL_EVENTS] < STALL_EVENTS * stall_dt


@njit(cache=True, error_model="numpy")
def _event_loop_two(st, ev, rho, sigma, rule, t_end, mode, tau, track, pp, bt, bp, bx, by, bs,
                    stimes, samples, cnt, next_s, log_pp, ppl):
    """The logging/sampling event loop; returns `DONE` or `FULL` (a buffer is full).

    The state lives in local variables for the whole loop (read from ``st``/``ev`` on
    entry, written back on exit): kept in arrays, every event stored and reloaded it
    through memory, since numba cannot prove that the output buffers do not alias it. The
    only per-event writes are the output. The arithmetic is `process_event_two`'s (the
    same helpers), so the results are the same to the bit.

    Growing a buffer reassigns the array, and an array reassigned inside a numba loop
    costs reference counting on every iteration (it halved the speed): so this loop
    only detects a full buffer and returns, and the caller grows it outside (and checks
    the budget and for stalls there, at no cost per event). ``cnt = [n_pp, n_b, k]``
    and ``next_s[0]`` (the next sample time) carry the loop's position between calls.
    With ``log_pp`` every disk-disk collision also fills a row of ``ppl``
    (``runs.PP_LOG_COLUMNS``); only disk-disk events pay for the check.
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
    n_pp = cnt[0]
    n_b = cnt[1]
    k = cnt[2]
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
        # samples strictly before the next event lie on the current free flight
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
            status = DONE
            break
        if ke == 2:
            if n_pp >= pp_cap:
                break
            if log_pp:
                ppl[n_pp, 4] = vx0
                ppl[n_pp, 5] = vy0
                ppl[n_pp, 6] = vx1
                ppl[n_pp, 7] = vy1
        elif n_b >= b_cap:
            break
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
            # one call site for both disks: half the code of two
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
        # both kinds of event change the pair's relative motion
        tpp = pair_hit_time(x0 - x1, y0 - y1, vx0 - vx1, vy0 - vy1, sigma)
        if ke == 2:
            pp[n_pp] = t
            if log_pp:
                ppl[n_pp, 0] = x0
                ppl[n_pp, 1] = y0
                ppl[n_pp, 2] = x1
                ppl[n_pp, 3] = y1
                ppl[n_pp, 8] = vx0
                ppl[n_pp, 9] = vy0
                ppl[n_pp, 10] = vx1
                ppl[n_pp, 11] = vy1
            n_pp += 1
        else:
            bt[n_b] = t
            bp[n_b] = ke
            bx[n_b] = x1 if ke else x0
            by[n_b] = y1 if ke else y0
            bs[n_b] = sin_theta
            n_b += 1
        if mode == 2 and k < ns:
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
    cnt[0] = n_pp
    cnt[1] = n_b
    cnt[2] = k
    next_s[0] = ns_next
    return status


@njit(cache=True, error_model="numpy")
def simulate_two_kernel(st, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap, b_cap,
                        max_events, stall_dt, log_pp=False):
    """Run the two-disk billiard, logging every event and sampling the tracked disk.

    ``st`` is ``[t, x0, y0, vx0, vy0, x1, y1, vx1, vy1, clock compensation, energy]``.
    ``mode``: 0 no samples (run to ``t_max``), 1 uniform samples at ``k tau`` (run to
    ``t_max``), 2 the paper's collision-truncated steps (run until ``n_steps`` are done).
    Samples are interpolated along the free flight, inside the event loop. The run stops
    early with status `OVER_BUDGET` after ``max_events`` collisions, or `STALLED` (see
    `_event_loop_two`); ``st`` then holds the state where it stopped.

    Returns ``(pp_times, b_time, b_part, b_x, b_y, b_sin, sample_times, samples, t_end,
    pp_log, status)``; ``pp_log`` has a row per disk-disk collision if ``log_pp``, else none.
    """
    ev = np.empty(3)
    init_events_two(st, ev, rho, sigma)
    pp = np.empty(min(pp_cap, max_events + 1))
    ppl = np.empty((pp.shape[0] if log_pp else 0, 12))
    b_cap = min(b_cap, max_events + 1)
    bt = np.empty(b_cap)
    bp = np.empty(b_cap, dtype=np.int8)
    bx = np.empty(b_cap)
    by = np.empty(b_cap)
    bs = np.empty(b_cap)
    ns = n_steps + 1 if mode > 0 else 0
    stimes = np.empty(ns)
    samples = np.empty((ns, 2))
    cnt = np.zeros(3, dtype=np.int64)
    next_s = np.zeros(1)
    t_end = t_max if mode < 2 else np.inf
    while True:
        status = _event_loop_two(st, ev, rho, sigma, rule, t_end, mode, tau, track, pp,
                                 bt, bp, bx, by, bs, stimes, samples, cnt, next_s, log_pp, ppl)
        # budget and stalls are checked only here, when a buffer is full (or at the end):
        # nothing in the hot loop
        if _stalled(pp, cnt[0], stall_dt) or _stalled(bt, cnt[1], stall_dt):
            status = STALLED
            break
        if status != FULL:
            break
        room = max_events - cnt[0] - cnt[1]
        if room <= 0:
            status = OVER_BUDGET
            break
        if cnt[0] >= pp.shape[0]:
            limit = pp.shape[0] + room
            pp = _grow_to(pp, limit)
            if log_pp:
                ppl = _grow_rows_to(ppl, limit)
        if cnt[1] >= bt.shape[0]:
            limit = bt.shape[0] + room
            bt = _grow_to(bt, limit)
            bp = _grow_to(bp, limit)
            bx = _grow_to(bx, limit)
            by = _grow_to(by, limit)
            bs = _grow_to(bs, limit)
    if status == DONE:
        if mode == 2:
            t_end = stimes[ns - 1]
        finish_at(st, ev, t_end)
    n_pp = cnt[0]
    n_b = cnt[1]
    # views, not copies: the buffers are at most about twice the size needed
    return (pp[:n_pp], bt[:n_b], bp[:n_b], bx[:n_b], by[:n_b], bs[:n_b], stimes, samples, t_end,
            ppl[: n_pp if log_pp else 0], status)


def raise_for_status(status: int, st_time: float, n_events: int, *, max_events: int,
                     name: str, where: str) -> None:
    """Turn a kernel's early stop into a ValueError naming the input (no-op for `DONE`)."""
    if status == OVER_BUDGET:
        raise ValueError(
            f"max_events: the run needed more than max_events={max_events} collisions "
            f"(stopped at t = {float(st_time)!r}); a disk grazing the wall makes one collision "
            f"every 2e-4 (1 - r) / |v|; pass a larger max_events or a shorter run"
        )
    if status == STALLED:
        raise ValueError(
            f"{name}: the run makes no progress: {STALL_EVENTS} collisions in less than "
            f"{STALL_EVENTS} x 1e-9 (1 - r) / |v| at t = {float(st_time)!r} ({n_events} collisions "
            f"so far; {where}); the state is stuck (e.g. disks jammed against the wall)"
        )


def check_two_particle_ic(ic, r: float, rule: str, name: str = "ic") -> np.ndarray:
    """Validate a two-disk initial condition; returns a float64 (2, 4) copy."""
    arr = chk.check_state(name, ic, (2, 4))
    rho = 1.0 - r
    # plain floats: the checks run on every simulator call, and numpy scalars cost ~10x
    rows = arr.tolist()
    for i, (x, y, vx, vy) in enumerate(rows):
        which = "disk 0" if i == 0 else "disk 1"
        chk.check_inside(name, x, y, rho, r, which)
        if rule == "mirror":
            chk.check_unit_speed(name, vx, vy, which)
        else:
            chk.check_speed(name, vx, vy, which, allow_zero=True)
    (x0, y0, vx0, vy0), (x1, y1, vx1, vy1) = rows
    if rule != "mirror" and not (vx0 or vy0 or vx1 or vy1):
        raise ValueError(f"{name}: both disks are at rest; give a non-zero velocity")
    gap = math.hypot(x0 - x1, y0 - y1)
    if gap < 2.0 * r - chk.CONTACT_TOL:
        raise ValueError(
            f"{name}: the disks overlap (centre distance {gap:.15g} < 2 r = {2 * r:.15g})"
        )
    return arr


def simulate_two_particle(ic, r, *, t_max=None, rule="mirror", sampling="uniform", n_steps=None,
                          tau=None, track=0, seed=None, max_events=None,
                          log_collisions=False) -> TwoParticleRun:
    """Simulate two disks of radius ``r`` in the unit circular table.

    Event-driven and exact: the disks move freely between collisions whose times are
    roots of quadratics (docs/architecture.md); boundary collisions are specular, disk-disk
    collisions follow ``rule``.

    Parameters
    ----------
    ic : array_like, shape (2, 4)
        Rows ``(x, y, vx, vy)`` of disk 0 and disk 1. Centres must lie in the table
        (``|x| <= 1 - r``) without overlap; speeds must be 1 under the mirror rule.
    r : float
        Disk radius, ``0 < r < 0.5``.
    t_max : float, optional
        End time. With ``n_steps`` and ``tau`` (uniform sampling) it defaults to
        ``n_steps * tau``; it must not be given with ``sampling="paper"``.
    rule : {"mirror", "elastic"}
        Disk-disk collision rule: ``"mirror"`` (the paper's: each disk reflects off the
        other as off a fixed wall, speeds stay 1) or ``"elastic"`` (equal masses).
    sampling : {"uniform", "paper"}
        ``"uniform"``: the tracked disk's centre at ``t_k = k tau``, ``k = 0..n_steps``.
        ``"paper"``: step ``k`` ends at ``min(t_{k-1} + tau, next collision)``, samples at
        step ends; the run ends after ``n_steps`` steps (``t_max`` is that time).
    n_steps : int, optional
        Number of sampling steps (``>= 1``).
    tau : float, optional
        Step length (``> 0``).
    track : {0, 1}
        The disk whose centre is sampled.
    seed : int, optional
        Recorded in the run's metadata (the simulation itself is deterministic).
    max_events : int, optional
        Stop with a ValueError after this many collisions (``>= 1``). The default is a
        hundred times the expected number plus 10^6, at most 2e7; a run expected to need
        more than 5e6 is refused unless ``max_events`` is given.
    log_collisions : bool
        Also log every disk-disk collision: contact centres and both velocities before
        and after (``run.pp_log``, ``run.collisions`` with the contact normal).

    Returns
    -------
    TwoParticleRun
        ``pp_times``, ``boundary`` (DataFrame ``time, particle, s, sin_theta``),
        ``final_state``, ``sample_times``, ``samples`` and the parameters.

    Notes
    -----
    ``sin_theta = L / (1 - r)`` is the tangential component of the incoming unit
    velocity at a boundary collision (``L = x vy - y vx``); ``s`` is the polar angle of
    the contact point in ``[0, 2 pi)``. Events at exactly ``t_max`` are included.

    A contact within 5e-5 rad of tangent (an exactly tangent one included) slides on
    along the wall instead of being reflected: the disk leaves along the
    whispering-gallery chord of angle ``2e-4`` (`kicktimes.billiard.geometry.graze`).
    Speeds must be 1 (mirror) or 0 or in ``[1e-6, 1e6]`` (elastic); ``t_max``, ``tau`` and
    ``n_steps * tau`` at most 1e12, ``n_steps`` at most 1e8.

    Raises
    ------
    ValueError
        For arguments out of range, and when the run exceeds ``max_events`` or stops
        making progress (``10^4`` consecutive collisions at one instant).

    Warns
    -----
    RuntimeWarning
        A ``sampling="paper"`` run that covers no time (``t_max = 0``): every one of its
        ``n_steps`` steps ended at a collision at ``t = 0`` (disks starting in contact with
        each other or the wall, e.g. pinched between them).

    Examples
    --------
    >>> from kicktimes import simulate_two_particle, initial_conditions
    >>> ic = initial_conditions(1, 0.02, seed=1)[0]
    >>> run = simulate_two_particle(ic, 0.02, t_max=200.0)
    >>> bool((run.pp_times > 0).all() and (run.pp_times <= 200.0).all())
    True
    """
    r = chk.check_real("r", r, low=0.0, high=0.5)
    chk.check_choice("rule", rule, chk.RULES)
    t_max, n_steps, tau, mode = chk.check_sampling(t_max, n_steps, tau, sampling)
    track = chk.check_int("track", track, low=0)
    if track > 1:
        raise ValueError(f"track must be 0 or 1, got {track}")
    ic = check_two_particle_ic(ic, r, rule)
    if not isinstance(log_collisions, bool | np.bool_):
        raise TypeError(f"log_collisions must be a bool, got {type(log_collisions).__name__}")
    args = kernel_args(ic, r, rule, mode, t_max, n_steps, tau, track, max_events)
    out = simulate_two_kernel(*args, bool(log_collisions))
    return two_particle_run(out, args, r=r, rule=rule, sampling=sampling, tau=tau,
                            n_steps=n_steps, ic=ic, track=track, seed=seed, name="ic")


def kernel_args(ic, r, rule, mode, t_max, n_steps, tau, track, max_events) -> tuple:
    """`simulate_two_kernel`'s arguments (all but ``log_pp``) for validated inputs.

    ``ic``, ``r``, ``rule``, ``track`` validated, ``(t_max, n_steps, tau, mode)`` from
    `check_sampling`, ``max_events`` as given (``None``: the default budget). Shared with
    the one-pass FTLE (`kicktimes.diagnostics.lyapunov`), which must run the very same
    simulation.
    """
    x0, y0, vx0, vy0, x1, y1, vx1, vy1 = ic.ravel().tolist()
    # the initial kinetic energy, summed in this order (numpy's, bits of older runs kept)
    e0 = vx0 * vx0 + vy0 * vy0 + vx1 * vx1 + vy1 * vy1
    st = np.array([0.0, x0, y0, vx0, vy0, x1, y1, vx1, vy1, 0.0, e0])
    horizon = t_max if mode < 2 else n_steps * tau
    rho = 1.0 - r
    # the largest speed a disk can reach: all the kinetic energy in one disk
    speed = 1.0 if rule == "mirror" else math.sqrt(e0)
    max_events = chk.event_budget(max_events, horizon=horizon,
                                  horizon_name="t_max" if mode < 2 else "n_steps * tau",
                                  speed=speed, rho=rho, n_disks=2)
    # capacities are only a first guess: the kernel grows its buffers when needed
    b_cap = int(3.0 * speed * horizon) + 64
    pp_cap = int(20.0 * r * speed * horizon) + 16
    return (st, rho, 2.0 * r, chk.RULES[rule], 0.0 if mode == 2 else t_max, mode,
            n_steps if n_steps is not None else 0, tau if tau is not None else 0.0, track,
            pp_cap, b_cap, max_events, chk.stall_time(rho, speed))


def two_particle_run(out, args, *, r, rule, sampling, tau, n_steps, ic, track, seed,
                     name) -> TwoParticleRun:
    """The `TwoParticleRun` of `simulate_two_kernel`'s output ``out`` for ``args``
    (`kernel_args`); raises the ValueError of an early stop, naming the argument ``name``."""
    pp, bt, bp, bx, by, bs, stimes, samples, t_end, ppl, status = out
    st, mode, max_events = args[0], args[5], args[11]
    if status != DONE:  # (the message is formatted only when it is needed)
        raise_for_status(status, st[0], pp.shape[0] + bt.shape[0], max_events=max_events,
                         name=name, where=f"disks at ({st[1]:.6g}, {st[2]:.6g}) and "
                                          f"({st[5]:.6g}, {st[6]:.6g}), r={r!r}")
    if mode == 2 and t_end == 0.0:
        # every paper step was cut short by a collision at t = 0 (fewer than the STALL_EVENTS
        # a stuck state needs to end in the stall error)
        warnings.warn(
            f"{name}: the paper-sampled run covers no time (t_max = 0.0): all n_steps = "
            f"{n_steps} steps ended at collisions at t = 0 ({pp.shape[0]} disk-disk, "
            f"{bt.shape[0]} boundary), the disks starting in contact with each other or the "
            "wall; more steps may resolve the contacts (a state that stays stuck ends in an "
            f"error after {STALL_EVENTS} collisions), or start the disks apart",
            RuntimeWarning, stacklevel=3,
        )
    return TwoParticleRun(
        r=r,
        t_max=float(t_end),
        sampling=sampling if mode > 0 else None,
        tau=tau,
        n_steps=n_steps,
        ic=ic,
        final_state=st[1:9].reshape(2, 4).copy(),
        boundary_log=BoundaryLog(bt, bp, bx, by, bs),
        sample_times=stimes,
        samples=samples,
        seed=seed,
        rule=rule,
        track=track,
        pp_times=pp,
        pp_log=ppl,
    )
