"""The libraries a program LOADs, as the server sees them: their files, their names, their values.

Go to definition needs the place in the library's file where a loaded name
is defined, and hover needs what the library's text fixes about it (a
model's joints, a motion's length). So each LOADed file is read and parsed
here too, the same way as the program (nothing in it is run), indexed,
and evaluated as far as its text goes, its own LOADs included. The
costs are bounded as the command line bounds them: a file of at most
64 MB (``lang.source.read_source_bytes``), and a chain of LOADs at most
:data:`MAX_DEPTH` deep, where the compiler already refuses a cycle. A
library is kept until its file changes (its size or modification time).
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field

from liganimate.compiler import NotParsed, parse_program
from liganimate.compiler import library as L
from liganimate.lang import ast as A
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.lang.source import SourceFileError, lig_text, prepare, read_source_bytes

from . import index as I
from . import statics
from .text import Text

#: The longest chain of LOADs followed for definitions and values (the compiler refuses cycles itself).
MAX_DEPTH = 16


@dataclass
class LibraryInfo:
    """One LOADed library: its file, its text, its index and values, and what the compiler says it offers."""

    name: str  # as the LOAD wrote it
    path: str
    text: Text
    index: I.Index
    env: statics.Env
    offered: dict = field(default_factory=dict)  # NAME -> type or "PRIMITIVE"
    descriptions: dict = field(default_factory=dict)  # NAME -> its {@ NAME: ...} line
    defaults: list = field(default_factory=list)  # what LOAD 'library' brings


_cache: dict = {}  # path -> (size, mtime_ns, LibraryInfo | None)
_lock = threading.Lock()


def _stamp(path: str) -> tuple | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_size, st.st_mtime_ns


def open_library(name: str, loading_file: str | None, depth: int = 0) -> LibraryInfo | None:
    """The library ``LOAD ... 'name'`` opens from ``loading_file``, or None if it cannot be opened or parsed."""
    if depth >= MAX_DEPTH:
        return None
    try:
        path = L.resolve(name, loading_file)
    except (L.LibraryNotFound, OSError, ValueError):
        return None
    stamp = _stamp(path)
    with _lock:
        known = _cache.get(path)
    if known is not None and known[:2] == stamp:
        return known[2]
    info = _read(name, path, depth)
    with _lock:
        _cache[path] = (*(stamp or (None, None)), info)
    return info


def _read(name: str, path: str, depth: int) -> LibraryInfo | None:
    try:
        text = lig_text(read_source_bytes(path), path)
    except (SourceFileError, OSError):
        return None
    source = prepare(text, path)
    try:
        program, _ = parse_program(source, path=path)
    except (NotParsed, LigDiagnostics, RecursionError):
        return None
    doc = Text(text)
    info = LibraryInfo(name, path, doc, I.build(program, doc), statics.Env())
    try:
        compiled = L.load(name, path)
    except L.FAILURES:
        compiled = None
    if compiled is not None:
        info.offered = {n: compiled.kind_of(n) for n in list(compiled.types) + list(compiled.signatures)}
        info.descriptions = dict(compiled.descriptions)
        info.defaults = compiled.default_names()
    info.env = statics.evaluate(program, loaded_values(program, path, depth + 1))
    return info


def loads(program: A.Program) -> list:
    """The program's top-level LOAD statements."""
    return [s for s in program.body if isinstance(s, A.Load)]


def loaded_values(program: A.Program, path: str | None, depth: int = 0) -> dict:
    """NAME -> the value (see :mod:`.statics`) of each name the program's LOADs bring."""
    out: dict = {}
    for load in loads(program):
        info = open_library(load.library, path, depth)
        if info is None:
            continue
        names = [n.name for n in load.names] if load.names else info.defaults
        for n in names:
            out.setdefault(n, info.env.values.get(n))
    return out


def libraries_of(program: A.Program, path: str | None) -> dict:
    """NAME -> the LibraryInfo that brings it, for every name the program's LOADs bring."""
    out: dict = {}
    for load in loads(program):
        info = open_library(load.library, path)
        if info is None:
            continue
        names = [n.name for n in load.names] if load.names else info.defaults
        for n in names:
            out.setdefault(n, info)
    return out


def forget() -> None:
    """Drop every library read so far."""
    with _lock:
        _cache.clear()


__all__ = ["LibraryInfo", "MAX_DEPTH", "forget", "libraries_of", "loaded_values", "loads", "open_library"]
