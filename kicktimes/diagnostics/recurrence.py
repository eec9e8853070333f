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
from numba import njit

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
_RADIX_BITS = 11
# The line sweep of `rqa` uses a dense grid (an offset per cell, occupied or not) when it
# has at most this many cells per point (plus a floor that small point sets may use):
# eps = 1e-2 in the unit disk, ~40 000 cells, for N >= 2 000; eps = 1e-3 (4 million
# cells) keeps the radix-sorted occupied cells, whose memory is O(N).
_DENSE_CELLS_PER_POINT = 8
_DENSE_CELLS_MIN = 2**16

# Modes of the pair sweep: count the pairs, or also collect them into a buffer.
# (The line statistics of `rqa` have their own kernels, `_sweep_lines` and `_sweep_lines_dense`.)
_COUNT, _COLLECT = 0, 1


# --------------------------------------------------------------------------- kernels


@njit(cache=True)
def _bounding_box(points):
    """(xmin, xmax, ymin, ymax, all finite) of an (N, 2) array, in one pass."""
    xmin = np.inf
    xmax = -np.inf
    ymin = np.inf
    ymax = -np.inf
    finite = True
    for k in range(points.shape[0]):
        x = points[k, 0]
        y = points[k, 1]
        if not (np.isfinite(x) and np.isfinite(y)):
            finite = False
            break
        xmin = min(xmin, x)
        xmax = max(xmax, x)
        ymin = min(ymin, y)
        ymax = max(ymax, y)
    return xmin, xmax, ymin, ymax, finite


@njit(cache=True)
def _radix_argsort(keys, n_bits):
    """Stable LSD radix argsort of non-negative int64 keys below ``2**n_bits``.

    Returns ``(perm, sorted keys)``; ``keys`` is used as scratch space (overwritten).
    O(N) per 11-bit digit: for the cell keys of eps = 1e-3 in the unit disk (22 bits)
    that is two passes, faster than a comparison sort for N ~ 10^5..10^7.
    """
    n = keys.shape[0]
    nbuck = 1 << _RADIX_BITS
    mask = nbuck - 1
    perm = np.arange(n)
    k_cur = keys
    k_tmp = np.empty_like(keys)
    p_tmp = np.empty_like(perm)
    count = np.empty(nbuck, np.int64)
    shift = 0
    while shift < n_bits:
        count[:] = 0
        for a in range(n):
            count[(k_cur[a] >> shift) & mask] += 1
        total = 0
        for b in range(nbuck):
            c = count[b]
            count[b] = total
            total += c
        for a in range(n):
            d = (k_cur[a] >> shift) & mask
            pos = count[d]
            count[d] = pos + 1
            k_tmp[pos] = k_cur[a]
            p_tmp[pos] = perm[a]
        k_cur, k_tmp = k_tmp, k_cur
        perm, p_tmp = p_tmp, perm
        shift += _RADIX_BITS
    return perm, k_cur


@njit(cache=True)
def _cell_keys(points, xmin, ymin, inv_h, ncx):
    """Cell key ``cy * ncx + cx`` of every point (1-based cell coordinates, see
    `_build_cells`)."""
    n = points.shape[0]
    keys = np.empty(n, np.int64)
    for a in range(n):
        cx = np.int64((points[a, 0] - xmin) * inv_h) + 1
        cy = np.int64((points[a, 1] - ymin) * inv_h) + 1
        keys[a] = cy * ncx + cx
    return keys


@njit(cache=True)
def _cell_table(skeys):
    """``cell_start, cell_key`` of sorted keys: cell ``c`` holds sorted positions
    ``cell_start[c] : cell_start[c + 1]``."""
    n = skeys.shape[0]
    n_cells = 0
    for a in range(n):
        if a == 0 or skeys[a] != skeys[a - 1]:
            n_cells += 1
    cell_start = np.empty(n_cells + 1, np.int64)
    cell_key = np.empty(n_cells, np.int64)
    c = 0
    for a in range(n):
        if a == 0 or skeys[a] != skeys[a - 1]:
            cell_start[c] = a
            cell_key[c] = skeys[a]
            c += 1
    cell_start[n_cells] = n
    return cell_start, cell_key


@njit(cache=True)
def _build_cells(points, xmin, ymin, inv_h, ncx, n_bits):
    """Sort the points by cell; return sorted coordinates, permutation and cell table.

    Cell ``(cx, cy)`` (1-based, so that the neighbour ``cx +- 1`` of a border cell is an
    empty padding column and never aliases the next row) has key ``cy * ncx + cx``.
    Returns ``xs, ys, perm, cell_start, cell_key`` with the points of cell ``c`` at
    sorted positions ``cell_start[c] : cell_start[c + 1]`` and original indices ``perm``.
    """
    n = points.shape[0]
    perm, skeys = _radix_argsort(_cell_keys(points, xmin, ymin, inv_h, ncx), n_bits)
    xs = np.empty(n)
    ys = np.empty(n)
    for a in range(n):
        i = perm[a]
        xs[a] = points[i, 0]
        ys[a] = points[i, 1]
    cell_start, cell_key = _cell_table(skeys)
    return xs, ys, perm, cell_start, cell_key


@njit(cache=True)
def _build_cells_lines(points, xmin, ymin, inv_h, ncx, n_bits):
    """`_build_cells` for the line statistics: one row per sorted position,
    ``g[a] = (x, y, x_prev, y_prev, x_next, y_next)`` of the sample ``perm[a]`` and its
    time neighbours (NaN beyond the ends).

    One 48-byte row per point: the candidate test and, for a recurrent pair, the
    predecessor and successor tests read one cache line per point instead of three arrays.
    """
    n = points.shape[0]
    perm, skeys = _radix_argsort(_cell_keys(points, xmin, ymin, inv_h, ncx), n_bits)
    g = np.empty((n, 6))
    for a in range(n):
        i = perm[a]
        g[a, 0] = points[i, 0]
        g[a, 1] = points[i, 1]
        if i > 0:
            g[a, 2] = points[i - 1, 0]
            g[a, 3] = points[i - 1, 1]
        else:
            g[a, 2] = g[a, 3] = np.nan
        if i + 1 < n:
            g[a, 4] = points[i + 1, 0]
            g[a, 5] = points[i + 1, 1]
        else:
            g[a, 4] = g[a, 5] = np.nan
    cell_start, cell_key = _cell_table(skeys)
    return g, perm, cell_start, cell_key


@njit(cache=True)
def _dense_cells_lines(points, xmin, ymin, inv_h, ncx, n_cells):
    """`_build_cells_lines` on a dense grid of ``n_cells`` cells, by one counting sort.

    Returns ``g, perm, skey, start``: ``g`` and ``perm`` exactly as `_build_cells_lines`
    (the counting sort is stable, like the radix sort), ``skey[a]`` the cell key of sorted
    position ``a``, and ``start`` (``n_cells + 1``) with the points of the cell of key
    ``c``, occupied or not, at sorted positions ``start[c] : start[c + 1]``. A neighbour
    is then one array read away (`_sweep_lines_dense`) instead of a walk over the occupied
    cells. For grids of at most a few cells per point (eps = 1e-2 in the unit disk: about
    40 000 cells).
    """
    n = points.shape[0]
    keys = _cell_keys(points, xmin, ymin, inv_h, ncx)
    # counts shifted by two, so that after the prefix sum start[k + 1] is the first slot
    # of cell k and the placing pass leaves start[k] = first position of cell k (no copy)
    start = np.zeros(n_cells + 2, np.int64)
    for i in range(n):
        start[keys[i] + 2] += 1
    for c in range(1, n_cells + 2):
        start[c] += start[c - 1]
    perm = np.empty(n, np.int64)
    skey = np.empty(n, np.int64)
    for i in range(n):
        k = keys[i]
        a = start[k + 1]
        start[k + 1] = a + 1
        perm[a] = i
        skey[a] = k
    # then the rows in sorted order: sequential writes, reads of three adjacent samples
    g = np.empty((n, 6))
    for a in range(n):
        i = perm[a]
        g[a, 0] = points[i, 0]
        g[a, 1] = points[i, 1]
        if i > 0:
            g[a, 2] = points[i - 1, 0]
            g[a, 3] = points[i - 1, 1]
        else:
            g[a, 2] = g[a, 3] = np.nan
        if i + 1 < n:
            g[a, 4] = points[i + 1, 0]
            g[a, 5] = points[i + 1, 1]
        else:
            g[a, 4] = g[a, 5] = np.nan
    return g, perm, skey, start[: n_cells + 1]


@njit(cache=True, inline="always")
def _recurrent(pts, i, j, eps2):
    """The recurrence test of the sweep for original indices ``i, j`` (same float values)."""
    dx = pts[i, 0] - pts[j, 0]
    dy = pts[i, 1] - pts[j, 1]
    return dx * dx + dy * dy <= eps2


@njit(cache=True, inline="always")
def _add_line(sums, k, length):
    """Account a line in ``sums[k] = (l_min, lines >= l_min, entries on them, longest)``.

    Indexes the 2-D array rather than taking the row ``sums[k]``: a view per call costs
    reference counting in the innermost loop.
    """
    if length >= sums[k, 0]:
        sums[k, 1] += 1
        sums[k, 2] += length
    if length > sums[k, 3]:
        sums[k, 3] = length


@njit(cache=True, inline="always")
def _visit_block(xs, ys, perm, a0, a1, b0, b1, same, eps2, w, mode, count, buf):
    """Examine the pairs (a in [a0, a1), b in [b0, b1)) of sorted positions.

    ``same`` marks a block of one cell with itself: then only a < b is examined.
    Counts the unordered pairs with squared distance <= eps2 and ``|i - j| >= w``
    (``w >= 1``). In collect mode pair number ``k = count[0]`` is also written to
    ``buf[2k], buf[2k + 1]`` while it fits (``count[0]`` keeps counting beyond).
    """
    total = 0
    for a in range(a0, a1):
        xa = xs[a]
        ya = ys[a]
        ia = perm[a]
        start = a + 1 if same else b0
        for b in range(start, b1):
            dx = xa - xs[b]
            dy = ya - ys[b]
            if dx * dx + dy * dy <= eps2:
                ib = perm[b]
                if w > 1 and abs(ia - ib) < w:
                    continue
                total += 1
                if mode == _COLLECT:
                    k = count[0]
                    if 2 * k + 1 < buf.shape[0]:
                        buf[2 * k] = ia
                        buf[2 * k + 1] = ib
                    count[0] = k + 1
    return total


@njit(cache=True)
def _walk(pts, ia, ib, e2):
    """Length of the diagonal line that starts at the recurrent pair ``ia, ib`` whose
    successor is recurrent too (so at least 2)."""
    i = min(ia, ib)
    j = max(ia, ib)
    length = 2
    while j + length < pts.shape[0] and _recurrent(pts, i + length, j + length, e2):
        length += 1
    return length


@njit(cache=True)
def _pair_lines(k0, d2, p2, s2, ia, ib, pts, eps2s, count, diag):
    """Account a recurrent pair (original ``ia, ib``, squared distance ``d2``, squared
    distances ``p2`` of its predecessor and ``s2`` of its successor pair) at every
    threshold ``eps2s[k]``, ``k >= k0`` (decreasing), that it meets.

    ``count[k]`` counts it and, if the pair ``i < j`` starts a diagonal line
    (``(i - 1, j - 1)`` not recurrent), the line ``(i + k, j + k)`` is walked and
    accounted in ``diag[k]`` (`_add_line`): every line of the upper triangle is counted
    once, at its start, with O(1) work per recurrent pair and no pair stored.
    """
    for k in range(k0, eps2s.shape[0]):
        e2 = eps2s[k]
        if not (d2 <= e2):
            break
        count[k] += 1
        if not (p2 <= e2):  # (i, j) starts a diagonal line: walk it
            length = 1
            if s2 <= e2:
                length = _walk(pts, ia, ib, e2)
            _add_line(diag, k, length)


# Recurrent pairs are gathered over many points into a buffer until it holds this many
# pairs, then accounted in one loop (`_account_pairs`): a loop per point over its two or
# three pairs cost a mispredicted exit per point, the sweep's largest cost
# (benchmarks/bench_recurrence.py; docs/benchmarks.md).
_BATCH = 2048
# Fields of the accumulator of the first (largest) threshold, see `_account_pairs`.
_PAIRS, _STARTS2, _ON2, _SINGLE, _LONGEST = 0, 1, 2, 3, 4


@njit(cache=True)
def _account_pairs(g, perm, pts, pa, pb, pd2, m, w, eps2s, count, diag, acc):
    """Account ``m`` pairs of sorted positions ``pa[t], pb[t]``, recurrent at the largest
    threshold (squared distances ``pd2[t] <= eps2s[0]``), at every threshold.

    With ``l_min <= 2`` (``diag[0, 0]``) the first threshold needs no walk but to find the
    longest line, and is accounted without a branch in ``acc``: pairs, starts of lines of
    length >= 2 (``(i - 1, j - 1)`` not recurrent, ``(i + 1, j + 1)`` recurrent), entries
    with a recurrent predecessor or successor (the entries of those lines), isolated
    entries (lines of length 1) and the longest line (`_finish_lines` adds them to
    ``count[0], diag[0]``). A line is walked only if it can beat the longest so far,
    which the single test of ``(i + longest, j + longest)`` decides. The other thresholds,
    and every threshold for ``l_min > 2``, go through `_pair_lines`.
    """
    n = pts.shape[0]
    e20 = eps2s[0]
    e21 = eps2s[1] if eps2s.shape[0] > 1 else -1.0
    fast = diag[0, 0] <= 2
    # the thresholds `_pair_lines` accounts from: all, or those after the first (int64
    # variables: literal arguments would compile it once per value)
    k_all = np.int64(0)
    k_rest = np.int64(1)
    pairs = acc[_PAIRS]
    starts2 = acc[_STARTS2]
    on2 = acc[_ON2]
    single = acc[_SINGLE]
    longest = acc[_LONGEST]
    for t in range(m):
        a = pa[t]
        b = pb[t]
        ia = perm[a]
        ib = perm[b]
        if w > 1 and abs(ia - ib) < w:
            continue
        px = g[a, 2] - g[b, 2]
        py = g[a, 3] - g[b, 3]
        p2 = px * px + py * py  # NaN without a predecessor: never <= e2
        sx = g[a, 4] - g[b, 4]
        sy = g[a, 5] - g[b, 5]
        s2 = sx * sx + sy * sy
        d2 = pd2[t]
        if not fast:
            _pair_lines(k_all, d2, p2, s2, ia, ib, pts, eps2s, count, diag)
            continue
        pred = p2 <= e20
        succ = s2 <= e20
        pairs += 1
        on2 += pred | succ
        single += not (pred | succ)
        start2 = (not pred) & succ
        starts2 += start2
        if start2:
            # a line longer than `longest` contains (i + longest, j + longest)
            i = min(ia, ib)
            j = max(ia, ib)
            if j + longest < n and _recurrent(pts, i + longest, j + longest, e20):
                longest = max(longest, _walk(pts, ia, ib, e20))
        if d2 <= e21:
            _pair_lines(k_rest, d2, p2, s2, ia, ib, pts, eps2s, count, diag)
    acc[_PAIRS] = pairs
    acc[_STARTS2] = starts2
    acc[_ON2] = on2
    acc[_SINGLE] = single
    acc[_LONGEST] = longest


@njit(cache=True)
def _finish_lines(acc, count, diag):
    """Add the first threshold's accumulator of `_account_pairs` (``l_min <= 2``) to
    ``count[0]`` and ``diag[0]``."""
    if diag[0, 0] > 2:
        return
    single = acc[_SINGLE]
    count[0] += acc[_PAIRS]
    if diag[0, 0] <= 1:  # isolated entries are lines too
        diag[0, 1] += acc[_STARTS2] + single
        diag[0, 2] += acc[_ON2] + single
    else:
        diag[0, 1] += acc[_STARTS2]
        diag[0, 2] += acc[_ON2]
    longest = max(acc[_LONGEST], 1 if single > 0 else 0)
    diag[0, 3] = max(diag[0, 3], longest)


@njit(cache=True)
def _sweep(xs, ys, perm, cell_start, cell_key, ncx, eps2, w, mode, count, buf):
    """Visit every unordered pair of distinct points in the same or adjacent cells once.

    Half stencil: a cell is paired with itself, with ``(cx+1, cy)`` and with the three
    cells of the row above. Their keys are ``key + 1`` and ``key + ncx + (-1, 0, 1)``,
    which grow with ``key``, so a single forward pointer finds the upper-row cells.
    """
    n_cells = cell_key.shape[0]
    total = 0
    q = 0
    for c in range(n_cells):
        key = cell_key[c]
        s0 = cell_start[c]
        s1 = cell_start[c + 1]
        total += _visit_block(xs, ys, perm, s0, s1, s0, s1, True, eps2, w, mode, count, buf)
        if c + 1 < n_cells and cell_key[c + 1] == key + 1:
            total += _visit_block(
                xs, ys, perm, s0, s1, s1, cell_start[c + 2], False, eps2, w, mode, count, buf
            )
        lo = key + ncx - 1
        hi = key + ncx + 1
        while q < n_cells and cell_key[q] < lo:
            q += 1
        r = q
        while r < n_cells and cell_key[r] <= hi:
            total += _visit_block(
                xs,
                ys,
                perm,
                s0,
                s1,
                cell_start[r],
                cell_start[r + 1],
                False,
                eps2,
                w,
                mode,
                count,
                buf,
            )
            r += 1
    return total


@njit(cache=True)
def _vertical_entry(pts, r, c, p2, s2, e2, wv, vert, k):
    """Account entry ``(r, c)`` (row, column) in ``vert[k]`` if it starts a vertical line.

    ``p2`` and ``s2`` are the squared distances of ``(r - 1, c)`` and ``(r + 1, c)`` (NaN
    beyond the ends); an entry of the Theiler band ``|i - j| < wv`` is not admissible and
    ends a run. The tests are `_recurrent`'s, on the same float values.
    """
    if abs(r - 1 - c) >= wv and p2 <= e2:
        return  # the run started above
    length = 1
    if abs(r + 1 - c) >= wv and s2 <= e2:
        length = 2
        n = pts.shape[0]
        while r + length < n and abs(r + length - c) >= wv and _recurrent(pts, r + length, c, e2):
            length += 1
    _add_line(vert, k, length)


@njit(cache=True)
def _account_vertical(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, vert):
    """The vertical lines through both entries ``(i, j)`` and ``(j, i)`` of ``m`` pairs of
    sorted positions ``pa[t], pb[t]`` (recurrent at the largest threshold), at every
    threshold they meet; ``wv`` is the Theiler window of the matrix (0: the main diagonal
    is admissible, see `_diagonal_vertical`). Both entries' neighbours in their column,
    ``(i +- 1, j)`` and ``(j +- 1, i)``, are read from the time neighbours in ``g``."""
    for t in range(m):
        a = pa[t]
        b = pb[t]
        ia = perm[a]
        ib = perm[b]
        if w > 1 and abs(ia - ib) < w:
            continue
        d2 = pd2[t]
        xa = g[a, 0]
        ya = g[a, 1]
        xb = g[b, 0]
        yb = g[b, 1]
        # column ib: rows ia - 1 and ia + 1; column ia: rows ib - 1 and ib + 1
        dx = g[a, 2] - xb
        dy = g[a, 3] - yb
        pa2 = dx * dx + dy * dy
        dx = g[a, 4] - xb
        dy = g[a, 5] - yb
        sa2 = dx * dx + dy * dy
        dx = g[b, 2] - xa
        dy = g[b, 3] - ya
        pb2 = dx * dx + dy * dy
        dx = g[b, 4] - xa
        dy = g[b, 5] - ya
        sb2 = dx * dx + dy * dy
        for k in range(eps2s.shape[0]):
            e2 = eps2s[k]
            if not (d2 <= e2):
                break
            _vertical_entry(pts, ia, ib, pa2, sa2, e2, wv, vert, k)
            _vertical_entry(pts, ib, ia, pb2, sb2, e2, wv, vert, k)


@njit(cache=True)
def _diagonal_vertical(pts, eps2s, vert):
    """The vertical lines through the main diagonal's entries ``(j, j)`` (Theiler window
    0), at every threshold: the sweep visits the pairs ``i != j`` only."""
    n = pts.shape[0]
    for j in range(n):
        p2 = s2 = np.nan  # no row above the first, none below the last
        if j > 0:
            dx = pts[j - 1, 0] - pts[j, 0]
            dy = pts[j - 1, 1] - pts[j, 1]
            p2 = dx * dx + dy * dy
        if j + 1 < n:
            dx = pts[j + 1, 0] - pts[j, 0]
            dy = pts[j + 1, 1] - pts[j, 1]
            s2 = dx * dx + dy * dy
        for k in range(eps2s.shape[0]):
            _vertical_entry(pts, j, j, p2, s2, eps2s[k], 0, vert, k)


@njit(cache=True)
def _most_in_a_cell(start):
    """The largest ``start[c + 1] - start[c]``: the most points in one cell."""
    most = 0
    for c in range(start.shape[0] - 1):
        most = max(most, start[c + 1] - start[c])
    return most


@njit(cache=True)
def _flush(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, count, diag, acc, vert):
    """Account the buffer's ``m`` pairs: the diagonal lines (`_account_pairs`) and, when
    ``vert`` has a row per threshold (laminarity), the vertical ones (`_account_vertical`)."""
    _account_pairs(g, perm, pts, pa, pb, pd2, m, w, eps2s, count, diag, acc)
    if vert.shape[0] > 0:
        _account_vertical(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, vert)


@njit(cache=True)
def _sweep_lines(g, perm, cell_start, cell_key, ncx, w, pts, eps2s, count, diag, wv, vert):
    """The half-stencil sweep of `_sweep` for the line statistics (`_account_pairs`).

    Same pairs as `_sweep`, visited as two contiguous ranges per point: its own cell's
    later points plus the next cell of the row (adjacent when sorted), and the three cells
    of the row above (``key + ncx + (-1, 0, 1)``, also adjacent when sorted). The
    candidates are compacted without a branch (``m += d2 <= eps2``): most candidates are
    not recurrent, and a data-dependent branch per candidate costs more than the test
    (benchmarks/bench_recurrence.py). The recurrent
    ones gather over many points into a buffer, accounted in one loop once it holds
    ``_BATCH`` pairs, so it needs room for ``_BATCH`` plus one point's candidates (five
    cells' worth: O(1) memory for bounded cell occupancy, and it stays in cache).
    Kept apart from `_sweep` on purpose: one kernel with both bodies made the plain
    counting sweep of `recurrence_rate` 2.5x slower (measured).
    """
    n_cells = cell_key.shape[0]
    eps2 = eps2s[0]
    # a point's candidates lie in 5 cells; the buffer never holds more than _BATCH + those
    # (allocated here: from a helper returning them, the sweep measured about 5 % slower)
    cap = _BATCH + 5 * _most_in_a_cell(cell_start)
    pa = np.empty(cap, np.int64)
    pb = np.empty(cap, np.int64)
    pd2 = np.empty(cap)
    acc = np.zeros(5, np.int64)
    # an int64 from the start: with m = 0 numba's type inference first sees a literal 0
    # and compiles `_flush` for it too (a second signature, twice the compile)
    m = np.int64(0)
    q = 0
    for c in range(n_cells):
        key = cell_key[c]
        s0 = cell_start[c]
        s1 = cell_start[c + 1]
        e1 = s1
        if c + 1 < n_cells and cell_key[c + 1] == key + 1:
            e1 = cell_start[c + 2]
        lo = key + ncx - 1
        hi = key + ncx + 1
        while q < n_cells and cell_key[q] < lo:
            q += 1
        r = q
        while r < n_cells and cell_key[r] <= hi:
            r += 1
        u0 = cell_start[q]
        u1 = cell_start[r]
        for a in range(s0, s1):
            xa = g[a, 0]
            ya = g[a, 1]
            for b in range(a + 1, e1):
                dx = xa - g[b, 0]
                dy = ya - g[b, 1]
                d2 = dx * dx + dy * dy
                pa[m] = a
                pb[m] = b
                pd2[m] = d2
                m += d2 <= eps2
            for b in range(u0, u1):
                dx = xa - g[b, 0]
                dy = ya - g[b, 1]
                d2 = dx * dx + dy * dy
                pa[m] = a
                pb[m] = b
                pd2[m] = d2
                m += d2 <= eps2
            if m >= _BATCH:
                _flush(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, count, diag, acc, vert)
                m = 0
    _flush(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, count, diag, acc, vert)
    _finish_lines(acc, count, diag)


@njit(cache=True)
def _sweep_lines_dense(g, perm, skey, start, ncx, w, pts, eps2s, count, diag, wv, vert):
    """`_sweep_lines` on the dense grid of `_dense_cells_lines`: the same candidates in the
    same order, hence the same counts.

    The point at sorted position ``a`` (cell key ``k``) meets the later points of its cell
    and the next cell's, ``a + 1 .. start[k + 2]``, and the three cells of the row above,
    ``start[k + ncx - 1] .. start[k + ncx + 2]``: two contiguous ranges read off ``start``,
    with no per-cell bookkeeping (benchmarks/bench_recurrence.py). The per-point body is
    written out as in `_sweep_lines` on purpose: sharing it through an inlined helper made
    both sweeps slower (docs/benchmarks.md).
    """
    n = g.shape[0]
    eps2 = eps2s[0]
    # a point's candidates lie in 5 cells; the buffer never holds more than _BATCH + those
    # (allocated here: from a helper returning them, the sweep measured about 5 % slower)
    cap = _BATCH + 5 * _most_in_a_cell(start)
    pa = np.empty(cap, np.int64)
    pb = np.empty(cap, np.int64)
    pd2 = np.empty(cap)
    acc = np.zeros(5, np.int64)
    # an int64 from the start: with m = 0 numba's type inference first sees a literal 0
    # and compiles `_flush` for it too (a second signature, twice the compile)
    m = np.int64(0)
    for a in range(n):
        key = skey[a]
        e1 = start[key + 2]
        u0 = start[key + ncx - 1]
        u1 = start[key + ncx + 2]
        xa = g[a, 0]
        ya = g[a, 1]
        for b in range(a + 1, e1):
            dx = xa - g[b, 0]
            dy = ya - g[b, 1]
            d2 = dx * dx + dy * dy
            pa[m] = a
            pb[m] = b
            pd2[m] = d2
            m += d2 <= eps2
        for b in range(u0, u1):
            dx = xa - g[b, 0]
            dy = ya - g[b, 1]
            d2 = dx * dx + dy * dy
            pa[m] = a
            pb[m] = b
            pd2[m] = d2
            m += d2 <= eps2
        if m >= _BATCH:
            _flush(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, count, diag, acc, vert)
            m = 0
    _flush(g, perm, pts, pa, pb, pd2, m, w, wv, eps2s, count, diag, acc, vert)
    _finish_lines(acc, count, diag)


@njit(cache=True)
def _rows_from_pairs(pairs, m, n, diagonal):
    """Sorted rows of the symmetric matrix of ``m`` unordered pairs (+ the diagonal).

    Two O(N + m) bucket passes instead of a comparison sort: the entries are first
    bucketed by column, then, visiting the columns in increasing order, appended to their
    rows, so every row comes out sorted. By symmetry rows and columns have the same
    lengths, hence the same offsets.
    """
    deg = np.zeros(n, np.int64)
    for k in range(m):
        deg[pairs[2 * k]] += 1
        deg[pairs[2 * k + 1]] += 1
    if diagonal:
        for i in range(n):
            deg[i] += 1
    offsets = np.zeros(n + 1, np.int64)
    for i in range(n):
        offsets[i + 1] = offsets[i] + deg[i]
    by_col = np.empty(offsets[n], np.int64)
    cursor = offsets[:n].copy()
    for k in range(m):
        a = pairs[2 * k]
        b = pairs[2 * k + 1]
        by_col[cursor[b]] = a
        cursor[b] += 1
        by_col[cursor[a]] = b
        cursor[a] += 1
    if diagonal:
        for i in range(n):
            by_col[cursor[i]] = i
            cursor[i] += 1
    cols = np.empty(offsets[n], np.int64)
    for i in range(n):  # element copy: a slice assignment compiles numba's error strings
        cursor[i] = offsets[i]
    for c in range(n):
        for e in range(offsets[c], offsets[c + 1]):
            r = by_col[e]
            cols[cursor[r]] = c
            cursor[r] += 1
    return offsets, cols


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


def _check_eps(eps) -> float:
    if isinstance(eps, np.ndarray) and eps.ndim == 0:
        eps = eps.item()
    if isinstance(eps, bool) or not isinstance(eps, numbers.Real):
        raise TypeError(f"eps: expected a positive finite float, got {eps!r}")
    eps = float(eps)
    if not (np.isfinite(eps) and eps > 0.0):
        raise ValueError(f"eps: must be positive and finite (0 < eps < inf), got {eps!r}")
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


def recurrence_rate(points, eps=1e-3, *, theiler=0):
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
        times; a run record is accepted directly). Only planar points are supported.
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
        or y (``dx**2 + dy**2`` would overflow); ``eps`` not positive and finite;
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


def recurrence_pairs(points, eps=1e-3, *, theiler=0):
    r"""The recurrence plot as index pairs: every ``(i, j)`` of samples within ``eps``.

    Returns the nonzero entries of the recurrence matrix
    ``R_ij = Theta(eps - |x_i - x_j|)`` (both orders, main diagonal included unless a
    Theiler window removes it), never the N x N matrix. ``len(i) / N**2`` equals
    ``recurrence_rate(points, eps)`` for ``theiler=0``.

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
    >>> i, j = recurrence_pairs(np.array([[0.0, 0.0], [0.0005, 0.0], [0.5, 0.5]]), 1e-3)
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
