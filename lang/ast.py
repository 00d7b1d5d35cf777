"""The typed syntax tree of a LIG ANIMATE program.

Every node is a small dataclass with a :class:`Pos` (made by
:func:`.node_methods.node`, whose methods are written out once); names are upper-cased
(the language is case-insensitive) and numbers are already converted. The
tree is produced by :mod:`liganimate.lang.transform` while the LALR parser
runs, so building it never recurses.

Every statement's node, and each node its parts are made of, is declared
once, here, as pycparser declares its node shapes once: ``@syntax(rule,
statement=production, field=reader, ...)`` names the grammar rule that makes
it, gives a statement's production (written into lang/lig.lark by
``python -m liganimate.lang.tables``, see lang/grammar.py) and says how each
field is read from the rule's children (lang/syntax.py); the transformer is
made from that. A field also says what the other passes need to know of it:
the names a statement binds (``binds``, read by lang/bindings.py) or uses
without an expression (``uses``, read by the editor's index) and the
statement lists it holds (``holds``, read by lang/visitor.py's ``BLOCKS``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import MISSING, field, fields
from typing import Any, Self

from . import syntax as R
from .node_methods import node, record
from .numbers import literal
from .syntax import SYNTAX, Syntax, upper_name, value_rule
from .vocabulary import NUMBER, Type

_M12, _M24, _M28, _M32, _M64 = (1 << 12) - 1, (1 << 24) - 1, (1 << 28) - 1, (1 << 32) - 1, (1 << 64) - 1
_START = _M24 | _M12 << 24 | _M32 << 60  # the line, column and offset bits of a packed Pos
_PLACE = (1 << 60) - 1  # the line and column bits: a Pos without its offsets
_int_new = int.__new__


def _zig(n: int) -> int:
    return n << 1 if n >= 0 else ((-n) << 1) - 1


def _unzig(z: int) -> int:
    return z >> 1 if not z & 1 else -((z + 1) >> 1)


class Pos(int):
    """A source span: 1-based lines and columns, end exclusive, and character offsets.

    Read it as ``pos.line``, ``pos.column``, ``pos.end_line`` and
    ``pos.end_column``, which are where a diagnostic's caret and underline
    go, and ``pos.start`` and ``pos.end``, the 0-based character offsets of
    the text the construct occupies, so that ``text[pos.start:pos.end]`` is
    its spelling. The two agree except around parentheses: the parser widens
    the offsets of ``(A + B)`` over its parentheses (a parent's text and a
    PRINT label keep them) while the caret stays on ``A + B``. A position not
    made from program text (a synthetic one) has offsets 0 and 0.

    Make it as ``Pos(line, column, end_line, end_column, start, end)``. It is
    a value: immutable, hashable, equal to another Pos with the same six
    numbers.

    A big program has millions of positions, so the numbers are packed into
    one int (56 bytes, where an object with six fields would take 72 and
    keep its numbers alive in more). The usual span (line below 2**24,
    columns below 4096, at most 4095 lines long, starting in the first
    2**32 characters and at most 2**28 long, which a source of at most
    64 MB always is) packs into 120 bits; any other is stored negated, each
    number zigzag-encoded in 64 bits.
    """

    __slots__ = ()

    def __new__(cls, line: int, column: int, end_line: int, end_column: int, start: int = 0, end: int = 0) -> Self:
        lines = end_line - line
        length = end - start
        # (a | b) >> k is 0 exactly when both are in [0, 2**k): one test for range and sign.
        if not ((column | end_column | lines) >> 12 or line >> 24 or start >> 32 or length >> 28):
            return _int_new(cls, line | column << 24 | end_column << 36 | lines << 48 | start << 60 | length << 92)
        packed = 0
        for shift, n in enumerate((line, column, end_line, end_column, start, end)):
            z = _zig(n)
            if z > _M64:
                raise OverflowError(f"position {n} is out of range")
            packed |= z << (64 * shift)
        return _int_new(cls, -1 - packed)

    def _field(self, i: int) -> int:
        return _unzig((-1 - self) >> (64 * i) & _M64)

    @property
    def line(self) -> int:
        """First line (1-based)."""
        return self & _M24 if self >= 0 else self._field(0)

    @property
    def column(self) -> int:
        """First column (1-based)."""
        return self >> 24 & _M12 if self >= 0 else self._field(1)

    @property
    def end_line(self) -> int:
        """Last line."""
        return (self & _M24) + (self >> 48 & _M12) if self >= 0 else self._field(2)

    @property
    def end_column(self) -> int:
        """Column just after the end."""
        return self >> 36 & _M12 if self >= 0 else self._field(3)

    @property
    def start(self) -> int:
        """Offset of the first character of the construct's text (0-based)."""
        return self >> 60 & _M32 if self >= 0 else self._field(4)

    @property
    def end(self) -> int:
        """Offset just after the construct's text."""
        return (self >> 60 & _M32) + (self >> 92) if self >= 0 else self._field(5)

    def to(self, other: Pos) -> Pos:
        """The span from the start of ``self`` to the end of ``other``."""
        if self >= 0 and other >= 0:
            lines = (other & _M24) + (other >> 48 & _M12) - (self & _M24)
            length = (other >> 60 & _M32) + (other >> 92) - (self >> 60 & _M32)
            if not (lines >> 12 or length >> 28):
                return _int_new(Pos, (self & _START) | (other >> 36 & _M12) << 36 | lines << 48 | length << 92)
        return Pos(self.line, self.column, other.end_line, other.end_column, self.start, other.end)

    def widened(self, start: int, end: int) -> Pos:
        """The same caret, with the offsets ``start``, ``end`` (a construct's text with its parentheses)."""
        return Pos(self.line, self.column, self.end_line, self.end_column, start, end)

    def without_offsets(self) -> Pos:
        """The same lines and columns, with the offsets of a synthetic position (0 and 0)."""
        if self >= 0:
            return _int_new(Pos, self & _PLACE)
        return Pos(self.line, self.column, self.end_line, self.end_column)

    def __bool__(self) -> bool:
        return True  # a position, not a number: even NOWHERE

    def __repr__(self) -> str:
        text = f"Pos(line={self.line}, column={self.column}, end_line={self.end_line}, end_column={self.end_column}"
        start, end = self.start, self.end
        return text + (f", start={start}, end={end})" if start or end else ")")

    __str__ = __repr__

    def __reduce__(self):
        return (Pos, (self.line, self.column, self.end_line, self.end_column, self.start, self.end))


def token_pos(line: int, column: int, end_column: int, start: int = 0, end: int = 0) -> Pos:
    """``Pos(line, column, line, end_column, start, end)``, quicker: the parser makes one for every name and number."""
    length = end - start
    if not ((column | end_column) >> 12 or line >> 24 or start >> 32 or length >> 28):
        return _int_new(Pos, line | column << 24 | end_column << 36 | start << 60 | length << 92)
    return Pos(line, column, line, end_column, start, end)


NOWHERE = Pos(0, 0, 0, 0)


@node
class Node:
    pos: Pos


# ------------------------------------------------------------ declarations


def syntax(
    rule: str,
    pos: R.Reader | None = None,
    *,
    statement: str | None = None,
    production: str | None = None,
    **readers: R.Reader,
) -> Callable[[type], type]:
    """Declare that grammar rule ``rule`` makes the decorated node class (put it above ``@node``).

    Parameters
    ----------
    rule : str
        The rule or alias of lang/lig.lark; a class may be made by several.
    statement, production : str, optional
        The rule's production (Lark's notation), written into lig.lark by
        ``python -m liganimate.lang.tables`` (lang/grammar.py): a statement's
        (an alternative of ``?statement``), or a part's. A rule given
        neither is written in lig.lark by hand (an alias, or a part shared
        by several statements).
    pos : Reader, optional
        How the node's position is read (lang/syntax.py); by default the
        span of all the rule's children.
    **readers : Reader
        How each field is read; a field not named here is read by the
        reader its own declaration gives (:func:`read`, :func:`part`), or
        keeps its default, or else takes the next value (``R.value()``).
    """

    def register(cls: type) -> type:
        chosen = []
        for f in fields(cls):
            if f.name == "pos":
                continue
            reader = readers.get(f.name) or f.metadata.get("read")
            if reader is None and "part" in f.metadata:
                reader = R.rest() if f.metadata["part"].many else R.value()
            if reader is None:
                if f.default is not MISSING:
                    reader = R.const(f.default)
                elif f.default_factory is not MISSING:
                    reader = R.factory(f.default_factory)
                else:
                    reader = R.value()
            chosen.append((f.name, reader))
        unknown = set(readers) - {name for name, _ in chosen}
        assert not unknown and rule not in SYNTAX, (rule, unknown)
        SYNTAX[rule] = Syntax(rule, cls, tuple(chosen), pos)
        if statement is not None or production is not None:
            R.produce(rule, statement or production or "", statement=statement is not None)
        return cls

    return register


def read(
    reader: R.Reader | None = None, *, binds: str | None = None, uses: bool = False, holds: bool = False
) -> dict[str, Any]:
    """A field's metadata: read by ``reader``, binding names (``binds``), using one (``uses``) or holding statements.

    Write ``field(metadata=read(...))``. ``binds`` is "assigns" (the
    statement gives the names a value), "figure" (FIGURE's new value of its
    model, which some questions leave out) or "declares" (a declaration: a
    type, no value). ``uses`` marks a ``Name`` field that names a variable
    the statement reads without an expression (ANIMATE's model): the
    editor's index counts it among the variable's references. ``holds``
    marks a list of statements the statement holds.
    """
    metadata: dict[str, Any] = {"read": reader} if reader is not None else {}
    if binds is not None:
        metadata["binds"] = binds
    if uses:
        metadata["uses"] = True
    if holds:
        metadata["holds"] = True
    return metadata


def statement_fields(key: str) -> dict[type, tuple[tuple[str, Any], ...]]:
    """Each node class with fields that declare ``key`` ("binds", "uses", "holds") -> those fields and what they say, in order."""
    found: dict[type, tuple[tuple[str, Any], ...]] = {}
    # The module's classes, not Node.__subclasses__(): a slots dataclass leaves the class it replaced behind.
    for cls in list(globals().values()):
        if isinstance(cls, type) and issubclass(cls, Node):
            marked = tuple((f.name, f.metadata[key]) for f in fields(cls) if key in f.metadata)
            if marked:
                found[cls] = marked
    return found


# --------------------------------------------------------------- expressions


@node
class Num(Node):
    value: int | float
    text: str


@node
class Var(Node):
    name: str


@node
class Call(Node):
    name: str
    args: list


@node
class Tuple(Node):
    items: list


@node
class BinOp(Node):
    op: str  # one of + - * / MOD
    left: Node
    right: Node
    op_pos: Pos = NOWHERE


@node
class Neg(Node):
    operand: Node


@node
class Modifier(Node):
    """One entry of a ``< ... >`` list."""

    kind: str  # a key of lang.vocabulary.MODIFIERS
    arg: Node
    axis: str | None = None


@node
class Modified(Node):
    target: Node
    modifiers: list


@node
class Clause(Node):
    keyword: str
    value: Node


@node
class PrimCall(Node):
    name: str
    clauses: list


# JOINT's AXIS part: ("AXIS", the direction).
value_rule("joint_axis", R.const("AXIS"), R.value())


# What follows the word JOINT (in a JOINT statement and a JOINT expression):
# (the expressions, whether SLIDE is written, the AXIS direction or None).
value_rule("joint_args", R.rest(of=Node), R.flag("SLIDE"), R.item(1))


@syntax("joint_expr", args=R.item(0), slide=R.item(1), axis=R.item(2))
@node
class JointExpr(Node):
    args: list
    slide: bool = False  # SLIDE before the extremes: a prismatic joint
    axis: Node | None = None  # AXIS (x, y, z) after them


@node
class Strip(Node):
    motion: Node
    joints: list


@node
class Sync(Node):
    motions: list


@node
class Compare(Node):
    op: str
    left: Node
    right: Node


@node
class BoolOp(Node):
    op: str  # AND / OR
    left: Node
    right: Node


@node
class Not(Node):
    operand: Node


# ----------------------------------------------------------------- statements


@node
class Name(Node):
    """A name written in a statement (declared, assigned, animated...)."""

    name: str


def AS_NAME(text: str, pos: Pos) -> Name:
    """A name token's conversion (lang/syntax.py): a :class:`Name`, upper-cased."""
    return Name(pos, upper_name(text))


def AS_NUM(text: str, pos: Pos) -> Num:
    """A number token's conversion: a :class:`Num`.

    lang/numbers.py decides what a literal means; one outside the language's
    numbers comes back marked, and the checker reports it.
    """
    return Num(pos, literal(text.rstrip("°")), text)


def AS_LABEL(text: str, pos: Pos) -> int | float:
    """A DO label's conversion: the number's value."""
    return AS_NUM(text, pos).value


# The parts made of one token or a list of values.
value_rule("decl_name", R.token("NAME", AS_NAME), production="NAME")
value_rule("interpolate", R.token("NAME", AS_NAME))
value_rule("position", R.rest())
value_rule("block", R.rest(), production="BEGIN _sep* (statement _sep*)* END")
value_rule("table_column", R.value())
value_rule("pattern", R.rest())
value_rule("goal_link", R.token(("NAME", "NUMBER"), {"NAME": AS_NAME, "NUMBER": AS_NUM}))


R.produce("_name_list", 'decl_name ("," decl_name)*')


@syntax("declaration", statement="TYPE_KW _name_list", type=R.token("TYPE_KW", lambda text: Type(upper_name(text))))
@node
class Decl(Node):
    type: str  # a vocabulary.Type
    names: list = field(metadata=read(R.rest(), binds="declares"))  # of Name


@syntax("assignment", statement="NAME ASSIGN_OP rhs", op=R.token("ASSIGN_OP", R.TEXT))
@node
class Assign(Node):
    target: Name = field(metadata=read(R.token("NAME", AS_NAME), binds="assigns"))
    op: str  # = := :-
    value: Node


@syntax("keyframe", position=R.value(), method=R.value())
@node
class Keyframe(Node):
    frame: Node
    position: list  # 1 vector expression or 3 numbers
    method: Name | None


@syntax(
    "keyframe_assign",
    statement='NAME "[" (expr | root_track) "," expr "]" ASSIGN_OP keyframe',
    op=R.token("ASSIGN_OP", R.TEXT),
)
@node
class KeyframeAssign(Node):
    target: Name = field(metadata=read(R.token("NAME", AS_NAME), binds="assigns"))
    joint: Node
    index: Node
    op: str
    keyframe: Keyframe


@syntax(
    "do_stmt",
    statement='DO NUMBER NAME "=" expr "," expr ("," expr)?',
    label=R.token("NUMBER", AS_LABEL),
    var=R.token("NAME", AS_NAME),
    step=R.value(),
)
@node
class DoHeader(Node):
    """``DO label var = a, b[, step]`` before loops are grouped."""

    label: int
    var: Name
    start: Node
    stop: Node
    step: Node | None


@syntax("continue_stmt", statement="NUMBER CONTINUE", label=R.token("NUMBER", AS_LABEL))
@node
class Continue(Node):
    label: int


@node
class Do(Node):
    """A DO loop, made from a DoHeader, the statements after it and its CONTINUE (lang/structure.py)."""

    label: int
    var: Name = field(metadata=read(binds="assigns"))
    start: Node
    stop: Node
    step: Node | None
    body: list = field(metadata=read(holds=True))
    end_pos: Pos = NOWHERE


R.produce("_branch", "statement | block")


@syntax("if_stmt", statement="IF cond THEN _branch (ELSE _branch)?")
@node
class If(Node):
    cond: Node
    then: list = field(metadata=read(R.block(), holds=True))
    orelse: list | None = field(metadata=read(R.block(), holds=True))


@syntax("joint_stmt", production="JOINT joint_args", args=R.item(0), slide=R.item(1), axis=R.item(2))
@node
class JointStmt(Node):
    args: list
    slide: bool = False  # as in JointExpr
    axis: Node | None = None


@syntax("model_block", statement="STARTMODEL NAME _sep* (joint_stmt _sep*)* ENDMODEL", joints=R.rest())
@node
class ModelBlock(Node):
    name: Name = field(metadata=read(R.token("NAME", AS_NAME), binds="assigns"))
    joints: list  # of JointStmt


@syntax("root_track", pos=R.where(1), orientation=R.flag("ORIENTATION"))
@node
class RootTrack(Node):
    """The word ROOT where a joint identifier stands: the motion's root-translation track.

    ``ROOT ORIENTATION`` (``orientation`` True) is its root orientation track.
    """

    orientation: bool = False


@node
class MorphTrack(Node):
    """``SCALE LINK name`` or ``SHAPE LINK name`` where a joint identifier stands: a link's morph track."""

    kind: str  # "SCALE" or "SHAPE"
    link: str  # the link's name, in capitals (a name of the model's, not a variable)


@syntax("motion_joint", start=R.after("POSITION"), keyframes=R.rest(of=Keyframe))
@syntax("motion_root", start=R.after("POSITION"), keyframes=R.rest(of=Keyframe))
@syntax(
    "motion_morph",
    joint=R.made(MorphTrack, pos=R.where(3), kind=R.which(("SCALE", "SHAPE")), link=R.token("NAME", R.UPPER)),
    start=R.after("POSITION"),
    keyframes=R.rest(of=Keyframe),
)
@node
class MotionJoint(Node):
    joint: Node  # RootTrack for the ROOT entry, MorphTrack for SCALE and SHAPE
    start: list | None
    keyframes: list


@syntax("motion_table", columns=R.rest(), rows=R.token("TABLE_ROWS", R.TEXT), rows_pos=R.token("TABLE_ROWS", R.POS))
@node
class MotionTable(Node):
    """``TABLE 1, 2, ROOT`` and its ``| frame x y z ...`` rows: keyframes of several tracks at once.

    ``rows`` is the TABLE_ROWS token's text and ``rows_pos`` where it starts;
    the checker reads the numbers (lang/keyframe_table.py) into ``data``.
    """

    columns: list  # of expressions and RootTrack
    rows: str
    rows_pos: Pos
    data: object = None


@syntax(
    "motion_block",
    statement="STARTMOTION NAME _sep* ((motion_joint | motion_root | motion_table | motion_morph) _sep*)* ENDMOTION",
    joints=R.rest(of=MotionJoint),
    tables=R.rest(of=MotionTable),
)
@node
class MotionBlock(Node):
    name: Name = field(metadata=read(R.token("NAME", AS_NAME), binds="assigns"))
    joints: list  # of MotionJoint
    tables: list = field(default_factory=list)  # of MotionTable


@syntax("goal_point", kind=R.const("point"), point=R.after("AT"), target=R.after("TO"), normal=R.const(None))
@syntax("goal_plane", kind=R.const("plane"), point=R.after("AT"), target=R.after("PLANE"), normal=R.after("NORMAL"))
@syntax("goal_axis", kind=R.const("axis"), point=R.const(None), target=R.after("ALONG"), normal=R.after("AXIS_KW"))
@node
class GoalSpec(Node):
    """Where a GOAL wants its link (the parser's part, not the tree's: :class:`Goal` copies it)."""

    kind: str
    point: Node | None
    target: Node | None
    normal: Node | None


@syntax(
    "reach_goal",
    kind=R.inner(GoalSpec, "kind"),
    link=R.value(of=Name),
    joint=R.value(of=Num),
    point=R.inner(GoalSpec, "point"),
    target=R.inner(GoalSpec, "target"),
    normal=R.inner(GoalSpec, "normal"),
    weight=R.after("WEIGHT"),
)
@node
class Goal(Node):
    """One goal of a REACH block: ``kind`` is "point", "plane" or "axis"."""

    kind: str
    link: Name | None  # a link name, or None when ``joint`` names it
    joint: Node | None  # GOAL JOINT n: the link joint n attaches
    point: Node | None  # AT (p): the point in the link's coordinates
    target: Node | None  # point: TO (x); plane: its point; axis: ALONG (d)
    normal: Node | None  # plane: NORMAL (n); axis: AXIS (a) in the link
    weight: Node | None


@syntax("reach_move_joints", word=R.const("MOVE JOINTS"), value=R.rest())
@syntax("reach_move_chain", word=R.const("MOVE CHAIN"))
@syntax("reach_translate", word=R.const("TRANSLATE"), value=R.token("NAME", AS_NAME))
@syntax("reach_solver", word=R.const("SOLVER"), value=R.token("NAME", AS_NAME))
@syntax("reach_tolerance", word=R.const("TOLERANCE"))
@syntax("reach_iterations", word=R.const("ITERATIONS"))
@node
class Option(Node):
    """One option line of a block (REACH's MOVE JOINTS, SOLVER...): its block copies the value to a field of its own."""

    word: str
    value: Node


# Goal-directed positioning (not in the thesis; see docs/language.md 4.17):
# a MOTION from a start pose to the pose that best meets weighted goals.
@syntax(
    "reach_block",
    statement="STARTREACH NAME MODEL_KW expr FRAME expr interpolate? (FROM expr)? _sep* (reach_item _sep*)* ENDREACH",
    method=R.value(of=Name),
    start=R.after("FROM"),
    goals=R.rest(of=Goal),
    joints=R.option("MOVE JOINTS"),
    chain=R.option("MOVE CHAIN"),
    solver=R.option("SOLVER"),
    tolerance=R.option("TOLERANCE"),
    iterations=R.option("ITERATIONS"),
    options=R.options(),
)
@node
class ReachBlock(Node):
    name: Name = field(metadata=read(R.token("NAME", AS_NAME), binds="assigns"))
    model: Node
    frames: Node
    method: Name | None
    start: Node | None  # FROM motion
    goals: list  # of Goal
    joints: list | None = None  # MOVE JOINTS ...
    chain: Node | None = None  # MOVE CHAIN n
    translate: Name | None = field(
        default=None, metadata=read(R.option("TRANSLATE"), binds="assigns")
    )  # TRANSLATE INTO v
    solver: Name | None = None
    tolerance: Node | None = None
    iterations: Node | None = None
    options: dict = field(default_factory=dict)  # option word -> Pos of each line that gives it (for duplicates)


@syntax(
    "figure_stmt",
    statement="FIGURE NAME MAIN (LINK NAME | JOINT expr)?",
    kind=R.which(("LINK", "JOINT")),
    link=R.after("LINK", AS_NAME),
    joint=R.after("JOINT"),
)
@node
class FigureStmt(Node):
    model: Name = field(metadata=read(R.token("NAME", AS_NAME), binds="figure"))
    kind: str | None  # None, LINK or JOINT
    link: Name | None = None
    joint: Node | None = None


@syntax(
    "scene_block",
    statement="INITIALIZE SCENE expr _sep* (statement _sep*)* STARTSCENE LENGTH expr (SAMEFRAME expr)? _sep*"
    " (statement _sep*)* ENDSCENE",
    length=R.after("LENGTH"),
    sameframe=R.after("SAMEFRAME"),
    start_pos=R.where(3),
)
@node
class Scene(Node):
    scene_id: Node
    init: list = field(metadata=read(R.rest(until="STARTSCENE"), holds=True))
    length: Node
    sameframe: Node | None
    body: list = field(metadata=read(R.rest(), holds=True))
    start_pos: Pos = NOWHERE


@syntax("animate_stmt", statement="ANIMATE NAME FROM expr TO expr USING expr REPEAT?", repeat=R.flag("REPEAT"))
@node
class Animate(Node):
    model: Name = field(metadata=read(R.token("NAME", AS_NAME), uses=True))
    start: Node
    end: Node
    motion: Node
    repeat: bool


@syntax("background_stmt", statement='BACKGROUND expr ("," expr)*', items=R.rest())
@node
class Background(Node):
    items: list


def _dollar_name(text: str, pos: Pos) -> Name:
    """``$NAME`` in a PRINT: the model's name, without the dollar sign (nor the caret under it)."""
    return Name(Pos(pos.line, pos.column + 1, pos.end_line, pos.end_column, pos.start + 1, pos.end), text[1:].upper())


@syntax("print_table", kind=R.const("table"), value=R.token("DOLLAR_NAME", _dollar_name))
@syntax("print_text", kind=R.const("text"), value=R.token("STRING", R.UNQUOTE))
@node
class PrintItem(Node):
    kind: str  # value, table, text
    value: object  # Node for value, Name for table, str for text


def _print_value(item: Node) -> PrintItem:
    """An item of a PRINT that is an expression (a $ table and a text are PrintItems already)."""
    return item if isinstance(item, PrintItem) else PrintItem(item.pos, "value", item)


@syntax("print_stmt", statement='PRINT print_item ("," print_item)*', items=R.rest(convert=_print_value))
@node
class Print(Node):
    items: list


# ------------------------------------------------------- declared statements
# A statement made of expressions that the runtime carries out is declared
# with @declared: each field is one part, an expression of the types it
# accepts, and @declared names the grammar rule, where it may stand and the
# runtime method that runs it. The transformer, the checker and the lowering
# (the rule of Declared, compiler/rules/declared.py, which emits
# ``rt.<runtime>(<parts>, at)``) read the declaration; none of them names the
# statement.

#: Where a statement may stand: the program's top level (loops and IFs
#: included), a scene's initialisation, a scene's body, a PRIMITIVE.
PLACES = frozenset({"top", "scene", "scene-body", "primitive"})


@record(frozen=True, slots=True)
class Part:
    """One part of a declared statement: an expression of one of ``accepts`` (or, ``many``, a list of them).

    ``what`` names it in messages ("a view point (x, y, z)").
    """

    accepts: tuple[Type, ...]
    what: str
    many: bool = False


def part(*accepts: Type, what: str, many: bool = False) -> Any:
    """The field of a declared statement's node that holds one :class:`Part` (read in order, as :func:`syntax` does)."""
    return field(metadata={"part": Part(tuple(accepts), what, many)})


@record(frozen=True, slots=True)
class Declaration:
    """How a declared statement is checked and lowered (see :func:`declared`)."""

    rule: str
    runtime: str
    places: frozenset[str]
    misplaced: str
    hint: str | None
    parts: tuple[tuple[str, Part], ...]


#: Each declared statement's node class -> its declaration.
DECLARED: dict[type, Declaration] = {}


@node
class Declared(Node):
    """Base of the declared statements (compiler/rules/declared.py is the rule of them all)."""


def declared(
    rule: str,
    runtime: str,
    places: frozenset[str] = PLACES,
    misplaced: str = "",
    hint: str | None = None,
    *,
    statement: str,
) -> Callable[[type], type]:
    """Declare a statement: register the node class it decorates (and its :func:`syntax`).

    Parameters
    ----------
    rule : str
        The grammar rule whose children, keywords dropped, are the node's
        parts in order.
    runtime : str
        The ``Runtime`` method (runtime/host.py) the statement lowers to,
        called with the parts' values (a ``many`` part as a tuple) and the
        statement's position index.
    places : frozenset of str
        Where it may stand, a subset of :data:`PLACES`.
    misplaced, hint : str
        The error (and its hint) where it stands elsewhere.
    statement : str
        The rule's production (see :func:`syntax`).
    """
    assert places <= PLACES and (places == PLACES or misplaced), rule

    def register(cls: type) -> type:
        parts = tuple((f.name, f.metadata["part"]) for f in fields(cls) if f.name != "pos")
        # Only the last part may take the rest of the children.
        assert all(not p.many for _, p in parts[:-1]), cls.__name__
        DECLARED[cls] = Declaration(rule, runtime, places, misplaced, hint, parts)
        return syntax(rule, statement=statement)(cls)

    return register


@declared("view_point", "set_view_point", statement='VIEW POINT "=" expr')
@node
class ViewPoint(Declared):
    point: Node = part(Type.VECTOR, what="a view point (x, y, z)")


@declared("view_width", "set_view_width", statement='VIEW WIDTH_KW "=" expr')
@node
class ViewWidth(Declared):
    width: Node = part(*NUMBER, what="a view width")


@declared(
    "shoot_stmt",
    "shoot",
    frozenset({"top"}),
    "SHOOTSCENES belongs outside scenes and primitives",
    statement="SHOOTSCENES",
)
@node
class Shoot(Declared):
    pass


# SHOOTSCENES FROM a TO b (not in the thesis; see docs/language.md 4.9): only scenes a to b.
# A Shoot, so that a library refuses it and an archive leaves it out as it does SHOOTSCENES.
@declared(
    "shoot_range",
    "shoot_range",
    frozenset({"top"}),
    "SHOOTSCENES belongs outside scenes and primitives",
    statement="SHOOTSCENES FROM expr TO expr",
)
@node
class ShootRange(Shoot):
    first: Node = part(Type.INTEGER, what="the first scene to shoot")
    last: Node = part(Type.INTEGER, what="the last scene to shoot")


@syntax("stop_stmt", statement="STOP")
@node
class Stop(Node):
    pass


@syntax("return_stmt", statement="RETURN")
@node
class Return(Node):
    pass


@syntax("program_end")
@node
class ProgramEnd(Node):
    pass


# Inside a PRIMITIVE: DRAW WITH <LIGHTNESS l> (or <COLOUR (r, g, b)>) and DRAW POLY FROM (p) TO (q) ...
@syntax(
    "draw_with",
    statement="DRAW WITH modlist",
    pos=R.through("modifiers"),
    modifiers=R.value(convert=lambda mods: mods[1:-1]),
)
@node
class DrawWith(Node):
    modifiers: list


@syntax("draw_poly", statement="DRAW POLY FROM expr (TO expr)+", points=R.rest())
@node
class DrawPoly(Node):
    points: list


# LOAD 'library'  or  LOAD NAME, NAME FROM 'library' (see docs/language.md)
R.produce("_load_name", "NAME | PRIM_NAME")


@syntax(
    "load_stmt",
    statement='LOAD STRING | LOAD _load_name ("," _load_name)* FROM STRING',
    library=R.token("STRING", R.UNQUOTE),
    library_pos=R.token("STRING", R.POS),
    names=R.token(("NAME", "PRIM_NAME"), AS_NAME, many=True),
)
@node
class Load(Node):
    library: str  # as written, without its quotes
    library_pos: Pos
    names: list  # of Name; empty means the library's models, motions, graphics and primitives


@syntax("pat_word", word=R.token("STRING", lambda text: text[1:-1].strip().upper()))
@node
class PatWord(Node):
    word: str


@syntax("pat_param", name=R.token("NAME", R.UPPER))
@node
class PatParam(Node):
    name: str


# A default of a PRIMITIVE's optional part: (its parameter's Name, the expression).
value_rule("pat_default", R.token("NAME", AS_NAME), R.value())


@syntax("pat_optional", defaults=R.rest())
@node
class PatOptional(Node):
    items: list
    defaults: list  # of (Name, expr)


@syntax("pattern_def", name=R.token(("NAME", "PRIM_NAME"), R.UPPER))
@node
class PatternDef(Node):
    name: str
    items: list


@syntax("primitive_def", name=R.token(("NAME", "PRIM_NAME"), AS_NAME), pattern=R.find(PatternDef))
@node
class PrimitiveDef(Node):
    name: Name
    body: list = field(metadata=read(R.rest(), holds=True))
    pattern: PatternDef | None = None


@node
class Program(Node):
    filename: str
    source: str
    body: list
    primitives: list = field(default_factory=list)
