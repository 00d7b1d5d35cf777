"""The docs' commands and programs, run as written, with what the text claims they write checked.

Every shell command and LIG program in README.md, docs/tutorial.md and
examples/README.md runs here, in a folder of its own per document (with
``examples`` linked in, as "run from the repository's top folder" says), in
bash, with this test run's ``liganimate`` and ``python`` first on the PATH:

* a shell line runs as written, each part of an ``&&`` chain in turn;
  ``pip install`` and ``python -m pytest`` are not run (this is the
  installed package and its test suite), nor the servers (``--watch``,
  ``studio``: tests/runtime/view/test_view_watch.py and the studio's tests
  drive them); a synopsis line runs without its optional ``[...]`` parts. README's
  placeholders stand for its own example: ``scene.lig`` is the program README
  shows, ``MOTION`` its WALK, ``DIR`` a folder;
* a program is saved under the name the text gives it ("Save it as
  `first.lig`", its ``{ walker.lig: ... }`` first line) and run with the
  command the text gives ("Run it with `--gif leg.gif`"), or checked;
* every ``liganimate run`` gets ``--size 64x48`` (the pictures' size is not
  what the text claims; it keeps the test quick).

Then the claims: each file an option names (``-o``, ``--gif``, ``--mp4``,
``--poses``, ``.save("...")``), the default outputs (``<stem>_frames``,
``<stem>.py``, ``<stem>.html``), and every path the text after the block names in backticks
(`appendix_a_frames/scene1/00000.png`) exist; "and nothing else" means
nothing else was written.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ["README.md", "docs/tutorial.md", "examples/README.md"]
_BLOCK = re.compile(r"```(\w*)\n(.*?)```", re.S)
_CLAIMED = re.compile(r"`([\w./-]+(?:\.(?:png|gif|mp4|html|py|lig|glb|gltf|bvh|jsonl)|_frames/))`")
_NOT_RUN = re.compile(r"^(pip install|python -m pytest)\b|--watch|\bliganimate studio\b|\bliganimate lsp\b")
_OUTPUT_OPTIONS = ("-o", "--output", "--gif", "--mp4", "--poses")
# An optional part of a synopsis line (liganimate run scene.lig [-o DIR]): run without it.
_SYNOPSIS_OPTION = re.compile(r" \[[^\]'\"]*\]")
# README's placeholders, bound to its own example program.
_PLACEHOLDERS = {"MOTION": "WALK", "DIR": "out_frames"}


def blocks(doc: str) -> list:
    """``(language, code, the text after it up to the next block)`` for each fenced block of ``doc``."""
    text = (ROOT / doc).read_text()
    found = list(_BLOCK.finditer(text))
    return [
        (m.group(1), m.group(2), text[m.end() : found[i + 1].start() if i + 1 < len(found) else len(text)])
        for i, m in enumerate(found)
    ]


def _bash(command: str, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""))
    return subprocess.run(["bash", "-c", command], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


def _quick(command: str) -> str:
    """``command`` with small pictures: ``--size 64x48`` after ``liganimate run FILE`` and ``python X.py``."""
    command = re.sub(r"(\bliganimate run \S+)", r"\1 --size 64x48", command)
    return re.sub(r"(^|&& )(python \S+\.py)", r"\1\2 --size 64x48", command)


def _outputs(command: str) -> list:
    """The files and folders a command line says it writes."""
    try:
        words = shlex.split(command)
    except ValueError:
        return []
    out = [words[i + 1] for i, w in enumerate(words[:-1]) if w in _OUTPUT_OPTIONS]
    out += re.findall(r"\.save\(\"([^\"]+)\"\)", command)
    if words[:2] == ["liganimate", "run"] and not any(w in words for w in ("-o", "--gif", "--mp4")):
        out.append(Path(words[2]).stem + "_frames")
    if words[:2] == ["liganimate", "compile"] and "-o" not in words:
        out.append(Path(words[2]).stem + ".py")
    if words[:2] == ["liganimate", "view"] and "-o" not in words:
        out.append(Path(words[2]).stem + ".html")
    return out


def _run_line(line: str, cwd: Path, ran: list) -> None:
    line = line.split(" #", 1)[0].strip()
    for part in (p.strip() for p in line.split("&&")):
        if not part or _NOT_RUN.search(part):
            continue
        for name, value in _PLACEHOLDERS.items():
            part = re.sub(rf"\b{name}\b", value, part)
        r = _bash(_quick(part), cwd)
        assert r.returncode == 0, f"{part}\n{r.stderr}"
        assert "Traceback" not in r.stderr
        ran.append(part)
        for path in _outputs(part):
            assert (cwd / path).exists(), f"{part!r} does not write {path}"


def _claims(after: str, cwd: Path, before: set) -> None:
    paragraph = after.strip().split("\n\n", 1)[0]
    claimed = [p for p in _CLAIMED.findall(paragraph) if "<" not in p and not p.startswith("examples/")]
    written = []
    for path in claimed:
        if not (cwd / path).exists() and (ROOT / path).exists():
            continue  # a file of the repository the text names, not one the command writes
        assert (cwd / path).exists(), f"the text claims {path} is written:\n{paragraph}"
        written.append(path)
    if "nothing else" in paragraph:
        new = {p.name for p in cwd.iterdir()} - before
        assert new == {Path(p).parts[0] for p in written}, f"more than the text claims was written: {sorted(new)}"


def _program_name(code: str, after: str, n: int) -> str:
    paragraph = after.strip().split("\n\n", 1)[0]
    m = re.search(r"Save it as `([\w.-]+\.lig)`", paragraph) or re.match(r"\{\s*([\w.-]+\.lig):", code.strip())
    if m is None:
        m = re.search(r"`liganimate (?:run|check) ([\w.-]+\.lig)", paragraph)
    return m.group(1) if m else f"program{n}.lig"


def _program_commands(name: str, after: str) -> list:
    paragraph = after.strip().split("\n\n", 1)[0]
    commands = re.findall(r"`(liganimate [^`]+)`", paragraph)
    commands = [c for c in commands if name in c and not c.startswith("liganimate lib")]
    commands += [f"liganimate run {name} {opts}" for opts in re.findall(r"Run it with `(--[^`]+)`", paragraph)]
    return commands or [f"liganimate check {name}"]


def _workspace(tmp_path: Path) -> Path:
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    return tmp_path


@pytest.mark.parametrize("doc", DOCS)
def test_every_command_and_program_of_the_doc_runs_and_writes_what_the_text_claims(doc, tmp_path):
    cwd = _workspace(tmp_path)
    ran: list = []
    docs_blocks = blocks(doc)
    # README's example program is the scene.lig its synopsis lines stand for.
    for language, code, _ in docs_blocks:
        if language == "" and "SHOOTSCENES" in code:
            (cwd / "scene.lig").write_text(code)
    for n, (language, code, after) in enumerate(docs_blocks):
        before = {p.name for p in cwd.iterdir()}
        if language == "sh":
            for line in code.splitlines():
                _run_line(_SYNOPSIS_OPTION.sub("", line), cwd, ran)
        elif language == "lig" or (language == "" and "SHOOTSCENES" in code):
            name = "scene.lig" if language == "" else _program_name(code, after, n)
            (cwd / name).write_text(code)
            for command in _program_commands(name, after) if language == "lig" else [f"liganimate run {name}"]:
                _run_line(command, cwd, ran)
        else:
            continue
        _claims(after, cwd, before)
    assert ran, f"nothing of {doc} was run"
