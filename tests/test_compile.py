"""Specification of the first-run compilation notice (kicktimes.compilation)."""

from __future__ import annotations

import io

import pytest

from kicktimes import compilation as _compile


def test_a_cold_cache_is_announced_once_with_an_estimate(monkeypatch):
    monkeypatch.setattr(_compile, "_is_cold", lambda dispatcher: True)
    stream = io.StringIO()
    seconds = _compile.announce(stream=stream)
    expected = sum(s for *_, s in _compile.SWEEP_KERNELS)
    assert abs(seconds - expected) <= 2.5 and seconds % 5 == 0
    assert stream.getvalue() == (
        f"compiling kicktimes' numba kernels (once, about {int(seconds)} s)...\n"
    )


def test_a_warm_cache_is_not_announced(monkeypatch):
    monkeypatch.setattr(_compile, "_is_cold", lambda dispatcher: False)
    stream = io.StringIO()
    assert _compile.announce(stream=stream) == 0.0
    assert stream.getvalue() == ""


def test_unknown_cache_state_says_nothing(monkeypatch):
    # numba's private cache API may change: then nothing is printed, nothing fails
    monkeypatch.setattr(_compile, "_is_cold", lambda dispatcher: None)
    assert _compile.cold_kernels() == []


def test_the_cache_probe_reads_numbas_index_of_a_real_kernel():
    from kicktimes.billiard.kernels.drive_two import simulate_two_kernel

    assert _compile._is_cold(simulate_two_kernel) in (True, False)


_SETUP = """
from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.diagnostics import lyapunov

ic = initial_conditions(1, 0.02, rng=0)[0]
"""
_CALLS = """
for rule in ("mirror", "elastic"):
    for sampling in ("uniform", "paper"):
        simulate_two_particle(ic, 0.02, rule=rule, sampling=sampling, n_steps=20, tau=0.3)
simulate_two_particle(ic, 0.02, t_max=5.0, log_collisions=True)
for law in ("uniform", "gaussian", "scatter"):
    run = simulate_one_particle(ic[0], 0.02, n_steps=20, tau=0.3, kick_angle=law,
                                kicks=schedules.Poisson(0.5), rng=0)
    lyapunov(run)
    lyapunov(run, method="twin")
lyapunov(ic, 0.02, n_steps=20, tau=0.3)
lyapunov(ic, 0.02, n_steps=20, tau=0.3, method="twin")
"""


@pytest.mark.slow
def test_simulator_and_ftle_kernels_compile_once_without_error_strings(tmp_path):
    # A cold cache compiles everything the simulators and the FTLE call (~30 s). Each
    # kernel must compile one signature (literal int/bool arguments would add more), and
    # none may pull in numba's string formatting (error messages of slice assignments
    # or of raise with formatted text cost seconds of compilation).
    from _compile_record import kicktimes_compiles

    # (one signature per set of observers for the drivers: the simulation alone, with
    # tangent vectors, tangent vectors alone; the twins once per system; the buffer
    # growth is generic over the dtype: the int8 particle column and the floats)
    ours = kicktimes_compiles(_SETUP, _CALLS, tmp_path)
    assert "kicktimes.billiard.kernels.drive_two.simulate_two_kernel" in ours
    assert len(ours["kicktimes.billiard.kernels.observe.grow_to"]) <= 2


_SWEEP_AFTER_WARM_UP = r"""
import dataclasses, json
from numba.core import event
from kicktimes import compilation as _compile
from kicktimes.experiment import execute_task, preset

_compile._warm_two(None)
_compile._warm_one(None)
with event.install_recorder("numba:compile") as rec:
    for name in ("quick_a", "quick_b"):
        exp = dataclasses.replace(preset(name), n_ics=1, n_steps=60, block_size=1)
        execute_task(exp, exp.tasks()[0])
print(json.dumps([sorted({e.data["dispatcher"].py_func.__module__ for _, e in rec.buffer}),
                  _compile.cold_kernels()]))
"""


@pytest.mark.slow
def test_the_warm_up_groups_compile_every_kernel_a_sweep_task_calls(tmp_path):
    # the two warm-up groups run in parallel before a sweep; whatever they miss, every
    # worker of the sweep would compile again
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", _SWEEP_AFTER_WARM_UP], env=env, check=True,
                         capture_output=True, text=True)
    modules, still_cold = json.loads(out.stdout.strip().splitlines()[-1])
    assert [m for m in modules if m.startswith("kicktimes")] == []
    # and the cache probe agrees: nothing is announced as cold on the next run
    assert still_cold == []


_REPORT_AFTER_WARM_UP = r"""
import dataclasses, json, sys
from numba.core import event
from kicktimes import compilation as _compile
from kicktimes.experiment import preset, run_experiment
from kicktimes.report import build_report

# what `kicktimes reproduce` runs: the sweep's two groups, and the report process's warm-up
_compile._warm_group_two(False)
_compile._warm_group_one(False)
_compile.warm_report()
exp = dataclasses.replace(preset("quick_b"), n_ics=4, n_steps=300, block_size=2,
                          radii=[0.01, 0.02])
run_experiment(exp, sys.argv[1] + "/store", workers=1)
with event.install_recorder("numba:compile") as rec:
    build_report(sys.argv[1] + "/store", sys.argv[1] + "/report", workers=1)
print(json.dumps([sorted({e.data["dispatcher"].py_func.__module__ for _, e in rec.buffer}),
                  _compile.cold_kernels(_compile.SWEEP_KERNELS + _compile.REPORT_KERNELS)]))
"""


@pytest.mark.slow
def test_the_reproduce_warm_up_also_compiles_every_kernel_the_report_calls(tmp_path):
    # `kicktimes reproduce`'s report process warms the report's kernels while the sweep's
    # compile; whatever they miss, the report's workers compile on the first run
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    out = subprocess.run([sys.executable, "-c", _REPORT_AFTER_WARM_UP, str(tmp_path)], env=env,
                         check=True, capture_output=True, text=True)
    modules, still_cold = json.loads(out.stdout.strip().splitlines()[-1])
    assert [m for m in modules if m.startswith("kicktimes")] == []
    assert still_cold == []


_LOADED_AFTER_WARM_SWEEP = r"""
import importlib, json
from kicktimes import compilation as _compile

def loaded():
    return {name: bool(getattr(importlib.import_module(module), name).overloads)
            for module, name, _ in _compile.SWEEP_KERNELS}

before = loaded()
_compile.warm_sweep()
print(json.dumps([before, loaded()]))
"""


def test_warm_sweep_loads_every_kernel_of_the_sweep_into_this_process():
    # what the command line runs before it forks the pool: the workers inherit the loaded
    # kernels (on a cold cache this compiles them, about 15 s)
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", _LOADED_AFTER_WARM_SWEEP], check=True,
                         capture_output=True, text=True).stdout
    before, after = json.loads(out)
    assert not any(before.values())
    assert all(after.values()), after
