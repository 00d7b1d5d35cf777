"""The single solve's float path (runtime/ik/scalar.py) against the numpy formulas it replaces.

Small point-goal problems solved one at a time run their kinematics, goals
and damped step in Python floats.  Each piece is checked here against the
straightforward numpy version on random trees (random main links, AXIS
frames, joints turning about one axis or three, start angles at zero or not,
mirrored links, placements, translation, weights), and whole solves against
the numpy loop: same status, same iterations, the same angles to 1e-9 radian.
"""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.figure.tree import Figure, Joint, Link, frame_from_axis
from liganimate.runtime.ik import scalar
from liganimate.runtime.ik import solvers as S
from liganimate.runtime.ik.goals import GoalStack, PlaneGoal, PointGoal
from liganimate.runtime.ik.model import IKModel
from liganimate.runtime.ik.reach import solve_pose

HINGES = ([(-120, 120), (0, 0), (0, 0)], [(0, 0), (-90, 90), (0, 0)], [(0, 0), (0, 0), (-150, 150)])


def random_figure(rng: np.random.Generator, n: int) -> Figure:
    """A random tree of ``n`` links: hinges and ball joints, some with AXIS frames or limits away from zero."""
    parents = [int(rng.integers(0, i)) for i in range(1, n)]
    links = [Link(f"T{i}", None, scale=float(rng.choice([1.0, 2.0, -1.5]))) for i in range(n)]
    joints = []
    for i, p in zip(range(1, n), parents):
        kind = rng.integers(4)
        ext = HINGES[int(rng.integers(3))] if kind < 2 else [(-120, 150), (-90, 60), (-170, 170)]
        if kind == 3:
            ext = [(10, 80), (0, 0), (-30, -5)]  # neutral is outside: the start is clamped off zero
        axes = frame_from_axis(rng.normal(size=3)) if rng.random() < 0.3 else None
        joints.append(Joint(100 + i, p, i, rng.normal(size=3), rng.normal(size=3), ext, axes=axes))
    fig = Figure(tuple(links), tuple(joints), main=int(rng.integers(n)))
    if rng.random() < 0.5:
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        P = np.eye(4)
        P[:3, :3] = 1.7 * Q
        P[:3, 3] = rng.normal(size=3)
        fig = fig.with_placement(P)
    return fig


def problem(rng, fig, goals, translate, zero_start):
    model = IKModel(fig, rng.uniform(size=(fig.n_joints, 3)) < 0.8, translate=translate)
    stack = GoalStack(model, goals, 1)
    base = np.deg2rad(rng.uniform(fig.extremes[..., 0], fig.extremes[..., 1]))[None]
    if zero_start:
        base = np.where(rng.uniform(size=base.shape) < 0.8, 0.0, base)
    return S._Problem(model, stack, base)


@pytest.mark.parametrize("seed", range(12))
def test_float_evaluation_equals_the_numpy_one(seed):
    rng = np.random.default_rng(seed)
    fig = random_figure(rng, int(rng.integers(2, 8)))
    link = lambda: int(rng.integers(fig.n_links))  # noqa: E731
    goals = [PointGoal(link(), rng.normal(size=3), point=rng.normal(size=3), weight=2.0)]
    if seed % 3 == 0:
        goals.append(PointGoal(link(), rng.normal(size=3), weight=float(seed % 2)))
    prob = problem(rng, fig, goals, translate=seed % 4 == 1, zero_start=seed % 2 == 0)
    fast = scalar.kernel(prob, 1e-4, S.MAXSTEP)
    if prob.model.n_vars == 0:
        return
    assert fast is not None
    slow = S._numpy_kernel(prob, 1e-4)
    for _ in range(5):
        lo = np.where(np.isfinite(prob.lower), prob.lower, -3.0)
        hi = np.where(np.isfinite(prob.upper), prob.upper, 3.0)
        x = rng.uniform(lo, hi)
        a, b = fast.evaluate(x.tolist()), slow.evaluate(x)
        for got, want in zip(a, b):
            np.testing.assert_allclose(np.asarray(got), want, rtol=0, atol=1e-11)
        assert fast.curvature(a[1]) == pytest.approx(slow.curvature(b[1]), rel=1e-12)
        assert fast.met(a[2]) == slow.met(b[2])


@pytest.mark.parametrize("M, P", [(1, 4), (2, 2), (3, 6), (3, 3), (3, 9), (6, 6), (4, 7), (6, 4), (7, 5)])
def test_float_damped_step_equals_numpy_solve(M, P):
    """The written-out 3x3 Cholesky and the elimination against numpy.linalg.solve, both forms of the step."""
    rng = np.random.default_rng(M * 10 + P)
    for _ in range(20):
        J = rng.normal(size=(M, P))
        r = rng.normal(size=M)
        mu = float(10 ** rng.uniform(-3, 1))
        if M < P:
            want = J.T @ np.linalg.solve(J @ J.T + mu * np.eye(M), -r)
        else:
            want = -np.linalg.solve(J.T @ J + mu * np.eye(P), J.T @ r)
        np.testing.assert_allclose(scalar._damped(J.tolist(), r.tolist(), mu), want, rtol=0, atol=1e-9)
    # A matrix that is not definite (rounding can make one) goes to the elimination, as numpy would solve it.
    A = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    assert scalar._solve3(1.0, 2.0, 0.0, 1.0, 0.0, 1.0, [1.0, 1.0, 1.0]) is None
    np.testing.assert_allclose(scalar._solve(A, [1.0, 1.0, 1.0]), np.linalg.solve(A, [1.0, 1.0, 1.0]), atol=1e-15)


@pytest.mark.parametrize("seed", range(6))
def test_float_held_step_equals_the_numpy_one(seed):
    """Variables at their limits, pushed against them or not: hold, cap and projection agree."""
    rng = np.random.default_rng(100 + seed)
    V = int(rng.integers(2, 8))
    P = V + (3 if seed % 2 else 0)
    M = int(rng.choice([1, 3, 6]))
    lower = np.full(P, -np.inf)
    upper = np.full(P, np.inf)
    lower[:V] = rng.uniform(-2, -0.1, V)
    upper[:V] = rng.uniform(0.1, 2, V)
    upper[0] = np.inf  # a free axis
    for _ in range(30):
        x = rng.uniform(np.maximum(lower, -3), np.minimum(upper, 3))
        at = rng.uniform(size=V) < 0.4
        x[:V] = np.where(at, np.where(rng.uniform(size=V) < 0.5, lower[:V], upper[:V]), x[:V])
        x = np.where(np.isfinite(x), x, 0.5)
        J = rng.normal(size=(M, P)) * 3
        r = rng.normal(size=M) * 3
        mu = float(10 ** rng.uniform(-3, 0))
        want = S._held_step(x, r, J, lower, upper, mu, M < P, slice(None, None, min(M, P) + 1), V)
        dx, xn = scalar._step(x.tolist(), r.tolist(), J.tolist(), mu, lower.tolist(), upper.tolist(), V, S.MAXSTEP)
        np.testing.assert_allclose(dx, want, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(xn, x + np.asarray(dx))


def chain_of(rng, n: int) -> Figure:
    """A chain of hinges and a ball joint or two, with limits, as the benchmark's but varied."""
    links = [Link(f"C{i}", None) for i in range(n + 1)]
    joints = []
    for i in range(n):
        ext = HINGES[int(rng.integers(3))] if rng.random() < 0.8 else [(-100, 100), (-60, 60), (-170, 170)]
        joints.append(Joint(i + 1, i, i + 1, (0, 1.0 / n if i else 0, 0), (0, 0, 0), ext))
    return Figure(tuple(links), tuple(joints))


def numpy_only(monkeypatch):
    """Make the single solve take the numpy formulas."""
    monkeypatch.setattr(S, "float_kernel", lambda *args: None)


@pytest.mark.parametrize("seed", range(4))
def test_float_solves_end_where_the_numpy_loop_ends(seed, monkeypatch):
    """Random chains and trees, reachable and unreachable targets, limits, restarts, translation."""
    rng = np.random.default_rng(200 + seed)
    taken = []

    def recording(*args):
        k = scalar.kernel(*args)
        taken.append(k is not None)
        return k

    monkeypatch.setattr(S, "float_kernel", recording)
    for case in range(10):
        fig = chain_of(rng, int(rng.integers(2, 9))) if case % 2 else random_figure(rng, int(rng.integers(2, 7)))
        end = fig.n_links - 1
        target = rng.normal(size=3) * (0.5 if case % 3 else 3.0)
        goals = [PointGoal(end, target, point=(0, 0.1, 0))]
        if case % 4 == 0:
            goals.append(PointGoal(int(rng.integers(fig.n_links)), rng.normal(size=3), weight=0.3))
        opts = dict(tolerance=1e-4, max_iterations=int(rng.choice([12, 30, 200])), restarts=int(rng.integers(0, 3)))
        opts["translate"] = case % 5 == 4
        start = np.clip(rng.normal(size=(fig.n_joints, 3)) * 30, fig.extremes[..., 0], fig.extremes[..., 1])
        a = solve_pose(fig, goals, start=start if case % 3 == 0 else None, **opts)
        with monkeypatch.context() as m:
            numpy_only(m)
            b = solve_pose(fig, goals, start=start if case % 3 == 0 else None, **opts)
        assert (a.status, a.iterations) == (b.status, b.iterations)
        np.testing.assert_allclose(np.deg2rad(a.angles), np.deg2rad(b.angles), rtol=0, atol=1e-9)  # radians
        np.testing.assert_allclose(a.translation, b.translation, rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.residuals, b.residuals, rtol=0, atol=1e-9)
    assert sum(taken) >= 8, "the float path was taken"


def test_slides_take_the_float_path_too(monkeypatch):
    """A figure with a SLIDE: its slides are held and the angles solved, by floats or numpy alike."""
    links = (Link("BASE", None), Link("RAIL", None), Link("ARM", None))
    joints = (
        Joint(1, 0, 1, (0, 0, 0), (0, 0, 0), [(-0.5, 0.5), (0, 0), (0, 0)], slide=True),
        Joint(2, 1, 2, (0, 0, 0), (0, -1, 0), [(-170, 170)], axes=frame_from_axis((0, 0, 1))),
    )
    fig = Figure(links, joints)
    goals = [PointGoal("ARM", (0.6, 0.3, 0.0))]
    a = solve_pose(fig, goals, tolerance=1e-6)
    with monkeypatch.context() as m:
        numpy_only(m)
        b = solve_pose(fig, goals, tolerance=1e-6)
    assert a.converged and (a.status, a.iterations) == (b.status, b.iterations)
    np.testing.assert_allclose(np.deg2rad(a.angles), np.deg2rad(b.angles), rtol=0, atol=1e-9)


def test_which_problems_take_the_float_path():
    rng = np.random.default_rng(7)
    fig = chain_of(rng, 6)
    model = IKModel(fig, np.ones((6, 3), dtype=bool))
    base = np.zeros((1, 6, 3))

    def kernel_for(goals, model=model):
        return scalar.kernel(S._Problem(model, GoalStack(model, goals, 1), base), 1e-4, S.MAXSTEP)

    assert kernel_for([PointGoal(6, (0.1, 0.2, 0.3))]) is not None
    assert kernel_for([PointGoal(6, (0.1, 0.2, 0.3)), PointGoal(3, (0, 0, 0))]) is not None
    assert kernel_for([PlaneGoal(6, (0, 0, 0), (0, 1, 0))]) is None  # only point goals
    big = chain_of(rng, 90)
    big_model = IKModel(big, np.ones((90, 3), dtype=bool))
    big_base = np.zeros((1, 90, 3))
    prob = S._Problem(big_model, GoalStack(big_model, [PointGoal(90, (0.1, 0.2, 0.3))], 1), big_base)
    assert scalar.kernel(prob, 1e-4, S.MAXSTEP) is None  # 3 rows x 90 variables: numpy's products win
