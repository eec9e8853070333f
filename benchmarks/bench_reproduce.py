"""Wall time of the real command, ``kicktimes reproduce``, end to end.

Each variant runs as its own process (``python -m kicktimes reproduce ...``) into a fresh
``--out``, so the time includes everything a user waits for: start-up, the numba cache
load, both sweeps, the report. The variants are alternated round by round, so they share
the machine's drift (up to 25 % within a session):

* one per ``--content`` of this tree (``paper``: the paper's own systems and diagnostics;
  ``full``: the presets);
* with ``--source DIR``, the same command from another source tree (an export of an older
  commit: ``git archive <commit> | tar -x -C DIR``), run with its own defaults (trees
  before ``--content`` existed run their presets). Its numba cache is warmed first by a
  quick run, as this tree's is.

Run it on an idle machine. Usage::

    python benchmarks/bench_reproduce.py                          # paper scale, both contents
    python benchmarks/bench_reproduce.py --contents paper --source /tmp/v01 --rounds 2
    python benchmarks/bench_reproduce.py --scale quick --rounds 6
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def run(cmd: list[str], out: Path, env: dict, log: Path) -> float:
    """Wall time of ``cmd --out out`` into a fresh ``out``; exits if it fails."""
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    with open(log, "w") as fh:
        proc = subprocess.run(
            cmd + ["--out", str(out)], stdout=fh, stderr=subprocess.STDOUT, env=env, check=False
        )
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed (exit {proc.returncode}); see {log}")
    return wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", choices=("quick", "paper"), default="paper")
    parser.add_argument("--contents", default="paper,full", help="comma-separated")
    parser.add_argument("--source", type=Path, default=None, help="a reference source tree")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", type=Path, default=None, help="keep outputs and logs here")
    args = parser.parse_args()
    contents = [c for c in args.contents.split(",") if c]
    if not set(contents) <= {"paper", "full"}:
        parser.error(f"--contents: choose among paper, full; got {args.contents!r}")
    if args.rounds < 1:
        parser.error("--rounds must be >= 1")

    root = (args.out or Path(tempfile.mkdtemp(prefix="bench-reproduce-"))).resolve()
    source = args.source.resolve() if args.source is not None else None
    root.mkdir(parents=True, exist_ok=True)
    base = [sys.executable, "-m", "kicktimes", "reproduce", "--scale", args.scale]
    if args.workers:
        base += ["--workers", str(args.workers)]
    # `python -m` puts the working directory first on sys.path: run from elsewhere, so
    # that a reference tree on PYTHONPATH is not shadowed by a checkout here
    os.chdir(tempfile.gettempdir())
    here = dict(os.environ)
    variants = {f"--content {c}": (base + ["--content", c], here) for c in contents}
    if source is not None:
        there = dict(os.environ, PYTHONPATH=str(source))
        variants[f"{source} (its defaults)"] = (base, there)
        # its compiled kernels live in its own tree: compile them before timing
        print(f"warming {source}'s numba cache (a quick run) ...", flush=True)
        run(
            [sys.executable, "-m", "kicktimes", "reproduce", "--scale", "quick"],
            root / "warm", there, root / "warm.log",
        )

    load0 = os.getloadavg()[0]
    print(f"kicktimes reproduce --scale {args.scale}: {len(variants)} variants x "
          f"{args.rounds} rounds, alternated; {os.cpu_count()} cores, load {load0:.2f}")
    walls: dict[str, list[float]] = {name: [] for name in variants}
    for k in range(args.rounds):
        for j, (name, (cmd, env)) in enumerate(variants.items()):
            slug = f"r{k}-v{j}"
            wall = run(cmd, root / slug, env, root / f"{slug}.log")
            walls[name].append(wall)
            print(f"round {k + 1}: {name:40s} {wall:7.1f} s", flush=True)

    print("\nvariant                                   runs (s)                 mean (s)")
    first = None
    for name, w in walls.items():
        mean = statistics.fmean(w)
        first = first or mean
        runs = ", ".join(f"{x:.1f}" for x in w)
        print(f"{name:40s}  {runs:24s} {mean:7.1f}   {mean / first:.2f}x the first")
    if not args.out:
        shutil.rmtree(root, ignore_errors=True)
    print(f"load average at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
