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

The arrays (`new_calendar`; memory O(n): 36 bytes per disk and 4 per bucket, ``nb`` the
power of two at or above ``max(64, 2 n)``):

* ``qt[i]`` the event time of disk ``i``; ``qi[i] = (where, next, prev, heap slot,
  disk at heap slot i)``, where ``where`` is `IN_HEAP`, `OVERFLOW`, `NEVER` or the
  bucket slot ``kb % nb`` of a listed disk;
* ``ht[k]`` the times of the heap (slot ``k``; ``qi[k, HEAP_DISK]`` its disk);
* ``qh[b]`` the first disk of bucket slot ``b`` (``qh[nb]`` the overflow list), -1 empty;
* ``qs = [heap size, current bucket, first bucket of the window, nb]`` and
  ``qw = [1 / bw]``.

Bucket numbers are ``kb = int(t / bw)`` (monotone in ``t``): every listed disk's event is
later than every event in the heap.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from kicktimes.billiard.kernels import cells

__all__ = ["IN_HEAP", "NEVER", "OVERFLOW", "build", "new_calendar", "remove", "schedule",
           "top", "update"]

#: ``qi`` columns
WHERE, NEXT, PREV, SLOT, HEAP_DISK = range(5)
#: ``where`` codes other than a bucket slot
IN_HEAP, OVERFLOW, NEVER = -1, -2, -3
#: ``qs`` fields
HN, CUR, WIN, NB = range(4)


def new_calendar(n: int, mean_spacing: float):
    """Empty calendar arrays ``(qt, qi, ht, qh, qs, qw)`` for ``n`` disks whose events are
    ``mean_spacing`` apart on average (fill with `build`)."""
    nb = 64
    while nb < 2 * n:
        nb *= 2
    bw = 2.0 * mean_spacing if mean_spacing > 0.0 and np.isfinite(mean_spacing) else 1.0
    qt = np.full(n, np.inf)
    qi = np.full((n, 5), -1, dtype=np.int32)
    ht = np.empty(n)
    qh = np.full(nb + 1, -1, dtype=np.int32)
    qs = np.array([0, 0, 0, nb], dtype=np.int64)
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


# --- the bucket lists ------------------------------------------------------------------------
@njit(cache=True, inline="always", error_model="numpy")
def _list_push(qi, qh, i, b, where):
    cells.insert(qh, qi, NEXT, PREV, i, b)
    qi[i, WHERE] = where


@njit(cache=True, inline="always", error_model="numpy")
def _list_remove(qi, qh, i, b):
    cells.remove(qh, qi, NEXT, PREV, i, b)


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
        _list_push(qi, qh, i, b, b)
    else:
        _list_push(qi, qh, i, nb, OVERFLOW)


@njit(cache=True, inline="always", error_model="numpy")
def remove(qt, qi, ht, qh, qs, i):
    """Take disk ``i`` out of the calendar."""
    wh = qi[i, WHERE]
    if wh == IN_HEAP:
        _heap_remove(qi, ht, qs, i)
    elif wh >= 0:
        _list_remove(qi, qh, i, wh)
    elif wh == OVERFLOW:
        _list_remove(qi, qh, i, qs[NB])
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
    while qs[HN] == 0:
        cur = qs[CUR] + 1
        if cur >= qs[WIN] + nb:
            # every bucket of the window is done (its lists are empty): the next window
            # starts at the earliest overflow event's bucket, skipping empty stretches
            i = qh[nb]
            if i < 0:
                return False
            t_min = np.inf
            while i >= 0:
                t_min = min(t_min, qt[i])
                i = qi[i, NEXT]
            cur = max(cur, int(t_min * qw[0]))
            qs[WIN] = cur
            i = qh[nb]
            qh[nb] = -1
            while i >= 0:
                j = qi[i, NEXT]
                kb = int(qt[i] * qw[0])
                if kb < cur + nb:
                    _list_push(qi, qh, i, kb % nb, kb % nb)
                else:
                    _list_push(qi, qh, i, nb, OVERFLOW)
                i = j
        qs[CUR] = cur
        b = cur % nb
        i = qh[b]
        qh[b] = -1
        while i >= 0:
            j = qi[i, NEXT]
            _heap_push(qi, ht, qs, i, qt[i])
            i = j
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
    for b in range(qh.shape[0]):
        qh[b] = -1
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
