"""The server's analysis with the document's Reparser gives exactly what ``check`` finds, edit after edit.

The server parses only the text around a change (lang/incremental.py);
what it publishes must still be the diagnostics of the whole text, so each
step of a random edit sequence on every example (which LOAD the standard
library) is analysed both ways and compared: the diagnostics (message,
place, severity, hint, notes) and the checked program's tree. The parser's
own property tests are in tests/lang/test_incremental.py; the server is
driven as a real client in test_server.py.
"""

from __future__ import annotations

import os

from hypothesis import given, settings
from hypothesis import strategies as st
from mutations import SOURCES, fuzz, mutation
from paths import ROOT_DIR

from liganimate.lang.parser import reparser as new_reparser
from liganimate.lsp.analysis import analyse


def _seen(a) -> tuple:
    diagnostics = [(d.filename, d.pos, d.message, d.hint, d.severity, tuple(d.notes)) for d in a.diagnostics]
    return diagnostics, a.program.body if a.program is not None else None, a.checked is not None


@settings(max_examples=40, deadline=None)
@given(st.integers(0, len(SOURCES) - 1), st.lists(mutation, min_size=1, max_size=4))
def test_each_edit_is_analysed_as_the_whole_text_is(index, steps):
    name, text = SOURCES[index]
    path = os.path.join(ROOT_DIR, "examples", name)
    reparser = new_reparser()
    analyse(text, path, whole=False, reparser=reparser)
    for kind, u, v, pick in steps:
        text = fuzz.mutate(text, kind, u, v, pick)
        incremental = analyse(text, path, whole=False, reparser=reparser)
        assert _seen(incremental) == _seen(analyse(text, path, whole=False)), (kind, u, v, pick)


def test_a_broken_block_in_a_big_program_is_reported_as_check_reports_it():
    import sys

    sys.path.insert(0, os.path.join(ROOT_DIR, "benchmarks"))
    from compile import thesis_style_program

    text = thesis_style_program(2000)
    path = os.path.join(ROOT_DIR, "examples", "big.lig")
    reparser = new_reparser()
    assert analyse(text, path, whole=False, reparser=reparser).diagnostics == []
    at = text.index("JOINT", text.index("STARTMOTION", len(text) // 2))
    for broken in ("JOINT 99, FRAME 1 ", "JOINT (1, 2) ", "ENDMOTION\n      ", "FRAME -1 POSITION 0,0,0\n      "):
        edited = text[:at] + broken + text[at:]
        got = analyse(edited, path, whole=False, reparser=reparser)
        assert got.diagnostics, broken
        assert _seen(got) == _seen(analyse(edited, path, whole=False))
    assert analyse(text, path, whole=False, reparser=reparser).diagnostics == []
    assert reparser.reused > 0.9 * len(text)
