"""The studies' cache (kicktimes.studies.cache) and option checks (kicktimes.studies.options)."""

import json

import pandas as pd
import pytest

from kicktimes.studies.cache import cached_table, cached_tables, read_cached, write_cached
from kicktimes.studies.options import check_scale, check_workers


def _table(n):
    return pd.DataFrame({"x": [float(k) for k in range(n)],
                         "times": [[0.5 * k, 1.0 * k] for k in range(n)]})


def test_the_same_parameters_reuse_the_table_and_others_recompute(tmp_path):
    path = tmp_path / "t.parquet"
    calls = []

    def compute(n):
        calls.append(n)
        return _table(n)

    first = cached_table(path, {"n": 3}, lambda: compute(3))
    again = cached_table(path, {"n": 3}, lambda: compute(3))
    assert calls == [3] and not first.reused and again.reused
    pd.testing.assert_frame_equal(first.table, again.table)
    assert list(again.table["times"].iloc[2]) == [1.0, 2.0]
    other = cached_table(path, {"n": 4}, lambda: compute(4))
    assert calls == [3, 4] and not other.reused and len(other.table) == 4
    assert json.loads(path.with_suffix(".json").read_text())["params"] == {"n": 4}


def test_a_table_without_its_parameters_is_never_reused(tmp_path):
    path = tmp_path / "t.parquet"
    write_cached(path, {"n": 2}, _table(2), seconds=1.5)
    assert read_cached(path, {"n": 2}).seconds == 1.5
    path.with_suffix(".json").unlink()        # as an interrupted write leaves it
    assert read_cached(path, {"n": 2}) is None
    assert read_cached(tmp_path / "none.parquet", {"n": 2}) is None


def test_cached_tables_keep_the_order_of_the_jobs_and_compute_only_the_missing(tmp_path):
    write_cached(tmp_path / "b.parquet", {"n": 2}, _table(2))
    jobs = [(tmp_path / "a.parquet", {"n": 1}, _table, (1,)),
            (tmp_path / "b.parquet", {"n": 2}, _table, (2,)),
            (tmp_path / "c.parquet", {"n": 3}, _table, (3,))]
    lines = []
    got = cached_tables(jobs, progress=lines.append)
    assert [len(c.table) for c in got] == [1, 2, 3]
    assert [c.reused for c in got] == [False, True, False]
    assert lines[0] == "1 of 3 tables cached, computing 2"


def test_scale_and_workers_are_checked_by_name():
    assert check_scale("paper", {"quick": 1, "paper": 2}) == "paper"
    with pytest.raises(ValueError, match="scale must be one of 'quick', 'paper'"):
        check_scale("full", {"quick": 1, "paper": 2})
    assert check_workers(3) == 3
    for bad in (0, -1, 2.0, True, "2"):
        with pytest.raises(ValueError, match="workers"):
            check_workers(bad)
