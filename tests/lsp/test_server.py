"""``liganimate lsp`` end to end: pytest-lsp starts the real command and talks to it over stdio as an editor would.

Every feature of issue 21 is asked for by a real client: diagnostics (the
same sentences, positions, severities and hints as ``liganimate check``),
hover, completion, definition (into the standard library and into a
library file of the program's own), references, symbols, rename, folding,
and the answers while the text is broken.
"""

from __future__ import annotations

import asyncio
import os
import pathlib
import re
import subprocess
import sys

import pytest
import pytest_lsp
from lsprotocol import types as T
from pygls.uris import from_fs_path, to_fs_path
from pytest_lsp import ClientServerConfig, LanguageClient

PROGRAM = """\
C A figure of our own, a motion, the standard humanoid and a prop of our own.
      LOAD HUMANOID, WALK FROM 'humanoid'
      LOAD LAMP FROM 'props.lig'
      REAL SPEED
      GRAPHICAL UPPER, LOWER
      SPEED = 2.5 * 2
      TILT = (0.0, 45.0, 90.0)
      UPPER :- BOX WIDTH 0.2, HEIGHT 1.0, DEPTH 0.2
      LOWER :- BOX WIDTH 0.2, HEIGHT 0.8, DEPTH 0.2
      STARTMODEL ARM
        JOINT 1, UPPER, (0.0, -0.5, 0.0), LOWER, (0.0, 0.4, 0.0),
                 (0.0, 135.0), (-20.0, 20.0)
      ENDMODEL
      STARTMOTION BEND
        JOINT 1 POSITION 0.0, 0.0, 0.0
          FRAME 12 POSITION 90.0, 0.0, 0.0 INTERPOLATION ACCDCC
          FRAME 24 POSITION 0.0, 0.0, 0.0
      ENDMOTION
      BOTH = 2 * BEND + WALK
      INITIALIZE SCENE 1
          VIEW WIDTH = 4.0
          BACKGROUND LAMP
      STARTSCENE LENGTH 48
          ANIMATE HUMANOID FROM 0 TO 47 USING WALK
          ANIMATE ARM FROM 0 TO 47 USING BEND REPEAT
      ENDSCENE
      SHOOTSCENES
"""

PROPS = """\
{@ LAMP: a lamp on a stand }
      LAMP :- BOX WIDTH 0.3, HEIGHT 1.5, DEPTH 0.3, LIGHTNESS 80.0
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> pathlib.Path:
    root = tmp_path_factory.mktemp("lsp")
    (root / "props.lig").write_text(PROPS)
    (root / "scene.lig").write_text(PROGRAM)
    return root


@pytest_lsp.fixture(
    scope="module",
    config=ClientServerConfig(server_command=[sys.executable, "-m", "liganimate", "lsp"]),
)
async def client(lsp_client: LanguageClient, tmp_path_factory):
    record_versions(lsp_client)
    result = await lsp_client.initialize_session(
        T.InitializeParams(capabilities=pytest_lsp.client_capabilities("visual-studio-code"))
    )
    CAPABILITIES.append(result.capabilities)
    yield
    await lsp_client.shutdown_session()


pytestmark = pytest.mark.asyncio(loop_scope="module")


def pos_of(text: str, needle: str, nth: int = 0, into: int = 0) -> T.Position:
    """The position of the ``nth`` occurrence of ``needle`` in ``text``, ``into`` characters in."""
    at = -1
    for _ in range(nth + 1):
        at = text.index(needle, at + 1)
    at += into
    line = text.count("\n", 0, at)
    return T.Position(line=line, character=at - (text.rfind("\n", 0, at) + 1))


#: What the server said it can do, at initialize.
CAPABILITIES: list = []

#: (uri, version) -> the diagnostics the server published for that version of the document.
PUBLISHED: dict = {}


def record_versions(client: LanguageClient) -> None:
    """Keep each published version's diagnostics, beside what pytest-lsp's own handler keeps."""
    features = client.protocol.fm.features
    theirs = features[T.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS]

    def record(params: T.PublishDiagnosticsParams):
        PUBLISHED[(params.uri, params.version)] = params.diagnostics
        return theirs(params)

    features[T.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS] = record


async def diagnostics_for(client: LanguageClient, uri: str, version: int) -> list:
    """Wait for the diagnostics of ``version`` of the document (the server sends each version's once)."""
    for _ in range(400):
        if (uri, version) in PUBLISHED:
            return PUBLISHED[(uri, version)]
        await asyncio.sleep(0.05)
    raise AssertionError(f"no diagnostics for version {version} of {uri} within 20 s")


async def open_doc(client: LanguageClient, path: pathlib.Path, text: str | None = None) -> str:
    uri = from_fs_path(str(path))
    client.text_document_did_open(
        T.DidOpenTextDocumentParams(
            text_document=T.TextDocumentItem(
                uri=uri, language_id="lig", version=1, text=text if text is not None else path.read_text()
            )
        )
    )
    await diagnostics_for(client, uri, 1)
    return uri


def change(client: LanguageClient, uri: str, version: int, text: str) -> None:
    client.text_document_did_change(
        T.DidChangeTextDocumentParams(
            text_document=T.VersionedTextDocumentIdentifier(uri=uri, version=version),
            content_changes=[T.TextDocumentContentChangeWholeDocument(text=text)],
        )
    )


def check_output(path: pathlib.Path) -> str:
    """What ``liganimate check`` prints on standard error for ``path``."""
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "check", str(path)],
        capture_output=True,
        text=True,
        cwd=path.parent,
        timeout=120,
    )
    return done.stderr


@pytest.mark.parametrize(
    "name, old, new, expected",
    [
        ("wrong.lig", "SPEED = 2.5 * 2", "SPEED = UPPER + 1", "cannot add an INTEGER to a GRAPHICAL object"),
        ("warned.lig", "      REAL SPEED", "C = 3 looks like a statement\n      REAL SPEED", "this line is a comment"),
        ("unparsed.lig", "      ENDMODEL\n", "", "unexpected 'STARTMOTION'; expected ENDMODEL or JOINT"),
        ("unloaded.lig", "'humanoid'", "'humanoids'", "there is no library 'humanoids'"),
    ],
)
async def test_diagnostics_are_those_check_prints(
    client: LanguageClient, folder: pathlib.Path, name, old, new, expected
):
    text = PROGRAM.replace(old, new)
    path = folder / name
    path.write_text(text)
    uri = from_fs_path(str(path))
    client.text_document_did_open(
        T.DidOpenTextDocumentParams(text_document=T.TextDocumentItem(uri=uri, language_id="lig", version=1, text=text))
    )
    found = await diagnostics_for(client, uri, 1)
    printed = check_output(path)
    assert any(expected in d.message for d in found), found
    for d in found:
        first_line = d.message.split("\n")[0]
        head = f"{path}:{d.range.start.line + 1}:{d.range.start.character + 1}: "
        severity = "error" if d.severity == T.DiagnosticSeverity.Error else "warning"
        assert head + f"{severity}: {first_line}" in printed
        for line in d.message.split("\n")[1:]:
            assert "  " + line in printed


async def test_diagnostics_of_a_clean_program_are_none(client: LanguageClient, folder: pathlib.Path):
    uri = from_fs_path(str(folder / "scene.lig"))
    client.text_document_did_open(
        T.DidOpenTextDocumentParams(
            text_document=T.TextDocumentItem(uri=uri, language_id="lig", version=1, text=PROGRAM)
        )
    )
    assert list(await diagnostics_for(client, uri, 1)) == []


async def hover_text(client: LanguageClient, uri: str, position: T.Position) -> str:
    result = await client.text_document_hover_async(
        T.HoverParams(text_document=T.TextDocumentIdentifier(uri=uri), position=position)
    )
    assert result is not None
    assert isinstance(result.contents, T.MarkupContent)
    return result.contents.value


async def test_hover(client: LanguageClient, folder: pathlib.Path):
    uri = from_fs_path(str(folder / "scene.lig"))
    method = await hover_text(client, uri, pos_of(PROGRAM, "ACCDCC", into=2))
    assert "STARTMOTION ... ENDMOTION" in method
    animate = await hover_text(client, uri, pos_of(PROGRAM, "ANIMATE HUMANOID", into=2))
    assert "4.10 ANIMATE" in animate and "animate_stmt = ANIMATE name FROM expr TO expr USING expr" in animate
    arm = await hover_text(client, uri, pos_of(PROGRAM, "ARM FROM", into=1))
    assert "**ARM**: MODEL" in arm
    assert "| 1 | UPPER → LOWER | 0° to 135° | -20° to 20° | locked |" in arm
    bend = await hover_text(client, uri, pos_of(PROGRAM, "USING BEND", into=7))
    assert "**BEND**: MOTION" in bend and "length: 24 frames" in bend and "joints driven: 1" in bend
    speed = await hover_text(client, uri, pos_of(PROGRAM, "SPEED =", into=1))
    assert "**SPEED**: REAL" in speed and "`5`" in speed and "declared at line 4" in speed
    tilt = await hover_text(client, uri, pos_of(PROGRAM, "TILT", into=1))
    assert "**TILT**: VECTOR" in tilt and "`(0, 45, 90)`" in tilt
    walk = await hover_text(client, uri, pos_of(PROGRAM, "USING WALK", into=7))
    assert "loaded from 'humanoid'" in walk and "**WALK**: MOTION" in walk
    both = await hover_text(client, uri, pos_of(PROGRAM, "BOTH", into=1))
    # What the server reads from the text, without running it, is what the program prints when it runs.
    printed = printed_motions(folder, ["WALK", "BOTH", "BEND"])
    for name, shown in (("WALK", walk), ("BOTH", both), ("BEND", bend)):
        length, joints = printed[name]
        assert f"length: {length} frames" in shown and f"joints driven: {joints}" in shown
    lamp = await hover_text(client, uri, pos_of(PROGRAM, "LAMP", nth=1, into=1))
    assert "a lamp on a stand" in lamp and "loaded from 'props.lig'" in lamp
    box = await hover_text(client, uri, pos_of(PROGRAM, "BOX", into=1))
    assert "BOX [AT centre], WIDTH width, HEIGHT height, DEPTH depth, [LIGHTNESS light]" in box


def printed_motions(folder: pathlib.Path, names: list) -> dict:
    """NAME -> (length, joints) as ``PRINT`` writes them when ``liganimate check`` runs the program."""
    path = folder / "printing.lig"
    path.write_text(PROGRAM.replace("      SHOOTSCENES\n", "      PRINT " + ", ".join(names) + "\n"))
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "check", str(path)], capture_output=True, text=True, timeout=120
    )
    out = {}
    for line in done.stdout.splitlines():
        m = re.match(r"MOTION (\w+): length (\S+) frames, joints (.*)$", line)
        if m:
            out[m.group(1)] = (m.group(2), m.group(3))
    assert set(out) == set(names), done.stdout + done.stderr
    return out


async def completion_labels(client: LanguageClient, uri: str, position: T.Position) -> set:
    result = await client.text_document_completion_async(
        T.CompletionParams(text_document=T.TextDocumentIdentifier(uri=uri), position=position)
    )
    assert result is not None
    items = result.items if isinstance(result, T.CompletionList) else result
    return {i.label for i in items}


async def test_completion(client: LanguageClient, folder: pathlib.Path):
    path = folder / "typing.lig"
    uri = await open_doc(client, path, PROGRAM)
    version = 1

    async def at_end_of(extra: str, where: str = "      SHOOTSCENES\n") -> set:
        nonlocal version
        version += 1
        text = PROGRAM.replace(where, where + extra)
        change(client, uri, version, text)
        return await completion_labels(client, uri, pos_of(text, extra, into=len(extra)))

    view = await at_end_of("      VIEW ")
    assert {"POINT", "WIDTH"} <= view and "ANIMATE" not in view
    # The modifiers the grammar takes after <, narrowed to those of the value's type.
    graphical = await at_end_of("      X = UPPER <")
    assert graphical == {"SCALE", "TRANS", "ROT", "LIGHTNESS", "COLOUR", "COLOR"}
    assert await at_end_of("      X = BEND <") == {"SCALE"}
    assert await at_end_of("      X = BEND <SCALE ") == {"FRAMES", "FRAME", "EXTREMES", "EXTREME"}
    assert {"TRANS", "ROT", "SCALE"} == await at_end_of("      X = ARM <")
    methods = await at_end_of("      BEND[1, 3] = FRAME 30 POSITION 0, 0, 0 INTERPOLATION ")
    assert {"LINEAR", "ACCELERATE", "DECELERATE", "ACCDCC"} <= methods
    statement = await at_end_of("      ")
    assert {"ANIMATE", "STARTMOTION", "LOAD", "SPEED", "ARM", "BEND", "WALK", "HUMANOID"} <= statement
    assert "ENDMOTION" not in statement
    inside = await at_end_of("      STARTMOTION M2\n        JOINT 1 ")
    assert {"POSITION", "FRAME", "ENDMOTION", "ENDJOINT"} <= inside and "ANIMATE" not in inside
    box = await at_end_of("      G :- BOX WIDTH 1, ")
    assert box == {"HEIGHT"}
    libraries = await at_end_of("      LOAD '")
    assert {"humanoid", "shapes", "./props.lig"} <= libraries
    offered = await completion_labels(client, uri, pos_of(PROGRAM, "HUMANOID, WALK", into=0))
    assert {"HUMANOID", "WALK", "RUN", "WAVE"} <= offered


async def test_definition_in_the_file_and_in_libraries(client: LanguageClient, folder: pathlib.Path):
    uri = from_fs_path(str(folder / "scene.lig"))

    async def definition(position: T.Position) -> T.Location:
        result = await client.text_document_definition_async(
            T.DefinitionParams(text_document=T.TextDocumentIdentifier(uri=uri), position=position)
        )
        assert isinstance(result, T.Location)
        return result

    local = await definition(pos_of(PROGRAM, "USING BEND", into=7))
    assert local.uri == uri and local.range.start == pos_of(PROGRAM, "BEND")
    speed = await definition(pos_of(PROGRAM, "SPEED =", into=2))
    assert speed.range.start == pos_of(PROGRAM, "SPEED")  # the declaration
    walk = await definition(pos_of(PROGRAM, "USING WALK", into=7))
    walk_file = pathlib.Path(to_fs_path(walk.uri) or "")
    assert walk_file.name == "humanoid.lig" and walk_file.parent.name == "stdlib"
    line = walk_file.read_text().split("\n")[walk.range.start.line]
    assert line[walk.range.start.character : walk.range.end.character] == "WALK"
    lamp = await definition(pos_of(PROGRAM, "BACKGROUND LAMP", into=12))
    assert to_fs_path(lamp.uri) == str(folder / "props.lig")
    assert lamp.range.start == T.Position(line=1, character=6)


async def test_references_and_symbols(client: LanguageClient, folder: pathlib.Path):
    uri = from_fs_path(str(folder / "scene.lig"))
    refs = await client.text_document_references_async(
        T.ReferenceParams(
            text_document=T.TextDocumentIdentifier(uri=uri),
            position=pos_of(PROGRAM, "UPPER", nth=1),
            context=T.ReferenceContext(include_declaration=True),
        )
    )
    assert refs is not None
    assert [r.range.start for r in refs] == [pos_of(PROGRAM, "UPPER", nth=i) for i in range(3)]
    symbols = await client.text_document_document_symbol_async(
        T.DocumentSymbolParams(text_document=T.TextDocumentIdentifier(uri=uri))
    )
    assert symbols is not None
    by_name = {s.name: s for s in symbols if isinstance(s, T.DocumentSymbol)}
    assert by_name["ARM"].kind == T.SymbolKind.Class and by_name["BEND"].kind == T.SymbolKind.Event
    assert by_name["SCENE 1"].kind == T.SymbolKind.Module
    assert by_name["SCENE 1"].range.end.line == PROGRAM.split("\n").index("      ENDSCENE")
    assert by_name["SPEED"].detail == "REAL" and by_name["WALK"].detail == "MOTION (loaded)"


async def test_rename(client: LanguageClient, folder: pathlib.Path):
    uri = from_fs_path(str(folder / "scene.lig"))
    doc = T.TextDocumentIdentifier(uri=uri)
    edit = await client.text_document_rename_async(
        T.RenameParams(text_document=doc, position=pos_of(PROGRAM, "BEND", nth=1), new_name="flex")
    )
    assert edit is not None and edit.changes is not None
    edits = edit.changes[uri]
    assert {e.new_text for e in edits} == {"FLEX"}
    assert sorted(e.range.start.line for e in edits) == [
        i for i, line in enumerate(PROGRAM.split("\n")) if "BEND" in line
    ]
    for refused, new in (("WALK", "STRIDE"), ("UPPER", "LOWER"), ("UPPER", "ANIMATE")):
        with pytest.raises(Exception) as caught:
            await client.text_document_rename_async(
                T.RenameParams(text_document=doc, position=pos_of(PROGRAM, refused, into=1), new_name=new)
            )
        assert "rename" in str(caught.value) or "already" in str(caught.value) or "cannot name" in str(caught.value)


async def test_lines_are_counted_as_the_editor_counts_them(client: LanguageClient, folder: pathlib.Path):
    """A form feed (which LIG text may hold) does not end a line, for the editor or for LIG.

    The server asks for whole texts: pygls would apply an edit by lines cut at form feeds too.
    """
    sync = CAPABILITIES[0].text_document_sync
    assert (sync.change if isinstance(sync, T.TextDocumentSyncOptions) else sync) == T.TextDocumentSyncKind.Full
    features = CAPABILITIES[0]
    assert features.hover_provider and features.definition_provider and features.references_provider
    assert features.rename_provider and features.document_symbol_provider and features.folding_range_provider
    assert features.completion_provider is not None
    text = "{ page one }\f{ page two }\n      X = 1\n      Y = X + BOX\n"
    uri = from_fs_path(str(folder / "paged.lig"))
    client.text_document_did_open(
        T.DidOpenTextDocumentParams(text_document=T.TextDocumentItem(uri=uri, language_id="lig", version=1, text=text))
    )
    found = await diagnostics_for(client, uri, 1)
    # As liganimate check prints them: 3:15 (BOX needs WIDTH) and 3:11 (the sum).
    assert sorted((d.range.start.line, d.range.start.character) for d in found) == [(2, 10), (2, 14)]
    change(client, uri, 2, text.replace("X = 1", "X = 2"))
    assert {d.range.start.line for d in await diagnostics_for(client, uri, 2)} == {2}


async def test_broken_text_keeps_answering(client: LanguageClient, folder: pathlib.Path):
    path = folder / "broken.lig"
    uri = await open_doc(client, path, PROGRAM)
    broken = PROGRAM.replace("      BOTH = 2 * BEND + WALK\n", "      BOTH = 2 * BEND +\n      STARTMOTION HALF\n")
    change(client, uri, 2, broken)
    found = await diagnostics_for(client, uri, 2)
    assert len(found) == 1 and found[0].severity == T.DiagnosticSeverity.Error
    # Hover and definition still know the names, from the last analysis that parsed.
    arm = await hover_text(client, uri, pos_of(broken, "ARM FROM", into=1))
    assert "| 1 | UPPER → LOWER | 0° to 135° | -20° to 20° | locked |" in arm
    result = await client.text_document_definition_async(
        T.DefinitionParams(
            text_document=T.TextDocumentIdentifier(uri=uri), position=pos_of(broken, "USING BEND", into=7)
        )
    )
    assert isinstance(result, T.Location) and result.range.start == pos_of(broken, "BEND")
    # Completion inside the unfinished block, and folding of the blocks that close.
    labels = await completion_labels(client, uri, pos_of(broken, "STARTMOTION HALF\n", into=len("STARTMOTION HALF\n")))
    assert "JOINT" in labels and "ENDMOTION" in labels
    folds = await client.text_document_folding_range_async(
        T.FoldingRangeParams(text_document=T.TextDocumentIdentifier(uri=uri))
    )
    assert folds is not None
    lines = broken.split("\n")
    assert any(lines[f.start_line].strip().startswith("STARTMODEL ARM") for f in folds)
    with pytest.raises(Exception, match="does not parse"):
        await client.text_document_rename_async(
            T.RenameParams(
                text_document=T.TextDocumentIdentifier(uri=uri), position=pos_of(broken, "ARM"), new_name="LIMB"
            )
        )
    # Fixed again: the diagnostics clear.
    change(client, uri, 3, PROGRAM)
    assert list(await diagnostics_for(client, uri, 3)) == []


async def test_typing_in_a_big_program_ends_with_the_diagnostics_of_the_last_text(
    client: LanguageClient, folder: pathlib.Path
):
    """Keystrokes sent one right after the other, while earlier texts are still analysed (and indexed).

    The server parses only the text around each change (lang/incremental.py);
    the last text's diagnostics must come, and be those of the whole text as
    ``liganimate check`` finds them, here a syntax error in a block and then
    its repair.
    """
    body = PROGRAM[PROGRAM.index("      STARTMODEL ARM") : PROGRAM.index("      SHOOTSCENES")]
    copies = [body.replace("ARM", f"ARM{i}").replace("BEND", f"BEND{i}").replace("BOTH", f"BOTH{i}") for i in range(60)]
    big = PROGRAM.replace(body, "".join(copies))
    path = folder / "keystrokes.lig"
    path.write_text(big)
    uri = await open_doc(client, path, big)
    assert list(PUBLISHED[(uri, 1)]) == []
    at = big.index("FRAME 12 POSITION 90.0", len(big) // 2) + len("FRAME 12 POSITION 9")
    text, version = big, 1
    for typed in ", ,":  # 90.0 -> 9, ,0.0: a comma where a number must be
        text = text[:at] + typed + text[at:]
        at += 1
        version += 1
        change(client, uri, version, text)
    found = await diagnostics_for(client, uri, version)
    path.write_text(text)
    printed = check_output(path)
    assert len(found) == 1 and found[0].severity == T.DiagnosticSeverity.Error
    first = found[0]
    assert f"{path}:{first.range.start.line + 1}:{first.range.start.character + 1}: error: " in printed
    assert first.message.split("\n")[0] in printed
    version += 1
    change(client, uri, version, big)
    assert list(await diagnostics_for(client, uri, version)) == []


async def test_the_command_is_installed():
    """``liganimate lsp`` is a subcommand of the installed command (its help names it)."""
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "--help"], capture_output=True, text=True, timeout=60, env=os.environ
    )
    assert "lsp" in done.stdout
