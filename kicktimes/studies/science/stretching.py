r"""Stretching per perturbation: the FTLE over the perturbation rate, per radius.

The FTLE sweep (`stretching_experiment`) is the paper's family-A setup at radii down to
0.002, FTLE only, for the two disks and the disk kicked at Poisson times (uniform and
scatter kicks). Per radius and system the stretching per perturbation is
:math:`s = \bar\lambda / \hat\Gamma`; `stretching` gives it with bootstrap intervals over
ICs, the kicked / two-disk ratios with their `ratio_verdict`, the least-squares line
:math:`s = a + b \ln(1/r)` over the measured range and the trend of the ratio.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from kicktimes.experiment import preset
from kicktimes.render.pages import trend_verdict
from kicktimes.stats import (
    margin_of,
    percentile_interval,
    ratio_verdict,
    resample_indices,
    stretching_per_perturbation,
)

__all__ = ["KICKED", "N_BOOT", "SMALL_RADII", "SYSTEMS", "stretching", "stretching_experiment"]

SMALL_RADII = (0.002, 0.003, 0.004, 0.006, 0.008, 0.012, 0.016, 0.02, 0.025, 0.03)
N_BOOT = 1000
SYSTEMS = ("two_particle", "poisson", "poisson_scatter")
KICKED = {"poisson": "uniform kick", "poisson_scatter": "scatter kick"}


def stretching_experiment(radii=SMALL_RADII, n_ics=100, n_steps=None,
                          name="stretching_small_r"):
    """The paper's family-A setup at ``radii`` (default down to 0.002): FTLE only, three
    systems; ``n_steps`` defaults to family A's."""
    changes = {} if n_steps is None else {"n_steps": n_steps}
    return dataclasses.replace(
        preset("family_a"), name=name, radii=list(radii), n_ics=n_ics,
        systems=SYSTEMS, diagnostics=("lyapunov",),
        rr_sampling="run", seed=11, block_size=25,
        description="FTLE at radii 0.002-0.03 for the stretching-per-perturbation fits.",
        **changes,
    )


def _per_ic(results, system):
    """Arrays (radius x IC) of the FTLE, the run time and the perturbations of disk 0 (the
    disk-disk collisions) or of the kicked disk (its kicks); NaN where a run is missing."""
    part = results[results["system"] == system]
    wide = part.pivot_table(index=["radius", "ic"], columns="diagnostic", values="value")
    n = wide["n_pp"] if system == "two_particle" else wide["n_kicks"]
    frame = pd.DataFrame({"lam": wide["lyapunov"], "t": wide["t_max"], "n": n})
    return {k: frame[k].unstack("ic").sort_index() for k in frame}


def stretching(results, n_boot=N_BOOT, seed=0):
    r"""Stretching per perturbation per radius and system, its ratios and their trend.

    The stretching per perturbation at radius r is :math:`s = \bar\lambda / \hat\Gamma`,
    the mean FTLE over ICs over the pooled perturbation rate (perturbations / run time,
    summed over ICs), in nats. Since the kicks are drawn at the two-disk collision rate,
    :math:`\lambda_{kicked} / \lambda_{two} = s_{kicked} / s_{two}` up to the rates'
    difference, which the ratio of the s keeps. Intervals: percentile bootstrap over ICs
    (the same resampled ICs for every system and radius, so the ratios are paired).

    Parameters
    ----------
    results : DataFrame
        A store's long results table (``radius, ic, system, diagnostic, value``) with the
        diagnostics ``lyapunov``, ``t_max`` and ``n_pp`` (two disks) or ``n_kicks``.
    n_boot : int
        Bootstrap resamples of the ICs.
    seed : int
        Seed of the resampling.

    Returns
    -------
    per_radius, fits, trend : DataFrame
        Per (system, radius) the stretching and (kicked systems) the ratio to the
        two-disk value with intervals and `ratio_verdict`; per system the least-squares
        line a + b ln(1/r) over the measured range with intervals and the range of local
        slopes between adjacent radii; per kicked system the slope of the ratio and of
        :math:`|\ln \text{ratio}|` against ln(1/r) with intervals and their verdicts.

    Examples
    --------
    >>> import pandas as pd
    >>> rows = [(r, ic, s, d, v) for r in (0.01, 0.02) for ic in range(3)
    ...         for s, n in (("two_particle", "n_pp"), ("poisson", "n_kicks"),
    ...                      ("poisson_scatter", "n_kicks"))
    ...         for d, v in (("lyapunov", 0.5), ("t_max", 100.0), (n, 10.0))]
    >>> table = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])
    >>> per_radius, fits, trend = stretching(table, n_boot=20)
    >>> float(per_radius["stretch_per_perturbation"].iloc[0])
    5.0
    """
    rng = np.random.default_rng(seed)
    arrays = {s: _per_ic(results, s) for s in SYSTEMS}
    radii = arrays["two_particle"]["lam"].index.to_numpy(float)
    n_ics = arrays["two_particle"]["lam"].shape[1]
    x = np.log(1 / radii)
    picks = resample_indices(n_ics, n_boot=n_boot, rng=rng, with_identity=True)

    def stretch(system):
        a = {k: v.to_numpy(float) for k, v in arrays[system].items()}
        s = stretching_per_perturbation(a["lam"][:, picks], a["n"][:, picks],
                                        a["t"][:, picks])
        return s.T                       # (1 + n_boot, radii); row 0 the estimate

    s = {k: stretch(k) for k in SYSTEMS}
    design = np.vstack([np.ones_like(x), x]).T

    def lstsq(y):                         # (B, radii) -> (B, 2): intercept, slope
        return np.linalg.lstsq(design, y.T, rcond=None)[0].T

    per_radius, fits, trend = [], [], []
    for system in SYSTEMS:
        ratio = s[system] / s["two_particle"]
        for j, r in enumerate(radii):
            row = {"system": system, "radius": r, "ln_inv_r": x[j],
                   "stretch_per_perturbation": s[system][0, j]}
            row["ci_low"], row["ci_high"] = percentile_interval(s[system][1:, j])
            if system != "two_particle":
                lo, hi = percentile_interval(ratio[1:, j])
                row.update(ratio=ratio[0, j], ratio_ci_low=lo, ratio_ci_high=hi,
                           verdict=ratio_verdict(lo, hi, tolerance=margin_of("ftle")))
            per_radius.append(row)
        coef = lstsq(s[system])
        local = np.diff(s[system][0]) / np.diff(x)
        row = {"system": system, "intercept": coef[0, 0], "slope": coef[0, 1],
               "ln_inv_r_min": x.min(), "ln_inv_r_max": x.max(),
               "local_slope_min": local.min(), "local_slope_max": local.max()}
        row["intercept_ci_low"], row["intercept_ci_high"] = percentile_interval(coef[1:, 0])
        row["slope_ci_low"], row["slope_ci_high"] = percentile_interval(coef[1:, 1])
        fits.append(row)
        if system != "two_particle":
            for what, y in (("ratio", ratio), ("abs_log_ratio", np.abs(np.log(ratio)))):
                b = lstsq(y)[:, 1]
                lo, hi = percentile_interval(b[1:])
                trend.append({"system": system, "quantity": what, "slope_per_ln_inv_r": b[0],
                              "ci_low": lo, "ci_high": hi, "verdict": trend_verdict(lo, hi)})
    return pd.DataFrame(per_radius), pd.DataFrame(fits), pd.DataFrame(trend)
