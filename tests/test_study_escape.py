"""The escape study (kicktimes.studies.escape): its page from its tables, its cache."""

import re

import numpy as np
import pandas as pd
import pytest
from conftest import assert_provenance, assert_study_page, first_screen_answers, refuse_simulations

import kicktimes.studies.escape as study
from kicktimes.stats import format_interval
from kicktimes.stats import ratio_reading as ratio_verdict

TINY = study.Params(n_ics=100, t_max=400.0, t_min=50.0, n_free=300)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("escape")
    lines = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(study.SCALES, "quick", TINY)
        page = study.reproduce(out, progress=lines.append)
    return out, page, lines


def test_the_page_names_its_command_and_no_machine_path(built):
    _, page, _ = built
    assert_study_page(page, "escape")
    assert (page.parent / "escape" / "escape_survival.png").stat().st_size > 0


def test_the_page_s_ratios_are_its_csv_with_their_verdicts(built):
    _, page, _ = built
    text = page.read_text(encoding="utf-8")
    ratios = pd.read_csv(page.parent / "escape" / "escape_ratios.csv")
    assert set(ratios.loc[ratios["negative_control"], "system"]) == set(study.compute.CONTROLS)
    for row in ratios.itertuples():
        assert row.verdict == ratio_verdict(row.ci_low, row.ci_high)
        assert format_interval(row.ratio, row.ci_low, row.ci_high) in text
    constant = pd.read_csv(page.parent / "escape" / "escape_constant.csv")
    assert (constant["n"] == TINY.n_free).all()


def test_a_rerun_reuses_the_cached_escape_times(built, monkeypatch):
    out, page, _ = built
    before = {p.name: p.read_bytes() for p in (page.parent / "escape").glob("*.csv")}
    refuse_simulations(monkeypatch, study, "escape_times", "free_disk_escapes")
    monkeypatch.setitem(study.SCALES, "quick", TINY)
    again = study.reproduce(out, command="my command")
    assert "(`my command`)" in again.read_text(encoding="utf-8")
    for name, data in before.items():
        assert (again.parent / "escape" / name).read_bytes() == data, name


def test_the_tail_rate_is_events_over_time_at_risk_beyond_t_min():
    rng = np.random.default_rng(1)
    t = rng.exponential(100.0, 20000)
    horizon = np.full(t.size, 3000.0)
    t[t > 3000.0] = np.inf
    picks = np.arange(t.size)[None, :]
    one = study.tail_rates(t, horizon, 50.0, picks)[0]
    assert one == pytest.approx(0.01, rel=0.03)
    assert study.tail_rates(t, horizon, 50.0, picks, disks=2)[0] == pytest.approx(one / 2)


def test_the_paper_scale_is_the_published_page_s():
    assert study.SCALES["paper"] == study.Params(n_ics=4000, t_max=3000.0, t_min=50.0,
                                                 n_free=40000, seed=11)


def test_the_c_over_t_law_gets_a_verdict_from_both_its_parts(built):
    _, page, _ = built
    text = page.read_text(encoding="utf-8")
    (line,) = [ln for ln in text.splitlines() if ln.startswith("**Verdict on the law")]
    verdict = re.search(r"C/t of the free disk: (\w+)\.", line).group(1)
    alpha_tab = pd.read_csv(page.parent / "escape" / "escape_alpha.csv")
    constant = pd.read_csv(page.parent / "escape" / "escape_constant.csv")
    # the exponent under both IC samples: the paper ICs' fit and the invariant measure's
    alpha = [ratio_verdict(lo, hi) for lo, hi in zip(alpha_tab["alpha_low"],
                                                     alpha_tab["alpha_high"], strict=True)]
    const = [ratio_verdict(lo / c, hi / c) for lo, hi, c in
             zip(constant["t_S_low"], constant["t_S_high"], constant["C_predicted"],
                 strict=True)]
    assert verdict == study.page.law_verdict(alpha, const)
    assert "10 %" in line and "stated in advance" in line
    assert study.page.law_verdict(["within 10 %"] * 2, ["within 10 %"]) == "confirmed"
    assert study.page.law_verdict(["within 10 %"], ["higher", "inconclusive"]) == "rejected"
    assert study.page.law_verdict(["inconclusive"], ["within 10 %"]) == "unconfirmed"
    with pytest.raises(ValueError, match="must not both be empty"):
        study.page.law_verdict([], [])


def test_the_survival_curves_turn_grey_below_the_at_risk_floor():
    from kicktimes.stats import MIN_AT_RISK, escape_survival, reliable_until
    from kicktimes.studies.escape.figures import survival_figure

    rng = np.random.default_rng(1)
    t = rng.exponential(100.0, 400)
    km = escape_survival(np.where(t < 1000, t, np.inf), 1000.0)
    cut = reliable_until(km)
    assert km.loc[km["time"] < cut, "n_at_risk"].min() >= MIN_AT_RISK
    assert km.loc[km["time"] == cut, "n_at_risk"].iloc[0] < MIN_AT_RISK
    assert reliable_until(km, floor=1) == float("inf") or reliable_until(km, floor=1) > cut
    with pytest.raises(ValueError, match="floor"):
        reliable_until(km, floor=0)
    curves = {(r, "two_particle"): km for r in study.compute.RADII}
    fig = survival_figure(curves)
    ax = fig.axes[0]
    (grey,) = [ln for ln in ax.get_lines() if ln.get_gid() == "few_at_risk_two_particle"]
    label = study.compute.LABELS["two_particle"]
    (black,) = [ln for ln in ax.get_lines() if ln.get_label() == label]
    # the measured part holds its value up to the first step of fewer runs, then grey
    assert black.get_xdata().max() == cut < grey.get_xdata().max()
    assert grey.get_xdata()[0] == black.get_xdata()[-1]  # the two parts meet
    assert grey.get_ydata()[0] == black.get_ydata()[-1]
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_no_survival_curve_hides_the_two_disk_one():
    from kicktimes.stats import escape_survival
    from kicktimes.studies.escape.figures import survival_figure

    t = np.random.default_rng(2).exponential(100.0, 400)
    km = escape_survival(np.where(t < 1000, t, np.inf), 1000.0)
    # identical curves: the worst case, one on another
    systems = ("two_particle", "poisson", "poisson_scatter")
    fig = survival_figure({(r, s): km for r in study.compute.RADII for s in systems})
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
    two, uniform, scatter = (lines[study.compute.LABELS[s]] for s in systems)
    # the two disks thin and on top; the uniform-kick curve wider, see-through, below
    assert two.get_zorder() > scatter.get_zorder() > uniform.get_zorder()
    assert uniform.get_linewidth() > two.get_linewidth()
    assert uniform.get_alpha() < 1 and scatter.get_linestyle() != "-"
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_the_page_ends_with_where_its_numbers_come_from(built):
    _, page, _ = built
    rows = assert_provenance(page, every_csv_in="escape")
    assert ("escape/escape_tails.csv", "alpha, alpha_low, alpha_high, aic_exp_minus_alg",
            "kicktimes.stats.survival.fit_escape_tail") in rows


def test_the_page_opens_with_at_most_five_answers_each_with_an_interval(built):
    first_screen_answers(built[1])


def test_the_exponent_answer_names_both_ic_samples(built):
    from kicktimes.stats import robust_verdict

    _, page, _ = built
    (line,) = [a for a in first_screen_answers(page)
               if a.startswith("- **Free disk's exponent")]
    assert "paper ICs" in line and "invariant measure" in line
    alpha = pd.read_csv(page.parent / "escape" / "escape_alpha.csv")
    for _, g in alpha.groupby("radius"):
        assert list(g["sample"]) == list(study.compute.ALPHA_SAMPLES)
        robust, why = robust_verdict(list(g["verdict"]), g["alpha_low"], g["alpha_high"])
        reasons = {"" if pd.isna(x) else x for x in g["not_robust_by"]}
        assert (g["robust"] == robust).all() and reasons == {why}
    assert ("depends on the IC sample" in line) == (not alpha["robust"].all())


def test_the_first_answer_says_what_the_escape_rate_can_tell_apart(built):
    _, page, _ = built
    first = first_screen_answers(page)[0]
    assert first.startswith("- **What the escape rate can tell apart")
    ratios = pd.read_csv(page.parent / "escape" / "escape_ratios.csv")
    for system in study.compute.CONTROLS:
        v = ratios.loc[ratios["system"] == system, "verdict"]
        assert f"{v.isin(['lower', 'higher']).sum()} of {len(v)}" in first


def test_an_interval_beyond_a_band_edge_that_excludes_1_is_not_inconclusive():
    # the general rule: 1.13 [1.09, 1.16] lies above 1 and straddles 1.1
    assert ratio_verdict(1.09, 1.16) == "above 1, size unresolved"
    assert ratio_verdict(0.854, 0.988) == "below 1, size unresolved"
    assert ratio_verdict(0.9661, 1.101) == "inconclusive"  # contains 1: only then a size
    assert ratio_verdict(0.95, 1.05) == "within 10 %"
    assert ratio_verdict(1.2, 1.3) == "higher" and ratio_verdict(0.2, 0.3) == "lower"
    assert ratio_verdict(float("nan"), 1.2) == "inconclusive"


def test_the_headline_and_the_ratio_table_count_one_per_radius_verdict(built):
    _, page, _ = built
    text = page.read_text(encoding="utf-8")
    ratios = pd.read_csv(page.parent / "escape" / "escape_ratios.csv")
    (table,) = [ln for ln in text.splitlines() if ln.startswith("Per radius, the verdict")]
    for system, name in (("poisson", "Uniform kicks"), ("poisson_scatter", "Scatter kicks")):
        per = study.page.per_radius_verdicts(ratios, system)
        assert len(per) == ratios["radius"].nunique()
        g = ratios[ratios["system"] == system]
        for r, v in per.items():
            both = set(g.loc[g["radius"] == r, "verdict"])
            assert v == (both.pop() if len(both) == 1 else "depends on the estimator")
        count = study.page.count_text(per)
        (line,) = [a for a in first_screen_answers(page) if a.startswith(f"- **{name}")]
        assert f"under both estimators: {count}" in line
        assert count + " radii" in table


def test_an_exponent_within_the_margin_says_when_it_excludes_1(built):
    _, page, _ = built
    alpha = pd.read_csv(page.parent / "escape" / "escape_alpha.csv")
    g = alpha.assign(verdict="within 10 %",
                     alpha_low=0.91, alpha_high=0.99)
    assert study.page._side_text(g) == f"; of those within, below 1 at {len(g)}"
    assert study.page._side_text(g.assign(alpha_high=1.01)) == ""


def test_the_ratios_over_radii_are_geometric_means_with_their_verdicts(built):
    _, page, _ = built
    over = pd.read_csv(page.parent / "escape" / "escape_over_radii.csv")
    ratios = pd.read_csv(page.parent / "escape" / "escape_ratios.csv")
    for row in over.itertuples():
        assert row.verdict == ratio_verdict(row.ci_low, row.ci_high)
        if row.reference != "ergodic":
            per = ratios[(ratios["system"] == row.system)
                         & (ratios["reference"] == row.reference)]["ratio"]
            assert row.ratio == pytest.approx(float(np.exp(np.log(per).mean())))
        assert row.n_ics_to_resolve >= row.n_ics
