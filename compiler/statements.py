"""Statement checks: what each statement needs of its parts, and where it may stand.

``_s_<Node>(stmt, context)`` checks one statement; ``context`` says where it
stands: ``"top"`` (the program or a PRIMITIVE body), ``"scene"`` (a scene's
initialisation) or ``"scene-body"`` (between STARTSCENE and ENDSCENE).
Expressions are typed by :class:`~.expressions.ExpressionTyper`, names bound
by the rules of :mod:`.scopes`. A declared statement (``@declared`` in
lang/ast.py) has no method of its own: ``_s_Declared`` checks it from its
declaration.
"""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import bindings, keyframe_table, messages, numbers
from liganimate.lang.diagnostics import did_you_mean
from liganimate.lang.visitor import NodeVisitor
from liganimate.lang.vocabulary import DRAW_WITH, NUMBER
from liganimate.runtime.ik.names import SOLVER_KEYWORDS  # the solvers, by name only
from liganimate.runtime.motion import interpolation

from . import scopes as S
from . import types as T
from .expressions import ExpressionTyper, const, fmt


class StatementChecker(NodeVisitor):
    """Checks the statements of one scope (see :class:`~liganimate.lang.visitor.NodeVisitor`)."""

    def __init__(self, state: S.State, typer: ExpressionTyper, top_loads: set):
        self.st = state
        self.t = typer
        self.top_loads = top_loads  # id() of the LOADs at the program's top level

    def stmts(self, stmts: list, context: str) -> None:
        """Check a list of statements standing in ``context``."""
        for s in stmts:
            self.dispatch("_s_", s)(s, context)

    # ------------------------------------------------------------ names
    def _s_PrimitiveDef(self, s, context):
        pass  # checked in its own scope

    def _s_Decl(self, s, context):
        S.declare(self.st, s)

    def _s_Assign(self, s, context):
        if s.target.name in self.st.signatures:
            self.st.out.error(s.target, f"{s.target.name} is a primitive, so it cannot be assigned")
            return
        if isinstance(s.value, A.JointExpr):
            self._check_self_cycle(s.target.name, s.value)
        t = self.t.expr(s.value)
        S.assign_type(self.st, s.target, t, s.value)

    def _check_self_cycle(self, target: str, joint: A.JointExpr) -> None:
        args = joint.args
        if len(args) >= 4:
            p, sec = bindings.plain_name(args[1]), bindings.plain_name(args[3])
            if p == target and sec == target:
                self.st.out.error(
                    args[3],
                    f"{target} cannot be joined to itself: the model would contain a cycle",
                    f"join a copy: make another model from {target} first",
                )

    def _s_Do(self, s, context):
        if isinstance(s.label, numbers.BadLiteral):
            self.st.out.error(
                s, f"the label {numbers.shown(s.label.text)} is too large", "a label is a small number such as 10"
            )
        bounds = [e for e in (s.start, s.stop, s.step) if e is not None]
        types = [self.t.expr(e) for e in bounds]
        for e, t in zip(bounds, types):
            if t is not None and not T.is_numeric(t):
                self.st.out.error(e, f"a DO loop bound must be a number, not {T.NOUN[t]}")
        loop_type = T.INTEGER if all(t == T.INTEGER for t in types) else T.REAL
        S.assign_type(self.st, s.var, loop_type, s.start)
        self.stmts(s.body, context)

    def _s_If(self, s, context):
        self.t.cond(s.cond)
        self.stmts(s.then, context)
        if s.orelse:
            self.stmts(s.orelse, context)

    # ----------------------------------------------------------- models
    def _s_ModelBlock(self, s, context):
        S.define_as(self.st, s.name, T.MODEL, "{name} is {noun}, not a MODEL")
        ids = {}
        for j in s.joints:
            args = j.args
            self.t.joint_args(args, j, in_block=True)
            ident = const(args[0]) if args else None
            if isinstance(ident, int):
                if ident in ids:
                    self.st.out.error(
                        args[0],
                        f"joint {ident} appears twice in model {s.name.name}",
                        f"the first is at line {ids[ident].line}; joint identifiers must be unique",
                    )
                else:
                    ids[ident] = args[0].pos

    def _s_FigureStmt(self, s, context):
        self.t.want_var(s.model, T.MODEL)
        if s.kind == "JOINT":
            self.t.want(s.joint, T.INTEGER, "a joint identifier")

    # ---------------------------------------------------------- motions
    def _s_KeyframeAssign(self, s, context):
        S.define_as(self.st, s.target, T.MOTION, "{name} is {noun}; keyframes belong to a MOTION")
        if not isinstance(s.joint, A.RootTrack):
            self.t.want(s.joint, T.INTEGER, "a joint identifier")
        self.t.want(s.index, T.INTEGER, "a keyframe number")
        self._keyframe(s.keyframe)

    def _keyframe(self, k: A.Keyframe, shape: bool = False) -> None:
        self.t.want_number(k.frame, "a frame number")
        self._shape(k.position, k) if shape else self._position(k.position, k)
        if k.method is not None:
            self._method(k.method)

    def _method(self, name: A.Name) -> None:
        try:
            interpolation.get(name.name)
        except KeyError:
            hint = did_you_mean(name.name, interpolation.names())
            self.st.out.error(
                name,
                f"{name.name} is not an interpolation method",
                hint or "the methods are " + ", ".join(interpolation.names()),
            )

    def _position(self, items: list, node) -> None:
        if len(items) == 1:
            self.t.want(items[0], T.VECTOR, "a position (ax, ay, az)")
        elif len(items) == 3:
            for it in items:
                self.t.want_number(it, "an angle")
        else:
            self.st.out.error(
                items[1] if len(items) > 1 else node,
                f"a position is three angles or one vector, not {len(items)} values",
            )

    def _shape(self, items: list, node) -> None:
        """A SHAPE track's position: one GRAPHICAL object, the shape the link takes."""
        if len(items) != 1:
            self.st.out.error(items[1], f"a shape is one graphical object, not {len(items)} values")
            return
        self.t.want(items[0], T.GRAPHICAL, "a shape (a GRAPHICAL object)")

    def _s_MotionBlock(self, s, context):
        S.define_as(self.st, s.name, T.MOTION, "{name} is {noun}, not a MOTION")
        seen: dict = {}
        for j in s.joints:
            self._track_joint(s, j.joint, seen)
            shape = isinstance(j.joint, A.MorphTrack) and j.joint.kind == "SHAPE"
            if j.start is not None:
                self._shape(j.start, j) if shape else self._position(j.start, j)
            last = None
            for k in j.keyframes:
                self._keyframe(k, shape)
                c = const(k.frame)
                if c is not None and last is not None and c < last:
                    self.st.out.error(k.frame, messages.keyframes_out_of_order(c, last))
                last = c if c is not None else last
        for t in s.tables:
            for column in t.columns:
                self._track_joint(s, column, seen)
            try:
                t.data = keyframe_table.read_rows(t.rows, t.rows_pos, len(t.columns))
            except keyframe_table.TableProblem as problem:
                self.st.out.error(problem.pos, problem.message, problem.hint)

    def _track_joint(self, s, joint, seen: dict) -> None:
        """The JOINT (or ROOT) a track of a STARTMOTION block drives (an entry or a table's column), each once."""
        if isinstance(joint, A.MorphTrack):
            key = (joint.kind, joint.link)
            if key in seen:
                self.st.out.error(
                    joint,
                    f"{joint.kind} LINK {joint.link} appears twice in motion {s.name.name}",
                    f"the first is at line {seen[key].line}; put all its keyframes under one entry",
                )
            seen[key] = joint.pos
            return
        if isinstance(joint, A.RootTrack):
            word = "ROOT ORIENTATION" if joint.orientation else "ROOT"
            if word in seen:
                self.st.out.error(
                    joint,
                    f"{word} appears twice in motion {s.name.name}",
                    f"the first is at line {seen[word].line}; a motion has one {word} track",
                )
            seen[word] = joint.pos
        else:
            self.t.want(joint, T.INTEGER, "a joint identifier")
        ident = const(joint)
        if isinstance(ident, int):
            if ident in seen:
                self.st.out.error(
                    joint,
                    f"joint {ident} appears twice in motion {s.name.name}",
                    f"the first is at line {seen[ident].line}; put all its keyframes under one JOINT",
                )
            seen[ident] = joint.pos

    # ------------------------------------------------------------- REACH
    def _s_ReachBlock(self, s, context):
        out = self.st.out
        if self.st.primitive is not None:
            out.error(s, "STARTREACH belongs in the main program or a scene, not in a PRIMITIVE")
        S.define_as(self.st, s.name, T.MOTION, "{name} is {noun}, not a MOTION")
        self.t.want(s.model, T.MODEL, "the model of a REACH")
        self.t.want_number(s.frames, "the frame of the solved pose")
        if s.method is not None:
            self._method(s.method)
        if s.start is not None:
            self.t.want(s.start, T.MOTION, "the start motion (FROM)")
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
            self._goal(g)
        self._reach_options(s)

    def _goal(self, g) -> None:
        if g.joint is not None:
            self.t.want(g.joint, T.INTEGER, "a joint identifier")
        if g.point is not None:
            self.t.want(g.point, T.VECTOR, "a point in the link's coordinates (AT)")
        if g.kind == "point":
            self.t.want(g.target, T.VECTOR, "the goal's world point (TO)")
        elif g.kind == "plane":
            self.t.want(g.target, T.VECTOR, "a point of the plane (ON PLANE)")
            self.t.want(g.normal, T.VECTOR, "the plane's normal (NORMAL)")
        else:
            self.t.want(g.normal, T.VECTOR, "a direction in the link's coordinates (AXIS)")
            self.t.want(g.target, T.VECTOR, "the world direction (ALONG)")
        if g.weight is not None:
            self.t.want_number(g.weight, "a goal's weight")
            c = const(g.weight)
            if c is not None and c < 0:
                self.st.out.error(
                    g.weight,
                    f"a goal's weight cannot be negative ({fmt(c)})",
                    "only the ratios of weights matter; 0 switches a goal off",
                )

    def _reach_options(self, s) -> None:
        for j in s.joints or ():
            self.t.want(j, T.INTEGER, "a joint identifier")
        if s.chain is not None:
            self.t.want(s.chain, T.INTEGER, "a chain length")
        if s.translate is not None:
            S.define_as(self.st, s.translate, T.VECTOR, "{name} is {noun}; TRANSLATE INTO needs a VECTOR")
        if s.solver is not None and s.solver.name not in SOLVER_KEYWORDS:
            hint = did_you_mean(s.solver.name, list(SOLVER_KEYWORDS))
            self.st.out.error(
                s.solver, f"{s.solver.name} is not a solver", hint or "the solvers are " + ", ".join(SOLVER_KEYWORDS)
            )
        if s.tolerance is not None:
            self.t.want_number(s.tolerance, "the tolerance")
        if s.iterations is not None:
            self.t.want(s.iterations, T.INTEGER, "the iteration limit")

    # ----------------------------------------------------------- scenes
    def _s_Scene(self, s, context):
        st = self.st
        if st.primitive is not None or context != "top":
            st.out.error(
                s.start_pos,
                "a scene cannot be defined inside a PRIMITIVE or another scene"
                if st.primitive is not None or context == "scene"
                else "a scene definition belongs at the program's top level, not inside a loop or IF",
            )
        info = S.SceneInfo()
        st.scenes[id(s)] = info
        outer = st.scene
        st.scene = info
        self.t.want(s.scene_id, T.INTEGER, "a scene identifier")
        self.stmts(s.init, "scene")
        self.t.want(s.length, T.INTEGER, "a scene length (a number of ticks)")
        if s.sameframe is not None:
            self.t.want(s.sameframe, T.INTEGER, "a number of ticks per image")
        self.stmts(s.body, "scene-body")
        st.scene = outer
        info.assigned = {n.name for n in bindings.assigned(s)}
        info.models = sorted(n for n in S.names_used(s) if st.scope.types.get(n) == T.MODEL)

    def _s_Animate(self, s, context):
        if context != "scene-body":
            self.st.out.error(
                s,
                "ANIMATE belongs between STARTSCENE and ENDSCENE",
                "a scene is INITIALIZE SCENE n ... STARTSCENE LENGTH n ... ENDSCENE",
            )
        self.t.want_var(s.model, T.MODEL)
        self.t.want(s.start, T.INTEGER, "a tick number")
        self.t.want(s.end, T.INTEGER, "a tick number")
        t = self.t.expr(s.motion)
        if t is not None and t != T.MOTION:
            self.st.out.error(s.motion, f"ANIMATE ... USING needs a MOTION, not {T.NOUN[t]}")
        if self.st.scene is not None and s.model.name not in self.st.scene.animated:
            self.st.scene.animated.append(s.model.name)

    def _s_Background(self, s, context):
        if self.st.primitive is not None:
            self.st.out.error(s, "BACKGROUND belongs in a scene, not in a PRIMITIVE")
        for item in s.items:
            t = self.t.expr(item)
            if t is not None and t not in (T.GRAPHICAL, T.MODEL):
                self.st.out.error(item, f"a background is made of GRAPHICAL objects, not {T.NOUN[t]}")
        if context not in ("scene", "scene-body"):
            self.st.out.warning(
                s, "BACKGROUND outside a scene has no effect", "put it between INITIALIZE SCENE and ENDSCENE"
            )

    def _s_Declared(self, s: A.Declared, context: str) -> None:
        """A declared statement (lang/ast.py): where it may stand, and the types of its parts."""
        declaration = A.DECLARED[type(s)]
        place = "primitive" if self.st.primitive is not None else context
        if place not in declaration.places:
            self.st.out.error(s, declaration.misplaced, declaration.hint)
        for name, part in declaration.parts:
            value = getattr(s, name)
            for e in value if part.many else (value,):
                self._part(e, part)

    def _part(self, e, part: A.Part) -> None:
        if part.accepts == NUMBER:
            self.t.want_number(e, part.what)
        elif len(part.accepts) == 1:
            self.t.want(e, part.accepts[0], part.what)
        else:
            got = self.t.expr(e)
            if got is not None and not any(T.fits(t, got) for t in part.accepts):
                nouns = " or ".join(T.NOUN[t] for t in part.accepts)
                self.st.out.error(e, f"{part.what} must be {nouns}, not {T.NOUN[got]}")

    # ------------------------------------------------------------ other
    def _s_Print(self, s, context):
        for item in s.items:
            if item.kind == "value":
                t = self.t.expr(item.value)
                if t == T.PAIR:
                    self.st.out.error(item.value, "a pair can only be a joint's extremes")
            elif item.kind == "table":
                self.t.want_var(item.value, T.MODEL, what="PRINT $ needs a MODEL")

    def _s_Load(self, s, context):
        if self.st.primitive is not None or context != "top" or id(s) not in self.top_loads:
            self.st.out.error(
                s,
                "LOAD belongs at the top level of the program, outside loops, IFs, scenes and primitives",
                "a library is loaded once, before the program runs",
            )

    # -------------------------------------------------------- PRIMITIVE
    def _s_Return(self, s, context):
        if self.st.primitive is None:
            self.st.out.error(s, "RETURN belongs in a PRIMITIVE")

    def _s_DrawWith(self, s, context):
        if self.st.primitive is None:
            self.st.out.error(s, "DRAW belongs in a PRIMITIVE")
        for m in s.modifiers:
            spec = next((d for d in DRAW_WITH if d.kind == m.kind), None)
            if spec is None:
                self.st.out.error(m, f"DRAW WITH takes {' or '.join(f'<{d.label} ...>' for d in DRAW_WITH)}")
                self.t.expr(m.arg)
                continue
            got = self.t.expr(m.arg)
            if got is not None and got not in spec.accepts:
                self.st.out.error(m.arg, f"{spec.label} needs {spec.accepts_noun}, not {T.NOUN[got]}")

    def _s_DrawPoly(self, s, context):
        if self.st.primitive is None:
            self.st.out.error(s, "DRAW belongs in a PRIMITIVE")
        for p in s.points:
            self.t.want(p, T.VECTOR, "a point (x, y, z)")
