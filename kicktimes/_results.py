"""The result protocol: every public result object summarises itself the same way.

A result class mixes in :class:`Result` and declares only what is special to it:

* ``_title`` -- the first line of ``summary()`` (what was estimated);
* ``_summary_fields`` -- the fields shown, in order (default: every dataclass field);
* ``_intervals`` -- ``{estimate: (low, high)}`` or ``{estimate: ci_tuple_field}``: the
  estimate is shown with its 95 % interval (:func:`format_interval`), its bounds are not
  shown again;
* ``_frame`` -- with :class:`TableResult`: the field (or property) holding the result's
  table, returned by ``to_frame()``;
* ``_summary_extra(self)`` -- further lines (a method, for what fields cannot say).

``summary()`` is the title, then one ``  name: value`` line per field (arrays by shape and
first values, tables by size and columns, floats with six significant digits), then
``  reason: ...`` when the result has a ``reason`` that is not None. ``__repr__`` is
``Name(field=value, ...)`` over the same fields, each value as short as in the summary; a
class keeps its own ``__repr__`` (or its dataclass one, when readable) by defining it.

:class:`TupleCompat` keeps the tuple protocol of a result that used to be a NamedTuple
(``a, b = f(...)``, ``f(...)[0]``, ``len``) for one release, with a DeprecationWarning
that names the fields.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True, repr=False)
... class Share(Result):
...     _title = "Share of re-collisions"
...     _intervals = {"share": ("ci_low", "ci_high")}
...     share: float
...     ci_low: float
...     ci_high: float
...     n: int
...     reason: str | None = None
>>> print(Share(0.25, 0.2, 0.31, 40).summary())
Share of re-collisions
  share: 0.250 [0.200, 0.310]  (95 % interval)
  n: 40
>>> Share(0.25, 0.2, 0.31, 40)
Share(share=0.25, ci_low=0.2, ci_high=0.31, n=40, reason=None)
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import ClassVar

import numpy as np

__all__ = ["Result", "TableResult", "TupleCompat", "Value", "format_interval", "format_value",
           "nan_reason"]

#: values of a short 1-D array (or sequence) shown in full; longer ones show their first 3
_SHOWN = 6
#: the longest value text before it is abbreviated
_WIDTH = 100


def format_interval(estimate, low, high, *, edges=(0.9, 1.0, 1.1), digits=3):
    """``"0.886 [0.883, 0.892]"``: three significant digits, more where rounding would move
    an endpoint across one of ``edges`` (the band and 1) or merge distinct endpoints, so
    that the printed interval shows the verdict it was given.

    Examples
    --------
    >>> format_interval(0.913, 0.89996, 0.927)
    '0.91300 [0.89996, 0.92700]'
    >>> format_interval(0.889, 0.886, 0.892)
    '0.889 [0.886, 0.892]'
    >>> format_interval(0.32, 0.3219, 0.3273)
    '0.320 [0.322, 0.327]'
    """
    def side(x, e):
        return int(x > e) - int(x < e)

    def text(x, d):
        return f"{x:#.{d}g}".rstrip(".") if np.isfinite(x) else "n/a"

    estimate, low, high = float(estimate), float(low), float(high)
    for d in range(digits, 8):
        lo, hi = (float(text(v, d)) if np.isfinite(v) else v for v in (low, high))
        ok = all(side(lo, e) == side(low, e) and side(hi, e) == side(high, e) for e in edges)
        if ok and (lo < hi or not low < high):
            break
    return f"{text(estimate, d)} [{text(low, d)}, {text(high, d)}]"


def nan_reason(values, notes=(), fallback="undefined for this input") -> str | None:
    """The ``reason`` of a result: None when every one of ``values`` is finite, else the
    ``notes`` (the result's warnings) joined by ``; ``, or ``fallback`` without notes.

    Examples
    --------
    >>> nan_reason([1.0, 2.0], ["ignored"]) is None, nan_reason([1.0, float("nan")], ["a", "b"])
    (True, 'a; b')
    """
    values = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, float)
    if np.isfinite(values).all():
        return None
    return "; ".join(notes) or fallback


def format_value(value) -> str:
    """One value, short: floats with 6 significant digits, arrays by shape and first values,
    tables by size and columns, results by their ``repr``.

    Examples
    --------
    >>> format_value(0.123456789), format_value(np.arange(10.0)), format_value(None)
    ('0.123457', 'array (10,): 0, 1, 2, ...', 'None')
    >>> format_value(np.array([0.5, 1.5])), format_value({"a": 1.0, "b": "x"})
    ('[0.5, 1.5]', '{a: 1, b: x}')
    """
    import pandas as pd

    if isinstance(value, bool | np.bool_) or value is None:
        return str(value)
    if isinstance(value, float | np.floating):
        return f"{float(value):.6g}"
    if isinstance(value, int | np.integer | str):
        return str(value)
    if isinstance(value, np.ndarray):
        if value.ndim == 1 and value.size <= _SHOWN and value.dtype != object:
            return "[" + ", ".join(format_value(v) for v in value.tolist()) + "]"
        head = ", ".join(format_value(v) for v in value.ravel()[:3].tolist())
        more = ", ..." if value.size > 3 else ""
        return f"array {value.shape}: {head}{more}" if value.size else f"array {value.shape}"
    if isinstance(value, pd.DataFrame):
        cols = ", ".join(map(str, value.columns[:8])) + (", ..." if value.shape[1] > 8 else "")
        return f"table {value.shape[0]} x {value.shape[1]} ({cols})"
    if isinstance(value, pd.Series):
        return f"series of {value.size}"
    if isinstance(value, dict):
        text = "{" + ", ".join(f"{k}: {format_value(v)}" for k, v in value.items()) + "}"
        return text if len(value) <= _SHOWN and len(text) <= _WIDTH else f"dict of {len(value)}"
    if isinstance(value, tuple | list):
        if len(value) <= _SHOWN:
            inner = ", ".join(format_value(v) for v in value)
            text = f"({inner})" if isinstance(value, tuple) else f"[{inner}]"
            if len(text) <= _WIDTH:
                return text
        head = ", ".join(format_value(v) for v in value[:3])
        return f"{type(value).__name__} of {len(value)}: {head}, ..."
    text = repr(value)
    return text if len(text) <= _WIDTH else text[:_WIDTH - 3] + "..."


def _repr_value(value) -> str:
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, float | np.floating):
        return repr(float(value))
    if isinstance(value, np.ndarray) and value.size <= _SHOWN:
        return repr(value)
    return format_value(value)


class Result:
    """The mixin of the result protocol (see the module docstring)."""

    _title: ClassVar[str] = ""
    _summary_fields: ClassVar[tuple[str, ...] | None] = None
    _intervals: ClassVar[dict] = {}
    _frame: ClassVar[str | None] = None

    def _field_names(self) -> tuple[str, ...]:
        if self._summary_fields is not None:
            return self._summary_fields
        return tuple(f.name for f in dataclasses.fields(self) if f.repr)

    def _summary_extra(self) -> list[str]:
        """Further lines of the summary (none by default)."""
        return []

    def _interval_text(self, name) -> str:
        bounds = self._intervals[name]
        low, high = ((getattr(self, b) for b in bounds) if isinstance(bounds, tuple)
                     else getattr(self, bounds))
        value = getattr(self, name)
        if not all(isinstance(v, int | float | np.number) and math.isfinite(v)
                   for v in (low, high)):
            return format_value(value)
        return format_interval(value, low, high, edges=()) + "  (95 % interval)"

    def summary(self) -> str:
        """The result as text: what was estimated, each field, the reason if undefined."""
        hidden = set()
        for bounds in self._intervals.values():
            hidden.update(bounds if isinstance(bounds, tuple) else (bounds,))
        lines = [self._title or type(self).__name__]
        for name in self._field_names():
            if name in hidden or name == "reason":
                continue
            text = (self._interval_text(name) if name in self._intervals
                    else format_value(getattr(self, name)))
            lines.append(f"  {name}: {text}")
        lines.extend(f"  {line}" for line in self._summary_extra())
        reason = getattr(self, "reason", None)
        if reason is not None:
            lines.append(f"  reason: {reason}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        shown = ", ".join(f"{n}={_repr_value(getattr(self, n))}" for n in self._field_names())
        return f"{type(self).__name__}({shown})"



class TableResult(Result):
    """A result that holds a table: ``to_frame()`` returns it (the ``_frame`` attribute)."""

    def to_frame(self):
        """The result's table as a pandas DataFrame (a copy)."""
        return getattr(self, self._frame).copy()


class TupleCompat:
    """The tuple protocol of a former NamedTuple, deprecated: use the named fields.

    ``_tuple_fields`` lists the old tuple's fields in order.
    """

    _tuple_fields: ClassVar[tuple[str, ...]] = ()

    def _warn_tuple(self):
        names = ", ".join(f".{n}" for n in self._tuple_fields)
        warnings.warn(
            f"unpacking or indexing a {type(self).__name__} as a tuple is deprecated and stops "
            f"working in 0.3.0; use its fields {names}",
            DeprecationWarning,
            stacklevel=3,
        )

    def _as_tuple(self) -> tuple:
        return tuple(getattr(self, n) for n in self._tuple_fields)

    def __iter__(self):
        self._warn_tuple()
        return iter(self._as_tuple())

    def __getitem__(self, index):
        self._warn_tuple()
        return self._as_tuple()[index]

    def __len__(self):
        self._warn_tuple()
        return len(self._tuple_fields)

    def __bool__(self):
        return True  # a result is true, as the NamedTuple was (without __len__'s warning)


class Value(float):
    """A number that says why it is undefined: a ``float`` with ``reason`` (None when it is
    defined, a sentence when it is NaN) and the named facts of how it was computed.

    It is the float in every arithmetic (``value + 1`` is a plain float), compares and
    prints as the float, and is immutable. A subclass names the quantity in ``_title``.

    Examples
    --------
    >>> v = Value(float("nan"), "series too short", n=1)
    >>> v.reason, v.n, v == v
    ('series too short', 1, False)
    >>> print(Value(0.25, n=4).summary())
    Value: 0.25
      n: 4
    """

    _title: ClassVar[str] = "Value"

    def __new__(cls, value, reason=None, **facts):
        self = super().__new__(cls, value)
        self.__dict__.update(facts, reason=reason)
        return self

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable")

    def __delattr__(self, name):
        raise AttributeError(f"{type(self).__name__} is immutable")

    def summary(self) -> str:
        """The value, the facts of its computation, and the reason if it is undefined."""
        lines = [f"{self._title}: {format_value(float(self))}"]
        lines += [f"  {k}: {format_value(v)}" for k, v in self.__dict__.items() if k != "reason"]
        if self.reason is not None:
            lines.append(f"  reason: {self.reason}")
        return "\n".join(lines)
