"""The MMPP study's simulations: the collision times of paper ICs under each rule."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, simulate_two_particle, stats
from kicktimes.stats import STICKY_FACTOR

__all__ = ["RULES", "STICKY_FACTOR", "collision_runs", "sticky_runs"]

RULES = ("mirror", "elastic")


def collision_runs(rule, n_ics, r, t_max, seed) -> pd.DataFrame:
    """The collision times (column ``pp_times``) of ``n_ics`` paper ICs (``seed``, drawn
    at ``r`` under ``rule``) run to ``t_max``, one row per IC (``ic``)."""
    ics = initial_conditions(n_ics, r, rng=seed, method="paper", rule=rule)
    times = [np.asarray(simulate_two_particle(ic, r, t_max=t_max, rule=rule).pp_times, float)
             for ic in ics]
    return pd.DataFrame({"ic": np.arange(n_ics), "pp_times": times})


def sticky_runs(times, r, t_max):
    """Which runs are sticky: collision rate above ``STICKY_FACTOR`` Γ(r)."""
    sizes = np.array([t.size for t in times], dtype=float)
    return stats.is_sticky(sizes / t_max, stats.kinetic_rate(r))
