"""Files written whole: atomic replacement, plain-word errors, and durability in batches.

Every file liganimate writes (frames, GIF, MP4, pose records, compiled
modules, plots) goes through :class:`AtomicWriter` or :func:`write_atomic`:
it is written under a temporary name in the destination's folder and
renamed over the destination only when complete.  A reader, or a run that
crashed or was interrupted, never sees a half-written file, and a failed
write leaves any earlier file intact.

Two levels of promise, chosen per write:

* **Process crash** (Ctrl-C, SIGKILL, an exception): the rename alone
  makes the file whole-or-absent; the data is in the kernel's page cache,
  which outlives the process.  No ``fsync`` is needed for this.
* **Power loss or kernel crash**: the data and the rename must reach the
  disk first.  ``fsync=True`` syncs each file before its rename (one disk
  flush a file).  A :class:`SyncBatch` instead syncs many files written
  with ``fsync=False`` together, then their folders: everything before its
  last :meth:`SyncBatch.sync` survives a power loss, and files renamed since
  may be missing or empty afterwards (never a mixture of two versions).
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys
import tempfile
import threading
from typing import Self

from liganimate.runtime.errors import RenderError

# Plain words for the errors a full, read-only or forbidden destination gives.
_ERRNO_WORDS = {
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "the file grew larger than the system allows",
    errno.EROFS: "the file system is read-only",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EIO: "input/output error",
}


def os_error_words(exc: OSError) -> str:
    """A plain, lower-case phrase for an OSError ("no space left on device")."""
    words = _ERRNO_WORDS.get(exc.errno) if exc.errno is not None else None
    if words is None:
        text = exc.strerror or str(exc) or type(exc).__name__
        words = text[:1].lower() + text[1:]
    return words


def write_error(exc: OSError, path) -> RenderError:
    """The error to show for ``exc`` raised while writing ``path``: it names ``path``, not a temporary file."""
    path = os.fspath(path)
    if exc.errno == errno.EISDIR:
        return RenderError(f"{path} is a folder, not a file")
    if exc.errno == errno.ENOENT:
        return RenderError(f"cannot write {path}: the folder {os.path.dirname(path) or '.'} does not exist")
    if exc.errno == errno.ENOTDIR:
        return RenderError(f"cannot write {path}: part of its path is not a folder")
    return RenderError(f"{os_error_words(exc)} while writing {path}")


def temporary_beside(path) -> str:
    """Create an empty temporary file (``.<name>.<random>.tmp``) in ``path``'s folder; return its path.

    Raises
    ------
    RenderError
        Naming ``path`` when the folder refuses.
    """
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix="." + os.path.basename(path) + ".", suffix=".tmp")
        os.close(fd)
    except OSError as exc:
        raise write_error(exc, path) from None
    return tmp


def publish(tmp: str, path, fsync: bool = True) -> None:
    """Give the finished temporary file ``tmp`` ordinary permissions and rename it over ``path``.

    ``fsync`` flushes its data to disk first (see the module's notes).

    Raises
    ------
    OSError
        As the system reports it; the caller removes ``tmp``.
    """
    if fsync:
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    os.chmod(tmp, 0o666 & ~_UMASK)
    os.replace(tmp, path)


class AtomicWriter:
    """A file written under a temporary name and renamed over ``path`` by :meth:`commit`.

    The temporary file (``.<name>.<random>.tmp``) lives in the destination's
    folder, so the rename is atomic.  Data is written with ``os.write`` from
    an in-memory buffer (no Python file object whose ``close`` could fail
    half-way).  On any failure, and on :meth:`abort`, the temporary file is
    unlinked before anything else is tried, so a full disk gets its space
    back; :meth:`abort` may be called any number of times.  Used as a
    context manager, it commits when the block succeeds and aborts otherwise.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.  It is also the name errors give.
    fsync : bool, optional
        Flush the data to disk before the rename (default), so that after a
        power loss the file is either the old one or the complete new one.
        Without it the file is still whole after a crash of the process;
        see :class:`SyncBatch` for making many such files durable at once.
    buffer : int, optional
        Bytes gathered before each ``os.write``.

    Raises
    ------
    RenderError
        From any method, when the system refuses: the message names ``path``
        and says why in words ("no space left on device while writing out/a.gif").
    """

    def __init__(self, path, fsync: bool = True, buffer: int = 1 << 18):
        self.path = os.fspath(path)
        self._fsync = fsync
        self._limit = buffer
        self._buf = bytearray()
        self._fd = -1
        self._tmp = None
        folder = os.path.dirname(os.path.abspath(self.path))
        try:
            self._fd, self._tmp = tempfile.mkstemp(
                dir=folder, prefix="." + os.path.basename(self.path) + ".", suffix=".tmp"
            )
        except OSError as exc:
            raise write_error(exc, self.path) from None

    def write(self, data) -> None:
        """Append bytes (or any buffer) to the file."""
        if self._tmp is None:
            raise ValueError("write to a finished AtomicWriter")
        self._buf += data
        if len(self._buf) >= self._limit:
            self._guarded(self._drain)

    def commit(self) -> None:
        """Write what is buffered, sync (if asked), and rename the file over the destination."""
        if self._tmp is None:
            raise ValueError("commit of a finished AtomicWriter")
        self._guarded(self._finish)

    def abort(self) -> None:
        """Remove the temporary file and release the descriptor; never raises an OSError."""
        tmp, fd = self._tmp, self._fd
        self._tmp, self._fd, self._buf = None, -1, bytearray()
        # Unlink first: if closing fails (or is interrupted) the space is already given back.
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if fd >= 0:
            with contextlib.suppress(OSError):
                os.close(fd)

    def _guarded(self, step) -> None:
        try:
            step()
        except OSError as exc:
            self.abort()
            raise write_error(exc, self.path) from None
        except BaseException:
            self.abort()
            raise

    def _drain(self) -> None:
        view = memoryview(self._buf)
        try:
            while view:
                n = os.write(self._fd, view)
                if n <= 0:  # a regular file never does this; do not spin if one does
                    raise OSError(errno.EIO, "write wrote nothing")
                view = view[n:]
        finally:
            view.release()
        self._buf.clear()

    def _finish(self) -> None:
        self._drain()
        if self._fsync:
            os.fsync(self._fd)
        # mkstemp creates the file 0600; give it the permissions a plain open() would.
        os.fchmod(self._fd, 0o666 & ~_UMASK)
        fd, self._fd = self._fd, -1
        os.close(fd)  # close can report a late write error (NFS, quotas): before the rename
        assert self._tmp is not None  # set in __init__, cleared only here and by abort
        os.replace(self._tmp, self.path)
        self._tmp = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if kind is None:
            self.commit()
        else:
            self.abort()


def write_atomic(path, data, fsync: bool = True) -> None:
    """Replace ``path`` with ``data`` (bytes or any buffer) atomically; see :class:`AtomicWriter`.

    Raises
    ------
    RenderError
        Naming ``path``, when the system refuses; ``path`` is then untouched.
    """
    with AtomicWriter(path, fsync, buffer=0) as f:
        f.write(data)


def fsync_folder(path) -> None:
    """Make the renames done in folder ``path`` durable (a no-op where folders cannot be opened)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # some file systems refuse to sync a folder; the files themselves are synced
    finally:
        os.close(fd)


class SyncBatch:
    """Files renamed into place without ``fsync``, made durable together every ``every`` files.

    :meth:`add` notes a file once it has been renamed into place; every
    ``every`` files the noted files' data and then their folders are
    flushed to disk, in a thread of its own (the flush waits for the disk,
    and the caller need not); :meth:`sync` flushes everything noted and
    waits for it.  On Linux one ``syncfs`` call flushes the whole file
    system the folder is on (one journal commit for the batch, not one a
    file); elsewhere each file is opened and synced.  Failures to sync are
    ignored: the files are whole either way, only their durability is at
    stake.

    Parameters
    ----------
    every : int
        Files between two syncs.

    Notes
    -----
    After a power loss, every file added before the last completed sync is
    whole; files added since may be missing or empty (the rename reached
    the disk, the data not yet), never a mixture of two versions.
    """

    def __init__(self, every: int = 256):
        self.every = max(1, int(every))
        self.files: list = []
        self.folders: dict = {}  # folder -> None, in order first seen
        self._thread: threading.Thread | None = None

    def add(self, path) -> None:
        """Note ``path`` (renamed into place); start a sync of the batch when it is full."""
        self.files.append(os.fspath(path))
        if len(self.files) >= self.every and (self._thread is None or not self._thread.is_alive()):
            files, folders = self._take()
            self._thread = threading.Thread(target=_sync, args=(files, folders), name="liganimate-sync", daemon=True)
            self._thread.start()

    def add_folder(self, folder) -> None:
        """Sync ``folder`` too at the next :meth:`sync` (a folder made, a file renamed into it)."""
        self.folders[os.fspath(folder)] = None

    def sync(self) -> None:
        """Flush every noted file, then the folders holding them, and wait for it (best effort)."""
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        _sync(*self._take())

    def _take(self) -> tuple:
        files, self.files = self.files, []
        folders = dict.fromkeys(os.path.dirname(os.path.abspath(f)) for f in files)
        folders.update(self.folders)
        self.folders = {}
        return files, list(folders)


def _sync(files: list, folders: list) -> None:
    """Flush ``files`` to disk, then ``folders``; errors are ignored."""
    if not files and not folders:
        return
    # One syncfs per file system the files are on; per-file fsync where that is not possible.
    devices: dict = {}
    for folder in folders:
        with contextlib.suppress(OSError):
            devices.setdefault(os.stat(folder).st_dev, folder)
    if files and not (devices and all(_syncfs(f) for f in devices.values())):
        for f in files:
            _fsync_path(f)
    for folder in folders:
        fsync_folder(folder)


def _fsync_path(path: str) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


_LIBC = None


def _syncfs(folder: str) -> bool:
    """``syncfs`` on ``folder``'s file system (Linux); False where it is not available or fails."""
    global _LIBC
    if not sys.platform.startswith("linux"):
        return False
    try:
        if _LIBC is None:
            import ctypes

            _LIBC = ctypes.CDLL(None, use_errno=True)
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    except (OSError, AttributeError):
        return False
    try:
        return _LIBC.syncfs(fd) == 0
    except AttributeError:
        return False
    finally:
        os.close(fd)


# os.umask can only be read by setting it; do that once, at import, rather
# than briefly changing it under other threads on every write.
_UMASK = os.umask(0o022)
os.umask(_UMASK)

__all__ = [
    "AtomicWriter",
    "SyncBatch",
    "fsync_folder",
    "os_error_words",
    "publish",
    "temporary_beside",
    "write_atomic",
    "write_error",
]
