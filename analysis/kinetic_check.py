"""The exact kinetic-theory check of the simulator, as a table.

With ICs drawn from the invariant measure the mean number of disk-disk collisions in
[0, T] is Gamma(r) T exactly (docs/architecture.md, "Invariant measure and the kinetic
rate"). Prints mean count, its standard error, the kinetic expectation and the z-score
for both rules at several radii.

Run: python analysis/kinetic_check.py [--n-ics 20000] [--t-max 200]
"""

import argparse

import numpy as np

from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.stats import kinetic_rate


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ics", type=int, default=20000)
    ap.add_argument("--t-max", type=float, default=200.0)
    ap.add_argument("--radii", type=float, nargs="+", default=[0.01, 0.02, 0.05])
    args = ap.parse_args()
    print(f"{args.n_ics} invariant-measure ICs per radius, T = {args.t_max:g}")
    print(f"{'rule':8s} {'r':>6s} {'mean N':>9s} {'sem':>7s} {'Gamma T':>9s} {'z':>6s}")
    for rule in ("mirror", "elastic"):
        for r in args.radii:
            ics = initial_conditions(args.n_ics, r, rng=7, method="uniform", rule=rule)
            counts = np.array([simulate_two_particle(ic, r, t_max=args.t_max, rule=rule).n_pp
                               for ic in ics])
            expected = kinetic_rate(r, rule=rule) * args.t_max
            sem = counts.std(ddof=1) / np.sqrt(len(counts))
            z = (counts.mean() - expected) / sem
            print(f"{rule:8s} {r:6.3f} {counts.mean():9.3f} {sem:7.3f} {expected:9.3f} {z:6.2f}")


if __name__ == "__main__":
    main()
