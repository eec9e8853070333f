"""Files written whole or not at all, and their digests: the one I/O helper of kicktimes.

Every file kicktimes writes (store parts and manifests, run and kick-schedule files, the
report's figures, tables and cache) goes through :func:`atomic_write`: the content is
written to a temporary file beside the target, flushed to disk, given the mode a plain
``open(path, "w")`` would have (``0666 & ~umask``) and moved into place with
``os.replace``, so a reader sees the old file or the new one, never half of one, and an
interrupted write leaves no temporary file behind.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

__all__ = ["TMP_PREFIX", "atomic_write", "atomic_write_bytes", "file_sha256", "read_csv_exact",
           "umask"]

#: Prefix of the temporary files (a store treats leftovers with it as debris).
TMP_PREFIX = ".tmp-"


def umask() -> int:
    """The process umask, read without changing it where the OS allows (Linux)."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    # os.umask can only be read by setting it; put it straight back
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def atomic_write(path: str | os.PathLike, write) -> None:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then move it into place.

    Parameters
    ----------
    path : path-like
        The target; its folder is created if needed.
    write : callable
        ``write(tmp_path)`` writes the whole content to ``tmp_path`` (a ``str``).

    Notes
    -----
    ``mkstemp`` creates the file 0600; it is given ``0666 & ~umask`` and fsynced before
    ``os.replace``. On any exception (``KeyboardInterrupt`` included) the temporary file
    is removed and the exception propagates; ``path`` is untouched.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
    >>> atomic_write(target, lambda tmp: pathlib.Path(tmp).write_text("hello"))
    >>> target.read_text()
    'hello'
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=TMP_PREFIX, suffix=path.suffix)
    os.close(fd)
    try:
        write(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
            os.chmod(tmp, 0o666 & ~umask())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> str:
    """:func:`atomic_write` of ``data``; returns its SHA-256 (hex)."""

    def write(tmp):
        with open(tmp, "wb") as fh:
            fh.write(data)

    atomic_write(path, write)
    return hashlib.sha256(data).hexdigest()


def file_sha256(path: str | os.PathLike) -> str:
    """SHA-256 (hex) of a file's bytes, read in 1 MiB blocks (memory O(1))."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_csv_exact(path):
    """``pandas.read_csv(path)`` with every float exactly as written: pandas' round-trip
    parser, which pandas 3 made the default (and deprecated the option for); before it,
    the default parser misses the last bit of some floats."""
    import pandas as pd

    if int(pd.__version__.split(".")[0]) >= 3:
        return pd.read_csv(path)
    return pd.read_csv(path, float_precision="round_trip")

