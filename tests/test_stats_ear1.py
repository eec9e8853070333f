"""`stats.ear1_intervals` on its known answers: Exp(1) marginals, lag-l correlation rho**l."""

import numpy as np
import pytest
import scipy.stats

from kicktimes import stats


def test_the_recursion_is_the_one_of_gaver_and_lewis():
    rng = np.random.default_rng(5)
    keep = rng.uniform(size=300) > 0.3
    e = rng.exponential(size=300)
    x = [rng.exponential()]
    for k in range(1, 300):
        x.append(0.3 * x[-1] + keep[k] * e[k])
    np.testing.assert_array_equal(stats.ear1_intervals(300, 0.3, rng=5), x)


@pytest.mark.parametrize("rho", [0.0, 0.5, 0.9])
def test_marginals_are_exponential_and_correlations_geometric(rho):
    x = stats.ear1_intervals(400_000, rho, rng=11)
    # the marginal is Exp(1) (KS on a thinned, nearly independent subsample)
    assert scipy.stats.kstest(x[::50], "expon").pvalue > 1e-3
    for lag in (1, 2, 3):
        r = np.corrcoef(x[:-lag], x[lag:])[0, 1]
        assert r == pytest.approx(rho**lag, abs=0.01)


@pytest.mark.parametrize("kw, match", [(dict(n=0, rho=0.5), "n must"),
                                       (dict(n=10, rho=1.0), "rho must"),
                                       (dict(n=10, rho=-0.1), "rho must"),
                                       (dict(n=10, rho=float("nan")), "rho must be finite")])
def test_bad_arguments_are_named(kw, match):
    with pytest.raises(ValueError, match=match):
        stats.ear1_intervals(**kw)
