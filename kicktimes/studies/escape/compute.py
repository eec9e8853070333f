"""The escape study's simulations and tables: escape times per IC and system, tail rates
with their paired bootstrap, the ratios against the two disks, the free disk's constant."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import scipy.stats as sps

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.stats import (
    MARGIN,
    circle_escape_constant,
    escape_survival,
    fit_escape_tail,
    kinetic_rate,
    percentile_interval,
    ratio_verdict,
    resample_indices,
)

__all__ = [
    "BURSTY_SHAPE", "CONTROLS", "FREE_TIMES", "HOLE", "KICKED", "LABELS", "N_BOOT", "RADII",
    "SMALL_HOLE", "SYSTEMS",
    "bootstrap_picks", "censor", "constant_rows", "ergodic_rate", "escape_tables",
    "escape_times", "free_disk_escapes", "tail_rates",
]

RADII = (0.005, 0.01, 0.02, 0.03)
HOLE = [(0.0, 0.05)]
SMALL_HOLE = [(0.0, 0.025)]
BURSTY_SHAPE = 0.1
N_BOOT = 1000
#: the times at which the free disk's t S(t) is set against the circle's C
FREE_TIMES = (300.0, 1000.0, 3000.0)
SYSTEMS = ("two_particle", "two_particle_pooled", "poisson", "poisson_scatter",
           "poisson_small_hole", "bursty", "free")
KICKED = ("poisson", "poisson_scatter", "poisson_small_hole", "bursty")
CONTROLS = ("poisson_small_hole", "bursty")
LABELS = {"two_particle": "two disks (disk 0, censored by disk 1)",
          "two_particle_pooled": "two disks (both disks pooled)",
          "poisson": "kicked, uniform kicks", "poisson_scatter": "kicked, scatter kicks",
          "poisson_small_hole": "kicked, uniform, half-width hole (control)",
          "bursty": f"kicked, uniform, gamma({BURSTY_SHAPE:g}) renewal times (control)",
          "free": "free disk (no kicks)"}


def escape_times(r, ics, t_max, seed) -> pd.DataFrame:
    """Per system (a column) the escape time of disk 0 of each IC (a row; inf: none by
    ``t_max``); for the two disks also the first escape of either disk
    (``two_particle_pooled``) and who left (``escaped``: 0, 1 or -1). A negative
    ``two_particle`` time is disk 0 censored by disk 1's escape at its absolute value."""
    rate = float(kinetic_rate(r))
    out = {s: np.full(len(ics), np.inf) for s in SYSTEMS}
    out["escaped"] = np.full(len(ics), -1)
    bursty = schedules.Renewal(sps.gamma(BURSTY_SHAPE, scale=1.0 / (BURSTY_SHAPE * rate)),
                               stationary=True)
    for i, ic in enumerate(ics):
        two = simulate_two_particle(ic, r, t_max=t_max, holes=HOLE)
        out["escaped"][i] = two.escaped
        if two.escaped >= 0:
            out["two_particle_pooled"][i] = two.escape_time
        if two.escaped == 0:
            out["two_particle"][i] = two.escape_time
        elif two.escaped == 1:
            out["two_particle"][i] = -two.escape_time  # censored by disk 1's escape
        for system, law, kicks, holes in (
                ("poisson", "uniform", schedules.Poisson(rate), HOLE),
                ("poisson_scatter", "scatter", schedules.Poisson(rate), HOLE),
                ("poisson_small_hole", "uniform", schedules.Poisson(rate), SMALL_HOLE),
                ("bursty", "uniform", bursty, HOLE)):
            run = simulate_one_particle(ic[0], r, t_max=t_max, holes=holes, kick_angle=law,
                                        kicks=kicks, rng=np.random.default_rng((seed, i)))
            out[system][i] = run.escape_time
        out["free"][i] = simulate_one_particle(ic[0], r, t_max=t_max, holes=HOLE).escape_time
    return pd.DataFrame(out)


def tail_rates(times, horizon, t_min, picks, disks=1):
    """Exponential tail rate beyond ``t_min`` for each row of IC indices ``picks``:
    escapes after t_min / (disks x time beyond t_min of the runs alive at t_min)."""
    end = np.minimum(times, horizon)
    alive = end > t_min
    event = np.isfinite(times) & alive
    exposure = np.where(alive, end - t_min, 0.0)
    return event[picks].sum(-1) / (disks * exposure[picks].sum(-1))


def free_disk_escapes(r, n, t_max, seed) -> pd.DataFrame:
    """Escape times (column ``escape_time``) of the free disk from ``n`` unit-speed ICs of
    the invariant measure (the measure the circle's C is derived for)."""
    states = initial_conditions(n, r, method="uniform", seed=seed)[:, 0].copy()
    states[:, 2:] /= np.hypot(states[:, 2], states[:, 3])[:, None]
    escapes = np.array([simulate_one_particle(s, r, t_max=t_max, holes=HOLE).escape_time
                        for s in states])
    return pd.DataFrame({"escape_time": escapes})


def constant_rows(r, escapes, times=FREE_TIMES):
    """t S(t) of the free disk's ``escapes`` with its binomial 95 % interval, against
    Bunimovich & Dettmann's C for the circle of radius 1 - r."""
    escapes = np.asarray(escapes, float)
    n = escapes.size
    predicted = circle_escape_constant(HOLE[0][1], radius=1.0 - r)
    rows = []
    for t in times:
        alive = int(np.sum(escapes > t))
        half = 1.96 * t * math.sqrt(alive * (1.0 - alive / n)) / n
        rows.append({"radius": r, "t": t, "n": n, "alive": alive, "t_S": t * alive / n,
                     "t_S_low": t * alive / n - half, "t_S_high": t * alive / n + half,
                     "C_predicted": predicted})
    return rows


def ergodic_rate(r, half_width=HOLE[0][1], speed=1.0):
    """Escape rate of a disk whose direction is uniformly random at every wall hit:
    speed x hole length / (pi x area) for its centre's circle of radius 1 - r."""
    radius = 1.0 - r
    return speed * 2.0 * half_width * radius / (math.pi * math.pi * radius ** 2)


def censor(times, t_max):
    """Escape times and per-run horizons: a negative time is a censoring at |t|."""
    t = np.asarray(times, dtype=float)
    horizon = np.where(t < 0, -t, t_max)
    return np.where(t < 0, np.inf, t), horizon


def bootstrap_picks(n_ics, seed, n_boot=N_BOOT):
    """The IC indices of the estimate (first row) and of ``n_boot`` bootstrap resamples,
    shared by every radius and system (the bootstrap is paired)."""
    rng = np.random.default_rng(seed)
    return resample_indices(n_ics, n_boot, rng, with_identity=True)


def escape_tables(times_by_radius, t_max, t_min, picks):
    """The tail table and the ratio table of the page, and the Kaplan-Meier curves.

    Parameters
    ----------
    times_by_radius : dict
        Radius -> the `escape_times` table of that radius.
    t_max, t_min : float
        The runs' horizon and where the tail fits start.
    picks : ndarray
        `bootstrap_picks`.

    Returns
    -------
    table, ratios : DataFrame
        ``escape_tails.csv`` and ``escape_ratios.csv``.
    curves : dict
        ``(radius, system)`` -> Kaplan-Meier table (`kicktimes.stats.escape_survival`).
    """
    rows, ratios, curves = [], [], {}
    for r, times in times_by_radius.items():
        gammas = {}
        for system in SYSTEMS:
            t, horizon = censor(times[system].to_numpy(), t_max)
            if system != "two_particle_pooled":
                curves[(r, system)] = escape_survival(t, horizon)
            disks = 2 if system == "two_particle_pooled" else 1
            gammas[system] = tail_rates(t, horizon, t_min, picks, disks)
            tail = fit_escape_tail(t, horizon, t_min=t_min)
            lo, hi = percentile_interval(gammas[system][1:])
            rows.append({"radius": r, "system": system, "kinetic_rate": float(kinetic_rate(r)),
                         "n": t.size, "escaped": int(np.isfinite(t).sum()),
                         "censored_by_partner": int((times["escaped"] == 1).sum())
                         if system == "two_particle" else 0,
                         "rate": gammas[system][0], "rate_boot_low": lo, "rate_boot_high": hi,
                         "alpha": tail.alpha, "alpha_low": tail.alpha_ci[0],
                         "alpha_high": tail.alpha_ci[1],
                         "aic_exp_minus_alg": tail.aic_exponential - tail.aic_algebraic,
                         "best_tail": tail.best})
        for system in KICKED:
            for reference in ("two_particle", "two_particle_pooled"):
                q = gammas[system] / gammas[reference]
                lo, hi = percentile_interval(q[1:])
                ratios.append({"radius": r, "system": system, "reference": reference,
                               "ratio": q[0], "ci_low": lo, "ci_high": hi,
                               "verdict": ratio_verdict(lo, hi, MARGIN),
                               "negative_control": system in CONTROLS})
    return pd.DataFrame(rows), pd.DataFrame(ratios), curves
