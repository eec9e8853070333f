"""docs/results/disks.md: from two disks to a gas, written from the disks stores.

`write_disks_page` reads the stores of the `kicktimes.experiment.DISKS_PRESETS` sweeps,
their controls (`DISKS_CONTROLS`) and the two-disk references, computes their tables
(`kicktimes.studies.disks.tables`; every statistic against Poisson streams shaped like the
runs, `kicktimes.studies.disks.versus_null`; the one answer to "Poisson?",
`kicktimes.studies.disks.readings.poisson_answer`; the findings under their controls,
`kicktimes.studies.disks.controls`; the renewal models, `kicktimes.studies.disks.renewal`;
the kicked comparison, `kicktimes.studies.disks.kicked`), writes them as CSV beside the
page, draws the figures (`kicktimes.studies.disks.figures`) and writes the page: five
one-line answers, the table at the largest N, the rule, then D against its null at every
N, the figures and one line per further check, each pointing to its CSV.
`kicktimes.studies.disks.run.reproduce_disks` runs (or resumes) the sweeps and the gas's
FTLE computations first: ``kicktimes reproduce --study disks``. The page closes with the
table of where its numbers come from (`kicktimes.render.pages.write_results_page`).
"""

from __future__ import annotations

import datetime as _dt
import time
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes import __version__
from kicktimes.render.pages import write_results_page
from kicktimes.render.provenance import Source
from kicktimes.stats import (
    D_MARGIN,
    format_interval,
    paired_ratio,
    percentile_interval,
    rejection_verdict,
    share_ratio_sample_size,
)
from kicktimes.studies.disks.boltzmann import boltzmann_lines, boltzmann_table
from kicktimes.studies.disks.controls import (
    BULK_WITHIN,
    CONTROL_NAMES,
    FINDINGS,
    controls_findings,
    controls_lines,
)
from kicktimes.studies.disks.density import one_state as density_state
from kicktimes.studies.disks.density import summarise as density_summary
from kicktimes.studies.disks.figures import (
    ALPHA,
    controls_figure,
    hazard_figure,
    rates_figure,
    rejection_figure,
)
from kicktimes.studies.disks.ftle_check import pair as ftle_check_pair
from kicktimes.studies.disks.kicked import kicked_rate_check
from kicktimes.studies.disks.null import calibration_rows, null_rows
from kicktimes.studies.disks.readings import (
    ANSWER_RULE,
    answer_table,
    diff_text,
    family_table,
    opening_lines,
    poisson_answer,
    summary_lines,
)
from kicktimes.studies.disks.renewal import renewal_models
from kicktimes.studies.disks.tables import (
    PEAK_MIN_SHARE,
    RATE_MARGIN,
    disks_hazard,
    disks_table,
    kicked_table,
    sweep_cost,
    two_disk_check,
)
from kicktimes.studies.disks.versus_null import (
    MARGINS,
    aic_margin,
    bin_rows,
    edge_null_verdict,
    versus_null,
)
from kicktimes.studies.disks.windows import summarise as windows_summary

__all__ = ["ELASTIC_SOURCES", "REPLICATE_SOURCE", "SOURCES", "replicate_rows", "sources",
           "write_disks_page"]

#: the controls figure shows N from here on
CONTROLS_MIN_N = 10
#: the verdict of a rate within its margin of Enskog's
RATE_WITHIN = f"within {100 * RATE_MARGIN:g} %"
#: the controls table's name of the collision rate over Enskog's
RATE_FINDING = next(name for name, spec in FINDINGS.items() if spec[0] == "rate_enskog")


def load_store_names(stores) -> list:
    """The names of the stores a page reads (disks_stores.csv's ``store``), in order."""
    return [st.experiment.name for st in stores]


def _holds_from(ns, ok):
    """The smallest N of ``ns`` (increasing) from which ``ok`` holds at every larger N, or
    None."""
    ok = np.asarray(ok, dtype=bool)
    return next((int(ns[m]) for m in range(len(ns)) if ok[m:].all()), None)


def _robust_from(long, finding, verdict):
    """The smallest N from which, in every geometry x rule, ``finding`` is robust under the
    controls with the primary ``verdict`` at every larger N (None: no such N)."""
    prim = long[(long["control"] == "primary") & (long["diagnostic"] == finding)]
    froms = []
    for _, g in prim.groupby("family", sort=False, observed=True):
        g = g.sort_values("n_disks")
        froms.append(_holds_from(g["n_disks"].to_numpy(),
                                 g["robust"].astype(bool) & g["verdict"].eq(verdict)))
    return max(froms) if froms and all(froms) else None


def _rate_from(table, long):
    """``(from_n, robust_from_n)``: the smallest N from which the rate is within
    `RATE_MARGIN` of Enskog's at every geometry and rule (primary design; under every
    control)."""
    froms = [_holds_from(g["n_disks"].to_numpy(), g["rate_enskog_verdict"].eq(RATE_WITHIN))
             for _, g in table.groupby(["geometry", "rule"], sort=False, observed=True)]
    robust = (_robust_from(long, RATE_FINDING, RATE_WITHIN)
              if long is not None and not long.empty else None)
    return (max(froms) if all(froms) else None), robust


def _rate_line(table, rate_from, robust_from):
    """The fifth answer: the collision rate against Enskog-Henderson."""
    big = table[table["n_disks"] == table["n_disks"].max()]
    worst = big.loc[(big["rate_enskog"] - 1.0).abs().idxmax()]
    n_top = int(table["n_disks"].max())
    at = (f"at N = {n_top}, the largest N run," if rate_from == n_top
          else f"from N = {rate_from} on")
    where = (f"within {100 * RATE_MARGIN:g} % {at} at every geometry and rule"
             if rate_from else f"not within {100 * RATE_MARGIN:g} % from one N on everywhere")
    robust = (" (not under every control)" if not robust_from else
              " (there under every control too)" if robust_from == rate_from == n_top else
              f" (under every control at N = {n_top}, the largest N run)"
              if robust_from == n_top else f" (under every control from N = {robust_from} on)")
    return (f"**Collision rate / Enskog:** {where}{robust}; farthest at N = "
            f"{int(worst['n_disks'])}: {worst['geometry']}, {worst['rule']} "
            + format_interval(worst["rate_enskog"], worst["rate_enskog_low"],
                              worst["rate_enskog_high"]) + ". "
            "Caveat: N = 2 against the two-disk rate Γ(r) instead.")


def replicate_rows(primary, replicate, *, n_boot=999) -> pd.DataFrame:
    """The replicate's D against the primary design's null D, per geometry, rule and N:
    ``replicate_d`` (its interval), ``replicate_diff`` = replicate D - primary null D and its
    interval from the two stores' bootstrap replicates (independent runs:
    `versus_null`'s replicates, differences of independent draws).

    Parameters
    ----------
    primary, replicate : dict
        ``{(geometry, rule): {n: (D replicates, null D replicates)}}``, the third item of
        `versus_null` of the primary store and of its replicate.
    """
    rows = []
    for key, reps in primary.items():
        if key not in replicate:
            continue
        rep = replicate[key]
        for n, (_, null_d) in reps.items():
            if n not in rep:
                continue
            d, _ = rep[n]
            m = min(d.size, null_d.size)
            low, high = percentile_interval(d[1:m] - null_d[1:m])
            d_low, d_high = percentile_interval(d[1:])
            rows.append({"geometry": key[0], "rule": key[1], "n_disks": int(n),
                         "replicate_d": float(d[0]), "replicate_d_low": float(d_low),
                         "replicate_d_high": float(d_high), "null_d": float(null_d[0]),
                         "replicate_diff": float(d[0] - null_d[0]),
                         "replicate_diff_low": float(low), "replicate_diff_high": float(high),
                         "replicate_verdict": edge_null_verdict(low, high, D_MARGIN)})
    return pd.DataFrame(rows)


def _margin_lines() -> list:
    """The margins, stated once: each the smallest effect the page means to detect."""
    return [
        "**Margins**, stated before the readings, each half the elastic linear Boltzmann "
        "tagged disk's own departure from Poisson in that statistic (the effect the page "
        f"must resolve): D ±{MARGINS['d']:g} (Boltzmann D∞ − 1 = 0.14), KS share "
        f"±{MARGINS['ks']:g} (Boltzmann 0.070 at K = 30, Poisson 0.05), gamma shape "
        f"±{MARGINS['gamma']:g} (Boltzmann 0.957), a hazard bin ±{MARGINS['hazard_first']:g} "
        "(Boltzmann h(0) = 1.064); the exponential's ΔAIC departs above what a gamma shape "
        f"1 − {MARGINS['gamma']:g} gives on as many intervals (2 n KL − 2), is at its null at "
        f"≤ 2; the rate over Enskog's ±{100 * RATE_MARGIN:g} % (half the contact value's "
        "g(σ) − 1 = 0.032 at packing 0.02).", ""]


def _hazard_lines(bins, vn) -> list:
    """The hazard against its null and against linear Boltzmann, bin by bin, at the
    largest N: counts and the largest departures."""
    n_max = int(bins["n_disks"].max())
    at = bins[bins["n_disks"] == n_max]
    dep = at[at["verdict"].isin(("above its null", "below its null"))]
    el = at[at["rule"] == "elastic"]
    b_at = int(el["boltzmann_verdict"].eq("at its null").sum())
    b_dep = int(el["boltzmann_verdict"].isin(("above its null", "below its null")).sum())
    big = vn[vn["n_disks"] == n_max]
    peak_null = ", ".join(f"{r['null_hazard_peak']:.3g}" for _, r in big.iterrows())
    lines = [
        "## The hazard against its null and linear Boltzmann", "",
        f"Every hazard bin against the null streams' (paired by run) and, elastic, "
        "linear Boltzmann's h(t) in that bin ([disks_hazard_null.csv]"
        f"(disks_hazard_null.csv), every N). At N = {n_max}: "
        f"{len(dep)} of {len(at)} bins depart from their null by more than "
        f"±{MARGINS['hazard_first']:g}"]
    if not dep.empty:
        r = dep.loc[dep["diff"].abs().idxmax()]
        lines[-1] += (f", the largest {r['geometry']}, {r['rule']} in [{r['t_low']:g}, "
                      f"{r['t_high']:g}): {r['hazard']:.3g} against null "
                      f"{r['null_hazard']:.3g}, "
                      + diff_text(r["diff"], r["diff_low"], r["diff_high"],
                                  MARGINS["hazard_first"]))
    lines[-1] += (f"; the elastic gas is within ±{MARGINS['hazard_first']:g} of Boltzmann's "
                  f"h(t) in {b_at} of {len(el)} bins and departs in {b_dep}. The highest later "
                  f"bin (among bins with ≥ {100 * PEAK_MIN_SHARE:g} % of the intervals) is a "
                  f"maximum over bins, read against the null's own ({peak_null} at "
                  f"N = {n_max}). A bin's interval is the wider of the bootstrap clustered on "
                  "runs and Garwood's.")
    return [*lines, ""]


def _window_growth(out) -> list:
    """Why K = 60 is read against its own null: D at one N against the window K, the row
    of disks_dispersion_windows.csv that grows most (none if the file is not there)."""
    path = out / "disks_dispersion_windows.csv"
    if not path.is_file():
        return []
    w = pd.read_csv(path)
    w = w[w["boundary"] == "circle"]
    if w.empty:
        return []
    grow = w.groupby(["packing", "rule"])["d"].agg(lambda d: d.iloc[-1] - d.iloc[0])
    packing, rule = grow.idxmax()
    g = w[(w["packing"] == packing) & (w["rule"] == rule)].sort_values("window")
    lo, hi = g.iloc[0], g.iloc[-1]
    return [f"D depends on its window: packing {packing:g}, {rule}, N = "
            f"{int(lo['n_disks'])}: {lo['d']:.3g} at K = {int(lo['window'])} → {hi['d']:.3g} at "
            f"K = {int(hi['window'])} ([disks_dispersion_windows.csv]"
            "(disks_dispersion_windows.csv)); so K = 60 is read against its own null at "
            "K = 60.", ""]


def _checks_lines(out, checks) -> list:
    """The further checks, one line each, their numbers in their CSVs."""
    lines = ["## Further checks (numbers in their CSVs)", ""]
    if not checks.empty:
        c = checks.sort_values("engine_n").iloc[-1]
        lines.append(
            f"- The engine's N = 2 against the two-disk simulator (`simulate_two_particle`, "
            f"{int(c['engine_n'])} and {int(c['two_disk_n'])} runs): KS share ratio "
            f"{format_interval(c['ratio'], c['ratio_low'], c['ratio_high'])} "
            f"{c['ratio_verdict']}, rate ratio "
            f"{format_interval(c['rate_ratio'], c['rate_ratio_low'], c['rate_ratio_high'])} "
            f"{c['rate_ratio_verdict']} ([disks_two_disk.csv](disks_two_disk.csv); margin "
            "10 %, a validation of the engine, not a physical effect).")
    found = [f"[{name}]({name})" for name in (
        "disks_renewal.csv", "disks_kicked.csv", "disks_ftle_check.csv",
        "disks_lyapunov_density.csv", "disks_dispersion_windows.csv") if (out / name).is_file()]
    if found:
        lines.append("- Not read here: " + ", ".join(found) + ".")
    return [*lines, ""]


def _left_out(long, kicked_stores) -> list:
    """The page's "Left out" list, from what was run."""
    out = [
        "- The speed-rescaled statistics (disks.csv's `rescaled_*`): their null shares are "
        "in null_calibration.csv (`<test>, speed-rescaled`), but no verdict is computed, so "
        "neither page nor figures read them; the shares of D − 1 from speed or wall.",
        "- The renewal models' ranking (AIC on pooled intervals, no standard error)."]
    if kicked_stores:
        out.append("- The kicked comparison (packing 0.02, mirror; disks_kicked.csv).")
    if long.empty:
        out.append("- No controls: every verdict is the primary design's, none robust.")
    return out


#: the rows of the page's closing table, "where the numbers come from": per CSV beside the
#: page (or per group of its columns) the columns the page quotes and the function that
#: computes them. A CSV written only when its table is not empty (the controls, the kicked
#: comparison, the two-disk check, the cost) or only by
#: `kicktimes.studies.disks.run.reproduce_disks` (the FTLE checks, the FTLE against
#: density, D against the window) is named only when it is there: `sources`
SOURCES = (
    Source("disks_poisson.csv", "geometry, rule, n_disks, d, d_low, d_high, null_d, d_diff, "
           "d_diff_low, d_diff_high, d_verdict, d_n_needed, ks_diff, ks_verdict, gamma_diff, "
           "gamma_verdict, hazard_first_diff, hazard_peak, null_hazard_peak", versus_null),
    Source("disks_poisson.csv", "delta_aic_exponential, aic_margin", aic_margin),
    Source("disks_poisson.csv", "answer, by, others", poisson_answer),
    Source("disks_poisson.csv", "replicate_changed", answer_table),
    Source("disks_hazard_null.csv", "t_low, t_high, hazard, null_hazard, diff, verdict, "
           "boltzmann, boltzmann_verdict", bin_rows),
    Source("disks.csv", "radius, n_tagged, n_short, rate, rate_enskog, reject_uniformity_ks, "
           "dispersion, hazard_first, hazard_peak, gamma_shape", disks_table),
    Source("disks_hazard.csv", "t_mid, hazard, ci_low, ci_high", disks_hazard),
    Source("disks_null.csv", "design, reject_uniformity_ks, dispersion, hazard_first, "
           "hazard_peak, gamma_shape", null_rows),
    Source("null_calibration.csv", "statistic, value, ci_low, ci_high", calibration_rows),
    Source("null_calibration.csv", "verdict", rejection_verdict),
    Source("disks_controls.csv", "control, estimate, ci_low, ci_high, verdict, robust, "
           "depends_on", controls_findings),
    Source("disks_renewal.csv", "best, second, delta_aic_exponential", renewal_models),
    Source("disks_boltzmann_kicks.csv", "gas, kicked, diff, diff_low, diff_high, verdict",
           boltzmann_table),
    Source("disks_kicked.csv", "system, diagnostic, value, reference, ratio, verdict, n_runs",
           kicked_table),
    Source("disks_kicked_rate.csv", "kicked_rate, density_rate, ratio, verdict",
           kicked_rate_check),
    Source("disks_two_disk.csv", "engine, two_disk, ratio, ratio_verdict, rate_ratio",
           two_disk_check),
    Source("disks_two_disk.csv", "n_needed", share_ratio_sample_size),
    Source("disks_dispersion_windows.csv", "d, prediction, ratio, verdict", windows_summary),
    Source("disks_ftle_check.csv", "estimate, lo, hi", paired_ratio),
    Source("disks_ftle_check_runs.csv", "numerator, denominator", ftle_check_pair),
    Source("disks_lyapunov_density.csv", "lam_per_coll, lo, hi", density_summary),
    Source("disks_lyapunov_density_fit.csv", "a, b, c, local_over_b, reading",
           density_summary),
    Source("disks_lyapunov_density_runs.csv", "lam, nu", density_state),
    Source("disks_cost.csv", "cpu_seconds, wall_seconds", sweep_cost),
    Source("disks_stores.csv", "store", load_store_names),
)
#: the rows of the columns only an elastic sweep has (none is read on the page)
ELASTIC_SOURCES = ()
#: the row of the replicate's columns, there when the replicate (the seed control) ran
REPLICATE_SOURCE = Source("disks_poisson.csv", "replicate_d, replicate_diff, "
                          "replicate_verdict", replicate_rows)


def _has_table(path) -> bool:
    """Whether ``path`` is a CSV with a header (an empty table is written as a blank line)."""
    path = Path(path)
    if not path.is_file():
        return False
    with path.open(encoding="utf-8") as f:
        return bool(f.readline().strip())


def sources(out_dir, *, elastic=False, replicate=False) -> list:
    """The closing table's rows for the page in ``out_dir``: those of `SOURCES` (with
    ``elastic``, of `ELASTIC_SOURCES` too; with ``replicate``, `REPLICATE_SOURCE`) whose CSV
    is there with a header, a CSV's rows together. Their columns are checked against the
    CSVs when the page is written (`kicktimes.render.provenance.check_sources`)."""
    rows = [*SOURCES, *(ELASTIC_SOURCES if elastic else ()),
            *((REPLICATE_SOURCE,) if replicate else ())]
    order = list(dict.fromkeys(s.csv for s in rows))
    rows.sort(key=lambda s: order.index(s.csv))  # stable: a CSV's rows together
    return [s for s in rows if _has_table(Path(out_dir) / s.csv)]


def write_disks_page(store_paths, out_dir, *, command="kicktimes reproduce --study disks",
                     dpi=110, n_boot=999, n_mc=199, cost=None) -> Path:
    """Write ``disks.md``, its CSV tables and figures into ``out_dir``; the page, written
    last, closes with the table of where its numbers come from (`sources`).

    Parameters
    ----------
    store_paths : sequence of path-like
        Stores of `kicktimes.experiment.DisksExperiment` sweeps.
    out_dir : path-like
        Output folder (created; files of the same names are replaced).
    command : str
        The command the "Generated" line names.
    dpi, n_boot, n_mc : int
        PNG resolution; bootstrap replicates and Monte Carlo samples
        (`kicktimes.studies.disks.tables.disks_table`).
    cost : pandas.DataFrame, optional
        The sweeps' cost (``experiment``, ``cpu_seconds``), written beside the page.

    Returns
    -------
    pathlib.Path
        ``out_dir / "disks.md"``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from kicktimes.experiment import DisksExperiment, disks_control, load_store
    from kicktimes.render.pages import write_null_calibration
    from kicktimes.stats import dilute_tagged_disk

    paths = list(store_paths)
    if not paths:
        raise ValueError("store_paths: give at least one disks store")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    every = [load_store(p) for p in paths]
    disks = [st for st in every if isinstance(st.experiment, DisksExperiment)]
    kicked_stores = [st for st in disks if st.experiment.kicked_runs]
    control_stores = [st for st in disks if disks_control(st.experiment.name)]
    # a validation store: two disks only, the engine's side of a two-disk check
    checks_only = [st for st in disks if st.experiment.n_disks == (2,)
                   and not st.experiment.kicked_runs]
    stores = [st for st in disks if not st.experiment.kicked_runs
              and st not in control_stores and st not in checks_only]
    two_stores = [st for st in every if not isinstance(st.experiment, DisksExperiment)]
    if not stores:
        raise ValueError("store_paths: give at least one disks sweep without kicked runs")
    t0 = time.process_time()

    def key(st):
        return st.experiment.geometry_label, st.experiment.rule

    def against(group, **kw):
        """Per store: (its disks_table, its versus_null rows and bins)."""
        return {key(st): (disks_table(st, n_boot=n_boot, n_mc=n_mc, seed=42, **kw),
                          *versus_null(st, n_boot=n_boot, seed=42, **kw)) for st in group}

    def merged(parts):
        """A control's disks_table rows with its differences from its own null."""
        keys = ["geometry", "rule", "n_disks"]
        rows = []
        for t, vn, *_ in parts.values():
            extra = vn[[*keys, *(c for c in vn.columns if c.endswith(
                ("_diff", "_diff_low", "_diff_high", "_verdict")))]]
            rows.append(t.merge(extra, on=keys, how="left"))
        return pd.concat(rows, ignore_index=True)

    primary = against(stores)
    table = pd.concat([p[0] for p in primary.values()], ignore_index=True)
    vn = pd.concat([p[1] for p in primary.values()], ignore_index=True)
    bins = pd.concat([p[2] for p in primary.values()], ignore_index=True)
    # the controls: other stores of the same sweeps, and the primary's bulk tagged disks,
    # each against its own null
    by_control = {"primary": merged(primary)}
    seed_parts, seed_group = {}, []
    for control in ("seed", "k60", "box"):
        group = [st for st in control_stores if disks_control(st.experiment.name)[1] == control
                 and disks_control(st.experiment.name)[0] in {s.experiment.name for s in stores}]
        if group:
            parts = against(group)
            by_control[control] = merged(parts)
            if control == "seed":
                seed_parts, seed_group = parts, group
    if control_stores:
        by_control["bulk"] = merged(against(stores, within=BULK_WITHIN))
    long = controls_findings(by_control) if len(by_control) > 1 else pd.DataFrame()
    if not long.empty:
        long.to_csv(out / "disks_controls.csv", index=False)
    replicate = replicate_rows({k: p[3] for k, p in primary.items()},
                               {k: p[3] for k, p in seed_parts.items()}, n_boot=n_boot)
    renewal = pd.concat([renewal_models(st) for st in stores], ignore_index=True)
    renewal.to_csv(out / "disks_renewal.csv", index=False)
    # the replicate's own readings (each against its own null), for the answer's rule
    seed_vn = (pd.concat([p[1] for p in seed_parts.values()], ignore_index=True)
               if seed_parts else None)
    seed_bins = (pd.concat([p[2] for p in seed_parts.values()], ignore_index=True)
                 if seed_parts else None)
    seed_renewal = (pd.concat([renewal_models(st) for st in seed_group], ignore_index=True)
                    if seed_group else None)
    answers = answer_table(vn, bins, renewal, replicate, seed_vn=seed_vn,
                           seed_bins=seed_bins, seed_renewal=seed_renewal)
    keys = ["geometry", "rule", "n_disks"]
    poisson = vn.merge(answers.drop(columns=["n_runs", "d_n_needed"]), on=keys)
    if not replicate.empty:
        poisson = poisson.merge(replicate.drop(columns=["null_d"]), on=keys, how="left")
    poisson.to_csv(out / "disks_poisson.csv", index=False)
    bins.to_csv(out / "disks_hazard_null.csv", index=False)
    hazard = pd.concat([disks_hazard(st) for st in stores], ignore_index=True)
    kicked = (pd.concat([kicked_table(st, n_boot=n_boot, seed=42) for st in kicked_stores],
                        ignore_index=True) if kicked_stores else pd.DataFrame())
    if not kicked.empty:
        kicked.to_csv(out / "disks_kicked.csv", index=False)
        rate_check = kicked_rate_check(kicked, table, kicked_stores[0].experiment)
        if not rate_check.empty:
            rate_check.to_csv(out / "disks_kicked_rate.csv", index=False)
    checks = []
    for two in two_stores:
        # the engine's store of a two-disk reference "disks-two-<x>" is "disks-<x>" if given,
        # else the first sweep of the same rule and radius
        match = [st for st in stores + checks_only if st.experiment.rule == two.experiment.rule
                 and 2 in st.experiment.n_disks
                 and two.experiment.radii == (st.experiment.radius(2),)]
        named = [st for st in match
                 if st.experiment.name == two.experiment.name.replace("disks-two-", "disks-")]
        if match:
            checks.append(two_disk_check((named or match)[0], two, n_boot=n_boot, n_mc=n_mc,
                                         seed=42))
    checks = pd.DataFrame(checks)
    if not checks.empty:
        checks.to_csv(out / "disks_two_disk.csv", index=False)
    # the gas half of the null calibration: null streams shaped like the primary runs
    nulls = pd.concat([null_rows(st, n_boot=n_boot, n_mc=n_mc, seed=42) for st in stores],
                      ignore_index=True)
    nulls.to_csv(out / "disks_null.csv", index=False)
    write_null_calibration(out, "disks", calibration_rows(nulls, alpha=ALPHA))
    boltz = boltzmann_table(table, nulls)
    boltz.to_csv(out / "disks_boltzmann_kicks.csv", index=False)
    analysis_cpu = time.process_time() - t0
    table.to_csv(out / "disks.csv", index=False)
    hazard.to_csv(out / "disks_hazard.csv", index=False)
    elastic = dilute_tagged_disk("elastic")
    levels = {"dispersion": 1.14, "hazard_first": float(elastic.hazard(0.005))}
    figures = {"disks_rejection_vs_n.png": rejection_figure(table, nulls=nulls),
               "disks_hazard_vs_n.png": hazard_figure(hazard, table),
               "disks_rate_dispersion_vs_n.png": rates_figure(table, nulls=vn,
                                                              boltzmann=levels)}
    with_controls_figure = not long.empty and (long["n_disks"] >= CONTROLS_MIN_N).any()
    if with_controls_figure:
        figures["disks_controls_vs_n.png"] = controls_figure(long, n_min=CONTROLS_MIN_N,
                                                             names=CONTROL_NAMES)
    for name, fig in figures.items():
        fig.savefig(out / name, dpi=dpi)
        plt.close(fig)
    exp0 = stores[0].experiment
    now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    k = exp0.collisions
    rate_from, rate_robust_from = _rate_from(table, long)
    boltz_d = boltz[boltz["statistic"] == "dispersion"]
    lines = [
        *opening_lines(answers, vn, boltz_d, _rate_line(table, rate_from, rate_robust_from)),
        *summary_lines(answers, vn), "",
        f"**The answer's rule** (`studies.disks.readings.poisson_answer`): {ANSWER_RULE}. "
        "Each cell: statistic − its null (Poisson streams at each run's collision frequency, "
        "shaped like the runs, `studies.disks.versus_null`; 95 % interval by the bootstrap "
        "clustered on runs, the null paired by run), its verdict (`stats.null_verdict`). "
        "D: the variance over the mean of each tagged disk's collisions in one window of "
        f"K = {k} mean intervals, over all runs of one N (the spread of rates across runs "
        "is in it and in its null). Replicate D: the independent replicate's D "
        "against the same null. Every N: [disks_poisson.csv](disks_poisson.csv); nulls: "
        "[null_calibration.csv](null_calibration.csv) and [disks_null.csv](disks_null.csv).",
        "", *_margin_lines(),
        f"Generated {now} by kicktimes {__version__} (`{command}`) from {len(every)} "
        "stores (disks_stores.csv). Every number is computed from the "
        "stores; nothing is typed.", "",
        "The tagged disk's collision times among N equal hard disks in the unit circle "
        f"(`kicktimes.simulate_disks`), N = {min(exp0.n_disks)} to {max(exp0.n_disks)}, "
        "mirror and elastic rule, at its first "
        f"K = {k} collisions; about {exp0.n_tagged} tagged disks per N in at least "
        f"{int(table[table['n_disks'] > 2]['n_runs'].min())} runs (at most "
        f"{exp0.max_tagged_per_run} per run). Linear Boltzmann: the dilute tagged disk of "
        "Visco, van Wijland & Trizac (2008), `stats.dilute_tagged_disk`.", "",
        "## D against its null at every N", "",
        *family_table(vn), "",
        "![rates and dispersion](disks_rate_dispersion_vs_n.png)", "",
        "**Against N**: rate / Enskog (±1.5 % shaded; stars: N = 2 over the two-disk "
        "rate), D (log y), the first hazard bin; 95 % CIs; crosses: the Poisson null of the "
        "same runs; black: elastic linear Boltzmann (dashed D∞ = 1.14, dash-dotted "
        f"h(0.005) = {levels['hazard_first']:.3g}).", "",
        "![rejection shares](disks_rejection_vs_n.png)", "",
        "**Rejection shares against N** (log y): uniform times (KS, top), exponential "
        "intervals (AD, bottom); dotted crosses: the Poisson null's share; black dashed: "
        f"elastic linear Boltzmann's; grey: α = 5 % ± {100 * MARGINS['ks']:g} point (the KS "
        "margin).", "",
        "![hazard](disks_hazard_vs_n.png)", "",
        "**The hazard against the time since the last collision** (mean intervals, log x to "
        "the last bin with data) over the constant rate; top rows: every N, log y; bottom "
        f"rows: N ≥ 10, linear y (±{MARGINS['hazard_first']:g} shaded); 95 % Garwood bands; "
        "purple dashed: linear Boltzmann h(t).", "",
        *_hazard_lines(bins, vn),
        *controls_lines(long), *(_window_growth(out) if not long.empty else [])]
    if with_controls_figure:
        lines += [
            "![controls](disks_controls_vs_n.png)", "",
            f"**Each finding under its controls** (N ≥ {CONTROLS_MIN_N}; D, KS share and "
            "first hazard bin, each minus its own null, margin shaded; hollow: not robust).",
            ""]
    lines += boltzmann_lines(boltz)
    lines += _checks_lines(out, checks)
    lines += ["## Cost", ""]
    sweeps = ""
    if cost is not None:
        sweeps = (f"The disks sweeps: {cost['cpu_seconds'].sum():.0f} s of CPU in all "
                  "([disks_cost.csv](disks_cost.csv)); ")
        cost.to_csv(out / "disks_cost.csv", index=False)
    lines += [f"{sweeps}these tables and figures: {analysis_cpu:.0f} s of CPU.", "",
              "## Left out", "", *_left_out(long, kicked_stores), "",
              "## Stores", "", "[disks_stores.csv](disks_stores.csv).", ""]
    pd.DataFrame({"store": load_store_names(every)}).to_csv(
        out / "disks_stores.csv", index=False)
    for stale in ("disks_wall_share.csv",):
        (out / stale).unlink(missing_ok=True)
    return write_results_page(out / "disks.md", lines,
                              sources(out, replicate=not replicate.empty))
