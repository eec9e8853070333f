"""The tables study (kicktimes.studies.tables): its experiments, its comparisons on data
with known answers, the free disk's tables and its page."""

import math
import re

import numpy as np
import pandas as pd
import pytest

from kicktimes.report.controls import COLUMNS
from kicktimes.stats import ratio_verdict
from kicktimes.studies import STUDIES
from kicktimes.studies.tables import (
    SCALES,
    TABLES,
    against_circle,
    family_name,
    focal_drift,
    focal_product,
    free_ftle,
    free_runs,
    reproduce,
    tables_experiment,
)
from kicktimes.studies.tables.page import _answer
from kicktimes.tables import Circle, Ellipse, Stadium


def test_the_experiments_are_the_paper_design_in_each_table():
    exp = tables_experiment("stadium", "elastic", n_ics=200)
    assert exp.name == "tables_stadium-elastic" and exp.rule == "elastic"
    assert exp.table == "stadium a=1.0" and exp.ic_method == "uniform"
    assert exp.horizon == pytest.approx(5000.0) and exp.radii == (0.01, 0.02, 0.03)
    # the paper's family A protocol, but for its ICs (the paper's are the circle's)
    from kicktimes.experiment.presets import PRESETS

    family_a = PRESETS["family_a"]
    for field in ("n_steps", "tau", "sampling", "eps", "rr_sampling", "lyapunov_variant",
                  "lyapunov_method", "diagnostics"):
        assert getattr(exp, field) == getattr(family_a, field), field
    assert set(exp.systems) == {"two_particle", "poisson", "actual", "poisson_scatter"}
    # a circle store's hash is the table-free experiment's (the field's default)
    circle = tables_experiment("circle", "mirror", n_ics=4, n_steps=100)
    assert circle.table == "circle"
    assert circle.hash() == type(circle).from_dict(
        {k: v for k, v in circle.to_dict().items() if k != "table"}).hash()
    assert family_name("ellipse", "mirror") == "tables_ellipse"
    with pytest.raises(ValueError, match="table must be one of"):
        family_name("sinai", "mirror")
    assert STUDIES["tables"].page == "tables.md" and "scheduler" in STUDIES["tables"].options


def _runs(ratios, n_ics=40, seed=0, noise=0.05):
    """Per-IC FTLEs whose kicked / two-disk ratio is ``ratios[table]`` (a known answer)."""
    rng = np.random.default_rng(seed)
    rows = []
    for table, ratio in ratios.items():
        for rule in ("mirror", "elastic"):
            for r in (0.01, 0.02):
                two = rng.uniform(0.5, 1.5, n_ics)
                row = {"table": table, "rule": rule, "radius": r, "ic": np.arange(n_ics),
                       "two_particle": two, "sticky": np.zeros(n_ics, bool)}
                for system in ("poisson", "actual", "poisson_scatter"):
                    row[system] = ratio * two * (1 + noise * rng.standard_normal(n_ics))
                rows.append(pd.DataFrame(row))
    return pd.concat(rows, ignore_index=True)


def test_against_circle_recovers_a_known_ratio_of_ratios():
    out = against_circle(_runs({"circle": 0.4, "stadium": 1.0, "ellipse": 0.41}))
    assert list(out.columns[:len(COLUMNS)]) == list(COLUMNS)
    st = out[(out["family"] == "tables_stadium") & (out["system"] == "poisson")]
    prim = st[st["control"] == "primary"].iloc[0]
    assert prim["estimate"] == pytest.approx(2.5, rel=0.03)
    assert prim["ci_low"] < 2.5 < prim["ci_high"]
    assert prim["verdict_at_margin"] == "higher" and prim["robust"]
    el = out[(out["family"] == "tables_ellipse") & (out["control"] == "primary")]
    assert (el["ci_low"] < 1.025 * 1.01).all() and (el["ci_high"] > 1.025 * 0.99).all()
    # every row's verdicts are its interval's
    for _, row in out.iterrows():
        assert row["verdict"] == ratio_verdict(row["ci_low"], row["ci_high"])
        assert row["verdict_at_margin"] == ratio_verdict(row["ci_low"], row["ci_high"],
                                                         tolerance=0.05)
    assert set(out["control"]) == {"primary", "sticky_excluded", "elastic"}
    assert _answer(out, "poisson") == "Yes"


def test_against_circle_without_an_effect_says_no_and_is_calibrated():
    """Same ratio in every table: the 95 % interval of the ratio of ratios covers 1 in
    about 95 % of 40 replicates (coverage of the independent-bootstrap quotient)."""
    covered, answers = 0, set()
    for seed in range(40):
        out = against_circle(_runs({"circle": 0.5, "stadium": 0.5}, n_ics=30, seed=seed,
                                   noise=0.2), n_boot=400)
        prim = out[(out["control"] == "primary") & (out["system"] == "poisson")].iloc[0]
        covered += prim["ci_low"] <= 1.0 <= prim["ci_high"]
        answers.add(_answer(out, "poisson"))
    assert 34 <= covered <= 40
    assert "Yes" not in answers or covered < 40


def test_the_focal_product_is_the_ellipse_s_integral_and_moves_with_the_radius():
    e = Ellipse(1.25, 0.8)
    d = focal_drift(e, [1e-9, 0.03], n_states=3, n_bounces=2000, seed=1)
    assert d["max_drift"].iloc[0] < 1e-8 < 1e-3 < d["max_drift"].iloc[1]   # O(r) at r = 1e-9
    # F at the centre moving along y: (0 - c)(1)(0 + c)(1) = -c^2
    c2 = 1.25 ** 2 - 0.8 ** 2
    assert focal_product(e, [0.0, 0.0], [0.0, 1.0])[0] == pytest.approx(-c2)


def test_the_free_disk_is_chaotic_only_in_the_stadium():
    states = free_runs({"circle": Circle(), "stadium": Stadium(1.0)}, [0.02], n_states=8,
                       horizon=1000.0, seed=3)
    free = free_ftle(states, horizon=1000.0, n_boot=200)
    c = free[free["table"] == "circle"].iloc[0]
    s = free[free["table"] == "stadium"].iloc[0]
    assert c["ftle"] < 2 * c["shear_scale"] == 2 * math.log(1000.0) / 1000.0
    assert 0.35 < s["ci_low"] <= s["ftle"] <= s["ci_high"] < 0.55


def test_scales():
    assert SCALES["paper"].n_ics == 200
    assert SCALES["paper"].n_steps * SCALES["paper"].tau == pytest.approx(5000.0)
    assert sorted(TABLES) == ["circle", "ellipse", "stadium"]
    with pytest.raises(ValueError, match="scale must be one of"):
        reproduce("unused", scale="huge")


@pytest.mark.full
def test_quick_page(tmp_path):
    page = reproduce(tmp_path, scale="quick", workers=1)
    text = page.read_text(encoding="utf-8")
    assert text.startswith("# The paper's comparison in the circle, the ellipse")
    assert "Generated " in text
    head = text.split("\n\n", 3)[2]
    answers = [ln for ln in head.splitlines() if ln.startswith("- ")]
    assert 1 <= len(answers) <= 5
    assert len(re.findall(r"\S+", text)) <= 2000
    found = pd.read_csv(page.parent / "tables_findings.csv")
    assert set(found["family"]) == {f"tables_{t}" for t in TABLES}
    assert {"primary", "elastic", "paired_median", "sticky_excluded"} <= set(found["control"])
    assert (page.parent / "tables.png").stat().st_size > 10_000
    free = pd.read_csv(page.parent / "tables_against_free.csv")
    assert set(free["table"]) == set(TABLES) and (free["estimate"] > 0).all()
    again = reproduce(tmp_path, scale="quick", workers=1)   # resumes: stores reused
    assert again == page


def test_against_free_recovers_a_known_ratio():
    from kicktimes.studies.tables import against_free

    runs = _runs({"circle": 0.5, "stadium": 0.9}, n_ics=50, noise=0.02)
    rng = np.random.default_rng(4)
    free = pd.concat([pd.DataFrame({"table": t, "radius": r, "state": np.arange(60),
                                    "ftle": base * (1 + 0.02 * rng.standard_normal(60))})
                      for t, base in (("circle", 0.25), ("stadium", 1.0)) for r in (0.01, 0.02)])
    out = against_free(runs, free, n_boot=400)
    two = out[(out["system"] == "two_particle") & (out["rule"] == "mirror")].set_index("table")
    # the two-disk FTLE is uniform on [0.5, 1.5]: mean 1
    assert two.loc["circle", "estimate"] == pytest.approx(4.0, rel=0.05)
    assert two.loc["stadium", "estimate"] == pytest.approx(1.0, rel=0.05)
    kick = out[(out["system"] == "poisson") & (out["rule"] == "mirror")].set_index("table")
    assert kick.loc["stadium", "estimate"] == pytest.approx(
        0.9 * two.loc["stadium", "estimate"], rel=0.02)
    assert kick.loc["stadium", "ci_low"] < kick.loc["stadium", "estimate"] \
        < kick.loc["stadium", "ci_high"]
    assert kick.loc["circle", "verdict_at_margin"] == "higher"
