"""Specification of the recurrence quantification analysis (kicktimes.diagnostics.rqa).

The reference is the definition applied to the full N x N boolean matrix: every diagonal
and every column is scanned for maximal runs of recurrent admissible entries.
"""

from __future__ import annotations

import numpy as np
import pytest
from _references import chord_trajectory
from hypothesis import given, settings
from hypothesis import strategies as st

from kicktimes.diagnostics import RQAResult, _recurrence_kernels, recurrence_rate, rqa

# ------------------------------------------------------------------ reference


def runs(mask: np.ndarray) -> list[int]:
    """Lengths of the maximal runs of True in a 1-D boolean array."""
    out, k = [], 0
    for v in mask:
        if v:
            k += 1
        elif k:
            out.append(k)
            k = 0
    if k:
        out.append(k)
    return out


def brute_rqa(points: np.ndarray, eps: float, theiler: int, l_min: int) -> dict:
    """RQA from the definition on the full matrix (same float expression as the code)."""
    n = len(points)
    dx = points[:, None, 0] - points[None, :, 0]
    dy = points[:, None, 1] - points[None, :, 1]
    mat = dx * dx + dy * dy <= eps * eps
    i, j = np.indices((n, n))
    mat &= np.abs(i - j) >= theiler
    n_rec = int(mat.sum())
    diag = [length for d in range(-(n - 1), n) for length in runs(np.diagonal(mat, d))]
    vert = [length for col in range(n) for length in runs(mat[:, col])]
    long_d = [length for length in diag if length >= l_min]
    long_v = [v for v in vert if v >= l_min]
    n_adm = n * n if theiler == 0 else (n - theiler) * (n - theiler + 1)
    return {
        "n_recurrent": n_rec,
        "n_admissible": n_adm,
        "rr": n_rec / n_adm,
        "det": sum(long_d) / n_rec if n_rec else np.nan,
        "l_mean": sum(long_d) / len(long_d) if long_d else np.nan,
        "l_max": max(diag, default=0),
        "n_lines": len(long_d),
        "lam": sum(long_v) / n_rec if n_rec else np.nan,
        "tt": sum(long_v) / len(long_v) if long_v else np.nan,
        "v_max": max(vert, default=0),
    }


def assert_matches_brute_force(points, eps, theiler, l_min):
    res = rqa(points, eps=eps, theiler=theiler, l_min=l_min)
    ref = brute_rqa(np.asarray(points, dtype=float), eps, theiler, l_min)
    # without laminarity only the upper triangle is built: the same diagonal measures
    half = rqa(points, eps=eps, theiler=theiler, l_min=l_min, laminarity=False)
    assert half.lam is None and half.tt is None and half.v_max is None
    full, part = res.to_dict(), half.to_dict()
    for key in set(full) - {"lam", "tt", "v_max", "undefined"}:
        np.testing.assert_equal(part[key], full[key], err_msg=key)  # NaN equals NaN here
    diagonal_reasons = {k: v for k, v in full["undefined"].items() if k not in ("lam", "tt")}
    assert part["undefined"] == diagonal_reasons
    for key, value in ref.items():
        got = getattr(res, key)
        if isinstance(value, float) and np.isnan(value):
            assert np.isnan(got), (key, got)
            assert key in res.undefined
        else:
            assert got == value, (key, got, value)  # exact: same integers, same division
    assert set(res.undefined) == {k for k, v in ref.items() if isinstance(v, float) and v != v}


# ------------------------------------------------------------------ point sets


def trajectory(n: int, seed: int, tau: float = 0.05) -> np.ndarray:
    """A point particle in the unit disk sampled every tau, direction redrawn at the wall.

    Short steps make consecutive samples recur, so there are long diagonal lines.
    """
    return chord_trajectory(n, seed, tau=tau)


def periodic_with_duplicates(n: int) -> np.ndarray:
    """A period-7 orbit on a coarse grid: exact duplicates, ties at distance eps."""
    k = np.arange(n)
    return np.column_stack([0.01 * (k % 7), 0.01 * ((k * 3) % 5)])


RNG = np.random.default_rng(11)
POINT_SETS = {
    "uniform": RNG.uniform(-1, 1, (300, 2)),
    "trajectory": trajectory(350, seed=1),
    "periodic_duplicates": periodic_with_duplicates(200),
    "clumps": np.round(RNG.uniform(0, 0.05, (250, 2)), 2),  # many ties and duplicates
}


# ------------------------------------------------------------------ exactness


@pytest.mark.parametrize("eps", [1e-2, 0.05])
@pytest.mark.parametrize("name", ["paper_samples", *sorted(POINT_SETS)])
def test_dense_and_sparse_cell_grids_give_the_same_line_statistics(name, eps, monkeypatch):
    # rqa sweeps a dense grid (an offset per cell) when it has few cells per point and the
    # radix-sorted occupied cells otherwise; both must give the very same counts
    from kicktimes.diagnostics import recurrence

    if name == "paper_samples":
        from kicktimes import initial_conditions, simulate_two_particle

        ic = initial_conditions(1, 0.02, rng=4, method="paper")[0]
        pts = simulate_two_particle(ic, 0.01, n_steps=3000, tau=0.3, sampling="paper").samples
    else:
        pts = POINT_SETS[name]
    eps_list = [eps, eps / 3]
    monkeypatch.setattr(recurrence, "_DENSE_CELLS_MIN", 2**62)
    dense = rqa(pts, eps=eps_list, theiler=1, laminarity=False)
    monkeypatch.setattr(recurrence, "_DENSE_CELLS_PER_POINT", 0)
    monkeypatch.setattr(recurrence, "_DENSE_CELLS_MIN", 0)
    sparse = rqa(pts, eps=eps_list, theiler=1, laminarity=False)
    assert dense == sparse
    assert dense[0].n_recurrent > 0  # there is something to count


def test_the_sweep_threshold_takes_the_dense_grid_for_billiard_samples():
    from kicktimes.diagnostics import recurrence

    pts = POINT_SETS["trajectory"]
    *_, ncx, ncy, _ = recurrence._grid(pts, 1e-2)
    assert ncx * ncy <= recurrence._DENSE_CELLS_PER_POINT * len(pts) + recurrence._DENSE_CELLS_MIN
    *_, ncx, ncy, _ = recurrence._grid(np.tile(pts, (80, 1)), 1e-3)  # 28 000 points
    assert ncx * ncy > recurrence._DENSE_CELLS_PER_POINT * 28_000 + recurrence._DENSE_CELLS_MIN


@pytest.mark.parametrize("name", sorted(POINT_SETS))
@pytest.mark.parametrize("eps", [0.01, 0.05, 0.2])
@pytest.mark.parametrize("theiler", [0, 1, 5])
@pytest.mark.parametrize("l_min", [2, 3])
def test_rqa_equals_the_definition_on_the_full_matrix(name, eps, theiler, l_min):
    assert_matches_brute_force(POINT_SETS[name], eps, theiler, l_min)


@pytest.mark.parametrize("l_min", [1, 2, 3, 4])
@pytest.mark.parametrize("theiler", [0, 1, 5])
def test_many_batches_of_pairs_equal_the_definition(theiler, l_min):
    # the sweep accounts the recurrent pairs in batches of about _BATCH, the largest
    # threshold without a walk unless a line can beat the longest (l_min <= 2), and the
    # vertical lines through both entries of each pair; here the pairs fill several
    # batches and the lines have many lengths

    pts = trajectory(900, seed=3, tau=0.02)
    eps = [0.15, 0.05]
    res = rqa(pts, eps=eps, theiler=theiler, l_min=l_min)
    assert res[0].n_recurrent / 2 > 6 * _recurrence_kernels._BATCH
    for e, got in zip(eps, res, strict=True):
        ref = brute_rqa(pts, e, theiler, l_min)
        for key, value in ref.items():
            assert getattr(got, key) == value, (e, key, getattr(got, key), value)


@pytest.mark.parametrize("grid", ["dense", "sparse"])
def test_a_point_with_more_candidates_than_the_buffer(grid, monkeypatch):
    # 4500 samples within 1e-6 of each other: every pair recurs, each point has thousands
    # of candidates (more than the sweep's buffer of 2 * _BATCH pairs); the upper triangle
    # holds one line of length N - d on each diagonal d >= 1
    from kicktimes.diagnostics import recurrence

    n = 4500
    pts = 0.3 + 1e-7 * np.random.default_rng(5).uniform(size=(n, 2))
    if grid == "sparse":
        monkeypatch.setattr(recurrence, "_DENSE_CELLS_PER_POINT", 0)
        monkeypatch.setattr(recurrence, "_DENSE_CELLS_MIN", 0)
    assert n > 2 * _recurrence_kernels._BATCH
    for l_min in (1, 2, 3):
        res = rqa(pts, eps=1e-3, theiler=1, l_min=l_min)
        assert res.n_recurrent == n * (n - 1)
        assert res.n_lines == 2 * (n - l_min)  # diagonals d = 1 .. n - l_min, both sides
        on_lines = 2 * sum(n - d for d in range(1, n - l_min + 1))
        assert res.det == on_lines / (n * (n - 1))
        assert res.l_max == n - 1
        # column j: rows 0 .. j-1 and j+1 .. n-1, the diagonal entry (Theiler 1) cuts it
        runs = [v for j in range(n) for v in (j, n - 1 - j) if v >= l_min]
        assert res.lam == sum(runs) / (n * (n - 1)) and res.v_max == n - 1
        assert res.tt == sum(runs) / len(runs)
    res0 = rqa(pts, eps=1e-3, theiler=0)  # with the diagonal: every column is one run of n
    assert (res0.lam, res0.tt, res0.v_max) == (1.0, n, n)


@settings(max_examples=150, deadline=None)
@given(
    data=st.lists(
        st.tuples(
            st.sampled_from([0.0, 0.001, 0.002, 0.01, -0.003]),
            st.sampled_from([0.0, 0.001, 0.0015, 0.004]),
        ),
        min_size=1,
        max_size=40,
    ),
    eps=st.sampled_from([1e-4, 1e-3, 0.0015, 2e-3, 5e-3, 0.05]),
    theiler=st.integers(0, 4),
    l_min=st.integers(1, 4),
)
def test_property_rqa_equals_the_definition(data, eps, theiler, l_min):
    pts = np.array(data, dtype=float)
    assert_matches_brute_force(pts, eps, min(theiler, len(pts) - 1), l_min)


@pytest.mark.parametrize("laminarity", [True, False])
def test_several_thresholds_in_one_sweep_equal_one_call_each(laminarity):
    pts = trajectory(1500, seed=9)
    eps = [0.01, 0.2, 0.001, 0.05]  # any order; the sweep runs at the largest
    for w in (0, 1, 3):
        many = rqa(pts, eps=eps, theiler=w, laminarity=laminarity)
        assert isinstance(many, tuple) and len(many) == 4
        for e, res in zip(eps, many, strict=True):
            one = rqa(pts, eps=e, theiler=w, laminarity=laminarity)
            assert res.eps == e
            for key, value in one.to_dict().items():
                np.testing.assert_equal(res.to_dict()[key], value, err_msg=key)
    assert rqa(pts, eps=np.array([0.01]))[0].eps == 0.01
    with pytest.raises(ValueError, match="eps"):
        rqa(pts, eps=[])
    with pytest.raises(ValueError, match="eps"):
        rqa(pts, eps=[0.01, -1.0])


def test_rr_is_the_recurrence_rate_with_the_same_theiler_window():
    pts = trajectory(2000, seed=5)
    for w in (0, 1, 4):
        assert rqa(pts, eps=0.02, theiler=w).rr == recurrence_rate(pts, eps=0.02, theiler=w)


def test_off_diagonal_rate_is_n_rr_minus_one_over_n_minus_one():
    # N * RR - 1 = (N - 1) * RR_offdiag: the paper's RR minus its main diagonal
    pts = trajectory(3000, seed=6, tau=0.2)
    n = len(pts)
    for eps in (1e-3, 1e-2):
        rr = recurrence_rate(pts, eps=eps)
        off = recurrence_rate(pts, eps=eps, theiler=1)
        assert off > 0
        assert n * rr - 1 == pytest.approx((n - 1) * off, rel=1e-12)
        assert rqa(pts, eps=eps).rr == off


# ------------------------------------------------------------------ meaning


def test_a_repeated_segment_is_one_diagonal_line_on_each_side():
    seg = np.column_stack([np.linspace(0, 0.9, 10), np.zeros(10)])
    far = np.array([[0.0, 0.9], [0.3, 0.9], [0.6, 0.9]])
    pts = np.vstack([seg, far, seg])  # samples 0..9 recur as 13..22
    res = rqa(pts, eps=1e-3)
    assert res.n_recurrent == 20
    assert (res.det, res.l_mean, res.l_max, res.n_lines) == (1.0, 10.0, 10, 2)
    assert res.lam == 0.0 and np.isnan(res.tt) and res.v_max == 1


def test_isolated_recurrences_have_zero_determinism():
    pts = np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 0.9], [0.0, 0.0]])
    res = rqa(pts, eps=1e-3)
    assert res.n_recurrent == 2 and res.det == 0.0 and res.l_max == 1
    assert np.isnan(res.l_mean) and "l_mean" in res.undefined


def test_a_point_at_rest_is_one_vertical_block():
    pts = np.zeros((6, 2))
    res = rqa(pts, eps=1e-3, theiler=0)
    assert res.rr == 1.0 and res.lam == 1.0 and res.tt == 6.0 and res.v_max == 6
    # the main diagonal counts for theiler = 0; the corners (0, 5), (5, 0) are lines of 1
    assert res.l_max == 6 and res.det == 34 / 36 and res.n_lines == 9


def test_no_recurrence_gives_nan_with_reasons():
    pts = np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]])
    res = rqa(pts, eps=1e-3)
    assert res.n_recurrent == 0 and res.rr == 0.0 and res.l_max == 0 and res.v_max == 0
    assert np.isnan(res.det) and np.isnan(res.lam)
    assert "no recurrent pair" in res.undefined["det"]
    assert isinstance(res, RQAResult) and res.to_dict()["n_points"] == 3


def test_theiler_window_removes_the_lines_along_the_trajectory():
    pts = trajectory(1000, seed=2, tau=0.002)  # consecutive samples recur: long lines
    near = rqa(pts, eps=0.01, theiler=1)
    far = rqa(pts, eps=0.01, theiler=5)
    assert near.l_max > 900 and far.l_max < near.l_max
    assert near.det > far.det


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"l_min": 0}, ValueError, "l_min: must be >= 1"),
        ({"l_min": 2.0}, TypeError, "l_min"),
        ({"l_min": True}, TypeError, "l_min"),
        ({"theiler": 5}, ValueError, "theiler"),
        ({"theiler": -1}, ValueError, "theiler"),
        ({"eps": 0.0}, ValueError, "eps"),
        ({"eps": np.nan}, ValueError, "eps"),
        ({"laminarity": 1}, TypeError, "laminarity"),
    ],
)
def test_bad_arguments_raise(kwargs, error, match):
    pts = np.zeros((5, 2))
    with pytest.raises(error, match=match):
        rqa(pts, **{"eps": 1e-3, **kwargs})


def test_bad_points_raise():
    with pytest.raises(ValueError, match="points"):
        rqa(np.zeros((4, 3)), eps=1e-3)
    with pytest.raises(ValueError, match="finite"):
        rqa(np.array([[0.0, np.nan], [0.0, 0.0]]), eps=1e-3)
