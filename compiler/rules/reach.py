"""The rule of STARTREACH blocks: goal-directed positioning (runtime/ik/)."""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang.diagnostics import did_you_mean
from liganimate.runtime.ik.names import DEFAULT_SOLVER, SOLVER_KEYWORDS  # the solvers, by name only

from .. import scopes as S
from .. import types as T
from ..expressions import const, fmt
from .base import Rule, rule
from .motions import check_method


@rule(A.ReachBlock)
class ReachBlock(Rule):
    """``STARTREACH name MODEL m FRAME f ... GOAL ... ENDREACH``: a MOTION to the pose that best meets the goals."""

    def check(self, c, s, context):
        out = c.st.out
        if c.st.primitive is not None:
            out.error(s, "STARTREACH belongs in the main program or a scene, not in a PRIMITIVE")
        S.define_as(c.st, s.name, T.MOTION, "{name} is {noun}, not a MOTION")
        c.t.want(s.model, T.MODEL, "the model of a REACH")
        c.t.want_number(s.frames, "the frame of the solved pose")
        if s.method is not None:
            check_method(c, s.method)
        if s.start is not None:
            c.t.want(s.start, T.MOTION, "the start motion (FROM)")
        for word, places in s.options.items():
            if word != "GOAL" and len(places) > 1:
                out.error(
                    places[1],
                    f"{word} is given twice in this REACH",
                    f"the first is at line {places[0].line}; keep one",
                )
        if s.joints is not None and s.chain is not None:
            out.error(s.options["MOVE CHAIN"][0], "MOVE JOINTS and MOVE CHAIN both choose the movable joints; keep one")
        if not s.goals:
            out.error(
                s, f"REACH {s.name.name} has no GOAL", "add a line such as GOAL HAND TO (0.5, 1.0, 0.0) WEIGHT 10"
            )
        for g in s.goals:
            _goal(c, g)
        _options(c, s)

    def lower(self, lo, s, where):
        def opt(e):
            return "None" if e is None else lo.expr(e)

        goals = []
        for g in s.goals:
            link = repr(g.link.name) if g.link is not None else "None"
            goals.append(
                f"_host.GoalArgs(kind={g.kind!r}, link={link}, joint={opt(g.joint)}, point={opt(g.point)}, "
                f"target={opt(g.target)}, normal={opt(g.normal)}, weight={opt(g.weight)}, at={lo.at(g)})"
            )
        if s.joints is not None:
            movable = "(" + "".join(lo.expr(j) + ", " for j in s.joints) + ")"  # joint ids: a tuple
        elif s.chain is not None:
            movable = lo.expr(s.chain)  # a chain length: an INTEGER
        else:
            movable = "None"
        solver = SOLVER_KEYWORDS[s.solver.name] if s.solver is not None else DEFAULT_SOLVER
        method = repr(s.method.name) if s.method is not None else "'LINEAR'"
        target = f"{s.name.name}, {s.translate.name}" if s.translate is not None else f"{s.name.name}, _"
        lo.emit(f"{target} = rt.reach({lo.expr(s.model)}, {opt(s.start)}, {lo.expr(s.frames)}, {method}, (")
        for g in goals:
            lo.emit(f"    {g},")
        # The block's options, one frozen ReachOptions (runtime/ik/options.py) that every IK layer passes on.
        lo.emit(
            f"), _host.ReachOptions(movable={movable}, translate={s.translate is not None!r}, solver={solver!r}, "
            f"tolerance={opt(s.tolerance)}, max_iterations={opt(s.iterations)}), {lo.at(s)})"
        )


def _goal(c, g: A.Goal) -> None:
    if g.joint is not None:
        c.t.want(g.joint, T.INTEGER, "a joint identifier")
    if g.point is not None:
        c.t.want(g.point, T.VECTOR, "a point in the link's coordinates (AT)")
    if g.kind == "point":
        c.t.want(g.target, T.VECTOR, "the goal's world point (TO)")
    elif g.kind == "plane":
        c.t.want(g.target, T.VECTOR, "a point of the plane (ON PLANE)")
        c.t.want(g.normal, T.VECTOR, "the plane's normal (NORMAL)")
    else:
        c.t.want(g.normal, T.VECTOR, "a direction in the link's coordinates (AXIS)")
        c.t.want(g.target, T.VECTOR, "the world direction (ALONG)")
    if g.weight is not None:
        c.t.want_number(g.weight, "a goal's weight")
        value = const(g.weight)
        if value is not None and value < 0:
            c.st.out.error(
                g.weight,
                f"a goal's weight cannot be negative ({fmt(value)})",
                "only the ratios of weights matter; 0 switches a goal off",
            )


def _options(c, s: A.ReachBlock) -> None:
    for j in s.joints or ():
        c.t.want(j, T.INTEGER, "a joint identifier")
    if s.chain is not None:
        c.t.want(s.chain, T.INTEGER, "a chain length")
    if s.translate is not None:
        S.define_as(c.st, s.translate, T.VECTOR, "{name} is {noun}; TRANSLATE INTO needs a VECTOR")
    if s.solver is not None and s.solver.name not in SOLVER_KEYWORDS:
        hint = did_you_mean(s.solver.name, list(SOLVER_KEYWORDS))
        c.st.out.error(
            s.solver, f"{s.solver.name} is not a solver", hint or "the solvers are " + ", ".join(SOLVER_KEYWORDS)
        )
    if s.tolerance is not None:
        c.t.want_number(s.tolerance, "the tolerance")
    if s.iterations is not None:
        c.t.want(s.iterations, T.INTEGER, "the iteration limit")
