"""ROOT ORIENTATION in the language: the STARTMOTION entry, the table column, m[ROOT ORIENTATION, k], PRINT, fmt, errors."""

from __future__ import annotations

import io

import numpy as np
import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic
from liganimate.lang.formatter import format_text


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
      MOTION GO
      STARTMOTION GO
        ROOT POSITION 0.0, 0.0, 0.0
          FRAME 8 POSITION 2.0, 0.0, 0.0
        ROOT ORIENTATION POSITION 0.0, 10.0, 0.0
          FRAME 4 POSITION 5.0, 55.0, 0.0 INTERPOLATE ACCDCC
          FRAME 8 POSITION 0.0, 100.0, 0.0
      ENDMOTION
"""

TABLE = """\
      MOTION GO
      STARTMOTION GO
        TABLE ROOT, ROOT ORIENTATION
{ frame, then x y z of ROOT, ROOT ORIENTATION }
          |  0   0 0 0     0 10 0
          |  4   1 0 0     5 55 0
          |  8   2 0 0     0 100 0
      ENDMOTION
"""

LINES = """\
      MOTION GO
      STARTMOTION GO
        ROOT
          FRAME 4 POSITION 1, 0, 0
          FRAME 8 POSITION 2, 0, 0
        ROOT ORIENTATION POSITION 0, 10, 0
          FRAME 4 POSITION 5, 55, 0
          FRAME 8 POSITION 0, 100, 0
      ENDMOTION
"""


def test_startmotion_takes_a_root_orientation_and_print_lists_it():
    rt, out = run(BLOCK + "      PRINT GO\n")
    go = rt.variables["GO"]
    assert go.length == 8.0
    np.testing.assert_allclose(go.root_orientation([0.0, 4.0, 8.0]), [[0, 10, 0], [5, 55, 0], [0, 100, 0]])
    assert go.heading("end") == 100.0
    assert "  ROOT ORIENTATION POSITION 0, 10, 0\n    FRAME 4 POSITION 5, 55, 0 INTERPOLATE ACCDCC\n" in out


def test_plus_continues_the_heading_in_a_program():
    rt, _ = run(BLOCK + "      TWICE = GO + GO\n")
    two = rt.variables["TWICE"]
    assert two.heading("end") == pytest.approx(190.0)
    # The second path walks along +X turned by the 90 degrees the first one turned: along -Z.
    np.testing.assert_allclose(two.root_offset([16.0]), [[2.0, 0.0, -2.0]], atol=1e-12)


def test_a_table_column_is_the_same_track_as_its_lines():
    a = load_program(text=TABLE)[0].execute("check").variables["GO"]
    b = load_program(text=LINES)[0].execute("check").variables["GO"]
    t = np.linspace(0, 8, 33)
    assert np.array_equal(a.root_orientation(t), b.root_orientation(t))
    assert np.array_equal(a.root_offset(t), b.root_offset(t))


def test_keyframe_by_keyframe_orientation_edits():
    text = """\
      MOTION M
      DO 10 I = 1, 4
        M[ROOT ORIENTATION, I] = FRAME 3 * I POSITION 0.0, 90.0 * I, 0.0
   10 CONTINUE
      X = LEN(M)
"""
    rt, _ = run(text)
    m = rt.finished(rt.variables["M"])
    assert m.length == 12.0 and m.joints == () and m.root is None
    np.testing.assert_allclose(m.root_orientation([3.0, 12.0])[:, 1], [90.0, 360.0])


def test_fmt_keeps_root_orientation_entries_and_columns():
    for text in (BLOCK, TABLE):
        once = format_text(text)
        assert format_text(once) == once
        assert "ROOT ORIENTATION" in once
    a = load_program(text=format_text(BLOCK))[0].execute("check").variables["GO"]
    np.testing.assert_allclose(a.root_orientation([4.0]), [[5, 55, 0]])


def test_a_variable_may_still_be_called_orientation():
    rt, _ = run("      ORIENTATION = 2\n      Y = ORIENTATION + 1\n")
    assert rt.variables["Y"] == 3


def test_an_orientation_on_a_joint_is_refused_where_it_is_written():
    d = error(
        "      MOTION M\n      STARTMOTION M\n        JOINT 3 ORIENTATION POSITION 0.0, 0.0, 0.0\n      ENDMOTION\n"
    )
    assert (d.pos.line, d.pos.column) == (3, 17)
    assert d.message == "only the ROOT track has an ORIENTATION; a joint's three angles are its POSITION"
    assert "ROOT ORIENTATION" in d.hint
    d = error("      MOTION M\n      M[3 ORIENTATION, 1] = FRAME 3 POSITION 0.0, 10.0, 0.0\n")
    assert (d.pos.line, d.pos.column) == (2, 11)


def test_root_orientation_twice_is_an_error_at_the_second():
    d = error(
        BLOCK.replace(
            "      ENDMOTION\n", "        ROOT ORIENTATION\n          FRAME 9 POSITION 1.0, 0.0, 0.0\n      ENDMOTION\n"
        )
    )
    assert (d.pos.line, d.pos.column) == (8, 9)
    assert d.message == "ROOT ORIENTATION appears twice in motion GO"
    # ROOT and ROOT ORIENTATION are two tracks: each once.
    load_program(text=BLOCK)[0].check()


def test_orientation_angles_are_three_numbers_and_in_order():
    d = error("      MOTION M\n      STARTMOTION M\n        ROOT ORIENTATION POSITION 1.0, 2.0\n      ENDMOTION\n")
    assert d.pos.line == 3 and "three" in d.message
    d = error(
        "      MOTION M\n      STARTMOTION M\n        ROOT ORIENTATION\n          FRAME 4 POSITION 1.0, 0.0, 0.0\n"
        "          FRAME 2 POSITION 1.0, 0.0, 0.0\n      ENDMOTION\n      X = LEN(M)\n"
    )
    assert d.pos.line == 5 and "ascending frame order" in d.message


def test_synchronize_of_two_orientations_is_an_error():
    text = """\
      MOTION A, B
      A[ROOT ORIENTATION, 1] = FRAME 2 POSITION 0.0, 10.0, 0.0
      B[ROOT ORIENTATION, 1] = FRAME 2 POSITION 0.0, 20.0, 0.0
      C = SYNCHRONIZE A, B
"""
    d = error(text)
    assert d.pos.line == 4
    assert d.message == "the root orientation is driven by both operand 1 and operand 2 of SYNCHRONIZE"


def test_a_rerooted_figure_turns_about_its_new_main_link():
    """FIGURE ... MAIN JOINT 4 stands the human on its right foot: ROOT ORIENTATION turns it about that foot."""
    from liganimate.runtime import exchange as X
    from liganimate.runtime.figure.pose import world_transforms

    text = """\
      LOAD HUMAN FROM 'human'
      MODEL ON_FOOT
      MOTION SPIN
      STARTMOTION SPIN
        ROOT ORIENTATION
          FRAME 8 POSITION 0.0, 90.0, 0.0
      ENDMOTION
      ON_FOOT :- HUMAN
      FIGURE ON_FOOT MAIN JOINT 4
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 9
        ANIMATE ON_FOOT FROM 0 TO 8 USING SPIN
      ENDSCENE
      SHOOTSCENES
      END
"""
    program, _ = load_program(text=text, name="t.lig")
    take = X.collect(program)[0].models[0]
    fig = take.figure
    W = world_transforms(fig, take.angles, take.placements)
    foot = fig.main
    torso = fig.root
    # The foot (the main link) turns in place; the torso, above it, swings round it.
    np.testing.assert_allclose(W[:, foot, :3, 3], W[:1, foot, :3, 3].repeat(9, axis=0), atol=1e-12)
    np.testing.assert_allclose(W[-1, foot, :3, :3] @ [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], atol=1e-9)
    lever = W[:, torso, :3, 3] - W[:, foot, :3, 3]
    assert not np.allclose(lever[0], lever[-1], atol=1e-3)
    np.testing.assert_allclose(np.linalg.norm(lever, axis=1), np.linalg.norm(lever[0]), atol=1e-9)
