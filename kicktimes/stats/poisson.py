r"""Is an event sequence a homogeneous Poisson process? Intervals and one-sequence tests.

Conventions (see also :mod:`kicktimes.stats.iid_tests`):

* a sequence is event times ``0 <= t_1 < ... < t_n <= T`` observed in ``[0, T]``;
* every single-sequence test is **conditional on n** and has an exact null (exact
  distribution, or Monte Carlo with ``n_mc`` samples, which is exact up to its
  Monte Carlo resolution); Laplace's trend test alone uses its normal limit;
* interval tests use the ``n - 1`` inner intervals: the first time ``t_1`` is a
  forward recurrence time and ``T - t_n`` is censored, so both are left out;
* tests are per sequence (one initial condition); :func:`~kicktimes.stats.test_poisson_ensemble`
  runs them on every sequence, combines their p-values, controls the false
  discovery rate across sequences and tests whether all sequences share one rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numba import njit
from statsmodels.stats.multitest import multipletests

from kicktimes._results import Result, TupleCompat

from . import iid_tests as iid
from ._checks import check_choice, check_int, check_real, check_rng, check_times

TESTS = (
    "uniformity_ks",
    "laplace_trend",
    "exponential_ks",
    "exponential_ad",
    "ljung_box",
    "runs",
    "dispersion",
)
#: how each test's null distribution is computed (the report's captions say it)
TEST_NULLS = {
    "uniformity_ks": "exact KS (given n)",
    "laplace_trend": "asymptotic normal",
    "exponential_ks": "Monte Carlo (given n)",
    "exponential_ad": "Monte Carlo (given n)",
    "ljung_box": "Monte Carlo (given n)",
    "runs": "exact runs law (given n)",
    "dispersion": "Monte Carlo multinomial (given n)",
}
_MIN_EVENTS = {
    "uniformity_ks": 2,
    "laplace_trend": 3,
    "exponential_ks": 5,
    "exponential_ad": 5,
    "ljung_box": 11,
    "runs": 11,
    "dispersion": 10,
}
COMBINE_METHODS = ("fisher", "pearson", "tippett", "stouffer", "mudholkar_george")
FDR_METHODS = ("fdr_bh", "fdr_by", "bonferroni", "holm", "fdr_tsbh", "fdr_tsbky")


@dataclass(frozen=True, repr=False)
class Intervals(TupleCompat, Result):
    """Complete and right-censored intervals of one or several sequences.

    Attributes
    ----------
    complete : ndarray
        The complete intervals ``t_{k+1} - t_k``.
    censored : ndarray
        The right-censored ones, ``T - t_n`` per sequence.

    Unpacking (``complete, censored = intervals_from_times(...)``) and indexing still work
    until 0.3.0, with a DeprecationWarning: use the fields.
    """

    _title = "Inter-event intervals (complete and right-censored)"
    _tuple_fields = ("complete", "censored")

    complete: np.ndarray
    censored: np.ndarray

    def _summary_extra(self) -> list[str]:
        mean = self.complete.mean() if self.complete.size else math.nan
        return [f"n: {self.complete.size} complete, {self.censored.size} censored; mean "
                f"complete interval {mean:.6g}"]


def _is_ensemble(times) -> bool:
    if isinstance(times, np.ndarray):
        return times.dtype == object
    return (
        isinstance(times, list | tuple)
        and len(times) > 0
        and all(np.ndim(t) == 1 and not isinstance(t, str) for t in times)
    )


def _windows(windows, k):
    if np.ndim(windows) == 0:
        w = check_real("t_window", windows, low=0.0)
        return np.full(k, w)
    arr = np.asarray(windows, dtype=float)
    if arr.shape != (k,):
        raise ValueError(
            f"windows must be a scalar or hold one window per sequence ({k}), got shape {arr.shape}"
        )
    for i, w in enumerate(arr):
        check_real(f"windows[{i}]", w, low=0.0)
    return arr


def intervals_from_times(times, t_window, *, first="drop") -> Intervals:
    r"""Complete and right-censored intervals of event sequences observed on ``[0, T]``.

    Parameters
    ----------
    times : array_like or list of array_like
        Strictly increasing event times in ``[0, t_window]``; a list of such arrays
        pools several sequences (e.g. one per initial condition).
    t_window : float or sequence of float
        Window length ``T`` (one per sequence, or common).
    first : {"drop", "keep"}, optional
        The first time ``t_1`` is a forward recurrence time when observation starts
        at an arbitrary instant (a stationary process): its law is the equilibrium
        law :math:`S(x)/\mu`, not the interval law, so ``"drop"`` (default) leaves it
        out. ``"keep"`` counts it as a complete interval, which is right only when an
        event (a renewal) happened at time 0; then an empty window also gives one
        censored interval ``T``.

    Returns
    -------
    Intervals
        ``complete``: ``t_{k+1} - t_k`` (and ``t_1`` with ``first="keep"``);
        ``censored``: ``T - t_n`` per sequence (the interval running at the end of the
        window, right-censored), dropped when exactly 0.

    Examples
    --------
    >>> from kicktimes import stats
    >>> stats.intervals_from_times([1.0, 1.5, 3.0], 4.0)
    Intervals(complete=array([0.5, 1.5]), censored=array([1.]))
    """
    check_choice("first", first, ("drop", "keep"))
    if _is_ensemble(times):
        seqs = list(times)
        ws = _windows(t_window, len(seqs))
        parts = [intervals_from_times(s, w, first=first) for s, w in zip(seqs, ws, strict=True)]
        return Intervals(
            np.concatenate([p.complete for p in parts]),
            np.concatenate([p.censored for p in parts]),
        )
    t_window = check_real("t_window", t_window, low=0.0)
    t = check_times("times", times, t_window)
    if first == "keep":
        t = np.concatenate([[0.0], t])
        complete = np.diff(t)
        if complete.size and complete[0] == 0:
            complete = complete[1:]  # an event at 0 is the renewal itself
    else:
        complete = np.diff(t)
    last = t[-1] if t.size else None
    censored = np.empty(0) if last is None or t_window - last == 0 else np.array([t_window - last])
    return Intervals(complete, censored)



# ------------------------------------------------------------------ exact KS p-value
# scipy's exact two-sided KS law (``kstwo.sf``, Simard & L'Ecuyer 2011) runs the Pomeranz
# recursion in Python, which at paper scale (10^4 sequences) was most of the Poisson tests
# (docs/benchmarks.md). The same recursion as a numba kernel; every other branch of the
# dispatch stays scipy's own. The sums of the convolutions run in index order (numpy's may
# use a blocked dot), so p-values can differ from scipy's in the last bits only.

_E128 = 128
_EP128 = 2.0**128
_EM128 = 2.0**-128


@njit(cache=True)
def _pomeranz_j1j2(i, n, ll, ceilf, roundf):
    """Endpoints of the non-zero band of row ``i`` of the Pomeranz recursion."""
    if i == 0:
        j1, j2 = -ll - ceilf - 1, ll + ceilf - 1
    else:
        ip1div2, ip1mod2 = (i + 1) // 2, (i + 1) % 2
        if ip1mod2 == 0:
            if ip1div2 == n + 1:
                j1, j2 = n - ll - ceilf - 1, n + ll + ceilf - 1
            else:
                j1, j2 = ip1div2 - 1 - ll - roundf - 1, ip1div2 + ll - 1 + ceilf - 1
        else:
            j1, j2 = ip1div2 - 1 - ll - 1, ip1div2 + ll + roundf - 1
    return max(j1 + 2, 0), min(j2, n)


@njit(cache=True)
def pomeranz_cdf(n, x):
    r"""Exact :math:`P(D_n \le x)` of the two-sided KS statistic by Pomeranz's recursion.

    Each of the ``2n + 1`` rows is the previous row convolved with (almost) Poisson
    weights :math:`(g/n)^m/m!`, :math:`(2g/n)^m/m!` or :math:`((1-2g)/n)^m/m!`, with
    :math:`g = \min(f, 1 - f)` and ``f`` the fractional part of ``n x``; the answer is
    ``n!`` times the last entry (scaled by powers of 2 to avoid underflow). A port of
    ``scipy.stats._ksstats._kolmogn_Pomeranz``, clipped to [0, 1].
    """
    t = n * x
    ll = int(math.floor(t))
    f = t - ll
    g = min(f, 1.0 - f)
    ceilf = 1 if f > 0 else 0
    roundf = 1 if f > 0.5 else 0
    npwrs = 2 * (ll + 1)
    pw = np.empty((3, npwrs))  # rows: gpower, twogpower, onem2gpower
    pw[0, 0] = pw[1, 0] = pw[2, 0] = 1.0
    g_n, two_g_n, one_m2g_n = g / n, 2 * g / n, (1 - 2 * g) / n
    for m in range(1, npwrs):
        pw[0, m] = pw[0, m - 1] * g_n / m
        pw[1, m] = pw[1, m - 1] * two_g_n / m
        pw[2, m] = pw[2, m - 1] * one_m2g_n / m
    v0 = np.zeros(npwrs)
    v1 = np.zeros(npwrs)
    v1[0] = 1.0
    v0s, v1s = 0, 0
    expnt = 0
    j1, j2 = _pomeranz_j1j2(0, n, ll, ceilf, roundf)
    for i in range(1, 2 * n + 2):
        k1 = j1
        v0, v1 = v1, v0
        v0s, v1s = v1s, v0s
        v1[:] = 0.0
        j1, j2 = _pomeranz_j1j2(i, n, ll, ceilf, roundf)
        row = 0 if (i == 1 or i == 2 * n + 1) else (1 if i % 2 else 2)
        ln2 = j2 - k1 + 1
        if ln2 > 0:
            a0 = k1 - v0s
            la = min(ln2, npwrs - a0)  # numpy's slice stops at the array's end
            c0 = j1 - k1
            for q in range(j2 - j1 + 1):
                k = c0 + q
                s = 0.0
                for j in range(max(0, k - ln2 + 1), min(k, la - 1) + 1):
                    s += v0[a0 + j] * pw[row, k - j]
                v1[q] = s
            mx = v1.max()
            if 0 < mx < _EM128:
                v1 *= _EP128
                expnt -= _E128
            v1s = v0s + j1 - k1
    ans = v1[n - v1s]
    for m in range(1, n + 1):
        if abs(ans) > _EP128:
            ans *= _EM128
            expnt += _E128
        ans *= m
    if expnt != 0:
        ans = ans * 2.0**expnt
    return min(max(ans, 0.0), 1.0)


def _kolmogorov_sf(n, d):
    """``scipy.stats.kstwo.sf(d, n)`` for one ``n`` and an array ``d``, with the Pomeranz
    branch of scipy's dispatch (n <= 140, 0.754693 < n d^2 <= 4) run by :func:`pomeranz_cdf`."""
    from scipy import stats

    try:
        from scipy.stats._ksstats import _kolmogn
    except ImportError:  # a scipy without the private module: its public (slower) law
        return np.clip(stats.kstwo.sf(d, n), 0.0, 1.0)
    d = np.asarray(d, dtype=float)
    out = np.empty(d.shape)
    for i, x in np.ndenumerate(d):
        t = n * x
        if n <= 140 and 0 < x < 0.5 and 1.0 < t < n - 1 and 0.754693 < t * x <= 4:
            out[i] = min(max(1.0 - pomeranz_cdf(n, float(x)), 0.0), 1.0)
        else:
            out[i] = _kolmogn(n, float(x), cdf=False)
    return np.clip(out, 0.0, 1.0)


def uniformity_ks(u):
    r"""KS distance of each row of sorted uniforms ``u`` from U(0, 1) and its exact p-value.

    The same statistic and law as ``scipy.stats.ks_1samp(u, uniform.cdf, axis=-1,
    method="exact")`` (:math:`D = \max(\max_i (i/n - u_i), \max_i (u_i - (i-1)/n))`,
    p-value ``kstwo.sf(D, n)``), with the exact law's slow branch compiled
    (:func:`pomeranz_cdf`).
    """
    u = np.clip(np.sort(np.asarray(u, dtype=float), axis=-1), 0.0, 1.0)
    n = u.shape[-1]
    d_plus = (np.arange(1.0, n + 1) / n - u).max(axis=-1)
    d_minus = (u - np.arange(0.0, n) / n).max(axis=-1)
    d = np.where(d_plus > d_minus, d_plus, d_minus)
    return d, _kolmogorov_sf(n, d)


def _default_lags(m):
    return int(min(10, m // 5))


def _default_bins(n):
    return int(min(20, max(2, n // 5)))


MC_TESTS = ("exponential_ks", "exponential_ad", "ljung_box", "dispersion")
#: first spawn-key word of the null streams of `MonteCarloNulls` ("null")
_NULL_DOMAIN = 0x6E756C6C


class MonteCarloNulls:
    r"""Monte Carlo nulls of the conditional Poisson tests, drawn once and shared.

    The null of a Monte Carlo test given ``n`` events depends on ``(test, n, lags,
    n_bins)`` only, not on the sequence, its window or its group. A bank gives each such
    key its own stream, ``SeedSequence(seed, spawn_key=(key...))``, and the key's null
    is the sequence of statistics drawn from that stream in order: its first ``size``
    values are the same whoever asks first, however the request grew (the refinement
    doubles nulls) and in whichever process. So every call given a bank with the same
    ``seed`` (the radii of a report, the groups of `kicktimes analyze`, the controls)
    shares the nulls of equal ``n``, and the results do not depend on the order of the
    calls, the grouping or the worker count.

    Parameters
    ----------
    seed : int
        Seed of every key's stream (``>= 0``).

    Examples
    --------
    >>> from kicktimes import stats
    >>> bank = stats.MonteCarloNulls(7)
    >>> first = bank.sample("exponential_ks", 40, 199).copy()
    >>> longer = bank.sample("exponential_ks", 40, 399)      # extended, not redrawn
    >>> bool((longer[:199] == first).all())
    True
    >>> bool((stats.MonteCarloNulls(7).sample("exponential_ks", 40, 399) == longer).all())
    True
    """

    def __init__(self, seed: int):
        self.seed = check_int("seed", seed, low=0)
        self._streams: dict = {}
        self._values: dict = {}

    def __repr__(self) -> str:
        return f"MonteCarloNulls(seed={self.seed}, keys={len(self._values)})"

    def summary(self) -> str:
        """The bank as text: its seed and the nulls drawn so far, per test."""
        lines = ["Monte Carlo nulls of the conditional Poisson tests (a shared bank)",
                 f"  seed: {self.seed}", f"  keys drawn: {len(self._values)}"]
        for index, test in enumerate(MC_TESTS):
            sizes = [np.asarray(v).size for k, v in self._values.items() if k[0] == index]
            if sizes:
                lines.append(f"  {test}: {len(sizes)} key(s), up to {max(sizes)} statistics")
        return "\n".join(lines)

    def sample(self, test: str, n_events: int, size: int, *, lags: int = 0,
               n_bins: int = 2) -> np.ndarray:
        """The first ``size`` null statistics of ``test`` given ``n_events`` (read-only).

        ``lags`` (Ljung-Box) and ``n_bins`` (dispersion) are part of the key of the tests
        that use them and ignored by the others.
        """
        check_choice("test", test, MC_TESTS)
        n_events = check_int("n_events", n_events, low=1)
        size = check_int("size", size, low=0)
        lags = check_int("lags", lags, low=0) if test == "ljung_box" else 0
        n_bins = check_int("n_bins", n_bins, low=2) if test == "dispersion" else 2
        key = (MC_TESTS.index(test), n_events, lags, n_bins)
        have = self._values.get(key)
        if have is None or have.size < size:
            stream = self._streams.get(key)
            if stream is None:
                stream = np.random.default_rng(
                    np.random.SeedSequence(self.seed, spawn_key=(_NULL_DOMAIN, *key)))
                self._streams[key] = stream
            done = 0 if have is None else have.size
            more = iid.simulate_null(test, n_events, size - done, stream, lags=lags,
                                     n_bins=n_bins)
            have = more if have is None else np.concatenate([have, more])
            have.flags.writeable = False
            self._values[key] = have
        return have[:size]


@dataclass
class _Group:
    """The sequences with one number of events ``n``: they share the Monte Carlo nulls."""

    members: np.ndarray
    n: int
    lags: int
    n_bins: int
    notes: dict
    stat: dict = field(default_factory=dict)
    null: dict = field(default_factory=dict)
    draws: dict = field(default_factory=dict)
    exact: dict = field(default_factory=dict)
    nulls: MonteCarloNulls | None = None

    def pvalue(self, name):
        if name in ("exponential_ks", "exponential_ad", "ljung_box"):
            return iid.mc_pvalue(self.stat[name], self.null[name])
        if name == "dispersion":
            return iid.mc_pvalue(
                self.stat[name], self.null[name], two_sided=True, u=self.draws[name]
            )
        runs, n1 = self.stat["runs"], self.stat["runs_n1"]
        m = self.n - 1
        draws = self.draws["runs"]
        draws = [None] * len(runs) if draws is None else draws
        return np.array(
            [iid.runs_pvalue(r, a, m - a, d) for r, a, d in zip(runs, n1, draws, strict=True)]
        )

    def extend(self, name, size, rng):
        if self.nulls is not None:
            self.null[name] = self._shared(name, self.null[name].size + size)
            return
        more = iid.simulate_null(name, self.n, size, rng, lags=self.lags, n_bins=self.n_bins)
        self.null[name] = np.concatenate([self.null[name], more])

    def _shared(self, name, size):
        return self.nulls.sample(name, self.n, size, lags=self.lags, n_bins=self.n_bins)


def _make_group(times, t_window, members, *, lags, n_bins, n_mc, rng, randomize, nulls=None):
    """Statistics, exact p-values and Monte Carlo nulls of ``k`` sequences with ``n`` events
    (from ``rng``, or from the bank ``nulls``)."""
    k, n = times.shape
    m = n - 1
    h = _default_lags(m) if lags is None else lags
    bins = _default_bins(n) if n_bins is None else n_bins
    notes = {}
    for name in TESTS:
        need = _MIN_EVENTS[name]
        if n < need:
            notes[name] = f"needs at least {need} events, got {n}"
        elif name == "ljung_box" and (h < 1 or m < h + 5):
            notes[name] = f"needs at least lags + 5 = {h + 5} intervals, got {m}"
        elif name == "dispersion" and n < 2 * bins:
            notes[name] = f"needs at least 2 events per sub-window ({2 * bins}), got {n}"
    g = _Group(members=members, n=n, lags=h, n_bins=bins, notes=notes, nulls=nulls)
    u = times / t_window[:, None]
    x = np.diff(times, axis=1)
    funs = {
        "exponential_ks": lambda: iid.exponential_ks(x),
        "exponential_ad": lambda: iid.exponential_ad(x),
        "ljung_box": lambda: iid.ljung_box(x, h),
        "dispersion": lambda: iid.dispersion_index(u, bins),
    }
    for name in MC_TESTS:
        if name not in notes:
            g.stat[name] = funs[name]()
            g.null[name] = (iid.simulate_null(name, n, n_mc, rng, lags=h, n_bins=bins)
                            if nulls is None else g._shared(name, n_mc))
    if "runs" not in notes:
        g.stat["runs"], g.stat["runs_n1"] = iid.runs_count(x)
    for name in ("dispersion", "runs"):
        g.draws[name] = rng.uniform(size=k) if randomize else None
    if "uniformity_ks" not in notes:
        g.stat["uniformity_ks"], g.exact["uniformity_ks"] = uniformity_ks(u)
    if "laplace_trend" not in notes:
        g.stat["laplace_trend"], g.exact["laplace_trend"] = iid.laplace_trend(u)
    return g


def _run_tests(seqs, ws, *, lags, n_bins, n_mc, rng, randomize, refine=None, nulls=None):
    """Per-sequence statistics, p-values and notes.

    Sequences are grouped by their number of events so that each ``n`` gets one
    Monte Carlo null (drawn from ``rng``, or taken from the bank ``nulls``, a
    `MonteCarloNulls`). With ``refine = (alpha, fdr_method, n_mc_max)`` the nulls of
    groups holding a sequence whose p-value is at the Monte Carlo floor but above the
    running FDR cut-off are extended (doubling, up to ``n_mc_max`` samples), so that a
    strong signal in a large ensemble is not lost to Monte Carlo resolution.
    """
    k = len(seqs)
    stat = np.full((k, len(TESTS)), np.nan)
    pval = np.full((k, len(TESTS)), np.nan)
    notes = [dict() for _ in range(k)]
    settings = [dict() for _ in range(k)]
    counts = np.array([s.size for s in seqs])
    groups = []
    for n in np.unique(counts):
        members = np.flatnonzero(counts == n)
        if n == 0:
            for i in members:
                notes[i] = {name: "no events in the window" for name in TESTS}
            continue
        block = np.vstack([seqs[i] for i in members])
        g = _make_group(
            block,
            ws[members],
            members,
            lags=lags,
            n_bins=n_bins,
            n_mc=n_mc,
            rng=rng,
            randomize=randomize,
            nulls=nulls,
        )
        groups.append(g)
        for i in members:
            notes[i], settings[i] = dict(g.notes), {"lags": g.lags, "n_bins": g.n_bins}
        for j, name in enumerate(TESTS):
            if name in g.notes:
                continue
            stat[members, j] = g.stat[name]
            pval[members, j] = g.exact[name] if name in g.exact else g.pvalue(name)
            for i in members[~np.isfinite(pval[members, j])]:
                notes[i][name] = "degenerate: all inner intervals are equal"
    if refine is not None:
        _refine(groups, pval, refine, rng)
    return stat, pval, notes, settings


def _refine(groups, pval, refine, rng):
    alpha, method, n_mc_max = refine
    for name in MC_TESTS:
        j = TESTS.index(name)
        while True:
            p = pval[:, j]
            ok = np.isfinite(p)
            if not ok.any():
                break
            n_reject = int(multipletests(p[ok], alpha=alpha, method=method)[0].sum())
            cutoff = alpha * (n_reject + 1) / ok.sum()
            todo = []
            for g in groups:
                if name not in g.null or g.null[name].size >= n_mc_max:
                    continue
                pg = pval[g.members, j]
                # Fewer than ~10 null exceedances: the p-value is too coarse to compare
                # with the cut-off.
                if np.any((pg > cutoff) & (pg * (g.null[name].size + 1) < 11)):
                    todo.append(g)
            if not todo:
                break
            for g in todo:
                g.extend(name, min(g.null[name].size + 1, n_mc_max - g.null[name].size), rng)
                pval[g.members, j] = g.pvalue(name)


#: The largest Monte Carlo null: 10^7 simulated sequences already pin a p-value to 3e-4
#: relative (binomial), and a null is held in memory whole.
N_MC_MAX = 10**7


def check_nulls(nulls):
    """``nulls``: None or a `MonteCarloNulls`."""
    if nulls is not None and not isinstance(nulls, MonteCarloNulls):
        raise TypeError(f"nulls: expected a MonteCarloNulls or None, got {type(nulls).__name__}")
    return nulls


def _check_options(n_mc, lags, n_bins):
    n_mc = check_int("n_mc", n_mc, low=19, high=N_MC_MAX)
    if lags is not None:
        lags = check_int("lags", lags, low=1)
    if n_bins is not None:
        n_bins = check_int("n_bins", n_bins, low=2)
    return n_mc, lags, n_bins


def test_poisson(times, t_window, *, n_mc=999, lags=None, n_bins=None, randomize=True, rng=None,
                 nulls=None):
    r"""Test whether one event sequence is a homogeneous Poisson process.

    Parameters
    ----------
    times : array_like
        Strictly increasing event times in ``[0, t_window]``.
    t_window : float
        Observation window ``T``.
    n_mc : int, optional
        Monte Carlo samples of the conditional nulls (p-value resolution
        ``1/(n_mc + 1)``), from 19 to ``N_MC_MAX`` = 10^7.
    lags : int, optional
        Ljung-Box lags (default ``min(10, (n - 1) // 5)``).
    n_bins : int, optional
        Equal sub-windows of the dispersion test (default ``clip(n // 5, 2, 20)``,
        about five expected events per sub-window).
    randomize : bool, optional
        Break ties of the discrete statistics (runs, dispersion) at random so that
        those tests have exactly their nominal size; ``False`` gives conservative
        p-values.
    rng : Generator or int, optional
        Source of randomness for the Monte Carlo.
    nulls : MonteCarloNulls, optional
        Take the Monte Carlo nulls from this bank (shared with every call given it)
        instead of drawing them from ``rng``; ``rng`` still breaks the ties.

    Returns
    -------
    pandas.DataFrame
        Indexed by test (``TESTS``), columns ``statistic``, ``pvalue``, ``null`` (how the
        p-value is computed) and ``note`` (why a test could not run: its row is NaN).
        ``attrs`` holds ``n_events``, ``t_window``, ``rate``, ``lags``, ``n_bins``.

    Notes
    -----
    ``uniformity_ks``: KS distance of :math:`t_i/T` from U(0, 1). ``laplace_trend``:
    :math:`z = (\bar t/T - 1/2)\sqrt{12 n}`. ``exponential_ks``: KS distance of the
    inner intervals from an exponential with rate 1/mean (Lilliefors);
    ``exponential_ad``: the Anderson-Darling distance, more powerful in the tails.
    ``ljung_box``: :math:`Q` of the inner intervals. ``runs``: number of runs
    above/below the median of the inner intervals (Wald-Wolfowitz). ``dispersion``:
    variance-to-mean ratio of counts in equal sub-windows (two-sided). All are
    conditional on n (see the module notes).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> rng = np.random.default_rng(0)
    >>> t = np.sort(rng.uniform(0, 100, size=rng.poisson(100)))
    >>> res = stats.test_poisson(t, 100.0, rng=1)
    >>> list(res.index)[:2]
    ['uniformity_ks', 'laplace_trend']
    """
    t_window = check_real("t_window", t_window, low=0.0)
    t = check_times("times", times, t_window)
    n_mc, lags, n_bins = _check_options(n_mc, lags, n_bins)
    rng = check_rng(rng)
    stat, pval, notes, used = _run_tests(
        [t],
        np.array([t_window]),
        lags=lags,
        n_bins=n_bins,
        n_mc=n_mc,
        rng=rng,
        randomize=randomize,
        nulls=check_nulls(nulls),
    )
    table = pd.DataFrame(
        {
            "statistic": stat[0],
            "pvalue": pval[0],
            "null": [TEST_NULLS[name] for name in TESTS],
            "note": [notes[0].get(name, "") for name in TESTS],
        },
        index=pd.Index(TESTS, name="test"),
    )
    table.attrs.update(
        n_events=int(t.size), t_window=t_window, rate=t.size / t_window, n_mc=n_mc, **used[0]
    )
    return table


test_poisson.__test__ = False  # a library function, not a pytest test
