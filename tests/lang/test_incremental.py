"""lang/incremental.py: parsing a text again after an edit gives what parsing it whole gives.

Property tests: a real program (every example and standard library) is
edited step after step, as an editor would send it (mutations of
benchmarks/fuzz_compile.py: lines deleted, duplicated or swapped, characters
inserted or deleted, tokens replaced, the text cut short), and after each
step the tree one Reparser gives, positions included, or its syntax error,
must be the whole parse's. Broken text is kept as the base of the next step
too, so that edits of a text that does not parse, and edits that repair it,
are covered.
"""

from __future__ import annotations

import re
import sys

from fuzzgen import corpus
from hypothesis import given, settings
from hypothesis import strategies as st
from mutations import fuzz, mutation
from paths import ROOT_DIR

from liganimate.lang import ast as A
from liganimate.lang import parser
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.source import prepare

sys.path.insert(0, f"{ROOT_DIR}/benchmarks")
from compile import thesis_style_program  # noqa: E402 - found through the line above

PROGRAMS = [(name, "\n".join(lines)) for name, lines in corpus()]


def outcome(text: str, reparser=None, name: str = "t.lig"):
    """The program's statements, or its diagnostics as (message, position, hint, notes)."""
    try:
        return ("ok", parser.parse_source(prepare(text, name), reparser=reparser).body)
    except LigDiagnostics as exc:
        return ("error", [(d.message, d.pos, d.hint, tuple(d.notes)) for d in exc.diagnostics])


def test_the_corpus_is_there():
    assert len(PROGRAMS) >= 15
    assert any(outcome(text)[0] == "ok" for _, text in PROGRAMS)


@settings(max_examples=150, deadline=None)
@given(st.integers(0, len(PROGRAMS) - 1), st.lists(mutation, min_size=1, max_size=6))
def test_each_edit_parses_as_the_whole_text_does(index, steps):
    name, text = PROGRAMS[index]
    reparser = parser.reparser()
    assert outcome(text, reparser, name) == outcome(text, None, name)
    for kind, u, v, pick in steps:
        text = fuzz.mutate(text, kind, u, v, pick)
        assert outcome(text, reparser, name) == outcome(text, None, name), (kind, u, v, pick)


def _edit(text: str, at: float, insert: str, delete: int = 0) -> str:
    i = int(len(text) * at)
    return text[:i] + insert + text[i + delete :]


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0, 1, exclude_max=True),
            st.sampled_from(
                ["", "1", "\n", " X = 1\n", "ENDMODEL", "STARTMODEL M\n", "{", "}", "'", "(", ";", "END\n"]
            ),
            st.integers(0, 30),
        ),
        min_size=1,
        max_size=8,
    )
)
def test_random_keystrokes_in_a_big_program_parse_as_the_whole_text_does(edits):
    text = thesis_style_program(400)
    reparser = parser.reparser()
    outcome(text, reparser)
    for at, insert, delete in edits:
        text = _edit(text, at, insert, delete)
        assert outcome(text, reparser) == outcome(text)


BIG = thesis_style_program(3000)


def _in_motion_block(text: str) -> int:
    """An offset in the middle of a STARTMOTION block past the middle of the text."""
    start = text.index("STARTMOTION", len(text) // 2)
    return text.index("\n", text.index("JOINT", start)) + 1


def test_broken_text_in_the_middle_of_a_block_reports_the_whole_parse_s_error():
    reparser = parser.reparser()
    assert outcome(BIG, reparser)[0] == "ok"
    at = _in_motion_block(BIG)
    for broken in (
        "      JOINT 3 (\n",
        "      FRAME 4 POSITION\n",
        "      ENDMODEL\n",
        "   {never closed\n",
        "  X = \n",
    ):
        text = BIG[:at] + broken + BIG[at:]
        got = outcome(text, reparser)
        assert got[0] == "error"
        assert got == outcome(text)
        # and repairing it again gives the program's tree again
        assert outcome(BIG, reparser) == outcome(BIG)


def test_an_edit_reparses_only_the_text_around_it():
    reparser = parser.reparser()
    outcome(BIG, reparser)
    assert reparser.reused == 0
    text = BIG
    for at in (0.1, 0.5, 0.9):
        digit = re.compile(r"(?<![A-Za-z0-9_])\d").search(text, int(len(text) * at))
        assert digit is not None
        line_start = text.rindex("\n", 0, digit.start()) + 1
        # a digit added (every later offset moves) and a line added (every later line moves)
        for where, insert in ((digit.start(), "7"), (line_start, "\n")):
            text = text[:where] + insert + text[where:]
            got = outcome(text, reparser)
            assert got == outcome(text)
            assert reparser.reused > 0.97 * len(text), (at, insert, reparser.reused)


def test_positions_after_the_change_are_moved_to_the_new_text():
    reparser = parser.reparser()
    outcome(BIG, reparser)
    middle = BIG.index("\n", len(BIG) // 2) + 1
    text = BIG[:middle] + "      {a comment\n      of two lines}\n" + BIG[middle:]
    kind, body = outcome(text, reparser)
    assert kind == "ok" and reparser.reused > 0.9 * len(text)
    last = body[-2]
    assert isinstance(last, A.Node)
    assert text[last.pos.start : last.pos.end].upper().startswith(("STOP", "SHOOTSCENES"))
    assert last.pos.line == text[: last.pos.start].count("\n") + 1


def test_a_change_of_the_primitives_parses_the_whole_text():
    reparser = parser.reparser()
    base = "PRIMITIVE P\nREAL W\nP ::= 'P' 'WIDTH' W;\nRETURN\nEND\nX = 1\nY = 2\nZ = 3\n"
    assert outcome(base, reparser)[0] == "ok"
    renamed = base.replace("PRIMITIVE P\n", "PRIMITIVE Q\n").replace("P ::= 'P'", "Q ::= 'Q'")
    assert outcome(renamed, reparser) == outcome(renamed)
    assert reparser.reused == 0


def test_a_change_just_after_a_statement_s_first_word_is_lexed_as_the_whole_parse_does():
    # MOTION is a type before a name and a variable before "=": the word is decided by what follows it.
    reparser = parser.reparser()
    base = "X = 1\nY = 2\nMOTION M\nZ = 3\n"
    assert outcome(base, reparser)[0] == "ok"
    for text in ("X = 1\nY = 2\nMOTION =M\nZ = 3\n", "X = 1\nY = 2\nMOTION= M\nZ = 3\n", base):
        assert outcome(text, reparser) == outcome(text)


def test_an_edit_of_the_first_statement_reparses_it_and_takes_the_rest_from_the_last_parse():
    reparser = parser.reparser()
    outcome(BIG, reparser)
    at = BIG.index("LIGHT2 = LIGHT * 1.5") + len("LIGHT2 = LIGHT * 1.")  # inside the PRIMITIVE BOX that opens it
    text = BIG[:at] + "7" + BIG[at:]
    assert outcome(text, reparser) == outcome(text)
    assert reparser.reused > 0.9 * len(text)
