"""Row-wise robust summaries for the bootstraps: the median that skips NaN, vectorised.

`numpy.nanmedian` along an axis runs a Python-level loop over the rows
(`numpy.apply_along_axis`) once a row has NaN; a bootstrap of per-IC medians calls it for
every resample, and that loop was most of the report's controls and gap decomposition
(``benchmarks/bench_ratio.py``; docs/benchmarks.md). `nanmedian` sorts each row once
instead and reads the middle, with the same arithmetic, so it equals `numpy.nanmedian`
bit for bit.
"""

from __future__ import annotations

import numpy as np

__all__ = ["nanmedian"]


def nanmedian(a, axis=-1):
    r"""Median along ``axis`` ignoring NaN: `numpy.nanmedian`, bit for bit, without its loop.

    Each row is sorted once (NaN last); with :math:`n` finite-or-infinite values the
    median is the middle one for odd :math:`n` and :math:`(s_{(n/2-1)} + s_{(n/2)})/2`
    for even :math:`n`, with the very operations of `numpy.median` (a sum from 0.0, so
    even the sign of a zero median agrees). A row without a number
    gives NaN (and no warning).

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
    with np.errstate(invalid="ignore"):
        first = 0.0 + s_lo
        even = (first + s_hi) / 2.0
    out = np.where(n % 2 == 1, first, even)
    # a fresh C-ordered array, as numpy's: reductions over it then sum in the same order
    return np.ascontiguousarray(np.where(n == 0, np.nan, out))
