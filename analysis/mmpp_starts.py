"""How much the report's MMPP-2 comparison depends on its number of EM starts.

The report's MMPP section (`kicktimes.report.mmpp`) fits every eligible IC's collision
times with `kicktimes.stats.compare_point_processes` and `kicktimes.report.mmpp.N_STARTS`
EM starts (4 until issue 39, now 12). This script refits the same ICs, with the report's
own seeds, at several numbers of starts and prints, per number of starts, the share of
ICs where the MMPP-2 beats Poisson by AIC, and how many ICs' MMPP-2 AIC is worse than
with the most starts (by more than 0.01). Two independent fits with the same number of
starts are also compared (the report's comparison fit against `fit_mmpp` continuing the
same stream, as the report did before it kept one fit per IC).

Run (after ``kicktimes reproduce --scale paper --out paper/``, whose report lists the
fitted ICs in ``<family>_mmpp_per_ic.csv``)::

    python analysis/mmpp_starts.py paper/store-family_b paper/report/family_b_mmpp_per_ic.csv

Measured on 2026-11-26 with the search before issue 39 (family B, 106 fitted ICs):
shares 0.642, 0.660 and 0.670 with 4, 8 and 16 starts; 18 ICs worse than with 16 starts
by more than 0.01 in AIC (up to 30); the two 4-start fits differ by more than 1e-6 in
log-likelihood in 25 ICs (docs/report.md).
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np
import pandas as pd

from kicktimes import stats
from kicktimes.experiment import load_store
from kicktimes.report.context import seeded_rng


def report_seed(exp_seed: int, radius: float, ic: int) -> int:
    """The seed of one IC's fits in the report (`kicktimes.report.mmpp.sections`)."""
    return int(seeded_rng(exp_seed, 10, int(round(radius * 1e6)), int(ic)).integers(2**63))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("store", help="a sweep store (e.g. paper/store-family_b)")
    ap.add_argument("per_ic", help="the report's <family>_mmpp_per_ic.csv (the fitted ICs)")
    ap.add_argument("--starts", type=int, nargs="+", default=[4, 8, 16])
    args = ap.parse_args(argv)
    starts = sorted(set(args.starts))
    store = load_store(args.store, verify=False)
    coll = store.collisions.set_index(["radius", "ic"])
    fitted = pd.read_csv(args.per_ic)
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # degenerate fits are expected on some ICs
        for row in fitted.itertuples():
            c = coll.loc[(row.radius, row.ic)]
            times, window = np.asarray(c["pp_times"], float), float(c["t_window"])
            seed = report_seed(store.experiment.seed, row.radius, row.ic)
            out = {"radius": row.radius, "ic": row.ic}
            for n in starts:
                rng = np.random.default_rng(seed)
                table, fits = stats.compare_point_processes(
                    times, window, models=[], n_states=(2,), n_starts=n, rng=rng,
                    return_fits=True)
                out[f"aic_{n}"] = table.loc["mmpp2", "aic"]
                out[f"beats_{n}"] = table.loc["mmpp2", "aic"] < table.loc["poisson", "aic"]
                if n == starts[0]:
                    # a second fit on the continued stream: independent starts
                    again = stats.fit_mmpp(times, window, n_states=2, n_starts=n, rng=rng)
                    out["loglik_gap"] = fits["mmpp2"].loglik - again.loglik
            rows.append(out)
    df = pd.DataFrame(rows)
    most = starts[-1]
    print(f"{len(df)} fitted ICs of {args.store}")
    for n in starts:
        worse = df[f"aic_{n}"] - df[f"aic_{most}"]
        print(f"  {n:3d} starts: MMPP-2 beats Poisson in {df[f'beats_{n}'].mean():.3f}; AIC "
              f"worse than with {most} starts by > 0.01 in {int((worse > 0.01).sum())} "
              f"(largest {worse.max():.3g})")
    gap = df["loglik_gap"].abs()
    print(f"  two independent {starts[0]}-start fits differ by > 1e-6 in log-likelihood in "
          f"{int((gap > 1e-6).sum())} ICs (largest {gap.max():.3g})")
    return df


if __name__ == "__main__":
    main()
