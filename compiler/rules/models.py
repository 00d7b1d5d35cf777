"""Rules of the statements that make and pose models: STARTMODEL blocks and FIGURE."""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import bindings

from .. import scopes as S
from .. import types as T
from ..expressions import const
from .base import Rule, rule


@rule(A.ModelBlock)
class ModelBlock(Rule):
    """``STARTMODEL name JOINT ... ENDMODEL``."""

    def check(self, c, s, context):
        S.define_as(c.st, s.name, T.MODEL, "{name} is {noun}, not a MODEL")
        ids = {}
        for j in s.joints:
            args = j.args
            c.t.joint_args(args, j, in_block=True)
            ident = const(args[0]) if args else None
            if isinstance(ident, int):
                if ident in ids:
                    c.st.out.error(
                        args[0],
                        f"joint {ident} appears twice in model {s.name.name}",
                        f"the first is at line {ids[ident].line}; joint identifiers must be unique",
                    )
                else:
                    ids[ident] = args[0].pos

    def lower(self, lo, s, where):
        specs = []
        for j in s.joints:
            a = j.args
            pname = a[1].name if isinstance(a[1], A.Var) else None
            sname = bindings.plain_name(a[3])
            exts = ", ".join(lo.expr(e) for e in a[5:])
            specs.append(
                f"_host.JointArgs(jid={lo.expr(a[0])}, primary_name={pname!r}, primary={lo.expr(a[1])}, "
                f"primary_location={lo.expr(a[2])}, secondary={lo.expr(a[3])}, secondary_name={sname!r}, "
                f"secondary_location={lo.expr(a[4])}, extremes=({exts},), at={lo.at(j)}"
                f"{lo.joint_kind(j, ', kind=')})"
            )
        lo.emit(f"{s.name.name} = rt.model_block({s.name.name!r}, (")
        for sp in specs:
            lo.emit(f"    {sp},")
        lo.emit(f"), {lo.at(s)})")


@rule(A.FigureStmt)
class FigureStmt(Rule):
    """``FIGURE model MAIN [LINK name | JOINT n]``: the model with another main link."""

    def check(self, c, s, context):
        c.t.want_var(s.model, T.MODEL)
        if s.kind == "JOINT":
            c.t.want(s.joint, T.INTEGER, "a joint identifier")

    def lower(self, lo, s, where):
        if s.kind is None:
            arg = "None"
        elif s.kind == "LINK":
            arg = repr(s.link.name)
        else:
            arg = lo.expr(s.joint)
        lo.emit(f"{s.model.name} = rt.figure({s.model.name}, {s.kind!r}, {arg}, {lo.at(s)})")
