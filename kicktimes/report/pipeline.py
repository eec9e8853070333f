r"""The report pipeline: load the stores, run every section module, write the page.

Each section is one module of :mod:`kicktimes.report` holding its computation, figure and
text; :data:`STAGES` lists them in page order, so adding a diagnostic means writing one
module and adding it here (and, for the Findings, to
:data:`kicktimes.report.findings.EFFECT_MODULES`).
"""

from __future__ import annotations

import datetime as _dt
import html
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from kicktimes import __version__
from kicktimes.report import (
    autocorrelation,
    counts,
    findings,
    heterogeneity,
    kick_times,
    lyapunov,
    poisson,
    recurrence,
    renewal,
    summary,
    trajectories,
)
from kicktimes.report._common import (
    Context,
    Mapper,
    Progress,
    Section,
    check_fraction,
    check_int,
)
from kicktimes.report._figures import DIAGNOSTIC_LABELS
from kicktimes.report.html import CSS, store_header, table_html, write_outputs

__all__ = ["build_report", "analyse", "STAGES"]

#: (stage name, section module) in page order; every module has ``sections(ctx)``
STAGES = (
    ("trajectories", trajectories),
    ("kick times", kick_times),
    ("counts", counts),
    ("diagnostic tables", summary),
    ("Lyapunov exponents", lyapunov),
    ("recurrence", recurrence),
    ("autocorrelation", autocorrelation),
    ("Poisson tests", poisson),
    ("renewal models", renewal),
    ("rate heterogeneity", heterogeneity),
    ("findings", findings),
)


def analyse(ctx, *, bar, timings):
    """Every section of one store: ``(findings section, other sections, notes)``."""
    secs, found = [], None
    for stage, module in STAGES:
        bar.step(f"{ctx.exp.name}: {stage}")
        t0 = time.perf_counter()
        if module is findings:
            found = findings.section(ctx)
        else:
            secs += module.sections(ctx)
        timings.append((ctx.exp.name, stage, time.perf_counter() - t0))
        bar.advance()
    return found, secs, ctx.notes


def families_section(stores):
    """The paper's layout, one panel per experiment (family A top, B bottom) for the FTLE
    and the autocorrelation; the recurrence rate as the paper's Fig. 7: family A, all radii
    on top and a zoom on its small radii below, with the off-diagonal rate beside."""
    sec = Section("families", "Diagnostics against radius, all experiments")
    summaries = [summary.diagnostic_summary(st.results, _present(st)) for st in stores]
    for diagnostic in ("lyapunov", "autocorrelation"):
        having = [
            (st, sm)
            for st, sm in zip(stores, summaries, strict=True)
            if diagnostic in set(sm["diagnostic"])
        ]
        if len(having) < 2:
            continue
        fig = Figure(figsize=(6.4, 4.0 * len(having)), layout="constrained")
        axes = np.atleast_1d(fig.subplots(len(having), 1))
        for ax, (st, sm) in zip(axes, having, strict=True):
            exp = st.experiment
            summary.diagnostic_vs_radius(
                sm,
                diagnostic,
                ax=ax,
                medians=True,
                title=f"{exp.name}: {exp.n_ics} ICs, {exp.n_steps} steps of τ = {exp.tau:g}",
            )
        name = DIAGNOSTIC_LABELS[diagnostic][0]
        sec.figure(
            f"families_{diagnostic}_vs_radius",
            fig,
            f"{name} against radius, one panel per experiment (the paper's top and bottom "
            "plots); thick pale bars ± std/10 (the paper's), thin capped bars ± std/√n_valid, "
            "open markers the medians.",
        )
    rr = recurrence.family_figure(stores)
    if rr is not None:
        sec.figure("families_recurrence_rate_vs_radius", *rr)
    return sec if sec.figures else None


def _present(store):
    have = set(store.results["diagnostic"])
    return [d for d in ("lyapunov", "autocorrelation") if d in have] or None


def build_report(
    store_path,
    out_dir,
    *,
    progress=None,
    alpha=0.05,
    n_mc=199,
    max_ics_tests=None,
    max_ics_model_fits=12,
    max_pooled_intervals=200_000,
    dpi=150,
    workers=None,
    n_boot=2000,
    tolerance=0.1,
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
    max_ics_tests : int, optional
        Use only the first ``max_ics_tests`` ICs (by index) per radius in the Poisson
        tests (default: all).
    max_ics_model_fits : int, optional
        ICs (first by index) per radius whose intervals get a per-IC renewal-model
        comparison (6 censored fits each, ~0.4 s per IC).
    max_pooled_intervals : int, optional
        Interval budget of the pooled fits per radius (whole ICs in index order).
    dpi : int, optional
        Resolution of the PNG files.
    workers : int, optional
        Processes for the Poisson tests (one job per radius) and the renewal fits (one
        job per sample); default ``os.cpu_count()``; ``1`` computes in this process.
        The results do not depend on it.
    n_boot : int, optional
        Bootstrap resamples (over ICs) of the Findings' confidence intervals.
    tolerance : float, optional
        Half-width of the "agrees" band of a ratio's verdict: agrees when the 95 % CI
        lies inside ``[1 - tolerance, 1 + tolerance]`` (see :mod:`kicktimes.report.effects`).

    Returns
    -------
    pathlib.Path
        ``out_dir / "report.html"``.

    Notes
    -----
    The page opens with the Findings of each store (:mod:`kicktimes.report.findings`):
    one computed statement per question with its effect size, 95 % CI and verdict, a
    banner when the store is below paper scale, then one part per section module.
    Deterministic: the Monte Carlo streams derive from each experiment's seed
    (``SeedSequence(seed, spawn_key=(REPORT_DOMAIN, ...))``), the trajectories from its
    IC 0 and the Poisson kicks from the sweep's own ``kick_rng``. Every subsampling is
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
    from kicktimes.experiment import load_store

    if isinstance(store_path, str | os.PathLike):
        paths = [store_path]
    elif isinstance(store_path, list | tuple) and store_path:
        paths = list(store_path)
        for k, p in enumerate(paths):
            if not isinstance(p, str | os.PathLike):
                raise TypeError(f"store_path[{k}] must be a path, got {type(p).__name__}")
    else:
        raise TypeError(
            "store_path must be a path or a non-empty list of paths, got "
            f"{type(store_path).__name__}"
        )
    if not isinstance(out_dir, str | os.PathLike):
        raise TypeError(f"out_dir must be a path, got {type(out_dir).__name__}")
    alpha = check_fraction("alpha", alpha)
    n_mc = check_int("n_mc", n_mc, 19)
    max_ics_tests = check_int("max_ics_tests", max_ics_tests, 2, allow_none=True)
    max_ics_model_fits = check_int("max_ics_model_fits", max_ics_model_fits, 1)
    max_pooled_intervals = check_int("max_pooled_intervals", max_pooled_intervals, 100)
    dpi = check_int("dpi", dpi, 30)
    n_boot = check_int("n_boot", n_boot, 100)
    tolerance = check_fraction("tolerance", tolerance)
    workers = check_int("workers", (os.cpu_count() or 1) if workers is None else workers, 1)
    bar = Progress(progress, 2 + len(STAGES) * len(paths))
    pool = Mapper(workers)
    try:
        bar.step("load store")
        t0 = time.perf_counter()
        stores = [load_store(p) for p in paths]
        for p, st in zip(paths, stores, strict=True):
            if st.results.empty or st.collisions.empty:
                raise ValueError(f"store_path: {os.fspath(p)!r} holds no finished task yet")
        names = [st.experiment.name for st in stores]
        if len(set(names)) != len(names):
            raise ValueError(
                f"store_path: the stores' experiments must have distinct names, got {names}"
            )
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        timings = [("", "load store", time.perf_counter() - t0)]
        bar.advance()
        options = dict(
            alpha=alpha,
            n_mc=n_mc,
            max_ics_tests=max_ics_tests,
            max_ics_model_fits=max_ics_model_fits,
            max_pooled_intervals=max_pooled_intervals,
            n_boot=n_boot,
            tolerance=tolerance,
        )
        analysed = [
            analyse(Context(st, pmap=pool.map, **options), bar=bar, timings=timings)
            for st in stores
        ]
        bar.step("write files")
        t0 = time.perf_counter()
        multi = len(stores) > 1
        parts, toc, sweep_rows = [], [], []
        # Findings first: every store's statements before any detail
        for st, (findings, _, _) in zip(stores, analysed, strict=True):
            prefix = f"{st.experiment.name}_" if multi else ""
            parts.append(write_outputs([findings], out, dpi, prefix))
            toc.append(f'<li><a href="#{prefix}findings">{html.escape(findings.title)}</a></li>')
        if multi:
            families = families_section(stores)
            if families is not None:
                parts.append(write_outputs([families], out, dpi))
                toc.append(f'<li><a href="#{families.key}">{html.escape(families.title)}</a></li>')
        for st, (_, secs, notes) in zip(stores, analysed, strict=True):
            name = st.experiment.name
            prefix = f"{name}_" if multi else ""
            header, params = store_header(st, notes)
            params.to_csv(out / f"{prefix}experiment.csv", index=False)
            (out / f"{prefix}experiment.toml").write_text(st.experiment.to_toml(), encoding="utf-8")
            sweep = st.timings.sum(numeric_only=True)
            sweep_rows += [(name, stage, float(v)) for stage, v in sweep.items()]
            body = write_outputs(secs, out, dpi, prefix)
            parts.append(
                f'<h2 id="{prefix}experiment">Experiment {html.escape(name)}</h2>{header}{body}'
            )
            items = "".join(
                f'<li><a href="#{prefix}{s.key}">{html.escape(s.title)}</a></li>' for s in secs
            )
            toc.append(
                f'<li><a href="#{prefix}experiment">Experiment {html.escape(name)}</a>'
                f"<ul>{items}</ul></li>"
            )
        sweep_t = pd.DataFrame(sweep_rows, columns=["experiment", "stage", "seconds"])
        sweep_t.to_csv(out / "sweep_timings.csv", index=False)
        timings.append(("", "write files", time.perf_counter() - t0))
        bar.advance()
        report_t = pd.DataFrame(timings, columns=["experiment", "stage", "seconds"])
        report_t.to_csv(out / "report_timings.csv", index=False)
        title = " + ".join(names)
        page = (
            '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f"<title>kicktimes report: {html.escape(title)}</title><style>{CSS}</style>"
            f"</head><body><h1>kicktimes report: {html.escape(title)}</h1>"
            f"<p>Built {_dt.datetime.now(_dt.timezone.utc).isoformat(timespec='seconds')} "
            f"with kicktimes {html.escape(__version__)} from "
            + ", ".join(html.escape(os.fspath(Path(st.path).resolve())) for st in stores)
            + f".</p><h2>Contents</h2><ul>{''.join(toc)}</ul>{''.join(parts)}"
            "<h2>Timings</h2><p>Report stages (seconds, this build):</p>"
            + table_html(report_t)
            + "<p>Sweep stages (seconds, summed over tasks and workers):</p>"
            + table_html(sweep_t)
            + "</body></html>"
        )
        path = out / "report.html"
        path.write_text(page, encoding="utf-8")
        return path
    finally:
        pool.close()
        bar.close()
