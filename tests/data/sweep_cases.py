"""Golden sweep results: small experiments whose tidy tables must not change by a bit.

The one-pass sweep (simulation, FTLE and the actual-time continuation from one event
loop per trajectory) was introduced without changing any result; ``sweep_golden.parquet``
holds the ``results`` and ``collisions`` tables of the experiments below computed by the
code before it (separate simulation, FTLE and continuation runs), and the test compares
every value bit for bit.

Usage (from the repository root, with ``PYTHONPATH=$PWD``)::

    python tests/data/sweep_cases.py dump tests/data/sweep_golden.parquet
    python tests/data/sweep_cases.py check tests/data/sweep_golden.parquet
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
import pandas as pd


def experiments():
    """Three small experiments: the paper's setup (paper sampling and variant, all five
    systems and diagnostics) for both quick families, uniform sampling with the norm
    variant, and the elastic rule with gaussian kicks."""
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
              sigma=0.5),
    ]


def tables() -> tuple[pd.DataFrame, pd.DataFrame]:
    """The results and collisions of every experiment, with a column ``experiment``."""
    from kicktimes.experiment import run_task

    results, collisions = [], []
    for exp in experiments():
        for task in exp.tasks():
            res, col = run_task(exp, task)
            results.append(res.assign(experiment=exp.name))
            collisions.append(col.assign(experiment=exp.name))
    return pd.concat(results, ignore_index=True), pd.concat(collisions, ignore_index=True)


def save(path) -> None:
    """One parquet file: the results rows, then one row per IC with its collision times
    (``diagnostic == "pp_times"``, the times in ``pp_times``)."""
    res, col = tables()
    col = col.assign(system="two_particle", diagnostic="pp_times", value=col["t_window"],
                     note="")
    both = pd.concat([res.assign(pp_times=[np.empty(0)] * len(res)),
                      col[list(res.columns) + ["pp_times"]]], ignore_index=True)
    both.to_parquet(path, compression="zstd")


def load(path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The ``(results, collisions)`` written by `save`, as `tables` returns them."""
    both = pd.read_parquet(path)
    is_col = both["diagnostic"] == "pp_times"
    res = both[~is_col].drop(columns="pp_times").reset_index(drop=True)
    col = both[is_col].reset_index(drop=True)
    col = pd.DataFrame({
        "radius": col["radius"], "ic": col["ic"], "t_window": col["value"],
        "n_pp": col["pp_times"].map(len).astype("int64"),
        "pp_times": [np.asarray(p, dtype=np.float64) for p in col["pp_times"]],
        "experiment": col["experiment"],
    })
    return res, col


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


def main(argv):
    action, path = argv[0], argv[1]
    if action == "dump":
        save(path)
        print(f"written to {path}")
        return 0
    bad = differences(load(path), tables())
    print("identical" if not bad else "\n".join(bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
