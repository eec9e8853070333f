"""``kicktimes run``, ``report`` and ``reproduce``: sweeps into stores, and their reports."""

from __future__ import annotations

import click

from kicktimes.cli._group import _cli_errors, option
from kicktimes.compilation import compile_first
from kicktimes.studies import STUDIES, studies_help


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


def _sweep_options(command):
    """The options of a command that runs sweeps: --workers, --scheduler, --progress, --wait
    (in that order in its help)."""
    for add in (_wait_option, _progress_option, _scheduler_option, _workers_option):
        command = add(command)
    return command


# library argument names -> the options that set them
_RUN_OPTIONS = {"store": "--out", "workers": "--workers", "scheduler": "--scheduler",
                "path": "--out"}


def _experiment(name_or_path):
    """The experiment of ``kicktimes run EXPERIMENT``: a TOML file, or a built-in preset's
    name (`kicktimes presets` lists them)."""
    import os

    from kicktimes.experiment import Experiment, disks_preset, preset, preset_names

    if os.path.isfile(name_or_path):
        return Experiment.from_toml(name_or_path)
    two, disks = preset_names()
    if name_or_path in two:
        return preset(name_or_path)
    if name_or_path in disks:
        return disks_preset(name_or_path)
    raise click.BadParameter(
        f"{name_or_path!r} is neither a TOML file nor a preset; the presets are "
        + ", ".join(two + disks) + " (kicktimes presets)", param_hint="'EXPERIMENT'")


@click.command("run")
@click.argument("experiment")
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Store directory (created; rerunning resumes it).")
@_sweep_options
def run_command(experiment, out, workers, scheduler, progress, wait):
    """Run (or resume) the sweep EXPERIMENT into the store --out.

    EXPERIMENT is a TOML file or the name of a built-in preset (kicktimes presets lists
    them; kicktimes presets NAME prints a preset's TOML, to copy and edit).

    \b
    Examples:
      kicktimes run quick_a --out stores/quick_a
      kicktimes presets family_b > my_b.toml   # edit it, then
      kicktimes run my_b.toml --out stores/b --scheduler tcp://host:8786
    """
    if workers is not None and scheduler is not None:
        raise click.UsageError("--workers sizes the local pool; it cannot go with --scheduler")
    with _cli_errors(_RUN_OPTIONS):
        exp = _experiment(experiment)
        click.echo(exp.summary())
        if scheduler is None and _pending(exp, out):
            compile_first(workers)
        store = _run_one(exp, out, workers, scheduler, progress, wait)
    click.echo(store.summary())


@click.command("presets")
@click.argument("name", required=False)
def presets_command(name):
    """List the built-in experiments, or print preset NAME as TOML.

    The two-disk presets (the paper's families, their controls and quick versions) are
    what kicktimes reproduce --study paper runs; the disks presets what --study disks
    runs. A two-disk preset's TOML is the file to copy and edit for your own sweep; a
    disks preset runs by its name (kicktimes run NAME).

    \b
    Examples:
      kicktimes presets
      kicktimes presets family_a > family_a.toml
    """
    from kicktimes.experiment import disks_preset, preset, preset_names

    two, disks = preset_names()
    if name is None:
        import textwrap

        width = max(map(len, two + disks)) + 2

        def line(n, description):
            return f"  {n:<{width}}" + textwrap.shorten(description, 96 - width,
                                                          placeholder=" ...")

        click.echo("two-disk presets (kicktimes presets NAME prints the TOML):")
        for n in two:
            click.echo(line(n, preset(n).description))
        click.echo("disks presets (kicktimes run NAME):")
        for n in disks:
            click.echo(line(n, disks_preset(n).description))
        return
    if name in disks:
        raise click.BadParameter(f"{name!r} is a disks preset: it has no TOML form; run it "
                                 f"with kicktimes run {name}", param_hint="'NAME'")
    if name not in two:
        raise click.BadParameter(f"{name!r} is not a preset; the two-disk presets are "
                                 + ", ".join(two), param_hint="'NAME'")
    click.echo(preset(name).to_toml(), nl=False)




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
        from kicktimes.report.process import build_stores_report

        path = build_stores_report(stores, out, workers, progress, pdf, force)
    click.echo(f"report written to {path if path is not None else out}")


_REPRODUCE_HELP = f"""Build a study's results page: run (or resume) its computation into --out
and write its page into --results.

\b
Studies (--study NAME, its page, what it answers):
{studies_help()}
  all        every study above, in this order, every page into --results

--study paper runs the paper's two families (and, at paper scale, their controls) as the
built-in presets (kicktimes presets lists them; with --content paper reduced to the
paper's own systems and diagnostics), builds the sweep report into OUT/report and, with
--results, the page README.md. Every page's "Generated" line names the command that
built it; docs/results/NAME.md is built with --scale paper --results docs/results.

\b
Examples:
  kicktimes reproduce --scale quick --out kicktimes-out
  kicktimes reproduce --study escape --scale paper --out work --results docs/results
  kicktimes reproduce --study all --scale paper --out work --results docs/results
"""


@click.command("reproduce", help=_REPRODUCE_HELP)
@click.option("--study", type=click.Choice([*STUDIES, "all"]), default="paper",
              show_default=True, help="The study to build (listed above).")
@click.option("--results", "results", type=click.Path(file_okay=False), default=None,
              help="Folder of the study's page: --study paper writes README.md there from its "
              "stores (none by default); every other study writes its page there (default "
              "OUT/results-NAME; with --study all, OUT/results).")
@click.option("--findings", "findings", type=click.Path(file_okay=False, exists=True),
              default=None,
              help="--study protocol and science: folder of the paper study's paper-scale "
              "findings tables (family_a_findings.csv, ...; e.g. docs/results) (default: "
              "--results, if it holds them).")
@option("--scale", type=click.Choice(["quick", "paper"]), default="quick",
        help="quick: a small version of the study; paper: the scale of its page in "
        "docs/results (the paper's full scale for paper and protocol).")
@click.option(
    "--content",
    type=click.Choice(["full", "paper"]),
    default="full",
    show_default=True,
    help="--study paper: full: the presets (the paper's systems and diagnostics plus the "
    "scatter-kicked systems, RQA at two thresholds, ACF curves); paper: the paper's own "
    "content only (3 systems, RR at eps = 0.001, R_1), under half the sweep's work, into "
    "store-<name>-paper and report-paper/.",
)
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Work folder: the studies' stores and caches (store-<name>, ...) and the "
              "sweep report (report/).")
@_sweep_options
@_pdf_option
def reproduce_command(study, results, findings, scale, content, out, workers, scheduler,
                      progress, wait, pdf):
    import os

    if study == "all":
        results = results if results is not None else os.path.join(out, "results")
        # each page names its own study's command, the one that rebuilds it alone
        for name in STUDIES:
            click.echo(f"== --study {name}", err=True)
            _reproduce_one(name, results, findings, scale, content, out, workers, scheduler,
                           progress, wait, pdf)
        return
    _reproduce_one(study, results, findings, scale, content, out, workers, scheduler,
                   progress, wait, pdf)


#: the options of some studies only: (reproduce's keyword, the command line's option)
_STUDY_OPTIONS = (("findings_dir", "--findings"), ("scheduler", "--scheduler"),
                  ("content", "--content"), ("wait", "--wait"), ("pdf", "--pdf"))


def _reproduce_one(study, results, findings, scale, content, out, workers, scheduler,
                   progress, wait, pdf, command=None):
    """`reproduce_command` for one study: ``STUDIES[study].reproduce`` with the common
    options and those of its own (`Study.options`) that were given; ``command`` (default:
    the study's own, `Study.command`) is the command its page's Generated line names."""
    import os
    import sys
    import warnings

    from kicktimes.experiment import StoreWarning

    spec = STUDIES[study]
    given = {"findings_dir": findings, "scheduler": scheduler,
             "content": None if content == "full" else content,
             "wait": wait or None, "pdf": pdf or None}
    options = {}
    for name, flag in _STUDY_OPTIONS:
        if given[name] is None:
            continue
        if name not in spec.options:
            where = ", ".join(s.name for s in STUDIES.values() if name in s.options)
            raise click.UsageError(f"{flag} applies to --study {where}, not to --study "
                                   f"{study}")
        options[name] = given[name]
    if workers is not None and scheduler is not None:
        raise click.UsageError("--workers sizes the local pool; it cannot go with --scheduler")
    if progress is None:
        progress = sys.stderr.isatty() and not os.environ.get("CI")
    show = warnings.showwarning

    def store_warnings_as_lines(message, category, *args, **kwargs):
        # a store's warning is one plain line; every other warning is shown as usual (and
        # none is kept: a study may warn millions of times)
        if issubclass(category, StoreWarning):
            click.echo(f"warning: {message}", err=True)
        else:
            show(message, category, *args, **kwargs)

    with _cli_errors(_RUN_OPTIONS), warnings.catch_warnings():
        warnings.simplefilter("always", StoreWarning)
        warnings.showwarning = store_warnings_as_lines
        page = spec.reproduce(out, scale=scale, results_dir=results, workers=workers,
                              progress=progress,
                              command=command or spec.command(scale, results), **options)
    click.echo(f"page written to {page}")
