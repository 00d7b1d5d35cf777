"""Goal-directed positioning: Jacobians, limits, unreachable goals, POSIT weights, batching, options.

The properties issue 4 asks of the solvers, one test (or a parametrized
family) each.  Figures are small and built here; the humanoid scenarios are
in test_ik_posit.py and the motions in test_ik_motion.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.tree import Figure, Joint, Link
from liganimate.runtime.ik import reach as reach_module
from liganimate.runtime.ik.goals import AxisGoal, GoalError, GoalStack, PlaneGoal, PointGoal
from liganimate.runtime.ik.model import IKModel
from liganimate.runtime.ik.reach import solve_pose

SOLVERS = ["dls", "transpose", "ccd"]
FREE = [(-180, 180)] * 3


def chain(n: int, length: float = 1.0, extremes=None, name: str = "L") -> Figure:
    """A chain of ``n`` joints along +Y, links ``L0`` (the root) to ``Ln``, each ``length`` long.

    Link ``k`` has its joint at its origin and its far end at ``(0, length, 0)``
    (where the next joint is); joint ids are 1..n.
    """
    ext = extremes if extremes is not None else [(-170, 170)] * 3
    links = [Link(f"{name}{i}", None) for i in range(n + 1)]
    joints = [Joint(i + 1, i, i + 1, (0, length if i else 0, 0), (0, 0, 0), ext) for i in range(n)]
    return Figure(tuple(links), tuple(joints))


def planar_arm(lengths=(1.0, 1.0), z_range=(-170, 170)) -> Figure:
    """Links turning about Z only (X and Y locked): a planar arm in the XY plane."""
    links = [Link(f"A{i}", None) for i in range(len(lengths) + 1)]
    joints = [
        Joint(i + 1, i, i + 1, (0, lengths[i - 1] if i else 0, 0), (0, 0, 0), [(0, 0), (0, 0), z_range])
        for i in range(len(lengths))
    ]
    return Figure(tuple(links), tuple(joints))


def random_tree(rng: np.random.Generator, n: int) -> Figure:
    """A random tree of ``n`` links with random locations, limits, scales and current main link."""
    parents = [int(rng.integers(0, i)) for i in range(1, n)]
    links = [Link(f"T{i}", None, scale=float(rng.choice([1.0, 2.0, -1.5]))) for i in range(n)]
    joints = [
        Joint(100 + i, p, i, rng.normal(size=3), rng.normal(size=3), [(-120, 150), (-90, 60), (-170, 170)])
        for i, p in zip(range(1, n), parents)
    ]
    return Figure(tuple(links), tuple(joints), main=int(rng.integers(n)))


def tip(figure: Figure, angles, link: int, point, translation=None) -> np.ndarray:
    """World position of ``point`` (shape coordinates) of ``link`` at ``angles`` (degrees)."""
    X = np.asarray(figure.placement) @ K.pose_transforms(figure, np.asarray(angles, dtype=float))[..., link, :, :]
    p = X[..., :3, :3] @ (figure.links[link].scale * np.asarray(point, dtype=float)) + X[..., :3, 3]
    return p if translation is None else p + translation


# ------------------------------------------------------------------ kinematics and Jacobian


@pytest.mark.parametrize("seed", range(4))
def test_model_forward_kinematics_match_pose_transforms(seed):
    rng = np.random.default_rng(seed)
    fig = random_tree(rng, 7)
    model = IKModel(fig, np.ones((fig.n_joints, 3), dtype=bool))
    angles = rng.uniform(-180, 180, size=(5, fig.n_joints, 3))
    R, p = model.forward(np.deg2rad(angles))
    X = K.pose_transforms(fig, angles)
    np.testing.assert_allclose(R, X[..., :3, :3], atol=1e-12)
    np.testing.assert_allclose(p, X[..., :3, 3], atol=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_analytic_jacobian_matches_central_differences(seed):
    """Every goal kind, reversed joints (a random main link), mirrored links, a placement with
    rotation and scale, and the root translation, for a batch of poses."""
    rng = np.random.default_rng(seed)
    fig = random_tree(rng, 8)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    P = np.eye(4)
    P[:3, :3] = 1.7 * Q
    P[:3, 3] = rng.normal(size=3)
    fig = fig.with_placement(P)
    model = IKModel(fig, np.ones((fig.n_joints, 3), dtype=bool), translate=True)
    B = 3
    link = lambda: int(rng.integers(fig.n_links))  # noqa: E731
    goals = [
        PointGoal(link(), rng.normal(size=(B, 3)), point=rng.normal(size=3), weight=2.0),
        PointGoal(link(), rng.normal(size=3), weight=rng.uniform(0.5, 3.0, size=B)),
        PlaneGoal(link(), rng.normal(size=3), rng.normal(size=(B, 3)), point=rng.normal(size=3), weight=1.5),
        AxisGoal(link(), rng.normal(size=3), rng.normal(size=(B, 3)), weight=0.7),
    ]
    stack = GoalStack(model, goals, B)
    base = rng.uniform(-2.5, 2.5, size=(B, fig.n_joints, 3))
    x = np.concatenate([base.reshape(B, -1)[:, model.var_flat], rng.normal(size=(B, 3))], axis=1)

    def evaluate(x, jac):
        q, t = x[:, : model.n_vars], x[:, model.n_vars :] * model.length
        angles = model.full_angles(q, base)
        R, p = model.forward(angles)
        if jac:
            return stack.evaluate(R, p, t, *model.axes(angles, R, p))
        return stack.evaluate(R, p, t)

    r, J, _ = evaluate(x, True)
    assert J.shape == (B, stack.n_rows, model.n_params) == (B, 3 + 3 + 1 + 3, model.n_vars + 3)
    h = 1e-6
    numeric = np.empty_like(J)
    for i in range(x.shape[1]):
        e = np.zeros(x.shape[1])
        e[i] = h
        numeric[:, :, i] = (evaluate(x + e, False)[0] - evaluate(x - e, False)[0]) / (2 * h)
    np.testing.assert_allclose(J, numeric, atol=1e-7 * max(1.0, np.abs(J).max()))


@pytest.mark.parametrize("seed", range(4))
def test_turning_a_variable_never_moves_the_axis_of_a_later_one(seed):
    """The variable order CCD sweeps in: each turn leaves the axes and pivots still to come alone."""
    rng = np.random.default_rng(seed)
    fig = random_tree(rng, 8).with_main(7)  # re-rooted at a leaf: some joints are walked backwards
    model = IKModel(fig, np.ones((fig.n_joints, 3), dtype=bool))
    assert fig.reversed_joints.any() and not fig.reversed_joints.all()
    base = rng.uniform(-2.5, 2.5, size=(1, fig.n_joints, 3))
    q = base.reshape(1, -1)[:, model.var_flat]

    def axes(q):
        angles = model.full_angles(q, base)
        return model.axes(angles, *model.forward(angles))

    omega, pivot = axes(q)
    for v in range(model.n_vars):
        turned = q.copy()
        turned[0, v] += 0.7
        o2, p2 = axes(turned)
        np.testing.assert_allclose(o2[0, v + 1 :], omega[0, v + 1 :], atol=1e-12)
        np.testing.assert_allclose(p2[0, v + 1 :], pivot[0, v + 1 :], atol=1e-12)


# ------------------------------------------------------------------ solvers reach


@pytest.mark.parametrize("solver", SOLVERS)
def test_each_solver_reaches_a_reachable_goal(solver):
    fig = chain(4)
    target = tip(fig, [[10, 20, 30], [-40, 10, 5], [30, -20, 40], [5, 5, -60]], 4, (0, 1, 0))
    sol = solve_pose(fig, [PointGoal("L4", target, point=(0, 1, 0))], solver=solver, tolerance=1e-6)
    assert sol.status == "converged" and sol.converged
    assert sol.status is reach_module.SolveStatus.CONVERGED  # an enum member, not a bare string
    assert sol.residuals[0] <= 1e-6
    np.testing.assert_allclose(tip(fig, sol.angles, 4, (0, 1, 0)), target, atol=1e-6)


def test_damped_least_squares_is_the_default_and_converges_fastest():
    fig = chain(6, 0.5)
    rng = np.random.default_rng(3)
    targets = tip(fig, rng.uniform(-60, 60, size=(20, 6, 3)), 6, (0, 0.5, 0))
    goals = [PointGoal(6, targets, point=(0, 0.5, 0))]
    default = solve_pose(fig, goals, tolerance=1e-6)
    dls = solve_pose(fig, goals, tolerance=1e-6, solver="dls")
    np.testing.assert_array_equal(default.angles, dls.angles)
    transpose = solve_pose(fig, goals, tolerance=1e-6, solver="transpose")
    assert dls.converged.all() and transpose.converged.all()
    assert np.median(dls.iterations) * 5 < np.median(transpose.iterations)


@pytest.mark.parametrize("solver", SOLVERS)
def test_plane_and_axis_goals_are_met(solver):
    fig = chain(4, extremes=[(-120, 120), (-120, 120), (-120, 120)])
    goals = [
        PlaneGoal("L4", origin=(0, 0, 1.2), normal=(0, 0, 2), point=(0, 1, 0)),
        AxisGoal("L4", axis=(0, 1, 0), direction=(1, 0, 1)),
        AxisGoal("L2", axis=(0, 1, 0), direction=(0, 1, 0.2)),
    ]
    sol = solve_pose(fig, goals, solver=solver, tolerance=1e-6, max_iterations=20000)
    assert sol.converged, sol.residuals
    X = K.pose_transforms(fig, sol.angles)
    assert tip(fig, sol.angles, 4, (0, 1, 0))[2] == pytest.approx(1.2, abs=1e-6)
    for link, direction in ((4, (1, 0, 1)), (2, (0, 1, 0.2))):
        y = X[link, :3, 1]
        assert np.degrees(np.arccos(y @ direction / np.linalg.norm(direction))) < 1e-3
    assert sol.residuals.shape == (3,)


# ------------------------------------------------------------------ limits


def _record_iterates(monkeypatch):
    """Every variable vector the solvers evaluate, collected through IKModel.trig and the batch walk."""
    from liganimate.runtime.ik import solvers as S

    seen = []
    original = IKModel.trig
    original_walk = S.batch_evaluator

    def trig(self, q, base_cos, base_sin):
        seen.append((self, np.array(q)))
        return original(self, q, base_cos, base_sin)

    def batch_evaluator(prob):
        walk = original_walk(prob)
        if walk is None:
            return None

        def evaluate(stack, x):
            seen.append((prob.model, np.array(x[:, : prob.model.n_vars])))
            return walk(stack, x)

        return evaluate

    monkeypatch.setattr(IKModel, "trig", trig)
    monkeypatch.setattr(S, "batch_evaluator", batch_evaluator)
    return seen


@pytest.mark.parametrize("solver", SOLVERS)
def test_joint_limits_hold_at_every_iterate(solver, monkeypatch):
    ext = [(-30, 45), (-10, 20), (-60, 5)]
    fig = chain(5, extremes=ext)
    seen = _record_iterates(monkeypatch)
    rng = np.random.default_rng(11)
    # Targets all round, most outside what the limits allow: the solvers push hard into them.
    targets = rng.normal(size=(16, 3)) * 4.0
    sol = solve_pose(fig, [PointGoal("L5", targets, point=(0, 1, 0))], solver=solver, max_iterations=300)
    assert seen
    for model, q in seen:
        assert np.all(q >= model.lower - 1e-12) and np.all(q <= model.upper + 1e-12)
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    assert np.all(sol.angles >= lo) and np.all(sol.angles <= hi)
    # The limits are actually reached, so they were tested.
    assert np.isclose(sol.angles, lo).any() and np.isclose(sol.angles, hi).any()
    assert np.all(np.isfinite(sol.residuals))


@pytest.mark.parametrize("solver", SOLVERS)
def test_locked_axes_and_unlisted_joints_keep_their_angles(solver):
    # Joint 2 turns about Z only; joint 3 is not movable and starts bent.
    ext = {1: FREE, 2: [(0, 0), (0, 0), (-90, 90)], 3: [(-90, 90)] * 3, 4: [(-90, 90), (0, 0), (-90, 90)]}
    links = [Link(f"L{i}", None) for i in range(5)]
    joints = [Joint(i, i - 1, i, (0, 1 if i > 1 else 0, 0), (0, 0, 0), ext[i]) for i in range(1, 5)]
    fig = Figure(tuple(links), tuple(joints))
    start = np.zeros((4, 3))
    start[2] = (20, -15, 30)
    sol = solve_pose(
        fig, [PointGoal("L4", (1.5, 1.5, 1.0), point=(0, 1, 0))], start=start, movable=[1, 2, 4], solver=solver
    )
    assert sol.angles[1, 0] == 0 and sol.angles[1, 1] == 0  # locked at (0, 0)
    assert sol.angles[3, 1] == 0
    np.testing.assert_array_equal(sol.angles[2], start[2])  # not movable
    assert np.abs(sol.angles[0]).max() > 1 and abs(sol.angles[1, 2]) > 1  # the movable ones did move


def test_free_axes_turn_past_the_wrap_and_come_back_wrapped():
    fig = planar_arm((1.0,), z_range=(-180, 180))
    # From 170 degrees, the goal at 200 (= -160) is reached by turning through 180.
    start = np.array([[0, 0, 170.0]])
    target = (-np.sin(np.radians(200)), np.cos(np.radians(200)), 0)
    sol = solve_pose(fig, [PointGoal("A1", target, point=(0, 1, 0))], start=start, tolerance=1e-9)
    assert sol.converged
    assert sol.angles[0, 2] == pytest.approx(-160.0, abs=1e-6)


# ------------------------------------------------------------------ unreachable goals


def _scipy_best(fig, goals_fn, bounds, starts):
    """The best of scipy's bounded least squares from several starts (cost, x)."""
    from scipy.optimize import least_squares  # a test dependency (pyproject: test)

    best = None
    for x0 in starts:
        res = least_squares(goals_fn, x0, bounds=bounds, xtol=1e-14, ftol=1e-14, gtol=1e-14)
        if best is None or res.cost < best.cost:
            best = res
    return best


@pytest.mark.parametrize("solver", SOLVERS)
def test_unreachable_goal_ends_at_the_least_squares_best_pose_without_oscillating(solver):
    fig = chain(3)
    target = np.array([4.0, 2.0, 1.0])  # 4.58 away; the chain is 3 long
    sol = solve_pose(fig, [PointGoal("L3", target, point=(0, 1, 0))], solver=solver, trace=True)
    assert sol.status == "stalled" and not sol.converged
    assert np.all(np.isfinite(sol.angles)) and np.isfinite(sol.residuals).all()
    # The best any pose can do is to point the straight chain at the target.
    assert sol.residuals[0] == pytest.approx(np.linalg.norm(target) - 3.0, rel=1e-5)
    history = np.array(sol.history)
    assert np.all(np.diff(history) <= 1e-15 * history[0]), "the cost never rises: no oscillation"


@pytest.mark.parametrize("solver", ["dls", "ccd"])
def test_unreachable_goal_against_limits_matches_scipy_least_squares(solver):
    ext = [(-20, 30), (0, 0), (-40, 50)]
    fig = chain(4, extremes=ext)
    target = np.array([-3.0, -1.0, 2.0])
    sol = solve_pose(fig, [PointGoal("L4", target, point=(0, 1, 0))], solver=solver)
    assert sol.status == "stalled"
    lo = np.deg2rad([-20, -40] * 4)
    hi = np.deg2rad([30, 50] * 4)

    def residual(x):
        a = np.zeros((4, 3))
        a[:, 0], a[:, 2] = np.rad2deg(x[0::2]), np.rad2deg(x[1::2])
        return tip(fig, a, 4, (0, 1, 0)) - target

    starts = [np.zeros(8)] + list(np.random.default_rng(0).uniform(lo, hi, size=(12, 8)))
    best = _scipy_best(fig, residual, (lo, hi), starts)
    assert sol.residuals[0] == pytest.approx(np.linalg.norm(best.fun), rel=1e-4)


# ------------------------------------------------------------------ POSIT weights


@pytest.mark.parametrize("solver", SOLVERS)
def test_posit_two_unreachable_collinear_goals_weighted_40_and_10_end_1_to_4(solver):
    """POSIT's Figures 6 and 7: the hand pulled one way with 40, the elbow the other with 10.

    With the root free to translate, the least-squares pose balances the
    weighted displacements, 40 d1 = 10 d2: the distances are 1 : 4.
    """
    arm = planar_arm((1.0, 1.0))
    hand = PointGoal("A2", (5.0, 0.0, 0.0), point=(0, 1, 0), weight=40)
    elbow = PointGoal("A1", (-5.0, 0.0, 0.0), weight=10)
    sol = solve_pose(arm, [hand, elbow], translate=True, tolerance=1e-9, solver=solver)
    assert not sol.converged  # neither goal can be met: the arm is 2 long, the goals 10 apart
    d_hand, d_elbow = sol.residuals
    assert d_elbow / d_hand == pytest.approx(4.0, rel=0.01)
    # The displacements are collinear and opposite.
    h = tip(arm, sol.angles, 2, (0, 1, 0), sol.translation) - hand.target
    e = tip(arm, sol.angles, 1, (0, 0, 0), sol.translation) - np.array(elbow.target)
    cos = h @ e / (np.linalg.norm(h) * np.linalg.norm(e))
    assert cos == pytest.approx(-1.0, abs=1e-6)


def test_posit_ratio_holds_for_one_point_pulled_two_ways_from_a_fixed_root():
    arm = planar_arm((1.0, 1.0))
    # Both goals out of reach (2.5 and 2.2 from the root); their weighted mean (1.54, 0) is reachable.
    goals = [
        PointGoal("A2", (2.5, 0, 0), point=(0, 1, 0), weight=40),
        PointGoal("A2", (-2.2, 0, 0), point=(0, 1, 0), weight=10),
    ]
    sol = solve_pose(arm, goals)
    assert sol.residuals[1] / sol.residuals[0] == pytest.approx(4.0, rel=0.01)


def test_posit_weight_1_against_10000_is_effectively_ignored():
    arm = chain(3)
    strong = PointGoal("L3", (1.0, 1.5, 1.0), point=(0, 1, 0), weight=10_000)
    weak = PointGoal("L3", (-2.0, -1.0, 0.5), point=(0, 1, 0), weight=1)
    alone = solve_pose(arm, [strong])
    both = solve_pose(arm, [strong, weak])
    gap = np.linalg.norm(np.subtract(strong.target, weak.target))
    assert both.residuals[0] < 1e-3 * gap  # the strong goal is met as if alone
    assert both.residuals[1] == pytest.approx(gap, rel=1e-3)
    assert alone.residuals[0] < 1e-4


def test_only_weight_ratios_matter_and_zero_switches_a_goal_off():
    arm = chain(3)
    a = dict(link="L3", target=(2.0, 2.0, 1.0), point=(0, 1, 0))
    b = dict(link="L2", target=(-1.0, 0.5, 0.0))
    s1 = solve_pose(arm, [PointGoal(**a, weight=40), PointGoal(**b, weight=10)])
    s2 = solve_pose(arm, [PointGoal(**a, weight=4), PointGoal(**b, weight=1)])
    np.testing.assert_allclose(s1.angles, s2.angles, atol=1e-9)
    off = solve_pose(arm, [PointGoal(**a, weight=3), PointGoal(**b, weight=0)])
    only = solve_pose(arm, [PointGoal(**a, weight=3)])
    np.testing.assert_allclose(off.angles, only.angles, atol=1e-12)
    assert off.residuals[1] > 0.1  # still reported, though switched off
    nothing = solve_pose(arm, [PointGoal(**a, weight=0)])
    assert nothing.converged and np.all(nothing.angles == 0)


# ------------------------------------------------------------------ batches


def test_batched_solves_equal_single_solves_and_take_one_batch_of_kinematics(monkeypatch):
    fig = chain(5, 0.6)
    rng = np.random.default_rng(5)
    targets = tip(fig, rng.uniform(-70, 70, size=(40, 5, 3)), 5, (0, 0.6, 0))
    targets[::7] *= 3.0  # some unreachable
    calls = []
    original = IKModel.forward_trig

    def counted(self, c, s):
        calls.append(c.shape[0])
        return original(self, c, s)

    monkeypatch.setattr(IKModel, "forward_trig", counted)
    batch = solve_pose(fig, [PointGoal(5, targets, point=(0, 0.6, 0))])
    batch_calls = len(calls)
    assert batch.angles.shape == (40, 5, 3) and batch.residuals.shape == (40, 1)
    singles = [solve_pose(fig, [PointGoal(5, t, point=(0, 0.6, 0))]) for t in targets]
    # One batch: no more kinematics passes than its slowest member's iterations
    # (single solves take their own one-pose path, so only the batch is counted).
    assert batch_calls <= max(s.iterations for s in singles) + 3
    np.testing.assert_allclose(batch.angles, [s.angles for s in singles], atol=1e-9)
    np.testing.assert_allclose(batch.residuals[:, 0], [s.residuals[0] for s in singles], atol=1e-12)
    assert list(batch.status) == [s.status for s in singles]


def test_a_batch_of_start_poses_with_one_goal():
    fig = chain(3)
    starts = np.zeros((3, 3, 3))
    starts[1, :, 2] = 30
    starts[2, :, 0] = -30
    sol = solve_pose(fig, [PointGoal("L3", (1.0, 2.0, 0.5), point=(0, 1, 0))], start=starts)
    assert sol.angles.shape == (3, 3, 3) and sol.converged.all()


# ------------------------------------------------------------------ options


def test_chain_length_moves_only_the_joints_nearest_the_goal():
    fig = chain(5)
    sol = solve_pose(fig, [PointGoal("L5", (1.0, 3.5, 0.5), point=(0, 1, 0))], movable=2)
    assert sol.converged
    assert np.all(sol.angles[:3] == 0) and np.abs(sol.angles[3:]).max() > 1
    none = solve_pose(fig, [PointGoal("L5", (1.0, 3.5, 0.5), point=(0, 1, 0))], movable=0)
    assert np.all(none.angles == 0) and none.status == "stalled"


def test_translation_moves_the_whole_figure_and_is_returned_in_world_units():
    fig = chain(2).placed(np.diag([2.0, 2.0, 2.0, 1.0]))  # placed at twice the size
    target = np.array([10.0, 3.0, -2.0])
    sol = solve_pose(fig, [PointGoal("L2", target, point=(0, 1, 0))], translate=True, tolerance=1e-9)
    assert sol.converged
    T = np.eye(4)
    T[:3, 3] = sol.translation
    moved = fig.placed(T)  # m :- m <TRANS (t)>
    np.testing.assert_allclose(tip(moved, sol.angles, 2, (0, 1, 0)), target, atol=1e-8)
    fixed = solve_pose(fig, [PointGoal("L2", target, point=(0, 1, 0))])
    assert np.all(fixed.translation == 0) and fixed.status == "stalled"


@pytest.mark.parametrize("solver", SOLVERS)
def test_goals_are_in_the_world_of_the_placed_figure_seen_from_its_current_main_link(solver):
    fig = chain(4).with_main(2)  # FIGURE ... MAIN: joints 1 and 2 are walked backwards
    M = np.eye(4)
    M[:3, :3] = K.matrix_from_euler_zyx([0, 0, 90])
    M[:3, 3] = (5, 0, 0)
    fig = fig.placed(M)
    # Targets from a pose, so both are reachable at once: one on each side of the main link.
    pose = np.array([[0, 0, 0], [20, -30, 40], [10, 25, -35], [-30, 15, 20]], dtype=float)
    t4, t0 = tip(fig, pose, 4, (0, 1, 0)), tip(fig, pose, 0, (0, 0, 0))
    assert np.linalg.norm(t0 - tip(fig, np.zeros((4, 3)), 0, (0, 0, 0))) > 0.5
    goals = [PointGoal("L4", t4, point=(0, 1, 0)), PointGoal("L0", t0, weight=0.5)]
    tol = 1e-8 if solver == "dls" else 1e-5
    sol = solve_pose(fig, goals, tolerance=tol, solver=solver, max_iterations=50000)
    assert sol.converged, sol.residuals
    np.testing.assert_allclose(tip(fig, sol.angles, 4, (0, 1, 0)), t4, atol=tol)
    np.testing.assert_allclose(tip(fig, sol.angles, 0, (0, 0, 0)), t0, atol=tol)


def test_link_points_are_in_shape_coordinates_so_scale_model_keeps_them():
    fig = chain(2)
    scaled = fig.scale_model(3.0)
    target = np.array([1.0, 1.2, 0.5])
    a = solve_pose(fig, [PointGoal("L2", target, point=(0, 1, 0))], tolerance=1e-9)
    b = solve_pose(scaled, [PointGoal("L2", 3 * target, point=(0, 1, 0))], tolerance=3e-9)
    np.testing.assert_allclose(a.angles, b.angles, atol=1e-6)
    assert b.residuals[0] <= 3e-9


def bench_chain(n: int) -> Figure:
    """benchmarks/ik.py's chain: hinges alternately about Z (-120, 120) and X (-90, 90), total length 1."""
    seg = 1.0 / n
    links = [Link(f"C{i}", None) for i in range(n + 1)]
    joints = []
    for i in range(n):
        ext = [(0, 0), (0, 0), (-120, 120)] if i % 2 == 0 else [(-90, 90), (0, 0), (0, 0)]
        joints.append(Joint(i + 1, i, i + 1, (0, seg if i else 0, 0), (0, 0, 0), ext))
    return Figure(tuple(links), tuple(joints))


def test_restarts_find_poses_the_start_cannot_and_leave_unreachable_goals_alone():
    fig = bench_chain(10)
    rng = np.random.default_rng(0)
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    targets = tip(fig, rng.uniform(lo, hi, size=(300, 10, 3)), 10, (0, 0.1, 0))  # all reachable
    goals = [PointGoal(10, targets, point=(0, 0.1, 0))]
    plain = solve_pose(fig, goals, tolerance=1e-4)
    stuck = np.flatnonzero(~plain.converged)
    assert stuck.size > 0, "some starts end in a local minimum against the limits"
    again = solve_pose(fig, goals, tolerance=1e-4, restarts=3)
    assert again.converged.all()
    # Restarts touch only the solves heading for a local minimum (and the few
    # converging so slowly that they look like it).
    same = np.all(again.angles == plain.angles, axis=(1, 2))
    assert same[plain.converged].mean() > 0.95
    # A goal nothing can reach keeps the best pose from the given start.
    far = [PointGoal(10, (3.0, 1.0, 0.0), point=(0, 0.1, 0))]
    np.testing.assert_array_equal(solve_pose(fig, far).angles, solve_pose(fig, far, restarts=3).angles)


# ------------------------------------------------------------------ single solves


@pytest.mark.parametrize("seed", range(8))
def test_one_pose_evaluation_equals_the_batched_one(seed):
    """The single solve's kinematics and goals (IKModel.forward_one, GoalStack.evaluate_one) against
    the batched ones: trees with random main links, chains, placements, translation, every goal kind."""
    from liganimate.runtime.ik import solvers as S

    rng = np.random.default_rng(seed)
    fig = random_tree(rng, int(rng.integers(2, 9))) if seed % 3 else chain(int(rng.integers(1, 8)))
    if seed % 2:
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        P = np.eye(4)
        P[:3, :3] = 1.7 * Q
        P[:3, 3] = rng.normal(size=3)
        fig = fig.with_placement(P)
    translate = seed % 4 == 1
    model = IKModel(fig, rng.uniform(size=(fig.n_joints, 3)) < 0.7, translate=translate)
    link = lambda: int(rng.integers(fig.n_links))  # noqa: E731
    for kinds in ("point", "points", "all"):
        goals = [PointGoal(link(), rng.normal(size=3), point=rng.normal(size=3), weight=2.0)]
        if kinds != "point":
            goals.append(PointGoal(link(), rng.normal(size=3), weight=0.5))
        if kinds == "all":
            goals += [
                PlaneGoal(link(), rng.normal(size=3), rng.normal(size=3), point=rng.normal(size=3)),
                AxisGoal(link(), rng.normal(size=3), rng.normal(size=3), weight=0.7),
            ]
        stack = GoalStack(model, goals, 1)
        base = rng.uniform(-2.5, 2.5, size=(1, fig.n_joints, 3))
        prob = S._Problem(model, stack, base)
        x = np.concatenate([base.reshape(-1)[model.var_flat], rng.normal(size=3) if translate else []])
        one = prob.one(x)
        batched = prob.evaluate(np.zeros(1, dtype=np.intp), stack, x[None])
        for a, b in zip(one, batched):
            np.testing.assert_allclose(a, b[0], rtol=0, atol=1e-13)


def test_single_dls_solves_take_the_batched_loops_steps(monkeypatch):
    """A batch of one runs its own loop (solvers._dls_one); with restarts, given-up attempts,
    iteration limits and unreachable goals it ends where the batched loop ends a batch of one."""
    from liganimate.runtime.ik import solvers as S

    def batched_loop(prob, x, tol, max_iter, restarts, seed, trace):
        st = S._State(prob, x[None].copy(), tol, trace, jac=True, max_iter=max_iter, restarts=restarts, seed=seed)
        S._dls(prob, st)
        return st.finish()

    fig = bench_chain(10)
    rng = np.random.default_rng(3)
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    targets = tip(fig, rng.uniform(lo, hi, size=(60, 10, 3)), 10, (0, 0.1, 0))
    targets[::4] *= 3.0  # some out of reach
    fast = S._dls_one
    options = [
        dict(tolerance=1e-4, max_iterations=30, restarts=3),
        dict(tolerance=1e-4, restarts=1, trace=True),
        dict(tolerance=1e-4, max_iterations=12, restarts=2),
    ]
    restarted = 0
    for opts in options:
        for t in targets:
            goals = [PointGoal(10, t, point=(0, 0.1, 0))]
            monkeypatch.setattr(S, "_dls_one", fast)
            a = solve_pose(fig, goals, **opts)
            monkeypatch.setattr(S, "_dls_one", batched_loop)
            b = solve_pose(fig, goals, **opts)
            assert (a.status, a.iterations, len(a.history)) == (b.status, b.iterations, len(b.history))
            np.testing.assert_allclose(a.angles, b.angles, atol=1e-6)
            restarted += a.iterations != solve_pose(fig, goals, **{**opts, "restarts": 0}).iterations
    assert restarted > 0, "restarts were exercised"


# ------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    "kwargs, goals, message",
    [
        ({}, [PointGoal("NOSE", (0, 0, 0))], "no link named NOSE"),
        ({}, [PointGoal(9, (0, 0, 0))], "no link number 9"),
        ({}, [PlaneGoal("L1", (0, 0, 0), (0, 0, 0))], "must not be the zero vector"),
        ({}, [AxisGoal("L1", (0, 0, 0), (1, 0, 0))], "must not be the zero vector"),
        ({}, [PointGoal("L1", (0, 0, 0), weight=-1)], "must not be negative"),
        ({}, [PointGoal("L1", (0, 0))], "three numbers"),
        ({}, [PointGoal("L1", np.zeros((2, 3))), PointGoal("L1", np.zeros((3, 3)))], "disagree"),
        ({"solver": "newton"}, [PointGoal("L1", (0, 0, 0))], "unknown solver"),
        ({"movable": [7]}, [PointGoal("L1", (0, 0, 0))], "no joint 7"),
        ({"tolerance": 0}, [PointGoal("L1", (0, 0, 0))], "tolerance"),
        ({"start": np.zeros((3, 3))}, [PointGoal("L1", (0, 0, 0))], "start pose"),
    ],
)
def test_malformed_goals_and_options_are_lig_errors(kwargs, goals, message):
    with pytest.raises(LigError, match=message):
        solve_pose(chain(2), goals, **kwargs)
    assert issubclass(GoalError, LigError)


def test_an_ambiguous_link_name_takes_the_first_and_warns():
    links = (Link("BODY", None), Link("HAND", None), Link("HAND", None))
    joints = (Joint(1, 0, 1, (1, 0, 0), (0, 0, 0), FREE), Joint(2, 0, 2, (-1, 0, 0), (0, 0, 0), FREE))
    fig = Figure(links, joints)
    sol = solve_pose(fig, [PointGoal("hand", (1.0, 0.5, 0.0), point=(0, 0, 0))])
    assert any("2 links are named hand" in w and "joint 2" in w for w in sol.warnings)


def test_a_one_link_figure_can_only_translate_and_no_goals_is_nothing_to_do():
    box = Figure((Link("BOX", None),))
    moved = solve_pose(box, [PointGoal("BOX", (1.0, 2.0, 3.0))], translate=True, tolerance=1e-9)
    assert moved.converged and moved.angles.shape == (0, 3)
    np.testing.assert_allclose(moved.translation, (1.0, 2.0, 3.0), atol=1e-9)
    still = solve_pose(box, [PointGoal("BOX", (1.0, 2.0, 3.0))])
    assert still.status == "stalled" and still.residuals[0] == pytest.approx(np.sqrt(14))
    idle = solve_pose(chain(2), [], start=np.full((2, 3), 10.0))
    assert idle.converged and np.all(idle.angles == 10.0)


# ------------------------------------------------------------------ the solver registry


def test_the_solver_registry_is_the_one_table_of_names_words_and_limits():
    from liganimate.runtime.ik import solvers as S
    from liganimate.runtime.ik.reach import DEFAULT_MAX_ITERATIONS

    assert S.SOLVER_NAMES == tuple(SOLVERS)
    assert dict(S.SOLVER_KEYWORDS) == {"DLS": "dls", "TRANSPOSE": "transpose", "CCD": "ccd"}
    assert DEFAULT_MAX_ITERATIONS == {name: spec.max_iterations for name, spec in S.SOLVERS.items()}
    assert DEFAULT_MAX_ITERATIONS == {"dls": 200, "transpose": 5000, "ccd": 500}
    assert not S.SOLVERS["ccd"].jacobian and S.SOLVERS["dls"].jacobian
    assert S.DEFAULT_SOLVER == "dls" and S.DEFAULT_SOLVER in S.SOLVERS
    with pytest.raises(TypeError):
        S.SOLVERS["newton"] = S.SOLVERS["dls"]  # read-only: one table, not a copy per reader


def test_the_solver_names_load_without_the_solvers():
    """The compiler and the host read the solver names from ik/names.py: no solver, no figure code, no numpy."""
    import subprocess
    import sys

    code = (
        "import sys; from liganimate.runtime.ik.names import SOLVER_KEYWORDS; "
        "print(sorted(m for m in sys.modules if m.startswith('liganimate.runtime.') or m == 'numpy'))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "['liganimate.runtime.ik', 'liganimate.runtime.ik.names']"


def test_the_solver_names_are_the_solver_tables_names():
    """ik/names.py and the SOLVERS table name the same solvers with the same words, in the same order."""
    from liganimate.runtime.ik import names as N
    from liganimate.runtime.ik import solvers as S

    assert dict(N.SOLVER_KEYWORDS) == {s.keyword: s.name for s in S.SOLVERS.values()}
    assert tuple(N.SOLVER_KEYWORDS.values()) == S.SOLVER_NAMES
    assert S.SOLVER_KEYWORDS is N.SOLVER_KEYWORDS and S.DEFAULT_SOLVER == N.DEFAULT_SOLVER


def test_the_stopping_rules_say_the_same_for_one_solve_and_for_a_batch():
    """The rules both DLS loops call (solvers._step_status, _progress, _damping, ...) give, on one
    solve's Python scalars, what they give element by element on a batch's arrays."""
    from liganimate.runtime.ik import solvers as S

    rng = np.random.default_rng(11)
    n = 1500
    status = rng.choice([S.RUNNING, S.CONVERGED, S.STALLED], size=n, p=[0.8, 0.1, 0.1])
    k = rng.integers(1, 40, size=n)
    f = rng.choice([1e-12, 1e-3, 0.5], size=n) * rng.uniform(0.5, 1.5, size=n)
    window_f = f * rng.choice([1.0, 1 + 1e-7, 2.0], size=n)
    fast_f = f * rng.choice([1.5, 3.0], size=n)
    may = rng.uniform(size=n) < 0.5
    conv = rng.uniform(size=n) < 0.2
    accept = rng.uniform(size=n) < 0.7
    gain = f * rng.choice([1e-10, 1e-3, 0.5], size=n)
    step = rng.choice([1e-12, 1e-3], size=n)
    size = rng.uniform(0.1, 3.0, size=n)
    mu = rng.choice([1e-3, 1e20], size=n)
    curv = rng.choice([0.0, 1.0, 30.0], size=n)
    nu = rng.choice([2.0, 8.0], size=n)
    rho = rng.uniform(-0.5, 1.5, size=n)
    spent = S._damping_spent(np.where, mu, curv)
    batched = (
        S._step_status(np.where, conv, accept, gain, f, step, size, spent),
        *S._progress(np.where, status, k, f, window_f, fast_f, 30, may, 1e-6),
        *S._damping(np.where, mu, nu, accept, rho),
        *S._first_damping(np.where, status, curv)[:2],
    )
    for i in range(n):
        one = (
            S._step_status(
                S._pick,
                bool(conv[i]),
                bool(accept[i]),
                float(gain[i]),
                float(f[i]),
                float(step[i]),
                float(size[i]),
                S._damping_spent(S._pick, float(mu[i]), float(curv[i])),
            ),
            *S._progress(
                S._pick,
                int(status[i]),
                int(k[i]),
                float(f[i]),
                float(window_f[i]),
                float(fast_f[i]),
                30,
                bool(may[i]),
                1e-6,
            ),
            *S._damping(S._pick, float(mu[i]), float(nu[i]), bool(accept[i]), float(rho[i])),
            *S._first_damping(S._pick, int(status[i]), float(curv[i]))[:2],
        )
        many = tuple(np.asarray(b)[i] if np.ndim(b) else b for b in batched)
        # Statuses and flags exactly; the damping up to rounding (a scalar's
        # ** 3 and an array's round differently in the last bit).
        assert one[:5] == many[:5] and one[7] == many[7], i
        np.testing.assert_allclose(one[5:7] + one[8:], many[5:7] + many[8:], rtol=1e-15, atol=0)
    # Every outcome is exercised.
    assert {S.CONVERGED, S.STALLED, S.RUNNING} <= set(batched[0]) and S.LIMIT in set(batched[1])
    assert batched[4].any()  # some attempts given up
