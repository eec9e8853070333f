r"""The paper study's page: figures (PNG) and a generated Markdown findings page,
``README.md``, written from the stores (``docs/results/README.md``).

``kicktimes reproduce --study paper --scale paper --out OUT --results docs/results`` runs
the families and calls :func:`write_results`; every number on the page is computed from
the stores by the same section modules as the HTML report (:mod:`kicktimes.report`).
"""

from __future__ import annotations

import datetime as _dt
import os
import re
import time
from pathlib import Path

import pandas as pd

from kicktimes import __version__
from kicktimes.fileio import atomic_write_bytes
from kicktimes.report.context import Context, Mapper, Progress
from kicktimes.report.store import load_report_store
from kicktimes.stats import format_interval, margin_of
from kicktimes.validation import check_int

__all__ = ["PROTOCOL_POINTER", "copy_first_screen", "counts_section", "poisson_section",
           "results_sources", "write_results"]

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"


def _md_escape(text):
    return text.replace("|", "\\|").replace("\n", " ")


def poisson_section(table, calibrated=False):
    """The Markdown of the Poisson question under the rule x IC design: per family and
    collision rule (the paper's ICs; the invariant-measure ICs are in the findings CSVs),
    the headline test's rejection share against its calibrated level, how many of the
    other tests reject above theirs, D, the first hazard bin and the gamma shape each read
    against the runs' own Poisson control streams (`kicktimes.stats.null_verdict`), and
    the one standard (`kicktimes.stats.poisson_verdict`)."""
    from kicktimes.render.pages import markdown_table
    from kicktimes.report.controls import POISSON_QUESTION, SHAPE_MARGIN
    from kicktimes.report.poisson import HEADLINE_TEST
    from kicktimes.stats import D_MARGIN

    rows = table[table["question"] == POISSON_QUESTION]
    if rows.empty:
        return []
    columns = [(f, c) for f in dict.fromkeys(rows["family"]) for c in ("primary", "elastic")
               if ((rows["family"] == f) & (rows["control"] == c)).any()]
    labels = {"share": f"{HEADLINE_TEST} share (vs its null streams' level)",
              "others": "other tests above their level",
              "dispersion_index_excess": "D − null D (within-run dispersion)",
              "hazard_first_excess": "hazard at t < 0.1 mean intervals − its null",
              "gamma_shape_excess": "gamma shape − its null",
              "standard": "one standard (`poisson_verdict`)"}
    frame = {"": list(labels.values())}
    for family, control in columns:
        part = rows[(rows["family"] == family) & (rows["control"] == control)].set_index(
            "diagnostic")
        head = part.loc[f"reject@{HEADLINE_TEST}"]
        tests = part[part.index.str.startswith("reject@") & ~part.index.str.contains("@first")]
        above = tests.drop(index=f"reject@{HEADLINE_TEST}")["verdict"] == "above nominal"
        cells = [format_interval(100 * head.estimate, 100 * head.ci_low, 100 * head.ci_high,
                                 edges=(2.5, 5.0, 7.5)) + f" % {head.verdict}",
                 f"{int(above.sum())} of {len(above)}"]
        for key in ("dispersion_index_excess", "hazard_first_excess", "gamma_shape_excess"):
            r = part.loc[key] if key in part.index else None
            cells.append("—" if r is None else
                         f"{format_interval(r.estimate, r.ci_low, r.ci_high, edges=())} "
                         f"{r.verdict}")
        standard = part.loc[f"poisson@{HEADLINE_TEST}"] if (
            f"poisson@{HEADLINE_TEST}" in part.index) else None
        cells.append("—" if standard is None else standard.verdict)
        frame[f"{_short(family)}, {control}"] = cells
    level = ("the share of each run's own Poisson control stream (same rate, window and "
             "tests) that the test rejects, [null_calibration.csv](null_calibration.csv)"
             if calibrated else "α")
    return [
        "## Are the collision times Poisson? The collision rule as a factor", "",
        *markdown_table(pd.DataFrame(frame)), "",
        f"A share is read against {level} (`rejection_verdict`: above nominal beyond 1.5 "
        f"times it); the other rows against the same statistic on those streams "
        f"(`null_verdict`, ±{D_MARGIN:g} for D, ±{SHAPE_MARGIN:g} otherwise). Every test and "
        "control: "
        "[family_a_findings.csv](family_a_findings.csv).", ""]


def gap_section(gaps):
    """The Markdown of the gap decomposition: the shares under the primary setting with
    the sign marks over every control, and, where 'left' (what no ingredient closes) has
    an interval containing 1, that nothing here closes that gap."""
    from kicktimes.render.pages import markdown_table
    from kicktimes.report.decomposition import STEPS, gap_everywhere, gap_summary

    summary = gap_summary(gaps)
    missing = gap_everywhere(gaps)
    short = {STEPS[0]: "deflection", STEPS[1]: "kinetic-rate timing",
             STEPS[2]: "left (kinetic)", STEPS[4]: "actual-times timing"}
    robust_gap = [not missing.get((f, d), "none") for f, d in
                  zip(summary["family"], summary["diagnostic"], strict=True)]
    with_gap = summary[robust_gap]
    shown = with_gap[["family", "diagnostic"]].copy()
    for step in (STEPS[0], STEPS[1], STEPS[4], STEPS[2]):
        if step in with_gap.columns:
            mark = with_gap[f"{step} robust"].replace("—", "")
            shown[short[step]] = (with_gap[step] + " " + mark).str.strip()
    open_gaps = _open_gaps(gaps)
    return [
        "## Which ingredient of a collision closes the gap?", "",
        *markdown_table(shown), "",
        "Shapley shares of |log(kicked / two-disk)| closed by the deflection law and by the "
        "timing (two 2 × 2 factorials), 95 % CIs clustered on ICs; sign ✓: the same sign "
        "under every control (their range beside); 'left' = 1 − both shares (a share beyond "
        "[0, 1]: the two factors interact, not add). "
        + (open_gaps + " " if open_gaps else "")
        + "Not decomposed here (no gap beyond the margin under some control; each "
        "control's own shares are in the CSV): "
        + ", ".join(dict.fromkeys(summary.loc[[not g for g in robust_gap], "diagnostic"]))
        + ". Every control: [gap_decomposition.csv](gap_decomposition.csv).", "",
        "![gap decomposition](gap_decomposition.png)", ""]


def _open_gaps(gaps) -> str:
    """The sentence on the gaps the kinetic-rate factorial does not close under the
    primary setting (its 'left' has a CI containing 1), per diagnostic with every family's
    value: where that holds under every control (`decomposition.closes_nothing`) its
    shares are not read; otherwise the range of 'left' over the controls says that some
    control closes part of the gap (or widens it)."""
    from kicktimes.report.decomposition import STEPS, closes_nothing

    left_all = gaps[gaps["quantity"] == STEPS[2]]
    left = left_all[left_all["control"] == "primary"]
    open_ = left[(left["ci_low"] <= 1) & (left["ci_high"] >= 1)]
    if open_.empty:
        return ""
    unread = closes_nothing(gaps)
    parts = []
    for diagnostic, g in open_.groupby("diagnostic", sort=False):
        values = ", ".join(f"{format_interval(r.estimate, r.ci_low, r.ci_high)} "
                           f"({_short(r.family)})" for r in g.itertuples())
        if all((r.family, diagnostic) in unread for r in g.itertuples()):
            parts.append(f"closes none of the {diagnostic} gap under every control (left "
                         f"{values}), so its shares are not read")
            continue
        parts.append(f"closes none of the {diagnostic} gap under the primary only (its "
                     "'left' over the controls beside it)")
    return "The kinetic-rate factorial " + "; it ".join(parts) + "."


def counts_section(table):
    """The Markdown of the collision counts against kinetic theory: per family the primary
    ratio and the one without the sticky runs (every control: the findings CSVs)."""
    rows = table[table["diagnostic"] == "counts"]
    if rows.empty:
        return []
    return ["## Do the collision counts follow kinetic theory?", "",
            "Observed two-disk collisions over the kinetic-theory count Γ(r)T (95 % CIs), at a "
            f"±{100 * margin_of('counts'):g} % margin." + "".join(_counts_reading(rows))
            + " Every control: the findings CSVs.", ""]


def _counts_reading(rows) -> list[str]:
    """What the counts' controls say, from their verdicts: per family, the primary ratio
    against the ratio with the sticky runs left out (same ICs, same rule)."""
    out = []
    for family, part in rows.groupby("family", sort=False, observed=True):
        by = part.set_index("control")
        if not {"primary", "sticky_excluded"} <= set(by.index):
            continue
        p, k = by.loc["primary"], by.loc["sticky_excluded"]

        def said(row):  # at the counts' own margin (`margin_of("counts")`)
            return row.get("verdict_at_margin", row.verdict)

        text = (f"{_short(family)}: {format_interval(p.estimate, p.ci_low, p.ci_high)} "
                f"({said(p)}), without the sticky runs "
                f"{format_interval(k.estimate, k.ci_low, k.ci_high)} ({said(k)})")
        if "elastic" in by.index:
            e = by.loc["elastic"]
            text += (f", elastic {format_interval(e.estimate, e.ci_low, e.ci_high)}"
                     f" ({said(e)})")
        text += _counts_robustness(part)
        out.append(text)
    return [" " + "; ".join(out) + "."] if out else []


def _counts_robustness(part) -> str:
    """``"; not robust (0.982–1.1 over 6 settings, CIs on both sides of 1)"``: what the
    counts' controls say together (`with_robustness`)."""
    x = part["estimate"].astype(float)
    if part["robust"].astype(str).str.lower().eq("true").all():
        return f"; robust ({x.min():.3g}–{x.max():.3g} over {len(part)} settings)"
    sides = (part["ci_low"] > 1).any() and (part["ci_high"] < 1).any()
    return (f"; not robust ({x.min():.3g}–{x.max():.3g} over {len(part)} settings"
            + (", CIs on both sides of 1" if sides else ", the verdict changes") + ")")


def copy_first_screen(page, target):
    """Replace the block between `BEGIN` and `END` of ``target`` (the repository's README)
    by the first screen of the generated ``page`` (its "Generated ..." line, the answers,
    the table and the figure, with links made relative to ``target``; it ends at the next
    ``## `` heading, so never takes the page's closing table of where its numbers come
    from), atomically.

    Raises ``ValueError`` when ``target`` has no such block.
    """
    page, target = Path(page), Path(target)
    lines = page.read_text(encoding="utf-8").splitlines()
    generated = next(line for line in lines if line.startswith("Generated "))
    start = lines.index("## The answers") + 1
    stop = next(k for k in range(start, len(lines)) if lines[k].startswith("## "))
    rel = os.path.relpath(page.parent, target.parent)
    body = [generated, ""] + lines[start:stop]
    body = [re.sub(r"\]\((?!https?:)([^)]+)\)", lambda m: f"]({rel}/{m.group(1)})", line)
            for line in body]
    text = target.read_text(encoding="utf-8")
    if BEGIN not in text or END not in text:
        raise ValueError(f"{target}: no block between {BEGIN} and {END}")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    new = head + BEGIN + "\n" + "\n".join(body).strip() + "\n" + END + tail
    atomic_write_bytes(target, new.encode("utf-8"))


#: the first screen's pointer to the protocol study's page: no number of another study on
#: this page, so the paper study needs no other study (the protocol study reads this one's
#: findings tables, and runs after it)
PROTOCOL_POINTER = [
    "The FTLE is the tangent-space exponent (the paper's variant: the larger of the x- and "
    "y-perturbation exponents). [paper.md](paper.md) reads the paper's claims by its own "
    "protocol, on its own runs."]


def results_sources(findings, families, by_radius, *, gaps, nulls):
    """The closing table of ``README.md``, from what `write_results` wrote there (the names
    depend on the stores): ``<name>_findings.csv`` per name of ``findings`` (those in
    ``families``, ``{family: table}`` of `merge_control_families`, hold every control, and
    the Poisson question where the table has it), ``<name>_findings_by_radius.csv`` per
    name of ``by_radius``, and, when written, ``gap_decomposition.csv`` (``gaps``) and the
    paper study's rows of ``null_calibration.csv`` (``nulls``)."""
    from kicktimes.render.pages import NULL_CALIBRATION
    from kicktimes.render.provenance import Source
    from kicktimes.report.answers import overview_table
    from kicktimes.report.controls import POISSON_QUESTION, compute_controls, poisson_rows
    from kicktimes.report.decomposition import gap_decomposition
    from kicktimes.report.poisson import null_calibration
    from kicktimes.stats import paired_ratio

    rows = [Source("overview.csv", "all", overview_table)]
    for name in findings:
        csv = f"{name}_findings.csv"
        if name not in families:  # a control experiment's own table: folded into its family's
            continue
        rows.append(Source(csv, "diagnostic, system, control, estimate, ci_low, ci_high, "
                           "verdict, robust, depends_on", compute_controls))
        if (families[name]["question"] == POISSON_QUESTION).any():
            rows.append(Source(csv, "question, diagnostic, estimate, ci_low, ci_high, verdict",
                               poisson_rows))
    rows += [Source(f"{name}_findings_by_radius.csv", "radius, ratio, ci_low, ci_high",
                    paired_ratio) for name in by_radius if name in families]
    if gaps:
        rows.append(Source("gap_decomposition.csv", "diagnostic, control, quantity, estimate, "
                           "ci_low, ci_high", gap_decomposition))
    if nulls:
        rows.append(Source(NULL_CALIBRATION, "study, statistic, test, value, ci_low, ci_high",
                           null_calibration))
    return rows


def _family_page(out, name, paper, scale, ctx, secs, notes, *, dpi, seconds, command,
                 table=None) -> str:
    """Write ``out/<name>.md``, the family's detail page: the first screen's answers read
    over this family's controls alone (``table``, its merged findings), its scale, the
    statements under the primary setting (``<name>_statements.csv``: every Effect of the
    sweep report, with its rule and method) and every report figure with its caption;
    returns ``name``."""
    from kicktimes.render.pages import write_results_page
    from kicktimes.render.provenance import Source
    from kicktimes.report.pipeline import analyse
    from kicktimes.studies.paper.first_screen import answer_lines

    statements = pd.DataFrame([{
        "question": e.question, "system": e.system, "quantity": e.quantity,
        "estimate": e.estimate, "ci_low": e.ci_low, "ci_high": e.ci_high,
        "verdict": e.verdict, "statement": e.statement, "rule": e.rule, "method": e.method,
        "detail": e.detail} for e in ctx.found.effects])
    statements.to_csv(out / f"{name}_statements.csv", index=False)
    lines = [f"# {name}: its statements and figures (generated)", "",
             f"Generated {_dt.datetime.now(_dt.UTC).isoformat(timespec='seconds')} by "
             f"kicktimes {__version__} (`{command}`) from the store `{name}` in "
             f"{seconds:.0f} s. The answers, read over every control: [README.md](README.md).",
             ""]
    if table is not None and len(table):
        lines += ["Its answers, over its own controls:", "", *answer_lines(table), ""]
    lines += ([f"> **Below paper scale** ({scale}): a pipeline check; its verdicts answer "
               "nothing.", ""] if not paper else [f"Scale: {scale}.", ""])
    lines += [f"Every statement under the primary setting, with its rule and interval: "
              f"[{name}_statements.csv]({name}_statements.csv); every ratio under every "
              f"control: [{name}_findings.csv]({name}_findings.csv)."
              + (" Subsampling: " + " ".join(notes) if notes else ""), "", "## Figures", ""]
    for sec in secs:
        for fname, fig, caption in sec.figures:
            file = f"{name}_{fname}.png"
            fig.savefig(out / file, dpi=dpi)
            lines += [f"**{sec.title}.** {_md_escape(caption)}", "", f"![{fname}]({file})", ""]
        sec.figures.clear()
    write_results_page(out / f"{name}.md", lines, [
        Source(f"{name}_statements.csv", "statement, estimate, ci_low, ci_high, verdict",
               analyse)])
    return name


def _short(family):
    return {"family_a": "A", "family_b": "B"}.get(family, family)


def write_results(
    store_paths, out_dir, *, dpi=110, workers=1, n_mc=199, n_boot=2000, max_ics_model_fits=12,
    command="kicktimes reproduce --study paper --scale paper --results docs/results",
) -> Path:
    r"""Write every report figure as PNG and a findings page ``README.md`` into ``out_dir``.

    Parameters
    ----------
    store_paths : path-like or sequence of path-like
        Result stores (e.g. the paper's ``family_a`` and ``family_b``).
    out_dir : path-like
        Output folder (created; files of the same names are replaced).
    dpi : int
        Resolution of the PNG files.
    workers, n_mc, n_boot, max_ics_model_fits : int
        As in :func:`kicktimes.report.build_report`.
    command : str
        The command the page's "Generated" line names.

    Returns
    -------
    pathlib.Path
        ``out_dir / "README.md"``: per store the scale (with a banner below paper scale),
        the Findings statements with effect sizes, CIs and verdicts, the verdict rules,
        and every figure with its caption; last, the table of where its numbers come from
        (`results_sources`).

    Examples
    --------
    >>> from kicktimes.studies.paper import write_results
    >>> write_results("stores/family_a", "docs/results")  # doctest: +SKIP
    """
    from kicktimes.report.answers import overview_table, ratio_curves_figure
    from kicktimes.report.controls import merge_control_families
    from kicktimes.report.findings import scale_statement
    from kicktimes.report.pipeline import CONTROL_STAGES, analyse, n_stages
    from kicktimes.studies.paper.first_screen import first_screen

    paths = [store_paths] if isinstance(store_paths, str | os.PathLike) else list(store_paths)
    if not paths or not all(isinstance(p, str | os.PathLike) for p in paths):
        raise TypeError("store_paths must be a path or a non-empty sequence of paths")
    if not isinstance(out_dir, str | os.PathLike):
        raise TypeError(f"out_dir must be a path, got {type(out_dir).__name__}")
    dpi = check_int("dpi", dpi, low=30)
    workers = check_int("workers", workers, low=1)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stores = [load_report_store(p) for p in paths]
    pool = Mapper(workers)
    bar = Progress(False, n_stages() * len(stores))
    lines = [
        "# What the reproduction shows (generated)",
        "",
        f"Generated {_dt.datetime.now(_dt.UTC).isoformat(timespec='seconds')} by "
        f"kicktimes {__version__} (`{command}`) from the stores "
        + ", ".join(f"`{st.experiment.name}`" for st in stores)
        + ".",
        "",
    ]
    head = len(lines)
    controls, curves, gaps, control_lines, nulls = [], [], [], [], []
    details, family_figures = [], []  # the families' detail pages, the shared figures
    written = []  # the experiments whose <name>_findings.csv is written
    names = {st.experiment.name for st in stores}
    try:
        for st in stores:
            t0 = time.perf_counter()
            ctx = Context(
                st,
                n_mc=check_int("n_mc", n_mc, low=19),
                n_boot=check_int("n_boot", n_boot, low=100),
                max_ics_model_fits=check_int("max_ics_model_fits", max_ics_model_fits, low=1),
                pmap=pool.map,
            )
            name = st.experiment.name
            family, _, control = name.partition("-")
            is_control = bool(control) and family in names
            # a control experiment contributes rows to its family's table: its Poisson
            # tests and findings are all it needs
            findings, secs, notes = analyse(ctx, bar=bar, timings=[],
                                            only=CONTROL_STAGES if is_control else None)
            paper, scale = scale_statement(st)
            if ctx.found.null_calibration is not None and len(ctx.found.null_calibration):
                nulls.append(ctx.found.null_calibration)
            if ctx.found.gaps is not None and not ctx.found.gaps.empty:
                gaps.append(ctx.found.gaps)
            if is_control:
                controls.append(ctx.found.controls.table)
                curves.append(ctx.found.controls.curves)
                findings.tables[0][1].to_csv(out / f"{name}_findings.csv", index=False)
                written.append(name)
                control_lines.append(name)
                continue
            controls.append(ctx.found.controls.table)
            curves.append(ctx.found.controls.curves)
            findings.tables[0][1].to_csv(out / f"{name}_findings.csv", index=False)
            written.append(name)
            details.append((name, paper, scale, ctx, secs, notes, time.perf_counter() - t0))
        if len(stores) > 1:
            from kicktimes.report.pipeline import families_section

            families = families_section([st for st in stores
                                         if "-" not in st.experiment.name])
            if families is not None:
                for fname, fig, caption in families.figures:
                    fig.savefig(out / f"{fname}.png", dpi=dpi)
                    family_figures.append((fname, _md_escape(caption)))
    finally:
        pool.close()
    import pandas as pd

    from kicktimes.report.decomposition import gap_figure, merge_control_gaps

    # control experiments ("<family>-<control>") become rows of their family's table
    merged = merge_control_families(controls)
    for family, t in merged.items():
        t.to_csv(out / f"{family}_findings.csv", index=False)
    by_radius = {c["family"].iloc[0]: c for c in curves if not c.empty}
    for name, c in by_radius.items():
        c.to_csv(out / f"{name}_findings_by_radius.csv", index=False)
    details_args = list(details)
    details = [_family_page(out, name, paper, scale, ctx, secs, notes, dpi=dpi,
                            seconds=seconds, command=command,
                            table=merged.get(name))
               for name, paper, scale, ctx, secs, notes, seconds in details]
    table = pd.concat(list(merged.values()), ignore_index=True)
    overview_table(table).to_csv(out / "overview.csv", index=False)
    screen = ["## The answers", ""] + first_screen(table)
    curves = pd.concat(curves, ignore_index=True)
    figure = ratio_curves_figure(curves[curves["family"].isin(list(merged))])
    figure.savefig(out / "headline_ratios_vs_radius.png", dpi=dpi)
    screen += [
        "![headline](headline_ratios_vs_radius.png)", "",
        "Kicked / two-disk ratio of ensemble means against r (95 % CIs clustered on ICs; "
        "grey: the diagnostic's band). "
        "Verdicts (`ratio_verdict` at `margin_of`) and robustness: "
        "[definitions](../definitions.md#margins-and-nulls). "
        + PROTOCOL_POINTER[0], ""]
    if nulls:
        from kicktimes.render.pages import write_null_calibration

        write_null_calibration(out, "paper", pd.concat(nulls, ignore_index=True))
    screen += poisson_section(table, calibrated=bool(nulls))
    has_gaps = bool(gaps)
    if has_gaps:
        gaps = merge_control_gaps(gaps)
        gaps = gaps[gaps["family"].isin(list(merged))]
        gaps.to_csv(out / "gap_decomposition.csv", index=False)
        gap_figure(gaps).savefig(out / "gap_decomposition.png", dpi=dpi)
        screen += gap_section(gaps)
    screen += counts_section(table)
    screen += ["## More", "",
               "Per family: "
               + ", ".join(f"[{d}.md]({d}.md)" for d in details)
               + "".join(f" ([both families]({f}.png))" for f, _ in family_figures)
               + ". The other studies: " + _other_studies() + ".", ""]
    below = [f"{name}: {scale}" for name, paper, scale, *_ in details_args if not paper]
    if below:  # the page's answers stand on stores below the paper's scale: it says so first
        screen = [f"> **Below paper scale** ({'; '.join(below)}): a pipeline check; its "
                  "verdicts answer nothing.", ""] + screen
    lines[head:head] = screen
    from kicktimes.render.pages import write_results_page

    return write_results_page(out / "README.md", lines, results_sources(
        written, merged, by_radius, gaps=has_gaps, nulls=bool(nulls)))


def _other_studies() -> str:
    """Links to every other study's page, in `kicktimes.studies.STUDIES` order, the
    protocol study's paper.md last."""
    from kicktimes.studies import STUDIES

    pages = [s.page for s in STUDIES.values() if s.name not in ("paper", "protocol")]
    return ", ".join(f"[{p}]({p})" for p in [*pages, STUDIES["protocol"].page])
