"""Is the tangent FTLE of N disks right? Two equivalence checks, margins stated in advance.

* ``tangent/twin``: the largest Lyapunov exponent of `kicktimes.diagnostics.disks_lyapunov`
  from tangent vectors (``method="tangent"``, one run of the N-disk engine carrying them)
  over the same from a Benettin twin (``method="twin"``, ``d0 = 1e-9``, restarted through
  `simulate_disks` at every segment), on the same states (``initial_state``, seeds
  ``0 .. ics-1``) and the same first direction, at packing 0.15, N = 2, 10, 100, 1000, both
  rules. Margin 2 %.
* ``engine/two-disk``: two disks of radius 0.1 through the N-disk engine (tangent FTLE)
  over the two-disk simulator's tangent FTLE (`kicktimes.diagnostics.lyapunov`, disk 0's
  position deviation), same states, both rules. Margin 5 %.

Each method's runs of one state follow different trajectories after some ``37 / lambda``
(the twin's restarts, and the two simulators, round differently; chaos amplifies it), so
only means over states compare: ``estimate`` is the ratio of the means over the states,
``lo, hi`` its 95 % percentile interval from a paired bootstrap over the states
(`kicktimes.report.effects.paired_ratio`), ``verdict`` `kicktimes.stats.ratio_verdict`
with ``tolerance=margin`` (an equivalence test: "within" when the whole interval lies in
``[1 - margin, 1 + margin]``).

Writes ``OUT/disks_ftle_check.csv`` (columns ``check, n_disks, rule, packing, n_ics, t_max,
estimate, lo, hi, margin, verdict``) and ``OUT/disks_ftle_check_runs.csv`` (every state's
two exponents).

Run: python analysis/disks_ftle_check.py --out docs/results [--ics 32] [--workers 1]
     [--scale 1.0] [--max-disks 1000]
     python analysis/disks_ftle_check.py --out docs/results --from-runs   (statistics only)
"""

from __future__ import annotations

import argparse
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

PACKING = 0.15
TWO_DISK_R = 0.1
MARGINS = {"tangent/twin": 0.02, "engine/two-disk": 0.05}
# per N: (t_max, segment) at scale 1; the twin's segment keeps d0 e^(lambda segment) far
# below r (lambda segment about 2-3) and the collisions per segment few enough that a
# grazing one missed by the twin is rare
TWIN_RUNS = {2: (4000.0, 5.0), 10: (400.0, 0.5), 100: (40.0, 0.1), 1000: (8.0, 0.04)}
TWO_DISK_RUN = (20000.0, 10.0)
COLUMNS = ["check", "n_disks", "rule", "packing", "n_ics", "t_max", "estimate", "lo", "hi",
           "margin", "verdict"]


def pair(task):
    """One state's two exponents: ``(check, n, rule, seed, t_max, numerator, denominator)``."""
    import kicktimes as kt
    from kicktimes.diagnostics import disks_lyapunov, lyapunov

    check, n, rule, seed, t_max, segment = task
    if check == "tangent/twin":
        r = math.sqrt(PACKING / n)
        state = kt.initial_state(n, r, seed=seed, rule=rule)
        kw = dict(t_max=t_max, segment=segment, rule=rule, rng=seed)
        num = disks_lyapunov(state, r, **kw).exponent
        den = disks_lyapunov(state, r, method="twin", **kw).exponent
    else:
        state = kt.initial_state(2, TWO_DISK_R, seed=seed, rule=rule)
        num = disks_lyapunov(state, TWO_DISK_R, t_max=t_max, segment=segment, rule=rule,
                             rng=seed).exponent
        den = lyapunov(state, TWO_DISK_R, n_steps=int(round(t_max / segment)), tau=segment,
                       rule=rule).lam
    return check, n, rule, seed, t_max, num, den


def tasks(ics, scale, max_disks):
    out = []
    for rule in ("mirror", "elastic"):
        for n, (t_max, segment) in TWIN_RUNS.items():
            if n <= max_disks:
                out += [("tangent/twin", n, rule, s, t_max * scale, segment) for s in range(ics)]
        t_max, segment = TWO_DISK_RUN
        out += [("engine/two-disk", 2, rule, s, t_max * scale, segment) for s in range(ics)]
    # the longest first, for the pool
    return sorted(out, key=lambda t: -t[4] * t[1] / t[5])


def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    from kicktimes.report.effects import paired_ratio
    from kicktimes.stats import ratio_verdict

    rows = []
    for (check, n, rule), g in runs.groupby(["check", "n_disks", "rule"], sort=False,
                                            observed=True):
        idx = pd.MultiIndex.from_product([[0.0], g["seed"].to_numpy()], names=["radius", "ic"])
        _, overall = paired_ratio(pd.Series(g["numerator"].to_numpy(), index=idx),
                                  pd.Series(g["denominator"].to_numpy(), index=idx),
                                  rng=np.random.default_rng(20261127), n_boot=4000)
        margin = MARGINS[check]
        rows.append({
            "check": check, "n_disks": int(n), "rule": rule,
            "packing": PACKING if check == "tangent/twin" else round(2 * TWO_DISK_R ** 2, 12),
            "n_ics": len(g), "t_max": float(g["t_max"].iloc[0]),
            "estimate": overall["ratio"], "lo": overall["ci_low"], "hi": overall["ci_high"],
            "margin": margin,
            "verdict": ratio_verdict(overall["ci_low"], overall["ci_high"], tolerance=margin),
        })
    table = pd.DataFrame(rows, columns=COLUMNS)
    return table.sort_values(["check", "rule", "n_disks"], ascending=[False, False, True],
                             ignore_index=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="folder of disks_ftle_check.csv")
    parser.add_argument("--ics", type=int, default=32, help="states per (check, N, rule)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--scale", type=float, default=1.0, help="times every t_max")
    parser.add_argument("--max-disks", type=int, default=1000, help="largest N checked")
    parser.add_argument("--from-runs", action="store_true",
                        help="only the statistics, from OUT/disks_ftle_check_runs.csv")
    args = parser.parse_args(argv)
    if args.ics < 2 or args.workers < 1 or not args.scale > 0:
        parser.error("--ics must be >= 2, --workers >= 1, --scale > 0")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    if args.from_runs:
        runs = pd.read_csv(out / "disks_ftle_check_runs.csv")
    else:
        todo = tasks(args.ics, args.scale, args.max_disks)
        if args.workers == 1:
            done = [pair(t) for t in todo]
        else:
            with ProcessPoolExecutor(args.workers) as pool:
                done = list(pool.map(pair, todo, chunksize=1))
        runs = pd.DataFrame(done, columns=["check", "n_disks", "rule", "seed", "t_max",
                                           "numerator", "denominator"])
        runs = runs.sort_values(["check", "n_disks", "rule", "seed"], ignore_index=True)
        runs.to_csv(out / "disks_ftle_check_runs.csv", index=False)
    table = summarise(runs)
    table.to_csv(out / "disks_ftle_check.csv", index=False)
    with pd.option_context("display.width", 140, "display.max_columns", 20):
        print(table.to_string(index=False))
    print(f"{len(runs)} states in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
