"""The N-disk engine: event-driven hard disks in the unit circular table.

docs/disks.md has the algorithm and its checks. The pieces:

* the **physics** is the two-disk kernels', called, not copied: contact times
  (`kicktimes.billiard.geometry.pair_hit_time`, `boundary_hit_time`), the collision
  rules with masses (`two.pair_event`, `two.anchor_energy`) and the curved wall
  (`two.wall_event`: contact put back on the circle, reflection or grazing slide, the
  next chord);
* the **calendar** (`kicktimes.billiard.kernels.calendar`): one entry per disk, its
  earliest predicted event; stale entries are recognised by per-disk event counters;
* the **cells** (`kicktimes.billiard.kernels.cells`): a grid of cells at least one
  diameter wide, a cell-crossing event per disk;
* **delayed states**: each disk carries its own clock and is moved only when an event
  touches it; a prediction extrapolates its neighbours to the present without moving them.

The disk table ``fs`` (float64, one row of 8 per disk, 64 bytes: a cache line):
``x, y, vx, vy`` at the disk's own time ``t``, ``tw`` the time of its next wall contact,
``tp`` the time of its earliest contact with another disk found by the last scan, ``rad``
its radius. The event table ``iv`` (int64, one row of 5 per disk): the scheduled event's
kind (a partner disk ``>= 0``, `WALL`, `CROSS` or `NONE`), its stamp (the partner's
counter at the prediction, or the cell a crossing enters), the disk's own counter
(incremented whenever its velocity changes), and the kind and stamp of ``tp``'s contact.
Then its cell (-1: escaped) and its links in the cell's list. ``mass`` (float64, one per
disk) only under the elastic rule with masses, else ``None``. Disks are numbered in space
(`cells.spatial_order`) so that neighbours share cache lines; the caller maps them back.

Times in the loop are local: ``clock[OFFSET]`` (Kahan-summed with ``clock[COMP]``) is
added for the logs, and once the next event passes `REBASE` all disks are brought to it
and every time shifted back by it, so that times keep their digits in long runs.

The loop is compiled without numba's reference counting (``_nrt=False``; it allocates
nothing): counting the references of the arrays each inlined helper takes cost 40 ns per
helper call, more than the helper (measured: 45 ns against 5 ns for six arrays).

Optional observers, compiled out when passed as ``None`` (as in `drive_two`): ``arcs``
(holes in the wall), ``walls`` (the wall-contact log of selected disks), ``samp``
(positions of selected disks every ``tau``), ``contacts`` (the contact point of every
disk-disk collision), ``tan`` (a tangent vector, one row ``(dx, dy, dvx, dvy)`` per disk,
in the same delayed form as the disk table: carried by the linearised event maps of
`kicktimes.billiard.kernels.tangent`, for the largest Lyapunov exponent).

The table switch ``tab``, beside ``box``: ``None`` is the unit circle (its code as it was,
the branches below pruned at compile time); a stadium or an ellipse is ``(kind, p0, p1,
p2, h, where)`` (`kicktimes.billiard.kernels.disk_walls`: the kernel tuple of
`kicktimes.billiard.kernels.tables`, the grid's half side, each disk's pending contact),
compiled once for every such table, with the observers on (empty when unused): one loop
variant more.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kicktimes.billiard.geometry import boundary_hit_time, pair_hit_time
from kicktimes.billiard.kernels import calendar as cal
from kicktimes.billiard.kernels import cells
from kicktimes.billiard.kernels import disk_walls as dw
from kicktimes.billiard.kernels import observe as ob
from kicktimes.billiard.kernels.aligned import aligned_zeros
from kicktimes.billiard.kernels.tangent import (
    BIG,
    curved_wall_tangent,
    pair_tangent,
    wall_tangent,
)
from kicktimes.billiard.kernels.two import (
    anchor_energy,
    mass_factors,
    pair_energy,
    pair_event,
    wall_event,
)

__all__ = ["CROSS", "NONE", "PREDICT", "REORDER", "WALL", "drive", "final_state", "relabel",
           "setup", "tangent_at", "tangent_back"]

#: columns of the disk table ``fs``
X, Y, VX, VY, T, TW, TP, RAD = range(8)
#: columns of the event table ``iv``
KIND, STAMP, COUNT, KIND_P, STAMP_P, CELL, NEXT, PREV = range(8)
#: event kinds other than a partner's index (`PREDICT`: the disk's first prediction is due)
WALL, CROSS, NONE, PREDICT = -1, -2, -3, -4
#: fields of ``clock`` (float64) and ``cnt`` (int64), the loop's position between calls;
#: ``clock`` also carries the pressure's sums (`collide`, the wall events of `drive`) and
#: the squared radius of the central region they are taken in
OFFSET, COMP, T_CHECK, W_IMPULSE, VIRIAL, VIRIAL_B, RB2 = range(7)
N_CLOCK = 7
N_PP, N_WALL, N_CROSS, N_STALE, N_WLOG, K_SAMPLE, N_ESC, N_CHECK, N_SINCE = range(9)
#: the engine's own status (beside `kicktimes.billiard.kernels.observe`'s): ``reorder_every``
#: collisions since the last renumbering; the caller renumbers (`relabel`) and resumes
REORDER = 4
#: local clocks are shifted back to 0 once they pass this (ulp(32) = 7e-15)
REBASE = 32.0
#: a stall: this many events with the clock advancing less than ``stall_dt`` in all
STALL_EVENTS = 100_000


@njit(cache=True, inline="always", error_model="numpy")
def scan(i, x, y, vx, vy, now, gx0, gx1, gy0, gy1, fs, iv, head, m, best, kind, stamp, box):
    """The earliest contact of disk ``i`` (at ``(x, y)`` at ``now``) with the disks of
    cells ``gx0..gx1 x gy0..gy1`` (extrapolated to ``now``), if before ``best``; returns the
    new ``(best, kind, stamp)``.

    In the periodic box (``box``: its side ``L``; ``None``: the table) the cell indices
    may lie one beyond the grid: that cell across the box, its disks seen under the image
    shifted by ``-L`` (index -1) or ``+L`` (index ``m``); the cell, not the distance, picks
    the image, so a pair is scanned under one image only (``m >= 3``)."""
    ri = fs[i, RAD]
    for gy in range(gy0, gy1 + 1):
        gyc, sy = gy, 0.0
        if box is not None:
            gyc, sy = cells.image_of(gy, m, box)
        for gx in range(gx0, gx1 + 1):
            gxc, sx = gx, 0.0
            if box is not None:
                gxc, sx = cells.image_of(gx, m, box)
            k = head[gxc + m * gyc]
            while k >= 0:
                if k != i:
                    dk = now - fs[k, T]
                    wx = vx - fs[k, VX]
                    wy = vy - fs[k, VY]
                    if box is None:
                        dx = x - (fs[k, X] + fs[k, VX] * dk)
                        dy = y - (fs[k, Y] + fs[k, VY] * dk)
                    else:
                        dx = x - (fs[k, X] + fs[k, VX] * dk + sx)
                        dy = y - (fs[k, Y] + fs[k, VY] * dk + sy)
                    # (the approach test first: half the pairs separate)
                    if dx * wx + dy * wy < 0.0:
                        tk = now + pair_hit_time(dx, dy, wx, wy, ri + fs[k, RAD])
                        if tk < best:
                            best = tk
                            kind = k
                            stamp = iv[k, COUNT]
                k = iv[k, NEXT]
    return best, kind, stamp


@njit(cache=True, inline="always", error_model="numpy")
def schedule(i, x, y, vx, vy, now, best, kind, stamp, fs, iv, m, w, qt, qi, ht, qh, qs, qw,
             box, tab):
    """Keep ``(best, kind, stamp)`` as disk ``i``'s earliest contact with a disk, and
    schedule the earliest of it, the wall contact (the box: none, ``tw = inf``) and the
    next cell crossing."""
    fs[i, TP] = best
    iv[i, KIND_P] = kind
    iv[i, STAMP_P] = stamp
    if fs[i, TW] <= best:
        best = fs[i, TW]
        kind = WALL
        stamp = 0
    if box is None:
        if tab is None:
            dtc, cn = cells.crossing(x, y, vx, vy, iv[i, CELL], m, w)
        else:
            dtc, cn = cells.crossing_table(x, y, vx, vy, iv[i, CELL], m, w, tab[4])
    else:
        dtc, cn = cells.crossing_box(x, y, vx, vy, iv[i, CELL], m, w)
    if now + dtc < best:
        best = now + dtc
        kind = CROSS
        stamp = cn
    iv[i, KIND] = kind
    iv[i, STAMP] = stamp
    cal.update(qt, qi, ht, qh, qs, qw, i, best)


@njit(cache=True, inline="always", error_model="numpy")
def rescan(i, now, gx0, gx1, gy0, gy1, best, kind, stamp, fs, iv, head, m, w, qt, qi, ht, qh,
           qs, qw, tan, box, tab):
    """Bring disk ``i`` to ``now``, look for an earlier contact than ``(best, kind, stamp)``
    in cells ``gx0..gx1 x gy0..gy1`` and schedule its earliest event (`scan`, `schedule`).

    The one place the scan is compiled into the event loop: numba inlines it once, not
    once per kind of event (with four copies the loop took 95-155 s to compile, with one
    20-30 s, and runs 3 % slower: benchmarks/bench_compile.py)."""
    x, y = bring(fs, i, now, tan)
    vx = fs[i, VX]
    vy = fs[i, VY]
    best, kind, stamp = scan(i, x, y, vx, vy, now, gx0, gx1, gy0, gy1, fs, iv, head, m, best,
                             kind, stamp, box)
    schedule(i, x, y, vx, vy, now, best, kind, stamp, fs, iv, m, w, qt, qi, ht, qh, qs, qw,
             box, tab)


@njit(cache=True, inline="always", error_model="numpy")
def neighbourhood(c, m, box):
    """``(gx0, gx1, gy0, gy1)``: the block of 3 x 3 cells around cell ``c`` in the grid
    (the box: not clipped, `scan` wraps it)."""
    cx = c % m
    cy = c // m
    if box is not None:
        return cx - 1, cx + 1, cy - 1, cy + 1
    return max(cx - 1, 0), min(cx + 1, m - 1), max(cy - 1, 0), min(cy + 1, m - 1)


@njit(cache=True, inline="always", error_model="numpy")
def enter_cell(i, c, fs, iv, head, m, box):
    """Disk ``i`` enters cell ``c``: moved to its list. Returns the row of three cells that
    became neighbours (``gx0 > gx1``: none, beyond the grid) and the earliest contact kept
    from before, which still holds for the others (a partner that has moved since is a
    stale event, found when it comes due): ``(gx0, gx1, gy0, gy1, best, kind, stamp)``."""
    old = iv[i, CELL]
    cells.remove(head, iv, NEXT, PREV, i, old)
    d = c - old
    iv[i, CELL] = c
    cells.insert(head, iv, NEXT, PREV, i, c)
    gx0, gx1, gy0, gy1 = neighbourhood(c, m, box)
    if box is not None:
        # the grid wraps: the step is +-1 in one direction, modulo m (m >= 3)
        if c // m == old // m:
            gx0 = gx1 = c % m + (1 if c % m == (old % m + 1) % m else -1)
        else:
            gy0 = gy1 = c // m + (1 if c // m == (old // m + 1) % m else -1)
    elif d == 1 or d == -1:
        gx0 = gx1 = c % m + d
        if gx0 < 0 or gx0 >= m:
            gx0, gx1 = 1, 0
    else:
        gy0 = gy1 = c // m + (1 if d > 0 else -1)
        if gy0 < 0 or gy0 >= m:
            gx0, gx1 = 1, 0
    return gx0, gx1, gy0, gy1, fs[i, TP], iv[i, KIND_P], iv[i, STAMP_P]


@njit(cache=True, inline="always", error_model="numpy")
def predict(i, now, fs, iv, head, m, w, qt, qi, ht, qh, qs, qw, box, tab):
    """Schedule disk ``i``'s earliest event from ``now``: its wall contact, its next cell
    crossing, or a contact with a disk of the 3 x 3 cells around it (extrapolated to
    ``now``); the disk is first brought to ``now``."""
    gx0, gx1, gy0, gy1 = neighbourhood(iv[i, CELL], m, box)
    rescan(i, now, gx0, gx1, gy0, gy1, np.inf, NONE, 0, fs, iv, head, m, w, qt, qi, ht, qh, qs,
           qw, None, box, tab)


@njit(cache=True, inline="always", error_model="numpy")
def bring(fs, i, now, tan):
    """``(x, y)`` of disk ``i`` flown to ``now`` (stored, its clock set to ``now``); its row
    of the tangent observer ``tan`` (if any) flown with it, ``dq += dv dt``."""
    dt = now - fs[i, T]
    x = fs[i, X] + fs[i, VX] * dt
    y = fs[i, Y] + fs[i, VY] * dt
    fs[i, X] = x
    fs[i, Y] = y
    fs[i, T] = now
    if tan is not None:
        u = tan[0]
        if u.shape[0] > 0:
            u[i, 0] += u[i, 2] * dt
            u[i, 1] += u[i, 3] * dt
    return x, y


@njit(cache=True, inline="always", error_model="numpy")
def collide(i, j, now, fs, rule, mass, tan, box, clock, tab):
    r"""The disk-disk collision of ``i`` and ``j`` at ``now`` (both brought there, with their
    tangent rows): the rule's velocity map, the elastic rule's energy anchored to the pair's
    energy before, both wall times afresh (the box: none; ``j`` seen under its nearest
    image). Returns the mass factors ``(ki, kj)`` of the velocity map (1 for equal masses).

    The pressure's sums, into ``clock`` (Allen & Tildesley, *Computer Simulation of
    Liquids*, 2nd ed. (2017), sec. 2.4 and 3.7.2: the collisional virial): with
    :math:`\Delta p_i = m_i \Delta v_i`, the pair's virial
    :math:`\tfrac12 r_{ij}\cdot(\Delta p_i - \Delta p_j)` (:math:`= \sigma |\Delta p|`
    under the elastic rule, :math:`\Delta p_j = -\Delta p_i \parallel r_{ij}`) into
    ``VIRIAL_B`` if the contact point :math:`x_i - r_i r_{ij}/\sigma` lies inside the
    central disk of squared radius ``clock[RB2]`` (the box: always); into ``VIRIAL`` the
    table's :math:`r_i\cdot\Delta p_i + r_j\cdot\Delta p_j` (absolute positions: the
    virial theorem with the wall as external force holds for the mirror rule too) or the
    box's pair virial (minimum image)."""
    xi, yi = bring(fs, i, now, tan)
    xj, yj = bring(fs, j, now, tan)
    if box is not None:
        # the image of j next to i (in contact: |x_i - x_j| = sigma < box / 3)
        if xi - xj > 0.5 * box:
            xj += box
        elif xi - xj < -0.5 * box:
            xj -= box
        if yi - yj > 0.5 * box:
            yj += box
        elif yi - yj < -0.5 * box:
            yj -= box
    ai, bi, aj, bj = fs[i, VX], fs[i, VY], fs[j, VX], fs[j, VY]
    ki = 1.0
    kj = 1.0
    mi = 1.0
    mj = 1.0
    if mass is not None:
        mi = mass[i]
        mj = mass[j]
        ki, kj = mass_factors(mi, mj)
    ai2, bi2, aj2, bj2 = pair_event(xi, yi, ai, bi, xj, yj, aj, bj, rule, ki, kj)
    if rule != 0:
        e = pair_energy(ai, bi, aj, bj, ki, kj)
        ai2, bi2, aj2, bj2 = anchor_energy(ai2, bi2, aj2, bj2, e, ki, kj)
    fs[i, VX] = ai2
    fs[i, VY] = bi2
    fs[j, VX] = aj2
    fs[j, VY] = bj2
    dpx = mi * (ai2 - ai)
    dpy = mi * (bi2 - bi)
    dqx = mj * (aj2 - aj)
    dqy = mj * (bj2 - bj)
    dx = xi - xj
    dy = yi - yj
    pv = 0.5 * (dx * (dpx - dqx) + dy * (dpy - dqy))
    if box is None:
        if tab is None:
            fs[i, TW] = now + boundary_hit_time(xi, yi, ai2, bi2, 1.0 - fs[i, RAD])
            fs[j, TW] = now + boundary_hit_time(xj, yj, aj2, bj2, 1.0 - fs[j, RAD])
        else:
            fs[i, TW] = now + dw.hit_where(tab, i, xi, yi, ai2, bi2)
            fs[j, TW] = now + dw.hit_where(tab, j, xj, yj, aj2, bj2)
        clock[VIRIAL] += xi * dpx + yi * dpy + xj * dqx + yj * dqy
        s = fs[i, RAD] / (fs[i, RAD] + fs[j, RAD])
        cx = xi - s * dx
        cy = yi - s * dy
        if cx * cx + cy * cy < clock[RB2]:
            clock[VIRIAL_B] += pv
    else:
        clock[VIRIAL] += pv
        clock[VIRIAL_B] += pv
    return ki, kj


@njit(cache=True, inline="always", error_model="numpy")
def pair_tangent_rows(u, lg, i, j, fs, ai, bi, aj, bj, rule, ki, kj):
    """The tangent rows of ``i`` and ``j`` across their collision (`tangent.pair_tangent`;
    both disks and rows at the contact, ``(ai, bi)``, ``(aj, bj)`` the incoming velocities),
    and all rows rescaled by ``1/BIG`` (``log BIG`` into ``lg[0]``) once the squared norm
    of one passes ``BIG`` (1e100): the vector grows at disk-disk collisions (the circle's
    wall only shears it; a table's focusing wall stretches it, and checks the same way), so
    this check keeps it finite however long the caller's segments are."""
    (u[i, 0], u[i, 1], u[i, 2], u[i, 3], u[j, 0], u[j, 1], u[j, 2], u[j, 3]) = pair_tangent(
        u[i, 0], u[i, 1], u[i, 2], u[i, 3], u[j, 0], u[j, 1], u[j, 2], u[j, 3],
        fs[i, X], fs[i, Y], fs[j, X], fs[j, Y], ai, bi, aj, bj,
        fs[i, VX], fs[i, VY], fs[j, VX], fs[j, VY], rule, ki, kj)
    si = u[i, 0] * u[i, 0] + u[i, 1] * u[i, 1] + u[i, 2] * u[i, 2] + u[i, 3] * u[i, 3]
    sj = u[j, 0] * u[j, 0] + u[j, 1] * u[j, 1] + u[j, 2] * u[j, 2] + u[j, 3] * u[j, 3]
    if si > BIG or sj > BIG:
        shrink_tangent(u, lg)


@njit(cache=True, error_model="numpy")
def shrink_tangent(u, lg):
    """All tangent rows times ``1/BIG``, ``log BIG`` added to ``lg[0]`` (the dynamics is
    linear: rows at different clocks scale alike)."""
    for k in range(u.shape[0]):
        for c in range(4):
            u[k, c] /= BIG
    lg[0] += np.log(BIG)


@njit(cache=True, error_model="numpy")
def fly_tangent(u, fs, iv, now):
    """Every live disk's tangent row flown to ``now`` (``dq += dv (now - t_k)``), as
    `rebase` flies the disks."""
    for k in range(u.shape[0]):
        if iv[k, CELL] >= 0:
            dt = now - fs[k, T]
            u[k, 0] += u[k, 2] * dt
            u[k, 1] += u[k, 3] * dt


def tangent_at(u, fs, clock, t_end):
    """The tangent vector at the common time ``t_end`` (absolute): a copy of the rows ``u``
    (the engine's numbering, each at its disk's own clock) flown there; and the flight
    times, for putting the rows back (`tangent_back`)."""
    dt = (t_end - clock[OFFSET]) - fs[:, T]
    out = u.copy()
    out[:, :2] += out[:, 2:] * dt[:, None]
    return out, dt


def tangent_back(u, common, dt):
    """Write the common-time rows ``common`` back into ``u`` at the disks' own clocks (flown
    back by ``dt``, from `tangent_at`)."""
    u[:, 2:] = common[:, 2:]
    u[:, :2] = common[:, :2] - common[:, 2:] * dt[:, None]


@njit(cache=True, inline="always", error_model="numpy")
def wrap(i, now, fs, iv, m, box, tan):
    """Disk ``i``, whose crossing into cell ``iv[i, STAMP]`` is due at ``now``, brought
    there and, if the crossing leaves the box, moved by ``-+box`` to the side it enters."""
    bring(fs, i, now, tan)
    c = iv[i, STAMP]
    old = iv[i, CELL]
    if old % m == m - 1 and c % m == 0:
        fs[i, X] -= box
    elif old % m == 0 and c % m == m - 1:
        fs[i, X] += box
    elif old // m == m - 1 and c // m == 0:
        fs[i, Y] -= box
    elif old // m == 0 and c // m == m - 1:
        fs[i, Y] += box


@njit(cache=True, error_model="numpy")
def setup(fs, iv, head, m, w, qt, qi, ht, qh, qs, qw, box, tab):
    """Fill the cells and the wall times (the box: none) for the disks of ``fs`` at local
    time 0 (their clocks set to 0), and file each disk's first prediction as a `PREDICT`
    event at time 0: `drive` makes it (the scan is compiled once, in the loop)."""
    n = fs.shape[0]
    for c in range(head.shape[0]):
        head[c] = -1
    for i in range(n):
        fs[i, T] = 0.0
        if box is None:
            if tab is None:
                fs[i, TW] = boundary_hit_time(fs[i, X], fs[i, Y], fs[i, VX], fs[i, VY],
                                              1.0 - fs[i, RAD])
                c = cells.cell_of(fs[i, X], fs[i, Y], m, w)
            else:
                fs[i, TW] = dw.hit_where(tab, i, fs[i, X], fs[i, Y], fs[i, VX], fs[i, VY])
                c = cells.cell_of_table(fs[i, X], fs[i, Y], m, w, tab[4])
        else:
            fs[i, TW] = np.inf
            c = cells.cell_of_box(fs[i, X], fs[i, Y], m, w)
        fs[i, TP] = np.inf
        iv[i, COUNT] = 0
        iv[i, KIND] = PREDICT
        iv[i, CELL] = c
        cells.insert(head, iv, NEXT, PREV, i, c)
    cal.build(qt, qi, ht, qh, qs, qw, np.zeros(n))


@njit(cache=True, error_model="numpy")
def rebase(fs, iv, qt, qi, ht, qh, qs, qw, now):
    """Bring every disk in the table to ``now`` and shift all clocks back by ``now``."""
    for i in range(fs.shape[0]):
        if iv[i, CELL] >= 0:
            dt = now - fs[i, T]
            fs[i, X] += fs[i, VX] * dt
            fs[i, Y] += fs[i, VY] * dt
            fs[i, T] = 0.0
            fs[i, TW] -= now
            fs[i, TP] -= now
    for k in range(qt.shape[0]):
        qt[k] -= now
    cal.build(qt, qi, ht, qh, qs, qw, qt)


@njit(cache=True, error_model="numpy")
def check_state(fs, iv, head, m, now, dbg, box, tab):
    """Debug observer: the largest overlap of two disks and the largest distance of a
    centre outside its room ``1 - r`` (the box: outside ``[0, L]^2``), at ``now`` (all
    disks flown there), into ``dbg[0]``, ``dbg[1]`` (maxima over the calls); ``dbg[2]``
    counts the calls. Overlaps in the box: nearest images."""
    for i in range(fs.shape[0]):
        if iv[i, CELL] < 0:
            continue
        dt = now - fs[i, T]
        x = fs[i, X] + fs[i, VX] * dt
        y = fs[i, Y] + fs[i, VY] * dt
        if box is None:
            if tab is None:
                dbg[1] = max(dbg[1], np.sqrt(x * x + y * y) - (1.0 - fs[i, RAD]))
            else:
                dbg[1] = max(dbg[1], dw.outside(tab[0], tab[1], tab[2], tab[3], x, y))
        else:
            dbg[1] = max(dbg[1], -x, -y, x - box, y - box)
        gx0, gx1, gy0, gy1 = neighbourhood(iv[i, CELL], m, box)
        for gy in range(gy0, gy1 + 1):
            for gx in range(gx0, gx1 + 1):
                k = head[gx % m + m * (gy % m)]
                while k >= 0:
                    if k > i:
                        dk = now - fs[k, T]
                        dx = x - (fs[k, X] + fs[k, VX] * dk)
                        dy = y - (fs[k, Y] + fs[k, VY] * dk)
                        if box is not None:
                            dx -= box * np.round(dx / box)
                            dy -= box * np.round(dy / box)
                        ov = fs[i, RAD] + fs[k, RAD] - np.sqrt(dx * dx + dy * dy)
                        dbg[0] = max(dbg[0], ov)
                    k = iv[k, NEXT]
    dbg[2] += 1.0


@njit(cache=True, error_model="numpy", _nrt=False)
def drive(fs, iv, head, m, w, qt, qi, ht, qh, qs, qw, rule, mass, t_end, max_events,
          stall_dt, clock, cnt, pp_t, pp_i, pp_j, esc, ident, reorder_every, arcs, walls, samp,
          contacts, tan, dbg, box, tab):
    r"""Run the event loop until ``t_end`` (absolute; events at ``t_end`` included).

    Returns a status of `kicktimes.billiard.kernels.observe`: ``DONE``, ``FULL`` (a log is
    full: grow it and call again, the loop resumes where it stopped), ``OVER_BUDGET``
    (``max_events`` collisions, disk-disk and wall) or ``STALLED``.

    ``pp_t, pp_i, pp_j``: the disk-disk log (absolute time, ``i < j``) and ``esc[i]`` the
    escape time of disk ``i`` (``inf``), both in the caller's numbering: engine disk ``k`` is
    the caller's ``ident[k]``. Every ``reorder_every`` disk-disk collisions (0: never) the
    loop returns `REORDER`, for the caller to renumber the disks in space (`relabel`).
    Observers (``None``: compiled out): ``arcs`` the
    holes; ``walls = (bt, bd, bx, by, bs, sel)`` the contacts of the disks with
    ``sel[i]``; ``samp = (tau, sdisks, spos)``: positions of ``sdisks`` at ``k tau`` into
    ``spos[k]``; ``contacts = (cx, cy)`` the contact points of the disk-disk log;
    ``tan = (u, lg)`` a tangent vector, ``u[k] = (dx, dy, dvx, dvy)`` of disk ``k`` at its
    own clock ``fs[k, T]`` (flown with it by `bring`, through collisions by
    `tangent.pair_tangent`, wall contacts by `tangent.wall_tangent`, zeroed at an escape;
    ``u`` of shape (0, 4): off), ``lg[0]`` the log of its rescalings;
    ``dbg`` (debug mode if ``dbg[3] != 0``): `check_state` after every event.

    ``box``: ``None``, the unit table; else the side ``L`` of the periodic box
    ``[0, L)^2`` (no wall events; a crossing out of an edge cell moves the centre by
    ``-+L`` into the cell across, so centres stay in ``[0, L)``). The pressure's sums
    accumulate in ``clock`` (`collide`; ``W_IMPULSE``: the wall's :math:`\sum m|\Delta
    v|`, escapes excluded). ``tab``: ``None``, the unit circle; else a stadium or an
    ellipse (`kicktimes.billiard.kernels.disk_walls`; with ``box`` None and equal radii).
    """
    cap = pp_t.shape[0]
    t_loc = t_end - clock[OFFSET]
    while True:
        i, te = cal.top(qt, qi, ht, qh, qs, qw)
        if samp is not None:
            tau, sdisks, spos = samp
            while cnt[K_SAMPLE] < spos.shape[0]:
                ts = cnt[K_SAMPLE] * tau - clock[OFFSET]
                if ts > te or ts > t_loc:
                    break
                ks = cnt[K_SAMPLE]
                for q in range(sdisks.shape[0]):
                    k = sdisks[q]
                    if iv[k, CELL] >= 0:
                        spos[ks, q, 0] = fs[k, X] + fs[k, VX] * (ts - fs[k, T])
                        spos[ks, q, 1] = fs[k, Y] + fs[k, VY] * (ts - fs[k, T])
                    else:
                        spos[ks, q, 0] = np.nan
                        spos[ks, q, 1] = np.nan
                cnt[K_SAMPLE] = ks + 1
        if te > t_loc:
            return ob.DONE
        if te > REBASE:
            # no event before te: every disk can fly there, and te becomes 0
            now = te
            if tan is not None:
                fly_tangent(tan[0], fs, iv, now)
            rebase(fs, iv, qt, qi, ht, qh, qs, qw, now)
            yk = now - clock[COMP]
            tn = clock[OFFSET] + yk
            clock[COMP] = (tn - clock[OFFSET]) - yk
            clock[OFFSET] = tn
            clock[T_CHECK] -= now
            t_loc = t_end - clock[OFFSET]
            continue
        if dbg is not None:
            if dbg[3] != 0.0:
                check_state(fs, iv, head, m, te, dbg, box, tab)
        kind = iv[i, KIND]
        if kind != PREDICT:
            # a stall: STALL_EVENTS events in less than STALL_EVENTS * stall_dt
            cnt[N_CHECK] += 1
            if cnt[N_CHECK] >= STALL_EVENTS:
                if te - clock[T_CHECK] < STALL_EVENTS * stall_dt:
                    return ob.STALLED
                clock[T_CHECK] = te
                cnt[N_CHECK] = 0
        # the disks to predict afresh after the event: ``pa`` (and ``pb``), as entering a
        # cell if ``enter``
        pa = i
        pb = -1
        enter = False
        if kind >= 0:
            j = kind
            if iv[j, COUNT] != iv[i, STAMP]:
                # the partner has moved since the prediction
                cnt[N_STALE] += 1
            else:
                n = cnt[N_PP]
                if n >= cap:
                    return ob.FULL
                if n + cnt[N_WALL] >= max_events:
                    return ob.OVER_BUDGET
                ai, bi, aj, bj = fs[i, VX], fs[i, VY], fs[j, VX], fs[j, VY]
                ki, kj = collide(i, j, te, fs, rule, mass, tan, box, clock, tab)
                if tan is not None:
                    if tan[0].shape[0] > 0:
                        pair_tangent_rows(tan[0], tan[1], i, j, fs, ai, bi, aj, bj, rule, ki,
                                          kj)
                pp_t[n] = clock[OFFSET] + te
                pp_i[n] = min(ident[i], ident[j])
                pp_j[n] = max(ident[i], ident[j])
                if contacts is not None:
                    contacts[0][n] = 0.5 * (fs[i, X] + fs[j, X])
                    contacts[1][n] = 0.5 * (fs[i, Y] + fs[j, Y])
                cnt[N_PP] = n + 1
                iv[i, COUNT] += 1
                iv[j, COUNT] += 1
                pb = j
        elif kind == WALL:
            if walls is not None:
                if walls[5][i] and cnt[N_WLOG] >= walls[0].shape[0]:
                    return ob.FULL
            if cnt[N_PP] + cnt[N_WALL] >= max_events:
                return ob.OVER_BUDGET
            x, y = bring(fs, i, te, tan)
            iv[i, COUNT] += 1
            cnt[N_WALL] += 1
            if arcs is not None:
                if ob.in_hole(x, y, arcs):
                    # the disk leaves the table: out of its cell, never scheduled again
                    esc[ident[i]] = clock[OFFSET] + te
                    cells.remove(head, iv, NEXT, PREV, i, iv[i, CELL])
                    iv[i, CELL] = -1
                    iv[i, KIND] = NONE
                    cnt[N_ESC] += 1
                    cal.update(qt, qi, ht, qh, qs, qw, i, np.inf)
                    if tan is not None:
                        if tan[0].shape[0] > 0:
                            # the disk leaves the phase space: its deviation with it
                            for c in range(4):
                                tan[0][i, c] = 0.0
                    continue
            if tab is None:
                x, y, vx, vy, tn, sin_theta = wall_event(x, y, fs[i, VX], fs[i, VY],
                                                         1.0 - fs[i, RAD], rule)
                if tan is not None:
                    u = tan[0]
                    if u.shape[0] > 0:
                        ai = fs[i, VX]
                        bi = fs[i, VY]
                        # a reflection (or a grazing slide, where the map is singular); a
                        # disk already moving inward is not reflected: the identity (as
                        # drive_two)
                        if x * ai + y * bi >= 0.0:
                            u[i, 0], u[i, 1], u[i, 2], u[i, 3] = wall_tangent(
                                u[i, 0], u[i, 1], u[i, 2], u[i, 3], x, y, ai, bi, vx, vy,
                                1.0 - fs[i, RAD])
            else:
                x, y, vx, vy, tn, nx, ny, kap, sin_theta = dw.table_wall(
                    tab, i, x, y, fs[i, VX], fs[i, VY], rule)
                if tan is not None:
                    u = tan[0]
                    if u.shape[0] > 0:
                        # the reflection's map with the wall's curvature (as drive_tables;
                        # a grazing slide takes it too)
                        u[i, 0], u[i, 1], u[i, 2], u[i, 3] = curved_wall_tangent(
                            u[i, 0], u[i, 1], u[i, 2], u[i, 3], fs[i, VX], fs[i, VY], vx, vy,
                            nx, ny, kap)
                        # a focusing wall stretches too (the stadium's arcs): the same
                        # check as at a disk-disk collision keeps the rows finite
                        if (u[i, 0] * u[i, 0] + u[i, 1] * u[i, 1] + u[i, 2] * u[i, 2]
                                + u[i, 3] * u[i, 3]) > BIG:
                            shrink_tangent(u, tan[1])
            if walls is not None:
                if walls[5][i]:
                    q = cnt[N_WLOG]
                    walls[0][q] = clock[OFFSET] + te
                    walls[1][q] = ident[i]
                    walls[2][q] = x
                    walls[3][q] = y
                    walls[4][q] = sin_theta
                    cnt[N_WLOG] = q + 1
            mw = 1.0
            if mass is not None:
                mw = mass[i]
            clock[W_IMPULSE] += mw * np.sqrt((vx - fs[i, VX]) ** 2 + (vy - fs[i, VY]) ** 2)
            fs[i, X] = x
            fs[i, Y] = y
            fs[i, VX] = vx
            fs[i, VY] = vy
            fs[i, TW] = te + tn
        elif kind == CROSS:
            cnt[N_CROSS] += 1
            enter = True
            if box is not None:
                wrap(i, te, fs, iv, m, box, tan)
        elif kind != PREDICT:
            return ob.DONE
        for k in range(1 if pb < 0 else 2):
            d = pa if k == 0 else pb
            if enter:
                gx0, gx1, gy0, gy1, best, bk, bs = enter_cell(d, iv[d, STAMP], fs, iv, head, m,
                                                              box)
            else:
                gx0, gx1, gy0, gy1 = neighbourhood(iv[d, CELL], m, box)
                best = np.inf
                bk = NONE
                bs = 0
            rescan(d, te, gx0, gx1, gy0, gy1, best, bk, bs, fs, iv, head, m, w, qt, qi, ht,
                   qh, qs, qw, tan, box, tab)
        if pb >= 0 and reorder_every > 0:
            cnt[N_SINCE] += 1
            if cnt[N_SINCE] >= reorder_every:
                cnt[N_SINCE] = 0
                return REORDER


@njit(cache=True, error_model="numpy")
def relabel(fs, iv, head, m, qt, qi, ht, qh, qs, qw, order):
    """Renumber the disks: the disk numbered ``order[k]`` becomes disk ``k``. Returns the
    new number of each old disk.

    A pure relabelling between two events: the rows of ``fs`` and ``iv`` move with their
    disks (each keeps its clock, position and scheduled event; a partner's index in the
    event table is renamed), the cell lists and the calendar are rebuilt from the moved
    rows. Nothing is predicted again, so the run goes on with the same events, bitwise, up
    to the order of exactly simultaneous ones. The disks drift apart as they diffuse; at
    10^4 disks, renumbering them in space every few collisions per disk keeps a collision's
    neighbours in nearby cache lines (benchmarks/bench_disks.py)."""
    n = fs.shape[0]
    new_of = np.empty(n, dtype=np.int32)
    for k in range(n):
        new_of[order[k]] = k
    fs_old = fs.copy()
    iv_old = iv.copy()
    times = np.empty(n)
    for k in range(n):
        o = order[k]
        for c in range(fs.shape[1]):
            fs[k, c] = fs_old[o, c]
        for c in range(iv.shape[1]):
            iv[k, c] = iv_old[o, c]
        if iv[k, KIND] >= 0:
            iv[k, KIND] = new_of[iv[k, KIND]]
        if iv[k, KIND_P] >= 0:
            iv[k, KIND_P] = new_of[iv[k, KIND_P]]
        times[k] = qt[o]
    for c in range(head.shape[0]):
        head[c] = -1
    for k in range(n - 1, -1, -1):
        if iv[k, CELL] >= 0:
            cells.insert(head, iv, NEXT, PREV, k, iv[k, CELL])
    cal.build(qt, qi, ht, qh, qs, qw, times)
    return new_of


@njit(cache=True, error_model="numpy")
def final_state(fs, iv, clock, t_end):
    """Rows ``(x, y, vx, vy)`` of the disks at ``t_end`` (escaped disks: at their escape)."""
    n = fs.shape[0]
    out = np.empty((n, 4))
    t_loc = t_end - clock[OFFSET]
    for i in range(n):
        dt = t_loc - fs[i, T] if iv[i, CELL] >= 0 else 0.0
        out[i, 0] = fs[i, X] + fs[i, VX] * dt
        out[i, 1] = fs[i, Y] + fs[i, VY] * dt
        out[i, 2] = fs[i, VX]
        out[i, 3] = fs[i, VY]
    return out


def no_observers(n: int) -> tuple:
    """``(mass, arcs, walls, samp, contacts, tan, dbg)`` of `drive` with every observer
    present and off (no holes, no disk selected, no samples, no tangent, no checks): the
    types of the loop's observer variant, which a table always runs."""
    return (np.ones(n), np.empty((0, 2)),
            (np.empty(1), np.empty(1, np.int32), np.empty(1), np.empty(1), np.empty(1),
             np.zeros(n, dtype=np.bool_)),
            (1.0, np.zeros(0, dtype=np.int64), np.empty((0, 0, 2))),
            (np.empty(1), np.empty(1)), (np.empty((0, 4)), np.zeros(1)),
            np.array([-np.inf, -np.inf, 0.0, 0.0]))


def new_engine(state: np.ndarray, radii: np.ndarray, m: int, w: float,
               box: float | None = None, tab: tuple | None = None) -> tuple:
    """``(perm, engine)``: the engine's arrays ``(fs, iv, head, qt, qi, ht, qh, qs, qw)`` for
    a validated ``state`` (n, 4), set up at time 0 (`setup`), its disk ``k`` the caller's
    disk ``perm[k]`` (`cells.spatial_order`: neighbours share cache lines). ``tab``: a
    table's switch (`drive`; its ``where`` rows filled here, in the engine's numbering).

    Memory: 64 + 32 bytes per disk here, 36 in the calendar, 4 per cell (at most about
    ``4 n`` cells) and per bucket (``2 n`` rounded up to a power of two): 153-161 bytes per
    disk at 10^4 disks (docs/disks.md)."""
    n = state.shape[0]
    perm = cells.spatial_order(state[:, 0], state[:, 1], m, w, box,
                               None if tab is None else tab[4])
    fs = aligned_zeros((n, 8), np.float64)
    fs[:, :4] = state[perm]
    fs[:, RAD] = radii[perm]
    iv = aligned_zeros((n, 8), np.int32)
    head = np.empty(m * m, dtype=np.int32)
    q = cal.new_calendar(n, 1.0)
    no_log = np.empty(0, dtype=np.int32)
    if tab is None:
        setup(fs, iv, head, m, w, *q, box, None)
        # the first predictions, made by the loop up to (not including) the first event at 0
        drive(fs, iv, head, m, w, *q, 0, None, 0.0, 0, 0.0, np.zeros(N_CLOCK),
              np.zeros(9, np.int64), np.empty(0), no_log, no_log, np.empty(n),
              np.arange(n, dtype=np.int32), 0, None, None, None, None, None, None, box, None)
    else:
        setup(fs, iv, head, m, w, *q, None, tab)
        mass, arcs, walls, samp, con, tan, dbg = no_observers(n)
        drive(fs, iv, head, m, w, *q, 0, mass, 0.0, 0, 0.0, np.zeros(N_CLOCK),
              np.zeros(9, np.int64), np.empty(0), no_log, no_log, np.empty(n),
              np.arange(n, dtype=np.int32), 0, arcs, walls, samp, con, tan, dbg, None, tab)
    # buckets about two event spacings wide: a disk's next event is about mean(qt) away
    qt = q[0]
    finite = qt[np.isfinite(qt)]
    if finite.size:
        q[5][0] = 1.0 / (2.0 * max(float(finite.mean()), 1e-300) / finite.size)
        cal.build(*q, qt.copy())
    return perm, (fs, iv, head, *q)
