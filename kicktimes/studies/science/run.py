"""Run (or resume) the science study and write ``science.md``: `reproduce`.

The study's work folder ``out`` caches what is expensive: the FTLE sweep is a kicktimes
store (``store-<sweep name>``, resumable task by task), the twins and the decorrelation
runs are parquet tables with their parameters beside them
(`kicktimes.studies.cache`); a rerun with the same parameters reuses them and recomputes
the statistics, the figure and the page. The paper study's stores and findings tables are
read, never written.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kicktimes.experiment import load_store
from kicktimes.render.pages import header, store_name, write_results_page
from kicktimes.studies.cache import cached_table, read_cached, study_store, write_cached
from kicktimes.studies.options import check_scale, check_workers, status_lines
from kicktimes.studies.science.decorrelation import (
    closest_kick_law,
    decorrelation,
    prediction_against_measurement,
)
from kicktimes.studies.science.figures import stretching_figure
from kicktimes.studies.science.page import (
    SOURCES,
    decorrelation_lines,
    first_screen,
    reading,
    store_lines,
    stretching_lines,
    twin_lines,
)
from kicktimes.studies.science.rates import rate_relaxation, sticky_orbits
from kicktimes.studies.science.stretching import (
    N_BOOT,
    SMALL_RADII,
    stretching,
    stretching_experiment,
)
from kicktimes.studies.science.twins import twin_table, twins_raw

__all__ = ["SCALES", "ScienceScale", "reproduce"]


@dataclass(frozen=True)
class ScienceScale:
    """The sizes of one scale of the study.

    ``sweep``: the FTLE sweep's name; ``radii``, ``n_ics``, ``n_steps`` its radii, ICs and
    steps (``None``: family A's 25000); ``twin_*``: the independent-angle twins (radii,
    ICs, steps of tau); ``decorrelation_*``: the single-perturbation runs (radii, ICs,
    run time). The twins' radii must be among the sweep's, the decorrelation radii among
    the radii of the paper study's findings.
    """

    sweep: str
    radii: tuple
    n_ics: int
    n_steps: int | None
    twin_radii: tuple
    twin_ics: int
    twin_steps: int
    decorrelation_radii: tuple
    decorrelation_ics: int
    decorrelation_t_max: float


#: ``paper``: the sizes of docs/results/science.md; ``quick``: seconds (on the quick stores)
SCALES = {
    "paper": ScienceScale("stretching_small_r", SMALL_RADII, 100, None, (0.008, 0.02), 40,
                          3000, (0.008, 0.02), 40, 20000.0),
    "quick": ScienceScale("stretching_small_r-quick", (0.014, 0.02, 0.03), 8, 1000, (0.02,),
                          2, 150, (0.008, 0.02), 4, 2000.0),
}
#: the paper study's stores read, by the scale they come from (a quick run takes either)
STORES = {"paper": ("family",), "quick": ("quick", "family")}
RULES = {"mirror": "", "elastic": "-elastic"}
DECORRELATION = ("decorrelation", "decorrelation_by_angle", "decorrelation_predicted")


def _paper_command(scale):
    return f"kicktimes reproduce --study paper --scale {scale} --out OUT"


def find_stores(stores_dir, scale) -> list[Path]:
    """The paper study's stores of families A and B in ``stores_dir``.

    At ``scale="paper"`` they are ``store-family_a`` and ``store-family_b``; at
    ``"quick"`` the quick stores ``store-quick_a``, ``store-quick_b`` or, where those are
    missing, the paper-scale ones.
    """
    found = []
    for letter in "ab":
        names = [f"store-{kind}_{letter}" for kind in STORES[scale]]
        hit = next((Path(stores_dir) / n for n in names
                    if (Path(stores_dir) / n / "manifest.json").is_file()), None)
        if hit is None:
            source = "paper" if scale == "paper" else "quick"
            raise ValueError(
                f"stores_dir: {' or '.join(str(Path(stores_dir) / n) for n in names)} is "
                f"missing; the paper study makes it: `{_paper_command(source)}` (then "
                "stores_dir=OUT)")
        found.append(hit)
    return found


def findings_families(findings_dir, names, scale):
    """``(rules, closest)``: the family whose by-radius findings give the measured 1 - R1
    per collision rule, and the families whose pooled findings `closest_kick_law` reads.

    The elastic rule's tables (``<family>-elastic``, the paper study's control stores) are
    required at ``scale="paper"`` and used at ``"quick"`` where they are there.
    """
    folder = Path(findings_dir)
    source = "paper" if names[0].startswith("family") else "quick"

    def need(name):
        if not (folder / name).is_file():
            raise ValueError(
                f"findings_dir: {folder / name} is missing; the paper study writes it: "
                f"`{_paper_command(source)} --results DIR` (then findings_dir=DIR)")

    rules, closest = {}, []
    for rule, suffix in RULES.items():
        family = f"{names[0]}{suffix}"
        pair = [f"{n}{suffix}" for n in names]
        files = [f"{family}_findings_by_radius.csv"] + [f"{n}_findings.csv" for n in pair]
        if suffix and scale != "paper" and not all((folder / f).is_file() for f in files):
            continue
        for name in files:
            need(name)
        rules[rule] = family
        closest += pair
    # the pooled tables in the order of the page: both mirror families, then both elastic
    return rules, closest


def _sweep(exp, out, workers, say):
    """The FTLE sweep's store in ``out`` (`kicktimes.studies.cache.study_store`)."""
    return study_store(exp, out, workers=workers, say=say)[0]


def _decorrelation(out, rule, sizes, say):
    """The three decorrelation tables of one rule, from the cache or computed."""
    params = {"rule": rule, "radii": list(sizes.decorrelation_radii),
              "n_ics": sizes.decorrelation_ics, "t_max": sizes.decorrelation_t_max,
              "seed": 5, "n_boot": N_BOOT}
    paths = [Path(out) / f"science-{name}-{rule}.parquet" for name in DECORRELATION]
    found = [read_cached(p, params) for p in paths]
    if all(found):
        say(f"decorrelation, {rule} rule: reused")
        return [f.table for f in found], True
    start = time.perf_counter()
    tables = decorrelation(sizes.decorrelation_radii, rule=rule, n_ics=sizes.decorrelation_ics,
                           t_max=sizes.decorrelation_t_max)
    seconds = time.perf_counter() - start
    for path, table in zip(paths, tables, strict=True):
        write_cached(path, params, table, seconds)
    say(f"decorrelation, {rule} rule: computed in {seconds:.0f} s")
    return list(tables), False


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int = 1, progress=None,
              command: str | None = None, stores_dir: str | os.PathLike | None = None,
              findings_dir: str | os.PathLike | None = None) -> Path:
    """Run (or resume) the science study in ``out`` and write ``science.md``.

    Parameters
    ----------
    out : path-like
        The study's work folder: the FTLE sweep's store and the cached twin and
        decorrelation tables (each with its parameters; a rerun with the same parameters
        reuses them).
    scale : {"quick", "paper"}
        ``"paper"``: the sizes of docs/results/science.md (`SCALES`; from scratch about
        1.5 CPU-minutes, 6.5 minutes of wall on a busy 2-core machine, most of it the
        decorrelation runs; from the cache 27 s); ``"quick"``: a small version for trying
        it out (7 s on one core from the paper study's quick stores).
    results_dir : path-like, optional
        Where ``science.md``, its ``science_*.csv`` tables and its figure go (default
        ``out/results-science``).
    workers : int
        Processes of the FTLE sweep (1: in this process).
    progress : callable, optional
        Takes one line of text per step; ``None``: silent.
    command : str, optional
        The command the page's "Generated" line names (default
        ``kicktimes reproduce --study science --scale <scale>``).
    stores_dir : path-like, optional
        The folder of the paper study's stores ``store-family_a``, ``store-family_b`` (as
        ``kicktimes reproduce --study paper --scale paper --out OUT`` makes them; at
        ``scale="quick"`` also ``store-quick_a``, ``store-quick_b``, preferred there).
        Default ``out``.
    findings_dir : path-like, optional
        The folder of the paper study's findings tables of those stores and of their
        elastic controls (``family_a_findings.csv``, ``family_a_findings_by_radius.csv``,
        ``family_a-elastic_findings.csv``, ...; ``kicktimes reproduce --study paper
        --results DIR`` writes them). Default ``results_dir``.

    Returns
    -------
    pathlib.Path
        The page, ``results_dir/science.md``.

    Raises
    ------
    ValueError
        A bad ``scale`` or ``workers``, or a missing store or findings table (the
        message names the file and the command that makes it).
    """
    scale = check_scale(scale, SCALES)
    workers = check_workers(workers)
    sizes = SCALES[scale]
    out = Path(out)
    results = Path(results_dir) if results_dir is not None else out / "results-science"
    stores_dir = Path(stores_dir) if stores_dir is not None else out
    findings = Path(findings_dir) if findings_dir is not None else results
    command = command or f"kicktimes reproduce --study science --scale {scale}"
    say = status_lines(progress)
    paths = find_stores(stores_dir, scale)
    names = [store_name(p) for p in paths]
    families, closest_families = findings_families(findings, names, scale)
    out.mkdir(parents=True, exist_ok=True)
    results.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()

    exp = stretching_experiment(sizes.radii, sizes.n_ics, sizes.n_steps, name=sizes.sweep)
    store = _sweep(exp, out, workers, say)
    per_radius, fits, trend = stretching(store.results)
    per_radius.to_csv(results / "science_stretching.csv", index=False)
    fits.to_csv(results / "science_stretching_fits.csv", index=False)
    trend.to_csv(results / "science_stretching_trend.csv", index=False)
    stretching_figure(per_radius, results / "science_stretching.png")
    body = stretching_lines(exp, per_radius, fits, trend)
    say(f"stretching at {time.perf_counter() - t0:.0f} s")

    params = {"radii": list(sizes.twin_radii), "n_ics": sizes.twin_ics,
              "n_steps": sizes.twin_steps, "tau": exp.tau, "d0": exp.d0, "seed": 3}
    raw = cached_table(out / "science-twins.parquet", params, lambda: twins_raw(
        sizes.twin_radii, tau=exp.tau, d0=exp.d0, n_ics=sizes.twin_ics,
        n_steps=sizes.twin_steps), progress=say)
    twins = twin_table(raw.table, per_radius, tau=exp.tau, d0=exp.d0)
    twins.to_csv(results / "science_independent_twins.csv", index=False)
    body += twin_lines(twins, exp, n_ics=sizes.twin_ics, n_steps=sizes.twin_steps)
    say(f"twins at {time.perf_counter() - t0:.0f} s")

    parts = [_decorrelation(out, rule, sizes, say) for rule in families]
    reused = raw.reused and all(p[1] for p in parts)
    dec, bins, preds = (pd.concat([p[0][k] for p in parts], ignore_index=True)
                        for k in range(3))
    dec.to_csv(results / "science_decorrelation.csv", index=False)
    bins.to_csv(results / "science_decorrelation_by_angle.csv", index=False)
    compare = prediction_against_measurement(preds, findings, families)
    compare.to_csv(results / "science_decorrelation_prediction.csv", index=False)
    closest = closest_kick_law(findings, closest_families)
    closest.to_csv(results / "science_closest.csv", index=False)
    body += decorrelation_lines(dec, compare, closest, n_ics=sizes.decorrelation_ics,
                                t_max=sizes.decorrelation_t_max)
    say(f"decorrelation at {time.perf_counter() - t0:.0f} s")

    stores = [load_store(p) for p in paths]
    parts = [rate_relaxation(s) for s in stores]
    relax = pd.concat([p[0] for p in parts], ignore_index=True)
    whole = pd.concat([p[1] for p in parts], ignore_index=True)
    windows = pd.concat([p[2] for p in parts], ignore_index=True)
    windows.to_csv(results / "science_rate_windows.csv", index=False)
    relax.to_csv(results / "science_rate_relaxation.csv", index=False)
    whole.to_csv(results / "science_rate_count.csv", index=False)
    sticky = pd.DataFrame([sticky_orbits(s) for s in stores])
    sticky.to_csv(results / "science_sticky.csv", index=False)
    # the same without the sticky runs (the README's control of the counts)
    kept = [rate_relaxation(s, exclude_sticky=True) for s in stores]
    whole_kept = pd.concat([p[1] for p in kept], ignore_index=True)
    windows_kept = pd.concat([p[2] for p in kept], ignore_index=True)
    windows_kept.to_csv(results / "science_rate_windows_no_sticky.csv", index=False)
    whole_kept.to_csv(results / "science_rate_count_no_sticky.csv", index=False)
    body += store_lines(whole, windows, sticky,
                        n_ics={s.experiment.name: s.experiment.n_ics for s in stores},
                        kept=(whole_kept, windows_kept))

    lines = header(
        "Kicks against the two-disk system: stretching, decorrelation, collision rate",
        command,
        ["the stores " + ", ".join(f"`{n}`" for n in names)]
        + [f"the FTLE sweep `{exp.name}` (run here)",
           "the findings tables of " + ", ".join(f"`{f}`" for f in families.values()),
           "the direct simulations of sections 2–3"
           + (" (read from the study's cache of an earlier run)" if reused else "")])
    lines += first_screen(per_radius, trend, twins, compare, windows, whole,
                          n_ics=sizes.twin_ics, n_dec=sizes.decorrelation_ics,
                          windows_kept=windows_kept)
    lines += reading() + body + [f"Built in {time.perf_counter() - t0:.0f} s.", ""]
    page = write_results_page(results / "science.md", lines, SOURCES)
    say(f"{page.name} written in {time.perf_counter() - t0:.0f} s")
    return page
