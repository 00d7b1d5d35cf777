"""Reading a source file: strict UTF-8 and the 1986 listing conventions.

The thesis' listings flag extension statements with ``*`` in column 1 and
write FORTRAN comment lines as ``C`` in column 1. Both are blanked here,
keeping every other character where it was so that columns in diagnostics
still point into the text the user wrote.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from .ast import Pos
from .diagnostics import Diagnostic, LigDiagnostics

# A C-comment line that looks like a statement deserves a warning: in 1986
# it was a comment, but today the writer probably meant a variable called C.
_LOOKS_LIKE_CODE = re.compile(r"^[Cc]\s*(=|:-|:=|\[)")
_PRIMITIVE_HEAD = re.compile(r"(?im)^[ \t*]*PRIMITIVE[ \t]+([A-Za-z][A-Za-z0-9_]*)")
# LOAD statements, found before parsing for the same reason as PRIMITIVE heads:
# a loaded primitive's name must already be a PRIM_NAME when the lexer meets it.
_LOAD = re.compile(
    r"(?i)(?:^|[;\n])[ \t]*LOAD\s+(?:'([^'\n]*)'|((?:[A-Za-z][A-Za-z0-9_]*\s*,\s*)*[A-Za-z][A-Za-z0-9_]*)\s+FROM\s+'([^'\n]*)')")
_BRACES = re.compile(r"\{[^}]*\}")


@dataclass
class Source:
    """A decoded program: the text as written and the text the lexer sees."""

    filename: str
    text: str
    lexed: str
    warnings: list = field(default_factory=list)

    def primitive_names(self) -> set:
        """Names of the PRIMITIVEs this file defines (found before parsing, see lang/lig.lark)."""
        return {m.group(1).upper() for m in _PRIMITIVE_HEAD.finditer(self.lexed)}

    def load_requests(self) -> list:
        """The LOAD statements, found before parsing: ``[(library, names or None), ...]``.

        Only a hint for the lexer (which loaded names are primitives); the
        parsed LOAD statements are what the checker acts on.
        """
        text = _BRACES.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), self.lexed)
        found = []
        for m in _LOAD.finditer(text):
            if m.group(1) is not None:
                found.append((m.group(1), None))
            else:
                found.append((m.group(3), [n.strip().upper() for n in m.group(2).split(",")]))
        return found


def decode(data: bytes, filename: str) -> str:
    """Decode UTF-8 strictly, reporting the first bad byte at its line and column."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        good = data[: exc.start].decode("utf-8", errors="replace")
        line = good.count("\n") + 1
        col = len(good) - (good.rfind("\n") + 1) + 1
        shown = data.decode("utf-8", errors="replace")
        raise LigDiagnostics([
            Diagnostic(
                filename,
                Pos(line, col, line, col + 1),
                f"the file is not valid UTF-8 (byte 0x{data[exc.start]:02x} at offset {exc.start})",
                "save the file as UTF-8; a degree sign written by an old editor is a common cause",
                source=shown,
            )
        ]) from None
    if text.startswith("\ufeff"):
        text = text[1:]
    return text


def prepare(text: str, filename: str) -> Source:
    """Blank column-1 ``*`` flags and ``C`` comment lines, keeping positions."""
    out = []
    warnings = []
    for number, line in enumerate(text.split("\n"), start=1):
        if line[:1] == "*":
            line = " " + line[1:]
        elif line[:1] in ("C", "c") and (len(line) == 1 or line[1] in " \t\r"):
            if _LOOKS_LIKE_CODE.match(line):
                warnings.append(Diagnostic(
                    filename, Pos(number, 1, number, 2),
                    "this line is a comment: a C in column 1 followed by a blank starts a comment line",
                    "indent the line if it is a statement about a variable called C",
                    severity="warning",
                ))
            line = ""
        out.append(line)
    return Source(filename, text, "\n".join(out), warnings)


def load(path: str, display_name: str | None = None) -> Source:
    """Read, decode and prepare a program file."""
    with open(path, "rb") as fh:
        data = fh.read()
    name = display_name or path
    return prepare(decode(data, name), name)
