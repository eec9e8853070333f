"""Test-suite settings shared by every test module."""

import contextlib
import os
import re
import warnings

from hypothesis import settings

# Property-based tests draw the same examples on every run and machine: a suite that can
# fail at random is no test, and a failure found once is found again (the search stays
# as broad; widen it locally with HYPOTHESIS_PROFILE=explore).
settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


def assert_provenance(page, every_csv_in=None):
    """Assert that the results page ``page`` ends with the table of where its numbers come
    from (`kicktimes.render.provenance`): its title is the page's last ``## `` heading,
    nothing but the table follows it, and every CSV the table names lies beside the page
    with the columns it names; with ``every_csv_in`` (a folder beside the page), that the
    table names every CSV of that folder. Returns the rows as (csv, columns, function)."""
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
    if every_csv_in is not None:
        written = {f"{every_csv_in}/{p.name}" for p in (page.parent / every_csv_in).glob("*.csv")}
        assert {csv for csv, _, _ in rows} == written
    return rows


#: a path of the machine the page was built on (a page names stores and commands, never
#: where they lay)
MACHINE_PATH = re.compile(r"(/tmp/|/work/|/home/|/Users/|/root/|[A-Za-z]:\\\\)")


def built_study(name, study, params, patches=()):
    """A module-scoped fixture ``(out, page)``: ``study.reproduce(out)`` at a tiny size, its
    ``study.SCALES["quick"]`` set to ``params`` and each ``(object, attribute, value)`` of
    ``patches`` in place for the run. Use as ``built = built_study("scatter", study, TINY)``.
    """
    import pytest

    @pytest.fixture(scope="module")
    def built(tmp_path_factory):
        out = tmp_path_factory.mktemp(name)
        with pytest.MonkeyPatch.context() as mp:
            mp.setitem(study.SCALES, "quick", params)
            for target, attribute, value in patches:
                mp.setattr(target, attribute, value)
            page = study.reproduce(out)
        return out, page

    return built


def assert_study_page(page, study, scale="quick"):
    """The page of ``reproduce`` for ``study`` at ``scale``: ``results-<study>/<study>.md``,
    its Generated line naming the command, no path of this machine. Returns its text."""
    text = page.read_text(encoding="utf-8")
    assert page.name == f"{study}.md" and page.parent.name == f"results-{study}"
    assert f"(`kicktimes reproduce --study {study} --scale {scale}`)" in text.splitlines()[2]
    assert not MACHINE_PATH.search(text), MACHINE_PATH.search(text).group(0)
    return text


def refuse_simulations(monkeypatch, module, *names):
    """Replace ``module``'s functions ``names`` by one that fails: a rerun that reuses its
    cache never calls them."""
    def simulated_again(*args, **kwargs):
        raise AssertionError("simulated again")

    for name in names:
        monkeypatch.setattr(module, name, simulated_again)


def table_cells(text, first):
    """The cells of the Markdown table row of ``text`` whose first cell is ``first``."""
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells and cells[0] == first:
            return cells
    raise AssertionError(f"no table row {first!r}")


@contextlib.contextmanager
def local_dask(n_workers):
    """``(cluster, client)`` of a local Dask cluster of ``n_workers`` one-thread processes
    (the test is skipped without kicktimes[dask]); dask's start-up chatter is silenced."""
    import pytest

    distributed = pytest.importorskip("distributed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ports, versions
        with distributed.LocalCluster(n_workers=n_workers, processes=True, threads_per_worker=1,
                                      dashboard_address=None) as cluster:
            with distributed.Client(cluster) as client:
                yield cluster, client


def first_screen_answers(page):
    """The answer lines (``- `` bullets) of a results page before its first table, checked:
    one to five of them, each with a number and its interval ``x [low, high]``."""
    head = page.read_text(encoding="utf-8").split("\n|")[0]
    answers = [line for line in head.splitlines() if line.startswith("- ")]
    assert 1 <= len(answers) <= 5, answers
    interval = re.compile(r"\d %? ?\[[-−+]?[\d.]+, [-−+]?[\d.]+\]")
    assert all(interval.search(line) for line in answers), answers
    return answers
