r"""Escape times: survival with censoring, and the law of its tail.

A run that escapes through a hole in the table (``run.escape_time``) gives an event time;
one that does not by its end is right-censored there. The survival function
:math:`S(t) = P(T > t)` is the Kaplan–Meier estimate with pointwise 95 % intervals on the
log-log scale (statsmodels' `SurvfuncRight`), and its tail is compared between the two
laws that open billiards show: an exponential tail :math:`S(t) \propto e^{-\gamma t}`
(chaotic or randomly perturbed motion) and the algebraic tail of the circle,
:math:`S(t) \propto t^{-\alpha}` with :math:`\alpha = 1` for the integrable circle
(Bunimovich & Dettmann, Phys. Rev. Lett. 94, 100201 (2005)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes._results import Result
from kicktimes.validation import keyword_only_after

from ._checks import check_real

__all__ = ["MIN_AT_RISK", "EscapeTail", "circle_escape_constant", "escape_survival",
           "fit_escape_tail", "reliable_until"]

#: the fewest runs at risk of a Kaplan-Meier step read as measured: beyond, each step is
#: made by a handful of runs (for the two disks: where disk 1's escapes have censored
#: most of disk 0's runs), and the figures draw it thin and grey, without its band
MIN_AT_RISK = 50


def _censored(escape_times, t_max):
    """Observed times (escape, or the horizon) and the escape flags."""
    if isinstance(escape_times, str | bytes):
        raise TypeError("escape_times must be an array of numbers")
    t = np.asarray(escape_times, dtype=np.float64).ravel()
    if t.size == 0:
        raise ValueError("escape_times must not be empty")
    if np.isnan(t).any() or (t <= 0).any():
        raise ValueError("escape_times must be positive (inf: no escape by t_max)")
    horizon = np.broadcast_to(np.asarray(t_max, dtype=float), t.shape)
    if not np.isfinite(horizon).all() or (horizon <= 0).any():
        raise ValueError("t_max must be positive and finite (the runs' horizons)")
    if (t[np.isfinite(t)] > horizon[np.isfinite(t)]).any():
        raise ValueError("escape_times must not exceed t_max")
    escaped = np.isfinite(t)
    return np.where(escaped, t, horizon), escaped


def escape_survival(escape_times, t_max) -> pd.DataFrame:
    """Kaplan–Meier survival of escape times, censored at each run's horizon.

    Parameters
    ----------
    escape_times : array_like
        Per run the escape time, ``inf`` for a run that did not escape.
    t_max : float or array_like
        The runs' horizons (one, or one per run).

    Returns
    -------
    pandas.DataFrame
        ``time, survival, ci_low, ci_high, n_at_risk`` at each escape time (pointwise
        95 % intervals, log-log transform).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.random.default_rng(0).exponential(2.0, 500)
    >>> t[t > 5.0] = np.inf
    >>> km = escape_survival(t, 5.0)
    >>> bool(abs(km.loc[km.time <= 2.0, "survival"].iloc[-1] - np.exp(-1.0)) < 0.05)
    True
    """
    import statsmodels.api as sm

    time, escaped = _censored(escape_times, t_max)
    if not escaped.any():
        return pd.DataFrame(columns=["time", "survival", "ci_low", "ci_high", "n_at_risk"])
    sf = sm.SurvfuncRight(time, escaped.astype(float))
    s, se = sf.surv_prob, sf.surv_prob_se
    with np.errstate(divide="ignore", invalid="ignore"):
        # log-log interval: exp(-exp(log(-log s) +- z se / (s log s)))
        z = 1.959963984540054
        ll = np.log(-np.log(s))
        half = z * se / np.abs(s * np.log(s))
        lo = np.exp(-np.exp(ll + half))
        hi = np.exp(-np.exp(ll - half))
    lo = np.where(np.isfinite(lo), lo, 0.0)
    hi = np.where(np.isfinite(hi), hi, 1.0)
    return pd.DataFrame({"time": sf.surv_times, "survival": s, "ci_low": lo, "ci_high": hi,
                         "n_at_risk": sf.n_risk})


@keyword_only_after(1, since="0.2.0")
def reliable_until(km, *, floor=MIN_AT_RISK) -> float:
    """The first time of a Kaplan-Meier table (`escape_survival`) at which fewer than
    ``floor`` runs are at risk (inf: never): the curve is read as measured before it.

    Parameters
    ----------
    km : pandas.DataFrame
        ``time, n_at_risk`` (as `escape_survival` gives them), in time order.
    floor : int
        The fewest runs at risk of a step read as measured (default `MIN_AT_RISK`).

    Returns
    -------
    float

    Examples
    --------
    >>> import pandas as pd
    >>> reliable_until(pd.DataFrame({"time": [1.0, 2.0, 3.0], "n_at_risk": [80, 50, 49]}))
    3.0
    """
    if isinstance(floor, bool) or not isinstance(floor, int) or floor < 1:
        raise ValueError(f"floor must be a positive integer, got {floor!r}")
    below = km.loc[km["n_at_risk"] < floor, "time"]
    return float(below.iloc[0]) if len(below) else float("inf")


@dataclass(frozen=True)
class EscapeTail(Result):
    """Result of `fit_escape_tail`: the two tail laws fitted beyond ``t_min``.

    Attributes
    ----------
    t_min : float
    n_tail, n_escaped : int
        Runs alive at ``t_min``; of them, escaped by their horizon.
    rate, rate_ci : float, tuple
        Exponential tail: the escape rate :math:`\\gamma` and its 95 % interval.
    alpha, alpha_ci : float, tuple
        Algebraic tail :math:`S \\propto t^{-\\alpha}`: the exponent and its 95 % interval.
    aic_exponential, aic_algebraic : float
    best : str
        ``"exponential"`` or ``"algebraic"`` (lower AIC; both have one parameter).
    """

    _title = "Tail of the escape times beyond t_min: exponential against algebraic"
    _intervals = {"rate": "rate_ci", "alpha": "alpha_ci"}

    t_min: float
    n_tail: int
    n_escaped: int
    rate: float
    rate_ci: tuple
    alpha: float
    alpha_ci: tuple
    aic_exponential: float
    aic_algebraic: float
    best: str


def fit_escape_tail(escape_times, t_max, *, t_min) -> EscapeTail:
    r"""Exponential against algebraic tail of the escape times beyond ``t_min``.

    Conditionally on survival to ``t_min``, censored maximum likelihood: exponential,
    :math:`S(t)/S(t_{\min}) = e^{-\gamma (t - t_{\min})}`, gives
    :math:`\hat\gamma = d / \sum (t_i - t_{\min})`; algebraic (Pareto),
    :math:`S(t)/S(t_{\min}) = (t/t_{\min})^{-\alpha}`, gives
    :math:`\hat\alpha = d / \sum \log(t_i / t_{\min})`, with ``d`` the escapes and the sums
    over the runs alive at ``t_min`` (escape or censoring times). Both intervals are the
    exact chi-square intervals of a rate with ``d`` events (:math:`\chi^2_{2d}` and
    :math:`\chi^2_{2d+2}` quantiles over twice the exposure).

    Parameters
    ----------
    escape_times : array_like
        Per run the escape time, ``inf`` without escape.
    t_max : float or array_like
        The runs' horizons.
    t_min : float
        Where the tail starts (``> 0``, below the horizons).

    Returns
    -------
    EscapeTail
    """
    from scipy import stats as sps

    time, escaped = _censored(escape_times, t_max)
    t_min = check_real("t_min", t_min, low=0.0)
    alive = time > t_min
    if not alive.any():
        raise ValueError(f"t_min={t_min!r}: no run is alive beyond it; choose a smaller t_min")
    t, e = time[alive], escaped[alive]
    d = int(e.sum())
    expo_exposure = float(np.sum(t - t_min))
    log_exposure = float(np.sum(np.log(t / t_min)))

    def rate_ci(exposure):
        lo = sps.chi2.ppf(0.025, 2 * d) / (2 * exposure) if d > 0 else 0.0
        hi = sps.chi2.ppf(0.975, 2 * d + 2) / (2 * exposure)
        return float(lo), float(hi)

    rate = d / expo_exposure
    alpha = d / log_exposure
    # log-likelihoods (the constant sum of log t over escapes kept in the algebraic one)
    ll_exp = d * math.log(rate) - rate * expo_exposure if d else 0.0
    ll_alg = (d * math.log(alpha) - alpha * log_exposure - float(np.sum(np.log(t[e])))
              if d else 0.0)
    aic_e, aic_a = 2 - 2 * ll_exp, 2 - 2 * ll_alg
    return EscapeTail(t_min=float(t_min), n_tail=int(alive.sum()), n_escaped=d, rate=rate,
                      rate_ci=rate_ci(expo_exposure), alpha=alpha,
                      alpha_ci=rate_ci(log_exposure), aic_exponential=aic_e,
                      aic_algebraic=aic_a,
                      best="exponential" if aic_e <= aic_a else "algebraic")


def circle_escape_constant(half_width, *, radius=1.0, speed=1.0) -> float:
    r"""The constant :math:`C` of the circle's algebraic escape, :math:`S(t) \sim C/t`.

    A point particle in a circle of radius :math:`R` at speed :math:`v`, started from the
    Liouville measure of the flow (position uniform in the disk, direction uniform), with
    one hole: the arc of half-width :math:`h` (radians) of the wall. Following Bunimovich
    & Dettmann's argument, write :math:`\omega \in (0, 2\pi)` for the angle the bounce
    point advances per chord, of length :math:`2R\sin(\omega/2)`; the flow measure gives
    :math:`\omega` the density :math:`\sin^2(\omega/2)/\pi`. At long times only
    :math:`\omega` near :math:`2\pi p/q` survive: the :math:`q` bounce points drift by
    :math:`\delta = \omega - 2\pi p/q` per chord and stay out of the hole for
    :math:`N` chords on a fraction :math:`(2\pi/q - 2h - N|\delta|)_+ \, q/2\pi` of the
    first bounce points. Integrating over :math:`\delta` with :math:`N = t v / (2R\sin(\pi
    p/q))` and summing over :math:`p/q` in lowest terms,

    .. math::

        C = \frac{4R}{\pi^2 v} \sum_{2 \le q < \pi/h} q \left(\frac{\pi}{q} - h\right)^2
            \sum_{\substack{1 \le p < q \\ \gcd(p, q) = 1}} \sin^3\frac{\pi p}{q} .

    The sum is finite: orbits whose :math:`q` bounce points are closer than the hole's
    width all escape.

    For a disk of radius :math:`r` in the unit table, whose contact point lies at the
    angle of its centre, pass ``radius=1 - r``. With a distribution of speeds,
    :math:`S(t) \sim C(v{=}1)\, E[1/v]/t`.

    Parameters
    ----------
    half_width : float
        The hole's half-width in radians, in (0, π).
    radius, speed : float
        The circle the centre moves on, and the speed (both > 0).

    Returns
    -------
    float
        :math:`C`, in units of time.

    References
    ----------
    L. A. Bunimovich and C. P. Dettmann, "Open circular billiards and the Riemann
    hypothesis", Phys. Rev. Lett. 94, 100201 (2005).

    Examples
    --------
    >>> from kicktimes.stats import circle_escape_constant
    >>> round(circle_escape_constant(0.25), 4)
    3.99
    >>> round(circle_escape_constant(0.05, radius=0.99), 3)   # a disk of radius 0.01
    21.333
    """
    h = check_real("half_width", half_width, low=0.0, high=math.pi)
    radius = check_real("radius", radius, low=0.0)
    speed = check_real("speed", speed, low=0.0)
    total = 0.0
    q = 2
    while math.pi / q > h:
        p = np.arange(1, q)
        coprime = p[np.gcd(p, q) == 1]
        total += q * (math.pi / q - h) ** 2 * float(np.sum(np.sin(math.pi * coprime / q) ** 3))
        q += 1
    return 4.0 * radius * total / (math.pi ** 2 * speed)
