"""Goal-made motions: reach() and reach_keyframes() give ordinary motions that the algebra takes."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import pose as P
from liganimate.runtime.figure.tree import Figure, Joint, Link
from liganimate.runtime.ik.reach import GoalError, PointGoal, reach, reach_keyframes, solve_pose
from liganimate.runtime.motion import algebra as M
from liganimate.runtime.motion.keyframe import Keyframe

EXT = [(-120, 120)] * 3


def body() -> Figure:
    """A torso with a three-joint arm (ids 1-3) and a two-joint leg (ids 11, 12)."""
    links = [Link(n, None) for n in ("TORSO", "UPPER", "FORE", "HAND", "THIGH", "SHIN")]
    joints = [
        Joint(1, 0, 1, (0.3, 1.0, 0), (0, 0, 0), EXT),
        Joint(2, 1, 2, (0, -0.6, 0), (0, 0, 0), EXT),
        Joint(3, 2, 3, (0, -0.5, 0), (0, 0, 0), EXT),
        Joint(11, 0, 4, (0.1, 0, 0), (0, 0, 0), EXT),
        Joint(12, 4, 5, (0, -0.8, 0), (0, 0, 0), [(0, 0), (0, 0), (-150, 0)]),
    ]
    return Figure(tuple(links), tuple(joints))


def hand_at(fig, angles) -> np.ndarray:
    """World position of the hand's tip (0, -0.2, 0) at joint angles (..., 5, 3)."""
    X = K.pose_transforms(fig, angles)[..., 3, :, :]
    return X[..., :3, :3] @ np.array([0, -0.2, 0]) + X[..., :3, 3]


TARGET = np.array([1.0, 0.6, 0.4])
GOAL = PointGoal("HAND", TARGET, point=(0, -0.2, 0))


def test_reach_goes_from_the_start_pose_at_frame_0_to_the_solved_pose_at_frame_n():
    fig = body()
    r = reach(fig, [GOAL], 24, "ACCDCC", movable=3)
    assert isinstance(r.motion, M.Motion) and r.motion.length == 24
    assert r.joints == (1, 2, 3) and r.motion.joints == (1, 2, 3)
    angles = P.joint_angles(fig, r.motion, np.arange(25))
    np.testing.assert_allclose(angles[0], 0)
    np.testing.assert_allclose(angles[24], r.solution.angles, atol=1e-12)
    assert np.linalg.norm(hand_at(fig, angles[24]) - TARGET) == pytest.approx(r.residuals[0], abs=1e-12)
    assert r.converged and r.residuals[0] < 1e-4
    # The chosen method shapes the way there: ACCDCC starts slowly.
    start, keys = r.motion.keyframes(2)
    assert keys[-1].method == "ACCDCC"
    moved = np.abs(angles - angles[0]).max(axis=(1, 2))
    assert moved[1] < 0.02 * moved[24]


def test_a_start_motion_lends_its_final_pose_and_its_joints():
    fig = body()
    wave = M.Motion.from_tracks(
        {1: (None, [Keyframe(10, (0, 0, 60), "LINEAR")]), 11: (None, [Keyframe(10, (0, 0, 30), "LINEAR")])}
    )
    r = reach(fig, [GOAL], 12, start=wave, movable=[2, 3])
    assert r.joints == (1, 2, 3, 11)  # the movable joints and the start motion's
    whole = wave + r.motion
    a = P.joint_angles(fig, whole, np.array([10.0, 22.0]))
    end_of_wave = P.joint_angles(fig, wave, np.array([10.0]))[0]
    np.testing.assert_allclose(a[0], end_of_wave)  # continuous at the junction
    np.testing.assert_allclose(a[1], r.solution.angles, atol=1e-12)
    np.testing.assert_allclose(r.solution.angles[[0, 3]], end_of_wave[[0, 3]])  # locked joints kept
    # Played on its own it still starts where the wave ended.
    np.testing.assert_allclose(P.joint_angles(fig, r.motion, np.array([0.0]))[0], end_of_wave)


def test_goal_made_motions_take_the_algebra():
    fig = body()
    arm = reach(fig, [GOAL], 10, movable=3).motion
    kick = M.Motion.from_tracks({11: (None, [Keyframe(5, (0, 0, 40), "ACCDCC"), Keyframe(10, (0, 0, 0), "ACCDCC")])})
    both = M.synchronize(arm, kick)
    assert both.joints == (1, 2, 3, 11) and both.length == 10
    there_and_back = arm + arm.scale_frames(-1)
    a = P.joint_angles(fig, there_and_back, np.array([0.0, 10.0, 20.0]))
    np.testing.assert_allclose(a[0], a[2], atol=1e-12)
    assert np.linalg.norm(hand_at(fig, a[1]) - TARGET) < 1e-4
    thrice = 3 * there_and_back
    assert thrice.length == 60
    assert M.strip(arm, [3]).joints == (3,)
    assert arm.scale_frames(2).length == 20


def test_an_unreachable_goal_still_makes_a_motion_and_reports_its_residual():
    fig = body()
    far = PointGoal("HAND", (3.0, -3.0, 0.0), point=(0, -0.2, 0))
    r = reach(fig, [far], 8, movable=3)
    assert not r.converged and r.solution.status == "stalled"
    best = np.linalg.norm(np.array([3.0, -3.0, 0.0]) - (0.3, 1.0, 0)) - 1.3  # the straight arm
    assert r.residuals[0] == pytest.approx(best, rel=1e-5)
    a = P.joint_angles(fig, r.motion, np.arange(9))
    assert np.all(np.isfinite(a))


def test_translation_is_returned_beside_the_motion():
    fig = body()
    far = PointGoal("HAND", (5.0, 5.0, 0.0), point=(0, -0.2, 0))
    r = reach(fig, [far], 8, movable=3, translate=True)
    assert r.converged and r.translation.shape == (3,)
    T = np.eye(4)
    T[:3, 3] = r.translation
    moved = fig.placed(T)
    final = P.joint_angles(moved, r.motion, np.array([8.0]))
    X = K.shape_transforms(moved, final)[0, 3]
    np.testing.assert_allclose(X[:3, :3] @ (0, -0.2, 0) + X[:3, 3], (5.0, 5.0, 0.0), atol=1e-4)


def test_zero_frames_is_an_instant_change():
    fig = body()
    r = reach(fig, [GOAL], 0, movable=3)
    assert r.motion.length == 0
    np.testing.assert_allclose(P.joint_angles(fig, r.motion, np.array([0.0]))[0], r.solution.angles)


def test_reach_keyframes_follows_a_moving_target_in_one_batch():
    fig = body()
    s = np.linspace(0, 1, 6)
    path = np.stack([0.9 + 0.2 * s, 0.3 + 0.5 * s, 0.4 - 0.3 * s], axis=1)  # (6, 3)
    frames = [4, 8, 12, 16, 20, 24]
    r = reach_keyframes(fig, [PointGoal("HAND", path, point=(0, -0.2, 0))], frames, "LINEAR", movable=3)
    assert r.solution.angles.shape == (6, 5, 3) and r.solution.converged.all()
    assert r.motion.length == 24
    a = P.joint_angles(fig, r.motion, np.array(frames, dtype=float))
    np.testing.assert_allclose(hand_at(fig, a), path, atol=1e-4)
    np.testing.assert_allclose(P.joint_angles(fig, r.motion, np.array([0.0]))[0], 0)
    single = solve_pose(fig, [PointGoal("HAND", path[3], point=(0, -0.2, 0))], movable=3)
    np.testing.assert_allclose(r.solution.angles[3], single.angles, atol=1e-9)


def test_reach_rejects_batched_goals_and_bad_motion_options():
    fig = body()
    batch = PointGoal("HAND", np.zeros((2, 3)), point=(0, -0.2, 0))
    with pytest.raises(GoalError, match="reach_keyframes"):
        reach(fig, [batch], 10)
    with pytest.raises(GoalError, match="2 keyframe frames for a batch of 3"):
        reach_keyframes(fig, [PointGoal("HAND", np.zeros((3, 3)))], [1, 2])
    with pytest.raises(M.MotionError):
        reach(fig, [GOAL], 10, "WOBBLE", movable=3)
    with pytest.raises(M.MotionError):
        reach(fig, [GOAL], -1, movable=3)


def test_unmet_goals_become_one_sentence_each():
    from liganimate.runtime.ik.reach import AxisGoal, PlaneGoal, residual_warnings

    fig = body()
    goals = [
        PointGoal("HAND", (3.0, -3.0, 0.0), point=(0, -0.2, 0)),
        PlaneGoal("FORE", (0, 0, 0), (0, 1, 0), weight=0),
        AxisGoal("THIGH", (0, -1, 0), (0, 1, 0)),
    ]
    sol = solve_pose(fig, goals)
    assert list(sol.met) == [False, True, False]
    lines = residual_warnings(fig, goals, sol)
    assert lines[0] == f"goal 1: the point of HAND stays {sol.residuals[0]:.4g} from its target."
    assert lines[1].startswith("goal 3: the axis of THIGH stays") and lines[1].endswith("degrees from its direction.")
    assert len(lines) == 2
    assert residual_warnings(fig, [GOAL], solve_pose(fig, [GOAL])) == []


def test_reach_returns_unmet_goals_as_data_with_the_warnings_own_text():
    from liganimate.runtime.ik.reach import AxisGoal, PlaneGoal, UnmetGoal, residual_warnings

    fig = body()
    goals = [
        PointGoal("HAND", (3.0, -3.0, 0.0), point=(0, -0.2, 0)),
        PlaneGoal("FORE", (0, 0, 0), (0, 1, 0), weight=0),
        AxisGoal("THIGH", (0, -1, 0), (0, 1, 0)),
    ]
    r = reach(fig, goals, 12)
    assert [u.index for u in r.unmet] == [0, 2]
    assert [u.distance for u in r.unmet] == [r.residuals[0], r.residuals[2]]
    assert r.unmet[0].sentence == f"the point of HAND stays {r.residuals[0]:.4g} from its target."
    assert r.unmet[1].sentence.startswith("the axis of THIGH stays")
    # The sentences users see are these, prefixed by the goal's number.
    assert [str(u) for u in r.unmet] == residual_warnings(fig, goals, r.solution)
    assert str(r.unmet[1]) == "goal 3: " + r.unmet[1].sentence
    assert r.limit_warning is None  # stalled, not stopped by the limit
    with pytest.raises(AttributeError):
        r.unmet[0].index = 1  # frozen: data, not a message to edit
    assert isinstance(r.unmet[0], UnmetGoal)
    assert reach(fig, [GOAL], 12).unmet == ()


def test_a_solve_cut_short_by_its_iteration_limit_says_so_beside_its_unmet_goals():
    from liganimate.runtime.ik.reach import residual_warnings

    fig = body()
    r = reach(fig, [GOAL], 12, max_iterations=1)
    assert r.solution.status == "limit" and len(r.unmet) == 1
    assert r.limit_warning == "the solver stopped at its iteration limit (1) before settling."
    assert residual_warnings(fig, [GOAL], r.solution) == [str(r.unmet[0]), r.limit_warning]
    batch = reach_keyframes(fig, [PointGoal("HAND", np.stack([TARGET, TARGET]), point=(0, -0.2, 0))], [5, 10])
    assert batch.unmet is None and batch.limit_warning is None  # a batch reports through solution.met
