"""The studies' cache of raw simulation tables: a parquet file beside the parameters that
made it.

A study's expensive outputs (per-IC tables) live in its work folder as ``<name>.parquet``
with ``<name>.json`` beside it, holding the parameters of the computation and the seconds
it took. `cached_table` returns the stored table when the JSON's parameters equal the ones
asked for, and otherwise computes it and writes both, each atomically
(`kicktimes.fileio.atomic_write`). The JSON is removed before a new table is written and
written after it, so an interrupted write leaves a table without parameters, which the
next call recomputes, never a table under another computation's parameters.

Examples
--------
>>> import tempfile, pathlib
>>> import pandas as pd
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> calls = []
>>> def compute():
...     calls.append(1)
...     return pd.DataFrame({"x": [1.0, 2.0]})
>>> first = cached_table(folder / "demo.parquet", {"n": 2}, compute)
>>> again = cached_table(folder / "demo.parquet", {"n": 2}, compute)
>>> len(calls), again.reused, again.table["x"].tolist()
(1, True, [1.0, 2.0])

`cached_tables` does the same for several tables, computing the missing ones in a local
process pool when ``workers > 1``.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kicktimes.fileio import atomic_write
from kicktimes.studies.options import status_lines

__all__ = ["Cached", "cached_table", "cached_tables", "read_cached", "runs_table", "study_store",
           "write_cached"]


@dataclass(frozen=True)
class Cached:
    """A cached table: the ``table``, the ``seconds`` its computation took when it ran,
    and whether this call ``reused`` it rather than computing it."""

    table: pd.DataFrame
    seconds: float
    reused: bool


def _normal(params) -> str:
    """The parameters as canonical JSON (tuples and lists alike, keys sorted)."""
    return json.dumps(json.loads(json.dumps(params)), sort_keys=True)


def _params_path(path: Path) -> Path:
    return path.with_suffix(".json")


def read_cached(path: str | os.PathLike, params) -> Cached | None:
    """The table at ``path`` if it was computed with ``params``, else ``None``."""
    path = Path(path)
    meta = _params_path(path)
    if not (path.is_file() and meta.is_file()):
        return None
    record = json.loads(meta.read_text(encoding="utf-8"))
    if _normal(record.get("params")) != _normal(params):
        return None
    return Cached(pd.read_parquet(path), float(record.get("seconds", float("nan"))), True)


def write_cached(path: str | os.PathLike, params, table: pd.DataFrame,
                 seconds: float = float("nan")) -> None:
    """Write ``table`` to ``path`` and ``params`` (with ``seconds``) beside it."""
    path = Path(path)
    meta = _params_path(path)
    meta.unlink(missing_ok=True)
    atomic_write(path, lambda tmp: table.to_parquet(tmp, index=False))
    text = json.dumps({"params": json.loads(_normal(params)), "seconds": seconds}, indent=1)
    atomic_write(meta, lambda tmp: Path(tmp).write_text(text + "\n", encoding="utf-8"))


def cached_table(path: str | os.PathLike, params, compute, *, progress=None) -> Cached:
    """The table ``compute()`` returns for ``params``, from ``path`` if it is there.

    Parameters
    ----------
    path : path-like
        The parquet file; its parameters go to the same name with ``.json``.
    params : dict
        Everything the table depends on (JSON-serialisable).
    compute : callable
        ``compute()`` returns the table as a `pandas.DataFrame`.
    progress : callable, optional
        Takes one line of text: told whether the table was reused or computed.

    Returns
    -------
    Cached
    """
    say = status_lines(progress)
    found = read_cached(path, params)
    if found is not None:
        say(f"{Path(path).name}: reused")
        return found
    start = time.perf_counter()
    table = compute()
    seconds = time.perf_counter() - start
    write_cached(path, params, table, seconds)
    say(f"{Path(path).name}: computed in {seconds:.0f} s")
    return Cached(table, seconds, False)


def _compute_and_write(path, params, function, args) -> float:
    """Compute ``function(*args)``, cache it at ``path`` under ``params``; its seconds."""
    start = time.perf_counter()
    table = function(*args)
    seconds = time.perf_counter() - start
    write_cached(path, params, table, seconds)
    return seconds


def cached_tables(jobs, *, workers: int = 1, progress=None) -> list[Cached]:
    """`cached_table` for each of ``jobs``, the missing tables computed in parallel.

    Parameters
    ----------
    jobs : sequence of tuple
        ``(path, params, function, args)``: the table ``function(*args)`` (a picklable
        module-level function when ``workers > 1``) cached at ``path`` under ``params``.
    workers : int
        Processes computing the missing tables (1: in this process, in order). Each
        table is written as soon as it is done, so an interrupted run resumes.
    progress : callable, optional
        Takes one line of text per table computed.

    Returns
    -------
    list of Cached
        In the order of ``jobs``.
    """
    say = status_lines(progress)
    jobs = list(jobs)
    todo = [k for k, (path, params, _, _) in enumerate(jobs)
            if read_cached(path, params) is None]
    if todo:
        say(f"{len(jobs) - len(todo)} of {len(jobs)} tables cached, computing {len(todo)}")
    computed = {}
    if workers == 1 or len(todo) <= 1:
        for n, k in enumerate(todo, 1):
            computed[k] = _compute_and_write(*jobs[k])
            say(f"{Path(jobs[k][0]).name}: {n}/{len(todo)} in {computed[k]:.0f} s")
    elif todo:
        from concurrent.futures import as_completed

        from kicktimes.experiment.runner import local_pool

        with local_pool(workers) as pool:
            futures = {pool.submit(_compute_and_write, *jobs[k]): k for k in todo}
            for n, fut in enumerate(as_completed(futures), 1):
                k = futures[fut]
                computed[k] = fut.result()
                say(f"{Path(jobs[k][0]).name}: {n}/{len(todo)} in {computed[k]:.0f} s")
    results = []
    for k, (path, params, _, _) in enumerate(jobs):
        found = read_cached(path, params)
        if found is None:
            raise RuntimeError(f"cache: {path} was not written")
        results.append(found if k not in computed else
                       Cached(found.table, found.seconds, False))
    return results


def runs_table(runs, columns) -> pd.DataFrame:
    """``runs``, a table of runs to seed a cache with, as a DataFrame: ``runs`` itself, or
    the CSV at that path read exactly (`kicktimes.fileio.read_csv_exact`); ValueError
    naming the ``columns`` it lacks."""
    from kicktimes.fileio import read_csv_exact

    if isinstance(runs, str | os.PathLike):
        runs = read_csv_exact(runs)
    runs = pd.DataFrame(runs)
    missing = [c for c in columns if c not in runs.columns]
    if missing:
        raise ValueError(f"runs: missing columns {missing}")
    return runs



def study_store(exp, out, *, workers: int = 1, scheduler: str | None = None, say=print):
    """Run (or resume) the sweep store ``out/store-<exp.name>`` of a study:
    ``(Store, seconds)``.

    A store of that name made with other parameters (another experiment hash) is the
    study's own stale cache: it is removed and recomputed. ``scheduler`` (a Dask
    scheduler's address) runs the tasks there instead of on ``workers`` local processes.
    """
    import shutil

    from kicktimes.experiment import run_experiment

    path = Path(out) / f"store-{exp.name}"
    manifest = path / "manifest.json"
    if manifest.is_file():
        record = json.loads(manifest.read_text(encoding="utf-8"))
        if record.get("experiment_hash") != exp.hash():
            say(f"{path.name}: made with other parameters; recomputed")
            shutil.rmtree(path)
    start = time.perf_counter()
    kwargs = {"scheduler": scheduler} if scheduler else {"workers": workers}
    store = run_experiment(exp, path, progress=False, **kwargs)
    seconds = time.perf_counter() - start
    say(f"{path.name}: {seconds:.0f} s")
    return store, seconds
