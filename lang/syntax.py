"""How a node is read from its grammar rule: the readers a node's declaration names.

Every statement's node (and the nodes its parts are made of) is declared
once, in lang/ast.py, with ``@syntax(rule, field=reader, ...)``: the grammar
rule (or alias) of lang/lig.lark that makes it, and for each field how its
value is found among the rule's children. The transformer
(lang/transform.py) makes one method per declared rule from the readers
alone, as pycparser makes its node classes from one description; no
statement has a hand-written transformer method.

A rule's children are, in order, its tokens (keywords, names, numbers,
strings: the named terminals of the grammar; quoted ones like ``","`` are
dropped by the parser) and its values (the nodes and lists its sub-rules
made). The readers, each evaluated in the order of the node's fields:

- :func:`value`: the next value not taken yet (None when there is none,
  or when ``of`` is given and the next one is not of that type);
- :func:`rest`: every value not taken yet (of a type, before a token), a list;
- :func:`block`: the next value as a list of statements (one statement or a BEGIN ... END block);
- :func:`after`: the child just after a token (a value, or a token converted), or None;
- :func:`token`: a token of the types given, converted (or all of them, ``many=True``);
- :func:`flag`: whether a token of a type is there; :func:`which`: which of several is;
- :func:`find`: the first value of a type, not taken (so that a list may also hold it);
  :func:`inner`: a field of the first value of a type (a sub-rule's node the node copies);
  :func:`item`: an item of the first value that is a tuple (a sub-rule made by :func:`value_rule`);
  :func:`made`: a node of another class read from the same children (a part with no rule of its own);
- :func:`option`: the value of a block's option line (an ``Option`` node, the last one given),
  :func:`options`: where each option line is (for "given twice");
- :func:`where`: the span of the first ``n`` children; :func:`through`: the span from
  the first child to the end of another field's value; :func:`const`: a constant.

A value reader takes ``convert`` too: a function of the value, declared on
the field that needs it.

A node's position is the span of all its children unless its declaration
says otherwise (``pos=where(1)``, ``pos=token("NAME", POS)``).

A token's conversion takes its text, or its text and its position: here
:func:`UPPER` (a name as a string), :func:`TEXT`, :func:`UNQUOTE` (a
string's text without its quotes) and :func:`POS`; in lang/ast.py
``AS_NAME`` (a ``Name`` node), ``AS_NUM`` (a ``Num`` node) and ``AS_LABEL``
(a number's value); a node whose token needs another one declares it beside
its fields.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

#: One string per distinct upper-cased name: a million ``X = 1`` lines share one "X".
_NAMES: dict = {}


def upper_name(text: str) -> str:
    """``text`` upper-cased, the same string object for every spelling of one name."""
    name = _NAMES.get(text)
    if name is None:
        name = text.upper()
        if len(_NAMES) < 1 << 16:  # a bound, for programs of endless distinct names
            name = _NAMES.setdefault(name, name)
            _NAMES[text] = name
    return name


class Reader(NamedTuple):
    """How one field's value is found among a rule's children (made by the functions below).

    A named tuple, not a dataclass: lang/ast.py makes a hundred at import, on every start.
    """

    kind: str
    types: tuple[str, ...] = ()
    convert: Callable[..., Any] | None = None  # of a token (its text, and its position) or of a value
    of: type | tuple[type, ...] | None = None
    until: str | None = None
    many: bool = False
    table: tuple[tuple[str, Any], ...] = ()
    default: Any = None


def _types(types: str | tuple[str, ...]) -> tuple[str, ...]:
    return (types,) if isinstance(types, str) else tuple(types)


def value(of: type | tuple[type, ...] | None = None, convert: Callable[[Any], Any] | None = None) -> Reader:
    """The next value not taken yet (of type ``of``, if given; converted by ``convert``), or None."""
    return Reader("value", of=of, convert=convert)


def rest(
    of: type | tuple[type, ...] | None = None, until: str | None = None, convert: Callable[[Any], Any] | None = None
) -> Reader:
    """Every value not taken yet (of type ``of``; before the token ``until``; each converted), as a list."""
    return Reader("rest", of=of, until=until, convert=convert)


def block() -> Reader:
    """The next value as a list of statements: a BEGIN ... END block's list, or one statement in a list; or None."""
    return Reader("block")


def after(types: str | tuple[str, ...], convert: Callable[..., Any] | None = None) -> Reader:
    """The child just after the first token of ``types`` (a token converted by ``convert``), or None."""
    return Reader("after", _types(types), convert)


def token(
    types: str | tuple[str, ...],
    convert: Callable[..., Any] | dict[str, Callable[..., Any]],
    many: bool = False,
) -> Reader:
    """The first token of ``types``, converted (None if absent); ``many``: all of them, a list.

    ``convert`` is one conversion, or one for each token type.
    """
    if isinstance(convert, dict):
        return Reader("token", _types(types), None, many=many, table=tuple(convert.items()))
    return Reader("token", _types(types), convert, many=many)


def flag(type_: str) -> Reader:
    """True when a token of type ``type_`` is among the children."""
    return Reader("flag", (type_,))


def which(table: dict[str, Any] | tuple[str, ...], default: Any = None) -> Reader:
    """The value ``table`` gives the first token whose type it names (a tuple: the type itself), else ``default``."""
    pairs = tuple(table.items()) if isinstance(table, dict) else tuple((t, t) for t in table)
    return Reader("which", tuple(t for t, _ in pairs), table=pairs, default=default)


def find(of: type) -> Reader:
    """The first value of type ``of``, taken or not (None if there is none)."""
    return Reader("find", of=of)


def inner(of: type, name: str) -> Reader:
    """Field ``name`` of the first value of type ``of`` (a part a sub-rule made), or None."""
    return Reader("inner", (name,), of=of)


def made(cls: type, pos: Reader | None = None, **readers: Reader) -> Reader:
    """A node of class ``cls`` read from the same children (its position by ``pos``, else their span)."""
    return Reader("made", of=cls, table=tuple(readers.items()), default=pos)


def item(k: int) -> Reader:
    """Item ``k`` of the first value that is a tuple (made by a sub-rule's :func:`value_rule`), or None."""
    return Reader("item", default=k)


def option(word: str) -> Reader:
    """The value of the last option line (an ``Option`` node) whose word is ``word``, or None."""
    return Reader("option", (word,))


def options() -> Reader:
    """Each option line's word -> the positions of its lines, in order (for an option given twice)."""
    return Reader("options")


def where(n: int) -> Reader:
    """The span of the first ``n`` children (negative: all but the last ``-n``)."""
    return Reader("where", default=n)


def through(name: str) -> Reader:
    """The span from the first child to the end of field ``name``'s value (a position's reader)."""
    return Reader("through", (name,))


def const(v: Any) -> Reader:
    """Always ``v``."""
    return Reader("const", default=v)


def factory(make: Callable[[], Any]) -> Reader:
    """A new ``make()`` for each node (a field's default factory)."""
    return Reader("factory", default=make)


# ------------------------------------------------------------ conversions
# A token's conversion takes its text and its position. NAME and NUMBER make
# nodes, so lang/ast.py fills them in once those classes exist.


# A conversion of one parameter is given the text alone: the parser then makes
# no position for a token whose position nobody keeps (every assignment's "=").


def TEXT(text: str) -> str:
    """The token's text as written."""
    return text


def UPPER(text: str) -> str:
    """The token's text upper-cased (a name: the language is case-insensitive)."""
    return upper_name(text)


def UNQUOTE(text: str) -> str:
    """A string token's text without its quotes."""
    return text[1:-1]


def POS(text: str, pos: Any) -> Any:
    """The token's position."""
    return pos


class Syntax(NamedTuple):
    """How one grammar rule's value is made.

    A node: ``cls`` called with the position (``pos``'s reader, None for the
    span of all children) and each field's reader's value, in the fields'
    order. A value rule (``cls`` None): the single reader's value, or the
    tuple of the readers' values.
    """

    rule: str
    cls: type | None
    readers: tuple[tuple[str, Reader], ...]
    pos: Reader | None


#: Grammar rule or alias -> how its value is made (filled by lang/ast.py's ``@syntax`` and ``value_rule``).
SYNTAX: dict[str, Syntax] = {}


def value_rule(rule: str, *readers: Reader, production: str | None = None) -> None:
    """Declare a sub-rule whose value is not a node: what its one reader gives, or the tuple of its readers' values.

    ``production``, if given, is the rule's right-hand side in Lark's
    notation, written into lang/lig.lark by ``python -m liganimate.lang.tables``.
    """
    assert rule not in SYNTAX, rule
    SYNTAX[rule] = Syntax(rule, None, tuple((str(i), r) for i, r in enumerate(readers)), None)
    if production is not None:
        produce(rule, production)


# ------------------------------------------------------------ productions
# A statement's production is declared beside its node (lang/ast.py), as
# pycparser's parser keeps each production beside the code that builds its
# node: one place says what a statement is written as, what node it makes
# and how the node's fields are read. lang/grammar.py writes them into
# lig.lark's generated section, which every reader of the grammar (the
# tables, Lark, the highlighters, the tests) reads as before.

#: Grammar rule -> its right-hand side (Lark's notation), in declaration order.
PRODUCTIONS: dict[str, str] = {}

#: The rules that are statements: ``?statement``'s alternatives, in declaration order.
STATEMENTS: list[str] = []


def produce(rule: str, production: str, statement: bool = False) -> None:
    """Declare grammar rule ``rule`` as ``production`` (a statement's, with ``statement``).

    Parameters
    ----------
    rule : str
        The rule's name, lower case (a name starting with ``_`` is inlined by Lark).
    production : str
        Its right-hand side in Lark's notation: terminals in capitals (a word
        no terminal of lig.lark defines yet becomes a case-insensitive
        keyword of that spelling), rules in lower case, quoted punctuation,
        alternatives with ``|``.
    statement : bool
        Whether it is one of the statements (an alternative of ``?statement``).
    """
    assert rule not in PRODUCTIONS and rule == rule.lower(), rule
    PRODUCTIONS[rule] = " ".join(production.split())
    if statement:
        STATEMENTS.append(rule)
