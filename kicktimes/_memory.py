"""Process-wide allocator setting for kicktimes' own worker processes (no heavy imports:
the report's and the sweep's pools install it as their initializer)."""

from __future__ import annotations

import ctypes
import sys

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
    above 256 MB of free memory removes nearly all of them (648 000 -> 300 page faults on
    24 family-A tasks) and makes family-A tasks 1.5x and family-B tasks 1.14x faster
    (benchmarks/bench_memory.py, same run). A worker keeps at most that much freed
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
