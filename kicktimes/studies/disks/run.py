"""``kicktimes reproduce --study disks``: the disks sweeps and the gas's FTLE computations,
run or resumed in one work folder, then the page.

`reproduce_disks` runs the presets of `kicktimes.experiment.DISKS_PRESETS` (their controls
and the two-disk references) into ``out/store-<name>``, the checks of the gas's FTLE
(`kicktimes.studies.disks.ftle_check`) and its sweep against density
(`kicktimes.studies.disks.density`) and the dispersion against the window in the circle
and the box (`kicktimes.studies.disks.windows`) into their caches in ``out``, writes those
computations' CSV tables into the results folder and then the page
(`kicktimes.studies.disks.page.write_disks_page`). A rerun reuses every complete store and
every cached table whose parameters match.
"""

from __future__ import annotations

import dataclasses
import os
import sys
from pathlib import Path

import pandas as pd

from kicktimes.experiment import DisksExperiment
from kicktimes.studies.disks.density import DENSITY, LyapunovDensity, write_lyapunov_density
from kicktimes.studies.disks.ftle_check import FTLE_CHECK, FtleCheck, write_ftle_check
from kicktimes.studies.disks.page import write_disks_page
from kicktimes.studies.disks.tables import sweep_cost
from kicktimes.studies.disks.windows import (
    DISPERSION_WINDOWS,
    DispersionWindows,
    write_dispersion_windows,
)
from kicktimes.studies.options import check_scale, check_workers

__all__ = ["QUICK_N", "quick_experiment", "reproduce", "reproduce_disks"]

#: the quick scale's numbers of disks (the paper scale's are 2 .. 1000)
QUICK_N = (2, 10, 100)
#: the quick scale's gas-FTLE checks and density law: a few states up to N = 100
QUICK_FTLE_CHECK = FtleCheck(ics=4, scale=0.2, max_disks=100)
QUICK_DENSITY = LyapunovDensity(n_disks=(100,), states=4, mean_free_times=30, skip=3)
#: the quick scale's D against the window: 100 disks, packing 0.02, short runs
QUICK_WINDOWS = DispersionWindows(n_disks=100, packings=(0.02,), windows=(15, 30, 60),
                                  states=2, length=60.0, skip=5.0)


def _progress_lines(progress):
    """``(say, bar)``: the callable taking the FTLE computations' lines (or None) and the
    ``progress`` for `run_experiment`, from ``reproduce_disks``'s ``progress``."""
    if callable(progress):
        return progress, False
    show = (progress if progress is not None
            else sys.stderr.isatty() and not os.environ.get("CI"))
    return ((lambda line: print(line, file=sys.stderr, flush=True)) if show else None,
            progress)


def quick_experiment(exp):
    """The quick version of a disks preset (the same name and design): N in `QUICK_N`,
    at most 200 tagged disks per N (the N = 2 validation 1000), the kicked comparison 4
    runs of 50 mean free times, a two-disk reference with as many ICs as its row's
    tagged disks."""
    if isinstance(exp, DisksExperiment):
        if exp.kicked_runs:
            return dataclasses.replace(exp, n_disks=QUICK_N, n_tagged=4, min_runs=4,
                                       kicked_runs=4, kicked_time=50.0)
        n_disks = tuple(n for n in exp.n_disks if n in QUICK_N)
        return dataclasses.replace(exp, n_disks=n_disks,
                                   n_tagged=min(exp.n_tagged, 1000 if n_disks == (2,) else 200))
    return dataclasses.replace(exp, n_ics=min(exp.n_ics, 1000 if exp.n_ics > 4000 else 200))


def reproduce(out, *, scale="quick", results_dir=None, workers=1, progress=None,
              command=None, scheduler=None) -> Path:
    """The disks study at ``scale`` (`reproduce_disks`, the options of every study:
    `kicktimes.studies.options`): ``"paper"`` the presets of docs/results/disks.md (N = 2 ..
    1000, about an hour on 2 cores), ``"quick"`` their `quick_experiment` versions with
    `QUICK_FTLE_CHECK` and `QUICK_DENSITY`, in ``out/disks-quick`` (a few minutes)."""
    check_scale(scale, ("quick", "paper"))
    command = command or f"kicktimes reproduce --study disks --scale {scale}"
    options = dict(results_dir=results_dir, workers=workers, scheduler=scheduler,
                   progress=progress, command=command)
    if scale == "paper":
        return reproduce_disks(out, **options)
    if results_dir is None:
        options["results_dir"] = os.path.join(out, "results-disks")
    return reproduce_disks(os.path.join(out, "disks-quick"), experiment=quick_experiment,
                           ftle_check=QUICK_FTLE_CHECK, density=QUICK_DENSITY,
                           windows=QUICK_WINDOWS, **options)


def reproduce_disks(out, *, results_dir=None, names=None, workers=1, scheduler=None,
                    progress=None, command="kicktimes reproduce --study disks --scale paper",
                    ftle_check=FTLE_CHECK, density=DENSITY, windows=DISPERSION_WINDOWS,
                    experiment=None) -> Path:
    """Run (or resume) the disks presets into ``out/store-<name>`` and the gas's FTLE
    computations into ``out``, then write the page.

    Parameters
    ----------
    out : path-like
        Folder of the stores and of the FTLE computations' cache (``out/ftle-check``,
        ``out/lyapunov-density``).
    results_dir : path-like, optional
        Where the page goes (default ``out/results-disks``).
    names : sequence of str, optional
        Presets (default every one of `kicktimes.experiment.DISKS_PRESETS`, their controls
        `DISKS_CONTROLS` and the two-disk references `DISKS_REFERENCES`).
    workers, scheduler :
        As in `kicktimes.experiment.run_experiment`; the FTLE computations run on
        ``workers`` local processes (one if ``workers`` is None).
    progress : bool or callable, optional
        As in `run_experiment` (a progress bar; default: on a terminal, not under CI);
        the FTLE computations then say what they compute or reuse on stderr. A callable
        takes those lines instead (and no bar is shown).
    command : str
        The command the page's "Generated" line names.
    ftle_check : kicktimes.studies.disks.ftle_check.FtleCheck or None
        The checks of the gas's FTLE (`write_ftle_check`; default the published ones,
        about 10 minutes on one core from scratch); None: not run (the page renders a
        ``disks_ftle_check.csv`` already in ``results_dir``, if any).
    density : kicktimes.studies.disks.density.LyapunovDensity or None
        The FTLE against density (`write_lyapunov_density`; default the published sweep);
        None: not run, as ``ftle_check``.
    windows : kicktimes.studies.disks.windows.DispersionWindows or None
        D against the window in the circle and the box (`write_dispersion_windows`;
        default the published sweep); None: not run, as ``ftle_check``.
    experiment : callable, optional
        Maps each preset to the experiment run under its name (`quick_experiment` for the
        quick scale); default the presets themselves.

    Returns
    -------
    pathlib.Path
        The page, ``results_dir / "disks.md"``.
    """
    from kicktimes.experiment import (
        DISKS_CONTROLS,
        DISKS_PRESETS,
        DISKS_REFERENCES,
        disks_preset,
        run_experiment,
    )

    pool = 1 if workers is None else check_workers(workers)
    # before the sweeps: a wrong argument is found in a second, not after hours
    for name, value, kind in (("ftle_check", ftle_check, FtleCheck),
                              ("density", density, LyapunovDensity),
                              ("windows", windows, DispersionWindows)):
        if value is not None and not isinstance(value, kind):
            raise ValueError(f"{name} must be a {kind.__name__} or None, got {value!r}")
    say, bar = _progress_lines(progress)
    names = list(names or [*DISKS_PRESETS, *DISKS_CONTROLS, *DISKS_REFERENCES])
    paths, cost = [], []
    for name in names:
        path = os.path.join(out, f"store-{name}")
        exp = disks_preset(name) if experiment is None else experiment(disks_preset(name))
        store = run_experiment(exp, path, workers=workers if scheduler is None
                               else None, scheduler=scheduler, progress=bar)
        cost.append(sweep_cost(name, store))
        paths.append(path)
    target = results_dir if results_dir is not None else os.path.join(out, "results-disks")
    if ftle_check is not None:
        write_ftle_check(out, target, ftle_check, workers=pool, progress=say)
    if density is not None:
        write_lyapunov_density(out, target, density, workers=pool, progress=say)
    if windows is not None:
        write_dispersion_windows(out, target, windows, workers=pool, progress=say)
    return write_disks_page(paths, target, command=command, cost=pd.DataFrame(cost))
