"""Applying motions to models: joint angles, link transforms and world triangles, batched.

Everything here works on whole batches of frames at once (numpy over the
frame axis); the only Python loops are over joints or tree levels, never
over frames.
"""

from __future__ import annotations

import weakref

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import morphing as MO
from liganimate.runtime.figure import tree as F
from liganimate.runtime.motion.algebra import Motion
from liganimate.runtime.motion.turning import orientation_matrix
from liganimate.runtime.values import Graphical, joined_shades

# (id(motion), id(joints)) -> (motion, joints, bound); the stored objects keep
# the ids valid. Bounded so a long program cannot grow it without limit.
_bound: dict = {}
_BOUND_MAX = 512


def _bound_motion(fig: F.Figure, motion: Motion) -> Motion:
    """The motion with free (full-turn) axes unwrapped, cached per (model, motion)."""
    key = (id(motion), id(fig.joints))
    hit = _bound.get(key)
    if hit is not None:
        return hit[2]
    free = {j: axes for j, axes in K.free_axes(fig).items() if any(axes) and j in set(motion.joints)}
    bound = motion.unwrapped(free) if free else motion
    if len(_bound) >= _BOUND_MAX:
        _bound.clear()
    _bound[key] = (motion, fig.joints, bound)
    return bound


def joint_angles(fig: F.Figure, motion: Motion, frames: np.ndarray, full: bool = False):
    """Clamped joint angles of ``fig`` driven by ``motion``.

    Parameters
    ----------
    fig : Figure
    motion : Motion
    frames : ndarray, shape (T,)
        Motion frames (may be fractional).
    full : bool
        Also return velocity and acceleration (deg/frame, deg/frame^2).

    Returns
    -------
    ndarray, shape (T, J, 3)
        In the figure's joint order; joints the motion does not drive sit at
        neutral (0, 0, 0), clamped into their extremes like every other angle.
        With ``full``, a tuple (angles, velocity, acceleration).
    """
    frames = np.asarray(frames, dtype=np.float64).reshape(-1)
    ids = fig.joint_ids
    drives = set(motion.joints)
    driven = [j for j in ids if j in drives]
    angles = np.zeros((len(frames), len(ids), 3))
    if full:
        vel = np.zeros_like(angles)
        acc = np.zeros_like(angles)
    if driven:
        bound = _bound_motion(fig, motion)
        cols = [fig.joint_index(j) for j in driven]
        if full:
            a, v, c = bound.evaluate_full(frames, driven)
            angles[:, cols], vel[:, cols], acc[:, cols] = a, v, c
        else:
            if np.isnan(frames).any():
                bound.evaluate(frames, driven)  # raises the motion's error
            for j, col in zip(driven, cols):
                angles[:, col] = bound.track(j).sample_x(frames)
    clamped = K.clamp(fig, angles, out=None if full else angles)
    if full:
        # A clamped axis is held by its stop: it neither moves nor accelerates.
        held = clamped != angles
        held &= ~np.isclose(clamped, angles)
        vel[held] = 0.0
        acc[held] = 0.0
        return clamped, vel, acc
    return clamped


class MeshTable:
    """A model's link shapes concatenated once: triangles in link coordinates.

    Attributes
    ----------
    triangles : ndarray, shape (M, 3, 3)
    link : ndarray of int, shape (M,)
    lightness : ndarray, shape (M,)
    colour : ndarray, shape (M, 3), or None
        None when no link's shape has a COLOUR.
    shade : ndarray of uint8, shape (M,) or (M, 3)
        What the rasterizer draws: grey levels, or RGB when any link has a colour.
    closed : ndarray of bool, shape (M,)
    """

    def __init__(self, fig: F.Figure):
        tris, link, light, closed, shapes = [], [], [], [], []
        for i, l in enumerate(fig.links):
            g = l.shape
            if not isinstance(g, Graphical) or len(g) == 0:
                continue
            t = g.triangles
            c = g.closed
            if l.scale < 0:
                # A mirrored link flips its triangles' winding.
                t = t[:, ::-1, :]
            tris.append(t)
            link.append(np.full(len(g), i))
            light.append(g.lightness)
            closed.append(c)
            shapes.append(g)
        self.colour = None
        if tris:
            self.triangles = np.concatenate(tris)
            self.link = np.concatenate(link)
            self.lightness = np.concatenate(light)
            if any(g.colour is not None for g in shapes):
                self.colour = np.concatenate([g.colours() for g in shapes])
            self.shade = joined_shades(g.shades() for g in shapes)
            self.closed = np.concatenate(closed)
        else:
            self.triangles = np.zeros((0, 3, 3))
            self.link = np.zeros(0, dtype=int)
            self.lightness = np.zeros(0)
            self.shade = np.zeros(0, dtype=np.uint8)
            self.closed = np.zeros(0, dtype=bool)


_meshes: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def mesh_table(fig: F.Figure) -> MeshTable:
    """The cached :class:`MeshTable` of a figure's links (shared by figures with the same links)."""
    key = fig.links[0]
    entry = _meshes.get(key)
    if entry is not None and entry[0] is fig.links:
        return entry[1]
    table = MeshTable(fig)
    _meshes[key] = (fig.links, table)
    return table


def rooted_placements(placements: np.ndarray, motion: Motion | None, frames: np.ndarray) -> np.ndarray:
    """Host placements with a motion's root track applied: ``placement @ Trans(root(frame)) @ Rot(orientation(frame))``.

    Parameters
    ----------
    placements : ndarray, shape (T, 4, 4)
        Host placement of the current main link at each frame.
    motion : Motion or None
    frames : ndarray, shape (T,)
        Motion frames.

    Returns
    -------
    ndarray, shape (T, 4, 4)
        ``placements`` itself when the motion has neither a root path nor a
        root orientation; otherwise a new array whose translation column
        moves by the placement's linear part applied to the offset, so a
        model turned by ``<ROT Y 90>`` walks along its turned path, and whose
        linear part is turned by the root orientation
        (:func:`liganimate.runtime.motion.turning.orientation_matrix`).
    """
    placements = np.asarray(placements, dtype=np.float64)
    if motion is None or (motion.root is None and motion.turn is None):
        return placements
    times = np.asarray(frames, dtype=np.float64).reshape(-1)
    out = placements.copy()
    if motion.root is not None:
        offset = motion.root_offset(times)
        out[:, :3, 3] += np.einsum("tij,tj->ti", placements[:, :3, :3], offset)
    if motion.turn is not None:
        out[:, :3, :3] = placements[:, :3, :3] @ orientation_matrix(motion.root_orientation(times))
    return out


def world_transforms(fig: F.Figure, angles: np.ndarray, placements: np.ndarray) -> np.ndarray:
    """Each link's shape-to-world transform.

    Parameters
    ----------
    fig : Figure
    angles : ndarray, shape (T, J, 3)
        Clamped angles.
    placements : ndarray, shape (T, 4, 4)
        Per-frame host placement of the current main link.

    Returns
    -------
    ndarray, shape (T, n_links, 4, 4)
        ``placement @ pose @ diag(s, s, s, 1)``.
    """
    X = K.placed_transforms(fig, np.asarray(angles, dtype=np.float64), placements)
    s = fig.link_scales
    if (s != 1.0).any():
        X[..., :3, :3] *= s[None, :, None, None]
    return X


def world_triangles(table: MeshTable, X: np.ndarray, local: np.ndarray | None = None) -> np.ndarray:
    """Triangles in world coordinates, shape (T, M, 3, 3), from link transforms X (T, L, 4, 4).

    ``local`` (T, M, 3, 3), when given, replaces the table's triangles frame by
    frame (a motion's SHAPE tracks, :func:`morphed`).
    """
    if len(table.triangles) == 0:
        return np.zeros((X.shape[0], 0, 3, 3))
    R = X[:, table.link, :3, :3]  # (T, M, 3, 3)
    t = X[:, table.link][..., :3, 3]  # (T, M, 3)
    if local is not None:
        return np.einsum("tmij,tmkj->tmki", R, local, optimize=True) + t[:, :, None, :]
    return np.einsum("tmij,mkj->tmki", R, table.triangles, optimize=True) + t[:, :, None, :]


_bindings: dict = {}


def morphed(fig: F.Figure, motion: Motion | None, frames, X: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """A motion's SCALE and SHAPE tracks applied to a model's link transforms and triangles.

    Parameters
    ----------
    fig : Figure
    motion : Motion or None
    frames : array_like, shape (T,)
        Motion frames.
    X : ndarray, shape (T, L, 4, 4)
        From :func:`world_transforms`.

    Returns
    -------
    X : ndarray, shape (T, L, 4, 4)
        With each scaled link's scale factors (along its own axes) folded in.
    local : ndarray, shape (T, M, 3, 3), or None
        The mesh table's triangles, morphed, per frame; None when the motion
        shapes no link (draw the table's own).

    Raises
    ------
    LigError
        If the motion morphs a link the model has not, or a shape whose
        structure is not the link's (ANIMATE's check reports it first).
    """
    morphs = None if motion is None else motion.morphs
    if morphs is None:
        return X, None
    return MO.apply(morph_binding(fig, morphs), morphs, frames, X, mesh_table(fig))


def morph_binding(fig: F.Figure, morphs) -> MO.Binding:
    """A motion's morphs bound to a model's links, remembered per (links, morphs)."""
    key = (id(fig.links), id(morphs))
    hit = _bindings.get(key)
    if hit is None or hit[0] is not fig.links or hit[1] is not morphs:
        if len(_bindings) >= _BOUND_MAX:
            _bindings.clear()
        hit = _bindings[key] = (fig.links, morphs, MO.bind(fig, morphs))
    return hit[2]


def morph_record(fig: F.Figure, motion: Motion | None, frames) -> list[dict]:
    """Per frame, the morphed links' scale factors and shape weights (``--poses``; see :func:`.morphing.record`)."""
    n = len(np.asarray(frames).reshape(-1))
    morphs = None if motion is None else motion.morphs
    if morphs is None:
        return [{} for _ in range(n)]
    return MO.record(morph_binding(fig, morphs), morphs, frames)


def static_triangles(fig: F.Figure):
    """A model drawn as a background object: neutral pose at its placement.

    Returns
    -------
    (triangles (M, 3, 3), shade (M,) or (M, 3), closed (M,))
    """
    J = fig.n_joints
    angles = K.clamp(fig, np.zeros((1, J, 3)))
    X = world_transforms(fig, angles, np.asarray(fig.placement)[None])
    table = mesh_table(fig)
    return (
        world_triangles(table, X)[0],
        table.shade,
        table.closed & (np.linalg.det(np.asarray(fig.placement)[:3, :3]) > 0),
    )


def posed_graphical(fig: F.Figure, motion: Motion | None, frame: float) -> Graphical:
    """A model as a graphical object: its triangles in one pose, at its placement.

    Parameters
    ----------
    fig : Figure
    motion : Motion or None
        None for the neutral pose.
    frame : float
        Frame of ``motion`` (clamped angles, as the renderer draws them).

    Returns
    -------
    Graphical
        World-space triangles (M, 3, 3); closed only where the placement does
        not mirror (the winding is then still outward).
    """
    placement = np.asarray(fig.placement, dtype=np.float64)
    if motion is None:
        angles = K.clamp(fig, np.zeros((1, fig.n_joints, 3)))
    else:
        angles = joint_angles(fig, motion, np.array([float(frame)]))
    X = world_transforms(fig, angles, rooted_placements(placement[None], motion, np.array([float(frame)])))
    X, local = morphed(fig, motion, np.array([float(frame)]), X)
    table = mesh_table(fig)
    closed = table.closed & (np.linalg.det(placement[:3, :3]) > 0)
    return Graphical(world_triangles(table, X, local)[0], table.lightness, closed, table.colour)


def slide_out_of_range(fig: F.Figure, motion: Motion, limit: int = 100_000) -> tuple[str, str] | None:
    """The first keyframe that asks a slide for a displacement beyond its extremes, as ``(sentence, hint)``.

    A turn past its extremes is clamped, as the thesis has it ("the joint
    will enforce its extreme rotation limit"); a slide's extremes are the
    length of its rail, and a keyframe beyond them is a mistake in the
    program, so ANIMATE refuses it.  In-betweens are still clamped.  A
    motion too long to list (beyond ``limit`` keyframes) is not checked.

    Returns
    -------
    tuple of (str, str), or None when every keyframe is within range.
    """
    driven = set(motion.joints)
    for joint in fig.joints:
        if not joint.slide or joint.id not in driven:
            continue
        try:
            start, keys = motion.keyframes(joint.id, limit)
        except LigError:
            continue
        lo, hi = joint.extremes[:, 0], joint.extremes[:, 1]
        for frame, value in [(0.0, start)] + [(k.frame, k.position) for k in keys]:
            v = np.asarray(value, dtype=np.float64)
            bad = np.flatnonzero((v < lo - 1e-9) | (v > hi + 1e-9))
            if bad.size:
                a = int(bad[0])
                return (
                    f"joint {joint.id} slides within ({lo[a]:g}, {hi[a]:g}) along {F.AXES[a]}, but the motion "
                    f"puts it at {v[a]:g} at frame {frame:g}",
                    "keep the keyframe within the SLIDE extremes, or widen them",
                )
    return None
