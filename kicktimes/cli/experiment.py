"""``kicktimes run``, ``report`` and ``reproduce``: sweeps into stores, and their reports."""

from __future__ import annotations

import click

from kicktimes.cli._group import _cli_errors, _compile_first, option
from kicktimes.studies import STUDIES


# --- experiment commands ---
def _run_one(experiment, out, workers, scheduler, progress, wait=False, executor=None):
    """Run or resume one sweep, printing store warnings as plain lines; returns the store.
    ``executor``: a pool shared by several sweeps (then ``workers`` is not passed on)."""
    import warnings

    from kicktimes.experiment import StoreWarning, run_experiment

    if executor is not None:
        workers = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", StoreWarning)
        try:
            store = run_experiment(
                experiment, out, executor=executor, workers=workers, scheduler=scheduler,
                progress=progress, wait=wait,
            )
        finally:
            for w in caught:
                click.echo(f"warning: {w.message}", err=True)
    return store


def _pending(experiment, store_path) -> bool:
    """True unless ``store_path`` already holds every task of ``experiment`` (by its
    manifest; the run itself verifies the parts)."""
    from kicktimes.experiment.store import pending_tasks

    return bool(pending_tasks(experiment, store_path))


_workers_option = click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Local worker processes (default: all cores; 1 runs in this process).",
)
_scheduler_option = click.option(
    "--scheduler",
    metavar="ADDRESS",
    default=None,
    help="Run on a Dask distributed cluster, e.g. tcp://host:8786 (needs kicktimes[dask]).",
)
_progress_option = click.option(
    "--progress/--no-progress",
    default=None,
    help="Progress bar (default: on a terminal, off when CI is set).",
)
_wait_option = click.option(
    "--wait",
    is_flag=True,
    help="If another run is writing the store, wait for it instead of stopping.",
)
# library argument names -> the options that set them
_RUN_OPTIONS = {"store": "--out", "workers": "--workers", "scheduler": "--scheduler",
                "path": "--out"}


@click.command("run")
@click.argument("experiment", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Store directory (created; rerunning resumes it).")
@_workers_option
@_scheduler_option
@_progress_option
@_wait_option
def run_command(experiment, out, workers, scheduler, progress, wait):
    """Run (or resume) the sweep of EXPERIMENT.toml into the store --out.

    \b
    Examples:
      kicktimes run analysis/quick_a.toml --out stores/quick_a
      kicktimes run analysis/family_b.toml --out stores/b --scheduler tcp://host:8786
    """
    from kicktimes.experiment import Experiment

    if workers is not None and scheduler is not None:
        raise click.UsageError("--workers sizes the local pool; it cannot go with --scheduler")
    with _cli_errors(_RUN_OPTIONS):
        exp = Experiment.from_toml(experiment)
        click.echo(exp.summary())
        if scheduler is None and _pending(exp, out):
            _compile_first(workers)
        store = _run_one(exp, out, workers, scheduler, progress, wait)
    click.echo(store.summary())


def _build_report(stores, out, workers=None, progress=None, pdf=False, force=False):
    try:
        from kicktimes.report import build_report
    except ImportError as exc:
        raise click.ClickException(f"the report module is not available: {exc}") from None
    target = stores[0] if len(stores) == 1 else list(stores)
    return build_report(target, out, workers=workers, progress=progress, pdf=pdf, force=force)


def _report_server(conn, driver_end):
    """Body of `_ReportProcess`: import the report's modules, then build the one report
    the driver sends and send back ``("ok", path)`` or ``("error", exception)``."""
    import pickle

    driver_end.close()  # the fork's copy: else closing the driver's would never reach us
    from kicktimes import compilation as _compile
    from kicktimes.report import pipeline

    pipeline._stages()
    _compile.warm_report()
    try:
        job = conn.recv()
    except EOFError:  # the driver is gone, or had no report to build
        return
    try:
        result = ("ok", _build_report(*job))
    except BaseException as exc:  # noqa: BLE001  (handed to the driver, which raises it)
        result = ("error", exc)
    try:
        try:
            conn.send(result)
        except (TypeError, AttributeError, pickle.PicklingError):  # an unpicklable error
            exc = result[1]
            conn.send(("error", RuntimeError(f"{type(exc).__name__}: {exc}")))
    except OSError:  # the driver is gone (e.g. interrupted): nobody to tell
        pass


class _ReportProcess:
    """A process forked at the start of ``reproduce`` that builds its report.

    It imports the report's modules (matplotlib, scipy, statsmodels: about 2 s) and loads
    (on a cold cache: compiles) the report's kernels while the driver checks the numba
    cache and runs the sweeps, on the core the driver's imports leave idle; the report
    starts at once when the sweeps end, and its workers, forked from this process,
    inherit all of it. Forked before the driver starts any thread or pool (measured:
    docs/benchmarks.md, "Measurements behind design choices").
    """

    def __init__(self):
        import multiprocessing as mp

        ctx = mp.get_context("fork")
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_report_server, args=(child, self._conn),
                                 name="kicktimes-report")
        self._proc.start()
        child.close()

    def build(self, *job):
        """`_build_report` of ``job`` in the report process; raises what it raised."""
        self._conn.send(job)
        try:
            status, value = self._conn.recv()
        except EOFError:
            raise RuntimeError(
                f"the report process ended unexpectedly (exit code {self._proc.exitcode})"
            ) from None
        if status == "error":
            raise value
        return value

    def close(self):
        self._conn.close()  # a process still waiting for a job ends
        self._proc.join(timeout=10)
        if self._proc.is_alive():
            self._proc.terminate()
            self._proc.join()


_pdf_option = click.option(
    "--pdf", is_flag=True, help="Also write a PDF of every figure (the page embeds PNGs)."
)
_force_option = click.option(
    "--force",
    is_flag=True,
    help="Rebuild every part of the report (default: reuse the parts whose stores and "
    "options did not change, recorded in OUT/.cache.json).",
)


@click.command("report")
@click.argument("stores", nargs=-1, required=True, type=click.Path(exists=True, file_okay=False))
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Report directory (HTML page, figures, tables).")
@_workers_option
@_progress_option
@_pdf_option
@_force_option
def report_command(stores, out, workers, progress, pdf, force):
    """Build the report of one or more result STORES into --out.

    A rebuild reuses every part whose store and options are unchanged: with nothing
    changed it writes nothing.

    \b
    Examples:
      kicktimes report stores/quick_a --out report-a
      kicktimes report stores/family_a stores/family_b --out report --pdf
    """
    with _cli_errors(_RUN_OPTIONS):
        path = _build_report(stores, out, workers, progress, pdf, force)
    click.echo(f"report written to {path if path is not None else out}")


@click.command("reproduce")
@click.option("--study", type=click.Choice(list(STUDIES)), default="paper", show_default=True,
              help="; ".join(f"{s.name}: {s.summary} (page {s.page})"
                             for s in STUDIES.values()) + ".")
@click.option("--results", "results", type=click.Path(file_okay=False), default=None,
              help="Folder of the study's page: --study paper writes README.md there from its "
              "stores (none by default), protocol paper.md (default OUT/results-protocol), "
              "disks disks.md (default OUT/results-disks).")
@click.option("--findings", "findings", type=click.Path(file_okay=False, exists=True),
              default=None,
              help="--study protocol: folder of the paper study's paper-scale findings "
              "tables (family_a_findings.csv, family_b_findings.csv; e.g. docs/results), for "
              "the count claims (default: --results, if it holds them).")
@option("--scale", type=click.Choice(["quick", "paper"]), default="quick",
        help="quick: small versions of both families; paper: the paper's full scale.")
@click.option(
    "--content",
    type=click.Choice(["full", "paper"]),
    default="full",
    show_default=True,
    help="full: the presets (the paper's systems and diagnostics plus the scatter-kicked "
    "systems, RQA at two thresholds, ACF curves); paper: the paper's own content only "
    "(3 systems, RR at eps = 0.001, R_1), under half the sweep's work, into "
    "store-<name>-paper and report-paper/.",
)
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Directory for the stores (store-<name>) and the report (report/).")
@_workers_option
@_scheduler_option
@_progress_option
@_wait_option
@_pdf_option
def reproduce_command(study, results, findings, scale, content, out, workers, scheduler,
                      progress, wait, pdf):
    """Run the paper's experiment families (and, at paper scale, their controls) and report.

    Reruns resume the stores in --out. The experiments are the built-in presets, the
    same as analysis/<name>.toml (with --content paper, reduced to the paper's own
    systems and diagnostics: kicktimes.experiment.presets.PAPER_CONTENT). With
    --study disks: the disks presets (kicktimes.experiment.DISKS_PRESETS) and the page
    disks.md (docs/results/disks.md is built with --results docs/results). With --study
    protocol: kicktimes.studies.protocol and the page paper.md (docs/results/paper.md is
    built with --scale paper --results docs/results; about 18 minutes on 2 cores).
    """
    import os
    import sys

    if findings is not None and study != "protocol":
        raise click.UsageError("--findings applies to --study protocol")
    if study == "protocol":
        from kicktimes.studies.protocol import reproduce_protocol

        if scheduler is not None:
            raise click.UsageError("--study protocol runs on the local pool (--workers); "
                                   "--scheduler is not supported")
        if progress is None:
            progress = sys.stderr.isatty() and not os.environ.get("CI")
        say = (lambda line: click.echo(line, err=True)) if progress else None
        command = f"kicktimes reproduce --study protocol --scale {scale}"
        with _cli_errors(_RUN_OPTIONS):
            page = reproduce_protocol(out, scale=scale, results_dir=results,
                                      findings_dir=findings, workers=workers, progress=say,
                                      command=command)
        click.echo(f"page written to {page}")
        return

    if study == "disks":
        from kicktimes.studies.disks import reproduce_disks

        if workers is not None and scheduler is not None:
            raise click.UsageError("--workers sizes the local pool; it cannot go with "
                                   "--scheduler")
        with _cli_errors(_RUN_OPTIONS):
            page = reproduce_disks(out, results_dir=results, workers=workers or 1,
                                   scheduler=scheduler, progress=progress,
                                   command="kicktimes reproduce --study disks")
        click.echo(f"page written to {page}")
        return

    from kicktimes.experiment.presets import preset, scale_presets

    if workers is not None and scheduler is not None:
        raise click.UsageError("--workers sizes the local pool; it cannot go with --scheduler")
    from contextlib import ExitStack

    from kicktimes.experiment.runner import local_pool

    stores = []
    with _cli_errors(_RUN_OPTIONS), ExitStack() as stack:
        # the paper's content goes to its own stores and report: both contents can share --out
        suffix = "-paper" if content == "paper" else ""
        names = scale_presets(scale, content)
        exps = [preset(n, content) for n in names]
        paths = [os.path.join(out, f"store-{exp.name}{suffix}") for exp in exps]
        pending = scheduler is None and any(
            _pending(e, p) for e, p in zip(exps, paths, strict=True)
        )
        pool = None
        n_workers = workers or os.cpu_count() or 1
        report_process = None
        if pending and n_workers > 1:
            report_process = _ReportProcess()
            stack.callback(report_process.close)
        if pending:
            _compile_first(workers, report=True, report_process=report_process is not None)
            if n_workers > 1:
                # one pool for both families: each worker starts (imports, loads the
                # compiled kernels) once
                pool = stack.enter_context(local_pool(workers))
        for exp, path in zip(exps, paths, strict=True):
            click.echo(exp.summary())
            store = _run_one(exp, path, workers, scheduler, progress, wait, executor=pool)
            click.echo(store.summary())
            stores.append(path)
        if pool is not None:
            pool.shutdown()  # the sweep workers end before the report starts its own
        report_dir = os.path.join(out, f"report{suffix}")
        job = (stores, report_dir, workers, progress, pdf)
        report = report_process.build(*job) if report_process else _build_report(*job)
        if results is not None:
            # the study's page: docs/results/README.md from the same stores
            from kicktimes.report import write_results

            page = write_results(stores, results, workers=workers or os.cpu_count() or 1,
                                 command=f"kicktimes reproduce --study paper --scale {scale} "
                                 f"--results {results}")
    click.echo(f"report written to {report if report is not None else report_dir}")
    if results is not None:
        click.echo(f"page written to {page}")
