"""Autocorrelation of the boundary-collision angle series.

The paper's lag-``l`` autocorrelation of a series ``x_1..x_N`` with mean ``x̄`` is

    R_l = sum_{i=1}^{N-l} (x_i - x̄)(x_{i+l} - x̄) / sum_{i=1}^{N} (x_i - x̄)^2,

the biased estimator (the same normalisation as ``statsmodels.tsa.stattools.acf`` with
its default ``adjusted=False``). It is undefined for a constant series (the integrable
disk without kicks hits the boundary at the same angle forever) and for a series with
no pair at lag ``l``. Then NaN is returned together with a *reason*: `autocorrelation`
returns an `AcfValue` whose ``.reason`` says why, with an `UndefinedDiagnosticWarning`,
and `autocorrelation_many` puts it in a ``reason`` column, so
that ensemble means can count the valid values.
"""

from __future__ import annotations

import math
import numbers
import warnings
from collections.abc import Mapping

import numpy as np
import pandas as pd
from numba import njit

from kicktimes._results import Value
from kicktimes.validation import keyword_only_after

__all__ = [
    "AcfValue",
    "UndefinedDiagnosticWarning",
    "autocorrelation",
    "autocorrelation_many",
    "boundary_angles",
    "boundary_map",
]

REASON_OK = "ok"
REASON_CONSTANT = "constant"
REASON_TOO_SHORT = "too_short"
_REASONS = (REASON_OK, REASON_CONSTANT, REASON_TOO_SHORT)

# Default tolerances of the "constant series" test std <= atol + rtol * max|x|. Round-off
# in a simulated integrable run leaves sin(theta) constant to ~1e-12 (docs/simulator.md
# invariants), while any genuinely varying angle series has a std of order 0.1 rad.
_RTOL = 1e-9
_ATOL = 1e-9

# |sin_theta| may exceed 1 by round-off; beyond this it is a broken record.
_SIN_SLACK = 1e-9


class UndefinedDiagnosticWarning(RuntimeWarning):
    """A diagnostic is undefined for this input (e.g. a constant series); NaN returned.

    Silence it in ensemble loops with
    ``warnings.simplefilter("ignore", UndefinedDiagnosticWarning)``, or use the
    warning-free `autocorrelation_many` or `acf_curve`; the value itself carries the reason
    (``autocorrelation(...).reason``).
    """


# --------------------------------------------------------------------------- kernel


@njit(cache=True)
def _centred_sums(values, lo, hi, lag, mean, f):
    """(sum d_i^2, sum_{i < n-lag} d_i d_{i+lag}) with d_i = f x_i - mean, over [lo, hi).

    Four independent accumulators: they break the add-latency chain and, as a side
    effect, sum in a slightly more accurate blocked order.
    """
    d0 = d1 = d2 = d3 = 0.0
    c0 = c1 = c2 = c3 = 0.0
    m = hi - lag  # products exist for i < m
    i = lo
    while i + 3 < m:
        a0 = values[i] * f - mean
        a1 = values[i + 1] * f - mean
        a2 = values[i + 2] * f - mean
        a3 = values[i + 3] * f - mean
        d0 += a0 * a0
        d1 += a1 * a1
        d2 += a2 * a2
        d3 += a3 * a3
        c0 += a0 * (values[i + lag] * f - mean)
        c1 += a1 * (values[i + 1 + lag] * f - mean)
        c2 += a2 * (values[i + 2 + lag] * f - mean)
        c3 += a3 * (values[i + 3 + lag] * f - mean)
        i += 4
    while i < m:
        a0 = values[i] * f - mean
        d0 += a0 * a0
        c0 += a0 * (values[i + lag] * f - mean)
        i += 1
    while i < hi:
        a0 = values[i] * f - mean
        d0 += a0 * a0
        i += 1
    return (d0 + d1) + (d2 + d3), (c0 + c1) + (c2 + c3)


@njit(cache=True)
def _max_abs(values, lo, hi):
    """max |x_i| over [lo, hi) (0 for an empty range)."""
    b0 = b1 = b2 = b3 = 0.0
    i = lo
    while i + 3 < hi:
        b0 = max(b0, abs(values[i]))
        b1 = max(b1, abs(values[i + 1]))
        b2 = max(b2, abs(values[i + 2]))
        b3 = max(b3, abs(values[i + 3]))
        i += 4
    while i < hi:
        b0 = max(b0, abs(values[i]))
        i += 1
    return max(max(b0, b1), max(b2, b3))


@njit(cache=True)
def _shifted_sum(values, lo, hi, f, shift):
    """sum (f x_i - shift) over [lo, hi), four independent accumulators."""
    s0 = s1 = s2 = s3 = 0.0
    i = lo
    while i + 3 < hi:
        s0 += values[i] * f - shift
        s1 += values[i + 1] * f - shift
        s2 += values[i + 2] * f - shift
        s3 += values[i + 3] * f - shift
        i += 4
    while i < hi:
        s0 += values[i] * f - shift
        i += 1
    return (s0 + s1) + (s2 + s3)


@njit(cache=True)
def _prepare(values, lo, hi):
    """(mean of f x, f, max|x|) of a segment, with f an exact power of two.

    The series is scaled by ``f = 2^-e`` with ``max|x| = m 2^e``, ``0.5 <= m < 1``, so
    that sums of squares cannot overflow (``[1e308, -1e308]``) nor underflow; scaling by
    a power of two is exact, so ``R_l`` is bitwise what the unscaled sums would give
    whenever those are finite. ``e`` is capped at -1000 below so that ``f`` stays finite.
    """
    n = hi - lo
    scale = _max_abs(values, lo, hi)
    e = 0
    if scale > 0.0:
        e = max(math.frexp(scale)[1], -1000)
    f = math.ldexp(1.0, -e)
    mean = _shifted_sum(values, lo, hi, f, 0.0) / n
    # two-pass mean: the second pass corrects the round-off of the first
    mean += _shifted_sum(values, lo, hi, f, mean) / n
    return mean, f, scale


@njit(cache=True)
def _is_constant(den, n, f, scale, rtol, atol):
    """std <= atol + rtol max|x|, evaluated in the scaled units (no overflow)."""
    return np.sqrt(den / n) <= atol * f + rtol * scale * f


@njit(cache=True)
def _acf_segments(values, offsets, lag, rtol, atol, out, code):
    """R_lag of each segment ``values[offsets[s]:offsets[s+1]]``; code 0 ok, 1 const, 2 short."""
    for s in range(offsets.shape[0] - 1):
        lo = offsets[s]
        hi = offsets[s + 1]
        n = hi - lo
        if n < 2 or n <= lag:
            out[s] = np.nan
            code[s] = 2
            continue
        mean, f, scale = _prepare(values, lo, hi)
        den, num = _centred_sums(values, lo, hi, lag, mean, f)
        if _is_constant(den, n, f, scale, rtol, atol):
            out[s] = np.nan
            code[s] = 1
            continue
        out[s] = num / den
        code[s] = 0


@njit(cache=True)
def _acf_curve(values, max_lag, rtol, atol, out, code):
    """R_1..R_max_lag of one series into ``out[0..max_lag-1]``, codes as `_acf_segments`.

    ``out[l - 1]`` is bitwise ``autocorrelation(values, l)``, i.e. what `_centred_sums`
    gives at lag ``l`` (a property test), faster than running those sums lag by lag
    (benchmarks/bench_autocorrelation.py; docs/benchmarks.md):

    * the centred, scaled values ``a_i = f x_i - mean`` are computed once, by the same
      expression, instead of twice per lag;
    * the sum of squares of lag ``l`` is four blocked accumulators over the first
      ``4 ((N - l) // 4)`` values, then the rest added to the first one in order. The
      blocks are a prefix shared by every lag, so they are advanced once, from the
      largest lag (fewest blocks) down, and each lag adds only its tail (at most
      ``l + 3`` values).
    """
    n = values.shape[0]
    if n < 2:
        out[:] = np.nan
        code[:] = 2
        return
    # an int64 zero, not the literal 0: numba would compile the callee a second time
    # for the type Literal[int](0) (it is also called with int64 bounds)
    lo = np.int64(0)
    mean, f, scale = _prepare(values, lo, n)
    a = np.empty(n)
    for i in range(n):
        a[i] = values[i] * f - mean
    top = min(max_lag, n - 1)
    for lag in range(top + 1, max_lag + 1):  # no pair that far apart
        out[lag - 1] = np.nan
        code[lag - 1] = 2
    d0 = d1 = d2 = d3 = 0.0
    blocks = 0
    for lag in range(top, 0, -1):
        m = n - lag  # products exist for i < m
        while blocks < m // 4:
            i = 4 * blocks
            d0 += a[i] * a[i]
            d1 += a[i + 1] * a[i + 1]
            d2 += a[i + 2] * a[i + 2]
            d3 += a[i + 3] * a[i + 3]
            blocks += 1
        t0 = d0
        for i in range(4 * blocks, n):
            t0 += a[i] * a[i]
        den = (t0 + d1) + (d2 + d3)
        if _is_constant(den, n, f, scale, rtol, atol):
            out[lag - 1] = np.nan
            code[lag - 1] = 1
            continue
        c0 = c1 = c2 = c3 = 0.0
        i = 0
        while i + 3 < m:
            c0 += a[i] * a[i + lag]
            c1 += a[i + 1] * a[i + 1 + lag]
            c2 += a[i + 2] * a[i + 2 + lag]
            c3 += a[i + 3] * a[i + 3 + lag]
            i += 4
        while i < m:
            c0 += a[i] * a[i + lag]
            i += 1
        out[lag - 1] = ((c0 + c1) + (c2 + c3)) / den
        code[lag - 1] = 0


# ------------------------------------------------------------------------- validation


def _check_lag(lag) -> int:
    if isinstance(lag, bool) or not isinstance(lag, numbers.Integral):
        raise TypeError(f"lag: expected a non-negative int, got {lag!r}")
    if lag < 0:
        raise ValueError(f"lag: must be >= 0, got {lag}")
    return int(lag)


def _check_tol(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a non-negative float, got {value!r}")
    value = float(value)
    if not (np.isfinite(value) and value >= 0.0):
        raise ValueError(f"{name}: must be finite and >= 0, got {value!r}")
    return value


def _as_series(series, name: str = "series") -> np.ndarray:
    arr = np.asarray(series)
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.floating)
        or np.issubdtype(arr.dtype, np.integer)
        or arr.dtype == np.bool_
    ):
        raise TypeError(f"{name}: expected a real 1-D array, got dtype {arr.dtype}")
    if arr.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D series, got shape {arr.shape}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.isfinite(arr).all():
        k = int(np.flatnonzero(~np.isfinite(arr))[0])
        raise ValueError(f"{name}: must be finite; element {k} is {float(arr[k])!r}")
    return arr


def _reason_text(code: int, n: int, lag: int) -> str:
    if code == 1:
        return (
            f"constant series (N = {n}): the variance is zero to within the tolerance, "
            f"so R_{lag} is undefined"
        )
    return f"series too short: N = {n} needs N > lag = {lag} and N >= 2"


# ------------------------------------------------------------------------ public API


class AcfValue(Value):
    """The result of `autocorrelation`: ``R_lag`` as a float, with ``reason`` (None when it
    is defined, why it is NaN otherwise), ``lag`` and ``n`` (the series' length ``N``).

    Examples
    --------
    >>> from kicktimes.diagnostics import autocorrelation
    >>> value = autocorrelation([1.0, 2.0, 3.0, 4.0])
    >>> value, value.reason, value.n
    (0.25, None, 4)
    >>> print(value.summary())
    Autocorrelation R_lag: 0.25
      lag: 1
      n: 4
    """

    _title = "Autocorrelation R_lag"


def autocorrelation(series, lag=1, *, rtol=_RTOL, atol=_ATOL, return_reason=False):
    r"""The paper's lag-``l`` autocorrelation of a series.

    .. math::

        R_l = \frac{\sum_{i=1}^{N-l} (x_i - \bar x)(x_{i+l} - \bar x)}
                   {\sum_{i=1}^{N} (x_i - \bar x)^2}

    Parameters
    ----------
    series : array_like, shape (N,)
        Real, finite values, e.g. ``boundary_angles(run)``.
    lag : int, default 1
        The lag ``l >= 0`` (``R_0 = 1``).
    rtol, atol : float, default 1e-9
        The series counts as constant, and ``R_l`` as undefined, when its standard
        deviation ``sqrt(sum (x_i - x̄)^2 / N)`` is at most ``atol + rtol * max|x_i|``
        (otherwise round-off would be divided by round-off). The defaults suit angle
        series in radians; for series in other units scale ``atol`` (``atol=0`` keeps
        only the relative test; ``rtol=atol=0`` only an exactly zero variance).
    return_reason : bool, default False
        Deprecated (until 0.3.0): the result's ``.reason`` says why it is NaN. If True
        return the old ``(value, reason)`` tuple and issue no `UndefinedDiagnosticWarning`
        (a DeprecationWarning instead).

    Returns
    -------
    AcfValue
        ``R_l`` in ``[-1, 1]`` (a float), or NaN when undefined: constant series, or too
        short (``N <= lag`` or ``N < 2``); its ``.reason`` says why (None when defined), and
        the NaN comes with an `UndefinedDiagnosticWarning` stating the reason (filter it, or
        use `acf_curve`, for a warning-free call).

    Raises
    ------
    ValueError
        NaN or inf in ``series``, a series that is not 1-D, negative ``lag`` or tolerance.
    TypeError
        Non-numeric input.

    Notes
    -----
    This is the biased (``1/N``-normalised) estimator; it equals
    ``statsmodels.tsa.stattools.acf(series, nlags=lag)[lag]`` (``adjusted=False``). For
    an AR(1) series ``x_t = phi x_{t-1} + e_t`` it estimates ``phi`` with standard error
    about ``sqrt((1 - phi^2) / N)``.

    Examples
    --------
    >>> from kicktimes.diagnostics import autocorrelation
    >>> autocorrelation([1.0, 2.0, 3.0, 4.0])
    0.25
    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
    ...     autocorrelation([0.3, 0.3, 0.3]).reason[:15]
    'constant series'
    """
    x = _as_series(series)
    lag = _check_lag(lag)
    rtol = _check_tol("rtol", rtol)
    atol = _check_tol("atol", atol)
    out = np.empty(1)
    code = np.empty(1, np.int8)
    _acf_segments(x, np.array([0, x.size], np.int64), lag, rtol, atol, out, code)
    value = float(out[0])
    reason = None if code[0] == 0 else _reason_text(int(code[0]), x.size, lag)
    if return_reason:
        warnings.warn(
            "autocorrelation(..., return_reason=True) is deprecated and stops working in 0.3.0; "
            "autocorrelation returns an AcfValue whose .reason says why it is NaN (filter "
            "UndefinedDiagnosticWarning, or use acf_curve, for no warning)",
            DeprecationWarning,
            stacklevel=2,
        )
        return value, reason
    if reason is not None:
        warnings.warn(f"autocorrelation is NaN: {reason}", UndefinedDiagnosticWarning, stacklevel=2)
    return AcfValue(value, reason, lag=lag, n=int(x.size))


@keyword_only_after(1, since="0.2.0", names=('lag',))
def autocorrelation_many(series, *, lag=1, rtol=_RTOL, atol=_ATOL):
    r"""`autocorrelation` of many series at once, with the reasons in a column.

    One compiled pass over all series (no Python loop per series, no warnings), for
    ensembles of thousands of initial conditions.

    Parameters
    ----------
    series : 2-D array_like, sequence of 1-D array_like, or mapping
        A 2-D array is read row by row; a sequence may hold series of different lengths;
        a mapping ``{key: series}`` keeps its keys as the index of the result.
    lag, rtol, atol
        As in `autocorrelation`.

    Returns
    -------
    DataFrame
        One row per series with columns ``autocorrelation`` (``R_lag``, NaN when
        undefined), ``n`` (length), ``valid`` (bool) and ``reason`` (``"ok"``,
        ``"constant"`` or ``"too_short"``). ``df.attrs["lag"]`` records the lag.

    Raises
    ------
    ValueError, TypeError
        As `autocorrelation`; the message names the offending series.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.diagnostics import autocorrelation_many
    >>> df = autocorrelation_many({"a": [1.0, 2.0, 3.0, 4.0], "b": np.ones(5), "c": [1.0]})
    >>> df["reason"].tolist(), df["valid"].sum()
    (['ok', 'constant', 'too_short'], np.int64(1))
    """
    lag = _check_lag(lag)
    rtol = _check_tol("rtol", rtol)
    atol = _check_tol("atol", atol)
    index = None
    if isinstance(series, Mapping):
        index = pd.Index(list(series.keys()))
        items = list(series.values())
    elif isinstance(series, np.ndarray) and series.ndim == 2:
        items = None
    else:
        if isinstance(series, (str, bytes)) or not hasattr(series, "__len__"):
            raise TypeError(
                f"series: expected a 2-D array, a sequence or a mapping of 1-D "
                f"series, got {type(series).__name__}"
            )
        items = list(series)
    if items is None:
        if not (
            np.issubdtype(series.dtype, np.floating)
            or np.issubdtype(series.dtype, np.integer)
            or series.dtype == np.bool_
        ):
            raise TypeError(f"series: expected a real 2-D array, got dtype {series.dtype}")
        arr = np.ascontiguousarray(series, dtype=np.float64)
        if not np.isfinite(arr).all():
            row, col = np.argwhere(~np.isfinite(arr))[0]
            raise ValueError(
                f"series: must be finite; row {row}, element {col} is {float(arr[row, col])!r}"
            )
        values = arr.ravel()
        lengths = np.full(arr.shape[0], arr.shape[1], np.int64)
    else:
        label = list(index) if index is not None else range(len(items))
        parts = [_as_series(s, name=f"series[{k!r}]") for k, s in zip(label, items, strict=True)]
        values = np.concatenate(parts) if parts else np.empty(0)
        lengths = np.array([p.size for p in parts], np.int64)
    offsets = np.zeros(lengths.size + 1, np.int64)
    np.cumsum(lengths, out=offsets[1:])
    out = np.empty(lengths.size)
    code = np.empty(lengths.size, np.int8)
    _acf_segments(values, offsets, lag, rtol, atol, out, code)
    df = pd.DataFrame(
        {
            "autocorrelation": out,
            "n": lengths,
            "valid": code == 0,
            "reason": pd.Categorical.from_codes(code, categories=list(_REASONS)),
        },
        index=index,
    )
    df.attrs["lag"] = lag
    return df


@keyword_only_after(1, since="0.2.0")
def boundary_angles(run, *, particle=None):
    r"""Boundary-collision angles ``theta = arcsin(sin_theta)`` of one disk, in time order.

    ``sin_theta`` is the tangential component of the incoming unit velocity at each
    disk-boundary collision (docs/architecture.md); ``theta`` in ``[-pi/2, pi/2]`` is the series
    whose autocorrelation the paper reports. In another table (a run's ``table``, a
    stadium or an ellipse) it is the same Birkhoff coordinate at the local wall,
    ``v.t / |v|`` with ``t`` the counter-clockwise tangent (docs/tables.md).

    Parameters
    ----------
    run : TwoParticleRun, OneParticleRun or DataFrame
        A run record (anything with a ``boundary`` DataFrame, or with the raw
        ``boundary_log`` arrays, which are read without building the DataFrame), or the
        boundary table itself, with columns ``time`` and ``sin_theta`` and, for two
        disks, ``particle``.
    particle : int, optional
        Which disk (0 or 1) of a two-particle table. Default: the run's tracked disk
        ``run.track``, or disk 0 for a bare table. Tables without a ``particle`` column
        (one-particle runs) take ``None`` or 0.

    Returns
    -------
    ndarray of float64, shape (n,)
        ``theta`` at the disk's boundary collisions, sorted by time (stably, should the
        record not be).

    Raises
    ------
    ValueError
        Missing columns, a particle that is not 0/1, NaN/inf, or ``|sin_theta| > 1``
        beyond round-off.
    TypeError
        ``run`` is neither a run record nor a DataFrame.

    Examples
    --------
    >>> import pandas as pd
    >>> from kicktimes.diagnostics import boundary_angles
    >>> table = pd.DataFrame({"time": [0.5, 1.1, 1.9], "particle": [0, 1, 0],
    ...                       "s": [0.0, 1.0, 2.0], "sin_theta": [0.0, 0.5, 1.0]})
    >>> boundary_angles(table).round(4).tolist()
    [0.0, 1.5708]
    """
    time, sin_theta, particles, track = _boundary_columns(run)
    fast = _fast_columns(time, sin_theta, particles)
    if particles is None:
        if particle is not None and not _is_int(particle, 0):
            raise ValueError(
                f"particle: the boundary table has no 'particle' column "
                f"(one-particle run); pass None or 0, got {particle!r}"
            )
    else:
        if particle is None:
            particle = track if track is not None else 0
        if not (_is_int(particle, 0) or _is_int(particle, 1)):
            raise ValueError(f"particle: must be 0 or 1 (the disk to analyse), got {particle!r}")
    if fast:
        # one pass selects the disk's values and checks them; anything unusual (unsorted
        # times, a bad value) takes the general path below, which sorts or says what is wrong
        which = -1 if particles is None else int(particle)
        chosen, ok = _select_checked(time, sin_theta, _NO_PARTICLE if which < 0 else particles,
                                     which, 1.0 + _SIN_SLACK)
        if ok:
            return np.arcsin(np.clip(chosen, -1.0, 1.0))
    if particles is not None:
        mask = particles == int(particle)
        sin_theta = sin_theta[mask]
        time = time[mask] if time is not None else None
    if time is not None and time.size > 1 and not (time[1:] >= time[:-1]).all():
        order = np.argsort(time, kind="stable")
        sin_theta = sin_theta[order]
    sin_theta = np.asarray(sin_theta, dtype=np.float64)
    if not np.isfinite(sin_theta).all():
        k = int(np.flatnonzero(~np.isfinite(sin_theta))[0])
        raise ValueError(f"sin_theta: must be finite; element {k} is {sin_theta[k]!r}")
    if sin_theta.size and np.abs(sin_theta).max() > 1.0 + _SIN_SLACK:
        k = int(np.argmax(np.abs(sin_theta)))
        raise ValueError(f"sin_theta: must lie in [-1, 1]; element {k} is {sin_theta[k]!r}")
    # clip only the round-off excess; arcsin writes a fresh array, the record is untouched
    return np.arcsin(np.clip(sin_theta, -1.0, 1.0))


_NO_PARTICLE = np.empty(0, np.int8)


def boundary_map(run, *, particle=None) -> np.ndarray:
    r"""The boundary map of one disk: Birkhoff's coordinates ``(arc / L, sin_theta)`` of its
    wall contacts, in time order, in any table.

    ``arc`` is the arc length along the centre's curve counter-clockwise from its
    rightmost point and ``L`` that curve's length, so the first coordinate lies in
    ``[0, 1)`` in every table; in the unit circle it is the contact's polar angle over
    ``2 pi`` (the run's ``s / (2 pi)``). ``sin_theta`` is `boundary_angles`' ``sin``. Points
    of this map are what `kicktimes.diagnostics.recurrence_rate` takes to measure the
    recurrences of the boundary map rather than of the sampled positions (its ``eps`` then
    is a distance in these coordinates).

    Parameters
    ----------
    run : TwoParticleRun or OneParticleRun
        A run record with a ``boundary`` table (``s`` or, in another table, ``arc``).
    particle : int, optional
        Which disk (0 or 1) of a two-disk run; default ``run.track``.

    Returns
    -------
    ndarray of float64, shape (n, 2)

    Examples
    --------
    >>> from kicktimes import initial_conditions, simulate_two_particle
    >>> from kicktimes.tables import Stadium
    >>> ic = initial_conditions(1, 0.05, rng=1, method="uniform", table=Stadium(1.0))[0]
    >>> run = simulate_two_particle(ic, 0.05, t_max=100.0, table=Stadium(1.0))
    >>> pts = boundary_map(run)
    >>> bool(((0 <= pts[:, 0]) & (pts[:, 0] < 1) & (abs(pts[:, 1]) <= 1)).all())
    True
    """
    if not hasattr(run, "boundary") or isinstance(run, pd.DataFrame):
        raise TypeError(f"run: expected a run record, got {type(run).__name__}")
    df = run.boundary
    if "particle" in df.columns:
        if particle is None:
            particle = getattr(run, "track", 0)
        if not (_is_int(particle, 0) or _is_int(particle, 1)):
            raise ValueError(f"particle: must be 0 or 1 (the disk to analyse), got {particle!r}")
        df = df[df["particle"].to_numpy() == int(particle)]
    elif particle is not None and not _is_int(particle, 0):
        raise ValueError(f"particle: a one-disk run has disk 0 only, got {particle!r}")
    if "arc" in df.columns:
        frac = df["arc"].to_numpy() / run.table.perimeter(run.r)
    else:
        frac = df["s"].to_numpy() / (2.0 * math.pi)
    order = np.argsort(df["time"].to_numpy(), kind="stable")
    return np.column_stack([frac, df["sin_theta"].to_numpy()])[order]


def _fast_columns(time, sin_theta, particles) -> bool:
    """Whether `_select_checked` takes these columns: a run record's own arrays (float64
    times and values, int8 disk labels), so that one compiled signature serves."""
    return (
        isinstance(time, np.ndarray)
        and isinstance(sin_theta, np.ndarray)
        and time.dtype == np.float64
        and sin_theta.dtype == np.float64
        and time.shape == sin_theta.shape
        and time.ndim == 1
        and (particles is None or (particles.dtype == np.int8 and particles.shape == time.shape))
    )


@njit(cache=True)
def _select_checked(time, sin_theta, particles, which, bound):
    """``(sin_theta of disk `which` in record order, ok)`` in one pass (``which < 0``:
    every row). ``ok`` is False when the chosen times are not non-decreasing (or NaN) or
    a value is not within ``[-bound, bound]`` (or not finite): the caller then takes the
    general path. Replaces two boolean-mask gathers and four checks
    (benchmarks/bench_autocorrelation.py; docs/benchmarks.md)."""
    n = sin_theta.shape[0]
    out = np.empty(n)
    k = 0
    ok = True
    last = -np.inf
    for i in range(n):
        if which >= 0 and particles[i] != which:
            continue
        t = time[i]
        v = sin_theta[i]
        if not (t >= last and abs(v) <= bound):
            ok = False
        last = t
        out[k] = v
        k += 1
    return out[:k], ok


def _is_int(value, target: int) -> bool:
    return (
        (not isinstance(value, bool))
        and isinstance(value, numbers.Integral)
        and (int(value) == target)
    )


def _boundary_columns(run):
    """(time or None, sin_theta, particle or None, track or None) as arrays, no copies."""
    if isinstance(run, pd.DataFrame):
        table, track = run, None
    elif hasattr(run, "boundary_log"):
        log = run.boundary_log
        track = getattr(run, "track", None)
        # a one-particle log carries an all-zero particle column; only two disks need it
        particles = np.asarray(log.particle) if track is not None else None
        return np.asarray(log.time), np.asarray(log.sin_theta), particles, track
    elif hasattr(run, "boundary"):
        table, track = run.boundary, getattr(run, "track", None)
        if not isinstance(table, pd.DataFrame):
            raise TypeError(f"run.boundary: expected a DataFrame, got {type(table).__name__}")
    else:
        raise TypeError(
            f"run: expected a run record or a boundary DataFrame, got {type(run).__name__}"
        )
    if "sin_theta" not in table.columns:
        raise ValueError(
            f"run: the boundary table needs a 'sin_theta' column, has {list(table.columns)}"
        )
    time = table["time"].to_numpy() if "time" in table.columns else None
    particles = table["particle"].to_numpy() if "particle" in table.columns else None
    return time, table["sin_theta"].to_numpy(), particles, track
