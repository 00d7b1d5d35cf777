"""Writing output files all or nothing.

Each file goes to a temporary file in its own folder, is flushed to disk,
and only when every one of them is complete are they renamed over their
destinations; any failure before that removes the temporary files and
leaves every destination as it was.
"""

from __future__ import annotations

import contextlib
import os
import tempfile

__all__ = ["write_files"]


def write_files(contents, folders=()) -> None:
    """Write several files atomically as a group.

    Parameters
    ----------
    contents : iterable of (str, bytes)
        Destination paths and their bytes.
    folders : iterable of str, optional
        Folders to make first if they are missing (a URDF's meshes folder);
        those made are removed again if the writing fails.

    Raises
    ------
    OSError
        From creating or writing a temporary file; nothing is replaced then.
    """
    temps = []
    made = []
    try:
        for folder in folders:
            if not os.path.isdir(folder):
                os.mkdir(folder)
                made.append(folder)
        for path, data in contents:
            folder = os.path.dirname(os.path.abspath(path))
            fd, tmp = tempfile.mkstemp(dir=folder, prefix="." + os.path.basename(path) + ".", suffix=".tmp")
            temps.append((tmp, path))
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            # mkstemp makes the file 0600; give it what a plain open() would.
            os.chmod(tmp, 0o666 & ~_UMASK)
    except BaseException:
        for tmp, _ in temps:
            with contextlib.suppress(FileNotFoundError):
                os.remove(tmp)
        for folder in reversed(made):
            with contextlib.suppress(OSError):
                os.rmdir(folder)
        raise
    for tmp, path in temps:
        os.replace(tmp, path)


# os.umask can only be read by setting it: once, at import, not under other threads later.
_UMASK = os.umask(0o022)
os.umask(_UMASK)
