"""Compare two output trees of `kicktimes reproduce`: does a change move any number?

Every CSV must be byte-identical, except the timing tables (``*_timings.csv``,
``disks_cost.csv``); every PNG pixel-identical (decoded with matplotlib, so that metadata
cannot hide or fake a difference); every Markdown page identical once the lines that state
when or how fast it was built are set aside (the "Generated <date>" line, "Built in N s",
the CPU-time sentences); the sweep report's HTML identical but for its dates, the stores'
folders and its timings section, with every embedded figure pixel-identical. Store folders
and caches are skipped: they hold the raw runs, which the tables summarise.

Usage (the check of issue 59: the same command before and after a change)::

    git archive <before> | tar -x -C /tmp/before-src       # or a clone with its own venv
    kicktimes reproduce --study all --scale quick --out /tmp/before --workers 2   # at <before>
    kicktimes reproduce --study all --scale quick --out /tmp/after --workers 2    # at <after>
    python analysis/compare_outputs.py /tmp/before /tmp/after

Exit status 0 when nothing but the set-aside lines differs, 1 otherwise.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

TIMINGS = re.compile(r"(_timings|^disks_cost)\.csv$")
#: page lines that state when or how fast the page was made, not what it says
VOLATILE = re.compile(r"^Generated \d{4}-\d\d-\d\dT|[Bb]uilt in \d|\bs of CPU\b|\bs of wall\b")


def _files(root: Path):
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root)
        if path.is_file() and not any(p.startswith(("store-", "cache")) or p == "__pycache__"
                                      for p in rel.parts[:-1]):
            yield rel


def _page_lines(path: Path):
    return [ln for ln in path.read_text(encoding="utf-8").splitlines()
            if not VOLATILE.search(ln)]


def _pixels_equal(a, b) -> bool:
    """Whether two PNGs (paths or bytes) decode to the same pixels."""
    import io

    import matplotlib.image as mpimg
    import numpy as np

    x, y = (mpimg.imread(io.BytesIO(v) if isinstance(v, bytes) else v) for v in (a, b))
    return x.shape == y.shape and bool(np.array_equal(x, y))


_IMAGE = re.compile(r'src="data:image/png;base64,([^"]+)"')
_STAMP = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d[+-]\d\d:\d\d")
_TIMINGS = re.compile(r"<h2>Timings</h2>.*?(?=<h2|</body>)", flags=re.S)


def _html_equal(a: Path, b: Path, roots) -> bool:
    """The sweep report's pages: the same text once the build and run dates, the stores'
    folders and the timings section are set aside, and the same pixels in every embedded
    figure."""
    import base64

    texts = []
    for path, root in zip((a, b), roots, strict=True):
        text = path.read_text(encoding="utf-8").replace(str(root), "ROOT")
        texts.append(text)
    images = [_IMAGE.findall(text) for text in texts]
    if len(images[0]) != len(images[1]) or not all(
            x == y or _pixels_equal(base64.b64decode(x), base64.b64decode(y))
            for x, y in zip(*images, strict=True)):
        return False
    plain = [_TIMINGS.sub("", _STAMP.sub("DATE", _IMAGE.sub("", text))) for text in texts]
    return plain[0] == plain[1]


def _numeric_difference(a: Path, b: Path) -> str:
    """How far two CSVs of the same shape differ: ``"; largest relative difference X in
    column C"`` over their numeric columns (text columns must agree), or ``""`` when they
    differ in shape, columns or text."""
    import numpy as np
    import pandas as pd

    x, y = pd.read_csv(a), pd.read_csv(b)
    if x.shape != y.shape or list(x.columns) != list(y.columns):
        return " (shape or columns)"
    worst, where = 0.0, None
    for col in x.columns:
        u, v = x[col], y[col]
        if u.dtype.kind in "fi" and v.dtype.kind in "fi":
            u, v = u.to_numpy(float), v.to_numpy(float)
            same = (u == v) | (np.isnan(u) & np.isnan(v))
            if not same.all():
                rel = np.abs(u - v)[~same] / np.maximum(np.abs(u), np.abs(v))[~same]
                if np.nanmax(rel) > worst or where is None:
                    worst, where = float(np.nanmax(rel)), col
        elif not u.astype(str).equals(v.astype(str)):
            return f" (text of column {col})"
    return "" if where is None else f"; largest relative difference {worst:.2g} in {where}"


def compare(before: Path, after: Path) -> list[str]:
    """The differences, one line each (empty: the trees say the same)."""
    problems = []
    old, new = set(_files(before)), set(_files(after))
    problems += [f"only in {before}: {p}" for p in sorted(old - new)]
    problems += [f"only in {after}: {p}" for p in sorted(new - old)]
    for rel in sorted(old & new):
        a, b = before / rel, after / rel
        if rel.suffix == ".csv":
            if not TIMINGS.search(rel.name) and a.read_bytes() != b.read_bytes():
                problems.append(f"CSV differs: {rel}{_numeric_difference(a, b)}")
        elif rel.suffix == ".png":
            if a.read_bytes() != b.read_bytes() and not _pixels_equal(a, b):
                problems.append(f"figure differs: {rel}")
        elif rel.suffix == ".html":
            if not _html_equal(a, b, (before, after)):
                problems.append(f"page differs: {rel}")
        elif rel.suffix == ".md":
            if _page_lines(a) != _page_lines(b):
                problems.append(f"page differs: {rel}")
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    args = parser.parse_args(argv)
    for folder in (args.before, args.after):
        if not folder.is_dir():
            parser.error(f"{folder}: not a folder")
    problems = compare(args.before, args.after)
    n = sum(1 for _ in _files(args.after))
    print("\n".join(problems) if problems else
          f"{n} files compared: every CSV byte-identical (timings aside), every figure "
          "pixel-identical, every page identical but for its date and timing lines")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
