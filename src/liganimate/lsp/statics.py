"""What can be known of a program's values without running it: constants, models' joints, motions' lengths.

The server never executes program text, so hover shows what the text
itself fixes: a number or vector assigned from constants, a model's joints
and extremes where its JOINTs are written with constants, a motion's
length and the joints it drives where its keyframes are. The walk follows
the main program's top-level statements in order; a name assigned inside
a DO loop, an IF or a scene is unknown from there on (its value depends on
the run). Anything this evaluation cannot settle is ``None``, "not known":
never a guess.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from liganimate.lang import ast as A
from liganimate.lang.bindings import assigned, plain_name
from liganimate.lang.visitor import BLOCKS

#: A joint's extremes: three (min, max) pairs, X, Y, Z (an omitted axis is locked at (0, 0)).
Extremes = tuple


@dataclass(frozen=True)
class Joint:
    """One joint of a model: its identifier, the links it joins, its extremes (None where not constant)."""

    ident: int
    parent: str | None  # the primary's link name, if it is a named graphical object
    child: str | None  # the secondary's link name
    extremes: tuple | None


@dataclass(frozen=True)
class ModelValue:
    """A model as far as the text fixes it: its joints by identifier, or None for "not known"."""

    joints: tuple | None  # of Joint, sorted by identifier
    main: str | None = None  # the original main link's name
    # The link FIGURE made main (None: the original one, "?": not known from
    # the text): where a JOINT that takes this model as its secondary holds it.
    current: str | None = None


@dataclass(frozen=True)
class MotionValue:
    """A motion as far as the text fixes it: its length in frames and the joints it drives."""

    length: float | None
    joints: frozenset | None
    root: bool = False  # whether it has a ROOT track


@dataclass(frozen=True)
class Graphic:
    """A graphical object; ``link`` is the name a JOINT gives the link made from it."""

    link: str | None


@dataclass
class Env:
    """The values known after the main program's top-level statements, by NAME."""

    values: dict = field(default_factory=dict)
    loaded: dict = field(default_factory=dict)  # NAME -> value from a library (see libraries.py)


_FUNCTIONS = {
    "SIN": lambda a: math.sin(math.radians(a)),
    "COS": lambda a: math.cos(math.radians(a)),
    "TAN": lambda a: math.tan(math.radians(a)),
    "SQRT": lambda a: math.sqrt(a) if a >= 0 else None,
    "ABS": abs,
    "INT": lambda a: int(a),
    "NINT": lambda a: int(math.floor(abs(a) + 0.5)) * (1 if a >= 0 else -1),
    "REAL": float,
    "FLOAT": float,
}


class Evaluator:
    """Evaluates expressions against an :class:`Env`; every unknown is None."""

    def __init__(self, env: Env) -> None:
        self.env = env

    def value(self, e):
        """The value of expression ``e``, or None."""
        try:
            return self._value(e)
        except (ArithmeticError, TypeError, ValueError):
            return None

    def _value(self, e):
        kind = type(e)
        if kind is A.Num:
            return e.value
        if kind is A.Var:
            return self.env.values.get(e.name)
        if kind is A.Neg:
            v = self._value(e.operand)
            return _neg(v)
        if kind is A.Tuple:
            items = [self._value(i) for i in e.items]
            if len(items) == 3 and all(_is_number(i) for i in items):
                return tuple(float(i) for i in items)
            if len(items) == 2 and all(_is_number(i) for i in items):
                return ("pair", float(items[0]), float(items[1]))
            return None
        if kind is A.BinOp:
            return _binop(e.op, self._value(e.left), self._value(e.right))
        if kind is A.Call:
            f = _FUNCTIONS.get(e.name)
            args = [self._value(a) for a in e.args]
            if f is not None and len(args) == 1 and _is_number(args[0]):
                return f(args[0])
            return None
        if kind is A.PrimCall:
            return Graphic(None)
        if kind is A.Modified:
            return self._modified(e)
        if kind is A.JointExpr:
            return self.joint(e.args)
        if kind is A.Strip:
            return self._strip(e)
        if kind is A.Sync:
            return _sync([self._value(m) for m in e.motions])
        return None

    def _modified(self, e: A.Modified):
        v = self._value(e.target)
        if isinstance(v, Graphic):
            return Graphic(plain_name(e) or v.link)
        for m in e.modifiers:
            arg = self._value(m.arg)
            if isinstance(v, MotionValue) and m.kind == "scale_frames":
                v = replace(v, length=abs(arg) * v.length if _is_number(arg) and v.length is not None else None)
            elif isinstance(v, ModelValue) and v.joints is not None and m.kind == "trans_joints":
                v = _shift(v, arg)
            elif isinstance(v, ModelValue) and v.joints is not None and m.kind == "scale_extremes":
                v = _scale_extremes(v, arg)
        return v

    def joint(self, args: list) -> ModelValue | None:
        """The model ``JOINT id, primary, loc1, secondary, loc2, extremes...`` makes."""
        if len(args) < 6:
            return None
        ident = self._value(args[0])
        primary, secondary = self._value(args[1]), self._value(args[3])
        pairs = [self._value(a) for a in args[5:8]]
        extremes = None
        if all(isinstance(p, tuple) and len(p) == 3 and p[0] == "pair" for p in pairs):
            extremes = tuple((p[1], p[2]) for p in pairs) + ((0.0, 0.0),) * (3 - len(pairs))
        parent = _link(primary, args[1])
        # A secondary model is held by its current main link (thesis 3.3), a primary by its original one.
        child = (
            (secondary.current or secondary.main) if isinstance(secondary, ModelValue) else _link(secondary, args[3])
        )
        joints: list | None = []
        for part in (primary, secondary):
            if isinstance(part, ModelValue):
                joints = None if part.joints is None or joints is None else joints + list(part.joints)
        if not isinstance(ident, int) or joints is None:
            return ModelValue(None, parent)
        joints.append(Joint(ident, parent, child, extremes))
        main = primary.main if isinstance(primary, ModelValue) else parent
        current = primary.current if isinstance(primary, ModelValue) else None  # the result keeps the primary's
        return ModelValue(tuple(sorted(joints, key=lambda j: j.ident)), main, current)

    def _strip(self, e: A.Strip):
        m = self._value(e.motion)
        ids = [self._value(j) for j in e.joints]
        if not isinstance(m, MotionValue):
            return None
        kept = frozenset(i for i in ids if isinstance(i, int)) if all(isinstance(i, int) for i in ids) else None
        if kept is not None and m.joints is not None:
            kept = kept & m.joints
        return MotionValue(m.length, kept, m.root)


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _neg(v):
    if _is_number(v):
        return -v
    if isinstance(v, tuple) and len(v) == 3 and all(_is_number(i) for i in v):
        return tuple(-i for i in v)
    return None


def _binop(op: str, a, b):
    if _is_number(a) and _is_number(b):
        if op == "+":
            return a + b
        if op == "-":
            return a - b
        if op == "*":
            return a * b
        if op == "/":
            return a / b
        if op == "MOD":
            return a - b * math.floor(a / b) if isinstance(a, float) or isinstance(b, float) else a % b
    if isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 3 and op in "+-":
        return tuple(x + y if op == "+" else x - y for x, y in zip(a, b))
    if op == "*" and _is_number(a) and isinstance(b, tuple) and len(b) == 3:
        return tuple(a * y for y in b)
    if op in "*/" and _is_number(b) and isinstance(a, tuple) and len(a) == 3:
        return tuple(x * b if op == "*" else x / b for x in a)
    if op == "+" and isinstance(a, MotionValue) and isinstance(b, MotionValue):
        length = a.length + b.length if a.length is not None and b.length is not None else None
        joints = a.joints | b.joints if a.joints is not None and b.joints is not None else None
        return MotionValue(length, joints, a.root or b.root)
    if op == "*" and isinstance(a, int) and isinstance(b, MotionValue):
        return replace(b, length=a * b.length if b.length is not None else None)
    if op == "+" and isinstance(a, Graphic) and isinstance(b, Graphic):
        return Graphic(None)
    return None


def _sync(motions: list):
    if not motions or not all(isinstance(m, MotionValue) for m in motions):
        return None
    lengths = [m.length for m in motions]
    joint_sets = [m.joints for m in motions]
    length = max(lengths) if all(x is not None for x in lengths) else None
    joints = frozenset().union(*joint_sets) if all(j is not None for j in joint_sets) else None
    return MotionValue(length, joints, any(m.root for m in motions))


def _link(value, node) -> str | None:
    if isinstance(value, ModelValue):
        return value.main
    if isinstance(value, Graphic):
        return plain_name(node) or value.link
    return None


def _shift(v: ModelValue, by) -> ModelValue:
    if not isinstance(by, int):
        return replace(v, joints=None)
    assert v.joints is not None
    return replace(v, joints=tuple(replace(j, ident=j.ident + by) for j in v.joints))


def _scale_extremes(v: ModelValue, r) -> ModelValue:
    assert v.joints is not None
    if not _is_number(r):
        return replace(v, joints=tuple(replace(j, extremes=None) for j in v.joints))
    out = []
    for j in v.joints:
        ext = None if j.extremes is None else tuple(tuple(sorted((lo * r, hi * r))) for lo, hi in j.extremes)
        out.append(replace(j, extremes=ext))
    return replace(v, joints=tuple(out))


class _Statements:
    """The top-level walk: one method per statement that gives a name a value."""

    def __init__(self, env: Env) -> None:
        self.env = env
        self.ev = Evaluator(env)

    def run(self, body: list) -> None:
        for s in body:
            kind = type(s)
            handler = getattr(self, "s_" + kind.__name__, None)
            if handler is not None:
                handler(s)
            elif kind in (A.Do, A.If, A.Scene):
                self._block(s)

    def _block(self, s) -> None:
        """A loop, an IF or a scene: a name it assigns keeps its value only where every pass leaves it so.

        The block's statements are walked on a copy of the values; a name
        whose value they change (or cannot tell) is unknown from here on.
        Walked again until nothing more changes, so a name changed late in
        the block also unsettles what was computed from it earlier.
        """
        names = {n.name for n in assigned(s)}
        if isinstance(s, A.Do):
            self.env.values[s.var.name] = None  # the loop's variable takes many values
        inner = [t for field in BLOCKS[type(s)] for t in (getattr(s, field) or ())]
        for _ in range(4):
            scratch = Env(dict(self.env.values), self.env.loaded)
            _Statements(scratch).run(inner)
            changed = {n for n in names if scratch.values.get(n) != self.env.values.get(n)}
            changed = {n for n in changed if self.env.values.get(n) is not None or n not in self.env.values}
            if not changed:
                return
            for n in changed:
                self.env.values[n] = None  # its value depends on the run

    def set(self, name: str, value) -> None:
        self.env.values[name] = value

    def s_Assign(self, s: A.Assign) -> None:
        self.set(s.target.name, self.ev.value(s.value))

    def s_Decl(self, s: A.Decl) -> None:
        zero = {"INTEGER": 0, "REAL": 0.0, "VECTOR": (0.0, 0.0, 0.0), "MOTION": MotionValue(0.0, frozenset())}
        for n in s.names:
            self.env.values.setdefault(n.name, zero.get(s.type))

    def s_Load(self, s: A.Load) -> None:
        for name, value in self.env.loaded.items():
            self.env.values.setdefault(name, value)

    def s_ModelBlock(self, s: A.ModelBlock) -> None:
        joints: dict | None = {}
        parents, children = set(), set()
        for stmt in s.joints:
            m = self.ev.joint(stmt.args)
            if m is None or m.joints is None or joints is None:
                joints = None
                continue
            for j in m.joints:
                joints[j.ident] = j
                parents.add(j.parent)
                children.add(j.child)
        main = min((x for x in parents - children if x), default=None)
        found = tuple(joints[i] for i in sorted(joints)) if joints is not None else None
        self.set(s.name.name, ModelValue(found, main))

    def s_MotionBlock(self, s: A.MotionBlock) -> None:
        length: float | None = 0.0
        joints: set | None = set()
        root = False
        for mj in s.joints:
            if isinstance(mj.joint, A.RootTrack):
                root = root or not mj.joint.orientation  # ROOT ORIENTATION turns, it carries no path
            else:
                ident = self.ev.value(mj.joint)
                if isinstance(ident, int) and joints is not None:
                    joints.add(ident)
                else:
                    joints = None
            for k in mj.keyframes:
                frame = self.ev.value(k.frame)
                length = max(length, float(frame)) if length is not None and _is_number(frame) else None
        self.set(s.name.name, MotionValue(length, frozenset(joints) if joints is not None else None, root))

    def s_KeyframeAssign(self, s: A.KeyframeAssign) -> None:
        old = self.env.values.get(s.target.name)
        if not isinstance(old, MotionValue):
            old = MotionValue(0.0, frozenset()) if s.target.name not in self.env.values else MotionValue(None, None)
        ident = self.ev.value(s.joint)
        frame = self.ev.value(s.keyframe.frame)
        joints = old.joints | {ident} if old.joints is not None and isinstance(ident, int) else None
        length = max(old.length, float(frame)) if old.length is not None and _is_number(frame) else None
        self.set(s.target.name, MotionValue(length, joints, old.root))

    def s_ReachBlock(self, s: A.ReachBlock) -> None:
        frame = self.ev.value(s.frames)
        model = self.ev.value(s.model)
        joints = None
        if s.joints is not None:
            ids = [self.ev.value(j) for j in s.joints]
            joints = frozenset(ids) if all(isinstance(i, int) for i in ids) else None
        elif isinstance(model, ModelValue) and model.joints is not None:
            joints = frozenset(j.ident for j in model.joints)
        start = self.ev.value(s.start) if s.start is not None else MotionValue(0.0, frozenset())
        if joints is not None and isinstance(start, MotionValue) and start.joints is not None:
            joints = joints | start.joints
        elif s.start is not None:
            joints = None
        self.set(s.name.name, MotionValue(float(frame) if _is_number(frame) else None, joints))
        if s.translate is not None:
            self.set(s.translate.name, None)

    def s_FigureStmt(self, s: A.FigureStmt) -> None:
        """The structure and extremes stay; the main link a later JOINT holds the model by changes."""
        m = self.env.values.get(s.model.name)
        if not isinstance(m, ModelValue):
            return
        current: str | None = "?"
        if s.kind is None:
            current = None
        elif s.kind == "LINK" and s.link is not None:
            current = s.link.name
        elif s.kind == "JOINT" and m.joints is not None:
            ident = self.ev.value(s.joint)
            current = next((j.child for j in m.joints if j.ident == ident and j.child), "?")
        self.set(s.model.name, replace(m, current=current))


def evaluate(program: A.Program, loaded: dict | None = None) -> Env:
    """The values the main program's top-level statements fix, by name.

    Parameters
    ----------
    program : liganimate.lang.ast.Program
        The parsed program.
    loaded : dict, optional
        NAME -> value of the names its LOADs bring (from the libraries' own evaluation).
    """
    env = Env(loaded=dict(loaded or {}))
    _Statements(env).run(program.body)
    return env


def describe(value) -> str | None:
    """A value as hover shows it (Markdown), or None if nothing is known."""
    if value is None:
        return None
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return f"`{_num(value)}`"
    if isinstance(value, tuple) and len(value) == 3 and all(_is_number(v) for v in value):
        return "`(" + ", ".join(_num(v) for v in value) + ")`"
    if isinstance(value, MotionValue):
        return _describe_motion(value)
    if isinstance(value, ModelValue):
        return _describe_model(value)
    if isinstance(value, Graphic):
        return None
    return None


def _num(v) -> str:
    if isinstance(v, int):
        return str(v)
    return f"{v:.6g}"


def _describe_motion(m: MotionValue) -> str:
    length = "not known without running it" if m.length is None else f"{_num(m.length)} frames"
    if m.joints is None:
        joints = "not known without running it"
    else:
        joints = ", ".join(str(j) for j in sorted(m.joints)) or "none"
    text = f"length: {length}  \njoints driven: {joints}"
    if m.root:
        text += "  \nROOT track: the figure travels along a path"
    return text


def _describe_model(m: ModelValue) -> str:
    if m.joints is None:
        return "joints: not known without running it"
    rows = ["| joint | links | X | Y | Z |", "|---:|---|---|---|---|"]
    for j in m.joints:
        links = f"{j.parent or '?'} → {j.child or '?'}"
        if j.extremes is None:
            ext = ["?", "?", "?"]
        else:
            ext = [f"{_num(lo)}° to {_num(hi)}°" if (lo, hi) != (0.0, 0.0) else "locked" for lo, hi in j.extremes]
        rows.append(f"| {j.ident} | {links} | " + " | ".join(ext) + " |")
    head = f"{len(m.joints)} joint{'s' if len(m.joints) != 1 else ''}"
    if m.main:
        head += f", main link {m.main}"
    if m.current and m.current != "?":
        head += f", animated from {m.current}"
    return head + "\n\n" + "\n".join(rows)


__all__ = ["Env", "Evaluator", "Graphic", "Joint", "ModelValue", "MotionValue", "describe", "evaluate"]
