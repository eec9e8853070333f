r"""Monte Carlo goodness of fit for renewal fits, with and without censoring.

Three routes, chosen from the fit:

* **uncensored, full sample** (not a power law): :func:`scipy.stats.goodness_of_fit`
  with the location known (``loc = 0``; for the hyperexponential also ``scale = 1``)
  and the other parameters refitted to every Monte Carlo sample (Lilliefors-type);
* **censored, full sample**: a parametric bootstrap of the censored-likelihood fit;
* **tail fits** (``x_min``) and **power laws**: the same bootstrap on the tail; for a
  power law whose ``x_min`` was chosen by the CSN scan, the CSN semi-parametric
  bootstrap (body resampled from the data, tail from the fitted power law, ``x_min``
  re-chosen in every sample).

Statistic of the bootstrap routes: the Kolmogorov-Smirnov distance between the
Kaplan-Meier estimate (:func:`scipy.stats.ecdf` on :class:`scipy.stats.CensoredData`;
the empirical CDF when nothing is censored) and the fitted CDF (conditional on
``x >= x_min`` for tail fits), over the observed range.

Censoring model of the bootstrap (random censorship): each simulated interval ``X``
from the fit meets an independent censoring time ``C`` drawn from the reverse
Kaplan-Meier estimate of the censoring distribution (censored values as events,
complete values as censoring); the mass that estimate leaves beyond the largest
observation means "not censored". The sample keeps its size; ``min(X, C)`` is
recorded, censored when ``X > C``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from kicktimes._results import Result

from ._checks import check_choice, check_int, check_rng
from .distributions import hyperexpon
from .renewal import _TIME_POWER, PARAM_NAMES, RenewalFit, frozen_distribution, mle

_SCIPY_ROUTE = {
    "exponential": (stats.expon, lambda p: {"scale": 1.0 / p["rate"]}),
    "gamma": (stats.gamma, lambda p: {"a": p["shape"], "scale": p["scale"]}),
    "weibull": (stats.weibull_min, lambda p: {"c": p["shape"], "scale": p["scale"]}),
    "lognormal": (stats.lognorm, lambda p: {"s": p["sigma"], "scale": np.exp(p["mu"])}),
    "lomax": (stats.lomax, lambda p: {"c": p["shape"], "scale": p["scale"]}),
    "hyperexponential": (
        hyperexpon,
        lambda p: {"p": p["p"], "lam1": p["rate1"], "lam2": p["rate2"]},
    ),
}


@dataclass(frozen=True)
class GofResult(Result):
    """Result of :func:`goodness_of_fit`."""

    _title = "Goodness of fit of a renewal model (Monte Carlo p-value)"
    _summary_fields = ("statistic_name", "statistic", "pvalue", "method", "n_mc", "n_failed")

    statistic: float
    pvalue: float
    statistic_name: str
    method: str
    n_mc: int
    n_failed: int = 0
    null_distribution: np.ndarray = field(default=None, repr=False)


def km_ks(complete, censored, cdf) -> float:
    """sup |F_KM(t) - cdf(t)| over the observed range (both sides of each jump)."""
    if censored.size:
        res = stats.ecdf(stats.CensoredData(uncensored=complete, right=censored))
    else:
        res = stats.ecdf(complete)
    q, prob = res.cdf.quantiles, res.cdf.probabilities
    fitted = cdf(q)
    before = np.concatenate([[0.0], prob[:-1]])
    return float(max(np.abs(prob - fitted).max(), np.abs(before - fitted).max()))


def _km_sampler(values, events, *, conditional=False):
    """Inverse-transform sampler of a Kaplan-Meier law.

    The mass the estimate leaves beyond the last observation maps to ``inf``, or,
    with ``conditional``, is removed (draws conditional on a finite value).
    """
    if events.sum() == 0:
        return lambda u: np.full(u.shape, np.inf)
    res = stats.ecdf(stats.CensoredData(uncensored=values[events], right=values[~events]))
    q, prob = res.cdf.quantiles, res.cdf.probabilities
    top = prob[-1] if conditional else 1.0

    def draw(u):
        u = u * top
        idx = np.searchsorted(prob, u, side="left")
        out = np.full(u.shape, np.inf)
        ok = idx < q.size
        out[ok] = q[idx[ok]]
        return out

    return draw


def _censor(x_true, censoring_draw, rng):
    cens = censoring_draw(rng.uniform(size=x_true.size))
    is_cens = x_true > cens
    return x_true[~is_cens], cens[is_cens]


def _tail_cdf(fit_model, dist, x_min):
    if x_min is None or fit_model == "powerlaw":
        return dist.cdf
    s0 = dist.sf(x_min)
    return lambda t: 1.0 - dist.sf(t) / s0


def _bootstrap(fit: RenewalFit, n_mc: int, rng) -> GofResult:
    csn = fit.model == "powerlaw" and fit.x_min_method == "csn"
    if csn:
        x, c = fit.complete, fit.censored
    else:
        x, c = fit.sample
    values = np.concatenate([x, c])
    events = np.concatenate([np.ones(x.size, bool), np.zeros(c.size, bool)])
    censoring_draw = _km_sampler(values, ~events)
    xs, cs = fit.sample
    observed = km_ks(xs, cs, _tail_cdf(fit.model, fit.dist, fit.x_min))
    if csn:
        # CSN: tail from the fit with the Kaplan-Meier tail probability, body from
        # the Kaplan-Meier law below x_min.
        km = stats.ecdf(stats.CensoredData(uncensored=x, right=c) if c.size else x)
        p_tail = float(km.sf.evaluate(np.nextafter(fit.x_min, 0)))
        below = values < fit.x_min
        if not events[below].any():
            p_tail = 1.0  # nothing observed in the body: all draws come from the tail
        body_draw = _km_sampler(values[below], events[below], conditional=True)
    null, failed = [], 0
    for _ in range(n_mc):
        if csn:
            n_tail = rng.binomial(values.size, p_tail)
            body = body_draw(rng.uniform(size=values.size - n_tail))
            tail = fit.dist.ppf(rng.uniform(size=n_tail))
            x_true = np.concatenate([body, tail])
        elif fit.x_min is not None:
            s0 = fit.dist.sf(fit.x_min)
            x_true = fit.dist.isf(rng.uniform(size=values.size) * s0)
        else:
            x_true = fit.dist.rvs(size=values.size, random_state=rng)
        bx, bc = _censor(x_true, censoring_draw, rng)
        try:
            # Rescale as fit_renewal does, so the refit is as well conditioned.
            unit = (bx.sum() + bc.sum()) / (bx.size + bc.size)
            xm = None if (csn or fit.x_min is None) else fit.x_min / unit
            theta, extra = mle(fit.model, bx / unit, bc / unit, xm, **fit.scan)
        except (ValueError, RuntimeError, FloatingPointError):
            failed += 1
            continue
        if fit.model == "powerlaw":
            null.append(extra["ks"])
            continue
        dist = frozen_distribution(fit.model, _rescale(fit.model, theta, unit))
        xm = None if fit.x_min is None else fit.x_min
        keep_x = bx if xm is None else bx[bx >= xm]
        keep_c = bc if xm is None else bc[bc >= xm]
        null.append(km_ks(keep_x, keep_c, _tail_cdf(fit.model, dist, xm)))
    null = np.asarray(null)
    pvalue = (1 + np.count_nonzero(null >= observed)) / (null.size + 1)
    method = "CSN semi-parametric bootstrap" if csn else "parametric bootstrap (censored KM-KS)"
    return GofResult(observed, float(pvalue), "ks", method, n_mc, failed, null)


def _rescale(model, theta, unit):
    """Parameters fitted in units of ``unit`` back in the data's units."""
    out = np.array(theta, dtype=float)
    for i, name in enumerate(PARAM_NAMES[model]):
        out[i] *= unit ** _TIME_POWER.get(name, 0)
    if model == "lognormal":
        out[0] = theta[0] + np.log(unit)
    return out


def goodness_of_fit(fit, *, n_mc=999, statistic="ks", rng=None) -> GofResult:
    r"""Monte Carlo goodness-of-fit p-value of a renewal fit, censoring-aware.

    Parameters
    ----------
    fit : RenewalFit
        A result of :func:`fit_renewal`; its data are re-used.
    n_mc : int, optional
        Monte Carlo samples; each one is refitted, so the cost is ``n_mc`` fits.
    statistic : {"ks", "ad", "cvm"}, optional
        For uncensored full-sample fits, the EDF statistic passed to
        :func:`scipy.stats.goodness_of_fit`. Censored, tail and power-law fits use
        the Kaplan-Meier KS distance and accept only ``"ks"``.
    rng : Generator or int, optional
        Source of randomness.

    Returns
    -------
    GofResult
        ``statistic``, ``pvalue`` (``(1 + #{null >= observed}) / (1 + n_mc)``),
        ``method``, ``null_distribution`` and ``n_failed`` (bootstrap samples whose
        refit failed; they are left out).

    Notes
    -----
    The parameters are re-estimated in every Monte Carlo sample, so the p-value
    accounts for the fit (a plain KS p-value with estimated parameters is far too
    large). See the module notes for the censoring model of the bootstrap.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> x = np.random.default_rng(0).exponential(2.0, size=200)
    >>> res = stats.goodness_of_fit(stats.fit_renewal(x, "exponential"), n_mc=99, rng=1)
    >>> res.pvalue > 0.05
    True
    """
    if not isinstance(fit, RenewalFit):
        raise TypeError(f"fit must be a RenewalFit from fit_renewal, got {type(fit).__name__}")
    n_mc = check_int("n_mc", n_mc, low=1)
    check_choice("statistic", statistic, ("ks", "ad", "cvm"))
    rng = check_rng(rng)
    simple = fit.censored.size == 0 and fit.x_min is None and fit.model != "powerlaw"
    if not simple:
        if statistic != "ks":
            raise ValueError(
                f"statistic must be 'ks' for censored, tail or power-law fits, got {statistic!r}"
            )
        return _bootstrap(fit, n_mc, rng)
    family, guess = _SCIPY_ROUTE[fit.model]
    unit = float(fit.complete.mean())
    guessed = guess(fit.params)
    # EDF statistics are scale invariant: fit in units of the mean for conditioning.
    for key in ("scale",):
        if key in guessed:
            guessed[key] = guessed[key] / unit
    known = {"loc": 0.0}
    if fit.model == "hyperexponential":
        guessed = {
            "p": guessed["p"],
            "lam1": guessed["lam1"] * unit,
            "lam2": guessed["lam2"] * unit,
        }
        known["scale"] = 1.0
    res = stats.goodness_of_fit(
        family,
        fit.complete / unit,
        known_params=known,
        guessed_params=guessed,
        statistic=statistic,
        n_mc_samples=n_mc,
        rng=rng,
    )
    return GofResult(
        float(res.statistic),
        float(res.pvalue),
        statistic,
        "scipy.stats.goodness_of_fit",
        n_mc,
        0,
        np.asarray(res.null_distribution),
    )
