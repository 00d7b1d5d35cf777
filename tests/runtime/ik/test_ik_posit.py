"""POSIT's scenarios (Badler, Manoochehri and Walters 1987) on the standard library's humanoid.

The humanoid (stdlib/humanoid.lig) faces +X with +Y up and its right side
towards +Z; it is built in the posing thesis' units and scaled to metres,
so link points are written in those units (a hand's tip is (0, -12, 0))
and targets in metres.  Its root TOP is the lower torso, at the origin.

POSIT balances goals like springs: at the solved pose no move of the
whole figure can lower the weighted cost, so the weighted displacements
sum to zero.  Each scenario checks the goals the paper describes and that
balance.
"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from liganimate.compiler import load_program
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.ik.reach import PointGoal, solve_pose

MM = 1e-3


@pytest.fixture(scope="module")
def humanoid(tmp_path_factory):
    """The HUMANOID model, compiled from a one-line program that loads the library."""
    folder = tmp_path_factory.mktemp("humanoid")
    path = pathlib.Path(folder) / "load.lig"
    path.write_text("LOAD 'humanoid'\n")
    program, _ = load_program(str(path))
    return program.execute("check").variables["HUMANOID"]


def where(fig, angles, name, point=(0, 0, 0), translation=(0, 0, 0)) -> np.ndarray:
    """World position of ``point`` (the link's own units) of link ``name`` at ``angles``."""
    i = fig.links_named(name)[0]
    X = np.asarray(fig.placement) @ K.pose_transforms(fig, angles)[i]
    return X[:3, :3] @ (fig.links[i].scale * np.asarray(point, dtype=float)) + X[:3, 3] + np.asarray(translation)


def balance(fig, sol, goals) -> tuple[float, float]:
    """``|sum w_i d_i|`` and ``sum w_i |d_i|`` over point goals: 0 and something when balanced."""
    total, size = np.zeros(3), 0.0
    for g in goals:
        d = where(fig, sol.angles, g.link, g.point, sol.translation) - np.asarray(g.target)
        total += g.weight * d
        size += g.weight * np.linalg.norm(d)
    return float(np.linalg.norm(total)), size


HAND_TIP = (0, -12, 0)


def test_the_humanoid_is_the_one_these_scenarios_assume(humanoid):
    zero = np.zeros((humanoid.n_joints, 3))
    assert humanoid.n_links == 20 and humanoid.n_joints == 19
    np.testing.assert_allclose(where(humanoid, zero, "TOP"), 0)
    np.testing.assert_allclose(where(humanoid, zero, "R_UPPERARM"), (0, 0.45, 0.225))
    np.testing.assert_allclose(where(humanoid, zero, "R_HAND", HAND_TIP), (0, -0.18, 0.225), atol=1e-12)


def test_sitting_lower_torso_100_back_10_knees_10(humanoid):
    """POSIT's Figures 8 and 9: the seat's back edge pulls the lower torso (100), the chair back
    the top of the back (10), the front of the seat the knees (10 each).  The back and knee
    goals are set only roughly, in the direction wanted, beyond reach."""
    seat = np.array([0.0, -0.45, 0.0])
    goals = [
        PointGoal("TOP", seat, weight=100),
        PointGoal("SPINE", (-0.08, 0.10, 0.0), point=(0, 50, 0), weight=10),
        PointGoal("R_SHIN", (0.50, -0.45, 0.144), weight=10),
        PointGoal("L_SHIN", (0.50, -0.45, -0.144), weight=10),
    ]
    sol = solve_pose(humanoid, goals, translate=True)
    assert sol.status == "stalled"  # the rough goals cannot all be met
    a, t = sol.angles, sol.translation
    # The lower torso is on the seat, within the pull the weaker goals can exert.
    assert np.linalg.norm(where(humanoid, a, "TOP", translation=t) - seat) < 0.025
    for side in ("R", "L"):
        hip = where(humanoid, a, f"{side}_THIGH", translation=t)
        knee = where(humanoid, a, f"{side}_SHIN", translation=t)
        thigh = knee - hip
        assert thigh[0] > 0.39  # forward, the thigh's whole length of 0.405
        assert np.degrees(np.arctan2(abs(thigh[1]), thigh[0])) < 3.0  # level with the seat
    # The back leans on the chair back: the top of the spine behind the lower torso, high above it.
    back = where(humanoid, a, "SPINE", (0, 50, 0), t) - where(humanoid, a, "TOP", translation=t)
    assert back[0] < -0.03 and back[1] > 0.43
    pull, size = balance(humanoid, sol, goals)
    assert pull < 1e-3 * size


def test_restrained_reach_torso_100_hand_10(humanoid):
    """POSIT's Figure 10: the lower torso held at its own position (100) while the hand reaches
    an instrument in front (10) that the arm alone cannot: the back bends and turns instead."""
    zero = np.zeros((humanoid.n_joints, 3))
    torso = where(humanoid, zero, "TOP")
    instrument = np.array([0.75, 0.30, 0.20])
    shoulder = where(humanoid, zero, "R_UPPERARM")
    assert np.linalg.norm(instrument - shoulder) > 0.63  # beyond the arm's 0.63 m
    goals = [PointGoal("TOP", torso, weight=100), PointGoal("R_HAND", instrument, point=HAND_TIP, weight=10)]
    sol = solve_pose(humanoid, goals, translate=True)
    assert sol.converged
    assert np.linalg.norm(where(humanoid, sol.angles, "TOP", translation=sol.translation) - torso) < 1 * MM
    assert np.linalg.norm(where(humanoid, sol.angles, "R_HAND", HAND_TIP, sol.translation) - instrument) < 1 * MM
    spine = sol.angles[humanoid.joint_index(1)]
    assert np.abs(spine).max() > 5  # the back did the extra reaching


def test_seat_belt_torso_and_shoulder_100_hand_10(humanoid):
    """POSIT's Figure 11: waist belt and shoulder strap (100 each) while the hand reaches (10).
    Within the arm's reach the torso and the shoulder stay put (the back may still turn about
    the line between them); beyond it they give only in the ratio of the weights, and the
    hand stops short."""
    zero = np.zeros((humanoid.n_joints, 3))
    torso, shoulder = where(humanoid, zero, "TOP"), where(humanoid, zero, "R_UPPERARM")

    def goals(target):
        return [
            PointGoal("TOP", torso, weight=100),
            PointGoal("R_UPPERARM", shoulder, weight=100),
            PointGoal("R_HAND", target, point=HAND_TIP, weight=10),
        ]

    near = goals(np.array([0.50, 0.30, 0.30]))
    sol = solve_pose(humanoid, near, translate=True)
    assert sol.converged
    assert np.all(sol.residuals < 1 * MM)  # torso and shoulder stay, the hand gets there

    far = goals(np.array([0.75, 0.30, 0.20]))
    sol = solve_pose(humanoid, far, translate=True)
    assert sol.status == "stalled"
    d_torso, d_shoulder, d_hand = sol.residuals
    assert d_hand > 0.05  # the strapped figure cannot get there
    assert d_torso < 5 * MM and d_shoulder < 0.15 * d_hand  # held by the straps, in the ratio of weights
    pull, size = balance(humanoid, sol, far)
    assert pull < 1e-3 * size


def test_two_handed_reach_both_hands_on_one_goal(humanoid):
    target = np.array([0.40, 0.25, 0.0])
    goals = [PointGoal("R_HAND", target, point=HAND_TIP), PointGoal("L_HAND", target, point=HAND_TIP)]
    sol = solve_pose(humanoid, goals)
    assert sol.converged
    for hand in ("R_HAND", "L_HAND"):
        assert np.linalg.norm(where(humanoid, sol.angles, hand, HAND_TIP) - target) < 1e-3
    lo, hi = humanoid.extremes[..., 0], humanoid.extremes[..., 1]
    assert np.all(sol.angles >= lo) and np.all(sol.angles <= hi)


@pytest.mark.parametrize("solver", ["transpose", "ccd"])
def test_the_other_solvers_also_manage_the_two_handed_reach(humanoid, solver):
    target = np.array([0.40, 0.25, 0.0])
    goals = [PointGoal("R_HAND", target, point=HAND_TIP), PointGoal("L_HAND", target, point=HAND_TIP)]
    sol = solve_pose(humanoid, goals, solver=solver, tolerance=1e-4)
    assert sol.converged and np.all(sol.residuals < 1e-3)
