"""Specification of the sweep engine: experiments, tasks, executors, the store and resuming."""

from __future__ import annotations

import dataclasses
import errno
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import local_dask

from kicktimes.experiment import (
    COLLISION_COLUMNS,
    PRESETS,
    RESULT_COLUMNS,
    Experiment,
    StoreLockedError,
    StoreWarning,
    kick_rng,
    load_store,
    run_experiment,
    run_task,
)
from kicktimes.experiment.store import StoreWriter
from kicktimes.experiment.tasks import _actual_times

REPO = Path(__file__).resolve().parents[1]

TINY = Experiment(
    name="tiny",
    radii=[0.01, 0.025],
    n_ics=4,
    n_steps=400,
    tau=0.3,
    seed=7,
    sampling="paper",
    lyapunov_variant="paper",
    block_size=2,
)


def run_quiet(exp, path, **kw):
    kw.setdefault("progress", False)
    return run_experiment(exp, path, **kw)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The tiny experiment run in this process (workers=1): the reference for equality."""
    return run_quiet(TINY, tmp_path_factory.mktemp("ref") / "store", workers=1)


def assert_same_store(a, b):
    pd.testing.assert_frame_equal(a.results, b.results)
    pd.testing.assert_frame_equal(
        a.collisions.drop(columns="pp_times"), b.collisions.drop(columns="pp_times")
    )
    for x, y in zip(a.collisions["pp_times"], b.collisions["pp_times"], strict=True):
        np.testing.assert_array_equal(x, y)


# ------------------------------------------------------------------------ experiments


def test_toml_round_trip_preserves_the_experiment_and_its_hash(tmp_path):
    exp = dataclasses.replace(TINY, description='quotes " and \\ and unicode: é', eps=1e-5)
    path = tmp_path / "exp.toml"
    exp.write_toml(path)
    back = Experiment.from_toml(path)
    assert back == exp
    assert back.hash() == exp.hash()
    assert Experiment.from_dict(json.loads(json.dumps(exp.to_dict()))) == exp


def test_the_presets_have_the_papers_parameters_and_their_toml_reads_back(tmp_path):
    from click.testing import CliRunner

    from kicktimes.cli import main

    for name, exp in PRESETS.items():
        printed = CliRunner().invoke(main, ["presets", name])
        assert printed.exit_code == 0, printed.output
        assert Experiment.from_toml_string(printed.output) == exp
    a, b = PRESETS["family_a"], PRESETS["family_b"]
    assert a.radii == tuple(k / 1000 for k in range(8, 31, 2)) and len(a.radii) == 12
    assert (a.n_ics, a.n_steps, a.tau) == (200, 25000, 0.2)
    assert b.radii == tuple(k / 1000 for k in range(8, 27, 2)) and len(b.radii) == 10
    assert (b.n_ics, b.n_steps, b.tau) == (1000, 15000, 0.3)
    for exp in (a, b):
        assert exp.sampling == "paper" and exp.ic_method == "paper"
        assert exp.d0 == 1 / 5000 and exp.lyapunov_variant == "paper"
        assert exp.eps == (1e-3, 1e-2) and exp.rr_sampling == "run+uniform"
        assert exp.acf_max_lag == 20


def test_the_papers_content_drops_only_the_extensions():
    from kicktimes.experiment import preset

    for name, full in PRESETS.items():
        assert preset(name) is full and preset(name, content="full") is full
        paper = preset(name, content="paper")
        assert paper.systems == ("two_particle", "poisson", "actual")
        assert paper.eps == (1e-3,) and paper.acf_max_lag == 1 and paper.rr_sampling == "run"
        kept = {f.name for f in dataclasses.fields(Experiment)} - {
            "systems", "eps", "acf_max_lag", "rr_sampling", "description"
        }
        assert all(getattr(paper, k) == getattr(full, k) for k in kept)
        assert paper.hash() != full.hash()


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"name": "family_c"}, ValueError, "name: unknown preset"),
        ({"name": 3}, TypeError, "name: expected a str"),
        ({"name": "family_a", "content": "extended"}, ValueError, "content: expected one of"),
        ({"name": "family_a", "content": None}, TypeError, "content: expected a str"),
    ],
)
def test_preset_refuses_unknown_names_and_contents(kwargs, error, match):
    from kicktimes.experiment import preset

    with pytest.raises(error, match=match):
        preset(**kwargs)


def test_the_papers_rows_are_bitwise_the_same_in_both_contents():
    # the shared rows (every system, IC and radius) must not depend on the content: the
    # paper's quantities come from the same runs, kick draws and kernels
    from kicktimes.experiment.presets import PAPER_CONTENT

    full = dataclasses.replace(TINY, systems=PRESETS["family_a"].systems, n_ics=2, block_size=2)
    paper = dataclasses.replace(full, **PAPER_CONTENT)
    task = full.tasks()[0]
    rows_full, coll_full = run_task(full, task)
    rows_paper, coll_paper = run_task(paper, task)
    pd.testing.assert_frame_equal(coll_full, coll_paper)
    key = ["radius", "ic", "system", "diagnostic"]
    # the ACF curve's summaries (decorrelation lag, tau_int) depend on its length
    curve = {"decorrelation_lag", "tau_int"}
    shared = rows_paper[~rows_paper["diagnostic"].isin(curve)]
    both = shared.merge(rows_full, on=key, suffixes=("_paper", "_full"), validate="1:1")
    assert len(both) == len(shared) > 50
    assert set(both["system"]) == {"two_particle", "poisson", "actual"}
    assert {"recurrence_rate", "autocorrelation", "lyapunov", "n_pp"} <= set(both["diagnostic"])
    same = (both["value_paper"] == both["value_full"]) | (
        both["value_paper"].isna() & both["value_full"].isna()
    )
    assert same.all(), both[~same]
    assert (both["note_paper"] == both["note_full"]).all()


def test_reproduce_content_paper_writes_its_own_stores_and_report(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from kicktimes.cli import main
    from kicktimes.experiment import presets

    # the quick presets, shrunk: the command's wiring is under test, not the science
    for name in ("quick_a", "quick_b"):
        monkeypatch.setitem(
            presets.PRESETS,
            name,
            dataclasses.replace(presets.PRESETS[name], radii=[0.02], n_ics=2, n_steps=120),
        )
    results = tmp_path / "results"
    result = CliRunner().invoke(
        main,
        ["reproduce", "--content", "paper", "--out", str(tmp_path), "--workers", "1",
         "--no-progress", "--results", str(results)],
    )
    assert result.exit_code == 0, result.output
    for name in ("quick_a", "quick_b"):
        store = load_store(tmp_path / f"store-{name}-paper")
        assert store.experiment == presets.preset(name, content="paper")
        assert set(store.results["system"]) == {"two_particle", "poisson", "actual"}
    assert (tmp_path / "report-paper" / "report.html").is_file()
    assert not (tmp_path / "report").exists()
    assert not (tmp_path / "store-quick_a").exists()
    assert f"page written to {tmp_path / 'results' / 'README.md'}" in result.output
    # --results: the study's page, its Generated line naming the command
    page = (results / "README.md").read_text(encoding="utf-8")
    generated = next(line for line in page.splitlines() if line.startswith("Generated "))
    assert f"`kicktimes reproduce --study paper --scale quick --results {results}`" in generated
    assert (results / "quick_a_findings.csv").is_file()


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"radii": []}, "radii"),
        ({"radii": [0.01, 0.6]}, "radii"),
        ({"radii": [0.01, 0.01]}, "distinct"),
        ({"n_ics": 0}, "n_ics"),
        ({"n_steps": 2.5}, "n_steps"),
        ({"tau": -0.1}, "tau"),
        ({"tau": math.nan}, "tau"),
        ({"eps": math.inf}, "eps"),
        ({"eps": []}, "eps"),
        ({"eps": [0.001, 0.001]}, "eps: thresholds must be distinct"),
        ({"eps": [0.001, -0.01]}, "eps\\[1\\]"),
        ({"eps": "0.001"}, "eps"),
        ({"rr_sampling": "paper"}, "rr_sampling"),
        ({"acf_max_lag": 0}, "acf_max_lag"),
        ({"acf_max_lag": 2.5}, "acf_max_lag"),
        ({"sampling": "daily"}, "sampling"),
        ({"systems": ["two_particle", "kicked"]}, "systems"),
        ({"diagnostics": []}, "diagnostics"),
        ({"lyapunov_variant": "max"}, "lyapunov_variant"),
        ({"block_size": True}, "block_size"),
        ({"name": "a b/c"}, "name"),
    ],
)
def test_invalid_fields_are_refused_with_the_field_name(change, match):
    with pytest.raises((ValueError, TypeError), match=match):
        dataclasses.replace(TINY, **change)


def test_unknown_or_missing_toml_keys_are_refused():
    text = TINY.to_toml()
    with pytest.raises(ValueError, match="unknown experiment key.*n_ic\\b"):
        Experiment.from_toml_string(text + "n_ic = 3\n")
    with pytest.raises(ValueError, match="missing required.*tau"):
        Experiment.from_toml_string(text.replace("tau = 0.3\n", ""))
    with pytest.raises(ValueError, match="invalid TOML"):
        Experiment.from_toml_string("name = ")


def test_hash_changes_with_every_parameter_but_not_with_the_order_of_radii():
    assert dataclasses.replace(TINY, radii=[0.025, 0.01]).hash() == TINY.hash()
    for change in (
        {"seed": 8},
        {"tau": 0.31},
        {"rule": "elastic"},
        {"block_size": 3},
        {"eps": 0.001},
        {"eps": (0.01, 0.001)},
        {"rr_sampling": "uniform"},
        {"acf_max_lag": 21},
    ):
        assert dataclasses.replace(TINY, **change).hash() != TINY.hash()


def test_a_single_eps_is_accepted_and_kept_as_a_tuple():
    exp = dataclasses.replace(TINY, eps=0.002)
    assert exp.eps == (0.002,)
    assert Experiment.from_toml_string(exp.to_toml()) == exp
    text = TINY.to_toml().replace("eps = [0.001, 0.01]", "eps = 0.001")
    assert Experiment.from_toml_string(text).eps == (0.001,)


def legacy_record(exp: Experiment) -> dict:
    """The record of a store written before eps lists, acf_max_lag, rr_sampling,
    lyapunov_method, holes, unequal disks (partner_ratio, partner_mass), log_events and
    table."""
    record = exp.to_dict()
    del record["acf_max_lag"], record["rr_sampling"], record["lyapunov_method"]
    del record["holes"], record["partner_ratio"], record["partner_mass"], record["log_events"]
    del record["table"]
    record["eps"] = record["eps"][0]
    return record


def test_experiments_of_the_old_format_keep_their_hash():
    import hashlib

    old = dataclasses.replace(TINY, eps=0.001, lyapunov_method="twin")
    record = legacy_record(old)
    text = json.dumps(record, sort_keys=True, separators=(",", ":"))
    assert old.hash() == hashlib.sha256(text.encode()).hexdigest()[:16]
    assert Experiment.from_record(record) == old
    assert Experiment.from_dict(record).lyapunov_method == "tangent"  # a TOML gets the default
    assert old.hash() == "21f9b7ce323e6659"  # computed by kicktimes before this change


def test_a_store_written_before_the_new_rows_still_loads(tmp_path):
    old = dataclasses.replace(
        TINY, eps=0.001, radii=[0.02], n_ics=1, n_steps=50, diagnostics=["recurrence_rate"],
        lyapunov_method="twin",
    )
    run_quiet(old, tmp_path / "s", workers=1)
    manifest = json.loads((tmp_path / "s" / "manifest.json").read_text())
    manifest["experiment"] = legacy_record(old)  # what an older kicktimes wrote
    (tmp_path / "s" / "manifest.json").write_text(json.dumps(manifest))
    store = load_store(tmp_path / "s")
    assert store.experiment == old and store.complete


# ----------------------------------------------------------------------------- tasks


def test_tidy_tables_have_the_documented_columns_and_one_row_per_value(reference):
    res, coll = reference.results, reference.collisions
    assert tuple(res.columns) == RESULT_COLUMNS
    assert tuple(coll.columns) == COLLISION_COLUMNS
    assert res["radius"].dtype == np.float64 and res["ic"].dtype == np.int64
    assert res["value"].dtype == np.float64
    assert not res.duplicated(["radius", "ic", "system", "diagnostic"]).any()
    per_system = {
        "two_particle": {"t_max", "n_pp", "n_boundary"},
        "poisson": {"t_max", "kick_rate", "n_kicks", "n_boundary"},
        "actual": {"t_max", "n_kicks", "n_boundary"},
    }
    common = {
        "recurrence_rate",
        "autocorrelation",
        "decorrelation_lag",
        "tau_int",
        "lyapunov",
        "lyapunov_x",
        "lyapunov_y",
        "lyapunov_n_renorm",
        "lyapunov_n_forced",
    }
    common |= {f"{name}@{e}" for name in ("rr", "rr_offdiag", "det", "l_mean", "l_max")
               for e in ("0.001", "0.01")}
    common |= {f"acf@{lag}" for lag in range(1, 21)}
    for (system, _, _), group in res.groupby(["system", "radius", "ic"]):
        assert set(group["diagnostic"]) == per_system[system] | common
    # NaN only with a reason; reasons only with NaN, except tau_int's "lower bound" remark
    assert (res["note"][res["value"].isna()] != "").all()
    finite_noted = res[res["value"].notna() & (res["note"] != "")]
    assert set(finite_noted["diagnostic"]) <= {"tau_int"}
    assert finite_noted["note"].str.contains("lower bound").all()
    assert len(coll) == TINY.n_ics * len(TINY.radii)
    assert coll["n_pp"].tolist() == [len(t) for t in coll["pp_times"]]
    for row in coll.itertuples():
        assert np.all(np.diff(row.pp_times) > 0) and (row.pp_times <= row.t_window).all()


def test_recurrence_and_acf_rows_are_the_library_diagnostics_of_the_run():
    from kicktimes import initial_conditions, simulate_two_particle
    from kicktimes.diagnostics import (
        autocorrelation,
        autocorrelation_function,
        boundary_angles,
        recurrence_rate,
        rqa,
    )

    exp = dataclasses.replace(TINY, systems=["two_particle"], diagnostics=["recurrence_rate",
                              "autocorrelation"], acf_max_lag=5, eps=(0.01, 0.05))
    res, _ = run_task(exp, exp.tasks()[3])  # r = 0.025, ICs 2 and 3
    got = res[res.ic == 2].set_index("diagnostic")["value"]
    ic = initial_conditions(4, 0.025, rng=7)[2]
    run = simulate_two_particle(ic, 0.025, sampling="paper", n_steps=400, tau=0.3)
    pts, n = run.samples, len(run.samples)
    assert got["recurrence_rate"] == got["rr@0.01"] == recurrence_rate(pts, eps=0.01)
    for e in (0.01, 0.05):
        q = rqa(pts, eps=e)
        assert got[f"rr@{e:g}"] == recurrence_rate(pts, eps=e)
        assert got[f"rr_offdiag@{e:g}"] == q.rr == recurrence_rate(pts, eps=e, theiler=1)
        assert n * got[f"rr@{e:g}"] - 1 == pytest.approx((n - 1) * q.rr, rel=1e-12)
        np.testing.assert_equal([got[f"det@{e:g}"], got[f"l_max@{e:g}"]], [q.det, q.l_max])
    theta = boundary_angles(run, particle=0)
    assert got["autocorrelation"] == got["acf@1"] == autocorrelation(theta, 1)
    np.testing.assert_array_equal(
        got[[f"acf@{lag}" for lag in range(1, 6)]], autocorrelation_function(theta, 5)
    )
    assert "acf@6" not in got.index


@pytest.mark.parametrize(
    ("theta", "lag", "max_lag"),
    [
        (np.sin(np.arange(300.0)), 1, 20),
        (np.sin(np.arange(300.0)), 3, 2),  # R_lag beyond the curve: its own call
        (np.full(40, 0.2), 1, 5),  # constant: NaN with the reason
        (np.array([0.1, -0.4, 0.3]), 2, 6),  # short: NaN beyond N - 1
        (np.array([0.5]), 1, 3),
    ],
)
def test_acf_rows_take_r_lag_from_the_curve_exactly(theta, lag, max_lag):
    # the rows compute one curve and read R_lag off it: value and note must be what
    # the public functions give
    from kicktimes.diagnostics import (
        UndefinedDiagnosticWarning,
        autocorrelation,
        autocorrelation_function,
    )
    from kicktimes.experiment.tasks import autocorrelation_rows

    rows = {name: (value, note) for name, value, note in
            autocorrelation_rows(theta, lag, max_lag)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
        value = autocorrelation(theta, lag)
    reason = value.reason
    np.testing.assert_equal(rows["autocorrelation"], (value, reason or ""))
    curve, reason = autocorrelation_function(theta, max_lag, return_reason=True)
    for k in range(max_lag):
        note = (reason or "") if np.isnan(curve[k]) else ""
        np.testing.assert_equal(rows[f"acf@{k + 1}"], (curve[k], note))


def test_uniform_rr_sampling_uses_a_uniform_rerun_of_the_same_trajectory():
    from kicktimes import initial_conditions, simulate_two_particle
    from kicktimes.diagnostics import recurrence_rate
    from kicktimes.experiment.tasks import uniform_samples

    exp = dataclasses.replace(TINY, diagnostics=["recurrence_rate"], n_ics=2)
    uni = dataclasses.replace(exp, rr_sampling="uniform")
    by_run, _ = run_task(exp, exp.tasks()[0])
    by_uni, _ = run_task(uni, uni.tasks()[0])
    key = ["radius", "ic", "system", "diagnostic"]
    a, b = by_run.set_index(key)["value"], by_uni.set_index(key)["value"]
    rr_rows = a.index.get_level_values("diagnostic").str.contains("rr|recurrence|det|l_")
    pd.testing.assert_series_equal(a[~rr_rows], b[~rr_rows])  # nothing else changes
    assert (a[rr_rows] != b[rr_rows]).any()
    ic = initial_conditions(2, 0.025, rng=7)[0]
    run = simulate_two_particle(ic, 0.01, sampling="paper", n_steps=400, tau=0.3)
    again = simulate_two_particle(ic, 0.01, t_max=run.t_max, tau=0.3, sampling="uniform")
    assert b[(0.01, 0, "two_particle", "rr@0.001")] == recurrence_rate(again.samples, eps=1e-3)
    # the uniform re-run retraces the paper-sampled run's trajectory, kicks included
    from kicktimes import simulate_one_particle

    kicked = simulate_one_particle(ic[0], 0.01, kicks=np.array([3.0, 50.0, 77.7]),
                                   sampling="paper", n_steps=400, tau=0.3, rng=5)
    pts = uniform_samples(uni, "poisson", ic, 0.01, kicked)
    assert len(pts) == int(np.floor(kicked.t_max / 0.3 * (1 + 1e-12))) + 1
    same_times = np.isin(kicked.sample_times, np.arange(len(pts)) * 0.3)
    assert same_times.any()
    idx = np.round(kicked.sample_times[same_times] / 0.3).astype(int)
    np.testing.assert_allclose(kicked.samples[same_times], pts[idx], atol=1e-9)
    # with uniform sampling there is nothing to re-run
    flat = dataclasses.replace(uni, sampling="uniform")
    assert uniform_samples(flat, "poisson", ic, 0.01, kicked) is kicked.samples


def test_poisson_rate_and_window_come_from_the_same_ics_two_particle_run(reference):
    res = reference.results.set_index(["radius", "ic", "system", "diagnostic"])["value"]
    for row in reference.collisions.itertuples():
        assert res[(row.radius, row.ic, "two_particle", "t_max")] == row.t_window
        assert res[(row.radius, row.ic, "two_particle", "n_pp")] == row.n_pp
        assert res[(row.radius, row.ic, "poisson", "kick_rate")] == row.n_pp / row.t_window


def test_ics_are_drawn_once_at_the_largest_radius_and_shared_by_all_radii():
    from kicktimes import initial_conditions, simulate_two_particle

    exp = dataclasses.replace(TINY, systems=["two_particle"], diagnostics=["recurrence_rate"])
    _, coll = run_task(exp, exp.tasks()[0])  # r = 0.01, ICs 0 and 1
    ic = initial_conditions(2, 0.025, rng=7)[1]
    run = simulate_two_particle(ic, 0.01, sampling="paper", n_steps=400, tau=0.3)
    np.testing.assert_array_equal(coll["pp_times"][1], run.pp_times)


def test_actual_kicks_cover_the_whole_paper_sampled_one_particle_run():
    from kicktimes import initial_conditions, simulate_two_particle

    ic = initial_conditions(1, 0.03, rng=3)[0]
    two = simulate_two_particle(ic, 0.03, sampling="paper", n_steps=2000, tau=0.3)
    times = _actual_times(dataclasses.replace(TINY, n_steps=2000), ic, 0.03, two)
    # the sampled run ends before n_steps * tau; its collisions are the continuation's start
    assert two.t_max < 600.0 and times[-1] > two.t_max and times[-1] <= 600.0
    np.testing.assert_array_equal(times[: two.n_pp], two.pp_times)


@pytest.mark.reproducibility
def test_sweep_results_are_bitwise_those_of_separate_simulation_and_ftle_runs():
    # small experiments (paper setup of both families with every system and diagnostic,
    # uniform sampling, elastic rule with gaussian kicks, MMPP kicks): the one-pass sweep
    # and separate simulation, FTLE and actual-time continuation calls per trajectory,
    # both computed here, must agree in every bit
    import importlib.util

    data = REPO / "tests" / "data"
    spec = importlib.util.spec_from_file_location("sweep_cases", data / "sweep_cases.py")
    cases = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cases)
    separate = cases.tables(one_pass=False)
    assert len(separate[0]) == 9054 and len(separate[1]) == 30  # with the uniform_ rows
    assert set(separate[0]["system"]) == {"two_particle", "poisson", "actual",
                                          "poisson_scatter", "actual_scatter",
                                          "poisson_kinetic", "uniform_kinetic", "mmpp"}
    assert cases.differences(separate, cases.tables()) == []


def test_one_pass_continues_the_two_disk_run_to_the_horizon_for_the_actual_kicks():
    from kicktimes import initial_conditions, simulate_two_particle
    from kicktimes.diagnostics.lyapunov import lyapunov_pass

    exp = dataclasses.replace(TINY, n_steps=2000)
    ic = initial_conditions(1, 0.03, rng=3)[0]
    two = simulate_two_particle(ic, 0.03, sampling="paper", n_steps=2000, tau=0.3)
    _, run, times = lyapunov_pass(ic, 0.03, sampling="paper", n_steps=2000, tau=0.3,
                                  t_continue=exp.horizon)
    np.testing.assert_array_equal(run.pp_times, two.pp_times)
    assert run.t_max == two.t_max < exp.horizon
    np.testing.assert_array_equal(times, _actual_times(exp, ic, 0.03, two))
    assert times.size > two.n_pp


def test_the_one_pass_sweep_keeps_its_stage_timings_under_the_ftle_keys():
    from kicktimes.experiment import execute_task

    out = execute_task(TINY, TINY.tasks()[0])
    # simulation + FTLE of every trajectory is timed as one stage; no separate simulation
    assert out.timings["lyapunov_two_particle"] > 0 and out.timings["lyapunov_kicked"] > 0
    assert "simulation_two_particle" not in out.timings
    plain = dataclasses.replace(TINY, diagnostics=["recurrence_rate"])
    assert "simulation_two_particle" in execute_task(plain, plain.tasks()[0]).timings


def test_kick_streams_differ_by_ic_radius_and_system_and_ignore_the_radius_list():
    draws = {
        key: kick_rng(*key, rng=7).random()
        for key in [
            (0, 0.01, "poisson"),
            (1, 0.01, "poisson"),
            (0, 0.02, "poisson"),
            (0, 0.01, "actual"),
        ]
    }
    assert len(set(draws.values())) == 4
    one = dataclasses.replace(TINY, radii=[0.025])
    res_one, _ = run_task(one, one.tasks()[0])
    res_two, _ = run_task(TINY, TINY.tasks()[2])  # radius 0.025 of the two-radius family
    pd.testing.assert_frame_equal(res_one, res_two)


def test_run_task_rejects_a_task_of_another_experiment():
    task = dataclasses.replace(TINY, radii=[0.02]).tasks()[0]
    with pytest.raises(ValueError, match="radius"):
        run_task(TINY, task)


# -------------------------------------------------------------------------- executors


@pytest.mark.reproducibility
def test_results_are_identical_for_one_or_two_processes_and_threads(reference, tmp_path):
    two = run_quiet(TINY, tmp_path / "two", workers=2)
    assert_same_store(reference, two)
    with ThreadPoolExecutor(max_workers=3) as pool:
        threads = run_quiet(TINY, tmp_path / "threads", executor=pool)
    assert_same_store(reference, threads)


@pytest.mark.reproducibility
def test_results_are_identical_on_a_dask_local_cluster(reference, tmp_path):
    with local_dask(n_workers=2) as (cluster, client):
        on_dask = run_quiet(TINY, tmp_path / "dask", executor=client.get_executor())
        via_address = run_quiet(TINY, tmp_path / "addr", scheduler=cluster.scheduler_address)
    assert_same_store(reference, on_dask)
    assert_same_store(reference, via_address)


@pytest.mark.reproducibility
def test_results_do_not_depend_on_the_block_size(reference, tmp_path):
    other = run_quiet(dataclasses.replace(TINY, block_size=3), tmp_path / "b3", workers=1)
    assert_same_store(reference, other)


def test_missing_dask_gives_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(ImportError, match=r"kicktimes\[dask\]"):
        run_quiet(TINY, tmp_path / "s", scheduler="tcp://127.0.0.1:1")


def test_bad_runner_arguments_are_refused(tmp_path):
    with pytest.raises(ValueError, match="workers"):
        run_quiet(TINY, tmp_path / "s", workers=0)
    with pytest.raises(ValueError, match="workers"):
        with ThreadPoolExecutor(1) as pool:
            run_quiet(TINY, tmp_path / "s", workers=2, executor=pool)


# ------------------------------------------------------------------- store and resume


def test_store_layout_manifest_and_no_temporary_files(reference):
    root = reference.path
    names = sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file())
    ids = [t.id for t in TINY.tasks()]
    expected = [".lock", "manifest.json"]
    expected += [f"collisions/{i}.parquet" for i in ids] + [f"results/{i}.parquet" for i in ids]
    assert names == sorted(expected)
    manifest = json.loads((root / "manifest.json").read_text())
    assert manifest["experiment_hash"] == TINY.hash()
    assert Experiment.from_dict(manifest["experiment"]) == TINY
    assert set(manifest["tasks"]) == set(ids)
    entry = manifest["tasks"][ids[0]]
    assert {"file", "sha256", "rows", "collisions_file", "collisions_sha256"} <= set(entry)
    assert reference.complete and reference.missing_tasks == []


def test_rerunning_a_finished_store_recomputes_nothing(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    before = {p: p.stat().st_mtime_ns for p in path.rglob("*.parquet")}
    with warnings.catch_warnings():
        warnings.simplefilter("error", StoreWarning)
        again = run_quiet(TINY, path, workers=1)
    assert {p: p.stat().st_mtime_ns for p in path.rglob("*.parquet")} == before
    assert_same_store(reference, again)


@pytest.mark.filterwarnings("ignore:.*leftover temporary file")
def test_resume_after_a_killed_run_equals_an_uninterrupted_run(tmp_path):
    exp = dataclasses.replace(TINY, n_ics=24, block_size=1, n_steps=1500)
    toml = tmp_path / "exp.toml"
    exp.write_toml(toml)
    store = tmp_path / "store"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "kicktimes",
            "run",
            str(toml),
            "--out",
            str(store),
            "--workers",
            "1",
            "--no-progress",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    manifest = store / "manifest.json"
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline:
            if manifest.exists() and len(json.loads(manifest.read_text())["tasks"]) >= 3:
                break
            time.sleep(0.02)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait(30)
    done = len(json.loads(manifest.read_text())["tasks"])
    assert 3 <= done < len(exp.tasks()), "the run was not stopped midway"
    partial = load_store(store)
    assert len(partial.missing_tasks) == len(exp.tasks()) - done
    resumed = run_quiet(exp, store, workers=2)
    whole = run_quiet(exp, tmp_path / "whole", workers=1)
    assert_same_store(whole, resumed)
    assert not list(store.rglob(".tmp-*"))


def test_a_part_written_but_not_yet_in_the_manifest_is_recomputed_once(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    manifest = json.loads((path / "manifest.json").read_text())
    del manifest["tasks"][TINY.tasks()[1].id]  # as if killed between part and manifest
    (path / "manifest.json").write_text(json.dumps(manifest))
    (path / "results" / ".tmp-abc.parquet").write_bytes(b"half a file")
    with pytest.warns(StoreWarning, match="leftover temporary"):
        resumed = run_quiet(TINY, path, workers=1)
    assert_same_store(reference, resumed)
    assert len(list((path / "results").iterdir())) == len(TINY.tasks())


def test_a_damaged_part_is_refused_by_load_and_recomputed_by_run(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    victim = path / "results" / f"{TINY.tasks()[2].id}.parquet"
    victim.write_bytes(victim.read_bytes()[:-40])
    with pytest.raises(ValueError, match=f"damaged store.*{TINY.tasks()[2].id}"):
        load_store(path)
    with pytest.warns(StoreWarning, match="damaged"):
        repaired = run_quiet(TINY, path, workers=1)
    assert_same_store(reference, repaired)


def test_a_foreign_part_is_detected_and_recomputed(reference, tmp_path):
    other = dataclasses.replace(TINY, seed=8)
    foreign = run_quiet(other, tmp_path / "other", workers=1)
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    tid = TINY.tasks()[0].id
    # a foreign part swapped in together with a manifest entry that matches its checksum
    for part in ("results", "collisions"):
        shutil.copy(foreign.path / part / f"{tid}.parquet", path / part / f"{tid}.parquet")
    manifest = json.loads((path / "manifest.json").read_text())
    manifest["tasks"][tid] = json.loads((foreign.path / "manifest.json").read_text())["tasks"][tid]
    (path / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ValueError, match="foreign"):
        load_store(path)
    with pytest.warns(StoreWarning, match="foreign"):
        repaired = run_quiet(TINY, path, workers=1)
    assert_same_store(reference, repaired)
    # a foreign part lying in the store without a manifest entry is reported too
    del manifest["tasks"][tid]
    (path / "manifest.json").write_text(json.dumps(manifest))
    shutil.copy(foreign.path / "results" / f"{tid}.parquet", path / "results" / f"{tid}.parquet")
    with pytest.warns(StoreWarning, match="foreign part"):
        repaired = run_quiet(TINY, path, workers=1)
    assert_same_store(reference, repaired)


def test_a_store_of_another_experiment_is_refused_naming_both(reference, tmp_path):
    other = dataclasses.replace(TINY, name="tiny_other", n_steps=401)
    with pytest.raises(ValueError) as info:
        run_quiet(other, reference.path, workers=1)
    message = str(info.value)
    for text in ("tiny", "tiny_other", TINY.hash(), other.hash()):
        assert text in message


def test_a_directory_that_is_not_a_store_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("my thesis")
    with pytest.raises(ValueError, match="not a kicktimes store"):
        run_quiet(TINY, tmp_path, workers=1)
    with pytest.raises(ValueError, match="not a kicktimes store"):
        load_store(tmp_path)


# ---------------------------------------------------------------- store hardening


def _edit_manifest(path, edit):
    manifest = json.loads((path / "manifest.json").read_text())
    edit(manifest)
    (path / "manifest.json").write_text(json.dumps(manifest))


def test_a_second_writer_is_refused_and_leaves_the_first_writers_files_alone(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    with StoreWriter(path, TINY):
        in_flight = path / "results" / ".tmp-in-flight.parquet"
        in_flight.write_bytes(b"being written")
        with pytest.raises(StoreLockedError, match=r"being written by another kicktimes run \(pid"):
            run_quiet(TINY, path, workers=1)
        assert in_flight.exists()
        in_flight.unlink()
    assert run_quiet(TINY, path, workers=1).complete  # the lock is released on close


def test_a_second_writer_can_wait_for_the_lock(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    writer = StoreWriter(path, TINY)
    with pytest.raises(StoreLockedError, match="after waiting 0.2 s"):
        run_quiet(TINY, path, workers=1, wait=0.2)
    timer = threading.Timer(0.3, writer.close)
    timer.start()
    start = time.monotonic()
    assert run_quiet(TINY, path, workers=1, wait=True).complete
    assert time.monotonic() - start >= 0.25
    timer.join()


@pytest.mark.parametrize("wait", [-1, float("nan"), "yes"])
def test_a_bad_wait_is_refused(tmp_path, wait):
    with pytest.raises(ValueError, match="wait: must be"):
        run_quiet(TINY, tmp_path / "s", workers=1, wait=wait)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_pool_workers_exit_when_the_driver_is_killed(tmp_path):
    exp = dataclasses.replace(TINY, n_ics=40, block_size=1, n_steps=20000)
    script = (
        "import sys\nfrom kicktimes.experiment import Experiment, run_experiment\n"
        f"run_experiment(Experiment.from_toml({str(tmp_path / 'e.toml')!r}), "
        f"{str(tmp_path / 'store')!r}, workers=2, progress=False)\n"
    )
    exp.write_toml(tmp_path / "e.toml")
    proc = subprocess.Popen([sys.executable, "-c", script])
    children_file = Path(f"/proc/{proc.pid}/task/{proc.pid}/children")
    children = []
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline and len(children) < 2:
            time.sleep(0.1)
            children = children_file.read_text().split() if children_file.exists() else []
        assert len(children) >= 2, "the pool did not start"
    finally:
        proc.kill()
        proc.wait(30)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(Path(f"/proc/{c}").exists() for c in children):
        time.sleep(0.1)
    alive = [c for c in children if Path(f"/proc/{c}").exists()]
    for c in alive:  # do not leak them if the test fails
        os.kill(int(c), signal.SIGKILL)
    assert not alive, f"pool workers {alive} outlived the killed driver"


@pytest.mark.parametrize("bad", ["../../x.parquet", "/etc/passwd", "results/other.parquet"])
def test_manifest_entries_may_only_name_their_own_files(reference, tmp_path, bad):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    tid = TINY.tasks()[0].id

    def point_elsewhere(m):
        m["tasks"][tid]["file"] = bad

    _edit_manifest(path, point_elsewhere)
    with pytest.raises(ValueError, match="may only name their own files"):
        load_store(path)
    with pytest.warns(StoreWarning, match=f"task {tid}: .*may only name their own files"):
        repaired = run_quiet(TINY, path, workers=1)
    assert_same_store(reference, repaired)
    manifest = json.loads((path / "manifest.json").read_text())
    assert manifest["tasks"][tid]["file"] == f"results/{tid}.parquet"


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda m: m.update(layout=2), "layout 2 .* upgrade kicktimes"),
        (lambda m: m.update(layout=0), "layout 0 .* not a valid layout"),
        (lambda m: m.update(layout="1"), "'layout' must be a JSON integer"),
        (lambda m: m.pop("layout"), "has no 'layout' entry"),
        (lambda m: m.update(tasks=[]), "'tasks' must be a JSON object"),
        (lambda m: m.update(experiment=None), "'experiment' must be a JSON object"),
        (lambda m: m["experiment"].update(radii=[]), "bad experiment record"),
    ],
)
def test_a_corrupt_manifest_is_refused_with_a_clear_message(reference, tmp_path, edit, match):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    _edit_manifest(path, edit)
    with pytest.raises(ValueError, match=match):
        load_store(path)
    with pytest.raises(ValueError, match=match if "record" not in match else "."):
        run_quiet(TINY, path, workers=1)


def test_a_manifest_that_is_not_an_object_is_refused(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    (path / "manifest.json").write_text("[]")
    with pytest.raises(ValueError, match="holds a JSON list, not an object"):
        load_store(path)


def test_a_null_task_entry_is_refused_by_load_and_recomputed_by_run(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    tid = TINY.tasks()[1].id
    _edit_manifest(path, lambda m: m["tasks"].update({tid: None}))
    with pytest.raises(ValueError, match=f"task {tid}: manifest entry is a JSON NoneType"):
        load_store(path)
    with pytest.warns(StoreWarning, match="it will be recomputed"):
        assert_same_store(reference, run_quiet(TINY, path, workers=1))


def test_opening_a_complete_store_writes_nothing(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    before = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in path.rglob("*") if p.is_file()}
    run_quiet(TINY, path, workers=1)
    after = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in path.rglob("*") if p.is_file()}
    assert {p: v for p, v in after.items() if p.name != ".lock"} == {
        p: v for p, v in before.items() if p.name != ".lock"
    }


def _read_only(monkeypatch, root):
    """Make the store look read-only (the tests may run as root, which ignores modes)."""
    import kicktimes.experiment.store as store_module

    real_open = os.open

    def refuse_writes(path, flags, *args):
        if Path(path).parent == Path(root) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT):
            raise PermissionError(errno.EROFS, "Read-only file system", os.fspath(path))
        return real_open(path, flags, *args)

    monkeypatch.setattr(store_module.os, "open", refuse_writes)


def test_a_complete_read_only_store_can_be_resumed_and_loaded(reference, tmp_path, monkeypatch):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    _read_only(monkeypatch, path)
    assert_same_store(reference, run_quiet(TINY, path, workers=1))


def test_an_unfinished_read_only_store_names_the_write_it_cannot_do(reference, tmp_path,
                                                                    monkeypatch):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    tid = TINY.tasks()[0].id
    _edit_manifest(path, lambda m: m["tasks"].pop(tid))
    _read_only(monkeypatch, path)
    with pytest.raises(PermissionError, match="is read-only; cannot"):
        run_quiet(TINY, path, workers=1)
    assert len(load_store(path).missing_tasks) == 1


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root ignores file modes")
def test_a_complete_store_in_a_read_only_folder_loads(reference, tmp_path):
    path = tmp_path / "s"
    shutil.copytree(reference.path, path)
    (path / ".lock").unlink()
    folders = [path, path / "results", path / "collisions"]
    for folder in folders:
        folder.chmod(0o555)
    try:
        assert_same_store(reference, run_quiet(TINY, path, workers=1))
    finally:
        for folder in folders:
            folder.chmod(0o755)


@pytest.mark.skipif(os.name != "posix", reason="POSIX modes")
@pytest.mark.parametrize(("umask", "mode"), [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_store_files_get_the_permissions_of_the_umask(tmp_path, umask, mode):
    old = os.umask(umask)
    try:
        store = run_quiet(dataclasses.replace(TINY, n_ics=2, radii=[0.02]), tmp_path / "s",
                          workers=1)
    finally:
        os.umask(old)
    files = [p for p in store.path.rglob("*") if p.is_file() and p.name != ".lock"]
    assert files and {oct(p.stat().st_mode & 0o777) for p in files} == {oct(mode)}


# --------------------------------------------------------------------------------- CLI


def test_progress_bar_is_off_in_ci_and_can_be_forced(monkeypatch):
    from kicktimes.experiment.runner import _progress_enabled

    monkeypatch.setenv("CI", "true")
    assert _progress_enabled(None) is False
    assert _progress_enabled(True) is True and _progress_enabled(False) is False


def test_cli_run_writes_a_store_and_refuses_another_experiment(reference, tmp_path):
    from click.testing import CliRunner

    from kicktimes.cli import main

    toml = tmp_path / "tiny.toml"
    TINY.write_toml(toml)
    out = tmp_path / "store"
    result = CliRunner().invoke(main, ["run", str(toml), "--out", str(out), "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert "4/4 tasks finished" in result.output
    assert_same_store(reference, load_store(out))
    dataclasses.replace(TINY, seed=99).write_toml(toml)
    result = CliRunner().invoke(main, ["run", str(toml), "--out", str(out)])
    assert result.exit_code != 0
    assert "refusing to mix" in result.output and TINY.hash() in result.output


@pytest.mark.slow
def test_reproduce_quick_runs_both_quick_families_and_builds_the_report(tmp_path):
    from click.testing import CliRunner

    from kicktimes.cli import main

    result = CliRunner().invoke(main, ["reproduce", "--scale", "quick", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    for name in ("quick_a", "quick_b"):
        assert load_store(tmp_path / f"store-{name}").experiment == PRESETS[name]
    assert (tmp_path / "report" / "report.html").is_file()
    # the findings tables: every comparison under its controls, robust flags consistent
    from kicktimes.report.controls import COLUMNS

    for name in ("quick_a", "quick_b"):
        table = pd.read_csv(tmp_path / "report" / f"{name}_findings.csv")
        assert tuple(table.columns) == COLUMNS
        assert set(table["family"]) == {name}
        assert {"ftle", "rr_offdiag@0.001", "rr_offdiag@0.01", "det@0.01", "one_minus_r1",
                "counts"} <= set(table["diagnostic"])
        comparisons = table[table["diagnostic"] != "counts"]
        for _, part in comparisons.groupby(["diagnostic", "system"]):
            controls = set(part["control"])
            assert {"primary", "paired_median", "sticky_excluded"} <= controls
            assert part["robust"].nunique() == 1
            assert bool(part["robust"].iloc[0]) == (part["verdict"].nunique() == 1)
        recurrence = comparisons[comparisons["diagnostic"].str.startswith(("rr_", "det"))]
        assert (recurrence.groupby(["diagnostic", "system"])["control"]
                .apply(lambda c: "paper_sampling" in set(c)
                       and "uniform_sampling" not in set(c)).all())


def test_the_uniform_control_rows_are_those_of_a_uniform_rr_sampling_run():
    from kicktimes.experiment import run_task

    both = dataclasses.replace(TINY, n_ics=2, block_size=2, n_steps=300,
                               rr_sampling="run+uniform", eps=(1e-3, 1e-2))
    run = dataclasses.replace(both, rr_sampling="run")
    uniform = dataclasses.replace(both, rr_sampling="uniform")
    task = both.tasks()[0]
    res_both, _ = run_task(both, task)
    res_run, _ = run_task(run, task)
    res_uniform, _ = run_task(uniform, task)
    prefixed = res_both["diagnostic"].str.startswith("uniform_")
    pd.testing.assert_frame_equal(res_both[~prefixed].reset_index(drop=True), res_run)
    mine = res_both[prefixed].assign(
        diagnostic=res_both.loc[prefixed, "diagnostic"].str.removeprefix("uniform_"))
    theirs = res_uniform[res_uniform["diagnostic"].isin(set(mine["diagnostic"]))]
    assert len(mine) == len(theirs) > 0
    pd.testing.assert_frame_equal(mine.reset_index(drop=True), theirs.reset_index(drop=True))


def test_a_name_with_a_trailing_newline_is_refused():
    with pytest.raises(ValueError, match="name"):
        dataclasses.replace(TINY, name="abc\n")


def test_the_store_seams_read_the_manifest_and_the_pending_tasks(reference, tmp_path):
    from kicktimes.experiment import pending_tasks, read_manifest

    manifest = read_manifest(reference.path)
    assert manifest["experiment_hash"] == TINY.hash() and len(manifest["tasks"]) == len(
        TINY.tasks())
    assert pending_tasks(TINY, reference.path) == []
    assert pending_tasks(TINY, tmp_path / "nothing") == TINY.tasks()
    other = dataclasses.replace(TINY, seed=99)
    assert pending_tasks(other, reference.path) == other.tasks()
    with pytest.raises(ValueError, match="is not a kicktimes store"):
        read_manifest(tmp_path)
    few = load_store(reference.path, result_columns=["radius", "ic", "system", "value"],
                     categories=("system",))
    assert list(few.results.columns) == ["radius", "ic", "system", "value"]
    assert few.results["system"].dtype == "category"
