"""Numbers at run time: the operators and built-in functions generated code calls.

Every result is held to the policy of :mod:`liganimate.lang.numbers`: an
INTEGER stays within ``±INT_MAX``, a REAL stays finite. ``+``, ``-`` and
``*`` are checked inline by the generated code (see ``compiler/lower.py``),
which calls :meth:`Arithmetic.overflow` when a result is out of range; ``/``,
``MOD`` and every function are methods here that check their own results.
A failure is a diagnostic at the operator or call (``at``), never a Python
exception or a NaN carried on.

:class:`Arithmetic` is a mixin of the runtime object ``rt``; it needs the
runtime's ``fail(at, message, hint)``.
"""

from __future__ import annotations

import math
import os

from liganimate.lang import numbers as N
from liganimate.runtime.values import Vec

_R = N.REAL_MAX
_RESULT = {"+": "the sum", "-": "the difference", "*": "the product"}


def _finite_vec(v) -> bool:
    return -_R <= v[0] <= _R and -_R <= v[1] <= _R and -_R <= v[2] <= _R


class Arithmetic:
    """Operators and built-in functions of LIG numbers and vectors (a mixin of the runtime)."""

    def fail(self, at, message, hint=None):  # pragma: no cover - provided by the runtime
        raise NotImplementedError

    # ------------------------------------------------------------- checks
    def overflow(self, value, kind, at):
        """Report the value of a chain of ``+ - *`` that is outside the language's numbers.

        ``kind`` is the chain's static type (``I``, ``R``), followed by its
        operator when the chain is that one operation (``'R*'``).
        """
        exc = overflow_error(value, kind)
        self.fail(at, exc.message, exc.hint)

    def vector_ok(self, v, at, kind="V"):
        """``v`` if its components are finite, else a diagnostic at ``at`` (``kind`` as for :meth:`overflow`)."""
        if _finite_vec(v):
            return v
        what = _RESULT.get(kind[-1], "the value of this expression")
        exc = N.overflow(math.inf, f"a component of {what}")
        self.fail(at, exc.message, exc.hint)

    def _real(self, value, at, what):
        if -_R <= value <= _R:
            return value
        exc = N.overflow(float(value) if isinstance(value, int) else value, what)
        self.fail(at, exc.message, exc.hint)

    def _integer(self, value, at, what):
        try:
            return N.integer(value, what)
        except N.NumberError as exc:
            self.fail(at, exc.message, exc.hint)

    @staticmethod
    def vec(x, y, z) -> Vec:
        """A vector from three numbers (already in range, so finite as REALs)."""
        return Vec(x, y, z)

    # ---------------------------------------------------------- operators
    def div(self, a, b, at):
        """``a / b``: always REAL (or a VECTOR divided by a number)."""
        if isinstance(b, Vec):
            self.fail(at, "cannot divide by a vector")
        if b == 0:
            self.fail(at, "division by zero", "check the divisor's value before dividing")
        if isinstance(a, Vec):
            return self.vector_ok(Vec(a[0] / b, a[1] / b, a[2] / b), at)
        # Both operands are in range, so an INTEGER quotient is finite; a
        # REAL one can still overflow (1E308 / 0.1).
        return self._real(a / b, at, "the quotient")

    def mod(self, a, b, at):
        """``a MOD b``, floored: the result has the sign of ``b`` (exact, never overflows)."""
        if b == 0:
            self.fail(at, "MOD by zero")
        return a % b

    def do_range(self, start, stop, step, at):
        """The values of a DO loop's variable, produced one at a time (never a list).

        A loop of more than :func:`max_loop_trips` passes is refused at its
        DO statement before its first pass (issue 24: ``DO 10 R = 0.0, 1E18,
        1E-300`` ran forever).
        """
        if step == 0:
            self.fail(at, "a DO loop's step cannot be 0")
        trips = _trips(start, stop, step)
        limit = max_loop_trips()
        if trips > limit:
            shown = N.magnitude(float(trips)) if trips != math.inf else "endlessly many"
            self.fail(
                at,
                f"this DO loop would make {shown} passes, over the budget of {limit} passes for one loop",
                f"take a larger step or a shorter range, or raise the budget with {LOOP_TRIPS_ENV}",
            )
        if isinstance(start, int) and isinstance(stop, int) and isinstance(step, int):
            return range(start, stop + (1 if step > 0 else -1), step)
        return _real_steps(start, stop, step)

    # ---------------------------------------------------------- functions
    def _math(self, at, name, fn, x):
        try:
            return fn(x)
        except OverflowError:
            self.fail(
                at, f"{name}({N.describe(x)}) is too large for a REAL", "a REAL can hold magnitudes up to about 1.8E308"
            )
        except ValueError:
            self.fail(at, f"{name} of {N.describe(x)} is not defined")

    def f_SIN(self, x, at):
        return math.sin(math.radians(x))

    def f_COS(self, x, at):
        return math.cos(math.radians(x))

    def f_TAN(self, x, at):
        return math.tan(math.radians(x))

    def f_ASIN(self, x, at):
        return math.degrees(self._math(at, "ASIN", math.asin, x))

    def f_ACOS(self, x, at):
        return math.degrees(self._math(at, "ACOS", math.acos, x))

    def f_ATAN(self, x, at):
        return math.degrees(math.atan(x))

    def f_ATAN2(self, y, x, at):
        return math.degrees(math.atan2(y, x))

    def f_SQRT(self, x, at):
        return self._math(at, "SQRT", math.sqrt, x)

    def f_EXP(self, x, at):
        return self._math(at, "EXP", math.exp, x)

    def f_LOG(self, x, at):
        return self._math(at, "LOG", math.log, x)

    def f_ABS(self, x, at):
        return abs(x)

    def f_INT(self, x, at):
        return x if isinstance(x, int) else self._integer(x, at, "INT's result")

    def f_NINT(self, x, at):
        if isinstance(x, int):
            return x
        # FORTRAN's NINT, which the thesis' host language had: halves away from zero.
        return self._integer(math.copysign(math.floor(abs(x) + 0.5), x) if abs(x) < 2**53 else x, at, "NINT's result")

    def f_REAL(self, x, at):
        return float(x)

    f_FLOAT = f_REAL

    def f_MIN(self, a, b, at):
        m = min(a, b)
        return float(m) if isinstance(a, float) or isinstance(b, float) else m  # REAL if either is

    def f_MAX(self, a, b, at):
        m = max(a, b)
        return float(m) if isinstance(a, float) or isinstance(b, float) else m

    def f_MOD(self, a, b, at):
        return self.mod(a, b, at)

    def f_DOT(self, a, b, at):
        return self._real(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], at, "DOT's result")

    def f_CROSS(self, a, b, at):
        return self.vector_ok(Vec(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]), at)

    def f_NORM(self, a, at):
        # hypot scales internally: NORM((1E200, 1E200, 1E200)) is 1.7E200, not an overflow.
        return self._real(math.hypot(a[0], a[1], a[2]), at, "NORM's result")

    def f_X(self, a, at):
        return a[0]

    def f_Y(self, a, at):
        return a[1]

    def f_Z(self, a, at):
        return a[2]


def overflow_error(value, kind) -> N.NumberError:
    """The error for a + - * value out of range (``kind`` as for :meth:`Arithmetic.overflow`)."""
    if kind[0] == "R" and isinstance(value, int):
        value = math.inf  # a REAL-typed expression holding a huge whole number
    return N.overflow(value, _RESULT.get(kind[-1], "the value of this expression"))


#: The environment variable that sets the most passes one DO loop may make.
LOOP_TRIPS_ENV = "LIGANIMATE_MAX_LOOP_PASSES"
#: The default budget of passes of one DO loop (a billion passes of Python would take hours).
DEFAULT_LOOP_TRIPS = 100_000_000


def max_loop_trips() -> int:
    """The most passes one DO loop may make: ``$LIGANIMATE_MAX_LOOP_PASSES`` if it is a whole number, else 10^8."""
    text = os.environ.get(LOOP_TRIPS_ENV, "").strip()
    return int(text) if text.isdigit() else DEFAULT_LOOP_TRIPS


def _trips(start, stop, step) -> float:
    """The number of passes of a DO loop, computed before the first (``inf`` when it cannot be counted)."""
    if isinstance(start, int) and isinstance(stop, int) and isinstance(step, int):
        return max(0, (stop - start) // step + 1)
    q = (stop - start + step) / step + 1e-9  # as _real_steps counts them
    if not q > 0:  # also NaN: no pass, as _real_steps makes
        return 0
    return math.floor(q) if q != math.inf else math.inf


def _real_steps(start, stop, step):
    """A REAL DO loop's values: ``start + i*step`` while within ``stop``, as the loop used to list them.

    The number of passes is ``floor((stop - start + step) / step)`` (with a
    1e-9 tolerance for rounding); when that count overflows, the loop runs
    until its value passes ``stop``.
    """
    q = (stop - start + step) / step + 1e-9
    if not q > 0:  # also NaN
        return
    if q <= 2.0**62:
        if isinstance(start, float) and isinstance(step, float):
            for i in range(math.floor(q)):
                yield start + i * step
        else:
            for i in range(math.floor(q)):
                yield float(start + i * step)
        return
    i = 0
    while True:
        v = start + i * step
        if (v > stop) if step > 0 else (v < stop):
            return
        yield float(v)
        i += 1
