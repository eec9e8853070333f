"""Specification of the report's escape section (kicktimes.report.escape): a tiny sweep
with holes gets the section and its tables, a store without holes gets none, and the
computed answer is right on synthetic escape times whose answer is known."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from kicktimes.experiment import load_store, preset, run_experiment
from kicktimes.report import Render, Subsampling, build_report
from kicktimes.report.escape import (
    escape_answer,
    escape_comparison,
    escape_curves,
    escape_figure,
    escape_runs,
    escape_table,
    sections,
)
from kicktimes.stats import MIN_AT_RISK

HOLES = [(0.0, 0.15)]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    exp = dataclasses.replace(preset("quick_a"), name="holes_report", radii=(0.02, 0.03),
                              n_ics=6, block_size=6, n_steps=1500, holes=HOLES)
    store = tmp_path_factory.mktemp("store")
    run_experiment(exp, store, workers=1, progress=False)
    out = tmp_path_factory.mktemp("report")
    build_report(store, out, progress=False, workers=1, n_mc=19, n_boot=100,
                 subsampling=Subsampling(max_ics_model_fits=1), render=Render(dpi=40))
    return exp, load_store(store), out


def test_a_sweep_with_holes_gets_the_escape_section_figure_and_tables(report):
    exp, _, out = report
    page = (out / "report.html").read_text(encoding="utf-8")
    assert 'id="escape"' in page
    assert "Does the kicked disk escape like the two disks? " in page
    assert (out / "fig11_escape_survival.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    tails = pd.read_csv(out / "escape_tails.csv")
    pairs = {(r, s) for r in exp.radii for s in exp.systems}
    assert len(tails) == len(pairs)
    assert set(zip(tails["radius"], tails["system"], strict=True)) == pairs
    assert (tails["n"] == exp.n_ics).all()
    assert ((tails["escaped"] >= 0) & (tails["escaped"] <= tails["n"])).all()
    assert (tails["followed"] == "disk 0").all()
    for column in ("survival_t_min", "survival_10_t_min"):
        s = tails[column].dropna()
        assert ((s >= 0) & (s <= 1)).all()
    fitted = tails.dropna(subset=["rate"])
    assert len(fitted) > 0
    assert (fitted["rate_low"] <= fitted["rate"]).all()
    assert (fitted["rate"] <= fitted["rate_high"]).all()
    assert (fitted["alpha_low"] <= fitted["alpha"]).all()
    assert set(tails["tail_law"]) <= {"exponential", "algebraic", "undecided", "n/a"}
    assert np.allclose(tails["t_min"], exp.horizon / 20)
    comparison = pd.read_csv(out / "escape_comparison.csv")
    assert len(comparison) == len(exp.radii) * (len(exp.systems) - 1)
    assert set(comparison["verdict"]) <= {"like", "not like", "inconclusive", "n/a"}
    # the figure's own curves: survival decreasing in [0, 1] within each (radius, system)
    curves = pd.read_csv(out / "escape_survival.csv")
    for _, g in curves.groupby(["radius", "system"]):
        s = g["survival"].to_numpy()
        assert (np.diff(s) <= 0).all() and 0 <= s[-1] <= s[0] <= 1


def test_disk_1_escaping_first_censors_disk_0_at_that_time(report):
    _, store, _ = report
    res = store.results
    disk = res[res["diagnostic"] == "escaped_disk"].set_index(["radius", "ic"])["value"]
    assert set(disk) <= {-1.0, 0.0, 1.0}
    runs = escape_runs(res)
    two = runs[runs["system"] == "two_particle"].set_index(["radius", "ic"])
    t_max = res[(res["diagnostic"] == "t_max") & (res["system"] == "two_particle")]
    t_max = t_max.set_index(["radius", "ic"])["value"]
    assert (two["horizon"] == t_max.loc[two.index]).all()
    other = disk[disk == 1].index
    assert len(other) > 0, "the tiny sweep should have a run where disk 1 leaves first"
    assert np.isinf(two.loc[other, "time"]).all() and two.loc[other, "other_disk"].all()
    own = disk[disk == 0].index
    assert (two.loc[own, "time"] == two.loc[own, "horizon"]).all()


def _results(times_by_radius, horizon=1000.0, disk_rows=True):
    """Tidy rows of escape times ({radius: {system: times}}; > horizon: censored)."""
    rows = []
    for r, by_system in times_by_radius.items():
        for system, times in by_system.items():
            for ic, t in enumerate(times):
                escaped = t <= horizon
                rows += [(r, ic, system, "escape_time", t if escaped else math.inf),
                         (r, ic, system, "t_max", t if escaped else horizon)]
                if system == "two_particle" and disk_rows:
                    rows.append((r, ic, system, "escaped_disk", 0.0 if escaped else -1.0))
    return pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])


def _verdicts(results, t_min=10.0):
    table = escape_table(escape_runs(results), t_min=t_min)
    comparison = escape_comparison(table)
    return comparison, escape_answer(comparison)


def test_the_same_exponential_escape_is_like_the_two_disks():
    # "like" is an equivalence test: the ratio's interval within 10 %, which needs many runs
    rng = np.random.default_rng(1)
    law = {s: rng.exponential(40.0, 6000) for s in ("two_particle", "poisson", "actual")}
    comparison, answer = _verdicts(_results({0.02: law}))
    assert (comparison["verdict"] == "like").all()
    assert ((comparison["ratio_low"] >= 0.9) & (comparison["ratio_high"] <= 1.1)).all()
    assert (comparison["compared"] == "rate").all()
    assert answer.startswith("Does the kicked disk escape like the two disks? Yes")


def test_an_algebraic_tail_against_an_exponential_one_is_not_like():
    rng = np.random.default_rng(2)
    law = {"two_particle": rng.exponential(40.0, 800),
           "poisson": 5.0 * rng.random(800) ** -1.0}  # Pareto, S = 5 / t: the circle's
    comparison, answer = _verdicts(_results({0.02: law}))
    row = comparison.iloc[0]
    assert (row["tail_law"], row["tail_law_two_particle"]) == ("algebraic", "exponential")
    assert row["verdict"] == "not like"
    assert "No:" in answer and "algebraic tail against" in answer


def test_an_answer_that_differs_across_radii_says_so_with_the_numbers():
    rng = np.random.default_rng(3)
    same = {s: rng.exponential(40.0, 6000) for s in ("two_particle", "poisson")}
    faster = {"two_particle": rng.exponential(40.0, 800), "poisson": rng.exponential(15.0, 800)}
    comparison, answer = _verdicts(_results({0.01: same, 0.03: faster}))
    assert list(comparison["verdict"]) == ["like", "not like"]
    assert "It depends on the radius: like at r = 0.01" in answer
    assert "r = 0.03, Poisson: γ = " in answer  # the differing case, with its numbers


def test_overlapping_intervals_alone_are_not_agreement():
    # few runs: the intervals overlap, but the ratio's interval reaches past the 10 % band
    rng = np.random.default_rng(5)
    law = {s: rng.exponential(40.0, 300) for s in ("two_particle", "poisson")}
    comparison, answer = _verdicts(_results({0.02: law}))
    row = comparison.iloc[0]
    assert row["ci_overlap"] and row["verdict"] == "inconclusive"
    assert "Undecided" in answer


def test_a_store_that_does_not_say_which_disk_left_is_not_compared():
    rng = np.random.default_rng(4)
    law = {s: rng.exponential(40.0, 300) for s in ("two_particle", "poisson")}
    results = _results({0.02: law}, disk_rows=False)
    runs = escape_runs(results)
    assert set(runs.loc[runs["system"] == "two_particle", "followed"]) == {"either disk"}
    comparison, answer = _verdicts(results)
    assert list(comparison["verdict"]) == ["n/a"]
    assert "Not computed: the store does not record which disk left" in answer


def test_a_store_without_holes_gets_no_escape_section():
    from test_report_sections import synthetic_store

    from kicktimes.report.context import Context

    ctx = Context(synthetic_store(n_ics=4))
    assert not getattr(ctx.exp, "holes", ())
    assert sections(ctx) == []


def test_bad_input_is_refused_with_clear_errors(tmp_path):
    runs = escape_runs(_results({0.02: {"two_particle": [5.0, 50.0], "poisson": [3.0, 9.0]}}))
    with pytest.raises(ValueError, match="t_min must be positive"):
        escape_table(runs, t_min=-1.0)
    with pytest.raises(TypeError, match="t_min must be a number"):
        escape_table(runs, t_min="50")
    with pytest.raises(ValueError, match="escape_t_min must be positive"):
        build_report(tmp_path / "nowhere", tmp_path / "out", escape_t_min=0.0)
    no_horizon = _results({0.02: {"poisson": [5.0]}})
    no_horizon = no_horizon[no_horizon["diagnostic"] != "t_max"]
    with pytest.raises(ValueError, match="has no t_max row"):
        escape_runs(no_horizon)
    with pytest.raises(ValueError, match="curves must have columns"):
        escape_figure(pd.DataFrame({"radius": [0.02]}))


def test_the_figure_has_a_panel_per_radius_in_the_system_colours():
    from matplotlib.colors import to_rgba

    from kicktimes.render.figures import system_style

    rng = np.random.default_rng(5)
    law = {s: rng.exponential(40.0, 200) for s in ("two_particle", "poisson")}
    curves = escape_curves(escape_runs(_results({0.01: law, 0.02: law, 0.03: law})))
    fig = escape_figure(curves, t_min=10.0)
    panels = [ax for ax in fig.axes if ax.get_visible() and ax.lines]
    assert len(panels) == 3
    assert [ax.get_title() for ax in panels] == ["r = 0.01", "r = 0.02", "r = 0.03"]
    for ax in panels:
        assert ax.get_xscale() == ax.get_yscale() == "log"
        colours = {line.get_label(): to_rgba(line.get_color()) for line in ax.lines}
        assert colours["Two-particle"] == to_rgba(system_style("two_particle")["color"])
        assert colours["Poisson"] == to_rgba(system_style("poisson")["color"])
        # below MIN_AT_RISK runs at risk: thin and grey, joined to the measured part
        (grey,) = [ln for ln in ax.lines if ln.get_gid() == "few_at_risk_poisson"]
        (line,) = [ln for ln in ax.lines if ln.get_label() == "Poisson"]
        assert grey.get_xdata()[0] == line.get_xdata()[-1]
        assert grey.get_ydata()[0] == line.get_ydata()[-1]
        km = curves[(curves["system"] == "poisson") & (curves["radius"] == 0.01)]
        first_few = km.loc[km["n_at_risk"] < MIN_AT_RISK, "time"].iloc[0]
        assert line.get_xdata()[-1] == pytest.approx(first_few)
