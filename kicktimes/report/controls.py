r"""Every comparison finding under its controls, and whether its verdict survives them.

A ratio "kicked system / two-disk system" is a finding only if its verdict is the same
under every control that applies to it; otherwise it *depends on* the control that
changes it. The controls:

``primary``
    The report's setting: per radius the ratio of ensemble means
    :math:`\rho_r = \sum_i x_{ri} / \sum_i y_{ri}`, averaged over radii
    (:func:`kicktimes.report.effects.paired_ratio`).
``paired_median``
    A robust paired statistic: per radius the median over ICs of the per-IC ratio
    :math:`x_{ri} / y_{ri}`, averaged over radii. A few runs with extreme values (sticky
    orbits) cannot move it.
``sticky_excluded``
    The primary ratio without the sticky runs: a (radius, IC) pair is left out when its
    two-disk run collides faster than :data:`~kicktimes.report.counts.STICKY_FACTOR`
    times the kinetic rate :math:`\Gamma(r)` (regular orbits in which the disks bounce
    almost radially and meet near the centre).
``uniform_sampling``
    Recurrence diagnostics only: the same trajectories sampled at uniform times
    :math:`k\tau` (the store's ``uniform_`` rows, ``rr_sampling = "run+uniform"``) instead
    of the paper's collision-truncated steps, whose samples sit on the rim at every wall
    hit and differ in number between the systems.

Every interval is a percentile bootstrap clustered on ICs: one resample draws IC indices
with replacement and applies them at every radius and to every system (the same IC is
the same initial condition everywhere), so the correlation of one IC across radii and
systems is kept. Verdicts use one band (:func:`kicktimes.stats.ratio_verdict`): *within 10 %*
when the whole 95 % interval lies in [0.9, 1.1], *differs* when it lies entirely outside,
*inconclusive* otherwise.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from kicktimes.report._common import REFERENCE, kicked_systems, wide
from kicktimes.report.effects import paired_ratio
from kicktimes.stats import ratio_rule, ratio_verdict

__all__ = [
    "COLUMNS",
    "CONTROLS",
    "controls_table",
    "diagnostics_of",
    "paired_median",
]

#: the controls, in the order of the table
CONTROLS = ("primary", "paired_median", "sticky_excluded", "uniform_sampling")
#: the columns of the findings table
COLUMNS = ("family", "question", "diagnostic", "system", "control", "estimate", "ci_low",
           "ci_high", "verdict", "robust", "n_pairs", "detail")
WITHIN = "within 10 %"
DIFFERS = "differs"
INCONCLUSIVE = "inconclusive"
#: how an interval becomes a verdict
_QUESTIONS = {
    "ftle": "FTLE",
    "rr_offdiag": "off-diagonal recurrence rate",
    "det": "determinism (DET)",
    "one_minus_r1": "decorrelation 1 − R₁ of boundary angles",
    "counts": "collision counts / kinetic theory Γ(r)T",
}


def paired_median(numerator, denominator, *, rng, n_boot=1000, level=0.95):
    r"""Median over ICs of the per-IC ratio, per radius, averaged over radii, with a CI.

    Parameters
    ----------
    numerator, denominator : pandas.Series
        Indexed by ``(radius, ic)``; a pair enters where both are finite and the
        denominator is non-zero.
    rng : numpy.random.Generator
        The bootstrap's stream.
    n_boot : int
        Resamples of the IC indices (one resample is applied at every radius).
    level : float
        Confidence level of the percentile interval.

    Returns
    -------
    dict
        ``ratio, ci_low, ci_high, n_pairs, per_radius`` (a Series of per-radius medians).

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> idx = pd.MultiIndex.from_product([[0.01, 0.02], range(9)], names=["radius", "ic"])
    >>> y = pd.Series(np.arange(1.0, 19.0), index=idx)
    >>> x = 0.5 * y
    >>> x.iloc[0] = 1e6  # one extreme run does not move a median
    >>> paired_median(x, y, rng=np.random.default_rng(0))["ratio"]
    0.5
    """
    frame = pd.concat({"x": numerator, "y": denominator}, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = (frame["x"] / frame["y"]).where(lambda s: np.isfinite(s))
    table = q.unstack("ic")  # radius x ic
    values = table.to_numpy(float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a radius without a finite pair
        per_radius = pd.Series(np.nanmedian(values, axis=1), index=table.index, dtype=float)
    usable = np.isfinite(per_radius.to_numpy())
    n_pairs = int(np.isfinite(values).sum())
    if not usable.any():
        return {"ratio": math.nan, "ci_low": math.nan, "ci_high": math.nan, "n_pairs": n_pairs,
                "per_radius": per_radius}
    values = values[usable]
    n = values.shape[1]
    boot = np.empty(n_boot)
    idx = rng.integers(0, n, size=(n_boot, n))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a resample without a finite pair
        for b in range(n_boot):
            boot[b] = np.nanmean(np.nanmedian(values[:, idx[b]], axis=1))
    boot = boot[np.isfinite(boot)]
    a = (1 - level) / 2 * 100
    return {
        "ratio": float(per_radius[usable].mean()),
        "ci_low": float(np.percentile(boot, a)) if boot.size else math.nan,
        "ci_high": float(np.percentile(boot, 100 - a)) if boot.size else math.nan,
        "n_pairs": n_pairs,
        "per_radius": per_radius,
    }


def diagnostics_of(results, eps):
    """The comparison diagnostics a store has: ``(name, store row, uniform row or None)``.

    ``name`` is the table's ``diagnostic`` (``ftle``, ``rr_offdiag@0.001``, ``det@0.01``,
    ``one_minus_r1``); the store rows hold the per-IC values.
    """
    have = set(results["diagnostic"].unique())
    out = []
    if "lyapunov" in have:
        out.append(("ftle", "lyapunov", None))
    for e in eps:
        tag = f"{e:g}"
        for name in ("rr_offdiag", "det"):
            row = f"{name}@{tag}"
            if row in have:
                uniform = f"uniform_{row}"
                out.append((row, row, uniform if uniform in have else None))
    if "autocorrelation" in have:
        out.append(("one_minus_r1", "autocorrelation", None))
    return out


def _per_ic(results, row, transform=None):
    table = wide(results, row)
    return table if transform is None else transform(table)


def _row(family, diagnostic, system, control, est, low, high, n_pairs, detail):
    return {
        "family": family,
        "question": _QUESTIONS[diagnostic.split("@")[0]],
        "diagnostic": diagnostic,
        "system": system,
        "control": control,
        "estimate": est,
        "ci_low": low,
        "ci_high": high,
        "verdict": ratio_verdict(low, high),
        "robust": False,
        "n_pairs": int(n_pairs),
        "detail": detail,
    }


def _ratio_rows(family, diagnostic, system, x, y, sticky, *, x_uniform, y_uniform, rng,
                n_boot, resamples):
    """The rows of one (diagnostic, system): every control that applies."""
    rows = []
    per_r, tot = paired_ratio(x, y, rng=rng, n_boot=n_boot, resamples=resamples)
    rows.append(_row(family, diagnostic, system, "primary", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     "ratio of means per radius, averaged over radii; per radius "
                     + ", ".join(f"{r:g}: {v:.3g}" for r, v in zip(per_r["radius"],
                                                                   per_r["ratio"], strict=True))))
    med = paired_median(x, y, rng=rng, n_boot=max(200, n_boot // 2))
    rows.append(_row(family, diagnostic, system, "paired_median", med["ratio"], med["ci_low"],
                     med["ci_high"], med["n_pairs"],
                     "median of per-IC ratios per radius, averaged over radii"))
    keep = ~sticky.reindex(x.index, fill_value=False).to_numpy(bool)
    n_out = int((~keep).sum())
    per_r, tot = paired_ratio(x[keep], y[keep], rng=rng, n_boot=n_boot, resamples=None)
    rows.append(_row(family, diagnostic, system, "sticky_excluded", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     f"{n_out} sticky (radius, IC) runs left out"))
    if x_uniform is not None:
        per_r, tot = paired_ratio(x_uniform, y_uniform, rng=rng, n_boot=n_boot,
                                  resamples=resamples)
        rows.append(_row(family, diagnostic, system, "uniform_sampling", tot["ratio"],
                         tot["ci_low"], tot["ci_high"], per_r["n_pairs"].sum(),
                         "samples at uniform times k τ of the same trajectories"))
    return rows


def controls_table(results, collisions, *, family, eps, rule="mirror", rng, n_boot=2000,
                   resamples=None) -> pd.DataFrame:
    """The findings table: every comparison diagnostic of every kicked system under every
    control, with the verdict and whether it is robust.

    Parameters
    ----------
    results, collisions : pandas.DataFrame
        A store's tidy tables (`kicktimes.experiment.load_store`).
    family : str
        The experiment's name (the ``family`` column).
    eps : sequence of float
        The experiment's recurrence thresholds.
    rule : {"mirror", "elastic"}
        The collision rule (for the kinetic rate that defines sticky runs).
    rng : numpy.random.Generator
        The bootstrap stream (the report seeds it: the table is deterministic).
    n_boot : int
        Bootstrap resamples of the ICs.
    resamples : dict, optional
        Shared bootstrap draws (`paired_ratio`).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`COLUMNS`. ``robust`` is True on every row of a (family,
        diagnostic, system) exactly when all its controls give the same verdict.
    """
    from kicktimes.report.counts import sticky_ics

    sticky = sticky_ics(collisions, rule).set_index(["radius", "ic"])["sticky"]
    rows = []
    systems = kicked_systems(results)
    for diagnostic, row, uniform in diagnostics_of(results, eps):
        transform = (lambda t: 1.0 - t) if diagnostic == "one_minus_r1" else None
        table = _per_ic(results, row, transform)
        table_u = _per_ic(results, uniform) if uniform else None
        if REFERENCE not in table.columns:
            continue
        for system in systems:
            if system not in table.columns:
                continue
            rows += _ratio_rows(
                family, diagnostic, system, table[system], table[REFERENCE], sticky,
                x_uniform=None if table_u is None else table_u[system],
                y_uniform=None if table_u is None else table_u[REFERENCE],
                rng=rng, n_boot=n_boot, resamples=resamples,
            )
    rows += _count_rows(family, collisions, sticky, rule, rng=rng, n_boot=n_boot,
                        resamples=resamples)
    out = pd.DataFrame(rows, columns=list(COLUMNS))
    if out.empty:
        return out
    same = out.groupby(["family", "diagnostic", "system"])["verdict"].transform("nunique") == 1
    out["robust"] = same.to_numpy(bool)
    return out


def _count_rows(family, collisions, sticky, rule, *, rng, n_boot, resamples):
    """Observed disk-disk collisions over the kinetic count Γ(r) T, under the controls."""
    from kicktimes.stats import kinetic_rate

    coll = collisions.set_index(["radius", "ic"])
    gamma = np.array([kinetic_rate(float(r), rule=rule) for r in
                      coll.index.get_level_values("radius")])
    observed = coll["n_pp"].astype(float)
    expected = pd.Series(gamma * coll["t_window"].to_numpy(float), index=coll.index)
    rows = []
    per_r, tot = paired_ratio(observed, expected, rng=rng, n_boot=n_boot, resamples=resamples)
    rows.append(_row(family, "counts", REFERENCE, "primary", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     "ΣN / Σ Γ(r)T per radius, averaged over radii; paper ICs, not the "
                     "invariant measure, so the ratio need not be 1"))
    med = paired_median(observed, expected, rng=rng, n_boot=max(200, n_boot // 2))
    rows.append(_row(family, "counts", REFERENCE, "paired_median", med["ratio"], med["ci_low"],
                     med["ci_high"], med["n_pairs"], "median of per-IC N / Γ(r)T"))
    keep = ~sticky.reindex(observed.index, fill_value=False).to_numpy(bool)
    per_r, tot = paired_ratio(observed[keep], expected[keep], rng=rng, n_boot=n_boot)
    rows.append(_row(family, "counts", REFERENCE, "sticky_excluded", tot["ratio"], tot["ci_low"],
                     tot["ci_high"], per_r["n_pairs"].sum(),
                     f"{int((~keep).sum())} sticky runs left out"))
    return rows


#: what the paper says of each diagnostic (Ranković & Porter 2013), beside the table's rows
PAPER_CLAIMS = {
    "ftle": "“very similar” λ (Fig. 6)",
    "rr_offdiag": "“excellent agreement” of RR at small r (Fig. 7)",
    "det": "not studied",
    "one_minus_r1": "similar R₁ (Fig. 8)",
}
_SHORT = {"poisson": "Poisson", "actual": "actual", "poisson_scatter": "Poisson, scatter",
          "actual_scatter": "actual, scatter"}


def _ci(row):
    return f"{row.estimate:.2f} [{row.ci_low:.2f}, {row.ci_high:.2f}]"


def _verdict_text(rows):
    """``(text, robust)`` of one (family, diagnostic, system): the primary ratio and CI,
    with "depends on <control>" and its number where a control changes the verdict."""
    rows = rows.set_index("control")
    primary = rows.loc["primary"]
    if bool(primary.robust):
        return f"{_ci(primary)} ✓", True
    other = [c for c in rows.index if rows.loc[c, "verdict"] != primary.verdict]
    c = other[0]
    return (f"{_ci(primary)} ✗ depends on {c}: {_ci(rows.loc[c])}"), False


def overview_table(table: pd.DataFrame) -> pd.DataFrame:
    """One screen: diagnostics as rows, kicked systems as columns; each cell the primary
    ratio to the two-disk value [95 % CI] per family, ✓ when the verdict is robust to every
    control and ✗ with the control that changes it otherwise; the paper's claim beside."""
    comp = table[table["system"] != REFERENCE]
    families = list(dict.fromkeys(comp["family"]))
    systems = [s for s in _SHORT if s in set(comp["system"])]
    out = []
    for diagnostic in dict.fromkeys(comp["diagnostic"]):
        line = {"diagnostic": diagnostic}
        for system in systems:
            cells = []
            for fam in families:
                rows = comp[(comp["family"] == fam) & (comp["diagnostic"] == diagnostic)
                            & (comp["system"] == system)]
                if not rows.empty:
                    text, _ = _verdict_text(rows)
                    cells.append(f"{fam}: {text}" if len(families) > 1 else text)
            line[_SHORT[system]] = "<br>".join(cells)
        line["paper"] = PAPER_CLAIMS.get(diagnostic.split("@")[0], "")
        out.append(line)
    return pd.DataFrame(out)


def _stated(rows):
    """A robust verdict as a finding, or "depends on" with both numbers."""
    text, robust = _verdict_text(rows)
    primary = rows.set_index("control").loc["primary"]
    if robust:
        return f"{primary.verdict} ({_ci(primary)} of the two-disk value, under every control)"
    return f"{primary.verdict} under the primary setting ({text.split(' ✗ ')[0]}), but it " \
        + text.split(" ✗ ")[1]


def answers(table: pd.DataFrame, poisson_share=None) -> list[str]:
    """The three sentences that open the results: Poisson? Does the paper's kicked disk
    reproduce the two-disk chaos (FTLE)? Does any kick?

    ``poisson_share``: ``{family: (share, ci_low, ci_high, alpha)}`` of runs whose collision
    times reject uniformity (the Poisson test), or None.
    """
    out = []
    poisson_share = {k: v for k, v in (poisson_share or {}).items() if v is not None}
    if poisson_share:
        parts = [f"{fam}: {s:.0%} of runs [{lo:.0%}, {hi:.0%}] reject it at α = {a:g}"
                 for fam, (s, lo, hi, a) in poisson_share.items()]
        reject = all(lo > a for (_, lo, _, a) in poisson_share.values())
        out.append("**Are the collision times Poisson?** "
                    + ("No. " if reject else "Not rejected everywhere. ")
                    + "; ".join(parts) + " (under Poisson times the share would be α).")
    ftle = table[(table["diagnostic"] == "ftle")]
    paper = []
    for fam in dict.fromkeys(ftle["family"]):
        for system in ("poisson", "actual"):
            rows = ftle[(ftle["family"] == fam) & (ftle["system"] == system)]
            if not rows.empty:
                paper.append(f"{fam}, {_SHORT[system]} kicks: {_stated(rows)}")
    if paper:
        mine = ftle[ftle["system"].isin(["poisson", "actual"])]
        verdicts = set(mine["verdict"])
        primary = mine[mine["control"] == "primary"]["estimate"]
        lead = ("Yes" if verdicts == {WITHIN} else "No" if verdicts == {DIFFERS}
                else "Not under every control")
        out.append("**Does the paper's kicked disk reproduce the two-disk chaos?** "
                   f"{lead}: its FTLE is {primary.min():.2f}–{primary.max():.2f} of the "
                   "two-disk one. " + "; ".join(paper) + ".")
    other = []
    for fam in dict.fromkeys(ftle["family"]):
        for system in ("poisson_scatter", "actual_scatter"):
            rows = ftle[(ftle["family"] == fam) & (ftle["system"] == system)]
            if not rows.empty:
                other.append(f"{fam}, {_SHORT[system]} kicks: {_stated(rows)}")
    if other:
        out.append("**Does any kick?** The scatter kick (a collision with a virtual partner) "
                   "comes closest; FTLE ratio " + "; ".join(other) + ".")
    return out


def markdown_table(frame: pd.DataFrame) -> list[str]:
    """``frame`` as the lines of a GitHub Markdown table (cells' ``|`` escaped)."""
    def cell(v):
        return str(v).replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(cell(c) for c in frame.columns) + " |",
             "|" + "---|" * len(frame.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |"
              for row in frame.itertuples(index=False)]
    return lines


def poisson_share(effects) -> tuple | None:
    """``(share, ci_low, ci_high, alpha)`` of the Poisson-rejection finding, or None."""
    for e in effects:
        if e.question.startswith("Poisson"):
            return (e.estimate, e.ci_low, e.ci_high, 0.05)
    return None


def first_screen(table: pd.DataFrame, shares: dict) -> list[str]:
    """The Markdown lines that open a results page: the three answers, then the table."""
    lines = []
    for sentence in answers(table, {k: v for k, v in shares.items() if v is not None}):
        lines += [sentence, ""]
    lines += ["Ratio of each kicked system to the two-disk value, averaged over radii [95 % "
              "CI, bootstrap clustered on ICs]; ✓: the verdict (" + ratio_rule(0.1).split(";")[0]
              + "; differs; inconclusive) is the same under every control (paired median, "
              "sticky runs excluded, uniform-time sampling for recurrence); ✗: it is not, and "
              "the control that changes it is named with its number.", ""]
    lines += markdown_table(overview_table(table))
    return lines + [""]
