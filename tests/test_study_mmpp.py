"""The MMPP study (kicktimes.studies.mmpp): its page from its tables, its cache."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from conftest import (
    assert_provenance,
    assert_study_page,
    built_study,
    first_screen_answers,
    refuse_simulations,
)

import kicktimes.studies.mmpp as study
import kicktimes.studies.mmpp.tables as tables
from kicktimes.stats import rejection_verdict

TINY = study.Params(n_ics=12, t_max=300.0, per_run=3)
#: fewer Monte Carlo samples and bootstrap resamples than the page's 199 and 1000
FEW = {"N_MC": 19, "N_BOOT": 50}


built = built_study("mmpp", study, TINY, [(tables, name, value) for name, value in FEW.items()])


def test_the_page_names_its_command_and_its_verdicts_are_its_csv(built):
    _, page = built
    text = assert_study_page(page, "mmpp")
    pooled = pd.read_csv(page.parent / "mmpp" / "mmpp_billiard_pooled.csv")
    assert pooled["rule"].tolist() == list(study.RULES)
    for p in pooled.itertuples():
        assert f"| {p.rule} | {p.n_runs} ({p.n_sticky}) | {p.n_events} |" in text
    resid = pd.read_csv(page.parent / "mmpp" / "mmpp_billiard_residuals.csv")
    for row in resid.itertuples():
        assert row.verdict == rejection_verdict(row.ci_low, row.ci_high, alpha=0.05)
    dip = pd.read_csv(page.parent / "mmpp" / "mmpp_billiard_dip.csv")
    assert (dip["mmpp"] >= 1.0 - 1e-9).all()
    # the whole early hazard: its minimum, where it falls, the MMPP's hazard in that bin
    for d in dip.itertuples():
        assert d.min_observed <= d.observed + 1e-12
        assert (d.min_bin_low, d.min_bin_high) in zip(tables.EARLY_EDGES[:-1],
                                                      tables.EARLY_EDGES[1:], strict=True)
        assert f"- {d.rule} rule, the whole early hazard: its minimum over t < 4 falls in " \
               f"[{d.min_bin_low:g}, {d.min_bin_high:g})" in text
        assert d.min_verdict in ("below the MMPP's", "above the MMPP's",
                                 "not distinguished from the MMPP's")


def test_a_rerun_reuses_the_cached_collision_times(built, monkeypatch):
    out, page = built
    before = (page.parent / "mmpp" / "mmpp_billiard_pooled.csv").read_bytes()
    refuse_simulations(monkeypatch, study, "collision_runs")
    monkeypatch.setitem(study.SCALES, "quick", TINY)
    for name, value in FEW.items():
        monkeypatch.setattr(tables, name, value)
    again = study.reproduce(out, command="my command")
    assert "(`my command`)" in again.read_text(encoding="utf-8")
    assert (again.parent / "mmpp" / "mmpp_billiard_pooled.csv").read_bytes() == before


def test_an_mmpp_has_no_refractory_dip():
    same = SimpleNamespace(rates=[0.5, 0.5], stationary=[0.5, 0.5],
                           generator=[[-0.1, 0.1], [0.1, -0.1]])
    assert study.mmpp_dip(same) == pytest.approx(1.0, rel=1e-6)
    bursty = SimpleNamespace(rates=[0.05, 2.0], stationary=[0.9, 0.1],
                             generator=[[-0.01, 0.01], [0.09, -0.09]])
    assert study.mmpp_dip(bursty) > 1.0


def test_the_mmpp_bin_hazard_is_exact_and_reads_the_mechanism_study_s_bins():
    from kicktimes.studies.mechanism.analysis import HAZARD_EDGES, RETURN_TIME

    assert tables.EARLY_EDGES == tuple(HAZARD_EDGES[HAZARD_EDGES <= RETURN_TIME])
    poisson = SimpleNamespace(rates=[0.3], stationary=[1.0], generator=[[0.0]])
    assert study.tables.mmpp_bin_hazard(poisson, 2.0, 3.0) == pytest.approx(1.0)
    bursty = SimpleNamespace(rates=[0.05, 2.0], stationary=[0.9, 0.1],
                             generator=[[-0.01, 0.01], [0.09, -0.09]])
    # the burst right after an event decays: the hazard falls from bin to bin
    early = study.tables.mmpp_bin_hazard(bursty, 0.0, 0.5)
    assert early == pytest.approx(study.mmpp_dip(bursty), rel=1e-6)
    assert early > study.tables.mmpp_bin_hazard(bursty, 3.0, 4.0)
    with pytest.raises(ValueError, match="a, b"):
        study.tables.mmpp_bin_hazard(bursty, 1.0, 1.0)


def test_the_paper_scale_is_the_published_page_s():
    assert study.SCALES["paper"] == study.Params(n_ics=200, t_max=2000.0, per_run=200,
                                                 radius=0.02, seed=29)


def test_the_page_ends_with_where_its_numbers_come_from(built):
    _, page = built
    rows = assert_provenance(page, every_csv_in="mmpp")
    assert ("mmpp/mmpp_billiard_dip.csv", "mmpp",
            "kicktimes.studies.mmpp.tables.mmpp_dip") in rows


def test_the_page_opens_with_at_most_five_answers_each_with_an_interval(built):
    answers = first_screen_answers(built[1])
    assert not any("intervals are not independent" in line for line in answers)


def test_the_residuals_are_read_against_their_calibrated_null(built):
    null_verdict = tables.edge_null_verdict
    _, page = built
    nulls = pd.read_csv(page.parent / "mmpp" / "mmpp_billiard_null.csv")
    resid = pd.read_csv(page.parent / "mmpp" / "mmpp_billiard_residuals.csv")
    assert len(nulls) == len(resid)
    for row in nulls.itertuples():
        assert row.verdict == null_verdict(row.diff_low, row.diff_high, margin=tables.SHARE_MARGIN)
        assert row.diff_low <= row.difference <= row.diff_high
        assert row.difference == pytest.approx(row.share - row.null_share)
        assert row.null_vs_alpha == rejection_verdict(row.null_ci_low, row.null_ci_high, alpha=0.05)
    # the residual table quotes each share with its null share and the verdict against it
    text = page.read_text(encoding="utf-8")
    assert "against α itself" not in text
    for row in nulls.itertuples():
        r = resid[(resid["rule"] == row.rule) & (resid["fit"] == row.fit)
                  & (resid["states"] == row.states) & (resid["test"] == row.test)].iloc[0]
        assert (f"{100 * r.share:.1f} % [{100 * r.ci_low:.1f}, {100 * r.ci_high:.1f}] "
                f"(null {100 * row.null_share:.1f} %), {row.verdict}") in text


def test_a_share_difference_beyond_a_margin_edge_that_excludes_0_is_not_inconclusive():
    v = tables.edge_null_verdict
    assert v(0.015, 0.13) == "above its null, size unresolved"
    assert v(-0.13, -0.01) == "below its null, size unresolved"
    assert v(-0.01, 0.05) == "inconclusive"
    assert v(0.03, 0.2) == "above its null" and v(-0.02, 0.02) == "at its null"
    assert v(float("nan"), 0.1) == "inconclusive"
    assert tables._difference([1, 0] * 50, [0] * 100, np.random.default_rng(0))[
        "verdict"] == "above its null"


def test_a_shuffled_twin_keeps_the_intervals_and_loses_their_order():
    import numpy as np

    t = np.cumsum(np.r_[np.full(20, 0.1), np.full(20, 5.0)])   # a burst, then calm
    twin = tables.shuffled_twin(t, t[-1] + 1.0, np.random.default_rng(3))
    assert sorted(np.round(np.diff(np.r_[0.0, twin]), 9)) == sorted(
        np.round(np.diff(np.r_[0.0, t]), 9))
    assert not np.allclose(twin, t)


def test_the_model_choice_finds_a_switching_process_and_not_its_shuffle():
    import numpy as np

    from kicktimes import stats

    bursty = dict(rates=[0.05, 2.0], generator=[[-0.01, 0.01], [0.09, -0.09]])
    runs = [np.asarray(stats.simulate_mmpp(**bursty, t_max=400.0, rng=k)) for k in range(12)]
    (row,) = tables.choice_rows("test", runs, 400.0, seed=1)
    assert row["share_billiard"] > row["share_shuffled"]
    assert row["ci_low_billiard"] <= row["share_billiard"] <= row["ci_high_billiard"]
    assert tables.choice_rows("test", [], 400.0, seed=1) == []
