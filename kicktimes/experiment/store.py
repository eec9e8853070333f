"""The result store of a sweep: Parquet part files per finished task plus a manifest.

Layout (docs/experiments.md)::

    STORE/manifest.json
    STORE/results/<task id>.parquet       tidy diagnostics of the task
    STORE/collisions/<task id>.parquet    disk-disk collision times of the task

Every file is written to a temporary name in the same folder and moved into place with
``os.replace`` (atomic on POSIX and Windows), so a killed run leaves whole files or none;
files get the permissions the umask allows (as ``open`` would), not ``mkstemp``'s 0600.
One writer at a time: `StoreWriter` holds an advisory lock (``fcntl.flock`` on
``STORE/.lock``), so a second run on the same store is refused (or waits) instead of
deleting the first run's in-flight temporary files. Readers take no lock (every write is
atomic). Opening a complete, intact store writes nothing, so a read-only store can be
loaded and "resumed". Manifest entries must name the task's own files: a path that
points elsewhere (``../x.parquet``, an absolute path) is refused, never read.
The parts carry the experiment hash and the task id in their Parquet schema metadata and
their SHA-256 is in the manifest: a damaged part (bad checksum, unreadable) or a foreign
one (another experiment's) is detected, reported and recomputed on the next run, and
`load_store` refuses a damaged store instead of half-reading it.
"""

from __future__ import annotations

import datetime as _dt
import errno
import json
import os
import socket
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from kicktimes import __version__
from kicktimes.experiment.config import Experiment
from kicktimes.experiment.disks import DisksExperiment
from kicktimes.experiment.disks_tasks import DISKS_COLLISION_COLUMNS, DISKS_RESULT_COLUMNS
from kicktimes.experiment.tasks import COLLISION_COLUMNS, RESULT_COLUMNS, Task, TaskOutput
from kicktimes.fileio import TMP_PREFIX, atomic_write, file_sha256

__all__ = [
    "Store",
    "StoreLockedError",
    "StoreWarning",
    "load_store",
    "pending_tasks",
    "read_manifest",
]

MANIFEST = "manifest.json"
LOCK = ".lock"
LAYOUT_VERSION = 1
PARTS = ("results", "collisions")
_META_KEY = b"kicktimes"
# errors that mean "this store cannot be written here" rather than a bug
_READ_ONLY_ERRNOS = {errno.EACCES, errno.EPERM, errno.EROFS}


class StoreWarning(UserWarning):
    """A store problem that a run repairs: damaged or foreign part, leftover temp file."""


class StoreLockedError(RuntimeError):
    """Another process is writing the store (it holds the store's lock)."""


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _schemas(experiment=None):
    """The part files' schemas: a radius sweep's, or a disks sweep's (``n_disks`` first;
    one collisions row per tagged disk, with its ``disk`` and its interval ``speeds``)."""
    import pyarrow as pa

    if isinstance(experiment, DisksExperiment):
        return _disks_schemas()
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


def _disks_schemas():
    import pyarrow as pa

    head = [("n_disks", pa.int64()), ("radius", pa.float64()), ("ic", pa.int64())]
    results = pa.schema(head + [("system", pa.string()), ("diagnostic", pa.string()),
                                ("value", pa.float64()), ("note", pa.string())])
    collisions = pa.schema(head + [("disk", pa.int64()), ("t_window", pa.float64()),
                                   ("n_pp", pa.int64()), ("pp_times", pa.list_(pa.float64())),
                                   ("speeds", pa.list_(pa.float64()))])
    return {"results": results, "collisions": collisions}


def _experiment_from_record(record):
    """The experiment a store's record describes: a `DisksExperiment` (``kind = "disks"``)
    or an `Experiment`."""
    if isinstance(record, dict) and record.get("kind") == DisksExperiment.kind:
        return DisksExperiment.from_record(record)
    return Experiment.from_record(record)


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
        meta = json.loads(raw)
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"corrupt kicktimes metadata ({exc})") from None
    if not isinstance(meta, dict):
        raise ValueError(f"corrupt kicktimes metadata (a {type(meta).__name__}, not an object)")
    return meta


def _part_path(root: Path, part: str, task_id: str) -> Path:
    return root / part / f"{task_id}.parquet"


def _lock_holder(fd: int) -> str:
    """What the lock file says about the process holding it (best effort)."""
    try:
        info = json.loads(os.pread(fd, 4096, 0).decode("utf-8") or "{}")
        return f" (pid {info['pid']} on {info['host']}, since {info['since']})"
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return ""


def _acquire_lock(root: Path, wait) -> tuple[int | None, bool]:
    """Hold the store's advisory write lock; returns its file descriptor and whether the
    store is writable.

    The descriptor is None when no lock file exists and none can be created (a
    read-only store): nothing will be written then, so none is needed. ``wait``: False
    refuses at once, True blocks, a number is a timeout in seconds.
    """
    try:
        import fcntl
    except ImportError:  # not POSIX: no advisory locks; one writer is the user's duty
        return None, True
    path = root / LOCK
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o666)
        writable = True
    except OSError as exc:
        if exc.errno not in _READ_ONLY_ERRNOS:
            raise
        if not path.exists():
            return None, False
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
        writable = False
    deadline = None if wait is True else time.monotonic() + float(wait or 0.0)
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if deadline is None else fcntl.LOCK_NB))
            break
        except BlockingIOError:
            if time.monotonic() < deadline:
                time.sleep(0.1)
                continue
            holder = _lock_holder(fd)
            os.close(fd)
            waited = "" if not wait else f" after waiting {float(wait):g} s"
            raise StoreLockedError(
                f"store {os.fspath(root)!r} is being written by another kicktimes run"
                f"{holder}{waited}; wait for it to finish, or let this run wait for it "
                "(run_experiment(..., wait=True), kicktimes run --wait)"
            ) from None
        except BaseException:
            os.close(fd)
            raise
    if writable:
        info = {"pid": os.getpid(), "host": socket.gethostname(), "since": _now()}
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps(info).encode("utf-8"), 0)
    return fd, writable


def _release_lock(fd: int | None) -> None:
    if fd is None:
        return
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)


def _only_leftovers(root: Path) -> bool:
    """True if the folder holds nothing but a lock and temporary files (an aborted start)."""
    return all(p.name == LOCK or p.name.startswith(TMP_PREFIX) for p in root.iterdir())


class StoreWriter:
    """Opens (creating or resuming) the store of one experiment and writes finished tasks.

    Only the driver process writes: workers return their tables, so the store may live on
    a disk the workers cannot see (a Dask cluster). The writer holds the store's lock
    from construction to `close` (it is a context manager); ``wait`` says what to do
    when another writer holds it (False: raise `StoreLockedError`, True: wait, a number:
    wait at most that many seconds).

    A store that cannot be written (read-only folder or file system) opens if it is
    complete and intact; anything that would need a write raises `PermissionError`.
    """

    def __init__(self, path: str | os.PathLike, experiment: Experiment, *, wait=False):
        self.root = Path(path)
        self.experiment = experiment
        self.hash = experiment.hash()
        self.all_tasks = {t.id: t for t in experiment.tasks()}
        self.problems: list[str] = []
        self._lock = None
        if self.root.exists() and not self.root.is_dir():
            raise ValueError(f"store: {os.fspath(self.root)!r} exists and is not a directory")
        manifest_path = self.root / MANIFEST
        # refuse a foreign folder before leaving a lock file in it
        if self.root.is_dir() and not manifest_path.exists() and not _only_leftovers(self.root):
            raise ValueError(
                f"store: {os.fspath(self.root)!r} is a non-empty directory without a "
                f"{MANIFEST}; it is not a kicktimes store (choose an empty or new directory)"
            )
        self.root.mkdir(parents=True, exist_ok=True)
        self._lock, writable = _acquire_lock(self.root, wait)
        self.writable = writable and os.access(self.root, os.W_OK)
        try:
            self._open(manifest_path)
        except BaseException:
            self.close()
            raise

    def _open(self, manifest_path: Path) -> None:
        experiment = self.experiment
        if manifest_path.exists():
            self.manifest = _read_manifest(self.root)
            old_hash = self.manifest.get("experiment_hash")
            if old_hash != self.hash:
                old_name = self.manifest["experiment"].get("name", "?")
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

    def close(self) -> None:
        """Release the store's lock (idempotent)."""
        fd, self._lock = self._lock, None
        _release_lock(fd)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _need_write(self, action: str) -> None:
        if not self.writable:
            raise PermissionError(
                errno.EACCES,
                f"store {os.fspath(self.root)!r} is read-only; cannot {action}",
            )

    # ----------------------------------------------------------------- checking
    def _report(self, message: str) -> None:
        self.problems.append(message)
        warnings.warn(f"store {os.fspath(self.root)}: {message}", StoreWarning, stacklevel=3)

    def _clean_temporaries(self) -> None:
        for folder in (self.root, *(self.root / p for p in PARTS)):
            if not folder.is_dir():
                continue
            for tmp in folder.glob(f"{TMP_PREFIX}*"):
                # we hold the lock, so no other writer owns this file: it is a leftover
                self._need_write(f"remove the leftover temporary file {tmp.name}")
                self._report(f"removing leftover temporary file {tmp.name} of an interrupted run")
                tmp.unlink()

    def _verify_finished(self) -> None:
        tasks = self.manifest["tasks"]
        changed = False
        for task_id in list(tasks):
            if task_id not in self.all_tasks:
                self._need_write(f"drop the manifest entry {task_id!r}")
                self._report(
                    f"manifest entry {task_id!r} is not a task of this experiment; dropped"
                )
                del tasks[task_id]
                changed = True
                continue
            problem = _check_entry(self.root, task_id, tasks[task_id], self.hash)
            if problem is not None:
                self._need_write(f"recompute task {task_id} ({problem})")
                self._report(f"task {task_id}: {problem}; it will be recomputed")
                del tasks[task_id]
                changed = True
        # an intact store is left untouched: reading must work on a read-only disk
        if changed:
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
                    self._need_write(f"remove the damaged part {part}/{path.name}")
                    self._report(f"{part}/{path.name}: {exc}; it will be recomputed")
                    path.unlink()
                    continue
                if meta.get("experiment_hash") != self.hash or task_id not in self.all_tasks:
                    self._need_write(f"remove the foreign part {part}/{path.name}")
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

        self._need_write(f"write task {output.task.id}")
        task = output.task
        entry = {
            "radius_index": task.radius_index,
            "radius": task.radius,
            "ic_start": task.ic_start,
            "ic_stop": task.ic_stop,
        }
        schemas = _schemas(self.experiment)
        for part, df in (("results", output.results), ("collisions", output.collisions)):
            meta = {_META_KEY: json.dumps(_part_meta(self.experiment, task, part)).encode()}
            schema = schemas[part].with_metadata(meta)
            table = pa.Table.from_pandas(df, schema=schema, preserve_index=False)
            path = _part_path(self.root, part, task.id)
            atomic_write(path, lambda tmp, table=table: pq.write_table(table, tmp))
            prefix = "" if part == "results" else "collisions_"
            entry[f"{prefix}file"] = f"{part}/{path.name}"
            entry[f"{prefix}sha256"] = file_sha256(path)
            entry[f"{prefix}rows"] = table.num_rows
        entry["timings"] = {k: round(v, 6) for k, v in output.timings.items()}
        entry["finished"] = _now()
        self.manifest["tasks"][task.id] = entry
        self._write_manifest()

    def _write_manifest(self) -> None:
        self._need_write(f"write its {MANIFEST}")
        self.manifest["updated"] = _now()
        text = json.dumps(self.manifest, indent=1, allow_nan=False)

        def write(tmp):
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)

        atomic_write(self.root / MANIFEST, write)


_MANIFEST_TYPES = {
    "layout": int,
    "experiment": dict,
    "experiment_hash": str,
    "tasks": dict,
    "kicktimes_version": str,
}


def _read_manifest(root: Path) -> dict:
    """The manifest, its structure and layout checked; ValueError naming what is wrong."""
    path = root / MANIFEST
    where = f"store {os.fspath(root)!r}"
    try:
        with open(path, encoding="utf-8") as fh:
            manifest = json.load(fh)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"damaged {where}: cannot read {MANIFEST} ({exc})") from None
    if not isinstance(manifest, dict):
        raise ValueError(
            f"damaged {where}: {MANIFEST} holds a JSON {type(manifest).__name__}, not an object"
        )
    for key, kind in _MANIFEST_TYPES.items():
        if key not in manifest:
            raise ValueError(f"damaged {where}: {MANIFEST} has no {key!r} entry")
        value = manifest[key]
        if isinstance(value, bool) or not isinstance(value, kind):
            raise ValueError(
                f"damaged {where}: {MANIFEST} entry {key!r} must be a JSON "
                f"{ {int: 'integer', dict: 'object', str: 'string'}[kind]}, got {value!r:.80}"
            )
    layout = manifest["layout"]
    if layout != LAYOUT_VERSION:
        newer = layout > LAYOUT_VERSION
        raise ValueError(
            f"{where} has layout {layout} (written by kicktimes "
            f"{manifest['kicktimes_version']}); kicktimes {__version__} reads layout "
            f"{LAYOUT_VERSION} only"
            + ("; upgrade kicktimes to read it" if newer else "; it is not a valid layout")
        )
    return manifest


def _check_entry(root: Path, task_id: str, entry, exp_hash: str) -> str | None:
    """None if both parts of a finished task are intact and ours, else what is wrong.

    The part files of a task have fixed names; an entry naming any other file (another
    task's, ``../x.parquet``, an absolute path) is refused without opening that file.
    """
    if not isinstance(entry, dict):
        return f"manifest entry is a JSON {type(entry).__name__}, not an object"
    for part in PARTS:
        prefix = "" if part == "results" else "collisions_"
        rel = entry.get(f"{prefix}file")
        sha = entry.get(f"{prefix}sha256")
        if rel is None or sha is None:
            return f"manifest entry lacks the {part} part"
        expected = f"{part}/{task_id}.parquet"
        if rel != expected:
            return (
                f"manifest entry names the file {rel!r:.200} for its {part} part, not "
                f"{expected!r}; a store's entries may only name their own files"
            )
        path = _part_path(root, part, task_id)
        if path.is_symlink():
            return f"part {rel} is a symbolic link; a store's parts must be regular files"
        if not path.is_file():
            return f"part {rel} is missing"
        if file_sha256(path) != sha:
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
            + (f"\n  {self.experiment.partner_line()}" if self.experiment.partner_line() else "")
        )

    def __repr__(self) -> str:
        n = len(self.experiment.tasks())
        return (
            f"Store(path={os.fspath(self.path)!r}, experiment={self.experiment.name!r}, "
            f"tasks={n - len(self.missing_tasks)}/{n}, results={len(self.results)} rows)"
        )


def read_manifest(path: str | os.PathLike) -> dict:
    """A store's manifest, checked (layout, structure), without reading any part file.

    Raises
    ------
    ValueError
        ``path`` is not a store, or its manifest is unreadable or malformed.
    """
    root = Path(path)
    if not (root / MANIFEST).is_file():
        raise ValueError(f"path: {os.fspath(root)!r} is not a kicktimes store (no {MANIFEST})")
    return _read_manifest(root)


def pending_tasks(experiment: Experiment, path: str | os.PathLike) -> list[Task]:
    """The tasks of ``experiment`` that the store at ``path`` does not list as finished.

    Every task when ``path`` holds no store, an unreadable one, or one of another
    experiment (a run would refuse or recompute it). Reads the manifest only: the run
    itself verifies the parts.
    """
    try:
        manifest = read_manifest(path)
    except ValueError:
        return list(experiment.tasks())
    if manifest.get("experiment_hash") != experiment.hash():
        return list(experiment.tasks())
    done = set(manifest.get("tasks") or {})
    return [t for t in experiment.tasks() if t.id not in done]


def load_store(path: str | os.PathLike, *, verify: bool = True, result_columns=None,
               categories=()) -> Store:
    """Load a result store written by `run_experiment`.

    Parameters
    ----------
    path : path-like
        The store directory.
    verify : bool, default True
        Check every listed part's SHA-256 and metadata before reading.
    result_columns : sequence of str, optional
        Read only these columns of the results (all by default).
    categories : sequence of str
        String columns of the results to read as categoricals with sorted categories (as
        ``astype("category")`` would give, without materialising the strings).

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
    return _load(path, verify=verify, result_columns=result_columns, categories=categories)


def _load(path, *, verify=True, result_columns=None, categories=()) -> Store:
    """`load_store`, optionally reading only ``result_columns`` of the results and the
    string columns ``categories`` of the results as categoricals with sorted categories
    (as ``astype("category")`` of the strings gives, without materialising 2 million
    strings: what the report reads, see `kicktimes.report.store.report_store`).
    """
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    root = Path(path)
    manifest = read_manifest(root)
    try:
        experiment = _experiment_from_record(manifest["experiment"])
    except (TypeError, ValueError, KeyError, IndexError, AttributeError) as exc:
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
    schemas = _schemas(experiment)
    disks = isinstance(experiment, DisksExperiment)
    keys = ["n_disks", "ic"] if disks else ["radius", "ic"]
    tables = {part: [] for part in PARTS}
    for tid in finished:
        entry = entries[tid]
        problem = _check_entry(root, tid, entry, manifest["experiment_hash"]) if verify else None
        if problem is None and not verify and not isinstance(entry, dict):
            problem = f"manifest entry is a JSON {type(entry).__name__}, not an object"
        if problem is not None:
            raise ValueError(
                f"damaged store {os.fspath(root)!r}: task {tid}: {problem}. Rerun the "
                "experiment on this store to recompute it"
            )
        for part in PARTS:
            # the file name is the task's, never the manifest's (see _check_entry)
            path = _part_path(root, part, tid)
            rel = f"{part}/{path.name}"
            try:
                if part == "results" and (result_columns or categories):
                    table = pq.read_table(
                        path, columns=result_columns, read_dictionary=list(categories)
                    )
                else:
                    table = pq.read_table(path, schema=schemas[part])
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
            columns = ((DISKS_RESULT_COLUMNS if part == "results" else DISKS_COLLISION_COLUMNS)
                       if disks else
                       (RESULT_COLUMNS if part == "results" else COLLISION_COLUMNS))
            if part == "results" and result_columns:
                columns = result_columns
            frames[part] = schemas[part].empty_table().to_pandas()[list(columns)]
    frames["collisions"] = frames["collisions"].sort_values(keys, kind="stable")
    frames["collisions"] = frames["collisions"].reset_index(drop=True)
    frames["results"] = frames["results"].sort_values(keys, kind="stable")
    frames["results"] = frames["results"].reset_index(drop=True)
    for column in categories:
        values = frames["results"][column]
        if not isinstance(values.dtype, pd.CategoricalDtype):  # no part: an empty table
            frames["results"][column] = values.astype("category")
        else:
            ordered = sorted(values.cat.categories)
            frames["results"][column] = values.cat.reorder_categories(ordered)
    return Store(
        path=root,
        experiment=experiment,
        manifest=manifest,
        results=frames["results"],
        collisions=frames["collisions"],
        missing_tasks=[tid for tid in order if tid not in entries],
    )
