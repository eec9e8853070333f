"""Initial-condition ensembles for the two-disk billiard (in the unit circle, or in another
table of `kicktimes.tables`).

IC ``i`` of an ensemble is drawn from its own generator,
``numpy.random.default_rng(SeedSequence(seed, spawn_key=(i,)))`` (the ``i``-th child of
``SeedSequence(seed)``), so it does not depend on how the ensemble is split into blocks
or across workers: ``initial_conditions(10, r, rng=s)[7]`` equals
``initial_conditions(3, r, rng=s, start=7)[0]``.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from kicktimes.billiard import checks as chk
from kicktimes.billiard._crmath import cos_sin
from kicktimes.billiard.tables import Circle, Ellipse, Stadium, check_table
from kicktimes.validation import check_seed_sequence, renamed_keyword

METHODS = ("paper", "uniform")


def ic_generator(seed: int, index: int) -> np.random.Generator:
    """The generator of IC ``index`` of the ensemble with root ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(index,)))


#: Rejection draws per disk (or pair) before the exact conditional sampler takes over.
#: At the paper's radii (r_max <= 0.1) a draw is accepted with probability >= 0.7, so the
#: cap is never reached and the ensembles are bit-for-bit those of the plain rejection.
N_TRY = 1000
#: Centres closer than this to the edge of feasibility (where the space left to the other
#: disk has zero area) are treated as infeasible: the conditional sampler needs some room.
FEASIBLE_MARGIN = 1e-9
_GRID = 4097
#: The largest r_max: 1 - r - (3 r - 1) = 2 - 4 r, the room a first centre has, must
#: exceed FEASIBLE_MARGIN comfortably.
R_MAX_IC = 0.5 - 1e-9


def _allowed_fraction(d, a, s):
    """Fraction of the circle ``|p| = d`` at distance ``>= s`` from a centre at distance ``a``.

    ``|p - c|^2 = d^2 + a^2 - 2 d a cos(phi)`` is ``>= s^2`` iff ``cos(phi) <= q`` with
    ``q = (d^2 + a^2 - s^2) / (2 d a)``: the fraction is ``1 - arccos(q) / pi``.
    """
    d = np.asarray(d, dtype=float)
    if a == 0.0:
        return (d >= s).astype(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = (d * d + a * a - s * s) / (2.0 * d * a)
    q = np.where(d > 0.0, q, -np.inf if a < s else np.inf)
    return 1.0 - np.arccos(np.clip(q, -1.0, 1.0)) / np.pi


def _inverse_cdf(rng, grid, weight):
    """One draw from the density proportional to ``weight`` (piecewise linear on ``grid``)."""
    cdf = np.concatenate(([0.0], np.cumsum(0.5 * (weight[1:] + weight[:-1]) * np.diff(grid))))
    return float(np.interp(rng.uniform(0.0, cdf[-1]), cdf, grid))


def _point_away_from(rng, c, s, rho, *, area):
    """A centre ``p`` with ``|p| <= rho`` and ``|p - c| >= s``, from the conditional law.

    The law is the rejection sampler's, conditioned on acceptance, drawn directly: the
    distance ``d`` from the table centre has density proportional to ``g(d)`` (the paper's
    distance uniform on (0, 1)) or ``d g(d)`` (area-uniform), ``g`` the allowed fraction
    of the circle of radius ``d``; the polar angle is uniform on the allowed arcs.
    """
    a = math.hypot(c[0], c[1])
    phi0 = math.atan2(c[1], c[0])
    d_lo = max(0.0, s - a)
    grid = np.linspace(d_lo, rho, _GRID)
    weight = _allowed_fraction(grid, a, s) * (grid if area else 1.0)
    for _ in range(100):
        d = min(_inverse_cdf(rng, grid, weight), rho)
        # arcs allowed at distance d: |phi - phi0| >= alpha
        alpha = float(np.pi * (1.0 - _allowed_fraction(d, a, s)))
        side = 1.0 if rng.uniform() < 0.5 else -1.0
        phi = phi0 + side * (alpha + rng.uniform() * (np.pi - alpha))
        c_phi, s_phi = cos_sin(phi)
        x, y = d * c_phi, d * s_phi
        if math.hypot(x, y) <= rho and math.hypot(x - c[0], y - c[1]) >= s:
            return x, y
    # round-off keeps missing a sliver: the farthest point is always allowed
    c_phi0, s_phi0 = cos_sin(phi0)
    return -rho * c_phi0, -rho * s_phi0


def _paper_ic(rng: np.random.Generator, r_max: float) -> np.ndarray:
    # The paper's procedure: distance from the centre uniform on (0, 1) (not area-uniform),
    # polar angle uniform; redraw a disk while it pokes out of the table or overlaps the
    # disk already placed, at the family's largest radius. For r_max > 1/3 the first disk
    # can leave no room for the second (|c0| <= 3 r_max - 1): it is then drawn again from
    # its law conditioned on leaving room, instead of redrawing the second disk forever.
    rho = 1.0 - r_max
    s = 2.0 * r_max
    a_min = 3.0 * r_max - 1.0 + FEASIBLE_MARGIN
    out = np.empty((2, 4))
    for i in range(2):
        for _ in range(N_TRY):
            dist = rng.uniform(0.0, 1.0)
            phi = rng.uniform(0.0, 2.0 * np.pi)
            c_phi, s_phi = cos_sin(phi)
            x, y = dist * c_phi, dist * s_phi
            if dist > rho:
                continue
            if i == 1 and math.hypot(x - out[0, 0], y - out[0, 1]) < s:
                continue
            break
        else:
            if i == 0:  # (1 - rho)^1000: unreachable in practice, but bounded
                dist = rng.uniform(0.0, rho)
                x, y = dist, 0.0
            else:
                x, y = _point_away_from(rng, out[0, :2], s, rho, area=False)
        if i == 0 and dist < a_min:
            dist = rng.uniform(a_min, rho)
            phi = rng.uniform(0.0, 2.0 * np.pi)
            c_phi, s_phi = cos_sin(phi)
            x, y = dist * c_phi, dist * s_phi
        angle = rng.uniform(0.0, 2.0 * np.pi)
        out[i] = (x, y, *cos_sin(angle))
    return out


@functools.lru_cache(maxsize=16)
def _first_centre_density(r_max):
    """Grid of distances ``a`` of the first centre and the density ``a A(a)`` on it."""
    rho = 1.0 - r_max
    s = 2.0 * r_max
    a_grid = np.linspace(max(0.0, 3.0 * r_max - 1.0 + FEASIBLE_MARGIN), rho, 513)
    d_grid = np.linspace(0.0, rho, 1025)
    area = np.array([np.trapezoid(d_grid * _allowed_fraction(d_grid, a, s), d_grid)
                     for a in a_grid])
    return a_grid, a_grid * area


def _uniform_pair(rng, r_max):
    """Two centres uniform on the non-overlapping configurations, by the exact marginals.

    The first centre's distance ``a`` from the table centre has density proportional to
    ``a A(a)``, ``A(a)`` the area left to the second centre; the second is then uniform on
    that area (`_point_away_from`).
    """
    rho = 1.0 - r_max
    s = 2.0 * r_max
    a_grid, weight = _first_centre_density(r_max)
    a = min(_inverse_cdf(rng, a_grid, weight), rho)
    phi = rng.uniform(0.0, 2.0 * np.pi)
    c_phi, s_phi = cos_sin(phi)
    c0 = (a * c_phi, a * s_phi)
    c1 = _point_away_from(rng, c0, s, rho, area=True)
    return np.array([c0[0], c1[0]]), np.array([c0[1], c1[1]])


def _uniform_ic(rng: np.random.Generator, r_max, rule: str, masses=None) -> np.ndarray:
    # The invariant (Liouville) measure: the *pair* of centres uniform on the
    # non-overlapping configurations, by joint rejection (redrawing only the second disk
    # would weight configurations by the free area left to it, which is not uniform).
    # Near r_max = 0.5 almost every pair overlaps: after N_TRY draws the pair is drawn
    # from the same law directly. Unequal disks (r_max = (r0, r1)): each centre in its own
    # disk of radius 1 - r_i, contact at r0 + r1 (rejection only: both radii < 1/3).
    if isinstance(r_max, tuple):
        rho = np.array([1.0 - r_max[0], 1.0 - r_max[1]])
        sigma = r_max[0] + r_max[1]
    else:
        rho = 1.0 - r_max
        sigma = 2.0 * r_max
    out = np.empty((2, 4))
    for _ in range(N_TRY):
        rad = rho * np.sqrt(rng.uniform(size=2))
        phi = rng.uniform(0.0, 2.0 * np.pi, size=2)
        (c0, s0), (c1, s1) = cos_sin(phi[0]), cos_sin(phi[1])
        x = rad * np.array([c0, c1])
        y = rad * np.array([s0, s1])
        if math.hypot(x[0] - x[1], y[0] - y[1]) >= sigma:
            break
    else:
        if isinstance(r_max, tuple):
            raise RuntimeError(f"r_max={r_max!r}: no non-overlapping pair in {N_TRY} draws")
        x, y = _uniform_pair(rng, r_max)
    out[:, 0] = x
    out[:, 1] = y
    _velocities(rng, out, rule, masses)
    return out


def _velocities(rng, out, rule, masses):
    """The velocities of the invariant measure of ``rule`` into ``out[:, 2:]``."""
    if rule == "mirror":
        angle = rng.uniform(0.0, 2.0 * np.pi, size=2)
        out[0, 2:] = cos_sin(angle[0])
        out[1, 2:] = cos_sin(angle[1])
    else:
        # (v1, v2) uniform on the sphere |v1|^2 + |v2|^2 = 2 in R^4
        # the norm by elementwise IEEE operations in a fixed order (np.linalg.norm calls
        # BLAS, whose kernels round differently on different CPUs)
        g = rng.standard_normal(4)
        g *= math.sqrt(2.0) / math.sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2] + g[3] * g[3])
        if masses is not None:
            # uniform on the ellipsoid m0 |v0|^2 + m1 |v1|^2 = 2, masses normalised to
            # (m0 + m1) / 2 = 1: v_i = u_i / sqrt(m_i), u uniform on the sphere
            total = masses[0] + masses[1]
            g[:2] /= math.sqrt(2.0 * masses[0] / total)
            g[2:] /= math.sqrt(2.0 * masses[1] / total)
        out[0, 2:] = g[:2]
        out[1, 2:] = g[2:]


def _half_widths(table, r):
    """Half the sides of the box ``[-X, X] x [-Y, Y]`` holding the centres' region."""
    if isinstance(table, Stadium):
        return table.a + 1.0 - r, 1.0 - r
    if isinstance(table, Ellipse):
        return table.a - r, table.b - r
    return 1.0 - r, 1.0 - r


def _table_ic(rng: np.random.Generator, r, rule: str, masses, table) -> np.ndarray:
    # The invariant measure in another table: the pair of centres uniform on the
    # non-overlapping configurations in the centre's region (joint rejection from the
    # region's bounding box, `table.contains`), the velocities as in the circle.
    hx, hy = _half_widths(table, r)
    out = np.empty((2, 4))
    scale = np.array([hx, hy, hx, hy])
    for _ in range(100 * N_TRY):
        q = rng.uniform(-1.0, 1.0, size=4) * scale
        if (math.hypot(q[0] - q[2], q[1] - q[3]) >= 2.0 * r
                and table.contains(q.reshape(2, 2), r).all()):
            break
    else:
        raise RuntimeError(f"r_max={r!r}: no non-overlapping pair in {table!r} in "
                           f"{100 * N_TRY} draws")
    out[:, :2] = q.reshape(2, 2)
    _velocities(rng, out, rule, masses)
    return out


@renamed_keyword(old="seed", new="rng", since="0.2.0")
def initial_conditions(n, r_max, *, rng=0, method="paper", rule="mirror", start=0,
                       masses=None, table=None) -> np.ndarray:
    """Draw an ensemble of two-disk initial conditions.

    Parameters
    ----------
    n : int
        Number of ICs (``>= 1``).
    r_max : float or (float, float)
        The largest disk radius the ensemble will be used with, ``0 < r_max <= 0.5 - 1e-9``.
        ICs are valid (inside the table, no overlap) for every ``r <= r_max``. A tuple
        ``(r0, r1)`` (with ``method="uniform"``, each at most 1/3): the invariant measure of
        two disks of those radii.
    rng : int, numpy.random.SeedSequence or numpy.random.Generator, default 0
        The root of the ensemble's streams (`kicktimes.validation.check_seed_sequence`):
        IC ``i`` is drawn from the root's child ``spawn_key=(i,)``, so the ensemble is a
        pure function of an int or SeedSequence root (a Generator is consumed: the root is
        drawn from it). ``seed=`` is its deprecated spelling (until 0.3.0).
    method : {"paper", "uniform"}
        ``"paper"``: per disk, distance from the centre uniform on (0, 1), polar angle
        and velocity angle uniform on [0, 2 pi), redrawn while it overlaps the boundary or
        the other disk at ``r_max``; unit speeds (for ``r_max > 1/3`` the first disk is
        redrawn while it leaves no room for the second). ``"uniform"``: the invariant measure of
        ``rule`` at ``r = r_max`` (positions uniform on the non-overlapping pairs; unit
        speeds with uniform directions under ``"mirror"``, ``(v1, v2)`` uniform on
        ``|v1|^2 + |v2|^2 = 2`` under ``"elastic"``).
    rule : {"mirror", "elastic"}
        Only used by ``method="uniform"``.
    start : int
        Index of the first IC: returns ICs ``start .. start + n - 1`` of the ensemble.
    masses : (float, float), optional
        ``method="uniform"``, ``rule="elastic"``: the disks' masses; velocities uniform on
        ``m0 |v0|^2 + m1 |v1|^2 = 2`` with the masses normalised to ``(m0 + m1) / 2 = 1``.
    table : Circle, Stadium or Ellipse, optional
        The table (`kicktimes.tables`; ``None``: the unit circle, whose ensembles do not
        change). In a `Stadium` or an `Ellipse` only ``method="uniform"``: both centres
        uniform in the region of a disk of radius ``r_max`` (the inner parallel curve,
        ``table.contains``), not overlapping (``|q0 - q1| >= 2 r_max``), by joint
        rejection from the region's bounding box; the velocities as the circle's uniform
        method draws them for ``rule``. ``r_max`` must be one radius that the table admits
        (``table.check_radius``).

    Notes
    -----
    Every ``r_max`` in (0, 0.5) works and each IC takes bounded time: after 1000 rejected
    draws of a disk (or pair) the draw is made from the same conditional law directly
    (inverse CDF on a 4097-point grid). This never happens for ``r_max <= 0.1``, so those
    ensembles are exactly the plain rejection sampler's.

    Returns
    -------
    ndarray, shape (n, 2, 4)
        Rows ``(x, y, vx, vy)`` of disk 0 and disk 1 for each IC.

    Examples
    --------
    >>> ics = initial_conditions(5, 0.03, rng=1)
    >>> ics.shape
    (5, 2, 4)
    >>> bool((initial_conditions(2, 0.03, rng=1, start=3) == ics[3:5]).all())
    True

    In an ellipse:

    >>> from kicktimes.tables import Ellipse
    >>> ics = initial_conditions(3, 0.05, rng=1, method="uniform", table=Ellipse(1.5, 1.0))
    >>> bool(Ellipse(1.5, 1.0).contains(ics[..., :2], 0.05).all())
    True
    """
    n = chk.check_int("n", n, low=1)
    table = check_table(table)
    if table != Circle():
        if isinstance(r_max, tuple):
            raise ValueError(f"r_max: two disks in {table!r} must be equal (one radius), got "
                             f"{r_max!r}")
        r_max = table.check_radius(chk.check_real("r_max", r_max, low=0.0, high=0.5))
        if method != "uniform":
            raise ValueError(f"method: only method='uniform' (the invariant measure) draws in "
                             f"{table!r}; the paper's procedure is the unit circle's, got "
                             f"method={method!r}")
    if isinstance(r_max, tuple):
        # unequal disks: the invariant measure of the pair of radii
        r0, r1, r_max = chk.check_radii(r_max)
        if method != "uniform" or max(r0, r1) > 1.0 / 3.0:
            raise ValueError("r_max: a pair of radii (r0, r1) needs method='uniform' and both "
                             "radii at most 1/3; for the paper's procedure draw at "
                             "max(r0, r1), which is valid for both disks")
    else:
        r_max = chk.check_real("r_max", r_max, low=0.0, high=0.5)
    if not isinstance(r_max, tuple) and r_max > R_MAX_IC:
        raise ValueError(
            f"r_max must lie in (0.0, {R_MAX_IC!r}], got {r_max!r}: two disks this large "
            "only fit diametrically opposite, against the wall, with no room to move"
        )
    root = check_seed_sequence(rng, "rng")
    start = chk.check_int("start", start, low=0)
    chk.check_choice("method", method, METHODS)
    chk.check_choice("rule", rule, chk.RULES)
    masses = chk.check_masses(masses, rule)
    if masses is not None and method != "uniform":
        raise ValueError("masses: the paper's procedure has unit speeds; draw method='uniform'")
    try:
        out = np.empty((n, 2, 4))
    except MemoryError:
        raise MemoryError(
            f"n: {n} ICs need {n * 64 / 2**30:.3g} GiB, more than this machine can allocate; "
            "draw them in blocks with start= (IC i does not depend on the block)"
        ) from None
    for k in range(n):
        gen = np.random.default_rng(np.random.SeedSequence(
            root.entropy, spawn_key=(*root.spawn_key, start + k), pool_size=root.pool_size))
        if table != Circle():
            out[k] = _table_ic(gen, r_max, rule, masses, table)
        else:
            out[k] = (_paper_ic(gen, r_max) if method == "paper"
                      else _uniform_ic(gen, r_max, rule, masses))
    return out
