r"""Renewal-model fits to right-censored inter-event intervals.

A renewal process is described by the law of its intervals. The models (``MODELS``)
and their parameters, in the units of the data:

==================  =======================  ==========================================
model               ``params``               frozen ``dist``
==================  =======================  ==========================================
exponential         rate                     ``expon(scale=1/rate)`` (Poisson process)
gamma               shape, scale             ``gamma(shape, scale=scale)``
weibull             shape, scale             ``weibull_min(shape, scale=scale)``
lognormal           mu, sigma                ``lognorm(sigma, scale=exp(mu))``
lomax               shape, scale             ``lomax(shape, scale=scale)`` (Pareto II)
hyperexponential    p, rate1, rate2          ``hyperexpon(p, rate1, rate2)``
powerlaw            alpha, x_min             ``pareto(alpha - 1, scale=x_min)``
==================  =======================  ==========================================

Every fit maximises the censored log-likelihood

.. math::

    \ell(\theta) = \sum_{i \in \text{complete}} \log f(x_i; \theta)
                 + \sum_{j \in \text{censored}} \log S(c_j; \theta)
                 \; [\, - (n + n_c) \log S(x_{min}; \theta) \,],

the bracket applying to tail fits (left-truncated at ``x_min``). The power law is
only defined above ``x_min``, so it is a tail fit by construction and its likelihood
is comparable only with other tail fits (see :func:`compare_models`).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats
from scipy.special import expit, logit
from statsmodels.tools.numdiff import approx_hess

from kicktimes._results import nan_reason

from ._checks import check_choice, check_int, check_intervals, check_real
from ._information import inverse_information
from ._renewal_mle import CLOSED_FORM_MODELS, FAST_FITS, log_density_and_survival
from .distributions import (
    _fit_hyperexponential_reference,
    _log_components,
    fit_hyperexponential,
    hyperexpon,
)
from .powerlaw import fit_powerlaw_tail


class FitWarning(RuntimeWarning):
    """A fit that did not converge, overflowed, or has unavailable standard errors.

    The result carries the same news: ``converged`` is False and ``warnings`` says why.
    """


MODELS = ("exponential", "gamma", "weibull", "lognormal", "lomax", "hyperexponential", "powerlaw")
FULL_SAMPLE_MODELS = MODELS[:-1]
PARAM_NAMES = {
    "exponential": ("rate",),
    "gamma": ("shape", "scale"),
    "weibull": ("shape", "scale"),
    "lognormal": ("mu", "sigma"),
    "lomax": ("shape", "scale"),
    "hyperexponential": ("p", "rate1", "rate2"),
    "powerlaw": ("alpha",),
}
_SCIPY_FAMILY = {
    "gamma": stats.gamma,
    "weibull": stats.weibull_min,
    "lognormal": stats.lognorm,
    "lomax": stats.lomax,
}
# Exponent e of the time unit in each parameter: measured in units of s, a parameter
# becomes theta * s**e (mu, a log-time, shifts by log s instead).
_TIME_POWER = {"rate": -1, "rate1": -1, "rate2": -1, "scale": 1}
_HYPER_FIT = {"fast": fit_hyperexponential, "scipy": _fit_hyperexponential_reference}
_MIN_COMPLETE = {"exponential": 1, "hyperexponential": 5}
# In units of the mean observation a sane estimate is far inside these bounds; beyond
# them the likelihood has no interior maximum (e.g. Lomax on exponential data, whose
# shape and scale run off to infinity together).
_DIVERGED = (1e-10, 1e10)
# messages of scipy/numpy warnings that mean "the optimiser gave up"
_NOT_CONVERGED = ("converge", "maximum number", "iterations", "precision loss")
#: Smallest supported interval length, the smallest normal float. Fits run in units of the
#: mean interval; for subnormal lengths that mean underflows (to 0 for 5e-324) and a rate,
#: its reciprocal, overflows.
INTERVAL_FLOOR = float(np.finfo(float).tiny)


def frozen_distribution(model: str, theta, x_min: float | None = None):
    """The frozen scipy distribution of ``model`` at natural parameters ``theta``."""
    t = [float(v) for v in theta]
    if model == "exponential":
        return stats.expon(scale=1.0 / t[0])
    if model == "gamma":
        return stats.gamma(t[0], scale=t[1])
    if model == "weibull":
        return stats.weibull_min(t[0], scale=t[1])
    if model == "lognormal":
        return stats.lognorm(t[1], scale=math.exp(t[0]))
    if model == "lomax":
        return stats.lomax(t[0], scale=t[1])
    if model == "hyperexponential":
        return hyperexpon(t[0], t[1], t[2])
    return stats.pareto(t[0] - 1.0, scale=x_min)


def pointwise_loglik(model, theta, complete, censored, x_min=None):
    """Per-observation log-likelihood terms: ``log f`` (complete), ``log S`` (censored),
    each minus ``log S(x_min)`` for tail fits."""
    if model == "powerlaw":
        # closed form in logs: scipy's pareto.logpdf underflows to -inf at x ~ 1e300
        b, lxm = float(theta[0]) - 1.0, math.log(x_min)
        with np.errstate(all="ignore"):
            lx = math.log(b) - lxm - (b + 1.0) * (np.log(complete) - lxm)
            lc = -b * (np.log(censored) - lxm)
        return np.asarray(lx, dtype=float), np.asarray(lc, dtype=float)
    with np.errstate(all="ignore"):
        if model in CLOSED_FORM_MODELS:
            lx, lc = log_density_and_survival(model, theta, complete, censored)
            shift = (
                None if x_min is None else log_density_and_survival(model, theta, [], [x_min])[1][0]
            )
        elif model == "hyperexponential":
            p, lam1, lam2 = (float(v) for v in theta)
            lx = np.logaddexp(*_log_components(complete, p, lam1, lam2, density=True))
            lc = np.logaddexp(*_log_components(censored, p, lam1, lam2, density=False))
            shift = None
            if x_min is not None:
                shift = np.logaddexp(*_log_components(x_min, p, lam1, lam2, density=False))
        if shift is not None:
            lx, lc = lx - shift, lc - shift
    return np.asarray(lx, dtype=float), np.asarray(lc, dtype=float)


def _total_loglik(model, theta, x, c, x_min):
    lx, lc = pointwise_loglik(model, theta, x, c, x_min)
    total = lx.sum() + lc.sum()
    return total if np.isfinite(total) else -np.inf


# Unconstrained coordinates for direct optimisation (tail fits, fallbacks).
def _to_free(model, theta):
    if model == "lognormal":
        return np.array([theta[0], math.log(theta[1])])
    if model == "hyperexponential":
        return np.array([logit(theta[0]), math.log(theta[1]), math.log(theta[2])])
    return np.log(np.asarray(theta, dtype=float))


def _from_free(model, free):
    if model == "lognormal":
        return np.array([free[0], math.exp(free[1])])
    if model == "hyperexponential":
        return np.array([expit(free[0]), math.exp(free[1]), math.exp(free[2])])
    return np.exp(free)


def _optimizer_trouble(caught) -> list[str]:
    """The caught warnings that say an optimiser stopped before converging."""
    return sorted(
        {
            str(w.message).splitlines()[0]
            for w in caught
            if any(key in str(w.message).lower() for key in _NOT_CONVERGED)
        }
    )


def _scipy_fit(model, x, c, trouble=None):
    """scipy's own (censored) MLE with the location fixed at 0; optimiser complaints go
    to ``trouble`` (a list) instead of the console."""
    data = stats.CensoredData(uncensored=x, right=c) if c.size else x
    with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
        warnings.simplefilter("always")
        est = _SCIPY_FAMILY[model].fit(data, floc=0)
    if trouble is not None:
        trouble.extend(f"scipy: {m}" for m in _optimizer_trouble(caught))
    shape, scale = float(est[0]), float(est[-1])
    return np.array([math.log(scale), shape]) if model == "lognormal" else np.array([shape, scale])


def _direct_fit(model, x, c, x_min, start, trouble=None):
    """Nelder-Mead on unconstrained coordinates; used for tail fits and as a fallback."""

    def nll(free):
        with np.errstate(all="ignore"):
            theta = _from_free(model, free)
            return -_total_loglik(model, theta, x, c, x_min) / (x.size + c.size)

    with np.errstate(all="ignore"):  # inf - inf among simplex values on wild data
        res = optimize.minimize(
            nll,
            _to_free(model, start),
            method="Nelder-Mead",
            options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 4000, "maxfev": 8000},
        )
    if trouble is not None and not res.success:
        trouble.append(f"Nelder-Mead: {res.message}")
    return _from_free(model, res.x)


def mle(model, x, c, x_min=None, *, min_tail=50, max_candidates=500, engine="fast"):
    """Maximum-likelihood parameters of ``model`` (numbers in the units of the data).

    Returns ``(theta, extra)``; ``extra`` holds the tail bookkeeping of power-law fits.
    ``engine="scipy"`` fits gamma, Weibull, lognormal and Lomax with the former
    ``scipy.stats.<dist>.fit`` path instead of the dedicated optimisers, and the
    hyperexponential with the former EM (kept as the reference of the tests and
    benchmarks).
    """
    extra: dict = {"trouble": []}
    trouble = extra["trouble"]
    if model == "powerlaw":
        res = fit_powerlaw_tail(x, c, x_min=x_min, min_tail=min_tail, max_candidates=max_candidates)
        extra.update(res)
        return np.array([res["alpha"]]), extra
    if x_min is not None:
        # Only the tail is modelled; the rest of the sample is left out.
        x, c = x[x >= x_min], c[c >= x_min]
        if model == "exponential":
            # Memoryless: the excess over x_min is exponential with the same rate.
            return np.array([x.size / ((x - x_min).sum() + (c - x_min).sum())]), extra
        if model == "hyperexponential":
            # The excess over x_min is again hyperexponential, with the weight of the
            # fast component discounted by exp(-(rate1 - rate2) x_min).
            p, lam1, lam2, _ = _HYPER_FIT[engine](x - x_min, c - x_min)
            odds = math.exp(min(math.log(p / (1 - p)) + (lam1 - lam2) * x_min, 700.0))
            return np.array([odds / (1 + odds), lam1, lam2]), extra
        start, _ = mle(model, x, c, engine=engine)
        return _direct_fit(model, x, c, x_min, start, trouble), extra
    if model == "exponential":
        return np.array([x.size / (x.sum() + c.sum())]), extra
    if model == "hyperexponential":
        return np.array(_HYPER_FIT[engine](x, c)[:3]), extra
    if engine == "fast":
        try:
            with np.errstate(all="ignore"):  # wild data: non-finite values are checked below
                theta, trouble_fast = FAST_FITS[model](x, c)
        except (ValueError, OverflowError, ZeroDivisionError, FloatingPointError) as exc:
            theta, trouble_fast = np.full(2, np.nan), [f"{model}: {exc}"]
        ok = np.all(np.isfinite(theta)) and np.isfinite(_total_loglik(model, theta, x, c, None))
        if ok and not trouble_fast:
            return theta, extra
        # the dedicated optimiser failed: polish (or start afresh) with Nelder-Mead
        return _fallback(model, x, c, theta if ok else None, trouble_fast, trouble), extra
    scipy_trouble: list[str] = []
    try:
        theta = _scipy_fit(model, x, c, scipy_trouble)
        ok = np.all(np.isfinite(theta)) and np.isfinite(_total_loglik(model, theta, x, c, None))
    except (ValueError, RuntimeError, FloatingPointError, OverflowError):
        ok = False  # scipy's solver gave up (e.g. "function value at x=inf is NaN")
    if not ok or scipy_trouble:
        theta = _fallback(model, x, c, theta if ok else None, scipy_trouble, trouble)
    return theta, extra


def _fallback(model, x, c, theta, theta_trouble, trouble):
    """Nelder-Mead from a default start when the first optimiser failed; the better of
    the two answers wins, with its own complaints appended to ``trouble``."""
    mean = (x.sum() + c.sum()) / x.size
    start = {"lognormal": [math.log(mean), 1.0]}.get(model, [1.0, mean])
    direct_trouble: list[str] = []
    direct = _direct_fit(model, x, c, None, np.array(start, dtype=float), direct_trouble)
    if theta is None or _total_loglik(model, direct, x, c, None) > _total_loglik(
        model, theta, x, c, None
    ):
        theta, theta_trouble = direct, direct_trouble
    trouble.extend(theta_trouble)
    return theta


def _covariance(model, theta, x, c, x_min, n_tail):
    """Inverse observed information in the natural parameters (NaN if singular)."""
    if model == "exponential" and x_min is None:
        return np.array([[theta[0] ** 2 / x.size]])
    if model == "powerlaw":
        return np.array([[(theta[0] - 1.0) ** 2 / n_tail]])

    def nll(t):
        if model == "hyperexponential" and not 0.0 < t[0] < 1.0:
            return np.nan
        if np.any(np.asarray(t)[1 if model == "lognormal" else 0 :] <= 0):
            return np.nan
        return -_total_loglik(model, t, x, c, x_min)

    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hess = approx_hess(np.asarray(theta, dtype=float), nll)
    # identified or not is decided on the unit-diagonal information, not by whether a
    # BLAS kernel's Cholesky happens to succeed near a singularity
    return inverse_information(hess)[0]


@dataclass(frozen=True, eq=False, repr=False)
class RenewalFit:
    """A fitted renewal model (result of :func:`fit_renewal`).

    Attributes
    ----------
    model : str
        One of ``MODELS``.
    params, stderr : dict
        Estimates and standard errors (square roots of the diagonal of the inverse
        observed information; NaN where the information is singular, e.g. at a
        boundary, and for ``x_min``, which is selected, not estimated smoothly).
    loglik : float
        Maximised censored log-likelihood (of the tail for tail fits).
    k : int
        Number of free parameters (``x_min`` is not counted).
    n, n_censored : int
        Complete and censored intervals that entered the likelihood.
    dist : scipy.stats frozen distribution
        The fitted interval law (untruncated parent for tail fits).
    x_min : float or None
        Threshold of a tail fit; ``n_excluded`` observations lay below it.
    complete, censored : ndarray
        The data as given (all of it, also for tail fits; see :attr:`sample`).
    scan : dict
        ``min_tail`` and ``max_candidates`` of the power-law threshold scan.
    converged : bool
        False when the optimiser gave up or the likelihood or an estimate is not
        finite; the numbers are then not an MLE. An estimate that runs off to 0 or
        infinity (the supremum is a limiting case, e.g. Lomax on exponential data)
        keeps ``converged`` True and is named in ``warnings``.
    warnings : tuple of str
        Every problem of the fit (also unavailable standard errors); each was issued
        as a `FitWarning` by :func:`fit_renewal`.
    """

    model: str
    params: dict
    stderr: dict
    loglik: float
    k: int
    n: int
    n_censored: int
    x_min: float | None = None
    x_min_method: str | None = None
    n_excluded: int = 0
    covariance: np.ndarray = field(default=None)
    complete: np.ndarray = field(default=None)
    censored: np.ndarray = field(default=None)
    scan: dict = field(default_factory=dict)
    converged: bool = True
    warnings: tuple = ()

    @functools.cached_property
    def dist(self):
        """The fitted interval law, a frozen scipy distribution (the untruncated parent
        for tail fits). Built on first use: freezing a scipy distribution costs about a
        millisecond, more than many fits, and model comparison never needs it."""
        return frozen_distribution(self.model, self.theta, self.x_min)

    @property
    def reason(self) -> str | None:
        """Why an estimate or a standard error of the free parameters is NaN (the fit's
        `warnings`), None when all are finite (``x_min``'s standard error, NaN by
        design, does not count)."""
        names = PARAM_NAMES[self.model]
        return nan_reason([*(self.params[n] for n in names), *(self.stderr[n] for n in names)],
                          self.warnings)

    @property
    def aic(self) -> float:
        """Akaike information criterion ``2k - 2 loglik``."""
        return 2 * self.k - 2 * self.loglik

    @property
    def bic(self) -> float:
        """Bayesian information criterion ``k log(n + n_censored) - 2 loglik``."""
        return self.k * math.log(self.n + self.n_censored) - 2 * self.loglik

    @property
    def theta(self) -> np.ndarray:
        """The free parameters in ``PARAM_NAMES[model]`` order."""
        return np.array([self.params[name] for name in PARAM_NAMES[self.model]])

    @property
    def sample(self) -> tuple[np.ndarray, np.ndarray]:
        """The ``(complete, censored)`` intervals that entered the likelihood
        (those at or above ``x_min`` for tail fits)."""
        if self.x_min is None:
            return self.complete, self.censored
        return self.complete[self.complete >= self.x_min], self.censored[
            self.censored >= self.x_min
        ]

    def pointwise_loglik(self, complete=None, censored=None):
        """Log-likelihood contributions ``(log f(x_i), log S(c_j))``, tail-conditional
        for tail fits; defaults to :attr:`sample`. Given data are used as they are."""
        x, c = self.sample
        x = x if complete is None else np.asarray(complete, dtype=float)
        c = c if censored is None else np.asarray(censored, dtype=float)
        return pointwise_loglik(self.model, self.theta, x, c, self.x_min)

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={v:.6g}" for k, v in self.params.items())
        flag = "" if self.converged else ", converged=False"
        return (
            f"RenewalFit(model={self.model!r}, {shown}, loglik={self.loglik:.6g}, "
            f"aic={self.aic:.6g}, n={self.n}, n_censored={self.n_censored}{flag})"
        )

    def summary(self) -> str:
        """A readable table of the fit."""
        lines = [f"Renewal fit: {self.model} (censored maximum likelihood)"]
        obs = f"  intervals: {self.n} complete, {self.n_censored} right-censored"
        if self.x_min is not None:
            how = {"csn": "chosen by KS (Clauset-Shalizi-Newman)", "fixed": "given"}
            obs += (
                f"; tail x >= x_min = {self.x_min:.6g} ({how.get(self.x_min_method, 'given')}),"
                f" {self.n_excluded} below left out"
            )
        lines.append(obs)
        lines.append(
            f"  log-likelihood {self.loglik:.6g}   AIC {self.aic:.6g}   BIC {self.bic:.6g}"
            f"   (k = {self.k})"
        )
        lines.append(f"  {'parameter':<10} {'estimate':>14} {'std. err.':>14}")
        for name, value in self.params.items():
            lines.append(f"  {name:<10} {value:>14.6g} {self.stderr[name]:>14.6g}")
        if self.x_min is None:
            mean = float(self.dist.mean())
            lines.append(f"  mean interval {mean:.6g}   (rate {1 / mean:.6g})")
        if not self.converged:
            lines.append("  NOT CONVERGED: the numbers above are not a maximum-likelihood fit")
        lines.extend(f"  warning: {w}" for w in self.warnings)
        return "\n".join(lines)


def check_sample(intervals, censored):
    """Validated ``(complete, censored)`` arrays: lengths at least `INTERVAL_FLOOR`
    (censored ones may be 0)."""
    x = check_intervals("intervals", intervals, allow_empty=False, floor=INTERVAL_FLOOR)
    c = (np.empty(0) if censored is None
         else check_intervals("censored", censored, allow_zero=True, floor=INTERVAL_FLOOR))
    return x, c


def fit_renewal(intervals, model, *, censored=None, x_min=None, min_tail=50, max_candidates=500):
    r"""Fit a renewal (interval) model by censored maximum likelihood.

    Parameters
    ----------
    intervals : array_like
        Complete inter-event intervals, finite and at least ``2.2250738585072014e-308``
        (the smallest normal float; change the time unit for smaller lengths).
    model : str
        One of ``MODELS``: ``"exponential"``, ``"gamma"``, ``"weibull"``,
        ``"lognormal"``, ``"lomax"``, ``"hyperexponential"``, ``"powerlaw"``.
    censored : array_like, optional
        Right-censored intervals (e.g. ``T - t_last``): the interval exceeds the value;
        0 or at least ``2.2250738585072014e-308``.
    x_min : float, optional
        Fit only the tail ``x >= x_min``, conditionally on exceeding ``x_min``
        (left-truncated likelihood). For ``"powerlaw"``, ``None`` chooses ``x_min``
        by the Clauset-Shalizi-Newman KS criterion.
    min_tail, max_candidates : int
        Bounds of the power-law ``x_min`` scan (minimum complete intervals in the
        tail, maximum number of thresholds tried).

    Returns
    -------
    RenewalFit
        ``params``, ``stderr``, ``loglik``, ``aic``, ``bic``, ``n``, ``n_censored``,
        ``dist`` (frozen scipy distribution), ``converged``, ``warnings`` and
        ``summary()``.

    Raises
    ------
    ValueError
        Bad input (naming the argument; subnormal interval lengths included), too few
        intervals for the model, or degenerate data: all complete intervals equal, which
        only the exponential model can fit (the others' likelihood grows without bound),
        or, for the exponential, hyperexponential and power-law tails, no interval that
        exceeds a given ``x_min`` (in the fit's units: the mean interval).

    Warns
    -----
    FitWarning
        The fit did not converge or overflowed (``converged`` is False), an estimate
        ran off to the edge of the parameter space, or standard errors are
        unavailable (``warnings`` says which); never a silent NaN or -inf.

    Notes
    -----
    Likelihood:
    :math:`\ell = \sum \log f(x_i) + \sum \log S(c_j)` (minus
    :math:`(n + n_c)\log S(x_{min})` for tail fits). Each model has a dedicated
    optimiser, with the complete-data part of the likelihood in sufficient statistics
    (:math:`n, \sum x, \sum\log x`) and the censored terms over the distinct
    censored values:

    * exponential: closed form :math:`\hat\lambda = n / (\sum x + \sum c)`;
    * gamma: uncensored, the profile equation
      :math:`\log a - \psi(a) = \log\bar x - \overline{\log x}` (Newton);
      censored, damped Newton on :math:`(\log a, \log s)` with
      :math:`\log Q(a, c/s)` computed log-safely (continued fraction where
      ``gammaincc`` underflows);
    * Weibull: the 1-D profile in the shape, :math:`\lambda^k = \sum y^k / n` over
      all observations, whose score equation has a unique root (safeguarded Newton);
    * lognormal: closed form uncensored; censored, damped Newton on
      :math:`(\mu, \log\sigma)` with ``log_ndtr`` survival terms;
    * Lomax: the 1-D profile in :math:`\eta = 1/\text{scale}` (the shape is
      :math:`n / \sum\log(1 + \eta y)`), grid plus bounded Brent;
      :math:`\eta \to 0` is the exponential limit, returned as a point at
      :math:`\eta = 10^{-12}` (flagged: the estimates run off to infinity) whose
      likelihood equals the exponential's;
    * hyperexponential: multi-start EM on a subsample, then Newton with the analytic
      Hessian on all the data;
    * power law: closed form above ``x_min``.

    When a dedicated optimiser fails (no convergence, a non-finite likelihood, a
    bound of its search box) Nelder-Mead from a default start takes over and the
    better of the two is kept; tail fits maximise the truncated likelihood by
    Nelder-Mead from the full-sample fit of the tail. Computations run in units of
    the mean observation, so the parameters are well scaled whatever the time unit.
    Standard errors come from the inverse of the numerical Hessian
    (``statsmodels.tools.numdiff.approx_hess``) of the negative log-likelihood in the
    natural parameters.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> x = np.random.default_rng(1).weibull(0.7, size=500)
    >>> fit = stats.fit_renewal(x[x < 3], "weibull", censored=np.full((x >= 3).sum(), 3.0))
    >>> round(fit.params["shape"], 1)
    0.7
    """
    check_choice("model", model, MODELS)
    x, c = check_sample(intervals, censored)
    min_tail = check_int("min_tail", min_tail, low=2)
    max_candidates = check_int("max_candidates", max_candidates, low=1)
    if x_min is not None:
        x_min = check_real("x_min", x_min, low=0.0)
    fit = _fit(x, c, model, x_min, min_tail=min_tail, max_candidates=max_candidates)
    if fit.warnings:
        status = "" if fit.converged else "did not converge: "
        warnings.warn(
            f"fit_renewal(model={model!r}): {status}{'; '.join(fit.warnings)}",
            FitWarning,
            stacklevel=2,
        )
    return fit


def _fit(x, c, model, x_min, *, min_tail=50, max_candidates=500, covariance=True, engine="fast"):
    """fit_renewal on validated arrays; ``covariance=False`` skips the Hessian
    (model comparison needs only the likelihood); ``engine`` as in :func:`mle`."""
    need = _MIN_COMPLETE.get(model, 3)
    n_used = x.size if x_min is None else int((x >= x_min).sum())
    if model != "powerlaw" and n_used < need:
        raise ValueError(
            f"intervals: model {model!r} needs at least {need} complete intervals"
            + ("" if x_min is None else f" at or above x_min={x_min!r}")
            + f", got {n_used}"
        )
    used = x if x_min is None else x[x >= x_min]
    if model != "exponential" and used.size and used.min() == used.max():
        # a shape parameter would run off to infinity (or sigma to 0): no MLE exists
        where = "" if x_min is None else f" at or above x_min={x_min!r}"
        raise ValueError(
            f"intervals: all {used.size} complete intervals{where} equal "
            f"{float(used[0])!r}; model {model!r} needs at least two distinct values "
            "(only 'exponential' fits constant intervals)"
        )
    # Work in units of the mean observation; convert back at the end. Summing x / n
    # rather than x keeps the mean finite for intervals near the float maximum; a unit of
    # at least INTERVAL_FLOOR keeps its reciprocal (rates) finite (a mean below it takes
    # many censored zeros: complete intervals are at least INTERVAL_FLOOR).
    n_all = x.size + c.size
    unit = max(float((x / n_all).sum() + (c / n_all).sum()), INTERVAL_FLOOR)
    xs, cs = x / unit, c / unit
    xm = None if x_min is None else x_min / unit
    if xm is not None and model == "powerlaw" and xm < INTERVAL_FLOOR:
        # the power law takes log(x_min) in these units: a "math domain error" once x_min
        # underflowed to 0 (intervals spanning more than the float range)
        raise ValueError(
            f"x_min must be at least {INTERVAL_FLOOR!r} times the mean interval {unit!r} "
            f"for the power law (the fits run in units of the mean), got {x_min!r}"
        )
    if xm is not None and model in ("exponential", "hyperexponential", "powerlaw"):
        # these fit the excess over x_min (the power law its logarithm); with none the
        # rate is infinite (1 / 0: a ZeroDivisionError in the hyperexponential's start)
        tail_x, tail_c = xs[xs >= xm], cs[cs >= xm]
        if not (tail_x - xm).sum() + (tail_c - xm).sum() > 0.0:
            raise ValueError(
                f"intervals: the {tail_x.size} complete and {tail_c.size} censored intervals "
                f"at or above x_min={x_min!r} exceed it by nothing (to float precision in "
                f"units of the mean interval, {unit!r}); model {model!r} fits the excess "
                "over x_min and needs some"
            )
    theta, extra = mle(
        model, xs, cs, xm, min_tail=min_tail, max_candidates=max_candidates, engine=engine
    )
    if model == "powerlaw":
        xm = extra["x_min"]
    # Tail masks: a given x_min applies in the data's units (as RenewalFit.sample
    # does); the CSN threshold is taken in the scaled units the scan used, and is then
    # reported as the data value it came from.
    if xm is None:
        keep_x, keep_c = np.ones(x.size, bool), np.ones(c.size, bool)
    elif x_min is not None:
        keep_x, keep_c = x >= x_min, c >= x_min
    else:
        keep_x, keep_c = xs >= xm, cs >= xm
    xt, ct = xs[keep_x], cs[keep_c]
    if covariance:
        cov = _covariance(model, theta, xt, ct, xm, extra.get("n_tail"))
    else:
        cov = np.full((len(theta), len(theta)), np.nan)
    names = PARAM_NAMES[model]
    factor = np.array([unit ** _TIME_POWER.get(name, 0) for name in names], dtype=float)
    with np.errstate(over="ignore"):  # an overflow shows as inf and is flagged below
        theta_out = theta * factor
    if model == "lognormal":
        theta_out[0] = theta[0] + math.log(unit)
    with np.errstate(over="ignore", invalid="ignore"):
        stderr_values = np.sqrt(np.where(np.diag(cov) >= 0, np.diag(cov), np.nan)) * factor
        cov = cov * np.outer(factor, factor)
    if xm is None:
        x_min_out = None
    elif x_min is not None:
        x_min_out = float(x_min)
    else:
        x_min_out = float(x[keep_x].min())  # CSN picks a data value: report it exactly
    loglik = _total_loglik(model, theta_out, x[keep_x], c[keep_c], x_min_out)
    if not np.isfinite(loglik):
        # parameters that overflow in the data's units (e.g. a Lomax scale of 1e12 means
        # of 1e300, the exponential limit) but not in the fit's: the scaled likelihood,
        # whose density terms differ from the data's by the Jacobian log(unit) each
        loglik = _total_loglik(model, theta, xt, ct, xm) - xt.size * math.log(unit)
    params = {n: float(v) for n, v in zip(names, theta_out, strict=True)}
    stderr = {n: float(v) for n, v in zip(names, stderr_values, strict=True)}
    problems = list(dict.fromkeys(extra.get("trouble", [])))
    converged = not problems
    scaled = [v for n, v in zip(names, theta, strict=True) if n not in ("mu", "p")]
    if not np.all(np.isfinite(theta_out)):
        problems.append("parameters are not finite")
        converged = False
    elif any(not _DIVERGED[0] < abs(v) < _DIVERGED[1] for v in scaled):
        shown = ", ".join(f"{n}={v:.3g}" for n, v in params.items())
        # the likelihood's supremum lies on the edge of the parameter space (e.g. Lomax
        # -> exponential): the fitted law is usable, its parameters individually are not
        problems.append(
            f"an estimate ran off to 0 or infinity ({shown}): the likelihood has no "
            "interior maximum for these data (a limiting case of the model fits best)"
        )
    if not np.isfinite(loglik):
        problems.append(f"the log-likelihood is not finite ({loglik})")
        converged = False
    if covariance:
        bad = [n for n, v in stderr.items() if not np.isfinite(v)]
        if bad:
            problems.append(
                f"standard errors of {', '.join(bad)} unavailable: the observed information "
                "is singular or overflows (an estimate at a boundary, or parameters not "
                "identified)"
            )
    if model == "powerlaw":
        params["x_min"], stderr["x_min"] = float(x_min_out), math.nan
    n_tail = int(xt.size)
    return RenewalFit(
        model=model,
        params=params,
        stderr=stderr,
        loglik=float(loglik),
        k=len(names),
        n=n_tail,
        n_censored=int(ct.size),
        x_min=x_min_out,
        x_min_method=None if x_min_out is None else extra.get("method", "fixed"),
        n_excluded=int(x.size + c.size - xt.size - ct.size),
        covariance=cov,
        complete=x,
        censored=c,
        scan={"min_tail": min_tail, "max_candidates": max_candidates},
        converged=converged,
        warnings=tuple(problems),
    )
