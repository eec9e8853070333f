r"""Distributions that scipy.stats lacks: the two-component hyperexponential.

A hyperexponential interval is exponential with rate ``lam1`` with probability ``p``
and with rate ``lam2`` otherwise. It is what pooling Poisson processes of different
rates gives (docs/architecture.md, "Invariant measure and the kinetic rate": under the
elastic rule angular momentum splits phase space into components with different
collision rates), and it is heavier-tailed than any single exponential (coefficient of
variation >= 1).

The instance is named exactly like its ``.name`` (``hyperexpon``) so that a frozen
distribution serialised as ``frozen.dist.name`` + args + kwds can be resolved by
looking the name up first in :mod:`scipy.stats` and then in this module.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy import optimize
from scipy.special import expit, gamma, logit
from scipy.stats import CensoredData, rv_continuous

from ._renewal_mle import newton

__all__ = ["hyperexpon", "hyperexpon_gen", "fit_hyperexponential"]


def _log_components(x, p, lam1, lam2, *, density: bool):
    """Log of each weighted component: density ``p lam e^{-lam x}`` or survival ``p e^{-lam x}``."""
    with np.errstate(divide="ignore"):
        a = np.log(p) - lam1 * x
        b = np.log1p(-p) - lam2 * x
        if density:
            a = a + np.log(lam1)
            b = b + np.log(lam2)
    return a, b


class hyperexpon_gen(rv_continuous):
    r"""A two-component hyperexponential (mixture of two exponentials) random variable.

    %(before_notes)s

    Notes
    -----
    The probability density function is

    .. math::

        f(x; p, \lambda_1, \lambda_2) = p \lambda_1 e^{-\lambda_1 x}
                                      + (1 - p) \lambda_2 e^{-\lambda_2 x},
        \qquad x \ge 0,

    for :math:`0 \le p \le 1` and rates :math:`\lambda_1, \lambda_2 > 0`. The survival
    function is :math:`p e^{-\lambda_1 x} + (1-p) e^{-\lambda_2 x}` and the raw moments
    are :math:`E[X^k] = k!\,(p \lambda_1^{-k} + (1-p) \lambda_2^{-k})`.

    The shapes already carry both time scales, so ``scale`` is redundant: keep it at 1
    (a ``scale`` s divides both rates by s). ``hyperexpon.fit(data, floc=0)`` fits by
    expectation-maximisation followed by a direct likelihood polish and accepts
    right-censored :class:`scipy.stats.CensoredData`; the returned rates are ordered
    ``lam1 >= lam2`` (component 1 is the fast one).

    %(after_notes)s

    %(example)s
    """

    def _argcheck(self, p, lam1, lam2):
        return (p >= 0) & (p <= 1) & (lam1 > 0) & (lam2 > 0)

    def _pdf(self, x, p, lam1, lam2):
        return p * lam1 * np.exp(-lam1 * x) + (1 - p) * lam2 * np.exp(-lam2 * x)

    def _logpdf(self, x, p, lam1, lam2):
        return np.logaddexp(*_log_components(x, p, lam1, lam2, density=True))

    def _cdf(self, x, p, lam1, lam2):
        # -expm1 keeps the small-x cdf accurate (cdf ~ (p lam1 + (1-p) lam2) x).
        return -p * np.expm1(-lam1 * x) - (1 - p) * np.expm1(-lam2 * x)

    def _sf(self, x, p, lam1, lam2):
        return p * np.exp(-lam1 * x) + (1 - p) * np.exp(-lam2 * x)

    def _logsf(self, x, p, lam1, lam2):
        return np.logaddexp(*_log_components(x, p, lam1, lam2, density=False))

    def _invert(self, target, fun, increasing, log_q_tail, p, lam1, lam2):
        """Solve ``fun(x) = target`` for the monotone ``fun`` (cdf or sf).

        The quantile lies between the quantiles of the two pure exponentials,
        ``x = -log(tail)/lam``, so bisection on log x in that bracket converges for
        every shape; a few Newton steps then polish to machine precision.
        """
        lam_hi = np.maximum(lam1, lam2)
        lam_lo = np.minimum(lam1, lam2)
        lo = np.log(-log_q_tail / lam_hi)
        hi = np.log(-log_q_tail / lam_lo)
        hi = np.where(hi - lo < 1e-12, lo + 1e-12, hi)
        for _ in range(64):
            mid = 0.5 * (lo + hi)
            above = fun(np.exp(mid), p, lam1, lam2) > target
            go_left = above if increasing else ~above
            hi = np.where(go_left, mid, hi)
            lo = np.where(go_left, lo, mid)
        x = np.exp(0.5 * (lo + hi))
        sign = 1.0 if increasing else -1.0
        for _ in range(2):
            dens = self._pdf(x, p, lam1, lam2)
            step = np.where(dens > 0, (fun(x, p, lam1, lam2) - target) / (sign * dens), 0.0)
            x = np.maximum(x - step, 0.5 * x)
        return x

    def _ppf(self, q, p, lam1, lam2):
        q, p, lam1, lam2 = np.broadcast_arrays(q, p, lam1, lam2)
        out = np.zeros(q.shape)
        inner = (q > 0) & (q < 1)
        out[q >= 1] = np.inf
        if inner.any():
            args = (p[inner], lam1[inner], lam2[inner])
            out[inner] = self._invert(q[inner], self._cdf, True, np.log1p(-q[inner]), *args)
        return out

    def _isf(self, q, p, lam1, lam2):
        q, p, lam1, lam2 = np.broadcast_arrays(q, p, lam1, lam2)
        out = np.zeros(q.shape)
        inner = (q > 0) & (q < 1)
        out[q <= 0] = np.inf
        if inner.any():
            args = (p[inner], lam1[inner], lam2[inner])
            out[inner] = self._invert(q[inner], self._sf, False, np.log(q[inner]), *args)
        return out

    def _rvs(self, p, lam1, lam2, size=None, random_state=None):
        fast = random_state.uniform(size=size) < p
        rate = np.where(fast, lam1, lam2)
        return random_state.standard_exponential(size=size) / rate

    def _munp(self, n, p, lam1, lam2):
        return gamma(n + 1.0) * (p / lam1**n + (1 - p) / lam2**n)

    def fit(self, data, *args, **kwds):
        """Maximum-likelihood fit; censoring-aware EM when ``floc`` is fixed.

        With ``floc`` given (usually 0), no fixed shapes and the default method, the
        fit is :func:`fit_hyperexponential` (EM + direct polish) on ``data - floc``,
        in units of ``fscale`` when that is given (otherwise ``scale = 1``). Any other
        combination falls back to the generic :meth:`scipy.stats.rv_continuous.fit`.
        """
        floc = kwds.get("floc")
        fixed_shapes = {"f0", "f1", "f2", "fp", "flam1", "flam2", "fix_p", "fix_lam1"}
        method = str(kwds.get("method", "mle")).lower()
        extra = set(kwds) - {"floc", "fscale", "method", "p", "lam1", "lam2", "scale"}
        if floc is None or fixed_shapes & set(kwds) or method != "mle" or extra:
            return super().fit(data, *args, **kwds)
        fscale = kwds.get("fscale")
        scale = 1.0 if fscale is None else float(fscale)
        if isinstance(data, CensoredData):
            # scipy keeps the censoring classes in private arrays; only right
            # censoring is modelled here, anything else goes to the generic fit.
            if data._left.size or data._interval.size:
                return super().fit(data, *args, **kwds)
            complete = np.asarray(data._uncensored, dtype=float)
            censored = np.asarray(data._right, dtype=float)
        else:
            complete = np.asarray(data, dtype=float).ravel()
            censored = np.empty(0)
        complete = (complete - floc) / scale
        censored = (censored - floc) / scale
        if complete.size == 0 or (complete < 0).any() or (censored < 0).any():
            raise ValueError("hyperexpon.fit needs non-negative data above floc, got some below")
        p, lam1, lam2, _ = fit_hyperexponential(complete, censored)
        return p, lam1, lam2, float(floc), scale


hyperexpon = hyperexpon_gen(a=0.0, name="hyperexpon", shapes="p, lam1, lam2")


@njit(cache=True)
def _odds_sums(v, offset, d):
    """Sums over ``v`` for the odds ``log r = offset - d v`` of component 1, with
    ``w = r / (1 + r)`` and ``u = w (1 - w)``: ``log(1 + r)``, ``w``, ``w v``, ``u``,
    ``u v``, ``u v^2`` (one fused, overflow-free pass)."""
    softplus = 0.0
    sum_w = 0.0
    sum_wv = 0.0
    sum_u = 0.0
    sum_uv = 0.0
    sum_uv2 = 0.0
    for i in range(v.size):
        lr = offset - d * v[i]
        e = math.exp(-abs(lr))
        softplus += max(lr, 0.0) + math.log1p(e)
        w = (1.0 if lr >= 0.0 else e) / (1.0 + e)
        u = e / ((1.0 + e) * (1.0 + e))
        sum_w += w
        sum_wv += w * v[i]
        sum_u += u
        sum_uv += u * v[i]
        sum_uv2 += u * v[i] * v[i]
    return softplus, sum_w, sum_wv, sum_u, sum_uv, sum_uv2


@njit(cache=True)
def _responsibility_sums(v, offset, d):
    """``sum w``, ``sum w v``, ``sum (1 - w) v`` for the odds of :func:`_odds_sums`;
    ``1 - w`` is formed directly, without cancellation, when ``w`` is near 1."""
    sum_w = sum_wv = sum_qv = 0.0
    for i in range(v.size):
        lr = offset - d * v[i]
        e = math.exp(-abs(lr))
        if lr >= 0.0:
            w, q = 1.0 / (1.0 + e), e / (1.0 + e)
        else:
            w, q = e / (1.0 + e), 1.0 / (1.0 + e)
        sum_w += w
        sum_wv += w * v[i]
        sum_qv += q * v[i]
    return sum_w, sum_wv, sum_qv


@njit(cache=True)
def _em_steps(x, c, p, lam1, lam2, n_iter):
    """``n_iter`` EM steps as in :func:`_em` (each exponential component gets its
    censored MLE, expected events / expected exposure), compiled as one loop."""
    n_obs = x.size + c.size
    for _ in range(n_iter):
        log_odds = math.log(p) - math.log1p(-p)
        w, wx, qx = _responsibility_sums(x, log_odds + math.log(lam1 / lam2), lam1 - lam2)
        wc, wcc, qcc = _responsibility_sums(c, log_odds, lam1 - lam2)
        p = min(max((w + wc) / n_obs, 1e-12), 1 - 1e-12)
        lam1 = max(w, 1e-300) / max(wx + wcc, 1e-300)
        lam2 = max(x.size - w, 1e-300) / max(qx + qcc, 1e-300)
    return p, lam1, lam2


def _mixture_sums(theta, x, c, sum_x, sum_c):
    """Censored log-likelihood at ``theta = (logit p, log lam1, log lam2)`` and the
    posterior sums of :func:`_odds_sums` over the complete (``sx``) and the censored
    (``sc``) intervals: ``(ll, sx, sc)``.

    With ``r`` the odds of component 1 given an observation,
    ``log r = logit p + log(lam1/lam2) - (lam1 - lam2) x`` (complete; no rate ratio for
    a censored one), the log-likelihood is ``log(1-p) + log lam2 - lam2 x + log(1 + r)``
    and the responsibility is ``w = r / (1 + r)``.
    """
    lp, l1, l2 = float(theta[0]), float(theta[1]), float(theta[2])
    d = math.exp(l1) - math.exp(l2)
    log_q = -(max(lp, 0.0) + math.log1p(math.exp(-abs(lp))))  # log(1 - p)
    sx = _odds_sums(x, lp + l1 - l2, d)
    sc = _odds_sums(c, lp, d)
    ll = x.size * (log_q + l2) + c.size * log_q - math.exp(l2) * (sum_x + sum_c) + sx[0] + sc[0]
    return ll, sx, sc


def _mixture_derivatives(theta, x, c, sum_x, sum_c):
    """Log-likelihood, gradient and Hessian in ``(logit p, log lam1, log lam2)``.

    Per complete interval ``d log r = (1, 1 - lam1 x, lam2 x - 1)`` and the score is
    ``(w - p, w (1 - lam1 x), (1 - w)(1 - lam2 x))``; per censored one
    ``d log r = (1, -lam1 c, lam2 c)`` and the score ``(w - p, -w lam1 c,
    -(1 - w) lam2 c)``. The Hessian is ``sum u (d log r)(d log r)^T`` plus the
    curvature of the linear terms (``-p(1-p)`` per observation, ``-w lam1 y`` and
    ``-(1 - w) lam2 y`` on the rate diagonals).
    """
    ll, sx, sc = _mixture_sums(theta, x, c, sum_x, sum_c)
    _, w, wx, u, ux, ux2 = sx
    _, wc, wcc, uc, ucc, ucc2 = sc
    n_obs = x.size + c.size
    p = float(expit(theta[0]))
    l1, l2 = math.exp(theta[1]), math.exp(theta[2])
    grad = np.array(
        [
            w + wc - p * n_obs,
            w - l1 * (wx + wcc),
            (x.size - w) - l2 * (sum_x - wx + sum_c - wcc),
        ]
    )
    h_aa = u + uc - p * (1.0 - p) * n_obs
    h_ab = u - l1 * (ux + ucc)
    h_ag = -u + l2 * (ux + ucc)
    h_bb = u - 2 * l1 * ux + l1 * l1 * (ux2 + ucc2) - l1 * (wx + wcc)
    h_bg = -u + (l1 + l2) * ux - l1 * l2 * (ux2 + ucc2)
    h_gg = u - 2 * l2 * ux + l2 * l2 * (ux2 + ucc2) - l2 * (sum_x - wx + sum_c - wcc)
    hess = np.array([[h_aa, h_ab, h_ag], [h_ab, h_bb, h_bg], [h_ag, h_bg, h_gg]])
    return ll, grad, hess


def fit_hyperexponential(complete, censored=None, *, n_em=40, max_polish=500, em_sample=None):
    r"""Maximum-likelihood fit of a hyperexponential to right-censored intervals.

    Parameters
    ----------
    complete : array_like
        Complete (uncensored) intervals, non-negative.
    censored : array_like, optional
        Right-censored intervals (the interval is known to exceed the value).
    n_em : int, optional
        EM iterations run from each of four starting points before the polish.
    max_polish : int, optional
        Iteration cap of the Newton polish.
    em_sample : int or None, optional
        Run the multi-start EM on an evenly strided subsample of about this many
        complete (and proportionally censored) intervals: faster on large samples, at
        the risk of missing a small fast component that only all the data reveal
        (default None: all of them).

    Returns
    -------
    p, lam1, lam2, loglik : float
        Fitted weight and rates with ``lam1 >= lam2``, and the maximised
        log-likelihood
        :math:`\sum_{complete} \log f(x_i) + \sum_{censored} \log S(c_j)`.

    Notes
    -----
    EM is monotone but slow near the optimum, a direct Newton polish with the
    analytic gradient and Hessian is fast there but needs a good start: EM from four
    spread-out starts (rates a few times above and below the exposure rate), then
    damped Newton on ``(logit p, log lam1, log lam2)`` from the best. The sums over
    the data (log-likelihood, responsibilities and their moments) come from fused
    numba passes. When the data are close to exponential the maximum is on the
    boundary (``p -> 0 or 1`` or ``lam1 -> lam2``) and the parameters are not
    identified.

    Examples
    --------
    >>> import numpy as np
    >>> x = hyperexpon(0.3, 5.0, 0.5).rvs(size=5000, random_state=np.random.default_rng(0))
    >>> p, lam1, lam2, loglik = fit_hyperexponential(x)
    >>> round(p, 1), round(lam2, 1)
    (0.3, 0.5)
    """
    x = np.ascontiguousarray(complete, dtype=float).ravel()
    c = np.empty(0) if censored is None else np.ascontiguousarray(censored, dtype=float).ravel()
    if x.size == 0:
        raise ValueError("complete must hold at least one interval, got none")
    sum_x, sum_c = float(x.sum()), float(c.sum())
    rate = x.size / (sum_x + sum_c)
    stride = 1 if em_sample is None else max(1, x.size // max(int(em_sample), 1))
    # contiguous copies: one compiled signature of the kernel serves every call
    xs, cs = np.ascontiguousarray(x[::stride]), np.ascontiguousarray(c[::stride])
    starts = [(0.5, 2.0, 0.5), (0.2, 5.0, 0.7), (0.8, 1.5, 0.2), (0.05, 20.0, 0.9)]
    best = None
    for p0, f1, f2 in starts:
        p, lam1, lam2 = _em_steps(xs, cs, p0, f1 * rate, f2 * rate, n_em)
        theta = np.array([logit(p), np.log(lam1), np.log(lam2)])
        ll = _mixture_sums(theta, x, c, sum_x, sum_c)[0]
        if best is None or ll > best[0]:
            best = (ll, theta)
    n_obs = x.size + c.size

    cache = {}

    def objective(theta):
        key = tuple(theta)
        if key not in cache:
            cache.clear()
            cache[key] = _mixture_derivatives(theta, x, c, sum_x, sum_c)
        ll, grad, _ = cache[key]
        if not np.isfinite(ll):
            return 1e10, np.zeros(3)
        return -ll / n_obs, -grad / n_obs

    def hessian(theta):
        objective(theta)
        return -cache[tuple(theta)][2] / n_obs

    # logit p within +-37: p within 1e-16 of 0 or 1 is a boundary fit
    bounds = [(-37.0, 37.0), (-700.0, 700.0), (-700.0, 700.0)]
    with np.errstate(all="ignore"):
        theta, _ = newton(objective, best[1], bounds, "hyperexponential", hessian, max_polish)
        ll_polish = -objective(theta)[0] * n_obs
    # on the boundary (nearly exponential data) the polish may stop anywhere on a ridge
    # of equal likelihood: it is kept only if it is at least as good as the EM start
    if not ll_polish >= best[0]:
        theta = best[1]
    return _mixture_fit(theta, x, c)


def _mixture_fit(theta, x, c):
    """``(p, lam1, lam2, loglik)`` of the fitted ``theta = (logit p, log lam1, log lam2)``:
    the weight's logit clipped to +-37 (p within 1e-16 of 0 or 1 is a boundary fit), the
    faster component first, and the censored log-likelihood at those values."""
    theta = np.array([np.clip(theta[0], -37.0, 37.0), theta[1], theta[2]])
    p, lam1, lam2 = float(expit(theta[0])), float(np.exp(theta[1])), float(np.exp(theta[2]))
    if lam1 < lam2:
        p, lam1, lam2 = 1.0 - p, lam2, lam1
    ax, bx = _log_components(x, p, lam1, lam2, density=True)
    ac, bc = _log_components(c, p, lam1, lam2, density=False)
    ll = np.logaddexp(ax, bx).sum() + np.logaddexp(ac, bc).sum()
    return p, lam1, lam2, float(ll)


# --- reference: the former implementation ------------------------------------------------


def _loglik_and_grad(theta, x, c):
    """Censored log-likelihood and its gradient in ``(logit p, log lam1, log lam2)``.

    With ``w`` the posterior weight of component 1, ``d/dlogit p = w - p``,
    ``d/dlog lam1 = w (delta - lam1 t)`` and ``d/dlog lam2 = (1 - w)(delta - lam2 t)``
    (``delta = 1`` for a complete interval, 0 for a censored one).
    """
    p = expit(theta[0])
    lam1, lam2 = np.exp(theta[1]), np.exp(theta[2])
    ax, bx = _log_components(x, p, lam1, lam2, density=True)
    ac, bc = _log_components(c, p, lam1, lam2, density=False)
    lx, lc = np.logaddexp(ax, bx), np.logaddexp(ac, bc)
    wx, wc = np.exp(ax - lx), np.exp(ac - lc)
    grad = np.array(
        [
            wx.sum() + wc.sum() - p * (x.size + c.size),
            (wx * (1 - lam1 * x)).sum() - (wc * lam1 * c).sum(),
            ((1 - wx) * (1 - lam2 * x)).sum() - ((1 - wc) * lam2 * c).sum(),
        ]
    )
    return lx.sum() + lc.sum(), grad


def _em(x, c, p, lam1, lam2, n_iter):
    """Plain EM steps; each exponential component gets its censored MLE
    (expected events / expected exposure), the weight its mean responsibility."""
    for _ in range(n_iter):
        ax, bx = _log_components(x, p, lam1, lam2, density=True)
        ac, bc = _log_components(c, p, lam1, lam2, density=False)
        wx = np.exp(ax - np.logaddexp(ax, bx))
        wc = np.exp(ac - np.logaddexp(ac, bc))
        events1, events2 = wx.sum(), (1 - wx).sum()
        expo1 = (wx * x).sum() + (wc * c).sum()
        expo2 = ((1 - wx) * x).sum() + ((1 - wc) * c).sum()
        p = (events1 + wc.sum()) / (x.size + c.size)
        p = min(max(p, 1e-12), 1 - 1e-12)
        lam1 = max(events1, 1e-300) / max(expo1, 1e-300)
        lam2 = max(events2, 1e-300) / max(expo2, 1e-300)
    return p, lam1, lam2


def _fit_hyperexponential_reference(complete, censored=None, *, n_em=40, max_polish=500):
    """The former :func:`fit_hyperexponential` (EM from four starts on all the data,
    then BFGS), kept as the reference of the tests and benchmarks."""
    x = np.asarray(complete, dtype=float).ravel()
    c = np.empty(0) if censored is None else np.asarray(censored, dtype=float).ravel()
    if x.size == 0:
        raise ValueError("complete must hold at least one interval, got none")
    rate = x.size / (x.sum() + c.sum())
    starts = [(0.5, 2.0, 0.5), (0.2, 5.0, 0.7), (0.8, 1.5, 0.2), (0.05, 20.0, 0.9)]
    best = None
    for p0, f1, f2 in starts:
        p, lam1, lam2 = _em(x, c, p0, f1 * rate, f2 * rate, n_em)
        theta = np.array([logit(p), np.log(lam1), np.log(lam2)])
        ll = _loglik_and_grad(theta, x, c)[0]
        if best is None or ll > best[0]:
            best = (ll, theta)
    n_obs = x.size + c.size

    def objective(theta):
        # Keep the weight's logit finite: p within 1e-16 of 0 or 1 is a boundary fit.
        theta = np.array([np.clip(theta[0], -37.0, 37.0), theta[1], theta[2]])
        ll, grad = _loglik_and_grad(theta, x, c)
        if not np.isfinite(ll):
            return np.inf, np.zeros(3)
        return -ll / n_obs, -grad / n_obs

    res = optimize.minimize(
        objective,
        best[1],
        jac=True,
        method="BFGS",
        options={"maxiter": max_polish, "gtol": 1e-9},
    )
    theta = res.x if np.isfinite(res.fun) and -res.fun * n_obs >= best[0] else best[1]
    return _mixture_fit(theta, x, c)
