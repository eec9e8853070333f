"""The ``kicktimes`` command line (click).

Errors reach the user as one line naming the command-line option (``--radius``, not the
library's ``r``), with plain numbers; file-system errors (read-only folder, full disk)
too, never as a traceback.
"""

from __future__ import annotations

import contextlib
import math
import re

import click

from kicktimes import __version__

# numpy 2 reprs ("np.float64(-2.0)") leak into messages built with !r
_NUMPY_REPR = re.compile(r"\bnp\.(?:float|int|uint|bool_?)\d*\((.*?)\)")


def _plain(message: str, options: dict | None = None) -> str:
    """``message`` with numpy scalar reprs unwrapped and a leading library argument name
    replaced by its command-line option (``t_max must ...`` -> ``--t-max must ...``)."""
    message = _NUMPY_REPR.sub(r"\1", message)
    for name, option in (options or {}).items():
        pattern = rf"^{re.escape(name)}(?=[\s:\[]|$)"
        if re.match(pattern, message):
            return re.sub(pattern, option, message, count=1)
    return message


def _os_message(exc: OSError) -> str:
    """One line for a file-system error: what failed and on which path."""
    what = exc.strerror or str(exc)
    if exc.filename is not None:
        return f"{what}: {exc.filename}"
    return what


@contextlib.contextmanager
def _cli_errors(options: dict | None = None):
    """Turn library and file-system errors into one-line click errors."""
    from kicktimes.experiment.store import StoreLockedError

    try:
        yield
    except click.ClickException:
        raise
    except OSError as exc:
        raise click.ClickException(_plain(_os_message(exc), options)) from None
    except (ValueError, TypeError, ImportError, StoreLockedError, RuntimeError) as exc:
        raise click.ClickException(_plain(str(exc), options)) from None


class _Real(click.ParamType):
    """A finite float in an open interval, checked by click so errors name the option."""

    name = "float"

    def __init__(self, low=None, high=None):
        self.low, self.high = low, high

    def convert(self, value, param, ctx):
        if isinstance(value, float):
            x = value
        else:
            try:
                x = float(value)
            except (TypeError, ValueError):
                self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(x):
            self.fail(f"must be finite, got {x}", param, ctx)
        if (self.low is not None and x <= self.low) or (self.high is not None and x >= self.high):
            lo = "-inf" if self.low is None else f"{self.low:g}"
            hi = "inf" if self.high is None else f"{self.high:g}"
            self.fail(f"must lie in ({lo}, {hi}), got {x:g}", param, ctx)
        return x


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="kicktimes")
def main():
    """kicktimes: collision-time processes in circular billiards."""
    # the command owns its process: freed arrays are kept for reuse instead of being
    # returned to the system and faulted in again by the next kernel call, and the cyclic
    # garbage collector runs less often until the command ends (the sweep's and the
    # report's forked workers inherit both; see kicktimes._memory)
    from kicktimes._memory import fewer_collections, keep_freed_memory

    keep_freed_memory()
    click.get_current_context().with_resource(fewer_collections())


# --- simulate command -------------------------------------------------------------------
@main.command("simulate")
@click.option(
    "--radius",
    "-r",
    "radii",
    type=_Real(0.0, 0.5),
    multiple=True,
    default=(0.01, 0.02),
    show_default=True,
    help="Disk radius (repeat for several), 0 < r < 0.5.",
)
@click.option(
    "--n-ics",
    type=click.IntRange(min=1),
    default=100,
    show_default=True,
    help="Number of initial conditions (drawn once, at the largest radius).",
)
@click.option(
    "--t-max", type=_Real(0.0), default=1000.0, show_default=True, help="Run time per IC."
)
@click.option(
    "--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Ensemble seed."
)
@click.option(
    "--rule",
    type=click.Choice(["mirror", "elastic"]),
    default="mirror",
    show_default=True,
    help="Disk-disk collision rule.",
)
@click.option(
    "--ic-method",
    type=click.Choice(["paper", "uniform"]),
    default="paper",
    show_default=True,
    help="'paper' procedure or the invariant measure.",
)
@click.option(
    "--out", "out", type=click.Path(file_okay=False), required=True, help="Output folder (created)."
)
@click.option("--save-runs", is_flag=True, help="Also write every run (boundary log) to OUT/runs/.")
def simulate_command(radii, n_ics, t_max, seed, rule, ic_method, out, save_runs):
    """Simulate two-disk billiards and log every disk-disk collision.

    Writes OUT/collisions.parquet (one row per radius and IC: radius, ic, t_window, n_pp,
    pp_times) with the parameters in its metadata, and prints, per radius, the mean
    number of disk-disk collisions per IC beside the kinetic-theory expectation
    (exact for --ic-method uniform).
    """
    import json
    import os

    import numpy as np
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq
    from tqdm.auto import tqdm

    from kicktimes import initial_conditions, simulate_two_particle
    from kicktimes.fileio import atomic_write
    from kicktimes.stats import kinetic_rate

    # the options are range-checked by click; this maps anything the library still
    # refuses back to the option that caused it
    options = {"r_max": "--radius", "r": "--radius", "n": "--n-ics", "t_max": "--t-max",
               "seed": "--seed", "rule": "--rule", "method": "--ic-method"}
    from kicktimes._compile import SIMULATE_KERNELS

    _compile_first(None, SIMULATE_KERNELS)
    with _cli_errors(options):
        ics = initial_conditions(n_ics, max(radii), seed=seed, method=ic_method, rule=rule)
        for r in radii:
            simulate_two_particle(ics[0], r, t_max=t_max, rule=rule)  # validates r, t_max
        os.makedirs(out, exist_ok=True)
    rows = []
    quiet = bool(os.environ.get("CI")) or not os.isatty(2)
    with _cli_errors(options), tqdm(total=len(radii) * n_ics, disable=quiet,
                                    desc="simulate") as bar:
        for r in radii:
            for i, ic in enumerate(ics):
                run = simulate_two_particle(ic, r, t_max=t_max, rule=rule, seed=seed)
                rows.append((r, i, run.t_max, run.n_pp, run.pp_times))
                if save_runs:
                    run.to_parquet(os.path.join(out, "runs", f"r{r:.4f}-ic{i:05d}.parquet"))
                bar.update()
    table = pa.table(
        {
            "radius": pa.array([row[0] for row in rows], pa.float64()),
            "ic": pa.array([row[1] for row in rows], pa.int64()),
            "t_window": pa.array([row[2] for row in rows], pa.float64()),
            "n_pp": pa.array([row[3] for row in rows], pa.int64()),
            "pp_times": pa.array([row[4] for row in rows], pa.list_(pa.float64())),
        }
    )
    meta = dict(
        radii=list(radii),
        n_ics=n_ics,
        t_max=t_max,
        seed=seed,
        rule=rule,
        ic_method=ic_method,
        version=__version__,
    )
    table = table.replace_schema_metadata({b"kicktimes": json.dumps(meta).encode()})
    path = os.path.join(out, "collisions.parquet")
    with _cli_errors():
        atomic_write(path, lambda tmp: pq.write_table(table, tmp))
    df = pd.DataFrame({"radius": table["radius"].to_numpy(), "n_pp": table["n_pp"].to_numpy()})
    summary = df.groupby("radius").n_pp.agg(["mean", "std", "count"])
    summary["sem"] = summary["std"] / np.sqrt(summary["count"])
    summary["kinetic"] = [kinetic_rate(r, rule=rule) * t_max for r in summary.index]
    click.echo(f"{n_ics} ICs ({ic_method}), rule={rule}, t_max={t_max:g}, seed={seed}")
    click.echo(f"{'radius':>8} {'mean n_pp':>10} {'± sem':>8} {'kinetic':>9}")
    for r, row in summary.iterrows():
        click.echo(f"{r:8.4f} {row['mean']:10.2f} {row['sem']:8.2f} {row['kinetic']:9.2f}")
    note = ("exact at the largest radius, where the ICs are invariant-measure draws"
            if ic_method == "uniform" else "the invariant-measure value; 'paper' ICs differ")
    click.echo(f"kinetic = Gamma(r) * t_max ({note})")
    click.echo(f"wrote {path}")


# --- end simulate command ---------------------------------------------------------------


# --- schedule command (kick-schedule generator) -----------------------------------
def _parse_schedule_params(params):
    parsed = {}
    for item in params:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise click.BadParameter(f"expected NAME=VALUE, got {item!r}", param_hint="--param")
        try:
            parsed[name.strip()] = float(value)
        except ValueError:
            raise click.BadParameter(
                f"{name.strip()} must be a number, got {value!r}", param_hint="--param"
            ) from None
    return parsed


_SCHEDULE_OPTIONS = {"t_max": "--t-max", "seed": "--seed", "window": "--window",
                     "times": "--input", "dist": "--dist", "path": "--output"}


@main.command("schedule")
@click.argument(
    "model", type=click.Choice(["poisson", "renewal", "bootstrap", "replay", "json"], False)
)
@click.option(
    "--param",
    "-p",
    "params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Model parameter, repeatable: rate=R (poisson); shape names, loc, scale (renewal).",
)
@click.option("--dist", help="Interval distribution for renewal: a scipy.stats name, e.g. gamma.")
@click.option(
    "--stationary/--no-stationary",
    default=False,
    help="Renewal/bootstrap: first interval from the equilibrium law (stationary from t=0).",
)
@click.option(
    "--input",
    "input_path",
    type=click.Path(exists=True, dir_okay=False),
    help="bootstrap/replay: CSV/Parquet file of event times; json: a schedule JSON file.",
)
@click.option(
    "--window",
    type=_Real(0.0),
    default=None,
    help="replay: observation window of the input times (sampling beyond it is an error).",
)
@click.option("--t-max", "t_max", type=_Real(0.0), required=True, help="Horizon: kicks in (0, T].")
@click.option(
    "--seed",
    type=click.IntRange(min=0),
    default=None,
    help="Integer seed (default: fresh entropy, printed and stored so the run can be redone).",
)
@click.option(
    "--output",
    "-o",
    type=click.Path(dir_okay=False),
    required=True,
    help="Output file, .csv or .parquet (one column kick_time, metadata inside).",
)
@click.option("--print-json", is_flag=True, help="Also print the schedule's JSON.")
def schedule_command(
    model, params, dist, stationary, input_path, window, t_max, seed, output, print_json
):
    """Generate kick times from a schedule MODEL and write them to a file.

    \b
    Examples:
      kicktimes schedule poisson -p rate=0.5 --t-max 1000 --seed 1 -o kicks.parquet
      kicktimes schedule renewal --dist gamma -p a=2 -p scale=0.5 --stationary \\
          --t-max 1000 --seed 1 -o kicks.csv
      kicktimes schedule bootstrap --input pp_times.csv --t-max 1000 --seed 2 -o boot.csv
      kicktimes schedule json --input schedule.json --t-max 1000 --seed 3 -o kicks.csv
    """
    import numpy as np

    from kicktimes import schedules

    try:
        if model == "json":
            if input_path is None or params or dist or stationary or window is not None:
                raise click.UsageError("model json takes only --input SCHEDULE.json")
            with open(input_path) as fh:
                schedule = schedules.from_json(fh.read())
        else:
            schedule = schedules.from_spec(
                model,
                _parse_schedule_params(params),
                dist=dist,
                stationary=stationary,
                times=input_path,
                window=window,
            )
        if seed is None:
            seed = int(np.random.SeedSequence().entropy)
        times = schedule.sample(t_max, seed)
        path = schedules.write_kick_times(times, output, t_max=t_max, schedule=schedule, seed=seed)
    except (ValueError, TypeError) as exc:
        raise click.UsageError(_plain(str(exc), _SCHEDULE_OPTIONS)) from None
    except OSError as exc:
        raise click.ClickException(_plain(_os_message(exc))) from None
    mean = f"{np.diff(times).mean():.6g}" if times.size > 1 else "n/a"
    click.echo(
        f"{schedule!r}: {times.size} kicks in (0, {t_max:g}], mean interval {mean}, "
        f"seed {seed} -> {path}"
    )
    if print_json:
        click.echo(schedule.to_json())


# --- end schedule command ------------------------------------------------------------


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


def _compile_first(workers, kernels=None, *, report=False, report_process=False):
    """On a cold numba cache, say so once and compile the sweep's kernels (and the
    report's, with ``report``) up front, the independent groups in parallel
    (:mod:`kicktimes._compile`); then, for a pool of several workers, load the sweep's
    kernels in this process, which the workers fork from. With ``report_process`` the
    report's kernels are left to the report process (`_ReportProcess`), which compiles
    them while the sweeps run; the estimate includes them, and their modules (scipy.stats,
    statsmodels: about 1 s) are not imported here."""
    import os

    from kicktimes import _compile

    if kernels is not None:
        _compile.announce(kernels)
        return
    here = report and not report_process
    elsewhere = sum(s for *_, s in _compile.REPORT_KERNELS) if report and report_process else 0
    wanted = _compile.SWEEP_KERNELS + (_compile.REPORT_KERNELS if here else ())
    n_workers = workers or os.cpu_count() or 1
    if _compile.announce(wanted, extra_seconds=elsewhere):
        _compile.warm_up(n_workers, report=here)
    if n_workers > 1:
        # load them here, once: the pool's workers, forked from this process, inherit them
        _compile.warm_sweep()


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


@main.command("run")
@click.argument("experiment", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False),
    required=True,
    help="Store directory (created; rerunning resumes it).",
)
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
    from kicktimes import _compile
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


@main.command("report")
@click.argument("stores", nargs=-1, required=True, type=click.Path(exists=True, file_okay=False))
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False),
    required=True,
    help="Report directory (HTML page, figures, tables).",
)
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


@main.command("reproduce")
@click.option(
    "--scale",
    type=click.Choice(["quick", "paper"]),
    default="quick",
    show_default=True,
    help="quick: small versions of both families; paper: the paper's full scale.",
)
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
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False),
    required=True,
    help="Directory for the stores (store-<name>) and the report (report/).",
)
@_workers_option
@_scheduler_option
@_progress_option
@_wait_option
@_pdf_option
def reproduce_command(scale, content, out, workers, scheduler, progress, wait, pdf):
    """Run the paper's two experiment families and build the report.

    Reruns resume the stores in --out. The experiments are the built-in presets, the
    same as analysis/<name>.toml (with --content paper, reduced to the paper's own
    systems and diagnostics: kicktimes.experiment.presets.PAPER_CONTENT).
    """
    import os

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
    click.echo(f"report written to {report if report is not None else report_dir}")


# --- end experiment commands ---


from kicktimes._cli_analyze import analyze_command  # noqa: E402

main.add_command(analyze_command)
