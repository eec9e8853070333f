"""kicktimes.studies.science and .mechanism: the mechanism statements' estimators on data
with known answers."""

import numpy as np
import pandas as pd
import pytest

from kicktimes.stats import margin_of, ratio_verdict


@pytest.fixture(scope="module")
def science():
    from kicktimes.studies import science as module

    return module


def test_the_stretching_per_radius_gives_the_ratio_its_verdict_and_its_trend(science):
    # per-IC FTLE built so that lambda / rate = a + b ln(1/r) exactly (rate 0.1 everywhere)
    radii = [0.002, 0.005, 0.01, 0.03]
    coef = {"two_particle": (-2.5, 2.0), "poisson": (-1.8, 0.9), "poisson_scatter": (-2.8, 2.0)}
    rng = np.random.default_rng(0)
    rows = []
    for r in radii:
        for ic in range(30):
            for system, (a, b) in coef.items():
                s = (a + b * np.log(1 / r)) * rng.uniform(0.9, 1.1)
                n_name = "n_pp" if system == "two_particle" else "n_kicks"
                rows += [(r, ic, system, "lyapunov", 0.1 * s), (r, ic, system, "t_max", 1000.0),
                         (r, ic, system, n_name, 100.0)]
    results = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])
    per_radius, fits, trend = science.stretching(results, n_boot=200)
    f = fits.set_index("system")
    assert f.loc["poisson", "slope"] == pytest.approx(0.9, rel=0.05)
    assert f.loc["two_particle", "intercept"] == pytest.approx(-2.5, abs=0.3)
    assert f.loc["poisson", "slope_ci_low"] < 0.9 < f.loc["poisson", "slope_ci_high"]
    kicked = per_radius[per_radius["system"] == "poisson"].set_index("radius")
    x = np.log(1 / kicked.index.to_numpy())
    np.testing.assert_allclose(kicked["ratio"], (-1.8 + 0.9 * x) / (-2.5 + 2.0 * x), rtol=0.05)
    for row in per_radius.dropna(subset=["ratio"]).itertuples():
        assert row.ci_low <= row.stretch_per_perturbation <= row.ci_high
        assert row.verdict == ratio_verdict(row.ratio_ci_low, row.ratio_ci_high,
                                            tolerance=margin_of("ftle"))
    t = trend.set_index(["system", "quantity"])
    assert t.loc[("poisson", "ratio"), "verdict"] == "rises"      # 0.30 -> 0.38
    assert t.loc[("poisson", "abs_log_ratio"), "verdict"] == "falls"
    assert len(per_radius) == 3 * len(radii)


def test_the_prediction_is_set_beside_the_store_s_measurement(science, tmp_path):
    by_radius = pd.DataFrame({
        "family": "fam", "diagnostic": "one_minus_r1", "system": ["poisson", "poisson_scatter"],
        "control": "primary", "radius": 0.01, "n_pairs": 200, "ratio": [0.77, 0.99],
        "ci_low": [0.72, 0.96], "ci_high": [0.82, 1.02]})
    by_radius.to_csv(tmp_path / "fam_findings_by_radius.csv", index=False)
    preds = pd.DataFrame({"rule": "mirror", "radius": 0.01,
                          "system": ["poisson", "poisson_scatter"],
                          "predicted": [0.88, 1.0], "predicted_ci_low": [0.86, 0.98],
                          "predicted_ci_high": [0.90, 1.02]})
    out = science.prediction_against_measurement(preds, tmp_path, {"mirror": "fam"}).set_index(
        "system")
    assert out.loc["poisson", "measured_over_predicted"] == pytest.approx(0.77 / 0.88)
    assert out.loc["poisson", "quotient_verdict"] == "inconclusive"   # 0.875 straddles 0.9
    assert out.loc["poisson_scatter", "quotient_verdict"] == "within 10 %"
    assert out.loc["poisson", "measured_verdict"] == "lower"
    with pytest.raises(ValueError, match="findings_dir"):
        science.prediction_against_measurement(preds, tmp_path, {"mirror": "missing"})


def test_a_law_comes_closest_only_when_its_distance_interval_is_clear(science, tmp_path):
    rows = [("poisson", 0.32, 0.31, 0.33), ("actual", 0.30, 0.29, 0.31),
            ("poisson_scatter", 0.97, 0.93, 1.02), ("actual_scatter", 0.92, 0.89, 0.96)]
    table = pd.DataFrame([{"family": "fam", "diagnostic": "ftle", "system": s,
                           "control": "primary", "estimate": e, "ci_low": lo, "ci_high": hi,
                           "verdict": ratio_verdict(lo, hi)} for s, e, lo, hi in rows])
    table.to_csv(tmp_path / "fam_findings.csv", index=False)
    out = science.closest_kick_law(tmp_path, ["fam"], diagnostics=("ftle",)).set_index("system")
    assert out["closest"].to_dict() == {"poisson": False, "actual": False,
                                        "poisson_scatter": True, "actual_scatter": True}
    assert (out.loc[out["closest"], "disjoint_under"] == "").all()
    # overlap under the primary is not agreement: a control under which the two scatter
    # laws' intervals are disjoint is named
    control = table.assign(control="paired_median")
    control.loc[control["system"] == "actual_scatter", ["ci_low", "ci_high"]] = (0.90, 0.92)
    control.loc[control["system"] == "poisson_scatter", ["ci_low", "ci_high"]] = (0.95, 1.0)
    pd.concat([table, control]).to_csv(tmp_path / "fam_findings.csv", index=False)
    out = science.closest_kick_law(tmp_path, ["fam"], diagnostics=("ftle",)).set_index("system")
    assert out.loc["actual_scatter", "disjoint_under"] == "paired_median"
    assert out.loc["poisson_scatter", "disjoint_under"] == ""


def test_one_perturbation_decorrelates_and_none_keeps_the_angle(science):
    table, by_angle, predicted = science.decorrelation(radii=(0.03,), n_ics=3, t_max=3000.0,
                                                       n_boot=50)
    corr = table.set_index("perturbation")["correlation"]
    assert corr["no perturbation"] == pytest.approx(1.0)  # the wall conserves the angle
    assert abs(corr["uniform kick"]) < 0.2  # a uniform kick draws a new direction
    assert corr["disk-disk collision"] < 0.5
    assert set(by_angle["perturbation"]) == set(corr.index)
    pred = predicted.set_index("system")["predicted"]
    assert pred["poisson"] == pytest.approx((1 - corr["uniform kick"])
                                            / (1 - corr["disk-disk collision"]))


def test_twins_with_independent_kick_angles_separate_by_order_one_at_every_kick(science):
    # without kicks the twins of the integrable billiard barely separate; with independent
    # angles every kick throws the twin O(1) away: about ln(1/d0) nats per kick or more
    import math

    lam, rate, (low, high) = science.independent_angle_twin(0.05, n_ics=2, n_steps=400)
    assert low <= lam <= high
    assert lam / rate > math.log(1 / 2e-4) - 1.0


def test_the_out_of_sample_rate_chain_keeps_the_order_of_its_training_states():
    from kicktimes.studies import mechanism as mech

    # training runs alternate a slow and a fast state: the chain must alternate too
    first = np.array([1.0, 1.0, 1.0])
    post = [np.tile([10.0, 1.0], 20) for _ in first]
    chain = mech.fit_rate_chain(first, post, n_bins=4)
    paths = mech.draw_rate_chains(chain, np.array([1.0, 10.0]), 50, np.random.default_rng(0))
    assert paths.shape == (2, 51)
    np.testing.assert_array_equal(paths[:, 0], [1.0, 10.0])
    np.testing.assert_array_equal(paths[0, 1::2], 10.0)
    np.testing.assert_array_equal(paths[0, 2::2], 1.0)
