"""The lexer: one regular expression, keywords decided by the parser's state.

LIG ANIMATE's keywords are contextual (see lang/lig.lark): WIDTH is a
keyword after VIEW and a variable elsewhere. Lark's own contextual lexer
gets that right by compiling one scanner per parser state, which costs a
tenth of a second at every start and two regex matches per token. This
lexer gives the same tokens with one scanner: it cuts the text into words,
numbers, strings and operators, then asks the parser's current state which
of the word's possible terminals it accepts.

The rules, which are Lark's: a keyword of priority 2 (the regex terminals
such as TYPE_KW or FRAMES) that the state accepts wins; then a plain
keyword the state accepts; then NAME. When the state accepts none of them,
the token is what the whole grammar would make of it, and the parser
reports it as unexpected. Operators take the longest spelling the state
accepts (``<=`` is RELOP in a condition but ``<`` then ``=`` in a modifier
list).

:class:`Scanner` holds those decisions and :mod:`liganimate.lang.lalr`'s
loop makes light :class:`Tok` tuples with them; Lark's own loop is not used
(:class:`TablesOnly`).
"""

from __future__ import annotations

import re
from collections.abc import Collection
from operator import itemgetter
from typing import NoReturn

from lark import Token
from lark.exceptions import UnexpectedCharacters, UnexpectedToken
from lark.lexer import Lexer, TerminalDef

# Possessive (*+, ++): with plain quantifiers a run of n blanks before a
# character that starts no token was split 2**n ways before the match
# failed (30 blanks and a stray "_" took minutes: a hang any file could cause).
_SKIP = r"(?:[ \t\f\r\n]++|\{[^}]*+\})*+"
SCAN = re.compile(
    _SKIP
    + r"(?:(?P<w>[A-Za-z][A-Za-z0-9_]*)"
    + r"|(?P<n>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?°?)"
    + r"|(?P<s>'[^'\n]*')"
    + r"|(?P<d>\$[A-Za-z0-9_]*)"
    + r"|(?P<o>::=|:-|:=|<=|>=|<>|/=|[=<>/;,\[\]+\-*()])"
    # A keyframe table's rows: a run of lines that start with "|", one token (TABLE_ROWS).
    + r"|(?P<t>\|[^\n]*+(?:\n[ \t\r\f]*+\|[^\n]*+)*+)"
    + r"|(?P<end>\Z))"
)
_NEWLINE = "\n"
#: SCAN's groups, by number (Match.lastindex).
WORD, NUMBER, STRING, DOLLAR, OPERATOR, ROWS, END = range(1, 8)

# Operator spellings, longest first, and the terminals each may be (in Lark's order).
_OPERATORS = {
    "::=": ("__ANON_0",),
    ":-": ("ASSIGN_OP",),
    ":=": ("ASSIGN_OP",),
    "<=": ("RELOP",),
    ">=": ("RELOP",),
    "<>": ("RELOP",),
    "/=": ("RELOP",),
    "=": ("RELOP", "ASSIGN_OP", "EQUAL"),
    "<": ("RELOP", "LESSTHAN"),
    ">": ("RELOP", "MORETHAN"),
    "/": ("DIV_OP",),
    ";": ("SEMICOLON",),
    ",": ("COMMA",),
    "[": ("LSQB",),
    "]": ("RSQB",),
    "+": ("PLUS",),
    "-": ("MINUS",),
    "*": ("STAR",),
    "(": ("LPAR",),
    ")": ("RPAR",),
}

# Words that are keywords only when not followed by an assignment or an index:
# "MOTION = ..." assigns a variable called MOTION.
_NOT_BEFORE_ASSIGN = re.compile(r"\s*(:-|:=|=|\[)")


class GrammarTables:
    """What the lexer needs to know about the grammar's terminals, read once."""

    def __init__(self, terminals: Collection[TerminalDef]) -> None:
        self.names = {t.name for t in terminals}
        # Priority-2 word terminals: (terminal, set of upper-case words, needs lookahead)
        self.strong: dict = {}
        self.plain: dict = {}  # upper-case word -> plain keyword terminal
        self.contextual: set = set()  # words whose terminal depends on the text after them
        for t in terminals:
            pattern = t.pattern
            if t.name in (
                "NAME",
                "CLAUSE_NAME",
                "DOLLAR_NAME",
                "NUMBER",
                "STRING",
                "WS",
                "BRACE_COMMENT",
                "TABLE_ROWS",
            ):
                continue
            if type(pattern).__name__ == "PatternStr" and pattern.value[:1].isalpha():
                self.plain[pattern.value.upper()] = t.name
            elif type(pattern).__name__ == "PatternRE" and t.priority > 0:
                words, lookahead = _words_of(pattern.value)
                for w in words:
                    self.strong.setdefault(w, []).append((t.name, lookahead))
                    if lookahead:
                        self.contextual.add(w)
        #: Every word that is a keyword somewhere; any other word is always a NAME.
        self.keywords = frozenset(self.strong) | frozenset(self.plain)

    def word_candidates(self, word: str, text: str, end: int) -> tuple:
        """Terminals the word may be, strongest first (NAME last)."""
        out = []
        for name, lookahead in self.strong.get(word, ()):
            if lookahead and _NOT_BEFORE_ASSIGN.match(text, end):
                continue
            out.append(name)
        plain = self.plain.get(word)
        if plain is not None:
            out.append(plain)
        out.append("NAME")
        return tuple(out)


def _words_of(regex: str):
    """The words a priority-2 keyword regex such as ``FRAMES?\\b`` matches, and whether it has a lookahead."""
    lookahead = "(?!" in regex
    core = regex.split("\\b")[0]
    # The grammar's keyword regexes are small: alternations, one optional
    # letter, one character class. Expand them.
    options = [""]
    i = 0
    core = core.strip("()")
    if "|" in core:
        return [w.upper() for w in core.split("|")], lookahead
    while i < len(core):
        c = core[i]
        if c == "[":
            j = core.index("]", i)
            chars = core[i + 1 : j]
            options = [o + ch for o in options for ch in chars]
            i = j + 1
        elif i + 1 < len(core) and core[i + 1] == "?":
            options = options + [o + c for o in options]
            i += 2
        else:
            options = [o + c for o in options]
            i += 1
    return [o.upper() for o in options], lookahead


class Tok(tuple):
    """A token: a tuple with the attribute names of Lark's ``Token``.

    The parser makes millions of them for a big program, and a tuple is made
    in C, where a Lark ``Token`` (a ``str`` with eight attributes set one by
    one) costs several times as much. Tokens never outlive the parse: the
    transformer turns them into positions and names.
    """

    __slots__ = ()
    type = property(itemgetter(0))
    value = property(itemgetter(1))
    start_pos = property(itemgetter(2))
    line = property(itemgetter(3))
    column = property(itemgetter(4))
    end_line = property(itemgetter(3))  # a token never spans lines (but TABLE_ROWS; see lalr.Driver.parse)
    end_column = property(itemgetter(5))
    end_pos = property(itemgetter(6))

    def __repr__(self) -> str:
        return f"Tok({self[0]!r}, {self[1]!r})"

    def as_lark(self) -> Token:
        """The same token as a Lark ``Token`` (for Lark's own parser and its exceptions)."""
        return Token(self[0], self[1], self[2], self[3], self[4], self[3], self[5], self[6])


_new_tok = tuple.__new__


class Scanner:
    """Cuts text into :class:`Tok` tokens, asking the parser's state which terminal each word is.

    ``states`` is the LALR table (a list: state -> the symbols it accepts). The
    loop that cuts the text is :meth:`liganimate.lang.lalr.Driver.parse`
    (scanning and parsing in one loop, as a generator between them cost a
    fifth of the time); the decisions it asks for are here: which terminal
    a keyword is in a state (:meth:`keyword`), which spelling of an
    operator (:meth:`_operator`), and the error for a character that
    starts no token.
    """

    def __init__(self, terminals: Collection[TerminalDef], states: list) -> None:
        self.tables = GrammarTables(terminals)
        self.states = states
        self._accepts: dict = {}  # parser state -> frozenset of terminal names
        self._choice: dict[tuple[object, str], str] = {}  # (state, word or operator) -> token type
        #: The parser states where a primitive's clause may start (they take CLAUSE_NAME).
        self.clause_states = frozenset(state for state, acts in enumerate(states) if "CLAUSE_NAME" in acts)

    def accepted(self, state) -> frozenset:
        """The symbols parser state ``state`` accepts."""
        acc = self._accepts.get(state)
        if acc is None:
            acc = self._accepts[state] = frozenset(self.states[state])
        return acc

    def keyword(self, word: str, state, text: str, end: int) -> str:
        """The terminal the keyword ``word`` (upper-cased, ending at ``end``) is in parser state ``state``."""
        key = (state, word)
        ttype = self._choice.get(key)
        if ttype is None:
            candidates = self.tables.word_candidates(word, text, end)
            # A word such as MOTION may be a type or a variable depending on
            # what follows it, so its choice is never remembered.
            ttype = self._pick(candidates, state, cache=None if word in self.tables.contextual else key)
        return ttype

    @staticmethod
    def clause(text: str, end: int) -> str:
        """What a NAME ending at ``end`` is in a state that takes a clause: CLAUSE_NAME, or NAME before an assignment.

        LALR(1) cannot tell ``P1 WIDTH 2`` (a clause) from ``P1`` followed by
        the statement ``B :- P1`` by the name alone; what follows the name
        can: a clause's word is followed by its value, a statement's name by
        ``=``, ``:=``, ``:-`` or ``[``, which no value starts with.
        """
        return "NAME" if _NOT_BEFORE_ASSIGN.match(text, end) else "CLAUSE_NAME"

    def unexpected_character(self, text: str, pos: int, line: int, state) -> NoReturn:
        """Raise UnexpectedCharacters for the first character after ``pos`` that starts no token."""
        blank = re.compile(_SKIP).match(text, pos)
        assert blank is not None  # _SKIP matches the empty string, so it matches anywhere
        skipped = blank.end()
        line += text.count(_NEWLINE, pos, skipped)
        line_start = text.rfind(_NEWLINE, 0, skipped) + 1
        raise UnexpectedCharacters(text, skipped, line, skipped - line_start + 1, allowed=self.accepted(state))

    def _pick(self, candidates, state, cache=None) -> str:
        acc = self.accepted(state)
        for c in candidates:
            # NAME stands for CLAUSE_NAME where a clause may start (the caller decides which, by what follows).
            if c in acc or (c == "NAME" and state in self.clause_states):
                break
        else:
            c = candidates[0]  # what the whole grammar makes of it; the parser will object
        if cache is not None:
            self._choice[cache] = c
        return c

    def _operator(self, greedy: str, start: int, state) -> tuple[str, str, int]:
        """The token for the operator ``greedy`` (the longest spelling) at ``start``.

        The longest spelling the state accepts wins; a choice for the whole
        spelling is remembered for the state.
        """
        acc = self.accepted(state)
        for width in range(len(greedy), 0, -1):
            spelling = greedy[:width]
            for ttype in _OPERATORS.get(spelling, ()):
                if ttype in acc:
                    if width == len(greedy):
                        self._choice[(state, spelling)] = ttype
                    return ttype, spelling, start + width
        return _OPERATORS[greedy][0], greedy, start + len(greedy)


class TablesOnly(Lexer):
    """The lexer Lark is told about, so that it keeps the tables: it never scans.

    The one loop that scans is :meth:`liganimate.lang.lalr.Driver.parse`,
    which asks :class:`Scanner` for its decisions; a second scanning loop for
    Lark's own ``Lark.parse`` would be the same rules written twice. Lark
    builds this class when it computes the tables from the grammar (cheaply,
    unlike its contextual lexer, which compiles a scanner per parser state),
    and ``Lark.parse`` is refused plainly.
    """

    __future_interface__ = 2

    def __init__(self, lexer_conf) -> None:
        self.terminals = lexer_conf.terminals

    def lex(self, lexer_state, parser_state):
        """Refuse: liganimate parses with :func:`liganimate.lang.parser.parse`."""
        raise NotImplementedError("liganimate parses with liganimate.lang.parser.parse, not Lark.parse")


__all__ = ["Scanner", "TablesOnly", "Tok", "UnexpectedToken"]
