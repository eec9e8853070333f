"""The gap decomposition: Shapley shares of the kicked-versus-two-disk gap that each kick
ingredient (deflection law, timing) closes, over the 2 x 2 factorial of kicked systems."""

import itertools

import numpy as np
import pandas as pd
import pytest

from kicktimes.report.decomposition import (
    FACTORIAL,
    NO_GAP,
    STEPS,
    gap_decomposition,
    gap_figure,
    gap_summary,
    shapley_shares,
)


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


FOUR = {"two_particle": 1.0, "poisson": 0.25, "poisson_scatter": 0.5, "uniform_kinetic": 0.4,
        "poisson_kinetic": 0.8}


def test_shapley_shares_average_both_orders_and_sum_to_one():
    res, col = _store(FOUR)
    tab = gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(1),
                            n_boot=100)
    prim = tab[(tab["control"] == "primary") & (tab["diagnostic"] == "ftle")]
    est = prim.set_index("quantity")["estimate"]
    assert est["ratio poisson"] == pytest.approx(0.25)
    g = dict(zip(FACTORIAL, np.abs(np.log([0.25, 0.5, 0.4, 0.8])), strict=True))
    up, sp, uk, sk = (g[s] for s in FACTORIAL)
    # deflection first, then timing; and timing first, then deflection: the average
    order_1 = ((up - sp), (sp - sk))
    order_2 = ((uk - sk), (up - uk))
    assert est[STEPS[0]] == pytest.approx(0.5 * (order_1[0] + order_2[0]) / up)
    assert est[STEPS[1]] == pytest.approx(0.5 * (order_1[1] + order_2[1]) / up)
    assert est[STEPS[2]] == pytest.approx(sk / up)
    assert est[list(STEPS[:3])].sum() == pytest.approx(1.0)
    assert not set(STEPS[3:]) & set(est.index)  # no actual-times systems, no such shares
    assert set(tab["control"]) == {"primary", "paired_median", "sticky_excluded"}
    assert set(tab["diagnostic"]) == {"ftle", "one_minus_r1"}


@pytest.mark.parametrize("rho", list(itertools.product([0.3, 0.6, 0.95], repeat=4)))
def test_shapley_shares_do_not_depend_on_which_ingredient_is_named_first(rho):
    """Swapping the two ingredients swaps their shares and keeps the remainder."""
    up, sp, uk, sk = rho
    a = shapley_shares(np.array([up, sp, uk, sk]))
    b = shapley_shares(np.array([up, uk, sp, sk]))  # timing <-> deflection
    np.testing.assert_allclose(a[[1, 0, 2]], b, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a.sum(), 1.0)


def test_a_gap_inside_the_band_is_not_decomposed():
    res, col = _store({"two_particle": 1.0, "poisson": 0.97, "poisson_scatter": 0.99,
                       "uniform_kinetic": 0.98, "poisson_kinetic": 1.0}, noise=0.01)
    tab = gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(0),
                            n_boot=100)
    shares = tab[tab["quantity"].isin(STEPS)]
    assert shares["estimate"].isna().all() and (shares["note"] == NO_GAP).all()
    summary = gap_summary(tab)
    assert (summary[STEPS[0]] == NO_GAP).all()
    fig = gap_figure(tab)
    assert any("no gap" in t.get_text() for ax in fig.axes for t in ax.texts)


def test_intervals_cover_the_estimate_and_widen_with_noise():
    values = {"two_particle": 1.0, "poisson": 0.3, "poisson_scatter": 0.9,
              "uniform_kinetic": 0.3, "poisson_kinetic": 0.9}
    quiet = gap_decomposition(*_store(values, noise=0.05), family="f", eps=(),
                              rng=np.random.default_rng(2), n_boot=300)
    loud = gap_decomposition(*_store(values, noise=0.4), family="f", eps=(),
                             rng=np.random.default_rng(2), n_boot=300)
    key = (quiet["control"] == "primary") & (quiet["quantity"] == STEPS[0])
    q, lo = quiet[key].iloc[0], loud[key.to_numpy()].iloc[0]
    assert q["ci_low"] <= q["estimate"] <= q["ci_high"]
    assert (lo["ci_high"] - lo["ci_low"]) > (q["ci_high"] - q["ci_low"])
    # a share is robust only when no control's CI straddles 0
    summary = gap_summary(quiet).set_index("diagnostic")
    assert summary.loc["ftle", f"{STEPS[0]} robust"].startswith("sign ✓ (0.9")
    # what is left: no sign mark, but its range over the controls
    assert summary.loc["ftle", f"{STEPS[2]} robust"].endswith("over the controls)")
    assert summary.loc["ftle", f"{STEPS[1]} robust"].startswith("✗")


def test_the_actual_times_factorial_switches_the_timing_to_the_real_collision_times():
    values = {**FOUR, "actual": 0.3, "actual_scatter": 0.7}
    tab = gap_decomposition(*_store(values), family="f", eps=(),
                            rng=np.random.default_rng(1), n_boot=100)
    est = tab[(tab["control"] == "primary") & (tab["diagnostic"] == "ftle")].set_index(
        "quantity")["estimate"]
    up, sp, ua, sa = np.abs(np.log([0.25, 0.5, 0.3, 0.7]))
    assert est[STEPS[4]] == pytest.approx(0.5 * ((up - ua) + (sp - sa)) / up)
    assert est[STEPS[3]] == pytest.approx(0.5 * ((up - sp) + (ua - sa)) / up)
    assert est[STEPS[5]] == pytest.approx(sa / up)
    # the kinetic-rate factorial's shares are unchanged by the extra systems
    alone = gap_decomposition(*_store(FOUR), family="f", eps=(),
                              rng=np.random.default_rng(1), n_boot=100)
    base = alone[(alone["control"] == "primary") & (alone["diagnostic"] == "ftle")]
    assert est[STEPS[1]] == pytest.approx(base.set_index("quantity")["estimate"][STEPS[1]])


def test_control_experiments_become_controls_of_their_family():
    from kicktimes.report.decomposition import merge_control_gaps

    a = gap_decomposition(*_store(FOUR), family="fam", eps=(), rng=np.random.default_rng(0),
                          n_boot=20)
    b = gap_decomposition(*_store(FOUR, seed=1), family="fam-elastic", eps=(),
                          rng=np.random.default_rng(0), n_boot=20)
    merged = merge_control_gaps([a, b])
    assert set(merged["family"]) == {"fam"}
    assert set(merged["control"]) == {"primary", "paired_median", "sticky_excluded", "elastic"}


def test_without_the_factorials_systems_the_table_is_empty_and_the_figure_draws():
    res, col = _store({"two_particle": 1.0, "poisson": 0.5, "poisson_scatter": 0.9,
                       "poisson_kinetic": 1.0})
    assert gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(0),
                             n_boot=10).empty
    res, col = _store(FOUR)
    tab = gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(0),
                            n_boot=50)
    fig = gap_figure(tab)
    assert len(fig.axes) == 2


def test_a_factorial_that_closes_none_of_the_gap_is_not_read():
    """The kinetic scatter kick as far from the two disks as the paper's kick: 'left' is 1,
    the deflection and timing shares cancel, and neither the table nor the figure reads
    them; the other diagnostic's shares stay."""
    from kicktimes.report.decomposition import NOT_READ, closes_nothing

    values = {"two_particle": 1.0, "poisson": 0.3, "poisson_scatter": 0.6,
              "uniform_kinetic": 0.6, "poisson_kinetic": 0.3}
    res, col = _store(values, noise=0.05)
    # only the FTLE closes nothing: 1 - R1's kinetic scatter kick sits near the two disks
    res.loc[(res["system"] == "poisson_kinetic") & (res["diagnostic"] == "autocorrelation"),
            "value"] = 1.0 - 0.95
    tab = gap_decomposition(res, col, family="f", eps=(), rng=np.random.default_rng(3),
                            n_boot=200)
    left = tab[(tab["control"] == "primary") & (tab["quantity"] == STEPS[2])].set_index(
        "diagnostic")
    assert left.loc["ftle", "ci_low"] <= 1 <= left.loc["ftle", "ci_high"]
    assert closes_nothing(tab) == {("f", "ftle")}
    summary = gap_summary(tab).set_index("diagnostic")
    assert summary.loc["ftle", STEPS[0]] == summary.loc["ftle", STEPS[1]] == NOT_READ
    assert summary.loc["one_minus_r1", STEPS[0]] != NOT_READ
    # the FTLE panel draws 'left' only (the third tick), not the two unread shares
    ftle = gap_figure(tab).axes[0]
    assert ftle.get_title() == "FTLE λ"
    xs = np.concatenate([np.atleast_1d(line.get_xdata()) for line in ftle.get_lines()
                         if len(np.atleast_1d(line.get_xdata())) == 1])
    assert xs.size and (xs > 1.5).all()
