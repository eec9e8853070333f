r"""Vectorised statistics and null distributions of the Poisson-process tests.

Conditional on the number ``n`` of events in ``[0, T]``, a homogeneous Poisson
process places them as ``n`` IID uniform points, so every test below has an exact
null given ``n`` (the tests are *conditional on n*):

* on the scaled times ``u_i = t_i / T`` (uniform order statistics): conditional
  uniformity (KS, exact null), Laplace's trend statistic (asymptotically normal),
  the index of dispersion of counts in equal sub-windows (multinomial null by
  Monte Carlo);
* on the ``m = n - 1`` inner intervals ``t_{k+1} - t_k`` (the first time, a forward
  recurrence time, and the censored ``T - t_n`` are left out): the inner spacings of
  uniform order statistics are a Dirichlet vector, i.e. IID exponentials divided by
  a common random sum. Every interval statistic here is scale invariant, so its
  conditional null is exactly its law on ``m`` IID Exp(1) variables; that is what
  the Monte Carlo simulates (exponentiality KS with estimated rate, Ljung-Box).
  The runs count depends only on the above/below-median pattern, which is a
  uniformly random arrangement under exchangeability: its null is exact and
  combinatorial.

Every function works on a matrix whose rows are sequences with the same ``n``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import stats
from scipy.special import gammaln

# Largest block of random numbers simulated at once (memory bound for long sequences).
_BLOCK = 2_000_000


def uniformity_ks(u):
    """KS distance of each row of sorted uniforms from U(0, 1) and its exact p-value."""
    res = stats.ks_1samp(u, stats.uniform.cdf, axis=-1, method="exact")
    return np.asarray(res.statistic, dtype=float), np.asarray(res.pvalue, dtype=float)


def laplace_trend(u):
    r"""Laplace's trend statistic :math:`z = (\bar u - 1/2)\sqrt{12 n}` and two-sided
    normal p-value (the mean of n uniforms has mean 1/2 and variance 1/(12 n))."""
    n = u.shape[-1]
    z = (u.mean(axis=-1) - 0.5) * np.sqrt(12.0 * n)
    return z, 2.0 * stats.norm.sf(np.abs(z))


def exponential_ks(x):
    r"""Lilliefors-type KS distance of each row from Exp(rate = 1 / row mean)."""
    m = x.shape[-1]
    xs = np.sort(x, axis=-1)
    fitted = -np.expm1(-xs / xs.mean(axis=-1, keepdims=True))
    i = np.arange(1, m + 1)
    return np.maximum((i / m - fitted).max(axis=-1), (fitted - (i - 1) / m).max(axis=-1))


def exponential_ad(x):
    r"""Anderson-Darling distance of each row from Exp(rate = 1 / row mean).

    :math:`A^2 = -m - \frac{1}{m}\sum_i (2i - 1)[\log F(x_{(i)}) + \log(1 - F(x_{(m+1-i)}))]`;
    it weighs the tails more than KS and is the more powerful exponentiality test.
    """
    m = x.shape[-1]
    xs = np.sort(x, axis=-1)
    fitted = -np.expm1(-xs / xs.mean(axis=-1, keepdims=True))
    fitted = np.clip(fitted, 1e-300, 1.0 - 1e-16)
    i = np.arange(1, m + 1)
    terms = (2 * i - 1) * (np.log(fitted) + np.log1p(-fitted[..., ::-1]))
    return -m - terms.sum(axis=-1) / m


def ljung_box(x, lags):
    r"""Ljung-Box :math:`Q = m(m+2)\sum_{k=1}^{h} \hat\rho_k^2/(m-k)` of each row.

    :math:`\hat\rho_k` is the sample autocorrelation with the biased (1/m)
    autocovariance, as in ``statsmodels.stats.diagnostic.acorr_ljungbox``.
    """
    m = x.shape[-1]
    d = x - x.mean(axis=-1, keepdims=True)
    denom = (d * d).sum(axis=-1)
    # Constant intervals have no autocorrelation: their Q is NaN, not a warning.
    denom = np.where(denom > 0, denom, np.nan)
    q = np.zeros(x.shape[:-1])
    for k in range(1, lags + 1):
        rho = (d[..., k:] * d[..., :-k]).sum(axis=-1) / denom
        q += rho * rho / (m - k)
    return m * (m + 2) * q


def runs_count(x):
    """Number of runs above/below the median (``x >= median`` counts as above, as in
    statsmodels' ``runstest_1samp``) and the number ``n1`` above, per row."""
    above = x >= np.median(x, axis=-1, keepdims=True)
    runs = 1 + np.count_nonzero(above[..., 1:] != above[..., :-1], axis=-1)
    return runs, above.sum(axis=-1)


def _log_comb(n, k):
    return gammaln(n + 1) - gammaln(k + 1) - gammaln(n - k + 1)


@lru_cache(maxsize=256)
def runs_pmf(n1, n2):
    """Exact null law of the number of runs for ``n1`` and ``n2`` items of two kinds.

    Returns ``(r, pmf)`` for ``r = 2 .. n1 + n2``: with ``k`` the number of runs of
    each kind, ``P(R = 2k) = 2 C(n1-1, k-1) C(n2-1, k-1) / C(n, n1)`` and
    ``P(R = 2k+1) = [C(n1-1, k) C(n2-1, k-1) + C(n1-1, k-1) C(n2-1, k)] / C(n, n1)``.
    """
    n = n1 + n2
    r = np.arange(2, n + 1)
    if n1 == 0 or n2 == 0:
        return r, (r == 1).astype(float)
    k = r // 2
    with np.errstate(invalid="ignore"):
        even = np.log(2.0) + _log_comb(n1 - 1, k - 1) + _log_comb(n2 - 1, k - 1)
        odd = np.logaddexp(
            _log_comb(n1 - 1, k) + _log_comb(n2 - 1, k - 1),
            _log_comb(n1 - 1, k - 1) + _log_comb(n2 - 1, k),
        )
    log_p = np.where(r % 2 == 0, even, odd) - _log_comb(n, n1)
    pmf = np.where(np.isfinite(log_p), np.exp(log_p), 0.0)
    pmf /= pmf.sum()
    r.flags.writeable = pmf.flags.writeable = False  # cached: shared between calls
    return r, pmf


def runs_pvalue(runs, n1, n2, u=None):
    """Two-sided exact p-value of the runs count.

    With ``u`` (a uniform draw) the p-value is randomised at the observed value,
    ``p_low = P(R < r) + u P(R = r)``, which is exactly uniform under the null, so the
    test has exactly its nominal size; ``u = None`` gives the conservative
    ``2 min(P(R <= r), P(R >= r))``.
    """
    if n1 == 0 or n2 == 0:
        return np.nan  # all intervals equal: no runs to count
    r, pmf = runs_pmf(int(n1), int(n2))
    below = pmf[r < runs].sum()
    at = pmf[r == runs].sum()
    if u is None:
        p_low, p_high = below + at, 1.0 - below
    else:
        p_low = below + u * at
        p_high = 1.0 - p_low
    return min(1.0, 2.0 * min(p_low, p_high))


def dispersion_index(u, n_bins):
    r"""Index of dispersion :math:`s^2/\bar N` (ddof 1) of counts in ``n_bins`` equal
    sub-windows, per row of scaled times ``u``."""
    n = u.shape[-1]
    rows = int(np.prod(u.shape[:-1]))
    idx = np.minimum((u * n_bins).astype(np.int64), n_bins - 1).reshape(rows, n)
    flat = (idx + n_bins * np.arange(rows)[:, None]).ravel()
    counts = np.bincount(flat, minlength=rows * n_bins).reshape(rows, n_bins)
    return _dispersion_from_counts(counts, n).reshape(u.shape[:-1])


def _dispersion_from_counts(counts, n):
    expected = n / counts.shape[-1]
    return ((counts - expected) ** 2).sum(axis=-1) / expected / (counts.shape[-1] - 1)


def simulate_null(test, n_events, size, rng, *, lags=0, n_bins=2):
    """``size`` Monte Carlo draws of a test statistic under the null, given n.

    Interval statistics are evaluated on ``n_events - 1`` IID Exp(1) variables
    (exact, see the module notes), the dispersion index on multinomial counts.
    Rows are simulated in blocks so that long sequences do not exhaust memory.
    """
    if test == "dispersion":
        counts = rng.multinomial(n_events, np.full(n_bins, 1.0 / n_bins), size=size)
        return _dispersion_from_counts(counts, n_events)
    fun = {
        "exponential_ks": exponential_ks,
        "exponential_ad": exponential_ad,
        "ljung_box": lambda x: ljung_box(x, lags),
    }[test]
    m = n_events - 1
    out = np.empty(size)
    block = max(1, _BLOCK // max(m, 1))
    for start in range(0, size, block):
        stop = min(size, start + block)
        out[start:stop] = fun(rng.standard_exponential((stop - start, m)))
    return out


def mc_pvalue(observed, null, *, two_sided=False, u=None):
    r"""Monte Carlo p-value :math:`(1 + \#\{null \ge s\})/(B + 1)`.

    Ties with the observed value (discrete statistics) are broken at random with the
    uniforms ``u`` (a tie counts as "at least as extreme" with probability ``u``), so
    the test has exactly its nominal size; ``u = 1`` gives the conservative p-value.
    ``two_sided`` doubles the smaller tail (capped at 1).
    """
    null = np.sort(null[np.isfinite(null)])
    b = null.size
    observed = np.atleast_1d(observed)
    u = np.ones(observed.shape) if u is None else np.broadcast_to(u, observed.shape)
    lo = np.searchsorted(null, observed, side="left")
    hi = np.searchsorted(null, observed, side="right")
    ties = hi - lo
    # Rank of the observed value among the B + 1 values, ties ordered at random.
    tie_share = np.floor(u * (ties + 1))
    tie_share = np.minimum(tie_share, ties)
    p_upper = (1 + (b - hi) + tie_share) / (b + 1)
    if two_sided:
        p_lower = (1 + lo + (ties - tie_share)) / (b + 1)
        p_upper = np.minimum(1.0, 2.0 * np.minimum(p_upper, p_lower))
    return np.where(np.isfinite(observed), p_upper, np.nan)
