"""Recurrence quantification analysis (RQA) without an N x N matrix and without the pairs.

The recurrence matrix ``R_ij = Theta(eps - |x_i - x_j|)`` of N planar points is symmetric.
Its recurrent pairs are enumerated once by the cell-list sweep of
`kicktimes.diagnostics.recurrence`, and the line statistics are counted on the fly:

* a **diagonal line** is a maximal run of recurrent entries ``(i + k, j + k)``,
  ``k = 0..l-1``, on one diagonal ``j - i = d``. When the sweep meets a pair ``i < j``
  whose predecessor ``(i - 1, j - 1)`` is not recurrent, the pair starts a line: the
  line is walked, ``(i + 1, j + 1), (i + 2, j + 2), ...``, testing distances directly,
  and its length is accounted (lines of length >= l_min, entries on them, longest).
  Every line is counted once, at its start. For ``l_min <= 2`` the counts need no walk
  (a line of length >= 2 starts at a pair with a recurrent successor; its entries are
  the pairs with a recurrent predecessor or successor), and only a line that may be
  the longest is walked;
* a **vertical line** is a maximal run ``(i + k, j)`` in one column, counted the same
  way (predecessor test, then a walk) in the same sweep, at both entries ``(i, j)`` and
  ``(j, i)`` of each recurrent pair (and, without a Theiler window, at the diagonal
  entries); only for the laminarity.

The distance test is the sweep's float expression, so the result equals the
brute-force matrix computation exactly. Memory is O(N) (the cells; no pair is stored)
and time O(N + candidate pairs + recurrent pairs), with or without laminarity. See
`rqa` and docs/diagnostics.md.
"""

from __future__ import annotations

import numbers
from dataclasses import asdict, dataclass, field

import numpy as np

from kicktimes._results import Result
from kicktimes.diagnostics.recurrence import (
    _as_points,
    _check_eps,
    _check_theiler,
    _line_sums,
)
from kicktimes.validation import keyword_only_after

__all__ = ["RQAResult", "rqa"]


@dataclass(frozen=True)
class RQAResult(Result):
    """Recurrence quantification measures of one point set (see `rqa` for the definitions).

    Attributes
    ----------
    eps, theiler, l_min : float, int, int
        The threshold, Theiler window and minimal line length used.
    n_points : int
        ``N``.
    n_admissible : int
        Entries of the matrix outside the Theiler window: ``N^2`` for ``theiler = 0``,
        ``(N - w)(N - w + 1)`` otherwise.
    n_recurrent : int
        Recurrent admissible entries (ordered pairs, so twice the unordered pairs, plus
        the ``N`` diagonal entries when ``theiler = 0``).
    rr : float
        ``n_recurrent / n_admissible``.
    det, l_mean, l_max, n_lines : float, float, int, int
        Determinism, mean and maximal diagonal line length, number of diagonal lines of
        length ``>= l_min``.
    lam, tt, v_max : float, float, int, or None
        Laminarity, trapping time and longest vertical line (``None``: not computed,
        ``laminarity=False``).
    undefined : dict
        ``{field: reason}`` for every field that is NaN (empty when all are defined).
    """

    _title = "Recurrence quantification (rqa)"
    _summary_fields = ("n_points", "eps", "theiler", "l_min", "rr", "det", "l_mean", "l_max",
                       "n_lines", "lam", "tt", "v_max")

    eps: float
    theiler: int
    l_min: int
    n_points: int
    n_admissible: int
    n_recurrent: int
    rr: float
    det: float
    l_mean: float
    l_max: int
    n_lines: int
    lam: float | None
    tt: float | None
    v_max: int | None
    undefined: dict = field(default_factory=dict)

    @property
    def reason(self) -> str | None:
        """Why some measure is NaN (``field: reason`` joined by ``; ``), None when all are
        defined: `undefined` as one sentence."""
        if not self.undefined:
            return None
        return "; ".join(f"{name}: {why}" for name, why in self.undefined.items())

    def to_dict(self) -> dict:
        """The fields as a plain dict (``undefined`` included)."""
        return asdict(self)


def _check_l_min(l_min) -> int:
    if isinstance(l_min, bool) or not isinstance(l_min, numbers.Integral):
        raise TypeError(f"l_min: expected an int >= 1, got {l_min!r}")
    if l_min < 1:
        raise ValueError(f"l_min: must be >= 1 (the shortest line that counts), got {l_min}")
    return int(l_min)


@keyword_only_after(1, since="0.2.0", names=('eps',))
def rqa(points, *, eps=1e-3, theiler=1, l_min=2, laminarity=True):
    r"""Recurrence quantification analysis: RR, determinism, line lengths, laminarity.

    Parameters
    ----------
    points : array_like, shape (N, 2), or a run record
        Sampled planar positions (a run record's ``samples`` are used).
    eps : float or sequence of float, default 1e-3
        Recurrence threshold ``> 0``; ``(i, j)`` is recurrent when
        ``dx**2 + dy**2 <= eps**2`` in float64 (the test of `recurrence_rate`). A
        sequence gives one result per threshold, all from one sweep of the points.
    theiler : int, default 1
        Theiler window ``w``, ``0 <= w < N``: the entries with ``|i - j| < w`` are removed
        from the matrix (``w = 1``: the main diagonal only, the usual choice).
    l_min : int, default 2
        Minimal length of a diagonal (and of a vertical) line, ``>= 1``.
    laminarity : bool, default True
        Also compute ``lam``, ``tt``, ``v_max`` (in the same sweep: 1.0-2.6x the time of
        ``False``, same O(N) memory; with ``False`` the fields are ``None``).

    Returns
    -------
    RQAResult, or tuple of RQAResult (one per threshold, in the given order)
        ``rr, det, l_mean, l_max, n_lines, lam, tt, v_max`` and the counts behind them.
        A measure that is undefined (no recurrence; no line of length ``>= l_min``) is
        NaN and ``result.undefined`` says why.

    Raises
    ------
    ValueError, TypeError
        As `recurrence_rate`, and for ``l_min`` not an int ``>= 1``.

    Notes
    -----
    All measures are taken over the *admissible* entries ``A_w = {(i, j) : |i - j| >= w}``
    of the full, symmetric ``N x N`` matrix (both triangles; the diagonal only when
    ``w = 0``). With ``R`` the number of recurrent admissible entries,

    .. math::

        RR = \frac{R}{|A_w|},\qquad
        DET = \frac{\sum_{l \ge l_{min}} l\, P(l)}{R},\qquad
        L = \frac{\sum_{l \ge l_{min}} l\, P(l)}{\sum_{l \ge l_{min}} P(l)},\qquad
        L_{max} = \max\{l : P(l) > 0\},

    .. math::

        LAM = \frac{\sum_{v \ge l_{min}} v\, P_V(v)}{R},\qquad
        TT = \frac{\sum_{v \ge l_{min}} v\, P_V(v)}{\sum_{v \ge l_{min}} P_V(v)},

    where ``P(l)`` counts the diagonal lines of length exactly ``l``: maximal runs of
    recurrent admissible entries ``(i + k, j + k)``, ``k = 0..l-1``, on one diagonal
    ``j - i = d`` with ``|d| >= w``; and ``P_V(v)`` counts the vertical lines, maximal
    runs ``(i + k, j)``, ``k = 0..v-1``, of recurrent admissible entries in one column
    (an excluded entry ends a run). ``|A_w| = N^2`` for ``w = 0`` and
    ``(N - w)(N - w + 1)`` for ``w >= 1``, so ``rr`` equals
    ``recurrence_rate(points, eps, theiler=w)``. The window removes whole diagonals, so
    it never cuts a diagonal line. By symmetry every line below the diagonal mirrors one
    above it, so ``P`` is twice the upper triangle's count, plus, for ``w = 0``, the main
    diagonal: one line of length ``N`` (then ``l_max = N``; use ``w >= 1`` for line
    statistics that describe the dynamics). ``DET = 1`` when every recurrent entry has a
    recurrent diagonal neighbour; ``DET`` and ``LAM`` are NaN when ``R = 0``, ``L`` and
    ``TT`` when no line reaches ``l_min``; ``l_max`` and ``v_max`` are 0 when ``R = 0``.

    Cost: one sweep of the cell list of `recurrence_rate`, for all thresholds at once
    (at the largest); each recurrent pair adds two distance tests (predecessor and
    successor, read from the time neighbours gathered in cell order). The recurrent pairs
    gather over many points in a buffer and are accounted in one loop; at the largest
    threshold with ``l_min <= 2`` the line counts are sums of those two tests, and a line
    is walked only when it can be longer than the longest so far. O(N) memory, never an
    ``N x N`` matrix nor the pair list; about the time of `recurrence_rate`
    (``laminarity=False``; at 1e-2 the cells are a dense grid, see
    `kicktimes.diagnostics.recurrence`; benchmarks/bench_recurrence.py and
    docs/benchmarks.md). The
    laminarity adds, per recurrent pair, the column tests of both its entries, read from
    the same time neighbours; for the matrix's diagonal (``theiler = 0``) one pass over
    the points.

    References
    ----------
    N. Marwan, M. C. Romano, M. Thiel, J. Kurths, "Recurrence plots for the analysis of
    complex systems", Phys. Rep. 438, 237 (2007), Sec. 3.2 (DET, L, LAM, TT).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes.diagnostics import rqa
    >>> pts = np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 0.0], [0.5, 0.0], [0.9, 0.9]])
    >>> res = rqa(pts, eps=0.1)            # the pairs (0, 2), (1, 3): one line of length 2
    >>> res.n_recurrent, res.det, res.l_mean, res.l_max
    (4, 1.0, 2.0, 2)
    >>> res.rr == 4 / (4 * 5)             # (N - 1) N admissible entries for theiler = 1
    True
    """
    pts = _as_points(points)
    n = pts.shape[0]
    w = _check_theiler(theiler, n)
    l_min = _check_l_min(l_min)
    if not isinstance(laminarity, bool):
        raise TypeError(f"laminarity: expected True or False, got {laminarity!r}")
    if np.ndim(eps) == 0:
        eps_list = [_check_eps(eps)]
    else:
        eps_arr = np.asarray(eps)
        if eps_arr.ndim != 1 or eps_arr.size == 0:
            raise ValueError(
                f"eps: expected a float or a non-empty 1-D sequence, got shape {eps_arr.shape}"
            )
        eps_list = [_check_eps(e.item()) for e in eps_arr]
    # one sweep at the largest threshold serves them all (decreasing order inside)
    order = sorted(range(len(eps_list)), key=lambda k: -eps_list[k])
    pairs, diag, vert = _line_sums(pts, [eps_list[k] for k in order], w, l_min, laminarity)
    results = [None] * len(eps_list)
    for row, k in enumerate(order):
        results[k] = _summarise(
            eps_list[k], n, w, l_min, int(pairs[row]), diag[row], vert[row] if laminarity else None
        )
    return results[0] if np.ndim(eps) == 0 else tuple(results)


def _summarise(eps, n, w, l_min, pairs, diag_up, vert) -> RQAResult:
    """The measures from the pair count and the line sums of one threshold."""
    # Python ints from here on: exact counts, correctly rounded ratios
    n_rec = 2 * pairs + (n if w == 0 else 0)
    n_adm = n * n if w == 0 else (n - w) * (n - w + 1)
    lines, on_lines, l_max = (int(v) for v in diag_up[1:])
    lines, on_lines = 2 * lines, 2 * on_lines  # the mirror image below the diagonal
    if w == 0:  # the main diagonal: one line of length N
        l_max = n
        if n >= l_min:
            lines += 1
            on_lines += n
    undefined = {}
    no_pair = f"no recurrent pair at eps = {eps:g} (theiler = {w})"

    def ratio(name, num, den, why):
        if den == 0:
            undefined[name] = why
            return np.nan
        return num / den

    det = ratio("det", on_lines, n_rec, no_pair)
    l_mean = ratio("l_mean", on_lines, lines, f"no diagonal line of length >= l_min = {l_min}")
    lam = tt = v_max = None
    if vert is not None:
        v_lines, on_v_lines, v_max = (int(v) for v in vert[1:])
        lam = ratio("lam", on_v_lines, n_rec, no_pair)
        tt = ratio("tt", on_v_lines, v_lines, f"no vertical line of length >= l_min = {l_min}")
    return RQAResult(
        eps=eps,
        theiler=w,
        l_min=l_min,
        n_points=n,
        n_admissible=n_adm,
        n_recurrent=n_rec,
        rr=n_rec / n_adm,
        det=det,
        l_mean=l_mean,
        l_max=l_max,
        n_lines=lines,
        lam=lam,
        tt=tt,
        v_max=v_max,
        undefined=undefined,
    )
