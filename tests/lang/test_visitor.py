"""lang/visitor.py: dispatch by node type, generic children for the types a pass does not handle."""

from __future__ import annotations

import pytest

from liganimate.lang.parser import parse
from liganimate.lang.visitor import NodeVisitor, children, too_deep


class Names(NodeVisitor):
    """Collects variable names, handling only Var: every other node is walked through."""

    def __init__(self):
        self.seen = []

    def v_Var(self, node):
        self.seen.append(node.name)


def test_a_pass_handles_its_types_and_walks_through_the_rest():
    body = parse("IF A > 1 THEN X = B + C * D ELSE Y = SIN(E)\n").body
    names = Names()
    for stmt in body:
        names.dispatch("v_", stmt)(stmt)
    assert names.seen == ["A", "B", "C", "D", "E"]


def test_a_pass_that_must_produce_a_value_refuses_a_type_it_does_not_handle():
    (stmt,) = parse("X = 1\n").body
    with pytest.raises(NotImplementedError, match="Names has no v_Assign"):
        Names().dispatch("v_", stmt, generic=False)


def test_methods_are_found_once_per_type():
    names = Names()
    (stmt,) = parse("X = A + B\n").body
    names.dispatch("v_", stmt)(stmt)
    assert names.dispatch("v_", stmt.value.left) is names.dispatch("v_", stmt.value.right)


def test_children_go_through_lists_in_source_order():
    (stmt,) = parse("X = SIN(A) + B\n").body
    assert [type(c).__name__ for c in children(stmt)] == ["Name", "BinOp"]
    assert [c.name for c in children(stmt.value.left)] == ["A"]


def test_too_deep_finds_the_first_node_past_the_limit_from_the_last_root_backwards():
    body = parse("X = -(-(A))\nY = -(B)\n").body
    # Y = -(B): Assign 1, Neg 2, B 3. X = -(-(A)): A is on level 4.
    assert too_deep(body, 4) is None
    assert too_deep(body, 3).name == "A"
    assert too_deep(body, 2).name == "B"
    assert type(too_deep(body, 1)).__name__ == "Neg"
