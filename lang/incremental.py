"""Parsing one text again and again as it is edited: only the part around the change is parsed.

An editor sends the whole program after every keystroke, and the language
server must answer a 5,000-line program within 200 ms; parsing it whole
took most of that. A :class:`Reparser` keeps, from its last parse, the
list of top-level statements and a :class:`~.lalr.Mark` at the first
token of each: the parser's exact state there. For the next text it

1. finds the changed span (the longest common start and end of the two
   texts);
2. goes on from the last Mark before the change, whose token and the
   lexer's look past it lie in the unchanged start, so the parser is where
   a whole parse of the new text would be (from the start of the text when
   the change is in the first statement);
3. stops at the first Mark past the change (on a later line) where the
   parser's states and the token are those of a Mark of the last parse at
   the same place in the unchanged end: from there the whole parse would do
   what the last one did, so the statements after it are the last parse's,
   moved down by the lines and characters the change added (copies:
   an older syntax tree is never changed).

The result is the list a whole parse gives, positions included, and a
syntax error is the one a whole parse reports, since the parser meets it
in the same state. tests/lang/test_incremental.py checks both on random
edits of real programs, broken text included.

The trees of successive parses share the statements before the change, so
they must not be taken apart (``lower(consume=True)``); the language
server, which only reads them, is the one user.
"""

from __future__ import annotations

import bisect
import dataclasses
import re

from . import ast as A
from . import visitor
from .lalr import Mark, _Inlined
from .lexer import Tok

_new_int = int.__new__
_new_tuple = tuple.__new__
_M12, _M24, _M32 = A._M12, A._M24, A._M32
#: The lexer decides a token by looking at most this far past the first non-blank character after it
#: (``a 1e+5`` exponent, ``:=`` after a word: lang/lexer.py); a resumed parse keeps that much unchanged.
_LOOK = 3
_NON_BLANK = re.compile(r"\S")


@dataclasses.dataclass
class _Last:
    """The last parse: its text, primitives, statements (before DO grouping) and Marks (by offset)."""

    text: str
    primitives: frozenset
    statements: list
    marks: list
    offsets: list  # marks[i].tok start, ascending
    passed: bool = False  # whether its statements passed the nesting checks (lang/structure.py)


class Reparser:
    """Parses successive versions of one text, each as :meth:`.lalr.Driver.parse` would, reusing the last parse.

    Parameters
    ----------
    driver : lang.lalr.Driver
        The parser.
    finish : callable
        What the start rule makes of the list of statements (the
        transformer's ``start``): applied to the list a resumed parse puts
        together.
    """

    def __init__(self, driver, finish) -> None:
        self.driver = driver
        self.finish = finish
        self.last: _Last | None = None
        self.reused = 0  # characters of the last text not parsed again (for tests and benchmarks)
        #: The statements of the last parse not known to pass the nesting checks (the others are
        #: those, or copies of those, of a parse that passed them), or None for all of them.
        self.fresh: list | None = None
        self._between: int | None = None

    def parse(self, text: str, primitives: frozenset):
        """The start rule's value for ``text``, as a whole parse gives it.

        Raises what :meth:`.lalr.Driver.parse` raises on a syntax error;
        the last parse is kept then, for the next text.
        """
        last, self.reused, self.fresh = self.last, 0, None
        if last is not None and last.primitives == primitives and last.marks:
            if last.text == text:
                self.reused = len(text)
                self.fresh = [] if last.passed else None
                return self.finish(list(last.statements))
            return self._resume(last, text)
        watch = _Watch(self._between_state(), None, text, primitives)
        value = self.driver.parse(text, primitives, watch=watch)
        self._keep(watch, watch.statements)
        return value

    def _between_state(self) -> int:
        """The parser's state after one or more statements, read once from a parse of two of them."""
        if self._between is None:
            seen: list = []

            def look(stack, values, line, line_start):
                if type(values[0]) is _Inlined:
                    seen.append(stack[1])
                return False

            self.driver.parse("A = 1\nB = 1\n", frozenset(), watch=look)
            self._between = seen[0]
        return self._between

    def _resume(self, last: _Last, text: str):
        """Parse ``text`` from the last Mark before its change from ``last.text`` (or from its start, if none)."""
        old = last.text
        head = _common_start(old, text)
        tail = _common_end(old, text, min(len(old), len(text)) - head)
        k = bisect.bisect_left(last.offsets, head) - 1
        while k >= 0 and _lexed_before(text, last.marks[k].tok, head) is False:
            k -= 1
        watch = _Watch(self._between_state(), last, text, last.primitives)
        watch.kept = last.marks[: k + 1]
        watch.changed_end = len(text) - tail
        watch.shift = len(text) - len(old)
        if k < 0:  # a change in the first statement: from the start, but the last parse still takes over after it
            first, resume, self.reused = 0, None, 0
        else:
            mark = last.marks[k]
            first, self.reused = mark.preceding, mark.tok[6]
            watch.statements = last.statements[:first]
            resume = (mark, watch.statements)
        value = self.driver.parse(text, last.primitives, resume=resume, watch=watch)
        statements = watch.statements
        self._keep(watch, statements)
        if last.passed and statements is not None:
            self.fresh = statements[first : watch.taken_at]
        self.reused += watch.reused_tail
        if watch.result is None:
            return value  # the parse went on to the end of the text
        return self.finish(list(watch.result))

    def forget(self) -> None:
        """Parse the next text whole."""
        self.last = None

    def passed(self) -> None:
        """Note that the last parse's statements passed the nesting checks (lang/structure.py)."""
        if self.last is not None:
            self.last.passed = True

    def _keep(self, watch: _Watch, statements: list | None) -> None:
        """Keep this parse for the next one (not one with no Mark: there is nothing to go on from)."""
        marks = watch.marks()
        if statements is None or not marks:
            self.last = None
            return
        self.last = _Last(watch.text, watch.primitives, statements, marks, [m.tok[2] for m in marks])


class _Watch:
    """What a parse does at each Mark: note it and, in a resumed parse, stop where the last parse takes over."""

    def __init__(self, between: int, last: _Last | None, text: str, primitives: frozenset) -> None:
        self.between, self.last, self.text, self.primitives = between, last, text, primitives
        self.new: list = []  # Marks of this parse
        self.kept: list = []  # Marks of the last parse before the resumed one (unchanged)
        self.moved: list = []  # Marks of the last parse after the stop, moved
        self.statements: list | None = None  # this parse's list of statements, once known
        self.changed_end = 0  # the change ends here in this text
        self.shift = 0  # characters the change added
        self.result: list | None = None  # the list of statements, when the last parse took over
        self.reused_tail = 0
        self.taken_at: int | None = None  # the number of statements parsed when the last parse took over

    def __call__(self, stack: list, values: list, line: int, line_start: int) -> bool:
        if stack[1] != self.between or type(values[0]) is not _Inlined:
            return False
        statements, tok = values[0][0], values[1]
        self.statements = statements
        if self.last is not None and tok[2] - tok[4] + 1 >= self.changed_end:
            if self._take_over(stack, statements, tok):
                return True
        self.new.append(Mark((stack[0], stack[1], stack[2]), len(statements), tok, line, line_start))
        return False

    def _take_over(self, stack: list, statements: list, tok: Tok) -> bool:
        """Whether the last parse has a Mark here, the same; if so, append its statements from there, moved."""
        last = self.last
        assert last is not None
        at = tok[2] - self.shift
        i = bisect.bisect_left(last.offsets, at)
        if i == len(last.offsets) or last.offsets[i] != at:
            return False
        old = last.marks[i]
        if old.stack != (stack[0], stack[1], stack[2]) or old.tok[0] != tok[0] or old.tok[1] != tok[1]:
            return False
        lines = tok[3] - old.tok[3]
        shift = _Shift(lines, self.shift)
        added = len(statements) - old.preceding
        self.taken_at = len(statements)
        statements.extend(shift.value(s) for s in last.statements[old.preceding :])
        self.moved = [_moved_mark(m, lines, self.shift, added) for m in last.marks[i:]]
        self.reused_tail = len(self.text) - tok[2]
        self.result = statements
        return True

    def marks(self) -> list:
        """This parse's Marks, in order: kept from the last parse, made now, moved from the last parse."""
        return self.kept + self.new + self.moved


def _moved_mark(m: Mark, lines: int, chars: int, added: int) -> Mark:
    t = m.tok
    tok = _new_tuple(Tok, (t[0], t[1], t[2] + chars, t[3] + lines, t[4], t[5], t[6] + chars))
    return Mark(m.stack, m.preceding + added, tok, m.line + lines, m.line_start + chars)


def _lexed_before(text: str, tok: Tok, head: int) -> bool:
    """Whether the token, and all the lexer looked at to make it, lie before offset ``head``."""
    after = _NON_BLANK.search(text, tok[6], head)
    return after is not None and after.start() + _LOOK <= head


def _common_start(a: str, b: str) -> int:
    """The length of the longest common start of ``a`` and ``b`` (halving: each step compares in C)."""
    lo, hi = 0, min(len(a), len(b))
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if a[lo:mid] == b[lo:mid]:
            lo = mid
        else:
            hi = mid - 1
    return lo


def _common_end(a: str, b: str, most: int) -> int:
    """The length of the longest common end of ``a`` and ``b``, at most ``most``."""
    la, lb = len(a), len(b)
    lo, hi = 0, most
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if a[la - mid : la - lo] == b[lb - mid : lb - lo]:
            lo = mid
        else:
            hi = mid - 1
    return lo


class _Shift:
    """Copies of syntax trees, every position moved down ``lines`` lines and ``chars`` characters.

    A position on a line the change did not touch keeps its columns; one
    without offsets (0 and 0: made by the parser, not read from the text)
    keeps them, and NOWHERE stays where it is. A node the parser puts in
    two places (a PRIMITIVE's pattern is also in its body) is copied once.
    """

    def __init__(self, lines: int, chars: int) -> None:
        self.lines, self.chars = lines, chars
        self.packed = lines + (chars << 60)
        self.memo: dict = {}

    def pos(self, p: A.Pos) -> A.Pos:
        """``p`` moved."""
        if p >= 0:
            if not p & _M24:
                return p  # NOWHERE, or a position of no line
            line = (p & _M24) + self.lines
            if p >> 60 == 0:
                if line <= _M24:
                    return _new_int(A.Pos, p + self.lines)
            elif line <= _M24 and (p >> 60 & _M32) + self.chars <= _M32:
                return _new_int(A.Pos, p + self.packed)
        if p.line == 0:
            return p
        offsets = (p.start + self.chars, p.end + self.chars) if p.start or p.end else (0, 0)
        return A.Pos(p.line + self.lines, p.column, p.end_line + self.lines, p.end_column, *offsets)

    def value(self, v):
        """A copy of ``v`` (a node, a list, a tuple or dict of them, a position or a plain value), moved."""
        t = type(v)
        copy = _COPIERS.get(t)
        if copy is not None:
            return copy(v, self)
        if t is A.Pos:
            return self.pos(v)
        if t is list:
            return [self.value(x) for x in v]
        if isinstance(v, A.Node):
            return _copier(t)(v, self)
        if t is tuple:
            return tuple(self.value(x) for x in v)
        if t is dict:
            return {k: self.value(x) for k, x in v.items()}
        return v  # names, numbers, words: no position

    def shared(self, v, copy):
        """``copy(v, self)``, made once however often ``v`` is met (a PRIMITIVE's pattern is also in its body)."""
        done = self.memo.get(id(v))
        if done is None:
            done = self.memo[id(v)] = copy(v, self)
        return done


_COPIERS: dict = {}
#: Fields the checker fills in (compiler/statements.py), which a parse leaves at their default.
_FILLED_LATER = {(A.MotionTable, "data")}
#: Node types the parser puts in two places of one tree; their copies are shared likewise.
_SHARED = {A.PatternDef}
#: Field types that hold a list of nodes (never None), and those that hold nothing to move.
_LISTS = {"list"}


def _copier(cls):
    """A function copying a node of type ``cls`` with its positions moved (made once per type)."""
    args = []
    for f in dataclasses.fields(cls):
        kind = getattr(f.type, "__name__", f.type)
        if (cls, f.name) in _FILLED_LATER:
            args.append("None")
        elif kind == "Pos":
            args.append(f"s.pos(n.{f.name})")
        elif kind in visitor._SCALAR:
            args.append(f"n.{f.name}")
        elif kind in _LISTS:
            args.append(f"[value(x) for x in n.{f.name}]")
        else:
            args.append(f"value(n.{f.name})")
    namespace = {"cls": cls}
    # Made from the dataclass' own field names (never from program text), as dataclasses makes __init__.
    body = f"def copy(n, s):\n    value = s.value\n    return cls({', '.join(args)})\n"
    exec(body, namespace)  # noqa: S102
    copy = namespace["copy"]
    if cls in _SHARED:
        plain = copy

        def copy(n, s):
            return s.shared(n, plain)

    _COPIERS[cls] = copy
    return copy


__all__ = ["Reparser"]
