"""The cell list of the N-disk engine: a square grid over the table, one linked list per cell.

The table's bounding square ``[-1, 1]^2`` is cut into ``m x m`` cells of width
``w = 2 / m >= 2 r_max`` (at least one largest diameter), so two disks can touch only if
their cells are neighbours (the 3 x 3 block around a cell). Cell ``c = cx + m cy`` holds
a doubly linked list of its disks: ``head[c]`` the first disk (-1: empty), and per disk
``links[i, nx]``, ``links[i, pv]`` the next and previous (-1: none), so a disk is moved in
O(1) (the columns are arguments: the engine keeps them in its row of integers per disk,
one cache line). The grid has at most
about ``4 n`` cells (`grid`), so memory is O(n) however dilute the disks.

A disk's cell is kept exact by events: `crossing` gives the time to the next cell edge
its centre reaches and the cell beyond; the engine moves the disk at that time.

The periodic square box ``[0, L)^2`` (`grid_box`, `crossing_box`): ``m >= 3`` cells of
width ``w = L / m >= 2 r_max`` per side; the grid wraps (the neighbours of a cell on an
edge lie across the box, and a crossing out of the last cell enters the first), and
``m >= 3`` makes the 3 x 3 cells around any cell distinct, so each pair of neighbouring
cells is seen under exactly one image.

A table other than the circle (`grid_table`, `cell_of_table`, `crossing_table`): the
square ``[-h, h]^2`` around its bounding box ``[-X, X] x [-Y, Y]`` (``h = max(X, Y)``), cut
and clipped as the circle's square; the circle's own functions keep their literal ``1``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["cell_of", "cell_of_box", "cell_of_table", "cell_order", "crossing", "crossing_box",
           "crossing_table", "grid", "grid_box", "grid_table", "image_of", "insert", "remove",
           "spatial_order"]

INF = np.inf


def grid(n: int, r_max: float) -> tuple[int, float]:
    """``(m, w)``: cells per side and their width for ``n`` disks of largest radius ``r_max``.

    ``w >= 2 r_max`` (a hair more, so that round-off cannot bring two touching disks two
    cells apart), and ``m^2 <= max(9, 4 n)``: more cells than that would only cost memory
    (at packing ``phi`` the finest grid has ``n / phi`` cells).
    """
    m = int(math.floor(2.0 / (2.0 * r_max * (1.0 + 1e-9))))
    m = max(1, min(m, max(3, int(math.ceil(2.0 * math.sqrt(n))))))
    return m, 2.0 / m


def grid_box(n: int, r_max: float, box: float) -> tuple[int, float]:
    """``(m, w)`` of the periodic box ``[0, box)^2``: as `grid` (``w >= 2 r_max`` by a hair,
    ``m^2 <= max(9, 4 n)``) with ``w = box / m`` and ``m >= 3``; a box narrower than three
    diameters, ``box < 6 r_max``, raises a ValueError naming ``box``."""
    m = int(math.floor(box / (2.0 * r_max * (1.0 + 1e-9))))
    if m < 3:
        raise ValueError(f"box must be at least 3 cells of one diameter wide, box >= 6 r_max "
                         f"= {6.0 * r_max * (1.0 + 1e-9):.6g}, got {box!r} (a smaller box would "
                         f"let a disk meet two images of one neighbour)")
    m = min(m, max(3, int(math.ceil(2.0 * math.sqrt(n)))))
    return m, box / m


def grid_table(n: int, r_max: float, half: float, area: float) -> tuple[int, float]:
    """``(m, w)`` of a table in the square ``[-half, half]^2`` whose own area is ``area``:
    ``w = 2 half / m >= 2 r_max`` by a hair, as `grid`, and at most about ``pi n`` cells
    over the table, as the circle has (``m <= 2 half sqrt(pi n / area)``: the circle's
    ``2 sqrt(n)``), so a long table's empty corners cost memory only (4 bytes a cell)."""
    m = int(math.floor(2.0 * half / (2.0 * r_max * (1.0 + 1e-9))))
    cap = int(math.ceil(2.0 * half * math.sqrt(math.pi * n / area)))
    m = max(1, min(m, max(3, cap)))
    return m, 2.0 * half / m


@njit(cache=True, inline="always", error_model="numpy")
def cell_of_table(x, y, m, w, h):
    """The cell ``cx + m cy`` of a centre ``(x, y)`` of the grid over ``[-h, h]^2``
    (clamped to the grid)."""
    cx = min(max(int((x + h) / w), 0), m - 1)
    cy = min(max(int((y + h) / w), 0), m - 1)
    return cx + m * cy


@njit(cache=True, inline="always", error_model="numpy")
def crossing_table(x, y, vx, vy, c, m, w, h):
    """`crossing` in the grid over ``[-h, h]^2``: edges ``-h + k w``."""
    cx = c % m
    cy = c // m
    dt = INF
    cn = -1
    if vx > 0.0 and cx < m - 1:
        dt = (-h + (cx + 1) * w - x) / vx
        cn = c + 1
    elif vx < 0.0 and cx > 0:
        dt = (-h + cx * w - x) / vx
        cn = c - 1
    if vy > 0.0 and cy < m - 1:
        d = (-h + (cy + 1) * w - y) / vy
        if d < dt:
            dt = d
            cn = c + m
    elif vy < 0.0 and cy > 0:
        d = (-h + cy * w - y) / vy
        if d < dt:
            dt = d
            cn = c - m
    if dt < 0.0:
        dt = 0.0
    return dt, cn


@njit(cache=True, inline="always", error_model="numpy")
def cell_of_box(x, y, m, w):
    """The cell ``cx + m cy`` of a centre ``(x, y)`` of the periodic box (clamped to the
    grid: a centre a rounding error outside ``[0, L)`` stays in the edge cell)."""
    cx = min(max(int(math.floor(x / w)), 0), m - 1)
    cy = min(max(int(math.floor(y / w)), 0), m - 1)
    return cx + m * cy


@njit(cache=True, inline="always", error_model="numpy")
def image_of(g, m, box):
    """``(g', shift)`` of a grid index ``g`` of the periodic box that may lie one beyond the
    grid (``-1`` or ``m``): the cell across the box, ``g' = g mod m``, and the shift of
    the image its disks are seen under, ``-box`` or ``+box`` (``0`` inside the grid)."""
    if g < 0:
        return g + m, -box
    if g >= m:
        return g - m, box
    return g, 0.0


@njit(cache=True, inline="always", error_model="numpy")
def crossing_box(x, y, vx, vy, c, m, w):
    """``(dt, c_new)`` of the periodic box: as `crossing` with edges ``k w`` and the grid
    wrapped (out of column ``m - 1`` to the right into column 0, and so on); ``inf, -1``
    only for a disk at rest."""
    cx = c % m
    cy = c // m
    dt = INF
    cn = -1
    if vx > 0.0:
        dt = ((cx + 1) * w - x) / vx
        cn = c + 1 if cx < m - 1 else c - (m - 1)
    elif vx < 0.0:
        dt = (cx * w - x) / vx
        cn = c - 1 if cx > 0 else c + (m - 1)
    if vy > 0.0:
        d = ((cy + 1) * w - y) / vy
        if d < dt:
            dt = d
            cn = c + m if cy < m - 1 else c - m * (m - 1)
    elif vy < 0.0:
        d = (cy * w - y) / vy
        if d < dt:
            dt = d
            cn = c - m if cy > 0 else c + m * (m - 1)
    if dt < 0.0:
        dt = 0.0
    return dt, cn


@njit(cache=True, inline="always", error_model="numpy")
def cell_of(x, y, m, w):
    """The cell ``cx + m cy`` of a centre ``(x, y)`` (clamped to the grid)."""
    cx = int((x + 1.0) / w)
    cy = int((y + 1.0) / w)
    cx = min(max(cx, 0), m - 1)
    cy = min(max(cy, 0), m - 1)
    return cx + m * cy


@njit(cache=True, inline="always", error_model="numpy")
def insert(head, links, nx, pv, i, c):
    """Put disk ``i`` at the front of cell ``c``'s list."""
    f = head[c]
    links[i, nx] = f
    links[i, pv] = -1
    if f >= 0:
        links[f, pv] = i
    head[c] = i


@njit(cache=True, inline="always", error_model="numpy")
def remove(head, links, nx, pv, i, c):
    """Take disk ``i`` out of cell ``c``'s list."""
    a = links[i, pv]
    b = links[i, nx]
    if a >= 0:
        links[a, nx] = b
    else:
        head[c] = b
    if b >= 0:
        links[b, pv] = a


@njit(cache=True, inline="always", error_model="numpy")
def crossing(x, y, vx, vy, c, m, w):
    """``(dt, c_new)``: time until the centre ``(x, y)`` moving at ``(vx, vy)`` leaves cell
    ``c`` and the cell it enters (``inf``, -1 if it never leaves the grid's interior).

    Edges are ``-1 + k w``; a time that round-off made negative is 0 (the crossing is due).
    """
    cx = c % m
    cy = c // m
    dt = INF
    cn = -1
    if vx > 0.0 and cx < m - 1:
        dt = (-1.0 + (cx + 1) * w - x) / vx
        cn = c + 1
    elif vx < 0.0 and cx > 0:
        dt = (-1.0 + cx * w - x) / vx
        cn = c - 1
    if vy > 0.0 and cy < m - 1:
        d = (-1.0 + (cy + 1) * w - y) / vy
        if d < dt:
            dt = d
            cn = c + m
    elif vy < 0.0 and cy > 0:
        d = (-1.0 + cy * w - y) / vy
        if d < dt:
            dt = d
            cn = c - m
    if dt < 0.0:
        dt = 0.0
    return dt, cn


def cell_order(c: np.ndarray, m: int) -> np.ndarray:
    """A permutation of the disks in cells ``c`` (-1: none, last) that puts neighbours next
    to each other in memory: by cell, the cells in boustrophedon order (rows of cells,
    every other one reversed). The engine numbers its disks so, and renumbers them so as
    they diffuse (`kicktimes.billiard.kernels.disks.relabel`): at 10^4 disks the rows of
    neighbours then share cache lines."""
    c = np.asarray(c, dtype=np.int64)
    cx, cy = c % m, c // m
    key = np.where(c >= 0, cy * m + np.where(cy % 2 == 0, cx, m - 1 - cx), m * m)
    return np.argsort(key, kind="stable")


def spatial_order(x: np.ndarray, y: np.ndarray, m: int, w: float,
                  box: float | None = None, half: float | None = None) -> np.ndarray:
    """`cell_order` of the disks at centres ``(x, y)`` (of the unit table, of the periodic
    box ``[0, box)^2``, or of a table's grid over ``[-half, half]^2``)."""
    if half is not None:
        cx = np.clip(((x + half) / w).astype(np.int64), 0, m - 1)
        cy = np.clip(((y + half) / w).astype(np.int64), 0, m - 1)
        return cell_order(cx + m * cy, m)
    if box is not None:
        cx = np.clip(np.floor(x / w).astype(np.int64), 0, m - 1)
        cy = np.clip(np.floor(y / w).astype(np.int64), 0, m - 1)
        return cell_order(cx + m * cy, m)
    cx = np.clip(((x + 1.0) / w).astype(np.int64), 0, m - 1)
    cy = np.clip(((y + 1.0) / w).astype(np.int64), 0, m - 1)
    return cell_order(cx + m * cy, m)
