"""Every statistic of the gas page read against its null stream, paired by run.

A statistic whose value on a Poisson process is not exactly 1 (or alpha) is read against
the same statistic on null streams shaped like the runs: the dispersion index of counts
over runs of unequal rates (the spread of the runs' collision frequencies adds to it, 5.06
at N = 2), a KS share at the pipeline's calibrated level, a gamma fit's shape on pooled
intervals of unequal rates, the hazard of binned intervals (its highest bin, a maximum
over bins, lies above 1 on any finite sample). `versus_null` draws each tagged disk's
Poisson stream at its run's collision frequency over its run's window (the ``"poisson"``
design of `kicktimes.studies.disks.null`, the same streams as ``disks_null.csv``: the
same seeds) and computes, for the gas and its null from one set of run weights (a
percentile bootstrap clustered on runs, `kicktimes.stats.resample_counts`, the null paired
with the gas by run), the difference *gas - null* of

* ``d``: the dispersion index D across tagged disks: the variance over the mean of each
  tagged disk's count of collisions in one common window of K mean intervals, over the
  tagged disks of all runs of one N (not one disk's counts in sub-windows: the run-to-run
  spread of rates is in it);
* ``ks``: the share of tagged disks whose first K collision times reject uniform times
  (exact KS, ``alpha``);
* ``gamma``: the shape of a gamma renewal model fitted by maximum likelihood to the pooled
  intervals (in units of the mean interval);
* ``hazard_first`` and ``hazard_peak``: the hazard of the next collision over the constant
  rate in the first bin, [0, 0.01) mean intervals, and in the highest later bin (each
  stream's own highest);
* every hazard bin (`bin_rows`), beside the linear Boltzmann tagged disk's hazard
  (`kicktimes.stats.dilute_tagged_disk`, exposure-weighted over the bin).

Each difference is read by `kicktimes.stats.null_verdict` with its margin, `MARGINS`: half
the effect the page must resolve, the elastic linear Boltzmann tagged disk's departure from
Poisson in that statistic. Where an interval is wider than its margin allows,
`kicktimes.stats.equivalence_sample_size` gives the runs the design would need.

Interval of a hazard bin: the wider of the paired bootstrap and the interval that takes
every interval as independent (the counts of a bin Poisson; Garwood's for one stream,
the normal sum of both variances for a difference). With 16 runs (N >= 300) the bootstrap's
variance rests on 15 degrees of freedom (its width uncertain by about a third): at packing
0.02, elastic, N = 1000 the first bin's per-run counts have a dispersion 0.72 of Poisson's,
consistent with 1, and the bootstrap interval came out narrower than Garwood's.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pandas as pd
from scipy.special import digamma, gammaln, polygamma

from kicktimes.stats import (
    D_MARGIN,
    dilute_tagged_disk,
    equivalence_sample_size,
    null_reading,
    percentile_interval,
    resample_counts,
)
from kicktimes.stats.poisson import uniformity_ks
from kicktimes.studies.disks.null import null_streams
from kicktimes.studies.disks.tables import HAZARD_EDGES, _Sequences, peak_bin

__all__ = [
    "EDGE_VERDICTS", "GAMMA_MARGIN", "HAZARD_MARGIN", "KS_MARGIN", "MARGINS", "STATISTICS",
    "aic_margin", "bin_rows", "boltzmann_bin_hazard", "edge_null_verdict", "gamma_shape_mle",
    "versus_null",
]

#: the verdicts of a CI that straddles a margin edge but excludes 0 (`edge_null_verdict`)
EDGE_VERDICTS = ("above its null, size unresolved",
                 "below its null, size unresolved")


def edge_null_verdict(low, high, margin):
    """`kicktimes.stats.null_reading`, the pages' one reading of the CI of statistic - null:
    a CI that straddles a margin edge but excludes 0 says on which side (`EDGE_VERDICTS`);
    ``"inconclusive"`` is kept for a CI that contains 0, the only case where a sample size
    is named.

    Examples
    --------
    >>> edge_null_verdict(0.018, 0.157, 0.07)
    'above its null, size unresolved'
    >>> edge_null_verdict(-0.014, 0.140, 0.07), edge_null_verdict(0.108, 0.239, 0.07)
    ('inconclusive', 'above its null')
    """
    return null_reading(low, high, margin=margin)


#: the KS share's margin: half the elastic linear Boltzmann tagged disk's excess over a
#: Poisson stream at K = 30 (`dilute_tagged_disk("elastic").ks_share(30)`: 0.070 against
#: 0.05, an excess of 0.020)
KS_MARGIN = 0.01
#: the gamma shape's margin: half the Boltzmann tagged disk's 1 - 0.957 (its `gamma_shape`)
GAMMA_MARGIN = 0.02
#: a hazard bin's margin: half the Boltzmann tagged disk's excess just after a collision,
#: h(0) - 1 = 0.064 (its `hazard(0)`)
HAZARD_MARGIN = 0.03
#: the statistics read against their null, their margins and the page's words
STATISTICS = {"d": "D", "ks": "KS share", "gamma": "gamma shape",
              "hazard_first": "hazard, first bin", "hazard_peak": "hazard, highest bin"}
MARGINS = {"d": D_MARGIN, "ks": KS_MARGIN, "gamma": GAMMA_MARGIN,
           "hazard_first": HAZARD_MARGIN, "hazard_peak": HAZARD_MARGIN}
_Z = 1.959963984540054


def gamma_shape_mle(log_ratio):
    r"""The maximum-likelihood shape of a gamma model of complete intervals: the root
    :math:`k` of :math:`\log k - \psi(k) = s`, with :math:`s = \log\bar x -
    \overline{\log x} > 0` (Minka's start, Newton steps); vectorised over ``log_ratio``.

    Examples
    --------
    >>> from scipy.special import digamma
    >>> k = gamma_shape_mle(np.log(2.0) - digamma(2.0))
    >>> round(float(k), 10)
    2.0
    """
    s = np.asarray(log_ratio, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = (3.0 - s + np.sqrt((s - 3.0) ** 2 + 24.0 * s)) / (12.0 * s)
        for _ in range(30):
            f = np.log(k) - digamma(k) - s
            step = f / (1.0 / k - polygamma(1, k))
            k = np.where(np.isfinite(step), np.maximum(k - step, k / 10.0), k)
    return k


def aic_margin(n_intervals, margin=GAMMA_MARGIN):
    r"""The exponential's AIC excess over a gamma model that a gamma shape at the margin,
    :math:`k = 1 - m`, gives on ``n_intervals`` intervals: :math:`2 n\,\mathrm{KL} - 2`,
    with the Kullback-Leibler divergence of the gamma law of mean 1 from the exponential
    of mean 1, :math:`(k - 1)(\psi(k) - \log k) - (k - 1) + k \log k - \log\Gamma(k)`
    (one parameter more costs 2).

    Examples
    --------
    >>> round(aic_margin(120000), 1)
    29.9
    """
    k = 1.0 - margin
    kl = (k - 1.0) * (digamma(k) - math.log(k)) - (k - 1.0) + k * math.log(k) - gammaln(k)
    return float(2.0 * n_intervals * kl - 2.0)


def _sums(seqs, runs, scale, edges, alpha):
    """Per-run sums of one N's sequences: counts (D), hazard events and exposure per bin,
    the gamma fit's sums, KS rejections."""
    pos = np.searchsorted(runs, seqs.count_run)
    c = seqs.counts
    out = {"count": np.stack([np.bincount(pos, weights=c ** j, minlength=runs.size)
                              for j in range(3)])}
    iv = [np.diff(np.append(t, w)) for t, w in zip(seqs.times, seqs.windows, strict=True)]
    pos = np.searchsorted(runs, np.repeat(seqs.run, [len(x) for x in iv]))
    y = np.concatenate(iv) * scale
    e = np.asarray(edges, float)
    out["events"] = np.stack([np.bincount(pos, weights=((y >= lo) & (y < hi)).astype(float),
                                          minlength=runs.size)
                              for lo, hi in zip(e[:-1], e[1:], strict=True)])
    out["exposure"] = np.stack([np.bincount(pos, weights=np.clip(y - lo, 0.0, hi - lo),
                                            minlength=runs.size)
                                for lo, hi in zip(e[:-1], e[1:], strict=True)])
    ok = y > 0
    out["gamma"] = np.stack([np.bincount(pos[ok], minlength=runs.size),
                             np.bincount(pos[ok], weights=y[ok], minlength=runs.size),
                             np.bincount(pos[ok], weights=np.log(y[ok]), minlength=runs.size)])
    u = np.stack(seqs.times) / np.asarray(seqs.windows)[:, None]
    _, p = uniformity_ks(u)
    pos = np.searchsorted(runs, seqs.run)
    out["ks"] = np.stack([np.bincount(pos, weights=(p < alpha).astype(float),
                                      minlength=runs.size),
                          np.bincount(pos, minlength=runs.size).astype(float)])
    return out


def _statistics(sums, w, peak=None):
    """Each statistic for every row of run weights ``w`` (row 0: all ones, the estimate);
    ``peak`` the bin of the highest later hazard (default: the estimate's)."""
    s0, s1, s2 = (w @ s for s in sums["count"])
    with np.errstate(divide="ignore", invalid="ignore"):
        d = ((s2 - s1 * s1 / s0) / (s0 - 1.0)) / (s1 / s0)
        ev, ex = w @ sums["events"].T, w @ sums["exposure"].T
        haz = (ev / ex) / (ev.sum(axis=1) / ex.sum(axis=1))[:, None]
        n, sy, sl = (w @ s for s in sums["gamma"])
        gamma = gamma_shape_mle(np.log(sy / n) - sl / n)
        ks = (w @ sums["ks"][0]) / (w @ sums["ks"][1])
    if peak is None:
        peak = peak_bin(sums["events"].sum(axis=1), haz[0])
    return {"d": d, "ks": ks, "gamma": gamma, "hazard_first": haz[:, 0],
            "hazard_peak": haz[:, peak], "bins": haz}, peak


def _interval(x):
    lo, hi = percentile_interval(x[1:])
    return float(x[0]), float(lo), float(hi)


def _binned_poisson_se(sums, b, hazard):
    """The standard error of one bin's hazard over the constant rate when its events are
    Poisson and every interval independent (the pooled Garwood interval's, normal)."""
    events = float(sums["events"][b].sum())
    return hazard / math.sqrt(events) if events > 0 else math.inf


def boltzmann_bin_hazard(rule, edges=HAZARD_EDGES, *, points=8) -> np.ndarray:
    r"""The linear Boltzmann tagged disk's hazard over the constant rate in each bin of
    ``edges`` (mean intervals): events over exposure, :math:`\int f / \int S` over the
    bin, with :math:`S = \exp(-\int h)` from its hazard (`kicktimes.stats.dilute_tagged_disk`)
    on ``points`` Gauss-Legendre nodes per bin. 1 under the mirror rule.

    Examples
    --------
    >>> boltzmann_bin_hazard("mirror", (0.0, 1.0, 2.0)).tolist()
    [1.0, 1.0]
    >>> h = boltzmann_bin_hazard("elastic", (0.0, 0.01, 5.0, 7.0))
    >>> bool(h[0] > 1.06 and h[2] < 0.86)
    True
    """
    return np.array(_boltzmann_bins(rule, tuple(float(x) for x in edges), int(points)))


@functools.lru_cache(maxsize=8)
def _boltzmann_bins(rule, edges, points):
    e = np.asarray(edges, float)
    if rule == "mirror":
        return tuple(np.ones(e.size - 1))
    model = dilute_tagged_disk(rule)
    x, wq = np.polynomial.legendre.leggauss(points)
    out, cum = [], 0.0
    for lo, hi in zip(e[:-1], e[1:], strict=True):
        t = lo + (hi - lo) * (x + 1) / 2
        h = model.hazard(t)
        # the cumulative hazard at each node: the bin's start plus the trapezoid to it
        tt = np.r_[lo, t]
        hh = np.r_[model.hazard([lo])[0], h]
        inner = cum + np.concatenate([[0.0], np.cumsum(np.diff(tt) * (hh[1:] + hh[:-1]) / 2)])
        surv = np.exp(-inner[1:])
        out.append(float((wq * h * surv).sum() / (wq * surv).sum()))
        end = model.hazard([hi])[0]
        cum = inner[-1] + (hi - t[-1]) * (h[-1] + end) / 2
    return tuple(out)


def versus_null(store, *, within=None, n_boot=999, alpha=0.05, seed=42, edges=HAZARD_EDGES,
                rng_of=None):
    """The page's statistics of one disks store against its Poisson null streams, per N.

    Parameters
    ----------
    store : Store
        A disks sweep's store (`kicktimes.experiment.load_store`).
    within : float, optional
        Keep the tagged disks starting at most ``within`` from the centre (the bulk
        control, `kicktimes.studies.disks.tables.bulk_rows`); their null streams are the
        same rows' (the null is drawn for every tagged disk, then the same rows kept).
    n_boot : int
        Bootstrap replicates (``>= 99``), one set of run weights for the gas and its null.
    alpha : float
        The KS test's level.
    seed : int
        The null streams' seed (`kicktimes.studies.disks.null.null_rows`'s: the same
        streams as ``disks_null.csv`` for the same seed) and the weights'.
    edges : sequence of float
        The hazard's bins, in mean intervals.

    Returns
    -------
    (DataFrame, DataFrame, dict)
        Per N (``geometry, rule, n_disks, n_runs``) each statistic of `STATISTICS`
        (``<s>``, ``<s>_low``, ``<s>_high``), its null's (``null_<s>`` ...), their
        difference (``<s>_diff`` ...), its verdict (``<s>_verdict``,
        `edge_null_verdict` with `MARGINS`) and, for an inconclusive one, the
        runs that would resolve its margin (``<s>_n_needed``); ``hazard_peak_t``, its
        null's and ``n_intervals``. And per N and hazard bin (`bin_rows`'s columns).
        And the bootstrap replicates of D and of its null, ``{n: (gas, null)}`` (row 0 the
        estimate), for unpaired comparisons with another store.
    """
    from kicktimes.studies.disks.tables import bulk_rows

    if n_boot < 99:
        raise ValueError(f"n_boot must be >= 99, got {n_boot!r}")
    exp = store.experiment
    keep = bulk_rows(store, within) if within is not None else None
    rows, bins, reps = [], [], {}
    for n in exp.n_disks:
        res = store.results[store.results["n_disks"] == n]
        mask = (store.collisions["n_disks"] == n).to_numpy()
        col = store.collisions[mask]
        if res.empty or col.empty:
            continue
        # the null's stream: the seed and order of null_rows' "poisson" design (m = 0)
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(n, 7, 0)))
        _, null_col = null_streams(store, n, "poisson", rng)
        if keep is not None:
            sub = keep[mask]
            col, null_col = col[sub], null_col[sub]
        runs = np.unique(res["ic"].to_numpy())
        freq = (res[res["diagnostic"] == "collision_frequency"].set_index("ic")["value"]
                .reindex(runs).to_numpy())
        nu_hat = float(freq.mean())
        k = exp.collisions
        t_count = min(k / nu_hat, float(store.collisions.loc[mask, "t_window"].min()))
        gas_seq = _Sequences(col, k, t_count, rescale=False)
        null_seq = _Sequences(null_col, k, t_count, rescale=False)
        if not gas_seq.times or not null_seq.times:
            continue
        # the run weights of disks_table's row (its first draw from the same stream), so
        # that the gas's intervals are disks.csv's; the null shares them (paired by run)
        wrng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(n,)))
        w = np.vstack([np.ones(runs.size), resample_counts(runs.size, n_boot=n_boot, rng=wrng)])
        gas_sums = _sums(gas_seq, runs, nu_hat, edges, alpha)
        null_sums = _sums(null_seq, runs, nu_hat, edges, alpha)
        gas, peak = _statistics(gas_sums, w)
        null, null_peak = _statistics(null_sums, w)
        mids = (np.asarray(edges[:-1]) + np.asarray(edges[1:])) / 2
        row = {"geometry": exp.geometry_label, "rule": exp.rule, "n_disks": int(n),
               "experiment": exp.name, "n_runs": int(runs.size),
               "n_tagged": len(gas_seq.times),
               "n_intervals": int(gas_sums["gamma"][0].sum()),
               "hazard_peak_t": float(mids[peak]), "null_hazard_peak_t": float(mids[null_peak])}
        for s, margin in MARGINS.items():
            a, b = gas[s], null[s]
            row[s], row[f"{s}_low"], row[f"{s}_high"] = _interval(a)
            row[f"null_{s}"], row[f"null_{s}_low"], row[f"null_{s}_high"] = _interval(b)
            est, lo, hi = _interval(a - b)
            if s in ("hazard_first", "hazard_peak"):
                # the wider of the bootstrap and the independent-intervals interval
                bin_g, bin_n = (0, 0) if s == "hazard_first" else (peak, null_peak)
                se = math.hypot(_binned_poisson_se(gas_sums, bin_g, row[s]),
                                _binned_poisson_se(null_sums, bin_n, row[f"null_{s}"]))
                lo, hi = min(lo, est - _Z * se), max(hi, est + _Z * se)
                for who, sums_, b_ in (("", gas_sums, bin_g), ("null_", null_sums, bin_n)):
                    se1 = _binned_poisson_se(sums_, b_, row[f"{who}{s}"])
                    row[f"{who}{s}_low"] = min(row[f"{who}{s}_low"], row[f"{who}{s}"] - _Z * se1)
                    row[f"{who}{s}_high"] = max(row[f"{who}{s}_high"],
                                                row[f"{who}{s}"] + _Z * se1)
            row[f"{s}_diff"], row[f"{s}_diff_low"], row[f"{s}_diff_high"] = est, lo, hi
            verdict = edge_null_verdict(lo, hi, margin)
            row[f"{s}_verdict"] = verdict
            se_boot = float(np.nanstd((a - b)[1:]))
            row[f"{s}_n_needed"] = (equivalence_sample_size(se_boot, int(runs.size), margin=margin)
                                    if verdict == "inconclusive" and se_boot > 0 else np.nan)
        rows.append(row)
        reps[int(n)] = (gas["d"], null["d"])
        bins.append(bin_rows(exp, n, edges, gas_sums, null_sums, gas["bins"], null["bins"]))
    return (pd.DataFrame(rows), pd.concat(bins, ignore_index=True) if bins else pd.DataFrame(),
            reps)


def bin_rows(exp, n, edges, gas_sums, null_sums, gas_haz, null_haz) -> pd.DataFrame:
    """Per hazard bin with events in both streams: ``t_low, t_high, events, hazard`` (over
    the constant rate, the wider of the clustered bootstrap and the independent-intervals
    interval), ``null_hazard``, ``diff`` (gas - null, paired) and its interval and
    ``verdict`` (`edge_null_verdict`, `HAZARD_MARGIN`), ``boltzmann`` (`boltzmann_bin_hazard`)
    and the gas's ``boltzmann_verdict`` (gas - Boltzmann: the gas's interval, the
    prediction exact)."""
    e = np.asarray(edges, float)
    boltz = boltzmann_bin_hazard(exp.rule, e)
    rows = []
    for b in range(e.size - 1):
        ev_g, ev_n = float(gas_sums["events"][b].sum()), float(null_sums["events"][b].sum())
        if ev_g <= 0 or ev_n <= 0:
            continue
        h, lo, hi = _interval(gas_haz[:, b])
        hn, nlo, nhi = _interval(null_haz[:, b])
        se_g, se_n = h / math.sqrt(ev_g), hn / math.sqrt(ev_n)
        lo, hi = min(lo, h - _Z * se_g), max(hi, h + _Z * se_g)
        nlo, nhi = min(nlo, hn - _Z * se_n), max(nhi, hn + _Z * se_n)
        est, dlo, dhi = _interval(gas_haz[:, b] - null_haz[:, b])
        se = math.hypot(se_g, se_n)
        dlo, dhi = min(dlo, est - _Z * se), max(dhi, est + _Z * se)
        rows.append({"geometry": exp.geometry_label, "rule": exp.rule, "n_disks": int(n),
                     "t_low": e[b], "t_high": e[b + 1], "events": int(ev_g),
                     "hazard": h, "hazard_low": lo, "hazard_high": hi,
                     "null_hazard": hn, "null_hazard_low": nlo, "null_hazard_high": nhi,
                     "diff": est, "diff_low": dlo, "diff_high": dhi,
                     "verdict": edge_null_verdict(dlo, dhi, HAZARD_MARGIN),
                     "boltzmann": float(boltz[b]),
                     "boltzmann_verdict": edge_null_verdict(lo - boltz[b], hi - boltz[b],
                                                            HAZARD_MARGIN)})
    return pd.DataFrame(rows)
