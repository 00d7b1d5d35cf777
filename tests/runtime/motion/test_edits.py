"""runtime/motion/edits.py: keyframe-by-keyframe motions, and the one sentence for keyframes out of order."""

from __future__ import annotations

import pytest

from liganimate.compiler import load_program
from liganimate.lang import messages
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import edits as E
from liganimate.runtime.motion.algebra import Motion


def test_edits_chain_and_apply_once():
    m = E.set_keyframe(Motion.empty(), 1, 1, 10.0, (0.0, 0.0, 30.0), None, "a")
    m = E.set_keyframe(m, 1, 2, 20.0, (0.0, 0.0, 60.0), "ACCELERATE", "b")
    motion = E.apply(m)
    assert motion.length == 20.0 and motion.joints == (1,)
    assert E.apply(m) is motion  # computed once


def test_a_skipped_keyframe_is_reported_at_the_edit_that_made_the_gap():
    m = E.set_keyframe(Motion.empty(), 2, 3, 10.0, (0.0, 0.0, 0.0), None, "third")
    with pytest.raises(E.EditError) as info:
        E.apply(m)
    assert info.value.at == "third" and "keyframe 1 never is" in info.value.message


def test_keyframe_limits_are_motion_errors():
    with pytest.raises(MotionError):
        E.set_keyframe(Motion.empty(), 1, -1, 1.0, (0.0, 0.0, 0.0), None, None)
    with pytest.raises(MotionError):
        E.set_keyframe(Motion.empty(), 1, 1, -1.0, (0.0, 0.0, 0.0), None, None)


def test_keyframes_out_of_order_say_the_one_sentence_at_every_stage():
    static = "MOTION M\nSTARTMOTION M\nJOINT 1\nFRAME 10 POSITION 0, 0, 0\nFRAME 5 POSITION 0, 0, 0\nENDMOTION\n"
    computed = "MOTION M\nF = 10\nM[1, 1] := FRAME F POSITION 0, 0, 0\nM[1, 2] := FRAME 5 POSITION 0, 0, 0\nPRINT M\n"
    with pytest.raises(LigDiagnostics) as checked:
        load_program(text=static)
    program, _ = load_program(text=computed)
    with pytest.raises(LigDiagnostics) as ran:
        program.execute()
    rule = messages.keyframes_out_of_order(5, 10).split(":")[0]
    assert rule in str(checked.value) and rule in str(ran.value)
    assert "frame 5 (keyframe 2 of joint 1) comes after frame 10" in str(ran.value)
    assert ran.value.diagnostics[0].pos.line == 4  # the edit that broke the order
