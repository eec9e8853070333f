"""Ensemble sweeps: experiments, tasks, executors, the result store and resuming.

An `Experiment` (a TOML file, or the same thing in Python) describes a sweep over disk
radii for an ensemble of initial conditions; `run_experiment` splits it into tasks (one
radius times one block of ICs), runs them on a local process pool, any
``concurrent.futures`` executor or a Dask cluster, and streams each finished task to a
store of Parquet part files with a manifest; `load_store` reads it back as tidy tables.
See docs/experiments.md.

Examples
--------
>>> import tempfile
>>> from kicktimes.experiment import Experiment, run_experiment, load_store
>>> exp = Experiment(name="demo", radii=[0.01, 0.02], n_ics=3, n_steps=300, tau=0.3)
>>> path = tempfile.mkdtemp()
>>> store = run_experiment(exp, path, workers=1, progress=False)
>>> load_store(path).collisions.shape
(6, 5)
"""

from kicktimes.experiment.config import DIAGNOSTICS, SYSTEMS, Experiment
from kicktimes.experiment.disks import (
    DISKS_CONTROLS,
    DISKS_PRESETS,
    DISKS_REFERENCES,
    DisksExperiment,
    disks_control,
    disks_preset,
)
from kicktimes.experiment.disks_tasks import execute_disks_task
from kicktimes.experiment.presets import PRESETS, preset, preset_names
from kicktimes.experiment.runner import run_experiment
from kicktimes.experiment.store import (
    Store,
    StoreLockedError,
    StoreWarning,
    load_store,
    pending_tasks,
    read_manifest,
)
from kicktimes.experiment.tasks import (
    COLLISION_COLUMNS,
    RESULT_COLUMNS,
    Task,
    TaskOutput,
    execute_task,
    kick_rng,
    make_tasks,
    run_task,
)

__all__ = [
    "COLLISION_COLUMNS",
    "DIAGNOSTICS",
    "DISKS_CONTROLS",
    "DISKS_PRESETS",
    "DISKS_REFERENCES",
    "DisksExperiment",
    "PRESETS",
    "preset_names",
    "RESULT_COLUMNS",
    "SYSTEMS",
    "Experiment",
    "Store",
    "StoreLockedError",
    "StoreWarning",
    "Task",
    "TaskOutput",
    "disks_control",
    "disks_preset",
    "execute_disks_task",
    "execute_task",
    "kick_rng",
    "load_store",
    "pending_tasks",
    "read_manifest",
    "make_tasks",
    "preset",
    "run_experiment",
    "run_task",
]
