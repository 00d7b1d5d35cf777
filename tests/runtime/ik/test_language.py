"""runtime/ik/language.py: the STARTREACH block's goals and solve, without the host."""

from __future__ import annotations

import numpy as np
import pytest
from test_reach_language import ARM

from liganimate.compiler import load_program
from liganimate.runtime.errors import FigureError
from liganimate.runtime.ik import language as RL
from liganimate.runtime.ik.goals import AxisGoal, GoalError, PlaneGoal, PointGoal

# TWIN adds a second link named UPPER below LOWER to the arm of test_reach_language.py.
TWIN = ARM.replace("ENDMODEL", "  JOINT 3, LOWER, (0, -1, 0), UPPER, (0, 0, 0), (0, 0), (0, 0), (0, 90)\nENDMODEL")


def model(text: str = ARM):
    program, _ = load_program(text=text, name="arm.lig")
    return program.execute("check").variables["ARM"]


def lower(fig) -> int:
    return fig.links_named("LOWER")[0]


def test_a_negative_frame_is_refused_and_zero_is_not():
    with pytest.raises(GoalError, match=r"frame cannot be negative \(-1\.5\)\.$"):
        RL.check_frames(-1.5)
    assert RL.check_frames(0.0) is None


def test_each_goal_kind_is_built_with_its_defaults():
    fig = model()
    k = lower(fig)
    point, warn = RL.language_goal(fig, "point", "lower", None, None, (1, 2, 3), None, None)
    assert point == PointGoal(k, (1, 2, 3), (0.0, 0.0, 0.0), 1.0) and warn is None
    plane, _ = RL.language_goal(fig, "plane", "LOWER", None, (0, -1, 0), (0, 0, 0), (0, 1, 0), 2)
    assert plane == PlaneGoal(k, (0, 0, 0), (0, 1, 0), (0, -1, 0), 2.0)
    axis, _ = RL.language_goal(fig, "axis", "LOWER", None, None, (1, 0, 0), (0, -1, 0), 0.5)
    assert axis == AxisGoal(k, (0, -1, 0), (1, 0, 0), 0.5)


def test_a_joint_names_its_secondary_link_and_an_unknown_one_is_refused():
    fig = model()
    goal, _ = RL.language_goal(fig, "point", None, 2, None, (1, 0, 0), None, None)
    assert goal.link == lower(fig)
    with pytest.raises(FigureError, match="no joint 9"):
        RL.language_goal(fig, "point", None, 9, None, (1, 0, 0), None, None)


def test_an_unknown_link_is_refused_and_an_ambiguous_one_warned():
    with pytest.raises(GoalError, match="no link named HAND") as info:
        RL.language_goal(model(), "point", "HAND", None, None, (1, 0, 0), None, None)
    assert "LOWER" in info.value.hint
    fig = model(TWIN)
    goal, warn = RL.language_goal(fig, "point", "UPPER", None, None, (1, 0, 0), None, None)
    assert goal.link == fig.links_named("UPPER")[0]
    assert warn.startswith("2 links are named UPPER; the goal uses the one attached by joint 1")


def solve(fig, goals, start=None, **block):
    from liganimate.runtime.ik.options import ReachOptions

    return RL.reach_block(fig, goals, 6, "LINEAR", start=start, options=ReachOptions(**block))


def test_a_met_goal_gives_the_motion_and_no_warning():
    fig = model()
    goal, _ = RL.language_goal(fig, "point", "LOWER", None, (0, -1, 0), (1.2, -0.9, 0), None, None)
    block = solve(fig, [goal])
    assert block.motion.length == 6 and set(block.motion.joints) == {1, 2}
    assert block.translation == (0.0, 0.0, 0.0) and block.warnings == ()


def test_move_chain_and_move_joints_choose_the_driven_joints():
    fig = model()
    goal, _ = RL.language_goal(fig, "point", "LOWER", None, (0, -1, 0), (1.5, -0.5, 0), None, None)
    assert solve(fig, [goal], movable=1).motion.joints == (2,)
    assert solve(fig, [goal], movable=(1,)).motion.joints == (1,)


def test_unmet_goals_and_the_iteration_limit_are_warnings_by_goal():
    fig = model()
    near, _ = RL.language_goal(fig, "point", "UPPER", None, None, (0, 0, 0), None, None)
    far, _ = RL.language_goal(fig, "point", "LOWER", None, (0, -1, 0), (5, 0, 0), None, None)
    block = solve(fig, [near, far], max_iterations=1)
    assert [w.goal for w in block.warnings] == [1, None]
    assert "stays 3" in block.warnings[0].sentence and block.warnings[0].hint == RL.UNMET_HINT
    assert "iteration limit (1)" in block.warnings[1].sentence and block.warnings[1].hint is None


def test_a_translation_beyond_the_geometry_limit_is_refused(monkeypatch):
    # The damped solvers do not carry a model past 1E12 units, so the solve's result is stood in for.
    fig = model()
    goal, _ = RL.language_goal(fig, "point", "LOWER", None, None, (3, 3, 0), None, None)
    real = solve(fig, [goal], translate=True)
    # Out of the arm's reach without moving: met by translating, within the limit.
    assert real.warnings == () and np.linalg.norm(real.translation) > 1.0

    class Far:
        motion, unmet, limit_warning = real.motion, (), None
        translation = np.array([2e12, 0.0, 0.0])

    monkeypatch.setattr(RL, "reach", lambda *args, **kwargs: Far())
    with pytest.raises(GoalError, match="not within the geometry limit") as info:
        solve(fig, [goal], translate=True)
    assert "1E12" in info.value.hint


def test_a_block_s_options_travel_as_one_reach_options(monkeypatch):
    from liganimate.compiler import compile_text
    from liganimate.runtime.ik.reach import ReachOptions, reach, reach_options

    # The generated module builds one ReachOptions: literals through repr(), the rest as expressions.
    text = ARM + "N = 1\nSTARTREACH R MODEL ARM FRAME 6\nGOAL LOWER TO (1.2, -0.9, 0)\nMOVE CHAIN N + 1\n"
    text += "TRANSLATE INTO T\nSOLVER CCD\nTOLERANCE 0.01\nITERATIONS 40\nENDREACH\nEND\n"
    python = compile_text(text).python
    built = "_host.ReachOptions(movable=_ck(N + 1, 'I+', "
    assert built in python and "translate=True, solver='ccd', tolerance=0.01, max_iterations=40)" in python
    # The host hands that very object to reach_block.
    seen = []
    real = RL.reach_block
    monkeypatch.setattr(
        RL, "reach_block", lambda *a, options, **k: seen.append(options) or real(*a, options=options, **k)
    )
    program, _ = load_program(text=text, name="arm.lig")
    program.execute("check")
    o = ReachOptions(movable=2, translate=True, solver="ccd", tolerance=0.01, max_iterations=40)
    assert seen == [o]
    with pytest.raises(AttributeError):
        o.solver = "dls"  # type: ignore[misc]
    fig = model()
    goal, _ = RL.language_goal(fig, "point", "LOWER", None, (0, -1, 0), (1.2, -0.9, 0), None, None)
    by_value = reach(fig, [goal], 6.0, options=o)
    by_fields = reach(fig, [goal], 6.0, movable=2, translate=True, solver="ccd", tolerance=0.01, max_iterations=40)
    assert np.array_equal(by_value.solution.angles, by_fields.solution.angles)
    assert reach_options(o, solver="dls") == ReachOptions(2, True, "dls", 0.01, 40)
    with pytest.raises(GoalError, match="no REACH option iterations"):
        reach(fig, [goal], 6.0, iterations=3)
