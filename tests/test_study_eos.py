"""The equation-of-state study: its tables on runs with known answers, its runs, and its
quick page end to end."""

import math

import numpy as np
import pandas as pd
import pytest
from conftest import first_screen_answers

from kicktimes import stats
from kicktimes.studies.eos import (
    SCALES,
    eos_table,
    finite_size,
    frequency_table,
    halves_table,
    reference_margin,
    reproduce,
    run_cell,
)


def _runs(z_of, n=1000, states=8, noise=0.0, rng=0, packings=(0.2, 0.4, 0.6)):
    """Synthetic runs: each state's halves at ``z_of(phi) * (1 + noise e)``."""
    g = np.random.default_rng(rng)
    rows = []
    for phi in packings:
        for k in range(states):
            for half in (1, 2):
                z = z_of(phi) * (1 + noise * g.standard_normal())
                rows.append({"packing": phi, "n": n, "state": k, "half": half, "z": z,
                             "frequency": 2.0 * (1 + noise * g.standard_normal()),
                             "enskog": 2.0, "kT": 0.5, "n_pp": 1, "seconds": 0.0})
    return pd.DataFrame(rows)


def test_exact_runs_are_within_and_a_biased_one_is_not():
    exact = eos_table(_runs(lambda p: stats.kolafa_rottner_z(p) if p > 0.4 else
                            stats.virial_z(p), noise=1e-5))
    assert exact["verdict"].str.startswith("within 0.1").all()
    # 0.5 % high: higher than the series and Kolafa-Rottner alike
    high = eos_table(_runs(lambda p: 1.005 * stats.kolafa_rottner_z(p), noise=1e-5))
    assert (high["verdict"] == "higher").all() and (high["verdict_kr"] == "higher").all()
    # Henderson reads as what it is: higher than the exact Z by more than the margin at 0.6
    hend = eos_table(_runs(stats.henderson_z, noise=1e-5)).set_index("packing")
    assert hend.loc[0.6, "verdict"] == "higher" and hend.loc[0.2, "verdict"].startswith("within")


def test_intervals_are_three_standard_errors_over_the_states():
    runs = _runs(lambda p: 2.0, noise=1e-3, packings=(0.3,))
    t = eos_table(runs).iloc[0]
    per_state = runs.groupby("state")["z"].mean()
    se = per_state.std(ddof=1) / math.sqrt(len(per_state))
    assert t["z"] == pytest.approx(per_state.mean())
    assert t["z_high"] - t["z"] == pytest.approx(3 * se)
    assert t["states"] == 8


def test_noisy_runs_are_inconclusive_not_within():
    t = eos_table(_runs(stats.kolafa_rottner_z, noise=0.01))
    assert (t["verdict"] == "inconclusive").all()


def test_frequency_finite_size_and_halves():
    runs = pd.concat([_runs(stats.kolafa_rottner_z, n=1000, noise=1e-5),
                      _runs(lambda p: 1.01 * stats.kolafa_rottner_z(p), n=100, noise=1e-5)])
    f = frequency_table(runs)
    assert (f["verdict"] == "within 0.1 %").all()
    size = finite_size(runs, 1000)
    assert list(size["n"].unique()) == [100]
    assert size["ratio"].to_numpy() == pytest.approx(1.01, abs=1e-4)
    assert (size["verdict"] == "higher").all()
    drift = runs.copy()
    drift.loc[drift["half"] == 2, "z"] *= 0.99
    h = halves_table(drift)
    assert h["ratio"].to_numpy() == pytest.approx(0.99, abs=1e-4)
    assert (h["verdict"] == "lower").all()


def test_coverage_pooling_and_the_states_to_resolve():
    from kicktimes.studies.eos.tables import coverage, pooled, states_to_resolve

    assert coverage(8) == pytest.approx(0.980, abs=1e-3)
    assert coverage(10**6) == pytest.approx(0.9973, abs=1e-4)
    frame = pd.DataFrame({"n": [10, 10], "ratio": [1.001, 1.003], "se": [0.001, 0.002]})
    p = pooled(frame).iloc[0]
    # inverse-variance weights 4 : 1
    assert p["ratio"] == pytest.approx((4 * 1.001 + 1.003) / 5)
    assert p["se"] == pytest.approx(1 / math.sqrt(1e6 + 2.5e5))
    # at an estimate 0 off, 3 se = 1.5 margins: (1.5)^2 = 2.25 times the states
    assert states_to_resolve(1.0, 0.0005, 8, 0.001) == 18
    assert math.isnan(states_to_resolve(1.0011, 0.0001, 8, 0.001))
    assert states_to_resolve(1.0, 1e-6, 8, 0.001) == 8


def test_the_frequency_prediction_counts_the_degrees_of_freedom():
    f = frequency_table(_runs(stats.kolafa_rottner_z, n=1000, noise=1e-5))
    assert f["dof_prediction"].to_numpy() == pytest.approx(math.sqrt(999 / 1000))


def test_margins():
    assert reference_margin("virial", 0.4) == stats.EOS_MARGIN
    assert reference_margin("kolafa_rottner", 0.5) == pytest.approx(stats.EOS_MARGIN + 1e-5)
    assert reference_margin("kolafa_rottner", 0.68) == pytest.approx(stats.EOS_MARGIN + 1e-4)
    with pytest.raises(ValueError, match="reference must be"):
        reference_margin("henderson", 0.3)


def test_a_cell_of_real_runs():
    """Two small states at packing 0.3: the halves, a Z near the reference (2 %: a few
    collisions per disk) and the frequency identity near 1."""
    t = run_cell(0.3, 200, 2, 10.0, 40.0, seed=5)
    assert list(t["half"]) == [1, 2, 1, 2] and (t["n"] == 200).all()
    assert t["z"].mean() == pytest.approx(stats.kolafa_rottner_z(0.3), rel=0.02)
    assert (t["frequency"] / t["enskog"]).mean() == pytest.approx(1.0, rel=0.02)
    assert t["kT"].to_numpy() == pytest.approx(0.5, rel=1e-9)


def test_the_quick_page(tmp_path):
    page = reproduce(tmp_path / "work", scale="quick", results_dir=tmp_path / "results",
                     workers=1)
    text = page.read_text(encoding="utf-8")
    assert text.startswith("# The N-disk engine's equation of state") and "Generated " in text
    answers = first_screen_answers(page)
    assert len(answers) == 5
    for name in ("eos_eos.csv", "eos_frequency.csv", "eos_finite_size.csv", "eos_halves.csv",
                 "eos_pooled.csv", "eos_runs.csv", "eos.png"):
        assert (tmp_path / "results" / name).exists(), name
    eos = pd.read_csv(tmp_path / "results" / "eos_eos.csv")
    assert set(eos["n"]) == set(SCALES["quick"].sizes)
    assert len(eos) == len(SCALES["quick"].packings) * len(SCALES["quick"].sizes)
    # a rerun reuses every cell
    again = reproduce(tmp_path / "work", scale="quick", results_dir=tmp_path / "results",
                      workers=1)
    assert again == page
