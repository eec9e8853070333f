"""Markov-modulated Poisson processes (MMPP) over censored windows: one home for the
concept (``docs/mmpp.md``).

* :mod:`.fit`: the fitted model :class:`MMPPFit` and :func:`fit_mmpp` (multi-start EM),
  with the windows' validation :func:`check_windows`;
* :mod:`.choice`: Poisson, renewal models and MMPPs on one likelihood
  (:func:`compare_point_processes`) and the bootstrap likelihood-ratio test against
  Poisson (:func:`mmpp_lr_test`);
* :mod:`.simulation`: :func:`simulate_mmpp`;
* the EM underneath: ``_estep`` (data layout, decomposition of ``D``, the E-step),
  ``_kernels`` (the compiled forward-backward pass and simulation), ``_em`` (M-step,
  score, SQUAREM iterations, information).

The public names are re-exported by :mod:`kicktimes.stats`.
"""

from .choice import MMPPLRTest, compare_point_processes, mmpp_lr_test
from .fit import MMPP_MIN_EVENTS, MMPPFit, check_windows, fit_mmpp
from .simulation import simulate_mmpp

__all__ = ["MMPP_MIN_EVENTS", "MMPPFit", "MMPPLRTest", "check_windows",
           "compare_point_processes", "fit_mmpp", "mmpp_lr_test", "simulate_mmpp"]
