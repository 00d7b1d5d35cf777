"""lang/structure.py: the nesting limits, checked by iterative walks, point at the same place every time."""

from __future__ import annotations

import pytest

from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.parser import parse


def refused(text: str):
    with pytest.raises(LigDiagnostics) as info:
        parse(text)
    (d,) = info.value.diagnostics
    return d


def negations(n: int, name: str = "A") -> str:
    return "-(" * n + name + ")" * n


def test_a_name_one_level_past_the_limit_is_refused_and_pointed_at():
    # The assignment is level 1, 98 negations levels 2 to 99, the name A level 100.
    parse("      X = " + negations(98) + "\n")
    d = refused("      X = " + negations(99) + "\n")
    assert d.message == "this is nested more than 100 levels deep"
    assert d.hint == "split it into several statements with variables in between"
    # Level 101 is the name A itself, a leaf: leaves count too.
    assert (d.pos.line, d.pos.column) == (1, len("      X = " + "-(" * 99) + 1)


def test_of_two_branches_too_deep_the_last_is_pointed_at():
    left = negations(120, "A")
    d = refused("      X = " + left + " + " + negations(120, "B") + "\n")
    # The walk goes from the last child backwards: the first place found past the limit is in B's branch.
    assert d.pos.column > len("      X = " + left + " + ")


def ifs(n: int) -> str:
    return "      IF A > 1 THEN BEGIN\n" * n + "      X = 1\n" + "      END\n" * n


def test_blocks_nested_past_the_limit_point_at_the_first_block_too_many():
    parse(ifs(15))
    d = refused(ifs(16))
    assert d.message == "blocks (DO, IF, scenes) are nested more than 15 deep here"
    assert (d.pos.line, d.pos.column) == (16, 7)


def test_of_two_block_nests_too_deep_the_last_is_pointed_at():
    d = refused(ifs(17) + ifs(17))
    # The second nest starts on line 36; its 16th IF is on line 51.
    assert (d.pos.line, d.pos.column) == (51, 7)


def test_do_loops_inside_if_else_and_scenes_are_grouped():
    text = (
        "      INTEGER I\n"
        "      IF I = 1 THEN BEGIN\n"
        "      DO 10 I = 1, 2\n"
        "      X = 1\n"
        " 10   CONTINUE\n"
        "      END ELSE BEGIN\n"
        "      DO 20 I = 1, 2\n"
        "      X = 2\n"
        " 20   CONTINUE\n"
        "      END\n"
    )
    (_, stmt) = parse(text).body
    assert [type(s).__name__ for s in stmt.then] == ["Do"]
    assert [type(s).__name__ for s in stmt.orelse] == ["Do"]
    assert stmt.orelse[0].label == 20
