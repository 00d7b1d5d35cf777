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


def compile_source(source: Source, module_name: str | None = None, *, path: str | None = None,
                   stack: tuple = ()) -> Compiled:
    """Parse, check and lower a prepared source. Raises LigDiagnostics on errors.

    ``path`` is the file the source came from: relative LOADs start there
    (default: the current folder). ``stack`` is the chain of libraries being
    loaded around this one (see :mod:`.library`).
    """
    path = path if path is not None else source.filename
    program = parse_source(source, _loaded_primitive_names(source, path, stack))
    checked = check(program, path=path, stack=stack)
    python = lower(checked, module_name or source.filename)
    return Compiled(python, list(source.warnings) + checked.warnings, checked)


def compile_text(text: str, filename: str = "<string>") -> Compiled:
    """Compile program text."""
    return compile_source(prepare(text, filename))


def compile_file(path: str) -> Compiled:
    """Compile a program file."""
    return compile_source(load(path), path=path)


def _loaded_primitive_names(source: Source, path: str, stack: tuple) -> set:
    """Names of the primitives the source's LOAD statements bring, for the lexer.

    A LOAD that fails here is left for the checker, which reports it at its line.
    """
    from . import library

    names = set()
    for lib_name, wanted in source.load_requests():
        try:
            lib = library.load(lib_name, library.resolve(lib_name, path), stack)
        except Exception:
            continue
        names.update(n for n in (wanted if wanted is not None else lib.signatures) if n in lib.signatures)
    return names
