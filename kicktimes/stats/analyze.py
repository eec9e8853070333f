r"""Statistics of collision times from any source: the analysis ``kicktimes analyze`` runs.

:func:`analyze` takes a tidy table of event times per sequence (see
:mod:`kicktimes.stats._table` for the input contract and its checks) and computes, with
the functions of :mod:`kicktimes.stats`, what the sweep report computes for kicktimes'
own runs:

* the Poisson / IID battery per sequence (:func:`test_poisson_ensemble`: conditional
  tests, Fisher-combined p-values, Benjamini-Hochberg FDR) per group of sequences;
* rate heterogeneity across the sequences of a group (Pearson and likelihood-ratio
  tests of a common rate, exact Monte Carlo p-values, index of dispersion);
* censored renewal-model comparisons (:func:`compare_models`) per sequence and pooled
  per group;
* count regressions (Poisson GLM and negative binomial with offset ``log T``, and the
  OLS line of the rate; :func:`regress_counts`) on every numeric covariate.

A *group* plays the part the disk radius plays in a sweep: sequences observed under the
same conditions, pooled together. Without ``group`` all sequences form one group. The
per-group tables come from :func:`~kicktimes.stats.poisson_group` and
:func:`~kicktimes.stats.pooled_intervals`, which the sweep report runs per radius.
Sequences without events count in the rates, the heterogeneity tests and the
regressions (a zero count is an observation); the tests and fits that need events skip
them, and ``Analysis.skipped`` says which and why.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats as sps

from kicktimes._old_keywords import old_keywords, pop_old, translator, warn_old

from ._checks import check_int, check_real, check_rng
from ._table import EventTable, event_table
from .comparison import compare_models
from .counts import regress_counts
from .groups import poisson_group, pooled_intervals
from .poisson import TESTS, MonteCarloNulls, intervals_from_times

__all__ = ["Analysis", "analyze"]

#: a sequence needs this many complete intervals for its own renewal-model comparison
MIN_INTERVALS = 10
_ALL = "all"


@dataclass(frozen=True, repr=False)
class Analysis:
    """Result of :func:`analyze`: every table, one row per item, with named columns.

    Attributes
    ----------
    sequences : DataFrame
        One row per sequence: ``sequence``, ``group``, window (``t_start``, ``t_end``,
        ``t_window``), ``n_events``, ``rate``, covariates, ``p_<test>`` of each Poisson
        test, ``p_rate`` (its count against the group's pooled rate), ``reject_any_fdr``
        (rejected by some test after FDR within its group) and ``best_model`` (AIC-best
        renewal model, if fitted). Event times are in ``events.sequences["times"]``.
    poisson : DataFrame
        Per group and test: ``n_tested``, ``n_reject`` (p < alpha), ``n_reject_fdr``,
        ``rate`` (share rejected), ``combined_pvalue`` (Fisher).
    heterogeneity : DataFrame
        Per group: ``n_sequences``, ``n_empty``, ``pooled_rate``, ``median_rate``,
        ``dispersion_index`` of the counts, Pearson and likelihood-ratio tests of a common
        rate (``pvalue``, ``pvalue_mc``, ``lr_pvalue``), ``n_flagged_fdr``.
    renewal_per_sequence, renewal_pooled : DataFrame
        ``compare_models`` tables (one row per sequence or group and model): ``aic``,
        ``delta_aic``, ``weight``, ``loglik``, ``k``, ``n``, ``n_censored``, ``note``.
    regressions : DataFrame
        Per covariate, model (``ols`` line of the rate, ``poisson``, ``negbin``) and term
        (``intercept``, ``slope``): ``g`` (``log`` or ``linear``: the regressor is
        ``log x`` or ``x``), ``estimate``, ``stderr``, ``ci_low``, ``ci_high`` (95 %).
        On ``log``, the count models' slope is the exponent ``b`` of ``rate ∝ x^b``.
    overdispersion : DataFrame
        Per covariate: Pearson dispersion of the Poisson fit, the negative-binomial
        ``alpha`` and the LR test of ``alpha = 0``.
    skipped : DataFrame
        ``sequence``, ``what`` (the step that skipped it) and ``reason``.
    reference : DataFrame or None
        With ``reference=``: per group, ``n_events``, ``expected`` (sum of reference rate
        times window), ``ratio`` (observed / expected), ``dispersion`` (the quasi-Poisson
        factor, >= 1) and its 95 % interval ``ci_low``, ``ci_high``.
    events : EventTable
        The checked input.
    """

    sequences: pd.DataFrame
    poisson: pd.DataFrame
    heterogeneity: pd.DataFrame
    renewal_per_sequence: pd.DataFrame
    renewal_pooled: pd.DataFrame
    regressions: pd.DataFrame
    overdispersion: pd.DataFrame
    skipped: pd.DataFrame
    events: EventTable
    group: str | None
    reference: pd.DataFrame | None
    reference_column: str | None
    alpha: float
    n_mc: int

    def __repr__(self) -> str:
        return (
            f"Analysis(n_sequences={len(self.sequences)}, "
            f"n_events={int(self.sequences['n_events'].sum())}, "
            f"groups={self.sequences['group'].nunique()}, alpha={self.alpha})"
        )

    def tables(self) -> dict:
        """Every table by file stem (what ``kicktimes analyze`` writes as CSV)."""
        seq = self.sequences.drop(columns=["times"], errors="ignore")
        out = {
            "sequences": seq,
            "poisson_tests": self.poisson,
            "rate_homogeneity": self.heterogeneity,
            "renewal_per_sequence": self.renewal_per_sequence,
            "renewal_pooled": self.renewal_pooled,
            "count_regressions": self.regressions,
            "count_overdispersion": self.overdispersion,
            "skipped": self.skipped,
        }
        if self.reference is not None:
            out["reference_rate"] = self.reference
        return out

    def findings(self) -> list:
        """One computed statement per question (:class:`kicktimes.stats.Finding`: the
        question, the verdict, the statement with its numbers, and the rule)."""
        from .findings import findings

        return findings(self)

    def summary(self) -> str:
        """The findings: the question and its verdict (one per group), then the
        statement with its numbers."""
        return "\n".join(
            f"- {f.question}{' ' if f.question.endswith('?') else ': '}{f.verdict}.\n"
            f"  {f.statement}"
            for f in self.findings()
        )


#: the events' column roles and their default names (``columns=`` of `analyze`)
COLUMNS = {"sequence": "sequence", "time": "time", "start": "t_start", "end": "t_end"}


def check_columns(columns) -> dict:
    """``columns`` (None or a dict from the roles of `COLUMNS` to column names) with the
    default name of every role it leaves out."""
    if columns is None:
        return dict(COLUMNS)
    if not isinstance(columns, dict):
        raise TypeError(f"columns must be None or a dict from {sorted(COLUMNS)} to column "
                        f"names, got {type(columns).__name__}")
    unknown = sorted(set(columns) - set(COLUMNS))
    if unknown:
        raise ValueError(f"columns: unknown roles {unknown}; the roles are {sorted(COLUMNS)}")
    for role, name in columns.items():
        if not isinstance(name, str):
            raise TypeError(f"columns[{role!r}] must be a column name (str), got "
                            f"{type(name).__name__}")
    return {**COLUMNS, **columns}


@translator(*COLUMNS)
def _old_analyze(args, kwargs):
    kwargs = dict(kwargs)
    old = pop_old(kwargs, COLUMNS)
    warn_old(", ".join(f"analyze({k}=...)" for k in old),
             "analyze(..., columns={" + ", ".join(f"{k!r}: ..." for k in old) + "})")
    if kwargs.get("columns") is not None:
        raise TypeError(f"analyze: give {', '.join(old)} in columns=, not as keywords")
    kwargs["columns"] = old
    return kwargs, None


@old_keywords(_old_analyze)
def analyze(
    events,
    *,
    windows=None,
    window=None,
    columns=None,
    covariates=None,
    group=None,
    reference=None,
    alpha=0.05,
    n_mc=199,
    max_fits_per_group=12,
    max_pooled_intervals=200_000,
    rng=None,
) -> Analysis:
    r"""Analyse collision (event) times from any source as kicktimes analyses its own.

    Parameters
    ----------
    events : DataFrame, path, list of them, or EventTable
        One row per event (see :func:`kicktimes.stats._table.event_table` for the
        contract: ``windows``, ``window``, the ``columns`` and ``covariates`` are passed
        to it).
    columns : dict, optional
        The names of the events' columns by role, those left out keeping their defaults:
        ``{"sequence": "sequence", "time": "time", "start": "t_start", "end": "t_end"}``
        (the sequence id, the event time, and the window's start and end), e.g.
        ``columns={"sequence": "run", "time": "t"}``.
    group : str, optional
        A per-sequence column whose values group the sequences (pooled fits, one Poisson
        ensemble and one rate-homogeneity test per group): a numeric covariate, or a
        text label (``kind = "poisson"``), whose groups keep their order of first
        appearance. Default: one group, ``"all"``.
    reference : str, optional
        A covariate holding each sequence's expected rate (e.g. a kinetic-theory rate):
        ``Analysis.reference`` then compares the observed rate with it per group.
    alpha : float, optional
        Level of the tests and of the FDR control.
    n_mc : int, optional
        Monte Carlo samples of the conditional nulls (p-value resolution
        ``1/(n_mc + 1)``).
    max_fits_per_group : int or None, optional
        Sequences (first by order of appearance) per group that get their own renewal
        comparison (6 censored fits, ~0.4 s each); ``None``: all.
    max_pooled_intervals : int, optional
        Interval budget of a group's pooled fits (whole sequences in order).
    rng : Generator or int, optional
        Seed of the Monte Carlo: one child stream per group, and the nulls of equal n
        shared by the groups (`MonteCarloNulls`).

    Returns
    -------
    Analysis

    Notes
    -----
    Times are shifted to ``t - t_start``, so each sequence is observed on
    ``[0, T]`` with ``T = t_end - t_start`` (the convention of
    :func:`intervals_from_times`): inner intervals are complete, the first time is a
    forward recurrence time (dropped), the time from the last event to ``t_end`` is
    right-censored. Regressions use one covariate at a time; a covariate with fewer
    than two distinct values is skipped (listed in ``skipped``).

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from kicktimes import stats
    >>> rng = np.random.default_rng(0)
    >>> rows = [(f"s{k}", t, d) for k, d in enumerate([1.0, 1.0, 2.0, 2.0] * 3)
    ...         for t in np.sort(rng.uniform(0, 100, rng.poisson(d * 100)))]
    >>> df = pd.DataFrame(rows, columns=["sequence", "time", "density"])
    >>> res = stats.analyze(df, window=(0, 100), group="density", rng=1,
    ...                     max_fits_per_group=2)
    >>> slope = res.regressions.query("model == 'poisson' and term == 'slope'")["estimate"]
    >>> round(float(slope.iloc[0]), 1)   # the rate doubles with the density: slope near 1
    1.1
    """
    columns = check_columns(columns)
    named = [covariates] if isinstance(covariates, str) else covariates
    tab = (
        events
        if isinstance(events, EventTable)
        else event_table(
            events,
            windows=windows,
            window=window,
            sequence=columns["sequence"],
            time=columns["time"],
            start=columns["start"],
            end=columns["end"],
            covariates=covariates,
            # a group outside the named covariates is kept as a label (text)
            labels=[group]
            if isinstance(group, str) and named is not None and group not in named
            else None,
        )
    )
    alpha = check_real("alpha", alpha, low=0.0, high=1.0)
    n_mc = check_int("n_mc", n_mc, low=19)
    if max_fits_per_group is not None:
        max_fits_per_group = check_int("max_fits_per_group", max_fits_per_group, low=0)
    max_pooled_intervals = check_int("max_pooled_intervals", max_pooled_intervals, low=10)
    rng = check_rng(rng)
    seqs = tab.sequences.copy()
    if group is not None:
        if group not in tab.covariates + tab.labels:
            raise ValueError(
                f"group must name a per-sequence column, one of "
                f"{list(tab.covariates + tab.labels)!r}, got {group!r}"
            )
        seqs.insert(1, "group", seqs[group])
    else:
        seqs.insert(1, "group", _ALL)
    skipped = [
        (s, "Poisson tests, renewal fits", "no events in the window")
        for s in seqs.loc[seqs["n_events"] == 0, "sequence"]
    ]
    groups = list(pd.unique(seqs["group"]))
    streams = rng.spawn(len(groups))
    # the groups share the Monte Carlo nulls of equal n (the conditional nulls depend on
    # n only), as the radii of a sweep report do
    nulls = MonteCarloNulls(int(rng.integers(2**63 - 1)))
    rej_rows, hom_rows, per_rows, pooled_rows, seq_p = [], [], [], [], []
    for g, stream in zip(groups, streams, strict=True):
        part = seqs[seqs["group"] == g]
        rows, hom, pvals = _poisson(part, g, alpha=alpha, n_mc=n_mc, rng=stream, nulls=nulls)
        rej_rows += rows
        hom_rows.append(hom)
        seq_p.append(pvals)
        per, pooled, skip = _renewal(
            part, g, max_fits=max_fits_per_group, max_pooled=max_pooled_intervals
        )
        per_rows += per
        pooled_rows += pooled
        skipped += skip
    seqs = seqs.merge(pd.concat(seq_p), on="sequence", how="left")
    per_seq = pd.DataFrame(per_rows, columns=_RENEWAL_COLS)
    best = (
        per_seq.loc[per_seq["delta_aic"] == 0]
        .drop_duplicates("sequence")
        .set_index("sequence")["model"]
        if not per_seq.empty
        else pd.Series(dtype=object)
    )
    seqs["best_model"] = seqs["sequence"].map(best)
    regressions, overdispersion, skip = _regressions(tab, seqs)
    skipped += skip
    if reference is not None:
        if reference not in tab.covariates:
            raise ValueError(
                f"reference must be one of the covariates {list(tab.covariates)!r}, got "
                f"{reference!r}"
            )
        bad = ~(seqs[reference].to_numpy(float) > 0)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"reference column {reference!r} must be positive, got "
                f"{seqs[reference].iloc[i]!r} for sequence {seqs['sequence'].iloc[i]!r}"
            )
    return Analysis(
        sequences=seqs,
        poisson=pd.DataFrame(rej_rows),
        heterogeneity=pd.DataFrame(hom_rows),
        renewal_per_sequence=per_seq,
        renewal_pooled=pd.DataFrame(pooled_rows, columns=["group", *_RENEWAL_COLS[2:]]),
        regressions=regressions,
        overdispersion=overdispersion,
        skipped=pd.DataFrame(skipped, columns=["sequence", "what", "reason"]),
        events=tab,
        group=group,
        reference=None if reference is None else _reference(seqs, reference),
        reference_column=reference,
        alpha=alpha,
        n_mc=n_mc,
    )


# ------------------------------------------------------------------ Poisson tests


def _poisson(part, g, *, alpha, n_mc, rng, nulls):
    res = poisson_group(list(part["times"]), part["t_window"].to_numpy(float), alpha=alpha,
                        n_mc=n_mc, rng=rng, nulls=nulls)
    rows = [{"group": g, **row} for row in res.rejections.to_dict("records")]
    ens = res.ensemble
    pcols = [f"p_{t}" for t in TESTS] + ["p_rate"]
    pvals = ens.per_sequence[pcols].reset_index(drop=True)
    pvals.insert(0, "sequence", part["sequence"].to_numpy())
    pvals["reject_any_fdr"] = ens.reject[list(TESTS)].any(axis=1).to_numpy()
    return rows, {"group": g, **res.homogeneity}, pvals


# ----------------------------------------------------------------- renewal models

_RENEWAL_COLS = [
    "group",
    "sequence",
    "model",
    "loglik",
    "k",
    "aic",
    "delta_aic",
    "weight",
    "n",
    "n_censored",
    "note",
]


def _compare(complete, censored):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # optimiser chatter; failed fits are in 'note'
        return compare_models(complete, censored=censored)


def _renewal(part, g, *, max_fits, max_pooled):
    per, pooled, skipped = [], [], []
    cols = _RENEWAL_COLS[3:]
    n_used, iv = pooled_intervals(
        list(part["times"]),
        part["t_window"].to_numpy(float),
        part["n_events"].to_numpy(),
        max_intervals=max_pooled,
    )
    if iv.complete.size >= MIN_INTERVALS:
        for model, t in _compare(iv.complete, iv.censored).iterrows():
            pooled.append({"group": g, "model": model, **{c: t[c] for c in cols}})
    for s in part["sequence"].iloc[n_used:]:
        skipped.append((s, "pooled renewal fit", f"over the budget of {max_pooled} intervals"))
    n_fitted = 0
    for row in part.itertuples():
        if row.n_events == 0:
            continue
        iv = intervals_from_times(row.times, row.t_window)
        if iv.complete.size < MIN_INTERVALS:
            skipped.append(
                (row.sequence, "renewal fit", f"{iv.complete.size} < {MIN_INTERVALS} intervals")
            )
            continue
        if max_fits is not None and n_fitted >= max_fits:
            skipped.append((row.sequence, "renewal fit", f"beyond max_fits_per_group = {max_fits}"))
            continue
        n_fitted += 1
        for model, t in _compare(iv.complete, iv.censored).iterrows():
            per.append(
                {"group": g, "sequence": row.sequence, "model": model, **{c: t[c] for c in cols}}
            )
    return per, pooled, skipped


# ---------------------------------------------------------------- reference rate


def _reference(seqs, col):
    r"""Observed against expected counts per group, with a quasi-Poisson 95 % interval.

    ``ratio = sum N / sum(rate_ref T)``; ``phi = max(1, X^2 / (k - 1))`` with
    :math:`X^2 = \sum (N_i - \hat r e_i)^2 / (\hat r e_i)` over the group's k sequences
    (extra-Poisson spread across sequences widens the interval); the interval is
    ``ratio * exp(+-1.96 sqrt(phi / sum N))``, and ``[0, 3.689 / sum e]`` (exact Poisson)
    when no event was seen. Sequences are taken as independent.
    """
    rows = []
    for g, part in seqs.groupby("group", sort=False, observed=True):
        n = part["n_events"].to_numpy(float)
        e = (part[col] * part["t_window"]).to_numpy(float)
        total, expected = n.sum(), e.sum()
        ratio = total / expected
        phi = 1.0
        if n.size > 1 and total > 0:
            fitted = ratio * e
            phi = max(1.0, float(((n - fitted) ** 2 / fitted).sum() / (n.size - 1)))
        if total > 0:
            half = 1.959963984540054 * math.sqrt(phi / total)
            lo, hi = ratio * math.exp(-half), ratio * math.exp(half)
        else:
            lo, hi = 0.0, 3.688879454113936 / expected
        rows.append(
            {
                "group": g,
                "n_sequences": n.size,
                "n_events": int(total),
                "expected": expected,
                "ratio": ratio,
                "dispersion": phi,
                "ci_low": lo,
                "ci_high": hi,
            }
        )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------- count regressions


def _regressions(tab, seqs):
    """Counts on each covariate through :func:`regress_counts`.

    ``regress_counts`` models a disk radius and checks ``0 < r < 0.5``; any covariate
    ``x`` is mapped affinely into that range (``x' = a + c x``) and the coefficients are
    mapped back, which is exact: on ``log x`` (all ``x > 0``, ``a = 0``) the slope is
    unchanged and the intercept shifts by ``slope * log c``; on ``x`` the slope scales
    by ``c`` and the intercept shifts by ``slope' * a``.
    """
    rows, od_rows, skipped = [], [], []
    for cov in tab.covariates:
        x = seqs[cov].to_numpy(float)
        if np.unique(x).size < 2:
            skipped.append(("(all)", f"count regression on {cov}", "fewer than 2 distinct values"))
            continue
        log = bool((x > 0).all())
        if log:
            a, c = 0.0, 0.4 / x.max()
        else:
            c = 0.4 / np.ptp(x)
            a = 0.05 - c * x.min()
        df = pd.DataFrame(
            {"radius": a + c * x, "count": seqs["n_events"], "t_window": seqs["t_window"]}
        )
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # OLS through 2 points: no residual variance
            reg = regress_counts(df, covariate="log_radius" if log else "radius")
        for model in ("ols", "poisson", "negbin"):
            linear = model == "ols" or not log
            shift = a if linear else math.log(c)
            scale = c if linear else 1.0
            rows += _back_transform(
                reg, cov, model, "log" if log and not linear else "linear", shift, scale
            )
        od = reg.overdispersion()
        od_rows.append({"covariate": cov, **od.to_dict()})
    cols = ["covariate", "g", "model", "term", "estimate", "stderr", "ci_low", "ci_high"]
    od_cols = ["covariate", "pearson_dispersion", "lr_statistic", "lr_pvalue", "alpha"]
    return pd.DataFrame(rows, columns=cols), pd.DataFrame(od_rows, columns=od_cols), skipped


def _back_transform(reg, cov, model, g, shift, scale):
    """Intercept and slope of ``eta = b0 + b1 u`` with ``u = shift + scale * v`` on ``v``,
    with the standard errors `regress_counts` decided (NaN where undefined)."""
    b = reg.params(model)[:2]
    v = reg.cov_params(model)[:2, :2]
    se = np.sqrt(np.diag(v))
    if model == "ols":
        df_resid = len(reg.by_radius) - 2
        q = float(sps.t.ppf(0.975, df_resid)) if df_resid > 0 else math.nan
    else:
        q = float(sps.norm.ppf(0.975))  # Wald intervals, as statsmodels' conf_int
    b0 = b[0] + b[1] * shift
    var0 = v[0, 0] + 2 * shift * v[0, 1] + shift**2 * v[1, 1]
    se0 = math.sqrt(var0) if var0 >= 0 else math.nan
    b1, se1 = b[1] * scale, se[1] * scale
    return [
        {
            "covariate": cov,
            "g": g,
            "model": model,
            "term": term,
            "estimate": est,
            "stderr": err,
            "ci_low": est - q * err,
            "ci_high": est + q * err,
        }
        for term, est, err in (("intercept", b0, se0), ("slope", b1, se1))
    ]
