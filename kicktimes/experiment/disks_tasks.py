"""Tasks of a `DisksExperiment`: one N times one block of runs of the N-disk engine.

Each run ``k`` at N:

1. draws its state (`kicktimes.initial_state`, equal disks of radius
   `DisksExperiment.radius`), its tagged disks (`DisksExperiment.tagged_per_run` of them,
   without replacement) and nothing else from ``SeedSequence(seed, spawn_key=(N, k))``;
2. runs `kicktimes.simulate_disks` for `DisksExperiment.t_max`; under the elastic rule
   with the tagged disks' positions sampled every ``tau = 1 / (samples_per_collision nu)``
   and their wall hits logged (the centre's position at each), from which each interval's
   speed is read (`interval_speeds`);
3. returns one results row per run quantity (``collision_frequency``, ``t_max``,
   ``n_pp``, ``energy`` the mean ``|v|^2`` at the end, ``speed_known`` the share of the
   tagged intervals whose speed was read) and one collisions row per tagged disk (its
   collision times and, elastic, its speeds).

The engine is called through its public API in one of its two compiled configurations:
no observers (mirror) or all of them (elastic).
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from kicktimes.experiment.disks import DisksExperiment, DisksTask

__all__ = ["DISKS_COLLISION_COLUMNS", "DISKS_RESULT_COLUMNS", "KICKED_EPS", "KICKED_THEILER",
           "execute_disks_task", "interval_speeds", "kicked_rate", "kicked_rows", "run_disks",
           "tagged_start_radii"]

DISKS_RESULT_COLUMNS = ("n_disks", "radius", "ic", "system", "diagnostic", "value", "note")
DISKS_COLLISION_COLUMNS = ("n_disks", "radius", "ic", "disk", "t_window", "n_pp", "pp_times",
                           "speeds")


def interval_speeds(pp_times, wall_times, sample_times, positions, wall_positions=None, *,
                    box=None):
    """The speed a disk flew each interval between its disk-disk collisions at.

    Parameters
    ----------
    pp_times : array_like
        The disk's collision times with other disks, increasing.
    wall_times : array_like
        Its wall hits, increasing (the speed does not change there, the direction does).
    sample_times, positions : array_like, shapes (n,) and (n, 2)
        Its positions sampled at increasing times.
    wall_positions : array_like, shape (len(wall_times), 2), optional
        Its centre at each wall hit: more observed positions.
    box : float, optional
        The periodic box's side: displacements are taken to their nearest image (the
        positions are wrapped into ``[0, box)``; a flight between two samples is shorter
        than ``box / 2``).

    Returns
    -------
    ndarray, shape (len(pp_times) + 1,)
        Entry ``j`` is the speed between collision ``j - 1`` and collision ``j`` (entry 0:
        before the first collision, the last: after the last one). Two consecutive observed
        positions (samples and, if given, wall hits) with no event (collision or wall hit)
        strictly between them lie on one straight flight, which gives the speed exactly,
        ``|x(s_b) - x(s_a)| / (s_b - s_a)``; an interval without such a pair gets NaN.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.arange(6) * 0.1
    >>> x = np.c_[np.where(s < 0.25, 2.0 * s, 0.5 + 0.5 * (s - 0.25)), 0.0 * s]
    >>> interval_speeds([0.25], [], s, x).round(12).tolist()
    [2.0, 0.5]
    """
    pp = np.asarray(pp_times, float)
    walls = np.asarray(wall_times, float)
    events = np.sort(np.concatenate([pp, walls]))
    s = np.asarray(sample_times, float)
    pos = np.asarray(positions, float).reshape(-1, 2)
    if wall_positions is not None:
        s = np.concatenate([s, walls])
        pos = np.concatenate([pos, np.asarray(wall_positions, float).reshape(-1, 2)])
        order = np.argsort(s, kind="stable")
        s, pos = s[order], pos[order]
    # events strictly between consecutive observations: a wall hit that is itself an
    # observation ends one straight flight and starts the next
    inside = (np.searchsorted(events, s[1:], side="left")
              - np.searchsorted(events, s[:-1], side="right"))
    step = np.diff(s)
    dx, dy = pos[1:, 0] - pos[:-1, 0], pos[1:, 1] - pos[:-1, 1]
    if box is not None:
        dx, dy = dx - box * np.round(dx / box), dy - box * np.round(dy / box)
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = np.hypot(dx, dy) / step
    ok = (inside == 0) & (step > 0) & np.isfinite(speed)
    which = np.searchsorted(pp, s[:-1], side="right")[ok]
    total = np.bincount(which, weights=speed[ok], minlength=pp.size + 1)
    count = np.bincount(which, minlength=pp.size + 1)
    out = np.full(pp.size + 1, np.nan)
    np.divide(total, count, out=out, where=count > 0)
    return out


def _start(experiment: DisksExperiment, n_disks: int, k: int):
    """Run ``k``'s generator, initial state and tagged disks (its first draws)."""
    from kicktimes.billiard import initial_state

    rng = np.random.default_rng(np.random.SeedSequence(experiment.seed, spawn_key=(n_disks, k)))
    state = initial_state(n_disks, experiment.radius(n_disks), rng=rng, rule=experiment.rule,
                          box=experiment.box_side)
    tagged = np.sort(rng.choice(n_disks, experiment.tagged_per_run(n_disks), replace=False))
    return rng, state, tagged


def tagged_start_radii(experiment: DisksExperiment, n_disks: int, k: int):
    """The tagged disks of run ``k`` at ``n_disks`` and their centres' distances from the
    table's centre at ``t = 0``: ``(tagged, radii)``, redrawn from the run's seed (no
    simulation), e.g. to keep the disks that start in the bulk, away from the wall."""
    _, state, tagged = _start(experiment, n_disks, k)
    return tagged, np.hypot(state[tagged, 0], state[tagged, 1])


def run_disks(experiment: DisksExperiment, n_disks: int, k: int):
    """Run ``k`` at ``n_disks``: ``(run, tagged, speeds)``, ``speeds`` a list of arrays
    (`interval_speeds`, one per tagged disk; ``None`` under the mirror rule, all speeds 1)."""
    from kicktimes.billiard import simulate_disks

    rng, state, tagged = _start(experiment, n_disks, k)
    r = experiment.radius(n_disks)
    t_max = experiment.t_max(n_disks)
    box = experiment.box_side
    if experiment.rule == "mirror":
        return simulate_disks(state, r, t_max=t_max, rule="mirror", box=box), tagged, None
    tau = 1.0 / (experiment.samples_per_collision * experiment.reference_frequency(n_disks))
    if box is not None:
        # no wall: the speeds from consecutive samples, displacements to the nearest image
        run = simulate_disks(state, r, t_max=t_max, rule="elastic", sample=tagged, tau=tau,
                             box=box)
        return run, tagged, [interval_speeds(run.collision_times(int(d)), [], run.sample_times,
                                             run.samples[:, m], box=box)
                             for m, d in enumerate(tagged)]
    run = simulate_disks(state, r, t_max=t_max, rule="elastic", sample=tagged, tau=tau,
                         log_walls=True)
    w_time, w_disk, w_x, w_y, _ = run.wall_log
    speeds = []
    for m, d in enumerate(tagged):
        mine = w_disk == d
        speeds.append(interval_speeds(run.collision_times(int(d)), w_time[mine],
                                      run.sample_times, run.samples[:, m],
                                      np.c_[w_x[mine], w_y[mine]]))
    return run, tagged, speeds


#: the recurrence threshold of the kicked comparison (positions sampled every 0.1 mean
#: free times; the runs are short, so a threshold coarser than the paper's 1e-3)
KICKED_EPS = 0.05
#: its Theiler window, in samples: pairs less than two mean free times apart are left out
#: (the diagonal and the successive samples of one flight, which are within KICKED_EPS of
#: each other at large N and would make every system's recurrence rate alike)
KICKED_THEILER = 20


def kicked_rate(experiment: DisksExperiment, gas, times) -> float:
    """The rate of the kicked comparison's Poisson and scatter kicks (and of its
    ``lambda / nu``).

    Parameters
    ----------
    experiment : DisksExperiment
        Its ``kicked_rate`` chooses: ``"gas"`` the whole gas's collision frequency per
        disk, ``nu = 2 n_pp / (N T)`` (`kicktimes.billiard.DisksRun.collision_frequency`,
        every collision counted for both disks; the rate of disks.csv), or ``"disk"`` the
        followed disk's own ``n / T``.
    gas : kicktimes.billiard.DisksRun
        The gas run of the comparison.
    times : ndarray
        The followed disk's collision times in it.

    Returns
    -------
    float
        The rate. With about 200 collisions of one disk, ``n / T`` has a relative noise of
        about ``1 / sqrt(200)``, 7 %; the whole gas's, ``sqrt(2 / (N n))`` of it.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.experiment import disks_preset
    >>> from kicktimes.billiard import initial_state, simulate_disks
    >>> exp = disks_preset("disks-kicked-phi0.02-mirror")
    >>> state = initial_state(10, exp.radius(10), rng=1, rule="mirror")
    >>> run = simulate_disks(state, exp.radius(10), t_max=20.0, rule="mirror")
    >>> kicked_rate(exp, run, run.collision_times(0)) == run.collision_frequency
    True
    """
    if experiment.kicked_rate == "gas":
        return float(gas.collision_frequency)
    return float(np.asarray(times).size / gas.t_max)


def kicked_rows(experiment: DisksExperiment, n_disks: int, k: int) -> list:
    """The kicked comparison of run ``k`` at ``n_disks`` (`DisksExperiment.kicked_runs`).

    A state of its own (``SeedSequence(seed, spawn_key=(N, k, 1))``) runs for
    ``T = kicked_time / nu`` with disk 0 sampled every ``0.1 / nu`` and its wall hits
    logged. Rows ``(system, diagnostic, value)``, systems ``"gas"`` (disk 0 in the gas;
    its FTLE is the whole gas's, `kicktimes.diagnostics.gas_lyapunov.disks_lyapunov` with
    ``method=experiment.gas_ftle``),
    ``"poisson"`` and ``"actual"`` (one disk from disk 0's state, kicked with uniform new
    directions at the rate `kicked_rate` or at disk 0's collision times; FTLE from tangent
    vectors, `kicktimes.diagnostics.lyapunov`), ``"scatter"`` (kicked at that rate, each
    kick a mirror collision with a virtual partner of radius ``r`` from the collision
    kernel, ``kick_angle="scatter"``, ``partner="weighted"``), those of
    `DisksExperiment.kicked_systems`, and, at N = 2, ``"two_particle"`` (the
    two-disk FTLE of the same state, `lyapunov`). Diagnostics: ``ftle``, ``acf@1`` (the
    boundary angles' lag-1 autocorrelation, `kicktimes.diagnostics.autocorrelation`),
    ``rr`` (the recurrence rate of the sampled positions at ``KICKED_EPS``, Theiler window
    ``KICKED_THEILER`` samples) and, for the
    gas, ``rate`` (the kicks' rate, `kicked_rate`: by default the whole gas's collision
    frequency per disk, the rate the gas's ``lambda / nu`` is read at).
    """
    import warnings

    from kicktimes.billiard import KickLaw, initial_state, simulate_disks, simulate_one_particle
    from kicktimes.diagnostics import (
        autocorrelation,
        boundary_angles,
        disks_lyapunov,
        lyapunov,
        recurrence_rate,
    )
    from kicktimes.schedules import Poisson, Replay

    rng = np.random.default_rng(np.random.SeedSequence(experiment.seed,
                                                       spawn_key=(n_disks, k, 1)))
    r = experiment.radius(n_disks)
    state = initial_state(n_disks, r, rng=rng, rule="mirror")
    nu = experiment.reference_frequency(n_disks)
    tau = 0.1 / nu
    n_steps = int(round(experiment.kicked_time / 0.1))
    t_max = n_steps * tau
    gas = simulate_disks(state, r, t_max=t_max, rule="mirror", sample=[0], tau=tau,
                         log_walls=True)
    times = gas.collision_times(0)
    rate = kicked_rate(experiment, gas, times)
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an ACF of too few wall hits is NaN, with a reason
        theta = np.arcsin(np.clip(gas.walls["sin_theta"].to_numpy()[
            gas.walls["disk"].to_numpy() == 0], -1.0, 1.0))
        ftle = disks_lyapunov(state, r, t_max=t_max, segment=1.0 / nu, rng=rng,
                              method=experiment.gas_ftle).lam
        rows += [("gas", "ftle", ftle), ("gas", "acf@1", autocorrelation(theta, 1)),
                 ("gas", "rr", recurrence_rate(gas.samples[:, 0], eps=KICKED_EPS,
                                               theiler=KICKED_THEILER)),
                 ("gas", "rate", rate)]
        schedules = {"poisson": Poisson(rate),
                     "actual": Replay(times, t_max=t_max),
                     "scatter": Poisson(rate)}
        for system in experiment.kicked_systems:
            # scatter: each kick a mirror collision with a partner of the gas's radius drawn
            # from the collision kernel (flux-weighted direction, (w.n)+ normal)
            kind = ({"angle": "scatter", "rule": "mirror", "partner": "weighted",
                     "partner_radius": r} if system == "scatter" else {})
            one = simulate_one_particle(state[0], r, t_max=t_max, rng=rng, tau=tau,
                                        kicks=KickLaw(schedules[system], **kind))
            rows += [(system, "ftle", lyapunov(one).lam),
                     (system, "acf@1", autocorrelation(boundary_angles(one), 1)),
                     (system, "rr", recurrence_rate(one.samples[:, :2], eps=KICKED_EPS,
                                                          theiler=KICKED_THEILER))]
        if n_disks == 2:
            rows.append(("two_particle", "ftle",
                         lyapunov(state, r, n_steps=n_steps, tau=tau, rule="mirror").lam))
    return [(s, d, float(v)) for s, d, v in rows]


def execute_disks_task(experiment: DisksExperiment, task: DisksTask):
    """Run every run of ``task`` and return its tables (a `TaskOutput`)."""
    from kicktimes.experiment.tasks import TaskOutput

    if not isinstance(experiment, DisksExperiment):
        raise TypeError(f"experiment: expected a DisksExperiment, got "
                        f"{type(experiment).__name__}")
    if task not in experiment.tasks():
        raise ValueError(f"task: {task!r} is not a task of experiment {experiment.name!r}")
    n, r = task.n_disks, task.radius
    results, collisions = [], []
    t0, c0 = time.perf_counter(), time.process_time()
    for k in range(task.ic_start, task.ic_stop):
        run, tagged, speeds = run_disks(experiment, n, k)
        v = run.final_state[:, 2:]
        known = (np.nan if speeds is None
                 else float(np.mean(np.concatenate([np.isfinite(s) for s in speeds]))))
        for name, value in (("collision_frequency", run.collision_frequency),
                            ("t_max", run.t_max), ("n_pp", run.n_pp),
                            ("energy", float(np.mean(np.sum(v * v, axis=1)))),
                            ("speed_known", known)):
            results.append((n, r, k, "disks", name, float(value), ""))
        if k < experiment.kicked_states(n):
            for system, name, value in kicked_rows(experiment, n, k):
                results.append((n, r, k, system, name, value, ""))
        for m, d in enumerate(tagged):
            times = run.collision_times(int(d))
            sp = np.empty(0) if speeds is None else speeds[m]
            collisions.append((n, r, k, int(d), run.t_max, int(times.size), times, sp))
    return TaskOutput(
        task=task,
        results=pd.DataFrame(results, columns=list(DISKS_RESULT_COLUMNS)),
        collisions=pd.DataFrame(collisions, columns=list(DISKS_COLLISION_COLUMNS)),
        # wall time, and this process's CPU time (the sweep's cost on a shared machine)
        timings={"simulate": time.perf_counter() - t0, "cpu": time.process_time() - c0},
    )
