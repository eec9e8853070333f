"""Time to generate 10^6 kick times with kicktimes.schedules, against same-run references.

References measured in the same run:
* floor: ``rng.exponential(size=n).cumsum()`` -- one numpy draw and one cumsum, no checks;
* loop: the plain Python loop a user would write (one interval drawn per iteration, as
  ``t += dist.rvs(random_state=rng)``), timed over 10^4 kicks (30 for the pdf-only family)
  and scaled to the kick count of the row.

Run: ``python benchmarks/bench_schedules.py``
"""

from __future__ import annotations

import os
import pickle
import sys

import numpy as np
import scipy.stats as st

from kicktimes import schedules

sys.path.insert(0, os.path.dirname(__file__))
import _timing  # noqa: E402

N_KICKS = 10**6
N_LOOP = 10**4
REPEATS = 5


class _Hyperexp(st.rv_continuous):
    """Two-phase hyperexponential defined by its pdf only (scipy's generic, slow rvs)."""

    def _pdf(self, x):
        return 0.3 * np.exp(-x) + 0.7 * 5.0 * np.exp(-5.0 * x)


def best_time(func, repeats=REPEATS):
    return _timing.best_time(func, repeats)


def python_loop(draw_one, n, rng):
    """Kick times by the naive loop: one interval per iteration."""
    t, times = 0.0, []
    for _ in range(n):
        t += draw_one(rng)
        times.append(t)
    return np.array(times)


def main():
    rng = np.random.default_rng(0)
    boot = rng.exponential(size=5000)
    gamma = st.gamma(2.0, scale=0.5)
    weibull = st.weibull_min(1.5)
    hyper = _Hyperexp(a=0.0, name="hyperexp")()
    cases = [
        ("Poisson(1)", schedules.Poisson(1.0), lambda g: g.exponential(1.0)),
        ("Renewal(gamma)", schedules.Renewal(gamma), lambda g: gamma.rvs(random_state=g)),
        (
            "Renewal(weibull, stationary)",
            schedules.Renewal(weibull, stationary=True),
            lambda g: weibull.rvs(random_state=g),
        ),
        ("Bootstrap(5000 intervals)", schedules.Bootstrap(boot), lambda g: boot[g.integers(5000)]),
        (
            "Renewal(halfnorm, stationary)",  # generic equilibrium law: PINV set-up once
            schedules.Renewal(st.halfnorm(), stationary=True),
            lambda g: st.halfnorm.rvs(random_state=g),
        ),
        ("Renewal(lomax(0.8)) inf. mean", schedules.Renewal(st.lomax(0.8)), None),
        # scipy's generic rvs root-finds a quadrature CDF per draw: loop over only 30 draws
        (
            "Renewal(pdf-only hyperexp)",
            schedules.Renewal(hyper),
            lambda g: hyper.rvs(random_state=g),
        ),
    ]

    floor = best_time(lambda: rng.exponential(size=N_KICKS).cumsum())
    print(f"kick times per sample: ~{N_KICKS:.0e}; best of {REPEATS}; 2-core shared machine")
    print(f"floor  rng.exponential(size=n).cumsum(): {floor * 1e3:.2f} ms\n")
    header = f"{'schedule':32s} {'kicks':>9s} {'ms':>8s} {'ns/kick':>8s} {'/floor':>7s}"
    print(header + f" {'loop ms (scaled)':>17s} {'speed-up':>9s}")
    for name, schedule, draw_one in cases:
        mean = schedule.mean_interval
        t_max = N_KICKS * mean if np.isfinite(mean) else 1.5e8  # lomax(0.8): N(t) ~ t^0.8
        schedule.sample(1.0, rng=rng)  # set up cached samplers (PINV tables) outside the timing
        # a pickled copy has no cached sampler: its first sample() pays the set-up
        setup = best_time(lambda s=schedule: pickle.loads(pickle.dumps(s)).sample(1.0, rng=0), 1)
        n = schedule.sample(t_max, rng=rng).size
        elapsed = best_time(lambda s=schedule, t=t_max: s.sample(t, rng=rng))
        row = f"{name:32s} {n:9d} {elapsed * 1e3:8.2f} {elapsed / n * 1e9:8.1f}"
        row += f" {elapsed / floor * N_KICKS / n:7.2f}"
        if draw_one is not None:
            m = 30 if "pdf-only" in name else N_LOOP
            loop = best_time(lambda d=draw_one, m=m: python_loop(d, m, rng), 1) * n / m
            row += f" {loop * 1e3:17.0f} {loop / elapsed:9.0f}"
        else:
            row += f" {'-':>17s} {'-':>9s}"
        print(row + f"   (first-call setup {setup * 1e3:.0f} ms)")

    # per-IC cost in an ensemble: many short samples (~1000 kicks each)
    print("\nper sample() call with ~1000 kicks (an IC of a sweep):")
    for name, schedule, _ in cases[:5]:
        t_max = 1000 * schedule.mean_interval
        per_call = best_time(lambda s=schedule, t=t_max: [s.sample(t, rng=rng) for _ in range(200)])
        print(f"  {name:32s} {per_call / 200 * 1e6:8.1f} us")


if __name__ == "__main__":
    main()
