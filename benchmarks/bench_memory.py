"""Sweep tasks with and without the workers' allocator setting (kicktimes.memory).

The local pool's workers call `kicktimes.memory.keep_freed_memory` (glibc ``mallopt``:
blocks below 32 MB from the heap, trim above 256 MB free) so that the arrays each kernel
call returns reuse freed memory instead of being ``mmap``-ed afresh and faulted in again.
This benchmark runs the same sweep tasks on two-worker pools, with the setting (the
default pool) and without it (the reference: glibc's defaults), alternating, same run,
and prints the wall time, the summed task time and the page faults of the workers.

Usage::

    python benchmarks/bench_memory.py [--preset family_a] [--n-ics 40] [--rounds 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import resource
import time

from kicktimes.experiment import execute_task, preset, runner


def _task(exp, task):
    """(seconds, page faults) of one sweep task in this worker."""
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    out = execute_task(exp, task)
    return out.timings["total"], resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


def one_round(exp, keep: bool):
    saved = runner._worker_init
    if not keep:
        runner._worker_init = runner._exit_with_parent  # glibc's defaults
    try:
        with runner.local_pool(2) as pool:
            tasks = exp.tasks()
            list(pool.map(_task, [exp] * 2, tasks[:2]))  # load the kernels
            t0 = time.perf_counter()
            outs = list(pool.map(_task, [exp] * len(tasks), tasks))
            wall = time.perf_counter() - t0
    finally:
        runner._worker_init = saved
    return wall, sum(o[0] for o in outs), sum(o[1] for o in outs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="family_a")
    parser.add_argument("--n-ics", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    base = preset(args.preset)
    radii = base.radii[:: max(1, len(base.radii) // 5)]
    exp = dataclasses.replace(base, radii=radii, n_ics=args.n_ics, block_size=10)
    print(f"{args.preset}: {len(radii)} radii x {args.n_ics} ICs x {exp.n_steps} steps, "
          f"{len(exp.tasks())} tasks, 2 workers, {args.rounds} alternating rounds")
    best = {True: None, False: None}
    for _ in range(args.rounds):
        for keep in (False, True):
            row = one_round(exp, keep)
            if best[keep] is None or row[0] < best[keep][0]:
                best[keep] = row
            print(f"  {'kept memory ' if keep else 'glibc default'}: wall {row[0]:6.2f} s, "
                  f"tasks {row[1]:6.2f} worker-s, page faults ~{row[2]:,}")
    (w0, b0, _), (w1, b1, _) = best[False], best[True]
    print(f"best wall: glibc default {w0:.2f} s, kept memory {w1:.2f} s: {w0 / w1:.2f}x "
          f"(worker-s {b0 / b1:.2f}x)")


if __name__ == "__main__":
    main()
