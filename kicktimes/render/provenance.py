r"""Where a page's numbers come from: the closing table of every results page.

Each page of ``docs/results/`` ends with a table that names, for each CSV beside it, the
columns a reader meets on the page and the function that computed them, as
``module.function``. The function is given as the object itself, not as a string, so
a renamed or moved function breaks the page's import at once instead of leaving a stale
name on the page; :func:`check_sources` refuses a page whose table names a CSV or a
column its folder does not have.

Examples
--------
>>> from kicktimes.stats import cluster_bootstrap
>>> rows = [Source("r.csv", "ratio, ci_low", cluster_bootstrap)]
>>> print("\n".join(provenance_lines(rows)))
## Where the numbers come from
<BLANKLINE>
| CSV | columns | computed by |
|---|---|---|
| [r.csv](r.csv) | ratio, ci_low | `kicktimes.stats.bootstrap.cluster_bootstrap` |
<BLANKLINE>
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["PROVENANCE_TITLE", "Source", "check_sources", "provenance_lines"]

#: the heading of the closing table (a test finds it at the end of every page)
PROVENANCE_TITLE = "## Where the numbers come from"


@dataclass(frozen=True)
class Source:
    """One row of the closing table: ``columns`` (comma-separated names of the CSV's
    columns, or ``"all"``) of ``csv`` (a path relative to the page) were computed by
    ``computed_by`` (a function or class of kicktimes)."""

    csv: str
    columns: str
    computed_by: Callable

    @property
    def function(self) -> str:
        """``module.qualname`` of :attr:`computed_by`."""
        fn = self.computed_by
        module = getattr(fn, "__module__", None)
        name = getattr(fn, "__qualname__", None)
        if not module or not name or not module.startswith("kicktimes"):
            raise TypeError(f"computed_by must be a function or class of kicktimes, got {fn!r}")
        return f"{module}.{name}"

    def column_names(self) -> list[str]:
        """The named columns (empty for ``"all"``)."""
        if self.columns.strip() == "all":
            return []
        return [c.strip() for c in self.columns.split(",") if c.strip()]


def provenance_lines(sources: Iterable[Source]) -> list[str]:
    """The Markdown lines of the closing table, one row per `Source`."""
    sources = list(sources)
    if not sources:
        raise ValueError("sources: a results page names at least one CSV and its function")
    lines = [PROVENANCE_TITLE, "", "| CSV | columns | computed by |", "|---|---|---|"]
    lines += [f"| [{s.csv}]({s.csv}) | {s.columns} | `{s.function}` |" for s in sources]
    return lines + [""]


def check_sources(folder, sources: Iterable[Source]) -> None:
    """Raise ValueError unless every `Source`'s CSV exists under ``folder`` (the page's
    folder) with every column it names."""
    import pandas as pd

    folder = Path(folder)
    for s in sources:
        path = folder / s.csv
        if not path.is_file():
            raise ValueError(f"sources: {s.csv} is not in {folder} (the page names it)")
        have = set(pd.read_csv(path, nrows=0).columns)
        missing = [c for c in s.column_names() if c not in have]
        if missing:
            raise ValueError(f"sources: {s.csv} has no column {', '.join(missing)} "
                             f"(its columns: {', '.join(sorted(have))})")
