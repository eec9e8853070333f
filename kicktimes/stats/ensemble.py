r"""Poisson tests over an ensemble of sequences (one per initial condition).

Each sequence is tested on its own (:func:`kicktimes.stats.test_poisson`'s tests,
conditional on its own n), then, per test, the p-values are

* combined into one ensemble p-value (:func:`scipy.stats.combine_pvalues`; the
  global null "every sequence is Poisson"), and
* screened with a false-discovery-rate procedure across sequences
  (:func:`statsmodels.stats.multitest.multipletests`), which names the sequences
  that are not Poisson (sticky orbits, for example).

Separately, the rates are compared across sequences: given the total count N, the
counts of Poisson sequences with a common rate are multinomial with probabilities
proportional to their windows (exposures). Heterogeneous rates are what makes pooled
intervals hyperexponential even when every sequence is Poisson.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats
from statsmodels.stats.multitest import multipletests

from ._checks import check_choice, check_int, check_real, check_rng, check_times
from .poisson import (
    COMBINE_METHODS,
    FDR_METHODS,
    TESTS,
    _check_options,
    _run_tests,
    _windows,
    check_nulls,
)


@dataclass(frozen=True, repr=False)
class PoissonEnsembleResult:
    """Result of :func:`test_poisson_ensemble`.

    Attributes
    ----------
    per_sequence : pandas.DataFrame
        One row per sequence: ``n_events``, ``t_window``, ``rate``, ``p_<test>`` for
        every test and ``p_rate`` (two-sided exact binomial test of the sequence's
        count against the pooled rate, given the total).
    statistics : pandas.DataFrame
        The test statistics, one column per test.
    reject : pandas.DataFrame
        FDR decisions (bool), one column per test and ``rate``.
    combined : pandas.DataFrame
        Per test: ``statistic`` and ``pvalue`` of the combination, ``n_sequences``
        tested, ``n_reject_raw`` (p < alpha) and ``n_reject_fdr``.
    rate_homogeneity : pandas.DataFrame
        Rows ``pearson`` and ``likelihood_ratio``: ``statistic``, ``df``, ``pvalue``
        (chi-square) and ``pvalue_mc`` (exact conditional Monte Carlo).
    notes : pandas.DataFrame
        Why a test did not run on a sequence (empty string when it did).
    """

    per_sequence: pd.DataFrame
    statistics: pd.DataFrame
    reject: pd.DataFrame
    combined: pd.DataFrame
    rate_homogeneity: pd.DataFrame
    notes: pd.DataFrame
    alpha: float
    combine: str
    fdr: str
    n_mc: int

    def __repr__(self) -> str:
        return (
            f"PoissonEnsembleResult(n_sequences={len(self.per_sequence)}, alpha={self.alpha}, "
            f"combine={self.combine!r}, fdr={self.fdr!r})"
        )

    def to_frame(self) -> pd.DataFrame:
        """The per-sequence table (`per_sequence`, a copy)."""
        return self.per_sequence.copy()

    def summary(self) -> str:
        """Combined p-values, FDR counts and the rate-homogeneity test as text."""
        k = len(self.per_sequence)
        lines = [
            f"Poisson tests over {k} sequences ({self.combine} combination, {self.fdr} at "
            f"alpha = {self.alpha}, Monte Carlo n_mc = {self.n_mc})",
            self.combined.to_string(float_format=lambda v: f"{v:.4g}"),
            "",
            "Rate homogeneity across sequences (given the total count):",
            self.rate_homogeneity.to_string(float_format=lambda v: f"{v:.4g}"),
            f"sequences flagged by the rate test after FDR: {int(self.reject['rate'].sum())}",
        ]
        return "\n".join(lines)


def _rate_tests(counts, windows, n_mc, rng):
    """Pearson and likelihood-ratio tests of a common rate, asymptotic and exact."""
    total = counts.sum()
    share = windows / windows.sum()
    k = counts.size
    out = pd.DataFrame(
        np.nan,
        index=pd.Index(["pearson", "likelihood_ratio"], name="test"),
        columns=["statistic", "df", "pvalue", "pvalue_mc"],
    )
    out["df"] = k - 1
    if total == 0 or k < 2:
        return out, np.full(k, np.nan)

    def pearson(c):
        expected = total * share
        return ((c - expected) ** 2 / expected).sum(axis=-1)

    def g_stat(c):
        expected = total * share
        with np.errstate(divide="ignore", invalid="ignore"):
            terms = np.where(c > 0, c * np.log(c / expected), 0.0)
        return 2.0 * terms.sum(axis=-1)

    null = rng.multinomial(total, share, size=n_mc)
    for name, fun in (("pearson", pearson), ("likelihood_ratio", g_stat)):
        s = float(fun(counts))
        sim = fun(null)
        out.loc[name, ["statistic", "pvalue", "pvalue_mc"]] = [
            s,
            stats.chi2.sf(s, k - 1),
            (1 + np.count_nonzero(sim >= s - 1e-9 * abs(s))) / (n_mc + 1),
        ]
    # Per-sequence outlier test: count_i ~ Binomial(N, T_i / sum T) under a common rate.
    low = stats.binom.cdf(counts, total, share)
    high = stats.binom.sf(counts - 1, total, share)
    return out, np.minimum(1.0, 2.0 * np.minimum(low, high))


def test_poisson_ensemble(
    sequences,
    windows,
    *,
    alpha=0.05,
    combine="fisher",
    fdr="fdr_bh",
    n_mc=999,
    n_mc_max=99_999,
    lags=None,
    n_bins=None,
    randomize=True,
    rng=None,
    nulls=None,
):
    r"""Poisson tests on every sequence of an ensemble, combined and FDR-screened.

    Parameters
    ----------
    sequences : list of array_like
        Event times of each sequence (strictly increasing, inside its window).
    windows : float or sequence of float
        Observation window of each sequence (or one common window).
    alpha : float, optional
        Level of the FDR procedure and of the raw rejection counts.
    combine : str, optional
        Method of :func:`scipy.stats.combine_pvalues` (``"fisher"``, ``"pearson"``,
        ``"tippett"``, ``"stouffer"``, ``"mudholkar_george"``).
    fdr : str, optional
        Method of :func:`statsmodels.stats.multitest.multipletests`
        (default Benjamini-Hochberg ``"fdr_bh"``).
    n_mc, lags, n_bins, randomize :
        As in :func:`test_poisson`.
    n_mc_max : int, optional
        Cap of the adaptive Monte Carlo refinement (see Notes).
    rng : Generator or int, optional
        Source of randomness.
    nulls : MonteCarloNulls, optional
        Take the Monte Carlo nulls of the per-sequence tests from this bank, shared with
        every other call given it (the groups of a report share the nulls of equal
        ``n``), instead of drawing them from ``rng``; ``rng`` still draws the tie-breaking
        uniforms and the rate test's null.

    Returns
    -------
    PoissonEnsembleResult

    Notes
    -----
    Sequences with the same number of events share one Monte Carlo null sample (the
    conditional null depends on n only); this makes the ensemble fast and leaves
    each sequence's p-value exact, but the p-values of sequences with equal n are
    not independent given that sample, by an amount of order
    :math:`1/\sqrt{n_{mc}}`; raise ``n_mc`` when combining very many sequences.

    A Monte Carlo p-value cannot go below :math:`1/(n_{mc}+1)`, while
    Benjamini-Hochberg needs :math:`p \le \alpha/k` to flag a lone outlier among k
    sequences. So the nulls of the groups holding a sequence with fewer than 10 null
    exceedances and a p-value above the running FDR cut-off are doubled until that is
    resolved or ``n_mc_max`` is reached: isolated strong signals (sticky orbits) are
    flagged, and the cost stays that of ``n_mc`` when nothing is extreme.
    Rate homogeneity: with counts :math:`N_i`, windows :math:`T_i` and
    :math:`e_i = N T_i / \sum T`, Pearson :math:`X^2 = \sum (N_i - e_i)^2 / e_i`
    and :math:`G = 2 \sum N_i \log(N_i / e_i)`, both :math:`\chi^2_{k-1}` for large
    counts; ``pvalue_mc`` uses the exact multinomial law given N.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> rng = np.random.default_rng(0)
    >>> seqs = [np.sort(rng.uniform(0, 50, size=rng.poisson(50))) for _ in range(20)]
    >>> ens = stats.test_poisson_ensemble(seqs, 50.0, rng=1)
    >>> int(ens.reject["uniformity_ks"].sum())
    0
    """
    if isinstance(sequences, np.ndarray) and sequences.dtype != object:
        if sequences.ndim != 2:
            raise TypeError(
                "sequences must be a list of 1-D arrays or a 2-D array with one sequence per "
                f"row, got an array of shape {sequences.shape} (use test_poisson for one sequence)"
            )
        seqs = list(sequences)
    else:
        try:
            seqs = list(sequences)
        except TypeError:
            raise TypeError(
                f"sequences must be a list of 1-D arrays, got {type(sequences).__name__}"
            ) from None
    if not seqs:
        raise ValueError("sequences must hold at least one sequence, got none")
    ws = _windows(windows, len(seqs))
    seqs = [
        check_times(f"sequences[{i}]", s, w) for i, (s, w) in enumerate(zip(seqs, ws, strict=True))
    ]
    alpha = check_real("alpha", alpha, low=0.0, high=1.0)
    check_choice("combine", combine, COMBINE_METHODS)
    check_choice("fdr", fdr, FDR_METHODS)
    n_mc, lags, n_bins = _check_options(n_mc, lags, n_bins)
    rng = check_rng(rng)
    n_mc_max = max(n_mc, check_int("n_mc_max", n_mc_max, low=19))
    stat, pval, notes, _ = _run_tests(
        seqs,
        ws,
        lags=lags,
        n_bins=n_bins,
        n_mc=n_mc,
        rng=rng,
        randomize=randomize,
        refine=(alpha, fdr, n_mc_max),
        nulls=check_nulls(nulls),
    )
    counts = np.array([s.size for s in seqs])
    homogeneity, p_rate = _rate_tests(counts, ws, n_mc, rng)
    index = pd.RangeIndex(len(seqs), name="sequence")
    per_seq = pd.DataFrame({"n_events": counts, "t_window": ws, "rate": counts / ws}, index=index)
    for j, name in enumerate(TESTS):
        per_seq[f"p_{name}"] = pval[:, j]
    per_seq["p_rate"] = p_rate
    reject = pd.DataFrame(False, index=index, columns=[*TESTS, "rate"])
    rows = []
    for name in [*TESTS, "rate"]:
        p = per_seq[f"p_{name}"].to_numpy()
        ok = np.isfinite(p)
        if ok.any():
            reject.loc[ok, name] = multipletests(p[ok], alpha=alpha, method=fdr)[0]
        if name == "rate":
            continue
        row = {"test": name, "statistic": np.nan, "pvalue": np.nan, "n_sequences": int(ok.sum())}
        if ok.any():
            # combine_pvalues rejects exact zeros; Monte Carlo p-values are >= 1/(n_mc+1).
            res = stats.combine_pvalues(np.clip(p[ok], 1e-300, 1.0), method=combine)
            row.update(statistic=float(res.statistic), pvalue=float(res.pvalue))
        row["n_reject_raw"] = int((p[ok] < alpha).sum())
        row["n_reject_fdr"] = int(reject.loc[ok, name].sum())
        rows.append(row)
    combined = pd.DataFrame(rows).set_index("test")
    statistics = pd.DataFrame(stat, index=index, columns=list(TESTS))
    note_table = pd.DataFrame(
        [[nt.get(name, "") for name in TESTS] for nt in notes], index=index, columns=list(TESTS)
    )
    return PoissonEnsembleResult(
        per_sequence=per_seq,
        statistics=statistics,
        reject=reject,
        combined=combined,
        rate_homogeneity=homogeneity,
        notes=note_table,
        alpha=alpha,
        combine=combine,
        fdr=fdr,
        n_mc=n_mc,
    )


test_poisson_ensemble.__test__ = False  # a library function, not a pytest test
