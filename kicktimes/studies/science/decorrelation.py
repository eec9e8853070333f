r"""Decorrelation per single perturbation, and which kick law comes closest.

`decorrelation` measures the correlation of the boundary angle across exactly one
perturbation (a disk-disk collision, a uniform kick, a scatter kick, none) under a
collision rule, and the kicked / two-disk ratio of 1 - R1 it predicts;
`prediction_against_measurement` sets that prediction beside the ratio the paper
study's findings tables measured; `closest_kick_law` reads from those tables which kick
law comes closest to the two-disk value.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.billiard import KickLaw
from kicktimes.stats import MARGIN, percentile_interval, ratio_verdict, resample_indices
from kicktimes.studies.science.stretching import N_BOOT

__all__ = ["closest_kick_law", "decorrelation", "prediction_against_measurement"]


def _pairs(times, theta, events):
    """For consecutive wall hits (k, k+1): theta_k, theta_{k+1}, perturbations between."""
    between = np.searchsorted(events, times[1:]) - np.searchsorted(events, times[:-1])
    return theta[:-1], theta[1:], between


def _corr(per_ic, pick):
    aa = np.concatenate([per_ic[k][0] for k in pick])
    bb = np.concatenate([per_ic[k][1] for k in pick])
    return float(np.corrcoef(aa, bb)[0, 1]) if aa.size > 2 else math.nan


def decorrelation(radii=(0.008, 0.02), *, rule="mirror", n_ics=40, t_max=20000.0, seed=5,
                  n_boot=N_BOOT):
    r"""Correlation of the boundary angle across exactly one perturbation, per kind.

    For each kind (one disk-disk collision of disk 0, one uniform kick, one scatter kick,
    no perturbation) the Pearson correlation :math:`c` of the wall angle
    :math:`\theta_k = \arcsin(\sin\theta_k)` at the wall hits just before and just after,
    pooled over ICs. The kicked disks start from disk 0's IC and are kicked at Poisson
    times at their two-disk run's collision rate; under ``rule="elastic"`` the two disks
    exchange speed and the scatter kick meets a virtual partner with the pair's energy.

    With as many perturbations per wall hit in both systems, the lag-1 autocorrelation
    of the angles falls by a factor :math:`c` per perturbation, so
    :math:`(1 - R_1)_{kicked} / (1 - R_1)_{two} \approx (1 - c_{kick}) / (1 - c_{coll})`:
    the **prediction** (``predicted``), with its interval from the same bootstrap over
    ICs (every kind resampled with the same ICs).
    """
    rows, bins_rows, preds = [], [], []
    edges = np.linspace(-np.pi / 2, np.pi / 2, 9)
    ics = initial_conditions(n_ics, max(radii), rng=seed)
    for r in radii:
        kinds = {"disk-disk collision": [], "uniform kick": [], "scatter kick": [],
                 "no perturbation": []}
        for i, ic in enumerate(ics):
            two = simulate_two_particle(ic, r, t_max=t_max, rule=rule)
            log = two.boundary_log
            mine = np.asarray(log.particle) == 0
            t0 = np.asarray(log.time)[mine]
            th0 = np.arcsin(np.clip(np.asarray(log.sin_theta)[mine], -1, 1))
            a, b, n = _pairs(t0, th0, np.asarray(two.pp_times))
            kinds["disk-disk collision"].append((a[n == 1], b[n == 1]))
            kinds["no perturbation"].append((a[n == 0], b[n == 0]))
            rate = two.n_pp / two.t_max
            e0 = 0.5 * float((ic[:, 2:] ** 2).sum()) if rule == "elastic" else None
            for name, kw in (("uniform kick", {"angle": "uniform"}),
                             ("scatter kick", {"angle": "scatter", "rule": rule, "e0": e0})):
                one = simulate_one_particle(ic[0], r, t_max=t_max, rng=1000 * i + len(name),
                                            kicks=KickLaw(schedules.Poisson(rate), **kw))
                lg = one.boundary_log
                th = np.arcsin(np.clip(np.asarray(lg.sin_theta), -1, 1))
                a, b, n = _pairs(np.asarray(lg.time), th, np.asarray(one.kick_times))
                kinds[name].append((a[n == 1], b[n == 1]))
        rng = np.random.default_rng(seed)
        picks = resample_indices(n_ics, n_boot=n_boot, rng=rng, with_identity=True)
        boot = {name: np.array([_corr(per_ic, p) for p in picks]) for name, per_ic in
                kinds.items()}
        for name, per_ic in kinds.items():
            a = np.concatenate([p[0] for p in per_ic])
            b = np.concatenate([p[1] for p in per_ic])
            lo, hi = percentile_interval(boot[name][1:])
            rows.append({"rule": rule, "radius": r, "perturbation": name,
                         "n_pairs": int(a.size), "correlation": boot[name][0], "ci_low": lo,
                         "ci_high": hi})
            which = np.digitize(a, edges[1:-1])
            for k in range(len(edges) - 1):
                sel = which == k
                bins_rows.append({"rule": rule, "radius": r, "perturbation": name,
                                  "theta_before_low": edges[k], "theta_before_high": edges[k + 1],
                                  "n": int(sel.sum()),
                                  "mean_theta_after": float(b[sel].mean()) if sel.any()
                                  else math.nan,
                                  "mean_abs_change": float(np.abs(b[sel] - a[sel]).mean())
                                  if sel.any() else math.nan})
        for name, system in (("uniform kick", "poisson"), ("scatter kick", "poisson_scatter")):
            p = (1 - boot[name]) / (1 - boot["disk-disk collision"])
            lo, hi = percentile_interval(p[1:])
            preds.append({"rule": rule, "radius": r, "system": system, "predicted": p[0],
                          "predicted_ci_low": lo, "predicted_ci_high": hi})
    return pd.DataFrame(rows), pd.DataFrame(bins_rows), pd.DataFrame(preds)


def prediction_against_measurement(preds, findings_dir, families):
    r"""The predicted ratios of 1 - R1 beside the measured ones, with their verdicts.

    ``families`` maps a rule to the family store whose by-radius findings table
    (``<family>_findings_by_radius.csv`` in ``findings_dir``, control ``primary``) holds
    the measured kicked / two-disk ratio of 1 - R1. The quotient measured / predicted gets
    a 95 % interval from the two independent intervals (different ICs), each read as
    normal on the log scale: :math:`\sigma = (\ln hi - \ln lo) / (2 \cdot 1.96)`,
    combined in quadrature; its `ratio_verdict` decides whether the one-collision
    prediction agrees with the measurement to 10 %.
    """
    rows = []
    for row in preds.itertuples():
        family = families[row.rule]
        path = Path(findings_dir) / f"{family}_findings_by_radius.csv"
        if not path.is_file():
            raise ValueError(f"findings_dir: {path} is missing (the paper study writes it: "
                             "kicktimes reproduce --study paper --results DIR)")
        tab = pd.read_csv(path)
        m = tab[(tab["diagnostic"] == "one_minus_r1") & (tab["system"] == row.system)
                & (tab["control"] == "primary") & np.isclose(tab["radius"], row.radius)]
        if len(m) != 1:
            raise ValueError(f"findings_dir: no single 1 - R1 row for {row.system} at "
                             f"r = {row.radius:g} in {path.name}")
        m = m.iloc[0]
        q = m["ratio"] / row.predicted
        sd = math.hypot(*(math.log(h / lo) / (2 * 1.96) for lo, h in
                          ((m["ci_low"], m["ci_high"]),
                           (row.predicted_ci_low, row.predicted_ci_high))))
        q_lo, q_hi = q * math.exp(-1.96 * sd), q * math.exp(1.96 * sd)
        rows.append({**row._asdict(), "family": family, "measured": m["ratio"],
                     "measured_ci_low": m["ci_low"], "measured_ci_high": m["ci_high"],
                     "measured_verdict": ratio_verdict(m["ci_low"], m["ci_high"], tolerance=MARGIN),
                     "measured_over_predicted": q, "quotient_ci_low": q_lo,
                     "quotient_ci_high": q_hi,
                     "quotient_verdict": ratio_verdict(q_lo, q_hi, tolerance=MARGIN)})
    out = pd.DataFrame(rows)
    return out.drop(columns=[c for c in out.columns if c == "Index"])


def closest_kick_law(findings_dir, families, diagnostics=("ftle", "one_minus_r1"),
                     systems=("poisson", "actual", "poisson_scatter", "actual_scatter")):
    r"""Which kick law comes closest to the two-disk value, per family and diagnostic.

    From the pooled findings (``<family>_findings.csv``, control ``primary``): the
    distance of a ratio from 1 is :math:`|\ln \text{ratio}|`, its interval the image of
    the ratio's interval. The *closest group* is the law with the lowest upper distance
    and every law whose distance interval reaches below that upper end (not distinguished
    from it); a single law in the group *comes closest*. ``closest`` marks the group.
    Overlapping distance intervals are not agreement: ``disjoint_under`` lists, for each
    member of the group, the controls of the table (every row of the same family and
    diagnostic, primary included) under which its ratio interval and the best law's are
    disjoint (``""`` for the best law and where they overlap under every control).
    """
    rows = []
    for family in families:
        tab = pd.read_csv(Path(findings_dir) / f"{family}_findings.csv")
        for diag in diagnostics:
            part = tab[(tab["diagnostic"] == diag) & (tab["control"] == "primary")
                       & tab["system"].isin(systems)].set_index("system")
            dist = {}
            for s, g in part.iterrows():
                ends = np.abs(np.log([g["ci_low"], g["ci_high"]]))
                inside = g["ci_low"] <= 1 <= g["ci_high"]
                dist[s] = (0.0 if inside else ends.min(), ends.max())
            best = min(dist, key=lambda s: dist[s][1])
            every = tab[(tab["diagnostic"] == diag) & tab["system"].isin(systems)]
            for s, g in part.iterrows():
                disjoint = []
                if s != best:
                    for control, c in every.groupby("control", sort=False, observed=True):
                        c = c.set_index("system")
                        if s in c.index and best in c.index and (
                                c.loc[s, "ci_high"] < c.loc[best, "ci_low"]
                                or c.loc[s, "ci_low"] > c.loc[best, "ci_high"]):
                            disjoint.append(control)
                rows.append({"family": family, "diagnostic": diag, "system": s,
                             "ratio": g["estimate"], "ci_low": g["ci_low"],
                             "ci_high": g["ci_high"],
                             "verdict": g.get("verdict_at_margin", g["verdict"]),
                             "distance_low": dist[s][0], "distance_high": dist[s][1],
                             "closest": bool(dist[s][0] <= dist[best][1]),
                             "disjoint_under": ", ".join(disjoint)})
    return pd.DataFrame(rows)
