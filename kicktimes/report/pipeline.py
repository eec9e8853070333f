r"""The report pipeline: load the stores, run every section module, write the page.

Each section is one module of :mod:`kicktimes.report` holding its computation, figure and
text; :data:`STAGES` lists them in page order, so adding a diagnostic means writing one
module and adding it here (and, for the Findings, to
:data:`kicktimes.report.findings.EFFECT_MODULES`).

A build is made of parts (one per experiment, the all-experiments figures, the page),
each cached under a key of what it depends on (:mod:`kicktimes.report._cache`): a rerun
with nothing changed writes nothing, and a store that gained a task rebuilds that
experiment's part and the page only. The parts to build run at the same time on the
process pool (each experiment's statistics, figures and files in one worker), so the
heavy statistics of both families overlap instead of following each other; inside a part,
the per-radius jobs (Poisson tests, started before the first section, and renewal fits)
and the figure rendering use a pool of their own, so that the larger family's work
spreads over every core once the smaller one is done.
"""

from __future__ import annotations

import html
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from contextlib import closing, contextmanager
from dataclasses import dataclass
from pathlib import Path

from kicktimes._old_keywords import old_keywords, pop_old, translator, warn_old
from kicktimes.memory import fewer_collections, keep_freed_memory
from kicktimes.render.html import (
    embed_figures,
    table_html,
    toc_item,
    write_outputs,
    write_page,
    write_table,
    write_text,
)
from kicktimes.report._cache import ReportCache, content_key, store_key
from kicktimes.report.context import Context, Mapper, Progress
from kicktimes.report.options import Render, Subsampling
from kicktimes.report.store import load_report_store, store_header
from kicktimes.validation import check_int, check_real

__all__ = ["build_report", "analyse", "STAGES"]  # noqa: F822 (STAGES: module __getattr__)


def _stages():
    # the section modules (matplotlib, scipy, statsmodels) are imported on first use, so
    # that a rebuild served from the cache does not pay for them
    from kicktimes.report import (
        autocorrelation,
        counts,
        escape,
        findings,
        heterogeneity,
        kick_times,
        lyapunov,
        mmpp,
        poisson,
        recurrence,
        renewal,
        summary,
        trajectories,
    )

    return (
        ("trajectories", trajectories),
        ("kick times", kick_times),
        ("counts", counts),
        ("diagnostic tables", summary),
        ("Lyapunov exponents", lyapunov),
        ("recurrence", recurrence),
        ("autocorrelation", autocorrelation),
        ("Poisson tests", poisson),
        ("renewal models", renewal),
        ("MMPP", mmpp),
        ("rate heterogeneity", heterogeneity),
        ("escape", escape),
        ("findings", findings),
    )


def n_stages() -> int:
    """The number of section stages per store (the length of the stage list)."""
    return len(_stages())


def __getattr__(name):
    # STAGES: (stage name, section module) in page order; every module has sections(ctx)
    if name == "STAGES":
        return _stages()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: the stages a control experiment needs (`write_results`): its findings table's rows come
#: from the store and from the Poisson tests
CONTROL_STAGES = ("Poisson tests", "findings")


def analyse(ctx, *, bar, timings, only=None):
    """Every section of one store: ``(findings section, other sections, notes)``.

    ``only``: the names of the stages to run (e.g. `CONTROL_STAGES`); the others are
    skipped (still counted on ``bar``)."""
    from kicktimes.report import findings

    secs, found = [], None
    stages = [(n, m) for n, m in _stages() if only is None or n in only]
    for _ in range(len(_stages()) - len(stages)):
        bar.advance()
    for _, module in stages:
        # jobs that need only the store (the Poisson tests) start on the pool now and run
        # while the sections before theirs are computed here
        if ctx.pstart is not None and hasattr(module, "start"):
            module.start(ctx)
    for stage, module in stages:
        bar.step(f"{ctx.exp.name}: {stage}")
        t0 = time.perf_counter()
        if module is findings:
            found = findings.section(ctx)
        else:
            secs += module.sections(ctx)
        timings.append((ctx.exp.name, stage, time.perf_counter() - t0))
        bar.advance()
    return found, secs, ctx.notes


def _preload():
    """Import the section modules (matplotlib, scipy, statsmodels: ~2 s) and load the
    Poisson tests' compiled kernels (exact KS law, Ljung-Box Q) once in this process, so
    that the part workers forked from it inherit them instead of each paying for them
    (only when something is to be built: a rebuild served from the cache stays light)."""
    import numpy as np

    from kicktimes.stats.iid_tests import ljung_box
    from kicktimes.stats.poisson import pomeranz_cdf

    _stages()
    pomeranz_cdf(10, 0.3)
    ljung_box(np.arange(12.0), 2)


@contextmanager
def _one_blas_thread():
    """BLAS on one thread while the report is built (and in the processes it forks).

    A report runs one process per core already. With OpenBLAS's default of a thread per
    core, its long sums (the pooled renewal fits' log-likelihoods) are split by thread
    count, so their last bits depended on the machine: on the paper's stores, 3 of 67
    files (the pooled fits' log-likelihoods, AIC and weights, 1 ulp of two Findings CIs)
    differed between 2 threads and 1. On one thread the files do not depend on the core
    count, at no measurable cost (``benchmarks/bench_startup.py``, section 3;
    docs/benchmarks.md). The limit applies to the BLAS
    libraries loaded when it is set, so the section modules (numpy's and scipy's BLAS)
    are imported first; the previous limits are restored on exit.
    """
    from threadpoolctl import threadpool_limits

    _stages()
    with threadpool_limits(limits=1, user_api="blas"):
        yield


def _inner_workers(workers, manifests):
    """Processes of each part's own pools when the parts run in parallel.

    As wide as the machine when the parts are unequal (the paper's family B has 2.5x the
    samples of A): when the small part is done, its core takes the large one's jobs
    instead of idling. When the parts are about equal (within 2x) and at least as many as
    the workers, every core already has a part, and the pools would only add processes
    (16 for the quick report instead of 2), each fork of a part worker costing CPU
    (copy-on-write of its heap), which made the quick report slower
    (benchmarks/bench_report.py, section 4; docs/benchmarks.md). The results do not
    depend on it.
    """
    work = [
        len(m["experiment"]["radii"]) * m["experiment"]["n_ics"] * m["experiment"]["n_steps"]
        for m in manifests
    ]
    if len(work) >= workers and max(work) <= 2 * min(work):
        return 1
    return workers


def _sweep_seconds(manifest):
    """Per-stage sweep seconds summed over the finished tasks (as ``Store.timings``)."""
    import pandas as pd

    rows = {tid: e.get("timings", {}) for tid, e in manifest["tasks"].items()}
    return pd.DataFrame.from_dict(rows, orient="index").sort_index().sum(numeric_only=True)


def experiment_part(job, bar=None):
    """Build one experiment's part: load its store, run every section, write its figures
    and tables; return what the page needs (HTML fragments, files, timings), JSON-ready.

    Runs in a worker process (``bar`` None) or in this one with a progress bar.
    """
    path, out, prefix, options, render, workers = job
    out = Path(out)
    t0 = time.perf_counter()
    store = load_report_store(path)
    name = store.experiment.name
    timings = [(name, "load store", time.perf_counter() - t0)]
    pool = Mapper(workers)
    try:
        ctx = Context(store, pmap=pool.map, pstart=pool.start, **options)
        found, secs, notes = analyse(ctx, bar=bar or Progress(False, 0), timings=timings)
    finally:
        pool.close()
    t0 = time.perf_counter()
    files = {}
    findings_html = write_outputs(
        [found], out, render["dpi"], prefix, pdf=render["pdf"], files=files, embed=False
    )
    header, params = store_header(store, notes)
    write_table(out, f"{prefix}experiment", params, files)
    write_text(out, f"{prefix}experiment.toml", store.experiment.to_toml(), files)
    body = write_outputs(
        secs,
        out,
        render["dpi"],
        prefix,
        pdf=render["pdf"],
        files=files,
        embed=False,
        workers=workers,
    )
    timings.append((name, "write files", time.perf_counter() - t0))
    return {
        "key": content_key("experiment", store_key(path, store.manifest), options, render, prefix),
        "files": files,
        "findings_html": findings_html,
        "findings_toc": toc_item(f"{prefix}findings", found.title),
        "html": f'<h2 id="{prefix}experiment">Experiment {html.escape(name)}</h2>{header}{body}',
        "toc": toc_item(
            f"{prefix}experiment",
            f"Experiment {name}",
            [toc_item(f"{prefix}{s.key}", s.title) for s in secs],
        ),
        "timings": [list(t) for t in timings],
    }


def families_part(paths, out, render, workers=1):
    """The all-experiments figures (:func:`families_section`) as a cache part."""
    t0 = time.perf_counter()
    stores = [load_report_store(p) for p in paths]
    families = families_section(stores)
    files = {}
    fragment, toc = "", ""
    if families is not None:
        fragment = write_outputs(
            [families],
            Path(out),
            render["dpi"],
            pdf=render["pdf"],
            files=files,
            embed=False,
            workers=workers,
        )
        toc = toc_item(families.key, families.title)
    keys = [store_key(p, st.manifest) for p, st in zip(paths, stores, strict=True)]
    return {
        "key": content_key("families", keys, render),
        "files": files,
        "html": fragment,
        "toc": toc,
        "timings": [["", "all-experiments figures", time.perf_counter() - t0]],
    }


def families_section(stores):
    """The recurrence rate in the paper's Fig. 7 layout: family A, all radii on top and a
    zoom on its small radii below, with the off-diagonal rate beside. (The FTLE and the
    autocorrelation of every family are in each family's fig05 and fig07, and their ratios
    to the two-disk values, both families together, in the Findings' fig00.)"""
    from kicktimes.report import recurrence
    from kicktimes.report.context import Section

    sec = Section("families", "Diagnostics against radius, all experiments")
    rr = recurrence.family_figure(stores)
    if rr is not None:
        sec.figure("families_recurrence_rate_vs_radius", *rr)
    return sec if sec.figures else None


#: build_report's keywords before 0.2.0 that became fields of `Render` / `Subsampling`
OLD_RENDER = ("dpi", "pdf")
OLD_SUBSAMPLING = ("max_ics_tests", "max_ics_model_fits", "max_pooled_intervals")


@translator(*OLD_RENDER, *OLD_SUBSAMPLING)
def _old_report(args, kwargs):
    kwargs = dict(kwargs)
    for key, cls, names in (("render", Render, OLD_RENDER),
                            ("subsampling", Subsampling, OLD_SUBSAMPLING)):
        old = pop_old(kwargs, names)
        if not old:
            continue
        warn_old(", ".join(f"build_report({k}=...)" for k in old),
                 f"build_report(..., {key}={cls.__name__}({', '.join(f'{k}=...' for k in old)}))"
                 " (kicktimes.report." + cls.__name__ + ")")
        if kwargs.get(key) is not None:
            raise TypeError(f"build_report: give {', '.join(old)} as fields of {key}=, not as "
                            "keywords")
        kwargs[key] = cls(**old)
    return kwargs, None


@old_keywords(_old_report)
def build_report(
    store_path,
    out_dir,
    *,
    progress=None,
    alpha=0.05,
    n_mc=199,
    subsampling=None,
    render=None,
    workers=None,
    n_boot=2000,
    tolerance=0.1,
    escape_t_min=None,
    force=False,
) -> Path:
    r"""Build the report of one or several sweeps: tables, figures, a self-contained page.

    Parameters
    ----------
    store_path : path-like or sequence of path-like
        A store written by :func:`kicktimes.experiment.run_experiment`, or several (e.g.
        the paper's two families): each gets its own part of the report, with file names
        prefixed by its experiment's name, and the diagnostics are also drawn one panel
        per experiment in one figure (the paper's top/bottom layout).
    out_dir : path-like
        Output folder (created if needed; existing files of the same names are replaced).
    progress : None, bool or callable, optional
        A tqdm bar over the stages (default: on a terminal, not under ``CI``), or a
        callable ``progress(stage, done, total)``.
    alpha : float, optional
        Level of the Poisson tests, rate-homogeneity tests and FDR control.
    n_mc : int, optional
        Monte Carlo samples of the conditional nulls of the Poisson tests (p-value
        resolution ``1/(n_mc + 1)``).
    subsampling : Subsampling, optional
        How far the tests and fits subsample the store (`kicktimes.report.Subsampling`:
        ``max_ics_tests``, ICs per radius in the Poisson tests, default all;
        ``max_ics_model_fits``, ICs per radius with a per-IC renewal-model comparison,
        default 12; ``max_pooled_intervals``, the pooled fits' interval budget per radius,
        default 200 000).
    render : Render, optional
        How the figures are written (`kicktimes.report.Render`: ``dpi``, default 150, the
        PNGs' resolution; ``pdf``, default False, also a PDF of every figure).
    workers : int, optional
        Processes (default ``os.cpu_count()``; ``1`` computes everything in this
        process). With several stores to (re)build, each store's part runs in its own
        worker, so both families' statistics and figures overlap; within a part, its
        Poisson tests (one job per radius, started before the first section), renewal
        fits (one job per sample) and figure rendering use ``workers`` processes of
        their own. The results and files do not depend on it.
    n_boot : int, optional
        Bootstrap resamples (over ICs) of the Findings' confidence intervals.
    tolerance : float, optional
        Half-width of the band of a ratio's verdict: "within 10 %" when the 95 % CI
        lies inside ``[1 - tolerance, 1 + tolerance]`` (see :mod:`kicktimes.report.effects`).
    escape_t_min : float, optional
        Where the escape section's tail fits start, in time units (stores of experiments
        with holes; default: 1/20 of the experiment's horizon ``n_steps * tau``; see
        :mod:`kicktimes.report.escape`).
    force : bool, optional
        Rebuild everything, ignoring the cache ``out_dir/.cache.json``.

    Returns
    -------
    pathlib.Path
        ``out_dir / "report.html"``.

    Notes
    -----
    The page opens with the Findings of each store (:mod:`kicktimes.report.findings`):
    one computed statement per question with its effect size, 95 % CI and verdict, a
    banner when the store is below paper scale, then one part per section module.
    Cached: each experiment's part is keyed by its store's content as the manifest records
    it (per-task SHA-256 entries, experiment hash), the options and the kicktimes version;
    a rebuild with nothing changed writes nothing and returns at once, a store that
    changed rebuilds its own part and the page only (:mod:`kicktimes.report._cache`). The
    cache trusts the store's manifest; ``force=True`` rebuilds from the part files.
    Every file is written atomically (temporary file, then rename). Deterministic: the
    Monte Carlo streams derive from each experiment's seed
    (``SeedSequence(seed, spawn_key=(REPORT_DOMAIN, ...))``), the trajectories from its
    IC 0 and the Poisson kicks from the sweep's own ``kick_rng``; BLAS runs on one thread
    during the build (the previous limit is restored afterwards), so the files do not
    depend on the machine's number of cores either. Every subsampling is
    listed in the report. Stage timings are written to ``report_timings.csv`` and the
    sweep's (summed over tasks) to ``sweep_timings.csv``.

    Examples
    --------
    >>> import tempfile
    >>> from kicktimes.experiment import Experiment, run_experiment
    >>> from kicktimes.report import build_report
    >>> exp = Experiment(name="demo", radii=[0.01, 0.02], n_ics=3, n_steps=300, tau=0.3,
    ...                  diagnostics=["recurrence_rate", "autocorrelation"])
    >>> store = tempfile.mkdtemp()
    >>> _ = run_experiment(exp, store, workers=1, progress=False)
    >>> build_report(store, tempfile.mkdtemp(), progress=False, workers=1).name
    'report.html'
    """
    subsampling = _check_group("subsampling", subsampling, Subsampling)
    render = _check_group("render", render, Render)
    paths = _check_paths(store_path)
    options, render, workers = _check_options(
        out_dir,
        progress=progress,
        alpha=alpha,
        n_mc=n_mc,
        max_ics_tests=subsampling.max_ics_tests,
        max_ics_model_fits=subsampling.max_ics_model_fits,
        max_pooled_intervals=subsampling.max_pooled_intervals,
        dpi=render.dpi,
        workers=workers,
        n_boot=n_boot,
        tolerance=tolerance,
        escape_t_min=escape_t_min,
        pdf=render.pdf,
        force=force,
    )
    t_start = time.perf_counter()
    plan = _plan(paths, Path(out_dir), options, render, force=force)
    if plan.up_to_date():
        return plan.out / "report.html"  # nothing changed: every file is what it would write
    # the parts to (re)build: one job per store, and the all-experiments figures
    jobs = {
        pid: (path, plan.out, prefix, options, render, workers)
        for pid, path, prefix in zip(plan.part_ids, paths, plan.prefixes, strict=True)
        if plan.parts[pid] is None
    }
    families_todo = plan.multi and plan.parts["families"] is None
    parallel = workers > 1 and len(jobs) + families_todo > 1
    n_steps = 2 + (len(jobs) if parallel else n_stages() * len(jobs)) + families_todo
    bar = Progress(progress, n_steps)
    # the collector runs less often while the report allocates (kicktimes.memory)
    with closing(bar), fewer_collections(), _one_blas_thread():
        bar.step("load store")
        timings = [("", "check cache", time.perf_counter() - t_start)]
        bar.advance()
        build = _build_parallel if parallel else _build_serial
        build(plan, jobs, families_todo, workers=workers, render=render, bar=bar)
        built = [*jobs, *(["families"] if families_todo else [])]
        for pid in built:
            timings += [tuple(t) for t in plan.parts[pid]["timings"]]
            plan.cache.record(pid, plan.parts[pid])
        bar.step("write files")
        page = _write_page(plan, timings, built)
        bar.advance()
        return page


def _check_group(name, value, cls):
    if value is None:
        return cls()
    if not isinstance(value, cls):
        raise TypeError(f"{name} must be a kicktimes.report.{cls.__name__}(...) or None, got "
                        f"{type(value).__name__}")
    return value


def _check_options(out_dir, *, progress, alpha, n_mc, max_ics_tests, max_ics_model_fits,
                   max_pooled_intervals, dpi, workers, n_boot, tolerance, escape_t_min, pdf,
                   force):
    """The checked arguments of :func:`build_report` as ``(options, render, workers)``:
    ``options`` the sections' (as `Context` takes them), ``render`` the figures'."""
    if not isinstance(out_dir, str | os.PathLike):
        raise TypeError(f"out_dir must be a path, got {type(out_dir).__name__}")
    options = {
        "alpha": check_real("alpha", alpha, low=0, high=1),
        "n_mc": check_int("n_mc", n_mc, low=19),
        "max_ics_tests": (None if max_ics_tests is None
                          else check_int("max_ics_tests", max_ics_tests, low=2)),
        "max_ics_model_fits": check_int("max_ics_model_fits", max_ics_model_fits, low=1),
        "max_pooled_intervals": check_int("max_pooled_intervals", max_pooled_intervals, low=100),
        "n_boot": check_int("n_boot", n_boot, low=100),
        "tolerance": check_real("tolerance", tolerance, low=0, high=1),
        "escape_t_min": _check_t_min(escape_t_min),
    }
    render = {"dpi": check_int("dpi", dpi, low=30), "pdf": pdf}
    workers = check_int("workers", (os.cpu_count() or 1) if workers is None else workers, low=1)
    for flag, value in (("pdf", pdf), ("force", force)):
        if not isinstance(value, bool):
            raise TypeError(f"{flag} must be True or False, got {type(value).__name__}")
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise TypeError(
            f"progress must be None, a bool or a callable(stage, done, total), got "
            f"{type(progress).__name__}"
        )
    return options, render, workers


def _check_t_min(value):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"escape_t_min must be a number or None, got {type(value).__name__}")
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"escape_t_min must be positive and finite, got {float(value)}")
    return float(value)


@dataclass
class _Plan:
    """What a build writes: one part per store (and the all-experiments figures with
    several), each with its cache key, and the cached parts (None: to build)."""

    paths: list
    out: Path
    names: list  # the stores' experiment names
    manifests: list
    part_ids: list  # "experiment <name>", one per store
    prefixes: list  # the file-name prefix of each store's files ("<name>_" with several)
    keys: dict  # part id (and "families") -> cache key
    parts: dict  # part id -> the part, from the cache or built; None until built
    page_key: str
    cache: ReportCache

    @property
    def multi(self):
        return len(self.paths) > 1

    def up_to_date(self):
        """Every part and the page are in the cache under their keys."""
        return all(e is not None for e in self.parts.values()) and bool(
            self.cache.lookup("page", self.page_key)
        )


def _plan(paths, out, options, render, *, force):
    """Read the stores' manifests, check them, and look every part up in the cache."""
    from kicktimes.experiment.store import read_manifest

    manifests = [read_manifest(p) for p in paths]
    for p, man in zip(paths, manifests, strict=True):
        if not man["tasks"]:
            raise ValueError(f"store_path: {os.fspath(p)!r} holds no finished task yet")
    names = [str(man["experiment"].get("name")) for man in manifests]
    if len(set(names)) != len(names):
        raise ValueError(
            f"store_path: the stores' experiments must have distinct names, got {names}"
        )
    out.mkdir(parents=True, exist_ok=True)
    cache = ReportCache(out, fresh=force)
    multi = len(paths) > 1
    prefixes = [f"{n}_" if multi else "" for n in names]
    part_ids = [f"experiment {n}" + (" (prefixed)" if multi else "") for n in names]
    store_keys = [store_key(p, m) for p, m in zip(paths, manifests, strict=True)]
    keys = {
        pid: content_key("experiment", sk, options, render, prefix)
        for pid, sk, prefix in zip(part_ids, store_keys, prefixes, strict=True)
    }
    if multi:
        keys["families"] = content_key("families", store_keys, render)
    return _Plan(
        paths=paths,
        out=out,
        names=names,
        manifests=manifests,
        part_ids=part_ids,
        prefixes=prefixes,
        keys=keys,
        parts={pid: cache.lookup(pid, key) for pid, key in keys.items()},
        page_key=content_key("page", list(keys.values())),
        cache=cache,
    )


def _build_serial(plan, jobs, families_todo, *, workers, render, bar):
    """Build the parts in this process, one after the other (each with its own pools)."""
    for pid, job in jobs.items():
        plan.parts[pid] = experiment_part(job, bar)
    if families_todo:
        bar.step("all-experiments figures")
        plan.parts["families"] = families_part(plan.paths, plan.out, render, workers)
        bar.advance()


def _build_parallel(plan, jobs, families_todo, *, workers, render, bar):
    """Build the parts at the same time, one worker process per part; each part maps its
    per-radius jobs (Poisson tests, renewal fits) and renders its figures on pools of its
    own (:func:`_inner_workers` processes)."""
    _preload()  # before the pool forks: the workers inherit the imports
    inner = _inner_workers(workers, [plan.manifests[plan.part_ids.index(pid)] for pid in jobs])
    with ProcessPoolExecutor(
        max_workers=min(workers, len(jobs) or 1), initializer=keep_freed_memory
    ) as ex:
        futures = {
            pid: ex.submit(experiment_part, job[:-1] + (inner,)) for pid, job in jobs.items()
        }
        if families_todo:
            # a pool job too, queued behind the parts: it runs in the worker of the first
            # part done (the smaller family), and renders on processes forked from that
            # single-threaded worker, not from this process, whose pool threads a fork
            # would copy
            fam = ex.submit(families_part, plan.paths, plan.out, render, workers)
            bar.step("all-experiments figures")
            plan.parts["families"] = fam.result()
            bar.advance()
        for pid, fut in futures.items():
            bar.step(f"{pid}: sections (in a worker process)")
            plan.parts[pid] = fut.result()
            bar.advance()


def _write_page(plan, timings, built):
    """Write the timing tables and the page from the parts; record the page in the cache
    and save it. Returns the page's path."""
    import pandas as pd

    t0 = time.perf_counter()
    out, files = plan.out, {}
    sweep_rows = [
        (name, stage, float(v))
        for name, man in zip(plan.names, plan.manifests, strict=True)
        for stage, v in _sweep_seconds(man).items()
    ]
    sweep_t = pd.DataFrame(sweep_rows, columns=["experiment", "stage", "seconds"])
    write_table(out, "sweep_timings", sweep_t, files)
    timings = timings + [
        (n, "reused from the cache", 0.0)
        for n, pid in zip(plan.names, plan.part_ids, strict=True)
        if pid not in built
    ]
    timings.append(("", "write page", time.perf_counter() - t0))
    report_t = pd.DataFrame(timings, columns=["experiment", "stage", "seconds"])
    write_table(out, "report_timings", report_t, files)
    ordered = [plan.parts[pid] for pid in plan.part_ids]
    lead = embed_figures("".join(e["findings_html"] for e in ordered), out)
    toc = [e["findings_toc"] for e in ordered]
    body = []
    if plan.multi and plan.parts["families"]["html"]:
        body.append(plan.parts["families"]["html"])
        toc.append(plan.parts["families"]["toc"])
    body += [e["html"] for e in ordered]
    toc += [e["toc"] for e in ordered]
    page = write_page(
        out,
        "kicktimes report: " + " + ".join(plan.names),
        sources=", ".join(
            html.escape(os.path.relpath(Path(p).resolve(), Path(out).resolve()))
            for p in plan.paths
        ),
        toc=toc,
        lead=lead,
        body=embed_figures("".join(body), out),
        appendix="<h2>Timings</h2><p>Report stages (seconds, this build; parts reused from "
        "the cache are listed as such):</p>"
        + table_html(report_t)
        + "<p>Sweep stages (seconds, summed over tasks and workers):</p>"
        + table_html(sweep_t),
        files=files,
    )
    plan.cache.record("page", {"key": plan.page_key, "files": files})
    plan.cache.save()
    return page


def _check_paths(store_path):
    if isinstance(store_path, str | os.PathLike):
        return [store_path]
    if isinstance(store_path, list | tuple) and store_path:
        paths = list(store_path)
        for k, p in enumerate(paths):
            if not isinstance(p, str | os.PathLike):
                raise TypeError(f"store_path[{k}] must be a path, got {type(p).__name__}")
        return paths
    raise TypeError(
        f"store_path must be a path or a non-empty list of paths, got {type(store_path).__name__}"
    )
