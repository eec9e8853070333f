"""Row-wise robust summaries for the bootstraps: the median that skips NaN, vectorised.

`numpy.nanmedian` along an axis runs a Python-level loop over the rows
(`numpy.apply_along_axis`) once a row has NaN; a bootstrap of per-IC medians calls it for
every resample, and that loop was most of the report's controls and gap decomposition
(``benchmarks/bench_ratio.py``; docs/benchmarks.md). `nanmedian` sorts each row once
instead and reads the middle, with the same arithmetic, so it equals `numpy.nanmedian`
bit for bit. `bootstrap_nanmedians` gives the medians of many resamples of the columns
without sorting any: each row is sorted once and a resample only counts its draws.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["bootstrap_nanmedians", "nanmedian"]


def nanmedian(a, axis=-1):
    r"""Median along ``axis`` ignoring NaN: `numpy.nanmedian`, bit for bit, without its loop.

    Each row is sorted once (NaN last); with :math:`n` finite-or-infinite values the
    median is the middle one for odd :math:`n` and :math:`(s_{(n/2-1)} + s_{(n/2)})/2`
    for even :math:`n`, with the very operations of `numpy.median` (a sum from 0.0, so
    even the sign of a zero median agrees). A row without a number
    gives NaN (and no warning). One exception: for an odd count, numpy's small-array path
    (fewer than 600 values along ``axis``) averages the middle value with itself,
    :math:`(m + m)/2`, which overflows to ``inf`` when :math:`|m| \ge 2^{1023}`; here the
    median is :math:`m`, as `numpy.median` gives.

    Parameters
    ----------
    a : array_like of float
    axis : int, default -1

    Returns
    -------
    numpy.ndarray
        ``a``'s shape without ``axis``.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.stats import nanmedian
    >>> nanmedian(np.array([[1.0, np.nan, 3.0, 2.0], [np.nan, np.nan, 4.0, 1.0]]))
    array([2. , 2.5])
    """
    a = np.moveaxis(np.asarray(a, dtype=np.float64), axis, -1)
    s = np.sort(a, axis=-1)  # NaN sorts last
    n = np.count_nonzero(~np.isnan(a), axis=-1)
    lo = np.maximum((n - 1) // 2, 0)[..., None]
    hi = np.maximum(n // 2, 0)[..., None]
    hi = np.minimum(hi, max(a.shape[-1] - 1, 0))
    if a.shape[-1] == 0:
        return np.full(a.shape[:-1], np.nan)
    s_lo = np.take_along_axis(s, lo, axis=-1)[..., 0]
    s_hi = np.take_along_axis(s, hi, axis=-1)[..., 0]
    # numpy's mean of the middle values sums from 0.0: (0 + a) + b, which differs from
    # a + b only in the sign of a zero
    first = 0.0 + s_lo
    out = first.copy()
    pairs = n % 2 == 0  # (only these rows average: no overflow warning from the odd ones)
    with np.errstate(invalid="ignore"):
        out[pairs] = (first[pairs] + s_hi[pairs]) / 2.0
    # a fresh C-ordered array, as numpy's: reductions over it then sum in the same order
    return np.ascontiguousarray(np.where(n == 0, np.nan, out))


def bootstrap_nanmedians(values, idx):
    r"""The NaN-skipping median of every row of ``values`` in every bootstrap resample of
    its columns: ``out[b] = nanmedian(values[:, idx[b]], axis=1)``, bit for bit, without
    sorting a resample.

    The median of a resample is an order statistic of the multiset it draws, so each row
    is sorted once and a resample only counts how often it drew each column:
    :math:`c_j = \#\{k : idx_{bk} = j\}`. With :math:`N_b = \sum_j c_j` over the row's
    numbers, the median is the value at rank :math:`\lfloor (N_b-1)/2 \rfloor` (odd
    :math:`N_b`) or the mean of ranks :math:`\lfloor (N_b-1)/2 \rfloor` and
    :math:`\lfloor N_b/2 \rfloor` (even), found by one walk of the cumulative counts in
    sorted order: O(rows x columns) per resample instead of a sort, with the arithmetic of
    `nanmedian`. (Equal values are interchangeable, so only the sign of a zero median
    could differ, where a row holds both -0.0 and 0.0.)

    Parameters
    ----------
    values : array_like, shape (R, N)
        Rows of numbers (NaN: missing); columns are the resampled units (ICs).
    idx : array_like of int, shape (B, N_draw)
        Column indices of each resample, in ``[0, N)``.

    Returns
    -------
    numpy.ndarray, shape (B, R)
        NaN where a resample drew no number of the row.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.stats import bootstrap_nanmedians, nanmedian
    >>> values = np.array([[1.0, 5.0, np.nan, 2.0], [4.0, 3.0, 2.0, 1.0]])
    >>> idx = np.array([[0, 0, 1, 2], [3, 2, 2, 1]])
    >>> bootstrap_nanmedians(values, idx)
    array([[1. , 3.5],
           [3.5, 2. ]])
    >>> np.array_equal(bootstrap_nanmedians(values, idx)[1], nanmedian(values[:, idx[1]]))
    True
    """
    # C-ordered and writable: a read-only array (pandas' to_numpy) would compile the
    # kernel a second time
    values = np.require(values, dtype=np.float64, requirements=["C", "W"])
    idx = np.asarray(idx)
    if values.ndim != 2:
        raise ValueError(f"values: expected a 2-D array (rows x columns), got shape "
                         f"{values.shape}")
    if idx.ndim != 2 or not np.issubdtype(idx.dtype, np.integer):
        raise ValueError(f"idx: expected a 2-D integer array (resamples x draws), got "
                         f"shape {idx.shape} and dtype {idx.dtype}")
    n = values.shape[1]
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        raise ValueError(f"idx: column indices must lie in [0, {n}), got "
                         f"[{idx.min()}, {idx.max()}]")
    order = np.argsort(values, axis=1, kind="stable")  # NaN last
    n_numbers = np.count_nonzero(~np.isnan(values), axis=1)
    return _bootstrap_nanmedians(values, order, n_numbers,
                                 np.ascontiguousarray(idx, dtype=np.int64))


@njit(cache=True)
def _bootstrap_nanmedians(values, order, n_numbers, idx):
    n_rows, n = values.shape
    n_boot = idx.shape[0]
    out = np.empty((n_boot, n_rows))
    counts = np.zeros(n, np.int64)
    for b in range(n_boot):
        counts[:] = 0
        for k in range(idx.shape[1]):
            counts[idx[b, k]] += 1
        for r in range(n_rows):
            m = n_numbers[r]
            total = 0
            for k in range(m):
                total += counts[order[r, k]]
            if total == 0:
                out[b, r] = np.nan
                continue
            lo = (total - 1) // 2
            hi = total // 2
            v_lo = np.nan
            v_hi = np.nan
            cum = 0
            for k in range(m):
                j = order[r, k]
                cum += counts[j]
                if cum > lo and np.isnan(v_lo):
                    v_lo = values[r, j]
                if cum > hi:
                    v_hi = values[r, j]
                    break
            # nanmedian's arithmetic: (0 + lo) for odd, ((0 + lo) + hi) / 2 for even
            first = 0.0 + v_lo
            out[b, r] = first if total % 2 == 1 else (first + v_hi) / 2.0
    return out
