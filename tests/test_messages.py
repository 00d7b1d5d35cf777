"""Every sentence liganimate can print, checked for its grammar; and the keyword hints of syntax errors.

The messages and hints are collected from the source (every string or
f-string given to a diagnostic or to an error the command line prints),
each ``{...}`` standing for what is filled in, and put in the form the
tool prints them (``lang.messages.sentence``: runtime libraries write
sentences with a capital and a period, diagnostics and ``liganimate:
error:`` print them without). Then the house rules: a lower-case start
(unless the first word is a LIG word in capitals, an option, a quoted or
filled-in part, or a number), no final period, none of the broken phrases
an earlier version printed ("unexpected the name X"), no doubled word,
no blank before a comma or a period, no doubled blank.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.messages import sentence
from liganimate.lang.parser import parse

ROOT = Path(__file__).resolve().parent.parent
SOURCES = [
    p
    for folder in ("lang", "compiler", "runtime", "src/liganimate")
    for p in sorted((ROOT / folder).rglob("*.py"))
    if p.name != "_tables.py"
]
# Calls whose first (message) and second (hint) arguments are printed to the user.
_PRINTED = re.compile(r"^(Diagnostic|error|warning|LigError|\w+Error|ArgumentTypeError)$")
# Errors that report a bug in a caller's Python, never printed to a user of the command line.
_PROGRAMMING = {"ValueError", "TypeError", "KeyError", "RuntimeError", "NotImplementedError", "AssertionError"}
_PROGRAMMING |= {"IndexError", "AttributeError", "OverflowError", "ImportError", "OSError", "SystemExit"}


def _template(node) -> str | None:
    """The text of a string, f-string or sum of them, each filled-in part as ``{}``; None for anything else."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in node.values)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _template(node.left), _template(node.right)
        return None if left is None or right is None else left + right
    return None


def printed_sentences() -> list:
    """``(file:line, call, template)`` for every message and hint the tool can print."""
    found = []
    for path in SOURCES:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            # message = f"..." / hint = "...", handed to a diagnostic a few lines later.
            if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id in ("message", "hint") for t in node.targets
            ):
                text = _template(node.value)
                if text is not None and " " in text.strip():
                    found.append((f"{path.relative_to(ROOT)}:{node.lineno}", "=", text))
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            if not _PRINTED.match(name) or name in _PROGRAMMING:
                continue
            args = [a for a in node.args if not isinstance(a, ast.Starred)]
            args += [k.value for k in node.keywords if k.arg in ("message", "hint")]
            for arg in args[:4]:
                text = _template(arg)
                if text is not None and " " in text.strip():
                    found.append((f"{path.relative_to(ROOT)}:{node.lineno}", name, text))
    return found


SENTENCES = printed_sentences()
_ALLOWED_START = re.compile(r"^(?:[a-z{'\"$(<\-0-9±]|[A-Z][A-Z0-9_]+\b|[A-Z]\b)")
_BROKEN = re.compile(r"unexpected the |\b(\w+) \1\b|  | [,;]| \.(?![.\w{])|\s$")


def test_the_collection_finds_the_sentences_it_must_check():
    # A collector that found nothing would pass every rule.
    texts = {t for _, _, t in SENTENCES}
    assert len(SENTENCES) > 300
    assert "the file ends too early; expected {}" in texts
    assert "joint identifier {} is used twice in one model" in {sentence(t) for t in texts}
    assert any(t.startswith("unexpected {}; expected {}") for t in texts)


@pytest.mark.parametrize("where, call, text", SENTENCES, ids=[s[0] for s in SENTENCES])
def test_a_printed_sentence_follows_the_house_rules(where, call, text):
    shown = sentence(text)
    assert _ALLOWED_START.match(shown), f"{where}: starts with a capital: {shown!r}"
    assert not shown.endswith(".") or shown.endswith("..."), f"{where}: ends with a period: {shown!r}"
    bad = _BROKEN.search(shown)
    assert bad is None or bad.group(1) in ("that", "had"), f"{where}: {bad.group(0)!r} in {shown!r}"


def _first(text: str):
    with pytest.raises(LigDiagnostics) as info:
        parse(text, "t.lig")
    return info.value.diagnostics[0]


def test_a_misspelt_keyword_gets_a_sentence_and_a_did_you_mean():
    d = _first("INITIALIZE SCENE 1\nSTARTSCENE LENGHT 4\nENDSCENE\n")
    assert d.message == "unexpected name LENGHT; expected LENGTH"
    assert d.hint == "did you mean LENGTH?"
    d = _first("X = 1\nIF X > 1 THNE X = 2\n")
    assert d.hint == "did you mean THEN?" and d.pos.line == 2 and d.pos.column == 10


def test_a_misspelt_statement_keyword_is_reported_at_itself():
    # STARTMOTON is read as a variable; the error would otherwise point at the M after it.
    d = _first("STARTMOTON M\nJOINT 1 POSITION 0, 0, 0\nENDMOTION\n")
    assert (d.pos.line, d.pos.column, d.pos.end_column) == (1, 1, 11)
    assert d.message.startswith("STARTMOTON is not a keyword")
    assert d.hint == "did you mean STARTMOTION?"
    # A name far from every keyword gets no guess.
    d = _first("FOO M\n")
    assert d.hint is None or "did you mean" not in d.hint


def test_the_command_lines_own_sentences_follow_them_too():
    from liganimate import cli

    for text in (cli.NO_SCENE, cli.NO_SCENE_HINT, cli.PROGRAM_HELP):
        assert sentence(text) == text and _BROKEN.search(text) is None and _ALLOWED_START.match(text)


def test_the_rules_catch_the_sentences_they_are_for():
    assert _BROKEN.search("unexpected the name X; expected LENGTH")
    assert _BROKEN.search("the the model") and _BROKEN.search("a model , b")
    assert not _ALLOWED_START.match(sentence("Frames per second must be positive.").upper()[:1] + "rames")
    assert sentence("The VIEW WIDTH must be positive.") == "the VIEW WIDTH must be positive"
    assert _ALLOWED_START.match("STARTMOTON is not a keyword") and _ALLOWED_START.match("--gif needs a file")
