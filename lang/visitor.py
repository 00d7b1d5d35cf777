"""One way to walk the syntax tree: dispatch by node type, with generic children.

Like Jinja2's ``NodeVisitor``: a pass names its methods after the node types
they handle (``s_Assign`` for statements, ``e_BinOp`` for expressions: each
pass chooses its prefixes), and :meth:`NodeVisitor.dispatch` finds the one
for a node, once per type. A node type a pass does not handle is walked
through: :meth:`NodeVisitor.generic_visit` visits its children
(:func:`liganimate.lang.structure.children`), so a new node type needs
methods only in the passes that care about it.
"""

from __future__ import annotations

from .structure import children


class NodeVisitor:
    """Base class of the passes over a tree (the checker, the lowering)."""

    def dispatch(self, prefix: str, node, generic: bool = True):
        """The bound method ``<prefix><type of node>``, or :meth:`generic_visit` when the pass has none.

        ``generic=False`` (for passes that must produce a value, such as an
        expression's type or code) makes a missing method an error instead.
        """
        key = (prefix, type(node))
        cache = self.__dict__.get("_methods")
        if cache is None:
            cache = self.__dict__["_methods"] = {}
        method = cache.get(key)
        if method is None:
            method = getattr(self, prefix + type(node).__name__, None)
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
