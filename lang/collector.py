"""Keeping Python's cyclic garbage collector out of compiling and loading a program.

Parsing, checking and lowering build trees and tables, never cycles that
must be freed at once; but every few hundred new objects the collector walks
the young ones, and once the survivors outnumber a quarter of the heap it
walks everything. So a program of 50,000 lines cost a third more per line
than one of 1,000, all of it in the collector (issue 12's benchmark,
benchmarks/compile.py).

While a program is compiled the collector is off. Afterwards the objects that
survive (the compiled program, its tables) are frozen: left out of later
collections, which then cost what they cost before the program was compiled.
Frozen objects are still freed when their last reference goes, as any
object is; only a cycle among them waits, until the next compile starts and
unfreezes them (they then age in the oldest generation as usual).
"""

from __future__ import annotations

import contextlib
import gc

_depth = 0  # how many paused() blocks are open (a program loading a library nests them)


@contextlib.contextmanager
def paused():
    """Run the ``with`` body with the cyclic collector off, then freeze what it left alive.

    The collector is on again afterwards if it was on before. Only the
    outermost of nested blocks unfreezes on entry and freezes on exit.
    """
    global _depth
    was_on = gc.isenabled()
    gc.disable()
    if _depth == 0:
        gc.unfreeze()  # the previous program's survivors age as usual again
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0:
            gc.freeze()
        if was_on:
            gc.enable()
