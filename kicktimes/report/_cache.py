"""The report's file cache: atomic writes and the manifest ``out_dir/.cache.json``.

A report is built in *parts*: one per experiment (its Findings, sections, parameter files),
the all-experiments figures, and the page (``report.html`` with the timing tables). Each
part has a key, the SHA-256 of everything its files depend on: the store content as
recorded by the store's manifest (experiment hash, per-task SHA-256 entries, timestamps,
the store's path), the report options, the rendering options and the kicktimes version.
``.cache.json`` records, per part, the key it was built with, the SHA-256 of every file it
wrote and the HTML fragment it contributes to the page. A part whose key is unchanged and
whose files are all present and intact is reused as it is: nothing is recomputed or
rewritten.

Every file is written to a temporary name in the same folder and renamed over its target
(:func:`os.replace` is atomic), so an interrupted build leaves either the old file or the
new one, never half of one; ``.cache.json`` is written last, so it only ever lists
finished files.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from kicktimes import __version__
from kicktimes.fileio import atomic_write_bytes, file_sha256

#: name of the cache manifest in the report folder
CACHE_FILE = ".cache.json"
#: bumped whenever the cached fragments or keys change meaning (old caches are ignored)
CACHE_LAYOUT = 1


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _sha256_file(path: Path) -> str | None:
    """The file's SHA-256, or None when it cannot be read."""
    try:
        return file_sha256(path)
    except OSError:
        return None


def content_key(*parts) -> str:
    """SHA-256 of a JSON-serialisable description (dict keys sorted: order-free)."""
    text = json.dumps([__version__, CACHE_LAYOUT, *parts], sort_keys=True, default=str)
    return sha256_bytes(text.encode("utf-8"))


def store_key(path, manifest: dict) -> str:
    """Key of a store's content as its manifest records it: the experiment hash, every
    finished task's entry (SHA-256 of both parts, timings, finish time), the creation and
    update times and the resolved path (the report prints it)."""
    return content_key(
        "store",
        os.fspath(Path(path).resolve()),
        manifest.get("experiment_hash"),
        manifest.get("created"),
        manifest.get("updated"),
        manifest.get("tasks"),
    )


class ReportCache:
    """The parts recorded in ``out_dir/.cache.json`` (empty if absent, damaged or of
    another layout). ``fresh=True`` reuses none of them, but still knows their files, so
    that a rebuild deletes the files a part no longer writes."""

    def __init__(self, out: Path, *, fresh: bool = False):
        self.path = Path(out) / CACHE_FILE
        self.parts: dict[str, dict] = {}
        self.fresh = fresh
        try:
            record = json.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            return
        if (
            isinstance(record, dict)
            and record.get("layout") == CACHE_LAYOUT
            and isinstance(record.get("parts"), dict)
        ):
            self.parts = {
                k: v
                for k, v in record["parts"].items()
                if isinstance(v, dict) and isinstance(v.get("files"), dict)
            }

    def lookup(self, part: str, key: str) -> dict | None:
        """The recorded entry of ``part`` if it was built with ``key`` and every file it
        wrote is still there with the same SHA-256; else None."""
        entry = self.parts.get(part)
        if self.fresh or entry is None or entry.get("key") != key:
            return None
        folder = self.path.parent
        for name, sha in entry["files"].items():
            if Path(name).name != name or _sha256_file(folder / name) != sha:
                return None
        return entry

    def record(self, part: str, entry: dict) -> None:
        """Record a freshly built part; files the part's previous build wrote and this one
        did not (e.g. the PDFs after ``pdf=False``) are deleted."""
        old = self.parts.get(part)
        if old is not None:
            for name in set(old["files"]) - set(entry["files"]):
                if Path(name).name == name:
                    (self.path.parent / name).unlink(missing_ok=True)
        self.parts[part] = entry

    def save(self) -> None:
        text = json.dumps({"layout": CACHE_LAYOUT, "parts": self.parts}, indent=1)
        atomic_write_bytes(self.path, text.encode("utf-8"))
