r"""The report of a sweep: findings first, every number computed from the store, every
figure redrawn.

:func:`build_report` loads one or more result stores
(:func:`kicktimes.experiment.load_store`) and writes into ``out_dir`` a self-contained
``report.html`` (figures as base64 PNG, tables as HTML), a PNG and a PDF per figure and a
CSV per table. The page opens with the *Findings*: one statement per question (Poisson?
which renewal model? which model with an MMPP? counts against kinetic theory? each
kicked system against the two-particle system for the FTLE, the off-diagonal recurrence
rate, DET and the autocorrelation), each with its effect size, 95 % confidence interval
and a verdict from a printed rule (:mod:`kicktimes.report.effects`), and a banner when the
store is below paper scale. The paper study's page (``docs/results/README.md``) is written from the
same sections by :func:`kicktimes.studies.paper.write_results`.

One module per section, each holding its computation, figure and text:
:mod:`~kicktimes.report.trajectories` (Poincaré sections, recurrence plot),
:mod:`~kicktimes.report.kick_times`, :mod:`~kicktimes.report.counts`,
:mod:`~kicktimes.report.summary` (generic summaries and the diagnostic-vs-radius figure),
:mod:`~kicktimes.report.lyapunov`, :mod:`~kicktimes.report.recurrence`,
:mod:`~kicktimes.report.autocorrelation`, :mod:`~kicktimes.report.poisson`,
:mod:`~kicktimes.report.renewal`, :mod:`~kicktimes.report.mmpp` (the Markov-modulated
Poisson model against Poisson and the renewal models), :mod:`~kicktimes.report.heterogeneity`,
:mod:`~kicktimes.report.findings` (with :mod:`~kicktimes.report.controls`,
:mod:`~kicktimes.report.answers` and :mod:`~kicktimes.report.decomposition`);
:mod:`~kicktimes.render.pages` holds the generated pages' header and Markdown helpers;
:mod:`~kicktimes.render.html` writes the page and
:mod:`~kicktimes.report.pipeline` runs them. See docs/report.md.
"""

from __future__ import annotations

from kicktimes.report.context import REPORT_DOMAIN
from kicktimes.report.options import Render, Subsampling
from kicktimes.report.pipeline import build_report

__all__ = ["build_report", "REPORT_DOMAIN", "Render", "Subsampling"]
