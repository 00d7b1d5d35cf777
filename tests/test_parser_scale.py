"""The parser at scale, and the tables it starts from.

* The LALR tables ship in the package (lang/_tables.py) and must be the ones
  the grammar gives today; nothing is read from or written to a cache.
* Parsing memory grows in proportion to the program, and so does the work
  (counted in objects and bytes, never in seconds: the machine is shared).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

from liganimate.lang import parser as P
from liganimate.lang import tables

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# ------------------------------------------------------------------ tables

def test_shipped_tables_are_the_ones_the_grammar_gives():
    path = os.path.join(ROOT, "lang", "_tables.py")
    with open(path, encoding="utf-8") as fh:
        shipped = fh.read()
    assert shipped == tables.fresh_module_text(), "run: python -m liganimate.lang.tables"


def test_tables_do_not_depend_on_string_hashing():
    # Lark numbers states in set order; the file must not change with PYTHONHASHSEED.
    code = "from liganimate.lang import tables; import sys; sys.stdout.write(tables.fresh_module_text())"
    outs = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env=dict(os.environ, PYTHONHASHSEED=seed)).stdout for seed in ("1", "2")}
    assert len(outs) == 1


def test_the_parser_starts_from_the_shipped_tables():
    loaded = tables.load(*P.grammar_parts())
    assert loaded is not None
    # Loading then saving again gives the file back: nothing was lost on the way.
    assert tables.module_text(loaded) == tables.fresh_module_text()
    assert P.build_parser().parser.parser._parse_table.states == loaded.parser.parser._parse_table.states


def test_edited_grammar_is_built_not_loaded(monkeypatch):
    edited = tables.grammar_text() + "\n// edited\n"
    monkeypatch.setattr(tables, "grammar_text", lambda: edited)
    assert tables.load(*P.grammar_parts()) is None


def test_loaded_parser_works_with_lark_own_loop():
    # LigLexer, the post-lexer (PRIM_NAME) and the transformer, through Lark.parse.
    token = P._primitive_names.set(P.BUILTIN_PRIMITIVES)
    try:
        body = P.build_parser().parse("G :- BOX WIDTH 1, HEIGHT 2, DEPTH 3\nX = 1\n")
    finally:
        P._primitive_names.reset(token)
    assert body == P.parse("G :- BOX WIDTH 1, HEIGHT 2, DEPTH 3\nX = 1\n").body


def test_nothing_is_cached_in_the_temporary_folder(tmp_path):
    # Lark's cache=True pickled the tables into the temporary folder and
    # unpickled whatever it found there on the next start. Starting the
    # parser (and the compiler) must leave an empty temporary folder empty.
    code = textwrap.dedent("""
        import os, tempfile
        from liganimate.compiler import compile_text
        from liganimate.lang.parser import build_parser, parse
        build_parser()
        parse("X = 1\\n")
        compile_text("X = 1\\n")
        print(os.listdir(tempfile.gettempdir()))
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False,
                       env=dict(os.environ, TMPDIR=str(tmp_path)))
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"
