"""One analysis of one version of a document: the compiler's diagnostics, its tree, the index and the values.

The diagnostics are the ones ``liganimate check`` prints before it runs
the program, found the same way (:func:`liganimate.compiler.parse_program`
and :func:`liganimate.compiler.check.check`, the stages ``compile_source``
runs): the same sentences, positions, severities and hints. What ``check``
finds only by running the program (a FIGURE naming a link the model lacks,
a keyframe out of order...) needs the run, and the server never runs
program text; ``liganimate check`` still does that.
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field

from liganimate.compiler import NotParsed, parse_program
from liganimate.compiler.check import Checked, check
from liganimate.lang import ast as A
from liganimate.lang import collector
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics
from liganimate.lang.incremental import Reparser
from liganimate.lang.source import MAX_SOURCE_BYTES, prepare

from . import index as I
from . import libraries, statics
from .text import Text

#: Held while the compiler works (parsing, checking, opening libraries): it pauses and freezes the
#: process's garbage collector (lang/collector.py) and keeps caches, so two threads must not run it at once.
COMPILER_LOCK = threading.RLock()


@dataclass
class Analysis:
    """What the server knows of one version of a document."""

    text: Text
    version: int | None
    path: str | None
    diagnostics: list  # of lang.diagnostics.Diagnostic
    program: A.Program | None = None  # the tree, if the text parses
    checked: Checked | None = None  # if it also passed the checks
    index: I.Index | None = None
    env: statics.Env | None = None
    libraries: dict = field(default_factory=dict)  # NAME -> libraries.LibraryInfo that brings it

    @property
    def parsed(self) -> bool:
        """Whether the text parsed (the tree, index and values are this text's)."""
        return self.program is not None


def _too_large(filename: str) -> Diagnostic:
    return Diagnostic(
        filename,
        A.Pos(1, 1, 1, 2),
        f"the file is larger than {MAX_SOURCE_BYTES // (1024 * 1024)} MB, the most a LIG source may hold",
        "split it into a program and libraries it LOADs",
    )


def analyse(
    source: str,
    path: str | None,
    version: int | None = None,
    encoding: str | None = None,
    *,
    whole: bool = True,
    reparser: Reparser | None = None,
) -> Analysis:
    """Analyse document text.

    Parameters
    ----------
    source : str
        The text as the editor holds it.
    path : str or None
        The file it is saved as (LOADs are relative to its folder), or None for an unsaved one.
    version : int, optional
        The editor's version of the text.
    encoding : str, optional
        The position encoding agreed with the client.
    whole : bool
        False stops once the diagnostics are known (the server publishes
        them, then calls :func:`complete`); True also builds the index and
        the values.
    reparser : liganimate.lang.incremental.Reparser, optional
        The document's parser (:func:`liganimate.lang.parser.reparser`),
        which parses again only the part of the text around a change: the
        same tree and diagnostics as a whole parse, sooner.
    """
    # The stages build trees, not cycles: the cyclic collector is paused while
    # they run, as the compiler pauses it (lang/collector.py), so that the
    # trees of earlier analyses the server still holds are not walked again and again.
    with COMPILER_LOCK, collector.paused():
        return _analyse(source, path, version, encoding, whole, reparser)


def _analyse(
    source: str, path: str | None, version: int | None, encoding: str | None, whole: bool, reparser: Reparser | None
) -> Analysis:
    text = Text(source) if encoding is None else Text(source, encoding)
    filename = path or "<untitled>"
    if len(source) > MAX_SOURCE_BYTES or len(source.encode("utf-8", errors="replace")) > MAX_SOURCE_BYTES:
        return Analysis(text, version, path, [_too_large(filename)])
    prepared = prepare(source, filename)
    where = path if path is not None else os.path.join(os.getcwd(), "<untitled>")
    try:
        program, opened = parse_program(prepared, path=where, reparser=reparser)
    except NotParsed as exc:
        return Analysis(text, version, path, list(exc.diagnostics))
    result = Analysis(text, version, path, [], program)
    try:
        result.checked = check(program, path=where, opened=opened)
        result.diagnostics = list(prepared.warnings) + list(result.checked.warnings)
    except LigDiagnostics as exc:
        result.diagnostics = list(exc.diagnostics)
    return complete(result) if whole else result


def complete(a: Analysis) -> Analysis:
    """Build the index, the libraries and the values of an analysis whose text parsed (in place; returns it)."""
    if a.program is None or a.index is not None:
        return a
    where = a.path if a.path is not None else os.path.join(os.getcwd(), "<untitled>")
    with COMPILER_LOCK, collector.paused():  # as in analyse
        a.index = I.build(a.program, a.text)
        a.libraries = libraries.libraries_of(a.program, where)
        a.env = statics.evaluate(a.program, libraries.loaded_values(a.program, where))
    return a


__all__ = ["COMPILER_LOCK", "Analysis", "analyse", "complete"]
