"""Static checks: names, kinds and types, statement placement.

:func:`check` takes a parsed :class:`~liganimate.lang.ast.Program` and returns
a :class:`Checked` program (the symbol tables and the type of every
expression) or raises :class:`~liganimate.lang.diagnostics.LigDiagnostics`
with every error it found. Checks that depend on values (a FIGURE naming a
link the model lacks, overlapping SYNCHRONIZE...) happen when the program
runs, still before anything is rendered.

Variables need no declaration: the first assignment declares them with the
type of its value, and an implicit number assigned a REAL anywhere is REAL.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from liganimate.lang import ast as A
from liganimate.lang import bindings, keyframe_table, messages, numbers
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics, did_you_mean
from liganimate.lang.visitor import NodeVisitor
from liganimate.lang.vocabulary import DRAW_WITH, MODIFIERS
from liganimate.runtime.ik.solvers import SOLVER_KEYWORDS  # the solver registry, by name only
from liganimate.runtime.motion import interpolation

from . import types as T
from .primitives import builtin_signatures, signature_from_pattern

MAX_ERRORS = 20


@dataclass
class Scope:
    """The variables of the main program or of one PRIMITIVE."""

    name: str
    types: dict = field(default_factory=dict)  # NAME -> type
    declared: dict = field(default_factory=dict)  # NAME -> Pos of declaration (explicit)
    implicit: set = field(default_factory=set)
    params: list = field(default_factory=list)


@dataclass
class SceneInfo:
    """What a scene uses: models to snapshot, models it animates, names it assigns."""

    animated: list = field(default_factory=list)
    models: list = field(default_factory=list)
    assigned: set = field(default_factory=set)


def expr_type(types: dict, e) -> str | None:
    """The type the checker settled for expression ``e`` (``types`` is :attr:`Checked.types`).

    Literals are not in the table: a literal's type follows from its value.
    """
    if type(e) is A.Num:
        return T.INTEGER if isinstance(e.value, int) else T.REAL
    return types.get(id(e))


@dataclass
class Checked:
    """A program that passed the static checks, with what lowering needs."""

    program: A.Program
    main: Scope
    primitives: dict  # NAME -> (PrimitiveDef | None, Signature, Scope | None)
    types: dict  # id(expr node) -> type, literals aside (see expr_type)
    scenes: dict  # id(Scene node) -> SceneInfo
    warnings: list
    libraries: list = field(default_factory=list)  # Library objects, in order of first LOAD
    loads: dict = field(default_factory=dict)  # id(Load node) -> (library index, [names])
    loaded_names: dict = field(default_factory=dict)  # NAME -> library index (values and primitives)
    loaded_primitives: dict = field(default_factory=dict)  # NAME -> library index


class _Stop(Exception):
    pass


class Checker(NodeVisitor):
    """Walks the tree once per scope, twice to settle implicit number types.

    ``_s_<Node>(stmt, context)`` checks a statement, ``_e_<Node>(expr)`` an
    expression and returns its type (see :class:`~liganimate.lang.visitor.NodeVisitor`).
    """

    def __init__(self, program: A.Program, path: str | None = None, stack: tuple = (), opened: dict | None = None):
        self.program = program
        self.opened = {} if opened is None else opened  # see library.open_library
        self.path = path if path is not None else program.filename
        self.stack = stack
        self.libraries: list = []
        self.loads: dict = {}
        self.loaded_names: dict = {}
        self.loaded_primitives: dict = {}
        self.errors: list = []
        self.warnings: list = []
        self.types: dict = {}
        self.scenes: dict = {}
        self.primitives: dict = {}
        self.final = False

    # ------------------------------------------------------------- errors
    def err(self, node_or_pos, message: str, hint: str | None = None) -> None:
        if not self.final:
            return
        pos = node_or_pos if isinstance(node_or_pos, A.Pos) else node_or_pos.pos
        self.errors.append(Diagnostic(self.program.filename, pos, message, hint, source=self.program.source))
        if len(self.errors) >= MAX_ERRORS:
            raise _Stop()

    def warn(self, node, message: str, hint: str | None = None) -> None:
        if self.final:
            self.warnings.append(
                Diagnostic(self.program.filename, node.pos, message, hint, "warning", self.program.source)
            )

    # ---------------------------------------------------------------- run
    def run(self) -> Checked:
        prog = self.program
        sigs = builtin_signatures()
        for p in prog.primitives:
            if p.pattern is None:
                self.final = True
                self.err(
                    p.name,
                    f"PRIMITIVE {p.name.name} has no invocation pattern",
                    f"add a line such as  {p.name.name} ::= '{p.name.name}' 'SIZE' S ;",
                )
                self.final = False
                continue
            sig, problems = signature_from_pattern(p.name.name, p.pattern)
            for node, message in problems:
                self.final = True
                self.err(
                    node,
                    message,
                    "a pattern is a series of 'KEYWORD' VALUE pairs separated by ',' (optional parts in [ ])",
                )
                self.final = False
            sigs[p.name.name] = sig
            self.primitives[p.name.name] = (p, sig, None)
        for name, sig in sigs.items():
            if name not in self.primitives:
                self.primitives[name] = (None, sig, None)
        main = Scope("main program")
        try:
            self._loads(main, sigs)
        except _Stop:
            raise LigDiagnostics(self.errors) from None
        self.signatures = sigs
        try:
            # First passes settle implicit types; the final pass reports.
            for p in prog.primitives:
                if self.primitives.get(p.name.name, (None,))[0] is None:
                    continue  # it has no pattern, which is already reported
                scope = self._primitive_scope(p)
                for _ in range(3):
                    self._check_scope(p.body, scope, primitive=p)
                self.final = True
                self._check_scope(p.body, scope, primitive=p)
                _, psig, _ = self.primitives[p.name.name]
                for default in psig.defaults.values():
                    if isinstance(default, A.Node):
                        self.expr(default)
                self._check_recursion(p)
                self.final = False
                prim, sig, _ = self.primitives[p.name.name]
                for slot in sig.slots:
                    sig.param_types[slot.keyword] = scope.types.get(slot.param, T.REAL)
                self.primitives[p.name.name] = (prim, sig, scope)
            self._check_scope(prog.body, main, primitive=None)
            self._settled_pass(prog.body, main)
        except _Stop:
            pass
        if self.errors:
            raise LigDiagnostics(self.errors)
        return Checked(
            prog,
            main,
            self.primitives,
            self.types,
            self.scenes,
            self.warnings,
            self.libraries,
            self.loads,
            self.loaded_names,
            self.loaded_primitives,
        )

    # -------------------------------------------------------------- LOAD
    def _loads(self, main: Scope, sigs: dict) -> None:
        """Bring in what the top-level LOAD statements name, before anything is checked."""
        from . import library as L

        self.final = True
        defined: dict = {}  # NAME -> Pos where the program defines it before a LOAD
        origin: dict = {}  # NAME -> (library path, Pos of the LOAD)
        self.top_loads = {id(s) for s in self.program.body if isinstance(s, A.Load)}
        for stmt in self.program.body:
            if not isinstance(stmt, A.Load):
                for name in bindings.defined(stmt):
                    defined.setdefault(name.name, name.pos)
                continue
            lib = L.open_library(stmt.library, self.path, self.stack, self.opened)
            if isinstance(lib, Exception):
                message, hint, inner = L.failure(lib, stmt.library)
                self.errors.extend(inner)
                self.err(stmt.library_pos, message, hint)
                continue
            if lib.scenes:
                self.err(
                    stmt.library_pos,
                    f"{lib.display} defines scenes, so it is a program, not a library",
                    "a library holds models, motions and primitives only",
                )
                continue
            index = next((i for i, known in enumerate(self.libraries) if known.path == lib.path), None)
            if index is None:
                index = len(self.libraries)
                self.libraries.append(lib)
            self.warnings.extend(w for w in lib.warnings if w not in self.warnings)
            wanted = stmt.names or [A.Name(stmt.library_pos, n) for n in lib.default_names()]
            taken = []
            for name in wanted:
                n = name.name
                if not lib.offers(n):
                    hint = did_you_mean(n, list(lib.types) + list(lib.signatures))
                    self.err(name, f"{lib.display} has no {n}", hint or "it offers " + ", ".join(lib.default_names()))
                    continue
                if n in origin:
                    where_path, where = origin[n]
                    if where_path == lib.path:
                        self.warn(
                            name,
                            f"{n} is already loaded from {lib.display} at line {where.line}; "
                            "this LOAD of it does nothing",
                        )
                        continue
                    self.err(
                        name,
                        f"{n} is already loaded from another library at line {where.line}",
                        "load it from one library only",
                    )
                    continue
                if n in defined:
                    self.err(
                        name,
                        f"{n} is already defined at line {defined[n].line}, so loading it would overwrite it",
                        "load libraries first, or rename your own definition",
                    )
                    continue
                if n in sigs and n in lib.signatures:
                    self.err(
                        name, f"{n} is already a primitive here, so it cannot be loaded", "rename your own PRIMITIVE"
                    )
                    continue
                if n in lib.signatures:
                    sigs[n] = lib.signatures[n]
                    self.primitives[n] = (None, lib.signatures[n], None)
                    self.loaded_primitives[n] = index
                elif n in sigs:
                    self.err(name, f"{n} is a primitive here, so it cannot also be a loaded variable")
                    continue
                else:
                    main.types[n] = lib.types[n]
                    main.declared[n] = name.pos
                origin[n] = (lib.path, stmt.pos)
                self.loaded_names[n] = index
                taken.append(n)
            self.loads[id(stmt)] = (index, taken)
        self.final = False

    def _settled_pass(self, body: list, main: Scope) -> None:
        """Run reporting passes until one leaves the implicit types as it found them.

        A pass can widen an implicit INTEGER to REAL that an earlier line
        already used; only a pass that changes no type has trustworthy
        reports. Big programs usually settle at once, so this costs one pass
        where a fixed count of passes cost three.
        """
        errors, warnings = len(self.errors), len(self.warnings)
        for attempt in range(4):
            before = dict(main.types)
            self.final = True
            del self.errors[errors:]
            del self.warnings[warnings:]
            try:
                self._check_scope(body, main, primitive=None)
            except _Stop:
                if main.types == before or attempt == 3:
                    raise
                continue
            if main.types == before:
                return

    def _check_recursion(self, p: A.PrimitiveDef) -> None:
        """A PRIMITIVE may not call itself, directly or through others (it would never end)."""
        calls = self.__dict__.get("_call_graph")
        if calls is None:  # once per check: walking every body for every PRIMITIVE was quadratic
            calls = self.__dict__["_call_graph"] = {q.name.name: _prim_calls(q) for q in self.program.primitives}
        seen, stack = set(), [(c, c) for c in calls.get(p.name.name, ())]
        while stack:
            name, first = stack.pop()
            if name == p.name.name:
                node = next((n for n in _prim_call_nodes(p) if n.name == first), p)
                self.err(node, f"PRIMITIVE {p.name.name} calls itself (through {first}), so it would never end")
                return
            if name in seen:
                continue
            seen.add(name)
            stack.extend((c, first) for c in calls.get(name, ()))

    def _primitive_scope(self, p: A.PrimitiveDef) -> Scope:
        scope = Scope(f"PRIMITIVE {p.name.name}")
        _, sig, _ = self.primitives.get(p.name.name, (None, None, None))
        # Parameter types come from the declarations inside the primitive.
        for stmt in p.body:
            if isinstance(stmt, A.Decl):
                for n in stmt.names:
                    scope.types[n.name] = stmt.type
                    scope.declared[n.name] = n.pos
        if sig is not None:
            for param in sig.params:
                scope.params.append(param)
                if param not in scope.types:
                    scope.types[param] = T.REAL
                    scope.implicit.add(param)
        return scope

    # --------------------------------------------------------- statements
    def _check_scope(self, body: list, scope: Scope, primitive) -> None:
        self.scope = scope
        self.primitive = primitive
        self.scene = None
        self._stmts(body, context="top")

    def _stmts(self, stmts: list, context: str) -> None:
        for s in stmts:
            self._stmt(s, context)

    def _stmt(self, s, context: str) -> None:
        self.dispatch("_s_", s)(s, context)

    def _s_PrimitiveDef(self, s, context):
        pass  # checked in its own scope

    def _s_Decl(self, s, context):
        for n in s.names:
            prev = self.scope.types.get(n.name)
            if n.name in self.signatures and self.primitive is None:
                self.err(n, f"{n.name} is a primitive, so it cannot be declared as a variable")
            if n.name in self.scope.declared and self.scope.declared[n.name] != n.pos and prev != s.type:
                where = self.scope.declared[n.name]
                self.err(n, f"{n.name} is already declared as {prev} at line {where.line}")
                continue
            self.scope.types[n.name] = s.type
            self.scope.declared[n.name] = n.pos
            self.scope.implicit.discard(n.name)

    def _assign_type(self, target: A.Name, value_type, value_node) -> None:
        if value_type is None:
            return
        name = target.name
        if value_type == T.PAIR:
            self.err(
                value_node,
                "a pair (min, max) can only be a joint's extremes",
                "a vector has three components: (x, y, z)",
            )
            return
        if value_type == T.BOOL:
            return
        current = self.scope.types.get(name)
        if current is None:
            self.scope.types[name] = value_type
            self.scope.implicit.add(name)
            return
        if name in self.scope.implicit and current == T.INTEGER and value_type == T.REAL:
            self.scope.types[name] = T.REAL
            return
        if current == T.GRAPHICAL and value_type == T.MODEL and self._animated_here(value_node):
            return  # §5.1: after ANIMATE, the model is also a graphical object (its pose this tick)
        if not T.fits(current, value_type):
            hint = (
                "use INT(...) or NINT(...) to make an INTEGER"
                if current == T.INTEGER and value_type == T.REAL
                else None
            )
            self.err(value_node, f"{name} is {T.NOUN[current]}, so it cannot hold {T.NOUN[value_type]}", hint)

    def _animated_here(self, node) -> bool:
        """True if ``node`` names (possibly modified) a model already ANIMATEd in this scene body.

        The thesis, §5.1: after ANIMATE "a graphical object of the name
        'model_name' is available"; it is the model in the current tick's pose.
        """
        while isinstance(node, A.Modified):
            node = node.target
        return self.scene is not None and isinstance(node, A.Var) and node.name in self.scene.animated

    def _s_Assign(self, s, context):
        if s.target.name in self.signatures:
            self.err(s.target, f"{s.target.name} is a primitive, so it cannot be assigned")
            return
        if isinstance(s.value, A.JointExpr):
            self._check_self_cycle(s.target.name, s.value)
        t = self.expr(s.value)
        self._assign_type(s.target, t, s.value)

    def _check_self_cycle(self, target: str, joint: A.JointExpr) -> None:
        args = joint.args
        if len(args) >= 4:
            p, sec = bindings.plain_name(args[1]), bindings.plain_name(args[3])
            if p == target and sec == target:
                self.err(
                    args[3],
                    f"{target} cannot be joined to itself: the model would contain a cycle",
                    f"join a copy: make another model from {target} first",
                )

    def _define_as(self, name: A.Name, t: str, message: str) -> None:
        """Declare ``name`` implicitly with type ``t``, or report ``message`` if it has another type."""
        current = self.scope.types.get(name.name)
        if current is None:
            self.scope.types[name.name] = t
            self.scope.implicit.add(name.name)
        elif current != t:
            self.err(name, message.format(name=name.name, noun=T.NOUN[current]))

    def _s_KeyframeAssign(self, s, context):
        self._define_as(s.target, T.MOTION, "{name} is {noun}; keyframes belong to a MOTION")
        if not isinstance(s.joint, A.RootTrack):
            self._want(s.joint, T.INTEGER, "a joint identifier")
        self._want(s.index, T.INTEGER, "a keyframe number")
        self._keyframe(s.keyframe)

    def _keyframe(self, k: A.Keyframe) -> None:
        self._want_number(k.frame, "a frame number")
        self._position(k.position, k)
        if k.method is not None:
            self._method(k.method)

    def _method(self, name: A.Name) -> None:
        try:
            interpolation.get(name.name)
        except KeyError:
            hint = did_you_mean(name.name, interpolation.names())
            self.err(
                name,
                f"{name.name} is not an interpolation method",
                hint or "the methods are " + ", ".join(interpolation.names()),
            )

    def _position(self, items: list, node) -> None:
        if len(items) == 1:
            self._want(items[0], T.VECTOR, "a position (ax, ay, az)")
        elif len(items) == 3:
            for it in items:
                self._want_number(it, "an angle")
        else:
            self.err(
                items[1] if len(items) > 1 else node,
                f"a position is three angles or one vector, not {len(items)} values",
            )

    def _s_Do(self, s, context):
        if isinstance(s.label, numbers.BadLiteral):
            self.err(s, f"the label {numbers.shown(s.label.text)} is too large", "a label is a small number such as 10")
        types = [self.expr(e) for e in (s.start, s.stop, s.step) if e is not None]
        for e, t in zip([e for e in (s.start, s.stop, s.step) if e is not None], types):
            if t is not None and not T.is_numeric(t):
                self.err(e, f"a DO loop bound must be a number, not {T.NOUN[t]}")
        loop_type = T.INTEGER if all(t == T.INTEGER for t in types) else T.REAL
        self._assign_type(s.var, loop_type, s.start)
        self._stmts(s.body, context)

    def _s_If(self, s, context):
        self.cond(s.cond)
        self._stmts(s.then, context)
        if s.orelse:
            self._stmts(s.orelse, context)

    def _s_ModelBlock(self, s, context):
        self._model_target(s.name)
        ids = {}
        for j in s.joints:
            args = j.args
            self._joint_args(args, j, in_block=True)
            if args and _const(args[0]) is not None and isinstance(args[0].value, int):
                if args[0].value in ids:
                    self.err(
                        args[0],
                        f"joint {args[0].value} appears twice in model {s.name.name}",
                        f"the first is at line {ids[args[0].value].line}; joint identifiers must be unique",
                    )
                else:
                    ids[args[0].value] = args[0].pos

    def _model_target(self, name: A.Name) -> None:
        self._define_as(name, T.MODEL, "{name} is {noun}, not a MODEL")

    def _joint_args(self, args: list, node, in_block: bool) -> None:
        if node.axis is not None:
            self._want(node.axis, T.VECTOR, "an axis (x, y, z)")
        if len(args) < 6 or len(args) > 8:
            self.err(
                node,
                f"JOINT takes an identifier, a primary segment and its location, a secondary segment "
                f"and its location, and one to three extreme pairs: {len(args)} values given",
                "JOINT id, primary, (x, y, z), secondary, (x, y, z), [SLIDE] (min, max), (min, max), (min, max)",
            )
            for a in args:
                self.expr(a)
            return
        self._want(args[0], T.INTEGER, "a joint identifier")
        if in_block and not isinstance(args[1], A.Var):
            self.err(args[1], "inside STARTMODEL the primary segment must be the name of a GRAPHICAL object")
        self._segment(args[1], "primary", in_block)
        self._want(args[2], T.VECTOR, "a location (x, y, z)")
        self._segment(args[3], "secondary", False)
        self._want(args[4], T.VECTOR, "a location (x, y, z)")
        for ext in args[5:]:
            t = self.expr(ext)
            if t is not None and t != T.PAIR:
                self.err(ext, f"joint extremes are pairs (min, max), not {T.NOUN[t]}")
            elif isinstance(ext, A.Tuple) and all(isinstance(i, (A.Num, A.Neg)) for i in ext.items):
                lo, hi = (_const(i) for i in ext.items)
                if lo is not None and hi is not None and lo > hi:
                    self.err(
                        ext,
                        f"these extremes have a minimum ({_fmt(lo)}) above the maximum ({_fmt(hi)})",
                        f"write ({_fmt(hi)}, {_fmt(lo)})",
                    )

    def _segment(self, e, role: str, in_block: bool) -> None:
        if in_block and role == "primary" and isinstance(e, A.Var):
            t = self.scope.types.get(e.name)
            if t is None:
                self._unknown(e)
            elif t != T.GRAPHICAL:
                self.err(
                    e, f"inside STARTMODEL the primary segment must be a GRAPHICAL object; {e.name} is {T.NOUN[t]}"
                )
            self.types[id(e)] = t
            return
        t = self.expr(e)
        if t is not None and t not in (T.GRAPHICAL, T.MODEL):
            self.err(e, f"a {role} segment is a GRAPHICAL object or a MODEL, not {T.NOUN[t]}")

    def _s_MotionBlock(self, s, context):
        self._define_as(s.name, T.MOTION, "{name} is {noun}, not a MOTION")
        seen: dict = {}
        for j in s.joints:
            self._track(j.joint, seen, s.name.name)
            if j.start is not None:
                self._position(j.start, j)
            last = None
            for k in j.keyframes:
                self._keyframe(k)
                c = _const(k.frame)
                if c is not None and last is not None and c < last:
                    self.err(k.frame, messages.keyframes_out_of_order(c, last))
                last = c if c is not None else last
        for t in s.tables:
            for column in t.columns:
                self._track(column, seen, s.name.name)
            try:
                t.data = keyframe_table.read_rows(t.rows, t.rows_pos, len(t.columns))
            except keyframe_table.TableProblem as problem:
                self.err(problem.pos, problem.message, problem.hint)

    def _track(self, joint, seen: dict, motion: str) -> None:
        """One track of a motion block (a JOINT entry, ROOT, or a table's column): its type, and only once."""
        if isinstance(joint, A.RootTrack):
            if "ROOT" in seen:
                self.err(
                    joint,
                    f"ROOT appears twice in motion {motion}",
                    f"the first is at line {seen['ROOT'].line}; a motion has one root track",
                )
            seen["ROOT"] = joint.pos
            return
        self._want(joint, T.INTEGER, "a joint identifier")
        if isinstance(joint, A.Num) and _const(joint) is not None:
            if joint.value in seen:
                self.err(
                    joint,
                    f"joint {joint.value} appears twice in motion {motion}",
                    f"the first is at line {seen[joint.value].line}; put all its keyframes under one JOINT",
                )
            seen[joint.value] = joint.pos

    def _s_ReachBlock(self, s, context):
        if self.primitive is not None:
            self.err(s, "STARTREACH belongs in the main program or a scene, not in a PRIMITIVE")
        self._define_as(s.name, T.MOTION, "{name} is {noun}, not a MOTION")
        self._want(s.model, T.MODEL, "the model of a REACH")
        self._want_number(s.frames, "the frame of the solved pose")
        if s.method is not None:
            self._method(s.method)
        if s.start is not None:
            self._want(s.start, T.MOTION, "the start motion (FROM)")
        for word, places in s.options.items():
            if word != "GOAL" and len(places) > 1:
                self.err(
                    places[1],
                    f"{word} is given twice in this REACH",
                    f"the first is at line {places[0].line}; keep one",
                )
        if s.joints is not None and s.chain is not None:
            self.err(s.options["MOVE CHAIN"][0], "MOVE JOINTS and MOVE CHAIN both choose the movable joints; keep one")
        if not s.goals:
            self.err(
                s, f"REACH {s.name.name} has no GOAL", "add a line such as  GOAL HAND TO (0.5, 1.0, 0.0) WEIGHT 10"
            )
        for g in s.goals:
            if g.joint is not None:
                self._want(g.joint, T.INTEGER, "a joint identifier")
            if g.point is not None:
                self._want(g.point, T.VECTOR, "a point in the link's coordinates (AT)")
            if g.kind == "point":
                self._want(g.target, T.VECTOR, "the goal's world point (TO)")
            elif g.kind == "plane":
                self._want(g.target, T.VECTOR, "a point of the plane (ON PLANE)")
                self._want(g.normal, T.VECTOR, "the plane's normal (NORMAL)")
            else:
                self._want(g.normal, T.VECTOR, "a direction in the link's coordinates (AXIS)")
                self._want(g.target, T.VECTOR, "the world direction (ALONG)")
            if g.weight is not None:
                self._want_number(g.weight, "a goal's weight")
                c = _const(g.weight)
                if c is not None and c < 0:
                    self.err(
                        g.weight,
                        f"a goal's weight cannot be negative ({_fmt(c)})",
                        "only the ratios of weights matter; 0 switches a goal off",
                    )
        for j in s.joints or ():
            self._want(j, T.INTEGER, "a joint identifier")
        if s.chain is not None:
            self._want(s.chain, T.INTEGER, "a chain length")
        if s.translate is not None:
            self._define_as(s.translate, T.VECTOR, "{name} is {noun}; TRANSLATE INTO needs a VECTOR")
        if s.solver is not None and s.solver.name not in SOLVER_KEYWORDS:
            hint = did_you_mean(s.solver.name, list(SOLVER_KEYWORDS))
            self.err(
                s.solver, f"{s.solver.name} is not a solver", hint or "the solvers are " + ", ".join(SOLVER_KEYWORDS)
            )
        if s.tolerance is not None:
            self._want_number(s.tolerance, "the tolerance")
        if s.iterations is not None:
            self._want(s.iterations, T.INTEGER, "the iteration limit")

    def _s_FigureStmt(self, s, context):
        self._want_var(s.model, T.MODEL)
        if s.kind == "JOINT":
            self._want(s.joint, T.INTEGER, "a joint identifier")

    def _s_Scene(self, s, context):
        if self.primitive is not None or context != "top":
            self.err(
                s.start_pos,
                "a scene cannot be defined inside a PRIMITIVE or another scene"
                if self.primitive is not None or context == "scene"
                else "a scene definition belongs at the program's top level, not inside a loop or IF",
            )
        info = SceneInfo()
        self.scenes[id(s)] = info
        outer = self.scene
        self.scene = info
        self._want(s.scene_id, T.INTEGER, "a scene identifier")
        self._stmts(s.init, "scene")
        self._want(s.length, T.INTEGER, "a scene length (a number of ticks)")
        if s.sameframe is not None:
            self._want(s.sameframe, T.INTEGER, "a number of ticks per image")
        self._stmts(s.body, "scene-body")
        self.scene = outer
        info.assigned = {n.name for n in bindings.assigned(s)}
        info.models = sorted(n for n in _names_used(s) if self.scope.types.get(n) == T.MODEL)

    def _s_Animate(self, s, context):
        if context != "scene-body":
            self.err(
                s,
                "ANIMATE belongs between STARTSCENE and ENDSCENE",
                "a scene is INITIALIZE SCENE n ... STARTSCENE LENGTH n ... ENDSCENE",
            )
        self._want_var(s.model, T.MODEL)
        self._want(s.start, T.INTEGER, "a tick number")
        self._want(s.end, T.INTEGER, "a tick number")
        t = self.expr(s.motion)
        if t is not None and t != T.MOTION:
            self.err(s.motion, f"ANIMATE ... USING needs a MOTION, not {T.NOUN[t]}")
        if self.scene is not None and s.model.name not in self.scene.animated:
            self.scene.animated.append(s.model.name)

    def _s_Background(self, s, context):
        if self.primitive is not None:
            self.err(s, "BACKGROUND belongs in a scene, not in a PRIMITIVE")
        for item in s.items:
            t = self.expr(item)
            if t is not None and t not in (T.GRAPHICAL, T.MODEL):
                self.err(item, f"a background is made of GRAPHICAL objects, not {T.NOUN[t]}")
        if context not in ("scene", "scene-body"):
            self.warn(s, "BACKGROUND outside a scene has no effect", "put it between INITIALIZE SCENE and ENDSCENE")

    def _s_Print(self, s, context):
        for item in s.items:
            if item.kind == "value":
                t = self.expr(item.value)
                if t == T.PAIR:
                    self.err(item.value, "a pair can only be a joint's extremes")
            elif item.kind == "table":
                self._want_var(item.value, T.MODEL, what="PRINT $ needs a MODEL")

    def _s_View(self, s, context):
        if s.what == "POINT":
            self._want(s.value, T.VECTOR, "a view point (x, y, z)")
        else:
            self._want_number(s.value, "a view width")

    def _s_Shoot(self, s, context):
        if self.primitive is not None or context.startswith("scene"):
            self.err(s, "SHOOTSCENES belongs outside scenes and primitives")

    def _s_Load(self, s, context):
        if self.primitive is not None or context != "top" or id(s) not in self.top_loads:
            self.err(
                s,
                "LOAD belongs at the top level of the program, outside loops, IFs, scenes and primitives",
                "a library is loaded once, before the program runs",
            )

    def _s_Return(self, s, context):
        if self.primitive is None:
            self.err(s, "RETURN belongs in a PRIMITIVE")

    def _s_DrawWith(self, s, context):
        if self.primitive is None:
            self.err(s, "DRAW belongs in a PRIMITIVE")
        for m in s.modifiers:
            spec = next((d for d in DRAW_WITH if d.kind == m.kind), None)
            if spec is None:
                self.err(m, f"DRAW WITH takes {' or '.join(f'<{d.label} ...>' for d in DRAW_WITH)}")
                self.expr(m.arg)
                continue
            got = self.expr(m.arg)
            if got is not None and got not in spec.accepts:
                self.err(m.arg, f"{spec.label} needs {spec.accepts_noun}, not {T.NOUN[got]}")

    def _s_DrawPoly(self, s, context):
        if self.primitive is None:
            self.err(s, "DRAW belongs in a PRIMITIVE")
        for p in s.points:
            self._want(p, T.VECTOR, "a point (x, y, z)")

    # -------------------------------------------------------- expressions
    def _want(self, e, t: str, what: str) -> None:
        got = self.expr(e)
        if got is None:
            return
        if not T.fits(t, got):
            if t == T.INTEGER and got == T.REAL:
                self.err(e, f"{what} must be an INTEGER; this is a REAL", "use INT(...) or NINT(...)")
            else:
                self.err(e, f"{what} must be {T.NOUN[t]}, not {T.NOUN[got]}")

    def _want_number(self, e, what: str) -> None:
        got = self.expr(e)
        if got is not None and not T.is_numeric(got):
            self.err(e, f"{what} must be a number, not {T.NOUN[got]}")

    def _want_var(self, name: A.Name, t: str, what: str | None = None) -> None:
        got = self.scope.types.get(name.name)
        if got is None:
            self._unknown(name)
        elif got != t:
            self.err(
                name,
                what + f"; {name.name} is {T.NOUN[got]}"
                if what
                else f"{name.name} is {T.NOUN[got]}, but {T.NOUN[t]} is needed here",
            )

    def _unknown(self, node) -> None:
        name = node.name
        hint = did_you_mean(name, list(self.scope.types) + list(self.signatures))
        self.err(node, f"{name} is not defined", hint or "assign it or declare it (REAL, VECTOR, MODEL, ...) first")

    def expr(self, e):
        t = self.dispatch("_e_", e, generic=False)(e)
        # A literal's type is its value's (expr_type): most nodes of a big
        # program are literals, and an entry each cost ~80 bytes a line.
        if type(e) is not A.Num:
            self.types[id(e)] = t
        return t

    def _e_Num(self, e):
        problem = numbers.literal_problem(e.value)
        if problem is not None:
            self.err(e, *problem)
        return T.INTEGER if isinstance(e.value, int) else T.REAL

    def _e_Var(self, e):
        t = self.scope.types.get(e.name)
        if t is None:
            if e.name in self.signatures:
                self.err(e, f"{e.name} is a primitive: call it with its keywords", self.signatures[e.name].usage())
            else:
                self._unknown(e)
        return t

    def _e_Tuple(self, e):
        ts = [self.expr(i) for i in e.items]
        for i, t in zip(e.items, ts):
            if t is not None and not T.is_numeric(t):
                self.err(i, f"a vector's components are numbers, not {T.NOUN[t]}")
        if len(e.items) == 3:
            return T.VECTOR
        if len(e.items) == 2:
            return T.PAIR
        self.err(e, f"a vector has three components, not {len(e.items)}")
        return None

    def _e_Neg(self, e):
        t = self.expr(e.operand)
        if t is None:
            return None
        if t in (T.INTEGER, T.REAL, T.VECTOR):
            return t
        self.err(e, f"cannot negate {T.NOUN[t]}")
        return None

    def _e_BinOp(self, e):
        lt, rt = self.expr(e.left), self.expr(e.right)
        if lt is None or rt is None:
            return None
        op = e.op
        if op in ("+", "-"):
            if T.is_numeric(lt) and T.is_numeric(rt):
                return T.numeric_join(lt, rt)
            if lt == rt == T.VECTOR:
                return T.VECTOR
            if op == "+" and lt == rt == T.GRAPHICAL:
                return T.GRAPHICAL
            if (
                op == "+"
                and {lt, rt} <= {T.GRAPHICAL, T.MODEL}
                and all(t == T.GRAPHICAL or self._animated_here(side) for t, side in ((lt, e.left), (rt, e.right)))
            ):
                return T.GRAPHICAL  # an animated model drawn in this tick's pose
            if op == "+" and lt == rt == T.MOTION:
                return T.MOTION
            if op == "+" and lt == rt == T.MODEL:
                self.err(
                    e,
                    "models are combined with JOINT, not +",
                    "a :- JOINT id, a, (x, y, z), b, (x, y, z), (min, max), ...",
                )
                return None
            self.err(
                e,
                f"cannot {'add' if op == '+' else 'subtract'} {T.NOUN[rt]} {'to' if op == '+' else 'from'} {T.NOUN[lt]}",
            )
            return None
        if op == "*":
            if T.is_numeric(lt) and T.is_numeric(rt):
                return T.numeric_join(lt, rt)
            if (T.is_numeric(lt) and rt == T.VECTOR) or (lt == T.VECTOR and T.is_numeric(rt)):
                return T.VECTOR
            if rt == T.MOTION:
                if lt == T.INTEGER:
                    return T.MOTION
                if lt == T.REAL:
                    self.err(
                        e.left,
                        "a repetition count must be an INTEGER, not a REAL",
                        "write a whole number such as 3 * walk, or use NINT(...)",
                    )
                    return None
            if lt == T.MOTION and T.is_numeric(rt):
                self.err(e, "the repetition count comes first: write n * motion")
                return None
            self.err(e, f"cannot multiply {T.NOUN[lt]} by {T.NOUN[rt]}")
            return None
        if op == "/":
            if T.is_numeric(lt) and T.is_numeric(rt):
                return T.REAL
            if lt == T.VECTOR and T.is_numeric(rt):
                return T.VECTOR
            self.err(e, f"cannot divide {T.NOUN[lt]} by {T.NOUN[rt]}")
            return None
        if op == "MOD":
            if T.is_numeric(lt) and T.is_numeric(rt):
                return T.numeric_join(lt, rt)
            self.err(e, "MOD works on numbers")
            return None
        raise AssertionError(op)

    def _e_Call(self, e):
        spec = T.BUILTINS.get(e.name)
        ts = [self.expr(a) for a in e.args]
        if spec is None:
            hint = did_you_mean(e.name, T.BUILTINS)
            self.err(e, f"{e.name} is not a function", hint or "the functions are " + ", ".join(sorted(T.BUILTINS)))
            return None
        params, result = spec.params, spec.result
        if len(params) != len(e.args):
            self.err(e, f"{e.name} takes {len(params)} argument{'s' if len(params) != 1 else ''}, not {len(e.args)}")
            return None
        for a, t, p in zip(e.args, ts, params):
            if t is None:
                return None
            if p == "N" and not T.is_numeric(t):
                self.err(a, f"{e.name} needs a number here, not {T.NOUN[t]}")
                return None
            if p not in ("N",) and t != p:
                self.err(a, f"{e.name} needs {T.NOUN[p]} here, not {T.NOUN[t]}")
                return None
        if result is None:
            return T.numeric_join(*ts) if len(ts) == 2 else ts[0]
        return result

    def _e_Modified(self, e):
        t = self.expr(e.target)
        if t is None:
            for m in e.modifiers:
                self.expr(m.arg)
            return None
        for m in e.modifiers:
            at = self.expr(m.arg)
            spec = MODIFIERS[m.kind]
            if t not in spec.targets:
                self.err(m, f"{spec.label} applies to {spec.targets_noun}; this is {T.NOUN[t]}")
                continue
            if at is None:
                continue
            if at not in spec.accepts:
                self.err(m.arg, f"{spec.label} needs {spec.accepts_noun}, not {T.NOUN[at]}")
            if spec.nonzero and _const(m.arg) == 0:
                self.err(m.arg, f"{spec.label} 0 would collapse it to nothing")
        return t

    def _e_PrimCall(self, e):
        sig = self.signatures.get(e.name)
        for c in e.clauses:
            self.expr(c.value)
        if sig is None:  # pragma: no cover - the lexer only makes PRIM_NAME for known names
            self.err(e, f"{e.name} is not a primitive")
            return None
        for node, message, hint in sig.match(e):
            self.err(node, message, hint)
        for c in e.clauses:
            ptype = sig.param_types.get(c.keyword)
            t = expr_type(self.types, c.value)
            if t is None or ptype is None:
                continue
            if not T.fits(ptype, t):
                self.err(
                    c.value,
                    f"{e.name} {c.keyword} needs {T.NOUN.get(ptype, ptype)}, not {T.NOUN[t]}",
                    f"put the {e.name} call in parentheses to apply <...> or + to the whole object"
                    if t == T.GRAPHICAL
                    else None,
                )
        return T.GRAPHICAL

    def _e_JointExpr(self, e):
        self._joint_args(e.args, e, in_block=False)
        return T.MODEL

    def _e_Strip(self, e):
        t = self.expr(e.motion)
        if t is not None and t != T.MOTION:
            self.err(e.motion, f"STRIP takes a MOTION first, not {T.NOUN[t]}")
        for j in e.joints:
            self._want(j, T.INTEGER, "a joint identifier")
        return T.MOTION

    def _e_Sync(self, e):
        for m in e.motions:
            t = self.expr(m)
            if t is not None and t != T.MOTION:
                self.err(m, f"SYNCHRONIZE takes MOTIONs, not {T.NOUN[t]}")
        return T.MOTION

    # --------------------------------------------------------- conditions
    def cond(self, c):
        if isinstance(c, A.BoolOp):
            self.cond(c.left)
            self.cond(c.right)
        elif isinstance(c, A.Not):
            self.cond(c.operand)
        else:
            lt, rt = self.expr(c.left), self.expr(c.right)
            if lt is None or rt is None:
                return
            if c.op in ("=", "<>", "/=") and lt == rt == T.VECTOR:
                return
            if not (T.is_numeric(lt) and T.is_numeric(rt)):
                self.err(
                    c,
                    f"cannot compare {T.NOUN[lt]} with {T.NOUN[rt]}",
                    "comparisons work on numbers (and = or <> on vectors)",
                )


def _const(e):
    """The value of a literal (or a negated one), or None; a literal out of range is reported elsewhere."""
    if isinstance(e, A.Neg):
        c = _const(e.operand) if isinstance(e.operand, A.Num) else None
        return -c if c is not None else None
    if isinstance(e, A.Num) and not isinstance(e.value, numbers.BadLiteral):
        return e.value
    return None


def _fmt(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _names_used(node) -> set:
    return {n.name for n in bindings.walk(node) if isinstance(n, (A.Var, A.Name))}


def _prim_call_nodes(node) -> list:
    return [n for n in bindings.walk(node) if isinstance(n, A.PrimCall)]


def _prim_calls(node) -> set:
    return {n.name for n in _prim_call_nodes(node)}


def check(program: A.Program, path: str | None = None, stack: tuple = (), opened: dict | None = None) -> Checked:
    """Check a parsed program; raise LigDiagnostics listing every error found.

    ``path`` is the program's file (relative LOADs start from its folder);
    ``stack`` the libraries being loaded around it; ``opened`` the libraries
    this compile has already opened (see ``library.open_library``).
    """
    return Checker(program, path, stack, opened).run()
