"""The statement checklist of docs/architecture.md: every statement is a production, a declared node and a rule.

A statement's transformer method is made from its node's declaration
(lang/ast.py ``@syntax``), and its check and lowering are one class in
compiler/rules/; these tests hold every statement of the grammar to that,
so that no statement keeps a second way (a hand-written transformer method,
an ``_s_X`` in the checker, an ``s_X`` in the lowering).
"""

from __future__ import annotations

import dataclasses
import pathlib
import re

import pytest
from paths import ROOT_DIR

from liganimate.compiler import compile_text
from liganimate.compiler.lower import Lowerer
from liganimate.compiler.rules import RULES, Rule, rule_for
from liganimate.compiler.statements import StatementChecker
from liganimate.lang import ast as A
from liganimate.lang import bindings, visitor
from liganimate.lang import syntax as R
from liganimate.lang.parser import parse
from liganimate.lang.transform import ToAst

GRAMMAR = (pathlib.Path(ROOT_DIR) / "lang" / "lig.lark").read_text(encoding="utf-8")


def _definition(rule: str) -> list[str]:
    """The alternatives of ``rule`` in lig.lark, as text."""
    # A definition runs on to the next line that starts a definition (comments may stand between).
    body = re.search(rf"^\??{rule}:(.*?)(?=^(?!//)\S|\Z)", GRAMMAR, re.M | re.S)
    assert body, rule
    return re.sub(r"//[^\n]*", "", body.group(1)).split("|")


def _alternatives(rule: str) -> list[str]:
    """The names the alternatives of ``rule`` make: their alias, else the rule's own name."""
    names = []
    for alternative in _definition(rule):
        alias = re.search(r"->\s*(\w+)", alternative)
        names.append(alias.group(1) if alias else rule)
    return names


def _statement_rules() -> list[str]:
    """Every rule or alias that makes a statement: ``?statement``'s alternatives, and the others the parser yields."""
    found = [name for member in _definition("statement") for name in _alternatives(member.strip())]
    return sorted(set(found + ["program_end", "continue_stmt", "primitive_def"]))


STATEMENT_RULES = _statement_rules()


def test_the_grammar_s_statements_are_found():
    # A test of the test: an empty list would pass everything below.
    assert {"assignment", "animate_stmt", "reach_block", "shoot_range", "view_width", "load_stmt"} <= set(
        STATEMENT_RULES
    )
    assert len(STATEMENT_RULES) >= 25


@pytest.mark.parametrize("rule", STATEMENT_RULES)
def test_every_statement_is_made_from_its_node_s_declaration(rule):
    syntax = R.SYNTAX.get(rule)
    assert syntax is not None and syntax.cls is not None, f"{rule} has no @syntax node in lang/ast.py"
    # The transformer's method is the one made from the declaration, not a hand-written one.
    method = ToAst.__dict__[rule]
    assert method.__qualname__.startswith(("_syntax_rule.", "_node_rule.")), method.__qualname__


@pytest.mark.parametrize("rule", STATEMENT_RULES)
def test_every_statement_has_one_rule_with_its_check_and_its_lowering(rule):
    cls = R.SYNTAX[rule].cls
    node = A.Do if cls is A.DoHeader else cls  # lang/structure.py makes the Do the passes see
    if cls is A.Continue:
        return  # it ends a DO: lang/structure.py consumes it
    assert isinstance(rule_for(node), Rule)
    assert not hasattr(StatementChecker, "_s_" + node.__name__) and not hasattr(Lowerer, "s_" + node.__name__)


def test_a_rule_is_found_through_the_node_s_base_class():
    # ShootRange has no rule of its own: the rule of Declared (its base's base) serves it.
    assert A.ShootRange not in RULES and rule_for(A.ShootRange) is RULES[A.Declared]


def test_a_statement_without_a_rule_is_an_error_not_silence():
    @dataclasses.dataclass(slots=True)
    class Unruled(A.Node):
        pass

    with pytest.raises(NotImplementedError, match="Unruled has no rule"):
        rule_for(Unruled)


def test_the_walks_learn_blocks_and_bindings_from_the_declarations():
    assert visitor.BLOCKS == {
        A.Do: ("body",),
        A.If: ("then", "orelse"),
        A.Scene: ("init", "body"),
        A.PrimitiveDef: ("body",),
    }
    (reach,) = parse("STARTREACH R MODEL M FRAME 3 TRANSLATE INTO V GOAL HAND TO (0, 1, 0) ENDREACH\nEND\n").body[:1]
    assert [n.name for n in bindings.assigned(reach)] == ["R", "V"]
    decl, figure = parse("MODEL A, B\nFIGURE A MAIN\nEND\n").body[:2]
    assert [n.name for n in bindings.defined(decl)] == ["A", "B"] and bindings.assigned(decl) == []
    assert [n.name for n in bindings.assigned(figure)] == ["A"] and bindings.assigned(figure, figure=False) == []


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        # R.after: an optional clause; R.which: which keyword; AS_NAME: a name token.
        ("FIGURE M MAIN LINK HEAD", A.FigureStmt),
        # R.flag, R.token and the default R.value for the expressions.
        ("ANIMATE M FROM 1 TO 2 USING W REPEAT", A.Animate),
        # R.rest(until=...), R.after and R.where for the scene's first line.
        ("INITIALIZE SCENE 1\nX = 1\nSTARTSCENE LENGTH 2 SAMEFRAME 1\nY = 2\nENDSCENE", A.Scene),
    ],
)
def test_readers_fill_a_node_s_fields_from_the_grammar_s_children(text, expected):
    (node,) = parse(text + "\nEND\n").body[:1]
    assert type(node) is expected
    if expected is A.FigureStmt:
        assert (node.model.name, node.kind, node.link.name, node.joint) == ("M", "LINK", "HEAD", None)
    elif expected is A.Animate:
        assert node.model.name == "M" and node.repeat is True and node.motion.name == "W"
        assert (node.start.value, node.end.value) == (1, 2)
    else:
        assert [type(s) for s in node.init] == [A.Assign] and [type(s) for s in node.body] == [A.Assign]
        assert node.length.value == 2 and node.sameframe.value == 1
        assert (node.start_pos.line, node.start_pos.column, node.start_pos.end_column) == (1, 1, 19)


def test_a_statement_s_check_and_lowering_come_from_its_rule():
    python = compile_text(
        "GRAPHICAL G, H\nMODEL M\nSTARTMODEL M\nJOINT 1, G, (0,0,0), H, (1,0,0), (0, 90)\nENDMODEL\n"
        "FIGURE M MAIN LINK H\nEND\n"
    ).python
    assert "M = rt.figure(M, 'LINK', 'H', " in python
