"""Unequal disks (``kicktimes reproduce --study unequal``): how the collision statistics
and the kicked disk's agreement with the two disks change with the size ratio.

Disk 0 keeps r0 = 0.01; disk 1 has r1 = 0.01, 0.015, 0.025, 0.04 (size ratio 1 to 4). Per
ratio, invariant ICs of the pair (mirror rule) run ``n_steps`` steps of ``tau`` with the
tangent FTLE of each disk (`compute.size_ratio_runs`); `tables.size_ratio_table` gives

* the collision rate against the exact kinetic rate Γ(r0, r1), a ratio of means with a
  95 % bootstrap interval over ICs;
* the Poisson battery on each IC's collision times (the share rejecting uniformity, with
  its Clopper-Pearson interval) and the rate dispersion across ICs, var / mean of the
  whole-run counts over ICs :math:`s_N^2 / \\bar N` (near 1 for a Poisson process; not the
  within-run D of counts in windows, nor the D across tagged disks of ``disks.md``), with a
  bootstrap interval and read against the same statistic on Poisson counts;
* per disk, the FTLE of the disk alone with scattering kicks at Poisson times at its IC's
  own collision rate over its FTLE in the two-disk system,
  :math:`\\sum_i \\lambda^{\\rm kicked}_i / \\sum_i \\lambda^{\\rm two}_i`, with the other
  disk's radius as the scattering partner and, as the control, a partner of its own size
  (the same kick times and numbers: they differ only in the contact distance).

Every ratio gets its `kicktimes.stats.ratio_verdict` with the 10 % margin. The page
``unequal.md`` goes into ``results_dir`` with ``size_ratio/size_ratio.csv`` and
``size_ratio/size_ratio.png``; the per-IC runs are cached in ``out``, one table per ratio.
Definitions and methods: docs/unequal.md.

Examples
--------
>>> from kicktimes.studies.unequal import R1, SCALES
>>> [r1 / 0.01 for r1 in R1]
[1.0, 1.5, 2.5, 4.0]
>>> SCALES["paper"].n_ics, SCALES["paper"].n_steps
(200, 10000)

``reproduce("work", scale="quick")`` writes ``work/results-unequal/unequal.md`` in well
under a minute on one core.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from kicktimes.studies.cache import cached_tables
from kicktimes.studies.options import study_run
from kicktimes.studies.unequal.compute import R0, R1, size_ratio_runs
from kicktimes.studies.unequal.figures import size_ratio_figure
from kicktimes.studies.unequal.page import FIGURE, SOURCES, TABLE, write_page
from kicktimes.studies.unequal.tables import (
    dispersion_ci,
    ks_interval,
    ratio_ci,
    size_ratio_table,
)

__all__ = ["R0", "R1", "SCALES", "Params", "dispersion_ci", "ks_interval", "ratio_ci",
           "reproduce", "size_ratio_figure", "size_ratio_runs", "size_ratio_table",
           "write_page"]


@dataclass(frozen=True)
class Params:
    """The unequal-disks study's sizes: ``n_ics`` invariant ICs per size ratio, each run
    ``n_steps`` steps of ``tau``; ICs, kicks and bootstraps from ``seed``."""

    n_ics: int
    n_steps: int
    tau: float = 0.3
    seed: int = 5


#: ``paper``: the sizes of docs/results/unequal.md; ``quick``: 20 ICs, 2000 steps
SCALES = {"quick": Params(n_ics=20, n_steps=2000),
          "paper": Params(n_ics=200, n_steps=10000)}


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1,
              progress=None, command: str | None = None) -> Path:
    """Run (or reuse) the size-ratio runs in ``out``, write ``unequal.md`` (returned).

    The per-IC runs are cached in ``out/cache-unequal``, one table per size ratio.
    ``scale="paper"``: 200 ICs, 10 000 steps of 0.3; ``"quick"``: 20 ICs, 2000 steps.
    The page comes with its folder ``size_ratio/``; ``workers`` run one size ratio at a
    time each. The other options are every study's (`kicktimes.studies.options`).
    """
    run = study_run("unequal", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    params = run.params
    jobs = [(run.cache / f"runs_r1_{r1:g}.parquet",
             {"r0": R0, "r1": r1, "n_ics": params.n_ics, "n_steps": params.n_steps,
              "tau": params.tau, "seed": params.seed, "rule": "mirror"},
             size_ratio_runs, (r1, params.n_ics, params.n_steps, params.tau, params.seed))
            for r1 in R1]
    cached = cached_tables(jobs, workers=run.workers, progress=progress)
    table = size_ratio_table({r1: c.table for r1, c in zip(R1, cached, strict=True)},
                             params.seed)
    run.write_csv(TABLE, table)
    run.write_figure(FIGURE, size_ratio_figure(table, params.n_ics))
    return run.write_page(write_page(table, params, run.command, run.cache.name), SOURCES)
