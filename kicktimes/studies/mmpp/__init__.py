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
``mmpp/mmpp_billiard_residuals.csv`` and ``mmpp/mmpp_billiard_dip.csv``; the collision
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

from kicktimes.fileio import atomic_write
from kicktimes.studies.cache import cached_tables
from kicktimes.studies.mmpp.compute import RULES, collision_runs, sticky_runs
from kicktimes.studies.mmpp.page import write_page
from kicktimes.studies.mmpp.tables import analyse, battery, intervals, mmpp_dip
from kicktimes.studies.options import check_scale, check_workers

__all__ = ["RULES", "SCALES", "Params", "analyse", "battery", "collision_runs", "intervals",
           "mmpp_dip", "reproduce", "sticky_runs", "write_page"]


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

#: the page's tables, relative to the page
TABLES = ("mmpp/mmpp_billiard_pooled.csv", "mmpp/mmpp_billiard_residuals.csv",
          "mmpp/mmpp_billiard_dip.csv")


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1,
              progress=None, command: str | None = None) -> Path:
    """Run (or reuse) the collision times in ``out``, fit them and write ``mmpp.md``.

    Parameters
    ----------
    out : path-like
        The work folder: the collision times are cached in ``out/cache-mmpp``
        (``cache-mmpp-quick`` at the quick scale), one parquet table per rule with its
        parameters beside it; a rerun with the same parameters reuses them and refits.
    scale : {"quick", "paper"}
        ``paper``: the sizes of docs/results/mmpp.md (200 ICs per rule at r = 0.02 to
        t = 2000, 200 runs fitted alone); ``quick``: 40 ICs to t = 500, 10 alone.
    results_dir : path-like, optional
        Folder of the page ``mmpp.md`` and its folder ``mmpp/`` (default
        ``out/results-mmpp``).
    workers : int
        Processes for the simulations, one rule at a time each (the fits run here).
    progress : callable, optional
        Takes one line of text per step; ``None``: silent.
    command : str, optional
        The command the page's "Generated" line names (default
        ``kicktimes reproduce --study mmpp --scale SCALE``).

    Returns
    -------
    pathlib.Path
        The page.
    """
    check_scale(scale, SCALES)
    workers = check_workers(workers)
    params = SCALES[scale]
    say = progress or (lambda line: None)
    start = time.perf_counter()
    cache = Path(out) / ("cache-mmpp" if scale == "paper" else f"cache-mmpp-{scale}")
    results = Path(results_dir) if results_dir is not None else Path(out) / "results-mmpp"
    command = command or f"kicktimes reproduce --study mmpp --scale {scale}"
    jobs = [(cache / f"collisions_{rule}.parquet",
             {"rule": rule, "n_ics": params.n_ics, "radius": params.radius,
              "t_max": params.t_max, "seed": params.seed, "ic_method": "paper"},
             collision_runs, (rule, params.n_ics, params.radius, params.t_max, params.seed))
            for rule in RULES]
    cached = cached_tables(jobs, workers=workers, progress=progress)
    pooled, resid, dip = [], [], []
    for rule, c in zip(RULES, cached, strict=True):
        times = [np.asarray(t, float) for t in c.table["pp_times"]]
        sticky = sticky_runs(times, params.radius, params.t_max)
        p, r, d = analyse(rule, times, sticky, params.t_max, params.per_run, params.seed)
        pooled += p
        resid += r
        dip += d
        say(f"mmpp: {rule} rule fitted at {time.perf_counter() - start:.0f} s")
    tables = [pd.DataFrame(rows) for rows in (pooled, resid, dip)]
    for name, frame in zip(TABLES, tables, strict=True):
        atomic_write(results / name, lambda tmp, frame=frame: frame.to_csv(tmp, index=False))
    page = results / "mmpp.md"
    # the build's seconds: this call's and those the reused simulations took when they ran
    seconds = time.perf_counter() - start + sum(c.seconds for c in cached if c.reused)
    lines = write_page(*tables, params, command, seconds, cache.name)
    atomic_write(page, lambda tmp: Path(tmp).write_text("\n".join(lines), encoding="utf-8"))
    say(f"mmpp: {page} written")
    return page
