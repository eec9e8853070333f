"""Old keywords of the simulators, `lyapunov`, `stats.analyze` and `report.build_report`.

A small private helper of issue 61's part "kick law and method options": a decorator that
lets a public function's old (flat) keywords keep working for one release, with a
`DeprecationWarning` that names the replacement. The function's own signature is the new
one (``inspect.signature`` follows ``__wrapped__``); the old keywords are translated into
new values before it is called. (The lead will unify it with `kicktimes.validation`'s
shared deprecation decorator at merge.)
"""

from __future__ import annotations

import functools
import warnings

#: stack levels from the helpers below to the caller of the decorated function
_USER = 4


def warn_old(old: str, new: str, *, stacklevel: int = _USER) -> None:
    """Warn that keyword ``old`` is deprecated in favour of ``new`` (until 0.3.0)."""
    warnings.warn(f"{old} is deprecated since 0.2.0 and will be removed in 0.3.0; use {new} "
                  "instead", DeprecationWarning, stacklevel=stacklevel)


def old_keywords(translate):
    """Decorate a function whose old keywords ``translate(args, kwargs)`` maps to new ones.

    ``translate`` receives the positional arguments and a dict of the keyword arguments
    and returns ``(kwargs, after)``: the keywords of the new signature and ``None`` or a
    function applied to the result (e.g. to record a deprecated metadata field). It warns
    with `warn_old` for every old keyword it meets. A call without old keywords costs one
    set intersection.
    """

    def decorate(func):
        names = translate.names

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if names.isdisjoint(kwargs):
                return func(*args, **kwargs)
            kwargs, after = translate(args, kwargs)
            out = func(*args, **kwargs)
            return out if after is None else after(out)

        return wrapper

    return decorate


def translator(*names):
    """Mark ``translate(args, kwargs)`` as handling the old keywords ``names``."""

    def mark(fn):
        fn.names = frozenset(names)
        return fn

    return mark


def pop_old(kwargs: dict, names) -> dict:
    """Remove the keywords ``names`` from ``kwargs``; the ones present, in order."""
    return {k: kwargs.pop(k) for k in names if k in kwargs}
