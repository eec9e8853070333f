"""Property tests of the public statistics API (hypothesis).

The contract under test, for any input: a call either returns finite, sane numbers (or a
result that flags its non-convergence), or raises ValueError/TypeError naming the
argument; it never returns a silent NaN/-inf, never leaks another exception type, and
finishes within a time limit. Example counts are kept small so the default suite stays
fast.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kicktimes import stats

SETTINGS = settings(
    max_examples=20,
    deadline=None,  # timed by hand: the first call compiles numba kernels
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,
    database=None,
)
TIME_LIMIT = 20.0  # seconds per call; generous for a shared two-core machine

# positive interval lengths over a wide but finite range, duplicates likely
lengths = st.one_of(
    st.floats(min_value=1e-6, max_value=1e6, allow_nan=False, allow_infinity=False),
    st.sampled_from([1.0, 2.0, 1e-300, 1e300]),
)
samples = st.lists(lengths, min_size=0, max_size=60)
bad_values = st.sampled_from([np.nan, np.inf, -1.0, 0.0, "x", None])


def _call(fun, *args, names, **kwargs):
    """Run ``fun``; return its result, or None if it refused the input properly."""
    start = time.monotonic()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", stats.FitWarning)
            out = fun(*args, **kwargs)
    except (ValueError, TypeError) as exc:
        message = str(exc)
        assert any(name in message for name in names), f"{message!r} names none of {names}"
        assert "np.float64" not in message
        out = None
    assert time.monotonic() - start < TIME_LIMIT
    return out


def _check_fit(fit):
    assert isinstance(fit.converged, bool)
    assert isinstance(fit.warnings, tuple)
    if fit.converged:
        assert math.isfinite(fit.loglik)
        assert all(math.isfinite(v) for v in fit.params.values())
    else:
        assert fit.warnings, "a fit flagged as not converged must say why"
    bad_se = [k for k, v in fit.stderr.items() if not math.isfinite(v) and k != "x_min"]
    if bad_se:
        assert any("standard errors" in w for w in fit.warnings)


@pytest.mark.parametrize("model", stats.MODELS)
@SETTINGS
@given(x=samples, c=st.one_of(st.none(), st.lists(lengths, max_size=10)))
def test_fit_renewal_returns_a_sane_or_flagged_fit_or_refuses(model, x, c):
    fit = _call(stats.fit_renewal, x, model, censored=c, min_tail=5,
                names=("intervals", "censored", "min_tail", "x_min"))
    if fit is not None:
        _check_fit(fit)
        assert fit.n + fit.n_excluded >= 1


@SETTINGS
@given(x=samples, bad=bad_values)
def test_fit_renewal_refuses_a_bad_entry_naming_intervals(x, bad):
    with pytest.raises((ValueError, TypeError), match="intervals"):
        stats.fit_renewal([*x, bad], "gamma")


@SETTINGS
@given(value=st.floats(min_value=1e-6, max_value=1e6), n=st.integers(5, 80))
def test_all_equal_intervals_are_refused_by_every_model_but_the_exponential(value, n):
    # n >= 5: fewer intervals than a model needs is refused first, for that reason
    for model in stats.MODELS[1:]:
        with pytest.raises(ValueError, match="intervals: all .* equal"):
            stats.fit_renewal(np.full(n, value), model, min_tail=2)
    fit = stats.fit_renewal(np.full(n, value), "exponential")
    assert fit.params["rate"] == pytest.approx(1 / value)


@settings(SETTINGS, max_examples=5)  # each call fits six models: ~3 s on extreme data
@given(x=st.lists(lengths, min_size=1, max_size=60))
def test_compare_models_ranks_finite_rows_and_explains_the_others(x):
    table = _call(stats.compare_models, x, names=("intervals", "censored"))
    if table is None:
        return
    assert set(table.index) == set(stats.FULL_SAMPLE_MODELS)
    for model, row in table.iterrows():
        if np.isfinite(row["aic"]):
            assert row["weight"] >= 0
        else:
            assert row["note"], f"{model}: no AIC and no reason"
    assert table["converged"].dtype == bool or set(table["converged"]) <= {True, False}


event_times = st.lists(
    st.floats(min_value=0.0, max_value=100.0, allow_nan=False), max_size=40, unique=True
).map(sorted)


@SETTINGS
@given(t=event_times, window=st.floats(min_value=100.0, max_value=1e4))
def test_intervals_from_times_partition_the_window(t, window):
    out = stats.intervals_from_times(t, window, first="keep")
    assert np.all(out.complete > 0) and np.all(out.censored > 0)
    total = out.complete.sum() + out.censored.sum()
    assert total == pytest.approx(window if t else window, rel=1e-9) or not t


@SETTINGS
@given(t=event_times, window=st.one_of(st.floats(min_value=100.0, max_value=1e4), bad_values))
def test_test_poisson_gives_p_values_in_0_1_or_a_note(t, window):
    table = _call(stats.test_poisson, t, window, n_mc=19, rng=0, names=("t_window", "times"))
    if table is None:
        return
    for name, row in table.iterrows():
        if np.isfinite(row["pvalue"]):
            assert 0 < row["pvalue"] <= 1
        else:
            assert row["note"], f"{name}: NaN p-value without a note"


@SETTINGS
@given(seqs=st.lists(event_times, min_size=1, max_size=4))
def test_test_poisson_ensemble_combines_sane_p_values(seqs):
    res = _call(stats.test_poisson_ensemble, seqs, 100.0, n_mc=19, n_mc_max=39, rng=0,
                names=("sequences", "windows"))
    if res is None:
        return
    p = res.combined["pvalue"].to_numpy()
    assert np.all((p[np.isfinite(p)] >= 0) & (p[np.isfinite(p)] <= 1))
    assert len(res.per_sequence) == len(seqs)


@SETTINGS
@given(
    counts=st.lists(st.integers(0, 60), min_size=4, max_size=30),
    radii=st.lists(st.sampled_from([0.005, 0.01, 0.02, 0.04]), min_size=4, max_size=30),
    window=st.floats(min_value=1.0, max_value=1e4),
)
def test_regress_counts_returns_finite_or_flagged_coefficients_or_refuses(counts, radii, window):
    n = min(len(counts), len(radii))
    df = pd.DataFrame({"radius": radii[:n], "count": counts[:n], "t_window": window})
    reg = _call(stats.regress_counts, df, names=("df[",))
    if reg is None:
        return
    assert isinstance(reg.converged, bool)
    if reg.converged:
        coef = reg.coefficients()
        assert np.all(np.isfinite(coef.loc[["poisson"], "estimate"]))
        assert np.all(np.isfinite(coef.loc[["negbin"], "estimate"]))
        se = coef["stderr"].drop(index="ols", level="model")
        assert np.all(np.isfinite(se)) or reg.warnings


@SETTINGS
@given(r=st.one_of(st.floats(allow_nan=True, allow_infinity=True), bad_values))
def test_kinetic_rate_is_positive_and_finite_or_refused_naming_r(r):
    rate = _call(stats.kinetic_rate, r, names=("r",))
    if rate is not None:
        assert 0 < r < 0.5 and math.isfinite(rate) and rate > 0


@settings(max_examples=200, deadline=None)
@given(st.lists(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                                    st.sampled_from([0.0, -0.0, 1.0, -1.0])),
                         min_size=0, max_size=9), min_size=1, max_size=5).filter(
    lambda rows: len({len(r) for r in rows}) == 1))
def test_nanmedian_equals_numpys_bit_for_bit(rows):
    import warnings

    from kicktimes.stats import nanmedian

    a = np.array(rows, dtype=float)
    got = nanmedian(a, axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ref = np.nanmedian(a, axis=1) if a.shape[1] else np.full(a.shape[0], np.nan)
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    # numpy.nanmedian's small-array path computes an odd count's median as (m + m) / 2,
    # which overflows for |m| >= 2**1023: there the median is m (numpy.median agrees)
    overflow = np.isinf(ref) & np.isfinite(got)
    for i in np.flatnonzero(overflow):
        row = np.sort(a[i][~np.isnan(a[i])])
        assert row.size % 2 == 1 and abs(got[i]) >= 2.0**1023
        assert got[i] == row[row.size // 2] == np.median(row)
    finite = ~np.isnan(ref) & ~overflow
    assert got[finite].tobytes() == ref[finite].tobytes()


def test_an_odd_count_median_near_the_float_limit_does_not_overflow():
    from kicktimes.stats import nanmedian

    big = 2.0**1023
    a = np.array([[0.0, 0.0, big, big, big], [0.0, big, big, np.nan, np.nan]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning from the odd row
        got = nanmedian(a[:1], axis=1)
    assert got[0] == big
    with np.errstate(over="ignore"):
        assert np.isinf(np.nanmedian(a[:1], axis=1)[0])  # numpy's overflow, for the record
    assert nanmedian(a, axis=1)[1] == big


def test_nanmedian_equals_numpys_on_long_rows_and_blocks():
    from kicktimes.stats import nanmedian

    rng = np.random.default_rng(3)
    a = rng.standard_normal((4, 3, 801))
    a[rng.random(a.shape) < 0.2] = np.nan
    a[0, 0] = np.nan  # a row without a number
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ref = np.nanmedian(a, axis=2)
        ref1 = np.nanmedian(a, axis=1)
    assert nanmedian(a, axis=2).tobytes() == ref.tobytes()
    assert nanmedian(a, axis=1).tobytes() == ref1.tobytes()


@settings(max_examples=200, deadline=None)
@given(
    rows=st.integers(1, 4),
    cols=st.integers(1, 12),
    data=st.data(),
)
def test_bootstrap_nanmedians_equal_the_medians_of_the_resamples(rows, cols, data):
    # every resample's nanmedian, bit for bit (values without -0.0, the documented
    # exception; repeated values, NaN, inf and whole-NaN rows included)
    from kicktimes.stats import bootstrap_nanmedians, nanmedian

    element = st.one_of(st.sampled_from([np.nan, np.inf, -np.inf, 0.0, 1.0, 2.5]),
                        st.floats(-1e6, 1e6).filter(lambda v: v != 0.0))
    a = np.array(data.draw(st.lists(st.lists(element, min_size=cols, max_size=cols),
                                    min_size=rows, max_size=rows)), dtype=float)
    idx = np.array(data.draw(st.lists(st.lists(st.integers(0, cols - 1), min_size=1,
                                               max_size=15), min_size=1, max_size=6)
                             .filter(lambda v: len({len(r) for r in v}) == 1)))
    got = bootstrap_nanmedians(a, idx)
    ref = np.array([nanmedian(a[:, idx[b]], axis=1) for b in range(idx.shape[0])])
    assert got.shape == (idx.shape[0], rows)
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    assert got[~np.isnan(ref)].tobytes() == ref[~np.isnan(ref)].tobytes()


def test_bootstrap_nanmedians_on_a_report_sized_bootstrap():
    from kicktimes.stats import bootstrap_nanmedians, nanmedian

    rng = np.random.default_rng(5)
    a = rng.lognormal(size=(10, 300))
    a[rng.random(a.shape) < 0.1] = np.nan
    a[3] = np.nan  # a radius without a pair
    idx = rng.integers(0, 300, size=(200, 300))
    got = bootstrap_nanmedians(a, idx)
    ref = np.array([nanmedian(a[:, idx[b]], axis=1) for b in range(200)])
    assert got.tobytes() == ref.tobytes()
    assert got.flags.c_contiguous


def test_bootstrap_nanmedians_bad_input():
    from kicktimes.stats import bootstrap_nanmedians

    with pytest.raises(ValueError, match="values"):
        bootstrap_nanmedians(np.zeros(3), np.zeros((1, 3), int))
    with pytest.raises(ValueError, match="idx"):
        bootstrap_nanmedians(np.zeros((2, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"idx: column indices must lie in \[0, 3\)"):
        bootstrap_nanmedians(np.zeros((2, 3)), np.array([[0, 3]]))
