"""The batched pose path gives what the plain definitions give.

Motion sampling without derivatives, joints that hold still, component-major
link transforms composed onto a placement, and the renderer's memory of
evaluated frames are all speed-ups (see benchmarks/pose.py): each must agree
with the straightforward computation, bit for bit where the arithmetic is
the same.
"""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import pose
from liganimate.runtime.figure.tree import Link, join
from liganimate.runtime.motion import algebra as M
from liganimate.runtime.motion.keyframe import Keyframe
from liganimate.runtime.render.frames import Renderer
from liganimate.runtime.values import box


def motions():
    a = M.Motion.from_tracks(
        {
            1: (
                (0, 0, 0),
                [
                    Keyframe(3, (10, 20, 30), "LINEAR"),
                    Keyframe(7, (0, 5, -10), "ACCDCC"),
                    Keyframe(7, (1, 1, 1), "LINEAR"),
                    Keyframe(12, (40, 0, 0), "ACCELERATE"),
                    Keyframe(12.5, (3, 3, 3), "LINEAR"),
                    Keyframe(20, (0, 0, 0), "DECELERATE"),
                ],
            ),
            2: ((5, 5, 5), [Keyframe(4, (0, 0, 90), "DECELERATE")]),
        }
    )
    b = M.Motion.from_tracks({2: ((0, 0, 0), [Keyframe(2, (1, 2, 3), "LINEAR")]), 3: ((1, 1, 1), [])})
    return [
        a,
        a + b,
        3 * a,
        a.scale_frames(-1.5),
        a.scale_frames(-1),
        M.synchronize(a.strip([1]), b.strip([3])),
        (a + b).scale_frames(2) + a,
        1_000_000 * (a + b),
    ]


@pytest.mark.parametrize("order", ["increasing", "shuffled"])
def test_angles_alone_equal_the_full_evaluation(order):
    rng = np.random.default_rng(7)
    t = np.concatenate([rng.uniform(-5, 100, 3000), np.arange(0, 60, 0.5), [7.0, 7.0, 12.0, 3.0, 20.0]])
    t = np.sort(t) if order == "increasing" else rng.permutation(t)
    for m in motions():
        np.testing.assert_array_equal(m.evaluate(t), m.evaluate_full(t)[0])


def chain(n: int = 5):
    """A chain of boxes with 3-axis joints, rooted in the middle (some joints walked backwards)."""
    fig = Link("L0", box((0, 0, 0), 0.2, 1.0, 0.2, 40.0))
    for k in range(1, n):
        fig = join(
            k,
            fig,
            (0.0, -0.5, 0.1 * k),
            Link(f"L{k}", box((0, 0, 0), 0.2, 1.0, 0.2, 30.0 + k)),
            (0.0, 0.5, 0.0),
            [(-90, 90), (-45, 45), (-170, 170)],
        )
    fig, _ = fig.with_main_link("L2")
    return fig


def test_link_transforms_equal_the_reference_walk():
    fig = chain()
    assert fig.reversed_joints.any() and not fig.reversed_joints.all()
    rng = np.random.default_rng(3)
    a = rng.uniform(-90, 90, (300, fig.n_joints, 3))
    a[:, 0] = (10.0, -5.0, 30.0)  # a joint that holds still
    a[:, 2, :2] = 0.0  # axes that hold still
    np.testing.assert_allclose(K.pose_transforms(fig, a), K.pose_transforms_reference(fig, a), atol=1e-12)
    # Composed onto a placement (here scaled and mirrored): placement @ pose.
    root = np.tile(np.diag([2.0, -1.0, 1.0, 1.0]), (300, 1, 1))
    root[:, :3, 3] = rng.uniform(-3, 3, (300, 3))
    got = K.placed_transforms(fig, a, root)
    np.testing.assert_allclose(got, root[:, None] @ K.pose_transforms_reference(fig, a), atol=1e-12)
    # One pose, many poses, no pose.
    np.testing.assert_allclose(K.pose_transforms(fig, a[5]), K.pose_transforms_reference(fig, a[5]), atol=1e-12)
    assert K.pose_transforms(fig, a[:0]).shape == (0, fig.n_links, 4, 4)
    # The short-batch path instead of the long one makes no difference.
    old = K.SHORT
    try:
        K.SHORT = 1000
        np.testing.assert_array_equal(K.placed_transforms(fig, a, root), got)
    finally:
        K.SHORT = old


def test_renderer_memory_of_frames_changes_nothing():
    fig = chain()
    m = motions()[1]
    r = Renderer.__new__(Renderer)
    r._angles = {}
    r.angle_frames = 0
    frames = [0.0, 1.5, 3.0, 0.0, 7.0, 1.5, 20.0, 3.0]
    first = r._joint_angles(fig, m, frames)
    np.testing.assert_array_equal(first, pose.joint_angles(fig, m, np.array(frames)))
    np.testing.assert_array_equal(r._joint_angles(fig, m, frames[::-1]), first[::-1])
