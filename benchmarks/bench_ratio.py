"""The whole paper as a multiple of the bare simulation: ``kicktimes reproduce`` against the
C loop that replays the same trajectories, measured in the same run.

Issue 32's yardstick. Per round, for each ``--content``:

1. the **C loop** (`benchmarks/c_reference/two_disk.c`, ``cc -O2``, checked to give
   `simulate_two_particle`'s output by `bench_simulators.py`) runs every two-disk
   trajectory of the command, every (radius, IC) of every experiment the command sweeps,
   with the experiment's rule, sampling, steps and ICs, in this process, one core;
2. the **command**, ``python -m kicktimes reproduce --scale paper [--content paper]``, runs
   as its own process into a fresh ``--out`` (start-up, numba cache load, sweeps, report,
   all included), for this tree and, with ``--source DIR``, for another tree (an export of
   an older commit, ``git archive <commit> | tar -x -C DIR``), alternated round by round so
   the variants share the machine's drift.

The ratio of each command is its wall time over the C loop's time measured in the same
round. After each command the stage table is read back from what it wrote: sweep
worker-seconds by stage (the stores' manifests) and report seconds by stage
(``report/report_timings.csv``). With ``--source``, each round then checks that the two
trees' stores are bitwise equal (results and collision times) and lists the report files
whose bytes differ.

Run it on an idle machine::

    python benchmarks/bench_ratio.py                                   # both contents, 1 round
    python benchmarks/bench_ratio.py --contents paper --rounds 3
    python benchmarks/bench_ratio.py --source /tmp/before --rounds 2   # before/after, alternated
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "c_reference"))

from two_disk import load as load_c_reference  # noqa: E402

from kicktimes import initial_conditions  # noqa: E402
from kicktimes.experiment import load_store  # noqa: E402
from kicktimes.experiment.presets import preset  # noqa: E402
from kicktimes.studies.paper import scale_presets  # noqa: E402


def c_loop_seconds(c_ref, scale: str, content: str) -> tuple[float, int]:
    """Seconds of the C loop over every two-disk trajectory the command sweeps, and their
    number (arguments prepared outside the timed calls)."""
    prepared = []
    for name in scale_presets(scale, content):
        exp = preset(name, content)
        ics = initial_conditions(exp.n_ics, exp.r_max, rng=exp.seed, method=exp.ic_method,
                                 rule=exp.rule)
        for r in exp.radii:
            prepared.append(c_ref.prepare_many(ics, r, rule=exp.rule, sampling=exp.sampling,
                                               n_steps=exp.n_steps, tau=exp.tau))
    t0 = time.perf_counter()
    for args in prepared:
        c_ref.run_many(args)
    return time.perf_counter() - t0, sum(p[1] for p in prepared)


def run_command(source: Path | None, scale: str, content: str, out: Path, workers: int,
                log: Path) -> float:
    """Wall seconds of ``kicktimes reproduce`` from ``source`` (None: this environment)."""
    shutil.rmtree(out, ignore_errors=True)
    env = dict(os.environ)
    if source is not None:
        env["PYTHONPATH"] = str(source)
    cmd = [sys.executable, "-m", "kicktimes", "reproduce", "--scale", scale, "--out", str(out),
           "--workers", str(workers), "--no-progress"]
    if content != "full":
        cmd += ["--content", content]
    t0 = time.perf_counter()
    with open(log, "w") as fh:
        proc = subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, env=env,
                              cwd=source or Path.cwd())
    wall = time.perf_counter() - t0
    if proc.returncode:
        sys.exit(f"{' '.join(cmd)} failed (exit {proc.returncode}); see {log}")
    return wall


def stage_table(out: Path) -> pd.Series:
    """Sweep worker-seconds by stage (all stores) and report seconds by stage."""
    sums = {}
    for store in sorted(out.glob("store-*")):
        for stage, sec in load_store(store, verify=False).timings.sum().items():
            sums[f"sweep: {stage}"] = sums.get(f"sweep: {stage}", 0.0) + float(sec)
    for report in out.glob("report*/report_timings.csv"):
        t = pd.read_csv(report)
        for stage, sec in t.groupby("stage", observed=True)["seconds"].sum().items():
            sums[f"report: {stage}"] = sums.get(f"report: {stage}", 0.0) + float(sec)
    return pd.Series(sums, dtype=float)


def store_differences(a: Path, b: Path) -> list[str]:
    """The stores of run ``a`` that are not bitwise those of run ``b``: their results
    (every column; values compared as bytes) and collision times."""
    diffs = []
    names = sorted(p.name for p in a.glob("store-*"))
    if names != sorted(p.name for p in b.glob("store-*")):
        return [f"different stores: {names}"]
    for name in names:
        sa, sb = load_store(a / name, verify=False), load_store(b / name, verify=False)
        ra, rb = sa.results.reset_index(drop=True), sb.results.reset_index(drop=True)
        ca, cb = sa.collisions.reset_index(drop=True), sb.collisions.reset_index(drop=True)
        values_same = ra["value"].to_numpy().tobytes() == rb["value"].to_numpy().tobytes()
        same = (ra.equals(rb) and values_same
                and ca.drop(columns="pp_times").equals(cb.drop(columns="pp_times"))
                and len(ca) == len(cb)
                and all(np.asarray(x).tobytes() == np.asarray(y).tobytes()
                        for x, y in zip(ca["pp_times"], cb["pp_times"], strict=True)))
        if not same:
            diffs.append(name)
    return diffs


def report_differences(a: Path, b: Path) -> list[str]:
    """The report files (CSV, PNG) of run ``a`` whose bytes differ from run ``b``'s
    (timings left out)."""
    out = []
    for f in sorted((a / "report").rglob("*")):
        if f.suffix not in (".csv", ".png") or "timings" in f.name:
            continue
        g = b / "report" / f.relative_to(a / "report")
        if not g.exists() or f.read_bytes() != g.read_bytes():
            out.append(f.name)
    return out


def warm(source: Path | None, root: Path, workers: int) -> None:
    """A quick run per tree first: its numba cache is then warm, as a user's is."""
    run_command(source, "quick", "full", root / "warm", workers, root / "warm.log")
    shutil.rmtree(root / "warm", ignore_errors=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scale", default="paper")
    ap.add_argument("--contents", nargs="+", default=["full", "paper"],
                    choices=["full", "paper"])
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--workers", type=int, default=os.cpu_count())
    ap.add_argument("--source", type=Path, default=None,
                    help="another source tree, run alternated with this one")
    ap.add_argument("--out", type=Path, default=None, help="keep the runs' folders here")
    args = ap.parse_args(argv)

    c_ref, why = load_c_reference()
    if c_ref is None:
        sys.exit(f"the C reference cannot be built: {why}")
    root = args.out or Path(tempfile.mkdtemp(prefix="bench-ratio-"))
    root.mkdir(parents=True, exist_ok=True)
    trees = [("this tree", None)] + ([("source", args.source.resolve())] if args.source else [])
    for _, src in trees:
        warm(src, root, args.workers)
    print(f"kicktimes reproduce --scale {args.scale} against the C loop; {args.workers} "
          f"workers, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f} at start")
    rows, stages = [], {}
    for rnd in range(1, args.rounds + 1):
        for content in args.contents:
            c_sec, n = c_loop_seconds(c_ref, args.scale, content)
            for label, src in (trees if rnd % 2 else trees[::-1]):
                out = root / f"{label.replace(' ', '_')}-{content}-{rnd}"
                wall = run_command(src, args.scale, content, out, args.workers,
                                   root / f"{out.name}.log")
                rows.append({"round": rnd, "content": content, "tree": label, "wall_s": wall,
                             "c_loop_s": c_sec, "trajectories": n, "ratio": wall / c_sec})
                stages[(content, label, rnd)] = stage_table(out)
                print(f"round {rnd}, {content:5s}, {label:9s}: {wall:7.1f} s, C loop "
                      f"{c_sec:5.2f} s ({n} trajectories): {wall / c_sec:5.1f}x", flush=True)
            runs = [root / f"{label.replace(' ', '_')}-{content}-{rnd}" for label, _ in trees]
            if len(runs) == 2:
                # no change to any result: the stores of the two trees, bitwise
                stores = store_differences(*runs)
                files = report_differences(*runs)
                print(f"round {rnd}, {content:5s}: stores bitwise equal: "
                      f"{'yes' if not stores else 'NO, ' + ', '.join(stores)}; report files "
                      f"that differ: {len(files)}{' (' + ', '.join(files) + ')' if files else ''}",
                      flush=True)
            if args.out is None:
                for run in runs:
                    shutil.rmtree(run, ignore_errors=True)
    table = pd.DataFrame(rows)
    print("\n" + table.to_markdown(index=False, floatfmt=".2f"))
    stage_frame = pd.DataFrame(stages).fillna(0.0)
    stage_frame.columns = [f"{c} / {t} / {r}" for c, t, r in stage_frame.columns]
    print("\nseconds by stage (sweeps: worker-seconds; report: seconds per stage, summed):")
    print(stage_frame.round(1).to_markdown())
    if args.out is None:
        shutil.rmtree(root, ignore_errors=True)
    return table, stage_frame


if __name__ == "__main__":
    main()
