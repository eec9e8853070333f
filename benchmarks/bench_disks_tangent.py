"""Cost of the N-disk engine's tangent observer: CPU time per disk-disk collision.

For N disks at one packing (mirror and elastic rule), the same state run for the same time
by the engine (`kicktimes.billiard.many_disks.engine_run`, no collision log kept):

* ``bare``: no observers (the loop `simulate_disks` runs without holes, samples or masses);
* ``observers``: the loop compiled with every observer, the tangent off (what a run with
  holes, samples or masses runs);
* ``observer``: the same, the tangent observer on, one stop at the end (its cost in the
  loop: flights, maps, the norm checks);
* ``tangent``: `kicktimes.diagnostics.disks_lyapunov`'s ``method="tangent"`` as a user
  calls it, stopping every ``segment`` for the projection and renormalisation (O(N) in
  Python per stop);
* ``twin``: ``method="twin"`` (two `simulate_disks` calls per segment; cost per
  collision of the reference), over a tenth of the time (its cost is mostly the calls').

Segments of one collision per disk (as the disks experiment's twin, ``1 / nu``).

CPU seconds (``time.process_time``: the machine is shared), the best of ``--repeats``
alternated rounds; ns per disk-disk collision of the reference run.

Run: python benchmarks/bench_disks_tangent.py [--n 100 1000] [--packing 0.15] [--repeats 3]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import kicktimes as kt
from kicktimes.billiard import many_disks as md
from kicktimes.billiard.checks import RULES
from kicktimes.diagnostics import disks_lyapunov


def variants(state, r, rule, t_max, segment):
    """name: (a run, its time)."""
    state, radii, _ = md.check_disks(state, r, rule)
    code = RULES[rule]
    t_twin = segment * max(1, round(0.1 * t_max / segment))
    u0 = np.random.default_rng(1).normal(size=state.shape)
    u0 /= np.linalg.norm(u0)
    runs = {
        "bare": lambda: md.engine_run(state, radii, code, t_max, log=False),
        "observers": lambda: md.engine_run(state, radii, code, t_max, log=False,
                                           contacts=True),
        "observer": lambda: md.engine_run(state, radii, code, t_max, log=False,
                                          tangent=u0, segment=t_max,
                                          on_segment=lambda *_: None),
        "tangent": lambda: disks_lyapunov(state, r, t_max=t_max, segment=segment, rule=rule,
                                          rng=1),
        "twin": lambda: disks_lyapunov(state, r, t_max=t_twin, segment=segment, rule=rule,
                                       method="twin", rng=1),
    }
    bare = runs["bare"]
    return {k: (f, t_twin if k == "twin" else t_max) for k, f in runs.items()}, bare


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[100, 1000])
    ap.add_argument("--packing", type=float, default=0.15)
    ap.add_argument("--collisions", type=float, default=1e6, help="per run (about)")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    names = ("bare", "observers", "observer", "tangent", "twin")
    print(f"{'N':>6} {'rule':>8} {'collisions':>11} " + " ".join(f"{k:>10}" for k in names)
          + "   ns/collision")
    for n in args.n:
        r = math.sqrt(args.packing / n)
        for rule in ("mirror", "elastic"):
            state = kt.initial_state(n, r, rng=1, rule=rule)
            probe = md.engine_run(*md.check_disks(state, r, rule)[:2], RULES[rule], 1.0,
                                  log=False)
            per_time = max(probe["n_pp_total"], 1)
            t_max = max(1.0, round(args.collisions / per_time))
            # one collision per disk per segment (as the disks experiment's twin)
            segment = t_max / max(1, round(t_max * 2.0 * per_time / n))
            runs, bare = variants(state, r, rule, t_max, segment)
            best = dict.fromkeys(runs, math.inf)
            for _ in range(args.repeats):
                for name, (run, _t) in runs.items():
                    t0 = time.process_time()
                    run()
                    best[name] = min(best[name], time.process_time() - t0)
            n_pp = bare()["n_pp_total"]
            per = {k: n_pp * runs[k][1] / t_max for k in runs}  # (the twin's run is shorter)
            print(f"{n:>6} {rule:>8} {n_pp:>11} " + " ".join(
                f"{1e9 * best[k] / per[k]:>10.0f}" for k in best)
                + f"   (t_max {t_max:g}, segment {segment:.3g})")


if __name__ == "__main__":
    main()
