"""Parsing: one cached LALR parser, syntax errors as diagnostics.

:func:`parse` turns source text into a :class:`liganimate.lang.ast.Program`.
The parser's tables are loaded once per process from the package
(:mod:`.tables`); :mod:`.lalr` runs them with the transformer inside,
and every Lark exception becomes a
:class:`~liganimate.lang.diagnostics.LigDiagnostics`.
"""

from __future__ import annotations

import functools
import re
from typing import TYPE_CHECKING

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from . import ast as A
from . import collector, tables
from .diagnostics import Diagnostic, LigDiagnostics
from .lalr import Driver
from .lexer import TablesOnly
from .messages import did_you_mean
from .source import Source, prepare
from .structure import group_blocks
from .transform import ToAst
from .vocabulary import BLOCKS, GRAPHICAL, INTEGER, MODEL, MOTION, REAL, VECTOR

if TYPE_CHECKING:  # imported when a reparser is made: only the language server edits a text
    from .incremental import Reparser

#: Primitives every program knows without defining them.
BUILTIN_PRIMITIVES = frozenset({"BOX"})


def grammar_parts() -> tuple:
    """The lexer class, post-lexer and transformer the parser's tables are made and loaded with.

    The lexer never scans and there is no post-lexer: :mod:`.lalr` scans
    and parses in one loop, PRIM_NAME included (see :class:`.lexer.TablesOnly`).
    """
    return TablesOnly, None, ToAst()


@functools.lru_cache(maxsize=1)
def grammar() -> tables.ParserTables:
    """The parser's tables (states, rules, terminals), once per process.

    They come from the package (lang/_tables.py, see
    :mod:`liganimate.lang.tables`), never from a cache a user could write;
    when they were not made from this lig.lark, from the grammar itself.
    """
    return tables.load() or tables.from_lark(tables.build(*grammar_parts()))


@functools.lru_cache(maxsize=1)
def build_parser() -> Lark:
    """Lark's own parser object for lig.lark, computed from the grammar (about 0.3 s).

    liganimate never parses with it (:func:`parse` runs :func:`driver`);
    it is here for tools and tests that compare with Lark's view of the
    grammar. Its ``parse`` is refused (see :class:`.lexer.TablesOnly`).
    """
    return tables.build(*grammar_parts())


@functools.lru_cache(maxsize=1)
def driver() -> Driver:
    """The LALR loop over :func:`grammar`, with the syntax tree's transformer, once per process."""
    return Driver(grammar(), ToAst())


def parse_source(
    source: Source,
    primitives: frozenset | set = frozenset(),
    tokens: list | None = None,
    reparser: Reparser | None = None,
) -> A.Program:
    """Parse a prepared source; ``primitives`` are extra primitive names (e.g. from a library).

    ``tokens``, when given, receives the tokens in order, each typed as the
    parser took it (see :meth:`.lalr.Driver.parse`). ``reparser`` (from
    :func:`reparser`), when given, parses only what changed since the text
    it parsed last (:mod:`.incremental`): the same tree, sooner.
    """
    names = frozenset(set(BUILTIN_PRIMITIVES) | set(primitives) | source.primitive_names())
    # The parse makes trees, never cycles: the cyclic collector would walk
    # the growing tree again and again for nothing (on a million-line
    # program, a third of the time).
    with collector.paused():
        try:
            if reparser is not None:
                body = reparser.parse(source.lexed, names)
            else:
                body = driver().parse(source.lexed, names, tokens)
        except UnexpectedInput as exc:
            raise LigDiagnostics([_syntax_diagnostic(exc, source)]) from None
        if reparser is None:
            body = group_blocks(body, source)
        else:
            body = group_blocks(body, source, reparser.fresh)
            reparser.passed()
    prims = [s for s in body if isinstance(s, A.PrimitiveDef)]
    return A.Program(A.Pos(1, 1, 1, 1), source.filename, source.text, body, prims)


def reparser() -> Reparser:
    """A parser for the successive versions of one text (a document being edited): see :mod:`.incremental`."""
    from .incremental import Reparser  # only the language server edits; a command parses once

    return Reparser(driver(), ToAst().start)


def parse(text: str, filename: str = "<string>", primitives: frozenset | set = frozenset()) -> A.Program:
    """Parse program text. Raises LigDiagnostics on any syntax error."""
    return parse_source(prepare(text, filename), primitives)


# ------------------------------------------------------------ error messages

# How the terminals the parser expects are named to the user. Keywords not
# listed are named by their own spelling (see _terminal_text); the test
# suite enumerates the grammar's terminals so that no internal name such as
# __ANON_0 or $END can reach a message.
_FRIENDLY = {
    "NAME": "a name",
    "CLAUSE_NAME": "a word of the primitive's pattern",
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
    "__ANON_0": "::=",
    "TYPE_KW": "a type (REAL, INTEGER, VECTOR, GRAPHICAL, MODEL, MOTION)",
    "AXIS": "an axis X, Y or Z",
    "AXIS_KW": "AXIS",
    "MODEL_KW": "MODEL",
    "WIDTH_KW": "WIDTH",
    "WS": "a blank",
    "BRACE_COMMENT": "a { comment }",
    "$END": "the end of the file",
}

_EXPRESSION_STARTS = {"NAME", "NUMBER", "LPAR"}
_SYMBOLS = frozenset({",", ";", "(", ")", "[", "]", "<", ">", "=", "+", "-", "*", "/", ":", "::="})
_STATEMENT_STARTS = {"TYPE_KW", "DO", "IF", "STARTMODEL", "STARTMOTION", "ANIMATE", "PRINT"}


def _terminal_text(name: str) -> str:
    """What the user would type (or a short description) for the terminal ``name``."""
    friendly = _FRIENDLY.get(name)
    if friendly is not None:
        return friendly
    term = grammar().terminal(name) if name.isidentifier() else None
    if term is not None and term.pattern.type == "str":
        return term.pattern.value.upper()
    if name.isalpha():
        return name  # a keyword given by a regular expression, such as FRAMES
    return "another symbol"


def _describe_expected(expected: set) -> str:
    expected = {e for e in expected if e not in ("SEMICOLON",)}
    if len(expected & _STATEMENT_STARTS) >= 3:
        closers = sorted(e for e in expected if e.startswith("END") or e in ("STARTSCENE",))
        if closers:
            return "a statement or " + " or ".join(_terminal_text(e) for e in closers)
        return "a statement"
    parts = []
    if _EXPRESSION_STARTS <= expected:
        parts.append("an expression")
        expected = expected - _EXPRESSION_STARTS - {"MINUS", "PLUS", "PRIM_NAME"}
    for e in sorted(expected):
        text = _terminal_text(e)
        # A symbol is quoted, as the unexpected token is: "expected ',' or ')'", never "expected , or )".
        parts.append(repr(text) if text in _SYMBOLS else text)
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
    if tok.type in ("NAME", "PRIM_NAME", "CLAUSE_NAME"):
        shown = text.upper() if len(text) <= 40 else text[:40].upper() + "..."
        return f"name {shown}"
    if tok.type == "NUMBER":
        return f"number {text}" if len(text) <= 40 else f"number {text[:40]}..."
    return repr(text) if len(text) <= 20 else repr(text[:20] + "...")


# The patterns below serve error messages only: written as text and compiled when first used (re keeps
# them), since compiling them at import cost about 0.4 ms of every start, a successful check included.
_BLOCK_WORDS = r"(?i)\b(" + "|".join(sorted({w for b in BLOCKS for w in (b.opener, b.closer)})) + r")\b"
_CLOSER = {b.opener: b.closer for b in BLOCKS}
# Each closing word, what opens it (as the user would write it), and the opening words.
_STRAY = {
    closer: (
        " or ".join(b.shown for b in BLOCKS if b.closer == closer),
        tuple(b.opener for b in BLOCKS if b.closer == closer),
    )
    for closer in dict.fromkeys(b.closer for b in BLOCKS)
}
_SHOWN = {b.opener: b.shown for b in BLOCKS}


def _shown(word: str) -> str:
    """An opening word as the user wrote it (a scene opens with INITIALIZE SCENE)."""
    return _SHOWN.get(word, word)


_BLANKED = r"\{[^}]*\}|'[^'\n]*'"


def _blanked(text: str, upto: int) -> str:
    """``text[:upto]`` with comments and quoted words blanked (offsets kept)."""
    return re.sub(_BLANKED, lambda m: re.sub(r"[^\n]", " ", m.group(0)), text[:upto])


def _scan_blocks(text: str, upto: int):
    """A rough scan of the block words before offset ``upto``, for messages.

    Returns the stack of open blocks ``[(word, offset), ...]`` and, for each
    opening word, the last ``(open offset, close offset)`` pair seen. JOINT
    counts as a block only directly inside STARTMOTION, where ENDJOINT may
    close it; the next JOINT or the ENDMOTION closes it too.
    """
    stack: list = []
    closed: dict = {}
    for m in re.finditer(_BLOCK_WORDS, _blanked(text, upto)):
        word = m.group(1).upper()
        if word == "JOINT":
            if stack and stack[-1][0] == "JOINT":
                stack.pop()
            if stack and stack[-1][0] == "STARTMOTION":
                stack.append((word, m.start()))
        elif word in _CLOSER:
            stack.append((word, m.start()))
        else:
            for i in range(len(stack) - 1, -1, -1):
                if _CLOSER[stack[i][0]] == word:
                    closed[stack[i][0]] = (stack[i][1], m.start())
                    del stack[i:]
                    break
    return stack, closed


def _open_blocks(text: str, upto: int):
    """The constructs still open at offset ``upto`` (a rough scan for hints); a JOINT needs no closing."""
    return [b for b in _scan_blocks(text, upto)[0] if b[0] != "JOINT"]


_OPENING = {")": "(", "]": "["}


def _open_brackets(text: str, upto: int):
    """The ( and [ still open at offset ``upto``: ``[(bracket, offset), ...]``."""
    stack: list = []
    for m in re.finditer(r"[()\[\]]", _blanked(text, upto)):
        ch = m.group(0)
        if ch in "([":
            stack.append((ch, m.start()))
        elif stack and stack[-1][0] == _OPENING[ch]:
            stack.pop()
    return stack


def _line_col(text: str, offset: int):
    line = text.count("\n", 0, offset) + 1
    col = offset - (text.rfind("\n", 0, offset) + 1) + 1
    return line, col


def _token_pos(tok: Token) -> A.Pos:
    line, column = tok.line, tok.column
    # Every token a syntax error carries has a line and column (see _start).
    assert line is not None and column is not None
    return A.Pos(line, column, tok.end_line or line, tok.end_column or column + 1)


def _start(tok: Token) -> int:
    """``tok.start_pos``, which Lark types Optional as a Token may be made without one.

    Every token that reaches a message has it: Tok.as_lark's, Lark's ``$END``
    (borrowed from the last token, or made at offset 0) and _word_taken_as_name's.
    """
    assert tok.start_pos is not None
    return tok.start_pos


def _end(tok: Token) -> int:
    """``tok.end_pos``, for a token that is not ``$END`` (see :func:`_start`)."""
    assert tok.end_pos is not None
    return tok.end_pos


def _word_taken_as_name(tok: Token, text: str, expected: set):
    """The closing word (or BEGIN) the parser took for the start of an assignment, if that is what failed.

    Where a statement may start, a closing word the state does not accept
    (ENDMOTION after its block is closed) is lexed as a NAME, and the error
    only shows at the next token, which is not ``=``. Only a NAME leads to a
    state expecting ``=`` or ``[``, so the word is the last one before the
    offending token (before its start; the end-of-file token borrows the
    last token's position, so that token itself).
    """
    if not {"ASSIGN_OP", "LSQB"} <= expected:
        return None
    if tok.type == "$END":
        start = tok.start_pos
    else:
        before = _blanked(text, _start(tok)).rstrip()
        m = re.compile(_LAST_WORD).search(before, max(0, len(before) - 40))
        if m is None:
            return None
        start = m.start()
    m = re.compile(_WORD).match(text, start or 0)
    if m is None or m.group(0).upper() not in _STRAY and m.group(0).upper() not in ("CONTINUE", "BEGIN"):
        return None
    line, col = _line_col(text, m.start())
    return Token("NAME", m.group(0), m.start(), line, col, line, col + len(m.group(0)), m.end())


_WORD = r"[A-Za-z][A-Za-z0-9_]*"
_ASSIGNED = r"[ \t]*(:-|:=|=|\[)"
_LAST_WORD = r"(?<![A-Za-z0-9_])[A-Za-z][A-Za-z0-9_]*\Z"


def _stray_diagnostic(tok: Token, text: str, source: Source, as_name: bool):
    """``ENDMOTION without STARTMOTION`` and its kind, at the stray word, or None if it is not stray."""
    word = tok.value.upper()
    pos = _token_pos(tok)
    if not as_name and re.compile(_ASSIGNED).match(text, _end(tok)):
        return Diagnostic(
            source.filename,
            pos,
            f"{word} cannot be a variable name here, after an expression",
            "choose another name, or start the statement with another one",
            source=source.text,
        )
    if word == "BEGIN":
        # The thesis' BEGIN ... END is a branch of IF; where a statement may
        # start, BEGIN is only a name, and the error would show at the next line.
        return Diagnostic(
            source.filename,
            pos,
            "BEGIN starts a block only after THEN or ELSE",
            "a program's statements need no BEGIN ... END around them; remove both, or write IF ... THEN BEGIN ... END",
            source=source.text,
        )
    if word == "CONTINUE":
        return Diagnostic(
            source.filename,
            pos,
            "CONTINUE needs the label of the DO loop it closes",
            "write the loop as DO 10 I = 1, 5 ... 10 CONTINUE",
            source=source.text,
        )
    opener_text, openers = _STRAY[word]
    stack, closed = _scan_blocks(text, _start(tok))
    if any(w in openers for w, _ in stack):
        return None  # its block is open: the word is misplaced, not stray
    others = [b for b in stack if b[0] != "JOINT"]
    if others and not as_name and (word == "END" or word == "ENDJOINT" and others[-1][0] != "STARTMOTION"):
        return None  # END inside another block: that block is what is unclosed
    pairs = [(closed[w][1], closed[w][0], w) for w in openers if w in closed]
    if pairs:
        by, at, opened_word = max(pairs)
        hint = (
            f"the {_shown(opened_word)} at line {_line_col(text, at)[0]} was already closed "
            f"by the {word} at line {_line_col(text, by)[0]}"
        )
    else:
        hint = f"no {opener_text} is open here"
    # Name the block that is open instead, unless it is the JOINT's own STARTMOTION.
    if others and not (word == "ENDJOINT" and others[-1][0] == "STARTMOTION"):
        inner, at = others[-1]
        hint += f"; the {_shown(inner)} opened at line {_line_col(text, at)[0]} is closed by {_CLOSER[inner]}"
    return Diagnostic(source.filename, pos, f"{word} without {opener_text}", hint, source=source.text)


def _bracket_hint(text: str, upto: int, after: int = -1):
    """'the ( opened at 1:5 is never closed' for the innermost open bracket after offset ``after``."""
    brackets = _open_brackets(text, upto)
    if not brackets or brackets[-1][1] < after:
        return None
    ch, at = brackets[-1]
    line, col = _line_col(text, at)
    return f"the {ch} opened at {line}:{col} is never closed"


def _syntax_diagnostic(exc: UnexpectedInput, source: Source) -> Diagnostic:
    text = source.lexed
    if isinstance(exc, UnexpectedCharacters):
        return _character_diagnostic(exc, source)
    assert isinstance(exc, UnexpectedToken)
    tok = exc.token
    expected = set(exc.expected) if exc.expected else set()
    stray = _word_taken_as_name(tok, text, expected)
    if stray is not None:
        d = _stray_diagnostic(stray, text, source, as_name=True)
        if d is not None:
            return d
    if tok.type != "$END" and tok.type not in expected and str(tok.value).upper() in _STRAY:
        d = _stray_diagnostic(tok, text, source, as_name=False)
        if d is not None:
            return d
    if tok.type == "$END":
        return _end_of_file(tok, expected, text, source)
    return _token_diagnostic(tok, expected, text, source)


def _character_diagnostic(exc: UnexpectedCharacters, source: Source) -> Diagnostic:
    """A character no token starts with: a $ name, an unclosed comment or quoted word, or a stray symbol."""
    text = source.lexed
    line, col = getattr(exc, "line", 1) or 1, getattr(exc, "column", 1) or 1
    at = exc.pos_in_stream
    assert at is not None  # Optional on UnexpectedInput; UnexpectedCharacters always sets it
    ch = text[at] if at < len(text) else ""
    hint = None
    if ch == "$":
        message = "names beginning with $ are reserved for liganimate"
        hint = "rename it; only PRINT $model uses a $"
    elif ch == "{":
        message = "this { comment is never closed with }"
        hint = "a comment runs from { to the next }; add the }"
    elif ch == "'":
        message = "this quoted word is never closed with ' on the same line"
        hint = "a quoted word ends with ' before the end of its line"
    else:
        message = f"unexpected character {ch!r}"
    return Diagnostic(source.filename, A.Pos(line, col, line, col + 1), message, hint, source=source.text)


def _token_diagnostic(tok, expected: set, text: str, source: Source) -> Diagnostic:
    """A token the grammar does not take here (not the end of the file): what it is, and the likeliest fix."""
    hint = None
    if tok.type == "DOLLAR_NAME":
        message = "names beginning with $ are reserved for liganimate"
        hint = "rename it; only PRINT $model uses a $"
    elif tok.type == "PRIM_NAME" and "NAME" in expected:
        message = f"{tok.value.upper()} is a primitive, so it cannot be used as a variable name here"
        hint = "choose another name"
    elif str(tok.value).upper() == "ORIENTATION" and "ORIENTATION" not in expected:
        # A turn written on a joint's track (JOINT 3 ORIENTATION, m[3 ORIENTATION, k]): only the figure turns as a whole.
        message = "only the ROOT track has an ORIENTATION; a joint's three angles are its POSITION"
        hint = "turn the whole figure with a ROOT ORIENTATION entry (its POSITION is three angles, the heading about Y)"
    else:
        message = f"unexpected {_describe_token(tok)}; expected {_describe_expected(expected)}"
        hint = _misspelt_keyword(tok, expected)
        if hint is None and {"ASSIGN_OP", "LSQB"} <= expected:
            d = _misspelt_statement(tok, text, source)
            if d is not None:
                return d
        if hint is None:
            hint = _unclosed_hint(tok, expected, text)
    return Diagnostic(source.filename, _token_pos(tok), message, hint, source=source.text)


def _unclosed_hint(tok, expected: set, text: str) -> str | None:
    """The block or bracket left open before ``tok``, when that explains the error."""
    closers = {e for e in expected if e.startswith("END")}
    if (tok.type.startswith("END") and tok.type not in expected) or closers:
        opened = _open_blocks(text, tok.start_pos)
        if opened:
            word, at = opened[-1]
            oline, _ = _line_col(text, at)
            return f"the {_shown(word)} opened at line {oline} is not closed; add {_CLOSER[word]}"
    if expected & {"RPAR", "RSQB"}:
        return _bracket_hint(text, tok.start_pos)
    return None


#: The declarable types, as TYPE_KW spells them.
TYPE_NAMES = (REAL, INTEGER, VECTOR, GRAPHICAL, MODEL, MOTION)


def _keyword_words(expected: set) -> set:
    """The keywords among the terminals ``expected``, as the user spells them."""
    words: set[str] = set()
    for e in expected:
        if e == "TYPE_KW":
            words |= set(TYPE_NAMES)
            continue
        shown = _terminal_text(e)
        if shown.isalpha() and shown.isupper() and len(shown) > 1:
            words.add(shown)
    return words


def _misspelt_keyword(tok: Token, expected: set) -> str | None:
    """'did you mean LENGTH?' when a name stands where a keyword close to it was expected."""
    if tok.type not in ("NAME", "PRIM_NAME", "CLAUSE_NAME"):
        return None
    return did_you_mean(str(tok.value), _keyword_words(expected), cutoff=0.75)


def _misspelt_statement(tok: Token, text: str, source: Source):
    """A misspelt statement keyword (STARTMOTON M): the word was read as a variable, so the name after it fails.

    Reported at the misspelt word, with the keyword it is closest to; None
    when the word before ``tok`` is close to no statement keyword.
    """
    before = _blanked(text, _start(tok)).rstrip()
    m = re.compile(_LAST_WORD).search(before, max(0, len(before) - 40))
    if m is None:
        return None
    word = m.group(0)
    hint = did_you_mean(word, _STATEMENT_WORDS, cutoff=0.75)
    if hint is None or word.upper() in _STATEMENT_WORDS:
        return None
    line, col = _line_col(text, m.start())
    return Diagnostic(
        source.filename,
        A.Pos(line, col, line, col + len(word)),
        f"{word.upper()} is not a keyword: read as a variable, it needs =, := or :- after it",
        hint,
        source=source.text,
    )


# The words a statement may start with (a misspelling of one is read as a variable name).
_STATEMENT_WORDS = frozenset(
    {w.opener for w in BLOCKS}
    | set(TYPE_NAMES)
    | {"ANIMATE", "BACKGROUND", "PRINT", "VIEW", "SHOOTSCENES", "LOAD", "STOP", "RETURN", "DRAW", "FIGURE"}
    | {"IF", "DO", "PRIMITIVE", "INITIALIZE", "STARTREACH", "ENDMODEL", "ENDMOTION", "ENDSCENE", "STARTSCENE"}
)


# When the file ends inside a block the scan did not see, the closer to suggest.
_CLOSING_ORDER = tuple(_STRAY)


def _end_of_file(tok: Token, expected: set, text: str, source: Source) -> Diagnostic:
    """The file ended inside something: say what is unclosed, at the end of the last token."""
    opened = _open_blocks(text, len(text))
    after = opened[-1][1] if opened else -1
    bracket = _bracket_hint(text, len(text), after) if expected & {"RPAR", "RSQB"} else None
    if opened and bracket is None:
        word, at = opened[-1]
        oline, ocol = _line_col(text, at)
        message = f"the file ends before {_CLOSER[word]} closes the {_shown(word)} opened at line {oline}"
        hint = f"add {_CLOSER[word]} after the last statement of the {_shown(word)}"
        return Diagnostic(
            source.filename, A.Pos(oline, ocol, oline, ocol + len(word)), message, hint, source=source.text
        )
    # Lark's end token borrows the position of the last real token: point just after it.
    # From its end offset, not its end column: a keyframe table's rows are one token
    # over many lines, and its end column counts from the line it starts on.
    end = getattr(tok, "end_pos", None)
    line, col = _line_col(text, end) if isinstance(end, int) and 0 < end <= len(text) else (None, None)
    if not line or not col:
        lines = text.split("\n")
        line, col = len(lines), len(lines[-1]) + 1
    message = f"the file ends too early; expected {_describe_expected(expected)}"
    closer = next((w for w in _CLOSING_ORDER if w in expected), None)
    if bracket:
        hint = bracket
    elif closer:
        hint = f"a block is still open; close it with {closer}"
    else:
        hint = "the last statement is not finished"
    return Diagnostic(source.filename, A.Pos(line, col, line, col + 1), message, hint, source=source.text)
