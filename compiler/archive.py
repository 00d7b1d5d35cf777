"""``liganimate archive``: a program's models and motions written out as a library.

The thesis asks for "a method to archive the models and motions defined in
a program"; we keep them as what defines them, the program's own text, so
an archived motion is exactly the motion (``1000000000 * walk`` stays one
line, not a billion keyframes). The archive is the program with its scenes
and SHOOTSCENES taken out (a library has none), its path LOADs re-aimed
from the archive's folder, and a ``{@ NAME: ... }`` description added for
every model and motion that has none, so ``LOAD 'archive.lig'`` brings them.
Every other character stays where it was.
"""

from __future__ import annotations

import os
from pathlib import Path

from liganimate.lang import ast as A
from liganimate.lang.source import load

from . import compile_source, library
from . import types as T


def _offsets(text: str) -> list:
    """Offset of the first character of each line (1-based line numbers index it)."""
    starts, total = [0, 0], 0
    for line in text.split("\n"):
        total += len(line) + 1
        starts.append(total)
    return starts


def _span(starts: list, pos: A.Pos) -> tuple:
    return starts[pos.line] + pos.column - 1, starts[pos.end_line] + pos.end_column - 1


def _blank(chars: list, start: int, end: int) -> None:
    # Spaces keep every other statement on its line and column.
    for i in range(start, end):
        if chars[i] != "\n":
            chars[i] = " "


def _walk(stmts, inside_if=False):
    for s in stmts:
        yield s, inside_if
        if isinstance(s, A.Do):
            yield from _walk(s.body, inside_if)
        elif isinstance(s, A.If):
            yield from _walk(s.then, True)
            yield from _walk(s.orelse or [], True)


def archive_text(path: str, out_path: str) -> str:
    """The library text archiving the program at ``path``, to be written at ``out_path``.

    Raises
    ------
    LigDiagnostics
        When the program does not compile, or its archive would not.
    """
    source = load(path)
    compiled = compile_source(source, path=path)
    checked = compiled.checked
    text = source.text
    starts = _offsets(text)
    chars = list(text)
    edits = []  # (start, end, replacement) applied back to front
    for stmt, inside_if in _walk(checked.program.body):
        if isinstance(stmt, A.Scene):
            first = min(stmt.pos, stmt.start_pos, key=lambda p: (p.line, p.column)) if stmt.start_pos.line else stmt.pos
            _blank(chars, _span(starts, first)[0], _span(starts, stmt.pos)[1])
        elif isinstance(stmt, A.Shoot):
            start, end = _span(starts, stmt.pos)
            _blank(chars, start, end)
            if inside_if:
                edits.append((start, start + len("BEGIN END"), "BEGIN END"))
        elif isinstance(stmt, A.Load) and library.is_path(stmt.library):
            target = Path(library.resolve(stmt.library, path))
            new = os.path.relpath(target, Path(out_path).resolve().parent).replace(os.sep, "/")
            start, end = _span(starts, stmt.library_pos)
            edits.append((start, end, f"'{new}'"))
    for start, end, replacement in sorted(edits, reverse=True):
        chars[start:end] = list(replacement)
    body = "\n".join(line.rstrip() for line in "".join(chars).split("\n"))
    described = library.descriptions(text)
    header = [
        f"{{ Archived from {Path(path).name} by liganimate archive: its models and motions, without its scenes. }}"
    ]
    loaded = set(checked.loaded_names)
    for name, t in sorted(checked.main.types.items()):
        if t in (T.MODEL, T.MOTION) and name not in described and name not in loaded:
            header.append(f"{{@ {name}: {t} defined in {Path(path).name} }}")
    result = "\n".join(header) + "\n" + body
    if not result.endswith("\n"):
        result += "\n"
    return result


__all__ = ["archive_text"]
