"""The two-disk runs of the mechanism study, with their collision logs.

The same ICs at both radii (drawn at the larger), paper ICs and invariant-measure ICs;
the runs are a pure function of the seed, so every worker count gives the same runs.
"""

from __future__ import annotations

from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.experiment.runner import local_pool

__all__ = ["METHODS", "RADII", "simulate"]

RADII = (0.01, 0.02)
METHODS = ("paper", "uniform")


def _simulate(task):
    ic, r, t_max, rule = task
    return simulate_two_particle(ic, r, t_max=t_max, rule=rule, log_collisions=True)


def simulate(n_ics, t_max, workers, seed, rule="mirror"):
    """``{(method, r): (ics, runs)}`` for every IC family of `METHODS` and radius of
    `RADII`, with the same ICs at both radii (drawn at the larger).

    ``workers`` processes run the simulations (1: in this process).

    Examples
    --------
    >>> groups = simulate(2, 5.0, 1, seed=29)
    >>> sorted(groups)
    [('paper', 0.01), ('paper', 0.02), ('uniform', 0.01), ('uniform', 0.02)]
    >>> len(groups["paper", 0.01][1])
    2
    """
    out = {}
    tasks = {}
    for method in METHODS:
        ics = initial_conditions(n_ics, max(RADII), rng=seed, method=method, rule=rule)
        for r in RADII:
            tasks[method, r] = (ics, [(ic, r, t_max, rule) for ic in ics])
    if workers == 1:
        return {key: (ics, [_simulate(t) for t in todo]) for key, (ics, todo) in tasks.items()}
    with local_pool(workers) as pool:
        for key, (ics, todo) in tasks.items():
            out[key] = (ics, list(pool.map(_simulate, todo, chunksize=10)))
    return out
