"""Arrays whose rows start on cache lines, for the N-disk engine's tables.

A large NumPy array starts 16 bytes past a page (the allocator's header), so each 64-byte
row of the engine's disk table (`kicktimes.billiard.kernels.disks`, eight float64 per
disk) would straddle two cache lines, and a scan of a neighbour's row would touch two.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CACHE_LINE", "aligned_zeros"]

#: the cache line of x86-64 CPUs, in bytes
CACHE_LINE = 64


def aligned_zeros(shape: tuple, dtype) -> np.ndarray:
    """A zeroed C-contiguous array of ``shape`` and ``dtype`` whose first element starts on
    a `CACHE_LINE` boundary (a view into a slightly larger buffer).

    >>> a = aligned_zeros((1000, 8), np.float64)
    >>> a.ctypes.data % CACHE_LINE, a.shape, a.flags.c_contiguous, float(a.sum())
    (0, (1000, 8), True, 0.0)
    """
    dtype = np.dtype(dtype)
    size = int(np.prod(shape)) * dtype.itemsize
    buf = np.zeros(size + CACHE_LINE, dtype=np.uint8)
    start = (-buf.ctypes.data) % CACHE_LINE
    return buf[start:start + size].view(dtype).reshape(shape)
