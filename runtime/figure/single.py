"""Forward kinematics of one pose in a fixed, small number of numpy calls.

The one-pose third of :func:`liganimate.runtime.figure.kinematics.placed_transforms`
(:mod:`.walk` holds short batches, :mod:`.folded` long ones).  One pose is
what the studio, IK and a still image ask for, and there the cost is not
arithmetic (a humanoid is a few thousand flops) but the number of numpy
calls, each of which costs about as much as a hundred flops.  So the walk's
arithmetic is laid out once per figure (per tree walk) as a :class:`Plan`:
every number of a pose has a fixed place in one flat **work array** ``Z``,
and each step of the computation is one gather from ``Z`` of a ``(k, n)``
table of places followed by one reduction over its ``k`` rows, written
back into ``Z``:

1. the cosines and sines of every angle (two calls, after one ``deg2rad``);
2. every product the rotation ``Rz Ry Rx`` needs, as ``a * b * c`` over
   three gathered rows (``c`` the constant 1 for a product of two, -1 for
   a negated one), in the very operations of :func:`.walk._local`;
3. the four sums of the rotation;
4. for a joint with its own AXIS, ``F R F^T`` as two sums of three
   products; for a slide, its shift ``k F d``;
5. each joint's translation, ``sum_m R[i, m] (-far[m]) + 1 * near[i]``;
6. one product per depth level of the tree, each child's entry
   ``sum_m P[i, m] A[m, j]`` over ``m = 0..3`` in order; a level whose
   parent is the identity (the main link, with no root transform) is not
   multiplied at all: its links' places in ``Z`` are their joints' entries;
7. one gather of every link's 4x4 (the bottom rows from constants in ``Z``).

Every sum runs over the leading axis of a C-contiguous table, which numpy
adds row after row, and every product is elementwise, so each number is the
one :mod:`.walk` computes for the same pose (bit for bit: an exact zero may
come out as -0.0), on every machine.  ``tests/runtime/figure/test_single.py``
checks that against the walk and against the previous implementation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from liganimate.runtime.figure.tree import Figure
from liganimate.runtime.figure.walk import Walk, walk_of

__all__ = ["Plan", "Stage", "plan_of", "placed_one"]


@dataclass(frozen=True, eq=False)
class Stage:
    """One step: ``Z[out]`` is the product of the gathered rows, their sum, or their sum weighted by constants.

    ``source.take(index)`` gathers a (k, n) table from Z (or from the pose's
    angles); a product or a sum reduces it over its rows, in order.
    """

    index: np.ndarray  # (k, n) places in the source
    kind: str  # "product", "sum" or "weighted" (sum of rows times weights)
    weights: np.ndarray | None  # (k, n) constants for "weighted"
    out: slice  # n places in Z


@dataclass(frozen=True, eq=False)
class Plan:
    """Where every number of one pose lives in the work array, and the steps between them."""

    template: np.ndarray  # Z before a pose: the constants 1, 0, -1 in place
    raw: slice  # 3J places: the pose's angles, for the slides (if any)
    radians: slice
    cosines: slice  # 3J places: cos of angle a of joint k at 3k + a
    sines: slice
    stages: tuple  # the joints' entries: products, sums, F R F^T, slides' shifts, translations
    slides: bool  # whether a stage reads the raw angles
    root: slice | None  # where the root transform's 3x4 goes (the main link's place), or None without one
    joint_entries: np.ndarray  # A[m, j] of every multiplied level's joints, level after level, each (4, 12 n) flattened
    levels: tuple  # per multiplied level: (parents' entries (4, 12 n), its slice of joint_entries, out slice)
    result: np.ndarray  # (1, L, 4, 4) places of every link's transform
    spare: list = field(default_factory=list)  # work arrays not in use (see _Work)


def placed_one(figure: Figure, angles: np.ndarray, root) -> np.ndarray:
    """Link transforms ``root @ pose`` (1, n_links, 4, 4) for angles (1, n_joints, 3); see ``placed_transforms``.

    Parameters
    ----------
    figure : Figure
    angles : numpy.ndarray, shape (1, n_joints, 3)
        Degrees (a slide's displacement), in the figure's joint order.
    root : numpy.ndarray, shape (1, 4, 4), or None
        Where the current main link goes; None for the identity.

    Returns
    -------
    numpy.ndarray, shape (1, n_links, 4, 4)
        A new C-contiguous array.
    """
    plan = plan_of(figure, root is not None)
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


class _Work:
    """A work array Z for one :class:`Plan` and every step on it, as calls on views made once.

    Making a view or a temporary costs about as much as a small numpy call,
    so each plan keeps work arrays for reuse (one per call in progress: a
    call takes one from ``Plan.spare`` and puts it back, so threads never
    share one), and a pose runs as a fixed list of calls.
    """

    def __init__(self, plan: Plan) -> None:
        Z = self.Z = plan.template.copy()
        shape = (1, -1, 3)
        self.raw = Z[plan.raw].reshape(shape)
        self.radians = Z[plan.radians].reshape(shape)
        self.root = Z[plan.root].reshape(3, 4) if plan.root is not None else None
        steps: list = [(np.cos, (self.radians, Z[plan.cosines].reshape(shape)))]
        steps.append((np.sin, (self.radians, Z[plan.sines].reshape(shape))))
        for stage in plan.stages:
            rows = np.empty(stage.index.shape)
            steps.append((Z.take, (stage.index, None, rows, "clip")))
            if stage.weights is not None:
                steps.append((np.multiply, (rows, stage.weights, rows)))
            steps += _folds(np.multiply if stage.kind == "product" else np.add, rows, Z[stage.out])
        A = np.empty(plan.joint_entries.shape)
        steps.append((Z.take, (plan.joint_entries, None, A, "clip")))
        for parents, entries, out in plan.levels:
            P = np.empty(parents.shape)
            steps.append((Z.take, (parents, None, P, "clip")))
            # A contiguous (4, 12 n) view: numpy multiplies a strided one several times slower.
            steps.append((np.multiply, (P, A[entries].reshape(P.shape), P)))
            steps += _folds(np.add, P, Z[out])
        self.steps = tuple(steps)


def _folds(op, rows: np.ndarray, out: np.ndarray) -> list:
    """Steps putting ``rows[0] op rows[1] op ...`` (in that order) into ``out``."""
    steps = [(op, (rows[0], rows[1], out))]
    steps += [(op, (out, row, out)) for row in rows[2:]]
    return steps


def plan_of(figure: Figure, rooted: bool) -> Plan:
    """The figure's :class:`Plan`, with or without a root transform, remembered per tree walk."""
    walk = walk_of(figure)
    key = (id(walk), rooted)
    hit = _PLANS.get(key)
    if hit is not None and hit[0] is walk:
        return hit[1]
    plan = _Builder(figure, walk, rooted).plan()
    if len(_PLANS) >= 256:
        _PLANS.clear()
    _PLANS[key] = (walk, plan)
    return plan


_PLANS: dict = {}  # (id(walk), rooted) -> (walk, Plan); the stored walk keeps the id valid

# The products of the rotation Rz Ry Rx of one joint, as three factors each
# (c cosine, s sine of axis x, y or z; 1 and -1 constants), in the order
# walk._local multiplies them: R00 = cy cz, ..., then U = (cz sy, sz sy)
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
_SUMS = {(0, 2): (5, 9), (0, 1): (6, 10), (1, 2): (7, 11), (1, 1): (8, 12)}


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
        stages.append(self._translations())
        if len(walk.slides):
            stages += self._slides()
        self.x = self._places(12 * fig.n_links)
        root = slice(self.x.start, self.x.start + 12) if self.rooted else None  # the main link's place
        levels, entries, width = [], [], 0
        for first, end, parents, jl, _ in walk.levels[0 if self.rooted else 1 :]:
            P, A = self._level(first, end, parents.tolist(), jl)
            entries.append(A.reshape(-1))
            out = slice(self.x.start + 12 * first, self.x.start + 12 * end)
            levels.append((P, slice(width, width + A.size), out))
            width += A.size
        template = np.zeros(self.size)
        template[self.one], template[self.minus_one] = 1.0, -1.0
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
        J = self.figure.n_joints
        self.prod = self._places(len(_PRODUCTS) * J)
        index = [[self._factor(k, f[r]) for k in range(J) for f in _PRODUCTS] for r in range(3)]
        return Stage(_table(index), "product", None, self.prod)

    def _sums(self) -> Stage:
        J = self.figure.n_joints
        self.sums = self._places(len(_SUMS) * J)
        n = len(_PRODUCTS)
        index = [[self.prod.start + n * k + pair[r] for k in range(J) for pair in _SUMS.values()] for r in range(2)]
        return Stage(_table(index), "sum", None, self.sums)

    def _plain(self, k: int, i: int, j: int) -> int:
        """Place of entry (i, j) of joint k's ``Rz Ry Rx``."""
        if (i, j) in _ENTRIES:
            return self.prod.start + len(_PRODUCTS) * k + _ENTRIES[(i, j)]
        return self.sums.start + len(_SUMS) * k + list(_SUMS).index((i, j))

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

    def _translations(self) -> Stage:
        """``t[i] = sum_m R[i, m] (-far[m]) + 1 * near[i]`` for every walked joint."""
        walk, J = self.walk, self.figure.n_joints
        self.t = self._places(3 * J)
        index = [
            [self._walked(q, i, m) if m < 3 else int(self.one) for q in range(J) for i in range(3)] for m in range(4)
        ]
        near, minus_far = walk.near[:, :, 0], walk.minus_far[0, :, :, 0]  # (3, J) each
        weights = [[minus_far[m, q] if m < 3 else near[i, q] for q in range(J) for i in range(3)] for m in range(4)]
        return Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), self.t)

    def _slides(self) -> tuple[Stage, Stage]:
        """A slide's shift ``sum_a F[i, a] d[a]``, and its translation ``t * 1 + shift * gain``."""
        walk = self.walk
        slides = walk.slides.tolist()
        shift = self._places(3 * len(slides))
        F = walk.slide_axes[:, :, :, 0]  # (3, 3, s): F[i, a]
        index = [[self.raw.start + 3 * int(walk.order[q]) + a for q in slides for i in range(3)] for a in range(3)]
        weights = [[F[i, a, n] for n in range(len(slides)) for i in range(3)] for a in range(3)]
        first = Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), shift)
        moved = self._places(3 * len(slides))
        index = [
            [self.t.start + 3 * q + i for q in slides for i in range(3)],
            [shift.start + 3 * n + i for n in range(len(slides)) for i in range(3)],
        ]
        gain = walk.slide_gain[:, 0]
        weights = [[1.0] * (3 * len(slides)), [gain[n] for n in range(len(slides)) for i in range(3)]]
        self.moved = {q: moved.start + 3 * n for n, q in enumerate(slides)}
        return first, Stage(_table(index), "weighted", np.array(weights, dtype=np.float64), moved)

    def _translation(self, q: int, i: int) -> int:
        return self.moved[q] + i if q in self.moved else self.t.start + 3 * q + i

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
