"""Declared statements (lang/ast.py ``@declared``): one declaration read by the parser, the checker and the lowering.

The checklist of docs/architecture.md promises that such a statement is its
grammar production, its node and its runtime method, and nothing else; these
tests hold the three to each other, and check SHOOTSCENES FROM a TO b, the
statement added by following that checklist.
"""

from __future__ import annotations

import inspect
import pathlib
import re

import pytest
from paths import ROOT_DIR

from liganimate.compiler import compile_text, load_program
from liganimate.compiler.lower import Lowerer
from liganimate.compiler.statements import StatementChecker
from liganimate.lang import ast as A
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.parser import parse
from liganimate.runtime.host import Runtime

GRAMMAR = (pathlib.Path(ROOT_DIR) / "lang" / "lig.lark").read_text(encoding="utf-8")
DECLARED = sorted(A.DECLARED.items(), key=lambda item: item[0].__name__)


def test_the_declared_statements_are_found():
    # A test of the test: an empty registry would pass everything below.
    assert {cls.__name__ for cls, _ in DECLARED} >= {"Shoot", "ShootRange", "ViewPoint", "ViewWidth"}


@pytest.mark.parametrize(("cls", "declaration"), DECLARED, ids=lambda x: getattr(x, "__name__", ""))
def test_a_declaration_names_its_grammar_rule_and_a_runtime_method_taking_its_parts(cls, declaration):
    # The rule is a production or an alias of lig.lark ...
    assert re.search(rf"(^{declaration.rule}:|->\s*{declaration.rule}\b)", GRAMMAR, re.M), declaration.rule
    # ... the runtime method takes the parts, then the position index ...
    method = getattr(Runtime, declaration.runtime, None)
    assert callable(method), declaration.runtime
    params = list(inspect.signature(method).parameters)[1:]
    assert params[-1] == "at" and len(params) == len(declaration.parts) + 1, (declaration.runtime, params)
    # ... and no pass has a method of its own for it: the declaration is all there is.
    assert not hasattr(StatementChecker, "_s_" + cls.__name__) and not hasattr(Lowerer, "s_" + cls.__name__)


def test_the_transformer_builds_a_declared_node_from_its_children():
    point, width, shoot, shoot_range = parse(
        "VIEW POINT = (1, 2, 3)\nVIEW WIDTH = 7.5\nSHOOTSCENES\nSHOOTSCENES FROM 2 TO 4 + 1\n"
    ).body
    assert type(point) is A.ViewPoint and isinstance(point.point, A.Tuple)
    assert type(width) is A.ViewWidth and width.width.value == 7.5
    assert type(shoot) is A.Shoot and type(shoot_range) is A.ShootRange
    assert shoot_range.first.value == 2 and isinstance(shoot_range.last, A.BinOp)
    assert (shoot_range.pos.line, shoot_range.pos.column, shoot_range.pos.end_column) == (4, 1, 28)


def test_the_lowering_calls_the_declared_runtime_method():
    python = compile_text("VIEW POINT = (1, 2, 3)\nVIEW WIDTH = 7\nSHOOTSCENES FROM 2 TO 3\nSHOOTSCENES\nEND\n").python
    for call in ("rt.set_view_point(rt.vec(1, 2, 3), ", "rt.set_view_width(7, ", "rt.shoot_range(2, 3, ", "rt.shoot("):
        assert call in python, call


@pytest.mark.parametrize(
    ("text", "where", "words"),
    [
        ("VIEW WIDTH = (1, 2, 3)\nEND\n", (1, 15), "a view width must be a number, not a VECTOR"),
        ("VIEW POINT = 2\nEND\n", (1, 14), "a view point (x, y, z) must be a VECTOR, not an INTEGER"),
        ("SHOOTSCENES FROM 1.5 TO 3\nEND\n", (1, 18), "the first scene to shoot must be an INTEGER; this is a REAL"),
        (
            "INITIALIZE SCENE 1\nSHOOTSCENES FROM 1 TO 2\nSTARTSCENE LENGTH 1\nENDSCENE\nEND\n",
            (2, 1),
            "SHOOTSCENES belongs outside scenes and primitives",
        ),
        (
            "PRIMITIVE P\nP ::= 'P' ;\nSHOOTSCENES FROM 1 TO 2\nRETURN\nEND\nEND\n",
            (3, 1),
            "SHOOTSCENES belongs outside scenes and primitives",
        ),
    ],
)
def test_the_checker_reports_a_declared_statement_from_its_declaration(text, where, words):
    with pytest.raises(LigDiagnostics) as info:
        compile_text(text)
    first = info.value.diagnostics[0]
    assert (first.pos.line, first.pos.column) == where and first.message == words


FILM = "".join(f"INITIALIZE SCENE {n}\nSTARTSCENE LENGTH 2\nPRINT 'scene {n}'\nENDSCENE\n" for n in (1, 2, 3))


def _printed(tmp_path, capsys, shoot: str) -> tuple:
    path = tmp_path / "film.lig"
    path.write_text(FILM + shoot + "\nEND\n")
    program, _ = load_program(str(path))
    rt = program.execute("check", echo_print=True)
    return capsys.readouterr().out.split(), rt


def test_shootscenes_from_to_shoots_only_those_scenes(tmp_path, capsys):
    out, rt = _printed(tmp_path, capsys, "SHOOTSCENES FROM 2 TO 3")
    assert out == ["scene", "2", "scene", "2", "scene", "3", "scene", "3"]
    assert not rt.warnings
    out, _ = _printed(tmp_path, capsys, "SHOOTSCENES")
    assert out == ["scene", "1", "scene", "1", "scene", "2", "scene", "2", "scene", "3", "scene", "3"]


def test_shootscenes_from_to_forgets_every_recorded_scene(tmp_path, capsys):
    # As SHOOTSCENES does: a later SHOOTSCENES finds none of the scenes recorded before.
    out, _ = _printed(tmp_path, capsys, "SHOOTSCENES FROM 3 TO 3\nSHOOTSCENES")
    assert out == ["scene", "3", "scene", "3"]


def test_shootscenes_from_to_of_no_recorded_scene_is_a_warning(tmp_path, capsys):
    out, rt = _printed(tmp_path, capsys, "SHOOTSCENES FROM 7 TO 9")
    assert out == []
    (warning,) = rt.warnings
    assert warning.message == "no scene from 7 to 9 has been recorded (recorded: 1, 2, 3)"


def test_shootscenes_from_after_to_is_an_error_at_the_statement(tmp_path, capsys):
    with pytest.raises(LigDiagnostics) as info:
        _printed(tmp_path, capsys, "N = 3\nSHOOTSCENES FROM N TO 1")
    (error,) = info.value.diagnostics
    assert error.pos.line == 14 and error.message == "SHOOTSCENES FROM 3 TO 1 names no scenes: 3 is after 1"


def test_a_library_refuses_shootscenes_from_to(tmp_path):
    (tmp_path / "lib.lig").write_text("MODEL M\nSHOOTSCENES FROM 1 TO 2\nEND\n")
    with pytest.raises(LigDiagnostics, match="defines scenes, so it is a program, not a library"):
        load_program(text="LOAD M FROM 'lib.lig'\nEND\n", name=str(tmp_path / "use.lig"))
