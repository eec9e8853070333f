"""Argument checks of the kick schedules (values, rates, horizons, time arrays)."""

from __future__ import annotations

import numpy as np

from kicktimes.validation import check_int, check_real

DEFAULT_MAX_KICKS = 10**8
_FORMAT_VERSION = 1
_FIRST_CHUNK = 1024
_MAX_CHUNK = 2**21
_TINY = float(np.nextafter(0.0, 1.0))  # "0+": a kick time that underflowed to 0.0


# --------------------------------------------------------------------------- validation
def _check_t_max(t_max, name="t_max"):
    return check_real(name, t_max, low=0.0)


def _check_rate(rate):
    """A rate >= 0 (0 means no kicks)."""
    return check_real("rate", rate, low=0.0, low_open=False)


def _check_bool(value, name):
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _check_max_kicks(max_kicks):
    return check_int("max_kicks", max_kicks, low=1)


def _float_array(values, name, *, lower, sorted_):
    """Validated read-only float64 copy; ``lower`` is "positive" or "non-negative"."""
    arr = np.asarray(values)
    if arr.dtype == object or arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    if arr.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {arr.shape}")
    arr = arr.astype(np.float64) + 0.0  # a copy; + 0.0 turns -0.0 into 0.0 (hash by bytes)
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(f"{name} must be finite, got {float(arr[bad[0]])!r} at index {bad[0]}")
    bad = np.flatnonzero(arr <= 0 if lower == "positive" else arr < 0)
    if bad.size:
        bound = "> 0" if lower == "positive" else ">= 0"
        raise ValueError(f"{name} must be {bound}, got {float(arr[bad[0]])!r} at index {bad[0]}")
    if sorted_ and arr.size > 1:
        bad = np.flatnonzero(np.diff(arr) < 0)
        if bad.size:
            i = bad[0]
            raise ValueError(
                f"{name} must be sorted (non-decreasing), got {float(arr[i])!r} then "
                f"{float(arr[i + 1])!r} "
                f"at indices {i}, {i + 1}"
            )
    arr.flags.writeable = False
    return arr


def _run_times(run):
    """``(pp_times, t_max)`` of a duck-typed two-particle run, validated."""
    if not (hasattr(run, "pp_times") and hasattr(run, "t_max")):
        raise TypeError(
            "run must have attributes pp_times and t_max (e.g. a TwoParticleRun), "
            f"got {type(run).__name__}"
        )
    t_max = _check_t_max(run.t_max, "run.t_max")
    times = _float_array(run.pp_times, "run.pp_times", lower="positive", sorted_=True)
    if times.size and times[-1] > t_max:
        raise ValueError(
            f"run.pp_times must lie in (0, run.t_max={t_max!r}], got {float(times[-1])!r}"
        )
    return times, t_max


def _array_repr(arr, noun):
    if arr.size <= 6:
        return "[" + ", ".join(repr(float(x)) for x in arr) + "]"
    mean = f", mean {arr.mean():.6g}" if noun == "intervals" else ""
    return f"<{arr.size} {noun} in [{arr.min():.6g}, {arr.max():.6g}]{mean}>"
