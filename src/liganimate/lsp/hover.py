"""What hover shows: a keyword's reference text, or a name's type, value and origin.

A keyword gets its section of docs/language.md (:mod:`.reference`). A
name gets its type as the checker settled it, where it is defined (or
which library it comes from, with the library's ``{@ NAME: ...}``
description), and what the text fixes about its value (:mod:`.statics`):
a number or vector, a model's joints with their extremes, a motion's
length and the joints it drives. A primitive shows how it is called.
"""

from __future__ import annotations

from liganimate.compiler.primitives import builtin_signatures
from liganimate.lang.vocabulary import FUNCTIONS

from . import index as I
from . import reference, statics
from .analysis import Analysis
from .lookup import Target, word_at


def _type_of(a: Analysis, key: tuple) -> str | None:
    scope, name = key
    checked = a.checked
    if checked is None:
        # The checks failed elsewhere: the type the text shows (the value's kind).
        return _kind_of(a.env.values.get(name)) if scope == I.MAIN and a.env is not None else None
    if scope == I.MAIN:
        found = checked.main.types.get(name)
        return found
    entry = checked.primitives.get(scope)
    if entry is not None and entry[2] is not None:
        return entry[2].types.get(name)
    return None


def _kind_of(value) -> str | None:
    if isinstance(value, statics.ModelValue):
        return "MODEL"
    if isinstance(value, statics.MotionValue):
        return "MOTION"
    if isinstance(value, statics.Graphic):
        return "GRAPHICAL"
    # A number's type may change with a later assignment (INTEGER, then REAL): only the checker settles it.
    return "VECTOR" if isinstance(value, tuple) and len(value) == 3 else None


def _signature(a: Analysis | None, name: str):
    if a is not None and a.checked is not None and name in a.checked.primitives:
        return a.checked.primitives[name][1]
    return builtin_signatures().get(name)


def _line_of(a: Analysis, occ: I.Occurrence) -> int:
    return a.text.source.count("\n", 0, occ.start) + 1


def name_hover(a: Analysis, key: tuple) -> str | None:
    """Markdown for the variable or primitive ``key`` of analysis ``a``, or None if ``a`` does not know it."""
    scope, name = key
    lines = []
    info = a.libraries.get(name) if scope == I.MAIN else None
    sig = _signature(a, name) if scope == I.MAIN else None
    definition = a.index.definition(key) if a.index is not None else None
    if sig is not None and (info is None or info.offered.get(name) == "PRIMITIVE"):
        lines.append(f"**{name}**: PRIMITIVE")
        lines.append(f"```lig\n{sig.usage()}\n```")
    else:
        kind = _type_of(a, key) or (info.offered.get(name) if info is not None else None)
        if kind is None and definition is None and info is None:
            return None
        head = f"**{name}**" + (f": {kind}" if kind else "")
        if scope != I.MAIN:
            head += f" (in PRIMITIVE {scope})"
        lines.append(head)
    if info is not None:
        lines.append(f"loaded from '{info.name}'")
        if name in info.descriptions:
            lines.append(info.descriptions[name])
    elif definition is not None and definition.role != "use":
        lines.append(f"{_WHAT.get(definition.role, 'defined')} at line {_line_of(a, definition)}")
    if scope == I.MAIN and a.env is not None:
        value = statics.describe(a.env.values.get(name))
        if value is not None:
            lines.append(value)
    return "\n\n".join(lines)


_WHAT = {
    "declaration": "declared",
    "assignment": "first assigned",
    "parameter": "a parameter of the primitive's pattern",
    "primitive": "defined",
    "load": "loaded",
}


def keyword_hover(word: str) -> str | None:
    """The reference text of keyword or built-in function ``word``, or None."""
    return reference.table().get(word)


def hover(
    current: str, offset: int, where: Target | None, latest: Analysis | None, good: Analysis | None
) -> tuple | None:
    """``(Markdown, start, end)`` for the cursor at ``offset``, or None.

    Parameters
    ----------
    current : str
        The document's text now.
    offset : int
        The cursor.
    where : Target or None
        The name under the cursor (:func:`.lookup.target`).
    latest, good : Analysis or None
        The analysis of the current text, and the last one that parsed.
    """
    tok = word_at(current, offset)
    if tok is None or tok.kind != "word":
        return None
    source = latest if latest is not None and latest.parsed and latest.text.source == current else good
    if where is not None and where.exact and source is not None:
        text = name_hover(source, where.key)
        if text is not None:
            return text, where.start, where.end
    exact = source is latest and source is not None
    keyword = keyword_hover(tok.value)
    known = source is not None and where is not None and name_hover(source, where.key)
    if keyword is not None and (exact or not known or tok.value in FUNCTIONS):
        return keyword, tok.start, tok.end
    if known:
        return known, tok.start, tok.end
    return None


__all__ = ["hover", "keyword_hover", "name_hover"]
