"""What every study's ``reproduce`` does with its options before and after it computes.

`study_run` checks ``scale`` and ``workers`` and lays out the run: the study's sizes at that
scale, its cache folder in ``out`` (``cache-NAME``, ``cache-NAME-quick`` at the quick
scale), its results folder (``results_dir``, default ``out/results-NAME``) and the command
its page's "Generated" line names (default ``kicktimes reproduce --study NAME --scale
SCALE``). The returned `StudyRun` writes the tables, figures and page atomically and says
what it wrote.

The options of every ``reproduce(out, *, scale, results_dir, workers, progress, command)``:

out : path-like
    The study's work folder: its raw tables are cached there (`kicktimes.studies.cache`),
    reused by a rerun with the same parameters.
scale : {"quick", "paper"}
    ``"paper"``: the sizes of the study's page in docs/results; ``"quick"``: a small version.
results_dir : path-like, optional
    Folder of the page, its CSVs and figures (default ``out/results-NAME``).
workers : int
    Processes for the simulations (``>= 1``).
progress : bool or callable, optional
    A callable takes one line of text per step; ``True`` prints those lines on stderr
    (and shows the study's progress bars, if it has any); ``None`` or ``False``: silent
    (`status_lines`).
command : str, optional
    The command the page's "Generated" line names.

Examples
--------
>>> check_scale("quick", {"quick": 1, "paper": 2})
'quick'
>>> check_workers(2)
2
>>> check_workers(0)
Traceback (most recent call last):
...
ValueError: workers must be an integer >= 1, got 0
>>> run = study_run("demo", "work", scale="quick", scales={"quick": 1, "paper": 2})
>>> run.params, run.cache.name, run.results.name, run.command
(1, 'cache-demo-quick', 'results-demo', 'kicktimes reproduce --study demo --scale quick')
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from numbers import Integral
from pathlib import Path

from kicktimes.fileio import atomic_write
from kicktimes.render.pages import write_results_page

__all__ = ["StudyRun", "check_scale", "check_workers", "study_run"]


def check_scale(scale, scales) -> str:
    """``scale`` if it names one of ``scales`` (a mapping or a sequence of names)."""
    names = list(scales)
    if not isinstance(scale, str) or scale not in names:
        raise ValueError(f"scale must be one of {', '.join(map(repr, names))}, got {scale!r}")
    return scale


def check_workers(workers) -> int:
    """``workers`` if it is an integer >= 1 (not a bool)."""
    if isinstance(workers, bool) or not isinstance(workers, Integral) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    return int(workers)


def status_lines(progress):
    """The callable that takes a study's status lines: ``progress`` itself if it is
    callable; for ``True``, one that prints each line on stderr; for ``None`` or
    ``False``, one that drops them.

    >>> status_lines(None)("dropped") is None
    True
    """
    if callable(progress):
        return progress
    if progress:
        return lambda line: print(line, file=sys.stderr, flush=True)
    return lambda line: None


@dataclass(frozen=True)
class StudyRun:
    """One run of a study: its ``name``, sizes ``params``, ``cache`` and ``results``
    folders, the ``command`` its page names, ``workers`` and ``progress``."""

    name: str
    params: object
    cache: Path
    results: Path
    command: str
    workers: int
    progress: object = None

    def say(self, line: str) -> None:
        """Pass ``line`` to ``progress`` (`status_lines`)."""
        status_lines(self.progress)(line)

    def write_csv(self, name: str, frame) -> None:
        """``frame`` as ``results/name`` (CSV, no index), atomically."""
        atomic_write(self.results / name, lambda tmp: frame.to_csv(tmp, index=False))

    def write_figure(self, name: str, fig, dpi: int = 110) -> None:
        """``fig`` as the PNG ``results/name``, atomically."""
        atomic_write(self.results / name, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png"))

    def write_page(self, lines, sources) -> Path:
        """The page ``results/<name>.md`` from its Markdown ``lines``, closed by the table
        of its ``sources`` (`kicktimes.render.pages.write_results_page`); returns its
        path."""
        page = write_results_page(self.results / f"{self.name}.md", lines, sources)
        self.say(f"{self.name}: {page} written")
        return page


def study_run(name: str, out: str | os.PathLike, *, scale: str, scales,
              results_dir: str | os.PathLike | None = None, workers: int = 1,
              progress=None, command: str | None = None) -> StudyRun:
    """Check ``scale`` (one of ``scales``, a mapping to the study's sizes) and ``workers``,
    and lay out the run of study ``name`` (module docstring)."""
    check_scale(scale, scales)
    # None: every core (the command line's --workers default)
    workers = (os.cpu_count() or 1) if workers is None else check_workers(workers)
    out = Path(out)
    return StudyRun(
        name=name, params=scales[scale],
        cache=out / (f"cache-{name}" if scale == "paper" else f"cache-{name}-{scale}"),
        results=Path(results_dir) if results_dir is not None else out / f"results-{name}",
        command=command or f"kicktimes reproduce --study {name} --scale {scale}",
        workers=workers, progress=progress)
