"""lig.lark's statements, written from the productions declared beside their nodes.

A statement's production is declared in lang/ast.py with its node
(``@syntax(rule, statement="...")``, ``@declared(..., statement="...")``,
``R.produce`` for a helper rule; see lang/syntax.py), so that adding a
statement takes its node, its rule and its runtime method, and no edit of
the grammar file. This module writes those productions into lang/lig.lark
between two marker lines, with ``?statement``'s list of alternatives and a
case-insensitive keyword terminal for each word a production uses that the
hand-written part of the grammar does not define. Everything that reads the
grammar (the parser's tables, Lark, the highlighters, the tests) reads
lig.lark as before; ``python -m liganimate.lang.tables`` writes this
section, then the tables, and its ``--check`` fails while either is stale.
"""

from __future__ import annotations

import re

from . import syntax as R

BEGIN = "// >>> statements: written by `python -m liganimate.lang.tables` from lang/ast.py; do not edit"
END = "// <<< end of the statements"

# A word in capitals outside quotes is a terminal; a quoted literal is not a word.
_WORD = re.compile(r"\"(?:[^\"\\]|\\.)*\"|'[^']*'|/(?:[^/\\]|\\.)+/[a-z]*|\b([A-Z][A-Z0-9_]*)\b")
_DEFINED = re.compile(r"^(?:%declare\s+(.+)|([A-Z][A-Z0-9_]*)(?:\.-?\d+)?\s*:)", re.M)


def _split(text: str) -> tuple[str, str, str]:
    """lig.lark as the text before the generated section, the section, and the text after it."""
    start, end = text.find(BEGIN), text.find(END)
    if start < 0 or end < start:
        raise ValueError(f"lig.lark has no generated section: its marker lines {BEGIN!r} and {END!r} are missing")
    after = end + len(END)
    return text[:start], text[start:after], text[after:]


def _terminals(text: str) -> set[str]:
    """The terminals ``text`` (grammar without the generated section) defines or declares."""
    names: set[str] = set()
    for declared, defined in _DEFINED.findall(text):
        names.update(declared.split() if declared else [defined])
    return names


def _words(production: str) -> list[str]:
    """The terminals a production names, in order of first use."""
    found = [m.group(1) for m in _WORD.finditer(production) if m.group(1)]
    return list(dict.fromkeys(found))


def section(hand_written: str) -> str:
    """The generated section for the declarations registered now, given the rest of the grammar's text."""
    lines = [BEGIN, "?statement: " + "\n          | ".join(R.STATEMENTS), ""]
    width = max(len(rule) for rule in R.PRODUCTIONS)
    for rule, production in R.PRODUCTIONS.items():
        lines.append(f"{rule + ':':<{width + 1}} {production}")
    defined = _terminals(hand_written)
    new = [w for p in R.PRODUCTIONS.values() for w in _words(p) if w not in defined]
    if new:
        lines += ["", "// The keywords only these productions use."]
        lines += [f'{word}: "{word}"i' for word in dict.fromkeys(new)]
    lines.append(END)
    return "\n".join(lines)


def fresh_text(text: str) -> str:
    """``text`` (lig.lark) with its generated section made from the declarations of lang/ast.py."""
    from . import ast  # noqa: F401  (registers the productions)

    before, _, after = _split(text)
    return before + section(before + after) + after
