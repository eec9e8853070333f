r"""The equation-of-state study's tables, from the runs' halves (`run.run_cell`).

Every interval is the estimate :math:`\pm 3` standard errors over the cell's independent
states (each state's value the mean of its two halves), as the check's statement asks
("its 3-SE interval inside the margin"); ratios to a reference divide that interval by the
reference. Verdicts: `kicktimes.stats.ratio_verdict` at the margin `reference_margin`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.stats import t as student

from kicktimes.stats import EOS_MARGIN, henderson_z, kolafa_rottner_z, ratio_verdict, virial_z

__all__ = ["KOLAFA_ROTTNER_ERROR", "SE_MULTIPLE", "VIRIAL_RANGE", "contact_speed_prediction",
           "coverage", "eos_table", "finite_size", "frequency_table", "halves_table", "pooled",
           "pooled_table", "reference_margin", "states_to_resolve"]

#: intervals are the estimate +- this many standard errors
SE_MULTIPLE = 3.0
#: the virial series is the reference up to this packing (issue 64; at 0.5 its truncation
#: at B10 is 0.6 % low)
VIRIAL_RANGE = 0.4
#: Kolafa & Rottner's relative accuracy: their MD pressures' errors, which the fit
#: reproduces within 1.2 of them (2e-6 at rho sigma^2 = 0.4 to 1e-5 at phi = 0.65, about
#: 1e-4 at 0.89-0.90; Mol. Phys. 104, 3435 (2006), Table 1)
KOLAFA_ROTTNER_ERROR = ((0.65, 1e-5), (math.inf, 1e-4))


def reference_margin(reference: str, packing: float) -> float:
    """The relative margin of ``Z`` against ``reference`` at ``packing``: `EOS_MARGIN`
    (0.1 %), plus Kolafa & Rottner's own accuracy against theirs.

    >>> reference_margin("virial", 0.3), reference_margin("kolafa_rottner", 0.68)
    (0.001, 0.0011)
    """
    if reference == "virial":
        return EOS_MARGIN
    if reference == "kolafa_rottner":
        return EOS_MARGIN + next(e for top, e in KOLAFA_ROTTNER_ERROR if packing <= top)
    raise ValueError(f"reference must be 'virial' or 'kolafa_rottner', got {reference!r}")


def coverage(states: int) -> float:
    """The coverage of an interval of `SE_MULTIPLE` standard errors over ``states``
    independent states (Student's t with ``states - 1`` degrees of freedom): 98.0 % at 8.

    >>> round(coverage(8), 3)
    0.98
    """
    return float(2.0 * student.cdf(SE_MULTIPLE, states - 1) - 1.0)


def states_to_resolve(estimate, se, states, margin):
    """The states at which the interval ``estimate +- SE_MULTIPLE se`` (the standard error
    falling as ``1 / sqrt(states)``) would fit inside ``1 +- margin``, were the estimate to
    stay where it is: ``states (SE_MULTIPLE se / (margin - |estimate - 1|))^2``, at least
    ``states``; NaN where the estimate itself lies at or beyond the margin (no number of
    states resolves it).

    >>> states_to_resolve(1.0005, 0.0002, 8, 0.001)
    12
    >>> states_to_resolve(1.002, 0.0002, 8, 0.001)
    nan
    """
    room = margin - abs(estimate - 1.0)
    if not room > 0.0:
        return math.nan
    return max(int(states), int(math.ceil(states * (SE_MULTIPLE * se / room) ** 2)))


def pooled(frame: pd.DataFrame) -> pd.DataFrame:
    """Per N: the inverse-variance mean of ``ratio`` over the packings, its standard error
    and its interval of `SE_MULTIPLE` of them (the packings are independent runs)."""
    rows = []
    for n, g in frame.groupby("n"):
        w = 1.0 / g["se"].to_numpy() ** 2
        m = float(np.sum(w * g["ratio"].to_numpy()) / np.sum(w))
        se = float(1.0 / math.sqrt(np.sum(w)))
        rows.append({"n": int(n), "ratio": m, "se": se, "ratio_low": m - SE_MULTIPLE * se,
                     "ratio_high": m + SE_MULTIPLE * se, "packings": len(g)})
    return pd.DataFrame(rows)


def contact_speed_prediction(n):
    """The frequency ratio's prediction at ``n`` disks: :math:`\\sqrt{(N-1)/N}`. kT is E/N,
    while the box's zero total momentum leaves 2N - 2 degrees of freedom: Maxwellian at
    E/(N - 1), the mean normal speed at contact is :math:`\\sqrt{\\pi E/(N-1)}`.

    >>> round(float(contact_speed_prediction(1000)), 6)
    0.9995
    """
    n = np.asarray(n, dtype=float)
    return np.sqrt((n - 1.0) / n)


def pooled_table(freq: pd.DataFrame, size: pd.DataFrame) -> pd.DataFrame:
    """The pooled frequency ratio per N (`pooled`) and the pooled Z(N) / Z(primary), each
    beside its prediction: ``prediction_low .. prediction_high`` (the frequency's
    `contact_speed_prediction`; Z's range of `finite_size`'s ``dof_prediction`` over the
    packings)."""
    f = pooled(freq).assign(what="frequency / Enskog(measured Z)")
    f["prediction_low"] = f["prediction_high"] = contact_speed_prediction(f["n"])
    s = pooled(size).assign(what="Z(N) / Z(primary)")
    pred = size.groupby("n")["dof_prediction"].agg(["min", "max"])
    s["prediction_low"] = pred.loc[s["n"], "min"].to_numpy()
    s["prediction_high"] = pred.loc[s["n"], "max"].to_numpy()
    return pd.concat([f, s], ignore_index=True)[
        ["what", "n", "ratio", "se", "ratio_low", "ratio_high", "packings", "prediction_low",
         "prediction_high"]]


def _per_state(runs: pd.DataFrame, column: str) -> pd.DataFrame:
    return runs.groupby(["packing", "n", "state"], as_index=False)[column].mean()


def _mean_se(frame: pd.DataFrame, column: str) -> pd.DataFrame:
    g = frame.groupby(["packing", "n"])[column]
    out = g.agg(["mean", "std", "count"]).reset_index()
    out["se"] = out["std"] / np.sqrt(out["count"])
    out["coverage"] = [coverage(int(k)) for k in out["count"]]
    return out.drop(columns="std").rename(columns={"count": "states"})


def eos_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per (packing, N): the measured ``z`` with its 3-SE interval, the references (the
    virial series to B10 up to `VIRIAL_RANGE`, Kolafa-Rottner, Henderson's approximation),
    the measured / reference ratio with its interval, margin and verdict (the virial series
    where it applies, else Kolafa-Rottner: ``reference``), and against Kolafa-Rottner
    always."""
    t = _mean_se(_per_state(runs, "z"), "z").rename(columns={"mean": "z"})
    half = SE_MULTIPLE * t["se"]
    t["z_low"], t["z_high"] = t["z"] - half, t["z"] + half
    t["virial_b10"] = [virial_z(p) if p <= VIRIAL_RANGE else np.nan for p in t["packing"]]
    t["kolafa_rottner"] = kolafa_rottner_z(t["packing"].to_numpy())
    t["henderson"] = henderson_z(t["packing"].to_numpy())
    t["reference"] = np.where(t["packing"] <= VIRIAL_RANGE, "virial", "kolafa_rottner")
    ref = np.where(t["reference"] == "virial", t["virial_b10"], t["kolafa_rottner"])
    t["ratio"], t["ratio_low"], t["ratio_high"] = t["z"] / ref, t["z_low"] / ref, \
        t["z_high"] / ref
    t["margin"] = [reference_margin(r, p) for r, p in zip(t["reference"], t["packing"],
                                                           strict=True)]
    t["verdict"] = [ratio_verdict(lo, hi, tolerance=m) for lo, hi, m in
                    zip(t["ratio_low"], t["ratio_high"], t["margin"], strict=True)]
    kr = t["kolafa_rottner"]
    t["ratio_kr"], t["ratio_kr_low"], t["ratio_kr_high"] = t["z"] / kr, t["z_low"] / kr, \
        t["z_high"] / kr
    t["margin_kr"] = [reference_margin("kolafa_rottner", p) for p in t["packing"]]
    t["verdict_kr"] = [ratio_verdict(lo, hi, tolerance=m) for lo, hi, m in
                       zip(t["ratio_kr_low"], t["ratio_kr_high"], t["margin_kr"], strict=True)]
    t["henderson_over_kr"] = t["henderson"] / kr
    return t


def frequency_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per (packing, N): the collision frequency over Enskog's with the contact value of
    the same run's ``z`` (`stats.contact_from_z`), its 3-SE interval and verdict at
    `EOS_MARGIN`. The frequency cancels: the ratio is :math:`\\sqrt{\\pi kT} /
    \\langle|w\\cdot n|\\rangle_{coll}`, the Maxwellian mean normal speed at contact over
    the measured one (kT = E/N), so it checks the velocities at contact, not the count
    (``dof_prediction``: :math:`\\sqrt{(N-1)/N}`, the zero total momentum's share)."""
    runs = runs.assign(ratio=runs["frequency"] / runs["enskog"])
    t = _mean_se(_per_state(runs, "ratio"), "ratio").rename(columns={"mean": "ratio"})
    half = SE_MULTIPLE * t["se"]
    t["ratio_low"], t["ratio_high"] = t["ratio"] - half, t["ratio"] + half
    t["margin"] = EOS_MARGIN
    t["verdict"] = [ratio_verdict(lo, hi, tolerance=EOS_MARGIN)
                    for lo, hi in zip(t["ratio_low"], t["ratio_high"], strict=True)]
    t["dof_prediction"] = contact_speed_prediction(t["n"])
    return t


def finite_size(runs: pd.DataFrame, primary: int) -> pd.DataFrame:
    """Per packing and each N other than ``primary``: Z(N) / Z(primary) with its 3-SE
    interval (independent states: the relative errors in quadrature), its verdict at
    `EOS_MARGIN`, the states per N that would resolve the margin at this estimate
    (`states_to_resolve`), and ``dof_prediction``: the ratio if the collisional part
    followed the temperature of the 2N - 2 degrees of freedom, E/(N - 1), while Z divides
    by E/N."""
    t = _mean_se(_per_state(runs, "z"), "z")
    base = t[t["n"] == primary].set_index("packing")
    rows = []
    for _, row in t[t["n"] != primary].iterrows():
        b = base.loc[row["packing"]]
        ratio = row["mean"] / b["mean"]
        se = ratio * math.hypot(row["se"] / row["mean"], b["se"] / b["mean"])
        lo, hi = ratio - SE_MULTIPLE * se, ratio + SE_MULTIPLE * se
        states = int(row["states"])
        z_inf = float(kolafa_rottner_z(row["packing"]))
        n = int(row["n"])
        rows.append({"packing": row["packing"], "n": n, "primary": primary,
                     "ratio": ratio, "se": se, "ratio_low": lo, "ratio_high": hi,
                     "margin": EOS_MARGIN,
                     "verdict": ratio_verdict(lo, hi, tolerance=EOS_MARGIN),
                     "dof_prediction": _dof_z(z_inf, n) / _dof_z(z_inf, primary),
                     "states": states,
                     "states_to_resolve": states_to_resolve(ratio, se, states, EOS_MARGIN)})
    return pd.DataFrame(rows)


def _dof_z(z_inf: float, n: int) -> float:
    """Z with kT = E/N of a box of ``n`` disks whose collisional part is the limit's at the
    temperature of its 2N - 2 degrees of freedom, E/(N - 1)."""
    return 1.0 + (z_inf - 1.0) * n / (n - 1.0)


def halves_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per (packing, N): the second half's Z over the first's, paired by state, with its
    3-SE interval and verdict at `EOS_MARGIN`: the equilibration left after the discarded
    collisions."""
    wide = runs.pivot_table(index=["packing", "n", "state"], columns="half", values="z")
    per = (wide[2] / wide[1]).rename("ratio").reset_index()
    t = _mean_se(per, "ratio").rename(columns={"mean": "ratio"})
    half = SE_MULTIPLE * t["se"]
    t["ratio_low"], t["ratio_high"] = t["ratio"] - half, t["ratio"] + half
    t["margin"] = EOS_MARGIN
    t["verdict"] = [ratio_verdict(lo, hi, tolerance=EOS_MARGIN)
                    for lo, hi in zip(t["ratio_low"], t["ratio_high"], strict=True)]
    t["states_to_resolve"] = [states_to_resolve(r, se, int(k), EOS_MARGIN) for r, se, k in
                              zip(t["ratio"], t["se"], t["states"], strict=True)]
    return t
