"""The language's vocabularies, each one table: types, modifiers, operators, built-in functions, blocks.

The parser, the checker, the lowering and the runtime all read these tables,
so adding a word means adding one entry here plus its implementation:

* a modifier (``<SCALE FRAMES 2>``): one :class:`Modifier` in :data:`MODIFIERS`,
  its grammar alternative ``-> mod_<kind>`` in ``lig.lark``, and the runtime
  method its entry names for each target type (``Runtime.motion_scale_frames``);
  ``tests/test_vocabulary.py`` checks that every entry is implemented;
* an operator rule (``MOTION + MOTION``): one :class:`Operator` in
  :data:`OPERATORS`, and its runtime method if it has one; a new operator
  symbol also needs its grammar production;
* a built-in function: one entry in :data:`FUNCTIONS` and the runtime method it names;
* a block: one :class:`Block` in :data:`BLOCKS` (the parser's messages about
  unclosed or stray blocks read it).

This module imports nothing of the package but lang/node_methods.py (how its records are
made), so every stage may read it.
"""

from __future__ import annotations

from dataclasses import field
from enum import StrEnum

from .node_methods import record


# ------------------------------------------------------------------ types
class Type(StrEnum):
    """The static type of a LIG value.

    A :class:`~enum.StrEnum`: each member is its own name, as the program,
    the messages and a library's cached table spell it.
    """

    INTEGER = "INTEGER"
    REAL = "REAL"
    VECTOR = "VECTOR"
    PAIR = "PAIR"  # a (min, max) pair: only joint extremes use it
    GRAPHICAL = "GRAPHICAL"
    MODEL = "MODEL"
    MOTION = "MOTION"
    BOOL = "BOOL"  # a condition


INTEGER, REAL, VECTOR, PAIR = Type.INTEGER, Type.REAL, Type.VECTOR, Type.PAIR
GRAPHICAL, MODEL, MOTION, BOOL = Type.GRAPHICAL, Type.MODEL, Type.MOTION, Type.BOOL
TYPES = tuple(Type)

#: How the kinds of object a modifier applies to are named in messages, in this order.
_PLURAL = {GRAPHICAL: "graphical objects", MODEL: "models", MOTION: "motions"}


# -------------------------------------------------------------- modifiers
@record(frozen=True)
class Modifier:
    """One modifier of the ``<...>`` lists.

    Attributes
    ----------
    kind : str
        The name in the syntax tree (``A.Modifier.kind``) and in the grammar's
        alias ``mod_<kind>``.
    label : str
        The words as the program writes them, for messages.
    methods : mapping of Type to str
        The types it applies to, each with the runtime method that applies
        it to a value of that type (``Runtime.model_trans``); the result has
        the target's type.
    accepts : tuple of Type
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
    methods: dict = field(hash=False)
    accepts: tuple = ()
    accepts_noun: str = ""
    nonzero: bool = False
    axis: bool = False

    @property
    def targets(self) -> tuple:
        """The types it applies to."""
        return tuple(self.methods)

    @property
    def targets_noun(self) -> str:
        """What it applies to, for messages (``"models and motions"``)."""
        return " and ".join(_PLURAL[t] for t in _PLURAL if t in self.methods)


#: The types a number may have.
NUMBER = (INTEGER, REAL)
_NUMBER = NUMBER

#: Every modifier, by kind, in the grammar's order.
MODIFIERS = {
    m.kind: m
    for m in (
        Modifier("trans_joints", "TRANS JOINTS", {MODEL: "model_trans_joints"}, (INTEGER,), "an INTEGER"),
        Modifier(
            "trans", "TRANS", {GRAPHICAL: "graphical_trans", MODEL: "model_trans"}, (VECTOR,), "a vector (x, y, z)"
        ),
        Modifier("rot", "ROT", {GRAPHICAL: "graphical_rot", MODEL: "model_rot"}, _NUMBER, "a number", axis=True),
        Modifier("scale_model", "SCALE MODEL", {MODEL: "model_scale_model"}, _NUMBER, "a number", nonzero=True),
        Modifier(
            "scale_extremes",
            "SCALE EXTREMES",
            {MODEL: "model_scale_extremes", MOTION: "motion_scale_extremes"},
            _NUMBER,
            "a number",
        ),
        Modifier("scale_frames", "SCALE FRAMES", {MOTION: "motion_scale_frames"}, _NUMBER, "a number", nonzero=True),
        Modifier(
            "scale",
            "SCALE",
            {GRAPHICAL: "graphical_scale", MODEL: "model_scale"},
            _NUMBER + (VECTOR,),
            "a number or a vector",
            nonzero=True,
        ),
        Modifier("lightness", "LIGHTNESS", {GRAPHICAL: "graphical_lightness"}, _NUMBER, "a number"),
        Modifier("colour", "COLOUR", {GRAPHICAL: "graphical_colour"}, (VECTOR,), "a colour (r, g, b), each 0 to 100"),
    )
}

#: The modifiers DRAW WITH takes inside a PRIMITIVE: they set what the next polygons are drawn with.
DRAW_WITH = (MODIFIERS["lightness"], MODIFIERS["colour"])


# -------------------------------------------------------------- operators
@record(frozen=True)
class Operator:
    """One row of the operator table: an operator on two operand types.

    Attributes
    ----------
    symbol : str
        As the syntax tree writes it (``A.BinOp.op``): ``+ - * / MOD``.
    rule : str
        The grammar's alias for it (``sum "+" product -> add``).
    left, right : tuple of str
        The operand types this row accepts.
    result : str or None
        The result's type; None for the numeric join (INTEGER only if both
        operands are).
    runtime : str or None
        The runtime method that computes it (``Runtime.superpose``), called
        as ``rt.<runtime>(left, right, at)``; None for the values' own
        Python operator, whose chains the lowering checks for overflow.
    at_operator : bool
        The runtime call's position is the operator's (a division by zero
        points at the ``/``), not the whole expression's.
    animated : bool
        A MODEL operand must be a model ANIMATEd earlier in this scene body
        (it is drawn in this tick's pose, the thesis' section 5.1).
    group_right : bool
        Chains are built right to left (``a + (b + c)``), as the thesis'
        BNF groups motion sums; the operator is associative.
    """

    symbol: str
    rule: str
    left: tuple
    right: tuple
    result: str | None
    runtime: str | None = None
    at_operator: bool = False
    animated: bool = False
    group_right: bool = False


_V, _G, _M = (VECTOR,), (GRAPHICAL,), (MOTION,)

#: Every operator rule, first match wins (the checker and the lowering read it in this order).
OPERATORS = (
    Operator("+", "add", _NUMBER, _NUMBER, None),
    Operator("-", "sub", _NUMBER, _NUMBER, None),
    Operator("+", "add", _V, _V, VECTOR),
    Operator("-", "sub", _V, _V, VECTOR),
    Operator("+", "add", _G, _G, GRAPHICAL, "superpose"),
    Operator("+", "add", (GRAPHICAL, MODEL), (GRAPHICAL, MODEL), GRAPHICAL, "superpose", animated=True),
    Operator("+", "add", _M, _M, MOTION, "concat", group_right=True),
    Operator("*", "mul", _NUMBER, _NUMBER, None),
    Operator("*", "mul", _NUMBER, _V, VECTOR),
    Operator("*", "mul", _V, _NUMBER, VECTOR),
    Operator("*", "mul", (INTEGER,), _M, MOTION, "repeat"),
    Operator("/", "div", _NUMBER, _NUMBER, REAL, "div", at_operator=True),
    Operator("/", "div", _V, _NUMBER, VECTOR, "div", at_operator=True),
    Operator("MOD", "mod", _NUMBER, _NUMBER, None, "mod", at_operator=True),
)


def operators_for(symbol: str, left: str | None, right: str | None) -> list:
    """The rows of :data:`OPERATORS` for ``symbol`` that take operands of these types, in table order."""
    return [o for o in OPERATORS if o.symbol == symbol and left in o.left and right in o.right]


# ----------------------------------------------------- built-in functions
@record(frozen=True)
class Function:
    """A built-in function: the types each argument may have, and the result type.

    Each of ``params`` is a tuple of the types that argument accepts
    (:data:`NUMBER` for INTEGER or REAL); a result of ``None`` means the
    type of the numeric arguments (ABS, MIN...). The runtime implements it
    as the method named :attr:`runtime`, called ``rt.<runtime>(*args, at=...)``.
    """

    name: str
    params: tuple
    result: Type | None
    runtime: str


#: Every built-in function, by name. Trigonometry is in degrees, like every angle in the language.
FUNCTIONS = {
    f.name: f
    for f in (
        Function("SIN", (NUMBER,), REAL, "f_SIN"),
        Function("COS", (NUMBER,), REAL, "f_COS"),
        Function("TAN", (NUMBER,), REAL, "f_TAN"),
        Function("ASIN", (NUMBER,), REAL, "f_ASIN"),
        Function("ACOS", (NUMBER,), REAL, "f_ACOS"),
        Function("ATAN", (NUMBER,), REAL, "f_ATAN"),
        Function("ATAN2", (NUMBER, NUMBER), REAL, "f_ATAN2"),
        Function("SQRT", (NUMBER,), REAL, "f_SQRT"),
        Function("EXP", (NUMBER,), REAL, "f_EXP"),
        Function("LOG", (NUMBER,), REAL, "f_LOG"),
        Function("ABS", (NUMBER,), None, "f_ABS"),
        Function("INT", (NUMBER,), INTEGER, "f_INT"),
        Function("NINT", (NUMBER,), INTEGER, "f_NINT"),
        Function("REAL", (NUMBER,), REAL, "f_REAL"),
        Function("FLOAT", (NUMBER,), REAL, "f_FLOAT"),
        Function("MIN", (NUMBER, NUMBER), None, "f_MIN"),
        Function("MAX", (NUMBER, NUMBER), None, "f_MAX"),
        Function("MOD", (NUMBER, NUMBER), None, "f_MOD"),
        Function("DOT", (_V, _V), REAL, "f_DOT"),
        Function("CROSS", (_V, _V), VECTOR, "f_CROSS"),
        Function("NORM", (_V,), REAL, "f_NORM"),
        Function("X", (_V,), REAL, "f_X"),
        Function("Y", (_V,), REAL, "f_Y"),
        Function("Z", (_V,), REAL, "f_Z"),
        Function("LEN", (_M,), REAL, "f_LEN"),
    )
}


# ------------------------------------------------------------------ blocks
@record(frozen=True)
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
