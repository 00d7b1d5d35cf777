"""A capture's turn about up, taken out of its ROOT joint and given to the motion's ROOT ORIENTATION.

A plain ``liganimate import`` builds the capture's own skeleton: an empty
``ORIGIN`` main link and the BVH ROOT (the hips) hanging from it by joint 1,
which turns freely.  The hips' heading, their turn about the file's Y, is
where the actor faces; :func:`split_heading` moves it from joint 1 to the
motion's ROOT ORIENTATION (docs/language.md 4.8), so that the motion algebra
continues it (``TAKE + WALK`` walks off the way the actor ended facing) and
the joint keeps the rest (the hips' tilt and their rest pose).  The figure
is drawn exactly as before: ``Ry(heading) @ joint 1`` is the hips' rotation.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx

from ._rotations import euler_zyx_from_matrix

__all__ = ["split_heading"]

#: The hips' axis that shows their heading must stay this far from vertical (the sine of its
#: elevation at most 1 - this) at every frame; a capture that tumbles keeps its turn on joint 1.
LEVEL = 0.1


def split_heading(parents: np.ndarray, angles: np.ndarray) -> tuple:
    """The ROOT joint's heading as a ROOT ORIENTATION, and the joint's angles without it.

    Parameters
    ----------
    parents : ndarray of int, shape (J,)
        The BVH joints' parents (-1 for the ROOT).
    angles : ndarray, shape (F, J, 3)
        The joint convention's angles (``Rz Ry Rx``, degrees), unwrapped.

    Returns
    -------
    angles : ndarray, shape (F, J, 3)
        A copy whose ROOT joint is ``Ry(-heading)`` of what it was.
    orientation : ndarray, shape (F, 3) or None
        ``(0, heading, 0)``, the heading in degrees from the first frame's,
        unwrapped; None where the ROOT has no axis that stays level enough to
        head anywhere (then ``angles`` is returned unchanged).
    """
    if len(angles) < 2:
        return angles, None  # a still: nowhere to turn
    root = int(np.flatnonzero(parents < 0)[0])
    Q = matrix_from_euler_zyx(angles[:, root])
    # The hips' own axis that stays most level over the take: its heading is the actor's.
    axis = int(np.argmin(np.abs(Q[:, 1, :]).mean(axis=0)))
    v = Q[:, :, axis]
    if (np.hypot(v[:, 0], v[:, 2]) < LEVEL).any():
        return angles, None
    heading = np.degrees(np.unwrap(np.arctan2(v[:, 0], v[:, 2])))
    heading -= heading[0]
    if not np.abs(heading).max() > 0.0:
        return angles, None  # no turn (or no rotation channels): nothing to move
    c, s = np.cos(np.radians(heading)), np.sin(np.radians(heading))
    back = np.zeros((len(heading), 3, 3))  # about_y(-heading), frame by frame
    back[:, 0, 0], back[:, 0, 2], back[:, 1, 1], back[:, 2, 0], back[:, 2, 2] = c, -s, 1.0, s, c
    rest = back @ Q
    out = angles.copy()
    out[:, root] = np.unwrap(euler_zyx_from_matrix(rest), period=360.0, axis=0)
    # Keep the first frame's angles as the file gave them (the same rotation; only the
    # Euler solution or a whole turn could differ).
    out[:, root] += np.round((angles[0, root] - out[0, root]) / 360.0) * 360.0
    orientation = np.zeros((len(heading), 3))
    orientation[:, 1] = heading
    return out, orientation
