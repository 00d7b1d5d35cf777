"""The canonical layout of a LIG ANIMATE program (``liganimate fmt``).

The layout is made from the parser's own tokens (each typed as the parser
took it: WIDTH a keyword after VIEW, a name elsewhere) and the text between
them, never from a second grammar:

- one statement a line, blocks indented by two blanks (a model's JOINTs, a
  motion's JOINTs and their keyframes, a scene's two parts, a primitive's
  body, BEGIN ... END, DO loops, a REACH's goals), ``;`` between statements
  dropped;
- keywords upper case, names, numbers and quoted words as written;
- one blank around binary operators and assignments, after commas, none
  inside brackets or after a sign;
- a line longer than :data:`WIDTH` is wrapped after commas, a JOINT's
  arguments as the thesis lays them out (the parent and its offset, the
  child and its offset, the extremes, each on a line of its own);
- every comment stays where it was: a ``{ comment }`` after a token on its
  line stays after it, one on a line of its own stays on a line of its own,
  a C comment line stays a C comment line, word for word; one blank line
  between statements is kept where there was at least one.

A file in the thesis' listing convention (C comment lines, ``*`` flags in
column 1) keeps it: its statements start in column 7, and a statement that
carried a ``*`` flag carries it on every line.

A PRINT statement keeps its spacing: its labels are its expressions' text
(lang/source.py's ``spelling``). The layout is checked before it is given
back: the formatted text must parse to the same program, positions aside
(:func:`meaning`), or :class:`LayoutError` is raised.
"""

from __future__ import annotations

import bisect
import dataclasses
import re

from . import ast as A
from .parser import parse_source
from .source import Source, prepare, spelling

#: The longest line the layout makes where it can break one.
WIDTH = 88
#: One level of block indentation.
INDENT = "  "
#: How much further a statement's continuation lines are indented.
CONTINUATION = "    "
#: Where statements start in a file in the thesis' listing convention (column 7).
LISTING_MARGIN = " " * 6

# Token types whose spelling is kept as written; every other word is a keyword.
_AS_WRITTEN = frozenset({"NAME", "CLAUSE_NAME", "PRIM_NAME", "NUMBER", "STRING", "DOLLAR_NAME", "TABLE_ROWS"})
# After one of these a + or - is binary; anywhere else it is a sign.
_OPERAND_ENDS = frozenset({"NUMBER", "NAME", "RPAR", "RSQB", "MORETHAN", "PRIM_NAME", "DOLLAR_NAME", "STRING"})
_NO_SPACE_AFTER = frozenset({"LPAR", "LSQB", "LESSTHAN"})
_NO_SPACE_BEFORE = frozenset({"RPAR", "RSQB", "COMMA", "MORETHAN", "SEMICOLON"})
_OPENING = frozenset({"LPAR", "LSQB", "LESSTHAN"})
_CLOSING = frozenset({"RPAR", "RSQB", "MORETHAN"})
# Statements that start with a keyword and open no block.
_STATEMENTS = frozenset(
    {
        "TYPE_KW",
        "IF",
        "FIGURE",
        "ANIMATE",
        "BACKGROUND",
        "PRINT",
        "VIEW",
        "SHOOTSCENES",
        "LOAD",
        "STOP",
        "RETURN",
        "DRAW",
    }
)
# Block openers and the frame each pushes.
_OPENERS = {
    "DO": "DO",
    "STARTMODEL": "MODEL",
    "STARTMOTION": "MOTION",
    "STARTREACH": "REACH",
    "INITIALIZE": "SCENE",
    "PRIMITIVE": "PRIMITIVE",
}
_CLOSERS = {"ENDMODEL": "MODEL", "ENDMOTION": "MOTION", "ENDREACH": "REACH", "ENDSCENE": "SCENE"}
# Words that close a block (or its first part): a comment before one is indented as the block's body.
_CLOSING_WORDS = frozenset({"END", "ENDJOINT", "STARTSCENE", "ELSE", *_CLOSERS})
_REACH_ITEMS = frozenset({"GOAL", "MOVE", "TRANSLATE", "SOLVER", "TOLERANCE", "ITERATIONS"})
# A line that would read as a C comment line if it started in column 1.
_PATTERN_BREAKS = frozenset({"STRING", "LSQB", "LESSTHAN"})
_C_LINE = re.compile(r"[Cc](?:[ \t\r]|$)")
_GAP = re.compile(r"\{[^}]*\}|\n")
_DROP = -1  # the plan of a ";" between statements: not written


class LayoutError(Exception):
    """The layout would have changed what the program means; nothing is written (a bug of the formatter)."""


@dataclasses.dataclass(frozen=True)
class Comment:
    """A comment between two tokens: a ``{ ... }`` or a whole C comment line, as written."""

    text: str
    own_line: bool  # it started its line (else it trails the token before it)
    star: bool = False  # its line carried a * flag in column 1


#: A blank line between two things.
BLANK = Comment("", True)


def format_source(source: Source, primitives: frozenset | set = frozenset()) -> str:
    """The program ``source`` in the canonical layout.

    Parameters
    ----------
    source : Source
        The prepared program (:func:`liganimate.lang.source.prepare`).
    primitives : set
        Primitive names the program's LOADs bring in (the lexer must know them).

    Raises
    ------
    LigDiagnostics
        The program does not parse.
    LayoutError
        The formatted text would not mean the same program (never expected).
    """
    tokens: list = []
    before = parse_source(source, primitives, tokens)
    text = _Layout(source, tokens, _labels(before)).render()
    after = parse_source(prepare(text, source.filename), primitives)
    if meaning(before, source.text) != meaning(after, text):
        raise LayoutError(f"the layout of {source.filename} would change its meaning")
    return text


def format_text(text: str, filename: str = "<string>", primitives: frozenset | set = frozenset()) -> str:
    """:func:`format_source` for program text."""
    return format_source(prepare(text, filename), primitives)


def meaning(program: A.Program, text: str) -> tuple:
    """What a parsed program means, positions aside: two layouts of one program give equal values.

    Every node is its type and its fields, without positions; a PRINT item
    adds its label (its expression's text, which the program prints).
    """
    return tuple(_stripped(s, text) for s in program.body)


def _stripped(value, text: str):
    if isinstance(value, A.Pos):
        return None
    if isinstance(value, (list, tuple)):
        return tuple(_stripped(v, text) for v in value)
    if isinstance(value, dict):
        return tuple(sorted((k, _stripped(v, text)) for k, v in value.items()))
    if not isinstance(value, A.Node):
        return value
    fields = [_stripped(getattr(value, f.name), text) for f in dataclasses.fields(value) if f.name != "pos"]
    if isinstance(value, A.PrintItem) and isinstance(value.value, A.Node) and value.kind == "value":
        fields.append(spelling(text, value.value.pos))
    return (type(value).__name__, *fields)


def _labels(program: A.Program) -> list:
    """The spans ``(start, end)`` of the PRINT items whose text is their label, in any block."""
    from .visitor import children

    spans: list = []
    todo = list(program.body)
    while todo:
        node = todo.pop()
        if isinstance(node, A.PrintItem):
            if node.kind == "value" and isinstance(node.value, A.Node):
                spans.append((node.value.pos.start, node.value.pos.end))
        elif isinstance(node, A.Node) and not isinstance(node, (A.Num, A.Var, A.Name)):
            todo.extend(children(node))
    return sorted(spans)


# ------------------------------------------------------------ the text between tokens


def _gaps(text: str, lexed: str, tokens: list) -> list:
    """The comments and blank lines before each token, and after the last: ``len(tokens) + 1`` lists."""
    bounds = [0] + [t[6] for t in tokens]
    ends = [t[2] for t in tokens] + [len(text)]
    return [_gap(text, lexed, a, b, first=i == 0) for i, (a, b) in enumerate(zip(bounds, ends))]


def _line_starred(text: str, lexed: str, at: int) -> bool:
    """Whether the line holding offset ``at`` has a ``*`` flag in column 1."""
    start = text.rfind("\n", 0, at) + 1
    return text.startswith("*", start) and lexed[start] == " "


def _gap(text: str, lexed: str, a: int, b: int, first: bool) -> list:
    items: list = []
    newlines = 0  # line breaks since the last thing (a token or a comment)
    own = first

    def c_line(at: int) -> None:
        nonlocal newlines
        if text.startswith(("C", "c"), at) and lexed[at] == " ":
            end = text.find("\n", at)
            if newlines >= 2 and (items or not first):
                items.append(BLANK)
            items.append(Comment(text[at : len(text) if end < 0 else end].rstrip(), True))
            newlines = 0

    if a == 0:
        c_line(0)
    for m in _GAP.finditer(lexed, a, b):
        at = m.start()
        if lexed[at] == "\n":
            newlines += 1
            own = True
            c_line(at + 1)
            continue
        if own and newlines >= 2 and (items or not first):
            items.append(BLANK)
        items.append(Comment(text[at : m.end()], own, own and _line_starred(text, lexed, at)))
        newlines, own = 0, False
    if newlines >= 2 and (items or not first):
        items.append(BLANK)
    return items


# ------------------------------------------------------------ which token starts a line


class _Blocks:
    """Decides, token by token, which tokens start a line and how deep in blocks each line is.

    :meth:`plan` gives, per token, the depth of the line it starts, None
    when it continues a line, or ``_DROP`` for a ``;`` between statements.
    """

    def __init__(self, tokens: list) -> None:
        self.tokens = tokens
        self.stack: list = []  # open blocks: [kind, DO label]
        self.pattern = False  # inside a primitive's pattern (between ::= and ;)
        #: The tokens of primitives' patterns.
        self.in_pattern: set = set()
        self.handlers = {
            "BEGIN": self._begin,
            "END": self._end,
            "ENDJOINT": self._endjoint,
            "STARTSCENE": self._startscene,
            "JOINT": self._joint,
            "ROOT": self._root,
            "TABLE": self._root,
            "SHAPE": self._root,
            "SCALE": self._morph,
            "TABLE_ROWS": self._rows,
            "FRAME": self._frame,
            "NAME": self._name,
            "PRIM_NAME": self._name,
            "NUMBER": self._number,
            "SEMICOLON": lambda i: _DROP,
        }

    def plan(self) -> list:
        """Per token: the depth of the line it starts, None, or ``_DROP``."""
        plans = [self._token(i) for i in range(len(self.tokens))]
        if plans and plans[0] is None:
            plans[0] = 0
        return plans

    def _token(self, i: int):
        ttype = self.tokens[i][0]
        if self.pattern:
            self.in_pattern.add(i)
            self.pattern = ttype != "SEMICOLON"
            return None
        if ttype in _STATEMENTS:
            return self._statement(i)
        if ttype in _OPENERS:
            depth = self._statement(i)
            self.stack.append([_OPENERS[ttype], self._label(i + 1)])
            return depth
        if ttype in _CLOSERS:
            return self._close(_CLOSERS[ttype])
        if ttype in _REACH_ITEMS:
            return len(self.stack) if self._top() == "REACH" else None
        handler = self.handlers.get(ttype)
        return handler(i) if handler is not None else None

    def _top(self):
        return self.stack[-1][0] if self.stack else None

    def _type(self, i: int):
        return self.tokens[i][0] if 0 <= i < len(self.tokens) else None

    def _label(self, i: int):
        value = self.tokens[i][1] if i < len(self.tokens) else ""
        try:
            return int(float(value.rstrip("°")))
        except ValueError:
            return value

    def _statement(self, i: int):
        """A statement starts a line, except a branch of IF written after its THEN or ELSE."""
        return None if self._type(i - 1) in ("THEN", "ELSE") else len(self.stack)

    def _close(self, kind: str):
        if kind == "MOTION" and self._top() in ("JOINT", "TABLE"):
            self.stack.pop()
        if self._top() == kind:
            self.stack.pop()
        return len(self.stack)

    def _begin(self, i: int):
        self.stack.append(["BEGIN", None])
        return None

    def _end(self, i: int):
        if self._top() in ("BEGIN", "PRIMITIVE"):
            self.stack.pop()
        return len(self.stack)

    def _endjoint(self, i: int):
        if self._top() == "JOINT":
            self.stack.pop()
        return len(self.stack)

    def _startscene(self, i: int):
        return len(self.stack) - 1 if self._top() == "SCENE" else len(self.stack)

    def _joint(self, i: int):
        if self._top() == "MODEL":
            return len(self.stack)
        return self._root(i)

    def _root(self, i: int):
        """A motion's JOINT, ROOT or TABLE entry: its keyframes (a table's rows) are indented under it."""
        if self._top() == "TABLE" and self._type(i - 1) in ("TABLE", "COMMA"):
            return None  # ROOT among a table's columns
        if self._top() not in ("MOTION", "JOINT", "TABLE"):
            return None
        if self._top() in ("JOINT", "TABLE"):
            self.stack.pop()
        depth = len(self.stack)
        self.stack.append(["TABLE" if self._type(i) == "TABLE" else "JOINT", None])
        return depth

    def _morph(self, i: int):
        """SCALE LINK starts a motion's morph entry (elsewhere SCALE is a modifier's word)."""
        return self._root(i) if self._type(i + 1) == "LINK" else None

    def _rows(self, i: int):
        """A keyframe table's rows (one token, written as it is): on lines of their own, under the TABLE."""
        return len(self.stack)

    def _frame(self, i: int):
        return len(self.stack) if self._top() == "JOINT" else None

    def _name(self, i: int):
        after = self._type(i + 1)
        if after == "__ANON_0":
            self.pattern = True
            return len(self.stack)
        if after == "ASSIGN_OP" or after == "LSQB":
            return self._statement(i)
        return None

    def _number(self, i: int):
        if self._type(i + 1) != "CONTINUE":
            return None
        label = self._label(i)
        while self._top() == "DO" and self.stack[-1][1] == label:
            self.stack.pop()
        return len(self.stack)


# ------------------------------------------------------------ writing the lines


class _Layout:
    """Writes the tokens of one program, with its comments, in the canonical layout."""

    def __init__(self, source: Source, tokens: list, labels: list) -> None:
        self.text = source.text
        self.labels = labels
        self.tokens = tokens
        self.gaps = _gaps(source.text, source.lexed, tokens)
        blocks = _Blocks(tokens)
        self.plans = blocks.plan()
        self.in_pattern = blocks.in_pattern
        starred = {i for i, t in enumerate(tokens) if _line_starred(source.text, source.lexed, t[2])}
        listing = bool(starred) or any(c.text and not c.text.startswith("{") for g in self.gaps for c in g)
        self.margin = LISTING_MARGIN if listing else ""
        self.starred = starred
        self.unary = {
            i
            for i, t in enumerate(tokens)
            if t[0] in ("MINUS", "PLUS") and (i == 0 or tokens[i - 1][0] not in _OPERAND_ENDS)
        }
        self.lines: list = []
        self.depth = 0  # of the last statement written

    def _continue_label(self, i: int) -> bool:
        return self.tokens[i][0] == "NUMBER" and i + 1 < len(self.tokens) and self.tokens[i + 1][0] == "CONTINUE"

    def render(self) -> str:
        """The whole program, one string ending in a newline (empty for an empty file)."""
        starts = [i for i, p in enumerate(self.plans) if p is not None and p != _DROP]
        for k, first in enumerate(starts):
            last = starts[k + 1] if k + 1 < len(starts) else len(self.tokens)
            self._unit(first, last)
        self._comments(self.gaps[len(self.tokens)], self.margin, final=True)
        while self.lines and not self.lines[-1]:
            self.lines.pop()
        return "".join(line + "\n" for line in self.lines)

    def _indent(self, depth: int) -> str:
        return self.margin + INDENT * depth

    def _comments(self, items: list, indent: str, final: bool = False) -> bool:
        """Write the comments of a gap; True when one ended a line (the next token starts a new one)."""
        broke = False
        for c in items:
            if c is BLANK:
                if self.lines and self.lines[-1] and not final:
                    self.lines.append("")
                continue
            if not c.own_line and self.lines:
                self.lines[-1] += " " + c.text
                broke = broke or "\n" in c.text
                continue
            if not c.text.startswith("{"):  # a C comment line, in column 1
                self.lines.append(c.text)
            else:
                self.lines.append(_starred(indent, c.text) if c.star else indent + c.text)
            broke = True
        return broke

    def _unit(self, first: int, last: int) -> None:
        """One statement (or block word), tokens ``first`` to ``last - 1``, with the comments among them."""
        depth = self.plans[first]
        indent = self._indent(depth)
        # Comments before a word that closes a block belong to the block's last statements.
        closing = self.tokens[first][0] in _CLOSING_WORDS or self._continue_label(first)
        self._comments(self.gaps[first], self._indent(max(depth, self.depth)) if closing else indent)
        self.depth = depth
        star = any(i in self.starred for i in range(first, last))
        # A statement holding a PRINT label is not wrapped: a line break there would change the label.
        verbatim = any(self._in_label(self.tokens[i][2], self.tokens[i][6]) for i in range(first, last))
        parts: list = [[]]  # runs of atoms (space, text, token index), and comments on lines of their own
        kept = [i for i in range(first, last) if self.plans[i] != _DROP]
        # The comments after the last word written (before a ";", which is dropped) are
        # written after the statement is laid out, as they are once the ";" is gone
        # (they are then the next statement's): else the layout would change on a second pass.
        end = kept[-1] + 1 if kept else last
        for i in range(first, end):
            if self.plans[i] != _DROP:
                atoms = parts[-1]
                atoms.append((self._space(i) if atoms else "", self._spelling(i), i))
            if i + 1 < end:
                self._gap_atoms(self.gaps[i + 1], parts)
        lead = indent
        for part in parts:
            if isinstance(part, Comment):
                self._comments([part], indent + CONTINUATION)
                continue
            if not part:
                continue
            for n, line in enumerate(_wrap(part, lead, self.tokens, verbatim)):
                here = lead if n == 0 else indent + CONTINUATION
                self.lines.append(_starred(here, line[len(here) :]) if star else _column_one(line))
            lead = indent + CONTINUATION
        for k in range(end, last):
            self._comments(self.gaps[k], indent)

    @staticmethod
    def _gap_atoms(items: list, parts: list) -> None:
        """The comments inside a statement: one after a token stays after it, others break the line."""
        for c in items:
            if c is BLANK:
                continue
            if not c.own_line and isinstance(parts[-1], list):
                parts[-1].append((" " if parts[-1] else "", c.text, None))
                if "\n" in c.text:
                    parts.append([])
                continue
            parts.extend([c, []])

    def _in_label(self, start: int, end: int) -> bool:
        """Whether the text from ``start`` to ``end`` lies inside a PRINT label."""
        k = bisect.bisect_right(self.labels, (start, float("inf"))) - 1
        return k >= 0 and self.labels[k][1] >= end

    def _spelling(self, i: int) -> str:
        ttype, value = self.tokens[i][0], self.tokens[i][1]
        return value if ttype in _AS_WRITTEN else value.upper()

    def _space(self, i: int) -> str:
        """The blank before token ``i`` on its line: '' or ' ' (or, inside a PRINT label, the blanks as written)."""
        prev, cur = self.tokens[i - 1], self.tokens[i]
        if self._in_label(prev[6], cur[2]):
            # The blanks as written, unless a line break or a comment is among them: PRINT's
            # labels keep a run of blanks and turn any other gap into one (source.spelling).
            gap = self.text[prev[6] : cur[2]]
            return gap if "\n" not in gap and "{" not in gap else " "
        if prev[0] in _NO_SPACE_AFTER or cur[0] in _NO_SPACE_BEFORE or i - 1 in self.unary:
            return ""
        if cur[0] in ("LPAR", "LSQB") and prev[0] == "NAME" and i not in self.in_pattern:
            return ""  # a call F(X), an indexed keyframe M[1, 2]
        return " "


def _starred(lead: str, rest: str) -> str:
    """A line with a ``*`` flag in column 1."""
    return ("*" + lead[1:] if lead else "* ") + rest


def _column_one(line: str) -> str:
    """A statement line that would read as a C comment line, moved off column 1."""
    return " " + line if _C_LINE.match(line) else line


def _wrap(atoms: list, lead: str, tokens: list, verbatim: bool) -> list:
    """The atoms ``(space, text, token index)`` as lines, the first starting with ``lead``, each within WIDTH where it can.

    A line breaks where the fewest brackets are open (after a comma, before
    a binary + or -, before a TO), as late as fits. Continuation lines start
    with ``lead`` and :data:`CONTINUATION`, or under a JOINT's parent (see
    :func:`_break_points`).
    """
    flat = lead + "".join(space + text for space, text, _ in atoms)
    if verbatim or _width(flat) <= WIDTH:
        return [flat]
    candidates, forced, column = _break_points(atoms, tokens, lead)
    continuation = " " * column if column is not None else lead + CONTINUATION
    lines: list = []
    bounds = [0, *sorted(forced), len(atoms)]
    current = lead
    for a, b in zip(bounds, bounds[1:]):
        if a:
            lines.append(current)
            current = continuation
        chunk = atoms[a:b] if not a else [("", atoms[a][1], atoms[a][2]), *atoms[a + 1 : b]]
        lines_here, current = _fill(
            chunk, {c - a: d for c, d in candidates.items() if a < c < b}, current, continuation
        )
        lines.extend(lines_here)
    lines.append(current)
    return lines


def _fill(atoms: list, candidates: dict, current: str, continuation: str) -> tuple:
    """Lay ``atoms`` out after ``current`` (a line's indentation): the full lines, and the last (open) line.

    Each line takes as many atoms as fit, then breaks at the candidate among
    them with the fewest brackets open (the latest of those); when none
    fits, at the first candidate after them.
    """
    lines: list = []
    while atoms:
        room = WIDTH - len(current)
        end, used = 0, 0
        while end < len(atoms) and used + len(atoms[end][0]) + _width(atoms[end][1]) <= room:
            used += len(atoms[end][0]) + _width(atoms[end][1])
            end += 1
        if end == len(atoms):
            break
        fits = [c for c in candidates if 0 < c <= end]
        later = [c for c in candidates if c > end]
        if not fits and not later:
            break
        cut = min(fits, key=lambda c: (candidates[c], -c)) if fits else min(later)
        lines.append(current + "".join(space + text for space, text, _ in atoms[:cut]))
        # A break inside brackets is indented one step further per bracket open.
        current = continuation + CONTINUATION * candidates[cut]
        atoms = [("", atoms[cut][1], atoms[cut][2]), *atoms[cut + 1 :]]
        candidates = {c - cut: d for c, d in candidates.items() if c > cut}
    return lines, current + "".join(space + text for space, text, _ in atoms)


def _width(text: str) -> int:
    """How far ``text`` reaches on its line: a comment of several lines ends the line it starts on."""
    end = text.find("\n")
    return len(text) if end < 0 else end


def _break_points(atoms: list, tokens: list, lead: str) -> tuple:
    """Where a long line may break: ``(candidates, forced, column)``.

    ``candidates`` maps an index into ``atoms`` (the line breaks before that
    atom) to the number of brackets open there: after a comma, before a
    binary + or -, before a TO; in a primitive's pattern before a quoted
    word, a ``[`` or a ``<``. For a JOINT's arguments the breaks after the
    parent's offset and after the child's offset are ``forced``, and
    ``column`` puts the lines after the first under the parent; otherwise it
    is None.
    """
    candidates, commas, joint = _candidates(atoms, tokens)
    # A comment after a token stays on its line: a break before it moves after it.
    candidates = {_after_comments(atoms, c): d for c, d in sorted(candidates.items(), reverse=True)}
    candidates = {c: d for c, d in candidates.items() if c < len(atoms)}
    mine = [_after_comments(atoms, n) for n, d in commas[joint:] if d == 0] if joint is not None else []
    if len(mine) < 5:
        return candidates, set(), None
    column = len(lead) + len("".join(space + text for space, text, _ in atoms[: mine[0]])) + 1
    return candidates, {n for n in (mine[2], mine[4]) if n < len(atoms)}, column


def _candidates(atoms: list, tokens: list) -> tuple:
    """The breaks a line may take (index -> brackets open), its commas ``(index, depth)``, and where a JOINT is.

    ``joint`` is the number of commas before the first JOINT outside
    brackets, or None.
    """
    depth = 0
    candidates: dict = {}
    commas: list = []  # (atom index after the comma, depth)
    joint = None
    pattern = False
    for n, (_space, _text, i) in enumerate(atoms):
        ttype = tokens[i][0] if i is not None else None
        if n and (ttype == "TO" or ttype in ("PLUS", "MINUS") and _space or pattern and ttype in _PATTERN_BREAKS):
            candidates[n] = depth
        pattern = pattern or ttype == "__ANON_0"
        if ttype in _OPENING:
            depth += 1
        elif ttype in _CLOSING:
            depth = max(0, depth - 1)
        elif ttype == "COMMA" and n + 1 < len(atoms):
            candidates[n + 1] = depth
            commas.append((n + 1, depth))
        elif depth == 0 and ttype == "JOINT" and joint is None:
            joint = len(commas)
    return candidates, commas, joint


def _after_comments(atoms: list, n: int) -> int:
    """The first index from ``n`` on that is not a comment."""
    while n < len(atoms) and atoms[n][2] is None:
        n += 1
    return n
