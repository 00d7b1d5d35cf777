"""Forward kinematics for long batches: one joint at a time over contiguous frames, constants folded.

The long-batch half of :func:`liganimate.runtime.figure.kinematics.placed_transforms`
(:mod:`.short` holds the short-batch half; :mod:`.walk` the walk both use).  Storage is
component-major, as it always was: entry ``(i, j)`` of link ``l``'s
transform is one contiguous row over the frames, so every numpy call runs
over thousands of numbers.  Joints are composed one by one, parents first,
and every matrix entry is either such a row or a plain number, **folded**:

* an axis whose angle holds still over the batch has its cosine and sine as
  numbers (computed by numpy, so the very same bits), and one that holds at
  zero contributes exact 1s and 0s;
* a product with an exact 0 is dropped, one with an exact 1 is the other
  factor, and a sum with a dropped term is the other term.

So a hinge costs the arithmetic of a hinge (four entries of a rotation, a
dozen products to compose it) and a fixed joint almost nothing, instead of
the full three-axis formula and 3x3 product for every joint.  The sums
that remain are the same operations in the same order as
:func:`~liganimate.runtime.figure.kinematics.matrix_from_euler_zyx` and a
4x4 product (``m = 0, 1, 2``, then the translation), so every number is the
same as without folding, except that an exact zero may come out with the
other sign (``-0.0`` for ``0.0``), which compares equal and draws the same.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.tree import Figure
from liganimate.runtime.figure.walk import walk_of

__all__ = ["placed_long"]


def _mul(a, b):
    if isinstance(a, float):
        if a == 0.0:
            return 0.0
        if a == 1.0:
            return b
        if isinstance(b, float):
            return a * b
    if isinstance(b, float):
        if b == 0.0:
            return 0.0
        if b == 1.0:
            return a
    return a * b


def _add(a, b):
    if isinstance(a, float) and a == 0.0:
        return b
    if isinstance(b, float) and b == 0.0:
        return a
    return a + b


def _sub(a, b):
    if isinstance(b, float) and b == 0.0:
        return a
    if isinstance(a, float) and a == 0.0:
        return -b
    return a - b


def _rotation(cs) -> list:
    """``Rz Ry Rx`` as nine entries, in the operations of ``matrix_from_euler_zyx``."""
    (cx, cy, cz), (sx, sy, sz) = cs
    czsy, szsy = _mul(cz, sy), _mul(sz, sy)
    return [
        [_mul(cy, cz), _sub(_mul(czsy, sx), _mul(sz, cx)), _add(_mul(czsy, cx), _mul(sz, sx))],
        [_mul(cy, sz), _add(_mul(szsy, sx), _mul(cz, cx)), _sub(_mul(szsy, cx), _mul(cz, sx))],
        [-sy, _mul(cy, sx), _mul(cy, cx)],
    ]


def placed_long(figure: Figure, angles: np.ndarray, root) -> np.ndarray:
    """Link transforms ``root @ pose`` (B, n_links, 4, 4) for angles (B, n_joints, 3); see ``placed_transforms``.

    A transposed view of component-major storage, not C-contiguous.
    """
    walk = walk_of(figure)
    B, J, L = angles.shape[0], figure.n_joints, figure.n_links
    buf = np.empty((4, 4, L, B))
    buf[3, :3] = 0.0
    buf[3, 3] = 1.0
    if B == 0:
        return buf.transpose(3, 2, 0, 1)
    rows = np.ascontiguousarray(angles.transpose(2, 1, 0)).reshape(3 * J, B)  # row a * J + k: axis a of joint k
    cs = _cos_sin(np.deg2rad(rows))
    entries: list = [None] * L  # per link: (3x3 rotation entries, 3 translation entries), rows or numbers
    main = figure.main
    if root is None:
        entries[main] = ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [0.0, 0.0, 0.0])
    else:
        root = np.asarray(root, dtype=np.float64)
        rt = np.ascontiguousarray(root[:, :3].transpose(1, 2, 0))  # (3, 4, B)
        entries[main] = ([[rt[i, j] for j in range(3)] for i in range(3)], [rt[i, 3] for i in range(3)])
    general = _general(figure, walk, rows)
    for q, k in enumerate(walk.order.tolist()):
        parent, child = walk.parent_link[q], walk.child_link[q]
        R, T = general[q] if q in general else _plain(walk, q, k, J, cs)
        P, tp = entries[parent]
        CR = [[_dot3(P[i], R, j) for j in range(3)] for i in range(3)]
        Ct = [_add(_add(_add(_mul(P[i][0], T[0]), _mul(P[i][1], T[1])), _mul(P[i][2], T[2])), tp[i]) for i in range(3)]
        for i in range(3):
            for j in range(3):
                buf[i, j, child] = CR[i][j]
                if not isinstance(CR[i][j], float):
                    CR[i][j] = buf[i, j, child]
            buf[i, 3, child] = Ct[i]
            if not isinstance(Ct[i], float):
                Ct[i] = buf[i, 3, child]
        entries[child] = (CR, Ct)
    P, tp = entries[main]
    for i in range(3):
        for j in range(3):
            buf[i, j, main] = P[i][j]
        buf[i, 3, main] = tp[i]
    return buf.transpose(3, 2, 0, 1)


def _dot3(Pi: list, R: list, j: int):
    """``sum_m P[i, m] R[m, j]``, m = 0, 1, 2 in order, folded."""
    return _add(_add(_mul(Pi[0], R[0][j]), _mul(Pi[1], R[1][j])), _mul(Pi[2], R[2][j]))


def _plain(walk, q: int, k: int, J: int, cs):
    """Rotation and translation entries of an ordinary joint (no AXIS, not a slide), folded."""
    c, s = cs
    R = _rotation(((c[k], c[J + k], c[2 * J + k]), (s[k], s[J + k], s[2 * J + k])))
    if walk.reversed[q]:
        R = [[R[j][i] for j in range(3)] for i in range(3)]
    near, far = walk.near_list[q], walk.far_list[q]
    T = [
        _sub(near[i], _add(_add(_mul(R[i][0], far[0]), _mul(R[i][1], far[1])), _mul(R[i][2], far[2]))) for i in range(3)
    ]
    return R, T


def _general(figure: Figure, walk, rows: np.ndarray) -> dict:
    """Entries of the joints with an AXIS or a slide, from the general formula (no folding)."""
    from liganimate.runtime.figure.kinematics import _local_transforms

    special = np.flatnonzero(figure.has_frames[walk.order] | figure.slides[walk.order])
    if not len(special):
        return {}
    joints = walk.order[special]
    J = figure.n_joints
    values = np.stack([rows[a * J + joints] for a in range(3)])  # (3, k, B)
    R, T = _local_transforms(figure, joints, values)
    return {
        int(q): ([[R[i, j, n] for j in range(3)] for i in range(3)], [T[i, n] for i in range(3)])
        for n, q in enumerate(special)
    }


def _cos_sin(a: np.ndarray):
    """Per row of ``a`` (rows, B): its cosine and sine, as a row, or as a number where the row holds still."""
    first = a[:, :1]
    moving = (a != first).any(axis=1)
    c0 = np.cos(first[:, 0]).tolist()
    s0 = np.sin(first[:, 0]).tolist()
    c: list = list(c0)
    s: list = list(s0)
    idx = np.flatnonzero(moving)
    if len(idx):
        m = a[idx]
        cm, sm = np.cos(m), np.sin(m)
        for n, r in enumerate(idx.tolist()):
            c[r] = cm[n]
            s[r] = sm[n]
    return c, s
