"""The language's vocabularies, each one table: types, modifiers, built-in functions, blocks.

The parser, the checker, the lowering and the runtime all read these tables,
so adding a word means adding one entry here plus its implementation:

* a modifier (``<SCALE FRAMES 2>``): one :class:`Modifier` in :data:`MODIFIERS`,
  its grammar alternative ``-> mod_<kind>`` in ``lig.lark``, and one runtime
  method per target type, named by :meth:`Modifier.runtime_name`
  (``Runtime.motion_scale_frames``); ``tests/test_vocabulary.py`` checks
  that every entry is implemented;
* a built-in function: one entry in :data:`FUNCTIONS` and ``f_<NAME>`` on the runtime;
* a block: one :class:`Block` in :data:`BLOCKS` (the parser's messages about
  unclosed or stray blocks read it).

This module imports nothing of the package, so every stage may read it.
"""

from __future__ import annotations

from dataclasses import dataclass

# ------------------------------------------------------------------ types
INTEGER = "INTEGER"
REAL = "REAL"
VECTOR = "VECTOR"
PAIR = "PAIR"  # a (min, max) pair: only joint extremes use it
GRAPHICAL = "GRAPHICAL"
MODEL = "MODEL"
MOTION = "MOTION"
BOOL = "BOOL"

#: How the kinds of object a modifier applies to are named in messages, in this order.
_PLURAL = {GRAPHICAL: "graphical objects", MODEL: "models", MOTION: "motions"}


# -------------------------------------------------------------- modifiers
@dataclass(frozen=True)
class Modifier:
    """One modifier of the ``<...>`` lists.

    Attributes
    ----------
    kind : str
        The name in the syntax tree (``A.Modifier.kind``) and in the grammar's
        alias ``mod_<kind>``.
    label : str
        The words as the program writes them, for messages.
    targets : tuple of str
        The types it applies to; the result has the target's type.
    accepts : tuple of str
        The types its argument may have.
    accepts_noun : str
        What the argument must be, for messages (``"a number"``).
    nonzero : bool
        A literal 0 is refused (it would collapse the object).
    axis : bool
        It names an axis (``ROT X 30``).
    """

    kind: str
    label: str
    targets: tuple
    accepts: tuple
    accepts_noun: str
    nonzero: bool = False
    axis: bool = False

    def runtime_name(self, target: str) -> str:
        """The runtime method that applies it to a value of type ``target`` (``"model_trans"``)."""
        return f"{target.lower()}_{self.kind}"

    @property
    def targets_noun(self) -> str:
        """What it applies to, for messages (``"models and motions"``)."""
        return " and ".join(_PLURAL[t] for t in _PLURAL if t in self.targets)


_NUMBER = (INTEGER, REAL)

#: Every modifier, by kind, in the grammar's order.
MODIFIERS = {
    m.kind: m
    for m in (
        Modifier("trans_joints", "TRANS JOINTS", (MODEL,), (INTEGER,), "an INTEGER"),
        Modifier("trans", "TRANS", (GRAPHICAL, MODEL), (VECTOR,), "a vector (x, y, z)"),
        Modifier("rot", "ROT", (GRAPHICAL, MODEL), _NUMBER, "a number", axis=True),
        Modifier("scale_model", "SCALE MODEL", (MODEL,), _NUMBER, "a number", nonzero=True),
        Modifier("scale_extremes", "SCALE EXTREMES", (MODEL, MOTION), _NUMBER, "a number"),
        Modifier("scale_frames", "SCALE FRAMES", (MOTION,), _NUMBER, "a number", nonzero=True),
        Modifier("scale", "SCALE", (GRAPHICAL, MODEL), _NUMBER + (VECTOR,), "a number or a vector", nonzero=True),
        Modifier("lightness", "LIGHTNESS", (GRAPHICAL,), _NUMBER, "a number"),
        Modifier("colour", "COLOUR", (GRAPHICAL,), (VECTOR,), "a colour (r, g, b), each 0 to 100"),
    )
}

#: The modifiers DRAW WITH takes inside a PRIMITIVE: they set what the next polygons are drawn with.
DRAW_WITH = (MODIFIERS["lightness"], MODIFIERS["colour"])


# ----------------------------------------------------- built-in functions
@dataclass(frozen=True)
class Function:
    """A built-in function: its argument types and result type.

    ``"N"`` as an argument type means a number (INTEGER or REAL); a result
    of ``None`` means the type of the numeric arguments (ABS, MIN...).
    The runtime implements it as ``f_<name>(*args, at)``.
    """

    name: str
    params: tuple
    result: str | None


#: Every built-in function, by name. Trigonometry is in degrees, like every angle in the language.
FUNCTIONS = {
    f.name: f
    for f in (
        Function("SIN", ("N",), REAL),
        Function("COS", ("N",), REAL),
        Function("TAN", ("N",), REAL),
        Function("ASIN", ("N",), REAL),
        Function("ACOS", ("N",), REAL),
        Function("ATAN", ("N",), REAL),
        Function("ATAN2", ("N", "N"), REAL),
        Function("SQRT", ("N",), REAL),
        Function("EXP", ("N",), REAL),
        Function("LOG", ("N",), REAL),
        Function("ABS", ("N",), None),
        Function("INT", ("N",), INTEGER),
        Function("NINT", ("N",), INTEGER),
        Function("REAL", ("N",), REAL),
        Function("FLOAT", ("N",), REAL),
        Function("MIN", ("N", "N"), None),
        Function("MAX", ("N", "N"), None),
        Function("MOD", ("N", "N"), None),
        Function("DOT", (VECTOR, VECTOR), REAL),
        Function("CROSS", (VECTOR, VECTOR), VECTOR),
        Function("NORM", (VECTOR,), REAL),
        Function("X", (VECTOR,), REAL),
        Function("Y", (VECTOR,), REAL),
        Function("Z", (VECTOR,), REAL),
        Function("LEN", (MOTION,), REAL),
    )
}


# ------------------------------------------------------------------ blocks
@dataclass(frozen=True)
class Block:
    """A block of statements: the word that opens it, the word that closes it.

    ``shown`` is how the opening is written in messages (a scene opens with
    ``INITIALIZE SCENE``).
    """

    opener: str
    closer: str
    shown: str


#: Every block, innermost-closing first: when a file ends inside a block the
#: parser did not see, the first closer it expects in this order is suggested.
BLOCKS = (
    Block("STARTMOTION", "ENDMOTION", "STARTMOTION"),
    Block("STARTMODEL", "ENDMODEL", "STARTMODEL"),
    Block("STARTREACH", "ENDREACH", "STARTREACH"),
    Block("INITIALIZE", "ENDSCENE", "INITIALIZE SCENE"),
    Block("BEGIN", "END", "BEGIN"),
    Block("PRIMITIVE", "END", "PRIMITIVE"),
    Block("JOINT", "ENDJOINT", "JOINT"),
)
