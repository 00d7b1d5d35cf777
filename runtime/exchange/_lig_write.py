"""BVH import: a capture as a LIG library, a MODEL whose joints follow the BVH hierarchy and a MOTION.

The model (``docs/exchange.md`` has the whole mapping):

* its main link is ``ORIGIN``, an empty segment at the origin;
* BVH joint number ``n`` (1-based, in the order the file lists them, ROOT
  first) becomes ``JOINT n``: its secondary is a segment named after the BVH
  joint, its primary the segment of the BVH parent (``ORIGIN`` for the
  ROOT), at the BVH OFFSET (the ROOT at the origin); every axis is free,
  extremes ``(-180, 180)``;
* each segment is drawn as thin boxes from its joint to each child joint and
  to its End Site.

The motion has the captured frames as keyframes: frame ``f`` of the file is
``FRAME f`` (frame 0 the starting position), LINEAR.  Rotation channels in
the order ``Zrotation Yrotation Xrotation`` (or any part of it) are the
joint convention ``Rz Ry Rx`` already and are copied; any other order is
turned into a rotation matrix and back into ``Rz Ry Rx`` angles, exactly.
The ROOT's position channels are its path, written as the motion's ROOT
track (one keyframe per frame), which ANIMATE follows; :func:`read_root_path`
reads it back.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass

import numpy as np

from liganimate.compiler.names import reserved
from liganimate.lang import name_table
from liganimate.lang.numbers import GEOMETRY_MAX, magnitude
from liganimate.runtime.motion.algebra import Motion
from liganimate.runtime.motion.keyframe import Keyframe

from ._clip import clip_pose, clip_size
from ._heading import split_heading
from ._numbers import format_rows

__all__ = [
    "ImportOptions",
    "clip_angles",
    "comment_text",
    "import_library",
    "lig_library",
    "motion_library",
    "read_root_path",
    "reduce_keyframes",
]

DECIMALS = 7
# Keywords and built-ins (compiler/names.py, read from the grammar), and the
# segment name the writers give a figure's empty root.
_RESERVED = reserved() | {"ORIGIN"}


def _identifier(name: str, taken: set) -> str:
    """A LIG name for a BVH joint name: letters, digits and _, starting with a letter, unique, not a keyword."""
    base = re.sub(r"[^A-Za-z0-9_]", "_", name).upper().strip("_") or "JOINT"
    if not base[0].isalpha():
        base = "J_" + base
    if base in _RESERVED:
        base += "_"
    candidate, n = base, 1
    while candidate in taken or candidate in _RESERVED:
        n += 1
        candidate = f"{base}_{n}"
    taken.add(candidate)
    return candidate


def clip_angles(clip, joint_translation: str = "error"):
    """The joint convention's angles, the root path and the rest offsets of a BVH clip.

    ``(angles, rotating, path, offsets)`` of :func:`._clip.clip_pose`, which
    documents them and what it raises.
    """
    pose = clip_pose(clip, joint_translation)
    return pose.angles, pose.rotating, pose.path, pose.offsets


def _num(x: float) -> str:
    x = float(x) + 0.0
    return repr(x)


def _bone(tip: np.ndarray, width: float) -> str:
    """A BOX from the segment's origin to ``tip``: along +Y, turned about Z then Y onto the tip."""
    length = float(np.linalg.norm(tip))
    d = tip / length
    alpha = -math.degrees(math.acos(max(-1.0, min(1.0, float(d[1])))))
    h = math.hypot(float(d[0]), float(d[2]))
    beta = math.degrees(math.atan2(-float(d[2]), float(d[0]))) if h > 1e-12 else 0.0
    return (
        f"(BOX AT (0.0, {_num(length / 2)}, 0.0), WIDTH {_num(width)}, HEIGHT {_num(length)}, "
        f"DEPTH {_num(width)}) <ROT Z {_num(alpha)}, ROT Y {_num(beta)}>"
    )


def comment_text(text: str) -> str:
    """Text safe inside a brace comment and on one line."""
    return re.sub(r"[{}\x00-\x1f\x7f]", "?", text)


@dataclass(frozen=True)
class ImportOptions:
    """How ``liganimate import`` turns a capture into a library.

    Attributes
    ----------
    model, motion : str
        The variable names (valid LIG names, checked by the caller).
    source_name : str, optional
        The BVH file's name as the comments mention it.
    tolerance : float
        Degrees.  0 keeps a keyframe at every frame; a positive tolerance
        drops the keyframes that the motion, as LIG plays it, can do without
        while every angle at every frame stays within ``tolerance`` of the
        captured one (see :func:`reduce_keyframes`).
    joint_translation : {"error", "drop"}
        What to do with joints other than the ROOT that slide
        (:func:`._clip.clip_pose`).
    """

    model: str = "CAPTURE"
    motion: str = "CAPTURED"
    source_name: str | None = None
    tolerance: float = 0.0
    joint_translation: str = "error"


def lig_library(
    clip, model: str = "CAPTURE", motion: str = "CAPTURED", source_name: str | None = None, tolerance: float = 0.0
) -> bytes:
    """The text of a LIG library holding a BVH clip's skeleton as a MODEL and its frames as a MOTION.

    The parameters are :class:`ImportOptions`' (see :func:`import_library`,
    which also returns the notes).

    Returns
    -------
    bytes
        UTF-8 text that ``LOAD model, motion FROM 'file.lig'`` takes.
    """
    return import_library(clip, ImportOptions(model, motion, source_name, tolerance))[0]


def import_library(clip, options: ImportOptions) -> tuple:
    """A BVH clip as a library: ``(UTF-8 text, notes)``.

    The model's segments are named after the BVH joints (:func:`_identifier`)
    and a name table (``lang/name_table.py``) keeps the BVH names and
    channels, so that export writes them back.

    Raises
    ------
    LigDiagnostics
        From :func:`._clip.clip_pose` (a sliding joint, with ``error``).
    """
    pose = clip_pose(clip, options.joint_translation)
    _refuse_beyond_reach(clip, pose.offsets)
    taken = {options.model.upper(), options.motion.upper()}
    links = [_identifier(n, taken) for n in clip.names]
    src = comment_text(options.source_name or os.path.basename(clip.filename))
    parts = [
        "\n".join(_header(clip, options, links, src)),
        _model_text(clip, options.model, options.motion, links, pose.offsets),
        name_table.format_table(options.model, _name_rows(clip, links)),
    ]
    head = ("\n".join(parts) + "\n").encode("utf-8")
    # The hips' turn about up is the motion's ROOT ORIENTATION, so that + continues it.
    angles, orientation = split_heading(clip.parents, pose.angles)
    keep = reduce_keyframes(angles, options.tolerance) if options.tolerance > 0 else None
    body = _motion_text(options.motion, angles, pose.rotating, keep, pose.path, orientation=orientation)
    return head + body, list(pose.notes)


def _refuse_beyond_reach(clip, offsets: np.ndarray) -> None:
    """Refuse, at the BVH OFFSET that passes it, a skeleton the model could not hold.

    A model is measured as LOAD measures it (``runtime/limits.py``): every
    joint location at full length, as if in one straight line, plus the
    largest segment, within the geometry limit; the segments here are the
    bones :func:`_model_text` draws (no longer than a tip plus its width).
    Refused here, a library that LOAD would refuse is never written.
    """
    with np.errstate(all="ignore"):
        size = clip_size(clip.parents, offsets)
        tips = [np.asarray(t, dtype=np.float64) for t in offsets[1:]]
        tips += [np.asarray(e, dtype=np.float64) for e in clip.end_sites if e is not None]
        bone = max((1.06 * float(np.linalg.norm(t)) + 0.01 * size for t in tips), default=0.0)
        running = math.sqrt(3.0) * bone
        for j in range(1, len(offsets)):
            running += math.sqrt(3.0) * float(np.max(np.abs(offsets[j])))
            if not running <= GEOMETRY_MAX and j < len(clip.offset_pos):
                raise clip.error(
                    clip.offset_pos[j],
                    f"the skeleton reaches {magnitude(running)} units at joint {clip.names[j]}, counting its "
                    f"offsets end to end, beyond the limit of {magnitude(GEOMETRY_MAX)} units for a model",
                    "a model must stay within 1E12 units of the origin in every pose; scale the capture down",
                )


def _header(clip, options: ImportOptions, links: list, src: str) -> list:
    """The comment lines that open the library: what it holds and the joint table."""
    F, J = clip.data.shape[0], len(clip.names)
    fps = 1.0 / clip.frame_time
    model, motion = options.model, options.motion
    out = [
        f"C {model}, {motion}: imported by liganimate from {src}",
        f"C {J} joints, {F} frames at {fps:g} frames per second (frame time {clip.frame_time:g} s).",
        "C",
        "C The model's main link is ORIGIN, an empty segment at the origin. BVH joint n, in the",
        "C order the file lists them (ROOT first), is JOINT n; its segment is named after it.",
        "C Every axis of every joint is free, (-180, 180). Frame f of the file is FRAME f of the",
        f"C motion (frame 0 is its starting position). Play it with ANIMATE ... USING {motion}; for",
        "C real time render with --fps matching the capture.",
        "C",
        "C The ROOT's path is the motion's ROOT track: ANIMATE carries the figure along it, in",
        "C the model's own frame, after the placement (see docs/exchange.md); the ROOT's turn",
        "C about Y, from the first frame's, is its ROOT ORIENTATION, and JOINT 1 the rest. The {@names}",
        "C table after the model keeps the BVH names and channels for export.",
        "C",
        "C   joint  segment            BVH joint (channels)",
    ]
    for j in range(J):
        out.append(
            f"C   {j + 1:<5}  {links[j]:<18} {comment_text(clip.names[j])} ({' '.join(clip.channels[j]) or 'none'})"
        )
    kept = "one keyframe per frame" if options.tolerance <= 0 else f"keyframes within {options.tolerance:g} degrees"
    out += [
        "",
        f"{{@ {model}: the skeleton of {src}, {J} joints, every axis free }}",
        f"{{@ {motion}: {F} frames of {src} at {fps:g} frames per second, {kept} }}",
        "",
    ]
    return out


def _model_text(clip, model: str, motion: str, links: list, offsets: np.ndarray) -> str:
    """GRAPHICAL, MODEL and MOTION declarations, the segments' bones, and STARTMODEL ... ENDMODEL."""
    J = len(links)
    size = clip_size(clip.parents, offsets)
    out = ["      GRAPHICAL ORIGIN"]
    for k in range(0, J, 6):
        out.append("      GRAPHICAL " + ", ".join(links[k : k + 6]))
    out += [f"      MODEL {model}", f"      MOTION {motion}", ""]
    children: dict = {j: [] for j in range(J)}
    for j in range(1, J):
        children[int(clip.parents[j])].append(j)
    for j in range(J):
        tips = [offsets[c] for c in children[j]]
        if clip.end_sites[j] is not None:
            tips.append(clip.end_sites[j])
        tips = [t for t in tips if np.linalg.norm(t) > 1e-9 * size]
        if not tips:
            continue
        bones = [_bone(np.asarray(t, dtype=np.float64), 0.06 * float(np.linalg.norm(t)) + 0.01 * size) for t in tips]
        out.append(f"      {links[j]} :- " + " +\n          ".join(bones))
    out += ["", f"      STARTMODEL {model}"]
    free = "(-180.0, 180.0), (-180.0, 180.0), (-180.0, 180.0)"
    for j in range(J):
        parent = "ORIGIN" if j == 0 else links[int(clip.parents[j])]
        o = (0.0, 0.0, 0.0) if j == 0 else offsets[j]
        out.append(
            f"        JOINT {j + 1}, {parent}, ({_num(o[0])}, {_num(o[1])}, {_num(o[2])}), "
            f"{links[j]}, (0.0, 0.0, 0.0), {free}"
        )
    out += ["      ENDMODEL", ""]
    return "\n".join(out)


def _name_rows(clip, links: list) -> list:
    rows = []
    for j, name in enumerate(clip.names):
        end = clip.end_sites[j]
        rows.append((links[j], name, clip.channels[j], None if end is None else tuple(float(x) for x in end)))
    return rows


def _motion_text(
    name: str, angles: np.ndarray, rotating: np.ndarray, keep=None, path=None, ids=None, orientation=None
) -> bytes:
    """STARTMOTION ... ENDMOTION: keyframes at every frame (or at ``keep[j]``) for every joint that moves.

    ``path`` (F, 3), if given, is the ROOT track: its start position, then a
    keyframe at every frame if it moves.  ``ids`` are the joints' identifiers
    (default 1, 2, ...).  ``orientation`` (F, 3), if given, is the ROOT
    ORIENTATION track, written as the path is.  With a keyframe at every frame (``keep`` None) the
    moving tracks go into one keyframe table (``TABLE``, docs/language.md
    4.8), a row a frame; with ``keep``, each joint lists its own keyframes.
    """
    F, J = angles.shape[:2]
    parts = [f"      STARTMOTION {name}\n".encode("ascii")]
    moving = (angles != angles[:1]).any(axis=(0, 2)) if F > 1 else np.zeros(J, dtype=bool)
    if F > 1 and not moving.any():
        moving[0] = True  # keep the motion's length: one joint carries every frame
    ids = list(range(1, J + 1)) if ids is None else list(ids)
    table = keep is None and F > 1
    frames = np.arange(1, F, dtype=np.float64)
    parts += _joint_entries(angles, rotating, moving, ids, keep, table)
    columns = [angles[:, j] for j in range(J) if moving[j]] if table else []
    names = [str(ids[j]) for j in range(J) if moving[j]] if table else []
    for word, track in (("ROOT", path), ("ROOT ORIENTATION", orientation)):
        if track is None:
            continue
        if table and F > 1 and bool((track != track[:1]).any()):
            columns.append(track)
            names.append(word)
            continue
        parts.append(format_rows(track[:1], DECIMALS, sep=",", prefix=f"        {word} POSITION", suffix="\n"))
        if F > 1 and bool((track != track[:1]).any()):
            parts.append(_keyframe_rows(frames, track[1:]))
    if table:
        parts.append(_table_text(names, np.arange(F, dtype=np.float64), columns))
    parts.append(b"      ENDMOTION\n")
    return b"".join(parts)


def _joint_entries(angles, rotating, moving, ids: list, keep, table: bool) -> list:
    """``JOINT n POSITION ...`` and its keyframe lines for each joint not in the table."""
    frames = np.arange(1, len(angles), dtype=np.float64)
    parts = []
    for j in range(angles.shape[1]):
        if not rotating[j] and not moving[j] or (table and moving[j]):
            continue
        start = format_rows(angles[:1, j], DECIMALS, sep=",", prefix=f"        JOINT {ids[j]} POSITION", suffix="\n")
        parts.append(start)
        if moving[j]:
            rows = keep[j][keep[j] > 0]
            parts.append(_keyframe_rows(frames[rows - 1], angles[rows, j]))
    return parts


def _table_text(names: list, frames: np.ndarray, columns: list) -> bytes:
    """``TABLE 1, 2, ROOT`` and one ``| frame x y z ...`` row per frame (lang/keyframe_table.py)."""
    head = [f"        TABLE {', '.join(names[:12])}"]
    for k in range(12, len(names), 12):
        head[-1] += ","
        head.append("              " + ", ".join(names[k : k + 12]))
    legend = "frame, then x y z of " + ", ".join(n if n.startswith("ROOT") else f"JOINT {n}" for n in names)
    head.append(f"{{ {legend} }}")
    table = np.column_stack([frames] + columns)
    rows = format_rows(table, [0] + [DECIMALS] * (table.shape[1] - 1), prefix="          |", suffix="\n")
    return ("\n".join(head) + "\n").encode("ascii") + rows


def motion_library(
    name: str,
    angles: np.ndarray,
    ids: list,
    path: np.ndarray,
    comments: list,
    tolerance: float = 0.0,
    orientation: np.ndarray | None = None,
) -> bytes:
    """A library holding one MOTION: ``comments`` (lines) first, then its declaration and keyframes.

    Parameters
    ----------
    name : str
    angles : ndarray, shape (F, J, 3)
        Per frame, the angles of joints ``ids``.
    ids : list of int
    path : ndarray, shape (F, 3)
        The ROOT track.
    comments : list of str
        Written as ``C`` lines (made safe for a brace comment).
    tolerance : float
        As :class:`ImportOptions`'.
    orientation : ndarray, shape (F, 3), optional
        The ROOT ORIENTATION track (degrees, unwrapped along the frames).
    """
    head = [("C " + comment_text(c)).rstrip() for c in comments]
    head += ["", f"      MOTION {name}", ""]
    keep = reduce_keyframes(angles, tolerance) if tolerance > 0 else None
    rotating = np.ones(angles.shape[1], dtype=bool)
    body = _motion_text(name, angles, rotating, keep, path, ids, orientation)
    return ("\n".join(head) + "\n").encode("utf-8") + body


def read_root_path(path: str) -> np.ndarray:
    """The ROOT track of a library written by ``liganimate import``, frame by frame.

    Parameters
    ----------
    path : str
        The ``.lig`` file.

    Returns
    -------
    ndarray, shape (F, 3)
        The root's position at frames 0 .. F-1 (F - 1 being its last
        keyframe's frame; 1 row for a root that holds still).

    Raises
    ------
    ValueError
        If the file has no ROOT track.
    """
    with open(path, encoding="utf-8") as fh:
        lines = fh.read().split("\n")
    table = _table_root(lines)
    if table is not None:
        return table
    at = next((i for i, line in enumerate(lines) if line.strip().startswith("ROOT POSITION")), None)
    if at is None:
        raise ValueError(f"{path} has no ROOT track")
    rows = [[0.0] + [float(v) for v in lines[at].split("POSITION", 1)[1].split(",")]]
    for line in lines[at + 1 :]:
        words = line.split()
        if not words or words[0] != "FRAME":
            break
        frame, rest = line.split("POSITION", 1)
        rows.append([float(frame.split()[1])] + [float(v) for v in rest.split(",")])
    return np.array(rows, dtype=np.float64)[:, 1:]


def _table_root(lines: list):
    """The ROOT column of a keyframe table written by :func:`_table_text`, or None."""
    at = next((i for i, line in enumerate(lines) if line.strip().startswith("TABLE ")), None)
    if at is None:
        return None
    names: list = []
    i = at
    while i < len(lines) and not lines[i].lstrip().startswith(("{", "|")):
        names += [w.strip() for w in lines[i].strip().removeprefix("TABLE").split(",") if w.strip()]
        i += 1
    if "ROOT" not in names:
        return None
    rows = [line.split("|", 1)[1] for line in lines[i:] if line.lstrip().startswith("|")]
    data = np.array([r.split() for r in rows], dtype=np.float64)
    k = 1 + 3 * names.index("ROOT")
    return data[:, k : k + 3]


def _wrapped(d: np.ndarray) -> np.ndarray:
    return (d + 180.0) % 360.0 - 180.0


def reduce_keyframes(angles: np.ndarray, tolerance: float, rounds: int = 64) -> list:
    """Which frames each joint needs as keyframes to stay within ``tolerance`` degrees everywhere.

    Parameters
    ----------
    angles : ndarray, shape (F, J, 3)
        The captured angles (unwrapped along the frames).
    tolerance : float
        Degrees, per axis, at every integer frame.

    Returns
    -------
    list of ndarray of int
        Per joint, the kept frames, ascending, always with the first and the
        last.

    Notes
    -----
    Frames are first dropped where a straight line between the kept ones
    stays within half the tolerance (and no two kept keyframes differ by
    180 degrees or more, which the player would take the short way round).
    That is then checked against the motion as LIG evaluates it (LINEAR
    with its velocity ramps, free axes unwrapped), at the values as written
    (seven decimals); frames that miss are kept again, until none miss.
    """
    F, J = angles.shape[:2]
    values = np.round(angles, DECIMALS)
    keep = [_linear_keep(values[:, j], tolerance / 2.0) for j in range(J)]
    frames = np.arange(F, dtype=np.float64)
    budget = tolerance - 10.0**-DECIMALS
    for _ in range(rounds):
        spec = {
            j + 1: (values[0, j], [Keyframe(float(f), values[f, j]) for f in keep[j][1:].tolist()]) for j in range(J)
        }
        motion = Motion.from_tracks(spec).unwrapped({j + 1: (True, True, True) for j in range(J)})
        played = motion.evaluate(frames)
        miss = np.abs(_wrapped(played - values)).max(axis=2) > budget  # (F, J)
        if not miss.any():
            return keep
        for j in np.flatnonzero(miss.any(axis=0)):
            keep[j] = np.union1d(keep[j], np.flatnonzero(miss[:, j]))
    return [np.arange(F) for _ in range(J)]


def _linear_keep(v: np.ndarray, tol: float) -> np.ndarray:
    """Frames of one joint's (F, 3) curve to keep so that straight lines between them stay within ``tol``."""
    F = len(v)
    kept = np.arange(F)
    while len(kept) > 2:
        # Try dropping every other interior keyframe at once; each gap then
        # spans two old gaps, and is checked over every frame inside it.
        trial = np.concatenate([kept[::2], kept[-1:]]) if len(kept) % 2 == 0 else kept[::2]
        dropped = np.setdiff1d(kept, trial)
        seg = np.searchsorted(trial, np.arange(F), side="right") - 1
        seg = seg.clip(0, len(trial) - 2)
        a, b = trial[seg], trial[seg + 1]
        u = ((np.arange(F) - a) / (b - a))[:, None]
        err = np.abs(v[a] + u * (v[b] - v[a]) - v).max(axis=1)
        span_err = np.zeros(len(trial) - 1)
        np.maximum.at(span_err, seg, err)
        jump = np.abs(np.diff(v[trial], axis=0)).max(axis=1) >= 180.0
        bad_span = (span_err > tol) | jump
        # A dropped frame comes back when the gap it sat in is too coarse.
        restore = dropped[bad_span[np.searchsorted(trial, dropped) - 1]]
        new = np.union1d(trial, restore)
        if len(new) == len(kept):
            break
        kept = new
    return kept


def _keyframe_rows(frames: np.ndarray, values: np.ndarray) -> bytes:
    """``FRAME f POSITION x, y, z`` lines: ``frames`` shape (K,), ``values`` shape (K, 3) (a joint's or the ROOT's)."""
    return format_rows(
        np.column_stack([frames, values]),
        [0, DECIMALS, DECIMALS, DECIMALS],
        columns_prefix=["          FRAME", " POSITION", ",", ","],
        suffix="\n",
    )
