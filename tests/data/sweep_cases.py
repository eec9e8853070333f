"""Sweep cases: small experiments whose tables the one-pass sweep must not change by a bit.

The one-pass sweep computes simulation, FTLE and the actual-time continuation from one
event loop per trajectory. ``tables(one_pass=False)`` computes the same experiments by
separate calls (a simulation, its FTLE, the continuation), and the test compares the two
in one process: a bitwise property of one machine, so no file made on another machine is
involved (chaotic trajectories are not bitwise across CPUs; docs/architecture.md,
*Reproducibility*).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd


def experiments():
    """Small experiments: the paper's setup (paper sampling and variant, every system and
    diagnostic) for both quick families, uniform sampling with the norm variant, the
    elastic rule with gaussian kicks (without the kinetic-rate kicks, mirror rule only),
    and the MMPP kicks at radii large enough for the IC's own fit (50+ collisions)."""
    from kicktimes.experiment import preset

    def small(family, **kw):
        exp = preset(family)
        return dataclasses.replace(exp, radii=[exp.radii[0], exp.radii[-1]], n_ics=3,
                                   block_size=3, **kw)

    return [
        small("quick_a", n_steps=1000),
        small("quick_b", n_steps=1000),
        small("quick_a", name="uniform", n_steps=600, sampling="uniform",
              lyapunov_variant="norm"),
        small("quick_b", name="elastic", n_steps=600, rule="elastic", kick_angle="gaussian",
              sigma=0.5, systems=[s for s in preset("quick_b").systems
                                  if s not in ("poisson_kinetic", "uniform_kinetic")]),
        dataclasses.replace(preset("quick_a"), name="mmpp", radii=[0.1, 0.2], n_ics=3,
                            block_size=3, n_steps=1500, systems=["two_particle", "poisson",
                                                                 "mmpp"]),
    ]


def tables(one_pass: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The results and collisions of every experiment, with a column ``experiment``."""
    from kicktimes.experiment.tasks import execute_task

    results, collisions = [], []
    for exp in experiments():
        for task in exp.tasks():
            out = execute_task(exp, task, one_pass=one_pass)
            res, col = out.results, out.collisions
            results.append(res.assign(experiment=exp.name))
            collisions.append(col.assign(experiment=exp.name))
    return pd.concat(results, ignore_index=True), pd.concat(collisions, ignore_index=True)


def differences(ref, new) -> list[str]:
    """What differs between two ``(results, collisions)`` pairs (empty: bit for bit equal)."""
    (res0, col0), (res1, col1) = ref, new
    bad = []
    try:
        pd.testing.assert_frame_equal(res1, res0, check_exact=True)
    except AssertionError as exc:
        bad.append(f"results: {exc}")
    scalars = ["radius", "ic", "t_window", "n_pp", "experiment"]
    try:
        pd.testing.assert_frame_equal(col1[scalars], col0[scalars], check_exact=True)
    except AssertionError as exc:
        bad.append(f"collisions: {exc}")
    for i, (a, b) in enumerate(zip(col0["pp_times"], col1["pp_times"], strict=False)):
        if a.tobytes() != np.asarray(b, dtype=np.float64).tobytes():
            bad.append(f"collisions row {i}: pp_times differ")
    return bad
