"""Function size: no function in lang/, compiler/ or runtime/ over 80 lines or complexity 25.

Long functions with many branches are where a newcomer who must add a feature
gets lost, so the rule of docs/architecture.md is measured here with lizard
(its ``length``, lines from ``def`` to the last line, and its cyclomatic
complexity). The generated grammar tables (lang/_tables.py) are exempt.

Today's offenders are listed in ``ALLOWED``, each with the helper who owns its
split. The list can only shrink: an entry that is no longer an offender (split,
renamed or deleted) fails the test too, so that it is removed and stays true.
"""

from __future__ import annotations

import ast
import pathlib

import lizard
import pytest
from paths import ROOT_DIR

ROOT = pathlib.Path(ROOT_DIR)
FOLDERS = ("lang", "compiler", "runtime")
EXEMPT = {"lang/_tables.py"}

MAX_LENGTH = 80
MAX_COMPLEXITY = 25

#: (file, qualified function name) -> who splits it. Only ever remove entries.
ALLOWED: dict[tuple[str, str], str] = {}


def _qualified_names(tree: ast.Module) -> dict[int, str]:
    """Map the line of every ``def`` to its dotted name (classes and enclosing functions)."""
    names: dict[int, str] = {}

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = prefix + child.name
                if not isinstance(child, ast.ClassDef):
                    names[child.lineno] = name
                visit(child, name + ".")
            else:
                visit(child, prefix)

    visit(tree, "")
    return names


def _measure() -> dict[tuple[str, str], tuple[int, int]]:
    """Every function of the measured folders -> (length, cyclomatic complexity)."""
    found: dict[tuple[str, str], tuple[int, int]] = {}
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            if rel in EXEMPT:
                continue
            text = path.read_text(encoding="utf-8")
            names = _qualified_names(ast.parse(text))
            for fn in lizard.analyze_file.analyze_source_code(rel, text).function_list:
                name = names.get(fn.start_line, fn.name)
                length, ccn = fn.length, fn.cyclomatic_complexity
                old = found.get((rel, name))
                if old is not None:  # two functions of one name (e.g. under `if`): keep the worse
                    length, ccn = max(length, old[0]), max(ccn, old[1])
                found[(rel, name)] = (length, ccn)
    return found


@pytest.fixture(scope="module")
def measured() -> dict[tuple[str, str], tuple[int, int]]:
    return _measure()


def _offends(size: tuple[int, int]) -> bool:
    return size[0] > MAX_LENGTH or size[1] > MAX_COMPLEXITY


def test_the_measure_sees_every_folder(measured):
    # A test of the test: an empty or misrouted measurement would pass everything.
    for folder in FOLDERS:
        assert sum(1 for rel, _ in measured if rel.startswith(folder + "/")) > 50, folder
    assert all((ROOT / rel).is_file() for rel, _ in ALLOWED), "an allow-listed file moved"


def test_no_new_long_or_branchy_function(measured):
    new = {
        f"{rel}:{name} (length {size[0]}, complexity {size[1]})"
        for (rel, name), size in measured.items()
        if _offends(size) and (rel, name) not in ALLOWED
    }
    assert not new, (
        f"functions over {MAX_LENGTH} lines or complexity {MAX_COMPLEXITY}; split them "
        f"(docs/architecture.md): {sorted(new)}"
    )


def test_the_allow_list_is_true(measured):
    stale = {
        f"{rel}:{name} ({owner})"
        for (rel, name), owner in ALLOWED.items()
        if not _offends(measured.get((rel, name), (0, 0)))
    }
    assert not stale, f"no longer over the limits (or gone); remove from ALLOWED: {sorted(stale)}"


def test_the_check_catches_an_offender():
    # A test of the test: a synthetic long, branchy function is measured as an offender.
    body = "".join(f"    if x == {i}:\n        x += {i}\n" for i in range(45))
    fn = lizard.analyze_file.analyze_source_code("x.py", f"def f(x):\n{body}    return x\n").function_list[0]
    assert _offends((fn.length, fn.cyclomatic_complexity))
    assert fn.length > MAX_LENGTH and fn.cyclomatic_complexity > MAX_COMPLEXITY
