"""The MMPP study's fits and checks: pooled and per-run MMPP fits to the two-disk
collision times, their time-rescaling residuals through the Poisson battery, and the
refractory dip against the fitted MMPP's exact hazard."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.linalg import expm

from kicktimes import stats
from kicktimes.stats import (
    MMPP_MIN_EVENTS,
    equivalence_sample_size,
    null_reading,
    percentile_interval,
    rejection_verdict,
)
from kicktimes.stats.findings import clopper_pearson

__all__ = ["CHOICE_COLUMNS", "DIP", "EARLY_EDGES", "N_BOOT", "N_MC", "PER_RUN_STARTS",
           "RENEWAL", "SHARE_MARGIN", "TESTS", "analyse", "battery", "choice_rows",
           "edge_null_verdict",
           "intervals", "mmpp_bin_hazard", "mmpp_dip", "null_rows", "rejections",
           "shuffled_twin"]

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
#: EM starts of a run fitted alone (its MMPP-2, and those of its twins, fitted the same way)
PER_RUN_STARTS = 6
#: the margin of a share read against its null stream's share (`null_verdict` on the CI
#: of share - null share), stated in advance: half of α = 0.05, the half-width of the band
#: `rejection_verdict` allows a rejection share around α
SHARE_MARGIN = 0.025
#: the columns of `choice_rows`' table (a rule without runs fitted alone has no row)
CHOICE_COLUMNS = ("rule", "n_runs", "n_best_billiard", "share_billiard", "ci_low_billiard",
                  "ci_high_billiard", "n_best_shuffled", "share_shuffled", "ci_low_shuffled",
                  "ci_high_shuffled", "share_beats_poisson", "difference", "diff_low",
                  "diff_high", "margin", "verdict", "n_to_resolve")


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


def rejections(times, windows, rng) -> dict:
    """Per test of `TESTS`, which windows' rescaled times the Poisson battery rejects at
    α = 0.05 (raw per-window p-values, before any FDR): a boolean array per test."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = stats.test_poisson_ensemble(times, windows, n_mc=N_MC, rng=rng)
    per = res.per_sequence
    return {test: (per[f"p_{test}"] < 0.05).to_numpy() for test in TESTS}


def battery(times, windows, rng):
    """Share of windows whose rescaled times reject each test, with its interval."""
    return _battery_rows(rejections(times, windows, rng))


def _battery_rows(rejected):
    rows = []
    for test in TESTS:
        k, n = int(rejected[test].sum()), len(rejected[test])
        lo, hi = clopper_pearson(k, n)
        rows.append({"test": test, "n_windows": n, "rejected": k, "share": k / n,
                     "ci_low": lo, "ci_high": hi, "verdict": rejection_verdict(lo, hi, alpha=0.05)})
    return rows


def analyse(rule, times, sticky, t_max, per_run, seed):
    """The rows of the five tables for one collision rule: the pooled fits (``pooled``),
    the time-rescaling residual checks (``resid``), the refractory dip (``dip``), the
    per-run model choice against shuffled twins (``choice``, `choice_rows`) and the
    residual checks against their calibrated null (``nulls``, `null_rows`), from the
    runs' collision ``times`` with the ``sticky`` ones left out; the per-run fits take
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
    observed = {}
    for k, fit in fits.items():
        rescaled = stats.mmpp_residuals(fit, calm, t_max)
        observed[("pooled", k)] = rejections(rescaled.times, rescaled.windows, rng)
        for row in _battery_rows(observed[("pooled", k)]):
            resid.append({"rule": rule, "fit": "pooled", "states": k, **row})
    # per run: each run fitted alone
    chosen = [t for t in calm if t.size >= MMPP_MIN_EVENTS][:per_run]
    per, per_fits = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, t in enumerate(chosen):
            fit = stats.fit_mmpp(t, t_max, n_states=2, n_starts=PER_RUN_STARTS, rng=seed + i)
            per_fits.append(fit)
            per.append(stats.mmpp_residuals(fit, t, t_max))
    if per:
        observed[("per run", 2)] = rejections([p.times[0] for p in per],
                                              [p.windows[0] for p in per], rng)
        for row in _battery_rows(observed[("per run", 2)]):
            resid.append({"rule": rule, "fit": "per run", "states": 2, **row})
    nulls = null_rows(rule, observed, fits, per_fits, len(calm), t_max, seed)
    choice = choice_rows(rule, chosen, t_max, seed)
    # the refractory dip
    complete, censored = intervals(calm, t_max)
    haz = stats.interval_hazard(complete, censored=censored, edges=[0.0, DIP, float(
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
    for idx in stats.resample_indices(len(calm), n_boot=N_BOOT, rng=boot_rng, chunk=1):
        pick = [calm[i] for i in idx]
        c, z = intervals(pick, t_max)
        h = stats.interval_hazard(c, censored=z, edges=[0.0, DIP, float(max(c.max(), z.max()))])
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
    return pooled, resid, dip, choice, nulls


def _early_hazard(complete, censored):
    """The hazard of the intervals on `EARLY_EDGES`, the rest of the time one last bin."""
    edges = [*EARLY_EDGES, max(float(complete.max()), float(censored.max()),
                               2 * EARLY_EDGES[-1])]
    return stats.interval_hazard(complete, censored=censored, edges=edges)


def intervals(times, t_max):
    """Complete intervals between collisions and the censored last gaps of each run (the
    first gap, from t = 0, is not an interval after a collision and is left out)."""
    complete = np.concatenate([np.diff(t) for t in times if t.size > 1])
    censored = np.array([t_max - t[-1] for t in times if t.size])
    return complete, censored


def edge_null_verdict(low, high, margin=SHARE_MARGIN):
    """`kicktimes.stats.null_reading` of the CI of a share's difference from its null share,
    at the page's margin `SHARE_MARGIN` (a CI that excludes 0 but crosses the margin's edge
    says on which side; ``"inconclusive"`` only for a CI that contains 0).

    Examples
    --------
    >>> edge_null_verdict(0.015, 0.13), edge_null_verdict(-0.05, 0.07)
    ('above its null, size unresolved', 'inconclusive')
    >>> edge_null_verdict(0.033, 0.116), edge_null_verdict(-0.02, -0.01)
    ('above its null', 'at its null')
    """
    return null_reading(low, high, margin=margin)


def _difference(a, b, rng, margin=SHARE_MARGIN):
    """Share of ``a`` minus share of ``b`` (boolean arrays of independent units) with its
    95 % bootstrap interval (each arm resampled on its own), its `null_verdict` and the
    units per arm that would resolve ``margin`` (`equivalence_sample_size`)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    ia = stats.resample_indices(a.size, n_boot=N_BOOT, rng=rng)
    ib = stats.resample_indices(b.size, n_boot=N_BOOT, rng=rng)
    boot = a[ia].mean(1) - b[ib].mean(1)
    lo, hi = percentile_interval(boot)
    se = float(np.std(boot, ddof=1))
    n = int(min(a.size, b.size))
    return {"difference": a.mean() - b.mean(), "diff_low": lo, "diff_high": hi,
            "margin": margin, "verdict": edge_null_verdict(lo, hi, margin),
            "n_to_resolve": equivalence_sample_size(se, n, margin=margin) if se > 0 else n}


def shuffled_twin(t, t_max, rng):
    """The run ``t`` with its intervals (the first gap from 0 included) in random order:
    the same interval law and censored end, every dependence between intervals gone."""
    gaps = np.diff(np.r_[0.0, np.asarray(t, float)])
    out = np.cumsum(rng.permutation(gaps))
    return out[out < t_max]


def choice_rows(rule, chosen, t_max, seed):
    """Per run of ``chosen`` (the runs fitted alone), whether the MMPP-2 is its AIC-best
    model among Poisson, the renewal models and the MMPP-2
    (`kicktimes.stats.compare_point_processes`, `PER_RUN_STARTS` starts), against the same
    on the run's `shuffled_twin`: the null level of "AIC-best" when the intervals are
    independent with the run's own law. One row per rule: both shares with their
    Clopper-Pearson intervals and their difference read against the twins'
    (`_difference`)."""
    rng = np.random.default_rng((seed, 2))
    best = {"billiard": [], "shuffled": []}
    beats = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, t in enumerate(chosen):
            for data, seq in (("billiard", t), ("shuffled", shuffled_twin(t, t_max, rng))):
                tab = stats.compare_point_processes(seq, t_max, n_starts=PER_RUN_STARTS,
                                                    rng=seed + i)
                best[data].append(tab.index[0] == "mmpp2")
                if data == "billiard":
                    beats.append(tab.loc["mmpp2", "aic"] < tab.loc["poisson", "aic"])
    if not chosen:
        return []
    row = {"rule": rule, "n_runs": len(chosen)}
    for data, flags in best.items():
        k = int(np.sum(flags))
        lo, hi = clopper_pearson(k, len(flags))
        row.update({f"n_best_{data}": k, f"share_{data}": k / len(flags),
                    f"ci_low_{data}": lo, f"ci_high_{data}": hi})
    row["share_beats_poisson"] = float(np.mean(beats))
    row.update(_difference(best["billiard"], best["shuffled"], rng))
    return [row]


def _null_windows(fit, n, t_max, rng, min_events=0, tries=50):
    """``n`` windows simulated from ``fit``, each redrawn until it has ``min_events``."""
    out = []
    for _ in range(n):
        for _ in range(tries):
            w = np.asarray(stats.simulate_mmpp(fit.rates, fit.generator, t_max, rng=rng), float)
            if w.size >= min_events:
                break
        out.append(w)
    return out


def null_rows(rule, observed, fits, per_fits, n_windows, t_max, seed):
    """The residual checks' calibrated null: the battery's rejection share on windows
    simulated from each fit, fitted and rescaled the same way (pooled: ``n_windows``
    windows from the pooled fit, refitted pooled; per run: one window from each run's own
    fit with at least `MMPP_MIN_EVENTS` events, refitted alone), beside the billiard's
    share (``observed``: `rejections` per (fit, states)) and their difference read
    against it (`_difference`, `null_verdict` with `SHARE_MARGIN`)."""
    rng = np.random.default_rng((seed, 3))
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        null = {}
        for k, fit in fits.items():
            sim = _null_windows(fit, n_windows, t_max, rng)
            refit = stats.fit_mmpp(sim, t_max, n_states=k, rng=seed)
            res = stats.mmpp_residuals(refit, sim, t_max)
            null[("pooled", k)] = rejections(res.times, res.windows, rng)
        if per_fits:
            times, windows = [], []
            for i, fit in enumerate(per_fits):
                (w,) = _null_windows(fit, 1, t_max, rng, min_events=MMPP_MIN_EVENTS)
                refit = stats.fit_mmpp(w, t_max, n_states=2, n_starts=PER_RUN_STARTS,
                                       rng=seed + i)
                res = stats.mmpp_residuals(refit, w, t_max)
                times.append(res.times[0])
                windows.append(res.windows[0])
            null[("per run", 2)] = rejections(times, windows, rng)
    for (fit, k), got in observed.items():
        for test in TESTS:
            ref = null[(fit, k)][test]
            lo, hi = clopper_pearson(int(ref.sum()), ref.size)
            rows.append({"rule": rule, "fit": fit, "states": k, "test": test,
                         "n_windows": int(got[test].size), "share": float(got[test].mean()),
                         "n_null": int(ref.size), "null_share": float(ref.mean()),
                         "null_ci_low": lo, "null_ci_high": hi,
                         "null_vs_alpha": rejection_verdict(lo, hi, alpha=0.05),
                         **_difference(got[test], ref, rng)})
    return rows
