"""The findings' controls: estimators on data with known answers, verdicts and robustness."""

import numpy as np
import pandas as pd
import pytest

from kicktimes.report.controls import (
    COLUMNS,
    answers,
    compute_controls,
    overview_table,
    paired_median,
)


def _frame(values_by_system, radii, n_ics):
    idx = pd.MultiIndex.from_product([radii, range(n_ics)], names=["radius", "ic"])
    rows = []
    for system, diag_values in values_by_system.items():
        for diagnostic, values in diag_values.items():
            for (r, i), v in zip(idx, values, strict=True):
                rows.append((r, i, system, diagnostic, float(v), ""))
    return pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value", "note"])


@pytest.mark.parametrize(("low", "high", "verdict"), [
    (0.95, 1.05, "within 10 %"), (0.9, 1.1, "within 10 %"), (0.3, 0.4, "differs"),
    (1.2, 1.5, "differs"), (0.85, 1.0, "inconclusive"), (np.nan, 1.0, "inconclusive"),
])
def test_the_band_verdict(low, high, verdict):
    from kicktimes.stats import ratio_verdict

    assert ratio_verdict(low, high) == verdict


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
    assert ftle.loc["sticky_excluded", "verdict"] == "within 10 %"
    assert not ftle["robust"].any()
    cell = overview_table(table).loc[0, "Poisson, scatter"]
    assert "✗ depends on paired_median" in cell
    counts = table[table["diagnostic"] == "counts"].set_index("control")
    assert counts.loc["sticky_excluded", "estimate"] == pytest.approx(1.0, abs=0.01)
    assert "3 sticky" not in counts.loc["primary", "detail"]
    assert counts.loc["sticky_excluded", "detail"].startswith("6 sticky")
    text = " ".join(answers(table))
    assert "Does any kick?" in text and "depends on" in text


# ------------------------------------------------------------- pooled shares, calibrated
def test_a_share_pooled_over_radii_gets_an_interval_clustered_on_ics():
    # every IC rejects at all 12 radii or at none: 12 x 200 runs are 200 independent
    # units, and the clustered interval is as wide as a binomial interval over 200
    from kicktimes.report.effects import clopper_pearson
    from kicktimes.report.poisson import clustered_share

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
    from kicktimes.report.effects import paired_ratio

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

    merged = merge_control_families([table("family_a", "differs"),
                                     table("family_a-elastic", "within 10 %"),
                                     table("family_b", "differs")])
    assert set(merged) == {"family_a", "family_b"}
    a = merged["family_a"]
    assert list(a["control"]) == ["primary", "paired_median", "elastic"]
    assert not a["robust"].any()  # the elastic rule changes the verdict
    assert a.loc[2, "detail"].startswith("from the experiment family_a-elastic")
    assert merged["family_b"]["robust"].all()
    # a control whose family is not there stays a family of its own
    alone = merge_control_families([table("family_c-elastic", "differs")])
    assert set(alone) == {"family_c-elastic"}
