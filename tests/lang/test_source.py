"""lang/source.py's spelling: a construct's text as the program wrote it, for PRINT labels."""

from liganimate.lang.ast import Pos
from liganimate.lang.source import prepare, spelling


def at(text: str, piece: str) -> Pos:
    """A position whose offsets cover the first ``piece`` in ``text`` (lines and columns do not matter here)."""
    start = text.index(piece)
    return Pos(1, 1, 1, 2, start, start + len(piece))


def test_the_spelling_is_the_text_between_the_offsets_upper_cased():
    text = "PRINT (a + b) * 2, c\n"
    assert spelling(text, at(text, "(a + b) * 2")) == "(A + B) * 2"


def test_line_breaks_and_comments_become_one_space():
    text = "PRINT a +  {half of it}  b\n   + c *\n\n      d\n"
    assert spelling(text, at(text, "a +  {half of it}  b\n   + c *\n\n      d")) == "A + B + C * D"


def test_comment_lines_and_flags_inside_are_dropped_as_the_lexer_drops_them():
    text = "PRINT a +\nC a remark, not the variable C\n* b\n"
    assert spelling(text, at(text, "a +\nC a remark, not the variable C\n* b")) == "A + B"


def test_a_variable_c_that_ends_a_line_is_not_a_comment():
    # The rule reads whole lines: "C, 3" is not a comment line, though the
    # item ends at its C.
    text = "PRINT a +\nC, 3\n"
    assert spelling(text, at(text, "a +\nC")) == "A + C"


def test_a_synthetic_or_impossible_position_spells_nothing():
    text = "PRINT a\n"
    assert spelling(text, Pos(1, 7, 1, 8)) == ""
    assert spelling(text, Pos(1, 7, 1, 8, 6, 100)) == ""
    assert spelling(text, Pos(1, 7, 1, 8, 7, 6)) == ""


def test_prepare_keeps_every_offset():
    text = "C a comment line\n*X = 1\nc\r\nY = 2\n"
    lexed = prepare(text, "t.lig").lexed
    assert len(lexed) == len(text)
    assert [i for i, ch in enumerate(lexed) if ch == "\n"] == [i for i, ch in enumerate(text) if ch == "\n"]
    assert lexed.index("X = 1") == text.index("X = 1") and lexed.index("Y = 2") == text.index("Y = 2")


def test_a_long_run_of_blanks_is_joined_whole():
    # Runs are matched whole (possessively): a pattern that backtracked
    # would take time quadratic in the run; this one is linear.
    text = "PRINT a +" + " " * 200_000 + "b,\n  c +" + " \n" * 50_000 + "d\n"
    assert spelling(text, at(text, "a +" + " " * 200_000 + "b")) == "A +" + " " * 200_000 + "B"
    assert spelling(text, at(text, "c +" + " \n" * 50_000 + "d")) == "C + D"
