"""Libraries: LIG ANIMATE files whose models, motions and primitives a program LOADs.

A library is an ordinary program without scenes. ``LOAD 'humanoid'`` finds
``humanoid.lig`` in the standard library; a name holding a ``/`` or ending
in ``.lig`` is a path relative to the loading file. A library is compiled
once and kept twice over: in memory for this process, and on disk (see
:func:`cache_dir`) keyed by the library's text, the texts of everything it
loads in turn and the compiler's own source, so an edited library or a new
compiler never meets a stale entry.

What a library offers: every top-level variable it defines (not the names
it loaded itself) and its own PRIMITIVEs. ``LOAD 'x'`` takes its models,
motions, graphical objects and primitives; numbers and vectors are usually
helpers, so they come only when named.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from liganimate import __version__

from . import types as T

# Kinds that LOAD 'library' brings without naming them.
DEFAULT_KINDS = (T.MODEL, T.MOTION, T.GRAPHICAL)

_DOC = re.compile(r"\{@\s*([A-Za-z][A-Za-z0-9_]*)\s*:\s*([^}]*)\}")
_CACHE_FORMAT = 1


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


@dataclass
class Library:
    """A compiled library and what it offers to the programs that load it."""

    name: str  # as programs name it: 'humanoid' or a path as written
    path: str  # absolute file path
    display: str  # shown in diagnostics and in generated modules
    python: str  # its lowered module (see compiler/lower.py)
    types: dict  # exported NAME -> type
    signatures: dict  # own PRIMITIVE NAME -> Signature
    descriptions: dict  # NAME -> one-line description from its {@ NAME: ...} comments
    warnings: list = field(default_factory=list)
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


def resolve(name: str, loading_file: str) -> str:
    """The absolute path of the library ``name`` loaded from ``loading_file``.

    Raises
    ------
    LibraryNotFound
        With the places looked at.
    """
    if is_path(name):
        base = Path(loading_file).resolve().parent if loading_file and not loading_file.startswith("<") else Path.cwd()
        candidate = (base / name).resolve()
        if candidate.suffix.lower() != ".lig" and not candidate.exists():
            candidate = candidate.with_name(candidate.name + ".lig")
        if candidate.is_file():
            return str(candidate)
        raise LibraryNotFound(name, [str(candidate)])
    candidate = stdlib_dir() / f"{name.lower()}.lig"
    if candidate.is_file():
        return str(candidate)
    raise LibraryNotFound(name, [str(candidate)])


def descriptions(text: str) -> dict:
    """``{NAME: description}`` from a library's ``{@ NAME: description }`` comments."""
    return {m.group(1).upper(): " ".join(m.group(2).split()) for m in _DOC.finditer(text)}


# ------------------------------------------------------------------ caching

_memory: dict = {}  # (absolute path, name as loaded) -> Library (validated by its deps' hashes)


def cache_dir() -> Path | None:
    """Where compiled libraries are kept between runs, or None to keep nothing.

    ``LIGANIMATE_CACHE`` names the folder (empty: no disk cache); otherwise
    ``$XDG_CACHE_HOME/liganimate`` or ``~/.cache/liganimate``.
    """
    env = os.environ.get("LIGANIMATE_CACHE")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "liganimate"


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
            if _sha(Path(path).read_bytes()) != sha:
                return False
        except OSError:
            return False
    return True


def _cache_file(path: str, name: str, data: bytes) -> Path | None:
    folder = cache_dir()
    if folder is None:
        return None
    key = _sha(b"\0".join([compiler_fingerprint().encode(), path.encode(), name.encode(), data]))
    return folder / f"{key}.pickle"


def _read_cache(file: Path | None):
    if file is None:
        return None
    try:
        with open(file, "rb") as fh:
            fmt, lib = pickle.load(fh)
    except Exception:  # a missing, partial or foreign entry is just a miss
        return None
    return lib if fmt == _CACHE_FORMAT and isinstance(lib, Library) else None


def _write_cache(file: Path | None, lib: Library) -> None:
    if file is None:
        return
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=file.parent, prefix=".tmp-")
        with os.fdopen(fd, "wb") as fh:
            pickle.dump((_CACHE_FORMAT, lib), fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, file)
    except OSError:
        pass  # a read-only home only costs a recompile next time


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
    """
    if path in stack:
        chain = [Path(p).name for p in stack[stack.index(path):]] + [Path(path).name]
        raise LibraryCycle(chain)
    # The name is part of the key: the compiled text names the library as
    # the LOAD wrote it, and compiling must not depend on what ran before.
    known = _memory.get((path, name))
    if known is not None and _deps_fresh(known.deps):
        return known
    data = Path(path).read_bytes()
    file = _cache_file(path, name, data)
    lib = _read_cache(file)
    if lib is None or not _deps_fresh(lib.deps):
        lib = _compile(name, path, data, stack)
        _write_cache(file, lib)
    _memory[(path, name)] = lib
    return lib


def _compile(name: str, path: str, data: bytes, stack: tuple) -> Library:
    from liganimate.lang.source import decode, prepare

    from . import compile_source

    display = display_name(name, path)
    source = prepare(decode(data, display), display)
    compiled = compile_source(source, display, path=path, stack=stack)
    checked = compiled.checked
    loaded = set(checked.loaded_names)
    types = {n: t for n, t in checked.main.types.items() if n not in loaded}
    sigs = {n: sig for n, (pdef, sig, _) in checked.primitives.items() if pdef is not None}
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
        deps=tuple(dict.fromkeys(deps)),
        scenes=_has_scenes(checked.program.body),
    )


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
    "Library",
    "LibraryNotFound",
    "LibraryCycle",
    "stdlib_dir",
    "stdlib_names",
    "resolve",
    "load",
    "descriptions",
    "cache_dir",
    "forget",
]
