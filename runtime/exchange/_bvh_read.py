"""Reading BVH files, with diagnostics that point at the line and column of what is wrong.

A BVH file is a HIERARCHY of joints (ROOT, JOINT, End Site; each with an
OFFSET and CHANNELS) followed by a MOTION section: ``Frames: N``, ``Frame
Time: t`` and N lines of channel values, one line per frame, in the order
the hierarchy lists its channels.  Anything else (a truncated file, a frame
with the wrong number of values, a value that is not a finite number, no
MOTION section) is a :class:`~liganimate.lang.diagnostics.LigDiagnostics`
error at its ``file:line:col``, never a Python exception.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import NoReturn

import numpy as np

from liganimate.lang.ast import Pos
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics
from liganimate.lang.numbers import GEOMETRY_MAX, MAX_ANGLE, magnitude

__all__ = ["CHANNEL_NAMES", "BvhClip", "parse_bvh", "read_bvh"]

CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
_CHANNEL_KEYS = {c.lower(): c for c in CHANNEL_NAMES}
_TOKEN = re.compile(r"\S+")


@dataclass
class BvhClip:
    """A parsed BVH file.

    Attributes
    ----------
    filename : str
    source : str
        The file's text (for diagnostics raised later, e.g. by the importer).
    names : list of str
        Joint names in the order the hierarchy lists them (depth first).
    parents : ndarray of int, shape (J,)
        Index of each joint's parent; -1 for the root.
    offsets : ndarray, shape (J, 3)
    channels : list of tuple of str
        Each joint's channel names, in file order.
    first : ndarray of int, shape (J,)
        Column of each joint's first channel in :attr:`data`.
    end_sites : list of (ndarray of shape (3,) or None)
        Each joint's End Site offset.
    channel_pos : list of Pos
        Where each joint's CHANNELS line is.
    offset_pos : list of Pos
        Where each joint's OFFSET keyword is (empty for a clip not read from a file).
    frame_time : float
        Seconds per frame.
    data : ndarray, shape (F, C)
        The channel values of every frame.
    """

    filename: str
    source: str
    names: list
    parents: np.ndarray
    offsets: np.ndarray
    channels: list
    first: np.ndarray
    end_sites: list
    channel_pos: list
    frame_time: float
    data: np.ndarray
    offset_pos: list = field(default_factory=list)

    def error(self, pos: Pos, message: str, hint: str | None = None) -> LigDiagnostics:
        """A diagnostic about this file (the caller raises it)."""
        return LigDiagnostics([Diagnostic(self.filename, pos, message, hint, source=self.source)])


def read_bvh(path: str) -> BvhClip:
    """Read and check a BVH file.

    Parameters
    ----------
    path : str

    Returns
    -------
    BvhClip

    Raises
    ------
    LigDiagnostics
        For any malformed content, at its line and column.
    OSError
        If the file cannot be read.
    """
    with open(path, "rb") as fh:
        raw = fh.read()
    # Windows editors save "Unicode" as UTF-16 with a byte order mark; old Mac files end lines with CR alone.
    encoding = "utf-16" if raw[:2] in (b"\xff\xfe", b"\xfe\xff") else "utf-8"
    text = raw.decode(encoding, errors="replace")
    text = text.removeprefix("\ufeff").replace("\r\n", "\n").replace("\r", "\n")
    return parse_bvh(text, path)


class _Tokens:
    """The hierarchy's tokens with their positions, line by line."""

    def __init__(self, text: str, filename: str):
        self.text = text
        self.filename = filename
        self.lines = text.split("\n")
        self.line = 0  # index of the next line to read
        self.pending: list = []  # tokens left on the current line: (text, Pos)

    def fail(self, pos: Pos, message: str, hint: str | None = None) -> NoReturn:
        raise LigDiagnostics([Diagnostic(self.filename, pos, message, hint, source=self.text)])

    def end_pos(self) -> Pos:
        """Just after the last character that is not blank (1:1 for an empty file)."""
        for i in range(len(self.lines) - 1, -1, -1):
            line = self.lines[i].rstrip()
            if line:
                return Pos(i + 1, len(line) + 1, i + 1, len(line) + 1)
        return Pos(1, 1, 1, 1)

    def _fill(self) -> bool:
        while not self.pending:
            if self.line >= len(self.lines):
                return False
            number = self.line + 1
            self.pending = [
                (m.group(), Pos(number, m.start() + 1, number, m.end() + 1))
                for m in _TOKEN.finditer(self.lines[self.line])
            ]
            self.line += 1
        return True

    def next(self, what: str):
        """The next token, or an error naming ``what`` was expected at the end of the file."""
        if not self._fill():
            self.fail(self.end_pos(), f"the file ends where {what} should come", "the file may have been cut short")
        return self.pending.pop(0)

    def peek(self):
        return self.pending[0] if self._fill() else None

    def rest_of_line(self) -> list:
        """The tokens left on the line of the last token read."""
        rest, self.pending = self.pending, []
        return rest

    def number(self, what: str) -> float:
        """The next token, which must be a finite number (``what`` names it in the error)."""
        return self._number(what)[0]

    def _number(self, what: str) -> tuple[float, str, Pos]:
        tok, pos = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            self.fail(pos, f"'{tok}' is not a number; {what} should be one")
        if not np.isfinite(value):
            self.fail(pos, f"{what} must be a finite number, not '{tok}'")
        return value, tok, pos

    def length(self, what: str) -> float:
        """A number that is a distance (an offset): finite and within the geometry limit."""
        value, tok, pos = self._number(what)
        if abs(value) > GEOMETRY_MAX:
            self.fail(
                pos,
                f"{what} is {tok}, beyond the limit of {magnitude(GEOMETRY_MAX)} units for anything drawn",
                "everything drawn must stay within 1E12 units of the origin along each axis",
            )
        return value

    def expect(self, word: str, what: str | None = None):
        tok, pos = self.next(f"'{word}'")
        if tok != word:
            self.fail(pos, f"expected '{word}'{' ' + what if what else ''}, found '{tok}'")
        return pos


def parse_bvh(text: str, filename: str = "<bvh>") -> BvhClip:
    """Parse BVH text (see :func:`read_bvh`)."""
    tk = _Tokens(text, filename)
    if tk.peek() is None:
        tk.fail(Pos(1, 1, 1, 1), "the file is empty, not a BVH file", "a BVH file starts with HIERARCHY")
    tok, pos = tk.next("HIERARCHY")
    if tok != "HIERARCHY":
        tk.fail(pos, f"a BVH file starts with HIERARCHY, not '{tok}'", "this does not look like a BVH file")
    tok, pos = tk.next("ROOT")
    if tok != "ROOT":
        tk.fail(pos, f"expected ROOT, the hierarchy's first joint, found '{tok}'")
    h = _Hierarchy(tk)
    h.joint(-1, pos)
    n_frames, frame_time = _motion_header(tk)
    counts = np.array([len(c) for c in h.channels], dtype=np.int64)
    first_col = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    data = _frames(tk, tk.line, n_frames, int(counts.sum()))
    _within_limits(tk, data, h)
    return BvhClip(
        filename=filename,
        source=text,
        names=h.names,
        parents=np.array(h.parents, dtype=np.int64),
        offsets=np.array(h.offsets, dtype=np.float64).reshape(-1, 3),
        channels=h.channels,
        first=first_col,
        end_sites=h.end_sites,
        channel_pos=h.channel_pos,
        frame_time=frame_time,
        data=data,
        offset_pos=h.offset_pos,
    )


class _Hierarchy:
    """The joints of a HIERARCHY section, read recursively from the tokens."""

    def __init__(self, tk: _Tokens):
        self.tk = tk
        self.names: list = []
        self.parents: list = []
        self.offsets: list = []
        self.channels: list = []
        self.channel_pos: list = []
        self.offset_pos: list = []
        self.end_sites: list[np.ndarray | None] = []

    def joint(self, parent: int, keyword_pos: Pos) -> None:
        """One ROOT or JOINT, its keyword just read, to its closing brace, with every joint inside it.

        Iterative, with a stack of the open joints: a chain of 10,000 joints
        is as legal as a skeleton of 20 (Python's recursion stops near 1,000).
        """
        tk = self.tk
        open_joints = [self._open(parent, keyword_pos)]
        while open_joints:
            me = open_joints[-1]
            name = self.names[me]
            tok, pos = tk.next(f"'}}' to close joint {name}")
            if tok == "JOINT":
                open_joints.append(self._open(me, pos))
            elif tok == "End":
                self._end_site(me)
            elif tok == "}":
                open_joints.pop()
            elif tok in ("MOTION", "ROOT"):
                tk.fail(pos, f"joint {name} is never closed with '}}' before {tok}")
            else:
                tk.fail(pos, f"expected JOINT, End Site or '}}' in joint {name}, found '{tok}'")

    def _open(self, parent: int, keyword_pos: Pos) -> int:
        """A joint's name, '{', OFFSET and CHANNELS, its keyword just read: its index."""
        tk = self.tk
        rest = tk.rest_of_line()
        if not rest:
            tk.fail(keyword_pos, "this joint has no name", "write ROOT name or JOINT name")
        self.names.append(" ".join(t for t, _ in rest))
        me = len(self.names) - 1
        name = self.names[me]
        self.parents.append(parent)
        tk.expect("{", f"to open joint {name}")
        tok, pos = tk.next(f"OFFSET of joint {name}")
        if tok != "OFFSET":
            tk.fail(pos, f"expected OFFSET in joint {name}, found '{tok}'")
        self.offset_pos.append(pos)
        self.offsets.append([tk.length(f"the {a} offset of joint {name}") for a in "XYZ"])
        self.end_sites.append(None)
        self._channels(name)
        return me

    def _channels(self, name: str) -> None:
        tk = self.tk
        tok, pos = tk.next(f"CHANNELS of joint {name}")
        if tok != "CHANNELS":
            tk.fail(pos, f"expected CHANNELS in joint {name}, found '{tok}'")
        count_tok, count_pos = tk.next("the number of channels")
        try:
            count = int(count_tok)
        except ValueError:
            tk.fail(count_pos, f"the number of channels must be a whole number, not '{count_tok}'")
        listed = tk.rest_of_line()
        if count < 0 or count != len(listed):
            tk.fail(
                count_pos,
                f"CHANNELS says {count_tok} but the line lists {len(listed)} channels",
                "list the channel names on the CHANNELS line itself",
            )
        seen: list = []
        for channel, npos in listed:
            canonical = _CHANNEL_KEYS.get(channel.lower())
            if canonical is None:
                tk.fail(npos, f"'{channel}' is not a BVH channel", "the channels are " + ", ".join(CHANNEL_NAMES))
            if canonical in seen:
                tk.fail(npos, f"joint {name} lists channel {canonical} twice")
            seen.append(canonical)
        self.channels.append(tuple(seen))
        self.channel_pos.append(count_pos)

    def _end_site(self, me: int) -> None:
        tk = self.tk
        site, spos = tk.next("'Site'")
        if site != "Site":
            tk.fail(spos, f"expected 'End Site', found 'End {site}'")
        tk.expect("{", "to open the End Site")
        tk.expect("OFFSET", "in the End Site")
        self.end_sites[me] = np.array([tk.length(f"the {a} offset of an End Site") for a in "XYZ"])
        tk.expect("}", "to close the End Site")


def _motion_header(tk: _Tokens) -> tuple:
    """``MOTION``, ``Frames: N`` and ``Frame Time: t`` after the hierarchy: (N, t)."""
    if tk.peek() is None:
        tk.fail(
            tk.end_pos(),
            "the file has no MOTION section",
            "a BVH file needs MOTION, then 'Frames: N', 'Frame Time: t' and N lines of channel values",
        )
    tok, pos = tk.next("MOTION")
    if tok == "ROOT":
        tk.fail(pos, "this file has several ROOT joints; liganimate imports one skeleton per file")
    if tok != "MOTION":
        tk.fail(pos, f"expected MOTION after the hierarchy, found '{tok}'")
    tok, pos = tk.next("'Frames:'")
    if tok == "Frames:":
        ntok, npos = tk.next("the number of frames")
    elif tok.startswith("Frames:") and len(tok) > 7:
        ntok, npos = tok[7:], Pos(pos.line, pos.column + 7, pos.line, pos.end_column)
    else:
        tk.fail(pos, f"expected 'Frames:' after MOTION, found '{tok}'")
    try:
        n_frames = int(ntok)
    except ValueError:
        tk.fail(npos, f"the number of frames must be a whole number, not '{ntok}'")
    if n_frames <= 0:
        tk.fail(npos, f"the file has {n_frames} frames, so there is no motion to import")
    tok, pos = tk.next("'Frame Time:'")
    tok2, pos2 = tk.next("'Time:'")
    if tok != "Frame" or tok2 != "Time:":
        tk.fail(pos, f"expected 'Frame Time:' after the number of frames, found '{tok} {tok2}'")
    frame_time = tk.number("the frame time")
    if frame_time <= 0:
        tk.fail(pos2, f"the frame time must be positive, not {frame_time:g} seconds")
    if tk.pending:
        extra, epos = tk.pending[0]
        tk.fail(epos, f"unexpected '{extra}' after the frame time", "the frame values start on the next line")
    return n_frames, frame_time


def _frames(tk: _Tokens, start: int, n_frames: int, n_channels: int) -> np.ndarray:
    """The frame lines from line index ``start`` on, as an (F, C) array, checked."""
    rows = [(i, line) for i, line in enumerate(tk.lines[start:], start) if line.strip()]
    if len(rows) > n_frames:
        i = rows[n_frames][0]
        tk.fail(
            Pos(i + 1, 1, i + 1, 2),
            f"there are more frame lines than the {n_frames} that 'Frames: {n_frames}' announces",
            "correct the Frames: line, or remove the extra lines",
        )
    split = [line.split() for _, line in rows]
    counts = np.fromiter(map(len, split), dtype=np.int64, count=len(split))
    bad = np.flatnonzero(counts != n_channels)
    if len(bad):
        k = int(bad[0])
        i, line = rows[k]
        last = k == len(rows) - 1 and len(rows) == n_frames
        cols = [m for m in _TOKEN.finditer(line)]
        if counts[k] > n_channels:
            m = cols[n_channels]
            where = Pos(i + 1, m.start() + 1, i + 1, m.end() + 1)
        else:
            end = len(line.rstrip()) + 1
            where = Pos(i + 1, end, i + 1, end)
        if last and counts[k] < n_channels:
            tk.fail(
                where,
                f"the file ends in the middle of frame {k + 1}: it has {counts[k]} of its {n_channels} values",
                "the file may have been cut short",
            )
        tk.fail(
            where,
            f"frame {k + 1} has {counts[k]} values, but the hierarchy's channels need {n_channels}",
            "each frame is one line with one value per channel, in the order the hierarchy lists them",
        )
    if len(rows) < n_frames:
        tk.fail(
            tk.end_pos(),
            f"the file ends after {len(rows)} of the {n_frames} frames that 'Frames: {n_frames}' announces",
            "the file may have been cut short; re-export it, or correct the Frames: line",
        )
    flat = [t for toks in split for t in toks]
    try:
        values = np.fromiter(map(float, flat), dtype=np.float64, count=len(flat))
    except ValueError:
        values = None
    if values is None or not np.isfinite(values).all():
        for k, toks in enumerate(split):
            for n, t in enumerate(toks):
                try:
                    ok = np.isfinite(float(t))
                except ValueError:
                    ok = False
                if not ok:
                    i, line = rows[k]
                    m = list(_TOKEN.finditer(line))[n]
                    tk.fail(
                        Pos(i + 1, m.start() + 1, i + 1, m.end() + 1),
                        f"'{t}' in frame {k + 1} is not a finite number",
                        "every channel value must be a number such as -12.5",
                    )
        raise AssertionError("a frame value is not a finite number, yet every token is one")
    return values.reshape(n_frames, n_channels)


def _within_limits(tk: _Tokens, data: np.ndarray, h: _Hierarchy) -> None:
    """Refuse, at its line and column, a frame value a model cannot hold.

    A position channel moves the skeleton, so it is held to the geometry
    limit (1E12 units from the origin); a rotation channel becomes a keyframe
    angle, held to the largest angle (1E9 degrees). A value near 1E308 used
    to overflow while the library was written, and LOAD refused the library.
    """
    kinds = [(c, name) for name, channels in zip(h.names, h.channels) for c in channels]
    if not kinds:
        return
    caps = np.array([GEOMETRY_MAX if c.endswith("position") else MAX_ANGLE for c, _ in kinds])
    over = np.abs(data) > caps
    if not over.any():
        return
    k, n = (int(i) for i in np.argwhere(over)[0])
    channel, joint = kinds[n]
    rows = [(i, line) for i, line in enumerate(tk.lines[tk.line :], tk.line) if line.strip()]
    i, line = rows[k]
    m = list(_TOKEN.finditer(line))[n]
    unit = "units from the origin" if channel.endswith("position") else "degrees"
    tk.fail(
        Pos(i + 1, m.start() + 1, i + 1, m.end() + 1),
        f"'{m.group()}' in frame {k + 1} ({channel} of joint {joint}) is beyond the limit of "
        f"{magnitude(caps[n])} {unit}",
        "a position must stay within 1E12 units of the origin and an angle within 1E9 degrees",
    )
