"""Libraries: LIG ANIMATE files whose models, motions and primitives a program LOADs.

A library is an ordinary program without scenes. ``LOAD 'humanoid'`` finds
``humanoid.lig`` in the standard library; a name holding a ``/`` or ending
in ``.lig`` is a path relative to the loading file (``.lig`` is added when
missing). A path LOAD reads only a regular file whose real name ends in
``.lig`` and that is LIG text (see lang/source.py); a library that does not
parse is reported by position only, without its text, because a LOAD may
name a file that is not LIG at all (docs/security.md).

A library is compiled once and kept twice over: in memory for this
process, and on disk (see :mod:`.library_cache`) keyed by the library's
text, the texts of everything it loads in turn and the compiler's own
source, so an edited library or a new compiler never meets a stale entry.

What a library offers: every top-level variable it defines (not the names
it loaded itself) and its own PRIMITIVEs. ``LOAD 'x'`` takes its models,
motions, graphical objects and primitives; numbers and vectors are usually
helpers, so they come only when named.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import re
import stat
from dataclasses import field
from pathlib import Path

from liganimate import __version__
from liganimate.lang.ast import Pos
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics, did_you_mean
from liganimate.lang.name_table import read_tables
from liganimate.lang.node_methods import record
from liganimate.lang.source import SourceFileError, lig_text, read_source_bytes

from . import library_cache
from . import types as T
from .library_cache import cache_dir
from .primitives import Signature, Slot

# Kinds that LOAD 'library' brings without naming them.
DEFAULT_KINDS = (T.MODEL, T.MOTION, T.GRAPHICAL)

_DOC = re.compile(r"\{@\s*([A-Za-z][A-Za-z0-9_]*)\s*:\s*([^}]*)\}")


class LibraryNotFound(Exception):
    """No library file answers to a LOAD's name; ``tried`` lists where we looked."""

    def __init__(self, name: str, tried: list):
        super().__init__(name)
        self.name = name
        self.tried = tried


class LibraryCycle(Exception):
    """A library loads itself, directly or through others; ``chain`` is the loop."""

    def __init__(self, chain: list):
        super().__init__(" -> ".join(chain))
        self.chain = chain


@record
class Library:
    """A compiled library and what it offers to the programs that load it."""

    name: str  # as programs name it: 'humanoid' or a path as written
    path: str  # absolute file path
    display: str  # shown in diagnostics and in generated modules
    python: str  # its lowered module (see compiler/lower.py)
    types: dict  # exported NAME -> type
    signatures: dict  # own PRIMITIVE NAME -> Signature (no defaults: they live in ``python``)
    descriptions: dict  # NAME -> one-line description from its {@ NAME: ...} comments
    warnings: list = field(default_factory=list)
    # MODEL -> {SEGMENT: (source name, channels, end)}: its {@names ...} tables (lang/name_table.py)
    names: dict = field(default_factory=dict)
    deps: tuple = ()  # ((absolute path, sha256 of its bytes), ...) of every file it loads, recursively
    scenes: bool = False  # whether it defines or shoots scenes (then it is a program, not a library)

    def offers(self, name: str) -> bool:
        """Whether ``LOAD name FROM`` this library can find ``name``."""
        return name in self.types or name in self.signatures

    def default_names(self) -> list:
        """The names ``LOAD 'library'`` brings: primitives, models, motions and graphical objects."""
        names = sorted(self.signatures)
        names += sorted(n for n, t in self.types.items() if t in DEFAULT_KINDS)
        return names

    def kind_of(self, name: str) -> str:
        """``PRIMITIVE`` or the type of an offered name."""
        return "PRIMITIVE" if name in self.signatures else self.types[name]


def _extra(row) -> list:
    """A name-table row's URDF columns (joint name, rpy) for the cache's JSON."""
    joint = row[3] if len(row) > 3 else None
    rpy = row[4] if len(row) > 4 else None
    mimic = row[5] if len(row) > 5 else None
    return [joint, None if rpy is None else list(rpy), None if mimic is None else list(mimic)]


def _row_back(row) -> tuple:
    """A name-table row read back from the cache, as ``lang.name_table`` reads it from the text.

    A row with no joint name, RPY or MIMIC is the three values alone there,
    so it is here too: a library must lower to the same module whether it
    came from the cache or was compiled afresh.
    """
    base = (row[0], tuple(row[1]), None if row[2] is None else tuple(row[2]))
    joint = row[3] if len(row) > 3 else None
    rpy = row[4] if len(row) > 4 else None
    mimic = row[5] if len(row) > 5 else None
    if joint is None and rpy is None and mimic is None:
        return base
    return (*base, joint, None if rpy is None else tuple(rpy), None if mimic is None else tuple(mimic))


def stdlib_dir() -> Path:
    """The folder of the standard library's ``.lig`` files."""
    from liganimate import stdlib

    return Path(stdlib.__file__).resolve().parent


def stdlib_names() -> list:
    """Names of the standard libraries (``humanoid``, ``shapes``...), sorted."""
    return sorted(p.stem for p in stdlib_dir().glob("*.lig"))


def is_path(name: str) -> bool:
    """Whether a LOAD names a file by path rather than a standard library."""
    return "/" in name or "\\" in name or name.lower().endswith(".lig")


def resolve(name: str, loading_file: str | None) -> str:
    """The absolute path of the library ``name`` loaded from ``loading_file``.

    A path may be relative (to the loading file's folder) or absolute, and
    may leave the program's folder; ``.lig`` is added when it is missing.
    The real file (symbolic links followed) must be a regular file whose
    name ends in ``.lig``.

    Raises
    ------
    LibraryNotFound
        With the places looked at.
    SourceFileError
        The file is there but is not a ``.lig`` file or not a regular file.
    OSError
        It cannot be looked at (permissions, a loop of links).
    """
    if not is_path(name):
        return _existing(name, str(stdlib_dir() / f"{name.lower()}.lig"))
    base = Path(loading_file).resolve().parent if loading_file and not loading_file.startswith("<") else Path.cwd()
    written = os.path.join(base, name)
    if _is_lig(written):
        return _existing(name, written)
    try:
        return _existing(name, written + ".lig")
    except LibraryNotFound:
        if _there(written):
            raise SourceFileError(_NOT_LIG, os.path.realpath(written)) from None
        raise


_NOT_LIG = "a LOAD reads only files whose names end in .lig"


def _is_lig(path: str) -> bool:
    return os.path.splitext(path)[1].lower() == ".lig"


def _there(path: str) -> bool:
    try:
        os.lstat(path)
    except (OSError, ValueError):
        return False
    return True


def _existing(name: str, path: str) -> str:
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except (FileNotFoundError, NotADirectoryError, ValueError):  # ValueError: a NUL in the name
        raise LibraryNotFound(name, [real]) from None
    if not _is_lig(real):
        raise SourceFileError(_NOT_LIG + " (this one is a link to another kind of file)", real)
    if not stat.S_ISREG(st.st_mode):
        read_source_bytes(real)  # raises, saying what it is instead
    return real


def descriptions(text: str) -> dict:
    """``{NAME: description}`` from a library's ``{@ NAME: description }`` comments."""
    return {m.group(1).upper(): " ".join(m.group(2).split()) for m in _DOC.finditer(text)}


# ------------------------------------------------------------------ caching

_memory: dict = {}  # (absolute path, name as loaded) -> Library (validated by its deps' hashes)


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


_fingerprint: str | None = None


def compiler_fingerprint() -> str:
    """A hash of the grammar and compiler sources: a new compiler invalidates the cache."""
    global _fingerprint
    if _fingerprint is None:
        from liganimate import lang

        h = hashlib.sha256(__version__.encode())
        for folder in (Path(lang.__file__).parent, Path(__file__).parent):
            for p in sorted(folder.iterdir()):
                if p.suffix in (".py", ".lark"):
                    h.update(p.name.encode())
                    h.update(p.read_bytes())
        _fingerprint = h.hexdigest()
    return _fingerprint


def _deps_fresh(deps) -> bool:
    for path, sha in deps:
        try:
            if _sha(read_source_bytes(path, follow_symlinks=False)) != sha:
                return False
        except (OSError, ValueError):
            return False
    return True


def _to_json(lib: Library) -> dict:
    """A library as plain JSON values (the disk cache stores nothing else)."""
    sources: list = []

    def source_index(text):
        if text is None:
            return None
        if text not in sources:
            sources.append(text)
        return sources.index(text)

    return {
        "name": lib.name,
        "path": lib.path,
        "display": lib.display,
        "python": lib.python,
        "types": lib.types,
        "descriptions": lib.descriptions,
        "names": {
            m: {k: [v[0], list(v[1]), None if v[2] is None else list(v[2]), *_extra(v)] for k, v in rows.items()}
            for m, rows in lib.names.items()
        },
        "scenes": lib.scenes,
        "deps": [list(d) for d in lib.deps],
        "signatures": [
            {"name": s.name, "slots": [[x.keyword, x.param, x.group] for x in s.slots], "param_types": s.param_types}
            for s in lib.signatures.values()
        ],
        "warnings": [
            {
                "filename": w.filename,
                "pos": [w.pos.line, w.pos.column, w.pos.end_line, w.pos.end_column],
                "message": w.message,
                "hint": w.hint,
                "severity": w.severity,
                "source": source_index(w.source),
                "notes": list(w.notes),
            }
            for w in lib.warnings
        ],
        "sources": sources,
    }


def _from_json(obj: dict) -> Library:
    """The inverse of :func:`_to_json`; raises KeyError, TypeError or ValueError on a foreign shape."""
    sources = obj["sources"]
    sigs = {}
    for s in obj["signatures"]:
        param_types = {k: T.Type(t) for k, t in s["param_types"].items()}
        sigs[s["name"]] = Signature(s["name"], [Slot(k, p, g) for k, p, g in s["slots"]], {}, param_types)
    warnings = [
        Diagnostic(
            w["filename"],
            Pos(*w["pos"]),
            w["message"],
            w["hint"],
            w["severity"],
            None if w["source"] is None else sources[w["source"]],
            list(w["notes"]),
        )
        for w in obj["warnings"]
    ]
    return Library(
        name=obj["name"],
        path=obj["path"],
        display=obj["display"],
        python=obj["python"],
        types={n: T.Type(t) for n, t in obj["types"].items()},
        signatures=sigs,
        descriptions=dict(obj["descriptions"]),
        warnings=warnings,
        names={m: {k: _row_back(v) for k, v in rows.items()} for m, rows in obj.get("names", {}).items()},
        deps=tuple((p, h) for p, h in obj["deps"]),
        scenes=bool(obj["scenes"]),
    )


def _from_disk(entry: str, name: str, path: str) -> Library | None:
    obj = library_cache.read(entry)
    if obj is None:
        return None
    try:
        lib = _from_json(obj)
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    return lib if (lib.name, lib.path) == (name, path) else None


# ------------------------------------------------------------------ loading


def display_name(name: str, path: str) -> str:
    """How a library is named in messages: ``stdlib/humanoid.lig`` or the path as written."""
    return f"stdlib/{Path(path).name}" if not is_path(name) else name


def load(name: str, path: str, stack: tuple = ()) -> Library:
    """Compile (or fetch from the caches) the library at ``path``.

    Parameters
    ----------
    name : str
        The name the LOAD used, kept for messages.
    path : str
        Absolute path from :func:`resolve`.
    stack : tuple of str
        Paths being loaded around this one, to catch a library that loads itself.

    Raises
    ------
    LibraryCycle, LigDiagnostics, OSError
        OSError includes SourceFileError: not a regular file, too large, or
        not LIG text.
    """
    if path in stack:
        chain = [Path(p).name for p in stack[stack.index(path) :]] + [Path(path).name]
        raise LibraryCycle(chain)
    # The name is part of the key: the compiled text names the library as
    # the LOAD wrote it, and compiling must not depend on what ran before.
    known = _memory.get((path, name))
    if known is not None and _deps_fresh(known.deps):
        return known
    data = read_source_bytes(path, follow_symlinks=False)
    entry = library_cache.entry_name(compiler_fingerprint().encode(), path.encode(), name.encode(), data)
    lib = _from_disk(entry, name, path)
    if lib is None or not _deps_fresh(lib.deps):
        lib = _compile(name, path, data, stack)
        library_cache.write(entry, _to_json(lib))
    _memory[(path, name)] = lib
    return lib


def _compile(name: str, path: str, data: bytes, stack: tuple) -> Library:
    from liganimate.lang.source import prepare

    from . import NotParsed, compile_source

    display = display_name(name, path)
    source = prepare(lig_text(data, path), display)
    try:
        compiled = compile_source(source, display, path=path, stack=stack)
    except NotParsed as exc:
        raise LigDiagnostics(exc.loads + [_withheld(d) for d in exc.syntax]) from None
    checked = compiled.checked
    loaded = set(checked.loaded_names)
    types = {n: t for n, t in checked.main.types.items() if n not in loaded}
    sigs = {
        n: dataclasses.replace(sig, defaults={}, param_types=dict(sig.param_types))
        for n, (pdef, sig, _) in checked.primitives.items()
        if pdef is not None
    }
    deps = [(path, _sha(data))]
    for lib in checked.libraries:
        deps.extend(lib.deps)
    return Library(
        name=name,
        path=path,
        display=display,
        python=compiled.python,
        types=types,
        signatures=sigs,
        descriptions=descriptions(source.text),
        warnings=list(compiled.warnings),
        names={m: rows for m, rows in read_tables(source.text).items() if types.get(m) == T.MODEL},
        deps=tuple(dict.fromkeys(deps)),
        scenes=_has_scenes(checked.program.body),
    )


def _withheld(d: Diagnostic) -> Diagnostic:
    """A library's syntax error by position only: a file that does not parse may not be LIG at all."""
    return Diagnostic(
        d.filename,
        Pos(d.pos.line, d.pos.column, d.pos.line, d.pos.column + 1),
        "the library does not parse as LIG here (a library that does not parse is not quoted)",
        "run liganimate check on the library itself to see its line and the full message",
    )


def failure(exc: Exception, name: str) -> tuple:
    """``(message, hint, the library's own diagnostics)`` for a LOAD of ``name`` that raised ``exc``.

    ``exc`` is one of LibraryNotFound, LibraryCycle, LigDiagnostics or
    OSError, the failures a LOAD reports at its own line.
    """
    if isinstance(exc, LibraryNotFound):
        if not is_path(name):
            hint = did_you_mean(name.lower(), stdlib_names()) or (
                "the standard libraries are " + ", ".join(stdlib_names())
            )
            hint += "; a file of your own is named by a path such as 'lib/mine.lig'"
            # Where the package is installed says nothing to the user.
            return f"there is no library '{name}' in the standard library", hint, []
        return f"there is no library '{name}' (looked for {exc.tried[0]})", None, []
    if isinstance(exc, LibraryCycle):
        return (
            "libraries load each other in a circle: " + " -> ".join(exc.chain),
            "move what both need into a third library",
            [],
        )
    if isinstance(exc, LigDiagnostics):
        return f"the library '{name}' has errors (shown above)", None, list(exc.diagnostics)
    return f"the library '{name}' cannot be read: {getattr(exc, 'strerror', None) or exc}", None, []


# What a LOAD reports at its own line (see failure); anything else is a bug.
FAILURES = (LibraryNotFound, LibraryCycle, LigDiagnostics, OSError)


def open_library(name: str, loading_file: str | None, stack: tuple, opened: dict):
    """The library a ``LOAD ... FROM 'name'`` opens, or the exception (one of FAILURES) saying why it cannot.

    The one place a LOAD is resolved and loaded: before parsing (the lexer
    needs the names of loaded primitives) and by the checker (which reports
    failures at the LOAD's line), for one compile, through ``opened``, a
    dict kept for that compile, so a library is resolved and loaded once.
    ``stack`` is the chain of libraries being loaded around the loading
    file; the file joins it here, so a cycle is a LibraryCycle.
    """
    found = opened.get(name)
    if found is None:
        around = stack + ((os.path.abspath(loading_file),) if loading_file and not loading_file.startswith("<") else ())
        try:
            found = load(name, resolve(name, loading_file), around)
        except FAILURES as exc:
            found = exc
        opened[name] = found
    return found


def _has_scenes(stmts) -> bool:
    from liganimate.lang import ast as A

    for s in stmts:
        if isinstance(s, (A.Scene, A.Shoot)):
            return True
        for attr in ("body", "then", "orelse"):
            inner = getattr(s, attr, None)
            if isinstance(inner, list) and _has_scenes(inner):
                return True
    return False


def forget() -> None:
    """Empty the in-memory cache (tests use it to exercise the disk cache)."""
    _memory.clear()


__all__ = [
    "FAILURES",
    "open_library",
    "Library",
    "LibraryCycle",
    "LibraryNotFound",
    "cache_dir",
    "descriptions",
    "failure",
    "forget",
    "load",
    "resolve",
    "stdlib_dir",
    "stdlib_names",
]
