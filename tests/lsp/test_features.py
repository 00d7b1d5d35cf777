"""The server's features in process, on text as an editor holds it: whole, cut anywhere, garbled, huge.

The end-to-end tests (test_server.py) go through the protocol; these call
the modules behind it on many more texts: every example and library file
cut at many places, and with lines dropped, so that each feature is asked
about broken text the way typing makes it. None may raise, and none may
run the program.
"""

from __future__ import annotations

import glob
import os
import random
import zlib

import pytest
from paths import ROOT_DIR

from liganimate.lang.source import MAX_SOURCE_BYTES
from liganimate.lsp import completion as C
from liganimate.lsp import hover as H
from liganimate.lsp import navigation as N
from liganimate.lsp import outline, scan
from liganimate.lsp.analysis import analyse
from liganimate.lsp.lookup import target
from liganimate.lsp.server import _completions

FILES = sorted(
    glob.glob(os.path.join(ROOT_DIR, "examples", "*.lig")) + glob.glob(os.path.join(ROOT_DIR, "stdlib", "*.lig"))
)


def broken_versions(text: str, seed: int, count: int = 6) -> list:
    """``text`` cut off at random places, and with a random run of lines dropped."""
    rng = random.Random(seed)
    out = [text[: rng.randrange(len(text))] for _ in range(count)]
    lines = text.split("\n")
    for _ in range(count):
        a = rng.randrange(len(lines))
        out.append("\n".join(lines[:a] + lines[a + rng.randrange(1, 6) :]))
    return out


def ask_everything(source: str, path: str, good) -> None:
    """Every feature, at a spread of offsets of ``source``, answered from its analysis and ``good``."""
    latest = analyse(source, path)
    assert latest.diagnostics or latest.parsed
    rng = random.Random(len(source))
    for offset in sorted(rng.sample(range(len(source) + 1), min(12, len(source) + 1))):
        where = target(source, offset, latest, good)
        H.hover(source, offset, where, latest, good)
        if where is not None:
            N.definition(where, source, latest, good)
            N.references(where, source, latest)
            try:
                N.prepare(where, latest)
            except N.RenameRefused:
                pass
        _completions(source, offset, good, path)
    outline.folds(source)
    outline.symbols(latest)


@pytest.mark.parametrize("path", FILES, ids=[os.path.basename(p) for p in FILES])
def test_every_feature_answers_on_broken_text(path):
    text = open(path, encoding="utf-8").read()
    good = analyse(text, path)
    assert good.parsed and good.checked is not None, good.diagnostics
    # A seed of the file's name (crc32, not hash(): the same cuts in every process).
    for broken in broken_versions(text, seed=zlib.crc32(os.path.basename(path).encode())):
        ask_everything(broken, path, good)


def test_nothing_is_executed(monkeypatch):
    """The analysis compiles libraries but never executes a module: executing one raises here."""
    from liganimate.runtime import loader

    def refuse(*args, **kwargs):
        raise AssertionError("the language server executed program text")

    monkeypatch.setattr(loader, "exec_module", refuse)
    for path in FILES:
        text = open(path, encoding="utf-8").read()
        ask_everything(text, path, analyse(text, path))


def test_a_text_larger_than_a_source_may_be_is_refused_unread():
    huge = "X = 1\n" * (MAX_SOURCE_BYTES // 6 + 1)
    a = analyse(huge, "/tmp/huge.lig")
    assert not a.parsed and len(a.diagnostics) == 1
    assert "larger than 64 MB" in a.diagnostics[0].message


def test_completion_takes_the_grammars_word():
    prims = frozenset({"BOX"})
    assert C.keywords_for(C.terminals_at("VIEW ", 5, prims)) == ["POINT", "WIDTH"]
    assert set(C.keywords_for(C.terminals_at("IF X > 1 ", 9, prims))) == {"AND", "OR", "THEN", "MOD"}
    text = "STARTMODEL R\n JOINT 3, A, (0,0,0), B, (0,0,0), (0,0)\n"
    inside = set(C.keywords_for(C.terminals_at(text, len(text), prims)))
    assert {"ENDMODEL", "JOINT"} <= inside and not inside & {"ANIMATE", "STARTMODEL", "ENDMOTION", "FRAME"}
    # A long program: the run starts at the statement, not at the top.
    long = "X = 1\n" * 20000 + "VIEW "
    assert C.keywords_for(C.terminals_at(long, len(long), prims)) == ["POINT", "WIDTH"]


def test_folds_pair_block_words_even_when_the_text_is_broken():
    text = "STARTMODEL A\n JOINT 1, B, (0,0,0), C, (0,0,0), (0,0)\n\nENDMODEL\nDO 10 I = 1, 3\n X = I\n\n10 CONTINUE\nSTARTMOTION M\n JOINT 1\n"
    folds = {(f.start_line, f.end_line) for f in outline.folds(text)}
    assert (0, 2) in folds and (4, 6) in folds
    blocks = scan.blocks(scan.tokens(text))
    assert [b.opener for b in blocks if b.end is None] == ["STARTMOTION"]


def printed_tables(text: str, path: str) -> dict:
    """MODEL name -> {joint: ((x min, x max), (y...), (z...))} as ``PRINT $MODEL`` writes them when the program runs."""
    import re
    import subprocess
    import sys

    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "check", path], capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, done.stderr
    tables: dict = {}
    for line in done.stdout.splitlines():
        m = re.match(r"MOTION (\w+): length (\S+) frames, joints (.*)$", line)
        if m:
            joints = frozenset(int(j) for j in m.group(3).split(", ")) if m.group(3) != "none" else frozenset()
            tables[m.group(1)] = (float(m.group(2)), joints)
    current = None
    pair = r"\((-?[\d.eE+]+), (-?[\d.eE+]+)\)"
    for line in done.stdout.splitlines():
        m = re.match(r"MODEL (\w+)$", line)
        if m:
            current = tables.setdefault(m.group(1), {})
            continue
        m = re.match(r"No\. (\d+)\s+\([^)]*\)\s+" + r"\s+".join([pair] * 3), line)
        if m and current is not None:
            n = [float(x) for x in m.groups()[1:]]
            current[int(m.group(1))] = ((n[0], n[1]), (n[2], n[3]), (n[4], n[5]))
    return tables


def test_what_hover_reads_is_what_the_run_prints(tmp_path):
    """A model's joints and extremes, a motion's length and joints, read from the text, are what PRINT shows when it runs.

    Every model and motion of the standard library, and Appendix A's HUMAN
    (built by JOINT assignments, moved in its scene).
    """
    from liganimate.lsp import statics

    compared = 0
    for lib in sorted(glob.glob(os.path.join(ROOT_DIR, "stdlib", "*.lig"))):
        name = os.path.basename(lib)[:-4]
        path = str(tmp_path / f"{name}.lig")
        a = analyse(f"LOAD '{name}'\n", path)
        assert a.env is not None
        models = {n: v for n, v in a.env.values.items() if isinstance(v, statics.ModelValue)}
        motions = {n: v for n, v in a.env.values.items() if isinstance(v, statics.MotionValue)}
        text = f"LOAD '{name}'\n" + "".join(f"PRINT ${n}\n" for n in models) + "".join(f"PRINT {n}\n" for n in motions)
        printed = printed_tables(text, path)
        for n, value in models.items():
            assert value.joints is not None, n
            read = {j.ident: j.extremes for j in value.joints}
            assert read == printed[n], n
            compared += 1
        for n, motion in motions.items():
            if motion.length is not None and motion.joints is not None:
                assert (motion.length, motion.joints) == printed[n], n
                compared += 1
    appendix = open(os.path.join(ROOT_DIR, "examples", "appendix_a.lig"), encoding="utf-8").read()
    path = str(tmp_path / "appendix_a.lig")
    human = analyse(appendix, path).env.values["HUMAN"]
    printed = printed_tables(appendix.replace("*     SHOOTSCENE", "      PRINT $HUMAN\n*     SHOOTSCENE"), path)
    assert {j.ident: j.extremes for j in human.joints} == printed["HUMAN"]
    assert compared >= 15, compared


def test_hover_holds_a_re_rooted_submodel_by_the_link_figure_chose(tmp_path):
    """After FIGURE S MAIN LINK C, a JOINT takes S by C (thesis 3.3): the joint's links say so."""
    from liganimate.lsp import statics

    text = (
        "      GRAPHICAL A, B, LEG, FOOT\n"
        "      MODEL S, M, K\n"
        + "".join(f"      {g} :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0\n" for g in ("A", "B", "LEG", "FOOT"))
        + "      S :- JOINT 1, B, (0.0, -1.0, 0.0), LEG, (0.0, 1.0, 0.0), (0.0, 90.0)\n"
        "      S :- JOINT 3, S, (0.0, 1.0, 0.0), FOOT, (0.0, 0.0, 0.0), (0.0, 90.0)\n"
        "      FIGURE S MAIN LINK LEG\n"
        "      M :- JOINT 2, A, (1.0, 0.0, 0.0), S, (0.5, 0.0, 0.0), (0.0, 90.0)\n"
        "      FIGURE S MAIN JOINT 3\n"
        "      K :- JOINT 4, A, (1.0, 0.0, 0.0), S, (0.5, 0.0, 0.0), (0.0, 90.0)\n"
    )
    a = analyse(text, str(tmp_path / "graft.lig"))
    assert a.env is not None
    s, m, k = (a.env.values[n] for n in ("S", "M", "K"))
    assert isinstance(m, statics.ModelValue) and isinstance(k, statics.ModelValue)
    assert s.main == "B" and s.current == "FOOT"
    links = {j.ident: (j.parent, j.child) for j in m.joints}
    assert links[2] == ("A", "LEG")
    assert {j.ident: (j.parent, j.child) for j in k.joints}[4] == ("A", "FOOT")
    assert "animated from FOOT" in statics.describe(s)
