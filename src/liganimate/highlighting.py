"""Highlighting LIG text: the word classes every highlighter uses, the Pygments lexer, the TextMate grammar.

Pygments finds :class:`LigLexer` through the ``pygments.lexers`` entry
point in pyproject.toml, so ``pygmentize -l lig`` and any documentation
tool that uses Pygments (Sphinx, MkDocs) colour ```` ```lig ```` blocks once
liganimate is installed. The TextMate grammar of the VS Code extension
(editors/vscode/syntaxes/lig.tmLanguage.json) is written from the same word
classes by ``python -m liganimate.highlighting editors/vscode/syntaxes/lig.tmLanguage.json``;
tests/lsp/test_highlighting.py checks that the file is what
:func:`textmate_grammar` gives and that the word classes are the grammar's
own keywords (lang/lig.lark), the built-in functions, the interpolation
methods and the solvers.

Keywords are contextual in LIG (``WIDTH`` may be a variable), and a
highlighter cannot run the parser, so a keyword is coloured as a keyword
wherever it stands; the language server knows better, and says so on hover.
"""

from __future__ import annotations

import functools
import re

from pygments.lexer import RegexLexer, bygroups, words
from pygments.token import Comment, Keyword, Name, Number, Operator, Punctuation, String, Whitespace

#: Words that steer the flow of a program.
CONTROL = ("AND", "BEGIN", "CONTINUE", "DO", "ELSE", "END", "IF", "NOT", "OR", "RETURN", "STOP", "THEN")
#: The type names.
TYPES = ("GRAPHICAL", "INTEGER", "MODEL", "MOTION", "REAL", "VECTOR")
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


@functools.cache
def keywords() -> tuple[str, ...]:
    """Every other keyword of the grammar (lang/lig.lark), spelling variants included.

    Read from the parser's own terminals, so that a new statement's or
    modifier's word is coloured without an edit here (only the TextMate
    grammar is written again). Reading them loads the parser's tables, so
    it is done when a lexer first needs them, not when this module is imported.
    """
    from liganimate.lang.lexer import GrammarTables
    from liganimate.lang.parser import grammar

    tables = GrammarTables(grammar().terminals)
    found = frozenset(tables.plain) | frozenset(tables.strong)
    return tuple(sorted(found - {*CONTROL, *TYPES, *WORD_OPERATORS}))


class _Keywords(words):
    """:func:`keywords` as a Pygments word list, read when Pygments first builds the lexer's patterns."""

    def __init__(self) -> None:
        super().__init__((), prefix=_WORD_START, suffix=_WORD_END)

    def get(self) -> str:
        self.words = keywords()
        return super().get()


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
            (_Keywords(), Keyword),
            (words(FUNCTIONS + PRIMITIVES, prefix=_WORD_START, suffix=_WORD_END), Name.Builtin),
            (words(CONSTANTS, prefix=_WORD_START, suffix=_WORD_END), Name.Constant),
            (r"[A-Za-z][A-Za-z0-9_]*", Name),
            (r"::=|:-|:=|<=|>=|<>|/=|[=<>/+\-*]", Operator),
            # The bar that starts each row of a keyframe table (TABLE ... then | rows).
            (r"[;,\[\]()|]", Punctuation),
        ],
    }


def _alternation(words_: tuple) -> str:
    """A TextMate (Oniguruma) pattern matching any of ``words_`` as a whole word, in any case."""
    ordered = sorted(words_, key=lambda w: (-len(w), w))
    return r"(?<![A-Za-z0-9_$])(?i:" + "|".join(ordered) + r")(?![A-Za-z0-9_])"


def textmate_grammar() -> dict:
    """The TextMate grammar of LIG (scope ``source.lig``), from the same word classes as :class:`LigLexer`."""
    number = r"(?<![A-Za-z0-9_])(?:(?:\d+\.\d*|\.\d+)(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+)°?"
    return {
        "$schema": "https://raw.githubusercontent.com/martinring/tmlanguage/master/tmlanguage.json",
        "name": "LIG ANIMATE",
        "scopeName": "source.lig",
        "fileTypes": ["lig"],
        "patterns": [
            {"include": f"#{part}"} for part in ("comments", "strings", "numbers", "declarations", "words", "operators")
        ],
        "repository": {
            "comments": {
                "patterns": [
                    {"name": "comment.line.c.lig", "match": r"^[Cc](?=[ \t\r]|$).*$"},
                    {"name": "comment.line.flag.lig", "match": r"^\*"},
                    {"name": "comment.block.documentation.lig", "begin": r"\{@", "end": r"\}"},
                    {"name": "comment.block.lig", "begin": r"\{", "end": r"\}"},
                ]
            },
            "strings": {
                "patterns": [
                    {"name": "string.quoted.single.lig", "match": r"'[^']*'"},
                    {"name": "invalid.illegal.unclosed-string.lig", "match": r"'[^']*$"},
                ]
            },
            "numbers": {
                "patterns": [
                    {"name": "constant.numeric.float.lig", "match": number},
                    {"name": "constant.numeric.integer.lig", "match": r"(?<![A-Za-z0-9_])\d+°?"},
                ]
            },
            "declarations": {
                "patterns": [
                    {
                        "match": r"(?<![A-Za-z0-9_])(?i:(PRIMITIVE|STARTMODEL|STARTMOTION|STARTREACH))\s+([A-Za-z][A-Za-z0-9_]*)",
                        "captures": {
                            "1": {"name": "keyword.other.block.lig"},
                            "2": {"name": "entity.name.function.lig"},
                        },
                    }
                ]
            },
            "words": {
                "patterns": [
                    {"name": "keyword.control.lig", "match": _alternation(CONTROL)},
                    {"name": "storage.type.lig", "match": _alternation(TYPES)},
                    {"name": "keyword.operator.word.lig", "match": _alternation(WORD_OPERATORS)},
                    {"name": "keyword.other.lig", "match": _alternation(keywords())},
                    {"name": "support.function.builtin.lig", "match": _alternation(FUNCTIONS + PRIMITIVES)},
                    {"name": "support.constant.lig", "match": _alternation(CONSTANTS)},
                    {"name": "variable.language.dollar.lig", "match": r"\$[A-Za-z][A-Za-z0-9_]*"},
                    {"name": "variable.other.lig", "match": r"[A-Za-z][A-Za-z0-9_]*"},
                ]
            },
            "operators": {
                "patterns": [
                    {"name": "keyword.operator.lig", "match": r"::=|:-|:=|<=|>=|<>|/=|[=<>/+\-*]"},
                    {"name": "punctuation.separator.lig", "match": r"[,;]"},
                    {"name": "punctuation.section.brackets.lig", "match": r"[\[\]()]"},
                ]
            },
        },
    }


def textmate_json() -> str:
    """:func:`textmate_grammar` as the extension's file holds it."""
    import json

    return json.dumps(textmate_grammar(), indent=2, ensure_ascii=False) + "\n"


def main(argv: list | None = None) -> int:
    """``python -m liganimate.highlighting PATH``: write the TextMate grammar to PATH."""
    import sys

    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        sys.stderr.write("usage: python -m liganimate.highlighting editors/vscode/syntaxes/lig.tmLanguage.json\n")
        return 2
    from liganimate.runtime.files import AtomicWriter

    with AtomicWriter(args[0]) as fh:
        fh.write(textmate_json().encode("utf-8"))
    return 0


__all__ = [
    "CONSTANTS",
    "CONTROL",
    "FUNCTIONS",
    "LigLexer",
    "PRIMITIVES",
    "TYPES",
    "WORD_OPERATORS",
    "keywords",
    "textmate_grammar",
    "textmate_json",
]


if __name__ == "__main__":
    raise SystemExit(main())
