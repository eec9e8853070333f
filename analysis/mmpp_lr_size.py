"""Size and power of the bootstrap LR test of an MMPP-2 against Poisson
(``kicktimes.stats.mmpp_lr_test``; issue 39, "Must show").

Run: ``python analysis/mmpp_lr_size.py [--null 300] [--alt 100] [--boot 99] [--out DIR]``

* size: ``--null`` single Poisson windows of about 150 events (rate 1, window 150), as
  the report's outside-data comparison tests them, one test each;
* power: ``--alt`` single windows of the same length from MMPP-2s with the same mean
  rate 1 in (a): (a) slow switching between rates 0.5 and 2 (switching rates 0.02 and 0.04),
  (b) bursts: rate 0.8 with a burst state of rate 20 entered at rate 0.01 and left at
  rate 2 (mean rate about 0.9; a few clusters of about 10 events per window).

Every test uses the default search of ``fit_mmpp`` for the data and for each of its
``--boot`` samples. Prints the rejection rates at alpha = 0.05 and 0.10 with 95 %
Clopper-Pearson intervals and the share of data sets whose LR statistic is 0, and writes
the p-values to ``DIR/lr_pvalues.csv``.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats as sps

from kicktimes import stats

T = 150.0
DESIGNS = {
    "poisson": ([1.0, 1.0], [[-1.0, 1.0], [1.0, -1.0]]),
    "slow switching 0.5 / 2": ([0.5, 2.0], [[-0.02, 0.02], [0.04, -0.04]]),
    "bursts 0.8 / 20": ([0.8, 20.0], [[-0.01, 0.01], [2.0, -2.0]]),
}


def clopper_pearson(k, n, level=0.95):
    a = 1 - level
    lo = sps.beta.ppf(a / 2, k, n - k + 1) if k > 0 else 0.0
    hi = sps.beta.ppf(1 - a / 2, k + 1, n - k) if k < n else 1.0
    return lo, hi


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--null", type=int, default=300)
    ap.add_argument("--alt", type=int, default=100)
    ap.add_argument("--boot", type=int, default=99)
    ap.add_argument("--out", default="analysis/mmpp_lr_size_out")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    master = np.random.default_rng(39)
    for design, (rates, gen) in DESIGNS.items():
        count = args.null if design == "poisson" else args.alt
        streams = master.spawn(count)
        start = time.perf_counter()
        for k, rng in enumerate(streams):
            times = stats.simulate_mmpp(rates, gen, T, rng=rng)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    res = stats.mmpp_lr_test(times, T, n_boot=args.boot, rng=rng)
                except ValueError:  # too few events for an MMPP-2
                    continue
            rows.append({"design": design, "k": k, "n_events": times.size,
                         "statistic": res.statistic, "pvalue": res.pvalue})
            if (k + 1) % 50 == 0:
                print(f"  {design}: {k + 1} of {count}, {time.perf_counter() - start:.0f} s",
                      flush=True)
        print(f"{design}: {count} tests in {time.perf_counter() - start:.0f} s", flush=True)
        pd.DataFrame(rows).to_csv(out / "lr_pvalues.csv", index=False)
    df = pd.DataFrame(rows)
    table = []
    for design, part in df.groupby("design", sort=False, observed=True):
        row = {"data": design, "sets": len(part),
               "LR = 0": f"{(part['statistic'] <= 1e-9).mean():.1%}"}
        for alpha in (0.05, 0.10):
            k = int((part["pvalue"] <= alpha).sum())
            lo, hi = clopper_pearson(k, len(part))
            row[f"rejects at {alpha:g}"] = f"{k / len(part):.1%} ({lo:.1%}-{hi:.1%})"
        table.append(row)
    table = pd.DataFrame(table)
    print(table.to_string(index=False))
    return table


if __name__ == "__main__":
    main()
