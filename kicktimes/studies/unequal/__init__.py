"""Unequal disks (``kicktimes reproduce --study unequal``): how the collision statistics
and the kicked disk's agreement with the two disks change with the size ratio.

Disk 0 keeps r0 = 0.01; disk 1 has r1 = 0.01, 0.015, 0.025, 0.04 (size ratio 1 to 4). Per
ratio, invariant ICs of the pair (mirror rule) run ``n_steps`` steps of ``tau`` with the
tangent FTLE of each disk (`compute.size_ratio_runs`); `tables.size_ratio_table` gives

* the collision rate against the exact kinetic rate Γ(r0, r1), a ratio of means with a
  95 % bootstrap interval over ICs;
* the Poisson battery on each IC's collision times (the share rejecting uniformity, with
  its Clopper-Pearson interval) and the dispersion index of the counts,
  :math:`D = s_N^2 / \\bar N` (1 for a Poisson process), with a bootstrap interval;
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

from kicktimes.fileio import atomic_write
from kicktimes.studies.cache import cached_tables
from kicktimes.studies.options import check_scale, check_workers
from kicktimes.studies.unequal.compute import R0, R1, size_ratio_runs
from kicktimes.studies.unequal.figures import size_ratio_figure
from kicktimes.studies.unequal.page import FIGURE, TABLE, write_page
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
    """Run (or reuse) the size-ratio simulations in ``out`` and write ``unequal.md``.

    Parameters
    ----------
    out : path-like
        The work folder: the per-IC runs are cached in ``out/cache-unequal``
        (``cache-unequal-quick`` at the quick scale), one parquet table per size ratio
        with its parameters beside it; a rerun with the same parameters reuses them.
    scale : {"quick", "paper"}
        ``paper``: the sizes of docs/results/unequal.md (200 ICs per ratio, 10 000 steps
        of 0.3); ``quick``: 20 ICs, 2000 steps.
    results_dir : path-like, optional
        Folder of the page ``unequal.md`` and its folder ``size_ratio/`` (default
        ``out/results-unequal``).
    workers : int
        Processes for the simulations, one size ratio at a time each.
    progress : callable, optional
        Takes one line of text per step; ``None``: silent.
    command : str, optional
        The command the page's "Generated" line names (default
        ``kicktimes reproduce --study unequal --scale SCALE``).

    Returns
    -------
    pathlib.Path
        The page.
    """
    check_scale(scale, SCALES)
    workers = check_workers(workers)
    params = SCALES[scale]
    cache = Path(out) / ("cache-unequal" if scale == "paper" else f"cache-unequal-{scale}")
    results = Path(results_dir) if results_dir is not None else Path(out) / "results-unequal"
    command = command or f"kicktimes reproduce --study unequal --scale {scale}"
    jobs = [(cache / f"runs_r1_{r1:g}.parquet",
             {"r0": R0, "r1": r1, "n_ics": params.n_ics, "n_steps": params.n_steps,
              "tau": params.tau, "seed": params.seed, "rule": "mirror"},
             size_ratio_runs, (r1, params.n_ics, params.n_steps, params.tau, params.seed))
            for r1 in R1]
    cached = cached_tables(jobs, workers=workers, progress=progress)
    table = size_ratio_table({r1: c.table for r1, c in zip(R1, cached, strict=True)},
                             params.seed)
    atomic_write(results / TABLE, lambda tmp: table.to_csv(tmp, index=False))
    fig = size_ratio_figure(table, params.n_ics)
    atomic_write(results / FIGURE, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    page = results / "unequal.md"
    lines = write_page(table, params, command, cache.name)
    atomic_write(page, lambda tmp: Path(tmp).write_text("\n".join(lines), encoding="utf-8"))
    if progress is not None:
        progress(f"unequal: {page} written")
    return page
