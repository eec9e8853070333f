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

import json
import shutil
import time
from pathlib import Path

import pandas as pd

from kicktimes.experiment import Experiment, load_store, run_experiment
from kicktimes.stats import kinetic_rate

__all__ = ["N_SAMPLES", "SYSTEMS", "load_sweep", "run_sweep", "seconds_per_ic",
           "small_r_experiment"]

#: the two disks, then the kicked systems the theory covers (`THEORY_SYSTEMS`)
SYSTEMS = ("two_particle", "poisson", "uniform_kinetic", "poisson_scatter", "poisson_kinetic")
#: samples per run (only the store's bookkeeping: the tangent FTLE is sample-free)
N_SAMPLES = 1000
SEED = 62


def small_r_experiment(r, rule, *, n_ics, n_collisions, block_size=10) -> Experiment:
    """The sweep's experiment at one radius and rule (module docstring).

    >>> exp = small_r_experiment(1e-3, "mirror", n_ics=100, n_collisions=10_000)
    >>> exp.name, round(exp.horizon * exp.kinetic_rate(1e-3))
    ('small_r-mirror-r0.001', 10000)
    """
    horizon = n_collisions / kinetic_rate(r, rule=rule)
    return Experiment(
        name=f"small_r-{rule}-r{r:g}", radii=[r], n_ics=n_ics, n_steps=N_SAMPLES,
        tau=horizon / N_SAMPLES, ic_method="uniform", seed=SEED, sampling="uniform",
        rule=rule, systems=SYSTEMS, diagnostics=("lyapunov",), lyapunov_method="tangent",
        block_size=block_size, log_events=False,
        description=f"tangent FTLE at r = {r:g} over {n_collisions} collisions per IC "
                    "(invariant ICs), for the low-density theory of the stretching")


def run_sweep(out, collisions, rules, *, n_ics, workers=1, scheduler=None,
              say=print) -> tuple[dict, dict]:
    """Run (or resume) every store of the sweep in ``out``: ``collisions`` maps each
    radius to its collisions per IC. Returns ``{(rule, r): Store}`` and the seconds each
    took in this call (a store made with other parameters is this study's stale cache:
    removed and recomputed). Largest radii first, both rules at each radius."""
    stores, seconds = {}, {}
    for r in sorted(collisions, reverse=True):
        for rule in rules:
            exp = small_r_experiment(r, rule, n_ics=n_ics, n_collisions=collisions[r])
            path = Path(out) / f"store-{exp.name}"
            manifest = path / "manifest.json"
            if manifest.is_file():
                record = json.loads(manifest.read_text(encoding="utf-8"))
                if record.get("experiment_hash") != exp.hash():
                    say(f"{path.name}: made with other parameters; recomputed")
                    shutil.rmtree(path)
            start = time.perf_counter()
            kwargs = {"scheduler": scheduler} if scheduler else {"workers": workers}
            stores[rule, r] = run_experiment(exp, path, progress=False, **kwargs)
            seconds[rule, r] = time.perf_counter() - start
            say(f"{path.name}: {seconds[rule, r]:.0f} s")
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
    for (rule, r), store in sorted(stores.items()):
        res = store.results
        n_pp = res[(res["system"] == "two_particle") & (res["diagnostic"] == "n_pp")]["value"]
        seconds = float(store.timings["total"].sum())
        rows.append({"rule": rule, "radius": r, "n_ics": store.experiment.n_ics,
                     "horizon": store.experiment.horizon, "cpu_seconds": seconds,
                     "seconds_per_ic": seconds / store.experiment.n_ics,
                     "collisions_per_ic": float(n_pp.mean())})
    return pd.DataFrame(rows)
