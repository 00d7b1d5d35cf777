"""The ROOT track in the language: STARTMOTION's ROOT entry, m[ROOT, k] = ..., PRINT, and its errors."""

from __future__ import annotations

import io

import numpy as np
import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic


def run(text: str):
    program, _ = load_program(text=text, name="t.lig")
    out = io.StringIO()
    rt = program.execute("run", stdout=out)
    return rt, out.getvalue()


def error(text: str):
    with pytest.raises(LigDiagnostics) as info:
        program, _ = load_program(text=text, name="t.lig")
        program.check()
    d = info.value.diagnostics[0]
    assert format_diagnostic(d).startswith(f"t.lig:{d.pos.line}:{d.pos.column}: error: ")
    return d


BLOCK = """\
      STARTMOTION GO
        JOINT 1 POSITION 0.0, 0.0, 5.0
          FRAME 4 POSITION 0.0, 0.0, 40.0
        ROOT POSITION 0.0, 1.0, 0.0
          FRAME 4 POSITION 2.0, 1.0, 0.0 INTERPOLATE ACCDCC
          FRAME 8 POSITION 3.0, 1.0, 0.0
      ENDMOTION
"""


def test_startmotion_takes_a_root_entry_and_print_lists_it():
    rt, out = run(BLOCK + "      PRINT GO\n")
    go = rt.variables["GO"]
    assert go.length == 8.0 and go.joints == (1,)
    np.testing.assert_allclose(go.root_offset([0.0, 4.0, 8.0]), [[0, 1, 0], [2, 1, 0], [3, 1, 0]])
    assert "  ROOT POSITION 0, 1, 0\n    FRAME 4 POSITION 2, 1, 0 INTERPOLATE ACCDCC\n" in out


def test_keyframe_by_keyframe_root_edits():
    text = """\
      MOTION M
      M[ROOT, 0] = FRAME 0 POSITION 1.0, 0.0, 0.0
      DO 10 I = 1, 3
        M[ROOT, I] = FRAME 2 * I POSITION 1.0 + I, 0.0, 0.0
   10 CONTINUE
      M[2, 1] = FRAME 1 POSITION 0.0, 0.0, 10.0
      X = LEN(M)
"""
    rt, _ = run(text)
    m = rt.finished(rt.variables["M"])
    assert m.joints == (2,) and m.length == 6.0
    np.testing.assert_allclose(m.root_offset([0.0, 2.0, 6.0])[:, 0], [1.0, 2.0, 4.0])


def test_a_variable_may_still_be_called_root():
    rt, _ = run("      X = 1\n      ROOT = 2\n      Y = ROOT + X\n")
    assert rt.variables["Y"] == 3


def test_root_twice_is_an_error_at_the_second():
    d = error(
        BLOCK.replace("      ENDMOTION\n", "        ROOT\n          FRAME 9 POSITION 1.0, 0.0, 0.0\n      ENDMOTION\n")
    )
    assert (d.pos.line, d.pos.column) == (7, 9)
    assert d.message == "ROOT appears twice in motion GO"


def test_root_positions_are_three_numbers():
    d = error("      STARTMOTION GO\n        ROOT POSITION 1.0, 2.0\n      ENDMOTION\n")
    assert d.pos.line == 2 and "three" in d.message


def test_root_keyframes_in_order():
    d = error(
        "      STARTMOTION GO\n        ROOT\n          FRAME 4 POSITION 1.0, 0.0, 0.0\n          FRAME 2 POSITION 1.0, 0.0, 0.0\n      ENDMOTION\n"
    )
    assert d.pos.line == 4 and "ascending frame order" in d.message


def test_root_positions_within_the_geometry_limit():
    d = error("      STARTMOTION GO\n        ROOT\n          FRAME 4 POSITION 2E13, 0.0, 0.0\n      ENDMOTION\n")
    assert d.pos.line == 3 and "geometry limit" in d.message


def test_root_keyframe_gaps_name_the_root_track():
    d = error("      MOTION M\n      M[ROOT, 2] = FRAME 2 POSITION 1.0, 0.0, 0.0\n      X = LEN(M)\n")
    assert d.pos.line == 2 and d.message == "keyframe 2 of the ROOT track is set, but keyframe 1 never is"


def test_synchronize_of_two_paths_is_an_error():
    text = """\
      MOTION A, B
      A[ROOT, 1] = FRAME 2 POSITION 1.0, 0.0, 0.0
      B[ROOT, 1] = FRAME 2 POSITION 0.0, 0.0, 1.0
      C = SYNCHRONIZE A, B
"""
    d = error(text)
    assert d.pos.line == 4
    assert d.message == "the root track is driven by both operand 1 and operand 2 of SYNCHRONIZE"


def test_root_outside_a_motion_block_is_a_syntax_error():
    d = error("      X = 1\n      ROOT POSITION 1.0, 0.0, 0.0\n")
    assert d.pos.line == 2
