"""Run (or resume) the tables study and write ``tables.md``: `reproduce`.

The study's work folder ``out`` holds one store per (table, collision rule)
(``store-tables_<table>[-elastic]``, resumable task by task, on a local pool or a Dask
cluster) and the free disk's tables (``cache-tables/free_disk.parquet``,
``focal_drift.parquet``, with their parameters beside them).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

import pandas as pd

from kicktimes.render.pages import header, write_null_calibration
from kicktimes.report.process import build_stores_report
from kicktimes.studies.cache import cached_table
from kicktimes.studies.options import study_run
from kicktimes.studies.tables.compare import (
    against_circle,
    against_free,
    elastic_speeds,
    findings,
    mean_ftle,
    null_levels,
    per_ic,
)
from kicktimes.studies.tables.figures import tables_figure
from kicktimes.studies.tables.one_disk import POINT_RADIUS, focal_drift, free_ftle, free_runs
from kicktimes.studies.tables.page import SOURCES, answers, body
from kicktimes.studies.tables.sweep import RADII, RULES, SEED, TABLES, run_stores, tables_experiment

__all__ = ["SCALES", "TablesScale", "reproduce"]


@dataclass(frozen=True)
class TablesScale:
    """The sizes of one scale: ICs per (table, rule, radius), the paper's steps and step
    length per run (the free disk's horizon is ``n_steps * tau``), the free disk's states
    and the focal drift's states and wall contacts."""

    n_ics: int
    n_steps: int
    tau: float
    free_states: int
    drift_states: int
    drift_bounces: int


#: ``paper``: the sizes of docs/results/tables.md (200 ICs per radius, the paper's family A:
#: 25000 collision-truncated steps of 0.2); ``quick``: a pipeline check
SCALES = {
    "paper": TablesScale(200, 25000, 0.2, 200, 50, 10_000),
    "quick": TablesScale(6, 1500, 0.2, 10, 4, 1000),
}


def reproduce(out: str | os.PathLike, *, scale: str = "quick", results_dir=None,
              workers: int = 1, progress=None, command: str | None = None,
              scheduler: str | None = None):
    """Run (or resume) the tables study in ``out`` and write ``tables.md``.

    Parameters
    ----------
    out : path-like
        The study's work folder: the stores and the free disk's cached tables.
    scale : {"quick", "paper"}
        ``"paper"``: the sizes of docs/results/tables.md (`SCALES`); ``"quick"``: a small
        version (seconds, after compilation).
    results_dir, workers, progress, command
        As every study's (`kicktimes.studies.options`).
    scheduler : str, optional
        A Dask distributed scheduler's address: the sweep's tasks run there.

    Returns
    -------
    pathlib.Path
        The page, ``results_dir/tables.md``.

    Examples
    --------
    >>> reproduce("unused", scale="huge")
    Traceback (most recent call last):
    ...
    ValueError: scale must be one of 'paper', 'quick', got 'huge'
    """
    run = study_run("tables", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    sizes = run.params
    # the free disk's horizon: the paper's n_steps tau (its collision-truncated runs cover
    # somewhat less)
    horizon = sizes.n_steps * sizes.tau
    t0 = time.perf_counter()
    run.cache.mkdir(parents=True, exist_ok=True)
    run.results.mkdir(parents=True, exist_ok=True)
    experiments = {(t, rule): tables_experiment(t, rule, n_ics=sizes.n_ics,
                                                n_steps=sizes.n_steps, tau=sizes.tau)
                   for t in TABLES for rule in RULES}
    named = run_stores(out, experiments.values(), workers=run.workers, scheduler=scheduler,
                       say=run.say)
    stores = {key: named[exp.name] for key, exp in experiments.items()}
    run.say(f"sweep done at {time.perf_counter() - t0:.0f} s")
    report_dir = run.cache / "report"
    # a report built by an older kicktimes may lack a table this study reads: rebuild it
    needed = [report_dir / f"{exp.name}_{part}.csv" for exp in experiments.values()
              for part in ("findings", "findings_by_radius", "poisson_tests",
                           "null_calibration")]
    build_stores_report([store.path for store in stores.values()], report_dir,
                        workers=run.workers, force=not all(p.is_file() for p in needed))
    run.say(f"sweep report done at {time.perf_counter() - t0:.0f} s")
    params = {"radii": list(RADII), "tables": [repr(t) for t in TABLES.values()],
              "point": POINT_RADIUS, "states": sizes.free_states, "horizon": horizon,
              "seed": SEED}

    def free_states():
        # every table at the sweep's radii, and the stadium's point particle
        return pd.concat([
            free_runs(TABLES, RADII, n_states=sizes.free_states, horizon=horizon,
                      seed=SEED),
            free_runs({"stadium": TABLES["stadium"]}, [POINT_RADIUS],
                      n_states=sizes.free_states, horizon=horizon, seed=SEED + 1)],
            ignore_index=True)

    free_states = cached_table(run.cache / "free_disk.parquet", params, free_states,
                               progress=run.say).table
    free = free_ftle(free_states, horizon=horizon, seed=SEED)
    params = {"radii": [POINT_RADIUS, *RADII], "table": repr(TABLES["ellipse"]),
              "states": sizes.drift_states, "bounces": sizes.drift_bounces, "seed": SEED}
    drift = cached_table(run.cache / "focal_drift.parquet", params, lambda: focal_drift(
        TABLES["ellipse"], (POINT_RADIUS, *RADII), n_states=sizes.drift_states,
        n_bounces=sizes.drift_bounces, seed=SEED), progress=run.say).table

    found, curves = findings(report_dir, stores)
    runs = per_ic(stores)
    against = against_circle(runs)
    free_ratio = against_free(runs, free_states)
    means = mean_ftle(runs)
    by_radius = mean_ftle(runs, per_radius=True)
    speeds = elastic_speeds(stores)
    levels = null_levels(report_dir, stores)
    for name, frame in (("findings", found), ("findings_by_radius", curves),
                        ("against_circle", against), ("against_free", free_ratio),
                        ("ftle", means), ("ftle_by_radius", by_radius), ("free_disk", free),
                        ("focal_drift", drift), ("elastic_speeds", speeds)):
        run.write_csv(f"tables_{name}.csv", frame)
    write_null_calibration(run.results, "tables",
                           levels.drop(columns=["table", "rule"]))
    run.write_figure("tables.png", tables_figure(curves, by_radius, free))
    lines = header(
        "The paper's comparison in the circle, the ellipse and the stadium", run.command,
        ["the sweep's stores " + ", ".join(f"`{exp.name}`" for exp in experiments.values()),
         f"the free disk's runs (`kicktimes.studies.tables.one_disk`, cached in "
         f"`{run.cache.name}`)"])
    lines += answers(found, against, free_ratio, free, levels, curves,
                     n_ics=sizes.n_ics) + [""]
    lines += body(found, means, free, drift, speeds, n_ics=sizes.n_ics, horizon=horizon,
                  radii=RADII)
    run.say(f"page at {time.perf_counter() - t0:.0f} s")
    return run.write_page(lines, SOURCES)
