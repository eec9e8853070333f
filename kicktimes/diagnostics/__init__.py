"""Chaos diagnostics of sampled trajectories and boundary-collision series.

Recurrence rate and recurrence plots (`recurrence_rate`, `recurrence_pairs`), the paper's
autocorrelation of the boundary-collision angles (`autocorrelation`,
`autocorrelation_many`, `boundary_angles`) and finite-time Lyapunov exponents
(`lyapunov`, exact tangent vectors, or Benettin twins); see docs/diagnostics.md.
"""

from kicktimes.diagnostics.autocorrelation import (
    UndefinedDiagnosticWarning,
    autocorrelation,
    autocorrelation_many,
    boundary_angles,
)
from kicktimes.diagnostics.lyapunov import (
    LyapunovResult,
    LyapunovSpectrum,
    lyapunov,
    lyapunov_spectrum,
)
from kicktimes.diagnostics.recurrence import recurrence_pairs, recurrence_rate

__all__ = [
    "LyapunovResult",
    "LyapunovSpectrum",
    "UndefinedDiagnosticWarning",
    "autocorrelation",
    "autocorrelation_many",
    "boundary_angles",
    "lyapunov",
    "lyapunov_spectrum",
    "recurrence_pairs",
    "recurrence_rate",
]
