"""Kick times in files: CSV with a JSON sidecar, or Parquet with the metadata in its schema."""

from __future__ import annotations

import json
import numbers
import os
from pathlib import Path

import numpy as np

from kicktimes.schedules._base import Schedule
from kicktimes.schedules._validate import _check_t_max, _float_array

# ----------------------------------------------------------------------------------- I/O
_TIME_COLUMNS = ("kick_time", "pp_time", "pp_times", "time", "t")
_CSV_MARK = "# kicktimes metadata: "


def _check_path(path, name="path"):
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"{name} must be a str or path, got {type(path).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise ValueError(f"{name} must end in .csv or .parquet, got {str(path)!r}")
    return path, suffix


def write_kick_times(times, path, *, t_max=None, schedule=None, seed=None, metadata=None):
    """Write kick times to ``path`` (.csv or .parquet) atomically, with metadata.

    Parameters
    ----------
    times : array_like
        Sorted, finite, ``> 0`` (and ``<= t_max`` when given). Stored as the float64
        column ``kick_time``; values round-trip exactly in both formats.
    path : str or path
        ``.csv`` or ``.parquet``. Written to a temporary file in the same directory
        and moved into place with ``os.replace``: readers never see a partial file.
    t_max, schedule, seed, metadata : keyword-only, optional
        Stored as JSON ``{"format", "kicktimes_version", "n_kicks", "t_max", "seed",
        "schedule", "metadata"}``: in the Parquet schema metadata (key ``kicktimes``) or,
        for a CSV, in the sidecar file ``<path>.json`` (``kicks.csv.json``), so that the
        CSV itself is plain (one header line ``kick_time``, one time per line) and any CSV
        reader takes it as it is.

    Returns
    -------
    pathlib.Path
    """
    path, suffix = _check_path(path)
    arr = _float_array(times, "times", lower="positive", sorted_=True)
    if t_max is not None:
        t_max = _check_t_max(t_max)
        if arr.size and arr[-1] > t_max:
            raise ValueError(f"times must lie in (0, t_max={t_max!r}], got {float(arr[-1])!r}")
    if schedule is not None and not isinstance(schedule, Schedule):
        raise TypeError(f"schedule must be a kicktimes Schedule, got {type(schedule).__name__}")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, numbers.Integral)):
        raise TypeError(f"seed must be an int or None, got {seed!r}")
    from kicktimes import __version__

    meta = {
        "format": "kicktimes.kick_times/1",
        "kicktimes_version": __version__,
        "n_kicks": int(arr.size),
        "t_max": t_max,
        "seed": None if seed is None else int(seed),
        "schedule": None if schedule is None else schedule.to_dict(),
        "metadata": metadata,
    }
    try:
        meta_json = json.dumps(meta, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"metadata must be JSON-serialisable without NaN/inf: {exc}") from None

    from kicktimes.fileio import atomic_write

    if suffix == ".csv":

        def write_csv(tmp):
            with open(tmp, "w", newline="") as fh:
                fh.write("kick_time\n")
                # repr is the shortest string that parses back to the same double
                fh.writelines(f"{x!r}\n" for x in arr.tolist())

        # sidecar first: a reader that sees the new CSV also sees its metadata
        atomic_write(_sidecar(path), lambda tmp: Path(tmp).write_text(meta_json + "\n"))
        atomic_write(path, write_csv)
    else:
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.table({"kick_time": pa.array(arr, type=pa.float64())})
        table = table.replace_schema_metadata({"kicktimes": meta_json})
        atomic_write(path, lambda tmp: pq.write_table(table, tmp))
    return path


def _sidecar(path: Path) -> Path:
    """The metadata file of a CSV of kick times: ``kicks.csv`` -> ``kicks.csv.json``."""
    return path.with_name(path.name + ".json")


def read_kick_times(path, *, column=None, with_metadata=False):
    """Read kick (or collision) times from a .csv or .parquet file.

    Parameters
    ----------
    path : str or path
    column : str, optional
        Column to read; by default ``kick_time``, else ``pp_time``, ``pp_times``,
        ``time``, ``t``, else the file's only column.
    with_metadata : bool, keyword-only
        Also return the metadata dict written by :func:`write_kick_times` (``{}`` for
        foreign files).

    Returns
    -------
    numpy.ndarray or (numpy.ndarray, dict)
        The times, validated: finite, ``> 0``, sorted, ``<= t_max`` of the metadata.
    """
    path, suffix = _check_path(path)
    meta = {}
    try:
        if suffix == ".csv":
            import pandas as pd

            skip = 0
            with open(path) as fh:
                # files written before version 0.2 carry the metadata in a comment line
                for line in fh:
                    if not line.startswith("#"):
                        break
                    skip += 1
                    if line.startswith(_CSV_MARK):
                        meta = json.loads(line[len(_CSV_MARK) :])
            sidecar = _sidecar(path)
            if not meta and sidecar.exists():
                meta = json.loads(sidecar.read_text())
                if not isinstance(meta, dict):
                    raise ValueError(f"{str(sidecar)!r} does not hold a JSON object")
            # read text and let float() parse it: correctly rounded whatever the pandas version
            frame = pd.read_csv(path, skiprows=skip, dtype=str, keep_default_na=False)
            data = {c: frame[c].to_numpy() for c in frame.columns}
        else:
            import pyarrow.parquet as pq

            table = pq.read_table(path)
            raw = (table.schema.metadata or {}).get(b"kicktimes")
            meta = {} if raw is None else json.loads(raw)
            data = {c: table.column(c).to_numpy() for c in table.column_names}
    except (ValueError, OSError) as exc:  # JSON, pandas and Arrow parse errors
        if isinstance(exc, FileNotFoundError):
            raise
        raise ValueError(f"invalid kick-time file {str(path)!r}: {exc}") from None
    columns = list(data)
    if column is None:
        column = next((c for c in _TIME_COLUMNS if c in columns), None)
        if column is None and len(columns) == 1:
            column = columns[0]
        if column is None:
            raise ValueError(
                f"{str(path)!r} has columns {columns}; pass column= (looked for {_TIME_COLUMNS})"
            )
    elif column not in columns:
        raise ValueError(f"column {column!r} is not in {str(path)!r}; columns are {columns}")
    what = f"column {column!r} of {str(path)!r}"
    try:
        values = data[column]
        if values.dtype == object:
            values = np.array([float(v) for v in values], dtype=np.float64)
        times = _float_array(values, what, lower="positive", sorted_=True)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"invalid kick-time file: {what}: {exc}") from None
    n_kicks = meta.get("n_kicks")
    if n_kicks is not None and n_kicks != times.size:
        raise ValueError(
            f"invalid kick-time file {str(path)!r}: its metadata says {n_kicks} kicks, the file "
            f"holds {times.size} (a stale {_sidecar(path).name}?)"
        )
    t_max = meta.get("t_max")
    if t_max is not None and times.size and times[-1] > t_max:
        raise ValueError(f"invalid kick-time file {str(path)!r}: times exceed t_max={t_max!r}")
    times = times.copy()
    return (times, meta) if with_metadata else times
