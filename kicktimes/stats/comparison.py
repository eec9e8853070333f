r"""Model comparison: AIC/BIC tables with Akaike weights, and Vuong's test.

Full-sample models and the power-law tail do not share a likelihood: the power law
only describes ``x >= x_min``. Comparisons are therefore made on one footing:

* without ``x_min`` and without ``"powerlaw"`` among the models, every model is
  fitted to the whole sample (the default);
* with ``"powerlaw"`` requested or ``x_min`` given, every model is fitted to the
  tail ``x >= x_min`` conditionally on exceeding it (left-truncated likelihood),
  with ``x_min`` chosen by the power-law fit (CSN) unless given. This is the
  comparison Clauset, Shalizi & Newman make.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from kicktimes._results import Result

from ._checks import check_choice, check_int, check_real, check_rng
from .renewal import FULL_SAMPLE_MODELS, MODELS, FitWarning, _fit, check_sample

# (nested, nesting): the first is a limit or special case of the second, where
# Vuong's normal null does not hold if the smaller model is true.
_NESTED = {
    ("exponential", "gamma"),
    ("exponential", "weibull"),
    ("exponential", "lomax"),
    ("exponential", "hyperexponential"),
}


def _check_models(models, x_min):
    if models is None:
        return list(FULL_SAMPLE_MODELS if x_min is None else MODELS)
    if isinstance(models, str):
        models = [models]
    models = list(models)
    if not models:
        raise ValueError("models must name at least one model, got an empty list")
    for m in models:
        check_choice("models", m, MODELS)
    if len(set(models)) != len(models):
        raise ValueError(f"models must not repeat a model, got {models!r}")
    return models


def _tail_threshold(x, c, models, x_min, min_tail):
    """The common ``x_min`` of a tail comparison, or None for a full-sample one."""
    if x_min is not None:
        x_min = check_real("x_min", x_min, low=0.0)
        if not x_min < x.max():
            raise ValueError(
                f"x_min must lie below the largest complete interval, in (0.0, "
                f"{float(x.max())!r}), got {x_min!r}: no complete interval would exceed it"
            )
        return x_min
    if "powerlaw" in models:
        return _fit(x, c, "powerlaw", None, min_tail=min_tail, covariance=False).x_min
    return None


def compare_models(
    intervals, *, censored=None, models=None, x_min=None, gof=False, n_mc=199, min_tail=50, rng=None
):
    r"""Fit several renewal models and rank them by AIC.

    Parameters
    ----------
    intervals : array_like
        Complete intervals (positive).
    censored : array_like, optional
        Right-censored intervals.
    models : sequence of str, optional
        Models to compare (default: every full-sample model, i.e. ``MODELS``
        without ``"powerlaw"``; with ``x_min`` given, all of ``MODELS``).
    x_min : float, optional
        Compare on the tail ``x >= x_min`` (see the module notes); it must lie below the
        largest complete interval. If ``"powerlaw"`` is among ``models`` and ``x_min``
        is None, the power law's CSN threshold is used for every model.
    gof : bool, optional
        Add a ``gof_pvalue`` column from :func:`goodness_of_fit` with ``n_mc``
        Monte Carlo samples (this refits each model ``n_mc`` times).
    min_tail : int, optional
        Minimum complete intervals in the power-law tail (CSN scan).
    rng : Generator or int, optional
        Randomness for the goodness-of-fit Monte Carlo.

    Returns
    -------
    pandas.DataFrame
        Indexed by model, sorted by AIC, with columns ``loglik``, ``k``, ``aic``,
        ``bic``, ``delta_aic``, ``weight`` (Akaike weight), ``delta_bic``, ``n``,
        ``n_censored``, ``gof_pvalue`` (if asked), ``converged`` (False: the fit did
        not converge, see `RenewalFit.converged`; its row is still shown) and ``note``
        (why a model could not be fitted, or what went wrong). The models with a finite
        AIC are compared: their weights sum to 1. A model that could not be fitted (too
        few intervals, degenerate data, a likelihood that is not finite) is left out of
        the comparison: NaN ``aic``, ``bic``, deltas and ``weight``, and its ``note``
        says why. ``attrs`` holds ``x_min`` and ``footing`` (``"full sample"`` or
        ``"tail"``).

    Raises
    ------
    ValueError
        Bad input (naming the argument: e.g. subnormal interval lengths, an ``x_min``
        not below the largest complete interval), or no model could be fitted (the
        message gives each model's reason).

    Warns
    -----
    FitWarning
        One warning naming the models whose fit did not converge (their rows still
        take part in the comparison when their AIC is finite).

    Notes
    -----
    :math:`\mathrm{AIC} = 2k - 2\ell`, :math:`\mathrm{BIC} = k\log N - 2\ell` (N the
    number of complete plus censored intervals used), Akaike weights
    :math:`w_m = e^{-\Delta_m/2} / \sum_j e^{-\Delta_j/2}` with
    :math:`\Delta_m = \mathrm{AIC}_m - \min \mathrm{AIC}`, over the fitted models.
    Every fit runs in units of the mean interval, so the table does not depend on the
    time unit (a parameter that overflows in the data's units keeps the likelihood of
    the scaled fit).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> x = np.random.default_rng(0).gamma(0.5, 2.0, size=800)
    >>> stats.compare_models(x).index[0] in ("gamma", "weibull", "hyperexponential")
    True
    """
    from .gof import goodness_of_fit

    x, c = check_sample(intervals, censored)
    models = _check_models(models, x_min)
    min_tail = check_int("min_tail", min_tail, low=2)
    threshold = _tail_threshold(x, c, models, x_min, min_tail)
    if gof:
        n_mc = check_int("n_mc", n_mc, low=1)
        rng = check_rng(rng)
    rows = []
    unconverged = []
    for m in models:
        row = {"model": m, "note": "", "converged": False}
        try:
            fit = _fit(x, c, m, threshold, min_tail=min_tail, covariance=False)
        except ValueError as exc:
            row.update(loglik=np.nan, k=np.nan, aic=np.nan, bic=np.nan, n=np.nan)
            row.update(n_censored=np.nan, note=str(exc))
            rows.append(row)
            continue
        row.update(loglik=fit.loglik, k=fit.k, aic=fit.aic, bic=fit.bic, n=fit.n)
        row["n_censored"] = fit.n_censored
        row["converged"] = fit.converged
        if fit.warnings:
            row["note"] = "; ".join(fit.warnings)
        if not fit.converged:
            unconverged.append(f"{m} ({fit.warnings[0]})")
        if gof:
            row["gof_pvalue"] = goodness_of_fit(fit, n_mc=n_mc, rng=rng).pvalue
        rows.append(row)
    table = pd.DataFrame(rows).set_index("model")
    # Compared are the fits with a finite AIC; a failed one (refused, or a likelihood that
    # is not finite) has NaN AIC, BIC, deltas and weight, and its note says why.
    fitted = np.isfinite(table["aic"].to_numpy(float))
    if not fitted.any():
        reasons = "; ".join(f"{m}: {note}" for m, note in table["note"].items())
        raise ValueError(f"intervals: none of the models could be fitted ({reasons})")
    table.loc[~fitted, ["aic", "bic"]] = np.nan
    table["delta_aic"] = table["aic"] - table["aic"].min()
    rel = np.exp(-0.5 * table["delta_aic"])
    table["weight"] = rel / rel.sum()
    table["delta_bic"] = table["bic"] - table["bic"].min()
    cols = ["loglik", "k", "aic", "bic", "delta_aic", "weight", "delta_bic", "n", "n_censored"]
    cols += ["gof_pvalue"] if gof else []
    table = table[[*cols, "converged", "note"]].sort_values("aic", na_position="last")
    if unconverged:
        warnings.warn(
            "compare_models: these fits did not converge (their rows are flagged "
            f"converged=False): {'; '.join(unconverged)}",
            FitWarning,
            stacklevel=2,
        )
    table.attrs["x_min"] = threshold
    table.attrs["footing"] = "full sample" if threshold is None else "tail"
    return table


@dataclass(frozen=True)
class VuongResult(Result):
    """Vuong's non-nested likelihood-ratio test (result of :func:`vuong`).

    ``statistic > 0`` favours ``model1``; ``preferred`` is the favoured model when
    ``pvalue < alpha`` and None otherwise.
    """

    _title = "Vuong's likelihood-ratio test of two renewal models (statistic > 0 favours model1)"
    _summary_fields = ("model1", "model2", "statistic", "pvalue", "preferred", "loglik_ratio",
                       "n", "correction", "x_min", "note")

    statistic: float
    pvalue: float
    preferred: str | None
    model1: str
    model2: str
    loglik_ratio: float
    n: int
    correction: str | None
    x_min: float | None
    note: str = ""


def vuong(intervals, model1, model2, *, censored=None, x_min=None, correction=None, alpha=0.05):
    r"""Vuong's test between two (non-nested) renewal models.

    Parameters
    ----------
    intervals : array_like
        Complete intervals.
    model1, model2 : str
        Models from ``MODELS`` (different).
    censored : array_like, optional
        Right-censored intervals (they contribute :math:`\log S(c)`).
    x_min : float, optional
        Compare on the tail ``x >= x_min`` (below the largest complete interval); forced
        (CSN threshold) when either model is ``"powerlaw"``.
    correction : {None, "aic", "bic"}, optional
        Penalise the log-likelihood ratio for the difference in parameter counts:
        ``LR - (k1 - k2)`` or ``LR - (k1 - k2) log(N) / 2``.
    alpha : float, optional
        Level at which ``preferred`` is named.

    Returns
    -------
    VuongResult

    Notes
    -----
    With :math:`m_i = \ell_1(y_i) - \ell_2(y_i)` the pointwise log-likelihood
    differences (complete: log densities; censored: log survival functions),

    .. math::

        z = \frac{\sum_i m_i - \text{penalty}}{\sqrt{N}\, \hat\omega},
        \qquad \hat\omega^2 = \frac{1}{N} \sum_i (m_i - \bar m)^2,

    and the two-sided p-value is :math:`2\Phi(-|z|)`. The test is antisymmetric:
    swapping the models negates ``z`` and keeps ``pvalue`` and ``preferred``. For
    nested pairs (exponential inside gamma, Weibull, Lomax, hyperexponential) the
    normal null fails when the smaller model is true; ``note`` says so.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> x = np.random.default_rng(0).lognormal(0.0, 1.0, size=2000)
    >>> stats.vuong(x, "lognormal", "weibull").preferred
    'lognormal'
    """
    check_choice("model1", model1, MODELS)
    check_choice("model2", model2, MODELS)
    if model1 == model2:
        raise ValueError(f"model1 and model2 must differ, got {model1!r} twice")
    if correction is not None:
        check_choice("correction", correction, ("aic", "bic"))
    alpha = check_real("alpha", alpha, low=0.0, high=1.0)
    x, c = check_sample(intervals, censored)
    threshold = _tail_threshold(x, c, [model1, model2], x_min, 50)
    fit1 = _fit(x, c, model1, threshold, covariance=False)
    fit2 = _fit(x, c, model2, threshold, covariance=False)
    failed = [f"{f.model}: {f.warnings[0]}" for f in (fit1, fit2) if not f.converged]
    if failed:
        warnings.warn(
            f"vuong: fit did not converge ({'; '.join(failed)}); the test compares "
            "non-maximised likelihoods",
            FitWarning,
            stacklevel=2,
        )
    m = np.concatenate(fit1.pointwise_loglik()) - np.concatenate(fit2.pointwise_loglik())
    n = m.size
    ratio = float(m.sum())
    penalty = {None: 0.0, "aic": fit1.k - fit2.k, "bic": (fit1.k - fit2.k) * math.log(n) / 2}
    omega = float(m.std())
    note = ""
    if (model1, model2) in _NESTED or (model2, model1) in _NESTED:
        note = "nested models: the normal null of Vuong's statistic needs the larger model"
    if failed:
        note = "; ".join([note, *(f"not converged: {f}" for f in failed)]).lstrip("; ")
    if not np.all(np.isfinite(m)):
        raise ValueError(
            f"intervals: some interval has zero likelihood under {model1!r} or {model2!r}; "
            "Vuong's test needs both fits to give every interval a positive density"
        )
    if omega <= 1e-12 * max(1.0, abs(m).max()):
        z, p, note = 0.0, 1.0, "the two fits are pointwise identical"
    else:
        z = (ratio - penalty[correction]) / (math.sqrt(n) * omega)
        p = float(2 * stats.norm.sf(abs(z)))
    preferred = None
    if p < alpha:
        preferred = model1 if z > 0 else model2
    return VuongResult(
        statistic=float(z),
        pvalue=p,
        preferred=preferred,
        model1=model1,
        model2=model2,
        loglik_ratio=ratio,
        n=n,
        correction=correction,
        x_min=threshold,
        note=note,
    )
