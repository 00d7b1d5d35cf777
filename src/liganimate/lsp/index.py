"""Where each name of a parsed program is defined and used: the index behind definition, references and rename.

One walk of the syntax tree records every occurrence of a name with its
scope (the main program, or one PRIMITIVE, whose variables are its own)
and its role. Primitives are global: a call inside a PRIMITIVE names the
same primitive as one in the main program. A link named in ``FIGURE ...
MAIN LINK`` or a ``GOAL`` is the graphical variable the link was made from
(docs/language.md, 4.5), so it is an occurrence of that variable too:
renaming the variable renames the link.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

from liganimate.lang import ast as A
from liganimate.lang.visitor import children

from .text import Text

MAIN = ""  # the main program's scope

#: Roles that introduce a name (the first one met is its definition).
DEFINING = ("declaration", "assignment", "load", "primitive", "parameter")


@dataclass(frozen=True, slots=True)
class Occurrence:
    """One place a name is written: ``text[start:end]`` is the name."""

    name: str
    scope: str  # MAIN, or the PRIMITIVE's name
    start: int
    end: int
    role: str  # one of DEFINING, "use", "link"

    @property
    def key(self) -> tuple:
        """``(scope, name)``: the variable this occurrence names."""
        return (self.scope, self.name)


@dataclass
class Index:
    """Every occurrence of every name of one program, by offset and by variable."""

    occurrences: list = field(default_factory=list)  # sorted by start
    by_key: dict = field(default_factory=dict)  # (scope, NAME) -> [Occurrence, ...] in source order
    scopes: list = field(default_factory=list)  # (start, end, primitive name) of each PRIMITIVE body

    def at(self, offset: int) -> Occurrence | None:
        """The occurrence under offset ``offset`` (its end included, where a cursor after a name stands)."""
        starts = self.__dict__.get("_starts")
        if starts is None:
            starts = self.__dict__["_starts"] = [o.start for o in self.occurrences]
        i = bisect.bisect_right(starts, offset) - 1
        if i >= 0 and self.occurrences[i].start <= offset <= self.occurrences[i].end:
            return self.occurrences[i]
        return None

    def scope_at(self, offset: int) -> str:
        """The scope the text at ``offset`` is in."""
        for start, end, name in self.scopes:
            if start <= offset < end:
                return name
        return MAIN

    def definition(self, key: tuple) -> Occurrence | None:
        """The first occurrence that introduces the variable ``key``, else its first occurrence."""
        found = self.by_key.get(key, ())
        for o in found:
            if o.role in DEFINING:
                return o
        return found[0] if found else None

    def references(self, key: tuple) -> list:
        """Every occurrence of the variable ``key``, in source order."""
        return list(self.by_key.get(key, ()))

    def names(self, scope: str) -> list:
        """The names of scope ``scope`` and the primitives, sorted."""
        return sorted({n for s, n in self.by_key if s == scope or s == MAIN and scope != MAIN and self._is_prim(n)})

    def _is_prim(self, name: str) -> bool:
        return any(o.role == "primitive" for o in self.by_key.get((MAIN, name), ()))


class _Walker:
    def __init__(self, text: Text, primitives: set) -> None:
        self.text = text
        self.primitives = primitives
        self.found: list = []
        self.scopes: list = []

    def add(self, name: str, scope: str, line: int, column: int, role: str) -> None:
        start = self.text.offset_of(line, column)
        scope = MAIN if name in self.primitives else scope
        self.found.append(Occurrence(name, scope, start, start + len(name), role))

    def name(self, n, scope: str, role: str) -> None:
        if isinstance(n, A.Name):
            self.add(n.name, scope, n.pos.line, n.pos.column, role)

    def statement(self, s, scope: str) -> None:
        kind = type(s)
        if kind is A.PrimitiveDef:
            self.name(s.name, MAIN, "primitive")
            inner = s.name.name
            self.scopes.append((self.text.offset_of(s.pos.line, s.pos.column), self._end(s.pos), inner))
            if s.pattern is not None:
                self.node(s.pattern, inner)
            for t in s.body:
                self.node(t, inner)
            return
        # The names a statement binds, as lang/ast.py declares them (binds=...).
        for attr, how in _BINDS.get(kind, ()):
            value = getattr(s, attr)
            for n in value if isinstance(value, list) else (value,):
                self.name(n, scope, _ROLES[how])
        if kind is A.Load:
            for n in s.names:
                self.name(n, scope, "load")
        elif kind is A.FigureStmt:
            self.name(s.link, scope, "link")
        for attr, _ in _USES.get(kind, ()):
            self.name(getattr(s, attr), scope, "use")
        self.rest(s, scope)

    def _end(self, pos) -> int:
        return self.text.offset_of(pos.end_line, pos.end_column)

    def rest(self, s, scope: str) -> None:
        skip = _named_fields(s)
        for child in children(s):
            if id(child) not in skip:
                self.node(child, scope)

    def node(self, n, scope: str) -> None:
        stack = [n]
        while stack:
            node = stack.pop()
            kind = type(node)
            if kind is A.Var:
                self.add(node.name, scope, node.pos.line, node.pos.column, "use")
                continue
            if kind is A.PrimCall:
                self.add(node.name, MAIN, node.pos.line, node.pos.column, "use")
            elif kind is A.PatParam:
                self.add(node.name, scope, node.pos.line, node.pos.column, "parameter")
                continue
            elif kind is A.PatOptional:
                for target, value in node.defaults:
                    self.name(target, scope, "use")
                    stack.append(value)
                stack.extend(reversed(node.items))
                continue
            elif kind is A.Goal:
                self.name(node.link, scope, "link")
            elif kind is A.PrintItem and node.kind == "table":
                self.name(node.value, scope, "use")
                continue
            elif kind in _STATEMENTS:
                self.statement(node, scope)
                continue
            elif kind is A.Name:
                continue  # methods, solvers: words of the language, not variables
            stack.extend(reversed(children(node)))


def _named_fields(s) -> set:
    """Ids of the Name children of statement ``s`` that :meth:`_Walker.statement` has already recorded."""
    out = set()
    for attr in ("target", "name", "var", "names", "model", "link", "translate"):
        value = getattr(s, attr, None)
        if isinstance(value, A.Name):
            out.add(id(value))
        elif isinstance(value, list):
            out.update(id(v) for v in value if isinstance(v, A.Name))
    return out


#: Each statement that binds names -> its fields that do, and how; the role each gets in the index.
_BINDS = A.statement_fields("binds")
#: Each statement with a field naming a variable it reads without an expression (``uses=True``) -> those fields.
_USES = A.statement_fields("uses")
_ROLES = {"declares": "declaration", "assigns": "assignment", "figure": "use"}  # FIGURE changes a model it uses

_STATEMENTS = (
    frozenset(_BINDS)
    | frozenset(_USES)
    | frozenset(
        {
            A.If,
            A.Load,
            A.FigureStmt,
            A.Scene,
            A.Print,
            A.Background,
            A.DrawWith,
            A.DrawPoly,
            A.PrimitiveDef,
        }
    )
)


def build(program: A.Program, text: Text) -> Index:
    """The index of a parsed program whose text is ``text``.

    Parameters
    ----------
    program : liganimate.lang.ast.Program
        The syntax tree (``Checked.program`` or the parser's).
    text : Text
        The text it was parsed from, for offsets.
    """
    primitives = {p.name.name for p in program.primitives}
    walker = _Walker(text, primitives | _called(program))
    for s in program.body:
        walker.statement(s, MAIN)
    found = sorted(walker.found, key=lambda o: (o.start, o.end))
    by_key: dict = {}
    for o in found:
        by_key.setdefault(o.key, []).append(o)
    return Index(found, by_key, walker.scopes)


def _called(program: A.Program) -> set:
    """The names of every primitive the program calls (BOX and loaded ones included)."""
    from liganimate.lang.bindings import walk

    return {n.name for n in walk(program) if type(n) is A.PrimCall}


__all__ = ["Index", "Occurrence", "MAIN", "build"]
