"""Rotations for the exchange formats: Euler angles of any order, quaternions, TRS, batched.

Every function takes a leading batch of any shape and works on all of it at
once.  Angles are in degrees, as in the language.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx

__all__ = [
    "continuous_quaternions",
    "decompose_trs",
    "euler_from_matrix",
    "euler_zyx_from_matrix",
    "matrix_from_axes",
    "matrix_from_euler_zyx",
    "quaternion_from_matrix",
]


def _axis_matrices(axis: str, deg: np.ndarray) -> np.ndarray:
    """Rotations about one coordinate axis, shape ``deg.shape + (3, 3)``."""
    a = np.deg2rad(deg)
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(deg.shape + (3, 3))
    i, j = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}[axis]
    k = 3 - i - j
    R[..., k, k] = 1.0
    R[..., i, i] = c
    R[..., i, j] = -s
    R[..., j, i] = s
    R[..., j, j] = c
    return R


def matrix_from_axes(order: str, angles) -> np.ndarray:
    """The rotation ``R = R_order[0](a0) R_order[1](a1) ...``, as BVH channels compose.

    Parameters
    ----------
    order : str
        Axis letters, e.g. ``"ZXY"``: a BVH joint's rotation channels in the
        order they are listed (the first listed is the outermost factor).
    angles : array_like, shape (..., len(order))
        Degrees, in the same order.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
    """
    a = np.asarray(angles, dtype=np.float64)
    R = np.broadcast_to(np.eye(3), a.shape[:-1] + (3, 3)).copy()
    for n, axis in enumerate(order):
        R = R @ _axis_matrices(axis, a[..., n])
    return R


def euler_zyx_from_matrix(R) -> np.ndarray:
    """The joint convention's angles of rotation matrices: ``R = Rz(az) Ry(ay) Rx(ax)``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ``(ax, ay, az)`` in degrees, ``ay`` in [-90, 90] and the others in
        (-180, 180].  At gimbal lock (``ay`` = +-90, where only ``ax - az``
        or ``ax + az`` is defined) ``az`` is 0.
    """
    R = np.asarray(R, dtype=np.float64)
    cy = np.hypot(R[..., 0, 0], R[..., 1, 0])
    ay = np.arctan2(-R[..., 2, 0], cy)
    ax = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    az = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    lock = cy < 1e-12
    if lock.any():
        # sy = +1: R01 = sin(ax - az), R11 = cos(ax - az); sy = -1: R01 = -sin(ax + az).
        sign = np.where(R[..., 2, 0] < 0, 1.0, -1.0)
        ax = np.where(lock, np.arctan2(sign * R[..., 0, 1], R[..., 1, 1]), ax)
        az = np.where(lock, 0.0, az)
    return np.rad2deg(np.stack([ax, ay, az], axis=-1))


def euler_from_matrix(order: str, R) -> np.ndarray:
    """Angles of three distinct axes that compose to ``R`` as BVH channels do: ``R = Ra(a) Rb(b) Rc(c)``.

    Parameters
    ----------
    order : str
        Three distinct axis letters, e.g. ``"ZXY"`` (the first is the
        outermost factor, as in :func:`matrix_from_axes`).
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Degrees, in ``order``'s order: the middle angle in [-90, 90], the
        others in (-180, 180].  At gimbal lock the last angle is 0.
    """
    R = np.asarray(R, dtype=np.float64)
    i, j, k = ("XYZ".index(a) for a in order)
    # +1 for a cyclic order (XYZ, YZX, ZXY), -1 for the others.
    s = 1.0 if (j - i) % 3 == 1 else -1.0
    c = np.hypot(R[..., i, i], R[..., i, j])
    b = np.arctan2(s * R[..., i, k], c)
    a = np.arctan2(-s * R[..., j, k], R[..., k, k])
    g = np.arctan2(-s * R[..., i, j], R[..., i, i])
    lock = c < 1e-12
    if lock.any():
        # Only a combination of the outer angles is defined: put it all on the first.
        a = np.where(lock, np.arctan2(s * R[..., k, j], R[..., j, j]), a)
        g = np.where(lock, 0.0, g)
    return np.rad2deg(np.stack([a, b, g], axis=-1))


def quaternion_from_matrix(R) -> np.ndarray:
    """Unit quaternions ``(x, y, z, w)`` (glTF's order) of rotation matrices.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        With ``w >= 0``; computed from the largest of the four candidate
        diagonals (Shepperd's method), so every branch is well conditioned.
    """
    R = np.asarray(R, dtype=np.float64)
    m00, m11, m22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    cand = np.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], axis=-1)
    best = np.argmax(cand, axis=-1)
    q = np.empty(R.shape[:-2] + (4,))
    d01, s01 = R[..., 1, 0] - R[..., 0, 1], R[..., 1, 0] + R[..., 0, 1]
    d02, s02 = R[..., 0, 2] - R[..., 2, 0], R[..., 0, 2] + R[..., 2, 0]
    d12, s12 = R[..., 2, 1] - R[..., 1, 2], R[..., 2, 1] + R[..., 1, 2]
    for b, (x, y, z, w) in enumerate(
        [(d12, d02, d01, None), (None, s01, s02, d12), (s01, None, s12, d02), (s02, s12, None, d01)]
    ):
        sel = best == b
        if not sel.any():
            continue
        r = np.sqrt(np.maximum(cand[..., b][sel], 0.0))  # 2 |component|
        half = 0.5 / r
        comps = [x, y, z, w]
        for c in range(4):
            q[..., c][sel] = 0.5 * r if comps[c] is None else comps[c][sel] * half
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    q *= np.where(q[..., 3:] < 0, -1.0, 1.0)
    return q


def continuous_quaternions(q: np.ndarray) -> np.ndarray:
    """Flip signs along axis 0 so that each quaternion is in the half-space of the one before.

    ``q`` and ``-q`` are the same rotation; interpolating between neighbours
    of opposite sign would take the long way round.  Shape (T, ..., 4).
    """
    if len(q) < 2:
        return q
    dots = np.einsum("t...i,t...i->t...", q[1:], q[:-1])
    flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
    out = q.copy()
    out[1:] *= flips[..., None]
    return out


def decompose_trs(M, tol: float = 1e-9):
    """Split affine 4x4 transforms into translation, rotation and per-axis scale: ``M = T R S``.

    Parameters
    ----------
    M : array_like, shape (..., 4, 4)
    tol : float
        Relative tolerance on the orthogonality of the rotation found.

    Returns
    -------
    t : numpy.ndarray, shape (..., 3)
    R : numpy.ndarray, shape (..., 3, 3)
        Proper rotations.
    s : numpy.ndarray, shape (..., 3)
        Scale factors; a mirror puts its sign on the X factor.
    ok : numpy.ndarray of bool, shape (...)
        False where ``M`` shears (its columns are not orthogonal), so that
        no ``T R S`` reproduces it.
    """
    M = np.asarray(M, dtype=np.float64)
    A = M[..., :3, :3]
    s = np.linalg.norm(A, axis=-2)
    s = np.where(s == 0, 1.0, s)
    neg = np.linalg.det(A) < 0
    s[..., 0] = np.where(neg, -s[..., 0], s[..., 0])
    R = A / s[..., None, :]
    err = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-2, -1))
    ok = err <= tol
    return M[..., :3, 3].copy(), R, s, ok
