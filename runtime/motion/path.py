"""Root paths: the optional track of a motion that carries the figure along.

A root path is a track (see :mod:`liganimate.runtime.motion.track`) whose
three values are a displacement of the model's current main link, in the
model's own frame, not angles.  Its algebra differs from a joint's in one
way: a path *continues*.  ``a + b`` plays ``b``'s displacement from where
``a`` ended, ``n * a`` walks on copy after copy, and reversal walks back
from where it starts.  Two lazy nodes do it without copying keyframes:
:class:`Shift` (a track moved by a constant) and :class:`Drift` (``n``
copies, each moved by the displacement of the ones before), and a third,
:class:`Reversal`, remembers what a reversal reversed so that reversing
twice gives the path back exactly.  The laws are written out in
``docs/semantics-motion.md``.
"""

from __future__ import annotations

import numpy as np

from . import track as tr
from . import turning as tu

__all__ = ["Drift", "Reversal", "Shift", "concat", "join", "repeat", "reverse", "shift"]


class Shift(tr.Wrapper):
    """A track moved by a constant displacement.

    Parameters
    ----------
    inner : Track
    d : array_like, shape (3,)
    """

    __slots__ = ("d",)

    def __init__(self, inner: tr.Track, d):
        self.inner = inner
        self.d = tr._frozen(d).reshape(3)
        self.end = inner.end
        self.start_value = inner.start_value + self.d
        self.end_value = inner.end_value + self.d
        self.min_keys = inner.min_keys

    def _rewrapped(self, inner):
        return Shift(inner, self.d)

    def sample(self, t):
        x, v, a = self.inner.sample(t)
        return tr.Samples(x + self.d, v, a)

    def sample_x(self, t):
        return self.inner.sample_x(t) + self.d

    def _emit(self, out, offset):
        saved = out.shift
        out.shift = saved + (self.d if out.rot is None else out.rot @ self.d)
        self.inner._emit(out, offset)
        out.shift = saved


def shift(track: tr.Track, d) -> tr.Track:
    """``track`` moved by ``d`` (shape (3,)); shifts of shifts fold into one node.

    Parameters
    ----------
    track : Track
    d : array_like, shape (3,)

    Returns
    -------
    Track
    """
    d = np.asarray(d, dtype=float).reshape(3)
    if not d.any():
        return track
    if isinstance(track, Reversal):  # a moved reversal is another path: fold into what it plays
        return shift(track.played, d)
    if isinstance(track, Shift):
        return Shift(track.inner, track.d + d)
    if isinstance(track, tr.Const):
        return tr.Const(track.value + d, track.end)
    return Shift(track, d)


class Drift(tr.Track):
    """``n`` copies of a path, one every ``period`` frames, copy ``k`` moved by ``k * step``.

    Parameters
    ----------
    inner : Track
        ``inner.end <= period``.
    n : int
        >= 2.
    period : float
        > 0.
    step : array_like, shape (3,)
        The displacement of one copy (its end value less its start value).
    end : float, optional
        Defaults to ``(n - 1) * period + inner.end``.
    """

    __slots__ = ("rep", "step")

    def __init__(self, inner: tr.Track, n: int, period: float, step, end: float | None = None):
        # The plain repeat settles which copy shows at each time; this node adds the drift.
        self.rep = tr.Repeat(inner, n, period, True, end)
        self.step = tr._frozen(step).reshape(3)
        self.end = self.rep.end
        self.start_value = inner.start_value
        self.end_value = inner.end_value + (self.rep.n - 1) * self.step
        self.min_keys = self.rep.min_keys

    @property
    def inner(self) -> tr.Track:
        """The repeated path."""
        return self.rep.inner

    def children(self):
        return (self.rep.inner,)

    def _copies(self, t):
        local = self.rep._local(t)
        k = np.rint((t - local) / self.rep.period)
        return local, k[:, None] * self.step

    def sample(self, t):
        local, d = self._copies(t)
        x, v, a = self.rep.inner.sample(local)
        return tr.Samples(x + d, v, a)

    def sample_x(self, t):
        local, d = self._copies(t)
        return self.rep.inner.sample_x(local) + d

    def _reversed(self, length, memo):
        # As Repeat's: the last copy (holding what follows) first, then n-1 mirrored periods
        # walking back, each one step behind the previous.
        n, P, inner = self.rep.n, self.rep.period, self.rep.inner
        split = P + (length - n * P)
        first = shift(tr.reverse(inner, split, memo), (n - 1) * self.step)
        one = tr.reverse(inner, P, memo)
        rest = (
            shift(one, (n - 2) * self.step) if n == 2 else Drift(shift(one, (n - 2) * self.step), n - 1, P, -self.step)
        )
        return tr.concat(first, rest, split, end=length)

    def _scaled_frames(self, r, memo):
        return Drift(tr.scale_frames(self.rep.inner, r, memo), self.rep.n, self.rep.period * r, self.step, self.end * r)

    def _mapped(self, m, memo):  # pragma: no cover - angle maps never reach a root path
        raise TypeError("a root path has no angles to map")

    def _emit(self, out, offset):
        P, inner = self.rep.period, self.rep.inner
        saved = out.shift
        step = self.step if out.rot is None else out.rot @ self.step
        for k in range(self.rep.n):
            out.shift = saved + k * step
            if k:
                out.junction(offset + k * P, inner.start_value, False)
            inner._emit(out, offset + k * P)
        out.shift = saved


def join(first: tr.Track, second: tr.Track, pivot: float) -> tuple[tr.Track, tr.Track]:
    """Share the velocity across a junction: a path always meets itself, so only the ends must be leaves."""
    if first.end != pivot:
        return first, second
    a, b = tr.edge_leaf(first, "right"), tr.edge_leaf(second, "left")
    if a is None or b is None or abs(tu.edge_turn(first, "right") - tu.edge_turn(second, "left")) > tu.SAME_TURN:
        return first, second  # where the heading changes the velocities are in different frames
    ea, eb = a._prepare().last, b._prepare().first
    if ea is None or eb is None or not tr._changes(ea, eb):
        return first, second
    return tr.with_edge(first, "right", eb), tr.with_edge(second, "left", ea)


def concat(a: tr.Track | None, la: float, b: tr.Track | None, lb: float, turn: float = 0.0) -> tr.Track | None:
    """The root path of ``a + b``, for motions of lengths ``la`` and ``lb``.

    Parameters
    ----------
    a, b : Track or None
        The operands' paths; None for a motion without one, which stands
        still (at the other's end or start, as a joint it does not drive).
    la, lb : float
    turn : float
        Degrees about Y by which ``b``'s heading is turned to continue from
        where ``a`` left the figure facing (0 without root orientations).

    Returns
    -------
    Track or None
        ``a`` until ``la``, then ``b`` turned by ``turn`` and moved so that it
        starts where ``a`` ended; None if neither operand has a path.
    """
    if b is None:
        return None if a is None else tr.pad(a, la + lb)
    if a is None:
        # Stands where b starts, then walks b in the heading it continues from.
        turned = tu.rotate(b, turn)
        if turn:
            turned = shift(turned, b.start_value - turned.start_value)
        return turned if la == 0 else tr.concat(tr.Const(b.start_value), turned, la)
    turned = tu.rotate(b, turn)
    moved = shift(turned, a.end_value - turned.start_value)
    first, second = join(a, moved, la)
    return tr.concat(first, second, la)


def repeat(a: tr.Track, n: int, period: float, turn: float = 0.0, step=None) -> tr.Track:
    """The root path of ``n * m`` (``n >= 2``), ``period`` being ``m``'s length.

    Parameters
    ----------
    a : Track
    n : int
    period : float
        > 0.
    turn : float
        Degrees about Y that ``m``'s heading changes by over one copy: copy
        ``k`` walks turned by ``k * turn`` (a :class:`~.turning.Spiral`).
    step : array_like, shape (3,), optional
        What one copy adds (default ``a.end_value - a.start_value``); a root
        orientation track passes its heading change alone.

    Returns
    -------
    Track
        Copy ``k`` shows ``a`` moved by ``k * step``; where ``a`` lasts the
        whole period the copies share their velocity at each junction, as a
        cycle's joints do (not where the path turns: see :mod:`.turning`).
    """
    step = a.end_value - a.start_value if step is None else np.asarray(step, dtype=float)
    end = n * period if a.end == period else None
    if abs(turn) > tu.SAME_TURN:
        return tu.Spiral(a, n, period, 0.0, turn, step, a.start_value, a.start_value, end)
    plain = Drift(a, n, period, step, end)
    if a.end != period:
        return plain
    last, first = tr.edge_leaf(a, "right"), tr.edge_leaf(a, "left")
    if last is None or first is None:
        return plain
    last_seg, first_seg = last._prepare().last, first._prepare().first
    if last_seg is None or first_seg is None or not tr._changes(last_seg, first_seg):
        return plain
    head = tr.with_edge(a, "right", first_seg)
    tail = shift(tr.with_edge(a, "left", last_seg), (n - 1) * step)
    if n == 2:
        return tr.concat(head, tail, period, end=plain.end)
    middle = tr.with_edge(head, "left", last_seg)
    mids = shift(middle if n == 3 else Drift(middle, n - 2, period, step), step)
    return tr.concat(tr.concat(head, mids, period), tail, (n - 1) * period, end=plain.end)


class Reversal(tr.Track):
    """A path played backwards over ``length`` frames, remembering the path it reverses.

    Mirroring a frame ``x`` to ``length - x`` is not an involution in
    floating point: ``20 - (20 - 1.6)`` is ``1.6000000000000014``.  Mirroring
    twice would move every step and junction that lies where the subtraction
    rounds, and a pose that jumps there would differ by the whole jump just
    beside it.  So reversing this node again over the same ``length`` hands
    back ``origin`` instead of mirroring what it plays.

    Parameters
    ----------
    origin : Track
        The path reversed; ``origin.end <= length``.
    length : float
    played : Track
        What the reversal shows: ``origin`` mirrored about ``length / 2``,
        turned by ``turn`` degrees about Y, then moved by ``d`` (to start
        where ``origin`` starts); ends at ``length``.
    turn : float
    d : array_like, shape (3,)
    """

    __slots__ = ("d", "length", "origin", "played", "turn")

    def __init__(self, origin: tr.Track, length: float, played: tr.Track, turn: float, d):
        self.origin, self.length, self.played = origin, float(length), played
        self.turn, self.d = float(turn), tr._frozen(d).reshape(3)
        self.end = played.end
        self.start_value, self.end_value = played.start_value, played.end_value
        self.min_keys = played.min_keys

    def children(self):
        return (self.played,)

    def sample(self, t):
        return self.played.sample(t)

    def sample_x(self, t):
        return self.played.sample_x(t)

    def _reversed(self, length, memo):
        # A time mirror alone (a piece of a reversed sum): over the same length it is the
        # origin, moved as ``played`` moved it.
        if length == self.length:
            return shift(tu.rotate(self.origin, self.turn), self.d)
        return tr.reverse(self.played, length, memo)

    def _scaled_frames(self, r, memo):
        # Stretching commutes with reversal; the played path is stretched as before, so
        # only the memory is new.
        origin, played = tr.scale_frames(self.origin, r, memo), tr.scale_frames(self.played, r, memo)
        return Reversal(origin, self.length * r, played, self.turn, self.d)

    def _mapped(self, m, memo):  # pragma: no cover - angle maps never reach a root path
        raise TypeError("a root path has no angles to map")

    def _emit(self, out, offset):
        self.played._emit(out, offset)

    def _edge_leaf(self, side):
        return tr.edge_leaf(self.played, side)

    def _with_edge(self, side, edge):
        return tr.with_edge(self.played, side, edge)


def reverse(a: tr.Track, length: float, memo: dict | None = None, turn: float = 0.0, d=None) -> tr.Track:
    """The path played backwards over ``length`` frames: ``a'(t) = a(0) + R (a(length - t) - a(length))``.

    Parameters
    ----------
    a : Track
    length : float
        >= ``a.end``.
    memo : dict, optional
        Shared with :func:`liganimate.runtime.motion.track.reverse`.
    turn : float
        ``R`` is a turn by this many degrees about Y: the heading the motion
        starts in less the one it ends in, so that the figure walks back the
        way it came, facing as it does.
    d : array_like, shape (3,), optional
        What to add instead of ``a(0) - R a(length)`` (a root orientation
        track passes its heading change alone).

    Returns
    -------
    Track
        Starts where ``a`` starts and walks back: a reversed walk walks
        backwards.  Reversing a :class:`Reversal` over its own length gives
        back the very path it reversed.
    """
    if isinstance(a, Reversal) and a.length == length:
        return a.origin
    mirrored = tu.rotate(tr.reverse(a, length, memo), turn)
    if d is None:
        d = a.start_value - tu.about_y(turn) @ a.end_value
    return Reversal(a, length, shift(mirrored, d), turn, d)
