"""The parser's tables, shipped in the package as plain data.

Building the LALR tables from ``lig.lark`` takes about 0.3 s, which every
``liganimate`` command would pay at start. Lark's own remedy (``cache=True``)
pickles the tables into the temporary folder and unpickles them on the next
start, and unpickling a file another user planted there runs their code.
Instead the tables are generated once, by Lark's own serializer, into
``lang/_tables.py``: a module holding nothing but literals (dicts, lists,
strings, numbers), committed with the grammar and installed with the
package. Loading it builds Lark objects only from classes Lark's
deserializer allows by name.

The module records the SHA-256 of the grammar and the Lark version it was
made from; when either differs (the grammar was edited, or another Lark is
installed) :func:`load` returns None and the parser is built from the
grammar instead, so editing ``lig.lark`` keeps working, only slower to start
until the tables are regenerated with::

    python -m liganimate.lang.tables          # rewrite lang/_tables.py
    python -m liganimate.lang.tables --check  # exit 1 if it is stale

tests/test_parser_scale.py fails while the committed tables differ from
freshly generated ones.
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import json
import sys
from importlib import resources
from pathlib import Path

import lark
from lark import Lark
from lark.grammar import Rule
from lark.lexer import TerminalDef

#: Stand-in for the objects the tables cannot hold (the lexer class, the
#: transformer, the post-lexer); :func:`load` puts the real ones back.
PLACEHOLDER = "<supplied when loading>"

_MODULE = "_tables.py"


def grammar_text() -> str:
    """The text of ``lig.lark`` as installed."""
    return resources.files("liganimate.lang").joinpath("lig.lark").read_text(encoding="utf-8")


def grammar_hash(text: str | None = None) -> str:
    """SHA-256 (hex) of the grammar text, which names the tables made from it."""
    return hashlib.sha256((grammar_text() if text is None else text).encode("utf-8")).hexdigest()


def options(lexer, postlex, transformer) -> dict:
    """The Lark options of liganimate's parser (one place, for building and for loading)."""
    return {
        "parser": "lalr",
        "lexer": lexer,
        "postlex": postlex,
        "transformer": transformer,
        "maybe_placeholders": False,
    }


def build(lexer, postlex, transformer, text: str | None = None) -> Lark:
    """Build the parser from the grammar (slow: computes the LALR tables)."""
    return Lark(grammar_text() if text is None else text, **options(lexer, postlex, transformer))


def serialize(parser: Lark) -> dict:
    """Lark's own serialization of ``parser``, with its Python objects replaced by :data:`PLACEHOLDER`."""
    data, memo = parser.memo_serialize([TerminalDef, Rule])
    data["options"] = {
        k: (PLACEHOLDER if k in ("lexer", "postlex", "transformer") else v) for k, v in data["options"].items()
    }
    data["parser"]["lexer_conf"]["lexer_type"] = PLACEHOLDER
    data["parser"]["parser"] = _canonical(data["parser"]["parser"])
    return {"data": data, "memo": memo}


def _canonical(table: dict) -> dict:
    """The parse table numbered in a fixed order: symbols by name, states breadth first.

    Lark numbers states and symbols in the order they come out of sets,
    which changes with Python's string hashing from one run to the next;
    the same grammar must give the same file. States are renumbered in the
    order a breadth-first walk from the start state meets them, taking each
    state's transitions by symbol name.
    """
    names = sorted(table["tokens"].values())
    symbol = {name: i for i, name in enumerate(names)}
    old_names = table["tokens"]
    states = table["states"]
    order: dict[int, int] = {}  # old state number -> new
    queue = list(table["start_states"].values())
    for s in queue:
        order.setdefault(s, len(order))
    i = 0
    while i < len(queue):
        for _, (kind, arg) in sorted((old_names[t], act) for t, act in states[queue[i]].items()):
            if kind == 0 and arg not in order:
                order[arg] = len(order)
                queue.append(arg)
        i += 1
    for s in states:  # unreachable states would be a Lark bug; keep them, numbered last
        order.setdefault(s, len(order))
    renumbered = {}
    for s in sorted(states, key=order.__getitem__):
        renumbered[order[s]] = dict(
            sorted(
                (symbol[old_names[t]], (kind, order[arg] if kind == 0 else arg)) for t, (kind, arg) in states[s].items()
            )
        )
    return dict(
        table,
        tokens=dict(enumerate(names)),
        states=renumbered,
        start_states={k: order[v] for k, v in table["start_states"].items()},
        end_states={k: order[v] for k, v in table["end_states"].items()},
    )


def _json_lines(tables: dict) -> list:
    """The tables as JSON text, one state or memo entry a line (a grammar change reads as a small diff).

    JSON has no int keys, so the parse table's symbols and states and the
    memo go in as lists of pairs; :func:`_from_json` turns them back.
    """
    data = tables["data"]
    table = data["parser"]["parser"]
    states, tokens = table["states"], table["tokens"]
    data["parser"]["parser"] = dict(table, states=PLACEHOLDER, tokens=PLACEHOLDER)
    dump = functools.partial(json.dumps, ensure_ascii=True, separators=(",", ":"))
    assert list(tokens) == list(range(len(tokens))) and list(states) == list(range(len(states)))
    lines = ['{"data":' + dump(data) + ",", '"tokens":' + dump(list(tokens.values())) + ",", '"states":[']
    lines += [dump([[sym, kind, arg] for sym, (kind, arg) in acts.items()]) + "," for acts in states.values()]
    lines[-1] = lines[-1][:-1]
    lines += ["],", '"memo":[']
    lines += [dump([k, v]) + "," for k, v in tables["memo"].items()]
    lines[-1] = lines[-1][:-1]
    lines += ["]}"]
    return lines


def _from_json(text: str) -> tuple:
    """(data, memo) for ``Lark._load_from_dict`` from the text :func:`_json_lines` wrote."""
    raw = json.loads(text)
    data = raw["data"]
    table = data["parser"]["parser"]
    table["tokens"] = dict(enumerate(raw["tokens"]))
    table["states"] = {i: {sym: (kind, arg) for sym, kind, arg in acts} for i, acts in enumerate(raw["states"])}
    return data, {k: v for k, v in raw["memo"]}


def module_text(parser: Lark, text: str | None = None) -> str:
    """The source of ``_tables.py`` for ``parser`` built from grammar ``text``."""
    body = "\n".join(f"    {line + chr(10)!r}" for line in _json_lines(serialize(parser)))
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


def load(lexer, postlex, transformer) -> Lark | None:
    """The parser from the shipped tables, or None when they were not made from this grammar and Lark."""
    try:
        from . import _tables
    except ImportError:
        return None
    if (
        getattr(_tables, "GRAMMAR_SHA256", None) != grammar_hash()
        or getattr(_tables, "LARK_VERSION", None) != lark.__version__
    ):
        return None
    data, memo = _from_json(_tables.TABLES_JSON)
    data["options"]["lexer"] = lexer
    data["parser"]["lexer_conf"]["lexer_type"] = lexer
    return Lark._load_from_dict(data, memo, postlex=postlex, transformer=transformer)


def fresh_module_text() -> str:
    """What ``_tables.py`` should hold for the grammar and Lark installed now."""
    from .parser import grammar_parts

    return module_text(build(*grammar_parts()))


def main(argv=None) -> int:
    """Regenerate ``lang/_tables.py`` (or with ``--check``, report whether it is current)."""
    ap = argparse.ArgumentParser(prog="python -m liganimate.lang.tables", description=main.__doc__)
    ap.add_argument("--check", action="store_true", help="only check; exit 1 if the shipped tables are stale")
    args = ap.parse_args(argv)
    path = Path(__file__).with_name(_MODULE)
    text = fresh_module_text()
    current = path.read_text(encoding="utf-8") if path.exists() else None
    if args.check:
        if current != text:
            print(f"{path} is stale: run python -m liganimate.lang.tables", file=sys.stderr)
            return 1
        print(f"{path} is current")
        return 0
    if current != text:
        path.write_text(text, encoding="utf-8")
        print(f"wrote {path}")
    else:
        print(f"{path} already current")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
