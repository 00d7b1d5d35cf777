"""The LIG ANIMATE camera: a perspective eye at ``VIEW POINT`` looking at the origin.

Conventions (see ``docs/semantics-render.md``):

* the eye sits at ``point`` and looks at the world origin, +Y is "up";
  when the viewing direction is parallel to the Y axis, -Z is used as the up
  hint instead (so a view from straight above shows +X to the right and -Z
  towards the top of the image);
* ``width`` is the width of the view measured in the plane through the origin
  perpendicular to the viewing direction; the height there is
  ``width * H / W`` (square pixels);
* pixel ``(i, j)`` covers ``[i, i+1) x [j, j+1)``, so its centre is at
  ``(i + 0.5, j + 0.5)``; x grows to the right and y grows downward.
"""

from __future__ import annotations

import math

import numpy as np

from liganimate.runtime.errors import RenderError

DEFAULT_SIZE = (640, 480)

# A view direction closer than this (as the sine of the angle) to the Y axis
# counts as parallel: the cross product with +Y would be numerically useless.
_PARALLEL_SINE = 1e-9

# The near plane sits at this fraction of the eye's distance from the origin.
# Depth is compared on the upper 32 bits of the float64 1/z (sign, exponent
# and 20 mantissa bits: about 1e-6 relative, see raster.py).  That precision
# is relative, so a small near distance costs no depth resolution; it only
# has to keep 1/z finite.
_NEAR_FRACTION = 1e-4


class Camera:
    """A perspective camera at ``point`` looking at the world origin.

    Parameters
    ----------
    point : array_like, shape (3,)
        The eye position (``VIEW POINT``); must not be the origin.
    width : float
        ``VIEW WIDTH``: the width of the view in the plane through the origin
        perpendicular to the viewing direction, in world units; positive.
    size : tuple of int, optional
        Image size ``(W, H)`` in pixels; default ``(640, 480)``.
    near : float, optional
        Distance of the near clipping plane from the eye along the viewing
        direction; default ``1e-4 * |point - target|``.
    target : array_like, shape (3,), optional
        The point looked at, the origin by default (as the thesis' VIEW
        always does; the modern look's default framing looks elsewhere).
        ``width`` is then measured in the plane through ``target``.

    Attributes
    ----------
    point : ndarray, shape (3,)
        The eye position.
    width : float
        The view width in the plane through the origin.
    size : tuple of int
        ``(W, H)``.
    distance : float
        ``|point - target|``, the eye's distance from the point looked at.
    focal : float
        Pixels per unit of camera-space x/z: ``distance * W / width``.
    near : float
        Near clipping distance.
    axes : ndarray, shape (3, 3)
        Rows are the camera's right, up and forward unit vectors in world space.

    Raises
    ------
    RenderError
        If the view point is the origin or not finite, the width is not a
        positive finite number, or the size is not two positive integers.
    """

    def __init__(self, point, width: float, size=DEFAULT_SIZE, near: float | None = None, target=None):
        p = np.asarray(point, dtype=np.float64)
        self.target = np.zeros(3) if target is None else np.asarray(target, dtype=np.float64)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise RenderError(
                "The VIEW POINT must be three finite numbers.",
                hint="Write it as a 3-vector, e.g. VIEW POINT (0, 1, 10).",
            )
        rel = p - self.target
        distance = math.sqrt(float(rel @ rel))
        if distance == 0.0:
            raise RenderError(
                "The VIEW POINT is the origin, so the camera has no direction to look in.",
                hint="The camera always looks at the origin; place it away from it, e.g. (0, 0, 10).",
            )
        try:
            w = float(width)
        except (TypeError, ValueError):
            w = math.nan
        if not (math.isfinite(w) and w > 0.0):
            raise RenderError(
                f"The VIEW WIDTH must be a positive number, not {width!r}.",
                hint="VIEW WIDTH is the width of the visible region around the origin, in world units.",
            )
        W, H = image_size(size)
        forward = -rel / distance
        up_hint = np.array([0.0, 1.0, 0.0])
        if np.linalg.norm(np.cross(forward, up_hint)) < _PARALLEL_SINE:
            up_hint = np.array([0.0, 0.0, -1.0])
        right = np.cross(forward, up_hint)
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)

        self.point = p
        self.width = w
        self.size = (W, H)
        self.distance = distance
        self.focal = distance * W / w
        self.near = float(near) if near is not None else _NEAR_FRACTION * distance
        if not (math.isfinite(self.near) and self.near > 0.0):
            raise RenderError(f"The near clipping distance must be positive, not {near!r}.")
        self.axes = np.stack([right, up, forward])
        self._supersampled: dict = {}

    def supersampled(self, factor: int) -> Camera:
        """The same view with ``factor`` times as many pixels in each direction.

        Pixel ``(i, j)`` of this camera covers the ``factor x factor``
        pixels ``(factor i + a, factor j + b)`` of the result, whose centres
        form a regular grid inside it.  The result is remembered.

        Parameters
        ----------
        factor : int
            A whole number, at least 1.

        Returns
        -------
        Camera
            ``self`` when ``factor`` is 1.
        """
        if factor == 1:
            return self
        cam = self._supersampled.get(factor)
        if cam is None:
            W, H = self.size
            cam = self._supersampled[factor] = Camera(
                self.point, self.width, (W * factor, H * factor), self.near, self.target
            )
        return cam

    def __repr__(self) -> str:
        return f"Camera(point={self.point.tolist()}, width={self.width}, size={self.size})"

    def to_camera(self, points) -> np.ndarray:
        """World points to camera space (x right, y up, z = depth along the view).

        Parameters
        ----------
        points : array_like, shape (..., 3)
            World-space points.

        Returns
        -------
        ndarray, shape (..., 3)
            Camera-space coordinates; the third one is the depth.
        """
        q = np.asarray(points, dtype=np.float64) - self.point
        a = self.axes
        # Written out element-wise rather than as a matrix product: BLAS may
        # round differently depending on a point's position in the array, and
        # the rasterizer needs a shared vertex to land on bit-identical pixel
        # coordinates in every triangle that uses it (no cracks along edges).
        # (The rasterizer repeats this arithmetic on its own array layout.)
        x, y, z = q[..., 0], q[..., 1], q[..., 2]
        return np.stack(
            [
                x * a[0, 0] + y * a[0, 1] + z * a[0, 2],
                x * a[1, 0] + y * a[1, 1] + z * a[1, 2],
                x * a[2, 0] + y * a[2, 1] + z * a[2, 2],
            ],
            axis=-1,
        )

    def camera_to_pixels(self, cam) -> np.ndarray:
        """Camera-space points to pixel coordinates and depth.

        Parameters
        ----------
        cam : array_like, shape (..., 3)
            Camera-space points (as from :meth:`to_camera`); depths must be
            non-zero (points behind the eye project mirrored).

        Returns
        -------
        ndarray, shape (..., 3)
            ``(x, y, depth)``: pixel x (rightward), pixel y (downward) and the
            camera-space depth.
        """
        cam = np.asarray(cam, dtype=np.float64)
        W, H = self.size
        z = cam[..., 2]
        s = self.focal / z
        return np.stack([0.5 * W + cam[..., 0] * s, 0.5 * H - cam[..., 1] * s, z], axis=-1)

    def project(self, points) -> np.ndarray:
        """Project world points to pixel coordinates and depth.

        Parameters
        ----------
        points : array_like, shape (N, 3)
            World-space points (any leading shape works).

        Returns
        -------
        ndarray, shape (N, 3)
            ``(x, y, depth)`` per point: pixel x (rightward, pixel centres at
            integer + 0.5), pixel y (downward) and the depth along the viewing
            direction (positive in front of the eye).
        """
        return self.camera_to_pixels(self.to_camera(points))


def image_size(size) -> tuple[int, int]:
    """``size`` as (width, height) in pixels, checked: two positive whole numbers.

    Raises
    ------
    RenderError
        Anything else (zero, negative, fractional, not a pair).
    """
    try:
        W, H = (int(s) for s in size)
        ok = W > 0 and H > 0 and (W, H) == tuple(size)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise RenderError(
            f"The image size must be two positive whole numbers, not {size!r}.",
            hint="For example 640 by 480.",
        )
    return W, H
