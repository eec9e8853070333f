"""The closing table of every results page (kicktimes.render.provenance): a page names
only CSVs and columns its folder has, and a failed check writes no page."""

import pandas as pd
import pytest

from kicktimes.render.pages import write_results_page
from kicktimes.render.provenance import PROVENANCE_TITLE, Source, check_sources
from kicktimes.stats import paired_ratio


def test_check_sources_refuses_a_missing_csv_and_a_missing_column_naming_the_csv(tmp_path):
    pd.DataFrame({"ratio": [1.0], "ci_low": [0.9]}).to_csv(tmp_path / "r.csv", index=False)
    check_sources(tmp_path, [Source("r.csv", "ratio, ci_low", paired_ratio),
                             Source("r.csv", "all", paired_ratio)])
    with pytest.raises(ValueError, match=r"gone\.csv"):
        check_sources(tmp_path, [Source("gone.csv", "all", paired_ratio)])
    with pytest.raises(ValueError, match=r"r\.csv has no column ci_high"):
        check_sources(tmp_path, [Source("r.csv", "ratio, ci_high", paired_ratio)])


def test_a_failed_check_leaves_no_page_and_a_passed_one_closes_the_page(tmp_path):
    page = tmp_path / "page.md"
    with pytest.raises(ValueError, match=r"r\.csv"):
        write_results_page(page, ["# t", ""], [Source("r.csv", "ratio", paired_ratio)])
    assert not page.exists() and list(tmp_path.iterdir()) == []
    pd.DataFrame({"ratio": [1.0]}).to_csv(tmp_path / "r.csv", index=False)
    write_results_page(page, ["# t", "", "body", "", ""], [Source("r.csv", "ratio",
                                                                 paired_ratio)])
    text = page.read_text(encoding="utf-8")
    assert text.startswith("# t\n\nbody\n\n" + PROVENANCE_TITLE + "\n")
    assert text.endswith("| [r.csv](r.csv) | ratio | `kicktimes.stats.bootstrap.paired_ratio` |\n")
