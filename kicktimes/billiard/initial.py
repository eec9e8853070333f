"""Initial-condition ensembles for the two-disk billiard.

IC ``i`` of an ensemble is drawn from its own generator,
``numpy.random.default_rng(SeedSequence(seed, spawn_key=(i,)))`` (the ``i``-th child of
``SeedSequence(seed)``), so it does not depend on how the ensemble is split into blocks
or across workers: ``initial_conditions(10, r, seed=s)[7]`` equals
``initial_conditions(3, r, seed=s, start=7)[0]``.
"""

from __future__ import annotations

import math

import numpy as np

from kicktimes.billiard import _checks as chk

METHODS = ("paper", "uniform")


def ic_generator(seed: int, index: int) -> np.random.Generator:
    """The generator of IC ``index`` of the ensemble with root ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(index,)))


def _paper_ic(rng: np.random.Generator, r_max: float) -> np.ndarray:
    # The paper's procedure: distance from the centre uniform on (0, 1) (not area-uniform),
    # polar angle uniform; redraw a disk while it pokes out of the table or overlaps the
    # disk already placed, at the family's largest radius.
    rho = 1.0 - r_max
    out = np.empty((2, 4))
    for i in range(2):
        while True:
            dist = rng.uniform(0.0, 1.0)
            phi = rng.uniform(0.0, 2.0 * np.pi)
            x, y = dist * math.cos(phi), dist * math.sin(phi)
            if dist > rho:
                continue
            if i == 1 and math.hypot(x - out[0, 0], y - out[0, 1]) < 2.0 * r_max:
                continue
            break
        angle = rng.uniform(0.0, 2.0 * np.pi)
        out[i] = (x, y, math.cos(angle), math.sin(angle))
    return out


def _uniform_ic(rng: np.random.Generator, r_max: float, rule: str) -> np.ndarray:
    # The invariant (Liouville) measure: the *pair* of centres uniform on the
    # non-overlapping configurations, by joint rejection (redrawing only the second disk
    # would weight configurations by the free area left to it, which is not uniform).
    rho = 1.0 - r_max
    out = np.empty((2, 4))
    while True:
        rad = rho * np.sqrt(rng.uniform(size=2))
        phi = rng.uniform(0.0, 2.0 * np.pi, size=2)
        x = rad * np.cos(phi)
        y = rad * np.sin(phi)
        if math.hypot(x[0] - x[1], y[0] - y[1]) >= 2.0 * r_max:
            break
    out[:, 0] = x
    out[:, 1] = y
    if rule == "mirror":
        angle = rng.uniform(0.0, 2.0 * np.pi, size=2)
        out[:, 2] = np.cos(angle)
        out[:, 3] = np.sin(angle)
    else:
        # (v1, v2) uniform on the sphere |v1|^2 + |v2|^2 = 2 in R^4
        g = rng.standard_normal(4)
        g *= math.sqrt(2.0) / np.linalg.norm(g)
        out[0, 2:] = g[:2]
        out[1, 2:] = g[2:]
    return out


def initial_conditions(n, r_max, *, seed=0, method="paper", rule="mirror", start=0) -> np.ndarray:
    """Draw an ensemble of two-disk initial conditions.

    Parameters
    ----------
    n : int
        Number of ICs (``>= 1``).
    r_max : float
        The largest disk radius the ensemble will be used with, ``0 < r_max < 0.5``.
        ICs are valid (inside the table, no overlap) for every ``r <= r_max``.
    seed : int
        Root seed (``>= 0``). The ensemble is a pure function of ``seed``.
    method : {"paper", "uniform"}
        ``"paper"``: per disk, distance from the centre uniform on (0, 1), polar angle
        and velocity angle uniform on [0, 2 pi), redrawn while it overlaps the boundary or
        the other disk at ``r_max``; unit speeds. ``"uniform"``: the invariant measure of
        ``rule`` at ``r = r_max`` (positions uniform on the non-overlapping pairs; unit
        speeds with uniform directions under ``"mirror"``, ``(v1, v2)`` uniform on
        ``|v1|^2 + |v2|^2 = 2`` under ``"elastic"``).
    rule : {"mirror", "elastic"}
        Only used by ``method="uniform"``.
    start : int
        Index of the first IC: returns ICs ``start .. start + n - 1`` of the ensemble.

    Returns
    -------
    ndarray, shape (n, 2, 4)
        Rows ``(x, y, vx, vy)`` of disk 0 and disk 1 for each IC.

    Examples
    --------
    >>> ics = initial_conditions(5, 0.03, seed=1)
    >>> ics.shape
    (5, 2, 4)
    >>> bool((initial_conditions(2, 0.03, seed=1, start=3) == ics[3:5]).all())
    True
    """
    n = chk.check_int("n", n, low=1)
    r_max = chk.check_real("r_max", r_max, low=0.0, high=0.5)
    seed = chk.check_int("seed", seed, low=0)
    start = chk.check_int("start", start, low=0)
    chk.check_choice("method", method, METHODS)
    chk.check_choice("rule", rule, chk.RULES)
    out = np.empty((n, 2, 4))
    for k in range(n):
        rng = ic_generator(seed, start + k)
        out[k] = _paper_ic(rng, r_max) if method == "paper" else _uniform_ic(rng, r_max, rule)
    return out
