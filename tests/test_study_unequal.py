"""The unequal-disks study (kicktimes.studies.unequal): its page from its table, its cache."""

import pandas as pd
from conftest import (
    assert_provenance,
    assert_study_page,
    built_study,
    first_screen_answers,
    refuse_simulations,
    table_cells,
)

import kicktimes.studies.unequal as study
from kicktimes.fileio import read_csv_exact
from kicktimes.stats import format_interval, null_reading, ratio_reading

TINY = study.Params(n_ics=10, n_steps=1000)


built = built_study("unequal", study, TINY)


def test_the_page_names_its_command_and_its_numbers_are_its_csv(built):
    _, page = built
    text = assert_study_page(page, "unequal")
    table = pd.read_csv(page.parent / "size_ratio" / "size_ratio.csv")
    assert table["size_ratio"].tolist() == [1.0, 1.5, 2.5, 4.0]
    for row in table.itertuples():
        cells = table_cells(text, f"{row.size_ratio:g}")
        lo, hi = row.ftle_partner_low_disk0, row.ftle_partner_high_disk0
        assert cells[4] == (f"{format_interval(row.ftle_partner_ratio_disk0, lo, hi)}, "
                            f"{ratio_reading(lo, hi)}")
        assert cells[3] == format_interval(row.dispersion_index, row.disp_low, row.disp_high,
                                           edges=(1.0,))
    assert (page.parent / "size_ratio" / "size_ratio.png").stat().st_size > 0


def test_at_ratio_one_both_partners_are_the_same_kick(built):
    out, _ = built
    runs = pd.read_parquet(out / "cache-unequal-quick" / "runs_r1_0.01.parquet")
    assert len(runs) == TINY.n_ics
    for disk in (0, 1):
        assert runs[f"kicked_partner_disk{disk}"].equals(runs[f"kicked_own_disk{disk}"])


def test_a_rerun_reuses_the_cached_runs(built, monkeypatch):
    out, page = built
    before = (page.parent / "size_ratio" / "size_ratio.csv").read_bytes()
    refuse_simulations(monkeypatch, study, "size_ratio_runs")
    monkeypatch.setitem(study.SCALES, "quick", TINY)
    again = study.reproduce(out, command="my command")
    assert "(`my command`)" in again.read_text(encoding="utf-8")
    assert (again.parent / "size_ratio" / "size_ratio.csv").read_bytes() == before


def test_the_paper_scale_is_the_published_page_s():
    assert study.SCALES["paper"] == study.Params(n_ics=200, n_steps=10000, tau=0.3, seed=5)


def test_the_figure_draws_ks_share_and_dispersion_on_their_own_axes():
    from pathlib import Path

    from kicktimes.studies.unequal.figures import size_ratio_figure

    table = pd.read_csv(Path(__file__).parents[1] / "docs/results/size_ratio/size_ratio.csv")
    fig = size_ratio_figure(table)
    # four panels, no twin axes: two y scales on one panel misled
    assert len(fig.axes) == 4
    ks, disp = fig.axes[1], fig.axes[2]
    assert "KS" in ks.get_title() and "rate dispersion across ICs" in disp.get_title()
    # every interval inside its axes
    assert ks.get_ylim()[1] > table["ks_reject_share"].max()
    assert disp.get_ylim()[1] > table["disp_high"].max()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_the_page_ends_with_where_its_numbers_come_from(built):
    _, page = built
    rows = assert_provenance(page)
    assert {csv for csv, _, _ in rows} == {study.page.TABLE}
    assert ("size_ratio/size_ratio.csv", "disp_low, disp_high",
            "kicktimes.studies.unequal.tables.dispersion_ci") in rows


def test_the_page_opens_with_at_most_five_answers_each_with_an_interval(built):
    first_screen_answers(built[1])


def test_d_is_read_against_its_null_and_the_ks_share_against_its_exact_alpha(built):
    from kicktimes.stats import D_MARGIN, null_verdict, rejection_verdict

    _, page = built
    table = read_csv_exact(page.parent / "size_ratio" / "size_ratio.csv")  # exact floats
    for row in table.itertuples():
        assert row.d_verdict == null_verdict(row.d_minus_null_low, row.d_minus_null_high,
                                             margin=D_MARGIN)
        assert row.d_minus_null == row.dispersion_index - row.d_null
        assert row.d_null_low <= row.d_null <= row.d_null_high
        assert row.ks_verdict == rejection_verdict(row.ks_low, row.ks_high, alpha=row.ks_null)
        # the test is exact given n: its null level is 0.05 within Monte Carlo noise (about
        # 4 standard errors: one interval's width beyond either end)
        width = row.ks_null_high - row.ks_null_low
        assert row.ks_null_low - width <= 0.05 <= row.ks_null_high + width
        cells = table_cells(page.read_text(encoding="utf-8"), f"{row.size_ratio:g}")
        # the page's reading: the CSV's verdict, or a departure where the CI excludes 0
        said = null_reading(row.d_minus_null_low, row.d_minus_null_high, margin=D_MARGIN)
        assert said == row.d_verdict or (row.d_verdict == "inconclusive"
                                         and ", size unresolved" in said)
        assert cells[-1].endswith(said)


def test_the_page_names_its_dispersion_across_ics_not_d(built):
    text = built[1].read_text(encoding="utf-8")
    assert "rate dispersion across ICs" in text
    assert "D − null" not in text and "Dispersion index D" not in text


def test_the_null_dispersion_of_poisson_counts_is_one_in_equal_windows_and_more_in_unequal():
    import numpy as np

    rng = np.random.default_rng(4)
    equal, lo, hi = study.tables.dispersion_null(np.full(200, 3000.0), 0.05, rng)
    assert abs(equal - 1.0) < 0.01 and lo < 1.0 < hi
    unequal, _, _ = study.tables.dispersion_null(np.r_[np.full(100, 1000.0),
                                                       np.full(100, 5000.0)], 0.05, rng)
    assert unequal > 10.0
