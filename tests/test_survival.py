"""Escape-time survival (Kaplan-Meier with censoring) and the law of its tail."""

import numpy as np
import pytest

from kicktimes import initial_conditions, schedules, simulate_one_particle
from kicktimes.stats import escape_survival, fit_escape_tail


def test_kaplan_meier_follows_a_censored_exponential_law_within_its_intervals():
    rng = np.random.default_rng(3)
    t = rng.exponential(2.0, 2000)
    horizon = rng.uniform(2.0, 8.0, t.size)  # each run its own censoring time
    t[t > horizon] = np.inf
    km = escape_survival(t, horizon)
    exact = np.exp(-km["time"] / 2.0)
    inside = (km["ci_low"] <= exact) & (exact <= km["ci_high"])
    assert inside.mean() > 0.9 and (km["survival"].diff().dropna() <= 0).all()


def test_the_tail_fit_tells_an_exponential_from_an_algebraic_tail_and_covers_the_rate():
    rng = np.random.default_rng(4)
    covered = 0
    for _ in range(40):
        e = 5.0 + rng.exponential(10.0, 400)
        e[e > 80.0] = np.inf
        fit = fit_escape_tail(e, 80.0, t_min=5.0)
        assert fit.best == "exponential"
        covered += fit.rate_ci[0] <= 0.1 <= fit.rate_ci[1]
    assert covered >= 34  # 95 % intervals: 38 expected of 40
    p = 5.0 * (1.0 - rng.random(2000)) ** -1.0
    p[p > 500.0] = np.inf
    fit = fit_escape_tail(p, 500.0, t_min=5.0)
    assert fit.best == "algebraic" and fit.alpha_ci[0] <= 1.0 <= fit.alpha_ci[1]


def test_kicks_turn_the_circles_algebraic_escape_into_an_exponential_one():
    # the integrable circle with a hole: survival ~ C / t (Bunimovich & Dettmann 2005);
    # a disk kicked at Poisson times forgets its orbit: an exponential tail
    r, horizon, hole = 0.02, 1500.0, [(0.0, 0.05)]
    states = initial_conditions(400, r, rng=8)[:, 0]
    free = [simulate_one_particle(s, r, t_max=horizon, holes=hole).escape_time for s in states]
    kicked = [simulate_one_particle(s, r, t_max=horizon, holes=hole, rng=i,
                                    kicks=schedules.Poisson(0.5)).escape_time
              for i, s in enumerate(states)]
    tail = fit_escape_tail(free, horizon, t_min=50.0)
    assert tail.best == "algebraic" and tail.alpha_ci[0] <= 1.0 <= tail.alpha_ci[1]
    assert fit_escape_tail(kicked, horizon, t_min=50.0).best == "exponential"


@pytest.mark.parametrize("times, t_max, match", [
    ([1.0, -2.0], 5.0, "positive"),
    ([1.0, 7.0], 5.0, "exceed t_max"),
    ([1.0, np.nan], 5.0, "positive"),
    ([1.0, 2.0], 0.0, "t_max must be positive"),
])
def test_bad_escape_times_are_refused(times, t_max, match):
    with pytest.raises(ValueError, match=match):
        escape_survival(times, t_max)
