"""Why the disk-disk collisions cluster, measured on runs (issue 29, item 2).

Simulates a moderate ensemble of two-disk runs with their collision logs (radii 0.01 and
0.02, paper ICs and invariant-measure ICs, ``t_max = 2000``) and measures:

1. per collision the angular momenta before and after, the impact parameter and the
   intervals (`kicktimes.diagnostics.mechanism.collision_tables`);
2. the hazard of the intervals against the time since the last collision, in raw time,
   in each run's own time unit (1 / its rate) and in the time rescaled by the predicted
   rate (`kicktimes.stats.interval_hazard`);
3. the share of re-collisions (at most one wall hit of each disk since the previous
   collision) against randomly placed events at the same rate;
4. with `kicktimes.stats.conditional_kinetic_rate`: each IC's predicted rate against its
   observed rate, the pooled interval law as a mixture over the post-collision angular
   momenta against the fitted hyperexponential, and the Poisson battery on Cox twins
   (rate redrawn at every event from the run's own post-collision sequence) next to
   Poisson, mixed-Poisson and observed sequences.

Writes ``mechanism_*.png`` (drawn by ``analysis/mechanism_figures.py``) and
``mechanism_numbers.csv`` (every number docs/mechanism.md quotes) into ``--out``. About
one and a half minutes on two cores::

    python analysis/mechanism.py --out docs/results/mechanism --workers 2
"""

from __future__ import annotations

import argparse
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.stats as sps
from mechanism_figures import write_figures

from kicktimes import initial_conditions, simulate_two_particle, stats
from kicktimes.diagnostics import mechanism

RADII = (0.01, 0.02)
METHODS = ("paper", "uniform")
BATTERY = ("uniformity_ks", "exponential_ks", "exponential_ad", "dispersion")
TWINS = ("poisson", "mixed_poisson", "cox_iid", "cox_sequence", "cox_markov_oos")
#: the models whose explained share is reported; cox_markov_oos is out of sample
EXPLAINERS = ("mixed_poisson", "cox_iid", "cox_sequence", "cox_markov_oos")
#: rescaled time beyond which the Gamma-rescaled hazard is read as one bin
LATE_RESCALED = 5.0
#: states drawn per out-of-sample twin (its path is recycled if a run needs more)
CHAIN_STATES = 600
STICKY_FACTOR = 5.0
#: intervals shorter than this hold the wall round trips (the hazard's peak)
RETURN_TIME = 4.0
#: hazard bins of rescaled times (in units of a mean interval)
RESCALED_EDGES = np.array([0, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1, 1.5,
                           2, 3, 5, 8], float)
#: hazard bins: fine around the wall round trip (~2 time units), geometric beyond
HAZARD_EDGES = np.array([0, 0.5, 1, 1.5, 2, 2.5, 3, 4, 6, 10, 16, 25, 40, 63, 100, 160, 250,
                         400, 630, 1000, 2000], float)


# ------------------------------------------------------------------ simulation
def _simulate(task):
    ic, r, t_max, rule = task
    return simulate_two_particle(ic, r, t_max=t_max, rule=rule, log_collisions=True)


def simulate(n_ics, t_max, workers, seed, rule="mirror"):
    """{(method, r): (ics, runs)} with the same ICs at both radii (drawn at the larger)."""
    out = {}
    with ProcessPoolExecutor(workers) as pool:
        for method in METHODS:
            ics = initial_conditions(n_ics, max(RADII), seed=seed, method=method, rule=rule)
            for r in RADII:
                runs = list(pool.map(_simulate, [(ic, r, t_max, rule) for ic in ics],
                                     chunksize=10))
                out[method, r] = (ics, runs)
    return out


def has_rate() -> bool:
    return hasattr(stats, "conditional_kinetic_rate")


def rate(r, L0, L1, speed0=None, speed1=None):
    """Gamma(r; L0, L1), vectorised (`kicktimes.stats.conditional_kinetic_rate`); with the
    speeds, the elastic rule's rate conditioned on them as well."""
    L0, L1 = np.asarray(L0, float), np.asarray(L1, float)
    if speed0 is None:
        return np.asarray(stats.conditional_kinetic_rate(r, L0, L1), float)
    return np.asarray(stats.conditional_kinetic_rate(
        r, L0, L1, rule="elastic", speed1=np.asarray(speed0, float),
        speed2=np.asarray(speed1, float)), float)


def fit_rate_chain(first, post_by_run, n_bins=10):
    """A first-order Markov chain of the post-collision rate, fitted on training runs.

    The pairs (rate of the state before, rate of the state after) of consecutive
    collisions of each run (the first "before" is the IC's predicted rate) are binned by
    the rate before at its deciles; the chain's step from a rate in bin k draws the next
    rate uniformly from the training pairs' "after" values in bin k. Returns
    ``(edges, pool, counts)``.
    """
    prev = np.concatenate([np.r_[g, p[:-1]] for g, p in zip(first, post_by_run, strict=True)
                           if p.size])
    nxt = np.concatenate([p for p in post_by_run if p.size])
    edges = np.unique(np.quantile(prev, np.linspace(0, 1, n_bins + 1)[1:-1]))
    b = np.digitize(prev, edges)
    counts = np.bincount(b, minlength=edges.size + 1)
    pool = np.full((edges.size + 1, max(int(counts.max()), 1)), np.nan)
    for k in range(edges.size + 1):
        pool[k, :counts[k]] = nxt[b == k] if counts[k] else np.nan
        if not counts[k]:                      # an empty bin steps like the whole sample
            pool[k, :min(nxt.size, pool.shape[1])] = nxt[:pool.shape[1]]
            counts[k] = min(nxt.size, pool.shape[1])
    return edges, pool, counts


def draw_rate_chains(chain, start, n_states, rng):
    """Paths (len(start), n_states + 1) of the chain, each from its start rate."""
    edges, pool, counts = chain
    out = np.empty((len(start), n_states + 1))
    out[:, 0] = cur = np.asarray(start, float)
    for k in range(n_states):
        b = np.digitize(cur, edges)
        cur = pool[b, (rng.random(cur.size) * counts[b]).astype(int)]
        out[:, k + 1] = cur
    return out


# ------------------------------------------------------------------ helpers
def clopper_pearson(k, n):
    """Exact (Clopper-Pearson) 95 % interval of a share ``k / n``."""
    ci = sps.binomtest(int(k), int(n)).proportion_ci(0.95, method="exact")
    return ci.low, ci.high


def _boot_ci(values_fn, n, rng, n_boot=1000):
    picks = rng.integers(0, n, (n_boot, n))
    vals = np.array([values_fn(p) for p in picks], float)
    return tuple(np.nanquantile(vals, [0.025, 0.975]))


def _row(rows, key, quantity, estimate, low=math.nan, high=math.nan, note=""):
    method, r = key
    rows.append({"method": method, "radius": r, "quantity": quantity, "estimate": float(estimate),
                 "ci_low": float(low), "ci_high": float(high), "note": note})


def _peak_row(rows, key, quantity, haz, *, scale):
    """The largest hazard among the first 10 bins (the returns), over ``scale``."""
    tab = haz.table
    i = int(tab["hazard"].iloc[:10].idxmax())
    _row(rows, key, quantity, tab["hazard"].iloc[i] / scale, tab["ci_low"].iloc[i] / scale,
         tab["ci_high"].iloc[i] / scale,
         note=f"bin [{tab['t_low'].iloc[i]:g}, {tab['t_high'].iloc[i]:g})")


def _sup_distance(t, sf_emp, sf_model):
    return float(np.max(np.abs(sf_emp - sf_model(t))))


# ------------------------------------------------------------------ analysis of one group
def analyse(key, ics, runs, *, n_twins, rng, rule="mirror"):
    method, r = key
    rows, data = [], {}
    t_max = runs[0].t_max
    tab = mechanism.collision_tables(runs)
    data["table"] = tab
    n_pp = np.array([run.n_pp for run in runs])
    obs_rate = n_pp / t_max
    gamma = stats.kinetic_rate(r)
    data.update(calm_ic=obs_rate <= STICKY_FACTOR * gamma, return_time=RETURN_TIME)
    _row(rows, key, "n_runs", len(runs))
    _row(rows, key, "n_collisions", n_pp.sum())
    _row(rows, key, "pooled_rate_over_kinetic", obs_rate.mean() / gamma)
    _row(rows, key, "sticky_runs", (obs_rate > STICKY_FACTOR * gamma).sum(),
         note=f"rate > {STICKY_FACTOR:g} kinetic")

    # 2. hazard: raw time, each run's own time unit
    done = ~tab["next_censored"].to_numpy()
    nxt = tab["next_interval"].to_numpy()
    sticky_run = (obs_rate > STICKY_FACTOR * gamma)[tab["run"].to_numpy()]
    data["sticky"] = pd.Series(sticky_run)
    longest = float(nxt.max())
    edges = HAZARD_EDGES[HAZARD_EDGES < longest].tolist() + [longest]
    haz = stats.interval_hazard(nxt[done], nxt[~done], edges=edges)
    data["hazard"] = haz
    calm = ~sticky_run
    data["hazard_nonsticky"] = stats.interval_hazard(nxt[done & calm], nxt[~done & calm],
                                                     edges=edges)
    _row(rows, key, "hazard_first_bin_over_rate", haz.ratio_first_to_rate,
         haz.table["ci_low"].iloc[0] / haz.rate, haz.table["ci_high"].iloc[0] / haz.rate,
         note=f"first bin [0, {haz.table['t_high'].iloc[0]:.3g})")
    _row(rows, key, "hazard_last_bin_over_rate", haz.table["hazard"].iloc[-1] / haz.rate,
         haz.table["ci_low"].iloc[-1] / haz.rate, haz.table["ci_high"].iloc[-1] / haz.rate)
    _row(rows, key, "hazard_flat_lr_pvalue", haz.pvalue, note=f"LR = {haz.statistic:.4g}, "
         f"df = {haz.df}")
    ns = data["hazard_nonsticky"]
    _row(rows, key, "hazard_nonsticky_first_bin_over_rate", ns.ratio_first_to_rate,
         ns.table["ci_low"].iloc[0] / ns.rate, ns.table["ci_high"].iloc[0] / ns.rate)
    _peak_row(rows, key, "hazard_nonsticky_peak_over_rate", ns, scale=ns.rate)
    dip = int(np.flatnonzero(ns.table["t_low"].to_numpy() == 3.0)[0])
    _row(rows, key, "hazard_nonsticky_dip_over_rate", ns.table["hazard"].iloc[dip] / ns.rate,
         ns.table["ci_low"].iloc[dip] / ns.rate, ns.table["ci_high"].iloc[dip] / ns.rate,
         note="bin [3, 4), just after the return peak")
    _row(rows, key, "hazard_nonsticky_flat_lr_pvalue", ns.pvalue,
         note=f"LR = {ns.statistic:.4g}, df = {ns.df}")
    own = np.maximum(obs_rate, 1.0 / t_max)[tab["run"].to_numpy()]
    v = nxt * own
    v_edges = RESCALED_EDGES[RESCALED_EDGES < v.max()].tolist() + [float(v.max())]
    haz_own = stats.interval_hazard(v[done & calm], v[~done & calm], edges=v_edges)
    data["hazard_own"] = haz_own
    _row(rows, key, "hazard_own_time_first_bin_over_rate", haz_own.ratio_first_to_rate,
         haz_own.table["ci_low"].iloc[0] / haz_own.rate,
         haz_own.table["ci_high"].iloc[0] / haz_own.rate,
         note="intervals times the run's own rate; sticky runs left out")
    _peak_row(rows, key, "hazard_own_time_peak_over_rate", haz_own, scale=haz_own.rate)
    _row(rows, key, "hazard_own_time_flat_lr_pvalue", haz_own.pvalue)

    # 3. re-collisions
    rec = mechanism.recollision_share(tab, rng=rng)
    null = mechanism.poisson_recollision_share(runs, n_rep=10, rng=rng)
    data["recollision"], data["recollision_null"] = rec, null
    _row(rows, key, "recollision_share", rec.share, rec.ci_low, rec.ci_high,
         note=f"{rec.n_recollisions} of {rec.n_collisions}; {rec.definition}")
    _row(rows, key, "recollision_share_poisson_null", null.share, null.ci_low, null.ci_high,
         note="Poisson events at each run's rate laid over its wall hits")
    again = ((tab["wall_hits0"] <= 1) & (tab["wall_hits1"] <= 1)
             & tab["interval"].notna()).to_numpy()
    _row(rows, key, "recollisions_in_sticky_runs", (again & sticky_run).sum() / max(again.sum(), 1))
    calm_runs = [run for run, g in zip(runs, obs_rate, strict=True)
                 if g <= STICKY_FACTOR * gamma]
    rec_ns = mechanism.recollision_share(tab[calm], rng=rng)
    null_ns = mechanism.poisson_recollision_share(calm_runs, n_rep=10, rng=rng)
    _row(rows, key, "recollision_share_nonsticky", rec_ns.share, rec_ns.ci_low, rec_ns.ci_high,
         note=f"{rec_ns.n_recollisions} of {rec_ns.n_collisions}; sticky runs left out")
    _row(rows, key, "recollision_share_poisson_null_nonsticky", null_ns.share, null_ns.ci_low,
         null_ns.ci_high)
    # the collision *before* a re-collision: was it glancing?
    before = tab.groupby("run", observed=True)["impact_ratio"].shift(1).to_numpy()
    tab["impact_ratio_before"] = before
    others = ~again & tab["interval"].notna().to_numpy()
    for name, mask in (("recollisions", again & calm), ("others", others & calm)):
        _row(rows, key, f"impact_ratio_median_{name}", np.median(tab["impact_ratio"][mask]),
             note="sticky runs left out")
        _row(rows, key, f"impact_ratio_before_median_{name}", np.median(before[mask]),
             note="impact of the previous collision; sticky runs left out")
    # the angular momenta the previous collision left: radial orbits return through the centre
    spin = np.maximum(np.abs(tab["L0_post"]), np.abs(tab["L1_post"]))
    spin_before = spin.groupby(tab["run"], observed=True).shift(1).to_numpy()
    for name, mask in (("recollisions", again & calm), ("others", others & calm)):
        _row(rows, key, f"max_abs_L_before_median_{name}", np.median(spin_before[mask]),
             note="max |L| left by the previous collision; sticky runs left out")
    _row(rows, key, "contact_radius_median_recollisions",
         np.median(tab["contact_radius"][again & calm]), note="sticky runs left out")
    _row(rows, key, "contact_radius_median_others",
         np.median(tab["contact_radius"][others & calm]), note="sticky runs left out")
    data["wall_hits_null"] = _null_wall_hits(runs, rng)

    # observed Poisson battery
    seqs = [run.pp_times for run in runs]
    obs = _battery(seqs, t_max, rng)
    data["observed"] = obs
    for test in BATTERY:
        k = int(obs["reject"][test].sum())
        low, high = clopper_pearson(k, len(runs))
        obs.setdefault("ci", {})[test] = (low, high)
        _row(rows, key, f"observed_reject_{test}", k / len(runs), low, high)
    _row(rows, key, "observed_dispersion_index", obs["dispersion_index"],
         *_boot_ci(lambda p: _dispersion(n_pp[p]), len(runs), rng))

    if not has_rate():
        return rows, data
    # 4. predicted rates
    pred = np.asarray(mechanism.predicted_rates(ics, r, rule=rule), float)
    speeds = (tab["speed0_post"], tab["speed1_post"]) if rule == "elastic" else ()
    post = rate(r, tab["L0_post"], tab["L1_post"], *speeds)
    tab["rate_post"] = post
    # memory of the state from one collision to the next
    log_rate = np.log(post)
    prev = pd.Series(log_rate).groupby(tab["run"].to_numpy(), observed=True).shift(1).to_numpy()
    ok = np.isfinite(prev)
    _row(rows, key, "lag1_corr_log_rate_post", np.corrcoef(log_rate[ok], prev[ok])[0, 1],
         note="consecutive post-collision states of a run")
    _row(rows, key, "corr_L_pre_post", np.corrcoef(
        np.r_[tab["L0_pre"], tab["L1_pre"]], np.r_[tab["L0_post"], tab["L1_post"]])[0, 1],
         note="each disk's L just before and just after a collision")
    first = np.array([run.pp_times[0] if run.n_pp else t_max for run in runs])
    comp = pred * first + np.bincount(tab["run"], weights=post * nxt, minlength=len(runs))
    data.update(pred=pred, obs_rate=obs_rate, comp_rate=comp / t_max)
    for name, x in (("initial", pred), ("compensator", comp / t_max)):
        rho = sps.spearmanr(x, obs_rate).statistic
        _row(rows, key, f"spearman_observed_vs_{name}_rate", rho,
             *_boot_ci(lambda p, x=x: sps.spearmanr(x[p], obs_rate[p]).statistic,
                       len(runs), rng))
        pos = obs_rate > 0
        rr = np.corrcoef(np.log(x[pos]), np.log(obs_rate[pos]))[0, 1]
        _row(rows, key, f"pearson_log_observed_vs_{name}_rate", rr)
    _row(rows, key, "compensator_over_count", comp.sum() / n_pp.sum(),
         *_boot_ci(lambda p: comp[p].sum() / n_pp[p].sum(), len(runs), rng),
         note="sum of the predicted rate along each run over its collisions")
    _row(rows, key, "initial_prediction_over_kinetic", pred.mean() / gamma)
    sticky_ic = obs_rate > STICKY_FACTOR * gamma
    if sticky_ic.any():
        _row(rows, key, "sticky_count_over_compensator", n_pp[sticky_ic].sum()
             / comp[sticky_ic].sum(), note="observed / predicted collisions in the sticky runs")

    # the pooled interval law: KM, rate mixture, hyperexponential, exponential
    km = sps.ecdf(sps.CensoredData(uncensored=nxt[done], right=nxt[~done])).sf
    t_km, sf_km = km.quantiles, km.probabilities
    mix = stats.rate_mixture(post)
    hyp = stats.fit_renewal(nxt[done], "hyperexponential", censored=nxt[~done])
    expo = stats.fit_renewal(nxt[done], "exponential", censored=nxt[~done])
    data.update(km=(t_km, sf_km), mixture=mix, hyper=hyp, expo=expo)
    late = t_km >= RETURN_TIME
    s_late = sf_km[late][0] if late.any() else math.nan
    for name, sf in (("mixture", mix.sf), ("hyperexponential", hyp.dist.sf),
                     ("exponential", expo.dist.sf)):
        _row(rows, key, f"sup_distance_km_{name}", _sup_distance(t_km, sf_km, sf))
        _row(rows, key, f"sup_distance_km_{name}_after_returns", _sup_distance(
            t_km[late], sf_km[late] / s_late, lambda t, sf=sf: sf(t) / sf(t_km[late][0])),
            note=f"survival conditional on an interval of at least {RETURN_TIME:g}")
    _row(rows, key, "km_survival_at_return_time", s_late,
         note=f"observed S({RETURN_TIME:g}); mixture {float(mix.sf(RETURN_TIME)):.4g}")
    p, l1, l2 = (hyp.params[k] for k in ("p", "rate1", "rate2"))
    _row(rows, key, "hyperexponential_p_fast", p, note=f"rates {l1:.4g}, {l2:.4g}")
    _row(rows, key, "mixture_mean_interval_over_observed",
         mix.mean() / ((nxt.sum()) / done.sum()),
         note="observed: censored-exponential mean (total time / complete intervals)")
    _row(rows, key, "mixture_cv_intervals", math.sqrt(
        2 * float(mix.weights @ (1 / mix.rates ** 2)) / mix.mean() ** 2 - 1))
    _row(rows, key, "observed_cv_intervals", nxt[done].std() / nxt[done].mean())

    # time rescaled by the predicted rate: Exp(1) if the phase-averaged Cox model held
    u = nxt * post
    u_edges = RESCALED_EDGES[RESCALED_EDGES < u.max()].tolist() + [float(u.max())]
    haz_u = stats.interval_hazard(u[done], u[~done], edges=u_edges)
    data["hazard_rescaled"] = haz_u
    _row(rows, key, "rescaled_hazard_first_bin", haz_u.table["hazard"].iloc[0],
         haz_u.table["ci_low"].iloc[0], haz_u.table["ci_high"].iloc[0],
         note=f"first bin [0, {haz_u.table['t_high'].iloc[0]:.3g}) of Gamma t")
    _peak_row(rows, key, "rescaled_hazard_peak", haz_u, scale=1.0)
    _row(rows, key, "rescaled_hazard_rate", haz_u.rate, note="1 if the rate is right on average")
    _row(rows, key, "rescaled_hazard_flat_lr_pvalue", haz_u.pvalue)
    # the long-time end of the same figure, read as one bin: Gamma t > LATE_RESCALED
    late = stats.interval_hazard(u[done], u[~done], edges=[0.0, LATE_RESCALED,
                                                          max(float(u.max()), 2 * LATE_RESCALED)])
    lt = late.table.iloc[1]
    _row(rows, key, "rescaled_hazard_late", lt["hazard"], lt["ci_low"], lt["ci_high"],
         note=f"Gamma-rescaled hazard over rescaled t > {LATE_RESCALED:g} "
         f"({int(lt['events'])} intervals end there); 1 if the phase-averaged rate held")
    for lo_t, hi_t in ((0.2, 1.0), (1.0, LATE_RESCALED)):
        mid = stats.interval_hazard(u[done], u[~done], edges=[0.0, lo_t, hi_t,
                                                             max(float(u.max()), 2 * hi_t)])
        mt = mid.table.iloc[1]
        _row(rows, key, f"rescaled_hazard_{lo_t:g}_{hi_t:g}", mt["hazard"], mt["ci_low"],
             mt["ci_high"], note=f"Gamma-rescaled hazard over rescaled t in [{lo_t:g}, {hi_t:g})")

    # Cox twins through the same battery
    twins = _twins(runs, tab, pred, post, t_max, n_twins, rng)
    _row(rows, key, "oos_chain_states", CHAIN_STATES,
         note="cox_markov_oos: rate chain fitted on the other half of the ICs (even / odd)")
    data["twins"] = twins
    for name, res in twins.items():
        for test in BATTERY:
            share = np.array([b["reject"][test].mean() for b in res])
            _row(rows, key, f"{name}_reject_{test}", share.mean(),
                 *np.quantile(share, [0.025, 0.975]),
                 note=f"mean and 95 % range over {n_twins} twin ensembles")
        d = np.array([b["dispersion_index"] for b in res])
        _row(rows, key, f"{name}_dispersion_index", d.mean(), *np.quantile(d, [0.025, 0.975]))
    for test in ("uniformity_ks", "exponential_ad"):
        _explained(rows, key, test, obs, twins, rng)
    _explained(rows, key, "dispersion_index", obs, twins, rng)
    calm_ic = obs_rate <= STICKY_FACTOR * gamma
    _row(rows, key, "observed_dispersion_index_nonsticky", _dispersion(n_pp[calm_ic]),
         *_boot_ci(lambda p: _dispersion(n_pp[calm_ic][p]), int(calm_ic.sum()), rng))
    for name, res in twins.items():
        d = np.array([_dispersion(b["counts"][calm_ic]) for b in res])
        _row(rows, key, f"{name}_dispersion_index_nonsticky", d.mean(),
             *np.quantile(d, [0.025, 0.975]))
    _explained(rows, key, "dispersion_index", obs, twins, rng, subset=calm_ic,
               suffix="_nonsticky")
    return rows, data


def _dispersion(counts):
    counts = np.asarray(counts, float)
    return counts.var(ddof=1) / counts.mean() if counts.mean() > 0 else math.nan


def _battery(seqs, t_max, rng):
    res = stats.poisson_group(seqs, t_max, n_mc=199, rng=rng)
    per = res.ensemble.per_sequence
    reject = pd.DataFrame({t: (per[f"p_{t}"] < 0.05).to_numpy() for t in BATTERY})
    counts = per["n_events"].to_numpy()
    return {"reject": reject, "counts": counts,
            "dispersion_index": res.homogeneity["dispersion_index"]}


def _twins(runs, tab, pred, post, t_max, n_twins, rng):
    """The battery on n_twins ensembles of each twin model, paired with the runs."""
    by_run = [post[tab["run"].to_numpy() == i] for i in range(len(runs))]
    pooled = np.array([run.n_pp for run in runs]).sum() / (len(runs) * t_max)
    out = {name: [] for name in TWINS}
    # out of sample: each half of the ICs gets the chain fitted on the other half
    half = np.arange(len(runs)) % 2
    chains = {h: fit_rate_chain(pred[half != h], [by_run[i] for i in np.flatnonzero(half != h)])
              for h in (0, 1)}
    for _ in range(n_twins):
        paths = np.empty((len(runs), CHAIN_STATES + 1))
        for h in (0, 1):
            paths[half == h] = draw_rate_chains(chains[h], pred[half == h], CHAIN_STATES, rng)
        draws = {
            "poisson": [stats.simulate_cox_times([pooled], t_max, rng=rng) for _ in runs],
            "mixed_poisson": [stats.simulate_cox_times([g], t_max, rng=rng) for g in pred],
            "cox_iid": [stats.simulate_cox_times(post, t_max, order="iid", rng=rng)
                        for _ in runs],
            "cox_sequence": [stats.simulate_cox_times(np.concatenate([[g], p]), t_max, rng=rng)
                             for g, p in zip(pred, by_run, strict=True)],
            "cox_markov_oos": [stats.simulate_cox_times(path, t_max, rng=rng) for path in paths],
        }
        for name, seqs in draws.items():
            out[name].append(_battery(seqs, t_max, rng))
    return out


def _explained(rows, key, what, obs, twins, rng, *, subset=None, suffix=""):
    """Share of the observed excess over a Poisson process that each twin model
    reproduces, (twin - base) / (observed - base), with a bootstrap over ICs. The base is
    the Poisson value: the level 0.05 for a rejection share (the tests are exact), 1 for
    the index of dispersion (equal windows); the Poisson twins check both."""
    ics = np.flatnonzero(subset) if subset is not None else np.arange(len(obs["counts"]))
    n = ics.size
    base = 1.0 if what == "dispersion_index" else 0.05

    def stat(name, p):
        p = ics[p]
        if what == "dispersion_index":
            return np.mean([_dispersion(b["counts"][p]) for b in twins[name]])
        return np.mean([b["reject"][what].to_numpy()[p].mean() for b in twins[name]])

    def observed(p):
        p = ics[p]
        return (_dispersion(obs["counts"][p]) if what == "dispersion_index"
                else obs["reject"][what].to_numpy()[p].mean())

    for name in EXPLAINERS:
        def ratio(p, name=name):
            with np.errstate(divide="ignore", invalid="ignore"):
                return (stat(name, p) - base) / (observed(p) - base)

        _row(rows, key, f"explained_{what}{suffix}_by_{name}", ratio(np.arange(n)),
             *_boot_ci(ratio, n, rng, n_boot=200),
             note=f"(twin - {base:g}) / (observed - {base:g}); bootstrap over ICs")


def _null_wall_hits(runs, rng):
    """max(wall hits of the two disks) between randomly placed events at each run's rate."""
    out = []
    for run in runs:
        m = rng.poisson(run.n_pp)
        times = np.sort(rng.uniform(0.0, run.t_max, m))
        log = run.boundary_log
        hits = np.zeros((m, 2), int)
        for disk in (0, 1):
            slot = np.searchsorted(times, log.time[log.particle == disk], side="left")
            hits[:, disk] = np.bincount(slot, minlength=m + 1)[:m]
        out.append(hits[1:].max(axis=1))
    return np.concatenate(out)


def state_rates(results, r, n_bins=12):
    """Empirical rate after a collision, binned by the post-collision (L0, L1) (both IC
    families pooled): complete intervals / time at risk per bin, and the bin's mean
    predicted rate."""
    tab = pd.concat([results[m, r]["table"] for m in METHODS if (m, r) in results])
    rho = 1.0 - r
    edges = np.linspace(-rho, rho, n_bins + 1)
    i = np.clip(np.digitize(tab["L0_post"], edges) - 1, 0, n_bins - 1)
    j = np.clip(np.digitize(tab["L1_post"], edges) - 1, 0, n_bins - 1)
    cell = i * n_bins + j
    size = n_bins * n_bins
    events = np.bincount(cell, weights=~tab["next_censored"], minlength=size)
    exposure = np.bincount(cell, weights=tab["next_interval"], minlength=size)
    pred = np.bincount(cell, weights=tab["rate_post"], minlength=size) / np.maximum(
        np.bincount(cell, minlength=size), 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        emp = events / exposure
    return edges, emp.reshape(n_bins, n_bins), pred.reshape(n_bins, n_bins), \
        events.reshape(n_bins, n_bins)


# ------------------------------------------------------------------ main
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="docs/results/mechanism")
    ap.add_argument("--n-ics", type=int, default=200)
    ap.add_argument("--t-max", type=float, default=2000.0)
    ap.add_argument("--twins", type=int, default=20, help="twin ensembles per model (20)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=29)
    ap.add_argument("--rule", choices=("mirror", "elastic"), default="mirror",
                    help="collision rule; elastic: rates conditioned on the speeds too")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    groups = simulate(args.n_ics, args.t_max, args.workers, args.seed, args.rule)
    print(f"simulated {sum(len(v[1]) for v in groups.values())} runs in "
          f"{time.perf_counter() - t0:.0f} s", flush=True)
    if not has_rate():
        print("stats.conditional_kinetic_rate is missing: the predicted-rate parts are skipped")
    rng = np.random.default_rng(args.seed)
    rows, results = [], {}
    for key, (ics, runs) in groups.items():
        part, results[key] = analyse(key, ics, runs, n_twins=args.twins, rng=rng,
                                     rule=args.rule)
        rows += part
        print(f"analysed {key} at {time.perf_counter() - t0:.0f} s", flush=True)
    if has_rate():
        for r in RADII:
            _, emp, pred, events = state_rates(results, r)
            ok = events >= 10
            w = events[ok]
            x, y = np.log(pred[ok]), np.log(emp[ok])
            xm, ym = np.average(x, weights=w), np.average(y, weights=w)
            corr = (np.average((x - xm) * (y - ym), weights=w)
                    / math.sqrt(np.average((x - xm) ** 2, weights=w)
                                * np.average((y - ym) ** 2, weights=w)))
            slope = np.average((x - xm) * (y - ym), weights=w) / np.average((x - xm) ** 2,
                                                                             weights=w)
            _row(rows, ("pooled", r), "cell_rate_log_correlation", corr,
                 note=f"{int(ok.sum())} (L0, L1) cells with >= 10 collisions, weighted by "
                 "collisions")
            _row(rows, ("pooled", r), "cell_rate_log_slope", slope,
                 note="weighted LS slope of log observed on log predicted cell rate")
            gamma = stats.kinetic_rate(r)
            # corner cells: (i, j) indexes (L0, L1) from -rho to rho
            for (i, j), name in (((0, -1), "counter_rotating_-+"), ((-1, 0), "counter_rotating_+-"),
                                 ((0, 0), "co_rotating_--"), ((-1, -1), "co_rotating_++")):
                _row(rows, ("pooled", r), f"cell_rate_rim_{name}", emp[i, j] / gamma,
                     note=f"corner cell (signs of L0, L1), over the kinetic rate; predicted "
                     f"{pred[i, j] / gamma:.3g}; {int(events[i, j])} collisions")
    for name, value in (("n_ics", args.n_ics), ("t_max", args.t_max), ("twins", args.twins),
                        ("seed", args.seed)):
        _row(rows, ("run", math.nan), name, value, note=f"rule {args.rule}")
    table = pd.DataFrame(rows)
    table.insert(0, "rule", args.rule)
    table.to_csv(out / "mechanism_numbers.csv", index=False, float_format="%.6g")
    cells = {r: state_rates(results, r) for r in RADII} if has_rate() else None
    write_figures(results, out, cells=cells, rate=rate)
    print(f"wrote {out} in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
