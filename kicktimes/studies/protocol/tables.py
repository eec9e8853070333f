r"""The protocol study's tables: ratios per reading, the choices' Shapley shares, convergence.

Every ratio is kicked over two-disk FTLE, the ratio of the ensemble means at each radius
averaged over the radii (`kicktimes.stats.paired_ratio`), with a 95 % bootstrap
CI clustered on ICs: one set of resampled IC indices (``N_BOOT`` draws from ``BOOT_SEED``)
is applied to every radius, system and reading, so differences between readings are
paired. Verdicts come from `kicktimes.stats.ratio_verdict` (the ±10 % band, an
equivalence test) and `kicktimes.stats.robust_verdict`.

**Shapley shares.** For a panel and a kicked system, let :math:`v(S) = |\log R(S)|`, the
ratio's distance from 1 (in log) when the choices in :math:`S \subseteq \{E, M, K\}`
(estimator, measure, twin kicks) take their alternative level (literal, norm,
independent) and the others kicktimes' default (renormalised, the paper's x/y measure,
shared). The share of choice :math:`i` is

.. math::

    \phi_i = \sum_{S \not\ni i} \frac{|S|! \, (2 - |S|)!}{3!} \, [v(S \cup \{i\}) - v(S)],

and :math:`\sum_i \phi_i = v(\{E, M, K\}) - v(\varnothing)` (Shapley 1953): a negative
share brings the ratio towards 1. Each share's CI comes from the same IC resamples.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pandas as pd

from kicktimes.stats import (
    paired_ratio,
    percentile_interval,
    ratio_verdict,
    robust_verdict,
    shapley_values,
)
from kicktimes.stats.findings import share_verdict
from kicktimes.studies.protocol.compute import CONVERGENCE

__all__ = ["BOOT_SEED", "FACTORS", "N_BOOT", "PAPER_READING", "Ratios", "convergence_table",
           "per_radius_table", "r1_table", "ratio_table", "reading_label", "rr_table",
           "shapley_table"]

N_BOOT = 2000
BOOT_SEED = 48
#: the choices decomposed by Shapley shares: (column, kicktimes' level, the alternative)
FACTORS = (("estimator", "renormalised", "literal"), ("measure", "paper", "norm"),
           ("twin_kicks", "shared", "independent"))
#: eq. (4) as printed, the paper's x/y measure, uniform kicks; the twins share the kicks
PAPER_READING = ("literal", "paper", "shared", "uniform")
_READING = ["estimator", "measure", "twin_kicks", "kick_angle"]
_KICKED = ("poisson", "actual")


def reading_label(reading) -> str:
    """A reading as a short name, e.g. ``literal/paper/shared/uniform``."""
    return "/".join(str(x) for x in reading)


def _two_disk_reading(reading):
    e, m, _, _ = reading
    return (e, "paper", "-", "-") if e == "tangent" else (e, m, "shared", "uniform")


class Ratios:
    """Kicked / two-disk ratios of one horizon's rows under shared IC resamples."""

    def __init__(self, rows: pd.DataFrame, horizon: int = 1, max_ic: int | None = None):
        rows = rows[(rows["horizon"] == horizon) & (rows["diagnostic"] == "ftle")]
        if max_ic is not None:
            rows = rows[rows["ic"] < max_ic]
        self.series = {
            key: g.set_index(["radius", "ic"])["lam"].sort_index()
            for key, g in rows.groupby(["panel", "system", *_READING], sort=True)
        }
        self._resamples: dict = {}
        self._cache: dict = {}

    def ratio(self, panel: str, system: str, reading) -> tuple[pd.DataFrame, dict, np.ndarray]:
        """(per radius, overall, the resamples' overall ratios) of ``system`` under
        ``reading`` against the two-disk system under the same estimator and measure."""
        key = (panel, system, *reading)
        if key not in self._cache:
            num = self.series[key]
            den = self.series[(panel, "two_particle", *_two_disk_reading(reading))]
            self._cache[key] = paired_ratio(
                num, den, rng=np.random.default_rng(BOOT_SEED), n_boot=N_BOOT,
                resamples=self._resamples, draws=True)
        return self._cache[key]

    def readings(self, panel: str, system: str) -> list[tuple]:
        return [k[2:] for k in self.series if k[0] == panel and k[1] == system]


def ratio_table(ratios: Ratios, panels) -> pd.DataFrame:
    """One row per panel, kicked system and reading: the ratio, its CI and verdict, with
    the verdict by the paper's reading and whether every reading gives it
    (``robust``, `kicktimes.stats.robust_verdict`)."""
    out = []
    for p in panels:
        for system in _KICKED:
            group = []
            for reading in ratios.readings(p.name, system):
                _, overall, _ = ratios.ratio(p.name, system, reading)
                lo, hi = overall["ci_low"], overall["ci_high"]
                group.append({
                    "family": p.name, "figure": p.figure, "diagnostic": "ftle",
                    "question": "FTLE by each reading of eq. (4)",
                    "system": system, "control": reading_label(reading),
                    **dict(zip(_READING, reading, strict=True)),
                    "estimate": overall["ratio"], "ci_low": lo, "ci_high": hi,
                    "verdict": ratio_verdict(lo, hi), "n_ics": overall["n_ics"],
                    "n_radii": overall["n_radii"],
                })
            robust, reason = robust_verdict([g["verdict"] for g in group],
                                            [g["ci_low"] for g in group],
                                            [g["ci_high"] for g in group])
            for g in group:
                g["robust"] = bool(robust)
                g["depends_on"] = "" if robust else f"reading ({reason})"
            out.extend(group)
    return pd.DataFrame(out)


def per_radius_table(rows: pd.DataFrame, ratios: Ratios, panels) -> pd.DataFrame:
    """Per panel, radius, system and reading (horizon T): the mean FTLE over ICs, its SD,
    the paper's error bar (SD/10), and, for the kicked systems, the ratio to the two-disk
    mean with its CI."""
    rows = rows[rows["horizon"] == 1]
    stats = (rows.groupby(["panel", "radius", "system", "diagnostic", *_READING])["lam"]
             .agg(mean="mean", sd="std", n="count").reset_index())
    stats["paper_bar"] = stats["sd"] / 10.0
    parts = []
    for p in panels:
        for system in _KICKED:
            for reading in ratios.readings(p.name, system):
                per_r, _, _ = ratios.ratio(p.name, system, reading)
                per_r = per_r.rename(columns={"ratio": "ratio", "ci_low": "ratio_ci_low",
                                              "ci_high": "ratio_ci_high"})
                per_r = per_r.assign(panel=p.name, system=system, diagnostic="ftle",
                                     **dict(zip(_READING, reading, strict=True)))
                parts.append(per_r.drop(columns="n_pairs"))
    merged = stats.merge(pd.concat(parts, ignore_index=True), how="left",
                         on=["panel", "radius", "system", "diagnostic", *_READING])
    return merged.sort_values(["panel", "diagnostic", "system", *_READING, "radius"],
                              ignore_index=True)


def r1_table(rows: pd.DataFrame, panels) -> pd.DataFrame:
    """The autocorrelation of the paper's Fig. 8 compared two ways, per panel and kicked
    system: the ratio of the mean ``R_1`` (the quantity the paper plots, ``"r1"``) and of
    the mean decorrelation ``1 - R_1`` (kicktimes', ``"one_minus_r1"``), each kicked over
    two-disk with its CI and verdict under the same IC resamples. One control only (the
    paper's sampling of the boundary angles over ``[0, n tau]``): ``robust`` is False."""
    sel = rows[(rows["diagnostic"] == "r1") & (rows["horizon"] == 1)]
    series = {k: g.set_index(["radius", "ic"])["lam"].sort_index()
              for k, g in sel.groupby(["panel", "system"])}
    out, resamples = [], {}
    for p in panels:
        for system in _KICKED:
            num, den = series[(p.name, system)], series[(p.name, "two_particle")]
            for diagnostic, a, b in (("r1", num, den), ("one_minus_r1", 1.0 - num, 1.0 - den)):
                _, overall = paired_ratio(a, b, rng=np.random.default_rng(BOOT_SEED),
                                          n_boot=N_BOOT, resamples=resamples)
                lo, hi = overall["ci_low"], overall["ci_high"]
                out.append({"family": p.name, "figure": p.figure, "diagnostic": diagnostic,
                            "question": "autocorrelation of the boundary angles",
                            "system": system, "control": "paper_protocol",
                            "estimate": overall["ratio"], "ci_low": lo, "ci_high": hi,
                            "verdict": ratio_verdict(lo, hi), "robust": False,
                            "depends_on": "one control only", "n_ics": overall["n_ics"],
                            "n_radii": overall["n_radii"]})
    return pd.DataFrame(out)


def rr_table(rows: pd.DataFrame, panels, small_radius: float) -> pd.DataFrame:
    """The recurrence rate of the paper's Fig. 7 compared two ways, per panel, kicked system
    and set of radii (``r <= small_radius``, the larger ones, each radius): the ratio of the
    mean RR with the main diagonal (the paper's formula, ``"rr_with_diagonal"``) and
    without it (``"rr_offdiag"``), kicked over two-disk, on the paper's steps, with CIs
    and verdicts under shared IC resamples. ``diagonal_share``: the part ``1/N`` of the
    two-disk mean RR with the diagonal (``N = n + 1`` samples)."""
    sel = rows[rows["diagnostic"] == "rr"]
    series = {k: g.set_index(["radius", "ic"])["lam"].sort_index()
              for k, g in sel.groupby(["panel", "system", "measure"])}
    out, resamples = [], {}
    for p in panels:
        subsets = {"small_radii": [r for r in p.radii if r <= small_radius],
                   "larger_radii": [r for r in p.radii if r > small_radius]}
        for system in _KICKED:
            for measure, diagnostic in (("with_diagonal", "rr_with_diagonal"),
                                        ("off_diagonal", "rr_offdiag")):
                num, den = series[(p.name, system, measure)], series[(p.name, "two_particle",
                                                                      measure)]
                per_r, _ = paired_ratio(num, den, rng=np.random.default_rng(BOOT_SEED),
                                        n_boot=N_BOOT, resamples=resamples)
                for name, radii in subsets.items():
                    if not radii:
                        continue
                    keep = num.index.get_level_values("radius").isin(radii)
                    _, overall = paired_ratio(num[keep], den[keep],
                                              rng=np.random.default_rng(BOOT_SEED),
                                              n_boot=N_BOOT, resamples=resamples)
                    two = den[keep].groupby(level="radius").mean()
                    lo, hi = overall["ci_low"], overall["ci_high"]
                    per = per_r[per_r["radius"].isin(radii)]
                    out.append({
                        "family": p.name, "figure": p.figure, "diagnostic": diagnostic,
                        "question": "recurrence rate on the paper's steps",
                        "system": system, "control": name,
                        "radii": f"{min(radii):g}-{max(radii):g}",
                        "estimate": overall["ratio"], "ci_low": lo, "ci_high": hi,
                        "verdict": ratio_verdict(lo, hi), "robust": False,
                        "depends_on": "one control only", "n_ics": overall["n_ics"],
                        "n_radii": overall["n_radii"],
                        "lowest_radius_ratio": float(per["ratio"].min()),
                        "highest_radius_ratio": float(per["ratio"].max()),
                        "diagonal_share": float((1.0 / (p.n_steps + 1) / two).mean())
                        if measure == "with_diagonal" else math.nan,
                    })
    return pd.DataFrame(out)


def shapley_table(ratios: Ratios, panels) -> pd.DataFrame:
    """Per panel and kicked system, each choice's Shapley share of the change in the
    distance from 1, ``|log R|``, from kicktimes' reading (renormalised, paper measure,
    shared, uniform) to the reading with every choice switched, with 95 % CIs from the
    shared resamples."""
    out = []
    for p in panels:
        for system in _KICKED:
            point, boot = {}, {}
            for k in range(len(FACTORS) + 1):
                for s in itertools.combinations(range(len(FACTORS)), k):
                    reading = tuple(FACTORS[i][2] if i in s else FACTORS[i][1]
                                    for i in range(len(FACTORS))) + ("uniform",)
                    _, overall, draws = ratios.ratio(p.name, system, reading)
                    point[frozenset(s)] = abs(math.log(overall["ratio"]))
                    with np.errstate(invalid="ignore", divide="ignore"):
                        boot[frozenset(s)] = np.abs(np.log(draws))
            phi, phi_boot = shapley_values(point, 3), shapley_values(boot, 3)
            total = point[frozenset(range(len(FACTORS)))] - point[frozenset()]
            for (column, default, alternative), value, draws in zip(FACTORS, phi, phi_boot,
                                                                   strict=True):
                lo, hi = percentile_interval(draws)
                out.append({
                    "family": p.name, "system": system, "choice": column,
                    "from": default, "to": alternative, "share": value,
                    "ci_low": float(lo), "ci_high": float(hi),
                    "fraction_of_change": value / total,
                    "verdict": share_verdict(lo, hi, 0.0),
                    "distance_from": point[frozenset()],
                    "distance_to": point[frozenset(range(len(FACTORS)))],
                })
    return pd.DataFrame(out)


def convergence_table(rows: pd.DataFrame, panels) -> pd.DataFrame:
    """The paper's reading and Benettin's at ``T, 2T, 4T, 8T`` on the convergence subset
    (each panel's ``convergence_radii`` and first ``convergence_ics`` ICs): the ratio with
    its CI and verdict, and the two-disk mean FTLE."""
    out = []
    for p in panels:
        sub = rows[rows["radius"].isin(p.convergence_radii) & (rows["ic"] < p.convergence_ics)
                   & (rows["panel"] == p.name)]
        for factor in CONVERGENCE:
            ratios = Ratios(sub, horizon=factor)
            for estimator in ("literal", "renormalised"):
                reading = (estimator, "paper", "shared", "uniform")
                two = sub[(sub["horizon"] == factor) & (sub["system"] == "two_particle")
                          & (sub["estimator"] == estimator) & (sub["measure"] == "paper")]
                for system in _KICKED:
                    _, overall, _ = ratios.ratio(p.name, system, reading)
                    lo, hi = overall["ci_low"], overall["ci_high"]
                    out.append({
                        "family": p.name, "estimator": estimator, "system": system,
                        "horizon": factor, "n_steps": factor * p.n_steps,
                        "estimate": overall["ratio"], "ci_low": lo, "ci_high": hi,
                        "verdict": ratio_verdict(lo, hi),
                        "two_particle_mean": float(two["lam"].mean()),
                        "n_ics": overall["n_ics"], "n_radii": overall["n_radii"],
                    })
    return pd.DataFrame(out)


