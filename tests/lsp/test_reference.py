"""The keywords' reference text that hover shows is docs/language.md's, as it is now."""

from __future__ import annotations

import json
import pathlib

from paths import ROOT_DIR

from liganimate.lsp import reference

DOC = pathlib.Path(ROOT_DIR) / "docs" / "language.md"


def test_the_shipped_table_is_what_the_document_gives():
    """Fails when docs/language.md changed and reference.json was not written again.

    Write it with ``python -m liganimate.lsp.reference docs/language.md``.
    """
    built = reference.build(DOC.read_text(encoding="utf-8"), reference.grammar_keywords())
    assert reference.dumps(built) == reference.dumps(reference.table()), (
        "docs/language.md changed: run  python -m liganimate.lsp.reference docs/language.md  and commit reference.json"
    )


def test_every_statement_keyword_has_its_section():
    table = reference.table()
    for word, section in {
        "ANIMATE": "4.10 ANIMATE",
        "STARTMOTION": "STARTMOTION ... ENDMOTION",
        "STARTMODEL": "4.6 STARTMODEL",
        "VIEW": "4.11 VIEW",
        "WIDTH": "4.11 VIEW",
        "LOAD": "4.15 LOAD",
        "GOAL": "4.17 STARTREACH",
        "SAMEFRAME": "4.9 Scenes",
        "SIN": "built-in function",
    }.items():
        assert section in table[word], word
    missing = sorted(set(reference.grammar_keywords()) - set(table))
    # Every keyword of the grammar is described somewhere in the reference part of the document.
    assert missing == [], missing


def test_the_table_is_json_text_in_the_package():
    shipped = pathlib.Path(reference.__file__).with_name("reference.json")
    assert json.loads(shipped.read_text(encoding="utf-8")) == reference.table()
