"""kicktimes reproduce --study science: the study's page from its cache and the paper
study's stores and findings, at a tiny size."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest
from conftest import refuse_simulations

from kicktimes.experiment import preset, run_experiment
from kicktimes.render.provenance import PROVENANCE_TITLE
from kicktimes.stats import (
    equivalence_sample_size,
    format_interval,
    margin_of,
    null_reading,
    ratio_reading,
    ratio_verdict,
    side_of,
)
from kicktimes.studies.science import page as science_page
from kicktimes.studies.science import run
from kicktimes.studies.science.page import SOURCES

TINY = run.ScienceScale("stretching_tiny", (0.03, 0.05), 4, 1000, (0.03,), 1, 10, (0.03,), 2,
                        300.0)


def _findings(folder, families, radius=0.03):
    """Findings tables as the paper study writes them, with made-up ratios."""
    for family in families:
        rows = [{"family": family, "diagnostic": d, "system": s, "control": "primary",
                 "estimate": e, "ci_low": e - 0.05, "ci_high": e + 0.05,
                 "verdict": ratio_verdict(e - 0.05, e + 0.05, tolerance=margin_of(d))}
                for d in ("ftle", "one_minus_r1")
                for s, e in (("poisson", 0.3), ("actual", 0.32), ("poisson_scatter", 0.97),
                             ("actual_scatter", 0.9))]
        pd.DataFrame(rows).to_csv(folder / f"{family}_findings.csv", index=False)
        by_radius = pd.DataFrame(rows).rename(columns={"estimate": "ratio"})
        by_radius["radius"] = radius
        by_radius.to_csv(folder / f"{family}_findings_by_radius.csv", index=False)


@pytest.fixture(scope="module")
def paper_study(tmp_path_factory):
    """Tiny quick stores of the paper study and its findings tables (mirror rule only)."""
    folder = tmp_path_factory.mktemp("paper")
    for name in ("quick_a", "quick_b"):
        exp = dataclasses.replace(preset(name), radii=[0.03], n_ics=2, n_steps=100,
                                  systems=("two_particle",), diagnostics=("lyapunov",),
                                  rr_sampling="run")
        run_experiment(exp, folder / f"store-{name}", workers=1, progress=False)
    _findings(folder, ["quick_a", "quick_b"])
    return folder


@pytest.fixture(scope="module")
def built(paper_study, tmp_path_factory):
    out = tmp_path_factory.mktemp("science")
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(run.SCALES, "quick", TINY)
        page = run.reproduce(out, stores_dir=paper_study, findings_dir=paper_study)
    return out, page


def test_the_page_names_the_command_and_quotes_its_csv(built):
    out, page = built
    assert page == out / "results-science" / "science.md"
    lines = page.read_text(encoding="utf-8").splitlines()
    assert lines[2].startswith("Generated ")
    assert "(`kicktimes reproduce --study science --scale quick`)" in lines[2]
    assert "`quick_a`, `quick_b`" in lines[2] and str(out) not in page.read_text()
    table = pd.read_csv(page.parent / "science_stretching.csv")
    text = page.read_text(encoding="utf-8")
    for row in table[table["system"] != "two_particle"].itertuples():
        assert row.verdict == ratio_verdict(row.ratio_ci_low, row.ratio_ci_high,
                                            tolerance=margin_of("ftle"))
        assert (f"{format_interval(row.ratio, row.ratio_ci_low, row.ratio_ci_high)}, "
                f"{row.verdict}") in text
    twins = pd.read_csv(page.parent / "science_independent_twins.csv")
    assert f"- r = {twins['radius'].iloc[0]:g}: λ = " in text
    assert "(1 paper ICs, T = 300;" not in text and "(2 paper ICs, T = 300;" in text
    compare = pd.read_csv(page.parent / "science_decorrelation_prediction.csv")
    assert list(compare["family"]) == ["quick_a", "quick_a"]    # no elastic tables: mirror only
    assert (page.parent / "science_stretching.png").stat().st_size > 0
    # last, the table of where the numbers come from: one row per CSV beside the page
    closing = text[text.rindex("\n## ") + 1:]
    assert closing.startswith(PROVENANCE_TITLE + "\n")
    csvs = {line.split("](")[0].removeprefix("| [") for line in closing.splitlines()[4:]}
    assert csvs == {p.name for p in page.parent.glob("*.csv")} == {s.csv for s in SOURCES}


def test_a_rerun_reuses_the_cache_and_recomputes_only_the_statistics(built, paper_study,
                                                                       monkeypatch):
    out, page = built
    parts = sorted((out / f"store-{TINY.sweep}").rglob("*.parquet"))
    stamps = [p.stat().st_mtime_ns for p in parts]

    monkeypatch.setitem(run.SCALES, "quick", TINY)
    refuse_simulations(monkeypatch, run, "twins_raw", "decorrelation")
    again = run.reproduce(out, results_dir=out / "again", stores_dir=paper_study,
                          findings_dir=paper_study, command="kicktimes reproduce --study science")
    text = again.read_text(encoding="utf-8")
    assert "(read from the study's cache of an earlier run)" in text
    assert "(`kicktimes reproduce --study science`)" in text
    assert [p.stat().st_mtime_ns for p in parts] == stamps
    for name in ("science_stretching.csv", "science_decorrelation.csv",
                 "science_independent_twins.csv", "science_rate_count.csv"):
        assert (out / "again" / name).read_bytes() == (page.parent / name).read_bytes(), name


def test_other_parameters_compute_again(built, paper_study, monkeypatch):
    out, _ = built
    calls = []

    def twins(radii, **kwargs):
        calls.append(kwargs["n_steps"])
        return pd.DataFrame({"radius": list(radii), "lam": 1.0, "rate": 0.1, "lo": 0.9,
                             "hi": 1.1})

    monkeypatch.setitem(run.SCALES, "quick", dataclasses.replace(TINY, twin_steps=11))
    monkeypatch.setattr(run, "twins_raw", twins)
    page = run.reproduce(out, results_dir=out / "other", stores_dir=paper_study,
                         findings_dir=paper_study)
    assert calls == [11]
    assert "11 steps of τ" in page.read_text(encoding="utf-8")


def test_missing_inputs_name_the_file_and_the_command_that_makes_it(tmp_path, paper_study):
    with pytest.raises(ValueError, match=r"store-family_a.*kicktimes reproduce --study paper "
                       r"--scale paper --out OUT"):
        run.reproduce(tmp_path, scale="paper")
    with pytest.raises(ValueError, match=r"store-quick_a or .*store-family_a.*--scale quick"):
        run.reproduce(tmp_path)
    with pytest.raises(ValueError, match=r"findings_dir: .*quick_a_findings_by_radius\.csv is "
                       r"missing.*kicktimes reproduce --study paper --scale quick --out OUT "
                       r"--results DIR"):
        run.reproduce(tmp_path, stores_dir=paper_study, findings_dir=tmp_path)


def test_the_page_opens_with_at_most_five_one_line_answers_before_its_first_table(built):
    _, page = built
    lines = page.read_text(encoding="utf-8").splitlines()
    first = next(i for i, x in enumerate(lines) if x.startswith("|"))
    answers = [x for x in lines[:first] if x.startswith("- ")]
    assert 1 <= len(answers) <= science_page.FIRST_SCREEN_MAX
    assert not [x for x in answers if "caveat" not in x or "[" not in x]
    assert not [x for x in lines[:first] if x.startswith("Verdicts of ratios")]


def test_every_inconclusive_ratio_of_the_page_names_the_size_that_would_resolve_it(built):
    _, page = built
    text = page.read_text(encoding="utf-8")
    table = pd.read_csv(page.parent / "science_stretching.csv")
    for row in table[table["verdict"] == "inconclusive"].itertuples():
        if side_of(row.ratio_ci_low, row.ratio_ci_high):
            continue                  # a departure from 1: it names no size
        cell = (f"{format_interval(row.ratio, row.ratio_ci_low, row.ratio_ci_high)}, "
                "inconclusive (not resolved at this size")
        assert cell in text


def test_the_size_an_inconclusive_ratio_needs_is_the_equivalence_sample_size():
    # CI [0.85, 1.15] around 1 at 100 ICs: the whole 0.1 of room to the band's edge
    se = 0.3 / (2 * science_page.Z95)
    assert science_page.needed_ics(1.0, 0.85, 1.15, 100) == (
        f"not resolved at this size; needs ≈ {equivalence_sample_size(se, 100, margin=0.1)} ICs")
    # an estimate just inside the band's edge has little room: many more ICs
    near = science_page.needed_ics(1.09, 0.94, 1.24, 100)
    assert int(near.split("≈ ")[1].split()[0]) == equivalence_sample_size(se, 100, margin=0.01)
    with pytest.raises(ValueError, match="n must be"):
        science_page.needed_ics(1.0, 0.9, 1.1, 0)


def test_the_first_screen_refuses_a_sixth_answer(built, monkeypatch):
    _, page = built
    folder = page.parent
    args = [pd.read_csv(folder / f"science_{n}.csv") for n in (
        "stretching", "stretching_trend", "independent_twins", "decorrelation_prediction",
        "rate_windows", "rate_count")]
    assert len(science_page.first_screen(*args, n_ics=1, n_dec=2)) <= 6
    monkeypatch.setattr(science_page, "FIRST_SCREEN_MAX", 1)
    with pytest.raises(ValueError, match="at most 1"):
        science_page.first_screen(*args, n_ics=1, n_dec=2)


def test_the_closest_table_pairs_each_law_with_its_own_verdict():
    # the two closest laws have different verdicts, in the order the referee found
    # reversed: each name must be followed by its own
    closest = pd.DataFrame({
        "family": ["family_a"] * 3, "diagnostic": ["ftle"] * 3,
        "system": ["poisson_scatter", "actual_scatter", "poisson"],
        "ratio": [0.976, 0.922, 0.4], "ci_low": [0.962, 0.897, 0.38],
        "ci_high": [1.02, 0.962, 0.42],
        "verdict": ["within 5 %", "inconclusive", "lower"],
        "closest": [True, True, False]})
    (row,) = science_page.closest_cells(closest)
    laws = row.split(" | ")[2].split("; ")
    assert laws == ["poisson_scatter 0.976 [0.962, 1.02], within 5 %",
                    "actual_scatter 0.922 [0.897, 0.962], below 1, size unresolved"]
    assert row.endswith("| poisson |")
    bad = closest.assign(verdict=["inconclusive", "within 5 %", "lower"])
    with pytest.raises(ValueError, match="poisson_scatter"):
        science_page.closest_cells(bad)


def test_an_interval_that_excludes_1_is_a_departure_and_names_no_sample_size():
    # point 4: a CI wholly above (below) 1 that straddles the band edge
    assert ratio_reading(1.06, 1.15) == "above 1, size unresolved"
    assert ratio_reading(0.815, 0.942) == "below 1, size unresolved"
    assert ratio_reading(0.913, 1.15) == "inconclusive"
    assert ratio_reading(0.95, 1.04) == "within 10 %" and ratio_reading(1.2, 1.3) == "higher"
    assert null_reading(0.01, 0.09, margin=0.05) == "above its null, size unresolved"
    assert null_reading(-0.01, 0.09, margin=0.05) == "inconclusive"
    assert side_of(float("nan"), 1.2) is None
    with pytest.raises(ValueError, match="low"):
        side_of(1.2, 1.1)
    cell = science_page._ratio_cell(1.10, 1.06, 1.15, 200)
    assert cell == "1.10 [1.06, 1.15], above 1, size unresolved"
    assert "needs ≈" in science_page._ratio_cell(0.998, 0.913, 1.15, 100)


def test_the_decorrelation_answer_says_the_model_overpredicts_and_picks_the_closest_row():
    compare = pd.DataFrame({
        "rule": ["mirror"] * 2 + ["elastic"] * 2, "radius": [0.008, 0.02] * 2,
        "system": ["poisson", "poisson_scatter"] * 2,
        "measured_over_predicted": [0.876, 0.819, 0.467, 0.535],
        "quotient_ci_low": [0.815, 0.705, 0.421, 0.482],
        "quotient_ci_high": [0.942, 0.951, 0.519, 0.594]})
    line = science_page._decorrelation_answer(compare, 40)
    assert "the model overpredicts in 4 of 4 rows (interval below 1)" in line
    assert "below 1, size unresolved in 2 (mirror 2)" in line
    assert "lower in 2 (elastic 2)" in line and "not resolved" not in line
    assert "closest to 1: 0.876 [0.815, 0.942]" in line and "(mirror, r = 0.008" in line
    mixed = compare.assign(quotient_ci_high=[1.05, 0.951, 0.519, 0.594])
    assert "1 of 4 rows not resolved at this size" in science_page._decorrelation_answer(
        mixed, 40)


def test_the_rate_without_the_sticky_runs_leaves_out_exactly_the_sticky_runs():
    """Runs at the kinetic rate plus two at ten times it: with them the whole-run ratio is
    pulled far above 1; without them (`exclude_sticky`) it is the ordinary runs' own."""
    from types import SimpleNamespace

    from kicktimes.stats import kinetic_rate
    from kicktimes.studies.science.rates import rate_relaxation

    rng = np.random.default_rng(4)
    r, t_end, gamma = 0.02, 4000.0, kinetic_rate(0.02)
    rows = []
    for ic in range(40):
        rate = gamma * (10.0 if ic < 2 else 1.0)
        times = np.sort(rng.uniform(0.0, t_end, rng.poisson(rate * t_end)))
        rows.append({"radius": r, "ic": ic, "n_pp": times.size, "t_window": t_end,
                     "pp_times": times})
    store = SimpleNamespace(collisions=pd.DataFrame(rows),
                            experiment=SimpleNamespace(name="demo"))
    _, whole_all, _ = rate_relaxation(store, n_boot=200)
    _, whole_kept, windows_kept = rate_relaxation(store, n_boot=200, exclude_sticky=True)
    assert whole_all["count_over_kinetic"].iloc[0] == pytest.approx(58 / 40, rel=0.05)
    kept = whole_kept.iloc[0]
    ordinary = sum(x["n_pp"] for x in rows[2:]) / (38 * t_end) / gamma
    assert kept["count_over_kinetic"] == pytest.approx(ordinary, rel=1e-12)
    assert kept["ci_low"] <= 1.0 <= kept["ci_high"]
    assert len(windows_kept) == 10
