"""Argument checks for the statistics layer.

Every message names the argument, the offending value and the valid range
(docs/architecture.md, "Bad input"); NaN and inf are rejected, never propagated.
"""

from __future__ import annotations

import numpy as np

from kicktimes.validation import check_choice, check_int, check_real, check_rng

__all__ = [
    "as_1d_float", "check_choice", "check_int", "check_intervals", "check_real", "check_rng",
    "check_times",
]


def _show(arr: np.ndarray, mask: np.ndarray) -> str:
    """The first offending entry, as ``name[i] = value``-ready text."""
    i = int(np.flatnonzero(mask)[0])
    return f"[{i}] = {float(arr[i])!r}"


def as_1d_float(name: str, value, *, allow_empty: bool = True) -> np.ndarray:
    """A finite 1-D float64 array (a fresh copy)."""
    if isinstance(value, str | bytes):
        raise TypeError(f"{name} must be a 1-D array of numbers, got {type(value).__name__}")
    try:
        arr = np.array(value, dtype=np.float64, copy=True)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a 1-D array of numbers ({exc})") from None
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    if not allow_empty and arr.size == 0:
        raise ValueError(f"{name} must not be empty")
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(f"{name} must be finite, got {name}{_show(arr, bad)}")
    return arr


def check_intervals(name: str, value, *, allow_zero: bool = False, allow_empty=True,
                    floor: float = 0.0):
    """Finite interval lengths, positive (or non-negative with ``allow_zero``); with a
    ``floor``, the positive ones at least ``floor``."""
    arr = as_1d_float(name, value, allow_empty=allow_empty)
    bad = arr < 0 if allow_zero else arr <= 0
    if floor > 0.0:
        bad |= (arr > 0) & (arr < floor)
    if bad.any():
        if floor > 0.0:
            rng = f"{'be 0 or ' if allow_zero else ''}lie in [{floor!r}, inf)"
        else:
            rng = f"lie in {'[0, inf)' if allow_zero else '(0, inf)'}"
        raise ValueError(f"{name} must {rng}, got {name}{_show(arr, bad)}")
    return arr


def check_times(name: str, value, t_window: float) -> np.ndarray:
    """Event times: finite, strictly increasing, inside the window ``[0, t_window]``."""
    arr = as_1d_float(name, value)
    outside = (arr < 0) | (arr > t_window)
    if outside.any():
        raise ValueError(
            f"{name} must lie in the window [0, t_window] = [0, {t_window!r}], "
            f"got {name}{_show(arr, outside)}"
        )
    if arr.size > 1:
        step = np.diff(arr)
        bad = step <= 0
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"{name} must be strictly increasing, got {name}[{i}] = {float(arr[i])!r} "
                f">= {name}[{i + 1}] = {float(arr[i + 1])!r}"
            )
    return arr


