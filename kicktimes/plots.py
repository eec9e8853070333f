"""Figures of the paper and of the collision-time statistics (backward-compatible names).

The figure functions live with their report sections in :mod:`kicktimes.report`; this
module re-exports them under their historical names (notebooks import them from here).
Every function takes data and returns a :class:`matplotlib.figure.Figure` built without
``pyplot``; pass ``ax=`` to draw into an existing Axes where offered.
"""

from __future__ import annotations

from kicktimes.render.figures import (
    DIAGNOSTIC_LABELS,
    RADIUS_LABEL,
    SYSTEM_LABELS,
    SYSTEMS,
    TIME_UNIT,
)
from kicktimes.report.counts import counts_by_radius, counts_vs_radius
from kicktimes.report.heterogeneity import rate_heterogeneity
from kicktimes.report.kick_times import TimesFit, kick_times_vs_collision_times, kth_time_fit
from kicktimes.report.poisson import binomial_ci, poisson_rejection_rates, rejection_table
from kicktimes.report.renewal import model_comparison
from kicktimes.report.summary import diagnostic_summary, diagnostic_vs_radius
from kicktimes.report.trajectories import poincare_panels, poincare_section, recurrence_plot

__all__ = [
    "DIAGNOSTIC_LABELS",
    "RADIUS_LABEL",
    "SYSTEMS",
    "SYSTEM_LABELS",
    "TIME_UNIT",
    "TimesFit",
    "binomial_ci",
    "counts_by_radius",
    "counts_vs_radius",
    "diagnostic_summary",
    "diagnostic_vs_radius",
    "kick_times_vs_collision_times",
    "kth_time_fit",
    "model_comparison",
    "poincare_panels",
    "poincare_section",
    "poisson_rejection_rates",
    "rate_heterogeneity",
    "recurrence_plot",
    "rejection_table",
]
