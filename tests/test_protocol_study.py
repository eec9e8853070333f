"""The protocol study (kicktimes.studies.protocol): rows, tables, Shapley shares, the page."""

import re

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from kicktimes.cli import main
from kicktimes.diagnostics import Twin, lyapunov
from kicktimes.render.provenance import PROVENANCE_TITLE
from kicktimes.stats import paired_ratio
from kicktimes.studies.protocol.compute import D0, Panel, compute_task, run_rows, tasks
from kicktimes.studies.protocol.page import FIGURE, build_page, fig6_figure
from kicktimes.studies.protocol.tables import count_line_table, fig4_table
from kicktimes.studies.protocol.verdicts import (
    CLOSER_MARGIN,
    balloon_verdict,
    closer_verdict,
    reproduces,
)

PANELS = (
    Panel("family_a", "Fig. 6 top", (0.012, 0.024), 4, 400, 0.2, 1, 2, (0.024,), 2),
    Panel("family_b", "Fig. 6 bottom", (0.012, 0.024), 4, 300, 0.3, 2, 2, (0.024,), 2),
)


@pytest.fixture(scope="module")
def rows(tmp_path_factory):
    store = tmp_path_factory.mktemp("protocol-store")
    frames = []
    for p in PANELS:
        for k, task in enumerate(tasks(p)):
            path = store / f"{p.name}-{k}.parquet"
            compute_task(p, task, path)
            frames.append(pd.read_parquet(path))
    return pd.concat(frames, ignore_index=True)


def test_every_reading_of_every_system_is_computed(rows):
    main_rows = rows[(rows["horizon"] == 1) & (rows["panel"] == "family_a")
                     & (rows["radius"] == 0.012) & (rows["ic"] == 0)]
    per_system = main_rows.groupby("system").size().to_dict()
    # two-disk: 2 estimators x 2 measures, tangent, R_1, RR with and without the diagonal;
    # kicked: the 2 x 2 x 2 factorial at uniform kicks, both N(0, 1) readings under both
    # estimators, tangent, R_1, the two RR; Poisson: Fig. 4's slope and R² at the
    # smallest radius
    assert per_system == {"two_particle": 8, "poisson": 18, "actual": 16}
    fig4 = rows[rows["diagnostic"].isin(["fig4_slope", "fig4_r2"])]
    assert set(fig4["radius"]) == {0.012} and len(fig4) == 2 * sum(p.n_ics for p in PANELS)
    assert set(rows["horizon"]) == {1, 2, 4, 8}
    conv = rows[rows["horizon"] == 8]
    assert set(conv["radius"]) == {0.024} and set(conv["ic"]) == {0, 1}


def test_the_literal_two_disk_row_is_eq4_of_lyapunov(rows):
    p = PANELS[0]
    ic = p.initial_conditions()[1]
    want = lyapunov(ic, 0.024, method=Twin(variant="paper", d0=D0, renormalize=False),
                    n_steps=p.n_steps, tau=p.tau, sampling="paper").lam
    got = rows[(rows["panel"] == p.name) & (rows["radius"] == 0.024) & (rows["ic"] == 1)
               & (rows["system"] == "two_particle") & (rows["estimator"] == "literal")
               & (rows["measure"] == "paper") & (rows["horizon"] == 1)]["lam"]
    assert got.tolist() == [want]


def test_the_papers_rr_is_the_off_diagonal_rr_plus_its_diagonal(rows):
    rr = rows[rows["diagnostic"] == "rr"].pivot_table(
        index=["panel", "radius", "ic", "system"], columns="measure", values="lam")
    n = {p.name: p.n_steps + 1 for p in PANELS}  # samples: the IC and n steps
    big_n = rr.index.get_level_values("panel").map(n).to_numpy(float)
    # RR = (N + R) / N^2 with the diagonal, R / (N (N - 1)) without it
    np.testing.assert_allclose(rr["with_diagonal"],
                               1 / big_n + rr["off_diagonal"] * (big_n - 1) / big_n,
                               rtol=1e-12)
    assert (rr["with_diagonal"] >= 1 / big_n).all()


def test_rows_are_deterministic():
    p = PANELS[1]
    ic = p.initial_conditions()[0]
    pd.testing.assert_frame_equal(pd.DataFrame(run_rows(p, "main", 0.012, 0, ic)),
                                  pd.DataFrame(run_rows(p, "main", 0.012, 0, ic)))


def test_paired_ratio_draws_are_the_resamples_of_its_interval():
    idx = pd.MultiIndex.from_product([[0.01, 0.02], range(30)], names=["radius", "ic"])
    y = pd.Series(np.random.default_rng(2).uniform(1, 2, 60), index=idx)
    x = y * np.random.default_rng(3).uniform(0.8, 1.2, 60)
    shared = {}
    _, overall, draws = paired_ratio(x, y, rng=np.random.default_rng(1), n_boot=500,
                                     resamples=shared, draws=True)
    assert draws.shape == (500,)
    assert np.percentile(draws, 2.5) == pytest.approx(overall["ci_low"])
    # a second ratio under the same resamples: its draws are paired with the first's
    _, _, again = paired_ratio(x, y, rng=np.random.default_rng(99), n_boot=500,
                               resamples=shared, draws=True)
    np.testing.assert_array_equal(draws, again)


def test_the_page_states_each_claim_from_its_tables(rows, tmp_path):
    page = build_page(rows, tmp_path, None, command="kicktimes reproduce --study protocol",
                      panel_list=PANELS, dpi=40)
    text = page.read_text()
    generated = next(line for line in text.splitlines() if line.startswith("Generated "))
    assert "eq. (4)" in generated and "kicktimes reproduce --study protocol" in generated
    first_screen = text[:text.index("\n|")]
    answers = [line for line in first_screen.splitlines() if line.startswith("- ")]
    # at most five one-line answers before the first table
    assert 1 <= len(answers) <= 5 and all(len(line) <= 260 for line in answers)
    # nothing but the title, the Generated line and the answers before the table
    assert len(first_screen.strip().split("\n\n")) == 3
    header = next(line for line in text.splitlines() if line.startswith("| Claim"))
    assert header.count("|") - 1 <= 8
    assert (tmp_path / FIGURE).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    findings = pd.read_csv(tmp_path / "paper_findings.csv")
    claims = pd.read_csv(tmp_path / "paper_claims.csv")
    # every verdict is its interval's (the rule of kicktimes.stats.ratio_verdict)
    for row in findings.itertuples():
        inside = row.ci_low >= 0.9 and row.ci_high <= 1.1
        assert (row.verdict == "within 10 %") == inside
    # the figures: FTLE Fig. 6, ACF Fig. 8, RR Fig. 7 for panel A only
    by = findings.groupby("diagnostic")["figure"].agg(set)
    assert by["ftle"] == {"Fig. 6 top", "Fig. 6 bottom"}
    assert by["r1"] == by["one_minus_r1"] == {"Fig. 8 top", "Fig. 8 bottom"}
    rr = findings[findings["diagnostic"] == "rr_with_diagonal"].set_index(["family", "control"])
    assert rr.loc[("family_a", "small_radii"), "figure"].eq("Fig. 7 bottom").all()
    assert rr.loc[("family_a", "larger_radii"), "figure"].eq("Fig. 7 top").all()
    assert not rr.loc["family_b", "figure"].str.startswith("Fig. 7").any()
    # every claim's "reproduces?" is the rule's, from its kind and verdict
    assert claims["reproduces"].tolist() == [reproduces(k, v) for k, v in zip(
        claims["kind"], claims["verdict"], strict=True)]
    assert set(claims.loc[claims["family"] == "family_b", "reproduces"][
        claims["claim"].str.startswith("RR")]) == {"not in the paper"}
    assert "| reproduces? |" in text
    # the first screen quotes the FTLE claims' range by the paper's protocol
    ftle = claims[claims["quantity"] == "FTLE ratio kicked / two-disk"]
    low = f"{ftle['estimate'].min():.3g}"
    assert re.search(rf"kicked/two-disk {re.escape(low)}", first_screen)
    for name in ("paper_by_radius.csv", "paper_shapley.csv", "paper_convergence.csv"):
        assert not pd.read_csv(tmp_path / name).empty
    # the page closes with where its numbers come from: every CSV beside it, by function
    assert [h for h in text.splitlines() if h.startswith("## ")][-1] == PROVENANCE_TITLE
    named = re.findall(r"^\| \[([^]]+)\]", text[text.index(PROVENANCE_TITLE):], re.M)
    assert set(named) == {p.name for p in tmp_path.glob("*.csv")}


def test_fig6_zooms_the_literal_column_on_its_data_and_says_so():
    # the eq. (4)-as-printed values differ by ~1.5 % of ~37: from 0 they would look equal
    frames = []
    for system, level in (("two_particle", 37.5), ("poisson", 37.0), ("actual", 36.9)):
        for estimator, scale in (("literal", 1.0), ("renormalised", 0.002)):
            frames.append(pd.DataFrame({
                "panel": "family_a", "radius": [0.012, 0.024], "system": system,
                "estimator": estimator, "measure": "paper", "twin_kicks": "shared",
                "kick_angle": "uniform", "mean": level * scale, "sd": 0.5 * scale,
                "n": 200, "paper_bar": 0.05 * scale}))
    fig = fig6_figure(pd.concat(frames, ignore_index=True), PANELS[:1])
    literal, renormalised = fig.axes[0], fig.axes[1]
    low, high = literal.get_ylim()
    assert 36.5 < low < 36.9 and 37.5 < high < 38.5
    assert any("not 0" in t.get_text() and f"{low:.3g}" in t.get_text() for t in literal.texts)
    assert renormalised.get_ylim()[0] == 0.0
    assert not renormalised.texts
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_findings_belong_to_the_protocol_study(tmp_path):
    res = CliRunner().invoke(main, ["reproduce", "--study", "paper", "--findings",
                                    str(tmp_path), "--out", str(tmp_path / "x")])
    assert res.exit_code == 2 and "--findings applies to --study protocol" in res.output


def test_the_results_first_screen_points_to_paper_md_without_its_numbers():
    from pathlib import Path

    from kicktimes.studies.paper import PROTOCOL_POINTER

    pointer = PROTOCOL_POINTER[0]
    assert "[paper.md](paper.md)" in pointer
    # names (eq. (4), Fig. 6), no number of paper.md
    assert not re.search(r"[0-9]", pointer.replace("eq. (4)", "").replace("Fig. 6", ""))
    # the protocol page states the readings of eq. (4) the pointer names
    results = Path(__file__).resolve().parents[1] / "docs" / "results"
    first = (results / "paper.md").read_text().split("\n|")[0]
    assert re.search(r"\*\*FTLE \(Fig\. 6\)\*\* .*eq\. \(4\) as printed.*kicked/two-disk", first)


def test_the_protocol_study_needs_the_paper_study_which_runs_first():
    from kicktimes.studies import STUDIES

    assert STUDIES["paper"].needs == () and STUDIES["protocol"].needs == ("paper",)
    assert list(STUDIES).index("paper") < list(STUDIES).index("protocol")


def test_every_registered_study_is_a_choice_of_reproduce_with_its_line():
    from kicktimes.studies import STUDIES

    res = CliRunner().invoke(main, ["reproduce", "--help"], terminal_width=400)
    assert res.exit_code == 0
    lines = [" ".join(line.split()) for line in res.output.splitlines()]
    for study in STUDIES.values():
        assert f"{study.name} {study.page} {study.summary}" in lines
    assert f"[{'|'.join(STUDIES)}|all]" in res.output


def test_equally_close_needs_the_whole_interval_inside_the_margin():
    m = CLOSER_MARGIN
    assert m == pytest.approx(0.01)
    # the renormalised reading: the CI lies beyond -m, a difference the margin resolves
    assert closer_verdict(-0.0807, -0.0679) == "Poisson closer"
    # eq. (4) as printed: the CI excludes 0 but lies inside the margin, real but negligible
    assert closer_verdict(-0.00327, -0.00103) == "Poisson closer, inside the margin"
    assert closer_verdict(0.001, 0.004) == "actual closer, inside the margin"
    assert closer_verdict(-0.004, 0.003) == "equally close"
    assert closer_verdict(0.2 * m, 3 * m) == "inconclusive"  # straddles the margin's edge
    assert closer_verdict(1.5 * m, 3 * m) == "actual closer"
    assert closer_verdict(float("nan"), 0.0) == "inconclusive"
    # overlapping intervals are not agreement: a CI wider than the margin is undecided
    assert closer_verdict(-0.5 * m, 1.5 * m) == "inconclusive"
    with pytest.raises(ValueError, match="margin"):
        closer_verdict(-0.001, 0.001, margin=0.0)


def test_the_balloon_is_a_sign_below_one():
    assert balloon_verdict(0.80, 0.95) == "balloon (ratio < 1)"
    # the paper's balloon at larger radii, measured: every CI above 1 (1.020-1.040)
    assert balloon_verdict(1.020, 1.040) == "no balloon (ratio > 1)"
    assert balloon_verdict(0.99, 1.01) == "inconclusive"
    # within 10 % and the balloon are different questions: this CI is both
    assert balloon_verdict(1.02, 1.03) != "balloon (ratio < 1)"


@pytest.mark.parametrize(("kind", "verdict", "answer"), [
    ("agreement", "within 10 %", "yes"),
    ("agreement", "lower", "no"),
    ("agreement", "higher", "no"),
    ("agreement", "inconclusive", "undecided"),
    ("balloon", "balloon (ratio < 1)", "yes"),
    ("balloon", "no balloon (ratio > 1)", "no, opposite sign"),
    ("balloon", "inconclusive", "undecided"),
    ("poisson_better", "Poisson closer", "yes"),
    ("poisson_better", "Poisson closer, inside the margin", "in sign only"),
    ("poisson_better", "equally close", "no"),
    ("poisson_better", "actual closer", "no, opposite sign"),
    ("poisson_better", "inconclusive: not resolved at this size (3000 ICs would)",
     "undecided"),
    ("not_tested", "not run", "not tested"),
    ("not_in_paper", "within 10 %", "not in the paper"),
])
def test_reproduces_is_read_off_the_verdict_by_the_claims_kind(kind, verdict, answer):
    assert reproduces(kind, verdict) == answer


def test_reproduces_refuses_an_unknown_kind():
    with pytest.raises(ValueError, match="kind"):
        reproduces("agrees", "within 10 %")


def _count_rows(panel, law, n_ics=40, seed=0):
    rng = np.random.default_rng(seed)
    out = []
    for r in (0.01, 0.02, 0.03, 0.04):
        for ic in range(n_ics):
            out.append({"panel": panel, "radius": r, "ic": ic, "system": "two_particle",
                        "diagnostic": "r1", "horizon": 1, "lam": 0.9,
                        "n_kicks": law(r) * rng.uniform(0.98, 1.02)})
    return pd.DataFrame(out)


def test_fig5_line_residual_is_below_10_percent_for_linear_counts_only():
    linear = _count_rows("family_a", lambda r: 100 + 5000 * r)
    # counts that grow as r^3 lie up to ~40 % off any straight line through them
    cubic = _count_rows("family_b", lambda r: 20 + 3e6 * r ** 3)
    tab = count_line_table(pd.concat([linear, cubic]), PANELS).set_index("family")
    assert tab.loc["family_a", "verdict"] == "residual below 10 %"
    assert tab.loc["family_a", "slope"] == pytest.approx(5000, rel=0.05)
    assert tab.loc["family_a", "estimate"] < 0.01
    assert tab.loc["family_b", "verdict"] == "residual above 10 %"
    assert tab.loc["family_b", "ci_low"] > 0.1


def test_fig5_line_needs_three_radii():
    two = _count_rows("family_a", lambda r: 100 + 5000 * r)
    two = two[two["radius"] <= 0.02]
    assert count_line_table(two, PANELS[:1]).empty


def test_fig4_slope_is_the_mean_of_the_ics_slopes():
    slopes = {"family_a": np.linspace(0.9, 1.1, 50), "family_b": np.linspace(1.3, 1.7, 50)}
    frames = []
    for panel, values in slopes.items():
        for name, lam in (("fig4_slope", values), ("fig4_r2", np.full(50, 0.95))):
            frames.append(pd.DataFrame({
                "panel": panel, "radius": 0.012, "ic": range(50), "system": "poisson",
                "diagnostic": name, "horizon": 1, "lam": lam}))
    # an IC with fewer than 3 collisions has no slope: left out, not counted as 0
    frames.append(pd.DataFrame({"panel": ["family_a"], "radius": [0.012], "ic": [50],
                                "system": ["poisson"], "diagnostic": ["fig4_slope"],
                                "horizon": [1], "lam": [np.nan]}))
    tab = fig4_table(pd.concat(frames, ignore_index=True), PANELS).set_index("family")
    assert tab.loc["family_a", "estimate"] == pytest.approx(1.0)
    assert tab.loc["family_a", "verdict"] == "within 10 %"
    assert tab.loc["family_a", "n_ics"] == 50
    assert tab.loc["family_b", "estimate"] == pytest.approx(1.5)
    assert tab.loc["family_b", "verdict"] == "higher"
    assert tab.loc["family_b", "r2"] == pytest.approx(0.95)
    assert fig4_table(frames[0].iloc[:0], PANELS).empty
