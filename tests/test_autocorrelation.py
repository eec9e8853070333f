"""Specification of the paper's autocorrelation and of the boundary-angle series."""

from __future__ import annotations

import types
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs
from numpy.testing import assert_allclose, assert_array_equal
from statsmodels.tsa.stattools import acf

from kicktimes.diagnostics import (
    UndefinedDiagnosticWarning,
    autocorrelation,
    autocorrelation_function,
    autocorrelation_many,
    boundary_angles,
    decorrelation_lag,
    integrated_autocorrelation_time,
)


def paper_formula(x: np.ndarray, lag: int) -> float:
    """R_l exactly as written in the paper (1-based sums rewritten 0-based)."""
    n = len(x)
    xbar = sum(x) / n
    num = sum((x[i] - xbar) * (x[i + lag] - xbar) for i in range(n - lag))
    den = sum((x[i] - xbar) ** 2 for i in range(n))
    return num / den


def ar1(phi: float, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    e = rng.normal(size=n)
    x = np.empty(n)
    x[0] = e[0] / np.sqrt(1.0 - phi**2)  # stationary start
    for t in range(1, n):
        x[t] = phi * x[t - 1] + e[t]
    return x


def point_billiard_sin_theta(n_hits: int, seed: int, kick_prob: float = 0.0) -> np.ndarray:
    """sin(theta) at the boundary hits of a point particle in the unit disk.

    Without kicks the orbit is integrable and sin(theta) = x × v is constant up to
    round-off; with probability kick_prob per hit the direction is redrawn.
    """
    rng = np.random.default_rng(seed)
    x = np.array([0.3, -0.2])
    a = rng.uniform(0.0, 2.0 * np.pi)
    v = np.array([np.cos(a), np.sin(a)])
    out = np.empty(n_hits)
    for k in range(n_hits):
        b = x @ v
        x = x + (-b + np.sqrt(b * b - x @ x + 1.0)) * v
        out[k] = x[0] * v[1] - x[1] * v[0]
        nrm = x / np.linalg.norm(x)
        v = v - 2.0 * (v @ nrm) * nrm
        if rng.uniform() < kick_prob:
            a = np.arctan2(x[1], x[0]) + np.pi + rng.uniform(-0.5 * np.pi, 0.5 * np.pi)
            v = np.array([np.cos(a), np.sin(a)])
    return out


# ------------------------------------------------------------------ the definition


@pytest.mark.parametrize("lag", [0, 1, 2, 7, 49])
def test_equals_the_paper_formula(lag):
    x = np.random.default_rng(1).normal(size=50).cumsum()
    assert_allclose(autocorrelation(x, lag), paper_formula(x, lag), rtol=1e-12, atol=1e-14)


def test_equals_statsmodels_acf_with_its_default_normalisation():
    for seed, x in enumerate([ar1(0.7, 5000, 2), np.random.default_rng(3).uniform(size=777)]):
        ref = acf(x, nlags=20, adjusted=False, fft=False)
        ours = [autocorrelation(x, lag) for lag in range(21)]
        assert_allclose(ours, ref, rtol=1e-10, atol=1e-13, err_msg=f"series {seed}")


def test_lag_zero_is_one():
    assert autocorrelation(np.array([0.1, -2.0, 3.0]), 0) == pytest.approx(1.0, abs=1e-15)


def test_known_small_values():
    assert autocorrelation([1.0, 2.0, 3.0, 4.0]) == 0.25
    assert autocorrelation([1.0, -1.0, 1.0, -1.0]) == -0.75


@pytest.mark.parametrize("phi", [-0.6, 0.0, 0.3, 0.8])
def test_ar1_series_has_lag_one_autocorrelation_phi(phi):
    n = 40_000
    r1 = autocorrelation(ar1(phi, n, seed=4), 1)
    se = np.sqrt((1.0 - phi**2) / n)
    assert abs(r1 - phi) < 4.0 * se + (1.0 + 4.0 * abs(phi)) / n  # + the O(1/N) bias


def test_ar1_higher_lags_decay_as_phi_to_the_lag():
    x = ar1(0.8, 40_000, seed=5)
    for lag in (2, 3, 5):
        assert autocorrelation(x, lag) == pytest.approx(0.8**lag, abs=0.03)


def test_invariant_under_affine_changes_of_the_series():
    x = np.random.default_rng(6).normal(size=300)
    ref = autocorrelation(x, 2)
    assert autocorrelation(3.0 * x + 10.0, 2) == pytest.approx(ref, rel=1e-10)
    assert autocorrelation(-x, 2) == pytest.approx(ref, rel=1e-12)


# ------------------------------------------------------------------ undefined values


def test_constant_series_gives_nan_with_a_warning_that_says_why():
    with pytest.warns(UndefinedDiagnosticWarning, match="constant series"):
        assert np.isnan(autocorrelation(np.full(100, 0.42)))


def acf_and_reason(series, lag=1, **options):
    """`autocorrelation`'s value and its ``.reason``, the undefined-value warning filtered
    (the tests of the warning call `autocorrelation` itself)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
        value = autocorrelation(series, lag, **options)
    return value, value.reason


def test_an_undefined_value_is_nan_with_its_reason_and_a_warning():
    with pytest.warns(UndefinedDiagnosticWarning, match="constant series"):
        value = autocorrelation(np.zeros(10))
    assert np.isnan(value) and isinstance(value, float)
    assert value.reason.startswith("constant series") and value.n == 10 and value.lag == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a defined value warns of nothing
        value = autocorrelation(np.arange(10.0))
    assert value.reason is None and np.isfinite(value)
    assert value + 0.0 == float(value) and type(value + 0.0) is float
    assert "reason" not in value.summary() and "constant series" in acf_and_reason(
        np.zeros(10))[0].summary()


def test_return_reason_still_returns_the_tuple_for_one_release_with_a_deprecation_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error", UndefinedDiagnosticWarning)  # and no undefined warning
        with pytest.warns(DeprecationWarning, match=r"return_reason=True\) is deprecated.*"
                          r"\.reason"):
            value, reason = autocorrelation(np.zeros(10), return_reason=True)
    assert type(value) is float and np.isnan(value) and reason.startswith("constant series")


def test_round_off_around_a_constant_is_still_constant():
    # the unkicked (integrable) billiard: sin(theta) is conserved up to round-off, and
    # dividing round-off by round-off must not produce a number
    theta = np.arcsin(point_billiard_sin_theta(3000, seed=7))
    assert 0.0 < theta.std() < 1e-12
    value, reason = acf_and_reason(theta)
    assert np.isnan(value) and reason.startswith("constant")


def test_kicked_billiard_angles_are_valid_and_tolerance_is_adjustable():
    theta = np.arcsin(point_billiard_sin_theta(3000, seed=8, kick_prob=0.05))
    assert np.isfinite(autocorrelation(theta))
    tiny = 0.5 + 1e-13 * np.random.default_rng(9).normal(size=500)
    assert np.isnan(acf_and_reason(tiny)[0])
    assert np.isfinite(autocorrelation(tiny, rtol=0.0, atol=0.0))  # exact zero only


def test_warning_can_be_silenced_for_ensembles():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
        assert np.isnan(autocorrelation(np.ones(5)))


@pytest.mark.parametrize(("n", "lag"), [(0, 1), (1, 1), (3, 3), (3, 5), (1, 0)])
def test_too_short_series_give_nan_with_reason(n, lag):
    value, reason = acf_and_reason(np.arange(float(n)), lag)
    assert np.isnan(value)
    assert reason.startswith("series too short")
    with pytest.warns(UndefinedDiagnosticWarning, match="too short"):
        autocorrelation(np.arange(float(n)), lag)


# ------------------------------------------------------------------ batches


def test_many_equals_one_by_one_for_ragged_series():
    rng = np.random.default_rng(10)
    series = [rng.normal(size=k).cumsum() for k in (5, 50, 500)] + [np.ones(7), [1.0]]
    df = autocorrelation_many(series, lag=2)
    for k, x in enumerate(series):
        value, reason = acf_and_reason(x, 2)
        assert_array_equal(df["autocorrelation"].iloc[k], value)
        assert df["valid"].iloc[k] == (reason is None)
    assert df["reason"].tolist() == ["ok", "ok", "ok", "constant", "too_short"]
    assert df["n"].tolist() == [5, 50, 500, 7, 1]
    assert df.attrs["lag"] == 2


def test_many_accepts_a_2d_array_and_a_mapping():
    arr = np.random.default_rng(11).normal(size=(4, 30))
    df = autocorrelation_many(arr)
    assert_allclose(df["autocorrelation"], [autocorrelation(row) for row in arr], rtol=0)
    by_ic = autocorrelation_many({17: arr[0], 23: arr[1]})
    assert by_ic.index.tolist() == [17, 23]
    assert by_ic.loc[23, "autocorrelation"] == autocorrelation(arr[1])


def test_many_ensemble_mean_counts_valid_values():
    series = [ar1(0.5, 2000, seed=s) for s in range(20)] + [np.zeros(100)] * 5
    df = autocorrelation_many(series)
    assert df["valid"].sum() == 20
    assert df["autocorrelation"].mean() == pytest.approx(0.5, abs=0.05)  # NaN skipped


def test_many_rejects_non_finite_values_naming_the_series():
    with pytest.raises(ValueError, match=r"series\[1\]: must be finite; element 2"):
        autocorrelation_many([np.ones(4), [0.0, 1.0, np.nan]])
    with pytest.raises(ValueError, match="row 1, element 0"):
        autocorrelation_many(np.array([[1.0, 2.0], [np.inf, 1.0]]))
    with pytest.raises(TypeError, match="series"):
        autocorrelation_many(3.0)


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_series_raise_value_error(bad):
    with pytest.raises(ValueError, match="series: must be finite; element 1"):
        autocorrelation([0.0, bad, 1.0])


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"series": np.zeros((3, 3))}, ValueError, "1-D"),
        ({"series": ["a", "b"]}, TypeError, "series"),
        ({"series": np.array([1j, 2j])}, TypeError, "series"),
        ({"lag": -1}, ValueError, "lag: must be >= 0"),
        ({"lag": 1.5}, TypeError, "lag"),
        ({"rtol": -1e-3}, ValueError, "rtol"),
        ({"atol": np.nan}, ValueError, "atol"),
    ],
)
def test_bad_arguments_raise(kwargs, error, match):
    args = {"series": np.arange(5.0), **kwargs}
    with pytest.raises(error, match=match):
        autocorrelation(**args)


# ------------------------------------------------------------------ boundary angles


def two_particle_table(shuffle: bool = False) -> pd.DataFrame:
    rng = np.random.default_rng(12)
    n = 200
    df = pd.DataFrame(
        {
            "time": np.sort(rng.uniform(0.0, 50.0, n)),
            "particle": rng.integers(0, 2, n).astype(np.int8),
            "s": rng.uniform(0.0, 2 * np.pi, n),
            "sin_theta": rng.uniform(-1.0, 1.0, n),
        }
    )
    return df.sample(frac=1.0, random_state=1) if shuffle else df


def test_angles_of_the_tracked_disk_in_time_order():
    df = two_particle_table()
    run = types.SimpleNamespace(boundary=df, track=1)
    expected = np.arcsin(df.loc[df["particle"] == 1, "sin_theta"].to_numpy())
    assert_array_equal(boundary_angles(run), expected)
    assert_array_equal(
        boundary_angles(run, particle=0),
        np.arcsin(df.loc[df["particle"] == 0, "sin_theta"].to_numpy()),
    )
    assert_array_equal(boundary_angles(df), boundary_angles(run, particle=0))  # disk 0


def test_unsorted_records_are_put_in_time_order():
    df = two_particle_table()
    shuffled = two_particle_table(shuffle=True)
    assert_array_equal(boundary_angles(shuffled, particle=1), boundary_angles(df, particle=1))


def test_one_particle_table_uses_every_row():
    df = two_particle_table().drop(columns="particle")
    run = types.SimpleNamespace(boundary=df)
    assert_array_equal(boundary_angles(run), np.arcsin(df["sin_theta"].to_numpy()))
    assert_array_equal(boundary_angles(run, particle=0), boundary_angles(run))
    with pytest.raises(ValueError, match="no 'particle' column"):
        boundary_angles(run, particle=1)


class _RawRun:
    """A run exposing the raw boundary log; building its DataFrame is an error."""

    def __init__(self, df: pd.DataFrame, track=None):
        self.boundary_log = types.SimpleNamespace(
            time=df["time"].to_numpy(),
            particle=df["particle"].to_numpy(),
            x=np.zeros(len(df)),
            y=np.zeros(len(df)),
            sin_theta=df["sin_theta"].to_numpy(),
        )
        if track is not None:
            self.track = track

    @property
    def boundary(self):
        raise AssertionError("the boundary DataFrame should not be built")


def test_raw_boundary_log_is_read_without_building_the_table():
    df = two_particle_table()
    assert_array_equal(boundary_angles(_RawRun(df, track=1)), boundary_angles(df, particle=1))
    one = df.assign(particle=np.int8(0))
    assert_array_equal(boundary_angles(_RawRun(one)), np.arcsin(one["sin_theta"].to_numpy()))


def test_real_run_records_work():
    from kicktimes.billiard import runs

    df = two_particle_table()
    log = runs.BoundaryLog(
        df["time"].to_numpy(),
        df["particle"].to_numpy(),
        np.cos(df["s"].to_numpy()),
        np.sin(df["s"].to_numpy()),
        df["sin_theta"].to_numpy(),
    )
    common = dict(
        r=0.03,
        t_max=50.0,
        sampling=None,
        tau=None,
        n_steps=None,
        ic=np.zeros((2, 4)),
        final_state=np.zeros((2, 4)),
        boundary_log=log,
        sample_times=np.empty(0),
        samples=np.empty((0, 2)),
    )
    run = runs.TwoParticleRun(**common, track=1)
    assert_array_equal(boundary_angles(run), boundary_angles(df, particle=1))


@pytest.mark.parametrize("seed", range(6))
def test_one_pass_selection_gives_what_masking_and_sorting_give(seed):
    # run records take a one-pass kernel (float64 columns, int8 disks); anything else,
    # and any record it finds unsorted, takes the general path: both must agree
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    times = np.round(rng.uniform(0.0, 20.0, n), 1)  # ties
    if seed % 2 == 0:
        times = np.sort(times)
    df = pd.DataFrame({"time": times, "particle": rng.integers(0, 2, n).astype(np.int8),
                       "s": np.zeros(n), "sin_theta": rng.uniform(-1.0, 1.0, n)})
    for particle in (0, 1):
        chosen = df[df["particle"] == particle]
        expected = np.arcsin(chosen["sin_theta"].to_numpy()[
            np.argsort(chosen["time"].to_numpy(), kind="stable")])
        got = boundary_angles(_RawRun(df, track=particle))
        assert_array_equal(got, expected)
        wide = df.astype({"particle": np.int64})  # not the kernel's dtype: general path
        assert_array_equal(boundary_angles(wide, particle=particle), expected)


def test_round_off_beyond_one_is_clipped_but_real_violations_raise():
    df = pd.DataFrame({"time": [0.0, 1.0], "s": [0.0, 1.0], "sin_theta": [1.0 + 1e-15, -1.0]})
    assert_array_equal(boundary_angles(df), [np.pi / 2, -np.pi / 2])
    with pytest.raises(ValueError, match=r"sin_theta: must lie in \[-1, 1\]"):
        boundary_angles(df.assign(sin_theta=[1.1, 0.0]))
    with pytest.raises(ValueError, match="sin_theta: must be finite"):
        boundary_angles(df.assign(sin_theta=[np.nan, 0.0]))


def test_bad_runs_and_particles_raise():
    df = two_particle_table()
    with pytest.raises(ValueError, match="particle: must be 0 or 1"):
        boundary_angles(df, particle=2)
    with pytest.raises(ValueError, match="sin_theta"):
        boundary_angles(df.drop(columns="sin_theta"))
    with pytest.raises(TypeError, match="run"):
        boundary_angles(np.zeros(3))


def test_angle_series_feeds_the_autocorrelation():
    theta = boundary_angles(
        pd.DataFrame({"time": np.arange(3000.0), "sin_theta": point_billiard_sin_theta(3000, 13)})
    )
    value, reason = acf_and_reason(theta)
    assert np.isnan(value) and reason.startswith("constant")


def test_simulated_runs_unkicked_disk_is_constant_and_two_disks_are_not():
    import kicktimes as kt

    ic = kt.initial_conditions(1, 0.03, rng=3)[0]
    two = kt.simulate_two_particle(ic, 0.03, n_steps=5000, tau=0.2)
    one = kt.simulate_one_particle(ic[0], 0.03, n_steps=5000, tau=0.2)
    value, reason = acf_and_reason(boundary_angles(one))
    assert np.isnan(value) and reason.startswith("constant")  # integrable: sin(theta) fixed
    r1 = autocorrelation(boundary_angles(two))
    assert np.isfinite(r1) and -1.0 <= r1 <= 1.0


# ------------------------------------------------------------------ extreme magnitudes


@pytest.mark.parametrize("scale", [1e308, 1e200, 1e-200, 5e-324])
def test_huge_and_tiny_series_do_not_overflow_or_underflow(scale):
    x = np.array([1.0, -1.0, 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # neither NaN nor an overflow warning
        value = autocorrelation(x * scale, rtol=0.0, atol=0.0)
    assert value == pytest.approx(-2.0 / 3.0, rel=1e-15)


def test_scaling_is_exact_so_ordinary_values_are_unchanged():
    x = ar1(0.5, 5000, seed=3)
    for lag in (1, 2, 5):
        for power in (600, -600, 1000):  # a power of two: exactly the same sums, scaled
            scaled = autocorrelation(x * 2.0**power, lag, atol=0.0)  # atol is absolute
            assert scaled == autocorrelation(x, lag)
        assert autocorrelation(x, lag) == pytest.approx(paper_formula(x, lag), abs=1e-12)


# ------------------------------------------------------------------ the curve R_1..R_L


def test_curve_is_bitwise_the_lag_by_lag_autocorrelation():
    x = ar1(0.8, 3000, seed=4)
    curve = autocorrelation_function(x, 25)
    assert curve.shape == (25,)
    assert_array_equal(curve, [autocorrelation(x, lag) for lag in range(1, 26)])


@settings(max_examples=150, deadline=None)
@given(
    n=hs.integers(1, 120),
    max_lag=hs.integers(1, 40),
    scale_exp=hs.integers(-200, 200),
    kind=hs.sampled_from(["noise", "walk", "nearly_constant", "constant"]),
    seed=hs.integers(0, 2**32 - 1),
)
def test_curve_is_bitwise_lag_by_lag_for_any_series(n, max_lag, scale_exp, kind, seed):
    # the curve shares the sums of squares of all lags (a prefix of blocks); every value
    # and every NaN must still be exactly what autocorrelation gives lag by lag
    rng = np.random.default_rng(seed)
    x = rng.normal(size=n)
    if kind == "walk":
        x = np.cumsum(x)
    elif kind == "nearly_constant":
        x = 0.3 + 1e-13 * x
    elif kind == "constant":
        x = np.full(n, 0.3)
    x = x * 2.0**scale_exp
    curve, _ = autocorrelation_function(x, max_lag, return_reason=True)
    expected = [acf_and_reason(x, lag)[0] for lag in range(1, max_lag + 1)]
    assert_array_equal(curve.view(np.int64), np.array(expected).view(np.int64))


def test_curve_equals_statsmodels_acf():
    x = ar1(-0.4, 2000, seed=5)
    assert_allclose(autocorrelation_function(x, 20), acf(x, nlags=20)[1:], atol=1e-12)


def test_curve_of_ar1_decays_as_phi_to_the_lag():
    x = ar1(0.7, 40_000, seed=6)
    curve = autocorrelation_function(x, 8)
    assert_allclose(curve, 0.7 ** np.arange(1, 9), atol=0.03)


def test_curve_of_a_constant_series_is_nan_with_one_warning():
    with pytest.warns(UndefinedDiagnosticWarning, match="constant series") as record:
        curve = autocorrelation_function(np.full(50, 0.3), 5)
    assert len(record) == 1 and np.isnan(curve).all()
    curve, reason = autocorrelation_function(np.full(50, 0.3), 5, return_reason=True)
    assert np.isnan(curve).all() and reason.startswith("constant series")


def test_curve_of_a_short_series_is_nan_beyond_its_length():
    x = np.array([1.0, 3.0, 2.0, 5.0])
    curve, reason = autocorrelation_function(x, 6, return_reason=True)
    assert_array_equal(curve[:3], [autocorrelation(x, lag) for lag in (1, 2, 3)])
    assert np.isnan(curve[3:]).all() and "lags 4..6 are NaN" in reason
    curve, reason = autocorrelation_function([1.0], 2, return_reason=True)
    assert np.isnan(curve).all() and "N = 1 < 2" in reason
    _, reason = autocorrelation_function(x, 3, return_reason=True)
    assert reason is None


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"max_lag": 0}, ValueError, "max_lag: must be >= 1"),
        ({"max_lag": 2.0}, TypeError, "max_lag"),
        ({"rtol": -1.0}, ValueError, "rtol"),
    ],
)
def test_curve_bad_arguments_raise(kwargs, error, match):
    with pytest.raises(error, match=match):
        autocorrelation_function(np.arange(10.0), **kwargs)


def test_curve_rejects_non_finite_series():
    with pytest.raises(ValueError, match="element 1"):
        autocorrelation_function([0.0, np.inf, 1.0], 2)


# ------------------------------------------------------------------ decay summaries


def test_decorrelation_lag_is_the_first_lag_below_the_threshold():
    assert decorrelation_lag([0.9, 0.6, 0.3, 0.1]) == 3.0
    assert decorrelation_lag([0.9, 0.6, 0.3, 0.1], threshold=0.7) == 2.0
    assert decorrelation_lag([0.2]) == 1.0
    assert decorrelation_lag([0.9, np.exp(-1.0), 0.3]) == 3.0  # "below" is strict


def test_decorrelation_lag_of_ar1_is_about_minus_one_over_log_phi():
    x = ar1(0.9, 40_000, seed=7)  # R_l = 0.9^l < 1/e from l = 10 (0.9^10 = 0.349)
    assert decorrelation_lag(autocorrelation_function(x, 30)) in (9.0, 10.0, 11.0)


def test_decorrelation_lag_not_reached_or_undefined_is_nan_with_reason():
    with pytest.warns(UndefinedDiagnosticWarning, match="not reached"):
        assert np.isnan(decorrelation_lag([0.9, 0.8]))
    value, reason = decorrelation_lag([0.9, np.nan, 0.1], return_reason=True)
    assert np.isnan(value) and "R_2 is undefined" in reason


def test_integrated_time_truncates_before_the_first_non_positive_lag():
    assert integrated_autocorrelation_time([0.5, 0.25, -0.1, 0.2]) == 1.25
    assert integrated_autocorrelation_time([0.5, 0.0, 0.4]) == 1.0
    assert integrated_autocorrelation_time([-0.2, 0.9]) == 0.5
    value, note = integrated_autocorrelation_time([0.5, 0.25], return_reason=True)
    assert value == 1.25 and "lower bound" in note
    assert integrated_autocorrelation_time([0.5, -0.1], return_reason=True) == (1.0, None)


def test_integrated_time_of_ar1_is_one_plus_phi_over_two_one_minus_phi():
    phi = 0.6
    x = ar1(phi, 100_000, seed=8)
    tau = integrated_autocorrelation_time(autocorrelation_function(x, 60))
    assert tau == pytest.approx((1 + phi) / (2 * (1 - phi)), rel=0.1)


def test_integrated_time_with_an_undefined_lag_first_is_nan_with_reason():
    with pytest.warns(UndefinedDiagnosticWarning, match="undefined"):
        assert np.isnan(integrated_autocorrelation_time([0.5, np.nan, -0.1]))


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (lambda: decorrelation_lag([]), ValueError, "acf: expected a non-empty"),
        (lambda: decorrelation_lag([[0.5]]), ValueError, "acf"),
        (lambda: decorrelation_lag(["a"]), TypeError, "acf"),
        (lambda: decorrelation_lag([0.5, np.inf]), ValueError, "element 1"),
        (lambda: decorrelation_lag([0.5], threshold=2.0), ValueError, "threshold"),
        (lambda: decorrelation_lag([0.5], threshold=np.nan), ValueError, "threshold"),
        (lambda: decorrelation_lag([0.5], threshold="x"), TypeError, "threshold"),
        (lambda: integrated_autocorrelation_time([]), ValueError, "acf"),
    ],
)
def test_decay_summaries_reject_bad_input(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_acf_curve_is_autocorrelation_lag_by_lag_with_its_reasons():
    from kicktimes.diagnostics import (
        UndefinedDiagnosticWarning,
        acf_curve,
        autocorrelation_function,
    )

    x = np.random.default_rng(4).normal(size=12)
    curve = acf_curve(x, 15)
    with pytest.warns(UndefinedDiagnosticWarning):  # the function warns; the curve does not
        np.testing.assert_array_equal(curve.acf, autocorrelation_function(x, 15))
    for lag in range(1, 16):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
            value, reason = acf_and_reason(x, lag)
        assert np.array_equal(curve.acf[lag - 1], value, equal_nan=True)
        assert curve.lag_reasons[lag - 1] == reason
    assert "series too short" in curve.reason
    assert acf_curve(np.ones(5), 2).reason.startswith("constant series")


def test_acf_curve_is_a_frozen_result_that_still_unpacks_for_one_release():
    import dataclasses

    from kicktimes.diagnostics import acf_curve

    curve = acf_curve([1.0, 2.0, 1.0, 2.0], 4)
    with pytest.raises(dataclasses.FrozenInstanceError):
        curve.reason = "x"
    with pytest.warns(DeprecationWarning, match=r"\.acf, \.lag_reasons, \.reason"):
        acf, lag_reasons, reason = curve
    assert acf is curve.acf and lag_reasons is curve.lag_reasons and reason is curve.reason
    with pytest.warns(DeprecationWarning, match="AcfCurve as a tuple"):
        assert curve[0] is curve.acf and len(curve) == 3
    table = curve.to_frame()
    assert table.columns.tolist() == ["lag", "acf", "reason"]
    assert table["lag"].tolist() == [1, 2, 3, 4]
    assert table["reason"].iloc[3] == curve.lag_reasons[3] and "max_lag: 4" in curve.summary()
