"""The protocol study (kicktimes.studies.protocol): rows, tables, Shapley shares, the page."""

import re

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from kicktimes.cli import main
from kicktimes.diagnostics import lyapunov
from kicktimes.render.provenance import PROVENANCE_TITLE
from kicktimes.stats import paired_ratio
from kicktimes.studies.protocol.compute import D0, Panel, compute_task, run_rows, tasks
from kicktimes.studies.protocol.page import FIGURE, build_page, fig6_figure

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
    # estimators, tangent, R_1, the two RR
    assert per_system == {"two_particle": 8, "poisson": 16, "actual": 16}
    assert set(rows["horizon"]) == {1, 2, 4, 8}
    conv = rows[rows["horizon"] == 8]
    assert set(conv["radius"]) == {0.024} and set(conv["ic"]) == {0, 1}


def test_the_literal_two_disk_row_is_eq4_of_lyapunov(rows):
    p = PANELS[0]
    ic = p.initial_conditions()[1]
    want = lyapunov(ic, 0.024, method="twin", variant="paper", d0=D0, renormalize=False,
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
    assert len(first_screen) <= 1200
    header = next(line for line in text.splitlines() if line.startswith("| Claim"))
    assert header.count("|") - 1 <= 8
    assert (tmp_path / FIGURE).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    findings = pd.read_csv(tmp_path / "paper_findings.csv")
    claims = pd.read_csv(tmp_path / "paper_claims.csv")
    # every verdict is its interval's (the rule of kicktimes.stats.ratio_verdict)
    for row in findings.itertuples():
        inside = row.ci_low >= 0.9 and row.ci_high <= 1.1
        assert (row.verdict == "within 10 %") == inside
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
    assert "eq. (4) as printed gives kicked/two-disk" in (results / "paper.md").read_text()


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
