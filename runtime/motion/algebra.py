"""Motion values: per-joint tracks with the thesis' motion algebra.

A :class:`Motion` maps joint ids to tracks (see :mod:`liganimate.runtime.motion.track`).
It is immutable, and every operation is lazy: ``a + b``, ``n * a``, STRIP,
SYNCHRONIZE and the SCALE transforms build new node graphs of a size that
does not depend on repetition counts, so ``10**9 * walk`` costs what ``walk``
costs.  The semantics are written out in ``docs/semantics-motion.md``.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Iterable, Mapping

import numpy as np

from liganimate.lang.numbers import GEOMETRY_MAX, magnitude
from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import interpolation
from liganimate.runtime.motion import morph as mo
from liganimate.runtime.motion import path as rp
from liganimate.runtime.motion import track as tr
from liganimate.runtime.motion.keyframe import RAMP, Keyframe

__all__ = [
    "DEFAULT_KEYFRAME_LIMIT",
    "ORIENTATION",
    "Motion",
    "concat",
    "repeat",
    "scale_extremes",
    "scale_frames",
    "strip",
    "synchronize",
]

DEFAULT_KEYFRAME_LIMIT = 100_000

#: The key of the root orientation track where tracks are keyed by joint (None is the ROOT path).
ORIENTATION = "ORIENTATION"

# Derived motions remembered per motion (see Motion._derive).
_DERIVED_MAX = 8


def _joint_id(joint) -> int:
    if isinstance(joint, bool):
        raise MotionError(f"joint id {joint!r} is not an integer")
    try:
        return operator.index(joint)
    except TypeError:
        raise MotionError(f"joint id {joint!r} is not an integer") from None


def _vector(value, what: str) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise MotionError(f"{what} must be three angles (x, y, z), got {value!r}") from None
    if not np.all(np.isfinite(v)):
        raise MotionError(f"{what} must be finite, got {tuple(v)}")
    return v


def _real(r, what: str) -> float:
    try:
        r = float(r)
    except (TypeError, ValueError):
        raise MotionError(f"{what} must be a number, got {r!r}") from None
    if not math.isfinite(r):
        raise MotionError(f"{what} must be finite, got {r}")
    return r


def _who(joint) -> str:
    if joint is None:
        return "the root track"
    return "the root orientation" if joint == ORIENTATION else f"joint {joint}"


def _leaf(joint, spec) -> tr.Leaf:
    """Validate one joint's ``(start, keyframes)`` and build its leaf (``joint`` None: the root track)."""
    who = _who(joint)
    try:
        start, keys = spec
    except (TypeError, ValueError):
        raise MotionError(f"{who}: expected (start position, list of keyframes)") from None
    start = np.zeros(3) if start is None else _vector(start, f"{who}: start position")
    frames, values, methods, ramps = [], [], [], []
    previous = 0.0
    for k, key in enumerate(keys, start=1):
        where = f"{who}, keyframe {k}"
        if not isinstance(key, Keyframe):
            raise MotionError(f"{where}: expected a Keyframe, not {type(key).__name__}")
        frame = _real(key.frame, f"{where}: frame")
        if frame < 0:
            raise MotionError(
                f"{where}: frame {frame:g} is negative",
                hint="frames count ticks from the start of the motion, which is frame 0",
            )
        if frame < previous:
            raise MotionError(
                f"{where}: frame {frame:g} comes before the previous keyframe's frame {previous:g}",
                hint="list keyframes in order of their frames; equal frames make an instantaneous step",
            )
        previous = frame
        try:
            method = interpolation.get(key.method)
        except KeyError:
            raise MotionError(
                f"{where}: unknown interpolation method {key.method!r}",
                hint="known methods: " + ", ".join(interpolation.names()),
            ) from None
        ramp = _real(key.ramp, f"{where}: ramp")
        if ramp <= 0:
            raise MotionError(f"{where}: ramp {ramp:g} must be positive")
        frames.append(frame)
        values.append(_vector(key.position, f"{where}: position"))
        methods.append(method)
        ramps.append(ramp)
    positions = np.reshape(values, (-1, 3))
    tr.check_frames(np.asarray(frames, dtype=float), f"{who}: a keyframe list that")
    if joint is None:
        far = float(np.max(np.abs(np.vstack([start[None, :], positions]))))
        if not far <= GEOMETRY_MAX:
            raise MotionError(
                f"the root track: a position {magnitude(far)} from the origin is beyond the geometry limit, "
                f"{magnitude(GEOMETRY_MAX)}"
            )
    else:
        tr.check_angles(np.vstack([start[None, :], positions]), f"{who}: a position that")
    return tr.Leaf(start, frames, positions, methods, ramps)


def _array_leaf(joint, start, frames, values) -> tr.Leaf:
    """A LINEAR leaf from arrays (a keyframe table's column), checked at once rather than key by key."""
    who = _who(joint)
    start = _vector(start, f"{who}: start position")
    frames = np.asarray(frames, dtype=np.float64).reshape(-1)
    positions = np.asarray(values, dtype=np.float64).reshape(len(frames), 3)
    if not (np.isfinite(frames).all() and np.isfinite(positions).all()):
        raise MotionError(f"{who}: a keyframe table holds a number that is not finite")
    if len(frames) and (frames.min() < 0 or (np.diff(frames) < 0).any()):
        raise MotionError(f"{who}: a keyframe table's frames must be 0 or more, in order")
    tr.check_frames(frames, f"{who}: a keyframe list that")
    everything = np.vstack([start[None, :], positions])
    if joint is None:
        far = float(np.max(np.abs(everything)))
        if not far <= GEOMETRY_MAX:
            raise MotionError(
                f"the root track: a position {magnitude(far)} from the origin is beyond the geometry limit, "
                f"{magnitude(GEOMETRY_MAX)}"
            )
    else:
        tr.check_angles(everything, f"{who}: a position that")
    linear = interpolation.get("LINEAR")
    return tr.Leaf(start, frames, positions, (linear,) * len(frames), np.full(len(frames), RAMP))


class Motion:
    """An immutable motion: a track per joint, built lazily by the motion algebra.

    Build one with :meth:`from_tracks` or :meth:`empty`; combine with ``+``,
    ``n * m`` and the methods below.  All operations return new motions.
    """

    __slots__ = ("_derived", "_expr", "_length", "_morph", "_open", "_root", "_tail", "_tracks", "_turn")

    def __init__(
        self,
        tracks: Mapping[int, tr.Track],
        expr: tuple,
        length: float | None = None,
        gaps: tuple[Iterable[int], Iterable[int]] = ((), ()),
        root: tr.Track | None = None,
        morph: mo.Morphs | None = None,
        turn: tr.Track | None = None,
    ):
        """Internal: use :meth:`from_tracks`, :meth:`empty` and the operations.

        Parameters
        ----------
        tracks : mapping of int to Track
        expr : tuple
            The expression node :meth:`describe` renders.
        length : float, optional
            Defaults to the largest track end.
        gaps : (iterable of int, iterable of int)
            Joints whose track begins with a time no operand of ``+`` drove
            (its leftmost piece is a ``Const`` that ``+`` may refill), and
            joints whose track ends with such a time (a hold).
        root : Track, optional
            The root path (see :mod:`liganimate.runtime.motion.path`).
        morph : Morphs, optional
            The links' scale and shape channels (see :mod:`liganimate.runtime.motion.morph`).
        turn : Track, optional
            The root orientation: three angles (see :mod:`liganimate.runtime.motion.turning`).
        """
        self._tracks = dict(sorted(tracks.items()))
        self._root = root
        self._turn = turn
        self._open = frozenset(gaps[0]) & self._tracks.keys()
        self._tail = frozenset(gaps[1]) & self._tracks.keys()
        ends = [t.end for t in self._tracks.values()] + [t.end for t in (root, turn) if t is not None]
        ends += [morph.end] if morph is not None else []
        self._length = float(length if length is not None else max(ends, default=0.0))
        if not math.isfinite(self._length):
            # n * m and SCALE FRAMES multiply lengths; LEN must stay a finite REAL.
            raise MotionError(
                "the motion would be longer than a REAL can count (about 1.8E308 frames)",
                hint="repeat or stretch it less",
            )
        self._expr = expr
        self._morph = None if morph is None else morph.fitted(self._length)
        self._derived: dict | None = None

    def _derive(self, key: tuple, keep, make) -> Motion:
        """``make()``, remembered under ``key`` (a few entries per motion).

        A scene body such as ``ANIMATE H USING WALK <SCALE FRAMES 2>`` runs
        once a tick; remembering the result hands back the same motion
        object every tick, so the renderer evaluates its frames in one batch
        and the per-tick cost of rebuilding the track graph disappears.
        Motions are immutable, so the cached result is always right.  ``keep``
        is held alongside (an operand whose ``id`` is part of the key).
        """
        d = self._derived
        if d is None:
            d = self._derived = {}
        hit = d.get(key)
        if hit is not None and hit[0] is keep:
            return hit[1]
        out = make()
        if len(d) >= _DERIVED_MAX:
            d.pop(next(iter(d)))
        d[key] = (keep, out)
        return out

    def __getstate__(self):
        return (self._tracks, self._length, self._expr, self._open, self._tail, self._root, self._morph, self._turn)

    def __setstate__(self, state):
        self._tracks, self._length, self._expr = state[:3]
        self._open, self._tail = state[3:5] if len(state) > 3 else (frozenset(), frozenset())
        self._root = state[5] if len(state) > 5 else None
        self._morph = state[6] if len(state) > 6 else None
        self._turn = state[7] if len(state) > 7 else None
        self._derived = None

    # -- construction -----------------------------------------------------

    @classmethod
    def from_tracks(
        cls,
        tracks: Mapping[int, tuple],
        name: str | None = None,
        root: tuple | None = None,
        arrays=None,
        turn: tuple | None = None,
    ) -> Motion:
        """Build a motion from explicit keyframes.

        Parameters
        ----------
        tracks : mapping of int to (start, keyframes)
            ``start`` is array_like of shape (3,) (or None for the neutral
            position); ``keyframes`` is a sequence of :class:`Keyframe`.
        name : str, optional
            Shown by :meth:`describe`.
        root : (start, keyframes), optional
            The root track, built as a joint's: ``start`` (None for the
            origin) and keyframes whose positions are displacements of the
            model's main link in the model's own frame.
        arrays : mapping of (int or None) to (start, frames, values), optional
            Tracks given as arrays (a keyframe table's columns): ``start``
            shape (3,), ``frames`` shape (K,), ``values`` shape (K, 3), every
            keyframe LINEAR with the default ramp; None is the root track.
            Checked all at once, so a table of 20,000 rows stays fast.
            :data:`ORIENTATION` is the root orientation.
        turn : (start, keyframes), optional
            The root orientation, built as a joint's: three angles in
            degrees, the heading about Y outermost (see :func:`.turning.orientation_matrix`).

        Returns
        -------
        Motion

        Raises
        ------
        MotionError
            For decreasing or negative frames, unknown methods, malformed
            positions; the message names the joint and the keyframe.
        """
        leaves = {}
        for joint, spec in tracks.items():
            j = _joint_id(joint)
            leaves[j] = _leaf(j, spec)
        path = None if root is None else _leaf(None, root)
        heading = None if turn is None else _leaf(ORIENTATION, turn)
        for joint, (start, frames, values) in (arrays or {}).items():
            if joint is None:
                path = _array_leaf(None, start, frames, values)
            elif joint == ORIENTATION:
                heading = _array_leaf(ORIENTATION, start, frames, values)
            else:
                j = _joint_id(joint)
                leaves[j] = _array_leaf(j, start, frames, values)
        nkeys = sum(len(leaf.frames) for leaf in [*leaves.values(), path, heading] if leaf is not None)
        return cls(leaves, ("keys", name, len(leaves), nkeys), root=path, turn=heading)

    @classmethod
    def empty(cls) -> Motion:
        """The motion with no joints and length 0.

        Returns
        -------
        Motion
        """
        return cls({}, ("empty",))

    # -- properties -------------------------------------------------------

    @property
    def length(self) -> float:
        """Last frame at which any track changes (float)."""
        return self._length

    @property
    def joints(self) -> tuple[int, ...]:
        """Driven joint ids, sorted."""
        return tuple(self._tracks)

    @property
    def cycle(self) -> tuple[int, float] | None:
        """``(n, period)`` when this motion is ``n * a`` (REPEAT) with n >= 2 and a of positive length, else None.

        Copies 1 .. n-2 of such a motion are the same track graph (the first
        and the last copy differ: they meet a neighbour on one side only), so
        a frame in a middle copy poses the figure exactly as the frame one
        period earlier does, as long as the frames subtract exactly.
        """
        e = self._expr
        if e[0] != "*" or e[1] < 2 or self._length <= 0:
            return None
        return int(e[1]), self._length / e[1]

    @property
    def morphs(self) -> mo.Morphs | None:
        """The links' scale and shape channels, or None for a motion that morphs nothing."""
        return self._morph

    def with_morphs(self, morph: mo.Morphs | None) -> Motion:
        """This motion with morph channels added (STARTMOTION's SCALE and SHAPE entries).

        Parameters
        ----------
        morph : Morphs or None

        Returns
        -------
        Motion
            Its length covers the morph channels too.
        """
        return Motion(self._tracks, self._expr, None, (self._open, self._tail), self._root, morph, self._turn)

    @property
    def root(self) -> tr.Track | None:
        """The root path, or None for a motion that does not move the figure."""
        return self._root

    def root_offset(self, times) -> np.ndarray:
        """The root path's displacement at some times (zero without a path).

        Parameters
        ----------
        times : array_like, shape (T,)

        Returns
        -------
        ndarray, shape (T, 3)
            In the model's own units and axes; ``world = placement @
            Trans(offset) @ pose``.
        """
        return self._sample_root(self._root, times)

    @property
    def turn(self) -> tr.Track | None:
        """The root orientation track, or None for a motion that does not turn the figure."""
        return self._turn

    def root_orientation(self, times) -> np.ndarray:
        """The root orientation's three angles at some times (zero without one).

        Parameters
        ----------
        times : array_like, shape (T,)

        Returns
        -------
        ndarray, shape (T, 3)
            Degrees; ``world = placement @ Trans(offset) @ Rot(angles) @ pose``
            with ``Rot`` :func:`.turning.orientation_matrix`.
        """
        return self._sample_root(self._turn, times)

    def _sample_root(self, track: tr.Track | None, times) -> np.ndarray:
        """A root track's three values at ``times`` ``(T,)`` as ``(T, 3)``; zeros for a motion without that track."""
        t = self._times(times)
        if track is None:
            return np.zeros((len(t), 3))
        with np.errstate(all="ignore"):  # see evaluate
            out = track.sample_x(t)
        _finite(out)
        return out

    def turn_keyframes(self, limit: int = DEFAULT_KEYFRAME_LIMIT) -> tuple[tuple, list[Keyframe]]:
        """The root orientation written out as one keyframe list (see :meth:`keyframes`).

        Returns
        -------
        start : tuple of 3 float
        keys : list of Keyframe

        Raises
        ------
        MotionError
            If the motion has no root orientation or the listing would exceed ``limit``.
        """
        if self._turn is None:
            raise MotionError("this motion has no root orientation")
        try:
            return tr.materialize(self._turn, limit)
        except MotionError as exc:
            raise MotionError(
                f"the root orientation: {exc.message}", hint="use describe() to see how the motion is built"
            ) from None

    def heading(self, side: str) -> float:
        """Degrees about Y the figure faces at the start (``"start"``) or the end (``"end"``); 0 without a root orientation.

        Parameters
        ----------
        side : {"start", "end"}

        Returns
        -------
        float
        """
        if self._turn is None:
            return 0.0
        return float((self._turn.start_value if side == "start" else self._turn.end_value)[1])

    def root_keyframes(self, limit: int = DEFAULT_KEYFRAME_LIMIT) -> tuple[tuple, list[Keyframe]]:
        """The root path written out as one keyframe list (see :meth:`keyframes`).

        Returns
        -------
        start : tuple of 3 float
        keys : list of Keyframe

        Raises
        ------
        MotionError
            If the motion has no root path or the listing would exceed ``limit``.
        """
        if self._root is None:
            raise MotionError("this motion has no root track")
        try:
            start, keys = tr.materialize(self._root, limit)
        except MotionError as exc:
            raise MotionError(
                f"the root track: {exc.message}", hint="use describe() to see how the motion is built"
            ) from None
        return start, keys

    def track(self, joint: int) -> tr.Track:
        """The track node of one joint (for the runtime and tests).

        Parameters
        ----------
        joint : int

        Returns
        -------
        Track
        """
        return self._tracks[self._driven(joint, "this motion")]

    def gap(self, joint: int) -> float:
        """Frames at the start during which no operand of ``+`` drives ``joint``.

        Such a joint shows the previous driven value there once this motion
        follows another that drives it, else its first driven value.

        Parameters
        ----------
        joint : int

        Returns
        -------
        float
            0 if the joint is driven from frame 0.
        """
        j = self._driven(joint, "this motion")
        return tr.gap_length(self._tracks[j]) if j in self._open else 0.0

    def _driven(self, joint, where: str) -> int:
        j = _joint_id(joint)
        if j not in self._tracks:
            raise MotionError(f"joint {j} is not driven by {where}", hint=f"it drives joints {list(self.joints)}")
        return j

    # -- algebra ----------------------------------------------------------

    def __add__(self, other: Motion) -> Motion:
        """``self + other``: ``other`` played after this motion (see :func:`concat`).

        Parameters
        ----------
        other : Motion

        Returns
        -------
        Motion
            Of length ``self.length + other.length``.
        """
        if not isinstance(other, Motion):
            return NotImplemented
        return self._derive(("+", id(other)), other, lambda: self._concat(other))

    def _concat(self, other: Motion) -> Motion:
        # A joint an operand does not drive is left "not driven here" and filled
        # from its neighbours: the previous driven value, else the next.  Only
        # a leading gap depends on what comes before, so ``other``'s leading
        # gap is refilled here; that makes + associative by construction.
        la, lb = self._length, other._length
        tracks = {}
        opened, tail = set(self._open), set(other._tail)
        for j in self._tracks.keys() | other._tracks.keys():
            ta, tb = self._tracks.get(j), other._tracks.get(j)
            if tb is None:
                assert ta is not None  # j is driven by one operand at least
                if lb == 0:
                    tracks[j] = tr.pad(ta, la)  # the empty motion (or any of length 0) is an identity
                    if j in self._tail:
                        tail.add(j)
                else:
                    tracks[j] = tr.pad(ta, la + lb, hold_from=la)  # a's end value is held through b
                    tail.add(j)
            elif ta is None and la == 0:
                tracks[j] = tb
                if j in other._open:
                    opened.add(j)
            elif ta is None:
                if j in other._open:
                    tracks[j] = tr.lead_gap(tb, la)  # one gap: refilled whole by what comes before
                else:
                    tracks[j] = tr.concat(tr.Const(tb.start_value), tb, la)  # already in place for b
                opened.add(j)
            else:
                if j in other._open:
                    tb = tr.refill(tb, ta.end_value)
                ta, tb = tr.join_smoothly(ta, tb, la)
                tracks[j] = tr.concat(ta, tb, la)
        # The later motion continues in the heading the earlier one leaves the figure in;
        # an empty operand without an orientation is an identity.
        delta = 0.0 if (self._turn is None and la == 0) else self.heading("end") - other.heading("start")
        root = rp.concat(self._root, la, other._root, lb, delta)
        turn = _concat_turns(self._turn, la, other._turn, lb, delta)
        morph = mo.concat(self._morph, la, other._morph, lb, Motion)
        return Motion(tracks, ("+", self._expr, other._expr), gaps=(opened, tail), root=root, morph=morph, turn=turn)

    def repeat(self, n: int) -> Motion:
        """``n`` copies played back to back (the thesis' ``n * motion``).

        Parameters
        ----------
        n : int
            Non-negative.

        Returns
        -------
        Motion
            Of length ``n * self.length``; for ``n = 0``, length 0 and every
            joint holding its start value.

        Raises
        ------
        MotionError
            If ``n`` is not a non-negative integer.
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
            raise MotionError(f"a motion can only be repeated a whole number of times, not {n!r}")
        n = int(n)
        if n < 0:
            raise MotionError(f"a motion cannot be repeated a negative number of times ({n})")
        return self._derive(("*", n), None, lambda: self._repeat(n))

    def _repeat(self, n: int) -> Motion:
        expr = ("*", n, self._expr)
        root, turn = self._root, self._turn
        morph = mo.repeat(self._morph, n, self._length)
        if n == 0:
            still = None if root is None else tr.Const(root.start_value)
            facing = None if turn is None else tr.Const(turn.start_value)
            consts = {j: tr.Const(t.start_value) for j, t in self._tracks.items()}
            return Motion(consts, expr, root=still, morph=morph, turn=facing)
        gaps = (self._open, self._tail)
        if n == 1 or self._length == 0:
            return Motion(self._tracks, expr, self._length * n, gaps, root, morph, turn)
        L = self._length
        tracks = {}
        for j, t in self._tracks.items():
            # A track that lasts the whole period ends exactly where the repeat does.
            end = n * L if t.end == L else None
            if j in self._open:
                # Copies after the first fill their leading gap with the previous copy's end
                # value, as a + a + ... + a would.
                later = tr.refill(t, t.end_value)
                rest = later if n == 2 else tr.Repeat(later, n - 1, L)
                tracks[j] = tr.concat(t, rest, L, end=end if end is not None else (n - 1) * L + t.end)
            else:
                tracks[j] = tr.repeat_smoothly(t, n, L, end)
        delta = self.heading("end") - self.heading("start")
        root = None if root is None else rp.repeat(root, n, L, delta)
        return Motion(tracks, expr, n * L, gaps, root, morph, _repeat_turn(turn, n, L, delta))

    def __mul__(self, n) -> Motion:
        return self.repeat(n)

    __rmul__ = __mul__

    def strip(self, joints: Iterable[int]) -> Motion:
        """Keep only some joints (STRIP).

        Parameters
        ----------
        joints : iterable of int

        Returns
        -------
        Motion
            Its length is recomputed from the kept tracks.

        Raises
        ------
        MotionError
            If a listed joint is not driven by this motion.
        """
        kept = {}
        for joint in joints:
            j = self._driven(joint, "the motion being stripped")
            kept[j] = self._tracks[j]
        # The root tracks and the morphs are not joints: STRIP keeps them.
        return Motion(
            kept,
            ("strip", tuple(kept), self._expr),
            gaps=(self._open, self._tail),
            root=self._root,
            morph=self._morph,
            turn=self._turn,
        )

    def scale_frames(self, r: float) -> Motion:
        """Stretch time by ``|r|``; a negative ``r`` also plays the motion backwards.

        Parameters
        ----------
        r : float
            Non-zero.

        Returns
        -------
        Motion
            Its pose at ``|r| * t`` is this motion's pose at ``t`` (for
            ``r > 0``) or at ``length - t`` (for ``r < 0``).

        Raises
        ------
        MotionError
            If ``r`` is zero or not finite.
        """
        r = _real(r, "the SCALE FRAMES factor")
        if r == 0:
            raise MotionError("SCALE FRAMES 0 would squeeze the motion into no time", hint="use a non-zero factor")
        return self._derive(("frames", r), None, lambda: self._scale_frames(r))

    def _scale_frames(self, r: float) -> Motion:
        s, L = abs(r), self._length * abs(r)
        memo: dict = {}
        tracks = {j: tr.scale_frames(t, s, memo) for j, t in self._tracks.items()}
        root = None if self._root is None else tr.scale_frames(self._root, s, memo)
        turn = None if self._turn is None else tr.scale_frames(self._turn, s, memo)
        gaps = (self._open, self._tail)
        if r < 0:
            tracks = {j: tr.reverse(t, L, memo) for j, t in tracks.items()}
            gaps = (self._tail, self._open)  # a trailing hold played backwards is a leading gap
            back = self.heading("start") - self.heading("end")  # walk back facing as it came
            root = None if root is None else rp.reverse(root, L, memo, back)
            turn = None if turn is None else rp.reverse(turn, L, memo, 0.0, (0.0, back, 0.0))
        morph = mo.scale_frames(self._morph, r, self._length)
        return Motion(tracks, ("frames", r, self._expr), L, gaps, root, morph, turn)

    def scale_extremes(self, r: float) -> Motion:
        """Multiply every angle (start and keyframe positions) by ``r``.

        Parameters
        ----------
        r : float

        Returns
        -------
        Motion
        """
        r = _real(r, "the SCALE EXTREMES factor")
        return self._derive(("extremes", r), None, lambda: self._scale_extremes(r))

    def _scale_extremes(self, r: float) -> Motion:
        memo: dict = {}
        tracks = {j: tr.scale_extremes(t, r, memo) for j, t in self._tracks.items()}
        # Positions, scales and shapes are not angles: the root tracks and the morphs are left as they
        # are (where the figure faces is not a joint's angle either).
        gaps = (self._open, self._tail)
        return Motion(tracks, ("extremes", r, self._expr), self._length, gaps, self._root, self._morph, self._turn)

    def unwrapped(self, free_axes: Mapping[int, tuple[bool, bool, bool]]) -> Motion:
        """Take the short way round on axes that can turn freely.

        Parameters
        ----------
        free_axes : mapping of int to tuple of 3 bool
            Joints (and their X, Y, Z axes) with no rotation limit; joints this
            motion does not drive are ignored.

        Returns
        -------
        Motion
            In every leaf track, each keyframe value on a listed axis is moved
            by a multiple of 360 to within 180 degrees of the previous one; the
            start values are kept.
        """
        memo: dict = {}
        tracks = dict(self._tracks)
        for joint, axes in free_axes.items():
            j = _joint_id(joint)
            if j in tracks and any(axes):
                tracks[j] = tr.unwrap(tracks[j], (bool(axes[0]), bool(axes[1]), bool(axes[2])), memo)
        gaps = (self._open, self._tail)
        return Motion(tracks, ("unwrap", self._expr), self._length, gaps, self._root, self._morph, self._turn)

    # -- evaluation -------------------------------------------------------

    def _times(self, times) -> np.ndarray:
        t = np.asarray(times, dtype=float).reshape(-1)
        if np.isnan(t).any():
            raise MotionError("cannot evaluate a motion at a NaN time")
        return np.ascontiguousarray(t)

    def _joint_list(self, joints) -> list[int]:
        if joints is None:
            return list(self._tracks)
        return [self._driven(j, "the motion being evaluated") for j in joints]

    def evaluate(self, times, joints: Iterable[int] | None = None) -> np.ndarray:
        """Joint angles at some times.

        Parameters
        ----------
        times : array_like, shape (T,)
            Frames (real numbers); before 0 the start values are shown,
            after ``length`` the end values.
        joints : iterable of int, optional
            Defaults to :attr:`joints`.

        Returns
        -------
        ndarray, shape (T, J, 3)
            Degrees about X, Y, Z.
        """
        t = self._times(times)
        js = self._joint_list(joints)
        out = np.empty((len(t), len(js), 3))
        # The limits on frames, gaps and angles (lang/numbers.py) keep every
        # formula finite on the rows it is chosen for; np.where also
        # evaluates the other branch, whose overflow must not print.
        with np.errstate(all="ignore"):
            for i, j in enumerate(js):
                out[:, i] = self._tracks[j].sample_x(t)
        _finite(out)
        return out

    def evaluate_full(self, times, joints: Iterable[int] | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint angles with their analytic velocity and acceleration.

        Parameters
        ----------
        times : array_like, shape (T,)
        joints : iterable of int, optional

        Returns
        -------
        angles : ndarray, shape (T, J, 3)
            Degrees.
        velocity : ndarray, shape (T, J, 3)
            Degrees per frame (one-sided at keyframes, on the side the value is taken from).
        acceleration : ndarray, shape (T, J, 3)
            Degrees per frame squared.
        """
        t = self._times(times)
        js = self._joint_list(joints)
        out = np.zeros((3, len(t), len(js), 3))
        with np.errstate(all="ignore"):  # see evaluate
            for i, j in enumerate(js):
                s = self._tracks[j].sample(t)
                out[0, :, i], out[1, :, i], out[2, :, i] = s
        _finite(out)
        return out[0], out[1], out[2]

    # -- inspection -------------------------------------------------------

    def keyframes(self, joint: int, limit: int = DEFAULT_KEYFRAME_LIMIT) -> tuple[tuple, list[Keyframe]]:
        """One joint's track written out as a single keyframe list (for PRINT).

        Junctions of ``+`` and ``*`` appear as a repeated keyframe (a
        zero-length step), and holds as a constant LINEAR segment, so the
        listing fed back to :meth:`from_tracks` gives the same angles except exactly at left-continuous steps.

        Parameters
        ----------
        joint : int
        limit : int
            Most keyframes to produce.

        Returns
        -------
        start : tuple of 3 float
        keys : list of Keyframe

        Raises
        ------
        MotionError
            If the joint is not driven, or the listing would exceed ``limit``
            (checked before anything big is built).
        """
        j = self._driven(joint, "this motion")
        try:
            start, keys = tr.materialize(self._tracks[j], limit)
        except MotionError as exc:
            raise MotionError(
                f"joint {j}: {exc.message}", hint="use describe() to see how the motion is built"
            ) from None
        return start, keys

    def footprint(self) -> tr.Footprint:
        """What this motion stores: distinct track nodes and leaf keyframes.

        Returns
        -------
        Footprint
        """
        return tr.footprint(list(self._tracks.values()) + [t for t in (self._root, self._turn) if t is not None])

    def describe(self, max_chars: int = 2000) -> str:
        """A compact text of the expression that built this motion.

        Parameters
        ----------
        max_chars : int
            The text is cut (ending in "...") beyond this, so a motion built
            by doubling 60 times still describes quickly.

        Returns
        -------
        str
        """
        text = _Describer(max_chars)
        if not text.render(self._expr, 0):
            return "".join(text.parts)[:max_chars] + "..."
        return "".join(text.parts)

    def __repr__(self) -> str:
        return f"<Motion length={self._length:g} joints={list(self.joints)}: {self.describe(200)}>"


class _Describer:
    """Writes a motion's expression (``Motion._expr``) as text, stopping once ``budget`` characters are spent.

    Each method returns False when the budget ran out, which stops the walk.
    """

    def __init__(self, budget: int):
        self.parts: list[str] = []
        self.budget = budget

    def put(self, s: str) -> bool:
        self.parts.append(s)
        self.budget -= len(s)
        return self.budget > 0

    def render(self, e: tuple, prec: int) -> bool:
        """``prec``: 0 inside + or a list, 1 as a * operand, 2 before a <transform>."""
        kind = e[0]
        if kind == "keys":
            _, name, nj, nk = e
            return self.put(name or f"keyframes[{nj} joints, {nk} keyframes]")
        if kind == "empty":
            return self.put("EMPTY")
        if kind in ("+", "*"):
            return self._operation(e, prec)
        if kind in ("frames", "extremes"):
            label = "FRAMES" if kind == "frames" else "EXTREMES"
            return self.render(e[2], 2) and self.put(f" <SCALE {label} {e[1]:g}>")
        if kind == "strip":
            return self.put("STRIP(") and self.render(e[2], 0) and self.put("".join(f", {j}" for j in e[1]) + ")")
        if kind == "sync":
            return self._sync(e[1])
        if kind == "unwrap":
            return self.put("UNWRAP(") and self.render(e[1], 0) and self.put(")")
        return self.put(f"<{kind}>")

    def _operation(self, e: tuple, prec: int) -> bool:
        kind = e[0]
        paren = prec > (0 if kind == "+" else 1)
        if paren and not self.put("("):
            return False
        if kind == "+":
            ok = self.render(e[1], 0) and self.put(" + ") and self.render(e[2], 0)
        else:
            ok = self.put(f"{e[1]} * ") and self.render(e[2], 2)
        return ok and (not paren or self.put(")"))

    def _sync(self, operands: tuple) -> bool:
        if not self.put("SYNCHRONIZE("):
            return False
        for i, sub in enumerate(operands):
            if (i and not self.put(", ")) or not self.render(sub, 0):
                return False
        return self.put(")")


def _concat_turns(a: tr.Track | None, la: float, b: tr.Track | None, lb: float, delta: float) -> tr.Track | None:
    """The root orientation of ``a + b``: ``b``'s heading turned by ``delta``.

    A motion without one keeps the figure upright, facing on in the heading
    it inherits (as a zero orientation would); one of length 0 is an identity.
    """
    if a is None and b is None:
        return None
    if b is None and lb == 0:
        return tr.pad(a, la) if a is not None else None
    if a is None and la == 0:
        return b
    a = tr.Const(np.zeros(3)) if a is None else a
    moved = rp.shift(tr.Const(np.zeros(3)) if b is None else b, (0.0, delta, 0.0))
    if _tilt_meets(a.end_value, moved.start_value):
        # The headings meet by construction: share the velocity as a path does.
        a, moved = rp.join(a, moved, la)
    return tr.concat(a, moved, la)


def _tilt_meets(end: np.ndarray, start: np.ndarray) -> bool:
    """Whether an orientation that ends tilted as ``end`` meets one that starts as ``start`` (X and Z)."""
    return bool(end[0] == start[0] and end[2] == start[2])


def _repeat_turn(turn: tr.Track | None, n: int, period: float, delta: float) -> tr.Track | None:
    """The root orientation of ``n * m`` (``n >= 2``): copy ``k`` turned by ``k * delta``, as ``m + m + ...``."""
    if turn is None:
        return None
    step = (0.0, delta, 0.0)
    if _tilt_meets(turn.end_value, turn.start_value):
        return rp.repeat(turn, n, period, 0.0, step)
    return rp.Drift(turn, n, period, step, n * period if turn.end == period else None)


def _finite(values: np.ndarray) -> None:
    if not np.isfinite(values).all():  # pragma: no cover - the limits are meant to make this impossible
        raise MotionError("the motion's interpolation gave a number that is not finite")


def concat(a: Motion, b: Motion) -> Motion:
    """``a + b``: ``b`` played after ``a``.

    Parameters
    ----------
    a, b : Motion

    Returns
    -------
    Motion
    """
    return a + b


def repeat(n: int, a: Motion) -> Motion:
    """``n * a``; see :meth:`Motion.repeat`.

    Parameters
    ----------
    n : int
    a : Motion

    Returns
    -------
    Motion
    """
    return a.repeat(n)


def strip(a: Motion, joints: Iterable[int]) -> Motion:
    """STRIP: see :meth:`Motion.strip`.

    Parameters
    ----------
    a : Motion
    joints : iterable of int

    Returns
    -------
    Motion
    """
    return a.strip(joints)


def synchronize(*motions: Motion) -> Motion:
    """SYNCHRONIZE: one motion driving the union of disjoint joint sets.

    Parameters
    ----------
    *motions : Motion

    Returns
    -------
    Motion
        Its length is the longest operand's.

    Raises
    ------
    MotionError
        If two operands drive the same joint; the message names the joint
        and the two operands (counted from 1).
    """
    tracks: dict[int, tr.Track] = {}
    owner: dict[int, int] = {}
    opened: set[int] = set()
    tail: set[int] = set()
    root, root_owner = None, 0
    turn, turn_owner = None, 0
    for i, m in enumerate(motions, start=1):
        if not isinstance(m, Motion):
            raise MotionError(f"operand {i} of SYNCHRONIZE is not a motion")
        if m._turn is not None:
            if turn is not None and m._turn is not turn:
                raise MotionError(
                    f"the root orientation is driven by both operand {turn_owner} and operand {i} of SYNCHRONIZE",
                    hint="a figure faces one way at a time: build one of them without a ROOT ORIENTATION track",
                )
            turn, turn_owner = m._turn, i
        if m._root is not None:
            # The same path twice (two STRIPs of one motion) is one path, not two.
            if root is not None and m._root is not root:
                raise MotionError(
                    f"the root track is driven by both operand {root_owner} and operand {i} of SYNCHRONIZE",
                    hint="a figure travels along one path: build one of them without a ROOT track",
                )
            root, root_owner = m._root, i
        for j, t in m._tracks.items():
            if j in owner:
                raise MotionError(
                    f"joint {j} is driven by both operand {owner[j]} and operand {i} of SYNCHRONIZE",
                    hint="STRIP the joint from one of them first",
                )
            owner[j] = i
            tracks[j] = t
        opened |= m._open
        tail |= m._tail
    morph = mo.synchronize(enumerate((m._morph for m in motions), start=1), Motion)
    sync = ("sync", tuple(m._expr for m in motions))
    return Motion(tracks, sync, gaps=(opened, tail), root=root, morph=morph, turn=turn)


def scale_frames(a: Motion, r: float) -> Motion:
    """SCALE FRAMES: see :meth:`Motion.scale_frames`.

    Parameters
    ----------
    a : Motion
    r : float

    Returns
    -------
    Motion
    """
    return a.scale_frames(r)


def scale_extremes(a: Motion, r: float) -> Motion:
    """SCALE EXTREMES: see :meth:`Motion.scale_extremes`.

    Parameters
    ----------
    a : Motion
    r : float

    Returns
    -------
    Motion
    """
    return a.scale_extremes(r)
