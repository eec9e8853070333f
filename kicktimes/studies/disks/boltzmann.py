"""docs/results/disks.md: the gas's tagged disk beside the Boltzmann-kicked disk.

The paper's question transposed to a gas, like for like: one disk kicked at the rate
:math:`\\lambda(v)\\,g(\\sigma)` of its own speed by virtual partners drawn from the bath
(the Maxwellian on the energy shell under the elastic rule, the unit-speed kernel under
the mirror rule), each kick a collision that sets its new velocity. Its wall collisions
keep its speed, so its kick times do not depend on where it is: they are the linear
Boltzmann (Boltzmann-Lorentz) process of `kicktimes.stats.dilute_tagged_disk`, whatever the
table's shape. Its collision-time statistics are therefore computed from that process's
exact event Monte Carlo (`kicktimes.stats.dilute_tagged_times`) shaped like the gas's runs
(`kicktimes.studies.disks.null`: the ``"dilute"`` design under the elastic rule, the
Poisson design under the mirror rule, where every speed is 1 and the rate constant), at
each run's measured collision rate, through the page's own estimators
(`kicktimes.studies.disks.tables`): the share of tagged disks whose first K collision
times reject uniformity, the index of dispersion D of the counts in K mean intervals, the
hazard's first bin after a collision and a gamma renewal fit's shape.

What the Boltzmann equation leaves out is what the gas does beyond this process:
correlated re-collisions (ring events), the density's structure at contact beyond
Enskog's constant g(σ), and, in the circle, the wall layer. `boltzmann_table` sets each
statistic of the gas beside the kicked disk's, with their ratio and its verdict
(`kicktimes.stats.ratio_verdict`, margin 10 %, stated before the run) or, for the share,
the gas's share read against the kicked disk's as a calibrated level
(`kicktimes.stats.rejection_verdict`), and the large-sample prediction of
`kicktimes.stats.dilute_tagged_disk` beside both.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import (
    dilute_tagged_disk,
    format_interval,
    ratio_interval,
    ratio_verdict,
    rejection_verdict,
)

__all__ = ["BOLTZMANN_COLUMNS", "STATISTICS", "boltzmann_answer", "boltzmann_lines",
           "boltzmann_table", "dilute_predictions"]

#: the statistics compared, with the page's words: disks.csv's column names
STATISTICS = {"dispersion": "D", "hazard_first": "hazard, first bin",
              "gamma_shape": "gamma shape", "reject_uniformity_ks": "KS share"}
#: the columns of docs/results/disks_boltzmann_kicks.csv
BOLTZMANN_COLUMNS = ("geometry", "rule", "n_disks", "statistic", "gas", "gas_low", "gas_high",
                     "kicked", "kicked_low", "kicked_high", "prediction", "ratio", "ratio_low",
                     "ratio_high", "verdict", "reading")


def dilute_predictions(rule, collisions, *, hazard_bin=(0.0, 0.01), n_events=2_000_000,
                       seed=0) -> dict:
    """The large-sample predictions of the dilute tagged disk for one rule.

    Parameters
    ----------
    rule : {"elastic", "mirror"}
    collisions : int
        K: D is over a window of K mean intervals.
    hazard_bin : tuple of float
        The hazard's first bin (in mean intervals); the prediction is the hazard at its
        middle.
    n_events, seed :
        The Monte Carlo of `DiluteTaggedDisk.dispersion` at a finite window.

    Returns
    -------
    dict
        ``dispersion``, ``hazard_first``, ``gamma_shape``; ``reject_uniformity_ks`` is
        NaN (the share depends on the test's finite K: the kicked disk's column is it).

    Examples
    --------
    >>> dilute_predictions("mirror", 30)["dispersion"]
    1.0
    """
    disk = dilute_tagged_disk(rule)
    middle = 0.5 * (hazard_bin[0] + hazard_bin[1])
    return {"dispersion": float(disk.dispersion(collisions, n_events=n_events, rng=seed)),
            "hazard_first": float(disk.hazard(middle)),
            "gamma_shape": float(disk.gamma_shape), "reject_uniformity_ks": np.nan}


def _reading(verdict, ratio, low, high, statistic) -> str:
    if statistic == "reject_uniformity_ks":
        return {"nominal": "agrees (at the kicked disk's level)",
                "above nominal": "above the kicked disk's",
                "below nominal": "below the kicked disk's"}.get(verdict, "inconclusive")
    if verdict.startswith("within"):
        return f"agrees {verdict}"
    if verdict in ("higher", "lower"):
        return (f"departs from the kicked disk by {100 * (ratio - 1):+.0f} % "
                f"[{100 * (low - 1):+.0f}, {100 * (high - 1):+.0f}]")
    return "inconclusive"


def boltzmann_table(table, nulls, predictions=None) -> pd.DataFrame:
    """Each statistic of the gas beside the Boltzmann-kicked disk's, per geometry, rule and N.

    Parameters
    ----------
    table : DataFrame
        The gas's rows (`kicktimes.studies.disks.tables.disks_table`, disks.csv).
    nulls : DataFrame
        `kicktimes.studies.disks.null.null_rows` of the same stores: the kicked disk is the
        ``"dilute"`` design under the elastic rule and the ``"poisson"`` design under the
        mirror rule.
    predictions : dict, optional
        ``{(rule, K): dilute_predictions(rule, K)}``; computed when missing.

    Returns
    -------
    DataFrame
        Columns `BOLTZMANN_COLUMNS`. ``ratio`` is gas over kicked with the interval of
        `kicktimes.stats.ratio_interval` (independent samples) and the verdict of
        `ratio_verdict` (10 %); for the KS share, ``ratio`` is the gas's share over the
        kicked disk's and the verdict is `rejection_verdict` of the gas's interval at the
        kicked disk's share.
    """
    predictions = {} if predictions is None else dict(predictions)
    rows = []
    for _, gas in table.iterrows():
        design = "dilute" if gas["rule"] == "elastic" else "poisson"
        match = nulls[(nulls["geometry"] == gas["geometry"]) & (nulls["rule"] == gas["rule"])
                      & (nulls["n_disks"] == gas["n_disks"]) & (nulls["design"] == design)]
        if match.empty:
            continue
        kicked = match.iloc[0]
        key = (gas["rule"], int(gas["collisions"]))
        if key not in predictions:
            predictions[key] = dilute_predictions(*key)
        for stat in STATISTICS:
            values = [gas.get(stat), gas.get(f"{stat}_low"), gas.get(f"{stat}_high"),
                      kicked.get(stat), kicked.get(f"{stat}_low"), kicked.get(f"{stat}_high")]
            values = [float(v) if v is not None else np.nan for v in values]
            if not np.isfinite(values[0]) or not np.isfinite(values[3]):
                continue
            if stat == "reject_uniformity_ks":
                ratio = values[0] / values[3] if values[3] > 0 else np.nan
                low = high = np.nan
                verdict = rejection_verdict(values[1], values[2], values[3])
            else:
                ratio, low, high = ratio_interval(*values)
                verdict = ratio_verdict(low, high)
            rows.append({"geometry": gas["geometry"], "rule": gas["rule"],
                         "n_disks": int(gas["n_disks"]), "statistic": stat,
                         "gas": values[0], "gas_low": values[1], "gas_high": values[2],
                         "kicked": values[3], "kicked_low": values[4],
                         "kicked_high": values[5], "prediction": predictions[key][stat],
                         "ratio": ratio, "ratio_low": low, "ratio_high": high,
                         "verdict": verdict,
                         "reading": _reading(verdict, ratio, low, high, stat)})
    return pd.DataFrame(rows, columns=list(BOLTZMANN_COLUMNS))


def _cell(row) -> str:
    if row["statistic"] == "reject_uniformity_ks":
        return (f"{100 * row['gas']:.3g} % vs {100 * row['kicked']:.3g} %: "
                f"{row['reading']}")
    return (f"{format_interval(row['gas'], row['gas_low'], row['gas_high'])} vs "
            f"{format_interval(row['kicked'], row['kicked_low'], row['kicked_high'])}: "
            f"{row['reading']}")


def boltzmann_answer(boltz, statistic="dispersion") -> list:
    """The answers' table: at the largest N, per geometry and rule, the gas's statistic
    beside the Boltzmann-kicked disk's and its reading (`boltzmann_table`)."""
    if boltz.empty:
        return []
    at = boltz[(boltz["n_disks"] == boltz["n_disks"].max())
               & (boltz["statistic"] == statistic)]
    head = ["geometry", "rule", "N", f"{STATISTICS[statistic]}, gas",
            f"{STATISTICS[statistic]}, kicked disk", "reading"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for _, r in at.iterrows():
        out.append("| " + " | ".join([
            r["geometry"], r["rule"], str(int(r["n_disks"])),
            format_interval(r["gas"], r["gas_low"], r["gas_high"]),
            format_interval(r["kicked"], r["kicked_low"], r["kicked_high"]),
            r["reading"]]) + " |")
    return out


def boltzmann_lines(boltz, *, n_disks=None) -> list:
    """The section "The gas beside the Boltzmann-kicked disk": the method in a paragraph,
    one table at the largest N (rows: geometry and rule; columns: the statistics, each
    "gas vs kicked: reading"), the predictions, and the full table's file."""
    if boltz.empty:
        return []
    n = int(boltz["n_disks"].max()) if n_disks is None else n_disks
    at = boltz[boltz["n_disks"] == n]
    heads = ["geometry, rule", *STATISTICS.values()]
    lines = [
        "## The gas beside the Boltzmann-kicked disk", "",
        "The paper's question, transposed to the gas like for like: one disk kicked at the "
        "rate λ(v) g(σ) of its own speed by virtual partners from the bath (the Maxwellian "
        "under the elastic rule, the unit-speed kernel under the mirror rule). Its walls "
        "keep its speed, so its kick times are the linear Boltzmann process "
        "(`kicktimes.stats.dilute_tagged_disk`) whatever the table: they are drawn exactly "
        "(`dilute_tagged_times`), shaped like the gas's runs (same runs, tagged disks, "
        "windows, each run's measured rate) and put through this page's estimators. Gas "
        "vs kicked disk, ratio's 95 % interval from both intervals "
        "(`kicktimes.stats.ratio_interval`), agreement: the interval inside ±10 % "
        "(`ratio_verdict`, margin stated before the run); the KS share is read against "
        "the kicked disk's share as a calibrated level (`rejection_verdict`). What departs "
        "is what the Boltzmann equation leaves out: re-collisions, structure at contact "
        "beyond Enskog's g(σ), the wall layer. Every N: "
        "[disks_boltzmann_kicks.csv](disks_boltzmann_kicks.csv).", "",
        f"**N = {n}** (gas vs Boltzmann-kicked disk)", "",
        "| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    for (geo, rule), g in at.groupby(["geometry", "rule"], sort=False):
        cells = []
        for stat in STATISTICS:
            r = g[g["statistic"] == stat]
            cells.append(_cell(r.iloc[0]) if len(r) else "—")
        lines.append(f"| {geo}, {rule} | " + " | ".join(cells) + " |")
    pred = (boltz.drop_duplicates(["rule", "statistic"])
            .set_index(["rule", "statistic"])["prediction"])
    if ("elastic", "dispersion") in pred.index:
        lines += ["", "The large-sample predictions of the dilute tagged disk "
                  "(`dilute_tagged_disk`), elastic rule: D over the window "
                  f"{pred['elastic', 'dispersion']:.4g}, first hazard bin "
                  f"{pred['elastic', 'hazard_first']:.4g}, gamma shape "
                  f"{pred['elastic', 'gamma_shape']:.4g}; mirror rule: 1, 1, 1. The kicked "
                  "disk's columns are these with the runs' finite samples and estimators."]
    return lines + [""]
