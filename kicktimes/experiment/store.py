"""The result store of a sweep: Parquet part files per finished task plus a manifest.

Layout (docs/experiments.md)::

    STORE/manifest.json
    STORE/results/<task id>.parquet       tidy diagnostics of the task
    STORE/collisions/<task id>.parquet    disk-disk collision times of the task

Every file is written to a temporary name in the same folder and moved into place with
``os.replace`` (atomic on POSIX and Windows), so a killed run leaves whole files or none.
The parts carry the experiment hash and the task id in their Parquet schema metadata and
their SHA-256 is in the manifest: a damaged part (bad checksum, unreadable) or a foreign
one (another experiment's) is detected, reported and recomputed on the next run, and
`load_store` refuses a damaged store instead of half-reading it.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import os
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kicktimes import __version__
from kicktimes.experiment.config import Experiment
from kicktimes.experiment.tasks import COLLISION_COLUMNS, RESULT_COLUMNS, Task, TaskOutput

__all__ = ["Store", "StoreWarning", "load_store"]

MANIFEST = "manifest.json"
LAYOUT_VERSION = 1
PARTS = ("results", "collisions")
_TMP_PREFIX = ".tmp-"
_META_KEY = b"kicktimes"


class StoreWarning(UserWarning):
    """A store problem that a run repairs: damaged or foreign part, leftover temp file."""


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _sha256(path: str | os.PathLike) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _atomic_write(path: Path, write) -> None:
    """``write(tmp)`` into a temp file beside ``path``, fsync, then ``os.replace``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=_TMP_PREFIX, suffix=path.suffix)
    os.close(fd)
    try:
        write(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def _schemas():
    import pyarrow as pa

    results = pa.schema(
        [
            ("radius", pa.float64()),
            ("ic", pa.int64()),
            ("system", pa.string()),
            ("diagnostic", pa.string()),
            ("value", pa.float64()),
            ("note", pa.string()),
        ]
    )
    collisions = pa.schema(
        [
            ("radius", pa.float64()),
            ("ic", pa.int64()),
            ("t_window", pa.float64()),
            ("n_pp", pa.int64()),
            ("pp_times", pa.list_(pa.float64())),
        ]
    )
    return {"results": results, "collisions": collisions}


def _part_meta(experiment: Experiment, task: Task, part: str) -> dict:
    return {
        "experiment_hash": experiment.hash(),
        "experiment_name": experiment.name,
        "task_id": task.id,
        "part": part,
        "radius": task.radius,
        "ic_start": task.ic_start,
        "ic_stop": task.ic_stop,
        "kicktimes_version": __version__,
    }


def _read_part_meta(path: Path) -> dict:
    """The kicktimes metadata of a part file; raises ValueError if unreadable or missing."""
    import pyarrow.parquet as pq

    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # pyarrow raises several types for a broken file
        raise ValueError(f"unreadable Parquet file ({exc})") from None
    raw = (schema.metadata or {}).get(_META_KEY)
    if raw is None:
        raise ValueError("no kicktimes metadata (not a part file of a kicktimes store)")
    try:
        return json.loads(raw)
    except json.JSONDecodeError as exc:
        raise ValueError(f"corrupt kicktimes metadata ({exc})") from None


def _part_path(root: Path, part: str, task_id: str) -> Path:
    return root / part / f"{task_id}.parquet"


class StoreWriter:
    """Opens (creating or resuming) the store of one experiment and writes finished tasks.

    Only the driver process writes: workers return their tables, so the store may live on
    a disk the workers cannot see (a Dask cluster).
    """

    def __init__(self, path: str | os.PathLike, experiment: Experiment):
        self.root = Path(path)
        self.experiment = experiment
        self.hash = experiment.hash()
        self.all_tasks = {t.id: t for t in experiment.tasks()}
        self.problems: list[str] = []
        if self.root.exists() and not self.root.is_dir():
            raise ValueError(f"store: {os.fspath(self.root)!r} exists and is not a directory")
        manifest_path = self.root / MANIFEST
        if manifest_path.exists():
            self.manifest = _read_manifest(self.root)
            old_hash = self.manifest.get("experiment_hash")
            if old_hash != self.hash:
                old_name = self.manifest.get("experiment", {}).get("name", "?")
                raise ValueError(
                    f"store {os.fspath(self.root)!r} holds experiment {old_name!r} (hash "
                    f"{old_hash}), not experiment {experiment.name!r} (hash {self.hash}); "
                    "refusing to mix them: use another --out directory, or delete the store "
                    "to start over"
                )
            if self.manifest.get("kicktimes_version") != __version__:
                self._report(
                    f"store was created by kicktimes {self.manifest.get('kicktimes_version')}, "
                    f"resuming with {__version__}"
                )
        else:
            if self.root.is_dir() and any(self.root.iterdir()):
                raise ValueError(
                    f"store: {os.fspath(self.root)!r} is a non-empty directory without a "
                    f"{MANIFEST}; it is not a kicktimes store (choose an empty or new directory)"
                )
            created = _now()
            self.manifest = {
                "layout": LAYOUT_VERSION,
                "kicktimes_version": __version__,
                "experiment": experiment.to_dict(),
                "experiment_hash": self.hash,
                "n_tasks": len(self.all_tasks),
                "tasks": {},
                "created": created,
                "updated": created,
            }
            self._write_manifest()
        self._clean_temporaries()
        self._verify_finished()
        self._check_strays()

    # ----------------------------------------------------------------- checking
    def _report(self, message: str) -> None:
        self.problems.append(message)
        warnings.warn(f"store {os.fspath(self.root)}: {message}", StoreWarning, stacklevel=3)

    def _clean_temporaries(self) -> None:
        for folder in (self.root, *(self.root / p for p in PARTS)):
            if not folder.is_dir():
                continue
            for tmp in folder.glob(f"{_TMP_PREFIX}*"):
                self._report(f"removing leftover temporary file {tmp.name} of an interrupted run")
                tmp.unlink()

    def _verify_finished(self) -> None:
        tasks = self.manifest["tasks"]
        for task_id in list(tasks):
            if task_id not in self.all_tasks:
                self._report(
                    f"manifest entry {task_id!r} is not a task of this experiment; dropped"
                )
                del tasks[task_id]
                continue
            problem = _check_entry(self.root, task_id, tasks[task_id], self.hash)
            if problem is not None:
                self._report(f"task {task_id}: {problem}; it will be recomputed")
                del tasks[task_id]
        self._write_manifest()

    def _check_strays(self) -> None:
        """Part files not in the manifest: a kill between part and manifest, or foreign."""
        for part in PARTS:
            folder = self.root / part
            if not folder.is_dir():
                continue
            for path in sorted(folder.glob("*.parquet")):
                task_id = path.stem
                if task_id in self.manifest["tasks"]:
                    continue
                try:
                    meta = _read_part_meta(path)
                except ValueError as exc:
                    self._report(f"{part}/{path.name}: {exc}; it will be recomputed")
                    path.unlink()
                    continue
                if meta.get("experiment_hash") != self.hash or task_id not in self.all_tasks:
                    self._report(
                        f"{part}/{path.name} is a foreign part (experiment "
                        f"{meta.get('experiment_name')!r}, hash {meta.get('experiment_hash')}); "
                        "removed, the task will be recomputed"
                    )
                    path.unlink()
                # a part of this experiment that the manifest does not list yet (the run was
                # stopped between the two writes) is simply overwritten by the recomputation

    # ------------------------------------------------------------------ writing
    @property
    def finished(self) -> set[str]:
        return set(self.manifest["tasks"])

    def pending(self) -> list[Task]:
        done = self.finished
        return [t for t in self.all_tasks.values() if t.id not in done]

    def write(self, output: TaskOutput) -> None:
        """Write the task's two parts atomically, then record them in the manifest."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        task = output.task
        entry = {
            "radius_index": task.radius_index,
            "radius": task.radius,
            "ic_start": task.ic_start,
            "ic_stop": task.ic_stop,
        }
        schemas = _schemas()
        for part, df in (("results", output.results), ("collisions", output.collisions)):
            meta = {_META_KEY: json.dumps(_part_meta(self.experiment, task, part)).encode()}
            schema = schemas[part].with_metadata(meta)
            table = pa.Table.from_pandas(df, schema=schema, preserve_index=False)
            path = _part_path(self.root, part, task.id)
            _atomic_write(path, lambda tmp, table=table: pq.write_table(table, tmp))
            prefix = "" if part == "results" else "collisions_"
            entry[f"{prefix}file"] = f"{part}/{path.name}"
            entry[f"{prefix}sha256"] = _sha256(path)
            entry[f"{prefix}rows"] = table.num_rows
        entry["timings"] = {k: round(v, 6) for k, v in output.timings.items()}
        entry["finished"] = _now()
        self.manifest["tasks"][task.id] = entry
        self._write_manifest()

    def _write_manifest(self) -> None:
        self.manifest["updated"] = _now()
        text = json.dumps(self.manifest, indent=1, allow_nan=False)

        def write(tmp):
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)

        _atomic_write(self.root / MANIFEST, write)


def _read_manifest(root: Path) -> dict:
    path = root / MANIFEST
    try:
        with open(path, encoding="utf-8") as fh:
            manifest = json.load(fh)
    except (OSError, json.JSONDecodeError) as exc:
        raise ValueError(
            f"damaged store {os.fspath(root)!r}: cannot read {MANIFEST} ({exc})"
        ) from None
    for key in ("experiment", "experiment_hash", "tasks", "kicktimes_version"):
        if key not in manifest:
            raise ValueError(f"damaged store {os.fspath(root)!r}: {MANIFEST} has no {key!r} entry")
    return manifest


def _check_entry(root: Path, task_id: str, entry: dict, exp_hash: str) -> str | None:
    """None if both parts of a finished task are intact and ours, else what is wrong."""
    for part in PARTS:
        prefix = "" if part == "results" else "collisions_"
        rel = entry.get(f"{prefix}file")
        sha = entry.get(f"{prefix}sha256")
        if rel is None or sha is None:
            return f"manifest entry lacks the {part} part"
        path = root / rel
        if not path.is_file():
            return f"part {rel} is missing"
        if _sha256(path) != sha:
            return f"part {rel} is damaged (SHA-256 does not match the manifest)"
        try:
            meta = _read_part_meta(path)
        except ValueError as exc:
            return f"part {rel}: {exc}"
        if meta.get("experiment_hash") != exp_hash or meta.get("task_id") != task_id:
            return (
                f"part {rel} is foreign (experiment {meta.get('experiment_name')!r}, hash "
                f"{meta.get('experiment_hash')}, task {meta.get('task_id')!r})"
            )
    return None


@dataclass(frozen=True, repr=False)
class Store:
    """A loaded result store (see `load_store`).

    Attributes
    ----------
    path : Path
    experiment : Experiment
    manifest : dict
    results : DataFrame
        Tidy rows ``radius, ic, system, diagnostic, value, note`` of every finished task,
        ordered by radius, IC, then as computed.
    collisions : DataFrame
        ``radius, ic, t_window, n_pp, pp_times`` (one row per radius and IC).
    missing_tasks : list of str
        Ids of the experiment's tasks not finished yet (empty for a complete store).
    """

    path: Path
    experiment: Experiment
    manifest: dict
    results: pd.DataFrame
    collisions: pd.DataFrame
    missing_tasks: list

    @property
    def complete(self) -> bool:
        """True when every task of the experiment is in the store."""
        return not self.missing_tasks

    @property
    def timings(self) -> pd.DataFrame:
        """Per-task stage timings (seconds) recorded by the run, one row per task."""
        rows = {tid: e.get("timings", {}) for tid, e in self.manifest["tasks"].items()}
        return pd.DataFrame.from_dict(rows, orient="index").sort_index()

    def summary(self) -> str:
        n = len(self.experiment.tasks())
        done = n - len(self.missing_tasks)
        return (
            f"Store {os.fspath(self.path)!r}: experiment {self.experiment.name!r} (hash "
            f"{self.manifest['experiment_hash']}), kicktimes {self.manifest['kicktimes_version']}"
            f"\n  {done}/{n} tasks finished; {len(self.results)} result rows, "
            f"{len(self.collisions)} collision rows"
        )

    def __repr__(self) -> str:
        n = len(self.experiment.tasks())
        return (
            f"Store(path={os.fspath(self.path)!r}, experiment={self.experiment.name!r}, "
            f"tasks={n - len(self.missing_tasks)}/{n}, results={len(self.results)} rows)"
        )


def load_store(path: str | os.PathLike, *, verify: bool = True) -> Store:
    """Load a result store written by `run_experiment`.

    Parameters
    ----------
    path : path-like
        The store directory.
    verify : bool, default True
        Check every listed part's SHA-256 and metadata before reading.

    Returns
    -------
    Store
        ``.results``, ``.collisions``, ``.experiment``, ``.manifest``, ``.missing_tasks``.
        An unfinished store loads (with ``missing_tasks`` non-empty).

    Raises
    ------
    ValueError
        Not a store, unreadable manifest, or a damaged, missing or foreign part file (the
        message names it; rerunning the experiment on the store recomputes it).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    root = Path(path)
    if not (root / MANIFEST).is_file():
        raise ValueError(f"path: {os.fspath(root)!r} is not a kicktimes store (no {MANIFEST})")
    manifest = _read_manifest(root)
    try:
        experiment = Experiment.from_record(manifest["experiment"])
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"damaged store {os.fspath(root)!r}: bad experiment record ({exc})"
        ) from None
    if experiment.hash() != manifest["experiment_hash"]:
        raise ValueError(
            f"damaged store {os.fspath(root)!r}: the recorded experiment hashes to "
            f"{experiment.hash()}, the manifest says {manifest['experiment_hash']}"
        )
    entries = manifest["tasks"]
    order = [t.id for t in experiment.tasks()]
    finished = [tid for tid in order if tid in entries]
    schemas = _schemas()
    tables = {part: [] for part in PARTS}
    for tid in finished:
        entry = entries[tid]
        if verify:
            problem = _check_entry(root, tid, entry, manifest["experiment_hash"])
            if problem is not None:
                raise ValueError(
                    f"damaged store {os.fspath(root)!r}: task {tid}: {problem}. Rerun the "
                    "experiment on this store to recompute it"
                )
        for part in PARTS:
            rel = entry["file" if part == "results" else "collisions_file"]
            try:
                table = pq.read_table(root / rel, schema=schemas[part])
            except Exception as exc:
                raise ValueError(
                    f"damaged store {os.fspath(root)!r}: cannot read {rel} ({exc})"
                ) from None
            tables[part].append(table.replace_schema_metadata(None))
    frames = {}
    for part in PARTS:
        if tables[part]:
            frames[part] = pa.concat_tables(tables[part]).to_pandas()
        else:
            columns = RESULT_COLUMNS if part == "results" else COLLISION_COLUMNS
            frames[part] = schemas[part].empty_table().to_pandas()[list(columns)]
    frames["collisions"] = frames["collisions"].sort_values(["radius", "ic"], kind="stable")
    frames["collisions"] = frames["collisions"].reset_index(drop=True)
    frames["results"] = frames["results"].sort_values(["radius", "ic"], kind="stable")
    frames["results"] = frames["results"].reset_index(drop=True)
    return Store(
        path=root,
        experiment=experiment,
        manifest=manifest,
        results=frames["results"],
        collisions=frames["collisions"],
        missing_tasks=[tid for tid in order if tid not in entries],
    )
