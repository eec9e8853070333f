"""The analysis layer: statistics of event-time processes.

It takes event times and observation windows only (no billiard knowledge):

* renewal-model fits with right censoring and their comparison
  (:func:`fit_renewal`, :func:`compare_models`, :func:`vuong`,
  :func:`goodness_of_fit`; models in ``MODELS``);
* Poisson / IID tests of one sequence and of an ensemble
  (:func:`intervals_from_times`, :func:`test_poisson`, :func:`test_poisson_ensemble`, the
  shared Monte Carlo nulls :class:`MonteCarloNulls`), and
  the tables of one group of sequences (:func:`poisson_group`, :func:`pooled_intervals`,
  shared by :func:`analyze` and the sweep report);
* collision counts versus radius and the kinetic-theory rate
  (:func:`regress_counts`, :func:`kinetic_rate`), and the rate conditioned on the two
  angular momenta (:func:`conditional_kinetic_rate`, :func:`mean_kinetic_rate`);
* the hazard of intervals against the time since the last event and the rate-mixture
  (Cox) processes that explain a falling one (:func:`interval_hazard`,
  :func:`rate_mixture`, :func:`simulate_cox_times`);
* Markov-modulated Poisson processes over censored windows: the EM fit and simulation
  (:func:`fit_mmpp`, :func:`simulate_mmpp`), the comparison with Poisson and renewal
  models on one likelihood (:func:`compare_point_processes`), the bootstrap
  likelihood-ratio test against Poisson (:func:`mmpp_lr_test`) and time-rescaling
  residuals (:func:`mmpp_residuals`).

See ``docs/statistics.md`` for the conventions.
"""

from .analyze import Analysis, analyze
from .bootstrap import (
    ClusterBootstrap,
    cluster_bootstrap,
    paired_median,
    paired_ratio,
    percentile_interval,
    ratio_of_means,
    resample_counts,
    resample_indices,
)
from .comparison import VuongResult, compare_models, vuong
from .correlation import spearman
from .counts import STICKY_FACTOR, CountRegression, is_sticky, kinetic_rate, regress_counts
from .dilute import DiluteEstimate, DiluteTaggedDisk, dilute_tagged_disk, dilute_tagged_times
from .distributions import hyperexpon
from .ear1 import ear1_intervals
from .ensemble import PoissonEnsembleResult, test_poisson_ensemble
from .enskog import contact_value, enskog_frequency, henderson_z, speed_rate_factor
from .eos import contact_from_z, kolafa_rottner_z, virial_z
from .findings import (
    D_MARGIN,
    DIAGNOSTIC_MARGINS,
    FINE_MARGIN,
    MARGIN,
    RR_MARGIN,
    SHARE_RULE,
    Finding,
    clopper_pearson,
    equivalence_sample_size,
    format_interval,
    margin_of,
    null_rule,
    null_verdict,
    poisson_rule,
    poisson_verdict,
    ratio_interval,
    ratio_rule,
    ratio_verdict,
    rejection_rule,
    rejection_verdict,
    robust_verdict,
    share_ratio_sample_size,
    share_verdict,
)
from .gamma_shape import gamma_shape_mle
from .gof import GofResult, goodness_of_fit
from .groups import PoissonGroup, poisson_group, pooled_intervals
from .hazard import HazardTable, interval_hazard
from .kinetic import conditional_kinetic_rate, mean_kinetic_rate
from .margins import COUNTS_MARGIN, EOS_MARGIN
from .mixture import RateMixture, rate_mixture, simulate_cox_times
from .mmpp import (
    MMPP_MIN_EVENTS,
    MMPPFit,
    MMPPLRTest,
    compare_point_processes,
    fit_mmpp,
    mmpp_lr_test,
    simulate_mmpp,
)
from .perturbation import stretching_per_perturbation
from .poisson import TESTS, Intervals, MonteCarloNulls, intervals_from_times, test_poisson
from .readings import null_reading, ratio_reading, ratio_words, side_of
from .renewal import (
    FULL_SAMPLE_MODELS,
    MODELS,
    PARAM_NAMES,
    FitWarning,
    RenewalFit,
    fit_renewal,
)
from .rescaling import RescaledTimes, mmpp_residuals
from .robust import bootstrap_nanmedians, nanmedian
from .shapley import shapley_values
from .survival import (
    MIN_AT_RISK,
    EscapeTail,
    circle_escape_constant,
    escape_survival,
    fit_escape_tail,
    reliable_until,
)

__all__ = [
    "MIN_AT_RISK",
    "MMPP_MIN_EVENTS",
    "SHARE_RULE",
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
    "MonteCarloNulls",
    "poisson_group",
    "pooled_intervals",
    "regress_counts",
    "kinetic_rate",
    "STICKY_FACTOR",
    "ClusterBootstrap",
    "cluster_bootstrap",
    "paired_median",
    "paired_ratio",
    "percentile_interval",
    "ratio_of_means",
    "resample_counts",
    "resample_indices",
    "is_sticky",
    "stretching_per_perturbation",
    "enskog_frequency", "henderson_z",
    "virial_z", "kolafa_rottner_z", "contact_from_z",
    "speed_rate_factor",
    "dilute_tagged_times",
    "dilute_tagged_disk",
    "DiluteTaggedDisk",
    "DiluteEstimate",
    "contact_value",
    "conditional_kinetic_rate",
    "mean_kinetic_rate",
    "circle_escape_constant",
    "escape_survival",
    "nanmedian",
    "bootstrap_nanmedians",
    "fit_escape_tail",
    "EscapeTail",
    "hyperexpon",
    "RenewalFit",
    "VuongResult",
    "GofResult",
    "Intervals",
    "PoissonEnsembleResult",
    "PoissonGroup",
    "CountRegression",
    "FitWarning",
    "Finding",
    "ratio_verdict",
    "reliable_until",
    "MARGIN",
    "D_MARGIN",
    "FINE_MARGIN",
    "DIAGNOSTIC_MARGINS",
    "RR_MARGIN",
    "COUNTS_MARGIN",
    "EOS_MARGIN",
    "margin_of",
    "null_reading",
    "ratio_reading",
    "ratio_words",
    "side_of",
    "null_verdict",
    "null_rule",
    "equivalence_sample_size",
    "clopper_pearson",
    "robust_verdict",
    "spearman",
    "share_ratio_sample_size",
    "shapley_values",
    "share_verdict",
    "format_interval",
    "rejection_verdict",
    "poisson_verdict",
    "poisson_rule",
    "rejection_rule",
    "ratio_interval",
    "ratio_rule",
    "interval_hazard",
    "HazardTable",
    "rate_mixture",
    "RateMixture",
    "simulate_cox_times",
    "fit_mmpp",
    "MMPPFit",
    "simulate_mmpp",
    "ear1_intervals",
    "gamma_shape_mle",
    "compare_point_processes",
    "mmpp_lr_test",
    "MMPPLRTest",
    "mmpp_residuals",
    "RescaledTimes",
]
