"""Rules of the statements that bind names: declarations and assignments."""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import bindings

from .. import scopes as S
from .. import types as T
from .base import Rule, rule


@rule(A.Decl)
class Decl(Rule):
    """``REAL A, B``: the names get their type; nothing runs (the lowering starts every variable at zero)."""

    def check(self, c, s, context):
        S.declare(c.st, s)


@rule(A.Assign)
class Assign(Rule):
    """``A = e``, ``A := e``, ``A :- e``."""

    def check(self, c, s, context):
        if s.target.name in c.st.signatures:
            c.st.out.error(s.target, f"{s.target.name} is a primitive, so it cannot be assigned")
            return
        if isinstance(s.value, A.JointExpr):
            _check_self_cycle(c, s.target.name, s.value)
        t = c.t.expr(s.value)
        S.assign_type(c.st, s.target, t, s.value)

    def lower(self, lo, s, where):
        target = s.target.name
        value = lo.expr(s.value)
        scope_t = lo.var_type(target)
        if scope_t == T.REAL and lo.type_of(s.value) == T.INTEGER:
            value = lo.as_real(s.value, value)
        if scope_t == T.GRAPHICAL and lo.type_of(s.value) == T.MODEL:
            value = f"rt.as_graphical({value}, {lo.at(s.value)})"
        lo.emit(f"{target} = {value}")


def _check_self_cycle(c, target: str, joint: A.JointExpr) -> None:
    args = joint.args
    if len(args) >= 4:
        p, sec = bindings.plain_name(args[1]), bindings.plain_name(args[3])
        if p == target and sec == target:
            c.st.out.error(
                args[3],
                f"{target} cannot be joined to itself: the model would contain a cycle",
                f"join a copy: make another model from {target} first",
            )
