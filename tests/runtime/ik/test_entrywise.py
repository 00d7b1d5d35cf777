"""The single solve's float path (runtime/ik/entrywise.py) against the numpy formulas it replaces.

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

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.tree import Figure, Joint, Link, frame_from_axis
from liganimate.runtime.ik import entrywise as scalar
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
    assert scalar.solve3(1.0, 2.0, 0.0, 1.0, 0.0, 1.0, [1.0, 1.0, 1.0]) is None
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


# ------------------------------------------------------------------ batches


def no_walk(monkeypatch):
    """Make batches take the numpy formulas (IKModel.forward_trig, axes_trig, GoalStack.evaluate)."""
    monkeypatch.setattr(S, "batch_evaluator", lambda prob: None)


@pytest.mark.parametrize("seed", range(12))
def test_batch_walk_equals_the_numpy_evaluation(seed, monkeypatch):
    """Random trees (hinges, ball joints, AXIS frames, start poses off zero), placements, translation,
    batched targets and weights (some zero): residuals, Jacobian and distances agree to 1e-11."""
    rng = np.random.default_rng(300 + seed)
    fig = random_figure(rng, int(rng.integers(2, 8)))
    B = int(rng.integers(1, 7))
    link = lambda: int(rng.integers(fig.n_links))  # noqa: E731
    goals = [PointGoal(link(), rng.normal(size=(B, 3)), point=rng.normal(size=3), weight=2.0)]
    if seed % 3 == 0:
        goals.append(PointGoal(link(), rng.normal(size=(B, 3)), weight=rng.choice([0.0, 0.5, 3.0], size=B)))
    model = IKModel(fig, rng.uniform(size=(fig.n_joints, 3)) < 0.8, translate=seed % 4 == 1)
    stack = GoalStack(model, goals, B)
    base = np.deg2rad(rng.uniform(fig.extremes[..., 0], fig.extremes[..., 1]))[None]
    if seed % 2 == 0:
        base = np.where(rng.uniform(size=base.shape) < 0.8, 0.0, base)
    prob = S._Problem(model, stack, base)
    if model.n_vars == 0:
        return
    walked = prob.walked
    if walked is None:  # too many ball joints for the walk: nothing to compare
        assert (
            sum(k is not None and k[0] != scalar._TURN for k in scalar._start_of(scalar._walk_of(model), base[0])[0])
            > scalar.MAX_FULL_JOINTS
        )
        return
    lo = np.where(np.isfinite(prob.lower), prob.lower, -3.0)
    hi = np.where(np.isfinite(prob.upper), prob.upper, 3.0)
    x = rng.uniform(lo, hi, size=(B, model.n_params))
    idx = np.arange(B)
    a = prob.evaluate(idx, stack, x)
    prob.__dict__["walked"] = None
    b = prob.evaluate(idx, stack, x)
    for got, want in zip(a, b):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-11)
    sub = np.array([0, B - 1]) if B > 1 else idx  # a sub-batch, as the loops take when some have stopped
    prob.__dict__["walked"] = walked
    a = prob.evaluate(sub, stack.take(sub), x[sub])
    np.testing.assert_allclose(a[0], b[0][sub], rtol=0, atol=1e-11)


@pytest.mark.parametrize("method", ["dls", "transpose", "ccd"])
def test_batched_solves_with_the_walk_end_where_the_numpy_ones_end(method, monkeypatch):
    """Batches on random chains (limits, reachable and unreachable targets, restarts, translation):
    the same status per element, and where the goal is met the same iterations and angles to 1e-9 radian."""
    rng = np.random.default_rng(400)
    for case in range(4):
        fig = chain_of(rng, int(rng.integers(3, 9)))
        end = fig.n_links - 1
        poses = rng.uniform(fig.extremes[..., 0], fig.extremes[..., 1], size=(40, fig.n_joints, 3))
        targets = K.pose_transforms(fig, poses)[:, end, :3, 3]  # reachable: where random poses put the tip
        targets[::5] *= 6.0  # out of reach
        goals = [PointGoal(end, targets)]
        opts = dict(tolerance=1e-4, restarts=case % 3, translate=case == 3, solver=method)
        if method != "dls":
            opts["max_iterations"] = 40
        a = solve_pose(fig, goals, **opts)
        with monkeypatch.context() as m:
            no_walk(m)
            b = solve_pose(fig, goals, **opts)
        np.testing.assert_array_equal(a.status, b.status)
        met = a.converged
        assert met.sum() >= (20 if method == "dls" else 0)  # the others take thousands of iterations
        np.testing.assert_array_equal(a.iterations[met], b.iterations[met])
        np.testing.assert_allclose(np.deg2rad(a.angles[met]), np.deg2rad(b.angles[met]), rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.translation[met], b.translation[met], rtol=0, atol=1e-9)
        # Out of reach, a solve creeps along its limits by steps of a hair for
        # hundreds of iterations, and the iteration at which the progress
        # window sees it stall is decided by the last digits: the pose and the
        # distance left agree, the iteration count may not.
        np.testing.assert_allclose(a.residuals, b.residuals, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(np.deg2rad(a.angles), np.deg2rad(b.angles), rtol=0, atol=1e-5)


def test_which_batches_take_the_walk():
    rng = np.random.default_rng(8)
    fig = chain_of(rng, 6)
    model = IKModel(fig, np.ones((6, 3), dtype=bool))
    targets = rng.normal(size=(4, 3))

    def walked(goals, base=None, model=model):
        base = np.zeros((1, 6, 3)) if base is None else base
        return S._Problem(model, GoalStack(model, goals, 4), base).walked is not None

    assert walked([PointGoal(6, targets)])
    assert not walked([PointGoal(6, targets), PlaneGoal(2, (0, 0, 0), (0, 1, 0))])  # only point goals
    assert not walked([PointGoal(6, targets)], base=np.zeros((4, 6, 3)))  # one start pose for the batch
    n = scalar.MAX_FULL_JOINTS + 1
    balls = Figure(
        tuple(Link(f"B{i}", None) for i in range(n + 1)),
        tuple(Joint(i + 1, i, i + 1, (0, 0.2, 0), (0, 0, 0), [(-90, 90)] * 3) for i in range(n)),
    )
    ball_model = IKModel(balls, np.ones((n, 3), dtype=bool))
    base = np.zeros((1, n, 3))
    assert not walked([PointGoal(n, targets)], base, model=ball_model)  # many ball joints: the 4x4 products win
    assert walked(
        [PointGoal(n, targets)], base, model=IKModel(balls, (np.arange(n) < n - 1)[:, None] & np.ones(3, dtype=bool))
    )


@pytest.mark.parametrize("P", [4, 6, 9])
def test_batched_damped_step_with_the_written_out_3x3_equals_numpy_solve(P):
    """solvers._solve_damped's Cholesky over a batch against np.linalg.solve, with held variables."""
    rng = np.random.default_rng(P)
    B = 50
    J = rng.normal(size=(B, 3, P)) * 2
    r = rng.normal(size=(B, 3))
    free = rng.uniform(size=(B, P)) < 0.8
    mu = 10 ** rng.uniform(-3, 1, size=B)
    Jf = J * free[:, None, :]
    want = np.stack([Jf[b].T @ np.linalg.solve(Jf[b] @ Jf[b].T + mu[b] * np.eye(3), -r[b]) for b in range(B)])
    np.testing.assert_allclose(S._solve_damped(J, r, free, mu), want, rtol=0, atol=1e-9)
    # An element whose system is not definite (only rounding makes one) sends the batch to np.linalg.solve.
    assert (
        scalar.solve3(
            np.ones(2), np.full(2, 2.0), np.zeros(2), np.ones(2), np.zeros(2), np.ones(2), np.ones((3, 2)), np.sqrt
        )
        is None
    )


def test_batched_solves_of_a_figure_with_a_slide_walk_too(monkeypatch):
    """A batch on a figure with a SLIDE holds the slide and solves the angles: walk and numpy agree."""
    links = (Link("BASE", None), Link("RAIL", None), Link("ARM", None), Link("HAND", None))
    joints = (
        Joint(1, 0, 1, (0, 0, 0), (0, 0, 0), [(-0.5, 0.5), (0, 0), (0, 0)], slide=True),
        Joint(2, 1, 2, (0, 0, 0), (0, -1, 0), [(-170, 170)], axes=frame_from_axis((0, 0, 1))),
        Joint(3, 2, 3, (0, 1, 0), (0, 0, 0), [(0, 0), (0, 0), (-120, 120)]),
    )
    fig = Figure(links, joints)
    rng = np.random.default_rng(9)
    start = np.zeros((3, 3))
    start[0, 0] = 0.25  # the slide's displacement, held
    poses = np.repeat(start[None], 30, axis=0)
    poses[:, 1, 0] = rng.uniform(-170, 170, 30)
    poses[:, 2, 2] = rng.uniform(-120, 120, 30)
    X = K.pose_transforms(fig, poses)[:, 3]
    targets = X[:, :3, :3] @ np.array([0, 0.5, 0]) + X[:, :3, 3]  # reachable with the slide where it is
    goals = [PointGoal("HAND", targets, point=(0, 0.5, 0))]
    a = solve_pose(fig, goals, start=start, tolerance=1e-6)
    with monkeypatch.context() as m:
        no_walk(m)
        b = solve_pose(fig, goals, start=start, tolerance=1e-6)
    assert a.converged.sum() >= 10
    np.testing.assert_array_equal(a.status, b.status)
    met = a.converged
    np.testing.assert_array_equal(a.iterations[met], b.iterations[met])
    np.testing.assert_allclose(np.deg2rad(a.angles[met]), np.deg2rad(b.angles[met]), rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.angles[:, 0], b.angles[:, 0])  # the slide stays where it started
