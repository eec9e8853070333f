"""The scatter study's simulations: per IC and radius of family A, the FTLE of the two
disks, of the kicked disk under uniform and scattering kicks, and of the two disks with
the partner's deviation zeroed at every collision; RR, DET and the ACF of three systems.

Systems (columns of `scatter_runs`):

* ``two``: the two-disk billiard (disk 0 tracked);
* ``uniform``: the paper's kicked disk, Poisson kicks at the two-disk run's own rate
  ``n_pp / t_max``, new direction uniform (state-blind);
* ``scatter``: the same Poisson kick times, scattering kicks (docs/scatter.md), mirror
  rule, weighted partner; ``scatter_unw``: the same numbers with the unweighted uniform
  partner;
* ``scatter_actual``: scattering kicks at the two-disk run's own collision times;
* ``two_fresh``: the two-disk trajectory, the partner's tangent vector set to zero just
  before every disk-disk collision (`kernel.fresh_lam`).

Every FTLE is the paper's ``max(lambda_x, lambda_y)`` from exact tangent-space
exponents on the paper's collision-truncated steps.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, simulate_one_particle, simulate_two_particle
from kicktimes.billiard import KickLaw
from kicktimes.diagnostics import (
    Tangent,
    autocorrelation_function,
    boundary_angles,
    lyapunov,
    rqa,
)
from kicktimes.schedules import Poisson
from kicktimes.studies.scatter.kernel import fresh_lam

__all__ = ["one_ic", "scatter_runs", "shape_rows"]


def shape_rows(run, particle):
    """Off-diagonal RR and DET (eps = 0.001, Theiler 1) of ``run``'s samples and the ACF
    R_1..R_5 of the boundary angles of ``particle`` (None: the one disk)."""
    res = rqa(run.samples, eps=1e-3, theiler=1, l_min=2)
    with warnings.catch_warnings():
        # the 20-step warm-up run has too few boundary collisions for an ACF
        warnings.simplefilter("ignore")
        acf = autocorrelation_function(boundary_angles(run, particle=particle), 5)
    return {"rr_offdiag": res.rr, "det": res.det, **{f"acf{k + 1}": acf[k] for k in range(5)}}


def one_ic(r, i, ic, n_steps, tau):
    """One row of the per-IC table: IC ``i`` (state ``ic``) at radius ``r`` in every
    system (the module's docstring), its kick numbers drawn from
    ``SeedSequence(2026, spawn_key=(i, int(r * 1e6)))``."""
    steps = dict(n_steps=n_steps, tau=tau, sampling="paper")
    ftle = dict(method=Tangent(variant="paper"), **steps)
    two = simulate_two_particle(ic, r, **steps)
    rate = two.n_pp / two.t_max
    rng = np.random.default_rng(np.random.SeedSequence(2026, spawn_key=(i, int(r * 1e6))))
    times = Poisson(rate).sample(n_steps * tau, rng=rng)
    u_angles = rng.uniform(0.0, 2.0 * np.pi, times.size)
    s_numbers = rng.uniform(-1.0, 1.0, (times.size, 2))
    # actual collision times, continued to cover the kicked run (paper steps are longer)
    actual = simulate_two_particle(ic, r, t_max=n_steps * tau).pp_times
    a_numbers = rng.uniform(-1.0, 1.0, (actual.size, 2))
    uni = simulate_one_particle(ic[0], r, kicks=KickLaw(times, angles=u_angles), **steps)
    sca = simulate_one_particle(ic[0], r, kicks=KickLaw(times, angle="scatter", angles=s_numbers),
                                **steps)
    row = {
        "radius": r, "ic": i, "rate": rate,
        "two": lyapunov(two, method=Tangent(variant="paper")).lam,
        "two_fresh": fresh_lam(ic, r, n_steps, tau),
        "uniform": lyapunov(uni, method=Tangent(variant="paper")).lam,
        "scatter": lyapunov(sca, method=Tangent(variant="paper")).lam,
        "scatter_unw": lyapunov(ic[0], r, kicks=KickLaw(times, angle="scatter", angles=s_numbers,
                                                        partner="uniform"), **ftle).lam,
        "scatter_actual": lyapunov(ic[0], r, **ftle, kicks=KickLaw(
            actual[actual <= n_steps * tau], angle="scatter",
            angles=a_numbers[actual <= n_steps * tau])).lam,
        "outside": sca.kick_log.outside.mean() if sca.n_kicks else math.nan,
    }
    for name, run, particle in (("two", two, 0), ("uniform", uni, None), ("scatter", sca, None)):
        for key, value in shape_rows(run, particle).items():
            row[f"{name}_{key}"] = value
    return row


def scatter_runs(r, n_ics, n_steps, tau, ic_radius, ic_seed, ic_method) -> pd.DataFrame:
    """The per-IC table at radius ``r``: `one_ic` for the first ``n_ics`` ICs drawn at
    ``ic_radius`` (the same ICs at every radius)."""
    ics = initial_conditions(n_ics, ic_radius, rng=ic_seed, method=ic_method)
    return pd.DataFrame([one_ic(r, i, ics[i], n_steps, tau) for i in range(n_ics)])
