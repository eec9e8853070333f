r"""The stretching per perturbation: the FTLE over the perturbation rate.

A chaotic run stretches a deviation at the rate :math:`\lambda` (nats per unit time); the
perturbations that do the stretching (the disk-disk collisions of two disks, the kicks of a
kicked disk) come at the rate :math:`\Gamma`. Their ratio is the stretching per
perturbation, in nats:

.. math::

    s = \frac{\bar\lambda}{\hat\Gamma}, \qquad
    \bar\lambda = \frac{1}{m}\sum_i \lambda_i, \qquad
    \hat\Gamma = \frac{\sum_i n_i}{\sum_i T_i},

over the :math:`m` runs of one radius and system (NaN values left out), with
:math:`n_i` perturbations in the run's duration :math:`T_i`: the pooled rate, so that a
run without perturbations counts. Against :math:`\ln(1/r)` it tests the one-collision
picture (a collision between round disks defocuses by about :math:`\ln(1/r)`).
"""

from __future__ import annotations

import warnings

import numpy as np

from kicktimes.validation import keyword_only_after

__all__ = ["stretching_per_perturbation"]


@keyword_only_after(3, since="0.2.0")
def stretching_per_perturbation(lam, n, t, *, axis=-1):
    r"""The stretching per perturbation :math:`\bar\lambda / \hat\Gamma` (module docstring).

    Parameters
    ----------
    lam, n, t : array_like of float
        Per run: the FTLE, the number of perturbations and the duration (broadcast
        together; NaN: a run without the value, left out of its sum or mean).
    axis : int
        The axis of the runs (default the last: resamples of runs along it give one value
        per resample).

    Returns
    -------
    float or ndarray
        :math:`s`; NaN where no perturbation was counted (:math:`\hat\Gamma \le 0`) or no
        FTLE is finite.

    Examples
    --------
    >>> from kicktimes.stats import stretching_per_perturbation
    >>> float(stretching_per_perturbation([0.5, 0.7], [10.0, 14.0], [100.0, 100.0]))
    5.0
    """
    lam, n, t = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (lam, n, t)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a row without a finite value
        rate = np.nansum(n, axis=axis) / np.nansum(t, axis=axis)
        mean = np.nanmean(lam, axis=axis)
        out = np.where(rate > 0, mean / np.where(rate > 0, rate, 1.0), np.nan)
    return out if out.ndim else float(out)
