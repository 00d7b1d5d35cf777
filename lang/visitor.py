"""One way to walk the syntax tree: dispatch by node type, with generic children.

Like Jinja2's ``NodeVisitor``: a pass names its methods after the node types
they handle (``e_BinOp`` for the lowering's expressions, ``_e_BinOp`` for the
checker's: each pass chooses its prefixes; statements have one rule each in
compiler/rules/ instead), and :meth:`NodeVisitor.dispatch` finds the one
for a node, once per type. A node type a pass does not handle is walked
through: :meth:`NodeVisitor.generic_visit` visits its children
(:func:`children`), so a new node type needs methods only in the passes
that care about it.

The other walks share the same two facts about the tree: :func:`children`
(any node's child nodes) and :data:`BLOCKS` (the statements that hold
statements, and which fields hold them). :func:`too_deep` is the iterative
walk of the nesting checks (lang/structure.py), which must not recurse:
they exist to refuse trees too deep for the recursive passes.
"""

from __future__ import annotations

import dataclasses

from . import ast as A

_FIELDS: dict = {}  # node type -> names of the fields that may hold nodes
#: The node types seen so far that have no field that can hold a node (names, numbers, text).
LEAVES: set = set()
# Field annotations (strings: lang/ast.py postpones them) that never hold a node.
_SCALAR = {"str", "int", "float", "bool", "Pos", "int | float", "str | None", "int | None", "float | None"}

#: Statements that hold statements, and the fields that hold their statement lists, in source order
#: (the fields lang/ast.py declares with ``holds=True``).
BLOCKS: dict = {cls: tuple(name for name, _ in marked) for cls, marked in A.statement_fields("holds").items()}


def _node_fields(cls) -> tuple:
    """Names of the fields of node type ``cls`` that may hold nodes (not ``pos``, not names or numbers)."""
    names = _FIELDS.get(cls)
    if names is None:
        names = _FIELDS[cls] = tuple(
            f.name
            for f in dataclasses.fields(cls)
            if f.name != "pos" and getattr(f.type, "__name__", f.type) not in _SCALAR
        )
        if not names:
            LEAVES.add(cls)
    return names


def children(node) -> list:
    """Child nodes of ``node`` (through lists and tuples), in source order."""
    cls = type(node)
    names = _FIELDS.get(cls)
    if names is None:
        names = _node_fields(cls)
    out: list = []
    # Every walk calls this for every node: a field holding one node is
    # taken here, without a call.
    for name in names:
        value = getattr(node, name)
        if isinstance(value, A.Node):
            out.append(value)
        elif isinstance(value, (list, tuple)):
            _collect(value, out)
    return out


def _collect(value, out: list) -> None:
    for item in value:
        if isinstance(item, A.Node):
            out.append(item)
        elif isinstance(item, (list, tuple)):
            _collect(item, out)


def too_deep(roots: list, limit: int, inner=children, leaves=LEAVES):
    """The first node more than ``limit`` levels deep, or None; iterative, so any depth is safe.

    ``roots`` are at level 1; ``inner(node)`` gives the nodes one level
    below ``node`` (by default its :func:`children`). The walk is depth
    first, from the last root and the last child backwards, and the node
    reported is the first one found on a level past ``limit``: the last
    of the inner nodes of the first node found on level ``limit`` that has
    any. Nodes whose type is in ``leaves`` have no inner nodes and are not
    walked (most nodes are names and numbers).
    """
    stack = [(node, 1) for node in roots]
    pop, push = stack.pop, stack.extend
    while stack:
        node, depth = pop()
        if depth > limit:
            return node
        below = inner(node)
        if below:
            depth += 1
            if depth > limit:
                return below[-1]
            push([(child, depth) for child in below if type(child) not in leaves])
    return None


class NodeVisitor:
    """Base class of the passes over a tree (the checker, the lowering)."""

    def dispatch(self, prefix: str, node, generic: bool = True):
        """The bound method ``<prefix><type of node>`` (or of its nearest base class that has one), else :meth:`generic_visit`.

        ``generic=False`` (for passes that must produce a value, such as an
        expression's type or code) makes a missing method an error instead.
        """
        key = (prefix, type(node))
        cache = self.__dict__.get("_methods")
        if cache is None:
            cache = self.__dict__["_methods"] = {}
        method = cache.get(key)
        if method is None:
            # The node's own method, else one for a base class.
            method = next(
                (m for c in type(node).__mro__[:-1] if (m := getattr(self, prefix + c.__name__, None)) is not None),
                None,
            )
            if method is None:
                if not generic:
                    raise NotImplementedError(f"{type(self).__name__} has no {prefix}{type(node).__name__}")
                method = self._generic(prefix)
            cache[key] = method
        return method

    def _generic(self, prefix: str):
        def visit(node, *args):
            return self.generic_visit(prefix, node, *args)

        return visit

    def generic_visit(self, prefix: str, node, *args):
        """Visit each child of ``node`` with this pass's ``prefix`` methods; the result is None."""
        for child in children(node):
            self.dispatch(prefix, child)(child, *args)
