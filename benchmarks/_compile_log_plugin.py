"""A pytest plugin for ``benchmarks/bench_suite.py``: every numba compilation of a test
run, with its exclusive and inclusive seconds and the test that caused it, one JSON file
per process in ``$KICKTIMES_COMPILE_LOG`` (a folder).

numba emits a ``numba:compile`` event only when it really compiles (not when it loads a
signature from its cache), so on a warm cache the log is empty.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

from numba.core import event


class _CompileLog(event.Listener):
    """(kernel, signature, exclusive s, inclusive s, test) of each compilation; a kernel
    compiled while another compiles is subtracted from the outer one's exclusive time."""

    def __init__(self):
        self.stack, self.rows, self.test = [], [], ""

    def on_start(self, ev):
        self.stack.append([time.perf_counter(), 0.0])

    def on_end(self, ev):
        start, inner = self.stack.pop()
        seconds = time.perf_counter() - start
        if self.stack:
            self.stack[-1][1] += seconds
        func = ev.data["dispatcher"].py_func
        self.rows.append((f"{func.__module__}.{func.__qualname__}", str(ev.data["args"]),
                          seconds - inner, seconds, self.test))


_LOG = _CompileLog()


def pytest_configure(config):
    event.register("numba:compile", _LOG)


def pytest_runtest_setup(item):
    _LOG.test = item.nodeid


def pytest_sessionfinish(session):
    folder = os.environ.get("KICKTIMES_COMPILE_LOG")
    if folder:
        name = os.environ.get("PYTEST_XDIST_WORKER", "main")
        Path(folder, f"{name}.json").write_text(json.dumps(_LOG.rows))
