"""The static types of LIG ANIMATE values (:class:`~liganimate.lang.vocabulary.Type`) and the built-in functions."""

from __future__ import annotations

from liganimate.lang.vocabulary import (  # noqa: F401  (the type names are the language's)
    BOOL,
    FUNCTIONS,
    GRAPHICAL,
    INTEGER,
    MODEL,
    MOTION,
    NUMBER,
    PAIR,
    REAL,
    VECTOR,
    Type,
)

NUMERIC = NUMBER

#: How a type is named in messages.
NOUN = {
    INTEGER: "an INTEGER",
    REAL: "a REAL",
    VECTOR: "a VECTOR",
    PAIR: "a pair (min, max)",
    GRAPHICAL: "a GRAPHICAL object",
    MODEL: "a MODEL",
    MOTION: "a MOTION",
    BOOL: "a condition",
}


def is_numeric(t: Type | None) -> bool:
    """INTEGER or REAL."""
    return t in NUMERIC


def numeric_join(a: Type, b: Type) -> Type:
    """The type of arithmetic on two numbers: INTEGER only if both are."""
    return INTEGER if a == INTEGER and b == INTEGER else REAL


def fits(declared: Type, value: Type) -> bool:
    """Can a value of type ``value`` be stored in a variable of type ``declared``?"""
    if declared == value:
        return True
    return declared == REAL and value == INTEGER


#: The built-in functions (lang/vocabulary.py), by name.
BUILTINS = FUNCTIONS
