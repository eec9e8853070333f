"""Speed of the sweep's autocorrelation stage (boundary angles, the curve R_1..R_20).

Run: ``python benchmarks/bench_autocorrelation.py [--ics 5] [--repeat 5]``

Input: the boundary logs of paper-sampled two-disk runs (family B: r = 0.016, 15 000
collision-truncated steps of tau = 0.3, about 2 400 boundary collisions of the tracked
disk), the stage a sweep task times as "autocorrelation".

1. The curve's kernel (what ``autocorrelation_function(theta, 20)`` calls after its
   input checks); references in the same run: the previous kernel (one compiled call;
   per lag, the blocked sums of `autocorrelation` from the series: centring again and
   the sum of squares again), which the curve
   equals bitwise (checked here), and ``statsmodels``' ``acf`` (``fft=False``,
   ``adjusted=False``; equal to 1e-12).
2. The whole stage, ``autocorrelation_rows(boundary_angles(run, 0), 1, 20)``; reference:
   the stage as it was (angles selected by boolean masks and checked by four numpy
   passes, ``R_1`` by its own call, the curve by the previous kernel), same rows.
3. ``boundary_angles(run, 0)`` of the two-disk log alone against the masked selection.

Times are the best of ``--repeat`` rounds of 100 calls per run, in microseconds per call.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from numba import njit
from statsmodels.tsa.stattools import acf

from kicktimes import initial_conditions, simulate_two_particle
from kicktimes.diagnostics import (
    UndefinedDiagnosticWarning,
    autocorrelation,
    autocorrelation_function,
    boundary_angles,
    decorrelation_lag,
    integrated_autocorrelation_time,
)
from kicktimes.diagnostics.autocorrelation import _centred_sums, _is_constant, _prepare
from kicktimes.diagnostics.decorrelation import _curve
from kicktimes.experiment.tasks import autocorrelation_rows


@njit(cache=True)
def _previous_curve(values, max_lag, rtol, atol, out):
    # the curve kernel before the shared sums of squares (this release's reference)
    n = values.shape[0]
    lo = np.int64(0)
    mean, f, scale = _prepare(values, lo, n)
    for lag in range(1, max_lag + 1):
        if n <= lag:
            out[lag - 1] = np.nan
            continue
        den, num = _centred_sums(values, lo, n, lag, mean, f)
        out[lag - 1] = np.nan if _is_constant(den, n, f, scale, rtol, atol) else num / den


def previous_curve(theta, max_lag):
    out = np.empty(max_lag)
    _previous_curve(theta, max_lag, 1e-9, 1e-9, out)
    return out


def per_call_us(fun, items, repeat):
    best = np.inf
    for item in items:  # compile and warm up
        fun(item)
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(100):
            for item in items:
                fun(item)
        best = min(best, (time.perf_counter() - start) / (100 * len(items)))
    return best * 1e6


def masked_angles(run):
    log = run.boundary_log
    mask = log.particle == 0
    sin_theta, times = log.sin_theta[mask], log.time[mask]
    assert (times[1:] >= times[:-1]).all() and np.isfinite(sin_theta).all()
    assert np.abs(sin_theta).max() <= 1.0 + 1e-9
    return np.arcsin(np.clip(sin_theta, -1.0, 1.0))


def previous_rows(run):
    theta = masked_angles(run)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UndefinedDiagnosticWarning)
        value = autocorrelation(theta, 1)
    value, reason = float(value), value.reason
    rows = [("autocorrelation", value, reason or "")]
    curve = previous_curve(theta, 20)
    rows += [(f"acf@{k + 1}", v, "") for k, v in enumerate(curve)]
    rows.append(("decorrelation_lag", *decorrelation_lag(curve, return_reason=True)))
    rows.append(("tau_int", *integrated_autocorrelation_time(curve, return_reason=True)))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ics", type=int, default=5, help="runs (paper ICs of family B)")
    parser.add_argument("--repeat", type=int, default=5, help="rounds; the best is kept")
    args = parser.parse_args()
    ics = initial_conditions(args.ics, 0.026, method="paper", rng=2)
    runs = [
        simulate_two_particle(ic, 0.016, n_steps=15000, tau=0.3, sampling="paper", track=0,
                              rule="mirror")
        for ic in ics
    ]
    thetas = [boundary_angles(run, particle=0) for run in runs]
    for theta in thetas:
        curve = autocorrelation_function(theta, 20)
        assert np.array_equal(curve, previous_curve(theta, 20))
        assert np.array_equal(curve, [autocorrelation(theta, lag) for lag in range(1, 21)])
        np.testing.assert_allclose(curve, acf(theta, nlags=20, fft=False)[1:], atol=1e-12)
    sizes = [theta.size for theta in thetas]
    print(f"{len(runs)} runs, {min(sizes)}-{max(sizes)} boundary angles of the tracked disk")

    curve_us = per_call_us(lambda t: _curve(t, 20), thetas, args.repeat)
    lags_us = per_call_us(lambda t: previous_curve(t, 20), thetas, args.repeat)
    sm_us = per_call_us(lambda t: acf(t, nlags=20, fft=False), thetas, args.repeat)
    print("1. the curve R_1..R_20, kernels (us per series)")
    print(f"   this release:             {curve_us:7.1f}")
    print(f"   previous kernel:          {lags_us:7.1f}  -> {lags_us / curve_us:.2f}x")
    print(f"   statsmodels acf:          {sm_us:7.1f}  -> {sm_us / curve_us:.2f}x")

    for run in runs:
        got = autocorrelation_rows(boundary_angles(run, particle=0), 1, 20)
        ref = previous_rows(run)
        assert [r[:2] for r in got] == [r[:2] for r in ref]
    stage_us = per_call_us(lambda r: autocorrelation_rows(boundary_angles(r, particle=0), 1, 20),
                           runs, args.repeat)
    ref_us = per_call_us(previous_rows, runs, args.repeat)
    print("2. the sweep's stage: angles + rows (us per run)")
    print(f"   one curve, one-pass angles: {stage_us:7.1f}")
    print(f"   as it was (reference):      {ref_us:7.1f}  -> {ref_us / stage_us:.2f}x")
    for run in runs:
        assert np.array_equal(boundary_angles(run, particle=0), masked_angles(run))
    angles_us = per_call_us(lambda r: boundary_angles(r, particle=0), runs, args.repeat)
    masked_us = per_call_us(masked_angles, runs, args.repeat)
    n_log = [run.boundary_log.time.size for run in runs]
    print(f"3. boundary angles of a {min(n_log)}-{max(n_log)} row two-disk log (us per run)")
    print(f"   one-pass selection:         {angles_us:7.1f}")
    print(f"   boolean masks (reference):  {masked_us:7.1f}  -> {masked_us / angles_us:.2f}x")


if __name__ == "__main__":
    main()
