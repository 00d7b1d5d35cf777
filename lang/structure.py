"""Block structure the grammar cannot express: DO loops closed by labels.

``DO 10 I = 1, 5 ... 10 CONTINUE`` is FORTRAN's loop; the label ties the two
together, which a context-free grammar cannot check, so the parser yields a
flat :class:`~liganimate.lang.ast.DoHeader` and :class:`~liganimate.lang.ast.Continue`
and :func:`group_blocks` nests them. It also refuses absurdly deep nesting
before any recursive pass could overflow Python's stack.
"""

from __future__ import annotations

import dataclasses

from . import ast as A
from .diagnostics import Diagnostic, LigDiagnostics

#: Deeper syntax trees are refused with a diagnostic (no RecursionError may escape).
MAX_DEPTH = 100

_FIELDS: dict = {}  # node type -> names of the fields that may hold nodes
# Field annotations (strings: lang/ast.py postpones them) that never hold a node.
_SCALAR = {"str", "int", "float", "bool", "Pos", "int | float", "str | None", "int | None", "float | None"}


def _node_fields(cls) -> tuple:
    """Names of the fields of node type ``cls`` that may hold nodes (not ``pos``, not names or numbers)."""
    names = _FIELDS.get(cls)
    if names is None:
        names = _FIELDS[cls] = tuple(
            f.name
            for f in dataclasses.fields(cls)
            if f.name != "pos" and getattr(f.type, "__name__", f.type) not in _SCALAR
        )
    return names


def children(node):
    """Child nodes of ``node`` (through lists and tuples), in source order."""
    out = []
    for name in _node_fields(type(node)):
        _collect(getattr(node, name), out)
    return out


def _collect(value, out):
    if isinstance(value, A.Node):
        out.append(value)
    elif isinstance(value, (list, tuple)):
        for item in value:
            _collect(item, out)


def check_depth(roots: list, source) -> None:
    """Refuse trees deeper than MAX_DEPTH, iteratively, pointing at the deepest place."""
    stack = [(node, 1) for node in roots]
    fields = _FIELDS
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise LigDiagnostics(
                [
                    Diagnostic(
                        source.filename,
                        node.pos,
                        f"this is nested more than {MAX_DEPTH} levels deep",
                        "split it into several statements with variables in between",
                        source=source.text,
                    )
                ]
            )
        names = fields.get(type(node))
        if names is None:
            names = _node_fields(type(node))
        # Most nodes are leaves (names, numbers): they are not walked at all.
        if names:
            depth += 1
            for child in children(node):
                if depth > MAX_DEPTH or fields.get(type(child)) != ():
                    stack.append((child, depth))


#: Blocks (DO, IF, scenes) nested deeper than this are refused: Python, which
#: runs the compiled program, allows only 20 statically nested blocks.
MAX_BLOCKS = 15


def group_blocks(body: list, source) -> list:
    """Check nesting depth, then nest DO loops in every statement list."""
    check_depth(body, source)
    grouped = _group_list(body, source)
    _check_blocks(grouped, source)
    return grouped


def _check_blocks(body: list, source) -> None:
    stack = [(s, 1) for s in body if isinstance(s, _BLOCKS)]
    while stack:
        node, depth = stack.pop()
        inner = []
        if isinstance(node, A.Do):
            inner = node.body
        elif isinstance(node, A.If):
            inner = list(node.then) + list(node.orelse or [])
        elif isinstance(node, A.Scene):
            inner = list(node.init) + list(node.body)
        elif isinstance(node, A.PrimitiveDef):
            inner = node.body
        else:
            continue
        if depth > MAX_BLOCKS:
            raise LigDiagnostics(
                [
                    Diagnostic(
                        source.filename,
                        node.pos,
                        f"blocks (DO, IF, scenes) are nested more than {MAX_BLOCKS} deep here",
                        "move the inner part into a loop of its own or a PRIMITIVE",
                        source=source.text,
                    )
                ]
            )
        stack.extend((s, depth + 1) for s in inner if isinstance(s, _BLOCKS))


_BLOCKS = (A.Do, A.If, A.Scene, A.PrimitiveDef)  # statements that hold statements
_INNER = (A.If, A.Scene, A.PrimitiveDef)  # ... before DO loops are grouped


def _group_list(stmts: list, source) -> list:
    out: list = []
    open_dos: list = []  # (header, index in out where its body starts)
    closed: dict = {}  # label -> (DO line, CONTINUE line) of the last loop it closed, for hints
    for stmt in stmts:
        if isinstance(stmt, _INNER):
            _group_inner(stmt, source)
        if isinstance(stmt, A.DoHeader):
            open_dos.append((stmt, len(out)))
            continue
        if isinstance(stmt, A.Continue):
            if not any(h.label == stmt.label for h, _ in open_dos):
                if stmt.label in closed:
                    do_line, end_line = closed[stmt.label]
                    hint = (
                        f"the DO {stmt.label} at line {do_line} was already closed "
                        f"by the {stmt.label} CONTINUE at line {end_line}"
                    )
                else:
                    hint = f"a loop is opened with DO {stmt.label} var = first, last in the same block"
                raise LigDiagnostics(
                    [
                        Diagnostic(
                            source.filename,
                            stmt.pos,
                            f"{stmt.label} CONTINUE closes no DO loop",
                            hint,
                            source=source.text,
                        )
                    ]
                )
            # FORTRAN lets nested loops share one terminal label: close them all.
            while open_dos and open_dos[-1][0].label == stmt.label:
                header, start = open_dos.pop()
                closed[stmt.label] = (header.pos.line, stmt.pos.line)
                loop = A.Do(
                    header.pos, header.label, header.var, header.start, header.stop, header.step, out[start:], stmt.pos
                )
                del out[start:]
                out.append(loop)
            if open_dos and any(h.label == stmt.label for h, _ in open_dos):
                inner = open_dos[-1][0]
                raise LigDiagnostics(
                    [
                        Diagnostic(
                            source.filename,
                            stmt.pos,
                            f"{stmt.label} CONTINUE closes a DO loop while the inner DO {inner.label} is still open",
                            f"close DO {inner.label} (line {inner.pos.line}) with {inner.label} CONTINUE first",
                            source=source.text,
                        )
                    ]
                )
            continue
        out.append(stmt)
    if open_dos:
        header = open_dos[0][0]
        raise LigDiagnostics(
            [
                Diagnostic(
                    source.filename,
                    header.pos,
                    f"DO {header.label} is never closed by {header.label} CONTINUE",
                    f"add '{header.label} CONTINUE' after the last statement of the loop",
                    source=source.text,
                )
            ]
        )
    return out


def _group_inner(stmt, source) -> None:
    if isinstance(stmt, A.If):
        stmt.then = _group_list(stmt.then, source)
        if stmt.orelse is not None:
            stmt.orelse = _group_list(stmt.orelse, source)
    elif isinstance(stmt, A.Scene):
        stmt.init = _group_list(stmt.init, source)
        stmt.body = _group_list(stmt.body, source)
    elif isinstance(stmt, A.PrimitiveDef):
        stmt.body = _group_list(stmt.body, source)
