"""lang/bindings.py: which names statements bind, for the checker and the lowering alike."""

from __future__ import annotations

from liganimate.lang import bindings
from liganimate.lang.parser import parse

PROGRAM = """REAL R
X = 1
IF X > 0 THEN Y = 2 ELSE Z = 3
DO 10 I = 1, 2
  M[1, I] := FRAME I POSITION 0, 0, 0
10 CONTINUE
INITIALIZE SCENE 1
  W = 4
STARTSCENE LENGTH 2
  FIGURE A MAIN
  V = 5
ENDSCENE
"""


def test_assigned_and_defined_walk_ifs_loops_and_scenes_in_source_order():
    body = parse(PROGRAM).body
    names = [n.name for s in body for n in bindings.assigned(s)]
    assert names == ["X", "Y", "Z", "I", "M", "W", "A", "V"]
    defined = [n.name for s in body for n in bindings.defined(s)]
    assert defined == ["R", "X", "Y", "Z", "I", "M", "W", "V"]  # FIGURE gives a value, it defines nothing


def test_plain_name_sees_through_modifiers():
    (stmt,) = parse("B = A <TRANS (1, 2, 3)> <ROT X 30>\n").body
    assert bindings.plain_name(stmt.value) == "A"
    (stmt,) = parse("B = (1, 2, 3)\n").body
    assert bindings.plain_name(stmt.value) is None


def test_walk_is_iterative_and_preorder():
    (stmt,) = parse("X = 1 + 2 * 3\n").body
    kinds = [type(n).__name__ for n in bindings.walk(stmt)]
    assert kinds[:3] == ["Assign", "Name", "BinOp"] and kinds.count("Num") == 3
