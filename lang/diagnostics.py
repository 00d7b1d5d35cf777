"""Diagnostics: ``file:line:col``, the source line with a caret, one sentence, a hint.

Every error a user can cause ends up as a :class:`Diagnostic`; the command
line prints it with :func:`format_diagnostic` and exits non-zero, so no
Python traceback ever reaches the user.
"""

from __future__ import annotations

from dataclasses import field

from .ast import Pos
from .display import at_end, escape_text, last_line, render_line, source_line
from .messages import closest, did_you_mean  # noqa: F401  (the one did-you-mean, re-exported)
from .node_methods import record


@record(slots=True)
class Diagnostic:
    """One message about one place in one file."""

    filename: str
    pos: Pos
    message: str
    hint: str | None = None
    severity: str = "error"
    source: str | None = None
    notes: list = field(default_factory=list)


class LigDiagnostics(Exception):
    """Raised to stop compilation or a run; carries one or more diagnostics."""

    def __init__(self, diagnostics: list):
        super().__init__("; ".join(d.message for d in diagnostics))
        self.diagnostics = diagnostics


def error(filename: str, pos: Pos, message: str, hint: str | None = None, source: str | None = None) -> LigDiagnostics:
    """Build the exception for a single error (the caller raises it)."""
    return LigDiagnostics([Diagnostic(filename, pos, message, hint, "error", source)])


def format_diagnostic(d: Diagnostic, source: str | None = None) -> str:
    """Render a diagnostic the way compilers do: location, sentence, line, caret, hint.

    Everything program-derived (file name, message, source line, hint) is
    escaped for the terminal (see :mod:`liganimate.lang.display`). A long
    line is cut around the caret. A position at the end of the file (past
    the last line, or on blank lines after it) shows the last line that is
    not blank, with the caret just after its last character.
    """
    src = d.source if d.source is not None else source
    head = f"{escape_text(str(d.filename))}:{d.pos.line}:{d.pos.column}: {d.severity}: {escape_text(d.message)}"
    lines = [head]
    if src is not None and d.pos.line >= 1:
        lines.extend(_shown_source(src, d.pos))
    for note in d.notes:
        lines.append(f"  note: {escape_text(str(note))}")
    if d.hint:
        lines.append(f"  hint: {escape_text(d.hint)}")
    return "\n".join(lines)


def _shown_source(src: str, pos: Pos) -> list:
    """The source line and caret lines for ``pos`` (none for an empty source)."""
    if at_end(src, pos.line):
        last = last_line(src)
        if last is None:
            return []
        shown, caret = render_line(last[1], len(last[1]) + 1)
        return [f"    {shown}", f"    {caret} at the end of the file"]
    line = source_line(src, pos.line)
    width = 1
    if pos.end_line == pos.line and pos.end_column > pos.column:
        width = pos.end_column - pos.column
    shown, caret = render_line(line, pos.column, width)
    return [f"    {shown}", f"    {caret}"]
