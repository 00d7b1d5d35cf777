"""Run mypy the way CI sees the code, whatever way liganimate is installed here.

Usage::

    python tools/typecheck.py            # the [tool.mypy] files, as CI checks them
    python tools/typecheck.py -- ARGS    # extra arguments for mypy

Why: CI installs the project with ``pip install '.[test]'`` (not editable), so
every ``liganimate.*`` import reaches mypy as the installed, typed package
(``py.typed`` is shipped). A developer's editable install maps ``liganimate.lang``
to ``lang/`` through an import hook mypy cannot follow, so those imports reach
it as ``Any`` and errors that CI reports stay hidden. This script lays the
sources out as they are installed (``liganimate/`` holding ``lang/``,
``compiler/``, ``runtime/``, ``stdlib/`` beside ``src/liganimate``'s own files) in a
temporary folder, puts it first on mypy's search path and runs mypy there:
the same answer in every environment, and never fewer errors than CI finds.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: The folders installed as liganimate.<name> (pyproject.toml's package-dir).
SUBPACKAGES = ("lang", "compiler", "runtime", "stdlib")


def lay_out(target: str) -> None:
    """Copy the sources into ``target/liganimate`` as ``pip install .`` arranges them."""
    skip = shutil.ignore_patterns("__pycache__", "*.pyc")
    package = os.path.join(target, "liganimate")
    shutil.copytree(os.path.join(ROOT, "src", "liganimate"), package, ignore=skip)
    for name in SUBPACKAGES:
        shutil.copytree(os.path.join(ROOT, name), os.path.join(package, name), ignore=skip)


def main(argv: list[str]) -> int:
    """Run mypy over the configured files with the installed layout first on its path; return its status."""
    extra = argv[1:] if argv[:1] == ["--"] else argv
    with tempfile.TemporaryDirectory(prefix="liganimate-typecheck-") as tmp:
        lay_out(tmp)
        env = dict(os.environ, MYPYPATH=tmp)
        # The copy is checked as well as the sources it mirrors; report each error once, at the source.
        run = subprocess.run(
            [sys.executable, "-m", "mypy", *extra], cwd=ROOT, env=env, capture_output=True, text=True, check=False
        )
    lines = [
        line
        for line in run.stdout.splitlines()
        if not line.startswith(tmp) and ": note: By default the bodies" not in line
    ]
    print("\n".join(lines))
    sys.stderr.write(run.stderr)
    return run.returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
