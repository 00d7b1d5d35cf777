"""The command line of the modules that write out a generated file of lang/ (the parser's tables, the node methods).

Each of ``python -m liganimate.lang.tables`` and ``python -m
liganimate.lang.node_methods`` writes its file again when the text it makes
differs, or with ``--check`` only reports whether the shipped file is
current (a test runs that check). The file is replaced whole, never left
half-written.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path


def regenerate(argv, module: str, path: Path, make_text: Callable[[], str], summary: str) -> int:
    """Write ``path`` again from ``make_text()`` (or with ``--check`` in ``argv``, report whether it is current).

    Parameters
    ----------
    argv : list of str or None
        The command's arguments (None: ``sys.argv[1:]``).
    module : str
        The command's module, as typed after ``python -m`` (for its usage line and the hint).
    path : Path
        The generated file.
    make_text : callable
        Makes the file's text as it should be now.
    summary : str
        What the command does (its ``--help`` description).

    Returns
    -------
    int
        The exit status: 0, or 1 for ``--check`` of a stale file.
    """
    ap = argparse.ArgumentParser(prog=f"python -m {module}", description=summary)
    ap.add_argument("--check", action="store_true", help="only check; exit 1 if the file is stale")
    args = ap.parse_args(argv)
    text = make_text()
    current = path.read_text(encoding="utf-8") if path.exists() else None
    if args.check:
        if current != text:
            print(f"{path} is stale: run python -m {module}", file=sys.stderr)
            return 1
        print(f"{path} is current")
        return 0
    if current == text:
        print(f"{path} already current")
        return 0
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise
    print(f"wrote {path}")
    return 0
