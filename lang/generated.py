"""The command line of the modules that write out a generated file of lang/ (the parser's tables, the node methods).

Each of ``python -m liganimate.lang.tables`` (lig.lark's generated
statements, then the parser's tables) and ``python -m
liganimate.lang.node_methods`` writes its files again when the text it makes
differs, or with ``--check`` only reports whether the shipped file is
current (a test runs that check). The file is replaced whole, never left
half-written.
"""

from __future__ import annotations

import argparse
import os
import stat
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path


def regenerate(argv, module: str, files: Sequence[tuple[Path, Callable[[], str]]], summary: str) -> int:
    """Write each file again from its ``make_text()`` (or with ``--check`` in ``argv``, report whether it is current).

    Parameters
    ----------
    argv : list of str or None
        The command's arguments (None: ``sys.argv[1:]``).
    module : str
        The command's module, as typed after ``python -m`` (for its usage line and the hint).
    files : sequence of (Path, callable)
        The generated files and what makes each one's text as it should be
        now, in order: a file may be made from the ones before it, so each
        text is made after the files before it are written.
    summary : str
        What the command does (its ``--help`` description).

    Returns
    -------
    int
        The exit status: 0, or 1 for ``--check`` of a stale file.
    """
    ap = argparse.ArgumentParser(prog=f"python -m {module}", description=summary)
    ap.add_argument("--check", action="store_true", help="only check; exit 1 if a file is stale")
    args = ap.parse_args(argv)
    status = 0
    for path, make_text in files:
        text = make_text()
        current = path.read_text(encoding="utf-8") if path.exists() else None
        if args.check:
            if current != text:
                print(f"{path} is stale: run python -m {module}", file=sys.stderr)
                status = 1
            else:
                print(f"{path} is current")
        elif current == text:
            print(f"{path} already current")
        else:
            _replace(path, text)
            print(f"wrote {path}")
    return status


def _replace(path: Path, text: str) -> None:
    """Replace ``path`` whole with ``text`` (a temporary file renamed over it: never half-written)."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        # mkstemp makes the file readable by its owner alone; keep the mode the file had.
        os.chmod(tmp, stat.S_IMODE(path.stat().st_mode) if path.exists() else 0o644)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise
