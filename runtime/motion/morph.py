"""Morph tracks: a link's size (SCALE) and shape (SHAPE) keyframed over a motion.

The thesis' chapter 6 proposes segments "which change in size and shape
throughout a model's animation sequence", keyframed and in-betweened.  A
motion carries them beside its joint tracks as a :class:`Morphs`, whose
channels are ordinary tracks (:mod:`.track`) keyed by link name, so they are
in-betweened by the same methods and velocity rules as joints and composed
by the same algebra (they ride in an inner :class:`~.algebra.Motion` of the
same length as the outer one):

* ``("SCALE", link)``: the link's scale factors ``(sx, sy, sz)`` along its
  own axes, start ``(1, 1, 1)``;
* ``("SHAPE", link, key)``: the weight (first component; the others stay 0)
  of one target shape, ``key`` naming it in :attr:`Morphs.targets`.  The
  link's own shape is the base: its weight is one less the targets'.  A
  keyframe naming a shape puts that target's weight at 1 and every other
  at 0, so the drawn shape is ``base + sum w_k (target_k - base)``.

A link's shape channels are one family: where ``a + b`` meets two motions
that both drive a link's shape, each side gets the family's missing
targets at weight 0 (the shape it shows does not use them), so the
"previous driven value" rule of ``+`` holds for the shape as a whole.

The laws are written out in ``docs/semantics-motion.md``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from liganimate.lang.node_methods import record
from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import interpolation
from liganimate.runtime.motion import track as tr
from liganimate.runtime.motion.keyframe import Keyframe

if TYPE_CHECKING:
    from liganimate.runtime.motion.algebra import Motion

SCALE, SHAPE = "SCALE", "SHAPE"


def _channels(m: Motion) -> dict[Any, tr.Track]:
    """An inner motion's tracks, keyed by channel (a Motion's are typed by joint id)."""
    return cast("dict[Any, tr.Track]", m._tracks)


def _gaps(m: Motion) -> tuple[frozenset[Any], frozenset[Any]]:
    """An inner motion's channels that begin with a gap, and those that end with a hold."""
    return cast("frozenset[Any]", m._open), cast("frozenset[Any]", m._tail)


ONE = (1.0, 1.0, 1.0)


@record(frozen=True, slots=True)
class Target:
    """A shape a SHAPE keyframe names: ``key`` identifies it by content, ``shape`` is the value (a Graphical)."""

    key: str
    shape: Any
    triangles: int


@record(frozen=True, slots=True)
class ShapeKey:
    """One keyframe of a SHAPE track: the target (None: the link's own shape) reached at ``frame``."""

    frame: float
    target: Target | None
    method: str = "LINEAR"
    ramp: float = 3.0


class Morphs:
    """A motion's morph channels (see the module docstring).

    Attributes
    ----------
    motion : Motion
        Tracks keyed by ``("SCALE", link)`` and ``("SHAPE", link, key)``, of
        the outer motion's length.
    targets : dict of str to Target
    """

    __slots__ = ("motion", "targets")

    def __init__(self, motion: Motion, targets: Mapping[str, Target]):
        self.motion = motion
        self.targets = dict(targets)

    @property
    def end(self) -> float:
        """The last frame at which a morph channel changes."""
        return max((t.end for t in _channels(self.motion).values()), default=0.0)

    def fitted(self, length: float) -> Morphs:
        """The same channels inside a motion of ``length`` frames (the outer motion's)."""
        m = self.motion
        if m._length == length:
            return self
        inner = type(m)(m._tracks, m._expr, length, (m._open, m._tail))
        return Morphs(inner, self.targets)

    def links(self, kind: str) -> tuple[str, ...]:
        """Links with a channel of ``kind`` (SCALE or SHAPE), in name order."""
        return tuple(dict.fromkeys(k[1] for k in _channels(self.motion) if k[0] == kind))

    def scale(self, link: str, times: np.ndarray) -> np.ndarray:
        """The link's scale factors at ``times``, shape (T, 3)."""
        with np.errstate(all="ignore"):
            return _channels(self.motion)[(SCALE, link)].sample_x(np.asarray(times, dtype=float))

    def shape(self, link: str, times: np.ndarray) -> tuple[list[Target], np.ndarray]:
        """The link's targets and their weights at ``times``, shape (T, K)."""
        keys = [k for k in _channels(self.motion) if k[0] == SHAPE and k[1] == link]
        t = np.asarray(times, dtype=float)
        with np.errstate(all="ignore"):
            w = np.stack([_channels(self.motion)[k].sample_x(t)[:, 0] for k in keys], axis=1)
        return [self.targets[k[2]] for k in keys], w

    def largest_scale(self, link: str) -> float:
        """The largest factor the link's SCALE track ever shows (its start, keyframes and holds).

        No in-between leaves the range of the keyframes it joins, so this
        bounds every frame; found on the track's distinct nodes, whatever
        repetition count the motion carries.
        """
        seen: set = set()
        stack = [_channels(self.motion)[(SCALE, link)]]
        big = 1.0
        while stack:
            node = stack.pop()
            if id(node) in seen:
                continue
            seen.add(id(node))
            for values in (getattr(node, "start", None), getattr(node, "values", None), getattr(node, "value", None)):
                if values is not None and np.size(values):
                    big = max(big, float(np.max(values)))
            stack.extend(node.children())
        return big

    def channels(self) -> tuple:
        """Every channel key, sorted."""
        return tuple(_channels(self.motion))


def _leaf(who: str, start, keys: list) -> tr.Leaf:
    frames = np.array([float(k.frame) for k in keys], dtype=float)
    values = np.reshape([k.position for k in keys], (-1, 3)).astype(float)
    methods = []
    for k in keys:
        try:
            methods.append(interpolation.get(k.method))
        except KeyError:
            raise MotionError(f"{who}: unknown interpolation method {k.method!r}") from None
    if len(frames) and (frames.min() < 0 or (np.diff(frames) < 0).any()):
        raise MotionError(f"{who}: keyframes must be at frames 0 or more, in order")
    tr.check_frames(frames, f"{who}: a keyframe list that")
    return tr.Leaf(start, frames, values, methods, [float(k.ramp) for k in keys])


def check_scale(value, who: str) -> tuple[float, float, float]:
    """A scale keyframe's three factors, refused unless each is positive and finite.

    Raises
    ------
    MotionError
        For a factor of zero (the segment would vanish) or below (it would turn inside out).
    """
    v = np.asarray(value, dtype=float).reshape(3)
    bad = np.flatnonzero(~(v > 0) | ~np.isfinite(v))
    if bad.size:
        a = int(bad[0])
        raise MotionError(
            f"{who}: a scale factor of {v[a]:g} along {'XYZ'[a]} would "
            + ("flatten the segment to nothing" if v[a] == 0 else "turn the segment inside out"),
            hint="scale factors are positive: 1 keeps the segment's size, 0.5 halves it, 2 doubles it",
        )
    return (float(v[0]), float(v[1]), float(v[2]))


def build(scales: Mapping[str, tuple], shapes: Mapping[str, tuple], length: float, motion_type) -> Morphs | None:
    """The morph channels of a STARTMOTION block.

    Parameters
    ----------
    scales : mapping of link name to (start or None, list of Keyframe)
        Factors ``(sx, sy, sz)``; start defaults to ``(1, 1, 1)``.
    shapes : mapping of link name to (Target or None, list of ShapeKey)
        The start shape (None: the link's own) and the keyframes.
    length : float
        The outer motion's length (its joint tracks' ends); the result may be longer.
    motion_type : type
        :class:`~.algebra.Motion` (passed in, so that this module does not import it).

    Returns
    -------
    Morphs or None
        None when there are no channels.
    """
    tracks: dict = {}
    targets: dict = {}
    for link, (start, keys) in scales.items():
        who = f"the scale of link {link}"
        start = ONE if start is None else check_scale(start, f"{who}, start")
        for n, k in enumerate(keys, start=1):
            check_scale(k.position, f"{who}, keyframe {n}")
        tracks[(SCALE, link)] = _leaf(who, start, keys)
    for link, (start, keys) in shapes.items():
        family = [t for t in [start, *(k.target for k in keys)] if t is not None]
        _same_structure(link, family)
        for t in family:
            targets[t.key] = t
        for key in dict.fromkeys(t.key for t in family):
            s = 1.0 if start is not None and start.key == key else 0.0
            wkeys = [
                Keyframe(
                    k.frame, (1.0 if k.target is not None and k.target.key == key else 0.0, 0.0, 0.0), k.method, k.ramp
                )
                for k in keys
            ]
            tracks[(SHAPE, link, key)] = _leaf(f"the shape of link {link}", (s, 0.0, 0.0), wkeys)
    if not tracks:
        return None
    end = max([length] + [t.end for t in tracks.values()])
    return Morphs(motion_type(tracks, ("keys", "morph", len(tracks), 0), end), targets)


def _same_structure(link: str, family: list) -> None:
    if not family:
        return
    first = family[0]
    for t in family[1:]:
        if t.triangles != first.triangles:
            raise MotionError(
                f"the shape of link {link} cannot in-between a shape of {first.triangles} triangles "
                f"and one of {t.triangles}",
                hint="a morph needs shapes of the same structure: the same triangles in the same order, "
                "as two BOX calls or two calls of one PRIMITIVE give",
            )


def _empty(motion_type, length: float) -> Morphs:
    return Morphs(motion_type({}, ("empty",), length), {})


def _families(m: Morphs) -> dict:
    out: dict = {}
    for k in _channels(m.motion):
        if k[0] == SHAPE:
            out.setdefault(k[1], []).append(k[2])
    return out


def _completed(m: Morphs, other: Morphs) -> Morphs:
    """``m`` with every shape target ``other`` uses on a link ``m`` also shapes, at weight 0.

    The new channel is a sibling of the family scaled by 0: the same pieces,
    gaps and holds, so that ``+`` refills and holds it as it does the family
    (a gap shows the previous motion's weight of that target), and ``+``
    stays associative.
    """
    mine, theirs = _families(m), _families(other)
    inner = m.motion
    extra, opened, tail = {}, set(_gaps(inner)[0]), set(_gaps(inner)[1])
    for link, keys in mine.items():
        sibling = (SHAPE, link, keys[0])
        for key in theirs.get(link, ()):
            if key not in keys:
                new = (SHAPE, link, key)
                extra[new] = tr.scale_extremes(_channels(inner)[sibling], 0.0)
                if sibling in _gaps(inner)[0]:
                    opened.add(new)
                if sibling in _gaps(inner)[1]:
                    tail.add(new)
    if not extra:
        return m
    tracks = dict(_channels(inner))
    tracks.update(extra)
    return Morphs(type(inner)(tracks, inner._expr, inner._length, (opened, tail)), m.targets)


def concat(a: Morphs | None, la: float, b: Morphs | None, lb: float, motion_type) -> Morphs | None:
    """The morphs of ``a + b`` (operand lengths ``la`` and ``lb``): as joint tracks, shapes as one family each."""
    if a is None and b is None:
        return None
    a = _empty(motion_type, la) if a is None else a.fitted(la)
    b = _empty(motion_type, lb) if b is None else b.fitted(lb)
    a, b = _completed(a, b), _completed(b, a)
    return Morphs(a.motion + b.motion, {**a.targets, **b.targets})


def repeat(a: Morphs | None, n: int, length: float) -> Morphs | None:
    """The morphs of ``n * m`` (``length`` is ``m``'s)."""
    return None if a is None else Morphs(a.fitted(length).motion.repeat(n), a.targets)


def scale_frames(a: Morphs | None, r: float, length: float) -> Morphs | None:
    """The morphs of ``m <SCALE FRAMES r>`` (``length`` is ``m``'s)."""
    return None if a is None else Morphs(a.fitted(length).motion.scale_frames(r), a.targets)


def synchronize(parts: Iterable[tuple[int, Morphs | None]], motion_type) -> Morphs | None:
    """The morphs of SYNCHRONIZE: the union of the operands' links (operand number, morphs).

    Raises
    ------
    MotionError
        If two operands drive the same link's scale or shape with different tracks.
    """
    tracks: dict = {}
    owner: dict = {}
    targets: dict = {}
    opened: set = set()
    tail: set = set()
    for i, m in parts:
        if m is None:
            continue
        for k, t in _channels(m.motion).items():
            family = k[:2]
            if family in owner and owner[family] != i and tracks.get(k) is not t:
                raise MotionError(
                    f"the {k[0].lower()} of link {k[1]} is driven by both operand {owner[family]} "
                    f"and operand {i} of SYNCHRONIZE",
                    hint=f"morph link {k[1]} in one of them only",
                )
            owner[family] = i
            tracks[k] = t
        targets.update(m.targets)
        opened |= _gaps(m.motion)[0]
        tail |= _gaps(m.motion)[1]
    if not tracks:
        return None
    ends = max(t.end for t in tracks.values())
    return Morphs(motion_type(tracks, ("sync-morph",), ends, (opened, tail)), targets)


def keyframes(m: Morphs, key: tuple, limit: int) -> tuple[tuple, list[Keyframe]]:
    """One channel written out as a keyframe list (for PRINT)."""
    return tr.materialize(_channels(m.motion)[key], limit)
