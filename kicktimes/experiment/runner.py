"""Run a sweep on any ``concurrent.futures`` executor, streaming finished tasks to the store."""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, Executor, ProcessPoolExecutor, wait

from kicktimes.experiment.config import Experiment
from kicktimes.experiment.disks import DisksExperiment
from kicktimes.experiment.disks_tasks import execute_disks_task
from kicktimes.experiment.store import Store, StoreWriter, load_store
from kicktimes.experiment.tasks import execute_task
from kicktimes.memory import keep_freed_memory

__all__ = ["run_experiment"]


def _progress_enabled(progress) -> bool:
    if progress is not None:
        return bool(progress)
    # a bar on an interactive terminal only: CI logs and pipes stay quiet
    ci = os.environ.get("CI", "").strip().lower()
    return sys.stderr.isatty() and ci in ("", "0", "false", "no")


_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def _exit_with_parent(parent_pid: int, poll: float = 1.0) -> None:
    """Pool-worker initializer: the worker ends when the driver process ends.

    A ``ProcessPoolExecutor`` worker waits on a pipe that it shares with its siblings,
    so it never sees the driver die (SIGKILL, OOM killer) and would live on, holding
    memory. On Linux the kernel sends SIGKILL to the worker when its parent dies
    (``prctl(PR_SET_PDEATHSIG)``); everywhere, a daemon thread also checks the parent
    pid every ``poll`` seconds, which also covers a parent that died before the prctl.
    """
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # no usable libc: the watcher below suffices
            pass

    # Under "fork" and "spawn" the parent is the driver; under "forkserver" it is the
    # server process, which itself exits when the driver does.
    first_parent = os.getppid()

    def driver_alive() -> bool:
        if os.getppid() != first_parent:
            return False  # re-parented: our parent has died
        try:
            os.kill(parent_pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True  # it exists, under another user
        return True

    def watch():
        while driver_alive():
            time.sleep(poll)
        os._exit(1)  # orphaned: nobody will read our results

    if not driver_alive():
        os._exit(1)
    threading.Thread(target=watch, name="kicktimes-parent-watch", daemon=True).start()


def _worker_init(parent_pid: int) -> None:
    """Initializer of the local pool's workers: end with the driver
    (`_exit_with_parent`), keep freed memory for reuse (`keep_freed_memory`)."""
    _exit_with_parent(parent_pid)
    keep_freed_memory()


def _dask_executor(scheduler: str):
    try:
        from distributed import Client
    except ImportError:
        raise ImportError(
            "scheduler: running on a Dask cluster needs the optional dependency "
            "dask[distributed]; install it with  pip install 'kicktimes[dask]'"
        ) from None
    client = Client(scheduler)
    return client, client.get_executor()


def local_pool(workers: int | None = None) -> ProcessPoolExecutor:
    """The local process pool of `run_experiment` (``workers`` processes, default
    ``os.cpu_count()``), whose workers end with this process.

    Give it as ``executor=`` to several `run_experiment` calls (``kicktimes reproduce``
    runs both families on one) so that each worker imports kicktimes and loads the
    compiled kernels once (about a second per process) instead of once per sweep.
    """
    return ProcessPoolExecutor(
        max_workers=workers or os.cpu_count(),
        initializer=_worker_init,
        initargs=(os.getpid(),),
    )


def run_experiment(
    experiment,
    store,
    *,
    executor: Executor | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool | None = None,
    wait: bool | float = False,
) -> Store:
    """Run (or resume) a sweep and stream each finished task to the store.

    Parameters
    ----------
    experiment : Experiment, DisksExperiment or path-like
        The sweep (over radii, or over the number of disks N: `DisksExperiment`), or the
        path of an `Experiment`'s TOML file.
    store : path-like
        Store directory (created if needed). If it already holds this experiment the run
        resumes: finished tasks whose parts are intact are skipped, damaged or foreign
        parts are reported (`StoreWarning`) and recomputed. A store of another
        experiment is refused.
    executor : concurrent.futures.Executor, optional
        Run the tasks on it (it is not shut down). Default: a local process pool.
    workers : int, optional
        Size of the local process pool (default ``os.cpu_count()``); ``workers=1`` runs
        the tasks in this process, one after the other.
    scheduler : str, optional
        Address of a Dask distributed scheduler (e.g. ``"tcp://host:8786"``): the tasks
        run on that cluster through ``distributed.Client(address).get_executor()``.
        Needs the optional dependency ``dask[distributed]``.
    progress : bool, optional
        Show a tqdm progress bar; default: only on a terminal and not when the ``CI``
        environment variable is set.
    wait : bool or float, default False
        One run writes a store at a time (an advisory lock in the store). If another
        run holds it: False raises `StoreLockedError` at once, True waits for it, a
        number waits at most that many seconds.

    Returns
    -------
    Store
        The loaded store (`load_store`).

    Raises
    ------
    ValueError
        Bad arguments, or a store of a different experiment.
    RuntimeError
        A task failed; the tasks finished before it are kept, so a rerun resumes.
    StoreLockedError
        Another run is writing the store (a `RuntimeError`).
    OSError
        The store cannot be written (read-only folder, full disk); a complete store
        on a read-only disk loads without writing.

    Notes
    -----
    Results are identical for every executor and worker count: each task is a pure
    function of the experiment and its IC range, and every random number comes from a
    seed sequence keyed by (IC, radius, system). Workers return their tables to this
    process, which alone writes the store (the cluster needs no shared disk). Workers of
    the local pool end with this process, even when it is killed.

    Examples
    --------
    >>> import tempfile
    >>> from kicktimes.experiment import Experiment, run_experiment
    >>> exp = Experiment(name="demo", radii=[0.02], n_ics=2, n_steps=100, tau=0.3,
    ...                  diagnostics=["recurrence_rate"])
    >>> store = run_experiment(exp, tempfile.mkdtemp(), workers=1, progress=False)
    >>> store.complete, sorted(store.results["system"].unique())
    (True, ['actual', 'poisson', 'two_particle'])
    """
    if isinstance(experiment, (str, os.PathLike)):
        experiment = Experiment.from_toml(experiment)
    if not isinstance(experiment, Experiment | DisksExperiment):
        raise TypeError(
            f"experiment: expected an Experiment, a DisksExperiment or a TOML path, got "
            f"{type(experiment).__name__}"
        )
    if not isinstance(store, (str, os.PathLike)):
        raise TypeError(f"store: expected a directory path, got {type(store).__name__}")
    if executor is not None and scheduler is not None:
        raise ValueError("give either executor or scheduler, not both")
    if workers is not None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers: must be an integer >= 1, got {workers!r}")
        if executor is not None or scheduler is not None:
            raise ValueError(
                "workers: sizes the local process pool; it cannot be combined "
                "with executor or scheduler"
            )
    if scheduler is not None and not isinstance(scheduler, str):
        raise TypeError(f"scheduler: expected an address string, got {scheduler!r}")
    if not isinstance(wait, bool):
        if not isinstance(wait, (int, float)) or not 0 <= wait < float("inf"):
            raise ValueError(f"wait: must be True, False or a number of seconds >= 0, got {wait!r}")

    with StoreWriter(store, experiment, wait=wait) as writer:
        pending = writer.pending()
        if pending:
            show = _progress_enabled(progress)
            _run_pending(writer, pending, executor, workers, scheduler, show)
    return load_store(store)


def _run_pending(writer, pending, executor, workers, scheduler, show):
    from tqdm import tqdm

    experiment = writer.experiment
    execute = execute_disks_task if isinstance(experiment, DisksExperiment) else execute_task
    total = len(writer.all_tasks)
    bar = tqdm(
        total=total,
        initial=total - len(pending),
        unit="task",
        desc=experiment.name,
        disable=not show,
        dynamic_ncols=True,
    )
    client = None
    own_pool = None
    try:
        if executor is None and scheduler is None and (workers or os.cpu_count() or 1) == 1:
            for task in pending:
                writer.write(execute(experiment, task))
                bar.update()
            return
        if scheduler is not None:
            client, executor = _dask_executor(scheduler)
        elif executor is None:
            own_pool = executor = local_pool(workers)
        futures = {executor.submit(execute, experiment, task): task for task in pending}
        not_done = set(futures)
        try:
            while not_done:
                done, not_done = wait(not_done, return_when=FIRST_COMPLETED)
                for fut in done:
                    task = futures[fut]
                    exc = fut.exception()
                    if exc is not None:
                        raise RuntimeError(
                            f"task {task.id} (radius {task.radius:g}, ICs {task.ic_start}.."
                            f"{task.ic_stop - 1}) failed: {exc!r}; the finished tasks are in "
                            "the store, rerun to resume"
                        ) from exc
                    # stream: each task is on disk as soon as it finishes
                    writer.write(fut.result())
                    bar.update()
        except BaseException:
            for fut in not_done:
                fut.cancel()
            raise
    finally:
        bar.close()
        if own_pool is not None:
            own_pool.shutdown(wait=True, cancel_futures=True)
        if client is not None:
            client.close()
