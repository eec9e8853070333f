r"""Processes whose rate is redrawn at every event: the interval law they imply, and
simulated event times.

If after event ``k`` the rate is a constant :math:`\Gamma_k` until the next event, the
interval that follows is :math:`\text{Exp}(\Gamma_k)` and the intervals pooled over many
events follow the mixture :math:`S(t) = \text{mean}_k\, e^{-\Gamma_k t}`
(:func:`rate_mixture`); the event times are a Cox process driven by the sequence of
rates (:func:`simulate_cox_times`). Rates are plain numbers here; where they come from
(the angular momenta after each disk-disk collision) is the diagnostics layer's concern.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kicktimes._results import Result

from ._checks import as_1d_float, check_choice, check_real, check_rng

__all__ = ["RateMixture", "rate_mixture", "simulate_cox_times"]


@dataclass(frozen=True, repr=False)
class RateMixture(Result):
    """The mixture of exponential laws with ``rates`` and ``weights`` (summing to 1).

    Built by :func:`rate_mixture`; ``sf``, ``pdf``, ``hazard`` take times in the rates'
    inverse unit.
    """

    _title = "Mixture of exponential interval laws (rate redrawn after every event)"
    _summary_fields = ("rates", "weights")

    rates: np.ndarray
    weights: np.ndarray

    def _summary_extra(self) -> list[str]:
        return [f"mean rate: {float(self.weights @ self.rates):.6g}",
                f"mean interval: {self.mean():.6g}"]

    def sf(self, t) -> np.ndarray:
        """Survival function ``sum_k w_k exp(-rate_k t)``."""
        t = np.asarray(t, float)
        return np.exp(-np.multiply.outer(t, self.rates)) @ self.weights

    def pdf(self, t) -> np.ndarray:
        """Density ``sum_k w_k rate_k exp(-rate_k t)``."""
        t = np.asarray(t, float)
        return np.exp(-np.multiply.outer(t, self.rates)) @ (self.weights * self.rates)

    def hazard(self, t) -> np.ndarray:
        """Hazard ``pdf / sf``: the mean rate of the states that have not yet fired."""
        return self.pdf(t) / self.sf(t)

    def mean(self) -> float:
        """Mean interval ``sum_k w_k / rate_k``."""
        return float(self.weights @ (1.0 / self.rates))

    def __repr__(self) -> str:
        return (f"RateMixture(n_rates={self.rates.size}, mean_rate="
                f"{float(self.weights @ self.rates):.4g}, mean_interval={self.mean():.4g})")


def rate_mixture(rates, *, weights=None) -> RateMixture:
    r"""The interval law of events whose rate is redrawn after every event.

    Parameters
    ----------
    rates : array_like
        Positive rates, one per state (e.g. one per event: the rate that holds after it).
    weights : array_like, optional
        Non-negative weights of the states (default equal); they are normalised.

    Returns
    -------
    RateMixture
        With ``sf``, ``pdf``, ``hazard`` and ``mean``.

    Notes
    -----
    With weights :math:`w_k` the survival function is
    :math:`S(t) = \sum_k w_k e^{-\Gamma_k t}`, and the hazard
    :math:`h(t) = \sum_k w_k \Gamma_k e^{-\Gamma_k t} / S(t)` is the mean rate under the
    weights tilted by survival. It starts at the mean rate and falls, with
    :math:`h'(t) = -\mathrm{Var}_t(\Gamma) \le 0`: any spread of rates gives a decreasing
    hazard and a coefficient of variation of the intervals above 1. A hyperexponential
    law is the two-state case.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> mix = stats.rate_mixture([1.0, 3.0])
    >>> bool(np.isclose(mix.sf(0.5), (np.exp(-0.5) + np.exp(-1.5)) / 2))
    True
    >>> float(mix.hazard(0.0)), round(mix.mean(), 4)
    (2.0, 0.6667)
    """
    rates = as_1d_float("rates", rates, allow_empty=False)
    if np.any(rates <= 0):
        i = int(np.flatnonzero(rates <= 0)[0])
        raise ValueError(f"rates must lie in (0, inf), got rates[{i}] = {float(rates[i])!r}")
    if weights is None:
        w = np.full(rates.size, 1.0 / rates.size)
    else:
        w = as_1d_float("weights", weights)
        if w.shape != rates.shape:
            raise ValueError(f"weights must have the shape of rates {rates.shape}, "
                             f"got {w.shape}")
        if np.any(w < 0) or w.sum() <= 0:
            raise ValueError("weights must be non-negative with a positive sum")
        w = w / w.sum()
    return RateMixture(rates, w)


def simulate_cox_times(rates, t_window, *, order="sequence", rng=None) -> np.ndarray:
    r"""Event times in ``[0, t_window]`` of a process whose rate is redrawn at every event.

    Parameters
    ----------
    rates : array_like
        Positive rates. ``order="sequence"``: ``rates[0]`` holds from time 0 to the first
        event and ``rates[k]`` from event ``k`` to event ``k + 1``; when the sequence is
        used up, each further rate is drawn uniformly from ``rates[1:]`` (from ``rates``
        if it has one entry). ``order="iid"``: every rate, the first included, is drawn
        uniformly from ``rates``.
    t_window : float
        Length of the observation window.
    order : {"sequence", "iid"}, optional
        Replay the rates in order (a Cox process driven by an observed path of states) or
        draw them independently (a renewal process with the mixture law of
        :func:`rate_mixture`).
    rng : Generator or int, optional
        The random stream.

    Returns
    -------
    ndarray
        Increasing event times in ``(0, t_window]``.

    Notes
    -----
    Given the rates, interval :math:`k` is :math:`E_k / \Gamma_k` with IID
    :math:`E_k \sim \text{Exp}(1)`. A constant sequence gives a Poisson process. The
    ``"sequence"`` order keeps the serial dependence of the states (long runs of fast
    states in a sticky orbit); ``"iid"`` keeps only their law.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> t = stats.simulate_cox_times([2.0], 1000.0, rng=0)     # Poisson at rate 2
    >>> bool(1800 < t.size < 2200), bool(t[-1] <= 1000.0)
    (True, True)
    >>> t = stats.simulate_cox_times([0.2, 5.0], 5000.0, order="iid", rng=1)
    >>> dt = np.diff(t)
    >>> bool(dt.std() / dt.mean() > 1.3)                       # overdispersed intervals
    True
    """
    rates = as_1d_float("rates", rates, allow_empty=False)
    if np.any(rates <= 0):
        i = int(np.flatnonzero(rates <= 0)[0])
        raise ValueError(f"rates must lie in (0, inf), got rates[{i}] = {float(rates[i])!r}")
    t_window = check_real("t_window", t_window, low=0.0)
    check_choice("order", order, ("sequence", "iid"))
    rng = check_rng(rng)
    pool = rates[1:] if rates.size > 1 else rates
    if order == "iid":
        pool, head = rates, np.empty(0)
    else:
        head = rates
    # draw in chunks of about twice the expected count (bounded) until the window is passed
    chunk = int(min(max(16.0, 2.0 * t_window * float(np.mean(pool))), 65_536.0))
    parts, total, used = [], 0.0, 0
    while total <= t_window:
        seq = head[used:used + chunk]
        if seq.size < chunk:
            seq = np.concatenate([seq, rng.choice(pool, chunk - seq.size)])
        used += chunk
        steps = np.cumsum(rng.standard_exponential(chunk) / seq) + total
        parts.append(steps)
        total = float(steps[-1])
    times = np.concatenate(parts)
    return times[times <= t_window]
