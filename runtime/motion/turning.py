"""Root paths that turn: a path seen from a figure that has turned about the vertical.

A motion's root orientation (its ``ROOT ORIENTATION`` track) gives the
figure a heading, the angle about the model's Y axis.  When the motion
algebra continues one motion from where another left the figure (``a + b``,
``n * a``, a reversal), the later path is walked *in the new heading*: its
displacements turn with the figure.  Two lazy nodes do it without copying
keyframes: :class:`Rotated` (a path turned by a constant angle about Y) and
:class:`Spiral` (``n`` copies of a path, each turned by one more step and
starting where the previous one ended: ``n * a`` of a motion that turns).
The laws are in ``docs/semantics-motion.md``, "The root orientation".

A turn about Y maps ``(x, y, z)`` to ``(x cos t + z sin t, y, -x sin t + z cos t)``:
as the complex number ``z + i x`` it is multiplication by ``exp(i t)``,
which sums a spiral's ``k`` steps in closed form, whatever ``k``.
"""

from __future__ import annotations

import math

import numpy as np

from . import track as tr

__all__ = [
    "SAME_TURN",
    "Rotated",
    "edge_turn",
    "Spiral",
    "about_y",
    "orientation_angles",
    "orientation_matrix",
    "rotate",
    "spiral_offsets",
]


def about_y(degrees: float) -> np.ndarray:
    """The rotation matrix by ``degrees`` about +Y (right-hand rule).

    Parameters
    ----------
    degrees : float

    Returns
    -------
    ndarray, shape (3, 3)
    """
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _turn_rows(v: np.ndarray, degrees: np.ndarray) -> np.ndarray:
    """Each row of ``v`` (N, 3) turned about Y by its own angle (N,)."""
    a = np.radians(degrees)
    c, s = np.cos(a)[:, None], np.sin(a)[:, None]
    out = np.empty_like(v)
    out[:, 0:1] = v[:, 0:1] * c + v[:, 2:3] * s
    out[:, 1] = v[:, 1]
    out[:, 2:3] = -v[:, 0:1] * s + v[:, 2:3] * c
    return out


def spiral_offsets(k: np.ndarray, theta: float, phi: float, step) -> np.ndarray:
    """``sum(about_y(theta + i phi) @ step for i < k)`` for each ``k``, in closed form.

    Parameters
    ----------
    k : ndarray, shape (N,)
        Whole numbers >= 0.
    theta, phi : float
        Degrees.
    step : array_like, shape (3,)

    Returns
    -------
    ndarray, shape (N, 3)
    """
    k = np.asarray(k, dtype=float)
    step = np.asarray(step, dtype=float)
    half = math.radians(phi) / 2
    # sum_{i<k} exp(i (theta + i phi)) = exp(i (theta + (k-1) phi / 2)) sin(k phi / 2) / sin(phi / 2)
    if abs(math.sin(half)) < 1e-12:
        gain = k.astype(complex)
    else:
        gain = np.sin(k * half) / math.sin(half) + 0j
    w = (step[2] + 1j * step[0]) * gain * np.exp(1j * (math.radians(theta) + (k - 1) * half))
    return np.column_stack([w.imag, k * step[1], w.real])


class Rotated(tr.Wrapper):
    """A path turned by ``degrees`` about Y (values, velocities and accelerations alike).

    Parameters
    ----------
    inner : Track
    degrees : float
    """

    __slots__ = ("degrees", "matrix")

    def __init__(self, inner: tr.Track, degrees: float):
        self.inner, self.degrees = inner, float(degrees)
        self.matrix = about_y(self.degrees)
        self.end = inner.end
        self.start_value = self.matrix @ inner.start_value
        self.end_value = self.matrix @ inner.end_value
        self.min_keys = inner.min_keys

    # A junction shares velocities only between leaves seen in the same heading (the knot
    # velocity is worked out axis by axis, so both sides must be in one frame): the edge
    # leaf is the inner one (tr.Wrapper), and :func:`edge_turn` says how far it is turned.
    def _rewrapped(self, inner):
        return Rotated(inner, self.degrees)

    def sample(self, t):
        x, v, a = self.inner.sample(t)
        M = self.matrix.T
        return tr.Samples(x @ M, v @ M, a @ M)

    def sample_x(self, t):
        return self.inner.sample_x(t) @ self.matrix.T

    def _emit(self, out, offset):
        saved = out.rot
        out.rot = self.matrix if saved is None else saved @ self.matrix
        self.inner._emit(out, offset)
        out.rot = saved


#: Turns (degrees) smaller than this count as none: a junction between paths turned by
#: amounts this close shares its velocity, and ``n * m`` of a motion turning less is a drift.
SAME_TURN = 1e-9


def edge_turn(track: tr.Track, side: str) -> float:
    """Degrees about Y by which the :func:`~.track.edge_leaf` of ``track`` on ``side`` is turned.

    Parameters
    ----------
    track : Track
    side : {"left", "right"}

    Returns
    -------
    float
    """
    from . import path as rp

    turn = 0.0
    while True:
        if isinstance(track, Rotated):
            turn += track.degrees
            track = track.inner
        elif isinstance(track, (rp.Shift, tr.Pad)):
            track = track.inner
        elif isinstance(track, rp.Reversal):
            track = track.played
        elif isinstance(track, tr.Concat):
            track = track.pieces[0 if side == "left" else -1]
        elif isinstance(track, tr.Repeat):
            track = track.inner
        else:
            return turn


def rotate(track: tr.Track, degrees: float) -> tr.Track:
    """``track`` turned by ``degrees`` about Y; turns of turns fold into one node.

    Parameters
    ----------
    track : Track
    degrees : float

    Returns
    -------
    Track
    """
    from . import path as rp  # path builds on this module

    degrees = float(degrees)
    if degrees == 0.0:
        return track
    if isinstance(track, Rotated):
        return rotate(track.inner, track.degrees + degrees)
    if isinstance(track, rp.Shift):
        return rp.shift(rotate(track.inner, degrees), about_y(degrees) @ track.d)
    if isinstance(track, tr.Const):
        return tr.Const(about_y(degrees) @ track.value, track.end)
    return Rotated(track, degrees)


class Spiral(tr.Track):
    """``n`` copies of a path that turn: copy ``k`` is ``origin + G(k) + R(theta + k phi) (inner - ref)``.

    ``G(k)`` is :func:`spiral_offsets` of ``step``; ``R`` a turn about Y.
    ``n * a`` of a motion whose heading changes by ``phi`` over its length is
    ``Spiral(a, n, L, 0, phi, a.end - a.start, a.start, a.start)``; its
    reversal is another spiral, turning the other way.

    Parameters
    ----------
    inner : Track
        ``inner.end <= period``.
    n : int
        >= 2.
    period : float
    theta, phi : float
        Degrees.
    step, origin, ref : array_like, shape (3,)
    end : float, optional
    """

    __slots__ = ("origin", "phi", "ref", "rep", "step", "theta")

    def __init__(self, inner: tr.Track, n: int, period: float, theta: float, phi: float, step, origin, ref, end=None):
        self.rep = tr.Repeat(inner, n, period, True, end)
        self.theta, self.phi = float(theta), float(phi)
        self.step, self.origin, self.ref = (tr._frozen(v).reshape(3) for v in (step, origin, ref))
        self.end = self.rep.end
        self.start_value = self._place(0, inner.start_value)
        self.end_value = self._place(self.rep.n - 1, inner.end_value)
        self.min_keys = self.rep.min_keys

    def _affine(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Copy ``k``'s ``(R, c)``: it shows ``R @ inner + c``."""
        R = about_y(self.theta + k * self.phi)
        c = self.origin + spiral_offsets(np.array([k]), self.theta, self.phi, self.step)[0] - R @ self.ref
        return R, c

    def _place(self, k: int, value) -> np.ndarray:
        R, c = self._affine(k)
        return R @ np.asarray(value, dtype=float) + c

    def children(self):
        return (self.rep.inner,)

    def _copies(self, t):
        local = self.rep._local(t)
        k = np.rint((t - local) / self.rep.period)
        return local, k

    def _moved(self, rows: np.ndarray, k: np.ndarray, translate: bool) -> np.ndarray:
        angle = self.theta + k * self.phi
        out = _turn_rows(rows - self.ref if translate else rows, angle)
        if translate:
            out += self.origin + spiral_offsets(k, self.theta, self.phi, self.step)
        return out

    def sample(self, t):
        local, k = self._copies(t)
        x, v, a = self.rep.inner.sample(local)
        return tr.Samples(self._moved(x, k, True), self._moved(v, k, False), self._moved(a, k, False))

    def sample_x(self, t):
        local, k = self._copies(t)
        return self._moved(self.rep.inner.sample_x(local), k, True)

    def _piece(self, inner: tr.Track, k: int) -> tr.Track:
        """``inner`` placed as copy ``k`` is."""
        from . import path as rp

        return rp.shift(rotate(inner, self.theta + k * self.phi), self._affine(k)[1])

    def _reversed(self, length, memo):
        # As Repeat's: the last copy (holding what follows) first, then n - 1 mirrored
        # periods, walking back through the copies: a spiral turning the other way.
        n, P, inner = self.rep.n, self.rep.period, self.rep.inner
        split = P + (length - n * P)
        first = self._piece(tr.reverse(inner, split, memo), n - 1)
        one = tr.reverse(inner, P, memo)
        if n == 2:
            rest = self._piece(one, 0)
        else:
            back = -(about_y(-self.phi) @ self.step)
            rest = Spiral(
                one, n - 1, P, self.theta + (n - 2) * self.phi, -self.phi, back, self._origin(n - 2), self.ref
            )
        return tr.concat(first, rest, split, end=length)

    def _origin(self, k: int) -> np.ndarray:
        return self.origin + spiral_offsets(np.array([k]), self.theta, self.phi, self.step)[0]

    def _scaled_frames(self, r, memo):
        inner = tr.scale_frames(self.rep.inner, r, memo)
        args = (self.theta, self.phi, self.step, self.origin, self.ref, self.end * r)
        return Spiral(inner, self.rep.n, self.rep.period * r, *args)

    def _mapped(self, m, memo):  # pragma: no cover - angle maps never reach a root path
        raise TypeError("a root path has no angles to map")

    def _emit(self, out, offset):
        P, inner = self.rep.period, self.rep.inner
        saved_rot, saved_shift = out.rot, out.shift
        outer = np.eye(3) if saved_rot is None else saved_rot
        for k in range(self.rep.n):
            R, c = self._affine(k)
            out.rot, out.shift = outer @ R, saved_shift + outer @ c
            if k:
                out.junction(offset + k * P, inner.start_value, False)
            inner._emit(out, offset + k * P)
        out.rot, out.shift = saved_rot, saved_shift


def orientation_matrix(angles) -> np.ndarray:
    """Rotation matrices of root orientations: ``Ry(ay) Rz(az) Rx(ax)``, the heading outermost.

    A joint's three angles turn ``Rz Ry Rx``; a root orientation puts the
    turn about Y (up, in BVH captures and the library figures) outside the
    tilts, so that continuing a heading (``a + b``) adds to one angle, and a
    capture's yaw is that angle alone.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        ``(ax, ay, az)`` in degrees.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    a = np.deg2rad(np.asarray(angles, dtype=float))
    cx, cy, cz = np.cos(a[..., 0]), np.cos(a[..., 1]), np.cos(a[..., 2])
    sx, sy, sz = np.sin(a[..., 0]), np.sin(a[..., 1]), np.sin(a[..., 2])
    R = np.empty(a.shape[:-1] + (3, 3))
    # Ry @ Rz @ Rx written out.
    R[..., 0, 0] = cy * cz
    R[..., 0, 1] = -cy * sz * cx + sy * sx
    R[..., 0, 2] = cy * sz * sx + sy * cx
    R[..., 1, 0] = sz
    R[..., 1, 1] = cz * cx
    R[..., 1, 2] = -cz * sx
    R[..., 2, 0] = -sy * cz
    R[..., 2, 1] = sy * sz * cx + cy * sx
    R[..., 2, 2] = -sy * sz * sx + cy * cx
    return R


def orientation_angles(R: np.ndarray) -> np.ndarray:
    """The inverse of :func:`orientation_matrix`: ``(ax, ay, az)`` degrees with ``az`` in [-90, 90].

    Parameters
    ----------
    R : ndarray, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    R = np.asarray(R, dtype=float)
    az = np.arcsin(np.clip(R[..., 1, 0], -1.0, 1.0))
    ay = np.arctan2(-R[..., 2, 0], R[..., 0, 0])
    ax = np.arctan2(-R[..., 1, 2], R[..., 1, 1])
    return np.degrees(np.stack([ax, ay, az], axis=-1))
