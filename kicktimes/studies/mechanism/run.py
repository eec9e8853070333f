"""Run (or resume) the mechanism study under both collision rules and write its page.

Each rule is one computation (`run_rule`): its runs (a few seconds) and their analysis
(minutes: the Poisson battery on the twin ensembles) give ``mechanism_numbers.csv`` and
the figures. The study's work folder caches each rule's numbers (a parquet table with its
parameters beside it, `kicktimes.studies.cache`) and figures, in ``mechanism-<rule>/``; a
rerun with the same parameters reuses them and rewrites the tables, figures and page of
``results_dir`` from them. The runs themselves are not cached: simulating them again
takes less time than reading them.
"""

from __future__ import annotations

import math
import os
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.studies.cache import read_cached, write_cached
from kicktimes.studies.mechanism.analysis import (
    NULL_DRAWS,
    against_null,
    analyse,
    cell_rows,
    hazard_profile_rows,
    poisson_null_rows,
    state_rates,
)
from kicktimes.studies.mechanism.figures import write_figures
from kicktimes.studies.mechanism.page import load, write_page
from kicktimes.studies.mechanism.simulate import RADII, simulate
from kicktimes.studies.mechanism.twins import rate
from kicktimes.studies.options import check_scale, check_workers, status_lines

__all__ = ["CSV_NAMES", "FIGURES", "RULES", "SCALES", "MechanismScale", "public_names",
           "reproduce", "run_rule"]


@dataclass(frozen=True)
class MechanismScale:
    """The sizes of one scale: ICs per group, run time, twin ensembles per model, seed,
    and the resamples of the bootstrap intervals over ICs."""

    n_ics: int
    t_max: float
    twins: int
    seed: int = 29
    n_boot: int = 1000


#: ``paper``: the sizes of docs/results/mechanism.md; ``quick``: under a minute on one core
SCALES = {"paper": MechanismScale(200, 2000.0, 20),
          "quick": MechanismScale(16, 1000.0, 1, n_boot=100)}
#: each rule's folder, relative to the page
RULES = {"mirror": "mechanism", "elastic": "mechanism/elastic"}
FIGURES = ("hazard", "hazard_normalised", "recollisions", "impact", "rate_prediction",
           "survival", "battery", "state_rates")
NUMBERS = "mechanism_numbers.csv"


def run_rule(rule, sizes, folder, *, workers=1, progress=None) -> pd.DataFrame:
    """Simulate and analyse the four groups under ``rule``; write the figures
    (``mechanism_<name>.png``) into ``folder`` and return the numbers table."""
    say = status_lines(progress)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    groups = simulate(sizes.n_ics, sizes.t_max, workers, sizes.seed, rule)
    say(f"mechanism, {rule} rule: simulated {sum(len(v[1]) for v in groups.values())} runs "
        f"in {time.perf_counter() - t0:.0f} s")
    rng = np.random.default_rng(sizes.seed)
    rows, results = [], {}
    for key, (ics, runs) in groups.items():
        part, results[key] = analyse(key, ics, runs, n_twins=sizes.twins, rng=rng, rule=rule,
                                     n_boot=sizes.n_boot)
        rows += part
        say(f"mechanism, {rule} rule: analysed {key} at {time.perf_counter() - t0:.0f} s")
    rows += cell_rows(results, RADII)
    for name, value in (("n_ics", sizes.n_ics), ("t_max", sizes.t_max),
                        ("twins", sizes.twins), ("seed", sizes.seed)):
        rows.append({"method": "run", "radius": math.nan, "quantity": name,
                     "estimate": float(value), "ci_low": math.nan, "ci_high": math.nan,
                     "note": f"rule {rule}"})
    table = pd.DataFrame(rows)
    table.insert(0, "rule", rule)
    write_figures(results, folder, cells={r: state_rates(results, r) for r in RADII},
                  rate=rate)
    return table


def _cached_rule(out, rule, sizes, workers, say):
    """The numbers of ``rule`` and the folder of its figures, from the cache or run."""
    folder = Path(out) / f"mechanism-{rule}"
    path = folder / "mechanism_numbers.parquet"
    params = {"rule": rule, "n_ics": sizes.n_ics, "t_max": sizes.t_max,
              "twins": sizes.twins, "seed": sizes.seed, "n_boot": sizes.n_boot}
    found = read_cached(path, params)
    if found is not None and all((folder / f"mechanism_{n}.png").is_file() for n in FIGURES):
        say(f"mechanism, {rule} rule: reused")
        return found.table, folder
    path.with_suffix(".json").unlink(missing_ok=True)
    start = time.perf_counter()
    table = run_rule(rule, sizes, folder, workers=workers, progress=say)
    write_cached(path, params, table, time.perf_counter() - start)
    return table, folder


def _cached_profile(out, rule, sizes, workers, say):
    """The early hazard read bin by bin (`hazard_profile_rows`) of ``rule``'s four groups,
    from its own cache ``mechanism-<rule>/mechanism_hazard_profile.parquet`` or from the
    runs simulated again (seconds: no twins, no battery), beside the numbers' cache."""
    path = Path(out) / f"mechanism-{rule}" / "mechanism_hazard_profile.parquet"
    params = {"rule": rule, "n_ics": sizes.n_ics, "t_max": sizes.t_max, "seed": sizes.seed,
              "rows": "hazard_profile_rows"}
    found = read_cached(path, params)
    if found is not None:
        return found.table
    start = time.perf_counter()
    groups = simulate(sizes.n_ics, sizes.t_max, workers, sizes.seed, rule)
    rows = [row for key, (_, runs) in groups.items() for row in hazard_profile_rows(key, runs)]
    table = pd.DataFrame(rows)
    table.insert(0, "rule", rule)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_cached(path, params, table, time.perf_counter() - start)
    say(f"mechanism, {rule} rule: hazard profile in {time.perf_counter() - start:.0f} s")
    return table


#: the CSV's name of the index of dispersion of whole-run counts over ICs (analyse's
#: ``dispersion_index`` rows): a spread of rates between ICs, not the within-run D
CSV_NAMES = {"dispersion_index": "rate_dispersion_across_ics"}


def public_names(table):
    """``table`` with the quantities and notes of `CSV_NAMES` renamed as the CSV and the
    page name them (the cache keeps the names `analyse` wrote)."""
    table = table.copy()
    for old, new in CSV_NAMES.items():
        table["quantity"] = table["quantity"].str.replace(old, new, regex=False)
    table["note"] = (table["note"].fillna("")
                     .str.replace("index of dispersion", "rate dispersion across ICs",
                                  regex=False)
                     .str.replace(r"^first bin \[0, ([0-9.]+)\) of Gamma t$",
                                  r"hazard in [0, \1) of Γ-rescaled time", regex=True)
                     .str.replace(r"^first bin \[0, ([0-9.]+)\)$",
                                  r"hazard in [0, \1) time units after a collision",
                                  regex=True))
    return table


def _cached_null(out, rule, sizes, workers, say):
    """The Poisson nulls of the rate dispersion across ICs and of the early hazard
    (`poisson_null_rows`) of
    ``rule``'s four groups, from its own cache ``mechanism-<rule>/mechanism_null.parquet``
    or from the runs simulated again (seconds) and a Monte Carlo of Poisson ensembles."""
    path = Path(out) / f"mechanism-{rule}" / "mechanism_null.parquet"
    params = {"rule": rule, "n_ics": sizes.n_ics, "t_max": sizes.t_max, "seed": sizes.seed,
              "rows": "poisson_null_rows", "n_draws": NULL_DRAWS}
    found = read_cached(path, params)
    if found is not None:
        return found.table
    start = time.perf_counter()
    groups = simulate(sizes.n_ics, sizes.t_max, workers, sizes.seed, rule)
    rng = np.random.default_rng([sizes.seed, 60])
    rows = [row for key, (_, runs) in groups.items()
            for row in poisson_null_rows(key, runs, rng=rng)]
    table = pd.DataFrame(rows)
    table.insert(0, "rule", rule)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_cached(path, params, table, time.perf_counter() - start)
    say(f"mechanism, {rule} rule: Poisson nulls in "
        f"{time.perf_counter() - start:.0f} s")
    return table


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1, progress=None,
              command: str | None = None) -> Path:
    """Run (or resume) the mechanism study in ``out`` and write ``mechanism.md``.

    Parameters
    ----------
    out : path-like
        The study's work folder: per rule, ``mechanism-<rule>/`` caches the numbers (with
        their parameters) and the figures; a rerun with the same parameters reuses them.
    scale : {"quick", "paper"}
        ``"paper"``: the sizes of docs/results/mechanism.md (200 ICs per group, runs of
        2000, 20 twin ensembles per model, seed 29, 1000 bootstrap resamples; about 11
        CPU-minutes, 26 minutes of wall on a busy 2-core machine, 7 s from the cache);
        ``"quick"``: 16 ICs, runs of 1000, 1 twin ensemble, 100 resamples (under a
        minute on one core, most of it the figures), for trying it out.
    results_dir : path-like, optional
        Where the page goes (default ``out/results-mechanism``): ``mechanism.md``, and per
        rule its ``mechanism_numbers.csv`` and figures in ``mechanism/`` (mirror) and
        ``mechanism/elastic/``.
    workers : int
        Processes that simulate the runs (1: in this process); the analysis runs here.
    progress : callable, optional
        Takes one line of text per step; ``None``: silent.
    command : str, optional
        The command the page's "Generated" line names (default
        ``kicktimes reproduce --study mechanism --scale <scale>``).

    Returns
    -------
    pathlib.Path
        The page, ``results_dir/mechanism.md``.

    Raises
    ------
    ValueError
        A bad ``scale`` or ``workers``.
    """
    scale = check_scale(scale, SCALES)
    workers = check_workers(workers)
    sizes = SCALES[scale]
    out = Path(out)
    results = Path(results_dir) if results_dir is not None else out / "results-mechanism"
    command = command or f"kicktimes reproduce --study mechanism --scale {scale}"
    say = status_lines(progress)
    tables = []
    for rule, rel in RULES.items():
        table, cache = _cached_rule(out, rule, sizes, workers, say)
        table = pd.concat([public_names(table), _cached_profile(out, rule, sizes, workers, say),
                           _cached_null(out, rule, sizes, workers, say)], ignore_index=True)
        table = pd.concat([table, pd.DataFrame(against_null(table))],
                          ignore_index=True)
        target = results / rel
        target.mkdir(parents=True, exist_ok=True)
        table.to_csv(target / NUMBERS, index=False, float_format="%.6g")
        for name in FIGURES:
            shutil.copyfile(cache / f"mechanism_{name}.png", target / f"mechanism_{name}.png")
        # the page reads the table as written, as a reader of the CSV does
        tables.append(load(target))
    page = write_page(tables, list(RULES.values()), results / "mechanism.md", command=command)
    say(f"{page.name} written")
    return page
