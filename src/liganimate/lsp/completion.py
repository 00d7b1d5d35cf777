"""What may be written at the cursor: the parser's own answer, then names, libraries and methods.

Keywords are contextual (docs/language.md, section 1), so the list of
keywords worth offering is the parser's: the text before the cursor is run
through the same LALR tables and scanner the compiler uses
(:class:`liganimate.lang.lalr.Driver`), and the state stack it ends
with says which terminals it takes there, each tried through the
reductions it would cause.
Running all of a long program for each keystroke would cost as much as
parsing it, so the run starts at the statement the cursor is in: the
outermost block open at the cursor, or the nearest line that begins a
statement; only when no such start parses is the whole prefix run.

The terminals become words: each keyword terminal its spellings, NAME the
variables in scope, PRIM_NAME the primitives, CLAUSE_NAME the words of the
primitive being called. After INTERPOLATE come the interpolation methods
(plugins included), after SOLVER the solvers, inside a LOAD's quotes the
standard libraries and the .lig files beside the program, and between
LOAD and FROM the names that library offers.
"""

from __future__ import annotations

import functools
import os
import re
from collections.abc import Collection
from dataclasses import dataclass

from lark.lexer import TerminalDef

from liganimate.lang.lalr import Driver
from liganimate.lang.lexer import END, NUMBER, OPERATOR, SCAN, STRING, WORD, GrammarTables
from liganimate.lang.parser import BUILTIN_PRIMITIVES, grammar
from liganimate.lang.parser import driver as _compiler_driver

from . import scan

#: How many lines before the cursor the blocks open at it are looked for in.
_WINDOW_LINES = 300
#: How far back from the cursor's statement a start is looked for, in lines.
_LINES_BACK = 40
#: The longest prefix run whole when no statement start parses (a 5,000-line program is about 200,000).
MAX_PREFIX = 400_000
#: How many files of the program's folder a LOAD's quotes list at most.
MAX_FILES = 200
_CONTINUED = re.compile(r"(,|\+|-|\*|/|=|:-|:=|\(|<|\bMOD|\bTHEN|\bELSE)\s*$", re.IGNORECASE)


@dataclass(frozen=True)
class Item:
    """One completion: the text to insert, its kind (keyword, variable, primitive...) and a detail line."""

    label: str
    kind: str
    detail: str = ""


def _driver() -> Driver:
    return _compiler_driver()  # the compiler's own loop and tables


@functools.lru_cache(maxsize=1)
def _tables() -> GrammarTables:
    return GrammarTables(grammar().terminals)


def keyword_terminals(terminals: Collection[TerminalDef]) -> dict:
    """``{WORD: frozenset of the terminals it may be}`` for every keyword of the grammar, given its ``terminals``."""
    tables = GrammarTables(terminals)
    out: dict = {}
    for word, term in tables.plain.items():
        out.setdefault(word, set()).add(term)
    for word, entries in tables.strong.items():
        for term, _ in entries:
            out.setdefault(word, set()).add(term)
    return {w: frozenset(t) for w, t in out.items()}


@functools.lru_cache(maxsize=1)
def _words_of_terminal() -> dict:
    out: dict = {}
    for word, terms in keyword_terminals(grammar().terminals).items():
        for t in terms:
            out.setdefault(t, set()).add(word)
    return out


def _stack_after(prefix: str, primitives: frozenset) -> list | None:
    """The parser's state stack after the tokens of ``prefix``, or None if they do not parse.

    The compiler's loop (:meth:`liganimate.lang.lalr.Driver.parse`) with
    the same scanner decisions, keeping states only: no syntax tree is
    built, and the stack is what :func:`_takes` needs to try each terminal.
    """
    driver = _driver()
    actions, rules, scanner = driver.actions, driver.rules, driver.scanner
    keywords = scanner.tables.keywords
    stack = [driver.start]
    pos = 0
    while True:
        m = SCAN.match(prefix, pos)
        if m is None or not m.lastindex or m.lastindex == END:
            return stack if m is not None and m.lastindex == END else None
        k, start, end = m.lastindex, m.start(m.lastindex), m.end()
        value = prefix[start:end]
        state = stack[-1]
        if k == WORD:
            word = value.upper()
            ttype = scanner.keyword(word, state, prefix, end) if word in keywords else "NAME"
            if ttype == "NAME" and word in primitives:
                ttype = "PRIM_NAME"
            if ttype == "NAME" and state in scanner.clause_states:
                ttype = scanner.clause(prefix, end)
        elif k == NUMBER:
            ttype = "NUMBER"
        elif k == OPERATOR:
            ttype, value, end = scanner._operator(value, start, state)
        elif k == STRING:
            ttype = "STRING"
        else:
            ttype = "DOLLAR_NAME"
        pos = end
        if not _feed(stack, ttype, actions, rules):
            return None


def _feed(stack: list, ttype: str, actions: list, rules: dict) -> bool:
    """Reduce and shift terminal ``ttype`` onto ``stack`` (changed in place); False if the grammar refuses it."""
    while True:
        code = actions[stack[-1]].get(ttype)
        if code is None:
            return False
        if code >= 0:
            stack.append(code)
            return True
        size, origin, _ = rules[~code]
        if size:
            del stack[-size:]
        stack.append(actions[stack[-1]][origin])


def accepted(prefix: str, primitives: frozenset) -> frozenset | None:
    """The terminals the parser would take after ``prefix``, or None if ``prefix`` has a syntax error.

    LALR tables merge the lookaheads of states, so a state's table lists
    terminals that a reduction would then refuse; each candidate is tried
    on a copy of the stack, so only what really parses is returned.
    """
    stack = _stack_after(prefix, primitives)
    if stack is None:
        return None
    driver = _driver()
    out = set()
    for ttype in driver.actions[stack[-1]]:
        if ttype[:1].isupper() and _feed(list(stack), ttype, driver.actions, driver.rules):
            out.add(ttype)
    if "$END" in driver.actions[stack[-1]]:
        out.add("$END")
    return frozenset(out)


def _starts(text: str, toks: list, offset: int) -> list:
    """Offsets where the run may start, nearest first: the outermost open block, else line starts before the cursor."""
    opened = scan.open_at(toks, offset)
    anchor = opened[0].start if opened else offset
    line_start = text.rfind("\n", 0, anchor) + 1
    starts = [anchor] if opened else []
    pos = line_start
    for _ in range(_LINES_BACK):
        before = text[:pos].rstrip()
        if not _CONTINUED.search(before[-20:]) and text[pos:offset].strip():
            starts.append(pos)
        if pos == 0:
            break
        pos = text.rfind("\n", 0, pos - 1) + 1
    return list(dict.fromkeys(starts))


def terminals_at(text: str, offset: int, primitives: frozenset) -> frozenset:
    """The terminals the grammar accepts at ``offset`` (the start of the word being typed)."""
    # The blocks are looked for in the last lines only: a block longer than
    # that is found by the whole-prefix run below.
    window = offset
    for _ in range(_WINDOW_LINES):
        window = text.rfind("\n", 0, window)
        if window < 0:
            window = 0
            break
    toks = [scan.Token(t.kind, t.start + window, t.end + window, t.value) for t in scan.tokens(text[window:offset])]
    for start in _starts(text, toks, offset):
        found = accepted(text[start:offset], primitives)
        if found is not None:
            return found
    if offset <= MAX_PREFIX:
        found = accepted(text[:offset], primitives)
        if found is not None:
            return found
    return accepted("", primitives) or frozenset()


def keywords_for(terminals: frozenset) -> list:
    """The keyword spellings of ``terminals``, sorted."""
    words = _words_of_terminal()
    return sorted({w for t in terminals for w in words.get(t, ())})


_LOAD_NAMES = re.compile(r"\bLOAD\s+((?:[A-Za-z][A-Za-z0-9_]*\s*,\s*)*)[A-Za-z0-9_]*$", re.IGNORECASE)
_FROM_AFTER = re.compile(r"^[A-Za-z0-9_]*\s*(?:,\s*[A-Za-z][A-Za-z0-9_]*\s*)*FROM\s+'([^'\n]*)'", re.IGNORECASE)
_IN_QUOTES = re.compile(r"\bLOAD\b[^'\n]*'([^'\n]*)$", re.IGNORECASE)
_METHOD = re.compile(r"\bINTERPOLAT(?:E|ION)\s+[A-Za-z0-9_]*$", re.IGNORECASE)
_SOLVER = re.compile(r"\bSOLVER\s+[A-Za-z0-9_]*$", re.IGNORECASE)


def load_context(text: str, offset: int) -> tuple | None:
    """``("library", typed)`` in a LOAD's quotes, ``("names", library)`` between LOAD and FROM 'library', or None."""
    line_start = text.rfind("\n", 0, offset) + 1
    before = text[line_start:offset]
    m = _IN_QUOTES.search(before)
    if m is not None:
        return ("library", m.group(1))
    if _LOAD_NAMES.search(before):
        line_end = text.find("\n", offset)
        after = text[offset : len(text) if line_end < 0 else line_end]
        m = _FROM_AFTER.match(after)
        if m is not None:
            return ("names", m.group(1))
    return None


def word_context(text: str, offset: int) -> str | None:
    """``"method"`` after INTERPOLATE, ``"solver"`` after SOLVER, else None."""
    line_start = text.rfind("\n", 0, offset) + 1
    before = text[line_start:offset]
    if _METHOD.search(before):
        return "method"
    if _SOLVER.search(before):
        return "solver"
    return None


_MODIFIER_TARGET = re.compile(r"([A-Za-z][A-Za-z0-9_]*)\s*<([^<>;]*)$")
_VARIANTS = {"EXTREMES": ("EXTREME",), "FRAMES": ("FRAME",), "COLOUR": ("COLOR",)}


def modifier_words(before: str, target_type) -> tuple | None:
    """What may continue a modifier of a value of type ``target_type`` after the text ``before``.

    ``before`` ends inside a ``< ... >`` list that follows a name; the
    words already written of the current modifier (``SCALE``) narrow the
    choice (``FRAMES`` for a MOTION; ``MODEL``, ``EXTREMES`` or a value for
    a MODEL). Returns ``(words, value)``: the next words, and whether a
    value may come instead; None when this is not known (no list, no type),
    so the grammar's own choice stands.
    """
    from liganimate.lang.vocabulary import MODIFIERS

    m = _MODIFIER_TARGET.search(before)
    if m is None or target_type is None:
        return None
    written = [w.upper() for w in re.findall(r"[A-Za-z]+", m.group(2).rsplit(",", 1)[-1])]
    labels = [mod.label.split() for mod in MODIFIERS.values() if target_type in mod.targets]
    if not any(words[: len(written)] == written for words in labels):
        return None  # past the modifier's words: the grammar knows
    nxt = set()
    for words in labels:
        if len(words) > len(written) and words[: len(written)] == written:
            word = words[len(written)]
            nxt.add(word)
            nxt.update(_VARIANTS.get(word, ()))
    if not nxt:
        return None  # only a value (or ROT's axis) comes next: the grammar knows
    return frozenset(nxt), bool(written) and written in labels


def methods() -> list:
    """The interpolation methods a keyframe may name, plugins included."""
    from liganimate.runtime.motion import interpolation

    return sorted(interpolation.names())


def solvers() -> list:
    """The REACH solvers' keywords."""
    from liganimate.runtime.ik.solvers import SOLVER_KEYWORDS

    return sorted(SOLVER_KEYWORDS)


def library_files(folder: str | None) -> list:
    """The standard libraries and the ``.lig`` files of ``folder`` (at most MAX_FILES), as a LOAD names them."""
    from liganimate.compiler.library import stdlib_names

    names = [Item(n, "library", "standard library") for n in stdlib_names()]
    if folder and os.path.isdir(folder):
        try:
            with os.scandir(folder) as entries:
                for i, entry in enumerate(entries):
                    if i >= MAX_FILES:
                        break
                    if entry.name.lower().endswith(".lig") and entry.is_file():
                        names.append(Item("./" + entry.name, "file", "a library file beside the program"))
        except OSError:
            pass
    return names


def primitive_words(text: str, offset: int, toks: list, primitives: frozenset) -> str | None:
    """The primitive whose call the cursor is in (the last primitive name before it in the statement), or None."""
    before = [t for t in toks if t.end <= offset and t.kind == "word"]
    for t in reversed(before[-60:]):
        if t.value in primitives:
            return t.value
    return None


__all__ = [
    "BUILTIN_PRIMITIVES",
    "Item",
    "accepted",
    "keyword_terminals",
    "keywords_for",
    "library_files",
    "load_context",
    "methods",
    "modifier_words",
    "primitive_words",
    "solvers",
    "terminals_at",
    "word_context",
]
