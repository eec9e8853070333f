"""Every public class summarises itself: ``summary()`` is a short, non-empty text.

The rule, checked by introspection: a *public class* is a class named in ``__all__`` of
``kicktimes`` or of one of its public subpackages (``billiard``, ``schedules``, ``stats``,
``diagnostics``, ``experiment``, ``plots``, ``report``). Every public class that is not an
exception or warning (``BaseException`` subclasses) and not abstract
(``inspect.isabstract``) must give ``summary()`` a non-empty ``str`` on a real instance.
That covers the results (dataclasses, former NamedTuples, `kicktimes._results.Value`
numbers), and on purpose also the models and helpers (the schedules, the experiment
configurations, the Monte Carlo bank): the protocol is uniform, and a new public class
fails :func:`test_every_public_class_is_built_here` until it is given an instance below.

The instances come from small real computations (short runs, small samples), each built
once; the numba kernels are cached, so the file takes a few seconds.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

SUBPACKAGES = ("billiard", "schedules", "stats", "diagnostics", "experiment", "plots", "report",
               "tables")
R = 0.05
#: the longest summary the protocol allows
MAX_LINES = 25


def public_classes() -> dict[str, type]:
    """``{name: class}`` of every public class the rule covers (see the module docstring)."""
    found = {}
    for name in ("kicktimes", *(f"kicktimes.{p}" for p in SUBPACKAGES)):
        module = importlib.import_module(name)
        for attr in module.__all__:
            obj = getattr(module, attr)
            if (inspect.isclass(obj) and not issubclass(obj, BaseException)
                    and not inspect.isabstract(obj)):
                found[obj.__name__] = obj
    return found


@pytest.fixture(scope="module")
def instances(tmp_path_factory):
    """One real instance of every public class, from small computations."""
    import kicktimes as kt
    from kicktimes import diagnostics as dg
    from kicktimes import experiment as ex
    from kicktimes import schedules as sch
    from kicktimes import stats
    from kicktimes.plots import kth_time_fit

    rng = np.random.default_rng(1)
    ic = kt.initial_conditions(1, R, rng=3)[0]
    two = kt.simulate_two_particle(ic, R, t_max=200.0, log_collisions=True, tau=0.5)
    one = kt.simulate_one_particle(ic[0], R, t_max=50.0, tau=0.5, kicks=sch.Poisson(1.0), rng=1)
    gas = kt.simulate_disks(kt.initial_state(5, R, rng=1), R, t_max=5.0)
    x = rng.exponential(size=200)
    fit = stats.fit_renewal(x, "gamma")
    times = [np.sort(rng.uniform(0, 50, size=k)) for k in (40, 60, 50)]
    mmpp = stats.fit_mmpp(times, 50.0, n_states=2, n_starts=2, rng=1)
    rows = [(f"s{k}", t, d) for k, d in enumerate([1.0, 1.0, 2.0, 2.0])
            for t in np.sort(rng.uniform(0, 50, rng.poisson(d * 50)))]
    events = pd.DataFrame(rows, columns=["sequence", "time", "density"])
    counts = pd.DataFrame({"radius": np.repeat([0.01, 0.02, 0.03], 10),
                           "count": rng.poisson(50, 30), "t_window": 100.0})
    escapes = rng.exponential(10.0, 50)
    escapes[escapes > 40.0] = np.inf
    exp = ex.Experiment(name="tiny", radii=[0.02], n_ics=2, n_steps=100, tau=0.3)
    task = exp.tasks()[0]
    store = ex.run_experiment(exp, tmp_path_factory.mktemp("store") / "tiny", progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dg.UndefinedDiagnosticWarning)
        undefined = dg.autocorrelation(np.zeros(10))
    built = {
        # kicktimes, kicktimes.billiard
        "TwoParticleRun": two,
        "OneParticleRun": one,
        "DisksRun": gas,
        "DisksPressure": gas.pressure(blocks=2),
        # kicktimes.schedules
        "Poisson": sch.Poisson(2.0),
        "Renewal": sch.Renewal(sps.gamma(2.0, scale=0.5)),
        "Replay": sch.Replay([0.5, 1.0, 2.5], t_max=3.0),
        "Bootstrap": sch.Bootstrap([0.5, 1.0, 2.0]),
        "MMPP": sch.MMPP([1.0, 4.0], [[-0.5, 0.5], [1.0, -1.0]]),
        "KineticRate": sch.KineticRate(R, n_grid=16),
        # kicktimes.stats
        "Analysis": stats.analyze(events, window=(0, 50), group="density", rng=1, n_mc=19,
                                  max_fits_per_group=1),
        "MonteCarloNulls": stats.MonteCarloNulls(7),
        "ClusterBootstrap": stats.cluster_bootstrap(lambda idx: x[:20][idx].mean(axis=1), 20,
                                                    n_boot=99, rng=1),
        "DiluteTaggedDisk": stats.dilute_tagged_disk("mirror"),
        "DiluteEstimate": stats.dilute_tagged_disk("mirror").dispersion(),
        "EscapeTail": stats.fit_escape_tail(escapes, 40.0, t_min=2.0),
        "RenewalFit": fit,
        "VuongResult": stats.vuong(x, "gamma", "weibull"),
        "GofResult": stats.goodness_of_fit(stats.fit_renewal(x, "exponential"), n_mc=19, rng=1),
        "Intervals": stats.intervals_from_times(times, 50.0),
        "PoissonEnsembleResult": stats.test_poisson_ensemble(times, 50.0, n_mc=19, rng=1),
        "PoissonGroup": stats.poisson_group(times, 50.0, n_mc=19, rng=1),
        "CountRegression": stats.regress_counts(counts, rule="mirror"),
        "Finding": stats.Finding("Poisson?", "consistent", "3 sequences, none rejects.",
                                 "p > 0.05", quantity="share", estimate=0.1, ci_low=0.02,
                                 ci_high=0.3, method="Clopper-Pearson"),
        "HazardTable": stats.interval_hazard(x, bins=4),
        "RateMixture": stats.rate_mixture([1.0, 3.0]),
        "MMPPFit": mmpp,
        "MMPPLRTest": stats.mmpp_lr_test(times, 50.0, n_boot=2, n_starts=2, rng=1),
        "RescaledTimes": stats.mmpp_residuals(mmpp, times, 50.0),
        # kicktimes.diagnostics
        "AcfCurve": dg.acf_curve(two.theta(0), 5),
        "AcfValue": undefined,
        "DisksLyapunov": dg.disks_lyapunov(kt.initial_state(5, R, rng=3), R, t_max=4.0,
                                           segment=1.0, rng=1),
        "LyapunovResult": dg.lyapunov(ic, R, n_steps=200, tau=0.2),
        "LyapunovSpectrum": dg.lyapunov_spectrum(ic, R, t_max=20.0),
        "RQAResult": dg.rqa(two.samples, eps=0.05),
        "RecollisionShare": dg.recollision_share(dg.collision_table(two), n_boot=99, rng=0),
        # kicktimes.experiment
        "Experiment": exp,
        "DisksExperiment": ex.disks_preset("disks-phi0.02-mirror"),
        "Store": store,
        "Task": task,
        "TaskOutput": ex.execute_task(exp, task),
        # kicktimes.billiard, diagnostics, report: the option values
        "KickLaw": kt.billiard.KickLaw(sch.Poisson(0.1), angle="gaussian", sigma=0.5),
        "Tangent": dg.Tangent(),
        "Twin": dg.Twin(d0=1e-4),
        "Render": kt.report.Render(dpi=90),
        "Subsampling": kt.report.Subsampling(),
        # kicktimes.tables
        "Circle": kt.tables.Circle(),
        "Stadium": kt.tables.Stadium(1.0),
        "Ellipse": kt.tables.Ellipse(1.5, 1.0),
        "TableRun": kt.tables.free_run(kt.tables.Stadium(1.0), [0.0, 0.0, 0.6, 0.8], R,
                                       n_bounces=50, rng=1),
        "TableLyapunov": kt.tables.table_lyapunov(kt.tables.Stadium(1.0), [0.0, 0.0, 0.6, 0.8],
                                                  R, n_bounces=200, rng=1),
        # kicktimes.plots
        "TimesFit": kth_time_fit(two.pp_times, sch.Poisson(1.0).sample(200.0, rng=1)),
    }
    return built


def test_every_public_class_is_built_here(instances):
    classes = public_classes()
    assert set(classes) == set(instances), (
        "give every public class an instance in the fixture: missing "
        f"{sorted(set(classes) - set(instances))}, stale {sorted(set(instances) - set(classes))}"
    )
    for name, obj in instances.items():
        assert isinstance(obj, classes[name]), name


@pytest.mark.parametrize("name", sorted(public_classes()))
def test_summary_is_a_short_nonempty_text(instances, name):
    obj = instances[name]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # summarising warns of nothing
        text = obj.summary()
        shown = repr(obj)
    assert isinstance(text, str) and text.strip()
    assert len(text.splitlines()) <= MAX_LINES, text
    assert isinstance(shown, str) and shown.startswith(type(obj).__name__) or isinstance(
        obj, float), shown
    assert len(shown) <= 600, shown  # readable: no array printed in full


#: the public classes that hold a table, and give it by ``to_frame()``
TABLES = {"TwoParticleRun", "OneParticleRun", "DisksRun", "PoissonEnsembleResult",
          "PoissonGroup", "CountRegression", "HazardTable", "AcfCurve", "TaskOutput"}


def test_results_holding_a_table_give_it_as_a_frame(instances):
    assert {name for name, obj in instances.items() if hasattr(obj, "to_frame")} == TABLES
    for name in TABLES:
        frame = instances[name].to_frame()
        assert isinstance(frame, pd.DataFrame) and frame.shape[1] > 0, name


def test_the_public_result_dataclasses_are_frozen():
    thawed = [name for name, cls in public_classes().items()
              if dataclasses.is_dataclass(cls) and not cls.__dataclass_params__.frozen]
    assert thawed == []


def test_a_summary_shows_the_estimate_with_its_interval_n_and_the_reason(instances):
    share = instances["RecollisionShare"]
    text = share.summary()
    assert f"n_collisions: {share.n_collisions}" in text and "(95 % interval)" in text
    assert "ci_low" not in text  # the bounds are shown with the estimate, not again
    tail = instances["EscapeTail"].summary()
    assert "rate: " in tail and "alpha: " in tail and tail.count("95 % interval") == 2
    assert "reason: constant series" in instances["AcfValue"].summary()


def test_undefined_results_say_why_in_a_reason():
    from kicktimes.diagnostics import recollision_share, rqa

    empty = pd.DataFrame({"interval": [np.nan], "wall_hits0": [0], "wall_hits1": [0]})
    nan_share = recollision_share(empty, rng=0)
    assert np.isnan(nan_share.share) and "n_collisions = 0" in nan_share.reason
    assert "reason: " in nan_share.summary()
    apart = rqa(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), eps=0.1)
    assert np.isnan(apart.det) and apart.reason.startswith("det: no recurrent pair")
    assert rqa(np.zeros((4, 2)), eps=0.1).reason is None


def test_fits_name_the_reason_of_a_nan_estimate_beside_converged(instances):
    from kicktimes import stats

    assert instances["RenewalFit"].reason is None and instances["MMPPFit"].reason is None
    rng = np.random.default_rng(0)
    poisson = pd.DataFrame({"radius": np.repeat([0.01, 0.02, 0.03], 10),
                            "count": rng.poisson(50, 30), "t_window": 100.0})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stats.FitWarning)
        counts = stats.regress_counts(poisson)
    assert counts.converged  # a different thing: alpha's standard error is undefined
    assert "alpha has no standard error" in counts.reason
    assert instances["DisksPressure"].reason is None and instances["TimesFit"].reason is None


def test_existing_summaries_keep_their_text(instances):
    fit = instances["RenewalFit"]
    assert fit.summary().splitlines()[0] == "Renewal fit: gamma (censored maximum likelihood)"
    assert instances["DisksPressure"].summary().startswith("Z wall ")


@pytest.mark.parametrize(("name", "fields"), [
    ("AcfCurve", ("acf", "lag_reasons", "reason")),
    ("Intervals", ("complete", "censored")),
    ("TimesFit", ("slope", "intercept", "r_squared", "n")),
])
def test_former_namedtuples_unpack_for_one_release_with_a_warning(instances, name, fields):
    obj = instances[name]
    with pytest.warns(DeprecationWarning, match=r"\." + r", \.".join(fields)):
        values = tuple(obj)
    assert all(v is getattr(obj, f) for v, f in zip(values, fields, strict=True))
    with pytest.warns(DeprecationWarning, match="as a tuple"):
        assert obj[0] is getattr(obj, fields[0]) and len(obj) == len(fields)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert obj  # truth needs no tuple protocol
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(obj, fields[0], None)


def test_format_value_keeps_arrays_and_tables_short():
    from kicktimes._results import format_value

    assert format_value(np.arange(1000.0)) == "array (1000,): 0, 1, 2, ..."
    assert format_value(pd.DataFrame({"a": [1, 2]})) == "table 2 x 1 (a)"
    assert format_value(list(range(50))).startswith("list of 50: 0, 1, 2")
