"""The disks page's controls, renewal models, scatter-kicked system and FTLE-check section
(issue 42, "left out" closed): the verdict logic on synthetic numbers, the wording of a
robust finding and of one that depends on a control, and the sections written from tables.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pandas as pd
import pytest

from kicktimes.experiment import (
    DISKS_CONTROLS,
    DISKS_PRESETS,
    DisksExperiment,
    disks_control,
    run_experiment,
)
from kicktimes.stats import share_ratio_sample_size
from kicktimes.studies.disks.controls import controls_findings, controls_lines, robust_text

TINY = DisksExperiment(name="tiny-gas", n_disks=[2, 5], packing=0.1, n_tagged=6, min_runs=3,
                       collisions=5, block_sequences=2, seed=3)


def run_quiet(exp, path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_experiment(exp, path, progress=False, workers=1)


def _table(n=1000, d=(0.2, 0.15, 0.25, "above its null"),
           share=(0.005, -0.004, 0.009, "at its null"), p=1e-5,
           first=(-0.08, -0.14, -0.02, "inconclusive"), rate=(1.01, 1.005, 1.012,
                                                               "within 1.5 %")):
    """A control's row: D, the KS share and the first hazard bin as differences from their
    own null (`versus_null`'s ``<s>_diff`` and ``<s>_verdict``), the rate as a ratio."""
    row = {"geometry": "packing 0.02", "rule": "mirror", "n_disks": n,
           "hazard_flat_pvalue": p}
    for key, (est, lo, hi, v) in (("d", d), ("ks", share), ("hazard_first", first)):
        row.update({f"{key}_diff": est, f"{key}_diff_low": lo, f"{key}_diff_high": hi,
                    f"{key}_verdict": v})
    est, lo, hi, v = rate
    row.update({"rate_enskog": est, "rate_enskog_low": lo, "rate_enskog_high": hi,
                "rate_enskog_verdict": v})
    return pd.DataFrame([row])


def _group(long, finding):
    return long[long["diagnostic"] == finding]


def test_a_finding_with_the_same_verdict_under_every_control_is_robust():
    long = controls_findings({"primary": _table(), "seed": _table(),
                              "k60": _table(d=(0.3, 0.2, 0.4, "above its null"))})
    g = _group(long, "D − null D")
    assert g["robust"].all() and list(g["control"]) == ["primary", "seed", "k60"]
    assert robust_text(g) == "robust: above its null"


def test_a_finding_whose_verdict_changes_depends_on_that_control_with_both_numbers():
    long = controls_findings({"primary": _table(), "seed": _table(),
                              "k60": _table(share=(0.03, 0.02, 0.04, "above its null"))})
    g = _group(long, "KS share − null")
    assert not g["robust"].any() and set(g["depends_on"]) == {"k60"}
    text = robust_text(g)
    assert text.startswith("depends on k60: ")
    assert "+0.005 [−0.004, +0.009] at its null (primary)" in text
    assert "+0.030 [+0.020, +0.040] above its null (k60)" in text
    assert "(seed)" not in text  # the controls that agree are not listed


def test_a_change_of_direction_alone_is_not_robust():
    # both inconclusive, one interval above the null and the other below it
    long = controls_findings({"primary": _table(first=(0.08, 0.02, 0.14, "inconclusive")),
                              "bulk": _table(first=(-0.07, -0.12, -0.02, "inconclusive"))})
    g = _group(long, "hazard first bin − null")
    assert not g["robust"].any() and set(g["reason"]) == {"direction"}
    assert robust_text(g).startswith("depends on bulk: +0.080 [+0.020, +0.140] inconclusive "
                                     "(primary)")


def test_the_hazard_flatness_verdict_is_its_p_value_and_bulk_is_no_control_of_the_rate():
    long = controls_findings({"primary": _table(p=1e-5), "bulk": _table(p=0.3)})
    g = _group(long, "hazard flatness")
    assert list(g["verdict"]) == ["flatness rejected", "flatness not rejected"]
    assert g["ci_low"].isna().all()
    assert "p = 1e-05 flatness rejected (primary)" in robust_text(g)
    assert list(_group(long, "rate / Enskog")["control"]) == ["primary"]
    # the page names, per finding, only the controls run for it: no bulk for the rate
    text = "\n".join(controls_lines(controls_findings(
        {"primary": _table(), "seed": _table(), "bulk": _table()})))
    assert "D − null D, KS share − null, hazard first bin − null: seed, bulk" in text
    assert "rate / Enskog: seed)" in text


def test_the_controls_section_counts_robust_and_dependent_findings():
    long = controls_findings({"primary": _table(), "seed": _table(), "k60": _table(
        share=(0.03, 0.02, 0.04, "above its null"))})
    text = "\n".join(controls_lines(long))
    assert "## Under the controls" in text
    # the hazard's flatness is not read on the page: 4 findings, not 5
    assert "Of the 4 findings at N ≥ 30, 3 are robust and 1 depend on a control" in text
    assert "(seed: 0, k60: 1)" in text
    assert "The replicate alone (another seed, the same design) changes 0 of 4" in text


def test_the_controls_table_is_lint_clean(tmp_path):
    long = controls_findings({"primary": _table(), "seed": _table(d=(0.05, -0.01, 0.09,
                                                                     "inconclusive"))})
    d = long[long["diagnostic"] == "D − null D"]
    assert set(d["verdict"]) == {"above its null", "inconclusive"} and not d["robust"].any()
    assert {"family", "diagnostic", "system", "control", "estimate", "ci_low", "ci_high",
            "verdict", "robust"} <= set(long.columns)


def test_the_controls_are_presets_of_their_own_that_keep_the_sweeps_hashes():
    assert disks_control("disks-phi0.2-mirror-k60") == ("disks-phi0.2-mirror", "k60")
    assert disks_control("disks-phi0.2-mirror") is None
    sweeps = {n for n, e in DISKS_PRESETS.items() if not e.kicked_runs and len(e.n_disks) > 1}
    assert {disks_control(n)[0] for n in DISKS_CONTROLS} == sweeps
    for name, exp in DISKS_CONTROLS.items():
        base = DISKS_PRESETS[disks_control(name)[0]]
        changed = {f.name for f in dataclasses.fields(exp)
                   if getattr(exp, f.name) != getattr(base, f.name)}
        assert changed <= {"name", "seed", "collisions", "description", "boundary", "n_disks"}
        assert exp.seed != base.seed
        # the box is the only control with other disk numbers: N = 2 left out
        if exp.boundary == "box":
            assert exp.n_disks == tuple(n for n in base.n_disks if n >= 3)
        else:
            assert exp.n_disks == base.n_disks
    # a circle sweep's hash is the one it had before the box existed
    assert DISKS_PRESETS["disks-phi0.2-elastic"].hash() == "775d19c3f9da73ab"
    with pytest.raises(ValueError, match="kicked_runs"):
        dataclasses.replace(TINY, boundary="box", kicked_runs=1)
    with pytest.raises(ValueError, match="boundary"):
        dataclasses.replace(TINY, boundary="square")
    # the kicked systems' field leaves the hash of a store without it unchanged
    assert dataclasses.replace(TINY, kicked_systems=("poisson", "actual")).hash() == TINY.hash()
    k = dataclasses.replace(TINY, kicked_runs=1)
    assert dataclasses.replace(k, kicked_systems=("poisson", "actual", "scatter")).hash() \
        != k.hash()
    with pytest.raises(ValueError, match="kicked_systems"):
        dataclasses.replace(TINY, kicked_systems=("poisson", "poisson"))


def test_the_gas_ftle_method_is_in_the_hash_only_when_the_kicked_comparison_uses_it():
    # without the kicked comparison the method is unused: no hash changes
    assert dataclasses.replace(TINY, gas_ftle="twin").hash() == TINY.hash()
    k = dataclasses.replace(TINY, kicked_runs=1)
    twin = dataclasses.replace(k, gas_ftle="twin")
    assert k.gas_ftle == "tangent" and k.hash() != twin.hash()
    # a record from before the field (a twin's store) reads back as the twin, same hash
    old = twin.to_dict()
    del old["gas_ftle"]
    back = type(TINY).from_record(old)
    assert back.gas_ftle == "twin" and back.hash() == twin.hash()
    assert type(TINY).from_record(k.to_dict()) == k
    with pytest.raises(ValueError, match="gas_ftle"):
        dataclasses.replace(k, gas_ftle="benettin")


def test_the_sample_size_of_a_share_ratio_gives_its_power():
    p, n = 0.08, share_ratio_sample_size(0.08)
    rng = np.random.default_rng(0)
    a, b = rng.binomial(n, p, size=4000) / n, rng.binomial(n, p, size=4000) / n
    se = np.sqrt((1 - a) / (n * a) + (1 - b) / (n * b))
    lo, hi = np.exp(np.log(a / b) - 1.96 * se), np.exp(np.log(a / b) + 1.96 * se)
    power = np.mean((lo >= 0.9) & (hi <= 1.1))
    # at least the power asked for (the band's lower side is the wider)
    assert 0.8 <= power <= 0.88
    assert share_ratio_sample_size(0.3) < n < share_ratio_sample_size(0.02)
    with pytest.raises(ValueError, match="share"):
        share_ratio_sample_size(0.0)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return run_quiet(TINY, tmp_path_factory.mktemp("tiny"))


def test_the_bulk_control_keeps_the_tagged_disks_that_start_near_the_centre(tiny):
    from kicktimes.experiment.disks_tasks import tagged_start_radii
    from kicktimes.studies.disks.tables import bulk_rows, disks_table

    keep = bulk_rows(tiny, 0.5)
    col = tiny.collisions
    for m, row in enumerate(col.itertuples(index=False)):
        tagged, radii = tagged_start_radii(tiny.experiment, row.n_disks, row.ic)
        assert keep[m] == (radii[list(tagged).index(row.disk)] <= 0.5)
    assert 0 < keep.sum() < len(col)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bulk = disks_table(tiny, n_boot=99, n_mc=19, within=0.5)
    assert (bulk["n_tagged"].sum()) == keep.sum()


def test_renewal_models_rank_gamma_intervals_gamma_and_check_the_halves():
    from types import SimpleNamespace

    from kicktimes.studies.disks.renewal import renewal_lines, renewal_models

    rng = np.random.default_rng(2)
    exp = DisksExperiment(name="x", n_disks=[10], packing=0.1, collisions=20)
    col = pd.DataFrame({"n_disks": 10, "ic": np.arange(600) % 12,
                        "pp_times": [np.cumsum(rng.gamma(3.0, size=25)) for _ in range(600)]})
    t = renewal_models(SimpleNamespace(experiment=exp, collisions=col))
    row = t.iloc[0]
    assert row["best"] == "gamma" and row["n_intervals"] == 600 * 20
    assert row["delta_aic_exponential"] > 100 and row["stable"]
    text = "\n".join(renewal_lines(t))
    assert "not independent" in text and "| 10 | gamma; exp. ΔAIC" in text


def test_the_scatter_kicked_system_is_compared_with_the_gas(tmp_path):
    from kicktimes.studies.disks.kicked import kicked_ftle_cells, kicked_section
    from kicktimes.studies.disks.tables import kicked_table

    exp = dataclasses.replace(TINY, name="tiny-scatter", kicked_runs=3, kicked_time=20.0,
                              kicked_systems=("poisson", "actual", "scatter"))
    store = run_quiet(exp, tmp_path / "k")
    rows = store.results[store.results["system"] == "scatter"]
    assert set(rows["diagnostic"]) == {"ftle", "acf@1", "rr"}
    assert len(rows) == 3 * 3 * 2  # diagnostics x runs x N
    tab = kicked_table(store, n_boot=99)
    sc = tab[(tab["system"] == "scatter/gas") & (tab["diagnostic"] == "ftle")]
    assert len(sc) == 2 and sc["verdict"].notna().all()
    # a scattered disk keeps the deviation of its direction: its FTLE is positive
    assert (sc["value"] > 0).all()
    cells = kicked_ftle_cells(tab, 5)
    assert len(cells) == 2 and cells[0].startswith("Poisson-kicked ") and "; gas " in cells[0]
    text = "\n".join(kicked_section(tab, exp))
    assert "**FTLE λ over the gas's** (no verdict" in text and "collision kernel" in text


def test_the_ftle_check_section_is_rendered_from_its_table_or_skipped(tmp_path):
    from kicktimes.studies.disks.kicked import ftle_check_lines

    path = tmp_path / "disks_ftle_check.csv"
    lines = ftle_check_lines(path)
    assert lines[0].startswith("## The gas's FTLE: tangent vectors against a twin")
    assert lines[2].startswith("Not run here: no disks_ftle_check.csv")
    pd.DataFrame([
        {"check": "tangent/twin", "n_disks": 100, "rule": "mirror", "packing": 0.02,
         "n_ics": 8, "t_max": 50.0, "estimate": 1.003, "lo": 0.991, "hi": 1.012,
         "margin": 0.02, "verdict": "within 2 %"},
        {"check": "engine/two-disk", "n_disks": 2, "rule": "mirror", "packing": 0.02,
         "n_ics": 16, "t_max": 200.0, "estimate": 1.06, "lo": 1.01, "hi": 1.11,
         "margin": 0.05, "verdict": "inconclusive"},
        {"check": "tangent/twin", "n_disks": 2, "rule": "mirror", "packing": 0.02,
         "n_ics": 8, "t_max": 50.0, "estimate": 1.0, "lo": 0.97, "hi": 1.03,
         "margin": 0.02, "verdict": "pass"},
    ]).to_csv(path, index=False)
    text = "\n".join(ftle_check_lines(path))
    assert "| tangent/twin (0.02) | 100 | mirror | 8 | 50 | 1.00 [0.991, 1.01] | 0.02 | " \
           "within 2 % |" in text
    assert "| engine/two-disk (0.02) | 2 | mirror | 16 | 200 | 1.06 [1.01, 1.11] | 0.05 | " \
           "inconclusive |" in text
    # the page's verdict is the rule's, the file's other word beside it
    assert "| inconclusive (the file: pass) |" in text
    pd.DataFrame([{"check": "x"}]).to_csv(path, index=False)
    with pytest.raises(ValueError, match="missing columns"):
        ftle_check_lines(path)


def test_the_page_gives_every_finding_under_its_controls(tiny, tmp_path):
    from kicktimes.studies.disks.page import write_disks_page

    control = run_quiet(dataclasses.replace(TINY, name="tiny-gas-seed", seed=4),
                        tmp_path / "seed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        page = write_disks_page([tiny.path, control.path], tmp_path / "results", n_boot=99,
                                n_mc=19, dpi=30)
    text = page.read_text()
    long = pd.read_csv(tmp_path / "results" / "disks_controls.csv")
    # not a sweep report's findings table (tests/test_results_pages.py reads *_findings.csv)
    assert not list((tmp_path / "results").glob("*_findings.csv"))
    assert set(long["control"]) == {"primary", "seed", "bulk"}
    assert "## Under the controls" in text and "[disks_controls.csv]" in text
    assert (tmp_path / "results" / "disks_renewal.csv").exists()
    # D, the KS share and the first hazard bin are read under every control against their
    # own null: differences with the null's verdicts
    d = long[long["diagnostic"] == "D − null D"]
    assert set(d["verdict"]) <= {"at its null", "above its null", "below its null",
                                 "inconclusive"}
    assert "count dispersion D" not in set(long["diagnostic"])
    # the replicate's D against the primary's null, in the answers' table
    answers = pd.read_csv(tmp_path / "results" / "disks_poisson.csv")
    assert answers["replicate_diff"].notna().all()
    assert set(answers["answer"]) <= {"Poisson", "not Poisson", "not resolved"}


def test_the_kicked_rate_is_the_whole_gas_collision_frequency():
    # issue 50: the kicks' rate (and lambda / nu) is the gas's 2 n_pp / (N T), the rate of
    # disks.csv, not the followed disk's own n / T
    from kicktimes.billiard import initial_state, simulate_disks
    from kicktimes.experiment.disks_tasks import kicked_rate, kicked_rows

    exp = dataclasses.replace(TINY, n_disks=[6], kicked_runs=1, kicked_time=20.0)
    assert exp.kicked_rate == "gas"
    rows = {(s, d): v for s, d, v in kicked_rows(exp, 6, 0)}
    # the same gas run, redrawn from the run's seed as kicked_rows draws it
    rng = np.random.default_rng(np.random.SeedSequence(exp.seed, spawn_key=(6, 0, 1)))
    r = exp.radius(6)
    state = initial_state(6, r, rng=rng, rule="mirror")
    tau = 0.1 / exp.reference_frequency(6)
    gas = simulate_disks(state, r, t_max=int(round(20.0 / 0.1)) * tau, rule="mirror",
                         sample=[0], tau=tau, log_walls=True)
    assert rows["gas", "rate"] == pytest.approx(gas.collision_frequency, rel=1e-12)
    assert rows["gas", "rate"] == pytest.approx(2 * gas.n_pp / (6 * gas.t_max), rel=1e-12)
    own = gas.collision_times(0).size / gas.t_max
    assert own != pytest.approx(gas.collision_frequency, rel=1e-6)
    disk = dataclasses.replace(exp, kicked_rate="disk")
    assert kicked_rate(disk, gas, gas.collision_times(0)) == own


def test_the_kicked_rate_is_in_the_hash_and_old_records_read_as_the_disk_rate():
    k = dataclasses.replace(TINY, kicked_runs=1)
    disk = dataclasses.replace(k, kicked_rate="disk")
    assert k.hash() != disk.hash()
    assert dataclasses.replace(TINY, kicked_rate="disk").hash() == TINY.hash()
    old = disk.to_dict()
    del old["kicked_rate"]
    back = type(TINY).from_record(old)
    assert back.kicked_rate == "disk" and back.hash() == disk.hash()
    with pytest.raises(ValueError, match="kicked_rate"):
        dataclasses.replace(k, kicked_rate="tagged")


def test_the_null_streams_are_shaped_like_the_runs_and_calibrate_the_tests(tmp_path):
    from kicktimes.studies.disks.null import calibration_rows, null_rows, null_streams

    exp = dataclasses.replace(TINY, name="tiny-elastic", rule="elastic", n_disks=[5],
                              n_tagged=40, collisions=10)
    store = run_quiet(exp, tmp_path / "e")
    res, col = null_streams(store, 5, "dilute", np.random.default_rng(0))
    assert col[["ic", "disk", "t_window"]].equals(store.collisions[["ic", "disk", "t_window"]])
    assert all(s.size == t.size + 1 for t, s in zip(col["pp_times"], col["speeds"],
                                                      strict=True))
    _, pois = null_streams(store, 5, "poisson", np.random.default_rng(0))
    assert all(np.isnan(s).all() for s in pois["speeds"])
    with pytest.raises(ValueError, match="design"):
        null_streams(store, 5, "cox", np.random.default_rng(0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        table = null_rows(store, n_boot=99, n_mc=19)
    assert table["design"].tolist() == ["poisson", "dilute"]
    assert (table["n_runs"] == store.results["ic"].nunique()).all()
    rows = calibration_rows(table)
    assert set(rows["design"]) == {"poisson", "dilute"}
    assert rows["test"].str.endswith("speed-rescaled").any()
    assert ((rows["ci_low"] <= rows["value"]) & (rows["value"] <= rows["ci_high"])).all()
    assert (rows["n_clusters"] == store.results["ic"].nunique()).all()
    # the null values a page reads its statistics against, beside the rejection shares
    assert {"rejection share", "D", "hazard, first bin", "hazard, highest bin",
            "gamma shape"} == set(rows["statistic"])
    d = rows[(rows["statistic"] == "D") & (rows["design"] == "poisson")].iloc[0]
    assert d["value"] == table.set_index("design").loc["poisson", "dispersion"]
    assert d["test"] == "" and d["n_runs"] > 0


def test_the_walls_share_of_d_minus_one_is_read_only_outside_its_noise():
    from kicktimes.studies.disks.controls import wall_share_lines, wall_shares

    def rows(ds):
        return pd.DataFrame([{"geometry": "packing 0.2", "rule": "mirror", "n_disks": n,
                              "dispersion": d, "dispersion_low": d - w,
                              "dispersion_high": d + w} for n, d, w in ds])

    circle = rows([(10, 1.4, 0.05), (30, 1.4, 0.05), (100, 1.40, 0.05), (300, 1.02, 0.05),
                   (1000, 1.4, 0.02)])
    box = rows([(30, 1.2, 0.05), (100, 1.40, 0.05), (300, 1.0, 0.05), (1000, 0.9, 0.02)])
    s = wall_shares(circle, box).set_index("n_disks")
    assert list(s.index) == [30, 100, 300, 1000]  # N >= 30 with both
    assert s.loc[30, "share"] == pytest.approx(0.5)
    assert s.loc[30, "reading"].endswith("part of it")
    assert s.loc[100, "reading"].endswith("no wall share detected")
    assert s.loc[300, "reading"].endswith("not decomposed (D's interval reaches 1)")
    assert s.loc[1000, "reading"].endswith("more than all (the box lies below Poisson)")
    lines = wall_share_lines(s.reset_index())
    assert lines[0].startswith("## What the wall makes")
    assert sum(x.startswith("| packing 0.2") for x in lines) == 4
