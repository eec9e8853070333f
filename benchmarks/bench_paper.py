"""Wall time of the whole paper: both experiment families at full scale, plus the report.

Runs ``family_a`` (12 radii x 200 ICs x 25000 steps of 0.2) and ``family_b`` (10 radii x
1000 ICs x 15000 steps of 0.3) on the local process pool, three systems and three
diagnostics each, then builds the report (if ``kicktimes.report`` is available), and
prints the wall times with a breakdown by stage (summed over tasks, i.e. worker-seconds,
from the timings each task records in the store manifest).

References measured in the same run:

* the bare two-disk simulation of the same ICs (every radius and IC of every family, the
  experiments' own steps and sampling, no diagnostics, no store, one process): the whole
  paper's wall time is printed as a multiple of it, with a Markdown row for the README's
  speed table;
* a subset of family A (3 radii x 16 ICs, the full 25000 steps) with one worker and with
  all workers, giving the parallel speed-up and the per-IC cost of each stage.

The report is built twice: from scratch, then again with nothing changed (the cached
rebuild, which must not recompute anything).

``--content paper`` times the paper's own content instead of kicktimes' presets: its three
systems (no scatter-kicked systems), the recurrence rate at eps = 1e-3 only (no second
threshold) and R_1 only (no ACF curve), to separate the cost of the extensions.

Usage::

    python benchmarks/bench_paper.py                 # full scale (minutes)
    python benchmarks/bench_paper.py --content paper # the paper's three systems, RR, R_1
    python benchmarks/bench_paper.py --scale quick   # the quick presets (seconds)
    python benchmarks/bench_paper.py --out DIR --keep --json timings.json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

import pandas as pd

from kicktimes.experiment import execute_task, preset, run_experiment
from kicktimes.experiment.runner import local_pool
from kicktimes.studies.paper import SCALES, scale_presets

# with the tangent FTLE (the presets) each trajectory is simulated once, together with its
# FTLE (one pass): that time is under lyapunov_*; simulation_* is what runs without it
STAGES = [
    ("simulation_two_particle", "simulation: two-particle runs (without the FTLE)"),
    ("simulation_one_particle", "kick draws (+ kicked runs without the FTLE)"),
    ("lyapunov_two_particle", "simulation + FTLE, two-particle (one pass)"),
    ("lyapunov_kicked", "simulation + FTLE, kicked (one pass)"),
    ("recurrence_rate", "diagnostic: recurrence rate"),
    ("autocorrelation", "diagnostic: autocorrelation"),
    ("tables", "tidy tables"),
]


def stage_table(store) -> pd.DataFrame:
    sums = store.timings.sum()
    total = float(sums.get("total", 0.0))
    rows = []
    for key, label in STAGES:
        sec = float(sums.get(key, 0.0))
        rows.append({"stage": label, "worker_s": sec, "share": sec / total if total else 0.0})
    other = total - sum(r["worker_s"] for r in rows)
    rows.append({"stage": "other (ICs, loop)", "worker_s": other, "share": other / total})
    rows.append({"stage": "total (worker-seconds)", "worker_s": total, "share": 1.0})
    return pd.DataFrame(rows)


def bare_simulation(names) -> tuple[float, int]:
    """Seconds to simulate every radius x IC of the experiments ``names`` as two bare
    disks (the sweep's first step, nothing else), in this process; and the run count."""
    from kicktimes import initial_conditions, simulate_two_particle

    t0 = time.perf_counter()
    n = 0
    for name in names:
        exp = preset(name)
        ics = initial_conditions(
            exp.n_ics, exp.r_max, rng=exp.seed, method=exp.ic_method, rule=exp.rule
        )
        for r in exp.radii:
            for ic in ics:
                simulate_two_particle(
                    ic,
                    r,
                    rule=exp.rule,
                    track=0,
                    n_steps=exp.n_steps,
                    tau=exp.tau,
                    sampling=exp.sampling,
                )
                n += 1
    return time.perf_counter() - t0, n


def report_breakdown(timings: pd.DataFrame) -> pd.DataFrame:
    """Report seconds per stage, summed over the experiments (sections run in workers, so
    the sum can exceed the wall time)."""
    t = timings.groupby("stage", sort=False, observed=True)["seconds"].sum().reset_index()
    return t.sort_values("seconds", ascending=False, ignore_index=True)


def reference(workers: int, root: Path) -> dict:
    """Subset of family A with 1 worker and with ``workers``: speed-up and per-IC costs."""
    exp = dataclasses.replace(
        preset("family_a"), name="ref_a", radii=[0.008, 0.02, 0.03], n_ics=16, block_size=4
    )
    out = {}
    for w in sorted({1, workers}):
        path = root / f"ref-{w}"
        t0 = time.perf_counter()
        store = run_experiment(exp, path, workers=w, progress=False)
        out[w] = time.perf_counter() - t0
    n_pairs = len(exp.radii) * exp.n_ics
    per_ic = (store.timings.sum() / n_pairs * 1e3).round(2).to_dict()
    return {"experiment": exp, "wall": out, "per_ic_ms": per_ic, "n_pairs": n_pairs}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", choices=sorted(SCALES), default="paper")
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    parser.add_argument("--out", type=Path, default=None, help="keep stores/report here")
    parser.add_argument("--keep", action="store_true", help="do not delete --out afterwards")
    parser.add_argument("--no-report", action="store_true")
    parser.add_argument("--json", type=Path, default=None, help="also write the numbers here")
    parser.add_argument(
        "--content",
        choices=("full", "paper"),
        default="full",
        help="full: the presets (5 systems, RQA at 2 eps, ACF curves); paper: the paper's "
        "3 systems, RR at 1e-3, R_1",
    )
    args = parser.parse_args()

    root = args.out or Path(tempfile.mkdtemp(prefix="bench-paper-"))
    root.mkdir(parents=True, exist_ok=True)
    load0 = os.getloadavg()[0]
    print(
        f"kicktimes paper benchmark: scale {args.scale}, content {args.content}, "
        f"{args.workers} workers, "
        f"{os.cpu_count()} cores, load average at start {load0:.2f}"
    )

    # numba kernels load from the on-disk cache (or compile) once per process; do it here
    # so the first task's time is not a compilation
    t0 = time.perf_counter()
    warm = dataclasses.replace(preset("quick_a"), n_ics=1, n_steps=50, block_size=1)
    execute_task(warm, warm.tasks()[0])
    warmup = time.perf_counter() - t0

    results = {
        "scale": args.scale,
        "workers": args.workers,
        "warmup_s": warmup,
        "load_start": load0,
        "families": {},
    }
    stores = []
    t_all = time.perf_counter()
    # one pool for both families, as `kicktimes reproduce` does (its start-up is timed)
    pool = local_pool(args.workers) if args.workers > 1 else None
    for name in scale_presets(args.scale, args.content):
        # --content paper: PAPER_CONTENT, what `kicktimes reproduce --content paper` runs
        exp = preset(name, content=args.content)
        path = root / f"store-{name}"
        t0 = time.perf_counter()
        store = run_experiment(
            exp, path, executor=pool, workers=None if pool else 1, progress=False
        )
        wall = time.perf_counter() - t0
        stores.append(path)
        table = stage_table(store)
        n_pairs = len(exp.radii) * exp.n_ics
        results["families"][name] = {
            "wall_s": wall,
            "n_radius_ic": n_pairs,
            "ms_per_radius_ic": wall / n_pairs * 1e3,
            "stages": table.to_dict(orient="records"),
        }
        print(
            f"\n{name}: {len(exp.radii)} radii x {exp.n_ics} ICs x {exp.n_steps} steps "
            f"(tau {exp.tau}), {len(exp.tasks())} tasks: wall {wall:.1f} s "
            f"({wall / n_pairs * 1e3:.1f} ms per radius-IC, {len(exp.systems)} systems)"
        )
        print(table.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    if pool is not None:
        pool.shutdown()
    sweep_wall = time.perf_counter() - t_all

    report_wall = None
    if not args.no_report:
        try:
            from kicktimes.report import build_report
        except ImportError:
            print("\nkicktimes.report is not available: report not timed")
        else:
            t0 = time.perf_counter()
            build_report(stores, root / "report", workers=args.workers, progress=False)
            report_wall = time.perf_counter() - t0
            timings = root / "report" / "report_timings.csv"
            print(f"\nreport (statistics + figures + HTML): wall {report_wall:.1f} s")
            if timings.exists():
                t = pd.read_csv(timings).fillna("")
                print(t.to_string(index=False, float_format=lambda x: f"{x:.2f}"))
                print("\nreport seconds by stage, summed over experiments:")
                print(report_breakdown(t).to_string(index=False, float_format="{:.2f}".format))
                results["report_stages"] = t.to_dict(orient="records")
            t0 = time.perf_counter()
            build_report(stores, root / "report", workers=args.workers, progress=False)
            rerun = time.perf_counter() - t0
            results["report_rerun_s"] = rerun
            print(f"report rebuilt with nothing changed (cache): wall {rerun:.2f} s")
    results["sweep_wall_s"] = sweep_wall
    results["report_wall_s"] = report_wall
    total = sweep_wall + (report_wall or 0.0)
    results["total_wall_s"] = total

    bare, n_runs = bare_simulation(scale_presets(args.scale, args.content))
    results["bare_simulation_s"] = bare
    print(
        f"\nreference (same run): bare two-disk simulation of the same {n_runs} radius-IC "
        f"pairs, one process: {bare:.2f} s; whole paper = {total / bare:.1f}x that"
    )

    print("\nreference (same run): subset of family A, 3 radii x 16 ICs x 25000 steps")
    ref = reference(args.workers, root)
    w1 = ref["wall"][1]
    wn = ref["wall"][args.workers]
    print(f"  1 worker: {w1:.2f} s   {args.workers} workers: {wn:.2f} s   speed-up {w1 / wn:.2f}x")
    print(f"  per radius-IC (all systems), ms: {ref['per_ic_ms']}")
    results["reference"] = {"wall": ref["wall"], "speedup": w1 / wn, "per_ic_ms": ref["per_ic_ms"]}

    print(
        f"\nTOTAL: sweeps {sweep_wall:.1f} s + report "
        f"{report_wall if report_wall is not None else float('nan'):.1f} s = {total:.1f} s "
        f"({total / 60:.2f} min; target < 10 min, aim < 2 min); "
        f"load average at end {os.getloadavg()[0]:.2f}"
    )
    families = " + ".join(scale_presets(args.scale, args.content))
    print("\nREADME speed table row:")
    print(
        f"| **the whole paper** ({args.scale} scale, {args.content} content: {families}, "
        f"{n_runs} radius-IC pairs x {len(exp.systems)} systems x 3 diagnostics) + report, "
        f"{args.workers} workers "
        f"| **{total:.0f} s** (sweeps {sweep_wall:.0f} s, report {report_wall or 0:.0f} s; "
        f"unchanged rerun of the report {results.get('report_rerun_s', float('nan')):.1f} s) "
        f"| the bare two-disk simulation of the same ICs in one process: {bare:.1f} s, "
        f"**{total / bare:.0f}x**; 1 -> {args.workers} workers: {w1 / wn:.2f}x |"
    )
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=str))
    if args.out is None or not args.keep:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
