"""N hard disks in the unit circular table, a stadium, an ellipse or a periodic square box:
the Python layer of the N-disk engine.

`simulate_disks` checks its arguments (`check_disks`), sets up the engine
(`kicktimes.billiard.kernels.disks`), runs its event loop, growing the logs as they fill
and stopping every so often to count the centres of the central region (the pressure's
log, `DisksRun.pressure`), and returns a `DisksRun`. docs/disks.md describes the
algorithm and its checks.
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
from kicktimes.billiard.tables import Circle, check_table
from kicktimes.stats.enskog import PACKING_MAX, contact_value

__all__ = ["check_box", "check_disks", "check_disks_table", "engine_run",
           "expected_collisions", "raise_for_status", "simulate_disks"]

#: most disks a run takes (int32 indices; about 180 bytes each)
N_DISKS_MAX = 10**7
#: bytes of the log per disk-disk collision (time, i, j)
LOG_BYTES = 16
#: the engine renumbers its disks in space (`kd.relabel`) every this many disk-disk
#: collisions per disk, from this many disks on (fewer fit in the core's cache anyway)
REORDER_SWEEPS = 10
REORDER_MIN_DISKS = 2048
#: the central region of the table whose pressure `DisksRun.pressure` calls the bulk: the
#: centres within this radius (the box: the whole box)
BULK_RADIUS = 0.5
#: at most this many counts of the region's centres (stops of the loop, 35-60 us each) per
#: run, one per `PRESSURE_EVERY` collisions per disk, at least 2 (`pressure_samples`)
PRESSURE_SAMPLES = 100
PRESSURE_EVERY = 4.0


def _memory_bytes() -> float:
    try:
        return float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 8e9


def check_box(box):
    """``box`` as a float: ``None`` (the unit table) or the side ``L > 0`` of the periodic
    square box ``[0, L)^2``."""
    if box is None:
        return None
    return chk.check_real("box", box, low=0.0, high=1e12)


def check_radii_of(r, n: int, name: str = "r", box: float | None = None,
                   table=None) -> np.ndarray:
    """One radius per disk from ``r`` (a number, or ``n`` numbers), each in ``(0, 1)`` (the
    box: in ``(0, box / 6]``), with a packing ``sum r_i^2`` (the box: ``pi sum r_i^2 /
    box^2``) below the densest, ``pi / sqrt(12)``.

    ``table`` (a `Stadium` or an `Ellipse`; ``None`` or a `Circle`: the unit table): one
    radius for every disk (the wall's kernel is the centre's curve of one radius), admitted
    by ``table.check_radius``, at a packing ``pi sum r_i^2 / table.area(0)`` below the
    densest."""
    if table is not None and not isinstance(table, Circle):
        if np.ndim(r) == 0:
            radius = table.check_radius(r)
        else:
            try:
                arr = np.array(r, dtype=np.float64)
            except (TypeError, ValueError):
                raise TypeError(f"{name} must be a number or one number per disk") from None
            if arr.shape != (n,):
                raise ValueError(f"{name} must be one radius or {n} radii (one per disk), got "
                                 f"shape {arr.shape}")
            if np.ptp(arr) > 0:
                raise ValueError(f"{name}: the disks in {table!r} must have one radius (the "
                                 f"wall is the centre's curve of one radius), got radii in "
                                 f"[{arr.min()!r}, {arr.max()!r}]")
            radius = table.check_radius(arr[0])
        radii = np.full(n, radius)
        packing = math.pi * n * radius * radius / table.area(0.0)
        if packing >= PACKING_MAX:
            raise ValueError(f"{name}: the disks' packing pi n r^2 / area = {packing:.6g} "
                             f"cannot exist in {table!r}: it must be below the densest "
                             f"packing pi/sqrt(12) = {PACKING_MAX:.6g}")
        return radii
    high = 1.0 if box is None else box / 6.0
    if np.ndim(r) == 0 and box is None:
        radii = np.full(n, chk.check_real(name, r, low=0.0, high=high))
    elif np.ndim(r) == 0:
        radii = np.full(n, chk.check_real(name, r, low=0.0))
        if radii[0] > high:
            raise ValueError(f"{name} must lie in (0.0, box / 6 = {high:.6g}] (three cells of "
                             f"one diameter per side), got {radii[0]!r}")
    else:
        try:
            radii = np.array(r, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"{name} must be a number or one number per disk") from None
        if radii.shape != (n,):
            raise ValueError(f"{name} must be one radius or {n} radii (one per disk), got "
                             f"shape {radii.shape}")
        ok = (radii < 1.0) if box is None else (radii <= high)
        bad = np.flatnonzero(~(np.isfinite(radii) & (radii > 0.0) & ok))
        if bad.size:
            span = "(0.0, 1.0)" if box is None else f"(0.0, box / 6 = {high:.6g}]"
            raise ValueError(f"{name}[{bad[0]}] must lie in {span}, got {radii[bad[0]]!r}")
    if box is None:
        packing = float(np.sum(radii * radii))
        what = "sum(r^2)"
    else:
        packing = math.pi * float(np.sum(radii * radii)) / (box * box)
        what = "pi sum(r^2) / box^2"
    if packing >= PACKING_MAX:
        raise ValueError(f"{name}: the disks' packing {what} = {packing:.6g} cannot exist in "
                         f"the {'table' if box is None else 'box'}: it must be below the "
                         f"densest packing pi/sqrt(12) = {PACKING_MAX:.6g}")
    return radii


def check_disks_table(table, box, name: str = "table"):
    """The table of an N-disk run (`kicktimes.billiard.tables.check_table`: ``None`` is the
    `Circle`), or ``None`` with a periodic ``box``; both given: a ValueError naming
    ``table``."""
    if box is not None:
        if table is not None:
            raise ValueError(f"{name}: pass a table or a periodic box, not both (got "
                             f"{name}={table!r} and box={box!r})")
        return None
    return check_table(table, name=name)


def check_disks(state, r, rule: str, masses=None, name: str = "state", box=None, table=None):
    """Validate an N-disk state; returns ``(state, radii, masses)`` as float64 arrays
    (``masses`` None for equal masses). Names the disk or pair at fault. In the periodic
    box (``box`` its side ``L``) centres must lie in ``[0, L]^2`` (``L`` is wrapped to 0)
    and overlaps are measured between nearest images. In a ``table`` other than the
    circle the centres must keep their disks inside it (``table.contains``)."""
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
    radii = check_radii_of(r, n, box=box, table=table)
    if table is not None and not isinstance(table, Circle):
        out = np.flatnonzero(~table.contains(arr[:, :2], float(radii[0])))
        if out.size:
            k = int(out[0])
            raise ValueError(f"{name}: disk {k}'s centre ({arr[k, 0]:.15g}, {arr[k, 1]:.15g}) "
                             f"lies outside {table!r}: a disk of radius {radii[k]!r} there "
                             f"crosses the wall")
    elif box is not None:
        out = np.flatnonzero(((arr[:, :2] < 0.0) | (arr[:, :2] > box)).any(axis=1))
        if out.size:
            k = int(out[0])
            raise ValueError(f"{name}: disk {k}'s centre ({arr[k, 0]:.15g}, {arr[k, 1]:.15g}) "
                             f"lies outside the box; centres must lie in [0, box]^2, box = "
                             f"{box!r}")
        arr[:, :2] = np.where(arr[:, :2] >= box, arr[:, :2] - box, arr[:, :2])
    dist = np.hypot(arr[:, 0], arr[:, 1])
    circle = box is None and (table is None or isinstance(table, Circle))
    out = np.flatnonzero(dist > 1.0 - radii + chk.CONTACT_TOL) if circle else dist[:0]
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

        tree = cKDTree(arr[:, :2], boxsize=box)
        pairs = tree.query_pairs(2.0 * float(radii.max()), output_type="ndarray")
        if pairs.size:
            a, b = pairs[:, 0], pairs[:, 1]
            d = arr[a, :2] - arr[b, :2]
            if box is not None:
                d -= box * np.round(d / box)
            gap = np.hypot(d[:, 0], d[:, 1])
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


def expected_collisions(radii: np.ndarray, speed: float, t_max: float,
                        box: float | None = None, table=None) -> tuple[float, float]:
    """Rough counts ``(disk-disk, wall)`` of collisions of a run: Enskog's frequency at the
    table's packing, and the wall flux ``2 n rho |v| / pi`` round the wall (``n`` the
    density), for the budgets and the memory check (the box: area ``box^2``, no wall; a
    stadium or an ellipse: its area and the flux ``n |v| / pi`` along its perimeter)."""
    n = radii.shape[0]
    other = table is not None and not isinstance(table, Circle)
    area = table.area(0.0) if other else math.pi if box is None else box * box
    phi = float(np.sum(radii * radii)) * math.pi / area
    r = float(np.sqrt(phi * area / (math.pi * n)))
    nu = (n / area) * 4.0 * r * float(contact_value(min(phi, 0.85))) * 4.0 / math.pi * speed
    walls = 2.0 * n / math.pi * speed * t_max * (1.0 + 4.0 * phi) if box is None else 0.0
    if other:
        walls = n * table.perimeter(0.0) / (math.pi * area) * speed * t_max * (1.0 + 4.0 * phi)
    return 0.5 * n * nu * t_max, walls


def engine_run(state, radii, rule_code, t_max, *, masses=None, arcs=None, walls_sel=None,
               sample=None, tau=None, contacts=False, max_events=None, log=True,
               cap_hint=1024, debug=False, tangent=None, segment=None, on_segment=None,
               box=None, bulk_radius=BULK_RADIUS, pressure_samples=0, table=None):
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
    (`kd.shrink_tangent`). ``out["tangent"]``: the vector at ``t_max``.

    ``box``: the side ``L`` of a periodic square box ``[0, L)^2`` instead of the table
    (centres in ``[0, L)``; no wall). ``pressure_samples`` (``k >= 1``): the run also stops
    at ``t_max j / k``, ``j = 1..k``, and ``out["pressure_log"]`` has rows ``(t, centres
    within bulk_radius of the table's centre (the box: all), the sums of the wall's
    impulse, the virial and the central region's virial up to t)``, the first at ``t = 0``
    (`kd.collide`; `DisksRun.pressure`).

    ``table``: a `Stadium` or an `Ellipse` (equal radii, no box; ``None`` or a `Circle`:
    the unit table, its own loop): the engine's table switch ``(kind, p0, p1, p2, h,
    where)`` (`kicktimes.billiard.kernels.disk_walls`), its cells over the square ``[-h,
    h]^2`` around the table's bounding box (`cells.grid_table`), always the loop's observer
    variant (one compilation for every such table)."""
    n = state.shape[0]
    tab = None
    if table is not None and not isinstance(table, Circle):
        kind, p0, p1, p2 = table.kernel(float(radii[0]))
        half = float(max(table.bounding_box()))
        m, w = cells.grid_table(n, float(radii.max()), half, table.area(0.0))
        tab = (kind, p0, p1, p2, half, np.zeros((n, 2)))
    elif box is None:
        m, w = cells.grid(n, float(radii.max()))
    else:
        m, w = cells.grid_box(n, float(radii.max()), float(box))
    perm, eng = kd.new_engine(state, radii, m, w, box, tab)
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    ident = perm.astype(np.int32)  # engine disk k is the caller's ident[k]
    reorder_every = max(1, int(REORDER_SWEEPS * n)) if n >= REORDER_MIN_DISKS else 0
    mass = None if masses is None else np.ascontiguousarray(masses[perm])
    clock = np.zeros(kd.N_CLOCK)
    clock[kd.RB2] = bulk_radius * bulk_radius
    cnt = np.zeros(9, dtype=np.int64)
    cap = int(min(max(cap_hint, 64), 2**31 - 1)) if log else 4096
    pp_t, pp_i, pp_j = np.empty(cap), np.empty(cap, np.int32), np.empty(cap, np.int32)
    esc = np.full(n, np.inf)
    # The loop compiles once with no observers and once with all of them (an absent one
    # then gets empty arrays: no holes, no disk selected, no samples): two compilations
    # of a minute each instead of one per combination.
    full = (masses is not None or arcs is not None or walls_sel is not None
            or sample is not None or contacts or debug or tangent is not None
            or tab is not None)
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
    stall_dt = 1e-9 * (1.0 - float(radii.max()) if box is None else box) / (speed * n)
    budget = np.iinfo(np.int64).max if max_events is None else int(max_events)
    fs, iv, head, qt, qi, ht, qh, qs, qw = eng
    dropped = 0  # collisions of a reused log buffer (log=False)
    # the stops of the tangent's segments (the last at t_max)
    n_stop = 1 if tangent is None else max(1, int(math.floor(t_max / segment * (1 + 1e-12))))
    k_stop = 1
    # the pressure's log: a row at 0, then one at each stop t_max j / k
    plog = np.zeros((pressure_samples + 1, 5))
    if pressure_samples:
        plog[0] = _pressure_row(fs, iv, clock, 0.0, box)
    k_samp = 1
    while True:
        t_tan = float(t_max) if k_stop == n_stop else k_stop * segment
        t_stop = t_tan
        if k_samp <= pressure_samples:
            t_samp = float(t_max) if k_samp == pressure_samples else \
                t_max * k_samp / pressure_samples
            t_stop = min(t_stop, t_samp)
        status = kd.drive(fs, iv, head, m, w, qt, qi, ht, qh, qs, qw, rule_code, mass,
                          t_stop, budget, stall_dt, clock, cnt, pp_t, pp_i, pp_j, esc,
                          ident, reorder_every, arcs, walls, samp, con, tan, dbg, box, tab)
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
            if tab is not None:
                tab = tab[:5] + (tab[5][order],)
            continue
        if status == DONE and k_samp <= pressure_samples and t_stop == t_samp:
            plog[k_samp] = _pressure_row(fs, iv, clock, t_stop, box)
            k_samp += 1
            if t_stop < t_tan:
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
    if box is not None:
        # (centres leave [0, L) only at a crossing, a rounding error beyond the edge)
        final[:, :2] -= box * np.floor(final[:, :2] / box)
        final[:, :2] = np.where(final[:, :2] >= box, 0.0, final[:, :2])
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
    if pressure_samples:
        out["pressure_log"] = plog[:k_samp]
    out["sums"] = clock[kd.W_IMPULSE:kd.VIRIAL_B + 1].copy()
    return out


def _pressure_row(fs, iv, clock, t, box):
    """``(t, centres in the central region, wall impulse, virial, region's virial)`` at the
    absolute time ``t`` (a stop of the loop: the disks flown there, not moved)."""
    live = iv[:, kd.CELL] >= 0
    if box is None:
        dt = (t - clock[kd.OFFSET]) - fs[:, kd.T]
        x = fs[:, kd.X] + fs[:, kd.VX] * dt
        y = fs[:, kd.Y] + fs[:, kd.VY] * dt
        inside = int(np.count_nonzero(live & (x * x + y * y < clock[kd.RB2])))
    else:
        inside = int(np.count_nonzero(live))
    return (t, inside, clock[kd.W_IMPULSE], clock[kd.VIRIAL], clock[kd.VIRIAL_B])


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
                   tau=None, log_walls=False, max_events=None, box=None,
                   bulk_radius=BULK_RADIUS, table=None) -> DisksRun:
    """Simulate N hard disks in the unit circular table, a stadium, an ellipse, or a
    periodic square box, event by event.

    Parameters
    ----------
    state : array_like, shape (n_disks, 4)
        Rows ``(x, y, vx, vy)``: centres in the table (``|x_i| <= 1 - r_i``; another
        table: ``table.contains``; the box: ``0 <= x_i, y_i <= L``) without overlaps (the
        box: between nearest images), unit speeds under the mirror rule
        (`kicktimes.initial_state` draws one).
    r : float or array_like, shape (n_disks,)
        The disks' radius, or one radius per disk, each in ``(0, 1)`` (the box:
        ``(0, L / 6]``; a stadium or an ellipse: one radius, ``table.check_radius``).
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
        The circle only (they are arcs of the circle).
    sample : sequence of int, optional
        The disks whose positions are sampled every ``tau`` and whose wall hits are logged
        with ``log_walls``; default all.
    tau : float, optional
        Sampling step: positions of ``sample`` at ``k tau``, ``k = 0..floor(t_max / tau)``.
    log_walls : bool
        Log the wall hits of ``sample`` as ``(time, disk, s, sin_theta)`` (``run.walls``;
        in a stadium or an ellipse ``s`` is the arc length along the centre's curve: the
        contact's Birkhoff coordinates).
    max_events : int, optional
        Stop with a ValueError after this many collisions, disk-disk and wall (``>= 1``).
        Default: ten times the expected number plus 10^6.
    box : float, optional
        The side ``L`` of a periodic square box ``[0, L)^2`` instead of the table: no wall,
        distances between nearest images, centres wrapped into ``[0, L)`` (``final_state``).
        At least three cells of one diameter per side: ``L >= 6 r_max``. No ``holes`` or
        ``log_walls`` then.
    bulk_radius : float
        The central region of the table, centres within ``bulk_radius`` of its centre
        (``0 < bulk_radius <= 1 - r_max``; another table: ``<= table.inradius(r)``), whose
        collisions and density give `DisksRun.pressure`'s bulk pressure; the box's region
        is the whole box.
    table : Circle, Stadium or Ellipse, optional
        The table (``None``: the unit circle, `kicktimes.tables.Circle`, whose runs are
        those of before, bit for bit). In a `Stadium` or an `Ellipse` the disks have one
        radius and meet the wall through `kicktimes.billiard.kernels.tables` (docs/tables.md,
        "N disks in a table"). Not with ``box`` (a ValueError).

    Returns
    -------
    DisksRun
        ``collisions`` (``time, i, j``), ``final_state``, ``n_events``,
        ``collision_times(k)``, ``walls``, ``samples``, ``escape_times``, ``pressure()``.

    Raises
    ------
    ValueError
        Naming the argument: disks that overlap (the pair), a disk outside the table, radii
        whose packing cannot exist, a log that would not fit in memory (``t_max``), a run
        over ``max_events`` or one that makes no progress, a box too small for three
        cells, wall options with a box, ``table`` with ``box``, ``holes`` in a table other
        than the circle, a radius the table refuses (its ``check_radius``).
    TypeError
        A ``table`` that is not a `Circle`, `Stadium` or `Ellipse`.

    Notes
    -----
    Exact and event-driven (docs/disks.md): collision times are roots of quadratics,
    disks carry their own clocks and move only when an event touches them. The wall and
    the rules are those of `simulate_two_particle`, and two disks agree with it event by
    event. Memory: about 180 bytes per disk plus 16 per logged collision.

    The pressure's sums (the wall's impulse, the collisional virial, the central
    region's) are accumulated by the engine as it goes, and the loop stops once per four
    collisions per disk (at least 2, at most 100 times) to count the centres of the
    central region:
    `DisksRun.pressure` (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed.,
    2017, secs. 2.4 and 3.7).

    Examples
    --------
    >>> import kicktimes as kt
    >>> state = kt.initial_state(50, 0.03, rng=1)
    >>> run = kt.simulate_disks(state, 0.03, t_max=5.0)
    >>> bool((run.collisions.i < run.collisions.j).all())
    True
    >>> s = kt.initial_state(200, 0.02, box=1.0, rule="elastic", rng=1)
    >>> run = kt.simulate_disks(s, 0.02, t_max=2.0, rule="elastic", box=1.0)
    >>> run.box, bool(((run.final_state[:, :2] >= 0) & (run.final_state[:, :2] < 1)).all())
    (1.0, True)
    >>> import math
    >>> from kicktimes.tables import Stadium
    >>> s = kt.initial_state(100, None, packing=0.3, table=Stadium(1.0), rng=1)
    >>> r = math.sqrt(0.3 * Stadium(1.0).area(0.0) / (100 * math.pi))  # packing's radius
    >>> run = kt.simulate_disks(s, r, t_max=1.0, table=Stadium(1.0))
    >>> run.table, bool(Stadium(1.0).contains(run.final_state[:, :2], r).all())
    (Stadium(a=1.0), True)
    """
    chk.check_choice("rule", rule, chk.RULES)
    t_max = chk.check_real("t_max", t_max, low=0.0, high=chk.TIME_LIMIT, high_open=False)
    box = check_box(box)
    table = check_disks_table(table, box)
    other = table is not None and not isinstance(table, Circle)
    state, radii, masses = check_disks(state, r, rule, masses, box=box, table=table)
    n = state.shape[0]
    if box is not None and holes is not None:
        raise ValueError("holes: the periodic box has no wall to cut holes in; pass "
                         "holes=None with box")
    if other and holes is not None:
        raise ValueError(f"holes: holes are arcs of the circular table (centre angle, "
                         f"half-width); {table!r} takes none; pass holes=None")
    arcs = chk.check_holes(holes)
    if not isinstance(log_walls, bool | np.bool_):
        raise TypeError(f"log_walls must be a bool, got {type(log_walls).__name__}")
    if box is not None and log_walls:
        raise ValueError("log_walls: the periodic box has no wall hits to log; pass "
                         "log_walls=False with box")
    if other:
        bulk_radius = chk.check_real("bulk_radius", bulk_radius, low=0.0,
                                     high=table.inradius(float(radii[0])), high_open=False)
    elif box is None:
        bulk_radius = chk.check_real("bulk_radius", bulk_radius, low=0.0,
                                     high=1.0 - float(radii.max()), high_open=False)
    else:
        bulk_radius = math.inf
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
    e_pp, e_wall = expected_collisions(radii, speed, t_max, box, table)
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
    n_samples = int(min(PRESSURE_SAMPLES, max(2, round(2.0 * e_pp / n / PRESSURE_EVERY))))
    out = engine_run(state, radii, chk.RULES[rule], t_max, masses=masses, arcs=arcs,
                     walls_sel=sample if log_walls else None, sample=sample, tau=tau,
                     max_events=budget, cap_hint=int(1.2 * e_pp) + 1024, box=box,
                     bulk_radius=bulk_radius if box is None else 0.0,
                     pressure_samples=n_samples, table=table)
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
        box=box, bulk_radius=None if box is not None else bulk_radius,
        pressure_log=out["pressure_log"], table=table,
    )
