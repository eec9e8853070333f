"""Every event-loop driver of the kernel layer, timed; and two source trees compared.

One workload per driver, on the issue-13 setting (r = 0.01, tau = 0.3, paper ICs): the
two-disk simulation (mirror/uniform, elastic/paper, with the collision log), the kicked
disk (Poisson kicks with uniform angles, scattering kicks), the tangent FTLE of both
systems, the twin FTLE of both, the one pass (simulation + FTLE, two-disk with its
continuation, kicked disk) and the Lyapunov spectrum. Each row is CPU seconds
(``time.process_time``), the minimum over ``--repeat`` interleaved rounds.

``--compare A B`` runs this script on the source trees ``A`` and ``B`` (e.g. a worktree
of the previous commit and the working tree) in alternated subprocesses, ``--rounds``
times each, and prints per driver the best time of each tree and the ratio ``B / A``.
Each tree compiles into its own numba cache (``__pycache__`` beside its sources); a
warm-up run per tree comes first.

Run: python benchmarks/bench_kernels.py [--n-ics 10] [--repeat 5]
     python benchmarks/bench_kernels.py --compare /tmp/before . [--rounds 4]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time


def workloads(n_ics: int):
    """``{name: callable}``: one call runs the driver on every IC of its workload."""
    from kicktimes import (
        initial_conditions,
        schedules,
        simulate_one_particle,
        simulate_two_particle,
    )
    from kicktimes.diagnostics import lyapunov, lyapunov_spectrum
    from kicktimes.diagnostics.lyapunov import lyapunov_pass

    r, tau, n = 0.01, 0.3, 15000
    ics = initial_conditions(n_ics, r, seed=2026, method="paper")
    el = initial_conditions(n_ics, r, seed=2026, method="uniform", rule="elastic")
    kicks = schedules.Poisson(0.1)
    short = max(1, n_ics // 4)

    def each(fn, items):
        return lambda: [fn(i, x) for i, x in enumerate(items)]

    return {
        "two mirror uniform": each(lambda i, ic: simulate_two_particle(ic, r, n_steps=n, tau=tau),
                                   ics),
        "two elastic paper": each(lambda i, ic: simulate_two_particle(
            ic, r, n_steps=n, tau=tau, rule="elastic", sampling="paper"), el),
        "two collision log": each(lambda i, ic: simulate_two_particle(
            ic, r, t_max=n * tau, log_collisions=True), ics),
        "one poisson uniform": each(lambda i, ic: simulate_one_particle(
            ic[0], r, n_steps=n, tau=tau, kicks=kicks, rng=i), ics),
        "one scatter paper": each(lambda i, ic: simulate_one_particle(
            ic[0], r, n_steps=n, tau=tau, kicks=kicks, rng=i, kick_angle="scatter",
            sampling="paper"), ics),
        "ftle two tangent": each(lambda i, ic: lyapunov(ic, r, n_steps=n, tau=tau), ics),
        "ftle one tangent": each(lambda i, ic: lyapunov(ic[0], r, n_steps=n, tau=tau, kicks=kicks,
                                                        rng=i), ics),
        "ftle two twin": each(lambda i, ic: lyapunov(ic, r, n_steps=n, tau=tau, method="twin",
                                                     variant="paper"), ics[:short]),
        "ftle one twin": each(lambda i, ic: lyapunov(ic[0], r, n_steps=n, tau=tau, kicks=kicks,
                                                     rng=i, method="twin"), ics[:short]),
        "pass two paper": each(lambda i, ic: lyapunov_pass(
            ic, r, n_steps=n, tau=tau, sampling="paper", t_continue=1.2 * n * tau), ics),
        "pass one scatter": each(lambda i, ic: lyapunov(
            ic[0], r, n_steps=n, tau=tau, kicks=kicks, rng=i, kick_angle="scatter",
            sampling="paper", return_run=True), ics),
        "spectrum two": each(lambda i, ic: lyapunov_spectrum(ic, r, t_max=n * tau / 4),
                             ics[:short]),
    }


def measure(n_ics: int, repeat: int) -> dict[str, float]:
    calls = workloads(n_ics)
    for fn in calls.values():  # compile, or load from the numba cache
        fn()
    best = dict.fromkeys(calls, float("inf"))
    for _ in range(repeat):
        for name, fn in calls.items():
            t0 = time.process_time()
            fn()
            best[name] = min(best[name], time.process_time() - t0)
    return best


def compare(tree_a: str, tree_b: str, rounds: int, n_ics: int, repeat: int) -> None:
    def run(tree):
        env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
        out = subprocess.run([sys.executable, __file__, "--json", "--n-ics", str(n_ics),
                              "--repeat", str(repeat)], env=env, check=True,
                             capture_output=True, text=True).stdout
        return json.loads(out.strip().splitlines()[-1])

    best = {tree_a: {}, tree_b: {}}
    for i in range(rounds):
        for tree in (tree_a, tree_b) if i % 2 == 0 else (tree_b, tree_a):
            for name, sec in run(tree).items():
                best[tree][name] = min(best[tree].get(name, float("inf")), sec)
    print(f"{rounds} alternated rounds, each the min of {repeat} repeats, {n_ics} ICs; "
          f"CPU seconds")
    print(f"{'driver':22s} {'A':>9s} {'B':>9s} {'B / A':>7s}")
    for name in best[tree_a]:
        a, b = best[tree_a][name], best[tree_b][name]
        print(f"{name:22s} {a:9.4f} {b:9.4f} {b / a:7.3f}")
    print(f"A = {tree_a}, B = {tree_b}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ics", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--compare", nargs=2, metavar=("A", "B"))
    ap.add_argument("--json", action="store_true", help="print the timings as one JSON line")
    args = ap.parse_args()
    if args.compare:
        compare(*args.compare, args.rounds, args.n_ics, args.repeat)
        return
    best = measure(args.n_ics, args.repeat)
    if args.json:
        print(json.dumps(best))
        return
    for name, sec in best.items():
        print(f"{name:22s} {sec:9.4f} s")


if __name__ == "__main__":
    main()
