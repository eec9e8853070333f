"""Speed of the report's MMPP stage (kicktimes.report.mmpp.sections; issue 39, item 4).

Run: ``python benchmarks/bench_mmpp_stage.py STORE --source DIR [--rounds 2]``

Per round, for this tree and for the export ``DIR`` of an older commit (``git archive
<commit> | tar -x -C DIR``), in that order and then the other way round in the next
round, a fresh process loads the store as the report does (``load_report_store``), runs
the renewal section (which picks the ICs the MMPP stage fits; not timed) and times
``kicktimes.report.mmpp.sections`` in one process (``pmap = map``: every fit of every IC
and of its Poisson twin one after the other), with the report's default options. Prints
the wall and CPU seconds of the stage, the number of fits and the stage's shares (MMPP-2
AIC-best, beats Poisson; on the data and on the twins), so that a change of the fits
shows beside its cost.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

_CHILD = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
from kicktimes.report import mmpp, renewal
from kicktimes.report.context import Context
from kicktimes.report.store import load_report_store
ctx = Context(load_report_store(sys.argv[1]))
renewal.sections(ctx)
t0, c0 = time.perf_counter(), time.process_time()
mmpp.sections(ctx)
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
per_ic = ctx.found.mmpp
print(json.dumps({"wall": wall, "cpu": cpu, "ics": len(per_ic),
                  "best": float(per_ic["mmpp_best"].mean()),
                  "beats": float(per_ic["mmpp_beats_poisson"].mean()),
                  "null_best": float(per_ic["null_mmpp_best"].mean()),
                  "null_beats": float(per_ic["null_mmpp_beats_poisson"].mean())}))
"""


def stage(store, tree):
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = tree
    out = subprocess.run([sys.executable, "-c", _CHILD, store], env=env, check=True,
                         capture_output=True, text=True, cwd=tree or os.getcwd())
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("store")
    ap.add_argument("--source", required=True, help="export of the older tree")
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args()
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    trees = [("this tree", here), ("source", os.path.abspath(args.source))]
    print(f"store {args.store}; load average {os.getloadavg()[0]:.2f}")
    for k in range(args.rounds):
        for name, tree in trees if k % 2 == 0 else trees[::-1]:
            r = stage(args.store, tree)
            print(f"round {k + 1}, {name:>9}: MMPP stage {r['wall']:.2f} s wall, "
                  f"{r['cpu']:.2f} s CPU, {r['ics']} ICs (+ twins); MMPP-2 AIC-best "
                  f"{r['best']:.3f} (twins {r['null_best']:.3f}), beats Poisson "
                  f"{r['beats']:.3f} (twins {r['null_beats']:.3f}); load "
                  f"{os.getloadavg()[0]:.2f}", flush=True)


if __name__ == "__main__":
    main()
