"""Property tests: the motion algebra's laws carried through prismatic joints (SLIDE).

The algebra works on a slide's displacements as on angles; these tests check
what a figure makes of them: slides are clipped, never unwrapped, and the
laws survive the slide kinematics (a + b plays b after a, STRIP/SYNCHRONIZE
split and rejoin, SCALE FRAMES stretches time, SCALE EXTREMES scales an
all-slide robot's displacements).
"""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from test_motion_laws import EXTREME_FACTOR, FEW, FRAME_FACTOR, PROFILE, motions, probe_times

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.pose import joint_angles
from liganimate.runtime.figure.tree import Figure, Joint, Link, frame_from_axis
from liganimate.runtime.motion.algebra import strip, synchronize

# Joint 1 slides without limits that matter (its range spans far more than 360:
# a turn joint with it would be free and unwrapped), joint 2 turns about its
# own axis and is free, joint 3 slides within narrow limits.
ROBOT = Figure(
    (Link("BASE", None), Link("CARRIAGE", None), Link("ARM", None), Link("HAND", None)),
    (
        Joint(1, 0, 1, (0.5, 0, 0), (0, -0.5, 0), [(-1e6, 1e6)] * 3, slide=True, axes=frame_from_axis((1, 1, 0))),
        Joint(2, 1, 2, (0, 0.5, 0), (0, -1, 0), [(-180, 180)] * 3, axes=frame_from_axis((0, 0, 1))),
        Joint(3, 2, 3, (0, 1, 0), (0, 0, 0), [(-5, 5), (0, 100), (-360, 360)], slide=True),
    ),
)
# Every joint a slide, all locations zero: each link sits at a sum of displacements.
SLIDES = Figure(
    tuple(Link(f"S{i}", None) for i in range(4)),
    tuple(
        Joint(j, j - 1, j, (0, 0, 0), (0, 0, 0), [(-1e6, 1e6)] * 3, slide=True, axes=frame_from_axis(axis))
        for j, axis in zip((1, 2, 3), ((1, 0, 0), (1, 2, 3), (0, -1, 1)))
    ),
)


def poses(fig: Figure, m, t) -> np.ndarray:
    return K.pose_transforms(fig, joint_angles(fig, m, t))


@PROFILE
@given(motions(2))
def test_slides_take_the_algebras_values_clipped_and_never_unwrapped(m):
    t = probe_times(m)
    a = joint_angles(ROBOT, m, t)
    lo, hi = ROBOT.extremes[..., 0], ROBOT.extremes[..., 1]
    for jid in (1, 3):
        k = ROBOT.joint_index(jid)
        want = np.clip(m.track(jid).sample_x(t), lo[k], hi[k]) if jid in m.joints else np.zeros((len(t), 3))
        np.testing.assert_array_equal(a[:, k], want)


@PROFILE
@given(motions(2), motions(2))
def test_concat_plays_b_after_a_through_the_slides(a, b):
    m = a + b
    La = a.length
    t = probe_times(b)
    t = t[t >= 0.25]  # strictly after the junction
    got, alone = joint_angles(ROBOT, m, La + t), joint_angles(ROBOT, b, t)
    for jid in m.joints:
        k = ROBOT.joint_index(jid)
        if jid not in b.joints:
            # Only a drives it: it holds a's end, clipped like any value.
            end = joint_angles(ROBOT, a, np.array([La + 1e9]))[0, k]
            np.testing.assert_array_equal(got[:, k], np.broadcast_to(end, got[:, k].shape))
            continue
        meet = jid in a.joints and np.array_equal(a.evaluate([La + 1e9], [jid])[:, 0], b.evaluate([-1.0], [jid])[:, 0])
        if b.gap(jid) == 0 and not meet:  # (where they meet the velocity is shared: the algebra's own test)
            np.testing.assert_allclose(got[:, k], alone[:, k], atol=1e-9)


@FEW
@given(motions(2), st.integers(1, 7))
def test_strip_and_synchronize_split_and_rejoin_a_slide_motion(m, mask):
    if not m.joints:
        return
    kept = [j for i, j in enumerate(m.joints) if mask >> i & 1] or [m.joints[0]]
    rest = [j for j in m.joints if j not in kept]
    rejoined = synchronize(strip(m, kept), strip(m, rest)) if rest else strip(m, kept)
    t = probe_times(m)
    np.testing.assert_allclose(poses(ROBOT, rejoined, t), poses(ROBOT, m, t), atol=1e-9)


@FEW
@given(motions(2), FRAME_FACTOR)
def test_scale_frames_stretches_a_slide_motion_in_time(m, r):
    if r <= 0:
        return  # negative factors reverse; the reversal law is the algebra's own test
    t = probe_times(m)
    np.testing.assert_allclose(poses(ROBOT, m.scale_frames(r), r * t), poses(ROBOT, m, t), atol=1e-9)


@FEW
@given(motions(2), EXTREME_FACTOR)
def test_scale_extremes_scales_every_displacement_of_an_all_slide_robot(m, r):
    t = probe_times(m)
    X = poses(SLIDES, m, t)
    Y = poses(SLIDES, m.scale_extremes(r), t)
    np.testing.assert_array_equal(Y[..., :3, :3], X[..., :3, :3])  # slides never turn
    np.testing.assert_allclose(Y[..., :3, 3], r * X[..., :3, 3], atol=1e-6)
