"""Running `liganimate` and compiled modules in a child Python, as a user does, with the output kept as text."""

from __future__ import annotations

import subprocess
import sys


def python(*args: str, cwd=None, env=None, **kw) -> subprocess.CompletedProcess:
    """Run this test run's Python with ``args`` and wait for it.

    Parameters
    ----------
    *args
        The command line after ``python``: a script (a compiled module) and its options, or ``-m``.
    cwd, env
        The child's folder and environment (None: the test's own).
    **kw
        Passed on to :func:`subprocess.run` (``timeout``, ``input``...).

    Returns
    -------
    subprocess.CompletedProcess
        With ``stdout`` and ``stderr`` as text; a failing status is not an exception, the test looks at it.
    """
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=cwd, env=env, **kw)


def liganimate(*args: str, cwd=None, env=None, **kw) -> subprocess.CompletedProcess:
    """Run the ``liganimate`` command (``python -m liganimate ARGS``) as :func:`python` does."""
    return python("-m", "liganimate", *args, cwd=cwd, env=env, **kw)
