"""Speed of the billiard simulators and of the FTLE, against references in the same run.

Workload (issue 2): r = 0.01, tau = 0.3, 15 000 uniform samples, 200 paper-procedure ICs,
one `simulate_two_particle` call per IC as a user would make it. Reference: the paper's
time-stepped algorithm in plain NumPy (benchmarks/paper_timestep.py) on a few of the same
ICs, scaled per trajectory. Also: the Poisson-kicked one-disk billiard on the same
workload, and the FTLE cost (default tangent method; see bench_lyapunov.py for both
methods) relative to the bare simulation.

Issue 13: the same two-disk workload against a C loop producing the same output
(benchmarks/c_reference/two_disk.c: boundary log, disk-disk times, samples, fresh malloc'd
arrays per IC), built with ``cc -O2`` and called through ctypes; its output is checked to
equal the kernel's before timing. Those rows use CPU time (``time.process_time``), the
minimum of interleaved repeats: the machine is shared, and wall time counts the waits.

Run: python benchmarks/bench_simulators.py [--n-ics 200] [--c-only]
"""

import argparse
import os
import sys
import time

import numpy as np

from kicktimes.diagnostics import Tangent

sys.path.insert(0, os.path.dirname(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "c_reference"))
from paper_timestep import paper_timestep  # noqa: E402
from two_disk import load as load_c_reference  # noqa: E402

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.diagnostics import lyapunov


def best_of(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def check_c_matches(c_ref, r, tau, n_steps):
    """The C loop's output equals simulate_two_particle's (both rules and samplings)."""
    for rule in ("mirror", "elastic"):
        for sampling in ("uniform", "paper"):
            method = "paper" if rule == "mirror" else "uniform"
            for ic in initial_conditions(3, r, rng=7, method=method, rule=rule):
                run = simulate_two_particle(ic, r, rule=rule, sampling=sampling,
                                            n_steps=n_steps, tau=tau)
                out = c_ref.run(ic, r, rule=rule, sampling=sampling, n_steps=n_steps, tau=tau)
                log = run.boundary_log
                assert out["status"] == 0
                assert out["pp_times"].shape == run.pp_times.shape, (rule, sampling)
                assert out["time"].shape == log.time.shape, (rule, sampling)
                assert (out["particle"] == log.particle).all()
                for a, b in ((out["pp_times"], run.pp_times), (out["time"], log.time),
                             (out["x"], log.x), (out["y"], log.y),
                             (out["sin_theta"], log.sin_theta),
                             (out["sample_times"], run.sample_times),
                             (out["samples"], run.samples)):
                    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def compare_with_c(ics, r, tau, n_steps, repeat=15):
    """CPU seconds of (simulate_two_particle, the bare kernel, the C loop) over ``ics``,
    minima of ``repeat`` interleaved rounds; None if no C compiler."""
    from kicktimes.billiard.kernels.drive_two import simulate_two_kernel

    c_ref, why = load_c_reference()
    if c_ref is None:
        print(f"C reference skipped: {why}")
        return None
    check_c_matches(c_ref, r, tau, min(n_steps, 3000))
    prepared = c_ref.prepare_many(ics, r, n_steps=n_steps, tau=tau)
    st0, n_ics, rho, sigma, rule, t_max, mode, *_ = prepared
    pp_cap, b_cap, max_events, stall_dt = prepared[-4:]

    def api():
        for ic in ics:
            simulate_two_particle(ic, r, n_steps=n_steps, tau=tau)

    def kernel():
        # the kernel on the wrapper's arguments: what the Python layer costs on top
        for i in range(n_ics):
            simulate_two_kernel(st0[i].copy(), (rho, rho, 1.0, 1.0), sigma, rule, t_max, mode,
                                n_steps, tau, 0,
                                int(pp_cap[i]), int(b_cap[i]), int(max_events[i]),
                                float(stall_dt[i]), False)

    def c_loop():
        c_ref.run_many(prepared)

    best = {"api": float("inf"), "kernel": float("inf"), "c": float("inf")}
    for _ in range(repeat):
        for name, fn in (("api", api), ("kernel", kernel), ("c", c_loop)):
            t0 = time.process_time()
            fn()
            best[name] = min(best[name], time.process_time() - t0)
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ics", type=int, default=200)
    ap.add_argument("--n-ref", type=int, default=3, help="ICs for the slow NumPy reference")
    ap.add_argument("--c-only", action="store_true", help="only the comparison with the C loop")
    args = ap.parse_args()
    r, tau, n_steps = 0.01, 0.3, 15000
    ics = initial_conditions(args.n_ics, r, rng=2026, method="paper")
    simulate_two_particle(ics[0], r, n_steps=10, tau=tau)
    c_times = compare_with_c(ics, r, tau, n_steps)
    if c_times is not None:
        ms = 1e3 / args.n_ics
        c = c_times["c"]
        print(f"issue 13 workload: r={r}, tau={tau}, n_steps={n_steps}, {args.n_ics} paper ICs; "
              "CPU time, min of 15 interleaved rounds")
        print(f"{'what':46s} {'ms/IC':>9s} {'C / this':>9s}")
        print(f"{'C loop, same output (cc -O2, fresh arrays)':46s} {c * ms:9.4f} {1.0:9.3f}")
        print(f"{'simulate_two_kernel (numba, no Python layer)':46s} "
              f"{c_times['kernel'] * ms:9.4f} {c / c_times['kernel']:9.3f}")
        print(f"{'simulate_two_particle, one call per IC':46s} {c_times['api'] * ms:9.4f} "
              f"{c / c_times['api']:9.3f}   (goal >= 0.8)")
    if args.c_only:
        return

    # warm-up: compile (or load from the numba cache)
    simulate_two_particle(ics[0], r, n_steps=10, tau=tau)
    simulate_one_particle(ics[0, 0], r, n_steps=10, tau=tau, kicks=[0.1], rng=0)
    lyapunov(ics[0], r, n_steps=10, tau=tau)
    lyapunov(ics[0, 0], r, n_steps=10, tau=tau, kicks=[0.1], rng=0)

    def two():
        return [simulate_two_particle(ic, r, n_steps=n_steps, tau=tau) for ic in ics]

    t_two, runs = best_of(two)
    events = sum(run.n_pp + run.n_boundary for run in runs)

    def two_streamed():
        # as a sweep uses it: each run is reduced and dropped, so memory is reused
        return sum(simulate_two_particle(ic, r, n_steps=n_steps, tau=tau).n_pp for ic in ics)

    t_stream, _ = best_of(two_streamed)
    rates = [schedules.Poisson.from_run(run) for run in runs]

    def one():
        return [simulate_one_particle(ic[0], r, n_steps=n_steps, tau=tau, kicks=rate, rng=i)
                for i, (ic, rate) in enumerate(zip(ics, rates, strict=True))]

    t_one, ones = best_of(one)
    events_one = sum(run.n_boundary + run.n_kicks for run in ones)

    n_ftle = min(50, args.n_ics)
    t_ftle_norm, _ = best_of(lambda: [lyapunov(ic, r, n_steps=n_steps, tau=tau)
                                      for ic in ics[:n_ftle]], repeat=1)
    t_ftle_paper, _ = best_of(lambda: [lyapunov(ic, r, n_steps=n_steps, tau=tau,
                                                method=Tangent(variant="paper"))
                                       for ic in ics[:n_ftle]], repeat=1)
    t_ftle_one, _ = best_of(lambda: [lyapunov(o) for o in ones[:n_ftle]], repeat=1)

    t0 = time.perf_counter()
    for ic in ics[: args.n_ref]:
        paper_timestep(ic, r, n_steps, tau)
    t_ref = (time.perf_counter() - t0) / args.n_ref
    # the paper-sampled kicktimes run does the same steps: compare like with like
    t_paper_mode, _ = best_of(lambda: [simulate_two_particle(ic, r, n_steps=n_steps, tau=tau,
                                                             sampling="paper")
                                       for ic in ics[: args.n_ref]])
    t_paper_mode /= args.n_ref

    ms = 1e3 / args.n_ics
    print(f"workload: r={r}, tau={tau}, n_steps={n_steps}, {args.n_ics} paper ICs, "
          f"{os.cpu_count()} cores (one used)")
    print(f"{'what':46s} {'ms/traj':>9s} {'events/s':>12s} {'ratio':>8s}")
    print(f"{'simulate_two_particle, runs dropped (sweep)':46s} {t_stream * ms:9.3f} "
          f"{events / t_stream:12.3e} {t_stream / t_two:8.2f}")
    print(f"{'simulate_two_particle, all 200 runs kept':46s} {t_two * ms:9.3f} "
          f"{events / t_two:12.3e} {'1':>8s}")
    print(f"{'simulate_one_particle (Poisson kicks)':46s} {t_one * ms:9.3f} "
          f"{events_one / t_one:12.3e} {t_one / t_two:8.2f}")
    per = 1e3 / n_ftle
    print(f"{'lyapunov two-particle, norm (tangent)':46s} {t_ftle_norm * per:9.3f} "
          f"{'':12s} {t_ftle_norm / n_ftle / (t_two / args.n_ics):8.2f}")
    print(f"{'lyapunov two-particle, paper (tangent)':46s} {t_ftle_paper * per:9.3f} "
          f"{'':12s} {t_ftle_paper / n_ftle / (t_two / args.n_ics):8.2f}")
    print(f"{'lyapunov one-particle, norm (tangent)':46s} {t_ftle_one * per:9.3f} "
          f"{'':12s} {t_ftle_one / n_ftle / (t_one / args.n_ics):8.2f} (vs one-particle sim)")
    print(f"{'simulate_two_particle (paper sampling)':46s} {t_paper_mode * 1e3:9.3f}")
    print(f"{'paper time-stepped algorithm, plain NumPy':46s} {t_ref * 1e3:9.3f} {'':12s} "
          f"{t_ref / t_paper_mode:8.0f}x slower than kicktimes (same steps)")
    print(f"mean events per trajectory: {events / args.n_ics:.0f}; "
          f"mean disk-disk collisions: {np.mean([run.n_pp for run in runs]):.1f}")


if __name__ == "__main__":
    main()
