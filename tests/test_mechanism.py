"""The mechanism measured on runs (docs/mechanism.md): angular momenta per collision,
the hazard of the intervals, re-collisions, rate mixtures and predicted rates."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from kicktimes import initial_conditions, simulate_two_particle, stats
from kicktimes.diagnostics import mechanism

needs_conditional_rate = pytest.mark.skipif(
    not hasattr(stats, "conditional_kinetic_rate"),
    reason="stats.conditional_kinetic_rate (issue 29, item 1) is not there yet")


@pytest.fixture(scope="module")
def logged_run():
    ic = initial_conditions(1, 0.03, rng=4)[0]
    return simulate_two_particle(ic, 0.03, t_max=3000.0, log_collisions=True)


def _diameter_ic(r=0.02):
    """Two disks on one diameter, heading for each other: they meet at the centre, go out
    to the wall and come back, forever, every 2 - 4r."""
    return np.array([[-0.5, 0.0, 1.0, 0.0], [0.5, 0.0, -1.0, 0.0]])


# ------------------------------------------------------------------ collision table
def test_angular_momentum_is_conserved_between_collisions(logged_run):
    tab = mechanism.collision_table(logged_run)
    assert len(tab) == logged_run.n_pp > 50
    for disk in ("L0", "L1"):
        pre, post = tab[f"{disk}_pre"].to_numpy(), tab[f"{disk}_post"].to_numpy()
        np.testing.assert_allclose(pre[1:], post[:-1], rtol=0, atol=1e-12)
    first = mechanism.initial_angular_momenta(logged_run.ic)
    np.testing.assert_allclose(tab.loc[0, ["L0_pre", "L1_pre"]].to_numpy(float), first,
                               rtol=0, atol=1e-12)
    # collisions do change them (otherwise nothing here would be a mechanism)
    assert np.median(np.abs(tab["L0_post"] - tab["L0_pre"])) > 1e-2


def test_no_collision_follows_another_without_a_wall_hit(logged_run):
    tab = mechanism.collision_table(logged_run)
    later = tab.iloc[1:]
    assert ((later["wall_hits0"] + later["wall_hits1"]) >= 1).all()
    assert tab["wall_hits0"].sum() + tab["wall_hits1"].sum() <= logged_run.n_boundary


def test_the_table_s_intervals_are_the_pooled_intervals_of_the_run(logged_run):
    tab = mechanism.collision_table(logged_run)
    iv = stats.intervals_from_times(logged_run.pp_times, logged_run.t_max)
    done = ~tab["next_censored"]
    np.testing.assert_allclose(tab.loc[done, "next_interval"], iv.complete)
    np.testing.assert_allclose(tab.loc[~done, "next_interval"], iv.censored)
    np.testing.assert_allclose(tab["interval"].iloc[1:], iv.complete)
    assert ((tab["impact_ratio"] >= 0) & (tab["impact_ratio"] <= 1 + 1e-9)).all()


def test_a_head_on_pair_on_a_diameter_recollides_every_two_minus_four_r():
    r = 0.02
    run = simulate_two_particle(_diameter_ic(r), r, t_max=100.0, log_collisions=True)
    tab = mechanism.collision_table(run)
    np.testing.assert_allclose(tab["interval"].iloc[1:], 2 - 4 * r, rtol=1e-12)
    np.testing.assert_allclose(tab[["L0_post", "L1_post", "impact"]], 0.0, atol=1e-12)
    res = mechanism.recollision_share(tab, rng=0)
    assert (res.share, res.n_collisions) == (1.0, run.n_pp - 1)


def test_collision_tables_stack_runs_with_their_keys(logged_run):
    keys = pd.DataFrame({"radius": [0.03, 0.03], "ic": [7, 8]})
    both = mechanism.collision_tables([logged_run, logged_run], keys=keys)
    assert list(both.columns[:3]) == ["run", "radius", "ic"]
    assert len(both) == 2 * logged_run.n_pp
    assert set(both.loc[both["run"] == 1, "ic"]) == {8}


# ------------------------------------------------------------------ re-collisions
def test_recollision_share_counts_returns_after_at_most_one_wall_hit_each():
    nan = float("nan")
    tab = pd.DataFrame({
        "run": [0, 0, 0, 0, 1, 1, 1],
        "interval": [nan, 1.9, 25.0, 2.0, nan, 1.8, 40.0],
        "wall_hits0": [4, 1, 8, 0, 0, 1, 2],
        "wall_hits1": [2, 1, 5, 2, 3, 0, 1],
    })
    one = mechanism.recollision_share(tab, rng=0)
    assert (one.n_recollisions, one.n_collisions, one.n_runs) == (2, 5, 2)
    assert one.share == pytest.approx(0.4)
    assert one.ci_low <= one.share <= one.ci_high
    two = mechanism.recollision_share(tab, max_wall_hits=2, rng=0)
    assert two.n_recollisions == 4
    assert "at most 2 wall hit" in two.definition


def test_randomly_placed_events_rarely_find_a_single_wall_round_trip(logged_run):
    null = mechanism.poisson_recollision_share([logged_run], n_rep=20, n_boot=99, rng=1)
    rate = logged_run.n_pp / logged_run.t_max
    # placed at rate G, an event finds a round trip (< ~4 time units) with prob. < 1 - e^{-4G}
    assert 0 <= null.share < 1 - np.exp(-4 * rate)
    assert null.n_collisions > 10 * logged_run.n_pp


# ------------------------------------------------------------------ hazard
def test_the_hazard_of_exponential_intervals_is_flat_within_its_intervals():
    rng = np.random.default_rng(0)
    haz = stats.interval_hazard(rng.exponential(2.0, 20_000), bins=10)
    tab = haz.table
    covered = ((tab["ci_low"] <= 0.5) & (0.5 <= tab["ci_high"])).mean()
    assert covered >= 0.8
    assert haz.rate == pytest.approx(0.5, rel=0.03)


def test_the_flat_hazard_test_has_its_size_on_exponential_data():
    rng = np.random.default_rng(1)
    p = np.array([stats.interval_hazard(rng.exponential(1.0, 400), bins=8).pvalue
                  for _ in range(400)])
    assert 0.02 <= (p < 0.05).mean() <= 0.09


def test_censoring_adds_exposure_without_events():
    rng = np.random.default_rng(2)
    x, c = rng.exponential(1.0, 20_000), rng.exponential(1.0, 20_000)
    haz = stats.interval_hazard(x[x <= c], censored=c[c < x], bins=6)
    assert haz.rate == pytest.approx(1.0, rel=0.04)
    assert haz.pvalue > 1e-3
    # dropping the censored intervals would bias the rate up (to ~2)
    assert stats.interval_hazard(x[x <= c], bins=6).rate > 1.7


def test_the_hazard_of_gamma_half_intervals_falls():
    rng = np.random.default_rng(3)
    haz = stats.interval_hazard(rng.gamma(0.5, 2.0, 3000), bins=8)
    tab = haz.table
    assert haz.pvalue < 1e-10
    assert tab["ci_low"].iloc[0] > tab["ci_high"].iloc[-1]
    assert np.all(np.diff(tab["hazard"].to_numpy()[:4]) < 0)


def test_hazard_rejects_bad_edges():
    with pytest.raises(ValueError, match="edges"):
        stats.interval_hazard([1.0, 2.0], edges=[0.5, 1.0])
    with pytest.raises(ValueError, match="complete"):
        stats.interval_hazard([1.0, -2.0])


# ------------------------------------------------------------------ rate mixtures
def test_a_rate_mixture_has_the_mixture_survival_and_a_falling_hazard():
    mix = stats.rate_mixture([1.0, 4.0], weights=[3.0, 1.0])
    t = np.array([0.0, 0.3, 2.0])
    np.testing.assert_allclose(mix.sf(t), 0.75 * np.exp(-t) + 0.25 * np.exp(-4 * t))
    assert mix.hazard(0.0) == pytest.approx(1.75)
    assert np.all(np.diff(mix.hazard(np.linspace(0, 5, 20))) < 0)
    assert mix.mean() == pytest.approx(0.75 + 0.25 / 4)


def test_cox_times_replay_the_rates_in_order():
    # three fast states then a frozen one: exactly three events
    t = stats.simulate_cox_times([1e9, 1e9, 1e9, 1e-12], 10.0, rng=0)
    assert t.size == 3 and t[-1] < 1e-6
    n = [stats.simulate_cox_times([0.5], 100.0, rng=s).size for s in range(300)]
    assert np.mean(n) == pytest.approx(50.0, rel=0.03)
    assert np.var(n) / np.mean(n) == pytest.approx(1.0, abs=0.25)


def test_iid_cox_intervals_follow_the_rate_mixture():
    rates = np.array([0.2, 1.0, 5.0])
    t = stats.simulate_cox_times(rates, 20_000.0, order="iid", rng=4)
    x = np.diff(t)
    mix = stats.rate_mixture(rates)
    for q in (0.5, 2.0, 8.0):
        assert (x > q).mean() == pytest.approx(float(mix.sf(q)), abs=0.02)


# ------------------------------------------------------------------ predicted rates
@needs_conditional_rate
def test_predicted_rates_are_the_conditional_rate_at_the_initial_angular_momenta():
    ic = np.array([[0.5, 0.0, 0.0, 1.0], [0.0, -0.3, 1.0, 0.0]])   # L = (0.5, 0.3)
    got = mechanism.predicted_rates(np.stack([ic, ic[::-1]]), 0.02)
    want = stats.conditional_kinetic_rate(0.02, np.array([0.5, 0.3]), np.array([0.3, 0.5]))
    np.testing.assert_allclose(got, want)
    # symmetric in the disks, to the quadrature's accuracy (3e-4, docs/kinetic.md)
    assert got[0] == pytest.approx(got[1], rel=1e-3)


@needs_conditional_rate
def test_predicted_rates_average_to_the_kinetic_rate_over_invariant_ics():
    r = 0.02
    ics = initial_conditions(2000, r, rng=5, method="uniform")
    rates = mechanism.predicted_rates(ics, r)
    se = rates.std() / np.sqrt(rates.size)
    assert abs(rates.mean() - stats.kinetic_rate(r)) < 3 * se + 0.05 * stats.kinetic_rate(r)


def test_the_elastic_rule_s_speeds_change_at_collisions_and_keep_the_energy():
    ic = initial_conditions(1, 0.03, rng=4)[0]
    run = simulate_two_particle(ic, 0.03, t_max=1500.0, rule="elastic", log_collisions=True)
    tab = mechanism.collision_table(run)
    energy = tab["speed0_post"] ** 2 + tab["speed1_post"] ** 2
    np.testing.assert_allclose(energy, (ic[:, 2:] ** 2).sum(), rtol=1e-9)
    assert tab["speed0_post"].std() > 0.05
    mirror = mechanism.collision_table(simulate_two_particle(ic, 0.03, t_max=300.0,
                                                             log_collisions=True))
    np.testing.assert_allclose(mirror[["speed0_post", "speed1_post"]], 1.0, rtol=1e-12)


@needs_conditional_rate
def test_predicted_rates_under_the_elastic_rule_condition_on_the_speeds():
    ic = initial_conditions(1, 0.02, rng=2, method="uniform", rule="elastic")
    slow, fast = ic.copy(), ic.copy()
    slow[0, :, 2:] *= 0.5
    fast[0, :, 2:] *= 2.0
    rates = [float(np.squeeze(mechanism.predicted_rates(x, 0.02, rule="elastic")))
             for x in (slow, ic, fast)]
    assert rates[0] < rates[1] < rates[2]
    np.testing.assert_allclose(rates[2] / rates[1], 2.0, rtol=1e-9)
