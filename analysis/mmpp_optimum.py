"""Does the default ``fit_mmpp`` reach the MMPP-2 optimum on two-disk collision times?
(issue 39, "Must show").

Data: the disk-disk collision times of ``initial_conditions(60, 0.02, rng=5)``, one run
of ``t_max = 3000`` per IC (``simulate_two_particle``, mirror rule). Sets: the 59 single
runs with at least 4 collisions, the 6 groups of 10 runs (runs 0-9, ..., 50-59; one
window per run) and all 60 together: 66 sets.

Three steps, each writing a CSV in ``--out``:

``fits``
    the default fit, ``fit_mmpp(times, 3000.0, rng=seed)`` for each ``--seeds``, with
    the public API only (so it runs on an older tree as well:
    ``PYTHONPATH=/tmp/base python analysis/mmpp_optimum.py fits --tag before``);
``reference``
    the optimum found by ``--starts`` (default 64) independent random starts, each run
    by the EM to convergence (``tol = 1e-12``, up to 20 000 E-steps). The starts are
    drawn log-uniformly and independently of ``fit_mmpp``'s own: both rates in
    ``[1e-2, 1e3]`` and both switching rates in ``[1e-4, 1e3]`` times the set's mean
    event rate. This step calls the EM itself (``kicktimes.stats.mmpp._em``), not
    the public API;
``table``
    the shortfall of each tag's fits below the optimum (the larger of the reference and
    the best fit seen for the set), counted per threshold.

Run::

    python analysis/mmpp_optimum.py reference
    python analysis/mmpp_optimum.py fits --tag after
    PYTHONPATH=/tmp/base python analysis/mmpp_optimum.py fits --tag before
    python analysis/mmpp_optimum.py table --tags before after
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, simulate_two_particle, stats

T_MAX = 3000.0
RADIUS = 0.02


def collision_sets(cache=None):
    """``{name: list of windows}``: 59 single runs (>= 4 collisions), 6 groups, all 60."""
    if cache is not None and Path(cache).is_file():
        runs = list(np.load(cache, allow_pickle=True))
    else:
        ics = initial_conditions(60, RADIUS, rng=5)
        runs = [simulate_two_particle(ic, RADIUS, t_max=T_MAX).pp_times for ic in ics]
        if cache is not None:
            np.save(cache, np.array(runs, dtype=object), allow_pickle=True)
    sets = {f"run {k}": [t] for k, t in enumerate(runs) if t.size >= 4}
    sets.update({f"runs {10 * g}-{10 * g + 9}": runs[10 * g:10 * g + 10] for g in range(6)})
    sets["all 60"] = runs
    return sets


def default_fits(sets, seeds):
    rows = []
    for name, windows in sets.items():
        for seed in seeds:
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fit = stats.fit_mmpp(windows, T_MAX, rng=seed)
            rows.append({"set": name, "seed": seed, "loglik": fit.loglik,
                         "rate_low": fit.rates[0], "rate_high": fit.rates[1],
                         "seconds": time.perf_counter() - start,
                         "n_best": getattr(fit, "n_best", np.nan)})
    return pd.DataFrame(rows)


def reference_optimum(sets, n_starts, rng):
    from kicktimes.stats.mmpp import _em as em

    rows = []
    for name, windows in sets.items():
        data = em.Windows.of(windows, np.full(len(windows), T_MAX))
        shift = data.n_events.sum() * np.log(data.unit)  # fit units -> data units
        best, lls = None, []
        for _ in range(n_starts):
            rates = np.sort(10.0 ** rng.uniform(-2.0, 3.0, 2))
            q = 10.0 ** rng.uniform(-4.0, 3.0, 2)
            Q = np.array([[-q[0], q[0]], [q[1], -q[1]]])
            run = em.run_em(rates, Q, data, initial="stationary", max_iter=20_000, tol=1e-12)
            lls.append(run.loglik)
            if best is None or run.loglik > best.loglik:
                best = run
        lls = np.array(lls) - shift
        top = lls.max()
        rows.append({"set": name, "n_events": int(data.n_events.sum()),
                     "reference": top, "n_at_reference": int((lls >= top - 0.01).sum()),
                     "n_starts": n_starts,
                     "rate_low": best.rates.min() / data.unit,
                     "rate_high": best.rates.max() / data.unit})
        print(f"{name:>12}: {top:.4f} ({rows[-1]['n_at_reference']} of {n_starts} starts "
              "within 0.01)", flush=True)
    return pd.DataFrame(rows)


def shortfall_table(ref, fits_by_tag):
    """Per tag: fits within 0.01 of the optimum, shortfalls above 0.01 and 1, worst."""
    best = ref.set_index("set")["reference"]
    for fits in fits_by_tag.values():
        best = np.maximum(
            best, fits.groupby("set", observed=True)["loglik"].max().reindex(best.index))
    rows, detail = [], []
    for tag, fits in fits_by_tag.items():
        gap = best.reindex(fits["set"]).to_numpy() - fits["loglik"].to_numpy()
        rows.append({"code": tag, "fits": len(fits), "within 0.01": int((gap <= 0.01).sum()),
                     "short > 0.01": int((gap > 0.01).sum()), "short > 1": int((gap > 1).sum()),
                     "worst shortfall": float(gap.max()),
                     "seconds (all fits)": float(fits["seconds"].sum())})
        detail.append(fits.assign(code=tag, shortfall=gap))
    return pd.DataFrame(rows), pd.concat(detail)


def markdown(table):
    """A pipe table (no extra dependency)."""
    def cell(v):
        return f"{v:.3g}" if isinstance(v, float) else str(v)
    lines = ["| " + " | ".join(table.columns) + " |",
             "|" + "|".join("---" for _ in table.columns) + "|"]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |"
              for row in table.itertuples(index=False)]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("step", choices=["fits", "reference", "table"])
    ap.add_argument("--out", default="analysis/mmpp_optimum_out")
    ap.add_argument("--tag", default="after")
    ap.add_argument("--tags", nargs="+", default=["before", "after"])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--starts", type=int, default=64)
    ap.add_argument("--cache", default=None, help="a .npy file of the 60 runs' times")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.step == "table":
        ref = pd.read_csv(out / "reference.csv")
        fits = {tag: pd.read_csv(out / f"fits_{tag}.csv") for tag in args.tags}
        table, detail = shortfall_table(ref, fits)
        detail.to_csv(out / "shortfalls.csv", index=False)
        print(markdown(table))
        missed = detail[detail["shortfall"] > 0.01]
        if len(missed):
            print("\nfits more than 0.01 below the optimum:")
            print(missed[["code", "set", "seed", "loglik", "shortfall"]].to_string(index=False))
        return table
    sets = collision_sets(args.cache)
    if args.step == "reference":
        table = reference_optimum(sets, args.starts, np.random.default_rng(2026))
        table.to_csv(out / "reference.csv", index=False)
    else:
        table = default_fits(sets, args.seeds)
        table.to_csv(out / f"fits_{args.tag}.csv", index=False)
        print(f"{len(table)} fits, {table['seconds'].sum():.1f} s")
    return table


if __name__ == "__main__":
    main()
