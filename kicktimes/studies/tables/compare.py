r"""The tables study's comparisons: the kicked / two-disk FTLE ratio in each table, and each
table's ratio against the circle's.

* `findings` -- per table, the sweep report's findings (`kicktimes.report.build_report`,
  the estimators and verdict rules of the circle's pages): every kicked system's FTLE,
  recurrence and decorrelation ratio to the two disks under their controls (the paired
  median, the sticky runs left out, the paper's samples for the recurrence), the Poisson
  question of the two disks' collision times against its null streams, the collision
  counts against the table's kinetic rate (`kicktimes.stats.kinetic_rate`); the elastic
  store folded in as the collision rule's control by
  `kicktimes.report.controls.merge_control_families`.
* `against_circle` -- the question of the study: does the kicked disk's FTLE deficit
  depend on the table's integrability? Per kicked system, the table's ratio over the
  circle's,

  .. math::  Q_T = \frac{\bar\rho_T}{\bar\rho_{\rm circle}}, \qquad
             \bar\rho_T = \frac1R \sum_r \frac{\sum_i \lambda^{\rm kicked}_{ri}}
                                          {\sum_i \lambda^{\rm two}_{ri}} ,

  with a percentile interval from the two tables' independent bootstraps clustered on
  ICs (`kicktimes.stats.paired_ratio` with ``draws=True``; the tables' ICs are
  independent draws, so the replicates divide pairwise). ``Q = 1`` within the FTLE's
  margin (`kicktimes.stats.margin_of`): the deficit is the circle's whatever the table;
  ``Q > 1``: the table's own stretching hides it. Its controls: the elastic rule, the
  sticky runs left out.

* `against_free` -- each system's FTLE over the free disk's in the same table (the mean
  over ICs and radii over the free disk's mean over states and radii; the two
  independent bootstraps divide): whether the perturbations add stretching to the table's
  own or remove some of it.

The findings tables have the columns of every findings table (`kicktimes.report.controls.COLUMNS`);
``verdict`` is read at ±10 % (the lint's band), ``verdict_at_margin`` at the FTLE's ±5 %,
``robust`` over the controls (`kicktimes.report.controls.with_robustness`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.report.controls import COLUMNS, merge_control_families, with_robustness
from kicktimes.report.counts import sticky_ics
from kicktimes.report.store import REFERENCE, wide
from kicktimes.stats import (
    cluster_bootstrap,
    margin_of,
    paired_ratio,
    percentile_interval,
    ratio_verdict,
)
from kicktimes.studies.tables.sweep import RULES, SEED, TABLES, family_name

__all__ = ["KICKED", "N_BOOT", "against_circle", "against_free", "elastic_speeds", "findings",
           "mean_ftle", "null_levels", "per_ic"]

#: the kicked systems of the sweep, as the pages name them
KICKED = {"poisson": "uniform kicks at Poisson times",
          "actual": "uniform kicks at the two disks' collision times",
          "poisson_scatter": "scattering kicks at Poisson times"}
N_BOOT = 2000
#: the control each collision rule's store stands for
_CONTROL = {"mirror": "primary", "elastic": "elastic"}


def findings(report_dir, stores) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The sweep report's findings of every store (module docstring), read from
    ``report_dir`` (`kicktimes.report.build_report` of the stores: ``<name>_findings.csv``
    and ``<name>_findings_by_radius.csv``), the elastic stores folded into their table's
    family. ``stores`` is ``{(table, rule): Store}``; out the findings table (`COLUMNS`)
    and its ratios per radius (with ``table, rule``)."""
    from pathlib import Path

    report_dir = Path(report_dir)
    tables, curves = [], []
    for (table, rule), store in sorted(stores.items()):
        name = store.experiment.name
        tables.append(pd.read_csv(report_dir / f"{name}_findings.csv"))
        curves.append(pd.read_csv(report_dir / f"{name}_findings_by_radius.csv")
                      .assign(table=table, rule=rule))
    merged = merge_control_families(tables)
    table = pd.concat([merged[family_name(t, "mirror")] for t in TABLES if
                       family_name(t, "mirror") in merged], ignore_index=True)
    return table, pd.concat(curves, ignore_index=True)


def mean_ftle(runs, *, per_radius=False, n_boot=N_BOOT, seed=SEED) -> pd.DataFrame:
    """Per (table, rule, system): the mean FTLE over ICs and radii (``per_radius``: per
    radius too), with its 95 % interval from the bootstrap clustered on ICs
    (`kicktimes.stats.cluster_bootstrap`; one IC's radii resampled together)."""
    rows = []
    keys = ["table", "rule", "radius"] if per_radius else ["table", "rule"]
    for k, (key, g) in enumerate(runs.groupby(keys, sort=True)):
        for system in (REFERENCE, *KICKED):
            lam = g.pivot_table(index="ic", columns="radius", values=system).to_numpy()
            est, draws = _mean_draws(lam, rng=np.random.default_rng([seed, k]), n_boot=n_boot)
            low, high = percentile_interval(draws)
            rows.append({**dict(zip(keys, key, strict=True)), "system": system,
                         "n_ics": lam.shape[0], "ftle": est, "ci_low": low, "ci_high": high})
    return pd.DataFrame(rows)


def per_ic(stores) -> pd.DataFrame:
    """One row per (table, rule, radius, IC): each system's FTLE and whether the IC's
    two-disk run is sticky (`kicktimes.report.counts.sticky_ics`)."""
    parts = []
    for (table, rule), store in sorted(stores.items()):
        lam = wide(store.results, "lyapunov")
        sticky = sticky_ics(store.collisions, rule, kinetic=store.experiment.kinetic_rate)
        sticky = sticky.set_index(["radius", "ic"])["sticky"].reindex(lam.index,
                                                                     fill_value=False)
        parts.append(lam.assign(sticky=sticky.to_numpy(bool), table=table, rule=rule)
                     .reset_index())
    return pd.concat(parts, ignore_index=True)


def _ratio_draws(block, system, *, rng, n_boot):
    """``(estimate, draws)`` of one table's kicked / two-disk ratio (`paired_ratio`)."""
    frame = block.set_index(["radius", "ic"])
    _, overall, draws = paired_ratio(frame[system], frame[REFERENCE], rng=rng, n_boot=n_boot,
                                     draws=True)
    return overall["ratio"], draws


def against_circle(runs, *, reference="circle", n_boot=N_BOOT, seed=SEED) -> pd.DataFrame:
    """Each table's kicked / two-disk FTLE ratio over the circle's, per kicked system,
    under its controls (module docstring); ``runs`` is `per_ic`'s table.

    Returns
    -------
    pandas.DataFrame
        `COLUMNS` (``family`` is ``tables_<table>``, ``diagnostic`` ``ftle_vs_circle``),
        with ``ratio`` and ``reference_ratio``, the two ratios it divides.
    """
    tol = margin_of("ftle")
    rows = []
    tables = [t for t in TABLES if t != reference and t in set(runs["table"])]
    for system in KICKED:
        for rule in RULES:
            for control in ((_CONTROL[rule], "sticky_excluded") if rule == "mirror"
                            else (_CONTROL[rule],)):
                part = runs[runs["rule"] == rule]
                if control == "sticky_excluded":
                    part = part[~part["sticky"]]
                # one stream per (table, rule, control): the tables' bootstraps are independent
                streams = {t: np.random.default_rng([seed, k, RULES.index(rule),
                                                     control == "sticky_excluded"])
                           for k, t in enumerate(TABLES)}
                ref, ref_draws = _ratio_draws(part[part["table"] == reference], system,
                                              rng=streams[reference], n_boot=n_boot)
                for t in tables:
                    est, draws = _ratio_draws(part[part["table"] == t], system,
                                              rng=streams[t], n_boot=n_boot)
                    low, high = percentile_interval(draws / ref_draws)
                    n_sticky = int(runs[(runs["rule"] == rule)
                                        & runs["table"].isin([t, reference])]["sticky"].sum())
                    rows.append({
                        "family": family_name(t, "mirror"),
                        "question": "FTLE ratio against the circle's", "diagnostic":
                        "ftle_vs_circle", "system": system, "control": control,
                        "estimate": est / ref, "ci_low": low, "ci_high": high,
                        "verdict": ratio_verdict(low, high), "margin": tol,
                        "verdict_at_margin": ratio_verdict(low, high, tolerance=tol),
                        "robust": False, "depends_on": "",
                        "n_pairs": int((part["table"] == t).sum()),
                        "detail": (f"{rule} rule; {t} {est:.4g} over circle {ref:.4g}"
                                   + (f"; {n_sticky} sticky runs left out"
                                      if control == "sticky_excluded" else "")),
                        "ratio": est, "reference_ratio": ref})
    out = pd.DataFrame(rows, columns=[*COLUMNS, "ratio", "reference_ratio"])
    return with_robustness(out)


def _mean_draws(values, *, rng, n_boot):
    """``(mean, draws)``: the mean of a ``(clusters, radii)`` matrix over both axes and its
    bootstrap replicates, clusters resampled with their radii (`cluster_bootstrap`)."""
    boot = cluster_bootstrap(lambda idx: np.nanmean(values[idx], axis=(1, 2)),
                             values.shape[0], n_boot=n_boot, rng=rng)
    return boot.estimate, boot.replicates


def against_free(runs, free, *, n_boot=N_BOOT, seed=SEED) -> pd.DataFrame:
    """Each system's mean FTLE over the free disk's in the same table, per (table, rule,
    system), at the sweep's radii (module docstring); ``runs`` is `per_ic`'s table,
    ``free`` `kicktimes.studies.tables.one_disk.free_runs`'s.

    Returns
    -------
    pandas.DataFrame
        ``table, rule, system, ftle, free_ftle, estimate, ci_low, ci_high, verdict,
        verdict_at_margin`` (the ratio's 95 % interval; verdicts at ±10 % and at the FTLE's
        margin).
    """
    tol = margin_of("ftle")
    radii = sorted(runs["radius"].unique())
    rows = []
    for k, table in enumerate(t for t in TABLES if t in set(runs["table"])):
        f = free[(free["table"] == table) & free["radius"].isin(radii)]
        lam_free = f.pivot_table(index="state", columns="radius", values="ftle").to_numpy()
        base, base_draws = _mean_draws(lam_free, rng=np.random.default_rng([seed, k, 9]),
                                       n_boot=n_boot)
        for j, rule in enumerate(RULES):
            g = runs[(runs["table"] == table) & (runs["rule"] == rule)]
            for i, system in enumerate((REFERENCE, *KICKED)):
                lam = g.pivot_table(index="ic", columns="radius", values=system).to_numpy()
                est, draws = _mean_draws(lam, rng=np.random.default_rng([seed, k, j, i]),
                                         n_boot=n_boot)
                low, high = percentile_interval(draws / base_draws)
                rows.append({"table": table, "rule": rule, "system": system, "ftle": est,
                             "free_ftle": base, "estimate": est / base, "ci_low": low,
                             "ci_high": high, "verdict": ratio_verdict(low, high),
                             "verdict_at_margin": ratio_verdict(low, high, tolerance=tol)})
    return pd.DataFrame(rows)


def elastic_speeds(stores, *, system="poisson") -> pd.DataFrame:
    """Under the elastic rule the disks' speeds differ from IC to IC (they share the pair's
    energy) and the kicked disk keeps disk 0's: per (table, radius) of the elastic stores,
    the range of that speed over the ICs and the correlation over ICs of the kicked FTLE
    (``system``) and of the two-disk FTLE with it."""
    from kicktimes import initial_conditions

    rows = []
    for (table, rule), store in sorted(stores.items()):
        if rule != "elastic":
            continue
        exp = store.experiment
        ics = initial_conditions(exp.n_ics, exp.ic_radius, rng=exp.seed, method=exp.ic_method,
                                 rule=rule, table=exp.table_value)
        speed = np.hypot(ics[:, 0, 2], ics[:, 0, 3])
        lam = wide(store.results, "lyapunov")
        for r, g in lam.groupby(level="radius"):
            g = g.droplevel("radius").reindex(np.arange(exp.n_ics))
            ok = np.isfinite(g[system]) & np.isfinite(g[REFERENCE])
            rows.append({"table": table, "radius": float(r), "speed_min": float(speed.min()),
                         "speed_max": float(speed.max()),
                         "kicked_corr": float(np.corrcoef(speed[ok], g[system][ok])[0, 1]),
                         "two_disk_corr": float(np.corrcoef(speed[ok], g[REFERENCE][ok])[0, 1])})
    return pd.DataFrame(rows)


def null_levels(report_dir, stores) -> pd.DataFrame:
    """Per (table, rule): the sweep report's null calibration (``<name>_null_calibration.csv``,
    `kicktimes.report.poisson.null_calibration`: the runs' Poisson control streams through
    the same tests and statistics), with ``table`` and ``rule``: the levels the Poisson rows
    of `findings` are read against."""
    from pathlib import Path

    parts = [pd.read_csv(Path(report_dir) / f"{store.experiment.name}_null_calibration.csv",
                         keep_default_na=False, na_values=[""]).assign(table=table, rule=rule)
             for (table, rule), store in sorted(stores.items())]
    return pd.concat(parts, ignore_index=True)
