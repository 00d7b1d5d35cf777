"""Drawing frames on a Dask cluster: ``liganimate run --scheduler ADDRESS``.

The program, its scenes and every pose are evaluated once, in this process
(the Dask *client*); only the drawing is sent out.  :class:`DaskExecutor`
stands in for the renderer's local process pool: each task is one call of
the renderer's task function on a batch of images' draw lists, run on
whichever worker is free, and it returns the encoded images, which this
process writes (so the workers need no access to the output files).
Nothing here is imported unless a scheduler is given, so a local run never
loads Dask.

Faults:

- a task that raises is run again up to ``retries`` times; a worker that
  dies (killed, out of memory, its machine lost) has its tasks moved to
  another worker by the scheduler, up to Dask's
  ``distributed.scheduler.allowed-failures`` times per task.  A task may
  therefore run more than once: it only computes, and the same draw list
  gives the same bytes, so that is harmless;
- a task that has not answered ``task_timeout`` seconds after it was
  handed to the cluster (``$LIGANIMATE_DASK_TASK_TIMEOUT``, default 600: a
  worker that hangs, a scheduler that stopped answering) fails with a
  :class:`RenderError` in one sentence, and is cancelled on the cluster;
  the renderer keeps about twice as many tasks in flight as the workers
  have threads, so a task waits for at most one other before it starts;
- a scheduler that cannot be reached, that has no worker, or whose workers
  cannot import liganimate (or run other versions of what decides a
  frame's bytes) is a :class:`RenderError` before any frame is drawn.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import itertools
import logging
import math
import os
import secrets
import socket
import threading
import time

import distributed

from liganimate.runtime.errors import RenderError

# Times a task that raised is run again (a worker that died is Dask's allowed-failures).
RETRIES = 2
# Seconds to reach the scheduler, and to wait for its first worker.
CONNECT_TIMEOUT = 10.0
WORKER_WAIT = 30.0
# Seconds shutdown waits for the tasks being drawn before it lets them finish on their own.
CLOSE_WAIT = 30.0
#: The environment variable that sets the seconds one task may take, from being handed to the cluster.
TASK_TIMEOUT_ENV = "LIGANIMATE_DASK_TASK_TIMEOUT"
#: The default: ten minutes for one batch of images (a 640x480 image takes some milliseconds).
TASK_TIMEOUT = 600.0
_HINT = (
    "check the address (--scheduler or LIGANIMATE_SCHEDULER) and that a scheduler runs there "
    "('dask scheduler', with workers started by 'dask worker ADDRESS')"
)


class DaskExecutor:
    """Runs the renderer's tasks on a Dask cluster, as a ``concurrent.futures`` executor would.

    Parameters
    ----------
    address : str or distributed.Client or cluster
        The scheduler's address (``tcp://host:8786``, or ``host:8786``), a
        connected :class:`distributed.Client` (kept open by :meth:`shutdown`:
        it is the caller's), or a cluster object such as
        :class:`distributed.LocalCluster` (a client of its own is opened on
        it, and closed by :meth:`shutdown`; the cluster is left running).
    retries : int, optional
        Times a task that raised is run again.
    connect_timeout, worker_wait, close_wait : float, optional
        Seconds to reach the scheduler, to wait for a worker to join it,
        and for :meth:`shutdown` to wait for the tasks being drawn.
    task_timeout : float, optional
        Seconds a task may take from :meth:`submit` to its answer (default
        ``$LIGANIMATE_DASK_TASK_TIMEOUT``, else 600).
    silence_logs : bool, optional
        Keep Dask's log lines (reconnection attempts, with tracebacks) off
        stderr while the executor is open; what goes wrong reaches the
        caller as a :class:`RenderError` instead.  False leaves logging alone.

    Attributes
    ----------
    address : str
        The scheduler's address, as messages give it.
    workers : int
        Threads of the cluster's workers when it was reached: how many tasks
        run at once (the renderer keeps about twice that many in flight).

    Raises
    ------
    RenderError
        The scheduler cannot be reached, has no worker after
        ``worker_wait`` seconds, or a worker cannot import liganimate or
        runs another version of liganimate, numpy or zlib.
    """

    def __init__(
        self,
        address,
        retries: int = RETRIES,
        connect_timeout: float = CONNECT_TIMEOUT,
        worker_wait: float = WORKER_WAIT,
        close_wait: float = CLOSE_WAIT,
        silence_logs: bool = True,
        task_timeout: float | None = None,
    ):
        self.retries = int(retries)
        self.task_timeout = task_timeout_from_env() if task_timeout is None else float(task_timeout)
        self.close_wait = float(close_wait)
        self._levels = _silence() if silence_logs else {}
        try:
            self._client, self._own = _connect(address, connect_timeout)
        except BaseException:
            _restore(self._levels)
            raise
        self.address = self._client.scheduler.address
        try:
            self.workers = _wait_for_workers(self._client, worker_wait)
            _check_workers(self._client)
        except BaseException:
            self._close_client()
            raise
        self._token = secrets.token_hex(8)
        self._count = itertools.count()
        self._lock = threading.Lock()
        self._pending: dict = {}  # task key -> (Dask future, concurrent future)
        self._deadlines: dict = {}  # task key -> time.monotonic() by which it must have answered
        self._closed = False
        self._watch = threading.Thread(target=self._watchdog, name="liganimate-dask-deadlines", daemon=True)
        self._watch.start()

    @property
    def client(self) -> distributed.Client:
        """The Dask client the tasks go through."""
        return self._client

    def submit(self, fn, *args) -> cf.Future:
        """Run ``fn(*args)`` on a worker; the future holds its result or its exception.

        ``fn`` must be importable on the workers by name (a module-level
        function of liganimate), and its arguments picklable.  The future
        is running from the start: Dask does not tell when a task starts,
        so :meth:`concurrent.futures.Future.cancel` never succeeds;
        ``shutdown(cancel_futures=True)`` drops the tasks not started.
        """
        if self._closed:
            raise RuntimeError("cannot schedule new futures after shutdown")
        key = f"liganimate-draw-{self._token}-{next(self._count)}"
        future: cf.Future = cf.Future()
        future.set_running_or_notify_cancel()
        dask_future = self._client.submit(_call, fn, *args, key=key, pure=False, retries=self.retries)
        with self._lock:
            self._pending[key] = (dask_future, future)
            self._deadlines[key] = time.monotonic() + self.task_timeout
        dask_future.add_done_callback(self._done)
        return future

    def _watchdog(self) -> None:
        """Fail every task that has not answered by its deadline (in a thread of its own)."""
        step = min(1.0, max(0.05, self.task_timeout / 10))
        while not self._closed:
            time.sleep(step)
            now = time.monotonic()
            with self._lock:
                late = [k for k, when in self._deadlines.items() if when <= now]
                entries = [self._pending.pop(k, None) for k in late]
                for k in late:
                    del self._deadlines[k]
            for entry in entries:
                if entry is None:
                    continue
                dask_future, future = entry
                with contextlib.suppress(Exception):
                    self._client.cancel([dask_future])
                if not future.done():
                    future.set_exception(
                        RenderError(
                            f"a task on the Dask cluster at {self.address} did not answer in "
                            f"{self.task_timeout:g} s (a worker hangs, or the scheduler stopped answering); "
                            "the frames written before are complete",
                            f"see the workers' logs; for very large images raise {TASK_TIMEOUT_ENV} (seconds)",
                        )
                    )

    def _done(self, dask_future) -> None:
        """Hand a finished task's outcome to its concurrent future (in Dask's callback thread)."""
        with self._lock:
            entry = self._pending.pop(dask_future.key, None)
            self._deadlines.pop(dask_future.key, None)
        if entry is None:
            return
        future = entry[1]
        try:
            status = dask_future.status
            if status == "finished":
                future.set_result(dask_future.result())
            elif status == "error":
                future.set_exception(_worded(dask_future.exception()))
            else:
                future.set_exception(self._lost(status))
        except Exception as exc:  # the result could not be fetched
            if not future.done():
                future.set_exception(self._lost(exc))

    def _lost(self, why) -> BaseException:
        """A task that ended without a result: dropped by :meth:`shutdown`, or its scheduler lost."""
        if self._closed:
            return cf.CancelledError()
        said = f" ({_why(why)})" if isinstance(why, BaseException) else ""
        return RenderError(
            f"the connection to the Dask scheduler at {self.address} was lost while drawing{said}; "
            "the frames written before are complete",
            "see the scheduler's log; render again when it runs",
        )

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        """Stop taking tasks, optionally drop those not started and wait for the rest, then disconnect.

        Parameters
        ----------
        wait : bool
            Wait (at most ``close_wait`` seconds) for the tasks given to
            workers.  A task still running after that finishes on its own
            on its worker, and its result is dropped.
        cancel_futures : bool
            Drop the tasks the scheduler has not yet given to a worker.

        Safe to call more than once.  Closes the client if this executor opened it.
        """
        if self._closed:
            return
        self._closed = True
        try:
            with self._lock:
                entries = list(self._pending.values())
            running = entries
            if cancel_futures and running:
                busy = _processing(self._client)
                if busy is not None:
                    queued = [d for d, _ in running if d.key not in busy]
                    running = [e for e in running if e[0].key in busy]
                    with contextlib.suppress(Exception):
                        self._client.cancel(queued)
            if wait and running:
                cf.wait([f for _, f in running], timeout=self.close_wait)
        finally:
            self._close_client()
            # Callbacks that will never come now (the client is gone): nobody waits forever.
            with self._lock:
                left, self._pending, self._deadlines = list(self._pending.values()), {}, {}
            for _, future in left:
                if not future.done():
                    future.set_exception(cf.CancelledError())

    def _close_client(self) -> None:
        try:
            if self._own:
                self._own = False
                with contextlib.suppress(Exception):
                    self._client.close(timeout=self.close_wait)
        finally:
            levels, self._levels = self._levels, {}
            _restore(levels)


# Loggers that print Dask's own troubles (with tracebacks) on stderr, and their children.
_LOGGERS = ("distributed", "tornado")


def task_timeout_from_env() -> float:
    """Seconds one task may take: ``$LIGANIMATE_DASK_TASK_TIMEOUT``, else :data:`TASK_TIMEOUT`.

    Raises
    ------
    RenderError
        When the variable is set but is not a positive number of seconds.
    """
    text = os.environ.get(TASK_TIMEOUT_ENV, "").strip()
    if not text:
        return TASK_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (0 < value < math.inf):
        raise RenderError(f"{TASK_TIMEOUT_ENV}={text!r} is not a number of seconds; give one such as 600")
    return value


def _silence() -> dict:
    """Turn Dask's loggers off; return their levels, for :func:`_restore`.

    Dask's configuration gives some children levels of their own
    (``distributed.client``), so each is set, not only the parents.
    """
    names = [n for n in list(logging.root.manager.loggerDict) if n.split(".")[0] in _LOGGERS]
    levels = {}
    for name in sorted(set(names) | set(_LOGGERS)):
        logger = logging.getLogger(name)
        levels[name] = logger.level
        logger.setLevel(logging.CRITICAL + 1)
    return levels


def _restore(levels: dict) -> None:
    for name, level in levels.items():
        logging.getLogger(name).setLevel(level)


def _connect(address, timeout: float):
    """(client, opened here) for an address, a Client or a cluster; a RenderError if unreachable."""
    if isinstance(address, distributed.Client):
        return address, False
    if not isinstance(address, str):
        address = getattr(address, "scheduler_address", address)
    if not isinstance(address, str):
        raise TypeError(f"DaskExecutor wants a scheduler address, a Client or a cluster, not {type(address).__name__}")
    shown = address.strip()
    _probe(shown, timeout)
    # Built in two steps so that a client that failed to connect can be closed here and now:
    # left to the garbage collector, it prints a traceback while it times out again.
    client = distributed.Client.__new__(distributed.Client)
    try:
        distributed.Client.__init__(client, shown, timeout=timeout, set_as_default=False)
    except Exception as exc:
        with contextlib.suppress(Exception):
            client.close(timeout=1)
        client.status = "closed"
        raise RenderError(f"cannot reach the Dask scheduler at {shown}: {_why(exc)}", _HINT) from None
    except BaseException:  # Ctrl-C while connecting: closed now, or Dask prints a traceback at exit
        with contextlib.suppress(Exception):
            client.close(timeout=1)
        client.status = "closed"
        raise
    return client, True


def _probe(address: str, timeout: float) -> None:
    """Fail at once, in words, for a TCP address nobody listens on (Dask would retry until its timeout)."""
    try:
        scheme, location = distributed.comm.parse_address(address)
        if scheme not in distributed.comm.registry.backends:
            raise ValueError(scheme)
        if scheme != "tcp":
            return
        host, port = distributed.comm.parse_host_port(location)
    except (ValueError, TypeError):
        raise RenderError(
            f"{address!r} is not a Dask scheduler address; give one like tcp://host:8786", _HINT
        ) from None
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            # A Dask server writes its handshake as soon as it accepts; an
            # endpoint that accepts and stays silent would keep Dask's client
            # waiting without end, so its first answer is awaited here, bounded.
            sock.settimeout(timeout)
            first = sock.recv(1)
    except TimeoutError:
        raise RenderError(
            f"the Dask scheduler at {address} accepted the connection but did not answer in {timeout:g} s", _HINT
        ) from None
    except OSError as exc:
        raise RenderError(f"cannot reach the Dask scheduler at {address}: {_why(exc)}", _HINT) from None
    if not first:
        raise RenderError(f"cannot reach the Dask scheduler at {address}: the connection closed", _HINT)


def _why(exc: BaseException) -> str:
    """Why a connection failed, in a few words (Dask wraps the system's reason in its own exceptions)."""
    cause: BaseException | None = exc
    while cause is not None and not (isinstance(cause, OSError) and cause.strerror):
        cause = cause.__cause__ or cause.__context__
    if cause is not None:
        exc = cause
    elif isinstance(exc, distributed.comm.CommClosedError):
        return "the connection closed"
    if isinstance(exc, socket.gaierror):
        return "the host name is not known"
    if isinstance(exc, (TimeoutError, socket.timeout)) or "Timed out" in str(exc):
        return "no answer (timed out)"
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror[:1].lower() + exc.strerror[1:]
    if isinstance(exc, (OSError, ValueError)) and str(exc):
        return str(exc)
    return "it does not answer as a Dask scheduler"


def _wait_for_workers(client, timeout: float) -> int:
    """Threads of the cluster's workers, waiting up to ``timeout`` seconds for the first to join."""
    threads = sum(client.nthreads().values())
    if threads:
        return threads
    try:
        client.wait_for_workers(1, timeout=timeout)
    except Exception:
        raise RenderError(
            f"the Dask scheduler at {client.scheduler.address} has no workers (waited {timeout:g} s)",
            "start workers with 'dask worker ADDRESS' in an environment with the same liganimate",
        ) from None
    return max(1, sum(client.nthreads().values()))


def _check_workers(client) -> None:
    """Refuse workers that cannot import liganimate, or whose versions would draw other bytes.

    A task whose function a worker cannot unpickle does not fail in Dask:
    the worker's connection to the scheduler breaks and the task waits
    forever.  So every worker present is asked first (workers that join
    later are not: they need the same environment, see docs/distributed.md).
    """
    try:
        answers = client.run(_environment, on_error="return")
    except Exception as exc:
        raise RenderError(f"cannot ask the Dask workers what they run: {_why(exc)}", _HINT) from None
    mine = _environment()
    for address, theirs in sorted(answers.items()):
        if isinstance(theirs, BaseException):
            if "liganimate" in str(theirs):
                raise RenderError(
                    f"the Dask worker at {address} cannot import liganimate; install the same liganimate on every worker",
                    "pip install 'liganimate[dask]' in the workers' environment",
                )
            raise RenderError(f"the Dask worker at {address} cannot run liganimate: {theirs}")
        for (what, want), got in zip(mine, theirs, strict=True):
            if got[1] != want:
                raise RenderError(
                    f"the Dask worker at {address} has {what} {got[1]}, this machine {want}; "
                    "the frames would not be the bytes of a local run",
                    "give the workers the same environment as this machine (the same liganimate, numpy and zlib)",
                )


def _environment() -> tuple:
    """What decides the bytes of a frame, besides its draw list: ((name, version), ...)."""
    import zlib

    import numpy

    import liganimate

    return (("liganimate", liganimate.__version__), ("numpy", numpy.__version__), ("zlib", zlib.ZLIB_RUNTIME_VERSION))


def _processing(client):
    """Keys of the tasks the scheduler has given to workers, or None if it cannot say."""
    try:
        return {k for keys in client.processing().values() for k in keys}
    except Exception:
        return None


def _worded(exc: BaseException) -> BaseException:
    """A task's failure as the user should see it: the cluster's own failures in words, others as they are."""
    if isinstance(exc, distributed.KilledWorker):
        return RenderError(
            "Dask workers died again and again while drawing the same images (killed, or out of memory); "
            "the images written before are complete",
            "see the workers' logs; Dask gives up on a task after distributed.scheduler.allowed-failures worker deaths",
        )
    if isinstance(exc, ImportError) and (exc.name or "").split(".")[0] == "liganimate":
        return RenderError(
            "a Dask worker cannot import liganimate; install the same liganimate on every worker",
            "pip install 'liganimate[dask]' in the workers' environment",
        )
    if isinstance(exc, cf.CancelledError) or type(exc).__name__ == "CancelledError":
        return cf.CancelledError()
    return exc


# ------------------------------------------------------------------ on the workers


_TUNED: list = []  # the worker process whose allocator is set up (a forked child sets up its own)


def _call(fn, *args):
    """A task on a worker: set up the worker process's allocator (once), then run ``fn(*args)``."""
    if _TUNED != [os.getpid()]:
        _TUNED[:] = [os.getpid()]
        _keep_freed_memory()
    return fn(*args)


def _keep_freed_memory() -> None:
    """Keep the large blocks freed after each image in the heap, as the local pool's workers do.

    Each image allocates and frees the same few large arrays; by default
    glibc returns them to the kernel and gets them back as fresh zeroed
    pages every image, which on a Dask worker doubled the CPU time of
    drawing (measured: 4.0 s against 2.0 s for 600 frames at 640x480).
    """
    try:
        import ctypes

        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return  # not glibc
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    mallopt(M_MMAP_THRESHOLD, 32 << 20)
    mallopt(M_TRIM_THRESHOLD, 256 << 20)


__all__ = ["DaskExecutor"]
