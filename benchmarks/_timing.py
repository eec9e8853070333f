"""The timing helper the benchmarks share: the minimum over repeats of one call."""

import time


def best_time(func, repeats=3, clock=time.perf_counter):
    """Seconds of the fastest of ``repeats`` calls of ``func()`` on ``clock`` (wall time by
    default; ``time.process_time`` for CPU time on a shared machine)."""
    best = float("inf")
    for _ in range(repeats):
        start = clock()
        func()
        best = min(best, clock() - start)
    return best
