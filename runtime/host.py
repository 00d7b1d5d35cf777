"""The runtime a compiled program calls: host operations, models, motions, scenes.

A lowered module defines ``_main(rt)`` and hands it to :class:`Program`.
Every operation that can fail takes ``at``, an index into the module's table
of source positions, so a failure is reported at the statement that caused
it. A program runs twice when rendered: once in *check* mode, which runs
every statement and every scene tick without drawing, so that nothing is
written unless the whole program is sound; then in *render* mode.
"""

from __future__ import annotations

import dataclasses
import io
import sys
from typing import TYPE_CHECKING, NoReturn

import numpy as np

from liganimate.lang import messages
from liganimate.lang import numbers as N
from liganimate.lang.ast import Pos
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics
from liganimate.lang.node_methods import record
from liganimate.runtime import budgets, limits, printing
from liganimate.runtime.arithmetic import Arithmetic
from liganimate.runtime.errors import LigError
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import tree as F

# Posing (`figure.pose`) and morphing segments (`figure.morphing`) are imported
# where they are first needed, not here: a check, and a program that draws
# nothing, would pay for their set-up at start-up (issue 22's cold start).
from liganimate.runtime.ik.options import ReachOptions  # generated modules build it as _host.ReachOptions
from liganimate.runtime.library import Library  # noqa: F401  (generated modules name it _host.Library)
from liganimate.runtime.motion import algebra as M
from liganimate.runtime.motion import edits as E
from liganimate.runtime.motion.keyframe import Keyframe
from liganimate.runtime.render import framing
from liganimate.runtime.values import EMPTY, ZERO, Canvas, Graphical, Vec, box

if TYPE_CHECKING:
    from liganimate.runtime.render.options import RenderOptions

#: How often a long scene reports its progress while it is checked, in ticks.
PROGRESS_TICKS = 4096


class _StopProgram(Exception):
    """STOP: ends the main program; the variables are handed over before it is raised."""


class Posed:
    """A model as ANIMATE hands it to the host for one tick: a figure, a motion and a frame."""

    __slots__ = ("figure", "frame", "motion", "statement")

    def __init__(self, figure: F.Figure, motion: M.Motion, frame: float, statement: int):
        self.figure = figure
        self.motion = motion
        self.frame = frame
        self.statement = statement

    def with_figure(self, figure: F.Figure) -> Posed:
        """The same pose on a changed figure (placement, main link...)."""
        return Posed(figure, self.motion, self.frame, self.statement)


@record(frozen=True, slots=True)
class TableArgs:
    """A keyframe table of a STARTMOTION block, as the compiled module passes it to :meth:`Runtime.motion_block`.

    ``columns`` are the joint identifiers (None for ROOT), ``numbers`` the
    rows' numbers, blank-separated, deflated and in base 64 (``keyframe_table.pack``;
    checked by the compiler), ``at`` the table's position index.
    """

    columns: tuple
    numbers: str
    at: int


@record(frozen=True, slots=True)
class JointArgs:
    """One JOINT line of a STARTMODEL block, as the compiled module passes it to :meth:`Runtime.model_block`.

    ``primary_name`` and ``secondary_name`` are the variables named there
    (None for an expression); ``extremes`` holds one to three (min, max)
    pairs; ``at`` is the line's position index.
    """

    jid: int
    primary_name: str | None
    primary: object
    primary_location: object
    secondary: object
    secondary_name: str | None
    secondary_location: object
    extremes: tuple
    at: int
    kind: tuple = (False, None)  # (SLIDE written, the AXIS vector or None)


@record(frozen=True, slots=True)
class GoalArgs:
    """One GOAL line of a STARTREACH block, as the compiled module passes it to :meth:`Runtime.reach`.

    ``kind`` is "point", "plane" or "axis"; the goal's link is named by
    ``link`` or by ``joint`` (the joint whose secondary link it is); the
    others are None where the line does not give them. ``at`` is the line's
    position index.
    """

    kind: str
    link: str | None
    joint: int | None
    point: object
    target: object
    normal: object
    weight: float | None
    at: int


class Program:
    """A compiled LIG ANIMATE program, ready to check, execute or render.

    Parameters
    ----------
    name : str
        The source file's name, used in diagnostics.
    positions : tuple of (line, col, end_line, end_col), or str
        Source positions referred to by the ``at`` arguments of the runtime.
        A big program gives them packed, as one string of decimal numbers
        separated by spaces, four per position: CPython compiles a string
        constant at once, a tuple of a million tuples in 24 s and 4 GB.
        The string is decoded when a diagnostic first needs a position.
    main : callable
        ``main(rt) -> dict`` runs the program and returns its variables.
    source : str
        The program text, for the source line shown under a diagnostic.
    """

    def __init__(self, name: str, positions, main, source: str = ""):
        self.name = name
        self._positions = positions
        self.main = main
        self.source = source
        # Scene id -> world box (lo, hi) of what the scene draws, or None when
        # it sets VIEW: gathered by check, read by the renderer's default framing.
        self.framings: dict = {}

    @property
    def positions(self) -> tuple:
        """The source positions, a tuple of (line, col, end_line, end_col), decoded on first use."""
        if isinstance(self._positions, str):
            numbers = iter(map(int, self._positions.split()))
            self._positions = tuple(zip(numbers, numbers, numbers, numbers))
        return self._positions

    def execute(
        self,
        mode: str = "check",
        renderer=None,
        stdout=None,
        echo_print: bool = False,
        progress=None,
        drawing: bool = False,
    ) -> Runtime:
        """Run the program; return the runtime, whose ``variables`` hold its final values.

        In ``"check"`` mode PRINT only checks its items unless ``echo_print``;
        ``drawing`` says that a render follows, so a scene over the frames
        budget is refused by the check, before any folder is made.
        ``progress(scene_id, tick, length)``, if given, is called every
        :data:`PROGRESS_TICKS` ticks of a scene, so a long check is not silent.
        """
        rt = Runtime(self, mode, renderer, stdout)
        rt.echo_print = echo_print
        rt.progress = progress
        rt.drawing = drawing or renderer is not None
        try:
            rt.variables = self.main(rt) or {}
        except _StopProgram:
            pass  # STOP handed over its variables
        # LIG names are upper case; generated ones (rt, _scene_0...) are not program variables.
        rt.variables = {k: rt.finished(v) for k, v in rt.variables.items() if k.isupper() and not k.startswith("_")}
        for scene_id, (_, _, at) in sorted(rt.scenes.items()):
            rt.warn(at, f"scene {scene_id} is defined but never shot", "add SHOOTSCENES after the scenes")

        return rt

    def check(self, stdout=None, progress=None) -> list:
        """Run every statement and every scene tick without drawing; return the warnings.

        Parameters
        ----------
        stdout : text stream, optional
            Where PRINT writes, as the thesis' preprocessor printed its
            tables when it read the program (``liganimate check`` passes
            ``sys.stdout``). By default PRINT output is dropped, so a caller
            that checks and then renders (``run``) prints it only once.

        progress : callable, optional
            ``progress(scene_id, tick, length)``, called every
            :data:`PROGRESS_TICKS` ticks (the command line draws a line from it).

        Returns
        -------
        list of Diagnostic
        """
        if stdout is None:
            return self.execute("check", stdout=io.StringIO(), progress=progress).warnings
        return self.execute("check", stdout=stdout, echo_print=True, progress=progress).warnings

    def render(
        self,
        out_dir: str | None = None,
        checked: bool = False,
        *,
        options: RenderOptions | None = None,
        stdout=None,
        progress=None,
        executor=None,
        **fields,
    ) -> Runtime:
        """Check, then render every scene (see :class:`~.render.frames.Renderer`).

        Parameters
        ----------
        out_dir : str or None
            The frames folder (``RenderOptions.out``); None writes only the movies asked for.
        checked : bool
            The caller has just run :meth:`check` itself (the command line
            does, to show its warnings first), so it is not run twice.
        options : RenderOptions, optional
            What to write and how; ``out_dir`` and ``fields`` replace its values.
        stdout : text stream, optional
            Where PRINT writes (default ``sys.stdout``).
        progress, executor
            As :class:`~.render.frames.Renderer` takes them.
        **fields
            Fields of :class:`~.render.options.RenderOptions` (``size=``, ``gif=``, ``fps=``...).
        """
        import dataclasses

        from liganimate.runtime.render.frames import Renderer
        from liganimate.runtime.render.options import RenderOptions

        base = options if options is not None else RenderOptions()
        if out_dir is not None:
            fields["out"] = out_dir
        try:
            chosen = dataclasses.replace(base, **fields)
        except TypeError:
            unknown = sorted(set(fields) - {f.name for f in dataclasses.fields(RenderOptions)})
            raise TypeError(f"render() got unknown options: {', '.join(unknown)}") from None
        if not checked:
            self.execute("check", stdout=io.StringIO(), drawing=True)
        if progress is None and chosen.progress:
            progress = True  # RenderOptions.progress: shown even when stderr is not a terminal
        renderer = Renderer(chosen, progress=progress, executor=executor)
        try:
            rt = self.execute("render", renderer=renderer, stdout=stdout)
            renderer.finish()
        finally:
            renderer.close()
        return rt


def overflow(program: Program, value, kind, at):
    """Report a + - * value out of range from a compiled module's own check (``_ck``), at ``at``."""
    from liganimate.runtime.arithmetic import overflow_error

    exc = overflow_error(value, kind)
    raise LigDiagnostics(
        [Diagnostic(program.name, Pos(*program.positions[at]), exc.message, exc.hint, source=program.source)]
    )


class Runtime(Arithmetic):
    """The ``rt`` object generated code calls (numbers and functions: :class:`~.arithmetic.Arithmetic`)."""

    ZERO = ZERO
    EMPTY = EMPTY
    NO_MOTION = M.Motion.empty()

    def __init__(self, program: Program, mode: str, renderer=None, stdout=None):
        self.program = program
        self.mode = mode
        self.renderer = renderer
        self.out = stdout if stdout is not None else sys.stdout
        self.progress = None  # see Program.execute
        self.drawing = False  # a render follows (or this is it): the frames budget applies
        self.warnings: list = []
        self._warned: set = set()
        self.scenes: dict = {}
        #: How many scenes SHOOTSCENES has shot (none: the program draws nothing, a library say).
        self.shot = 0
        self.scene = None
        self.view_point = Vec(0.0, 0.0, 10.0)
        self.view_width = 10.0
        self.viewed = False  # a VIEW statement has run (outside a scene)
        self.variables: dict = {}
        self._bind_cache: dict = {}
        self.echo_print = False

    # ---------------------------------------------------------- diagnostics
    def pos(self, at: int) -> Pos:
        return Pos(*self.program.positions[at])

    def fail(self, at: int, message: str, hint: str | None = None) -> NoReturn:
        """Raise a diagnostic at the statement ``at``."""
        raise LigDiagnostics([Diagnostic(self.program.name, self.pos(at), message, hint, source=self.program.source)])

    def warn(self, at: int, message: str, hint: str | None = None) -> None:
        key = (at, message)
        if key in self._warned:
            return
        self._warned.add(key)
        self.warnings.append(Diagnostic(self.program.name, self.pos(at), message, hint, "warning", self.program.source))

    def _guard(self, at, fn, *args):
        """``fn(*args)``, its LigError or NumberError reported at ``at``.

        numpy's floating-point warnings are silenced: the runtime checks its
        results (finite, within the limits) and reports at ``at`` instead of
        letting numpy print.
        """
        try:
            with np.errstate(all="ignore"):
                return fn(*args)
        except (LigError, N.NumberError) as exc:
            self.fail(at, _sentence(exc.message), exc.hint)

    def f_LEN(self, m, at):
        return float(self._motion(m, at).length)

    # ----------------------------------------------------------- graphics
    @staticmethod
    def canvas() -> Canvas:
        return Canvas()

    @staticmethod
    def prim_BOX(rt, CENTRE=None, WIDTH=None, HEIGHT=None, DEPTH=None, LIGHT=None, _at=None) -> Graphical:
        """The built-in BOX primitive (``_at``: the call's position)."""
        return rt._guard(
            _at,
            box,
            CENTRE if CENTRE is not None else ZERO,
            WIDTH or 0.0,
            HEIGHT or 0.0,
            DEPTH or 0.0,
            40.0 if LIGHT is None else LIGHT,
        )

    def poly(self, canvas: Canvas, points, at) -> None:
        """DRAW POLY inside a PRIMITIVE."""
        self._guard(at, canvas.poly, points)

    def superpose(self, a, b, at=None) -> Graphical:
        """``a + b`` of graphical objects (either may be an ANIMATEd model, drawn in its pose)."""
        return self._guard(at, Graphical.__add__, self.as_graphical(a, at), self.as_graphical(b, at))

    def as_graphical(self, value, at) -> Graphical:
        """A graphical object, or a model as a graphical object (thesis §5.1).

        An ANIMATEd model is drawn in its pose of the current tick, at its
        placement; any other model in its neutral pose.
        """
        if value is None:
            self.fail(at, "a graphical object is used before it has a value")
        if isinstance(value, Posed | F.Figure):
            from liganimate.runtime.figure import pose as P

            if isinstance(value, Posed):
                return self._guard(at, P.posed_graphical, value.figure, value.motion, value.frame)
            return self._guard(at, P.posed_graphical, value, None, 0.0)
        return value

    # ----------------------------------------------------------- modifiers
    # One method per modifier of lang/vocabulary.py and type it applies to,
    # named in its entry (Modifier.methods); a compiled <...> list calls them in order.
    def graphical_trans(self, g: Graphical, v, at) -> Graphical:
        """``g <TRANS v>``."""
        return self._transform(g, K.translation(v), at)

    def graphical_rot(self, g: Graphical, degrees, axis, at) -> Graphical:
        """``g <ROT axis degrees>``."""
        return self._transform(g, K.rotation(axis, degrees), at)

    def graphical_scale(self, g: Graphical, k, at) -> Graphical:
        """``g <SCALE k>`` (a number or a vector of factors)."""
        return self._transform(g, self._scaling(k, at), at)

    def graphical_lightness(self, g: Graphical, lightness, at) -> Graphical:
        """``g <LIGHTNESS l>``."""
        return g.with_lightness(lightness)

    def graphical_colour(self, g: Graphical, colour, at) -> Graphical:
        """``g <COLOUR (r, g, b)>`` (an extension): the colour its LIGHTNESS lights."""
        return g.with_colour(colour)

    def _transform(self, g: Graphical, matrix, at) -> Graphical:
        g = self._guard(at, g.transformed, matrix)
        self._guard(at, limits.check_graphical, g, "the transformed object")
        return g

    def _scaling(self, k, at) -> np.ndarray:
        if np.any(np.asarray(k, dtype=np.float64) == 0):
            self.fail(at, "SCALE by 0 would collapse the object to nothing")
        return K.scaling(k)

    def model_trans(self, m, v, at):
        """``m <TRANS v>``: the model placed further by ``v``."""
        return self._refigure(m, at, F.Figure.placed, K.translation(v))

    def model_rot(self, m, degrees, axis, at):
        """``m <ROT axis degrees>``."""
        return self._refigure(m, at, F.Figure.placed, K.rotation(axis, degrees))

    def model_scale(self, m, k, at):
        """``m <SCALE k>``: the whole model, placement and all."""
        return self._refigure(m, at, F.Figure.placed, self._scaling(k, at))

    def model_trans_joints(self, m, n, at):
        """``m <TRANS JOINTS n>``: every joint identifier plus ``n``."""
        return self._refigure(m, at, F.Figure.trans_joints, n)

    def model_scale_model(self, m, k, at):
        """``m <SCALE MODEL k>``: the segments and locations scaled."""
        return self._refigure(m, at, F.Figure.scale_model, k)

    def model_scale_extremes(self, m, r, at):
        """``m <SCALE EXTREMES r>``: every joint's range of motion scaled."""
        return self._refigure(m, at, F.Figure.scale_extremes, r, checked=False)

    def _refigure(self, m, at, change, arg, checked: bool = True):
        """``change(figure, arg)`` of a model, or of an ANIMATEd model's figure (it stays in its pose)."""
        fig = self._guard(at, change, self._model(m, at), arg)
        if checked:  # extremes change no geometry
            self._guard(at, limits.check_figure, fig, "the transformed model")
        return m.with_figure(fig) if isinstance(m, Posed) else fig

    def motion_scale_frames(self, m, r, at) -> M.Motion:
        """``m <SCALE FRAMES r>``: the motion ``r`` times as long."""
        return self._guard(at, M.scale_frames, self._motion(m, at), r)

    def motion_scale_extremes(self, m, r, at) -> M.Motion:
        """``m <SCALE EXTREMES r>``: every angle ``r`` times as large."""
        return self._guard(at, M.scale_extremes, self._motion(m, at), r)

    # -------------------------------------------------------------- models
    def _model(self, m, at, what="a model"):
        if m is None:
            self.fail(at, f"{what} is used before it has a value", "assign it with :- JOINT or STARTMODEL first")
        return m.figure if isinstance(m, Posed) else m

    def _segment(self, value, name, at):
        if isinstance(value, Posed):
            return value.figure
        if isinstance(value, F.Figure):
            return value
        if value is None:
            self.fail(at, f"{name or 'a model'} is used before it has a value")
        return F.Link(name, value)

    def joint(self, jid, primary, loc1, secondary, loc2, extremes, names, at, kind=(False, None)):
        p = self._segment(primary, names[0], at)
        s = self._segment(secondary, names[1], at)
        self._guard(at, budgets.check_model_joints, len(getattr(p, "joints", ())) + len(getattr(s, "joints", ())) + 1)
        fig = self._guard(at, F.join, jid, p, loc1, s, loc2, extremes, _joint_kind(kind))
        return self._guard(at, limits.check_joined, fig, p, s, "the joined model")

    def model_block(self, name, specs, at):
        sizes = (len(getattr(j.secondary, "joints", ())) for j in specs)  # submodels bring their joints
        self._guard(at, budgets.check_model_joints, len(specs) + sum(sizes))
        shapes = {}
        out = []
        for index, j in enumerate(specs):
            shapes[j.primary_name] = j.primary
            sec, sname = j.secondary, j.secondary_name
            if isinstance(sec, (F.Figure, Posed)):
                secondary, sshape = self._segment(sec, sname, j.at), None
            else:
                if sec is None:
                    self.fail(j.at, f"{sname or 'a segment'} is used before it has a value")
                secondary, sshape = (sname if sname is not None else f"<segment of joint {j.jid}>"), sec
            out.append(
                F.JointSpec(
                    j.jid,
                    j.primary_name,
                    j.primary_location,
                    secondary,
                    sshape,
                    j.secondary_location,
                    j.extremes,
                    index,
                    *dataclasses.astuple(_joint_kind(j.kind)),
                )
            )
        try:
            figure, warnings = F.assemble(out, shapes)
        except LigError as exc:
            self.fail(at, _sentence(exc.message), exc.hint)
        for index, sentence in warnings:
            self.warn(specs[index].at, _sentence(sentence))
        return self._guard(at, limits.check_figure, figure, f"the model {name}")

    def figure(self, m, kind, arg, at):
        posed = m if isinstance(m, Posed) else None
        fig = self._model(m, at)
        if kind is None:
            fig = fig.with_original_main()
        elif kind == "JOINT":
            fig = self._guard(at, fig.with_main_joint, arg)
        else:
            try:
                fig, warning = fig.with_main_link(arg)
            except LigError as exc:
                self.fail(at, _sentence(exc.message), exc.hint)
            if warning:
                self.warn(at, _sentence(warning))
        return posed.with_figure(fig) if posed is not None else fig

    # ------------------------------------------------------------- motions
    def finished(self, value):
        """A variable's value as Python code or another program sees it: keyframe edits become a Motion."""
        if isinstance(value, E.KeyframeEdits):
            return self._apply_edits(value, value.at)
        return value

    def for_program(self, program: Program) -> Runtime:
        """This runtime, reporting positions in ``program`` (a library's primitive runs with it)."""
        view = self.__dict__.get("_views", {}).get(id(program))
        if view is None:
            view = object.__new__(Runtime)
            view.__dict__ = dict(self.__dict__)
            view.program = program
            self.__dict__.setdefault("_views", {})[id(program)] = view
        return view

    def _motion(self, m, at) -> M.Motion:
        if isinstance(m, E.KeyframeEdits):
            return self._apply_edits(m, at)
        return m

    def set_keyframe(self, m, joint, k, frame, position, method, at):
        """``m[joint, k] := FRAME ...``: the motion with one more keyframe edit (runtime/motion/edits.py)."""
        return self._guard(at, E.set_keyframe, m, joint, k, frame, position, method, at)

    def _apply_edits(self, m: E.KeyframeEdits, at) -> M.Motion:
        try:
            with np.errstate(all="ignore"):
                return E.apply(m)
        except E.EditError as exc:
            self.fail(at if exc.at is None else exc.at, _sentence(exc.message), exc.hint)
        except (LigError, N.NumberError) as exc:
            self.fail(at, _sentence(exc.message), exc.hint)

    # ------------------------------------------------------------- REACH
    def reach(self, model, start, frames, method, goals, options: ReachOptions, at):
        """A STARTREACH block: (the motion to the solved pose, the solved translation).

        The arguments are the block's, as the lowering writes them; ``options``
        (MOVE, TRANSLATE INTO, the solver and its settings) is the one
        :class:`ReachOptions` the generated module built, passed on unchanged.
        """
        from liganimate.runtime.ik import language as RL

        fig = self._model(model, at, "the model of a REACH")
        start_motion = self._motion(start, at) if start is not None else None
        self._guard(at, RL.check_frames, frames)
        built = []
        for g in goals:
            # One call per GOAL line, so that an unknown or ambiguous link is reported at its own line.
            goal, ambiguous = self._guard(
                g.at, RL.language_goal, fig, g.kind, g.link, g.joint, g.point, g.target, g.normal, g.weight
            )
            if ambiguous:
                self.warn(g.at, _sentence(ambiguous))
            built.append(goal)
        block = self._guard(
            at,
            lambda: RL.reach_block(fig, built, frames, method, start=start_motion, options=options),
        )
        for w in block.warnings:
            self.warn(at if w.goal is None else goals[w.goal].at, _sentence(w.sentence), w.hint)
        return block.motion, Vec(*block.translation)

    def motion_block(self, joints, at, tables=()):
        spec = {}
        morphs = []  # SCALE and SHAPE entries: (kind, link, start, keyframes, at)
        for joint, start, kfs, jat in joints:
            if isinstance(joint, tuple):
                self._frames_in_order(kfs)
                morphs.append((*joint, start, kfs, jat))
                continue
            if joint in spec:
                self.fail(jat, f"{_track_label(joint)} appears twice in this motion")
            for _frame, pos, _method, kat in kfs:
                self._guard(kat, E.check_angles, pos, joint is None)
            self._frames_in_order(kfs)
            if start is not None:
                self._guard(jat, E.check_angles, start, joint is None)
            spec[joint] = (
                tuple(start) if start is not None else (0.0, 0.0, 0.0),
                [Keyframe(f, tuple(p), meth or "LINEAR") for f, p, meth, _ in kfs],
            )
        # The ROOT entries (lower.py writes their joints as None and M.ORIENTATION).
        root, turn = spec.pop(None, None), spec.pop(M.ORIENTATION, None)
        given = {j for j, track in ((None, root), (M.ORIENTATION, turn)) if track is not None}
        arrays = self._table_tracks(tables, spec, given)
        motion = self._guard(at, lambda: M.Motion.from_tracks(spec, root=root, arrays=arrays, turn=turn))
        if not morphs:
            return motion
        from liganimate.runtime.figure import morphing as MO

        return self._guard(at, lambda: motion.with_morphs(MO.channels(morphs, motion.length, self.fail)))

    def _frames_in_order(self, kfs) -> None:
        """A track's keyframe frames: each within the limits, in order, and a step or the least gap apart."""
        last = 0
        for frame, _pos, _method, kat in kfs:
            self._guard(kat, E.check_frame, frame)
            if frame < last:
                self.fail(kat, messages.keyframes_out_of_order(frame, last))
            if 0 < frame - last < N.MIN_FRAME_GAP:
                self.fail(kat, messages.keyframes_too_close(frame, last), messages.GAP_HINT)
            last = frame

    def _table_tracks(self, tables, spec: dict, given: set) -> dict:
        """Each table column as ``(start, frames, values)``: its first row is the start, the others keyframes."""
        arrays: dict = {}
        for t in tables:
            from liganimate.lang import keyframe_table  # here: only a TABLE needs it

            width = 1 + 3 * len(t.columns)
            data = keyframe_table.unpack(t.numbers)
            if data is None or data.size == 0 or data.size % width:
                self.fail(t.at, "this keyframe table's rows do not have one frame and three numbers per column")
            data = data.reshape(-1, width)
            for n, joint in enumerate(t.columns):
                if joint in spec or joint in arrays or joint in given:
                    self.fail(t.at, f"{_track_label(joint)} appears twice in this motion")
                cols = data[:, 1 + 3 * n : 4 + 3 * n]
                arrays[joint] = (cols[0], data[1:, 0], cols[1:])
        return arrays

    def concat(self, a, b, at):
        return self._guard(at, M.concat, self._motion(a, at), self._motion(b, at))

    def repeat(self, n, m, at):
        if n < 0:
            self.fail(at, f"a repetition count cannot be negative ({n})")
        return self._guard(at, M.repeat, n, self._motion(m, at))

    def strip(self, m, joints, at):
        return self._guard(at, M.strip, self._motion(m, at), joints)

    def synchronize(self, motions, at):
        return self._guard(at, M.synchronize, *[self._motion(m, at) for m in motions])

    # -------------------------------------------------------------- scenes
    def set_view_point(self, point, at):
        """VIEW POINT = point: where the camera stands, in this scene or for the scenes to come."""
        # The limits guarantee that the renderer's camera accepts the view
        # and projects everything drawn to finite pixel coordinates.
        self._view("view_point", Vec(*self._guard(at, limits.check_view_point, point)))

    def set_view_width(self, width, at):
        """VIEW WIDTH = width: how wide the camera sees, in this scene or for the scenes to come."""
        self._view("view_width", self._guard(at, limits.check_view_width, width))

    def _view(self, target, value):
        if self.scene is not None:
            setattr(self.scene, target, value)
            self.scene.viewed = True
        else:
            setattr(self, target, value)
            self.viewed = True

    def define_scene(self, scene_id, fn, snapshot, at):
        if scene_id in self.scenes:
            self.fail(at, f"scene {scene_id} is already defined at line {self.pos(self.scenes[scene_id][2]).line}")
        self.scenes[scene_id] = (fn, snapshot, at)

    def shoot(self, at):
        """SHOOTSCENES: run every scene recorded since the last SHOOTSCENES, in identifier order, then forget them."""
        self._shoot(sorted(self.scenes))

    def shoot_range(self, first, last, at):
        """SHOOTSCENES FROM first TO last: shoot only the recorded scenes with those identifiers; forget them all.

        A film made piece by piece can be previewed a few scenes at a time
        without editing out the others.
        """
        if first > last:
            self.fail(at, f"SHOOTSCENES FROM {first} TO {last} names no scenes: {first} is after {last}")
        chosen = [scene_id for scene_id in sorted(self.scenes) if first <= scene_id <= last]
        if not chosen:
            recorded = ", ".join(str(i) for i in sorted(self.scenes)) or "none"
            self.warn(at, f"no scene from {first} to {last} has been recorded (recorded: {recorded})")
        self._shoot(chosen)

    def _shoot(self, chosen):
        for scene_id in chosen:
            fn, snapshot, sat = self.scenes[scene_id]
            self.scene = SceneState(scene_id, self.view_point, self.view_width, sat)
            self.shot += 1
            self.scene.viewed = self.viewed
            if self.renderer is not None:
                self.renderer.begin_scene(scene_id)
            try:
                fn(snapshot)
                if self.mode == "check":
                    self.program.framings[scene_id] = None if self.scene.viewed else self.scene.extent
            finally:
                if self.renderer is not None:
                    self.renderer.end_scene()
                self.scene = None
        self.scenes = {}

    def ticks(self, length, sameframe, at, sameframe_at=None):
        """The ticks of the scene being shot (``at``: its LENGTH, ``sameframe_at``: its SAMEFRAME)."""
        if length < 0:
            self.fail(at, f"a scene's LENGTH cannot be negative ({length})")
        if length > N.MAX_SCENE_LENGTH:
            self.fail(
                at,
                f"a scene of {length:,} ticks is longer than the longest allowed, {N.MAX_SCENE_LENGTH:,}",
                "that is about 4.6 days at 24 frames a second; split the action into several scenes",
            )
        if sameframe < 1:
            self.fail(at if sameframe_at is None else sameframe_at, f"SAMEFRAME must be at least 1, not {sameframe}")
        state = self.scene
        state.length, state.sameframe = length, sameframe
        if self.drawing:
            self._guard(at, budgets.check_frames, length, sameframe)
        progress = self.progress
        mark = (0, 0)  # (tick, work done) at the last estimate
        for t in range(length):
            state.tick = t
            if t == 1 or not t % PROGRESS_TICKS:
                if t:  # estimate the scene's work from the ticks run so far (runtime/budgets.py)
                    done = state.posed + t
                    rate = (done - mark[1]) / (t - mark[0])
                    self._guard(at, budgets.check_joint_ticks, length, t, done, rate)
                    mark = (t, done)
                if progress is not None and not t % PROGRESS_TICKS:  # t == 1 only estimates
                    progress(state.id, t, length)
            yield t
        if progress is not None and length >= PROGRESS_TICKS:
            progress(state.id, length, length)

    def animate(self, m, name, start, end, motion, repeat, at):
        fig = self._model(m, at, name)
        motion = self._motion(motion, at)
        t = self.scene.tick
        self.scene.posed += fig.n_joints  # the scene's work (runtime/budgets.py)
        if t < start or t > end:
            return m  # another ANIMATE of this model may cover this tick
        frame = float(t - start)
        if repeat:
            length = motion.length
            if length > 0:
                # Played as n * motion (n copies cover the whole range), not as
                # frame MOD length: the poses are the same, but a cycle then keeps
                # its velocity across each junction instead of restarting from rest.
                copies = int((end - start) // length) + 1
                motion = self._guard(at, M.repeat, copies, motion)
            else:
                frame = 0.0
        if self.mode == "check":
            self._bind(fig, motion, at)
        return Posed(fig, motion, frame, at)

    def _bind(self, fig: F.Figure, motion: M.Motion, at):
        """Check (once per pair) that a motion suits a model; warn about joints it lacks."""
        # (A motion that morphs segments meets the links too: the same joints may carry other shapes.)
        key = (id(fig.joints), id(motion), id(fig.links) if motion.morphs is not None else None)
        if key in self._bind_cache:
            return
        self._bind_cache[key] = (fig, motion)
        missing = [j for j in motion.joints if j not in set(fig.joint_ids)]
        if missing:
            self.warn(
                at,
                f"the motion drives joint{'s' if len(missing) > 1 else ''} "
                f"{', '.join(map(str, missing))}, which the model does not have",
            )
        if motion.morphs is not None:
            from liganimate.runtime.figure import morphing as MO

            self._guard(at, MO.bind, fig, motion.morphs)
        if fig.slides.any():
            from liganimate.runtime.figure import pose as P

            problem = P.slide_out_of_range(fig, motion)
            if problem is not None:
                self.fail(at, *problem)

    def background(self, items, at):
        out = []
        for item in items:
            if item is None:
                self.fail(at, "a background object is used before it has a value")
            out.append(self.as_graphical(item, at) if isinstance(item, Posed) else item)
        if self.scene is not None:
            self.scene.background = out

    def end_tick(self, pairs):
        state = self.scene
        for name, value in pairs:
            if isinstance(value, Posed):
                state.drawn.append((name, _rooted(value)))
        if self.mode == "check" and not state.viewed and framing.sampled(state.tick, state.length):
            state.measure()
        if self.renderer is not None:
            self.renderer.add_tick(state, self)
        state.drawn = []

    def stop(self, variables=None):
        if variables is not None:
            self.variables = variables
        raise _StopProgram()

    # --------------------------------------------------------------- PRINT
    def print_items(self, items, at):
        if self.mode == "check" and not self.echo_print:
            # Nothing is written, but whatever could fail when it is (a model
            # without a value, a motion whose keyframes do not fit) fails now.
            for kind, value, label in items:
                if kind in ("MODEL", "table"):
                    self._model(value, at, label)
                elif kind == "MOTION":
                    self._motion(value, at)
            return
        for kind, value, label in items:
            self.out.write(self._print_one(kind, value, label, at) + "\n")

    def _print_one(self, kind, value, label, at) -> str:
        if kind == "text":
            return value
        if kind == "MODEL":
            return printing.model_tree(self._model(value, at, label), label)
        if kind == "table":
            fig = self._model(value, at, label)
            if isinstance(value, Posed):
                return printing.model_table(fig, label, value.motion, value.frame)
            return printing.model_table(fig, label)
        if kind == "MOTION":
            return printing.motion_listing(self._motion(value, at), label)
        return printing.value_line(kind, value, label)


class SceneState:
    """One scene while it is being shot: its camera, background and this tick's drawings."""

    def __init__(self, scene_id, view_point, view_width, at):
        self.id = scene_id
        self.view_point = view_point
        self.view_width = view_width
        self.background: list = []
        self.drawn: list = []
        self.tick = 0
        self.length = 0
        self.sameframe = 1
        self.at = at
        self.viewed = False  # a VIEW statement has run before or in the scene
        self.extent = None  # world box of what is drawn at the ticks measured
        self.posed = 0  # joints its ANIMATE statements have posed so far

    def measure(self) -> None:
        """Add this tick's drawing (and the background) to :attr:`extent`, for the default framing."""
        from liganimate.runtime.figure import pose as P

        for item in self.background:
            tris = item.triangles if isinstance(item, Graphical) else P.static_triangles(item)[0]
            self.extent = framing.union(self.extent, framing.extent(tris))
        for _name, posed in self.drawn:
            tris = P.posed_graphical(posed.figure, posed.motion, posed.frame).triangles
            self.extent = framing.union(self.extent, framing.extent(tris))


def _rooted(posed: Posed) -> Posed:
    """A drawn pose with its motion's root track folded into the placement (world = placement @ Trans(root) @ Rot @ pose)."""
    if posed.motion.root is None and posed.motion.turn is None:
        return posed
    from liganimate.runtime.figure import pose as P

    fig = posed.figure
    placed = P.rooted_placements(np.asarray(fig.placement)[None], posed.motion, np.array([posed.frame]))[0]
    return posed.with_figure(fig.with_placement(placed))


def _track_label(joint) -> str:
    """How a diagnostic names a motion's track: ``joint 3``, ``ROOT``, ``ROOT ORIENTATION``."""
    if joint is None:
        return "ROOT"
    return "ROOT ORIENTATION" if joint == M.ORIENTATION else f"joint {joint}"


def _joint_kind(kind) -> F.JointKind:
    """The runtime's JointKind from the ``(slide, axis)`` pair a compiled JOINT passes."""
    slide, axis = kind
    return F.JointKind(bool(slide), None if axis is None else tuple(float(x) for x in axis))


def _sentence(message: str) -> str:
    """Runtime libraries write sentences; diagnostics print them without the final period (messages.sentence)."""
    from liganimate.lang.messages import sentence

    return sentence(message)
