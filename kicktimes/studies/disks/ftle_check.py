"""Is the tangent FTLE of N disks right? Two equivalence checks, margins stated in advance.

* ``tangent/twin``: the largest Lyapunov exponent of `kicktimes.diagnostics.disks_lyapunov`
  from tangent vectors (``method="tangent"``, one run of the N-disk engine carrying them)
  over the same from a Benettin twin (``method="twin"``, ``d0 = 1e-9``, restarted through
  `simulate_disks` at every segment), on the same states (``initial_state``, seeds
  ``0 .. ics-1``) and the same first direction, at packing 0.15, N = 2, 10, 100, 1000, both
  rules. Margin 2 %.
* ``engine/two-disk``: two disks of radius 0.1 through the N-disk engine (tangent FTLE)
  over the two-disk simulator's tangent FTLE (`kicktimes.diagnostics.lyapunov`, disk 0's
  position deviation), same states, both rules. Margin 5 %.

Each method's runs of one state follow different trajectories after some ``37 / lambda``
(the twin's restarts, and the two simulators, round differently; chaos amplifies it), so
only means over states compare: ``estimate`` is the ratio of the means over the states,
``lo, hi`` its 95 % percentile interval from a paired bootstrap over the states
(`kicktimes.stats.paired_ratio`), ``verdict`` `kicktimes.stats.ratio_verdict`
with ``tolerance=margin`` (an equivalence test: "within" when the whole interval lies in
``[1 - margin, 1 + margin]``).

`write_ftle_check` writes ``disks_ftle_check.csv`` (columns ``check, n_disks, rule,
packing, n_ics, t_max, estimate, lo, hi, margin, verdict``) and ``disks_ftle_check_runs.csv``
(every state's two exponents) beside the disks page; `kicktimes.studies.disks.reproduce_disks`
calls it with the published parameters (`FTLE_CHECK`: 32 states per row, 599 s on one
worker). The states' exponents are cached in ``OUT/ftle-check/`` (one table per check, N
and rule, with its parameters beside it: `kicktimes.studies.cache`), so a rerun with the
same parameters recomputes only the statistics.

Examples
--------
>>> check = FtleCheck(ics=2, scale=0.01, max_disks=10)
>>> for g in check.groups()[:3]:
...     print(g["check"], g["n_disks"], g["rule"], g["t_max"])
tangent/twin 2 mirror 40.0
tangent/twin 10 mirror 4.0
engine/two-disk 2 mirror 200.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.fileio import atomic_write
from kicktimes.studies.cache import cached_tables, runs_table, write_cached
from kicktimes.studies.disks.kicked import FTLE_CHECK_COLUMNS

__all__ = ["FTLE_CHECK", "MARGINS", "RUNS_COLUMNS", "FtleCheck", "ftle_check_runs", "pair",
           "seed_ftle_check", "summarise", "write_ftle_check"]

PACKING = 0.15
TWO_DISK_R = 0.1
MARGINS = {"tangent/twin": 0.02, "engine/two-disk": 0.05}
# per N: (t_max, segment) at scale 1; the twin's segment keeps d0 e^(lambda segment) far
# below r (lambda segment about 2-3) and the collisions per segment few enough that a
# grazing one missed by the twin is rare
TWIN_RUNS = {2: (4000.0, 5.0), 10: (400.0, 0.5), 100: (40.0, 0.1), 1000: (8.0, 0.04)}
TWO_DISK_RUN = (20000.0, 10.0)
#: the columns of disks_ftle_check_runs.csv: one row per state
RUNS_COLUMNS = ("check", "n_disks", "rule", "seed", "t_max", "numerator", "denominator")
#: the cache's folder under the study's work folder
CACHE = "ftle-check"


@dataclass(frozen=True)
class FtleCheck:
    """The checks' parameters; the defaults made docs/results/disks_ftle_check.csv.

    Parameters
    ----------
    ics : int
        States (seeds ``0 .. ics-1``) per check, N and rule (``>= 2``: a bootstrap over
        states).
    scale : float
        Multiplies every ``t_max`` (``> 0``).
    max_disks : int
        The largest N of the ``tangent/twin`` check (``>= 2``).
    """

    ics: int = 32
    scale: float = 1.0
    max_disks: int = 1000

    def __post_init__(self):
        if isinstance(self.ics, bool) or not isinstance(self.ics, Integral) or self.ics < 2:
            raise ValueError(f"ics must be an integer >= 2, got {self.ics!r}")
        if not (isinstance(self.scale, (int, float)) and math.isfinite(self.scale)
                and self.scale > 0):
            raise ValueError(f"scale must be a finite number > 0, got {self.scale!r}")
        if (isinstance(self.max_disks, bool) or not isinstance(self.max_disks, Integral)
                or self.max_disks < 2):
            raise ValueError(f"max_disks must be an integer >= 2, got {self.max_disks!r}")

    def groups(self) -> list[dict]:
        """One dict per (check, N, rule): ``check, n_disks, rule, radius, ics, t_max,
        segment``, the parameters of its cached table."""
        out = []
        for rule in ("mirror", "elastic"):
            for n, (t_max, segment) in TWIN_RUNS.items():
                if n <= self.max_disks:
                    out.append({"check": "tangent/twin", "n_disks": n, "rule": rule,
                                "radius": math.sqrt(PACKING / n), "ics": int(self.ics),
                                "t_max": t_max * self.scale, "segment": segment})
            t_max, segment = TWO_DISK_RUN
            out.append({"check": "engine/two-disk", "n_disks": 2, "rule": rule,
                        "radius": TWO_DISK_R, "ics": int(self.ics),
                        "t_max": t_max * self.scale, "segment": segment})
        return out


#: the published checks (docs/results/disks_ftle_check.csv): 32 states per row
FTLE_CHECK = FtleCheck()


def pair(task):
    """One state's two exponents: ``(check, n, rule, seed, t_max, numerator, denominator)``
    for ``task = (check, n, rule, seed, t_max, segment)``."""
    import kicktimes as kt
    from kicktimes.diagnostics import disks_lyapunov, lyapunov

    check, n, rule, seed, t_max, segment = task
    if check == "tangent/twin":
        r = math.sqrt(PACKING / n)
        state = kt.initial_state(n, r, rng=seed, rule=rule)
        kw = dict(t_max=t_max, segment=segment, rule=rule, rng=seed)
        num = disks_lyapunov(state, r, **kw).lam
        den = disks_lyapunov(state, r, method="twin", **kw).lam
    else:
        state = kt.initial_state(2, TWO_DISK_R, rng=seed, rule=rule)
        num = disks_lyapunov(state, TWO_DISK_R, t_max=t_max, segment=segment, rule=rule,
                             rng=seed).lam
        den = lyapunov(state, TWO_DISK_R, n_steps=int(round(t_max / segment)), tau=segment,
                       rule=rule).lam
    return check, n, rule, seed, t_max, num, den


def _group_runs(check, n, rule, ics, t_max, segment) -> pd.DataFrame:
    """The runs of one (check, N, rule): seeds ``0 .. ics-1``."""
    return pd.DataFrame([pair((check, n, rule, s, t_max, segment)) for s in range(ics)],
                        columns=list(RUNS_COLUMNS))


def _jobs(out, check: FtleCheck):
    folder = Path(out) / CACHE
    return [(folder / f"{g['check'].replace('/', '-')}-n{g['n_disks']}-{g['rule']}.parquet",
             g, _group_runs,
             (g["check"], g["n_disks"], g["rule"], g["ics"], g["t_max"], g["segment"]))
            for g in check.groups()]


def _say_reused(cached, what, progress):
    """Tell ``progress`` how many of ``cached`` (`kicktimes.studies.cache.Cached`) were
    reused."""
    if progress is not None:
        progress(f"{what}: {sum(c.reused for c in cached)} of {len(cached)} tables reused "
                 "from the cache")


def _sorted(runs: pd.DataFrame) -> pd.DataFrame:
    return runs.sort_values(["check", "n_disks", "rule", "seed"], ignore_index=True)


def ftle_check_runs(out, check: FtleCheck = FTLE_CHECK, *, workers: int = 1,
                    progress=None) -> pd.DataFrame:
    """Every state's two exponents (columns `RUNS_COLUMNS`), from the cache in
    ``out/ftle-check`` where its parameters match, else computed and cached.

    Parameters
    ----------
    out : path-like
        The study's work folder.
    check : FtleCheck
        The parameters (default: the published ones).
    workers : int
        Processes computing the missing tables, one (check, N, rule) each.
    progress : callable, optional
        Takes one line of text per table computed.

    Returns
    -------
    pandas.DataFrame
        Sorted by check, N, rule and seed.
    """
    cached = cached_tables(_jobs(out, check), workers=workers, progress=progress)
    _say_reused(cached, "the FTLE checks", progress)
    return _sorted(pd.concat([c.table for c in cached], ignore_index=True))


def seed_ftle_check(out, runs, check: FtleCheck = FTLE_CHECK) -> None:
    """Seed the cache of ``check`` in ``out`` with the exponents ``runs`` (a
    ``disks_ftle_check_runs.csv``, or its path: read exactly), so that `ftle_check_runs`
    reuses them instead of simulating.

    Raises
    ------
    ValueError
        If ``runs`` lacks a (check, N, rule) of ``check``, its seeds are not ``0 ..
        ics-1`` or its ``t_max`` differs.
    """
    runs = runs_table(runs, RUNS_COLUMNS)
    for path, params, _, _ in _jobs(out, check):
        g = runs[(runs["check"] == params["check"]) & (runs["n_disks"] == params["n_disks"])
                 & (runs["rule"] == params["rule"])].sort_values("seed", ignore_index=True)
        what = f"{params['check']}, N = {params['n_disks']}, {params['rule']}"
        if g["seed"].tolist() != list(range(params["ics"])):
            raise ValueError(f"runs: {what} has not the seeds 0 .. {params['ics'] - 1}")
        if not (g["t_max"] == params["t_max"]).all():
            raise ValueError(f"runs: {what} has not t_max = {params['t_max']:g}")
        write_cached(path, params, g[list(RUNS_COLUMNS)])


def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    """The checks' table (columns `FTLE_CHECK_COLUMNS`) from the states' exponents."""
    from kicktimes.stats import paired_ratio, ratio_verdict

    rows = []
    for (check, n, rule), g in runs.groupby(["check", "n_disks", "rule"], sort=False,
                                            observed=True):
        idx = pd.MultiIndex.from_product([[0.0], g["seed"].to_numpy()], names=["radius", "ic"])
        _, overall = paired_ratio(pd.Series(g["numerator"].to_numpy(), index=idx),
                                  pd.Series(g["denominator"].to_numpy(), index=idx),
                                  rng=np.random.default_rng(20261127), n_boot=4000)
        margin = MARGINS[check]
        rows.append({
            "check": check, "n_disks": int(n), "rule": rule,
            "packing": PACKING if check == "tangent/twin" else round(2 * TWO_DISK_R ** 2, 12),
            "n_ics": len(g), "t_max": float(g["t_max"].iloc[0]),
            "estimate": overall["ratio"], "lo": overall["ci_low"], "hi": overall["ci_high"],
            "margin": margin,
            "verdict": ratio_verdict(overall["ci_low"], overall["ci_high"], tolerance=margin),
        })
    table = pd.DataFrame(rows, columns=list(FTLE_CHECK_COLUMNS))
    return table.sort_values(["check", "rule", "n_disks"], ascending=[False, False, True],
                             ignore_index=True)


def write_ftle_check(out, results_dir, check: FtleCheck = FTLE_CHECK, *, workers: int = 1,
                     progress=None) -> pd.DataFrame:
    """Run (or reuse from ``out``) the checks and write ``disks_ftle_check.csv`` and
    ``disks_ftle_check_runs.csv`` into ``results_dir``, each atomically.

    Parameters
    ----------
    out : path-like
        The study's work folder (the cache: ``out/ftle-check``).
    results_dir : path-like
        The disks page's folder.
    check, workers, progress :
        As in `ftle_check_runs`.

    Returns
    -------
    pandas.DataFrame
        The checks' table, as written.
    """
    runs = ftle_check_runs(out, check, workers=workers, progress=progress)
    table = summarise(runs)
    results = Path(results_dir)
    for name, frame in (("disks_ftle_check_runs", runs), ("disks_ftle_check", table)):
        atomic_write(results / f"{name}.csv", lambda tmp, f=frame: f.to_csv(tmp, index=False))
    return table
