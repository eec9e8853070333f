"""The gas's largest Lyapunov exponent against density: the kinetic-theory form (issue 42).

For a dilute gas of hard disks kinetic theory gives the largest Lyapunov exponent per
collision as linear in the logarithm of the reduced density,

.. math:: \\lambda / \\nu = a + b \\ln(1/\\tilde n), \\qquad \\tilde n = n \\sigma^2,

with :math:`\\nu` the collision frequency per disk, :math:`n` the number density and
:math:`\\sigma = 2r` the diameter (van Zon, van Beijeren & Dellago, Phys. Rev. Lett. 80,
2035 (1998); the clock model there also predicts a slow growth with N, corrections of order
:math:`1/\\ln^2 N`). In the unit table :math:`n = N/\\pi` and the packing is
:math:`\\phi = N r^2`, so :math:`\\tilde n = 4\\phi/\\pi`.

`LyapunovDensity` measures :math:`\\lambda/\\nu` of N disks (mirror rule; N = 300 and 1000
published) at packings from 0.0025 to 0.08 (:math:`\\ln(1/\\tilde n)` from 5.7 to 2.3),
16 states each: `kicktimes.diagnostics.disks_lyapunov` (tangent vectors) over 100 mean free
times, renormalised every mean free time, the first 10 segments left out (the tangent
vector's alignment); :math:`\\nu` is each run's own collision rate per disk.
`write_lyapunov_density` writes, beside the disks page,

* ``disks_lyapunov_density_runs.csv``: one row per state;
* ``disks_lyapunov_density.csv``: per (N, packing) the mean :math:`\\lambda/\\nu` with a
  95 % percentile bootstrap over states;
* ``disks_lyapunov_density_fit.csv``: per N the least-squares line
  :math:`a + b \\ln(1/\\tilde n)` through the means at packings up to ``fit_max_packing``
  (0.02: the dilute range), the quadratic coefficient :math:`c` of
  :math:`a' + b' x + c x^2` (curvature), and each local slope between adjacent packings over
  :math:`b` with `kicktimes.stats.ratio_verdict` (10 % margin, set before the run); all
  intervals from the same bootstrap (states resampled within each packing).

The form is read as holding over the range if no curvature is detected (c's interval
contains 0) and every local slope is within 10 % of b; as not holding if c's interval
excludes 0; inconclusive otherwise. The states' exponents are cached in
``OUT/lyapunov-density/`` (one table per N and packing, with its parameters beside it:
`kicktimes.studies.cache`), so a rerun with the same parameters recomputes only the
statistics.

Examples
--------
>>> sweep = LyapunovDensity(n_disks=(20,), packings=(0.005, 0.01, 0.02), states=2)
>>> [g["packing"] for g in sweep.groups()]
[0.005, 0.01, 0.02]
>>> round(reduced_density(0.02), 5)
0.02546
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral, Real
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.fileio import atomic_write
from kicktimes.stats import percentile_interval, resample_indices
from kicktimes.studies.cache import cached_tables, runs_table, write_cached
from kicktimes.studies.disks.ftle_check import _say_reused

__all__ = ["DENSITY", "FIT_MAX_PACKING", "PACKINGS", "RUNS_COLUMNS", "SLOPE_MARGIN",
           "LyapunovDensity", "lyapunov_density_runs", "one_state", "reduced_density",
           "seed_lyapunov_density", "summarise", "write_lyapunov_density"]

PACKINGS = (0.0025, 0.005, 0.01, 0.02, 0.04, 0.08)
#: the margin of the local slopes' equivalence with the global slope, set before the run
SLOPE_MARGIN = 0.10
#: the fit's dilute range: packings up to this (reduced density 0.025). Chosen after a pilot
#: (3 states, N = 300) showed the local slope falling to 0.73 b between packings 0.04 and
#: 0.08, where the O(n~) corrections of the dilute expansion are no longer small; the
#: denser points are still measured and shown
FIT_MAX_PACKING = 0.02
#: the columns of disks_lyapunov_density_runs.csv: one row per state
RUNS_COLUMNS = ("n_disks", "packing", "state", "lam", "nu", "lam_per_coll")
#: the cache's folder under the study's work folder
CACHE = "lyapunov-density"


def _is_int(value) -> bool:
    return isinstance(value, Integral) and not isinstance(value, bool)


@dataclass(frozen=True)
class LyapunovDensity:
    """The sweep's parameters; the defaults made docs/results/disks_lyapunov_density*.csv.

    Parameters
    ----------
    n_disks : tuple of int
        The numbers of disks (each ``>= 2``).
    packings : tuple of float
        The packings ``N r^2`` (each in ``(0, 0.5)``); a state's seed depends on its
        packing's position in this tuple.
    states : int
        States per (N, packing) (``>= 2``: a bootstrap over states).
    mean_free_times : float
        Each run's length in mean free times (Enskog's), one segment each.
    skip : int
        The first segments left out (``>= 0``, leaving at least two).
    seed : int
        The root of every state's seed (``SeedSequence(seed, spawn_key=(N, packing's
        position, state))``).
    fit_max_packing : float
        The fit's dilute range: packings up to this (at least 3 of them).
    """

    n_disks: tuple = (300, 1000)
    packings: tuple = PACKINGS
    states: int = 16
    mean_free_times: float = 100.0
    skip: int = 10
    seed: int = 4242
    fit_max_packing: float = FIT_MAX_PACKING

    def __post_init__(self):
        object.__setattr__(self, "n_disks", tuple(self.n_disks))
        object.__setattr__(self, "packings", tuple(self.packings))
        if not self.n_disks or not all(_is_int(n) and n >= 2 for n in self.n_disks):
            raise ValueError(f"n_disks must be integers >= 2, got {self.n_disks!r}")
        if not self.packings or not all(isinstance(p, Real) and 0 < p < 0.5
                                        for p in self.packings):
            raise ValueError(f"packings must lie in (0, 0.5), got {self.packings!r}")
        if not _is_int(self.states) or self.states < 2:
            raise ValueError(f"states must be an integer >= 2 (a bootstrap over states), "
                             f"got {self.states!r}")
        if not (isinstance(self.mean_free_times, Real) and self.mean_free_times > 0):
            raise ValueError(f"mean_free_times must be > 0, got {self.mean_free_times!r}")
        if not _is_int(self.skip) or not 0 <= self.skip < self.mean_free_times - 1:
            raise ValueError(f"skip must be an integer >= 0 leaving at least two segments, "
                             f"got {self.skip!r}")
        if not _is_int(self.seed):
            raise ValueError(f"seed must be an integer, got {self.seed!r}")
        dilute = sum(p <= self.fit_max_packing * (1 + 1e-12) for p in self.packings)
        if dilute < 3:
            raise ValueError(f"fit_max_packing: at least 3 packings must lie at or below "
                             f"{self.fit_max_packing}, got {dilute}")

    def groups(self) -> list[dict]:
        """One dict per (N, packing), in the runs table's order: the parameters of its
        cached table (``n_disks, packing, packing_index, states, seed, mean_free_times,
        skip``)."""
        return [{"n_disks": int(n), "packing": float(p), "packing_index": i,
                 "states": int(self.states), "seed": int(self.seed),
                 "mean_free_times": float(self.mean_free_times), "skip": int(self.skip)}
                for n in self.n_disks for i, p in enumerate(self.packings)]


#: the published sweep (docs/results/disks_lyapunov_density*.csv)
DENSITY = LyapunovDensity()


def reduced_density(packing: float) -> float:
    """:math:`\\tilde n = n \\sigma^2 = (N/\\pi)(2r)^2 = 4\\phi/\\pi` in the unit table."""
    return 4.0 * packing / math.pi


def one_state(task):
    """``(n_disks, packing, state, lam, nu)`` of one state (`disks_lyapunov`, tangent) for
    ``task = (n_disks, i_packing, packing, state, seed, mean_free_times, skip)``."""
    import kicktimes as kt
    from kicktimes.diagnostics import disks_lyapunov
    from kicktimes.stats import enskog_frequency

    n_disks, i_packing, packing, state, seed, mean_free_times, skip = task
    r = math.sqrt(packing / n_disks)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(n_disks, i_packing,
                                                                        state)))
    x = kt.initial_state(n_disks, r, rng=rng, rule="mirror")
    segment = 1.0 / enskog_frequency(r, n_disks)
    t_max = mean_free_times * segment
    res = disks_lyapunov(x, r, t_max=t_max, segment=segment, rng=rng, method="tangent")
    lam = float(np.sum(res.logs[skip:]) / ((res.logs.size - skip) * segment))
    nu = 2.0 * res.n_collisions / (n_disks * res.logs.size * segment)
    return n_disks, packing, state, lam, nu


def _group_runs(n_disks, packing_index, packing, states, seed, mean_free_times, skip):
    """The runs of one (N, packing): states ``0 .. states-1``."""
    runs = pd.DataFrame([one_state((n_disks, packing_index, packing, k, seed,
                                    mean_free_times, skip)) for k in range(states)],
                        columns=list(RUNS_COLUMNS[:-1]))
    runs["lam_per_coll"] = runs["lam"] / runs["nu"]
    return runs


def _jobs(out, sweep: LyapunovDensity):
    folder = Path(out) / CACHE
    return [(folder / f"n{g['n_disks']}-phi{g['packing']:g}.parquet", g, _group_runs,
             (g["n_disks"], g["packing_index"], g["packing"], g["states"], g["seed"],
              g["mean_free_times"], g["skip"]))
            for g in sweep.groups()]


def lyapunov_density_runs(out, sweep: LyapunovDensity = DENSITY, *, workers: int = 1,
                          progress=None) -> pd.DataFrame:
    """Every state's exponent and collision rate (columns `RUNS_COLUMNS`), by N, packing
    (in the sweep's order) and state: from the cache in ``out/lyapunov-density`` where its
    parameters match, else computed and cached, one table per (N, packing) by each of
    ``workers`` processes; ``sweep`` the parameters (default: the published ones),
    ``progress`` as in `kicktimes.studies.disks.ftle_check.ftle_check_runs`."""
    cached = cached_tables(_jobs(out, sweep), workers=workers, progress=progress)
    _say_reused(cached, "the FTLE against density", progress)
    return pd.concat([c.table for c in cached], ignore_index=True)


def seed_lyapunov_density(out, runs, sweep: LyapunovDensity = DENSITY) -> None:
    """Put the states' rows ``runs`` (a ``disks_lyapunov_density_runs.csv``, or its path:
    read exactly) into the cache of ``sweep`` in ``out``, so that `lyapunov_density_runs`
    reuses them.

    Raises
    ------
    ValueError
        If ``runs`` lacks an (N, packing) of ``sweep`` or its states are not ``0 ..
        states-1``.
    """
    runs = runs_table(runs, RUNS_COLUMNS)
    for path, params, _, _ in _jobs(out, sweep):
        g = runs[(runs["n_disks"] == params["n_disks"])
                 & (runs["packing"] == params["packing"])].sort_values("state",
                                                                      ignore_index=True)
        if g["state"].tolist() != list(range(params["states"])):
            raise ValueError(f"runs: N = {params['n_disks']}, packing {params['packing']:g} "
                             f"has not the states 0 .. {params['states'] - 1}")
        write_cached(path, params, g[list(RUNS_COLUMNS)])


def _fit(x, y):
    """``(a, b, c, local slopes / b)``: the line ``a + b x`` and the quadratic coefficient
    ``c`` through ``(x, y)``, and the slopes between adjacent points over ``b``."""
    b, a = np.polyfit(x, y, 1)
    c = np.polyfit(x, y, 2)[0]
    return a, b, c, (np.diff(y) / np.diff(x)) / b


def summarise(runs: pd.DataFrame, *, n_boot=2000, seed=0, fit_max_packing=FIT_MAX_PACKING):
    """The per-packing table and the per-N fit table (see the module docstring), the fit
    over the packings up to ``fit_max_packing``."""
    from kicktimes.stats import ratio_verdict
    from kicktimes.studies.disks.kicked import density_form_reading

    rng = np.random.default_rng(seed)
    rows, fits = [], []
    for n_disks, g in runs.groupby("n_disks", sort=True, observed=True):
        packings = sorted(g["packing"].unique())
        x = np.array([math.log(1.0 / reduced_density(p)) for p in packings])
        per = [g.loc[g["packing"] == p, "lam_per_coll"].to_numpy() for p in packings]
        means = np.array([v.mean() for v in per])
        # per replicate one resample of each packing's states, in turn (the stream of the page)
        boot = np.array([[v[resample_indices(v.size, n_boot=1, rng=rng)[0]].mean() for v in per]
                         for _ in range(n_boot)])
        lo, hi = percentile_interval(boot, axis=0)
        for p, xv, v, m, a, b in zip(packings, x, per, means, lo, hi, strict=True):
            rows.append({"n_disks": n_disks, "packing": p, "reduced_density":
                         reduced_density(p), "ln_inv_density": xv, "n_states": v.size,
                         "lam_per_coll": m, "lo": a, "hi": b})

        dilute = np.array(packings) <= fit_max_packing * (1 + 1e-12)
        if dilute.sum() < 3:
            raise ValueError(f"fit_max_packing: at least 3 packings must lie at or below "
                             f"{fit_max_packing}, got {dilute.sum()}")
        xd = x[dilute]

        est = _fit(xd, means[dilute])
        bs = [_fit(xd, y[dilute]) for y in boot]
        ci = {k: percentile_interval([f[k] for f in bs], axis=0) for k in range(4)}
        local_verdicts = [ratio_verdict(ci[3][0][i], ci[3][1][i], tolerance=SLOPE_MARGIN)
                          for i in range(int(dilute.sum()) - 1)]
        reading = density_form_reading(ci[2][0], ci[2][1], local_verdicts, SLOPE_MARGIN)
        fits.append({"n_disks": n_disks, "fit_max_packing": fit_max_packing,
                     "a": est[0], "a_lo": ci[0][0], "a_hi": ci[0][1],
                     "b": est[1], "b_lo": ci[1][0], "b_hi": ci[1][1], "c": est[2],
                     "c_lo": ci[2][0], "c_hi": ci[2][1],
                     "local_over_b": ";".join(f"{v:.4g}" for v in est[3]),
                     "local_lo": ";".join(f"{v:.4g}" for v in ci[3][0]),
                     "local_hi": ";".join(f"{v:.4g}" for v in ci[3][1]),
                     "local_verdicts": ";".join(local_verdicts), "margin": SLOPE_MARGIN,
                     "reading": reading})
    return pd.DataFrame(rows), pd.DataFrame(fits)


def write_lyapunov_density(out, results_dir, sweep: LyapunovDensity = DENSITY, *,
                           workers: int = 1, progress=None) -> pd.DataFrame:
    """Run (or reuse from the cache ``out/lyapunov-density``) the sweep and write
    ``disks_lyapunov_density_runs.csv``, ``disks_lyapunov_density.csv`` and
    ``disks_lyapunov_density_fit.csv`` into the disks page's folder ``results_dir``, each
    atomically; ``sweep``, ``workers`` and ``progress`` as in `lyapunov_density_runs`.
    Returns the per-N fit table, as written.
    """
    runs = lyapunov_density_runs(out, sweep, workers=workers, progress=progress)
    table, fits = summarise(runs, fit_max_packing=sweep.fit_max_packing)
    results = Path(results_dir)
    for name, frame in (("disks_lyapunov_density_runs", runs),
                        ("disks_lyapunov_density", table),
                        ("disks_lyapunov_density_fit", fits)):
        atomic_write(results / f"{name}.csv", lambda tmp, f=frame: f.to_csv(tmp, index=False))
    return fits
