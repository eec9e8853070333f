r"""Twins of the Poisson-kicked disk that draw their own kick angles.

kicktimes' twins share the kicks (common random numbers). A twin that draws its own kick
angles is thrown O(1) away from the reference at every kick: with a position separation
of O(tau) renormalised to d0 every tau, a first estimate is
:math:`\lambda \approx \Gamma \ln(\tau / d_0)`. `independent_angle_twin` simulates it;
`twin_table` sets it beside that estimate and beside the two-disk stretching.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, schedules, simulate_one_particle
from kicktimes.billiard import KickLaw
from kicktimes.stats import kinetic_rate, percentile_interval, resample_indices

__all__ = ["independent_angle_twin", "twin_table", "twins_raw"]

N_BOOT = 1000


def independent_angle_twin(r, *, n_ics=8, n_steps=3000, tau=0.2, d0=2e-4, seed=3):
    """Benettin twins of the Poisson-kicked disk that draw *independent* kick angles.

    Reference and twin share the kick times (rate Gamma(r)) but not the new directions;
    every tau the phase-space separation d of (x, y, vx, vy) is measured, ln(d / d0)
    accumulated and the twin put back at distance d0 along the separation (Benettin).

    Returns
    -------
    lam, rate, (low, high)
        The mean lambda over ICs, the kick rate Gamma(r) and the 95 % bootstrap interval
        of the mean over ICs.

    Examples
    --------
    >>> lam, rate, (low, high) = independent_angle_twin(0.05, n_ics=1, n_steps=20)
    >>> low <= lam <= high
    True
    """
    rate = kinetic_rate(r)
    ics = initial_conditions(n_ics, r, rng=seed)
    lams = []
    for k, ic in enumerate(ics):
        rng = np.random.default_rng([seed, k])
        horizon = n_steps * tau
        kicks = schedules.Poisson(rate).sample(horizon, rng=rng)
        ang_a = rng.uniform(0.0, 2.0 * np.pi, kicks.size)
        ang_b = rng.uniform(0.0, 2.0 * np.pi, kicks.size)
        a = np.array(ic[0], dtype=float)
        b = a.copy()
        b[0] += d0
        total = 0.0
        for step in range(n_steps):
            t0 = step * tau
            sel = (kicks > t0) & (kicks <= t0 + tau)
            ks = kicks[sel] - t0
            a = simulate_one_particle(a, r, t_max=tau, kicks=KickLaw(ks, angles=ang_a[sel])
                                      ).final_state.ravel()[:4]
            b = simulate_one_particle(b, r, t_max=tau, kicks=KickLaw(ks, angles=ang_b[sel])
                                      ).final_state.ravel()[:4]
            diff = b - a
            d = float(np.sqrt(diff @ diff))
            total += math.log(d / d0)
            b = a + diff * (d0 / d)
            # a twin pushed outside the table by the rescaling is put back on the reference
            if math.hypot(b[0], b[1]) > 1.0 - r:
                b = a.copy()
                b[0] += d0 if a[0] < 0 else -d0
        lams.append(total / (n_steps * tau))
    boot_rng = np.random.default_rng(1)
    lams = np.asarray(lams, float)
    boot = [np.mean(lams[p])
            for p in resample_indices(lams.size, n_boot=N_BOOT, rng=boot_rng, chunk=1)]
    return float(np.mean(lams)), rate, percentile_interval(boot)


def twins_raw(radii, *, tau, d0, n_ics=8, n_steps=3000):
    """The simulated twins per radius: columns ``radius, lam, rate, lo, hi``."""
    rows = []
    for r in radii:
        lam, rate, (lo, hi) = independent_angle_twin(r, n_ics=n_ics, n_steps=n_steps,
                                                     tau=tau, d0=d0)
        rows.append((r, lam, rate, lo, hi))
    return pd.DataFrame(rows, columns=["radius", "lam", "rate", "lo", "hi"])


def twin_table(raw, per_radius, *, tau, d0):
    """The twins beside the estimate Gamma ln(tau / d0) per kick and the two-disk
    stretching per collision (``per_radius`` of `stretching`), with the ratios'
    intervals (the ends divided crosswise: conservative)."""
    two = per_radius[per_radius["system"] == "two_particle"].set_index("radius")
    rows = []
    per_kick = math.log(tau / d0)
    for r_twin, lam, rate, lo, hi in raw.itertuples(index=False):
        s = two.loc[r_twin]
        rows.append({"radius": r_twin, "lam": lam, "ci_low": lo, "ci_high": hi,
                     "kick_rate": rate, "per_kick": lam / rate,
                     "two_disk_per_collision": s.stretch_per_perturbation,
                     "two_disk_ci_low": s.ci_low, "two_disk_ci_high": s.ci_high,
                     "predicted_per_kick": per_kick,
                     "over_predicted": lam / rate / per_kick,
                     "over_predicted_ci_low": lo / rate / per_kick,
                     "over_predicted_ci_high": hi / rate / per_kick,
                     "ratio": lam / rate / s.stretch_per_perturbation,
                     "ratio_ci_low": lo / rate / s.ci_high,
                     "ratio_ci_high": hi / rate / s.ci_low})
    return pd.DataFrame(rows)
