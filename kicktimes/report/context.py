"""What every section of the sweep report sees while it is built: the section record
(:class:`Section`), the build context of one store (:class:`Context`, with the typed
results the sections leave for later ones, :class:`Found`), the progress reporting and
the process pool (:class:`Mapper`), and the report's seeded Monte Carlo streams."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from kicktimes.memory import keep_freed_memory

if TYPE_CHECKING:  # pandas and scipy load with the sections that use them
    import pandas as pd

__all__ = ["Context", "Found", "Mapper", "Progress", "REPORT_DOMAIN", "Section",
           "seeded_rng"]

#: first spawn-key word of the report's Monte Carlo streams ("rprt"), distinct from the
#: IC and kick streams of the sweep
REPORT_DOMAIN = 0x72707274


class Section:
    """One part of the report: title, computed text, figures and tables."""

    def __init__(self, key, title, *, answers_first=False):
        self.key, self.title = key, title
        #: the page shows this section's text up to its `fold` (or its first list), then
        #: its shown tables, then its figures, then the rest (a section that opens with its
        #: answers); otherwise figures, text, tables
        self.answers_first = answers_first
        self.blocks: list[tuple[str, object]] = []  # ("p" | "banner", str), ("ul", [str])
        self.figures: list[tuple[str, object, str]] = []  # (name, Figure, caption)
        self.tables: list[tuple[str, pd.DataFrame, str, bool]] = []  # (name, df, title, html)

    @property
    def paragraphs(self):
        return [b for kind, b in self.blocks if kind == "p"]

    def text(self, paragraph):
        self.blocks.append(("p", paragraph))

    def banner(self, paragraph):
        self.blocks.append(("banner", paragraph))

    def bullets(self, items):
        self.blocks.append(("ul", list(items)))

    def fold(self):
        """Where an ``answers_first`` section's opening text ends."""
        self.blocks.append(("fold", None))

    def figure(self, name, fig, caption):
        self.figures.append((name, fig, caption))

    def table(self, name, df, title, *, show=True):
        self.tables.append((name, df, title, show))


@dataclass
class Found:
    """What the sections compute for later sections and for the Findings, typed.

    Each attribute is set by the section named beside it and read after it (the page's
    stage order, `kicktimes.report.pipeline`); None until then.
    """

    summary: object = None  # summary: the diagnostics' summary table
    count_regression: object = None  # counts: the regressions of counts on the radius
    sticky: object = None  # counts: per (radius, IC) rate and the sticky flag
    recurrence_rows: object = None  # recurrence: the rows behind the RR figures
    rejections: object = None  # poisson: rejections per radius and test
    homogeneity: object = None  # poisson: rate-homogeneity tests per radius
    poisson_per_ic: object = None  # poisson: per-IC p-values of the headline test
    null_calibration: object = None  # poisson: the Poisson control streams through the tests
    null_referenced: object = None  # poisson: D, hazard, gamma shape against the controls'
    poisson_cis: object = None  # poisson: the headline shares' clustered CIs, by column
    renewal_best: object = None  # renewal: the AIC-best model of every fitted IC
    renewal_pooled: object = None  # renewal: the comparison of pooled intervals
    mmpp: object = None  # mmpp: the MMPP-2 against Poisson and renewal, per fitted IC
    effects: list = field(default_factory=list)  # findings: the statements
    controls: object = None  # findings: `kicktimes.report.controls.Controls`
    gaps: object = None  # findings: the gap decomposition (`report.decomposition`)


@dataclass
class Context:
    """What every section of one store sees: the store, the options, the pool and the
    place where sections leave results for later ones (``found``) and subsampling notes."""

    store: object
    alpha: float = 0.05
    n_mc: int = 199
    n_boot: int = 2000
    tolerance: float = 0.1
    max_ics_tests: int | None = None
    max_ics_model_fits: int = 12
    max_pooled_intervals: int = 200_000
    #: where the escape section's tail fits start (None: `report.escape.T_MIN_FRACTION` of
    #: the horizon)
    escape_t_min: float | None = None
    pmap: object = map
    #: ``pstart(fn, jobs)`` starts ``fn`` over ``jobs`` now and returns a callable giving
    #: the results later (:meth:`Mapper.start`); None: the sections use ``pmap``
    pstart: object = None
    #: results of jobs started ahead of their section (see :func:`start_ahead`)
    pending: dict = field(default_factory=dict)
    #: the bootstrap resamples of the ICs shared by every ratio of the Findings
    #: (`kicktimes.stats.paired_ratio`'s ``resamples``, drawn from ``boot_rng()``)
    resamples: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    found: Found = field(default_factory=Found)

    @property
    def exp(self):
        return self.store.experiment

    @property
    def results(self):
        return self.store.results

    def rng(self, *key):
        return seeded_rng(self.exp.seed, *key)

    def boot_rng(self):
        """The stream of the Findings' shared bootstrap resamples (``resamples``)."""
        return self.rng(3)


class Progress:
    """Stage reporting: a tqdm bar, a callable ``progress(stage, done, total)``, or nothing."""

    def __init__(self, progress, total):
        self.total, self.done, self.bar, self.call = total, 0, None, None
        if callable(progress):
            self.call = progress
        elif progress is None or isinstance(progress, bool):
            show = (
                progress
                if progress is not None
                else (sys.stderr.isatty() and not os.environ.get("CI"))
            )
            if show:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, desc="report", unit="stage")
        else:
            raise TypeError(
                f"progress must be None, a bool or a callable(stage, done, total), got "
                f"{type(progress).__name__}"
            )

    def step(self, stage):
        if self.bar is not None:
            self.bar.set_postfix_str(stage)
        if self.call is not None:
            self.call(stage, self.done, self.total)

    def advance(self):
        self.done += 1
        if self.bar is not None:
            self.bar.update(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


class Mapper:
    """``map`` in this process, or on a process pool started at first use."""

    def __init__(self, workers):
        self.workers, self.pool = workers, None

    def _pool(self):
        if self.pool is None:
            from concurrent.futures import ProcessPoolExecutor

            self.pool = ProcessPoolExecutor(
                max_workers=self.workers, initializer=keep_freed_memory
            )
        return self.pool

    def map(self, fn, jobs):
        jobs = list(jobs)
        if self.workers == 1 or len(jobs) < 2:
            return [fn(job) for job in jobs]
        return list(self._pool().map(fn, jobs))

    def start(self, fn, jobs):
        """Start ``fn`` over ``jobs`` on the pool now (in this process: when collected);
        return a callable that waits for the results, in order."""
        jobs = list(jobs)
        if self.workers == 1 or len(jobs) < 2:
            return lambda: [fn(job) for job in jobs]
        futures = [self._pool().submit(fn, job) for job in jobs]
        return lambda: [f.result() for f in futures]

    def close(self):
        if self.pool is not None:
            self.pool.shutdown()


def seeded_rng(seed, *key):
    """The report's stream ``key`` of the experiment seeded ``seed`` (spawn key
    ``(REPORT_DOMAIN, *key)``)."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(REPORT_DOMAIN, *key)))
