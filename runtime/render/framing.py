"""Default framing: a scene that never sets VIEW is shown whole, in the modern look.

The thesis' camera sits at ``VIEW POINT`` (0, 0, 10 unless a program says
otherwise) and looks at the origin, ``VIEW WIDTH`` 10 wide; a program that
draws its figures elsewhere, or larger or smaller, shows them cut off or
lost in a corner.  In the modern look a scene in which no VIEW statement is
ever executed (before the scene or during it) is framed instead: while the
program is checked, the world-space box of what the scene draws is gathered
at up to :data:`SAMPLES` evenly spaced ticks (and the last one), and the
camera looks at the box's centre from the front, a little to the right and
above (direction :data:`DIRECTION`), at three times the box's half-diagonal,
with the view just wide enough to hold the box's corners with a margin of
:data:`MARGIN` on each side.  The thesis look, and every scene that sets
VIEW, keep the thesis' camera exactly.
"""

from __future__ import annotations

import math

import numpy as np

from liganimate.runtime.render.camera import Camera

#: Ticks of a scene at which what it draws is measured, at most (evenly spaced, plus its last).
SAMPLES = 64
#: From the centre of what is drawn towards the eye: front, a little right and above.
DIRECTION = (0.45, 0.35, 1.0)
#: Fraction of the view left empty on each side.
MARGIN = 0.08
#: The eye's distance from the centre, in half-diagonals of the box.
DISTANCE = 3.0


def sampled(tick: int, length: int) -> bool:
    """Whether tick ``tick`` of a scene of ``length`` ticks is one whose drawing is measured."""
    stride = max(1, -(-length // SAMPLES))
    return tick % stride == 0 or tick == length - 1


def extent(triangles) -> tuple | None:
    """The world box ``(lo, hi)`` of triangles (N, 3, 3), or None for none."""
    t = np.asarray(triangles, dtype=np.float64).reshape(-1, 3)
    if not len(t):
        return None
    return t.min(axis=0), t.max(axis=0)


def union(a, b):
    """The box holding boxes ``a`` and ``b`` (either may be None)."""
    if a is None:
        return b
    if b is None:
        return a
    return np.minimum(a[0], b[0]), np.maximum(a[1], b[1])


def framing_view(box, size) -> tuple:
    """The view ``(point, width, target)`` that shows the box ``(lo, hi)`` whole in an image of ``size``.

    Parameters
    ----------
    box : (array_like (3,), array_like (3,))
        World-space corners, least and greatest.
    size : (int, int)
        ``(W, H)`` of the image.

    Returns
    -------
    tuple
        ``((x, y, z), width, (tx, ty, tz))``, floats, for :class:`Camera`.
    """
    lo, hi = np.asarray(box[0], dtype=np.float64), np.asarray(box[1], dtype=np.float64)
    centre = 0.5 * (lo + hi)
    half = 0.5 * float(np.linalg.norm(hi - lo))
    if not half > 0:
        half = max(1.0, float(np.abs(centre).max()) * 1e-3)  # a point: a small view around it
    d = np.asarray(DIRECTION, dtype=np.float64)
    eye = centre + d * (DISTANCE * half / math.sqrt(float(d @ d)))
    probe = Camera(eye, 1.0, size, target=centre)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    cam = probe.to_camera(corners)
    W, H = probe.size
    # Width at the target's plane so that every corner's x/z and y/z (times the distance) fit.
    reach_x = float(np.max(np.abs(cam[:, 0]) / cam[:, 2]))
    reach_y = float(np.max(np.abs(cam[:, 1]) / cam[:, 2]))
    width = 2.0 * probe.distance * max(reach_x, reach_y * W / H) / (1.0 - 2.0 * MARGIN)
    if not width > 0:
        width = 2.0 * half
    return tuple(float(v) for v in eye), width, tuple(float(v) for v in centre)
