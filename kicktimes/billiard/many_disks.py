"""N hard disks in the unit circular table: the Python layer of the N-disk engine.

`simulate_disks` checks its arguments (`check_disks`), sets up the engine
(`kicktimes.billiard.kernels.disks`), runs its event loop, growing the logs as they fill,
and returns a `DisksRun`. docs/disks.md describes the algorithm and its checks.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kicktimes.billiard import checks as chk
from kicktimes.billiard.disks_run import DisksRun
from kicktimes.billiard.kernels import cells
from kicktimes.billiard.kernels import disks as kd
from kicktimes.billiard.kernels.observe import DONE, FULL, OVER_BUDGET, STALLED
from kicktimes.stats.enskog import PACKING_MAX, contact_value

__all__ = ["check_disks", "engine_run", "expected_collisions", "raise_for_status",
           "simulate_disks"]

#: most disks a run takes (int32 indices; about 180 bytes each)
N_DISKS_MAX = 10**7
#: bytes of the log per disk-disk collision (time, i, j)
LOG_BYTES = 16
#: the engine renumbers its disks in space (`kd.relabel`) every this many disk-disk
#: collisions per disk, from this many disks on (fewer fit in the core's cache anyway)
REORDER_SWEEPS = 10
REORDER_MIN_DISKS = 2048


def _memory_bytes() -> float:
    try:
        return float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 8e9


def check_radii_of(r, n: int, name: str = "r") -> np.ndarray:
    """One radius per disk from ``r`` (a number, or ``n`` numbers), each in ``(0, 1)``, with a
    packing ``sum r_i^2`` below the densest, ``pi / sqrt(12)``."""
    if np.ndim(r) == 0:
        radii = np.full(n, chk.check_real(name, r, low=0.0, high=1.0))
    else:
        try:
            radii = np.array(r, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"{name} must be a number or one number per disk") from None
        if radii.shape != (n,):
            raise ValueError(f"{name} must be one radius or {n} radii (one per disk), got "
                             f"shape {radii.shape}")
        bad = np.flatnonzero(~(np.isfinite(radii) & (radii > 0.0) & (radii < 1.0)))
        if bad.size:
            raise ValueError(f"{name}[{bad[0]}] must lie in (0.0, 1.0), got {radii[bad[0]]!r}")
    packing = float(np.sum(radii * radii))
    if packing >= PACKING_MAX:
        raise ValueError(f"{name}: the disks' packing sum(r^2) = {packing:.6g} cannot exist in "
                         f"the table: it must be below the densest packing pi/sqrt(12) = "
                         f"{PACKING_MAX:.6g}")
    return radii


def check_disks(state, r, rule: str, masses=None, name: str = "state"):
    """Validate an N-disk state; returns ``(state, radii, masses)`` as float64 arrays
    (``masses`` None for equal masses). Names the disk or pair at fault."""
    try:
        arr = np.array(state, dtype=np.float64, copy=True, order="C")
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an array of rows (x, y, vx, vy)") from None
    if arr.ndim != 2 or arr.shape[1] != 4 or arr.shape[0] < 1:
        raise ValueError(f"{name} must have shape (n_disks, 4) (rows x, y, vx, vy) with "
                         f"n_disks >= 1, got {arr.shape}")
    n = arr.shape[0]
    if n > N_DISKS_MAX:
        raise ValueError(f"{name}: n_disks must be <= {N_DISKS_MAX}, got {n}")
    if not np.isfinite(arr).all():
        k = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise ValueError(f"{name} must be finite, got NaN or inf in disk {k}: {arr[k].tolist()}")
    chk.check_choice("rule", rule, chk.RULES)
    radii = check_radii_of(r, n)
    dist = np.hypot(arr[:, 0], arr[:, 1])
    out = np.flatnonzero(dist > 1.0 - radii + chk.CONTACT_TOL)
    if out.size:
        k = int(out[0])
        raise ValueError(f"{name}: disk {k}'s centre at distance {dist[k]:.15g} from the table "
                         f"centre lies outside the table; centres must satisfy |x| <= 1 - r = "
                         f"{1.0 - radii[k]:.15g}")
    speed = np.hypot(arr[:, 2], arr[:, 3])
    if rule == "mirror":
        bad = np.flatnonzero(np.abs(speed - 1.0) > 1e-9)
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"{name}: disk {k}'s speed must be 1 (within 1e-09) under the "
                             f"mirror rule, got {float(speed[k])!r}")
    else:
        lo, hi = chk.SPEED_RANGE
        bad = np.flatnonzero((speed != 0.0) & ((speed < lo) | (speed > hi)))
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"{name}: disk {k}'s speed must be 0 or in [{lo:g}, {hi:g}], got "
                             f"{float(speed[k])!r}")
        if not speed.any():
            raise ValueError(f"{name}: all disks are at rest; give a non-zero velocity")
    if n > 1:
        from scipy.spatial import cKDTree

        pairs = cKDTree(arr[:, :2]).query_pairs(2.0 * float(radii.max()), output_type="ndarray")
        if pairs.size:
            a, b = pairs[:, 0], pairs[:, 1]
            gap = np.hypot(arr[a, 0] - arr[b, 0], arr[a, 1] - arr[b, 1])
            sig = radii[a] + radii[b]
            bad = np.flatnonzero(gap < sig - chk.CONTACT_TOL)
            if bad.size:
                k = bad[np.argmin(gap[bad] - sig[bad])]
                i, j = sorted((int(a[k]), int(b[k])))
                raise ValueError(f"{name}: disks {i} and {j} overlap (centre distance "
                                 f"{gap[k]:.15g} < r_{i} + r_{j} = {sig[k]:.15g})")
    if masses is not None:
        if rule != "elastic":
            raise ValueError(f"masses apply to rule='elastic' (the mirror rule keeps each "
                             f"disk's speed), got rule={rule!r}")
        try:
            masses = np.array(masses, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError("masses must be one positive number per disk") from None
        if masses.ndim == 0:
            masses = np.full(n, float(masses))
        if masses.shape != (n,):
            raise ValueError(f"masses must be one mass per disk ({n}), got shape {masses.shape}")
        bad = np.flatnonzero(~(np.isfinite(masses) & (masses > 0.0)))
        if bad.size:
            raise ValueError(f"masses[{bad[0]}] must lie in (0.0, inf), got {masses[bad[0]]!r}")
    return arr, radii, masses


def expected_collisions(radii: np.ndarray, speed: float, t_max: float) -> tuple[float, float]:
    """Rough counts ``(disk-disk, wall)`` of collisions of a run: Enskog's frequency at the
    table's packing, and the wall flux ``2 n rho |v| / pi`` round the wall (``n`` the
    density), for the budgets and the memory check."""
    n = radii.shape[0]
    phi = float(np.sum(radii * radii))
    r = float(np.sqrt(phi / n))
    nu = (n / math.pi) * 4.0 * r * float(contact_value(min(phi, 0.85))) * 4.0 / math.pi * speed
    walls = 2.0 * n / math.pi * speed * t_max * (1.0 + 4.0 * phi)
    return 0.5 * n * nu * t_max, walls


def engine_run(state, radii, rule_code, t_max, *, masses=None, arcs=None, walls_sel=None,
               sample=None, tau=None, contacts=False, max_events=None, log=True,
               cap_hint=1024, debug=False, tangent=None, segment=None, on_segment=None):
    """Run the engine on a validated state; returns a dict of its raw outputs in the
    caller's disk numbering. ``log=False`` keeps no collision log (the log buffer is
    reused: the initial-state growth runs only need the final state). ``debug=True``
    checks every disk for overlaps and the table's wall after every event (O(n) per event,
    `kd.check_state`): ``out["debug"] = [largest overlap, largest distance outside, checks]``.

    ``tangent`` (n, 4): a tangent vector ``(dx, dy, dvx, dvy)`` per disk at time 0, carried
    by the engine's tangent observer; the run stops at every multiple of ``segment`` (and
    at ``t_max``) and calls ``on_segment(u, v, lg)`` with the vector flown to that time
    (``u``, caller's numbering, changed in place and carried on from there), the disks'
    velocities ``v`` and ``lg`` the log of the engine's own rescalings since the last stop
    (`kd.shrink_tangent`). ``out["tangent"]``: the vector at ``t_max``."""
    n = state.shape[0]
    m, w = cells.grid(n, float(radii.max()))
    perm, eng = kd.new_engine(state, radii, m, w)
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    ident = perm.astype(np.int32)  # engine disk k is the caller's ident[k]
    reorder_every = max(1, int(REORDER_SWEEPS * n)) if n >= REORDER_MIN_DISKS else 0
    mass = None if masses is None else np.ascontiguousarray(masses[perm])
    clock = np.zeros(3)
    cnt = np.zeros(9, dtype=np.int64)
    cap = int(min(max(cap_hint, 64), 2**31 - 1)) if log else 4096
    pp_t, pp_i, pp_j = np.empty(cap), np.empty(cap, np.int32), np.empty(cap, np.int32)
    esc = np.full(n, np.inf)
    # The loop compiles once with no observers and once with all of them (an absent one
    # then gets empty arrays: no holes, no disk selected, no samples): two compilations
    # of a minute each instead of one per combination.
    full = (masses is not None or arcs is not None or walls_sel is not None
            or sample is not None or contacts or debug or tangent is not None)
    walls = samp = con = tan = dbg = None
    if full:
        if mass is None:
            mass = np.ones(n)
        if arcs is None:
            arcs = np.empty((0, 2))
        sel = np.zeros(n, dtype=np.bool_)
        if walls_sel is not None:
            sel[inv[walls_sel]] = True
        wc = 1024 if walls_sel is not None else 1
        walls = (np.empty(wc), np.empty(wc, np.int32), np.empty(wc), np.empty(wc), np.empty(wc),
                 sel)
        if sample is not None and tau is not None:
            n_s = int(math.floor(t_max / tau * (1.0 + 1e-12))) + 1
            samp = (float(tau), np.ascontiguousarray(inv[sample]),
                    np.full((n_s, len(sample), 2), np.nan))
        else:
            samp = (1.0, np.zeros(0, dtype=np.int64), np.empty((0, 0, 2)))
        con = (np.empty(cap), np.empty(cap))
        u = np.empty((0, 4)) if tangent is None else np.array(tangent, dtype=np.float64)[perm]
        tan = (u, np.zeros(1))
        dbg = np.array([-np.inf, -np.inf, 0.0, 1.0 if debug else 0.0])
    speed = float(np.hypot(state[:, 2], state[:, 3]).max())
    if masses is not None:
        e = float(np.sum(masses * (state[:, 2] ** 2 + state[:, 3] ** 2)))
        speed = max(speed, math.sqrt(e / float(masses.min())))
    stall_dt = 1e-9 * (1.0 - float(radii.max())) / (speed * n)
    budget = np.iinfo(np.int64).max if max_events is None else int(max_events)
    fs, iv, head, qt, qi, ht, qh, qs, qw = eng
    dropped = 0  # collisions of a reused log buffer (log=False)
    # the stops of the tangent's segments (the last at t_max)
    n_stop = 1 if tangent is None else max(1, int(math.floor(t_max / segment * (1 + 1e-12))))
    k_stop = 1
    while True:
        t_stop = float(t_max) if k_stop == n_stop else k_stop * segment
        status = kd.drive(fs, iv, head, m, w, qt, qi, ht, qh, qs, qw, rule_code, mass,
                          t_stop, budget, stall_dt, clock, cnt, pp_t, pp_i, pp_j, esc,
                          ident, reorder_every, arcs, walls, samp, con, tan, dbg)
        if status == kd.REORDER:
            order = cells.cell_order(iv[:, kd.CELL], m)
            new_of = kd.relabel(fs, iv, head, m, qt, qi, ht, qh, qs, qw, order)
            ident = ident[order]
            if mass is not None:
                mass = mass[order]
            if walls is not None:
                walls = walls[:5] + (walls[5][order],)
            if samp is not None:
                samp = (samp[0], new_of[samp[1]].astype(np.int64), samp[2])
            if tangent is not None:
                tan = (tan[0][order], tan[1])
            continue
        if status == DONE and tangent is not None:
            common, dt = kd.tangent_at(tan[0], fs, clock, t_stop)
            at_stop = np.empty_like(common)
            at_stop[ident] = common
            v = np.empty((n, 2))
            v[ident] = fs[:, kd.VX:kd.VY + 1]
            on_segment(at_stop, v, float(tan[1][0]))
            tan[1][0] = 0.0
            kd.tangent_back(tan[0], at_stop[ident], dt)
            if k_stop < n_stop:
                k_stop += 1
                continue
        if status != FULL:
            break
        if cnt[kd.N_PP] >= pp_t.shape[0]:
            if not log:
                cnt[kd.N_PP] = 0
                budget -= pp_t.shape[0]
                dropped += pp_t.shape[0]
            else:
                new = min(2 * pp_t.shape[0], 2**31 - 1)
                pp_t, pp_i, pp_j = (np.resize(pp_t, new), np.resize(pp_i, new),
                                    np.resize(pp_j, new))
                if con is not None:
                    con = (np.resize(con[0], new), np.resize(con[1], new))
        if walls is not None and cnt[kd.N_WLOG] >= walls[0].shape[0]:
            new = 2 * walls[0].shape[0]
            walls = tuple(np.resize(a, new) for a in walls[:5]) + (walls[5],)
    n_pp = int(cnt[kd.N_PP])
    fin = kd.final_state(fs, iv, clock, float(t_max))
    final = np.empty_like(fin)
    final[ident] = fin
    out = {"status": int(status), "final_state": final, "clock_time": float(clock[0]),
           "pp_times": pp_t[:n_pp].copy(), "pp_i": pp_i[:n_pp].copy(),
           "pp_j": pp_j[:n_pp].copy(), "n_wall": int(cnt[kd.N_WALL]),
           "n_pp_total": n_pp + dropped, "crossings": int(cnt[kd.N_CROSS]),
           "stale": int(cnt[kd.N_STALE]),
           "cells_per_side": m, "buckets": int(qs[3])}
    out["escape_times"] = esc
    if walls_sel is not None:
        q = int(cnt[kd.N_WLOG])
        out["wall_log"] = (walls[0][:q].copy(), walls[1][:q].copy(),
                           walls[2][:q].copy(), walls[3][:q].copy(), walls[4][:q].copy())
    if sample is not None and tau is not None:
        out["samples"] = samp[2]
        out["sample_times"] = np.arange(samp[2].shape[0]) * float(tau)
    if debug:
        out["debug"] = dbg[:3].copy()
    if contacts:
        out["contacts"] = (con[0][:n_pp].copy(), con[1][:n_pp].copy())
    if tangent is not None and status == DONE:
        out["tangent"] = at_stop
    return out


def raise_for_status(out: dict, budget: int) -> None:
    """A ValueError naming the argument for a run of `engine_run` that did not finish."""
    if out["status"] == OVER_BUDGET:
        raise ValueError(f"max_events: the run needed more than max_events={budget} collisions "
                         f"(stopped at t = {out['clock_time']:.6g}); pass a larger max_events "
                         f"or a shorter t_max")
    if out["status"] == STALLED:
        raise ValueError(f"state: the run makes no progress at t = {out['clock_time']:.6g} "
                         f"(disks jammed: {kd.STALL_EVENTS} events in no time)")
    assert out["status"] == DONE


def simulate_disks(state, r, *, t_max, rule="mirror", masses=None, holes=None, sample=None,
                   tau=None, log_walls=False, max_events=None) -> DisksRun:
    """Simulate N hard disks in the unit circular table, event by event.

    Parameters
    ----------
    state : array_like, shape (n_disks, 4)
        Rows ``(x, y, vx, vy)``: centres in the table (``|x_i| <= 1 - r_i``) without
        overlaps, unit speeds under the mirror rule (`kicktimes.initial_state` draws one).
    r : float or array_like, shape (n_disks,)
        The disks' radius, or one radius per disk, each in ``(0, 1)``.
    t_max : float
        End time (``0 < t_max <= 1e12``); collisions at ``t_max`` are included.
    rule : {"mirror", "elastic"}
        Disk-disk collision rule (docs/architecture.md, "The physics, precisely").
    masses : array_like, shape (n_disks,), optional
        The disks' masses under the elastic rule (default equal):
        ``v_i' = v_i - 2 m_j / (m_i + m_j) ((v_i - v_j).n) n``.
    holes : array_like, shape (n, 2), optional
        Holes in the wall, rows ``(centre angle, half-width)`` in radians. A disk whose
        wall contact lies in a hole leaves the table (``escape_times``); the others go on.
    sample : sequence of int, optional
        The disks whose positions are sampled every ``tau`` and whose wall hits are logged
        with ``log_walls``; default all.
    tau : float, optional
        Sampling step: positions of ``sample`` at ``k tau``, ``k = 0..floor(t_max / tau)``.
    log_walls : bool
        Log the wall hits of ``sample`` as ``(time, disk, s, sin_theta)`` (``run.walls``).
    max_events : int, optional
        Stop with a ValueError after this many collisions, disk-disk and wall (``>= 1``).
        Default: ten times the expected number plus 10^6.

    Returns
    -------
    DisksRun
        ``collisions`` (``time, i, j``), ``final_state``, ``n_events``,
        ``collision_times(k)``, ``walls``, ``samples``, ``escape_times``.

    Raises
    ------
    ValueError
        Naming the argument: disks that overlap (the pair), a disk outside the table, radii
        whose packing cannot exist, a log that would not fit in memory (``t_max``), a run
        over ``max_events`` or one that makes no progress.

    Notes
    -----
    Exact and event-driven (docs/disks.md): collision times are roots of quadratics,
    disks carry their own clocks and move only when an event touches them. The wall and
    the rules are those of `simulate_two_particle`, and two disks agree with it event by
    event. Memory: about 180 bytes per disk plus 16 per logged collision.

    Examples
    --------
    >>> import kicktimes as kt
    >>> state = kt.initial_state(50, 0.03, seed=1)
    >>> run = kt.simulate_disks(state, 0.03, t_max=5.0)
    >>> bool((run.collisions.i < run.collisions.j).all())
    True
    """
    chk.check_choice("rule", rule, chk.RULES)
    t_max = chk.check_real("t_max", t_max, low=0.0, high=chk.TIME_LIMIT, high_open=False)
    state, radii, masses = check_disks(state, r, rule, masses)
    n = state.shape[0]
    arcs = chk.check_holes(holes)
    if not isinstance(log_walls, bool | np.bool_):
        raise TypeError(f"log_walls must be a bool, got {type(log_walls).__name__}")
    if sample is not None:
        try:
            sample = np.array(sample, dtype=np.int64, ndmin=1)
        except (TypeError, ValueError):
            raise TypeError("sample must be a sequence of disk indices") from None
        if sample.ndim != 1 or sample.size == 0:
            raise ValueError(f"sample must be a non-empty sequence of disk indices, got shape "
                             f"{sample.shape}")
        bad = np.flatnonzero((sample < 0) | (sample >= n))
        if bad.size:
            raise ValueError(f"sample: disk indices must lie in [0, {n - 1}], got "
                             f"{int(sample[bad[0]])}")
        if np.unique(sample).size != sample.size:
            raise ValueError("sample: disk indices must be distinct")
    elif tau is not None or log_walls:
        sample = np.arange(n)
    if tau is not None:
        tau = chk.check_real("tau", tau, low=0.0, high=chk.TIME_LIMIT, high_open=False)
        n_s = math.floor(t_max / tau * (1.0 + 1e-12)) + 1
        if n_s * sample.size > chk.N_STEPS_MAX:
            raise ValueError(f"tau: t_max / tau = {n_s} samples of {sample.size} disks is more "
                             f"than {chk.N_STEPS_MAX} positions; pass a larger tau or fewer "
                             f"disks in sample")
    speed = float(np.hypot(state[:, 2], state[:, 3]).max())
    e_pp, e_wall = expected_collisions(radii, speed, t_max)
    if max_events is not None:
        max_events = chk.check_int("max_events", max_events, low=1)
    budget = max_events if max_events is not None else int(10.0 * (e_pp + e_wall) + 10**6)
    mem = _memory_bytes()
    if e_pp * LOG_BYTES > 0.5 * mem:
        raise ValueError(
            f"t_max={t_max!r}: {n} disks at packing {float(np.sum(radii ** 2)):.3g} make about "
            f"{e_pp:.3g} disk-disk collisions, a log of {e_pp * LOG_BYTES / 1e9:.3g} GB, more "
            f"than half this machine's memory ({mem / 1e9:.3g} GB); pass a shorter t_max or "
            f"fewer disks")
    out = engine_run(state, radii, chk.RULES[rule], t_max, masses=masses, arcs=arcs,
                     walls_sel=sample if log_walls else None, sample=sample, tau=tau,
                     max_events=budget, cap_hint=int(1.2 * e_pp) + 1024)
    raise_for_status(out, budget)
    return DisksRun(
        radii=radii, rule=rule, t_max=t_max, state=state, final_state=out["final_state"],
        pp_times=out["pp_times"], pp_i=out["pp_i"], pp_j=out["pp_j"],
        n_events=out["n_pp_total"] + out["n_wall"], n_wall=out["n_wall"], masses=masses,
        holes=arcs, escape_times=out["escape_times"],
        sample=sample if (tau is not None or log_walls) else None, tau=tau,
        sample_times=out.get("sample_times"), samples=out.get("samples"),
        wall_log=out.get("wall_log"),
        engine={"cell_crossings": out["crossings"], "stale_events": out["stale"],
                "cells_per_side": out["cells_per_side"], "buckets": out["buckets"]},
    )
