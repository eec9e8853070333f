"""D against the window, in the circle and in the box (kicktimes.studies.disks.windows)."""

import numpy as np
import pandas as pd
import pytest

from kicktimes.studies.disks.windows import (
    RUNS_COLUMNS,
    DispersionWindows,
    dispersion_runs,
    one_state,
    summarise,
    windows_lines,
)


def test_poisson_counts_give_d_of_one_within_ten_percent():
    rng = np.random.default_rng(1)
    rows = []
    for state in range(6):
        for k in (15, 30):
            c = rng.poisson(k, size=4000).astype(float)
            rows.append((1000, 0.02, "mirror", "circle", state, k, c.size, c.sum(),
                         (c ** 2).sum(), 1.0))
            # counts of a mixture of two rates: over-dispersed, D = 1 + k var(rate) / mean
            lam = np.where(rng.random(4000) < 0.5, 0.7, 1.3) * k
            c = rng.poisson(lam).astype(float)
            rows.append((1000, 0.02, "mirror", "box", state, k, c.size, c.sum(),
                         (c ** 2).sum(), 1.0))
    t = summarise(pd.DataFrame(rows, columns=list(RUNS_COLUMNS)), n_boot=300)
    plain = t[t["boundary"] == "circle"]
    assert (plain["verdict"] == "within 10 %").all()
    mixed = t[t["boundary"] == "box"].set_index("window")
    assert mixed.loc[15, "d"] == pytest.approx(1 + 15 * 0.09, rel=0.05)
    assert (mixed["verdict"] == "higher").all() and (mixed["prediction"] == 1.0).all()


def test_every_collision_is_counted_once_for_each_disk(tmp_path):
    rows = one_state(40, 0.02, 0, "mirror", "circle", (5, 10), 20.0, 2.0, 7, 0)
    by_k = {k: (n, s1, nu) for k, n, s1, _, nu in rows}
    n5, s5, nu = by_k[5]
    assert n5 == 40 * 4  # four whole windows of 5 mean intervals per disk in 20
    assert s5 == pytest.approx(40 * 20, rel=0.15)  # about one collision per mean interval
    assert by_k[10][1] <= s5  # two windows of 10 cover what four of 5 do, or less


def test_the_box_runs_and_the_page_section_reads_the_table(tmp_path):
    sweep = DispersionWindows(n_disks=60, packings=(0.05,), rules=("mirror",),
                              windows=(5, 10), states=2, length=20.0, skip=2.0)
    runs = dispersion_runs(tmp_path, sweep)
    assert set(runs["boundary"]) == {"circle", "box"}
    t = summarise(runs, n_boot=100)
    t.to_csv(tmp_path / "disks_dispersion_windows.csv", index=False)
    lines = windows_lines(tmp_path / "disks_dispersion_windows.csv")
    assert lines[0] == "## D against the window, in the circle and in the box"
    assert sum(x.startswith("| 0.05, mirror") for x in lines) == 2
    assert windows_lines(tmp_path / "absent.csv") == []
    with pytest.raises(ValueError, match="length"):
        DispersionWindows(windows=(15, 500))
