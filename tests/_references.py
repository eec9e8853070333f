"""Reference computations shared by the tests and the benchmarks, written from the
definitions rather than from the code they check (the benchmarks put this folder on
``sys.path``, as for ``_disks_reference.py``)."""

from __future__ import annotations

import numpy as np


def chord_trajectory(n: int, seed: int, tau: float = 0.2, kicked: bool = True):
    """A point particle in the unit disk sampled every ``tau``: straight chords, and at
    the wall a new direction drawn inwards (``kicked``) or the mirror reflection."""
    rng = np.random.default_rng(seed)
    x = np.array([0.3, -0.2])
    a = rng.uniform(0.0, 2.0 * np.pi)
    v = np.array([np.cos(a), np.sin(a)])
    pts = np.empty((n, 2))
    t, k = 0.0, 0
    while k < n:
        b = x @ v
        dt = -b + np.sqrt(b * b - x @ x + 1.0)
        while k < n and k * tau <= t + dt:
            pts[k] = x + (k * tau - t) * v
            k += 1
        x = x + dt * v
        if kicked:  # new direction pointing inwards
            a = np.arctan2(x[1], x[0]) + np.pi + rng.uniform(-0.5 * np.pi, 0.5 * np.pi)
            v = np.array([np.cos(a), np.sin(a)])
        else:
            nrm = x / np.linalg.norm(x)
            v = v - 2.0 * (v @ nrm) * nrm
        t += dt
    return pts


def ljung_box_numpy(x, lags):
    """The Ljung-Box statistic along the last axis as the vectorised numpy expression
    the compiled kernel of `kicktimes.stats.iid_tests.ljung_box` replaced."""
    m = x.shape[-1]
    d = x - x.mean(axis=-1, keepdims=True)
    denom = (d * d).sum(axis=-1)
    denom = np.where(denom > 0, denom, np.nan)
    q = np.zeros(x.shape[:-1])
    for k in range(1, lags + 1):
        rho = (d[..., k:] * d[..., :-k]).sum(axis=-1) / denom
        q += rho * rho / (m - k)
    return m * (m + 2) * q
