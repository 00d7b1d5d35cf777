"""Retargeting: a capture's motion onto another figure, its joints mapped, its rest pose aligned, its feet kept.

The steps (docs/exchange.md, "Retargeting", has the whole story):

1. **Facing.**  Each skeleton's right, up and forward directions come from
   its rest pose (right: the right thigh's joint less the left's; up: the
   head or neck less the hips); ``F`` turns the capture's world into the
   figure's (a capture facing +Z onto HUMANOID, which faces +X), the
   capture's mean heading forward.  Where the capture's hips head, frame by
   frame (their turn about up away from that mean), is the motion's ROOT
   ORIENTATION: the figure's main link turns with the actor, and the tilt
   is left to the joints below it, as before.
2. **Rest pose.**  For each mapped pair, ``C`` is the smallest rotation
   taking the figure's bone (from its joint to the next mapped joint below
   it) onto the capture's rest bone, seen through ``F``: a T-pose capture's
   arms line up with a figure whose arms hang.
3. **Rotations.**  Frame by frame, from the main link down, a mapped link
   should have the world rotation ``F Q(f) F^T C``, ``Q(f)`` the capture
   joint's world rotation; its joint gets what that leaves after its parent,
   in the joint convention's angles, clamped into the joint's extremes
   (frames where an angle moves by more than :data:`CLAMP_REPORT` degrees
   are counted).  The links below build on the clamped result, so one
   clamped joint does not bend the rest of the limb.
4. **Size.**  The root path is scaled by the ratio of the leg lengths (or
   ``scale``), turned by ``F``, and carried so that the figure's hips are as
   high over its feet as the capture's, in proportion.
5. **Feet.**  Contacts are found in the capture (an ankle low and slow) and
   kept: during a contact the figure's ankle is held at one point and each
   leg is solved exactly, hip and knee (two-link inverse kinematics about the
   knee's own axis), the foot keeping its retargeted world rotation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx
from liganimate.runtime.motion.turning import orientation_angles

from ._clip import clip_pose, rest_positions
from ._feet import keep_feet, leg_chain_positions
from ._joint_map import JointMap
from ._rigging import CLAMP_REPORT, at_least, fit_angles, rotation_between, runs

__all__ = ["CLAMP_REPORT", "Retargeted", "RetargetOptions", "retarget", "runs"]

#: A capture's ankle is planted when it is within this fraction of the leg's length of its
#: lowest height (the 5th percentile of both ankles) and moves slower than this many leg
#: lengths a second, for at least three frames.
CONTACT_HEIGHT = 0.06
CONTACT_SPEED = 0.15


@dataclass(frozen=True)
class RetargetOptions:
    """How a capture is retargeted.

    Attributes
    ----------
    scale : float or None
        Multiplies the capture's lengths (root path); None: the figure's leg
        length over the capture's.
    joint_translation : {"error", "drop"}
        See :func:`._clip.clip_pose`.
    keep_feet : bool
        Hold planted feet (step 5); off, the feet go where the angles take them.
    """

    scale: float | None = None
    joint_translation: str = "error"
    keep_feet: bool = True


@dataclass
class Retargeted:
    """A retargeted motion and what happened on the way.

    Attributes
    ----------
    joint_ids : list of int
        The figure's joints the motion drives.
    angles : ndarray, shape (F, len(joint_ids), 3)
    path : ndarray, shape (F, 3)
        The ROOT track: the main link's displacement in the model's frame.
    orientation : ndarray, shape (F, 3)
        The ROOT ORIENTATION track: the main link's heading, degrees
        (:func:`liganimate.runtime.motion.turning.orientation_angles`),
        unwrapped along the frames.
    scale : float
    clamped : dict
        Joint id -> number of frames an angle of it was clamped by more than
        :data:`CLAMP_REPORT` degrees.
    planted : dict
        Side ("L", "R") -> bool array (F,) of contact frames.
    notes : list of str
    """

    joint_ids: list
    angles: np.ndarray
    path: np.ndarray
    orientation: np.ndarray
    scale: float
    clamped: dict
    planted: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)


# ---------------------------------------------------------------- source side


class _Source:
    """The capture's world rotations and joint positions, every frame."""

    def __init__(self, clip, joint_translation: str):
        pose = clip_pose(clip, joint_translation)
        self.notes = list(pose.notes)
        self.parents = clip.parents
        self.rest = rest_positions(clip.parents, pose.offsets)
        local = matrix_from_euler_zyx(pose.angles)  # (F, J, 3, 3)
        F, J = local.shape[:2]
        self.Q = np.empty_like(local)
        self.P = np.empty((F, J, 3))
        for j in range(J):
            p = int(clip.parents[j])
            if p < 0:
                self.Q[:, j] = local[:, j]
                self.P[:, j] = pose.path
            else:
                self.Q[:, j] = self.Q[:, p] @ local[:, j]
                self.P[:, j] = self.P[:, p] + self.Q[:, p] @ pose.offsets[j]
        self.frame_time = clip.frame_time
        self.turn = np.zeros(F)  # radians the hips turn away from their mean heading (set by _alignment)
        self.up = np.array([0.0, 1.0, 0.0])  # the figure's up (set by _alignment)


# ---------------------------------------------------------------- target side


class _Target:
    """The figure at neutral: each link's parent, joint, and rest joint position, walked from the main link."""

    def __init__(self, fig):
        if fig.main != fig.root or fig.inverted.any():
            # A joint walked from its secondary turns its link the other way,
            # which the retargeting's rest offsets (loc1 - loc2) do not follow.
            raise LigError(
                "the figure is re-rooted (FIGURE ... MAIN, or a submodel attached by the main link FIGURE chose), "
                "which retargeting does not follow.",
                "retarget onto the model as its library defines it",
            )
        self.fig = fig
        loc1, loc2 = fig.locations
        n = fig.n_links
        self.parent = np.full(n, -1)
        self.joint = np.full(n, -1)
        self.origin = np.zeros((n, 3))  # link frame origin at neutral
        self.order = [fig.main]
        for level in fig.traversal:
            for k, p, c in zip(level.joints, level.parents, level.children):
                self.parent[c], self.joint[c] = p, k
                self.origin[c] = self.origin[p] + loc1[k] - loc2[k]
                self.order.append(int(c))
        self.loc1, self.loc2 = loc1, loc2
        # Where each link's joint is at neutral (the main link: its origin).
        self.pivot = np.array([self.origin[i] + (loc2[self.joint[i]] if self.joint[i] >= 0 else 0.0) for i in range(n)])
        self.extremes = fig.extremes  # (J, 3, 2)


def _frame(right: np.ndarray, up: np.ndarray) -> np.ndarray:
    """An orthonormal basis (columns right, up, right x up) from a skeleton's right and up directions."""
    u = up / np.linalg.norm(up)
    r = right - u * (right @ u)
    r /= np.linalg.norm(r)
    return np.column_stack([r, u, np.cross(r, u)])


def _alignment(src: _Source, tgt: _Target, jmap: JointMap):
    """``Fw`` (capture world to figure world), ``Fr`` (capture rest to figure rest) and each pair's rest correction ``C``.

    The two differ for a capture whose rest pose does not stand upright in
    its file (bvhtools' long take lies along -X at rest, its hips' rotation
    standing it up): the world's up is the file's axis the posed hips stand
    along over the ankles, the rest pose's where its own hips are.
    """
    (s_left, _, s_lfoot), (t_left, _, t_lfoot) = jmap.feet["L"]
    (s_right, _, s_rfoot), (t_right, _, t_rfoot) = jmap.feet["R"]
    s_root = int(np.flatnonzero(src.parents < 0)[0])
    # Up: from between the ankles to the hips (legs are straight at rest, arms may not be).
    s_up = src.rest[s_root] - (src.rest[s_lfoot] + src.rest[s_rfoot]) / 2
    t_up = tgt.pivot[tgt.fig.main] - (tgt.pivot[t_lfoot] + tgt.pivot[t_rfoot]) / 2
    t_frame = _frame(tgt.pivot[t_right] - tgt.pivot[t_left], t_up)
    Fr = t_frame @ _frame(src.rest[s_right] - src.rest[s_left], s_up).T
    # The world's up is the file's axis nearest to where the posed hips are over the ankles
    # (BVH's Y, nearly always): the floor of a capture is level in its file.
    lift = (src.P[:, s_root] - (src.P[:, s_lfoot] + src.P[:, s_rfoot]) / 2).mean(axis=0)
    w_up = np.zeros(3)
    w_up[int(np.argmax(np.abs(lift)))] = 1.0 if lift[int(np.argmax(np.abs(lift)))] > 0 else -1.0
    Fw = rotation_between(w_up, t_frame[:, 1])
    # Face the capture's mean heading forward; the main link turns away from it with the hips.
    turn = _heading(Fw, src.Q[:, s_root], Fr.T @ t_frame[:, 2], t_frame[:, 1], t_frame[:, 2])
    mean = float(np.arctan2(np.sin(turn).mean(), np.cos(turn).mean()))
    Fw = _about(t_frame[:, 1], -mean) @ Fw
    src.turn = np.unwrap((turn - mean + np.pi) % (2 * np.pi) - np.pi)
    src.up = t_frame[:, 1]
    corrections = []
    for s, t in jmap.pairs:
        tip = _tip(src.parents, tgt.parent, jmap.pairs, s, t)
        if tip is None:
            corrections.append(np.eye(3))
            continue
        s_bone = Fr @ (src.rest[tip[0]] - src.rest[s])
        t_bone = tgt.pivot[tip[1]] - tgt.pivot[t]
        if np.linalg.norm(s_bone) < 1e-12 or np.linalg.norm(t_bone) < 1e-12:
            corrections.append(np.eye(3))
        else:
            corrections.append(rotation_between(t_bone, s_bone))
    return Fw, Fr, corrections


def _heading(Fw: np.ndarray, Q: np.ndarray, forward: np.ndarray, up: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """The angles (radians, about ``up``) from ``ref`` to where rotations ``Q`` point the capture's rest ``forward``, seen through ``Fw``."""
    v = np.einsum("ij,fjk,k->fi", Fw, Q, forward)
    v -= np.outer(v @ up, up)
    return np.arctan2(np.cross(ref, v) @ up, v @ ref)


def _about(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation by ``angle`` radians about unit ``axis``."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _descends(parents, a: int, b: int) -> bool:
    """Whether joint/link ``b`` is below ``a``."""
    while b >= 0:
        b = int(parents[b])
        if b == a:
            return True
    return False


def _tip(s_parents, t_parents, pairs, s: int, t: int):
    """The nearest mapped pair below (s, t) on both sides: the other end of the bone."""
    best = None
    for s2, t2 in pairs:
        if _descends(s_parents, s, s2) and _descends(t_parents, t, t2):
            depth = _depth(s_parents, s2)
            if best is None or depth < best[0]:
                best = (depth, s2, t2)
    return None if best is None else best[1:]


def _depth(parents, j: int) -> int:
    d = 0
    while parents[j] >= 0:
        j = int(parents[j])
        d += 1
    return d


# ---------------------------------------------------------------- rotations


def _main_rotation(src: _Source) -> np.ndarray:
    """The main link's world rotation (F, 3, 3): the hips' heading about the figure's up."""
    axis = src.up
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    s, c = np.sin(src.turn)[:, None, None], np.cos(src.turn)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def _rotations(src: _Source, tgt: _Target, jmap: JointMap, frames: tuple, corrections: list):
    """Clamped joint angles (F, J, 3) of the figure and each link's world rotation (F, n_links, 3, 3)."""
    Fw, Fr = frames
    F = src.Q.shape[0]
    n, J = tgt.fig.n_links, tgt.fig.n_joints
    desired = {t: np.einsum("ij,fjk,lk,lm->fim", Fw, src.Q[:, s], Fr, C) for (s, t), C in zip(jmap.pairs, corrections)}
    W = np.empty((F, n, 3, 3))
    angles = np.zeros((F, J, 3))
    clamped = np.zeros((F, J), dtype=bool)
    for i in tgt.order:
        p, k = tgt.parent[i], tgt.joint[i]
        if p < 0:
            W[:, i] = _main_rotation(src)
            continue
        if i in desired:
            local = np.swapaxes(W[:, p], -1, -2) @ desired[i]
            angles[:, k], clamped[:, k] = fit_angles(tgt.extremes[k], local)
        W[:, i] = W[:, p] @ matrix_from_euler_zyx(angles[:, k])
    return angles, W, clamped, desired


# ---------------------------------------------------------------- root and feet


def _leg_length(points: np.ndarray, leg: tuple) -> float:
    up, low, foot = leg
    return float(np.linalg.norm(points[low] - points[up]) + np.linalg.norm(points[foot] - points[low]))


def _root_path(src: _Source, tgt: _Target, jmap: JointMap, Fm: np.ndarray, scale: float) -> np.ndarray:
    """The main link's displacement: the capture's hips path scaled, turned, and set over the figure's feet."""
    s_root = int(np.flatnonzero(src.parents < 0)[0])
    feet_s = [jmap.feet[s][0][2] for s in jmap.feet]
    feet_t = [jmap.feet[s][1][2] for s in jmap.feet]
    hips = src.P[:, s_root] @ Fm.T  # in the figure's axes, capture units
    ankles = np.concatenate([src.P[:, f] @ Fm.T for f in feet_s])
    ankle_level = float(np.percentile(ankles[:, 1], 5))  # the ankles' height when standing
    path = (hips - hips[0]) * scale
    path[:, 1] = (hips[:, 1] - ankle_level) * scale + float(np.mean(tgt.pivot[feet_t, 1])) - tgt.pivot[tgt.fig.main, 1]
    return path


def _stand(tgt: _Target, jmap: JointMap, angles: np.ndarray, path: np.ndarray, main: np.ndarray) -> None:
    """Set the figure on its feet (``path`` changed in place): its ankles, as its own retargeted legs put them, are
    as low at their lowest (the 5th percentile of both) as they are when the figure stands at rest.

    The capture's hips-over-ankles height, scaled, only approximates this: the figure's legs bend
    as their extremes let them, not exactly as the actor's.
    """
    feet = [jmap.feet[side][1][2] for side in jmap.feet]
    points = leg_chain_positions(tgt, angles, path, None, main)
    level = float(np.percentile(points[:, feet, 1], 5))
    path[:, 1] += float(np.mean(tgt.pivot[feet, 1])) - level


def _contacts(src: _Source, jmap: JointMap, Fm: np.ndarray, length: float) -> dict:
    """Per side, the frames where the capture's ankle is planted: near its lowest and nearly still."""
    out = {}
    ankles = {side: src.P[:, jmap.feet[side][0][2]] @ Fm.T for side in jmap.feet}
    low = float(np.percentile(np.concatenate([a[:, 1] for a in ankles.values()]), 5))
    for side, a in ankles.items():
        v = np.zeros(len(a))
        if len(a) > 1:
            step = np.linalg.norm(np.diff(a, axis=0), axis=1) / src.frame_time
            v[1:-1] = np.minimum(step[:-1], step[1:])
            v[0], v[-1] = step[0], step[-1]
        planted = (a[:, 1] < low + CONTACT_HEIGHT * length) & (v < CONTACT_SPEED * length)
        out[side] = at_least(planted, 3)
    return out


def retarget(clip, fig, jmap: JointMap, options: RetargetOptions = RetargetOptions()) -> Retargeted:
    """Retarget a BVH clip onto a figure (see the module's docstring).

    Parameters
    ----------
    clip : BvhClip
    fig : Figure
        The figure as its library defines it (SCALE MODEL included).
    jmap : JointMap
        From :func:`._joint_map.auto_map` or :func:`._joint_map.read_map`.
    options : RetargetOptions

    Returns
    -------
    Retargeted

    Raises
    ------
    LigError
        For a figure without feet, a capture without legs, a re-rooted
        figure.
    """
    if "L" not in jmap.feet or "R" not in jmap.feet:
        raise LigError(
            "the figure or the capture has no two legs that the map names (thigh, shin and foot on each side).",
            "map both legs in the map file (--map), or retarget onto a figure with legs and feet",
        )
    src, tgt = _Source(clip, options.joint_translation), _Target(fig)
    Fm, Fr, corrections = _alignment(src, tgt, jmap)
    s_len = np.mean([_leg_length(src.rest, jmap.feet[s][0]) for s in "LR"])
    t_len = np.mean([_leg_length(tgt.pivot, jmap.feet[s][1]) for s in "LR"])
    scale = options.scale if options.scale is not None else float(t_len / s_len)
    angles, W, clamped, desired = _rotations(src, tgt, jmap, (Fm, Fr), corrections)
    path = _root_path(src, tgt, jmap, Fm, scale)
    planted = _contacts(src, jmap, Fm, float(s_len)) if options.keep_feet else {}
    notes = list(src.notes)
    main = _main_rotation(src)
    orientation = np.degrees(np.unwrap(np.radians(orientation_angles(main)), axis=0))
    _stand(tgt, jmap, angles, path, main)
    if planted:
        notes += keep_feet(tgt, angles, path, desired, planted, jmap, main)
        _stand(tgt, jmap, angles, path, main)  # the held feet moved: stand again (all together, so none slides)
    driven = sorted({int(tgt.joint[t]) for _, t in jmap.pairs if tgt.joint[t] >= 0} | _feet_joints(tgt, jmap))
    ids = [tgt.fig.joints[k].id for k in driven]
    return Retargeted(
        joint_ids=ids,
        angles=angles[:, driven],
        path=path,
        orientation=orientation,
        scale=scale,
        clamped={tgt.fig.joints[k].id: int(clamped[:, k].sum()) for k in driven if clamped[:, k].any()},
        planted=planted,
        notes=notes,
    )


def _feet_joints(tgt: _Target, jmap: JointMap) -> set:
    return {int(tgt.joint[t]) for side in jmap.feet for t in jmap.feet[side][1]}
