"""Finite-time Lyapunov exponents: the public API, both methods, validation."""

import math
import warnings

import numpy as np
import pytest

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.billiard import KickLaw
from kicktimes.billiard.kernels.drive_two import tangent_two_kernel
from kicktimes.billiard.kernels.tangent import MAX_SAME_INSTANT
from kicktimes.billiard.kernels.twins import ftle_two_kernel
from kicktimes.billiard.one_particle import draw_kick_angles
from kicktimes.diagnostics import Tangent, Twin, UndefinedDiagnosticWarning, lyapunov
from kicktimes.diagnostics.lyapunov import check_kernel_status
from kicktimes.diagnostics.spectrum import lyapunov_spectrum


@pytest.fixture(scope="module")
def ics():
    return initial_conditions(6, 0.03, rng=3)


@pytest.mark.parametrize("method", ["tangent", "twin"])
def test_unkicked_one_particle_exponent_tends_to_zero(ics, method):
    short = np.mean([lyapunov(ic[0], 0.03, n_steps=2500, tau=0.2, method=method).lam
                     for ic in ics])
    long = np.mean([lyapunov(ic[0], 0.03, n_steps=25000, tau=0.2, method=method).lam
                    for ic in ics])
    assert long < short
    assert 0 <= long < 0.01


def test_two_particle_twin_exponent_is_positive_and_stable_to_halving_d0(ics):
    lam = np.array([lyapunov(ic, 0.03, n_steps=10000, tau=0.2, method="twin").lam for ic in ics])
    lam_half = np.array([lyapunov(ic, 0.03, n_steps=10000, tau=0.2, method=Twin(d0=1e-4)).lam
                         for ic in ics])
    assert (lam > 0.1).all()
    assert abs(lam.mean() - lam_half.mean()) < 0.1 * lam.mean()


@pytest.mark.parametrize("method", ["tangent", "twin"])
def test_paper_variant_is_the_maximum_of_its_parts(ics, method):
    kind = Twin if method == "twin" else Tangent
    res = lyapunov(ics[0], 0.03, n_steps=5000, tau=0.2, method=kind(variant="paper"))
    assert res.variant == "paper" and res.method == method
    assert res.lam == max(res.lam_x, res.lam_y)
    assert np.isnan(lyapunov(ics[0], 0.03, n_steps=100, tau=0.2, method=method).lam_x)


@pytest.mark.parametrize("sampling", ["uniform", "paper"])
def test_both_sampling_modes_give_positive_two_particle_exponents(ics, sampling):
    res = lyapunov(ics[1], 0.03, n_steps=10000, tau=0.2, sampling=sampling, method="twin")
    assert res.lam > 0.05
    assert res.n_renorm > 0.5 * 10000
    tangent = lyapunov(ics[1], 0.03, n_steps=10000, tau=0.2, sampling=sampling)
    assert tangent.lam > 0.05 and tangent.total_time == res.total_time
    if sampling == "paper":
        assert res.total_time < 10000 * 0.2


@pytest.mark.parametrize("kick_angle", ["uniform", "gaussian"])
def test_kicks_make_the_one_particle_billiard_chaotic(ics, kick_angle):
    kicks = np.sort(np.random.default_rng(1).uniform(0, 2000, 40))
    res = lyapunov(ics[0, 0], 0.03, n_steps=10000, tau=0.2, kicks=KickLaw(kicks, angle=kick_angle),
                   rng=2)
    unkicked = lyapunov(ics[0, 0], 0.03, n_steps=10000, tau=0.2)
    assert res.n_perturbations == 40 and unkicked.n_perturbations == 0
    assert res.lam > 5 * unkicked.lam


def test_independent_twin_kicks_need_a_kicked_twin(ics):
    with pytest.raises(TypeError, match="twin_kicks"):
        Tangent(twin_kicks="independent")  # a tangent vector has no kicks of its own
    with pytest.raises(ValueError, match="not to two disks"):
        lyapunov(ics[1], 0.03, n_steps=10, tau=0.2, method=Twin(twin_kicks="independent"))
    with pytest.raises(ValueError, match="kick_angle='scatter'"):
        lyapunov(ics[1, 0], 0.03, n_steps=10, tau=0.2, method=Twin(twin_kicks="independent"),
                 kicks=KickLaw(np.array([0.5]), angle="scatter"), rng=1)
    with pytest.raises(ValueError, match="twin_kicks"):
        lyapunov(ics[1, 0], 0.03, n_steps=10, tau=0.2, method=Twin(twin_kicks="own"))


@pytest.mark.parametrize("method", ["tangent", "twin"])
def test_run_objects_are_accepted_and_reuse_their_kicks(ics, method):
    run = simulate_one_particle(ics[0, 0], 0.03, n_steps=2000, tau=0.2,
                                kicks=KickLaw(np.array([10.0, 20.0, 30.0]), angle="gaussian",
                                              sigma=0.3), rng=4)
    a = lyapunov(run, method=method)
    b = lyapunov(ics[0, 0], 0.03, n_steps=2000, tau=0.2,
                 kicks=KickLaw(run.kick_times, angle="gaussian", angles=run.kick_angles),
                 method=method)
    assert a == b and a.n_perturbations == 3
    two = simulate_two_particle(ics[0], 0.03, n_steps=2000, tau=0.2, rule="elastic")
    assert lyapunov(two, method=method) == lyapunov(ics[0], 0.03, n_steps=2000, tau=0.2,
                                                    rule="elastic", method=method)
    assert lyapunov(two, method=method).n_perturbations == two.n_pp


def test_a_run_longer_than_its_samples_is_accepted(ics):
    run = simulate_one_particle(ics[0, 0], 0.03, t_max=100.0, n_steps=300, tau=0.3,
                                kicks=np.array([10.0, 95.0]), rng=1)
    res = lyapunov(run)
    assert res.total_time <= 90.0 and np.isfinite(res.lam)


@pytest.mark.parametrize("method", ["tangent", "twin"])
def test_results_are_deterministic(ics, method):
    assert (lyapunov(ics[2], 0.03, n_steps=3000, tau=0.2, method=method)
            == lyapunov(ics[2], 0.03, n_steps=3000, tau=0.2, method=method))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(n_steps=10, tau=0.2, method="benettin"), "method must be one of"),
        (dict(n_steps=10**7, tau=100.0), "horizon n_steps \\* tau must be at most"),
        (dict(n_steps=10, tau=1e307), "tau must lie in"),
        (dict(tau=0.2), "n_steps"),
        (dict(n_steps=10, tau=0.2, kicks=[1.0]), "one-disk"),
    ],
)
def test_bad_arguments_raise(ics, kwargs, match):
    with pytest.raises(ValueError, match=match):
        lyapunov(ics[0], 0.03, **kwargs)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        (lambda: Tangent(variant="max"), "variant must be one of"),
        (lambda: Twin(variant="max"), "variant must be one of"),
        (lambda: Twin(d0=0.0), "d0 must lie in"),
        (lambda: Twin(d0=5e-324), "d0 must lie in"),
        (lambda: Twin(d0=1e-12), "d0 must lie in"),
        (lambda: Twin(d0=0.05), "d0 must lie in"),
    ],
)
def test_bad_method_options_raise_naming_them(options, match):
    with pytest.raises(ValueError, match=match):
        options()


@pytest.mark.parametrize("sigma", [math.inf, math.nan, 0.0, -1.0])
@pytest.mark.parametrize("method", ["tangent", "twin"])
def test_bad_sigma_is_refused_not_a_hang(ics, sigma, method):
    with pytest.raises(ValueError, match="sigma must"):
        lyapunov(ics[0, 0], 0.03, n_steps=100, tau=0.2,
                 kicks=KickLaw([1.0, 2.0], angle="gaussian", sigma=sigma),
                 method=method)


@pytest.mark.parametrize("method", ["tangent", "twin"])
def test_a_pile_of_simultaneous_events_is_an_error_not_a_hang(ics, method):
    kicks = np.full(MAX_SAME_INSTANT + 5, 3.0)
    with pytest.raises(RuntimeError, match="consecutive events at the same instant"):
        lyapunov(ics[0, 0], 0.03, n_steps=100, tau=0.2, kicks=kicks, method=method)
    # a few simultaneous kicks are fine
    assert np.isfinite(lyapunov(ics[0, 0], 0.03, n_steps=100, tau=0.2, kicks=kicks[:50],
                                method=method).lam)


# Degenerate two-disk states where the exponent is undefined; each gave lam = -inf (the
# tracked disk's position deviation vanished exactly) or a ZeroDivisionError, silently.
HEAD_ON = [[-0.05, 0.0, 1.0, 0.0], [0.05, 0.0, -1.0, 0.0]]  # touching, colliding head-on at t = 0
HEAD_ON_TINY = [[-1e-12, 0.0, 1.0, 0.0], [1e-12, 0.0, -1.0, 0.0]]  # the same with r = 1e-12
ONTO_A_DISK_AT_REST = [[0.0, 0.0, 1.0, 0.0], [0.1, 0.0, 0.0, 0.0]]  # elastic: disk 0 stops
ON_THE_WALL = [[0.95, 0.0, 0.0, 1.0], [0.0, 0.5, 0.0, 1.0]]  # disk 0 tangent to the wall


@pytest.mark.parametrize(
    ("ic", "r", "kwargs", "reason"),
    [
        (HEAD_ON, 0.05, {}, "position deviation of disk 0 is exactly 0"),
        (HEAD_ON, 0.05, {"n_steps": 1}, "position deviation of disk 0 is exactly 0"),
        (HEAD_ON_TINY, 1e-12, {}, "position deviation of disk 0 is exactly 0"),
        (ONTO_A_DISK_AT_REST, 0.05, {"rule": "elastic"}, "position deviation of disk 0 is exa"),
        (ON_THE_WALL, 0.05, {}, "tangent vector is not finite"),
        (ON_THE_WALL, 0.05, {"sampling": "paper"}, "tangent vector is not finite"),
        (ON_THE_WALL, 0.05, {"variant": "paper"}, "tangent vector is not finite"),
    ],
)
def test_an_undefined_tangent_exponent_is_nan_with_a_reason_and_a_warning(ic, r, kwargs, reason):
    variant = kwargs.pop("variant", "norm")
    kwargs = {"n_steps": 100, "tau": 0.3, **kwargs}
    with pytest.warns(UndefinedDiagnosticWarning, match=f"lyapunov: lam is NaN: .*{reason}"):
        res = lyapunov(ic, r, method=Tangent(variant=variant), **kwargs)
    assert math.isnan(res.lam) and reason in res.reason
    assert math.isnan(res.lam_per_perturbation)
    # one pass with the run: the same result
    with pytest.warns(UndefinedDiagnosticWarning):
        res2, _ = lyapunov(ic, r, method=Tangent(variant=variant, return_run=True), **kwargs)
    assert_results_bitwise_equal(res2, res)


def test_a_vanished_part_of_the_paper_variant_is_named():
    with pytest.warns(UndefinedDiagnosticWarning, match=r"\|dx\| of disk 0 is exactly 0"):
        res = lyapunov(HEAD_ON, 0.05, n_steps=100, tau=0.3, method=Tangent(variant="paper"))
    assert math.isnan(res.lam_x) and math.isfinite(res.lam_y) and math.isnan(res.lam)


def test_a_horizon_that_covers_no_time_gives_nan_with_a_reason():
    # one paper step, ended by the collision at t = 0
    with pytest.warns(UndefinedDiagnosticWarning, match="covers no time"):
        res = lyapunov(HEAD_ON, 0.05, n_steps=1, tau=0.3, sampling="paper")
    assert math.isnan(res.lam) and res.total_time == 0.0 and "covers no time" in res.reason
    with pytest.warns(UndefinedDiagnosticWarning, match="twin was never renormalised"):
        res = lyapunov(HEAD_ON, 0.05, n_steps=1, tau=0.3, method="twin")
    assert math.isnan(res.lam) and "never renormalised" in res.reason


def test_defined_exponents_have_no_reason_and_no_warning(ics):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for method in ("tangent", "twin"):
            for variant in ("norm", "paper"):
                kind = Twin if method == "twin" else Tangent
                res = lyapunov(ics[1], 0.03, n_steps=500, tau=0.2, method=kind(variant=variant))
                assert math.isfinite(res.lam) and res.reason is None


def test_the_spectrum_refuses_a_contact_tangent_to_the_wall():
    # the linearised reflection divides by v.n = 0 (was a ZeroDivisionError from the kernel)
    with pytest.raises(ValueError, match="ic: the linearised dynamics is singular"):
        lyapunov_spectrum(ON_THE_WALL, 0.05, t_max=10.0)


def test_every_event_loop_has_a_budget(ics):
    st = np.zeros(11)
    st[1:9] = ics[0].ravel()
    st[10] = 2.0
    table = (0.97, 0.97, 1.0, 1.0)  # kernels.two.table(0.97, 0.97)
    out = tangent_two_kernel(st.copy(), table, 0.06, 0, 1, 1000, 0.2, np.eye(8)[[0]], 50, 0)
    assert out[4] == 1
    out = ftle_two_kernel(st, table, 0.06, 0, 1, 1000, 0.2, 0, np.array([[1e-8, 0.0]]),
                          np.array([0]), 1e-8, 10, 50, True)
    assert out[6] == 1
    with pytest.raises(RuntimeError, match="budget of 50 events"):
        check_kernel_status(1, 200.0, 50)
    with pytest.raises(ValueError, match="non-finite event time"):
        check_kernel_status(3, 200.0, 50)


@pytest.mark.slow
def test_two_particle_exponent_at_r_003_with_paper_scale_runs():
    ics = initial_conditions(50, 0.03, rng=8)
    lam = np.array([lyapunov(ic, 0.03, n_steps=25000, tau=0.2).lam for ic in ics])
    lam_half = np.array([lyapunov(ic, 0.03, n_steps=25000, tau=0.2, method=Twin(d0=1e-4)).lam
                         for ic in ics])
    sem = lam.std(ddof=1) / np.sqrt(len(lam))
    assert lam.mean() > 10 * sem
    assert abs(lam.mean() - lam_half.mean()) < 4 * sem


def test_sweeps_pass_the_lyapunov_method_through():
    from kicktimes.experiment.config import Experiment
    from kicktimes.experiment.tasks import run_task

    values = {}
    for method in ("tangent", "twin"):
        exp = Experiment(name="m", radii=[0.02], n_ics=1, n_steps=300, tau=0.3,
                         lyapunov_method=method, systems=("two_particle",),
                         diagnostics=("lyapunov",))
        results, _ = run_task(exp, exp.tasks()[0])
        values[method] = results.loc[results.diagnostic == "lyapunov", "value"].item()
    ic = initial_conditions(1, 0.02, rng=0)[0]
    assert values["tangent"] == lyapunov(ic, 0.02, n_steps=300, tau=0.3).lam
    assert values["twin"] == lyapunov(ic, 0.02, n_steps=300, tau=0.3, method="twin").lam
    with pytest.raises(ValueError, match="lyapunov_method"):
        Experiment(name="m", radii=[0.02], n_ics=1, n_steps=3, tau=0.3, lyapunov_method="qr")


# ------------------------------------------------ one pass: the run and the FTLE together
def assert_runs_bitwise_equal(a, b):
    """Same class, every field equal to the bit (arrays: dtype, shape and bytes)."""
    import dataclasses

    assert type(a) is type(b)
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "boundary_log":
            for u, v in zip(x, y, strict=True):
                assert u.dtype == v.dtype and u.tobytes() == v.tobytes(), f.name
        elif isinstance(x, np.ndarray):
            assert (x.dtype, x.shape) == (y.dtype, y.shape) and x.tobytes() == y.tobytes(), f.name
        else:
            assert x == y or (x != x and y != y), (f.name, x, y)


def assert_results_bitwise_equal(a, b):
    import dataclasses

    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        assert x == y or (x != x and y != y), (f.name, x, y)


@pytest.mark.parametrize("r", [0.005, 0.02, 0.1])
@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("sampling", ["uniform", "paper"])
@pytest.mark.parametrize("variant", ["norm", "paper"])
def test_one_pass_gives_the_two_disk_run_and_exponent_of_separate_calls(r, rule, sampling,
                                                                        variant):
    for k, ic in enumerate(initial_conditions(2, r, rng=11, rule=rule)):
        kw = dict(n_steps=800, tau=0.3, sampling=sampling, rule=rule, track=k)
        res, run = lyapunov(ic, r, method=Tangent(variant=variant, return_run=True), **kw)
        assert_results_bitwise_equal(res, lyapunov(ic, r, method=Tangent(variant=variant), **kw))
        assert_runs_bitwise_equal(run, simulate_two_particle(ic, r, **kw))
        assert res.n_perturbations == run.n_pp and (run.n_pp > 0 or r < 0.01)


@pytest.mark.parametrize("r", [0.005, 0.02, 0.1])
@pytest.mark.parametrize(("kick_angle", "extra"), [("uniform", {}), ("gaussian", {"sigma": 0.4}),
                                                   ("scatter", {"rule": "mirror"}),
                                                   ("scatter", {"rule": "elastic"})])
@pytest.mark.parametrize("sampling", ["uniform", "paper"])
@pytest.mark.parametrize("variant", ["norm", "paper"])
def test_one_pass_gives_the_kicked_run_and_exponent_of_separate_calls(r, kick_angle, extra,
                                                                      sampling, variant):
    state = initial_conditions(1, r, rng=12)[0, 0]
    kw = dict(n_steps=800, tau=0.3, sampling=sampling)
    law = KickLaw(schedules.Poisson(0.2), angle=kick_angle, **extra)
    # drawn from a schedule with rng (the same draws both ways), and given explicitly with
    # kicks beyond the run's end (paper sampling: applied only while the run lasts)
    res, run = lyapunov(state, r, kicks=law, rng=3,
                        method=Tangent(variant=variant, return_run=True), **kw)
    assert_results_bitwise_equal(res, lyapunov(state, r, kicks=law, rng=3,
                                               method=Tangent(variant=variant), **kw))
    assert_runs_bitwise_equal(run, simulate_one_particle(state, r, kicks=law, rng=3, **kw))
    assert run.n_kicks > 0 and res.n_perturbations == run.n_kicks
    if sampling == "paper":
        late = 0.3 * 800 + 1.0
        kicks = np.r_[run.kick_times, late]
        angles = np.concatenate([run.kick_angles, run.kick_angles[:1]])
        given = law.replace(times=kicks, angles=angles)
        res, run2 = lyapunov(state, r, kicks=given,
                             method=Tangent(variant=variant, return_run=True), **kw)
        assert_runs_bitwise_equal(run2, simulate_one_particle(state, r, kicks=given, **kw))
        assert_runs_bitwise_equal(run2, run)


def test_one_pass_accepts_runs_and_refuses_the_twin_method(ics):
    run = simulate_one_particle(ics[0, 0], 0.03, n_steps=500, tau=0.2, kicks=[5.0, 9.0], rng=2)
    res, again = lyapunov(run, method=Tangent(return_run=True))
    assert res == lyapunov(run)
    assert_runs_bitwise_equal(again, run)
    with pytest.raises(TypeError, match="return_run"):
        Twin(return_run=True)  # the twin method has no one pass
    with pytest.raises(TypeError, match="return_run must be a bool"):
        lyapunov(ics[0], 0.03, n_steps=10, tau=0.2, method=Tangent(return_run="yes"))


def test_an_ftle_error_in_one_pass_is_the_error_of_the_separate_call(ics):
    # simultaneous kicks stop the tangent half (as lyapunov() would), not silently
    kicks = np.full(MAX_SAME_INSTANT + 5, 3.0)
    simulate_one_particle(ics[0, 0], 0.03, n_steps=100, tau=0.2, kicks=kicks, rng=0)
    with pytest.raises(RuntimeError, match="consecutive events at the same instant"):
        lyapunov(ics[0, 0], 0.03, n_steps=100, tau=0.2, kicks=kicks, rng=0,
                 method=Tangent(return_run=True))


@pytest.mark.parametrize("r", [0.005, 0.03])
@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_the_continued_pass_has_the_collision_times_of_a_fresh_run_to_the_horizon(r, rule):
    from kicktimes.diagnostics.lyapunov import lyapunov_pass

    horizon = 1500 * 0.3
    for ic in initial_conditions(3, r, rng=13, rule=rule):
        kw = dict(n_steps=1500, tau=0.3, rule=rule)
        res, run, times = lyapunov_pass(ic, r, sampling="paper", method=Tangent(variant="paper"),
                                        t_continue=horizon, **kw)
        assert_runs_bitwise_equal(run, simulate_two_particle(ic, r, sampling="paper", **kw))
        assert res == lyapunov(ic, r, sampling="paper", method=Tangent(variant="paper"), **kw)
        fresh = simulate_two_particle(ic, r, t_max=horizon, rule=rule)
        assert run.t_max < horizon and times.tobytes() == fresh.pp_times.tobytes()
        # nothing to continue: a window that reaches t_continue, or uniform sampling
        _, _, same = lyapunov_pass(ic, r, sampling="paper", t_continue=run.t_max, **kw)
        assert same.tobytes() == run.pp_times.tobytes()
        _, uni, same = lyapunov_pass(ic, r, t_continue=2 * horizon, **kw)
        assert same.tobytes() == uni.pp_times.tobytes()


_ONE_PASS_SETUP = """
import numpy as np
from kicktimes import initial_conditions, schedules
from kicktimes.billiard import KickLaw
from kicktimes.diagnostics import Tangent, lyapunov
from kicktimes.diagnostics.lyapunov import lyapunov_pass

ic = initial_conditions(1, 0.02, rng=0)[0]
"""
_ONE_PASS_CALLS = """
for rule in ("mirror", "elastic"):
    for sampling in ("uniform", "paper"):
        for variant in ("norm", "paper"):
            lyapunov(ic, 0.02, rule=rule, sampling=sampling, n_steps=20, tau=0.3,
                     method=Tangent(variant=variant, return_run=True))
    lyapunov_pass(ic, 0.02, rule=rule, sampling="paper", n_steps=20, tau=0.3,
                  t_continue=30.0)
for law in ("uniform", "gaussian", "scatter"):
    for sampling in ("uniform", "paper"):
        lyapunov(ic[0], 0.02, n_steps=20, tau=0.3, sampling=sampling,
                 kicks=KickLaw(schedules.Poisson(0.5), angle=law), rng=0,
                 method=Tangent(return_run=True))
    lyapunov(ic[0], 0.02, n_steps=20, tau=0.3, kicks=KickLaw(np.empty(0), angle=law),
             method=Tangent(return_run=True))
"""


@pytest.mark.slow
def test_one_pass_kernels_compile_once_without_error_strings(tmp_path):
    # as tests/test_compile.py checks for the simulators: one signature per kernel whatever
    # the rule, sampling, variant or kick law, and no numba string formatting
    from _compile_record import kicktimes_compiles

    ours = kicktimes_compiles(_ONE_PASS_SETUP, _ONE_PASS_CALLS, tmp_path)
    assert "kicktimes.billiard.kernels.drive_two.simulate_tangent_two_kernel" in ours
    assert "kicktimes.billiard.kernels.drive_one.simulate_tangent_one_kernel" in ours


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_the_one_pass_records_the_uniform_samples_of_a_uniform_rerun(rule):
    """lyapunov_pass(uniform=True): the samples at k tau from the paper run's own event loop
    are bitwise those of the trajectory re-simulated with uniform sampling to its end."""
    from kicktimes import schedules, simulate_one_particle, simulate_two_particle
    from kicktimes.diagnostics.lyapunov import lyapunov_pass

    steps = {"sampling": "paper", "n_steps": 1500, "tau": 0.3}
    for i, ic in enumerate(initial_conditions(6, 0.03, rng=17, rule=rule)):
        res, run, _, u = lyapunov_pass(ic, 0.02, rule=rule, t_continue=450.0, uniform=True,
                                       **steps)
        again = simulate_two_particle(ic, 0.02, t_max=run.t_max, tau=0.3, rule=rule)
        assert u.tobytes() == again.samples.tobytes()
        assert res == lyapunov_pass(ic, 0.02, rule=rule, t_continue=450.0, **steps)[0]
        for law in ("uniform", "scatter"):
            kicks = schedules.Poisson(0.05).sample(450.0, rng=np.random.default_rng(i))
            _, one, _, u1 = lyapunov_pass(ic[0], 0.02, kicks=KickLaw(kicks, angle=law),
                                          rng=np.random.default_rng(i), uniform=True, **steps)
            again = simulate_one_particle(ic[0], 0.02, t_max=one.t_max, tau=0.3,
                                          kicks=KickLaw(one.kick_times, angle=law,
                                                        angles=one.kick_angles))
            assert u1.tobytes() == again.samples.tobytes()
    # no uniform samples to record: uniform sampling, or holes (the run ends at an escape)
    ic = initial_conditions(1, 0.03, rng=18)[0]
    assert lyapunov_pass(ic, 0.02, n_steps=100, tau=0.3, uniform=True)[3] is None
    assert lyapunov_pass(ic, 0.02, holes=[(0.0, 0.1)], uniform=True, **steps)[3] is None
    with pytest.raises(TypeError, match="uniform"):
        lyapunov_pass(ic, 0.02, uniform="yes", **steps)


# --- eq. (4) of Rankovic & Porter read literally (renormalize=False) -------------------------


def _literal_eq4(reference, twin_x, twin_y, d0, tau):
    """``max`` over x and y of ``1/(n tau) sum_k log(|q_twin(k tau) - q(k tau)| / d0)``,
    from three separately simulated runs' samples (k = 1..n)."""
    lams = [np.log(np.abs(tw.samples[1:, c] - reference.samples[1:, c]) / d0).sum()
            / (tau * (reference.samples.shape[0] - 1)) for tw, c in ((twin_x, 0), (twin_y, 1))]
    return max(lams), lams


def test_the_literal_eq4_is_the_sum_of_log_raw_separations_of_two_trajectories():
    r, tau, n, d0 = 0.05, 0.2, 100, 1 / 5000
    ic = initial_conditions(1, r, rng=11)[0]
    reference = simulate_two_particle(ic, r, n_steps=n, tau=tau)
    twins = []
    for c in (0, 1):  # the paper's twins: the tracked disk moved by +d0 along x, along y
        moved = ic.copy()
        moved[0, c] += d0
        twins.append(simulate_two_particle(moved, r, n_steps=n, tau=tau))
    want, (want_x, want_y) = _literal_eq4(reference, *twins, d0, tau)
    got = lyapunov(reference, method=Twin(variant="paper", d0=d0, renormalize=False))
    assert not got.renormalized and got.n_renorm == 0
    np.testing.assert_allclose([got.lam, got.lam_x, got.lam_y], [want, want_x, want_y],
                               rtol=1e-7)
    # the separations saturated: the literal sum is far from Benettin's exponent
    benettin = lyapunov(reference, method=Twin(variant="paper", d0=d0))
    assert got.lam > 3 * benettin.lam > 0


def test_the_literal_eq4_of_a_kicked_run_shares_its_kicks():
    r, tau, n, d0 = 0.02, 0.2, 150, 1 / 5000
    state = initial_conditions(1, r, rng=5)[0][0]
    kicks = schedules.Poisson(rate=0.2).sample(n * tau, rng=np.random.default_rng(3))
    angles = np.random.default_rng(4).uniform(0, 2 * np.pi, kicks.size)
    common = dict(kicks=KickLaw(kicks, angles=angles, angle="uniform"), n_steps=n, tau=tau)
    reference = simulate_one_particle(state, r, **common)
    twins = []
    for c in (0, 1):
        moved = state.copy()
        moved[c] += d0
        twins.append(simulate_one_particle(moved, r, **common))
    want, parts = _literal_eq4(reference, *twins, d0, tau)
    got = lyapunov(reference, method=Twin(variant="paper", d0=d0, renormalize=False))
    assert kicks.size > 5 and got.n_perturbations == kicks.size
    np.testing.assert_allclose([got.lam, got.lam_x, got.lam_y], [want, *parts], rtol=1e-7)


@pytest.mark.parametrize("kick_angle", ["uniform", "gaussian"])
def test_independent_twins_take_their_own_angles_at_the_shared_times(kick_angle):
    r, tau, n, d0 = 0.02, 0.2, 150, 1 / 5000
    state = initial_conditions(1, r, rng=5)[0][0]
    kicks = schedules.Poisson(rate=0.2).sample(n * tau, rng=np.random.default_rng(3))
    angles = draw_kick_angles(kicks.size, kick_angle, 0.5, np.random.default_rng(4))
    common = dict(n_steps=n, tau=tau)
    law = KickLaw(kicks, angle=kick_angle, sigma=0.5)
    reference = simulate_one_particle(state, r, kicks=law.replace(angles=angles), **common)
    # the twins' angles: drawn from rng after the run's (here given, so none drawn)
    own = np.random.default_rng(7)
    twins = []
    for c in (0, 1):
        moved = state.copy()
        moved[c] += d0
        own_angles = draw_kick_angles(kicks.size, kick_angle, 0.5, own)
        twins.append(simulate_one_particle(moved, r, kicks=law.replace(angles=own_angles),
                                           **common))
    want, parts = _literal_eq4(reference, *twins, d0, tau)
    got = lyapunov(state, r, kicks=law.replace(angles=angles),
                   method=Twin(variant="paper", d0=d0, renormalize=False, twin_kicks="independent"),
                   rng=7, **common)
    np.testing.assert_allclose([got.lam, got.lam_x, got.lam_y], [want, *parts], rtol=1e-7)
    shared = lyapunov(reference, method=Twin(variant="paper", d0=d0, renormalize=False))
    assert got.lam != shared.lam
    # renormalised, each kick throws the twin O(1) away: far above the shared twins' value
    own_kicks = lyapunov(reference, method=Twin(d0=d0, twin_kicks="independent"), rng=7)
    assert own_kicks.lam > 3 * lyapunov(reference, method=Twin(d0=d0)).lam


def test_renormalize_false_needs_the_twin_method_and_a_bool(ics):
    ic = ics[0]
    with pytest.raises(TypeError, match="renormalize"):
        Tangent(renormalize=False)  # eq. (4) read literally is a reading of the twin
    with pytest.raises(TypeError, match="renormalize must be a bool"):
        lyapunov(ic, 0.03, n_steps=10, tau=0.2, method=Twin(renormalize="no"))
