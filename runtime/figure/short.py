"""Forward kinematics of one pose, or a short batch, in a fixed, small number of numpy calls.

The short half of :func:`liganimate.runtime.figure.kinematics.placed_transforms`
(:mod:`.folded` holds long batches; both start from the figure's
:class:`~.walk.Walk`).  One pose is what the studio, IK and a still image
ask for, a short batch what the renderer poses at a time, and there the
cost is not arithmetic (a humanoid is a few thousand flops a pose) but the
number of numpy calls, each of which costs about as much as a hundred
flops.  So the arithmetic is laid out once per figure (per tree walk) as a
:class:`Plan`: every number of a pose has a fixed place in one flat **work
array** ``Z`` (for B poses, a row of B numbers), and each step is one
gather from ``Z`` of a ``(k, n)`` table of places and a product or sum over
its ``k`` rows, in order, written back into ``Z``:

1. the cosines and sines of every angle (two calls, after one ``deg2rad``);
2. every product the rotation ``Rz Ry Rx`` needs, as ``a * b * c`` over
   three gathered rows (``c`` the constant 1 for a product of two, -1 for
   a negated one), in the very operations of
   :func:`~liganimate.runtime.figure.kinematics.matrix_from_euler_zyx`;
3. the four sums of the rotation, ``U + V``, read in place;
4. for a joint with its own AXIS, ``F R F^T`` as two sums of three
   products; for a slide, its shift ``k F d``;
5. each joint's translation, ``sum_m R[i, m] (-far[m]) + 1 * near[i]``
   (``near - R far``: ``L1 - R L2``, or ``L2 - R^T L1`` for a joint walked
   backwards, whose rotation is read transposed); where ``far`` is 0 every
   term but ``near`` is a zero, and the translation is the constant
   ``near``, computed by no call;
6. one product per depth level of the tree, each child's entry
   ``sum_m P[i, m] A[m, j]`` over ``m = 0..3`` in order (``P`` its parent's
   3x4, ``A`` its joint's 4x4); a level whose parent is the identity (the
   main link, with no root transform) is not multiplied at all: its links'
   places in ``Z`` are their joints' entries;
7. one gather of every link's 4x4 (the bottom rows from constants in ``Z``).

Sums are elementwise adds, row after row, and products elementwise (never
BLAS), so every number is the one the previous short-batch walk computed
(bit for bit: an exact zero may come out as -0.0; for angles that are not
finite the rotations are NaN as before, though a translation may keep its
number), on every machine and for any batch size.  ``tests/runtime/figure/test_short.py`` checks that
against the previous walk and the previous kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from liganimate.runtime.figure.tree import Figure
from liganimate.runtime.figure.walk import Walk, walk_of

__all__ = ["Plan", "Stage", "plan_of", "placed_short"]


@dataclass(frozen=True, eq=False)
class Stage:
    """One step: ``Z[out]`` is the product of some rows of places, their sum, or their sum weighted by constants.

    The rows are gathered from Z by a (k, n) table of places, or read in
    place as k runs of Z; a product or a sum goes over them in order.
    """

    index: np.ndarray | tuple  # (k, n) places in Z, or k slices of Z read in place
    kind: str  # "product", "sum" or "weighted" (sum of rows times weights)
    weights: np.ndarray | None  # (k, n) constants for "weighted"
    out: slice  # n places in Z


@dataclass(frozen=True, eq=False)
class Plan:
    """Where every number of one pose lives in the work array, and the steps between them."""

    template: np.ndarray  # Z before a pose: the constants (1, 0, -1, every joint's near) in place
    raw: slice  # 3J places: the pose's angles, for the slides (if any)
    radians: slice
    cosines: slice  # 3J places: cos of angle a of joint k at 3k + a
    sines: slice
    stages: tuple  # the joints' entries: products, sums, F R F^T, slides' shifts, translations
    slides: bool  # whether a stage reads the raw angles
    root: slice | None  # where the root transform's 3x4 goes (the main link's place), or None without one
    joint_entries: np.ndarray  # A[m, j] of every multiplied level's joints, level after level, each (4, 12 n) flattened; then the first level's parents
    levels: tuple  # per multiplied level: (parents' entries (4, 12 n) or their slice of joint_entries, its slice of them, out slice)
    result: np.ndarray  # (1, L, 4, 4) places of every link's transform
    spare: list = field(default_factory=list)  # work arrays for one pose not in use (see _Work)


def placed_short(figure: Figure, angles: np.ndarray, root) -> np.ndarray:
    """Link transforms ``root @ pose`` (B, n_links, 4, 4) for angles (B, n_joints, 3), B >= 1; see ``placed_transforms``.

    Parameters
    ----------
    figure : Figure
    angles : numpy.ndarray, shape (B, n_joints, 3)
        Degrees (a slide's displacement), in the figure's joint order.
    root : numpy.ndarray, shape (B, 4, 4), or None
        Where the current main link goes; None for the identity.

    Returns
    -------
    numpy.ndarray, shape (B, n_links, 4, 4)
        A new array: C-contiguous for one pose, else a transposed view of
        component-major storage.
    """
    plan = plan_of(figure, root is not None)
    if angles.shape[0] > 1:
        return _placed_batch(plan, angles, root)
    try:
        work = plan.spare.pop()
    except IndexError:
        work = _Work(plan)
    try:
        np.deg2rad(angles, work.radians)
        if plan.slides:
            work.raw[...] = angles
        if root is not None:
            work.root[...] = root[0, :3]
        for f, args in work.steps:
            f(*args)
        return work.Z[plan.result]
    finally:
        plan.spare.append(work)


def _placed_batch(plan: Plan, angles: np.ndarray, root) -> np.ndarray:
    """:func:`placed_short` for B > 1 poses, in blocks of at most :data:`BLOCK`."""
    B = angles.shape[0]
    if B <= BLOCK:
        return _block(plan, angles, root, None).transpose(3, 0, 1, 2)
    out = np.empty(plan.result.shape[1:] + (B,))
    for lo in range(0, B, BLOCK):
        hi = min(lo + BLOCK, B)
        _block(plan, angles[lo:hi], None if root is None else root[lo:hi], out[..., lo:hi])
    return out.transpose(3, 0, 1, 2)


def _block(plan: Plan, angles: np.ndarray, root, out) -> np.ndarray:
    """Link transforms ``X[link, i, j, pose]`` of b > 1 poses, into ``out`` if given: every place of Z a row of b numbers."""
    b = angles.shape[0]
    key = (id(plan), b)
    kept = _BATCH_WORK.get(key)
    try:
        work = kept[1].pop() if kept is not None and kept[0] is plan else _Work(plan, b)
    except IndexError:
        work = _Work(plan, b)
    a = angles.transpose(1, 2, 0)
    np.deg2rad(a, work.radians)
    if plan.slides:
        work.raw[...] = a
    if root is not None:
        work.root[...] = root[:, :3].transpose(1, 2, 0)
    for f, args in work.steps:
        f(*args)
    if out is None:
        out = work.Z[plan.result[0]]
    else:
        out[...] = work.Z[plan.result[0]]
    if len(_BATCH_WORK) >= 8 and key not in _BATCH_WORK:
        _BATCH_WORK.clear()
    _BATCH_WORK.setdefault(key, (plan, []))[1].append(work)
    return out


BLOCK = 32
"""Poses worked on together; their work arrays are kept for reuse (eight sizes and figures at most).

Every number of a block is a row of at most this many: large enough for
numpy's per-call cost to be shared out, small enough for a block's work
arrays (about 25 KB a pose for a humanoid, 0.8 MB a block) to stay near
the cache, and for the memory kept to stay bounded (under 10 MB for
humanoids) whatever batch sizes a program asks for.  Measured on
HUMANOID, blocks of 32 beat 64 and 128 for every batch from 32 to 255.
"""

_BATCH_WORK: dict = {}  # (id(plan), b) -> (plan, work arrays not in use); the stored plan keeps the id valid


class _Work:
    """A work array Z for one :class:`Plan` and every step on it, as calls on views made once.

    Making a view or a temporary costs about as much as a small numpy call,
    so work arrays are kept for reuse (one per call in progress: a call
    takes one from ``Plan.spare``, or from ``_BATCH_WORK`` for a batch, and
    puts it back, so threads never share one), and a pose runs as a fixed
    list of calls.  For a batch of ``B > 1`` poses every place of Z is a
    row of ``B`` numbers.
    """

    def __init__(self, plan: Plan, B: int | None = None) -> None:
        # B None: one pose, Z flat; else rows of B numbers (a block, b may be 1).
        tail = () if B is None else (B,)
        axis = None if B is None else 0
        Z = self.Z = plan.template.copy() if B is None else np.repeat(plan.template[:, None], B, axis=1)
        shape = (1, -1, 3) if B is None else (-1, 3, B)
        self.raw = Z[plan.raw].reshape(shape)
        self.radians = Z[plan.radians].reshape(shape)
        self.root: np.ndarray = Z[plan.root].reshape((3, 4) + tail) if plan.root is not None else Z[:0]
        steps: list = [(np.cos, (self.radians, Z[plan.cosines].reshape(shape)))]
        steps.append((np.sin, (self.radians, Z[plan.sines].reshape(shape))))
        for stage in plan.stages:
            if isinstance(stage.index, tuple):
                steps += _folds(np.add, [Z[run] for run in stage.index], Z[stage.out])
                continue
            rows = np.empty(stage.index.shape + tail)
            steps.append((Z.take, (stage.index, axis, rows, "clip")))
            if stage.weights is not None:
                weights = stage.weights if B is None else stage.weights[:, :, None]
                steps.append((np.multiply, (rows, weights, rows)))
            steps += _folds(np.multiply if stage.kind == "product" else np.add, rows, Z[stage.out])
        A = np.empty(plan.joint_entries.shape + tail)
        steps.append((Z.take, (plan.joint_entries, axis, A, "clip")))
        for parents, entries, out in plan.levels:
            if isinstance(parents, slice):  # gathered with the joints' entries, before any level is computed
                P = A[parents].reshape((4, -1) + tail)
            else:
                P = np.empty(parents.shape + tail)
                steps.append((Z.take, (parents, axis, P, "clip")))
            # A contiguous (4, 12 n) view: numpy multiplies a strided one several times slower.
            steps.append((np.multiply, (P, A[entries].reshape(P.shape), P)))
            steps += _folds(np.add, P, Z[out])
        self.steps = tuple(steps)


def _folds(op, rows, out: np.ndarray) -> list:
    """Steps putting ``rows[0] op rows[1] op ...`` (in that order) into ``out``."""
    steps = [(op, (rows[0], rows[1], out))]
    steps += [(op, (out, row, out)) for row in rows[2:]]
    return steps


def plan_of(figure: Figure, rooted: bool) -> Plan:
    """The figure's :class:`Plan`, with or without a root transform, remembered per tree walk.

    Keyed as :func:`.walk.walk_of` keys its walks (the figure's traversal
    and joints), looked up here without it: on every call this is overhead.
    """
    levels = figure.traversal
    cache = _PLANS[rooted]
    hit = cache.get(id(levels))
    if hit is not None and hit[0] is levels and hit[1] is figure.joints:
        return hit[2]
    plan = _Builder(figure, walk_of(figure), rooted).plan()
    if len(cache) >= 256:
        cache.clear()
    cache[id(levels)] = (levels, figure.joints, plan)
    return plan


_PLANS: dict = {
    False: {},
    True: {},
}  # rooted -> id(traversal) -> (traversal, joints, Plan); the stored objects keep the id valid

# The products of the rotation Rz Ry Rx of one joint, as three factors each
# (c cosine, s sine of axis x, y or z; 1 and -1 constants), in the order
# the previous walk multiplied them: R00 = cy cz, ..., then U = (cz sy, sz sy)
# times (cx, sx), and V = (sz sx, sz cx, cz sx, cz cx) times the signs.
_PRODUCTS = (
    ("cy", "cz", "1"),
    ("cy", "sz", "1"),
    ("cy", "cx", "1"),
    ("cy", "sx", "1"),
    ("sy", "-1", "1"),
    ("cz", "sy", "cx"),
    ("cz", "sy", "sx"),
    ("sz", "sy", "cx"),
    ("sz", "sy", "sx"),
    ("sz", "sx", "1"),
    ("sz", "cx", "-1"),
    ("cz", "sx", "-1"),
    ("cz", "cx", "1"),
)
# The rotation's entries: a product above (its number), or a sum of two (U + V).
_ENTRIES = {(0, 0): 0, (1, 0): 1, (2, 2): 2, (2, 1): 3, (2, 0): 4}
_SUMS = {(0, 2): (5, 9), (0, 1): (6, 10), (1, 2): (7, 11), (1, 1): (8, 12)}  # U rows 5-8 plus V rows 9-12, in order


class _Builder:
    """Lays out one figure's :class:`Plan` (Python, once per tree walk)."""

    def __init__(self, figure: Figure, walk: Walk, rooted: bool) -> None:
        self.figure, self.walk, self.rooted = figure, walk, rooted
        self.size = 0
        J = figure.n_joints
        self.raw = self._places(3 * J)
        self.radians = self._places(3 * J)
        self.cos = self._places(3 * J)
        self.sin = self._places(3 * J)
        constants = self._places(3).start
        self.one, self.zero, self.minus_one = constants, constants + 1, constants + 2
        self.slide_set = frozenset(walk.slides.tolist())
        self.framed_at: dict = {}
        self.moved: dict = {}
        self.constants: list = []  # (slice, values): places of Z that hold constants besides 1, 0, -1
        self.level_one_end = walk.levels[0][1] if walk.levels else 1

    def _places(self, n: int) -> slice:
        """``n`` fresh places in Z."""
        s = slice(self.size, self.size + n)
        self.size += n
        return s

    def _factor(self, k: int, name: str) -> int:
        if name in ("1", "-1"):
            return int(self.one if name == "1" else self.minus_one)
        base = self.cos if name[0] == "c" else self.sin
        return base.start + 3 * k + "xyz".index(name[1])

    def plan(self) -> Plan:
        fig, walk = self.figure, self.walk
        stages = [self._products(), self._sums()]
        framed = walk.framed.tolist()
        if framed:
            stages += self._framed(framed)
        stages += self._translations()
        if len(walk.slides):
            stages += self._slides()
        self.x = self._places(12 * fig.n_links)
        root = slice(self.x.start, self.x.start + 12) if self.rooted else None  # the main link's place
        levels: list[tuple] = []
        entries, width = [], 0
        for first, end, parents, jl, _ in walk.levels[0 if self.rooted else 1 :]:
            P, A = self._level(first, end, parents.tolist(), jl)
            entries.append(A.reshape(-1))
            out = slice(self.x.start + 12 * first, self.x.start + 12 * end)
            levels.append((P, slice(width, width + A.size), out))
            width += A.size
        if levels:
            # The first level's parents are known before any level is computed: gathered with the joints' entries.
            P = levels[0][0]
            entries.append(P.reshape(-1))
            levels[0] = (slice(width, width + P.size),) + levels[0][1:]
        template = np.zeros(self.size)
        template[self.one], template[self.minus_one] = 1.0, -1.0
        for places, values in self.constants:
            template[places] = values
        return Plan(
            template=template,
            raw=self.raw,
            radians=self.radians,
            cosines=self.cos,
            sines=self.sin,
            stages=tuple(stages),
            slides=bool(len(walk.slides)),
            root=root,
            joint_entries=np.concatenate(entries) if entries else np.zeros(0, dtype=np.intp),
            levels=tuple(levels),
            result=self._result(),
        )

    # -- the joints' local transforms ---------------------------------------

    def _products(self) -> Stage:
        """Every product, product after product, each over all joints (joint k of product e at e J + k)."""
        J = self.figure.n_joints
        self.prod = self._places(len(_PRODUCTS) * J)
        index = [[self._factor(k, f[r]) for f in _PRODUCTS for k in range(J)] for r in range(3)]
        return Stage(_table(index), "product", None, self.prod)

    def _sums(self) -> Stage:
        """``U + V``: the two terms of every sum are runs of the products, read in place (no gather)."""
        J, start = self.figure.n_joints, self.prod.start
        self.sums = self._places(len(_SUMS) * J)
        return Stage(
            (slice(start + 5 * J, start + 9 * J), slice(start + 9 * J, start + 13 * J)), "sum", None, self.sums
        )

    def _plain(self, k: int, i: int, j: int) -> int:
        """Place of entry (i, j) of joint k's ``Rz Ry Rx``."""
        J = self.figure.n_joints
        if (i, j) in _ENTRIES:
            return self.prod.start + J * _ENTRIES[(i, j)] + k
        return self.sums.start + J * list(_SUMS).index((i, j)) + k

    def _framed(self, framed: list) -> list:
        """``F R F^T`` for the joints with an AXIS: ``FR[i, j] = sum_a F[i, a] R[a, j]``, then ``sum_k FR[i, k] F[j, k]``."""
        order, F = self.walk.order, self.figure.frames
        fr = self._places(9 * len(framed))
        index = [
            [self._plain(int(order[q]), a, j) for q in framed for i in range(3) for j in range(3)] for a in range(3)
        ]
        weights = [[F[order[q]][i, a] for q in framed for i in range(3) for j in range(3)] for a in range(3)]
        first = Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), fr)
        self.turned = self._places(9 * len(framed))
        index = [
            [fr.start + 9 * n + 3 * i + m for n in range(len(framed)) for i in range(3) for j in range(3)]
            for m in range(3)
        ]
        weights = [[F[order[q]][j, m] for q in framed for i in range(3) for j in range(3)] for m in range(3)]
        self.framed_at = {q: n for n, q in enumerate(framed)}
        return [first, Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), self.turned)]

    def _walked(self, q: int, i: int, j: int) -> int:
        """Place of entry (i, j) of walked joint q's rotation, as walked (transposed backwards; identity for a slide)."""
        walk = self.walk
        if q in self.slide_set:
            return int(self.one if i == j else self.zero)
        if walk.reversed[q]:
            i, j = j, i
        if q in self.framed_at:
            return self.turned.start + 9 * self.framed_at[q] + 3 * i + j
        return self._plain(int(walk.order[q]), i, j)

    def _translations(self) -> list:
        """``t[i] = sum_m R[i, m] (-far[m]) + 1 * near[i]`` for every walked joint whose ``far`` is not 0.

        With ``far`` 0 (a joint at its far link's origin, as most are) every
        term of the sum but ``near`` is a zero, and the sum is ``near``: its
        places are constants of the work array, and cost no call.
        """
        walk, J = self.walk, self.figure.n_joints
        near, minus_far = walk.near, walk.minus_far  # (3, J) each
        self.near = self._places(3 * J)
        self.constants.append((self.near, near.T.reshape(-1)))
        moving = [q for q in range(J) if minus_far[:, q].any()]
        self.t = self._places(3 * len(moving))
        self.t_at = {q: self.t.start + 3 * n for n, q in enumerate(moving)}
        if not moving:
            return []
        index = [
            [self._walked(q, i, m) if m < 3 else int(self.one) for q in moving for i in range(3)] for m in range(4)
        ]
        weights = [[minus_far[m, q] if m < 3 else near[i, q] for q in moving for i in range(3)] for m in range(4)]
        return [Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), self.t)]

    def _slides(self) -> tuple[Stage, Stage]:
        """A slide's shift ``sum_a F[i, a] d[a]``, and its translation ``t * 1 + shift * gain``."""
        walk = self.walk
        slides = walk.slides.tolist()
        shift = self._places(3 * len(slides))
        F = walk.slide_axes  # (3, 3, s): F[i, a]
        index = [[self.raw.start + 3 * int(walk.order[q]) + a for q in slides for i in range(3)] for a in range(3)]
        weights = [[F[i, a, n] for n in range(len(slides)) for i in range(3)] for a in range(3)]
        first = Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), shift)
        moved = self._places(3 * len(slides))
        index = [
            [self._unmoved(q, i) for q in slides for i in range(3)],
            [shift.start + 3 * n + i for n in range(len(slides)) for i in range(3)],
        ]
        gain = walk.slide_gain
        weights = [[1.0] * (3 * len(slides)), [gain[n] for n in range(len(slides)) for i in range(3)]]
        self.moved = {q: moved.start + 3 * n for n, q in enumerate(slides)}
        return first, Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), moved)

    def _unmoved(self, q: int, i: int) -> int:
        """Place of entry i of walked joint q's translation ``near - R far`` (a constant where far is 0)."""
        return self.t_at[q] + i if q in self.t_at else self.near.start + 3 * q + i

    def _translation(self, q: int, i: int) -> int:
        return self.moved[q] + i if q in self.moved else self._unmoved(q, i)

    # -- the walk down the tree ----------------------------------------------

    def _entry(self, q: int, m: int, j: int) -> int:
        """Place of entry (m, j) of walked joint q's 4x4."""
        if m == 3:
            return int(self.one if j == 3 else self.zero)
        return self._translation(q, m) if j == 3 else self._walked(q, m, j)

    def _link(self, place: int, i: int, m: int) -> int:
        """Place of entry (i, m) (i < 3) of the link at breadth-first ``place``."""
        if place == 0 and not self.rooted:
            return int(self.one if i == m else self.zero)
        if not self.rooted and place < self.level_one_end:
            return self._entry(place - 1, i, m)  # below the identity: its joint's own entries
        return self.x.start + 12 * place + 4 * i + m

    def _level(self, first: int, end: int, parents: list, jl: int) -> tuple[np.ndarray, np.ndarray]:
        cells = [(u, i, j) for u in range(end - first) for i in range(3) for j in range(4)]
        P = [[self._link(parents[u], i, m) for u, i, j in cells] for m in range(4)]
        A = [[self._entry(jl + u, m, j) for u, i, j in cells] for m in range(4)]
        return _table(P), _table(A)

    def _result(self) -> np.ndarray:
        out = np.empty((1, self.figure.n_links, 4, 4), dtype=np.intp)
        for link, place in enumerate(self.walk.where.tolist()):
            for i in range(4):
                for j in range(4):
                    out[0, link, i, j] = (self.one if j == 3 else self.zero) if i == 3 else self._link(place, i, j)
        return out


def _table(rows: list) -> np.ndarray:
    """A (k, n) table of places, C-contiguous (so that a reduction over its rows adds them in order)."""
    return np.ascontiguousarray(np.array(rows, dtype=np.intp).reshape(len(rows), -1))
