"""The Lark transformer: one method per grammar rule, producing :mod:`.ast` nodes.

It runs inside the LALR parser (Lark's ``transformer=`` option), so the tree
is built bottom-up in the parser's own loop, without recursion and without
an intermediate parse tree.
"""

from __future__ import annotations

from lark import Token, Transformer

from . import ast as A
from .lexer import Tok
from .numbers import literal
from .vocabulary import MODIFIERS, OPERATORS, Type

#: What a terminal is in the children: our parser's Tok, or a Token from Lark's own loop.
TOKENS = (Token, Tok)


def _tpos(tok: Token | Tok) -> A.Pos:
    if type(tok) is Tok:
        return A.token_pos(tok[3], tok[4], tok[5], tok[2], tok[6])
    # Lark types a Token's positions Optional, as a Token may be made without
    # them; the Tokens that reach here come from Lark's own lexer (in the
    # stock reference parser the tests compare with), which sets them all.
    return A.Pos(tok.line, tok.column, tok.end_line, tok.end_column, tok.start_pos, tok.end_pos)  # type: ignore[arg-type]


def _pos_of(x) -> A.Pos | None:
    if isinstance(x, TOKENS):
        return _tpos(x)
    if isinstance(x, A.Node):
        return x.pos
    if isinstance(x, list):
        for item in x:
            p = _pos_of(item)
            if p is not None:
                return p
    return None


def _last_pos_of(x) -> A.Pos | None:
    if isinstance(x, list):
        for item in reversed(x):
            p = _last_pos_of(item)
            if p is not None:
                return p
        return None
    return _pos_of(x)


def span(children) -> A.Pos:
    """The span covering all positioned children."""
    # The usual shapes first: a token or a node at each end.
    if children:
        first, last = children[0], children[-1]
        if type(first) is Tok:
            start = A.token_pos(first[3], first[4], first[5], first[2], first[6])
        elif isinstance(first, A.Node):
            start = first.pos
        else:
            start = None
        if start is not None:
            if type(last) is Tok:
                return start.to(A.token_pos(last[3], last[4], last[5], last[2], last[6]))
            if isinstance(last, A.Node):
                return start.to(last.pos)
    first = _pos_of(children)
    if first is None:
        return A.NOWHERE
    last = _last_pos_of(children)
    assert last is not None  # the scan from the front found a position, so the one from the back does
    return first.to(last)


def _offsets(tok: Token | Tok) -> tuple[int, int]:
    """The character offsets (start, end) of a token."""
    if type(tok) is Tok:
        return tok[2], tok[6]
    return tok.start_pos, tok.end_pos  # type: ignore[return-value]  # set by both lexers, as in _tpos


def _enclosed(pos: A.Pos, first: Token | Tok, last: Token | Tok) -> A.Pos:
    """``pos`` with its text widened from ``first``'s start to ``last``'s end; its caret stays."""
    return pos.widened(_offsets(first)[0], _offsets(last)[1])


def _nodes(children):
    """Children that are values (nodes or lists), dropping keyword tokens."""
    return [c for c in children if not isinstance(c, TOKENS)]


#: One string per distinct upper-cased name: a million ``X = 1`` lines share one "X".
_NAMES: dict = {}


def upper_name(text: str) -> str:
    """``text`` upper-cased, the same string object for every spelling of one name."""
    name = _NAMES.get(text)
    if name is None:
        name = text.upper()
        if len(_NAMES) < 1 << 16:  # a bound, for programs of endless distinct names
            name = _NAMES.setdefault(name, name)
            _NAMES[text] = name
    return name


def _name(tok: Token) -> A.Name:
    return A.Name(_tpos(tok), upper_name(tok.value))


def _number(tok: Token) -> A.Num:
    # lang/numbers.py decides what a literal means; one outside the
    # language's numbers comes back marked, and the checker reports it.
    return A.Num(_tpos(tok), literal(tok.value.rstrip("°")), tok.value)


class ToAst(Transformer):
    """Builds the syntax tree; method names are the grammar's rule names and aliases."""

    # ------------------------------------------------------------ program
    def start(self, children):
        return [c for c in children if not isinstance(c, TOKENS)]

    def program_end(self, children):
        return A.ProgramEnd(span(children))

    # --------------------------------------------------------- statements
    def declaration(self, children):
        kw = children[0]
        return A.Decl(span(children), Type(upper_name(kw.value)), _nodes(children))

    def decl_name(self, children):
        return _name(children[0])

    def assignment(self, children):
        target, op, value = children
        return A.Assign(span(children), _name(target), op.value, value)

    def keyframe_assign(self, children):
        target, joint, index, op, keyframe = children
        return A.KeyframeAssign(span(children), _name(target), joint, index, op.value, keyframe)

    def keyframe(self, children):
        rest = _nodes(children)
        frame, position = rest[0], rest[1]
        method = rest[2] if len(rest) > 2 else None
        return A.Keyframe(span(children), frame, position, method)

    def position(self, children):
        return list(children)

    # ------------------------------------------------------------- REACH
    def reach_block(self, children):
        name, model, frames = _name(children[1]), children[3], children[5]
        method = start = None
        items = []
        i = 6
        while i < len(children):
            c = children[i]
            if isinstance(c, A.Name) and method is None and not items and start is None:
                method = c
            elif isinstance(c, TOKENS) and c.type == "FROM":
                start = children[i + 1]
                i += 1
            elif isinstance(c, tuple) and not isinstance(c, Tok):  # a reach item (a Tok is a tuple too)
                items.append(c)
            i += 1
        block = A.ReachBlock(span(children), name, model, frames, method, start, [])
        for word, pos, value in items:
            block.options.setdefault(word, []).append(pos)
            if word == "GOAL":
                block.goals.append(value)
            elif word == "MOVE JOINTS":
                block.joints = value
            elif word == "MOVE CHAIN":
                block.chain = value
            elif word == "TRANSLATE":
                block.translate = value
            elif word == "SOLVER":
                block.solver = value
            elif word == "TOLERANCE":
                block.tolerance = value
            elif word == "ITERATIONS":
                block.iterations = value
        return block

    def reach_goal(self, children):
        link, spec = children[1], children[2]
        kind, point, target, normal = spec
        weight = children[4] if len(children) > 3 else None
        last = max(
            (n for n in (weight, target, normal) if n is not None), key=lambda n: (n.pos.end_line, n.pos.end_column)
        )
        goal = A.Goal(
            _tpos(children[0]).to(last.pos),
            kind,
            link if isinstance(link, A.Name) else None,
            None if isinstance(link, A.Name) else link,
            point,
            target,
            normal,
            weight,
        )
        return ("GOAL", goal.pos, goal)

    def goal_link(self, children):
        if len(children) == 1:
            return _name(children[0])
        return _number(children[1])

    def goal_point(self, children):
        point = children[1] if len(children) == 4 else None
        return ("point", point, children[-1], None)

    def goal_plane(self, children):
        point = children[1] if len(children) == 7 else None
        return ("plane", point, children[-3], children[-1])

    def goal_axis(self, children):
        return ("axis", None, children[3], children[1])

    def reach_move_joints(self, children):
        return ("MOVE JOINTS", span(children), [c for c in children[2:] if not isinstance(c, TOKENS)])

    def reach_move_chain(self, children):
        return ("MOVE CHAIN", span(children), children[2])

    def reach_translate(self, children):
        return ("TRANSLATE", span(children), _name(children[2]))

    def reach_solver(self, children):
        return ("SOLVER", span(children), _name(children[1]))

    def reach_tolerance(self, children):
        return ("TOLERANCE", span(children), children[1])

    def reach_iterations(self, children):
        return ("ITERATIONS", span(children), children[1])

    def interpolate(self, children):
        return _name(children[1])

    def do_stmt(self, children):
        label = _number(children[1])
        var = _name(children[2])
        exprs = children[3:]
        step = exprs[2] if len(exprs) > 2 else None
        return A.DoHeader(span(children), label.value, var, exprs[0], exprs[1], step)

    def continue_stmt(self, children):
        label = _number(children[0])
        return A.Continue(span(children), label.value)

    def if_stmt(self, children):
        cond = children[1]
        branches = [c for c in children[3:] if not isinstance(c, TOKENS)]
        then = branches[0] if isinstance(branches[0], list) else [branches[0]]
        orelse = None
        if len(branches) > 1:
            orelse = branches[1] if isinstance(branches[1], list) else [branches[1]]
        return A.If(span(children), cond, then, orelse)

    def block(self, children):
        return _nodes(children)

    def model_block(self, children):
        return A.ModelBlock(span(children), _name(children[1]), _nodes(children[2:]))

    def joint_stmt(self, children):
        args, slide, axis = children[1]
        return A.JointStmt(span(children), args, slide, axis)

    def motion_block(self, children):
        items = _nodes(children[2:])
        joints = [c for c in items if not isinstance(c, A.MotionTable)]
        tables = [c for c in items if isinstance(c, A.MotionTable)]
        return A.MotionBlock(span(children), _name(children[1]), joints, tables)

    def motion_table(self, children):
        rows = children[-1]
        columns = [c for c in children[1:-1] if not isinstance(c, TOKENS)]
        return A.MotionTable(span(children), columns, rows.value, _tpos(rows))

    def table_column(self, children):
        return children[0]

    def root_track(self, children):
        return A.RootTrack(_tpos(children[0]), len(children) > 1)

    def motion_joint(self, children):
        joint = children[1]
        start = None
        keyframes = []
        i = 2
        while i < len(children):
            c = children[i]
            if isinstance(c, TOKENS) and c.type == "POSITION":
                start = children[i + 1]
                i += 2
                continue
            if isinstance(c, A.Keyframe):
                keyframes.append(c)
            i += 1
        return A.MotionJoint(span(children), joint, start, keyframes)

    def motion_root(self, children):
        joint = A.MotionJoint(span(children), children[0], None, [])
        rest = self.motion_joint([children[0], None] + list(children[1:]))
        joint.start, joint.keyframes = rest.start, rest.keyframes
        return joint

    def motion_morph(self, children):
        track = A.MorphTrack(span(children[:3]), upper_name(children[0].value), upper_name(children[2].value))
        joint = A.MotionJoint(span(children), track, None, [])
        rest = self.motion_joint([children[0], None] + list(children[3:]))
        joint.start, joint.keyframes = rest.start, rest.keyframes
        return joint

    def figure_stmt(self, children):
        model = _name(children[1])
        if len(children) <= 3:
            return A.FigureStmt(span(children), model, None)
        kind = children[3].type
        if kind == "LINK":
            return A.FigureStmt(span(children), model, "LINK", link=_name(children[4]))
        return A.FigureStmt(span(children), model, "JOINT", joint=children[4])

    def scene_block(self, children):
        at = next(i for i, c in enumerate(children) if isinstance(c, TOKENS) and c.type == "STARTSCENE")
        init = _nodes(children[3:at])
        length = children[at + 2]
        rest = at + 3
        sameframe = None
        if rest < len(children) and isinstance(children[rest], TOKENS) and children[rest].type == "SAMEFRAME":
            sameframe = children[rest + 1]
            rest += 2
        body = _nodes(children[rest:])
        return A.Scene(span(children), children[2], init, length, sameframe, body, span(children[:3]))

    def animate_stmt(self, children):
        repeat = isinstance(children[-1], TOKENS) and children[-1].type == "REPEAT"
        return A.Animate(span(children), _name(children[1]), children[3], children[5], children[7], repeat)

    def background_stmt(self, children):
        return A.Background(span(children), _nodes(children))

    def print_stmt(self, children):
        items = []
        for c in children[1:]:
            if isinstance(c, A.PrintItem):
                items.append(c)
            else:
                items.append(A.PrintItem(c.pos, "value", c))
        return A.Print(span(children), items)

    def print_table(self, children):
        tok = children[0]
        pos = _tpos(tok)
        return A.PrintItem(
            pos,
            "table",
            A.Name(
                A.Pos(pos.line, pos.column + 1, pos.end_line, pos.end_column, pos.start + 1, pos.end),
                tok.value[1:].upper(),
            ),
        )

    def print_text(self, children):
        tok = children[0]
        return A.PrintItem(_tpos(tok), "text", tok.value[1:-1])

    def load_stmt(self, children):
        lib = children[-1]
        names = [_name(t) for t in children[1:-1] if t.type in ("NAME", "PRIM_NAME")]
        return A.Load(span(children), lib.value[1:-1], _tpos(lib), names)

    def stop_stmt(self, children):
        return A.Stop(span(children))

    def return_stmt(self, children):
        return A.Return(span(children))

    def draw_with(self, children):
        draw, with_, (_lt, *mods, _gt) = children
        return A.DrawWith(span([draw, with_, mods]), mods)

    def draw_poly(self, children):
        return A.DrawPoly(span(children), _nodes(children))

    # --------------------------------------------------------- primitives
    def primitive_def(self, children):
        name = _name(children[1])
        body, pattern = [], None
        for c in children[2:]:
            if isinstance(c, TOKENS):
                continue
            if isinstance(c, A.PatternDef):
                pattern = c if pattern is None else pattern
                body.append(c)
            else:
                body.append(c)
        return A.PrimitiveDef(span(children), name, body, pattern)

    def pattern_def(self, children):
        return A.PatternDef(span(children), upper_name(children[0].value), children[1])

    def pattern(self, children):
        return list(children)

    def pat_word(self, children):
        tok = children[0]
        return A.PatWord(_tpos(tok), tok.value[1:-1].strip().upper())

    def pat_param(self, children):
        tok = children[0]
        return A.PatParam(_tpos(tok), upper_name(tok.value))

    def pat_optional(self, children):
        return A.PatOptional(span(children), children[0], list(children[1:]))

    def pat_default(self, children):
        return (_name(children[0]), children[1])

    # -------------------------------------------------------- expressions
    def joint_expr(self, children):
        args, slide, axis = children[1]
        return A.JointExpr(span(children), args, slide, axis)

    def joint_args(self, children):
        # (the expressions, whether SLIDE was written, the AXIS expression or None)
        slide = any(type(c) is Tok and c[0] == "SLIDE" for c in children)
        axis = children[-1][1] if children and type(children[-1]) is tuple else None  # from joint_axis
        return [c for c in children if isinstance(c, A.Node)], slide, axis

    def joint_axis(self, children):
        return ("AXIS", children[1])

    def strip_expr(self, children):
        return A.Strip(span(children), children[1], list(children[2:]))

    def sync_expr(self, children):
        return A.Sync(span(children), list(children[1:]))

    def neg(self, children):
        minus, operand = children
        # The caret stays on the operand, as it always has; the text takes the sign.
        return A.Neg(operand.pos.widened(_offsets(minus)[0], operand.pos.end), operand)

    def plus(self, children):
        sign, operand = children
        operand.pos = operand.pos.widened(_offsets(sign)[0], operand.pos.end)
        return operand

    def paren(self, children):
        # (A + B) is the node A + B: its caret stays inside, its text takes the
        # parentheses, so that an enclosing span and a PRINT label keep them.
        lpar, node, rpar = children
        node.pos = _enclosed(node.pos, lpar, rpar)
        return node

    def modified(self, children):
        target, (_lt, *mods, gt) = children
        # The caret ends at the last modifier, as it always has; the text at ">".
        pos = span([target, mods]).widened(target.pos.start, _offsets(gt)[1])
        if isinstance(target, A.Modified):
            # The parser hands the chain so far to nothing else: extend it in
            # place, so that a chain of n lists costs n steps, not n*n copies.
            target.modifiers.extend(mods)
            target.pos = pos
            return target
        return A.Modified(pos, target, mods)

    def number(self, children):
        return _number(children[0])

    def var(self, children):
        tok = children[0]
        return A.Var(_tpos(tok), upper_name(tok.value))

    def call(self, children):
        tok, args, rpar = children[0], children[2:-1], children[-1]
        return A.Call(_enclosed(span([tok, *args]), tok, rpar), upper_name(tok.value), args)

    def tuple(self, children):
        items = children[1:-1]
        return A.Tuple(_enclosed(span(items), children[0], children[-1]), items)

    def prim_call(self, children):
        tok = children[0]
        return A.PrimCall(span(children), upper_name(tok.value), list(children[1:]))

    def prim_clause(self, children):
        tok, value = children
        return A.Clause(span(children), upper_name(tok.value), value)

    def modlist(self, children):
        return list(children)  # "<", the modifiers, ">": its user takes the ">" for its text

    # --------------------------------------------------------- conditions
    def cond_or(self, children):
        return A.BoolOp(span(children), "OR", children[0], children[2])

    def cond_and(self, children):
        return A.BoolOp(span(children), "AND", children[0], children[2])

    def cond_not(self, children):
        return A.Not(span(children), children[1])

    def compare(self, children):
        left, op, right = children
        return A.Compare(span(children), op.value, left, right)

    def cond_group(self, children):
        return self.paren(children)


def _modifier_rule(kind: str, axis: bool):
    """The transformer method of the grammar alternative ``-> mod_<kind>``: its argument is its last child."""

    def rule(self, children):
        return A.Modifier(span(children), kind, children[-1], upper_name(children[1].value) if axis else None)

    rule.__name__ = "mod_" + kind
    return rule


# One method per modifier of lang/vocabulary.py: a new modifier needs no code here.
for _spec in MODIFIERS.values():
    setattr(ToAst, "mod_" + _spec.kind, _modifier_rule(_spec.kind, _spec.axis))


def _operator_rule(rule_name: str, symbol: str):
    """The transformer method of ``left <op> right -> <rule_name>``.

    An operator the grammar names as a terminal (``DIV_OP``, ``MOD``) is
    kept as a child: its position is where a division by zero points.
    """

    def rule(self, children):
        if len(children) == 3:
            left, op, right = children
            return A.BinOp(span(children), symbol, left, right, _tpos(op))
        left, right = children
        return A.BinOp(span(children), symbol, left, right)

    rule.__name__ = rule_name
    return rule


# One method per operator of lang/vocabulary.py's table: a new operator needs no code here.
for _op in OPERATORS:
    setattr(ToAst, _op.rule, _operator_rule(_op.rule, _op.symbol))


def _declared_rule(cls: type, declaration: A.Declaration):
    """The transformer method of a declared statement: its children, keywords dropped, are its parts in order."""
    many = bool(declaration.parts) and declaration.parts[-1][1].many
    count = len(declaration.parts)

    def rule(self, children):
        values = _nodes(children)
        if many:
            values = [*values[: count - 1], values[count - 1 :]]
        return cls(span(children), *values)

    rule.__name__ = declaration.rule
    return rule


# One method per declared statement of lang/ast.py: a new one needs no code here.
for _cls, _declaration in A.DECLARED.items():
    setattr(ToAst, _declaration.rule, _declared_rule(_cls, _declaration))
