"""Rules of the statements of a PRIMITIVE's body: DRAW WITH, DRAW POLY and RETURN."""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang.vocabulary import DRAW_WITH

from .. import types as T
from .base import Rule, rule


@rule(A.Return)
class Return(Rule):
    """``RETURN``: the PRIMITIVE's drawing is its value."""

    def check(self, c, s, context):
        if c.st.primitive is None:
            c.st.out.error(s, "RETURN belongs in a PRIMITIVE")

    def lower(self, lo, s, where):
        lo.emit("return _g.result()")


@rule(A.DrawWith)
class DrawWith(Rule):
    """``DRAW WITH <LIGHTNESS l>`` (or ``<COLOUR (r, g, b)>``): how the following polygons are drawn."""

    def check(self, c, s, context):
        if c.st.primitive is None:
            c.st.out.error(s, "DRAW belongs in a PRIMITIVE")
        for m in s.modifiers:
            spec = next((d for d in DRAW_WITH if d.kind == m.kind), None)
            if spec is None:
                c.st.out.error(m, f"DRAW WITH takes {' or '.join(f'<{d.label} ...>' for d in DRAW_WITH)}")
                c.t.expr(m.arg)
                continue
            got = c.t.expr(m.arg)
            if got is not None and got not in spec.accepts:
                c.st.out.error(m.arg, f"{spec.label} needs {spec.accepts_noun}, not {T.NOUN[got]}")

    def lower(self, lo, s, where):
        for m in s.modifiers:
            # The canvas has one setter per DRAW WITH modifier, named by its kind.
            lo.emit(f"_g.{m.kind}({lo.expr(m.arg)})")


@rule(A.DrawPoly)
class DrawPoly(Rule):
    """``DRAW POLY FROM p TO q ...``: one polygon of the PRIMITIVE's drawing."""

    def check(self, c, s, context):
        if c.st.primitive is None:
            c.st.out.error(s, "DRAW belongs in a PRIMITIVE")
        for p in s.points:
            c.t.want(p, T.VECTOR, "a point (x, y, z)")

    def lower(self, lo, s, where):
        pts = "".join(lo.expr(p) + ", " for p in s.points)
        lo.emit(f"rt.poly(_g, ({pts}), {lo.at(s)})")
