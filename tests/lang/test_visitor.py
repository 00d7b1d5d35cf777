"""lang/visitor.py: dispatch by node type, generic children for the types a pass does not handle."""

from __future__ import annotations

import pytest

from liganimate.lang.parser import parse
from liganimate.lang.visitor import NodeVisitor


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
