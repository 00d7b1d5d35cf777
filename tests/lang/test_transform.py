"""The transformer's spans: the text a node covers, with its parentheses and sign; the caret where it was."""

import dataclasses
from pathlib import Path

import pytest
from paths import ROOT_DIR

from liganimate.compiler import compile_file
from liganimate.lang import ast as A
from liganimate.lang.parser import parse
from liganimate.lang.source import spelling
from liganimate.lang.visitor import children

EXPRESSIONS = (A.Num, A.Var, A.Call, A.Tuple, A.BinOp, A.Neg, A.Modified, A.PrimCall, A.Strip, A.Sync, A.JointExpr)
PROGRAMS = sorted(Path(ROOT_DIR, "examples").glob("*.lig")) + sorted(Path(ROOT_DIR, "stdlib").glob("*.lig"))


def shape(node):
    """A node as its type and fields, positions left out: what a parse means, not where."""
    if isinstance(node, A.Node):
        return (type(node).__name__,) + tuple(
            shape(getattr(node, f.name)) for f in dataclasses.fields(node) if f.name not in ("pos", "op_pos")
        )
    if isinstance(node, list):
        return [shape(x) for x in node]
    return node


def walk(node):
    """Every node under ``node``, itself first."""
    stack = [node]
    while stack:
        n = stack.pop()
        yield n
        stack.extend(children(n))


def only_expression(text: str, primitives=frozenset()):
    """The expression of ``X = text``, parsed alone (``primitives``: the names the program made primitives)."""
    (statement,) = parse(f"X = {text}\n", primitives=primitives).body
    return statement.value


def test_a_parenthesised_expression_keeps_its_caret_and_its_text_takes_the_parentheses():
    text = "X = (A + B) * 2\n"
    (statement,) = parse(text).body
    product = statement.value
    inner = product.left
    assert text[inner.pos.start : inner.pos.end] == "(A + B)"
    assert (inner.pos.column, inner.pos.end_column) == (6, 11)  # the caret underlines A + B, as before
    assert text[product.pos.start : product.pos.end] == "(A + B) * 2"
    assert product.pos.column == 6


def test_a_call_and_a_tuple_end_at_their_closing_parenthesis():
    text = "X = MAX(A, (B)) + (1, 2, 3)\n"
    (statement,) = parse(text).body
    call, tup = statement.value.left, statement.value.right
    assert text[call.pos.start : call.pos.end] == "MAX(A, (B))"
    assert text[tup.pos.start : tup.pos.end] == "(1, 2, 3)"
    assert (tup.pos.column, tup.pos.end_column) == (20, 27)  # the caret: from the first item to the last


def test_a_sign_belongs_to_the_text_not_the_caret():
    text = "X = -(A) + +B\n"
    (statement,) = parse(text).body
    neg, plus = statement.value.left, statement.value.right
    assert text[neg.pos.start : neg.pos.end] == "-(A)" and neg.pos.column == 7
    assert text[plus.pos.start : plus.pos.end] == "+B" and shape(plus) == ("Var", "B")


def test_a_condition_in_parentheses_takes_them():
    text = "IF (X > 1) AND NOT (Y = 2) THEN Z = 1\n"
    (statement,) = parse(text).body
    cond = statement.cond
    assert text[cond.pos.start : cond.pos.end] == "(X > 1) AND NOT (Y = 2)"


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_every_expression_spells_itself(path):
    # Each expression's text, parsed alone, means the same expression: its
    # offsets start and end exactly at its own first and last characters.
    text = path.read_text(encoding="utf-8")
    program = compile_file(str(path)).checked.program  # through the compiler, for the LOADed primitives
    primitives = {node.name for node in walk(program) if isinstance(node, A.PrimCall)}
    seen = 0
    for node in walk(program):
        if isinstance(node, EXPRESSIONS) and not isinstance(node, (A.Strip, A.Sync, A.JointExpr)):
            written = spelling(text, node.pos)
            assert shape(only_expression(written, primitives)) == shape(node), (path.name, written)
            seen += 1
    assert seen > 10
