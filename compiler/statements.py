"""Statement checks: the walk over a scope's statements, each checked by its rule.

Each statement's check is the ``check`` of its rule (compiler/rules/, found
by the node's type), beside its lowering; ``context`` says where the
statement stands: ``"top"`` (the program or a PRIMITIVE body), ``"scene"``
(a scene's initialisation) or ``"scene-body"`` (between STARTSCENE and
ENDSCENE). A rule reaches what every statement shares through the checker:
``st`` (the :class:`~.scopes.State`: scope, diagnostics), ``t`` (the
:class:`~.expressions.ExpressionTyper`) and :meth:`StatementChecker.stmts`
for the statements a statement holds.
"""

from __future__ import annotations

from . import scopes as S
from .expressions import ExpressionTyper
from .rules import rule_for


class StatementChecker:
    """Checks the statements of one scope, each by its rule's ``check``."""

    def __init__(self, state: S.State, typer: ExpressionTyper, top_loads: set):
        self.st = state
        self.t = typer
        self.top_loads = top_loads  # id() of the LOADs at the program's top level

    def stmts(self, stmts: list, context: str) -> None:
        """Check a list of statements standing in ``context``."""
        for s in stmts:
            rule_for(type(s)).check(self, s, context)
