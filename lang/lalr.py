"""The LALR(1) loop that :func:`liganimate.lang.parser.parse` runs: Lark's tables, a lean driver.

Lark builds the tables and the callbacks (its tree builder wrapped around
:class:`~liganimate.lang.transform.ToAst`), and its own loop would run them
correctly; but it finds each rule's callback in a dict keyed by ``Rule``
objects, whose hash and equality are Python methods, and it calls the
callback of every one-child ``?rule`` (``?sum: product``) only to hand the
child back. On a program of a million short lines that loop was most of
the parse. Here the same tables are renumbered once: a state's actions map
a symbol to an int (a shift's next state, or ``~rule``), rules are a list,
and a one-child ``?rule`` only changes the state on top of the stack.

The tree is the one Lark's loop builds (tests/test_lexer.py checks this
against Lark's stock contextual lexer and loop), and errors are Lark's
``UnexpectedToken`` and ``UnexpectedCharacters``, as before.
"""

from __future__ import annotations

from lark.exceptions import UnexpectedToken
from lark.lexer import Token
from lark.parse_tree_builder import ExpandSingleChild
from lark.parsers.lalr_analysis import Shift

from .lexer import Scanner


class Driver:
    """A Lark LALR parser's tables and callbacks, renumbered for :meth:`parse`.

    Parameters
    ----------
    lark : lark.Lark
        A parser built with ``parser="lalr"`` and a transformer (its
        callbacks produce the values).
    """

    def __init__(self, lark):
        lalr = lark.parser.parser
        table = lalr._parse_table
        callbacks = lalr.parser.callbacks
        if any(isinstance(key, str) for key in callbacks):
            raise ValueError("terminal callbacks are not supported")
        rule_index: dict = {}
        self.rules: list = []  # (number of symbols, the rule's name, callback or None for "keep the child")
        self.actions: dict = {}  # state -> {symbol: next state, or ~rule to reduce}
        for state, row in table.states.items():
            acts = {}
            for symbol, (action, arg) in row.items():
                if action is Shift:
                    acts[symbol] = arg
                else:
                    i = rule_index.get(arg)
                    if i is None:
                        i = rule_index[arg] = len(self.rules)
                        self.rules.append(self._rule(arg, callbacks[arg]))
                    acts[symbol] = ~i
            self.actions[state] = acts
        self.start = table.start_states["start"]
        self.end = table.end_states["start"]
        self.scanner = Scanner(lark.terminals, table.states)

    @staticmethod
    def _rule(rule, callback):
        size = len(rule.expansion)
        # Lark's ExpandSingleChild hands a lone child back without calling the
        # transformer; when nothing else wraps it, the reduction is a no-op.
        keeps_child = (size == 1 and type(callback) is ExpandSingleChild and not rule.expansion[0].is_term
                       and not rule.expansion[0].name.startswith("_"))
        return size, rule.origin.name, None if keeps_child else callback

    def parse(self, text: str, primitives: frozenset):
        """Parse ``text``; a NAME in ``primitives`` is a PRIM_NAME. Returns the start rule's value."""
        actions = self.actions
        rules = self.rules
        stack = [self.start]
        values: list = []
        push_state = stack.append
        push_value = values.append
        tok = None
        for tok in self.scanner.tokens(text, stack, primitives):
            ttype = tok[0]
            while True:
                code = actions[stack[-1]].get(ttype)
                if code is None:
                    raise self._unexpected(tok.as_lark(), stack[-1])
                if code >= 0:
                    push_state(code)
                    push_value(tok)
                    break
                size, origin, callback = rules[~code]
                if callback is None:
                    stack[-1] = actions[stack[-2]][origin]
                    continue
                if size:
                    children = values[-size:]
                    del values[-size:]
                    del stack[-size:]
                else:
                    children = []
                push_value(callback(children))
                push_state(actions[stack[-1]][origin])
        end = Token.new_borrow_pos("$END", "", tok.as_lark()) if tok is not None else Token("$END", "", 0, 1, 1)
        while True:
            code = actions[stack[-1]].get("$END")
            if code is None or code >= 0:
                raise self._unexpected(end, stack[-1])
            size, origin, callback = rules[~code]
            if callback is None:
                stack[-1] = actions[stack[-2]][origin]
            else:
                if size:
                    children = values[-size:]
                    del values[-size:]
                    del stack[-size:]
                else:
                    children = []
                push_value(callback(children))
                push_state(actions[stack[-1]][origin])
            if stack[-1] == self.end:
                return values[-1]

    def _unexpected(self, token: Token, state) -> UnexpectedToken:
        expected = {s for s in self.actions[state] if s.isupper()}
        return UnexpectedToken(token, expected, state=state)
