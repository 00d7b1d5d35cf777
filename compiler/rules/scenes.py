"""Rules of the statements of scenes: INITIALIZE SCENE blocks, ANIMATE, BACKGROUND and PRINT."""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import bindings
from liganimate.lang.source import spelling

from .. import scopes as S
from .. import types as T
from .base import Rule, rule


@rule(A.Scene)
class Scene(Rule):
    """``INITIALIZE SCENE n ... STARTSCENE LENGTH l [SAMEFRAME k] ... ENDSCENE``."""

    def check(self, c, s, context):
        st = c.st
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
        c.t.want(s.scene_id, T.INTEGER, "a scene identifier")
        c.stmts(s.init, "scene")
        c.t.want(s.length, T.INTEGER, "a scene length (a number of ticks)")
        if s.sameframe is not None:
            c.t.want(s.sameframe, T.INTEGER, "a number of ticks per image")
        c.stmts(s.body, "scene-body")
        st.scene = outer
        info.assigned = {n.name for n in bindings.assigned(s)}
        info.models = sorted(n for n in S.names_used(s) if st.scope.types.get(n) == T.MODEL)

    def lower(self, lo, s, where):
        info = lo.c.scenes[id(s)]
        fn = f"_scene_{lo.tmp}"
        lo.tmp += 1
        snap = info.models
        assigned = info.assigned | set(snap) | set(info.animated)
        lo.emit(f"def {fn}(_snap):")
        lo.indent += 1
        if assigned:
            lo.emit(f"{'global' if lo.chunked else 'nonlocal'} {', '.join(sorted(assigned))}")
        if snap:
            # The scene sees its models as they were where it was defined;
            # the program's own variables get their values back afterwards.
            lo.emit(f"_saved = {_names(snap)}")
            lo.emit(f"{_names(snap)} = _snap")
        lo.block(s.init, "scene")
        self._ticks(lo, s, info.animated)
        if snap:
            lo.emit(f"{_names(snap)} = _saved")
        elif info.animated:
            lo.emit(f"{_names(info.animated)} = _base")
        lo.indent -= 1
        lo.emit(f"rt.define_scene({lo.expr(s.scene_id)}, {fn}, {_names(snap)}, {lo.at(s.start_pos)})")

    @staticmethod
    def _ticks(lo, s: A.Scene, animated: list) -> None:
        """The scene's loop over its ticks, each starting from the animated models' values before it."""
        sameframe = lo.expr(s.sameframe) if s.sameframe is not None else "1"
        if animated:
            lo.emit(f"_base = {_names(animated)}")
        sameframe_at = lo.at(s.sameframe) if s.sameframe is not None else "None"
        lo.emit(f"for _tick in rt.ticks({lo.expr(s.length)}, {sameframe}, {lo.at(s.length)}, {sameframe_at}):")
        lo.indent += 1
        if animated:
            lo.emit(f"{_names(animated)} = _base")
        lo.hot += 1
        lo.block(s.body, "scene-body")
        lo.hot -= 1
        pairs = "".join(f"({n!r}, {n}), " for n in animated)
        lo.emit(f"rt.end_tick(({pairs}))")
        lo.indent -= 1


def _names(names) -> str:
    """A tuple of variables, as a value or an assignment's target: ``(A, B, )``."""
    return "(" + "".join(n + ", " for n in names) + ")"


@rule(A.Animate)
class Animate(Rule):
    """``ANIMATE model FROM a TO b USING motion [REPEAT]``."""

    def check(self, c, s, context):
        if context != "scene-body":
            c.st.out.error(
                s,
                "ANIMATE belongs between STARTSCENE and ENDSCENE",
                "a scene is INITIALIZE SCENE n ... STARTSCENE LENGTH n ... ENDSCENE",
            )
        c.t.want_var(s.model, T.MODEL)
        c.t.want(s.start, T.INTEGER, "a tick number")
        c.t.want(s.end, T.INTEGER, "a tick number")
        t = c.t.expr(s.motion)
        if t is not None and t != T.MOTION:
            c.st.out.error(s.motion, f"ANIMATE ... USING needs a MOTION, not {T.NOUN[t]}")
        if c.st.scene is not None and s.model.name not in c.st.scene.animated:
            c.st.scene.animated.append(s.model.name)

    def lower(self, lo, s, where):
        m = s.model.name
        lo.emit(
            f"{m} = rt.animate({m}, {m!r}, {lo.expr(s.start)}, {lo.expr(s.end)}, {lo.expr(s.motion)}, "
            f"{bool(s.repeat)}, {lo.at(s)})"
        )


@rule(A.Background)
class Background(Rule):
    """``BACKGROUND g, ...``: what a scene draws behind its models."""

    def check(self, c, s, context):
        if c.st.primitive is not None:
            c.st.out.error(s, "BACKGROUND belongs in a scene, not in a PRIMITIVE")
        for item in s.items:
            t = c.t.expr(item)
            if t is not None and t not in (T.GRAPHICAL, T.MODEL):
                c.st.out.error(item, f"a background is made of GRAPHICAL objects, not {T.NOUN[t]}")
        if context not in ("scene", "scene-body"):
            c.st.out.warning(
                s, "BACKGROUND outside a scene has no effect", "put it between INITIALIZE SCENE and ENDSCENE"
            )

    def lower(self, lo, s, where):
        items = "".join(lo.expr(i) + ", " for i in s.items)
        lo.emit(f"rt.background(({items}), {lo.at(s)})")


@rule(A.Print)
class Print(Rule):
    """``PRINT e, $MODEL, 'text'``."""

    def check(self, c, s, context):
        for item in s.items:
            if item.kind == "value":
                t = c.t.expr(item.value)
                if t == T.PAIR:
                    c.st.out.error(item.value, "a pair can only be a joint's extremes")
            elif item.kind == "table":
                c.t.want_var(item.value, T.MODEL, what="PRINT $ needs a MODEL")

    def lower(self, lo, s, where):
        parts = []
        for item in s.items:
            if item.kind == "text":
                parts.append(f"('text', {item.value!r}, None)")
            elif item.kind == "table":
                parts.append(f"('table', {item.value.name}, {item.value.name!r})")
            else:
                t = lo.type_of(item.value)
                label = spelling(lo.c.program.source, item.value.pos)
                kind = None if t is None else str(t)  # the type's name, as program text
                parts.append(f"({kind!r}, {lo.expr(item.value)}, {label!r})")
        lo.emit(f"rt.print_items(({''.join(p + ', ' for p in parts)}), {lo.at(s)})")
