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
which URDF export reads back.  A link the source did not
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
        joint, rpy = (list(more) + [None, None])[:2]
        row = f"  {segment} {_quoted(name)}"
        if channels:
            row += " " + " ".join(channels)
        if end is not None:
            row += " END " + " ".join(repr(float(x) + 0.0) for x in end)
        if joint is not None:
            row += " JOINT " + _quoted(joint)
        if rpy is not None:
            row += " RPY " + " ".join(repr(float(x) + 0.0) for x in rpy)
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
    except ValueError:
        return None
    rest = m.group(3)
    joint = None
    jm = _JOINT.search(rest)
    if jm is not None:
        try:
            joint, _ = _DECODE.raw_decode(jm.group(1))
        except ValueError:
            return None
        rest = rest[: jm.start()] + rest[jm.end() :]
    words = rest.split()
    channels = []
    end = None
    rpy = None
    while words:
        w = words.pop(0)
        if w in CHANNELS and w not in channels and end is None:
            channels.append(w)
        elif w == "END" and end is None and len(words) >= 3:
            try:
                end = tuple(float(x) for x in words[:3])
            except ValueError:
                return None
            del words[:3]
        elif w == "RPY" and rpy is None and len(words) >= 3:
            try:
                rpy = tuple(float(x) for x in words[:3])
            except ValueError:
                return None
            del words[:3]
        else:
            return None
    if joint is None and rpy is None:
        return m.group(1).upper(), name, tuple(channels), end
    return m.group(1).upper(), name, tuple(channels), end, joint, rpy
