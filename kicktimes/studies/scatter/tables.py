"""The scatter study's statistics: sticky two-disk orbits, the ratios of mean FTLE per
radius with paired bootstrap intervals over ICs and their verdicts, the summaries."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import (
    FINE_MARGIN,
    MARGIN,
    percentile_interval,
    ratio_verdict,
    resample_indices,
    robust_verdict,
)

__all__ = ["FINE_MARGIN", "RATIOS", "over_radii", "ratio_table", "sticky", "summary_tables"]



#: (numerator, denominator, label) of the page's ratios of means
RATIOS = (("scatter", "two", "scatter kicks / two disks"),
          ("uniform", "two", "uniform kicks / two disks"),
          ("scatter_actual", "two", "scatter kicks at the actual times / two disks"),
          ("two_fresh", "two", "partner tangent zeroed / two disks"),
          ("scatter", "two_fresh", "scatter kicks / partner tangent zeroed"))


def sticky(df):
    """A two-disk orbit is sticky when its exponent is below a quarter of its radius's
    median (a near-periodic head-on orbit with a collision rate ~10x the typical one)."""
    return df["two"] < 0.25 * df.groupby("radius", observed=True)["two"].transform("median")


def ratio_table(df, n_boot=1000, seed=0):
    """Per radius and IC set (without / with the sticky ICs) each ratio of means with a
    95 % bootstrap interval over ICs (paired: the same resampled ICs for both means) and
    its `ratio_verdict`."""
    rng = np.random.default_rng(seed)
    calm = ~sticky(df)
    rows = []
    for ics, part in (("without sticky ICs", df[calm]), ("all ICs", df)):
        for r, g in part.groupby("radius", observed=True):
            picks = resample_indices(len(g), n_boot=n_boot, rng=rng, with_identity=True)
            for num, den, label in RATIOS:
                q = g[num].to_numpy()[picks].mean(1) / g[den].to_numpy()[picks].mean(1)
                lo, hi = percentile_interval(q[1:])
                rows.append({"ics": ics, "radius": r, "n": len(g), "ratio": label,
                             "estimate": q[0], "ci_low": lo, "ci_high": hi,
                             "verdict": ratio_verdict(lo, hi, tolerance=MARGIN),
                             "verdict_fine": ratio_verdict(lo, hi, tolerance=FINE_MARGIN)})
    return pd.DataFrame(rows)


def summary_tables(df) -> dict[str, pd.DataFrame]:
    """The per-radius summaries behind the page, as DataFrames: ``"sticky"`` (the sticky
    runs: radius, ic, rate, two, scatter), ``"all ICs"`` and ``"without sticky ICs"`` (mean
    FTLE over ICs per system and their quotients; ``+-`` the standard error of scatter /
    two) and ``"shape"`` (RR off the diagonal in units of 1e-4, DET, R_1 and R_5 without the
    sticky ICs)."""
    df = df.assign(sticky=sticky(df))
    out = {"sticky": df.loc[df.sticky, ["radius", "ic", "rate", "two", "scatter"]]}
    cols = ["two", "two_fresh", "uniform", "scatter", "scatter_unw", "scatter_actual"]
    for label, part in (("all ICs", df), ("without sticky ICs", df[~df.sticky])):
        g = part.groupby("radius", observed=True)
        tab = g[cols].mean()
        tab["n"] = g.size()
        ratio = part["scatter"] / part["two"]
        tab["scatter/two"] = tab["scatter"] / tab["two"]
        tab["+-"] = np.sqrt(g["scatter"].var() / g.size()) / tab["two"]
        tab["median ratio"] = ratio.groupby(part["radius"], observed=True).median()
        tab["uniform/two"] = tab["uniform"] / tab["two"]
        tab["unw/two"] = tab["scatter_unw"] / tab["two"]
        tab["actual/two"] = tab["scatter_actual"] / tab["two"]
        tab["fresh/two"] = tab["two_fresh"] / tab["two"]
        tab["scatter/fresh"] = tab["scatter"] / tab["two_fresh"]
        tab["outside"] = g["outside"].mean()
        out[label] = tab
    part = df[~df.sticky]
    names = [f"{n}_{k}" for n in ("two", "uniform", "scatter")
             for k in ("rr_offdiag", "det", "acf1", "acf5")]
    shape = part.groupby("radius", observed=True)[names].mean()
    for name in ("two", "uniform", "scatter"):
        shape[f"{name}_rr_offdiag"] *= 1e4
    out["shape"] = shape
    return out


def _mean_kept(x):
    """Mean over axis 1 of the finite values; NaN where there is none."""
    kept = np.isfinite(x)
    n = kept.sum(axis=1)
    total = np.where(kept, x, 0.0).sum(axis=1)
    return np.divide(total, n, out=np.full(total.shape, np.nan), where=n > 0)


def over_radii(df, n_boot=1000, seed=0) -> pd.DataFrame:
    """``scatter_over_radii.csv``: each ratio of `RATIOS` averaged over the radii (the mean
    of the per-radius ratios of means), without and with the sticky ICs (the control),
    with a 95 % bootstrap interval over ICs paired across radii (the same ICs run at
    every radius: one resample of the IC indices for all of them), its `ratio_verdict` at
    the 10 % margin and at `FINE_MARGIN`, the deficit ``1 - ratio`` and whether the
    verdict is robust over the two IC sets (`kicktimes.stats.robust_verdict`)."""
    rng = np.random.default_rng(seed)
    ics = np.sort(df["ic"].unique())
    picks = resample_indices(len(ics), n_boot=n_boot, rng=rng, with_identity=True)
    calm = ~sticky(df)
    rows = []
    for label_ics, keep in (("without sticky ICs", calm), ("all ICs", calm | True)):
        part = df[keep]
        for num, den, label in RATIOS:
            wide = [part.pivot(index="ic", columns="radius", values=c).reindex(ics).to_numpy()
                    for c in (num, den)]
            # a resample that draws only sticky ICs at some radius has no ratio there: it
            # is NaN and left out of the interval (``n_draws`` counts the draws kept)
            q = (_mean_kept(wide[0][picks]) / _mean_kept(wide[1][picks])).mean(axis=1)
            lo, hi = percentile_interval(q[1:])
            rows.append({"ics": label_ics, "ratio": label, "n_radii": wide[0].shape[1],
                         "n_ics": len(ics), "n_draws": int(np.isfinite(q[1:]).sum()),
                         "estimate": q[0], "ci_low": lo, "ci_high": hi,
                         "deficit": 1 - q[0], "deficit_low": 1 - hi, "deficit_high": 1 - lo,
                         "verdict": ratio_verdict(lo, hi, tolerance=MARGIN),
                         "verdict_fine": ratio_verdict(lo, hi, tolerance=FINE_MARGIN)})
    out = pd.DataFrame(rows)
    for column, name in (("verdict", "robust"), ("verdict_fine", "robust_fine")):
        robust = {label: robust_verdict(list(g[column]), g["ci_low"], g["ci_high"])[0]
                  for label, g in out.groupby("ratio", sort=False)}
        out[name] = out["ratio"].map(robust)
    return out
