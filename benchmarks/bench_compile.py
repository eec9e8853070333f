"""Compile time of kicktimes' numba kernels, per workload step and per kernel.

Runs the workload twice in fresh subprocesses sharing one empty numba cache directory
(``NUMBA_CACHE_DIR`` pointing at a new temporary folder): the first run compiles every
kernel it calls (what a first run after installing costs), the second loads them from the
cache. Per step, the first-call time of each run; per kernel, the compile time numba
records (``numba:compile`` events; a kernel compiled inside another one's compilation is
counted in both, so the per-kernel column is inclusive), with the number of compiled
signatures (more than one means the callers pass inconsistent dtypes).

Reference measured in the same run: the same steps with a warm cache (the second
subprocess), i.e. the part of the cold time that is not compilation.

With ``--reproduce``, also the wall time of ``kicktimes reproduce --scale quick`` with a
cold cache (a fresh ``NUMBA_CACHE_DIR``) and then a warm one (fresh output folders both
times). ``--source DIR`` measures the kicktimes source tree in DIR instead (its path goes
first on ``PYTHONPATH`` of every subprocess), e.g. an export of another branch, so that two
versions are compared in the same session: ``git archive main | tar -x -C /tmp/main``.

Usage::

    python benchmarks/bench_compile.py            # prints the tables
    python benchmarks/bench_compile.py --json compile.json
    python benchmarks/bench_compile.py --reproduce --source /tmp/main
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import subprocess
import sys
import tempfile
import time


def _steps():
    """(name, callable) of the workload: what `kicktimes reproduce` compiles."""
    import numpy as np

    def sweep_task():
        from kicktimes.experiment import execute_task, preset

        exp = dataclasses.replace(preset("quick_a"), n_ics=1, n_steps=200, block_size=1)
        execute_task(exp, exp.tasks()[0])

    def report_kernels():
        # what the report calls beyond the sweep's kernels: the trajectory figures'
        # re-simulation with a collision log, the RQA of the recurrence plot, the
        # power-law fit of the renewal comparison, the Poisson tests (exact KS law,
        # Ljung-Box Q)
        from kicktimes import initial_conditions, simulate_two_particle
        from kicktimes.diagnostics import rqa
        from kicktimes.stats import compare_models, test_poisson

        ic = initial_conditions(1, 0.02, rng=0)[0]
        run = simulate_two_particle(ic, 0.02, n_steps=200, tau=0.3, log_collisions=True)
        rqa(np.column_stack([run.boundary_log.x, run.boundary_log.sin_theta])[:300], eps=0.05)
        rng = np.random.default_rng(0)
        compare_models(rng.exponential(size=200), censored=rng.exponential(size=3))
        test_poisson(np.sort(rng.uniform(0.0, 60.0, 60)), 60.0, n_mc=99, rng=rng)

    def disks(**observers):
        # the N-disk engine's two compiled loops: no observers, and all of them
        from kicktimes import initial_state, simulate_disks

        state = initial_state(20, 0.05, rng=0)
        return lambda: simulate_disks(state, 0.05, t_max=1.0, **observers)

    return [
        ("import kicktimes (no compilation expected)", lambda: None),
        ("sweep task (3 systems x 3 diagnostics)", sweep_task),
        ("report kernels", report_kernels),
        ("N-disk engine, no observers", disks()),
        ("N-disk engine, all observers", disks(holes=[(0.0, 0.1)], tau=0.5, log_walls=True)),
    ]


def child():
    """One measured run in this (fresh) process; prints JSON."""
    from numba.core import event

    t0 = time.perf_counter()
    import kicktimes.diagnostics  # noqa: F401
    import kicktimes.experiment  # noqa: F401

    steps = {"import": time.perf_counter() - t0}
    with event.install_recorder("numba:compile") as rec:
        for name, fn in _steps()[1:]:
            t0 = time.perf_counter()
            fn()
            steps[name] = time.perf_counter() - t0
    starts, kernels = {}, {}
    for ts, ev in rec.buffer:
        disp = ev.data["dispatcher"]
        name = f"{disp.py_func.__module__}.{disp.py_func.__qualname__}"
        key = (name, str(ev.data["args"]))
        if ev.is_start:
            starts[key] = ts
        elif key in starts:
            k = kernels.setdefault(name, {"seconds": 0.0, "signatures": []})
            k["seconds"] += ts - starts.pop(key)
            k["signatures"].append(str(ev.data["args"]))
    print(json.dumps({"steps": steps, "kernels": kernels}))


def _env(cache_dir, source):
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    if source:
        env["PYTHONPATH"] = os.pathsep.join(p for p in (source, env.get("PYTHONPATH")) if p)
    return env


def run_child(cache_dir, source=None):
    env = _env(cache_dir, source)
    t0 = time.perf_counter()
    out = subprocess.run(
        [sys.executable, __file__, "--child"],
        env=env,
        capture_output=True,
        text=True,
    )
    if out.returncode:
        raise SystemExit(f"the measured subprocess failed:\n{out.stderr[-3000:]}")
    result = json.loads(out.stdout.strip().splitlines()[-1])
    result["process_wall"] = time.perf_counter() - t0
    return result


def time_reproduce(cache_dir, source=None):
    """Wall seconds of ``kicktimes reproduce --scale quick`` into a fresh folder."""
    with tempfile.TemporaryDirectory(prefix="kicktimes-reproduce-") as out:
        t0 = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, "-m", "kicktimes", "reproduce", "--scale", "quick", "--out", out,
             "--no-progress"],
            env=_env(cache_dir, source), capture_output=True, text=True,
        )
        seconds = time.perf_counter() - t0
    if proc.returncode:
        raise SystemExit(f"kicktimes reproduce failed:\n{proc.stderr[-3000:]}")
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--json", default=None, help="also write the numbers here")
    parser.add_argument("--reproduce", action="store_true",
                        help="also time `kicktimes reproduce --scale quick`, cold and warm")
    parser.add_argument("--source", default=None,
                        help="measure the kicktimes source tree in this folder")
    args = parser.parse_args()
    if args.child:
        child()
        return
    source = os.path.abspath(args.source) if args.source else None
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}"
          + (f"; source {source}" if source else ""))
    reproduce = {}
    if args.reproduce:
        with tempfile.TemporaryDirectory(prefix="numba-cache-") as cache:
            reproduce["cold"] = time_reproduce(cache, source)
            reproduce["warm"] = time_reproduce(cache, source)
        print(f"kicktimes reproduce --scale quick: cold cache {reproduce['cold']:.1f} s, "
              f"warm cache {reproduce['warm']:.1f} s")
    with tempfile.TemporaryDirectory(prefix="numba-cache-") as cache:
        cold = run_child(cache, source)
        warm = run_child(cache, source)
    print(f"\n{'step':48s} {'cold s':>8s} {'warm s':>8s} {'compile s':>10s}")
    for name, sec in cold["steps"].items():
        w = warm["steps"].get(name, float("nan"))
        print(f"{name:48s} {sec:8.2f} {w:8.2f} {sec - w:10.2f}")
    total_c, total_w = sum(cold["steps"].values()), sum(warm["steps"].values())
    print(
        f"{'total (whole process)':48s} {cold['process_wall']:8.2f} {warm['process_wall']:8.2f}"
        f" {cold['process_wall'] - warm['process_wall']:10.2f}"
    )
    print(f"steps only: cold {total_c:.2f} s = {total_c / total_w:.1f}x the warm run")
    kernels = sorted(cold["kernels"].items(), key=lambda kv: -kv[1]["seconds"])
    print(f"\n{'kernel (compile time, inclusive of kernels it calls)':72s} {'s':>6s} {'sigs':>4s}")
    for name, k in kernels:
        print(f"{name:72s} {k['seconds']:6.2f} {len(k['signatures']):4d}")
    several = [(n, k["signatures"]) for n, k in kernels if len(k["signatures"]) > 1]
    if several:
        print("\nkernels compiled for more than one signature (inconsistent argument dtypes):")
        for n, sigs in several:
            print(f"  {n}: " + " | ".join(sigs))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"cold": cold, "warm": warm, "reproduce": reproduce}, fh, indent=1)


if __name__ == "__main__":
    main()
