"""Go to definition, find references and rename.

Definition and references use the index of the current text when it
parsed, and the last good analysis (by name, in the scope the cursor was
in) or the tolerant scan's words when it does not. A name a LOAD brings is
defined in the library's file, which is opened for it
(:mod:`.libraries`). Rename changes one variable's every occurrence in the
file; it needs the current text to parse (a rename guessed from broken
text could change the wrong words), refuses a name the language reserves
or one the scope already uses, and refuses loaded names, whose definition
is another file's.
"""

from __future__ import annotations

from dataclasses import dataclass

from liganimate.compiler.names import definable
from liganimate.lang.parser import BUILTIN_PRIMITIVES

from . import index as I
from . import scan
from .analysis import Analysis
from .lookup import Target


@dataclass(frozen=True)
class Place:
    """A span of a file: its path (None for the document itself) and offsets into that file's text."""

    path: str | None
    start: int
    end: int


class RenameRefused(Exception):
    """A rename that cannot be done; the message says why, in one sentence."""


def definition(where: Target, current: str, latest: Analysis | None, good: Analysis | None) -> Place | None:
    """Where the name ``where`` is defined: in this file, or in the library that brings it."""
    source = latest if latest is not None and latest.parsed else good
    if source is None:
        return _scanned_definition(where, current)
    info = source.libraries.get(where.word) if where.key[0] == I.MAIN else None
    local = source.index.definition(where.key) if source.index is not None else None
    if info is not None and (local is None or local.role in ("load", "use")):
        occ = info.index.definition((I.MAIN, where.word))
        if occ is not None:
            return Place(info.path, occ.start, occ.end)
    if local is None:
        return _scanned_definition(where, current)
    if source is latest and latest.text.source == current:
        return Place(None, local.start, local.end)
    # The text changed since: find the same name by the scan, nearest the old place.
    return _scanned_definition(where, current, near=local.start)


def _scanned_definition(where: Target, current: str, near: int | None = None) -> Place | None:
    words = [t for t in scan.tokens(current) if t.kind == "word" and t.value == where.word]
    if not words:
        return None
    if near is not None:
        best = min(words, key=lambda t: abs(t.start - near))
    else:
        best = words[0]
    return Place(None, best.start, best.end)


def references(where: Target, current: str, latest: Analysis | None, include_definition: bool = True) -> list:
    """Every occurrence of the name ``where`` in the document (offsets into ``current``)."""
    if where.exact and latest is not None and latest.index is not None:
        found = latest.index.references(where.key)
        if not include_definition:
            first = latest.index.definition(where.key)
            found = [o for o in found if o is not first]
        return [Place(None, o.start, o.end) for o in found]
    words = [t for t in scan.tokens(current) if t.kind == "word" and t.value == where.word]
    return [Place(None, t.start, t.end) for t in words]


def prepare(where: Target | None, latest: Analysis | None) -> Target:
    """The name a rename at the cursor would change; raises RenameRefused if there is none to rename."""
    if where is None:
        raise RenameRefused("there is no name here to rename")
    if not where.exact or latest is None or latest.index is None:
        raise RenameRefused("the text does not parse: fix the error first, then rename")
    if where.key[0] == I.MAIN and where.word in latest.libraries:
        info = latest.libraries[where.word]
        raise RenameRefused(f"{where.word} comes from the library '{info.name}': rename it there")
    if where.word in BUILTIN_PRIMITIVES and latest.index.definition(where.key) is None:
        raise RenameRefused(f"{where.word} is the built-in primitive")
    first = latest.index.definition(where.key)
    if first is None or first.role not in I.DEFINING:
        raise RenameRefused(f"{where.word} is not defined in this file")
    return where


def rename(where: Target, new_name: str, latest: Analysis) -> list:
    """The places to change to rename ``where`` to ``new_name``; raises RenameRefused if it may not be."""
    prepare(where, latest)
    assert latest.index is not None  # prepare checked it
    new = new_name.strip()
    if not definable(new):
        raise RenameRefused(
            f"{new!r} cannot name a variable: a name is a letter then letters, digits or _, not a keyword"
        )
    upper = new.upper()
    if upper == where.word:
        return []
    scope = where.key[0]
    taken = (scope, upper) in latest.index.by_key or (I.MAIN, upper) in latest.index.by_key
    if taken or upper in latest.libraries or upper in BUILTIN_PRIMITIVES:
        raise RenameRefused(f"{upper} is already a name in this program")
    return [Place(None, o.start, o.end) for o in latest.index.references(where.key)]


__all__ = ["Place", "RenameRefused", "definition", "prepare", "references", "rename"]
