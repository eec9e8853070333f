"""`kicktimes.stats.dilute_tagged_disk`: the dilute gas's tagged disk and its predictions,
each checked against a route that does not share its code (issue 51)."""

import math

import numpy as np
import pytest

from kicktimes.stats import (
    DiluteTaggedDisk,
    dilute_tagged_disk,
    dilute_tagged_times,
    poisson_group,
)

KT = 0.5


def _gauss_legendre(edges, n=24):
    """Nodes and weights of an n-point Gauss-Legendre rule on each panel of ``edges``."""
    x, w = np.polynomial.legendre.leggauss(n)
    nodes, weights = [], []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        nodes.append(0.5 * (b - a) * x + 0.5 * (a + b))
        weights.append(0.5 * (b - a) * w)
    return np.concatenate(nodes), np.concatenate(weights)


def _mean_relative_speed(v, kT=KT):
    r""":math:`\langle |v - w| \rangle_w` over the 2-D Maxwellian by a 2-D quadrature in
    polar coordinates about ``v`` (:math:`w = v + r e_\theta`: the kink of :math:`|v - w|`
    sits at the origin, where :math:`r\,dr` smooths it): no Bessel function, no closed form."""
    sigma = math.sqrt(kT)
    theta = 2.0 * math.pi * np.arange(64) / 64        # periodic: the trapezoid is spectral
    out = []
    for s in np.atleast_1d(v):
        r, wr = _gauss_legendre(np.linspace(0.0, s + 12.0 * sigma, 9))
        w2 = s * s + 2.0 * s * r[:, None] * np.cos(theta)[None, :] + r[:, None] ** 2
        dens = np.exp(-w2 / (2.0 * kT)) / (2.0 * math.pi * kT)
        out.append(np.sum(wr[:, None] * r[:, None] ** 2 * dens) * 2.0 * math.pi / 64)
    return np.asarray(out)


def _direct_interval_law(t_values, kT=KT):
    """Hazard and cv^2 of the intervals from the Maxwell speed law and the directly
    integrated rate, in the speed variable (not u), normalising the mean rate numerically."""
    edges = np.array([0.0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4, 12.0]) * math.sqrt(2 * kT)
    v, wv = _gauss_legendre(edges)
    maxwell = v / kT * np.exp(-v * v / (2.0 * kT))      # 2-D Maxwell speed density
    lam = _mean_relative_speed(v, kT)
    nu = np.sum(wv * maxwell * lam)                      # the stationary mean rate
    rho = lam / nu
    post = rho * maxwell                                 # the flux-weighted speed law
    hazard = [np.sum(wv * post * rho * np.exp(-(rho - rho.min()) * t))
              / np.sum(wv * post * np.exp(-(rho - rho.min()) * t)) for t in t_values]
    mean = np.sum(wv * post / rho)
    second = np.sum(wv * post * 2.0 / rho ** 2)
    return np.asarray(hazard), second / mean ** 2 - 1.0, mean


@pytest.fixture(scope="module")
def elastic():
    return dilute_tagged_disk("elastic")


@pytest.fixture(scope="module")
def intervals():
    """Stationary intervals of the exact event Monte Carlo, in mean intervals: two long
    streams, their first 20 intervals (the start's transient) and the censored last dropped."""
    times = dilute_tagged_times("elastic", 1.0, 1.0e6, n_runs=2, rng=np.random.default_rng(51))
    return np.concatenate([np.diff(t)[20:] for t in times])


def test_rate_closed_form_matches_direct_quadrature(elastic):
    v = np.array([0.0, 0.3, 1.0, 2.5, 5.0])
    direct = _mean_relative_speed(v) / math.sqrt(math.pi * KT)
    np.testing.assert_allclose(elastic.rate(v), direct, rtol=1e-9)
    assert elastic.rate(0.0) == pytest.approx(1.0 / math.sqrt(2.0), rel=1e-12)


def test_hazard_and_cv2_match_independent_quadrature(elastic):
    direct_h, direct_cv2, mean = _direct_interval_law([0.0, 5.0, 40.0])
    assert mean == pytest.approx(1.0, abs=1e-9)          # the mean interval is 1/nu
    np.testing.assert_allclose(elastic.hazard([0.0, 5.0, 40.0]), direct_h, atol=0.01)
    assert elastic.interval_cv2 == pytest.approx(direct_cv2, abs=0.01)
    # not a tautology: the hazard falls by a quarter and the intervals are over-dispersed
    assert direct_h[0] - direct_h[2] > 0.3 and direct_cv2 > 1.05


def test_hazard_long_time_limit_is_the_rate_at_rest(elastic):
    h = elastic.hazard(np.array([[40.0], [400.0]]))
    assert h.shape == (2, 1)
    # 1/sqrt(2) + 1/(t + 2 sqrt(2)): a power-law approach to the rate of a disk at rest
    for t, value in zip((40.0, 400.0), h.ravel(), strict=True):
        assert value == pytest.approx(1.0 / math.sqrt(2.0) + 1.0 / (t + 2.0 * math.sqrt(2.0)),
                                      abs=0.2 / t)
        assert value > 1.0 / math.sqrt(2.0)


def test_interval_cv2_and_first_hazard_match_the_event_monte_carlo(elastic, intervals):
    tau = intervals
    assert tau.mean() == pytest.approx(1.0, abs=0.005)
    cv2 = tau.var() / tau.mean() ** 2
    # standard error by batch means (the intervals are correlated through the speed)
    b = tau[: tau.size // 10_000 * 10_000].reshape(-1, 10_000)
    se = np.std(b.var(axis=1) / b.mean(axis=1) ** 2, ddof=1) / math.sqrt(b.shape[0])
    assert se < 0.01 / 3
    assert cv2 == pytest.approx(elastic.interval_cv2, abs=0.01)
    # the hazard at 0: events over exposure in [0, 0.1), against the quadrature's mean
    # hazard over the same bin (Simpson, the hazard is smooth there)
    delta = 0.1
    events = np.sum(tau < delta)
    exposure = np.minimum(tau, delta).sum()
    mc = events / exposure
    assert math.sqrt(events) / exposure < 0.01 / 3
    h = elastic.hazard(np.linspace(0.0, delta, 5))
    mean_h = (h[0] + 4 * h[1] + 2 * h[2] + 4 * h[3] + h[4]) / 12.0
    assert mc == pytest.approx(mean_h, abs=0.01)
    assert mc > 1.04                                    # faster than the mean just after


@pytest.fixture(scope="module")
def d_infinity(elastic):
    return elastic.dispersion()


def _disjoint_window_dispersion(window, n_windows, seed):
    """D and its standard error from the counts of ``n_windows`` disjoint windows of one
    long stream (not independent stationary starts, not the speed chain)."""
    (t,) = dilute_tagged_times("elastic", 1.0, window * n_windows, n_runs=1,
                               rng=np.random.default_rng(seed))
    counts = np.bincount((t // window).astype(int), minlength=n_windows)[:n_windows]
    d = counts.var(ddof=1) / counts.mean()
    return d, d * math.sqrt(2.0 / n_windows)


def test_long_window_dispersion_matches_counts_in_disjoint_windows(elastic, d_infinity):
    d = d_infinity
    assert d.stderr < 0.003 and d.ci_low < d.value < d.ci_high
    # independent: another seed, raw counts in disjoint windows of 150 mean intervals
    # (their bias against the limit, about 0.17 / 150, is a tenth of the tolerance)
    d_counts, se_counts = _disjoint_window_dispersion(150.0, 30_000, 7)
    assert se_counts < 0.01
    assert abs(d.value - d_counts) < 3.0 * math.hypot(d.stderr, se_counts)
    # and it is not the intervals' cv^2: the speed correlates successive intervals
    assert d.ci_low > elastic.interval_cv2 + 0.02


def test_finite_window_dispersion_matches_disjoint_windows(elastic):
    d = elastic.dispersion(window=30.0, n_events=600_000, rng=3)
    assert d.n == 20_000 and d.quantity == "dispersion, window 30"
    d_counts, se_counts = _disjoint_window_dispersion(30.0, 20_000, 11)
    assert abs(d.value - d_counts) < 3.0 * math.hypot(d.stderr, se_counts)
    assert d.ci_low > 1.05                              # over-dispersed already at 30


def test_ks_share_is_the_gas_pages_uniformity_ks(elastic):
    share = elastic.ks_share(10, n_runs=60, rng=5)
    times = dilute_tagged_times("elastic", 1.0, 2.0 * 11 + 50.0, n_runs=60,
                                rng=np.random.default_rng(5))
    group = poisson_group([x[:10] for x in times], [float(x[10]) for x in times], n_mc=19,
                          rng=0)
    p = group.ensemble.per_sequence["p_uniformity_ks"].to_numpy()
    assert share.value == pytest.approx(np.mean(p < 0.05), abs=1e-12)
    assert share.ci_low <= share.value <= share.ci_high


def test_mirror_is_poisson_exactly():
    disk = dilute_tagged_disk("mirror")
    assert float(disk.dispersion()) == 1.0 and disk.dispersion().stderr == 0.0
    assert float(disk.dispersion(window=30.0)) == 1.0
    assert disk.interval_cv2 == 1.0
    assert np.all(disk.hazard([0.0, 5.0, 40.0]) == 1.0)
    assert np.all(disk.rate([0.0, 1.0, 3.0]) == 1.0)
    assert disk.ks_share(30, alpha=0.1).value == 0.1


def test_predictions_do_not_depend_on_the_temperature(elastic):
    hot = dilute_tagged_disk("elastic", kT=2.0)
    assert hot.interval_cv2 == pytest.approx(elastic.interval_cv2, rel=1e-9)
    np.testing.assert_allclose(hot.hazard([0.0, 5.0]), elastic.hazard([0.0, 5.0]), rtol=1e-9)
    assert hot.rate(2.0) == pytest.approx(float(elastic.rate(1.0)), rel=1e-12)


@pytest.mark.parametrize(("call", "name"), [
    (lambda: dilute_tagged_disk("inelastic"), "rule"),
    (lambda: dilute_tagged_disk("elastic", kT=0.0), "kT"),
    (lambda: dilute_tagged_disk("elastic", kT=-1.0), "kT"),
    (lambda: DiluteTaggedDisk("elastic", kT=float("nan")), "kT"),
    (lambda: dilute_tagged_disk("elastic").dispersion(window=0.0), "window"),
    (lambda: dilute_tagged_disk("elastic").dispersion(window=-5.0), "window"),
    (lambda: dilute_tagged_disk("mirror").dispersion(window=-5.0), "window"),
    (lambda: dilute_tagged_disk("elastic").hazard([1.0, -0.5]), "t"),
    (lambda: dilute_tagged_disk("elastic").hazard(float("nan")), "t"),
    (lambda: dilute_tagged_disk("elastic").rate(-1.0), "v"),
    (lambda: dilute_tagged_disk("elastic").ks_share(0), "k"),
    (lambda: dilute_tagged_disk("elastic").ks_share(5, alpha=1.5), "alpha"),
    (lambda: dilute_tagged_disk("elastic").dispersion(n_events=10), "n_events"),
])
def test_bad_input_names_the_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        call()


def test_bad_types_are_type_errors():
    with pytest.raises(TypeError, match="kT"):
        dilute_tagged_disk("elastic", kT="hot")
    with pytest.raises(TypeError, match="k"):
        dilute_tagged_disk("elastic").ks_share(2.5)


def test_the_gamma_shape_is_the_maximum_likelihood_limit_on_many_intervals():
    """The shape a gamma fit converges to, against scipy's maximum-likelihood fit of 2e5
    exact intervals (standard error about 0.003): 0.957 against a fit near 0.953."""
    from scipy import stats

    from kicktimes.stats import dilute_tagged_disk, dilute_tagged_times

    k = dilute_tagged_disk("elastic").gamma_shape
    times = dilute_tagged_times("elastic", 1.0, 2e5, n_runs=1, rng=np.random.default_rng(1))[0]
    fitted = stats.gamma.fit(np.diff(times), floc=0)[0]
    assert k == pytest.approx(fitted, abs=0.01)
    assert k < 0.97  # over-dispersed intervals: a shape below 1
    assert dilute_tagged_disk("mirror").gamma_shape == 1.0
