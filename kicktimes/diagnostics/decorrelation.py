"""The autocorrelation curve ``R_1..R_L`` of a series and how fast it decays.

The lag-1 autocorrelation of the boundary-collision angles is about one minus the number
of perturbations per boundary collision, and the kicked billiards are kicked at the
two-disk collision rate by construction, so its agreement between the systems is nearly
built in. The whole curve ``R_l``, ``l = 1..L``, and two summaries of its decay
(`decorrelation_lag`, `integrated_autocorrelation_time`) say more; see
docs/diagnostics.md.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes._results import Result, TupleCompat
from kicktimes.diagnostics.autocorrelation import (
    _ATOL,
    _RTOL,
    UndefinedDiagnosticWarning,
    _acf_curve,
    _as_series,
    _check_tol,
)

#: The default decorrelation threshold 1/e (an exponential decay's time constant).
INV_E = math.exp(-1.0)

__all__ = [
    "AcfCurve",
    "acf_curve",
    "autocorrelation_function",
    "decorrelation_lag",
    "integrated_autocorrelation_time",
]


def _check_max_lag(max_lag) -> int:
    if isinstance(max_lag, bool) or not isinstance(max_lag, numbers.Integral):
        raise TypeError(f"max_lag: expected an int >= 1, got {max_lag!r}")
    if max_lag < 1:
        raise ValueError(f"max_lag: must be >= 1, got {max_lag}")
    return int(max_lag)


def _as_acf(acf) -> np.ndarray:
    arr = np.asarray(acf)
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)
    ):
        raise TypeError(f"acf: expected a real 1-D array R_1..R_L, got dtype {arr.dtype}")
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"acf: expected a non-empty 1-D array R_1..R_L, got shape {arr.shape}")
    arr = arr.astype(np.float64, copy=False)
    if np.isinf(arr).any():
        k = int(np.flatnonzero(np.isinf(arr))[0])
        raise ValueError(f"acf: must be finite or NaN (undefined); element {k} is {arr[k]!r}")
    return arr


def _finish(value, reason, return_reason, what):
    if return_reason:
        return value, reason
    if reason is not None and isinstance(value, float) and math.isnan(value):
        warnings.warn(f"{what} is NaN: {reason}", UndefinedDiagnosticWarning, stacklevel=3)
    return value


def autocorrelation_function(series, max_lag=20, *, rtol=_RTOL, atol=_ATOL, return_reason=False):
    r"""The autocorrelation curve ``R_l`` for ``l = 1..max_lag``.

    .. math::

        R_l = \frac{\sum_{i=1}^{N-l} (x_i - \bar x)(x_{i+l} - \bar x)}
                   {\sum_{i=1}^{N} (x_i - \bar x)^2}, \qquad l = 1, \dots, L,

    the estimator of `autocorrelation` at every lag: ``acf[l - 1]`` is bitwise
    ``autocorrelation(series, l)``.

    Parameters
    ----------
    series : array_like, shape (N,)
        Real, finite values, e.g. ``boundary_angles(run)``.
    max_lag : int, default 20
        The largest lag ``L >= 1``.
    rtol, atol : float, default 1e-9
        The constant-series test of `autocorrelation`.
    return_reason : bool, default False
        If True return ``(acf, reason)``, ``reason`` ``None`` when every lag is defined and
        a sentence otherwise; no warning is issued.

    Returns
    -------
    ndarray of float64, shape (max_lag,), or (ndarray, str or None)
        ``acf[l - 1] = R_l``. NaN at every lag for a constant series or ``N < 2``, and at
        the lags ``l >= N`` (no pair that far apart); then, without ``return_reason``, one
        `UndefinedDiagnosticWarning` says why.

    Raises
    ------
    ValueError
        NaN or inf in ``series``, a series that is not 1-D, ``max_lag < 1``, negative
        tolerances.
    TypeError
        Non-numeric input.

    Notes
    -----
    The centred series once, then one pass per lag for the lagged products: O(N L) with
    four independent accumulators (benchmarks/bench_autocorrelation.py). Each lag's sum of
    squares keeps the blocking of `autocorrelation` (so the values are bitwise equal) but
    shares its blocks with the other lags. The series is scaled by an exact power of two,
    so neither huge nor tiny values overflow.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.diagnostics import autocorrelation_function
    >>> autocorrelation_function([1.0, 2.0, 3.0, 4.0], 2)
    array([ 0.25, -0.3 ])
    >>> acf, reason = autocorrelation_function([1.0, 2.0, 3.0], 4, return_reason=True)
    >>> acf[2:], reason[:20]
    (array([nan, nan]), 'series too short: N ')
    """
    x = _as_series(series)
    max_lag = _check_max_lag(max_lag)
    rtol = _check_tol("rtol", rtol)
    atol = _check_tol("atol", atol)
    out, code = _curve(x, max_lag, rtol, atol)
    reason = _curve_reason(code, x.size, max_lag)
    if return_reason:
        return out, reason
    if reason is not None:
        warnings.warn(
            f"autocorrelation_function has NaN: {reason}", UndefinedDiagnosticWarning, stacklevel=2
        )
    return out


def _curve(x: np.ndarray, max_lag: int, rtol: float = _RTOL, atol: float = _ATOL):
    """``(acf, code)`` of a checked series: the values of `autocorrelation_function` and
    the kernel's code per lag (0 defined, 1 constant series, 2 no pair that far apart)."""
    out = np.empty(max_lag)
    code = np.empty(max_lag, np.int8)
    _acf_curve(x, max_lag, rtol, atol, out, code)
    return out, code


@dataclass(frozen=True, repr=False)
class AcfCurve(TupleCompat, Result):
    """The autocorrelation curve of one series and why any of it is undefined.

    Attributes
    ----------
    acf : ndarray, shape (max_lag,)
        ``R_1 .. R_max_lag``, bitwise `autocorrelation_function`'s values.
    lag_reasons : tuple of (str or None)
        Per lag, why ``R_l`` is NaN (None where it is defined); the text of
        ``autocorrelation(series, l, return_reason=True)``.
    reason : str or None
        Why some of the curve is NaN (None when every lag is defined).

    ``to_frame()`` is the curve as a table (``lag``, ``acf``, ``reason``). Unpacking
    (``acf, lag_reasons, reason = acf_curve(...)``) and indexing still work until 0.3.0,
    with a DeprecationWarning: use the fields.
    """

    _title = "Autocorrelation curve R_1 .. R_max_lag of one series"
    _summary_fields = ("acf", "reason")
    _tuple_fields = ("acf", "lag_reasons", "reason")

    acf: np.ndarray
    lag_reasons: tuple
    reason: str | None

    def _summary_extra(self) -> list[str]:
        defined = int(np.isfinite(self.acf).sum())
        return [f"max_lag: {self.acf.size}, defined at {defined} lag(s)"]

    def to_frame(self) -> pd.DataFrame:
        """The curve as a table: ``lag`` (1 .. max_lag), ``acf`` and ``reason`` (None where
        defined)."""
        return pd.DataFrame({"lag": np.arange(1, self.acf.size + 1), "acf": self.acf,
                             "reason": list(self.lag_reasons)})


def acf_curve(series, max_lag=20, *, name="series") -> AcfCurve:
    """The autocorrelations ``R_1`` to ``R_max_lag`` of one series in one pass, with reasons.

    The same numbers as `autocorrelation_function` (and, lag by lag, as
    :func:`~kicktimes.diagnostics.autocorrelation`), without warnings: the reasons come
    back with the values, for callers that store them beside the numbers (the sweep's
    rows).

    Parameters
    ----------
    series : array_like, shape (N,)
        Finite values.
    max_lag : int
        The last lag, ``>= 1``.
    name : str
        The argument's name in error messages.

    Examples
    --------
    >>> curve = acf_curve([1.0, 2.0, 1.0, 2.0], 4)
    >>> curve.acf[:2].round(3).tolist(), curve.lag_reasons[3] is not None
    ([-0.75, 0.5], True)
    """
    from kicktimes.diagnostics.autocorrelation import _as_series, _reason_text

    x = _as_series(series, name)
    acf, code = _curve(x, _check_max_lag(max_lag))
    reasons = tuple(_reason_text(int(c), x.size, k + 1) if c else None
                    for k, c in enumerate(code.tolist()))
    return AcfCurve(acf, reasons, _curve_reason(code, x.size, acf.size))


def _curve_reason(code: np.ndarray, n: int, max_lag: int) -> str | None:
    """Why some of a curve is NaN (None when every lag is defined)."""
    if (code == 1).any():
        return (
            f"constant series (N = {n}): the variance is zero to within the tolerance, so "
            f"R_l is undefined at every lag"
        )
    if (code == 2).any():
        if n < 2:
            return f"series too short: N = {n} < 2, so R_l is undefined at every lag"
        return (
            f"series too short: N = {n} gives R_l only for l < N; lags {n}..{max_lag} "
            "are NaN"
        )
    return None


def decorrelation_lag(acf, threshold=INV_E, *, return_reason=False):
    r"""The first lag at which the autocorrelation falls below ``threshold``.

    .. math::

        l^* = \min\{\, l \ge 1 : R_l < \theta \,\}, \qquad \theta = 1/e \text{ by default}.

    Parameters
    ----------
    acf : array_like, shape (L,)
        ``R_1..R_L`` as returned by `autocorrelation_function` (``acf[l - 1] = R_l``).
    threshold : float, default 1/e
        ``theta`` in ``[-1, 1]``.
    return_reason : bool, default False
        If True return ``(lag, reason)`` (``reason`` ``None`` for a defined lag), without
        a warning.

    Returns
    -------
    float, or (float, str or None)
        ``l*`` as a float (an integer value), or NaN when ``R_l >= theta`` for every
        ``l <= L`` (not reached: raise ``max_lag``) or when an undefined ``R_l`` (NaN)
        comes first; without ``return_reason`` the NaN comes with an
        `UndefinedDiagnosticWarning` stating the reason.

    Raises
    ------
    ValueError, TypeError
        ``acf`` not a non-empty real 1-D array (inf is refused, NaN means undefined);
        ``threshold`` not finite in ``[-1, 1]``.

    Examples
    --------
    >>> from kicktimes.diagnostics import decorrelation_lag
    >>> decorrelation_lag([0.9, 0.6, 0.3, 0.1])
    3.0
    >>> decorrelation_lag([0.9, 0.8], return_reason=True)
    (nan, 'R_l >= 0.3679 for every lag l = 1..2: not reached (raise max_lag)')
    """
    r = _as_acf(acf)
    if isinstance(threshold, bool) or not isinstance(threshold, numbers.Real):
        raise TypeError(f"threshold: expected a float in [-1, 1], got {threshold!r}")
    threshold = float(threshold)
    if not (math.isfinite(threshold) and -1.0 <= threshold <= 1.0):
        raise ValueError(f"threshold: must be finite in [-1, 1], got {threshold!r}")
    below = np.flatnonzero(~(r >= threshold))  # NaN counts here, and is sorted out below
    if below.size == 0:
        value, reason = math.nan, (
            f"R_l >= {threshold:.4g} for every lag l = 1..{r.size}: not reached (raise max_lag)"
        )
    elif math.isnan(r[below[0]]):
        reason = f"R_{below[0] + 1} is undefined (NaN) before R_l < {threshold:.4g}"
        value = math.nan
    else:
        value, reason = float(below[0] + 1), None
    return _finish(value, reason, return_reason, "decorrelation_lag")


def integrated_autocorrelation_time(acf, *, return_reason=False):
    r"""Integrated autocorrelation time, truncated at the first non-positive ``R_l``.

    .. math::

        \tau_{int} = \frac12 + \sum_{l=1}^{m} R_l, \qquad
        m = \min\{\, l : R_{l+1} \le 0 \,\} \ (\text{or } m = L),

    i.e. the sum stops *before* the first lag with ``R_l <= 0``, where the estimate is
    dominated by noise. In units of the series' index (here: boundary collisions);
    ``tau_int = 1/2`` for white noise and ``(1 + phi) / (2 (1 - phi))`` for AR(1).

    Parameters
    ----------
    acf : array_like, shape (L,)
        ``R_1..R_L`` as returned by `autocorrelation_function`.
    return_reason : bool, default False
        If True return ``(tau, note)``: ``note`` is ``None``, the reason of a NaN, or,
        for a finite value, the remark that no ``R_l <= 0`` occurred up to ``L`` (then
        ``tau`` sums every lag and is a lower bound of the untruncated time).

    Returns
    -------
    float, or (float, str or None)
        ``tau_int >= 1/2``; NaN when an undefined ``R_l`` (NaN) occurs before the
        truncation point (with an `UndefinedDiagnosticWarning` unless ``return_reason``).

    Raises
    ------
    ValueError, TypeError
        ``acf`` not a non-empty real 1-D array (inf is refused).

    Examples
    --------
    >>> from kicktimes.diagnostics import integrated_autocorrelation_time
    >>> integrated_autocorrelation_time([0.5, 0.25, -0.1, 0.2])   # 1/2 + 0.5 + 0.25
    1.25
    >>> integrated_autocorrelation_time([0.5, 0.25], return_reason=True)[1][:22]
    'no R_l <= 0 up to L = '
    """
    r = _as_acf(acf)
    stop = np.flatnonzero(~(r > 0.0))  # first non-positive or NaN lag
    note = None
    if stop.size == 0:
        m = r.size
        note = (
            f"no R_l <= 0 up to L = {r.size}: tau_int sums every lag and is a lower bound "
            "(raise max_lag)"
        )
    elif math.isnan(r[stop[0]]):
        reason = f"R_{stop[0] + 1} is undefined (NaN) before any R_l <= 0"
        return _finish(math.nan, reason, return_reason, "integrated_autocorrelation_time")
    else:
        m = int(stop[0])
    value = 0.5 + float(np.sum(r[:m]))
    return (value, note) if return_reason else value
