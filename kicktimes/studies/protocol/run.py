"""Run the protocol study's tasks (resumable) and gather their rows."""

from __future__ import annotations

import os
from concurrent.futures import as_completed
from pathlib import Path

import pandas as pd

from kicktimes.experiment.runner import local_pool
from kicktimes.studies.options import status_lines
from kicktimes.studies.protocol.compute import compute_task, panels, tasks

__all__ = ["load_rows", "run_protocol_study", "task_path"]


def task_path(store: str | os.PathLike, panel, task) -> Path:
    """The parquet file of one task in ``store``."""
    kind, radius, a, b = task
    return Path(store) / panel.name / f"{kind}_r{radius:.3f}_ic{a:04d}-{b:04d}.parquet"


def run_protocol_study(store: str | os.PathLike, scale: str = "paper", *,
                       workers: int | None = None, progress=None) -> pd.DataFrame:
    """Compute every task of both panels not yet in ``store`` and return all rows.

    Tasks run in a local pool of ``workers`` processes (default: every core; 1 runs them
    here). Each finished task is one parquet file, written atomically, so an interrupted
    run resumes where it stopped. ``progress``: a callable taking a line of text, or
    ``None``.
    """
    todo = [(p, t) for p in panels(scale) for t in tasks(p)
            if not task_path(store, p, t).exists()]
    say = status_lines(progress)
    total = 0.0
    if todo and (workers == 1 or (workers is None and (os.cpu_count() or 1) == 1)):
        for k, (p, t) in enumerate(todo, 1):
            total += compute_task(p, t, task_path(store, p, t))
            say(f"protocol: {k}/{len(todo)} tasks ({total:.0f} worker-s)")
    elif todo:
        with local_pool(workers) as pool:
            futures = [pool.submit(compute_task, p, t, task_path(store, p, t)) for p, t in todo]
            for k, fut in enumerate(as_completed(futures), 1):
                total += fut.result()
                say(f"protocol: {k}/{len(todo)} tasks ({total:.0f} worker-s)")
    return load_rows(store, scale)


def load_rows(store: str | os.PathLike, scale: str = "paper") -> pd.DataFrame:
    """Every row of the study in ``store`` (all tasks must be there)."""
    frames = []
    for p in panels(scale):
        for t in tasks(p):
            path = task_path(store, p, t)
            if not path.exists():
                raise FileNotFoundError(f"store: task {t} of {p.name} is missing ({path}); "
                                        "run the study first")
            frames.append(pd.read_parquet(path))
    return pd.concat(frames, ignore_index=True)
