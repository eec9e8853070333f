"""``kicktimes reproduce --study paper``: the paper's families (and, at the paper's scale,
their controls) into stores, the sweep report, and, with ``results_dir``, the page."""

from __future__ import annotations

import os
from contextlib import ExitStack
from pathlib import Path

from kicktimes.studies.options import check_scale, check_workers, status_lines

__all__ = ["reproduce"]


def reproduce(out, *, scale="quick", results_dir=None, workers=None, progress=None,
              command=None, content="full", scheduler=None, wait=False, pdf=False) -> Path:
    """Run (or resume) the presets of ``scale`` into ``out/store-<name>``, build the sweep
    report into ``out/report`` and, with ``results_dir``, write the page ``README.md``
    there (`write_results`).

    Parameters
    ----------
    out : path-like
        Work folder: the stores and the report.
    scale : {"quick", "paper"}
        ``"paper"``: both families and their controls (`kicktimes.studies.paper.SCALES`);
        ``"quick"``: the small versions ``quick_a``, ``quick_b``.
    results_dir : path-like, optional
        Folder of the page (none by default: the report alone).
    workers : int, optional
        Local worker processes (default: all cores).
    progress : bool or callable, optional
        Progress bars and status lines (`kicktimes.studies.options.status_lines`);
        default: bars on a terminal, not under CI.
    command : str, optional
        The command the page's "Generated" line names.
    content : {"full", "paper"}
        ``"paper"``: the paper's own systems and diagnostics only, into
        ``store-<name>-paper`` and ``report-paper``.
    scheduler : str, optional
        A Dask scheduler's address for the sweeps (then not with ``workers``).
    wait : bool
        Wait for another run writing a store instead of stopping.
    pdf : bool
        Also a PDF of every figure of the report.

    Returns
    -------
    pathlib.Path
        The page ``results_dir / "README.md"``, or the report's page when no
        ``results_dir`` is given.
    """
    from kicktimes.compilation import compile_first
    from kicktimes.experiment import run_experiment
    from kicktimes.experiment.presets import CONTENTS, preset
    from kicktimes.experiment.runner import local_pool
    from kicktimes.experiment.store import pending_tasks
    from kicktimes.report.process import ReportProcess, build_stores_report
    from kicktimes.studies.paper.page import write_results
    from kicktimes.studies.paper.presets import SCALES, scale_presets

    check_scale(scale, SCALES)
    if workers is not None:
        workers = check_workers(workers)
    if content not in CONTENTS:
        raise ValueError(f"content must be one of {sorted(CONTENTS)}, got {content!r}")
    if workers is not None and scheduler is not None:
        raise ValueError("workers sizes the local pool; it cannot go with scheduler")
    say = status_lines(progress)
    bars = progress if progress is None or isinstance(progress, bool) else True
    out = Path(out)
    # the paper's content goes to its own stores and report: both contents can share `out`
    suffix = "-paper" if content == "paper" else ""
    exps = [preset(n, content) for n in scale_presets(scale, content)]
    paths = [out / f"store-{exp.name}{suffix}" for exp in exps]
    stores = []
    with ExitStack() as stack:
        pending = scheduler is None and any(pending_tasks(e, p)
                                            for e, p in zip(exps, paths, strict=True))
        pool = None
        n_workers = workers or os.cpu_count() or 1
        report_process = None
        if pending and n_workers > 1:
            report_process = stack.enter_context(ReportProcess())
        if pending:
            compile_first(workers, report=True, report_process=report_process is not None)
            if n_workers > 1:
                # one pool for both families: each worker starts (imports, loads the
                # compiled kernels) once
                pool = stack.enter_context(local_pool(workers))
        for exp, path in zip(exps, paths, strict=True):
            say(exp.summary())
            store = run_experiment(exp, path, executor=pool,
                                   workers=None if pool is not None else workers,
                                   scheduler=scheduler, progress=bars, wait=wait)
            say(store.summary())
            stores.append(str(path))
        if pool is not None:
            pool.shutdown()  # the sweep workers end before the report starts its own
        report_dir = out / f"report{suffix}"
        job = (stores, str(report_dir), workers, bars, pdf)
        report = report_process.build(*job) if report_process else build_stores_report(*job)
        say(f"report written to {report if report is not None else report_dir}")
        if results_dir is None:
            return Path(report) if report is not None else report_dir / "report.html"
        return write_results(stores, results_dir, workers=workers or os.cpu_count() or 1,
                             command=command or f"kicktimes reproduce --study paper "
                             f"--scale {scale} --results {results_dir}")
