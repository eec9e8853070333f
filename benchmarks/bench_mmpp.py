"""Speed of the MMPP fit (kicktimes.stats.fit_mmpp; issue 30, item 5).

Run: ``python benchmarks/bench_mmpp.py [--windows 1000] [--events 100] [--starts 8]
[--repeats 3] [--subset 10]``

Data: an MMPP-2 (rates 0.5 and 5, switching rates 0.1 and 0.3, stationary rate 1.625),
``--windows`` windows of length ``--events / 1.625`` (about ``--events`` events each).

1. One E-step over all the windows: the compiled forward-backward pass
   (``kicktimes.stats.mmpp._estep.estep``) against the plain NumPy/scipy implementation of
   the same recursions (``estep_reference``: one ``scipy.linalg.expm`` of the 2n x 2n Van
   Loan block matrix per interval), timed on the first ``--subset`` windows and scaled
   to all of them by their number of intervals; the two are checked equal.
2. The whole fit, ``fit_mmpp(times, t_max, n_starts=--starts)`` with its standard
   errors, minimum of ``--repeats`` (wall clock; the kernels run on one core), and the
   intervals its E-steps processed: what the reference E-step would take for them.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from unittest import mock

import numpy as np

from kicktimes import stats
from kicktimes.stats.mmpp import _em as em

sys.path.insert(0, os.path.dirname(__file__))
from _timing import best_time  # noqa: E402

RATES = np.array([0.5, 5.0])
Q = np.array([[-0.1, 0.1], [0.3, -0.3]])
STATIONARY_RATE = 0.75 * 0.5 + 0.25 * 5.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=1000)
    parser.add_argument("--events", type=float, default=100.0, help="mean events per window")
    parser.add_argument("--starts", type=int, default=8, help="n_starts of fit_mmpp")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--subset", type=int, default=10, help="windows of the reference")
    args = parser.parse_args()
    t_max = args.events / STATIONARY_RATE
    times = stats.simulate_mmpp(RATES, Q, t_max, n_windows=args.windows, rng=2024)
    data = em.Windows.of(times, np.full(args.windows, t_max))
    part = data.subset(np.arange(args.subset))
    theta = (RATES * data.unit, Q * data.unit, em.stationary_law(Q))
    print(f"MMPP-2 data: {args.windows} windows of length {t_max:.4g}, "
          f"{int(data.n_events.sum())} events, {data.x.size} intervals (censored ends "
          f"included); {os.cpu_count()} cores")

    # 1. one E-step
    fast = em.estep(*theta, part)  # compiles on a cold cache
    ref = em.estep_reference(*theta, part)
    worst = max(float(np.max(np.abs(getattr(fast, f) - getattr(ref, f))
                             / np.maximum(1.0, np.abs(getattr(ref, f)))))
                for f in ("loglik", "time", "transitions", "events", "init"))
    if worst > 1e-9:
        raise AssertionError(f"compiled and reference E-steps differ by {worst:.2e}")
    kernel = best_time(lambda: em.estep(*theta, data), repeats=5)
    ref_part = best_time(lambda: em.estep_reference(*theta, part), repeats=args.repeats)
    per_interval = ref_part / part.x.size
    reference = per_interval * data.x.size
    print("one E-step over all windows:")
    print(f"  reference (numpy + scipy.linalg.expm, {args.subset} windows, scaled)"
          f" {reference:9.3f} s")
    print(f"  compiled forward-backward                                   {kernel:9.4f} s"
          f"   x{reference / kernel:.0f} faster; max relative difference {worst:.1e}")

    # 2. the whole fit
    processed = []
    estep = em.estep

    def counting(*a, **k):
        processed.append(a[3].x.size)
        return estep(*a, **k)

    with mock.patch.object(em, "estep", counting):
        fit = stats.fit_mmpp(times, t_max, n_starts=args.starts, rng=1)
    sec = best_time(lambda: stats.fit_mmpp(times, t_max, n_starts=args.starts, rng=1),
                    repeats=args.repeats)
    intervals = sum(processed)
    print(f"fit_mmpp(n_starts={args.starts}), standard errors included, min of "
          f"{args.repeats}:  {sec:.3f} s   (goal: <= 2 s)")
    slow = per_interval * intervals
    print(f"  {len(processed)} E-steps over {intervals} intervals "
          f"({intervals / data.x.size:.1f} passes over the data); the reference E-step "
          f"would take {slow:.0f} s for them (x{slow / sec:.0f})")
    errors = np.concatenate([fit.rates / RATES - 1,
                             fit.generator[[0, 1], [1, 0]] / Q[[0, 1], [1, 0]] - 1])
    print(f"  rates {np.round(fit.rates, 4)}, switching rates "
          f"{np.round(fit.generator[[0, 1], [1, 0]], 4)}: largest relative error "
          f"{np.abs(errors).max():.3f}; n_iter {fit.n_iter}, converged {fit.converged}")
    if not math.isfinite(fit.loglik):
        raise AssertionError("the fit's log-likelihood is not finite")


if __name__ == "__main__":
    main()
