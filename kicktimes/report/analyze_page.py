"""The pages of ``kicktimes analyze``: findings first, then the report's own sections.

:func:`write_analysis` turns an :class:`kicktimes.stats.Analysis` into ``report.html``
(self-contained), ``findings.md``, one PNG + PDF per figure and one CSV per table. The
figures are the sweep report's (Poisson rejection rates, renewal-model comparison, rate
heterogeneity); where they draw against the disk radius, the sequences' group takes its
place: groups are mapped affinely into the radius range the figures accept and the x
axis is relabelled with the group's own values and name, so the geometry is that of the
group values (see :func:`_as_radius`).
"""

from __future__ import annotations

import datetime as _dt
import html
import os
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.ticker import FixedFormatter, FixedLocator, FuncFormatter

from kicktimes import __version__

__all__ = ["write_analysis"]


def _report_api():
    """The report's section record, figure functions and HTML writer."""
    from types import SimpleNamespace

    from kicktimes.report import heterogeneity, poisson, renewal
    from kicktimes.report.common import Section
    from kicktimes.report.figures import RADIUS_LABEL
    from kicktimes.report.html import CSS, write_outputs

    figures = SimpleNamespace(
        RADIUS_LABEL=RADIUS_LABEL,
        poisson_rejection_rates=poisson.poisson_rejection_rates,
        model_comparison=renewal.model_comparison,
        rate_heterogeneity=heterogeneity.rate_heterogeneity,
    )
    return Section, figures, write_outputs, CSS


def _as_radius(groups):
    """Map group values into (0, 0.5) for the radius-axis figures; return the map and a
    function that relabels an Axes' x axis with the group values.

    Numeric groups: ``x' = a + c x`` (spacing kept, ticks show ``x``); others: evenly
    spaced positions with the labels as fixed ticks.
    """
    values = list(dict.fromkeys(groups))
    try:
        x = np.asarray(values, dtype=float)
        numeric = bool(np.isfinite(x).all())
    except (TypeError, ValueError):
        numeric = False
    if numeric and x.size > 1 and np.ptp(x) > 0:
        c = 0.4 / np.ptp(x)
        a = 0.05 - c * x.min()
        mapping = {v: a + c * float(v) for v in values}

        def relabel(ax, name):
            ax.xaxis.set_major_formatter(FuncFormatter(lambda u, _: f"{(u - a) / c:.4g}"))
            ax.set_xlabel(name)

    else:
        pos = np.linspace(0.1, 0.4, len(values)) if len(values) > 1 else np.array([0.25])
        mapping = dict(zip(values, pos.tolist(), strict=True))

        def relabel(ax, name):
            ax.xaxis.set_major_locator(FixedLocator(pos))
            ax.xaxis.set_major_formatter(FixedFormatter([str(v) for v in values]))
            ax.set_xlabel(name)

    return mapping, relabel


def _relabel_figure(fig, relabel, name, radius_label):
    for ax in fig.axes:
        label = ax.get_xlabel()
        if label in (radius_label, ""):
            relabel(ax, name if label else "")


def _sections(res, Section, plots):
    secs = []
    group_name = res.group or "group"
    mapping, relabel = _as_radius(res.sequences["group"])
    radius_label = getattr(plots, "RADIUS_LABEL", "")

    def radius(df):
        out = df.copy()
        out["radius"] = out["group"].map(mapping)
        return out

    # ---- findings first
    fs = res.findings()
    sec = Section("findings", "Findings")
    sec.bullets(f"{f.question} — {f.verdict}. {f.statement} (Rule: {f.rule})" for f in fs)
    table = pd.DataFrame([f.__dict__ for f in fs])
    sec.table("findings", table, "Findings", show=False)
    secs.append(sec)

    # ---- data
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
    secs.append(sec)

    # ---- Poisson tests
    sec = Section("poisson_tests", "Poisson tests of the event times, per sequence")
    rej = radius(res.poisson)
    if (rej["n_tested"] > 0).any():
        fig = plots.poisson_rejection_rates(rej, alpha=res.alpha)
        _relabel_figure(fig, relabel, group_name, radius_label)
        sec.figure(
            "poisson_rejection_rates",
            fig,
            f"Share of sequences rejecting a homogeneous Poisson process at α = {res.alpha:g}, "
            f"per test and {group_name}, with 95 % Clopper-Pearson intervals (each test "
            f"conditional on the sequence's own count; Monte Carlo nulls, n_mc = {res.n_mc}).",
        )
    sec.table("poisson_tests", res.poisson, "Rejections per group and test")
    secs.append(sec)

    # ---- renewal models
    sec = Section("renewal", "Renewal-model comparison of the intervals")
    per = radius(res.sequences.dropna(subset=["best_model"])[["group", "best_model"]])
    pooled = radius(res.renewal_pooled)
    if len(per) or len(pooled):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fig = plots.model_comparison(per, pooled)
        _relabel_figure(fig, relabel, group_name, radius_label)
        sec.figure(
            "renewal_model_comparison",
            fig,
            "(a) Per sequence: share of sequences for which each renewal model has the lowest "
            "AIC; (b) intervals pooled per group: ΔAIC of each model (0 = best).",
        )
    sec.table("renewal_pooled", res.renewal_pooled, "Pooled intervals: model comparison")
    sec.table("renewal_per_sequence", res.renewal_per_sequence, "Per sequence", show=False)
    secs.append(sec)

    # ---- heterogeneity
    sec = Section("heterogeneity", "Rate heterogeneity across sequences")
    coll = radius(res.sequences[["group", "n_events", "t_window"]]).rename(
        columns={"n_events": "n_pp"}
    )
    hom = radius(res.heterogeneity)
    fig = plots.rate_heterogeneity(coll, homogeneity=hom, rule=None)
    _relabel_figure(fig, relabel, group_name, radius_label)
    sec.figure(
        "rate_heterogeneity",
        fig,
        "(a) Event rate n / t_window of every sequence with the pooled and median rates per "
        f"{group_name}; (b) index of dispersion of the counts across the sequences of a group, "
        "annotated with the p-value of the Pearson test of a common rate (given the total).",
    )
    sec.table("rate_homogeneity", res.heterogeneity, "Rate homogeneity per group")
    if res.reference is not None:
        sec.table("reference_rate", res.reference, f"Observed / {res.reference_column}")
    secs.append(sec)

    # ---- counts
    sec = Section("counts", "Counts against the covariates")
    sec.text(
        "One covariate at a time: Poisson GLM and negative binomial (NB2) of the counts with "
        "offset log(t_window) on log x (all x > 0; the slope is the exponent b of "
        "rate ∝ x^b) or on x, and the OLS line of the pooled rate per covariate value."
    )
    sec.table("count_regressions", res.regressions, "Coefficients (95 % intervals)")
    sec.table("count_overdispersion", res.overdispersion, "Over-dispersion")
    secs.append(sec)
    return secs, fs


def write_analysis(res, out_dir, *, dpi=150, sources=None, windows=None) -> Path:
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

    Returns
    -------
    pathlib.Path
        ``out_dir / "report.html"``.
    """
    Section, plots, write_outputs, css = _report_api()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    secs, fs = _sections(res, Section, plots)
    for name, df in res.tables().items():
        df.to_csv(out / f"{name}.csv", index=False)
    md = ["# Findings", ""]
    md += [f"- **{f.question}** {f.verdict}. {f.statement} _Rule: {f.rule}_" for f in fs]
    (out / "findings.md").write_text("\n".join(md) + "\n", encoding="utf-8")
    body = write_outputs(secs, out, dpi)
    inputs = ", ".join(html.escape(os.fspath(s)) for s in (sources or [])) or "a DataFrame"
    if windows is not None:
        inputs += f"; windows from {html.escape(os.fspath(windows))}"
    toc = "".join(f'<li><a href="#{s.key}">{html.escape(s.title)}</a></li>' for s in secs)
    page = (
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
        f"<title>kicktimes analyze</title><style>{css}</style></head><body>"
        f"<h1>kicktimes analyze</h1><p>Built "
        f"{_dt.datetime.now(_dt.timezone.utc).isoformat(timespec='seconds')} with kicktimes "
        f"{html.escape(__version__)} from {inputs}: {len(res.sequences)} sequences, "
        f"{int(res.sequences['n_events'].sum())} events, α = {res.alpha:g}, "
        f"n_mc = {res.n_mc}.</p><h2>Contents</h2><ul>{toc}</ul>{body}</body></html>"
    )
    path = out / "report.html"
    path.write_text(page, encoding="utf-8")
    return path
