"""Initial states of N disks in a table (the unit circle, a stadium, an ellipse) or a
periodic square box: `initial_state`.

Positions: random sequential addition (RSA) up to packing `RSA_PACKING`; denser states
are grown from there with the engine itself (Lubachevsky-Stillinger growth in steps: the
disks move, then each grows by half the room it has, `grow_step`); finally the disks are
relaxed by the dynamics (`RELAX_COLLISIONS` collisions per disk), whose invariant measure
is uniform over the non-overlapping configurations. Velocities are drawn last. In the
periodic box ``[0, L)^2`` the same, with nearest images and no wall (`box_side` gives
``L`` for a packing). In a stadium or an ellipse the same with the candidates drawn in
the table's bounding box and kept if their disk lies inside (``table.contains``), and the
room to the wall from ``table.wall_distance``. docs/disks.md, "Initial states".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard import checks as chk
from kicktimes.billiard.many_disks import (
    check_box,
    check_disks_table,
    check_radii_of,
    engine_run,
)
from kicktimes.billiard.tables import Circle
from kicktimes.stats.enskog import PACKING_MAX, contact_value
from kicktimes.validation import (
    check_int,
    check_real,
    check_rng,
    keyword_only_after,
    renamed_keyword,
)

__all__ = ["box_side", "initial_state", "grow_step"]

#: RSA places disks directly up to this packing (its jamming limit is 0.547)
RSA_PACKING = 0.35
#: densest state `initial_state` grows
PACKING_LIMIT = 0.7
#: collisions per disk of the relaxation run, and of each growth step
RELAX_COLLISIONS = 20.0
GROW_COLLISIONS = 2.0
#: at most this many growth steps
GROW_STEPS = 2000


@njit(cache=True, error_model="numpy")
def _clear_of_cell(x, y, r, q, xy, radii, nxt, box):
    """Whether a disk of radius ``r`` at ``(x, y)`` overlaps none of the disks of one cell
    (the linked list from ``q``); in the periodic box of side ``box`` the nearest images
    (``box = 0``: no wrap, the circle)."""
    while q >= 0:
        dx = x - xy[q, 0]
        dy = y - xy[q, 1]
        if box > 0.0:
            dx -= box * np.round(dx / box)
            dy -= box * np.round(dy / box)
        s = r + radii[q]
        if dx * dx + dy * dy < s * s:
            return False
        q = nxt[q]
    return True


@njit(cache=True, error_model="numpy")
def _clear_of_cells(x, y, r, lo_x, hi_x, lo_y, hi_y, m, head, xy, radii, nxt, box):
    """Whether a disk of radius ``r`` at ``(x, y)`` overlaps none of the disks of the cells
    ``lo_x..hi_x x lo_y..hi_y`` (indices taken modulo the grid's ``m``: the box wraps),
    row by row (`_clear_of_cell`)."""
    for gy in range(lo_y, hi_y + 1):
        for gx in range(lo_x, hi_x + 1):
            if not _clear_of_cell(x, y, r, head[gx % m + m * (gy % m)], xy, radii, nxt, box):
                return False
    return True


@njit(cache=True, error_model="numpy")
def _place(i, x, y, c, xy, head, nxt):
    """Put disk ``i`` at ``(x, y)`` and at the head of cell ``c``'s list."""
    xy[i, 0] = x
    xy[i, 1] = y
    nxt[i] = head[c]
    head[c] = i


@njit(cache=True, error_model="numpy")
def _rsa(radii, order, u, xy, m, w, head, nxt, k0, j0, box, half):
    """Place disks ``order[k0:]`` one by one at candidates ``u[j]`` (uniform in [0, 1)^2,
    mapped to the square) inside the table (``box = 0``) or in the periodic box ``[0,
    box)^2`` (the grid of cells wraps; the nearest images count), clear of the disks
    placed; returns ``(k, j)``: disks placed so far and candidates used (more candidates
    are needed if ``j == len(u)``). ``half > 0``: another table, ``u`` the candidate
    centres themselves (already inside), the grid over ``[-half, half]^2``."""
    k = k0
    j = j0
    n = order.shape[0]
    r_max = radii[order[0]]
    while k < n and j < u.shape[0]:
        i = order[k]
        reach_cells = int(math.ceil((radii[i] + r_max) / w))
        if box > 0.0:
            x = box * u[j, 0]
            y = box * u[j, 1]
            j += 1
            cx = min(int(x / w), m - 1)
            cy = min(int(y / w), m - 1)
            # all cells once if the reach wraps round the box
            whole = 2 * reach_cells + 1 >= m
            lo_x, hi_x = (0, m - 1) if whole else (cx - reach_cells, cx + reach_cells)
            lo_y, hi_y = (0, m - 1) if whole else (cy - reach_cells, cy + reach_cells)
        elif half > 0.0:
            x = u[j, 0]
            y = u[j, 1]
            j += 1
            cx = min(max(int((x + half) / w), 0), m - 1)
            cy = min(max(int((y + half) / w), 0), m - 1)
            lo_x, hi_x = max(cx - reach_cells, 0), min(cx + reach_cells, m - 1)
            lo_y, hi_y = max(cy - reach_cells, 0), min(cy + reach_cells, m - 1)
        else:
            x = 2.0 * u[j, 0] - 1.0
            y = 2.0 * u[j, 1] - 1.0
            j += 1
            rho = 1.0 - radii[i]
            if x * x + y * y > rho * rho:
                continue
            cx = min(int((x + 1.0) / w), m - 1)
            cy = min(int((y + 1.0) / w), m - 1)
            lo_x, hi_x = max(cx - reach_cells, 0), min(cx + reach_cells, m - 1)
            lo_y, hi_y = max(cy - reach_cells, 0), min(cy + reach_cells, m - 1)
        if not _clear_of_cells(x, y, radii[i], lo_x, hi_x, lo_y, hi_y, m, head, xy, radii, nxt,
                               box):
            continue
        _place(i, x, y, cx + m * cy, xy, head, nxt)
        k += 1
    return k, j


def _rsa_table(radii: np.ndarray, rng: np.random.Generator, table) -> np.ndarray:
    """Centres by random sequential addition in a stadium or an ellipse (equal radii):
    candidates uniform in the bounding box, kept if inside (``table.contains``)."""
    n = radii.shape[0]
    r = float(radii[0])
    bx, by = table.bounding_box()
    half = float(max(bx, by))
    m = max(1, min(int(2.0 * half / (2.0 * r)), int(math.ceil(2.0 * math.sqrt(n)))))
    w = 2.0 * half / m
    head = np.full(m * m, -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    xy = np.zeros((n, 2))
    order = np.arange(n)
    k = 0
    tries = 0
    while k < n:
        u = rng.random((max(4 * (n - k), 256), 2))
        q = np.column_stack([bx * (2.0 * u[:, 0] - 1.0), by * (2.0 * u[:, 1] - 1.0)])
        q = np.ascontiguousarray(q[table.contains(q, r)])
        k, _ = _rsa(radii, order, q, xy, m, w, head, nxt, k, 0, 0.0, half)
        tries += u.shape[0]
        if tries > 1000 * n + 10**6:  # pragma: no cover - RSA_PACKING is far from jamming
            raise RuntimeError("random sequential addition did not place the disks")
    return xy


def _rsa_positions(radii: np.ndarray, rng: np.random.Generator, box=None,
                   table=None) -> np.ndarray:
    """Centres by random sequential addition, largest disks first (in the table, or in
    the periodic box of side ``box``; a stadium or an ellipse: `_rsa_table`)."""
    if table is not None and not isinstance(table, Circle):
        return _rsa_table(radii, rng, table)
    n = radii.shape[0]
    order = np.argsort(-radii, kind="stable")
    side = 2.0 if box is None else box  # the square the candidates are drawn in
    m = max(1, min(int(side / (2.0 * radii.max())), int(math.ceil(2.0 * math.sqrt(n)))))
    w = side / m
    head = np.full(m * m, -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    xy = np.zeros((n, 2))
    k = 0
    tries = 0
    while k < n:
        u = rng.random((max(4 * (n - k), 256), 2))
        k, _ = _rsa(radii, order, u, xy, m, w, head, nxt, k, 0,
                    0.0 if box is None else float(box), 0.0)
        tries += u.shape[0]
        if tries > 1000 * n + 10**6:  # pragma: no cover - RSA_PACKING is far from jamming
            raise RuntimeError("random sequential addition did not place the disks")
    return xy


def grow_step(xy: np.ndarray, radii: np.ndarray, target: np.ndarray, box=None,
              table=None) -> np.ndarray:
    """Radii grown by half the room each disk has (capped at ``target``): disk ``i`` may
    reach ``min(1 - |x_i|, min_j (d_ij - r_j))`` (the periodic box of side ``box``: no
    wall, nearest images; a stadium or an ellipse: ``table.wall_distance`` instead of
    ``1 - |x_i|``); if both disks of a pair take half their room they still do not
    overlap."""
    from scipy.spatial import cKDTree

    if table is not None and not isinstance(table, Circle):
        room = table.wall_distance(xy) - radii
    elif box is None:
        room = 1.0 - np.hypot(xy[:, 0], xy[:, 1]) - radii
    else:
        room = np.full(radii.shape, np.inf)
    pairs = cKDTree(xy, boxsize=box).query_pairs(2.0 * float(target.max()),
                                                 output_type="ndarray")
    if pairs.size:
        a, b = pairs[:, 0], pairs[:, 1]
        d = xy[a] - xy[b]
        if box is not None:
            d -= box * np.round(d / box)
        gap = np.hypot(d[:, 0], d[:, 1]) - radii[a] - radii[b]
        np.minimum.at(room, a, gap)
        np.minimum.at(room, b, gap)
    # (a margin of 1e-9 of the room: the contact tests of the engine take touching disks)
    return np.minimum(target, radii + 0.5 * np.maximum(room, 0.0) * (1.0 - 1e-9))


def _unit_velocities(n: int, rng: np.random.Generator) -> np.ndarray:
    theta = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.column_stack([np.cos(theta), np.sin(theta)])


def _relax(xy, radii, t, rng, box=None, table=None):
    """Positions after the mirror dynamics has run for ``t`` from unit velocities."""
    state = np.column_stack([xy, _unit_velocities(radii.shape[0], rng)])
    out = engine_run(state, radii, chk.RULES["mirror"], t, log=False, box=box, table=table)
    return out["final_state"][:, :2]


def _collision_time(radii: np.ndarray, per_disk: float, box=None, table=None) -> float:
    """The time in which each disk collides about ``per_disk`` times (Enskog, unit speeds)."""
    n = radii.shape[0]
    area = math.pi if box is None else box * box
    if table is not None and not isinstance(table, Circle):
        area = table.area(0.0)
    phi = math.pi * float(np.sum(radii ** 2)) / area
    r = math.sqrt(phi * area / (math.pi * n))
    nu = (n / area) * 4.0 * r * float(contact_value(phi)) * 4.0 / math.pi
    return per_disk / max(nu, 1e-12) if n > 1 else per_disk


@keyword_only_after(2, since="0.2.0")
def box_side(n_disks, r, *, packing) -> float:
    r"""The side :math:`L` of the periodic square box in which ``n_disks`` disks of radius
    ``r`` have the area fraction ``packing``: :math:`\varphi = N\pi r^2 / L^2`.

    >>> round(box_side(2000, 0.01, packing=0.3), 6)
    1.447203
    """
    n = check_int("n_disks", n_disks, low=1, high=10**7)
    r = check_real("r", r, low=0.0)
    packing = check_real("packing", packing, low=0.0, high=PACKING_MAX)
    return math.sqrt(n * math.pi * r * r / packing)


@renamed_keyword(old="seed", new="rng", since="0.2.0")
def initial_state(n_disks, r, *, rng=0, rule="mirror", masses=None, packing=None,
                  box=None, table=None) -> np.ndarray:
    """A state of ``n_disks`` non-overlapping disks in the unit table, a stadium or an
    ellipse (or a periodic square box), for `simulate_disks`.

    Parameters
    ----------
    n_disks : int
        Number of disks (``>= 1``).
    r : float or array_like or None
        The disks' radius, or one radius per disk (each in ``(0, 1)``); with ``packing``,
        relative radii (``None``: equal disks).
    rng : None, int, numpy.random.SeedSequence or numpy.random.Generator, default 0
        The random stream (`kicktimes.validation.check_rng`); ``seed=`` is its deprecated
        spelling (until 0.3.0).
    rule : {"mirror", "elastic"}
        The velocities: unit speeds with uniform directions (``"mirror"``), or uniform on
        the energy shell ``sum_i m_i |v_i|^2 = n_disks`` (``"elastic"``).
    masses : array_like, optional
        The masses of the energy shell (elastic rule; default 1).
    packing : float, optional
        The area fraction ``sum r_i^2`` (the table has area pi, a disk pi r^2), at most 0.7:
        the radii ``r`` are scaled to it. In the box, the true area fraction
        ``pi sum r_i^2 / L^2`` likewise (`box_side` gives ``L`` for given radii instead).
        In a stadium or an ellipse, as in the circle, the disks' area over the table's
        own area: ``pi n r^2 / table.area(0)`` (``pi + 4 a`` for `Stadium(a)`, ``pi a b``
        for `Ellipse(a, b)`), one radius ``r = sqrt(packing table.area(0) / (pi n))``.
    box : float, optional
        The side ``L`` of the periodic square box ``[0, L)^2`` instead of the table:
        centres in ``[0, L)``, nearest images; under the elastic rule the total momentum
        is set to 0 (then the energy shell ``sum m |v|^2 = n_disks``, ``kT = 1/2``).
    table : Circle, Stadium or Ellipse, optional
        The table (``None``: the unit circle; its states are those of before, bit for bit).
        A stadium or an ellipse takes one radius for every disk (``table.check_radius``).
        Not with ``box``.

    Returns
    -------
    ndarray, shape (n_disks, 4)
        Rows ``(x, y, vx, vy)``.

    Raises
    ------
    ValueError
        Naming the argument: a packing that cannot exist or is above 0.7, radii of the
        wrong shape, a box below three cells of one diameter (``L < 6 r_max``), ``table``
        with ``box``, a radius the table refuses or unequal radii in a stadium or an
        ellipse.

    Notes
    -----
    Positions are placed by random sequential addition up to packing 0.35; a denser
    state grows from there with the engine (each step: two collisions per disk of the
    mirror dynamics, then every disk grows by half the room it has, up to its radius).
    Then the dynamics runs for 20 collisions per disk, so that positions come close to
    the invariant measure, uniform over non-overlapping configurations (RSA alone is
    not: it favours gaps near the disks placed first). docs/disks.md, "Initial states".

    Examples
    --------
    >>> import numpy as np, kicktimes as kt
    >>> s = kt.initial_state(100, None, packing=0.3, rng=2)
    >>> s.shape, bool(np.allclose(np.hypot(s[:, 2], s[:, 3]), 1.0))
    ((100, 4), True)
    >>> b = kt.initial_state(2000, None, packing=0.3, box=1.0, rule="elastic", rng=2)
    >>> bool(abs(b[:, 2:].sum(axis=0)).max() < 1e-9), round(float((b[:, 2:] ** 2).sum()))
    (True, 2000)
    """
    n = check_int("n_disks", n_disks, low=1, high=10**7)
    rng = check_rng(rng, "rng")
    chk.check_choice("rule", rule, chk.RULES)
    box = check_box(box)
    table = check_disks_table(table, box)
    other = table is not None and not isinstance(table, Circle)
    # the table's packing sum r^2 is its area fraction (area pi); the box's, pi sum r^2/L^2
    unit = 1.0 if box is None else math.pi / (box * box)
    if other:
        unit = math.pi / table.area(0.0)
    if packing is not None:
        packing = check_real("packing", packing, low=0.0)
        if packing >= PACKING_MAX:
            raise ValueError(f"packing must lie in (0.0, {PACKING_LIMIT}]: a packing of "
                             f"{packing!r} cannot exist (the densest is pi/sqrt(12) = "
                             f"{PACKING_MAX:.6g})")
        rel = np.ones(n) if r is None else check_radii_of(r, n)
        radii = rel * math.sqrt(packing / (unit * float(np.sum(rel ** 2))))
        if other:
            radii = check_radii_of(radii, n, "packing", table=table)
        elif box is None and radii.max() >= 1.0:
            raise ValueError(f"packing={packing!r} makes a radius of {radii.max():.6g}, not "
                             f"below 1")
    else:
        if r is None:
            raise ValueError("give r (a radius, or one per disk) or packing")
        radii = check_radii_of(r, n, box=box, table=table)
    if box is not None and box < 6.0 * float(radii.max()) * (1.0 + 1e-9):
        raise ValueError(f"box must be at least 3 cells of one diameter wide, box >= 6 r_max "
                         f"= {6.0 * float(radii.max()) * (1.0 + 1e-9):.6g}, got {box!r}")
    phi = unit * float(np.sum(radii ** 2))
    if phi > PACKING_LIMIT:
        raise ValueError(f"packing must lie in (0.0, {PACKING_LIMIT}], got {phi:.6g}: denser "
                         f"states are not grown (hard disks freeze above about 0.70)")
    if masses is not None:
        if rule != "elastic":
            raise ValueError(f"masses apply to rule='elastic', got rule={rule!r}")
        masses = np.array(masses, dtype=np.float64)
        if masses.ndim == 0:
            masses = np.full(n, float(masses))
        if masses.shape != (n,) or not (np.isfinite(masses) & (masses > 0.0)).all():
            raise ValueError(f"masses must be {n} positive finite numbers (one per disk)")
    start = min(1.0, math.sqrt(RSA_PACKING / phi))
    cur = radii * start
    xy = _rsa_positions(cur, rng, box, table)
    steps = 0
    while n > 1 and (cur < radii).any():
        xy = _relax(xy, cur, _collision_time(cur, GROW_COLLISIONS, box, table), rng, box,
                    table)
        cur = grow_step(xy, cur, radii, box, table)
        steps += 1
        if steps > GROW_STEPS:
            raise RuntimeError(f"initial_state: the disks did not grow to packing {phi:.4g} "
                               f"in {GROW_STEPS} steps (reached "
                               f"{unit * float(np.sum(cur ** 2)):.4g})")
    if n > 1:
        xy = _relax(xy, radii, _collision_time(radii, RELAX_COLLISIONS, box, table), rng, box,
                    table)
    if rule == "mirror":
        v = _unit_velocities(n, rng)
    else:
        m = np.ones(n) if masses is None else masses
        v = rng.standard_normal((n, 2)) / np.sqrt(m)[:, None]
        if box is not None and n > 1:
            # no drift of the whole: the centre of mass at rest in the box
            v -= (m[:, None] * v).sum(axis=0) / m.sum()
        v *= math.sqrt(n / float(np.sum(m * (v[:, 0] ** 2 + v[:, 1] ** 2))))
    return np.column_stack([xy, v])
