"""Reading a source file: what counts as LIG text, strict UTF-8 and the 1986 listing conventions.

A source file is read only if it is a regular file of at most
:data:`MAX_SOURCE_BYTES`, opened without blocking so that a named pipe or a
device named by mistake (or by a hostile LOAD) cannot hang a run. LIG text
is UTF-8 without control characters other than tab, line feed, form feed
and carriage return; see docs/security.md for why a file that is not LIG
text is refused without quoting it.

The thesis' listings flag extension statements with ``*`` in column 1 and
write FORTRAN comment lines as ``C`` in column 1. Both are blanked here,
keeping every other character where it was so that columns in diagnostics
still point into the text the user wrote.
"""

from __future__ import annotations

import errno
import os
import re
import stat
from dataclasses import field

from .ast import Pos
from .diagnostics import Diagnostic, LigDiagnostics
from .node_methods import record

# A C-comment line that looks like a statement deserves a warning: in 1986
# it was a comment, but today the writer probably meant a variable called C.
_LOOKS_LIKE_CODE = re.compile(r"^[Cc]\s*(=|:-|:=|\[)")
# ASCII (the "a" flag), as the lexer's words and blanks are: ignoring case in all of Unicode
# would also take the Kelvin sign for a K, and costs about 0.4 ms more to compile at every start.
_PRIMITIVE_HEAD = re.compile(r"(?ima)^[ \t*]*PRIMITIVE[ \t]+([A-Za-z][A-Za-z0-9_]*)")
# LOAD statements, found before parsing for the same reason as PRIMITIVE heads:
# a loaded primitive's name must already be a PRIM_NAME when the lexer meets it.
_LOAD = re.compile(
    r"(?ia)(?:^|[;\n])[ \t]*LOAD\s+(?:'([^'\n]*)'|((?:[A-Za-z][A-Za-z0-9_]*\s*,\s*)*[A-Za-z][A-Za-z0-9_]*)\s+FROM\s+'([^'\n]*)')"
)
_BRACES = re.compile(r"\{[^}]*\}")

# Larger than any program written by hand (the thesis' longest listing is a
# few hundred lines) and small enough that checking it fits in memory.
MAX_SOURCE_BYTES = 64 * 1024 * 1024
# Control characters LIG text may hold: tab, line feed, form feed, carriage return.
_CONTROL_BYTES = re.compile(rb"[\x00-\x08\x0b\x0e-\x1f\x7f]")
_CONTROL_CHARS = re.compile("[\x00-\x08\x0b\x0e-\x1f\x7f-\x9f]")


class SourceFileError(OSError):
    """A file that cannot be a LIG source: not a regular file, too large, or not LIG text.

    ``strerror`` is one plain sentence that never quotes the file's content,
    so it is safe to show whatever file a LOAD named.
    """

    def __init__(self, message: str, filename: str):
        super().__init__(errno.EINVAL, message, filename)


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "a special file"


def _require_regular(st: os.stat_result, path: str) -> None:
    if not stat.S_ISREG(st.st_mode):
        raise SourceFileError(f"not an ordinary file but {_kind(st.st_mode)}", path)
    if st.st_size > MAX_SOURCE_BYTES:
        raise SourceFileError(_too_large(), path)


def _too_large() -> str:
    return f"larger than {MAX_SOURCE_BYTES // (1024 * 1024)} MB, the most a LIG source may hold"


def read_source_bytes(path: str, *, follow_symlinks: bool = True) -> bytes:
    """The bytes of a source file, refusing anything but a regular file of at most MAX_SOURCE_BYTES.

    The file is looked at before it is opened (a device is never opened),
    opened without blocking (a named pipe put in its place meanwhile cannot
    hang) and looked at again through the open descriptor. Files that report
    no size (``/proc``) are read up to the limit.

    Parameters
    ----------
    path : str
        The file.
    follow_symlinks : bool
        False refuses a symbolic link as the last part of ``path`` (library
        paths are already resolved, so a link there appeared afterwards).

    Raises
    ------
    SourceFileError
        Not a regular file, or too large.
    OSError
        Missing, unreadable.
    """
    _require_regular(os.stat(path, follow_symlinks=follow_symlinks), path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)
    if not follow_symlinks:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    fd = os.open(path, flags)
    try:
        _require_regular(os.fstat(fd), path)
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, min(1 << 20, MAX_SOURCE_BYTES + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > MAX_SOURCE_BYTES:
                raise SourceFileError(_too_large(), path)
    finally:
        os.close(fd)
    return b"".join(chunks)


def _line_col(data: bytes, offset: int) -> tuple[int, int]:
    start = data.rfind(b"\n", 0, offset) + 1
    return data.count(b"\n", 0, offset) + 1, len(data[start:offset].decode("utf-8", errors="replace")) + 1


def _text_line_col(text: str, offset: int) -> tuple[int, int]:
    return text.count("\n", 0, offset) + 1, offset - (text.rfind("\n", 0, offset) + 1) + 1


def lig_text(data: bytes, path: str) -> str:
    """Decode a file a LOAD named, refusing anything that is not LIG text.

    The refusal says what is wrong and where, never what the file holds: a
    LOAD may name a file its author cannot read (see docs/security.md).

    Raises
    ------
    SourceFileError
        Not UTF-8, or holding control characters other than tab, line feed,
        form feed and carriage return.
    """
    bad_byte = _CONTROL_BYTES.search(data)
    if bad_byte is not None:
        line, col = _line_col(data, bad_byte.start())
        raise SourceFileError(f"not LIG text (a control character at line {line}, column {col})", path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line, col = _line_col(data, exc.start)
        raise SourceFileError(f"not UTF-8 text (a bad byte at line {line}, column {col})", path) from None
    bad_char = _CONTROL_CHARS.search(text)
    if bad_char is not None:
        line, col = _text_line_col(text, bad_char.start())
        raise SourceFileError(f"not LIG text (a control character at line {line}, column {col})", path)
    return text.removeprefix("\ufeff")


@record
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
        """The LOAD statements, found before parsing: ``[(library, names or None, Pos of the quote), ...]``.

        Only a hint for the lexer (which loaded names are primitives); the
        parsed LOAD statements are what the checker acts on.
        """
        text = _BRACES.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), self.lexed)
        found = []
        for m in _LOAD.finditer(text):
            group = 1 if m.group(1) is not None else 3
            line, col = _text_line_col(text, m.start(group) - 1)
            pos = Pos(line, col, line, col + len(m.group(group)) + 2)
            names = None if group == 1 else [n.strip().upper() for n in m.group(2).split(",")]
            found.append((m.group(group), names, pos))
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
        raise LigDiagnostics(
            [
                Diagnostic(
                    filename,
                    Pos(line, col, line, col + 1),
                    f"the file is not valid UTF-8 (byte 0x{data[exc.start]:02x} at offset {exc.start})",
                    "save the file as UTF-8; a degree sign written by an old editor is a common cause",
                    source=shown,
                )
            ]
        ) from None
    text = text.removeprefix("\ufeff")
    return text


# Lines are what text.split("\n") gives (a "\r" stays in its line); with
# re.M, ^ and $ are exactly their ends.
_STAR_FLAG = re.compile(r"^\*", re.MULTILINE)
_COMMENT_LINE = re.compile(r"^[Cc](?:[ \t\r][^\n]*)?$", re.MULTILINE)


def prepare(text: str, filename: str) -> Source:
    """Blank column-1 ``*`` flags and ``C`` comment lines, keeping positions.

    The whole text is substituted at once: a list of a million lines cost
    more memory than the program's syntax tree.
    """
    warnings = []
    counted = [1, 0]  # line number at offset: lines are counted only up to a comment that warns

    def blank(match) -> str:
        if _LOOKS_LIKE_CODE.match(match.group()):
            counted[0] += text.count("\n", counted[1], match.start())
            counted[1] = match.start()
            number = counted[0]
            warnings.append(
                Diagnostic(
                    filename,
                    Pos(number, 1, number, 2),
                    "this line is a comment: a C in column 1 followed by a blank starts a comment line",
                    "indent the line if it is a statement about a variable called C",
                    severity="warning",
                )
            )
        # Blanks, not nothing: every character keeps its offset, so that a
        # position's offsets index the text as written (lang/ast.py's Pos).
        return " " * len(match.group())

    prepared = _STAR_FLAG.sub(" ", _COMMENT_LINE.sub(blank, text))
    return Source(filename, text, prepared, warnings)


# Each maximal run of blanks and {comments}, taken whole (possessive), so
# that joining is linear however long a run is.
_BLANKS = re.compile(r"(?:\s|\{[^}]*+\})++")


def _joined(match: re.Match) -> str:
    run = match.group()
    return " " if "\n" in run or "{" in run else run


def spelling(text: str, pos: Pos) -> str:
    """The program's own spelling of the construct at ``pos``, on one line and upper-cased.

    It is ``text[pos.start:pos.end]`` (the parser's offsets include the
    parentheses and sign around a construct), with the comments the lexer
    skips dropped: ``{...}``, and C comment lines and ``*`` flags as
    :func:`prepare` blanks them. A line break or a comment, with the blanks
    around it, becomes one space. A synthetic position spells "".

    Parameters
    ----------
    text : str
        The program text as written (``Source.text``).
    pos : Pos
        A position the parser made from that text.
    """
    start, end = pos.start, pos.end
    if not 0 <= start < end <= len(text):
        return ""
    # Whole lines, so that the comment-line rule sees each line as the lexer did.
    first = text.rfind("\n", 0, start) + 1
    last = text.find("\n", end)
    lines = text[first : len(text) if last < 0 else last]
    lines = _STAR_FLAG.sub(" ", _COMMENT_LINE.sub(lambda m: " " * len(m.group()), lines))
    return _BLANKS.sub(_joined, lines[start - first : end - first]).strip().upper()


def load(path: str, display_name: str | None = None) -> Source:
    """Read, decode and prepare a program file.

    Raises
    ------
    SourceFileError
        Not a regular file, or too large (see :func:`read_source_bytes`).
    LigDiagnostics
        Not UTF-8, or holding control characters: at the first bad one. Only
        a file that is text in some encoding has its line shown (a binary
        file's "line" is noise, or worse, terminal escapes).
    """
    data = read_source_bytes(path)
    name = display_name or path
    bad_byte = _CONTROL_BYTES.search(data)
    if bad_byte is not None:
        raise _binary(name, *_line_col(data, bad_byte.start()), data[bad_byte.start()])
    text = decode(data, name)
    bad_char = _CONTROL_CHARS.search(text)
    if bad_char is not None:
        raise _binary(name, *_text_line_col(text, bad_char.start()), ord(bad_char.group()))
    return prepare(text, name)


def _binary(filename: str, line: int, col: int, code: int) -> LigDiagnostics:
    return LigDiagnostics(
        [
            Diagnostic(
                filename,
                Pos(line, col, line, col + 1),
                f"the file holds a control character (U+{code:04X}), so it is not LIG text",
                "a LIG program is plain UTF-8 text; tab, line feed, form feed and carriage return are the only "
                "control characters it may hold",
            )
        ]
    )
