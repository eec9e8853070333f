"""The unequal-disks study's simulations: per IC of each size ratio, the collision times,
the tangent FTLE of each disk and of each disk kicked alone."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, schedules
from kicktimes.billiard import KickLaw
from kicktimes.diagnostics import lyapunov
from kicktimes.diagnostics.lyapunov import lyapunov_pass

__all__ = ["KINDS", "R0", "R1", "size_ratio_runs"]

#: disk 0's radius; disk 1's radii (size ratios 1 to 4)
R0 = 0.01
R1 = (0.01, 0.015, 0.025, 0.04)
#: the kicked disk's scattering partner: the other disk's radius, or its own (the control)
KINDS = ("partner", "own")


def size_ratio_runs(r1, n_ics, n_steps, tau, seed) -> pd.DataFrame:
    """One row per IC of the pair ``(R0, r1)`` (invariant ICs, mirror rule).

    Columns: ``ic``; ``t_max`` and ``pp_times`` (the two-disk run's window and collision
    times); ``lam_disk0``, ``lam_disk1`` (the tangent FTLE of each disk in the two-disk
    system); ``kicked_<kind>_disk<d>`` (disk d alone with scattering kicks at Poisson
    times at its IC's own collision rate, with a partner of the other disk's radius,
    ``partner``, or its own, ``own``; the same kick times and numbers for both kinds).
    """
    radii = (R0, r1)
    ics = initial_conditions(n_ics, radii, rng=seed, method="uniform")
    rows = []
    for i, ic in enumerate(ics):
        row = {"ic": i}
        for disk in (0, 1):
            res, run, _ = lyapunov_pass(ic, radii, n_steps=n_steps, tau=tau, track=disk)
            row[f"lam_disk{disk}"] = res.lam
        row["t_max"] = run.t_max
        row["pp_times"] = np.asarray(run.pp_times, float)
        rate = max(run.n_pp, 1) / run.t_max
        for disk in (0, 1):
            partners = {"partner": radii[1 - disk], "own": radii[disk]}
            for kind, partner_radius in partners.items():
                one = lyapunov(ic[disk], radii[disk], n_steps=n_steps, tau=tau,
                               kicks=KickLaw(schedules.Poisson(rate), angle="scatter",
                                             partner_radius=partner_radius),
                               rng=np.random.default_rng((seed, i, disk)))
                row[f"kicked_{kind}_disk{disk}"] = one.lam
        rows.append(row)
    return pd.DataFrame(rows)
