r"""One free disk in each table: its own FTLE, and how far the ellipse's integral drifts.

The tables differ before any second disk or kick enters. A free disk of radius ``r``
moves as a point in the centre's region ``D_r`` (the table shrunk by ``r``):

* in the circle ``D_r`` is a circle: integrable (the angular momentum), the FTLE over a
  horizon ``T`` is the linear shear's :math:`\sim \ln T / T`;
* in the ellipse ``D_r`` is the ellipse's *parallel curve*, not an ellipse: the point
  particle's second integral, the product of the angular momenta about the two foci
  :math:`F = L_1 L_2` (Berry, Eur. J. Phys. 2, 91 (1981)), is kept exactly only at
  ``r = 0``; `focal_drift` measures how far it moves at the study's radii;
* in Bunimovich's stadium the flow is chaotic, :math:`\lambda \approx 0.43` per unit time
  for ``a = 1`` (Benettin & Strelcyn, Phys. Rev. A 17, 773 (1978); tests/test_tables.py
  checks it at ``r = 1e-9``).

`free_runs` is the FTLE of the free disk over the sweep's horizon from invariant-measure
states (`kicktimes.tables.uniform_state`, `kicktimes.tables.free_run`), the baseline the
two-disk and kicked FTLEs of the sweep are read against (`free_ftle` summarises it).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes.stats import cluster_bootstrap
from kicktimes.tables import Ellipse, free_run, uniform_state

__all__ = ["POINT_RADIUS", "focal_drift", "focal_product", "free_ftle", "free_runs"]

#: the radius that stands for a point particle (the integral is then kept to round-off)
POINT_RADIUS = 1e-9


def focal_product(table: Ellipse, positions, velocities) -> np.ndarray:
    r"""The product of the angular momenta about the ellipse's foci :math:`(\pm c, 0)`,
    :math:`c = \sqrt{a^2 - b^2}`: :math:`F = [(x - c) v_y - y v_x][(x + c) v_y - y v_x]`,
    constant along a point particle's orbit in the ellipse.

    Examples
    --------
    >>> round(float(focal_product(Ellipse(1.25, 0.8), [[0.0, 0.0]], [[0.0, 1.0]])[0]), 12)
    -0.9225
    """
    c = math.sqrt(table.a ** 2 - table.b ** 2)
    q, v = np.atleast_2d(positions), np.atleast_2d(velocities)
    l1 = (q[:, 0] - c) * v[:, 1] - q[:, 1] * v[:, 0]
    l2 = (q[:, 0] + c) * v[:, 1] - q[:, 1] * v[:, 0]
    return l1 * l2


def free_runs(tables, radii, *, n_states, horizon, seed) -> pd.DataFrame:
    """The free disk's FTLE per state: ``n_states`` invariant-measure states per (table,
    radius), each run over ``horizon`` with its tangent vector (`kicktimes.tables.free_run`).

    Returns
    -------
    pandas.DataFrame
        ``table, radius, state, ftle``.

    Examples
    --------
    >>> from kicktimes.tables import Circle
    >>> runs = free_runs({"circle": Circle()}, [0.02], n_states=2, horizon=100.0, seed=1)
    >>> list(runs.columns), len(runs)
    (['table', 'radius', 'state', 'ftle'], 2)
    """
    rows = []
    for k, (name, table) in enumerate(tables.items()):
        for j, r in enumerate(radii):
            rng = np.random.default_rng([seed, k, j])
            for i in range(n_states):
                run = free_run(table, uniform_state(table, r, rng=rng), r, t_max=horizon,
                               n_record=0, rng=rng)
                rows.append({"table": name, "radius": float(r), "state": i,
                             "ftle": run.lyapunov})
    return pd.DataFrame(rows)


def free_ftle(runs, *, horizon, n_boot=1000, seed=0) -> pd.DataFrame:
    """The free disk's FTLE per (table, radius) from `free_runs`: the mean over states, its
    95 % bootstrap interval over states (`kicktimes.stats.cluster_bootstrap`), and the
    horizon's shear scale ``ln(T) / T`` (an integrable table's FTLE over ``T``).

    Returns
    -------
    pandas.DataFrame
        ``table, radius, n_states, horizon, ftle, ci_low, ci_high, shear_scale``.

    Examples
    --------
    >>> from kicktimes.tables import Circle
    >>> runs = free_runs({"circle": Circle()}, [0.02], n_states=4, horizon=200.0, seed=1)
    >>> t = free_ftle(runs, horizon=200.0)
    >>> bool(t["ftle"].iloc[0] < 5 * t["shear_scale"].iloc[0])
    True
    """
    rows = []
    for k, ((table, r), g) in enumerate(runs.groupby(["table", "radius"], sort=False)):
        lam = g["ftle"].to_numpy(float)
        boot = cluster_bootstrap(lambda idx, lam=lam: lam[idx].mean(axis=1), lam.size,
                                 n_boot=n_boot, rng=np.random.default_rng([seed, k]))
        rows.append({"table": table, "radius": float(r), "n_states": lam.size,
                     "horizon": float(horizon), "ftle": boot.estimate, "ci_low": boot.ci_low,
                     "ci_high": boot.ci_high, "shear_scale": math.log(horizon) / horizon})
    return pd.DataFrame(rows)


def focal_drift(table: Ellipse, radii, *, n_states, n_bounces, seed) -> pd.DataFrame:
    r"""How far the focal product :math:`F` of `focal_product` moves along a free disk's
    orbit in ``table``, per radius: over ``n_states`` invariant-measure states, the largest
    :math:`\max_k |F_k - F_0|` over ``n_bounces`` wall contacts, and its median; next to
    the range of ``F`` over the states (:math:`F` lies in :math:`[-b^2, c^2]`, here its
    spread over the ensemble), so a drift is read against the spread it could cover.

    Returns
    -------
    pandas.DataFrame
        ``radius, n_states, n_bounces, max_drift, median_drift, ensemble_range``.

    Examples
    --------
    >>> d = focal_drift(Ellipse(1.25, 0.8), [1e-9], n_states=2, n_bounces=1000, seed=0)
    >>> bool(d["max_drift"].iloc[0] < 1e-8)   # O(r): the centre's curve is not the ellipse
    True
    """
    rows = []
    for j, r in enumerate(radii):
        rng = np.random.default_rng([seed, j])
        drift, start = [], []
        for _ in range(n_states):
            st = uniform_state(table, r, rng=rng)
            run = free_run(table, st, r, n_bounces=n_bounces, tangent=False, rng=rng)
            f0 = focal_product(table, st[:2], st[2:])[0]
            drift.append(float(np.abs(focal_product(table, run.positions, run.velocities)
                                      - f0).max()))
            start.append(f0)
        rows.append({"radius": float(r), "n_states": n_states, "n_bounces": n_bounces,
                     "max_drift": max(drift), "median_drift": float(np.median(drift)),
                     "ensemble_range": float(np.ptp(start))})
    return pd.DataFrame(rows)
