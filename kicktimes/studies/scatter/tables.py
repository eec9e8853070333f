"""The scatter study's statistics: sticky two-disk orbits, the ratios of mean FTLE per
radius with paired bootstrap intervals over ICs and their verdicts, the summaries."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import MARGIN, percentile_interval, ratio_verdict, resample_indices

__all__ = ["RATIOS", "ratio_table", "sticky", "summary_tables"]


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
            picks = resample_indices(len(g), n_boot, rng, with_identity=True)
            for num, den, label in RATIOS:
                q = g[num].to_numpy()[picks].mean(1) / g[den].to_numpy()[picks].mean(1)
                lo, hi = percentile_interval(q[1:])
                rows.append({"ics": ics, "radius": r, "n": len(g), "ratio": label,
                             "estimate": q[0], "ci_low": lo, "ci_high": hi,
                             "verdict": ratio_verdict(lo, hi, MARGIN)})
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
