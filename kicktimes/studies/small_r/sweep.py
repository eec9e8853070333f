r"""The FTLE sweep to r = 1e-4: one resumable store per (collision rule, radius).

Each radius is its own `kicktimes.experiment.Experiment` because the horizon grows as
1/r: a run lasts ``n_collisions / kinetic_rate(r, rule)``, so every IC sees about the
same number of disk-disk collisions (of kicks, for the kicked systems) at every radius.
The ICs are drawn from the invariant measure at the radius itself
(``ic_method="uniform"``, ``r_max = r``), the FTLE is the tangent-space one, and the run
is sampled only ``N_SAMPLES`` times (the tangent FTLE does not need the samples).

The stores' statistics are in `kicktimes.studies.small_r.tables`.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from kicktimes.experiment import Experiment, load_store
from kicktimes.stats import kinetic_rate
from kicktimes.studies.cache import study_store

__all__ = ["CONTROL_RADIUS", "CONTROL_STORES", "N_SAMPLES", "SYSTEMS", "control_experiments",
           "load_sweep", "run_sweep", "seconds_per_ic", "small_r_experiment"]

#: the two disks, then the kicked systems the theory covers (`THEORY_SYSTEMS`)
SYSTEMS = ("two_particle", "poisson", "uniform_kinetic", "poisson_scatter", "poisson_kinetic")
#: samples per run (only the store's bookkeeping: the tangent FTLE is sample-free)
N_SAMPLES = 1000
SEED = 62


def small_r_experiment(r, rule, *, n_ics, n_collisions, block_size=10, seed=SEED,
                       ic_method="uniform", control="") -> Experiment:
    """The sweep's experiment at one radius and rule (module docstring); ``control``
    names a control's store (another ``seed``, the paper's ``ic_method``, a shorter
    horizon) and goes into its name.

    >>> exp = small_r_experiment(1e-3, "mirror", n_ics=100, n_collisions=10_000)
    >>> exp.name, round(exp.horizon * exp.kinetic_rate(1e-3))
    ('small_r-mirror-r0.001', 10000)
    """
    horizon = n_collisions / kinetic_rate(r, rule=rule)
    return Experiment(
        name=f"small_r-{rule}-r{r:g}" + (f"-{control}" if control else ""), radii=[r],
        n_ics=n_ics, n_steps=N_SAMPLES, tau=horizon / N_SAMPLES, ic_method=ic_method,
        seed=seed, sampling="uniform", rule=rule, systems=SYSTEMS, diagnostics=("lyapunov",),
        lyapunov_method="tangent", block_size=block_size, log_events=False,
        description=f"tangent FTLE at r = {r:g} over {n_collisions} collisions per IC "
                    f"({ic_method} ICs, seed {seed}), for the low-density theory of the "
                    "stretching")


#: the controls' stores, at one radius (`CONTROL_RADIUS`): ``name: (rules, changes)``; a
#: seed replicate under both rules (the radii of the sweep share their ICs' seed, so their
#: errors are correlated), the paper's ICs (drawn at r_max = r), a ten times shorter horizon
CONTROL_STORES = {
    "seed": (("mirror", "elastic"), {"seed": SEED + 1}),
    "paper_ics": (("mirror",), {"ic_method": "paper"}),
    "horizon": (("mirror",), {"n_collisions_factor": 0.1}),
}
CONTROL_RADIUS = 1e-3


def control_experiments(n_ics, n_collisions, radius=CONTROL_RADIUS) -> dict:
    """``{(control, rule, r): Experiment}`` of `CONTROL_STORES`."""
    out = {}
    for control, (rules, changes) in CONTROL_STORES.items():
        kw = dict(changes)
        factor = kw.pop("n_collisions_factor", 1.0)
        for rule in rules:
            out[control, rule, radius] = small_r_experiment(
                radius, rule, n_ics=n_ics, n_collisions=round(factor * n_collisions),
                control=control, **kw)
    return out


def run_sweep(out, collisions, rules, *, n_ics, workers=1, scheduler=None, controls=None,
              say=print) -> tuple[dict, dict]:
    """Run (or resume) every store of the sweep in ``out``: ``collisions`` maps each
    radius to its collisions per IC; ``controls`` (`control_experiments`) adds the
    controls' stores. Returns ``{(rule, r): Store}`` (and ``{(control, rule, r): Store}``
    under the key ``"controls"``) and the seconds each took in this call (a store made
    with other parameters is this study's stale cache: removed and recomputed). Largest
    radii first, both rules at each radius, the controls last."""
    stores, seconds = {}, {}
    for r in sorted(collisions, reverse=True):
        for rule in rules:
            exp = small_r_experiment(r, rule, n_ics=n_ics, n_collisions=collisions[r])
            stores[rule, r], seconds[rule, r] = study_store(exp, out, workers=workers,
                                                             scheduler=scheduler, say=say)
    stores["controls"] = {}
    for key, exp in (controls or {}).items():
        stores["controls"][key], seconds[key] = study_store(
            exp, out, workers=workers, scheduler=scheduler, say=say)
    return stores, seconds


def load_sweep(out, collisions, rules, *, n_ics) -> dict:
    """The finished stores of the sweep in ``out`` (no computation)."""
    names = {(rule, r): small_r_experiment(r, rule, n_ics=n_ics,
                                          n_collisions=collisions[r]).name
             for rule in rules for r in collisions}
    return {key: load_store(Path(out) / f"store-{name}") for key, name in names.items()}


def seconds_per_ic(stores) -> pd.DataFrame:
    """Per (rule, radius): the CPU seconds of the sweep's tasks (each task's own timing in
    its worker, all five systems), per IC, and the two-disk collisions per IC."""
    rows = []
    for (rule, r), store in sorted((k, v) for k, v in stores.items() if k != "controls"):
        res = store.results
        n_pp = res[(res["system"] == "two_particle") & (res["diagnostic"] == "n_pp")]["value"]
        seconds = float(store.timings["total"].sum())
        rows.append({"rule": rule, "radius": r, "n_ics": store.experiment.n_ics,
                     "horizon": store.experiment.horizon, "cpu_seconds": seconds,
                     "seconds_per_ic": seconds / store.experiment.n_ics,
                     "collisions_per_ic": float(n_pp.mean())})
    return pd.DataFrame(rows)
