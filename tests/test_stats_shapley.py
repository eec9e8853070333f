"""stats.shapley_values: exact on games with known values, efficient, and the report's
two-ingredient gap shares bitwise the closed form they replaced."""

import itertools

import numpy as np
import pytest

from kicktimes.report.decomposition import shapley_shares
from kicktimes.stats import shapley_values


def _coalitions(n):
    return [frozenset(s) for k in range(n + 1) for s in itertools.combinations(range(n), k)]


def test_an_additive_game_gives_each_player_its_own_worth_and_any_game_is_efficient():
    a = (0.5, -1.0, 2.0)
    additive = {s: sum(a[i] for i in s) for s in _coalitions(3)}
    np.testing.assert_allclose(shapley_values(additive, 3), a)
    rng = np.random.default_rng(0)
    for n in (1, 2, 3, 4):
        game = {s: rng.normal() for s in _coalitions(n)}
        phi = shapley_values(game, n)
        assert sum(phi) == pytest.approx(game[frozenset(range(n))] - game[frozenset()])


def test_symmetric_players_share_equally_and_a_dummy_gets_nothing():
    # players 0 and 1 are symmetric; player 2 adds nothing to any coalition
    game = {s: float(len(s & {0, 1}) ** 2) for s in _coalitions(3)}
    phi = shapley_values(game, 3)
    assert phi[0] == pytest.approx(phi[1]) and phi[2] == 0.0


def test_the_gap_shares_are_the_two_player_closed_form_bit_for_bit():
    rng = np.random.default_rng(3)
    rho = rng.uniform(0.2, 1.2, size=(4, 500))
    g_up, g_sp, g_uk, g_sk = np.abs(np.log(rho))
    closed = np.stack([0.5 * ((g_up - g_sp) + (g_uk - g_sk)) / g_up,
                       0.5 * ((g_up - g_uk) + (g_sp - g_sk)) / g_up, g_sk / g_up])
    assert np.array_equal(shapley_shares(rho), closed)


@pytest.mark.parametrize(("values", "n", "match"), [
    ({frozenset(): 0.0}, 0, "n must be"),
    ({frozenset(): 0.0}, True, "n must be"),
    ({frozenset(): 0.0, frozenset({0}): 1.0}, 2, "coalition"),
])
def test_bad_input_is_refused_by_name(values, n, match):
    with pytest.raises(ValueError, match=match):
        shapley_values(values, n)
