"""The analysis layer: statistics of event-time processes.

It takes event times and observation windows only (no billiard knowledge):

* renewal-model fits with right censoring and their comparison
  (:func:`fit_renewal`, :func:`compare_models`, :func:`vuong`,
  :func:`goodness_of_fit`; models in ``MODELS``);
* Poisson / IID tests of one sequence and of an ensemble
  (:func:`intervals_from_times`, :func:`test_poisson`, :func:`test_poisson_ensemble`);
* collision counts versus radius and the kinetic-theory rate
  (:func:`regress_counts`, :func:`kinetic_rate`).

See ``docs/statistics.md`` for the conventions.
"""

from kicktimes.stats._findings import ratio_rule, ratio_verdict

from .analyze import Analysis, analyze
from .comparison import VuongResult, compare_models, vuong
from .counts import CountRegression, kinetic_rate, regress_counts
from .distributions import hyperexpon
from .ensemble import PoissonEnsembleResult, test_poisson_ensemble
from .gof import GofResult, goodness_of_fit
from .poisson import TESTS, Intervals, intervals_from_times, test_poisson
from .renewal import (
    FULL_SAMPLE_MODELS,
    MODELS,
    PARAM_NAMES,
    FitWarning,
    RenewalFit,
    fit_renewal,
)

__all__ = [
    "MODELS",
    "FULL_SAMPLE_MODELS",
    "PARAM_NAMES",
    "TESTS",
    "analyze",
    "Analysis",
    "fit_renewal",
    "compare_models",
    "vuong",
    "goodness_of_fit",
    "intervals_from_times",
    "test_poisson",
    "test_poisson_ensemble",
    "regress_counts",
    "kinetic_rate",
    "hyperexpon",
    "RenewalFit",
    "VuongResult",
    "GofResult",
    "Intervals",
    "PoissonEnsembleResult",
    "CountRegression",
    "FitWarning",
    "ratio_verdict",
    "ratio_rule",
]
