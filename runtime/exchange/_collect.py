"""Running a program's scenes without drawing them: what every tick shows, gathered for export.

:class:`SceneCollector` stands where the renderer stands (``Program.execute``
calls ``begin_scene``, ``add_tick`` and ``end_scene`` on it), so a program
runs exactly as ``liganimate run`` runs it, in one check-mode pass, and
nothing is rasterized.  :func:`collect` then evaluates every drawn model's
clamped joint angles and placements for all its ticks at once.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from liganimate.runtime.figure import tree as F
from liganimate.runtime.figure.pose import joint_angles
from liganimate.runtime.values import Graphical

__all__ = ["ModelTake", "SceneCollector", "SceneTake", "collect"]


@dataclass
class ModelTake:
    """One model as a scene draws it, tick after tick.

    A model whose structure changes during the scene (its main link, or
    segments rebuilt with other shapes) is split into one take per structure.

    Attributes
    ----------
    name : str
        The MODEL variable, in capitals.
    figure : Figure
        The figure as first drawn (structure, shapes, scales; its placement
        and extremes are per tick).
    ticks : ndarray of int, shape (T,)
        The ticks at which the model is drawn, ascending.
    angles : ndarray, shape (T, J, 3)
        Clamped joint angles at those ticks, in the figure's joint order:
        the angles drawn and written by ``--poses``.
    placements : ndarray, shape (T, 4, 4)
        The host placement of the current main link at each tick.
    """

    name: str
    figure: F.Figure
    ticks: np.ndarray
    angles: np.ndarray
    placements: np.ndarray
    # (rows, figure, motion, frames) per group of ticks: what velocities() evaluates.
    sources: tuple = field(default=(), repr=False)

    def velocities(self) -> np.ndarray:
        """Joint velocities at the ticks, per tick (degrees or lengths), from the interpolation's own derivatives.

        Returns
        -------
        numpy.ndarray, shape (T, J, 3)
            Zero where a joint is held by its extremes (as the pose record's).
        """
        out = np.zeros_like(self.angles)
        for rows, fig, motion, frames in self.sources:
            # ANIMATE plays one motion frame per tick.
            out[rows] = joint_angles(fig, motion, frames, full=True)[1]
        return out


@dataclass
class SceneTake:
    """One shot scene.

    Attributes
    ----------
    id : int
    length, sameframe : int
    cameras : list of ((x, y, z), width)
        The camera in force at the end of each tick, one per tick.
    models : list of ModelTake
        In the order of their first drawing.
    backgrounds : list of (object, ndarray of int)
        Each background object (a Graphical or a Figure drawn still) with
        the ticks at which it is in the background.
    viewed : bool
        Whether a VIEW statement ran before or during the scene (else the
        modern look frames it: docs/semantics-render.md, "Default framing").
    framing : (ndarray (3,), ndarray (3,)) or None
        For a scene without VIEW, the world box ``(lo, hi)`` of what it
        draws, measured at the ticks ``liganimate run``'s default framing
        measures (:mod:`liganimate.runtime.render.framing`); None when the
        scene sets VIEW or draws nothing.
    """

    id: int
    length: int = 0
    sameframe: int = 1
    cameras: list = field(default_factory=list)
    models: list = field(default_factory=list)
    backgrounds: list = field(default_factory=list)
    viewed: bool = False
    framing: tuple | None = None


class _Drawn:
    """What one (model, structure) accumulates tick by tick before evaluation."""

    __slots__ = ("figure", "figures", "frames", "motions", "name", "ticks")

    def __init__(self, name, figure):
        self.name = name
        self.figure = figure
        self.ticks: list = []
        self.figures: list = []
        self.motions: list = []
        self.frames: list = []


class _SceneRecord:
    def __init__(self, scene_id):
        self.id = scene_id
        self.length = 0
        self.sameframe = 1
        self.cameras: list = []
        self.viewed = False
        self.drawn: dict = {}
        self.background: dict = {}  # id -> [object, ticks]


class SceneCollector:
    """A stand-in for the renderer that keeps what each tick would draw.

    Give it to ``Program.execute("check", renderer=collector)``; afterwards
    :attr:`scenes` holds one record per shot scene (see :func:`collect`).
    """

    def __init__(self):
        self.records: list = []
        self._current = None
        self._keys: dict = {}
        self._shape_keys: dict = {}

    def begin_scene(self, scene_id) -> None:
        """A scene starts being shot."""
        self._current = _SceneRecord(scene_id)

    def end_scene(self) -> None:
        """The scene has run all its ticks."""
        if self._current is not None:
            self.records.append(self._current)
        self._current = None

    def add_tick(self, state, rt) -> None:
        """Keep one tick: its camera, background and drawn models (``state`` is the host's SceneState)."""
        rec = self._current
        tick = state.tick
        rec.length, rec.sameframe = state.length, state.sameframe
        rec.cameras.append((tuple(float(x) for x in state.view_point), float(state.view_width)))
        rec.viewed = rec.viewed or bool(getattr(state, "viewed", True))
        for item in state.background:
            entry = rec.background.setdefault(id(item), [item, []])
            entry[1].append(tick)
        for name, posed in state.drawn:
            fig = posed.figure
            key = (name, self._structure(fig))
            d = rec.drawn.get(key)
            if d is None:
                d = rec.drawn[key] = _Drawn(name, fig)
            d.ticks.append(tick)
            d.figures.append(fig)
            d.motions.append(posed.motion)
            d.frames.append(posed.frame)

    def _structure(self, fig: F.Figure):
        """A key equal for figures of the same tree, main link, locations, scales and shapes."""
        memo = (id(fig.links), id(fig.joints), fig.main)
        hit = self._keys.get(memo)
        if hit is not None and hit[0] is fig.links and hit[1] is fig.joints:
            return hit[2]
        links = tuple((l.name, l.scale, self._shape_key(l.shape)) for l in fig.links)
        joints = tuple((j.primary, j.secondary, j.loc1.tobytes(), j.loc2.tobytes(), j.id) for j in fig.joints)
        key = (fig.main, fig.root, links, joints)
        self._keys[memo] = (fig.links, fig.joints, key)
        return key

    def _shape_key(self, shape):
        hit = self._shape_keys.get(id(shape))
        if hit is not None and hit[0] is shape:
            return hit[1]
        if isinstance(shape, Graphical):
            h = hashlib.blake2b(digest_size=16)
            for a in (shape.triangles, shape.lightness, shape.closed):
                h.update(np.ascontiguousarray(a).tobytes())
            key = h.hexdigest()
        else:
            key = ("object", id(shape))
        self._shape_keys[id(shape)] = (shape, key)
        return key


def collect(program, warnings: list | None = None) -> list:
    """Run ``program`` once, without drawing, and return its shot scenes.

    Parameters
    ----------
    program : Program
        A compiled program (``liganimate.compiler.load_program``).
    warnings : list, optional
        Receives the run's warning diagnostics (those ``liganimate check``
        shows).

    Returns
    -------
    list of SceneTake
        In the order the scenes are shot.

    Raises
    ------
    LigDiagnostics
        Whatever the program's own check run raises (the same errors
        ``liganimate check`` reports).
    """
    collector = SceneCollector()
    rt = program.execute("check", renderer=collector)
    if warnings is not None:
        warnings.extend(rt.warnings)
    # The check run measured each VIEW-less scene's drawing, as it does before `liganimate run` draws.
    framings = rt.program.framings
    return [_take(rec, None if rec.viewed else framings.get(rec.id)) for rec in collector.records]


def _take(rec: _SceneRecord, framing) -> SceneTake:
    take = SceneTake(rec.id, rec.length, rec.sameframe, rec.cameras, viewed=rec.viewed, framing=framing)
    for d in rec.drawn.values():
        take.models.append(_model_take(d))
    take.backgrounds = [(obj, np.asarray(ticks, dtype=np.int64)) for obj, ticks in rec.background.values()]
    return take


def _model_take(d: _Drawn) -> ModelTake:
    T = len(d.ticks)
    J = d.figure.n_joints
    angles = np.empty((T, J, 3))
    # Ticks sharing a motion and a set of joints (extremes included) are
    # evaluated together, as the renderer does.
    groups: dict = {}
    for n, (fig, motion) in enumerate(zip(d.figures, d.motions)):
        groups.setdefault((id(fig.joints), id(motion)), []).append(n)
    frames = np.asarray(d.frames, dtype=np.float64)
    sources = []
    for rows in groups.values():
        fig, motion = d.figures[rows[0]], d.motions[rows[0]]
        angles[rows] = joint_angles(fig, motion, frames[rows])
        sources.append((rows, fig, motion, frames[rows]))
    placements = np.stack([np.asarray(f.placement, dtype=np.float64) for f in d.figures])
    return ModelTake(d.name, d.figure, np.asarray(d.ticks, dtype=np.int64), angles, placements, tuple(sources))
