"""Diagnostics: ``file:line:col``, the source line with a caret, one sentence, a hint.

Every error a user can cause ends up as a :class:`Diagnostic`; the command
line prints it with :func:`format_diagnostic` and exits non-zero, so no
Python traceback ever reaches the user.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from typing import Iterable, Optional

from .ast import Pos


@dataclass(slots=True)
class Diagnostic:
    """One message about one place in one file."""

    filename: str
    pos: Pos
    message: str
    hint: Optional[str] = None
    severity: str = "error"
    source: Optional[str] = None
    notes: list = field(default_factory=list)


class LigDiagnostics(Exception):
    """Raised to stop compilation or a run; carries one or more diagnostics."""

    def __init__(self, diagnostics: list):
        super().__init__("; ".join(d.message for d in diagnostics))
        self.diagnostics = diagnostics


def error(filename: str, pos: Pos, message: str, hint: str | None = None, source: str | None = None) -> LigDiagnostics:
    """Build the exception for a single error (the caller raises it)."""
    return LigDiagnostics([Diagnostic(filename, pos, message, hint, "error", source)])


def closest(name: str, candidates: Iterable[str], n: int = 3) -> list:
    """The known names closest to ``name``, for 'did you mean' hints."""
    return difflib.get_close_matches(name.upper(), sorted({c.upper() for c in candidates}), n=n, cutoff=0.6)


def did_you_mean(name: str, candidates: Iterable[str]) -> Optional[str]:
    """A hint sentence naming the closest known names, or None."""
    near = closest(name, candidates)
    if not near:
        return None
    if len(near) == 1:
        return f"did you mean {near[0]}?"
    return "did you mean " + ", ".join(near[:-1]) + " or " + near[-1] + "?"


def format_diagnostic(d: Diagnostic, source: str | None = None) -> str:
    """Render a diagnostic the way compilers do: location, sentence, line, caret, hint."""
    src = d.source if d.source is not None else source
    head = f"{d.filename}:{d.pos.line}:{d.pos.column}: {d.severity}: {d.message}"
    lines = [head]
    if src is not None and d.pos.line >= 1:
        text_lines = src.splitlines()
        if d.pos.line <= len(text_lines):
            line = text_lines[d.pos.line - 1].expandtabs(1)
            lines.append(f"    {line}")
            width = 1
            if d.pos.end_line == d.pos.line and d.pos.end_column > d.pos.column:
                width = d.pos.end_column - d.pos.column
            width = max(1, min(width, max(1, len(line) - d.pos.column + 1)))
            lines.append("    " + " " * max(0, d.pos.column - 1) + "^" + "~" * (width - 1))
    for note in d.notes:
        lines.append(f"  note: {note}")
    if d.hint:
        lines.append(f"  hint: {d.hint}")
    return "\n".join(lines)
