"""The compiled kernels of the recurrence diagnostics (`kicktimes.diagnostics.recurrence`,
`kicktimes.diagnostics.rqa`): the cell grid, the radix sort, the pair sweep and the line
sweeps. The algorithms and their invariants are described in
:mod:`kicktimes.diagnostics.recurrence`; the checks and the public functions live there.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_RADIX_BITS = 11
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
