"""Speed of the statistics layer (kicktimes.stats).

Run: ``python benchmarks/bench_stats.py [--n 100000] [--sequences 1000] [--events 100]
[--part all|fits|compare|poisson]``

1. Fit every renewal model to 10^5 right-censored intervals (with standard errors),
   and the full AIC comparison; reference: scipy's plain, uncensored
   ``expon.fit`` / ``weibull_min.fit`` with ``floc=0`` on the same data, same run.
2. ``compare_models`` (6 full-sample models, no standard errors) on 50 / 2000 / 10^5
   exponential intervals with 2 % right-censored ones: the dedicated optimisers
   against the former scipy path (``scipy.stats.<dist>.fit`` on CensoredData, EM
   hyperexponential; ``engine="scipy"``), same data, same run.
3. The Poisson test battery on an ensemble of 1000 sequences of about 100 events;
   reference: a plain loop of ``scipy.stats.kstest`` (uniformity only, one test of
   seven) over the same sequences, same run. Then where the tests should run: 200 of
   the sequences as one ensemble (what the report does per radius: equal event counts
   share a Monte Carlo null) against one `test_poisson` per sequence (what a sweep task
   would do, each IC with its own null and stream), n_mc = 199, same run. Last, the
   Ljung-Box statistic of the Monte Carlo nulls: the compiled kernel against the numpy
   expression it replaced (checked bitwise equal), alternating.
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import time
import warnings
from unittest import mock

import numpy as np
import scipy.stats

from kicktimes import stats
from kicktimes.stats import comparison, iid_tests
from kicktimes.stats.renewal import _fit

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
from _references import ljung_box_numpy  # noqa: E402


def timed(fun, repeat=1):
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - start)
    return best, out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100_000, help="intervals to fit")
    parser.add_argument("--sequences", type=int, default=1000, help="ensemble size")
    parser.add_argument("--events", type=float, default=100.0, help="mean events per sequence")
    parser.add_argument(
        "--part",
        choices=("all", "fits", "compare", "poisson"),
        default="all",
        help="run only one part",
    )
    args = parser.parse_args()
    rng = np.random.default_rng(2024)
    if args.part in ("all", "fits"):
        bench_fits(args, rng)
    if args.part in ("all", "compare"):
        bench_compare(rng)
    if args.part in ("all", "poisson"):
        bench_poisson(args, rng)


def bench_fits(args, rng):
    law = scipy.stats.weibull_min(0.7, scale=1.0)
    truth = law.rvs(args.n, random_state=rng)
    cens_time = rng.exponential(8.0, args.n)
    x, c = truth[truth <= cens_time], cens_time[truth > cens_time]
    # Warm up numba (power-law scan) and scipy once, outside the timings.
    stats.fit_renewal(x[:2000], "powerlaw", censored=c[:200])
    ref_expon, _ = timed(lambda: scipy.stats.expon.fit(truth, floc=0), repeat=3)
    ref_weib, _ = timed(lambda: scipy.stats.weibull_min.fit(truth, floc=0), repeat=3)
    print(f"renewal fits: {x.size} complete + {c.size} censored intervals (Weibull 0.7)")
    print(f"  reference scipy expon.fit (uncensored, floc=0)        {ref_expon:8.3f} s")
    print(f"  reference scipy weibull_min.fit (uncensored, floc=0)  {ref_weib:8.3f} s")
    print(f"  {'model':<18}{'fit + stderr (s)':>18}{'x weibull ref':>15}")
    total = 0.0
    for model in stats.MODELS:
        sec, fit = timed(lambda m=model: stats.fit_renewal(x, m, censored=c))
        total += sec
        print(f"  {model:<18}{sec:>18.3f}{sec / ref_weib:>15.1f}")
    print(f"  {'all models':<18}{total:>18.3f}{total / ref_weib:>15.1f}")
    sec, table = timed(lambda: stats.compare_models(x, censored=c))
    print(
        f"  compare_models (6 full-sample models, no stderr): {sec:.3f} s; best = {table.index[0]}"
    )


def bench_compare(rng):
    # Warm up numba (hyperexponential kernel) and scipy once, outside the timings.
    stats.compare_models(rng.exponential(1.0, 100))
    print()
    print("compare_models, 6 models, exponential intervals + 2 % censored: new vs scipy path")
    print(
        f"  {'intervals':>10}{'scipy path (s)':>16}{'new (s)':>10}{'speed-up':>10}{'max dll':>10}"
    )
    scipy_path = functools.partial(_fit, engine="scipy")
    for n in (50, 2000, 100_000):
        xe = rng.exponential(1.0, n)
        ce = rng.uniform(0.0, 2.0, max(1, n // 50))
        repeat = 1 if n > 10_000 else 5
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", stats.FitWarning)
            new_sec, new = timed(lambda x=xe, c=ce: stats.compare_models(x, censored=c), repeat)
            with mock.patch.object(comparison, "_fit", scipy_path):
                old_sec, old = timed(lambda x=xe, c=ce: stats.compare_models(x, censored=c), repeat)
        dll = (new["loglik"] - old.loc[new.index, "loglik"]).abs().max()
        print(f"  {n:>10}{old_sec:>16.3f}{new_sec:>10.3f}{old_sec / new_sec:>9.1f}x{dll:>10.1e}")


def bench_poisson(args, rng):
    t_window = args.events
    seqs = [
        np.sort(rng.uniform(0, t_window, rng.poisson(args.events))) for _ in range(args.sequences)
    ]

    def reference():
        return [scipy.stats.kstest(s / t_window, "uniform").pvalue for s in seqs]

    ref_sec, _ = timed(reference)
    sec, ens = timed(lambda: stats.test_poisson_ensemble(seqs, t_window, rng=1))
    one, _ = timed(lambda: stats.test_poisson(seqs[0], t_window, rng=1), repeat=3)
    print()
    print(f"Poisson tests: {args.sequences} sequences of ~{args.events:.0f} events, n_mc = 999")
    print(f"  reference loop of scipy.stats.kstest (1 test)  {ref_sec:8.3f} s")
    print(f"  test_poisson_ensemble (7 tests, FDR, combine)  {sec:8.3f} s   x{sec / ref_sec:.1f}")
    print(f"  test_poisson, one sequence                     {one:8.3f} s")
    flagged = int(ens.reject.to_numpy().sum())
    print(f"  FDR rejections on these Poisson sequences (8 BH families): {flagged}")
    # Where the tests should run: the report tests each radius's ICs as one ensemble
    # (sequences with equal event counts share one Monte Carlo null); a sweep task would
    # test its ICs one by one, each with its own null (its own stream, so that the
    # p-values do not depend on the block size). Same sequences, the report's n_mc = 199.
    part = seqs[: min(len(seqs), 200)]
    ens_sec, _ = timed(lambda: stats.test_poisson_ensemble(part, t_window, n_mc=199, rng=1))
    loop_sec, _ = timed(
        lambda: [stats.test_poisson(s, t_window, n_mc=199, rng=k) for k, s in enumerate(part)]
    )
    print(f"  per IC or per ensemble ({len(part)} sequences, n_mc = 199):")
    print(f"    one ensemble (the report)                    {ens_sec:8.3f} s")
    print(
        f"    one test per sequence (in sweep tasks)       {loop_sec:8.3f} s   "
        f"x{loop_sec / ens_sec:.1f}"
    )
    bench_ljung_box(rng)


def bench_ljung_box(rng, rounds=7):
    """The Ljung-Box Monte Carlo null's statistic (199 rows of m Exp(1) intervals, 10
    lags): the compiled kernel against the numpy expression it replaced, checked bitwise
    equal, alternating, min of ``rounds``."""
    print("  Ljung-Box Q of a Monte Carlo null (199 rows, 10 lags), min of "
          f"{rounds} alternating rounds:")
    print(f"  {'m':>8}{'numpy ms':>10}{'kernel ms':>11}{'ratio':>8}")
    for m in (30, 60, 120, 250, 1000):
        x = rng.standard_exponential((199, m))
        if not np.array_equal(iid_tests.ljung_box(x, 10), ljung_box_numpy(x, 10)):
            raise AssertionError(f"ljung_box differs from the numpy expression at m = {m}")
        old = new = np.inf
        for _ in range(rounds):
            old = min(old, timed(functools.partial(ljung_box_numpy, x, 10), repeat=5)[0])
            new = min(new, timed(functools.partial(iid_tests.ljung_box, x, 10), repeat=5)[0])
        print(f"  {m:>8}{old * 1e3:>10.3f}{new * 1e3:>11.3f}{old / new:>7.2f}x")


if __name__ == "__main__":
    main()
