"""Big programs: the main program lowered into many functions (compiler/lower.py).

A program with more than ``CHUNK_STATEMENTS`` top-level statements is
lowered into functions of about ``CHUNK_LINES`` lines whose variables are
module globals, compiled one by one (runtime/loader.py). With the limits
made tiny, every example is lowered that way, and must behave exactly as
when it is one function.
"""

from __future__ import annotations

import importlib
import io
import pathlib

import numpy as np
import pytest
from paths import ROOT_DIR

from liganimate.compiler import compile_file, load_program
from liganimate.lang.diagnostics import format_diagnostic
from liganimate.runtime.loader import exec_module

L = importlib.import_module("liganimate.compiler.lower")  # the package exports a function of that name
EXAMPLES = sorted((pathlib.Path(ROOT_DIR) / "examples").glob("*.lig"))


def behaviour(program) -> tuple:
    """What a run shows: its printed text, its warnings, its variables' names and printed values."""
    out = io.StringIO()
    rt = program.execute("check", stdout=out)
    values = {k: fingerprint(v) for k, v in sorted(rt.variables.items())}
    return out.getvalue(), [format_diagnostic(w) for w in rt.warnings], values


def fingerprint(value, depth: int = 12):
    """A value as nested plain data (numbers, lists, dicts), to compare two runs' results."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if depth == 0:
        return type(value).__name__
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {repr(k): fingerprint(v, depth - 1) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        items = sorted(value, key=repr) if isinstance(value, (set, frozenset)) else value
        return [fingerprint(v, depth - 1) for v in items]
    fields = getattr(value, "__dict__", None)
    if fields is None and hasattr(value, "__slots__"):
        fields = {n: getattr(value, n, None) for n in value.__slots__}
    if fields is None:
        return type(value).__name__
    # Caches of derived values are keyed by id(): not part of the value.
    fields = {k: v for k, v in fields.items() if "derived" not in k and "cache" not in k}
    return type(value).__name__, fingerprint(fields, depth - 1)


def run_text(python: str, piecewise: bool):
    namespace = {"__name__": "big"}
    if piecewise:
        exec_module(python, "<big>", namespace)
    else:  # as `python compiled.py` or an import would: the whole text at once
        exec(compile(python, "<big>", "exec"), namespace)  # noqa: S102
    return namespace["program"]


@pytest.fixture
def tiny_chunks(monkeypatch):
    monkeypatch.setattr(L, "CHUNK_STATEMENTS", 5)
    monkeypatch.setattr(L, "CHUNK_LINES", 4)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_a_program_split_into_functions_behaves_as_one_function(path, monkeypatch):
    whole = compile_file(str(path)).python
    assert "def _main_0(rt):" not in whole  # the examples are small: one function
    expected = behaviour(run_text(whole, True))
    monkeypatch.setattr(L, "CHUNK_STATEMENTS", 5)
    monkeypatch.setattr(L, "CHUNK_LINES", 4)
    split = compile_file(str(path)).python
    assert "def _main_1(rt):" in split and "_AT = '" in split
    assert behaviour(run_text(split, True)) == expected
    assert behaviour(run_text(split, False)) == expected


def test_each_piece_assigns_the_program_variables(tmp_path, tiny_chunks):
    # A chunk that assigned X without `global X` would change only its own local.
    src = tmp_path / "p.lig"
    src.write_text(
        "      INTEGER X, I\n" + "      X = X + 1\n" * 12 + "      DO 10 I = 1, 3\n      X = X * 2\n 10   CONTINUE\n"
    )
    program, _ = load_program(str(src))
    rt = program.execute("check", stdout=io.StringIO())
    assert rt.variables["X"] == 96 and rt.variables["I"] == 3


def test_a_position_in_a_late_piece_is_reported_at_its_line(tmp_path, tiny_chunks):
    src = tmp_path / "p.lig"
    src.write_text("      REAL R\n" + "      R = 1.0\n" * 20 + "      R = SQRT(-1.0)\n")
    program, _ = load_program(str(src))
    with pytest.raises(Exception) as info:
        program.check()
    text = "\n".join(format_diagnostic(d) for d in info.value.diagnostics)
    assert f"{src}:22:" in text
