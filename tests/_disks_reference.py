"""A brute-force N-disk simulator in NumPy: every pair and every wall at every event.

The oracle of tests/test_disks.py and the slow baseline of benchmarks/bench_disks.py.
Written from the physics (docs/architecture.md, "The physics, precisely"), not from the
engine: no cells, no calendar, no delayed states, one global clock; O(N^2) per event.
"""

from __future__ import annotations

import numpy as np


def wall_times(x, v, rho):
    """Time from now until each centre reaches ``|x| = rho`` (0 if outside and leaving)."""
    b = np.einsum("ij,ij->i", x, v)
    vv = np.einsum("ij,ij->i", v, v)
    c = rho * rho - np.einsum("ij,ij->i", x, x)
    sq = np.sqrt(np.maximum(b * b + vv * c, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(b > 0.0, c / (b + sq), (-b + sq) / vv)
    t[vv == 0.0] = np.inf
    return np.maximum(t, 0.0)


def pair_times(x, v, radii):
    """``(t, i, j)``: the earliest contact of an approaching pair, over all pairs."""
    n = x.shape[0]
    i, j = np.triu_indices(n, 1)
    d = x[i] - x[j]
    w = v[i] - v[j]
    b = np.einsum("ij,ij->i", d, w)
    ww = np.einsum("ij,ij->i", w, w)
    sig = radii[i] + radii[j]
    c = np.einsum("ij,ij->i", d, d) - sig * sig
    disc = b * b - ww * c
    ok = (b < 0.0) & (disc > 0.0)
    t = np.full(i.shape, np.inf)
    t[ok] = np.maximum(c[ok] / (-b[ok] + np.sqrt(disc[ok])), 0.0)
    if t.size == 0:
        return np.inf, -1, -1
    k = int(np.argmin(t))
    return float(t[k]), int(i[k]), int(j[k])


def simulate(state, radii, t_max, *, rule="mirror", masses=None, n_pp=None):
    """Disk-disk collisions ``(time, i, j)`` from ``state`` up to ``t_max`` (or the first
    ``n_pp``), and the state at the end."""
    x = np.array(state, dtype=float)[:, :2].copy()
    v = np.array(state, dtype=float)[:, 2:].copy()
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (x.shape[0],)).copy()
    m = np.ones(x.shape[0]) if masses is None else np.asarray(masses, dtype=float)
    rho = 1.0 - radii
    t = 0.0
    log = []
    while n_pp is None or len(log) < n_pp:
        tw = wall_times(x, v, rho)
        kw = int(np.argmin(tw))
        tp, i, j = pair_times(x, v, radii) if x.shape[0] > 1 else (np.inf, -1, -1)
        dt = min(tw[kw], tp)
        if t + dt > t_max:
            x += v * (t_max - t)
            break
        x += v * dt
        t += dt
        if tw[kw] <= tp:
            n = x[kw] / np.linalg.norm(x[kw])
            v[kw] -= 2.0 * (v[kw] @ n) * n
        else:
            n = (x[i] - x[j]) / np.linalg.norm(x[i] - x[j])
            if rule == "mirror":
                v[i] -= 2.0 * (v[i] @ n) * n
                v[j] -= 2.0 * (v[j] @ n) * n
            else:
                p = (v[i] - v[j]) @ n
                v[i] -= 2.0 * m[j] / (m[i] + m[j]) * p * n
                v[j] += 2.0 * m[i] / (m[i] + m[j]) * p * n
            log.append((t, i, j))
    return np.array(log).reshape(-1, 3), np.column_stack([x, v])
