"""The header and the verdict phrases shared by the generated pages of the studies.

Every page under ``docs/results/`` that states results starts with one line, ::

    Generated <UTC time> by kicktimes <version> (`<command>`) from <stores by name>.

(the model is ``docs/results/README.md``), and every comparative word in it comes from
a verdict of :mod:`kicktimes.stats` (``ratio_verdict``, ``share_verdict``), never typed.
The sweep report (:mod:`kicktimes.report`) and the studies of
:mod:`kicktimes.studies` import these from here.

Examples
--------
>>> from kicktimes.render.pages import ratio_text, trend_verdict
>>> ratio_text(0.771, 0.721, 0.825)
'0.771 [0.721, 0.825], lower'
>>> trend_verdict(0.1, 0.4)
'rises'
"""

from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes import __version__
from kicktimes.stats import MARGIN, format_interval, ratio_verdict

__all__ = ["NULL_CALIBRATION", "NULL_CALIBRATION_COLUMNS", "NULL_STATISTICS", "header",
           "markdown_table", "number_text", "p_value_text", "percent_text", "ratio_text",
           "rho_text", "simulations_source", "store_name", "trend_verdict",
           "write_null_calibration", "write_results_page"]


def store_name(path) -> str:
    """The experiment name of a store (its manifest's ``experiment.name``), never its path."""
    manifest = Path(path) / "manifest.json"
    if not manifest.is_file():
        raise ValueError(f"stores: {path} is not a kicktimes store (no manifest.json)")
    return json.loads(manifest.read_text(encoding="utf-8"))["experiment"]["name"]


def header(title, command, sources) -> list[str]:
    """The page's title and "Generated ..." line; ``sources`` are names, not paths."""
    now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    return [f"# {title} (generated)", "",
            f"Generated {now} by kicktimes {__version__} (`{command}`) from "
            + ", ".join(sources) + ". Every number below is computed; nothing is typed.", ""]


def simulations_source(study, cache, *extra) -> str:
    """The source of a page built from a study's own simulations: ``"the direct
    simulations of `kicktimes.studies.<study>` (its cache `<cache>`; <extra>; no store)"``.

    >>> simulations_source("mmpp", "cache-mmpp")
    'the direct simulations of `kicktimes.studies.mmpp` (its cache `cache-mmpp`; no store)'
    """
    parts = [f"its cache `{cache}`", *extra, "no store"]
    return f"the direct simulations of `kicktimes.studies.{study}` ({'; '.join(parts)})"


def ratio_text(estimate, low, high, tolerance=MARGIN) -> str:
    """``"0.771 [0.721, 0.825], lower"``: the interval and its `ratio_verdict`."""
    return (f"{format_interval(estimate, low, high)}, "
            f"{ratio_verdict(low, high, tolerance=tolerance)}")


def number_text(x, digits=3) -> str:
    """``x`` with ``digits`` significant figures; ``"n/a"`` when None or not finite.

    >>> number_text(0.123456), number_text(float("nan"))
    ('0.123', 'n/a')
    """
    return "n/a" if x is None or not np.isfinite(x) else f"{x:.{digits}g}"


def percent_text(x) -> str:
    """A share as a percentage with one decimal: ``percent_text(0.0512) == '5.1%'``."""
    return "n/a" if not np.isfinite(x) else f"{100 * x:.1f}%"


def p_value_text(p) -> str:
    """A p-value with 3 significant figures; ``"< 1e-300"`` for an underflowed 0."""
    if not np.isfinite(p):
        return "n/a"
    return "< 1e-300" if p == 0 else f"{p:.3g}"


def rho_text(rho, p) -> str:
    """A rank correlation and its p-value: ``rho_text(0.9, 0.037) == '0.90, p = 0.037'``."""
    return "n/a" if not np.isfinite(rho) else f"{rho:.2f}, p = {p_value_text(p)}"


def trend_verdict(low, high) -> str:
    """``"rises"``, ``"falls"`` or ``"no trend detected"`` for a slope's 95 % CI against 0."""
    if not (np.isfinite(low) and np.isfinite(high)):
        return "no trend detected"
    if low > 0:
        return "rises"
    if high < 0:
        return "falls"
    return "no trend detected"


def markdown_table(frame: pd.DataFrame) -> list[str]:
    """``frame`` as the lines of a GitHub Markdown table (cells' ``|`` escaped)."""
    def cell(v):
        return str(v).replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(cell(c) for c in frame.columns) + " |",
             "|" + "---|" * len(frame.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |"
              for row in frame.itertuples(index=False)]
    return lines



#: the file, in a results folder, of the null streams sent through the pages' tests
NULL_CALIBRATION = "null_calibration.csv"
#: its columns: the study that wrote the row, the data set it is shaped like, the
#: statistic (`NULL_STATISTICS`), the test (for a rejection share; else empty), the null
#: design, the runs and clusters, the statistic's value on the null streams with its 95 %
#: CI, and its verdict against the naive reference: for a rejection share
#: `kicktimes.stats.rejection_verdict` against the nominal level ``alpha``, for the others
#: `kicktimes.stats.ratio_verdict` against 1 (where the null's own value is not 1, a page
#: reads the statistic against this row, never against 1)
NULL_CALIBRATION_COLUMNS = ("study", "data", "statistic", "test", "design", "alpha", "n_runs",
                            "n_clusters", "value", "ci_low", "ci_high", "verdict")
#: the statistics a null calibration row may carry: the share of null streams a test
#: rejects; the dispersion index of the counts; the interval hazard in units of the rate
#: (first bin, highest bin); the fitted gamma shape of the intervals
NULL_STATISTICS = ("rejection share", "D", "hazard, first bin", "hazard, highest bin",
                   "gamma shape")


def write_null_calibration(results_dir, study, rows: pd.DataFrame) -> Path:
    """Put ``study``'s rows into ``results_dir/null_calibration.csv``, keeping the other
    studies' rows (each study owns its rows; the file is shared by the pages that cite
    it). Written atomically; returns the path.

    ``rows`` has the columns `NULL_CALIBRATION_COLUMNS` except ``study`` and ``verdict``,
    which are filled in here; a table without ``statistic`` holds rejection shares (its
    ``share`` column is the ``value``). The verdict: `kicktimes.stats.rejection_verdict` of
    a share's CI against ``alpha``, `kicktimes.stats.ratio_verdict` of another statistic's
    CI against 1.
    """
    from kicktimes.fileio import atomic_write
    from kicktimes.stats import ratio_verdict, rejection_verdict

    rows = rows.rename(columns={"share": "value"})
    if "statistic" not in rows:
        rows = rows.assign(statistic="rejection share")
    missing = set(NULL_CALIBRATION_COLUMNS) - {"study", "verdict"} - set(rows.columns)
    if missing:
        raise ValueError(f"rows: the null calibration needs the columns {sorted(missing)}")
    unknown = set(rows["statistic"]) - set(NULL_STATISTICS)
    if unknown:
        raise ValueError(f"rows: statistic must be one of {list(NULL_STATISTICS)}, "
                         f"got {sorted(unknown)}")
    rows = rows.copy()
    rows.insert(0, "study", study)
    share = rows["statistic"] == "rejection share"
    rows["verdict"] = [rejection_verdict(lo, hi, alpha=a) if s else ratio_verdict(lo, hi)
                       for lo, hi, a, s in zip(rows["ci_low"], rows["ci_high"], rows["alpha"],
                                               share, strict=True)]
    path = Path(results_dir) / NULL_CALIBRATION
    if path.is_file():
        old = pd.read_csv(path, keep_default_na=False, na_values=[""])
        old = old.rename(columns={"share": "value"})  # a file from before `statistic`
        if "statistic" not in old:
            old = old.assign(statistic="rejection share")
        rows = pd.concat([old[old["study"] != study], rows], ignore_index=True)
    rows = rows[list(NULL_CALIBRATION_COLUMNS)].sort_values(
        ["study", "data", "statistic", "test"], kind="stable")
    atomic_write(path, lambda tmp: rows.to_csv(tmp, index=False))
    return path


def write_results_page(path, lines, sources) -> Path:
    """Write the results page ``path`` from its Markdown ``lines``, closed by the table of
    where its numbers come from (`kicktimes.render.provenance`), atomically; returns the
    path.

    ``sources`` are the page's `kicktimes.render.provenance.Source` rows, checked first
    against the CSVs in the page's folder (`check_sources`): a page never names a CSV or
    a column that is not there, and a failed check leaves the old page in place.
    """
    from kicktimes.fileio import atomic_write
    from kicktimes.render.provenance import check_sources, provenance_lines

    path = Path(path)
    sources = list(sources)
    check_sources(path.parent, sources)
    lines = list(lines)
    while lines and lines[-1] == "":
        lines.pop()
    text = "\n".join([*lines, "", *provenance_lines(sources)])
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    return path
