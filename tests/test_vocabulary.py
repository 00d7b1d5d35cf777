"""The vocabulary tables (lang/vocabulary.py) agree with the grammar and the runtime."""

from __future__ import annotations

import pathlib
import re

import pytest
from paths import ROOT_DIR

from liganimate.lang import vocabulary as V
from liganimate.lang.parser import parse
from liganimate.runtime.host import Runtime

GRAMMAR = (pathlib.Path(ROOT_DIR) / "lang" / "lig.lark").read_text(encoding="utf-8")


def test_every_grammar_modifier_is_in_the_table_and_back():
    in_grammar = set(re.findall(r"->\s*mod_(\w+)", GRAMMAR))
    assert in_grammar == set(V.MODIFIERS)


@pytest.mark.parametrize("kind", sorted(V.MODIFIERS))
def test_every_modifier_has_a_transformer_rule_and_a_runtime_method_per_target(kind):
    spec = V.MODIFIERS[kind]
    # The transformer rule (made from the table) builds this modifier from its grammar alternative.
    arg = "(1, 2, 3)" if V.VECTOR in spec.accepts else "2"
    words = f"{spec.label} X {arg}" if spec.axis else f"{spec.label} {arg}"
    (stmt,) = parse(f"H = G <{words}>\n").body
    (modifier,) = stmt.value.modifiers
    assert (modifier.kind, modifier.axis) == (kind, "X" if spec.axis else None)
    assert spec.targets and set(spec.targets) <= set(V.TYPES)
    for target, method in spec.methods.items():
        assert callable(getattr(Runtime, method, None)), method
        assert method == f"{target.lower()}_{kind}"  # the house naming, so a reader can guess it


@pytest.mark.parametrize("name", sorted(V.FUNCTIONS))
def test_every_builtin_function_is_implemented(name):
    spec = V.FUNCTIONS[name]
    assert callable(getattr(Runtime, spec.runtime, None))
    assert all(p and set(p) <= set(V.TYPES) for p in spec.params)


def test_no_runtime_function_is_missing_from_the_table():
    implemented = {n for n in dir(Runtime) if n.startswith("f_") and n[2:].isupper()}
    assert implemented == {f.runtime for f in V.FUNCTIONS.values()}


def test_block_words_are_the_grammars_keywords():
    for block in V.BLOCKS:
        for word in (block.opener, block.closer):
            assert re.search(rf'"{word}"i?|\b{word}\b', GRAMMAR), word


def test_a_modifier_on_the_wrong_type_is_worded_from_the_table():
    from liganimate.compiler import compile_text
    from liganimate.lang.diagnostics import LigDiagnostics

    with pytest.raises(LigDiagnostics) as info:
        compile_text("MOTION M\nX = 1\nY = X <SCALE FRAMES 2>\n")
    assert "SCALE FRAMES applies to motions; this is an INTEGER" in str(info.value)


def _binary_productions() -> dict:
    """Grammar alias -> operator as written, for the left-recursive arithmetic productions."""
    terminals = dict(re.findall(r'^(\w+)(?:\.\d+)?:\s*"([^"]+)"i?\s*$', GRAMMAR, flags=re.M))
    found = {}
    for token, alias in re.findall(r"\|\s*c?(?:sum|product)\s+(\S+)\s+c?\w+\s+->\s*(\w+)", GRAMMAR):
        found[alias] = token.strip('"') if token.startswith('"') else terminals[token]
    return found


def test_every_grammar_operator_is_in_the_table_and_back():
    grammar = _binary_productions()
    assert set(grammar) == {"add", "sub", "mul", "div", "mod"}  # a test of the pattern above
    assert grammar == {o.rule: o.symbol for o in V.OPERATORS}


@pytest.mark.parametrize("row", V.OPERATORS, ids=lambda o: f"{o.left[0]}{o.symbol}{o.right[0]}")
def test_every_operator_row_has_a_transformer_rule_and_its_runtime_method(row):
    # The transformer rule (made from the table) builds this operator from its grammar production.
    (stmt,) = parse(f"X = A {row.symbol} B\n").body
    # A runtime error that points at the operator needs its position from the tree.
    assert stmt.value.op == row.symbol and (stmt.value.op_pos.line > 0) == row.at_operator
    if row.runtime is not None:
        assert callable(getattr(Runtime, row.runtime, None)), row.runtime
    assert row.result is None or row.result in V.TYPES


def test_operator_rows_are_reachable_and_lowered_from_the_table():
    # Each row is the first for some operand types (none is shadowed by an earlier one) ...
    for row in V.OPERATORS:
        firsts = {V.operators_for(row.symbol, a, b)[0] for a in row.left for b in row.right}
        assert row in firsts, row
    # ... and the lowering calls the row's runtime method, not one spelled by hand.
    from liganimate.compiler import compile_text

    program = (
        "MOTION A\nA[1, 1] := FRAME 1 POSITION 0, 0, 0\nB = 2 * A + A\n"
        "G :- BOX WIDTH 1, HEIGHT 1, DEPTH 1\nH = G + G\nX = 7 MOD 2\n"
    )
    python = compile_text(program).python
    for name in ("repeat", "concat", "superpose", "mod"):
        assert f"rt.{name}(" in python, name


def test_a_refused_operator_is_explained():
    from liganimate.compiler import compile_text
    from liganimate.lang.diagnostics import LigDiagnostics

    cases = {
        "G :- BOX WIDTH 1, HEIGHT 1, DEPTH 1\nM :- JOINT 1, G, (0, 0, 0), G, (0, 0, 0), (0, 1)\nN = M + M\n": "combined with JOINT",
        "MOTION A\nA[1, 1] := FRAME 1 POSITION 0, 0, 0\nB = 2.5 * A\n": "repetition count must be an INTEGER",
        "MOTION A\nA[1, 1] := FRAME 1 POSITION 0, 0, 0\nB = A * 2\n": "the repetition count comes first",
        "X = (1, 2, 3) / (1, 2, 3)\n": "cannot divide a VECTOR by a VECTOR",
        "X = (1, 2, 3) MOD 2\n": "MOD works on numbers",
    }
    for program, words in cases.items():
        with pytest.raises(LigDiagnostics) as info:
            compile_text(program)
        assert words in str(info.value), program
