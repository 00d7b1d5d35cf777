"""The language's numbers, in one place: what an INTEGER and a REAL may hold.

* An INTEGER is an exact whole number within ``±INT_MAX`` (``2**63 - 1``).
* A REAL is a finite IEEE double: at most ``REAL_MAX`` (about ``1.8E308``)
  in magnitude, never infinite, never NaN.

A literal outside these is a compile-time error at the literal
(:func:`literal` marks it, the checker reports it). An operation whose result
leaves them (INTEGER overflow, a REAL overflowing to infinity, a NaN) is a
run-time error at that operation: the compiled program checks every
arithmetic result with an inline range test (``lo <= x <= hi``, False for NaN), and
the runtime's built-in functions and conversions use :func:`integer` and
:func:`real`, which raise :class:`NumberError`.

The host's own limits (:data:`MAX_KEYFRAME`, :data:`MAX_SCENE_LENGTH`,
:data:`GEOMETRY_MAX`...) live here too, so that the compiler, the runtime and
``docs/language.md`` quote the same numbers.
"""

from __future__ import annotations

import math
import sys

INT_MAX = 2**63 - 1
"""The largest INTEGER; the smallest is ``-INT_MAX``."""

REAL_MAX = sys.float_info.max
"""The largest finite REAL (about 1.8E308); the smallest is ``-REAL_MAX``."""

_REAL_MAX_TEXT = "1.8E308"

MAX_KEYFRAME = 1_000_000
"""The largest keyframe number ``k`` in ``m[j, k] = ...``."""

MAX_SCENE_LENGTH = 10_000_000
"""The longest scene, in ticks (about 4.6 days at 24 frames a second)."""

MAX_FRAME = 1e9
"""The latest frame a keyframe, a solved REACH pose or a stretched motion may put a keyframe at."""

MIN_FRAME_GAP = 1e-100
"""The closest two keyframes of a joint may be, in frames, unless they share a frame (a step).

Closer keyframes would make the interpolation's speeds overflow; the bound
sits far below any rounding noise between frames of everyday size."""

MAX_ANGLE = 1e9
"""The largest angle, in degrees, a keyframe or a starting position may hold."""

GEOMETRY_MAX = 1e12
"""The farthest, in world units, anything drawn or the VIEW POINT may be from the origin."""

GEOMETRY_MIN = 1e-12
"""The smallest VIEW WIDTH, and the closest the VIEW POINT may be to the origin."""


class NumberError(ValueError):
    """A number outside the language's range, or an operation leaving it.

    Parameters
    ----------
    message : str
        One plain sentence.
    hint : str, optional
        How to fix it.
    """

    def __init__(self, message: str, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint


# ------------------------------------------------------------------ literals


class BadLiteral:
    """Mixin of a literal outside the language's numbers; it keeps its spelling.

    The parser cannot report errors in the middle of building the tree, so
    :func:`literal` returns one of these; it behaves as a harmless number of
    the right type (so type checking goes on) and the checker reports it.
    """

    text: str = ""


class BadInteger(BadLiteral, int):
    """An integer literal beyond ``±INT_MAX`` (its value is 0; see :attr:`text`)."""


class BadReal(BadLiteral, float):
    """A real literal that overflows a double (its value is 0.0; see :attr:`text`)."""


def literal(text: str) -> int | float:
    """The value of a NUMBER token's spelling (degree sign already removed).

    Parameters
    ----------
    text : str
        Digits, an optional fraction and exponent, as ``lang/lig.lark`` lexes them.

    Returns
    -------
    int or float
        The value, or a :class:`BadInteger` / :class:`BadReal` standing for
        a literal outside the language's numbers (the checker reports it).
    """
    if "." in text or "e" in text or "E" in text:
        value = float(text)  # Python parses any length; overflow gives inf
        if math.isinf(value):
            bad = BadReal(0.0)
            bad.text = text
            return bad
        return value
    # Python refuses to convert strings of more than 4300 digits, and
    # anything past 19 digits is out of range anyway: look at the length first.
    digits = text.lstrip("0")
    if len(digits) <= 19 and int(text) <= INT_MAX:
        return int(text)
    too_big = BadInteger(0)
    too_big.text = text
    return too_big


def shown(text: str, width: int = 24) -> str:
    """A literal's spelling for a message, shortened if long."""
    return text if len(text) <= width else f"{text[: width - 4]}..."


def literal_problem(value) -> tuple[str, str] | None:
    """(message, hint) for a literal :func:`literal` marked as bad, else None."""
    if not isinstance(value, BadLiteral):
        return None
    text = value.text
    if isinstance(value, BadInteger):
        digits = text.lstrip("0")
        spelled = text if len(text) <= 24 else f"{text[:6]}...{text[-3:]} ({len(digits)} digits)"
        fits_real = len(digits) <= 308
        return (
            f"the integer {spelled} is too large: an INTEGER lies within ±{INT_MAX}",
            f"write it as a REAL such as {digits[0]}.{digits[1:4] or '0'}E{len(digits) - 1} if an approximate "
            "value will do"
            if fits_real
            else f"a REAL can hold magnitudes up to about {_REAL_MAX_TEXT}",
        )
    return (
        f"the number {shown(text)} is too large for a REAL (the largest is about {_REAL_MAX_TEXT})",
        "a REAL is a finite double-precision number",
    )


# -------------------------------------------------------------- run-time checks


def describe(x) -> str:
    """A short text of a number for messages (huge integers abbreviated, ``%g`` for reals)."""
    if isinstance(x, bool):
        return str(x)
    if isinstance(x, int):
        if abs(x) < 10**24:
            return str(x)
        digits = x.bit_length() * 0.30103
        return f"{'-' if x < 0 else ''}about 1E{int(digits)}"
    x = float(x)
    if math.isnan(x):
        return "not a number (NaN)"
    if math.isinf(x):
        return "infinite" if x > 0 else "minus infinity"
    return f"{x:g}"


def magnitude(x: float) -> str:
    """A size for a message: ``%g`` when finite, words otherwise (never 'inf' or 'nan')."""
    if math.isnan(x):
        return "an undefined amount"
    if math.isinf(x):
        return f"more than {_REAL_MAX_TEXT}"
    # Spelled as LIG writes numbers (1E12, 2.5E-7), not as Python prints them.
    text = f"{x:g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}E{int(exponent)}"
    return text


def overflow(value, what: str = "the result") -> NumberError:
    """The error for an arithmetic result outside the language's numbers (the caller raises it)."""
    if isinstance(value, int):
        return NumberError(
            f"INTEGER overflow: {what} is {describe(value)}, outside ±{INT_MAX}",
            "use REAL numbers for values this large",
        )
    if isinstance(value, float) and math.isnan(value):
        return NumberError(
            f"REAL overflow: {what} is not a number, because part of it went beyond ±{_REAL_MAX_TEXT}",
            "a REAL can hold magnitudes up to about 1.8E308; check for a runaway value",
        )
    return NumberError(
        f"REAL overflow: {what} is beyond ±{_REAL_MAX_TEXT}",
        "a REAL can hold magnitudes up to about 1.8E308; check for a runaway value",
    )


def integer(x, what: str = "the result") -> int:
    """``x`` (an int, or a whole float such as INT's result) as an INTEGER; NumberError if out of range.

    Parameters
    ----------
    x : int or float
    what : str
        What ``x`` is, for the message.
    """
    if isinstance(x, float):
        if not math.isfinite(x):
            raise NumberError(f"{what} is {describe(x)}, which is not an INTEGER")
        if not -INT_MAX <= x <= INT_MAX:
            raise NumberError(
                f"INTEGER overflow: {what} is {describe(x)}, outside ±{INT_MAX}",
                "keep it a REAL: INTEGERs hold whole numbers up to about 9.2E18",
            )
        return int(x)
    if not -INT_MAX <= x <= INT_MAX:
        raise overflow(x, what)
    return x


def real(x, what: str = "the result") -> float:
    """``x`` as a finite REAL; NumberError if it is not one.

    Parameters
    ----------
    x : int or float
    what : str
        What ``x`` is, for the message.
    """
    try:
        r = float(x)
    except OverflowError:
        raise overflow(x, what) from None
    if not -REAL_MAX <= r <= REAL_MAX:
        raise overflow(r, what)
    return r
