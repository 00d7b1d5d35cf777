"""A document's text and its positions: offsets, LIG lines and columns, and the client's units.

LIG counts lines by line feeds only (a form feed or a carriage return stays
in its line, as in :mod:`liganimate.lang.source`), and its columns are
characters (code points). An editor counts columns in the position
encoding the client and server agreed on (UTF-16 unless it offered
another); :class:`Text` converts between the three with one table of line
starts, so a conversion costs a bisection, not a pass over the text.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

from lsprotocol import types as lsp


def _units(encoding: str, chars: str) -> int:
    """How many code units of ``encoding`` the characters ``chars`` take."""
    if encoding == lsp.PositionEncodingKind.Utf32:
        return len(chars)
    if encoding == lsp.PositionEncodingKind.Utf8:
        return len(chars.encode("utf-8", errors="surrogatepass"))
    return len(chars) + sum(1 for c in chars if ord(c) > 0xFFFF)


@dataclass
class Text:
    """One version of a document: its text, and conversions between its offsets and the client's positions.

    Attributes
    ----------
    source : str
        The text as the editor holds it.
    encoding : str
        The position encoding agreed with the client (``utf-16`` by default).
    """

    source: str
    encoding: str = lsp.PositionEncodingKind.Utf16
    starts: list = field(init=False, repr=False)  # offset of each line's first character

    def __post_init__(self) -> None:
        starts = [0]
        find = self.source.find
        i = find("\n")
        while i >= 0:
            starts.append(i + 1)
            i = find("\n", i + 1)
        self.starts = starts

    def line_text(self, line: int) -> str:
        """The text of 0-based line ``line`` without its line feed ("" past the end)."""
        if not 0 <= line < len(self.starts):
            return ""
        end = self.starts[line + 1] - 1 if line + 1 < len(self.starts) else len(self.source)
        return self.source[self.starts[line] : end]

    def offset(self, position: lsp.Position) -> int:
        """The character offset of a client position (clamped into the text)."""
        line = position.line
        if line >= len(self.starts):
            return len(self.source)
        text = self.line_text(line)
        if self.encoding == lsp.PositionEncodingKind.Utf32:
            col = min(position.character, len(text))
        else:
            col, used = 0, 0
            while col < len(text) and used < position.character:
                used += _units(self.encoding, text[col])
                col += 1
        return self.starts[line] + col

    def position(self, offset: int) -> lsp.Position:
        """The client position of character offset ``offset``."""
        offset = max(0, min(offset, len(self.source)))
        line = bisect.bisect_right(self.starts, offset) - 1
        start = self.starts[line]
        return lsp.Position(line=line, character=_units(self.encoding, self.source[start:offset]))

    def range(self, start: int, end: int) -> lsp.Range:
        """The client range of the offsets ``start`` to ``end``."""
        return lsp.Range(start=self.position(start), end=self.position(end))

    def offset_of(self, line: int, column: int) -> int:
        """The offset of a LIG position: 1-based ``line`` and ``column`` (characters), clamped into the text."""
        if line < 1:
            return 0
        if line > len(self.starts):
            return len(self.source)
        text = self.line_text(line - 1)
        return self.starts[line - 1] + max(0, min(column - 1, len(text)))

    def lig_range(self, line: int, column: int, end_line: int, end_column: int) -> lsp.Range:
        """The client range of a LIG span (1-based, end exclusive), at least one character wide where it can be."""
        start = self.offset_of(line, column)
        end = self.offset_of(end_line, end_column)
        if end <= start:
            end = min(start + 1, self.starts[line] - 1 if line < len(self.starts) else len(self.source))
            end = max(end, start)
        return self.range(start, end)

    def line_count(self) -> int:
        """The number of lines (a text ending in a line feed has an empty last line)."""
        return len(self.starts)


__all__ = ["Text"]
