"""The N-disk engine's wall in a table other than the circle: the helpers of its table switch.

`kicktimes.billiard.kernels.disks` takes a table as ``tab = (kind, p0, p1, p2, h, where)``
(``None``: the unit circle, whose own code stays as it was): the kernel tuple of
`kicktimes.billiard.kernels.tables` (``table.kernel(r)``, one radius for every disk), the
half side ``h`` of the cell grid's square ``[-h, h]^2`` and ``where`` (float64, ``(n, 2)``)
the "where" ``(w1, w2)`` of each disk's pending wall contact (`tables.hit`: the stadium's
piece, the ellipse's normal), which `tables.contact` needs when the contact comes due.
Every disk's ``where`` is written whenever its wall time is (`hit_where`).

The wall event (`table_wall`) is the sequence of `kicktimes.billiard.kernels.drive_tables`:
`tables.contact` (the centre put back on the wall, the normal, the curvature), `tables.bounce`
(reflection, or the grazing slide), one Newton step of the outgoing speed towards the
incoming one (the mirror rule: towards 1), and the next `tables.hit`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard.kernels import tables

__all__ = ["arc_lengths", "hit_where", "outside", "table_wall"]


@njit(cache=True, inline="always", error_model="numpy")
def hit_where(tab, i, x, y, vx, vy):
    """Time from now to disk ``i``'s next wall contact from ``(x, y)`` at ``(vx, vy)``; its
    "where" stored in ``tab``'s row ``i``."""
    kind, p0, p1, p2, _, where = tab
    t, w1, w2 = tables.hit(kind, p0, p1, p2, x, y, vx, vy)
    where[i, 0] = w1
    where[i, 1] = w2
    return t


@njit(cache=True, inline="always", error_model="numpy")
def table_wall(tab, i, x, y, vx, vy, rule):
    """Disk ``i``'s wall contact, due now at ``(x, y)`` with the incoming ``(vx, vy)``.

    Returns ``(x, y, wx, wy, t_next, nx, ny, kappa, sin_theta)``: the contact put back on
    the centre's curve, the outgoing velocity (its squared speed brought to the incoming
    one by one Newton step, to 1 under the mirror rule, ``rule == 0``), the time to the next
    contact (its "where" stored), the outward normal and the curvature there (for the
    tangent map), and ``sin_theta = v.t / |v|``, ``t = (-n_y, n_x)`` (as the circle's).
    """
    kind, p0, p1, p2, _, where = tab
    x, y, nx, ny, kappa = tables.contact(kind, p0, p1, p2, x, y, vx, vy, where[i, 0],
                                         where[i, 1])
    wx, wy = tables.bounce(vx, vy, nx, ny)
    if rule == 0:
        f = 1.5 - 0.5 * (wx * wx + wy * wy)
        sp = 1.0
    else:
        vv = vx * vx + vy * vy
        f = 1.5 - 0.5 * (wx * wx + wy * wy) / vv
        sp = math.sqrt(vv)
    wx *= f
    wy *= f
    sin_theta = (vy * nx - vx * ny) / sp
    tn = hit_where(tab, i, x, y, wx, wy)
    return x, y, wx, wy, tn, nx, ny, kappa, sin_theta


@njit(cache=True, error_model="numpy")
def outside(kind, p0, p1, p2, x, y):
    """How far ``(x, y)`` lies outside the centre's curve (negative: inside), for the
    engine's debug check: the stadium's exactly, the ellipse's along the normal of the
    nearest point of the curve (`tables.ellipse_parameter`)."""
    if kind == tables.CIRCLE:
        return math.sqrt(x * x + y * y) - p0
    if kind == tables.STADIUM:
        dx = max(abs(x) - p0, 0.0)
        return math.sqrt(dx * dx + y * y) - p1
    c, s = tables.ellipse_parameter(x, y, p0, p1, p2)
    nx, ny, _ = tables.ellipse_normal(c, s, p0, p1, p2)
    h = math.sqrt(p1 * p1 * c * c + p0 * p0 * s * s)
    cx = (p0 - p2 * p1 / h) * c
    cy = (p1 - p2 * p0 / h) * s
    return (x - cx) * nx + (y - cy) * ny


@njit(cache=True, error_model="numpy")
def arc_lengths(kind, p0, p1, p2, x, y):
    """The arc length ``s`` of each wall contact ``(x[k], y[k])`` along the centre's curve,
    counter-clockwise from its rightmost point (`tables.boundary_coordinates`)."""
    out = np.empty(x.shape[0])
    for k in range(x.shape[0]):
        out[k] = tables.boundary_coordinates(kind, p0, p1, p2, x[k], y[k], 1.0, 0.0)[0]
    return out
