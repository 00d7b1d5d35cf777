"""The Lark transformer: one method per grammar rule, producing :mod:`.ast` nodes.

The methods of the statements and their parts are made from their
declarations in lang/ast.py (``@syntax``, read by lang/syntax.py's readers);
the modifiers' and operators' from lang/vocabulary.py's tables. Written here
by hand are only the expressions' and the shared helpers (positions and
spans, parentheses and signs).

It runs inside the LALR parser (Lark's ``transformer=`` option), so the tree
is built bottom-up in the parser's own loop, without recursion and without
an intermediate parse tree.
"""

from __future__ import annotations

import re

from lark import Token, Transformer

from . import ast as A
from . import syntax as R
from .lexer import Tok
from .numbers import literal
from .syntax import upper_name
from .vocabulary import MODIFIERS, OPERATORS

#: What a terminal is in the children: our parser's Tok, or a Token from Lark's own loop.
TOKENS = (Token, Tok)


def _tpos(tok: Token | Tok) -> A.Pos:
    if type(tok) is Tok:
        return A.token_pos(tok[3], tok[4], tok[5], tok[2], tok[6])
    # Lark types a Token's positions Optional, as a Token may be made without
    # them; the Tokens that reach here come from Lark's own lexer (in the
    # stock reference parser the tests compare with), which sets them all.
    return A.Pos(tok.line, tok.column, tok.end_line, tok.end_column, tok.start_pos, tok.end_pos)  # type: ignore[arg-type]


def _pos_of(x) -> A.Pos | None:
    if isinstance(x, TOKENS):
        return _tpos(x)
    if isinstance(x, A.Node):
        return x.pos
    if isinstance(x, list):
        for item in x:
            p = _pos_of(item)
            if p is not None:
                return p
    return None


def _last_pos_of(x) -> A.Pos | None:
    if isinstance(x, list):
        for item in reversed(x):
            p = _last_pos_of(item)
            if p is not None:
                return p
        return None
    return _pos_of(x)


def span(children) -> A.Pos:
    """The span covering all positioned children."""
    # The usual shapes first: a token or a node at each end.
    if children:
        first, last = children[0], children[-1]
        if type(first) is Tok:
            start = A.token_pos(first[3], first[4], first[5], first[2], first[6])
        elif isinstance(first, A.Node):
            start = first.pos
        else:
            start = None
        if start is not None:
            if type(last) is Tok:
                return start.to(A.token_pos(last[3], last[4], last[5], last[2], last[6]))
            if isinstance(last, A.Node):
                return start.to(last.pos)
    first = _pos_of(children)
    if first is None:
        return A.NOWHERE
    last = _last_pos_of(children)
    assert last is not None  # the scan from the front found a position, so the one from the back does
    return first.to(last)


def _offsets(tok: Token | Tok) -> tuple[int, int]:
    """The character offsets (start, end) of a token."""
    if type(tok) is Tok:
        return tok[2], tok[6]
    return tok.start_pos, tok.end_pos  # type: ignore[return-value]  # set by both lexers, as in _tpos


def _enclosed(pos: A.Pos, first: Token | Tok, last: Token | Tok) -> A.Pos:
    """``pos`` with its text widened from ``first``'s start to ``last``'s end; its caret stays."""
    return pos.widened(_offsets(first)[0], _offsets(last)[1])


def _nodes(children):
    """Children that are values (nodes or lists), dropping keyword tokens."""
    return [c for c in children if not isinstance(c, TOKENS)]


def _name(tok: Token | Tok) -> A.Name:
    return A.Name(_tpos(tok), upper_name(tok.value))


class ToAst(Transformer):
    """Builds the syntax tree; method names are the grammar's rule names and aliases."""

    # ------------------------------------------------------------ program
    def start(self, children):
        return [c for c in children if not isinstance(c, TOKENS)]

    # -------------------------------------------------------- expressions
    def strip_expr(self, children):
        return A.Strip(span(children), children[1], list(children[2:]))

    def sync_expr(self, children):
        return A.Sync(span(children), list(children[1:]))

    def neg(self, children):
        minus, operand = children
        # The caret stays on the operand, as it always has; the text takes the sign.
        return A.Neg(operand.pos.widened(_offsets(minus)[0], operand.pos.end), operand)

    def plus(self, children):
        sign, operand = children
        operand.pos = operand.pos.widened(_offsets(sign)[0], operand.pos.end)
        return operand

    def paren(self, children):
        # (A + B) is the node A + B: its caret stays inside, its text takes the
        # parentheses, so that an enclosing span and a PRINT label keep them.
        lpar, node, rpar = children
        node.pos = _enclosed(node.pos, lpar, rpar)
        return node

    def modified(self, children):
        target, (_lt, *mods, gt) = children
        # The caret ends at the last modifier, as it always has; the text at ">".
        pos = span([target, mods]).widened(target.pos.start, _offsets(gt)[1])
        if isinstance(target, A.Modified):
            # The parser hands the chain so far to nothing else: extend it in
            # place, so that a chain of n lists costs n steps, not n*n copies.
            target.modifiers.extend(mods)
            target.pos = pos
            return target
        return A.Modified(pos, target, mods)

    def number(self, children):
        # lang/numbers.py decides what a literal means (as lang/ast.py's AS_NUM, inline: numbers are most tokens).
        tok = children[0]
        return A.Num(_tpos(tok), literal(tok.value.rstrip("°")), tok.value)

    def var(self, children):
        tok = children[0]
        return A.Var(_tpos(tok), upper_name(tok.value))

    def call(self, children):
        tok, args, rpar = children[0], children[2:-1], children[-1]
        return A.Call(_enclosed(span([tok, *args]), tok, rpar), upper_name(tok.value), args)

    def tuple(self, children):
        items = children[1:-1]
        return A.Tuple(_enclosed(span(items), children[0], children[-1]), items)

    def prim_call(self, children):
        tok = children[0]
        return A.PrimCall(span(children), upper_name(tok.value), list(children[1:]))

    def prim_clause(self, children):
        tok, value = children
        return A.Clause(span(children), upper_name(tok.value), value)

    def modlist(self, children):
        return list(children)  # "<", the modifiers, ">": its user takes the ">" for its text

    # --------------------------------------------------------- conditions
    def cond_or(self, children):
        return A.BoolOp(span(children), "OR", children[0], children[2])

    def cond_and(self, children):
        return A.BoolOp(span(children), "AND", children[0], children[2])

    def cond_not(self, children):
        return A.Not(span(children), children[1])

    def compare(self, children):
        left, op, right = children
        return A.Compare(span(children), op.value, left, right)

    def cond_group(self, children):
        return self.paren(children)


def _modifier_rule(kind: str, axis: bool):
    """The transformer method of the grammar alternative ``-> mod_<kind>``: its argument is its last child."""

    def rule(self, children):
        return A.Modifier(span(children), kind, children[-1], upper_name(children[1].value) if axis else None)

    rule.__name__ = "mod_" + kind
    return rule


# One method per modifier of lang/vocabulary.py: a new modifier needs no code here.
for _spec in MODIFIERS.values():
    setattr(ToAst, "mod_" + _spec.kind, _modifier_rule(_spec.kind, _spec.axis))


def _operator_rule(rule_name: str, symbol: str):
    """The transformer method of ``left <op> right -> <rule_name>``.

    An operator the grammar names as a terminal (``DIV_OP``, ``MOD``) is
    kept as a child: its position is where a division by zero points.
    """

    def rule(self, children):
        if len(children) == 3:
            left, op, right = children
            return A.BinOp(span(children), symbol, left, right, _tpos(op))
        left, right = children
        return A.BinOp(span(children), symbol, left, right)

    rule.__name__ = rule_name
    return rule


# One method per operator of lang/vocabulary.py's table: a new operator needs no code here.
for _op in OPERATORS:
    setattr(ToAst, _op.rule, _operator_rule(_op.rule, _op.symbol))


# ------------------------------------------------------------- declared rules
# Every statement, and every part of one, is declared in lang/ast.py
# (``@syntax`` and ``value_rule``): its rule's method is made here from the
# readers the declaration names (lang/syntax.py). A reader is compiled once
# into a function of the children and the set of the value children taken
# so far (``taken``, their indices).


#: The classes of a token: our parser's Tok, Lark's Token (from its own loop, in the stock reference parser).
_TOKEN_TYPES = frozenset((Tok, Token))


def _is_token(c) -> bool:
    return type(c) in _TOKEN_TYPES


def _type(c) -> str:
    return c[0] if type(c) is Tok else c.type


def _takes_position(convert) -> bool:
    """Does a token's conversion take the token's position too (or its text alone)?"""
    return convert.__code__.co_argcount > 1


def _converted(tok, convert, table: dict):
    """A token through its reader's conversion (by its type, when the reader has a table)."""
    f = table.get(_type(tok), convert) if table else convert
    return f(tok.value, _tpos(tok)) if _takes_position(f) else f(tok.value)


def _next_value(children, taken: set, of=None):
    """The index of the first value child not taken (None if none, or if ``of`` is given and it is not one)."""
    tokens = _TOKEN_TYPES
    for i, c in enumerate(children):
        if type(c) not in tokens and i not in taken:
            return i if of is None or isinstance(c, of) else None
    return None


def _value(r: R.Reader):
    of, convert, tokens = r.of, r.convert, _TOKEN_TYPES

    def read(children, taken):
        # The usual case inline (every assignment's value): the next value, no type asked, no conversion.
        for i, c in enumerate(children):
            if type(c) not in tokens and i not in taken:
                if of is not None and not isinstance(c, of):
                    return None
                taken.add(i)
                return c if convert is None else convert(c)
        return None

    return read


def _rest(r: R.Reader):
    of, until, convert = r.of, r.until, r.convert

    def read(children, taken):
        out = []
        for i, c in enumerate(children):
            if _is_token(c):
                if until is not None and _type(c) == until:
                    break
            elif i not in taken and (of is None or isinstance(c, of)):
                taken.add(i)
                out.append(c if convert is None else convert(c))
        return out

    return read


def _block(r: R.Reader):
    def read(children, taken):
        i = _next_value(children, taken)
        if i is None:
            return None
        taken.add(i)
        c = children[i]
        return c if isinstance(c, list) else [c]

    return read


def _after(r: R.Reader):
    types, convert = r.types, r.convert

    def read(children, taken):
        for i, c in enumerate(children):
            if _is_token(c) and _type(c) in types:
                if i + 1 >= len(children):
                    return None
                taken.add(i + 1)
                value = children[i + 1]
                return _converted(value, convert, {}) if convert is not None and _is_token(value) else value
        return None

    return read


def _token(r: R.Reader):
    types, convert, table, many = r.types, r.convert, dict(r.table), r.many
    if many:
        return lambda children, taken: [
            _converted(c, convert, table) for c in children if _is_token(c) and _type(c) in types
        ]
    if len(types) == 1 and not table:
        (kind,) = types
        if not _takes_position(convert):

            def read_text(children, taken):
                for c in children:
                    if type(c) is Tok:
                        if c[0] == kind:
                            return convert(c[1])
                    elif type(c) is Token and c.type == kind:
                        return convert(c.value)
                return None

            return read_text

        def read_one(children, taken):
            for c in children:
                if type(c) is Tok:
                    if c[0] == kind:
                        return convert(c[1], A.token_pos(c[3], c[4], c[5], c[2], c[6]))
                elif type(c) is Token and c.type == kind:
                    return convert(c.value, _tpos(c))
            return None

        return read_one

    def read(children, taken):
        for c in children:
            if _is_token(c) and _type(c) in types:
                return _converted(c, convert, table)
        return None

    return read


def _flag(r: R.Reader):
    types = r.types
    return lambda children, taken: any(_is_token(c) and _type(c) in types for c in children)


def _which(r: R.Reader):
    table, default = dict(r.table), r.default

    def read(children, taken):
        return next((table[_type(c)] for c in children if _is_token(c) and _type(c) in table), default)

    return read


def _find(r: R.Reader):
    of = r.of
    return lambda children, taken: next((c for c in children if isinstance(c, of)), None)  # type: ignore[arg-type]


def _inner(r: R.Reader):
    of, name = r.of, r.types[0]

    def read(children, taken):
        c = next((c for c in children if isinstance(c, of)), None)
        return None if c is None else getattr(c, name)

    return read


def _item(r: R.Reader):
    k = r.default

    def read(children, taken):
        c = next((c for c in children if type(c) is tuple), None)
        return None if c is None else c[k]

    return read


def _option(r: R.Reader):
    word = r.types[0]

    def read(children, taken):
        found = [c.value for c in children if isinstance(c, A.Option) and c.word == word]
        return found[-1] if found else None

    return read


def _options(r: R.Reader):
    def read(children, taken):
        places: dict = {}
        for c in children:
            if isinstance(c, A.Option):
                places.setdefault(c.word, []).append(c.pos)
        return places

    return read


def _made(r: R.Reader):
    cls, make = r.of, _node_maker(r.of, r.table, r.default)  # type: ignore[arg-type]
    assert cls is not None
    return make


_READERS = {
    "value": _value,
    "rest": _rest,
    "block": _block,
    "after": _after,
    "token": _token,
    "flag": _flag,
    "which": _which,
    "find": _find,
    "inner": _inner,
    "item": _item,
    "option": _option,
    "options": _options,
    "made": _made,
    "where": lambda r: lambda children, taken, n=r.default: span(children[:n]),
    "const": lambda r: lambda children, taken, v=r.default: v,
    "factory": lambda r: lambda children, taken, make=r.default: make(),
}


def _reader(r: R.Reader):
    """The function ``(children, taken) -> value`` of reader ``r``."""
    return _READERS[r.kind](r)


def _position(r: R.Reader | None, names: tuple):
    """The function ``(children, values) -> Pos`` of a position's reader (None: the span of all children)."""
    if r is None:
        return lambda children, values: span(children)
    if r.kind == "where":
        n = r.default
        return lambda children, values: span(children[:n])
    if r.kind == "through":
        index = names.index(r.types[0])
        return lambda children, values: span([children[0], values[index]])
    read = _reader(r)
    return lambda children, values: read(children, set())


def _node_maker(cls: type, readers: tuple, pos: R.Reader | None):
    """The function ``(children, taken) -> node`` of a node class and its fields' readers."""
    reads = [_reader(r) for _, r in readers]
    if pos is None and len(reads) <= 3:
        # The common shapes spelt out (a million assignments are parsed through here):
        # no list of values, and the span of all children.
        if not reads:
            return lambda children, taken: cls(span(children))
        if len(reads) == 1:
            (r0,) = reads
            return lambda children, taken: cls(span(children), r0(children, taken))
        if len(reads) == 2:
            r0, r1 = reads
            return lambda children, taken: cls(span(children), r0(children, taken), r1(children, taken))
        r0, r1, r2 = reads
        return lambda children, taken: cls(
            span(children), r0(children, taken), r1(children, taken), r2(children, taken)
        )
    where = _position(pos, tuple(name for name, _ in readers))

    def make(children, taken):
        values = [read(children, taken) for read in reads]
        return cls(where(children, values), *values)

    return make


# ------------------------------------------------ readers of a fixed shape
# A production without optional, repeated or alternative parts (``NAME
# ASSIGN_OP rhs``) gives its children always in the same places, so its
# fields can be read by position instead of by searching the children: a
# million assignments are parsed through here, and the search cost about a
# tenth of their parse. The generic readers above stay the definition; these
# give the same values, each from the one place it can be.

_SYMBOL = re.compile(r'"(?:[^"\\]|\\.)*"i?|[A-Za-z_][A-Za-z0-9_]*|\S')


def _fixed_shape(production: str | None) -> tuple[str, ...] | None:
    """The symbols whose values are a production's children, in order, when there are always the same; else None."""
    if production is None:
        return None
    shape = []
    for symbol in _SYMBOL.findall(production):
        if symbol.startswith('"'):
            continue  # a quoted literal: dropped by the parser
        if not (symbol[0].isalpha() and symbol.replace("_", "").isalnum()):
            return None  # ( ) | ? * + [ ]: optional, repeated or alternative parts
        shape.append(symbol)
    return tuple(shape)


def _token_at(i: int, convert):
    """A token reader of a fixed shape: the token ``i``-th among the children, converted."""
    if not _takes_position(convert):
        return lambda children, taken: convert(children[i][1] if type(children[i]) is Tok else children[i].value)

    def read(children, taken):
        c = children[i]
        if type(c) is Tok:
            return convert(c[1], A.token_pos(c[3], c[4], c[5], c[2], c[6]))
        return convert(c.value, _tpos(c))

    return read


def _positional(readers: tuple, shape: tuple[str, ...]) -> list | None:
    """Readers by position for a node of a fixed ``shape`` (None where a field needs the generic reader)."""
    values = iter(i for i, symbol in enumerate(shape) if symbol.islower())
    reads = []
    for _, r in readers:
        if r.kind == "token" and not r.many and not r.table and len(r.types) == 1 and r.types[0] in shape:
            reads.append(_token_at(shape.index(r.types[0]), r.convert))
        elif r.kind == "value" and r.of is None:
            i, convert = next(values, None), r.convert
            if i is None:
                return None
            if convert is None:
                reads.append(lambda children, taken, i=i: children[i])
            else:
                reads.append(lambda children, taken, i=i, f=convert: f(children[i]))
        elif r.kind == "flag":
            reads.append(lambda children, taken, v=r.types[0] in shape: v)
        elif r.kind in ("const", "factory"):
            reads.append(_reader(r))
        else:
            return None
    return reads


def _node_rule(cls: type, readers: tuple, pos: R.Reader | None, shape: tuple[str, ...] | None = None):
    """The transformer method of a node's rule: one call per node, for the shapes most statements have."""
    reads = (_positional(readers, shape) if shape is not None else None) or [_reader(r) for _, r in readers]
    if pos is not None or len(reads) > 3:
        make = _node_maker(cls, readers, pos)
        return lambda self, children: make(children, set())
    # Spelt out by arity (a million assignments are parsed through here): no list of
    # values, no second call, and the span of all children.
    if not reads:
        return lambda self, children: cls(span(children))
    if len(reads) == 1:
        (r0,) = reads
        return lambda self, children: cls(span(children), r0(children, set()))
    if len(reads) == 2:
        r0, r1 = reads

        def rule2(self, children):
            taken: set = set()
            return cls(span(children), r0(children, taken), r1(children, taken))

        return rule2
    r0, r1, r2 = reads

    def rule3(self, children):
        taken: set = set()
        return cls(span(children), r0(children, taken), r1(children, taken), r2(children, taken))

    return rule3


def _syntax_rule(sx: R.Syntax):
    """The transformer method of a declared rule (lang/ast.py)."""
    if sx.cls is not None:
        rule = _node_rule(sx.cls, sx.readers, sx.pos, _fixed_shape(R.PRODUCTIONS.get(sx.rule)))
    else:
        reads = [_reader(r) for _, r in sx.readers]
        if len(reads) == 1:
            (one,) = reads

            def rule(self, children):
                return one(children, set())
        else:

            def rule(self, children):
                taken: set = set()
                return tuple(read(children, taken) for read in reads)

    rule.__name__ = sx.rule
    return rule


# One method per declared rule of lang/ast.py: a new statement needs no code here.
for _sx in R.SYNTAX.values():
    assert not hasattr(ToAst, _sx.rule), f"{_sx.rule} is declared in lang/ast.py and written in ToAst"
    setattr(ToAst, _sx.rule, _syntax_rule(_sx))
