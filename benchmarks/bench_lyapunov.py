"""Cost of the FTLE (tangent and twin methods) relative to the bare simulation.

Workload (as benchmarks/bench_simulators.py): r = 0.01, tau = 0.3, 15 000 uniform samples,
paper-procedure ICs. References, timed in the same run on the same trajectories:
`simulate_two_particle` (for the two-disk FTLE) and `simulate_one_particle` with Poisson
kicks at each IC's own collision rate (for the kicked FTLE, on the very runs it computes).
Each trajectory's calls are timed back to back, each the best of ``--repeat``.

Run: python benchmarks/bench_lyapunov.py [--n-ics 100] [--repeat 3]
"""

import argparse
import os
import time

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.diagnostics import lyapunov


def interleaved_min(calls, n, repeat):
    """Per item ``i < n``: every call back to back, each the best of ``repeat``; summed.

    Timing the calls of one trajectory next to each other makes the ratios robust to the
    load of a shared machine drifting during the run.
    """
    totals = dict.fromkeys(calls, 0.0)
    for i in range(n):
        for name, fn in calls.items():
            best = float("inf")
            for _ in range(repeat):
                t0 = time.perf_counter()
                fn(i)
                best = min(best, time.perf_counter() - t0)
            totals[name] += best
    return totals


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

    calls = {
        "simulate_two_particle": lambda i: simulate_two_particle(ics[i], r, n_steps=n_steps,
                                                                 tau=tau),
        "simulate_one_particle (Poisson kicks)": lambda i: simulate_one_particle(
            ones[i].ic, r, n_steps=n_steps, tau=tau, kicks=ones[i].kick_times,
            kick_angles=ones[i].kick_angles),
    }
    for method in ("tangent", "twin"):
        for variant in ("norm", "paper"):
            calls[f"lyapunov two-disk, {method}, {variant}"] = (
                lambda i, m=method, v=variant: lyapunov(ics[i], r, n_steps=n_steps, tau=tau,
                                                        method=m, variant=v))
            calls[f"lyapunov kicked disk, {method}, {variant}"] = (
                lambda i, m=method, v=variant: lyapunov(ones[i], method=m, variant=v))
    totals = interleaved_min(calls, args.n_ics, args.repeat)
    t_two = totals["simulate_two_particle"]
    t_one = totals["simulate_one_particle (Poisson kicks)"]
    print(f"workload: r={r}, tau={tau}, n_steps={n_steps}, {args.n_ics} paper ICs, "
          f"best of {args.repeat} per trajectory, interleaved; {os.cpu_count()} cores (one used)")
    print(f"{'what':44s} {'ms/traj':>8s} {'ratio to bare simulation':>26s}")
    ms = 1e3 / args.n_ics
    for name, t in totals.items():
        ref = t_one if ("kicked" in name or "one_particle" in name) else t_two
        print(f"{name:44s} {t * ms:8.3f} {t / ref:26.2f}")


if __name__ == "__main__":
    main()
