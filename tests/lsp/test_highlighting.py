"""Highlighting everywhere: the Pygments lexer (through its entry point) and the VS Code TextMate grammar.

Both are checked against the language itself: their word classes are the
grammar's keywords, the built-in functions, the interpolation methods and
the solvers; and on every example, every standard library file and every
```lig block of the docs, each keyword, number, string, comment and name
(as the tolerant scan of the language server cuts the text) gets a token
of its own class: Pygments with no error token, and the TextMate grammar,
run by VS Code's own tokenizer (vscode-textmate on vscode-oniguruma) in
node, with a scope beyond the file's ``source.lig``.
"""

from __future__ import annotations

import glob
import json
import os
import re
import subprocess

import pytest
from editor_tools import tools_or_skip
from paths import ROOT_DIR, TESTS_DIR
from pygments.lexers import get_lexer_by_name, get_lexer_for_filename
from pygments.token import Comment, Error, Keyword, Name, Number, Operator, String

from liganimate import highlighting as H
from liganimate.lang import parser as P
from liganimate.lang.vocabulary import FUNCTIONS
from liganimate.lsp import scan
from liganimate.lsp.completion import keyword_terminals
from liganimate.runtime.ik.solvers import SOLVER_KEYWORDS
from liganimate.runtime.motion import interpolation

GRAMMAR = os.path.join(ROOT_DIR, "editors", "vscode", "syntaxes", "lig.tmLanguage.json")
TOKENIZE = os.path.join(TESTS_DIR, "lsp", "tokenize.js")
FILES = sorted(
    glob.glob(os.path.join(ROOT_DIR, "examples", "*.lig")) + glob.glob(os.path.join(ROOT_DIR, "stdlib", "*.lig"))
)
DOCS = [os.path.join(ROOT_DIR, "README.md"), os.path.join(ROOT_DIR, "examples", "README.md")] + sorted(
    glob.glob(os.path.join(ROOT_DIR, "docs", "*.md"))
)
_LIG_BLOCK = re.compile(r"^```lig\n(.*?)^```", re.MULTILINE | re.DOTALL)


def doc_blocks() -> list:
    """``(name, text)`` of every ```lig block of the docs."""
    out = []
    for path in DOCS:
        text = open(path, encoding="utf-8").read()
        for i, m in enumerate(_LIG_BLOCK.finditer(text)):
            out.append((f"{os.path.relpath(path, ROOT_DIR)}#{i + 1}", m.group(1)))
    return out


def corpus() -> list:
    """``(name, text)`` of every example, library file and docs block."""
    files = [(os.path.relpath(p, ROOT_DIR), open(p, encoding="utf-8").read()) for p in FILES]
    return files + doc_blocks()


def test_the_corpus_is_there():
    names = [n for n, _ in corpus()]
    assert len(FILES) >= 16 and sum(1 for n in names if "#" in n) >= 8, names


# ------------------------------------------------------------------ word classes


def test_word_classes_are_the_languages():
    grammar = set(keyword_terminals(P.grammar().terminals))
    classed = set(H.CONTROL) | set(H.TYPES) | set(H.keywords()) | set(H.WORD_OPERATORS)
    assert classed == grammar
    for group in (H.CONTROL, H.TYPES, H.keywords(), H.WORD_OPERATORS):
        assert len(set(group)) == len(group)
    assert set(H.FUNCTIONS) == set(FUNCTIONS) - grammar
    assert set(H.CONSTANTS) == set(interpolation.names()) | set(SOLVER_KEYWORDS)


def _alternatives(pattern: str) -> set:
    m = re.search(r"\(\?i:([A-Z0-9_|]+)\)", pattern)
    assert m is not None, pattern
    return set(m.group(1).split("|"))


def test_the_textmate_grammar_is_written_from_the_word_classes():
    """Fails when a word class changed and the grammar was not written again.

    Write it with ``python -m liganimate.highlighting editors/vscode/syntaxes/lig.tmLanguage.json``.
    """
    assert open(GRAMMAR, encoding="utf-8").read() == H.textmate_json()
    grammar = json.load(open(GRAMMAR, encoding="utf-8"))
    by_scope = {p["name"]: p["match"] for p in grammar["repository"]["words"]["patterns"]}
    assert _alternatives(by_scope["keyword.control.lig"]) == set(H.CONTROL)
    assert _alternatives(by_scope["storage.type.lig"]) == set(H.TYPES)
    assert _alternatives(by_scope["keyword.other.lig"]) == set(H.keywords())
    assert _alternatives(by_scope["keyword.operator.word.lig"]) == set(H.WORD_OPERATORS)
    assert _alternatives(by_scope["support.function.builtin.lig"]) == set(H.FUNCTIONS) | set(H.PRIMITIVES)
    assert _alternatives(by_scope["support.constant.lig"]) == set(H.CONSTANTS)


# ------------------------------------------------------------------ what each piece of text is


def pieces(text: str) -> list:
    """``(start, end, class)`` of each keyword, number, string, comment and name, as the language server's scan cuts them."""
    keywords = set(keyword_terminals(P.grammar().terminals))
    out = []
    for t in scan.tokens(text):
        if t.kind == "word":
            kind = "keyword" if t.value in keywords else "name"
        elif t.kind in ("number", "string", "comment"):
            kind = t.kind
        elif t.kind == "dollar":
            kind = "name"
        else:
            continue
        out.append((t.start, t.end, kind))
    return out


_PYGMENTS = {
    # A keyword is contextual (docs/language.md, section 1): where it names a variable it may be coloured as a name.
    "keyword": (Keyword, Operator.Word, Name),
    "name": (Name,),
    "number": (Number,),
    "string": (String,),
    "comment": (Comment, String.Doc),
}


def test_pygments_finds_the_lexer_by_its_entry_point():
    assert type(get_lexer_by_name("lig")) is H.LigLexer
    assert type(get_lexer_for_filename("scene.lig")) is H.LigLexer


@pytest.mark.parametrize("name, text", corpus(), ids=[n for n, _ in corpus()])
def test_pygments_gives_each_piece_its_class_and_no_error(name, text):
    lexer = get_lexer_by_name("lig", stripnl=False, ensurenl=False)
    classes = [(start, start + len(value), token) for start, token, value in lexer.get_tokens_unprocessed(text)]
    errors = [text[s:e] for s, e, token in classes if token in Error]
    assert errors == [], f"{name}: error tokens {errors[:5]}"
    for start, end, kind in pieces(text):
        covering = [token for s, e, token in classes if s <= start and end <= e]
        assert covering, f"{name}: {text[start:end]!r} at {start} is split across tokens"
        assert any(covering[0] in c for c in _PYGMENTS[kind]), (
            f"{name}: {text[start:end]!r} is {covering[0]}, not a {kind}"
        )


_SCOPES = {
    "keyword": ("keyword.", "storage.type.", "entity.name."),
    "name": ("variable.", "entity.name.", "support."),
    "number": ("constant.numeric.",),
    "string": ("string.",),
    "comment": ("comment.",),
}


def test_vscode_tokenizer_gives_each_piece_a_scope_of_its_class(tmp_path):
    modules = tools_or_skip()
    files = []
    for i, (name, text) in enumerate(corpus()):
        path = tmp_path / f"{i:03d}.lig"
        path.write_text(text, encoding="utf-8")
        files.append((name, str(path), text))
    done = subprocess.run(
        ["node", TOKENIZE, modules, GRAMMAR, *[p for _, p, _ in files]],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    results = [json.loads(line) for line in done.stdout.splitlines()]
    assert [r["file"] for r in results] == [p for _, p, _ in files]
    checked = 0
    for (name, _, text), result in zip(files, results):
        # Token offsets are per line; make them offsets into the text.
        spans = []
        starts = [0] + [m.end() for m in re.finditer("\n", text)]
        for line_start, tokens in zip(starts, result["lines"]):
            for start, end, scopes in tokens:
                spans.append((line_start + start, line_start + end, scopes))
        for start, end, kind in pieces(text):
            covering = [scopes for s, e, scopes in spans if s < end and start < e]
            assert covering, f"{name}: {text[start:end]!r} has no token"
            for scopes in covering:
                assert scopes[0] == "source.lig" and len(scopes) > 1, f"{name}: {text[start:end]!r} has no scope"
                assert any(s.startswith(_SCOPES[kind]) for s in scopes[1:]), (
                    f"{name}: {text[start:end]!r} is {scopes}, not a {kind}"
                )
            checked += 1
    assert checked > 10000
