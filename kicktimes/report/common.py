"""Plumbing shared by the report's sections: the section record, the build context,
progress, the process pool, seeded streams, validation and number formatting."""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from kicktimes.memory import keep_freed_memory

if TYPE_CHECKING:  # pandas and scipy load with the sections that use them
    import pandas as pd

#: first spawn-key word of the report's Monte Carlo streams ("rprt"), distinct from the
#: IC and kick streams of the sweep
REPORT_DOMAIN = 0x72707274
#: the reference system every other ("kicked") system is compared with
REFERENCE = "two_particle"
#: ICs and steps of the paper's smaller family (A): below this a report is a smoke test
PAPER_SCALE = {"n_ics": 200, "n_steps": 15000}


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


def check_int(name, value, low, allow_none=False):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < low:
        raise ValueError(f"{name} must be >= {low}, got {int(value)}")
    return int(value)


def check_fraction(name, value):
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}")
    if not 0 < value < 1:
        raise ValueError(f"{name} must satisfy 0 < {name} < 1, got {float(value)}")
    return float(value)


def seeded_rng(seed, *key):
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(REPORT_DOMAIN, *key)))


def nearest(radii, target):
    radii = np.asarray(radii, dtype=float)
    return float(radii[np.argmin(np.abs(radii - target))])


def pct(x):
    return "n/a" if not np.isfinite(x) else f"{100 * x:.1f}%"


def fmt_p(p):
    if not np.isfinite(p):
        return "n/a"
    return "< 1e-300" if p == 0 else f"{p:.3g}"


def fmt(x, digits=3):
    """A number with ``digits`` significant figures, 'n/a' when not finite."""
    return "n/a" if x is None or not np.isfinite(x) else f"{x:.{digits}g}"


def spearman(x, y):
    """Spearman's rho and two-sided p-value (exact permutation for n <= 8), NaN when
    fewer than 3 finite points or a constant variable."""
    from scipy import stats as sps

    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if x.size < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan, math.nan
    rho = float(sps.spearmanr(x, y).statistic)
    if x.size <= 8:
        # the t approximation is meaningless for a handful of radii (it gives p = 0 at
        # |rho| = 1); enumerate the permutations instead
        from itertools import permutations

        ry = sps.rankdata(y)
        null = [sps.spearmanr(x, ry[list(p)]).statistic for p in permutations(range(x.size))]
        return rho, float(np.mean(np.abs(null) >= abs(rho) - 1e-12))
    p = float(sps.spearmanr(x, y).pvalue)
    return rho, p if p > 0 else 2.0 / math.factorial(x.size)


def fmt_rho(rho, p):
    return "n/a" if not np.isfinite(rho) else f"{rho:.2f}, p = {fmt_p(p)}"


def kicked_systems(results):
    """Every system of the store except the reference, in a stable order."""
    from kicktimes.report.figures import SYSTEMS

    present = set(results["system"].unique())
    known = [s for s in SYSTEMS if s in present and s != REFERENCE]
    return known + sorted(present - set(SYSTEMS))


def is_paper_scale(exp):
    return exp.n_ics >= PAPER_SCALE["n_ics"] and exp.n_steps >= PAPER_SCALE["n_steps"]


def eps_values(exp):
    """The experiment's recurrence thresholds as a tuple (old stores: one float)."""
    eps = exp.eps
    return tuple(float(e) for e in eps) if isinstance(eps, list | tuple) else (float(eps),)


def report_store(store):
    """The store as the report reads it: ``results`` with ``system`` and ``diagnostic`` as
    categoricals (sorted categories) and without the ``note`` column no section reads.

    The sections filter the results by system and diagnostic dozens of times, and ask
    which are present (``set(results["diagnostic"])``); on Arrow strings each filter copies
    every string and each ``set`` iterates the rows in Python (~1 s per call on a paper
    store's 2 million rows); on categoricals both work on integer codes. Groupings and
    sort orders are unchanged (sorted categories sort as the strings; groupby keeps the
    observed groups only), and so is every table written.
    """
    import copy
    import dataclasses

    import pandas as pd

    res = store.results
    if isinstance(res["diagnostic"].dtype, pd.CategoricalDtype):
        return store
    res = res.drop(columns=[c for c in ("note",) if c in res.columns])
    res = res.astype({"system": "category", "diagnostic": "category"})
    if dataclasses.is_dataclass(store):
        return dataclasses.replace(store, results=res)
    view = copy.copy(store)  # a store-like namespace (tests, notebooks)
    view.results = res
    return view


def load_report_store(path):
    """``report_store(load_store(path))``, read straight into that form: the results
    without ``note``, ``system`` and ``diagnostic`` read from Parquet as dictionaries
    (categoricals, then their categories sorted), never as 2 million strings. The same
    frames (a test compares them), read faster
    (``python benchmarks/bench_report.py --load-only --stores ...``; docs/benchmarks.md).
    """
    from kicktimes.experiment import load_store

    columns = ["radius", "ic", "system", "diagnostic", "value"]
    return load_store(path, result_columns=columns, categories=("system", "diagnostic"))


def distinct(frame, column):
    """The distinct values of ``frame[column]`` as a set (fast on categoricals: only the
    observed values, not the categories)."""
    return set(frame[column].unique())


def wide(results, diagnostic):
    """``value`` of one diagnostic as a (radius, ic) x system table."""
    part = results[results["diagnostic"] == diagnostic]
    return part.pivot_table(index=["radius", "ic"], columns="system", values="value", dropna=False,
                            observed=True)
