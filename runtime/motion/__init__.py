"""Motions: per-joint keyframe tracks, their in-betweening and the motion algebra.

Owns :mod:`.keyframe` (the :class:`~.keyframe.Keyframe` a track is built
from and listed as), :mod:`.interpolation` (the ease curves), :mod:`.track` (one joint's
keyframes and how a track is evaluated) and :mod:`.algebra` (the
:class:`~.algebra.Motion` value: ``+``, ``n *``, STRIP, SYNCHRONIZE, the
SCALE transforms).

May import: :mod:`liganimate.lang.numbers`, :mod:`liganimate.runtime.errors`
and its own modules. Nothing about figures, goals or pictures.
"""
