"""STARTREACH in the language: goals in, an ordinary MOTION out, misses as warnings."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime.figure.kinematics import pose_transforms
from liganimate.runtime.figure.pose import joint_angles

# A planar two-segment arm of unit segments, hanging from the origin along -Y.
ARM = """\
UPPER :- BOX AT (0, -0.5, 0), WIDTH 0.1, HEIGHT 1, DEPTH 0.1
LOWER :- BOX AT (0, -0.5, 0), WIDTH 0.1, HEIGHT 1, DEPTH 0.1
BASE :- BOX WIDTH 0.2, HEIGHT 0.2, DEPTH 0.2
STARTMODEL ARM
  JOINT 1, BASE, (0, 0, 0), UPPER, (0, 0, 0), (0, 0), (0, 0), (-170, 170)
  JOINT 2, UPPER, (0, -1, 0), LOWER, (0, 0, 0), (0, 0), (0, 0), (0, 160)
ENDMODEL
"""


def run(text: str):
    """Compile and execute in check mode; return (variables, warnings)."""
    program, warnings = load_program(text=text, name="reach.lig")
    rt = program.execute("check")
    return rt.variables, warnings + rt.warnings


def tip(variables, motion_name: str, frame: float) -> np.ndarray:
    """Where LOWER's far end (0, -1, 0) is at ``frame`` of the motion."""
    fig = variables["ARM"]
    a = joint_angles(fig, variables[motion_name], np.array([frame]))
    X = pose_transforms(fig, a)[0]
    lower = fig.links_named("LOWER")[0]
    return (X[lower] @ np.array([0.0, -1.0, 0.0, 1.0]))[:3]


def test_a_reachable_goal_is_met_at_the_last_frame():
    v, warnings = run(
        ARM
        + """
STARTREACH R MODEL ARM FRAME 12 INTERPOLATE ACCDCC
  GOAL LOWER AT (0, -1, 0) TO (1.2, -0.9, 0) WEIGHT 10
ENDREACH
"""
    )
    assert v["R"].length == 12 and set(v["R"].joints) == {1, 2}
    assert np.allclose(tip(v, "R", 12), [1.2, -0.9, 0.0], atol=1e-4)
    assert np.allclose(tip(v, "R", 0), [0.0, -2.0, 0.0])  # starts from neutral
    assert not [w for w in warnings if " stays " in w.message]


def test_reach_motions_compose_with_the_algebra():
    v, _ = run(
        ARM
        + """
STARTREACH R MODEL ARM FRAME 10
  GOAL LOWER AT (0, -1, 0) TO (1.0, -1.0, 0)
ENDREACH
THERE = R + R <SCALE FRAMES -1>
TWICE = 2 * THERE
"""
    )
    assert v["TWICE"].length == 40
    assert np.allclose(tip(v, "TWICE", 10), [1.0, -1.0, 0.0], atol=1e-4)
    assert np.allclose(tip(v, "TWICE", 20), [0.0, -2.0, 0.0], atol=1e-9)
    assert np.allclose(tip(v, "TWICE", 30), [1.0, -1.0, 0.0], atol=1e-4)


def test_a_do_loop_follows_a_moving_target_keyframe_by_keyframe():
    v, warnings = run(
        ARM
        + """
MOTION PATH
PATH[1, 0] := FRAME 0 POSITION 0, 0, 0
DO 10 K = 1, 4
  STARTREACH STEP MODEL ARM FRAME 5 FROM PATH
    GOAL LOWER AT (0, -1, 0) TO (0.3 * K, -1.5, 0)
  ENDREACH
  PATH = PATH + STEP
10 CONTINUE
"""
    )
    for k in range(1, 5):
        assert np.allclose(tip(v, "PATH", 5 * k), [0.3 * k, -1.5, 0.0], atol=1e-4), k
    assert not [w for w in warnings if " stays " in w.message]


def test_an_unreachable_goal_is_a_warning_at_the_goal_and_the_best_pose():
    v, warnings = run(
        ARM
        + """
STARTREACH FAR MODEL ARM FRAME 5
  GOAL LOWER AT (0, -1, 0) TO (3, 0, 0)
ENDREACH
"""
    )
    missed = [w for w in warnings if " stays " in w.message]
    assert len(missed) == 1
    assert (missed[0].pos.line, missed[0].pos.column) == (10, 3)
    assert missed[0].message.startswith("the point of LOWER stays 1") and missed[0].message.endswith("from its target")
    assert missed[0].hint.startswith("the model cannot get there")
    # The best pose: the arm straight out toward the target.
    assert np.allclose(tip(v, "FAR", 5), [2.0, 0.0, 0.0], atol=1e-3)


def test_translate_into_a_vector_moves_the_whole_model():
    v, _ = run(
        ARM
        + """
STARTREACH R MODEL ARM FRAME 5
  GOAL LOWER AT (0, -1, 0) TO (0, -5, 0)
  MOVE JOINTS 2
  TRANSLATE INTO SHIFT
ENDREACH
"""
    )
    assert np.allclose(list(v["SHIFT"]), [0.0, -3.0, 0.0], atol=1e-4)


def test_locked_joints_stay_put():
    v, _ = run(
        ARM
        + """
STARTREACH R MODEL ARM FRAME 5
  GOAL LOWER AT (0, -1, 0) TO (1.5, -0.5, 0)
  MOVE CHAIN 1
ENDREACH
"""
    )
    assert v["R"].joints == (2,)


@pytest.mark.parametrize(
    "body, line, col, message",
    [
        ("STARTREACH R MODEL ARM FRAME 5\nENDREACH\n", 8, 1, "REACH R has no GOAL"),
        (
            "STARTREACH R MODEL ARM FRAME 5\n GOAL LOWER TO (1, 0, 0)\n SOLVER NEWTON\nENDREACH\n",
            10,
            9,
            "NEWTON is not a solver",
        ),
        (
            "STARTREACH R MODEL ARM FRAME 5\n GOAL LOWER TO (1, 0, 0) WEIGHT -2\nENDREACH\n",
            9,
            34,
            "a goal's weight cannot be negative (-2)",
        ),
        (
            "STARTREACH R MODEL ARM FRAME 5\n GOAL LOWER TO (1, 0, 0)\n MOVE JOINTS 1\n MOVE CHAIN 1\nENDREACH\n",
            11,
            2,
            "MOVE JOINTS and MOVE CHAIN both choose the movable joints; keep one",
        ),
        (
            "STARTREACH R MODEL ARM FRAME 5\n GOAL LOWER TO (1, 0, 0)\n SOLVER DLS\n SOLVER CCD\nENDREACH\n",
            11,
            2,
            "SOLVER is given twice in this REACH",
        ),
        (
            "STARTREACH R MODEL UPPER FRAME 5\n GOAL LOWER TO (1, 0, 0)\nENDREACH\n",
            8,
            20,
            "the model of a REACH must be a MODEL, not a GRAPHICAL object",
        ),
    ],
)
def test_reach_diagnostics(body, line, col, message):
    with pytest.raises(LigDiagnostics) as info:
        run(ARM + body)
    d = info.value.diagnostics[0]
    assert (d.pos.line, d.pos.column, d.message) == (line, col, message)


def test_an_unknown_link_is_reported_at_its_goal():
    with pytest.raises(LigDiagnostics) as info:
        run(ARM + "STARTREACH R MODEL ARM FRAME 5\n GOAL HAND TO (1, 0, 0)\nENDREACH\n")
    d = info.value.diagnostics[0]
    assert (d.pos.line, d.pos.column) == (9, 2)
    assert "no link named HAND" in d.message and "LOWER" in d.hint
