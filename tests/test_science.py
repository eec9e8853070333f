"""analysis/science.py: the mechanism statements' estimators on data with known answers."""

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def science():
    spec = importlib.util.spec_from_file_location("science", REPO / "analysis" / "science.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_stretching_fit_recovers_known_slopes_and_their_ratio(science):
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
    fits, per_radius = science.stretching(results, n_boot=200)
    f = fits.set_index("system")
    assert f.loc["poisson", "slope"] == pytest.approx(0.9, rel=0.05)
    assert f.loc["two_particle", "slope"] == pytest.approx(2.0, rel=0.05)
    assert f.loc["poisson", "slope_ci_low"] < 0.9 < f.loc["poisson", "slope_ci_high"]
    assert f.loc["poisson", "slope_ratio"] == pytest.approx(0.45, rel=0.07)
    assert len(per_radius) == 3 * len(radii)


def test_one_perturbation_decorrelates_and_none_keeps_the_angle(science):
    table, by_angle = science.decorrelation(radii=(0.03,), n_ics=3, t_max=3000.0, n_boot=50)
    corr = table.set_index("perturbation")["correlation"]
    assert corr["no perturbation"] == pytest.approx(1.0)  # the wall conserves the angle
    assert abs(corr["uniform kick"]) < 0.2  # a uniform kick draws a new direction
    assert corr["disk-disk collision"] < 0.5
    assert set(by_angle["perturbation"]) == set(corr.index)


def test_twins_with_independent_kick_angles_separate_by_order_one_at_every_kick(science):
    # without kicks the twins of the integrable billiard barely separate; with independent
    # angles every kick throws the twin O(1) away: about ln(1/d0) nats per kick or more
    import math

    lam, rate, (low, high) = science.independent_angle_twin(0.05, n_ics=2, n_steps=400)
    assert low <= lam <= high
    assert lam / rate > math.log(1 / 2e-4) - 1.0
