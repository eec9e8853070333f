"""Run (or resume) the small-r study and write ``small_r.md``: `reproduce`.

The study's work folder ``out`` holds the sweep's stores (``store-small_r-<rule>-r<r>``,
resumable task by task, on a local pool or a Dask cluster) and the theory's table
(``cache-small_r/theory.parquet``, with its parameters beside it, reused by a rerun with
the same sizes).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

from kicktimes.render.pages import header
from kicktimes.studies.cache import cached_table
from kicktimes.studies.options import study_run
from kicktimes.studies.small_r.figures import small_r_figure
from kicktimes.studies.small_r.page import SOURCES, answers, body
from kicktimes.studies.small_r.sweep import control_experiments, run_sweep, seconds_per_ic
from kicktimes.studies.small_r.tables import (
    against_theory,
    control_runs,
    findings,
    measured,
    per_ic,
    rate_check,
    ratio_table,
    slopes,
    theory_table,
)

__all__ = ["RULES", "SCALES", "SmallRScale", "reproduce"]

RULES = ("mirror", "elastic")


@dataclass(frozen=True)
class SmallRScale:
    """The sizes of one scale: the radii, the ICs per radius and rule, the collisions per
    IC (``collisions``, the horizon ``collisions / kinetic_rate(r)``), the theory's
    chains per rule ``(n_chains, n_steps, burn_in)`` and the radius of the controls'
    stores (`kicktimes.studies.small_r.sweep.CONTROL_STORES`)."""

    radii: tuple
    n_ics: int
    collisions: int
    chains: dict
    control_radius: float


#: ``paper``: the sizes of docs/results/small_r.md (six radii 1e-4..3e-2, 100 ICs, 10^4
#: collisions per IC; the elastic chains are many and short because the elastic rule
#: conserves the pair's angular momentum, so each chain keeps its start's);
#: ``quick``: seconds
SCALES = {
    "paper": SmallRScale((1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2), 100, 10_000,
                         {"mirror": (400, 1000, 100), "elastic": (2000, 200, 50)}, 1e-3),
    "quick": SmallRScale((1e-3, 1e-2), 4, 500,
                         {"mirror": (20, 200, 20), "elastic": (40, 100, 20)}, 1e-3),
}


def reproduce(out: str | os.PathLike, *, scale: str = "quick", results_dir=None,
              workers: int = 1, progress=None, command: str | None = None,
              scheduler: str | None = None):
    """Run (or resume) the small-r study in ``out`` and write ``small_r.md``.

    Parameters
    ----------
    out : path-like
        The study's work folder: the sweep's stores and the theory's cached table.
    scale : {"quick", "paper"}
        ``"paper"``: the sizes of docs/results/small_r.md (`SCALES`; about 70 CPU-minutes
        for the sweep, most of it at r = 1e-4, and 8 for the theory); ``"quick"``: a
        small version (about a minute).
    results_dir, workers, progress, command
        As every study's (`kicktimes.studies.options`).
    scheduler : str, optional
        A Dask distributed scheduler's address: the sweep's tasks run there.

    Returns
    -------
    pathlib.Path
        The page, ``results_dir/small_r.md``.

    Examples
    --------
    >>> reproduce("unused", scale="huge")
    Traceback (most recent call last):
    ...
    ValueError: scale must be one of 'paper', 'quick', got 'huge'
    """
    run = study_run("small_r", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    sizes = run.params
    t0 = time.perf_counter()
    run.cache.mkdir(parents=True, exist_ok=True)
    run.results.mkdir(parents=True, exist_ok=True)
    collisions = dict.fromkeys(sizes.radii, sizes.collisions)
    controls = control_experiments(sizes.n_ics, sizes.collisions, radius=sizes.control_radius)
    stores, _ = run_sweep(out, collisions, RULES, n_ics=sizes.n_ics, workers=run.workers,
                          scheduler=scheduler, controls=controls, say=run.say)
    extra = stores.pop("controls")
    run.say(f"sweep done at {time.perf_counter() - t0:.0f} s")
    params = {"radii": list(sizes.radii), "rules": list(RULES),
              "chains": {k: list(v) for k, v in sizes.chains.items()}, "seed": 62}
    theory = cached_table(run.cache / "theory.parquet", params, lambda: theory_table(
        sizes.radii, RULES, chains=sizes.chains, rng=62), progress=run.say).table
    run.say(f"theory done at {time.perf_counter() - t0:.0f} s")

    runs = per_ic(stores)
    meas = measured(runs)
    compare = against_theory(meas, theory)
    ratios = ratio_table(meas, theory)
    robust = findings(runs, control_runs(extra))
    slope = slopes(runs)
    rates = rate_check(runs)
    seed_runs = control_runs(extra)
    seed_runs = seed_runs[seed_runs["control"] == "seed"].drop(columns="control")
    rep_meas = measured(seed_runs)
    replicate = against_theory(rep_meas, theory).merge(
        rep_meas[["rule", "system", "radius", "ratio", "ratio_ci_low", "ratio_ci_high"]],
        on=["rule", "system", "radius"]).merge(
        rate_check(seed_runs)[["rule", "radius", "count_over_kinetic", "ci_low", "ci_high"]]
        .rename(columns={"ci_low": "count_ci_low", "ci_high": "count_ci_high"}),
        on=["rule", "radius"])
    cost = seconds_per_ic(stores)
    for name, frame in (("measured", meas), ("theory", theory), ("against_theory", compare),
                        ("ratios", ratios), ("findings", robust), ("slopes", slope),
                        ("rate_check", rates), ("seed_replicate", replicate), ("cost", cost)):
        run.write_csv(f"small_r_{name}.csv", frame)
    run.write_figure("small_r.png", small_r_figure(meas, compare, ratios))

    smallest = min(sizes.radii)
    lines = header(
        "The paper's premise at its limit r → 0: kicked disk against two disks",
        run.command,
        ["the sweep's stores " + ", ".join(f"`{s.experiment.name}`" for s in stores.values())
         + ", the controls' " + ", ".join(f"`{s.experiment.name}`" for s in extra.values()),
         "the low-density theory (`kicktimes.diagnostics.low_density`, cached in "
         f"`{run.cache.name}`)"])
    lines += answers(ratios, compare, robust, slope, theory, smallest, replicate) + [""]
    lines += body(meas, theory, compare, ratios, robust, rates, replicate, cost,
                  n_ics=sizes.n_ics, collisions=sizes.collisions)
    run.say(f"page at {time.perf_counter() - t0:.0f} s")
    return run.write_page(lines, SOURCES)
