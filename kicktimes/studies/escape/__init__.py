"""Escape through a hole (``kicktimes reproduce --study escape``): does the kicked disk
escape at the two-disk rate, and could the comparison tell kick laws apart at all?

For each radius of `RADII`, the same paper ICs run with one hole of half-width 0.05 rad in
the wall (`compute.escape_times`):

* ``two_particle``: the two disks. The run ends at the first escape, so disk 0's escape
  is censored by disk 1's (competing risks). Two estimators of the per-disk rate: disk 0's
  cause-specific rate, and the rate pooled over both exchangeable disks (events over
  twice the time at risk); a verdict is given only where both give it;
* ``poisson``, ``poisson_scatter``: disk 0 alone, kicked at Poisson times at the kinetic
  rate Γ(r), with uniform new directions (the paper's kick) or scattering kicks;
* negative controls, which a comparison able to tell escape laws apart must find
  different: a hole of half the width, and uniform kicks at the same mean rate Γ(r) from a
  stationary gamma renewal process of shape 0.1 (bursty);
* ``free``: disk 0 alone, never kicked (the integrable circle).

The escape rate γ is the exponential tail rate beyond ``t_min``: escapes after ``t_min``
over the time the runs alive there spend beyond it,

.. math:: \\gamma = \\frac{\\#\\{i : t_{\\min} < T_i \\le t_{\\max}\\}}
                         {\\sum_i (\\min(T_i, t_{\\max}) - t_{\\min})_+},

and each kicked / two-disk ratio of γ has a 95 % interval from a bootstrap over ICs,
paired across systems, and the verdict `kicktimes.stats.ratio_verdict` with the 10 %
margin. Each γ is also set against the ergodic rate of the hole alone,
:math:`2h / (\\pi^2 (1 - r))`, and the free disk's t S(t), on invariant-measure ICs,
against Bunimovich & Dettmann's constant C of the circle
(`kicktimes.stats.circle_escape_constant`).

The page ``escape.md`` goes into ``results_dir`` with ``escape/escape_tails.csv``,
``escape/escape_ratios.csv``, ``escape/escape_constant.csv``,
``escape/escape_over_radii.csv`` (each ratio over the radii, `compute.over_radii`),
``escape/escape_alpha.csv`` (α under both IC samples, `compute.alpha_table`) and
``escape/escape_survival.png``; the escape times per IC are cached in ``out``, one table
per radius (`compute.escape_times`, `compute.free_disk_escapes`).

The constant C and the tail law t S(t) -> C are Bunimovich & Dettmann's (Phys. Rev. Lett.
94, 100201, 2005; the reference of `kicktimes.stats.circle_escape_constant`).

Examples
--------
>>> from kicktimes.studies.escape import SCALES, ergodic_rate
>>> SCALES["paper"].n_ics, SCALES["paper"].n_free
(4000, 40000)
>>> round(ergodic_rate(0.01), 5)
0.01023

``reproduce("work", scale="quick")`` writes ``work/results-escape/escape.md`` in well
under a minute on one core.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kicktimes.studies.cache import cached_tables
from kicktimes.studies.escape.compute import (
    BURSTY_SHAPE,
    FREE_TIMES,
    HOLE,
    RADII,
    SMALL_HOLE,
    alpha_table,
    bootstrap_picks,
    constant_rows,
    ergodic_rate,
    escape_tables,
    escape_times,
    free_disk_escapes,
    over_radii,
    tail_rates,
)
from kicktimes.studies.escape.figures import survival_figure
from kicktimes.studies.escape.page import (
    ALPHA,
    CONSTANT,
    FIGURE,
    OVER_RADII,
    RATIOS,
    SOURCES,
    TAILS,
    write_page,
)
from kicktimes.studies.options import study_run

__all__ = [
    "SCALES", "Params", "alpha_table", "constant_rows", "ergodic_rate", "escape_tables",
    "escape_times", "free_disk_escapes", "over_radii", "reproduce", "survival_figure",
    "tail_rates", "write_page",
]


@dataclass(frozen=True)
class Params:
    """The escape study's sizes: ``n_ics`` paper ICs per radius run to ``t_max``, tail
    fits beyond ``t_min``, ``n_free`` invariant-measure ICs per radius for the free disk's
    constant, every draw from ``seed``."""

    n_ics: int
    t_max: float
    t_min: float
    n_free: int
    seed: int = 11


#: ``paper``: the sizes of docs/results/escape.md; ``quick``: 400 ICs, 2000 free-disk ICs
SCALES = {"quick": Params(n_ics=400, t_max=3000.0, t_min=50.0, n_free=2000),
          "paper": Params(n_ics=4000, t_max=3000.0, t_min=50.0, n_free=40000)}


def _escape_times(r, n_ics, t_max, seed):
    from kicktimes import initial_conditions

    ics = initial_conditions(n_ics, max(RADII), rng=seed)
    return escape_times(r, ics, t_max, seed)


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1,
              progress=None, command: str | None = None) -> Path:
    """Run (or reuse) the escape simulations in ``out`` and write ``escape.md``; returns its path.

    The escape times per IC are cached in ``out/cache-escape``, one table per radius.
    ``scale="paper"``: 4000 ICs per radius to t = 3000, 40 000 free-disk ICs per radius;
    ``"quick"``: 400 and 2000. The page comes with its folder ``escape/``; ``workers``
    run one radius at a time each. The other options are every study's
    (`kicktimes.studies.options`).
    """
    run = study_run("escape", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    params, cache = run.params, run.cache
    start = time.perf_counter()
    geometry = {"hole": HOLE, "small_hole": SMALL_HOLE, "bursty_shape": BURSTY_SHAPE}
    free_t_max = max(params.t_max, 3000.0)
    jobs = [(cache / f"escape_times_r{r:g}.parquet",
             {"radius": r, "n_ics": params.n_ics, "t_max": params.t_max,
              "seed": params.seed, **geometry},
             _escape_times, (r, params.n_ics, params.t_max, params.seed)) for r in RADII]
    jobs += [(cache / f"free_escapes_r{r:g}.parquet",
              {"radius": r, "n_free": params.n_free, "t_max": free_t_max,
               "seed": params.seed, "hole": HOLE},
              free_disk_escapes, (r, params.n_free, free_t_max, params.seed)) for r in RADII]
    cached = cached_tables(jobs, workers=run.workers, progress=progress)
    times = {r: c.table for r, c in zip(RADII, cached[:len(RADII)], strict=True)}
    picks = bootstrap_picks(params.n_ics, params.seed)
    table, ratio_tab, curves = escape_tables(times, params.t_max, params.t_min, picks)
    summary = over_radii(times, params.t_max, params.t_min, picks)
    constant = pd.DataFrame([row for r, c in zip(RADII, cached[len(RADII):], strict=True)
                             for row in constant_rows(r, c.table["escape_time"], FREE_TIMES)])
    alpha = alpha_table(table, constant, params.t_min, params.t_max)
    for name, frame in ((TAILS, table), (RATIOS, ratio_tab), (CONSTANT, constant),
                        (OVER_RADII, summary), (ALPHA, alpha)):
        run.write_csv(name, frame)
    run.write_figure(FIGURE, survival_figure(curves))
    # the build's seconds: this call's and those the reused simulations took when they ran
    seconds = time.perf_counter() - start + sum(c.seconds for c in cached if c.reused)
    return run.write_page(write_page(table, ratio_tab, constant, params, run.command, seconds,
                                     cache.name, summary=summary, alpha=alpha, curves=curves),
                          SOURCES)
