"""Cost per wall event of the tangent FTLE at small radii (the small-r sweep's workload).

At fixed collisions per IC the horizon grows as 1/Γ(r) ∝ 1/r, and almost every event is a
wall reflection: about 2 T / (π ρ / 2) of them for two disks (the mean chord of the circle
of radius ρ = 1 - r is π ρ / 2 at unit speed). Per radius, one invariant IC over
``--collisions`` collisions: the two-disk tangent FTLE and the FTLE of the disk kicked
at Poisson times at the kinetic rate (uniform kicks), each the best of ``--repeat`` CPU
times. Printed: seconds, expected wall events, nanoseconds per event and its ratio to the
largest radius, measured in the same run.

Run: python benchmarks/bench_small_r.py [--radii 1e-2 1e-3 1e-4] [--collisions 2000]
     [--repeat 3]
"""

import argparse
import math
import time

import numpy as np
from _timing import best_time

from kicktimes.billiard import KickLaw, initial_conditions
from kicktimes.diagnostics import lyapunov
from kicktimes.schedules import Poisson
from kicktimes.stats import kinetic_rate


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radii", type=float, nargs="+", default=[1e-2, 1e-3, 1e-4])
    parser.add_argument("--collisions", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    warm = initial_conditions(1, 0.01, method="uniform", rng=0)[0]
    lyapunov(warm, 0.01, n_steps=10, tau=10.0)
    lyapunov(warm[0], 0.01, n_steps=10, tau=10.0, kicks=KickLaw(np.array([5.0])))
    rows = []
    for r in sorted(args.radii, reverse=True):
        gamma = kinetic_rate(r)
        horizon = args.collisions / gamma
        ic = initial_conditions(1, r, method="uniform", rng=1)[0]
        kicks = KickLaw(Poisson(gamma).sample(horizon, rng=2))
        steps = {"n_steps": 100, "tau": horizon / 100}
        two = best_time(lambda ic=ic, r=r, steps=steps: lyapunov(ic, r, **steps),
                        args.repeat, clock=time.process_time)
        one = best_time(lambda ic=ic, r=r, steps=steps, k=kicks: lyapunov(
            ic[0], r, kicks=k, **steps), args.repeat, clock=time.process_time)
        walls = horizon / (0.5 * math.pi * (1 - r))
        rows.append((r, horizon, two, 2 * walls, one, walls))
    base_two = rows[0][2] / rows[0][3]
    base_one = rows[0][4] / rows[0][5]
    print(f"{args.collisions} collisions per run, best of {args.repeat} CPU times")
    print("| r | horizon | two disks s | wall events | ns/event | × largest r "
          "| kicked s | ns/event | × largest r |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r, horizon, two, e2, one, e1 in rows:
        print(f"| {r:g} | {horizon:.3g} | {two:.3g} | {e2:.3g} | {1e9 * two / e2:.1f} | "
              f"{two / e2 / base_two:.2f} | {one:.3g} | {1e9 * one / e1:.1f} | "
              f"{one / e1 / base_one:.2f} |")


if __name__ == "__main__":
    main()
