"""Run (or resume) the equation-of-state study and write ``eos.md``: `reproduce`.

One cached table per (packing, N): ``cache-eos/eos-p<phi>-n<N>.parquet``, its runs'
halves (`run_cell`), computed in a local process pool, resumed cell by cell.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes.render.pages import header, simulations_source
from kicktimes.studies.cache import cached_tables
from kicktimes.studies.eos.page import SOURCES, answers, body, eos_figure
from kicktimes.studies.eos.tables import (
    eos_table,
    finite_size,
    frequency_table,
    halves_table,
    pooled_table,
)
from kicktimes.studies.options import study_run

__all__ = ["PACKINGS", "SCALES", "EosScale", "reproduce", "run_cell"]

#: the packings of the check (issue 64): dilute to the dense fluid, below the
#: liquid-hexatic transition near 0.70
PACKINGS = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.65, 0.68)


@dataclass(frozen=True)
class EosScale:
    """The sizes of one scale: the packings, the numbers of disks (the first is the
    primary, the others its finite-size control), the independent states per cell, the
    collisions per disk discarded (``equilibrate``) and kept (``collisions``, in two
    halves) per state."""

    packings: tuple
    sizes: tuple
    states: int
    equilibrate: float
    collisions: float


#: ``paper``: docs/results/eos.md (about 20 CPU-minutes); ``quick``: seconds
SCALES = {
    "paper": EosScale(PACKINGS, (10_000, 1000), 8, 500.0, 4000.0),
    "quick": EosScale((0.1, 0.4, 0.65), (400, 100), 3, 50.0, 200.0),
}


def run_cell(packing: float, n: int, states: int, equilibrate: float, collisions: float,
             seed: int) -> pd.DataFrame:
    """Runs of ``n`` disks at area fraction ``packing`` in the periodic unit box, elastic
    rule: ``states`` independent initial states (`kicktimes.initial_state`, seeds
    ``seed + k``), each run for ``equilibrate`` collisions per disk (discarded), then for
    ``collisions`` per disk in two halves (`kicktimes.simulate_disks`).

    Returns one row per state and half: ``z`` (the collisional virial, `DisksRun.pressure`),
    ``frequency`` (collisions per disk per unit time), ``enskog`` (Enskog's frequency with
    the contact value of that half's own ``z``, `stats.contact_from_z`, at its ``kT``),
    ``kT``, ``n_pp``, ``seconds`` (CPU).
    """
    import kicktimes as kt
    from kicktimes import stats

    r = math.sqrt(packing / (math.pi * n))
    # time per collision per disk, from the reference's contact value (sets the horizons)
    g_ref = stats.contact_from_z(stats.kolafa_rottner_z(packing), packing)
    per_disk = 1.0 / stats.enskog_frequency(r, n, rule="elastic", area=1.0, contact=g_ref)
    rows = []
    for k in range(states):
        t0 = time.process_time()
        state = kt.initial_state(n, r, rng=seed + k, rule="elastic", box=1.0)
        state = kt.simulate_disks(state, r, t_max=equilibrate * per_disk, rule="elastic",
                                  box=1.0).final_state
        for half in (1, 2):
            run = kt.simulate_disks(state, r, t_max=0.5 * collisions * per_disk,
                                    rule="elastic", box=1.0)
            state = run.final_state
            z = run.pressure(blocks=4).z_virial
            enskog = stats.enskog_frequency(r, n, rule="elastic", area=1.0, kT=run.kT,
                                            contact=stats.contact_from_z(z, packing))
            rows.append({"packing": packing, "n": n, "state": k, "half": half, "z": z,
                         "frequency": run.collision_frequency, "enskog": enskog,
                         "kT": run.kT, "n_pp": run.n_pp,
                         "seconds": time.process_time() - t0})
            t0 = time.process_time()
    return pd.DataFrame(rows)


def reproduce(out: str | os.PathLike, *, scale: str = "quick", results_dir=None,
              workers: int = 1, progress=None, command: str | None = None):
    """Run (or resume) the equation-of-state study in ``out`` and write ``eos.md``.

    Parameters
    ----------
    out : path-like
        The study's work folder: one cached table per (packing, N).
    scale : {"quick", "paper"}
        ``"paper"``: the sizes of docs/results/eos.md (`SCALES`); ``"quick"``: a small
        version (seconds).
    results_dir, workers, progress, command
        As every study's (`kicktimes.studies.options`).

    Returns
    -------
    pathlib.Path
        The page, ``results_dir/eos.md``.

    Examples
    --------
    >>> reproduce("unused", scale="huge")
    Traceback (most recent call last):
    ...
    ValueError: scale must be one of 'paper', 'quick', got 'huge'
    """
    run = study_run("eos", out, scale=scale, scales=SCALES, results_dir=results_dir,
                    workers=workers, progress=progress, command=command)
    sizes = run.params
    t0 = time.perf_counter()
    run.cache.mkdir(parents=True, exist_ok=True)
    run.results.mkdir(parents=True, exist_ok=True)
    jobs = []
    for n in sizes.sizes:
        for phi in sizes.packings:
            seed = 64_000 + int(round(1000 * phi)) + 7 * n
            args = (phi, n, sizes.states, sizes.equilibrate, sizes.collisions, seed)
            params = dict(zip(("packing", "n", "states", "equilibrate", "collisions", "seed"),
                              args, strict=True))
            jobs.append((run.cache / f"eos-p{phi:g}-n{n}.parquet", params, run_cell, args))
    cells = cached_tables(jobs, workers=run.workers, progress=run.say)
    runs = pd.concat([c.table for c in cells], ignore_index=True)
    cpu = float(np.sum([c.table["seconds"].sum() for c in cells]))
    run.say(f"runs done at {time.perf_counter() - t0:.0f} s")

    primary = sizes.sizes[0]
    eos = eos_table(runs)
    freq = frequency_table(runs)
    size = finite_size(runs, primary)
    halves = halves_table(runs)
    pool = pooled_table(freq, size)
    for name, frame in (("eos", eos), ("frequency", freq), ("finite_size", size),
                        ("halves", halves), ("pooled", pool), ("runs", runs)):
        run.write_csv(f"eos_{name}.csv", frame)
    run.write_figure("eos.png", eos_figure(eos, freq, primary))
    lines = header("The N-disk engine's equation of state against the literature",
                   run.command, [simulations_source("eos", run.cache.name)])
    lines += answers(eos, freq, size, halves, pool, primary) + [""]
    lines += body(eos, freq, size, halves, pool, sizes, cpu, primary)
    return run.write_page(lines, SOURCES)
