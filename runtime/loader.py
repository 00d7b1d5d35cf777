"""Executing a generated module's text in memory, one piece at a time.

A big program is lowered into many top-level functions (``def _main_0(rt):``,
``def _main_1(rt):``... see compiler/lower.py). CPython holds the whole
syntax tree and code of what it compiles at once, so compiling the module in
one go would cost about as much memory as compiling one giant function; the
pieces are compiled and executed one after the other into one namespace
instead. The result is the namespace that importing the module would give.
"""

from __future__ import annotations

from liganimate.lang import collector

# Every line the lowerer writes is one physical line (program text reaches the
# module only through repr(), which never writes a raw line break), so a line
# that begins with this text is a top-level function of the main program.
PIECE_MARK = "\ndef _main"


def exec_module(text: str, filename: str, namespace: dict) -> dict:
    """Execute generated module ``text`` into ``namespace``, piece by piece; return ``namespace``.

    ``filename`` names the code in tracebacks. The pieces are: the module
    up to the first function of the main program, then each such function
    (the last piece holds ``_main`` and the module's tail).
    """
    start = 0
    with collector.paused():  # code objects and constants, no cycles (lang/collector.py)
        while True:
            end = text.find(PIECE_MARK, start + 1)
            piece = text[start:] if end < 0 else text[start : end + 1]
            exec(compile(piece, filename, "exec"), namespace)  # noqa: S102 - the module the lowerer wrote
            if end < 0:
                return namespace
            start = end + 1
