"""Scatter kicks against the two disks (``kicktimes reproduce --study scatter``): does a
disk kicked by scattering off a virtual partner reproduce the two-disk FTLE?

For each radius of family A and each of its first ICs (paper ICs drawn at r = 0.03, seed
1; the paper's collision-truncated steps of τ = 0.2 and its ``max(λ_x, λ_y)`` from exact
tangent-space exponents), `compute.scatter_runs` gives the FTLE of the two disks, of the
kicked disk under uniform kicks and under scattering kicks (at Poisson times at the
two-disk run's own rate, or at its actual collision times), and of the two disks with
the partner's deviation zeroed before every collision (`kernel.fresh_lam`, through the two-disk
driver's own event loop: the two-disk system as the scatter model sees it).

Per radius, each ratio of mean FTLE over ICs,
:math:`\\bar\\lambda_{\\rm num} / \\bar\\lambda_{\\rm den}`, has a 95 % bootstrap interval
over ICs (paired: the same resampled ICs for both means) and its
`kicktimes.stats.ratio_verdict` (10 % margin), without the sticky two-disk orbits
(exponent below a quarter of the radius's median) and, as the control, with them
(`tables.ratio_table`). The page ``scatter.md`` goes into ``results_dir`` with
``scatter_ratios.csv`` and ``scatter_over_radii.csv`` (each ratio over the radii, at the
10 % margin and at `tables.FINE_MARGIN`); the per-IC tables are cached in ``out``, one per radius.
Definitions and methods: docs/scatter.md.

Examples
--------
>>> from kicktimes.studies.scatter import RATIOS, SCALES
>>> SCALES["paper"].n_ics, SCALES["paper"].n_steps, len(SCALES["paper"].radii)
(40, 25000, 12)
>>> RATIOS[0]
('scatter', 'two', 'scatter kicks / two disks')

``reproduce("work", scale="quick")`` writes ``work/results-scatter/scatter.md`` in well
under a minute on one core.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kicktimes.studies.cache import cached_tables
from kicktimes.studies.options import study_run
from kicktimes.studies.scatter.compute import one_ic, scatter_runs, shape_rows
from kicktimes.studies.scatter.kernel import fresh_lam
from kicktimes.studies.scatter.page import OVER_RADII, SOURCES, TABLE, write_page
from kicktimes.studies.scatter.tables import (
    RATIOS,
    over_radii,
    ratio_table,
    sticky,
    summary_tables,
)

__all__ = ["RATIOS", "SCALES", "Params", "cache_jobs", "fresh_lam", "one_ic", "over_radii",
           "ratio_table", "reproduce", "scatter_runs", "shape_rows", "sticky",
           "summary_tables", "write_page"]

#: family A's radii (`kicktimes.experiment.preset("family_a")`)
FAMILY_A_RADII = (0.008, 0.01, 0.012, 0.014, 0.016, 0.018, 0.02, 0.022, 0.024, 0.026, 0.028,
                  0.03)


@dataclass(frozen=True)
class Params:
    """The scatter study's sizes: at each of ``radii``, the first ``n_ics`` ICs drawn at
    ``ic_radius`` (``ic_method``, ``ic_seed``), each run ``n_steps`` paper steps of
    ``tau``. The paper scale's are family A's (`kicktimes.experiment.preset`)."""

    n_ics: int
    n_steps: int
    radii: tuple = FAMILY_A_RADII
    tau: float = 0.2
    ic_radius: float = 0.03
    ic_seed: int = 1
    ic_method: str = "paper"


#: ``paper``: the sizes of docs/results/scatter.md; ``quick``: 4 ICs, 2000 steps
SCALES = {"quick": Params(n_ics=4, n_steps=2000), "paper": Params(n_ics=40, n_steps=25000)}


def cache_jobs(cache: str | os.PathLike, params: Params) -> list[tuple]:
    """The per-radius tables of ``params`` as `kicktimes.studies.cache.cached_tables` jobs:
    ``(path, parameters, scatter_runs, arguments)``, one per radius."""
    return [(Path(cache) / f"runs_r{r:g}.parquet",
             {"radius": r, "n_ics": params.n_ics, "n_steps": params.n_steps,
              "tau": params.tau, "ic_radius": params.ic_radius, "ic_seed": params.ic_seed,
              "ic_method": params.ic_method, "rule": "mirror", "sampling": "paper"},
             scatter_runs, (r, params.n_ics, params.n_steps, params.tau, params.ic_radius,
                            params.ic_seed, params.ic_method))
            for r in params.radii]


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1,
              progress=None, command: str | None = None) -> Path:
    """Run (or reuse) the per-IC FTLE table in ``out``, write ``scatter.md`` (returned).

    The per-IC tables are cached in ``out/cache-scatter``, one per radius.
    ``scale="paper"``: family A's 12 radii, its first 40 ICs, 25 000 steps of 0.2;
    ``"quick"``: 4 ICs, 2000 steps. The page comes with ``scatter_ratios.csv``;
    ``workers`` run one radius at a time each. The other options are every study's
    (`kicktimes.studies.options`).
    """
    run = study_run("scatter", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    cached = cached_tables(cache_jobs(run.cache, run.params), workers=run.workers,
                           progress=progress)
    df = pd.concat([c.table for c in cached], ignore_index=True)
    tab = ratio_table(df)
    over = over_radii(df)
    run.write_csv(TABLE, tab)
    run.write_csv(OVER_RADII, over)
    return run.write_page(write_page(df, tab, run.command, run.cache.name, over), SOURCES)
