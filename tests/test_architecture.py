"""The import contract of docs/architecture.md: each package imports only the layers below it.

Every module of lang/, compiler/ and runtime/ is parsed (not imported, so
lazy imports inside functions count too) and each ``liganimate`` import it
makes is compared with the modules its package may import.
"""

from __future__ import annotations

import ast
import pathlib

import pytest
from paths import ROOT_DIR

ROOT = pathlib.Path(ROOT_DIR)
FOLDERS = {"lang": "liganimate.lang", "compiler": "liganimate.compiler", "runtime": "liganimate.runtime"}

#: The command line and the tools above the runtime: nothing below imports them.
ABOVE = (
    "liganimate.cli",
    "liganimate.__main__",
    "liganimate.api",
    "liganimate.exchange_cli",
    "liganimate.view_cli",
    "liganimate.fmt_cli",
    "liganimate.lsp",
    "liganimate.highlighting",
)

#: Package -> the modules (and packages, with everything in them) it may import, besides itself
#: and ``liganimate`` (the version). The most specific package of a module applies.
CONTRACT = {
    "liganimate.lang": (),
    "liganimate.compiler": (
        "liganimate.lang",
        # The runtime's vocabularies, by name only: the interpolation methods and solvers a program may name.
        "liganimate.runtime.motion.interpolation",
        "liganimate.runtime.ik.names",
        # compiler.load_program executes the module it lowered, piece by piece.
        "liganimate.runtime.loader",
    ),
    # lang.node_methods: @record, the dataclasses whose methods are written out (a leaf: see
    # test_the_record_maker_imports_nothing_of_the_language below).
    "liganimate.runtime.motion": (
        "liganimate.lang.numbers",
        "liganimate.lang.messages",
        "liganimate.lang.node_methods",
        "liganimate.runtime.errors",
    ),
    "liganimate.runtime.figure": (
        "liganimate.lang.numbers",
        "liganimate.lang.messages",
        "liganimate.lang.node_methods",
        "liganimate.runtime.errors",
        "liganimate.runtime.values",
        "liganimate.runtime.motion",
    ),
    "liganimate.runtime.ik": (
        "liganimate.lang.numbers",
        "liganimate.lang.messages",
        "liganimate.lang.node_methods",
        "liganimate.runtime.errors",
        "liganimate.runtime.figure",
        "liganimate.runtime.motion",
    ),
    "liganimate.runtime.render": (
        "liganimate.lang.numbers",
        "liganimate.lang.messages",
        "liganimate.lang.diagnostics",
        "liganimate.runtime.errors",
        "liganimate.runtime.values",
        "liganimate.runtime.limits",
        "liganimate.runtime.files",
        "liganimate.runtime.figure",
        "liganimate.runtime.motion",
    ),
    # The runtime core: the host and the other top-level modules. Never the compiler: a
    # compiled module runs without it (TOOLS below are the layer that compiles).
    "liganimate.runtime": ("liganimate.lang", "liganimate.runtime"),
    # The tools that compile and run programs, a layer above the runtime core.
    "liganimate.runtime.exchange": ("liganimate.lang", "liganimate.compiler", "liganimate.runtime"),
    "liganimate.runtime.view": ("liganimate.lang", "liganimate.compiler", "liganimate.runtime"),
    "liganimate.runtime.studio": ("liganimate.lang", "liganimate.compiler", "liganimate.runtime"),
}


#: The tools' layer: nothing of the runtime core below it imports these.
TOOLS = ("liganimate.runtime.exchange", "liganimate.runtime.view", "liganimate.runtime.studio")


def _modules():
    for folder, package in FOLDERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            parts = list(path.relative_to(ROOT / folder).with_suffix("").parts)
            is_package = parts[-1] == "__init__"
            if is_package:
                parts.pop()
            yield ".".join([package, *parts]), is_package, path


MODULES = {name: (is_package, path) for name, is_package, path in _modules()}


def imports_of(name: str) -> set:
    """The ``liganimate`` modules that module ``name`` imports, anywhere in its text."""
    is_package, path = MODULES[name]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_package else name.split(".")[:-1]
                base = base[: len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            for alias in node.names:
                # ``from liganimate.lang import numbers`` imports the module liganimate.lang.numbers.
                sub = f"{module}.{alias.name}"
                found.add(sub if sub in MODULES else module)
    return {m for m in found if m == "liganimate" or m.startswith("liganimate.")}


def _rule(name: str) -> str:
    return max((p for p in CONTRACT if name == p or name.startswith(p + ".")), key=len)


def _is_under(name: str, packages) -> bool:
    return any(name == p or name.startswith(p + ".") for p in packages)


def _allowed(name: str, imported: str) -> bool:
    rule = _rule(name)
    if rule not in TOOLS and _is_under(imported, TOOLS):
        return False  # the runtime core never reaches up to the tools built on it
    if imported == "liganimate" or _is_under(imported, (rule,)):
        return True
    return _is_under(imported, CONTRACT[rule])


@pytest.mark.parametrize("name", sorted(MODULES))
def test_module_imports_only_what_its_package_may(name):
    wrong = sorted(m for m in imports_of(name) if not _allowed(name, m) or m.startswith(ABOVE))
    assert not wrong, f"{name} imports {', '.join(wrong)}, which {_rule(name)} may not (docs/architecture.md)"


def _reported(tmp_path, monkeypatch, name: str, text: str) -> list:
    """What the contract test says of a module ``name`` with this text (a file that is not in the tree)."""
    fake = tmp_path / (name.rsplit(".", 1)[-1] + ".py")
    fake.write_text(text)
    monkeypatch.setitem(MODULES, name, (False, fake))
    try:
        test_module_imports_only_what_its_package_may(name)
    except AssertionError as exc:
        return [str(exc)]
    return []


def test_the_contract_catches_a_wrong_import(tmp_path, monkeypatch):
    # The check itself can fail: a motion module importing the figure code breaks the contract.
    fake = tmp_path / "bad.py"
    fake.write_text("from liganimate.runtime.figure import tree\nimport liganimate.cli\n")
    monkeypatch.setitem(MODULES, "liganimate.runtime.motion.bad", (False, fake))
    found = imports_of("liganimate.runtime.motion.bad")
    assert found == {"liganimate.runtime.figure.tree", "liganimate.cli"}
    assert not _allowed("liganimate.runtime.motion.bad", "liganimate.runtime.figure.tree")
    assert not _allowed("liganimate.runtime.host", "liganimate.cli")


@pytest.mark.parametrize(
    "text",
    [
        "from liganimate.compiler import check\n",
        "def later():\n    from liganimate.compiler.names import reserved\n",
        "from liganimate.runtime.exchange import collect\n",
        "from .view import iframe\n",
    ],
)
def test_the_runtime_core_may_not_import_the_compiler_or_the_tools(tmp_path, monkeypatch, text):
    # A module beside runtime/host.py, in the core's package: each of these imports is reported.
    (report,) = _reported(tmp_path, monkeypatch, "liganimate.runtime.extra", text)
    assert (
        report.startswith("liganimate.runtime.extra imports liganimate.")
        and "which liganimate.runtime may not" in report
    )


def test_the_tools_may_compile(tmp_path, monkeypatch):
    text = "from liganimate.compiler import check\nfrom liganimate.runtime.host import Program\n"
    for tool in TOOLS:
        assert _reported(tmp_path, monkeypatch, f"{tool}.extra", text) == []
    (report,) = _reported(tmp_path, monkeypatch, "liganimate.runtime.view.extra", "import liganimate.view_cli\n")
    assert "imports liganimate.view_cli" in report


def test_the_record_maker_imports_nothing_of_the_language():
    # The runtime's inner packages may use @record because lang/node_methods.py is a leaf: besides its
    # own written-out methods and the generated files' command line, nothing of lang/ (no syntax tree,
    # no parser) comes with it.
    assert imports_of("liganimate.lang.node_methods") <= {
        "liganimate.lang.node_methods",  # module_text reads the classes it made, as imported
        "liganimate.lang._node_methods",
        "liganimate.lang.generated",
    }
    assert imports_of("liganimate.lang._node_methods") == set()
    assert imports_of("liganimate.lang.generated") == set()


def test_no_module_below_the_command_line_imports_it():
    for name in MODULES:
        assert not any(m.startswith(ABOVE) for m in imports_of(name)), name


def test_one_function_loads_a_program():
    # The command line, the Python API, the tools and the tests load programs through
    # compiler.load_program; a second loader (the command line had one) is a second way to drift.
    found = sorted(
        path.relative_to(ROOT).as_posix()
        for folder in ("lang", "compiler", "runtime", "src")
        for path in (ROOT / folder).rglob("*.py")
        if "def load_program(" in path.read_text(encoding="utf-8")
    )
    assert found == ["compiler/__init__.py"]
