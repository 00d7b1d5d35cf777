"""Lowering: a checked program becomes the source of a standalone Python module.

The module imports only ``liganimate.runtime.host`` and defines ``program``;
``liganimate run`` executes this very text in memory, and ``liganimate
compile`` writes it to a file, so there is one path to test.

LIG names are upper-cased identifiers, and every name the generator itself
uses contains a lower-case letter or begins with an underscore, so no LIG
name (``CLASS``, ``NONE``, ``SELF``, ``NP``, ``LIGANIMATE``...) can clash with
Python's keywords, builtins or the generated machinery.
"""

from __future__ import annotations

import re

from liganimate import __version__
from liganimate.lang import ast as A
from liganimate.lang import bindings
from liganimate.lang import numbers as N
from liganimate.lang.visitor import NodeVisitor
from liganimate.lang.vocabulary import FUNCTIONS, MODIFIERS, Operator, operators_for

from . import types as T
from .check import Checked, expr_type
from .rules import rule_for

_ZERO = {
    T.INTEGER: "0",
    T.REAL: "0.0",
    T.VECTOR: "rt.ZERO",
    T.GRAPHICAL: "rt.EMPTY",
    T.MOTION: "rt.NO_MOTION",
    T.MODEL: "None",
}

# Inline range tests of + - * results (lang/numbers.py): a chained comparison,
# false for NaN, costs a fraction of a call; only a result out of range calls
# the runtime, which reports it at the operation.
# The bounds are module globals (_lo_I <= x <= _hi_I): a global costs about
# what a constant does, and the generated text stays short.
_BOUND = {T.INTEGER: ("_lo_I", "_hi_I"), T.REAL: ("_lo_R", "_hi_R")}
_BOUND_DEFS = (
    f"_lo_I, _hi_I = {-N.INT_MAX!r}, {N.INT_MAX!r}  # INTEGER range (lang/numbers.py)",
    f"_lo_R, _hi_R = {-N.REAL_MAX!r}, {N.REAL_MAX!r}  # REAL range",
    "",
    "",
    "def _ck(x, kind, at):",
    '    """x, the value of a + - * expression, if it is in range (kind: I or R, and the operator)."""',
    '    if (_lo_I <= x <= _hi_I) if kind[0] == "I" else (_lo_R <= x <= _hi_R):',
    "        return x",
    "    _host.overflow(program, x, kind, at)",
    "",
)
_KIND = {T.INTEGER: "I", T.REAL: "R", T.VECTOR: "V"}
_CHECKED = (T.INTEGER, T.REAL, T.VECTOR)
_ARITH = ("+", "-", "*")

# A program with more top-level statements than this is lowered into many
# functions of about CHUNK_LINES lines, each compiled on its own (see
# Lowerer.main_chunks and runtime/loader.py): CPython needs about 1.5 KB a
# line to compile one function and frees it only at the end.
CHUNK_STATEMENTS = 1000
CHUNK_LINES = 1000
_WORD = re.compile(r"(?<![\w.])[A-Z][A-Z0-9_]*\b")

_CMP = {"=": "==", "<>": "!=", "/=": "!=", "<": "<", ">": ">", "<=": "<=", ">=": ">="}


class Lowerer(NodeVisitor):
    """Emits Python source line by line: a statement's rule (compiler/rules/) emits it, ``e_<Node>`` returns an expression's code."""

    def __init__(self, checked: Checked, module_doc_name: str):
        self.c = checked
        self.lines: list = []
        self.positions: list = []
        self.pos_index: dict = {}
        self.indent = 0
        self.doc_name = module_doc_name
        self.consume = False  # see lower()
        self.canvas = None
        self.tmp = 0
        self.table_spans: list = []  # (start, end) offsets of keyframe-table rows, left out of the embedded source
        # > 0 inside code that runs many times (DO bodies, scene bodies,
        # primitives): there + - * results are range-checked inline, which
        # runs fastest; elsewhere by a call, which CPython compiles several
        # times faster (a conditional expression costs ~40 us to compile).
        self.hot = 0
        prog = checked.program
        # A big main program becomes many functions whose variables are module globals.
        self.chunked = len(prog.body) + len(checked.main.types) > CHUNK_STATEMENTS
        self.main_names = set(checked.main.types)

    # ------------------------------------------------------------- basics
    def at(self, node) -> int:
        # The module keeps lines and columns only (where a runtime error's caret
        # goes); a Pos without its offsets is one int, equal exactly when those
        # four numbers are: the key costs nothing more than the position.
        pos = (node if isinstance(node, A.Pos) else node.pos).without_offsets()
        index = self.pos_index.get(pos)
        if index is None:
            index = self.pos_index[pos] = len(self.positions)
            self.positions.append(pos)
        return index

    def emit(self, text: str) -> None:
        self.lines.append("    " * self.indent + text)

    def type_of(self, e) -> T.Type | None:
        return expr_type(self.c.types, e)

    # ------------------------------------------------------------- module
    def module(self) -> str:
        prog = self.c.program
        head = [
            # No program-derived text goes into comments or docstrings: a name
            # holding a line break would end a comment and start code. The
            # source's name reaches the module only through repr(), as _SOURCE_NAME.
            f"# Generated by liganimate {__version__}. Recompile rather than edit.",
            '"""A LIG ANIMATE program compiled by liganimate; _SOURCE_NAME names its source.',
            "",
            "Render it:  python <this file> -o DIR   (see --help)",
            "Use it:     import it and call program.execute() or program.render(...)",
            '"""',
            "",
            "from liganimate.runtime import host as _host",
            "",
            f"_SOURCE_NAME = {self.doc_name!r}",
            *_BOUND_DEFS,
            "",
        ]
        body_start = len(self.lines)
        for i, lib in enumerate(self.c.libraries):
            # The library's own compiled module travels inside this one, so the
            # generated file stays standalone; it runs once, when first needed.
            names = f", names={lib.names!r}" if lib.names else ""
            self.emit(f"_LIB{i} = _host.Library({lib.display!r}, {lib.python!r}{names})")
        for name, i in sorted(self.c.loaded_primitives.items()):
            self.emit(f"_prim_{name} = _LIB{i}.primitive({name!r})")
        if self.c.libraries:
            self.emit("")
        for _name, (pdef, sig, scope) in sorted(self.c.primitives.items()):
            if pdef is not None:
                self.primitive(pdef, sig, scope)
                self.emit("")
        if self.chunked:
            self.main_chunks(prog.body)
        else:
            self.emit("def _main(rt):")
            self.indent += 1
            self.emit(repr(f"The main program of {self.doc_name}."))
            for name, t in sorted(self.c.main.types.items()):
                self.emit(f"{name} = {_ZERO[t]}")
            self.block(prog.body, "main")
            self.emit("return locals()")
            self.indent -= 1
            self.emit("")
        body = self.lines[body_start:]
        del self.lines[body_start:]
        if len(self.positions) > CHUNK_STATEMENTS:
            # Packed (see host.Program): a tuple literal this long costs CPython seconds and gigabytes.
            packed = " ".join(f"{p.line} {p.column} {p.end_line} {p.end_column}" for p in self.positions)
            positions = [f"_AT = {packed!r}", ""]
        else:
            positions = ["_AT = ("] + [f"    {(p.line, p.column, p.end_line, p.end_column)!r}," for p in self.positions]
            positions += [")", ""]
        tail = [
            "",
            f"program = _host.Program(_SOURCE_NAME, _AT, _main, {self.source_literal()})",
            "",
            'if __name__ == "__main__":',
            "    from liganimate.cli import run_program_cli",
            "",
            "    raise SystemExit(run_program_cli(program))",
            "",
        ]
        return "\n".join(head + positions + body + tail)

    def main_chunks(self, body: list) -> None:
        """Emit the main program of a big program as top-level functions of about CHUNK_LINES lines.

        Its variables are the module's globals, so that every function sees
        them; the functions are split only between top-level statements.
        """
        self.emit("def _variables():")
        self.emit('    """The program variables: LIG names are upper case, generated names are not."""')
        self.emit('    return {k: v for k, v in globals().items() if k.isupper() and not k.startswith("_")}')
        self.emit("")
        chunks: list[str] = []
        start = len(self.lines)
        self.indent += 1
        inits = [f"{name} = {_ZERO[t]}" for name, t in sorted(self.c.main.types.items())]

        def cut(least: int) -> None:
            if len(self.lines) - start >= least:
                # Kept as one string: a million lines cost ~60 bytes each as separate strings.
                chunks.append("\n".join(self.lines[start:]))
                del self.lines[start:]

        for item in inits:
            self.emit(item)
            cut(CHUNK_LINES)
        for i, stmt in enumerate(body):
            rule_for(type(stmt)).lower(self, stmt, "main")
            if self.consume:
                body[i] = stmt = None  # lowered: its part of the tree can go now
            cut(CHUNK_LINES)
        cut(1)
        self.indent -= 1
        # Popped from the end, so each chunk's text is freed once it is in self.lines.
        count = len(chunks)
        chunks.reverse()
        for k in range(count):
            text = chunks.pop()
            self.emit(f"def _main_{k}(rt):")
            # Every upper-case word of the chunk that is a variable: a chunk
            # that assigns one without `global` would make it its own local.
            names = set(_WORD.findall(text)) & self.main_names
            if names:
                self.emit(f"    global {', '.join(sorted(names))}")
            self.lines.append(text)
            self.emit("")
        self.emit("def _main(rt):")
        self.emit("    " + repr(f"The main program of {self.doc_name}."))
        for k in range(count):
            self.emit(f"    _main_{k}(rt)")
        self.emit("    return _variables()")
        self.emit("")

    def source_literal(self) -> str:
        source = self.c.program.source
        if self.table_spans:
            # A keyframe table's rows are data the module already carries; the source kept for
            # diagnostics keeps their lines (so every line number holds) but not their numbers.
            pieces, last = [], 0
            for start, end in sorted(self.table_spans):
                pieces += [source[last:start], "|" + "\n|" * source.count("\n", start, end)]
                last = end
            source = "".join(pieces) + source[last:]
        return repr(source)

    # --------------------------------------------------------- primitives
    def primitive(self, pdef: A.PrimitiveDef, sig, scope) -> None:
        name = pdef.name.name
        params = sig.params
        self.emit(f"def _prim_{name}(rt, {', '.join(p + '=None' for p in params)}):")
        self.indent += 1
        self.emit(repr(f"PRIMITIVE {name}: {sig.usage()}."))
        for p in params:
            self.emit(f"if {p} is None:")
            self.indent += 1
            default = sig.defaults.get(p)
            if default is None:
                self.emit(f"{p} = {_ZERO[scope.types.get(p, T.REAL)]}")
            else:
                code = self.expr(default)
                if (
                    scope.types.get(p) == T.REAL
                    and not isinstance(default, tuple)
                    and self.type_of(default) == T.INTEGER
                ):
                    code = _as_real(default, code)  # a REAL parameter holds a REAL
                self.emit(f"{p} = {code}")
            self.indent -= 1
        for var, t in sorted(scope.types.items()):
            if var not in params:
                self.emit(f"{var} = {_ZERO[t]}")
        self.emit("_g = rt.canvas()")
        self.scope_types = scope.types
        self.hot += 1
        self.block(pdef.body, "primitive")
        self.hot -= 1
        self.emit("return _g.result()")
        self.scope_types = None
        self.indent -= 1

    # --------------------------------------------------------- statements
    def block(self, stmts: list, where: str) -> None:
        start = len(self.lines)
        for s in stmts:
            rule_for(type(s)).lower(self, s, where)
        if len(self.lines) == start:
            self.emit("pass")

    def as_real(self, e, code: str) -> str:
        """Code for an INTEGER expression's value as a REAL (a literal is converted here, once)."""
        return _as_real(e, code)

    def var_type(self, name: str):
        return self.current_scope_types().get(name)

    def current_scope_types(self):
        return self.scope_types if getattr(self, "scope_types", None) is not None else self.c.main.types

    # -------------------------------------------------------- expressions
    def expr(self, e) -> str:
        if isinstance(e, tuple):  # a Python constant default (built-in primitives)
            return repr(e)
        return self.dispatch("e_", e, generic=False)(e)

    def e_Num(self, e):
        return repr(e.value)

    def e_Var(self, e):
        return e.name

    def e_Tuple(self, e):
        items = ", ".join(self.expr(i) for i in e.items)
        if len(e.items) == 3:
            return f"rt.vec({items})"
        return f"({items})"

    def e_Neg(self, e):
        return f"(-{self.expr(e.operand)})"

    def e_BinOp(self, e):
        return self._binop(e, root=True)

    def _binop(self, e, root: bool) -> str:
        t = self.type_of(e)
        if e.op in _ARITH and t in _CHECKED and self._operator(e).runtime is None:
            # A chain of + - * of one type is checked once, at its root: a
            # REAL that overflows stays infinite or NaN through + - *, and
            # INTEGER arithmetic inside an expression is exact (Python ints).
            left, right = self._chained(e.left, t), self._chained(e.right, t)
            text = f"{left} {e.op} {right}"
            if not root:
                return f"({text})"
            single = not (_in_chain(e.left, t, self) or _in_chain(e.right, t, self))
            kind = _KIND[t] + (e.op if single else "")
            if t == T.VECTOR:
                return f"rt.vector_ok({text}, {self.at(e)}, {kind!r})"
            if not self.hot:
                return f"_ck({text}, {kind!r}, {self.at(e)})"
            lo, hi = _BOUND[t]
            return f"(_n if {lo} <= (_n := {text}) <= {hi} else rt.overflow(_n, {kind!r}, {self.at(e)}))"
        row = self._operator(e)
        if row.group_right:
            return self._right_grouped(e, row)
        left, right = self.expr(e.left), self.expr(e.right)
        if row.runtime is None:
            return f"({left} {e.op} {right})"
        # The runtime call checks what Python's operator would not (the triangle limit
        # of a superposition, a division by zero at the operator's position...).
        return f"rt.{row.runtime}({left}, {right}, {self.at(e.op_pos if row.at_operator else e)})"

    def _operator(self, e) -> Operator:
        """The row of the operator table the checker typed ``e`` by (the first that takes its operand types)."""
        return operators_for(e.op, self.type_of(e.left), self.type_of(e.right))[0]

    def _right_grouped(self, e, row: Operator) -> str:
        """``A + B + C`` grouped to the right, as the thesis' BNF
        (``<motion term> + <motion express>``) does; the parser groups it to the left.

        The operator is associative, so this changes no pose; it keeps the listing of
        PRINT and describe() in the thesis' shape.  Operands are still
        evaluated left to right.
        """
        ops = []
        while isinstance(e, A.BinOp) and e.op == row.symbol and self._operator(e) is row:
            ops.append(e)
            e = e.left
        operands = [self.expr(e)] + [self.expr(op.right) for op in reversed(ops)]
        text = operands[-1]
        for operand, op in zip(reversed(operands[:-1]), ops):
            text = f"rt.{row.runtime}({operand}, {text}, {self.at(op)})"
        return text

    def _chained(self, e, t) -> str:
        """An operand inside a checked chain of type ``t``: unchecked if it continues the chain."""
        if isinstance(e, A.BinOp) and _in_chain(e, t, self):
            return self._binop(e, root=False)
        if isinstance(e, A.Neg) and _in_chain(e, t, self):
            return f"(-{self._chained(e.operand, t)})"
        return self.expr(e)

    def e_Call(self, e):
        args = "".join(self.expr(a) + ", " for a in e.args)
        return f"rt.{FUNCTIONS[e.name].runtime}({args}at={self.at(e)})"

    def e_Modified(self, e):
        t = self.type_of(e.target)
        code, at = self.expr(e.target), self.at(e)
        for m in e.modifiers:
            spec = MODIFIERS[m.kind]
            axis = f", {m.axis!r}" if spec.axis else ""
            code = f"rt.{spec.methods[t]}({code}, {self.expr(m.arg)}{axis}, {at})"
        return code

    def e_PrimCall(self, e):
        _, sig, _ = self.c.primitives[e.name]
        given = {c.keyword: c.value for c in e.clauses}
        args = []
        for slot in sig.slots:
            if slot.keyword in given:
                value = given[slot.keyword]
                code = self.expr(value)
                if sig.param_types.get(slot.keyword) == T.REAL and self.type_of(value) == T.INTEGER:
                    code = _as_real(value, code)  # a REAL parameter holds a REAL
                args.append(f"{slot.param}={code}")
        pdef = self.c.primitives[e.name][0]
        own = pdef is not None or e.name in self.c.loaded_primitives
        if own:
            return f"_prim_{e.name}(rt, {', '.join(args)})"
        args.append(f"_at={self.at(e)}")  # a built-in primitive reports its own failures here
        return f"rt.prim_{e.name}(rt, {', '.join(args)})"

    def e_JointExpr(self, e):
        a = e.args
        exts = "".join(self.expr(x) + ", " for x in a[5:])
        return (
            f"rt.joint({self.expr(a[0])}, {self.expr(a[1])}, {self.expr(a[2])}, {self.expr(a[3])}, "
            f"{self.expr(a[4])}, ({exts}), ({bindings.plain_name(a[1])!r}, {bindings.plain_name(a[3])!r}), {self.at(e)}"
            f"{self.joint_kind(e, ', kind=')})"
        )

    def joint_kind(self, j, lead: str) -> str:
        """``lead`` and the (slide, axis) pair of a JOINT that says SLIDE or AXIS; nothing for the thesis' joint."""
        if not j.slide and j.axis is None:
            return ""
        axis = "None" if j.axis is None else self.expr(j.axis)
        return f"{lead}({j.slide!r}, {axis})"

    def e_Strip(self, e):
        joints = "".join(self.expr(j) + ", " for j in e.joints)
        return f"rt.strip({self.expr(e.motion)}, ({joints}), {self.at(e)})"

    def e_Sync(self, e):
        ms = "".join(self.expr(m) + ", " for m in e.motions)
        return f"rt.synchronize(({ms}), {self.at(e)})"

    def cond(self, c) -> str:
        if isinstance(c, A.BoolOp):
            return f"({self.cond(c.left)} {c.op.lower()} {self.cond(c.right)})"
        if isinstance(c, A.Not):
            return f"(not {self.cond(c.operand)})"
        return f"({self.expr(c.left)} {_CMP[c.op]} {self.expr(c.right)})"


def _as_real(e, code: str) -> str:
    """Code for an INTEGER expression's value as a REAL (a literal is converted here, once)."""
    if isinstance(e, A.Num) and not isinstance(e.value, N.BadLiteral):
        return repr(float(e.value))
    return f"float({code})"


def _in_chain(e, t, lowerer) -> bool:
    """Does ``e`` continue a chain of + - * (through unary minus) of type ``t``?"""
    if lowerer.type_of(e) != t:
        return False
    if isinstance(e, A.Neg):
        return _in_chain(e.operand, t, lowerer)
    # Only rows the table computes with Python's own operator chain; a runtime method checks itself.
    return isinstance(e, A.BinOp) and e.op in _ARITH and lowerer._operator(e).runtime is None


def lower(checked: Checked, name: str, consume: bool = False) -> str:
    """Return the Python source of the module for a checked program.

    ``consume=True`` (for a caller that drops ``checked`` at once) lets a
    big main program's statements go as they are lowered, so that the
    syntax tree and the module text are not both whole at the same time.
    """
    lowerer = Lowerer(checked, name)
    lowerer.consume = consume
    return lowerer.module()
