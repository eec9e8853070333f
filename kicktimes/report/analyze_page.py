"""The page of ``kicktimes analyze``: findings first, then the report's own sections.

:func:`write_analysis` turns an :class:`kicktimes.stats.Analysis` into ``report.html``
(self-contained, written by :func:`kicktimes.render.html.write_page` as the sweep report
is), ``findings.md``, one PNG + PDF per figure and one CSV per table. The figures are the
sweep report's (Poisson rejection rates, renewal-model comparison, rate heterogeneity),
drawn against the sequences' group where the report draws against the disk radius (their
``x`` and ``xlabel`` arguments): numeric groups at their values, the single group
``"all"`` of an analysis without ``group`` as one labelled position. With an MMPP table
(`kicktimes.report.mmpp_analysis.analyze_mmpp`, ``kicktimes analyze --mmpp``) the page
adds the finding "Clustered (MMPP-2)?" and the section of the MMPP-2 fits.
"""

from __future__ import annotations

import html
import os
import warnings
from pathlib import Path

from kicktimes.render.html import toc_item, write_outputs, write_page, write_table, write_text
from kicktimes.report.context import Section
from kicktimes.report.heterogeneity import rate_heterogeneity
from kicktimes.report.poisson import poisson_rejection_rates
from kicktimes.report.renewal import model_comparison
from kicktimes.stats.findings import findings_table

__all__ = ["write_analysis"]


def _findings_section(fs):
    sec = Section("findings", "Findings")
    sec.bullets(f"{f.question} — {f.verdict}. {f.statement} (Rule: {f.rule})" for f in fs)
    sec.table("findings", findings_table(fs), "Findings", show=False)
    return sec


def _data_section(res):
    sec = Section("data", "The sequences")
    seq = res.tables()["sequences"]
    sec.text(
        "One row per sequence: window, number of events, rate, covariates, the p-value of "
        "each Poisson test, FDR decision and AIC-best renewal model. Event times are "
        "shifted to t - t_start; the first event time (a forward recurrence time) is left "
        "out of the intervals and the time from the last event to t_end is right-censored."
    )
    sec.table("sequences", seq, "Sequences", show=len(seq) <= 40)
    if len(res.skipped):
        sec.table(
            "skipped", res.skipped, "Skipped sequences and steps", show=len(res.skipped) <= 40
        )
    return sec


def _poisson_section(res, axis):
    sec = Section("poisson_tests", "Poisson tests of the event times, per sequence")
    if (res.poisson["n_tested"] > 0).any():
        sec.figure(
            "poisson_rejection_rates",
            poisson_rejection_rates(res.poisson, alpha=res.alpha, **axis),
            f"Share of sequences rejecting a homogeneous Poisson process at α = {res.alpha:g}, "
            f"per test and {axis['xlabel']}, with 95 % Clopper-Pearson intervals (each test "
            f"conditional on the sequence's own count; Monte Carlo nulls, n_mc = {res.n_mc}).",
        )
    sec.table("poisson_tests", res.poisson, "Rejections per group and test")
    return sec


def _renewal_section(res, axis):
    sec = Section("renewal", "Renewal-model comparison of the intervals")
    per = res.sequences.dropna(subset=["best_model"])[["group", "best_model"]]
    if len(per) or len(res.renewal_pooled):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fig = model_comparison(per, res.renewal_pooled, **axis)
        sec.figure(
            "renewal_model_comparison",
            fig,
            "(a) Per sequence: share of sequences for which each renewal model has the lowest "
            "AIC; (b) intervals pooled per group: ΔAIC of each model (0 = best).",
        )
    sec.table("renewal_pooled", res.renewal_pooled, "Pooled intervals: model comparison")
    sec.table("renewal_per_sequence", res.renewal_per_sequence, "Per sequence", show=False)
    return sec


def _heterogeneity_section(res, axis):
    sec = Section("heterogeneity", "Rate heterogeneity across sequences")
    counts = res.sequences[["group", "n_events", "t_window"]].rename(columns={"n_events": "n_pp"})
    sec.figure(
        "rate_heterogeneity",
        rate_heterogeneity(counts, homogeneity=res.heterogeneity, rule=None, **axis),
        "(a) Event rate n / t_window of every sequence with the pooled and median rates per "
        f"{axis['xlabel']}; (b) index of dispersion of the counts across the sequences of a "
        "group, annotated with the p-value of the Pearson test of a common rate (given the "
        "total).",
    )
    sec.table("rate_homogeneity", res.heterogeneity, "Rate homogeneity per group")
    if res.reference is not None:
        sec.table("reference_rate", res.reference, f"Observed / {res.reference_column}")
    return sec


def _mmpp_section(res, table, axis):
    from kicktimes.report.mmpp import MIN_EVENTS, mmpp_comparison

    sec = Section("mmpp", "Clustered events: a Markov-modulated Poisson model (MMPP-2)")
    sec.text(
        "A two-state Markov-modulated Poisson process: a hidden Markov chain switches the "
        "event rate between a low and a high value, so events cluster and successive "
        "intervals are correlated (no renewal model allows that). Per sequence with "
        f"{MIN_EVENTS} or more events: the likelihood-ratio test of the MMPP-2 against "
        "Poisson, calibrated by a parametric bootstrap (kicktimes.stats.mmpp_lr_test; the "
        "χ² reference fails where the two rates coincide), and the MMPP-2's AIC on the "
        "renewal fits' likelihood (the events after the first, given it), set against the "
        "sequence's Poisson and renewal AICs. Rates and switching rates are the "
        "full-likelihood fit's (stationary start)."
    )
    ok = table.dropna(subset=["mmpp_aic"])
    if len(ok):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fig = mmpp_comparison(ok, alpha=res.alpha, **axis)
        sec.figure(
            "mmpp_comparison",
            fig,
            f"(a) Per {axis['xlabel']}: share of tested sequences whose AIC-best model "
            "(Poisson, renewal models, MMPP-2) is the MMPP-2, where the MMPP-2 beats Poisson "
            f"by AIC, and where the bootstrap LR test rejects Poisson at α = {res.alpha:g}, "
            "with 95 % Clopper-Pearson intervals. (b) Fitted low and high rates over the "
            "sequence's rate n/T; (c) mean time in each state (1/q) in mean intervals T/n; "
            "medians and quartiles over the sequences where the MMPP-2 beats Poisson.",
        )
    else:
        sec.text(f"No sequence has {MIN_EVENTS} or more events: no MMPP-2 fit.")
    sec.table("mmpp_per_sequence", table, "MMPP-2 per sequence", show=len(table) <= 40)
    return sec


def _counts_section(res):
    sec = Section("counts", "Counts against the covariates")
    sec.text(
        "One covariate at a time: Poisson GLM and negative binomial (NB2) of the counts with "
        "offset log(t_window) on log x (all x > 0; the slope is the exponent b of "
        "rate ∝ x^b) or on x, and the OLS line of the pooled rate per covariate value."
    )
    sec.table("count_regressions", res.regressions, "Coefficients (95 % intervals)")
    sec.table("count_overdispersion", res.overdispersion, "Over-dispersion")
    return sec


def write_analysis(res, out_dir, *, dpi=150, sources=None, windows=None, mmpp=None) -> Path:
    """Write the report of an analysis: HTML, findings.md, figures and CSV tables.

    Parameters
    ----------
    res : kicktimes.stats.Analysis
        The result of :func:`kicktimes.stats.analyze`.
    out_dir : path-like
        Output folder (created).
    dpi : int, optional
        Resolution of the PNG files.
    sources, windows : optional
        The input files, named in the page header.
    mmpp : pandas.DataFrame, optional
        `kicktimes.report.mmpp_analysis.analyze_mmpp` of ``res``: adds its finding and
        section.

    Returns
    -------
    pathlib.Path
        ``out_dir / "report.html"``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fs = res.findings()
    if mmpp is not None:
        from kicktimes.report.mmpp_analysis import mmpp_finding

        fs.insert(3, mmpp_finding(res, mmpp))  # after "Which renewal model?"
    # the figures' x axis: the group, named as the analysis names it
    axis = {"x": "group", "xlabel": res.group or "group"}
    secs = [
        _findings_section(fs),
        _data_section(res),
        _poisson_section(res, axis),
        _renewal_section(res, axis),
        *([_mmpp_section(res, mmpp, axis)] if mmpp is not None else []),
        _heterogeneity_section(res, axis),
        _counts_section(res),
    ]
    files = {}
    in_sections = {name for sec in secs for name, *_ in sec.tables}
    for name, df in res.tables().items():
        if name not in in_sections:
            write_table(out, name, df, files)
    md = ["# Findings", ""]
    md += [f"- **{f.question}** {f.verdict}. {f.statement} _Rule: {f.rule}_" for f in fs]
    write_text(out, "findings.md", "\n".join(md) + "\n", files)
    lead = write_outputs(secs[:1], out, dpi, files=files)
    body = write_outputs(secs[1:], out, dpi, files=files)

    def shown(path):
        return html.escape(os.path.relpath(Path(path).resolve(), out.resolve()))

    inputs = ", ".join(shown(s) for s in (sources or [])) or "a DataFrame"
    if windows is not None:
        inputs += f"; windows from {shown(windows)}"
    return write_page(
        out,
        "kicktimes analyze",
        sources=f"{inputs}: {len(res.sequences)} sequences, "
        f"{int(res.sequences['n_events'].sum())} events, α = {res.alpha:g}, n_mc = {res.n_mc}",
        toc=[toc_item(s.key, s.title) for s in secs],
        lead=lead,
        body=body,
        files=files,
    )
