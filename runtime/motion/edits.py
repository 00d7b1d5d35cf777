"""A motion written keyframe by keyframe: ``m[j, k] := FRAME f POSITION a, b, c``.

Each assignment adds one edit to a chain in O(1); the chain becomes a
:class:`~.algebra.Motion` once, when the motion is first used, so a DO loop
writing n keyframes costs O(n), not O(n^2).

Errors carry ``at``, the statement that made the offending edit (an opaque
token the host turns into a source position), or ``None`` for the statement
that uses the motion.
"""

from __future__ import annotations

from liganimate.lang import messages
from liganimate.lang import numbers as N
from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion.algebra import ORIENTATION, Motion
from liganimate.runtime.motion.keyframe import Keyframe


class EditError(MotionError):
    """A keyframe edit that does not fit; ``at`` is the edit's statement (None: the statement using the motion)."""

    def __init__(self, message: str, hint: str | None = None, at=None):
        super().__init__(message, hint)
        self.at = at


class KeyframeEdits:
    """A motion being written keyframe by keyframe: a base motion and a chain of edits.

    ``edit`` is ``(joint, k, frame, position (3,), method or None, at)``; joint None is the ROOT track,
    :data:`~.algebra.ORIENTATION` the ROOT ORIENTATION track.
    """

    __slots__ = ("_cache", "base", "edit", "parent")

    def __init__(self, base: Motion, edit: tuple, parent: KeyframeEdits | None):
        self.base = base
        self.edit = edit
        self.parent = parent
        self._cache: Motion | None = None

    @property
    def at(self):
        """The statement of the last edit."""
        return self.edit[5]


def check_frame(frame) -> None:
    """A keyframe's frame within the limits of lang/numbers.py, or MotionError."""
    if frame < 0:
        raise MotionError(f"frame {frame:g} is before the motion starts")
    if frame > N.MAX_FRAME:
        raise MotionError(
            f"frame {N.magnitude(frame)} is beyond the last frame a keyframe may have, {N.magnitude(N.MAX_FRAME)}"
        )


def check_angles(position, root: bool = False) -> None:
    """A keyframe's angles (3,) within the limits of lang/numbers.py, or MotionError.

    ``root``: the position is a ROOT track's, a point within the geometry limit.
    """
    if root:
        if not max(abs(a) for a in position) <= N.GEOMETRY_MAX:
            far = max(abs(a) for a in position)
            raise MotionError(
                f"a root position {N.magnitude(far)} from the origin is beyond the geometry limit, "
                f"{N.magnitude(N.GEOMETRY_MAX)}",
                "everything drawn stays within 1E12 units of the origin",
            )
        return
    if not max(abs(a) for a in position) <= N.MAX_ANGLE:
        far = max(abs(a) for a in position)
        raise MotionError(
            f"an angle of {N.magnitude(far)} degrees is beyond the largest a keyframe may hold, "
            f"{N.magnitude(N.MAX_ANGLE)}",
            "angles are in degrees; a joint's extremes clip them anyway",
        )


def set_keyframe(m, joint: int, k: int, frame, position, method: str | None, at) -> KeyframeEdits:
    """``m[joint, k] := FRAME frame POSITION position INTERPOLATE method``: ``m`` (a Motion or edits) with one more edit."""
    if k < 0:
        raise MotionError(f"keyframe numbers start at 0 (the starting position), not {k}")
    if k > N.MAX_KEYFRAME:
        raise MotionError(
            f"keyframe {k} is beyond the last keyframe number allowed, {N.MAX_KEYFRAME:,}",
            "number the keyframes of each joint 1, 2, 3, ...",
        )
    check_frame(frame)
    check_angles(position, joint is None)
    if isinstance(m, KeyframeEdits):
        return KeyframeEdits(m.base, (joint, k, frame, tuple(position), method, at), m)
    return KeyframeEdits(m, (joint, k, frame, tuple(position), method, at), None)


def apply(m: KeyframeEdits) -> Motion:
    """The motion the edits describe (computed once, then kept).

    Raises
    ------
    EditError
        A keyframe number is skipped, or the keyframes do not ascend.
    MotionError
        The base motion cannot list its keyframes, or the tracks do not make a motion.
    """
    if m._cache is not None:
        return m._cache
    edits = []
    node: KeyframeEdits | None = m
    while node is not None:
        edits.append(node.edit)
        node = node.parent
    edits.reverse()
    base = m.base
    tracks: dict = {}
    extra = ((None,) if base.root is not None else ()) + ((ORIENTATION,) if base.turn is not None else ())
    for j in base.joints + extra:
        # Keep each keyframe's ramp so a stretched motion stays stretched.
        if j is None:
            start, kfs = base.root_keyframes()
        elif isinstance(j, str):  # ORIENTATION
            start, kfs = base.turn_keyframes()
        else:
            start, kfs = base.keyframes(j)
        tracks[j] = [tuple(start), {i + 1: (kf, None) for i, kf in enumerate(kfs)}]
    for joint, k, frame, position, method, eat in edits:
        entry = tracks.setdefault(joint, [(0.0, 0.0, 0.0), {}])
        if k == 0:
            entry[0] = position
        else:
            entry[1][k] = (Keyframe(frame, position, method or "LINEAR"), eat)
    spec = {}
    for joint, (start, kfs) in tracks.items():
        numbers = sorted(kfs)
        n = numbers[-1] if numbers else 0
        if len(numbers) != n:
            # The keys are 1..n exactly when there are n of them; else find the first gap (O(set), not O(n)).
            first = next(i for i, k in enumerate(numbers, start=1) if k != i)
            raise EditError(
                f"keyframe {n} of {_track_name(joint)} is set, but keyframe {first} never is",
                "number the keyframes of each joint 1, 2, 3, ... without gaps",
                kfs[n][1],
            )
        seq = [kfs[i] for i in numbers]
        previous = 0.0  # keyframe 0, the starting position, is at frame 0
        for i, (key, eat) in enumerate(seq):
            gap = key.frame - previous
            if gap < 0:
                where = f"keyframe {i + 1} of {_track_name(joint)}"
                raise EditError(messages.keyframes_out_of_order(key.frame, previous, where), None, eat)
            if 0 < gap < N.MIN_FRAME_GAP:
                where = f"keyframe {i + 1} of {_track_name(joint)}"
                raise EditError(messages.keyframes_too_close(key.frame, previous, where), messages.GAP_HINT, eat)
            previous = key.frame
        spec[joint] = (start, [key for key, _ in seq])
    root, turn = spec.pop(None, None), spec.pop(ORIENTATION, None)
    motion = Motion.from_tracks(spec, root=root, turn=turn)
    m._cache = motion
    return motion


def _track_name(joint) -> str:
    if joint == ORIENTATION:
        return "the ROOT ORIENTATION track"
    return "the ROOT track" if joint is None else f"joint {joint}"
