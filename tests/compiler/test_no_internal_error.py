"""Issue 24: inputs that reached an internal error in the compiler, fixed as classes.

Every check that looks at a constant goes through one function that folds
signs (``-1`` is a ``Neg`` node, not a literal), and a chain of modifiers
counts one nesting level per modifier, as the compiled Python nests it.
"""

from __future__ import annotations

import pytest

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic
from liganimate.lang.parser import parse

SEGMENT = "      GRAPHICAL G, H\n      G :- BOX WIDTH 1, HEIGHT 1, DEPTH 1\n      H :- G\n"
JOINT_REST = "G, (0,0,0), H, (0,0,0), (0,0), (0,0), (0,0)"


def refused(text: str, name: str = "t.lig"):
    """The first error of a program that must be refused (by the compiler or its check)."""
    with pytest.raises(LigDiagnostics) as info:
        program, _ = load_program(text=text, name=name)
        program.check()
    d = info.value.diagnostics[0]
    assert format_diagnostic(d).startswith(f"{name}:{d.pos.line}:{d.pos.column}: error: ")
    return d


@pytest.mark.parametrize("ident", ["-1", "-(1)", "-(-(-1))", "(-1)"])
def test_a_negative_joint_identifier_inside_startmodel_is_accepted_like_the_assignment(ident):
    block = SEGMENT + f"      STARTMODEL M\n      JOINT {ident}, {JOINT_REST}\n      ENDMODEL\n"
    assign = SEGMENT + f"      MODEL N\n      N :- JOINT {ident}, {JOINT_REST}\n"
    for text in (block, assign):
        program, _ = load_program(text=text, name="t.lig")
        program.check()


def test_the_same_negative_joint_twice_in_a_model_is_refused_at_the_second():
    text = (
        SEGMENT + f"      STARTMODEL M\n      JOINT -1, {JOINT_REST}\n      JOINT -(1), {JOINT_REST}\n      ENDMODEL\n"
    )
    d = refused(text)
    assert d.message == "joint -1 appears twice in model M"
    assert d.pos.line == 6


def test_the_same_negative_joint_twice_in_a_motion_is_refused_at_the_second():
    text = (
        "      STARTMOTION W\n      JOINT -2 POSITION 0.0, 0.0, 1.0\n"
        "      JOINT -(2) POSITION 0.0, 0.0, 2.0\n      ENDMOTION\n"
    )
    d = refused(text)
    assert d.message == "joint -2 appears twice in motion W"
    assert d.pos.line == 3


def test_extremes_written_with_nested_signs_are_compared():
    text = SEGMENT + "      MODEL M\n      M :- JOINT 1, G, (0,0,0), H, (0,0,0), (-(-3), -(2)), (0,0), (0,0)\n"
    d = refused(text)
    assert d.message == "these extremes have a minimum (3) above the maximum (-2)"


def modifiers(n: int) -> str:
    return SEGMENT + "      G :- G" + " <SCALE 1>" * n + "\n"


@pytest.mark.parametrize("n", [201, 5000, 50_000])
def test_a_long_modifier_chain_is_refused_by_the_nesting_limit_with_its_place(n):
    with pytest.raises(LigDiagnostics) as info:
        parse(modifiers(n), "t.lig")
    (d,) = info.value.diagnostics
    assert d.message == "this is nested more than 100 levels deep"
    assert d.pos.line == 4
    assert d.hint == "split it into several statements with variables in between"


def test_a_modifier_chain_within_the_limit_compiles_and_runs():
    program, _ = load_program(text=modifiers(95) + "      PRINT 'done'\n", name="t.lig")
    program.check()


def test_modifiers_count_as_levels_with_the_expression_around_them():
    # 60 negations and a chain of 60 modifiers: neither alone is too deep, together they are.
    deep = SEGMENT + "      REAL S\n      S = 1\n      G :- G" + " <SCALE S>" * 60 + "\n"
    load_program(text=deep, name="t.lig")
    inner = "-(" * 60 + "S" + ")" * 60
    d = refused(SEGMENT + "      REAL S\n      S = 1\n      G :- G" + f" <SCALE {inner}>" + " <SCALE S>" * 60 + "\n")
    assert d.message == "this is nested more than 100 levels deep"
