"""Highlighting LIG text: the word classes every highlighter uses, and the Pygments lexer.

Pygments finds :class:`LigLexer` through the ``pygments.lexers`` entry
point in pyproject.toml, so ``pygmentize -l lig`` and any documentation
tool that uses Pygments (Sphinx, MkDocs) colour ```` ```lig ```` blocks once
liganimate is installed. The TextMate grammar of the VS Code extension
(editors/vscode/syntaxes/lig.tmLanguage.json) uses the same word classes;
tests/lsp/test_highlighting.py checks that both agree with the grammar's
own keywords (lang/lig.lark), the built-in functions, the interpolation
methods and the solvers.

Keywords are contextual in LIG (``WIDTH`` may be a variable), and a
highlighter cannot run the parser, so a keyword is coloured as a keyword
wherever it stands; the language server knows better, and says so on hover.
"""

from __future__ import annotations

import re

from pygments.lexer import RegexLexer, bygroups, words
from pygments.token import Comment, Keyword, Name, Number, Operator, Punctuation, String, Whitespace

#: Words that steer the flow of a program.
CONTROL = ("AND", "BEGIN", "CONTINUE", "DO", "ELSE", "END", "IF", "NOT", "OR", "RETURN", "STOP", "THEN")
#: The type names.
TYPES = ("GRAPHICAL", "INTEGER", "MODEL", "MOTION", "REAL", "VECTOR")
#: Every other keyword of the grammar (lang/lig.lark), spelling variants included.
KEYWORDS = (
    "ALONG", "ANIMATE", "AT", "AXIS", "BACKGROUND", "BY", "CHAIN", "COLOR", "COLOUR", "DRAW", "ENDJOINT",
    "ENDMODEL", "ENDMOTION", "ENDREACH", "ENDSCENE", "EXTREME", "EXTREMES", "FIGURE", "FRAME", "FRAMES", "FROM",
    "GOAL", "INITIALIZE", "INTERPOLATE", "INTERPOLATION", "INTO", "ITERATIONS", "JOINT", "JOINTS", "LENGTH",
    "LIGHTNESS", "LINK", "LOAD", "MAIN", "MOVE", "NORMAL", "ON", "PLANE", "POINT", "POLY", "POSITION",
    "PRIMITIVE", "PRINT", "REPEAT", "ROOT", "ROT", "SAMEFRAME", "SCALE", "SCENE", "SHOOTSCENE", "SHOOTSCENES",
    "SLIDE",
    "SOLVER", "STARTMODEL", "STARTMOTION", "STARTREACH", "STARTSCENE", "STRIP", "SYNCHRONISE", "SYNCHRONIZE",
    "TO", "TOLERANCE", "TRANS", "TRANSLATE", "USING", "VIEW", "WEIGHT", "WIDTH", "WITH", "X", "Y", "Z",
)  # fmt: skip
#: The word operator.
WORD_OPERATORS = ("MOD",)
#: The built-in functions that are not also keywords (REAL, MOD, X, Y, Z are coloured as such).
FUNCTIONS = (
    "ABS", "ACOS", "ASIN", "ATAN", "ATAN2", "COS", "CROSS", "DOT", "EXP", "FLOAT", "INT", "LEN", "LOG", "MAX",
    "MIN", "NINT", "NORM", "SIN", "SQRT", "TAN",
)  # fmt: skip
#: The built-in primitive (a program's own PRIMITIVEs are names like any other).
PRIMITIVES = ("BOX",)
#: The interpolation methods and REACH solvers the language names (plugins may add methods).
CONSTANTS = ("ACCDCC", "ACCELERATE", "CCD", "DECELERATE", "DLS", "LINEAR", "TRANSPOSE")

_WORD_END = r"(?![A-Za-z0-9_])"
_WORD_START = r"(?<![A-Za-z0-9_$])"


class LigLexer(RegexLexer):
    """Pygments lexer for LIG ANIMATE programs (Cachola's 1986 language, as liganimate reads it)."""

    name = "LIG ANIMATE"
    aliases = ["lig", "liganimate"]
    filenames = ["*.lig"]
    mimetypes = ["text/x-lig"]
    url = "https://pypi.org/project/liganimate/"
    flags = re.MULTILINE | re.IGNORECASE

    tokens = {
        "root": [
            # C (or c) in column 1 then a blank, a tab or the end of the line: a FORTRAN comment line.
            (r"^[Cc](?=[ \t\r]|$)[^\n]*", Comment.Single),
            # * in column 1 flagged a statement for the 1986 preprocessor.
            (r"^\*", Comment.Special),
            (r"\{@[^}]*\}", String.Doc),
            (r"\{[^}]*\}", Comment.Multiline),
            (r"[ \t\r\n\f]+", Whitespace),
            (r"'[^'\n]*'", String.Single),
            (r"\$[A-Za-z][A-Za-z0-9_]*", Name.Variable.Magic),
            (r"(?:\d+\.\d*|\.\d+)(?:[eE][-+]?\d+)?°?|\d+[eE][-+]?\d+°?", Number.Float),
            (r"\d+°?", Number.Integer),
            (
                r"(?<![A-Za-z0-9_])(PRIMITIVE|STARTMODEL|STARTMOTION|STARTREACH)(\s+)([A-Za-z][A-Za-z0-9_]*)",
                bygroups(Keyword, Whitespace, Name.Function),
            ),  # fmt: skip
            (words(CONTROL, prefix=_WORD_START, suffix=_WORD_END), Keyword),
            (words(TYPES, prefix=_WORD_START, suffix=_WORD_END), Keyword.Type),
            (words(WORD_OPERATORS, prefix=_WORD_START, suffix=_WORD_END), Operator.Word),
            (words(KEYWORDS, prefix=_WORD_START, suffix=_WORD_END), Keyword),
            (words(FUNCTIONS + PRIMITIVES, prefix=_WORD_START, suffix=_WORD_END), Name.Builtin),
            (words(CONSTANTS, prefix=_WORD_START, suffix=_WORD_END), Name.Constant),
            (r"[A-Za-z][A-Za-z0-9_]*", Name),
            (r"::=|:-|:=|<=|>=|<>|/=|[=<>/+\-*]", Operator),
            (r"[;,\[\]()]", Punctuation),
        ],
    }


__all__ = ["CONSTANTS", "CONTROL", "FUNCTIONS", "KEYWORDS", "LigLexer", "PRIMITIVES", "TYPES", "WORD_OPERATORS"]
