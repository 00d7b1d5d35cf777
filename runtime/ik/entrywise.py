"""Point goals' kinematics written entry by entry: in floats for one solve, in arrays for a batch.

Every entry of a rotation, an origin, an axis, a pivot or a Jacobian row is a
value of its own, combined with ``+``, ``-`` and ``*`` only, so the same walk
serves two uses:

* **One solve** (the language's STARTREACH, ``reach``): about ten iterations
  on a handful of numbers, where one numpy call costs as much as twenty
  float operations.  For point goals on a small problem (:func:`kernel`
  says which), :func:`solvers._dls_one` takes its evaluation and its step
  from here in Python floats, with the damped step of
  ``solvers._held_step`` (hold, damped solve, cap, projection; its 3x3
  system by a written-out Cholesky factorisation, :func:`solve3`, any other
  small one by Gaussian elimination with partial pivoting).
* **A batch** (:func:`batch_evaluator`): each entry an array over the batch,
  where the 4x4 products and gathers of :meth:`IKModel.forward_trig` and
  :meth:`IKModel.axes_trig` cost several times more.

The walk goes joint by joint from the main link.  A joint that turns about
one of its own axes, its other two at zero and no AXIS frame (every hinge
of a chain), is a plane rotation of two of its parent's columns, and its
variable's axis a column of the parent's rotation; any other joint is its
full ``Rz Ry Rx`` (turned by its AXIS frame, transposed when walked
backwards) times its parent's rotation.  A variable's pivot is its joint's
location, passed on the way.

The values are those of the numpy formulas (:meth:`IKModel.forward_one`,
:meth:`GoalStack.evaluate_one` and ``evaluate``) up to rounding; the tests
check both against each other on random trees, placements, limits,
translation and slides (``tests/runtime/ik/test_entrywise.py``).  Plane and
axis goals, and problems too big for it, stay with the numpy formulas.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from operator import add, ge, le, mul, sub

import numpy as np

__all__ = ["Kernel", "kernel", "batch_evaluator", "solve3", "MAX_SIZE", "MAX_FULL_JOINTS"]

#: The float path takes problems with at most this many residual rows times
#: variables (a point goal on a 30-joint chain is 90): beyond, the step's
#: products are long enough for numpy to win.
MAX_SIZE = 240
#: ... and whose damped system (the smaller of rows and variables) is at most this big.
MAX_SYSTEM = 6

_IDENTITY = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
_ORIGIN = (_IDENTITY, (0.0, 0.0, 0.0))  # the main link's rotation and origin


@dataclass(frozen=True)
class Kernel:
    """A single solve's evaluation, step and norms on one representation of its vectors.

    ``solvers._dls_one`` runs its loop on either numpy arrays or, for small
    point-goal problems, lists of floats (:func:`kernel`); the rules (the
    acceptance, the damping, the stopping) are the same code for both.

    Attributes
    ----------
    evaluate : callable
        ``evaluate(x) -> (r, J, dist, f)``: residual rows, Jacobian rows,
        goal distances and cost at variables ``x``.
    step : callable
        ``step(x, r, J, mu) -> (dx, x + dx)``: the damped step, variables
        held at a limit they push against, capped and projected.
    curvature : callable
        ``curvature(J) -> float``: the largest squared column norm.
    native : callable
        A numpy value (a row of a batch's arrays) in this representation.
    linear_sq : callable
        ``linear_sq(r, J, dx) -> |r + J dx|^2``.
    norm : callable
        ``norm(v) -> |v|``.
    met : callable
        ``met(dist) -> bool``: every goal that counts within the tolerance.
    n_active : int
        How many goals count (weight above 0).
    """

    evaluate: Callable
    step: Callable
    curvature: Callable
    native: Callable
    linear_sq: Callable
    norm: Callable
    met: Callable
    n_active: int


# ---------------------------------------------------------------- 3x3 rotations, row-major 9-tuples


def _mul(a: tuple, b: tuple) -> tuple:
    """The product of two 3x3 matrices."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (
        a0 * b0 + a1 * b3 + a2 * b6,
        a0 * b1 + a1 * b4 + a2 * b7,
        a0 * b2 + a1 * b5 + a2 * b8,
        a3 * b0 + a4 * b3 + a5 * b6,
        a3 * b1 + a4 * b4 + a5 * b7,
        a3 * b2 + a4 * b5 + a5 * b8,
        a6 * b0 + a7 * b3 + a8 * b6,
        a6 * b1 + a7 * b4 + a8 * b7,
        a6 * b2 + a7 * b5 + a8 * b8,
    )


def _transposed(a: tuple) -> tuple:
    return (a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8])


def _joint_rotation(cs: list, frame: tuple | None, rev: bool) -> tuple:
    """A joint's rotation from ``[cx, cy, cz, sx, sy, sz]``: ``Rz Ry Rx``, framed ``F R F^T``, transposed if reversed."""
    cx, cy, cz, sx, sy, sz = cs
    szsy, czsy = sz * sy, cz * sy
    r = (
        cy * cz,
        czsy * sx - sz * cx,
        czsy * cx + sz * sx,
        cy * sz,
        szsy * sx + cz * cx,
        szsy * cx - cz * sx,
        -sy,
        cy * sx,
        cy * cx,
    )
    if frame is not None:
        r = _mul(_mul(frame, r), _transposed(frame))
    return _transposed(r) if rev else r


def _turned(R: tuple, axis: int, c: float, s: float) -> tuple:
    """``R @ Ra(theta)``, ``Ra`` the turn about coordinate axis ``axis``: two of ``R``'s columns turned."""
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = R
    if axis == 2:
        return (
            c * r0 + s * r1,
            c * r1 - s * r0,
            r2,
            c * r3 + s * r4,
            c * r4 - s * r3,
            r5,
            c * r6 + s * r7,
            c * r7 - s * r6,
            r8,
        )
    if axis == 0:
        return (
            r0,
            c * r1 + s * r2,
            c * r2 - s * r1,
            r3,
            c * r4 + s * r5,
            c * r5 - s * r4,
            r6,
            c * r7 + s * r8,
            c * r8 - s * r7,
        )
    return (
        c * r0 - s * r2,
        r1,
        s * r0 + c * r2,
        c * r3 - s * r5,
        r4,
        s * r3 + c * r5,
        c * r6 - s * r8,
        r7,
        s * r6 + c * r8,
    )


def _local_axis(cs: list, axis: int, frame: tuple | None) -> tuple:
    """A joint variable's axis in its primary's frame: ``Rz Ry e_x``, ``Rz e_y`` or ``e_z``, times ``F``."""
    cx, cy, cz, sx, sy, sz = cs
    if axis == 0:
        v = (cy * cz, cy * sz, -sy)
    elif axis == 1:
        v = (-sz, cz, 0.0)
    else:
        v = (0.0, 0.0, 1.0)
    if frame is None:
        return v
    f = frame
    return (
        f[0] * v[0] + f[1] * v[1] + f[2] * v[2],
        f[3] * v[0] + f[4] * v[1] + f[5] * v[2],
        f[6] * v[0] + f[7] * v[1] + f[8] * v[2],
    )


def _nonzero(v) -> tuple:
    """``(index, value)`` of a 3-vector's non-zero components (the walk skips the zeros)."""
    return tuple((i, float(x)) for i, x in enumerate(v) if x != 0.0)


def _moved(R: tuple, p: tuple, v: tuple) -> tuple:
    """``p + R v`` for ``v`` given by :func:`_nonzero`."""
    px, py, pz = p
    for i, x in v:
        # Not +=: on a batch's arrays that would write into the parent's origin.
        px = px + R[i] * x
        py = py + R[3 + i] * x
        pz = pz + R[6 + i] * x
    return (px, py, pz)


# ---------------------------------------------------------------- the plan


@dataclass(frozen=True)
class _Walk:
    """What the walk of one model needs, fixed per figure (kept on the model)."""

    steps: tuple  # per joint in walk order: (joint, parent link, child link, reversed, frame, near, far, variables)
    n_vars: int
    n_links: int
    main: int
    lower: list  # the variables' bounds (radians; the translation's infinite)
    upper: list
    starts: dict  # start angles (bytes) -> :func:`_joint_kinds` of them, for the last few


def _walk_of(model) -> _Walk:
    """The model's :class:`_Walk`, built at its first single solve."""
    walk = model.__dict__.get("_entrywise_walk")
    if walk is not None:
        return walk
    fig = model.figure
    var_of = {(k, a): v for v, (k, a) in enumerate(zip(model.var_joint.tolist(), model.var_axis.tolist()))}
    frames = [tuple(fig.frames[k].ravel().tolist()) if fig.has_frames[k] else None for k in range(fig.n_joints)]
    steps = []
    for joints, parents, children in model._levels:
        level = [(joints, parents, children)] if isinstance(joints, int) else zip(joints, parents, children)
        for k, parent, child in level:
            k = int(k)
            var_axes = tuple(var_of.get((k, a), -1) for a in range(3))
            steps.append(
                (
                    k,
                    int(parent),
                    int(child),
                    bool(model._rev[k]),
                    frames[k],
                    _nonzero(model._near[k]),
                    _nonzero(model._far[k]),
                    var_axes,
                )
            )
    pad = [math.inf] * (model.n_params - model.n_vars)
    lower, upper = model.lower.tolist() + [-v for v in pad], model.upper.tolist() + pad
    walk = _Walk(tuple(steps), model.n_vars, fig.n_links, fig.main, lower, upper, {})
    model.__dict__["_entrywise_walk"] = walk
    return walk


# How a joint's rotation is made (see _joint_kinds).
_TURN, _FIXED, _FULL = 1, 2, 3


def _joint_kinds(walk: _Walk, base: np.ndarray) -> tuple[list, list]:
    """Per walk step, how its rotation is made for start angles ``base`` (n_joints, 3), and every joint's trig.

    A kind is ``(_TURN, axis, variable)`` (one variable axis, the others at
    zero, no frame), ``(_FIXED, M)`` (no variable: its rotation, once; None
    when that is the identity, all angles zero and no frame) or ``(_FULL,)``.
    The trig is ``[cx, cy, cz, sx, sy, sz]`` of the start angles.
    """
    cos, sin = np.cos(base).tolist(), np.sin(base).tolist()
    trig = [c + s for c, s in zip(cos, sin)]
    zero = (base == 0.0).tolist()
    kinds: list[tuple | None] = []
    for k, _parent, _child, rev, frame, _near, _far, variables in walk.steps:
        moving = [a for a in range(3) if variables[a] >= 0]
        if not moving:
            still = frame is None and all(zero[k])
            kinds.append(None if still else (_FIXED, _joint_rotation(trig[k], frame, rev)))
        elif len(moving) == 1 and frame is None and all(zero[k][a] for a in range(3) if a != moving[0]):
            kinds.append((_TURN, moving[0], variables[moving[0]]))
        else:
            kinds.append((_FULL,))
    return kinds, trig


def _walked(walk: _Walk, kinds: list, trig: list, cv: list, sv: list, origin: tuple) -> tuple[list, list, list, list]:
    """Every link's rotation (9-tuple) and origin (3-tuple), and every variable's signed axis and pivot.

    ``cv``, ``sv`` are the variables' cosines and sines; ``origin`` the main
    link's rotation and origin (floats, or arrays for a batch).  A
    variable's pivot is its joint's location, ``p_near + R_near near`` on
    the walk's way (the same point seen from either link), and a hinge's
    axis is a column of the near link's rotation, which its turn keeps.
    """
    R: list = [None] * walk.n_links
    p: list = [None] * walk.n_links
    omega: list = [None] * walk.n_vars
    pivot: list = [None] * walk.n_vars
    R[walk.main], p[walk.main] = origin
    for (k, parent, child, rev, frame, near, far, variables), kind in zip(walk.steps, kinds):
        RP = R[parent]
        pc = _moved(RP, p[parent], near)  # the joint's location
        if kind is None:
            RC = RP
        elif kind[0] == _TURN:
            a, v = kind[1], kind[2]
            RC = _turned(RP, a, cv[v], -sv[v] if rev else sv[v])
            omega[v] = (-RP[a], -RP[3 + a], -RP[6 + a]) if rev else (RP[a], RP[3 + a], RP[6 + a])
            pivot[v] = pc
        elif kind[0] == _FIXED:
            RC = _mul(RP, kind[1])
        else:
            RC = _full_joint(RP, list(trig[k]), variables, cv, sv, frame, rev, pc, omega, pivot)
        R[child] = RC
        for i, f in far:
            pc = (pc[0] - RC[i] * f, pc[1] - RC[3 + i] * f, pc[2] - RC[6 + i] * f)
        p[child] = pc
    return R, p, omega, pivot


def _full_joint(RP: tuple, cs: list, variables: tuple, cv, sv, frame, rev: bool, at: tuple, omega: list, pivot: list):
    """A joint's far-side rotation from ``RP`` through its full ``Rz Ry Rx``; its variables' axes and pivots set.

    ``cs`` is the joint's start trig (its variables' replaced here) and ``at``
    the joint's location.  The axes are those of :meth:`IKModel.axes`, in
    the primary's frame (the far link's when walked backwards), signed.
    """
    for a in range(3):
        v = variables[a]
        if v >= 0:
            cs[a], cs[a + 3] = cv[v], sv[v]
    RC = _mul(RP, _joint_rotation(cs, frame, rev))
    Rp = RC if rev else RP
    for a in range(3):
        v = variables[a]
        if v >= 0:
            u = _local_axis(cs, a, frame)
            w = (
                Rp[0] * u[0] + Rp[1] * u[1] + Rp[2] * u[2],
                Rp[3] * u[0] + Rp[4] * u[1] + Rp[5] * u[2],
                Rp[6] * u[0] + Rp[7] * u[1] + Rp[8] * u[2],
            )
            omega[v] = (-w[0], -w[1], -w[2]) if rev else w
            pivot[v] = at
    return RC


# ---------------------------------------------------------------- point goals


@dataclass(frozen=True)
class _Goals:
    """A single solve's point goals (all but their targets) and placement, in floats."""

    links: tuple
    points: tuple  # link points (:func:`_nonzero`), link frame
    weights: tuple  # each goal's row weight (square root of its normalised weight)
    moves: tuple  # per goal, per variable: whether the variable moves the goal's link
    A: tuple | None  # the placement's 3x3 (row-major), None when it is the identity
    b: tuple
    translate: bool
    length: float
    n_vars: int
    inactive: list  # per goal, whether its weight is 0


def _goals_of(model, stack) -> _Goals:
    """:class:`_Goals` of a batch of one's point goals, kept in the stack's memo (shared by its re-targeted copies)."""
    hit = stack.memo.get("float goals")
    if hit is not None:
        return hit
    G = len(stack.p_link)
    w = stack.row_weight[0].tolist()
    identity = model.placement_is_identity
    goals = _Goals(
        tuple(stack.p_link.tolist()),
        tuple(_nonzero(v) for v in stack.p_local),
        tuple(w[3 * g] for g in range(G)),
        tuple(tuple(row) for row in (stack._downstream_p > 0).tolist()),
        None if identity else tuple(model.A.ravel().tolist()),
        tuple(model.b.tolist()),
        model.translate,
        float(model.length),
        model.n_vars,
        (~stack.active[0]).tolist(),
    )
    stack.memo["float goals"] = goals
    return goals


def _apply(A: tuple, v: tuple) -> tuple:
    return (
        A[0] * v[0] + A[1] * v[1] + A[2] * v[2],
        A[3] * v[0] + A[4] * v[1] + A[5] * v[2],
        A[6] * v[0] + A[7] * v[1] + A[8] * v[2],
    )


_ZERO3 = (0.0, 0.0, 0.0)


def _point_rows(
    goals: _Goals, targets: list, R: list, p: list, omega: list, pivot: list, x: list
) -> tuple[list, list, list]:
    """Residual rows, Jacobian rows and distances of the point goals at ``targets`` (as :meth:`GoalStack.evaluate_one`)."""
    A, V = goals.A, goals.n_vars
    t = [v * goals.length for v in x[V:]] if goals.translate else None
    r: list = []
    J: list = []
    dist = []
    for link, point, target, w, moves in zip(goals.links, goals.points, targets, goals.weights, goals.moves):
        y = _moved(R[link], p[link], point)
        world = y if A is None else _apply(A, y)
        if A is not None:
            world = (world[0] + goals.b[0], world[1] + goals.b[1], world[2] + goals.b[2])
        if t is not None:
            world = (world[0] + t[0], world[1] + t[1], world[2] + t[2])
        res = (world[0] - target[0], world[1] - target[1], world[2] - target[2])
        dist.append(math.sqrt(res[0] * res[0] + res[1] * res[1] + res[2] * res[2]))
        cols = []
        for (ox, oy, oz), (cx, cy, cz), moving in zip(omega, pivot, moves):
            if not moving:
                cols.append(_ZERO3)
                continue
            dx, dy, dz = y[0] - cx, y[1] - cy, y[2] - cz
            u = (oy * dz - oz * dy, oz * dx - ox * dz, ox * dy - oy * dx)
            cols.append(u if A is None else _apply(A, u))
        rows = list(map(list, zip(*cols))) if cols else [[], [], []]  # the goal's three rows
        if w != 1.0:
            rows = [[v * w for v in row] for row in rows]
        if t is not None:
            lw = goals.length * w
            for i, row in enumerate(rows):
                row += [lw if j == i else 0.0 for j in range(3)]
        J += rows
        r += [res[0] * w, res[1] * w, res[2] * w]
    return r, J, dist


# ---------------------------------------------------------------- the damped step


def _dot(a, b) -> float:
    return sum(map(mul, a, b))


def _solve(A: list, b: list) -> list:
    """``A^-1 b`` for a small non-singular ``A`` (lists): Gaussian elimination with partial pivoting."""
    n = len(b)
    A = [row[:] for row in A]
    b = list(b)
    for j in range(n):
        piv = max(range(j, n), key=lambda i: abs(A[i][j]))
        if A[piv][j] == 0.0:
            return np.linalg.solve(np.array(A), np.array(b)).tolist()  # raises as the numpy step would
        if piv != j:
            A[j], A[piv] = A[piv], A[j]
            b[j], b[piv] = b[piv], b[j]
        Aj, inv = A[j], 1.0 / A[j][j]
        for i in range(j + 1, n):
            m = A[i][j] * inv
            if m != 0.0:
                Ai = A[i]
                for k in range(j + 1, n):
                    Ai[k] -= m * Aj[k]
                b[i] -= m * b[j]
    out = [0.0] * n
    for i in range(n - 1, -1, -1):
        Ai = A[i]
        out[i] = (b[i] - sum([Ai[k] * out[k] for k in range(i + 1, n)])) / Ai[i]
    return out


def _positive(v) -> bool:
    """``v > 0`` for a float, or for every entry of an array (a batch's)."""
    return v > 0.0 if type(v) is float else bool((v > 0.0).all())


def solve3(a00, a01, a02, a11, a12, a22, r, sqrt=math.sqrt) -> tuple | None:
    """``-A^-1 r`` for the symmetric positive definite 3x3 ``A`` by Cholesky, written out; None if not definite.

    Each entry a float, or an array over a batch (then ``sqrt`` is
    :func:`numpy.sqrt`, and None unless every element's ``A`` is definite).
    """
    if not _positive(a00):
        return None
    l00 = sqrt(a00)
    l10, l20 = a01 / l00, a02 / l00
    d1 = a11 - l10 * l10
    if not _positive(d1):
        return None
    l11 = sqrt(d1)
    l21 = (a12 - l20 * l10) / l11
    d2 = a22 - l20 * l20 - l21 * l21
    if not _positive(d2):
        return None
    l22 = sqrt(d2)
    z0 = -r[0] / l00
    z1 = (-r[1] - l10 * z0) / l11
    z2 = (-r[2] - l20 * z0 - l21 * z1) / l22
    y2 = z2 / l22
    y1 = (z1 - l21 * y2) / l11
    return (z0 - l10 * y1 - l20 * y2) / l00, y1, y2


def _damped(J: list, r: list, mu: float) -> list:
    """``-(J^T J + mu I)^-1 J^T r``, through ``-J^T (J J^T + mu I)^-1 r`` when ``J`` has fewer rows than columns."""
    M, P = len(J), len(J[0]) if J else 0
    if M == 3 and P > 3:
        # One point goal: the 3x3 system written out.
        j0, j1, j2 = J
        y3 = solve3(
            _dot(j0, j0) + mu, _dot(j0, j1), _dot(j0, j2), _dot(j1, j1) + mu, _dot(j1, j2), _dot(j2, j2) + mu, r
        )
        if y3 is not None:
            y0, y1, y2 = y3
            return [a * y0 + b * y1 + c * y2 for a, b, c in zip(j0, j1, j2)]
    if M < P:
        A = [[_dot(a, b) for b in J] for a in J]
        for i in range(M):
            A[i][i] += mu
        y = _solve(A, [-v for v in r])
        return [_dot(col, y) for col in zip(*J)]
    cols = list(zip(*J))
    A = [[_dot(a, b) for b in cols] for a in cols]
    for i in range(P):
        A[i][i] += mu
    return [-v for v in _solve(A, [_dot(col, r) for col in cols])]


def _held_damped(r: list, J: list, mu: float, at_lower: list, at_upper: list) -> tuple[list, list]:
    """The damped step holding the variables at a limit that the descent, then the step, pushes against.

    Returns the step and which variables are free (at most three passes, as ``solvers._held_step``).
    """
    g = [_dot(col, r) for col in zip(*J)]
    free = [not ((lo and gi > 0) or (hi and gi < 0)) for lo, hi, gi in zip(at_lower, at_upper, g)]
    for _pass in range(3):
        dx = _damped([[v if f else 0.0 for v, f in zip(row, free)] for row in J], r, mu)
        out = [f and ((lo and d < 0) or (hi and d > 0)) for f, lo, hi, d in zip(free, at_lower, at_upper, dx)]
        if not any(out):
            break
        free = [f and not o for f, o in zip(free, out)]
    return [d if f else 0.0 for d, f in zip(dx, free)], free


def _step(x: list, r: list, J: list, mu: float, lower: list, upper: list, V: int, maxstep: float) -> tuple:
    """``solvers._held_step`` in floats: held, damped, capped and projected; returns ``(dx, x + dx)``.

    Only a variable at a limit can be held, so while none is (most
    iterations) the step is the plain damped one.
    """
    if any(map(le, x, lower)) or any(map(ge, x, upper)):
        # Capping scales the held variables' zeros to zeros: hold first, then cap.
        dx, _free = _held_damped(r, J, mu, list(map(le, x, lower)), list(map(ge, x, upper)))
    else:
        dx = _damped(J, r, mu)
    big = max(map(abs, dx[:V]), default=0.0)
    if big > maxstep:
        scale = maxstep / big
        dx = [d * scale for d in dx]
    xn = list(map(min, map(max, map(add, x, dx), lower), upper))
    dx = list(map(sub, xn, x))
    return dx, list(map(add, x, dx))


def _curvature(J) -> float:
    """The largest squared column norm of the Jacobian rows ``J``."""
    return max([_dot(col, col) for col in zip(*J)], default=0.0)


def _linear_sq(r: list, J: list, dx: list) -> float:
    """``|r + J dx|^2``: the linear model's cost of a step, times 2."""
    lin = [ri + _dot(row, dx) for ri, row in zip(r, J)]
    return _dot(lin, lin)


# ---------------------------------------------------------------- the kernel


def kernel(prob, tol: float, maxstep: float) -> Kernel | None:
    """The floats' :class:`Kernel` for ``solvers._Problem`` ``prob`` (a batch of one), or None.

    None unless every goal is a point goal and the problem is small
    (:data:`MAX_SIZE`, :data:`MAX_SYSTEM`): then the numpy formulas serve.
    """
    model, stack = prob.model, prob.stack
    M, P = stack.n_rows, model.n_params
    if not stack._points_only or M * P > MAX_SIZE or min(M, P) > MAX_SYSTEM or M == 0 or P == 0:
        return None
    walk = _walk_of(model)
    kinds, trig = _start_of(walk, prob.base[0])
    goals = _goals_of(model, stack)
    targets = stack.p_target[0].tolist()
    lower, upper, V, inactive = walk.lower, walk.upper, model.n_vars, goals.inactive

    def evaluate(x: list) -> tuple:
        R, p, omega, pivot = _walked(walk, kinds, trig, list(map(math.cos, x)), list(map(math.sin, x)), _ORIGIN)
        r, J, dist = _point_rows(goals, targets, R, p, omega, pivot, x)
        return r, J, dist, 0.5 * _dot(r, r)

    return Kernel(
        evaluate=evaluate,
        step=lambda x, r, J, mu: _step(x, r, J, mu, lower, upper, V, maxstep),
        curvature=_curvature,
        native=_native,
        linear_sq=_linear_sq,
        norm=lambda v: math.sqrt(_dot(v, v)),
        met=lambda dist: all([d <= tol or off for d, off in zip(dist, inactive)]),
        n_active=inactive.count(False),
    )


def _start_of(walk: _Walk, base: np.ndarray) -> tuple[list, list]:
    """:func:`_joint_kinds` of start angles ``base`` (n_joints, 3), remembered on the walk for the last few."""
    key = base.tobytes()
    start = walk.starts.get(key)
    if start is None:
        if len(walk.starts) >= 8:
            walk.starts.clear()
        start = walk.starts[key] = _joint_kinds(walk, base)
    return start


def _native(a):
    """A numpy value as Python floats (lists)."""
    return a.tolist() if isinstance(a, np.ndarray) else a


# ---------------------------------------------------------------- batches


def batch_evaluator(prob) -> Callable | None:
    """``evaluate(stack, x) -> (r, J, dist)`` for sub-batches of ``solvers._Problem`` ``prob``, entry by entry; or None.

    The same walk as a single solve's, each entry a numpy array over the
    batch instead of a float: a hinge costs a few dozen operations on arrays
    of ``B`` numbers, where the 4x4 products of :meth:`IKModel.forward_trig`
    and the gathers of :meth:`IKModel.axes_trig` cost several times more.
    None (the numpy formulas serve) unless every goal is a point goal, the
    batch shares one start pose and at most :data:`MAX_FULL_JOINTS` moving
    joints are not hinges.
    """
    model, stack = prob.model, prob.stack
    if not stack._points_only or prob.base.shape[0] != 1 or stack.n_rows == 0 or model.n_vars == 0:
        return None
    walk = _walk_of(model)
    kinds, trig = _start_of(walk, prob.base[0])
    if sum(1 for kind in kinds if kind is not None and kind[0] != _TURN) > MAX_FULL_JOINTS:
        return None
    goals = _goals_of(model, stack)
    V = model.n_vars

    def evaluate(stack, x: np.ndarray) -> tuple:
        B = x.shape[0]
        xt = np.ascontiguousarray(x.T)
        one, zero = np.ones(B), np.zeros(B)
        origin = ((one, zero, zero, zero, one, zero, zero, zero, one), (zero, zero, zero))
        R, p, omega, pivot = _walked(walk, kinds, trig, list(np.cos(xt[:V])), list(np.sin(xt[:V])), origin)
        return _batch_point_rows(
            goals, stack, R, p, np.array(omega), np.array(pivot), xt[V:] if model.translate else None
        )

    return evaluate


#: A batch walks entry by entry when at most this many moving joints are not hinges
#: (each costs a full 3x3 product, about 80 array operations, where the 4x4
#: products take a whole tree level at once).  Measured on batches of 1000:
#: six ball joints 1.3 times as fast as the 4x4 products, the library's
#: humanoid (19 joints) 1.0 to 1.3 times.
MAX_FULL_JOINTS = 24


def _batch_point_rows(goals: _Goals, stack, R: list, p: list, omega, pivot, t) -> tuple:
    """``r (B, M)``, ``J (B, M, P)`` and ``dist (B, G)`` of the point goals for a batch.

    ``omega``, ``pivot``: (V, 3, B); ``t``: the translation variables (3, B) or None.
    """
    B = omega.shape[2]
    V, G = goals.n_vars, len(goals.links)
    P = V + (3 if t is not None else 0)
    Y = np.array([_moved(R[link], p[link], point) for link, point in zip(goals.links, goals.points)])  # (G, 3, B)
    world = (
        Y if goals.A is None else np.einsum("ij,gjb->gib", np.reshape(goals.A, (3, 3)), Y) + np.reshape(goals.b, (3, 1))
    )
    if t is not None:
        world = world + t * goals.length
    res = world - stack.p_target.transpose(1, 2, 0)
    dist = np.sqrt(np.einsum("gib,gib->bg", res, res))
    # (G, 1, B): a goal's rows share its weight; None when every weight is the largest (1).
    w = None if bool((stack.row_weight == 1.0).all()) else stack.row_weight.T.reshape(G, 3, B)[:, :1]
    J = np.zeros((G, 3, P, B))
    o0, o1, o2 = omega[:, 0], omega[:, 1], omega[:, 2]  # (V, B) each
    for g, moves in enumerate(goals.moves):
        D = Y[g] - pivot  # (V, 3, B)
        Jg = J[g, :, :V]  # (3, V, B): omega x D, written in place
        np.subtract(o1 * D[:, 2], o2 * D[:, 1], out=Jg[0])
        np.subtract(o2 * D[:, 0], o0 * D[:, 2], out=Jg[1])
        np.subtract(o0 * D[:, 1], o1 * D[:, 0], out=Jg[2])
        if not all(moves):
            Jg *= np.array(moves, dtype=float)[:, None]
        if goals.A is not None:
            Jg[...] = np.einsum("ij,jvb->ivb", np.reshape(goals.A, (3, 3)), Jg)
        if w is not None:
            Jg *= w[g]
        if t is not None:
            J[g, :, V:] = np.eye(3)[:, :, None] * (goals.length if w is None else goals.length * w[g])
    r = (res if w is None else res * w).reshape(3 * G, B).T
    return r, J.reshape(3 * G, P, B).transpose(2, 0, 1), dist
