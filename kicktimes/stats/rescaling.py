r"""Goodness of fit of an MMPP by time rescaling.

With :math:`\lambda(t) = \pi(t \mid \mathcal H_t) \cdot \text{rates}` the conditional
intensity (the filtered state law before ``t`` times the rates) and
:math:`\Lambda(t) = \int_0^t \lambda(s)\,ds` its compensator, the rescaled times
:math:`\Lambda(t_1) < \Lambda(t_2) < \dots` of a correctly specified process form a
unit-rate Poisson process (the time-rescaling theorem; Brown et al. 2002). Between
events the filter evolves as :math:`a\,e^{Ds} / (a\,e^{Ds}\mathbf 1)`, and since
:math:`Q\mathbf 1 = 0`,

.. math::

    \Lambda(t_k) - \Lambda(t_{k-1}) = -\log\big(a_{k-1}\, e^{D x_k} \mathbf 1\big),

minus the log-probability of no event in the interval given the history: the same
forward pass as the likelihood computes it exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kicktimes._results import Result

from .ensemble import test_poisson_ensemble
from .mmpp import _em as em
from .mmpp.fit import MMPPFit, check_windows


@dataclass(frozen=True, repr=False)
class RescaledTimes(Result):
    """Time-rescaled windows (result of :func:`mmpp_residuals`).

    Attributes
    ----------
    times : list of ndarray
        Rescaled event times :math:`\\Lambda(t_k)` of each window.
    windows : ndarray
        Rescaled window lengths :math:`\\Lambda(T)`.
    intervals : ndarray
        The rescaled intervals :math:`\\Lambda(t_k) - \\Lambda(t_{k-1})` of every window
        (the first from 0), IID Exp(1) under a correct model.
    censored : ndarray
        :math:`\\Lambda(T) - \\Lambda(t_N)` of each window (right-censored Exp(1)).
    """

    _title = "Time-rescaled windows under a fitted MMPP (IID Exp(1) intervals if it is right)"
    _summary_fields = ("windows", "intervals", "censored")

    times: list
    windows: np.ndarray
    intervals: np.ndarray
    censored: np.ndarray

    def _summary_extra(self) -> list[str]:
        mean = self.intervals.mean() if self.intervals.size else np.nan
        return [f"n: {len(self.times)} windows, events: {self.intervals.size}, mean rescaled "
                f"interval {mean:.4g} (1 under the model)"]

    def __repr__(self) -> str:
        return (f"RescaledTimes(n_windows={len(self.times)}, n_events={self.intervals.size}, "
                f"mean_interval={self.intervals.mean() if self.intervals.size else np.nan:.4g})")

    def test(self, **kwargs):
        """The Poisson battery on the rescaled windows: :func:`test_poisson_ensemble`
        (keyword arguments are passed on)."""
        return test_poisson_ensemble(self.times, self.windows, **kwargs)


def mmpp_residuals(fit: MMPPFit, times, t_max) -> RescaledTimes:
    r"""Time-rescaled event times of windows under a fitted MMPP.

    Parameters
    ----------
    fit : MMPPFit
        A fit of :func:`fit_mmpp` (any number of states; one state is the Poisson
        process, whose rescaling is :math:`\hat\lambda t`).
    times, t_max :
        Event times in windows, as in :func:`fit_mmpp` (the fitted data or others).

    Returns
    -------
    RescaledTimes
        Rescaled times and windows; ``.test()`` runs the Poisson/IID battery on them.

    Notes
    -----
    Each window starts from :attr:`MMPPFit.initial` (the stationary law for a
    stationary fit), as in the likelihood. The rescaled window end :math:`\Lambda(T)`
    depends on the history, so the battery's tests, exact given the number of events
    in a fixed window, are approximate here; their size stays near nominal for windows
    of tens of events (``docs/mmpp.md``).

    References
    ----------
    E. N. Brown, R. Barbieri, V. Ventura, R. E. Kass, L. M. Frank, "The time-rescaling
    theorem and its application to neural spike train data analysis", Neural Comput.
    14 (2002) 325-340.

    Examples
    --------
    Under the fitted model the rescaled intervals have mean 1:

    >>> from kicktimes import stats
    >>> times = stats.simulate_mmpp([0.5, 5.0], [[-0.1, 0.1], [0.3, -0.3]], 60.0,
    ...                             n_windows=50, rng=1)
    >>> res = stats.mmpp_residuals(stats.fit_mmpp(times, 60.0, rng=2), times, 60.0)
    >>> round(float(res.intervals.mean()), 1)
    1.0
    """
    if not isinstance(fit, MMPPFit):
        raise TypeError(f"fit must be an MMPPFit (from fit_mmpp), got {type(fit).__name__}")
    seqs, lengths = check_windows(times, t_max)
    data = em.Windows.of(seqs, lengths)
    st = em.estep(fit.rates * data.unit, fit.generator * data.unit, fit.initial, data,
                  log_surv=True)
    increments = -st.log_surv
    rescaled, ends, inner, tails = [], np.empty(data.n_windows), [], np.empty(data.n_windows)
    for w in range(data.n_windows):
        steps = np.cumsum(increments[data.start[w]:data.start[w + 1]])
        rescaled.append(steps[:-1])
        ends[w] = steps[-1]
        inner.append(increments[data.start[w]:data.start[w + 1] - 1])
        tails[w] = increments[data.start[w + 1] - 1]
    return RescaledTimes(rescaled, ends, np.concatenate(inner), tails)
