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


def check_seed_sequence(rng, name: str = "rng") -> np.random.SeedSequence:
    """The `numpy.random.SeedSequence` behind ``rng``, for functions whose draws are a pure
    function of a root seed and an index (IC ``i`` of an ensemble is drawn from the root's
    child ``spawn_key=(i,)``, whatever block it is drawn in).

    An int ``s`` gives ``SeedSequence(s)`` (so its children are exactly
    ``SeedSequence(s, spawn_key=(i,))``), a SeedSequence is used as is, None fresh entropy;
    a Generator or BitGenerator is consumed: the root's entropy is drawn from it. The
    accepted inputs and the errors are those of `check_rng`.

    >>> check_seed_sequence(3).entropy
    3
    """
    if isinstance(rng, np.random.SeedSequence):
        return rng
    if rng is None or (isinstance(rng, Integral | np.integer) and not isinstance(rng, bool)):
        check_rng(rng, name)  # (the same TypeError/ValueError as everywhere)
        return np.random.SeedSequence(None if rng is None else int(rng))
    gen = check_rng(rng, name)
    return np.random.SeedSequence(int(gen.integers(2**63)))


# -- Deprecations: one shared path for every renamed keyword and every option made
# keyword-only (CHANGELOG.md, "0.2.0"). Each wrapper records what it accepts for one more
# release in a marker attribute, which tests/test_api_signatures.py reads.

#: the marker attribute of `renamed_keyword`: ``{old: new}``
RENAMED_MARKER = "__kicktimes_renamed__"
#: the marker attribute of `keyword_only_after`: the names once accepted by position
POSITIONAL_MARKER = "__kicktimes_formerly_positional__"


def renamed_keyword(*, old: str, new: str, since: str = "0.2.0", until: str = "0.3.0"):
    """Decorator: the keyword ``old`` still works, with a DeprecationWarning naming ``new``,
    until release ``until``; passing both is a TypeError.

    >>> @renamed_keyword(old="seed", new="rng")
    ... def draw(*, rng=0):
    ...     return rng
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     draw(seed=3), w[0].category.__name__
    (3, 'DeprecationWarning')
    """
    import functools
    import warnings

    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if old in kwargs:
                if new in kwargs:
                    raise TypeError(f"{func.__name__}() got both {old}= and {new}=; pass only "
                                    f"{new}= ({old}= is deprecated since {since})")
                warnings.warn(f"{func.__name__}(): {old}= is deprecated since {since} and will "
                              f"be removed in {until}; use {new}= instead", DeprecationWarning,
                              stacklevel=2)
                kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)

        renamed = dict(getattr(func, RENAMED_MARKER, {}))
        renamed[old] = new
        setattr(wrapper, RENAMED_MARKER, renamed)
        return wrapper

    return decorate


def keyword_only_after(n: int, *, since: str = "0.2.0", until: str = "0.3.0", names=None):
    """Decorator for a function whose options became keyword-only: it takes ``n`` positional
    parameters (``self`` not counted), and until ``until`` more positional arguments are
    still mapped, in order, to ``names`` (default: the keyword-only parameters in signature
    order, which is their old positional order), with one DeprecationWarning per call
    naming the keywords to use.

    >>> @keyword_only_after(1)
    ... def scaled(x, *, factor=2.0):
    ...     return x * factor
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     scaled(1.0, 3.0), str(w[0].message).split(";")[0]
    (3.0, 'scaled(): pass factor= by keyword')
    """
    import functools
    import inspect
    import warnings

    def decorate(func):
        params = list(inspect.signature(func).parameters.values())
        positional = [p for p in params
                      if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
        offset = 1 if positional and positional[0].name in ("self", "cls") else 0
        if len(positional) - offset != n:
            raise TypeError(f"keyword_only_after({n}) on {func.__qualname__}, which takes "
                            f"{len(positional) - offset} positional parameters")
        extra = tuple(names) if names is not None else tuple(
            p.name for p in params if p.kind is p.KEYWORD_ONLY)
        n_pos = n + offset

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if len(args) > n_pos:
                moved = args[n_pos:]
                if len(moved) > len(extra):
                    raise TypeError(f"{func.__name__}() takes at most "
                                    f"{n + len(extra)} arguments by position "
                                    f"({n} from {until} on), got {len(args) - offset}")
                keys = extra[:len(moved)]
                for key in keys:
                    if key in kwargs:
                        raise TypeError(f"{func.__name__}() got multiple values for "
                                        f"argument {key!r}")
                warnings.warn(
                    f"{func.__name__}(): pass {', '.join(f'{k}=' for k in keys)} by keyword; "
                    f"passing it by position is deprecated since {since} and will fail "
                    f"in {until}", DeprecationWarning, stacklevel=2)
                kwargs.update(zip(keys, moved, strict=True))
                args = args[:n_pos]
            return func(*args, **kwargs)

        setattr(wrapper, POSITIONAL_MARKER, extra)
        for marker in (RENAMED_MARKER,):
            if hasattr(func, marker):
                setattr(wrapper, marker, getattr(func, marker))
        return wrapper

    return decorate

