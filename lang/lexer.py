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
"""

from __future__ import annotations

import re

from lark import Token
from lark.exceptions import UnexpectedCharacters, UnexpectedToken
from lark.lexer import Lexer

_SKIP = r"(?:[ \t\f\r\n]+|\{[^}]*\})*"
_SCAN = re.compile(
    _SKIP
    + r"(?:(?P<w>[A-Za-z][A-Za-z0-9_]*)"
    + r"|(?P<n>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?°?)"
    + r"|(?P<s>'[^'\n]*')"
    + r"|(?P<d>\$[A-Za-z0-9_]*)"
    + r"|(?P<o>::=|:-|:=|<=|>=|<>|/=|[=<>/;,\[\]+\-*()])"
    + r"|(?P<end>\Z))"
)
_NEWLINE = "\n"

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

    def __init__(self, terminals):
        self.names = {t.name for t in terminals}
        # Priority-2 word terminals: (terminal, set of upper-case words, needs lookahead)
        self.strong: dict = {}
        self.plain: dict = {}  # upper-case word -> plain keyword terminal
        self.contextual: set = set()  # words whose terminal depends on the text after them
        for t in terminals:
            pattern = t.pattern
            if t.name in ("NAME", "DOLLAR_NAME", "NUMBER", "STRING", "WS", "BRACE_COMMENT"):
                continue
            if type(pattern).__name__ == "PatternStr" and pattern.value[:1].isalpha():
                self.plain[pattern.value.upper()] = t.name
            elif type(pattern).__name__ == "PatternRE" and t.priority > 0:
                words, lookahead = _words_of(pattern.value)
                for w in words:
                    self.strong.setdefault(w, []).append((t.name, lookahead))
                    if lookahead:
                        self.contextual.add(w)

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
            chars = core[i + 1:j]
            options = [o + ch for o in options for ch in chars]
            i = j + 1
        elif i + 1 < len(core) and core[i + 1] == "?":
            options = options + [o + c for o in options]
            i += 2
        else:
            options = [o + c for o in options]
            i += 1
    return [o.upper() for o in options], lookahead


class LigLexer(Lexer):
    """A Lark lexer (``lexer=LigLexer``) that decides keywords by parser state."""

    __future_interface__ = 2

    def __init__(self, lexer_conf):
        self.tables = GrammarTables(lexer_conf.terminals)
        self.terminals_by_name = lexer_conf.terminals_by_name
        self._accepts: dict = {}  # parser state -> frozenset of terminal names
        self._choice: dict = {}  # (state, word or operator) -> token type

    def _accepted(self, parser_state) -> frozenset:
        state = parser_state.position
        acc = self._accepts.get(state)
        if acc is None:
            acc = self._accepts[state] = frozenset(parser_state.parse_conf.parse_table.states[state])
        return acc

    def lex(self, lexer_state, parser_state):
        text = lexer_state.text
        text = getattr(text, "text", text)  # Lark 1.3 hands over a TextSlice
        pos = 0
        line, line_start = 1, 0
        scan = _SCAN.match
        tables = self.tables
        choice = self._choice
        while True:
            m = scan(text, pos)
            start = m.start(m.lastindex) if m and m.lastindex else -1
            if m is None or start < 0:
                # Nothing we know starts here: skip what can be skipped, report the character.
                skipped = re.match(_SKIP, text[pos:]).end() + pos
                line += text.count(_NEWLINE, pos, skipped)
                line_start = text.rfind(_NEWLINE, 0, skipped) + 1
                raise UnexpectedCharacters(text, skipped, line, skipped - line_start + 1,
                                           allowed=self._accepted(parser_state), state=parser_state)
            nl = text.count(_NEWLINE, pos, start)
            if nl:
                line += nl
                line_start = text.rfind(_NEWLINE, pos, start) + 1
            kind = m.lastgroup
            if kind == "end":
                return
            end = m.end()
            value = text[start:end]
            state = parser_state.position
            if kind == "w":
                word = value.upper()
                key = (state, word)
                ttype = choice.get(key)
                if ttype is None:
                    candidates = tables.word_candidates(word, text, end)
                    # A word such as MOTION may be a type or a variable depending on
                    # what follows it, so its choice is never remembered.
                    ttype = self._pick(candidates, parser_state,
                                       cache=None if word in tables.contextual else key)
            elif kind == "n":
                ttype = "NUMBER"
            elif kind == "o":
                key = (state, value)
                ttype = choice.get(key)
                if ttype is None:
                    ttype, value, end = self._operator(value, start, parser_state)
            elif kind == "s":
                ttype = "STRING"
            else:
                ttype = "DOLLAR_NAME"
            column = start - line_start + 1
            tok = Token(ttype, value, start, line, column, line, column + (end - start), end)
            lexer_state.last_token = tok
            yield tok
            pos = end

    def _pick(self, candidates, parser_state, cache=None) -> str:
        acc = self._accepted(parser_state)
        for c in candidates:
            if c in acc:
                break
        else:
            c = candidates[0]  # what the whole grammar makes of it; the parser will object
        if cache is not None:
            self._choice[cache] = c
        return c

    def _operator(self, greedy: str, start: int, parser_state):
        """The token for the operator ``greedy`` (the longest spelling) at ``start``.

        The longest spelling the state accepts wins; a choice for the whole
        spelling is remembered for the state.
        """
        acc = self._accepted(parser_state)
        for width in range(len(greedy), 0, -1):
            spelling = greedy[:width]
            for ttype in _OPERATORS.get(spelling, ()):
                if ttype in acc:
                    if width == len(greedy):
                        self._choice[(parser_state.position, spelling)] = ttype
                    return ttype, spelling, start + width
        return _OPERATORS[greedy][0], greedy, start + len(greedy)

__all__ = ["LigLexer", "UnexpectedToken"]
