"""Specification of the recurrence rate and the recurrence plot (kicktimes.diagnostics)."""

from __future__ import annotations

import functools
import types

import numpy as np
import pytest
from _references import chord_trajectory
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal
from scipy.spatial import cKDTree

from kicktimes.diagnostics import recurrence_pairs, recurrence_rate

# ------------------------------------------------------------------ references


def brute_matrix(points: np.ndarray, eps: float, theiler: int = 0) -> np.ndarray:
    """The full recurrence matrix, straight from the definition (same float expression)."""
    dx = points[:, None, 0] - points[None, :, 0]
    dy = points[:, None, 1] - points[None, :, 1]
    mat = dx * dx + dy * dy <= eps * eps
    if theiler:
        n = len(points)
        i, j = np.indices((n, n))
        mat &= np.abs(i - j) >= theiler
    return mat


def brute_rate(points: np.ndarray, eps: float, theiler: int = 0) -> float:
    n = len(points)
    count = int(brute_matrix(points, eps, theiler).sum())
    if theiler == 0:
        return count / (n * n)
    k = n - theiler
    return count / (k * (k + 1))


# ------------------------------------------------------------------ point sets


def uniform_disk(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(size=n))
    a = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


def clustered(n: int, seed: int) -> np.ndarray:
    """Points on three circles and two lines, many of them exact duplicates."""
    rng = np.random.default_rng(seed)
    kind = rng.integers(0, 5, n)
    u = rng.uniform(0.0, 1.0, n)
    u = np.round(u * 400) / 400  # coarse grid along each curve: duplicates
    pts = np.empty((n, 2))
    for k, (cx, cy, rad) in enumerate([(0.0, 0.0, 0.5), (0.2, -0.1, 0.01), (-0.3, 0.3, 0.002)]):
        sel = kind == k
        pts[sel, 0] = cx + rad * np.cos(2 * np.pi * u[sel])
        pts[sel, 1] = cy + rad * np.sin(2 * np.pi * u[sel])
    sel = kind == 3
    pts[sel] = np.column_stack([u[sel] - 0.5, np.full(sel.sum(), 0.25)])
    sel = kind == 4
    pts[sel] = np.column_stack([np.full(sel.sum(), -0.1), 0.01 * u[sel]])
    return pts


POINT_SETS = {
    "uniform": uniform_disk(2500, seed=1),
    "clustered": clustered(3000, seed=2),
    "trajectory": chord_trajectory(3000, seed=3),
    "integrable_trajectory": chord_trajectory(2000, seed=4, kicked=False),
}


# ------------------------------------------------------------------ exactness


@functools.cache
def squared_distances(name: str) -> np.ndarray:
    """The N x N squared distances of a named point set, computed once per session."""
    pts = POINT_SETS[name]
    dx = pts[:, None, 0] - pts[None, :, 0]
    dy = pts[:, None, 1] - pts[None, :, 1]
    return dx * dx + dy * dy


@pytest.mark.parametrize("name", sorted(POINT_SETS))
@pytest.mark.parametrize("eps", [1e-3, 1e-2, 0.05, 0.3])
@pytest.mark.parametrize("theiler", [0, 1, 5])
def test_recurrence_rate_equals_brute_force(name, eps, theiler):
    pts = POINT_SETS[name]
    n = len(pts)
    recurrent = squared_distances(name) <= eps * eps  # the definition, same float expression
    count = int(recurrent.sum()) - int(np.trace(recurrent))  # off-diagonal
    for d in range(1, theiler):  # the Theiler band |i - j| < w, both sides
        count -= 2 * int(np.diagonal(recurrent, d).sum())
    expected = (count + n) / n**2 if theiler == 0 else count / ((n - theiler) * (n - theiler + 1))
    assert recurrence_rate(pts, eps=eps, theiler=theiler) == expected


@pytest.mark.parametrize("name", sorted(POINT_SETS))
@pytest.mark.parametrize("theiler", [0, 3])
def test_recurrence_pairs_equal_brute_force_pair_set_in_sorted_order(name, theiler):
    pts = POINT_SETS[name][:1500]
    i, j = recurrence_pairs(pts, eps=0.02, theiler=theiler)
    bi, bj = np.nonzero(brute_matrix(pts, 0.02, theiler))  # row-major: sorted by (i, j)
    assert i.dtype == np.int64 and j.dtype == np.int64
    assert_array_equal(i, bi)
    assert_array_equal(j, bj)


def test_pair_count_over_n_squared_is_the_recurrence_rate():
    pts = POINT_SETS["clustered"]
    i, _ = recurrence_pairs(pts, eps=0.01)
    assert i.size / len(pts) ** 2 == recurrence_rate(pts, eps=0.01)


def test_recurrence_plot_is_symmetric_and_contains_the_diagonal():
    pts = POINT_SETS["trajectory"]
    i, j = recurrence_pairs(pts, eps=0.05)
    pairs = set(zip(i.tolist(), j.tolist(), strict=True))
    assert all((b, a) in pairs for a, b in pairs)
    assert all((a, a) in pairs for a in range(len(pts)))


def test_theiler_window_of_one_removes_exactly_the_diagonal():
    pts = POINT_SETS["uniform"]
    i, j = recurrence_pairs(pts, eps=0.05, theiler=1)
    i0, j0 = recurrence_pairs(pts, eps=0.05)
    assert not np.any(i == j)
    assert i.size == i0.size - len(pts)


def test_theiler_normalisation_counts_admissible_pairs_only():
    # three coincident points: every admissible entry is a recurrence, so RR = 1
    pts = np.zeros((3, 2))
    assert recurrence_rate(pts, eps=0.1) == 1.0
    assert recurrence_rate(pts, eps=0.1, theiler=1) == 1.0  # 6 of 6 off-diagonal entries
    assert recurrence_rate(pts, eps=0.1, theiler=2) == 1.0  # (0, 2) and (2, 0) only


@pytest.mark.parametrize("eps", [5e-324, 1e-320, 1e-200, 1.4e-154])
def test_a_threshold_whose_square_is_subnormal_is_refused_by_name(eps):
    with pytest.raises(ValueError, match=r"eps: must be at least 1\.492e-154"):
        recurrence_rate(np.zeros((3, 2)), eps=eps)


def test_the_smallest_threshold_counts_exactly():
    from kicktimes.diagnostics.recurrence import EPS_MIN

    pts = np.array([[0.0, 0.0], [EPS_MIN, 0.0], [0.0, 3 * EPS_MIN]])
    assert recurrence_rate(pts, eps=EPS_MIN) == 5 / 9


def test_points_exactly_eps_apart_are_recurrent():
    # 0.25 and its squares are exact in binary: the tie |x_i - x_j| = eps counts
    pts = np.array([[0.0, 0.0], [0.25, 0.0], [0.25, 0.25], [0.75, 0.25]])
    assert recurrence_rate(pts, eps=0.25) * 16 == 4 + 2 * 2
    assert recurrence_rate(pts, eps=np.nextafter(0.25, 0.0)) * 16 == 4


def test_lattice_with_spacing_eps_matches_brute_force():
    # many near-ties: spacing eps in float arithmetic lands on both sides of eps
    g = np.arange(40) * 1e-3
    pts = np.column_stack([np.repeat(g, 40), np.tile(g, 40)]) + 0.123
    assert recurrence_rate(pts, eps=1e-3) == brute_rate(pts, 1e-3)


def test_pairs_almost_exactly_eps_apart_are_found_wherever_they_sit():
    # 10^4 isolated pairs, each |dx| or |dy| within round-off of eps, at random offsets
    # relative to any cell grid: a cell list with cells even 0.1 % smaller than eps would
    # miss about ten of them. Expected count from the definition, pair by pair.
    rng = np.random.default_rng(9)
    eps = 1e-3
    g = np.arange(100) * 0.01
    base = np.column_stack([np.repeat(g, 100), np.tile(g, 100)])
    base += rng.uniform(0.0, 0.002, base.shape)
    step = np.where(rng.uniform(size=(len(base), 1)) < 0.5, [[eps, 0.0]], [[0.0, -eps]])
    # half just inside eps (certainly recurrent), half at eps (ties, either side)
    step *= np.where(rng.uniform(size=(len(base), 1)) < 0.5, 1.0 - 1e-11, 1.0)
    partner = base + step
    d = base - partner
    recurrent = int(np.count_nonzero(d[:, 0] ** 2 + d[:, 1] ** 2 <= eps * eps))
    assert 5000 < recurrent < 10_000  # both sides of the tie occur
    pts = np.concatenate([base, partner])
    n = len(pts)
    assert recurrence_rate(pts, eps=eps) == (n + 2 * recurrent) / n**2


def test_rate_includes_the_diagonal_so_is_at_least_one_over_n():
    pts = POINT_SETS["uniform"]
    n = len(pts)
    assert recurrence_rate(pts, eps=1e-9) == 1.0 / n  # no two points that close
    for eps in (1e-4, 1e-3, 1e-2):
        assert recurrence_rate(pts, eps=eps) >= 1.0 / n


def test_duplicated_points_all_recur():
    pts = np.repeat(POINT_SETS["uniform"][:50], 4, axis=0)
    assert recurrence_rate(pts, eps=1e-12) == 4 / len(pts)  # each point has 4 copies


def test_single_point_has_rate_one():
    assert recurrence_rate(np.array([[0.1, 0.2]]), eps=1e-3) == 1.0


def test_rate_grows_with_eps_and_reaches_one():
    pts = POINT_SETS["trajectory"]
    rates = recurrence_rate(pts, eps=np.array([1e-3, 1e-2, 0.1, 1.0, 2.0]))
    assert np.all(np.diff(rates) > 0)
    assert rates[-1] == 1.0  # the diameter of the table is 2


def test_array_of_eps_gives_the_scalar_values():
    pts = POINT_SETS["clustered"]
    eps = [1e-3, 0.02, 0.2]
    assert_array_equal(recurrence_rate(pts, eps=eps), [recurrence_rate(pts, eps=e) for e in eps])


def test_rate_does_not_depend_on_the_order_of_points():
    pts = POINT_SETS["clustered"]
    perm = np.random.default_rng(0).permutation(len(pts))
    assert recurrence_rate(pts[perm], eps=0.01) == recurrence_rate(pts, eps=0.01)


def test_tiny_eps_on_a_large_extent_uses_coarse_cells_exactly():
    # 1e6 / 2^26 > eps: the cell size is capped above eps, the count must stay exact
    rng = np.random.default_rng(5)
    base = rng.uniform(0.0, 1e6, (300, 2))
    pts = np.concatenate([base, base + rng.normal(0.0, 1e-3, base.shape), [[0.0, 0.0]]])
    assert recurrence_rate(pts, eps=1e-3) == brute_rate(pts, 1e-3)
    assert recurrence_rate(pts, eps=1e-3) > 1.0 / len(pts)


def test_strided_integer_and_run_inputs_are_accepted():
    pts = POINT_SETS["uniform"][:1000]
    ref = recurrence_rate(pts, eps=0.03)
    assert recurrence_rate(np.asfortranarray(pts), eps=0.03) == ref
    assert recurrence_rate(np.hstack([pts, pts])[:, :2], eps=0.03) == ref  # strided view
    assert recurrence_rate(types.SimpleNamespace(samples=pts), eps=0.03) == ref
    grid = np.array([[0, 0], [1, 0], [5, 5]])
    assert recurrence_rate(grid, eps=1.0) * 9 == 5


def test_run_records_are_read_through_their_samples():
    import kicktimes as kt

    ic = kt.initial_conditions(1, 0.03, rng=3)[0]
    run = kt.simulate_two_particle(ic, 0.03, n_steps=5000, tau=0.2)
    n = len(run.samples)
    assert recurrence_rate(run) == recurrence_rate(run.samples) >= 1.0 / n
    assert recurrence_rate(run) == brute_rate(np.asarray(run.samples), 1e-3)


@pytest.mark.parametrize("name", ["uniform", "trajectory"])
def test_count_agrees_with_scipy_kdtree_at_larger_n(name):
    pts = uniform_disk(40_000, seed=6) if name == "uniform" else chord_trajectory(20_000, seed=7)
    tree = cKDTree(pts)
    for eps in (1e-3, 1e-2):
        ordered = tree.count_neighbors(tree, eps)  # ordered pairs, diagonal included
        assert recurrence_rate(pts, eps=eps) == ordered / len(pts) ** 2


@settings(max_examples=150, deadline=None)
@given(
    data=st.lists(
        st.tuples(
            st.sampled_from([0.0, 0.001, 0.0015, 0.002, 0.01, -0.003, 0.5]),
            st.floats(-0.01, 0.01, allow_nan=False, allow_subnormal=False),
        ),
        min_size=1,
        max_size=60,
    ),
    eps=st.sampled_from([1e-4, 1e-3, 0.0015, 2e-3, 5e-3, 0.05]),
    theiler=st.integers(0, 4),
)
def test_property_rate_and_pairs_equal_brute_force(data, eps, theiler):
    pts = np.array(data, dtype=float)
    theiler = min(theiler, len(pts) - 1)
    assert recurrence_rate(pts, eps=eps, theiler=theiler) == brute_rate(pts, eps, theiler)
    i, j = recurrence_pairs(pts, eps=eps, theiler=theiler)
    bi, bj = np.nonzero(brute_matrix(pts, eps, theiler))
    assert_array_equal(i, bi)
    assert_array_equal(j, bj)


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("points", "match"),
    [
        (np.zeros((5, 3)), "points: expected shape"),
        (np.zeros(5), "points: expected shape"),
        (np.zeros((0, 2)), "N = 0"),
        (np.array([[0.0, 0.0], [np.nan, 1.0]]), "points: must be finite; row 1"),
        (np.array([[0.0, np.inf], [0.0, 1.0]]), "points: must be finite; row 0"),
    ],
)
def test_bad_points_raise_value_error(points, match):
    with pytest.raises(ValueError, match=match):
        recurrence_rate(points, eps=1e-3)
    with pytest.raises(ValueError, match=match):
        recurrence_pairs(points, eps=1e-3)


@pytest.mark.parametrize(
    "points",
    [
        np.array([[1e308, 0.0], [-1e308, 0.5]]),  # x - xmin overflows to inf
        np.array([[0.0, -1e308], [0.5, 1e308]]),
        np.array([[0.0, 0.0], [1e200, 0.0]]),  # finite spread, but dx**2 overflows
    ],
)
def test_points_spreading_beyond_the_float_range_raise_value_error(points):
    # the cell grid took (xmax - xmin) * (1 / inf) = NaN cells ("cannot convert float NaN
    # to integer"), or the distance test dx**2 + dy**2 <= eps**2 overflowed
    match = r"points: the coordinates must span at most 1e\+150 in x and in y"
    for fun in (recurrence_rate, recurrence_pairs):
        with pytest.raises(ValueError, match=match):
            fun(points, eps=1e-3)


def test_points_spreading_up_to_the_bound_are_counted_exactly():
    pts = np.array([[0.0, 0.0], [1e-4, 0.0], [1e150, 0.0], [1e150, 1e-4], [0.0, 1e150]])
    assert recurrence_rate(pts, eps=1e-3) == (5 + 2 * 2) / 25
    assert recurrence_rate(pts, eps=1e300) == 1.0  # eps**2 = inf: every (finite) d**2 is below


def test_non_numeric_points_raise_type_error():
    with pytest.raises(TypeError, match="points"):
        recurrence_rate(np.array([["a", "b"]]), eps=1e-3)


@pytest.mark.parametrize("eps", [0.0, -1e-3, np.nan, np.inf])
def test_bad_eps_raises_value_error(eps):
    with pytest.raises(ValueError, match="eps: must be positive and finite"):
        recurrence_rate(np.zeros((3, 2)), eps=eps)
    with pytest.raises(ValueError, match="eps"):
        recurrence_rate(np.zeros((3, 2)), eps=[1e-3, eps])


@pytest.mark.parametrize("eps", ["0.1", None, True])
def test_non_numeric_eps_raises_type_error(eps):
    with pytest.raises(TypeError, match="eps"):
        recurrence_pairs(np.zeros((3, 2)), eps=eps)


@pytest.mark.parametrize(
    ("theiler", "error", "match"),
    [
        (-1, ValueError, "theiler: must be >= 0"),
        (3, ValueError, "need 0 <= theiler < N"),
        (1.0, TypeError, "theiler"),
        (True, TypeError, "theiler"),
    ],
)
def test_bad_theiler_raises(theiler, error, match):
    with pytest.raises(error, match=match):
        recurrence_rate(np.zeros((3, 2)), eps=0.1, theiler=theiler)
    with pytest.raises(error, match=match):
        recurrence_pairs(np.zeros((3, 2)), eps=0.1, theiler=theiler)


# ------------------------------------------------------------------ paper scale


@pytest.mark.slow
def test_paper_scale_count_agrees_with_kdtree():
    pts = uniform_disk(1_000_000, seed=8)
    tree = cKDTree(pts)
    assert recurrence_rate(pts, eps=1e-3) == tree.count_neighbors(tree, 1e-3) / len(pts) ** 2
