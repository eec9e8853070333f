"""The numbers of the mechanism study: one group (IC family, radius) at a time.

`analyse` measures, on the runs of one group: per collision the angular momenta before
and after, the impact parameter and the intervals
(`kicktimes.diagnostics.mechanism.collision_tables`); the hazard of the intervals in raw
time, in each run's own time unit and in the time rescaled by the predicted rate
(`kicktimes.stats.interval_hazard`); the share of re-collisions against randomly placed
events; each IC's predicted rate against its observed rate; the pooled interval law as a
mixture over the post-collision states against the hyperexponential fit; and the Poisson
battery on the twins of `kicktimes.studies.mechanism.twins` with the share of the
observed excess each reproduces (`explained`). `state_rates` and `cell_rows` pool both IC
families per radius by the post-collision (L0, L1).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import scipy.stats as sps

from kicktimes import stats
from kicktimes.diagnostics import mechanism
from kicktimes.stats import STICKY_FACTOR
from kicktimes.studies.mechanism.simulate import METHODS
from kicktimes.studies.mechanism.twins import (
    BATTERY,
    CHAIN_STATES,
    battery,
    dispersion,
    rate,
    twin_batteries,
)

__all__ = [
    "EXPLAINERS", "HAZARD_EDGES", "LATE_RESCALED", "NULL_DRAWS", "RATE_DISPERSION_MARGIN",
    "HAZARD_NULL_MARGIN", "RETURN_TIME", "STICKY_FACTOR", "analyse", "cell_rows",
    "hazard_profile_rows", "against_null", "poisson_null_rows", "state_rates",
]

#: the models whose explained share is reported; cox_markov_oos is out of sample
EXPLAINERS = ("mixed_poisson", "cox_iid", "cox_sequence", "cox_markov_oos")
#: rescaled time beyond which the Gamma-rescaled hazard is read as one bin
LATE_RESCALED = 5.0
#: intervals shorter than this hold the wall round trips (the hazard's peak)
RETURN_TIME = 4.0
#: Poisson ensembles drawn for the null of the rate dispersion across ICs
NULL_DRAWS = 4000
#: the margin of the rate dispersion across ICs against its null (`stats.null_verdict`):
#: the same var / mean of counts as D, so D's margin, `stats.D_MARGIN`; the smallest excess
#: the page reads is over 1, so the margin is far below the effect it resolves
RATE_DISPERSION_MARGIN = stats.D_MARGIN
#: the margin of an early hazard bin over the rate against its null: the first hazard
#: bin's margin of docs/definitions.md (`kicktimes.report.controls.SHAPE_MARGIN`)
HAZARD_NULL_MARGIN = 0.05
#: hazard bins of rescaled times (in units of a mean interval)
RESCALED_EDGES = np.array([0, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1, 1.5,
                           2, 3, 5, 8], float)
#: hazard bins: fine around the wall round trip (~2 time units), geometric beyond
HAZARD_EDGES = np.array([0, 0.5, 1, 1.5, 2, 2.5, 3, 4, 6, 10, 16, 25, 40, 63, 100, 160, 250,
                         400, 630, 1000, 2000], float)




def _boot_ci(values_fn, n, rng, n_boot=1000):
    picks = stats.resample_indices(n, n_boot=n_boot, rng=rng)
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


def hazard_profile_rows(key, runs):
    r"""The early hazard of the next collision read bin by bin, not by its first bin alone.

    Over every bin of :data:`HAZARD_EDGES` that ends by :data:`RETURN_TIME` (the refractory
    time and the wall round trips, [0, 0.5) to [3, 4)), the hazard of the intervals after
    a collision, sticky runs left out, over the pooled rate, with its 95 % Garwood
    interval: one row per bin, the minimum and the bin where it falls, and the number of
    bins whose interval lies wholly below the 10 % band (`kicktimes.stats.ratio_verdict`
    "lower"). The same `kicktimes.stats.interval_hazard` as :func:`analyse`'s
    ``hazard_nonsticky_*`` rows, so the bin [0, 0.5) is its first-bin row.

    Parameters
    ----------
    key : tuple
        ``(method, r)``.
    runs : sequence
        The group's runs (simulated with ``log_collisions=True``).

    Returns
    -------
    list of dict
        Rows of ``mechanism_numbers.csv``: ``hazard_nonsticky_bin_<a>_<b>_over_rate``,
        ``hazard_nonsticky_min_over_rate`` (note: its bin) and
        ``hazard_nonsticky_bins_lower`` (estimate: the count; note: the bins, of how many).

    Notes
    -----
    The minimum of several bins is a selected value: its Garwood interval is that of its
    own bin, not adjusted for the choice; the count of bins lower than the rate, each by
    its own interval, is the reading that does not select.
    """
    method, r = key
    rows = []
    t_max = runs[0].t_max
    tab = mechanism.collision_tables(runs)
    obs_rate = np.array([run.n_pp for run in runs]) / t_max
    calm = ~stats.is_sticky(obs_rate, stats.kinetic_rate(r))[tab["run"].to_numpy()]
    done = ~tab["next_censored"].to_numpy()
    nxt = tab["next_interval"].to_numpy()
    edges = HAZARD_EDGES[HAZARD_EDGES < float(nxt.max())].tolist() + [float(nxt.max())]
    ns = stats.interval_hazard(nxt[done & calm], censored=nxt[~done & calm], edges=edges)
    early = ns.table[ns.table["t_high"] <= RETURN_TIME].reset_index(drop=True)
    ratio = early["hazard"] / ns.rate
    low, high = early["ci_low"] / ns.rate, early["ci_high"] / ns.rate
    for k in range(len(early)):
        a, b = early["t_low"].iloc[k], early["t_high"].iloc[k]
        _row(rows, key, f"hazard_nonsticky_bin_{a:g}_{b:g}_over_rate", ratio.iloc[k],
             low.iloc[k], high.iloc[k], note=f"bin [{a:g}, {b:g})")
    i = int(np.argmin(ratio.to_numpy()))
    _row(rows, key, "hazard_nonsticky_min_over_rate", ratio.iloc[i], low.iloc[i], high.iloc[i],
         note=f"bin [{early['t_low'].iloc[i]:g}, {early['t_high'].iloc[i]:g})")
    lower = [k for k in range(len(early))
             if stats.ratio_verdict(low.iloc[k], high.iloc[k]) == "lower"]
    _row(rows, key, "hazard_nonsticky_bins_lower", len(lower),
         note=f"of {len(early)} bins below t = {RETURN_TIME:g}: " + (", ".join(
             f"[{early['t_low'].iloc[k]:g}, {early['t_high'].iloc[k]:g})" for k in lower)
             or "none"))
    return rows


def poisson_null_rows(key, runs, *, rng, n_draws=NULL_DRAWS):
    r"""The page's statistics on Poisson streams shaped like the group's calm runs.

    Two nulls, both over the calm runs (sticky runs left out, as the statistics are):

    - the *rate dispersion across ICs*, the index of dispersion var / mean (``ddof = 1``)
      of the whole-run collision counts over the group's ICs (the row
      ``observed_dispersion_index_nonsticky`` of :func:`analyse`; not the within-run D of
      counts in windows of one run). Its null is the same statistic on a Poisson ensemble
      of the same design: as many ICs, each a Poisson count at the calm runs' mean count;
      close to 1 but not exactly 1, drawn by Monte Carlo (``n_draws`` ensembles);
    - the *early hazard* over the pooled rate, per bin ``[a, b)`` of
      :data:`HAZARD_EDGES` up to :data:`RETURN_TIME`: on Poisson streams at each run's own
      rate :math:`\lambda_i = n_i / T` with its :math:`n_i` intervals, a bin's events and
      exposure are :math:`n_i (e^{-\lambda_i a} - e^{-\lambda_i b})` and that over
      :math:`\lambda_i`, so the pooled hazard over the pooled rate is
      :math:`\sum_i n_i \Delta_i / \sum_i n_i \Delta_i / \lambda_i` over
      :math:`\sum_i n_i / \sum_i T`, above 1 where the rates differ between runs (a rate
      mixture's hazard falls); exact, no draw.

    Parameters
    ----------
    key : tuple
        ``(method, r)``.
    runs : sequence
        The group's runs (``n_pp`` and ``t_max`` are read).
    rng : numpy.random.Generator
        The generator of the Poisson ensembles.
    n_draws : int
        Poisson ensembles drawn.

    Returns
    -------
    list of dict
        Rows ``rate_dispersion_poisson_null`` (estimate: the mean over the ensembles;
        interval: their 2.5 and 97.5 % percentiles, the null's spread at this design),
        ``rate_dispersion_poisson_null_mc_se`` (the Monte Carlo standard error of that
        mean) and ``hazard_nonsticky_bin_<a>_<b>_poisson_null`` per early bin (note: the
        bin).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> runs = [SimpleNamespace(n_pp=40, t_max=2000.0) for _ in range(200)]
    >>> rows = poisson_null_rows(("paper", 0.01), runs, rng=np.random.default_rng(0))
    >>> round(rows[0]["estimate"], 2), rows[0]["ci_low"] < 1 < rows[0]["ci_high"]
    (1.0, True)
    >>> round(rows[2]["estimate"], 12), rows[2]["note"]   # equal rates: a flat hazard
    (1.0, 'bin [0, 0.5)')
    """
    if not (isinstance(n_draws, int | np.integer) and n_draws >= 2):
        raise ValueError(f"n_draws must be an integer >= 2, got {n_draws!r}")
    method, r = key
    t_max = runs[0].t_max
    n_pp = np.array([run.n_pp for run in runs], float)
    counts = n_pp[n_pp / t_max <= STICKY_FACTOR * stats.kinetic_rate(r)]
    if counts.size < 2 or counts.mean() <= 0:
        raise ValueError(f"runs: the group {method}, r = {r:g} has fewer than two calm runs "
                         "with collisions; its nulls are undefined")
    draws = rng.poisson(counts.mean(), size=(int(n_draws), counts.size)).astype(float)
    mean = draws.mean(axis=1)
    d = draws.var(axis=1, ddof=1) / np.where(mean > 0, mean, np.nan)
    d = d[np.isfinite(d)]
    rows = []
    _row(rows, key, "rate_dispersion_poisson_null", d.mean(), *stats.percentile_interval(d),
         note=f"var / mean of {counts.size} Poisson counts at the calm runs' mean count "
         f"{counts.mean():.4g}; {d.size} ensembles")
    _row(rows, key, "rate_dispersion_poisson_null_mc_se", d.std(ddof=1) / math.sqrt(d.size),
         note="Monte Carlo standard error of the null's mean")
    n = counts[counts > 0]
    lam = n / t_max
    rate = n.sum() / (n.size * t_max)
    edges = HAZARD_EDGES[HAZARD_EDGES <= RETURN_TIME]
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        part = n * (np.exp(-lam * a) - np.exp(-lam * b))
        _row(rows, key, f"hazard_nonsticky_bin_{a:g}_{b:g}_poisson_null",
             part.sum() / (part / lam).sum() / rate, note=f"bin [{a:g}, {b:g})")
    return rows


def against_null(table):
    """The page's statistics minus their Poisson nulls (:func:`poisson_null_rows`), per
    group of ``table``, each with `stats.null_verdict` in its note.

    - ``rate_dispersion_minus_null``: the rate dispersion across ICs
      (``observed_rate_dispersion_across_ics_nonsticky``, `analyse`'s
      ``observed_dispersion_index_nonsticky`` as the CSV names it; bootstrap interval over
      ICs) minus the
      null's mean, margin :data:`RATE_DISPERSION_MARGIN`;
    - ``hazard_first_bin_minus_null`` and ``hazard_min_minus_null``: the hazard over the
      rate in the first bin and in the bin of the early minimum
      (``hazard_nonsticky_first_bin_over_rate``, ``hazard_nonsticky_min_over_rate``,
      Garwood intervals) minus the null of that bin, margin :data:`HAZARD_NULL_MARGIN`.

    The interval of a difference is the statistic's interval shifted by the null (the
    nulls' own errors, a Monte Carlo standard error or none, are far below it).

    Examples
    --------
    >>> t = pd.DataFrame({"rule": "mirror", "method": "paper", "radius": 0.01,
    ...     "quantity": ["observed_rate_dispersion_across_ics_nonsticky",
    ...                  "rate_dispersion_poisson_null"],
    ...     "estimate": [2.5, 1.01], "ci_low": [2.0, 0.8], "ci_high": [3.0, 1.2], "note": ""})
    >>> row = against_null(t)[0]
    >>> round(row["estimate"], 2), round(row["ci_low"], 2), row["note"][:15]
    (1.49, 0.99, 'above its null ')
    """
    rows = []
    for (method, r), g in table.groupby(["method", "radius"], sort=False):
        q = g.set_index("quantity")
        reads = [("rate_dispersion_minus_null", "observed_rate_dispersion_across_ics_nonsticky",
                  "rate_dispersion_poisson_null", RATE_DISPERSION_MARGIN)]
        if "hazard_nonsticky_min_over_rate" in q.index:
            low = q.loc["hazard_nonsticky_min_over_rate", "note"].removeprefix("bin [")
            a, b = low.rstrip(")").split(", ")
            reads += [("hazard_first_bin_minus_null", "hazard_nonsticky_first_bin_over_rate",
                       f"hazard_nonsticky_bin_0_{HAZARD_EDGES[1]:g}_poisson_null",
                       HAZARD_NULL_MARGIN),
                      ("hazard_min_minus_null", "hazard_nonsticky_min_over_rate",
                       f"hazard_nonsticky_bin_{a}_{b}_poisson_null", HAZARD_NULL_MARGIN)]
        for name, stat, null_name, margin in reads:
            if not {stat, null_name} <= set(q.index):
                continue
            obs, null = q.loc[stat], q.loc[null_name]
            lo, hi = obs["ci_low"] - null["estimate"], obs["ci_high"] - null["estimate"]
            verdict = stats.null_verdict(lo, hi, margin=margin)
            _row(rows, (method, r), name, obs["estimate"] - null["estimate"], lo, hi,
                 note=f"{verdict} (stats.null_verdict, margin {margin:g}); null "
                 f"{null['estimate']:.4f}")
    for row in rows:
        row["rule"] = table["rule"].iloc[0]
    return rows


def _sup_distance(t, sf_emp, sf_model):
    return float(np.max(np.abs(sf_emp - sf_model(t))))


def analyse(key, ics, runs, *, n_twins, rng, rule="mirror", n_boot=1000):
    """Every number of one group (IC family, radius) and the data of its figures.

    ``key`` is ``(method, r)``; ``ics`` and ``runs`` the group's ICs and runs (simulated
    with ``log_collisions=True``); ``n_twins`` the twin ensembles per model; ``rng`` the
    generator every random draw of the analysis takes (shared across groups, in order);
    ``n_boot`` the resamples of its bootstrap intervals over ICs (the explained shares
    take 200).
    Returns ``(rows, data)``: the rows of ``mechanism_numbers.csv`` and a dict of tables,
    hazards, fits and batteries for `kicktimes.studies.mechanism.figures`.
    """
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
    _row(rows, key, "sticky_runs", stats.is_sticky(obs_rate, gamma).sum(),
         note=f"rate > {STICKY_FACTOR:g} kinetic")

    # 2. hazard: raw time, each run's own time unit
    done = ~tab["next_censored"].to_numpy()
    nxt = tab["next_interval"].to_numpy()
    sticky_run = stats.is_sticky(obs_rate, gamma)[tab["run"].to_numpy()]
    data["sticky"] = pd.Series(sticky_run)
    longest = float(nxt.max())
    edges = HAZARD_EDGES[HAZARD_EDGES < longest].tolist() + [longest]
    haz = stats.interval_hazard(nxt[done], censored=nxt[~done], edges=edges)
    data["hazard"] = haz
    calm = ~sticky_run
    data["hazard_nonsticky"] = stats.interval_hazard(nxt[done & calm], censored=nxt[~done & calm],
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
    haz_own = stats.interval_hazard(v[done & calm], censored=v[~done & calm], edges=v_edges)
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
    obs = battery(seqs, t_max, rng)
    data["observed"] = obs
    for test in BATTERY:
        k = int(obs["reject"][test].sum())
        low, high = stats.clopper_pearson(int(k), len(runs))
        obs.setdefault("ci", {})[test] = (low, high)
        _row(rows, key, f"observed_reject_{test}", k / len(runs), low, high)
    _row(rows, key, "observed_dispersion_index", obs["dispersion_index"],
         *_boot_ci(lambda p: dispersion(n_pp[p]), len(runs), rng, n_boot))

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
                       len(runs), rng, n_boot))
        pos = obs_rate > 0
        rr = np.corrcoef(np.log(x[pos]), np.log(obs_rate[pos]))[0, 1]
        _row(rows, key, f"pearson_log_observed_vs_{name}_rate", rr)
    _row(rows, key, "compensator_over_count", comp.sum() / n_pp.sum(),
         *_boot_ci(lambda p: comp[p].sum() / n_pp[p].sum(), len(runs), rng, n_boot),
         note="sum of the predicted rate along each run over its collisions")
    _row(rows, key, "initial_prediction_over_kinetic", pred.mean() / gamma)
    sticky_ic = stats.is_sticky(obs_rate, gamma)
    if sticky_ic.any():
        _row(rows, key, "sticky_count_over_compensator", n_pp[sticky_ic].sum()
             / comp[sticky_ic].sum(), note="observed / predicted collisions in the sticky runs")

    # the pooled interval law: KM, rate mixture, hyperexponential, exponential
    km = sps.ecdf(sps.CensoredData(uncensored=nxt[done], right=nxt[~done])).sf
    t_km, sf_km = km.quantiles, km.probabilities
    mix = stats.rate_mixture(post)
    hyp = stats.fit_renewal(nxt[done], "hyperexponential", censored=nxt[~done])
    expo = stats.fit_renewal(nxt[done], "exponential", censored=nxt[~done])
    with warnings.catch_warnings():           # Greenwood's band is undefined where S = 0
        warnings.simplefilter("ignore", RuntimeWarning)
        band = km.confidence_interval(0.95)   # no random draw: the numbers stay the same
    data.update(km=(t_km, sf_km), km_ci=(np.nan_to_num(band.low.probabilities),
                                         np.nan_to_num(band.high.probabilities, nan=1.0)),
                mixture=mix, hyper=hyp, expo=expo)
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
    haz_u = stats.interval_hazard(u[done], censored=u[~done], edges=u_edges)
    data["hazard_rescaled"] = haz_u
    _row(rows, key, "rescaled_hazard_first_bin", haz_u.table["hazard"].iloc[0],
         haz_u.table["ci_low"].iloc[0], haz_u.table["ci_high"].iloc[0],
         note=f"first bin [0, {haz_u.table['t_high'].iloc[0]:.3g}) of Gamma t")
    _peak_row(rows, key, "rescaled_hazard_peak", haz_u, scale=1.0)
    _row(rows, key, "rescaled_hazard_rate", haz_u.rate, note="1 if the rate is right on average")
    _row(rows, key, "rescaled_hazard_flat_lr_pvalue", haz_u.pvalue)
    # the long-time end of the same figure, read as one bin: Gamma t > LATE_RESCALED
    late = stats.interval_hazard(u[done], censored=u[~done], edges=[0.0, LATE_RESCALED,
                                                          max(float(u.max()), 2 * LATE_RESCALED)])
    lt = late.table.iloc[1]
    _row(rows, key, "rescaled_hazard_late", lt["hazard"], lt["ci_low"], lt["ci_high"],
         note=f"Gamma-rescaled hazard over rescaled t > {LATE_RESCALED:g} "
         f"({int(lt['events'])} intervals end there); 1 if the phase-averaged rate held")
    for lo_t, hi_t in ((0.2, 1.0), (1.0, LATE_RESCALED)):
        mid = stats.interval_hazard(u[done], censored=u[~done], edges=[0.0, lo_t, hi_t,
                                                             max(float(u.max()), 2 * hi_t)])
        mt = mid.table.iloc[1]
        _row(rows, key, f"rescaled_hazard_{lo_t:g}_{hi_t:g}", mt["hazard"], mt["ci_low"],
             mt["ci_high"], note=f"Gamma-rescaled hazard over rescaled t in [{lo_t:g}, {hi_t:g})")

    # Cox twins through the same battery
    twins = twin_batteries(runs, tab, pred, post, t_max, n_twins, rng)
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
    _row(rows, key, "observed_dispersion_index_nonsticky", dispersion(n_pp[calm_ic]),
         *_boot_ci(lambda p: dispersion(n_pp[calm_ic][p]), int(calm_ic.sum()), rng,
                   n_boot))
    for name, res in twins.items():
        d = np.array([dispersion(b["counts"][calm_ic]) for b in res])
        _row(rows, key, f"{name}_dispersion_index_nonsticky", d.mean(),
             *np.quantile(d, [0.025, 0.975]))
    _explained(rows, key, "dispersion_index", obs, twins, rng, subset=calm_ic,
               suffix="_nonsticky")
    return rows, data


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
            return np.mean([dispersion(b["counts"][p]) for b in twins[name]])
        return np.mean([b["reject"][what].to_numpy()[p].mean() for b in twins[name]])

    def observed(p):
        p = ics[p]
        return (dispersion(obs["counts"][p]) if what == "dispersion_index"
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


def cell_rows(results, radii):
    """The rows of the pooled (L0, L1) cells per radius (`state_rates`): the weighted
    correlation and slope of log observed on log predicted cell rate over the cells with
    at least 10 collisions, and the four corner cells over the kinetic rate."""
    rows = []
    for r in radii:
        _, emp, pred, events = state_rates(results, r)
        ok = events >= 10
        w = events[ok]
        x, y = np.log(pred[ok]), np.log(emp[ok])
        corr = slope = math.nan                # no cell with 10 collisions (tiny runs)
        if ok.any():
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
    return rows
