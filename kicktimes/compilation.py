"""First-run compilation of the numba kernels: detect a cold cache, announce it, split it.

numba compiles each ``@njit(cache=True)`` kernel on its first call and stores the machine
code on disk (next to the source, or under ``NUMBA_CACHE_DIR``); later processes load it
in milliseconds. On a fresh install the sweep's kernels take tens of seconds to compile
(``python benchmarks/bench_compile.py`` measures them per kernel), so the command line
says so once, and compiles two groups of kernels in two processes at the same time instead
of one after the other in every worker: a tiny task of the two-disk system (its one-pass
kernel: simulation, tangent FTLE and uniform samples in one event loop; the recurrence and
the autocorrelation), and one of every kicked system (the kicked disk's one-pass kernel for
each kind of kick, the kinetic rate table, the recurrence again). ``kicktimes
reproduce`` leaves the report's kernels to its report process (`warm_report`), which
compiles them at the same time, while the sweep's groups compile.
"""

from __future__ import annotations

import sys

from kicktimes.billiard import KickLaw

__all__ = ["cold_kernels", "announce", "compile_first", "warm_up", "warm_sweep", "warm_report"]

#: (module, kernel, compile seconds measured by benchmarks/bench_compile.py on the
#: project's 2-core machine, inclusive of the kernels each one calls; the recurrence entry,
#: the kernel of the sweep's `rqa` call (not `_sweep`, which only `recurrence_rate` calls:
#: it stayed "cold" after every sweep), stands for all its kernels)
#: A sweep with the tangent FTLE (every preset) runs each trajectory once, through the
#: one-pass kernels (kicktimes.billiard.kernels.drive_two, .drive_one); the separate simulation and
#: tangent kernels are compiled on first use by the calls that need them.
SWEEP_KERNELS = (
    ("kicktimes.billiard.kernels.drive_two", "simulate_tangent_two_kernel", 5.5),
    ("kicktimes.billiard.kernels.drive_one", "simulate_tangent_one_kernel", 5.0),
    ("kicktimes.diagnostics._recurrence_kernels", "_sweep_lines_dense", 3.0),
    ("kicktimes.diagnostics.autocorrelation", "_acf_curve", 1.3),
    ("kicktimes.diagnostics.autocorrelation", "_select_checked", 0.2),
    # the kinetic-rate kicks' table of the rate against the angular momentum
    ("kicktimes.stats._kinetic_quadrature", "invariant_partner_rates", 2.0),
)
SIMULATE_KERNELS = (("kicktimes.billiard.kernels.drive_two", "simulate_two_kernel", 4.5),)
#: ``kicktimes simulate --disks``: the N-disk engine's loop, its variant without observers
#: (inlined helpers: 70 s to 180 s on the 2-core machine at a load of 10, 2026-11-26)
DISKS_KERNELS = (("kicktimes.billiard.kernels.disks", "drive", 60.0),)
#: What the report compiles beyond the sweep's kernels (``kicktimes reproduce``'s report
#: process warms them while the sweep's compile or run): the trajectory figures'
#: re-simulations (two disks with a collision log, the kicked disk plainly), the
#: recurrence plot's pair sweep (sorted cells, pairs collected), the hyperexponential EM of
#: the renewal fits, the exact KS law and the Ljung-Box statistic of the Poisson tests, the
#: Findings' bootstrap medians.
REPORT_KERNELS = (
    ("kicktimes.billiard.kernels.drive_two", "simulate_two_kernel", 2.0),
    ("kicktimes.billiard.kernels.drive_one", "simulate_one_kernel", 2.8),
    ("kicktimes.diagnostics._recurrence_kernels", "_sweep", 1.0),
    ("kicktimes.stats.distributions", "_em_steps", 0.5),
    ("kicktimes.stats.poisson", "pomeranz_cdf", 0.5),
    ("kicktimes.stats.iid_tests", "_ljung_box_rows", 1.9),
    ("kicktimes.stats.robust", "_bootstrap_nanmedians", 0.5),
)


def _is_cold(dispatcher) -> bool | None:
    """True if ``dispatcher`` has no valid on-disk cache entry, None if unknown."""
    try:
        # numba's own index reader: {} when the index is missing or stale (source changed)
        return not dispatcher._cache._cache_file._load_index()
    except Exception:  # private numba API: when it changes, say nothing rather than fail
        return None


def cold_kernels(kernels=SWEEP_KERNELS) -> list[tuple[str, str, float]]:
    """The entries of ``kernels`` whose compiled code is not in numba's cache."""
    import importlib

    cold = []
    for module, name, seconds in kernels:
        try:
            dispatcher = getattr(importlib.import_module(module), name)
        except (ImportError, AttributeError):
            continue
        if _is_cold(dispatcher):
            cold.append((module, name, seconds))
    return cold


def announce(kernels=SWEEP_KERNELS, *, stream=None, extra_seconds=0.0) -> float:
    """Print "compiling kicktimes' numba kernels (once, about N s)..." to stderr if some
    of ``kernels`` are not cached; return N (0 when everything is cached). ``extra_seconds``
    is added to the estimate: kernels compiled elsewhere at the same time (the report's,
    in `kicktimes reproduce`'s report process), whose modules are too costly to import
    here just to probe them."""
    cold = cold_kernels(kernels)
    if not cold:
        return 0.0
    seconds = sum(s for *_, s in cold) + extra_seconds
    n = max(5, 5 * round(seconds / 5))
    print(
        f"compiling kicktimes' numba kernels (once, about {n} s)...",
        file=stream or sys.stderr,
        flush=True,
    )
    return float(n)


def _warm_task(systems, diagnostics=None) -> None:
    """One tiny task of the quick preset with these ``systems`` (and ``diagnostics``): the
    very calls, argument types and observers (the one pass's uniform samples) of a
    sweep's task."""
    import dataclasses

    from kicktimes.experiment import execute_task, preset

    exp = preset("quick_a")
    exp = dataclasses.replace(exp, n_ics=1, n_steps=50, block_size=1, systems=systems,
                              diagnostics=diagnostics or exp.diagnostics)
    execute_task(exp, exp.tasks()[0])


def _warm_two(_):
    # the two-disk system exactly as a sweep task runs it: its one pass (simulation,
    # tangent FTLE and the uniform samples of the recurrence control), the recurrence rows
    # and the autocorrelation
    _warm_task(("two_particle",))


def _warm_one(_):
    # the kicked disk as a sweep task runs it, every kind of kick (Poisson and actual
    # times, uniform and scattering kicks, kinetic-rate kicks with their rate table), one
    # pass each, with the recurrence rows (compiled here too: the groups run at once); the
    # two-disk run that sets their rates is a plain simulation here
    _warm_task(("poisson", "actual", "poisson_scatter", "actual_scatter", "poisson_kinetic",
                "uniform_kinetic"),
               ("lyapunov", "recurrence_rate"))


def _warm_report_two(_):
    # the trajectory figures' two-disk run with a collision log and their kicked run (a
    # plain simulation: no FTLE, no observers); the Poisson tests' exact KS law (its
    # compiled branch: n <= 140 events, 0.75 < n D^2 <= 4) and Ljung-Box Q
    import numpy as np

    from kicktimes import initial_conditions, simulate_one_particle, simulate_two_particle
    from kicktimes.stats.iid_tests import ljung_box
    from kicktimes.stats.poisson import pomeranz_cdf

    ic = initial_conditions(1, 0.02, rng=0)[0]
    simulate_two_particle(ic, 0.02, n_steps=50, tau=0.3, log_collisions=True)
    simulate_one_particle(ic[0], 0.02, kicks=KickLaw(np.array([0.5, 1.0]), angle="uniform",
                                                     angles=np.zeros(2), sigma=1.0),
                          n_steps=50, tau=0.3,
                          sampling="paper")
    pomeranz_cdf(12, 0.3)
    ljung_box(np.arange(12.0), 2)


def _warm_report_one(_):
    # the recurrence plot's pairs (sorted cells); the renewal fits' EM; the findings'
    # bootstrap medians
    import numpy as np

    from kicktimes.diagnostics import recurrence_pairs
    from kicktimes.stats import bootstrap_nanmedians, compare_models

    rng = np.random.default_rng(0)
    recurrence_pairs(rng.uniform(-1.0, 1.0, (60, 2)), eps=1e-3)
    compare_models(rng.exponential(size=60), censored=rng.exponential(size=2))
    bootstrap_nanmedians(rng.uniform(size=(2, 5)), rng.integers(0, 5, size=(3, 5)))


def warm_sweep() -> None:
    """Load (or compile, on a cold cache) the sweep's kernels in this process, by running a
    tiny task of each kind (the one-pass kernels, the autocorrelation and the recurrence
    rows, with the sweep's own argument types).

    The command line does it before it forks the local pool: the workers inherit the
    loaded kernels instead of each loading them on its first task
    (``benchmarks/bench_startup.py``, section 1; docs/benchmarks.md).
    """
    _warm_two(None)
    _warm_one(None)


def warm_report() -> None:
    """Load (or compile, on a cold cache) the report's kernels in this process: what
    `kicktimes reproduce`'s report process does while the sweeps run, so that the report's
    workers, forked from it, inherit them."""
    _warm_report_two(None)
    _warm_report_one(None)


def _warm_group_two(report):
    _warm_two(None)
    if report:
        _warm_report_two(None)


def _warm_group_one(report):
    _warm_one(None)
    if report:
        _warm_report_one(None)


def warm_up(workers: int, *, report: bool = False) -> None:
    """Compile the sweep's kernels now (and the report's, with ``report=True``), the two
    groups in two processes at once (when ``workers >= 2``), so that the sweep's workers
    load them from the cache instead of each compiling all of them in turn. Does nothing
    when they are cached."""
    if not cold_kernels(SWEEP_KERNELS + REPORT_KERNELS if report else SWEEP_KERNELS):
        return
    if workers < 2:
        _warm_group_two(report)
        _warm_group_one(report)
        return
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=2) as pool:
        futures = [pool.submit(_warm_group_two, report), pool.submit(_warm_group_one, report)]
        for fut in futures:
            fut.result()


def compile_first(workers, kernels=None, *, report=False, report_process=False):
    """On a cold numba cache, say so once and compile the sweep's kernels (and the
    report's, with ``report``) up front, the independent groups in parallel
    (:mod:`kicktimes.compilation`); then, for a pool of several workers, load the sweep's
    kernels in this process, which the workers fork from. With ``report_process`` the
    report's kernels are left to the report process
    (`kicktimes.report.process.ReportProcess`), which compiles them while the sweeps run;
    the estimate includes them, and their modules (scipy.stats, statsmodels: about 1 s)
    are not imported here. ``kernels``: only announce those (the simulate commands)."""
    import os

    if kernels is not None:
        announce(kernels)
        return
    here = report and not report_process
    elsewhere = sum(s for *_, s in REPORT_KERNELS) if report and report_process else 0
    wanted = SWEEP_KERNELS + (REPORT_KERNELS if here else ())
    n_workers = workers or os.cpu_count() or 1
    if announce(wanted, extra_seconds=elsewhere):
        warm_up(n_workers, report=here)
    if n_workers > 1:
        # load them here, once: the pool's workers, forked from this process, inherit them
        warm_sweep()
