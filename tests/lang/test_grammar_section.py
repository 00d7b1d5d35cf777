"""lig.lark's statements are written from the productions declared beside their nodes (lang/grammar.py).

* The shipped grammar's section is the one the declarations give today.
* A statement declared only in the way docs/architecture.md's checklist says
  (a node with its production) reaches the grammar, gets its keywords, and
  parses into its node: no edit of lig.lark is needed.
"""

from __future__ import annotations

import os

import pytest
from paths import ROOT_DIR

from liganimate.lang import ast as A
from liganimate.lang import grammar, tables
from liganimate.lang import syntax as R
from liganimate.lang.lalr import Driver
from liganimate.lang.lexer import TablesOnly
from liganimate.lang.node_methods import node
from liganimate.lang.parser import BUILTIN_PRIMITIVES
from liganimate.lang.transform import ToAst, _syntax_rule

LARK = os.path.join(ROOT_DIR, "lang", "lig.lark")


def _shipped() -> str:
    with open(LARK, encoding="utf-8") as fh:
        return fh.read()


def test_the_shipped_statements_are_the_ones_the_declarations_give():
    assert _shipped() == grammar.fresh_text(_shipped()), "run: python -m liganimate.lang.tables"


def test_every_statement_of_the_grammar_is_declared_beside_its_node():
    # A test of the test above: the section holds the statements, so a
    # statement removed from lang/ast.py leaves lig.lark.
    _, section, _ = grammar._split(_shipped())
    assert len(R.STATEMENTS) >= 23
    for rule in R.STATEMENTS:
        assert f"\n          | {rule}\n" in section + "\n" or f"?statement: {rule}\n" in section, rule
        assert f"\n{rule}:" in section, rule
        assert R.SYNTAX[rule].cls is not None, rule
    assert "figure_stmt:     FIGURE NAME MAIN (LINK NAME | JOINT expr)?" in section


@pytest.fixture
def registries(monkeypatch):
    """The declaration registries, restored after the test declares a statement of its own."""
    monkeypatch.setattr(R, "PRODUCTIONS", dict(R.PRODUCTIONS))
    monkeypatch.setattr(R, "STATEMENTS", list(R.STATEMENTS))
    monkeypatch.setattr(R, "SYNTAX", dict(R.SYNTAX))
    monkeypatch.setattr(A, "SYNTAX", R.SYNTAX)


def test_a_statement_declared_with_its_node_reaches_the_grammar_and_parses(registries):
    # WAVE is no word of the language; FROM and TO are hand-written terminals already.
    @A.syntax("wave_stmt", statement="WAVE NAME FROM expr TO expr TIMES expr", model=R.token("NAME", A.AS_NAME))
    @node
    class Wave(A.Node):
        model: A.Name
        start: A.Node
        end: A.Node
        times: A.Node

    text = grammar.fresh_text(_shipped())
    _, section, _ = grammar._split(text)
    assert "          | wave_stmt\n" in section
    assert "wave_stmt:" in section and "WAVE NAME FROM expr TO expr TIMES expr" in section
    # The new words become case-insensitive keywords; the grammar's own are not written twice.
    assert 'WAVE: "WAVE"i' in section and 'TIMES: "TIMES"i' in section
    assert 'FROM: "FROM"i' not in section and "\nFROM" not in section

    class Transformer(ToAst):
        pass

    Transformer.wave_stmt = _syntax_rule(R.SYNTAX["wave_stmt"])  # type: ignore[attr-defined]
    transformer = Transformer()
    parser = Driver(tables.from_lark(tables.build(TablesOnly, None, transformer, text)), transformer)
    body = parser.parse("MODEL M\nwave m from 1 to 2 * 3 times 4\nX = 1\n", BUILTIN_PRIMITIVES)
    wave = body[1]
    assert type(wave) is Wave and wave.model.name == "M" and wave.times.value == 4
    assert isinstance(wave.end, A.BinOp) and (wave.pos.line, wave.pos.column) == (2, 1)
    # The shipped grammar does not know it.
    assert "wave_stmt" not in _shipped()


def test_a_grammar_without_its_markers_is_refused_with_a_sentence():
    with pytest.raises(ValueError, match="no generated section"):
        grammar.fresh_text("start: statement\n")


def test_fields_read_by_position_are_the_ones_the_generic_readers_find(monkeypatch):
    # A production of fixed shape (NAME ASSIGN_OP rhs) is read by position
    # (lang/transform.py); the generic readers, which search the children,
    # are the definition. Both transformers must build the same trees.
    from liganimate.lang import parser as P
    from liganimate.lang import transform

    fixed = [
        rule
        for rule, sx in R.SYNTAX.items()
        if sx.cls is not None
        and sx.pos is None
        and (shape := transform._fixed_shape(R.PRODUCTIONS.get(rule))) is not None
        and transform._positional(sx.readers, shape) is not None
    ]
    assert {"assignment", "continue_stmt", "view_point", "shoot_range", "stop_stmt"} <= set(fixed)

    class Generic(ToAst):
        pass

    for rule in fixed:
        sx = R.SYNTAX[rule]
        setattr(Generic, rule, transform._node_rule(sx.cls, sx.readers, sx.pos))
    generic = Driver(P.grammar(), Generic())
    texts = [
        "X = 1\nY := X + 2 * 3\nV :- (1, 2, 3)\nVIEW POINT = (1, 2, 3)\nVIEW WIDTH = 7.5\n"
        "SHOOTSCENES FROM 1 TO 2 + 1\nSHOOTSCENES\nDO 10 I = 1, 3\nJ = I\n10 CONTINUE\nSTOP\nEND\n"
    ]
    for name in sorted(os.listdir(os.path.join(ROOT_DIR, "examples"))):
        if name.endswith(".lig"):
            with open(os.path.join(ROOT_DIR, "examples", name), encoding="utf-8") as fh:
                texts.append(fh.read())
    shipped = [P.parse(text) for text in texts]
    monkeypatch.setattr(P, "driver", lambda: generic)
    assert [P.parse(text) for text in texts] == shipped
    assert len(texts) > 10 and sum(len(program.body) for program in shipped) > 200
