"""Size and power of the single-sequence Poisson tests (kicktimes.stats.test_poisson).

Run: ``python analysis/size_power.py [--size-replicates 4000] [--replicates 1000]``
writes ``docs/size_power.md``: the rejection rate at alpha = 0.05 of every test

* under the null: homogeneous Poisson sequences with about 100 (and about 25)
  events in a fixed window;
* under alternatives with about 100 events and unit mean interval: renewal
  processes with Weibull(0.6), lognormal(sigma = 1, 1.5) and gamma(2) intervals,
  serially correlated intervals with exponential marginals (EAR(1), Gaver & Lewis)
  and with lognormal marginals (AR(1) on log-intervals), and a Markov-modulated
  Poisson process (two rates, slow switching).

Every process is stationary in the window: it starts ``BURN_IN`` time units before
0 and only events in ``[0, T]`` are kept. Each sequence is tested on its own; the
ensemble function is used only to run many sequences at once (its FDR refinement is
switched off with ``n_mc_max = n_mc``, so the p-values are those of test_poisson)
on chunks of ``CHUNK`` sequences.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
import scipy.stats

from kicktimes import stats

T = 100.0
BURN_IN = 100.0
ALPHA = 0.05
CHUNK = 250


def keep_window(t):
    t = t - BURN_IN
    return t[(t >= 0) & (t <= T)]


def poisson(rate, t_window):
    def make(rng):
        return np.sort(rng.uniform(0, t_window, rng.poisson(rate * t_window)))

    return make


def renewal(draw):
    """Stationary renewal process; ``draw(rng, size)`` gives unit-mean intervals."""

    def make(rng):
        n = int(3 * (T + BURN_IN)) + 100
        t = np.cumsum(draw(rng, n))
        assert t[-1] > T + BURN_IN
        return keep_window(t)

    return make


def ear1(rho):
    """EAR(1): X_k = rho X_{k-1} + B_k E_k, B_k ~ Bernoulli(1 - rho): Exp(1) marginals,
    lag-k autocorrelation rho**k."""

    def make(rng):
        return keep_window(np.cumsum(stats.ear1_intervals(int(3 * (T + BURN_IN)) + 100, rho,
                                                          rng=rng)))

    return make


def ar1_lognormal(phi, sigma):
    """log X_k Gaussian AR(1) with coefficient phi and marginal sd sigma, unit mean."""

    def make(rng):
        n = int(3 * (T + BURN_IN)) + 100
        z = np.empty(n)
        z[0] = rng.standard_normal() * sigma
        e = rng.standard_normal(n) * sigma * math.sqrt(1 - phi**2)
        for i in range(1, n):
            z[i] = phi * z[i - 1] + e[i]
        return keep_window(np.cumsum(np.exp(z - sigma**2 / 2)))

    return make


def mmpp(rates, switch_rate):
    """Markov-modulated Poisson process: the rate alternates between two values, with
    exponential sojourns of mean 1 / switch_rate; starts in its stationary state."""

    def make(rng):
        t, state, events = 0.0, int(rng.integers(2)), []
        while t < T + BURN_IN:
            end = t + rng.exponential(1 / switch_rate)
            count = rng.poisson(rates[state] * (end - t))
            events.append(rng.uniform(t, end, count))
            t, state = end, 1 - state
        return keep_window(np.sort(np.concatenate(events)))

    return make


def unit_mean(dist):
    return lambda rng, n: dist.rvs(size=n, random_state=rng) / dist.mean()


def scenarios():
    return {
        "Poisson, ~100 events (size)": poisson(1.0, T),
        "Poisson, ~25 events (size)": poisson(1.0, 25.0),
        "Weibull(0.6) renewal": renewal(unit_mean(scipy.stats.weibull_min(0.6))),
        "lognormal(sigma=1) renewal": renewal(unit_mean(scipy.stats.lognorm(1.0))),
        "lognormal(sigma=1.5) renewal": renewal(unit_mean(scipy.stats.lognorm(1.5))),
        "gamma(2) renewal (regular)": renewal(unit_mean(scipy.stats.gamma(2.0))),
        "EAR(1) rho=0.6, Exp(1) marginals": ear1(0.6),
        "AR(1) log-intervals phi=0.6, sigma=1": ar1_lognormal(0.6, 1.0),
        "MMPP rates 0.4/1.6, switch rate 0.05": mmpp((0.4, 1.6), 0.05),
    }


def rejection_table(n_size, n_power, n_mc, seed):
    rng = np.random.default_rng(seed)
    rows = []
    for name, make in scenarios().items():
        k = n_size if "(size)" in name else n_power
        window = 25.0 if "~25" in name else T
        seqs = [make(rng) for _ in range(k)]
        start = time.perf_counter()
        # Chunks of CHUNK sequences: sequences with equal n share a Monte Carlo null
        # inside one call, so fresh nulls per chunk keep the replicates nearly
        # independent (the rejection rate is unbiased either way).
        p = np.vstack(
            [
                stats.test_poisson_ensemble(
                    seqs[i : i + CHUNK], window, n_mc=n_mc, n_mc_max=n_mc, rng=rng
                ).per_sequence[[f"p_{t}" for t in stats.TESTS]]
                for i in range(0, k, CHUNK)
            ]
        )
        seconds = time.perf_counter() - start
        rates = np.nanmean(p < ALPHA, axis=0)
        rows.append(
            {
                "scenario": name,
                "replicates": k,
                "mean_events": float(np.mean([s.size for s in seqs])),
                "rates": rates,
                "se": math.sqrt(ALPHA * (1 - ALPHA) / k),
                "seconds": seconds,
            }
        )
        print(f"{name:<40} {' '.join(f'{r:.3f}' for r in rates)}  ({seconds:.1f} s)")
    return rows


def markdown(rows, n_mc, seed):
    head = "| scenario | reps | mean n | " + " | ".join(stats.TESTS) + " |"
    rule = "|---|---:|---:|" + "---:|" * len(stats.TESTS)
    lines = [
        "# Size and power of the Poisson tests",
        "",
        "Generated by `python analysis/size_power.py` "
        f"(seed {seed}, Monte Carlo nulls with n_mc = {n_mc}); do not edit by hand.",
        "",
        f"Rejection rate at alpha = {ALPHA} of each single-sequence test of "
        "`kicktimes.stats.test_poisson` (window T = 100, unit mean interval, stationary "
        "processes). Size rows: a valid test sits within about 3 SE of 0.05 "
        f"(SE = {rows[0]['se']:.4f} with {rows[0]['replicates']} replicates; "
        f"power rows use {rows[-1]['replicates']} replicates).",
        "",
        head,
        rule,
    ]
    for row in rows:
        cells = " | ".join(f"{r:.3f}" for r in row["rates"])
        lines.append(
            f"| {row['scenario']} | {row['replicates']} | {row['mean_events']:.1f} | {cells} |"
        )
    lines += [
        "",
        "Reading the table:",
        "",
        "- `exponential_ks` / `exponential_ad` (exponentiality of the inner intervals, rate "
        "estimated, Monte Carlo null) detect non-exponential renewal intervals; the "
        "Anderson-Darling version is the more powerful (lognormal sigma = 1 is the hardest "
        "case: its coefficient of variation, 1.31, is close to the exponential's 1).",
        "- `ljung_box` and `runs` see serial dependence; they stay near 0.05 for renewal "
        "processes, whose intervals are independent.",
        "- `dispersion` (counts in about 20 sub-windows) sees clustering (Weibull, MMPP) and "
        "regularity (gamma(2): under-dispersion).",
        "- `uniformity_ks` and `laplace_trend` test the placement of the events in the "
        "window (a trend or a slow rate change); they have some power against bursty "
        "processes whose slow fluctuations look like trends in a single window.",
    ]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size-replicates", type=int, default=4000)
    parser.add_argument("--replicates", type=int, default=1000)
    parser.add_argument("--n-mc", type=int, default=999)
    parser.add_argument("--seed", type=int, default=20240601)
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parents[1] / "docs/size_power.md"
    )
    args = parser.parse_args()
    rows = rejection_table(args.size_replicates, args.replicates, args.n_mc, args.seed)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(markdown(rows, args.n_mc, args.seed))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
