"""The rule of every declared statement (``@declared`` in lang/ast.py): read from its declaration.

A declared statement needs no rule of its own: where it may stand and the
types of its parts are checked, and its runtime call emitted, from what
its node declares.
"""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang.vocabulary import NUMBER

from .. import types as T
from .base import Rule, rule


@rule(A.Declared)
class Declared(Rule):
    """``rt.<runtime>(<parts>, at)`` after checking each part's type and the statement's place."""

    def check(self, c, s, context):
        declaration = A.DECLARED[type(s)]
        place = "primitive" if c.st.primitive is not None else context
        if place not in declaration.places:
            c.st.out.error(s, declaration.misplaced, declaration.hint)
        for name, part in declaration.parts:
            value = getattr(s, name)
            for e in value if part.many else (value,):
                _part(c, e, part)

    def lower(self, lo, s, where):
        declaration = A.DECLARED[type(s)]
        args = []
        for name, part in declaration.parts:
            value = getattr(s, name)
            args.append("(" + "".join(lo.expr(v) + ", " for v in value) + ")" if part.many else lo.expr(value))
        lo.emit(f"rt.{declaration.runtime}({''.join(a + ', ' for a in args)}{lo.at(s)})")


def _part(c, e, part: A.Part) -> None:
    if part.accepts == NUMBER:
        c.t.want_number(e, part.what)
    elif len(part.accepts) == 1:
        c.t.want(e, part.accepts[0], part.what)
    else:
        got = c.t.expr(e)
        if got is not None and not any(T.fits(t, got) for t in part.accepts):
            nouns = " or ".join(T.NOUN[t] for t in part.accepts)
            c.st.out.error(e, f"{part.what} must be {nouns}, not {T.NOUN[got]}")
