"""Bindings and scopes: which names exist where, and the type each one settles on.

The checker's state while it walks one scope (the main program or one
PRIMITIVE) is a :class:`State`; the rules that bind a name (a declaration,
an assignment, a block that defines a MODEL or a MOTION) are functions of
it, so the statement checks and the expression typing share them.

Variables need no declaration: the first assignment declares them with the
type of its value, and an implicit number assigned a REAL anywhere is REAL.
"""

from __future__ import annotations

from dataclasses import field

from liganimate.lang import ast as A
from liganimate.lang import bindings
from liganimate.lang.diagnostics import did_you_mean
from liganimate.lang.node_methods import record

from . import types as T
from .reports import SILENT, Sink


@record
class Scope:
    """The variables of the main program or of one PRIMITIVE."""

    name: str
    types: dict = field(default_factory=dict)  # NAME -> type
    declared: dict = field(default_factory=dict)  # NAME -> Pos of declaration (explicit)
    implicit: set = field(default_factory=set)
    params: list = field(default_factory=list)


@record
class SceneInfo:
    """What a scene uses: models to snapshot, models it animates, names it assigns."""

    animated: list = field(default_factory=list)
    models: list = field(default_factory=list)
    assigned: set = field(default_factory=set)


@record
class State:
    """Where the checker is and what it has found.

    ``out`` is the pass's sink for diagnostics (:mod:`.reports`); ``types``
    and ``scenes`` are the tables :class:`~.check.Checked` hands to lowering.
    """

    signatures: dict  # NAME -> Signature of every primitive in force
    types: dict = field(default_factory=dict)  # id(expr node) -> type
    scenes: dict = field(default_factory=dict)  # id(Scene node) -> SceneInfo
    out: Sink = SILENT
    scope: Scope = field(default_factory=lambda: Scope("main program"))
    primitive: A.PrimitiveDef | None = None
    scene: SceneInfo | None = None

    def enter(self, scope: Scope, primitive: A.PrimitiveDef | None, out) -> None:
        """Start a pass over ``scope`` reporting to ``out``."""
        self.scope, self.primitive, self.scene, self.out = scope, primitive, None, out


def primitive_scope(p: A.PrimitiveDef, sig) -> Scope:
    """The scope of a PRIMITIVE: its declarations, and its parameters (REAL unless declared)."""
    scope = Scope(f"PRIMITIVE {p.name.name}")
    for stmt in p.body:
        if isinstance(stmt, A.Decl):
            for n in stmt.names:
                scope.types[n.name] = stmt.type
                scope.declared[n.name] = n.pos
    if sig is not None:
        for param in sig.params:
            scope.params.append(param)
            if param not in scope.types:
                scope.types[param] = T.REAL
                scope.implicit.add(param)
    return scope


def declare(st: State, s: A.Decl) -> None:
    """``REAL a, b``: declare names explicitly."""
    for n in s.names:
        prev = st.scope.types.get(n.name)
        if n.name in st.signatures and st.primitive is None:
            st.out.error(n, f"{n.name} is a primitive, so it cannot be declared as a variable")
        if n.name in st.scope.declared and st.scope.declared[n.name] != n.pos and prev != s.type:
            where = st.scope.declared[n.name]
            st.out.error(n, f"{n.name} is already declared as {prev} at line {where.line}")
            continue
        st.scope.types[n.name] = s.type
        st.scope.declared[n.name] = n.pos
        st.scope.implicit.discard(n.name)


def assign_type(st: State, target: A.Name, value_type, value_node) -> None:
    """Bind ``target`` to a value of ``value_type``: declare it, widen it to REAL, or refuse the value."""
    if value_type is None:
        return
    name = target.name
    if value_type == T.PAIR:
        st.out.error(
            value_node,
            "a pair (min, max) can only be a joint's extremes",
            "a vector has three components: (x, y, z)",
        )
        return
    if value_type == T.BOOL:
        return
    current = st.scope.types.get(name)
    if current is None:
        st.scope.types[name] = value_type
        st.scope.implicit.add(name)
        return
    if name in st.scope.implicit and current == T.INTEGER and value_type == T.REAL:
        st.scope.types[name] = T.REAL
        return
    if current == T.GRAPHICAL and value_type == T.MODEL and animated_here(st, value_node):
        return  # §5.1: after ANIMATE, the model is also a graphical object (its pose this tick)
    if not T.fits(current, value_type):
        hint = "use INT(...) or NINT(...) to make an INTEGER" if current == T.INTEGER and value_type == T.REAL else None
        st.out.error(value_node, f"{name} is {T.NOUN[current]}, so it cannot hold {T.NOUN[value_type]}", hint)


def define_as(st: State, name: A.Name, t: str, message: str) -> None:
    """Declare ``name`` implicitly with type ``t``, or report ``message`` if it has another type."""
    current = st.scope.types.get(name.name)
    if current is None:
        st.scope.types[name.name] = t
        st.scope.implicit.add(name.name)
    elif current != t:
        st.out.error(name, message.format(name=name.name, noun=T.NOUN[current]))


def animated_here(st: State, node) -> bool:
    """True if ``node`` names (possibly modified) a model already ANIMATEd in this scene body.

    The thesis, §5.1: after ANIMATE "a graphical object of the name
    'model_name' is available"; it is the model in the current tick's pose.
    """
    while isinstance(node, A.Modified):
        node = node.target
    return st.scene is not None and isinstance(node, A.Var) and node.name in st.scene.animated


def unknown(st: State, node) -> None:
    """Report a name that is not defined here, with the closest one that is."""
    name = node.name
    hint = did_you_mean(name, list(st.scope.types) + list(st.signatures))
    st.out.error(node, f"{name} is not defined", hint or "assign it or declare it (REAL, VECTOR, MODEL, ...) first")


def call_graph(program: A.Program) -> dict:
    """Each PRIMITIVE's name -> the names of the primitives its body calls."""
    return {q.name.name: _prim_calls(q) for q in program.primitives}


def recursion(calls: dict, p: A.PrimitiveDef, out) -> None:
    """A PRIMITIVE may not call itself, directly or through others (it would never end).

    ``calls`` is the program's :func:`call_graph`.
    """
    seen, stack = set(), [(c, c) for c in calls.get(p.name.name, ())]
    while stack:
        name, first = stack.pop()
        if name == p.name.name:
            node = next((n for n in _prim_call_nodes(p) if n.name == first), p)
            out.error(node, f"PRIMITIVE {p.name.name} calls itself (through {first}), so it would never end")
            return
        if name in seen:
            continue
        seen.add(name)
        stack.extend((c, first) for c in calls.get(name, ()))


def names_used(node) -> set:
    """Every name a node mentions."""
    return {n.name for n in bindings.walk(node) if isinstance(n, (A.Var, A.Name))}


def _prim_call_nodes(node) -> list:
    return [n for n in bindings.walk(node) if isinstance(n, A.PrimCall)]


def _prim_calls(node) -> set:
    return {n.name for n in _prim_call_nodes(node)}
