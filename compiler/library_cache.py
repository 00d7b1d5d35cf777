"""The disk cache of compiled libraries: JSON entries authenticated under a per-user key.

An entry is read back only if this user's own process wrote it: the folder
must be the user's (mode 0700, not writable by others, not a symbolic
link), the entry a regular file of the user's, and its HMAC-SHA256 under
the key file of the folder must match. Nothing here unpickles, imports or
runs what it reads; the caller decodes a plain JSON object. Anything out of
the ordinary (a missing key, a named pipe or a link at an entry's name, a
bad MAC, a full disk) is a miss or a skipped write, never an exception and
never a wait. docs/security.md states the trust model.

All files are opened relative to one descriptor of the folder, so a folder
swapped after it was checked is not followed.
"""

from __future__ import annotations

import errno
import hashlib
import hmac
import json
import os
import secrets
import stat
import sys
from pathlib import Path

FORMAT = b"liganimate-library-cache 2"
KEY_FILE = "key"
KEY_BYTES = 32
# Well above a compiled 64 MB library (see lang/source.py); a bigger entry is not written.
MAX_ENTRY_BYTES = 256 * 1024 * 1024

_O = getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
_READ = os.O_RDONLY | _O | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
_CREATE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | _O
# Without these (Windows) nothing here can be made safe, so there is no disk cache.
_SUPPORTED = (
    hasattr(os, "geteuid")
    and hasattr(os, "O_NOFOLLOW")
    and hasattr(os, "O_DIRECTORY")
    and os.open in os.supports_dir_fd
)

_warned: set = set()


def cache_dir() -> Path | None:
    """Where compiled libraries are kept between runs, or None to keep nothing.

    ``LIGANIMATE_CACHE`` names the folder (empty: no disk cache); otherwise
    ``$XDG_CACHE_HOME/liganimate`` or ``~/.cache/liganimate``.
    """
    env = os.environ.get("LIGANIMATE_CACHE")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "liganimate"


def _warn(folder: Path, reason: str) -> None:
    # Once per folder and reason: the cache is a speed-up, so a run goes on without it.
    if (str(folder), reason) not in _warned:
        _warned.add((str(folder), reason))
        shown = str(folder).encode("unicode_escape", "backslashreplace").decode("ascii")
        sys.stderr.write(f"liganimate: warning: not using the library cache {shown}: {reason}\n")


def _open_folder() -> tuple:
    """``(descriptor, folder)`` of the cache folder, made 0700 if new, or ``(None, folder)``."""
    folder = cache_dir()
    if folder is None or not _SUPPORTED:
        return None, folder
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        os.mkdir(folder, 0o700)
    except FileExistsError:
        pass
    except OSError:
        return None, folder  # a read-only home only costs compiling afresh
    try:
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | _O)
    except OSError as exc:
        if exc.errno in (errno.ELOOP, errno.ENOTDIR):
            _warn(folder, "it is a symbolic link or not a folder")
        return None, folder
    st = os.fstat(fd)
    reason = None
    if st.st_uid != os.geteuid():
        reason = "it belongs to another user"
    elif st.st_mode & 0o022:
        reason = "other users may write in it (chmod 700 it and remove what you did not put there)"
    if reason is not None:
        os.close(fd)
        _warn(folder, reason)
        return None, folder
    if st.st_mode & 0o077:
        try:  # a folder made by an older liganimate: nobody else needs to read it
            os.fchmod(fd, 0o700)
        except OSError:
            pass
    return fd, folder


def _private_file(fd: int, size: int | None = None) -> bool:
    st = os.fstat(fd)
    return (
        stat.S_ISREG(st.st_mode)
        and st.st_uid == os.geteuid()
        and not st.st_mode & 0o022
        and (st.st_size == size if size is not None else st.st_size <= MAX_ENTRY_BYTES)
    )


def _read_all(fd: int, limit: int) -> bytes | None:
    chunks: list[bytes] = []
    total = 0
    while True:
        chunk = os.read(fd, min(1 << 20, limit + 1 - total))
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)
        total += len(chunk)
        if total > limit:
            return None


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def _read_key(dfd: int, folder: Path) -> bytes | None:
    try:
        fd = os.open(KEY_FILE, _READ, dir_fd=dfd)
    except FileNotFoundError:
        return None
    except OSError:
        _warn(folder, f"its {KEY_FILE} file is not a private file of yours (remove it to start the cache afresh)")
        return None
    try:
        if os.fstat(fd).st_mode & 0o777 != 0o600 or not _private_file(fd, KEY_BYTES):
            _warn(folder, f"its {KEY_FILE} file is not a private file of yours (remove it to start the cache afresh)")
            return None
        key = _read_all(fd, KEY_BYTES)
    finally:
        os.close(fd)
    return key if key is not None and len(key) == KEY_BYTES else None


def _key(dfd: int, folder: Path) -> bytes | None:
    """The folder's secret key, made on first use.

    A new key is written whole to a fresh 0600 file (O_EXCL, O_NOFOLLOW) and
    then linked to its name, which fails if another process got there
    first: no process ever reads a half-written key.
    """
    key = _read_key(dfd, folder)
    if key is not None:
        return key
    try:
        os.stat(KEY_FILE, dir_fd=dfd, follow_symlinks=False)
        return None  # there, but not usable: _read_key said why
    except FileNotFoundError:
        pass
    except OSError:
        return None
    tmp = f".key-{secrets.token_hex(8)}"
    try:
        fd = os.open(tmp, _CREATE, 0o600, dir_fd=dfd)
        try:
            os.fchmod(fd, 0o600)  # whatever the umask
            _write_all(fd, secrets.token_bytes(KEY_BYTES))
        finally:
            os.close(fd)
        try:
            os.link(tmp, KEY_FILE, src_dir_fd=dfd, dst_dir_fd=dfd)
        except FileExistsError:
            pass  # another process made one a moment ago: use theirs
    except OSError:
        return None
    finally:
        try:
            os.unlink(tmp, dir_fd=dfd)
        except OSError:
            pass
    return _read_key(dfd, folder)


def _mac(key: bytes, entry: str, body: bytes) -> bytes:
    # The entry's name is signed too: a valid entry moved to another name is a miss.
    return hmac.new(key, FORMAT + b"\0" + entry.encode() + b"\0" + body, hashlib.sha256).hexdigest().encode()


def entry_name(*parts: bytes) -> str:
    """The file name of the entry for ``parts`` (what the entry depends on)."""
    return hashlib.sha256(b"\0".join(parts)).hexdigest() + ".json"


def read(entry: str) -> dict | None:
    """The JSON object stored at ``entry`` by this user, or None (a miss) for anything else."""
    dfd, folder = _open_folder()
    if dfd is None:
        return None
    try:
        key = _key(dfd, folder)
        if key is None:
            return None
        fd = os.open(entry, _READ, dir_fd=dfd)
        try:
            if not _private_file(fd):
                return None
            data = _read_all(fd, MAX_ENTRY_BYTES)
        finally:
            os.close(fd)
    except OSError:
        return None
    finally:
        os.close(dfd)
    if data is None:
        return None
    head, _, rest = data.partition(b"\n")
    mac, _, body = rest.partition(b"\n")
    if head != FORMAT or not hmac.compare_digest(mac, _mac(key, entry, body)):
        return None
    try:
        obj = json.loads(body)
    except (ValueError, RecursionError):
        return None
    return obj if isinstance(obj, dict) else None


def write(entry: str, obj: dict) -> None:
    """Store ``obj`` at ``entry``: whole or not at all (a fresh 0600 file renamed into place)."""
    body = json.dumps(obj, ensure_ascii=True, separators=(",", ":")).encode("ascii")
    if len(body) > MAX_ENTRY_BYTES - 200:
        return
    dfd, folder = _open_folder()
    if dfd is None:
        return
    tmp = f".tmp-{secrets.token_hex(8)}"
    placed = False
    try:
        key = _key(dfd, folder)
        if key is None:
            return
        fd = os.open(tmp, _CREATE, 0o600, dir_fd=dfd)
        try:
            os.fchmod(fd, 0o600)
            _write_all(fd, FORMAT + b"\n" + _mac(key, entry, body) + b"\n" + body)
        finally:
            os.close(fd)
        os.replace(tmp, entry, src_dir_fd=dfd, dst_dir_fd=dfd)
        placed = True
    except OSError:
        pass  # a full disk or a read-only folder only costs compiling afresh next time
    finally:
        if not placed:
            try:
                os.unlink(tmp, dir_fd=dfd)
            except OSError:
                pass
        os.close(dfd)
