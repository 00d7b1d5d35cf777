"""Figures: the joint tree, its kinematics, and motions applied to it as poses.

Owns :mod:`.tree` (the MODEL value and its operations), :mod:`.kinematics`
(rotation matrices, link transforms, clamping) and :mod:`.pose` (joint angles,
link matrices and world triangles for whole batches of frames).

May import: :mod:`liganimate.lang.numbers`, :mod:`liganimate.runtime.errors`,
:mod:`liganimate.runtime.values`, :mod:`liganimate.runtime.motion` and its own
modules.
"""
