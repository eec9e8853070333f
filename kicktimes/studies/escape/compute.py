"""The escape study's simulations and tables: escape times per IC and system, tail rates
with their paired bootstrap, the ratios against the two disks, the free disk's constant."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import scipy.stats as sps

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.billiard import KickLaw
from kicktimes.stats import (
    MARGIN,
    circle_escape_constant,
    equivalence_sample_size,
    escape_survival,
    fit_escape_tail,
    kinetic_rate,
    percentile_interval,
    ratio_reading,
    resample_indices,
    robust_verdict,
)

__all__ = [
    "ALPHA_SAMPLES", "BURSTY_SHAPE", "CONTROLS", "FREE_TIMES", "HOLE", "KICKED", "LABELS",
    "N_BOOT", "RADII", "SMALL_HOLE", "SYSTEMS",
    "alpha_table", "bootstrap_picks", "censor", "constant_rows", "ergodic_rate",
    "escape_tables", "escape_times", "free_disk_escapes", "local_alpha", "over_radii",
    "tail_rates",
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
            run = simulate_one_particle(ic[0], r, t_max=t_max, holes=holes,
                                        kicks=KickLaw(kicks, angle=law),
                                        rng=np.random.default_rng((seed, i)))
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
    states = initial_conditions(n, r, method="uniform", rng=seed)[:, 0].copy()
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
    return resample_indices(n_ics, n_boot=n_boot, rng=rng, with_identity=True)


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
                               "verdict": ratio_reading(lo, hi),
                               "negative_control": system in CONTROLS})
    return pd.DataFrame(rows), pd.DataFrame(ratios), curves


def over_radii(times_by_radius, t_max, t_min, picks) -> pd.DataFrame:
    r"""``escape_over_radii.csv``: each ratio of escape rates summarised over the radii.

    Per (system, reference), the geometric mean over radii of the per-radius ratio of γ,
    :math:`\exp(\overline{\log(\gamma_s / \gamma_{\rm ref})})`, with its 95 % interval
    from the same paired bootstrap over ICs (`bootstrap_picks`: one resample of the ICs
    for every radius and system), its `kicktimes.stats.ratio_reading` and, from the standard
    error of its
    logarithm, the ICs at which a ratio of 1 would be resolved within the margin
    (`kicktimes.stats.equivalence_sample_size` with the margin ``log(1 + MARGIN)``, the
    band's narrower side). References: the two-disk estimators and ``"ergodic"``, the
    hole's `ergodic_rate`.
    """
    logs = {}
    for r, times in times_by_radius.items():
        gammas = {}
        for system in SYSTEMS:
            t, horizon = censor(times[system].to_numpy(), t_max)
            disks = 2 if system == "two_particle_pooled" else 1
            gammas[system] = tail_rates(t, horizon, t_min, picks, disks)
        pairs = [(s, ref) for s in KICKED for ref in ("two_particle", "two_particle_pooled")]
        pairs += [(s, "ergodic") for s in ("two_particle", "two_particle_pooled", "poisson",
                                             "poisson_scatter")]
        for s, ref in pairs:
            den = ergodic_rate(r) if ref == "ergodic" else gammas[ref]
            logs.setdefault((s, ref), []).append(np.log(gammas[s] / den))
    rows = []
    n_ics = int(picks.shape[1])
    for (s, ref), per in logs.items():
        mean = np.mean(per, axis=0)
        lo, hi = percentile_interval(np.exp(mean[1:]))
        se = float(np.std(mean[1:], ddof=1))
        rows.append({"system": s, "reference": ref, "n_radii": len(per),
                     "ratio": float(np.exp(mean[0])), "ci_low": lo, "ci_high": hi,
                     "verdict": ratio_reading(lo, hi), "se_log": se, "n_ics": n_ics,
                     "n_ics_to_resolve": equivalence_sample_size(se, n_ics,
                                                                 margin=math.log1p(MARGIN)),
                     "negative_control": s in CONTROLS})
    return pd.DataFrame(rows)


def local_alpha(g) -> tuple[float, float, float]:
    """The local exponent of the free disk between the first and last times of ``g`` (its
    `constant_rows`), ``1 + ln(t1 S(t1) / t2 S(t2)) / ln(t2 / t1)``, with the ends of the
    two binomial intervals divided crosswise (conservative); NaN where an interval
    reaches 0 (too few runs alive)."""
    g = g.sort_values("t")
    a, b = g.iloc[0], g.iloc[-1]
    span = math.log(b.t / a.t)
    if min(a.t_S_low, b.t_S_low) <= 0:
        return math.nan, math.nan, math.nan
    return (1 + math.log(a.t_S / b.t_S) / span, 1 + math.log(a.t_S_low / b.t_S_high) / span,
            1 + math.log(a.t_S_high / b.t_S_low) / span)


#: the two readings of the free disk's exponent: the IC samples are the control
ALPHA_SAMPLES = ("paper ICs", "invariant measure")


def alpha_table(table, constant, t_min, t_max) -> pd.DataFrame:
    """``escape_alpha.csv``: the free disk's exponent α per radius under each IC sample,
    with its `ratio_verdict` against C/t's α = 1 and whether it is robust over the two
    samples (`kicktimes.stats.robust_verdict`: the same verdict and no CI above 1 while
    the other lies below 1).

    ``paper ICs``: the Pareto fit on (``t_min``, ``t_max``] of disk 0 of the paper ICs (``table``,
    `escape_tables`, exact χ² interval); ``invariant measure``: `local_alpha` of the
    invariant-measure sample (``constant``, `constant_rows`) over its times.
    """
    free = table[table["system"] == "free"].set_index("radius")
    rows = []
    for r, g in constant.groupby("radius", observed=True):
        fit = free.loc[r]
        loc = local_alpha(g)
        got = [(ALPHA_SAMPLES[0], float(t_min), float(t_max),
                fit.alpha, fit.alpha_low, fit.alpha_high),
               (ALPHA_SAMPLES[1], float(g["t"].min()), float(g["t"].max()), *loc)]
        verdicts = [ratio_reading(lo, hi) for *_, lo, hi in got]
        robust, reason = robust_verdict(verdicts, [x[4] for x in got], [x[5] for x in got])
        for (sample, t0, t1, a, lo, hi), v in zip(got, verdicts, strict=True):
            rows.append({"radius": r, "sample": sample, "t_from": t0, "t_to": t1,
                         "alpha": a, "alpha_low": lo, "alpha_high": hi, "verdict": v,
                         "robust": robust, "not_robust_by": reason})
    return pd.DataFrame(rows)
