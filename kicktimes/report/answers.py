"""The answers of a sweep's findings table: the overview, the sentences and the headline
figure.

The findings table under its controls (:mod:`kicktimes.report.controls`) gives
:func:`overview_table` (one cell per comparison, ✓ robust or ↕ depends on, the paper's
claim beside), the Poisson, FTLE and MMPP sentences (:func:`answers`) and the headline
figure of every ratio against the radius with its band (:func:`ratio_curves_figure`).
The sweep report's Findings section (:mod:`kicktimes.report.findings`) reads them; the
paper study's first screen (`kicktimes.studies.paper.first_screen`) builds on them.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kicktimes.report.controls import LOWER, POISSON_QUESTION
from kicktimes.report.store import REFERENCE
from kicktimes.stats import format_interval, margin_of

__all__ = ["CONTROL_WORDS", "PANELS", "PAPER_CLAIMS", "SCREEN_ROWS", "answers", "family_short",
           "ftle_answer", "log_ratio_axis", "mmpp_answer", "null_level_text", "overview_table",
           "poisson_answer", "poisson_share", "ratio_curves_figure", "screen_cell"]


#: what the paper says of each diagnostic (Ranković & Porter 2013), beside the table's rows
PAPER_CLAIMS = {
    "ftle": "“a good approximation” (Poisson), “an excellent approximation” (actual) (Fig. 6)",
    "rr_offdiag": "“very good agreement” of RR at small r (Fig. 7)",
    "det": "not studied",
    "one_minus_r1": "“excellent agreement” of R₁, top; “good agreement”, bottom (Fig. 8)",
}
CONTROL_WORDS = {
    "paired_median": "paired median",
    "sticky_excluded": "sticky runs excluded",
    "uniform_sampling": "uniform-time samples",
    "paper_sampling": "the paper's samples",
    "invariant_ics": "invariant-measure ICs",
    "elastic": "the elastic rule",
    "elastic+invariant_ics": "the elastic rule with invariant-measure ICs",
}
_SHORT = {"poisson": "Poisson", "actual": "actual", "poisson_scatter": "Poisson, scatter",
          "actual_scatter": "actual, scatter", "poisson_kinetic": "kinetic rate, scatter",
          "uniform_kinetic": "kinetic rate, uniform", "mmpp": "MMPP"}
#: the rows of the first screen's table, in order: (diagnostic, label)
SCREEN_ROWS = (
    ("ftle", "FTLE λ"),
    ("rr_offdiag@0.01", "off-diagonal RR, ε = 10⁻² (uniform-time samples)"),
    ("det@0.01", "DET, ε = 10⁻² (uniform-time samples)"),
    ("rr_offdiag@0.001", "off-diagonal RR, ε = 10⁻³ (uniform-time samples)"),
    ("one_minus_r1", "1 − R₁ (lag-1 decorrelation)"),
)
_FAMILY_SHORT = {"family_a": "A", "family_b": "B"}
#: the Poisson battery's tests, as the first screen names them
_TEST_NAMES = {"uniformity_ks": "uniformity (KS)", "laplace_trend": "Laplace trend",
               "exponential_ks": "exponential-interval (KS)",
               "exponential_ad": "exponential-interval (AD)", "ljung_box": "Ljung–Box",
               "runs": "runs", "dispersion": "dispersion"}


def _ci(row):
    return format_interval(row.estimate, row.ci_low, row.ci_high)


def family_short(family):
    """``"A"`` for ``family_a``, ``"B"`` for ``family_b``, else the name."""
    return _FAMILY_SHORT.get(family, family)


def _farthest(estimates: pd.Series, reference: float):
    """The index of the estimate farthest from ``reference`` in log scale (the largest
    ratio either way; of equal ones, to 1e-9, the first), or of the first when the
    reference is not a positive number."""
    x = estimates.astype(float)
    ok = np.isfinite(x) & (x > 0)
    if not ok.any():
        return None if x.empty else x.index[0]
    if not (np.isfinite(reference) and reference > 0):
        return x[ok].index[0]
    distance = (np.log(x[ok]) - math.log(reference)).abs()
    # ties (equal to rounding: the same value from two controls) go to the first control
    # in the table's order, whatever the last bits of each library version
    top = distance[distance >= distance.max() - 1e-9 * max(1.0, float(distance.max()))]
    return top.index[0]


def screen_cell(rows: pd.DataFrame) -> str:
    """One cell of the first screen: a comparison over every control and family.

    ``"✓ lower: 0.301–0.338"`` (the verdict word and the range of the estimate over every
    control and family) when it is robust in every family with one verdict; otherwise
    ``"depends on <control>: <primary> vs <control's value>"`` (the family named when there
    are several), or ``"depends on the family"`` with both primaries.
    """
    families = list(dict.fromkeys(rows["family"]))
    primary = rows[rows["control"] == "primary"].set_index("family")
    lo, hi = rows["estimate"].min(), rows["estimate"].max()
    missing = ""
    if (rows["system"].iloc[0] in ("poisson_kinetic", "uniform_kinetic")
            and "elastic" not in set(rows["control"])):
        missing = " (mirror rule only)"
    rows = rows.assign(estimate=pd.to_numeric(rows["estimate"], errors="coerce"))
    primary = rows[rows["control"] == "primary"].set_index("family")
    for fam in families:
        mine = rows[rows["family"] == fam]
        if not mine["robust"].all():
            where = f"{family_short(fam)}: " if len(families) > 1 else ""
            p = primary.loc[fam]
            below, above = mine[mine["ci_high"] < 1], mine[mine["ci_low"] > 1]
            if len(below) and len(above):
                # ↕: name every control on the other side of 1 from the primary, and show
                # the primary against the one farthest from it (with the primary on 1, the
                # two extremes)
                side = below if p.ci_low > 1 else above if p.ci_high < 1 else None
                if side is None:
                    lo_row = below.loc[below["estimate"].idxmin()]
                    other = above.loc[above["estimate"].idxmax()]
                    return (f"↕ depends on {lo_row['control']} vs {other['control']}: "
                            f"{where}{_ci(lo_row)} vs {_ci(other)}{missing}")
                other = side.loc[_farthest(side["estimate"], p.estimate)]
                names = ", ".join(dict.fromkeys([other["control"], *side["control"]]))
                return (f"↕ depends on {names}: {where}{_ci(p)} vs {_ci(other)} "
                        f"({other['control']}){missing}")
            # the control whose verdict differs from the primary's and that moves the
            # estimate most (not merely the first one that breaks it)
            differ = mine[(mine["verdict"] != p.verdict) & (mine["control"] != "primary")
                          & np.isfinite(mine["estimate"]) & (mine["estimate"] > 0)]
            if len(differ) and _farthest(differ["estimate"], p.estimate) is not None:
                other = differ.loc[_farthest(differ["estimate"], p.estimate)]
            else:
                other = mine[mine["control"] == mine["depends_on"].iloc[0]].iloc[0]
            return (f"depends on {other['control']}: {where}{_ci(p)} vs "
                    f"{_ci(other)}{missing}")
    verdicts = set(primary["verdict"])
    if len(verdicts) > 1:
        return ("depends on the family: " + "; ".join(
            f"{family_short(f)} {_ci(primary.loc[f])}" for f in families) + missing)
    if (rows["ci_low"] > 1).any() and (rows["ci_high"] < 1).any():
        return ("depends on the family: " + "; ".join(
            f"{family_short(f)} {_ci(primary.loc[f])}" for f in families) + missing)
    return f"✓ {verdicts.pop()}: {lo:.3g}–{hi:.3g}{missing}"


def overview_table(table: pd.DataFrame) -> pd.DataFrame:
    """The first screen's table: diagnostics as rows (`SCREEN_ROWS`), kick laws as columns,
    each cell :func:`screen_cell` over every control and family; the paper's claim beside."""
    comp = table[(table["system"] != REFERENCE) & (table["question"] != POISSON_QUESTION)]
    systems = [s for s in _SHORT if s in set(comp["system"])]
    out = []
    rows_wanted = [r for r in SCREEN_ROWS if r[0] in set(comp["diagnostic"])]
    for diagnostic, label in rows_wanted:
        line = {"diagnostic": label}
        for system in systems:
            rows = comp[(comp["diagnostic"] == diagnostic) & (comp["system"] == system)]
            line[_SHORT[system]] = screen_cell(rows) if not rows.empty else ""
        line["the paper"] = PAPER_CLAIMS.get(diagnostic.split("@")[0], "")
        out.append(line)
    return pd.DataFrame(out)


def _pct(row):
    return (f"{100 * row.estimate:.1f} % [{100 * row.ci_low:.1f}, {100 * row.ci_high:.1f}]")


def poisson_answer(table: pd.DataFrame, alpha=0.05) -> str:
    """The first screen's sentence on the Poisson question, with the collision rule as a
    factor: per family under the mirror and the elastic rule (the paper's ICs), the verdict
    of the one standard (`kicktimes.stats.poisson_verdict`: the headline test's rejection
    share against its null-calibrated level, and the dispersion index D against the ±10 %
    band), with both numbers, and whether the rejection shares of the two rules are
    disjoint. Without the standard's rows (an older table), the rejection shares alone."""
    from kicktimes.report.poisson import HEADLINE_TEST

    rows = table[table["question"] == POISSON_QUESTION]
    head = rows[rows["diagnostic"] == f"reject@{HEADLINE_TEST}"]
    if head.empty:
        return ""
    families = list(dict.fromkeys(head["family"]))

    def cell(diagnostic, fam, control):
        r = rows[(rows["diagnostic"] == diagnostic) & (rows["family"] == fam)
                 & (rows["control"] == control)]
        return r.iloc[0] if len(r) else None

    def rule_text(control):
        shares, ds, verdicts = [], [], set()
        for fam in families:
            share = cell(f"reject@{HEADLINE_TEST}", fam, control)
            d = cell("dispersion_index", fam, control)
            verdict = cell(f"poisson@{HEADLINE_TEST}", fam, control)
            if share is None:
                continue
            shares.append(f"{_pct(share)} ({family_short(fam)})")
            if d is not None:
                ds.append(format_interval(d.estimate, d.ci_low, d.ci_high))
            verdicts.add(verdict.verdict if verdict is not None else share.verdict)
        return shares, ds, verdicts

    def say(verdicts):
        return (next(iter(verdicts)) if len(verdicts) == 1
                else "depends on the family (" + " / ".join(sorted(verdicts)) + ")")

    shares, ds, v_mirror = rule_text("primary")
    null = cell(f"reject@{HEADLINE_TEST}", families[0], "primary")
    level = ("null streams " + null_level_text(rows, families)
             if "null_calibration" in str(null.detail) else f"Poisson {100 * alpha:g} %")
    text = (f"Poisson collision times? Mirror rule: {say(v_mirror)} (uniformity rejected in "
            + ", ".join(shares) + f" of runs, against {level}"
            + (f"; D = {', '.join(ds)}" if ds else "") + ")")
    e_shares, e_ds, v_elastic = rule_text("elastic")
    if e_shares:
        text += (f"; elastic rule: {say(v_elastic)} (" + ", ".join(e_shares)
                 + (f"; D = {', '.join(e_ds)}" if e_ds else "") + ")")
        pairs = [(cell(f"reject@{HEADLINE_TEST}", f, "elastic"),
                  cell(f"reject@{HEADLINE_TEST}", f, "primary")) for f in families]
        pairs = [(e, m) for e, m in pairs if e is not None and m is not None]
        if pairs and all(e.ci_high < m.ci_low for e, m in pairs):
            text += ", fewer rejections (disjoint)"
    return text + "."


def null_level_text(rows, families) -> str:
    """``"4.9 % (A), 5.1 % (B)"``: the calibrated level of the headline test per family,
    read from its rows' detail (null_calibration.csv)."""
    import re

    from kicktimes.report.poisson import HEADLINE_TEST

    out = []
    for fam in families:
        r = rows[(rows["diagnostic"] == f"reject@{HEADLINE_TEST}") & (rows["family"] == fam)
                 & (rows["control"] == "primary")]
        m = re.search(r"rejects, ([0-9.]+) %", str(r.iloc[0].detail)) if len(r) else None
        if m:
            out.append(f"{m.group(1)} % ({family_short(fam)})")
    return ", ".join(out)


def ftle_answer(table: pd.DataFrame) -> str:
    """The first screen's sentence on the FTLE of the paper's kicked disk (Poisson and
    actual kicks): its verdict over every control and family, or what it depends on."""
    ftle = table[(table["diagnostic"] == "ftle") & table["system"].isin(["poisson", "actual"])]
    if ftle.empty:
        return ""
    robust = ftle["robust"].all()
    verdicts = set(ftle["verdict"])
    lo, hi = ftle["estimate"].min(), ftle["estimate"].max()
    n_controls = ftle["control"].nunique()
    if robust and verdicts == {LOWER}:
        return ("The paper's kicked disk does not reproduce the two-disk chaos: its FTLE is "
                f"{lo:.3g}–{hi:.3g} of the two-disk value, lower under all {n_controls} "
                "controls in every family" + _scatter_clause(table) + ".")
    if robust and len(verdicts) == 1 and verdicts.pop().startswith("within"):
        return (f"The paper's kicked disk reproduces the two-disk FTLE within "
                f"{100 * margin_of('ftle'):g} % "
                f"({lo:.3g}–{hi:.3g}) under all {n_controls} controls.")
    cells = [screen_cell(ftle[ftle["system"] == s]) for s in ("poisson", "actual")]
    return (f"The paper's kicked disk's FTLE, Poisson kicks: {cells[0]}; actual kicks: "
            f"{cells[1]}.")


def _scatter_clause(table: pd.DataFrame) -> str:
    """``"; scatter kicks bring it to a–b, below 1 under k of n (family, control) cells"``:
    where the scatter kicks' FTLE ratios lie, and how many of their intervals exclude 1
    from below (a deficit that a "within" verdict does not show)."""
    rows = table[(table["diagnostic"] == "ftle")
                 & table["system"].isin(["poisson_scatter", "actual_scatter"])]
    if rows.empty:
        return ""
    below = int((rows["ci_high"] < 1.0).sum())
    above = int((rows["ci_low"] > 1.0).sum())
    text = (f"; scatter kicks: {rows['estimate'].min():.3g}–{rows['estimate'].max():.3g}, "
            f"CI below 1 in {below} of {len(rows)} cells")
    if above:
        text += f" and above 1 in {above}"
    return text


def mmpp_answer(table: pd.DataFrame) -> str:
    """With the ``mmpp`` system: does clustering in the kick times bring the kicked disk
    closer? Its FTLE ratio against the Poisson kicks' (primary, per family), and its cell."""
    ftle = table[table["diagnostic"] == "ftle"]
    if "mmpp" not in set(ftle["system"]):
        return ""
    primary = ftle[ftle["control"] == "primary"].set_index(["family", "system"])["estimate"]
    pairs = [f"{fam}: {primary[fam, 'mmpp']:.2f} against {primary[fam, 'poisson']:.2f}"
             for fam in dict.fromkeys(ftle["family"])
             if (fam, "mmpp") in primary.index and (fam, "poisson") in primary.index]
    return ("Does clustering in the kick times bring the kicked disk closer? MMPP kicks (a "
            "two-state Markov-modulated Poisson process fitted to each IC's collision times) "
            "against Poisson kicks at the same mean rate, FTLE ratio to the two-disk value"
            + (f" ({'; '.join(pairs)})" if pairs else "") + ": MMPP kicks: "
            + screen_cell(ftle[ftle["system"] == "mmpp"]) + ".")


def answers(table: pd.DataFrame, poisson_share=None) -> list[str]:
    """The answers that open a report's findings: the Poisson question, the paper's kicked
    disk, and (with the ``mmpp`` system) clustered kicks."""
    return [s for s in (poisson_answer(table), ftle_answer(table), mmpp_answer(table)) if s]


def poisson_share(effects) -> tuple | None:
    """``(share, ci_low, ci_high, alpha)`` of the Poisson-rejection finding, or None."""
    for e in effects:
        if e.question.startswith("Poisson"):
            return (e.estimate, e.ci_low, e.ci_high, 0.05)
    return None


#: the headline figure's panels: (diagnostic, title), in the order of the first screen's
#: table (`SCREEN_ROWS`)
PANELS = (
    ("ftle", "FTLE λ"),
    ("rr_offdiag@0.01", "off-diagonal RR, ε = 10⁻²\n(uniform-time samples)"),
    ("det@0.01", "DET, ε = 10⁻²\n(uniform-time samples)"),
    ("rr_offdiag@0.001", "off-diagonal RR, ε = 10⁻³\n(uniform-time samples)"),
    ("one_minus_r1", "1 − R₁\n(lag-1 decorrelation)"),
)
# y ticks of the ratio panels, by how many decades the panel spans (labels never overlap)
_LOG_TICKS = (
    (4.0, (0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.1, 1.5, 2.0, 3.0)),
    (20.0, (0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0)),
    (math.inf, (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)),
)
#: the statistic of the headline figure: the findings table's (the ratio of ensemble means)
HEADLINE_CONTROL = "primary"
#: the kick laws the headline figure draws (the others overplot them; every law and
#: radius: the findings_by_radius CSVs): the paper's two uniform kicks and the scatter kick
HEADLINE_SYSTEMS = ("poisson", "actual", "poisson_scatter")


def log_ratio_axis(ax):
    """A log y axis for ratios with plain tick labels that never overlap."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ax.set_yscale("log")
    lo, hi = ax.get_ylim()
    choice = next(t for span, t in _LOG_TICKS if hi / lo <= span)
    ax.yaxis.set_major_locator(FixedLocator([t for t in choice if lo <= t <= hi]))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def ratio_curves_figure(curves: pd.DataFrame, control=HEADLINE_CONTROL,
                        systems=HEADLINE_SYSTEMS):
    """The headline figure: the ratio of each kicked system to the two-disk value against
    r, one line per kick law, one panel per diagnostic (columns) and family (rows), with
    95 % CIs (bootstrap clustered on ICs) and the diagnostic's band
    (`kicktimes.stats.margin_of`). The panels of one diagnostic share a log y scale (each
    diagnostic its own, so that a deficit of a few per cent stays visible). The statistic
    is ``control``'s
    (default ``"primary"``: the ratio of ensemble means per radius, the statistic of the
    findings table, so the figure and the table read alike); the recurrence panels use
    uniform-time samples (the primary setting of recurrence). The kick laws are dodged
    along r (each by a few per cent of r), so laws with equal ratios stay visible.

    Parameters
    ----------
    curves : pandas.DataFrame
        ``Controls.curves`` of one or more stores (concatenated).
    control : str
        Which control's per-radius curves to draw.
    systems : sequence of str
        The kick laws drawn (default `HEADLINE_SYSTEMS`; ``None``: every one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from kicktimes.render.figures import radius_axis, system_label, system_style

    curves = curves[curves["control"] == control]
    panels = [(d, t) for d, t in PANELS if d in set(curves["diagnostic"])]
    families = list(dict.fromkeys(curves["family"]))
    systems = [s for s in _SHORT if s in set(curves["system"])
               and (systems is None or s in systems)]
    curves = curves[curves["system"].isin(systems)]
    ncol, nrow = max(len(panels), 1), max(len(families), 1)
    fig = Figure(figsize=(3.0 * ncol, 2.9 * nrow + 0.9), layout="constrained")
    # one radius axis for every panel: the families' radii differ (A to 0.030, B to 0.027)
    axes = fig.subplots(nrow, ncol, squeeze=False, sharey="col", sharex="all")
    limits = {}
    for diagnostic, _ in panels:  # one log scale per diagnostic: a 3 % deficit stays visible
        values = curves.loc[curves["diagnostic"] == diagnostic,
                            ["ratio", "ci_low", "ci_high"]].to_numpy(float)
        values = values[np.isfinite(values) & (values > 0)]
        band = margin_of(diagnostic)
        limits[diagnostic] = ((min(1 - 2 * band, float(values.min()) / 1.05),
                               max(1 + 2 * band, float(values.max()) * 1.05))
                              if values.size else (0.5, 2.0))
    for f, fam in enumerate(families):
        for j, (diagnostic, title) in enumerate(panels):
            ax = axes[f, j]
            band = margin_of(diagnostic)
            ax.axhspan(1 - band, 1 + band, color="0.85", zorder=0)
            ax.axhline(1.0, color="0.5", linewidth=0.8, zorder=0)
            part = curves[(curves["diagnostic"] == diagnostic) & (curves["family"] == fam)]
            for k, system in enumerate(systems):
                c = part[part["system"] == system].sort_values("radius")
                if c.empty:
                    continue
                style = system_style(system, k)
                err = np.vstack([c["ratio"] - c["ci_low"], c["ci_high"] - c["ratio"]])
                dodge = 1.0 + 0.025 * (k - (len(systems) - 1) / 2)
                ax.errorbar(c["radius"] * dodge, c["ratio"], yerr=np.clip(err, 0, None),
                            color=style["color"], marker=style["marker"], markersize=3,
                            linewidth=1.0, capsize=1.5)
            ax.set_title(f"{fam}: {title} (±{100 * band:g} %)", fontsize="small")
            radius_axis(ax)
            ax.tick_params(labelbottom=True)  # every row its radii, under the shared axis
            ax.set_ylim(*limits[diagnostic])
            log_ratio_axis(ax)
        statistic = ("ratio of means" if control == "primary"
                     else "median of per-IC ratios" if control == "paired_median" else control)
        axes[f, 0].set_ylabel(f"{fam}\nkicked / two-disk\n({statistic}; log scale)",
                              fontsize="small")
    handles = [Line2D([], [], color=system_style(s, k)["color"], marker=system_style(s, k)[
        "marker"], linestyle="-", label=system_label(s)) for k, s in enumerate(systems)]
    handles += [Line2D([], [], color="0.85", linewidth=6, label="the diagnostic's band")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4),
               fontsize="small")
    return fig
