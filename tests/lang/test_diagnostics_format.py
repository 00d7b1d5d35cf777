"""How diagnostics look: the end of the file, long lines, control characters, stray block ends, plain sentences.

Each behaviour is checked through :func:`format_diagnostic` (in process) and
through ``python -m liganimate check`` (what a user sees on the terminal).
"""

from __future__ import annotations

import os
import subprocess
import sys
import unicodedata

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mutations import SOURCES, example, mutated, mutations

from liganimate.lang.ast import Pos
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics, format_diagnostic
from liganimate.lang.display import MAX_COLUMNS
from liganimate.lang.parser import (
    _FRIENDLY,
    _describe_expected,
    _terminal_text,
    grammar,
    parse,
)


def syntax_error(text: str, name: str = "t.lig") -> Diagnostic:
    """The diagnostic of a program that must not parse."""
    with pytest.raises(LigDiagnostics) as info:
        parse(text, name)
    (d,) = info.value.diagnostics
    return d


def check_cli(tmp_path, text: str | bytes, name: str = "t.lig"):
    """Run ``liganimate check`` on a file holding ``text``; returns (exit status, stderr)."""
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8", newline="")
    env = dict(os.environ)
    env.pop("LIGANIMATE_DEBUG", None)
    env["PYTHONIOENCODING"] = "utf-8"
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "check", name],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        timeout=300,
        check=False,
    )
    assert b"Traceback" not in r.stderr + r.stdout
    return r.returncode, r.stderr.decode("utf-8")


def width(text: str) -> int:
    """Terminal columns of ``text`` (wide CJK characters take two)."""
    return sum(2 if unicodedata.east_asian_width(c) in ("W", "F") else 1 for c in text)


def caret_target(shown: str, caret: str) -> str:
    """The character of the shown source line the caret's ``^`` stands under."""
    column = caret.index("^")
    at = 0
    for ch in shown:
        if at == column:
            return ch
        at += width(ch)
    return ""  # just after the last character


def raw_controls(text: str) -> list:
    """Characters a terminal would act on: controls other than the line breaks, and format characters."""
    return [c for c in text if c != "\n" and unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp", "Cs")]


# ------------------------------------------------------------- 1. end of file


@pytest.mark.parametrize("text", ["X = (1 + 2", "X = (1 + 2\n", "X = (1 + 2\n\n   \n"])
def test_an_error_at_the_end_of_the_file_shows_the_last_line_a_caret_after_it_and_the_unclosed_bracket(text):
    d = syntax_error(text)
    assert (d.pos.line, d.pos.column) == (1, 11)
    assert "the file ends" in d.message
    assert d.hint == "the ( opened at 1:5 is never closed"
    lines = format_diagnostic(d).split("\n")
    assert lines[0].startswith("t.lig:1:11: error: ")
    assert lines[1] == "    X = (1 + 2"
    assert lines[2].rstrip() == "    " + " " * 10 + "^"
    assert lines[3] == "  hint: the ( opened at 1:5 is never closed"


def test_an_unclosed_index_bracket_is_named_too():
    d = syntax_error("M[1, 2\n")
    assert "the [ opened at 1:2 is never closed" == d.hint


def test_a_bracket_open_on_an_earlier_line_is_named_where_the_error_shows():
    d = syntax_error("X = (1 + 2\nY = 3\n")
    assert (d.pos.line, d.pos.column) == (2, 1)
    assert d.hint == "the ( opened at 1:5 is never closed"


def test_every_end_of_file_error_has_a_line_a_caret_and_a_hint():
    # Every cut of an example that ends inside a statement is an error at the end of the file.
    name, text = SOURCES[0]
    seen = 0
    for cut in range(0, len(text), max(1, len(text) // 150)):
        try:
            parse(text[:cut], name)
        except LigDiagnostics as exc:
            d = exc.diagnostics[0]
            if "the file ends" not in d.message:
                continue
            seen += 1
            lines = format_diagnostic(d).split("\n")
            assert lines[1].strip(), lines
            assert lines[2].strip().startswith("^"), lines
            assert d.hint and lines[-1].startswith("  hint: "), lines
    assert seen > 10


def test_a_position_past_the_last_line_shows_the_last_non_blank_line_at_the_end_of_the_file():
    src = "X = 1\nY = 2 {note}\n\n  \n"
    for line in (3, 4, 5, 9):
        d = Diagnostic("t.lig", Pos(line, 1, line, 1), "something is missing", "add it", source=src)
        lines = format_diagnostic(d).split("\n")
        assert lines[1] == "    Y = 2 {note}"
        assert lines[2] == "    " + " " * len("Y = 2 {note}") + "^ at the end of the file"


def test_end_of_file_via_the_cli(tmp_path):
    status, err = check_cli(tmp_path, "X = (1 + 2\n")
    assert status == 1
    assert err.splitlines() == [
        "t.lig:1:11: error: the file ends too early; expected ',' or ')'",
        "    X = (1 + 2",
        "              ^",
        "  hint: the ( opened at 1:5 is never closed",
    ]


# ------------------------------------------------------------- 2. long lines


def test_a_long_line_is_cut_around_the_caret():
    line = "a" * 3_000_000 + "Z" + "b" * 2_000_000
    d = Diagnostic("t.lig", Pos(1, 3_000_001, 1, 3_000_002), "bad", source="X = 1\n" * 0 + line + "\n")
    lines = format_diagnostic(d).split("\n")
    assert len(lines) == 3
    shown, caret = lines[1][4:], lines[2][4:]
    assert shown.startswith("…") and shown.endswith("…")
    assert width(shown) <= MAX_COLUMNS + 2
    assert caret_target(shown, caret) == "Z"
    assert caret.strip() == "^"


def test_the_caret_of_a_huge_token_stays_short_and_starts_at_the_token():
    line = "X = " + "7" * 1_000_000 + " + 1"
    d = Diagnostic("t.lig", Pos(1, 5, 1, 1_000_005), "too big", source=line)
    shown, caret = (s[4:] for s in format_diagnostic(d).split("\n")[1:3])
    assert shown.startswith("X = 7") and shown.endswith("…")
    assert caret.index("^") == 4
    assert len(caret) <= MAX_COLUMNS + 2


def test_a_caret_near_the_end_of_a_long_line_shows_the_end():
    line = "c" * 10_000 + " * * 2"
    d = Diagnostic("t.lig", Pos(1, 10_004, 1, 10_005), "bad", source=line)
    shown, caret = (s[4:] for s in format_diagnostic(d).split("\n")[1:3])
    assert shown.startswith("…") and shown.endswith("* * 2")
    assert caret_target(shown, caret) == "*" and shown[caret.index("^") + 1 :] == " 2"


def test_a_long_bad_line_via_the_cli_prints_a_short_error(tmp_path):
    text = "X = 1 {" + "x" * 2_000_000 + "} * * 2\n"
    status, err = check_cli(tmp_path, text)
    assert status == 1
    assert len(err) < 1000
    head, shown, caret = err.splitlines()[:3]
    assert head == f"t.lig:1:{text.rindex('*') + 1}: error: unexpected '*'; expected an expression"
    assert caret_target(shown[4:], caret[4:]) == "*"
    assert shown.endswith("} * * 2")


# ------------------------------------------------------ 3. control characters


def test_control_characters_in_the_shown_line_are_escaped_and_the_caret_follows_them():
    line = "A\x1b[31mB\u202eC\x7fD\x85E\tF漢G\u2066H\x0cI"
    src = line + "\nnext\n"
    for letter in "ABCDEFGHI":
        column = line.index(letter) + 1
        d = Diagnostic("t.lig", Pos(1, column, 1, column + 1), "bad", source=src)
        out = format_diagnostic(d)
        assert raw_controls(out) == []
        shown, caret = (s[4:] for s in out.split("\n")[1:3])
        assert caret_target(shown, caret) == letter
    assert "\\x1b[31m" in shown and "\\u202e" in shown and "\\x7f" in shown and "\\x85" in shown
    assert "\\u2066" in shown and "\\x0c" in shown and "E F" in shown  # a tab is one blank, as columns count it


def test_a_caret_under_an_escaped_character_covers_its_escape():
    d = Diagnostic("t.lig", Pos(1, 3, 1, 4), "unexpected character", source="X \x1b Y")
    shown, caret = (s[4:] for s in format_diagnostic(d).split("\n")[1:3])
    assert shown == "X \\x1b Y" and caret == "  ^~~~"


def test_a_wide_token_is_underlined_over_its_full_width():
    d = Diagnostic("t.lig", Pos(1, 5, 1, 9), "bad", source="X = '漢字' * * 1")
    caret = format_diagnostic(d).split("\n")[2][4:]
    assert caret == "    ^" + "~" * 5


_CHARS = st.sampled_from(
    list("ab =*(")
    + [
        "\t",
        "\x1b",
        "\x00",
        "\x7f",
        "\x85",
        "\x9b",
        "\u202e",
        "\u2066",
        "\u200b",
        "\ufeff",
        "\u2028",
        "漢",
        "字",
        "Ａ",
        "é",
        "\U0001f600",
    ]
)


@settings(max_examples=300, deadline=None)
@given(st.lists(_CHARS, max_size=400), st.lists(_CHARS, max_size=400), st.integers(1, 50))
def test_any_line_is_shown_escaped_short_and_with_the_caret_under_its_character(left, right, span):
    line = "".join(left) + "Z" + "".join(right)
    column = len(left) + 1
    d = Diagnostic("t.lig", Pos(1, column, 1, column + span), "bad", source=line + "\n")
    out = format_diagnostic(d)
    assert raw_controls(out) == []
    shown, caret = (s[4:] for s in out.split("\n")[1:3])
    assert width(shown) <= MAX_COLUMNS + 2
    assert caret_target(shown, caret) == "Z"
    assert set(caret) <= {" ", "^", "~"} and len(caret) <= width(shown) + 1


def test_file_name_message_hint_and_notes_are_escaped():
    d = Diagnostic(
        "evil\x1b[2J\nname.lig",
        Pos(1, 1, 1, 2),
        "unexpected '\x1b]0;title\x07' in \u202eNAME",
        "rename \x1b[31mit\r",
        source="X = 1\n",
        notes=["see \x9b1m"],
    )
    out = format_diagnostic(d)
    assert raw_controls(out) == []
    head = out.split("\n")[0]
    assert head.startswith("evil\\x1b[2J\\x0aname.lig:1:1: error: unexpected '\\x1b]0;title\\x07' in \\u202eNAME")
    assert "  hint: rename \\x1b[31mit\\x0d" in out and "  note: see \\x9b1m" in out


def test_lines_are_counted_at_line_feeds_only():
    # Form feed and U+2028 are blanks to the lexer, not line ends: line 2 is the line after the first \n.
    src = "X = 1 {\x0c\u2028\x1c}\nY = 2 * * 3\n"
    d = syntax_error(src)
    assert (d.pos.line, d.pos.column) == (2, 9)
    assert format_diagnostic(d).split("\n")[1] == "    Y = 2 * * 3"


def test_control_characters_via_the_cli(tmp_path):
    text = "X = 1 { \u202eevil\u2069 \x0c } * * 2\n"
    status, err = check_cli(tmp_path, text, name="bad\x1b[31m\nname.lig")
    assert status == 1
    assert raw_controls(err) == []
    head, shown, caret = err.splitlines()[:3]
    assert head.startswith("bad\\x1b[31m\\x0aname.lig:1:")
    assert "\\u202eevil\\u2069 \\x0c }" in shown
    assert caret_target(shown[4:], caret[4:]) == "*"


# --------------------------------------------------------- 4. stray block ends


MOTION = "STARTMOTION W\n  JOINT 1\n    FRAME 4 POSITION 0, 0, 40\n  ENDJOINT\nENDMOTION\n"  # lines 1-5


@pytest.mark.parametrize("after", ["", "X = 1\n", "Y = 2 * X\n", "  PRINT 3\n"])
def test_a_stray_endmotion_is_reported_at_its_own_line(after):
    d = syntax_error(MOTION + "X = 1\n  ENDMOTION\n" + after)
    assert (d.pos.line, d.pos.column, d.pos.end_column) == (7, 3, 12)
    assert d.message == "ENDMOTION without STARTMOTION"
    assert d.hint == "the STARTMOTION at line 1 was already closed by the ENDMOTION at line 5"


@pytest.mark.parametrize(
    "program, line, word, message, hint",
    [
        (
            "STARTMODEL M\nENDMODEL\nendmodel\nX = 1\n",
            3,
            "endmodel",
            "ENDMODEL without STARTMODEL",
            "the STARTMODEL at line 1 was already closed by the ENDMODEL at line 2",
        ),
        (
            MOTION.replace("ENDMOTION", "  ENDJOINT\nENDMOTION"),
            5,
            "ENDJOINT",
            "ENDJOINT without JOINT",
            "the JOINT at line 2 was already closed by the ENDJOINT at line 4",
        ),
        (
            "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 3\nENDSCENE\nENDSCENE\nX = 1\n",
            4,
            "ENDSCENE",
            "ENDSCENE without INITIALIZE SCENE",
            "the INITIALIZE SCENE at line 1 was already closed by the ENDSCENE at line 3",
        ),
        ("X = 1\nENDREACH\n", 2, "ENDREACH", "ENDREACH without STARTREACH", "no STARTREACH is open here"),
        (
            "ENDMOTION { a comment }\n\nX = 1\n",
            1,
            "ENDMOTION",
            "ENDMOTION without STARTMOTION",
            "no STARTMOTION is open here",
        ),
        (
            "STARTMODEL M\nENDMOTION\n",
            2,
            "ENDMOTION",
            "ENDMOTION without STARTMOTION",
            "no STARTMOTION is open here; the STARTMODEL opened at line 1 is closed by ENDMODEL",
        ),
        (
            "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 3\nENDMOTION\nENDSCENE\n",
            3,
            "ENDMOTION",
            "ENDMOTION without STARTMOTION",
            "no STARTMOTION is open here; the INITIALIZE SCENE opened at line 1 is closed by ENDSCENE",
        ),
        ("IF 1 > 0 THEN ENDMODEL\n", 1, "ENDMODEL", "ENDMODEL without STARTMODEL", "no STARTMODEL is open here"),
        (
            "X = 1\n  CONTINUE\n",
            2,
            "CONTINUE",
            "CONTINUE needs the label of the DO loop it closes",
            "write the loop as DO 10 I = 1, 5 ... 10 CONTINUE",
        ),
    ],
)
def test_every_stray_closing_word_is_reported_at_its_own_place(program, line, word, message, hint):
    d = syntax_error(program)
    text_line = program.split("\n")[line - 1]
    assert (d.pos.line, d.pos.column) == (line, text_line.index(word) + 1)
    assert d.pos.end_column - d.pos.column == len(word)
    assert (d.message, d.hint) == (message, hint)


def test_a_continue_whose_loop_is_closed_says_where():
    from liganimate.compiler import compile_text

    with pytest.raises(LigDiagnostics) as info:
        compile_text("DO 10 I = 1, 3\n  X = I\n10 CONTINUE\n10 CONTINUE\n", "t.lig")
    d = info.value.diagnostics[0]
    assert (d.pos.line, d.pos.column) == (4, 1)
    assert d.hint == "the DO 10 at line 1 was already closed by the 10 CONTINUE at line 3"


def test_end_inside_an_open_scene_names_the_scene():
    d = syntax_error("INITIALIZE SCENE 1\nSTARTSCENE LENGTH 3\nEND\n")
    assert (d.pos.line, d.pos.column) == (3, 1)
    assert d.hint == "the INITIALIZE SCENE opened at line 1 is not closed; add ENDSCENE"


def test_a_variable_called_like_a_closing_word_is_still_a_variable():
    from liganimate.lang import ast as A

    *_, assign = parse(MOTION + "ENDMOTION = 1\n").body
    assert isinstance(assign, A.Assign) and assign.target.name == "ENDMOTION"
    *_, key = parse(MOTION + "ENDJOINT[1, 2] = FRAME 3 POSITION 0\n").body
    assert isinstance(key, A.KeyframeAssign) and key.target.name == "ENDJOINT"


def test_a_closing_word_assigned_after_an_expression_is_refused_as_a_name():
    # After an expression the lexer takes ENDMOTION for the keyword (it may end a motion there).
    d = syntax_error("X = 1\nENDMOTION = 2\n")
    assert (d.pos.line, d.pos.column) == (2, 1)
    assert d.message == "ENDMOTION cannot be a variable name here, after an expression"
    assert d.hint == "choose another name, or start the statement with another one"


def test_stray_endmotion_via_the_cli(tmp_path):
    status, err = check_cli(tmp_path, MOTION + "ENDMOTION\nX = 1\n")
    assert status == 1
    assert err.splitlines() == [
        "t.lig:6:1: error: ENDMOTION without STARTMOTION",
        "    ENDMOTION",
        "    ^~~~~~~~~",
        "  hint: the STARTMOTION at line 1 was already closed by the ENDMOTION at line 5",
    ]


# ------------------------------------------------------- 5. plain sentences


INTERNAL = ("__", "$END", "_KW", "ANON", "Token(", "\n")


def test_every_terminal_of_the_grammar_has_a_plain_name():
    names = [t.name for t in grammar().terminals] + ["$END", "PRIM_NAME"]
    assert "__ANON_0" in names  # "::=": the grammar does have anonymous terminals
    for name in names:
        text = _terminal_text(name)
        assert text and not any(bad in text for bad in INTERNAL), (name, text)
        if name.isalpha() and name not in _FRIENDLY:
            assert text == name, (name, text)  # a keyword is named as it is written
    described = _describe_expected(set(names))
    assert not any(bad in described for bad in INTERNAL)
    for name in names:
        assert not any(bad in _describe_expected({name, "COMMA"}) for bad in INTERNAL), name


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(example, mutations)
def test_syntax_errors_of_mutated_programs_are_one_plain_sentence(index, steps):
    name, text = mutated(index, steps)
    try:
        parse(text, name)
    except LigDiagnostics as exc:
        for d in exc.diagnostics:
            assert not any(bad in d.message for bad in INTERNAL), d.message
            assert not any(bad in (d.hint or "") for bad in INTERNAL), d.hint
            out = format_diagnostic(d).split("\n")
            assert out[0].startswith(f"{name}:{d.pos.line}:{d.pos.column}: error: ")
            assert len(out) >= 3 and "^" in out[2], out


def test_a_syntax_error_via_the_cli_names_no_internal_terminal(tmp_path):
    # Inside a PRIMITIVE its name may start a pattern (P ::= ...), an anonymous terminal.
    status, err = check_cli(tmp_path, "PRIMITIVE P\n  P X\nEND\n")
    assert status == 1
    assert err.splitlines()[0] == "t.lig:2:5: error: unexpected name X; expected '::='"
