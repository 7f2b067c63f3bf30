"""Where sweep chunks are evaluated: in this process, a pool of local processes, or a Dask cluster.

Each executor maps a function over chunk tasks and yields results as they
complete, with only a few chunks in flight at once (bounded memory). The
workers of an existing Dask cluster need the same version of schuler installed.

Local worker processes share the machine's cores: each gets ``cores // workers``
threads for BLAS, OpenMP and numba (at least one), because a chunk's small
batched matrix products run several times slower when every worker also starts
a BLAS thread per core. Workers ignore SIGINT (a Ctrl-C reaches the whole
process group): the parent alone stops, terminating the pool.
"""

from __future__ import annotations

import os
import signal
from collections.abc import Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from schuler.exceptions import ScenarioError

THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
"""Environment variables that set a worker's thread pools (BLAS, OpenMP, numba); one that is set is kept."""

TERMINATE_SECONDS = 2.0
"""How long an interrupted sweep waits for each terminated worker process to end, s."""


class InProcess:
    """Evaluate chunks one after another in this process (vectorised within each)."""

    name = "in-process"

    def map(self, function, tasks: Iterable) -> Iterator:
        """Results of ``function`` on each task, in the order of the tasks (each computed when asked for).

        Parameters
        ----------
        function : callable
            ``function(task)`` -> the task's result (a sweep chunk's evaluation).
        tasks : iterable
            The tasks (sweep chunks), consumed lazily.

        Returns
        -------
        iterator
            The results, one per task.
        """
        for task in tasks:
            yield function(task)

    def close(self, abort: bool = False) -> None:
        """Nothing to release.

        Parameters
        ----------
        abort : bool
            Unused (nothing runs in the background).
        """


def available_cores() -> int:
    """The CPU cores this process may run on, number of (at least 1)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def worker_environment(workers: int, environ=None) -> dict[str, str]:
    """The thread settings a local worker process gets: the cores shared among the workers.

    Parameters
    ----------
    workers : int
        Worker processes, number of, at least 1.
    environ : mapping, optional
        The environment to complete (default: this process's); a variable it sets is kept.

    Returns
    -------
    dict
        The variables of :data:`THREAD_VARIABLES` that ``environ`` does not set, each ``cores // workers``
        (at least 1) as text.
    """
    environ = os.environ if environ is None else environ
    threads = str(max(1, available_cores() // workers))
    return {name: threads for name in THREAD_VARIABLES if name not in environ}


def _ignore_interrupts() -> None:
    # a Ctrl-C goes to the whole process group; the parent alone decides to stop (and terminates the pool)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class LocalProcesses:
    """A pool of local worker processes (spawned: safe beside threads), sharing the cores (module notes)."""

    name = "processes"

    def __init__(self, workers: int):
        import multiprocessing

        self.workers = workers
        # spawned children copy os.environ when they start, which the pool does on demand while tasks are
        # submitted: the thread settings stay in this process's environment until the pool is closed
        self._added = worker_environment(workers)
        os.environ.update(self._added)
        self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                                        initializer=_ignore_interrupts)

    def map(self, function, tasks: Iterable) -> Iterator:
        """Results of ``function`` on each task as they complete (any order), twice ``workers`` tasks in flight.

        Until the first worker delivers a result (the workers are still starting: each imports the toolkit),
        this process evaluates tasks too, rather than wait idle for them.

        Parameters
        ----------
        function : callable
            ``function(task)`` -> the task's result; it and the tasks must pickle (spawned processes).
        tasks : iterable
            The tasks (sweep chunks), consumed as room frees up.

        Returns
        -------
        iterator
            The results, one per task, in order of completion.
        """
        window = 2 * self.workers
        pending: set = set()
        started = False
        for task in tasks:
            if len(pending) >= window and not started:
                started = any(future.done() for future in pending)
                if not started:
                    yield function(task)
                    continue
            pending.add(self.pool.submit(function, task))
            if len(pending) >= window and started:
                yield from _wait_futures(pending)
        while pending:
            yield from _wait_futures(pending)

    def close(self, abort: bool = False) -> None:
        """Shut the pool down: after the running chunks (default), or at once, terminating the workers.

        Parameters
        ----------
        abort : bool
            Terminate the worker processes (an interrupted sweep), waiting at most :data:`TERMINATE_SECONDS`
            for each.
        """
        try:
            if abort:
                # ProcessPoolExecutor offers no public way to stop running tasks before Python 3.14
                processes = list((getattr(self.pool, "_processes", None) or {}).values())
                for process in processes:
                    process.terminate()
                for process in processes:
                    process.join(TERMINATE_SECONDS)
            self.pool.shutdown(wait=True, cancel_futures=True)
        finally:
            for name in self._added:
                os.environ.pop(name, None)


class DaskCluster:
    """A Dask cluster: a LocalCluster started here (``"local"``) or an existing scheduler."""

    name = "dask"

    def __init__(self, scheduler: str, workers: int | None = None):
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise ScenarioError("`scheduler`: Dask is not installed; install schuler[dask]") from None
        self.cluster = None
        if scheduler == "local":
            self.cluster = LocalCluster(
                n_workers=workers or 2,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # any free port: never clashes with another cluster
                silence_logs=50,
            )
            self.client = Client(self.cluster)
        elif scheduler.startswith(("tcp://", "tls://", "inproc://", "ws://", "wss://")):
            try:
                self.client = Client(scheduler, timeout="20s")
            except OSError as error:
                raise ScenarioError(f"`scheduler`: cannot reach {scheduler}: {error}") from None
        else:
            raise ScenarioError(f"`scheduler`: {scheduler!r} is neither 'local' nor an address like tcp://HOST:8786")

    def map(self, function, tasks: Iterable) -> Iterator:
        """Results of ``function`` on each task as they complete (any order), twice the cluster's threads in flight.

        Parameters
        ----------
        function : callable
            ``function(task)`` -> the task's result; it and the tasks must pickle (sent to the workers).
        tasks : iterable
            The tasks (sweep chunks), consumed as room frees up.

        Returns
        -------
        iterator
            The results, one per task, in order of completion (each released on the cluster once fetched).
        """
        from distributed import as_completed

        threads = max(1, sum(self.client.nthreads().values()))
        completed = as_completed()

        def submit(task):
            future = self.client.submit(function, task, pure=False)
            completed.add(future)
            return future

        def next_done(pending):
            future = next(completed)
            pending.discard(future)
            result = future.result()
            future.release()
            return [result]

        yield from _windowed(submit, tasks, 2 * threads, next_done)

    def close(self, abort: bool = False) -> None:
        """Close the client, and the LocalCluster started here.

        Parameters
        ----------
        abort : bool
            Unused: closing the client releases its chunks still on the cluster either way.
        """
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _wait_futures(pending: set) -> list:
    done, _ = wait(pending, return_when=FIRST_COMPLETED)
    pending -= done
    try:
        return [future.result() for future in done]
    except BrokenProcessPool:
        raise ScenarioError("`workers`: a worker process ended abruptly (out of memory?); "
                            "the same command resumes from the chunks stored") from None


def _windowed(submit, tasks: Iterable, window: int, next_done) -> Iterator:
    """Keep at most ``window`` tasks in flight; yield results as they complete."""
    pending: set = set()
    for task in tasks:
        pending.add(submit(task))
        if len(pending) >= window:
            yield from next_done(pending)
    while pending:
        yield from next_done(pending)


def make_executor(scheduler: str | None = None, workers: int | None = None):
    """In-process (default), local processes (``workers`` > 1) or Dask (``scheduler``).

    Parameters
    ----------
    scheduler : str, optional
        ``"local"`` (a Dask LocalCluster started here) or a Dask scheduler's address (``tcp://HOST:8786``);
        None: no Dask.
    workers : int, optional
        Worker processes, number of, at least 1 (for a local Dask cluster: its workers, default 2).

    Returns
    -------
    InProcess or LocalProcesses or DaskCluster
        The executor; close it with ``close()`` when done.

    Raises
    ------
    ScenarioError
        ``workers`` below 1, Dask missing, or a scheduler that is neither ``local`` nor reachable.
    """
    if workers is not None and workers < 1:
        raise ScenarioError(f"`workers`: {workers} must be at least 1")
    if scheduler:
        return DaskCluster(scheduler, workers)
    if workers and workers > 1:
        return LocalProcesses(workers)
    return InProcess()


