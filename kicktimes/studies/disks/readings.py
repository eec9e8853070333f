"""docs/results/disks.md: the one reading of "Poisson", against the null calibration.

Every "Poisson" / "not Poisson" on the page is `kicktimes.stats.poisson_verdict` of a row
of `kicktimes.studies.disks.tables.disks_table`: the share of tagged disks whose first K
collision times reject uniform times (KS, `POISSON_TEST`) against the share that Poisson
streams shaped like the runs reject through the same pipeline (the calibrated level,
`kicktimes.studies.disks.null`), and the dispersion index D against the band [0.9, 1.1].
Under the elastic rule the speed-rescaled stream is read the same way, against the share
the dilute tagged disk's rescaled streams reject (linear Boltzmann, whose rescaled stream
is exactly Poisson), and the dilute tagged disk's D at the same windows is the kinetic
theory's prediction quoted beside the gas's D.

`poisson_readings` is the table (``disks_poisson.csv``), `opening_lines` the page's first
screen (the answers before the first table), `summary_lines` its first table,
`family_lines` the reading per geometry and rule against N.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import format_interval, poisson_rule, poisson_verdict, rejection_verdict
from kicktimes.studies.disks.null import null_level

__all__ = ["POISSON_TEST", "POISSON_WITHIN", "opening_lines", "poisson_by_control",
           "poisson_from", "poisson_readings", "summary_lines", "family_lines"]

#: the test whose calibrated rejection share `poisson_verdict` reads
POISSON_TEST = "uniformity_ks"
#: the verdict of a stream read as Poisson
POISSON_WITHIN = "Poisson within 10 %"


def _holds_from(ns, ok):
    ok = np.asarray(ok, dtype=bool)
    return next((int(ns[m]) for m in range(len(ns)) if ok[m:].all()), None)


def _pct(est, lo, hi, level=None):
    edges = (100 * level * 0.5, 100 * level, 100 * level * 1.5) if level else (5.0,)
    return f"{format_interval(100 * est, 100 * lo, 100 * hi, edges=edges)} %"


def poisson_readings(table, nulls, *, test=POISSON_TEST) -> pd.DataFrame:
    """One row per row of ``table`` (a `disks_table`): the gas's rejection share of
    ``test`` and D, the calibrated level (the ``"poisson"`` null's share of the same row,
    `kicktimes.studies.disks.null.null_rows`), the share's verdict against it
    (`rejection_verdict`, within 50 %) and `poisson_verdict`; elastic rows also the
    speed-rescaled reading (against the ``"dilute"`` null's rescaled share) and the
    dilute tagged disk's D (``dilute_d``), the kinetic theory's prediction of D."""
    key = f"reject_{test}"
    out = []
    for _, r in table.iterrows():
        geo, rule, n = r["geometry"], r["rule"], int(r["n_disks"])
        level = null_level(nulls, geo, rule, n, key)
        row = {"geometry": geo, "rule": rule, "n_disks": n, "test": test,
               "share": r[key], "share_low": r[f"{key}_low"], "share_high": r[f"{key}_high"],
               "null_level": level,
               "share_verdict": rejection_verdict(r[f"{key}_low"], r[f"{key}_high"], level)
               if np.isfinite(level) else "not calibrated",
               "d": r["dispersion"], "d_low": r["dispersion_low"],
               "d_high": r["dispersion_high"],
               "verdict": poisson_verdict(r[f"{key}_low"], r[f"{key}_high"], level,
                                          r["dispersion_low"], r["dispersion_high"])
               if np.isfinite(level) else "not calibrated"}
        g = nulls[(nulls["geometry"] == geo) & (nulls["rule"] == rule)
                  & (nulls["n_disks"] == n)].set_index("design")
        if "poisson" in g.index:
            p = g.loc["poisson"]
            row.update(null_low=p[f"{key}_low"], null_high=p[f"{key}_high"],
                       null_d=p["dispersion"], null_d_low=p["dispersion_low"],
                       null_d_high=p["dispersion_high"])
        if rule == "elastic" and "dilute" in g.index:
            dl = g.loc["dilute"]
            lvl = float(dl[f"rescaled_{key}"])
            row.update(
                rescaled_share=r[f"rescaled_{key}"],
                rescaled_share_low=r[f"rescaled_{key}_low"],
                rescaled_share_high=r[f"rescaled_{key}_high"], rescaled_null_level=lvl,
                rescaled_d=r["rescaled_dispersion"],
                rescaled_d_low=r["rescaled_dispersion_low"],
                rescaled_d_high=r["rescaled_dispersion_high"],
                rescaled_verdict=poisson_verdict(
                    r[f"rescaled_{key}_low"], r[f"rescaled_{key}_high"], lvl,
                    r["rescaled_dispersion_low"], r["rescaled_dispersion_high"]),
                dilute_share=dl[key], dilute_share_low=dl[f"{key}_low"],
                dilute_share_high=dl[f"{key}_high"], dilute_d=dl["dispersion"],
                dilute_d_low=dl["dispersion_low"], dilute_d_high=dl["dispersion_high"])
        out.append(row)
    return pd.DataFrame(out)


def poisson_from(readings, verdict=POISSON_WITHIN, column="verdict") -> dict:
    """Per (geometry, rule): the smallest N from which ``column`` is ``verdict`` at every
    larger N (None: no such N)."""
    out = {}
    for (geo, rule), g in readings.groupby(["geometry", "rule"], sort=False):
        g = g.sort_values("n_disks")
        out[geo, rule] = _holds_from(g["n_disks"].to_numpy(), g[column].eq(verdict))
    return out


def poisson_by_control(by_control, nulls) -> pd.DataFrame:
    """`poisson_readings` of every control's table (the primary design's calibrated
    levels: the nulls are shaped like the primary runs), with a ``control`` column."""
    return pd.concat([poisson_readings(t, nulls).assign(control=c)
                      for c, t in by_control.items()], ignore_index=True)


def _control_cell(controls, geo, rule, n):
    if controls is None or controls.empty:
        return "not run"
    g = controls[(controls["geometry"] == geo) & (controls["rule"] == rule)
                 & (controls["n_disks"] == n)]
    prim = g[g["control"] == "primary"]["verdict"]
    if prim.empty:
        return "—"
    differ = g[(g["control"] != "primary") & (g["verdict"] != prim.iloc[0])]
    return ("same under all" if differ.empty
            else "differs: " + ", ".join(differ["control"]))


#: the share's verdict against its calibrated level, in words
LEVEL_WORDS = {"nominal": "at its calibrated level", "above nominal": "above its calibrated level",
               "below nominal": "below its calibrated level", "inconclusive": "inconclusive"}


def _level(verdict):
    return LEVEL_WORDS.get(verdict, verdict)


def _groups(items):
    """``{verdict: [family, ...]}`` preserving order."""
    out = {}
    for verdict, fam in items:
        out.setdefault(verdict, []).append(fam)
    return out


def opening_lines(readings, table, rate_from, rate_robust_from, boltz=None) -> list:
    """The page's first screen: whether the tagged disk's process is Poisson (at the
    largest N), from which N, and how the gas compares with kinetic theory (Enskog's rate;
    D against the Boltzmann-kicked disk's, `kicktimes.studies.disks.boltzmann`, when
    ``boltz`` is given, else the dilute tagged disk's D), each from a computed table."""
    big = readings.groupby(["geometry", "rule"], sort=False).tail(1)
    n_max = int(big["n_disks"].max())
    by = _groups((r["verdict"], f"{r['geometry']} {r['rule']}") for _, r in big.iterrows())
    verdicts = "; ".join(f"{v}: {', '.join(f)}" for v, f in by.items())
    froms = poisson_from(readings)
    found = {f"{g} {r}": n for (g, r), n in froms.items() if n is not None}
    from_text = ("; ".join(f"{f} from N = {n}" for f, n in found.items())
                 + ("; at no N in the others" if len(found) < len(froms) else "")
                 if found else "at no geometry and rule (no N from which every larger N "
                 "reads so)")
    el = big[big["rule"] == "elastic"]
    diff = sum(1 for _, r in el.iterrows() if "dilute_d" in r and np.isfinite(r["dilute_d"])
               and (r["d_low"] > r["dilute_d_high"] or r["d_high"] < r["dilute_d_low"]))
    rate = (f"within 10 % of Enskog's from N = {rate_from} on at every geometry and rule"
            if rate_from else "not within 10 % of Enskog's from one N on everywhere")
    rate += (f" (under every control from N = {rate_robust_from} on)" if rate_robust_from
             else "")
    theory = (f"the elastic gas's D at N = {n_max} differs from the dilute tagged disk's "
              f"(linear Boltzmann, same windows) at {diff} of {len(el)} geometries")
    if boltz is not None and not boltz.empty:
        d = boltz[(boltz["n_disks"] == n_max) & (boltz["statistic"] == "dispersion")]
        agree = [f"{r['geometry']} {r['rule']}" for _, r in d.iterrows()
                 if r["verdict"].startswith("within")]
        depart = [f"{r['geometry']} {r['rule']} ({r['reading'].split(' by ')[-1]})"
                  for _, r in d.iterrows() if r["verdict"] in ("higher", "lower")]
        theory = (f"D at N = {n_max} beside the Boltzmann-kicked disk's (linear Boltzmann, "
                  "same windows): within 10 % at " + (", ".join(agree) or "none")
                  + "; departs at " + (", ".join(depart) or "none")
                  + f"; inconclusive at the other {len(d) - len(agree) - len(depart)}")
    return [
        "# From two disks to a gas (generated)", "",
        f"**Is the tagged disk's collision process Poisson?** At N = {n_max}, by the one "
        f"rule stated below the table: {verdicts}. **From which N?** {POISSON_WITHIN} "
        f"at every larger N: {from_text}. **Against kinetic theory:** the collision rate is "
        f"{rate}; {theory}.", ""]


def summary_lines(readings, controls=None) -> list:
    """The first table: per geometry and rule at the largest N, the share against its
    calibrated level, D, the verdict, from which N it reads Poisson, and under the
    controls."""
    head = ["geometry, rule", "N", "KS rejected", "Poisson null", "D", "reading",
            "Poisson from N", "controls"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    froms = poisson_from(readings)
    for (geo, rule), g in readings.groupby(["geometry", "rule"], sort=False):
        r = g.sort_values("n_disks").iloc[-1]
        n = int(r["n_disks"])
        out.append("| " + " | ".join([
            f"{geo}, {rule}", str(n),
            _pct(r["share"], r["share_low"], r["share_high"], r["null_level"]),
            f"{100 * r['null_level']:.2f} %",
            format_interval(r["d"], r["d_low"], r["d_high"]), r["verdict"],
            str(froms[geo, rule]) if froms[geo, rule] else "none",
            _control_cell(controls, geo, rule, n)]) + " |")
    return out


def rule_lines(readings, alpha) -> list:
    """The rule, printed once, and what it says of the shares entirely above their level."""
    n_above = int((readings["share_low"] > readings["null_level"]).sum())
    n_at = int(((readings["share_low"] > readings["null_level"])
                & (readings["share_verdict"] == "nominal")).sum())
    lo, hi = readings["null_level"].min(), readings["null_level"].max()
    return [
        f"The rule (`stats.poisson_verdict`): {poisson_rule()}. The test is KS of the first "
        f"K collision times against uniform times (α = {alpha:g}); its calibrated level is "
        f"the share the same test rejects on Poisson streams at each run's collision "
        f"frequency, with the runs' windows, numbers of runs and tagged disks and bootstrap "
        f"clusters ({100 * lo:.2f}–{100 * hi:.2f} % over the rows; every null row in "
        f"[null_calibration.csv](null_calibration.csv), the page's readings in "
        f"[disks_poisson.csv](disks_poisson.csv)). Of the {len(readings)} rows, {n_above} "
        f"have a share whose interval lies entirely above its calibrated level; {n_at} of "
        "them are at the level by the rule (within 50 % of it): a departure smaller than the "
        "rule's margin, not read as one. The hazard's flatness p-value takes the intervals "
        "as independent and may be too small by an unknown factor: no reading rests on it.",
        ""]


def family_lines(readings) -> list:
    """Per geometry and rule, the reading at every N."""
    lines = []
    for (geo, rule), g in readings.groupby(["geometry", "rule"], sort=False):
        g = g.sort_values("n_disks")
        cells = "; ".join(f"{int(r['n_disks'])}: {r['verdict']}" for _, r in g.iterrows())
        lo, hi = g.iloc[0], g.iloc[-1]
        text = (f"- **{geo}, {rule}** — N = {cells}. KS share at N = {int(lo['n_disks'])} "
                f"{_pct(lo['share'], lo['share_low'], lo['share_high'], lo['null_level'])} "
                f"({_level(lo['share_verdict'])}), at N = {int(hi['n_disks'])} "
                f"{_pct(hi['share'], hi['share_low'], hi['share_high'], hi['null_level'])} "
                f"({_level(hi['share_verdict'])}); D "
                f"{format_interval(lo['d'], lo['d_low'], lo['d_high'])} → "
                f"{format_interval(hi['d'], hi['d_low'], hi['d_high'])}.")
        if rule == "elastic" and "rescaled_verdict" in g:
            text += (" Speed-rescaled (against the dilute null's rescaled level): N = "
                     + "; ".join(f"{int(r['n_disks'])}: {r['rescaled_verdict']}"
                                 for _, r in g.iterrows()) + ".")
        lines.append(text)
    return lines
