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
from dataclasses import dataclass, field

from liganimate.compiler import NotParsed, parse_program
from liganimate.compiler.check import Checked, check
from liganimate.lang import ast as A
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics
from liganimate.lang.source import MAX_SOURCE_BYTES, prepare

from . import index as I
from . import libraries, statics
from .text import Text


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


def analyse(source: str, path: str | None, version: int | None = None, encoding: str | None = None) -> Analysis:
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
    """
    text = Text(source) if encoding is None else Text(source, encoding)
    filename = path or "<untitled>"
    if len(source) > MAX_SOURCE_BYTES or len(source.encode("utf-8", errors="replace")) > MAX_SOURCE_BYTES:
        return Analysis(text, version, path, [_too_large(filename)])
    prepared = prepare(source, filename)
    where = path if path is not None else os.path.join(os.getcwd(), "<untitled>")
    try:
        program, opened = parse_program(prepared, path=where)
    except NotParsed as exc:
        return Analysis(text, version, path, list(exc.diagnostics))
    result = Analysis(text, version, path, [], program)
    try:
        result.checked = check(program, path=where, opened=opened)
        result.diagnostics = list(prepared.warnings) + list(result.checked.warnings)
    except LigDiagnostics as exc:
        result.diagnostics = list(exc.diagnostics)
    result.index = I.build(program, text)
    result.libraries = libraries.libraries_of(program, where)
    result.env = statics.evaluate(program, libraries.loaded_values(program, where))
    return result


__all__ = ["Analysis", "analyse"]
