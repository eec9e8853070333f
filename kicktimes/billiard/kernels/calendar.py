"""The event calendar of the N-disk engine: a bucket queue, one entry per disk.

Each disk has exactly one scheduled event, its earliest predicted one (docs/disks.md,
"Algorithm"); the calendar gives the disk whose event comes first. It is a bucket queue
(a calendar queue, as DynamO's bounded priority queue): time is cut into buckets of width
``bw``; the disks whose events fall in the current bucket are kept in a small indexed
binary heap, those of the next ``nb - 1`` buckets in one doubly linked list per bucket
(unsorted), later ones in an overflow list that is redistributed once every ``nb``
buckets, and disks with no event (``inf``: escaped) in none. With ``bw`` about two mean
event spacings, a disk's event is rescheduled in O(1) (a list insertion) and the heap
holds a handful of disks, so the cost per event does not grow with the number of disks
(a binary heap over all disks costs 130 ns per update at 10^2 disks and 240 ns at 10^4,
benchmarks/bench_disks.py).

Events that other disks' collisions made stale (a partner that has moved since the
prediction) stay in the calendar and are recognised when they come to the top, by the
per-disk event counters of the engine (`kicktimes.billiard.kernels.disks`): lazy
invalidation, without a search.

The bucket lists are lazy too. A list is a chain of *nodes* ``(disk, next)`` in a pool;
a disk filed in a list gets a new node at the list's front, and taking it out (it is
rescheduled) only changes its own row: its node stays in the chain, stale, and is
skipped and freed when the bucket is emptied into the heap. So filing a disk writes the
bucket's head and a node from the free stack (warm: the last one freed), never the rows
of the disks beside it in the list, which at 10^5-10^6 disks are cache misses. The live
nodes come out in the order of a doubly linked list with the same insertions and
removals (newest first), so the heap, and every tie between equal times, is as before.
When the pool runs out, the stale nodes of every list are unlinked in one pass
(`_collect`, order kept).

The arrays (`new_calendar`; memory O(n): about 70 bytes per disk and 4 per bucket, ``nb``
the power of two at or above ``max(64, 2 n)``, a pool of ``4 n + 64`` nodes):

* ``qt[i]`` the event time of disk ``i``; ``qi[i] = (where, node, -, heap slot, disk at
  heap slot i)``, where ``where`` is `IN_HEAP`, `OVERFLOW`, `NEVER` or the bucket slot
  ``kb % nb`` of a listed disk, and ``node`` its live node there;
* ``ht[k]`` the times of the heap (slot ``k``; ``qi[k, HEAP_DISK]`` its disk);
* ``qh[b]`` the first node of bucket slot ``b`` (``qh[nb]`` the overflow list), -1 empty;
  then the pool: node ``k`` is ``qh[P + 2k]`` (its disk) and ``qh[P + 2k + 1]`` (the next
  node, -1 at the end; for a free node the next free one), ``P = nb + 1``;
* ``qs = [heap size, current bucket, first bucket of the window, nb, first free node,
  pool size, collections]`` and ``qw = [1 / bw]``.

Bucket numbers are ``kb = int(t / bw)`` (monotone in ``t``): every listed disk's event is
later than every event in the heap.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["IN_HEAP", "NEVER", "OVERFLOW", "build", "new_calendar", "remove", "schedule",
           "top", "update"]

#: ``qi`` columns (``NODE``: the disk's live node in its bucket list)
WHERE, NODE, _SPARE, SLOT, HEAP_DISK = range(5)
#: ``where`` codes other than a bucket slot
IN_HEAP, OVERFLOW, NEVER = -1, -2, -3
#: ``qs`` fields
HN, CUR, WIN, NB, FREE, POOL, N_COLLECT = range(7)


def new_calendar(n: int, mean_spacing: float, pool: int | None = None):
    """Empty calendar arrays ``(qt, qi, ht, qh, qs, qw)`` for ``n`` disks whose events are
    ``mean_spacing`` apart on average (fill with `build`); ``pool`` list nodes (default
    ``4 n + 64``; at least ``n + 1``)."""
    nb = 64
    while nb < 2 * n:
        nb *= 2
    pool = 4 * n + 64 if pool is None else max(int(pool), n + 1)
    bw = 2.0 * mean_spacing if mean_spacing > 0.0 and np.isfinite(mean_spacing) else 1.0
    qt = np.full(n, np.inf)
    qi = np.full((n, 5), -1, dtype=np.int32)
    ht = np.empty(n)
    qh = np.full(nb + 1 + 2 * pool, -1, dtype=np.int32)
    qs = np.array([0, 0, 0, nb, -1, pool, 0], dtype=np.int64)
    qw = np.array([1.0 / bw])
    return qt, qi, ht, qh, qs, qw


# --- the heap of the current bucket -------------------------------------------------------
@njit(cache=True, inline="always", error_model="numpy")
def _put(qi, ht, k, t, i):
    """Heap slot ``k`` holds disk ``i`` with time ``t``; the disk knows its slot."""
    ht[k] = t
    qi[k, HEAP_DISK] = i
    qi[i, SLOT] = k


@njit(cache=True, inline="always", error_model="numpy")
def _sift_up(qi, ht, k):
    t = ht[k]
    i = qi[k, HEAP_DISK]
    while k > 0:
        p = (k - 1) >> 1
        if ht[p] <= t:
            break
        _put(qi, ht, k, ht[p], qi[p, HEAP_DISK])
        k = p
    _put(qi, ht, k, t, i)


@njit(cache=True, inline="always", error_model="numpy")
def _sift_down(qi, ht, k, n):
    t = ht[k]
    i = qi[k, HEAP_DISK]
    while True:
        c = 2 * k + 1
        if c >= n:
            break
        if c + 1 < n and ht[c + 1] < ht[c]:
            c += 1
        if ht[c] >= t:
            break
        _put(qi, ht, k, ht[c], qi[c, HEAP_DISK])
        k = c
    _put(qi, ht, k, t, i)


@njit(cache=True, inline="always", error_model="numpy")
def _heap_push(qi, ht, qs, i, t):
    k = qs[HN]
    qs[HN] = k + 1
    ht[k] = t
    qi[k, HEAP_DISK] = i
    qi[i, WHERE] = IN_HEAP
    _sift_up(qi, ht, k)


@njit(cache=True, inline="always", error_model="numpy")
def _heap_remove(qi, ht, qs, i):
    k = qi[i, SLOT]
    n = qs[HN] - 1
    qs[HN] = n
    if k < n:
        _put(qi, ht, k, ht[n], qi[n, HEAP_DISK])
        if k > 0 and ht[k] < ht[(k - 1) >> 1]:
            _sift_up(qi, ht, k)
        else:
            _sift_down(qi, ht, k, n)


# --- the bucket lists: chains of pool nodes, stale nodes skipped ------------------------------
@njit(cache=True, inline="always", error_model="numpy")
def _free_all(qh, qs):
    """Every node on the free stack (the lists are empty)."""
    p = qs[NB] + 1
    pool = qs[POOL]
    for k in range(pool):
        qh[p + 2 * k + 1] = k + 1
    qh[p + 2 * pool - 1] = -1
    qs[FREE] = 0


@njit(cache=True, inline="always", error_model="numpy")
def _free(qh, qs, node):
    qh[qs[NB] + 2 + 2 * node] = qs[FREE]
    qs[FREE] = node


@njit(cache=True, inline="always", error_model="numpy")
def _live(qi, i, node, where):
    """Node ``node`` of disk ``i`` in the list ``where`` is the disk's live entry."""
    return qi[i, WHERE] == where and qi[i, NODE] == node


@njit(cache=True, error_model="numpy")
def _collect(qi, qh, qs):
    """Unlink and free the stale nodes of every list, keeping the order of the others."""
    nb = qs[NB]
    p = nb + 1
    qs[N_COLLECT] += 1
    for b in range(nb + 1):
        where = b if b < nb else OVERFLOW
        prev = -1
        node = qh[b]
        while node >= 0:
            nxt = qh[p + 2 * node + 1]
            if _live(qi, qh[p + 2 * node], node, where):
                prev = node
            else:
                if prev < 0:
                    qh[b] = nxt
                else:
                    qh[p + 2 * prev + 1] = nxt
                _free(qh, qs, node)
            node = nxt


@njit(cache=True, inline="always", error_model="numpy")
def _list_push(qi, qh, qs, i, b, where):
    """File disk ``i`` at the front of list ``b`` (a new node; ``where``: its code)."""
    node = qs[FREE]
    if node < 0:
        _collect(qi, qh, qs)
        node = qs[FREE]
    p = qs[NB] + 1
    qs[FREE] = qh[p + 2 * node + 1]
    qh[p + 2 * node] = i
    qh[p + 2 * node + 1] = qh[b]
    qh[b] = node
    qi[i, NODE] = node
    qi[i, WHERE] = where


# --- the calendar ---------------------------------------------------------------------------
@njit(cache=True, inline="always", error_model="numpy")
def schedule(qt, qi, ht, qh, qs, qw, i, t):
    """File disk ``i`` (in no list or heap) with event time ``t``."""
    qt[i] = t
    if t == np.inf:
        qi[i, WHERE] = NEVER
        return
    kb = int(t * qw[0])
    nb = qs[NB]
    if kb <= qs[CUR]:
        _heap_push(qi, ht, qs, i, t)
    elif kb < qs[WIN] + nb:
        b = kb % nb
        _list_push(qi, qh, qs, i, b, b)
    else:
        _list_push(qi, qh, qs, i, nb, OVERFLOW)


@njit(cache=True, inline="always", error_model="numpy")
def remove(qt, qi, ht, qh, qs, i):
    """Take disk ``i`` out of the calendar (out of a list: its node goes stale)."""
    if qi[i, WHERE] == IN_HEAP:
        _heap_remove(qi, ht, qs, i)
    qi[i, WHERE] = NEVER


@njit(cache=True, inline="always", error_model="numpy")
def update(qt, qi, ht, qh, qs, qw, i, t):
    """Give disk ``i`` the event time ``t``."""
    if qi[i, WHERE] == IN_HEAP and t < np.inf and int(t * qw[0]) <= qs[CUR]:
        # stays in the current bucket: move it within the heap
        k = qi[i, SLOT]
        old = ht[k]
        ht[k] = t
        qt[i] = t
        if t < old:
            _sift_up(qi, ht, k)
        else:
            _sift_down(qi, ht, k, qs[HN])
        return
    remove(qt, qi, ht, qh, qs, i)
    schedule(qt, qi, ht, qh, qs, qw, i, t)


@njit(cache=True, error_model="numpy")
def _advance(qt, qi, ht, qh, qs, qw):
    """Move on to the next bucket that holds events (the heap is empty); False if the
    calendar holds none at all."""
    nb = qs[NB]
    p = nb + 1
    while qs[HN] == 0:
        cur = qs[CUR] + 1
        if cur >= qs[WIN] + nb:
            # every bucket of the window is done (its lists are empty): the next window
            # starts at the earliest overflow event's bucket, skipping empty stretches
            t_min = np.inf
            node = qh[nb]
            while node >= 0:
                i = qh[p + 2 * node]
                if _live(qi, i, node, OVERFLOW):
                    t_min = min(t_min, qt[i])
                node = qh[p + 2 * node + 1]
            if t_min == np.inf:
                # no live overflow event: the stale nodes go back to the pool
                node = qh[nb]
                qh[nb] = -1
                while node >= 0:
                    nxt = qh[p + 2 * node + 1]
                    _free(qh, qs, node)
                    node = nxt
                return False
            cur = max(cur, int(t_min * qw[0]))
            qs[WIN] = cur
            node = qh[nb]
            qh[nb] = -1
            while node >= 0:
                nxt = qh[p + 2 * node + 1]
                i = qh[p + 2 * node]
                live = _live(qi, i, node, OVERFLOW)
                _free(qh, qs, node)
                if live:
                    kb = int(qt[i] * qw[0])
                    if kb < cur + nb:
                        _list_push(qi, qh, qs, i, kb % nb, kb % nb)
                    else:
                        _list_push(qi, qh, qs, i, nb, OVERFLOW)
                node = nxt
        qs[CUR] = cur
        b = cur % nb
        node = qh[b]
        qh[b] = -1
        while node >= 0:
            nxt = qh[p + 2 * node + 1]
            i = qh[p + 2 * node]
            if _live(qi, i, node, b):
                _heap_push(qi, ht, qs, i, qt[i])
            _free(qh, qs, node)
            node = nxt
    return True


@njit(cache=True, inline="always", error_model="numpy")
def top(qt, qi, ht, qh, qs, qw):
    """``(i, t)``: the disk with the earliest event and its time (``-1, inf``: none)."""
    if qs[HN] == 0:
        if not _advance(qt, qi, ht, qh, qs, qw):
            return -1, np.inf
    return qi[0, HEAP_DISK], ht[0]


@njit(cache=True, error_model="numpy")
def build(qt, qi, ht, qh, qs, qw, times):
    """Empty the calendar and file the event times ``times[i]`` of disks ``0..n-1``; the
    current bucket is the one of the earliest time."""
    n = times.shape[0]
    for b in range(qs[NB] + 1):
        qh[b] = -1
    _free_all(qh, qs)
    qs[HN] = 0
    t_min = np.inf
    for i in range(n):
        t_min = min(t_min, times[i])
    kb = int(t_min * qw[0]) if t_min < np.inf else 0
    qs[CUR] = kb
    qs[WIN] = kb
    for i in range(n):
        qi[i, WHERE] = NEVER
        schedule(qt, qi, ht, qh, qs, qw, i, times[i])
