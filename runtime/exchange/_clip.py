"""A BVH capture as LIG sees it: joint-convention angles, the root path, and the capture trimmed or resampled.

:func:`clip_pose` turns every joint's rotation channels into the joint
convention's ``Rz Ry Rx`` angles and the ROOT's position channels into a
path.  Position channels on other joints are offsets: kept when they hold
still, and when they move either dropped with a note (``drop``: the joint
keeps its first frame's offset) or refused (``error``).  :func:`cut_frames`
and :func:`resample` make the clip that ``--frames A:B`` and ``--fps N``
ask for before anything else happens.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from liganimate.runtime.errors import LigError

from ._rotations import euler_from_matrix, euler_zyx_from_matrix, matrix_from_axes, quaternion_from_matrix

__all__ = ["ClipPose", "clip_pose", "clip_size", "cut_frames", "resample", "rest_positions"]

#: Position channels on a joint other than the ROOT that vary by less than this
#: fraction of the skeleton's size are print rounding, not sliding.
STILL = 1e-4


@dataclass(frozen=True)
class ClipPose:
    """A clip's frames in LIG's terms.

    Attributes
    ----------
    angles : ndarray, shape (F, J, 3)
        ``(ax, ay, az)`` per frame and BVH joint, ``R = Rz Ry Rx`` equal to
        the product of the joint's rotation channels in file order; each
        axis unwrapped along the frames (no jumps of 360).
    rotating : ndarray of bool, shape (J,)
        Joints with rotation channels.
    path : ndarray, shape (F, 3)
        The ROOT's position: its position channels, or its OFFSET for the
        components it has no channel for.
    offsets : ndarray, shape (J, 3)
        Each joint's offset from its parent; for joints with position
        channels, their first frame's values.
    notes : tuple of str
        What was done that the user should know (dropped channels).
    """

    angles: np.ndarray
    rotating: np.ndarray
    path: np.ndarray
    offsets: np.ndarray
    notes: tuple = ()


def _subsequence(order: str, of: str = "ZYX") -> bool:
    it = iter(of)
    return all(ch in it for ch in order)


def clip_size(parents, offsets) -> float:
    """The skeleton's extent at rest (largest coordinate range of its joints), 1 if it has none."""
    rest = rest_positions(parents, offsets)
    ext = float(np.ptp(rest, axis=0).max()) if len(rest) else 0.0
    return ext if ext > 0 else 1.0


def rest_positions(parents, offsets) -> np.ndarray:
    """Each joint's position with every angle 0 and the ROOT at the origin, (J, 3)."""
    rest = np.zeros_like(np.asarray(offsets, dtype=np.float64))
    for j in range(1, len(parents)):
        rest[j] = rest[parents[j]] + offsets[j]
    return rest


def clip_pose(clip, joint_translation: str = "error") -> ClipPose:
    """The joint convention's angles, the root path and the offsets of a BVH clip.

    Parameters
    ----------
    clip : BvhClip
    joint_translation : {"error", "drop"}
        What to do with a joint other than the ROOT whose position channels
        really move (more than :data:`STILL` of the skeleton's size).

    Returns
    -------
    ClipPose

    Raises
    ------
    LigDiagnostics
        With ``error``, at the first sliding joint's CHANNELS line.
    """
    F, J = clip.data.shape[0], len(clip.names)
    angles = np.zeros((F, J, 3))
    rotating = np.zeros(J, dtype=bool)
    offsets = clip.offsets.copy()
    path = np.broadcast_to(clip.offsets[0], (F, 3)).copy()
    size = clip_size(clip.parents, clip.offsets)
    notes: list = []
    still: list = []
    slid: list = []
    for j in range(J):
        cols = clip.first[j] + np.arange(len(clip.channels[j]))
        rot = [(c[0], col) for c, col in zip(clip.channels[j], cols) if c.endswith("rotation")]
        if rot:
            rotating[j] = True
            angles[:, j] = _joint_angles(clip.data, rot)
        for c, col in zip(clip.channels[j], cols):
            if not c.endswith("position"):
                continue
            axis, v = "XYZ".index(c[0]), clip.data[:, col]
            if j == 0:
                path[:, axis] = v
                continue
            offsets[j, axis] = v[0]
            moves = float(np.ptp(v))
            (still if moves <= STILL * size else slid).append((j, c, moves))
    if still:
        joints = sorted({clip.names[j] for j, _, _ in still})
        notes.append(
            f"dropped {len(still)} position channels of {len(joints)} joints other than the ROOT that hold still "
            f"(they vary by at most {max(m for _, _, m in still):.3g}); each keeps its value as the joint's offset"
        )
    if slid:
        _slid(clip, slid, joint_translation, notes)
    angles = np.unwrap(angles, period=360.0, axis=0)
    return ClipPose(angles, rotating, path, offsets, tuple(notes))


def _joint_angles(data: np.ndarray, rot: list) -> np.ndarray:
    order = "".join(a for a, _ in rot)
    values = data[:, [col for _, col in rot]]
    if _subsequence(order):
        out = np.zeros((len(data), 3))
        for n, (axis, _) in enumerate(rot):
            out[:, "XYZ".index(axis)] = values[:, n]
        return out
    return euler_zyx_from_matrix(matrix_from_axes(order, values))


def _slid(clip, slid: list, joint_translation: str, notes: list) -> None:
    j, channel, moves = max(slid, key=lambda s: s[2])
    if joint_translation == "error":
        raise clip.error(
            clip.channel_pos[slid[0][0]],
            f"joint {clip.names[slid[0][0]]} moves along its {slid[0][1]} channel (by up to {slid[0][2]:.3g}), "
            "but a LIG joint only turns",
            "import with --joint-translation drop to keep each such joint at its first frame's offset",
        )
    joints = sorted({clip.names[s[0]] for s in slid})
    notes.append(
        f"dropped the sliding of {len(joints)} joints other than the ROOT ({', '.join(joints[:6])}"
        f"{', ...' if len(joints) > 6 else ''}; the most, {clip.names[j]} along {channel}, by {moves:.3g}); "
        "each keeps its first frame's offset"
    )


def cut_frames(clip, first: int, last: int | None):
    """The clip's frames ``first`` to ``last`` (inclusive; None: to the end), as a new clip.

    Raises
    ------
    LigError
        When the range is empty or outside the capture.
    """
    F = clip.data.shape[0]
    stop = F - 1 if last is None else last
    if not (0 <= first <= stop < F):
        raise LigError(
            f"--frames {first}:{'' if last is None else last} is outside the capture's frames 0 to {F - 1}.",
            f"give frames between 0 and {F - 1}, the first no later than the last",
        )
    return dataclasses.replace(clip, data=clip.data[first : stop + 1].copy())


def resample(clip, fps: float):
    """The clip at ``fps`` frames per second: rotations interpolated on the sphere, positions linearly.

    The new frame ``k`` is the capture at time ``k / fps``, up to the last
    captured frame's time.  Rotation channels are turned into each joint's
    rotation, interpolated spherically between the two nearest frames and
    turned back into the joint's own channel order, so no axis order or
    wrap-around biases the result.
    """
    F = clip.data.shape[0]
    duration = (F - 1) * clip.frame_time
    n = int(np.floor(duration * fps + 1e-9)) + 1
    t = np.arange(n) / fps / clip.frame_time  # in source frames
    i0 = np.minimum(np.floor(t).astype(np.int64), F - 1)
    i1 = np.minimum(i0 + 1, F - 1)
    u = (t - i0)[:, None]
    data = clip.data[i0] * (1 - u) + clip.data[i1] * u
    for j in range(len(clip.names)):
        cols = clip.first[j] + np.arange(len(clip.channels[j]))
        rot = [(c[0], col) for c, col in zip(clip.channels[j], cols) if c.endswith("rotation")]
        if len(rot) < 2:
            continue
        order = "".join(a for a, _ in rot)
        q = quaternion_from_matrix(matrix_from_axes(order, clip.data[:, [c for _, c in rot]]))
        R = _slerp_matrices(q[i0], q[i1], u[:, 0])
        data[:, [c for _, c in rot]] = _angles_in_order(order, R)
    return dataclasses.replace(clip, data=data, frame_time=1.0 / fps)


def _slerp_matrices(q0: np.ndarray, q1: np.ndarray, u: np.ndarray) -> np.ndarray:
    dot = np.einsum("ti,ti->t", q0, q1)
    q1 = np.where(dot[:, None] < 0, -q1, q1)
    dot = np.abs(dot).clip(-1.0, 1.0)
    theta = np.arccos(dot)
    small = theta < 1e-9
    s = np.where(small, 1.0, np.sin(theta))
    w0 = np.where(small, 1 - u, np.sin((1 - u) * theta) / s)
    w1 = np.where(small, u, np.sin(u * theta) / s)
    q = w0[:, None] * q0 + w1[:, None] * q1
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    x, y, z, w = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def _angles_in_order(order: str, R: np.ndarray) -> np.ndarray:
    if len(order) == 3:
        return np.unwrap(euler_from_matrix(order, R), period=360.0, axis=0)
    # Two axes: the third of the Tait-Bryan decomposition stays near 0 for such a joint; drop it.
    full = order + next(a for a in "XYZ" if a not in order)
    return np.unwrap(euler_from_matrix(full, R), period=360.0, axis=0)[:, :2]
