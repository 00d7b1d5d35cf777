"""The parser's tables, shipped in the package as plain data, in the form the parse loop runs.

Building the LALR tables from ``lig.lark`` takes about 0.3 s, which every
``liganimate`` command would pay at start. Lark's own remedy (``cache=True``)
pickles the tables into the temporary folder and unpickles them on the next
start, and unpickling a file another user planted there runs their code.
Instead the tables are computed once, by Lark, and written into
``lang/_tables.py``: a module holding nothing but one JSON text (names,
numbers, flags), committed with the grammar and installed with the package.

They are written in the form :class:`liganimate.lang.lalr.Driver` runs
(:class:`ParserTables`): the terminals, the rules, and for each state a map
from a symbol's name to the next state (a shift or a goto) or ``~rule`` (a
reduction). Loading them builds those maps and the rules' few Lark objects
directly; Lark's generic deserializer, which rebuilt its own parse table and
then had it renumbered for the loop, was most of a cold ``liganimate
check`` beyond importing Lark itself (about 40 of 45 ms; now about 5).

The module records the SHA-256 of the grammar and the Lark version it was
made from; when either differs (the grammar was edited, or another Lark is
installed) :func:`load` returns None and the tables are computed from the
grammar instead, so editing ``lig.lark`` keeps working, only slower to start
until the tables are regenerated with::

    python -m liganimate.lang.tables          # rewrite lig.lark's statements, then lang/_tables.py
    python -m liganimate.lang.tables --check  # exit 1 if either is stale

(the statements' productions are declared beside their nodes in lang/ast.py;
lang/grammar.py writes them into lig.lark).

tests/lang/test_parser_scale.py fails while the committed tables differ
from freshly generated ones.
"""

from __future__ import annotations

import functools
import hashlib
import json
from importlib import resources
from pathlib import Path
from typing import NamedTuple

import lark
from lark import Lark
from lark.grammar import NonTerminal, Rule, RuleOptions, Terminal
from lark.lexer import PatternRE, PatternStr, TerminalDef
from lark.parse_tree_builder import ParseTreeBuilder
from lark.parsers.lalr_analysis import Shift
from lark.tree import Tree

_MODULE = "_tables.py"


class ParserTables(NamedTuple):
    """An LALR parser's tables, numbered for :class:`liganimate.lang.lalr.Driver`'s loop.

    States are numbered breadth first from the start state, taking each
    state's transitions by symbol name, and rules by name, so that the same
    grammar always gives the same numbers (Lark's own numbering follows set
    order, which changes with Python's string hashing).
    """

    terminals: tuple  # lark TerminalDef, in Lark's order (the lexer's keyword decisions follow it)
    rules: tuple  # lark Rule; the reduction code ~i names rules[i]
    actions: list  # state -> {symbol name: next state (shift or goto), or ~rule (reduce)}
    start: int  # the start state
    end: int  # the state after the start rule: reaching it accepts

    def terminal(self, name: str) -> TerminalDef | None:
        """The terminal called ``name``, or None."""
        return _terminals_by_name(self.terminals).get(name)


@functools.lru_cache(maxsize=4)
def _terminals_by_name(terminals: tuple) -> dict:
    return {t.name: t for t in terminals}


def grammar_text() -> str:
    """The text of ``lig.lark`` as installed."""
    return resources.files("liganimate.lang").joinpath("lig.lark").read_text(encoding="utf-8")


def grammar_hash(text: str | None = None) -> str:
    """SHA-256 (hex) of the grammar text, which names the tables made from it."""
    return hashlib.sha256((grammar_text() if text is None else text).encode("utf-8")).hexdigest()


def options(lexer, postlex, transformer) -> dict:
    """The Lark options of liganimate's parser (one place, for building and for the callbacks)."""
    return {
        "parser": "lalr",
        "lexer": lexer,
        "postlex": postlex,
        "transformer": transformer,
        "maybe_placeholders": False,
    }


def build(lexer, postlex, transformer, text: str | None = None) -> Lark:
    """Build Lark's parser from the grammar (slow: computes the LALR tables)."""
    return Lark(grammar_text() if text is None else text, **options(lexer, postlex, transformer))


def from_lark(parser: Lark) -> ParserTables:
    """The tables of a Lark LALR ``parser``, numbered as :class:`ParserTables` says."""
    table = parser.parser.parser._parse_table
    states = table.states
    rules = sorted(
        {arg for row in states.values() for kind, arg in row.values() if kind is not Shift},
        key=lambda r: (r.origin.name, r.order, [s.name for s in r.expansion]),
    )
    rule_index = {rule: i for i, rule in enumerate(rules)}
    start = table.start_states["start"]
    order = {start: 0}  # old state number -> new
    queue = [start]
    for s in queue:
        for _, (kind, arg) in sorted(states[s].items()):
            if kind is Shift and arg not in order:
                order[arg] = len(order)
                queue.append(arg)
    for s in states:  # unreachable states would be a Lark bug; keep them, numbered last
        order.setdefault(s, len(order))
    actions = [
        {
            symbol: (order[arg] if kind is Shift else ~rule_index[arg])
            for symbol, (kind, arg) in sorted(states[s].items())
        }
        for s in sorted(states, key=order.__getitem__)
    ]
    return ParserTables(tuple(parser.terminals), tuple(rules), actions, 0, order[table.end_states["start"]])


def refuse_terminal_callbacks(tables: ParserTables, transformer) -> None:
    """Raise ValueError if ``transformer`` has a method named for a terminal (the parse loop calls none)."""
    for t in tables.terminals:
        if getattr(transformer, t.name, None):
            raise ValueError(f"terminal callbacks are not supported ({t.name})")


def callback(rule: Rule, transformer):
    """A rule's callback (Lark's tree builder around ``transformer``'s method).

    The same callback ``Lark(..., transformer=transformer)`` makes with
    :func:`options`, made for one rule: the parse loop makes each when it
    first reduces that rule (a program reduces about a third of the
    grammar's, and making them all cost about 1 ms at every start).
    """
    return ParseTreeBuilder([rule], Tree, False, False, False).create_callback(transformer)[rule]


# ------------------------------------------------------------ the file


def _terminal_json(t: TerminalDef) -> list:
    p = t.pattern
    width = getattr(p, "_width", None)  # a regular expression's (min, max) length, once Lark has measured it
    width = list(width) if width is not None else None
    return [t.name, p.type, p.value, sorted(p.flags), p.raw, t.priority, width]


def _terminal(name, kind, value, flags, raw, priority, width) -> TerminalDef:
    if kind == "str":
        return TerminalDef(name, PatternStr(value, flags, raw), priority)
    pattern = PatternRE(value, flags, raw)
    if width is not None:
        pattern._width = tuple(width)  # type: ignore[assignment] # Lark declares it None until measured
    return TerminalDef(name, pattern, priority)


def _rule_json(r: Rule) -> list:
    o = r.options
    # A symbol as its name, with "!" before a terminal whose token the tree drops, "'" before any other terminal.
    expansion = [(("!" if getattr(s, "filter_out", False) else "'") if s.is_term else "") + s.name for s in r.expansion]
    options_ = [o.keep_all_tokens, o.expand1, o.priority, o.template_source, list(o.empty_indices)]
    return [r.origin.name, expansion, r.order, r.alias, options_]


class _Symbols(dict):
    """Each symbol spelled as :func:`_rule_json` spells it, made once (rules share their symbols)."""

    def __missing__(self, spelled: str):
        made = self[spelled] = _symbol(spelled)
        return made


def _symbol(spelled: str):
    if spelled[0] == "!":
        return Terminal(spelled[1:], True)
    if spelled[0] == "'":
        return Terminal(spelled[1:], False)
    return NonTerminal(spelled)


def _rule(symbols: _Symbols, origin, expansion, order, alias, options_) -> Rule:
    keep_all_tokens, expand1, priority, template_source, empty = options_
    return Rule(
        symbols[origin],
        [symbols[s] for s in expansion],
        order,
        alias,
        RuleOptions(keep_all_tokens, expand1, priority, template_source, tuple(empty)),
    )


def _json_lines(tables: ParserTables) -> list:
    """The tables as JSON text, one state, rule or terminal a line (a grammar change reads as a small diff).

    A state is an object from each symbol's name to its code, the map the
    parse loop runs: JSON's own decoder then builds it (building it in
    Python from a flat list of numbers cost about 1.5 ms of every start).
    """
    dump = functools.partial(json.dumps, ensure_ascii=True, separators=(",", ":"))

    def block(key: str, rows: list) -> list:
        out = [f'"{key}":[']
        out += [dump(row) + "," for row in rows]
        out[-1] = out[-1][:-1]
        return [*out, "],"]

    lines = ["{" + f'"start":{tables.start},"end":{tables.end},']
    lines += block("terminals", [_terminal_json(t) for t in tables.terminals])
    lines += block("rules", [_rule_json(r) for r in tables.rules])
    lines += block("states", tables.actions)
    lines[-1] = "]}"
    return lines


def _from_json(text: str) -> ParserTables:
    """The tables from the text :func:`_json_lines` wrote."""
    raw = json.loads(text)
    symbols = _Symbols()
    return ParserTables(
        tuple(_terminal(*t) for t in raw["terminals"]),
        tuple(_rule(symbols, *r) for r in raw["rules"]),
        raw["states"],
        raw["start"],
        raw["end"],
    )


def module_text(tables: ParserTables, text: str | None = None) -> str:
    """The source of ``_tables.py`` for ``tables`` computed from grammar ``text``."""
    body = "\n".join(f"    {line + chr(10)!r}" for line in _json_lines(tables))
    return "\n".join(
        [
            '"""LALR tables of lig.lark, generated by ``python -m liganimate.lang.tables``: do not edit.',
            "",
            "Data only: one JSON text, which lang/tables.py reads with json.loads (it explains why",
            "the tables are shipped). A string literal, because Python reads one in a few",
            "milliseconds even where it may not write bytecode caches.",
            '"""',
            "",
            f"GRAMMAR_SHA256 = {grammar_hash(text)!r}",
            f"LARK_VERSION = {lark.__version__!r}",
            "",
            "TABLES_JSON = (",
            body,
            ")",
            "",
        ]
    )


def load() -> ParserTables | None:
    """The shipped tables, or None when they were not made from this grammar and Lark."""
    try:
        from . import _tables
    except ImportError:
        return None
    if (
        getattr(_tables, "GRAMMAR_SHA256", None) != grammar_hash()
        or getattr(_tables, "LARK_VERSION", None) != lark.__version__
    ):
        return None
    return _from_json(_tables.TABLES_JSON)


def fresh_module_text() -> str:
    """What ``_tables.py`` should hold for the grammar and Lark installed now."""
    from .parser import grammar_parts

    return module_text(from_lark(build(*grammar_parts())))


def main(argv=None) -> int:
    """Write lig.lark's statements again, then ``lang/_tables.py`` (or with ``--check``, report whether they are current)."""
    from . import grammar
    from .generated import regenerate

    lark_file = Path(__file__).with_name("lig.lark")
    files = [
        (lark_file, lambda: grammar.fresh_text(lark_file.read_text(encoding="utf-8"))),
        (Path(__file__).with_name(_MODULE), fresh_module_text),
    ]
    return regenerate(argv, "liganimate.lang.tables", files, main.__doc__ or "")


if __name__ == "__main__":
    raise SystemExit(main())
