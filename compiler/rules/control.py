"""Rules of the statements that order the program: DO, IF, STOP, LOAD, PRIMITIVE, RETURN and END."""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import numbers

from .. import scopes as S
from .. import types as T
from .base import Rule, rule


@rule(A.Do)
class Do(Rule):
    """``DO 10 I = a, b[, step] ... 10 CONTINUE`` (lang/structure.py nests the body)."""

    def check(self, c, s, context):
        if isinstance(s.label, numbers.BadLiteral):
            c.st.out.error(
                s, f"the label {numbers.shown(s.label.text)} is too large", "a label is a small number such as 10"
            )
        bounds = [e for e in (s.start, s.stop, s.step) if e is not None]
        types = [c.t.expr(e) for e in bounds]
        for e, t in zip(bounds, types):
            if t is not None and not T.is_numeric(t):
                c.st.out.error(e, f"a DO loop bound must be a number, not {T.NOUN[t]}")
        loop_type = T.INTEGER if all(t == T.INTEGER for t in types) else T.REAL
        S.assign_type(c.st, s.var, loop_type, s.start)
        c.stmts(s.body, context)

    def lower(self, lo, s, where):
        step = lo.expr(s.step) if s.step is not None else "1"
        start = lo.expr(s.start)
        if lo.var_type(s.var.name) == T.REAL and lo.type_of(s.start) == T.INTEGER:
            start = lo.as_real(s.start, start)  # a REAL variable counts in REALs
        lo.emit(f"for {s.var.name} in rt.do_range({start}, {lo.expr(s.stop)}, {step}, {lo.at(s)}):")
        lo.indent += 1
        lo.hot += 1
        lo.block(s.body, where)
        lo.hot -= 1
        lo.indent -= 1


@rule(A.If)
class If(Rule):
    """``IF cond THEN ... ELSE ...``."""

    def check(self, c, s, context):
        c.t.cond(s.cond)
        c.stmts(s.then, context)
        if s.orelse:
            c.stmts(s.orelse, context)

    def lower(self, lo, s, where):
        lo.emit(f"if {lo.cond(s.cond)}:")
        lo.indent += 1
        lo.block(s.then, where)
        lo.indent -= 1
        if s.orelse:
            lo.emit("else:")
            lo.indent += 1
            lo.block(s.orelse, where)
            lo.indent -= 1


@rule(A.Stop)
class Stop(Rule):
    """``STOP``: the program ends here."""

    def lower(self, lo, s, where):
        # In the main program, hand the variables over so Python users see them.
        if where == "main" and getattr(lo, "scope_types", None) is None:
            lo.emit("rt.stop(_variables())" if lo.chunked else "rt.stop(locals())")
        else:
            lo.emit("rt.stop(None)")


@rule(A.Load)
class Load(Rule):
    """``LOAD 'library'`` (compiler/loads.py binds its names before the walk)."""

    def check(self, c, s, context):
        if c.st.primitive is not None or context != "top" or id(s) not in c.top_loads:
            c.st.out.error(
                s,
                "LOAD belongs at the top level of the program, outside loops, IFs, scenes and primitives",
                "a library is loaded once, before the program runs",
            )

    def lower(self, lo, s, where):
        index, names = lo.c.loads.get(id(s), (None, ()))
        for name in names:
            if name not in lo.c.loaded_primitives:
                lo.emit(f"{name} = _LIB{index}.value(rt, {name!r}, {lo.at(s)})")
        if not any(n not in lo.c.loaded_primitives for n in names):
            lo.emit("pass")


@rule(A.PrimitiveDef)
class PrimitiveDef(Rule):
    """``PRIMITIVE ... END``: checked in its own scope (compiler/check.py), lowered as a function of its own."""


@rule(A.PatternDef)
class PatternDef(Rule):
    """A PRIMITIVE's ``NAME ::= ...`` line: read by compiler/primitives.py, which makes the signature."""


@rule(A.ProgramEnd)
class ProgramEnd(Rule):
    """The program's ``END``."""
