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
    resample_indices,
    robust_verdict,
    shapley_values,
)
from kicktimes.stats.findings import share_verdict
from kicktimes.studies.protocol.compute import CONVERGENCE
from kicktimes.studies.protocol.verdicts import residual_verdict

__all__ = ["BOOT_SEED", "FACTORS", "N_BOOT", "PAPER_READING", "Ratios", "convergence_table",
           "count_line_table", "fig4_table", "figure_of", "per_radius_table", "r1_table",
           "ratio_table", "reading_label", "rr_table", "shapley_table"]

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


def figure_of(panel, number: int, *, small: bool | None = None) -> str:
    """The paper's figure of a panel's diagnostic: ``"Fig. 6 top"`` (FTLE, ``number`` 6)
    and ``"Fig. 8 bottom"`` (autocorrelation, 8) follow the panel; the recurrence rate's
    Fig. 7 (``number`` 7) shows family A only, all radii on top and the small radii
    (``small``) at the bottom, so family B's RR has no figure (``"none (Fig. 7: A only)"``).

    Examples
    --------
    >>> from kicktimes.studies.protocol.compute import panels
    >>> a, b = panels("quick")
    >>> figure_of(a, 8), figure_of(a, 7, small=True), figure_of(b, 7, small=False)
    ('Fig. 8 top', 'Fig. 7 bottom', 'none (Fig. 7: A only)')
    """
    if number not in (6, 7, 8):
        raise ValueError(f"number must be 6, 7 or 8 (the paper's Figs. 6-8), got {number!r}")
    if number != 7:
        return panel.figure.replace("Fig. 6", f"Fig. {number}")
    if small is None:
        raise ValueError("small: the RR's panel of Fig. 7 depends on the radii (True/False)")
    if panel.figure != "Fig. 6 top":
        return "none (Fig. 7: A only)"
    return "Fig. 7 bottom" if small else "Fig. 7 top"


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
                out.append({"family": p.name, "figure": figure_of(p, 8),
                            "diagnostic": diagnostic,
                            "question": "autocorrelation of the boundary angles, t ≤ nτ",
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
                        "family": p.name, "figure": figure_of(p, 7, small=name == "small_radii"),
                        "diagnostic": diagnostic,
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


def _counts(rows, panel, diagnostic="r1", system="two_particle", column="n_kicks"):
    """(radii, matrix radius x IC) of ``column`` of one panel's rows."""
    sel = rows[(rows["panel"] == panel.name) & (rows["diagnostic"] == diagnostic)
               & (rows["system"] == system) & (rows["horizon"] == 1)]
    wide = sel.pivot_table(index="radius", columns="ic", values=column).sort_index()
    return wide.index.to_numpy(float), wide.to_numpy(float)


def count_line_table(rows: pd.DataFrame, panels) -> pd.DataFrame:
    r"""The paper's Fig. 5 by its protocol, per panel: the least-squares line through the
    mean two-disk collision count over ``[0, n tau]`` at each radius, :math:`\bar N(r)
    \approx a + b r`, and how far the means lie from it: the RMS relative residual

    .. math:: s = \Big[\frac{1}{R} \sum_r \big(\bar N(r) / (a + b r) - 1\big)^2\Big]^{1/2},

    with its 95 % CI over IC resamples (the line refitted in each). Verdict:
    `kicktimes.studies.protocol.verdicts.residual_verdict`, ``s`` against 10 % (*residual
    below 10 %*: the CI of ``s`` lies below 0.1, the means within 10 % of their line in RMS;
    *residual above 10 %*: above it).
    A panel with fewer than 3 radii has no row (a line through 2 points fits exactly)."""
    out = []
    for p in panels:
        radii, counts = _counts(rows, p)
        if radii.size < 3:
            continue
        if not np.isfinite(counts).all():
            raise ValueError(f"rows: panel {p.name} has a missing or non-finite count")
        idx = resample_indices(counts.shape[1], n_boot=N_BOOT, rng=np.random.default_rng(BOOT_SEED),
                               with_identity=True)
        means = counts[:, idx].mean(axis=2).T  # (1 + B, radii)
        design = np.column_stack([np.ones_like(radii), radii])
        coef = np.linalg.lstsq(design, means.T, rcond=None)[0]  # (2, 1 + B)
        rms = np.sqrt(((means / (design @ coef).T - 1.0) ** 2).mean(axis=1))
        lo, hi = percentile_interval(rms[1:])
        out.append({"family": p.name, "figure": "Fig. 5", "diagnostic": "count_line",
                    "question": "RMS relative residual of the mean counts about their line",
                    "estimate": float(rms[0]), "ci_low": float(lo), "ci_high": float(hi),
                    "verdict": residual_verdict(lo, hi),
                    "intercept": float(coef[0, 0]), "slope": float(coef[1, 0]),
                    "n_radii": int(radii.size), "n_ics": int(counts.shape[1])})
    return pd.DataFrame(out)


def fig4_table(rows: pd.DataFrame, panels) -> pd.DataFrame:
    """The paper's Fig. 4 by its protocol, per panel at its smallest radius: the mean over
    ICs of the slope of the least-squares line of the Poisson kick times against the
    two-disk collision times (`compute.times_rows`), with its 95 % CI (bootstrap over ICs)
    and `kicktimes.stats.ratio_verdict` (the kicks keep the collisions' pace within 10 %),
    and beside it the mean R² of those lines with its CI. A panel without a finite Fig. 4
    row (no rows, or every IC with fewer than 3 collisions) has no row."""
    out = []
    for p in panels:
        values, n = {}, 0
        for name in ("fig4_slope", "fig4_r2"):
            radii, v = _counts(rows, p, name, "poisson", "lam")
            if radii.size == 0:
                break
            v = v[0][np.isfinite(v[0])]
            n = n or v.size
            idx = resample_indices(v.size, n_boot=N_BOOT, rng=np.random.default_rng(BOOT_SEED))
            values[name] = (float(v.mean()), *percentile_interval(v[idx].mean(axis=1)))
        if len(values) < 2:
            continue
        (est, lo, hi), (r2, r2_lo, r2_hi) = values["fig4_slope"], values["fig4_r2"]
        out.append({"family": p.name, "figure": "Fig. 4", "diagnostic": "fig4_slope",
                    "question": "slope of Poisson kick times on collision times",
                    "radius": float(radii[0]), "estimate": est, "ci_low": float(lo),
                    "ci_high": float(hi), "verdict": ratio_verdict(lo, hi), "r2": r2,
                    "r2_ci_low": float(r2_lo), "r2_ci_high": float(r2_hi), "n_ics": int(n)})
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
                    "verdict": share_verdict(lo, hi, level=0.0),
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


