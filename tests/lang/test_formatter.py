"""``liganimate fmt`` (lang/formatter.py): one layout, idempotent, never a change of meaning.

Properties, on every example, the standard library (the thesis' programs
among them: Appendix A, the clock, its fragments) and fuzzed programs
(tests/fuzzgen.py): formatting twice gives what formatting once gives; the
formatted program is the same program: the same syntax tree, positions
aside, the same PRINT labels, the same checked program and the same lowered
module except its table of positions; every comment is kept, word for
word and in order. Then the layout's own rules, each on a small program.
"""

from __future__ import annotations

import glob
import os
import random
import re

import fuzzgen
import fuzzrun
import pytest
from hypothesis import assume

from liganimate.compiler import compile_source, loaded_primitive_names
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.formatter import BLANK, _gaps, format_source, format_text, meaning
from liganimate.lang.parser import parse_source
from liganimate.lang.source import load, prepare

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORPUS = sorted(glob.glob(os.path.join(ROOT, "examples", "*.lig")) + glob.glob(os.path.join(ROOT, "stdlib", "*.lig")))
# One line of the lowered module's table of positions: (line, column, end line, end column).
_POSITION_ROW = re.compile(r"^\s*\(\d+, \d+, \d+, \d+\),$", re.MULTILINE)
# The source text the module keeps for its messages (the only other place the layout shows).
_SOURCE_TEXT = re.compile(r"^(program = _host\.Program\(.*?, _main, )['\"].*$", re.MULTILINE)


def _comments(source) -> list:
    tokens: list = []
    parse_source(source, loaded_primitive_names(source, source.filename), tokens)
    return [c.text for gap in _gaps(source.text, source.lexed, tokens) for c in gap if c is not BLANK]


def _lowered(text: str, path: str) -> tuple:
    """The checked program (positions aside) and the lowered module without its positions."""
    compiled = compile_source(prepare(text, path), module_name="m", path=path)
    python = _SOURCE_TEXT.sub(r"\1", _POSITION_ROW.sub("", compiled.python))
    assert "_main" in python and "(1, " not in python.split("_AT = ")[-1][:20]
    return meaning(compiled.checked.program, text), python


def assert_same_program(before: str, after: str, path: str, checks: bool = True) -> None:
    """``after`` is ``before`` laid out again: idempotent, same meaning, same comments."""
    src_before, src_after = prepare(before, path), prepare(after, path)
    names = loaded_primitive_names(src_before, path)
    assert format_source(src_after, names) == after, "formatting is not idempotent"
    assert meaning(parse_source(src_before, names), before) == meaning(parse_source(src_after, names), after)
    assert _comments(src_before) == _comments(src_after)
    if checks:
        assert _lowered(before, path) == _lowered(after, path)


@pytest.mark.parametrize("path", CORPUS, ids=os.path.basename)
def test_every_example_and_library_keeps_its_meaning_and_is_a_fixed_point(path):
    source = load(path)
    after = format_source(source, loaded_primitive_names(source, path))
    assert_same_program(source.text, after, path)


def test_the_examples_and_the_standard_library_are_formatted():
    # CI's `liganimate fmt --check examples stdlib`, as a test.
    from liganimate.cli import main

    assert main(["fmt", "--check", "--quiet", os.path.join(ROOT, "examples"), os.path.join(ROOT, "stdlib")]) == 0


def _fuzzed(generator, rng, path) -> None:
    text = generator(rng)
    try:
        source = prepare(text, path)
        after = format_source(source, loaded_primitive_names(source, path))
    except LigDiagnostics:
        assume(False)  # a program that does not parse is not formatted
        return
    try:
        compile_source(prepare(text, path), module_name="m", path=path)
        checks = True
    except LigDiagnostics:
        checks = False  # it parses but fails a check: the syntax trees are still compared
    assert_same_program(text, after, path, checks)


@pytest.fixture
def fuzz_path():
    return os.path.join(ROOT, "examples", "fuzzed.lig")  # LOADs resolve as an example's do


@fuzzrun.seeded_programs(150)
def test_grammar_programs_keep_their_meaning(rng):
    _fuzzed(fuzzgen.grammar_program, rng, os.path.join(ROOT, "examples", "fuzzed.lig"))


@pytest.mark.parametrize("generator", [fuzzgen.splice_program, fuzzgen.number_program, fuzzgen.wild_program])
def test_spliced_and_extreme_programs_keep_their_meaning(generator, fuzz_path):
    formatted = 0
    for seed in range(80):
        text = generator(random.Random(seed))
        try:
            source = prepare(text, fuzz_path)
            after = format_source(source, loaded_primitive_names(source, fuzz_path))
        except LigDiagnostics:
            continue
        formatted += 1
        try:
            compile_source(prepare(text, fuzz_path), module_name="m", path=fuzz_path)
            checks = True
        except LigDiagnostics:
            checks = False
        assert_same_program(text, after, fuzz_path, checks)
    assert formatted >= 10, formatted


def test_most_fuzzed_programs_are_formatted(fuzz_path):
    done = 0
    for seed in range(60):
        try:
            format_text(fuzzgen.grammar_program(random.Random(seed)), fuzz_path)
            done += 1
        except LigDiagnostics:
            pass
    assert done >= 45, done


# ------------------------------------------------------------ the layout's rules


def test_blocks_are_indented_keywords_capitalised_and_operators_spaced():
    text = (
        "real x;x=1+2*-3\nstartmodel m joint 1,a,(0,0,0),b,(0,1,0),(0,0),(0,0),(0,90) endmodel\n"
        "initialize scene 1 view width=4 startscene length 2 x=sin(x)/2 endscene shootscenes\n"
    )
    assert format_text(text) == (
        "REAL x\n"
        "x = 1 + 2 * -3\n"
        "STARTMODEL m\n"
        "  JOINT 1, a, (0, 0, 0), b, (0, 1, 0), (0, 0), (0, 0), (0, 90)\n"
        "ENDMODEL\n"
        "INITIALIZE SCENE 1\n"
        "  VIEW WIDTH = 4\n"
        "STARTSCENE LENGTH 2\n"
        "  x = sin(x) / 2\n"
        "ENDSCENE\n"
        "SHOOTSCENES\n"
    )


def test_a_motion_indents_its_joints_and_their_keyframes():
    text = "STARTMOTION M JOINT 1 POSITION 0,0,0 FRAME 5 POSITION 0,0,90 INTERPOLATE LINEAR ENDJOINT ENDMOTION\n"
    assert format_text(text) == (
        "STARTMOTION M\n"
        "  JOINT 1 POSITION 0, 0, 0\n"
        "    FRAME 5 POSITION 0, 0, 90 INTERPOLATE LINEAR\n"
        "  ENDJOINT\n"
        "ENDMOTION\n"
    )


def test_a_long_joint_is_wrapped_as_the_thesis_lays_it_out():
    text = "ARM :- JOINT 1, UPPER_ARM_SEGMENT, (0.0, -0.24, 0.0), FOREARM_SEGMENT, (0.0, 0.24, 0.0), (0.0, 0.0), (0.0, 0.0), (0.0, 135.0)\n"
    assert format_text(text) == (
        "ARM :- JOINT 1, UPPER_ARM_SEGMENT, (0.0, -0.24, 0.0),\n"
        "                FOREARM_SEGMENT, (0.0, 0.24, 0.0),\n"
        "                (0.0, 0.0), (0.0, 0.0), (0.0, 135.0)\n"
    )


def test_do_loops_if_blocks_and_words_that_are_names_here():
    text = "DO 10 I=1,3\nIF I>1 THEN BEGIN\nwidth=I\nEND ELSE width=0\n10 CONTINUE\n"
    assert format_text(text) == (
        "DO 10 I = 1, 3\n  IF I > 1 THEN BEGIN\n    width = I\n  END ELSE width = 0\n10 CONTINUE\n"
    )


def test_every_comment_stays_where_it_was():
    text = "{ head }\n\n\nX = 1 { after X }\n  { own line }\nY = (1,\n{ inside }\n 2)\nZ = 3 ; { after the ; }\n"
    out = format_text(text)
    assert out == (
        "{ head }\n\nX = 1 { after X }\n{ own line }\nY = (1,\n    { inside }\n    2)\nZ = 3 { after the ; }\n"
    )
    assert format_text(out) == out


def test_a_comment_before_a_semicolon_is_laid_out_as_once_the_semicolon_is_gone():
    # A long statement's trailing comment before ";" took part in where the line broke;
    # once the ";" was gone it did not, so a second pass broke the line elsewhere
    # (a fuzzed program found it). The comment is written after the layout, both times.
    text = (
        "       G1 = BOX f 0.25 < TRANS ( 30 , 0.0 , 1e308 ) , TRANS JOINTS BY 180 - 360 , TRANS V1 {a b c d} ,"
        " LIGHTNESS 0.25 * 123456789 * 2.5 > - 1e3 MOD A { a comment } ;\n      X = 1\nc a comment line\n"
    )
    out = format_text(text)
    assert format_text(out) == out
    assert (
        out.split("\n")[1]
        == "              TRANS V1 {a b c d}, LIGHTNESS 0.25 * 123456789 * 2.5> - 1e3 MOD A { a comment }"
    )


def test_the_thesis_listing_convention_is_kept():
    text = "C a comment line\n      REAL A\n*     A = 1\n*     STARTMODEL M\n*       JOINT 1, P, (0,0,0), Q, (0,0,0), (0,0), (0,0), (0,0)\n*     ENDMODEL\n"
    out = format_text(text)
    assert out == (
        "C a comment line\n      REAL A\n*     A = 1\n*     STARTMODEL M\n"
        "*       JOINT 1, P, (0, 0, 0), Q, (0, 0, 0), (0, 0), (0, 0), (0, 0)\n*     ENDMODEL\n"
    )


def test_a_statement_is_never_moved_into_column_one_as_a_c_comment():
    # "C = 1" in column 1 would be a FORTRAN comment line, and the assignment would vanish.
    out = format_text("   C = 1\n   PRINT C\n")
    assert out == " C = 1\nPRINT C\n"
    text = "   C = 1\n   PRINT C\n"
    assert meaning(parse_source(prepare(out, "f")), out) == meaning(parse_source(prepare(text, "f")), text)


def test_print_keeps_its_spacing_because_its_labels_are_the_text():
    out = format_text("X = 2\nprint   x+1 ,  (x , 2)\n")
    assert out == "X = 2\nPRINT x+1, (x , 2)\n" or out == "X = 2\nPRINT x+1 , (x , 2)\n"
    # The label printed is the expression's own spelling, unchanged.
    assert meaning(parse_source(prepare(out, "f")), out) == meaning(
        parse_source(prepare("X = 2\nprint   x+1 ,  (x , 2)\n", "f")), "X = 2\nprint   x+1 ,  (x , 2)\n"
    )


def test_a_program_that_does_not_parse_is_refused_with_its_diagnostic():
    with pytest.raises(LigDiagnostics) as info:
        format_text("X = = 1\n", "bad.lig")
    assert info.value.diagnostics[0].pos.line == 1
