"""Library loading: what the top-level LOAD statements bring into the program.

Runs before any statement is checked: a loaded MODEL, MOTION or value gets
its type in the main scope, a loaded PRIMITIVE its signature. The libraries
themselves were opened (and compiled) by ``library.open_library`` while the
source was scanned; here each LOAD is matched with what its library offers.
"""

from __future__ import annotations

from dataclasses import field

from liganimate.lang import ast as A
from liganimate.lang import bindings
from liganimate.lang.diagnostics import did_you_mean
from liganimate.lang.node_methods import record

from .reports import Report
from .scopes import Scope


@record
class Loaded:
    """What the LOADs brought: the tables :class:`~.check.Checked` carries to the lowering."""

    libraries: list = field(default_factory=list)  # Library objects, in order of first LOAD
    loads: dict = field(default_factory=dict)  # id(Load node) -> (library index, [names])
    names: dict = field(default_factory=dict)  # NAME -> library index (values and primitives)
    primitives: dict = field(default_factory=dict)  # NAME -> library index
    top: set = field(default_factory=set)  # id() of the LOADs at the top level


class _Loader:
    """One program's LOADs, in order; names bound in ``main`` and ``sigs``/``primitives``."""

    def __init__(self, program: A.Program, main: Scope, sigs: dict, primitives: dict, out: Report):
        self.program, self.main, self.sigs, self.primitives, self.out = program, main, sigs, primitives, out
        self.found = Loaded(top={id(s) for s in program.body if isinstance(s, A.Load)})
        self.defined: dict = {}  # NAME -> Pos where the program defines it before a LOAD
        self.origin: dict = {}  # NAME -> (library path, Pos of the LOAD)

    def run(self, path: str, stack: tuple, opened: dict) -> Loaded:
        for stmt in self.program.body:
            if not isinstance(stmt, A.Load):
                for name in bindings.defined(stmt):
                    self.defined.setdefault(name.name, name.pos)
                continue
            from . import library as L  # only a program that LOADs needs it (and its cache's cryptography)

            lib = L.open_library(stmt.library, path, stack, opened)
            if isinstance(lib, Exception):
                message, hint, inner = L.failure(lib, stmt.library)
                self.out.include(inner)
                self.out.error(stmt.library_pos, message, hint)
                continue
            if lib.scenes:
                self.out.error(
                    stmt.library_pos,
                    f"{lib.display} defines scenes, so it is a program, not a library",
                    "a library holds models, motions and primitives only",
                )
                continue
            self._load(stmt, lib)
        return self.found

    def _load(self, stmt: A.Load, lib) -> None:
        libraries = self.found.libraries
        index = next((i for i, known in enumerate(libraries) if known.path == lib.path), None)
        if index is None:
            index = len(libraries)
            libraries.append(lib)
        self.out.include_warnings(lib.warnings)
        wanted = stmt.names or [A.Name(stmt.library_pos, n) for n in lib.default_names()]
        taken = []
        for name in wanted:
            if self._take(name, lib, index):
                self.origin[name.name] = (lib.path, stmt.pos)
                self.found.names[name.name] = index
                taken.append(name.name)
        self.found.loads[id(stmt)] = (index, taken)

    def _take(self, name: A.Name, lib, index: int) -> bool:
        """Bind one loaded name, or report why it cannot be loaded (False)."""
        n, out = name.name, self.out
        if not lib.offers(n):
            hint = did_you_mean(n, list(lib.types) + list(lib.signatures))
            out.error(name, f"{lib.display} has no {n}", hint or "it offers " + ", ".join(lib.default_names()))
            return False
        if n in self.origin:
            where_path, where = self.origin[n]
            if where_path == lib.path:
                out.warning(
                    name, f"{n} is already loaded from {lib.display} at line {where.line}; this LOAD of it does nothing"
                )
            else:
                out.error(
                    name,
                    f"{n} is already loaded from another library at line {where.line}",
                    "load it from one library only",
                )
            return False
        if n in self.defined:
            out.error(
                name,
                f"{n} is already defined at line {self.defined[n].line}, so loading it would overwrite it",
                "load libraries first, or rename your own definition",
            )
            return False
        if n in self.sigs and n in lib.signatures:
            out.error(name, f"{n} is already a primitive here, so it cannot be loaded", "rename your own PRIMITIVE")
            return False
        if n in lib.signatures:
            self.sigs[n] = lib.signatures[n]
            self.primitives[n] = (None, lib.signatures[n], None)
            self.found.primitives[n] = index
        elif n in self.sigs:
            out.error(name, f"{n} is a primitive here, so it cannot also be a loaded variable")
            return False
        else:
            self.main.types[n] = lib.types[n]
            self.main.declared[n] = name.pos
        return True


def load_libraries(
    program: A.Program, main: Scope, sigs: dict, primitives: dict, out: Report, *, path: str, stack: tuple, opened: dict
) -> Loaded:
    """Bring in what the top-level LOAD statements name, reporting to ``out``.

    ``sigs`` (NAME -> Signature) and ``primitives`` (NAME -> (definition,
    Signature, Scope)) gain the loaded primitives, ``main`` the loaded values.
    """
    return _Loader(program, main, sigs, primitives, out).run(path, stack, opened)
