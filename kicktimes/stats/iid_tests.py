r"""Vectorised statistics and null distributions of the Poisson-process tests.

Conditional on the number ``n`` of events in ``[0, T]``, a homogeneous Poisson
process places them as ``n`` IID uniform points, so every test below has an exact
null given ``n`` (the tests are *conditional on n*):

* on the scaled times ``u_i = t_i / T`` (uniform order statistics): conditional
  uniformity (KS, exact null: `kicktimes.stats.poisson.uniformity_ks`), Laplace's trend
  statistic (asymptotically normal), the index of dispersion of counts in equal
  sub-windows (multinomial null by Monte Carlo);
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
from numba import njit
from scipy import stats
from scipy.special import gammaln

# Largest block of random numbers simulated at once (memory bound for long sequences).
_BLOCK = 2_000_000


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
    autocovariance, as in ``statsmodels.stats.diagnostic.acorr_ljungbox``. Constant rows
    have no autocorrelation: their Q is NaN.

    One compiled pass per row (`_ljung_box_rows`), bitwise what the numpy expression
    ``(d[..., k:] * d[..., :-k]).sum(axis=-1)`` per lag gave (the same pairwise sums), and
    faster (``python benchmarks/bench_stats.py --part poisson``; docs/benchmarks.md).
    """
    x = np.asarray(x, dtype=float)
    m = x.shape[-1]
    rows = int(np.prod(x.shape[:-1]))
    q = _ljung_box_rows(np.ascontiguousarray(x.reshape(rows, m)), int(lags))
    return q.reshape(x.shape[:-1])[()]


@njit(cache=True)
def _block_dot(a, ia, b, ib, n):
    # numpy's pairwise_sum of one block (n <= 128): 8 accumulators, then the rest in turn
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[ia + i] * b[ib + i]
        return res
    r0 = a[ia] * b[ib]
    r1 = a[ia + 1] * b[ib + 1]
    r2 = a[ia + 2] * b[ib + 2]
    r3 = a[ia + 3] * b[ib + 3]
    r4 = a[ia + 4] * b[ib + 4]
    r5 = a[ia + 5] * b[ib + 5]
    r6 = a[ia + 6] * b[ib + 6]
    r7 = a[ia + 7] * b[ib + 7]
    i = 8
    stop = n - n % 8
    while i < stop:
        r0 += a[ia + i] * b[ib + i]
        r1 += a[ia + i + 1] * b[ib + i + 1]
        r2 += a[ia + i + 2] * b[ib + i + 2]
        r3 += a[ia + i + 3] * b[ib + i + 3]
        r4 += a[ia + i + 4] * b[ib + i + 4]
        r5 += a[ia + i + 5] * b[ib + i + 5]
        r6 += a[ia + i + 6] * b[ib + i + 6]
        r7 += a[ia + i + 7] * b[ib + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[ia + i] * b[ib + i]
        i += 1
    return res


@njit(cache=True)
def _pairwise_dot(a, ia, b, ib, n, frames, partial):
    """``sum(a[ia:ia + n] * b[ib:ib + n])`` summed as numpy's ``add.reduce`` sums a
    contiguous row, so bitwise equal to it: blocks of at most 128 (`_block_dot`); a longer
    range is split at half its length rounded down to a multiple of 8, and the two sums
    added. Checked against numpy in tests/test_stats_poisson.py.

    The recursion is walked with an explicit stack (``frames``: offset, length, left half
    done; ``partial``: the left halves' sums; 64 levels cover any length) because numba
    cannot load a cached recursive kernel (numba issue 6061: a segfault).
    """
    if n <= 128:
        return _block_dot(a, ia, b, ib, n)
    half = n // 2
    half -= half % 8
    if n - half <= 128:  # one split (n <= 256): most Monte Carlo rows, without the stack
        return _block_dot(a, ia, b, ib, half) + _block_dot(a, ia + half, b, ib + half, n - half)
    top = 0
    frames[0, 0] = 0
    frames[0, 1] = n
    frames[0, 2] = 0
    while True:
        lo = frames[top, 0]
        cnt = frames[top, 1]
        if cnt > 128:  # descend into the left half
            half = cnt // 2
            half -= half % 8
            top += 1
            frames[top, 0] = lo
            frames[top, 1] = half
            frames[top, 2] = 0
            continue
        v = _block_dot(a, ia + lo, b, ib + lo, cnt)
        top -= 1
        # hand the sum up: a left half waits for its right half, a right one completes
        while top >= 0 and frames[top, 2] == 1:
            v = partial[top] + v
            top -= 1
        if top < 0:
            return v
        partial[top] = v
        frames[top, 2] = 1
        cnt = frames[top, 1]
        half = cnt // 2
        half -= half % 8
        lo = frames[top, 0] + half
        top += 1
        frames[top, 0] = lo
        frames[top, 1] = cnt - half
        frames[top, 2] = 0


@njit(cache=True, error_model="numpy")
def _ljung_box_rows(x, lags):
    # numpy's order of operations throughout (mean = sum / m, Q accumulated lag by lag);
    # the reduce adds its pairwise sum to an initial 0.0, hence the "0.0 +". One call
    # site of _pairwise_dot (the mean, the variance, then each lag): each call site is
    # inlined; with three, the kernel took 3.1 s to compile instead of 1.9 s.
    rows, m = x.shape
    ones = np.ones(m)
    d = np.empty(m)
    q = np.empty(rows)
    frames = np.empty((64, 3), np.int64)
    partial = np.empty(64)
    # an int64, not a literal 0: with a literal numba compiles _block_dot twice
    zero = np.int64(0)
    for r in range(rows):
        for i in range(m):
            d[i] = x[r, i]
        denom = 0.0
        s = 0.0
        for k in range(-1, lags + 1):
            lag = max(k, 0)
            other = ones if k < 0 else d
            total = 0.0 + _pairwise_dot(d, lag, other, zero, m - lag, frames, partial)
            if k < 0:  # the mean: centre the row
                mean = total / m
                for i in range(m):
                    d[i] = x[r, i] - mean
            elif k == 0:
                denom = total if total > 0 else np.nan
            else:
                rho = total / denom
                s += rho * rho / (m - k)
        q[r] = m * (m + 2) * s
    return q


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
