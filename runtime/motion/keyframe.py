"""One keyframe of a track, the unit a motion is built from and listed as.

Kept apart from :mod:`.track` (which evaluates tracks) so that the host, the
IK layer and the exchange writers can build keyframes without knowing how a
track is stored.
"""

from __future__ import annotations

from liganimate.lang.node_methods import record

RAMP = 3.0
"""Frames a LINEAR segment spends reaching its cruise speed (before SCALE FRAMES)."""


# @record: a dataclass whose methods are written out (lang/node_methods.py), cheaper to make at start-up.
@record(frozen=True, slots=True)
class Keyframe:
    """A joint's (or the root's) position at one frame, and how the track gets there.

    Values are checked when a motion is built from them
    (:meth:`~liganimate.runtime.motion.algebra.Motion.from_tracks`), which
    names the joint and the keyframe of a bad one.

    Attributes
    ----------
    frame : float
        Ticks from the start of the motion.
    position : tuple of 3 float
        Angles in degrees (a joint), or the displacement of the model's main
        link in the model's own frame (the root track).
    method : str
        The interpolation method's name (:mod:`.interpolation`) for the
        segment that ends here; case does not matter.
    ramp : float
        Frames a LINEAR segment spends reaching its cruise speed.
    """

    frame: float
    position: tuple[float, float, float]
    method: str = "LINEAR"
    ramp: float = RAMP
