"""A tolerant scan of LIG text: words, comments, strings and blocks, whatever state the text is in.

The parser stops at the first error; an editor's text is broken most of
the time it is being typed. This scan never fails: it cuts the text into
words, numbers, quoted words, comments and operators (an unclosed comment
or quoted word runs to the end of the text or the line), and pairs the
block words (STARTMODEL ... ENDMODEL, DO 10 ... 10 CONTINUE...) as far as
they pair. Folding, the words under the cursor and the fallbacks of
completion and rename read it; the parser's tree is preferred wherever the
text parses.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from liganimate.lang.source import prepare
from liganimate.lang.vocabulary import BLOCKS

_TOKEN = re.compile(
    r"(?P<comment>\{[^}]*\}?)"
    r"|(?P<string>'[^'\n]*'?)"
    r"|(?P<word>[A-Za-z][A-Za-z0-9_]*)"
    r"|(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?°?)"
    r"|(?P<dollar>\$[A-Za-z0-9_]*)"
    r"|(?P<op>::=|:-|:=|<=|>=|<>|/=|[=<>/;,\[\]+\-*():])"
)
_C_LINE = re.compile(r"^[Cc](?:[ \t\r][^\n]*)?$", re.MULTILINE)

_CLOSER = {b.opener: b.closer for b in BLOCKS if b.opener != "JOINT"}
_CLOSERS = frozenset(_CLOSER.values())


@dataclass(frozen=True, slots=True)
class Token:
    """One piece of text: ``kind`` is comment, string, word, number, dollar or op; ``value`` is upper-cased."""

    kind: str
    start: int
    end: int
    value: str


@dataclass(frozen=True, slots=True)
class Block:
    """A block as far as its words pair: ``end`` is the offset after its closing word, or None if unclosed."""

    opener: str
    start: int
    end: int | None


def tokens(text: str) -> list:
    """The tokens of ``text``, comment lines (``C`` in column 1) included as comments."""
    out = []
    lexed = prepare(text, "").lexed  # C lines and * flags blanked, offsets kept
    for m in _C_LINE.finditer(text):
        if lexed[m.start() : m.end()].strip() == "" and m.group().strip():
            out.append(Token("comment", m.start(), m.end(), ""))
    for m in _TOKEN.finditer(lexed):
        kind = m.lastgroup or "op"
        value = m.group().upper() if kind == "word" else m.group()
        out.append(Token(kind, m.start(), m.end(), value))
    out.sort(key=lambda t: t.start)
    return out


def at(toks: list, offset: int) -> Token | None:
    """The token that holds ``offset`` (or ends exactly there), or None between tokens."""
    lo, hi = 0, len(toks)
    while lo < hi:
        mid = (lo + hi) // 2
        if toks[mid].end < offset:
            lo = mid + 1
        else:
            hi = mid
    if lo < len(toks) and toks[lo].start <= offset <= toks[lo].end:
        return toks[lo]
    return None


def blocks(toks: list) -> list:
    """The blocks of the text, paired as a reader would pair them, in order of their opening words.

    A block word counts where a statement may start: STARTMODEL and the
    others anywhere, BEGIN after THEN or ELSE, ``DO label`` with its
    ``label CONTINUE``. JOINT, which begins a right-hand side too, is a
    block only inside STARTMOTION, where ENDJOINT may close it; it is not
    folded on its own.
    """
    words = [t for t in toks if t.kind in ("word", "number")]
    stack: list = []  # (opener, start, label)
    found: list = []
    prev = ""
    for i, t in enumerate(words):
        v = t.value
        if t.kind == "word" and v in _CLOSER and (v != "BEGIN" or prev in ("THEN", "ELSE")):
            stack.append((v, t.start, None))
        elif t.kind == "word" and v == "DO" and i + 1 < len(words) and words[i + 1].kind == "number":
            stack.append(("DO", t.start, words[i + 1].value))
        elif t.kind == "word" and v == "CONTINUE" and prev.isdigit():
            for j in range(len(stack) - 1, -1, -1):
                if stack[j][0] == "DO" and stack[j][2] == prev:
                    # Loops sharing a label all close here.
                    for opener, start, _ in stack[j:]:
                        found.append(Block(opener, start, t.end))
                    del stack[j:]
                    break
        elif t.kind == "word" and v in _CLOSERS:
            for j in range(len(stack) - 1, -1, -1):
                if _CLOSER.get(stack[j][0]) == v:
                    found.append(Block(stack[j][0], stack[j][1], t.end))
                    del stack[j:]
                    break
        prev = v
    found.extend(Block(opener, start, None) for opener, start, _ in stack)
    return sorted(found, key=lambda b: b.start)


def open_at(toks: list, offset: int) -> list:
    """The blocks open at ``offset`` (outermost first)."""
    inside = []
    for b in blocks([t for t in toks if t.start < offset]):
        if b.end is None or b.end > offset:
            inside.append(b)
    return inside


__all__ = ["Block", "Token", "at", "blocks", "open_at", "tokens"]
