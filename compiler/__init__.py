"""liganimate.compiler: static checks and lowering to a Python module."""

from __future__ import annotations

from liganimate.lang import collector
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics
from liganimate.lang.node_methods import record
from liganimate.lang.parser import parse_source
from liganimate.lang.source import Source, load, prepare

from .check import Checked, check
from .lower import lower


@record
class Compiled:
    """The result of compiling one program: the module text and the warnings found."""

    python: str
    warnings: list
    checked: Checked


class NotParsed(LigDiagnostics):
    """The source does not parse.

    ``syntax`` are the parser's diagnostics; ``loads`` report the LOADs that
    failed before parsing (a primitive of a library that failed to load is
    an unknown word to the parser, so its failure comes first).
    """

    def __init__(self, loads: list, syntax: list):
        super().__init__(loads + syntax)
        self.loads = loads
        self.syntax = syntax


def compile_source(
    source: Source, module_name: str | None = None, *, path: str | None = None, stack: tuple = (), consume: bool = False
) -> Compiled:
    """Parse, check and lower a prepared source.

    ``path`` is the file the source came from: relative LOADs start there
    (default: the current folder). ``stack`` is the chain of libraries being
    loaded around this one (see :mod:`.library`). ``consume=True`` takes the
    syntax tree apart while lowering (see :func:`.lower.lower`): only for a
    caller that drops ``Compiled.checked``.

    Raises
    ------
    NotParsed
        The source does not parse (a LigDiagnostics).
    LigDiagnostics
        Any other error.
    """
    # The stages build trees and tables, not cycles: see lang/collector.py.
    with collector.paused():
        checked = check_source(source, path=path, stack=stack)
        python = lower(checked, module_name or source.filename, consume)
    return Compiled(python, list(source.warnings) + checked.warnings, checked)


def check_source(source: Source, *, path: str | None = None, stack: tuple = ()) -> Checked:
    """Open the LOADed libraries, parse and check a prepared source, without lowering it.

    Every static diagnostic :func:`compile_source` reports, at the same
    cost minus the lowering. Nothing is executed (a library is compiled,
    never run). The warnings of reading the source are ``source.warnings``,
    those of the check ``Checked.warnings``.

    Raises
    ------
    NotParsed
        The source does not parse (a LigDiagnostics).
    LigDiagnostics
        Any other error.
    """
    with collector.paused():
        program, opened = parse_program(source, path=path, stack=stack)
        return check(program, path=path if path is not None else source.filename, stack=stack, opened=opened)


def parse_program(source: Source, *, path: str | None = None, stack: tuple = (), reparser=None) -> tuple:
    """Open the libraries a source LOADs and parse it: ``(Program, opened)``, for :func:`check`.

    ``opened`` holds the libraries opened for the parse (library name ->
    Library, or the exception it failed with), which :func:`check` takes
    so that a library is opened once. The language server calls this and
    :func:`check` apart, to keep the syntax tree of a program that parses
    but fails its checks; it passes the ``reparser`` of the document
    (:func:`liganimate.lang.parser.reparser`), so that only the part of
    the text around a change is parsed again.

    Raises
    ------
    NotParsed
        The source does not parse.
    """
    path = path if path is not None else source.filename
    opened: dict = {}  # library name -> Library or its failure, for this compile (library.open_library)
    names, failed = _scan_loads(source, path, stack, opened)
    try:
        program = parse_source(source, names, reparser=reparser)
    except LigDiagnostics as exc:
        raise NotParsed(_load_failures(source, failed), exc.diagnostics) from None
    return program, opened


def compile_text(text: str, filename: str = "<string>") -> Compiled:
    """Compile program text."""
    return compile_source(prepare(text, filename))


def compile_file(path: str) -> Compiled:
    """Compile a program file."""
    return compile_source(load(path), path=path)


def compile_for_run(path: str) -> tuple:
    """Compile a program file for running it at once: ``(module text, warnings)``.

    Unlike :func:`compile_file` it keeps no syntax tree (``Compiled.checked``),
    so the tree's memory is free again before CPython compiles the module.
    """
    compiled = compile_source(load(path), path=path, consume=True)
    return compiled.python, compiled.warnings


def load_program(path: str | None = None, *, text: str | None = None, name: str = "<text>") -> tuple:
    """Compile a .lig file (or program ``text``) in memory and execute its module: ``(program, warnings)``.

    This is the one place a program is compiled and executed; the command
    line, :func:`liganimate.load` and the studio all come here.

    The module is the text ``liganimate compile`` writes, executed piece by
    piece (:func:`liganimate.runtime.loader.exec_module`) so that a big
    program compiles in memory proportional to one piece.

    Raises
    ------
    LigDiagnostics
        The program is wrong (see :func:`compile_source`).
    """
    from liganimate.runtime.loader import exec_module

    if path is not None:
        python, warnings = compile_for_run(path)
        name = path
    else:
        compiled = compile_source(prepare(text or "", name), consume=True)
        python, warnings = compiled.python, compiled.warnings
    namespace = {"__name__": "liganimate_program", "__file__": name}
    exec_module(python, f"<liganimate {name}>", namespace)
    return namespace["program"], warnings


def _scan_loads(source: Source, path: str, stack: tuple, opened: dict | None = None) -> tuple:
    """Open what the source's LOAD statements name, before parsing (``library.open_library``).

    Returns ``(names, failed)``: the names of the primitives they bring, for
    the lexer, and ``[(library name, Pos, exception), ...]`` for each LOAD
    that failed in one of the ways a LOAD reports at its line
    (``library.FAILURES``). The checker reports those from ``opened``; if
    parsing fails first, :func:`compile_source` reports them itself.
    """
    requests = source.load_requests()
    if not requests:
        return set(), []
    from . import library  # only a program that LOADs needs it (and its cache's cryptography)

    opened = {} if opened is None else opened
    names: set[str] = set()
    failed: list = []
    for lib_name, wanted, pos in requests:
        lib = library.open_library(lib_name, path, stack, opened)
        if isinstance(lib, Exception):
            failed.append((lib_name, pos, lib))
            continue
        names.update(n for n in (wanted if wanted is not None else lib.signatures) if n in lib.signatures)
    return names, failed


def loaded_primitive_names(source: Source, path: str) -> set:
    """Names of the primitives the LOAD statements of ``source`` (a file at ``path``) bring in.

    The lexer must know them to parse the source; ``liganimate fmt`` parses
    without checking, so it asks here.
    """
    return _scan_loads(source, path, ())[0]


def _loaded_primitive_names(source: Source, path: str, stack: tuple) -> set:
    """Names of the primitives the source's LOAD statements bring (see :func:`_scan_loads`)."""
    return _scan_loads(source, path, stack)[0]


def _load_failures(source: Source, failed: list) -> list:
    """The diagnostics of LOADs that failed, each at its library string, as the checker words them."""
    from . import library

    out = []
    for lib_name, pos, exc in failed:
        message, hint, inner = library.failure(exc, lib_name)
        out.extend(inner)
        out.append(Diagnostic(source.filename, pos, message, hint, source=source.text))
    return out
