"""Billiard tables beyond the circle: the values `Circle`, `Stadium`, `Ellipse`, and the free
one-disk billiard in any of them with its maximal Lyapunov exponent (docs/tables.md).

A disk of radius ``r`` keeps its centre inside the table's inner parallel curve at distance
``r``; its wall contacts are the contacts of the centre with that curve:

* ``Circle()``: the unit circle; the centre's curve is the circle of radius ``1 - r``;
* ``Stadium(a)``: two semicircles of radius 1 centred at ``(+-a, 0)`` joined by segments
  of length ``2 a``; the centre's curve is again a stadium, of semicircles of radius
  ``1 - r`` and the same segments;
* ``Ellipse(a, b)``: ``(x / a)^2 + (y / b)^2 = 1`` with ``a >= b``; the centre's curve
  ``P(t) - r N(t)`` is not a conic, and it is smooth only for ``r < b^2 / a`` (the smallest
  radius of curvature of the ellipse).

The simulators (`kicktimes.simulate_one_particle`, ...) still know the circle only; these
values and `free_run`, `table_lyapunov` are the foundation they will be given.

Examples
--------
>>> from kicktimes.tables import Ellipse, Stadium, free_run, uniform_state
>>> Stadium(1.0)
Stadium(a=1.0)
>>> Ellipse(1.5, 1.0).max_radius
0.6666666666666666
>>> run = free_run(Stadium(1.0), uniform_state(Stadium(1.0), 0.01, rng=1), 0.01,
...                n_bounces=1000, rng=1)
>>> run.n_bounces, bool(abs(run.speed_drift) < 1e-12), bool(run.lyapunov > 0)
(1000, True, True)
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from kicktimes._results import Result
from kicktimes.billiard.kernels import covariogram as _cov
from kicktimes.billiard.kernels import drive_tables as _drive
from kicktimes.billiard.kernels import tables as _k
from kicktimes.validation import check_int, check_real, check_rng

__all__ = ["TABLE_KINDS", "Circle", "Ellipse", "Stadium", "TableLyapunov", "TableRun",
           "check_table", "free_run", "parse_table", "table_lyapunov", "table_spec",
           "uniform_state"]

#: the covariogram's quadrature per table kind: (Gauss-Legendre nodes per piece, grading
#: levels in the offset, in the direction) (`kicktimes.billiard.kernels.covariogram`)
_COVARIOGRAM_RULE = {_k.CIRCLE: (24, 0, 0), _k.STADIUM: (16, 8, 8), _k.ELLIPSE: (32, 0, 4)}



class _Table(Result, abc.ABC):
    """What every table has: the admissible disk radii, the kernel's parameters, the
    centre's region (area, perimeter, membership) and its wall times."""

    _kind: ClassVar[int] = -1

    @property
    def max_radius(self) -> float:
        """The disk radii ``r`` the table admits: ``0 < r < max_radius``."""
        return 1.0

    def check_radius(self, r) -> float:
        """``r`` as a float, or ValueError naming ``r`` and its range for this table."""
        return check_real("r", r, low=0.0, high=self.max_radius)

    @abc.abstractmethod
    def kernel(self, r) -> tuple[int, float, float, float]:
        """``(kind, p0, p1, p2)`` of `kicktimes.billiard.kernels.tables` for radius ``r``."""

    @abc.abstractmethod
    def area(self, r) -> float:
        """Area of the region the centre of a disk of radius ``r`` keeps to (``r = 0``:
        the table's)."""

    def _size_radius(self, r) -> float:
        """``r`` in ``[0, max_radius)``: a disk's radius, or 0 for the table itself."""
        return check_real("r", r, low=0.0, high=self.max_radius, low_open=False)

    @abc.abstractmethod
    def perimeter(self, r) -> float:
        """Length of the centre's curve for a disk of radius ``r``."""

    def mean_free_time(self, r) -> float:
        """Mean time between wall contacts at unit speed, ``pi area / perimeter`` (the
        billiard's invariant measure; Santalo's formula)."""
        return math.pi * self.area(r) / self.perimeter(r)

    @abc.abstractmethod
    def contains(self, positions, r) -> np.ndarray:
        """Whether each centre of ``positions`` (``(..., 2)``) keeps a disk of radius ``r``
        inside the table (on the centre's curve counts as inside, to ``1e-12``)."""

    def wall_time(self, positions, velocities, r) -> np.ndarray:
        """Time until each centre ``positions[i]`` (``(n, 2)``) moving with
        ``velocities[i]`` reaches the wall (the kernel's `tables.wall_time`)."""
        kind, p0, p1, p2 = self.kernel(r)
        q = np.asarray(positions, dtype=float).reshape(-1, 2)
        v = np.asarray(velocities, dtype=float).reshape(-1, 2)
        if q.shape != v.shape:
            raise ValueError(f"positions and velocities must have the same shape, got "
                             f"{q.shape} and {v.shape}")
        return np.array([_k.wall_time(kind, p0, p1, p2, *qi, *vi)
                         for qi, vi in zip(q, v, strict=True)])

    # --- the centre region's covariogram (the two-disk kinetic rate, docs/tables.md) ------

    @property
    def is_unit_circle(self) -> bool:
        """Whether this is the unit circle, whose two-disk rate has a closed form
        (`kicktimes.stats.kinetic_rate` reads it)."""
        return self._kind == _k.CIRCLE

    def covariogram(self, d, r) -> np.ndarray:
        r"""The isotropic set covariogram of the centre region ``D_r``: the area of
        :math:`D_r \cap (D_r + d\,e(\phi))`, averaged over the direction :math:`\phi`.

        .. math::  g(d) = \frac{1}{\pi} \int_0^\pi \int (\ell_\phi(u) - d)^+\, du\,
                   d\phi ,

        :math:`\ell_\phi(u)` the length of the chord of ``D_r`` along :math:`e(\phi)` at the
        offset ``u`` (``D_r`` is convex: a chord and its translate by ``d`` overlap on
        :math:`(\ell - d)^+`). Gauss-Legendre in the offset (written ``u = H sin theta``,
        ``H`` the support, so the chord is analytic up to the tangent line) and in
        :math:`\phi`, on pieces split where the integrand is not analytic (the stadium's
        joins, the direction beyond which :math:`K = 0`), graded towards their ends for the
        stadium (`kicktimes.billiard.kernels.covariogram`): about 1e-13 relative (1e-11
        near ``max_radius`` of a flat ellipse). ``g(0)`` is the area, ``g(d) = 0`` beyond
        the diameter; for the circle :math:`g(d) = L(d)`, the lens area of two disks of
        radius ``1 - r``.

        Parameters
        ----------
        d : float or array_like
            Distances, ``d >= 0``.
        r : float
            The disk radius (``D_r`` the region its centre keeps to).

        Returns
        -------
        float or ndarray
            ``g(d)``, the shape of ``d``.

        Examples
        --------
        >>> float(round(Circle().covariogram(0.0, 0.1) / (math.pi * 0.81), 12))
        1.0
        >>> float(round(Stadium(1.0).covariogram(3.0, 0.02), 4))
        0.2779
        """
        r = self.check_radius(r)
        dd = np.asarray(d, dtype=float)
        if not np.isfinite(dd).all() or (dd < 0).any():
            raise ValueError(f"d must be finite distances d >= 0, got {d!r}")
        kind, p0, p1, p2 = self.kernel(r)
        n, lt, lp = _COVARIOGRAM_RULE[kind]
        x, w = np.polynomial.legendre.leggauss(n)
        g = _cov.covariogram(kind, p0, p1, p2, dd.reshape(-1), x, w, lt, lp)
        return float(g[0]) if dd.ndim == 0 else g.reshape(dd.shape)

    def configuration_volume(self, r) -> float:
        r"""Volume of the configuration space of two disks of radius ``r`` (centres in
        ``D_r``, at least ``sigma = 2 r`` apart):

        .. math::  |Q| = |D_r|^2 - \int_0^\sigma 2\pi d\, g(d)\, dd

        (`covariogram` ``g``; 24-point Gauss-Legendre in ``d``, ``g`` smooth on
        ``[0, sigma]``).

        Examples
        --------
        >>> q = Stadium(1.0).configuration_volume(0.01)
        >>> a = Stadium(1.0).area(0.01)
        >>> bool(0.99 * a * a < q < a * a)
        True
        """
        r = self.check_radius(r)
        x, w = np.polynomial.legendre.leggauss(24)
        dist = r * (1.0 + x)  # [-1, 1] onto [0, 2 r]
        excluded = r * float((w * 2.0 * math.pi * dist * self.covariogram(dist, r)).sum())
        return self.area(r) ** 2 - excluded


@dataclass(frozen=True, repr=False)
class Circle(_Table):
    """The unit circular table (the simulators' table): the centre keeps to
    ``|q| <= 1 - r``.

    Examples
    --------
    >>> Circle().kernel(0.1)
    (0, 0.9, 0.0, 0.0)
    """

    _title: ClassVar[str] = "Circle (radius 1)"
    _kind: ClassVar[int] = _k.CIRCLE

    def kernel(self, r):
        r = self.check_radius(r)
        return self._kind, 1.0 - r, 0.0, 0.0

    def area(self, r):
        return math.pi * (1.0 - self._size_radius(r)) ** 2

    def perimeter(self, r):
        return 2.0 * math.pi * (1.0 - self._size_radius(r))

    def contains(self, positions, r):
        q = np.asarray(positions, dtype=float)
        return np.hypot(q[..., 0], q[..., 1]) <= (1.0 - r) * (1 + 1e-12)

    def bounding_box(self):
        """``(X, Y)``: the table lies in ``[-X, X] x [-Y, Y]`` (the N-disk engine's cells)."""
        return 1.0, 1.0

    def inradius(self, r):
        """Radius of the largest disk about the centre inside the centre's region."""
        return 1.0 - self._size_radius(r)

    def wall_distance(self, positions):
        """Distance of each point of ``positions`` (``(..., 2)``, inside) to the wall."""
        q = np.asarray(positions, dtype=float)
        return 1.0 - np.hypot(q[..., 0], q[..., 1])


@dataclass(frozen=True, repr=False)
class Stadium(_Table):
    """Bunimovich's stadium: semicircles of radius 1 centred at ``(+-a, 0)`` joined by the
    segments ``y = +-1``, ``|x| <= a`` (length ``2 a``).

    The centre of a disk of radius ``r`` keeps to the stadium of semicircles of radius
    ``rho = 1 - r`` with the same segments: the points within ``rho`` of the segment
    ``[-a, a] x {0}``.

    Parameters
    ----------
    a : float
        Half the length of the straight segments, ``a > 0`` (``a = 0`` is the `Circle`).

    Examples
    --------
    >>> Stadium(1.0).area(0.0), Stadium(1.0).perimeter(0.0)
    (7.141592653589793, 10.283185307179586)
    """

    _title: ClassVar[str] = "Stadium (semicircles of radius 1, segments of length 2a)"
    _kind: ClassVar[int] = _k.STADIUM
    a: float

    def __post_init__(self):
        object.__setattr__(self, "a", check_real("a", self.a, low=0.0))

    def kernel(self, r):
        r = self.check_radius(r)
        return self._kind, self.a, 1.0 - r, 0.0

    def area(self, r):
        rho = 1.0 - self._size_radius(r)
        return math.pi * rho * rho + 4.0 * self.a * rho

    def perimeter(self, r):
        return 2.0 * math.pi * (1.0 - self._size_radius(r)) + 4.0 * self.a

    def contains(self, positions, r):
        q = np.asarray(positions, dtype=float)
        dx = np.maximum(np.abs(q[..., 0]) - self.a, 0.0)
        return np.hypot(dx, q[..., 1]) <= (1.0 - r) * (1 + 1e-12)

    def bounding_box(self):
        """``(X, Y) = (a + 1, 1)``: the table lies in ``[-X, X] x [-Y, Y]``."""
        return self.a + 1.0, 1.0

    def inradius(self, r):
        """Radius of the largest disk about the centre inside the centre's region, ``1 - r``."""
        return 1.0 - self._size_radius(r)

    def wall_distance(self, positions):
        """Distance of each point of ``positions`` (``(..., 2)``, inside) to the wall: ``1``
        less its distance to the segment ``[-a, a] x {0}``."""
        q = np.asarray(positions, dtype=float)
        return 1.0 - np.hypot(np.maximum(np.abs(q[..., 0]) - self.a, 0.0), q[..., 1])


@dataclass(frozen=True, repr=False)
class Ellipse(_Table):
    """The elliptic table ``(x / a)^2 + (y / b)^2 <= 1``, ``a >= b > 0``.

    The centre of a disk of radius ``r`` keeps to the inner parallel curve
    ``C(t) = P(t) - r N(t)``, ``P(t) = (a cos t, b sin t)``, ``N`` the outward unit normal:
    ``C(t) = ((a - r b / h) cos t, (b - r a / h) sin t)``,
    ``h = sqrt(b^2 cos^2 t + a^2 sin^2 t)``. Its curvature is ``kappa / (1 - r kappa)``
    with the ellipse's ``kappa = a b / h^3``, largest (``a / b^2``) at the ends of the
    major axis: the curve is smooth only for ``r < b^2 / a`` (`max_radius`), and larger
    disks are refused.

    Parameters
    ----------
    a, b : float
        The semi-axes, ``a >= b > 0`` (``a = b = 1`` is the `Circle`).

    Examples
    --------
    >>> Ellipse(2.0, 1.0).check_radius(0.6)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: r must lie in (0.0, 0.5) for Ellipse(a=2.0, b=1.0) (r < b^2/a, where the ...
    """

    _title: ClassVar[str] = "Ellipse (semi-axes a >= b)"
    _kind: ClassVar[int] = _k.ELLIPSE
    a: float
    b: float

    def __post_init__(self):
        a = check_real("a", self.a, low=0.0)
        b = check_real("b", self.b, low=0.0)
        if b > a:
            raise ValueError(f"b must lie in (0.0, a] = (0.0, {a!r}] (the major semi-axis is "
                             f"a), got {b!r}")
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    @property
    def max_radius(self):
        return self.b * self.b / self.a

    def check_radius(self, r):
        try:
            return check_real("r", r, low=0.0, high=self.max_radius)
        except ValueError:
            x = float(r)
            raise ValueError(
                f"r must lie in (0.0, {self.max_radius!r}) for {self!r} (r < b^2/a, where the "
                f"centre's curve would lose its smoothness: the smallest radius of curvature "
                f"of the ellipse), got {x!r}") from None

    def kernel(self, r):
        r = self.check_radius(r)
        return self._kind, self.a, self.b, r

    def _ellipse_perimeter(self):
        return 4.0 * self.a * _k._elliptic_e(0.5 * math.pi, 1.0 - (self.b / self.a) ** 2)

    def area(self, r):
        # Steiner's formula for the inner parallel body (valid for r below b^2/a)
        r = self._size_radius(r)
        return math.pi * self.a * self.b - self._ellipse_perimeter() * r + math.pi * r * r

    def perimeter(self, r):
        return self._ellipse_perimeter() - 2.0 * math.pi * self._size_radius(r)

    def contains(self, positions, r):
        kind, p0, p1, p2 = self.kernel(r)
        q = np.asarray(positions, dtype=float)
        flat = q.reshape(-1, 2)
        out = np.empty(len(flat), dtype=bool)
        for i, (x, y) in enumerate(flat):
            c, s = _k.ellipse_parameter(x, y, p0, p1, p2)
            h = math.sqrt(p1 * p1 * c * c + p0 * p0 * s * s)
            cx = (p0 - p2 * p1 / h) * c
            cy = (p1 - p2 * p0 / h) * s
            # inside: the foot point's outward normal sees q behind it
            out[i] = (x - cx) * p1 * c / h + (y - cy) * p0 * s / h <= 1e-12
        return out.reshape(q.shape[:-1])

    def bounding_box(self):
        """``(X, Y) = (a, b)``: the table lies in ``[-X, X] x [-Y, Y]``."""
        return self.a, self.b

    def inradius(self, r):
        """Radius of the largest disk about the centre inside the centre's region, ``b - r``
        (the point ``(0, b - r)`` is at distance ``r`` from the vertex ``(0, b)``)."""
        return self.b - self._size_radius(r)

    def wall_distance(self, positions):
        """Distance of each point of ``positions`` (``(..., 2)``, inside) to the wall: the
        nearest of 256 points of the ellipse, refined by Newton's iteration on
        ``(q - P(t)).P'(t) = 0`` from there (a point deep inside has several stationary
        points; the nearest sample picks the global minimum's), never above the sample's."""
        q = np.asarray(positions, dtype=float)
        flat = q.reshape(-1, 2)
        a, b = self.a, self.b
        grid = np.linspace(0.0, 2.0 * math.pi, 256, endpoint=False)
        t = np.empty(len(flat))
        best = np.empty(len(flat))
        for lo in range(0, len(flat), 4096):
            x, y = flat[lo:lo + 4096, :1], flat[lo:lo + 4096, 1:]
            d2 = (a * np.cos(grid) - x) ** 2 + (b * np.sin(grid) - y) ** 2
            k = np.argmin(d2, axis=1)
            t[lo:lo + 4096] = grid[k]
            best[lo:lo + 4096] = np.sqrt(d2[np.arange(len(k)), k])
        x, y = flat[:, 0], flat[:, 1]
        for _ in range(8):
            c, s = np.cos(t), np.sin(t)
            ex, ey = x - a * c, y - b * s
            f = -ex * a * s + ey * b * c
            df = -(a * s) ** 2 - (b * c) ** 2 - ex * a * c - ey * b * s
            t = t - f / np.where(df < 0.0, df, -1.0)
        d = np.hypot(x - a * np.cos(t), y - b * np.sin(t))
        return np.minimum(d, best).reshape(q.shape[:-1])


def check_table(table, *, name: str = "table"):
    """The table a simulator runs in: ``None`` is the unit circle, `Circle()`; a `Circle`,
    `Stadium` or `Ellipse` is itself; anything else is a TypeError naming ``name``.

    Every function that takes ``table=`` reads it through this check, so the circle's
    default path is one test away: ``check_table(table) == Circle()``.

    Examples
    --------
    >>> check_table(None)
    Circle()
    >>> check_table(Stadium(1.0)) == Stadium(1.0)
    True
    """
    if table is None:
        return Circle()
    if not isinstance(table, _Table):
        raise TypeError(f"{name} must be None or a kicktimes.tables Circle, Stadium or "
                        f"Ellipse, got {type(table).__name__}")
    return table


def _check_state(table, state, r):
    s = np.array(state, dtype=float).reshape(-1)
    if s.shape != (4,) or not np.isfinite(s).all():
        raise ValueError(f"state must be 4 finite numbers (x, y, vx, vy), got {state!r}")
    if s[2] == 0.0 and s[3] == 0.0:
        raise ValueError("state: the disk must move (vx, vy) != (0, 0)")
    if not table.contains(s[:2], r):
        raise ValueError(f"state: the centre ({s[0]!r}, {s[1]!r}) keeps no disk of radius "
                         f"{r!r} inside {table!r}")
    return s


def uniform_state(table, r, *, rng=None) -> np.ndarray:
    """A disk state ``(x, y, vx, vy)``: the centre uniform in its region, unit speed in a
    uniform direction (the billiard's invariant measure).

    Examples
    --------
    >>> s = uniform_state(Ellipse(1.5, 1.0), 0.05, rng=1)
    >>> bool(Ellipse(1.5, 1.0).contains(s[:2], 0.05)), float(round(s[2]**2 + s[3]**2, 12))
    (True, 1.0)
    """
    table = check_table(table)
    r = table.check_radius(r)
    gen = check_rng(rng)
    box = (1.0 + getattr(table, "a", 0.0) if isinstance(table, Stadium)
           else getattr(table, "a", 1.0))
    while True:
        q = gen.uniform(-box, box, size=2)
        if table.contains(q, r):
            break
    phi = gen.uniform(0.0, 2.0 * math.pi)
    return np.array([q[0], q[1], math.cos(phi), math.sin(phi)])


def _unit_tangent_vector(state, gen):
    """A random tangent vector ``(dq, dv)`` off the flow: ``dq, dv`` perpendicular to ``v``
    (no shift along the orbit, no change of speed), norm 1."""
    v = state[2:] / math.hypot(*state[2:])
    perp = np.array([-v[1], v[0]])
    a, b = gen.normal(size=2)
    u = np.concatenate([a * perp, b * perp])
    return u / np.linalg.norm(u)


@dataclass(frozen=True, repr=False)
class TableRun(Result):
    """A free run of one disk in a table (`free_run`).

    ``times``, ``positions`` (``(n, 2)``), ``velocities`` (outgoing): the recorded wall
    contacts; ``state`` the final ``(x, y, vx, vy)`` at ``t_end``; ``lyapunov`` the maximal
    Lyapunov exponent per unit time from the tangent map (NaN if not computed),
    ``lyapunov_per_bounce`` the same per wall contact; ``speed_drift`` the final speed's
    relative change.
    """

    _title: ClassVar[str] = "Free run of one disk in a table"
    _summary_fields: ClassVar[tuple] = ("table", "r", "n_bounces", "t_end", "lyapunov",
                                        "lyapunov_per_bounce", "speed_drift", "times")
    table: object
    r: float
    n_bounces: int
    t_end: float
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    state: np.ndarray
    lyapunov: float
    lyapunov_per_bounce: float
    speed_drift: float
    reason: str | None = None

    def boundary_coordinates(self) -> np.ndarray:
        """``(n, 2)`` Birkhoff coordinates ``(s, sin_theta)`` of the recorded contacts
        (`kicktimes.billiard.kernels.tables.boundary_coordinates`)."""
        kind, p0, p1, p2 = self.table.kernel(self.r)
        pairs = zip(self.positions, self.velocities, strict=True)
        return np.array([_k.boundary_coordinates(kind, p0, p1, p2, *q, *v)
                         for q, v in pairs]).reshape(-1, 2)


_STATUS = {2: "more than 1000 wall contacts at one instant",
           3: "a non-finite wall time"}


def free_run(table, state, r, *, n_bounces=None, t_max=None, n_record=None, tangent=True,
             rng=None) -> TableRun:
    """Run one disk freely (no kicks) in ``table``, with its tangent vector.

    The disk flies straight between specular reflections at the wall of its centre's
    curve (`kicktimes.billiard.kernels.tables`). The tangent vector ``(dq, dv)`` flies as
    ``dq += dv t`` and crosses each reflection by the exact linearised map at a wall of
    local curvature ``kappa`` (`kicktimes.billiard.kernels.tangent.curved_wall_tangent`):
    ``lyapunov = log(|u(T)| / |u(0)|) / T``.

    Parameters
    ----------
    table : Circle, Stadium or Ellipse
    state : array_like
        ``(x, y, vx, vy)``: the centre (inside its region) and the velocity (any speed).
    r : float
        The disk's radius, ``0 < r < table.max_radius``.
    n_bounces : int, optional
        Stop after this many wall contacts.
    t_max : float, optional
        Stop at this time (at least one of ``n_bounces``, ``t_max`` is required).
    n_record : int, optional
        Record the first ``n_record`` contacts (default: all, if ``n_bounces`` is given
        and at most 10^6; else none).
    tangent : bool
        Carry the tangent vector (``lyapunov`` is NaN without it).
    rng : None, int or numpy.random.Generator
        The random start of the tangent vector (off the flow: ``dq, dv`` perpendicular to
        ``v``).

    Returns
    -------
    TableRun

    Examples
    --------
    >>> run = free_run(Circle(), [0.1, 0.2, 0.6, 0.8], 0.05, n_bounces=3)
    >>> run.times.round(6)
    array([0.729158, 2.627473, 4.525788])
    """
    table = check_table(table)
    r = table.check_radius(r)
    s = _check_state(table, state, r)
    if n_bounces is None and t_max is None:
        raise ValueError("give n_bounces or t_max (or both)")
    n_max = (np.iinfo(np.int64).max if n_bounces is None
             else check_int("n_bounces", n_bounces, low=1))
    tm = math.inf if t_max is None else check_real("t_max", t_max, low=0.0)
    if n_record is None:
        n_record = n_max if n_bounces is not None and n_max <= 10**6 else 0
    n_record = check_int("n_record", n_record, low=0, high=10**8)
    gen = check_rng(rng)
    kind, p0, p1, p2 = table.kernel(r)
    rec = np.empty((min(n_record, n_max), 5))
    u = _unit_tangent_vector(s, gen)
    speed0 = math.hypot(s[2], s[3])
    n, t_end, log_scale, status = _drive.free_kernel(kind, p0, p1, p2, s, n_max, tm, rec, u,
                                                     bool(tangent))
    rec = rec[:min(n, len(rec))]
    lyap = math.nan
    per = math.nan
    reason = _STATUS.get(status)
    if tangent and reason is None:
        grow = log_scale + math.log(np.linalg.norm(u))
        lyap = grow / t_end if t_end > 0 else math.nan
        per = grow / n if n > 0 else math.nan
        if not math.isfinite(lyap):
            reason = "the tangent map is singular at an exactly tangent contact"
    elif not tangent:
        reason = "tangent=False: no exponent"
    return TableRun(table=table, r=r, n_bounces=int(n), t_end=float(t_end),
                    times=rec[:, 0].copy(), positions=rec[:, 1:3].copy(),
                    velocities=rec[:, 3:5].copy(), state=s, lyapunov=float(lyap),
                    lyapunov_per_bounce=float(per),
                    speed_drift=float(math.hypot(s[2], s[3]) / speed0 - 1.0), reason=reason)


@dataclass(frozen=True, repr=False)
class TableLyapunov(Result):
    """The maximal Lyapunov exponent of the free disk in a table (`table_lyapunov`):
    ``exponent`` per unit time, ``per_bounce`` per wall contact, over ``n_bounces``
    contacts and the time ``t_end``, by ``method`` ("tangent" or "twin"; ``n_forced``:
    twin renormalisations forced across a contact)."""

    _title: ClassVar[str] = "Maximal Lyapunov exponent of a free disk in a table"
    table: object
    r: float
    method: str
    exponent: float
    per_bounce: float
    n_bounces: int
    t_end: float
    n_forced: int
    reason: str | None = None


def table_lyapunov(table, state, r, *, n_bounces, method="tangent", d0=1e-9, every=4,
                   rng=None) -> TableLyapunov:
    """The maximal Lyapunov exponent of one free disk in ``table``.

    ``method="tangent"``: the exact tangent map (`free_run`). ``method="twin"``: Benettin's
    renormalised twin (Benettin, Galgani & Strelcyn, Phys. Rev. A 14, 2338 (1976)), a
    second disk ``d0`` away in phase space, run by the same kernels, its distance measured
    and put back to ``d0`` every ``every`` contacts, mid-flight
    (`kicktimes.billiard.kernels.drive_tables.twin_kernel`): ``sum log(d / d0) / T``. The
    two estimate the same number; the twin checks the tangent map.

    Parameters
    ----------
    table : Circle, Stadium or Ellipse
    state : array_like
        ``(x, y, vx, vy)`` of the disk.
    r : float
        The disk's radius.
    n_bounces : int
        Wall contacts of the reference disk.
    method : {"tangent", "twin"}
    d0 : float
        The twin's distance (``1e-14 < d0 < 1e-3``).
    every : int
        Contacts between the twin's renormalisations.
    rng : None, int or numpy.random.Generator
        The direction of the first tangent vector or of the twin's offset.

    Returns
    -------
    TableLyapunov

    Examples
    --------
    >>> st = uniform_state(Stadium(1.0), 1e-9, rng=2)
    >>> lt = table_lyapunov(Stadium(1.0), st, 1e-9, n_bounces=20000, rng=2)
    >>> lw = table_lyapunov(Stadium(1.0), st, 1e-9, n_bounces=20000, method="twin", rng=2)
    >>> bool(abs(lt.exponent - lw.exponent) < 0.1 * lt.exponent)
    True
    """
    table = check_table(table)
    r = table.check_radius(r)
    s = _check_state(table, state, r)
    n = check_int("n_bounces", n_bounces, low=1)
    if method not in ("tangent", "twin"):
        raise ValueError(f"method must be one of ['tangent', 'twin'], got {method!r}")
    d0 = check_real("d0", d0, low=1e-14, high=1e-3)
    every = check_int("every", every, low=1)
    gen = check_rng(rng)
    if method == "tangent":
        run = free_run(table, s, r, n_bounces=n, n_record=0, rng=gen)
        return TableLyapunov(table=table, r=r, method=method, exponent=run.lyapunov,
                             per_bounce=run.lyapunov_per_bounce, n_bounces=run.n_bounces,
                             t_end=run.t_end, n_forced=0, reason=run.reason)
    kind, p0, p1, p2 = table.kernel(r)
    ref = _drive.twin_state(kind, p0, p1, p2, *s)
    off = _unit_tangent_vector(s, gen) * d0
    t = s + off
    if not table.contains(t[:2], r):
        t = s - off
    twin = _drive.twin_state(kind, p0, p1, p2, *t)
    log_sum, t_last, n_last, n_forced, status = _drive.twin_kernel(
        kind, p0, p1, p2, ref, twin, n, d0, every, 10)
    reason = _STATUS.get(status)
    exponent = log_sum / t_last if t_last > 0 else math.nan
    if reason is None and not math.isfinite(exponent):
        reason = "no renormalisation: too few contacts for the twin"
    per = log_sum / n_last if n_last > 0 else math.nan
    return TableLyapunov(table=table, r=r, method=method, exponent=float(exponent),
                         per_bounce=float(per), n_bounces=int(ref[8]), t_end=float(t_last),
                         n_forced=int(n_forced), reason=reason)


# --- tables as text (TOML presets, stores, the command line) -----------------------------

#: the table names of `table_spec` and `parse_table`, with their parameters
TABLE_KINDS = {"circle": (), "stadium": ("a",), "ellipse": ("a", "b")}


def table_spec(table) -> str:
    """A table as one line of text: ``"circle"``, ``"stadium a=1"``, ``"ellipse a=1.5 b=1"``
    (each parameter by ``repr``, so `parse_table` gives the same value back).

    Examples
    --------
    >>> table_spec(None), table_spec(Stadium(1.0)), table_spec(Ellipse(1.5, 1.0))
    ('circle', 'stadium a=1.0', 'ellipse a=1.5 b=1.0')
    """
    table = check_table(table)
    kind = {Circle: "circle", Stadium: "stadium", Ellipse: "ellipse"}[type(table)]
    return " ".join([kind] + [f"{p}={getattr(table, p)!r}" for p in TABLE_KINDS[kind]])


def parse_table(spec, *, name: str = "table"):
    """The table written by `table_spec`: a name of `TABLE_KINDS` followed by its parameters
    as ``key=value`` words (``"stadium a=1"``); a ValueError naming ``name`` otherwise.

    Examples
    --------
    >>> parse_table("ellipse a=1.5 b=1")
    Ellipse(a=1.5, b=1.0)
    >>> parse_table("circle") == Circle()
    True
    """
    if not isinstance(spec, str):
        raise TypeError(f"{name}: expected a table as text such as 'stadium a=1', got "
                        f"{type(spec).__name__}")
    words = spec.split()
    def form(kind):
        return " ".join([kind] + [f"{p}=..." for p in TABLE_KINDS[kind]])

    kinds = ", ".join(f"'{form(k)}'" for k in TABLE_KINDS)
    if not words or words[0] not in TABLE_KINDS:
        raise ValueError(f"{name}: expected one of {kinds}, got {spec!r}")
    kind, params = words[0], {}
    for word in words[1:]:
        key, eq, value = word.partition("=")
        if not eq or key not in TABLE_KINDS[kind] or key in params:
            raise ValueError(f"{name}: expected '{form(kind)}', got {spec!r}")
        try:
            params[key] = float(value)
        except ValueError:
            raise ValueError(f"{name}: {key} must be a number, got {value!r} in "
                             f"{spec!r}") from None
    missing = [p for p in TABLE_KINDS[kind] if p not in params]
    if missing:
        raise ValueError(f"{name}: expected '{form(kind)}', got {spec!r}")
    try:
        return {"circle": Circle, "stadium": Stadium, "ellipse": Ellipse}[kind](**params)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None
