"""The code's layout: no module over 800 lines, each over 600 named in docs/architecture.md
with its concern; each statistic of every page defined once, in `kicktimes.stats`."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "kicktimes"


def _modules():
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_no_module_is_over_800_lines_and_each_over_600_is_named_with_its_concern():
    table = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = table.split("## Long modules", 1)[1].split("\n## ", 1)[0]
    named = set(re.findall(r"^\| `([^`]+\.py)` \|", table, flags=re.M))
    long = {}
    for path in _modules():
        n = len(path.read_text(encoding="utf-8").splitlines())
        assert n <= 800, f"{path.relative_to(ROOT)}: {n} lines (at most 800)"
        if n > 600:
            long[str(path.relative_to(PACKAGE))] = n
    assert set(long) <= named, f"not named in architecture.md's 'Long modules': " \
                               f"{sorted(set(long) - named)}"


def test_the_sticky_rule_clopper_pearson_and_the_margin_are_defined_once():
    sticky, clopper, margin = [], [], []
    for path in _modules():
        text = path.read_text(encoding="utf-8")
        rel = str(path.relative_to(PACKAGE))
        sticky += [rel] * len(re.findall(r"^STICKY_FACTOR\s*=", text, flags=re.M))
        margin += [rel] * len(re.findall(r"^MARGIN\s*=", text, flags=re.M))
        # a definition, or a call of another library's interval (not its name in a docstring)
        clopper += [rel] * len(re.findall(r"^def \w*clopper\w*\(|(?<!`)\b(?:binomtest|"
                                          r"proportion_confint)\(", text, flags=re.M))
    assert sticky == ["stats/counts.py"]
    assert clopper == ["stats/findings.py"]
    assert margin == ["stats/margins.py"]


def test_no_page_draws_its_own_cluster_resamples():
    # the bootstrap clustered on runs draws its indices in kicktimes.stats (resample_indices)
    draw = re.compile(r"\.integers\(0,|\.choice\([^)]*\)\)?\.mean|\.choice\(\w+, len\(|"
                      r"\.multinomial\(")
    found = [str(p.relative_to(PACKAGE)) for p in _modules()
             if not p.is_relative_to(PACKAGE / "stats") and draw.search(p.read_text())]
    # the Bootstrap kick schedule resamples intervals (not runs); the compile warm-up
    # calls a stats kernel on random indices
    assert set(found) <= {"schedules/_base.py", "compilation.py"}, found


def test_no_page_writes_its_own_percentile_interval():
    # every bootstrap (and Monte Carlo) interval of the pages is stats.percentile_interval:
    # the same percentiles (exactly 2.5 and 97.5 %), the same handling of undefined draws
    literal = re.compile(r"percentile\([^)]*\[\s*2\.5\s*,\s*97\.5\s*\]|"
                         r"\(1(\.0)? - level\) / 2")
    found = [str(p.relative_to(PACKAGE)) for p in _modules()
             if not p.is_relative_to(PACKAGE / "stats") and literal.search(p.read_text())]
    assert found == [], found
