"""Which name the cursor is on, in the current text or, while it is broken, by the tolerant scan.

The navigation features (hover, definition, references, rename) start
here. When the current text parsed, the index of its own analysis says
which variable an offset names. When it does not, the word under the
cursor is taken from the tolerant scan and looked up by name (in the
scope the last good analysis had there), so the answers go on while the
user types; only rename refuses (see :mod:`.navigation`).
"""

from __future__ import annotations

from dataclasses import dataclass

from . import index as I
from . import scan
from .analysis import Analysis


@dataclass(frozen=True)
class Target:
    """The name under the cursor: the word's span in the current text, its variable, and whether the text parsed."""

    word: str
    start: int
    end: int
    key: tuple  # (scope, NAME)
    exact: bool  # found in the current text's own index (not by name)
    occurrence: I.Occurrence | None = None


def word_at(source: str, offset: int) -> scan.Token | None:
    """The word (or number) token under ``offset`` in ``source``, not inside a comment or a quoted word."""
    lo = source.rfind("\n", 0, offset) + 1
    hi = source.find("\n", offset)
    hi = len(source) if hi < 0 else hi
    # Comments may span lines: scan from the start of the text only when a
    # brace is open before the line (rare), else the line alone.
    before = source[:lo]
    start = 0 if before.rfind("{") > before.rfind("}") else lo
    toks = scan.tokens(source[start:hi])
    tok = scan.at(toks, offset - start)
    if tok is None or tok.kind not in ("word", "number"):
        return None
    return scan.Token(tok.kind, tok.start + start, tok.end + start, tok.value)


def target(current: str, offset: int, latest: Analysis | None, good: Analysis | None) -> Target | None:
    """The name at ``offset`` of the text ``current``.

    Parameters
    ----------
    current : str
        The document's text now.
    offset : int
        The cursor.
    latest : Analysis or None
        The analysis of ``current`` itself, if it has finished.
    good : Analysis or None
        The last analysis whose text parsed.
    """
    if latest is not None and latest.parsed and latest.text.source == current and latest.index is not None:
        occ = latest.index.at(offset)
        if occ is not None:
            return Target(occ.name, occ.start, occ.end, occ.key, True, occ)
    tok = word_at(current, offset)
    if tok is None or tok.kind != "word":
        return None
    scope = I.MAIN
    if good is not None and good.index is not None:
        scope = good.index.scope_at(min(offset, len(good.text.source)))
        if (scope, tok.value) not in good.index.by_key:
            scope = I.MAIN
    return Target(tok.value, tok.start, tok.end, (scope, tok.value), False)


__all__ = ["Target", "target", "word_at"]
