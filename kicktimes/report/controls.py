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
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kicktimes.report.common import REFERENCE, kicked_systems, wide
from kicktimes.report.effects import paired_ratio
from kicktimes.stats import bootstrap_nanmedians, nanmedian, ratio_verdict

__all__ = [
    "COLUMNS",
    "CONTROLS",
    "Controls",
    "compute_controls",
    "ratio_curves_figure",
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
        ``ratio, ci_low, ci_high, n_pairs`` and ``per_radius``, a DataFrame ``radius,
        n_pairs, ratio, ci_low, ci_high`` (per-radius medians and their intervals).

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
        per_radius = pd.Series(nanmedian(values, axis=1), index=table.index, dtype=float)
    usable = np.isfinite(per_radius.to_numpy())
    n_pairs = int(np.isfinite(values).sum())
    if not usable.any():
        curve = pd.DataFrame({"radius": table.index.to_numpy(float), "n_pairs": 0,
                              "ratio": np.nan, "ci_low": np.nan, "ci_high": np.nan})
        return {"ratio": math.nan, "ci_low": math.nan, "ci_high": math.nan, "n_pairs": n_pairs,
                "per_radius": curve}
    n = values.shape[1]
    idx = rng.integers(0, n, size=(n_boot, n))
    # boot_r[b] = nanmedian(values[:, idx[b]], axis=1), bit for bit, without a sort each
    boot_r = bootstrap_nanmedians(values, idx)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a resample without a finite pair
        boot = np.nanmean(boot_r[:, usable], axis=1)
        a = (1 - level) / 2 * 100
        low_r = np.nanpercentile(boot_r, a, axis=0)
        high_r = np.nanpercentile(boot_r, 100 - a, axis=0)
    boot = boot[np.isfinite(boot)]
    curve = pd.DataFrame({"radius": table.index.to_numpy(float),
                          "n_pairs": np.isfinite(values).sum(axis=1),
                          "ratio": per_radius.to_numpy(), "ci_low": low_r, "ci_high": high_r})
    return {
        "ratio": float(per_radius[usable].mean()),
        "ci_low": float(np.percentile(boot, a)) if boot.size else math.nan,
        "ci_high": float(np.percentile(boot, 100 - a)) if boot.size else math.nan,
        "n_pairs": n_pairs,
        "per_radius": curve,
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
                n_boot, resamples, curves):
    """The rows of one (diagnostic, system): every control that applies; the per-radius
    ratios and CIs of each go to ``curves``."""
    rows = []

    def add(control, per_r, tot, n_pairs, detail):
        rows.append(_row(family, diagnostic, system, control, tot["ratio"], tot["ci_low"],
                         tot["ci_high"], n_pairs, detail))
        curves.append(per_r.assign(family=family, diagnostic=diagnostic, system=system,
                                   control=control))

    per_r, tot = paired_ratio(x, y, rng=rng, n_boot=n_boot, resamples=resamples)
    add("primary", per_r, tot, per_r["n_pairs"].sum(),
        "ratio of means per radius, averaged over radii; per radius "
        + ", ".join(f"{r:g}: {v:.3g}" for r, v in zip(per_r["radius"], per_r["ratio"],
                                                      strict=True)))
    med = paired_median(x, y, rng=rng, n_boot=max(200, n_boot // 2))
    add("paired_median", med["per_radius"], med, med["n_pairs"],
        "median of per-IC ratios per radius, averaged over radii")
    keep = ~sticky.reindex(x.index, fill_value=False).to_numpy(bool)
    per_r, tot = paired_ratio(x[keep], y[keep], rng=rng, n_boot=n_boot, resamples=None)
    add("sticky_excluded", per_r, tot, per_r["n_pairs"].sum(),
        f"{int((~keep).sum())} sticky (radius, IC) runs left out")
    if x_uniform is not None:
        per_r, tot = paired_ratio(x_uniform, y_uniform, rng=rng, n_boot=n_boot,
                                  resamples=resamples)
        add("uniform_sampling", per_r, tot, per_r["n_pairs"].sum(),
            "samples at uniform times k τ of the same trajectories")
    return rows


@dataclass(frozen=True)
class Controls:
    """Every comparison of one store under its controls.

    Attributes
    ----------
    table : pandas.DataFrame
        The findings table, columns :data:`COLUMNS`: one row per (diagnostic, system,
        control), averaged over radii.
    curves : pandas.DataFrame
        The same per radius: ``family, diagnostic, system, control, radius, n_pairs,
        ratio, ci_low, ci_high`` (the headline figure's curves).
    """

    table: pd.DataFrame
    curves: pd.DataFrame


def compute_controls(results, collisions, *, family, eps, rule="mirror", rng, n_boot=2000,
                     resamples=None, kinetic=None) -> Controls:
    """Every comparison diagnostic of every kicked system under every control, with the
    verdict and whether it is robust, averaged over radii and per radius.

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
    kinetic : callable, optional
        The kinetic rate as a function of the radius (array in, array out), e.g.
        ``Experiment.kinetic_rate`` for unequal disks; default
        ``kicktimes.stats.kinetic_rate(r, rule)`` (equal disks).

    Returns
    -------
    Controls
        ``table`` (columns :data:`COLUMNS`; ``robust`` is True on every row of a (family,
        diagnostic, system) exactly when all its controls give the same verdict) and
        ``curves`` (per radius).
    """
    from kicktimes.report.counts import sticky_ics

    sticky = sticky_ics(collisions, rule, kinetic=kinetic).set_index(["radius", "ic"])["sticky"]
    rows, curves = [], []
    systems = kicked_systems(results)
    for diagnostic, row, uniform in diagnostics_of(results, eps):
        table = wide(results, row)
        if diagnostic == "one_minus_r1":
            table = 1.0 - table
        table_u = wide(results, uniform) if uniform else None
        if REFERENCE not in table.columns:
            continue
        for system in systems:
            if system not in table.columns:
                continue
            rows += _ratio_rows(
                family, diagnostic, system, table[system], table[REFERENCE], sticky,
                x_uniform=None if table_u is None else table_u[system],
                y_uniform=None if table_u is None else table_u[REFERENCE],
                rng=rng, n_boot=n_boot, resamples=resamples, curves=curves,
            )
    rows += _count_rows(family, collisions, sticky, rule, kinetic, rng=rng, n_boot=n_boot,
                        resamples=resamples)
    out = pd.DataFrame(rows, columns=list(COLUMNS))
    if not out.empty:
        same = out.groupby(["family", "diagnostic", "system"])["verdict"].transform(
            "nunique") == 1
        out["robust"] = same.to_numpy(bool)
    curve_cols = ["family", "diagnostic", "system", "control", "radius", "n_pairs", "ratio",
                  "ci_low", "ci_high"]
    curves = (pd.concat(curves, ignore_index=True)[curve_cols] if curves
              else pd.DataFrame(columns=curve_cols))
    return Controls(out, curves)


def _count_rows(family, collisions, sticky, rule, kinetic, *, rng, n_boot, resamples):
    """Observed disk-disk collisions over the kinetic count Γ(r) T, under the controls."""
    from kicktimes.report.counts import kinetic_rate_of

    coll = collisions.set_index(["radius", "ic"])
    gamma = np.array([kinetic_rate_of(float(r), rule, kinetic) for r in
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
_CONTROL_WORDS = {
    "paired_median": "paired median",
    "sticky_excluded": "sticky runs excluded",
    "uniform_sampling": "uniform-time samples for recurrence",
    "invariant_ics": "invariant-measure ICs",
    "elastic": "the elastic rule",
}
_SHORT = {"poisson": "Poisson", "actual": "actual", "poisson_scatter": "Poisson, scatter",
          "actual_scatter": "actual, scatter", "poisson_kinetic": "kinetic rate, scatter",
          "mmpp": "MMPP"}


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
    """The sentences that open the results: Poisson? Does the paper's kicked disk
    reproduce the two-disk chaos (FTLE)? Does any kick? And, with the ``mmpp`` system,
    does clustering in the kick times bring the kicked disk closer?

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

    def statements(systems):
        """"<family>, <system> kicks: <verdict>" for each family and system present."""
        out = []
        for fam in dict.fromkeys(ftle["family"]):
            for system in systems:
                rows = ftle[(ftle["family"] == fam) & (ftle["system"] == system)]
                if not rows.empty:
                    out.append(f"{fam}, {_SHORT[system]} kicks: {_stated(rows)}")
        return out

    paper = statements(("poisson", "actual"))
    if paper:
        mine = ftle[ftle["system"].isin(["poisson", "actual"])]
        verdicts = set(mine["verdict"])
        primary = mine[mine["control"] == "primary"]["estimate"]
        lead = ("Yes" if verdicts == {WITHIN} else "No" if verdicts == {DIFFERS}
                else "Not under every control")
        out.append("**Does the paper's kicked disk reproduce the two-disk chaos?** "
                   f"{lead}: its FTLE is {primary.min():.2f}–{primary.max():.2f} of the "
                   "two-disk one. " + "; ".join(paper) + ".")
    other = statements(("poisson_scatter", "actual_scatter", "poisson_kinetic"))
    if other:
        out.append("**Does any kick?** The scatter kick (a collision with a virtual partner, "
                   "at Poisson, actual or kinetic-rate times) comes closest; FTLE ratio "
                   + "; ".join(other) + ".")
    clustered = statements(("mmpp",))
    if clustered:
        primary = ftle[ftle["control"] == "primary"].set_index(["family", "system"])["estimate"]
        pairs = [f"{fam}: {primary[fam, 'mmpp']:.2f} against {primary[fam, 'poisson']:.2f}"
                 for fam in dict.fromkeys(ftle["family"])
                 if (fam, "mmpp") in primary.index and (fam, "poisson") in primary.index]
        out.append("**Does clustering in the kick times bring the kicked disk closer?** "
                   "MMPP kicks (a two-state Markov-modulated Poisson process fitted to each "
                   "IC's collision times) against Poisson kicks at the same mean rate, FTLE "
                   "ratio to the two-disk value" + (f" ({'; '.join(pairs)})" if pairs else "")
                   + ": " + "; ".join(clustered) + ".")
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
              "CI, bootstrap clustered on ICs]; ✓: the verdict (within 10 %: the whole CI lies in "
              "[0.9, 1.1]; differs: it lies entirely outside; inconclusive: it straddles an "
              "edge) is the same under every control ("
              + ", ".join(_CONTROL_WORDS.get(c, c) for c in dict.fromkeys(table["control"])
                          if c != "primary")
              + "); ✗: it is not, and the control that changes it is named with its "
              "number.", ""]
    lines += markdown_table(overview_table(table))
    return lines + [""]


#: the headline figure's panels: (diagnostic, title)
PANELS = (
    ("ftle", "FTLE λ"),
    ("rr_offdiag@0.001", "off-diagonal RR, ε = 10⁻³\n(uniform-time samples)"),
    ("rr_offdiag@0.01", "off-diagonal RR, ε = 10⁻²\n(uniform-time samples)"),
    ("det@0.01", "DET, ε = 10⁻²\n(uniform-time samples)"),
    ("one_minus_r1", "1 − R₁\n(lag-1 decorrelation)"),
)
_FAMILY_LINES = ("-", "--", ":", "-.")
# y ticks of the ratio panels, by how many decades the panel spans (labels never overlap)
_LOG_TICKS = (
    (4.0, (0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.1, 1.5, 2.0, 3.0)),
    (20.0, (0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0)),
    (math.inf, (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)),
)


def log_ratio_axis(ax):
    """A log y axis for ratios with plain tick labels that never overlap."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ax.set_yscale("log")
    lo, hi = ax.get_ylim()
    choice = next(t for span, t in _LOG_TICKS if hi / lo <= span)
    ax.yaxis.set_major_locator(FixedLocator([t for t in choice if lo <= t <= hi]))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def ratio_curves_figure(curves: pd.DataFrame):
    """The headline figure: the ratio of each kicked system to the two-disk value against
    r, one panel per diagnostic, with 95 % CIs (bootstrap clustered on ICs) and the ±10 %
    band; families by line style. The recurrence panels show the uniform-time control:
    on the paper's collision-truncated samples their ratios are inflated by where the
    samples fall (the findings table has both).

    Parameters
    ----------
    curves : pandas.DataFrame
        ``Controls.curves`` of one or more stores (concatenated).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from kicktimes.report.figures import radius_axis, system_label, system_style

    panels = [(d, t) for d, t in PANELS if d in set(curves["diagnostic"])]
    fig = Figure(figsize=(3.3 * max(len(panels), 1), 4.2), layout="constrained")
    axes = fig.subplots(1, max(len(panels), 1), squeeze=False)[0]
    families = list(dict.fromkeys(curves["family"]))
    systems = [s for s in _SHORT if s in set(curves["system"])]
    for ax, (diagnostic, title) in zip(axes, panels, strict=False):
        ax.axhspan(0.9, 1.1, color="0.85", zorder=0)
        ax.axhline(1.0, color="0.5", linewidth=0.8, zorder=0)
        part = curves[curves["diagnostic"] == diagnostic]
        recurrence = diagnostic.startswith(("rr_", "det"))
        controls = ["uniform_sampling"] if recurrence else ["primary"]
        for k, system in enumerate(systems):
            style = system_style(system, k)
            for f, fam in enumerate(families):
                for control in controls:
                    c = part[(part["system"] == system) & (part["family"] == fam)
                             & (part["control"] == control)].sort_values("radius")
                    if c.empty:
                        continue
                    err = np.vstack([c["ratio"] - c["ci_low"], c["ci_high"] - c["ratio"]])
                    ax.errorbar(c["radius"], c["ratio"], yerr=np.clip(err, 0, None),
                                color=style["color"], marker=style["marker"], markersize=3.5,
                                linestyle=_FAMILY_LINES[f % 4], linewidth=1.0, capsize=1.5)
        ax.set_title(title, fontsize="medium")
        radius_axis(ax)
        log_ratio_axis(ax)
    axes[0].set_ylabel("kicked / two-disk (ratio of means)")
    handles = [Line2D([], [], color=system_style(s, k)["color"], marker=system_style(s, k)[
        "marker"], linestyle="-", label=system_label(s)) for k, s in enumerate(systems)]
    handles += [Line2D([], [], color="k", linestyle=_FAMILY_LINES[f % 4], label=fam)
                for f, fam in enumerate(families)]
    handles += [Line2D([], [], color="0.85", linewidth=6, label="±10 % band")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 6),
               fontsize="small")
    return fig


def merge_control_families(tables):
    """Fold the findings of control experiments into their family's table.

    An experiment named ``"<family>-<control>"`` (the presets ``family_a_invariant`` and
    ``family_a_elastic``: invariant-measure ICs, the elastic rule) is a control of
    ``<family>``: the primary rows of its table become rows of ``<family>``'s table with
    ``control = "<control>"``, and ``robust`` is recomputed over every control.

    Parameters
    ----------
    tables : sequence of pandas.DataFrame
        Findings tables (:data:`COLUMNS`), one per experiment.

    Returns
    -------
    dict
        ``{family: table}`` of the experiments that are not controls of another present
        one (a control whose family is absent stays a family of its own).
    """
    tables = [t for t in tables if not t.empty]
    names = {t["family"].iloc[0] for t in tables}
    out = {}
    extra = {}
    for t in tables:
        name = t["family"].iloc[0]
        family, _, control = name.partition("-")
        if control and family in names:
            rows = t[t["control"] == "primary"].assign(
                family=family, control=control,
                detail=lambda d, n=name: f"from the experiment {n}: " + d["detail"])
            extra.setdefault(family, []).append(rows)
        else:
            out[name] = t
    for family, parts in extra.items():
        merged = pd.concat([out[family], *parts], ignore_index=True)
        keys = ["family", "diagnostic", "system"]
        merged["robust"] = (merged.groupby(keys)["verdict"].transform("nunique") == 1).to_numpy()
        pair = list(zip(merged["diagnostic"], merged["system"], strict=True))
        first = {p: k for k, p in reversed(list(enumerate(pair)))}
        rank = np.array([first[p] for p in pair])
        out[family] = merged.iloc[np.argsort(rank, kind="stable")].reset_index(drop=True)
    return out
