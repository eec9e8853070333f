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
from kicktimes.stats import format_interval
from kicktimes.validation import check_int

__all__ = ["PROTOCOL_POINTER", "copy_first_screen", "counts_section", "poisson_section",
           "results_sources", "write_results"]

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"


def _md_escape(text):
    return text.replace("|", "\\|").replace("\n", " ")


def poisson_section(table, calibrated=False):
    """The Markdown of the Poisson question under the rule x IC design: one row per test
    (and the headline test on the first collisions, the dispersion index and the one
    standard for "Poisson"), one column per (family, control)."""
    from kicktimes.render.pages import markdown_table
    from kicktimes.report.controls import POISSON_QUESTION
    from kicktimes.stats import poisson_rule

    rows = table[table["question"] == POISSON_QUESTION]
    if rows.empty:
        return []
    cells = {}
    for r in rows.itertuples():
        if r.diagnostic == "dispersion_index":
            cell = f"{format_interval(r.estimate, r.ci_low, r.ci_high)} {r.verdict}"
        else:
            cell = format_interval(100 * r.estimate, 100 * r.ci_low, 100 * r.ci_high,
                                   edges=(2.5, 5.0, 7.5)) + f" % {r.verdict}"
        cells.setdefault(r.diagnostic, {})[f"{_short(r.family)}, {r.control}"] = cell
    frame = pd.DataFrame.from_dict(cells, orient="index").rename_axis("test").reset_index()
    frame["test"] = frame["test"].str.replace("reject@", "", regex=False)
    robust = rows.groupby("diagnostic", sort=False, observed=True)["robust"].all()
    level = ("the share of null streams shaped like the runs (each run's own Poisson "
             "control stream: same rate, window and tests) that the same test rejects, "
             "listed in [null_calibration.csv](null_calibration.csv)" if calibrated
             else "α")
    return [
        "## Are the collision times Poisson? The collision rule as a factor", "",
        "Share of (radius, IC) runs whose two-disk collision times reject each test at "
        "α = 0.05, under the 2 × 2 design collision rule (primary: the paper's mirror rule; "
        "elastic) × initial conditions (the paper's; invariant_ics: the invariant measure), "
        "with 95 % CIs (the headline uniformity test: bootstrap clustered on ICs; the others: "
        "Clopper-Pearson). Each share is read against " + level + " (for the first-"
        "collisions row, α = 0.05) by the rule of `kicktimes.stats.rejection_verdict` with "
        "that level in place of α: nominal: the 95 % CI lies within 50 % of the level; above"
        " / below nominal: entirely above / below that band; inconclusive otherwise. "
        "dispersion_index: the mean over runs of D (variance / mean "
        "of the counts in 10 equal sub-windows; 1 for Poisson), in the ±10 % band. "
        "poisson@…: " + poisson_rule() + ". Robust over the design: "
        + ", ".join(f"{d.replace('reject@', '')} {'✓' if ok else '✗'}"
                    for d, ok in robust.items()) + ".", "",
        *markdown_table(frame), ""]


def gap_section(gaps):
    """The Markdown of the gap decomposition: the shares under the primary setting, the
    sign marks over every control, and how to read them."""
    from kicktimes.render.pages import markdown_table
    from kicktimes.report.decomposition import STEPS, gap_everywhere, gap_summary

    summary = gap_summary(gaps)
    missing = gap_everywhere(gaps)
    short = {STEPS[0]: "deflection", STEPS[1]: "kinetic-rate timing",
             STEPS[2]: "left (kinetic)", STEPS[3]: "deflection (actual-times factorial)",
             STEPS[4]: "actual-times timing", STEPS[5]: "left (actual)"}
    robust_gap = [not missing.get((f, d), "none") for f, d in
                  zip(summary["family"], summary["diagnostic"], strict=True)]
    with_gap = summary[robust_gap]
    shown = with_gap[["family", "diagnostic"]].copy()
    for step in (STEPS[0], STEPS[1], STEPS[4], STEPS[2]):
        if step in with_gap.columns:
            mark = with_gap[f"{step} robust"].replace("—", "")
            shown[short[step]] = (with_gap[step] + " " + mark).str.strip()
    none = summary.loc[[not g for g in robust_gap], ["family", "diagnostic"]]
    controls = ", ".join(c for c in dict.fromkeys(gaps["control"]) if c != "primary")
    return [
        "## Which ingredient of a collision closes the gap?", "",
        "Two 2 × 2 factorials of kicks with the same deflection law (uniform / scatter "
        "kick): the timing switched from Poisson to the kinetic rate of the disk's own "
        "angular momentum (a model of the collision process), and from Poisson to the "
        "two-disk run's actual collision times. Each gives the Shapley shares (both orders "
        "averaged) of the paper's gap |log(kicked / two-disk)| closed by each ingredient, "
        "with 95 % CIs from one bootstrap clustered on ICs, where the gap exists under every "
        "control. 'left' is what the factorial's "
        "best system (scatter kicks at the kinetic rate) still has, one minus the two "
        "shares: no experiment here tests what it is made of. A gap whose CI touches the "
        "±10 % band is not decomposed. The mark checks the sign only: sign ✓ when every "
        f"control ({controls}) puts the share's CI on the same side of 0, with the range "
        "of the estimates over the controls beside it; ✗ names the first control that "
        "does not.", "",
        *markdown_table(shown), "",
        "Not decomposed, because the paper's kick is within the ±10 % band (or its CI on a "
        "band edge) under the named control, so the gap is inside its own noise: "
        + "; ".join(f"{f} {d} ({missing.get((f, d)) or 'primary'})"
                    for f, d in none.itertuples(index=False)) + ".", "",
        "![gap decomposition](gap_decomposition.png)", "",
        "Every control and both factorials' shares: "
        "[gap_decomposition.csv](gap_decomposition.csv).", ""]


def counts_section(table):
    """The Markdown of the collision counts against kinetic theory under every control."""
    from kicktimes.render.pages import markdown_table

    rows = table[table["diagnostic"] == "counts"]
    if rows.empty:
        return []
    frame = pd.DataFrame({
        "family": rows["family"].map(_short), "control": rows["control"],
        "ΣN / ΣΓ(r)T": [format_interval(r.estimate, r.ci_low, r.ci_high)
                        for r in rows.itertuples()],
        "verdict": rows["verdict"]})
    return ["## Do the collision counts follow kinetic theory?", "",
            "Observed two-disk collisions over the kinetic-theory count Γ(r)T (the rule's own "
            "Γ), per family and control, 95 % CI (bootstrap clustered on ICs)."
            + "".join(_counts_reading(rows)), "",
            *markdown_table(frame), ""]


def _counts_reading(rows) -> list[str]:
    """What the counts' controls say, from their verdicts: per family, the primary ratio
    against the ratio with the sticky runs left out (same ICs, same rule)."""
    out = []
    for family, part in rows.groupby("family", sort=False, observed=True):
        by = part.set_index("control")
        if not {"primary", "sticky_excluded"} <= set(by.index):
            continue
        p, k = by.loc["primary"], by.loc["sticky_excluded"]
        text = (f"{_short(family)}: {format_interval(p.estimate, p.ci_low, p.ci_high)} "
                f"({p.verdict}) with every run, "
                f"{format_interval(k.estimate, k.ci_low, k.ci_high)} ({k.verdict}) with the "
                "sticky runs left out")
        if k.verdict.startswith("within") and not p.verdict.startswith("within"):
            text += (": under the mirror rule with the paper's ICs the counts are within 10 % "
                     "of kinetic theory once the sticky runs are left out")
        if "elastic" in by.index:
            e = by.loc["elastic"]
            text += (f"; under the elastic rule {format_interval(e.estimate, e.ci_low, e.ci_high)}"
                     f" ({e.verdict}; its own sticky-excluded control: "
                     "family_*-elastic_findings.csv)")
        out.append(text)
    return [" " + "; ".join(out) + "."] if out else []


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
    "The paper's claims read by its own protocol (its eq. (4) as printed and renormalised, "
    "Fig. 6, RR, R₁) are on [paper.md](paper.md) (`kicktimes reproduce --study protocol`). "
    "Below: kicktimes' tangent-space FTLE and every comparison under its controls.", ""]


def results_sources(findings, families, by_radius, *, gaps, nulls):
    """The closing table of ``README.md``, from what `write_results` wrote there (the names
    depend on the stores): ``<name>_findings.csv`` per name of ``findings`` (those in
    ``families``, ``{family: table}`` of `merge_control_families`, hold every control, and
    the Poisson question where the table has it), ``<name>_findings_by_radius.csv`` per
    name of ``by_radius``, and, when written, ``gap_decomposition.csv`` (``gaps``) and the
    paper study's rows of ``null_calibration.csv`` (``nulls``)."""
    from kicktimes.render.pages import NULL_CALIBRATION
    from kicktimes.render.provenance import Source
    from kicktimes.report.controls import POISSON_QUESTION, compute_controls, poisson_rows
    from kicktimes.report.decomposition import gap_decomposition
    from kicktimes.report.poisson import null_calibration
    from kicktimes.stats import paired_ratio

    rows = []
    for name in findings:
        csv = f"{name}_findings.csv"
        if name not in families:  # not folded: a control experiment's own table
            rows.append(Source(csv, "control, estimate, ci_low, ci_high, verdict",
                               compute_controls))
            continue
        rows.append(Source(csv, "diagnostic, system, control, estimate, ci_low, ci_high, "
                           "verdict, robust, depends_on", compute_controls))
        if (families[name]["question"] == POISSON_QUESTION).any():
            rows.append(Source(csv, "question, diagnostic, estimate, ci_low, ci_high, verdict",
                               poisson_rows))
    rows += [Source(f"{name}_findings_by_radius.csv", "radius, ratio, ci_low, ci_high",
                    paired_ratio) for name in by_radius]
    if gaps:
        rows.append(Source("gap_decomposition.csv", "diagnostic, control, quantity, estimate, "
                           "ci_low, ci_high", gap_decomposition))
    if nulls:
        rows.append(Source(NULL_CALIBRATION, "study, test, share, ci_low, ci_high",
                           null_calibration))
    return rows


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
    from kicktimes.report.answers import ratio_curves_figure
    from kicktimes.report.controls import merge_control_families
    from kicktimes.report.findings import rules_text, scale_statement
    from kicktimes.report.pipeline import CONTROL_STAGES, analyse, n_stages
    from kicktimes.stats import ratio_rule
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
        + ". Every number below is computed from the stores; nothing is typed.",
        "",
    ]
    head = len(lines)
    controls, curves, gaps, control_lines, nulls = [], [], [], [], []
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
                control_lines += [f"- `{name}`: {scale}; its primary rows are the control "
                                  f"`{control}` of {family}'s findings "
                                  f"([{name}_findings.csv]({name}_findings.csv), built in "
                                  f"{time.perf_counter() - t0:.0f} s).", ""]
                continue
            lines += [f"## {name}", ""]
            if not paper:
                lines += [
                    f"> **Below paper scale** ({scale}): a pipeline check; its verdicts answer "
                    "nothing.",
                    "",
                ]
            else:
                lines += [f"Scale: {scale}.", ""]
            controls.append(ctx.found.controls.table)
            curves.append(ctx.found.controls.curves)
            lines += ["### All statements (primary setting)", ""]
            for e in ctx.found.effects:
                lines.append(
                    "- " + _md_escape(e.sentence())
                )
            lines += ["", _md_escape(rules_text(ctx)), ""]
            if notes:
                lines += ["Subsampling: " + " ".join(notes), ""]
            findings.tables[0][1].to_csv(out / f"{name}_findings.csv", index=False)
            written.append(name)
            lines += ["### Figures", ""]
            for sec in secs:
                for fname, fig, caption in sec.figures:
                    file = f"{name}_{fname}.png"
                    fig.savefig(out / file, dpi=dpi)
                    lines += [
                        f"**{sec.title}.** {_md_escape(caption)}",
                        "",
                        f"![{fname}]({file})",
                        "",
                    ]
                sec.figures.clear()
            lines += [
                f"Findings table: [{name}_findings.csv]({name}_findings.csv). Built in "
                f"{time.perf_counter() - t0:.0f} s.",
                "",
            ]
        if len(stores) > 1:
            from kicktimes.report.pipeline import families_section

            families = families_section([st for st in stores
                                         if "-" not in st.experiment.name])
            if families is not None:
                lines += ["## All experiments, the paper's layout", ""]
                for fname, fig, caption in families.figures:
                    fig.savefig(out / f"{fname}.png", dpi=dpi)
                    lines += [_md_escape(caption), "", f"![{fname}]({fname}.png)", ""]
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
    table = pd.concat(list(merged.values()), ignore_index=True)
    screen = ["## The answers", ""] + PROTOCOL_POINTER + first_screen(table)
    curves = pd.concat(curves, ignore_index=True)
    figure = ratio_curves_figure(curves[curves["family"].isin(list(merged))])
    figure.savefig(out / "headline_ratios_vs_radius.png", dpi=dpi)
    screen += [
        "![headline](headline_ratios_vs_radius.png)", "",
        "**The ratio to the two-disk value against r**, one line per kick law, per diagnostic "
        "and family: the ratio of ensemble means per radius (the findings table's "
        "statistic), 95 % CIs from a bootstrap clustered on ICs, one log scale for every "
        "panel with the ±10 % band (grey); recurrence on uniform-time samples; the kick "
        "laws dodged along r so that equal ratios stay visible. The paired median of per-IC "
        "ratios is a control in the findings CSVs.", "",
        "Verdicts (`kicktimes.stats.ratio_verdict`): " + ratio_rule(0.1) + ". Every row "
        "under every control: " + ", ".join(f"[{f}_findings.csv]({f}_findings.csv)"
                                            for f in merged) + ".", ""]
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
    if control_lines:
        screen += ["## The control experiments", ""] + control_lines
    screen += [
        "The mechanism behind these numbers: [science.md](science.md), "
        "[mechanism.md](mechanism.md); escape through a hole: [escape.md](escape.md); "
        "unequal disks: [unequal.md](unequal.md); scatter kicks: [scatter.md](scatter.md); "
        "MMPP fits to the collision times: [mmpp.md](mmpp.md); from two disks to a gas "
        "(N = 2 to 1000 disks): [disks.md](disks.md); the paper's claims by its own "
        "protocol: [paper.md](paper.md). Each is written by its study, `kicktimes reproduce "
        "--study NAME` (`--study all`: every page). Below: per family, the scale, every "
        "statement under the primary setting, and the figures.", ""]
    lines[head:head] = screen
    from kicktimes.render.pages import write_results_page

    return write_results_page(out / "README.md", lines, results_sources(
        written, merged, by_radius, gaps=has_gaps, nulls=bool(nulls)))
