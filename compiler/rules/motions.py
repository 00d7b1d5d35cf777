"""Rules of the statements that make motions: STARTMOTION blocks and keyframe assignments.

Their keyframes share the checks here (frame, position or shape,
interpolation method), which the REACH rule also uses for its method.
"""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import messages
from liganimate.lang.diagnostics import did_you_mean
from liganimate.runtime.motion import interpolation

from .. import scopes as S
from .. import types as T
from ..expressions import const
from .base import Rule, rule


@rule(A.KeyframeAssign)
class KeyframeAssign(Rule):
    """``M[joint, n] = FRAME f POSITION p``."""

    def check(self, c, s, context):
        S.define_as(c.st, s.target, T.MOTION, "{name} is {noun}; keyframes belong to a MOTION")
        if not isinstance(s.joint, A.RootTrack):
            c.t.want(s.joint, T.INTEGER, "a joint identifier")
        c.t.want(s.index, T.INTEGER, "a keyframe number")
        check_keyframe(c, s.keyframe)

    def lower(self, lo, s, where):
        k = s.keyframe
        method = repr(k.method.name) if k.method is not None else "None"
        lo.emit(
            f"{s.target.name} = rt.set_keyframe({s.target.name}, {track(lo, s.joint)}, {lo.expr(s.index)}, "
            f"{lo.expr(k.frame)}, {position(lo, k.position)}, {method}, {lo.at(s)})"
        )


@rule(A.MotionBlock)
class MotionBlock(Rule):
    """``STARTMOTION name JOINT ... ENDMOTION``, with its ROOT, morph tracks and keyframe tables."""

    def check(self, c, s, context):
        S.define_as(c.st, s.name, T.MOTION, "{name} is {noun}, not a MOTION")
        seen: dict = {}
        for j in s.joints:
            _track_joint(c, s, j.joint, seen)
            shape = isinstance(j.joint, A.MorphTrack) and j.joint.kind == "SHAPE"
            if j.start is not None:
                _shape(c, j.start) if shape else _position(c, j.start, j)
            last = None
            for k in j.keyframes:
                check_keyframe(c, k, shape)
                value = const(k.frame)
                if value is not None and last is not None and value < last:
                    c.st.out.error(k.frame, messages.keyframes_out_of_order(value, last))
                last = value if value is not None else last
        if s.tables:
            from liganimate.lang import keyframe_table  # only a TABLE needs it (a cold check imports it otherwise)
        for t in s.tables:
            for column in t.columns:
                _track_joint(c, s, column, seen)
            try:
                t.data = keyframe_table.read_rows(t.rows, t.rows_pos, len(t.columns))
            except keyframe_table.TableProblem as problem:
                c.st.out.error(problem.pos, problem.message, problem.hint)

    def lower(self, lo, s, where):
        lo.emit(f"{s.name.name} = rt.motion_block((")
        for j in s.joints:
            start = position(lo, j.start) if j.start is not None else "None"
            kfs = []
            for k in j.keyframes:
                method = repr(k.method.name) if k.method is not None else "None"
                kfs.append(f"({lo.expr(k.frame)}, {position(lo, k.position)}, {method}, {lo.at(k)})")
            inner = "".join(x + ", " for x in kfs)
            lo.emit(f"    ({track(lo, j.joint)}, {start}, ({inner}), {lo.at(j)}),")
        tables = ""
        for t in s.tables:
            # The rows travel as one string of numbers (lang/keyframe_table.py), read in bulk at run time.
            columns = "".join(track(lo, col) + ", " for col in t.columns)
            from liganimate.lang import keyframe_table

            packed = keyframe_table.pack(t.rows)
            tables += f"_host.TableArgs(({columns}), {packed!r}, {lo.at(t)}), "
            lo.table_spans.append((t.rows_pos.start, t.rows_pos.start + len(t.rows)))
        lo.emit(f"), {lo.at(s)}" + (f", ({tables}))" if tables else ")"))


# ------------------------------------------------------------ keyframes


def check_keyframe(c, k: A.Keyframe, shape: bool = False) -> None:
    """A keyframe's frame, position (or, on a SHAPE track, shape) and interpolation method."""
    c.t.want_number(k.frame, "a frame number")
    _shape(c, k.position) if shape else _position(c, k.position, k)
    if k.method is not None:
        check_method(c, k.method)


def check_method(c, name: A.Name) -> None:
    """An interpolation method's name (runtime/motion/interpolation.py's registry)."""
    try:
        interpolation.get(name.name)
    except KeyError:
        hint = did_you_mean(name.name, interpolation.names())
        c.st.out.error(
            name,
            f"{name.name} is not an interpolation method",
            hint or "the methods are " + ", ".join(interpolation.names()),
        )


def _position(c, items: list, node) -> None:
    if len(items) == 1:
        c.t.want(items[0], T.VECTOR, "a position (ax, ay, az)")
    elif len(items) == 3:
        for it in items:
            c.t.want_number(it, "an angle")
    else:
        c.st.out.error(
            items[1] if len(items) > 1 else node,
            f"a position is three angles or one vector, not {len(items)} values",
        )


def _shape(c, items: list) -> None:
    """A SHAPE track's position: one GRAPHICAL object, the shape the link takes."""
    if len(items) != 1:
        c.st.out.error(items[1], f"a shape is one graphical object, not {len(items)} values")
        return
    c.t.want(items[0], T.GRAPHICAL, "a shape (a GRAPHICAL object)")


def _track_joint(c, s, joint, seen: dict) -> None:
    """The JOINT (or ROOT) a track of a STARTMOTION block drives (an entry or a table's column), each once."""
    if isinstance(joint, A.MorphTrack):
        key = (joint.kind, joint.link)
        if key in seen:
            c.st.out.error(
                joint,
                f"{joint.kind} LINK {joint.link} appears twice in motion {s.name.name}",
                f"the first is at line {seen[key].line}; put all its keyframes under one entry",
            )
        seen[key] = joint.pos
        return
    if isinstance(joint, A.RootTrack):
        word = "ROOT ORIENTATION" if joint.orientation else "ROOT"
        if word in seen:
            c.st.out.error(
                joint,
                f"{word} appears twice in motion {s.name.name}",
                f"the first is at line {seen[word].line}; a motion has one {word} track",
            )
        seen[word] = joint.pos
    else:
        c.t.want(joint, T.INTEGER, "a joint identifier")
    ident = const(joint)
    if isinstance(ident, int):
        if ident in seen:
            c.st.out.error(
                joint,
                f"joint {ident} appears twice in motion {s.name.name}",
                f"the first is at line {seen[ident].line}; put all its keyframes under one JOINT",
            )
        seen[ident] = joint.pos


# ------------------------------------------------------------ lowering


def track(lo, e) -> str:
    """A keyframe's joint identifier: None for the ROOT track, 'ORIENTATION' for ROOT ORIENTATION, ``(kind, link)`` for a morph track."""
    if isinstance(e, A.MorphTrack):
        return repr((e.kind, e.link))
    if isinstance(e, A.RootTrack):
        return repr("ORIENTATION") if e.orientation else "None"
    return lo.expr(e)


def position(lo, items: list) -> str:
    """A keyframe's position: one vector expression, or three angles made a vector."""
    if len(items) == 1:
        return lo.expr(items[0])
    return f"rt.vec({', '.join(lo.expr(i) for i in items)})"
