"""The registry of statement rules: one class per statement, found by its node's type.

A statement's rule holds both things the compiler does with it, side by
side: :meth:`Rule.check` (what it needs of its parts and where it may
stand, run by :class:`~liganimate.compiler.statements.StatementChecker`)
and :meth:`Rule.lower` (the Python it becomes, emitted by
:class:`~liganimate.compiler.lower.Lowerer`). Both passes find it here, by
the node's type or its nearest base class that has a rule (the rule of
:class:`~liganimate.lang.ast.Declared` serves every declared statement).
The passes keep what statements share (scopes, expression typing, the
lowering's buffer and positions); a rule only says what is its own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..lower import Lowerer
    from ..statements import StatementChecker


class Rule:
    """How one statement is checked and lowered; the defaults do nothing (END, STOP in a check...)."""

    def check(self, c: StatementChecker, s: Any, context: str) -> None:
        """Check statement ``s`` standing in ``context`` ("top", "scene" or "scene-body")."""

    def lower(self, lo: Lowerer, s: Any, where: str) -> None:
        """Emit the Python of statement ``s`` through ``lo`` (``where``: "main", "primitive", "scene"...)."""


#: Node type -> its rule, as registered by :func:`rule`.
RULES: dict[type, Rule] = {}
_FOUND: dict[type, Rule] = {}


def rule(node: type):
    """Register the decorated :class:`Rule` subclass as the rule of statements of type ``node``."""

    def register(cls: type[Rule]) -> type[Rule]:
        assert node not in RULES, f"{node.__name__} has two rules"
        RULES[node] = cls()
        return cls

    return register


def rule_for(node_type: type) -> Rule:
    """The rule of ``node_type``: its own, else that of its nearest base class that has one."""
    found = _FOUND.get(node_type)
    if found is None:
        found = next((RULES[c] for c in node_type.__mro__ if c in RULES), None)
        if found is None:
            raise NotImplementedError(f"the statement {node_type.__name__} has no rule in compiler/rules/")
        _FOUND[node_type] = found
    return found
