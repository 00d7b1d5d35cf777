"""liganimate.compiler: static checks and lowering to a Python module."""

from __future__ import annotations

from dataclasses import dataclass

from liganimate.lang.parser import parse_source
from liganimate.lang.source import Source, load, prepare

from .check import Checked, check
from .lower import lower


@dataclass
class Compiled:
    """The result of compiling one program: the module text and the warnings found."""

    python: str
    warnings: list
    checked: Checked


def compile_source(source: Source, module_name: str | None = None) -> Compiled:
    """Parse, check and lower a prepared source. Raises LigDiagnostics on errors."""
    program = parse_source(source)
    checked = check(program)
    python = lower(checked, module_name or source.filename)
    return Compiled(python, list(source.warnings) + checked.warnings, checked)


def compile_text(text: str, filename: str = "<string>") -> Compiled:
    """Compile program text."""
    return compile_source(prepare(text, filename))


def compile_file(path: str) -> Compiled:
    """Compile a program file."""
    return compile_source(load(path))
