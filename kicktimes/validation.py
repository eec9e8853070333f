"""Scalar argument checks shared by every layer of kicktimes.

Each message names the argument, the offending value and the valid range (docs/architecture.md,
"Bad input"). NaN and inf are rejected, never propagated. Layer-specific checks (initial
conditions, event times, intervals) live beside the code that needs them.
"""

from __future__ import annotations

import math
import re
from numbers import Integral, Real

import numpy as np


def check_real(name: str, value, *, low=None, high=None, low_open=True, high_open=True) -> float:
    """A finite real number inside the given (open by default) interval."""
    # (exact float and int first: the ABC check costs more than the rest of a simulator call's
    # argument checks together)
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()  # a 0-d numeric array is its number
    if not (type(value) is float or type(value) is int) and (
            isinstance(value, bool | np.bool_)
            or not isinstance(value, Real | np.floating | np.integer)):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x!r}")
    bad_low = low is not None and (x <= low if low_open else x < low)
    bad_high = high is not None and (x >= high if high_open else x > high)
    if bad_low or bad_high:
        lo = "-inf" if low is None else repr(float(low))
        hi = "inf" if high is None else repr(float(high))
        span = f"{'(' if low_open else '['}{lo}, {hi}{')' if high_open else ']'}"
        raise ValueError(f"{name} must lie in {span}, got {x!r}")
    return x


def check_int(name: str, value, *, low: int, high: int | None = None) -> int:
    """An integer (not a bool) in ``[low, high]`` (no upper bound if ``high`` is None)."""
    if type(value) is not int and (
            isinstance(value, bool) or not isinstance(value, Integral | np.integer)):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    n = int(value)
    if n < low or (high is not None and n > high):
        span = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ValueError(f"{name} must be an integer {span}, got {n}")
    return n


def check_choice(name: str, value, choices) -> str:
    """One of a fixed set of strings."""
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{name} must be one of {sorted(choices)!r}, got {value!r}")
    return value


#: a name that may name files: a letter or digit, then letters, digits and ``_ . + -``
_FILE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*")


def check_file_name(name: str, value) -> str:
    """A string that may name files: a letter or digit, then letters, digits and ``_ . + -``.

    >>> check_file_name("name", "family_a")
    'family_a'
    """
    if not isinstance(value, str) or not _FILE_NAME.fullmatch(value):  # (no trailing newline)
        raise ValueError(f"{name}: must be a non-empty identifier of letters, digits, '_', '.', "
                         f"'+', '-' (it names files), got {value!r}")
    return value


def check_distinct(name: str, values, check_item, *, what: str) -> tuple:
    """The distinct ``values``, each passed through ``check_item(f"{name}[k]", v)``, sorted
    increasingly; a string or a non-iterable raises TypeError, an empty or repeating list
    ValueError (``what``: the items' name in the messages).

    >>> check_distinct("radii", [0.02, 0.01], lambda n, v: check_real(n, v, low=0), what="radii")
    (0.01, 0.02)
    """
    if isinstance(values, str | bytes) or not hasattr(values, "__iter__"):
        raise TypeError(f"{name}: expected a list of {what}, got {values!r}")
    items = [check_item(f"{name}[{k}]", v) for k, v in enumerate(values)]
    if not items:
        raise ValueError(f"{name}: must contain at least one of the {what}, got []")
    if len(set(items)) != len(items):
        raise ValueError(f"{name}: must be distinct, got {items}")
    return tuple(sorted(items))


def check_rng(rng, name: str = "rng") -> np.random.Generator:
    """``numpy.random.default_rng(rng)`` for the inputs kicktimes accepts, else an error.

    Accepted: None (fresh entropy), an integer seed >= 0 (not a bool), a
    `numpy.random.Generator` (used as is), a `numpy.random.BitGenerator` or a
    `numpy.random.SeedSequence`. TypeError for anything else, ValueError for a negative
    seed; both name ``name``.

    >>> bool(check_rng(3).integers(10) == check_rng(np.random.default_rng(3)).integers(10))
    True
    """
    if isinstance(rng, bool | np.bool_) or not (
        rng is None or isinstance(rng, Integral | np.integer | np.random.Generator
                                  | np.random.BitGenerator | np.random.SeedSequence)
    ):
        raise TypeError(
            f"{name} must be None, an int seed >= 0, a numpy Generator, BitGenerator or "
            f"SeedSequence, got {type(rng).__name__}"
        )
    if isinstance(rng, Integral | np.integer):
        if int(rng) < 0:
            raise ValueError(f"{name} must be an int seed >= 0, got {int(rng)}")
        rng = int(rng)
    return np.random.default_rng(rng)
