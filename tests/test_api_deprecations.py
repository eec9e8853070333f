"""Every old spelling of issue 61's part "api" still works until 0.3.0, warns naming the new
one, and gives exactly what the new spelling gives (CHANGELOG.md, 0.2.0, "rng and keywords"
and "names")."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import kicktimes as kt
from kicktimes import diagnostics as dg
from kicktimes import schedules, stats
from kicktimes.experiment import kick_rng
from kicktimes.validation import check_seed_sequence, keyword_only_after, renamed_keyword


def _same(a, b):
    if isinstance(a, np.random.Generator):
        return a.bit_generator.state == b.bit_generator.state
    if isinstance(a, pd.DataFrame):
        pd.testing.assert_frame_equal(a, b)
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and np.isnan(a):
        return np.isnan(b)
    return a == b


# -- seed= -> rng=: the stream is bit-identical


def test_initial_conditions_rng_int_is_the_old_seed_stream():
    # the old definition: IC i from SeedSequence(seed, spawn_key=(i,))
    from kicktimes.billiard.initial import _paper_ic, ic_generator

    new = kt.initial_conditions(4, 0.05, rng=11, start=2)
    old = np.stack([_paper_ic(ic_generator(11, 2 + k), 0.05) for k in range(4)])
    assert np.array_equal(new, old)
    assert np.array_equal(kt.initial_conditions(4, 0.05, rng=np.random.SeedSequence(11),
                                                start=2), new)
    with pytest.warns(DeprecationWarning, match="seed= is deprecated.*use rng="):
        assert np.array_equal(kt.initial_conditions(4, 0.05, seed=11, start=2), new)
    assert np.array_equal(kt.initial_conditions(4, 0.05), kt.initial_conditions(4, 0.05, rng=0))


def test_initial_conditions_takes_a_generator_and_rejects_the_rest():
    a = kt.initial_conditions(2, 0.05, rng=np.random.default_rng(3))
    b = kt.initial_conditions(2, 0.05, rng=np.random.default_rng(3))
    assert np.array_equal(a, b) and a.shape == (2, 2, 4)
    with pytest.raises(TypeError, match="rng"):
        kt.initial_conditions(2, 0.05, rng="seven")
    with pytest.raises(ValueError, match="rng"):
        kt.initial_conditions(2, 0.05, rng=-1)
    with pytest.raises(TypeError, match="both seed= and rng="):
        kt.initial_conditions(2, 0.05, seed=1, rng=1)


def test_initial_state_seed_is_rng():
    new = kt.initial_state(30, None, packing=0.2, rng=4)
    with pytest.warns(DeprecationWarning, match="initial_state.*use rng="):
        old = kt.initial_state(30, None, packing=0.2, seed=4)
    assert np.array_equal(new, old)
    assert np.array_equal(kt.initial_state(30, None, packing=0.2, rng=np.random.default_rng(4)),
                          new)


def test_kick_rng_old_order_and_seed_keyword():
    new = kick_rng(3, 0.02, "poisson", rng=9)
    with pytest.warns(DeprecationWarning, match=r"kick_rng\(ic, radius, system, rng=seed\)"):
        old = kick_rng(9, 3, 0.02, "poisson")
    assert _same(new, old)
    with pytest.warns(DeprecationWarning, match="rng=seed"):
        assert _same(kick_rng(3, 0.02, "poisson", seed=9), new)
    # the stream of the old definition, SeedSequence(seed, spawn_key=(domain, ic, bits, code))
    from kicktimes.experiment.tasks import KICK_DOMAIN, SYSTEM_CODES, _radius_key

    ref = np.random.default_rng(np.random.SeedSequence(
        9, spawn_key=(KICK_DOMAIN, 3, _radius_key(0.02), SYSTEM_CODES["poisson"])))
    assert _same(new, ref)
    with pytest.raises(TypeError, match="rng="):
        kick_rng(9, 3, 0.02, "poisson", rng=9)


def test_check_seed_sequence_of_an_int_is_its_root():
    assert check_seed_sequence(5).entropy == 5
    ss = np.random.SeedSequence(5)
    assert check_seed_sequence(ss) is ss


# -- options by position: mapped to their keywords, with one warning

_TWO = kt.simulate_two_particle(kt.initial_conditions(1, 0.05, rng=2)[0], 0.05, n_steps=400,
                                tau=0.5)
_POINTS = np.random.default_rng(0).uniform(-0.5, 0.5, size=(300, 2))
_KM = pd.DataFrame({"time": [1.0, 2.0, 3.0], "n_at_risk": [80, 50, 49]})
_BURSTS = np.random.default_rng(1)
_FIT = stats.fit_mmpp(np.sort(np.concatenate([_BURSTS.uniform(0, 5, 60), _BURSTS.uniform(5, 50, 9),
                                              _BURSTS.uniform(50, 55, 60)])), 60.0,
                      rng=1, n_starts=2)

#: (function, old positional arguments, the same call by keyword)
OLD_POSITIONAL = [
    (kt.box_side, (200, 0.01, 0.3), ((200, 0.01), {"packing": 0.3})),
    (stats.stretching_per_perturbation, (np.ones(3), np.ones(3), np.ones(3), 0),
     ((np.ones(3), np.ones(3), np.ones(3)), {"axis": 0})),
    (stats.dilute_tagged_times, ("mirror", 1.0, 10.0, 5, 3),
     (("mirror", 1.0, 10.0), {"n_runs": 5, "rng": 3})),
    (stats.ratio_verdict, (0.95, 1.05, 0.2), ((0.95, 1.05), {"tolerance": 0.2})),
    (stats.null_reading, (0.01, 0.2, 0.1), ((0.01, 0.2), {"margin": 0.1})),
    (stats.ratio_reading, (0.8, 0.95, 0.1), ((0.8, 0.95), {"tolerance": 0.1})),
    (stats.ratio_words, (0.8, 0.95, 0.1), ((0.8, 0.95), {"tolerance": 0.1})),
    (stats.side_of, (0.1, 0.3, 0.0), ((0.1, 0.3), {"null": 0.0})),
    (stats.null_verdict, (0.01, 0.2, 0.1), ((0.01, 0.2), {"margin": 0.1})),
    (stats.equivalence_sample_size, (0.05, 40, 0.1), ((0.05, 40), {"margin": 0.1})),
    (stats.clopper_pearson, (3, 40, 0.9), ((3, 40), {"level": 0.9})),
    (stats.robust_verdict, (["within 10 %", "within 10 %"], [0.95, 0.96], [1.04, 1.05], 0.5),
     ((["within 10 %", "within 10 %"], [0.95, 0.96], [1.04, 1.05]), {"level": 0.5})),
    (stats.share_ratio_sample_size, (0.3, 0.1, 0.8, 0.95),
     ((0.3,), {"tolerance": 0.1, "power": 0.8, "level": 0.95})),
    (stats.share_verdict, (0.1, 0.3, 0.05), ((0.1, 0.3), {"level": 0.05})),
    (stats.rejection_verdict, (0.04, 0.07, 0.05, 0.5),
     ((0.04, 0.07), {"alpha": 0.05, "margin": 0.5})),
    (stats.poisson_verdict, (0.37, 0.41, 0.05, 1.2, 1.6),
     ((0.37, 0.41), {"null_level": 0.05, "dispersion_low": 1.2, "dispersion_high": 1.6})),
    (stats.poisson_rule, (0.5, 0.1), ((), {"margin": 0.5, "band": 0.1})),
    (stats.rejection_rule, (0.05, 0.5), ((), {"alpha": 0.05, "margin": 0.5})),
    (stats.ratio_rule, (0.1,), ((), {"tolerance": 0.1})),
    (stats.null_rule, (0.1, "D"), ((), {"margin": 0.1, "name": "D"})),
    (stats.resample_counts, (10, 5, 1), ((10,), {"n_boot": 5, "rng": 1})),
    (stats.resample_indices, (10, 5, 1), ((10,), {"n_boot": 5, "rng": 1})),
    (stats.percentile_interval, (np.arange(100.0), 0.9), ((np.arange(100.0),), {"level": 0.9})),
    (stats.kinetic_rate, (0.01, "elastic"), ((0.01,), {"rule": "elastic"})),
    (stats.interval_hazard, (np.arange(1.0, 60.0), np.array([70.0])),
     ((np.arange(1.0, 60.0),), {"censored": np.array([70.0])})),
    (stats.reliable_until, (_KM, 60), ((_KM,), {"floor": 60})),
    (dg.autocorrelation_many, ([np.arange(30.0) % 7], 2), (([np.arange(30.0) % 7],), {"lag": 2})),
    (dg.boundary_angles, (_TWO, 1), ((_TWO,), {"particle": 1})),
    (dg.recurrence_pairs, (_POINTS, 0.05), ((_POINTS,), {"eps": 0.05})),
    (dg.recurrence_rate, (_POINTS, 0.05), ((_POINTS,), {"eps": 0.05})),
    (dg.rqa, (_POINTS, 0.05), ((_POINTS,), {"eps": 0.05})),
    (schedules.Poisson(0.5).sample, (40.0, 3), ((40.0,), {"rng": 3})),
    (schedules.Replay([1.0, 2.0]).sample, (40.0, 3), ((40.0,), {"rng": 3})),
    (_FIT.simulate, (20.0, 4), ((20.0,), {"rng": 4})),
]


def _name(case):
    return getattr(case[0], "__qualname__", repr(case[0]))


@pytest.mark.parametrize("func, old, new", OLD_POSITIONAL, ids=[_name(c) for c in OLD_POSITIONAL])
def test_old_positional_options_warn_and_agree(func, old, new):
    args, kwargs = new
    expected = func(*args, **kwargs)
    names = "=.*".join(kwargs)
    with pytest.warns(DeprecationWarning, match=f"pass {names}=.* by keyword"):
        got = func(*old)
    if hasattr(expected, "__dataclass_fields__") and not isinstance(expected, np.ndarray):
        assert repr(got) == repr(expected)
    else:
        assert _same(got, expected)


def test_the_dilute_tagged_disk_methods_take_options_by_keyword():
    disk = stats.dilute_tagged_disk("mirror")
    with pytest.warns(DeprecationWarning, match="pass window= by keyword"):
        assert disk.dispersion(10.0) == disk.dispersion(window=10.0)
    with pytest.warns(DeprecationWarning, match="pass alpha= by keyword"):
        assert disk.ks_share(5, 0.1, n_runs=30) == disk.ks_share(5, alpha=0.1, n_runs=30)


def test_count_regression_predict_t_window_by_keyword():
    df = pd.DataFrame({"radius": [0.01, 0.02, 0.04] * 4, "count": [30, 55, 120] * 4,
                       "t_window": 100.0})
    reg = stats.regress_counts(df)
    with pytest.warns(DeprecationWarning, match="pass t_window= by keyword"):
        old = reg.predict(0.03, 50.0)
    pd.testing.assert_frame_equal(old, reg.predict(0.03, t_window=50.0))


def test_report_functions_take_options_by_keyword():
    from kicktimes import plots

    with pytest.warns(DeprecationWarning, match="pass level= by keyword"):
        assert _same(plots.binomial_ci(3, 40, 0.9), plots.binomial_ci(3, 40, level=0.9))


def test_too_many_positionals_and_a_repeated_keyword_are_type_errors():
    with pytest.raises(TypeError, match="at most 3 arguments by position"):
        stats.ratio_verdict(0.9, 1.1, 0.1, 0.2)
    with pytest.raises(TypeError, match="multiple values for argument 'tolerance'"):
        stats.ratio_verdict(0.9, 1.1, 0.1, tolerance=0.2)


def test_the_decorators_check_what_they_wrap():
    with pytest.raises(TypeError, match="keyword_only_after"):
        @keyword_only_after(2)
        def one(x, *, y=1):
            return x

    @renamed_keyword(old="old", new="new")
    def f(*, new=0):
        return new

    with pytest.warns(DeprecationWarning, match="old= is deprecated since 0.2.0.*use new="):
        assert f(old=4) == 4
    assert f(new=4) == 4


# -- names


def test_disks_lyapunov_exponent_is_lam():
    state = kt.initial_state(20, None, packing=0.1, rng=1)
    res = dg.disks_lyapunov(state, (0.1 / 20) ** 0.5, t_max=4.0, segment=1.0, rng=1)
    with pytest.warns(DeprecationWarning, match="DisksLyapunov.exponent is deprecated.*lam"):
        assert res.exponent == res.lam
    assert repr(res).startswith("DisksLyapunov(lam=")
