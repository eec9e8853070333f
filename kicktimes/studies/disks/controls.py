"""The disks page's findings under their controls: docs/results/disks_controls.csv.

(Not named ``*_findings.csv``: those are the sweep report's tables, one schema with a
``question`` column, that tests/test_results_pages.py reads; this table has the columns
``claims_lint`` reads, ``family, diagnostic, system, control, estimate, ci_low, ci_high,
verdict, robust``, and its verdicts are of three kinds.)

Every finding of a row (geometry x rule x N) of `kicktimes.studies.disks.tables.disks_table` is
computed under the primary design and under each control:

* ``seed``: an independent replicate, the same sweep from another root seed (the store
  ``<sweep>-seed``, `kicktimes.experiment.DISKS_CONTROLS`);
* ``k60``: the tests read at K = 60 collisions per tagged disk instead of 30 (the store
  ``<sweep>-k60``, another seed too): the tests' power grows with K, so this control can
  turn "nominal" into "above nominal";
* ``bulk``: the primary store's tagged disks that start in the bulk, their centre within
  `BULK_WITHIN` of the table's centre (`kicktimes.studies.disks.tables.disks_table`'s ``within``):
  the wall changes a disk's surroundings, so a wall effect would show as a difference.
  The collision rate is a quantity of all disks of a run, so ``bulk`` is not a control of
  rate / Enskog.

A finding is **robust** (`kicktimes.stats.robust_verdict`) when every control gives the
primary's verdict and no control's interval lies above the finding's level while another's
lies below it; otherwise it *depends on* the controls whose verdict differs (or, for a
change of direction alone, whose interval lies on the other side of the level).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes.stats import format_interval, percentile_interval, robust_verdict

__all__ = ["BULK_WITHIN", "CONTROL_NAMES", "FINDINGS", "NOT_READ", "WALL_SHARE_MAX_WIDTH",
           "controls_findings", "controls_lines", "robust_text", "wall_share_lines",
           "wall_shares"]

#: the bulk control keeps the tagged disks starting within this distance of the centre
#: (a quarter of the table's area)
BULK_WITHIN = 0.5
#: the controls, in the page's order, and how the page names them
CONTROL_NAMES = {"primary": "primary (K = 30, seed 42)", "seed": "replicate (seed 1042)",
                 "k60": "K = 60", "bulk": f"bulk tagged disks (start |x| ≤ {BULK_WITHIN:g})",
                 "box": "periodic box of the same area (no wall; seed 3042)"}
#: a wall share is not decomposed when its interval is this wide or wider
WALL_SHARE_MAX_WIDTH = 1.0
#: finding -> (column of the control's table, level of its direction, kind of verdict); the
#: names are the CSV's ``diagnostic``. D, the KS share and the first hazard bin are read as
#: the difference from their own null streams (`kicktimes.studies.disks.versus_null`: each
#: control's store against Poisson streams shaped like its own runs, K = 60 at K = 60, so
#: that a D that grows with the window is compared with a null that grows too)
FINDINGS = {
    "D − null D": ("d_diff", 0.0, "null"),
    "KS share − null": ("ks_diff", 0.0, "null"),
    "hazard flatness": ("hazard_flat_pvalue", 0.05, "p"),
    "hazard first bin − null": ("hazard_first_diff", 0.0, "null"),
    "rate / Enskog": ("rate_enskog", 1.0, "ratio"),
}
#: findings kept in disks_controls.csv but not read on the page (the hazard's flatness
#: p-value takes the intervals as independent and may be too small by an unknown factor)
NOT_READ = ("hazard flatness",)
#: the controls that do not apply to a finding
NOT_A_CONTROL = {("rate / Enskog", "bulk")}


def _p_verdict(p, alpha):
    if not np.isfinite(p):
        return "undetermined"
    return "flatness rejected" if p < alpha else "flatness not rejected"


def controls_findings(tables: dict) -> pd.DataFrame:
    """The long table of every finding under every control.

    Parameters
    ----------
    tables : dict
        Control name (``"primary"`` and any of `CONTROL_NAMES`) -> a `disks_table` of the
        sweeps under that control (rows ``geometry, rule, n_disks``).

    Returns
    -------
    pandas.DataFrame
        One row per geometry x rule x N x finding x control: ``family`` (``"<geometry>,
        <rule>"``), ``geometry``, ``rule``, ``n_disks``, ``system`` (``"N=<n>"``),
        ``diagnostic`` (the finding), ``control``, ``estimate``, ``ci_low``, ``ci_high``
        (NaN for the hazard's flatness, a p-value), ``verdict``, and over the group's
        controls ``robust`` (`kicktimes.stats.robust_verdict`), ``reason`` and
        ``depends_on`` (the controls that break it, ``;``-separated).

    Examples
    --------
    >>> import pandas as pd
    >>> row = dict(geometry="packing 0.02", rule="mirror", n_disks=30, d_diff=0.2,
    ...            d_diff_low=0.15, d_diff_high=0.25, d_verdict="above its null")
    >>> other = dict(row, d_diff=0.05, d_diff_low=-0.03, d_diff_high=0.09,
    ...              d_verdict="inconclusive")
    >>> t = controls_findings({"primary": pd.DataFrame([row]), "k60": pd.DataFrame([other])})
    >>> t[["control", "verdict", "robust", "depends_on"]].values.tolist()
    [['primary', 'above its null', False, 'k60'], ['k60', 'inconclusive', False, 'k60']]
    """
    if "primary" not in tables:
        raise ValueError(f"tables: needs the 'primary' table, got {sorted(tables)}")
    rows = []
    for control, table in tables.items():
        for _, r in table.iterrows():
            for finding, (key, level, kind) in FINDINGS.items():
                if key not in r or (finding, control) in NOT_A_CONTROL:
                    continue
                if kind == "p":
                    est, lo, hi = float(r[key]), math.nan, math.nan
                    verdict = _p_verdict(est, level)
                else:
                    est, lo, hi = float(r[key]), float(r[f"{key}_low"]), float(r[f"{key}_high"])
                    verdict = r[key.replace("_diff", "_verdict") if kind == "null"
                                else f"{key}_verdict"]
                if not np.isfinite(est):
                    continue
                rows.append({"family": f"{r['geometry']}, {r['rule']}",
                             "geometry": r["geometry"], "rule": r["rule"],
                             "n_disks": int(r["n_disks"]), "system": f"N={int(r['n_disks'])}",
                             "diagnostic": finding, "control": control, "estimate": est,
                             "ci_low": lo, "ci_high": hi, "verdict": verdict, "level": level})
    out = pd.DataFrame(rows)
    if out.empty:
        return out
    order = {c: m for m, c in enumerate(tables)}
    out["_order"] = out["control"].map(order)
    out = out.sort_values(["family", "n_disks", "diagnostic", "_order"], kind="stable")
    robust, reason, depends = {}, {}, {}
    for key, g in out.groupby(["family", "n_disks", "diagnostic"], sort=False, observed=True):
        ok, why = robust_verdict(g["verdict"].tolist(), g["ci_low"], g["ci_high"],
                                 level=float(g["level"].iloc[0]))
        robust[key], reason[key] = ok, why
        depends[key] = ";".join(_breaking(g)) if not ok else ""
    keys = list(zip(out["family"], out["n_disks"], out["diagnostic"], strict=True))
    out["robust"] = [robust[k] for k in keys]
    out["reason"] = [reason[k] for k in keys]
    out["depends_on"] = [depends[k] for k in keys]
    # restore the caller's order of geometries and rules
    fam = {f: m for m, f in enumerate(dict.fromkeys(
        f"{g}, {r}" for t in tables.values() for g, r in zip(t["geometry"], t["rule"],
                                                              strict=True)))}
    out["_fam"] = out["family"].map(fam)
    out = out.sort_values(["_fam", "n_disks", "diagnostic", "_order"], kind="stable")
    return out.drop(columns=["_order", "_fam", "level"]).reset_index(drop=True)


def _breaking(g):
    """The controls that break a group's robustness: those whose verdict is not the
    primary's, else (a change of direction alone) those on the other side of the level
    from the primary, else every control on the side opposite to the majority."""
    prim = g[g["control"] == "primary"].iloc[0]
    others = g[g["control"] != "primary"]
    diff = others[others["verdict"] != prim["verdict"]]["control"].tolist()
    if diff:
        return diff
    level = FINDINGS.get(prim["diagnostic"], (None, 1.0))[1]
    above, below = g["ci_low"] > level, g["ci_high"] < level
    side = "above" if above[prim.name] else "below" if below[prim.name] else None
    flip = below if side == "above" else above if side == "below" else None
    if flip is None:
        return [c for c in g[above | below]["control"] if c != "primary"]
    return g[flip]["control"].tolist()


def _number(row):
    if not np.isfinite(row["ci_low"]):
        return f"p = {row['estimate']:.2g}"
    spec = FINDINGS.get(row["diagnostic"])
    if spec is not None and spec[2] == "null":
        from kicktimes.studies.disks.readings import diff_text
        from kicktimes.studies.disks.versus_null import MARGINS

        margin = MARGINS[spec[0].removesuffix("_diff")]
        return diff_text(row["estimate"], row["ci_low"], row["ci_high"], margin)
    return format_interval(row["estimate"], row["ci_low"], row["ci_high"])


def robust_text(group) -> str:
    """``"robust: higher"`` or ``"depends on k60: 1.08 [1.03, 1.13] inconclusive (primary),
    1.21 [1.15, 1.27] higher (k60)"`` for the rows of one finding (one per control)."""
    prim = group[group["control"] == "primary"].iloc[0]
    if bool(prim["robust"]):
        return f"robust: {prim['verdict']}"
    on = [c for c in str(prim["depends_on"]).split(";") if c]
    shown = group[group["control"].isin(["primary", *on])]
    nums = ", ".join(f"{_number(r)} {r['verdict']} ({r['control']})"
                     for _, r in shown.iterrows())
    return f"depends on {', '.join(on) or 'the direction'}: {nums}"


def _cell(long, family, n, finding):
    """A short cell: ``"robust: higher"`` or ``"depends on seed, k60"`` (the numbers are in
    disks_controls.csv)."""
    g = long[(long["family"] == family) & (long["n_disks"] == n)
             & (long["diagnostic"] == finding)]
    if g.empty:
        return "—"
    prim = g[g["control"] == "primary"].iloc[0]
    if bool(prim["robust"]):
        return f"robust: {prim['verdict']}"
    on = [c for c in str(prim["depends_on"]).split(";") if c]
    return f"depends on {', '.join(on) or 'the direction'}"


def controls_lines(long, *, n_min=30) -> list:
    """The page's section on the controls: how many findings at N >= ``n_min`` are robust,
    how many depend on each control (a finding may depend on several), with the numbers in
    disks_controls.csv."""
    if long.empty:
        return []
    long = long[~long["diagnostic"].isin(NOT_READ)]
    prim = long[long["control"] == "primary"]
    controls = [c for c in CONTROL_NAMES if c in set(long["control"])]
    big = prim[prim["n_disks"] >= n_min]
    n_rob, n_all = int(big["robust"].sum()), len(big)
    by = {c: int(big["depends_on"].str.split(";").apply(lambda s, c=c: c in s).sum())
          for c in controls if c != "primary"}
    seed = by.get("seed", 0)
    # per finding the controls that were run for it, findings with the same controls together
    ran = {}
    for f, g in long[long["control"] != "primary"].groupby("diagnostic", sort=False):
        ran.setdefault(tuple(c for c in controls if c in set(g["control"])), []).append(f)
    per = "; ".join(f"{', '.join(fs)}: {', '.join(cs)}" for cs, fs in ran.items())
    return [
        "## Under the controls", "",
        "Each finding under the primary design and under the controls run for it ("
        + per + "); the controls: "
        + "; ".join(f"**{c}**: {CONTROL_NAMES[c]}" for c in controls if c != "primary")
        + ". Every control is read against Poisson streams shaped like its own runs. Robust "
        "(`stats.robust_verdict`): every control gives the "
        f"primary's verdict in the same direction. Of the {n_all} findings at N ≥ {n_min}, "
        f"{n_rob} are robust and {n_all - n_rob} depend on a control ("
        + ", ".join(f"{c}: {v}" for c, v in by.items())
        + f"). The replicate alone (another seed, the same design) changes {seed} of "
        f"{n_all} verdicts ({100 * seed / max(n_all, 1):.0f} %): those verdicts sit on their "
        "margins, and a verdict that a replicate changes is not read as a finding. Every "
        "number: [disks_controls.csv](disks_controls.csv).", ""]


def wall_shares(primary, box, *, n_min=30, n_draws=4000, seed=0) -> pd.DataFrame:
    """The share of the circle's departure from Poisson, ``D - 1``, that the wall makes:
    ``(D_circle - D_box) / (D_circle - 1)``, per geometry, rule and N (``>= n_min``),
    from the primary sweep (``primary``, `disks_table` rows) and its periodic-box control
    (``box``). The two are independent runs; the share's 95 % interval draws each D from
    a normal with its interval's width (±1.96 standard errors) and takes percentiles.
    Columns ``geometry, rule, n_disks, d_circle(_low, _high), d_box(_low, _high), share,
    share_low, share_high, reading`` (the reading of the speed share's rules: not
    decomposed where the circle's D reaches 1 or the interval is `WALL_SHARE_MAX_WIDTH`
    wide)."""
    rng = np.random.default_rng(seed)
    keys = ["geometry", "rule", "n_disks"]
    both = primary.merge(box, on=keys, suffixes=("", "_box"))
    rows = []
    for _, r in both[both["n_disks"] >= n_min].iterrows():
        dc, db = r["dispersion"], r["dispersion_box"]
        sc = (r["dispersion_high"] - r["dispersion_low"]) / (2 * 1.96)
        sb = (r["dispersion_high_box"] - r["dispersion_low_box"]) / (2 * 1.96)
        draws_c = rng.normal(dc, sc, n_draws)
        draws_b = rng.normal(db, sb, n_draws)
        with np.errstate(divide="ignore", invalid="ignore"):
            share = (dc - db) / (dc - 1.0)
            low, high = percentile_interval((draws_c - draws_b) / (draws_c - 1.0))
        text = format_interval(share, low, high, edges=(0.0, 1.0))
        if not r["dispersion_low"] > 1.0:
            reading = f"{text}: not decomposed (D's interval reaches 1)"
        elif high - low >= WALL_SHARE_MAX_WIDTH:
            reading = f"{text}: not decomposed (interval {high - low:.2g} wide)"
        elif low <= 0.0 <= high:
            reading = f"{text}: no wall share detected"
        elif low <= 1.0 <= high:
            reading = f"{text}: all of it not excluded"
        elif high < 0.0:
            reading = f"{text}: negative (the box departs more)"
        elif low > 1.0:
            reading = f"{text}: more than all (the box lies below Poisson)"
        else:
            reading = f"{text}: part of it"
        rows.append({"geometry": r["geometry"], "rule": r["rule"],
                     "n_disks": int(r["n_disks"]), "d_circle": dc,
                     "d_circle_low": r["dispersion_low"], "d_circle_high": r["dispersion_high"],
                     "d_box": db, "d_box_low": r["dispersion_low_box"],
                     "d_box_high": r["dispersion_high_box"], "share": share,
                     "share_low": low, "share_high": high, "reading": reading})
    return pd.DataFrame(rows)


def wall_share_lines(shares) -> list:
    """The section "What the wall makes": `wall_shares` as a table of 6 columns."""
    if shares.empty:
        return []
    head = ["geometry", "rule", "N", "D, circle", "D, box", "the wall's share of D − 1"]
    lines = [
        "## What the wall makes: the circle against the periodic box", "",
        "The same sweeps in the periodic square box of the same area (side √π, the same "
        "radius and packing, no wall; the control `box` of the table above, N ≥ 3), and "
        "the share of the circle's departure from Poisson that the wall makes, "
        "(D_circle − D_box) / (D_circle − 1), with a 95 % interval from both D's "
        "intervals (independent runs; normal draws); it is read only where the circle's "
        "D lies above 1 and the interval is narrower than "
        f"{WALL_SHARE_MAX_WIDTH:g}. Every control's other findings in the box: "
        "[disks_controls.csv](disks_controls.csv).", "",
        "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for _, r in shares.iterrows():
        lines.append("| " + " | ".join([
            r["geometry"], r["rule"], str(r["n_disks"]),
            format_interval(r["d_circle"], r["d_circle_low"], r["d_circle_high"]),
            format_interval(r["d_box"], r["d_box_low"], r["d_box_high"]),
            r["reading"]]) + " |")
    return lines + [""]
