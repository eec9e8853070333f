r"""One group of sequences: the Poisson battery, the rate-homogeneity row and the pooled
intervals.

A *group* is a set of sequences observed under the same conditions: the sequences of one
value of ``--group`` in :func:`kicktimes.stats.analyze`, the ICs of one radius in the
sweep report (:mod:`kicktimes.report.poisson`, :mod:`kicktimes.report.renewal`). Both
compute their per-group tables here, so the rows are the same wherever they appear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes._results import TableResult

from ._checks import check_int
from .ensemble import PoissonEnsembleResult, test_poisson_ensemble
from .poisson import TESTS, Intervals, intervals_from_times

__all__ = ["PoissonGroup", "poisson_group", "pooled_intervals"]


@dataclass(frozen=True, repr=False)
class PoissonGroup(TableResult):
    """Result of :func:`poisson_group`: the tests of one group of sequences, as table rows.

    Attributes
    ----------
    ensemble : PoissonEnsembleResult
        The per-sequence tests, combinations and FDR decisions.
    rejections : pandas.DataFrame
        One row per test of :data:`~kicktimes.stats.TESTS`: ``test``, ``n_tested``
        (sequences with enough events for it), ``n_reject`` (p < alpha), ``n_reject_fdr``,
        ``rate`` (``n_reject / n_tested``, NaN when none was tested) and
        ``combined_pvalue`` (the combination over the tested sequences).
    homogeneity : dict
        ``n_sequences``, ``n_empty`` (sequences without events), ``pooled_rate``
        (:math:`\\sum N / \\sum T`), ``median_rate``, ``dispersion_index`` (see Notes of
        :func:`poisson_group`), ``pearson_statistic``, ``df``, ``pvalue`` and
        ``pvalue_mc`` (Pearson test of a common rate, asymptotic and exact), ``lr_pvalue``
        (likelihood-ratio test) and ``n_flagged_fdr`` (sequences whose count is
        incompatible with the group's rate after FDR).
    """

    _title = "Poisson tests of one group of sequences"
    _summary_fields = ()
    _frame = "rejections"

    ensemble: PoissonEnsembleResult
    rejections: pd.DataFrame
    homogeneity: dict

    def _summary_extra(self) -> list[str]:
        h = self.homogeneity
        table = self.rejections.to_string(index=False, float_format=lambda v: f"{v:.4g}")
        return [
            f"sequences: {h['n_sequences']} ({h['n_empty']} without events); pooled rate "
            f"{h['pooled_rate']:.6g}, median rate {h['median_rate']:.6g}",
            f"common rate: dispersion index {h['dispersion_index']:.4g}, Pearson "
            f"{h['pearson_statistic']:.4g} on {h['df']} df (p = {h['pvalue']:.3g}, Monte Carlo "
            f"{h['pvalue_mc']:.3g}), LR p = {h['lr_pvalue']:.3g}; {h['n_flagged_fdr']} "
            "sequence(s) flagged after FDR",
            *table.split("\n"),
        ]

    def __repr__(self) -> str:
        h = self.homogeneity
        return (
            f"PoissonGroup(n_sequences={h['n_sequences']}, pooled_rate={h['pooled_rate']:.4g}, "
            f"dispersion_index={h['dispersion_index']:.4g}, pvalue_mc={h['pvalue_mc']:.4g})"
        )


def poisson_group(times, windows, *, alpha=0.05, n_mc=199, rng=None, nulls=None) -> PoissonGroup:
    r"""Poisson tests of every sequence of one group and the test of a common rate.

    Parameters
    ----------
    times : list of array_like
        Event times of each sequence, strictly increasing in ``[0, T_i]``.
    windows : float or sequence of float
        Observation window ``T_i`` of each sequence (or one common window).
    alpha : float, optional
        Level of the rejection counts and of the FDR control.
    n_mc : int, optional
        Monte Carlo samples of the conditional nulls.
    rng : Generator or int, optional
        The stream of the Monte Carlo (give each group its own).
    nulls : MonteCarloNulls, optional
        Take the per-sequence tests' nulls from this bank, shared by the groups given it
        (`test_poisson_ensemble`).

    Returns
    -------
    PoissonGroup
        The ensemble result, one rejection row per test and the group's rate-homogeneity
        row.

    Notes
    -----
    With counts :math:`N_i` over the group's :math:`k` sequences, the index of dispersion
    is the sample variance over the mean, :math:`D = s^2_N / \bar N` (1 for Poisson
    counts of a common rate and equal windows). It is undefined (NaN) for a single
    sequence (no variance) and for a group without events (no mean); the tests of a
    common rate are NaN there too (:func:`test_poisson_ensemble`).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> rng = np.random.default_rng(0)
    >>> seqs = [np.sort(rng.uniform(0, 50, rng.poisson(40))) for _ in range(8)]
    >>> res = stats.poisson_group(seqs, 50.0, n_mc=99, rng=1)
    >>> res.homogeneity["n_sequences"], bool(0.5 < res.homogeneity["dispersion_index"] < 2)
    (8, True)
    >>> stats.poisson_group([seqs[0]], 50.0, n_mc=99, rng=1).homogeneity["dispersion_index"]
    nan
    """
    ens = test_poisson_ensemble(times, windows, alpha=alpha, n_mc=n_mc, rng=rng, nulls=nulls)
    rows = []
    for test in TESTS:
        p = ens.per_sequence[f"p_{test}"].to_numpy()
        ok = np.isfinite(p)
        comb = ens.combined.loc[test]
        n_tested = int(ok.sum())
        rows.append(
            {
                "test": test,
                "n_tested": n_tested,
                "n_reject": int((p[ok] < alpha).sum()),
                "n_reject_fdr": int(comb["n_reject_fdr"]),
                "rate": (p[ok] < alpha).mean() if n_tested else math.nan,
                "combined_pvalue": float(comb["pvalue"]),
            }
        )
    counts = ens.per_sequence["n_events"].to_numpy(float)
    win = ens.per_sequence["t_window"].to_numpy(float)
    mean = counts.mean()
    hom = ens.rate_homogeneity
    homogeneity = {
        "n_sequences": counts.size,
        "n_empty": int((counts == 0).sum()),
        "pooled_rate": counts.sum() / win.sum(),
        "median_rate": float(np.median(counts / win)),
        # one sequence has no variance, a group without events no mean: D is undefined
        "dispersion_index": (
            counts.var(ddof=1) / mean if mean > 0 and counts.size > 1 else math.nan
        ),
        "pearson_statistic": hom.loc["pearson", "statistic"],
        "df": hom.loc["pearson", "df"],
        "pvalue": hom.loc["pearson", "pvalue"],
        "pvalue_mc": hom.loc["pearson", "pvalue_mc"],
        "lr_pvalue": hom.loc["likelihood_ratio", "pvalue"],
        "n_flagged_fdr": int(ens.reject["rate"].sum()),
    }
    return PoissonGroup(ens, pd.DataFrame(rows), homogeneity)


def pooled_intervals(times, windows, n_events, *, max_intervals) -> tuple[int, Intervals]:
    """The intervals of a group's pooled renewal fit: whole sequences, in order, until
    ``max_intervals`` complete intervals are used.

    Parameters
    ----------
    times : list of array_like
        Event times of each sequence, in the order they are taken.
    windows : sequence of float
        Observation window of each sequence.
    n_events : sequence of int
        Number of events of each sequence (a sequence of ``n`` events has ``n - 1``
        complete intervals).
    max_intervals : int
        The budget: a sequence is taken when the intervals before it are fewer than this,
        so the last one taken may pass the budget by its own intervals.

    Returns
    -------
    (int, Intervals)
        How many sequences were taken (the first ones), and their pooled intervals
        (:func:`intervals_from_times`).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> times = [np.array([1.0, 2.0, 4.0]), np.array([0.5, 1.0]), np.array([3.0, 3.5])]
    >>> n_used, iv = stats.pooled_intervals(times, [5.0, 5.0, 5.0], [3, 2, 2], max_intervals=2)
    >>> n_used, iv.complete.tolist()
    (1, [1.0, 2.0])
    """
    max_intervals = check_int("max_intervals", max_intervals, low=1)
    sizes = np.maximum(np.asarray(n_events) - 1, 0)
    used = np.cumsum(sizes) - sizes < max_intervals
    n_used = int(used.sum())
    win = np.asarray(windows, float)[used]
    return n_used, intervals_from_times([t for t, u in zip(times, used, strict=True) if u], win)
