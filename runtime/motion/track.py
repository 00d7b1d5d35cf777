"""Per-joint tracks: keyframe leaves and the lazy nodes that compose them.

A track is a function of time ``t`` (frames, any real number) to a joint's
three angles, with analytic velocity and acceleration.  Every track is
defined on the whole real line: before frame 0 it shows its *start value*,
after its *end* frame it shows its *end value*.  Composite tracks never copy
keyframes: ``Concat`` switches between pieces at pivot frames, ``Repeat``
maps time into one period, ``Pad`` only moves the end frame.  Transformations
(reversal, scaling) rebuild the node graph once per distinct node, so a motion
repeated a billion times is reversed as cheaply as the motion itself.

The exact formulas are documented in ``docs/semantics-motion.md``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from liganimate.lang.numbers import MAX_ANGLE, MAX_FRAME, MIN_FRAME_GAP, magnitude
from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import interpolation
from liganimate.runtime.motion.keyframe import RAMP, Keyframe

MAX_PIECES = 64
"""Pieces a flat Concat may hold; longer chains nest, which keeps appends cheap."""


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


class Samples(NamedTuple):
    """Angles and their time derivatives at N times.

    Attributes
    ----------
    x : ndarray, shape (N, 3)
        Angles in degrees.
    v : ndarray, shape (N, 3)
        Angular velocity in degrees per frame.
    a : ndarray, shape (N, 3)
        Angular acceleration in degrees per frame squared.
    """

    x: np.ndarray
    v: np.ndarray
    a: np.ndarray


def _empty(n: int) -> Samples:
    return Samples(np.empty((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)))


class Track:
    """Base class of the immutable track nodes.

    Attributes
    ----------
    end : float
        Frame after which the track holds ``end_value``.
    start_value, end_value : ndarray, shape (3,)
        Value before frame 0 and after ``end``.
    min_keys : int
        Keyframes the materialized listing has at least (exact for leaves);
        lets ``materialize`` refuse a billion-fold repeat before building it.
    """

    __slots__ = ("end", "end_value", "min_keys", "start_value")

    end: float
    start_value: np.ndarray
    end_value: np.ndarray
    min_keys: int

    def sample(self, t: np.ndarray) -> Samples:
        """Evaluate the track.

        Parameters
        ----------
        t : ndarray, shape (N,)
            Times in frames (float, no NaN).

        Returns
        -------
        Samples
            Each field of shape (N, 3).
        """
        raise NotImplementedError

    def sample_x(self, t: np.ndarray) -> np.ndarray:
        """The angles alone: ``sample(t).x``, without computing the derivatives.

        Parameters
        ----------
        t : ndarray, shape (N,)

        Returns
        -------
        ndarray, shape (N, 3)
        """
        return self.sample(t).x

    def children(self) -> tuple[Track, ...]:
        """Nodes this one evaluates (for inspection).

        Returns
        -------
        tuple of Track
        """
        return ()

    # Transformations are written per node and reached through the memoized
    # module functions below, so that shared subtrees are rebuilt only once.
    def _reversed(self, length: float, memo: dict) -> Track:
        raise NotImplementedError

    def _scaled_frames(self, r: float, memo: dict) -> Track:
        raise NotImplementedError

    def _mapped(self, m: LeafMap, memo: dict) -> Track:
        raise NotImplementedError

    def _emit(self, out: _Emitter, offset: float) -> None:
        raise NotImplementedError

    # Nodes defined elsewhere (the root path's Shift, liganimate.runtime.motion.path)
    # take part in smooth junctions through these two.
    def _edge_leaf(self, side: str) -> Leaf | None:
        return None

    def _with_edge(self, side: str, edge: Edge) -> Track:
        raise TypeError(f"track {type(self).__name__} has no edge leaf")  # pragma: no cover


# ---------------------------------------------------------------------------
# Leaves


def _harmonic(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
    """Harmonic mean where both slopes share a strict sign, else 0 (monotone, like PCHIP)."""
    same = ((s1 > 0) & (s2 > 0)) | ((s1 < 0) & (s2 < 0))
    out = np.zeros(np.broadcast(s1, s2).shape)
    out[same] = 2.0 * s1[same] * s2[same] / (s1[same] + s2[same])
    return out


HERMITE_CAP = 3.0
"""Largest boundary velocity, in units of its segment's mean slope, a cubic segment may take.

Fritsch and Carlson: a cubic Hermite piece whose end slopes lie in
``[0, 3]`` times its mean slope is monotone, so it never leaves the range
of the two keyframes it joins.
"""

# How a segment's end takes part in its knot's velocity (see _knot_velocity).
_WANTS, _FLEXIBLE, _LINEAR, _REST = 1, 2, 3, 4


def _cap(ramp: float, T: float, linear: bool) -> float:
    """Largest boundary velocity of a segment, in units of its slope (T/r for LINEAR)."""
    return T / min(ramp, T / 2.0) if linear else HERMITE_CAP


def _knot_velocity(s1, s2, kind_l, kind_r, w_l, w_r, cap_l, cap_r) -> np.ndarray:
    """Velocity shared by the two segments meeting at each interior knot.

    Parameters
    ----------
    s1, s2 : ndarray, shape (M, 3)
        Mean slopes ``D/T`` of the segment before and after each knot.
    kind_l, kind_r : ndarray of int, shape (M,)
        How each side's end behaves: ``_WANTS`` (a fixed-shape method whose
        ease has a non-zero slope there, proposing its natural velocity),
        ``_FLEXIBLE`` (ease slope 0 at that end only: ACCELERATE's start,
        DECELERATE's end; it takes whatever its neighbour brings),
        ``_LINEAR`` or ``_REST`` (slope 0 at both ends: ACCDCC).
    w_l, w_r : ndarray, shape (M, 3)
        Natural velocities proposed by ``_WANTS`` sides.
    cap_l, cap_r : ndarray, shape (M,)
        Largest velocity each side accepts, in units of its own slope, so
        that it stays between its keyframes (``T/r`` for LINEAR, 3 otherwise).

    Returns
    -------
    ndarray, shape (M, 3)
        0 where the slopes differ in sign (an extreme) or a side rests.
    """
    kl, kr = kind_l[:, None], kind_r[:, None]
    wants_l, wants_r = kl == _WANTS, kr == _WANTS
    v = np.where(
        wants_l & wants_r, _harmonic(w_l, w_r), np.where(wants_l, w_l, np.where(wants_r, w_r, _harmonic(s1, s2)))
    )
    # Two flexible ends (DECELERATE into a keyframe, ACCELERATE out) rest, as both names say.
    v = np.where(((kl == _FLEXIBLE) & (kr == _FLEXIBLE)) | (kl == _REST) | (kr == _REST), 0.0, v)
    same = ((s1 > 0) & (s2 > 0)) | ((s1 < 0) & (s2 < 0))
    limit = np.minimum(cap_l[:, None] * np.abs(s1), cap_r[:, None] * np.abs(s2))
    return np.where(same, np.clip(v, -limit, limit), 0.0)


class Wrapper(Track):
    """A root-path node that changes one inner track's values pointwise (moved, turned).

    The algebra's rebuilding (reversal, SCALE FRAMES, a junction's edge) goes
    through to the inner track and wraps the result the same way; a subclass
    gives :meth:`_rewrapped` and its own sampling and emitting.
    """

    __slots__ = ("inner",)
    inner: Track

    def _rewrapped(self, inner: Track) -> Track:
        """This node's change applied to another inner track."""
        raise NotImplementedError

    def children(self) -> tuple[Track, ...]:
        return (self.inner,)

    def _reversed(self, length: float, memo: dict) -> Track:
        return self._rewrapped(reverse(self.inner, length, memo))

    def _scaled_frames(self, r: float, memo: dict) -> Track:
        return self._rewrapped(scale_frames(self.inner, r, memo))

    def _mapped(self, m: LeafMap, memo: dict) -> Track:  # pragma: no cover - angle maps never reach a root path
        raise TypeError("a root path has no angles to map")

    # A junction shares velocities only between leaves seen the same way: the edge leaf is the
    # inner one (turning.edge_turn says how far a Rotated turns it).
    def _edge_leaf(self, side: str) -> Leaf | None:
        return edge_leaf(self.inner, side)

    def _with_edge(self, side: str, edge: Edge) -> Track:
        return self._rewrapped(with_edge(self.inner, side, edge))


class Edge(NamedTuple):
    """A leaf's first or last segment as its neighbour across a junction sees it.

    Attributes
    ----------
    slope : ndarray, shape (3,)
        Mean slope ``D/T`` of the segment.
    kind : int
        How that end takes part in the knot velocity (see ``_knot_velocity``).
    w : ndarray, shape (3,)
        Natural velocity of that end (used if ``kind`` wants speed).
    cap : float
        Largest velocity the segment accepts, in units of its slope.
    """

    slope: np.ndarray
    kind: int
    w: np.ndarray
    cap: float

    def time_scaled(self, r: float) -> Edge:
        """The edge after SCALE FRAMES ``r > 0`` (velocities divide by ``r``)."""
        return Edge(self.slope / r, self.kind, self.w / r, self.cap)

    def angle_scaled(self, r: float) -> Edge:
        """The edge after SCALE EXTREMES ``r`` (velocities multiply by ``r``)."""
        return Edge(self.slope * r, self.kind, self.w * r, self.cap)

    def mirrored(self) -> Edge:
        """The edge played backwards: it moves the other way, on the other side."""
        return Edge(-self.slope, self.kind, -self.w, self.cap)


def _edge_velocity(left: Edge, right: Edge) -> np.ndarray:
    """The knot velocity, shape (3,), shared across a smooth junction."""
    return _knot_velocity(
        left.slope[None],
        right.slope[None],
        np.array([left.kind]),
        np.array([right.kind]),
        left.w[None],
        right.w[None],
        np.array([left.cap]),
        np.array([right.cap]),
    )[0]


class _Prepared(NamedTuple):
    F: np.ndarray  # (K+1,) knot frames, knot 0 is the start at frame 0
    V: np.ndarray  # (K+1, 3) knot values
    T: np.ndarray  # (K,) segment durations
    D: np.ndarray  # (K, 3) segment displacements
    code: np.ndarray  # (K,) index into kinds
    kinds: tuple  # distinct method objects
    Vs: np.ndarray  # (K, 3) boundary velocity at segment start
    Ve: np.ndarray  # (K, 3) boundary velocity at segment end
    c: np.ndarray  # (K, 3) LINEAR cruise speed
    r: np.ndarray  # (K,) LINEAR ramp length actually used
    herm: np.ndarray  # (K, 3) fixed-shape segment-axes drawn as a cubic Hermite
    first: Edge | None  # the first segment as a neighbour before this leaf sees it
    last: Edge | None  # the last segment as a neighbour after this leaf sees it


class Leaf(Track):
    """A keyframe track: start value at frame 0, then keyframes.

    Parameters
    ----------
    start : array_like, shape (3,)
        Angles at frame 0.
    frames : array_like, shape (K,)
        Non-decreasing keyframe frames, all >= 0; equal frames form a step.
    values : array_like, shape (K, 3)
        Angles reached at each keyframe.
    methods : sequence of InterpolationMethod, length K
        Method of the segment arriving at each keyframe.
    ramps : array_like, shape (K,)
        LINEAR ramp length of the segment arriving at each keyframe (> 0).
    right : bool
        True if the track is right-continuous at its steps (as written by
        users); reversed leaves are left-continuous.
    before, after : Edge, optional
        The segment across a smooth junction before frame 0 / after the last
        keyframe (``a + b`` and ``n * a`` where the poses meet); the leaf's
        first / last knot then shares a velocity with it instead of stopping.
    """

    __slots__ = ("_prep", "after", "before", "frames", "methods", "ramps", "right", "start", "values")

    def __init__(
        self,
        start,
        frames,
        values,
        methods,
        ramps,
        right: bool = True,
        before: Edge | None = None,
        after: Edge | None = None,
    ):
        self.start = _frozen(start).reshape(3)
        self.frames = _frozen(frames).reshape(-1)
        k = len(self.frames)
        self.values = _frozen(values).reshape(k, 3)
        self.methods = tuple(methods)
        self.ramps = _frozen(ramps).reshape(k)
        self.right = bool(right)
        self.end = float(self.frames[-1]) if k else 0.0
        self.start_value = self.start
        self.end_value = self.values[-1] if k else self.start
        self.min_keys = k
        self.before, self.after = before, after
        self._prep: _Prepared | None = None

    def with_edges(self, before: Edge | None, after: Edge | None) -> Leaf:
        """The same keyframes with other neighbours across junctions.

        Parameters
        ----------
        before, after : Edge or None

        Returns
        -------
        Leaf
        """
        return Leaf(self.start, self.frames, self.values, self.methods, self.ramps, self.right, before, after)

    def _prepare(self) -> _Prepared:
        if self._prep is not None:
            return self._prep
        F = np.concatenate([[0.0], self.frames])
        V = np.vstack([self.start[None, :], self.values])
        T = np.diff(F)
        D = np.diff(V, axis=0)
        K = len(T)
        pos = T > 0
        slope = np.zeros((K, 3))
        slope[pos] = D[pos] / T[pos, None]
        kinds: list = []
        code = np.empty(K, dtype=np.intp)
        for i, m in enumerate(self.methods):
            for j, known in enumerate(kinds):  # noqa: B007 - j is kept by the break
                if known is m:
                    break
            else:
                j = len(kinds)
                kinds.append(m)
            code[i] = j
        lin = np.array([m.name == "LINEAR" for m in self.methods], dtype=bool)
        # Natural boundary velocities of fixed-shape segments: (D/T) e'(0), (D/T) e'(1).
        nat0 = np.zeros((K, 3))
        nat1 = np.zeros((K, 3))
        e0 = np.zeros(K)
        e1 = np.zeros(K)
        for j, m in enumerate(kinds):
            _, de, _ = m.ease(np.array([0.0, 1.0]))
            sel = code == j
            e0[sel], e1[sel] = de[0], de[1]
            nat0[sel] = slope[sel] * de[0]
            nat1[sel] = slope[sel] * de[1]
        Vs = np.where(lin[:, None], 0.0, nat0)
        Ve = np.where(lin[:, None], 0.0, nat1)
        if K > 1:
            # Knot i+1 joins segment i and i+1; a zero-length neighbour is a step (boundary kept).
            both = pos[:-1] & pos[1:]
            side = np.where(lin, _LINEAR, np.where(e0 + e1 == 0.0, _REST, 0))
            kind_l = np.where(side[:-1] != 0, side[:-1], np.where(e1[:-1] > 0, _WANTS, _FLEXIBLE))
            kind_r = np.where(side[1:] != 0, side[1:], np.where(e0[1:] > 0, _WANTS, _FLEXIBLE))
            with np.errstate(divide="ignore", invalid="ignore"):
                cap = np.where(lin, T / np.minimum(self.ramps, T / 2.0), HERMITE_CAP)
            knot = _knot_velocity(
                slope[:-1],
                slope[1:],
                kind_l,
                kind_r,
                e1[:-1, None] * slope[:-1],
                e0[1:, None] * slope[1:],
                cap[:-1],
                cap[1:],
            )
            Ve[:-1] = np.where(both[:, None], knot, Ve[:-1])
            Vs[1:] = np.where(both[:, None], knot, Vs[1:])
        first = last = None
        if K and pos[0]:
            kind0 = int(_LINEAR if lin[0] else _REST if e0[0] + e1[0] == 0 else _WANTS if e0[0] > 0 else _FLEXIBLE)
            first = Edge(slope[0], kind0, e0[0] * slope[0], float(_cap(self.ramps[0], T[0], lin[0])))
            if self.before is not None:
                Vs[0] = _edge_velocity(self.before, first)
        if K and pos[-1]:
            kind1 = int(_LINEAR if lin[-1] else _REST if e0[-1] + e1[-1] == 0 else _WANTS if e1[-1] > 0 else _FLEXIBLE)
            last = Edge(slope[-1], kind1, e1[-1] * slope[-1], float(_cap(self.ramps[-1], T[-1], lin[-1])))
            if self.after is not None:
                Ve[-1] = _edge_velocity(last, self.after)
        r = np.minimum(self.ramps, T / 2.0)
        c = np.zeros((K, 3))
        c[pos] = (D[pos] - r[pos, None] * (Vs[pos] + Ve[pos]) / 2.0) / (T[pos] - r[pos])[:, None]
        # A fixed-shape segment keeps its exact ease curve where both boundary
        # velocities are its natural ones; elsewhere it is the cubic Hermite.
        herm = ~lin[:, None] & ((Vs != nat0) | (Ve != nat1)) & pos[:, None]
        self._prep = _Prepared(F, V, T, D, code, tuple(kinds), Vs, Ve, c, r, herm, first, last)
        return self._prep

    def sample(self, t: np.ndarray) -> Samples:
        out = _empty(len(t))
        self._fill(self._prepare(), t, out.x, out)
        return out

    def sample_x(self, t: np.ndarray) -> np.ndarray:
        p = self._prepare()
        if len(t) > 8 * len(p.T) and (t[1:] >= t[:-1]).all():
            return self._sample_sorted_x(p, t)
        x = np.empty((len(t), 3))
        self._fill(p, t, x, None)
        return x

    def _fill(self, p: _Prepared, t: np.ndarray, x: np.ndarray, full: Samples | None) -> None:
        """Write the angles at ``t`` into ``x`` (N, 3), and the derivatives into ``full`` if given.

        ``full``, when given, is the Samples whose ``x`` is ``x``; without it
        no derivative is computed.
        """
        K = len(p.T)
        idx = np.searchsorted(p.F, t, side="right" if self.right else "left")
        x[idx == 0] = self.start
        x[idx > K] = p.V[K]
        inside = np.nonzero((idx > 0) & (idx <= K))[0]
        if len(inside) == 0:
            return
        seg = idx[inside] - 1
        for j, m in enumerate(p.kinds):
            sel = p.code[seg] == j
            if not sel.any():
                continue
            rows, s = inside[sel], seg[sel]
            ts = t[rows]
            if m.name == "LINEAR":
                xs, v, a = _trapezoid(p, s, ts, full is not None)
            else:
                xs, v, a = _fixed(p, m, s, ts, full is not None)
            x[rows] = xs
            if full is not None:
                full.v[rows], full.a[rows] = v, a

    def _sample_sorted_x(self, p: _Prepared, t: np.ndarray) -> np.ndarray:
        """Angles at increasing times: each segment's times are one slice, its values scalars.

        The same arithmetic as the general path, value for value, without
        gathering every row's segment data.
        """
        K = len(p.T)
        x = np.empty((len(t), 3))
        # Rows b[i] .. b[i+1] lie in segment i (knot i to knot i+1).
        b = np.searchsorted(t, p.F, side="left" if self.right else "right").tolist()
        x[: b[0]] = self.start
        x[b[K] :] = p.V[K]
        for k in range(K):
            lo, hi = b[k], b[k + 1]
            if hi <= lo:
                continue
            m = p.kinds[p.code[k]]
            if m.name == "LINEAR":
                x[lo:hi] = _trapezoid(p, k, t[lo:hi], False)[0]
            else:
                x[lo:hi] = _fixed_increasing(p, m, k, t[lo:hi])
        return x

    def _reversed(self, length, memo):
        rev = _cached(memo, ("leaf-rev",), self, self._mirror)
        if length > self.end:
            # The hold after this leaf's end becomes a hold before the mirrored keyframes.  The
            # frame `end` itself belongs to the hold if this leaf is right-continuous, else to
            # its last segment; mirrored, that is the first piece or the second.
            return concat(Const(self.end_value, 0.0), rev, length - self.end, right=not self.right, end=length)
        return rev

    def _mirror(self) -> Leaf:
        E = self.end
        F = np.concatenate([[0.0], self.frames])
        V = np.vstack([self.start[None, :], self.values])
        methods = []
        for m in reversed(self.methods):
            try:
                methods.append(interpolation.get(m.reverse))
            except KeyError:
                raise MotionError(
                    f"interpolation method {m.name} cannot be reversed: its reverse {m.reverse} is not known"
                ) from None
        before = None if self.after is None else self.after.mirrored()
        after = None if self.before is None else self.before.mirrored()
        return Leaf(V[-1], E - F[::-1][1:], V[::-1][1:], methods, self.ramps[::-1], not self.right, before, after)

    def _scaled_frames(self, r, memo):
        with np.errstate(all="ignore"):
            frames, ramps = self.frames * r, self.ramps * r
        check_frames(frames, f"SCALE FRAMES {r:g}")
        if len(ramps) and not ramps.min() > 0:
            raise MotionError(
                f"SCALE FRAMES {r:g} squeezes the motion's speed-up ramps to nothing", hint="use a larger factor"
            )
        before = None if self.before is None else self.before.time_scaled(r)
        after = None if self.after is None else self.after.time_scaled(r)
        return Leaf(self.start, frames, self.values, self.methods, ramps, self.right, before, after)

    def _mapped(self, m, memo):
        return m.leaf(self)

    def _emit(self, out, offset):
        for f, v, m, r in zip(self.frames, self.values, self.methods, self.ramps):
            out.add(offset + f, out.place(v), m.name, r)


def _col(a):
    """A per-row array as a column; a scalar (one segment for every row) as it is."""
    return a[:, None] if np.ndim(a) else a


def _gather(p: _Prepared, s, ts: np.ndarray):
    """Segment data for rows at times ``ts``: ``s`` is each row's segment, or one segment for all."""
    tau = (ts - p.F[s])[:, None]
    sig = (p.F[s + 1] - ts)[:, None]
    return tau, sig, p.V[s], p.V[s + 1]


def _trapezoid(p: _Prepared, s: np.ndarray | int, ts: np.ndarray, full: bool = True):
    """LINEAR segments: ramp Vs -> c over r frames, cruise, ramp c -> Ve over r frames.

    Returns (x, v, a); v and a are None unless ``full``.
    """
    tau, sig, v0, v1 = _gather(p, s, ts)
    r = _col(p.r[s])
    Vs, Ve, c = p.Vs[s], p.Ve[s], p.c[s]
    # Each half is measured from its own keyframe so that the mirrored segment
    # performs the mirrored arithmetic and keyframes are reached exactly.
    xs = np.where(tau < r, Vs * tau + (c - Vs) * tau * tau / (2.0 * r), r * (Vs + c) / 2.0 + c * (tau - r))
    xe = np.where(sig < r, Ve * sig + (c - Ve) * sig * sig / (2.0 * r), r * (Ve + c) / 2.0 + c * (sig - r))
    x = np.where(tau <= sig, v0 + xs, v1 - xe)
    if not full:
        return x, None, None
    v = np.where(tau < r, Vs + (c - Vs) * tau / r, np.where(sig < r, Ve + (c - Ve) * sig / r, c))
    a = np.where(tau < r, (c - Vs) / r, np.where(sig < r, -(c - Ve) / r, 0.0))
    return x, v, a


def _hermite(p: _Prepared, s, tau: np.ndarray, sig: np.ndarray, full: bool):
    """Cubic Hermite piece from ``(F[s], V[s], Vs)`` to ``(F[s+1], V[s+1], Ve)``; (x, v, a).

    Each half is measured from its nearer keyframe with the same arithmetic
    as the mirrored segment would use, so reversal stays exact and both
    keyframes are reached bit for bit.
    """
    T = _col(p.T[s])
    D, Vs, Ve = p.D[s], p.Vs[s], p.Ve[s]
    u, w = tau / T, sig / T
    # x = V0 + D (3u^2 - 2u^3) + T (Vs u w^2 - Ve u^2 w), written from either end.
    xs = p.V[s] + D * (u * u * (3.0 - 2.0 * u)) + T * (Vs * u * w * w - Ve * u * u * w)
    xe = p.V[s + 1] + (-D) * (w * w * (3.0 - 2.0 * w)) + T * ((-Ve) * w * u * u - (-Vs) * w * w * u)
    x = np.where(tau <= sig, xs, xe)
    if not full:
        return x, None, None
    v = D / T * (6.0 * u * w) + Vs * (w * w - 2.0 * u * w) + Ve * (u * u - 2.0 * u * w)
    a = (D / T * (6.0 - 12.0 * u) + Vs * (6.0 * u - 4.0) + Ve * (6.0 * u - 2.0)) / T
    return x, v, a


def _fixed(p: _Prepared, m, s: np.ndarray, ts: np.ndarray, full: bool = True):
    """Fixed-shape segments: v0 + D e(u), or the Hermite where velocities were adjusted.

    Returns (x, v, a); v and a are None unless ``full``.
    """
    tau, sig, v0, v1 = _gather(p, s, ts)
    T = _col(p.T[s])
    D = p.D[s]
    u = np.clip(tau / T, 0.0, 1.0)
    herm = p.herm[s]
    if not full:
        e = _ease_value(m, u[:, 0])[:, None]
        x = np.where(u <= 0.5, v0 + D * e, v1 - D * (1.0 - e))
        if herm.any():
            x = np.where(herm, _hermite(p, s, np.maximum(tau, 0.0), np.maximum(sig, 0.0), False)[0], x)
        return x, None, None
    e, de, d2e = m.ease(u[:, 0])
    e, de, d2e = e[:, None], de[:, None], d2e[:, None]
    x = np.where(u <= 0.5, v0 + D * e, v1 - D * (1.0 - e))
    v, a = D / T * de, D / (T * T) * d2e
    if herm.any():
        hx, hv, ha = _hermite(p, s, np.maximum(tau, 0.0), np.maximum(sig, 0.0), True)
        x, v, a = np.where(herm, hx, x), np.where(herm, hv, v), np.where(herm, ha, a)
    return x, v, a


def _fixed_increasing(p: _Prepared, m, k: int, ts: np.ndarray) -> np.ndarray:
    """:func:`_fixed`'s angles for increasing times all in segment k.

    ``u`` then increases too, so the rows taken from the segment's start
    (``u <= 0.5``) come first: each formula is evaluated on its own rows
    only, with the same arithmetic, value for value.
    """
    if p.herm[k].any():
        return _fixed(p, m, np.full(len(ts), k), ts, False)[0]
    tau = (ts - p.F[k])[:, None]
    D = p.D[k]
    u = np.clip(tau / p.T[k], 0.0, 1.0)
    e = _ease_value(m, u[:, 0])[:, None]
    h = int(np.searchsorted(u[:, 0], 0.5, side="right"))
    x = np.empty((len(ts), 3))
    x[:h] = p.V[k] + D * e[:h]
    x[h:] = p.V[k + 1] - D * (1.0 - e[h:])
    return x


def _ease_value(m, u: np.ndarray) -> np.ndarray:
    """``m.ease(u)[0]`` without the derivatives, for the built-in kind of method."""
    if type(m) is interpolation.Method:
        return np.broadcast_to(m._e(u), u.shape).astype(float)
    return m.ease(u)[0]


# ---------------------------------------------------------------------------
# Composite nodes


class Const(Track):
    """A joint that never moves.

    Parameters
    ----------
    value : array_like, shape (3,)
    end : float
        End frame (a constant track may still "last" for a while).
    """

    __slots__ = ("value",)

    def __init__(self, value, end: float = 0.0):
        self.value = _frozen(value).reshape(3)
        self.end = float(end)
        self.start_value = self.end_value = self.value
        self.min_keys = 0

    def sample(self, t):
        out = _empty(len(t))
        out.x[:] = self.value
        return out

    def sample_x(self, t):
        x = np.empty((len(t), 3))
        x[:] = self.value
        return x

    def _reversed(self, length, memo):
        return Const(self.value, length)

    def _scaled_frames(self, r, memo):
        return Const(self.value, self.end * r)

    def _mapped(self, m, memo):
        return Const(m.value(self.value), self.end)

    def _emit(self, out, offset):
        pass


class Pad(Track):
    """A track whose end is moved later (the hold counts as part of it).

    Parameters
    ----------
    inner : Track
    end : float
        New end frame, >= ``inner.end``.
    hold_from : float, optional
        From this frame on (inclusive) show ``inner.end_value``.  ``a + b``
        uses it for joints only ``a`` drives, so that the junction stays
        right-continuous even if ``a``'s track is left-continuous at its end;
        being tied to ``inner``, the held value follows any change of angles.
    """

    __slots__ = ("hold_from", "inner")

    def __init__(self, inner: Track, end: float, hold_from: float | None = None):
        self.inner = inner
        self.end = float(end)
        self.hold_from = None if hold_from is None else float(hold_from)
        self.start_value, self.end_value = inner.start_value, inner.end_value
        self.min_keys = inner.min_keys

    def sample(self, t):
        if self.hold_from is None:
            return self.inner.sample(t)
        held = t >= self.hold_from
        if not held.any():
            return self.inner.sample(t)
        out = _empty(len(t))
        out.x[held] = self.end_value
        if not held.all():
            out.x[~held], out.v[~held], out.a[~held] = self.inner.sample(t[~held])
        return out

    def sample_x(self, t):
        if self.hold_from is None:
            return self.inner.sample_x(t)
        held = t >= self.hold_from
        if not held.any():
            return self.inner.sample_x(t)
        x = np.empty((len(t), 3))
        x[held] = self.end_value
        if not held.all():
            x[~held] = self.inner.sample_x(t[~held])
        return x

    def children(self):
        return (self.inner,)

    def _reversed(self, length, memo):
        if self.hold_from is None:
            return reverse(self.inner, length, memo)
        split = length - self.hold_from
        return concat(Const(self.end_value), reverse(self.inner, self.hold_from, memo), split, False, length)

    def _scaled_frames(self, r, memo):
        hold = None if self.hold_from is None else self.hold_from * r
        return Pad(scale_frames(self.inner, r, memo), self.end * r, hold)

    def _mapped(self, m, memo):
        return Pad(map_leaves(self.inner, m, memo), self.end, self.hold_from)

    def _emit(self, out, offset):
        self.inner._emit(out, offset)


class Concat(Track):
    """Pieces played one after the other; piece j starts at ``pivots[j-1]``.

    Parameters
    ----------
    pieces : tuple of Track, length J+1
    pivots : array_like, shape (J,)
        Strictly increasing frames where the next piece takes over.  Each
        piece sees local time ``t - pivot``.
    rights : array_like of bool, shape (J,)
        True if, at exactly the pivot, the later piece is shown.
    end : float
    """

    __slots__ = ("pieces", "pivots", "rights")

    def __init__(self, pieces, pivots, rights, end: float):
        self.pieces = tuple(pieces)
        self.pivots = _frozen(pivots).reshape(-1)
        self.rights = np.array(rights, dtype=bool).reshape(-1)
        self.rights.flags.writeable = False
        self.end = float(end)
        self.start_value = self.pieces[0].start_value
        self.end_value = self.pieces[-1].end_value
        self.min_keys = sum(p.min_keys for p in self.pieces) + len(self.pivots)

    def children(self):
        return self.pieces

    def sample(self, t):
        out = _empty(len(t))
        for j, rows, local in self._split(t):
            out.x[rows], out.v[rows], out.a[rows] = self.pieces[j].sample(local)
        return out

    def sample_x(self, t):
        x = np.empty((len(t), 3))
        for j, rows, local in self._split(t):
            x[rows] = self.pieces[j].sample_x(local)
        return x

    def _split(self, t):
        """(piece, rows of t it shows, their local times) for every piece that shows."""
        idx = np.searchsorted(self.pivots, t, side="right")
        # Pivots are strictly increasing, so at most the last passed pivot equals t.
        at = idx > 0
        at[at] = (t[at] == self.pivots[idx[at] - 1]) & ~self.rights[idx[at] - 1]
        idx[at] -= 1
        offsets = np.concatenate([[0.0], self.pivots])
        for j in np.unique(idx):
            rows = idx == j
            yield j, rows, t[rows] - offsets[j]

    def _reversed(self, length, memo):
        bounds = np.concatenate([[0.0], self.pivots, [length]])
        pieces = [reverse(p, bounds[j + 1] - bounds[j], memo) for j, p in enumerate(self.pieces)]
        return Concat(pieces[::-1], (length - self.pivots)[::-1], ~self.rights[::-1], length)

    def _scaled_frames(self, r, memo):
        pieces = [scale_frames(p, r, memo) for p in self.pieces]
        return Concat(pieces, self.pivots * r, self.rights, self.end * r)

    def _mapped(self, m, memo):
        return Concat([map_leaves(p, m, memo) for p in self.pieces], self.pivots, self.rights, self.end)

    def _emit(self, out, offset):
        self.pieces[0]._emit(out, offset)
        for p, q in zip(self.pivots, self.pieces[1:]):
            out.junction(offset + p, q.start_value, _smooth_start(q))
            q._emit(out, offset + p)


class Repeat(Track):
    """``n`` copies of a track, one every ``period`` frames, without copying it.

    Parameters
    ----------
    inner : Track
        ``inner.end <= period``.
    n : int
        Number of copies, >= 2.
    period : float
        Frames between copies, > 0.
    right : bool
        True if at a junction the later copy is shown.
    end : float, optional
        Defaults to ``(n - 1) * period + inner.end``.
    """

    __slots__ = ("inner", "n", "period", "right")

    def __init__(self, inner: Track, n: int, period: float, right: bool = True, end: float | None = None):
        self.inner, self.n, self.period, self.right = inner, int(n), float(period), bool(right)
        self.end = float((self.n - 1) * self.period + inner.end if end is None else end)
        self.start_value, self.end_value = inner.start_value, inner.end_value
        self.min_keys = self.n * inner.min_keys + (self.n - 1)

    def children(self):
        return (self.inner,)

    def _local(self, t):
        """Times within the copy of the inner track that shows at each of ``t``."""
        P, last = self.period, self.n - 1
        with np.errstate(invalid="ignore"):
            k = np.floor(t / P) if self.right else np.ceil(t / P) - 1.0
        k = np.clip(np.nan_to_num(k, nan=0.0), 0, last)
        local = t - k * P
        # t / P can round across an integer; settle the copy by exact comparisons.
        if self.right:
            down, up = (local < 0) & (k > 0), (local >= P) & (k < last)
        else:
            down, up = (local <= 0) & (k > 0), (local > P) & (k < last)
        if down.any() or up.any():
            k = k - down + up
            local = t - k * P
        return local

    def sample(self, t):
        return self.inner.sample(self._local(t))

    def sample_x(self, t):
        return self.inner.sample_x(self._local(t))

    def _reversed(self, length, memo):
        # The last copy (it absorbs any hold after the repeat) comes first, then n-1 mirrored periods.
        # Written so that split is exactly one period when length is this repeat's n * period,
        # the usual case, even when the frames are too large to subtract exactly.
        split = self.period + (length - self.n * self.period)
        first = reverse(self.inner, split, memo)
        one = reverse(self.inner, self.period, memo)
        rest = one if self.n == 2 else Repeat(one, self.n - 1, self.period, not self.right)
        return concat(first, rest, split, right=not self.right, end=length)

    def _scaled_frames(self, r, memo):
        return Repeat(scale_frames(self.inner, r, memo), self.n, self.period * r, self.right, self.end * r)

    def _mapped(self, m, memo):
        return Repeat(map_leaves(self.inner, m, memo), self.n, self.period, self.right, self.end)

    def _emit(self, out, offset):
        for k in range(self.n):
            if k:
                out.junction(offset + k * self.period, self.inner.start_value, _smooth_start(self.inner))
            self.inner._emit(out, offset + k * self.period)


# ---------------------------------------------------------------------------
# Constructors and memoized transformations


def pad(track: Track, end: float, hold_from: float | None = None) -> Track:
    """Give ``track`` a later end frame without changing its values.

    Parameters
    ----------
    track : Track
    end : float
    hold_from : float, optional
        See :class:`Pad`.

    Returns
    -------
    Track
    """
    if isinstance(track, Const):
        return Const(track.value, end)
    if hold_from is None:
        if end == track.end:
            return track
        if isinstance(track, Pad):
            return Pad(track.inner, end, track.hold_from)
    return Pad(track, end, hold_from)


def concat(first: Track, second: Track, pivot: float, right: bool = True, end: float | None = None) -> Track:
    """``first`` until ``pivot``, then ``second`` shifted to start at ``pivot``.

    Parameters
    ----------
    first, second : Track
        ``first.end <= pivot``.
    pivot : float
    right : bool
        At exactly ``pivot``, show ``second`` (True) or ``first`` (False).
    end : float, optional
        Defaults to ``pivot + second.end``.

    Returns
    -------
    Track
    """
    if end is None:
        end = pivot + second.end
    while isinstance(first, Pad) and first.hold_from is None:  # its end is invisible once something follows
        first = first.inner
    if isinstance(first, Concat) and len(first.pieces) < MAX_PIECES and first.pivots[-1] < pivot:
        return Concat(first.pieces + (second,), np.append(first.pivots, pivot), np.append(first.rights, right), end)
    return Concat((first, second), [pivot], [right], end)


def refill(track: Track, value) -> Track:
    """The same track with its leftmost piece, a gap ``Const``, showing ``value``.

    ``a + b`` uses it when ``b`` begins with a time no operand drove the
    joint: that time shows the previous driven value, ``a``'s end.

    Parameters
    ----------
    track : Track
        Its leftmost piece (through Concat and Pad nodes) is a ``Const``.
    value : array_like, shape (3,)

    Returns
    -------
    Track
    """
    if isinstance(track, Const):
        return Const(value, track.end)
    if isinstance(track, Concat):
        first = refill(track.pieces[0], value)
        return Concat((first,) + track.pieces[1:], track.pivots, track.rights, track.end)
    if isinstance(track, Pad):
        return Pad(refill(track.inner, value), track.end, track.hold_from)
    raise TypeError(f"track {type(track).__name__} does not begin with a gap")  # pragma: no cover


def lead_gap(track: Track, frames: float) -> Track:
    """``track`` played ``frames`` later, its leftmost gap ``Const`` grown to cover the frames before.

    ``a + b``, where ``a`` does not drive the joint and ``b`` begins with a
    gap, makes one gap of the two: a gap prefixed as a piece of its own
    would be refilled later (:func:`refill`) while ``b``'s own stayed as it
    was, and ``+`` would not be associative.

    Parameters
    ----------
    track : Track
        Its leftmost piece (through Concat and Pad nodes) is a ``Const``.
    frames : float
        Non-negative.

    Returns
    -------
    Track
        Of end ``track.end + frames``.
    """
    if isinstance(track, Const):
        return Const(track.value, track.end + frames)
    if isinstance(track, Concat):
        first = track.pieces[0]
        first = Const(first.value, first.end + frames) if isinstance(first, Const) else lead_gap(first, frames)
        return Concat((first,) + track.pieces[1:], track.pivots + frames, track.rights, track.end + frames)
    if isinstance(track, Pad):
        hold = None if track.hold_from is None else track.hold_from + frames
        return Pad(lead_gap(track.inner, frames), track.end + frames, hold)
    raise TypeError(f"track {type(track).__name__} does not begin with a gap")  # pragma: no cover


def _smooth_start(track: Track) -> bool:
    """True if ``track`` begins with a leaf joined smoothly to what precedes it."""
    leaf = edge_leaf(track, "left")
    return leaf is not None and leaf.before is not None


def edge_leaf(track: Track, side: str) -> Leaf | None:
    """The leaf that plays at the very start (``"left"``) or end (``"right"``) of a track.

    Parameters
    ----------
    track : Track
    side : {"left", "right"}

    Returns
    -------
    Leaf or None
        None where the track starts or ends with a constant or a hold (the
        joint is at rest there, so a junction stays a velocity barrier).
    """
    if isinstance(track, Leaf):
        return track
    if isinstance(track, Pad):
        if track.hold_from is not None and (side == "right" or track.hold_from <= 0):
            return None
        if side == "right" and track.inner.end != track.end:
            return None
        return edge_leaf(track.inner, side)
    if isinstance(track, Concat):
        if side == "left":
            return edge_leaf(track.pieces[0], side)
        if track.pivots[-1] + track.pieces[-1].end != track.end:
            return None
        return edge_leaf(track.pieces[-1], side)
    if isinstance(track, Repeat):
        if side == "right" and track.end != (track.n - 1) * track.period + track.inner.end:
            return None
        return edge_leaf(track.inner, side)
    return track._edge_leaf(side)


def with_edge(track: Track, side: str, edge: Edge) -> Track:
    """``track`` with the neighbour ``edge`` given to its :func:`edge_leaf` on ``side``.

    Parameters
    ----------
    track : Track
        :func:`edge_leaf` of it on ``side`` is not None.
    side : {"left", "right"}
    edge : Edge

    Returns
    -------
    Track
        A repeat is split so that only its first or last copy changes.
    """
    if isinstance(track, Leaf):
        if side == "left":
            return track.with_edges(edge, track.after)
        return track.with_edges(track.before, edge)
    if isinstance(track, Pad):
        return Pad(with_edge(track.inner, side, edge), track.end, track.hold_from)
    if isinstance(track, Concat):
        pieces = list(track.pieces)
        i = 0 if side == "left" else -1
        pieces[i] = with_edge(pieces[i], side, edge)
        return Concat(pieces, track.pivots, track.rights, track.end)
    if isinstance(track, Repeat):
        P, n, inner = track.period, track.n, track.inner
        rest = inner if n == 2 else Repeat(inner, n - 1, P, track.right)
        if side == "left":
            return concat(with_edge(inner, side, edge), rest, P, track.right, track.end)
        return concat(rest, with_edge(inner, side, edge), (n - 1) * P, track.right, track.end)
    return track._with_edge(side, edge)


def join_smoothly(first: Track, second: Track, pivot: float) -> tuple[Track, Track]:
    """Share each joint's velocity across a junction where the poses meet.

    Parameters
    ----------
    first, second : Track
        ``second`` starts at ``pivot``.
    pivot : float

    Returns
    -------
    (Track, Track)
        Unchanged unless ``first`` ends exactly at ``pivot`` in a leaf whose
        last value is ``second``'s start value, and ``second`` starts in a
        leaf: then those two leaves know each other's edge segments.
    """
    if first.end != pivot or not np.array_equal(first.end_value, second.start_value):
        return first, second
    a, b = edge_leaf(first, "right"), edge_leaf(second, "left")
    if a is None or b is None:
        return first, second
    ea, eb = a._prepare().last, b._prepare().first
    if ea is None or eb is None or not _changes(ea, eb):
        return first, second
    return with_edge(first, "right", eb), with_edge(second, "left", ea)


def _changes(left: Edge, right: Edge) -> bool:
    """True if a smooth junction gives either side another velocity than a barrier does."""
    v = _edge_velocity(left, right)
    bar_l = 0.0 if left.kind == _LINEAR else left.w
    bar_r = 0.0 if right.kind == _LINEAR else right.w
    return not (np.array_equal(v, np.broadcast_to(bar_l, 3)) and np.array_equal(v, np.broadcast_to(bar_r, 3)))


def repeat_smoothly(track: Track, n: int, period: float, end: float | None) -> Track:
    """``Repeat(track, n, period)``, sharing velocities across junctions of a cycle.

    Parameters
    ----------
    track : Track
    n : int
        >= 2.
    period : float
    end : float or None
        As for :class:`Repeat`.

    Returns
    -------
    Track
        Where ``track`` ends at ``period`` on its start value (a cycle), the
        first copy, the middle copies and the last copy each know their
        neighbours; still lazy (at most three leaf copies).
    """
    plain = Repeat(track, n, period, end=end)
    if track.end != period or not np.array_equal(track.end_value, track.start_value):
        return plain
    a, b = edge_leaf(track, "right"), edge_leaf(track, "left")
    if a is None or b is None:
        return plain
    last_seg, first_seg = a._prepare().last, b._prepare().first
    if last_seg is None or first_seg is None or not _changes(last_seg, first_seg):
        return plain
    head = with_edge(track, "right", first_seg)
    tail = with_edge(track, "left", last_seg)
    if n == 2:
        return concat(head, tail, period, end=plain.end)
    middle = with_edge(head, "left", last_seg)
    mids = middle if n == 3 else Repeat(middle, n - 2, period)
    return concat(concat(head, mids, period), tail, (n - 1) * period, end=plain.end)


def gap_length(track: Track) -> float:
    """Frames the leftmost piece (a gap ``Const``, see :func:`refill`) lasts.

    Parameters
    ----------
    track : Track

    Returns
    -------
    float
    """
    while not isinstance(track, Concat):
        if not isinstance(track, Pad):
            return track.end
        track = track.inner
    first = track.pieces[0]
    return float(track.pivots[0]) if isinstance(first, Const) else gap_length(first)


def _cached(memo: dict, key: tuple, node: Track, make: Callable[[], Track]) -> Track:
    k = (id(node),) + key
    hit = memo.get(k)
    if hit is None:
        hit = memo[k] = (node, make())  # keep node alive so its id stays unique
    return hit[1]


def reverse(track: Track, length: float, memo: dict | None = None) -> Track:
    """Mirror a track about ``length / 2``: the result at t is ``track`` at ``length - t``.

    Parameters
    ----------
    track : Track
    length : float
        Mirror length, >= ``track.end`` (the motion's length).
    memo : dict, optional
        Shared between calls so shared subtrees are mirrored once.

    Returns
    -------
    Track
        Ends at ``length``; left-continuous wherever ``track`` was right-continuous.
    """
    memo = {} if memo is None else memo
    return _cached(memo, ("rev", length), track, lambda: pad(track._reversed(length, memo), length))


def scale_frames(track: Track, r: float, memo: dict | None = None) -> Track:
    """Stretch time by ``r > 0``: frames, pivots, periods and ramps times ``r``.

    Parameters
    ----------
    track : Track
    r : float
    memo : dict, optional

    Returns
    -------
    Track
    """
    memo = {} if memo is None else memo
    return _cached(memo, ("frames", r), track, lambda: track._scaled_frames(r, memo))


class LeafMap(NamedTuple):
    """A change of angles that keeps the time structure of a track.

    Attributes
    ----------
    key : hashable
        Identifies the map in the memo.
    leaf : callable
        Leaf -> Leaf with the same frames.
    value : callable
        ndarray (3,) -> ndarray (3,), applied to the value of constant tracks.
    """

    key: object
    leaf: Callable[[Leaf], Leaf]
    value: Callable[[np.ndarray], np.ndarray]


def map_leaves(track: Track, m: LeafMap, memo: dict | None = None) -> Track:
    """Rebuild the graph with ``m`` applied to every leaf and constant.

    Parameters
    ----------
    track : Track
    m : LeafMap
    memo : dict, optional

    Returns
    -------
    Track
    """
    memo = {} if memo is None else memo
    return _cached(memo, ("map", m.key), track, lambda: track._mapped(m, memo))


def scale_extremes(track: Track, r: float, memo: dict | None = None) -> Track:
    """Multiply every angle of the track by ``r``.

    Parameters
    ----------
    track : Track
    r : float
    memo : dict, optional

    Returns
    -------
    Track
    """

    def angles(v: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            out = v * r
        check_angles(out, f"SCALE EXTREMES {r:g}")
        return out

    def leaf(lf: Leaf) -> Leaf:
        before = None if lf.before is None else lf.before.angle_scaled(r)
        after = None if lf.after is None else lf.after.angle_scaled(r)
        return Leaf(angles(lf.start), lf.frames, angles(lf.values), lf.methods, lf.ramps, lf.right, before, after)

    return map_leaves(track, LeafMap(("extremes", r), leaf, angles), memo)


def check_frames(frames: np.ndarray, cause: str) -> None:
    """Keyframe frames (non-decreasing, from 0) within the limits of ``lang/numbers.py``, else MotionError.

    Parameters
    ----------
    frames : ndarray, shape (K,)
    cause : str
        What made them (``"SCALE FRAMES 0.5"``), to start the message.
    """
    if not len(frames):
        return
    last = frames[-1]
    if not last <= MAX_FRAME:
        raise MotionError(
            f"{cause} puts a keyframe at frame {magnitude(last)}, beyond the last frame allowed, {magnitude(MAX_FRAME)}",
            hint="a keyframe's frame is at most 1E9",
        )
    gaps = np.diff(frames, prepend=0.0)
    close = (gaps > 0) & (gaps < MIN_FRAME_GAP)
    if close.any():
        gap = float(gaps[close][0])
        raise MotionError(
            f"{cause} puts two keyframes {gap:g} frames apart, closer than {MIN_FRAME_GAP:g}",
            hint="keyframes of a joint share a frame (a step) or lie at least 1E-100 frames apart",
        )


def check_angles(values: np.ndarray, cause: str) -> None:
    """Angles within ``±MAX_ANGLE`` degrees, else MotionError naming ``cause``."""
    far = float(np.max(np.abs(values))) if np.size(values) else 0.0
    if not far <= MAX_ANGLE:
        raise MotionError(
            f"{cause} makes an angle of {magnitude(far)} degrees, beyond the largest allowed, {magnitude(MAX_ANGLE)}",
            hint="angles are in degrees; a joint's extremes clip them anyway",
        )


def unwrap_angles(start: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Shift each value by a multiple of 360 to lie within 180 degrees of its predecessor.

    Parameters
    ----------
    start : ndarray, shape (A,)
        Anchor, left unchanged.
    values : ndarray, shape (K, A)

    Returns
    -------
    ndarray, shape (K, A)
        A difference of exactly +-180 is kept, so a written half turn keeps its direction.
    """
    diffs = np.diff(np.vstack([start[None, :], values]), axis=0)
    turns = np.where(np.abs(diffs) > 180.0, np.sign(diffs) * np.ceil((np.abs(diffs) - 180.0) / 360.0), 0.0)
    return values - 360.0 * np.cumsum(turns, axis=0)


def unwrap(track: Track, axes: tuple[bool, bool, bool], memo: dict | None = None) -> Track:
    """Unwrap the listed axes inside every leaf (see :func:`unwrap_angles`).

    Parameters
    ----------
    track : Track
    axes : tuple of 3 bool
    memo : dict, optional

    Returns
    -------
    Track
    """
    ax = np.array(axes, dtype=bool)

    def leaf(lf: Leaf) -> Leaf:
        values = np.array(lf.values)
        values[:, ax] = unwrap_angles(lf.start[ax], values[:, ax])
        return Leaf(lf.start, lf.frames, values, lf.methods, lf.ramps, lf.right, lf.before, lf.after)

    # Start values are anchors, and a constant track is nothing but a start value.
    return map_leaves(track, LeafMap(("unwrap", tuple(ax)), leaf, lambda v: v), memo)


# ---------------------------------------------------------------------------
# Materialization and inspection


class _Emitter:
    """Collects a flat keyframe listing, refusing to grow past ``limit``."""

    def __init__(self, start: np.ndarray, limit: int):
        self.keys: list[Keyframe] = []
        self.limit = limit
        self.cur = start
        self.last = 0.0
        # Every value emitted is ``rot @ value + shift``: what a root path's Shift and turning
        # nodes (liganimate.runtime.motion.path) carry; rot None is the identity.
        self.shift = np.zeros(3)
        self.rot: np.ndarray | None = None

    def place(self, value) -> np.ndarray:
        """``value`` as the enclosing path nodes move it."""
        return (value if self.rot is None else self.rot @ value) + self.shift

    def add(self, frame, value, method, ramp):
        if len(self.keys) >= self.limit:
            raise MotionError(f"the keyframe listing exceeds the limit of {self.limit} keyframes")
        x, y, z = (float(v) for v in value)
        self.keys.append(Keyframe(float(frame), (x, y, z), method, float(ramp)))
        self.cur, self.last = value, frame

    def _at_step(self) -> bool:
        """True if the last knot is the end of a zero-length segment (a velocity barrier)."""
        if not self.keys:
            return False
        before = self.keys[-2].frame if len(self.keys) > 1 else 0.0
        return before == self.keys[-1].frame

    def hold_until(self, frame):
        """Constant until ``frame``.

        The hold is a LINEAR segment of zero displacement; it stays constant
        only if both its ends have velocity 0, so it must start at the track's
        start or at a step (a repeated keyframe is added to make one).
        """
        if self.last < frame:
            if self.keys and not self._at_step():
                self.add(self.last, self.cur, "LINEAR", RAMP)
            self.add(frame, self.cur, "LINEAR", RAMP)

    def junction(self, frame, start, smooth: bool = False):
        """A junction of + or *: a step, which also stops the velocity adjustment.

        A smooth junction (the poses meet and the velocity is shared) is
        written as a plain keyframe instead: the listing then computes the
        same shared velocity there.
        """
        if smooth and self.last == frame:
            return
        start = self.place(start)
        self.hold_until(frame)
        if not (self._at_step() and np.array_equal(self.cur, start)):
            self.add(frame, start, "LINEAR", RAMP)


def materialize(track: Track, limit: int) -> tuple[tuple, list[Keyframe]]:
    """Flatten a track into one keyframe list that evaluates to the same angles.

    Junctions appear as zero-length steps, which also stop the LINEAR velocity
    adjustment from crossing them, exactly like the junction they came from.

    Parameters
    ----------
    track : Track
    limit : int
        Most keyframes allowed.

    Returns
    -------
    start : tuple of 3 float
    keys : list of Keyframe

    Raises
    ------
    MotionError
        If the listing would exceed ``limit`` (checked before building it when possible).
    """
    if track.min_keys > limit:
        raise MotionError(
            f"the keyframe listing would have at least {track.min_keys} keyframes, more than the limit of {limit}"
        )
    out = _Emitter(track.start_value, limit)
    track._emit(out, 0.0)
    out.hold_until(track.end)
    return tuple(float(x) for x in track.start_value), out.keys


class Footprint(NamedTuple):
    """What a motion really stores.

    Attributes
    ----------
    nodes : int
        Distinct track nodes.
    keyframes : int
        Keyframes stored in distinct leaves.
    """

    nodes: int
    keyframes: int


def footprint(tracks) -> Footprint:
    """Count distinct nodes and stored keyframes reachable from some tracks.

    Parameters
    ----------
    tracks : iterable of Track

    Returns
    -------
    Footprint
    """
    seen: dict[int, Track] = {}
    stack = list(tracks)
    keys = 0
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen[id(node)] = node
        if isinstance(node, Leaf):
            keys += len(node.frames)
        stack.extend(node.children())
    return Footprint(len(seen), keys)
