"""What the command line does around its process pools, each against the alternative.

1. **Sweep kernels loaded before the fork.** The quick sweeps (``quick_a`` then
   ``quick_b``) on one local pool of 2 workers, with the sweep's kernels loaded in the
   parent before the pool forks (`kicktimes.compilation.warm_sweep`, what ``kicktimes run``
   and ``reproduce`` do) against without it (each worker loads them on its first task).
   Each variant runs in a fresh subprocess, alternating, ``--rounds`` times: wall time,
   CPU seconds (the subprocess and its children) and the tasks' own seconds summed over
   the workers (the stores' timings).
2. **Garbage collection during the report.** ``build_report`` of the quick stores
   (``workers=2``, ``force=True``) under `kicktimes.memory.fewer_collections` against
   CPython's default thresholds (700, 10, 10), each in a fresh subprocess, alternating:
   seconds spent in the collector in every process (``gc.callbacks``), wall time, CPU
   seconds and the largest resident set of any process; the CSV tables and PNG files of
   the two builds are compared byte for byte. ``--stores`` builds those stores instead
   (sections 2 and 3), e.g. the paper's.
3. **One BLAS thread.** The same build (under `fewer_collections`) with BLAS limited to
   one thread (`kicktimes.report.pipeline._one_blas_thread`, threadpoolctl) against
   OpenBLAS's default (a thread per core in every process), alternating: wall time and
   CPU seconds; the files are compared byte for byte (on the paper's stores the pooled
   renewal fits' log-likelihoods differ in their last bits: the thread count splits their
   sums).

Wall times depend on what else runs on the machine; the CPU and collector seconds are the
figures to compare on a busy one.

Usage::

    python benchmarks/bench_startup.py [--rounds 3]
    python benchmarks/bench_startup.py --rounds 1 --stores STORE_A STORE_B  # e.g. the paper's
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

_SWEEP_CHILD = """
import json, os, resource, sys, time
from kicktimes.memory import keep_freed_memory
from kicktimes.experiment import preset, run_experiment
from kicktimes.experiment.runner import local_pool
keep_freed_memory()
root, preload = sys.argv[1], sys.argv[2] == "1"
t0 = time.perf_counter()
if preload:
    from kicktimes import compilation as _compile
    _compile.warm_sweep()
work = 0.0
with local_pool(2) as pool:
    for name in ("quick_a", "quick_b"):
        store = run_experiment(preset(name), os.path.join(root, name), executor=pool,
                               progress=False)
        work += float(store.timings["total"].sum())
wall = time.perf_counter() - t0
use = [resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
print(json.dumps({"wall": wall, "cpu": sum(u.ru_utime + u.ru_stime for u in use),
                  "work": work}))
"""

_REPORT_CHILD = """
import gc, json, os, resource, sys, time
relaxed = sys.argv[3] == "1"
log = sys.argv[4]
one_blas_thread = sys.argv[5] == "1"
state = {}
def timed(phase, info):
    if phase == "start":
        state["t"] = time.thread_time()
    else:
        with open(log, "a") as fh:
            fh.write(f"{time.thread_time() - state['t']:.6f}\\n")
gc.callbacks.append(timed)
from kicktimes import _memory
from kicktimes.report import build_report
if not relaxed:
    _memory._GC_THRESHOLDS = gc.get_threshold()  # the context keeps CPython's defaults
if not one_blas_thread:
    import contextlib
    from kicktimes.report import pipeline
    pipeline._one_blas_thread = contextlib.nullcontext  # OpenBLAS's default threads
t0 = time.perf_counter()
build_report(sys.argv[1].split(","), sys.argv[2], workers=2, force=True, progress=False)
wall = time.perf_counter() - t0
use = [resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
print(json.dumps({"wall": wall, "cpu": sum(u.ru_utime + u.ru_stime for u in use),
                  "rss_mb": max(u.ru_maxrss for u in use) / 1024}))
"""


def _child(code, *args):
    out = subprocess.run([sys.executable, "-c", code, *map(str, args)], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def _mean(rows, key):
    return sum(r[key] for r in rows) / len(rows)


def _alternate(rounds, run):
    """``{False: [...], True: [...]}`` of ``run(k, flag)``, the reference (False) first in
    each of ``rounds`` rounds."""
    runs = {False: [], True: []}
    for k in range(rounds):
        for flag in (False, True):
            runs[flag].append(run(k, flag))
    return runs


def _report(title, runs, labels, columns, means):
    """Print the section: one row per run (``columns``: key, header, width, format) and the
    means of ``means`` (keys) as reference -> new, with their ratio."""
    print(title)
    print(f"   {'':34}" + "".join(f"{head:>{width}}" for _, head, width, _ in columns))
    for flag, label in zip((False, True), labels, strict=True):
        for r in runs[flag]:
            print(f"   {label:34}"
                  + "".join(f"{r[key]:>{width}{fmt}}" for key, _, width, fmt in columns))
    ref, new = runs[False], runs[True]
    print("   means: " + ", ".join(
        f"{key} {_mean(ref, key):.2f} -> {_mean(new, key):.2f} "
        f"({_mean(ref, key) / _mean(new, key):.2f}x)" for key in means))


_TIMES = [("wall", "wall (s)", 10, ".2f"), ("cpu", "CPU (s)", 10, ".2f")]


def bench_preload(root: Path, rounds: int):
    runs = _alternate(rounds, lambda k, preload: _child(
        _SWEEP_CHILD, root / f"sweep-{k}-{int(preload)}", int(preload)))
    _report(f"1. quick sweeps (quick_a + quick_b) on a pool of 2 workers, {rounds} alternating "
            f"rounds, load average {os.getloadavg()[0]:.1f}", runs,
            ("each worker loads (reference)", "loaded before the fork"),
            [*_TIMES, ("work", "task s", 10, ".2f")], ("wall", "cpu", "work"))
    return [root / f"sweep-0-1/{n}" for n in ("quick_a", "quick_b")]


def _files(folder: Path):
    return {f.name: f.read_bytes() for f in sorted(folder.iterdir())
            if f.suffix in (".csv", ".png") and "timings" not in f.name}


def _build(stores, out: Path, relaxed: bool, one_blas_thread: bool, log=None):
    """One `_REPORT_CHILD` build; with ``log``, the collector's passes and seconds too."""
    if log is not None:
        log.write_text("")
    r = _child(_REPORT_CHILD, ",".join(map(str, stores)), out, int(relaxed),
               log if log is not None else os.devnull, int(one_blas_thread))
    if log is not None:
        times = [float(x) for x in log.read_text().split()]
        r.update(gc=sum(times), n_gc=len(times))
    r["files"] = _files(out)
    return r


def _differing(runs):
    new, ref = runs[True][-1]["files"], runs[False][-1]["files"]
    differ = sorted(k for k in new if new[k] != ref.get(k))
    print(f"   files that differ between the two: {len(differ)} of {len(new)}"
          + (f" ({', '.join(differ)})" if differ else ""))


def bench_gc(stores, root: Path, rounds: int):
    runs = _alternate(rounds, lambda k, relaxed: _build(
        stores, root / f"report-{k}-{int(relaxed)}", relaxed, True,
        log=root / f"gc-{k}-{int(relaxed)}.txt"))
    print()
    _report(f"2. build_report of {', '.join(p.name for p in stores)} (workers=2, force=True), "
            f"{rounds} alternating rounds, load average {os.getloadavg()[0]:.1f}", runs,
            ("CPython's thresholds (reference)", "fewer_collections"),
            [("gc", "GC (s)", 8, ".2f"), ("n_gc", "passes", 8, "d"), *_TIMES,
             ("rss_mb", "RSS MB", 8, ".0f")], ("gc", "cpu", "wall"))
    _differing(runs)


def bench_blas(stores, root: Path, rounds: int):
    runs = _alternate(rounds, lambda k, single: _build(
        stores, root / f"blas-{k}-{int(single)}", True, single))
    print()
    _report(f"3. the same build, {rounds} alternating rounds, load average "
            f"{os.getloadavg()[0]:.1f}", runs,
            ("OpenBLAS's threads (reference)", "one BLAS thread"), _TIMES, ("cpu", "wall"))
    _differing(runs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds")
    parser.add_argument("--stores", nargs="+", type=Path, default=None,
                        help="stores to report in sections 2 and 3 (default: the quick ones)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        stores = bench_preload(root, args.rounds)
        if args.stores:
            stores = [p.resolve() for p in args.stores]
        bench_gc(stores, root, args.rounds)
        bench_blas(stores, root, args.rounds)


if __name__ == "__main__":
    main()
