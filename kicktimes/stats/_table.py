r"""Reading and checking a tidy table of event times from an outside source.

The input of :func:`kicktimes.stats.analyze` (and of ``kicktimes analyze``) is one row per
event: a sequence id and an event time. Each sequence also needs its observation window
``[t_start, t_end]``, taken from

* columns of the event table (constant within a sequence), or
* a second, small table with one row per sequence (``sequence``, ``t_start``, ``t_end``
  and any covariates; it may list sequences that have no events at all), or
* one window for every sequence, given as an option.

Covariates (radius, density, temperature, ...) are per-sequence numeric columns of either
table; labels (a material, a condition: ``kind = poisson``) are per-sequence text columns,
which can group the sequences but are never regressed on.

Every defect is a one-line :class:`ValueError` (or :class:`TypeError`) that names the
source, the column and the row: unsorted or duplicate times within a sequence, times
outside the window, sequences without a window, missing or non-numeric values, windows
or covariates that change within a sequence. Row numbers count data rows from 0 (a CSV
file's row ``i`` is on line ``i + 2``, after the header). Sequences without events are
kept (they count: a zero is an observation) and listed, never dropped silently.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["EventTable", "event_table", "read_table"]

_RESERVED = ("sequence", "t_start", "t_end", "t_window", "n_events", "times", "rate")


def read_table(path) -> pd.DataFrame:
    """Read a CSV or Parquet file (chosen by the suffix) into a DataFrame.

    ``attrs["source"]`` holds the file name and ``attrs["csv"]`` whether rows map to lines.
    """
    if not isinstance(path, str | os.PathLike):
        raise TypeError(f"path must be a file path, got {type(path).__name__}")
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{os.fspath(p)!r}: no such file")
    suffix = p.suffix.lower()
    name = p.name  # as every message about the table's content names it
    if suffix not in (".csv", ".parquet", ".pq"):
        raise ValueError(f"{os.fspath(p)}: the file must end in .csv or .parquet")
    if p.stat().st_size == 0:
        raise ValueError(f"{name}: the file is empty (expected a header and one row per event)")
    if suffix == ".csv":
        try:
            # strings first, so that a non-numeric value can be named (not silently NaN)
            df = pd.read_csv(p, dtype=str, keep_default_na=False, na_values=[""])
        except pd.errors.EmptyDataError:
            raise ValueError(f"{name}: the file has no header (no columns)") from None
        except pd.errors.ParserError as exc:
            detail = str(exc).strip().splitlines()[-1]
            raise ValueError(f"{name}: not a readable CSV table ({detail})") from None
        except UnicodeDecodeError:
            raise ValueError(f"{name}: not a text (UTF-8 CSV) file") from None
    else:
        import pyarrow as pa

        try:
            df = pd.read_parquet(p)
        except (pa.ArrowException, OSError) as exc:
            detail = str(exc).strip().splitlines()[0]
            detail = re.sub(r"^Could not open Parquet input source '.*?': ", "", detail)
            detail = detail.split(". ")[0].rstrip(".")
            raise ValueError(f"{name}: not a readable Parquet file ({detail})") from None
    df.attrs.update(source=p.name, csv=suffix == ".csv")
    return df


def _where(df, i):
    """'<source>, row i (line i + 2)' for messages."""
    src = df.attrs.get("source", "table")
    line = f" (line {i + 2})" if df.attrs.get("csv") else ""
    return f"{src}, row {i}{line}"


def _numeric(df, col, *, allow_missing=False):
    """Column ``col`` as float64; missing, non-numeric or infinite values raise, naming the row."""
    raw = df[col]
    values = pd.to_numeric(raw, errors="coerce")
    if pd.api.types.is_bool_dtype(raw):
        values = values.astype(float)
    values = values.to_numpy(dtype=float, na_value=np.nan)
    missing = raw.isna().to_numpy()
    bad = np.isnan(values) & ~missing
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{_where(df, i)}: column {col!r} must be numeric, got {raw.iloc[i]!r}")
    if missing.any() and not allow_missing:
        i = int(np.flatnonzero(missing)[0])
        raise ValueError(f"{_where(df, i)}: column {col!r} has a missing value")
    inf = np.isinf(values)
    if inf.any():
        i = int(np.flatnonzero(inf)[0])
        raise ValueError(
            f"{_where(df, i)}: column {col!r} must be finite, got {float(values[i])!r}"
        )
    return values


def _require(df, cols, what):
    missing = [c for c in cols if c not in df.columns]
    if missing:
        src = df.attrs.get("source", what)
        raise ValueError(
            f"{src}: no column {missing[0]!r} ({what}); the columns are {list(df.columns)!r}"
        )


def _ids(df, col):
    ids = df[col]
    missing = ids.isna().to_numpy()
    if missing.any():
        i = int(np.flatnonzero(missing)[0])
        raise ValueError(f"{_where(df, i)}: column {col!r} has a missing sequence id")
    # ids compare as text: 1 in one table and "1" in the other are the same sequence
    return ids.astype(str).to_numpy()


def _per_sequence(df, ids, values, col):
    """One value per sequence id; a value that changes within a sequence raises."""
    first = pd.Series(values).groupby(ids, sort=False, observed=True).transform("first").to_numpy()
    same = (first == values) | (np.isnan(first) & np.isnan(values))
    if not same.all():
        i = int(np.flatnonzero(~same)[0])
        raise ValueError(
            f"{_where(df, i)}: column {col!r} must be constant within sequence {str(ids[i])!r}, "
            f"got {float(values[i])!r} after {float(first[i])!r}"
        )
    out = pd.Series(values, index=ids)
    return out[~out.index.duplicated()]


@dataclass(frozen=True, repr=False)
class EventTable:
    """Checked event sequences with their windows and covariates.

    Attributes
    ----------
    sequences : pandas.DataFrame
        One row per sequence, in order of first appearance: ``sequence`` (text id),
        ``t_start``, ``t_end``, ``t_window`` (``t_end - t_start``), ``n_events``,
        ``rate`` (``n_events / t_window``), ``times`` (event times *relative to t_start*,
        increasing, in ``[0, t_window]``) and one column per covariate.
    covariates : tuple of str
        The covariate columns (numeric, constant within each sequence).
    labels : tuple of str
        The label columns (text, constant within each sequence), e.g. a condition that
        groups the sequences.
    """

    sequences: pd.DataFrame
    covariates: tuple
    labels: tuple = ()

    def __repr__(self) -> str:
        n = len(self.sequences)
        return (
            f"EventTable(n_sequences={n}, n_events={int(self.sequences['n_events'].sum())}, "
            f"empty={int((self.sequences['n_events'] == 0).sum())}, "
            f"covariates={list(self.covariates)!r}, labels={list(self.labels)!r})"
        )

    @property
    def empty_sequences(self) -> list:
        """Ids of the sequences without events in their window."""
        s = self.sequences
        return s.loc[s["n_events"] == 0, "sequence"].tolist()


def _check_names(**names):
    for key, value in names.items():
        if not isinstance(value, str) or not value:
            raise TypeError(f"{key} must be a column name (a non-empty string), got {value!r}")


def _frame(name, value):
    if isinstance(value, str | os.PathLike):
        return read_table(value)
    if isinstance(value, pd.DataFrame):
        df = value.reset_index(drop=True)
        df.attrs.setdefault("source", value.attrs.get("source", name))
        return df
    raise TypeError(f"{name} must be a DataFrame or a CSV/Parquet path, got {type(value).__name__}")


def _merge_per_sequence(values, col, series):
    """Put ``series`` (one value per sequence) into ``values[col]``, keeping the values
    an earlier table gave."""
    prev = values.get(col)
    values[col] = series if prev is None else prev.combine_first(series)


def event_table(
    events,
    *,
    windows=None,
    window=None,
    sequence="sequence",
    time="time",
    start="t_start",
    end="t_end",
    covariates=None,
    labels=None,
) -> EventTable:
    r"""Check a tidy table of event times and collect its sequences.

    Parameters
    ----------
    events : DataFrame, path or list of them
        One row per event, with a sequence-id column and a time column. Several
        tables (files) are concatenated; a sequence may not span two of them. A row
        whose time is missing declares a sequence without events (allowed only if the
        sequence has no other rows and the row carries its window).
    windows : DataFrame or path, optional
        One row per sequence: the id column, ``start`` and ``end`` columns, and
        covariates. Sequences listed here without events are empty sequences.
    window : (float, float), optional
        ``(t_start, t_end)`` for every sequence (used when neither table has window
        columns).
    sequence, time, start, end : str, optional
        Column names.
    covariates : list of str, optional
        Per-sequence numeric columns to keep (default: every further numeric column of
        the windows table, and those further columns of the event table that are numeric
        and constant within every sequence).
    labels : list of str, optional
        Per-sequence columns to keep as text (compared as strings; constant within each
        sequence). Default: with ``covariates`` None, every further column that is not
        numeric and is constant within every sequence; otherwise none. A column named
        here is a label even if it holds numbers.

    Returns
    -------
    EventTable

    Raises
    ------
    ValueError
        One line naming the source, row and column of the first defect.

    Examples
    --------
    >>> import pandas as pd
    >>> from kicktimes.stats._table import event_table
    >>> df = pd.DataFrame({"sequence": ["a", "a", "b"], "time": [0.5, 2.0, 1.0]})
    >>> tab = event_table(df, window=(0.0, 3.0))
    >>> tab.sequences[["sequence", "n_events", "t_window"]].to_dict("list")
    {'sequence': ['a', 'b'], 'n_events': [2, 1], 't_window': [3.0, 3.0]}
    """
    _check_names(sequence=sequence, time=time, start=start, end=end)
    if isinstance(events, list | tuple):
        if not events:
            raise ValueError("events must name at least one table, got an empty list")
        frames = [_frame(f"events[{k}]", e) for k, e in enumerate(events)]
    else:
        frames = [_frame("events", events)]
    win = None if windows is None else _frame("windows", windows)
    if window is not None:
        if win is not None:
            raise ValueError("give the windows either as a table (windows) or as window, not both")
        if not isinstance(window, list | tuple) or len(window) != 2:
            raise TypeError(f"window must be a pair (t_start, t_end), got {window!r}")
        try:
            w0, w1 = float(window[0]), float(window[1])
        except (TypeError, ValueError):
            raise TypeError(f"window must hold two numbers, got {window!r}") from None
        if not (np.isfinite(w0) and np.isfinite(w1) and w0 < w1):
            raise ValueError(f"window must satisfy t_start < t_end (finite), got {window!r}")
    if covariates is not None:
        if isinstance(covariates, str):
            covariates = [covariates]
        covariates = list(covariates)
        _check_names(**{f"covariates[{k}]": c for k, c in enumerate(covariates)})
        clash = [c for c in covariates if c in _RESERVED or c in (sequence, time, start, end)]
        if clash:
            raise ValueError(f"covariates must not name a reserved column, got {clash[0]!r}")

    # ---- events: ids, times, per-sequence window / covariate columns
    if all(len(df) == 0 for df in frames) and (win is None or len(win) == 0):
        names = ", ".join(df.attrs.get("source", "events") for df in frames)
        raise ValueError(f"{names}: no rows (only a header): no sequence to analyse")
    ids_all, times_all, seq_frames = [], [], []
    owner: dict[str, str] = {}
    for df in frames:
        _require(df, [sequence, time], "the event table")
        ids = _ids(df, sequence)
        t = _numeric(df, time, allow_missing=True)
        src = df.attrs.get("source", "events")
        for s in pd.unique(ids):
            if owner.setdefault(s, src) != src:
                raise ValueError(
                    f"{src}: sequence {s!r} also appears in {owner[s]}; a sequence must be in "
                    "one table"
                )
        _check_order(df, ids, t)
        ids_all.append(ids)
        times_all.append(t)
        seq_frames.append((df, ids))

    # ---- windows
    have_cols = [all(c in df.columns for c in (start, end)) for df, _ in seq_frames]
    if win is not None:
        _require(win, [sequence, start, end], "the windows table")
        wid = _ids(win, sequence)
        dup = pd.Series(wid).duplicated().to_numpy()
        if dup.any():
            i = int(np.flatnonzero(dup)[0])
            raise ValueError(f"{_where(win, i)}: sequence {str(wid[i])!r} is listed twice")
        t0 = pd.Series(_numeric(win, start), index=wid)
        t1 = pd.Series(_numeric(win, end), index=wid)
        _check_windows(win, wid, t0.to_numpy(), t1.to_numpy(), start, end)
    else:
        parts0, parts1 = [], []
        for (df, ids), has in zip(seq_frames, have_cols, strict=True):
            if has:
                a, b = _numeric(df, start), _numeric(df, end)
                _check_windows(df, ids, a, b, start, end)
                parts0.append(_per_sequence(df, ids, a, start))
                parts1.append(_per_sequence(df, ids, b, end))
            elif window is not None:
                u = pd.unique(ids)
                parts0.append(pd.Series(w0, index=u))
                parts1.append(pd.Series(w1, index=u))
            else:
                src = df.attrs.get("source", "events")
                raise ValueError(
                    f"{src}: no window for its sequences: give columns {start!r} and {end!r}, "
                    "a windows table, or window=(t_start, t_end)"
                )
        t0, t1 = pd.concat(parts0), pd.concat(parts1)

    # ---- sequences in order: the events' order, then the windows table's empty ones
    order = list(pd.unique(np.concatenate(ids_all)))
    if win is not None:
        missing = [s for s in order if s not in t0.index]
        if missing:
            raise ValueError(
                f"{win.attrs.get('source', 'windows')}: no window for sequence {missing[0]!r} "
                f"(it has events in {owner[missing[0]]})"
            )
        seen = set(order)
        order += [s for s in wid if s not in seen]

    # ---- events per sequence, inside their window
    per_seq: dict[str, np.ndarray] = {}
    for (df, ids), t in zip(seq_frames, times_all, strict=True):
        lo = t0.reindex(ids).to_numpy()
        hi = t1.reindex(ids).to_numpy()
        ok = ~np.isnan(t)
        outside = ok & ((t < lo) | (t > hi))
        if outside.any():
            i = int(np.flatnonzero(outside)[0])
            raise ValueError(
                f"{_where(df, i)}: column {time!r} = {float(t[i])!r} lies outside the window "
                f"[{float(lo[i])!r}, {float(hi[i])!r}] of sequence {str(ids[i])!r}"
            )
        for s, idx in pd.Series(np.arange(ids.size)).groupby(ids, sort=False, observed=True):
            vals = t[idx.to_numpy()]
            per_seq[s] = vals[~np.isnan(vals)] - t0[s]

    # ---- covariates
    cov_values: dict[str, pd.Series] = {}
    auto = covariates is None
    wanted = covariates or []
    taken = {sequence, time, start, end}
    sources = ([win] if win is not None else []) + [df for df, _ in seq_frames]
    if auto:
        wanted = []
        for df in sources:
            wanted += [c for c in df.columns if c not in taken and c not in wanted]
    label_values: dict[str, pd.Series] = {}
    if labels is not None:
        if isinstance(labels, str):
            labels = [labels]
        labels = list(labels)
        _check_names(**{f"labels[{k}]": c for k, c in enumerate(labels)})
        wanted = [c for c in wanted if c not in labels]
    def holders(col):
        """``(table, its rows' sequence ids)`` for each table that has ``col``, lazily."""
        return ((df, wid if df is win else _ids(df, sequence)) for df in sources
                if col in df.columns)

    for col in labels or []:
        if not any(col in df.columns for df in sources):
            raise ValueError(f"labels: no table has a column {col!r}")
        for df, ids in holders(col):
            _merge_per_sequence(label_values, col, _text_per_sequence(df, ids, col))
    for col in wanted:
        if not any(col in df.columns for df in sources):
            raise ValueError(f"covariates: no table has a column {col!r}")
        for df, ids in holders(col):
            if auto and pd.to_numeric(df[col], errors="coerce").isna().all():
                # a text label (e.g. a material name): kept as a label, out of the
                # regressions; an event-level text column (not constant) is dropped
                try:
                    series = _text_per_sequence(df, ids, col)
                except ValueError:
                    label_values.pop(col, None)
                    break
                _merge_per_sequence(label_values, col, series)
                continue
            try:
                values = _numeric(df, col, allow_missing=False)
                series = _per_sequence(df, ids, values, col)
            except ValueError:
                if auto and df is not win:
                    # an event-level column (e.g. the collision partner): not a covariate
                    cov_values.pop(col, None)
                    break
                raise
            _merge_per_sequence(cov_values, col, series)
    for col, series in list(cov_values.items()):
        lacking = [s for s in order if s not in series.index]
        if lacking and auto:
            del cov_values[col]  # e.g. an event-table column, absent for empty sequences
        elif lacking:
            raise ValueError(f"covariate {col!r} has no value for sequence {lacking[0]!r}")
        if col in _RESERVED:
            raise ValueError(f"covariate column {col!r} clashes with a reserved column name")

    for col, series in list(label_values.items()):
        lacking = [s for s in order if s not in series.index]
        if lacking and labels is None:
            del label_values[col]
        elif lacking:
            raise ValueError(f"label {col!r} has no value for sequence {lacking[0]!r}")
        if col in _RESERVED or col in cov_values:
            raise ValueError(f"label column {col!r} clashes with a reserved column name")

    if not any(t.size for t in per_seq.values()):
        names = ", ".join(df.attrs.get("source", "events") for df, _ in seq_frames)
        raise ValueError(
            f"{names}: no event in any of the {len(order)} sequences: nothing to analyse"
        )

    seqs = pd.DataFrame({"sequence": order})
    seqs["t_start"] = t0.reindex(order).to_numpy()
    seqs["t_end"] = t1.reindex(order).to_numpy()
    seqs["t_window"] = seqs["t_end"] - seqs["t_start"]
    seqs["times"] = [per_seq.get(s, np.empty(0)) for s in order]
    seqs["n_events"] = [int(t.size) for t in seqs["times"]]
    seqs["rate"] = seqs["n_events"] / seqs["t_window"]
    for col, series in cov_values.items():
        seqs[col] = series.reindex(order).to_numpy()
    for col, series in label_values.items():
        seqs[col] = series.reindex(order).to_numpy(dtype=object)
    return EventTable(sequences=seqs, covariates=tuple(cov_values), labels=tuple(label_values))


def _text_per_sequence(df, ids, col):
    """Column ``col`` as text, one value per sequence; a missing value, or a value that
    changes within a sequence, raises naming the row."""
    raw = df[col]
    missing = raw.isna().to_numpy()
    if missing.any():
        i = int(np.flatnonzero(missing)[0])
        raise ValueError(f"{_where(df, i)}: column {col!r} has a missing value")
    values = raw.astype(str).to_numpy(dtype=object)
    first = pd.Series(values).groupby(ids, sort=False, observed=True).transform("first").to_numpy()
    changed = first != values
    if changed.any():
        i = int(np.flatnonzero(changed)[0])
        raise ValueError(
            f"{_where(df, i)}: column {col!r} must be constant within sequence {str(ids[i])!r}, "
            f"got {values[i]!r} after {first[i]!r}"
        )
    out = pd.Series(values, index=ids)
    return out[~out.index.duplicated()]


def _check_order(df, ids, t):
    """Times strictly increasing within each sequence, in the table's row order."""
    ok = ~np.isnan(t)
    rows = np.flatnonzero(ok)
    frame = pd.DataFrame({"id": ids[rows], "t": t[rows], "row": rows})
    prev_t = frame.groupby("id", sort=False, observed=True)["t"].shift()
    prev_row = frame.groupby("id", sort=False, observed=True)["row"].shift()
    for kind, bad in (("duplicate", frame["t"] == prev_t), ("unsorted", frame["t"] < prev_t)):
        if bad.any():
            k = int(np.flatnonzero(bad.to_numpy())[0])
            i, j = int(frame["row"].iloc[k]), int(prev_row.iloc[k])
            what = "repeats the time of" if kind == "duplicate" else "is earlier than the time of"
            raise ValueError(
                f"{_where(df, i)}: {kind} times in sequence {str(ids[i])!r}: "
                f"{float(t[i])!r} {what} "
                f"row {j} ({float(t[j])!r}); times must increase strictly within a sequence"
            )
    # a row without time declares an empty sequence; next to events it is a missing value
    empty_rows = np.flatnonzero(~ok)
    if empty_rows.size:
        with_events = set(ids[rows])
        for i in empty_rows:
            if ids[i] in with_events:
                raise ValueError(
                    f"{_where(df, int(i))}: missing time in sequence {str(ids[i])!r}, which has "
                    "events (a row without time may only declare an empty sequence)"
                )


def _check_windows(df, ids, a, b, start, end):
    bad = ~(a < b)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{_where(df, i)}: window of sequence {str(ids[i])!r} must satisfy {start} < {end}, "
            f"got [{float(a[i])!r}, {float(b[i])!r}]"
        )
