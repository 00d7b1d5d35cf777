"""A figure as the goal solvers see it: free variables, bounds, batched kinematics.

Goal-directed positioning (``docs/semantics-ik.md``) moves some of a
figure's joint axes, and optionally the whole figure, until parts of it are
where goals ask.  :class:`IKModel` fixes, once per solve, which axes are free
*variables* and precomputes everything about the tree that does not depend on
the angles.  Its methods then work on a whole batch of poses at once (a
leading dimension ``B``), so a thousand independent solves cost one pass of
numpy per iteration, not a thousand.

Conventions are the figure's (``docs/semantics-figure.md``): angles in the
figure are degrees, ``R = Rz(az) Ry(ay) Rx(ax)``, poses are seen from the
current main link.  The solvers' variables are the same angles in
*radians*, so that a joint Jacobian column is "metres per radian" and
steps are well scaled.
"""

from __future__ import annotations

import weakref
from collections import OrderedDict

import numpy as np

from liganimate.runtime.figure.tree import Figure

__all__ = ["IKModel", "link_lengths", "figure_length", "matvec3", "cross3"]


def matvec3(M: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``M @ v`` for stacks of 3x3 matrices and 3-vectors, written out.

    Parameters
    ----------
    M : numpy.ndarray, shape (..., 3, 3)
    v : numpy.ndarray, shape (..., 3), broadcast against ``M``'s leading shape

    Returns
    -------
    numpy.ndarray, shape (..., 3)

    Notes
    -----
    numpy's batched ``matmul`` and ``einsum`` are several times slower than
    these five elementwise operations for 3x3 blocks, and the solvers do
    this in their inner loop.
    """
    return M[..., 0] * v[..., None, 0] + M[..., 1] * v[..., None, 1] + M[..., 2] * v[..., None, 2]


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of stacks of 3-vectors (broadcast), written out.

    Parameters
    ----------
    a, b : numpy.ndarray, shape (..., 3)

    Returns
    -------
    numpy.ndarray, shape (..., 3)

    Notes
    -----
    ``np.cross`` moves axes around and checks its arguments on every call,
    which costs more than the arithmetic for the small arrays of a solver
    iteration.
    """
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0), axis=-1)


# The products of cosines and sines that make up ``Rz Ry Rx`` and the local
# axes (see IKModel.forward_one): columns of [cx, cy, cz, sx, sy, sz, 1],
# three per product.
_TERMS = np.array(
    [
        (1, 2, 6),
        (2, 4, 3),
        (5, 0, 6),
        (2, 4, 0),
        (5, 3, 6),
        (1, 5, 6),
        (5, 4, 3),
        (2, 0, 6),
        (5, 4, 0),
        (2, 3, 6),
        (4, 6, 6),
        (1, 3, 6),
        (1, 0, 6),
        (5, 6, 6),
        (2, 6, 6),
        (6, 6, 6),
    ]
).T
# Which products, with which signs, add up to each entry: R row-major, then
# the local X axis Rz Ry e_x, Y axis Rz e_y and Z axis e_z.
_TERM_SUMS = np.zeros((16, 18))
for _col, _terms in enumerate(
    [
        {0: 1},
        {1: 1, 2: -1},
        {3: 1, 4: 1},
        {5: 1},
        {6: 1, 7: 1},
        {8: 1, 9: -1},
        {10: -1},
        {11: 1},
        {12: 1},
        {0: 1},
        {5: 1},
        {10: -1},
        {13: -1},
        {14: 1},
        {},
        {},
        {},
        {15: 1},
    ]
):
    for _k, _sign in _terms.items():
        _TERM_SUMS[_k, _col] = _sign
del _col, _terms, _k, _sign

_lengths_cache: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
# (id(figure), movable mask, translate) -> (figure, model).  The model holds
# its figure, so a weak-keyed cache would never let go; this one is bounded
# (least recently used out), and the stored figure keeps the id valid.
_model_cache: OrderedDict = OrderedDict()
_MODEL_CACHE_MAX = 32


def link_lengths(figure: Figure) -> np.ndarray:
    """Each link's length: the largest distance between two of its joint locations.

    Parameters
    ----------
    figure : Figure

    Returns
    -------
    numpy.ndarray, shape (n_links,)
        Read-only.  In the link frame's units (joint locations, already
        scaled by SCALE MODEL).  A link with fewer than two joints (a hand at the end of an
        arm) has length 0: its shape is opaque, so its tip is unknown.
    """
    hit = _lengths_cache.get(figure)
    if hit is not None:
        return hit  # figures are immutable values
    points: list[list[np.ndarray]] = [[] for _ in figure.links]
    for j in figure.joints:
        points[j.primary].append(j.loc1)
        points[j.secondary].append(j.loc2)
    out = np.zeros(figure.n_links)
    for i, pts in enumerate(points):
        if len(pts) > 1:
            P = np.array(pts)
            out[i] = np.max(np.linalg.norm(P[:, None] - P[None], axis=-1))
    out.setflags(write=False)
    _lengths_cache[figure] = out
    return out


def figure_length(figure: Figure) -> float:
    """The figure's characteristic length: the sum of its link lengths (1 if that is 0).

    It scales the root translation variables, axis goals on zero-length
    links and the default tolerance, so a solve of a figure scaled by ``r``
    is the same solve with every length times ``r``.

    Parameters
    ----------
    figure : Figure

    Returns
    -------
    float
    """
    total = float(link_lengths(figure).sum())
    return total if total > 0.0 else 1.0


def _framed_term_sums(F: np.ndarray) -> np.ndarray:
    """:data:`_TERM_SUMS` for a joint with axes ``F``: the columns of ``F R F^T`` and of ``F`` times each local axis."""
    sums = np.empty_like(_TERM_SUMS)
    rot = _TERM_SUMS[:, :9].reshape(16, 3, 3)
    sums[:, :9] = np.einsum("ia,tab,jb->tij", F, rot, F).reshape(16, 9)
    axes = _TERM_SUMS[:, 9:].reshape(16, 3, 3)  # (term, axis, component)
    sums[:, 9:] = np.einsum("ic,tac->tai", F, axes).reshape(16, 9)
    return sums


def _conjugate(r: list, joints: np.ndarray, F: np.ndarray) -> None:
    """Replace the rotation entries ``r[i][j]`` (each (J, B)) of ``joints`` by those of ``F R F^T``, in place."""
    R = np.array([[r[i][j][joints] for j in range(3)] for i in range(3)])  # (3, 3, f, B)
    out = np.einsum("fia,abfc,fjb->ijfc", F, R, F)
    for i in range(3):
        for j in range(3):
            r[i][j] = r[i][j].copy() if not r[i][j].flags.writeable else r[i][j]
            r[i][j][joints] = out[i, j]


def _tree_walk(figure: Figure) -> tuple:
    """Each joint's depth from the main link; per link its parent link and the joint into it; which links each joint moves."""
    J = figure.n_joints
    depth = np.zeros(J, dtype=int)
    for d, level in enumerate(figure.traversal):
        depth[level.joints] = d
    parent_of = np.full(figure.n_links, -1)
    into = np.full(figure.n_links, -1)  # the joint through which the walk reaches each link
    for level in figure.traversal:
        parent_of[level.children] = level.parents
        into[level.children] = level.joints
    moves = np.zeros((J, figure.n_links), dtype=bool)
    for link in range(figure.n_links):
        # Walk up from the link to the main link, marking every joint passed.
        cur = link
        while cur != figure.main:
            moves[into[cur], link] = True
            cur = parent_of[cur]
    return depth, parent_of, into, moves


def _variable_order(rev: np.ndarray, is_var: np.ndarray, depth: np.ndarray) -> tuple[list, list]:
    """The variables' joints and axes, in the solvers' order.

    Deepest joints first (stable within a depth, in joint order), then X, Y,
    Z within a joint -- Z, Y, X for a joint walked backwards.  CCD relies on
    this order: turning a variable changes neither the axis nor the pivot of
    any variable visited after it in the same sweep.  (Forward, ax turns
    about Rz Ry e_x, which ay and az change; walked backwards the axes are
    -Rs e_x, -Rs Rx^T e_y and -Rs Rx^T Ry^T e_z, Rs the near link's rotation.)
    """
    order = sorted(range(len(rev)), key=lambda k: (-depth[k], k))
    vj, va = [], []
    for k in order:
        for a in (2, 1, 0) if rev[k] else (0, 1, 2):
            if is_var[k, a]:
                vj.append(k)
                va.append(a)
    return vj, va


def _joint_term_maps(figure: Figure, near_all: np.ndarray, far_all: np.ndarray, rev: np.ndarray) -> np.ndarray:
    """For :meth:`IKModel.forward_one`: per joint, the (16, 25) map from its cosine and sine products.

    Each joint's 4x4 transform and local axes are linear in the products of
    its cosines and sines (_TERMS), so a matrix per joint maps the products
    to them, with the joint's locations, and its direction (R or R^T),
    folded in.
    """
    J = figure.n_joints
    SJ = np.zeros((J, 16, 25))
    frames = figure.frames
    for k in range(J):
        near, far = near_all[k], far_all[k]
        # AXIS turns the rotation into F R F^T, linear in R's entries.
        sums = _framed_term_sums(frames[k]) if figure.has_frames[k] else _TERM_SUMS
        for i in range(3):
            for j in range(3):
                src = 3 * j + i if rev[k] else 3 * i + j
                SJ[k, :, 4 * i + j] = sums[:, src]
            # t_i = near_i - sum_j R_ij far_j; the constant rides on the product "1".
            SJ[k, :, 4 * i + 3] = -(SJ[k, :, 4 * i : 4 * i + 3] @ far)
            SJ[k, 15, 4 * i + 3] += near[i]
        SJ[k, 15, 15] = 1.0
        SJ[k, :, 16:] = sums[:, 9:]
    return SJ


def _single_chain(levels: list, main: int):
    """(joints, links) when the figure is one chain from the main link (each level one joint, hanging from the last).

    Its link transforms are then prefix products, computed in log2(J)
    batched products instead of J single ones.  None otherwise.
    """
    chain = all(isinstance(lv[0], int) for lv in levels)
    prev = main
    for lv in levels if chain else ():
        chain = chain and lv[1] == prev
        prev = lv[2]
    if not chain:
        return None
    return (
        np.array([lv[0] for lv in levels], dtype=np.intp),
        np.array([lv[2] for lv in levels], dtype=np.intp),
    )


class IKModel:
    """The figure's free variables, their bounds and batched kinematics.

    Parameters
    ----------
    figure : Figure
        Posed from its current main link, placed by its placement.
    movable : array_like of bool, shape (n_joints, 3)
        Which joint axes the solver may turn.  Axes whose extremes are a
        single value (``min == max``, e.g. locked at ``(0, 0)``) are never
        variables, whatever this says.
    translate : bool
        Whether the whole figure may also translate (POSIT's root
        translation), adding three variables after the angles.

    Attributes
    ----------
    var_joint, var_axis : numpy.ndarray of int, shape (V,)
        Joint index (in joint order) and axis (0 = X, 1 = Y, 2 = Z) of each
        angle variable, ordered from the joints farthest from the main link
        to the nearest, X before Y before Z within a joint (Z, Y, X within a
        joint walked backwards): the order CCD visits them, in which no turn
        moves the axis of a variable still to come in the sweep.
    lower, upper : numpy.ndarray, shape (V,)
        Bounds of the angle variables in radians; ``-inf``/``inf`` on free
        axes (extremes spanning 360 degrees or more).
    param_lower, param_upper : numpy.ndarray, shape (n_params,)
        The same, then ``-inf``/``inf`` for the translation; read-only.
    downstream : numpy.ndarray of bool, shape (V, n_links)
        Whether each link moves with each variable (it lies on the far side
        of the variable's joint from the main link).
    sign : numpy.ndarray, shape (V,)
        ``+1``, or ``-1`` for joints walked from secondary to primary
        (FIGURE ... MAIN below the joint): turning such a joint turns the
        primary side the opposite way.
    length : float
        :func:`figure_length`.
    n_params : int
        ``V`` plus 3 when translating.
    """

    def __init__(self, figure: Figure, movable, translate: bool = False):
        self.figure = figure
        J = figure.n_joints
        movable = np.broadcast_to(np.asarray(movable, dtype=bool), (J, 3))
        ext = figure.extremes  # (J, 3, 2) degrees
        lo, hi = (ext[..., 0], ext[..., 1]) if J else (np.zeros((0, 3)), np.zeros((0, 3)))
        free_range = hi - lo >= 360.0
        is_var = movable & (hi > lo)

        depth, parent_of, into, moves = _tree_walk(figure)
        rev = figure.reversed_joints
        vj, va = _variable_order(rev, is_var, depth)
        self.var_joint = np.array(vj, dtype=np.intp)
        self.var_axis = np.array(va, dtype=np.intp)
        self.var_flat = self.var_joint * 3 + self.var_axis
        V = len(vj)
        self.n_vars = V
        self.translate = bool(translate)
        self.n_params = V + (3 if translate else 0)
        free = free_range[self.var_joint, self.var_axis] if V else np.zeros(0, dtype=bool)
        self.lower = np.where(free, -np.inf, np.deg2rad(lo[self.var_joint, self.var_axis]) if V else 0.0)
        self.upper = np.where(free, np.inf, np.deg2rad(hi[self.var_joint, self.var_axis]) if V else 0.0)
        # The bounds of all the parameters, the translation's infinite (read-only: solves share them).
        self.param_lower = np.concatenate((self.lower, np.full(self.n_params - V, -np.inf)))
        self.param_upper = np.concatenate((self.upper, np.full(self.n_params - V, np.inf)))
        self.param_lower.setflags(write=False)
        self.param_upper.setflags(write=False)
        # For clamping a solved pose: whether some axis wraps (kinematics.clamp), else the extremes to clip to.
        self.wraps = bool((free_range & ~figure.slides[:, None]).any()) if J else False
        self.extremes_lo, self.extremes_hi = lo, hi
        self.downstream = moves[self.var_joint] if V else np.zeros((0, figure.n_links), dtype=bool)
        # Per link, 1.0 for each variable that moves it: the goals' Jacobian masks.
        self.moved_by = self.downstream.T.astype(float)
        self.sign = np.where(rev[self.var_joint], -1.0, 1.0) if V else np.zeros(0)
        self.var_primary = np.array([figure.joints[k].primary for k in vj], dtype=np.intp)
        loc1, loc2 = figure.locations
        self.var_loc1 = loc1[self.var_joint] if V else np.zeros((0, 3))
        self._loc1, self._loc2, self._rev = loc1, loc2, rev
        self._any_reversed = bool(rev.any())
        self._framed = np.flatnonzero(figure.has_frames)
        self._framed_axes = figure.frames[self._framed]  # (f, 3, 3)
        self._var_framed = np.flatnonzero(figure.has_frames[self.var_joint]) if V else np.zeros(0, dtype=np.intp)
        self._var_frames = figure.frames[self.var_joint[self._var_framed]] if V else np.zeros((0, 3, 3))
        self._near = np.where(rev[:, None], loc2, loc1)
        self._far = np.where(rev[:, None], loc1, loc2)
        self._levels = [
            (int(l.joints[0]), int(l.parents[0]), int(l.children[0]))
            if len(l.joints) == 1
            else (l.joints, l.parents, l.children)
            for l in figure.traversal
        ]
        self.link_scale = np.asarray(figure.link_scales, dtype=float)
        P = np.asarray(figure.placement, dtype=float)
        self.A = P[:3, :3].copy()
        self.b = P[:3, 3].copy()
        self.placement_is_identity = bool(np.array_equal(P, np.eye(4)))
        # Variables grouped by axis, with their joints, for :meth:`axes_trig`.
        self._axis_vars = [(np.flatnonzero(self.var_axis == a), self.var_joint[self.var_axis == a]) for a in range(3)]
        self.lengths = link_lengths(figure)
        self.length = figure_length(figure)
        self._term_maps = _joint_term_maps(figure, self._near, self._far, rev)  # for forward_one
        self._term_index = (
            (np.arange(J)[:, None] * 7 + _TERMS[:, None, :]) if J else np.zeros((3, 0, 16), dtype=np.intp)
        )
        # Where the variables' cosines and sines go among [c, s, 1] per joint.
        self._cos_at = self.var_joint * 7 + self.var_axis
        self._sin_at = self._cos_at + 3
        self._chain = _single_chain(self._levels, figure.main) if J else None
        # Each variable's local axis in column 0, its pivot in column 1
        # (homogeneous): one product with the primary's 4x4 gives both.
        M = np.zeros((V, 4, 2))
        M[:, :3, 1] = self.var_loc1
        M[:, 3, 1] = 1.0
        self._axis_pivot = M
        self._eye4 = np.eye(4)
        self.moves = moves  # (J, n_links): every joint, variable or not
        self.parent_link = parent_of  # per link, the next link toward the main link (-1 for it)
        self.into_joint = into  # per link, the joint joining it to parent_link (-1 for the main link)

    @classmethod
    def cached(cls, figure: Figure, movable, translate: bool = False) -> IKModel:
        """An :class:`IKModel`, reused while the same figure is solved with the same options.

        Figures are immutable values, so a model built for one stays right;
        a script or a DO loop solving one figure many times builds it once.

        Parameters
        ----------
        figure, movable, translate
            As for the constructor.

        Returns
        -------
        IKModel
        """
        mask = np.asarray(movable, dtype=bool)
        if mask.shape != (figure.n_joints, 3):
            mask = np.broadcast_to(mask, (figure.n_joints, 3))
        key = (id(figure), mask.tobytes(), bool(translate))
        hit = _model_cache.get(key)
        if hit is not None and hit[0] is figure:
            _model_cache.move_to_end(key)
            return hit[1]
        model = cls(figure, mask, translate)
        _model_cache[key] = (figure, model)
        while len(_model_cache) > _MODEL_CACHE_MAX:
            _model_cache.popitem(last=False)
        return model

    # ------------------------------------------------------------ angles

    def full_angles(self, q: np.ndarray, base: np.ndarray) -> np.ndarray:
        """All joint angles in radians, the variables taken from ``q``.

        Parameters
        ----------
        q : numpy.ndarray, shape (B, V)
            Variable values, radians.
        base : numpy.ndarray, shape (B, n_joints, 3) or (1, n_joints, 3)
            Radians; supplies every axis that is not a variable.

        Returns
        -------
        numpy.ndarray, shape (B, n_joints, 3)
        """
        B = q.shape[0]
        a = np.broadcast_to(base.reshape(base.shape[0], -1), (B, base[0].size)).copy()
        a[:, self.var_flat] = q
        return a.reshape(B, self.figure.n_joints, 3)

    def trig(self, q: np.ndarray, base_cos: np.ndarray, base_sin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cosines and sines of all joint angles, computing only the variables' afresh.

        Parameters
        ----------
        q : numpy.ndarray, shape (B, V)
            Radians.
        base_cos, base_sin : numpy.ndarray, shape (B, n_joints * 3) or (1, n_joints * 3)
            Of the start angles (the axes that are not variables keep them).

        Returns
        -------
        c, s : numpy.ndarray, shape (B, n_joints, 3)
        """
        B = q.shape[0]
        shape = (B, self.figure.n_joints, 3)
        if base_cos.shape[0] == B:
            c, s = base_cos.copy(), base_sin.copy()
        else:
            c, s = np.repeat(base_cos, B, axis=0), np.repeat(base_sin, B, axis=0)
        # Sines and cosines are most of the cost of the kinematics, and most
        # axes are not variables: only the variables' are recomputed.
        c[:, self.var_flat] = np.cos(q)
        s[:, self.var_flat] = np.sin(q)
        return c.reshape(shape), s.reshape(shape)

    # ------------------------------------------------------------ kinematics

    def forward(self, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every link's rotation and origin in the model frame (main link at identity).

        Parameters
        ----------
        angles : numpy.ndarray, shape (B, n_joints, 3)
            Radians.

        Returns
        -------
        R : numpy.ndarray, shape (B, n_links, 3, 3)
        p : numpy.ndarray, shape (B, n_links, 3)
            ``R[:, l] @ x + p[:, l]`` is link ``l``'s point ``x`` (link
            frame) in the model frame.  The placement is not applied.
        """
        return self.forward_trig(np.cos(angles), np.sin(angles))

    def forward_trig(self, c: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`forward` from the angles' cosines and sines (see :meth:`trig`).

        Parameters
        ----------
        c, s : numpy.ndarray, shape (B, n_joints, 3)

        Returns
        -------
        R : numpy.ndarray, shape (B, n_links, 3, 3)
        p : numpy.ndarray, shape (B, n_links, 3)

        Notes
        -----
        The same walk as :func:`kinematics.pose_transforms`, with the same
        rotation ``Rz Ry Rx``, but computed link-major (each link's
        transforms contiguous), one 4x4 product per tree level.
        """
        fig = self.figure
        B = c.shape[0]
        J = fig.n_joints
        # Component-major: each entry of every joint's 4x4 transform is one
        # contiguous (J, B) array, so each operation below is one long
        # vector operation (numpy is slow on trailing axes of length 3).
        cx, cy, cz = (np.ascontiguousarray(c[..., i].T) for i in range(3))
        sx, sy, sz = (np.ascontiguousarray(s[..., i].T) for i in range(3))
        szsy, czsy = sz * sy, cz * sy
        r = [
            [cy * cz, czsy * sx - sz * cx, czsy * cx + sz * sx],
            [cy * sz, szsy * sx + cz * cx, szsy * cx - cz * sx],
            [-sy, cy * sx, cy * cx],
        ]
        if self._framed.size:
            _conjugate(r, self._framed, self._framed_axes)
        if self._any_reversed:
            # Reversed joints (walked from the secondary) use R^T and
            # L2 - R^T L1 instead of R and L1 - R L2.
            rev = self._rev[:, None]
            for i, j in ((0, 1), (0, 2), (1, 2)):
                r[i][j], r[j][i] = np.where(rev, r[j][i], r[i][j]), np.where(rev, r[i][j], r[j][i])
        near, far = self._near[:, :, None], self._far[:, :, None]  # (J, 3, 1)
        t = [near[:, i] - (r[i][0] * far[:, 0] + r[i][1] * far[:, 1] + r[i][2] * far[:, 2]) for i in range(3)]
        # Written entry by entry into a (J, 4, 4, B) array (contiguous rows,
        # much faster than interleaving), then viewed as (J, B, 4, 4):
        # matmul takes the strided view as fast as a contiguous one.
        Tc = np.zeros((J, 4, 4, B))
        for i in range(3):
            for j in range(3):
                Tc[:, i, j] = r[i][j]
            Tc[:, i, 3] = t[i]
        Tc[:, 3, 3] = 1.0
        T = Tc.transpose(0, 3, 1, 2)
        X = np.empty((fig.n_links, B, 4, 4))
        X[fig.main] = np.eye(4)
        for joints, parents, children in self._levels:
            if isinstance(joints, int):
                # A level of one joint (every level of a chain): contiguous
                # blocks, written in place.
                np.matmul(X[parents], T[joints], out=X[children])
            else:
                X[children] = X[parents] @ T[joints]
        X = X.swapaxes(0, 1)
        return X[..., :3, :3], X[..., :3, 3]

    def cos_sin_one(self, q: np.ndarray, base: np.ndarray) -> np.ndarray:
        """Per joint ``[cos x, cos y, cos z, sin x, sin y, sin z, 1]`` for one pose, flattened.

        Parameters
        ----------
        q : numpy.ndarray, shape (V,)
            The variables, radians.
        base : numpy.ndarray, shape (n_joints * 7,)
            The same of the start angles (:meth:`cos_sin_base`): the axes
            that are not variables keep them.

        Returns
        -------
        numpy.ndarray, shape (n_joints * 7,)
        """
        cs = base.copy()
        cs[self._cos_at] = np.cos(q)
        cs[self._sin_at] = np.sin(q)
        return cs

    @staticmethod
    def cos_sin_base(angles: np.ndarray) -> np.ndarray:
        """:meth:`cos_sin_one`'s layout for all the angles ``(n_joints, 3)`` (radians), flattened."""
        return np.concatenate((np.cos(angles), np.sin(angles), np.ones((angles.shape[0], 1))), axis=1).ravel()

    def forward_one(self, cs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`forward_trig` and :meth:`axes_trig` for one pose, as 4x4 link transforms.

        Parameters
        ----------
        cs : numpy.ndarray, shape (n_joints * 7,)
            From :meth:`cos_sin_one`.

        Returns
        -------
        X : numpy.ndarray, shape (n_links, 4, 4)
            Each link's transform in the model frame (``X[l, :3, :3]`` is
            :meth:`forward`'s ``R``, ``X[l, :3, 3]`` its ``p``).
        omega, pivot : numpy.ndarray, shape (V, 3)
            As :meth:`axes` returns them.

        Notes
        -----
        A single solve calls this once an iteration on arrays of a few
        entries, where the cost is the number of numpy calls, not their
        size.  Every entry of ``Rz Ry Rx`` and of the three local axes is a
        signed sum of products of at most three cosines and sines
        (:data:`_TERMS`, :data:`_TERM_SUMS`), so one gather, two products
        and one batched product with per-joint matrices give every joint's
        4x4 transform (locations and reversal folded in) and local axes.
        The same values as :meth:`forward_trig` and :meth:`axes_trig` up to
        rounding.
        """
        fig = self.figure
        J = fig.n_joints
        ia, ib, ic = self._term_index
        t = cs[ia] * cs[ib] * cs[ic]  # (J, 16)
        e = np.matmul(t[:, None, :], self._term_maps)[:, 0]  # (J, 25)
        T = e[:, :16].reshape(J, 4, 4)
        X = np.empty((fig.n_links, 4, 4))
        X[fig.main] = self._eye4
        if self._chain is not None:
            chain_joints, chain_children = self._chain
            # Hillis-Steele scan: after the step of span d, P[k] is the
            # product of T[k-2d+1 .. k] (clipped at 0), left to right.
            P = T[chain_joints]
            d = 1
            while d < J:
                P[d:] = P[:-d] @ P[d:]
                d *= 2
            X[chain_children] = P
        else:
            for joints, parents, children in self._levels:
                if isinstance(joints, int):
                    np.matmul(X[parents], T[joints], out=X[children])
                else:
                    X[children] = X[parents] @ T[joints]
        M = self._axis_pivot.copy()
        M[:, :3, 0] = e[:, 16:].reshape(J, 3, 3)[self.var_joint, self.var_axis]
        op = X[self.var_primary] @ M  # (V, 4, 2)
        return X, op[:, :3, 0] * self.sign[:, None], op[:, :3, 1]

    def axes(self, angles: np.ndarray, R: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each variable's signed rotation axis and pivot in the model frame.

        Parameters
        ----------
        angles : numpy.ndarray, shape (B, n_joints, 3)
            Radians.
        R, p : numpy.ndarray
            From :meth:`forward` for the same angles.

        Returns
        -------
        omega : numpy.ndarray, shape (B, V, 3)
            Unit axis times :attr:`sign`: a point ``y`` of a link in
            ``downstream`` moves at ``omega x (y - c)`` per radian.
        c : numpy.ndarray, shape (B, V, 3)
            The joint's location, a point on the axis.
        """
        return self.axes_trig(np.cos(angles), np.sin(angles), R, p)

    def axes_trig(self, c: np.ndarray, s: np.ndarray, R: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`axes` from the angles' cosines and sines (see :meth:`trig`).

        Notes
        -----
        With ``R = Rz(az) Ry(ay) Rx(ax)``, turning ``ax`` turns the secondary
        about ``Rz Ry e_x``, ``ay`` about ``Rz e_y`` and ``az`` about ``e_z``,
        all in the primary's frame (the rotation nearest the point is applied
        first).  For a reversed joint the primary side moves, by ``R^T``,
        whose derivative is the same axis turned the other way.
        """
        B = c.shape[0]
        V = self.n_vars
        local = np.zeros((B, V, 3))
        vx, jx = self._axis_vars[0]
        if vx.size:
            cy, sy, cz, sz = c[:, jx, 1], s[:, jx, 1], c[:, jx, 2], s[:, jx, 2]
            local[:, vx, 0] = cy * cz
            local[:, vx, 1] = cy * sz
            local[:, vx, 2] = -sy
        vy, jy = self._axis_vars[1]
        if vy.size:
            local[:, vy, 0] = -s[:, jy, 2]
            local[:, vy, 1] = c[:, jy, 2]
        vz, _ = self._axis_vars[2]
        local[:, vz, 2] = 1.0
        if self._var_framed.size:
            # AXIS: the joint's own axes are F's columns.
            local[:, self._var_framed] = matvec3(self._var_frames, local[:, self._var_framed])
        Rp = R[:, self.var_primary]  # (B, V, 3, 3)
        omega = matvec3(Rp, local) * self.sign[:, None]
        pivot = p[:, self.var_primary] + matvec3(Rp, self.var_loc1)
        return omega, pivot

    def to_world(self, y: np.ndarray, t: np.ndarray | None) -> np.ndarray:
        """Model-frame points to the world: placement, then root translation.

        Parameters
        ----------
        y : numpy.ndarray, shape (B, N, 3)
        t : numpy.ndarray, shape (B, 3), or None

        Returns
        -------
        numpy.ndarray, shape (B, N, 3)
        """
        x = y if self.placement_is_identity else y @ self.A.T + self.b
        if t is not None:
            x = x + t[:, None, :]
        return x

    def to_world_vectors(self, v: np.ndarray) -> np.ndarray:
        """Model-frame vectors (velocities, directions) to the world, any leading shape."""
        return v if self.placement_is_identity else v @ self.A.T
