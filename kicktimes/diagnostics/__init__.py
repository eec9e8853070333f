"""Chaos diagnostics of sampled trajectories and boundary-collision series.

Recurrence rate and recurrence plots (`recurrence_rate`, `recurrence_pairs`), recurrence
quantification (`rqa`: determinism, line lengths, laminarity), the paper's
autocorrelation of the boundary-collision angles (`autocorrelation`,
`autocorrelation_many`, `boundary_angles`), its curve over lags and decay
(`autocorrelation_function`, `decorrelation_lag`, `integrated_autocorrelation_time`)
and finite-time Lyapunov exponents (`lyapunov`: exact tangent vectors by default, or
Benettin twins; `lyapunov_spectrum`: all exponents of the two-disk billiard;
`disks_lyapunov`: the largest exponent of N disks from tangent vectors or a twin); see
docs/diagnostics.md. The collision mechanism of two-disk runs (angular momenta, impact
parameters and wall hits per collision, re-collisions, predicted rates) is in
`kicktimes.diagnostics.mechanism`; see docs/mechanism.md.
"""

from kicktimes.diagnostics.autocorrelation import (
    AcfValue,
    UndefinedDiagnosticWarning,
    autocorrelation,
    autocorrelation_many,
    boundary_angles,
    boundary_map,
)
from kicktimes.diagnostics.decorrelation import (
    AcfCurve,
    acf_curve,
    autocorrelation_function,
    decorrelation_lag,
    integrated_autocorrelation_time,
)
from kicktimes.diagnostics.ftle_methods import Tangent, Twin
from kicktimes.diagnostics.gas_lyapunov import DisksLyapunov, disks_lyapunov
from kicktimes.diagnostics.lyapunov import LyapunovResult, lyapunov
from kicktimes.diagnostics.mechanism import (
    RecollisionShare,
    collision_table,
    collision_tables,
    initial_angular_momenta,
    poisson_recollision_share,
    predicted_rates,
    recollision_share,
)
from kicktimes.diagnostics.recurrence import recurrence_pairs, recurrence_rate
from kicktimes.diagnostics.rqa import RQAResult, rqa
from kicktimes.diagnostics.spectrum import LyapunovSpectrum, lyapunov_spectrum

__all__ = [
    "AcfCurve",
    "AcfValue",
    "DisksLyapunov",
    "LyapunovResult",
    "LyapunovSpectrum",
    "RQAResult",
    "RecollisionShare",
    "Tangent",
    "Twin",
    "UndefinedDiagnosticWarning",
    "acf_curve",
    "disks_lyapunov",
    "autocorrelation",
    "autocorrelation_function",
    "autocorrelation_many",
    "boundary_angles",
    "boundary_map",
    "collision_table",
    "collision_tables",
    "decorrelation_lag",
    "initial_angular_momenta",
    "integrated_autocorrelation_time",
    "lyapunov",
    "lyapunov_spectrum",
    "poisson_recollision_share",
    "predicted_rates",
    "recollision_share",
    "recurrence_pairs",
    "recurrence_rate",
    "rqa",
]
