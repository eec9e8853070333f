"""Collision times and reflections in the unit circular table (pure numba kernels).

Conventions (docs/architecture.md, "The physics, precisely"): the table has radius 1, a disk of
radius ``r`` keeps its centre in ``|x| <= rho`` with ``rho = 1 - r``; two disks touch
when their centres are ``sigma = 2 r`` apart. Every function takes plain floats and
returns plain floats or tuples, so numba inlines them into the event loops.

The quadratic roots are evaluated in cancellation-free form: of the two algebraically
equal expressions ``(-b + sqrt(D)) / a`` and ``c / (b + sqrt(D))`` we use the one that
adds numbers of the same sign. This matters right after a collision, where the naive
formula subtracts two nearly equal numbers and can return a spurious tiny root.

Every division here has a divisor that cannot be zero (a speed tested non-zero, a root
``-b + sqrt(D)`` with ``b < 0``, the table radius), so these functions and the two-disk event
loop are compiled with ``error_model="numpy"``: numba then drops the zero test it puts
before each division under its default error model, which made the two-disk kernel
slower (benchmarks/bench_simulators.py --c-only; docs/benchmarks.md). The results are
the same to the bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from kicktimes.billiard._crmath import cos_sin

INF = np.inf

#: The grazing angle delta: a boundary contact whose velocity makes an angle smaller than
#: delta / 2 with the wall (|cos theta| < sin(delta) / 2, exactly tangent included) leaves
#: along the whispering-gallery chord of angle 2 delta (see `graze`). The factor 1/2 puts
#: the contacts of that chord (at angle delta) clearly on the ordinary side, so round-off
#: cannot make a sliding disk switch between the two treatments. Under the invariant
#: measure a contact is that close to tangent with probability 1.25e-9.
GRAZE_ANGLE = 1e-4
COS_GRAZE, SIN_GRAZE = cos_sin(GRAZE_ANGLE)  # correctly rounded: the same on every CPU
GRAZE_THRESHOLD = 0.5 * SIN_GRAZE


@njit(cache=True, error_model="numpy")
def boundary_hit_time(x, y, vx, vy, rho):
    """Time until a centre at ``(x, y)`` with velocity ``(vx, vy)`` reaches ``|x| = rho``.

    Solves ``|x + v t| = rho`` for the positive root,
    ``t = (-(x.v) + sqrt((x.v)^2 + |v|^2 (rho^2 - |x|^2))) / |v|^2``.
    For unit speed this is ``t = -x.v + sqrt((x.v)^2 - |x|^2 + rho^2)``.
    Returns ``inf`` for a disk at rest and ``0`` for a centre that round-off has put a
    hair outside the table while it moves outward (it is reflected at once).
    """
    vv = vx * vx + vy * vy
    if vv == 0.0:
        return INF
    b = x * vx + y * vy
    c = rho * rho - (x * x + y * y)
    disc = b * b + vv * c
    if disc < 0.0:
        disc = 0.0
    if b > 0.0:
        # moving outward: -b + sqrt(disc) would cancel, use the conjugate form
        t = c / (b + math.sqrt(disc))
    else:
        t = (-b + math.sqrt(disc)) / vv
    if t < 0.0:
        return 0.0
    return t


@njit(cache=True, error_model="numpy")
def pair_hit_time(dx, dy, wx, wy, sigma):
    """Time until two centres ``d = x1 - x2`` apart, relative velocity ``w = v1 - v2``, touch.

    First contact is the smaller root of ``|d + w t| = sigma`` while approaching
    (``d.w < 0``), in the cancellation-free form
    ``t = (|d|^2 - sigma^2) / (-(d.w) + sqrt((d.w)^2 - |w|^2 (|d|^2 - sigma^2)))``.
    Returns ``inf`` if the disks separate or miss, ``0`` if round-off has made them
    overlap by a hair while approaching.
    """
    b = dx * wx + dy * wy
    if b >= 0.0:
        return INF
    ww = wx * wx + wy * wy
    c = dx * dx + dy * dy - sigma * sigma
    disc = b * b - ww * c
    if disc <= 0.0:
        return INF
    t = c / (-b + math.sqrt(disc))
    if t < 0.0:
        return 0.0
    return t


@njit(cache=True, error_model="numpy")
def reflect(vx, vy, nx, ny):
    """Specular reflection ``v' = v - 2 (v.n) n`` for a unit normal ``n``."""
    p = 2.0 * (vx * nx + vy * ny)
    return vx - p * nx, vy - p * ny


@njit(cache=True, error_model="numpy")
def graze(x, y, vx, vy, rho, speed):
    """Outgoing velocity of a grazing contact at ``(x, y)`` (``|x| = rho``): the disk slides on.

    An exactly tangent contact is the whispering-gallery limit ``sin(theta) -> +-1``,
    where the chords shrink to points and the disk slides along the wall; reflecting it
    makes no progress (a chord of length 0, again and again at the same instant). The
    disk leaves instead along the chord of angle ``2 delta`` (``delta = GRAZE_ANGLE``) in
    its sense of rotation: ``v' = |v| (-sin(delta) n + s cos(delta) t)``, ``t`` the
    counter-clockwise tangent and ``s = sign(x vy - y vx)``. It is an exact billiard orbit
    (speed kept, inside the table, within ``rho (1 - cos delta) = 5e-9 rho`` of the wall)
    that advances along the wall at ``|v| delta / sin(delta) = |v|`` to 1e-8, the sliding
    speed, with one collision every ``2 rho sin(delta) / |v|``.
    """
    nx = x / rho
    ny = y / rho
    s = 1.0 if x * vy - y * vx >= 0.0 else -1.0
    return (speed * (-SIN_GRAZE * nx - s * COS_GRAZE * ny),
            speed * (-SIN_GRAZE * ny + s * COS_GRAZE * nx))


@njit(cache=True, error_model="numpy")
def boundary_normal(x, y):
    """Outward unit normal of the table at the contact point of a centre at ``(x, y)``."""
    rr = math.sqrt(x * x + y * y)
    return x / rr, y / rr


@njit(cache=True, error_model="numpy")
def collide_mirror(vx1, vy1, vx2, vy2, nx, ny):
    """The paper's rule: each disk reflects off the other as off a fixed wall.

    ``v_i' = v_i - 2 (v_i.n) n`` with the same ``n = d/|d|`` for both disks. Speeds are
    kept, momentum is not, and applying the map twice is the identity.
    """
    ax, ay = reflect(vx1, vy1, nx, ny)
    bx, by = reflect(vx2, vy2, nx, ny)
    return ax, ay, bx, by


@njit(cache=True, error_model="numpy")
def collide_elastic(vx1, vy1, vx2, vy2, nx, ny):
    """Equal-mass elastic collision: exchange the normal components of the velocities.

    ``v1' = v1 - (w.n) n``, ``v2' = v2 + (w.n) n`` with ``w = v1 - v2``; conserves
    kinetic energy and momentum.
    """
    p = (vx1 - vx2) * nx + (vy1 - vy2) * ny
    return vx1 - p * nx, vy1 - p * ny, vx2 + p * nx, vy2 + p * ny


@njit(cache=True, error_model="numpy")
def sin_theta_at(x, y, vx, vy, rho):
    """Tangential component of the unit incoming velocity at a boundary contact.

    ``sin_theta = (x vy - y vx) / (rho |v|)`` = ``L / rho`` for unit speed: the
    component along the counter-clockwise tangent ``(-sin s, cos s)``.
    """
    return (x * vy - y * vx) / (rho * math.sqrt(vx * vx + vy * vy))
