"""Drawing frames on a Dask cluster: ``liganimate run --scheduler ADDRESS``.

The program, its scenes and every pose are evaluated once, in this process
(the Dask *client*); only the drawing is sent out.  :class:`DaskExecutor`
stands in for the renderer's local process pool: each task is one call of
the renderer's task function (a batch of images' draw lists), run on
whichever worker is free.  Nothing here is imported unless a scheduler is
given, so a local run never loads Dask.

Faults:

- a task that raises is run again up to ``retries`` times; a worker that
  dies (killed, out of memory, its machine lost) has its tasks moved to
  another worker by the scheduler, up to Dask's
  ``distributed.scheduler.allowed-failures`` times per task.  A task may
  therefore run more than once, or a second time while a stale first run
  is still going: every file is written under a temporary name and
  renamed, and the same images give the same bytes, so a rerun only
  replaces a whole file by the same whole file;
- a scheduler that cannot be reached, or that has no worker, is a
  :class:`RenderError` before any frame is drawn;
- workers that write frames must see the output folder at the same path
  as this process (a shared file system).  :meth:`DaskExecutor.use_folder`
  leaves a marker file there, and each worker process checks it once
  before its first task: a worker that writes to a folder of its own
  fails the render with a message instead of scattering frames.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import itertools
import os
import secrets
import socket
import threading

import distributed

from liganimate.runtime.errors import RenderError

# Times a task that raised is run again (a worker that died is Dask's allowed-failures).
RETRIES = 2
# Seconds to reach the scheduler, and to wait for its first worker.
CONNECT_TIMEOUT = 10.0
WORKER_WAIT = 30.0
# Seconds shutdown waits for the tasks being drawn before it lets them finish on their own.
CLOSE_WAIT = 30.0
# The marker a run leaves in its output folder for the workers to find: MARKER + "." + token.
MARKER = ".liganimate-dask"
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
    folder : str, optional
        The output folder the tasks write to; see :meth:`use_folder`.
    retries : int, optional
        Times a task that raised is run again.
    connect_timeout, worker_wait, close_wait : float, optional
        Seconds to reach the scheduler, to wait for a worker to join it,
        and for :meth:`shutdown` to wait for the tasks being drawn.

    Attributes
    ----------
    workers : int
        Threads of the cluster's workers when it was reached: how many tasks
        run at once (the renderer keeps about twice that many in flight).

    Raises
    ------
    RenderError
        The scheduler cannot be reached, or has no worker after ``worker_wait`` seconds.
    """

    def __init__(
        self,
        address,
        folder=None,
        retries: int = RETRIES,
        connect_timeout: float = CONNECT_TIMEOUT,
        worker_wait: float = WORKER_WAIT,
        close_wait: float = CLOSE_WAIT,
    ):
        self.retries = int(retries)
        self.close_wait = float(close_wait)
        self._client, self._own = _connect(address, connect_timeout)
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
        self._folders: list = []  # folders the tasks write to
        self._marks: list = []  # (folder, marker name) written, checked on the workers
        self._closed = False
        if folder is not None:
            self.use_folder(folder)

    @property
    def client(self) -> distributed.Client:
        """The Dask client the tasks go through."""
        return self._client

    def use_folder(self, folder) -> None:
        """Say that the tasks write into ``folder``, so that every worker must see it.

        A marker file (``.liganimate-dask.<random>``) is written into the
        folder before the first task is sent (the folder exists by then),
        and removed by :meth:`shutdown`; each worker process reads it before
        its first task and refuses to draw if it cannot.  Markers of earlier
        runs killed before they could remove theirs are removed first (only
        one run at a time holds an output folder).
        """
        self._folders.append(os.path.abspath(os.fspath(folder)))

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
        marks = self._write_marks()
        key = f"liganimate-draw-{self._token}-{next(self._count)}"
        future = cf.Future()
        future.set_running_or_notify_cancel()
        dask_future = self._client.submit(_call, fn, marks, *args, key=key, pure=False, retries=self.retries)
        with self._lock:
            self._pending[key] = (dask_future, future)
        dask_future.add_done_callback(self._done)
        return future

    def _done(self, dask_future) -> None:
        """Hand a finished task's outcome to its concurrent future (in Dask's callback thread)."""
        with self._lock:
            entry = self._pending.pop(dask_future.key, None)
        if entry is None:
            return
        future = entry[1]
        try:
            if dask_future.status == "finished":
                future.set_result(dask_future.result())
            elif dask_future.status == "cancelled":
                future.set_exception(cf.CancelledError())
            else:
                future.set_exception(_worded(dask_future.exception()))
        except BaseException as exc:  # the client closing under us, a result lost with its worker
            if not future.done():
                future.set_exception(_worded(exc))

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        """Stop taking tasks, optionally drop those not started and wait for the rest, then disconnect.

        Parameters
        ----------
        wait : bool
            Wait (at most ``close_wait`` seconds) for the tasks given to
            workers, so that every file they write is there when this
            returns.  A task still running after that finishes on its own:
            its files are whole, as they are renamed into place.
        cancel_futures : bool
            Drop the tasks the scheduler has not yet given to a worker.

        Safe to call more than once.  Removes the folder markers and closes
        the client if this executor opened it.
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
            try:
                self._remove_marks()
            finally:
                self._close_client()
                # Callbacks that will never come now (the client is gone): nobody waits forever.
                with self._lock:
                    left, self._pending = list(self._pending.values()), {}
                for _, future in left:
                    if not future.done():
                        future.set_exception(cf.CancelledError())

    def _close_client(self) -> None:
        if self._own:
            self._own = False
            with contextlib.suppress(Exception):
                self._client.close(timeout=self.close_wait)

    # ----------------------------------------------------------- markers
    def _write_marks(self) -> tuple:
        """(folder, marker name) of every folder given to :meth:`use_folder`, written on first use."""
        for folder in self._folders[len(self._marks) :]:
            name = f"{MARKER}.{self._token}"
            _remove_stale_marks(folder)
            try:
                _write_whole(os.path.join(folder, name), self._token.encode("ascii"))
            except OSError as exc:
                raise RenderError(
                    f"cannot prepare the output folder {folder} for the Dask workers: {_why(exc)}"
                ) from None
            self._marks.append((folder, name))
        return tuple((folder, name, self._token) for folder, name in self._marks)

    def _remove_marks(self) -> None:
        for folder, name in self._marks:
            with contextlib.suppress(OSError):
                os.unlink(os.path.join(folder, name))
        self._marks = []


def _write_whole(path: str, data: bytes) -> None:
    """Write ``path`` under a temporary name and rename it, so a worker never reads it half-written."""
    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_CLOEXEC, 0o644)
        try:
            os.write(fd, data)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except OSError:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _remove_stale_marks(folder: str) -> None:
    with contextlib.suppress(OSError), os.scandir(folder) as it:
        stale = [e.path for e in it if e.name.startswith(MARKER + ".")]
    for path in stale:
        with contextlib.suppress(OSError):
            os.unlink(path)


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
        client.__init__(shown, timeout=timeout, set_as_default=False)
    except Exception as exc:
        with contextlib.suppress(Exception):
            client.close(timeout=1)
        client.status = "closed"
        raise RenderError(f"cannot reach the Dask scheduler at {shown}: {_why(exc)}", _HINT) from None
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
        socket.create_connection((host, port), timeout=timeout).close()
    except OSError as exc:
        raise RenderError(f"cannot reach the Dask scheduler at {address}: {_why(exc)}", _HINT) from None


def _why(exc: BaseException) -> str:
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
            "start workers with 'dask worker ADDRESS' on machines that share the output folder",
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
_SEEN: set = set()  # markers this worker process has found


_TUNED: list = []  # the worker process whose allocator is set up (a forked child sets up its own)


def _call(fn, marks, *args):
    """A task on a worker: check once that it sees the output folders, then run ``fn(*args)``."""
    if _TUNED != [os.getpid()]:
        _TUNED[:] = [os.getpid()]
        _keep_freed_memory()
    for mark in marks:
        if mark not in _SEEN:
            _check_folder(*mark)
            if len(_SEEN) >= 64:
                _SEEN.clear()
            _SEEN.add(mark)
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


def _check_folder(folder: str, name: str, token: str) -> None:
    """Raise a RenderError unless this machine sees the run's marker in ``folder`` and may write there."""
    host = socket.gethostname()
    try:
        with open(os.path.join(folder, name), encoding="ascii") as f:
            found = f.read() == token
    except (OSError, UnicodeDecodeError):
        found = False
    if not found:
        raise RenderError(
            f"the Dask worker on {host} does not see the output folder {folder} of this run; "
            "every worker must reach it at the same path, on a file system shared with this machine",
            "mount the folder on every worker (NFS, SMB...) at the same path, or choose -o inside such a mount",
        )
    if not os.access(folder, os.W_OK | os.X_OK):
        raise RenderError(f"the Dask worker on {host} may not write to the output folder {folder}: permission denied")


__all__ = ["DaskExecutor"]
