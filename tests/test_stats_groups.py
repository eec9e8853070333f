"""``stats.poisson_group`` and ``stats.pooled_intervals``: the per-group tables that
``kicktimes analyze`` computes per group and the sweep report per radius."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from kicktimes import stats


def _sequences(counts, window=50.0, seed=0):
    rng = np.random.default_rng(seed)
    return [np.sort(rng.uniform(0.0, window, n)) for n in counts]


def test_the_group_rows_count_the_ensembles_rejections_and_rates():
    seqs = _sequences([30, 45, 0, 60, 38, 2])
    res = stats.poisson_group(seqs, 50.0, alpha=0.1, n_mc=99, rng=3)
    ens = stats.test_poisson_ensemble(seqs, 50.0, alpha=0.1, n_mc=99, rng=3)
    assert list(res.rejections["test"]) == list(stats.TESTS)
    for row in res.rejections.itertuples():
        p = ens.per_sequence[f"p_{row.test}"].to_numpy()
        tested = p[np.isfinite(p)]
        assert row.n_tested == tested.size and row.n_reject == int((tested < 0.1).sum())
        assert row.rate == pytest.approx(row.n_reject / row.n_tested)
        assert row.combined_pvalue == ens.combined.loc[row.test, "pvalue"]
    h = res.homogeneity
    counts = np.array([30, 45, 0, 60, 38, 2], float)
    assert (h["n_sequences"], h["n_empty"]) == (6, 1)
    assert h["pooled_rate"] == pytest.approx(counts.sum() / 300.0)
    assert h["median_rate"] == pytest.approx(np.median(counts / 50.0))
    assert h["dispersion_index"] == pytest.approx(counts.var(ddof=1) / counts.mean())
    assert h["pvalue_mc"] == ens.rate_homogeneity.loc["pearson", "pvalue_mc"]


@pytest.mark.parametrize("counts", [[25], [0, 0, 0]], ids=["one sequence", "no events"])
def test_the_dispersion_index_is_undefined_for_one_count_or_none_without_a_warning(counts):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        res = stats.poisson_group(_sequences(counts), 50.0, n_mc=19, rng=0)
    assert np.isnan(res.homogeneity["dispersion_index"])
    assert res.homogeneity["n_sequences"] == len(counts)
    assert "dispersion_index=nan" in repr(res)


def test_pooled_intervals_take_whole_sequences_until_the_budget_is_reached():
    seqs = _sequences([11, 1, 6, 20])
    n_used, iv = stats.pooled_intervals(seqs, [50.0] * 4, [11, 1, 6, 20], max_intervals=15)
    # intervals before each sequence: 0, 10, 10, 15 -> the first three are taken
    assert n_used == 3
    alone = stats.intervals_from_times(seqs[:3], [50.0] * 3)
    np.testing.assert_array_equal(iv.complete, alone.complete)
    np.testing.assert_array_equal(iv.censored, alone.censored)
    assert stats.pooled_intervals(seqs, [50.0] * 4, [11, 1, 6, 20], max_intervals=1)[0] == 1
    with pytest.raises(ValueError, match="max_intervals"):
        stats.pooled_intervals(seqs, [50.0] * 4, [11, 1, 6, 20], max_intervals=0)


def test_analyze_and_the_report_build_the_same_homogeneity_numbers():
    # the report's Poisson section (one radius, its own stream) and the analysis of the
    # same sequences give the same rate-homogeneity numbers, under the report's names
    from types import SimpleNamespace

    from kicktimes.report import poisson
    from kicktimes.report.context import Context, seeded_rng

    seqs = _sequences([12, 30, 7, 22], window=40.0, seed=4)
    collisions = pd.DataFrame({"radius": 0.02, "ic": range(4), "t_window": 40.0,
                               "n_pp": [s.size for s in seqs], "pp_times": seqs})
    exp = SimpleNamespace(name="t", seed=1, rule="mirror")
    ctx = Context(SimpleNamespace(experiment=exp, collisions=collisions), n_mc=39)
    poisson.sections(ctx)
    report_row = ctx.found.homogeneity.iloc[0]
    # the report's stream of its first radius: SeedSequence(seed, (REPORT_DOMAIN, 1, 0))
    group = stats.poisson_group(seqs, np.full(4, 40.0), n_mc=39, rng=seeded_rng(1, 1, 0))
    assert report_row["n_ics"] == group.homogeneity["n_sequences"] == 4
    for name in ("pooled_rate", "median_rate", "dispersion_index", "pvalue", "pvalue_mc"):
        assert report_row[name] == group.homogeneity[name], name
    events = pd.DataFrame(
        [(f"s{k}", t) for k, s in enumerate(seqs) for t in s], columns=["sequence", "time"]
    )
    res = stats.analyze(events, window=(0, 40.0), n_mc=39, rng=0, max_fits_per_group=0)
    row = res.heterogeneity.iloc[0]
    for name in ("pooled_rate", "median_rate", "dispersion_index", "pvalue"):
        assert row[name] == pytest.approx(report_row[name], rel=1e-12), name
