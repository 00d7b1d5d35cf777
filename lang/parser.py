"""Parsing: one cached LALR parser, syntax errors as diagnostics.

:func:`parse` turns source text into a :class:`liganimate.lang.ast.Program`.
The Lark parser is loaded once per process from tables shipped in the
package (:mod:`.tables`); :mod:`.lalr` runs them with the transformer inside,
and every Lark exception becomes a
:class:`~liganimate.lang.diagnostics.LigDiagnostics`.
"""

from __future__ import annotations

import contextvars
import functools
import gc
import re

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from . import ast as A
from . import tables
from .diagnostics import Diagnostic, LigDiagnostics
from .lalr import Driver
from .lexer import LigLexer
from .source import Source, prepare
from .structure import group_blocks
from .transform import ToAst

#: Primitives every program knows without defining them.
BUILTIN_PRIMITIVES = frozenset({"BOX"})

_primitive_names: contextvars.ContextVar = contextvars.ContextVar("primitive_names", default=BUILTIN_PRIMITIVES)


class _PrimitiveNames:
    """Post-lexer: a NAME that names a primitive becomes PRIM_NAME.

    Primitive calls take their arguments by juxtaposition (``BOX WIDTH 1,
    ...``); knowing which words are primitives is what keeps that from
    swallowing the next statement of a newline-insensitive language.
    """

    always_accept = ()

    def process(self, stream):
        names = _primitive_names.get()
        for tok in stream:
            if tok.type == "NAME" and tok.value.upper() in names:
                tok.type = "PRIM_NAME"
            yield tok


def grammar_parts() -> tuple:
    """The lexer class, post-lexer and transformer the parser is made with."""
    return LigLexer, _PrimitiveNames(), ToAst()


@functools.lru_cache(maxsize=1)
def build_parser() -> Lark:
    """The LALR parser with the AST transformer inside, once per process.

    Its tables come from the package (lang/_tables.py, see
    :mod:`liganimate.lang.tables`), never from a cache a user could write;
    when they were not made from this lig.lark, from the grammar itself.
    """
    parts = grammar_parts()
    return tables.load(*parts) or tables.build(*parts)


@functools.lru_cache(maxsize=1)
def _driver() -> Driver:
    return Driver(build_parser())


def parse_source(source: Source, primitives: frozenset | set = frozenset()) -> A.Program:
    """Parse a prepared source; ``primitives`` are extra primitive names (e.g. from a library)."""
    names = frozenset(set(BUILTIN_PRIMITIVES) | set(primitives) | source.primitive_names())
    # The parse makes only trees, never cycles: the cyclic collector would
    # walk the growing tree again and again for nothing.
    collecting = gc.isenabled()
    gc.disable()
    try:
        body = _driver().parse(source.lexed, names)
    except UnexpectedInput as exc:
        raise LigDiagnostics([_syntax_diagnostic(exc, source)]) from None
    finally:
        if collecting:
            gc.enable()
    body = group_blocks(body, source)
    prims = [s for s in body if isinstance(s, A.PrimitiveDef)]
    return A.Program(A.Pos(1, 1, 1, 1), source.filename, source.text, body, prims)


def parse(text: str, filename: str = "<string>", primitives: frozenset | set = frozenset()) -> A.Program:
    """Parse program text. Raises LigDiagnostics on any syntax error."""
    return parse_source(prepare(text, filename), primitives)


# ------------------------------------------------------------ error messages

_FRIENDLY = {
    "NAME": "a name",
    "PRIM_NAME": "a primitive such as BOX",
    "NUMBER": "a number",
    "STRING": "a quoted word",
    "DOLLAR_NAME": "a $name",
    "ASSIGN_OP": "=, := or :-",
    "RELOP": "a comparison (=, <, >, <=, >=, <>)",
    "LPAR": "(",
    "RPAR": ")",
    "LSQB": "[",
    "RSQB": "]",
    "COMMA": ",",
    "SEMICOLON": ";",
    "LESSTHAN": "<",
    "MORETHAN": ">",
    "EQUAL": "=",
    "PLUS": "+",
    "MINUS": "-",
    "STAR": "*",
    "DIV_OP": "/",
    "COLON": ":",
    "TYPE_KW": "a type (REAL, INTEGER, VECTOR, GRAPHICAL, MODEL, MOTION)",
    "AXIS": "an axis X, Y or Z",
    "MODEL_KW": "MODEL",
    "WIDTH_KW": "WIDTH",
    "$END": "the end of the file",
}

_EXPRESSION_STARTS = {"NAME", "NUMBER", "LPAR"}
_STATEMENT_STARTS = {"TYPE_KW", "DO", "IF", "STARTMODEL", "STARTMOTION", "ANIMATE", "PRINT"}


def _describe_expected(expected: set) -> str:
    expected = {e for e in expected if e not in ("SEMICOLON",)}
    if len(expected & _STATEMENT_STARTS) >= 3:
        closers = sorted(e for e in expected if e.startswith("END") or e in ("STARTSCENE",))
        if closers:
            return "a statement or " + " or ".join(closers)
        return "a statement"
    parts = []
    if _EXPRESSION_STARTS <= expected:
        parts.append("an expression")
        expected = expected - _EXPRESSION_STARTS - {"MINUS", "PLUS", "PRIM_NAME"}
    for e in sorted(expected):
        parts.append(_FRIENDLY.get(e, e))
    if not parts:
        return "something else"
    if len(parts) > 6:
        parts = parts[:6] + ["..."]
    if len(parts) == 1:
        return parts[0]
    return ", ".join(parts[:-1]) + " or " + parts[-1]


def _describe_token(tok: Token) -> str:
    if tok.type == "$END":
        return "the end of the file"
    text = str(tok.value)
    if tok.type in ("NAME", "PRIM_NAME"):
        return f"the name {text.upper()}"
    if tok.type == "NUMBER":
        return f"the number {text}"
    return repr(text) if len(text) <= 20 else repr(text[:20] + "...")


_BLOCK_WORDS = re.compile(
    r"\b(STARTMODEL|ENDMODEL|STARTMOTION|ENDMOTION|STARTREACH|ENDREACH|INITIALIZE|ENDSCENE|PRIMITIVE|BEGIN|END)\b", re.I
)
_CLOSER = {"STARTMODEL": "ENDMODEL", "STARTMOTION": "ENDMOTION", "STARTREACH": "ENDREACH", "INITIALIZE": "ENDSCENE", "PRIMITIVE": "END", "BEGIN": "END"}


def _open_blocks(text: str, upto: int):
    """The constructs still open at offset ``upto`` (a rough scan for hints)."""
    cleaned = re.sub(r"\{[^}]*\}|'[^'\n]*'", lambda m: " " * len(m.group(0)), text[:upto])
    stack = []
    for m in _BLOCK_WORDS.finditer(cleaned):
        word = m.group(1).upper()
        if word in _CLOSER:
            stack.append((word, m.start()))
        else:
            for i in range(len(stack) - 1, -1, -1):
                if _CLOSER[stack[i][0]] == word:
                    del stack[i:]
                    break
    return stack


def _line_col(text: str, offset: int):
    line = text.count("\n", 0, offset) + 1
    col = offset - (text.rfind("\n", 0, offset) + 1) + 1
    return line, col


def _syntax_diagnostic(exc: UnexpectedInput, source: Source) -> Diagnostic:
    text = source.lexed
    line, col = getattr(exc, "line", 1) or 1, getattr(exc, "column", 1) or 1
    hint = None
    if isinstance(exc, UnexpectedCharacters):
        ch = text[exc.pos_in_stream] if exc.pos_in_stream < len(text) else ""
        if ch == "$":
            message = "names beginning with $ are reserved for liganimate"
            hint = "rename it; only PRINT $model uses a $"
        elif ch == "{":
            message = "this { comment is never closed with }"
        elif ch == "'":
            message = "this quoted word is never closed with ' on the same line"
        else:
            message = f"unexpected character {ch!r}"
        return Diagnostic(source.filename, A.Pos(line, col, line, col + 1), message, hint, source=source.text)
    assert isinstance(exc, UnexpectedToken)
    tok = exc.token
    expected = set(exc.expected) if exc.expected else set()
    if tok.type == "$END":
        opened = _open_blocks(text, len(text))
        lines = text.split("\n")
        line = len(lines)
        col = len(lines[-1]) + 1
        if opened:
            word, at = opened[-1]
            oline, ocol = _line_col(text, at)
            message = f"the file ends before {_CLOSER[word]} closes the {word} opened at line {oline}"
            hint = f"add {_CLOSER[word]} after the last statement of the {word}"
            pos = A.Pos(oline, ocol, oline, ocol + len(word))
            d = Diagnostic(source.filename, pos, message, hint, source=source.text)
            return d
        message = f"the file ends too early; expected {_describe_expected(expected)}"
        return Diagnostic(source.filename, A.Pos(line, col, line, col), message, hint, source=source.text)
    pos = A.Pos(tok.line, tok.column, tok.end_line or tok.line, tok.end_column or tok.column + 1)
    if tok.type == "DOLLAR_NAME":
        message = "names beginning with $ are reserved for liganimate"
        hint = "rename it; only PRINT $model uses a $"
    elif tok.type == "PRIM_NAME" and "NAME" in expected:
        message = f"{tok.value.upper()} is a primitive, so it cannot be used as a variable name here"
        hint = "choose another name"
    else:
        message = f"unexpected {_describe_token(tok)}; expected {_describe_expected(expected)}"
        closers = {e for e in expected if e.startswith("END")}
        if (tok.type.startswith("END") and tok.type not in expected) or closers:
            opened = _open_blocks(text, tok.start_pos)
            if opened:
                word, at = opened[-1]
                oline, _ = _line_col(text, at)
                hint = f"the {word} opened at line {oline} is not closed; add {_CLOSER[word]}"
    return Diagnostic(source.filename, pos, message, hint, source=source.text)
