r"""Starting points of the MMPP's EM: where the likelihood's maxima are, before the EM.

The likelihood of an MMPP has several local maxima, and the EM climbs to the one whose
basin holds its start. Starts drawn near the local event rates reach the maxima in which
every state holds many events; on collision times the global one often has a **burst
state** instead: a rate hundreds of times the mean, entered a few times and left at
once, which fits a handful of near-coincident events (issue 39). The starts here cover
the regimes a two-state chain can be in, each built from the data (all in the fit's unit,
mean event rate 1):

* ``"cluster"``: a burst state from the shortest gaps: with a threshold ``tau``, the
  maximal runs of consecutive gaps below ``tau`` within a window are clusters; with
  ``c`` clusters holding ``e`` events over a time ``d``, the burst state has rate
  ``(e - c) / d`` and is left at rate ``c / d``, the background has the other events'
  rate ``(N - e + c) / (T - d)`` and is left at rate ``c / (T - d)``. Thresholds just
  above the 1st, 2nd, 4th, ... shortest gap and at fractions of the mean gap;
* ``"quiet"``: a nearly silent state from the longest gaps: the gaps above ``tau`` are
  rests in a state of rate 0.02, left after the mean long gap; the active state holds
  every event (the optimum of some collision sequences has a state of rate 0);
* ``"local"``: quantiles of local event rates (blocks of up to 8 gaps) with slow
  switching, every 20 and every 100 events (the starts before issue 39);
* ``"fast"`` and ``"slow"``: the switching limits, rates 0.3 and 3 times the mean
  switching 30 times per mean gap, and quantiles of block rates over about 30 gaps
  switching once in all the windows;
* ``"random"``: rates and switching rates drawn log-uniformly (rates in
  ``[0.05, 200]``, switching rates in ``[1e-3, 30]``), the remaining starts.

For more than two states the burst state is the top one (the quiet state the bottom
one) and the other states take quantiles of the local rates. The order of
:func:`structured_starts` is the order of priority: :func:`starting_points` takes the
first ``n_starts - n_starts // 6`` and adds ``n_starts // 6`` random ones.

The Poisson fit is nested, not a start: an MMPP whose rates are equal has exactly its
likelihood, whatever ``Q``, and the EM cannot leave that point (the states are not told
apart). ``fit.py`` takes it when no start ends above it.
"""

from __future__ import annotations

import numpy as np

#: thresholds of the cluster starts: just above the k-th shortest gap, and fractions of
#: the mean gap (the two lists interleaved, duplicates dropped)
_CLUSTER_RANKS = (1, 2, 4, 8, 16)
_CLUSTER_FRACTIONS = (0.01, 0.1, 0.3)
#: thresholds of the quiet starts: between the k-th and (k+1)-th longest gap, and
#: multiples of the mean gap
_QUIET_RANKS = (2, 4, 8, 16)
_QUIET_MULTIPLES = (3.0, 5.0)


def _gaps(data):
    """The intervals between consecutive events of each window, and their window ids."""
    parts, owner = [], []
    for w in range(data.n_windows):
        xs = data.x[data.start[w] + 1:data.start[w + 1] - 1]
        parts.append(xs)
        owner.append(np.full(xs.size, w))
    if not parts:
        return np.empty(0), np.empty(0, dtype=int)
    return np.concatenate(parts), np.concatenate(owner)


def _generator(q):
    Q = np.array(q, dtype=float)
    np.fill_diagonal(Q, 0.0)
    np.fill_diagonal(Q, -Q.sum(axis=1))
    return Q


def _two(rates, q01, q10):
    return np.array(rates, dtype=float), _generator([[0.0, q01], [q10, 0.0]])


def _cluster(gaps, owner, tau, total_time, n_events):
    """A burst start from the gaps below ``tau`` (see the module notes), or None."""
    short = gaps < tau
    if not short.any() or short.all():
        return None
    # a cluster starts at a short gap whose predecessor is long or in another window
    new = short & ~np.concatenate(([False], short[:-1] & (owner[1:] == owner[:-1])))
    c = int(new.sum())
    d = float(gaps[short].sum())
    e = int(short.sum()) + c
    if d <= 0.0 or d >= total_time:
        return None
    burst = min((e - c) / d, 1e5)
    background = max(n_events - e + c, 1) / (total_time - d)
    return burst, c / d, background, c / (total_time - d)


def _quiet(gaps, tau, total_time, n_events):
    """A quiet-state start from the gaps above ``tau``: the chain rests in a nearly
    silent state (rate 0.02) through each long gap and leaves it after the mean long gap;
    the active state holds every event, or None."""
    long = gaps > tau
    k = int(long.sum())
    if k == 0 or long.all():
        return None
    rest = float(gaps[long].sum())
    if rest >= total_time:
        return None
    return 0.02, k / rest, n_events / (total_time - rest), k / (total_time - rest)


def _quiet_thresholds(gaps):
    srt = np.sort(gaps)[::-1]
    mean = gaps.mean()
    out = []
    by_rank = [0.5 * (srt[k - 1] + srt[k]) for k in _QUIET_RANKS if k < srt.size]
    by_multiple = [f * mean for f in _QUIET_MULTIPLES]
    for pair in zip(by_rank, by_multiple + [None] * len(by_rank), strict=False):
        for tau in pair:
            if tau is not None and not any(np.sum(gaps > tau) == np.sum(gaps > t)
                                           for t in out):
                out.append(tau)
    return out


def _cluster_thresholds(gaps):
    srt = np.sort(gaps)
    mean = gaps.mean()
    out = []
    by_rank = [0.5 * (srt[k - 1] + srt[k]) for k in _CLUSTER_RANKS if k < srt.size]
    by_fraction = [f * mean for f in _CLUSTER_FRACTIONS]
    for pair in zip(by_rank, by_fraction + [None] * len(by_rank), strict=False):
        for tau in pair:
            # thresholds that select the same gaps are the same start
            if tau is not None and not any(np.sum(gaps < tau) == np.sum(gaps < t)
                                           for t in out):
                out.append(tau)
    return out


def _local_rates(data, block):
    local = []
    for w in range(data.n_windows):
        xs = data.x[data.start[w]:data.start[w + 1] - 1]
        m = min(block, xs.size)
        if m:
            sums = xs[: xs.size // m * m].reshape(-1, m).sum(axis=1)
            local.append(m / np.maximum(sums, 1e-300))
    return np.concatenate(local) if local else np.ones(1)


def _spread(local, n, mean_rate):
    if local.size < 2 * n or np.ptp(local) == 0:
        local = mean_rate * np.linspace(0.5, 1.5, 2 * n)
    return local


def structured_starts(data, n):
    """The structured starts ``(rates, Q, kind)`` in the fit's unit, in order of priority
    (see the module notes)."""
    mean_rate = float(data.n_events.sum()) / max(data.total_time, 1e-300)
    local = _spread(_local_rates(data, 8), n, mean_rate)
    slow_local = _spread(_local_rates(data, 30), n, mean_rate)
    q_local = [(np.quantile(local, (np.arange(n) + 0.5) / n), 0.05),
               (np.quantile(local, (np.arange(n) + 1.0) / (n + 1)), 0.01)]
    gaps, owner = _gaps(data)
    clusters, quiets = [], []
    if gaps.size >= 2:
        for tau in _cluster_thresholds(gaps):
            c = _cluster(gaps, owner, tau, data.total_time, data.n_events.sum())
            if c is not None:
                clusters.append(c)
        for tau in _quiet_thresholds(gaps):
            c = _quiet(gaps, tau, data.total_time, data.n_events.sum())
            if c is not None:
                quiets.append(c)
    def quiet(c):
        rate_lo, leave_lo, rate_hi, leave_hi = c
        if n == 2:
            return _two([rate_lo * mean_rate, rate_hi * mean_rate], leave_lo * mean_rate,
                        leave_hi * mean_rate)
        high = np.quantile(local, (np.arange(n - 1) + 0.5) / (n - 1)) * rate_hi
        Q = np.full((n, n), 0.05 * mean_rate / (n - 2))
        Q[0, 1:] = leave_lo * mean_rate / (n - 1)
        Q[1:, 0] = leave_hi * mean_rate
        return np.concatenate([[rate_lo * mean_rate], high]), _generator(Q)

    def lower_states(q):
        """``n - 1`` lower states from the local rates, switching at ``q``."""
        rates = np.quantile(local, (np.arange(n - 1) + 0.5) / (n - 1)) if n > 2 \
            else np.array([])
        return rates, q

    def burst(c):
        rate_hi, leave_hi, rate_lo, leave_lo = c
        if n == 2:
            return _two([rate_lo * mean_rate, rate_hi * mean_rate], leave_lo * mean_rate,
                        leave_hi * mean_rate)
        low, q = lower_states(0.05 * mean_rate / (n - 2))
        Q = np.full((n, n), q)
        Q[:n - 1, n - 1] = leave_lo * mean_rate
        Q[n - 1, :n - 1] = leave_hi * mean_rate / (n - 1)
        return np.concatenate([low, [rate_hi * mean_rate]]), _generator(Q)

    def uniform_q(rates, q):
        return rates, _generator(np.full((n, n), q * mean_rate / max(n - 1, 1)))

    fast = mean_rate * np.geomspace(0.3, 3.0, n)
    slow = np.quantile(slow_local, (np.arange(n) + 0.5) / n)
    # one of each kind first, then the further thresholds, alternating
    structured = [(*burst(c), "cluster") for c in clusters[:1]]
    structured += [(*quiet(c), "quiet") for c in quiets[:1]]
    structured.append((*uniform_q(*q_local[0]), "local"))
    structured += [(*burst(c), "cluster") for c in clusters[1:2]]
    structured += [(*quiet(c), "quiet") for c in quiets[1:2]]
    structured.append((*uniform_q(*q_local[1]), "local"))
    structured.append((*uniform_q(fast, 30.0), "fast"))
    structured.append((*uniform_q(slow, 1.0 / max(data.total_time, 1e-300)), "slow"))
    for k in range(2, max(len(clusters), len(quiets))):
        structured += [(*burst(c), "cluster") for c in clusters[k:k + 1]]
        structured += [(*quiet(c), "quiet") for c in quiets[k:k + 1]]
    return [_sorted(rates, Q, kind, mean_rate) for rates, Q, kind in structured]


def _sorted(rates, Q, kind, mean_rate):
    rates = np.clip(np.asarray(rates, dtype=float), 1e-3 * mean_rate, None)
    order = np.argsort(rates, kind="stable")
    return rates[order], Q[np.ix_(order, order)], kind


def starting_points(data, n, n_starts, rng):
    """``n_starts`` starts ``(rates, Q, kind)`` in the fit's unit: structured ones in
    order of priority, then ``n_starts // 6`` random ones (more if the data give fewer
    structured starts)."""
    points = structured_starts(data, n)[:n_starts - n_starts // 6]
    mean_rate = float(data.n_events.sum()) / max(data.total_time, 1e-300)
    while len(points) < n_starts:
        rates = mean_rate * 10.0 ** rng.uniform(np.log10(0.05), np.log10(200.0), n)
        q = mean_rate * 10.0 ** rng.uniform(-3.0, np.log10(30.0), (n, n))
        points.append(_sorted(rates, _generator(q), "random", mean_rate))
    return points
