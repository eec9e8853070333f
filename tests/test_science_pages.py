"""The generated science pages (docs/results/*.md) say only what their tables show.

Each page starts with its "Generated ..." line, names no machine path, and the numbers a
reader sees are the ones in the CSV beside it, with the verdict their interval gives.
"""

import re
from pathlib import Path

import pandas as pd
import pytest
from conftest import MACHINE_PATH, table_cells

from kicktimes.stats import (
    format_interval,
    margin_of,
    null_reading,
    ratio_reading,
    ratio_verdict,
    ratio_words,
)

RESULTS = Path(__file__).resolve().parents[1] / "docs" / "results"
PAGES = ["README.md", "science.md", "mechanism.md", "escape.md", "unequal.md", "scatter.md"]


def _page(name):
    path = RESULTS / name
    assert path.is_file(), f"{name} is missing: rebuild it with kicktimes reproduce --study all"
    return path.read_text(encoding="utf-8")


@pytest.mark.parametrize("name", PAGES)
def test_every_page_starts_with_its_generated_line_and_names_no_machine_path(name):
    text = _page(name)
    lines = [line for line in text.splitlines() if line.strip()]
    assert lines[0].startswith("# ")
    assert lines[1].startswith("Generated "), lines[1][:80]
    assert " by kicktimes " in lines[1] and " from " in lines[1]
    assert not MACHINE_PATH.search(text), MACHINE_PATH.search(text).group(0)


def test_the_science_page_s_ratio_per_radius_is_its_csv_with_its_verdict():
    text = _page("science.md")
    table = pd.read_csv(RESULTS / "science_stretching.csv")
    kicked = table[table["system"] != "two_particle"]
    for row in kicked.itertuples():
        assert row.verdict == ratio_verdict(row.ratio_ci_low, row.ratio_ci_high,
                                            tolerance=margin_of("ftle"))
    for r, g in kicked.groupby("radius"):
        cells = table_cells(text, f"{r:g}")
        for k, system in enumerate(("poisson", "poisson_scatter")):
            row = g[g["system"] == system].iloc[0]
            said = ratio_words(row.ratio_ci_low, row.ratio_ci_high, tolerance=margin_of("ftle"))
            want = (f"{format_interval(row.ratio, row.ratio_ci_low, row.ratio_ci_high)}, "
                    f"{said}")
            # an inconclusive ratio whose CI contains 1 names the size that would resolve
            # it; one whose CI excludes 1 is a departure and names none
            assert cells[1 + k].split(" (not resolved")[0] == want
            assert ("(not resolved at this size" in cells[1 + k]) == (said == "inconclusive")


def test_the_science_page_extrapolates_nothing_and_quotes_predictions_with_measurements():
    text = _page("science.md")
    assert "10⁻⁶" not in text and "r → 0" not in text
    compare = pd.read_csv(RESULTS / "science_decorrelation_prediction.csv")
    for row in compare.itertuples():
        assert row.quotient_verdict == ratio_verdict(row.quotient_ci_low, row.quotient_ci_high)
        measured = format_interval(row.measured, row.measured_ci_low, row.measured_ci_high)
        predicted = format_interval(row.predicted, row.predicted_ci_low, row.predicted_ci_high)
        line = next(x for x in text.splitlines() if predicted in x and measured in x)
        # the CSV's verdict, read as a departure where the CI excludes 1
        assert line.rstrip(" |").endswith(
            ratio_reading(row.quotient_ci_low, row.quotient_ci_high)) or (
            "(not resolved at this size" in line.split(" | ")[-1])


def test_the_unequal_page_gives_every_ratio_the_verdict_of_its_interval():
    text = _page("unequal.md")
    table = pd.read_csv(RESULTS / "size_ratio" / "size_ratio.csv")
    for row in table.itertuples():
        cells = table_cells(text, f"{row.size_ratio:g}")
        want = (f"{format_interval(row.ftle_partner_ratio_disk0, row.ftle_partner_low_disk0, row.ftle_partner_high_disk0)}, "  # noqa: E501
                f"{ratio_reading(row.ftle_partner_low_disk0, row.ftle_partner_high_disk0, tolerance=0.05)}")  # noqa: E501
        assert cells[4] == want  # the FTLE at the page's margin, 5 %
    assert "within 10 % … at every ratio" not in text


def test_the_scatter_page_is_its_csv_and_no_longer_decomposes_the_gap():
    text = _page("scatter.md")
    table = pd.read_csv(RESULTS / "scatter_ratios.csv")
    for row in table.itertuples():
        assert row.verdict == ratio_verdict(row.ci_low, row.ci_high)
        assert row.verdict_fine == ratio_verdict(row.ci_low, row.ci_high, tolerance=0.05)
    main = table[table["ics"] == "without sticky ICs"]
    for r, g in main.groupby("radius"):
        cells = table_cells(text, f"{r:g}")
        first = g.iloc[0]
        assert cells[1] == (f"{format_interval(first.estimate, first.ci_low, first.ci_high)}, "
                            f"{first.verdict_fine}")  # the page's margin, 5 %
    assert "almost all" not in text.lower()


def _numbers(folder):
    path = RESULTS / "mechanism" / folder / "mechanism_numbers.csv"
    assert path.is_file(), (f"{path.name} of {folder or 'mirror'} is missing: rebuild it with "
                            "kicktimes reproduce --study mechanism --scale paper "
                            "--results docs/results")
    return pd.read_csv(path)


@pytest.mark.parametrize("folder", ["", "elastic"])
def test_the_mechanism_page_reads_the_late_hazard_from_its_table(folder):
    text = _page("mechanism.md")
    tab = _numbers(folder)
    rule = tab["rule"].iloc[0]
    section = text.split(f"## The {rule} rule")[1].split("\n## ")[0]
    cells = table_cells(section, "Γ-rescaled hazard, t > 5")
    groups = [("paper", 0.01), ("paper", 0.02), ("uniform", 0.01), ("uniform", 0.02)]
    for k, (method, r) in enumerate(groups):
        row = tab[(tab["method"] == method) & (tab["radius"] == r)
                  & (tab["quantity"] == "rescaled_hazard_late")].iloc[0]
        verdict = ratio_verdict(row["ci_low"], row["ci_high"])
        assert cells[1 + k].split(" (")[0].endswith(verdict), (cells[1 + k], verdict)
    assert "explains about half to two-thirds" not in text


def test_the_escape_page_answers_with_an_equivalence_test_and_its_controls():
    text = _page("escape.md")
    ratios = pd.read_csv(RESULTS / "escape" / "escape_ratios.csv")
    for row in ratios.itertuples():
        assert row.verdict == ratio_reading(row.ci_low, row.ci_high)
        assert format_interval(row.ratio, row.ci_low, row.ci_high) in text
    assert set(ratios.loc[ratios["negative_control"], "system"]) == {"poisson_small_hole",
                                                                      "bursty"}
    assert "Yes, at every radius" not in text


@pytest.mark.parametrize("study, name", [("escape", "escape.md"), ("unequal", "unequal.md"),
                                         ("scatter", "scatter.md"), ("mmpp", "mmpp.md")])
def test_the_study_pages_name_the_command_that_builds_them(study, name):
    generated = [line for line in _page(name).splitlines() if line.strip()][1]
    assert f"(`kicktimes reproduce --study {study} --scale paper`)" in generated
    assert "analysis/" not in generated


def test_the_mmpp_page_s_residual_verdicts_are_their_intervals():
    from kicktimes.stats import rejection_verdict

    _page("mmpp.md")
    resid = pd.read_csv(RESULTS / "mmpp" / "mmpp_billiard_residuals.csv")
    for row in resid.itertuples():
        assert row.verdict == rejection_verdict(row.ci_low, row.ci_high, alpha=0.05)
    dip = pd.read_csv(RESULTS / "mmpp" / "mmpp_billiard_dip.csv")
    assert (dip["mmpp"] >= 1.0 - 1e-9).all()   # an MMPP has no refractory dip


def test_every_results_page_names_the_study_command_that_builds_it():
    from kicktimes.studies import STUDIES

    pages = {s.page: s.name for s in STUDIES.values()}
    # the paper study's detail page of each family, linked from its README.md
    pages |= {p.name: "paper" for p in RESULTS.glob("family_*.md")}
    assert set(pages) == {p.name for p in RESULTS.glob("*.md")}
    for page, name in pages.items():
        generated = next(line for line in _page(page).splitlines()
                         if line.startswith("Generated "))
        assert f"(`kicktimes reproduce --study {name}" in generated, (page, generated[:160])
    readme = (RESULTS.parents[1] / "README.md").read_text(encoding="utf-8")
    assert "kicktimes reproduce --study NAME" in readme and "--study all" in readme


def test_the_science_page_claims_a_direction_only_where_both_trend_measures_agree():
    text = _page("science.md")
    trend = pd.read_csv(RESULTS / "science_stretching_trend.csv").set_index(["system",
                                                                            "quantity"])
    assert "holds in direction" not in text and "Named: *radial orbits*" not in text
    assert "## 6. Cost" not in text
    bullets = text.split("The paper's expectation")[1].split("What happens below")[0]
    screen = text.split("\n|")[0]
    for system, name in (("poisson", "Uniform kick"), ("poisson_scatter", "Scatter kick")):
        line = next(x for x in screen.splitlines() if x.startswith(f"- **{name}"))
        ratio, dist = (trend.loc[(system, q), "verdict"] for q in ("ratio", "abs_log_ratio"))
        if "no trend detected" in (ratio, dist) and ratio != dist:
            assert "no direction of the trend is claimed" in line
    for system, name in (("poisson", "uniform kick"), ("poisson_scatter", "scatter kick")):
        line = next(x for x in bullets.splitlines() if x.startswith(f"- {name}:"))
        ratio, dist = (trend.loc[(system, q), "verdict"] for q in ("ratio", "abs_log_ratio"))
        if "no trend detected" in (ratio, dist) and ratio != dist:
            assert "no direction is claimed" in line
        else:
            assert "no direction is claimed" not in line


def test_the_science_page_puts_the_twin_estimate_beside_its_measurement():
    text = _page("science.md")
    twins = pd.read_csv(RESULTS / "science_independent_twins.csv")
    for row in twins.itertuples():
        want = format_interval(row.over_predicted, row.over_predicted_ci_low,
                               row.over_predicted_ci_high)
        line = next(x for x in text.splitlines() if x.startswith(f"- r = {row.radius:g}:"))
        assert f"measured / predicted {want}, " + ratio_verdict(
            row.over_predicted_ci_low, row.over_predicted_ci_high) in line


def test_the_mmpp_page_s_dip_is_the_mechanism_page_s_at_the_same_ics():
    dip = pd.read_csv(RESULTS / "mmpp" / "mmpp_billiard_dip.csv").set_index("rule")
    mech = pd.read_csv(RESULTS / "mechanism" / "mechanism_numbers.csv")
    row = mech[(mech["method"] == "paper") & (mech["radius"] == 0.02)
               & (mech["quantity"] == "hazard_nonsticky_first_bin_over_rate")].iloc[0]
    assert abs(dip.loc["mirror", "observed"] - row["estimate"]) < 1e-4 * row["estimate"]
    text = _page("mmpp.md")
    # the residual shares are read against their null shares, not against alpha
    assert "null share" in text


def test_the_mechanism_page_reads_no_share_as_a_bound_or_an_overshoot_inside_noise():
    text = _page("mechanism.md")
    assert "upper bound" not in text and "(the model overshoots)" not in text
    assert "read as short of it only where its interval lies below 1" in text


def test_the_mechanism_page_reads_the_rate_dispersion_across_ics_against_its_null():
    from kicktimes.stats import D_MARGIN

    text = _page("mechanism.md")
    assert "dispersion index" not in text and "index of dispersion" not in text
    for folder in ("", "elastic"):
        tab = _numbers(folder)
        rule = tab["rule"].iloc[0]
        section = text.split(f"## The {rule} rule")[1].split("\n## ")[0]
        cells = table_cells(section, "rate dispersion across ICs vs its Poisson null")
        for k, (method, r) in enumerate([("paper", 0.01), ("paper", 0.02), ("uniform", 0.01),
                                         ("uniform", 0.02)]):
            g = tab[(tab["method"] == method) & (tab["radius"] == r)].set_index("quantity")
            diff, null = g.loc["rate_dispersion_minus_null"], g.loc[
                "rate_dispersion_poisson_null"]
            verdict = null_reading(diff["ci_low"], diff["ci_high"], margin=D_MARGIN)
            assert f"vs {null['estimate']:.3f}: {verdict}" in cells[1 + k]


@pytest.mark.parametrize("name", ["mechanism.md", "science.md"])
def test_the_mechanism_and_science_pages_open_with_five_answers_at_most(name):
    text = _page(name)
    assert len(text.split()) <= 2500
    lines = text.splitlines()
    first = next(i for i, x in enumerate(lines) if x.startswith("|"))
    answers = [x for x in lines[:first] if x.startswith("- ")]
    assert 1 <= len(answers) <= 5 and all("[" in x and "caveat" in x for x in answers)


def test_the_escape_page_sets_every_rate_beside_the_hole_s_ergodic_rate():
    import math

    text = _page("escape.md")
    tails = pd.read_csv(RESULTS / "escape" / "escape_tails.csv").set_index(["radius", "system"])
    block = text.split("**The hole alone.**")[1].split("**Ratio of escape rates")[0]
    for r in (0.005, 0.01, 0.02, 0.03):
        erg = 0.1 / (math.pi ** 2 * (1 - r))          # 2h / (pi^2 (1 - r)), h = 0.05
        cells = table_cells(block, f"{r:g}")
        assert cells[1] == f"{erg:.5f}"
        row = tails.loc[(r, "poisson")]
        lo, hi = row["rate_boot_low"] / erg, row["rate_boot_high"] / erg
        assert cells[4] == f"{format_interval(row['rate'] / erg, lo, hi)}, {ratio_reading(lo, hi)}"


def test_the_unequal_page_names_the_ftle_and_gives_ks_and_dispersion_intervals():
    text = _page("unequal.md")
    assert "finite-time Lyapunov exponent" in text
    table = pd.read_csv(RESULTS / "size_ratio" / "size_ratio.csv")
    for row in table.itertuples():
        cells = table_cells(text, f"{row.size_ratio:g}")
        assert re.fullmatch(r"[\d.]+ % \[[\d.]+, [\d.]+\]", cells[2])
        assert cells[3] == format_interval(row.dispersion_index, row.disp_low, row.disp_high,
                                           edges=(1.0,))


def test_the_science_page_pairs_each_closest_kick_law_with_its_own_verdict():
    text = _page("science.md")
    table = pd.read_csv(RESULTS / "science_closest.csv")
    for (family, diag), g in table.groupby(["family", "diagnostic"], sort=False):
        best = g[g["closest"]]
        if len(best) == len(g):
            continue
        cell = next(c[2] for c in ([x.strip() for x in line.strip().strip("|").split("|")]
                                   for line in text.splitlines())
                    if c[:2] == [f"`{family}`", diag])
        for row in best.itertuples():
            assert (f"{row.system} {format_interval(row.ratio, row.ci_low, row.ci_high)}, "
                    f"{ratio_words(row.ci_low, row.ci_high, tolerance=margin_of(diag))}"
                    ) in cell.split("; ")


def test_no_science_or_mechanism_cell_asks_for_ics_where_its_interval_excludes_the_null():
    for name in ("science.md", "mechanism.md"):
        for line in _page(name).splitlines():
            if "needs ≈" in line and ", size unresolved" in line:
                for cell in line.split(" | "):
                    assert not ("needs ≈" in cell and ", size unresolved" in cell), cell
