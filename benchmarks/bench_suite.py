"""Wall time of the README's test command, and where it goes: compiling against running.

Runs ``python -m pytest -n auto`` (the README's command; ``--workers`` to change ``-n``)
twice, sharing one new, empty numba cache folder (``NUMBA_CACHE_DIR``):

1. **cold**: what a fresh clone costs, every kernel compiled on first use;
2. **warm**: the same suite loading every kernel from the cache, which is the
   reference measured in the same run: cold minus warm is the compile time.

The cold run records every numba compilation in the pytest processes
(``benchmarks/_compile_log_plugin.py``): per kernel, and per kernel and signature, its
exclusive seconds, how many processes compiled the same signature (a signature compiled
by both workers costs twice) and the tests that compiled it. Compilations inside
subprocesses (the notebooks' kernels, the command-line tests) are in the cold-warm
difference only.

Usage::

    python benchmarks/bench_suite.py                  # cold and warm, tables
    python benchmarks/bench_suite.py --only cold --json suite.json
    python benchmarks/bench_suite.py -- -k stats      # extra pytest arguments after --
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run_suite(cache, log, workers, extra):
    """Wall seconds, pass/fail line and the per-test durations of one suite run."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), KICKTIMES_COMPILE_LOG=str(log),
               PYTHONPATH=os.pathsep.join([str(ROOT / "benchmarks"),
                                           os.environ.get("PYTHONPATH", "")]))
    cmd = [sys.executable, "-m", "pytest", "-n", workers, "-q", "-p", "no:cacheprovider",
           "-p", "_compile_log_plugin", "--durations=25", *extra]
    start = time.perf_counter()
    out = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    lines = out.stdout.splitlines()
    summary = next((ln for ln in reversed(lines) if re.search(r"\d+ (passed|failed)", ln)), "")
    if out.returncode != 0:
        print(out.stdout[-3000:], out.stderr[-3000:], sep="\n")
    slowest = [ln for ln in lines if re.match(r"^\d+\.\d+s (call|setup|teardown)", ln)]
    return {"wall_s": wall, "summary": summary.strip("= "), "returncode": out.returncode,
            "slowest": slowest}


def compile_table(log):
    """Per kernel: signatures, processes that compiled each, exclusive seconds summed."""
    rows = []
    for path in sorted(Path(log).glob("*.json")):
        for kernel, sig, exclusive, *_ in json.loads(path.read_text()):
            rows.append((path.stem, kernel, sig, exclusive))
    per = collections.defaultdict(lambda: {"seconds": 0.0, "sigs": set(), "compiles": 0})
    for _, kernel, sig, exclusive in rows:
        per[kernel]["seconds"] += exclusive
        per[kernel]["sigs"].add(sig)
        per[kernel]["compiles"] += 1
    table = sorted(({"kernel": k, "seconds": v["seconds"], "signatures": len(v["sigs"]),
                     "compilations": v["compiles"]} for k, v in per.items()),
                   key=lambda r: -r["seconds"])
    twice = sum(r["compilations"] - r["signatures"] for r in table)
    return table, sum(r["seconds"] for r in table), twice


def compile_by_signature(log):
    """Per kernel and signature: the compile seconds (exclusive, summed over processes),
    how many processes compiled it (more than one: a duplicate) and the tests that did."""
    per = collections.defaultdict(lambda: [0.0, 0, set()])
    for path in sorted(Path(log).glob("*.json")):
        for kernel, sig, exclusive, _, test in json.loads(path.read_text()):
            row = per[kernel, sig]
            row[0] += exclusive
            row[1] += 1
            row[2].add(test)
    return sorted(((k, s, sec, n, sorted(tests)) for (k, s), (sec, n, tests) in per.items()),
                  key=lambda r: -r[2])


def compile_by_test(log):
    """Per test: the compile seconds it caused (exclusive, summed) and the kernels."""
    per = collections.defaultdict(lambda: [0.0, set()])
    for path in sorted(Path(log).glob("*.json")):
        for kernel, _, exclusive, _, test in json.loads(path.read_text()):
            per[test][0] += exclusive
            per[test][1].add(kernel.rsplit(".", 2)[-2] + "." + kernel.rsplit(".", 1)[-1])
    return sorted(((t, s, sorted(k)) for t, (s, k) in per.items()), key=lambda r: -r[1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", default="auto", help="pytest-xdist -n (auto)")
    parser.add_argument("--only", choices=["cold", "warm", "both"], default="both")
    parser.add_argument("--json", help="write the measurements here")
    parser.add_argument("--keep-log", help="copy the cold run's compile log to this folder")
    parser.add_argument("extra", nargs="*", help="pytest arguments (after --)")
    args = parser.parse_args(argv)
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp, "numba-cache")
        runs = ["cold", "warm"] if args.only == "both" else [args.only]
        if args.only == "warm":  # fill the cache first, untimed
            run_suite(cache, Path(tmp), args.workers, args.extra)
        for name in runs:
            log = Path(tmp, f"log-{name}")
            log.mkdir()
            res = run_suite(cache, log, args.workers, args.extra)
            res["kernels"], res["compile_s"], res["duplicate_compilations"] = compile_table(log)
            res["by_test"] = compile_by_test(log)
            res["by_signature"] = compile_by_signature(log)
            if name == "cold" and args.keep_log:
                import shutil

                shutil.copytree(log, args.keep_log, dirs_exist_ok=True)
            results[name] = res
            print(f"{name}: {res['wall_s']:.0f} s wall ({res['summary']}); numba compiled "
                  f"{res['compile_s']:.0f} s in the pytest processes (exclusive, summed over "
                  f"processes), {res['duplicate_compilations']} signatures more than once")
    if "cold" in results:
        print("\nslowest tests, cold:")
        print("\n".join(results["cold"]["slowest"][:15]))
        print("\nkernel | compile s (summed) | signatures | compilations")
        for row in results["cold"]["kernels"][:25]:
            print(f"{row['kernel']} | {row['seconds']:.1f} | {row['signatures']} | "
                  f"{row['compilations']}")
        print("\nkernel | signature | compile s (summed) | compilations | tests")
        for kernel, sig, seconds, n, tests in results["cold"]["by_signature"][:25]:
            who = tests[0] + (f" and {len(tests) - 1} more" if len(tests) > 1 else "")
            print(f"{kernel} | {sig[:60]} | {seconds:.1f} | {n} | {who}")
        print("\ntests that compiled the most (exclusive s, kernels):")
        for test, seconds, kernels in results["cold"]["by_test"][:20]:
            print(f"{seconds:6.1f}  {test}  {', '.join(kernels[:6])}")
    if len(results) == 2:
        cold, warm = results["cold"]["wall_s"], results["warm"]["wall_s"]
        print(f"\ncold {cold:.0f} s = warm {warm:.0f} s + {cold - warm:.0f} s of compiling "
              f"(cold/warm {cold / warm:.2f})")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1, default=list))
    return 0 if all(r["returncode"] == 0 for r in results.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
