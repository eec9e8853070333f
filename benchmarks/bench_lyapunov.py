"""Cost of the FTLE (tangent and twin methods) relative to the bare simulation.

Workload (as benchmarks/bench_simulators.py): r = 0.01, tau = 0.3, 15 000 uniform samples,
paper-procedure ICs. References, timed in the same run on the same trajectories:
`simulate_two_particle` (for the two-disk FTLE) and `simulate_one_particle` with Poisson
kicks at each IC's own collision rate (for the kicked FTLE, on the very runs it computes).
Each time is the best of ``--repeat`` passes over all ICs.

Run: python benchmarks/bench_lyapunov.py [--n-ics 100] [--repeat 3]
"""

import argparse
import os
import time

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.diagnostics import lyapunov


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ics", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    r, tau, n_steps = 0.01, 0.3, 15000
    ics = initial_conditions(args.n_ics, r, seed=2026, method="paper")

    # warm-up: compile (or load from the numba cache) every kernel timed below
    for method in ("tangent", "twin"):
        for variant in ("norm", "paper"):
            lyapunov(ics[0], r, n_steps=10, tau=tau, method=method, variant=variant)
            lyapunov(ics[0, 0], r, n_steps=10, tau=tau, kicks=[0.1], rng=0, method=method,
                     variant=variant)
    simulate_one_particle(ics[0, 0], r, n_steps=10, tau=tau, kicks=[0.1], rng=0)

    runs = [simulate_two_particle(ic, r, n_steps=n_steps, tau=tau) for ic in ics]
    rates = [schedules.Poisson.from_run(run) for run in runs]
    ones = [simulate_one_particle(ic[0], r, n_steps=n_steps, tau=tau, kicks=rate, rng=i)
            for i, (ic, rate) in enumerate(zip(ics, rates, strict=True))]

    t_two = best_of(lambda: [simulate_two_particle(ic, r, n_steps=n_steps, tau=tau)
                             for ic in ics], args.repeat)
    t_one = best_of(lambda: [simulate_one_particle(o.ic, r, n_steps=n_steps, tau=tau,
                                                   kicks=o.kick_times, kick_angles=o.kick_angles)
                             for o in ones], args.repeat)

    print(f"workload: r={r}, tau={tau}, n_steps={n_steps}, {args.n_ics} paper ICs, "
          f"best of {args.repeat}, {os.cpu_count()} cores (one used)")
    print(f"{'what':44s} {'ms/traj':>8s} {'ratio to bare simulation':>26s}")
    ms = 1e3 / args.n_ics
    print(f"{'simulate_two_particle':44s} {t_two * ms:8.3f} {'1':>26s}")
    print(f"{'simulate_one_particle (Poisson kicks)':44s} {t_one * ms:8.3f} {'1':>26s}")
    for method in ("tangent", "twin"):
        for variant in ("norm", "paper"):
            t = best_of(lambda m=method, v=variant: [
                lyapunov(ic, r, n_steps=n_steps, tau=tau, method=m, variant=v) for ic in ics],
                args.repeat)
            print(f"{f'lyapunov two-disk, {method}, {variant}':44s} {t * ms:8.3f} "
                  f"{t / t_two:26.2f}")
    for method in ("tangent", "twin"):
        for variant in ("norm", "paper"):
            t = best_of(lambda m=method, v=variant: [
                lyapunov(o, method=m, variant=v) for o in ones], args.repeat)
            print(f"{f'lyapunov kicked disk, {method}, {variant}':44s} {t * ms:8.3f} "
                  f"{t / t_one:26.2f}")


if __name__ == "__main__":
    main()
