"""Test-suite settings shared by every test module."""

import os

from hypothesis import settings

# Property-based tests draw the same examples on every run and machine: a suite that can
# fail at random is no test, and a failure found once is found again (the search stays
# as broad; widen it locally with HYPOTHESIS_PROFILE=explore).
settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


def assert_provenance(page):
    """Assert that the results page ``page`` ends with the table of where its numbers come
    from (`kicktimes.render.provenance`): its title is the page's last ``## `` heading,
    nothing but the table follows it, and every CSV the table names lies beside the page
    with the columns it names. Returns the table's rows as (csv, columns, function)."""
    from pathlib import Path

    import pandas as pd

    from kicktimes.render.provenance import PROVENANCE_TITLE

    page = Path(page)
    lines = page.read_text(encoding="utf-8").splitlines()
    headings = [i for i, line in enumerate(lines) if line.startswith("## ")]
    assert headings and lines[headings[-1]] == PROVENANCE_TITLE, f"{page.name}: no closing table"
    table = [line for line in lines[headings[-1] + 1:] if line.strip()]
    assert table[:2] == ["| CSV | columns | computed by |", "|---|---|---|"], table[:2]
    assert len(table) > 2 and all(line.startswith("| [") for line in table[2:]), table
    rows = []
    for line in table[2:]:
        link, columns, function = (c.strip() for c in line.strip("|").split(" | "))
        csv = link[1:link.index("]")]
        assert link == f"[{csv}]({csv})" and function.startswith("`kicktimes."), line
        assert (page.parent / csv).is_file(), f"{page.name} names {csv}, not beside it"
        have = set(pd.read_csv(page.parent / csv, nrows=0).columns)
        named = [] if columns == "all" else [c.strip() for c in columns.split(",")]
        assert set(named) <= have, f"{csv} lacks {sorted(set(named) - have)}"
        rows.append((csv, columns, function.strip("`")))
    return rows
