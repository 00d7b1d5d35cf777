"""Rotation matrices and batched pose evaluation for articulated figures.

Joint convention (see ``docs/semantics-figure.md``): with locations ``L1``
(primary coordinates), ``L2`` (secondary coordinates) and angles
``(ax, ay, az)`` in degrees, a point ``p`` of the secondary is
``L1 + R (p - L2)`` in the primary, ``R = Rz(az) Ry(ay) Rx(ax)``, i.e. the
4x4 transform ``Trans(L1) R Trans(-L2)``.  Walking a joint the other way, from
secondary to primary (which FIGURE ... MAIN makes happen), uses its inverse
``Trans(L2) R^T Trans(-L1)``; ``R^T = Rx(-ax) Ry(-ay) Rz(-az)`` is the sign
reversal of the thesis' Figures 13 and 14, which therefore needs no special
case.

Pose evaluation is vectorised over frames: :func:`pose_transforms` loops only
over the depth levels of the tree, batching every joint of a level.
:func:`pose_transforms_reference` is a deliberately plain per-frame recursive
walk kept to cross-check it.
"""

from __future__ import annotations

import numpy as np

from .figure import Figure

__all__ = [
    "matrix_from_euler_zyx",
    "transform_from",
    "invert_transform",
    "joint_transforms",
    "pose_transforms",
    "pose_transforms_reference",
    "shape_transforms",
    "clamp",
    "free_axes",
]


def matrix_from_euler_zyx(angles) -> np.ndarray:
    """Rotation matrices ``R = Rz(az) Ry(ay) Rx(ax)`` from joint angles.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        ``(ax, ay, az)`` in DEGREES, in that (x, y, z) order -- unlike
        pytransform3d's ``active_matrix_from_intrinsic_euler_zyx``, whose
        input is ordered (z, y, x) and in radians.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Active rotations, right-hand rule: X first, then Y, then Z, all about
        the fixed axes of the primary (equivalently intrinsic z-y'-x'').
    """
    a = np.deg2rad(np.asarray(angles, dtype=float))
    if a.shape[-1:] != (3,):
        raise ValueError(f"angles must have shape (..., 3), not {a.shape}")
    cx, cy, cz = np.cos(a[..., 0]), np.cos(a[..., 1]), np.cos(a[..., 2])
    sx, sy, sz = np.sin(a[..., 0]), np.sin(a[..., 1]), np.sin(a[..., 2])
    R = np.empty(a.shape[:-1] + (3, 3))
    R[..., 0, 0] = cy * cz
    R[..., 0, 1] = cz * sy * sx - sz * cx
    R[..., 0, 2] = cz * sy * cx + sz * sx
    R[..., 1, 0] = cy * sz
    R[..., 1, 1] = sz * sy * sx + cz * cx
    R[..., 1, 2] = sz * sy * cx - cz * sx
    R[..., 2, 0] = -sy
    R[..., 2, 1] = cy * sx
    R[..., 2, 2] = cy * cx
    return R


def transform_from(R, p) -> np.ndarray:
    """Homogeneous transforms from rotations and translations.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    p : array_like, shape (..., 3)
        Broadcast against ``R``'s leading dimensions.

    Returns
    -------
    numpy.ndarray, shape (..., 4, 4)
        ``[[R, p], [0, 0, 0, 1]]``.
    """
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    lead = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    A = np.zeros(lead + (4, 4))
    A[..., :3, :3] = R
    A[..., :3, 3] = p
    A[..., 3, 3] = 1.0
    return A


def invert_transform(A) -> np.ndarray:
    """Inverse of rigid transforms, using ``R^T`` rather than a general inverse.

    Parameters
    ----------
    A : array_like, shape (..., 4, 4)
        Rigid transforms (orthonormal rotation block).

    Returns
    -------
    numpy.ndarray, shape (..., 4, 4)
        ``[[R^T, -R^T p], [0, 0, 0, 1]]``.
    """
    A = np.asarray(A, dtype=float)
    Rt = np.swapaxes(A[..., :3, :3], -1, -2)
    return transform_from(Rt, -np.einsum("...ij,...j->...i", Rt, A[..., :3, 3]))


def _check_angles(figure: Figure, angles) -> np.ndarray:
    a = np.asarray(angles, dtype=float)
    if a.ndim < 2 or a.shape[-2:] != (figure.n_joints, 3):
        raise ValueError(f"angles must have shape (..., {figure.n_joints}, 3) for this figure, not {a.shape}")
    return a


def joint_transforms(figure: Figure, angles) -> np.ndarray:
    """Each joint's secondary-to-primary transform ``Trans(L1) R Trans(-L2)``.

    Parameters
    ----------
    figure : Figure
    angles : array_like, shape (..., n_joints, 3)
        Degrees, in the figure's joint order.

    Returns
    -------
    numpy.ndarray, shape (..., n_joints, 4, 4)
    """
    a = _check_angles(figure, angles)
    loc1, loc2 = figure.locations
    R = matrix_from_euler_zyx(a)
    return transform_from(R, loc1 - np.einsum("...ij,...j->...i", R, loc2))


def pose_transforms(figure: Figure, angles) -> np.ndarray:
    """Link-to-model transforms of a figure, the CURRENT main link at identity.

    Parameters
    ----------
    figure : Figure
    angles : array_like, shape (..., n_joints, 3)
        Degrees, in the figure's joint order; typically ``(T, J, 3)`` for T
        frames.  Not clamped here (see :func:`clamp`).

    Returns
    -------
    numpy.ndarray, shape (..., n_links, 4, 4)
        Rigid transforms taking each link's coordinates to the model frame.
        Geometry scale and host placement are not included (see
        :func:`shape_transforms`).

    Notes
    -----
    Vectorised over frames; the only Python loop is over the depth levels of
    the tree seen from the current main link (``figure.traversal``), each
    level one batched matrix product.  Joints walked from secondary to
    primary use ``Trans(L2) R^T Trans(-L1)``.
    """
    a = _check_angles(figure, angles)
    lead = a.shape[:-2]
    a = a.reshape((int(np.prod(lead)), figure.n_joints, 3))  # -1 fails when n_joints == 0
    loc1, loc2 = figure.locations
    R = matrix_from_euler_zyx(a)  # (B, J, 3, 3)
    rev = figure.reversed_joints
    # Forward: rotation R, translation L1 - R L2.  Reversed (S to P):
    # rotation R^T, translation L2 - R^T L1.  Picking per joint keeps one
    # array of local transforms for the level loop below.
    Rl = np.where(rev[:, None, None], np.swapaxes(R, -1, -2), R)
    near = np.where(rev[:, None], loc2, loc1)
    far = np.where(rev[:, None], loc1, loc2)
    local = transform_from(Rl, near - np.einsum("...ij,...j->...i", Rl, far))
    X = np.empty((a.shape[0], figure.n_links, 4, 4))
    X[:, figure.main] = np.eye(4)
    for level in figure.traversal:
        X[:, level.children] = X[:, level.parents] @ local[:, level.joints]
    return X.reshape(lead + (figure.n_links, 4, 4))


# -- the reference implementation: plain loops, one frame at a time ----------


def _rx(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _ry(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])


def _rz(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _translation(v) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = v
    return T


def pose_transforms_reference(figure: Figure, angles) -> np.ndarray:
    """Same result as :func:`pose_transforms`, computed the slow obvious way.

    Per frame, walks the tree recursively from the current main link over
    every joint touching the link, composing ``Trans(L1) Rz Ry Rx Trans(-L2)``
    from single-axis matrices forwards and its general matrix inverse
    backwards.  For tests only.

    Parameters
    ----------
    figure : Figure
    angles : array_like, shape (..., n_joints, 3)

    Returns
    -------
    numpy.ndarray, shape (..., n_links, 4, 4)
    """
    a = _check_angles(figure, angles)
    out = np.empty(a.shape[:-2] + (figure.n_links, 4, 4))
    for idx in np.ndindex(*a.shape[:-2]):
        frame = a[idx]
        placed = {}

        def visit(link, X):
            placed[link] = X
            for k, joint in enumerate(figure.joints):
                ax, ay, az = frame[k]
                A = _translation(joint.loc1) @ _rz(az) @ _ry(ay) @ _rx(ax) @ _translation(-joint.loc2)
                if joint.primary == link and joint.secondary not in placed:
                    visit(joint.secondary, X @ A)
                elif joint.secondary == link and joint.primary not in placed:
                    visit(joint.primary, X @ np.linalg.inv(A))

        visit(figure.main, np.eye(4))
        for link in range(figure.n_links):
            out[idx + (link,)] = placed[link]
    return out


def shape_transforms(figure: Figure, angles) -> np.ndarray:
    """What the renderer applies to each link's shape coordinates.

    Parameters
    ----------
    figure : Figure
    angles : array_like, shape (..., n_joints, 3)

    Returns
    -------
    numpy.ndarray, shape (..., n_links, 4, 4)
        ``placement @ pose @ diag(s, s, s, 1)`` with ``s`` the link's scale
        (negative for a mirrored model, so these need not be rigid).
    """
    X = pose_transforms(figure, angles)
    S = np.ones((figure.n_links, 4))
    S[:, :3] = figure.link_scales[:, None]
    return np.asarray(figure.placement) @ X * S[:, None, :]


def free_axes(figure: Figure) -> dict[int, tuple[bool, bool, bool]]:
    """Which joint axes turn freely: extremes spanning 360 degrees or more.

    Returns
    -------
    dict of int to (bool, bool, bool)
        Per joint id, for X, Y and Z.
    """
    ext = figure.extremes
    free = ext[..., 1] - ext[..., 0] >= 360.0
    return {jid: tuple(bool(f) for f in row) for jid, row in zip(figure.joint_ids, free)}


def clamp(figure: Figure, angles) -> np.ndarray:
    """Enforce each joint's extremes over the motion's angles.

    Parameters
    ----------
    figure : Figure
    angles : array_like, shape (..., n_joints, 3)
        Degrees, in the figure's joint order.

    Returns
    -------
    numpy.ndarray, shape (..., n_joints, 3)
        Each axis clipped into ``[min, max]`` -- "the joint will enforce its
        extreme rotation limit over the motion specification" -- except on
        free axes (range of 360 degrees or more), which are wrapped into
        ``[min, min + 360)`` instead: there every angle is reachable, and
        clipping would make a spinning joint stop dead.
    """
    a = _check_angles(figure, angles)
    ext = figure.extremes
    lo, hi = ext[..., 0], ext[..., 1]
    free = hi - lo >= 360.0
    turns = np.mod(a - lo, 360.0)
    turns = np.where(turns >= 360.0, 0.0, turns)  # np.mod(-1e-17, 360) rounds to 360
    return np.where(free, lo + turns, np.clip(a, lo, hi))
