"""The LALR(1) loop that :func:`liganimate.lang.parser.parse` runs: Lark's tables, a lean driver.

Lark builds the tables and the callbacks (its tree builder wrapped around
:class:`~liganimate.lang.transform.ToAst`), and its own loop would run them
correctly; but it finds each rule's callback in a dict keyed by ``Rule``
objects, whose hash and equality are Python methods, and it calls the
callback of every one-child ``?rule`` (``?sum: product``) only to hand the
child back. On a program of a million short lines that loop was most of
the parse. Here the tables are numbered for the loop (lang/tables.py ships
them so): a state's actions map a symbol to an int (a shift's next state,
or ``~rule``), rules are a list, and a one-child ``?rule`` only changes the
state on top of the stack.

The tree is the one Lark's loop builds (tests/lang/test_lexer.py checks
this against Lark's stock contextual lexer and loop), and errors are Lark's
``UnexpectedToken`` and ``UnexpectedCharacters``, as before.
"""

from __future__ import annotations

import functools
from operator import itemgetter
from typing import NamedTuple

from lark.exceptions import UnexpectedToken
from lark.lexer import Token
from lark.parse_tree_builder import ChildFilterLALR_NoPlaceholders, ExpandSingleChild

from .lexer import DOLLAR, NUMBER, OPERATOR, ROWS, SCAN, STRING, WORD, Scanner, Tok
from .tables import ParserTables, callback, refuse_terminal_callbacks


class _Inlined(tuple):
    """The value of a ``_rule``, which its parent's child filter splices in.

    Lark makes a ``Tree`` for it (through the transformer's ``__default__``)
    only for the parent to read ``.children``: one per statement of a
    program, for nothing. This is that ``.children`` and no more.
    """

    __slots__ = ()
    children = property(itemgetter(0))


_new_tuple = tuple.__new__


def _inline(children: list) -> _Inlined:
    return _new_tuple(_Inlined, (children,))


def _unwatched(stack: list, values: list, line: int, line_start: int) -> bool:
    """The ``watch`` of a parse nobody watches: go on."""
    return False


def _inlined(callback):
    """``callback`` with Lark's tree for an inlined ``_rule`` replaced by :class:`_Inlined`.

    Only the two shapes Lark's tree builder gives such a rule are changed (a
    child filter around the default callback, or the default callback
    alone); any other is kept as it is, which is slower but the same.
    """

    def is_default(f):
        return isinstance(f, functools.partial) and getattr(f.func, "__name__", "") == "default_callback"

    if type(callback) is ChildFilterLALR_NoPlaceholders and is_default(callback.node_builder):
        return ChildFilterLALR_NoPlaceholders(callback.to_include, _inline)
    if is_default(callback):
        return _inline
    return callback


class Driver:
    """An LALR parser's tables and callbacks, ready for :meth:`parse`.

    :meth:`parse` cuts the text and runs the LALR loop in one loop: a
    generator between them cost a fifth of the time. What a word or an
    operator is in a state is the :class:`~.lexer.Scanner`'s decision.

    Parameters
    ----------
    tables : liganimate.lang.tables.ParserTables
        The states, rules and terminals (shipped in the package, or computed
        from a Lark parser by :func:`liganimate.lang.tables.from_lark`).
    transformer : lark.Transformer
        Makes the values: Lark's tree builder wraps its methods into each
        rule's callback, as ``Lark(..., transformer=transformer)`` would.
    """

    def __init__(self, tables: ParserTables, transformer) -> None:
        refuse_terminal_callbacks(tables, transformer)
        #: (number of symbols, the rule's name, callback or None for "keep the child"), by rule number.
        self.rules: dict = _Rules(tables.rules, transformer)
        #: state -> {symbol: next state, or ~rule to reduce}
        self.actions: list = tables.actions
        self.start = tables.start
        self.end = tables.end
        self.scanner = Scanner(tables.terminals, tables.actions)
        self._chains = _Chains(self)  # see _Chains

    @staticmethod
    def _rule(rule, callback):
        size = len(rule.expansion)
        # Lark's ExpandSingleChild hands a lone child back without calling the
        # transformer; when nothing else wraps it, the reduction is a no-op.
        keeps_child = (
            size == 1
            and type(callback) is ExpandSingleChild
            and not rule.expansion[0].is_term
            and not rule.expansion[0].name.startswith("_")
        )
        if keeps_child:
            return size, rule.origin.name, None
        if rule.origin.name.startswith("_"):
            callback = _inlined(callback)
        return size, rule.origin.name, callback

    def parse(self, text: str, primitives: frozenset, tokens: list | None = None, resume=None, watch=_unwatched):
        """Parse ``text``; a NAME in ``primitives`` is a PRIM_NAME. Returns the start rule's value.

        ``tokens``, if given, receives every :class:`~.lexer.Tok`, typed as the parser took it (lang/formatter.py);
        ``resume`` and ``watch`` go on from, and stop at, a :class:`Mark` (see there).
        """
        actions, rules, chains, scanner, accept = self.actions, self.rules, self._chains, self.scanner, self.end
        keywords, clause_states, choice = scanner.tables.keywords, scanner.clause_states, scanner._choice
        word_type, spellings = self._keyword_type, _Spellings()
        stack, values, state, pos, line, line_start, tok = _begin(self.start, resume)
        push_state, push_value, scan, count = stack.append, values.append, SCAN.match, text.count
        ttype: str | None  # None only between a missed operator choice and _operator
        end_tok: Token | None = None  # set once the text has ended
        while True:
            # ------------------------------------------------ next token
            m = scan(text, pos)
            if m is None:
                scanner.unexpected_character(text, pos, line, state)
            k = m.lastindex
            assert k  # a match always ends in one of the groups; this narrows k for mypy
            start = m.start(k)
            if start != pos:
                nl = count("\n", pos, start)
                if nl:
                    line += nl
                    line_start = text.rfind("\n", pos, start) + 1
            end = m.end()
            value = text[start:end]
            if k == WORD:
                if (word := value.upper()) in keywords:
                    ttype = word_type(word, state, text, end, primitives)
                else:
                    ttype = "PRIM_NAME" if word in primitives else "NAME"
                    if state in clause_states and ttype == "NAME":
                        ttype = scanner.clause(text, end)
            elif k == NUMBER:
                ttype, value = "NUMBER", spellings[value]
            elif k == OPERATOR:
                ttype = choice.get((state, value))
                if ttype is None:
                    ttype, value, end = scanner._operator(value, start, state)
            else:
                ttype = _FIXED.get(k, "$END")  # $END is fed like a token: it reduces what is left
            if ttype == "$END":
                end_tok = _end_token(tok)
            else:
                column = start - line_start + 1
                tok = _new_tuple(Tok, (ttype, value, start, line, column, column + end - start, end))
                pos = end
                line, line_start = _past_rows(text, start, end, line, line_start) if k == ROWS else (line, line_start)
                if tokens is not None:
                    tokens.append(tok)
            # ------------------------------------------------ feed it
            while True:
                code = actions[state].get(ttype)
                if code is None:
                    raise self._unexpected(_lookahead(tok, end_tok), state)
                if code >= 0:
                    push_state(code)
                    push_value(tok)
                    state = code
                    if len(stack) == 3 and watch(stack, values, line, line_start):
                        return watch.result
                    break
                size, origin, callback = rules[~code]
                if callback is None:
                    # A run of one-child ?rules (expr <- sum <- product ...) taken in one step.
                    stack[-1] = state = chains[stack[-2], state, ttype]
                    if state == accept:
                        return values[-1]
                    continue
                cut = len(values) - size  # not values[-size:]: size may be 0
                children = values[cut:]
                del values[cut:], stack[len(stack) - size :]
                push_value(callback(children))
                state = actions[stack[-1]][origin]
                push_state(state)
                # Only a reduction on $END reaches the start rule's end state.
                if state == accept:
                    return values[-1]

    def _keyword_type(self, word: str, state: int, text: str, end: int, primitives: frozenset) -> str:
        """What a keyword is in this state: the keyword, or a NAME (perhaps a primitive's or a clause's)."""
        ttype = self.scanner.keyword(word, state, text, end)
        if ttype == "NAME" and word in primitives:
            return "PRIM_NAME"
        if ttype == "NAME" and state in self.scanner.clause_states:
            return self.scanner.clause(text, end)
        return ttype

    def _chain(self, key: tuple) -> int:
        """The state a run of one-child ?rule reductions ends in, from (state below, state, lookahead)."""
        below, top, ttype = key
        while True:
            code = self.actions[top].get(ttype)
            if code is None or code >= 0 or self.rules[~code][2] is not None:
                return top
            top = self.actions[below][self.rules[~code][1]]

    def _unexpected(self, token: Token, state) -> UnexpectedToken:
        expected = {s for s in self.actions[state] if s.isupper()}
        return UnexpectedToken(token, expected, state=state)


class Mark(NamedTuple):
    """The driver just after it shifted the first token of a top-level statement (not the first one).

    Then the stack is the start state, the state after the statements so
    far, and the token's state: what follows depends only on those three
    states and the text after the token, so a parse can go on from here,
    and a parse that reaches the same states at the same token of the same
    remaining text would do what an earlier one did from here.

    :meth:`Driver.parse` goes on from a Mark when given ``resume=(mark,
    statements)``, the list of the statements before it (its ``preceding``
    first ones). Its ``watch(stack, values, line, line_start)`` is called
    whenever the stack is three states deep after a shift (at every Mark,
    and a few other places: a Mark's ``values[0]`` is an :class:`_Inlined`
    list of statements and its ``stack[1]`` the state after statements);
    when it returns True, the parse stops and returns ``watch.result``.
    lang/incremental.py does both.
    """

    stack: tuple  # the three states
    preceding: int  # statements before the token (the length of the list of statements so far)
    tok: Tok  # the token
    line: int  # the line the driver is on after the token
    line_start: int  # the offset where that line starts


def _begin(start: int, resume) -> tuple:
    """``(stack, values, state, offset, line, line_start, last token)`` to start a parse with: afresh, or at a Mark."""
    if resume is None:
        return [start], [], start, 0, 1, 0, None
    mark, statements = resume
    tok = mark.tok
    return list(mark.stack), [_inline(statements), tok], mark.stack[-1], tok[6], mark.line, mark.line_start, tok


def _past_rows(text: str, start: int, end: int, line: int, line_start: int) -> tuple:
    """``(line, line_start)`` after a keyframe table's rows, the only token that spans lines."""
    nl = text.count("\n", start, end)
    return (line + nl, text.rfind("\n", start, end) + 1) if nl else (line, line_start)


_FIXED = {STRING: "STRING", DOLLAR: "DOLLAR_NAME", ROWS: "TABLE_ROWS"}


class _Chains(dict):
    """(state below, state, lookahead) -> the state a run of one-child ?rule reductions ends in, found once."""

    def __init__(self, driver: Driver):
        super().__init__()
        self.driver = driver

    def __missing__(self, key: tuple) -> int:
        top = self[key] = self.driver._chain(key)
        return top


class _Rules(dict):
    """Rule number -> :meth:`Driver._rule` of it, made when the parse first reduces the rule (see :func:`.tables.callback`)."""

    def __init__(self, rules: tuple, transformer) -> None:
        super().__init__()
        self._rules = rules
        self._transformer = transformer

    def __missing__(self, number: int) -> tuple:
        rule = self._rules[number]
        made = self[number] = Driver._rule(rule, callback(rule, self._transformer))
        return made


class _Spellings(dict):
    """Each number's spelling, shared where it repeats: the syntax tree keeps them all.

    Bounded, for a text of endless distinct numbers: past the bound a new one is not kept.
    """

    def __missing__(self, value: str) -> str:
        if len(self) < 4096:
            self[value] = value
        return value


def _end_token(last: Tok | None) -> Token:
    """The $END token, placed at the last token (or the start of an empty text)."""
    return Token.new_borrow_pos("$END", "", last.as_lark()) if last is not None else Token("$END", "", 0, 1, 1)


def _lookahead(tok: Tok | None, end_tok: Token | None) -> Token:
    """The token the parser could not take, as Lark's exceptions want it: the end, once reached, else ``tok``."""
    if end_tok is not None:
        return end_tok
    assert tok is not None  # before the end, a token was just made
    return tok.as_lark()
