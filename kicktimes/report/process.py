"""The sweep report built in a process forked before the sweeps (`ReportProcess`), and
`build_stores_report`, the report of one store or several.

``kicktimes reproduce --study paper`` forks the report's process first: it imports the
report's modules (matplotlib, scipy, statsmodels: about 2 s) and loads (on a cold cache:
compiles) the report's kernels while the driver runs the sweeps, on the core the driver's
imports leave idle; the report starts at once when the sweeps end, and its workers, forked
from that process, inherit all of it (docs/benchmarks.md, "Measurements behind design
choices").
"""

from __future__ import annotations

import pickle

__all__ = ["ReportProcess", "build_stores_report"]


def build_stores_report(stores, out, workers=None, progress=None, pdf=False, force=False):
    """`kicktimes.report.build_report` of the store ``stores[0]`` or of the stores
    ``stores`` (one part per experiment); returns the page's path."""
    from kicktimes.report import Render, build_report

    target = stores[0] if len(stores) == 1 else list(stores)
    return build_report(target, out, workers=workers, progress=progress, render=Render(pdf=pdf),
                        force=force)


def _serve(conn, driver_end):
    """Body of `ReportProcess`: import the report's modules, then build the one report the
    driver sends and send back ``("ok", path)`` or ``("error", exception)``."""
    driver_end.close()  # the fork's copy: else closing the driver's would never reach us
    from kicktimes import compilation
    from kicktimes.report import pipeline

    pipeline._stages()
    compilation.warm_report()
    try:
        job = conn.recv()
    except EOFError:  # the driver is gone, or had no report to build
        return
    try:
        result = ("ok", build_stores_report(*job))
    except BaseException as exc:  # noqa: BLE001  (handed to the driver, which raises it)
        result = ("error", exc)
    try:
        try:
            conn.send(result)
        except (TypeError, AttributeError, pickle.PicklingError):  # an unpicklable error
            exc = result[1]
            conn.send(("error", RuntimeError(f"{type(exc).__name__}: {exc}")))
    except OSError:  # the driver is gone (e.g. interrupted): nobody to tell
        pass


class ReportProcess:
    """A process, forked now, that builds one report when asked (`build`).

    Fork it before the driver starts any thread or pool. Use it as a context manager, or
    call `close` (a process still waiting for a job then ends).
    """

    def __init__(self):
        import multiprocessing as mp

        ctx = mp.get_context("fork")
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_serve, args=(child, self._conn),
                                 name="kicktimes-report")
        self._proc.start()
        child.close()

    def build(self, stores, out, workers=None, progress=None, pdf=False, force=False):
        """`build_stores_report` in the report process; raises what it raised."""
        self._conn.send((stores, out, workers, progress, pdf, force))
        try:
            status, value = self._conn.recv()
        except EOFError:
            raise RuntimeError(
                f"the report process ended unexpectedly (exit code {self._proc.exitcode})"
            ) from None
        if status == "error":
            raise value
        return value

    def close(self):
        self._conn.close()
        self._proc.join(timeout=10)
        if self._proc.is_alive():
            self._proc.terminate()
            self._proc.join()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
