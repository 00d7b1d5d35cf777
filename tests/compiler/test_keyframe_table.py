"""The keyframe table (TABLE columns, then "| frame x y z ..." rows): the same motion as JOINT/ROOT lines, and its errors."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.compiler import compile_text, load_program
from liganimate.lang.diagnostics import LigDiagnostics

TABLE = """\
      MOTION M
      STARTMOTION M
        JOINT 5 POSITION 0.0, 0.0, 1.0
        TABLE 1, ROOT,
              2
{ frame, then x y z of JOINT 1, ROOT, JOINT 2 }
          |  0   0 0 0    0 0 0     1 2 3
          |  1   10 0 0   0.1 0 0   1 2 4
          |  2.5 20 0 0   0.2 0 0   1 2 5
      ENDMOTION
      R = 1.0
"""

LINES = """\
      MOTION M
      STARTMOTION M
        JOINT 5 POSITION 0.0, 0.0, 1.0
        JOINT 1 POSITION 0, 0, 0
          FRAME 1 POSITION 10, 0, 0
          FRAME 2.5 POSITION 20, 0, 0
        JOINT 2 POSITION 1, 2, 3
          FRAME 1 POSITION 1, 2, 4
          FRAME 2.5 POSITION 1, 2, 5
        ROOT POSITION 0, 0, 0
          FRAME 1 POSITION 0.1, 0, 0
          FRAME 2.5 POSITION 0.2, 0, 0
      ENDMOTION
"""


def _motion(text):
    program, _ = load_program(text=text)
    return program.execute("check").variables["M"]


def test_a_table_is_the_same_motion_as_its_joint_and_root_lines():
    a, b = _motion(TABLE), _motion(LINES)
    t = np.linspace(0, 2.5, 26)
    assert np.array_equal(a.evaluate(t), b.evaluate(t))
    assert np.array_equal(a.root_offset(t), b.root_offset(t))
    assert a.joints == b.joints == (1, 2, 5)


def test_lines_after_a_table_keep_their_numbers():
    # R = 1.0 is line 11; an error there must say so, so the rows' newlines were counted.
    with pytest.raises(LigDiagnostics) as e:
        compile_text(TABLE.replace("      R = 1.0", "      R = 'x' + 1"))
    assert e.value.diagnostics[0].pos.line == 11


@pytest.mark.parametrize(
    ("row", "where", "says"),
    [
        ("          |  1   10 0 0   0.1 0 zero   1 2 4", (8, 33), "'zero' is not a finite number"),
        ("          |  1   10 0 0   0.1 0 0   1 2", (8, 11), "this row has 9 numbers; the table's rows have 10"),
        ("          |  3   10 0 0   0.1 0 0   1 2 4", (9, 11), "frame 2.5 comes after frame 3"),
    ],
)
def test_a_wrong_row_is_reported_at_its_line_and_column(row, where, says):
    text = TABLE.replace("          |  1   10 0 0   0.1 0 0   1 2 4", row)
    with pytest.raises(LigDiagnostics) as e:
        compile_text(text)
    d = e.value.diagnostics[0]
    assert (d.pos.line, d.pos.column) == where and says in d.message


def test_a_table_starts_at_frame_0_and_a_joint_is_listed_once():
    with pytest.raises(LigDiagnostics) as e:
        compile_text(TABLE.replace("          |  0   0 0 0", "          |  0.5 0 0 0"))
    assert "first row is frame 0" in e.value.diagnostics[0].message
    with pytest.raises(LigDiagnostics) as e:
        compile_text(TABLE.replace("TABLE 1, ROOT,", "TABLE 5, ROOT,"))
    assert "joint 5 appears twice" in e.value.diagnostics[0].message


def test_table_stays_a_variable_name_elsewhere():
    program, _ = load_program(text="      REAL TABLE\n      TABLE = 2.0\n      PRINT TABLE\n")
    assert program.execute("check").variables["TABLE"] == 2.0


def test_fmt_keeps_a_table_and_its_rows_as_written():
    from liganimate.lang.formatter import format_text

    once = format_text(TABLE)
    assert format_text(once) == once
    assert "\n  TABLE 1, ROOT, 2\n" in once
    assert "|  2.5 20 0 0   0.2 0 0   1 2 5" in once
    assert np.array_equal(_motion(once).evaluate(np.arange(3.0)), _motion(TABLE).evaluate(np.arange(3.0)))


@pytest.mark.parametrize("blank", ["", "\f", "   "])
def test_a_file_that_ends_inside_a_table_is_reported_after_its_last_row(blank):
    # The rows are one token over several lines; the end of the file was placed by
    # the column of the token's first line, past the end of that line.
    text = f"MOTION W\nSTARTMOTION W TABLE 1 , ROOT |\n{blank} | ENDMOTION\n"
    with pytest.raises(LigDiagnostics) as info:
        load_program(text=text, name="t.lig")
    d = info.value.diagnostics[0]
    assert "ends too early" in d.message
    last = text.split("\n")[2]
    assert (d.pos.line, d.pos.column) == (3, len(last) + 1)
