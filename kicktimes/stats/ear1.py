"""Exponential autoregressive intervals, EAR(1): a serially dependent alternative to a
Poisson process whose intervals are still exponential, so that only the tests of serial
dependence (not those of the interval law) can see it."""

from __future__ import annotations

import numpy as np
import scipy.signal

from ._checks import check_int, check_real, check_rng

__all__ = ["ear1_intervals"]


def ear1_intervals(n, rho, *, rng=None) -> np.ndarray:
    r"""``n`` intervals of the EAR(1) process of Gaver & Lewis (1980).

    .. math::

        X_1 \sim \mathrm{Exp}(1), \qquad X_k = \rho X_{k-1} + B_k E_k, \qquad
        B_k \sim \mathrm{Bernoulli}(1 - \rho),\ E_k \sim \mathrm{Exp}(1),

    all independent: every :math:`X_k` is Exp(1) and the lag-:math:`\ell` autocorrelation
    is :math:`\rho^{\ell}`. A process with these intervals has a Poisson marginal law but
    is not Poisson for :math:`\rho > 0`.

    Parameters
    ----------
    n : int
        Number of intervals, ``>= 1``.
    rho : float
        Lag-1 autocorrelation, in ``[0, 1)`` (0: independent Exp(1) intervals).
    rng : Generator or int, optional
        The draws, in this order: ``n`` uniforms (the :math:`B_k`), ``n`` Exp(1)
        (the :math:`E_k`, the first unused), one Exp(1) (:math:`X_1`).

    Returns
    -------
    ndarray, shape (n,)

    References
    ----------
    D. P. Gaver and P. A. W. Lewis, "First-order autoregressive gamma sequences and point
    processes", Adv. Appl. Prob. 12, 727 (1980).

    Examples
    --------
    >>> from kicktimes import stats
    >>> x = stats.ear1_intervals(200_000, 0.6, rng=0)
    >>> round(float(x.mean()), 2), round(float(np.corrcoef(x[:-1], x[1:])[0, 1]), 2)
    (1.0, 0.6)
    """
    n = check_int("n", n, low=1)
    rho = check_real("rho", rho, low=0.0, high=1.0, low_open=False)
    rng = check_rng(rng)
    keep = rng.uniform(size=n) > rho
    innovations = keep * rng.exponential(size=n)
    first = rng.exponential()
    x = np.empty(n)
    x[0] = first
    # X_k = rho X_{k-1} + B_k E_k as a linear filter (the same sums as the recursion)
    x[1:], _ = scipy.signal.lfilter([1.0], [1.0, -rho], innovations[1:], zi=[rho * first])
    return x
