"""Is the kicked one-disk billiard cheaper than the two-disk billiard? Cost per unit time.

The paper's premise (Ranković & Porter 2013, introduction): one-particle approximations
are "much less computationally demanding" than the two-particle system, which needs "very
long computation time" for small disks. For an event-driven simulator both runs are
dominated by wall collisions (about one per unit time and disk, whatever r), so the
question is measured here, not assumed: CPU seconds per unit of simulated time of

* ``simulate_two_particle(ic, r, t_max=T)`` (both disks; disk-disk collisions logged),
* ``simulate_one_particle(ic[0], r, t_max=T, kicks=Poisson(Gamma(r)))`` (the paper's
  kicked disk at the kinetic collision rate),

at radii 0.001 to 0.03, the same paper ICs for both, interleaved, minimum of repeats
(``time.process_time``: the machine is shared). No samples are stored (``sampling`` off),
so the cost is the event loop's.

Run: python benchmarks/bench_cost_per_time.py [--t-max 20000] [--n-ics 5] [--csv out.csv]
"""

import argparse
import os
import sys
import time

import pandas as pd

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.stats import kinetic_rate

sys.path.insert(0, os.path.dirname(__file__))
from _timing import best_time  # noqa: E402

RADII = (0.001, 0.002, 0.005, 0.01, 0.03)


def cpu(fn, repeat):
    return best_time(fn, repeat, clock=time.process_time)


def measure(t_max=20000.0, n_ics=5, repeat=3, radii=RADII) -> pd.DataFrame:
    """One row per radius: CPU microseconds per unit time of each run and their ratio."""
    ics = initial_conditions(n_ics, max(radii), rng=3)
    rows = []
    # warm the kernels
    simulate_two_particle(ics[0], radii[0], t_max=10.0)
    simulate_one_particle(ics[0, 0], radii[0], t_max=10.0, kicks=schedules.Poisson(0.1), rng=0)
    for r in radii:
        rate = kinetic_rate(r)
        two = one = 0.0
        n_pp = n_kicks = 0
        for k, ic in enumerate(ics):
            kicks = schedules.Poisson(rate).sample(t_max, rng=k)
            two += cpu(lambda ic=ic, r=r: simulate_two_particle(ic, r, t_max=t_max), repeat)
            one += cpu(lambda ic=ic, r=r, kicks=kicks, k=k: simulate_one_particle(
                ic[0], r, t_max=t_max, kicks=kicks, rng=k), repeat)
            n_pp += simulate_two_particle(ic, r, t_max=t_max).n_pp
            n_kicks += kicks.size
        rows.append({
            "radius": r,
            "two_disk_us_per_time": 1e6 * two / (n_ics * t_max),
            "kicked_us_per_time": 1e6 * one / (n_ics * t_max),
            "two_over_kicked": two / one,
            "disk_collisions_per_time": n_pp / (n_ics * t_max),
            "kicks_per_time": n_kicks / (n_ics * t_max),
        })
    return pd.DataFrame(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--t-max", type=float, default=20000.0)
    ap.add_argument("--n-ics", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--csv", help="also write the table here")
    args = ap.parse_args()
    table = measure(args.t_max, args.n_ics, args.repeat)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    if args.csv:
        table.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
