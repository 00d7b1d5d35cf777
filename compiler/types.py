"""The static types of LIG ANIMATE values and the built-in functions."""

from __future__ import annotations

INTEGER = "INTEGER"
REAL = "REAL"
VECTOR = "VECTOR"
PAIR = "PAIR"  # a (min, max) pair: only joint extremes use it
GRAPHICAL = "GRAPHICAL"
MODEL = "MODEL"
MOTION = "MOTION"
BOOL = "BOOL"

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


# name -> (argument types, result type); "N" means INTEGER or REAL.
# Trigonometry is in degrees, like every angle in the language.
BUILTINS = {
    "SIN": (("N",), REAL),
    "COS": (("N",), REAL),
    "TAN": (("N",), REAL),
    "ASIN": (("N",), REAL),
    "ACOS": (("N",), REAL),
    "ATAN": (("N",), REAL),
    "ATAN2": (("N", "N"), REAL),
    "SQRT": (("N",), REAL),
    "EXP": (("N",), REAL),
    "LOG": (("N",), REAL),
    "ABS": (("N",), None),  # same type as the argument
    "INT": (("N",), INTEGER),
    "NINT": (("N",), INTEGER),
    "REAL": (("N",), REAL),
    "FLOAT": (("N",), REAL),
    "MIN": (("N", "N"), None),
    "MAX": (("N", "N"), None),
    "MOD": (("N", "N"), None),
    "DOT": ((VECTOR, VECTOR), REAL),
    "CROSS": ((VECTOR, VECTOR), VECTOR),
    "NORM": ((VECTOR,), REAL),
    "X": ((VECTOR,), REAL),
    "Y": ((VECTOR,), REAL),
    "Z": ((VECTOR,), REAL),
    "LEN": ((MOTION,), REAL),
}
