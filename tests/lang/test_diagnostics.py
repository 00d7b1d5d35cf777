"""Every kind of user error becomes a diagnostic at the right line and column.

Each test compiles (and, where the error is found while the program runs,
checks) a small program in process and asserts the line, the column, a
stable part of the sentence and, where one is promised, the hint. The last
tests drive the ``liganimate`` command itself.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys

import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics, format_diagnostic

# Three unit boxes and a one-joint motion that most tests build on (lines 1-9).
PRELUDE = """\
      GRAPHICAL S1, S2, S3
      S1 :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      S2 :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      S3 :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      STARTMOTION WALK
        JOINT 1
          FRAME 4 POSITION 0.0, 0.0, 40.0
        ENDJOINT
      ENDMOTION
"""
L = PRELUDE.count("\n")  # the prelude's last line; a test's first line is L + 1

A_MODEL = "      A :- JOINT 1, S1, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (0.0, 0.0)\n"


def program_of(text: str, name: str = "t.lig"):
    return load_program(text=text, name=name)


def diagnose(text: str, name: str = "t.lig") -> Diagnostic:
    """The first error of a program that must fail (statically or when checked)."""
    with pytest.raises(LigDiagnostics) as info:
        program, _ = program_of(text, name)
        program.check()
    diags = info.value.diagnostics
    assert diags, "LigDiagnostics without a diagnostic"
    d = diags[0]
    assert d.severity == "error"
    assert d.filename == name
    # Every diagnostic formats without error and starts with file:line:col.
    assert format_diagnostic(d).startswith(f"{name}:{d.pos.line}:{d.pos.column}: error: ")
    return d


def where(d: Diagnostic):
    return d.pos.line, d.pos.column


def col(line: str, token: str, nth: int = 1) -> int:
    """1-based column of the nth occurrence of token in line."""
    i = -1
    for _ in range(nth):
        i = line.index(token, i + 1)
    return i + 1


# ------------------------------------------------------------------- syntax


def test_syntax_error():
    d = diagnose("      X = 1\n      Y = 3 * * 4\n")
    assert where(d) == (2, 15)
    assert "unexpected '*'" in d.message
    assert "expected an expression" in d.message


def test_unknown_name_hint_names_the_closest_known_name():
    d = diagnose(PRELUDE + "      X = WALKK\n")
    assert where(d) == (L + 1, 11)
    assert "WALKK is not defined" in d.message
    assert d.hint is not None and "WALK" in d.hint and "did you mean" in d.hint


def test_unknown_name_without_a_close_name_still_has_a_hint():
    d = diagnose(PRELUDE + "      X = QQQQQQ\n")
    assert where(d) == (L + 1, 11)
    assert "QQQQQQ is not defined" in d.message
    assert d.hint


# ---------------------------------------------------------------- wrong kind


def test_animate_of_a_motion():
    d = diagnose(
        PRELUDE + "      INITIALIZE SCENE 1\n      STARTSCENE LENGTH 3\n"
        "      ANIMATE WALK FROM 0 TO 2 USING WALK\n      ENDSCENE\n"
    )
    assert where(d) == (L + 3, 15)
    assert "WALK is a MOTION" in d.message and "MODEL" in d.message


def test_animate_using_a_model():
    d = diagnose(
        PRELUDE + A_MODEL + "      INITIALIZE SCENE 1\n      STARTSCENE LENGTH 3\n"
        "      ANIMATE A FROM 0 TO 2 USING A\n      ENDSCENE\n"
    )
    assert where(d) == (L + 4, 35)
    assert "USING needs a MOTION" in d.message


def test_joint_with_a_motion_as_secondary_segment():
    d = diagnose(PRELUDE + "      M :- JOINT 1, S1, (0.0, 0.0, 0.0), WALK, (0.0, 0.0, 0.0), (0.0, 0.0)\n")
    assert where(d) == (L + 1, 42)
    assert "secondary segment" in d.message and "MOTION" in d.message


def test_joint_with_a_motion_as_primary_segment():
    d = diagnose(PRELUDE + "      M :- JOINT 1, WALK, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (0.0, 0.0)\n")
    assert where(d) == (L + 1, 21)
    assert "primary segment" in d.message and "MOTION" in d.message


# ------------------------------------------------------------ model structure


def test_duplicate_joint_ids_in_startmodel():
    d = diagnose(
        PRELUDE + "      STARTMODEL M\n"
        "        JOINT 1, S1, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (0.0, 0.0)\n"
        "        JOINT 1, S2, (0.0, 0.0, 0.0), S3, (0.0, 0.0, 0.0), (0.0, 0.0)\n"
        "      ENDMODEL\n"
    )
    assert where(d) == (L + 3, 15)
    assert "joint 1 appears twice" in d.message
    assert d.hint and f"line {L + 2}" in d.hint


def test_duplicate_joint_ids_when_joining_two_models():
    d = diagnose(
        PRELUDE
        + A_MODEL
        + "      B :- JOINT 1, S1, (0.0, 0.0, 0.0), S3, (0.0, 0.0, 0.0), (0.0, 0.0)\n"
        + "      C :- JOINT 2, A, (0.0, 0.0, 0.0), B, (0.0, 0.0, 0.0), (0.0, 0.0)\n"
    )
    assert where(d) == (L + 3, 12)
    assert "joint identifier 1" in d.message and "twice" in d.message
    assert d.hint and "TRANS JOINTS" in d.hint


def test_model_joined_to_itself_is_a_cycle():
    line = "      A :- JOINT 2, A, (0.0, 0.0, 0.0), A, (0.0, 0.0, 0.0), (0.0, 0.0)"
    d = diagnose(PRELUDE + A_MODEL + line + "\n")
    assert where(d) == (L + 2, col(line, "A,", 2))
    assert "cannot be joined to itself" in d.message and "cycle" in d.message
    assert d.hint


def test_startmodel_cycle():
    d = diagnose(
        PRELUDE + "      STARTMODEL M\n"
        "        JOINT 1, S1, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (0.0, 0.0)\n"
        "        JOINT 2, S2, (0.0, 0.0, 0.0), S1, (0.0, 0.0, 0.0), (0.0, 0.0)\n"
        "      ENDMODEL\n"
    )
    assert where(d) == (L + 1, 7)
    assert "cycle" in d.message
    assert d.hint


def test_figure_naming_a_missing_link_suggests_one():
    d = diagnose(PRELUDE + A_MODEL + "      FIGURE A MAIN LINK S22\n")
    assert where(d) == (L + 2, 7)
    assert "no link named S22" in d.message
    assert d.hint and "did you mean" in d.hint and "S2" in d.hint


def test_extremes_minimum_above_maximum():
    line = "      A :- JOINT 1, S1, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (90.0, -90.0)"
    d = diagnose(PRELUDE + line + "\n")
    # the pair, with or without its opening parenthesis
    assert d.pos.line == L + 1 and d.pos.column in (col(line, "(90.0"), col(line, "90.0"))
    assert "minimum (90) above the maximum (-90)" in d.message
    assert d.hint and "(-90, 90)" in d.hint


def test_extremes_minimum_above_maximum_found_when_running():
    d = diagnose(
        PRELUDE + "      REAL LO\n      LO = 90.0\n"
        "      A :- JOINT 1, S1, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (LO, -90.0)\n"
    )
    assert where(d) == (L + 3, 12)
    assert "minimum above" in d.message and "X extremes" in d.message
    assert d.hint and "(-90, 90)" in d.hint


# ----------------------------------------------------------------- motions


def test_synchronize_of_motions_driving_the_same_joint():
    d = diagnose(PRELUDE + "      B = WALK <SCALE FRAMES 2.0>\n      C = SYNCHRONIZE WALK, B\n")
    assert where(d) == (L + 2, 11)
    assert "joint 1 is driven by both" in d.message
    assert d.hint and "STRIP" in d.hint


def test_real_constant_repetition_count():
    d = diagnose(PRELUDE + "      B = 2.5 * WALK\n")
    assert where(d) == (L + 1, 11)
    assert "repetition count must be an INTEGER" in d.message
    assert d.hint


def test_real_variable_repetition_count():
    d = diagnose(PRELUDE + "      REAL R\n      R = 2.0\n      B = R * WALK\n")
    assert where(d) == (L + 3, 11)
    assert "repetition count must be an INTEGER" in d.message
    assert d.hint


# -------------------------------------------------------------- host code


DIVIDE_IN_A_LOOP = """\
      INTEGER I
      REAL X
      DO 10 I = -2, 2
         PRINT I
         X = 1.0 / I
 10   CONTINUE
"""


def test_division_by_zero_at_its_line_and_column():
    d = diagnose(DIVIDE_IN_A_LOOP)
    assert where(d) == (5, 18)
    assert "division by zero" in d.message
    assert d.hint


def test_division_by_zero_happens_at_the_iteration_that_divides_by_zero():
    program, _ = program_of(DIVIDE_IN_A_LOOP)
    out = io.StringIO()
    with pytest.raises(LigDiagnostics) as info:
        program.execute("render", stdout=out)
    assert where(info.value.diagnostics[0]) == (5, 18)
    # I = -2 and I = -1 divided; I = 0 printed, then failed; I = 1 never came.
    assert out.getvalue().split() == ["I", "=", "-2", "I", "=", "-1", "I", "=", "0"]


def test_do_without_continue():
    d = diagnose("      INTEGER I\n      REAL X\n      DO 10 I = 1, 3\n      X = I\n")
    assert where(d) == (3, 7)
    assert "DO 10 is never closed by 10 CONTINUE" in d.message
    assert d.hint and "10 CONTINUE" in d.hint


def test_continue_without_do():
    d = diagnose("      INTEGER I\n 10   CONTINUE\n")
    assert where(d) == (2, 2)
    assert "closes no DO loop" in d.message
    assert d.hint


# -------------------------------------------------------------- primitives


PEG = """\
      PRIMITIVE PEG
      REAL SIZE
      VECTOR CENTRE
      GRAPHICAL G
      PEG ::= 'PEG' [ 'AT' CENTRE ',' ] <CENTRE = {default}> 'SIZE' SIZE ;
      G :- BOX AT (CENTRE), WIDTH SIZE, HEIGHT SIZE, DEPTH SIZE
{extra}      RETURN
      END
      GRAPHICAL P
      P :- PEG SIZE 1.0
"""


def test_a_primitive_compiles_and_runs():
    program, _ = program_of(PEG.format(default="(0.0, 0.0, 0.0)", extra=""))
    program.check()


def test_unknown_function_in_a_pattern_default():
    text = PEG.format(default="C(0.0, 0.0, 0.0)", extra="")
    d = diagnose(text)
    assert where(d) == (5, col(text.split("\n")[4], "C("))
    assert "C is not a function" in d.message


def test_unknown_name_in_a_pattern_default():
    text = PEG.format(default="ORIGIN", extra="")
    d = diagnose(text)
    assert where(d) == (5, col(text.split("\n")[4], "ORIGIN"))
    assert "ORIGIN is not defined" in d.message


def test_a_primitive_that_calls_itself():
    text = PEG.format(default="(0.0, 0.0, 0.0)", extra="      G :- PEG SIZE SIZE\n")
    d = diagnose(text)
    # at the call inside PEG, or at the call that started the recursion
    assert where(d) in ((7, col(text.split("\n")[6], "PEG")), (11, col(text.split("\n")[10], "PEG")))
    assert "PEG" in d.message


# ------------------------------------------------------------- unclosed blocks


UNCLOSED = PRELUDE + "      STARTMODEL M\n        JOINT 1, S1, (0.0, 0.0, 0.0), S2, (0.0, 0.0, 0.0), (0.0, 0.0)\n"


def test_unclosed_startmodel_at_the_end_of_the_file():
    d = diagnose(UNCLOSED)
    assert where(d) == (L + 1, 7)
    assert f"ENDMODEL closes the STARTMODEL opened at line {L + 1}" in d.message
    assert d.hint and "ENDMODEL" in d.hint


def test_unclosed_startmodel_before_end():
    d = diagnose(UNCLOSED + "      END\n")
    assert where(d) == (L + 3, 7)
    assert "unexpected 'END'" in d.message
    assert d.hint and f"STARTMODEL opened at line {L + 1}" in d.hint


def test_unclosed_startmodel_before_another_statement_says_where_it_opened():
    d = diagnose(UNCLOSED + "      FIGURE M MAIN\n      END\n")
    assert where(d) == (L + 3, 7)
    text = d.message + " " + (d.hint or "")
    assert f"STARTMODEL opened at line {L + 1}" in text


# ------------------------------------------------------------------- $ names


def test_dollar_names_are_reserved():
    d = diagnose("      $X = 1\n")
    assert where(d) == (1, 7)
    assert "names beginning with $ are reserved" in d.message
    assert d.hint and "PRINT $" in d.hint


def test_dollar_inside_a_name():
    d = diagnose("      REAL X\n      X$ = 1\n")
    assert where(d) == (2, 8)
    assert "names beginning with $ are reserved" in d.message


def test_print_dollar_of_a_motion():
    d = diagnose(PRELUDE + "      PRINT $WALK\n")
    assert where(d) == (L + 1, 14)
    assert "PRINT $ needs a MODEL" in d.message and "MOTION" in d.message


# ----------------------------------------------------------------- warnings


def test_c_in_column_1_warning():
    program, warnings = program_of("C a comment line, no warning\n      REAL C\nC = 2.0\n      C = 3.0\n")
    assert len(warnings) == 1
    w = warnings[0]
    assert w.severity == "warning"
    assert where(w) == (3, 1)
    assert "this line is a comment" in w.message
    assert w.hint and "indent" in w.hint
    program.check()


# ---------------------------------------------------------------- nesting


def _no_crash(text: str):
    """Compile and check; success or LigDiagnostics, never another exception."""
    try:
        program, _ = program_of(text)
        program.check()
    except LigDiagnostics as exc:
        return exc.diagnostics[0]
    return None


def test_5000_nested_parenthesised_operations():
    n = 5000
    d = diagnose("      X = " + "-(" * n + "1" + ")" * n + "\n")
    assert d.pos.line == 1
    assert "nested more than" in d.message
    assert d.hint
    d = diagnose("      X = " + "(1 + " * n + "1" + ")" * n + "\n")
    assert "nested more than" in d.message


def test_5000_nested_parentheses():
    n = 5000
    # Parentheses alone add no nesting to the program: either is fine.
    d = _no_crash("      X = " + "(" * n + "1" + ")" * n + "\n")
    assert d is None or d.pos.line == 1


def test_5000_nested_if_begin_blocks():
    n = 5000
    text = "      INTEGER I\n      I = 1\n" + "      IF I = 1 THEN BEGIN\n" * n + "      I = 2\n" + "      END\n" * n
    d = diagnose(text)
    assert "nested more than" in d.message
    assert 3 <= d.pos.line <= n + 2 and d.pos.column == 7


def test_5000_nested_do_loops():
    n = 5000
    text = (
        "      INTEGER I\n"
        + "".join(f"      DO {k} I = 1, 1\n" for k in range(1, n + 1))
        + "".join(f" {k}   CONTINUE\n" for k in range(n, 0, -1))
    )
    d = diagnose(text)
    assert "nested more than" in d.message
    assert 2 <= d.pos.line <= n + 1


def test_25_nested_do_loops_run_or_are_diagnosed():
    n = 25
    text = (
        "      INTEGER I, S\n      S = 0\n"
        + "".join(f"      DO {k} I = 1, 1\n" for k in range(1, n + 1))
        + "      S = S + 1\n"
        + "".join(f" {k}   CONTINUE\n" for k in range(n, 0, -1))
    )
    d = _no_crash(text)
    assert d is None or "nested" in d.message


# --------------------------------------------------------------- invalid UTF-8


BAD_UTF8 = b"      REAL X\n      X = 1.0\n      Y = \xb0 + X\n"


def test_invalid_utf8_in_process(tmp_path):
    from liganimate.compiler import compile_file

    path = tmp_path / "bad.lig"
    path.write_bytes(BAD_UTF8)
    with pytest.raises(LigDiagnostics) as info:
        compile_file(str(path))
    d = info.value.diagnostics[0]
    assert where(d) == (3, 11)
    assert "not valid UTF-8" in d.message and "0xb0" in d.message
    assert d.hint


def test_invalid_utf8_diagnostic_shows_the_line(tmp_path):
    from liganimate.compiler import compile_file

    path = tmp_path / "bad.lig"
    path.write_bytes(BAD_UTF8)
    with pytest.raises(LigDiagnostics) as info:
        compile_file(str(path))
    shown = format_diagnostic(info.value.diagnostics[0])
    # Like every other diagnostic: the source line (as far as it decodes) and a caret.
    assert "      Y = " in shown
    assert "^" in shown


def run_cli(*args, cwd):
    env = dict(os.environ)
    env.pop("LIGANIMATE_DEBUG", None)
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=120
    )


def test_invalid_utf8_via_the_cli(tmp_path):
    (tmp_path / "bad.lig").write_bytes(BAD_UTF8)
    r = run_cli("check", "bad.lig", cwd=tmp_path)
    assert r.returncode == 1
    assert "bad.lig:3:11: error: the file is not valid UTF-8" in r.stderr
    assert "hint:" in r.stderr
    assert "Traceback" not in r.stderr + r.stdout


# ------------------------------------------------------------------------ CLI


def test_cli_bad_program_exits_1_and_writes_nothing(tmp_path):
    (tmp_path / "bad.lig").write_text(PRELUDE + "      X = WALKK\n", encoding="utf-8")
    # a runtime error too: the program compiles, then divides by zero while checked
    (tmp_path / "div.lig").write_text(DIVIDE_IN_A_LOOP, encoding="utf-8")
    before = set(os.listdir(tmp_path))
    r = run_cli("run", "bad.lig", "-o", "frames", "--size", "64x48", cwd=tmp_path)
    assert r.returncode == 1
    assert f"bad.lig:{L + 1}:11: error: WALKK is not defined" in r.stderr
    assert "hint: did you mean WALK?" in r.stderr
    assert "Traceback" not in r.stderr + r.stdout
    r = run_cli("run", "div.lig", "--size", "64x48", cwd=tmp_path)
    assert r.returncode == 1
    assert "div.lig:5:18: error: division by zero" in r.stderr
    assert "Traceback" not in r.stderr + r.stdout
    r = run_cli("compile", "bad.lig", "-o", "bad.py", cwd=tmp_path)
    assert r.returncode == 1
    assert "Traceback" not in r.stderr + r.stdout
    # No frames folder (neither -o frames nor the default div_frames), no module.
    assert set(os.listdir(tmp_path)) == before


@pytest.mark.parametrize("before", ["", "REAL X\nX = 1\n", "C a comment\n\n"])
def test_a_begin_block_outside_if_is_reported_at_begin(before):
    # BEGIN where a statement may start was read as a variable called BEGIN,
    # and the error came a line later ("unexpected REAL; expected =").
    d = diagnose(before + "BEGIN\n  REAL Y\n  Y = 2\nEND\n")
    line = before.count("\n") + 1
    assert (d.pos.line, d.pos.column, d.pos.end_column) == (line, 1, 6)
    assert d.message == "BEGIN starts a block only after THEN or ELSE"
    assert "remove both" in d.hint


def test_begin_is_still_a_variable_name():
    out = io.StringIO()
    program, _ = load_program(text="REAL BEGIN\nBEGIN = 2\nPRINT BEGIN\n")
    program.check(stdout=out)
    assert out.getvalue() == "BEGIN = 2\n"
