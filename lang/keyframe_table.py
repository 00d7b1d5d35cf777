"""The rows of a keyframe table (``TABLE 1, 2, ROOT`` then ``| frame x y z ...`` lines), read in bulk.

A table is one token (TABLE_ROWS), so a capture of 20,000 frames is not
two million tokens for the parser and two million constants for the
lowered module: its numbers are read here, all at once, by numpy, and the
lowered module carries them as one string.  The slow path, line by line,
runs only to say where a row is wrong.
"""

from __future__ import annotations

import re
import warnings
import zlib

import numpy as np

from .ast import Pos
from .numbers import MIN_FRAME_GAP

__all__ = ["TableProblem", "numbers_text", "pack", "parse_numbers", "read_rows", "unpack"]

# As text, compiled when a TABLE is first read (re keeps them): most programs have none.
_BAR = r"\|"
_CELL = r"\S+"


class TableProblem(Exception):
    """A row that is not right: ``pos`` is where, ``message`` and ``hint`` say what."""

    def __init__(self, pos: Pos, message: str, hint: str | None = None):
        super().__init__(message)
        self.pos, self.message, self.hint = pos, message, hint


def numbers_text(rows: str) -> str:
    """The rows' numbers, blank-separated: the token without its bars."""
    return re.sub(_BAR, " ", rows)


def read_rows(rows: str, pos: Pos, columns: int) -> np.ndarray:
    """The table's rows as an array of shape (rows, 1 + 3 * columns), checked.

    Parameters
    ----------
    rows : str
        The TABLE_ROWS token's text.
    pos : Pos
        Where it starts (for diagnostics).
    columns : int
        How many joints (and ROOT) the table lists.

    Raises
    ------
    TableProblem
        A cell that is not a finite number, a row with the wrong number of
        cells, frames that are negative, out of order or too close, or a
        first row whose frame is not 0.
    """
    width = 1 + 3 * columns
    flat = parse_numbers(numbers_text(rows))
    lines = rows.count("\n") + 1
    if flat is None or flat.size != lines * width or not np.isfinite(flat).all():
        _find_bad_cell(rows, pos, width)
    assert flat is not None  # _find_bad_cell raised otherwise
    data = flat.reshape(lines, width)
    frames = data[:, 0]
    if frames[0] != 0:
        raise TableProblem(
            _row_pos(rows, pos, 0), f"a table's first row is frame 0, its start position, not frame {frames[0]:g}"
        )
    gaps = np.diff(frames)
    bad = np.flatnonzero((gaps < 0) | ((gaps > 0) & (gaps < MIN_FRAME_GAP)) | (frames[1:] < 0))
    if len(bad):
        k = int(bad[0]) + 1
        raise TableProblem(
            _row_pos(rows, pos, k),
            f"frame {frames[k]:g} comes after frame {frames[k - 1]:g}; a table's frames go up",
            f"two rows share a frame (a step) or lie at least {MIN_FRAME_GAP:g} frames apart",
        )
    return data


def pack(rows: str) -> str:
    """The rows' numbers as the lowered module carries them: their text, deflated, in base 64 (about half the size)."""
    import base64  # here: a program without a TABLE (most) never needs it, and a cold check would pay 1 ms

    return base64.b64encode(zlib.compress(numbers_text(rows).encode("ascii", "replace"), 1)).decode("ascii")


def unpack(packed: str) -> np.ndarray | None:
    """The numbers of :func:`pack`, as a flat float array (None if they do not read)."""
    import base64

    return parse_numbers(zlib.decompress(base64.b64decode(packed)).decode("ascii"))


def parse_numbers(text: str) -> np.ndarray | None:
    """Blank-separated numbers as a float array, in bulk; None when a cell is not a number."""
    with warnings.catch_warnings():
        # numpy deprecates fromstring's binary mode, and warns when text ends in something unreadable.
        warnings.simplefilter("ignore")
        try:
            return np.fromstring(text, sep=" ")
        except ValueError:
            return None


def _row_pos(rows: str, pos: Pos, k: int) -> Pos:
    line = rows.split("\n")[k]
    col = (pos.column if k == 0 else 1) + len(line) - len(line.lstrip())
    return Pos(pos.line + k, col, pos.line + k, col + len(line.strip()))


def _find_bad_cell(rows: str, pos: Pos, width: int) -> None:
    """Raise for the first cell or row that is wrong (the slow path)."""
    for k, line in enumerate(rows.split("\n")):
        offset = pos.column - 1 if k == 0 else 0
        body = line.split("|", 1)[1] if "|" in line else line
        start = len(line) - len(body)
        cells = list(re.finditer(_CELL, body))
        for m in cells:
            try:
                ok = np.isfinite(float(m.group()))
            except ValueError:
                ok = False
            if not ok:
                col = offset + start + m.start() + 1
                raise TableProblem(
                    Pos(pos.line + k, col, pos.line + k, col + len(m.group())),
                    f"'{m.group()}' is not a finite number; every cell of a table is one",
                )
        if len(cells) != width:
            raise TableProblem(
                _row_pos(rows, pos, k),
                f"this row has {len(cells)} numbers; the table's rows have {width}",
                f"a row is its frame, then x y z for each of the table's {(width - 1) // 3} columns",
            )
    raise TableProblem(pos, "the table's rows could not be read")
