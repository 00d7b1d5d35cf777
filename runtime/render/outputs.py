"""Where a render writes: the options checked before any work, and locks against a second run.

Checking (:func:`check_outputs`) touches nothing: it only looks at the file
system, so a wrong ``--gif`` or ``--fps`` is refused before the program is
even compiled.  Locking (:class:`OutputLock`) then claims the frames folder
and every extra output file for one run, so two runs can never mix their
frames in one folder or one GIF.

Locks are POSIX record locks (``fcntl.lockf``) on a small lock file: the
frames folder's is ``<folder>/.liganimate.lock``, an output file's is
``.<name>.liganimate.lock`` beside it.  The kernel drops a lock when its
process ends, however it ends, so a killed run never leaves a folder
locked; a lock file left behind by a killed run is harmless and is reused.
A finished or interrupted run removes its lock files.  Record locks, unlike
``flock``, are not inherited by forked worker processes, so only the run
itself ever holds them.

Where there is no ``fcntl`` (Windows) the lock is ``msvcrt.locking`` on the
lock file's first byte, which Windows also drops when the process ends.
With neither, a lock is the lock file itself, created exclusively with the
holder's pid in it; a lock file whose process is gone is a killed run's and
is taken over.
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import re
import struct
import sys
import time
from collections.abc import Mapping
from typing import TYPE_CHECKING

from liganimate.runtime.errors import RenderError

if TYPE_CHECKING:
    from .options import RenderOptions

# POSIX record locks where there are (fcntl), Windows' byte locks where not (msvcrt).
try:
    import fcntl
except ImportError:
    fcntl = None  # type: ignore[assignment]
try:
    import msvcrt
except ImportError:
    msvcrt = None  # type: ignore[assignment]

# Flags that only some systems have: none of them is needed for the lock to work.
_OPEN_FLAGS = getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
# A lock file without a pid yet, younger than this, is being created by its holder.
_CREATING = 10.0

LOCK_NAME = ".liganimate.lock"
# The names AtomicWriter's temporary files take (mkstemp: 8 characters of [a-z0-9_]).
_TMP_TAIL = r"\.[a-z0-9_]{8}\.tmp"
_FRAME_TMP = re.compile(r"\.\d{5,}\.png" + _TMP_TAIL)
# GIF delays are 16-bit hundredths of a second: below 100/65535 fps a frame cannot be shown long enough.
MIN_FPS = 0.01
MAX_FPS = 1000.0

# Lock paths this process holds: record locks do not exclude the process that holds them.
_HELD: set = set()


def check_fps(fps, name: str = "--fps") -> float:
    """``fps`` as a float, or a RenderError saying why it cannot be a frame rate."""
    try:
        f = float(fps)
    except (TypeError, ValueError, OverflowError):
        f = math.nan
    if not (MIN_FPS <= f <= MAX_FPS):
        raise RenderError(
            f"{name} {fps} is not a usable frame rate; give a number of frames per second "
            f"from {MIN_FPS:g} to {MAX_FPS:g}"
        )
    return f


def check_outputs(options: RenderOptions, names: Mapping[str, str], make_poses_folder: bool = False) -> None:
    """Refuse output options that could not be honoured, before anything is computed or written.

    Parameters
    ----------
    options : RenderOptions
        ``out``, the frames folder, may not exist yet (it is created with
        its parents); None: no frames are written.  Each output file (the
        movies and the pose record) must name a file, not a folder, in a
        folder that exists.  ``fps`` is the movies' frame rate.
    names : mapping
        How to name each option in messages (:data:`.options.CLI_NAMES`
        or :data:`.options.KEYWORD_NAMES`).
    make_poses_folder : bool, optional
        The pose record's folder may be missing too, because the caller
        creates it (``Program.render(poses=...)`` always has); the command
        line refuses a missing folder for every file alike.

    Raises
    ------
    RenderError
        One line naming the option and the path, e.g. ``--gif out is a folder, not a file``.
    """
    check_fps(options.fps, names["fps"])
    out_dir = options.out
    if out_dir is not None:
        _check_folder(os.fspath(out_dir), names["out"])
    seen: dict = {}
    wanted = [(m.name, p) for m, p in options.movies()] + [("poses", options.poses)]
    for key, path in wanted:
        if path is None:
            continue
        path = os.fspath(path)
        opt = names[key]
        folder = os.path.dirname(os.path.abspath(path))
        if key == "poses" and make_poses_folder and not os.path.lexists(folder):
            _check_folder(os.path.dirname(path), opt)
        else:
            _check_file(path, opt, out_dir)
        real = os.path.realpath(path)
        if out_dir is not None and real == os.path.realpath(out_dir):
            raise RenderError(f"{opt} {path} is the frames folder ({names['out']} {out_dir}); give another file name")
        if real in seen:
            raise RenderError(f"{opt} and {seen[real]} both name {path}; give each its own file")
        seen[real] = opt


def _why_not_writable(folder: str) -> str:
    """Why ``folder`` refuses writes: a read-only file system (EROFS) or a permission, said as such."""
    try:
        read_only = bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):  # no statvfs (Windows): the permission is all there is to say
        read_only = False
    return "the file system is read-only (EROFS)" if read_only else "permission denied"


def _check_folder(path: str, opt: str) -> None:
    if not path:
        raise RenderError(f"{opt} is empty; give a folder for the frames")
    probe = os.path.abspath(path)
    while not os.path.lexists(probe):
        parent = os.path.dirname(probe)
        if parent == probe:
            break
        probe = parent
    if probe == os.path.abspath(path):
        if not os.path.isdir(probe):
            raise RenderError(f"{opt} {path} is a file, not a folder")
    elif not os.path.isdir(probe):
        raise RenderError(f"{opt} {path} cannot be created: {probe} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise RenderError(f"{opt} {path} cannot be written: {_why_not_writable(probe)} for {probe}")


def _check_file(path: str, opt: str, out_dir) -> None:
    if not path:
        raise RenderError(f"{opt} is empty; give a file name")
    if path.endswith(os.sep) or os.path.isdir(path):
        raise RenderError(f"{opt} {path} is a folder, not a file")
    if os.path.lexists(path) and not os.path.islink(path) and not os.path.isfile(path):
        # Replacing it would put a regular file where a device or pipe was.
        raise RenderError(f"{opt} {path} exists and is not a regular file")
    folder = os.path.dirname(os.path.abspath(path))
    shown = os.path.dirname(path) or "."
    if out_dir is not None and folder == os.path.abspath(out_dir) and not os.path.lexists(folder):
        return  # in the frames folder, which the render creates (and _check_folder has vetted)
    if not os.path.isdir(folder):
        what = "is not a folder" if os.path.lexists(folder) else "does not exist"
        raise RenderError(f"{opt} {path} cannot be written: the folder {shown} {what}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise RenderError(f"{opt} {path} cannot be written: {_why_not_writable(folder)} for the folder {shown}")


def lock_path_of(target: str, folder: bool) -> str:
    """The lock file guarding ``target`` (a frames folder, or an output file)."""
    if folder:
        return os.path.join(target, LOCK_NAME)
    return os.path.join(os.path.dirname(os.path.abspath(target)), f".{os.path.basename(target)}{LOCK_NAME}")


def lock_targets(out_dir, files) -> list:
    """(lock path, what it guards as the user wrote it, is it the folder) for a render's outputs.

    An output file inside the frames folder is guarded by the folder's lock.
    ``out_dir`` None: no frames folder.
    """
    out_real = os.path.realpath(out_dir) if out_dir is not None else None
    targets = [(lock_path_of(os.fspath(out_dir), True), os.fspath(out_dir), True)] if out_dir is not None else []
    for f in files:
        if f is None:
            continue
        f = os.fspath(f)
        if out_real is not None and os.path.realpath(f).startswith(out_real + os.sep):
            continue
        targets.append((lock_path_of(f, False), f, False))
    return targets


def holder_of(lock_path: str):
    """The pid of the process holding ``lock_path``'s lock, without taking it; None if free.

    Uses ``F_GETLK`` where the layout of ``struct flock`` is known (Linux);
    elsewhere it says nothing and the lock is found taken when acquired.
    """
    if fcntl is None and msvcrt is None:
        return _live_holder(lock_path)
    if fcntl is None or not sys.platform.startswith("linux"):
        return None
    try:
        fd = os.open(lock_path, os.O_RDONLY | _OPEN_FLAGS | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    try:
        # struct flock: short type, short whence, off_t start, off_t len, pid_t pid (+ padding).
        query = struct.pack("hhqqi4x", fcntl.F_WRLCK, os.SEEK_SET, 0, 0, 0)
        kind, _, _, _, pid = struct.unpack("hhqqi4x", fcntl.fcntl(fd, fcntl.F_GETLK, query))
    except OSError:
        return None
    finally:
        os.close(fd)
    return None if kind == fcntl.F_UNLCK else pid


def refuse_if_locked(out_dir, files, names=None) -> None:
    """Raise the "being written by another run" error now if any output is locked (takes nothing)."""
    for lock, shown, is_folder in lock_targets(out_dir, files):
        # Never open a lock file this process holds: closing any descriptor of it would drop the lock.
        if os.path.realpath(lock) in _HELD:
            raise _taken(shown, is_folder, os.getpid())
        pid = holder_of(lock)
        if pid is not None:
            raise _taken(shown, is_folder, pid)


def _words(exc: OSError) -> str:
    text = exc.strerror or str(exc)
    return text[:1].lower() + text[1:]


def _taken(shown: str, is_folder: bool, pid) -> RenderError:
    who = f" (pid {pid})" if pid and pid > 0 else ""
    what = (shown.rstrip(os.sep) + os.sep) if is_folder else shown
    return RenderError(
        f"{what} is being written by another liganimate run{who}; wait for it to end or choose another output"
    )


def _try_lock(fd: int) -> bool:
    """Lock the open lock file ``fd`` without waiting; False when another process holds it."""
    try:
        if fcntl is not None:
            fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        else:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
    except OSError as exc:
        if exc.errno in (errno.EACCES, errno.EAGAIN, errno.EDEADLK):
            return False
        raise
    return True


def _acquire(lock: str, shown: str, is_folder: bool) -> int:
    """Open and lock ``lock``; its descriptor, or a RenderError saying who holds it."""
    if fcntl is None and msvcrt is None:
        return _acquire_by_creation(lock, shown, is_folder)
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | _OPEN_FLAGS, 0o644)
        except OSError as exc:
            raise RenderError(f"cannot create the lock file {lock} for {shown}: {_words(exc)}") from None
        try:
            locked = _try_lock(fd)
        except OSError as exc:
            os.close(fd)
            raise RenderError(f"cannot lock {lock} for {shown}: {_words(exc)}") from None
        if not locked:
            os.close(fd)
            raise _taken(shown, is_folder, holder_of(lock))
        # The previous holder may have removed the file between our open and our lock:
        # then we hold a lock on a file nobody else will ever open, so start again.
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock, follow_symlinks=False))
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


def _acquire_by_creation(lock: str, shown: str, is_folder: bool) -> int:
    """The lock without an OS lock: create ``lock`` exclusively, taking over a dead holder's."""
    for _ in range(8):
        try:
            return os.open(lock, os.O_RDWR | os.O_CREAT | os.O_EXCL | _OPEN_FLAGS, 0o644)
        except FileExistsError:
            pid = _live_holder(lock)
            if pid is not None:
                raise _taken(shown, is_folder, pid) from None
            with contextlib.suppress(FileNotFoundError):
                os.unlink(lock)  # a killed run's: nobody holds it
        except OSError as exc:
            raise RenderError(f"cannot create the lock file {lock} for {shown}: {_words(exc)}") from None
    raise _taken(shown, is_folder, None)


def _live_holder(lock: str):
    """The pid written in a creation lock if that process is alive (or the file is still being made); else None."""
    try:
        with open(lock, "rb") as fh:
            text = fh.read(32).decode("ascii", "replace").strip()
        age = time.time() - os.stat(lock).st_mtime
    except OSError:
        return None
    if not text.isdigit():
        return -1 if age < _CREATING else None
    pid = int(text)
    if pid == os.getpid():
        return pid
    try:
        os.kill(pid, 0)  # only where there is neither fcntl nor msvcrt: not Windows, where this would kill
    except ProcessLookupError:
        return None
    except OSError:
        return pid  # alive, another user's
    return pid


class OutputLock:
    """Exclusive claim of a render's frames folder and output files, held until :meth:`release`.

    Taking it creates the frames folder, and then removes temporary files
    that a killed run left in the folder's scene subfolders or beside the
    output files (nobody else can be writing them now).

    Parameters
    ----------
    out_dir : str or None
        The frames folder (None: no frames are written).
    files : iterable of str or None
        The GIF, MP4 and pose record paths (None for those not asked for).

    Raises
    ------
    RenderError
        When another run (of this or another process) holds any of them;
        nothing is held then.
    """

    def __init__(self, out_dir, files=()):
        self.held: list = []  # (lock path, descriptor, key in _HELD)
        out_dir = os.fspath(out_dir) if out_dir is not None else None
        files = [os.fspath(f) for f in files if f is not None]
        created = out_dir is not None and not os.path.isdir(out_dir)
        try:
            if out_dir is not None:
                os.makedirs(out_dir, exist_ok=True)
        except OSError as exc:
            raise RenderError(f"cannot create the folder {out_dir}: {_words(exc)}") from None
        try:
            for lock, shown, is_folder in lock_targets(out_dir, files):
                self._take(lock, shown, is_folder)
        except BaseException:
            self.release()
            if created:
                with contextlib.suppress(OSError):
                    os.rmdir(out_dir)  # refused: leave no trace (empty only, so nothing of anyone's is lost)
            raise
        self.sweep(out_dir, files)

    def _take(self, lock: str, shown: str, is_folder: bool) -> None:
        key = os.path.realpath(lock)
        if key in _HELD:
            raise _taken(shown, is_folder, os.getpid())
        fd = _acquire(lock, shown, is_folder)
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
        self.held.append((lock, fd, key))
        _HELD.add(key)

    def sweep(self, out_dir, files=()) -> list:
        """Remove the temporary files of unfinished writes to these outputs; return their paths.

        Safe only while the lock is held: a temporary file then cannot
        belong to a write in progress elsewhere.
        """
        removed = []
        folders = []
        if out_dir is not None:
            with contextlib.suppress(OSError), os.scandir(os.fspath(out_dir)) as it:
                folders = [e.path for e in it if e.name.startswith("scene") and e.is_dir(follow_symlinks=False)]
        for folder in folders:
            with contextlib.suppress(OSError), os.scandir(folder) as it:
                removed += [e.path for e in it if _FRAME_TMP.fullmatch(e.name)]
        for f in files:
            if f is None:
                continue
            f = os.fspath(f)
            folder = os.path.dirname(os.path.abspath(f))
            pattern = re.compile(re.escape("." + os.path.basename(f)) + _TMP_TAIL)
            with contextlib.suppress(OSError), os.scandir(folder) as it:
                removed += [e.path for e in it if pattern.fullmatch(e.name)]
        for path in removed:
            with contextlib.suppress(OSError):
                os.unlink(path)
        return removed

    def release(self) -> None:
        """Remove the lock files and drop the locks; safe to call more than once."""
        while self.held:
            lock, fd, key = self.held.pop()
            # Unlink while still locked: a run waiting on this file then finds it gone and starts afresh.
            with contextlib.suppress(OSError):
                os.unlink(lock)
            with contextlib.suppress(OSError):
                os.close(fd)
            if msvcrt is not None:  # Windows cannot remove an open file: now it is closed
                with contextlib.suppress(OSError):
                    os.unlink(lock)
            _HELD.discard(key)


__all__ = ["OutputLock", "check_fps", "check_outputs", "holder_of", "refuse_if_locked"]
