"""The gap decomposition: shares of the kicked-versus-two-disk gap each kick ingredient closes."""

import numpy as np
import pandas as pd
import pytest

from kicktimes.report.decomposition import LADDER, STEPS, gap_decomposition, gap_figure


def _store(values, n_ics=30, radii=(0.01, 0.02), noise=0.0, seed=0):
    rng = np.random.default_rng(seed)
    rows = []
    for r in radii:
        for i in range(n_ics):
            for system, v in values.items():
                for diagnostic in ("lyapunov", "autocorrelation"):
                    x = v * (1.0 + noise * rng.standard_normal())
                    if diagnostic == "autocorrelation":
                        x = 1.0 - x  # 1 - R1 is the compared quantity
                    rows.append((r, i, system, diagnostic, x))
    res = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])
    col = pd.DataFrame([(r, i, 1000.0, 16) for r in radii for i in range(n_ics)],
                       columns=["radius", "ic", "t_window", "n_pp"])
    return res, col


def test_shares_of_a_known_ladder_and_they_sum_to_one():
    res, col = _store({"two_particle": 1.0, "poisson": 0.25, "poisson_scatter": 0.5,
                       "poisson_kinetic": 0.8})
    tab = gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(1),
                            n_boot=100)
    prim = tab[(tab["control"] == "primary") & (tab["diagnostic"] == "ftle")]
    est = prim.set_index("quantity")["estimate"]
    assert est["ratio poisson"] == pytest.approx(0.25)
    g = np.abs(np.log([0.25, 0.5, 0.8]))
    assert est[STEPS[0]] == pytest.approx((g[0] - g[1]) / g[0])
    assert est[STEPS[1]] == pytest.approx((g[1] - g[2]) / g[0])
    assert est[STEPS[2]] == pytest.approx(g[2] / g[0])
    assert est[list(STEPS)].sum() == pytest.approx(1.0)
    assert set(tab["control"]) == {"primary", "paired_median", "sticky_excluded"}
    assert set(tab["diagnostic"]) == {"ftle", "one_minus_r1"}


def test_intervals_cover_the_estimate_and_widen_with_noise():
    quiet = gap_decomposition(*_store({"two_particle": 1.0, "poisson": 0.3,
                                       "poisson_scatter": 0.9, "poisson_kinetic": 0.9},
                                      noise=0.05), family="f", eps=(),
                              rng=np.random.default_rng(2), n_boot=300)
    loud = gap_decomposition(*_store({"two_particle": 1.0, "poisson": 0.3,
                                      "poisson_scatter": 0.9, "poisson_kinetic": 0.9},
                                     noise=0.4), family="f", eps=(),
                             rng=np.random.default_rng(2), n_boot=300)
    key = (quiet["control"] == "primary") & (quiet["quantity"] == STEPS[0])
    q, lo = quiet[key].iloc[0], loud[key.to_numpy()].iloc[0]
    assert q["ci_low"] <= q["estimate"] <= q["ci_high"]
    assert (lo["ci_high"] - lo["ci_low"]) > (q["ci_high"] - q["ci_low"])


def test_without_the_ladders_systems_the_table_is_empty_and_the_figure_draws():
    res, col = _store({"two_particle": 1.0, "poisson": 0.5})
    assert gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(0),
                             n_boot=10).empty
    res, col = _store({"two_particle": 1.0, "poisson": 0.5, "poisson_scatter": 0.9,
                       "poisson_kinetic": 1.0})
    tab = gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(0),
                            n_boot=50)
    fig = gap_figure(tab)
    assert len(fig.axes) == 2 and len(LADDER) == 3
