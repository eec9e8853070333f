"""MMPP fits to the two-disk collision times (``kicktimes reproduce --study mmpp``), under
both collision rules, with their residuals.

docs/mmpp.md describes the Markov-modulated Poisson process and its fit; this study asks
what it says about the billiard's own collision times. Per collision rule (mirror,
elastic), paper ICs at r = ``radius`` run to ``t_max`` (`compute.collision_runs`); runs
faster than 5 Γ(r) (sticky) are left out and counted. Then (`tables.analyse`):

* **pooled**: one two-state MMPP (`kicktimes.stats.fit_mmpp`) and the Poisson process
  (one state) fitted to all runs as censored windows, against renewal models by AIC; the
  time-rescaled windows under each fit (`kicktimes.stats.mmpp_residuals`) through the
  Poisson battery (share of windows rejected at α = 0.05, Clopper-Pearson interval,
  `kicktimes.stats.rejection_verdict`);
* **per run**: the first ``per_run`` runs with at least 20 collisions, each fitted alone
  and rescaled by its own fit, the same battery;
* **the refractory dip**: the hazard of the next collision in [0, 0.5) after a collision
  over the pooled rate, observed (`kicktimes.stats.interval_hazard`) against the fitted
  MMPP's, exact from its interval law
  :math:`S(t) = \\pi_e e^{(Q - \\Lambda) t} 1`, :math:`\\pi_e = \\pi \\Lambda / \\pi \\Lambda 1`:
  the mean hazard :math:`(1 - S(d)) / \\int_0^d S` over the MMPP's mean rate, at least 1
  for any MMPP at t -> 0 (:math:`\\pi \\Lambda^2 1 / (\\pi \\Lambda 1)^2 \\ge 1`).

The page ``mmpp.md`` goes into ``results_dir`` with ``mmpp/mmpp_billiard_pooled.csv``,
``mmpp/mmpp_billiard_residuals.csv``, ``mmpp/mmpp_billiard_dip.csv``,
``mmpp/mmpp_billiard_choice.csv`` (per run: is the MMPP-2 AIC-best, against the run's
intervals shuffled, `tables.choice_rows`) and ``mmpp/mmpp_billiard_null.csv`` (each
residual check against windows simulated from its fit and fitted the same way,
`tables.null_rows`); the collision
times are cached in ``out``, one table per rule.

Examples
--------
>>> from kicktimes.studies.mmpp import SCALES, RULES
>>> RULES, SCALES["paper"].n_ics, SCALES["paper"].t_max
(('mirror', 'elastic'), 200, 2000.0)

``reproduce("work", scale="quick")`` writes ``work/results-mmpp/mmpp.md`` in well under a
minute on one core.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.studies.cache import cached_tables
from kicktimes.studies.mmpp.compute import RULES, collision_runs, sticky_runs
from kicktimes.studies.mmpp.page import SOURCES, TABLES, write_page
from kicktimes.studies.mmpp.tables import (
    CHOICE_COLUMNS,
    analyse,
    battery,
    choice_rows,
    intervals,
    mmpp_dip,
    null_rows,
)
from kicktimes.studies.options import study_run

__all__ = ["RULES", "SCALES", "Params", "analyse", "battery", "choice_rows", "collision_runs",
           "intervals", "mmpp_dip", "null_rows", "reproduce", "sticky_runs", "write_page"]


@dataclass(frozen=True)
class Params:
    """The MMPP study's sizes: ``n_ics`` paper ICs at ``radius`` per rule run to
    ``t_max``; ``per_run`` runs fitted alone; ICs and fits from ``seed`` (29 draws the
    mechanism study's paper-IC groups at r = 0.02)."""

    n_ics: int
    t_max: float
    per_run: int
    radius: float = 0.02
    seed: int = 29


#: ``paper``: the sizes of docs/results/mmpp.md; ``quick``: 40 ICs to t = 500, 10 per run
SCALES = {"quick": Params(n_ics=40, t_max=500.0, per_run=10),
          "paper": Params(n_ics=200, t_max=2000.0, per_run=200)}


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1,
              progress=None, command: str | None = None) -> Path:
    """Run (or reuse) the collision times in ``out``, fit them, write ``mmpp.md`` (returned).

    The collision times are cached in ``out/cache-mmpp``, one table per rule; a rerun
    refits them. ``scale="paper"``: 200 ICs per rule at r = 0.02 to t = 2000, 200 runs
    fitted alone; ``"quick"``: 40 ICs to t = 500, 10 alone. The page comes with its
    folder ``mmpp/``; ``workers`` simulate one rule at a time each (the fits run here).
    The other options are every study's (`kicktimes.studies.options`).
    """
    run = study_run("mmpp", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    params = run.params
    start = time.perf_counter()
    jobs = [(run.cache / f"collisions_{rule}.parquet",
             {"rule": rule, "n_ics": params.n_ics, "radius": params.radius,
              "t_max": params.t_max, "seed": params.seed, "ic_method": "paper"},
             collision_runs, (rule, params.n_ics, params.radius, params.t_max, params.seed))
            for rule in RULES]
    cached = cached_tables(jobs, workers=run.workers, progress=progress)
    parts = [[], [], [], [], []]   # pooled, resid, dip, choice, nulls
    for rule, c in zip(RULES, cached, strict=True):
        times = [np.asarray(t, float) for t in c.table["pp_times"]]
        sticky = sticky_runs(times, params.radius, params.t_max)
        for rows, new in zip(parts, analyse(rule, times, sticky, params.t_max, params.per_run,
                                            params.seed), strict=True):
            rows += new
        run.say(f"mmpp: {rule} rule fitted at {time.perf_counter() - start:.0f} s")
    tables = [pd.DataFrame(rows) for rows in parts]
    tables[3] = pd.DataFrame(parts[3], columns=list(CHOICE_COLUMNS))
    for name, frame in zip(TABLES, tables, strict=True):
        run.write_csv(name, frame)
    # the build's seconds: this call's and those the reused simulations took when they ran
    seconds = time.perf_counter() - start + sum(c.seconds for c in cached if c.reused)
    return run.write_page(write_page(*tables, params, run.command, seconds,
                                     run.cache.name), SOURCES)
