r"""Spearman's rank correlation with an exact permutation p-value for a handful of points.

A trend over a sweep's radii has 3 to 8 points, where the t approximation of
`scipy.stats.spearmanr` is meaningless (it gives :math:`p = 0` at :math:`|\rho| = 1`).
For :math:`n \le 8` the two-sided p-value is the share of the :math:`n!` permutations
of the ranks of ``y`` whose :math:`|\rho|` reaches the observed one,

.. math:: p = \frac{1}{n!} \sum_{\pi} \mathbf 1\{|\rho(x, y_\pi)| \ge |\rho(x, y)|\},

and beyond it scipy's t approximation (never below :math:`2/n!`).

Examples
--------
>>> rho, p = spearman([1, 2, 3, 4, 5], [2.0, 4.0, 5.0, 9.0, 10.0])
>>> round(rho, 12), round(p, 4)   # a perfect rise: 2 of the 120 orders reach |rho| = 1
(1.0, 0.0167)
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["spearman"]


def spearman(x, y) -> tuple[float, float]:
    """Spearman's rho and its two-sided p-value (exact permutation for n <= 8), over the
    pairs where both are finite; ``(nan, nan)`` with fewer than 3 such pairs or a
    constant variable."""
    from scipy import stats as sps

    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if x.size < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan, math.nan
    rho = float(sps.spearmanr(x, y).statistic)
    if x.size <= 8:
        # the t approximation is meaningless for a handful of radii (it gives p = 0 at
        # |rho| = 1); enumerate the permutations instead
        from itertools import permutations

        ry = sps.rankdata(y)
        null = [sps.spearmanr(x, ry[list(p)]).statistic for p in permutations(range(x.size))]
        return rho, float(np.mean(np.abs(null) >= abs(rho) - 1e-12))
    p = float(sps.spearmanr(x, y).pvalue)
    return rho, p if p > 0 else 2.0 / math.factorial(x.size)
