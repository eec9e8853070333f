"""Recurrence rate and recurrence plots of a sampled planar trajectory.

The recurrence matrix of N points ``x_1..x_N`` in the plane is
``R_ij = Theta(eps - |x_i - x_j|)`` (L2 norm) and the recurrence rate is its density,
``RR(eps) = (1/N^2) sum_ij R_ij``. Neither is ever built as an N x N matrix: pairs closer
than ``eps`` are found with a cell list of square cells of side just above ``eps``, so
that every recurrent pair lies in the same or in adjacent cells. The occupied cells are
found by an O(N) radix sort of integer cell keys (a dense grid of ``(2/eps)^2`` cells
would not fit in memory for small ``eps``; the line statistics of `rqa` use one when it
has at most a few cells per point), and one sweep over the sorted cells visits
each cell's own points and its four "forward" neighbours (the other four are visited
from the other side), so every unordered pair is examined once. Memory is O(N), time is
O(N + number of candidate pairs), and by a packing argument the candidate pairs (all
within ``2 sqrt(2) eps``) are at most a constant times ``N`` plus the recurrent pairs.

Conventions (see docs/diagnostics.md):

* the distance test is ``dx*dx + dy*dy <= eps*eps`` in float64, i.e. Theta(0) = 1 as in
  Marwan et al. (2007), and brute force with the same expression agrees exactly;
* the main diagonal (the line of identity) is included unless a Theiler window is set,
  so RR >= 1/N;
* with a Theiler window ``w >= 1`` the pairs with ``|i - j| < w`` are excluded from the
  count *and* from the normalisation, which becomes the number of admissible entries
  ``(N - w)(N - w + 1)`` (Webber & Zbilut 2005; Marwan & Webber 2015; the convention of
  RecurrenceAnalysis.jl). ``w = 0`` means no exclusion and the 1/N^2 of the paper.
"""

from __future__ import annotations

import numbers

import numpy as np

from kicktimes.validation import keyword_only_after

__all__ = ["recurrence_pairs", "recurrence_rate"]

# Cells are a hair larger than eps so that round-off in the cell coordinate
# (x - xmin) / h (at most a few 2^-53 relative, i.e. < 1e-7 cells with the cap below)
# can never put two points with |dx| <= eps two cells apart.
_CELL_PAD = 1.0 + 1e-6
# At most 2^26 cells per axis: keys stay below 2^53 and round-off stays far below 1 cell.
# Only reached for eps < 3e-8 * extent, where the coarser cells cost nothing in practice.
_MAX_CELLS_PER_AXIS = float(2**26)
# The coordinates must span at most this in x and in y: the distance test dx*dx + dy*dy
# then cannot overflow (2 * 1e300 < 1.8e308), and neither can the extent of the cell grid
# (beyond the float range it was inf, and the cell count (xmax - xmin) / inf NaN).
_MAX_SPREAD = 1e150
# The line sweep of `rqa` uses a dense grid (an offset per cell, occupied or not) when it
# has at most this many cells per point (plus a floor that small point sets may use):
# eps = 1e-2 in the unit disk, ~40 000 cells, for N >= 2 000; eps = 1e-3 (4 million
# cells) keeps the radix-sorted occupied cells, whose memory is O(N).
_DENSE_CELLS_PER_POINT = 8
_DENSE_CELLS_MIN = 2**16

from kicktimes.diagnostics._recurrence_kernels import (  # noqa: E402
    _COLLECT,
    _COUNT,
    _bounding_box,
    _build_cells,
    _build_cells_lines,
    _dense_cells_lines,
    _diagonal_vertical,
    _rows_from_pairs,
    _sweep,
    _sweep_lines,
    _sweep_lines_dense,
)

# ------------------------------------------------------------------------- front end


def _as_points(points) -> np.ndarray:
    """(N, 2) float64 C-contiguous view of ``points`` (no copy when already so)."""
    if hasattr(points, "samples") and not isinstance(points, np.ndarray):
        # a run record: its samples are the tracked disk's centres at the sample times
        points = points.samples
    try:
        arr = np.asarray(points)
    except Exception as exc:  # e.g. ragged lists
        raise TypeError(f"points: expected an (N, 2) array of floats, got {points!r}") from exc
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)
    ):
        raise TypeError(f"points: expected a real (N, 2) array, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(
            f"points: expected shape (N, 2) (planar positions; other dimensions are not "
            f"supported), got shape {arr.shape}"
        )
    if arr.shape[0] == 0:
        raise ValueError("points: need at least one point, got N = 0")
    return np.ascontiguousarray(arr, dtype=np.float64)


#: the smallest threshold whose square is a normal float64 (pairs compare squared lengths)
EPS_MIN = float(np.sqrt(np.finfo(np.float64).tiny))


def _check_eps(eps) -> float:
    if isinstance(eps, np.ndarray) and eps.ndim == 0:
        eps = eps.item()
    if isinstance(eps, bool) or not isinstance(eps, numbers.Real):
        raise TypeError(f"eps: expected a positive finite float, got {eps!r}")
    eps = float(eps)
    if not (np.isfinite(eps) and eps > 0.0):
        raise ValueError(f"eps: must be positive and finite (0 < eps < inf), got {eps!r}")
    if eps < EPS_MIN:
        raise ValueError(
            f"eps: must be at least {EPS_MIN:.4g}, so that eps**2 is a normal float64 (pairs "
            f"compare squared distances), got {eps!r}"
        )
    return eps


def _check_theiler(theiler, n: int) -> int:
    if isinstance(theiler, bool) or not isinstance(theiler, numbers.Integral):
        raise TypeError(f"theiler: expected a non-negative int, got {theiler!r}")
    theiler = int(theiler)
    if theiler < 0:
        raise ValueError(f"theiler: must be >= 0 (0 = no exclusion), got {theiler}")
    if theiler >= n:
        raise ValueError(
            f"theiler: a window of {theiler} excludes every pair of N = {n} points; "
            f"need 0 <= theiler < N"
        )
    return theiler


def _grid(pts: np.ndarray, eps: float):
    """``xmin, ymin, inv_h, ncx, ncy, n_bits`` of the cells of side just above ``eps``
    (``ncx`` columns and ``ncy`` rows, padding included; keys below ``2**n_bits``)."""
    xmin, xmax, ymin, ymax, finite = _bounding_box(pts)
    if not finite:
        bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
        raise ValueError(
            f"points: must be finite; row {bad[0]} is {pts[bad[0]].tolist()} "
            f"({bad.size} non-finite rows)"
        )
    extent = max(xmax - xmin, ymax - ymin)
    if not extent <= _MAX_SPREAD:
        raise ValueError(
            f"points: the coordinates must span at most {_MAX_SPREAD:g} in x and in y (so that "
            f"dx**2 + dy**2 cannot overflow), got x in [{float(xmin)!r}, {float(xmax)!r}] and "
            f"y in [{float(ymin)!r}, {float(ymax)!r}]"
        )
    h = max(eps * _CELL_PAD, extent / _MAX_CELLS_PER_AXIS)
    inv_h = 1.0 / h
    ncx = int(np.floor((xmax - xmin) * inv_h)) + 3  # 1-based columns plus padding
    ncy = int(np.floor((ymax - ymin) * inv_h)) + 3
    n_bits = max(1, int(ncx * ncy - 1).bit_length())
    return xmin, ymin, inv_h, ncx, ncy, n_bits


def _cells(pts: np.ndarray, eps: float):
    xmin, ymin, inv_h, ncx, _, n_bits = _grid(pts, eps)
    xs, ys, perm, cell_start, cell_key = _build_cells(pts, xmin, ymin, inv_h, ncx, n_bits)
    return xs, ys, perm, cell_start, cell_key, ncx


_EMPTY = np.empty(0, np.int64)


@keyword_only_after(1, since="0.2.0", names=('eps',))
def recurrence_rate(points, *, eps=1e-3, theiler=0):
    r"""Recurrence rate of a sampled planar trajectory.

    .. math::

        RR(\varepsilon) = \frac{1}{N^2} \sum_{i,j=1}^{N}
            \Theta\bigl(\varepsilon - \lVert x_i - x_j \rVert_2\bigr),
        \qquad \Theta(0) = 1,

    over all ordered pairs including the main diagonal, so ``RR >= 1/N``. Computed with
    a cell list in O(N) memory, exactly equal to brute-force counting.

    Parameters
    ----------
    points : array_like, shape (N, 2), or a run record
        Sampled positions (e.g. ``run.samples``, the tracked disk's centre at the sample
        times; a run record is accepted directly, in any table). Only planar points are
        supported. For the recurrences of the boundary map pass
        `kicktimes.diagnostics.boundary_map` (Birkhoff's ``(arc / L, sin_theta)``, the
        same coordinates in the circle, the stadium and the ellipse).
    eps : float or array_like of float, default 1e-3
        Recurrence threshold(s) ``eps > 0``. A pair is recurrent when
        ``dx**2 + dy**2 <= eps**2`` in float64. An array gives one RR per threshold.
    theiler : int, default 0
        Theiler window ``w``: pairs with ``|i - j| < w`` are excluded (``w = 0``: none;
        ``w = 1``: the main diagonal only). For ``w >= 1`` the normalisation is the number
        of admissible entries, ``(N - w)(N - w + 1)``, not ``N^2``; requires ``w < N``.

    Returns
    -------
    float or ndarray
        RR in ``[1/N, 1]`` for ``theiler=0``, in ``[0, 1]`` otherwise; an array when
        ``eps`` is an array.

    Raises
    ------
    ValueError
        Points not of shape (N, 2), empty or non-finite, or spanning more than 1e150 in x
        or y (``dx**2 + dy**2`` would overflow); ``eps`` not positive and finite, or
        below ``EPS_MIN`` = 1.49e-154 (``eps**2`` subnormal);
        ``theiler`` negative or ``>= N``.
    TypeError
        Non-numeric points, eps or theiler.

    Notes
    -----
    Cells of side ``h`` slightly above ``eps`` are keyed by ``cy * ncx + cx`` and sorted by
    an O(N) radix sort; a sweep visits each cell's own pairs and its four forward
    neighbours. Time O(N + pairs within ``2 sqrt(2) eps``), memory about 45 bytes/point.

    References
    ----------
    N. Marwan, M. C. Romano, M. Thiel, J. Kurths, "Recurrence plots for the analysis of
    complex systems", Phys. Rep. 438, 237 (2007). C. L. Webber, J. P. Zbilut, "Recurrence
    quantification analysis of nonlinear dynamical systems" (2005), for the Theiler
    window normalisation.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.diagnostics import recurrence_rate
    >>> pts = np.array([[0.0, 0.0], [0.0005, 0.0], [0.5, 0.5]])
    >>> recurrence_rate(pts, eps=1e-3) * 9      # 3 diagonal entries + the pair, twice
    5.0
    >>> recurrence_rate(pts, eps=1e-3, theiler=1) * 6   # (N - 1) N admissible entries
    2.0
    """
    pts = _as_points(points)
    n = pts.shape[0]
    w = _check_theiler(theiler, n)
    if np.ndim(eps) == 0:
        return _recurrence_rate_one(pts, _check_eps(eps), w)
    eps_arr = np.asarray(eps)
    if eps_arr.ndim != 1 or eps_arr.size == 0:
        raise ValueError(
            f"eps: expected a float or a non-empty 1-D array, got shape {eps_arr.shape}"
        )
    return np.array([_recurrence_rate_one(pts, _check_eps(e.item()), w) for e in eps_arr])


def _recurrence_rate_one(pts: np.ndarray, eps: float, w: int) -> float:
    n = pts.shape[0]
    xs, ys, perm, cell_start, cell_key, ncx = _cells(pts, eps)
    pairs = _sweep(
        xs, ys, perm, cell_start, cell_key, ncx, eps * eps, max(w, 1), _COUNT, _EMPTY, _EMPTY
    )
    if w == 0:
        # Python ints: N^2 overflows nothing, and the division is correctly rounded
        return (n + 2 * int(pairs)) / (n * n)
    k = n - w
    return 2 * int(pairs) / (k * (k + 1))


@keyword_only_after(1, since="0.2.0", names=('eps',))
def recurrence_pairs(points, *, eps=1e-3, theiler=0):
    r"""The recurrence plot as index pairs: every ``(i, j)`` of samples within ``eps``.

    Returns the nonzero entries of the recurrence matrix
    ``R_ij = Theta(eps - |x_i - x_j|)`` (both orders, main diagonal included unless a
    Theiler window removes it), never the N x N matrix. ``len(i) / N**2`` equals
    ``recurrence_rate(points, eps=eps)`` for ``theiler=0``.

    Parameters
    ----------
    points : array_like, shape (N, 2), or a run record
        Sampled planar positions.
    eps : float, default 1e-3
        Recurrence threshold, ``eps > 0`` (pairs with ``dx**2 + dy**2 <= eps**2``).
    theiler : int, default 0
        Exclude pairs with ``|i - j| < theiler`` (0: none; 1: the main diagonal).

    Returns
    -------
    i, j : ndarray of int64
        Row and column indices, sorted lexicographically by ``(i, j)``; the matrix is
        symmetric, so ``(j, i)`` is present whenever ``(i, j)`` is.

    Raises
    ------
    ValueError, TypeError
        As `recurrence_rate`.

    Notes
    -----
    One sweep of the cell list collects the pairs (a second one only when they exceed a
    buffer of a few per point), then two O(N + pairs) bucket passes put them in sorted
    rows. Memory is O(N + pairs); beware that for large ``eps`` the pair count approaches
    ``N^2``.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.diagnostics import recurrence_pairs
    >>> i, j = recurrence_pairs(np.array([[0.0, 0.0], [0.0005, 0.0], [0.5, 0.5]]), eps=1e-3)
    >>> i.tolist(), j.tolist()
    ([0, 0, 1, 1, 2], [0, 1, 0, 1, 2])

    A recurrence plot: ``plt.scatter(i, j, s=0.1)`` (or a sparse matrix,
    ``scipy.sparse.coo_array((np.ones(i.size, bool), (i, j)), shape=(N, N))``).
    """
    pts = _as_points(points)
    n = pts.shape[0]
    w = _check_theiler(theiler, n)
    eps = _check_eps(eps)
    offsets, out_j = _pairs_csr(pts, eps, w)
    out_i = np.repeat(np.arange(n, dtype=np.int64), np.diff(offsets))
    return out_i, out_j


def _pairs_csr(pts: np.ndarray, eps: float, w: int):
    """The recurrence plot as sorted rows: ``cols[offsets[i]:offsets[i+1]]`` are the ``j``.

    Both orders of every pair, and the diagonal when ``w == 0``; rows sorted increasingly.
    One sweep collects the unordered pairs into a buffer sized for a few per point; only
    when they do not fit (large ``eps``) is the sweep repeated with the exact size.
    """
    n = pts.shape[0]
    xs, ys, perm, cell_start, cell_key, ncx = _cells(pts, eps)
    cap = 4 * n + 1024
    while True:
        buf = np.empty(2 * cap, np.int64)
        count = np.zeros(1, np.int64)
        _sweep(xs, ys, perm, cell_start, cell_key, ncx, eps * eps, max(w, 1), _COLLECT, count, buf)
        m = int(count[0])
        if m <= cap:
            break
        cap = m
    return _rows_from_pairs(buf, m, n, w == 0)


def _line_sums(pts: np.ndarray, eps_list, w: int, l_min: int, vertical: bool):
    """(pairs, diag, vert) for each threshold of ``eps_list`` (decreasing), in one sweep.

    ``pairs[k]``: recurrent unordered pairs ``i != j`` outside the window at
    ``eps_list[k]``; ``diag[k] = (l_min, lines, entries on them, longest)`` over the
    diagonal lines of the upper triangle (the main diagonal is left to the caller), where
    ``lines`` counts those of length ``>= l_min``; ``vert[k]`` the same for the vertical
    lines of the whole matrix (zeros unless ``vertical``), over the admissible entries
    ``|i - j| >= w``. The cell list is built for the largest threshold, whose candidate
    pairs contain those of the smaller ones. O(N) memory (the cells and the time
    neighbours); no pair and no histogram is stored. The vertical lines are accounted in
    the same sweep, at both entries of each pair (`_account_vertical`), plus the
    diagonal's entries when ``w = 0`` (`_diagonal_vertical`).
    """
    m = len(eps_list)
    xmin, ymin, inv_h, ncx, ncy, n_bits = _grid(pts, eps_list[0])
    eps2s = np.array([e * e for e in eps_list])
    pairs = np.zeros(m, np.int64)
    diag = np.zeros((m, 4), np.int64)
    vert = np.zeros((m if vertical else 0, 4), np.int64)
    diag[:, 0] = vert[:, 0] = l_min
    if ncx * ncy <= _DENSE_CELLS_PER_POINT * pts.shape[0] + _DENSE_CELLS_MIN:
        g, perm, skey, start = _dense_cells_lines(pts, xmin, ymin, inv_h, ncx, ncx * ncy)
        _sweep_lines_dense(
            g, perm, skey, start, ncx, max(w, 1), pts, eps2s, pairs, diag, w, vert
        )
    else:
        g, perm, cell_start, cell_key = _build_cells_lines(pts, xmin, ymin, inv_h, ncx, n_bits)
        _sweep_lines(
            g, perm, cell_start, cell_key, ncx, max(w, 1), pts, eps2s, pairs, diag, w, vert
        )
    if vertical and w == 0:
        _diagonal_vertical(pts, eps2s, vert)
    if not vertical:
        vert = np.zeros((m, 4), np.int64)
    return pairs, diag, vert
