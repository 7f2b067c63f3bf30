"""The lab's background jobs, started by a job server that has no threads.

A job forked from the threaded web server inherits whatever locks its other
threads hold at that moment (an import lock, SQLite's, the allocator's) and can
wait on one of them forever. So jobs are never forked from the web server: at
start the lab spawns one *job server*, a fresh interpreter that imports the
systems, registers the same callbacks (the same keys: Dash derives them from
each function's source and output), warms the systems' compiled kernels once
and then, single-threaded, forks one process per job. The web server asks for a
job over a pipe and gets its process id; results travel, as in Dash's
``DiskcacheManager``, through the job cache folder.

A job ends when it finishes, is cancelled (Dash kills it), gets SIGTERM, or the
lab closes; Ctrl-C in the terminal reaches the whole process group, so the job
server and its jobs ignore SIGINT and are ended by the lab itself. If the web
server dies, the job server reads the end of its pipe and ends its jobs.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
from multiprocessing.connection import Connection, wait
from pathlib import Path

from dash import DiskcacheManager

import schuler
from schuler.exceptions import SchulerError

FIRST_WARMED = "align"
"""The system warmed first (the lab's most used page); the others follow in the registry's order."""


def os_threads() -> int:
    """The number of operating-system threads of this process (Linux; 1 where it cannot be read)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return 1


class JobServerManager(DiskcacheManager):
    """Dash's disk-cache job manager whose jobs are forked by the job server, never by the web server.

    Parameters
    ----------
    cache_dir : Path
        The job cache folder (results, progress), shared with the job server and its jobs.
    """

    def __init__(self, cache_dir: Path):
        import diskcache

        self.cache_dir = Path(cache_dir)
        self._lock = threading.Lock()  # one request at a time on the pipe (the web server has a thread per request)
        self._process: subprocess.Popen | None = None
        self._connection: Connection | None = None
        self._closed = False
        super().__init__(diskcache.Cache(str(self.cache_dir)))
        self._start()

    def _start(self) -> None:
        if self._connection is not None:
            self._connection.close()
        ours, theirs = socket.socketpair()
        environment = {
            **os.environ,
            # the job server imports schuler from where this process did (a script may have set its own path)
            "PYTHONPATH": os.pathsep.join([str(Path(schuler.__file__).parents[1]), os.environ.get("PYTHONPATH", "")]),
            # pandas loads pyarrow, whose allocator would start a background thread in the job server
            "JE_ARROW_MALLOC_CONF": os.environ.get("JE_ARROW_MALLOC_CONF", "background_thread:false"),
        }
        # a fresh interpreter (not multiprocessing's spawn, which would run the caller's main script again)
        self._process = subprocess.Popen([sys.executable, "-m", __name__, str(theirs.fileno()), str(self.cache_dir)],
                                         pass_fds=(theirs.fileno(),), env=environment, stdin=subprocess.DEVNULL)
        theirs.close()
        self._connection = Connection(ours.detach())

    @property
    def server_pid(self) -> int | None:
        """The job server's process id (None once closed)."""
        return None if self._process is None else self._process.pid

    def make_job_fn(self, fn, progress, key=None):
        """What Dash keeps for a background function here: its key (the job server holds the function).

        Parameters
        ----------
        fn : callable
            The callback's function.
        progress : bool
            Whether it reports progress.
        key : str
            Its key, from its source and its outputs.
        """
        return key

    def call_job_fn(self, key, job_fn, args, context):
        """Ask the job server for a job; returns its process id (a new job server if the last one ended).

        Parameters
        ----------
        key : str
            The job's result key in the job cache.
        job_fn : str
            The background function's key (what :meth:`make_job_fn` returned).
        args : list or dict
            The callback's arguments (the values the browser sent).
        context : dict
            Dash's callback context (plain data).
        """
        request = ("start", job_fn, key, self._make_progress_key(key), args, dict(context))
        with self._lock:
            if self._closed:
                raise SchulerError("the lab is stopping: no new computation starts")
            if self._process is None or self._process.poll() is not None:
                self._start()  # ended from outside (a signal): a new one, which warms again
            try:
                self._connection.send(request)
                return self._connection.recv()
            except (EOFError, OSError):  # it ended just now
                self._start()
                self._connection.send(request)
                return self._connection.recv()

    def _own_job(self, job) -> object | None:
        """The psutil process of job ``job`` when it is one of this lab's jobs still running, else None."""
        import psutil

        if job is None or self._process is None:
            return None
        try:
            process = psutil.Process(int(job))
            if process.ppid() != self._process.pid or process.status() == psutil.STATUS_ZOMBIE:
                return None  # ended (and its number possibly reused by another process)
            return process
        except (psutil.NoSuchProcess, psutil.AccessDenied, ValueError):
            return None

    def terminate_job(self, job):
        """Kill a job and its children; a job already gone is no error.

        Parameters
        ----------
        job : int or str or None
            The job's process id as :meth:`call_job_fn` returned it (an index, not a number to compute with).
        """
        import psutil

        process = self._own_job(job)
        if process is None:
            return
        try:
            for child in process.children(recursive=True):
                child.kill()
            process.kill()
        except psutil.NoSuchProcess:
            pass  # it ended meanwhile: nothing to do

    def job_running(self, job):
        """Whether the job still runs.

        Parameters
        ----------
        job : int or str or None
            The job's process id (an index).
        """
        return self._own_job(job) is not None

    def terminate_unhealthy_job(self, job):
        """Nothing to do: a job that ended was reaped by the job server.

        Parameters
        ----------
        job : int or str or None
            The job's process id (an index).
        """
        return False

    def close(self) -> None:
        """End the job server and its jobs: closing the pipe asks it to (it kills its jobs), then SIGTERM and
        SIGKILL for whatever of its process tree is left."""
        import psutil

        with self._lock:
            self._closed = True
            process, self._process = self._process, None
            try:
                tree = psutil.Process(process.pid).children(recursive=True) if process is not None else []
            except psutil.NoSuchProcess:
                tree = []
            if self._connection is not None:
                self._connection.close()
            if process is not None:
                for stop in (None, process.terminate, process.kill):
                    if stop is not None:
                        stop()
                    try:
                        process.wait(3)
                        break
                    except subprocess.TimeoutExpired:
                        continue
            for leftover in tree:  # a job forked while the pipe closed
                try:
                    leftover.kill()
                except psutil.NoSuchProcess:
                    pass
        self.handle.close()


def job_functions() -> dict:
    """Every background callback of the lab's pages: key -> (function, whether it reports progress).

    The pages' callbacks are registered on a throwaway application; Dash records
    each background function under a key made of its source and its outputs, the
    same in every process.
    """
    from dash import Dash
    from dash.background_callback.managers import BaseBackgroundCallbackManager

    from schuler.lab.pages import register_pages

    register_pages(Dash(__name__))
    return {key: (fn, progress) for key, fn, progress in BaseBackgroundCallbackManager.functions}


class Warming:
    """Runs each system's starting case once in the job server, so that jobs forked later find its kernels
    compiled and loaded.

    A case whose run starts threads (a parallel kernel's thread pool) is not run
    here: this process must stay single-threaded to fork safely. So each case is
    first run in a forked *probe* (it compiles into numba's disk cache and
    reports the threads it ends with) while the job server goes on serving; only
    then, and only while no job runs, the case runs here (loading from the cache).
    Systems are warmed in the registry's order, :data:`FIRST_WARMED` first.
    """

    def __init__(self):
        from schuler.registry import SYSTEM_MODULES

        self._names = sorted(SYSTEM_MODULES, key=lambda name: name != FIRST_WARMED)
        self._probe: tuple[int, int, str] | None = None  # process id, pipe to read, system
        self.warmed: list[str] = []

    @property
    def done(self) -> bool:
        return not self._names and self._probe is None

    @property
    def probe_fd(self) -> int | None:
        """The pipe the running probe answers on (None: no probe runs)."""
        return None if self._probe is None else self._probe[1]

    def start_probe(self) -> None:
        """Fork a probe for the next system (nothing when one runs or none is left)."""
        if self._probe is not None or not self._names:
            return
        name = self._names.pop(0)
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(read)
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            try:
                _run_case(name)
                single = os_threads() == 1
            except BaseException:
                single = False
            try:
                os.write(write, b"1" if single else b"0")
            finally:
                os._exit(0)  # the job server may have closed meanwhile (its end of the pipe gone)
        os.close(write)
        self._probe = (pid, read, name)

    def finish_probe(self) -> None:
        """Read the probe's answer; warm its system here when it stayed single-threaded."""
        if self._probe is None:
            return
        pid, read, name = self._probe
        self._probe = None
        with os.fdopen(read, "rb") as answer:
            single = answer.read(1) == b"1"
        os.waitpid(pid, 0)
        if single:
            try:
                _run_case(name)
                self.warmed.append(name)
            except Exception:  # not importable, or a failing starting case: its page says why when a job runs it
                pass


def _run_case(name: str) -> None:
    from schuler.lab import figures, system_page
    from schuler.registry import get_system

    system = get_system(name)
    result = system_page.run_typed(system, {})
    if figures.interactive_figures(system, result) is None:
        figures.file_figures(system, result)  # the page shows the system's own figures (matplotlib)


def serve_jobs(connection, cache_dir: str) -> None:
    """The job server's loop: fork a process for each job asked for, until the pipe closes.

    Parameters
    ----------
    connection : multiprocessing.connection.Connection
        The job server's end of the pipe: it receives ``("start", key, result_key, progress_key, args,
        context)`` and answers the job's process id.
    cache_dir : str
        The job cache folder; each job opens it itself (no database connection crosses a fork).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the web server's to handle; it ends us
    functions = job_functions()
    jobs: set[int] = set()

    def reap(signum=None, frame=None):
        for pid in list(jobs):
            try:
                done, _ = os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                done = pid
            if done:
                jobs.discard(pid)

    signal.signal(signal.SIGCHLD, reap)  # an ended job disappears at once: the web server sees it is not running
    warming = Warming()
    lab_gone = False
    try:
        while True:
            if not jobs:
                warming.start_probe()  # warming works only while no job needs the processor
            # a probe's answer is taken (and its case run here) only while no job runs
            probe = [warming.probe_fd] if warming.probe_fd is not None and not jobs else []
            waiting_on = [connection, *probe]
            ready = wait(waiting_on, timeout=None if warming.done else 0.2)
            if warming.probe_fd in ready and connection not in ready:
                warming.finish_probe()
                continue
            if connection not in ready:
                continue
            try:
                _, key, result_key, progress_key, args, context = connection.recv()
            except (EOFError, OSError):
                lab_gone = True  # the lab closed (or died)
                break
            pid = os.fork()
            if pid == 0:
                _run_job(functions[key], cache_dir, result_key, progress_key, args, context)
            jobs.add(pid)
            reap()
            connection.send(pid)
    finally:
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        for pid in jobs:
            try:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
            except (ProcessLookupError, ChildProcessError):
                pass
        if lab_gone:  # also when the web server was killed and could not remove it (a new job server keeps it)
            shutil.rmtree(cache_dir, ignore_errors=True)


def _run_job(function, cache_dir: str, result_key: str, progress_key: str, args, context) -> None:
    """In the forked job: run the callback, leave its result in the cache, exit without cleanups."""
    code = 1
    try:
        import diskcache
        from dash.background_callback.managers.diskcache_manager import _make_job_fn

        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        fn, progress = function
        cache = diskcache.Cache(cache_dir)
        _make_job_fn(fn, cache, progress)(result_key, progress_key, args, context)
        cache.close()
        code = 0
    finally:
        os._exit(code)  # never return into the job server's loop


if __name__ == "__main__":
    serve_jobs(Connection(int(sys.argv[1])), sys.argv[2])
