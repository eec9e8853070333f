"""The scatter study (kicktimes.studies.scatter): its page from its table, its cache."""

import numpy as np
import pandas as pd
from conftest import (
    assert_provenance,
    assert_study_page,
    built_study,
    first_screen_answers,
    refuse_simulations,
)

import kicktimes.studies.scatter as study
from kicktimes.experiment.presets import preset
from kicktimes.fileio import read_csv_exact
from kicktimes.stats import format_interval, ratio_verdict

TINY = study.Params(n_ics=3, n_steps=300, radii=(0.01, 0.03))


built = built_study("scatter", study, TINY)


def test_the_page_names_its_command_and_its_numbers_are_its_csv(built):
    _, page = built
    text = assert_study_page(page, "scatter")
    table = pd.read_csv(page.parent / "scatter_ratios.csv")
    assert set(table["radius"]) == set(TINY.radii)
    for row in table.itertuples():
        assert row.verdict == ratio_verdict(row.ci_low, row.ci_high)
    main = table[table["ics"] == "without sticky ICs"]
    for r, g in main.groupby("radius"):
        row = g.iloc[0]
        line = next(x for x in text.splitlines() if x.startswith(f"| {r:g} |"))
        assert line.split("|")[2].strip() == (
            f"{format_interval(row.estimate, row.ci_low, row.ci_high)}, {row.verdict}")


def test_the_per_ic_table_has_every_system_and_a_fresh_partner_exponent(built):
    out, _ = built
    runs = pd.read_parquet(out / "cache-scatter-quick" / "runs_r0.03.parquet")
    assert runs["ic"].tolist() == [0, 1, 2]
    for name in ("two", "two_fresh", "uniform", "scatter", "scatter_unw", "scatter_actual"):
        assert np.isfinite(runs[name]).all() and (runs[name] > 0).all(), name
    summaries = study.summary_tables(runs)
    assert set(summaries) == {"sticky", "all ICs", "without sticky ICs", "shape"}


def test_a_rerun_reuses_the_cached_table(built, monkeypatch):
    out, page = built
    before = (page.parent / "scatter_ratios.csv").read_bytes()
    refuse_simulations(monkeypatch, study, "scatter_runs")
    monkeypatch.setitem(study.SCALES, "quick", TINY)
    again = study.reproduce(out, command="my command")
    assert "(`my command`)" in again.read_text(encoding="utf-8")
    assert (again.parent / "scatter_ratios.csv").read_bytes() == before


def test_the_paper_scale_is_family_a_s():
    fam, paper = preset("family_a"), study.SCALES["paper"]
    assert paper.radii == tuple(fam.radii) and paper.n_ics == 40
    assert (paper.n_steps, paper.tau, paper.ic_seed, paper.ic_method) == (
        fam.n_steps, fam.tau, fam.seed, fam.ic_method)
    assert paper.ic_radius == fam.r_max


def test_the_page_ends_with_where_its_numbers_come_from(built):
    _, page = built
    rows = assert_provenance(page)
    assert {csv for csv, _, _ in rows} == {p.name for p in page.parent.glob("*.csv")}
    assert ("scatter_ratios.csv", "verdict", "kicktimes.stats.findings.ratio_verdict") in rows


def test_the_page_opens_with_at_most_five_answers_each_with_an_interval(built):
    assert all("margin" in line for line in first_screen_answers(built[1]))


def test_the_ratios_over_radii_are_read_at_both_margins_and_name_a_real_deficit(built):
    from kicktimes.studies.scatter.tables import FINE_MARGIN

    _, page = built
    # read exactly (pandas before 3 parses floats in a few ulps otherwise)
    over = read_csv_exact(page.parent / "scatter_over_radii.csv")
    assert FINE_MARGIN < 0.1
    for row in over.itertuples():
        assert row.verdict == ratio_verdict(row.ci_low, row.ci_high)
        assert row.verdict_fine == ratio_verdict(row.ci_low, row.ci_high, tolerance=FINE_MARGIN)
        assert row.deficit == 1 - row.estimate
    main = over[over["ics"] == "without sticky ICs"].set_index("ratio")
    first = main.loc["scatter kicks / two disks"]
    (line,) = [a for a in first_screen_answers(page)
               if a.startswith("- **Scatter kicks / two disks")]
    assert format_interval(first.estimate, first.ci_low, first.ci_high,
                           edges=(0.9, 0.95, 1.0, 1.05, 1.1)) in line
    assert ("a real deficit" in line) == bool(first.ci_high < 1)


def test_a_resample_of_only_sticky_ics_is_left_out_not_averaged_as_nan():
    from kicktimes.studies.scatter.tables import over_radii

    rng = np.random.default_rng(0)
    rows = [{"radius": r, "ic": i, "two": 0.01 if i == 0 else 1.0 + 0.1 * rng.random(),
             **{k: 0.93 for k in ("scatter", "uniform", "scatter_actual", "two_fresh")}}
            for r in (0.01, 0.02) for i in range(3)]
    over = over_radii(pd.DataFrame(rows), n_boot=200)
    main = over[over["ics"] == "without sticky ICs"]
    assert np.isfinite(main[["estimate", "ci_low", "ci_high"]]).all().all()
    assert (main["n_draws"] <= 200).all() and (main["n_draws"] > 150).all()
