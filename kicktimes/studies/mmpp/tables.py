"""The MMPP study's fits and checks: pooled and per-run MMPP fits to the two-disk
collision times, their time-rescaling residuals through the Poisson battery, and the
refractory dip against the fitted MMPP's exact hazard."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.linalg import expm

from kicktimes import stats
from kicktimes.stats import MMPP_MIN_EVENTS, percentile_interval, rejection_verdict
from kicktimes.stats.findings import clopper_pearson

__all__ = ["DIP", "EARLY_EDGES", "N_BOOT", "N_MC", "RENEWAL", "TESTS", "analyse",
           "battery", "intervals", "mmpp_bin_hazard", "mmpp_dip"]

TESTS = ("uniformity_ks", "exponential_ks", "exponential_ad", "ljung_box", "runs", "dispersion")
RENEWAL = ("gamma", "weibull", "hyperexponential")
DIP = 0.5
#: the early hazard is read over these bins (the refractory time and the wall round
#: trips), the first bins of the mechanism study's hazard, so that both pages read the
#: same bins: its minimum is the refractory dip wherever it falls, not only in [0, DIP)
EARLY_EDGES = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0)
#: Monte Carlo samples of the Poisson battery's nulls; bootstrap resamples of the dip
N_MC = 199
N_BOOT = 1000


def mmpp_dip(fit, d=DIP, n_grid=201):
    """Mean hazard of the MMPP's interval law over [0, d), over its mean rate."""
    lam = np.asarray(fit.rates, float)
    pi = np.asarray(fit.stationary, float)
    D = np.asarray(fit.generator, float) - np.diag(lam)
    pe = pi * lam / (pi @ lam)
    ts = np.linspace(0.0, d, n_grid)
    surv = np.array([pe @ expm(D * t) @ np.ones_like(lam) for t in ts])
    integral = np.trapezoid(surv, ts)
    return float((1.0 - surv[-1]) / integral / (pi @ lam))


def mmpp_bin_hazard(fit, a, b, n_grid=201):
    r"""Mean hazard of the MMPP's interval law over [a, b), over its mean rate.

    With :math:`S(t) = p_e\, e^{D t}\, \mathbf 1` the survival of the interval after an
    event (:math:`p_e` the state law just after an event, :math:`D = Q - \Lambda`), the
    mean hazard over the bin is :math:`(S(a) - S(b)) / \int_a^b S`, the quantity the
    hazard table of `kicktimes.stats.interval_hazard` estimates there.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> poisson = SimpleNamespace(rates=[2.0], stationary=[1.0], generator=[[0.0]])
    >>> round(mmpp_bin_hazard(poisson, 1.0, 1.5), 4)  # trapezoid rule on 201 points
    1.0
    """
    if not 0.0 <= a < b:
        raise ValueError(f"a, b: need 0 <= a < b, got a = {a!r}, b = {b!r}")
    lam = np.asarray(fit.rates, float)
    pi = np.asarray(fit.stationary, float)
    D = np.asarray(fit.generator, float) - np.diag(lam)
    pe = pi * lam / (pi @ lam)
    ts = np.linspace(a, b, n_grid)
    surv = np.array([pe @ expm(D * t) @ np.ones_like(lam) for t in ts])
    integral = np.trapezoid(surv, ts)
    return float((surv[0] - surv[-1]) / integral / (pi @ lam))


def battery(times, windows, rng):
    """Share of windows whose rescaled times reject each test, with its interval."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = stats.test_poisson_ensemble(times, windows, n_mc=N_MC, rng=rng)
    per = res.per_sequence            # raw per-window p-values (``reject`` is after FDR)
    rows = []
    for test in TESTS:
        k, n = int((per[f"p_{test}"] < 0.05).sum()), len(per)
        lo, hi = clopper_pearson(k, n)
        rows.append({"test": test, "n_windows": n, "rejected": k, "share": k / n,
                     "ci_low": lo, "ci_high": hi, "verdict": rejection_verdict(lo, hi, 0.05)})
    return rows


def analyse(rule, times, sticky, t_max, per_run, seed):
    """The rows of the three tables for one collision rule: the pooled fits (``pooled``),
    the time-rescaling residual checks (``resid``) and the refractory dip (``dip``), from
    the runs' collision ``times`` with the ``sticky`` ones left out; the per-run fits take
    the first ``per_run`` runs with at least `kicktimes.stats.MMPP_MIN_EVENTS` collisions."""
    rng = np.random.default_rng(seed)
    calm = [t for t, s in zip(times, sticky, strict=True) if not s]
    pooled, resid, dip = [], [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fits = {k: stats.fit_mmpp(calm, t_max, n_states=k, rng=seed) for k in (1, 2)}
    two = fits[2]
    # renewal models on the same windows: every gap a renewal interval (the first from
    # t = 0: an ordinary renewal process), the last gap of each window censored
    first_and_gaps = np.concatenate([np.diff(np.r_[0.0, t]) for t in calm])
    last = np.array([t_max - (t[-1] if t.size else 0.0) for t in calm])
    renewal = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for law in RENEWAL:
            renewal[law] = stats.fit_renewal(first_and_gaps, law, censored=last).aic
    pooled.append({"rule": rule, "n_runs": len(times), "n_sticky": int(sticky.sum()),
                   "n_events": two.n_events, "rate_low": two.rates[0],
                   "rate_high": two.rates[-1], "share_high": two.stationary[-1],
                   "mean_stay_high": two.mean_sojourns[-1],
                   "mean_stay_low": two.mean_sojourns[0], "t_max": t_max,
                   "aic_poisson_minus_mmpp": fits[1].aic - two.aic,
                   **{f"aic_{law}_minus_mmpp": aic - two.aic for law, aic in renewal.items()},
                   "n_best_starts": two.n_best, "n_starts": two.n_starts})
    for k, fit in fits.items():
        rescaled = stats.mmpp_residuals(fit, calm, t_max)
        for row in battery(rescaled.times, rescaled.windows, rng):
            resid.append({"rule": rule, "fit": "pooled", "states": k, **row})
    # per run: each run fitted alone
    chosen = [t for t in calm if t.size >= MMPP_MIN_EVENTS][:per_run]
    per = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, t in enumerate(chosen):
            fit = stats.fit_mmpp(t, t_max, n_states=2, n_starts=6, rng=seed + i)
            per.append(stats.mmpp_residuals(fit, t, t_max))
    if per:
        for row in battery([p.times[0] for p in per], [p.windows[0] for p in per], rng):
            resid.append({"rule": rule, "fit": "per run", "states": 2, **row})
    # the refractory dip
    complete, censored = intervals(calm, t_max)
    haz = stats.interval_hazard(complete, censored, edges=[0.0, DIP, float(
        max(complete.max(), censored.max()))])
    first = haz.table.iloc[0]
    model = mmpp_dip(two)
    # the whole early hazard: its minimum over the bins of EARLY_EDGES and where it falls
    early = _early_hazard(complete, censored)
    ratio = (early.table["hazard"] / early.rate).to_numpy()[:len(EARLY_EDGES) - 1]
    k = int(np.argmin(ratio))
    low_row = early.table.iloc[k]
    a, b = EARLY_EDGES[k], EARLY_EDGES[k + 1]
    boot_rng = np.random.default_rng(seed)
    boot, boot_min = [], []
    for idx in stats.resample_indices(len(calm), N_BOOT, boot_rng, chunk=1):
        pick = [calm[i] for i in idx]
        c, z = intervals(pick, t_max)
        h = stats.interval_hazard(c, z, edges=[0.0, DIP, float(max(c.max(), z.max()))])
        boot.append(h.table["hazard"].iloc[0] / h.rate)
        e = _early_hazard(c, z)
        boot_min.append(e.table["hazard"].iloc[k] / e.rate)  # the data's bin, held fixed
    b_lo, b_hi = percentile_interval(boot)
    m_lo, m_hi = percentile_interval(boot_min)
    m_model = mmpp_bin_hazard(two, a, b)
    m_obs_lo, m_obs_hi = low_row["ci_low"] / early.rate, low_row["ci_high"] / early.rate
    dip.append({"rule": rule, "observed": first["hazard"] / haz.rate,
                "ci_low": first["ci_low"] / haz.rate, "ci_high": first["ci_high"] / haz.rate,
                "boot_low": b_lo, "boot_high": b_hi,
                "mmpp": model, "poisson": 1.0,
                "mean_stay_max": float(max(two.mean_sojourns)), "t_max": t_max,
                "verdict": ("below the MMPP's" if max(first["ci_high"] / haz.rate, b_hi) < model
                            else "above the MMPP's" if min(first["ci_low"] / haz.rate, b_lo) > model
                            else "not distinguished from the MMPP's"),
                "min_bin_low": a, "min_bin_high": b, "min_observed": ratio[k],
                "min_ci_low": m_obs_lo, "min_ci_high": m_obs_hi,
                "min_boot_low": m_lo, "min_boot_high": m_hi, "min_mmpp": m_model,
                "min_verdict": ("below the MMPP's" if max(m_obs_hi, m_hi) < m_model
                                else "above the MMPP's" if min(m_obs_lo, m_lo) > m_model
                                else "not distinguished from the MMPP's")})
    return pooled, resid, dip


def _early_hazard(complete, censored):
    """The hazard of the intervals on `EARLY_EDGES`, the rest of the time one last bin."""
    edges = [*EARLY_EDGES, max(float(complete.max()), float(censored.max()),
                               2 * EARLY_EDGES[-1])]
    return stats.interval_hazard(complete, censored, edges=edges)


def intervals(times, t_max):
    """Complete intervals between collisions and the censored last gaps of each run (the
    first gap, from t = 0, is not an interval after a collision and is left out)."""
    complete = np.concatenate([np.diff(t) for t in times if t.size > 1])
    censored = np.array([t_max - t[-1] for t in times if t.size])
    return complete, censored
