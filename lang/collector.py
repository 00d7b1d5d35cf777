"""Keeping Python's cyclic garbage collector out of compiling and loading a program.

Parsing, checking and lowering build trees and tables, never cycles that
must be freed at once; but every few hundred new objects the collector walks
the young ones, and once the survivors outnumber a quarter of the heap it
walks everything. So a program of 50,000 lines cost a third more per line
than one of 1,000, all of it in the collector (issue 12's benchmark,
benchmarks/compile.py).

While a program is compiled the collector is off, and afterwards as it was.

The command line, whose process is the program's, also freezes what survives
(the compiled program, its tables; :func:`freeze_survivors`): left out of
later collections, which then cost what they cost before the program was
compiled. Frozen objects are still freed when their last reference goes, as
any object is; only a cycle among them waits, until the next compile starts
and unfreezes them (they then age in the oldest generation as usual).
``gc.freeze`` acts on every object of the process, so a library user's
process (``liganimate.load`` in a notebook) is never frozen: there the
collector is only paused while a program compiles.
"""

from __future__ import annotations

import contextlib
import gc

_depth = 0  # how many paused() blocks are open (a program loading a library nests them)
_freezing = False  # set by the command line: see freeze_survivors


def freeze_survivors(on: bool = True) -> None:
    """Freeze what each compile leaves alive, from now on in this process (the command line's choice).

    Only for a process that is the program's own: ``gc.freeze`` freezes
    every object of the process, not only the compiler's.
    """
    global _freezing
    _freezing = on


@contextlib.contextmanager
def paused():
    """Run the ``with`` body with the cyclic collector off (and, when freezing, freeze what it left alive).

    The collector is on again afterwards if it was on before. Only the
    outermost of nested blocks unfreezes on entry and freezes on exit, and
    only after :func:`freeze_survivors`.
    """
    global _depth
    was_on = gc.isenabled()
    gc.disable()
    freezing = _freezing
    if _depth == 0 and freezing:
        gc.unfreeze()  # the previous program's survivors age as usual again
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0 and freezing:
            gc.freeze()
        if was_on:
            gc.enable()
