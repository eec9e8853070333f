"""Process-wide memory settings for kicktimes' own processes (no heavy imports: the
report's and the sweep's pools install `keep_freed_memory` as their initializer; the
command line and `build_report` run under `fewer_collections`)."""

from __future__ import annotations

import ctypes
import gc
import sys
from contextlib import contextmanager

# glibc mallopt parameters <malloc.h>
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_MMAP_THRESHOLD = 32 * 2**20  # glibc's ceiling on 64-bit
_TRIM_THRESHOLD = 256 * 2**20


def keep_freed_memory() -> bool:
    """Let ``free`` keep memory for reuse instead of handing it back.

    Every kernel call returns fresh arrays (samples, logs, cell lists: 0.1-2 MB per
    trajectory). By default glibc serves blocks above a dynamic threshold (128 kB to start)
    with ``mmap`` and returns them to the system on ``free``, so the next call's arrays
    are new pages again, and each first touch of a page is a page fault (a costly exit on
    a virtual machine). Serving blocks below 32 MB from the heap and trimming it only
    above 256 MB of free memory removes nearly all of them and makes the sweep's tasks
    faster (benchmarks/bench_memory.py; docs/benchmarks.md). A worker keeps at most that much freed
    memory. Returns whether it applied (glibc only; elsewhere nothing changes).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc (e.g. musl): leave the allocator alone
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD)) and bool(
        mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD)
    )


#: Generation thresholds of the cyclic garbage collector inside `fewer_collections`
#: (CPython's defaults: 700, 10, 10).
_GC_THRESHOLDS = (100_000, 20, 10)


@contextmanager
def fewer_collections():
    """Run CPython's cyclic garbage collector less often inside the block.

    By default CPython collects its youngest generation every 700 net allocations of
    container objects, and the whole heap after about a hundred of those. A report
    allocates millions of short-lived objects (matplotlib artists, pandas frames) on a
    heap of millions of imported ones, so most of the collector's time went to full
    collections that found little: 1.7 of the quick report's 14 CPU seconds, 2.3 s of
    the paper report's. Collecting the youngest generation every 100 000 allocations and
    the middle one every 20 of those keeps the same collector, with every reference
    cycle still freed, at a fraction of the cost, with the same files and no larger peak
    memory (``benchmarks/bench_startup.py``, section 2; docs/benchmarks.md). The previous
    thresholds are restored on exit (never lowered: the larger of each pair applies);
    processes forked inside the block inherit the setting.
    """
    old = gc.get_threshold()
    gc.set_threshold(*(max(a, b) for a, b in zip(_GC_THRESHOLDS, old, strict=True)))
    try:
        yield
    finally:
        gc.set_threshold(*old)
