"""The gas half of the null calibration: streams that satisfy a null, shaped like the runs.

For each disks sweep and N, `null_rows` replaces every tagged disk's collision times by a
stream drawn from a null and runs the page's whole row (`kicktimes.studies.disks.tables`,
the same tests at the same ``alpha``, window of K = ``collisions`` collisions, count window,
bootstrap clustered on the same runs, with the same numbers of runs and of tagged disks
per run). Designs:

* ``"poisson"``: each tagged disk a Poisson stream at its run's collision frequency (the
  rate disks.csv reads), over its run's window; its speeds unknown (the speed-rescaled
  tests then see the stream unchanged);
* ``"dilute"`` (elastic sweeps): each tagged disk the dilute gas's tagged disk, the linear
  Boltzmann Cox process of `kicktimes.stats.dilute_tagged_times` at that rate and the
  gas's temperature, with its speeds (the speed-rescaled tests rescale it exactly). Under
  the mirror rule it is the Poisson stream, so it is not drawn twice.

The share a test rejects on these streams is the level a Poisson (or a dilute-gas) process
gives through the page's pipeline: the calibrated level of `kicktimes.stats.poisson_verdict`
(`calibration_rows` writes them to ``docs/results/null_calibration.csv`` through
`kicktimes.render.pages.write_null_calibration`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import TESTS, dilute_tagged_times

__all__ = ["NULL_DESIGNS", "NULL_VALUES", "calibration_rows", "null_level", "null_rows",
           "null_streams"]

#: the null designs and what they are
NULL_DESIGNS = {"poisson": "Poisson at each run's collision frequency",
                "dilute": "dilute tagged disk (linear Boltzmann Cox process)"}


#: null_calibration.csv's statistics other than rejection shares -> disks.csv's column
NULL_VALUES = {"D": "dispersion", "hazard, first bin": "hazard_first",
               "hazard, highest bin": "hazard_peak", "gamma shape": "gamma_shape"}


def null_streams(store, n_disks, design, rng):
    """The store's results and collision rows at ``n_disks`` with every tagged disk's
    collision times (and, elastic, speeds) replaced by a ``design`` stream: ``(res, col)``
    shaped as the store's (`null_rows`).

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> from kicktimes.experiment import disks_preset
    >>> exp = disks_preset("disks-phi0.02-mirror")
    >>> res = pd.DataFrame({"n_disks": 10, "radius": 0.1, "ic": [0, 1], "system": "disks",
    ...                     "diagnostic": "collision_frequency", "value": [2.0, 3.0],
    ...                     "note": ""})
    >>> col = pd.DataFrame({"n_disks": 10, "radius": 0.1, "ic": [0, 0, 1], "disk": [1, 4, 2],
    ...                     "t_window": 50.0, "n_pp": 0, "pp_times": [np.empty(0)] * 3,
    ...                     "speeds": [np.empty(0)] * 3})
    >>> st = SimpleNamespace(experiment=exp, results=res, collisions=col)
    >>> r, c = null_streams(st, 10, "poisson", np.random.default_rng(0))
    >>> c["ic"].tolist(), [round(t.size / 50.0) for t in c["pp_times"]][2]
    ([0, 0, 1], 3)
    """
    if design not in NULL_DESIGNS:
        raise ValueError(f"design must be one of {tuple(NULL_DESIGNS)}, got {design!r}")
    exp = store.experiment
    if design == "dilute" and exp.rule != "elastic":
        raise ValueError("design: 'dilute' is the Poisson stream under the mirror rule; give "
                         "'poisson'")
    res = store.results[store.results["n_disks"] == n_disks]
    col = store.collisions[store.collisions["n_disks"] == n_disks]
    rate = res[res["diagnostic"] == "collision_frequency"].set_index("ic")["value"]
    times, speeds = pd.Series(None, index=col.index, dtype=object), pd.Series(
        None, index=col.index, dtype=object)
    for ic, g in col.groupby("ic", sort=False):
        window = float(g["t_window"].iloc[0])
        rule = "elastic" if design == "dilute" else "mirror"
        if not float(rate[ic]) > 0:
            # a run without a collision (two disks whose conserved state keeps them apart):
            # its tagged disks' null streams are empty too
            t, s = [np.empty(0)] * len(g), [np.full(1, np.nan)] * len(g)
        else:
            t, s = dilute_tagged_times(rule, float(rate[ic]), window, n_runs=len(g), rng=rng,
                                       speeds=True)
        if design == "poisson":
            s = [np.full(x.size + 1, np.nan) if exp.rule == "elastic" else np.empty(0)
                 for x in t]
        times[g.index] = pd.Series(t, index=g.index, dtype=object)
        speeds[g.index] = pd.Series(s, index=g.index, dtype=object)
    col = col.copy()
    col["pp_times"], col["speeds"] = times, speeds
    col["n_pp"] = [x.size for x in times]
    known = 1.0 if design == "dilute" else 0.0
    res = res.copy()
    res.loc[res["diagnostic"] == "speed_known", "value"] = known
    return res, col


def null_rows(store, *, designs=None, alpha=0.05, n_boot=999, n_mc=199, seed=0):
    """The page's rows (`kicktimes.studies.disks.tables.disks_table`'s columns) of the null
    streams of one disks store, one per N and design, with a ``design`` column.

    Parameters
    ----------
    store : Store
        A disks sweep's store.
    designs : sequence of str, optional
        Of `NULL_DESIGNS` (default ``"poisson"``, and ``"dilute"`` under the elastic rule).
    alpha, n_boot, n_mc, seed :
        As in `disks_table`; each (N, design) has its own stream from ``seed``.
    """
    from kicktimes.studies.disks.tables import _row

    exp = store.experiment
    if designs is None:
        designs = ("poisson", "dilute") if exp.rule == "elastic" else ("poisson",)
    rows = []
    for n in exp.n_disks:
        for m, design in enumerate(designs):
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(n, 7, m)))
            res, col = null_streams(store, n, design, rng)
            if res.empty:
                continue
            row = _row(exp, n, res, col, alpha=alpha, n_boot=n_boot, n_mc=n_mc, rng=rng)
            row["design"] = design
            rows.append(row)
    return pd.DataFrame(rows)


def calibration_rows(null_table, *, alpha=0.05):
    """The rows of ``null_calibration.csv`` (`kicktimes.render.pages.write_null_calibration`)
    from `null_rows` tables: one per (geometry, rule, N), test and design; the speed-rescaled
    tests as ``"<test>, speed-rescaled"``; and per (geometry, rule, N) and design the
    statistics of `NULL_VALUES` on the null streams (D, the hazard's first and highest
    bin, the gamma shape), which the page reads the gas's against. ``n_runs`` the tagged
    disks tested, ``n_clusters`` the runs the bootstrap resamples."""
    out = []
    for _, r in null_table.iterrows():
        data = f"{r['geometry']}, {r['rule']}, N = {int(r['n_disks'])}"
        for prefix, suffix in (("", ""), ("rescaled_", ", speed-rescaled")):
            for test in TESTS:
                key = f"{prefix}reject_{test}"
                if key not in r or not np.isfinite(r.get(key, np.nan)):
                    continue
                out.append({"data": data, "statistic": "rejection share",
                            "test": test + suffix, "design": r["design"],
                            "alpha": alpha, "n_runs": int(r[f"{key}_n"]),
                            "n_clusters": int(r["n_runs"]), "value": float(r[key]),
                            "ci_low": float(r[f"{key}_low"]),
                            "ci_high": float(r[f"{key}_high"])})
        # the statistics whose null value is not 1: the page reads each against these
        for statistic, key in NULL_VALUES.items():
            if key not in r or not np.isfinite(r.get(key, np.nan)):
                continue
            out.append({"data": data, "statistic": statistic, "test": "",
                        "design": r["design"], "alpha": alpha,
                        "n_runs": int(r["n_tagged"] - r["n_short"]),
                        "n_clusters": int(r["n_runs"]), "value": float(r[key]),
                        "ci_low": float(r[f"{key}_low"]), "ci_high": float(r[f"{key}_high"])})
    return pd.DataFrame(out)


def null_level(null_table, geometry, rule, n_disks, key, design="poisson"):
    """The calibrated level of a test (``key`` a disks.csv share column, e.g.
    ``"reject_uniformity_ks"``): its share on the null streams of that row, or NaN when the
    null was not run."""
    g = null_table[(null_table["geometry"] == geometry) & (null_table["rule"] == rule)
                   & (null_table["n_disks"] == n_disks) & (null_table["design"] == design)]
    return float(g.iloc[0][key]) if not g.empty and key in g else float("nan")
