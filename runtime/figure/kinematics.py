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

import math
from collections.abc import Callable

import numpy as np

from liganimate.runtime.figure.tree import Figure

__all__ = [
    "matrix_from_euler_zyx",
    "transform_from",
    "invert_transform",
    "joint_transforms",
    "pose_transforms",
    "placed_transforms",
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
    a = np.asarray(angles, dtype=np.float64)
    if a.shape[-2:] != (figure.n_joints, 3) or a.ndim < 2:
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
    F = figure.frames
    R = F @ matrix_from_euler_zyx(a) @ np.swapaxes(F, -1, -2)
    slides = figure.slides
    R = np.where(slides[:, None, None], np.eye(3), R)
    shift = np.einsum("jik,...jk->...ji", F, a) * figure.slide_scales[:, None]
    t = loc1 - np.einsum("...ij,...j->...i", R, loc2) + np.where(slides[:, None], shift, 0.0)
    return transform_from(R, t)


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
    the tree seen from the current main link (``figure.traversal``).  Joints
    walked from secondary to primary use ``Trans(L2) R^T Trans(-L1)``.  See
    :func:`placed_transforms` for how it is computed.
    """
    a = _check_angles(figure, angles)
    if a.ndim == 3:
        return placed_transforms(figure, a, None)
    lead = a.shape[:-2]
    a = a.reshape((math.prod(lead), figure.n_joints, 3))  # -1 fails when n_joints == 0
    return placed_transforms(figure, a, None).reshape(lead + (figure.n_links, 4, 4))


def placed_transforms(figure: Figure, angles: np.ndarray, root) -> np.ndarray:
    """Link transforms for a batch of poses, each composed onto a root transform.

    Parameters
    ----------
    figure : Figure
    angles : numpy.ndarray, shape (B, n_joints, 3)
        Degrees, in the figure's joint order.
    root : numpy.ndarray, shape (B, 4, 4), or None
        Where each pose's current main link goes (an affine map, e.g. the
        host's placement); None for the identity.

    Returns
    -------
    numpy.ndarray, shape (B, n_links, 4, 4)
        ``root @ pose`` for every link: for more than one pose a view of
        other storage, not C-contiguous (``np.ascontiguousarray`` makes it
        so).

    Notes
    -----
    A batch of fewer than :data:`SHORT` poses (one pose, the renderer's
    batches) is computed by
    :func:`liganimate.runtime.figure.short.placed_short`: the walk down the
    tree laid out once per figure as a fixed list of about thirty numpy
    calls (gathers and elementwise products and sums; one product per depth
    level of the tree), whatever the number of joints.  A longer one by
    :func:`liganimate.runtime.figure.folded.placed_long` (one joint at a
    time over contiguous rows of frames, the arithmetic of each joint's
    kind only).  Both compute every entry with the operations of a 4x4
    product in the same order, summed ``m = 0, 1, 2`` then the
    translation, with elementwise numpy only (never BLAS), so the result
    is the same on every machine and for any batch size (an exact zero
    may differ in sign).
    """
    B = angles.shape[0]
    if 0 < B < SHORT:
        return _placed_short(figure, angles, None if root is None else np.asarray(root, dtype=np.float64))
    return _placed_long(figure, angles, root)


# The two walks are imported on first use, not with this module: `check` and
# every program that poses nothing (the matrices above are all it needs) would
# pay for their set-up at start-up.
_walks: tuple[Callable[..., np.ndarray], Callable[..., np.ndarray]] | None = None


def _placed_short(figure, angles, root) -> np.ndarray:
    return (_walks or _import_walks())[0](figure, angles, root)


def _placed_long(figure, angles, root) -> np.ndarray:
    return (_walks or _import_walks())[1](figure, angles, root)


def _import_walks() -> tuple[Callable[..., np.ndarray], Callable[..., np.ndarray]]:
    global _walks
    from liganimate.runtime.figure.folded import placed_long
    from liganimate.runtime.figure.short import placed_short

    _walks = (placed_short, placed_long)
    return _walks


SHORT = 256
"""Batches shorter than this take :mod:`.short`: there the number of numpy calls is the cost."""


def _local_transforms(figure: Figure, joints: np.ndarray, values: np.ndarray):
    """Rotations (3, 3, k, B) and translations (3, k, B) of some joints, as walked from the main link.

    ``values`` (3, k, B) holds the joints' angles in degrees (a slide's
    displacement), axis first.
    """
    (cx, cy, cz), (sx, sy, sz) = _cos_sin(np.deg2rad(values))
    # Entry by entry as in matrix_from_euler_zyx.
    R = np.empty((3, 3) + values.shape[1:])
    R[0, 0] = cy * cz
    R[0, 1] = cz * sy * sx - sz * cx
    R[0, 2] = cz * sy * cx + sz * sx
    R[1, 0] = cy * sz
    R[1, 1] = sz * sy * sx + cz * cx
    R[1, 2] = sz * sy * cx - cz * sx
    np.negative(sy, out=R[2, 0])
    R[2, 1] = cy * sx
    R[2, 2] = cy * cx
    framed = figure.has_frames[joints]
    if framed.any():
        # AXIS: the angles turn about the joint's own axes, F R F^T.
        F = figure.frames[joints[framed]].transpose(1, 2, 0)[:, :, :, None]  # (3, 3, f, 1)
        Rf = R[:, :, framed]
        FR = np.einsum("iafb,abfc->ibfc", F, Rf)
        R[:, :, framed] = np.einsum("ibfc,jbfd->ijfc", FR, F)
    slides = figure.slides[joints]
    if slides.any():
        R[:, :, slides] = np.eye(3)[:, :, None, None]
    rev = figure.reversed_joints[joints]
    loc1, loc2 = figure.locations
    loc1, loc2 = loc1[joints], loc2[joints]
    if rev.any():
        # Walked from the secondary: R^T, and L2 - R^T L1.
        R[:, :, rev] = R[:, :, rev].transpose(1, 0, 2, 3)
    near = np.where(rev[:, None], loc2, loc1).T[:, :, None]  # (3, k, 1)
    far = np.where(rev[:, None], loc1, loc2).T[:, :, None]
    T = near - (R[:, 0] * far[0] + R[:, 1] * far[1] + R[:, 2] * far[2])
    if slides.any():
        # A slide moves S by k F d along its axes; walked backwards, P moves by -k F d.
        k = joints[slides]
        F = figure.frames[k]  # (s, 3, 3)
        d = values[:, slides]  # (3, s, B)
        gain = (figure.slide_scales[k] * np.where(rev[slides], -1.0, 1.0))[:, None]
        T[:, slides] += np.einsum("sia,asb->isb", F, d) * gain
    return R, T


def _cos_sin(a: np.ndarray):
    """``cos`` and ``sin`` of ``a`` (3, J, B); rows that hold still are computed once.

    Most axes hold still over a motion (pinned by their extremes, or not
    driven), and the trigonometry is the costliest step.
    """
    rows = a.reshape(-1, a.shape[-1])
    first = rows[:, :1]
    moving = np.flatnonzero((rows != first).any(axis=1))
    c = np.empty_like(rows)
    s = np.empty_like(rows)
    c[...] = np.cos(first)
    s[...] = np.sin(first)
    if len(moving):
        m = rows[moving]
        c[moving] = np.cos(m)
        s[moving] = np.sin(m)
    return c.reshape(a.shape), s.reshape(a.shape)


# -- the reference implementation: plain loops, one frame at a time ----------


def rotation(axis: str, degrees: float) -> np.ndarray:
    """The (4, 4) rotation by ``degrees`` about ``axis`` ("X", "Y" or "Z"), right-handed."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    i, j = _PLANES[axis]
    m = np.eye(4)
    m[i, i] = c
    m[i, j] = -s
    m[j, i] = s
    m[j, j] = c
    return m


_PLANES = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}  # the axes each rotation turns, first towards second


def translation(v) -> np.ndarray:
    """The (4, 4) translation by ``v`` (3,)."""
    T = np.eye(4)
    T[:3, 3] = v
    return T


def scaling(k) -> np.ndarray:
    """The (4, 4) scaling by ``k``: a number, or (3,) factors along x, y and z."""
    m = np.eye(4)
    m[:3, :3] = np.diag(np.asarray(k, dtype=np.float64) * np.ones(3))
    return m


def _rx(deg: float) -> np.ndarray:
    return rotation("X", deg)


def _ry(deg: float) -> np.ndarray:
    return rotation("Y", deg)


def _rz(deg: float) -> np.ndarray:
    return rotation("Z", deg)


_translation = translation


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

        # visit runs within this iteration, so the loop's frame and placed are the ones meant.
        def visit(link, X):  # noqa: B023
            placed[link] = X  # noqa: B023
            for k, joint in enumerate(figure.joints):
                A = _reference_joint(joint, frame[k])  # noqa: B023
                if joint.primary == link and joint.secondary not in placed:  # noqa: B023
                    visit(joint.secondary, X @ A)
                elif joint.secondary == link and joint.primary not in placed:  # noqa: B023
                    visit(joint.primary, X @ np.linalg.inv(A))

        visit(figure.main, np.eye(4))
        for link in range(figure.n_links):
            out[idx + (link,)] = placed[link]
    return out


def _reference_joint(joint, values) -> np.ndarray:
    """One joint's secondary-to-primary transform, composed from single-axis matrices."""
    F = np.eye(4)
    if joint.axes is not None:
        F[:3, :3] = joint.axes
    if joint.slide:
        move = _translation(joint.slide_scale * (F[:3, :3] @ np.asarray(values, dtype=float)))
    else:
        ax, ay, az = values
        move = F @ _rz(az) @ _ry(ay) @ _rx(ax) @ F.T
    return _translation(joint.loc1) @ move @ _translation(-joint.loc2)


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
    free = (ext[..., 1] - ext[..., 0] >= 360.0) & ~figure.slides[:, None]
    return {jid: (bool(row[0]), bool(row[1]), bool(row[2])) for jid, row in zip(figure.joint_ids, free)}


def clamp(figure: Figure, angles, out=None) -> np.ndarray:
    """Enforce each joint's extremes over the motion's angles.

    Parameters
    ----------
    figure : Figure
    angles : array_like, shape (..., n_joints, 3)
        Degrees, in the figure's joint order.
    out : numpy.ndarray, optional
        Where to write the result (may be ``angles`` itself).

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
    free = (hi - lo >= 360.0) & ~figure.slides[:, None]  # a slide never wraps round
    if not free.any():
        return np.clip(a, lo, hi, out=out)
    turns = np.mod(a - lo, 360.0)
    turns = np.where(turns >= 360.0, 0.0, turns)  # np.mod(-1e-17, 360) rounds to 360
    result = np.where(free, lo + turns, np.clip(a, lo, hi))
    if out is None:
        return result
    out[...] = result
    return out
