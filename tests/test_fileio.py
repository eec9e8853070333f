"""kicktimes.fileio: whole-or-nothing writes and exact CSV reads."""

import numpy as np
import pandas as pd
import pytest

from kicktimes.fileio import atomic_write, atomic_write_bytes, file_sha256, read_csv_exact


def test_a_csv_is_read_back_with_every_float_exactly_as_written(tmp_path):
    rng = np.random.default_rng(0)
    x = rng.random(20_000) * 10.0 ** rng.integers(-300, 300, 20_000)
    path = tmp_path / "x.csv"
    pd.DataFrame({"x": x}).to_csv(path, index=False)
    assert np.array_equal(read_csv_exact(path)["x"].to_numpy(), x)


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "page.md"
    digest = atomic_write_bytes(path, b"old")
    assert digest == file_sha256(path)

    def fails(tmp):
        with open(tmp, "w") as fh:
            fh.write("half")
        raise RuntimeError("interrupted")

    with pytest.raises(RuntimeError, match="interrupted"):
        atomic_write(path, fails)
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["page.md"]
