"""The static types of LIG ANIMATE values and the built-in functions."""

from __future__ import annotations

from liganimate.lang.vocabulary import (  # noqa: F401  (the type names are the language's)
    BOOL,
    FUNCTIONS,
    GRAPHICAL,
    INTEGER,
    MODEL,
    MOTION,
    PAIR,
    REAL,
    VECTOR,
)

DECLARABLE = (INTEGER, REAL, VECTOR, GRAPHICAL, MODEL, MOTION)
NUMERIC = (INTEGER, REAL)

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


def is_numeric(t: str) -> bool:
    """INTEGER or REAL."""
    return t in NUMERIC


def numeric_join(a: str, b: str) -> str:
    """The type of arithmetic on two numbers: INTEGER only if both are."""
    return INTEGER if a == INTEGER and b == INTEGER else REAL


def fits(declared: str, value: str) -> bool:
    """Can a value of type ``value`` be stored in a variable of type ``declared``?"""
    if declared == value:
        return True
    return declared == REAL and value == INTEGER


#: The built-in functions (lang/vocabulary.py), by name.
BUILTINS = FUNCTIONS
