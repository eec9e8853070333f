r"""Dedicated censored maximum likelihood for the two-parameter renewal models.

Each fit takes complete intervals ``x`` and right-censored intervals ``c`` (already in
units of the mean observation, see :func:`kicktimes.stats.renewal._fit`) and returns
``(theta, trouble)``: the natural parameters in ``PARAM_NAMES`` order and a list of
messages, empty when the optimiser converged. They replace ``scipy.stats.<dist>.fit``
(Nelder-Mead on scipy's generic censored ``nnlf``), whose per-call overhead and
derivative-free search dominated the cost of :func:`compare_models`.

The complete part of every likelihood is written with sufficient statistics
(:math:`n, \sum x, \sum \log x, \sum \log^2 x`), so an optimiser step costs O(1) for it
and O(distinct censored values) for the survival terms:

==========  ======================================================================
gamma       no censoring: the 1-D profile equation
            :math:`\log a - \psi(a) = \log \bar x - \overline{\log x}` by Newton in
            :math:`\log a`; with censoring: damped Newton on :math:`(\log a, \log s)`,
            analytic gradient except :math:`\partial_a \log Q(a, c/s)`, a central
            difference on the censored terms only
weibull     1-D profile: :math:`\lambda^k = \sum_{all} y^k / n` and the root of
            :math:`1/k + \overline{\log x} - \sum y^k \log y / \sum y^k` (strictly
            decreasing in k), safeguarded Newton in :math:`\log k`
lognormal   no censoring: closed form; with censoring: damped Newton on
            :math:`(\mu, \log\sigma)` with the analytic gradient (``log_ndtr``)
lomax       1-D profile in :math:`\eta = 1/s`: :math:`\hat\alpha(\eta) = n / T(\eta)`,
            :math:`T = \sum_{all} \log(1 + \eta y)`; :math:`\eta = 0` is the
            exponential limit; grid on :math:`\log\eta` plus bounded Brent
==========  ======================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize
from scipy.special import digamma, gammaincc, gammaln, log_ndtr, polygamma, xlogy

_LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)
# A gradient (of the log-likelihood per observation, in the free coordinates) this
# small means the optimum even when the line search can no longer decrease on noise.
_GRAD_OK = 1e-6
# Lomax: the profile is searched on this grid of log10(eta) (eta = 1/scale in units of
# the mean observation); heavy tails (shape < 1) put the scale far below the mean.
_LOMAX_GRID = np.arange(-8.0, 20.01, 1.0)
# Lomax edge: returned when the supremum is the exponential limit (eta -> 0). Shape and
# scale are then ~1e12 (beyond the _DIVERGED bounds of renewal.py, so the fit says so),
# and the log-likelihood differs from the exponential's by ~n * 1e-12.
LOMAX_EDGE_ETA = 1e-12


@dataclass(frozen=True)
class Sample:
    """Complete intervals with their sufficient statistics, and the distinct positive
    censored values with multiplicities (a zero censored value adds log S(0) = 0)."""

    x: np.ndarray
    log_x: np.ndarray
    c: np.ndarray
    weight: np.ndarray
    n: int
    n_obs: int
    sum_x: float
    sum_log_x: float

    @classmethod
    def of(cls, x, c):
        x = np.asarray(x, dtype=float)
        c = np.asarray(c, dtype=float)
        cu, counts = np.unique(c[c > 0], return_counts=True)
        with np.errstate(divide="ignore"):
            log_x = np.log(x)
        return cls(
            x=x,
            log_x=log_x,
            c=cu,
            weight=counts.astype(float),
            n=x.size,
            n_obs=x.size + c.size,
            sum_x=float(x.sum()),
            sum_log_x=float(log_x.sum()),
        )


def _finite(value, grad):
    """A huge finite value where the likelihood is not finite, so that the line search
    of :func:`newton` backs off."""
    if not np.isfinite(value) or not np.all(np.isfinite(grad)):
        return 1e10, np.zeros_like(grad)
    return value, grad


def _numerical_hessian(objective, x, grad):
    """Forward differences of the analytic gradient, symmetrised."""
    k = x.size
    hess = np.empty((k, k))
    for i in range(k):
        h = 1e-6 * max(1.0, abs(x[i]))
        shifted = x.copy()
        shifted[i] += h
        hess[:, i] = (objective(shifted)[1] - grad) / h
    return 0.5 * (hess + hess.T)


def newton(objective, start, bounds, what, hess=None, max_iter=200):
    """Minimise ``objective`` (value, gradient) by damped Newton; ``(x, trouble)``.

    The Hessian is ``hess(x)`` or forward differences of the gradient; it is shifted by
    a multiple of the identity until positive definite (Levenberg), and steps are
    halved until the Armijo condition holds, inside the box ``bounds``. For these
    2- and 3-parameter likelihoods this converges in a handful of steps from the
    moment or profile starts, and it needs no BLAS: scipy's L-BFGS-B (a few BLAS calls
    per iteration) ran ~10 times slower on a loaded machine with threaded OpenBLAS.
    """
    lo = np.array([b[0] for b in bounds])
    hi = np.array([b[1] for b in bounds])
    x = np.clip(np.asarray(start, dtype=float), lo, hi)
    f, g = objective(x)
    if f >= 1e10:
        return x, [f"{what}: no finite likelihood at the start"]
    converged = False
    for _ in range(max_iter):
        # coordinates held at a bound by a gradient pushing outwards stay fixed
        free = ~(((x <= lo) & (g > 0)) | ((x >= hi) & (g < 0)))
        if not free.any() or np.max(np.abs(g[free])) < 1e-10:
            converged = True
            break
        h = hess(x) if hess is not None else _numerical_hessian(objective, x, g)
        h = h[np.ix_(free, free)]
        eye = np.eye(h.shape[0])
        shift = 0.0
        scale = max(1e-12, float(np.max(np.abs(np.diag(h)))))
        for _ in range(60):
            try:
                np.linalg.cholesky(h + shift * eye)
                break
            except np.linalg.LinAlgError:
                shift = max(2.0 * shift, 1e-10 * scale)
        step = np.zeros_like(x)
        step[free] = -np.linalg.solve(h + shift * eye, g[free])
        slope = float(g @ step)
        if -slope < 1e-15 * max(1.0, abs(f)):
            # the predicted gain is below rounding: the optimum, if the gradient is small
            converged = np.max(np.abs(g[free])) < _GRAD_OK
            break
        t = 1.0
        for _ in range(40):
            new = np.clip(x + t * step, lo, hi)
            f_new, g_new = objective(new)
            if f_new <= f + 1e-4 * t * slope:
                break
            t *= 0.5
        else:
            converged = np.max(np.abs(g[free])) < _GRAD_OK
            break
        moved = np.max(np.abs(new - x))
        x, f, g = new, f_new, g_new
        if moved < 1e-13:
            converged = np.max(np.abs(g[free])) < _GRAD_OK
            break
    trouble = []
    if np.any(np.minimum(np.abs(x - lo), np.abs(x - hi)) < 1e-8):
        trouble.append(f"{what}: Newton stopped at a bound of the search box")
    elif not converged:
        trouble.append(f"{what}: Newton did not converge (gradient {np.max(np.abs(g)):.2g})")
    return x, trouble


# --- gamma -------------------------------------------------------------------------------


def log_gammaincc(a, z):
    """``log Q(a, z)``, the log of the regularised upper incomplete gamma function.

    ``gammaincc`` underflows (and loses relative accuracy) far in the tail; there the
    continued fraction :math:`Q = z^a e^{-z} / \\Gamma(a) \\cdot 1/(z + 1 - a - \\ldots)`
    (modified Lentz; it converges fast for ``z > a + 1``, which a tiny Q implies) is
    evaluated in logs.
    """
    z = np.asarray(z, dtype=float)
    q = gammaincc(a, z)
    with np.errstate(divide="ignore"):
        out = np.log(q)
    tail = q < 1e-280
    if tail.any():
        out[tail] = _log_gammaincc_cf(a, z[tail])
    return out


def _log_gammaincc_cf(a, z):
    tiny = 1e-300
    b = z + 1.0 - a
    cc = np.full(z.shape, 1.0 / tiny)
    d = 1.0 / b
    h = d.copy()
    for i in range(1, 500):
        an = -i * (i - a)
        b = b + 2.0
        d = an * d + b
        d = np.where(np.abs(d) < tiny, tiny, d)
        cc = b + an / cc
        cc = np.where(np.abs(cc) < tiny, tiny, cc)
        d = 1.0 / d
        delta = d * cc
        h = h * delta
        if np.all(np.abs(delta - 1.0) < 1e-15):
            break
    return a * np.log(z) - z - gammaln(a) + np.log(h)


def _gamma_profile_shape(log_ratio):
    """Root of ``log a - digamma(a) = log_ratio`` (> 0): the uncensored gamma MLE shape.

    Minka's closed-form start, then Newton in ``log a`` (the function is convex and
    decreasing in ``log a``, so Newton from either side converges in a few steps).
    """
    r = log_ratio
    a = (3.0 - r + math.sqrt((r - 3.0) ** 2 + 24.0 * r)) / (12.0 * r)
    for _ in range(100):
        f = math.log(a) - float(digamma(a)) - r
        df = 1.0 - a * float(polygamma(1, a))  # d f / d log a, negative
        step = -f / df
        step = max(min(step, 3.0), -3.0)
        a *= math.exp(step)
        if abs(step) < 1e-13:
            return a, True
    return a, False


def fit_gamma(x, c):
    r"""Censored gamma MLE ``(shape, scale)``.

    .. math::

        \ell = -n \log\Gamma(a) - n a \log s + (a - 1)\sum \log x - \sum x / s
               + \sum_j \log Q(a, c_j / s)
    """
    s = Sample.of(x, c)
    trouble = []
    mean_x = s.sum_x / s.n
    log_ratio = math.log(mean_x) - s.sum_log_x / s.n
    if not (np.isfinite(log_ratio) and log_ratio > 0):
        return np.array([np.nan, np.nan]), ["gamma: log(mean) - mean(log) of the data is not > 0"]
    shape, ok = _gamma_profile_shape(log_ratio)
    if not s.c.size:
        if not ok:
            trouble.append("gamma: the profile-likelihood Newton iteration did not converge")
        return np.array([shape, mean_x / shape]), trouble
    # censored: start from the complete-data shape with the censored exposure in the scale
    start = np.array([math.log(shape), math.log((s.sum_x + s.weight @ s.c) / (s.n * shape))])
    free, trouble = newton(
        lambda f: _gamma_nll(f, s), start, [(-30.0, 30.0), (-700.0, 700.0)], "gamma"
    )
    return np.exp(free), trouble


def _gamma_nll(free, s):
    la, ls = float(free[0]), float(free[1])
    a, scale = math.exp(la), math.exp(ls)
    n = s.n
    with np.errstate(all="ignore"):
        lga = float(gammaln(a))
        ll = -n * lga - n * a * ls + (a - 1.0) * s.sum_log_x - s.sum_x / scale
        g_a = -n * float(digamma(a)) - n * ls + s.sum_log_x
        g_ls = -n * a + s.sum_x / scale
        z = s.c / scale
        lq = log_gammaincc(a, z)
        ll += s.weight @ lq
        # d log Q / d log s = z^a e^{-z} / (Gamma(a) Q)
        g_ls += s.weight @ np.exp(a * np.log(z) - z - lga - lq)
        h = 1e-5 * a  # central difference: error ~ h^2, noise ~ 1e-16 / h
        g_a += s.weight @ (log_gammaincc(a + h, z) - log_gammaincc(a - h, z)) / (2.0 * h)
    grad = -np.array([g_a * a, g_ls]) / s.n_obs
    return _finite(-ll / s.n_obs, grad)


# --- weibull -----------------------------------------------------------------------------


def fit_weibull(x, c):
    r"""Censored Weibull MLE ``(shape, scale)`` from its 1-D profile likelihood.

    With :math:`y` all observations (complete and censored), the scale maximising the
    likelihood at shape k is :math:`\lambda^k = \sum y^k / n`, and the shape solves

    .. math::

        g(k) = \frac1k + \frac1n \sum_{complete} \log x
               - \frac{\sum y^k \log y}{\sum y^k} = 0,

    :math:`g` falling strictly from :math:`+\infty` (its derivative is
    :math:`-1/k^2 - \mathrm{Var}_w(\log y) < 0`, weights :math:`w \propto y^k`).
    """
    s = Sample.of(x, c)
    ly = np.concatenate([s.log_x, np.log(s.c)])
    wy = np.concatenate([np.ones(s.n), s.weight])
    mean_lx = s.sum_log_x / s.n
    sd = float(np.std(s.log_x)) if s.n > 1 else 0.0
    if not (np.all(np.isfinite(ly)) and ly.max() > mean_lx):
        return np.array([np.nan, np.nan]), ["weibull: no profile root (degenerate data)"]
    # sd of log x is pi / (k sqrt 6) for Weibull data
    u = math.log(1.2825 / sd) if sd > 0 else 0.0
    lo, hi = -math.inf, math.inf  # bracket of the root in u = log k
    converged = False
    for _ in range(200):
        k = math.exp(u)
        t = k * (ly - ly.max())
        p = wy * np.exp(t)
        p /= p.sum()
        mean_ly = p @ ly
        var_ly = p @ (ly - mean_ly) ** 2
        g = 1.0 / k + mean_lx - mean_ly
        if g > 0:
            lo = max(lo, u)
        else:
            hi = min(hi, u)
        # Newton in u: dg/du = k g'(k) = -(1/k + k Var)
        step = g / (1.0 / k + k * var_ly)
        if abs(step) < 1e-13 or g == 0.0:
            u, converged = u + step, True
            break
        new = u + max(min(step, 2.0), -2.0)
        if not lo < new < hi:
            # Newton left the bracket: bisect (or keep stepping until there is one)
            new = 0.5 * (lo + hi) if math.isfinite(lo + hi) else u + (2.0 if g > 0 else -2.0)
        if hi - lo < 1e-13:
            u, converged = new, True
            break
        u = new
    k = math.exp(u)
    m = k * ly.max()
    log_sum = m + math.log(wy @ np.exp(k * ly - m))
    scale = math.exp((log_sum - math.log(s.n)) / k)
    trouble = [] if converged else ["weibull: the profile-likelihood root search did not converge"]
    return np.array([k, scale]), trouble


# --- lognormal ---------------------------------------------------------------------------


def fit_lognormal(x, c):
    r"""Censored lognormal MLE ``(mu, sigma)``.

    .. math::

        \ell = -n\log\sigma - \sum\log x - \frac{n}{2}\log 2\pi
               - \frac{Q_0 + n(\bar m - \mu)^2}{2\sigma^2}
               + \sum_j \log\Phi\!\left(-\frac{\log c_j - \mu}{\sigma}\right),

    :math:`\bar m` and :math:`Q_0` the mean and the sum of squared deviations of
    :math:`\log x`; closed form without censoring.
    """
    s = Sample.of(x, c)
    mean = s.sum_log_x / s.n
    q0 = float(((s.log_x - mean) ** 2).sum())
    if not (np.isfinite(q0) and q0 > 0):
        return np.array([np.nan, np.nan]), ["lognormal: log x has no spread"]
    sigma = math.sqrt(q0 / s.n)
    if not s.c.size:
        return np.array([mean, sigma]), []
    lc = np.log(s.c)

    def nll(free):
        mu, ls = float(free[0]), float(free[1])
        sig = math.exp(ls)
        with np.errstate(all="ignore"):
            z = (lc - mu) / sig
            lsf = log_ndtr(-z)
            dev2 = q0 + s.n * (mean - mu) ** 2
            ll = -s.n * ls - s.sum_log_x - s.n * _LOG_SQRT_2PI - dev2 / (2 * sig**2)
            ll += s.weight @ lsf
            hazard = s.weight * np.exp(-0.5 * z * z - _LOG_SQRT_2PI - lsf)  # phi / Phi(-z)
            g_mu = s.n * (mean - mu) / sig**2 + hazard.sum() / sig
            g_ls = -s.n + dev2 / sig**2 + hazard @ z
        return _finite(-ll / s.n_obs, -np.array([g_mu, g_ls]) / s.n_obs)

    start = np.array([mean, math.log(sigma)])
    free, trouble = newton(nll, start, [(-1e4, 1e4), (-700.0, 700.0)], "lognormal")
    return np.array([free[0], math.exp(free[1])]), trouble


# --- lomax -------------------------------------------------------------------------------


def _lomax_profile(eta, s, y, wy):
    """Profile log-likelihood of the Lomax at ``eta = 1/scale`` (shape maximised out),
    up to the constant ``n log n - n``; ``eta = 0`` is the exponential limit."""
    if eta == 0.0:
        return -s.n * math.log(wy @ y)
    l1p = np.log1p(eta * y)
    total = wy @ l1p
    return -s.n * math.log(total / eta) - l1p[: s.n].sum()


def fit_lomax(x, c):
    r"""Censored Lomax MLE ``(shape, scale)`` from its 1-D profile likelihood.

    At :math:`\eta = 1/s` the best shape is :math:`\hat\alpha = n / T(\eta)`,
    :math:`T = \sum_{all} \log(1 + \eta y)`, leaving

    .. math::

        \ell_p(\eta) = n \log n - n - n \log\frac{T(\eta)}{\eta}
                       - \sum_{complete} \log(1 + \eta x),

    continuous at :math:`\eta = 0` where it is the exponential's maximum. Its slope
    there is :math:`n \sum y^2 / (2 \sum y) - \sum x`: for data less dispersed than an
    exponential the supremum is this limit (shape and scale run off to infinity with
    ``shape / scale`` -> the exponential rate); then the point at
    ``eta = LOMAX_EDGE_ETA`` is returned, whose likelihood equals the limit's to
    ~1e-12 relative.
    """
    s = Sample.of(x, c)
    y = np.concatenate([s.x, s.c])
    wy = np.concatenate([np.ones(s.n), s.weight])
    if not np.all(np.isfinite(y)) or not (wy @ y) > 0:
        return np.array([np.nan, np.nan]), ["lomax: the data sum is not finite"]
    etas = np.concatenate([[0.0], 10.0**_LOMAX_GRID])
    prof = np.full(etas.size, -np.inf)
    below = 0
    with np.errstate(all="ignore"):
        for i, eta in enumerate(etas):
            prof[i] = _lomax_profile(eta, s, y, wy)
            # the profile falls (like -log log eta) for eta -> infinity: four decades
            # below the best so far end the scan
            below = below + 1 if prof[i] < np.max(prof[:i], initial=-np.inf) else 0
            if below == 4:
                break
    if not np.any(np.isfinite(prof)):
        return np.array([np.nan, np.nan]), ["lomax: the profile likelihood is not finite"]
    best = int(np.nanargmax(np.where(np.isfinite(prof), prof, -np.inf)))
    slope0 = s.n * (wy @ y**2) / (2.0 * (wy @ y)) - s.sum_x
    if best == 0 and not slope0 > 0:
        eta = LOMAX_EDGE_ETA
    else:
        if best == 0:
            lo, hi = math.log(LOMAX_EDGE_ETA), math.log(etas[1])
        else:
            lo = math.log(etas[best - 1]) if best > 1 else math.log(LOMAX_EDGE_ETA)
            hi = math.log(etas[min(best + 1, etas.size - 1)])
        with np.errstate(all="ignore"):
            res = optimize.minimize_scalar(
                lambda u: -_lomax_profile(math.exp(u), s, y, wy),
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": 1e-11, "maxiter": 500},
            )
        eta = math.exp(res.x)
        if -res.fun < prof[best]:  # Brent cannot do worse than the grid point
            eta = etas[best] if best > 0 else LOMAX_EDGE_ETA
    trouble = []
    if best == etas.size - 1:
        trouble.append("lomax: the scale ran below the search grid (shape -> 0)")
    with np.errstate(all="ignore"):
        total = wy @ np.log1p(eta * y)
    return np.array([s.n / total, 1.0 / eta]), trouble


def log_density_and_survival(model, theta, x, c):
    """``(log f(x), log S(c))`` in closed form for the scipy-family models and the
    exponential: the same formulas as scipy's ``_logpdf``/``_logsf`` (``xlogy`` for
    ``(shape - 1) log x``), without the frozen-distribution argument handling that
    dominated the cost on large samples; the gamma survival is log-safe
    (:func:`log_gammaincc`) where scipy's underflows to -inf."""
    x = np.asarray(x, dtype=float)
    c = np.asarray(c, dtype=float)
    # numpy scalars: wild parameters give inf/nan (checked by the callers), not errors
    t0, t1 = np.float64(theta[0]), np.float64(theta[-1])
    if model == "exponential":
        return np.log(t0) - t0 * x, -t0 * c
    if model == "gamma":
        z = x / t1
        return xlogy(t0 - 1.0, z) - z - gammaln(t0) - np.log(t1), log_gammaincc(t0, c / t1)
    if model == "weibull":
        z = x / t1
        return np.log(t0 / t1) + xlogy(t0 - 1.0, z) - z**t0, -((c / t1) ** t0)
    if model == "lognormal":
        lx = np.log(x)
        lx_pdf = -np.log(t1) - lx - _LOG_SQRT_2PI - 0.5 * ((lx - t0) / t1) ** 2
        return lx_pdf, log_ndtr(-(np.log(c) - t0) / t1)
    if model == "lomax":
        return np.log(t0 / t1) - (t0 + 1.0) * np.log1p(x / t1), -t0 * np.log1p(c / t1)
    raise ValueError(f"model {model!r} has no closed form here")


CLOSED_FORM_MODELS = ("exponential", "gamma", "weibull", "lognormal", "lomax")

FAST_FITS = {
    "gamma": fit_gamma,
    "weibull": fit_weibull,
    "lognormal": fit_lognormal,
    "lomax": fit_lomax,
}
