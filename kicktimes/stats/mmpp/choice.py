r"""Model choice for event times in windows: Poisson, renewal models and MMPPs on one
likelihood, and the bootstrap likelihood-ratio test of an MMPP against Poisson.

**One footing.** The renewal fits (:func:`~kicktimes.stats.fit_renewal` on
``intervals_from_times(..., first="drop")``) treat each window's right end exactly as
the MMPP does (the survival from the last event to ``t_max``), but leave out the time to
the first event, a forward recurrence time: their likelihood is that of the events after
each window's first event, given it. The MMPP's full likelihood also scores the first
event and the empty windows, so the two are not comparable as they stand.
:func:`compare_point_processes` therefore compares every model on the renewal models'
footing: the log-likelihood of each window's events after its first, given the first
event and the window's end,

.. math::

    \ell_{\text{cond}} = \sum_{w:\,N_w \ge 1} \big(\log L_w - \log p(t_{w,1})\big),

which for a renewal process is :math:`\sum \log f(x) + \sum \log S(c)` and for an MMPP
the full window likelihood divided by the density of its first event,
:math:`p(t_1) = \pi e^{D t_1} \lambda`. Each model is maximised on it: the renewal fits
as they are, the MMPP from its full-likelihood fit by L-BFGS-B on the exact gradient (two
forward-backward passes: Fisher's identity on all windows minus on the first events).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize

from kicktimes._results import Result

from .._checks import check_choice, check_int, check_rng
from ..comparison import compare_models
from ..poisson import intervals_from_times
from ..renewal import FULL_SAMPLE_MODELS, FitWarning
from . import _em as em
from .fit import MAX_STATES, MMPPFit, _fit, check_windows


def _conditional_loglik(rates, Q, data, first):
    """Conditional log-likelihood (fit units) and its gradient in ``(log rates, log q)``."""
    alpha = em.stationary_law(Q)
    full = em.estep(rates, Q, alpha, data)
    head = em.estep(rates, Q, alpha, first)
    value = full.loglik - head.loglik
    grad = (em.score(full, rates, Q, "stationary") - em.score(head, rates, Q, "stationary"))
    return value, grad


def _conditional_fit(fit: MMPPFit, data):
    """Maximise the conditional log-likelihood from ``fit``: ``(loglik, converged)`` in
    data units, over the windows with at least one event."""
    n = fit.n_states
    nonempty = data.subset(np.flatnonzero(data.n_events > 0))
    first = nonempty.first_events()
    off = ~np.eye(n, dtype=bool)
    u = data.unit
    theta0 = np.concatenate([np.log(fit.rates * u), np.log(np.clip(fit.generator[off] * u,
                                                                    em.Q_FLOOR, em.Q_CAP))])
    lo = np.concatenate([np.full(n, math.log(em.RATE_FLOOR)), np.full(n * n - n,
                                                                       math.log(em.Q_FLOOR))])
    hi = np.concatenate([np.full(n, 50.0), np.full(n * n - n, math.log(em.Q_CAP))])

    def objective(theta):
        theta = np.clip(theta, lo, hi)
        rates = np.exp(theta[:n])
        Q = em._generator_of(np.ascontiguousarray(theta[n:]), n)
        value, grad = _conditional_loglik(rates, Q, nonempty, first)
        return -value, -grad

    start = objective(theta0)[0]
    res = optimize.minimize(objective, theta0, jac=True, method="L-BFGS-B",
                            bounds=list(zip(lo, hi, strict=True)),
                            options={"maxiter": 200, "ftol": 1e-13, "gtol": 1e-6})
    best = min(float(res.fun), start)
    shift = (nonempty.n_events.sum() - nonempty.n_windows) * math.log(u)
    return -best - shift, bool(res.success) or best < start


def compare_point_processes(times, t_max, *, models=None, n_states=(2,), n_starts=12,
                            rng=None, return_fits=False):
    r"""Rank Poisson, renewal and MMPP models of event times in windows by AIC, on one
    likelihood.

    Parameters
    ----------
    times : array_like or list of array_like
        Event times of one window or of several, as in :func:`fit_mmpp`.
    t_max : float or sequence of float
        Window lengths (the right ends censored).
    models : sequence of str, optional
        Renewal models (``FULL_SAMPLE_MODELS`` by default; ``"exponential"`` is the
        Poisson process and shows as the row ``"poisson"``). ``[]`` for none but Poisson.
    n_states : sequence of int, optional
        MMPPs to fit (2 to 4 states; row ``"mmpp<n>"``).
    n_starts : int, optional
        EM starts of each MMPP fit.
    rng : Generator or int, optional
        Randomness of the MMPP starts.
    return_fits : bool, optional
        Also return the MMPP fits behind the rows (their full-likelihood fits, as
        :func:`fit_mmpp` gives them but without standard errors), so that their
        parameters need no second fit.

    Returns
    -------
    pandas.DataFrame
        Indexed by model, sorted by AIC: ``family`` (poisson, renewal, mmpp),
        ``loglik`` (the conditional log-likelihood, see the module notes), ``k``,
        ``aic``, ``bic``, ``delta_aic``, ``weight`` (Akaike weight), ``delta_bic``,
        ``converged`` and ``note``. ``attrs``: ``footing``, ``n_windows`` (with at least
        one event), ``n`` (events after each window's first, plus one censored end per
        window: the BIC's sample size).
    fits : dict of MMPPFit
        With ``return_fits``: ``{"mmpp<n>": fit}`` for every MMPP that could be fitted.

    Notes
    -----
    :math:`\mathrm{AIC} = 2k - 2\ell_{\text{cond}}`, :math:`\mathrm{BIC} = k \log n - 2
    \ell_{\text{cond}}`. An MMPP with ``n`` states has :math:`k = n^2` parameters.
    AIC's penalty is calibrated for regular models; an MMPP against the Poisson
    process is not one (when the rates are equal the switching rates are not
    identified), so AIC prefers a 2-state MMPP on Poisson data more often than a
    regular 3-parameter extension would: use :func:`mmpp_lr_test` for a calibrated
    answer.

    Examples
    --------
    Switching between a slow and a fast rate is not a renewal process:

    >>> from kicktimes import stats
    >>> slow_fast = dict(rates=[0.5, 5.0], generator=[[-0.1, 0.1], [0.3, -0.3]])
    >>> windows = [stats.simulate_mmpp(**slow_fast, t_max=60.0, rng=k) for k in range(100)]
    >>> stats.compare_point_processes(windows, 60.0, rng=2).index[0]
    'mmpp2'
    """
    seqs, lengths = check_windows(times, t_max)
    if models is None:
        models = FULL_SAMPLE_MODELS
    for m in [models] if isinstance(models, str) else models:
        check_choice("models", m, FULL_SAMPLE_MODELS)
    renewal = [m for m in dict.fromkeys([models] if isinstance(models, str) else models)
               if m != "exponential"]
    sizes = [check_int("n_states", k, low=2, high=MAX_STATES) for k in np.atleast_1d(n_states)]
    rng = check_rng(rng)
    data = em.Windows.of(seqs, lengths)
    iv = intervals_from_times(seqs, lengths, first="drop")
    complete, censored = iv.complete, iv.censored
    n_obs = complete.size + censored.size
    if complete.size < 1:
        raise ValueError("times: the comparison needs at least one window with two events "
                         "(it scores the events after each window's first)")
    rows = []
    with warnings.catch_warnings():
        # an unconverged renewal fit is flagged in its row and named in one warning below
        warnings.simplefilter("ignore", FitWarning)
        table = compare_models(complete, censored=censored, models=["exponential", *renewal])
    for model, row in table.iterrows():
        rows.append({"model": "poisson" if model == "exponential" else model,
                     "family": "poisson" if model == "exponential" else "renewal",
                     "loglik": row["loglik"], "k": row["k"], "converged": row["converged"],
                     "note": row["note"]})
    fits = {}
    for k in sizes:
        row = {"model": f"mmpp{k}", "family": "mmpp", "k": k * k}
        try:
            fit = _fit(data, k, n_starts=n_starts, rng=rng, covariance=False)
        except ValueError as exc:
            rows.append({**row, "loglik": np.nan, "converged": False, "note": str(exc)})
            continue
        fits[row["model"]] = fit
        loglik, ok = _conditional_fit(fit, data)
        rows.append({**row, "loglik": loglik, "converged": fit.converged and ok,
                     "note": "; ".join(fit.warnings)})
    out = pd.DataFrame(rows).set_index("model")
    out["aic"] = 2 * out["k"] - 2 * out["loglik"]
    out["bic"] = out["k"] * math.log(n_obs) - 2 * out["loglik"]
    out["delta_aic"] = out["aic"] - out["aic"].min()
    rel = np.exp(-0.5 * out["delta_aic"])
    out["weight"] = rel / rel.sum()
    out["delta_bic"] = out["bic"] - out["bic"].min()
    out = out[["family", "loglik", "k", "aic", "bic", "delta_aic", "weight", "delta_bic",
               "converged", "note"]].sort_values("aic", na_position="last")
    bad = [m for m, ok in out["converged"].items() if not ok]
    if bad:
        warnings.warn(f"compare_point_processes: these fits did not converge (rows flagged "
                      f"converged=False): {', '.join(bad)}", FitWarning, stacklevel=2)
    out.attrs.update(footing="conditional on each window's first event",
                     n_windows=int((data.n_events > 0).sum()), n=int(n_obs))
    return (out, fits) if return_fits else out


@dataclass(frozen=True)
class MMPPLRTest(Result):
    """Parametric-bootstrap likelihood-ratio test of an MMPP against Poisson (result of
    :func:`mmpp_lr_test`): ``statistic = 2 (loglik_mmpp - loglik_poisson)``, ``pvalue =
    (1 + #{null >= statistic}) / (1 + n_boot)``."""

    _title = "Parametric-bootstrap likelihood-ratio test of an MMPP against Poisson"
    _summary_fields = ("n_states", "statistic", "pvalue", "n_boot")

    statistic: float
    pvalue: float
    null_statistics: np.ndarray = field(repr=False)
    n_boot: int
    n_states: int
    poisson: MMPPFit = field(repr=False)
    mmpp: MMPPFit = field(repr=False)

    def _summary_extra(self) -> list[str]:
        return [f"log-likelihood: Poisson {self.poisson.loglik:.6g}, {self.n_states}-state MMPP "
                f"{self.mmpp.loglik:.6g}"]


def mmpp_lr_test(times, t_max, *, n_states=2, n_boot=99, n_starts=12, rng=None):
    r"""Is an MMPP needed? The likelihood-ratio test against the homogeneous Poisson
    process, calibrated by a parametric bootstrap given the number of events.

    Parameters
    ----------
    times, t_max :
        Event times in windows, as in :func:`fit_mmpp`.
    n_states : int, optional
        States of the alternative (2 to 4).
    n_boot : int, optional
        Bootstrap samples (>= 1); the p-value's resolution is ``1 / (n_boot + 1)``.
    n_starts : int, optional
        EM starts of every MMPP fit, the data's and each sample's alike: the search of
        :func:`fit_mmpp` (every start run to convergence), so that the statistic of the
        data and its null distribution come from the same maximisation.
    rng : Generator or int, optional

    Returns
    -------
    MMPPLRTest

    Notes
    -----
    :math:`LR = 2(\hat\ell_{\text{MMPP}} - \hat\ell_{\text{Poisson}})` on the full
    likelihood of the windows. Under the null the MMPP's rates coincide and its switching
    rates are not identified: the parameter lies on the boundary and the :math:`\chi^2`
    reference of Wilks' theorem does not hold. Each bootstrap sample draws a Poisson
    process in windows of the data's lengths given the data's total number of events
    (multinomial counts in proportion to the lengths, uniform times), and both models
    are refitted as for the data. The total count is sufficient for the Poisson rate, so
    the samples do not depend on it: the p-value is exact up to its Monte Carlo
    resolution (a Monte Carlo test conditional on the number of events, like the
    Poisson battery's).

    Examples
    --------
    Poisson windows (a 2-state MMPP with equal rates):

    >>> from kicktimes import stats
    >>> times = stats.simulate_mmpp([1.0, 1.0], [[-1, 1], [1, -1]], 50.0, n_windows=20, rng=0)
    >>> res = stats.mmpp_lr_test(times, 50.0, n_boot=19, n_starts=2, rng=1)
    >>> 0 < res.pvalue <= 1
    True
    """
    n = check_int("n_states", n_states, low=2, high=MAX_STATES)
    n_boot = check_int("n_boot", n_boot, low=1)
    n_starts = check_int("n_starts", n_starts, low=1)
    rng = check_rng(rng)
    seqs, lengths = check_windows(times, t_max)

    def statistic(data):
        null = _fit(data, 1)
        alt = _fit(data, n, n_starts=n_starts, rng=rng, covariance=False)
        return max(2.0 * (alt.loglik - null.loglik), 0.0), null, alt

    stat, null, alt = statistic(em.Windows.of(seqs, lengths))
    share = lengths / lengths.sum()
    sims = np.empty(n_boot)
    for b in range(n_boot):
        counts = rng.multinomial(null.n_events, share)
        sample = [np.sort(rng.uniform(0.0, w, c)) for w, c in zip(lengths, counts, strict=True)]
        try:
            sims[b] = statistic(em.Windows.of(sample, lengths))[0]
        except ValueError:  # fewer events than MMPP parameters: no evidence against Poisson
            sims[b] = 0.0
    pvalue = (1 + np.count_nonzero(sims >= stat - 1e-9 * max(1.0, stat))) / (1 + n_boot)
    return MMPPLRTest(float(stat), float(pvalue), sims, n_boot, n, null, alt)
