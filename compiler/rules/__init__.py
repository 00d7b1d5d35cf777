"""Statement rules: each statement's check and lowering side by side, one class a statement.

:func:`rule_for` finds a statement's rule by its node's type; the passes
(compiler/statements.py, compiler/lower.py) call ``rule.check(...)`` and
``rule.lower(...)``. A family of statements is one module here; a rule
registers itself with ``@rule(<node class>)`` when its module is imported,
which happens below, so a new family module is one more import line.
"""

from __future__ import annotations

from . import control, declared, drawing, models, motions, names, reach, scenes
from .base import RULES, Rule, rule, rule_for

__all__ = [
    "RULES",
    "Rule",
    "rule",
    "rule_for",
    "control",
    "declared",
    "drawing",
    "models",
    "motions",
    "names",
    "reach",
    "scenes",
]
