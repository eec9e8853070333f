"""Which renewal model fits the tagged disk's intervals: docs/results/disks_renewal.csv.

Per row (sweep x N) the intervals between the first ``K + 1`` collisions of every tested
tagged disk, pooled, in units of the mean interval, go to `kicktimes.stats.compare_models`
(every full-sample model: exponential, gamma, Weibull, lognormal, Lomax,
hyperexponential), which ranks them by AIC. The pooled intervals are not independent (the
intervals of one disk and the disks of one run share a gas): the likelihood counts them as
independent, so ΔAIC overstates the evidence by the unknown factor by which the effective
sample is smaller. As a check that does not lean on that count, the two best models are
refitted on each half of the runs (odd and even run numbers, independent gases): the
ranking is called *stable* when both halves give the same best model.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from kicktimes.stats import FitWarning, compare_models

__all__ = ["RENEWAL_MODELS", "renewal_lines", "renewal_models"]

RENEWAL_MODELS = ("exponential", "gamma", "weibull", "lognormal", "lomax", "hyperexponential")


def _intervals(col, k):
    """Pooled intervals of the tested sequences (first ``k + 1`` collisions) and their
    runs."""
    iv, runs = [], []
    for t, ic in zip(col["pp_times"], col["ic"], strict=True):
        t = np.asarray(t, float)
        if t.size > k:
            iv.append(np.diff(t[:k + 1]))
            runs.append(np.full(k, ic))
    if not iv:
        return np.empty(0), np.empty(0, int)
    return np.concatenate(iv), np.concatenate(runs)


def _compare(x, models):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitWarning)
        return compare_models(x, models=models)


def renewal_models(store, *, models=RENEWAL_MODELS) -> pd.DataFrame:
    """The renewal models of a disks store's rows, ranked by AIC.

    Returns
    -------
    pandas.DataFrame
        One row per N: ``experiment, geometry, rule, n_disks, n_intervals``, ``best`` (the
        AIC-best model), ``second``, ``delta_aic_second`` (its ΔAIC), ``delta_aic_<model>``
        for every model (NaN where it could not be fitted), ``best_odd``, ``best_even``
        (the better of the two best models on each half of the runs) and ``stable``
        (both halves give ``best``).

    Examples
    --------
    The intervals of Poisson sequences: the exponential is among the best.

    >>> import numpy as np, pandas as pd
    >>> from types import SimpleNamespace
    >>> from kicktimes.experiment import DisksExperiment
    >>> rng = np.random.default_rng(1)
    >>> col = pd.DataFrame({"n_disks": 10, "ic": np.arange(400) % 8,
    ...                     "pp_times": [np.cumsum(rng.exponential(size=12)) for _ in range(400)]})
    >>> exp = DisksExperiment(name="x", n_disks=[10], packing=0.1, collisions=10)
    >>> t = renewal_models(SimpleNamespace(experiment=exp, collisions=col))
    >>> bool(t.loc[0, "delta_aic_exponential"] < 4)
    True
    """
    exp = store.experiment
    rows = []
    for n in exp.n_disks:
        col = store.collisions[store.collisions["n_disks"] == n]
        x, runs = _intervals(col, exp.collisions)
        if x.size < 50:
            continue
        x = x / x.mean()
        tab = _compare(x, models)
        fitted = tab[np.isfinite(tab["aic"])]
        row = {"experiment": exp.name, "geometry": exp.geometry_label, "rule": exp.rule,
               "n_disks": int(n), "n_intervals": int(x.size), "best": fitted.index[0],
               "second": fitted.index[1] if len(fitted) > 1 else "",
               "delta_aic_second": (float(fitted["delta_aic"].iloc[1]) if len(fitted) > 1
                                    else np.nan)}
        for m in models:
            row[f"delta_aic_{m}"] = float(tab.loc[m, "delta_aic"]) if m in tab.index else np.nan
        top = list(fitted.index[:2])
        for half, keep in (("odd", runs % 2 == 1), ("even", runs % 2 == 0)):
            row[f"best_{half}"] = (_compare(x[keep], top).index[0]
                                   if keep.sum() >= 50 and len(top) > 1 else "")
        row["stable"] = row["best_odd"] == row["best_even"] == row["best"]
        rows.append(row)
    return pd.DataFrame(rows)


def _ns(ns):
    return f"N = {', '.join(str(n) for n in ns)}" if ns else "no N"


def _delta(x):
    return "—" if not np.isfinite(x) else f"{x:.3g}"


def renewal_lines(models: pd.DataFrame) -> list:
    """The page's section on the renewal models: one sentence per geometry x rule, then the
    table (rows N, columns geometry x rule: the AIC-best model and the exponential's ΔAIC)."""
    if models.empty:
        return []
    lines = [
        "## Which renewal model?", "",
        "Per row, the intervals between the first 31 collisions of every tested tagged disk, "
        "pooled and in units of the mean interval, ranked by AIC over "
        f"{', '.join(RENEWAL_MODELS)} (`stats.compare_models`; "
        "[disks_renewal.csv](disks_renewal.csv) has every model's ΔAIC). The pooled "
        "intervals are not independent (one disk's intervals, and the disks of one run, "
        "share a gas), while the likelihood counts them as independent: the ΔAIC values "
        "overstate the evidence by an unknown factor, and no standard error is given. As a "
        "check that does not rest on that count, the two best models are refitted on the odd "
        "and the even runs (independent gases): *stable* when both halves pick the same "
        "model.", ""]
    for (fam, rule), g in models.groupby(["geometry", "rule"], sort=False, observed=True):
        exp_best = g[g["best"] == "exponential"]["n_disks"].tolist()
        unstable = g[~g["stable"]]["n_disks"].tolist()
        big = g.iloc[-1]
        lines.append(
            f"- {fam}, {rule}: at N = {int(big['n_disks'])} the best is {big['best']} "
            f"(the next, {big['second']}, ΔAIC {_delta(big['delta_aic_second'])}; the "
            f"exponential ΔAIC {_delta(big['delta_aic_exponential'])}); the exponential is "
            f"the best at {_ns(exp_best)}; the ranking is not stable over the halves at "
            f"{_ns(unstable)}.")
    fams = list(dict.fromkeys(zip(models["geometry"], models["rule"], strict=True)))
    lines += ["", "| N | " + " | ".join(f"{g}, {r}" for g, r in fams) + " |",
              "|---|" + "---|" * len(fams)]
    for n in sorted(set(models["n_disks"])):
        cells = []
        for g, r in fams:
            m = models[(models["geometry"] == g) & (models["rule"] == r)
                       & (models["n_disks"] == n)]
            if m.empty:
                cells.append("—")
                continue
            m = m.iloc[0]
            mark = "" if m["stable"] else " †"
            exp_d = ("" if m["best"] == "exponential"
                     else f"; exp. ΔAIC {_delta(m['delta_aic_exponential'])}")
            cells.append(f"{m['best']}{mark}{exp_d}")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    return lines + ["", "Cells: the AIC-best model (†: the halves of the runs pick "
                    "different models), and the exponential's ΔAIC where it is not the best "
                    "(ΔAIC > 10 is conventionally strong evidence, on independent "
                    "intervals).", ""]
