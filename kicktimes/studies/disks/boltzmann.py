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
statistic of the gas beside the kicked disk's, with their difference and its verdict
(`kicktimes.stats.null_verdict`, the statistic's margin stated before the run:
`kicktimes.studies.disks.versus_null.MARGINS`), and the large-sample prediction of
`kicktimes.stats.dilute_tagged_disk` beside both.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.stats import dilute_tagged_disk

__all__ = ["BOLTZMANN_COLUMNS", "STATISTICS", "boltzmann_lines",
           "boltzmann_table", "dilute_predictions"]

#: the statistics compared, with the page's words: disks.csv's column names
STATISTICS = {"dispersion": "D", "hazard_first": "hazard, first bin",
              "gamma_shape": "gamma shape", "reject_uniformity_ks": "KS share"}
#: the columns of docs/results/disks_boltzmann_kicks.csv
BOLTZMANN_COLUMNS = ("geometry", "rule", "n_disks", "statistic", "gas", "gas_low", "gas_high",
                     "kicked", "kicked_low", "kicked_high", "prediction", "diff", "diff_low",
                     "diff_high", "margin", "verdict", "reading")


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
    return {"dispersion": float(disk.dispersion(window=collisions, n_events=n_events, rng=seed)),
            "hazard_first": float(disk.hazard(middle)),
            "gamma_shape": float(disk.gamma_shape), "reject_uniformity_ks": np.nan}


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
        Columns `BOLTZMANN_COLUMNS`. ``diff`` is gas minus kicked disk, its 95 % interval
        from both intervals (independent samples: the half-widths added in quadrature, on
        each side), and ``verdict`` `versus_null.edge_null_verdict` of it with the
        statistic's margin (`kicktimes.studies.disks.versus_null.MARGINS`: half the
        Boltzmann tagged disk's own departure from Poisson in it).
    """
    from kicktimes.studies.disks.versus_null import MARGINS, edge_null_verdict

    margins = {"dispersion": MARGINS["d"], "hazard_first": MARGINS["hazard_first"],
               "gamma_shape": MARGINS["gamma"], "reject_uniformity_ks": MARGINS["ks"]}
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
            g, g_lo, g_hi, k, k_lo, k_hi = values
            diff = g - k
            low = diff - np.hypot(g - g_lo, k_hi - k)
            high = diff + np.hypot(g_hi - g, k - k_lo)
            verdict = edge_null_verdict(low, high, margins[stat])
            rows.append({"geometry": gas["geometry"], "rule": gas["rule"],
                         "n_disks": int(gas["n_disks"]), "statistic": stat,
                         "gas": g, "gas_low": g_lo, "gas_high": g_hi,
                         "kicked": k, "kicked_low": k_lo, "kicked_high": k_hi,
                         "prediction": predictions[key][stat], "diff": diff,
                         "diff_low": low, "diff_high": high, "margin": margins[stat],
                         "verdict": verdict,
                         "reading": verdict.replace("its null", "the kicked disk's")})
    return pd.DataFrame(rows, columns=list(BOLTZMANN_COLUMNS))


def _cell(row) -> str:
    from kicktimes.studies.disks.readings import diff_text

    return (f"{row['gas']:.4g} vs {row['kicked']:.4g}: "
            + diff_text(row["diff"], row["diff_low"], row["diff_high"], row["margin"])
            + f" {row['reading']}")


def boltzmann_lines(boltz, *, n_disks=None) -> list:
    """The section "The gas beside the Boltzmann-kicked disk" at the largest N: the method
    in a sentence, D per geometry and rule (gas - kicked disk, its interval and reading),
    and how many of the other statistics lie within their margins; every N and statistic
    in the CSV."""
    if boltz.empty:
        return []
    n = int(boltz["n_disks"].max()) if n_disks is None else n_disks
    at = boltz[boltz["n_disks"] == n]
    # the mirror rule's kicked disk is a Poisson process: its D is the page's null D
    d = at[(at["statistic"] == "dispersion") & (at["rule"] == "elastic")]
    if d.empty:
        d = at[at["statistic"] == "dispersion"]
    from kicktimes.studies.disks.versus_null import EDGE_VERDICTS as EDGE

    rest = at[at["statistic"] != "dispersion"]
    counts = rest["verdict"].value_counts()
    cells = "; ".join(f"{r['geometry']}, {r['rule']}: {_cell(r)}" for _, r in d.iterrows())
    return [
        "## The gas beside the Boltzmann-kicked disk", "",
        "One disk kicked at the rate of its own speed by partners from the bath: the linear "
        "Boltzmann process (`stats.dilute_tagged_disk`; under the mirror rule a Poisson "
        "process), drawn exactly, shaped like the gas's runs and put through this page's "
        "estimators; gas − kicked disk with its 95 % interval (independent samples), read "
        f"with each statistic's margin (`stats.null_verdict`). At N = {n}, D (gas vs kicked "
        f"disk: gas − kicked): {cells}. The other {len(rest)} (hazard's first bin, gamma "
        f"shape, KS share): {int(counts.get('at its null', 0))} within their margin, "
        f"{int(counts.get('above its null', 0) + counts.get('below its null', 0))} depart, "
        f"{sum(int(counts.get(v, 0)) for v in EDGE)} beyond it, size unresolved, "
        f"{int(counts.get('inconclusive', 0))} inconclusive. Every N and statistic: "
        "[disks_boltzmann_kicks.csv](disks_boltzmann_kicks.csv).", ""]
