r"""The small-r study's tables: the sweep per IC, the theory, their comparison, the ratios.

* `per_ic` -- one row per (rule, radius, IC, system) of the sweep: the FTLE, the
  perturbations and the duration;
* `measured` -- the stretching per perturbation :math:`s = \bar\lambda/\hat\Gamma` per
  (rule, system, radius) with bootstrap intervals over ICs, and the kicked / two-disk
  ratio of the FTLE (paired: the same resampled ICs);
* `theory_table` -- `kicktimes.diagnostics.low_density.stretching_theory` at every
  (rule, system, radius);
* `against_theory` -- measured / predicted per cell, read against the ±5 % margin
  (`kicktimes.stats.margin_of("ftle")`) by `kicktimes.stats.ratio_verdict`;
* `ratio_table` -- the kicked / two-disk FTLE ratio, measured beside the theory's ratio
  and its limit r -> 0 (`limit_ratio`);
* `findings` -- the ratio under its controls (the other collision rule, the paired median
  of the per-IC ratios, the sticky runs left out) with the verdict at the ±10 % band
  (``verdict``, as every findings table), at the FTLE's margin (``verdict_at_margin``) and
  the robustness over the controls.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.diagnostics.low_density import (
    SLOPES,
    THEORY_SYSTEMS,
    limit_ratio,
    stretching_theory,
)
from kicktimes.stats import (
    is_sticky,
    kinetic_rate,
    margin_of,
    percentile_interval,
    ratio_verdict,
    resample_indices,
    stretching_per_perturbation,
)

__all__ = ["KICKED", "against_theory", "control_runs", "findings", "measured", "per_ic",
           "rate_check", "ratio_table", "slopes", "theory_table"]

SYSTEMS = THEORY_SYSTEMS
#: the kicked systems and their names on the page
KICKED = {"poisson": "uniform kicks", "uniform_kinetic": "uniform kicks, kinetic rate",
          "poisson_scatter": "scattering kicks",
          "poisson_kinetic": "scattering kicks, kinetic rate"}
#: the controls of every radius (the sticky runs' only where a run is sticky), then those
#: whose stores exist at one radius (`kicktimes.studies.small_r.sweep.CONTROL_STORES`)
CONTROLS = ("primary", "elastic", "paired_median", "sticky_excluded")


def per_ic(stores) -> pd.DataFrame:
    """One row per (rule, radius, IC, system): ``lam, n, t`` (FTLE, perturbations,
    duration) from the sweep's stores ``{(rule, r): Store}``."""
    parts = []
    for key, store in sorted((k, v) for k, v in stores.items() if k != "controls"):
        rule, r = key[-2:]
        res = store.results
        wide = res.pivot_table(index=["ic", "system"], columns="diagnostic",
                               values="value").reset_index()
        n = np.where(wide["system"] == "two_particle", wide.get("n_pp"), wide.get("n_kicks"))
        parts.append(pd.DataFrame({"rule": rule, "radius": float(r), "ic": wide["ic"],
                                   "system": wide["system"], "lam": wide["lyapunov"],
                                   "n": n.astype(float), "t": wide["t_max"]}))
    return pd.concat(parts, ignore_index=True)


def _arrays(block):
    """``{system: (lam, n, t)}`` arrays over the same ICs (rows sorted by IC)."""
    out = {}
    for system in SYSTEMS:
        part = block[block["system"] == system].sort_values("ic")
        out[system] = tuple(part[c].to_numpy(float) for c in ("lam", "n", "t"))
    return out


def measured(runs, *, n_boot=1000, seed=0) -> pd.DataFrame:
    r"""Per (rule, system, radius): the stretching per perturbation with its 95 % bootstrap
    interval over ICs and, for a kicked system, the kicked / two-disk ratio with its
    paired interval (the same resampled ICs for every system).

    ``runs`` is the `per_ic` table. Columns: ``rule, system, radius, ln_inv_r, n_ics,
    perturbations_per_ic, stretch, ci_low, ci_high, ratio, ratio_ci_low, ratio_ci_high``.
    """
    rows = []
    for (rule, r), block in runs.groupby(["rule", "radius"], sort=True):
        arr = _arrays(block)
        n_ics = len(arr["two_particle"][0])
        picks = resample_indices(n_ics, n_boot=n_boot, rng=np.random.default_rng(seed),
                                 with_identity=True)
        boot = {s: stretching_per_perturbation(*(a[picks] for a in arr[s])) for s in SYSTEMS}
        for system in SYSTEMS:
            row = {"rule": rule, "system": system, "radius": r, "ln_inv_r": np.log(1 / r),
                   "n_ics": n_ics, "perturbations_per_ic": float(np.nanmean(arr[system][1])),
                   "stretch": boot[system][0]}
            row["ci_low"], row["ci_high"] = percentile_interval(boot[system][1:])
            if system != "two_particle":
                ratio = boot[system] / boot["two_particle"]
                row["ratio"] = ratio[0]
                row["ratio_ci_low"], row["ratio_ci_high"] = percentile_interval(ratio[1:])
            rows.append(row)
    return pd.DataFrame(rows)


def slopes(runs, *, max_radius=1e-3, n_boot=1000, seed=0) -> pd.DataFrame:
    r"""The measured slope b of :math:`\lambda/\Gamma` against ln(1/r) per (rule, system),
    by least squares over the radii ``<= max_radius``, with a percentile-bootstrap interval
    (ICs resampled within each radius), beside the theory's b."""
    rows = []
    rng = np.random.default_rng(seed)
    for rule in sorted(runs["rule"].unique()):
        part = runs[(runs["rule"] == rule) & (runs["radius"] <= max_radius)]
        radii = np.sort(part["radius"].unique())
        x = np.log(1 / radii)
        boot = {s: [] for s in SYSTEMS}
        for r in radii:
            arr = _arrays(part[part["radius"] == r])
            picks = resample_indices(len(arr["two_particle"][0]), n_boot=n_boot, rng=rng,
                                     with_identity=True)
            for system in SYSTEMS:
                boot[system].append(stretching_per_perturbation(
                    *(a[picks] for a in arr[system])))
        design = np.vstack([np.ones_like(x), x]).T
        for system in SYSTEMS:
            y = np.array(boot[system])                  # (radii, 1 + n_boot)
            b = np.linalg.lstsq(design, y, rcond=None)[0][1]
            lo, hi = percentile_interval(b[1:])
            rows.append({"rule": rule, "system": system, "r_min": radii.min(),
                         "r_max": radii.max(), "slope": b[0], "ci_low": lo, "ci_high": hi,
                         "theory_slope": SLOPES[system]})
    return pd.DataFrame(rows)


def rate_check(runs, *, n_boot=1000, seed=0) -> pd.DataFrame:
    r"""Per (rule, radius): the two-disk collisions over :math:`\Gamma(r) T` (the
    invariant measure's exact expectation: 1 for invariant ICs), mean over ICs with its
    percentile-bootstrap interval, and the spread of the per-IC values."""
    rows = []
    for (rule, r), block in runs[runs["system"] == "two_particle"].groupby(["rule", "radius"]):
        x = (block["n"] / (kinetic_rate(r, rule=rule) * block["t"])).to_numpy(float)
        picks = resample_indices(len(x), n_boot=n_boot, rng=np.random.default_rng(seed),
                                 with_identity=True)
        boot = x[picks].mean(axis=-1)
        lo, hi = percentile_interval(boot[1:])
        rows.append({"rule": rule, "radius": r, "n_ics": len(x),
                     "count_over_kinetic": boot[0], "ci_low": lo, "ci_high": hi,
                     "per_ic_min": x.min(), "per_ic_max": x.max()})
    return pd.DataFrame(rows)


def theory_table(radii, rules, *, chains, rng=0) -> pd.DataFrame:
    """`stretching_theory` at every (rule, system, radius); ``chains`` maps a rule to
    ``(n_chains, n_steps, burn_in)``. Columns: ``rule, system, radius, stretch, se,
    ci_low, ci_high, slope, intercept, rate_over_kinetic, log_time, log_geometry,
    n_chains, n_steps``."""
    cells = [(u, s, r) for u in rules for s in SYSTEMS for r in sorted(radii)]
    seeds = np.random.SeedSequence(rng).spawn(len(cells))
    rows = []
    for (rule, system, r), seed in zip(cells, seeds, strict=True):
        n_chains, n_steps, burn_in = chains[rule]
        th = stretching_theory(r, system, rule=rule, n_chains=n_chains, n_steps=n_steps,
                               burn_in=burn_in, rng=np.random.default_rng(seed))
        rows.append({"rule": rule, "system": system, "radius": r, "stretch": th.stretch,
                     "se": th.se, "ci_low": th.ci_low, "ci_high": th.ci_high,
                     "slope": th.slope, "intercept": th.intercept,
                     "rate_over_kinetic": th.rate / kinetic_rate(r, rule=rule),
                     "log_time": th.log_time, "log_geometry": th.log_geometry,
                     "n_chains": th.n_chains, "n_steps": th.n_steps})
    return pd.DataFrame(rows)


Z95 = 1.959963984540054


def _log_se(low, high):
    return np.log(high / low) / (2 * Z95)


def against_theory(meas, theory) -> pd.DataFrame:
    """Measured over predicted stretching per (rule, system, radius), its interval (the
    measured bootstrap interval and the theory's Monte Carlo error combined in quadrature
    on the log scale) and its `ratio_verdict` at the FTLE's margin."""
    both = meas.merge(theory, on=["rule", "system", "radius"], suffixes=("", "_theory"))
    q = both["stretch"] / both["stretch_theory"]
    s = np.hypot(_log_se(both["ci_low"], both["ci_high"]),
                 both["se"] / both["stretch_theory"])
    tol = margin_of("ftle")
    out = pd.DataFrame({
        "rule": both["rule"], "system": both["system"], "radius": both["radius"],
        "measured": both["stretch"], "measured_ci_low": both["ci_low"],
        "measured_ci_high": both["ci_high"], "predicted": both["stretch_theory"],
        "predicted_se": both["se"], "measured_over_predicted": q,
        "ci_low": q * np.exp(-Z95 * s), "ci_high": q * np.exp(Z95 * s)})
    out["verdict"] = [ratio_verdict(lo, hi, tolerance=tol)
                      for lo, hi in zip(out["ci_low"], out["ci_high"], strict=True)]
    # the same comparison in nats: measured - predicted, the measured interval shifted and
    # widened by the theory's Monte Carlo error in quadrature
    half = np.hypot((both["ci_high"] - both["ci_low"]) / 2, Z95 * both["se"])
    centre = (both["ci_high"] + both["ci_low"]) / 2 - both["stretch_theory"]
    out["difference"] = both["stretch"] - both["stretch_theory"]
    out["difference_ci_low"] = centre - half
    out["difference_ci_high"] = centre + half
    return out


def ratio_table(meas, theory) -> pd.DataFrame:
    """Per (rule, kicked system, radius): the measured kicked / two-disk FTLE ratio with
    its paired interval and verdict against 1 at the FTLE's margin, the theory's ratio
    with its Monte Carlo interval, the measured / predicted quotient of the ratios with
    its verdict, and the limit r -> 0."""
    th = theory.set_index(["rule", "system", "radius"])
    tol = margin_of("ftle")
    rows = []
    for _, m in meas[meas["system"] != "two_particle"].iterrows():
        k = th.loc[(m["rule"], m["system"], m["radius"])]
        two = th.loc[(m["rule"], "two_particle", m["radius"])]
        pred = k["stretch"] / two["stretch"]
        pred_se = pred * np.hypot(k["se"] / k["stretch"], two["se"] / two["stretch"])
        s = np.hypot(_log_se(m["ratio_ci_low"], m["ratio_ci_high"]), pred_se / pred)
        q = m["ratio"] / pred
        lo, hi = q * np.exp(-Z95 * s), q * np.exp(Z95 * s)
        rows.append({"rule": m["rule"], "system": m["system"], "radius": m["radius"],
                     "ratio": m["ratio"], "ratio_ci_low": m["ratio_ci_low"],
                     "ratio_ci_high": m["ratio_ci_high"],
                     "ratio_verdict": ratio_verdict(m["ratio_ci_low"], m["ratio_ci_high"],
                                                    tolerance=tol),
                     "predicted_ratio": pred, "predicted_ci_low": pred - 1.96 * pred_se,
                     "predicted_ci_high": pred + 1.96 * pred_se,
                     "measured_over_predicted": q, "quotient_ci_low": lo,
                     "quotient_ci_high": hi,
                     "quotient_verdict": ratio_verdict(lo, hi, tolerance=tol),
                     "limit": limit_ratio(m["system"])})
    return pd.DataFrame(rows)


def _control_ratio(block, system, control, *, n_boot, seed):
    """The kicked / two-disk FTLE ratio of one (rule, radius) block under ``control``:
    the ratio of the stretching per perturbation, or (``paired_median``) the median over
    ICs of the per-IC ratio of the FTLE over its own rate; ``sticky_excluded`` leaves out
    the ICs whose two-disk rate exceeds `kicktimes.stats.STICKY_FACTOR` Γ(r)."""
    arr = _arrays(block)
    lam2, n2, t2 = arr["two_particle"]
    lam, n, t = arr[system]
    keep = np.ones(len(lam2), bool)
    if control == "sticky_excluded":
        keep = ~np.asarray(is_sticky(n2 / t2, kinetic_rate(block["radius"].iloc[0],
                                                           rule=block["rule"].iloc[0])))
    idx = np.flatnonzero(keep)
    picks = idx[resample_indices(len(idx), n_boot=n_boot, rng=np.random.default_rng(seed),
                                 with_identity=True)]
    if control == "paired_median":
        per = (lam / (n / t)) / (lam2 / (n2 / t2))
        boot = np.nanmedian(per[picks], axis=-1)
    else:
        boot = (stretching_per_perturbation(lam[picks], n[picks], t[picks])
                / stretching_per_perturbation(lam2[picks], n2[picks], t2[picks]))
    lo, hi = percentile_interval(boot[1:])
    return boot[0], lo, hi, len(idx)


def findings(runs, control_runs=None, *, primary_rule="mirror", n_boot=1000,
             seed=0) -> pd.DataFrame:
    """The kicked / two-disk FTLE ratio per (radius, kicked system) under each control,
    in the layout of kicktimes' findings tables (``family, question, diagnostic, system,
    control, estimate, ci_low, ci_high, verdict, margin, verdict_at_margin, robust``, and
    ``radius, n_ics``). The controls: the other collision rule, the paired median, the
    sticky runs left out (a row only where some run is sticky), and at the radius of the
    control stores (``control_runs``, a `per_ic` table with a ``control`` column) another
    seed, the paper's ICs and a ten times shorter horizon. ``robust``: every control's
    ``verdict_at_margin`` is the primary's, in the same direction (every interval on the
    same side of 1, or all within the margin)."""
    other = "elastic" if primary_rule == "mirror" else "mirror"
    tol = margin_of("ftle")
    extra = {} if control_runs is None else {
        c: g.drop(columns="control") for c, g in control_runs.groupby("control")}
    rows = []

    def add(r, system, control, block, how="primary"):
        est, lo, hi, n = _control_ratio(block, system, how, n_boot=n_boot, seed=seed)
        rows.append({"family": f"small_r-r{r:g}", "question": "FTLE",
                     "diagnostic": "ftle", "system": system, "control": control,
                     "radius": r, "n_ics": n, "estimate": est, "ci_low": lo, "ci_high": hi,
                     "verdict": ratio_verdict(lo, hi), "margin": tol,
                     "verdict_at_margin": ratio_verdict(lo, hi, tolerance=tol)})

    for r in sorted(runs["radius"].unique()):
        mine = runs[(runs["rule"] == primary_rule) & (runs["radius"] == r)]
        theirs = runs[(runs["rule"] == other) & (runs["radius"] == r)]
        two = mine[mine["system"] == "two_particle"]
        sticky = np.asarray(is_sticky(two["n"] / two["t"], kinetic_rate(r, rule=primary_rule)))
        for system in KICKED:
            add(r, system, "primary", mine)
            if not theirs.empty:
                add(r, system, "elastic" if other == "elastic" else "mirror", theirs)
            add(r, system, "paired_median", mine, "paired_median")
            if sticky.any():
                add(r, system, "sticky_excluded", mine, "sticky_excluded")
            for control, block in extra.items():
                part = block[(block["rule"] == primary_rule) & (block["radius"] == r)]
                if not part.empty:
                    add(r, system, control, part)
    table = pd.DataFrame(rows)
    robust = {}
    for key, g in table.groupby(["family", "system"]):
        same = g["verdict_at_margin"].nunique() == 1
        sides = {int(np.sign(lo - 1)) if lo > 1 or hi < 1 else 0
                 for lo, hi in zip(g["ci_low"], g["ci_high"], strict=True)}
        robust[key] = bool(same and len(sides) == 1)
    table["robust"] = [robust[k] for k in zip(table["family"], table["system"], strict=True)]
    return table


def control_runs(stores) -> pd.DataFrame:
    """The `per_ic` table of the control stores ``{(control, rule, r): Store}``, with a
    ``control`` column."""
    parts = [per_ic({key[1:]: store}).assign(control=key[0]) for key, store in stores.items()]
    return pd.concat(parts, ignore_index=True) if parts else None
