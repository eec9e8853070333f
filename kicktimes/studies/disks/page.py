"""docs/results/disks.md: from two disks to a gas, written from the disks stores.

`write_disks_page` reads the stores of the `kicktimes.experiment.DISKS_PRESETS` sweeps,
their controls (`DISKS_CONTROLS`) and the two-disk references, computes their tables
(`kicktimes.studies.disks.tables`; the findings under their controls,
`kicktimes.studies.disks.controls`; the renewal models, `kicktimes.studies.disks.renewal`;
the kicked comparison's sections, `kicktimes.studies.disks.kicked`), writes them as CSV
beside the page, draws the figures (`kicktimes.studies.disks.figures`) and writes the page:
the answers first, each from the table through the verdict rules of `kicktimes.stats`,
then one table per geometry with a row per N. `kicktimes.studies.disks.run.reproduce_disks`
runs (or resumes) the sweeps and the gas's FTLE computations first: ``kicktimes reproduce
--study disks``. The page closes with the table of where its numbers come from
(`kicktimes.render.pages.write_results_page`): the rows of `sources`, one per CSV beside
it (or per group of its columns) and the function that computed them.
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
    format_interval,
    paired_ratio,
    poisson_verdict,
    ratio_rule,
    rejection_rule,
    rejection_verdict,
    share_ratio_sample_size,
)
from kicktimes.stats.findings import share_verdict
from kicktimes.studies.disks.boltzmann import boltzmann_answer, boltzmann_lines, boltzmann_table
from kicktimes.studies.disks.controls import (
    BULK_WITHIN,
    CONTROL_NAMES,
    FINDINGS,
    NOT_READ,
    controls_findings,
    controls_lines,
    wall_share_lines,
    wall_shares,
)
from kicktimes.studies.disks.density import one_state as density_state
from kicktimes.studies.disks.density import summarise as density_summary
from kicktimes.studies.disks.figures import (
    ALPHA,
    HEADLINE,
    SHOWN_N,
    X_MIN,
    ZOOM_MIN_N,
    controls_figure,
    geometries_of,
    hazard_figure,
    rates_figure,
    rejection_figure,
)
from kicktimes.studies.disks.ftle_check import pair as ftle_check_pair
from kicktimes.studies.disks.kicked import (
    density_lines,
    ftle_check_lines,
    kicked_answer,
    kicked_not_chaotic,
    kicked_rate_check,
    kicked_section,
    scatter_answer,
)
from kicktimes.studies.disks.null import calibration_rows, null_rows
from kicktimes.studies.disks.readings import (
    family_lines,
    opening_lines,
    poisson_by_control,
    poisson_readings,
    rule_lines,
    summary_lines,
)
from kicktimes.studies.disks.renewal import renewal_lines, renewal_models
from kicktimes.studies.disks.tables import (
    disks_hazard,
    disks_table,
    kicked_table,
    sweep_cost,
    two_disk_check,
)
from kicktimes.studies.disks.windows import summarise as windows_summary
from kicktimes.studies.disks.windows import windows_lines

__all__ = ["ELASTIC_SOURCES", "SOURCES", "sources", "write_disks_page"]

#: the controls figure shows N from here on (where the page's "becomes Poisson" is decided)
CONTROLS_MIN_N = 10


def _pct(row, key, verdict=True):
    """``"39.1 [37.2, 41.0] % above nominal"`` from the row's share and its CI (without the
    verdict: ``"39.1 [37.2, 41.0] %"``)."""
    est, lo, hi = (100 * row[key], 100 * row[f"{key}_low"], 100 * row[f"{key}_high"])
    text = format_interval(est, lo, hi, edges=(100 * ALPHA * 0.5, 100 * ALPHA * 1.5))
    return f"{text} % {row[f'{key}_verdict']}" if verdict else f"{text} %"


def _ratio(row, key, verdict=True):
    text = format_interval(row[key], row[f"{key}_low"], row[f"{key}_high"])
    return f"{text} {row[f'{key}_verdict']}" if verdict else text


def _holds_from(ns, ok):
    """The smallest N of ``ns`` (increasing) from which ``ok`` holds at every larger N, or
    None."""
    ok = np.asarray(ok, dtype=bool)
    return next((int(ns[m]) for m in range(len(ns)) if ok[m:].all()), None)


def _first_nominal(d, keys):
    """The smallest N from which every larger N's verdict on every key is "nominal", or
    None."""
    return _holds_from(d["n_disks"].to_numpy(),
                       d[[f"{k}_verdict" for k in keys]].eq("nominal").all(axis=1))


def _p(p):
    return "< 1e-300" if p == 0 else f"{p:.2g}"


def _above(row, key, level):
    """`stats.share_verdict` of the row's interval against ``level``."""
    return share_verdict(row[f"{key}_low"], row[f"{key}_high"], level)


def _from_on(g, key, verdict):
    return _holds_from(g["n_disks"].to_numpy(), g[f"{key}_verdict"].eq(verdict))


#: the controls table's name of the collision rate over Enskog's
RATE_FINDING = next(name for name, spec in FINDINGS.items() if spec[0] == "rate_enskog")


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
    """``(from_n, robust_from_n)``: the smallest N from which the rate is within 10 % of
    Enskog's at every geometry and rule (primary design; under every control)."""
    froms = [_from_on(g, "rate_enskog", "within 10 %")
             for _, g in table.groupby(["geometry", "rule"], sort=False, observed=True)]
    robust = (_robust_from(long, RATE_FINDING, "within 10 %")
              if long is not None and not long.empty else None)
    return (max(froms) if all(froms) else None), robust


def _short_answers(kicked, long=None):
    """The answers' sentences on the kicked disks and the controls."""
    long = pd.DataFrame() if long is None else long
    lines = []
    bad = kicked_not_chaotic(kicked)
    if bad:
        lines += [f"The single disk kicked with uniform new directions has its own FTLE's 95 % "
                  f"interval at or below 0 at N = {', '.join(str(n) for n in bad)}: it is not "
                  "chaotic there, and no kicked/gas FTLE ratio is stated for it.", ""]
    if not kicked.empty and scatter_answer(kicked):
        lines += [scatter_answer(kicked), ""]
    if long.empty:
        lines += ["No controls were run: every verdict is the primary design's (one K, one "
                  "seed), none is called robust."]
        return lines
    prim = long[(long["control"] == "primary") & (long["n_disks"] >= 30)
                & ~long["diagnostic"].isin(NOT_READ)]
    dep = prim[~prim["robust"]]
    by = {c: int(dep["depends_on"].str.split(";").apply(lambda s, c=c: c in s).sum())
          for c in CONTROL_NAMES if c != "primary"}
    lines += [f"Under the controls (an independent replicate, K = 60, the tagged disks of the "
              f"bulk; below, \"Under the controls\"): of the {len(prim)} findings at N ≥ 30, "
              f"{int(prim['robust'].sum())} are robust (the same verdict, in the same "
              f"direction, under every control) and {len(dep)} depend on a control ("
              + ", ".join(f"{c}: {v}" for c, v in by.items()) + "); the verdicts above are "
              "the primary design's."]
    return lines


def _hazard_answers(table):
    lines = []
    for (geo, rule), g in table.groupby(["geometry", "rule"], sort=False, observed=True):
        lo, hi = g.iloc[0], g.iloc[-1]
        side = _above(hi, "hazard_first", 1.0)
        gap = abs(1.0 - hi["hazard_first"])
        resid = {"below": f" (interval below 1: a residual dip of {100 * gap:.0f} %)",
                 "above": f" (interval above 1: an excess of {100 * gap:.0f} %)"}.get(side, "")
        mid = g.iloc[1:-1]
        mid = mid[mid["hazard_first_verdict"] == "higher"]
        mid_text = ("; the first bin is higher than 1.1 at N = " + ", ".join(
            f"{int(r['n_disks'])}: {_ratio(r, 'hazard_first', False)}"
            for _, r in mid.iterrows()) if not mid.empty else "")
        lines.append(
            f"- {geo}, {rule}: first bin N = {int(lo['n_disks'])}: "
            f"{_ratio(lo, 'hazard_first')}, N = {int(hi['n_disks'])}: "
            f"{_ratio(hi, 'hazard_first')}{resid}{mid_text}; highest later bin N = "
            f"{int(lo['n_disks'])}: {_ratio(lo, 'hazard_peak')} at "
            f"{lo['hazard_peak_t']:.2g} mean intervals, N = {int(hi['n_disks'])}: "
            f"{_ratio(hi, 'hazard_peak')}.")
    return lines


#: a share of D - 1 is decomposed only where D's interval lies entirely above 1 (the gap
#: outside its own noise) and the share's interval is narrower than this, the whole range
#: from none of the gap to all of it (stated before the shares were read)
SHARE_MAX_WIDTH = 1.0


def _share(row):
    """The share of D - 1 the speed carries, with its reading; not decomposed where the gap
    D - 1 is inside its own noise (D's interval reaches 1) or the share's interval is at
    least `SHARE_MAX_WIDTH` wide; else no share detected (its interval contains 0), 1 not
    excluded (contains 1), negative (the rescaling makes D worse), above 1, or part."""
    lo, hi = row["speed_share_low"], row["speed_share_high"]
    text = format_interval(row["speed_share"], lo, hi, edges=(0.0, 1.0))
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return f"{text}: undetermined"
    if not row["dispersion_low"] > 1.0:
        return f"{text}: not decomposed (D's interval reaches 1)"
    if hi - lo >= SHARE_MAX_WIDTH:
        return f"{text}: not decomposed (interval {hi - lo:.2g} wide)"
    if lo <= 0.0 <= hi:
        return f"{text}: no share detected"
    if lo <= 1.0 <= hi:
        return f"{text}: all of it not excluded"
    if hi < 0.0:
        return f"{text}: negative (the rescaling makes D worse)"
    if lo > 1.0:
        return f"{text}: more than all"
    return f"{text}: part of it"


def _speed_answers(table, readings):
    lines = []
    d = table[table["rule"] == "elastic"]
    for geo in geometries_of(d):
        g = d[d["geometry"] == geo]
        big = g.iloc[-1]
        rd = readings[(readings["geometry"] == geo) & (readings["rule"] == "elastic")
                      & (readings["n_disks"] == big["n_disks"])].iloc[0]
        carried = "; ".join(f"N = {int(r['n_disks'])}: {_share(r)}" for _, r in g.iterrows())
        lines.append(
            f"- **{geo}, elastic**: at N = {int(big['n_disks'])} D = "
            f"{_ratio(big, 'dispersion', False)} (the dilute tagged disk at the same windows: "
            f"{format_interval(rd['dilute_d'], rd['dilute_d_low'], rd['dilute_d_high'])}), "
            f"after rescaling each interval by the rate of its speed "
            f"{_ratio(big, 'rescaled_dispersion', False)}; KS rejections "
            f"{_pct(big, f'reject_{HEADLINE}', False)} before (reading: {rd['verdict']}), "
            f"{_pct(big, f'rescaled_reject_{HEADLINE}', False)} after (calibrated level "
            f"{100 * rd['rescaled_null_level']:.3g} %; reading: {rd['rescaled_verdict']}). "
            f"The share "
            f"(D − D_rescaled) / (D − 1) the speed carries, at every N: {carried}. (Speeds "
            f"read for {100 * g['speed_known'].min():.1f}–{100 * g['speed_known'].max():.1f} "
            f"% of the intervals; the others count at the mean rate.)")
    return lines


def _rate_answers(table):
    lines = []
    for (geo, rule), g in table.groupby(["geometry", "rule"], sort=False, observed=True):
        within = g[g["rate_enskog_verdict"] == "within 10 %"]["n_disks"].tolist()
        two = g[g["n_disks"] == 2]
        two_text = (f"; N = 2 against the two-disk kinetic rate Γ(r) "
                    f"(`stats.kinetic_rate`, exact for two disks): "
                    f"{_ratio(two.iloc[0], 'rate_two_disk')}" if not two.empty
                    and "rate_two_disk" in two else "")
        lines.append(f"- {geo}, {rule}: within 10 % of Enskog at N = "
                     f"{', '.join(str(n) for n in within) or 'none'}; at N = 2 "
                     f"{_ratio(g.iloc[0], 'rate_enskog')}{two_text}.")
    return lines


def _two_disk_answers(checks):
    if checks.empty:
        return []
    checks = checks.sort_values("engine_n", kind="stable")
    lines = ["**The N = 2 row against the two-disk simulator** (`simulate_two_particle`, "
             "invariant-measure ICs, the same radius and K; [disks_two_disk.csv]"
             "(disks_two_disk.csv)): the share of runs rejecting uniform times:", ""]
    for _, c in checks.iterrows():
        lines.append(
            f"- r = {c['radius']:g}, {c['rule']}: engine (`{c['engine_store']}`) "
            f"{_pct(c, 'engine')} of {int(c['engine_n'])}, two-disk simulator "
            f"(`{c['two_disk_store']}`) {_pct(c, 'two_disk')} of {int(c['two_disk_n'])}; "
            f"ratio {format_interval(c['ratio'], c['ratio_low'], c['ratio_high'])} "
            f"{c['ratio_verdict']}: the engine's validation against the two-disk simulator "
            f"{'passes' if c['ratio_verdict'] == 'within 10 %' else 'has not passed'} "
            f"at this radius by the share; the runs per arm the share's ratio needs at the "
            f"two-disk share for 80 % power at the 10 % margin: {int(c['n_needed'])} "
            f"(`stats.share_ratio_sample_size`). The mean collision rate per run (more power): "
            f"ratio {format_interval(c['rate_ratio'], c['rate_ratio_low'], c['rate_ratio_high'])}"
            f" {c['rate_ratio_verdict']}.")
    return lines + ["", "The 10 % margin of these ratios is the project's, stated before the "
                    "runs; the powered elastic pair (`disks-n2-phi0.02-elastic` against "
                    "`disks-two-n2-phi0.02-elastic`, independent seeds) was sized from the "
                    "first pair's share with `stats.share_ratio_sample_size` before it ran. "
                    "(These shares' intervals are a percentile bootstrap over tagged disks "
                    "only, for the ratio; the table's interval of the same engine share is the "
                    "wider of the bootstrap clustered on runs and Clopper–Pearson, hence the "
                    "small difference.)", ""]


def _geometry_tables(table, readings, geo):
    """The rows N of one geometry, in two tables of at most 8 columns: the rates and the
    KS rejection shares, then D and the reading (`stats.poisson_verdict`) per rule."""
    g = table[table["geometry"] == geo]
    rd = readings[readings["geometry"] == geo]
    head_a = ["N", "r", "tagged (dropped)", "rate / Enskog, mirror", "rate / Enskog, elastic",
              "KS rejected, mirror", "KS rejected, elastic", "KS, elastic rescaled"]
    head_b = ["N", "D, mirror", "D, elastic", "D, elastic rescaled", "reading, mirror",
              "reading, elastic", "reading, elastic rescaled"]
    a = ["| " + " | ".join(head_a) + " |", "|" + "---|" * len(head_a)]
    b = ["| " + " | ".join(head_b) + " |", "|" + "---|" * len(head_b)]
    for n in sorted(set(g["n_disks"])):
        m = g[(g["n_disks"] == n) & (g["rule"] == "mirror")]
        e = g[(g["n_disks"] == n) & (g["rule"] == "elastic")]
        rm = rd[(rd["n_disks"] == n) & (rd["rule"] == "mirror")]
        re_ = rd[(rd["n_disks"] == n) & (rd["rule"] == "elastic")]

        def cell(d, fn, *args):
            return fn(d.iloc[0], *args) if not d.empty else "—"

        def word(d, key):
            return str(d.iloc[0][key]) if not d.empty and key in d else "—"

        tagged = " / ".join(f"{int(d.iloc[0]['n_tagged'])} ({int(d.iloc[0]['n_short'])})"
                            for d in (m, e) if not d.empty)
        r = (m if not m.empty else e).iloc[0]["radius"]
        a.append("| " + " | ".join(
            [str(n), f"{r:.4g}", tagged,
             cell(m, _ratio, "rate_enskog"), cell(e, _ratio, "rate_enskog"),
             cell(m, _pct, f"reject_{HEADLINE}", False), cell(e, _pct, f"reject_{HEADLINE}", False),
             cell(e, _pct, f"rescaled_reject_{HEADLINE}", False)]) + " |")
        b.append("| " + " | ".join(
            [str(n), cell(m, _ratio, "dispersion", False), cell(e, _ratio, "dispersion", False),
             cell(e, _ratio, "rescaled_dispersion", False), word(rm, "verdict"),
             word(re_, "verdict"), word(re_, "rescaled_verdict")]) + " |")
    return [*a, "", *b]


def _left_out(table, long, kicked_stores, k, ftle_checked):
    """The page's "Left out" list, from what was run."""
    out = []
    if kicked_stores:
        out.append(
            "- The kicked comparison is at one geometry (packing 0.02, mirror rule); its "
            "scatter kicks come at Poisson times only (not at the gas disk's own collision "
            "times), and every kicked/gas FTLE ratio sets a single disk's exponent against "
            "the whole gas's largest exponent: the tagged disk's own share of the gas's "
            "stretching is not computed. The kinetic-theory form is tested for its shape "
            "only (its prefactors are not computed), in the table's unit circle with its "
            "wall, at N = 300 and 1000. The null calibration is shaped like the primary "
            "design's runs only: the controls' Poisson readings use the primary's calibrated "
            "levels (the replicate has the same shape; K = 60 and the bulk disks have other "
            "windows and fewer tagged disks)."
            + ("" if ftle_checked else " The checks of the gas's FTLE (tangent against "
               "twin, the engine's N = 2 against the two-disk simulator) are not on this "
               "page: their table, disks_ftle_check.csv, was not beside it when it was "
               "written."))
    else:
        out.append("- The kicked single disk against the tagged disk is not computed here.")
    out.append("- The N = 2 row is compared with the exact two-disk kinetic rate and with the "
               "two-disk simulator at its own radius (packing 0.02 only), not with the "
               "rejection shares of docs/results/README.md, which are for other radii "
               "(0.008–0.030) and, but for its `@first30` rows, whole runs.")
    if long.empty:
        out.append("- No controls: every verdict here is the primary design's (one K, one "
                   "seed); none is checked under another (`robust_verdict`), so none is called "
                   "robust.")
    else:
        big = table[table["n_disks"] == table["n_disks"].max()]
        low = big.loc[big["packing"].idxmin()]
        out.append(
            f"- Controls not run: another cap on the tagged disks per run (at most 250 here; "
            f"the intervals are clustered on runs), starts away from equilibrium, another α, "
            f"K other than 30 and 60. The bulk control selects where a tagged disk starts, not "
            f"where it collides: at {low['geometry']}, N = {int(low['n_disks'])}, a unit-speed "
            f"disk flies 1/ν = {1 / low['rate']:.2g} table radii between collisions, so within "
            f"its {k} collisions it may reach the wall (inference from the mean free path); "
            "the control is weaker there than at packing 0.2.")
    out.append("- The renewal models are ranked by AIC on pooled intervals taken as "
               "independent; no standard error of ΔAIC and no goodness of fit is given (the "
               "halves of the runs are the only check of the ranking).")
    return out


#: the rows of the page's closing table, "where the numbers come from": per CSV beside the
#: page (or per group of its columns) the columns the page quotes, each with its ``_low``,
#: ``_high`` and ``_verdict`` columns where it has them, and the function that computes
#: them. A CSV written only when its table is not empty (the controls, the kicked
#: comparison, the two-disk check, the wall's share, the cost) or only by
#: `kicktimes.studies.disks.run.reproduce_disks` (the FTLE checks, the FTLE against
#: density, D against the window) is named only when it is there: `sources`
SOURCES = (
    Source("disks.csv", "radius, n_tagged, n_short, rate, rate_enskog, reject_uniformity_ks, "
           "dispersion, hazard_first, hazard_peak, gamma_shape", disks_table),
    Source("disks_poisson.csv", "share, null_level, share_verdict, d", poisson_readings),
    Source("disks_poisson.csv", "verdict", poisson_verdict),
    Source("disks_null.csv", "design, reject_uniformity_ks, dispersion", null_rows),
    Source("null_calibration.csv", "share, ci_low, ci_high", null_rows),
    Source("null_calibration.csv", "verdict", rejection_verdict),
    Source("disks_controls.csv", "control, estimate, ci_low, ci_high, verdict, robust, "
           "depends_on", controls_findings),
    Source("disks_renewal.csv", "best, second, delta_aic_second, delta_aic_exponential, "
           "stable", renewal_models),
    Source("disks_boltzmann_kicks.csv", "gas, kicked, prediction, ratio, verdict, reading",
           boltzmann_table),
    Source("disks_hazard.csv", "t_mid, hazard, ci_low, ci_high, flat_pvalue", disks_hazard),
    Source("disks_kicked.csv", "system, diagnostic, value, reference, ratio, verdict, n_runs",
           kicked_table),
    Source("disks_kicked_rate.csv", "kicked_rate, density_rate, ratio, verdict",
           kicked_rate_check),
    Source("disks_two_disk.csv", "engine, two_disk, ratio, ratio_verdict, rate_ratio",
           two_disk_check),
    Source("disks_two_disk.csv", "n_needed", share_ratio_sample_size),
    Source("disks_wall_share.csv", "d_circle, d_box, share, reading", wall_shares),
    Source("disks_dispersion_windows.csv", "d, prediction, ratio, verdict", windows_summary),
    Source("disks_ftle_check.csv", "estimate, lo, hi", paired_ratio),
    Source("disks_ftle_check_runs.csv", "numerator, denominator", ftle_check_pair),
    Source("disks_lyapunov_density.csv", "lam_per_coll, lo, hi", density_summary),
    Source("disks_lyapunov_density_fit.csv", "a, b, c, local_over_b, reading",
           density_summary),
    Source("disks_lyapunov_density_runs.csv", "lam, nu", density_state),
    Source("disks_cost.csv", "cpu_seconds, wall_seconds", sweep_cost),
)
#: the rows of the columns only an elastic sweep has (the speed-rescaled reading)
ELASTIC_SOURCES = (
    Source("disks.csv", "speed_known, rescaled_reject_uniformity_ks, rescaled_dispersion, "
           "speed_share", disks_table),
    Source("disks_poisson.csv", "rescaled_null_level, rescaled_verdict, dilute_d",
           poisson_readings),
)


def _has_table(path) -> bool:
    """Whether ``path`` is a CSV with a header (an empty table is written as a blank line)."""
    path = Path(path)
    if not path.is_file():
        return False
    with path.open(encoding="utf-8") as f:
        return bool(f.readline().strip())


def sources(out_dir, *, elastic=True) -> list:
    """The closing table's rows for the page in ``out_dir``: those of `SOURCES` (with
    ``elastic``, of `ELASTIC_SOURCES` too) whose CSV is there with a header, a CSV's rows
    together. Their columns are checked against the CSVs when the page is written
    (`kicktimes.render.provenance.check_sources`)."""
    rows = [*SOURCES, *(ELASTIC_SOURCES if elastic else ())]
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
    from kicktimes.stats import TESTS

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

    def tables(group, **kw):
        return pd.concat([disks_table(st, n_boot=n_boot, n_mc=n_mc, seed=42, **kw)
                          for st in group], ignore_index=True)

    table = tables(stores)
    # the controls: other stores of the same sweeps, and the primary's bulk tagged disks
    by_control = {"primary": table}
    for control in ("seed", "k60", "box"):
        group = [st for st in control_stores if disks_control(st.experiment.name)[1] == control
                 and disks_control(st.experiment.name)[0] in {s.experiment.name for s in stores}]
        if group:
            by_control[control] = tables(group)
    if control_stores:
        by_control["bulk"] = tables(stores, within=BULK_WITHIN)
    long = controls_findings(by_control) if len(by_control) > 1 else pd.DataFrame()
    if not long.empty:
        long.to_csv(out / "disks_controls.csv", index=False)
    renewal = pd.concat([renewal_models(st) for st in stores], ignore_index=True)
    renewal.to_csv(out / "disks_renewal.csv", index=False)
    hazard = pd.concat([disks_hazard(st) for st in stores], ignore_index=True)
    kicked = (pd.concat([kicked_table(st, n_boot=n_boot, seed=42) for st in kicked_stores],
                        ignore_index=True) if kicked_stores else pd.DataFrame())
    rate_check = pd.DataFrame()
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
    readings = poisson_readings(table, nulls)
    readings.to_csv(out / "disks_poisson.csv", index=False)
    by_reading = poisson_by_control(by_control, nulls) if len(by_control) > 1 else None
    analysis_cpu = time.process_time() - t0
    table.to_csv(out / "disks.csv", index=False)
    hazard.to_csv(out / "disks_hazard.csv", index=False)
    figures = {"disks_rejection_vs_n.png": rejection_figure(table, nulls=nulls),
               "disks_hazard_vs_n.png": hazard_figure(hazard, table),
               "disks_rate_dispersion_vs_n.png": rates_figure(table)}
    with_controls_figure = not long.empty and (long["n_disks"] >= CONTROLS_MIN_N).any()
    if with_controls_figure:
        figures["disks_controls_vs_n.png"] = controls_figure(long, n_min=CONTROLS_MIN_N,
                                                             names=CONTROL_NAMES)
    for name, fig in figures.items():
        fig.savefig(out / name, dpi=dpi)
        plt.close(fig)
    exp0 = stores[0].experiment
    names = ", ".join(f"`{st.experiment.name}`" for st in every)
    now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    k = exp0.collisions
    rate_from, rate_robust_from = _rate_from(table, long)
    lines = [
        *opening_lines(readings, table, rate_from, rate_robust_from, boltz),
        *summary_lines(readings, by_reading), "",
        *rule_lines(readings, ALPHA),
        f"Generated {now} by kicktimes {__version__} (`{command}`) from the stores {names}. "
        "Every number below is computed from the stores ([disks.csv](disks.csv), "
        "[disks_hazard.csv](disks_hazard.csv), [disks_null.csv](disks_null.csv)); nothing "
        "is typed.", "",
        "The tagged disk's disk-disk collision times among N equal hard disks in the unit "
        f"circular table (`kicktimes.simulate_disks`), from N = {min(exp0.n_disks)} to "
        f"{max(exp0.n_disks)}, at packing 0.02, "
        "at packing 0.2 and at the fixed radius 0.0045, under the mirror and the elastic "
        f"rule. Each tagged disk is read at a fixed number of collisions, its first K = {k} "
        f"(the window ends at collision {k + 1}). Scale: about {exp0.n_tagged} tagged disks "
        f"per N (at least {int(table[table['n_disks'] > 2]['n_runs'].min())} independent "
        f"runs per N at N > 2, at most {exp0.max_tagged_per_run} tagged disks per run, one "
        "of the two at N = 2); states from `kicktimes.initial_state` (equilibrated, elastic "
        "on the energy shell Σ|v|² = N, kT = 1/2). The null streams (`stats.dilute_tagged_"
        "times`, `studies.disks.null`): per tagged disk a Poisson stream at its run's "
        "collision frequency over its run's window, and under the elastic rule the dilute "
        "tagged disk (the linear Boltzmann Cox process of Visco, van Wijland & Trizac, "
        "J. Phys. Chem. B 112, 5412 and Phys. Rev. E 77, 041117 (2008): rate ∝ ⟨|v − w|⟩ "
        "over a Maxwellian partner at kT = 1/2, scaled to the run's rate; partners and "
        "contact directions from the collision kernel; elastic equal-mass collisions).", "",
        "## The answers", "",
        "**Does the tagged disk's process become Poisson as N grows?** The reading at every "
        "N (the rule above), and the KS share and D at the smallest and largest N:", "",
        *family_lines(readings), "",
        *_short_answers(kicked, long), "",
        "**How much of the elastic gas's non-Poisson statistics does the speed carry?** "
        "(Visco, van Wijland & Trizac 2008: the tagged disk as a Cox process whose rate "
        "ν(v) changes at its collisions; each interval rescaled by ν(v)/ν̄, "
        "`stats.speed_rate_factor`.)", "",
        *_speed_answers(table, readings), "",
        "**Against the Boltzmann-kicked disk** (the linear Boltzmann tagged disk, the "
        "kinetic theory's prediction, through the same estimators; section below): D at "
        "the largest N, gas vs kicked disk:", "",
        *boltzmann_answer(boltz), "",
        "**The refractory dip and the return peak** (the hazard of the next collision "
        "against the time since the last, over the constant rate; 1 for Poisson): the first "
        "bin, [0, 0.01) mean intervals, and the highest later bin:", "",
        *_hazard_answers(table), "",
        "**The collision rate against Enskog–Henderson** (kinetic theory, "
        "`stats.enskog_frequency`):", "",
        *_rate_answers(table), "",
        *_two_disk_answers(checks),
        *(kicked_answer(kicked, kicked_stores[0].experiment) if not kicked.empty else []),
        "Verdicts. Rejection shares are read against their calibrated level "
        "(`stats.rejection_verdict` with the Poisson null's share in place of α; a run "
        "there is a tagged disk here): at the level when the 95 % interval lies within 50 % "
        "of it, above or below when it lies entirely outside that band, inconclusive "
        "otherwise; disks.csv keeps the verdicts against the nominal α (" + rejection_rule(ALPHA)
        + "). Ratios and D (`stats.ratio_verdict`): " + ratio_rule(0.1).split(". Robust")[0]
        + ". 95 % intervals: percentile bootstrap clustered on runs (999 replicates; for a "
        "share, the wider of that and Clopper–Pearson) for the shares, D, the rates, the "
        "speed share and the hazard's first and highest later bins (disks.csv); the hazard "
        "figure's bands and disks_hazard.csv are Garwood intervals on the pooled intervals "
        "of all tagged disks, taken as independent: they ignore the correlation between the "
        "intervals of one disk and of the disks of one run, and so does the hazard "
        "flatness test, whose p-value may be too small by an unknown factor; the gamma "
        "shape's interval (disks.csv) is ±1.96 standard errors of its maximum-likelihood fit "
        "on the pooled intervals, taken as independent in the same way, and a gamma shape "
        "called within 10 % may still exclude 1.", "",
    ]
    for geo in geometries_of(table):
        lines += [f"## {geo}", "", *_geometry_tables(table, readings, geo), ""]
    lines += [
        "Columns: r the disk radius; tagged (dropped): tagged disks per rule (mirror / "
        f"elastic) and, in brackets, the number dropped in that row: those with fewer than "
        f"{k + 1} collisions in their run, left out of the tests (two disks whose conserved "
        "state makes them collide rarely, or a slow disk); rate: 2 n_pp / (N t) over all "
        "disks; rejected: uniform times (KS) at "
        f"α = {ALPHA:g}; D: the variance over the mean of the tagged disks' collision counts "
        f"in a common window of K mean intervals (in the rescaled clock for the rescaled "
        "column); reading: `stats.poisson_verdict` (the rule under the first table), the "
        "rescaled column against the dilute tagged disk's rescaled level; the kicked "
        "comparison's columns are in its own section. Every test of the battery "
        f"({', '.join(TESTS)}), the gamma renewal "
        "shape, the hazard's first bin and both rates are in [disks.csv](disks.csv).", "",
        "![rejection shares](disks_rejection_vs_n.png)", "",
        "**Rejection shares against N**: uniform times (top) and exponential intervals "
        "(Anderson–Darling, bottom), per geometry, on a log y axis; grey: the nominal band "
        f"[{100 * ALPHA * 0.5:g}, {100 * ALPHA * 1.5:g}] %, line: {100 * ALPHA:g} %; dotted "
        "with crosses: the share the Poisson null streams shaped like each rule's runs "
        "reject (the calibrated level); 95 % CIs; "
        "the three series dodged sideways, with different markers.", "",
        "![hazard](disks_hazard_vs_n.png)", "",
        "**The hazard of the next collision against the time since the last**, in units of "
        f"the mean interval (log scale; the first bin, [0, 0.01), drawn from {X_MIN:g}), over "
        "the constant rate (1 for a Poisson process), for N = "
        f"{', '.join(str(n) for n in SHOWN_N)}; top rows: the whole range (log y); bottom "
        f"rows: N ≥ {ZOOM_MIN_N} zoomed near 1 (linear y, ±10 % shaded; a bin beyond a "
        "row's limits is a filled triangle at the edge with its value, a bin whose 95 % "
        "band alone leaves them an open triangle); 95 % Garwood "
        "bands (intervals pooled and taken as independent); per-bin values in "
        "[disks_hazard.csv](disks_hazard.csv).",
        "",
        "![rates and dispersion](disks_rate_dispersion_vs_n.png)", "",
        "**Against N: the collision frequency over Enskog's, the index of dispersion D, and "
        "the hazard within 0.01 mean intervals of the last collision over the constant rate "
        "(the refractory dip)**; solid: mirror, dashed: elastic; 95 % CIs; grey: ±10 %; "
        "points dodged sideways; in the first panel the N = 2 points are against Enskog, "
        "whose kinetic theory does not hold for two disks (the two-disk kinetic rate is the "
        "reference there: stars, the rate over Γ(r)).", "",
    ]
    lines += [*controls_lines(long)]
    if with_controls_figure:
        lines += [
            "![controls](disks_controls_vs_n.png)", "",
            f"**The findings under their controls against N** (N ≥ {CONTROLS_MIN_N}): per "
            "geometry and rule (rows) the index of dispersion D, the share of tagged disks "
            "rejecting uniform times and the first hazard bin over the constant rate "
            "(columns), under each control (colours and markers, dodged sideways); 95 % "
            f"CIs; grey: ±10 % (the nominal band [{100 * ALPHA * 0.5:g}, "
            f"{100 * ALPHA * 1.5:g}] % for the share); "
            "hollow markers: the finding is not robust at that N (it depends on a control).",
            ""]
    lines += boltzmann_lines(boltz)
    if "box" in by_control:
        shares = wall_shares(table, by_control["box"])
        shares.to_csv(out / "disks_wall_share.csv", index=False)
        lines += wall_share_lines(shares)
    lines += windows_lines(out / "disks_dispersion_windows.csv")
    lines += renewal_lines(renewal)
    if not kicked.empty:
        lines += kicked_section(kicked, kicked_stores[0].experiment, rate_check)
    lines += ftle_check_lines(out / "disks_ftle_check.csv")
    lines += density_lines(out / "disks_lyapunov_density.csv",
                           out / "disks_lyapunov_density_fit.csv")
    lines += ["## Cost", ""]
    sweeps = ""
    if cost is not None:
        no_cpu = cost[cost["cpu_seconds"].isna()]
        sweeps = (f"The disks sweeps: {cost['cpu_seconds'].sum():.0f} s of CPU in all, on one "
                  "core" + (f" (the two-disk references: {no_cpu['wall_seconds'].sum():.0f} s "
                            "of wall time, their tasks record no CPU time)"
                            if not no_cpu.empty else "")
                  + " ([disks_cost.csv](disks_cost.csv)); ")
    if cost is not None:
        cost.to_csv(out / "disks_cost.csv", index=False)
    lines += [f"{sweeps}these tables and figures: {analysis_cpu:.0f} s of CPU.", "",
              "## Left out", "", *_left_out(table, long, kicked_stores, k,
                                          (out / "disks_ftle_check.csv").exists()), ""]
    elastic = bool((table["rule"] == "elastic").any())
    return write_results_page(out / "disks.md", lines, sources(out, elastic=elastic))
