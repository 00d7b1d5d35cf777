"""Lark's stock parser of lig.lark: its contextual lexer and its own LALR loop.

The reference our parser (lang/lexer.py's scanning decisions in
lang/lalr.py's one loop) is checked against in tests/lang/test_lexer.py,
and the baseline benchmarks/compile.py times it against.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import re

from lark import Lark

from liganimate.lang import tables
from liganimate.lang.parser import BUILTIN_PRIMITIVES
from liganimate.lang.transform import ToAst

_names: contextvars.ContextVar = contextvars.ContextVar("primitive_names", default=BUILTIN_PRIMITIVES)


class PrimitiveNames:
    """Post-lexer: a NAME (or CLAUSE_NAME) that names a primitive becomes PRIM_NAME (our scanner does this itself)."""

    always_accept = ()

    def process(self, stream):
        """Retype the NAMEs of the primitives :func:`primitives` set."""
        names = _names.get()
        for tok in stream:
            if tok.type in ("NAME", "CLAUSE_NAME") and tok.value.upper() in names:
                tok.type = "PRIM_NAME"
            yield tok


@contextlib.contextmanager
def primitives(names):
    """While the block runs, the stock parser reads ``names`` (upper-case) as primitives."""
    token = _names.set(frozenset(names))
    try:
        yield
    finally:
        _names.reset(token)


@functools.lru_cache(maxsize=1)
def stock_parser() -> Lark:
    """Lark's own LALR parser of lig.lark with its contextual lexer, the transformer inside.

    Two rules our scanner applies by itself are given to Lark as terminal
    priorities: keywords are whole words (Lark's scanner, in a state that
    does not accept NAME, would let "SCALE" match the start of
    "SCALEFRAMES"), so each plain keyword becomes a word-bounded regex; and
    the order is regex keywords, then plain keywords, then CLAUSE_NAME (a
    name not followed by an assignment, where a clause may start), then
    NAME.
    """
    grammar = tables.grammar_text()
    grammar = re.sub(r"^([A-Z_]+)\.2:", r"\1.3:", grammar, flags=re.MULTILINE)
    grammar = re.sub(r'^([A-Z_]+): "([A-Z]+)"i$', r"\1.2: /\2\\b/i", grammar, flags=re.MULTILINE)
    return Lark(grammar, **tables.options("contextual", PrimitiveNames(), ToAst()))
