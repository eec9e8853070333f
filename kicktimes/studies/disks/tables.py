"""The tagged disk's collision-time process against N: the tables of docs/results/disks.md.

From the stores of `kicktimes.experiment.DisksExperiment` sweeps, one row per (sweep, N):

* the collision frequency over Enskog's (`kicktimes.stats.enskog_frequency`), and for two
  disks over the exact two-disk kinetic rate (`kicktimes.stats.kinetic_rate`);
* the Poisson battery (`kicktimes.stats.poisson_group`, every test of
  `kicktimes.stats.TESTS`) on each tagged disk's first ``K = collisions`` collisions, its
  window ending at collision ``K + 1`` (given that collision, the first K of a Poisson
  process are uniform on the window): the share of tagged disks rejected at ``alpha``;
* the dispersion index across tagged disks (``dispersion``): of each tagged disk's count of
  collisions in one common window of ``K`` mean intervals, over the tagged disks of all
  runs of one N, ``D = s^2 / mean`` (1 for Poisson counts of one rate; more when the runs'
  rates differ, as they do: read against its null, `kicktimes.studies.disks.versus_null`);
* the hazard of the intervals against the time since the last collision, in units of the
  mean interval (`kicktimes.stats.interval_hazard`): its first bin over the constant rate
  (``hazard_first``, the refractory dip) and its highest later bin (``hazard_peak`` at
  ``hazard_peak_t``, the return peak), and a gamma renewal fit's shape
  (`kicktimes.stats.fit_renewal`; 1 for exponential intervals);
* under the elastic rule the same battery and dispersion after the speed-conditioned
  rescaling: time runs at ``nu(v) / nu_bar`` (`kicktimes.stats.speed_rate_factor`) while
  the disk flies at speed ``v``, so that a Cox process of rate ``nu(v)`` becomes a unit
  Poisson process (the time-rescaling theorem), and the share of ``D - 1`` it removes.

Intervals: 95 %, percentile bootstrap clustered on runs (the tagged disks of one run share
a gas), one set of run weights for every quantity of a row (for a rejection share, the
wider of that and the Clopper-Pearson interval); the hazard's per bin are
Garwood's (intervals taken as independent), the gamma shape's from its standard error.
Verdicts: `kicktimes.stats.ratio_verdict` of the rates (within `RATE_MARGIN`) and
`kicktimes.stats.rejection_verdict` of the shares (nominal within 50 % of alpha, against
the nominal level). D, the hazard and the gamma shape get no verdict here: their null value
is not 1, and the page reads them against their null streams
(`kicktimes.studies.disks.versus_null`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes.stats import (
    TESTS,
    cluster_bootstrap,
    enskog_frequency,
    fit_renewal,
    interval_hazard,
    kinetic_rate,
    percentile_interval,
    poisson_group,
    ratio_verdict,
    rejection_verdict,
    resample_counts,
    share_ratio_sample_size,
    speed_rate_factor,
)
from kicktimes.stats.findings import clopper_pearson

__all__ = [
    "HAZARD_EDGES", "KICKED_DIAGNOSTICS", "PEAK_MIN_SHARE", "RATE_MARGIN", "bulk_rows",
    "disks_hazard", "disks_table", "kicked_table", "peak_bin", "rescale_by_speed",
    "two_disk_check",
]

#: bins of the hazard, in units of the mean interval
#: (to 20: the longest of about 120000 intervals of a Poisson stream is about 12)
HAZARD_EDGES = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 7.0,
                10.0, 20.0)
#: the margin of the collision rate over Enskog's: half the smallest correction Enskog's
#: theory makes to the Boltzmann rate on the page, the contact value's g(sigma) - 1 = 0.032
#: at packing 0.02 (Henderson)
RATE_MARGIN = 0.015
#: the highest later bin (the return peak) is sought among the bins holding at least this
#: share of the intervals (a sparse tail bin's estimate is mostly noise)
PEAK_MIN_SHARE = 0.01
#: the speed-conditioned rescaling's temperature: the energy shell sum |v|^2 = N
KT = 0.5


def rescale_by_speed(times, speeds, t_end, *, kT=KT):
    """Collision times in the clock of a disk whose rate follows its speed.

    Parameters
    ----------
    times : array_like
        The disk's collision times, increasing.
    speeds : array_like, shape (len(times) + 1,)
        Its speed in each interval (before the first collision, between collisions, after
        the last); NaN (unknown) counts as the mean rate.
    t_end : float
        A time ``>= times[-1]`` to map too (a window's end).

    Returns
    -------
    (ndarray, float)
        ``Lambda(t_k)`` and ``Lambda(t_end)``, with ``Lambda(t) = int_0^t nu(v(s)) /
        nu_bar ds`` (`kicktimes.stats.speed_rate_factor`).

    Examples
    --------
    >>> import numpy as np
    >>> u, end = rescale_by_speed([1.0, 2.0], [0.0, np.nan, 0.0], 3.0)
    >>> u.round(4).tolist(), round(end, 4)
    ([0.7071, 1.7071], 2.4142)
    """
    t = np.asarray(times, float)
    rho = speed_rate_factor(np.nan_to_num(np.asarray(speeds, float), nan=-1.0).clip(0.0),
                            kT=kT)
    rho = np.where(np.isnan(np.asarray(speeds, float)), 1.0, rho)
    edges = np.concatenate([[0.0], t, [float(t_end)]])
    lam = np.concatenate([[0.0], np.cumsum(rho * np.diff(edges))])
    return lam[1:-1], float(lam[-1])


def peak_bin(events, hazard, min_share=PEAK_MIN_SHARE) -> int:
    """The highest later hazard bin (index >= 1) among those holding at least
    ``min_share`` of the events; bin 0 when no later bin does.

    Examples
    --------
    >>> peak_bin([10, 500, 400, 3], [0.5, 1.2, 1.4, 9.0])
    2
    """
    events = np.asarray(events, float)
    ok = events[1:] >= min_share * events.sum()
    if not ok.any():
        return 0
    return 1 + int(np.argmax(np.where(ok, np.asarray(hazard, float)[1:], -np.inf)))


def _ci(samples):
    return percentile_interval(samples)


def _dispersion(s0, s1, s2):
    """``s^2 / mean`` from sums of 1, x, x^2 (arrays: one per bootstrap replicate)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = s1 / s0
        var = (s2 - s1 * s1 / s0) / (s0 - 1.0)
        return var / mean


class _Sequences:
    """The tagged sequences of one N: the tested ones (first K collisions) and the counts."""

    def __init__(self, col, k, t_count, rescale):
        self.times, self.windows, self.run = [], [], []
        self.counts, self.count_run = [], []
        for row in col.itertuples(index=False):
            t = np.asarray(row.pp_times, float)
            if rescale:
                t, end = rescale_by_speed(t, row.speeds, row.t_window)
            else:
                end = row.t_window
            if end >= t_count:
                self.counts.append(int(np.searchsorted(t, t_count, side="right")))
                self.count_run.append(row.ic)
            if t.size >= k + 1:
                self.times.append(t[:k])
                self.windows.append(float(t[k]))
                self.run.append(row.ic)
        self.run = np.asarray(self.run)
        self.counts = np.asarray(self.counts, float)
        self.count_run = np.asarray(self.count_run)


def _tests(seqs, runs, weights, rng, alpha, n_mc, prefix):
    """Rejection shares of every test, with cluster-bootstrap CIs and verdicts."""
    out = {}
    if not seqs.times:
        return out
    group = poisson_group(seqs.times, seqs.windows, alpha=alpha, n_mc=n_mc, rng=rng)
    pos = np.searchsorted(runs, seqs.run)
    for test in TESTS:
        p = group.ensemble.per_sequence[f"p_{test}"].to_numpy()
        ok = np.isfinite(p)
        rej = np.bincount(pos[ok], weights=(p[ok] < alpha).astype(float), minlength=runs.size)
        n = np.bincount(pos[ok], minlength=runs.size).astype(float)
        share = rej.sum() / n.sum() if n.sum() else math.nan
        with np.errstate(divide="ignore", invalid="ignore"):
            lo, hi = _ci(weights @ rej / (weights @ n))
        # the wider of the cluster bootstrap and Clopper-Pearson: a bootstrap of a share
        # with no (or every) rejection collapses to a point
        cp_lo, cp_hi = clopper_pearson(int(rej.sum()), int(n.sum()))
        lo, hi = min(lo, cp_lo), max(hi, cp_hi)
        out[f"{prefix}reject_{test}"] = share
        out[f"{prefix}reject_{test}_low"], out[f"{prefix}reject_{test}_high"] = lo, hi
        out[f"{prefix}reject_{test}_verdict"] = rejection_verdict(lo, hi, alpha=alpha)
        out[f"{prefix}reject_{test}_n"] = int(n.sum())
    return out


def _count_sums(seqs, runs, weights):
    pos = np.searchsorted(runs, seqs.count_run)
    c = seqs.counts
    sums = [np.bincount(pos, weights=c ** j, minlength=runs.size) for j in range(3)]
    d = float(_dispersion(*(s.sum() for s in sums)))
    boot = _dispersion(*(weights @ s for s in sums))
    return d, boot


def _hazard_replicates(seqs, runs, weights, scale, edges=HAZARD_EDGES):
    """Bootstrap replicates (runs resampled with ``weights``) of the hazard per bin over the
    constant rate, of the intervals between the tested collisions in units of the mean
    interval (times ``scale``, the collision rate; as `kicktimes.stats.interval_hazard`
    with ``edges``: d_j / E_j over sum d / sum E); shape (replicates, bins)."""
    iv = [np.diff(np.append(t, w)) for t, w in zip(seqs.times, seqs.windows, strict=True)]
    pos = np.searchsorted(runs, np.repeat(seqs.run, [len(x) for x in iv]))
    y = np.concatenate(iv) * scale
    e = np.asarray(edges, float)
    d = np.stack([np.bincount(pos, weights=((y >= lo) & (y < hi)).astype(float),
                              minlength=runs.size) for lo, hi in zip(e[:-1], e[1:], strict=True)])
    x = np.stack([np.bincount(pos, weights=np.clip(y - lo, 0.0, hi - lo), minlength=runs.size)
                  for lo, hi in zip(e[:-1], e[1:], strict=True)])
    bd, bx = weights @ d.T, weights @ x.T
    with np.errstate(divide="ignore", invalid="ignore"):
        return (bd / bx) / (bd.sum(axis=1) / bx.sum(axis=1))[:, None]


def _row(exp, n, res, col, *, alpha, n_boot, n_mc, rng):
    k = exp.collisions
    r = exp.radius(n)
    runs = np.unique(res["ic"].to_numpy())
    weights = resample_counts(runs.size, n_boot=n_boot, rng=rng)
    freq = (res[res["diagnostic"] == "collision_frequency"].set_index("ic")["value"]
            .reindex(runs).to_numpy())
    nu_hat = float(freq.mean())
    nu_e = enskog_frequency(r, n, rule=exp.rule)
    boot_freq = weights @ freq / runs.size
    row = {"experiment": exp.name, "rule": exp.rule, "geometry": exp.geometry_label,
           "n_disks": n, "radius": r, "packing": exp.packing_at(n), "n_runs": runs.size,
           "n_tagged": len(col), "collisions": k, "t_max": exp.t_max(n),
           "rate": nu_hat, "enskog": nu_e, "rate_enskog": nu_hat / nu_e}
    row["rate_enskog_low"], row["rate_enskog_high"] = _ci(boot_freq / nu_e)
    row["rate_enskog_verdict"] = ratio_verdict(row["rate_enskog_low"], row["rate_enskog_high"],
                                               tolerance=RATE_MARGIN)
    if n == 2:
        gamma = float(kinetic_rate(r, rule=exp.rule))
        row["rate_two_disk"] = nu_hat / gamma
        row["rate_two_disk_low"], row["rate_two_disk_high"] = _ci(boot_freq / gamma)
        row["rate_two_disk_verdict"] = ratio_verdict(row["rate_two_disk_low"],
                                                     row["rate_two_disk_high"],
                                                     tolerance=RATE_MARGIN)
    t_count = min(k / nu_hat, float(col["t_window"].min()))
    plain = _Sequences(col, k, t_count, rescale=False)
    row["n_short"] = len(col) - len(plain.times)
    row.update(_tests(plain, runs, weights, rng, alpha, n_mc, ""))
    d, boot_d = _count_sums(plain, runs, weights)
    row["dispersion"] = d
    row["dispersion_low"], row["dispersion_high"] = _ci(boot_d)
    iv = (np.concatenate([np.diff(np.append(t, w)) for t, w in zip(plain.times, plain.windows,
                                                                     strict=True)]) * nu_hat
          if plain.times else [])
    if len(iv) > 10:
        haz = interval_hazard(iv, edges=HAZARD_EDGES)
        tab = haz.table[haz.table["exposure"] > 0]
        # the refractory dip: the first bin; the return peak: the highest later bin
        peak = tab.index[peak_bin(tab["events"].to_numpy(), tab["hazard"].to_numpy())]
        boot = _hazard_replicates(plain, runs, weights, nu_hat)
        for name, b in (("hazard_first", tab.index[0]), ("hazard_peak", peak)):
            row[name] = float(tab.loc[b, "hazard"] / haz.rate)
            # the wider of the percentile bootstrap clustered on runs and the Garwood
            # interval of the pooled intervals (independent): with 16 runs the bootstrap's
            # variance has 15 degrees of freedom and may come out narrower than Poisson's
            lo, hi = _ci(boot[:, int(b)])
            row[f"{name}_low"] = min(lo, float(tab.loc[b, "ci_low"] / haz.rate))
            row[f"{name}_high"] = max(hi, float(tab.loc[b, "ci_high"] / haz.rate))
        row["hazard_peak_t"] = float(tab.loc[peak, "t_mid"])
        row["hazard_flat_pvalue"] = haz.pvalue
        fit = fit_renewal(iv, "gamma")
        shape, se = fit.params["shape"], fit.stderr["shape"]
        row["gamma_shape"] = float(shape)
        row["gamma_shape_low"], row["gamma_shape_high"] = shape - 1.96 * se, shape + 1.96 * se
    if exp.rule == "elastic":
        known = res[res["diagnostic"] == "speed_known"]["value"]
        row["speed_known"] = float(known.mean())
        resc = _Sequences(col, k, t_count, rescale=True)
        row.update(_tests(resc, runs, weights, rng, alpha, n_mc, "rescaled_"))
        d_r, boot_r = _count_sums(resc, runs, weights)
        row["rescaled_dispersion"] = d_r
        row["rescaled_dispersion_low"], row["rescaled_dispersion_high"] = _ci(boot_r)
        with np.errstate(divide="ignore", invalid="ignore"):
            row["speed_share"] = (d - d_r) / (d - 1.0)
            row["speed_share_low"], row["speed_share_high"] = _ci(
                (boot_d - boot_r) / (boot_d - 1.0))
    return row


def bulk_rows(store, within):
    """Which collision rows of a disks store are tagged disks whose centre starts at most
    ``within`` from the table's centre (`kicktimes.experiment.disks_tasks.tagged_start_radii`,
    redrawn from each run's seed): a boolean array aligned with ``store.collisions``."""
    from kicktimes.experiment.disks_tasks import tagged_start_radii

    col = store.collisions
    keep = np.zeros(len(col), bool)
    pos = {key: m for m, key in enumerate(zip(col["n_disks"], col["ic"], col["disk"],
                                              strict=True))}
    found = 0
    for n, k in sorted(set(zip(col["n_disks"], col["ic"], strict=True))):
        tagged, radii = tagged_start_radii(store.experiment, int(n), int(k))
        for d, rad in zip(tagged, radii, strict=True):
            m = pos.get((n, k, int(d)))
            if m is not None:
                keep[m] = rad <= within
                found += 1
    if found != len(col):
        # the redrawn states tag other disks than the store's runs did: the code that draws
        # a run's state has changed since the store was written
        raise ValueError(f"store: {len(col) - found} of its {len(col)} tagged disks are not "
                         f"the ones its runs' seeds tag now; rerun the store")
    return keep


def disks_table(store, *, alpha=0.05, n_boot=999, n_mc=199, seed=0,
                within=None) -> pd.DataFrame:
    """One row per N of a disks store (see the module's docstring for the columns).

    Parameters
    ----------
    store : Store
        A loaded store of a `DisksExperiment` (`kicktimes.experiment.load_store`).
    alpha : float
        The tests' level.
    n_boot : int
        Bootstrap replicates (``>= 99``).
    n_mc : int
        Monte Carlo samples of the conditional nulls (`kicktimes.stats.poisson_group`).
    seed : int
        The bootstrap's and the Monte Carlo's stream (one per N, from ``(seed, N)``).
    within : float, optional
        Keep only the tagged disks whose centre starts at most ``within`` from the table's
        centre (`bulk_rows`): the tagged disks of the bulk, away from the wall. The runs'
        quantities (the collision rate) are those of all disks.
    """
    from kicktimes.experiment import DisksExperiment

    exp = store.experiment
    if not isinstance(exp, DisksExperiment):
        raise ValueError(f"store: expected the store of a DisksExperiment, got one of "
                         f"{type(exp).__name__} {exp.name!r}")
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must lie in (0, 1), got {alpha!r}")
    if n_boot < 99:
        raise ValueError(f"n_boot must be >= 99, got {n_boot!r}")
    collisions = store.collisions
    if within is not None:
        collisions = collisions[bulk_rows(store, within)]
    rows = []
    for n in exp.n_disks:
        res = store.results[store.results["n_disks"] == n]
        col = collisions[collisions["n_disks"] == n]
        if res.empty:
            continue
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(n,)))
        rows.append(_row(exp, n, res, col, alpha=alpha, n_boot=n_boot, n_mc=n_mc, rng=rng))
    return pd.DataFrame(rows)


def disks_hazard(store, *, edges=HAZARD_EDGES) -> pd.DataFrame:
    """The hazard of the tagged disks' first ``collisions`` intervals against the time
    since the last collision, per N, both in units of the mean interval
    (`kicktimes.stats.interval_hazard`): rows ``experiment, rule, n_disks`` and the
    hazard table's columns, ``hazard`` and its CI divided by the constant rate."""
    exp = store.experiment
    out = []
    for n in exp.n_disks:
        res = store.results[(store.results["n_disks"] == n)
                            & (store.results["diagnostic"] == "collision_frequency")]
        col = store.collisions[store.collisions["n_disks"] == n]
        if res.empty:
            continue
        nu_hat = float(res["value"].mean())
        k = exp.collisions
        iv = [np.diff(np.asarray(t, float)[:k + 1]) for t in col["pp_times"] if len(t) > k]
        if not iv:
            continue
        haz = interval_hazard(np.concatenate(iv) * nu_hat, edges=edges)
        tab = haz.table[haz.table["exposure"] > 0].copy()
        for c in ("hazard", "ci_low", "ci_high"):
            tab[c] = tab[c] / haz.rate
        tab.insert(0, "n_disks", n)
        tab.insert(0, "rule", exp.rule)
        tab.insert(0, "experiment", exp.name)
        tab["flat_pvalue"] = haz.pvalue
        out.append(tab)
    return pd.concat(out, ignore_index=True) if out else pd.DataFrame()


#: the kicked comparison's diagnostics and the systems compared with the gas
KICKED_DIAGNOSTICS = ("ftle", "acf@1", "rr")
KICKED_SYSTEMS = ("poisson", "actual", "scatter")


def kicked_table(store, *, n_boot=999, seed=0) -> pd.DataFrame:
    """The kicked single disk against the gas (`DisksExperiment.kicked_runs`): one row per
    (N, kicked system, diagnostic), the ratio kicked / gas of the means over runs with a
    percentile bootstrap clustered on runs and its `kicktimes.stats.ratio_verdict`, the
    means of both (``value``, ``reference``) with the same bootstrap's intervals; the
    gas's FTLE over its disk's collision rate (system ``"gas/gas"``, diagnostic
    ``"ftle/rate"``: the exponent per collision) and the kicked disks' FTLE over the same rate
    (``"poisson/gas"``, ``"actual/gas"``, ``"ftle/rate"``); at N = 2 also the gas's FTLE
    (`disks_lyapunov`, the store's ``gas_ftle`` method) over the two-disk FTLE of the same
    states (tangent, `kicktimes.diagnostics.lyapunov`), system ``"gas/two_particle"``.
    Empty when the store has no kicked rows."""
    res = store.results
    res = res[res["system"] != "disks"]
    rows = []
    for n, g in res.groupby("n_disks", sort=True, observed=True):
        wide = g.pivot_table(index="ic", columns=["system", "diagnostic"], values="value",
                              observed=True)
        runs = wide.index.size
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(int(n), 7)))
        weights = resample_counts(runs, n_boot=n_boot, rng=rng)
        # (system, diagnostic, reference system, reference diagnostic)
        systems = [s for s in KICKED_SYSTEMS if (s, "ftle") in wide]
        pairs = [(s, d, "gas", d) for s in systems for d in KICKED_DIAGNOSTICS]
        pairs.append(("gas", "ftle", "gas", "rate"))  # lambda / nu: per collision of a disk
        # the kicked disks' own exponents per collision of the gas's disk (their kick rate)
        pairs += [(s, "ftle", "gas", "rate") for s in systems]
        if ("two_particle", "ftle") in wide:
            pairs.append(("gas", "ftle", "two_particle", "ftle"))
        for system, diag, ref, ref_diag in pairs:
            num, den = wide[(system, diag)].to_numpy(), wide[(ref, ref_diag)].to_numpy()
            ok = np.isfinite(num) & np.isfinite(den)
            w = weights[:, ok]
            with np.errstate(divide="ignore", invalid="ignore"):
                boot = (w @ num[ok]) / (w @ den[ok])
                ratio = num[ok].mean() / den[ok].mean() if ok.any() else math.nan
            lo, hi = _ci(boot)
            ref_lo, ref_hi = _ci(w @ den[ok] / w.sum(axis=1))
            val_lo, val_hi = _ci(w @ num[ok] / w.sum(axis=1))
            rows.append({"experiment": store.experiment.name, "n_disks": int(n),
                         "system": f"{system}/{ref}",
                         "diagnostic": diag if ref_diag == diag else f"{diag}/{ref_diag}",
                         "reference": float(np.mean(den[ok])) if ok.any() else math.nan,
                         "reference_low": ref_lo, "reference_high": ref_hi,
                         "value": float(np.mean(num[ok])) if ok.any() else math.nan,
                         "value_low": val_lo, "value_high": val_hi,
                         "ratio": ratio, "ratio_low": lo, "ratio_high": hi,
                         "verdict": ratio_verdict(lo, hi), "n_runs": int(ok.sum())})
    return pd.DataFrame(rows)


def _first_k(pp_times, k):
    """The first ``k`` collision times of each sequence that has ``k + 1``, and the time of
    collision ``k + 1`` (the window)."""
    times, windows = [], []
    for t in pp_times:
        t = np.asarray(t, float)
        if t.size > k:
            times.append(t[:k])
            windows.append(float(t[k]))
    return times, windows


def _share_replicates(times, windows, *, alpha, n_mc, n_boot, rng):
    """The share of sequences rejecting uniform times at ``alpha`` and its bootstrap
    replicates (sequences resampled: each is its own cluster)."""
    group = poisson_group(times, windows, alpha=alpha, n_mc=n_mc, rng=rng)
    p = group.ensemble.per_sequence["p_uniformity_ks"].to_numpy()
    rej = (p[np.isfinite(p)] < alpha).astype(float)
    return float(rej.mean()), _boot_means(rej, n_boot, rng), int(rej.size)


def _boot_means(x, n_boot, rng, chunk=100):
    """Percentile-bootstrap replicates of the mean of ``x`` (each value its own cluster),
    drawn ``chunk`` replicates at a time (the same stream as all at once)."""
    return cluster_bootstrap(lambda idx: x[idx].mean(axis=1), x.size, n_boot=n_boot, rng=rng,
                             chunk=chunk).replicates


def two_disk_check(disks_store, two_store, *, alpha=0.05, n_boot=999, n_mc=199, seed=0):
    """The N = 2 row of a disks sweep against the two-disk simulator's own sweep.

    Parameters
    ----------
    disks_store : Store
        A `DisksExperiment` store with N = 2 (one tagged disk per run).
    two_store : Store
        An `Experiment` store of the two-disk simulator at the same radius and rule
        (`kicktimes.experiment.DISKS_REFERENCES`).

    Returns
    -------
    dict
        ``engine`` and ``two_disk``: the share of runs whose first K collision times
        (``K = collisions`` of the disks sweep, window to collision K + 1) reject uniform
        times at ``alpha``, with its percentile bootstrap CI and its count; ``ratio``:
        engine over two-disk, CI from the ratio of independent replicates, and its
        `kicktimes.stats.ratio_verdict`; ``rate_ratio`` (``_low``, ``_high``, ``_verdict``):
        the same for the mean collision rate per run (``n_pp / t_window``), a statistic
        with more power; ``n_needed``: the runs per arm the share ratio needs to be called
        within 10 % with probability 0.8 at the two-disk share
        (`kicktimes.stats.share_ratio_sample_size`); ``radius``, ``rule``, the stores' names.
    """
    exp, two = disks_store.experiment, two_store.experiment
    k = exp.collisions
    r = exp.radius(2)
    if two.radii != (r,) or two.rule != exp.rule:
        raise ValueError(f"two_store: expected a two-disk sweep at r = {r!r} under the "
                         f"{exp.rule} rule, got radii {list(two.radii)} under {two.rule}")
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(2, 11)))
    col = disks_store.collisions
    engine = _share_replicates(*_first_k(col[col["n_disks"] == 2]["pp_times"], k),
                               alpha=alpha, n_mc=n_mc, n_boot=n_boot, rng=rng)
    ref = _share_replicates(*_first_k(two_store.collisions["pp_times"], k), alpha=alpha,
                            n_mc=n_mc, n_boot=n_boot, rng=rng)
    out = {"engine_store": exp.name, "two_disk_store": two.name, "radius": r,
           "rule": exp.rule, "collisions": k}
    for name, (share, boot, n) in (("engine", engine), ("two_disk", ref)):
        lo, hi = _ci(boot)
        out.update({f"{name}": share, f"{name}_low": lo, f"{name}_high": hi,
                    f"{name}_n": n, f"{name}_verdict": rejection_verdict(lo, hi, alpha=alpha)})
    with np.errstate(divide="ignore", invalid="ignore"):
        out["ratio"] = engine[0] / ref[0] if ref[0] > 0 else math.nan
        out["ratio_low"], out["ratio_high"] = _ci(engine[1] / ref[1])
    out["ratio_verdict"] = ratio_verdict(out["ratio_low"], out["ratio_high"])
    out["n_needed"] = (share_ratio_sample_size(ref[0]) if 0 < ref[0] < 1 else math.nan)
    rates = []
    for c in (col[col["n_disks"] == 2], two_store.collisions):
        rate = c["n_pp"].to_numpy(float) / c["t_window"].to_numpy(float)
        rates.append((rate.mean(), _boot_means(rate, n_boot, rng)))
    out["rate_ratio"] = rates[0][0] / rates[1][0]
    out["rate_ratio_low"], out["rate_ratio_high"] = _ci(rates[0][1] / rates[1][1])
    out["rate_ratio_verdict"] = ratio_verdict(out["rate_ratio_low"], out["rate_ratio_high"])
    return out


def sweep_cost(name, store) -> dict:
    """One row of ``disks_cost.csv``: the sweep ``name``'s tasks and the seconds its tasks
    recorded (``cpu_seconds``: a disks sweep's CPU time, NaN for a two-disk sweep, whose
    tasks record their wall time only; ``wall_seconds``)."""
    timings = store.timings
    wall = timings["simulate"] if "simulate" in timings else timings["total"]
    return {"experiment": name, "tasks": len(store.manifest["tasks"]),
            "cpu_seconds": float(timings["cpu"].sum()) if "cpu" in timings else float("nan"),
            "wall_seconds": float(wall.sum())}

