"""The short-batch walk as it was before the one-pose plan (issue 22), kept to cross-check it.

``placed`` here is the previous ``liganimate.runtime.figure.walk.placed``,
verbatim (with its own copy of the walk's preparation): every joint's 4x4
at once from stacked cosines and sines, then one product per depth level
of the tree, over 5-D broadcast arrays.  ``runtime/figure/short.py`` does
the same arithmetic as a fixed list of gathers and sums and must give the
same doubles, bit for bit (``test_short.py``).

Its notes, as they were:

:func:`liganimate.runtime.figure.kinematics.placed_transforms` is computed
here.  Per figure (per tree walk from its current main link) a
:class:`Walk` is prepared once: the links in breadth-first order, so that
the children of one depth level are one contiguous slice, and the joints
in the same order.  Then, for a batch of poses:

1. **Local transforms of all joints at once**, as 4x4 matrices laid out
   component-major, ``A[i, j, joint, frame]``.  The nine rotation entries of
   ``Rz(az) Ry(ay) Rx(ax)`` are computed as eleven rows of one array from
   six stacked cosines and sines, with the very operations (and in the very
   order) of :func:`~liganimate.runtime.figure.kinematics.matrix_from_euler_zyx`,
   then put in place (transposed for a joint walked backwards, the identity
   for a slide) by one gather.  A joint with its own AXIS gets ``F R F^T``;
   the translation is ``near - R far`` (``L1 - R L2``, or ``L2 - R^T L1``
   backwards), computed as ``sum_m R[:, m] (-far[m]) + near``, which is the
   same number bit for bit.
2. **One product per depth level** of the tree: every child of the level is
   its parent's 3x4 ``[R | t]`` times its joint's 4x4, each entry summed over
   ``m = 0..3`` in order (``np.add.reduce`` over a leading axis, which adds
   in sequence; no BLAS, so the numbers do not depend on the machine).  The
   bottom row's 0s add nothing and its 1 adds the parent's translation: the
   sums are those of a 4x4 product, the same as the previous per-joint walk
   (``tests/runtime/figure/test_walk.py`` checks the two agree).

So the number of numpy calls depends on the depth of the tree, not on the
number of joints or frames: about forty for a humanoid (one pose takes
:mod:`.single`, the same arithmetic in fewer and cheaper calls), while a
large batch is worked through in blocks of :data:`BLOCK` frames, small
enough for every intermediate to stay in cache.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from liganimate.runtime.figure.tree import Figure

__all__ = ["BLOCK", "Walk", "walk_of", "placed"]

BLOCK = 256
"""Frames worked on together: the per-level products (3x4x4 entries for a level's joints) stay in cache."""

# Rows of the entry array E, from which one gather builds every joint's 4x4:
# 0-3 cy*(cz, sz, cx, sx) = R00, R10, R22, R21;  4-7 R02, R01, R12, R11;
# 8 R20 = -sy;  9 zero;  10 one.
_PLAIN = (0, 5, 4, 9, 1, 7, 6, 9, 8, 3, 2, 9, 9, 9, 9, 10)
_TRANSPOSED = (0, 1, 8, 9, 5, 7, 3, 9, 4, 6, 2, 9, 9, 9, 9, 10)
_IDENTITY = (10, 9, 9, 9, 9, 10, 9, 9, 9, 9, 10, 9, 9, 9, 9, 10)
# U + sign * V gives R02, R01, R12, R11 (see _local).
_SIGN = np.array([[1.0, -1.0], [-1.0, 1.0]])[:, :, None, None]


@dataclass(frozen=True, eq=False)
class Walk:
    """What one figure's walk needs, prepared once (see the module's notes).

    Joints are numbered in walk order: joint ``order[q]`` of the figure is
    the one that places link ``links[q + 1]``.
    """

    order: np.ndarray  # (J,) the figure's joint index of each walked joint
    links: np.ndarray  # (L,) the figure's link at each breadth-first place; links[0] is the main link
    where: np.ndarray  # (L,) the breadth-first place of each of the figure's links
    levels: tuple  # per depth level: (first child place, end, parent places (n,), first joint, end joint)
    gather: np.ndarray  # (16, J) the rows of E forming each joint's 4x4
    columns: np.ndarray  # (1, J) 0 .. J-1
    near: np.ndarray  # (3, J, 1)
    minus_far: np.ndarray  # (1, 3, J, 1): -far[m] for the sum over m
    framed: np.ndarray  # (f,) walk numbers of joints with an AXIS
    frames: np.ndarray  # (3, 3, f, 1) their axes F, F[i, a]
    framed_reversed_in_framed: np.ndarray  # (g,) which of those are walked backwards
    slides: np.ndarray  # (s,) walk numbers of slides
    slide_axes: np.ndarray  # (3, 3, s, 1) their axes F, F[i, a]
    slide_gain: np.ndarray  # (s, 1)
    # For the long-batch walk (.folded), per walked joint, as Python values:
    parent_link: tuple  # the link it hangs from
    child_link: tuple  # the link it places
    reversed: tuple  # walked secondary to primary
    near_list: tuple  # near, far as floats
    far_list: tuple


def walk_of(figure: Figure) -> Walk:
    """The figure's :class:`Walk`, remembered per tree walk (a few hundred)."""
    levels = figure.traversal
    hit = _WALKS.get(id(levels))
    if hit is not None and hit[0] is levels and hit[1] is figure.joints:
        return hit[2]
    walk = _prepare(figure)
    if len(_WALKS) >= 256:
        _WALKS.clear()
    _WALKS[id(levels)] = (levels, figure.joints, walk)
    return walk


_WALKS: dict = {}  # id(traversal) -> (traversal, joints, Walk); the stored objects keep the id valid


def _prepare(figure: Figure) -> Walk:
    J = figure.n_joints
    order = np.array([int(k) for level in figure.traversal for k in level.joints], dtype=np.intp)
    links = np.array([figure.main] + [int(c) for level in figure.traversal for c in level.children], dtype=np.intp)
    where = np.empty(figure.n_links, dtype=np.intp)
    where[links] = np.arange(figure.n_links)
    levels, first = [], 1
    for level in figure.traversal:
        n = len(level.joints)
        levels.append((first, first + n, where[level.parents], first - 1, first - 1 + n))
        first += n
    rev = figure.reversed_joints[order]
    slides = figure.slides[order]
    framed = figure.has_frames[order] & ~slides  # a slide's axes move it; it never turns
    gather = np.empty((16, J), dtype=np.intp)
    for q in range(J):
        pattern = _IDENTITY if slides[q] else _TRANSPOSED if rev[q] and not framed[q] else _PLAIN
        gather[:, q] = pattern
    loc1, loc2 = figure.locations
    loc1, loc2 = loc1[order], loc2[order]
    near = np.where(rev[:, None], loc2, loc1)
    far = np.where(rev[:, None], loc1, loc2)
    F = figure.frames[order]
    k = order[slides]
    return Walk(
        order=order,
        links=links,
        where=where,
        levels=tuple(levels),
        gather=gather,
        columns=np.arange(J)[None, :],
        near=np.ascontiguousarray(near.T[:, :, None]),
        minus_far=np.ascontiguousarray(-far.T)[None, :, :, None],
        framed=np.flatnonzero(framed),
        frames=np.ascontiguousarray(F[framed].transpose(1, 2, 0)[:, :, :, None]),
        framed_reversed_in_framed=np.flatnonzero(rev[framed]),
        slides=np.flatnonzero(slides),
        slide_axes=np.ascontiguousarray(figure.frames[k].transpose(1, 2, 0)[:, :, :, None]),
        slide_gain=(figure.slide_scales[k] * np.where(rev[slides], -1.0, 1.0))[:, None],
        parent_link=tuple(int(p) for level in figure.traversal for p in level.parents),
        child_link=tuple(int(c) for level in figure.traversal for c in level.children),
        reversed=tuple(bool(r) for r in rev),
        near_list=tuple(tuple(float(x) for x in row) for row in near),
        far_list=tuple(tuple(float(x) for x in row) for row in far),
    )


def placed(figure: Figure, angles: np.ndarray, root) -> np.ndarray:
    """Link transforms ``root @ pose`` (B, n_links, 4, 4) for angles (B, n_joints, 3); see ``placed_transforms``.

    A transposed view of component-major storage, not C-contiguous.
    """
    walk = walk_of(figure)
    B = angles.shape[0]
    if root is not None:
        root = np.asarray(root, dtype=np.float64)
    values = angles.take(walk.order, axis=1).transpose(2, 1, 0)  # (3, J, B): axis, joint in walk order, frame
    if B <= BLOCK:
        return _block(walk, values, root)[:, :, walk.where].transpose(3, 2, 0, 1)
    out = np.empty((4, 4, figure.n_links, B))
    for lo in range(0, B, BLOCK):
        hi = min(lo + BLOCK, B)
        X = _block(walk, values[:, :, lo:hi], None if root is None else root[lo:hi])
        out[:, :, :, lo:hi] = X[:, :, walk.where]
    return out.transpose(3, 2, 0, 1)


def _block(walk: Walk, values: np.ndarray, root) -> np.ndarray:
    """Link transforms ``X[i, j, link, frame]`` in breadth-first order for one block of poses."""
    b = values.shape[2]
    X = np.empty((4, 4, len(walk.links), b))
    X[3, :3] = 0.0
    X[3, 3] = 1.0
    if root is None:
        X[:3, :, 0] = _EYE34
    else:
        X[:3, :, 0] = root[:, :3].transpose(1, 2, 0)
    if b and len(walk.order):
        A = _local(walk, values)[None]  # (1, 4, 4, J, b)
        X3 = X[:3]
        for first, end, parents, jl, jh in walk.levels:
            # child[i, j] = sum_m parent[i, m] A[m, j], m = 0..3 in order.
            P = X3.take(parents, axis=2)[:, :, None]  # (3, 4, 1, n, b): each child's parent's [R | t]
            np.add.reduce(P * A[:, :, :, jl:jh], axis=1, out=X3[:, :, first:end])
    return X


_EYE34 = np.eye(4)[:3, :, None]


def _local(walk: Walk, values: np.ndarray) -> np.ndarray:
    """Every joint's 4x4 ``A[i, j, joint, frame]`` (walk order) from its angles ``values`` (3, J, b) in degrees."""
    J, b = values.shape[1:]
    # cs rows: cy, sy, cz, sz, cx, sx, so that every group used below is a slice.
    a = np.deg2rad(values.take(_YZX, axis=0))
    cs = np.empty((6, J, b))
    np.cos(a, out=cs[0::2])
    np.sin(a, out=cs[1::2])
    E = np.empty((11, J, b))
    np.multiply(cs[0], cs[2:6], out=E[0:4])  # cy*cz, cy*sz, cy*cx, cy*sx
    U = cs[2:4, None] * cs[1]  # (cz*sy, sz*sy)
    U = U * cs[4:6][None]  # [[czsy*cx, czsy*sx], [szsy*cx, szsy*sx]]
    V = cs[3:1:-1, None] * cs[None, 5:3:-1]  # [[sz*sx, sz*cx], [cz*sx, cz*cx]]
    np.add(U, V * _SIGN, out=E[4:8].reshape(2, 2, J, b))
    np.negative(cs[1], out=E[8])
    E[9] = 0.0
    E[10] = 1.0
    A = E[walk.gather, walk.columns].reshape(4, 4, J, b)
    if len(walk.framed):
        # AXIS: the angles turn about the joint's own axes, F R F^T (then R^T if walked backwards).
        f = walk.framed
        F = walk.frames  # (3, 3, f, 1): F[i, a] per framed joint
        FR = np.add.reduce(F[:, :, None] * A[None, :3, :3, f], axis=1)  # sum_a F[i, a] R[a, j]
        R = np.add.reduce(FR[:, None] * F[None], axis=2)  # sum_k FR[i, k] F[j, k]
        g = walk.framed_reversed_in_framed
        if len(g):
            R[:, :, g] = R[:, :, g].transpose(1, 0, 2, 3)
        A[:3, :3, f] = R
    # t = near - R far, as sum_m R[:, m] (-far[m]) + near: the same number.
    np.add.reduce(A[:3, :3] * walk.minus_far, axis=1, out=A[:3, 3])
    A[:3, 3] += walk.near
    if len(walk.slides):
        # A slide moves S by k F d along its axes; walked backwards, P moves by -k F d.
        s = walk.slides
        shift = np.add.reduce(walk.slide_axes * values[None, :, s], axis=1)  # sum_a F[i, a] d[a], (3, s, b)
        A[:3, 3, s] += shift * walk.slide_gain
    return A


_YZX = np.array([1, 2, 0])
