"""The findings' controls: estimators on data with known answers, verdicts and robustness."""

import numpy as np
import pandas as pd
import pytest

from kicktimes.report.answers import answers, overview_table
from kicktimes.report.controls import COLUMNS, compute_controls
from kicktimes.stats import paired_median


def _frame(values_by_system, radii, n_ics):
    idx = pd.MultiIndex.from_product([radii, range(n_ics)], names=["radius", "ic"])
    rows = []
    for system, diag_values in values_by_system.items():
        for diagnostic, values in diag_values.items():
            for (r, i), v in zip(idx, values, strict=True):
                rows.append((r, i, system, diagnostic, float(v), ""))
    return pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value", "note"])


@pytest.mark.parametrize(("low", "high", "verdict"), [
    (0.95, 1.05, "within 10 %"), (0.9, 1.1, "within 10 %"), (0.3, 0.4, "lower"),
    (1.2, 1.5, "higher"), (0.85, 1.0, "inconclusive"), (np.nan, 1.0, "inconclusive"),
])
def test_the_band_verdict(low, high, verdict):
    from kicktimes.stats import ratio_verdict

    assert ratio_verdict(low, high) == verdict


def test_a_median_of_mostly_zero_ratios_is_not_an_estimate():
    # DET of kicked runs without a single diagonal line: most per-IC ratios are 0, so
    # their median is 0 whatever the others are; that radius has no estimate
    idx = pd.MultiIndex.from_product([[0.01, 0.02], range(20)], names=["radius", "ic"])
    y = pd.Series(1.0, index=idx)
    x = pd.Series(np.r_[np.zeros(12), np.full(8, 1.2), np.full(20, 0.97)], index=idx)
    med = paired_median(x, y, rng=np.random.default_rng(0), n_boot=200)
    assert med["ratio"] == pytest.approx(0.97)  # the radius 0.02 alone
    curve = med["per_radius"].set_index("radius")
    assert np.isnan(curve.loc[0.01, "ratio"])
    none = paired_median(x * 0, y, rng=np.random.default_rng(0), n_boot=200)
    assert np.isnan(none["ratio"]) and np.isnan(none["ci_low"])


def test_the_paired_median_ignores_a_few_extreme_runs_and_covers_the_true_ratio():
    rng = np.random.default_rng(5)
    idx = pd.MultiIndex.from_product([[0.01, 0.02, 0.03], range(200)], names=["radius", "ic"])
    y = pd.Series(rng.lognormal(0.0, 0.3, idx.size), index=idx)
    x = 0.93 * y * rng.lognormal(0.0, 0.05, idx.size)
    x.iloc[[0, 250, 500]] *= 1e3  # three sticky runs
    med = paired_median(x, y, rng=np.random.default_rng(1), n_boot=400)
    assert med["ci_low"] < 0.93 < med["ci_high"]
    assert med["ci_high"] - med["ci_low"] < 0.02
    assert med["n_pairs"] == idx.size


def test_sticky_runs_are_left_out_and_a_control_that_flips_the_verdict_is_named():
    # a kicked system at 0.93 of the two-disk value, except three ICs whose two-disk run
    # is sticky (collides 10x the kinetic rate) and whose ratio is 2: the ratio of means
    # moves, the median and the sticky-free ratio do not
    from kicktimes.stats import kinetic_rate

    radii, n = [0.01, 0.02], 60
    rng = np.random.default_rng(2)
    two = rng.uniform(1.0, 1.2, len(radii) * n)
    kicked = 0.93 * two
    sticky_ics = [0, 1, 2]
    for r_i in range(len(radii)):
        for i in sticky_ics:
            two[r_i * n + i] = 0.05
            kicked[r_i * n + i] = 30.0
    results = _frame({"two_particle": {"lyapunov": two}, "poisson_scatter": {"lyapunov": kicked}},
                     radii, n)
    t = 1000.0
    coll = pd.DataFrame([(r, i, t, int(round(kinetic_rate(r) * t * (10 if i in sticky_ics
                                                                     else 1))))
                         for r in radii for i in range(n)],
                        columns=["radius", "ic", "t_window", "n_pp"])
    computed = compute_controls(results, coll, family="f", eps=(),
                                rng=np.random.default_rng(0), n_boot=400)
    table = computed.table
    curve = computed.curves.query("diagnostic == 'ftle' and control == 'sticky_excluded'")
    assert list(curve["radius"]) == radii
    assert np.allclose(curve["ratio"], 0.93)
    assert (curve["ci_low"] <= curve["ratio"]).all() and (curve["ratio"] <= curve["ci_high"]).all()
    assert tuple(table.columns) == COLUMNS
    ftle = table[table["diagnostic"] == "ftle"].set_index("control")
    assert ftle.loc["primary", "estimate"] > 1.3
    assert ftle.loc["sticky_excluded", "estimate"] == pytest.approx(0.93)
    assert ftle.loc["paired_median", "estimate"] == pytest.approx(0.93)
    # the tables' common band says "within 10 %"; the FTLE's own margin, ±5 %
    # (`margin_of`), which the pages read, says "lower"
    assert ftle.loc["sticky_excluded", "verdict"] == "within 10 %"
    assert ftle.loc["sticky_excluded", "margin"] == 0.05
    assert ftle.loc["sticky_excluded", "verdict_at_margin"] == "lower"
    assert not ftle["robust"].any() and (ftle["depends_on"] == "paired_median").all()
    cell = overview_table(table).loc[0, "Poisson, scatter"]
    assert cell.startswith("depends on paired_median: 2.36 [")
    counts = table[table["diagnostic"] == "counts"].set_index("control")
    assert counts.loc["sticky_excluded", "estimate"] == pytest.approx(1.0, abs=0.01)
    assert "3 sticky" not in counts.loc["primary", "detail"]
    assert counts.loc["sticky_excluded", "detail"].startswith("6 sticky")
    assert answers(table) == []  # neither the paper's kicked disk nor a Poisson question


# ------------------------------------------------------------- pooled shares, calibrated
def test_a_share_pooled_over_radii_gets_an_interval_clustered_on_ics():
    # every IC rejects at all 12 radii or at none: 12 x 200 runs are 200 independent
    # units, and the clustered interval is as wide as a binomial interval over 200
    from kicktimes.report.poisson import clustered_share
    from kicktimes.stats import clopper_pearson

    rng = np.random.default_rng(3)
    rejects = rng.uniform(size=200) < 0.3
    df = pd.DataFrame({"radius": np.repeat(np.arange(12) / 1000 + 0.008, 200),
                       "ic": np.tile(np.arange(200), 12),
                       "p": np.tile(np.where(rejects, 0.0, 1.0), 12)})
    low, high = clustered_share(df, "p", 0.05, rng=np.random.default_rng(0))
    naive = clopper_pearson(int(rejects.sum()) * 12, 2400)
    wide = clopper_pearson(int(rejects.sum()), 200)
    assert high - low > 2.5 * (naive[1] - naive[0])
    assert high - low == pytest.approx(wide[1] - wide[0], rel=0.25)


def test_the_fixed_interval_poisson_test_has_its_size_on_poisson_times():
    from kicktimes.report.poisson import FIXED_EVENTS, _poisson_job

    rng = np.random.default_rng(8)
    seqs, windows = [], []
    for _ in range(1500):
        t = np.cumsum(rng.exponential(1.0, 80))
        window = float(rng.uniform(35.0, 80.0))
        seqs.append(t[t <= window])
        windows.append(window)
    job = (0.01, seqs, np.array(windows), 0.05, 19, (1, 1, 0), "mirror", np.arange(1500), None)
    _, _, per_ic = _poisson_job(job)
    fixed = per_ic["p_fixed"].dropna()
    assert len(fixed) == sum(s.size >= FIXED_EVENTS for s in seqs) > 1000
    assert abs((fixed < 0.05).mean() - 0.05) < 0.02


def test_the_bca_interval_shifts_with_skew_and_keeps_the_estimate_inside():
    from kicktimes.stats import paired_ratio

    rng = np.random.default_rng(4)
    idx = pd.MultiIndex.from_product([[0.01, 0.02], range(150)], names=["radius", "ic"])
    y = pd.Series(rng.lognormal(0.0, 1.2, idx.size), index=idx)
    x = pd.Series(0.9 * rng.lognormal(0.0, 1.2, idx.size), index=idx)
    _, pct = paired_ratio(x, y, rng=np.random.default_rng(1), n_boot=1000)
    _, bca = paired_ratio(x, y, rng=np.random.default_rng(1), n_boot=1000, interval="bca")
    assert bca["ratio"] == pct["ratio"]
    assert bca["ci_low"] < bca["ratio"] < bca["ci_high"]
    assert (bca["ci_low"], bca["ci_high"]) != (pct["ci_low"], pct["ci_high"])
    with pytest.raises(ValueError, match="interval must be"):
        paired_ratio(x, y, rng=np.random.default_rng(1), n_boot=100, interval="studentized")


def test_the_poisson_tests_control_on_the_sweeps_own_kicks_sits_at_alpha():
    # two-disk-like times (clustered) and the control on the Poisson kicks of the same runs
    from kicktimes.report.poisson import _poisson_job

    rng = np.random.default_rng(9)
    seqs, windows = [], []
    for _ in range(400):
        window = 2000.0
        t = np.cumsum(rng.exponential(1.0, 80) * rng.choice([0.2, 3.0], 80))
        seqs.append(t[t <= window])
        windows.append(window)
    job = (0.02, seqs, np.array(windows), 0.05, 39, (1, 1, 0), "mirror", np.arange(400),
           (5, 3000.0))
    rows, _, _ = _poisson_job(job)
    table = pd.DataFrame(rows).set_index("test")
    rate = table["n_reject"] / table["n_tested"]
    control = table["control_n_reject"] / table["control_n_tested"]
    assert rate["exponential_ks"] > 0.5  # the clustered times are rejected
    assert (control < 0.12).all() and control.mean() == pytest.approx(0.05, abs=0.03)


def test_a_control_experiment_becomes_rows_of_its_familys_table():
    from kicktimes.report.controls import merge_control_families

    def table(family, verdict, controls=("primary", "paired_median")):
        return pd.DataFrame([
            {"family": family, "question": "FTLE", "diagnostic": "ftle", "system": "poisson",
             "control": c, "estimate": 0.3, "ci_low": 0.29, "ci_high": 0.31,
             "verdict": verdict, "robust": True, "n_pairs": 10, "detail": "d"}
            for c in controls])

    merged = merge_control_families([table("family_a", "lower"),
                                     table("family_a-elastic", "within 10 %"),
                                     table("family_b", "lower")])
    assert set(merged) == {"family_a", "family_b"}
    a = merged["family_a"]
    assert list(a["control"]) == ["primary", "paired_median", "elastic"]
    assert not a["robust"].any()  # the elastic rule changes the verdict
    assert (a["depends_on"] == "elastic").all()
    assert a.loc[2, "detail"].startswith("from the experiment family_a-elastic")
    assert merged["family_b"]["robust"].all()
    # a control whose family is not there stays a family of its own
    alone = merge_control_families([table("family_c-elastic", "lower")])
    assert set(alone) == {"family_c-elastic"}


def _rows(spec, question="FTLE", diagnostic="ftle", system="poisson"):
    from kicktimes.stats import ratio_verdict

    return pd.DataFrame([
        {"family": fam, "question": question, "diagnostic": diagnostic, "system": system,
         "control": c, "estimate": (lo + hi) / 2, "ci_low": lo, "ci_high": hi,
         "verdict": ratio_verdict(lo, hi), "robust": False, "depends_on": "", "n_pairs": 10,
         "detail": ""} for fam, c, lo, hi in spec])


def test_a_verdict_that_changes_direction_is_never_robust():
    """Both 'higher' and 'lower' used to read 'differs' and pass as robust: 1.88 on the
    paper's samples against 0.774 on uniform-time ones is a change of sign, not a finding."""
    from kicktimes.report.answers import overview_table
    from kicktimes.report.controls import with_robustness

    table = with_robustness(_rows([("family_b", "primary", 0.76, 0.79),
                                   ("family_b", "paper_sampling", 1.85, 1.90)],
                                  diagnostic="det@0.01"))
    assert not table["robust"].any() and set(table["depends_on"]) == {"paper_sampling"}
    # two inconclusive verdicts on opposite sides of 1: the same word, not the same finding
    table = with_robustness(_rows([("f", "primary", 1.08, 1.16), ("f", "uniform", 0.89, 0.95)],
                                  diagnostic="rr_offdiag@0.01"))
    assert set(table["verdict"]) == {"inconclusive"} and not table["robust"].any()
    cell = overview_table(table).iloc[0]["Poisson"]
    assert cell == "↕ depends on uniform: 1.12 [1.08, 1.16] vs 0.920 [0.890, 0.950] (uniform)"
    # the control named is the one that reverses the direction, not a milder one
    table = with_robustness(_rows([("f", "primary", 0.763, 0.823),
                                   ("f", "paired_median", 0.870, 0.922),
                                   ("f", "elastic", 1.33, 1.52)], diagnostic="det@0.01"))
    assert set(table["depends_on"]) == {"elastic"}
    assert overview_table(table).iloc[0]["Poisson"].startswith("↕ depends on elastic: 0.793")


def test_a_robust_cell_gives_its_verdict_and_the_range_over_every_control_and_family():
    from kicktimes.report.answers import screen_cell
    from kicktimes.report.controls import with_robustness

    table = with_robustness(_rows([("family_a", "primary", 0.32, 0.33),
                                   ("family_a", "elastic", 0.40, 0.42),
                                   ("family_b", "primary", 0.31, 0.33)]))
    assert table["robust"].all()
    assert screen_cell(table) == "✓ lower: 0.32–0.41"


def test_the_poisson_question_is_a_row_per_test_with_the_rule_as_a_control():
    from kicktimes.report.answers import poisson_answer
    from kicktimes.report.controls import POISSON_QUESTION, merge_control_families, poisson_rows
    from kicktimes.studies.paper.first_screen import answer_lines

    rej = pd.DataFrame({"radius": [0.01, 0.02] * 2,
                        "test": ["uniformity_ks"] * 2 + ["ljung_box"] * 2,
                        "n_tested": [200, 200, 1000, 1000], "n_reject": [80, 76, 52, 48]})
    rng = np.random.default_rng(3)
    per_ic = pd.DataFrame({"radius": np.repeat([0.01, 0.02], 200), "ic": np.tile(range(200), 2),
                           "p": np.r_[np.zeros(80), np.ones(120), np.zeros(76), np.ones(124)],
                           "p_fixed": np.nan, "dispersion": rng.normal(1.4, 0.3, 400)})
    # the null calibration: the uniformity test rejects 8 % of null streams (not nominal),
    # Ljung-Box 5 %
    null = pd.DataFrame({"test": ["uniformity_ks", "ljung_box"], "share": [0.08, 0.05]})
    mirror = pd.DataFrame(poisson_rows("family_a", rej, per_ic, alpha=0.05,
                                       rng=np.random.default_rng(0), n_boot=300, null=null))
    assert list(mirror["diagnostic"]) == ["reject@uniformity_ks", "reject@ljung_box",
                                          "dispersion_index", "poisson@uniformity_ks"]
    assert mirror.loc[0, "estimate"] == pytest.approx(156 / 400)
    assert mirror.loc[0, "verdict"] == "above nominal" and mirror.loc[1, "verdict"] == "nominal"
    assert "8.0 % (null_calibration.csv)" in mirror.loc[0, "detail"]
    assert mirror.loc[2, "verdict"] == "higher"
    assert mirror.loc[3, "verdict"] == "not Poisson"
    # elastic: 13 % of runs reject, above the calibrated 8 % by more than half of it? No:
    # the band is [4 %, 12 %], the CI straddles 12 %; D within 10 %
    rej_e = rej.assign(n_reject=[28, 24, 50, 45])
    per_ic_e = per_ic.assign(p=np.r_[np.zeros(28), np.ones(172), np.zeros(24), np.ones(176)],
                             dispersion=rng.normal(1.0, 0.2, 400))
    elastic = pd.DataFrame(poisson_rows("family_a-elastic", rej_e, per_ic_e, alpha=0.05,
                                        rng=np.random.default_rng(0), n_boot=300, null=null))
    assert elastic.loc[2, "verdict"] == "within 10 %"
    assert elastic.loc[3, "verdict"] == "inconclusive"
    table = merge_control_families([mirror, elastic])["family_a"]
    assert (table["question"] == POISSON_QUESTION).all()
    assert set(table["control"]) == {"primary", "elastic"}
    head = table[table["diagnostic"] == "reject@uniformity_ks"]
    assert not head["robust"].all()  # above nominal under one rule only
    assert table[table["diagnostic"] == "reject@ljung_box"]["robust"].all()  # nominal twice
    text = poisson_answer(table)
    assert text.startswith("Poisson collision times? Mirror rule: not Poisson (uniformity "
                           "rejected in 39.0 %")
    assert "against null streams 8.0 % (A)" in text
    assert "elastic rule: inconclusive (13.0 %" in text and "disjoint" in text
    # the first screen's answer: the mirror rule's verdict and share against its calibrated
    # level; not robust over the rule, so no "robust"; then the elastic rule's share
    line = answer_lines(table)[0]
    assert line.startswith("- **Are the two disks' collision times Poisson?** no: 39.0 [")
    assert "reject uniformity (null 8.0 %) (A);" in line
    assert "robust" not in line and "; elastic 13.0 [" in line


def test_the_first_screen_is_at_most_five_one_line_answers_then_a_compact_table():
    from kicktimes.report.controls import with_robustness
    from kicktimes.studies.paper.first_screen import QUESTIONS, first_screen

    spec = []
    for system in ("poisson", "actual", "poisson_scatter", "actual_scatter", "poisson_kinetic",
                   "uniform_kinetic"):
        for fam in ("family_a", "family_b"):
            for c in ("primary", "paired_median", "sticky_excluded", "invariant_ics",
                      "elastic", "elastic+invariant_ics"):
                spec.append((fam, c, system))
    rows = pd.concat([_rows([(f, c, 0.3, 0.33)], system=s) for f, c, s in spec],
                     ignore_index=True)
    # one control breaks the scatter kicks' verdict
    broken = (rows["system"] == "poisson_scatter") & (rows["control"] == "elastic")
    rows.loc[broken, ["estimate", "ci_low", "ci_high"]] = [0.95, 0.93, 0.97]
    rows.loc[broken, "verdict"] = "within 10 %"
    lines = first_screen(with_robustness(rows))
    answers = lines[:lines.index("")]
    assert len(answers) == 2  # no Poisson rows and one diagnostic here: the two FTLE questions
    assert answers[0] == (f"- **{QUESTIONS[0][0]}** no, lower at a 5 % margin: 0.315 [0.300, "
                          "0.330] (A, Poisson kicks); robust over 5 controls and both families "
                          "(0.315).")
    # the scatter kicks at their 5 % margin: 0.950 [0.930, 0.970] straddles 0.95
    assert answers[1] == (f"- **{QUESTIONS[1][0]}** depends on the control at a 5 % "
                          "margin: lower 0.315 [0.300, 0.330] (A, Poisson scatter kicks) under "
                          "the primary; below 1 0.950 [0.930, 0.970] under elastic.")
    assert all(len(a.split()) <= 45 for a in answers)  # one line each
    table = lines[lines.index("") + 3:]
    assert table[0].count("|") - 1 <= 8
    assert table[2] == ("| FTLE λ | lower 0.315 ✓ | lower 0.315 ✓ | lower 0.315 ✗ elastic | "
                        "lower 0.315 ✓ | lower 0.315 ✓ | lower 0.315 ✓ |")


def test_every_family_has_the_rule_by_ic_design_as_control_experiments():
    from kicktimes.experiment.presets import CONTROL_ICS_B, CONTROL_PRESETS, PRESETS
    from kicktimes.studies.paper import SCALES

    names = {PRESETS[k].name for k in CONTROL_PRESETS}
    assert names == {f"{fam}-{c}" for fam in ("family_a", "family_b")
                     for c in ("invariant_ics", "elastic", "elastic+invariant_ics")}
    assert set(CONTROL_PRESETS) <= set(SCALES["paper"])
    for key in CONTROL_PRESETS:
        exp = PRESETS[key]
        family = PRESETS[exp.name.split("-")[0]]
        control = exp.name.split("-", 1)[1]
        assert exp.rule == ("elastic" if "elastic" in control else "mirror")
        assert exp.ic_method == ("uniform" if "invariant_ics" in control else "paper")
        assert exp.n_ics == (CONTROL_ICS_B if family.name == "family_b" else family.n_ics) >= 200
        assert (exp.radii, exp.n_steps, exp.tau) == (family.radii, family.n_steps, family.tau)
        # every control runs every system, the kinetic-rate kicks under the elastic rule too
        assert set(exp.systems) == set(family.systems)


def test_the_readme_block_is_replaced_by_the_generated_first_screen(tmp_path):
    from kicktimes.studies.paper import BEGIN, END, copy_first_screen

    page = tmp_path / "docs" / "results" / "README.md"
    page.parent.mkdir(parents=True)
    page.write_text("# t\n\nGenerated 2026 by kicktimes from `a`.\n\n## The answers\n\nOne. "
                    "Two.\n\n![h](h.png)\n\n## Next\n\nrest\n")
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n\n{BEGIN}\nold\n{END}\n\ntail\n")
    copy_first_screen(page, readme)
    text = readme.read_text()
    assert "old" not in text and text.startswith("intro") and text.endswith("tail\n")
    assert "Generated 2026 by kicktimes" in text and "![h](docs/results/h.png)" in text
    assert "rest" not in text
    (tmp_path / "plain.md").write_text("no block\n")
    with pytest.raises(ValueError, match="no block"):
        copy_first_screen(page, tmp_path / "plain.md")


def test_the_paper_module_copies_the_first_screen_and_leaves_the_page_alone(tmp_path, capsys):
    from kicktimes.studies.paper import BEGIN, END
    from kicktimes.studies.paper.__main__ import main

    page = tmp_path / "README.md"
    page.write_text("# t\n\nGenerated 2026 from `a`.\n\n## The answers\n\n| FTLE λ | x |\n\n"
                    "![headline](h.png)\n\n## Next\n")
    before = page.read_bytes()
    readme = tmp_path / "top.md"
    readme.write_text(f"intro\n{BEGIN}\nold\n{END}\n")
    assert main([str(tmp_path), "--readme", str(readme)]) == 0
    assert "| FTLE λ | x |" in readme.read_text() and "old" not in readme.read_text()
    assert page.read_bytes() == before  # the page has one writer: write_results
    with pytest.raises(SystemExit) as stop:
        main([str(tmp_path / "nowhere"), "--readme", str(readme)])
    assert stop.value.code == 2 and "error:" in capsys.readouterr().err


def test_a_verdict_robust_in_direction_but_not_in_size_names_the_farthest_cell():
    """One verdict ("lower") under every control, but estimates from 0.43 to 0.84: the
    answer says the direction is robust and names the cell whose size differs most, not
    "robust" alone (a referee's point: 1 − R₁ "robust" over 0.426–0.842)."""
    from kicktimes.report.controls import with_robustness
    from kicktimes.studies.paper.first_screen import _ratio_line

    spec = [("family_a", c, 0.76, 0.81) for c in ("primary", "paired_median", "invariant_ics")]
    spec += [("family_b", "primary", 0.80, 0.84), ("family_b", "elastic", 0.40, 0.45)]
    rows = with_robustness(_rows(spec, question="decorrelation", diagnostic="one_minus_r1"))
    line = _ratio_line("Q?", rows, 0.1)
    assert line == ("**Q?** no, lower at a 10 % margin: 0.785 [0.760, 0.810] (A, Poisson "
                    "kicks); robust in direction over 3 controls and both families "
                    "(0.425–0.82), not in size: 0.425 (B, Poisson kicks, elastic).")
    # the same cells inside one margin band: plain "robust"
    spec[-1] = ("family_b", "elastic", 0.74, 0.79)
    rows = with_robustness(_rows(spec, question="decorrelation", diagnostic="one_minus_r1"))
    assert _ratio_line("Q?", rows, 0.1).endswith(
        "; robust over 3 controls and both families (0.765–0.82).")
