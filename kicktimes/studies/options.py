"""The checks every study's ``reproduce`` makes of its options before it runs anything.

Examples
--------
>>> check_scale("quick", {"quick": 1, "paper": 2})
'quick'
>>> check_workers(2)
2
>>> check_workers(0)
Traceback (most recent call last):
...
ValueError: workers must be an integer >= 1, got 0
"""

from __future__ import annotations

from numbers import Integral

__all__ = ["check_scale", "check_workers"]


def check_scale(scale, scales) -> str:
    """``scale`` if it names one of ``scales`` (a mapping or a sequence of names)."""
    names = list(scales)
    if not isinstance(scale, str) or scale not in names:
        raise ValueError(f"scale must be one of {', '.join(map(repr, names))}, got {scale!r}")
    return scale


def check_workers(workers) -> int:
    """``workers`` if it is an integer >= 1 (not a bool)."""
    if isinstance(workers, bool) or not isinstance(workers, Integral) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    return int(workers)
