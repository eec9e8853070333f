"""The first screen of the main results page (docs/results/README.md): the paper's
questions, each answered over every control and family of the findings table, then the
overview of every diagnostic by every kick law (`kicktimes.report.answers`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from kicktimes.render.pages import markdown_table
from kicktimes.report.answers import CONTROL_WORDS, null_level_text, overview_table
from kicktimes.report.controls import LOWER, POISSON_QUESTION, WITHIN

__all__ = ["QUESTIONS", "first_screen", "qa_table"]

#: the first screen's questions, in order: (question, diagnostic, kicked systems); the
#: Poisson question comes first and reads the one standard's rows
QUESTIONS = (
    ("Does the paper's kicked disk (uniform kicks) have the two-disk FTLE?", "ftle",
     ("poisson", "actual")),
    ("Do scatter kicks (virtual partners) give the two-disk FTLE?", "ftle",
     ("poisson_scatter", "actual_scatter", "poisson_kinetic")),
    ("Does the kicked disk have the two-disk recurrence rate (ε = 10⁻²)?", "rr_offdiag@0.01",
     ("poisson", "actual")),
    ("Does it decorrelate like the two disks at lag 1 (1 − R₁)?", "one_minus_r1",
     ("poisson", "actual")),
)


_ANSWER_WORDS = {LOWER: "no: lower", "higher": "no: higher", WITHIN: "yes, within 10 %",
                 "not Poisson": "no", "Poisson within 10 %": "yes, within 10 %"}


def _range(rows) -> str:
    x = pd.to_numeric(rows["estimate"], errors="coerce")
    x = x[np.isfinite(x)]
    if x.empty:
        return "—"
    lo, hi = x.min(), x.max()
    return f"{lo:.3g}" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}–{hi:.3g}"


def _qa_row(question, rows) -> dict:
    """One row of :func:`qa_table`: a question answered over every control and family.
    The deciding control's count excludes the primary; a row whose primary verdicts differ
    between kick laws or families says so; the number adds how many (family, control,
    kick law) cells have their interval below (above) 1, a deficit a "within 10 %"
    verdict does not show."""
    n_controls = rows.loc[rows["control"] != "primary", "control"].nunique()
    verdicts = set(rows["verdict"])
    primary = rows[rows["control"] == "primary"]
    first = set(primary["verdict"]) if len(primary) else {rows["verdict"].iloc[0]}
    main = primary["verdict"].mode().iloc[0] if len(primary) else rows["verdict"].iloc[0]
    robust = bool(rows["robust"].all()) and len(verdicts) == 1
    below = int((rows["ci_high"] < 1).sum())
    above = int((rows["ci_low"] > 1).sum())
    sides = ""
    if rows["question"].iloc[0] != POISSON_QUESTION and (below or above):
        sides = "; CI " + " and ".join(
            part for part in (f"below 1 in {below}" if below else "",
                              f"above 1 in {above}" if above else "") if part
        ) + f" of {len(rows)} cells"
    if robust:
        return {"question": question, "answer": _ANSWER_WORDS.get(main, main),
                "number": _range(rows) + sides, "robust?": "✓",
                "deciding control": f"none of {n_controls} controls"}
    # the controls that give another verdict than the primary's, the most cells first
    other = rows[(rows["verdict"] != main) & (rows["control"] != "primary")]
    deciding = list(other["control"].value_counts().index) or [
        c for c in dict.fromkeys(rows["depends_on"]) if c]
    crosses = (rows["ci_low"] > 1).any() and (rows["ci_high"] < 1).any()
    number = f"primary {_range(primary)}"
    if deciding:
        number += f"; {deciding[0]} {_range(rows[rows['control'] == deciding[0]])}"
    head = (f"{_ANSWER_WORDS.get(main, main)} under the primary" if len(first) == 1 else
            "under the primary: " + " / ".join(sorted(first)) + " by kick law or family")
    return {"question": question,
            "answer": head + ", not under every control"
                      + ("; CIs on both sides of 1" if crosses else ""),
            "number": number + sides, "robust?": "✗",
            "deciding control": ", ".join(deciding) or "the family"}


def qa_table(table: pd.DataFrame) -> pd.DataFrame:
    """The first screen's questions (`QUESTIONS`, after the Poisson question), each
    answered over every control and family of the findings table: the answer (the verdict
    of `kicktimes.stats.ratio_verdict` or `poisson_verdict`), the number (the range of the
    estimate over every control and family; when not robust, the primary's range and that
    of the control that decides), whether it is robust (`with_robustness`: one verdict and
    one direction under every control) and the controls that change it.

    Columns ``question``, ``answer``, ``number``, ``robust?``, ``deciding control``.
    """
    from kicktimes.report.poisson import HEADLINE_TEST

    out = []
    poisson = table[table["diagnostic"] == f"poisson@{HEADLINE_TEST}"]
    if len(poisson):
        row = _qa_row("Are the two disks' collision times Poisson?", poisson)
        shares = table[(table["diagnostic"] == f"reject@{HEADLINE_TEST}")
                       & (table["control"] == "primary")]
        ds = table[(table["diagnostic"] == "dispersion_index")
                   & (table["control"] == "primary")]
        level = null_level_text(table[table["question"] == POISSON_QUESTION],
                            list(dict.fromkeys(shares["family"])))
        row["number"] = (f"mirror: {_range(shares.assign(estimate=100 * shares['estimate']))}"
                         f" % of runs reject uniformity"
                         + (f" (null streams: {level})" if level else "")
                         + f", D {_range(ds)}")
        elastic = table[table["diagnostic"].isin([f"reject@{HEADLINE_TEST}",
                                                  "dispersion_index"])
                        & (table["control"] == "elastic")]
        if len(elastic) and row["robust?"] == "✓":
            e_share = elastic[elastic["diagnostic"] == f"reject@{HEADLINE_TEST}"]
            e_d = elastic[elastic["diagnostic"] == "dispersion_index"]
            row["deciding control"] += (
                f"; the elastic rule moves it most: "
                f"{_range(e_share.assign(estimate=100 * e_share['estimate']))} %, "
                f"D {_range(e_d)}")
        out.append(row)
    for question, diagnostic, systems in QUESTIONS:
        rows = table[(table["diagnostic"] == diagnostic) & table["system"].isin(systems)]
        if len(rows):
            out.append(_qa_row(question, rows))
    return pd.DataFrame(out, columns=["question", "answer", "number", "robust?",
                                      "deciding control"])


def first_screen(table: pd.DataFrame, shares=None) -> list[str]:
    """The Markdown lines that open a results page: the questions' table (:func:`qa_table`:
    question, answer, number, robust?, deciding control), one sentence on how to read the
    detailed table, that table (:func:`overview_table`: every diagnostic by every kick law)
    and the list of its controls. ``shares`` is accepted for compatibility and unused: the
    Poisson numbers come from the table's rows (the full sentence: :func:`poisson_answer`)."""
    controls = [c for c in dict.fromkeys(table["control"]) if c != "primary"]
    lines = markdown_table(qa_table(table)) + [""]
    lines += ["In detail, each cell: the kicked/two-disk ratio's range over every control "
              "(below the table) and family, ✓ when all agree in verdict and direction, else "
              "the control that changes it, both numbers (↕: crosses 1).", ""]
    lines += markdown_table(overview_table(table))
    kinetic = table[table["system"].isin(["poisson_kinetic", "uniform_kinetic"])]
    missing = [c for c in controls if c not in set(kinetic["control"])] if len(kinetic) else []
    lines += ["", "Controls: " + ", ".join(CONTROL_WORDS.get(c, c) for c in controls)
              + (f"; the kinetic-rate kicks not under {', '.join(missing)}" if missing else "")
              + "."]
    return lines + [""]
