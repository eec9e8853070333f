"""The first screen of the main results page (docs/results/README.md): five one-line
answers, each with one number, its 95 % interval and its caveat, then one compact table
of every diagnostic by every kick law (family A, the primary setting; every control and
family: ``overview.csv``, `kicktimes.report.answers.overview_table`).

Every word of a line comes from the findings table through the verdict rules of
`kicktimes.stats` (`ratio_verdict`, `rejection_verdict`, `null_verdict`,
`poisson_verdict`) and the robustness rule of `kicktimes.report.controls.with_robustness`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.render.pages import markdown_table
from kicktimes.report.answers import SCREEN_ROWS, family_short
from kicktimes.report.controls import LOWER, POISSON_QUESTION
from kicktimes.stats import MARGIN, format_interval, margin_of, ratio_verdict, side_of

__all__ = ["QUESTIONS", "answer_lines", "compact_overview", "first_screen", "qa_table"]

#: the first screen's ratio questions, in order: (question, diagnostic, kicked systems);
#: the first system is the one whose number the line gives; the Poisson question comes
#: first. Each is read at its diagnostic's margin (`kicktimes.stats.margin_of`), the
#: margin of the compact table and the findings CSVs
QUESTIONS = (
    ("Does the paper's kicked disk (uniform kicks) have the two-disk FTLE?",
     "ftle", ("poisson", "actual")),
    ("Do scatter kicks (virtual partners) give the two-disk FTLE?", "ftle",
     ("poisson_scatter", "actual_scatter", "poisson_kinetic")),
    ("Does it decorrelate like the two disks (1 − R₁ at lag 1, over n steps)?",
     "one_minus_r1", ("poisson", "actual")),
    ("Does it have the two-disk off-diagonal RR (ε = 10⁻²)?", "rr_offdiag@0.01",
     ("poisson", "actual")),
)
POISSON_LINE = "Are the two disks' collision times Poisson?"
_WORDS = {LOWER: "no, lower", "higher": "no, higher", "inconclusive": "inconclusive"}
_KICKS = {"poisson": "Poisson kicks", "actual": "kicks at the actual times",
          "poisson_scatter": "Poisson scatter kicks", "actual_scatter": "actual scatter kicks",
          "poisson_kinetic": "scatter kicks at the kinetic rate",
          "uniform_kinetic": "uniform kicks at the kinetic rate"}


#: the compact table's names of the controls
_CONTROL_SHORT = {"paired_median": "median", "sticky_excluded": "sticky",
                  "paper_sampling": "sampling", "invariant_ics": "ICs", "elastic": "elastic",
                  "elastic+invariant_ics": "elastic+ICs"}


def _ci(row) -> str:
    return format_interval(row.estimate, row.ci_low, row.ci_high)


def _pct(row) -> str:
    return format_interval(100 * row.estimate, 100 * row.ci_low, 100 * row.ci_high,
                           edges=(2.5, 5.0, 7.5)) + " %"


def _range(rows) -> str:
    x = pd.to_numeric(rows["estimate"], errors="coerce")
    x = x[np.isfinite(x)]
    lo, hi = (f"{x.min():.3g}", f"{x.max():.3g}") if len(x) else ("—", "—")
    return lo if lo == hi else f"{lo}–{hi}"


def _one(rows, **where):
    for key, value in where.items():
        rows = rows[rows[key] == value]
    return rows.iloc[0] if len(rows) else None


def _deciding(rows, main) -> list[str]:
    """The controls whose verdict differs from the primary's ``main``, most cells first;
    else those that put the interval on the other side of 1."""
    other = rows[(rows["verdict"] != main) & (rows["control"] != "primary")]
    found = list(other["control"].value_counts().index)
    return found or [c for c in dict.fromkeys(rows["depends_on"].fillna("")) if c]


def _word(verdict, row=None, short=False) -> str:
    """The answer's word for ``verdict``; an inconclusive ``row`` whose interval lies on
    one side of 1 says so (`kicktimes.stats.side_of`): a departure whose size the margin
    does not resolve, not an unresolved one."""
    side = side_of(row.ci_low, row.ci_high) if row is not None else None
    if verdict == "inconclusive" and side:
        return f"{side} 1" if short else f"{side} 1, size unresolved"
    return ("yes, " + verdict) if verdict.startswith("within") else _WORDS.get(verdict, verdict)


def _sides(rows) -> bool:
    """Whether some row's CI lies above 1 and another's below 1."""
    return bool((rows["ci_low"] > 1).any() and (rows["ci_high"] < 1).any())


def _ratio_line(question, rows, margin=MARGIN) -> str:
    """One answer at ``margin`` (`kicktimes.stats.ratio_verdict`).

    When every control and family gives one verdict and no two CIs lie on opposite sides
    of 1, the verdict is robust in direction: the line gives the primary verdict and number
    of the first family and kick law, with the range over the cells; when that range is
    wider than the margin band, it names the control whose estimate lies farthest from the
    primary's (the size depends on it). Otherwise the line says "depends on" the control
    that changes the verdict, with both numbers. A verdict "within" whose interval
    excludes 1 says in how many cells (a real difference smaller than the margin)."""
    rows = rows.assign(verdict=[ratio_verdict(lo, hi, tolerance=margin) for lo, hi
                                in zip(rows["ci_low"], rows["ci_high"], strict=True)])
    family = rows["family"].iloc[0]
    system = rows["system"].iloc[0]
    primary = _one(rows, family=family, system=system, control="primary")
    n_controls = rows.loc[rows["control"] != "primary", "control"].nunique()
    families = rows["family"].nunique()
    where = f"({family_short(family)}, {_KICKS.get(system, system)})"
    at = f" at a {100 * margin:g} % margin"
    over = (f"{n_controls} controls" + (" and both families" if families > 1 else "")
            if n_controls else "both families" if families > 1 else "")
    if rows["verdict"].nunique() == 1:
        text = (f"**{question}** {_word(primary.verdict, primary, short=True)}{at}: "
                f"{_ci(primary)} {where}")
        if _sides(rows):  # one verdict, but intervals on both sides of 1: not robust
            text += f"; not robust: CIs on both sides of 1 ({_range(rows)})"
        elif over:
            far = _size_control(rows, primary, margin)
            text += (f"; robust over {over} ({_range(rows)})" if far is None else
                     f"; robust in direction over {over} ({_range(rows)}), not in size: "
                     f"{far.estimate:.3g} ({_cell(far)})")
    else:
        # every control of the line's own cell (family, kick law) whose verdict differs,
        # grouped by verdict: no control that changes it is left unnamed
        cell = rows[(rows["family"] == family) & (rows["system"] == system)]
        other = cell[cell["verdict"] != primary.verdict]
        if other.empty:  # the cell agrees with itself; another family or law differs
            other = rows[rows["verdict"] != primary.verdict]
        groups = []
        for _, g in other.groupby("verdict", sort=False):
            names = ", ".join(_CONTROL_SHORT.get(c, c) if (f, k) == (family, system) else
                              f"{family_short(f)} {_CONTROL_SHORT.get(c, c)}"
                              for f, k, c in zip(g["family"], g["system"], g["control"],
                                                 strict=True))
            numbers = _ci(g.iloc[0]) if len(g) == 1 else _range(g)
            groups.append(f"{_read(g.iloc[0])} {numbers} under {names}")
        text = (f"**{question}** depends on the control{at}: {_read(primary)} "
                f"{_ci(primary)} {where} under the primary; " + "; ".join(groups))
    below = int((rows["ci_high"] < 1).sum())
    if primary.verdict.startswith("within") and below:
        text += f"; CI below 1 in {below} of {len(rows)} cells"
    return text + "."


def _read(row) -> str:
    """A row's verdict as the answer reads it (`_word` without the "yes, " / "no, ")."""
    word = _word(row.verdict, row, short=True)
    return row.verdict if word.startswith(("yes, ", "no, ")) else word


def _cell(row) -> str:
    """``"B, Poisson kicks, elastic"``: the family, kick law and control (its short name)
    of a findings row."""
    control = "" if row.control == "primary" else ", " + _CONTROL_SHORT.get(row.control,
                                                                            row.control)
    return f"{family_short(row.family)}, {_KICKS.get(row.system, row.system)}{control}"


def _size_control(rows, primary, margin):
    """The row whose estimate lies farthest from ``primary``'s on a log scale, when the
    cells' estimates span more than the margin band ((1 + margin) / (1 - margin)); else
    None."""
    x = pd.to_numeric(rows["estimate"], errors="coerce")
    ok = np.isfinite(x) & (x > 0)
    if ok.sum() < 2 or x[ok].max() / x[ok].min() <= (1 + margin) / (1 - margin):
        return None
    distance = np.abs(np.log(x[ok].to_numpy(float) / primary.estimate))
    return rows[ok.to_numpy()].iloc[int(np.argmax(distance))]


def _poisson_line(table) -> str | None:
    """The Poisson answer: the one standard's verdict (`kicktimes.stats.poisson_verdict`,
    D read against its null), family A's rejection share against its calibrated level and
    D's excess over its null, then the elastic rule's two numbers."""
    from kicktimes.report.poisson import HEADLINE_TEST

    rows = table[table["question"] == POISSON_QUESTION]
    verdicts = rows[rows["diagnostic"] == f"poisson@{HEADLINE_TEST}"]
    if verdicts.empty:
        return None
    family = verdicts["family"].iloc[0]
    main = _one(verdicts, family=family, control="primary")
    share = _one(rows, diagnostic=f"reject@{HEADLINE_TEST}", family=family, control="primary")
    excess = _one(rows, diagnostic="dispersion_index_excess", family=family, control="primary")
    robust = verdicts["verdict"].nunique() == 1 and verdicts["control"].nunique() > 1
    level = _null_share(share)
    text = (f"**{POISSON_LINE}** {'no' if main.verdict == 'not Poisson' else main.verdict}: "
            f"{_pct(share)} reject uniformity (null {level})")
    if excess is not None:
        text += f", D − null {_ci(excess)}"
    text += f" ({family_short(family)}{'; robust: rule × ICs' if robust else ''})"
    e_share = _one(rows, diagnostic=f"reject@{HEADLINE_TEST}", family=family, control="elastic")
    e_excess = _one(rows, diagnostic="dispersion_index_excess", family=family,
                    control="elastic")
    if e_share is not None:
        text += (f"; elastic {_pct(e_share)}"
                 + (f", {_ci(e_excess)}" if e_excess is not None else ""))
    return text + _sign_flips(rows, family) + "."


def _sign_flips(rows, family) -> str:
    """``"; the hazard at t < 0.1 mean intervals flips sign with the rule"``: the
    statistics read beyond their margin above their null under the primary rule and below
    it under the elastic rule, or the reverse (not Poisson both, in opposite directions:
    `null_verdict`)."""
    names = {"hazard_first_excess": "the hazard at t < 0.1 mean intervals",
             "gamma_shape_excess": "the gamma shape"}
    beyond = {"above its null", "below its null"}
    flips = []
    for diagnostic, name in names.items():
        p = _one(rows, diagnostic=diagnostic, family=family, control="primary")
        e = _one(rows, diagnostic=diagnostic, family=family, control="elastic")
        if p is None or e is None:
            continue
        if {p.verdict, e.verdict} == beyond:
            flips.append(name)
    if not flips:
        return ""
    return f"; {' and '.join(flips)} flip{'' if len(flips) > 1 else 's'} sign with the rule"


def _null_share(row) -> str:
    """``"5.0 %"``: the calibrated level a share row's detail names."""
    import re

    m = re.search(r"rejects, ([0-9.]+) % \(null_calibration", str(row.detail))
    return f"{m.group(1)} %" if m else "α"


def answer_lines(table: pd.DataFrame) -> list[str]:
    """At most five one-line answers (Markdown bullets): the Poisson question, then
    `QUESTIONS` in order, each from every control and family of ``table``."""
    out = []
    poisson = _poisson_line(table)
    if poisson:
        out.append("- " + poisson)
    for question, diagnostic, systems in QUESTIONS:
        rows = table[(table["diagnostic"] == diagnostic) & table["system"].isin(systems)]
        if len(rows):
            order = {s: k for k, s in enumerate(systems)}
            rows = rows.sort_values("system", key=lambda s: s.map(order), kind="stable")
            out.append("- " + _ratio_line(question, rows, margin_of(diagnostic)))
    return out[:5]


def compact_overview(table: pd.DataFrame) -> pd.DataFrame:
    """Every diagnostic of `SCREEN_ROWS` by every kick law: family A's primary ratio,
    ✓ when robust over every control and both families, else ✗ and the control that
    decides (its number: ``overview.csv``)."""
    comp = table[table["question"] != POISSON_QUESTION]
    family = comp["family"].iloc[0] if len(comp) else ""
    systems = [s for s in _KICKS if s in set(comp["system"])]
    out = []
    for diagnostic, label in SCREEN_ROWS:
        part = comp[comp["diagnostic"] == diagnostic]
        if part.empty:
            continue
        line = {"diagnostic": label}
        for system in systems:
            rows = part[part["system"] == system]
            # each cell at its diagnostic's margin, as the answers read it
            margin = margin_of(diagnostic)
            rows = rows.assign(verdict=[ratio_verdict(lo, hi, tolerance=margin) for lo, hi
                                        in zip(rows["ci_low"], rows["ci_high"], strict=True)])
            p = _one(rows, family=family, control="primary")
            if p is None:
                line[_KICKS[system]] = ""
                continue
            robust = (rows["robust"].astype(str).str.lower().eq("true").all()
                      and rows["verdict"].nunique() == 1)
            # every control that changes it (most cells first): none is hidden behind
            # the first
            deciding = _deciding(rows, p.verdict)
            mark = "✓" if robust else ("✗↕ " if _sides(rows) else "✗ ") + ", ".join(
                _CONTROL_SHORT.get(c, c) for c in deciding)
            word = _word(p.verdict, p, short=True).removeprefix("no, ").removeprefix("yes, ")
            line[_KICKS[system]] = f"{word} {p.estimate:.3g} {mark}"
        out.append(line)
    return pd.DataFrame(out)


def qa_table(table: pd.DataFrame) -> pd.DataFrame:
    """The answers as a table (question, answer line), for the report and tests."""
    lines = answer_lines(table)
    return pd.DataFrame({"answer": [line[2:] for line in lines]})


def first_screen(table: pd.DataFrame) -> list[str]:
    """The Markdown lines that open the page: :func:`answer_lines`, then the compact table
    (:func:`compact_overview`) with one sentence on how to read it."""
    lines = answer_lines(table) + [""]
    lines += ["Every diagnostic by kick law (family A, primary, each at its margin: "
              f"±{100 * margin_of('ftle'):g} % for the FTLE, ±{100 * margin_of('rr_offdiag'):g} "
              f"% for the off-diagonal RR, ±{100 * MARGIN:g} % otherwise; ✓ robust over every "
              "control and both families, ✗ the controls that change it (↕: CIs on both "
              "sides of 1); below 1: a CI below 1 that reaches into the band; "
              "every cell's numbers: [overview.csv](overview.csv)):", ""]
    return lines + markdown_table(compact_overview(table)) + [""]
