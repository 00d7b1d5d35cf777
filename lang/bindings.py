"""Which names a statement binds, computed once for the checker and the lowering.

Like Jinja2's ``idtracking``: the checker needs the names a program defines
before a LOAD (to refuse a LOAD that would overwrite one) and the names a
scene assigns; the lowering needs the latter to declare them ``nonlocal``
(or ``global``) in the scene's function. Both ask here.
"""

from __future__ import annotations

from . import ast as A
from .visitor import BLOCKS, children

#: Statements that hold statements, and the fields that hold them (PRIMITIVE bodies are scopes of their own).
_INNER = {kind: fields for kind, fields in BLOCKS.items() if kind is not A.PrimitiveDef}


def walk(node):
    """Every node under ``node`` (itself first), depth first; iterative, so deep trees cannot overflow."""
    stack = [node]
    while stack:
        n = stack.pop()
        yield n
        stack.extend(reversed(children(n)))


def plain_name(e) -> str | None:
    """The variable an expression names, through modifiers (``HEAD <TRANS v>`` names HEAD), or None."""
    while isinstance(e, A.Modified):
        e = e.target
    return e.name if isinstance(e, A.Var) else None


def assigned(stmt, figure: bool = True) -> list:
    """The names (``A.Name`` nodes) ``stmt`` and the statements inside it assign, in source order.

    The fields lang/ast.py declares ``binds="assigns"`` (an assignment, a
    keyframe assignment, a STARTMODEL, STARTMOTION or STARTREACH block and
    its TRANSLATE INTO vector, a DO variable), and ``binds="figure"`` (a
    FIGURE statement, which gives its model a new value) unless ``figure``
    is false. Declarations (``binds="declares"``) are not assignments (see
    :func:`defined`).
    """
    return [n for s in walk_statements(stmt) for n in _binds(s, figure, False)]


def defined(stmt) -> list:
    """The names ``stmt`` (and the statements inside it) declares or assigns a value to, FIGURE aside, in source order."""
    return [n for s in walk_statements(stmt) for n in _binds(s, False, True)]


def walk_statements(stmt):
    """``stmt`` and the statements inside it (not inside a PRIMITIVE's body), in source order."""
    stack = [stmt]
    while stack:
        s = stack.pop()
        yield s
        inner = _INNER.get(type(s))
        if inner:
            for name in reversed(inner):
                stack.extend(reversed(getattr(s, name) or ()))


#: Each statement that binds names -> its fields that do, and how (lang/ast.py's ``binds=``).
_BINDS = A.statement_fields("binds")


def _binds(s, figure: bool, decl: bool) -> tuple:
    """The names statement ``s`` itself binds (not those of statements inside it)."""
    marked = _BINDS.get(type(s))
    if not marked:
        return ()
    names: list = []
    for field, kind in marked:
        if (kind == "figure" and not figure) or (kind == "declares" and not decl):
            continue
        value = getattr(s, field)
        if isinstance(value, list):
            names.extend(value)
        elif value is not None:
            names.append(value)
    return tuple(names)
