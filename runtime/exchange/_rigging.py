"""Small pieces of rotation and frame arithmetic that retargeting and its leg solver share."""

from __future__ import annotations

import numpy as np

from ._rotations import euler_zyx_from_matrix

__all__ = ["CLAMP_REPORT", "at_least", "fit_angles", "rotation_between", "runs"]

#: An angle moved into its extremes by more than this many degrees counts as a clamped frame.
CLAMP_REPORT = 1.0


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotations taking directions ``a`` onto ``b``, both (..., 3)."""
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    v = np.cross(a, b)
    c = np.einsum("...i,...i->...", a, b)
    K = np.zeros(v.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    K[..., 1, 0], K[..., 2, 0], K[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    opposite = c < -1 + 1e-9
    k = np.where(opposite, 0.0, 1.0 / np.maximum(1.0 + c, 1e-12))[..., None, None]
    R = np.eye(3) + K + K @ K * k
    if np.any(opposite):
        # Half a turn about any axis across a.
        axis = np.cross(a, np.where(np.abs(a[..., :1]) < 0.9, [1.0, 0, 0], [0, 1.0, 0]))
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        half = 2 * np.einsum("...i,...j->...ij", axis, axis) - np.eye(3)
        R = np.where(opposite[..., None, None], half, R)
    return R


def fit_angles(extremes: np.ndarray, R: np.ndarray):
    """A joint's angles for local rotations ``R`` (F, 3, 3): the Euler solution that clamps least, clamped.

    ``extremes`` is the joint's (3, 2) array.  Returns the clamped angles
    (F, 3) and whether each frame was clamped by more than :data:`CLAMP_REPORT`
    on an axis that can move (a locked axis drops its turn, which is not counted).
    """
    a = euler_zyx_from_matrix(R)
    # The other solution of Rz Ry Rx: (ax + 180, 180 - ay, az + 180).
    b = np.stack([a[:, 0] + 180.0, 180.0 - a[:, 1], a[:, 2] + 180.0], axis=1)
    b = (b + 180.0) % 360.0 - 180.0
    lo, hi = extremes[:, 0], extremes[:, 1]
    free = hi - lo >= 360.0

    def clamped(x):
        return np.where(free, x, np.clip(x, lo, hi))

    ca, cb = clamped(a), clamped(b)
    da = np.abs(ca - a).sum(axis=1)
    db = np.abs(cb - b).sum(axis=1)
    pick = (db < da - 1e-9)[:, None]
    raw = np.where(pick, b, a)
    out = np.where(pick, cb, ca)
    # Turning about a locked axis (extremes (a, a)) is a degree of freedom the joint lacks, not a clamp.
    movable = hi > lo
    return out, (np.abs(out - raw) * movable).max(axis=1) > CLAMP_REPORT


def at_least(mask: np.ndarray, n: int) -> np.ndarray:
    """``mask`` with runs of True shorter than ``n`` cleared."""
    out = mask.copy()
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        if b - a < n:
            out[a:b] = False
    return out


def runs(mask: np.ndarray) -> list:
    """``[(first, stop)]`` of each run of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))
