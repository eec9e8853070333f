"""Finite-time Lyapunov exponents by Benettin's twin-trajectory method.

A twin starts ``d0`` away from the reference in the tracked disk's position. At every
sample time ``t_k`` the twin is compared with the reference: the separation ``d_k`` of the
tracked disk's centres is measured, ``log(d_k / d0)`` is added to a running sum and the
twin's whole phase-space difference is scaled by ``f = d0 / d_k`` (positions of every
disk; velocity differences linearly, then renormalised to the rescaled speed, which scales
the velocity *angle* difference to first order). ``lambda = sum log(d_k/d0) / t`` with
``t`` the time of the last renormalisation.

One guard makes this robust: the factor is ``f = d0 / max(d_k, |dx_i| for every disk i)``,
so no disk's position difference is ever blown up beyond ``d0`` (with two disks, or with
the paper's ``|dx|`` measure, ``d_k`` alone can be tiny while other components are not;
scaling by ``d0 / d_k`` would then throw the twin out of the table). The sum then
telescopes over the actual growth factors, ``log(d_k / d_{k-1}^+)`` with ``d^+`` the
measured separation right after the previous rescaling; it equals ``log(d_k / d0)`` in the
ordinary case ``d^+ = d0``.

Billiard flows are discontinuous. When the reference and the twin straddle a collision
at ``t_k`` (one has processed it, the other not yet), their difference is not small even
though the trajectories are close, so the renormalisation is *deferred* to the next sample
at which both have processed the same sequence of events (compared by event counts and
an order-sensitive hash). A twin that has genuinely left the reference (it missed a
disk-disk collision the reference had) never resynchronises by itself: after ``max_defer``
consecutive deferrals the renormalisation is *forced* and its (large) logarithm counted;
``n_forced`` reports how often that happened.

Kicked one-disk billiards share their kicks with the twin: the same times and the same
angles (common random numbers); otherwise a kick alone would separate them by O(1).

The paper's variant (``variant="paper"``) runs two twins, offset by ``d0`` in ``x`` and in
``y``, measures ``|dx|`` and ``|dy|`` separately and reports ``max(lambda_x, lambda_y)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from kicktimes.billiard import _checks as chk
from kicktimes.billiard.geometry import boundary_hit_time, pair_hit_time
from kicktimes.billiard.one_particle import (
    KICK_ANGLES,
    check_one_particle_state,
    draw_kick_angles,
    next_event_one,
    process_event_one,
    resolve_kicks,
)
from kicktimes.billiard.runs import OneParticleRun, TwoParticleRun
from kicktimes.billiard.two_particle import (
    HASH_MOD,
    check_two_particle_ic,
    init_events_two,
    next_event_two,
    process_event_two,
)

VARIANTS = ("norm", "paper")


@dataclass(frozen=True)
class LyapunovResult:
    """A finite-time Lyapunov exponent and how it was obtained.

    Attributes
    ----------
    lam : float
        The exponent (per unit time): the 2-norm exponent, or ``max(lam_x, lam_y)`` for
        the paper's variant.
    lam_x, lam_y : float
        The paper variant's parts (``nan`` for ``variant="norm"``).
    n_renorm : int
        Renormalisations counted (summed over twins).
    n_forced : int
        Renormalisations forced after ``max_defer`` deferrals (twin left the reference).
    n_deferred : int
        Samples at which a renormalisation was deferred across a collision.
    total_time : float
        The time over which the logarithms were summed (the last renormalisation).
    d0 : float
    variant : str
    """

    lam: float
    lam_x: float
    lam_y: float
    n_renorm: int
    n_forced: int
    n_deferred: int
    total_time: float
    d0: float
    variant: str


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
                    max_defer):
    """Benettin FTLE for the two-disk billiard with ``len(offsets)`` twins.

    Returns ``(log_sum, n_renorm, n_forced, n_deferred, t_last)`` per twin.
    """
    m = offsets.shape[0]
    nst = st0.shape[0]
    ref = st0.copy()
    ev_ref = np.empty(3)
    init_events_two(ref, ev_ref, rho, sigma)
    cnt_ref = np.zeros(5, dtype=np.int64)
    tw = np.empty((m, nst))
    ev_tw = np.empty((m, 3))
    cnt_tw = np.zeros((m, 5), dtype=np.int64)
    o = 1 + 4 * track
    for j in range(m):
        tw[j] = st0
        tw[j, o] += offsets[j, 0]
        tw[j, o + 1] += offsets[j, 1]
        init_events_two(tw[j], ev_tw[j], rho, sigma)
    log_sum = np.zeros(m)
    n_renorm = np.zeros(m, dtype=np.int64)
    n_forced = np.zeros(m, dtype=np.int64)
    n_deferred = np.zeros(m, dtype=np.int64)
    n_defer_now = np.zeros(m, dtype=np.int64)
    t_last = np.zeros(m)
    m_plus = np.full(m, d0)  # measured separation right after the last renormalisation
    pos = np.empty(4)
    t_prev = 0.0
    for k in range(1, n_steps + 1):
        if mode == 1:
            tk = k * tau
        else:
            tk = min(t_prev + tau, ref[0] + min(ev_ref[0], min(ev_ref[1], ev_ref[2])))
        # the reference: every event at time <= tk, no flight on (positions interpolated)
        while True:
            ke, dt = next_event_two(ev_ref)
            if ref[0] + dt > tk:
                break
            process_event_two(ref, ev_ref, ke, rho, sigma, rule)
            if ke == 2:
                cnt_ref[0] += 1
            else:
                cnt_ref[1] += 1
                cnt_ref[2 + ke] += 1
            cnt_ref[4] = (cnt_ref[4] * 4 + ke + 1) % HASH_MOD
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
                if tw[j, 0] + dt > tk:
                    break
                process_event_two(tw[j], ev_tw[j], ke, rho, sigma, rule)
                if ke == 2:
                    cnt_tw[j, 0] += 1
                else:
                    cnt_tw[j, 1] += 1
                    cnt_tw[j, 2 + ke] += 1
                cnt_tw[j, 4] = (cnt_tw[j, 4] * 4 + ke + 1) % HASH_MOD
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
    return log_sum, n_renorm, n_forced, n_deferred, t_last


@njit(cache=True)
def ftle_one_kernel(st0, rho, kicks, angles, twin_angles, kick_mode, mode, n_steps, tau, offsets,
                    measure, d0, max_defer):
    """Benettin FTLE for the kicked one-disk billiard.

    Twins share the kick times; their kick angles are ``twin_angles[j]`` (equal to
    ``angles`` for common random numbers).
    """
    m = offsets.shape[0]
    nk = kicks.shape[0]
    unit_speed = abs(st0[3] * st0[3] + st0[4] * st0[4] - 1.0) < 1e-12
    ref = st0.copy()
    ev_ref = np.empty(1)
    ev_ref[0] = boundary_hit_time(ref[1], ref[2], ref[3], ref[4], rho)
    cnt_ref = np.zeros(3, dtype=np.int64)
    tw = np.empty((m, st0.shape[0]))
    ev_tw = np.empty((m, 1))
    cnt_tw = np.zeros((m, 3), dtype=np.int64)
    for j in range(m):
        tw[j] = st0
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
    t_prev = 0.0
    for k in range(1, n_steps + 1):
        if mode == 1:
            tk = k * tau
        else:
            _, dtn = next_event_one(ref, ev_ref, kicks, cnt_ref)
            tk = min(t_prev + tau, ref[0] + dtn)
        while True:
            ik = cnt_ref[0]
            is_kick = False
            dt = ev_ref[0]
            if ik < nk and kicks[ik] - ref[0] < dt:
                is_kick = True
                dt = kicks[ik] - ref[0]
            if ref[0] + dt > tk:
                break
            if is_kick:
                process_event_one(ref, ev_ref, True, dt, rho, kicks[ik], angles[ik], kick_mode,
                                  False)
                cnt_ref[0] += 1
                cnt_ref[2] = (cnt_ref[2] * 4 + 4) % HASH_MOD
            else:
                process_event_one(ref, ev_ref, False, dt, rho, 0.0, 0.0, kick_mode, False)
                cnt_ref[1] += 1
                cnt_ref[2] = (cnt_ref[2] * 4 + 1) % HASH_MOD
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
                if tw[j, 0] + dt > tk:
                    break
                if is_kick:
                    process_event_one(tw[j], ev_tw[j], True, dt, rho, kicks[ik],
                                      twin_angles[j, ik], kick_mode, False)
                    cnt_tw[j, 0] += 1
                    cnt_tw[j, 2] = (cnt_tw[j, 2] * 4 + 4) % HASH_MOD
                else:
                    process_event_one(tw[j], ev_tw[j], False, dt, rho, 0.0, 0.0, kick_mode, False)
                    cnt_tw[j, 1] += 1
                    cnt_tw[j, 2] = (cnt_tw[j, 2] * 4 + 1) % HASH_MOD
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
    return log_sum, n_renorm, n_forced, n_deferred, t_last


def _twin_offsets(variant: str, d0: float, ok) -> tuple[np.ndarray, np.ndarray]:
    """Offsets of the twins and what each measures (0: 2-norm, 1: |dx|, 2: |dy|).

    The norm twin is offset along +x (along -x if that leaves the table or overlaps the
    other disk); the paper's twins along +x and +y (or their negatives).
    """
    axes = [(1.0, 0.0)] if variant == "norm" else [(1.0, 0.0), (0.0, 1.0)]
    measure = [0] if variant == "norm" else [1, 2]
    offsets = []
    for ax, ay in axes:
        for sign in (1.0, -1.0):
            off = (sign * d0 * ax, sign * d0 * ay)
            if ok(*off):
                offsets.append(off)
                break
        else:
            raise ValueError(f"d0={d0!r}: no twin offset of that size keeps the disk valid")
    return np.array(offsets), np.array(measure, dtype=np.int64)


def _result(out, variant, d0) -> LyapunovResult:
    log_sum, n_renorm, n_forced, n_deferred, t_last = out
    with np.errstate(invalid="ignore", divide="ignore"):
        lams = np.where(t_last > 0, log_sum / t_last, np.nan)
    if variant == "norm":
        lam, lam_x, lam_y = float(lams[0]), math.nan, math.nan
    else:
        lam_x, lam_y = float(lams[0]), float(lams[1])
        lam = max(lam_x, lam_y) if not (math.isnan(lam_x) or math.isnan(lam_y)) else math.nan
    return LyapunovResult(
        lam=lam, lam_x=lam_x, lam_y=lam_y, n_renorm=int(n_renorm.sum()),
        n_forced=int(n_forced.sum()), n_deferred=int(n_deferred.sum()),
        total_time=float(t_last.max()), d0=d0, variant=variant,
    )


def lyapunov(system, r=None, *, n_steps=None, tau=None, sampling="uniform", rule="mirror",
             track=0, kicks=None, kick_angles=None, kick_angle="uniform", sigma=1.0, rng=None,
             d0=1.0 / 5000.0, variant="norm", max_defer=10, twin_kicks="shared") -> LyapunovResult:
    """Finite-time Lyapunov exponent of a two-disk or a kicked one-disk billiard.

    Parameters
    ----------
    system : array_like or run
        A two-disk initial condition (shape (2, 4)), a one-disk state (shape (4,)), or a
        `TwoParticleRun` / `OneParticleRun`, whose setup (and kicks) is reused.
    r : float
        Disk radius (taken from the run if ``system`` is one).
    n_steps, tau, sampling
        The sample times at which the twins are compared and renormalised, as in the
        simulators (``uniform``: ``t_k = k tau``; ``paper``: collision-truncated steps of
        the reference trajectory).
    rule, track
        Two-disk collision rule and the disk whose position is perturbed and measured.
    kicks, kick_angles, kick_angle, sigma, rng
        One-disk kicks, as in `simulate_one_particle`; reference and twins share the same
        kick times and angles (common random numbers). Angles are drawn from ``rng`` when
        not given.
    d0 : float
        Initial separation and renormalisation length (the paper's 1/5000).
    variant : {"norm", "paper"}
        ``"norm"``: one twin, 2-norm of the position separation. ``"paper"``: twins offset
        in x and in y, separations ``|dx|`` and ``|dy|``, ``lam = max(lam_x, lam_y)``.
    max_defer : int
        Consecutive deferred renormalisations after which one is forced.
    twin_kicks : {"shared", "independent"}
        One-disk only. ``"shared"`` (default, design.md): twins get the reference's kick
        angles, so kicks are common random numbers and only the dynamics between them
        separates the twins. ``"independent"``: each twin draws its own angles from
        ``rng``, so every kick separates the pair by O(1) (each kick then contributes about
        ``log(O(1) / d0)``); the paper does not say which it used, and its agreement
        between kicked and two-disk exponents is what independent angles produce.

    Returns
    -------
    LyapunovResult

    Notes
    -----
    ``lambda = (1/t) sum_k log(d_k / d0)`` over the renormalisations, ``t`` the time of the
    last one (design.md, "Diagnostics"). The reference trajectory is bitwise the one
    `simulate_two_particle` / `simulate_one_particle` compute with the same arguments.

    Examples
    --------
    >>> from kicktimes import initial_conditions
    >>> from kicktimes.diagnostics import lyapunov
    >>> ic = initial_conditions(1, 0.03, seed=3)[0]
    >>> res = lyapunov(ic, 0.03, n_steps=2000, tau=0.2)
    >>> res.lam > 0
    True
    """
    if isinstance(system, TwoParticleRun | OneParticleRun):
        run = system
        if run.sampling is None:
            raise ValueError("system: the run has no sampling (n_steps, tau); the FTLE needs it")
        r, n_steps, tau, sampling = run.r, run.n_steps, run.tau, run.sampling
        if isinstance(run, TwoParticleRun):
            rule, track, system = run.rule, run.track, run.ic
        else:
            # the FTLE covers n_steps samples; a run may have gone on beyond them
            horizon = n_steps * tau
            keep = run.kick_times <= horizon
            kicks, kick_angles = run.kick_times[keep], run.kick_angles[keep]
            kick_angle = run.kick_angle
            sigma = run.sigma if run.sigma is not None else 1.0
            system = run.ic
    chk.check_choice("variant", variant, VARIANTS)
    d0 = chk.check_real("d0", d0, low=0.0, high=0.1)
    max_defer = chk.check_int("max_defer", max_defer, low=0)
    if n_steps is None or tau is None:
        raise ValueError("n_steps (>= 1) and tau (> 0) are required: the FTLE samples the flow")
    _, n_steps, tau, mode = chk.check_sampling(None, n_steps, tau, sampling)
    arr = np.asarray(system, dtype=np.float64)
    if arr.shape == (2, 4):
        r = chk.check_real("r", r, low=0.0, high=0.5)
        chk.check_choice("rule", rule, chk.RULES)
        track = chk.check_int("track", track, low=0)
        if track > 1:
            raise ValueError(f"track must be 0 or 1, got {track}")
        if kicks is not None:
            raise ValueError("kicks apply to a one-disk state (shape (4,)), not to two disks")
        ic = check_two_particle_ic(arr, r, rule, name="system")
        rho, sig = 1.0 - r, 2.0 * r
        o = track

        def ok(dx, dy):
            x, y = ic[o, 0] + dx, ic[o, 1] + dy
            other = ic[1 - o]
            return math.hypot(x, y) <= rho and math.hypot(x - other[0], y - other[1]) >= sig

        offsets, measure = _twin_offsets(variant, d0, ok)
        st = np.zeros(11)
        st[1:9] = ic.ravel()
        st[10] = (ic[:, 2:] ** 2).sum()
        out = ftle_two_kernel(st, rho, sig, chk.RULES[rule], mode, n_steps, tau, track, offsets,
                              measure, d0, max_defer)
        return _result(out, variant, d0)
    if arr.shape != (4,):
        raise ValueError(f"system must have shape (2, 4) or (4,), got {arr.shape}")
    r = chk.check_real("r", r, low=0.0, high=1.0)
    chk.check_choice("kick_angle", kick_angle, KICK_ANGLES)
    state = check_one_particle_state(arr, r, name="system")
    horizon = n_steps * tau
    times, angles, gen = resolve_kicks(kicks, kick_angles, kick_angle=kick_angle, sigma=sigma,
                                       rng=rng, horizon=horizon,
                                       t_max=horizon if mode == 1 else None)
    chk.check_choice("twin_kicks", twin_kicks, ("shared", "independent"))
    rho = 1.0 - r
    offsets, measure = _twin_offsets(
        variant, d0, lambda dx, dy: math.hypot(state[0] + dx, state[1] + dy) <= rho
    )
    if twin_kicks == "shared":
        twin_angles = np.broadcast_to(angles, (offsets.shape[0], angles.size)).copy()
    else:
        gen = gen if gen is not None else np.random.default_rng(rng)
        twin_angles = np.stack([draw_kick_angles(times.size, kick_angle, sigma, gen)
                                for _ in range(offsets.shape[0])])
    st = np.zeros(7)
    st[1:5] = state
    st[6] = state[2] ** 2 + state[3] ** 2
    out = ftle_one_kernel(st, rho, times, angles, twin_angles, KICK_ANGLES[kick_angle], mode,
                          n_steps, tau, offsets, measure, d0, max_defer)
    return _result(out, variant, d0)
