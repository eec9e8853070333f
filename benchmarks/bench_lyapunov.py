"""Cost of the FTLE (tangent and twin methods) relative to the bare simulation.

Workload (as benchmarks/bench_simulators.py): r = 0.01, tau = 0.3, 15 000 uniform samples,
paper-procedure ICs. References, timed in the same run on the same trajectories:
`simulate_two_particle` (for the two-disk FTLE) and `simulate_one_particle` with Poisson
kicks at each IC's own collision rate (for the kicked FTLE, on the very runs it computes).
Each trajectory's calls are timed back to back, each the best of ``--repeat``.

``--one-pass``: the sweep's physics per IC on the paper's workload (family_b, r = 0.01,
15000 collision-truncated steps of 0.3, variant "paper", all five systems): the separate
calls the sweep made before the one pass (simulation, then the FTLE re-simulating it, then
the two-disk run again to the horizon for the actual kick times; per kicked system a
simulation and an FTLE), against the one pass (`lyapunov_pass` and
``lyapunov(..., method=Tangent(return_run=True))``), in the same run, interleaved per IC.
Both compute the same numbers (checked). Also timed: the whole sweep task of one IC
(`execute_task`, with the recurrence and autocorrelation diagnostics, which the one pass
does not change).

Run: python benchmarks/bench_lyapunov.py [--n-ics 100] [--repeat 3]
     python benchmarks/bench_lyapunov.py --one-pass [--n-ics 20] [--repeat 3]
"""

import argparse
import os
import time

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.billiard import KickLaw
from kicktimes.diagnostics import Tangent, Twin, lyapunov


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


def one_pass(n_ics, repeat):
    """Per IC: the sweep's simulations and FTLEs as separate calls vs one pass."""
    import numpy as np

    from kicktimes.billiard.one_particle import draw_kick_angles
    from kicktimes.diagnostics.lyapunov import lyapunov_pass
    from kicktimes.experiment import Task, execute_task, kick_rng, preset
    from kicktimes.experiment.tasks import _actual_times, kick_law

    exp = preset("family_b")
    r = 0.01
    ri = exp.radii.index(r)
    ics = initial_conditions(n_ics, exp.r_max, rng=exp.seed, method=exp.ic_method,
                             rule=exp.rule)
    steps = {"n_steps": exp.n_steps, "tau": exp.tau, "sampling": exp.sampling}
    var = exp.lyapunov_variant
    kicked = [s for s in exp.systems if s != "two_particle"]

    def kicks(i, system, two, actual):
        rng = kick_rng(i, r, system, rng=exp.seed)
        kick = kick_law(exp, system, ics[i])
        if system.startswith("poisson"):
            times = schedules.Poisson(two.n_pp / two.t_max).sample(exp.horizon, rng=rng)
        else:
            times = actual
        angles = draw_kick_angles(times.size, kick.angle, exp.sigma, rng)
        return kick.replace(times=times, angles=angles)

    def separate(i):
        ic = ics[i]
        two = simulate_two_particle(ic, r, rule=exp.rule, track=0, **steps)
        out = [lyapunov(ic, r, rule=exp.rule, track=0, method=Tangent(variant=var), **steps).lam]
        actual = _actual_times(exp, ic, r, two)
        for system in kicked:
            law = kicks(i, system, two, actual)
            one = simulate_one_particle(ic[0], r, kicks=law, **steps)
            out += [one.n_boundary,
                    lyapunov(ic[0], r, kicks=law, method=Tangent(variant=var), **steps).lam]
        return out + [two.n_pp, actual.size]

    def together(i):
        ic = ics[i]
        res, two, actual = lyapunov_pass(ic, r, rule=exp.rule, track=0,
                                         method=Tangent(variant=var), t_continue=exp.horizon,
                                         **steps)
        out = [res.lam]
        for system in kicked:
            law = kicks(i, system, two, np.array(actual, dtype=np.float64))
            res, one = lyapunov(ic[0], r, kicks=law, method=Tangent(variant=var, return_run=True),
                                **steps)
            out += [one.n_boundary, res.lam]
        return out + [two.n_pp, actual.size]

    def task(i):
        execute_task(exp, Task(ri, r, i, i + 1))

    for i in range(n_ics):
        # (repr: bitwise for floats, NaN equal to NaN)
        assert repr(separate(i)) == repr(together(i)), f"IC {i}: the one pass differs"
    task(0)  # compile / load the sweep's remaining kernels
    calls = {"separate calls (before)": separate, "one pass (now)": together,
             "sweep task of one IC (now, + RR, ACF)": task}
    totals = interleaved_min(calls, n_ics, repeat)
    ref = totals["separate calls (before)"]
    print(f"workload: family_b, r={r}, {exp.n_steps} paper steps of tau={exp.tau}, variant "
          f"{var!r}, {len(exp.systems)} systems, {n_ics} ICs, best of {repeat} per IC, "
          f"interleaved; {os.cpu_count()} cores (one used); same numbers checked")
    print(f"{'what':40s} {'ms/IC':>8s} {'ratio to separate calls':>25s}")
    for name, t in totals.items():
        print(f"{name:40s} {t * 1e3 / n_ics:8.2f} {t / ref:25.3f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ics", type=int, default=None, help="default 100 (20 with --one-pass)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--one-pass", action="store_true",
                    help="the sweep's per-IC physics: separate calls vs one pass")
    args = ap.parse_args()
    if args.one_pass:
        one_pass(args.n_ics or 20, args.repeat)
        return
    args.n_ics = args.n_ics or 100
    r, tau, n_steps = 0.01, 0.3, 15000
    ics = initial_conditions(args.n_ics, r, rng=2026, method="paper")

    # warm-up: compile (or load from the numba cache) every kernel timed below
    for method in ("tangent", "twin"):
        for variant in ("norm", "paper"):
            m = (Twin if method == "twin" else Tangent)(variant=variant)
            lyapunov(ics[0], r, n_steps=10, tau=tau, method=m)
            lyapunov(ics[0, 0], r, n_steps=10, tau=tau, kicks=[0.1], rng=0, method=m)
    simulate_one_particle(ics[0, 0], r, n_steps=10, tau=tau, kicks=[0.1], rng=0)

    runs = [simulate_two_particle(ic, r, n_steps=n_steps, tau=tau) for ic in ics]
    rates = [schedules.Poisson.from_run(run) for run in runs]
    ones = [simulate_one_particle(ic[0], r, n_steps=n_steps, tau=tau, kicks=rate, rng=i)
            for i, (ic, rate) in enumerate(zip(ics, rates, strict=True))]

    calls = {
        "simulate_two_particle": lambda i: simulate_two_particle(ics[i], r, n_steps=n_steps,
                                                                 tau=tau),
        "simulate_one_particle (Poisson kicks)": lambda i: simulate_one_particle(
            ones[i].ic, r, n_steps=n_steps, tau=tau, kicks=KickLaw(ones[i].kick_times,
                                                                   angles=ones[i].kick_angles)),
    }
    for method in ("tangent", "twin"):
        for variant in ("norm", "paper"):
            m = (Twin if method == "twin" else Tangent)(variant=variant)
            calls[f"lyapunov two-disk, {method}, {variant}"] = (
                lambda i, m=m: lyapunov(ics[i], r, n_steps=n_steps, tau=tau, method=m))
            calls[f"lyapunov kicked disk, {method}, {variant}"] = (
                lambda i, m=m: lyapunov(ones[i], method=m))
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
