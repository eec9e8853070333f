"""The public API's signatures read like scipy's (issue 61, CHANGELOG.md 0.2.0).

The rule for "the data" of a function: its positional parameters are the values the
function is about, the arrays or numbers it computes on (``times, t_window``, ``low, high``,
``verdicts, lows, highs``, ``n_disks, r``, a schedule's horizon ``t_max``). Everything that
tunes how it computes (a level, margin, tolerance, band, number of draws, random stream,
axis, threshold, choice of rule) is an option and keyword-only; so is every parameter with a
default (a default makes it optional, and an optional value is an option). A function made
only of options (the verdict rules: ``poisson_rule(*, margin, band)``) takes nothing by
position.

So, for every public function and method (walking ``kicktimes.__all__`` and the ``__all__``
of kicktimes.billiard, .schedules, .stats, .diagnostics, .experiment, .plots, .report,
.tables):

(a) no parameter is called ``seed`` unless it is a record (a result field, a config or
    file key: ``EXCEPT_SEED``); a renamed ``seed=`` survives only through
    `kicktimes.validation.renamed_keyword` (its marker attribute);
(b) every ``rng`` parameter is keyword-only;
(c) no positional parameter has a default or an option's name (``OPTIONS``), beyond the
    short, justified ``EXCEPT_POSITIONAL``.

Result records (dataclasses and NamedTuples) are exempt from (c): their fields are their
data, constructed by the library.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect

from kicktimes.validation import POSITIONAL_MARKER, RENAMED_MARKER

PUBLIC = ["kicktimes", "kicktimes.billiard", "kicktimes.schedules", "kicktimes.stats",
          "kicktimes.diagnostics", "kicktimes.experiment", "kicktimes.plots", "kicktimes.report",
          "kicktimes.tables"]

#: part "kicklaw" of issue 61 owns these signatures (rng=, keywords); tested in its part
KICKLAW = {"simulate_one_particle", "simulate_two_particle", "lyapunov", "analyze",
           "build_report"}

#: ``seed`` kept as a name: a record of the seed, not a random source taken here
EXCEPT_SEED = {
    # the JSON metadata key "seed" written beside the kick times (a file key)
    "write_kick_times",
    # the root of the keyed null streams, compared between banks and shown in its repr;
    # a SPEC 7 rng= for it is left for a later part (CHANGELOG.md)
    "MonteCarloNulls",
}

#: names that are always options
OPTIONS = {"alpha", "level", "margin", "tolerance", "band", "power", "rng", "seed", "n_boot",
           "n_mc", "n_runs", "axis", "eps", "lag", "threshold", "null", "floor", "default",
           "particle", "censored", "regression", "window"}

#: positional parameters with a default or an option's name, and why
EXCEPT_POSITIONAL = {
    # part "results" of issue 61 reshapes these (return_reason= -> a result; AcfCurve)
    "autocorrelation": "results part", "autocorrelation_function": "results part",
    "decorrelation_lag": "results part", "acf_curve": "results part",
    # numpy.nanmedian's own signature, which it mirrors
    "nanmedian": "numpy's signature",
    # both arguments are data (complete and censored intervals), each defaulting to the fit's
    "pointwise_loglik": "data with the fit's own as default",
    # the kinetic rate at (L, speed): both are where it is evaluated
    "rate": "the point of evaluation",
    # a spec is (model, params): the parameters are its data
    "from_spec": "the spec's data",
    # a preset is named by (name, content)
    "preset": "the preset's key",
    # a float that carries its reason: float(value) and the reason are its data
    "AcfValue": "a value and its reason",
}


def _public_callables():
    seen = set()
    for module_name in PUBLIC:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.ismodule(obj) or not callable(obj):
                continue
            targets = []
            record = inspect.isclass(obj) and (dataclasses.is_dataclass(obj)
                                               or hasattr(obj, "_fields"))
            if inspect.isclass(obj):
                targets.append((name, obj, record))
                for attr, value in vars(obj).items():
                    if attr.startswith("_"):
                        continue
                    if isinstance(value, classmethod | staticmethod):
                        value = value.__func__
                    if inspect.isfunction(value):
                        targets.append((attr, value, False))
            else:
                targets.append((name, obj, False))
            for short, func, is_record in targets:
                if id(func) in seen:
                    continue
                seen.add(id(func))
                try:
                    sig = inspect.signature(func)
                except (TypeError, ValueError):
                    continue
                yield f"{module_name}.{getattr(func, '__qualname__', short)}", short, func, \
                    sig, is_record


CALLABLES = list(_public_callables())


def _params(sig):
    return [p for p in sig.parameters.values() if p.name not in ("self", "cls")]


def test_the_walk_sees_the_public_api():
    names = {c[1] for c in CALLABLES}
    assert {"initial_conditions", "box_side", "ratio_verdict", "resample_indices",
            "recurrence_rate", "sample", "kick_rng"} <= names
    assert len(CALLABLES) > 200


def test_no_public_function_takes_seed():
    bad = []
    for qualname, short, func, sig, record in CALLABLES:
        if short in KICKLAW or short in EXCEPT_SEED or record:
            continue
        names = [p.name for p in _params(sig)]
        if "seed" in names:
            bad.append(f"{qualname}: the random source is rng= (SPEC 7)")
        renamed = getattr(func, RENAMED_MARKER, {})
        if not set(renamed.values()) <= set(names):
            bad.append(f"{qualname}: renamed to a keyword it does not take: {renamed}")
    assert not bad, "\n".join(bad)


def test_seed_survives_only_through_the_deprecation_path():
    import kicktimes as kt
    from kicktimes.experiment import kick_rng

    for func in (kt.initial_conditions, kt.initial_state, kick_rng):
        assert getattr(func, RENAMED_MARKER) == {"seed": "rng"}


#: the public functions that draw random numbers (or hand out a stream) and take rng=
RANDOM = {"initial_conditions", "initial_state", "kick_rng", "dilute_tagged_times",
          "resample_indices", "resample_counts", "sample", "simulate", "dispersion",
          "ks_share", "test_poisson", "test_poisson_ensemble", "poisson_group",
          "compare_models", "goodness_of_fit", "cluster_bootstrap", "paired_median",
          "paired_ratio", "ratio_of_means", "simulate_cox_times", "fit_mmpp", "simulate_mmpp",
          "ear1_intervals", "compare_point_processes", "mmpp_lr_test", "disks_lyapunov",
          "poisson_recollision_share", "recollision_share"}


def test_rng_is_keyword_only():
    bad = []
    for qualname, short, _func, sig, record in CALLABLES:
        if short in KICKLAW:
            continue
        params = {p.name: p for p in _params(sig)}
        if "rng" in params:
            if params["rng"].kind is not inspect.Parameter.KEYWORD_ONLY:
                bad.append(f"{qualname}: rng is not keyword-only")
        elif short in RANDOM and not record and not any(e in qualname for e in EXCEPT_SEED):
            bad.append(f"{qualname} draws random numbers but takes no rng=")
    assert not bad, "\n".join(bad)


def test_every_random_source_was_seen():
    seen = {c[1] for c in CALLABLES if "rng" in c[3].parameters}
    assert RANDOM <= seen, RANDOM - seen


def test_options_are_keyword_only():
    bad = []
    for qualname, short, _func, sig, record in CALLABLES:
        if record or short in KICKLAW or short in EXCEPT_POSITIONAL or short in EXCEPT_SEED:
            continue
        positional = [p for p in _params(sig)
                      if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
        defaulted = [p.name for p in positional if p.default is not p.empty]
        if defaulted:
            bad.append(f"{qualname}: {defaulted} have defaults, so they are options")
        options = [p.name for p in positional if p.name in OPTIONS]
        if options:
            bad.append(f"{qualname}: {options} are options: keyword-only")
    assert not bad, "\n".join(bad)


def test_formerly_positional_options_are_recorded():
    """Every function whose options became keyword-only still maps them (one release)."""
    from kicktimes import stats

    assert getattr(stats.ratio_verdict, POSITIONAL_MARKER) == ("tolerance",)
    assert getattr(stats.poisson_verdict, POSITIONAL_MARKER) == (
        "null_level", "dispersion_low", "dispersion_high")
