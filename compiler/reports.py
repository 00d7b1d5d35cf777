"""Where the checker's diagnostics go: one collector per pass.

The checker walks a scope several times to settle the types of implicit
numbers (``compiler/check.py``); only the last pass's diagnostics are true.
So each pass writes to its own sink: the settling passes to :data:`SILENT`,
which drops everything, the reporting pass to a :class:`Report`, which is
kept only if the pass turned out to be the last.
"""

from __future__ import annotations

from typing import Protocol

from liganimate.lang import ast as A
from liganimate.lang.diagnostics import Diagnostic

#: Errors after which checking stops (the rest would mostly repeat them).
MAX_ERRORS = 20


class Sink(Protocol):
    """What a pass reports to: a :class:`Report` or :data:`SILENT`."""

    def error(self, node_or_pos, message: str, hint: str | None = None) -> None:
        """Report an error at a node or a position."""

    def warning(self, node, message: str, hint: str | None = None) -> None:
        """Report a warning at a node."""


class TooMany(Exception):
    """Raised by a :class:`Report` that reached :data:`MAX_ERRORS`; the checker stops there."""


class Report:
    """Collects the errors and warnings of one program.

    Parameters
    ----------
    program : Program
        Diagnostics name its file and quote its source.
    already : int
        Errors reported before this collector (a pass on trial counts the
        errors before it towards :data:`MAX_ERRORS`).
    """

    def __init__(self, program: A.Program, already: int = 0):
        self.program = program
        self.already = already
        self.errors: list = []
        self.warnings: list = []

    def error(self, node_or_pos, message: str, hint: str | None = None) -> None:
        """Report an error at a node (or a :class:`~liganimate.lang.ast.Pos`); raise TooMany at the limit."""
        pos = node_or_pos if isinstance(node_or_pos, A.Pos) else node_or_pos.pos
        self.errors.append(Diagnostic(self.program.filename, pos, message, hint, source=self.program.source))
        if self.already + len(self.errors) >= MAX_ERRORS:
            raise TooMany()

    def warning(self, node, message: str, hint: str | None = None) -> None:
        """Report a warning at a node."""
        self.warnings.append(Diagnostic(self.program.filename, node.pos, message, hint, "warning", self.program.source))

    def include(self, diagnostics: list) -> None:
        """Add errors found elsewhere (a library's own), without counting them towards the limit."""
        self.errors.extend(diagnostics)

    def include_warnings(self, diagnostics: list) -> None:
        """Add warnings found elsewhere (a library's own), each once."""
        self.warnings.extend(w for w in diagnostics if w not in self.warnings)

    def trial(self) -> Report:
        """A fresh collector for a pass that may be thrown away; :meth:`absorb` keeps it."""
        return Report(self.program, self.already + len(self.errors))

    def absorb(self, other: Report) -> None:
        """Keep what a trial pass reported."""
        self.errors.extend(other.errors)
        self.warnings.extend(other.warnings)


class Silent:
    """The sink of a settling pass: it reports nothing, so it never stops the pass."""

    def error(self, node_or_pos, message: str, hint: str | None = None) -> None:
        """Drop an error."""

    def warning(self, node, message: str, hint: str | None = None) -> None:
        """Drop a warning."""


SILENT = Silent()
