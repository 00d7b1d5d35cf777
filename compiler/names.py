"""Which words a program may use as a name it defines: one rule for every writer of LIG text.

Tools that write libraries (``liganimate import``, the studio's Save) and
the command-line options that name a MODEL or a MOTION all ask here, so a
generated library never defines a keyword or a built-in function. The
keywords are read from the grammar itself (the lexer's own table), so a
word added to ``lang/lig.lark`` is reserved here without another list.
"""

from __future__ import annotations

import functools
import re

from .types import BUILTINS

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


@functools.lru_cache(maxsize=1)
def reserved() -> frozenset:
    """Every upper-case word a program may not define: the grammar's keywords and the built-in functions."""
    from liganimate.lang.parser import driver

    # BOX and its pattern's words are the built-in primitive's, not the grammar's.
    return frozenset(driver().scanner.tables.keywords) | frozenset(BUILTINS) | {"BOX", "HEIGHT", "DEPTH"}


@functools.lru_cache(maxsize=1)
def _strict() -> frozenset:
    from liganimate.lang.parser import driver

    # Words such as MOVE or GOAL are keywords only where no assignment
    # follows, so a program may still define them (docs/language.md).
    return reserved() - frozenset(driver().scanner.tables.contextual)


def definable(text: str) -> bool:
    """Whether a program may define ``text``: a LIG name that is no keyword except a contextual one.

    Writers that invent names (segment names from a capture) avoid all of
    :func:`reserved`, contextual keywords included, to stay unambiguous.
    """
    return bool(_NAME.match(text)) and text.upper() not in _strict()


__all__ = ["definable", "reserved"]
