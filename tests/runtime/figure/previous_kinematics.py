"""The batched forward kinematics as it was before issue 22, kept to cross-check the new one.

``placed_transforms`` here is the previous
``liganimate.runtime.figure.kinematics.placed_transforms``, verbatim: every
joint's local transform from the full three-axis formula, then one joint
at a time down the tree with two ``einsum`` calls each.  The new paths
(``runtime/figure/short.py`` for short batches, ``runtime/figure/folded.py``
for long ones) must give the same numbers (``test_walk.py``, ``test_short.py``).
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.tree import Figure


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
        ``root @ pose`` for every link: a view of component-major storage,
        not C-contiguous (``np.ascontiguousarray`` makes it so).

    Notes
    -----
    Computed component-major: every entry of every joint's rotation and
    translation is one contiguous array over the batch, so each step is one
    long vector operation (numpy is slow on trailing axes of length 3 or 4,
    and batched 4x4 ``matmul`` spends most of its time on overhead and on
    the constant bottom row).  A child link's transform is its parent's
    times the joint's, ``R = Rp Rj`` and ``t = Rp tj + tp``, summed in
    the order a 4x4 product would.  Only elementwise operations are used,
    never BLAS, so the result is the same on every machine.
    """
    B, J, L = angles.shape[0], figure.n_joints, figure.n_links
    # Component-major storage: buf[i, j, link] holds entry (i, j) of that
    # link's transform for every frame, contiguous; the result is a
    # transposed view of it, so nothing is copied into frame-major order.
    buf = np.empty((4, 4, L, B))
    buf[3, :3] = 0.0
    buf[3, 3] = 1.0
    if B == 0:
        return buf.transpose(3, 2, 0, 1)
    if root is not None:
        root = np.asarray(root, dtype=np.float64)
    # Joints whose angles hold still over the batch (not driven, or pinned
    # by their extremes) have one local transform, computed once.
    flat = angles.reshape(B, -1)
    moving = np.flatnonzero((flat != flat[0]).any(axis=0).reshape(J, 3).any(axis=1))
    R0, T0 = _local_transforms(figure, np.arange(J), angles[:1].transpose(2, 1, 0))
    values = np.ascontiguousarray(angles[:, moving].transpose(2, 1, 0))  # (3, moving, B), contiguous
    # Blocks of frames small enough for the intermediates to stay in cache.
    for lo in range(0, B, _BLOCK):
        hi = min(lo + _BLOCK, B)
        R = np.empty((3, 3, J, hi - lo))
        T = np.empty((3, J, hi - lo))
        R[...] = R0
        T[...] = T0
        if len(moving):
            R[:, :, moving], T[:, moving] = _local_transforms(figure, moving, values[:, :, lo:hi])
        _compose(figure, R, T, None if root is None else root[lo:hi], buf[:, :, :, lo:hi])
    return buf.transpose(3, 2, 0, 1)


_BLOCK = 4096


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


def _compose(figure: Figure, R: np.ndarray, T: np.ndarray, root, buf: np.ndarray) -> None:
    """Walk the tree: fill ``buf`` (4, 4, n_links, B) from the joints' local transforms."""
    main = figure.main
    XR = buf[:3, :3]  # XR[i, j, link]: entry (i, j) of the link's rotation, over the frames
    Xt = buf[:3, 3]
    if root is None:
        XR[:, :, main] = np.eye(3)[:, :, None]
        Xt[:, main] = 0.0
    else:
        XR[:, :, main] = root[:, :3, :3].transpose(1, 2, 0)
        Xt[:, main] = root[:, :3, 3].T
    for k, p, c in _walk_order(figure):
        # Link c = link p through joint k: R = P Rj and t = P tj + tp, each
        # entry summed over m = 0, 1, 2 in order, as a 4x4 product would
        # (einsum without optimize: no BLAS).  Slices keep every operand a view.
        P = XR[:, :, p]
        np.einsum("imkb,mjkb->ijkb", P, R[:, :, k], out=XR[:, :, c])
        t = np.einsum("imkb,mkb->ikb", P, T[:, k], out=Xt[:, c])
        t += Xt[:, p]


def _walk_order(figure: Figure) -> list:
    """(joint, parent link, child link) as one-element slices, parents placed before children."""
    levels = figure.traversal
    hit = _WALKS.get(id(levels))
    if hit is not None and hit[0] is levels:
        return hit[1]
    order = [
        tuple(slice(int(v), int(v) + 1) for v in row)
        for level in levels
        for row in zip(level.joints, level.parents, level.children)
    ]
    if len(_WALKS) >= 256:
        _WALKS.clear()
    _WALKS[id(levels)] = (levels, order)
    return order


_WALKS: dict = {}  # id(figure.traversal) -> (traversal, walk order); the stored traversal keeps the id valid


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
