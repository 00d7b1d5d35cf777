"""The new batched forward kinematics gives the numbers the previous one gave (issue 22).

Two implementations that must agree, in the manner of pytransform3d's
tests: ``previous_kinematics.placed_transforms`` is the walk as it was
(every joint from the full three-axis formula, one joint at a time with
``einsum``), and ``kinematics.placed_transforms`` now takes the short-batch
path (``short.py``: all joints at once, one product per tree level, as a
fixed list of gathers and sums) or the long-batch one (``folded.py``: one
joint at a time, constants folded).
Both must give the same doubles, bit for bit (``array_equal``: an exact zero
may come out as -0.0), for joints that turn about one, two or three axes,
axes holding still or at zero, joints walked backwards, and placements that
scale and mirror.  Joints with their own AXIS, and slides, agree to 1e-12
only: there the previous walk summed ``F R F^T`` with ``einsum``, whose
order of summation depends on the shape of the batch (the previous walk
itself gives other last bits for one pose than for three), while the new
walks sum in a fixed order.
"""

from __future__ import annotations

import numpy as np
import pytest
from previous_kinematics import placed_transforms as previous
from test_slides_axes import random_robot, random_values

from liganimate.runtime.figure import folded, short
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.tree import Figure, Joint, Link


def hinges(rng: np.random.Generator, n: int) -> Figure:
    """A random tree of joints turning about one, two or three of their axes, or none, at random locations."""
    parents = [int(rng.integers(0, i)) for i in range(1, n)]
    joints = []
    for i, p in zip(range(1, n), parents):
        free = rng.random(3) < 0.5
        ext = [(-100.0, 120.0) if f else (0.0, 0.0) for f in free]
        loc2 = rng.normal(size=3) if rng.random() < 0.5 else (0.0, 0.0, 0.0)
        joints.append(Joint(i, p, i, rng.normal(size=3), loc2, ext))
    links = tuple(Link(f"H{i}", None) for i in range(n))
    return Figure(links, tuple(joints), main=int(rng.integers(n)))


def poses(rng: np.random.Generator, fig: Figure, frames: int) -> np.ndarray:
    """Angles within the extremes, with some joints and axes holding still (at zero or not)."""
    a = random_values(rng, fig, frames)
    if fig.n_joints:
        a[:, rng.integers(fig.n_joints)] = rng.uniform(-30, 30, 3)
        a[:, rng.integers(fig.n_joints), rng.integers(3)] = 0.0
    return a


def roots(rng: np.random.Generator, frames: int):
    """Affine placements that scale and mirror, or None."""
    if rng.random() < 0.5:
        return None
    R = np.tile(np.diag([2.0, -1.0, 1.5, 1.0]), (frames, 1, 1))
    R[:, :3, 3] = rng.uniform(-3, 3, (frames, 3))
    return R


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("frames", [0, 1, 3, 64, 255, 256, 300])
def test_both_walks_give_the_previous_numbers(seed, frames):
    rng = np.random.default_rng(seed)
    fig = hinges(rng, 8) if seed % 2 else random_robot(rng, 7)
    a = poses(rng, fig, frames)
    root = roots(rng, frames)
    want = previous(fig, a, root)
    short_path = short.placed_short(fig, a, root) if frames else want
    for got in (short_path, folded.placed_long(fig, a, root), K.placed_transforms(fig, a, root)):
        assert got.shape == (frames, fig.n_links, 4, 4)
        if fig.has_frames.any() or fig.slides.any():
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
        else:
            np.testing.assert_array_equal(got, want)


def test_a_single_link_and_the_library_humanoid(tmp_path):
    lone = Figure((Link("ONLY", None),), ())
    for n in (1, 100):
        np.testing.assert_array_equal(
            K.placed_transforms(lone, np.zeros((n, 0, 3)), None), np.tile(np.eye(4), (n, 1, 1, 1))
        )
    # The library's HUMANOID: hinges, fixed joints and three-axis joints, rooted where it is built and at a foot.
    from liganimate.compiler import load_program
    from liganimate.runtime.host import Posed

    path = tmp_path / "load.lig"
    path.write_text("LOAD 'humanoid'\n")
    program, _ = load_program(str(path))
    fig = program.execute("check").variables["HUMANOID"]
    fig = fig.figure if isinstance(fig, Posed) else fig
    rng = np.random.default_rng(11)
    for f in (fig, fig.with_main(fig.links_named("R_FOOT")[0])):
        for frames in (1, 40, 200):
            a = poses(rng, f, frames)
            np.testing.assert_array_equal(K.placed_transforms(f, a, None), previous(f, a, None))
