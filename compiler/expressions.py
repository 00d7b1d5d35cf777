"""Expression typing: the type of every expression, and the errors of ill-typed ones.

:class:`ExpressionTyper` returns each expression's type (None where an
error already made it unknown) and records it in ``State.types`` for the
lowering. Operators are typed from the table in ``lang/vocabulary.py``
(:data:`~liganimate.lang.vocabulary.OPERATORS`); what is left here is how a
refused combination is explained.
"""

from __future__ import annotations

from liganimate.lang import ast as A
from liganimate.lang import numbers
from liganimate.lang.diagnostics import did_you_mean
from liganimate.lang.visitor import NodeVisitor
from liganimate.lang.vocabulary import MODIFIERS, NUMBER, operators_for

from . import types as T
from .scopes import State, animated_here, unknown


def expr_type(types: dict, e) -> T.Type | None:
    """The type the checker settled for expression ``e`` (``types`` is :attr:`Checked.types`).

    Literals are not in the table: a literal's type follows from its value.
    """
    if type(e) is A.Num:
        return T.INTEGER if isinstance(e.value, int) else T.REAL
    return types.get(id(e))


def const(e):
    """The value of a constant expression (a literal, negated any number of times), or None.

    Every check that looks at a constant goes through here and uses the value
    it returns, never the node's own fields: ``-1`` is a ``Neg`` node, not a
    literal.  A literal out of range is reported elsewhere (None here).
    """
    sign = 1
    while isinstance(e, A.Neg):  # a loop, not recursion: the minus signs may be many
        sign, e = -sign, e.operand
    if isinstance(e, A.Num) and not isinstance(e.value, numbers.BadLiteral):
        return e.value if sign > 0 else -e.value
    return None


def fmt(x) -> str:
    """A number as messages show it."""
    return f"{x:g}" if isinstance(x, float) else str(x)


class ExpressionTyper(NodeVisitor):
    """``_e_<Node>(expr)`` returns the type of an expression (see :class:`~liganimate.lang.visitor.NodeVisitor`)."""

    def __init__(self, state: State):
        self.st = state

    # ------------------------------------------------------------ wants
    def want(self, e, t: T.Type, what: str) -> None:
        """Type ``e`` and report it unless it fits a ``t`` (an INTEGER fits a REAL)."""
        got = self.expr(e)
        if got is None:
            return
        if not T.fits(t, got):
            if t == T.INTEGER and got == T.REAL:
                self.st.out.error(e, f"{what} must be an INTEGER; this is a REAL", "use INT(...) or NINT(...)")
            else:
                self.st.out.error(e, f"{what} must be {T.NOUN[t]}, not {T.NOUN[got]}")

    def want_number(self, e, what: str) -> None:
        """Type ``e`` and report it unless it is a number."""
        got = self.expr(e)
        if got is not None and not T.is_numeric(got):
            self.st.out.error(e, f"{what} must be a number, not {T.NOUN[got]}")

    def want_var(self, name: A.Name, t: T.Type, what: str | None = None) -> None:
        """``name`` must be a variable of type ``t`` (a statement naming a MODEL, say)."""
        got = self.st.scope.types.get(name.name)
        if got is None:
            unknown(self.st, name)
        elif got != t:
            self.st.out.error(
                name,
                what + f"; {name.name} is {T.NOUN[got]}"
                if what
                else f"{name.name} is {T.NOUN[got]}, but {T.NOUN[t]} is needed here",
            )

    # ------------------------------------------------------ expressions
    def expr(self, e):
        """The type of ``e`` (None if unknown after an error), recorded for the lowering."""
        t = self.dispatch("_e_", e, generic=False)(e)
        # A literal's type is its value's (expr_type): most nodes of a big
        # program are literals, and an entry each cost ~80 bytes a line.
        if type(e) is not A.Num:
            self.st.types[id(e)] = t
        return t

    def _e_Num(self, e):
        problem = numbers.literal_problem(e.value)
        if problem is not None:
            self.st.out.error(e, *problem)
        return T.INTEGER if isinstance(e.value, int) else T.REAL

    def _e_Var(self, e):
        t = self.st.scope.types.get(e.name)
        if t is None:
            if e.name in self.st.signatures:
                self.st.out.error(
                    e, f"{e.name} is a primitive: call it with its keywords", self.st.signatures[e.name].usage()
                )
            else:
                unknown(self.st, e)
        return t

    def _e_Tuple(self, e):
        ts = [self.expr(i) for i in e.items]
        for i, t in zip(e.items, ts):
            if t is not None and not T.is_numeric(t):
                self.st.out.error(i, f"a vector's components are numbers, not {T.NOUN[t]}")
        if len(e.items) == 3:
            return T.VECTOR
        if len(e.items) == 2:
            return T.PAIR
        self.st.out.error(e, f"a vector has three components, not {len(e.items)}")
        return None

    def _e_Neg(self, e):
        t = self.expr(e.operand)
        if t is None:
            return None
        if t in (T.INTEGER, T.REAL, T.VECTOR):
            return t
        self.st.out.error(e, f"cannot negate {T.NOUN[t]}")
        return None

    def _e_BinOp(self, e):
        lt, rt = self.expr(e.left), self.expr(e.right)
        if lt is None or rt is None:
            return None
        for row in operators_for(e.op, lt, rt):
            if row.animated and not all(
                t == T.GRAPHICAL or animated_here(self.st, side) for t, side in ((lt, e.left), (rt, e.right))
            ):
                continue  # a model not ANIMATEd in this scene has no pose to draw
            return T.numeric_join(lt, rt) if row.result is None else row.result
        self._refuse(e, lt, rt)
        return None

    def _refuse(self, e, lt: T.Type, rt: T.Type) -> None:
        """Explain why no row of the operator table takes these operands."""
        op, out = e.op, self.st.out
        if op in ("+", "-"):
            if op == "+" and lt == rt == T.MODEL:
                out.error(
                    e,
                    "models are combined with JOINT, not +",
                    "a :- JOINT id, a, (x, y, z), b, (x, y, z), (min, max), ...",
                )
                return
            verb, prep = ("add", "to") if op == "+" else ("subtract", "from")
            out.error(e, f"cannot {verb} {T.NOUN[rt]} {prep} {T.NOUN[lt]}")
        elif op == "*":
            if rt == T.MOTION and lt == T.REAL:
                out.error(
                    e.left,
                    "a repetition count must be an INTEGER, not a REAL",
                    "write a whole number such as 3 * walk, or use NINT(...)",
                )
            elif lt == T.MOTION and T.is_numeric(rt):
                out.error(e, "the repetition count comes first: write n * motion")
            else:
                out.error(e, f"cannot multiply {T.NOUN[lt]} by {T.NOUN[rt]}")
        elif op == "/":
            out.error(e, f"cannot divide {T.NOUN[lt]} by {T.NOUN[rt]}")
        elif op == "MOD":
            out.error(e, "MOD works on numbers")
        else:
            raise AssertionError(op)

    def _e_Call(self, e):
        spec = T.BUILTINS.get(e.name)
        ts = [self.expr(a) for a in e.args]
        if spec is None:
            hint = did_you_mean(e.name, T.BUILTINS)
            self.st.out.error(
                e, f"{e.name} is not a function", hint or "the functions are " + ", ".join(sorted(T.BUILTINS))
            )
            return None
        params, result = spec.params, spec.result
        if len(params) != len(e.args):
            plural = "s" if len(params) != 1 else ""
            self.st.out.error(e, f"{e.name} takes {len(params)} argument{plural}, not {len(e.args)}")
            return None
        for a, t, p in zip(e.args, ts, params):
            if t is None:
                return None
            if t not in p:
                wanted = "a number" if p == NUMBER else T.NOUN[p[0]]
                self.st.out.error(a, f"{e.name} needs {wanted} here, not {T.NOUN[t]}")
                return None
        if result is None:
            return T.numeric_join(*ts) if len(ts) == 2 else ts[0]
        return result

    def _e_Modified(self, e):
        t = self.expr(e.target)
        if t is None:
            for m in e.modifiers:
                self.expr(m.arg)
            return None
        for m in e.modifiers:
            at = self.expr(m.arg)
            spec = MODIFIERS[m.kind]
            if t not in spec.targets:
                self.st.out.error(m, f"{spec.label} applies to {spec.targets_noun}; this is {T.NOUN[t]}")
                continue
            if at is None:
                continue
            if at not in spec.accepts:
                self.st.out.error(m.arg, f"{spec.label} needs {spec.accepts_noun}, not {T.NOUN[at]}")
            if spec.nonzero and const(m.arg) == 0:
                self.st.out.error(m.arg, f"{spec.label} 0 would collapse it to nothing")
        return t

    def _e_PrimCall(self, e):
        sig = self.st.signatures.get(e.name)
        for c in e.clauses:
            self.expr(c.value)
        if sig is None:  # pragma: no cover - the lexer only makes PRIM_NAME for known names
            self.st.out.error(e, f"{e.name} is not a primitive")
            return None
        for node, message, hint in sig.match(e):
            self.st.out.error(node, message, hint)
        for c in e.clauses:
            ptype = sig.param_types.get(c.keyword)
            t = expr_type(self.st.types, c.value)
            if t is None or ptype is None:
                continue
            if not T.fits(ptype, t):
                self.st.out.error(
                    c.value,
                    f"{e.name} {c.keyword} needs {T.NOUN.get(ptype, ptype)}, not {T.NOUN[t]}",
                    f"put the {e.name} call in parentheses to apply <...> or + to the whole object"
                    if t == T.GRAPHICAL
                    else None,
                )
        return T.GRAPHICAL

    def _e_JointExpr(self, e):
        self.joint_args(e.args, e, in_block=False)
        return T.MODEL

    def _e_Strip(self, e):
        t = self.expr(e.motion)
        if t is not None and t != T.MOTION:
            self.st.out.error(e.motion, f"STRIP takes a MOTION first, not {T.NOUN[t]}")
        for j in e.joints:
            self.want(j, T.INTEGER, "a joint identifier")
        return T.MOTION

    def _e_Sync(self, e):
        for m in e.motions:
            t = self.expr(m)
            if t is not None and t != T.MOTION:
                self.st.out.error(m, f"SYNCHRONIZE takes MOTIONs, not {T.NOUN[t]}")
        return T.MOTION

    # ------------------------------------------------------------ joints
    def joint_args(self, args: list, node, in_block: bool) -> None:
        """The values of a JOINT (an expression, or a line of a STARTMODEL block)."""
        if node.axis is not None:
            self.want(node.axis, T.VECTOR, "an axis (x, y, z)")
        if len(args) < 6 or len(args) > 8:
            self.st.out.error(
                node,
                f"JOINT takes an identifier, a primary segment and its location, a secondary segment "
                f"and its location, and one to three extreme pairs: {len(args)} values given",
                "JOINT id, primary, (x, y, z), secondary, (x, y, z), [SLIDE] (min, max), (min, max), (min, max)",
            )
            for a in args:
                self.expr(a)
            return
        self.want(args[0], T.INTEGER, "a joint identifier")
        if in_block and not isinstance(args[1], A.Var):
            self.st.out.error(args[1], "inside STARTMODEL the primary segment must be the name of a GRAPHICAL object")
        self._segment(args[1], "primary", in_block)
        self.want(args[2], T.VECTOR, "a location (x, y, z)")
        self._segment(args[3], "secondary", False)
        self.want(args[4], T.VECTOR, "a location (x, y, z)")
        for ext in args[5:]:
            self._extremes(ext)

    def _extremes(self, ext) -> None:
        t = self.expr(ext)
        if t is not None and t != T.PAIR:
            self.st.out.error(ext, f"joint extremes are pairs (min, max), not {T.NOUN[t]}")
        elif isinstance(ext, A.Tuple) and len(ext.items) == 2:
            lo, hi = (const(i) for i in ext.items)
            if lo is not None and hi is not None and lo > hi:
                self.st.out.error(
                    ext,
                    f"these extremes have a minimum ({fmt(lo)}) above the maximum ({fmt(hi)})",
                    f"write ({fmt(hi)}, {fmt(lo)})",
                )

    def _segment(self, e, role: str, in_block: bool) -> None:
        if in_block and role == "primary" and isinstance(e, A.Var):
            t = self.st.scope.types.get(e.name)
            if t is None:
                unknown(self.st, e)
            elif t != T.GRAPHICAL:
                self.st.out.error(
                    e, f"inside STARTMODEL the primary segment must be a GRAPHICAL object; {e.name} is {T.NOUN[t]}"
                )
            self.st.types[id(e)] = t
            return
        t = self.expr(e)
        if t is not None and t not in (T.GRAPHICAL, T.MODEL):
            self.st.out.error(e, f"a {role} segment is a GRAPHICAL object or a MODEL, not {T.NOUN[t]}")

    # -------------------------------------------------------- conditions
    def cond(self, c) -> None:
        """Type a condition (IF): comparisons of numbers, = and <> of vectors."""
        if isinstance(c, A.BoolOp):
            self.cond(c.left)
            self.cond(c.right)
        elif isinstance(c, A.Not):
            self.cond(c.operand)
        else:
            lt, rt = self.expr(c.left), self.expr(c.right)
            if lt is None or rt is None:
                return
            if c.op in ("=", "<>", "/=") and lt == rt == T.VECTOR:
                return
            if not (T.is_numeric(lt) and T.is_numeric(rt)):
                self.st.out.error(
                    c,
                    f"cannot compare {T.NOUN[lt]} with {T.NOUN[rt]}",
                    "comparisons work on numbers (and = or <> on vectors)",
                )
