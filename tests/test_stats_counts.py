"""Collision counts versus radius and the kinetic-theory rate (kicktimes.stats)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import integrate

from kicktimes import stats
from kicktimes.stats.counts import configuration_volume, lens_area

# --- kinetic theory ------------------------------------------------------------------------


def test_lens_area_matches_direct_integration():
    a = 0.8
    for d in (0.0, 0.3, 1.1, 1.6):
        # Overlap of |x| < a and |x - (d, 0)| < a, integrated over y then x.
        def height(x, d=d):
            h1 = math.sqrt(max(a * a - x * x, 0.0))
            h2 = math.sqrt(max(a * a - (x - d) ** 2, 0.0))
            return 2 * min(h1, h2)

        direct = integrate.quad(height, d - a, a, limit=200)[0] if d < 2 * a else 0.0
        assert float(lens_area(d, a)) == pytest.approx(direct, rel=1e-7, abs=1e-12)


def test_configuration_volume_matches_monte_carlo_pairs():
    # |Q| / (pi a^2)^2 is the probability that two uniform points in the disk of
    # radius a are at least 2r apart.
    rng = np.random.default_rng(0)
    r = 0.25
    a = 1 - r
    n = 2_000_000
    x, y = uniform_in_disk(a, (2, n), rng)
    far = np.mean((x[0] - x[1]) ** 2 + (y[0] - y[1]) ** 2 >= 4 * r * r)
    se = math.sqrt(far * (1 - far) / n)
    assert float(configuration_volume(r)) / (np.pi * a * a) ** 2 == pytest.approx(far, abs=5 * se)


def test_mean_approach_speeds_are_the_design_values():
    # Mirror rule: unit speeds, independent uniform directions; normal along x.
    mirror = (
        integrate.dblquad(
            lambda p2, p1: max(0.0, math.cos(p2) - math.cos(p1)), 0, 2 * np.pi, 0, 2 * np.pi
        )[0]
        / (2 * np.pi) ** 2
    )
    assert mirror == pytest.approx(4 / np.pi**2, rel=1e-6)
    # Elastic rule: (v1, v2) uniform on the sphere |v1|^2 + |v2|^2 = 2 in R^4.
    g = np.random.default_rng(1).standard_normal((2_000_000, 4))
    g *= math.sqrt(2) / np.linalg.norm(g, axis=1, keepdims=True)
    approach = np.maximum(0.0, g[:, 2] - g[:, 0])
    se = approach.std() / math.sqrt(approach.size)
    assert approach.mean() == pytest.approx(4 / (3 * np.pi), abs=5 * se)
    ratio = stats.kinetic_rate(0.1, rule="elastic") / stats.kinetic_rate(0.1, rule="mirror")
    assert ratio == pytest.approx((4 / (3 * np.pi)) / (4 / np.pi**2), rel=1e-12)


def uniform_in_disk(radius, n, rng):
    rad = radius * np.sqrt(rng.uniform(size=n))
    ang = rng.uniform(0, 2 * np.pi, size=n)
    return rad * np.cos(ang), rad * np.sin(ang)


def test_kinetic_rate_equals_the_collision_flux_measured_by_monte_carlo():
    # Independent of the lens and |Q| formulas: Gamma is the rate at which the pair
    # separation d crosses |d| = 2r inwards, i.e. the probability (under the uniform
    # law on Q) of lying in the thin shell 2r <= |d| < 2r + eps, times the mean
    # inward normal speed (w.n)^-, divided by eps. The shell is sampled directly:
    # x1 uniform in the disk of radius a, d area-uniform in the annulus, x2 = x1 - d.
    rng = np.random.default_rng(2)
    r, eps, n = 0.2, 1e-4, 2_000_000
    a = 1 - r
    x1, y1 = uniform_in_disk(a, n, rng)
    rho = np.sqrt(rng.uniform((2 * r) ** 2, (2 * r + eps) ** 2, n))
    psi = rng.uniform(0, 2 * np.pi, n)
    dx, dy = rho * np.cos(psi), rho * np.sin(psi)
    inside = (x1 - dx) ** 2 + (y1 - dy) ** 2 <= a * a
    phi = rng.uniform(0, 2 * np.pi, size=(2, n))  # mirror rule: independent unit speeds
    wx, wy = np.cos(phi[0]) - np.cos(phi[1]), np.sin(phi[0]) - np.sin(phi[1])
    integrand = inside * np.maximum(0.0, -(wx * dx + wy * dy) / rho)
    annulus = np.pi * ((2 * r + eps) ** 2 - (2 * r) ** 2)
    # |Q| by Monte Carlo too: pairs of uniform points at least 2r apart.
    px, py = uniform_in_disk(a, (2, n), rng)
    far = np.mean((px[0] - px[1]) ** 2 + (py[0] - py[1]) ** 2 >= 4 * r * r)
    volume = (np.pi * a * a) ** 2 * far
    flux = np.pi * a * a * annulus * integrand.mean() / (volume * eps)
    rel_se = integrand.std() / integrand.mean() / math.sqrt(n)
    # The shell's width biases by O(eps / r) = 5e-4; elastic would be 4.7% higher.
    assert stats.kinetic_rate(r) == pytest.approx(flux, rel=4 * rel_se + 1e-3)
    assert rel_se < 2e-3


def test_kinetic_rate_has_the_small_radius_limit():
    r = np.array([1e-2, 1e-3, 1e-4])
    limit = 16 * r / (np.pi**2 * (1 - r) ** 2)
    rel = np.abs(stats.kinetic_rate(r) / limit - 1)
    assert rel[-1] < 1e-3
    assert np.all(np.diff(rel) < 0)  # converges as r -> 0


def test_kinetic_rate_accepts_scalars_and_arrays():
    assert isinstance(stats.kinetic_rate(0.01), float)
    grid = np.array([[0.01, 0.02], [0.03, 0.4]])
    out = stats.kinetic_rate(grid, rule="elastic")
    assert out.shape == grid.shape
    assert out[0, 1] == pytest.approx(stats.kinetic_rate(0.02, rule="elastic"))


@pytest.mark.parametrize("bad", [0.0, 0.5, -0.1, 0.7, np.nan, np.inf])
def test_kinetic_rate_rejects_radii_outside_the_open_interval(bad):
    with pytest.raises(ValueError, match="r"):
        stats.kinetic_rate(bad)
    with pytest.raises(ValueError, match=r"r\[1\]"):
        stats.kinetic_rate([0.1, bad])


def test_kinetic_rate_rejects_unknown_rules():
    with pytest.raises(ValueError, match="rule"):
        stats.kinetic_rate(0.1, rule="sticky")


# --- regressions ---------------------------------------------------------------------------


def nb2_counts(mu, alpha, rng):
    """Negative binomial with mean mu and Var = mu + alpha mu^2 (gamma-Poisson)."""
    return rng.poisson(rng.gamma(1 / alpha, alpha * mu))


RADII = np.repeat([0.008, 0.012, 0.016, 0.02, 0.026, 0.03], 300)


def test_negative_binomial_recovers_a_known_dispersion_and_exponent():
    rng = np.random.default_rng(3)
    t_window = rng.uniform(500, 1500, RADII.size)
    mu = 1.7 * RADII**1.0 * t_window
    df = pd.DataFrame({"radius": RADII, "count": nb2_counts(mu, 0.4, rng), "t_window": t_window})
    reg = stats.regress_counts(df)
    coef = reg.coefficients()
    alpha = coef.loc[("negbin", "alpha")]
    assert abs(alpha["estimate"] - 0.4) < 3 * alpha["stderr"]
    slope = coef.loc[("negbin", "log_radius")]
    assert abs(slope["estimate"] - 1.0) < 3 * slope["stderr"]
    od = reg.overdispersion()
    assert od["pearson_dispersion"] > 3 and od["lr_pvalue"] < 1e-10
    # The Poisson model's standard errors ignore the overdispersion.
    assert coef.loc[("poisson", "log_radius"), "stderr"] < 0.6 * slope["stderr"]


def test_equidispersed_counts_give_a_negligible_dispersion():
    rng = np.random.default_rng(4)
    mu = stats.kinetic_rate(RADII) * 1000.0
    df = pd.DataFrame({"radius": RADII, "count": rng.poisson(mu), "t_window": 1000.0})
    reg = stats.regress_counts(df, rule="mirror")
    od = reg.overdispersion()
    assert od["alpha"] < 0.02
    assert od["lr_pvalue"] > 0.01
    assert od["pearson_dispersion"] == pytest.approx(1.0, abs=0.15)
    pred = reg.predict([0.01, 0.02], t_window=1000.0)
    np.testing.assert_allclose(pred["kinetic"], stats.kinetic_rate(np.array([0.01, 0.02])) * 1000)
    np.testing.assert_allclose(pred["poisson"], pred["kinetic"], rtol=0.05)


def test_ols_line_is_the_papers_line_of_mean_count_on_radius():
    rng = np.random.default_rng(5)
    df = pd.DataFrame(
        {"radius": RADII, "count": rng.poisson(1.7 * RADII * 2000), "t_window": 2000.0}
    )
    reg = stats.regress_counts(df)
    means = df.groupby("radius")["count"].mean()
    slope, intercept = np.polyfit(means.index, means.to_numpy(), 1)
    b = np.asarray(reg.ols.params)
    assert b[1] * 2000 == pytest.approx(slope, rel=1e-9)
    assert b[0] * 2000 == pytest.approx(intercept, rel=1e-6, abs=1e-9)
    pred = reg.predict(0.02, t_window=2000.0)
    assert pred.loc[0, "ols"] == pytest.approx(intercept + slope * 0.02)
    assert "OLS" in reg.summary() and "alpha" in reg.summary()
    assert list(reg.by_radius.index) == sorted(set(RADII))


def test_linear_covariate_option_changes_the_count_models():
    rng = np.random.default_rng(6)
    df = pd.DataFrame({"radius": RADII, "count": rng.poisson(RADII * 1000), "t_window": 1000.0})
    reg = stats.regress_counts(df, covariate="radius")
    assert ("poisson", "radius") in reg.coefficients().index
    assert "kinetic" not in reg.predict(0.01).columns


def test_two_rows_give_estimates_with_a_warning_naming_the_missing_degrees_of_freedom():
    # kicktimes decides: no residual degrees of freedom -> NaN standard errors, and a warning
    df = pd.DataFrame({"radius": [0.01, 0.02], "count": [172, 315], "t_window": 100.0})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        reg = stats.regress_counts(df)
    messages = [str(w.message) for w in caught]
    assert [w.category for w in caught] == [stats.FitWarning], messages  # no numpy warnings
    assert "no residual degrees of freedom" in messages[0]
    assert "at least 3 radii" in messages[0]
    assert any("no residual degrees of freedom" in w for w in reg.warnings)
    coef = reg.coefficients()
    assert np.isfinite(coef["estimate"]).all()
    # the Poisson GLM's errors need no residual degrees of freedom (its scale is fixed)
    assert np.isfinite(coef.loc["poisson", "stderr"]).all()
    assert np.isnan(coef.loc["ols", "stderr"]).all()
    assert np.isnan(coef.loc["negbin", "stderr"]).all()
    assert math.isnan(reg.overdispersion()["pearson_dispersion"])  # was inf
    # two rows: the Poisson line passes through both points, so the NB MLE is on alpha = 0
    # and is the Poisson fit, exactly (no optimiser, nothing a BLAS kernel could change)
    assert reg.negbin is None and reg.alpha == 0.0
    np.testing.assert_array_equal(reg.params("negbin")[:2], reg.params("poisson"))
    assert reg.converged


def test_one_radius_is_refused_naming_the_radius_and_the_remedy():
    df = pd.DataFrame({"radius": [0.01] * 4, "count": [172, 160, 133, 157], "t_window": 100.0})
    with pytest.raises(ValueError, match=r"takes one value \(0\.01\): no slope to estimate; "
                       "give at least two radii"):
        stats.regress_counts(df)


def test_three_rows_leave_the_negative_binomial_no_degrees_of_freedom_and_say_so():
    df = pd.DataFrame({"radius": [0.01, 0.02, 0.03], "count": [150, 340, 470],
                       "t_window": 100.0})
    with pytest.warns(stats.FitWarning, match="3 rows leave the negative binomial"):
        reg = stats.regress_counts(df)
    coef = reg.coefficients()
    assert np.isnan(coef.loc["negbin", "stderr"]).all()
    assert np.isfinite(coef.loc["ols", "stderr"]).all()  # 3 radii: one degree of freedom
    assert np.isfinite(coef.loc["poisson", "stderr"]).all()


def test_standard_errors_near_a_singularity_do_not_depend_on_what_statsmodels_returns(
        monkeypatch):
    """A BLAS kernel may turn a singular Hessian into finite numbers or NaN: kicktimes'
    answer must be the same either way (issue 47)."""
    from statsmodels.discrete.discrete_model import NegativeBinomialResults
    from statsmodels.regression.linear_model import RegressionResults

    df = pd.DataFrame({"radius": [0.01, 0.02, 0.03], "count": [150, 340, 470],
                       "t_window": 100.0})
    two = df.iloc[:2]
    answers = []
    for fake in (None, 0.25, np.nan):
        with monkeypatch.context() as m:
            if fake is not None:
                def cov(self, *args, _v=fake, **kwargs):
                    k = len(np.asarray(self.params))
                    return np.full((k, k), _v) + np.eye(k)
                m.setattr(NegativeBinomialResults, "cov_params", cov)
                m.setattr(RegressionResults, "cov_params", cov)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                answers.append([stats.regress_counts(d).coefficients() for d in (df, two)])
    (three, two_rows) = answers[0]
    assert np.isnan(three.loc["negbin", "stderr"]).all()
    assert np.isnan(two_rows.loc[["ols", "negbin"], "stderr"]).all()
    for other_three, other_two in answers[1:]:
        # what kicktimes decides is undefined stays so, whatever statsmodels returned
        pd.testing.assert_frame_equal(other_three.loc[["negbin"]], three.loc[["negbin"]])
        pd.testing.assert_frame_equal(other_two.loc[["ols", "negbin"]],
                                      two_rows.loc[["ols", "negbin"]])


def test_equidispersed_data_put_the_negative_binomial_on_its_boundary_with_a_note():
    # under-dispersed counts (binomial): the score in alpha at 0 is negative
    rng = np.random.default_rng(12)
    r = np.repeat([0.01, 0.02, 0.03], 40)
    df = pd.DataFrame({"radius": r, "count": rng.binomial(400, r * 5), "t_window": 100.0})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a boundary is expected, not a problem
        reg = stats.regress_counts(df)
    coef = reg.coefficients()
    assert reg.negbin is None and reg.alpha == 0.0
    np.testing.assert_array_equal(coef.loc["negbin", "stderr"].to_numpy()[:2],
                                  coef.loc["poisson", "stderr"].to_numpy())
    assert math.isnan(coef.loc[("negbin", "alpha"), "stderr"])
    assert any("boundary 0" in w for w in reg.warnings)
    assert reg.overdispersion()["lr_pvalue"] == 1.0
    assert reg.aic["negbin"] == pytest.approx(reg.aic["poisson"] + 2.0)


def test_two_radii_with_more_rows_warn_about_the_exact_ols_line_only():
    rng = np.random.default_rng(9)
    r = np.repeat([0.01, 0.02], 2)
    df = pd.DataFrame({"radius": r, "count": rng.poisson(r * 16000), "t_window": 100.0})
    with pytest.warns(stats.FitWarning, match="the OLS line through 2 radii is exact"):
        reg = stats.regress_counts(df)
    problem = next(w for w in reg.warnings if "degrees of freedom" in w)
    assert "Poisson" not in problem and "negative binomial" not in problem
    assert np.isfinite(reg.overdispersion()["pearson_dispersion"])


@pytest.mark.parametrize(
    ("frame", "match"),
    [
        (pd.DataFrame({"radius": [0.01, 0.02], "count": [1, 2]}), "t_window"),
        (pd.DataFrame({"radius": [0.01, 0.02], "count": [1, -2], "t_window": 1.0}), "count"),
        (pd.DataFrame({"radius": [0.01, 0.02], "count": [1, 2.5], "t_window": 1.0}), "count"),
        (pd.DataFrame({"radius": [0.01, 0.6], "count": [1, 2], "t_window": 1.0}), "radius"),
        (pd.DataFrame({"radius": [0.01, 0.02], "count": [1, 2], "t_window": 0.0}), "t_window"),
        (pd.DataFrame({"radius": [0.01, np.nan], "count": [1, 2], "t_window": 1.0}), "radius"),
        (pd.DataFrame({"radius": [0.01, 0.01], "count": [1, 2], "t_window": 1.0}), "two radii"),
    ],
)
def test_regress_counts_rejects_bad_frames(frame, match):
    with pytest.raises(ValueError, match=match):
        stats.regress_counts(frame)


def test_regress_counts_rejects_non_frames_and_bad_options():
    with pytest.raises(TypeError, match="DataFrame"):
        stats.regress_counts({"radius": [0.1], "count": [1], "t_window": [1.0]})
    df = pd.DataFrame({"radius": [0.01, 0.02], "count": [1, 2], "t_window": 1.0})
    with pytest.raises(ValueError, match="covariate"):
        stats.regress_counts(df, covariate="r2")
    with pytest.raises(ValueError, match="rule"):
        stats.regress_counts(df, rule="hard")


def test_the_boundary_rule_agrees_with_the_optimiser_from_many_starts():
    """Where the score in alpha at 0 is <= 0, no start of statsmodels' optimiser finds a
    higher likelihood than the Poisson fit (beyond 1e-4, an LR statistic of 2e-4: the
    Poisson fit's own convergence tolerance); where it is > 0, the fit has alpha > 0 and a
    higher likelihood (30 data sets from equidispersed to overdispersed)."""
    from statsmodels.discrete.discrete_model import NegativeBinomial

    rng = np.random.default_rng(47)
    seen = set()
    for k in range(30):
        r = np.repeat([0.01, 0.02, 0.03], 15)
        mu = 1600 * r
        alpha = [0.0, 0.002, 0.01][k % 3]
        y = rng.poisson(mu) if alpha == 0 else nb2_counts(mu, alpha, rng)
        df = pd.DataFrame({"radius": r, "count": y, "t_window": 1.0})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reg = stats.regress_counts(df)
            model = NegativeBinomial(y, np.column_stack([np.ones(r.size), np.log(r)]),
                                     loglike_method="nb2")
            best = max(model.fit(start_params=np.r_[reg.params("poisson"), a0], disp=0,
                                 maxiter=500).llf for a0 in (1e-4, 0.01, 0.1, 1.0))
        boundary = reg.negbin is None
        seen.add(boundary)
        if boundary:
            assert best <= reg.loglik["poisson"] + 1e-4
        else:
            assert reg.alpha > 0 and reg.loglik["negbin"] >= best - 1e-4
            assert reg.loglik["negbin"] > reg.loglik["poisson"]
    assert seen == {True, False}  # both branches were exercised


def test_the_sticky_rule_is_a_rate_above_five_kinetic_rates():
    g = stats.kinetic_rate(np.array([0.01, 0.02]))
    assert stats.STICKY_FACTOR == 5.0
    assert stats.is_sticky(5.0 * g * (1 + 1e-12), g).tolist() == [True, True]
    assert stats.is_sticky(5.0 * g, g).tolist() == [False, False]  # strictly above
    assert stats.is_sticky(np.nan, g[0]) is False
    assert stats.is_sticky(3.0, 1.0, factor=2.0) is True
    # the rule every study applies: a run of 600 collisions in 1000 time units at r = 0.02
    # (kinetic rate 0.0329) is sticky, one of 30 is not
    assert [stats.is_sticky(n / 1000.0, stats.kinetic_rate(0.02)) for n in (30, 600)] == [
        False, True]
