"""Tasks of a sweep: one radius times one block of initial conditions.

`run_task` does all the physics of a task, for each IC of its block:

1. the two-particle run (disk 0 tracked): its diagnostics, and its disk-disk collision
   times for the collision-time table;
2. the Poisson-kicked one-particle billiard started from disk 0's IC, kicked at the rate
   ``n_pp / t_max`` of that IC's two-particle run (the paper's per-IC estimate);
3. the actual-time one-particle billiard, kicked at that run's disk-disk collision times;
4. optionally (``poisson_scatter``, ``actual_scatter``) the same two kinds of kick times
   with scattering kicks, a collision with a virtual partner (docs/scatter.md);
5. optionally (``mmpp``) the kicks of the Poisson system at the times of a two-state
   Markov-modulated Poisson process fitted to that IC's collision times (`mmpp_kicks`).

With ``partner_ratio`` or ``partner_mass`` (unequal disks, docs/unequal.md) the
two-particle run is that of disk 0 (radius ``r``, the one the one-disk systems kick) and
disk 1 (``Experiment.radius_pair``, ``Experiment.masses``), its collision times are disk
0's with disk 1, and the scattering kicks meet a partner of disk 1's radius and mass.

Every random number of (IC, radius, system) comes from its own
``SeedSequence(seed, spawn_key=(KICK_DOMAIN, ic, radius bits, system code))``, so the
results do not depend on the block size, the worker count or the executor, nor on which
other radii the experiment holds. The kick angles are drawn once and given to both the
run and its Lyapunov twins (common random numbers).
"""

from __future__ import annotations

import functools
import math
import struct
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from kicktimes._results import TableResult
from kicktimes.experiment.config import KINETIC_SYSTEMS, Experiment

if TYPE_CHECKING:
    from kicktimes.billiard.kick_law import KickLaw
from kicktimes.experiment.plan import Task, make_tasks
from kicktimes.stats import MMPP_MIN_EVENTS
from kicktimes.validation import RENAMED_MARKER, check_seed_sequence

__all__ = [
    "COLLISION_COLUMNS",
    "RESULT_COLUMNS",
    "Task",
    "TaskOutput",
    "execute_task",
    "kick_law",
    "kick_rng",
    "make_tasks",
    "mmpp_kicks",
    "run_task",
    "task_initial_conditions",
    "uniform_samples",
]

RESULT_COLUMNS = ("radius", "ic", "system", "diagnostic", "value", "note")
COLLISION_COLUMNS = ("radius", "ic", "t_window", "n_pp", "pp_times")

#: First spawn-key word of the kick streams; IC streams use ``spawn_key=(i,)``, so the two
#: families of streams can never coincide (their keys differ in length and content).
KICK_DOMAIN = 0x6B69636B  # "kick"
SYSTEM_CODES = {"two_particle": 0, "poisson": 1, "actual": 2, "poisson_scatter": 3,
                "actual_scatter": 4, "poisson_kinetic": 5, "mmpp": 6,
                "uniform_kinetic": 7}
#: the rows of the ``mmpp`` system that describe its fit (NaN, with the reason, without one)
MMPP_ROWS = ("mmpp_rate_low", "mmpp_rate_high", "mmpp_switch_low", "mmpp_switch_high",
             "mmpp_delta_aic")


def _radius_key(radius: float) -> int:
    # the float's bit pattern: a stream is tied to the radius value, not to its index
    return struct.unpack("<Q", struct.pack("<d", float(radius)))[0]


def _kick_rng(ic: int, radius: float, system: str, *, rng) -> np.random.Generator:
    """The generator of the kick times and angles of one (IC, radius, system).

    ``rng`` is the sweep's root (`kicktimes.validation.check_seed_sequence`: an int seed
    or a SeedSequence; a Generator is consumed): the stream is the root's child
    ``spawn_key=(KICK_DOMAIN, ic, radius bits, system code)``, so ``rng=seed`` gives
    exactly the stream of the old ``kick_rng(seed, ic, radius, system)``.

    >>> bool(kick_rng(0, 0.01, "poisson", rng=7).random() == kick_rng(0, 0.01, "poisson",
    ...                                                              rng=7).random())
    True
    """
    root = check_seed_sequence(rng, "rng")
    key = (*root.spawn_key, KICK_DOMAIN, int(ic), _radius_key(radius), SYSTEM_CODES[system])
    return np.random.default_rng(
        np.random.SeedSequence(root.entropy, spawn_key=key, pool_size=root.pool_size))


@functools.wraps(_kick_rng)
def kick_rng(*args, **kwargs) -> np.random.Generator:
    # the old spelling kick_rng(seed, ic, radius, system) (or seed=): the root first, by
    # position; deprecated since 0.2.0 (CHANGELOG.md), the stream unchanged
    if "seed" in kwargs or len(args) == 4:
        if "rng" in kwargs:
            raise TypeError("kick_rng() got both the old root (seed) and rng=; pass only rng=")
        if len(args) == 4:
            seed, args = args[0], args[1:]
        else:
            seed = kwargs.pop("seed")
        warnings.warn("kick_rng(seed, ic, radius, system) is deprecated since 0.2.0 and will "
                      "be removed in 0.3.0; use kick_rng(ic, radius, system, rng=seed)",
                      DeprecationWarning, stacklevel=2)
        kwargs["rng"] = seed
    return _kick_rng(*args, **kwargs)


setattr(kick_rng, RENAMED_MARKER, {"seed": "rng"})


class _Timer:
    """Accumulates wall time per named stage of a task (aggregated by the benchmark)."""

    def __init__(self):
        self.seconds: dict[str, float] = {}

    @contextmanager
    def __call__(self, name):
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[name] = self.seconds.get(name, 0.0) + time.perf_counter() - t0


@dataclass(frozen=True, repr=False)
class TaskOutput(TableResult):
    """What a worker returns: the task's two tables and its stage timings (seconds)."""

    _title = "The tables of one task of a sweep (what a worker returns)"
    _frame = "results"

    task: Task
    results: pd.DataFrame
    collisions: pd.DataFrame
    timings: dict = field(default_factory=dict)


def _check_task(experiment, task):
    if not isinstance(experiment, Experiment):
        raise TypeError(f"experiment: expected an Experiment, got {type(experiment).__name__}")
    if not isinstance(task, Task):
        raise TypeError(f"task: expected a Task, got {type(task).__name__}")
    ri = task.radius_index
    if not (0 <= ri < len(experiment.radii)) or experiment.radii[ri] != task.radius:
        raise ValueError(
            f"task: radius index {ri} / radius {task.radius!r} is not one of the experiment's "
            f"radii {list(experiment.radii)}"
        )
    if not (0 <= task.ic_start < task.ic_stop <= experiment.n_ics):
        raise ValueError(
            f"task: IC range [{task.ic_start}, {task.ic_stop}) must lie in [0, "
            f"{experiment.n_ics}) and be non-empty"
        )


def run_task(experiment: Experiment, task: Task) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Simulate one task and compute its diagnostics.

    Parameters
    ----------
    experiment : Experiment
    task : Task
        One of ``experiment.tasks()``.

    Returns
    -------
    results : DataFrame
        Tidy rows ``radius, ic, system, diagnostic, value, note`` (docs/experiments.md
        lists the diagnostics); ``value`` is NaN where undefined and ``note`` says why.
    collisions : DataFrame
        One row per IC: ``radius, ic, t_window`` (the two-particle run's duration),
        ``n_pp`` and ``pp_times`` (array of disk-disk collision times in ``(0, t_window]``).

    Examples
    --------
    >>> from kicktimes.experiment import Experiment, run_task
    >>> exp = Experiment(name="demo", radii=[0.02], n_ics=2, n_steps=200, tau=0.3,
    ...                  diagnostics=["recurrence_rate"])
    >>> results, collisions = run_task(exp, exp.tasks()[0])
    >>> sorted(results["system"].unique())
    ['actual', 'poisson', 'two_particle']
    """
    out = execute_task(experiment, task)
    return out.results, out.collisions


def execute_task(experiment: Experiment, task: Task, *, one_pass: bool = True) -> TaskOutput:
    """`run_task` plus the per-stage timings, as a `TaskOutput` (what workers return).

    ``one_pass=False`` computes every trajectory by separate calls (a simulation, then
    its FTLE, then the two-disk continuation for the actual-time kicks) instead of one
    event loop per trajectory: the same tables bit for bit (tested), several times slower;
    it exists as the reference the one-pass sweep is checked against.
    """
    _check_task(experiment, task)
    timer = _Timer()
    t0 = time.perf_counter()
    ics = task_initial_conditions(experiment, task)
    rows: list[tuple] = []
    coll: list[tuple] = []
    for k in range(task.n_ics):
        _run_ic(experiment, task.radius, task.ic_start + k, ics[k], rows, coll, timer,
                one_pass=one_pass)
    with timer("tables"):
        results = pd.DataFrame(rows, columns=list(RESULT_COLUMNS))
        results = results.astype({"radius": "float64", "ic": "int64", "value": "float64"})
        collisions = pd.DataFrame(coll, columns=list(COLLISION_COLUMNS))
        collisions = collisions.astype(
            {"radius": "float64", "ic": "int64", "t_window": "float64", "n_pp": "int64"}
        )
    timer.seconds["total"] = time.perf_counter() - t0
    return TaskOutput(task, results, collisions, timer.seconds)


def task_initial_conditions(experiment: Experiment, task: Task) -> np.ndarray:
    """The initial conditions of ``task``'s ICs, shape ``(n_ics, 2, 4)``, read-only.

    Every radius of an experiment starts from the same ICs (drawn at ``ic_radius``), so a
    worker that runs a block of ICs at several radii draws them once: the draws are kept
    per process (`_cached_ics`; about 0.16 ms per IC with the correctly rounded
    ``cos_sin``, 12 radii share them in family A).
    """
    masses = None if experiment.masses is None else tuple(experiment.masses)
    return _cached_ics(task.n_ics, experiment.ic_radius, experiment.seed, experiment.ic_method,
                       experiment.rule, task.ic_start, masses, experiment.table)


@functools.lru_cache(maxsize=64)
def _cached_ics(n_ics, ic_radius, seed, method, rule, start, masses, table="circle"):
    from kicktimes.billiard.initial import initial_conditions
    from kicktimes.billiard.tables import parse_table

    where = {} if table == "circle" else {"table": parse_table(table)}
    ics = initial_conditions(n_ics, ic_radius, rng=seed, method=method, rule=rule,
                             start=start, masses=masses, **where)
    ics.flags.writeable = False  # shared by every radius: nothing may change it
    return ics


def _lyapunov():
    # the module path, not the package attribute: works whatever the package exports
    from kicktimes.diagnostics.lyapunov import lyapunov

    return lyapunov


def _lyapunov_pass():
    from kicktimes.diagnostics.lyapunov import lyapunov_pass

    return lyapunov_pass


def _run_ic(exp: Experiment, r: float, ic_index: int, ic: np.ndarray, rows, coll, timer, *,
            one_pass: bool = True):
    from kicktimes.billiard.one_particle import draw_kick_angles
    from kicktimes.billiard.two_particle import simulate_two_particle
    from kicktimes.diagnostics import boundary_angles
    from kicktimes.schedules import Poisson

    steps = {"n_steps": exp.n_steps, "tau": exp.tau, "sampling": exp.sampling}
    if not exp.log_events:
        _run_ic_log_free(exp, r, ic_index, ic, rows, timer, steps)
        return
    # holes in the wall: every run (and its FTLE) ends at its escape
    holes = {"holes": np.array(exp.holes)} if exp.holes else {}
    # the two-disk system: disk 0 of radius r, disk 1 of the partner's radius and mass
    pair, two_kw = exp.radius_pair(r), _two_disk_kw(exp)
    ftle_method = _ftle_method(exp)
    diags = exp.diagnostics

    def add(system, diagnostic, value, note=""):
        value = float(value)
        if not math.isfinite(value) and not note:
            note = f"{diagnostic} is not finite ({value!r})"
        rows.append((r, ic_index, system, diagnostic, value, note))

    def resampled(system, run, uniform):
        # the uniform samples recorded by the run's one pass, or a re-simulation
        if uniform is not None:
            return uniform
        with timer("recurrence_resampling"):
            return uniform_samples(exp, system, ic, r, run)

    def diagnose(system, run, ftle, uniform=None):
        if "recurrence_rate" in diags:
            points = run.samples
            if exp.rr_sampling == "uniform":
                points = resampled(system, run, uniform)
            with timer("recurrence_rate"):
                for diagnostic, value, note in recurrence_rows(points, exp.eps):
                    add(system, diagnostic, value, note)
            if exp.rr_sampling == "run+uniform":
                # the uniform-sampling control: the same trajectory sampled at k tau
                points = resampled(system, run, uniform)
                with timer("recurrence_rate"):
                    for diagnostic, value, note in recurrence_rows(points, exp.eps):
                        if "@" in diagnostic:
                            add(system, UNIFORM_PREFIX + diagnostic, value, note)
        if "autocorrelation" in diags:
            with timer("autocorrelation"):
                theta = boundary_angles(run, particle=0 if system == "two_particle" else None)
                acf_rows = autocorrelation_rows(theta, exp.lag, exp.acf_max_lag)
            for diagnostic, value, note in acf_rows:
                add(system, diagnostic, value, note)
        if "lyapunov" in diags:
            with timer(f"lyapunov_{'two_particle' if system == 'two_particle' else 'kicked'}"):
                res = ftle()
            add(system, "lyapunov", res.lam)
            if exp.lyapunov_variant == "paper":
                add(system, "lyapunov_x", res.lam_x)
                add(system, "lyapunov_y", res.lam_y)
            add(system, "lyapunov_n_renorm", res.n_renorm)
            add(system, "lyapunov_n_forced", res.n_forced)

    # One pass per trajectory: with the tangent FTLE among the diagnostics, one event loop
    # gives each run and its exponent (and, for the actual-time systems, the two-disk
    # collision times beyond the sampled window), bitwise what separate calls give; its
    # time is recorded under "lyapunov_*" (simulation + FTLE)
    one_pass = one_pass and "lyapunov" in diags and exp.lyapunov_method == "tangent"
    # the one passes also record the uniform samples of a paper run (lyapunov_pass), which
    # the recurrence control would otherwise get by simulating the trajectory again
    uniform_kw = {"uniform": True} if (
        one_pass and not holes and exp.sampling == "paper" and "recurrence_rate" in diags
        and exp.rr_sampling in ("uniform", "run+uniform")) else {}
    two_uniform = None
    horizon = exp.horizon
    continued = None
    two_pass = one_pass and "two_particle" in exp.systems
    if two_pass and holes:
        # the run ends at its escape: no continuation to the horizon
        with timer("lyapunov_two_particle"):
            res_two, two = _lyapunov()(ic, pair, track=0,
                                       method=_tangent(exp.lyapunov_variant, return_run=True),
                                       **holes, **two_kw, **steps)
        continued = two.pp_times
    elif two_pass:
        with timer("lyapunov_two_particle"):
            res_two, two, continued, *more = _lyapunov_pass()(
                ic, pair, track=0, method=_tangent(exp.lyapunov_variant),
                t_continue=horizon if exp.sampling == "paper" else 0.0, **two_kw, **steps,
                **uniform_kw,
            )
        two_uniform = more[0] if more else None
    else:
        with timer("simulation_two_particle"):
            two = simulate_two_particle(ic, pair, track=0, **holes, **two_kw, **steps)
        if holes:
            continued = two.pp_times
    n_b0 = int(np.count_nonzero(two.boundary_log.particle == 0))
    coll.append((r, ic_index, two.t_max, two.n_pp, np.array(two.pp_times, dtype=np.float64)))
    if "two_particle" in exp.systems:
        add("two_particle", "t_max", two.t_max)
        add("two_particle", "n_pp", two.n_pp)
        add("two_particle", "n_boundary", n_b0)
        if holes:
            none = "" if two.escaped >= 0 else "no escape by the end of the run"
            add("two_particle", "escape_time", two.escape_time, none)
            # which disk left (the run's `escaped`: 0, 1, or -1 for none): the kicked
            # systems follow disk 0, so disk 1's escape censors disk 0's (report/escape.py)
            add("two_particle", "escaped_disk", two.escaped, none)
        diagnose(
            "two_particle",
            two,
            (lambda: res_two) if two_pass else lambda: _lyapunov()(
                ic, pair, track=0, method=ftle_method, **holes, **two_kw, **steps,
            ),
            two_uniform,
        )

    actual_times = None
    for system in ("poisson", "actual", "poisson_scatter", "actual_scatter", "poisson_kinetic",
                   "uniform_kinetic", "mmpp"):
        if system not in exp.systems:
            continue
        kick = kick_law(exp, system, ic, r)
        rng = kick_rng(ic_index, r, system, rng=exp.seed)
        if system in ("poisson_kinetic", "uniform_kinetic"):
            # the event loop draws the kick times (and their scattering numbers) from rng
            one_kw = {"kicks": kick.replace(times=kinetic_rate_table(r, exp.rule)), "rng": rng,
                      **holes, **steps}
            _kicked(system, one_kw, one_pass, exp, ic, r, timer, add, diagnose,
                    uniform_kw=uniform_kw)
            continue
        if system.startswith("actual"):
            if actual_times is None:
                if continued is not None:
                    # the one pass went on to the horizon (_actual_times' continuation)
                    actual_times = np.array(continued, dtype=np.float64)
                else:
                    with timer("simulation_two_particle"):
                        actual_times = _actual_times(exp, ic, r, two)
            kick_times = actual_times
        extra = ()
        if system == "mmpp":
            with timer("mmpp_fit"):
                schedule, extra = mmpp_kicks(two.pp_times, two.t_max, rng)
        with timer("simulation_one_particle"):
            if system.startswith("poisson"):
                rate = two.n_pp / two.t_max
                kick_times = Poisson(rate).sample(horizon, rng=rng)
                extra = (("kick_rate", rate),)
            elif system == "mmpp":
                kick_times = schedule.sample(horizon, rng=rng)
            kick_angles = draw_kick_angles(kick_times.size, kick.angle, exp.sigma, rng)
        one_kw = {"kicks": kick.replace(times=kick_times, angles=kick_angles), **holes, **steps,
                  **table_kw(exp)}
        _kicked(system, one_kw, one_pass, exp, ic, r, timer, add, diagnose, extra,
                uniform_kw=uniform_kw)


def _run_ic_log_free(exp, r, ic_index, ic, rows, timer, steps):
    """One IC of an FTLE-only sweep without event logs (``exp.log_events`` false): each
    system's tangent FTLE from the event loop alone, with its perturbation count and
    duration from the `LyapunovResult` (memory O(1) in the horizon). The Poisson systems
    are kicked at the IC's own two-disk rate, as in `_run_ic`; nothing is sampled but the
    FTLE's renormalisation times. No collision times are stored (``coll`` stays empty)."""
    from kicktimes.billiard.one_particle import draw_kick_angles
    from kicktimes.schedules import Poisson

    lyapunov = _lyapunov()
    method = _tangent(exp.lyapunov_variant)

    def add(system, diagnostic, value):
        value = float(value)
        note = "" if math.isfinite(value) else f"{diagnostic} is not finite ({value!r})"
        rows.append((r, ic_index, system, diagnostic, value, note))

    def record(system, res, count):
        add(system, "t_max", res.total_time)
        add(system, count, res.n_perturbations)
        add(system, "lyapunov", res.lam)
        add(system, "lyapunov_n_renorm", res.n_renorm)
        add(system, "lyapunov_n_forced", res.n_forced)

    with timer("lyapunov_two_particle"):
        two = lyapunov(ic, exp.radius_pair(r), track=0, method=method, **_two_disk_kw(exp),
                       **steps)
    if "two_particle" in exp.systems:
        record("two_particle", two, "n_pp")
    for system in ("poisson", "poisson_scatter", "poisson_kinetic", "uniform_kinetic"):
        if system not in exp.systems:
            continue
        kick = kick_law(exp, system, ic, r)
        rng = kick_rng(ic_index, r, system, rng=exp.seed)
        with timer("lyapunov_kicked"):
            if system in KINETIC_SYSTEMS:
                res = lyapunov(ic[0], r, kicks=kick.replace(
                    times=kinetic_rate_table(r, exp.rule)), rng=rng, method=method, **steps)
            else:
                rate = two.n_perturbations / two.total_time
                times = Poisson(rate).sample(exp.horizon, rng=rng)
                angles = draw_kick_angles(times.size, kick.angle, exp.sigma, rng)
                res = lyapunov(ic[0], r, kicks=kick.replace(times=times, angles=angles),
                               method=method, **steps, **table_kw(exp))
                add(system, "kick_rate", rate)
        record(system, res, "n_kicks")


def _kicked(system, one_kw, one_pass, exp, ic, r, timer, add, diagnose, extra=(), *,
            uniform_kw=None):
    """Run the kicked ``system`` with the kicks ``one_kw`` (and its FTLE, in one pass or
    not), store its counts (``extra`` rows ``(name, value[, note])`` after ``t_max``) and
    diagnose it. ``uniform_kw`` (``{"uniform": True}`` or empty): the one pass also
    records the run's uniform samples (`lyapunov_pass`)."""
    from kicktimes.billiard.one_particle import simulate_one_particle

    ftle_method = _ftle_method(exp)
    uniform = None
    if one_pass:
        with timer("lyapunov_kicked"):
            res_one, one, _, *more = _lyapunov_pass()(
                ic[0], r, method=_tangent(exp.lyapunov_variant), **one_kw,
                **(uniform_kw or {}))
        uniform = more[0] if more else None

        def ftle(res_one=res_one):
            return res_one
    else:
        with timer("simulation_one_particle"):
            one = simulate_one_particle(ic[0], r, **one_kw)

        def ftle():
            kw = one_kw
            if "rng" in kw:
                # kinetic kicks are drawn by the run: the FTLE replays the ones it applied
                kw = {**one_kw, "kicks": one_kw["kicks"].replace(times=one.kick_times,
                                                                 angles=one.kick_angles)}
                del kw["rng"]
            return _lyapunov()(ic[0], r, method=ftle_method, **kw)
    add(system, "t_max", one.t_max)
    if "holes" in one_kw:
        add(system, "escape_time", one.escape_time,
            "" if one.escaped >= 0 else "no escape by the end of the run")
    for name, value, *note in extra:
        add(system, name, value, *note)
    add(system, "n_kicks", one.n_kicks)
    add(system, "n_boundary", one.n_boundary)
    diagnose(system, one, ftle, uniform)


def mmpp_kicks(pp_times, t_window: float, rng: np.random.Generator) -> tuple:
    """The kick schedule of the ``mmpp`` system of one IC, and its rows.

    A two-state MMPP fitted to the IC's disk-disk collision times on ``(0, t_window]``
    (`kicktimes.stats.fit_mmpp`, its starts drawn from a child of ``rng``), started in its
    stationary law (`kicktimes.schedules.MMPP.from_fit`): kicks at the IC's own mean rate,
    clustered as its collisions are. With fewer than `MMPP_MIN_EVENTS` collisions, or a fit
    that fails, Poisson kicks at the IC's rate ``n_pp / t_window`` (the ``poisson`` system's
    law, from this system's stream), and every row's note says so.

    Returns
    -------
    schedule : kicktimes.schedules.MMPP or Poisson
    rows : tuple of (name, value, note)
        ``kick_rate`` (the schedule's stationary rate), then `MMPP_ROWS`: the low and
        high rate, the rates of leaving the low and the high state (1 / mean sojourn) and
        ``AIC(MMPP-2) - AIC(Poisson)`` on the window likelihood (negative: the
        clustering is supported); NaN with the fallback's reason without a fit.
    """
    import warnings

    from kicktimes.schedules import MMPP, Poisson

    times = np.asarray(pp_times, dtype=np.float64)
    n = times.size
    rate = n / t_window
    reason = ""
    if n < MMPP_MIN_EVENTS:
        reason = f"{n} collisions, fewer than {MMPP_MIN_EVENTS} for an MMPP-2 fit"
    else:
        from kicktimes.stats import FitWarning, fit_mmpp

        try:
            with warnings.catch_warnings():
                # a degenerate fit (a state without events, equal rates) is still defined:
                # it is used, and its warnings go to the rows' note
                warnings.simplefilter("ignore", FitWarning)
                fit = fit_mmpp(times, t_window, n_states=2, rng=rng.spawn(1)[0])
            schedule = MMPP.from_fit(fit)
            if not (math.isfinite(fit.loglik) and math.isfinite(schedule.stationary_rate)):
                raise ValueError(f"a non-finite fit (loglik {fit.loglik!r})")
        except (ValueError, FloatingPointError, np.linalg.LinAlgError) as exc:
            reason = f"the MMPP-2 fit failed ({exc})"
    if reason:
        note = f"Poisson kicks at the IC's rate: {reason}"
        return Poisson(rate), (("kick_rate", rate, note),
                               *((name, math.nan, note) for name in MMPP_ROWS))
    # the Poisson model (MMPP-1) on the same window likelihood: n log(n / T) - n
    loglik_poisson = n * math.log(rate) - n
    delta_aic = fit.aic - (2.0 - 2.0 * loglik_poisson)
    note = "; ".join(fit.warnings)
    q = fit.generator
    rows = (("kick_rate", schedule.stationary_rate), ("mmpp_rate_low", fit.rates[0]),
            ("mmpp_rate_high", fit.rates[-1]), ("mmpp_switch_low", -q[0, 0]),
            ("mmpp_switch_high", -q[-1, -1]), ("mmpp_delta_aic", delta_aic))
    return schedule, tuple((name, float(value), note) for name, value in rows)


@functools.lru_cache(maxsize=64)
def kinetic_rate_table(r: float, rule: str = "mirror"):
    """The `KineticRate` of radius ``r`` under ``rule`` (tabulated once per process, radius
    and rule: the elastic table, over the disk's speed too, takes 4 to 7 s; 64 tables, 8 MB,
    hold a family's radii under both rules)."""
    from kicktimes.schedules import KineticRate

    return KineticRate(r, rule=rule)


def _two_disk_kw(exp: Experiment) -> dict:
    """The two-disk runs' ``rule`` (and ``masses``, for a partner of another mass; the
    ``table`` beyond the circle)."""
    return {"rule": exp.rule, **({"masses": exp.masses} if exp.masses else {}),
            **table_kw(exp)}


def table_kw(exp: Experiment) -> dict:
    """``{"table": ...}`` for a sweep beyond the circle, nothing for the circle: every
    simulator call of a circle sweep stays the call it always was."""
    return {} if exp.table == "circle" else {"table": exp.table_value}


def kick_law(exp: Experiment, system: str, ic: np.ndarray, r: float | None = None) -> KickLaw:
    """The kick law of a one-particle ``system`` at sweep radius ``r``, without its times
    (`KickLaw.replace` gives it them): the TOML's kick keys (``kick_angle``, ``sigma``, the
    rule and partner) as one value.

    The paper's systems use ``exp.kick_angle``; the ``*_scatter`` systems (and
    ``poisson_kinetic``, of equal disks and masses) collide with a
    virtual partner under the experiment's rule, with the two-disk IC's kinetic energy
    (elastic rule; with masses normalised to ``(m0 + m1) / 2 = 1``,
    ``e0 = (m0 |v0|^2 + m1 |v1|^2) / 2``) and, for unequal disks, disk 1's radius
    ``partner_ratio * r`` (``r`` is then required) and mass.
    """
    if system == "poisson_kinetic":
        if exp.rule == "mirror":
            return _law({"kick_angle": "scatter", "sigma": exp.sigma, "rule": "mirror"})
        # the elastic table's partner is on the shell |v0|^2 + |v1|^2 = 2: e0 = 1 up to
        # round-off (equal masses; Experiment refuses the kinetic systems with others)
        return _law({"kick_angle": "scatter", "sigma": exp.sigma, "rule": exp.rule,
                     "e0": 0.5 * float((ic[:, 2:] ** 2).sum())})
    if system == "uniform_kinetic":
        return _law({"kick_angle": exp.kick_angle, "sigma": exp.sigma})
    if not system.endswith("_scatter"):
        return _law({"kick_angle": exp.kick_angle, "sigma": exp.sigma})
    partner = {}
    if exp.partner_ratio != 1.0:
        if r is None:
            raise ValueError("r: the scattering kicks of unequal disks need the sweep radius")
        partner["partner_radius"] = exp.partner_ratio * r
    if exp.masses is None:
        e0 = 0.5 * float((ic[:, 2:] ** 2).sum()) if exp.rule == "elastic" else None
    else:
        partner["partner_mass"] = exp.partner_mass
        m0, m1 = 2.0 / (1.0 + exp.partner_mass), 2.0 * exp.partner_mass / (1.0 + exp.partner_mass)
        e0 = 0.5 * float(m0 * (ic[0, 2:] ** 2).sum() + m1 * (ic[1, 2:] ** 2).sum())
    return _law({"kick_angle": "scatter", "sigma": exp.sigma, "rule": exp.rule, "e0": e0,
                 **partner})


def _law(kw: dict) -> KickLaw:
    """The `KickLaw` of the TOML's kick keys (``kick_angle`` is the law's ``angle``)."""
    from kicktimes.billiard.kick_law import KickLaw

    return KickLaw(angle=kw.pop("kick_angle"), **kw)


def _tangent(variant: str, return_run: bool = False):
    from kicktimes.diagnostics.ftle_methods import Tangent

    return Tangent(variant=variant, return_run=return_run)


def _ftle_method(exp: Experiment):
    """The sweep's FTLE method (`kicktimes.diagnostics.Tangent` / `Twin`) from its TOML keys
    ``lyapunov_method``, ``lyapunov_variant`` and ``d0``."""
    from kicktimes.diagnostics.ftle_methods import Tangent, Twin

    if exp.lyapunov_method == "twin":
        return Twin(d0=exp.d0, variant=exp.lyapunov_variant)
    return Tangent(variant=exp.lyapunov_variant)


#: prefix of the recurrence rows computed on uniform-time samples when
#: ``rr_sampling = "run+uniform"`` (e.g. ``uniform_rr_offdiag@0.001``)
UNIFORM_PREFIX = "uniform_"


def eps_label(eps: float) -> str:
    """The threshold as written in row names: ``f"{eps:g}"``, e.g. ``0.001``."""
    return f"{eps:g}"


def recurrence_rows(points: np.ndarray, eps: tuple) -> list[tuple]:
    """The recurrence rows ``(diagnostic, value, note)`` of one run's samples.

    ``recurrence_rate`` (at ``eps[0]``, the paper's RR with the main diagonal), then for
    each threshold ``e``: ``rr@e`` (the same RR), ``rr_offdiag@e`` (Theiler window 1:
    pairs ``i != j``), ``det@e``, ``l_mean@e``, ``l_max@e`` (Theiler 1, ``l_min = 2``).
    One `rqa` call (one sweep) for all thresholds; ``rr@e = (N + R) / N^2`` from its
    ``R`` recurrent off-diagonal entries is bitwise ``recurrence_rate(points, eps=e)``.
    """
    from kicktimes.diagnostics import rqa

    n = int(points.shape[0])
    rows = []
    if n == 1:  # RR = 1 (the diagonal); nothing off the diagonal to compare
        rows.append(("recurrence_rate", 1.0, ""))
        for e in eps:
            tag = eps_label(e)
            rows.append((f"rr@{tag}", 1.0, ""))
            for name in ("rr_offdiag", "det", "l_mean", "l_max"):
                rows.append((f"{name}@{tag}", math.nan, "a single sample: no pair i != j"))
        return rows
    # one sweep of the points for all thresholds
    results = rqa(points, eps=list(eps), theiler=1, l_min=2, laminarity=False)
    for k, (e, res) in enumerate(zip(eps, results, strict=True)):
        tag = eps_label(e)
        # Python ints: the expression of recurrence_rate(points, eps=e), so bitwise equal
        rr = (n + res.n_recurrent) / (n * n)
        if k == 0:
            rows.append(("recurrence_rate", rr, ""))
        rows.append((f"rr@{tag}", rr, ""))
        rows.append((f"rr_offdiag@{tag}", res.rr, ""))
        rows.append((f"det@{tag}", res.det, res.undefined.get("det", "")))
        rows.append((f"l_mean@{tag}", res.l_mean, res.undefined.get("l_mean", "")))
        rows.append((f"l_max@{tag}", float(res.l_max), ""))
    return rows


def autocorrelation_rows(theta: np.ndarray, lag: int, max_lag: int) -> list[tuple]:
    """The autocorrelation rows ``(diagnostic, value, note)`` of one angle series.

    ``autocorrelation`` (``R_lag``), ``acf@l`` for ``l = 1..max_lag``,
    ``decorrelation_lag`` (first ``l`` with ``R_l < 1/e``) and ``tau_int`` (truncated at
    the first ``R_l <= 0``; a finite value whose note says "lower bound" had no
    ``R_l <= 0`` up to ``max_lag``). NaN values carry the reason.
    """
    from kicktimes.diagnostics import (
        UndefinedDiagnosticWarning,
        acf_curve,
        autocorrelation,
        decorrelation_lag,
        integrated_autocorrelation_time,
    )

    # one curve: R_lag is its entry lag - 1, bitwise autocorrelation(theta, lag)
    curve = acf_curve(theta, max_lag, name="theta")
    acf, curve_reason = curve.acf, curve.reason
    if 1 <= lag <= max_lag:
        value, reason = float(acf[lag - 1]), curve.lag_reasons[lag - 1]
    else:
        with warnings.catch_warnings():  # the reason goes into the row's note
            warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
            r_lag = autocorrelation(theta, lag)
        value, reason = float(r_lag), r_lag.reason
    rows = [("autocorrelation", value, reason or "")]
    for k, value in enumerate(acf.tolist()):
        rows.append((f"acf@{k + 1}", value, (curve_reason or "") if math.isnan(value) else ""))
    value, reason = decorrelation_lag(acf, return_reason=True)
    rows.append(("decorrelation_lag", value, reason or ""))
    value, reason = integrated_autocorrelation_time(acf, return_reason=True)
    rows.append(("tau_int", value, reason or ""))
    return rows


def uniform_samples(exp: Experiment, system: str, ic: np.ndarray, r: float, run) -> np.ndarray:
    """Samples at ``k tau``, ``k = 0..floor(t_max / tau)``, of the trajectory of ``run``.

    The same trajectory (same IC and, for a kicked system, the very kick times and angles
    that ``run`` applied) re-simulated with uniform sampling over ``run``'s duration. For
    ``sampling="uniform"`` these are ``run``'s own samples.
    """
    if exp.sampling == "uniform":
        return run.samples
    if run.t_max < exp.tau:  # not even one step: the start is the only sample
        return run.samples[:1]
    if system == "two_particle":
        from kicktimes.billiard.two_particle import simulate_two_particle

        again = simulate_two_particle(
            ic, exp.radius_pair(r), t_max=run.t_max, tau=exp.tau, track=0, sampling="uniform",
            **_two_disk_kw(exp),
        )
    else:
        from kicktimes.billiard.one_particle import simulate_one_particle

        again = simulate_one_particle(
            ic[0],
            r,
            t_max=run.t_max,
            tau=exp.tau,
            kicks=kick_law(exp, system, ic, r).replace(times=run.kick_times,
                                                       angles=run.kick_angles),
            sampling="uniform",
            **table_kw(exp),
        )
    return again.samples


def _actual_times(exp: Experiment, ic: np.ndarray, r: float, two) -> np.ndarray:
    """The disk-disk collision times that kick the actual-time billiard, up to the horizon.

    With uniform sampling every run lasts ``n_steps * tau`` and the two-particle run's
    times cover it. With the paper's collision-truncated steps the one-particle run (fewer
    collisions, so fewer truncated steps) lasts longer than the two-particle run; the
    two-particle billiard is continued to ``n_steps * tau`` (an upper bound of any paper
    run) so that the replayed times cover the whole kicked run instead of stopping early.
    """
    if exp.sampling == "uniform":
        return np.array(two.pp_times, dtype=np.float64)
    from kicktimes.billiard.two_particle import simulate_two_particle

    if two.t_max >= exp.horizon:
        return np.array(two.pp_times, dtype=np.float64)
    longer = simulate_two_particle(ic, exp.radius_pair(r), t_max=exp.horizon,
                                   **_two_disk_kw(exp))
    times = np.array(longer.pp_times, dtype=np.float64)
    # the event sequence does not depend on sampling: the continuation must start with
    # exactly the collisions of the sampled run
    if not np.array_equal(times[: two.n_pp], two.pp_times):
        raise RuntimeError(
            f"the continued two-particle run of r={r!r} does not reproduce the sampled run's "
            "collision times (simulator inconsistency)"
        )
    return times
