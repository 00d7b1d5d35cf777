"""A library's name table: the names its links had in the file they were imported from.

LIG names are letters, digits and ``_``; a BVH joint may be called
``mixamorig:Hips`` or ``thigh.L``.  ``liganimate import`` gives each link a
LIG name and writes, beside the model, a comment that the compiler reads
back, one row per link::

    {@names CAPTURE_FIGURE
      MIXAMORIG_HIPS "mixamorig:Hips" Xposition Yposition Zposition Zrotation Yrotation Xrotation
      MIXAMORIG_HEADTOP_END "mixamorig:HeadTop_End" Zrotation Yrotation Xrotation END 0 18.4 0
    }

A row is the segment's LIG name, its source name as a JSON string (any
character, ``}`` written ``\\u007d``), its BVH channels in the source's
order, and ``END x y z`` for a leaf's End Site.  A robot imported from
URDF adds ``JOINT "name"``, the URDF joint that attaches the link, and
``RPY r p y``, the URDF link frame's turn from the LIG link's (radians),
and for a mimic joint ``MIMIC "leader" multiplier offset``, which URDF
export reads back.  A link the source did not
have (the importer's ``ORIGIN``) has no row.  The table is a comment, so a
library with one still reads as before everywhere else; ``LOAD`` hands the
rows to the model's links (``Link.source``), and BVH and glTF export use
them (docs/exchange.md, "Names").
"""

from __future__ import annotations

import json
import re

__all__ = ["CHANNELS", "format_table", "read_tables"]

CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")

_TABLE = re.compile(r"\{@names[ \t]+([A-Za-z][A-Za-z0-9_]*)[ \t]*\n([^}]*)\}")
_ROW = re.compile(r"[ \t]*([A-Za-z][A-Za-z0-9_]*)[ \t]+(\"(?:[^\"\\\n]|\\.)*\")(.*)")
_JOINT = re.compile(r"[ \t]JOINT[ \t]+(\"(?:[^\"\\\n]|\\.)*\")")
_MIMIC = re.compile(r"[ \t]MIMIC[ \t]+(\"(?:[^\"\\\n]|\\.)*\")")
_DECODE = json.JSONDecoder()


def _quoted(name: str) -> str:
    return json.dumps(name, ensure_ascii=True).replace("}", "\\u007d").replace("{", "\\u007b")


def format_table(model: str, rows) -> str:
    """The comment text of one model's name table.

    Parameters
    ----------
    model : str
        The MODEL's LIG name.
    rows : iterable of (segment, source name, channels, end[, joint, rpy])
        ``channels`` a sequence of channel names, ``end`` None or 3 numbers,
        ``joint`` None or the attaching joint's source name, ``rpy`` None or
        3 numbers.

    Returns
    -------
    str
        ``{@names MODEL`` ... ``}``, ending with a newline.
    """
    out = [f"{{@names {model}"]
    for segment, name, channels, end, *more in rows:
        joint, rpy, mimic = (list(more) + [None, None, None])[:3]
        row = f"  {segment} {_quoted(name)}"
        if channels:
            row += " " + " ".join(channels)
        if end is not None:
            row += " END " + " ".join(repr(float(x) + 0.0) for x in end)
        if joint is not None:
            row += " JOINT " + _quoted(joint)
        if rpy is not None:
            row += " RPY " + " ".join(repr(float(x) + 0.0) for x in rpy)
        if mimic is not None:
            row += f" MIMIC {_quoted(mimic[0])} {float(mimic[1])!r} {float(mimic[2])!r}"
        out.append(row)
    out.append("}")
    return "\n".join(out) + "\n"


def read_tables(text: str) -> dict:
    """Every name table of a library text.

    Parameters
    ----------
    text : str

    Returns
    -------
    dict
        ``{MODEL: {SEGMENT: (source name, channels tuple, end tuple or None)}}``,
        with ``joint name or None, rpy tuple or None`` after them on a row
        that has either
        in capitals; rows that do not follow the format are left out (a
        table is a comment: it never stops a library from loading).
    """
    tables: dict = {}
    for m in _TABLE.finditer(text):
        rows = {}
        for line in m.group(2).split("\n"):
            row = _row(line)
            if row is not None:
                rows[row[0]] = row[1:]
        tables[m.group(1).upper()] = rows
    return tables


def _row(line: str):
    m = _ROW.fullmatch(line.rstrip())
    if m is None:
        return None
    try:
        name, _ = _DECODE.raw_decode(m.group(2))
        rest, joint, leader = _quoted_columns(m.group(3))
        channels, end, numbers = _columns(rest.split())
    except ValueError:
        return None
    rpy = numbers.get("RPY")
    mimic = None
    if "MIMIC" in numbers:
        if leader is None:
            return None
        mimic = (leader, *numbers["MIMIC"])
    if joint is None and rpy is None and mimic is None:
        return m.group(1).upper(), name, tuple(channels), end
    return m.group(1).upper(), name, tuple(channels), end, joint, rpy, mimic


def _quoted_columns(rest: str) -> tuple:
    """``JOINT "name"`` and ``MIMIC "leader"`` taken out of a row's tail: (rest, joint, leader).

    MIMIC's numbers stay behind its word for :func:`_columns`.
    """
    joint = leader = None
    for pattern in (_JOINT, _MIMIC):
        jm = pattern.search(rest)
        if jm is None:
            continue
        value, _ = _DECODE.raw_decode(jm.group(1))
        if pattern is _JOINT:
            joint, mark = value, " "
        else:
            leader, mark = value, " MIMIC"
        rest = rest[: jm.start()] + mark + rest[jm.end() :]
    return rest, joint, leader


_COUNTS = {"END": 3, "RPY": 3, "MIMIC": 2}  # the numbers each word takes


def _columns(words: list) -> tuple:
    """Channels, the End Site and the numbered columns (RPY, MIMIC) of a row; ValueError when malformed."""
    channels: list = []
    numbers: dict = {}
    while words:
        w = words.pop(0)
        if w in CHANNELS and w not in channels and "END" not in numbers:
            channels.append(w)
        elif w in _COUNTS and w not in numbers and len(words) >= _COUNTS[w]:
            numbers[w] = tuple(float(x) for x in words[: _COUNTS[w]])
            del words[: _COUNTS[w]]
        else:
            raise ValueError(w)
    return channels, numbers.pop("END", None), numbers
