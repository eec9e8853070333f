"""The scatter study (kicktimes.studies.scatter): its page from its table, its cache."""

import numpy as np
import pandas as pd
from conftest import assert_provenance, assert_study_page, built_study, refuse_simulations

import kicktimes.studies.scatter as study
from kicktimes.experiment.presets import preset
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
