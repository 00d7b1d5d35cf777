"""Program text made safe and readable for a terminal.

A diagnostic echoes text the user (or an attacker) wrote: a source line, a
file name, a name or a quoted word inside the message. Control characters
in it (an ESC sequence, a carriage return, a right-to-left override) would
otherwise be executed by the terminal, so they are shown as escapes such as
``\\x1b`` or ``\\u202e``. A source line is cut to a window around the caret
so that a 50 MB line prints one short line, and the caret is placed by
display columns, so it stays under the right character after escapes,
tabs and wide (CJK) characters.
"""

from __future__ import annotations

import functools
import re
import unicodedata

#: Display columns of a source line shown around the caret (plus the … marks).
MAX_COLUMNS = 100
#: Columns kept before the caret when a line is cut.
LEFT_CONTEXT = 40
#: Characters of a message, hint or file name kept; the middle of a longer one is cut.
MAX_TEXT = 400

# Controls (C0, DEL, C1), format characters (bidi overrides and isolates,
# zero-width joiners, BOM), line and paragraph separators, and lone
# surrogates (a file name undecodable in the locale).
_ESCAPED_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Zl", "Zp"})
_COMBINING = frozenset({"Mn", "Me"})
_SKIP_LINES = 1000
_SKIP = re.compile(r"(?:[^\n]*\n){" + str(_SKIP_LINES) + "}")
_NON_BLANK = re.compile(r"\S")


def _escape(ch: str) -> str:
    o = ord(ch)
    if o < 0x100:
        return f"\\x{o:02x}"
    if o < 0x10000:
        return f"\\u{o:04x}"
    return f"\\U{o:08x}"


@functools.lru_cache(maxsize=4096)
def cell(ch: str, tab: str = " ") -> tuple:
    """How one character is shown: ``(text, display columns)``.

    A tab is shown as ``tab`` (one blank in a source line, so columns count
    it as one character as the lexer does); controls are escaped; combining
    marks take no column; East Asian wide and fullwidth characters take two.
    """
    if ch == "\t":
        return tab, len(tab)
    category = unicodedata.category(ch)
    if category in _ESCAPED_CATEGORIES:
        text = _escape(ch)
        return text, len(text)
    if category in _COMBINING:
        return ch, 0
    if unicodedata.east_asian_width(ch) in ("W", "F"):
        return ch, 2
    return ch, 1


def escape_text(text: str, limit: int = MAX_TEXT) -> str:
    """``text`` with every control character escaped and its middle cut past ``limit`` characters."""
    if len(text) > limit:
        keep = limit // 4
        text = text[: limit - keep] + "…" + text[-keep:]
    return "".join(cell(ch, "\\t")[0] for ch in text)


def render_line(line: str, column: int, width: int = 1) -> tuple:
    """The source line as shown and the caret line under it.

    Parameters
    ----------
    line : str
        One source line, without its line break.
    column : int
        1-based character column of the caret; ``len(line) + 1`` points
        just after the last character.
    width : int
        Characters the caret underlines (at least one is marked).

    Returns
    -------
    (shown, caret) : tuple of str
        ``shown`` has at most about MAX_COLUMNS display columns, with ``…``
        where the line was cut; ``caret`` is blanks, ``^`` and ``~`` up to the
        end of the shown window.
    """
    c0 = min(max(column - 1, 0), len(line))
    # Every character takes at most one column more than nothing, and most take
    # one, so this many characters either side always fill the window.
    lo = max(0, c0 - MAX_COLUMNS)
    hi = min(len(line), c0 + MAX_COLUMNS + 1)
    cells = [cell(ch) for ch in line[lo:hi]]
    starts = []
    total = 0
    for _, w in cells:
        starts.append(total)
        total += w
    k = c0 - lo
    caret = starts[k] if k < len(cells) else total
    end_k = min(len(cells), k + max(1, width))
    caret_end = starts[end_k] if end_k < len(cells) else total
    if lo == 0 and hi == len(line) and total <= MAX_COLUMNS:
        a, b = 0, total
    else:
        a = max(0, caret - LEFT_CONTEXT)
        b = a + MAX_COLUMNS
        if b > total:
            b = total
            a = max(0, b - MAX_COLUMNS)
    shown = [i for i in range(len(cells)) if starts[i] >= a and starts[i] + cells[i][1] <= b]
    first = shown[0] if shown else k
    left_mark = lo > 0 or first > 0
    right_mark = hi < len(line) or (shown[-1] if shown else k - 1) < len(cells) - 1
    text = "".join(cells[i][0] for i in shown)
    origin = starts[first] if first < len(cells) else total
    indent = (1 if left_mark else 0) + max(0, caret - origin)
    # The underline ends where the shown text ends (a cut escape is not shown).
    shown_end = starts[shown[-1]] + cells[shown[-1]][1] if shown else caret
    underline = max(1, min(caret_end, shown_end) - caret)
    return (("…" if left_mark else "") + text + ("…" if right_mark else ""), " " * indent + "^" + "~" * (underline - 1))


# The last look-up: (source, line number, offset of that line). One tuple,
# replaced whole, so that threads formatting diagnostics never mix two.
_memo: tuple = (None, 1, 0)


def line_start(source: str, number: int):
    """Offset of the first character of line ``number`` (1-based, lines end at ``\\n``), or None.

    Lines are counted at ``\\n`` only, as the lexer counts them (form feeds
    and U+2028 do not end a line). Successive look-ups in one source resume
    from the previous one, so printing many diagnostics in order stays linear.
    """
    global _memo
    memo = _memo
    if memo[0] is source and memo[1] <= number:
        k, i = memo[1], memo[2]
    else:
        k, i = 1, 0
    while number - k >= _SKIP_LINES:
        m = _SKIP.match(source, i)
        if m is None:
            break
        i, k = m.end(), k + _SKIP_LINES
    while k < number:
        j = source.find("\n", i)
        if j < 0:
            return None
        i, k = j + 1, k + 1
    _memo = (source, number, i)
    return i


def source_line(source: str, number: int):
    """Line ``number`` of ``source`` without its line break (and a CR before it), or None."""
    start = line_start(source, number)
    if start is None:
        return None
    end = source.find("\n", start)
    line = source[start:] if end < 0 else source[start:end]
    return line.removesuffix("\r")


def last_line(source: str):
    """``(number, text)`` of the last line that is not blank, or None for a blank source."""
    end = len(source.rstrip())
    if end == 0:
        return None
    number = source.count("\n", 0, end) + 1
    return number, source_line(source, number).rstrip()


def at_end(source: str, number: int) -> bool:
    """Whether line ``number`` is past the text: it does not exist, or it and all after it are blank."""
    start = line_start(source, number)
    return start is None or _NON_BLANK.search(source, start) is None
