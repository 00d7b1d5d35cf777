"""One pose or a short batch (``short.py``) gives the numbers of the previous short-batch walk and kinematics (issue 22).

``kinematics.placed_transforms`` sends a batch of fewer than 256 poses to
``short.placed_short``, which lays the walk's arithmetic out once per
figure and runs it as a fixed list of numpy calls.  It must give the same
doubles as the walk it replaced (``previous_walk.placed``) bit for bit
(``array_equal``: an exact zero may come out as -0.0), for one pose and
for a batch, on hinges, fixed joints, joints turning about two or three axes,
joints with their own AXIS, slides, joints walked backwards (a figure
re-rooted by FIGURE ... MAIN) and root transforms that scale and mirror;
and the previous implementation's numbers, bit for bit where it summed in
a fixed order (no AXIS, no slide), else to 1e-12.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from previous_kinematics import placed_transforms as previous
from previous_walk import placed as previous_walk
from test_slides_axes import random_robot
from test_walk import hinges, poses, roots

from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import short
from liganimate.runtime.figure.tree import Figure, Joint, Link


def check(fig: Figure, a: np.ndarray, root) -> None:
    got = short.placed_short(fig, a, root)
    assert got.shape == (len(a), fig.n_links, 4, 4)
    np.testing.assert_array_equal(got, previous_walk(fig, a, root))
    want = previous(fig, a, root)
    if fig.has_frames.any() or fig.slides.any():
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    else:
        np.testing.assert_array_equal(got, want)


@settings(max_examples=300, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 12),
    kind=st.sampled_from(["hinges", "robot"]),
    frames=st.sampled_from([1, 1, 2, 5, 64, 65, 255]),
)
def test_one_pose_and_short_batches_give_the_walks_numbers(seed, n, kind, frames):
    rng = np.random.default_rng(seed)
    fig = hinges(rng, n) if kind == "hinges" else random_robot(rng, n)
    a = poses(rng, fig, frames)
    check(fig, a, roots(rng, frames))
    # The same tree re-rooted at another link: other joints walked backwards.
    other = fig.with_main(int(rng.integers(fig.n_links)))
    check(other, poses(rng, other, frames), roots(rng, frames))


def test_a_batch_gives_each_pose_the_numbers_it_gets_alone():
    rng = np.random.default_rng(2)
    for fig in (random_robot(rng, 9), hinges(rng, 9)):
        a = poses(rng, fig, 40)
        root = roots(rng, 40)
        batch = short.placed_short(fig, a, root)
        for i in range(len(a)):
            one = short.placed_short(fig, a[i : i + 1], None if root is None else root[i : i + 1])
            np.testing.assert_array_equal(batch[i : i + 1], one)


def test_slides_and_axes_are_exercised_by_the_random_robots():
    # The property above is only as good as its figures: make sure they hold every kind of joint.
    rng = np.random.default_rng(0)
    figs = [random_robot(rng, 9) for _ in range(20)]
    assert any(f.slides.any() for f in figs)
    assert any((f.has_frames & ~f.slides).any() for f in figs)
    assert any(f.reversed_joints.any() for f in figs)


def test_angles_outside_the_extremes_and_on_locked_axes_are_not_folded_away():
    # pose_transforms does not clamp: a locked axis given an angle must turn.
    rng = np.random.default_rng(3)
    fig = hinges(rng, 9)
    a = rng.uniform(-400, 400, size=(1, fig.n_joints, 3))
    check(fig, a, None)
    assert not np.array_equal(short.placed_short(fig, a, None), short.placed_short(fig, np.zeros_like(a), None))


def test_placed_transforms_takes_short_batches_here_and_pose_transforms_agrees():
    rng = np.random.default_rng(8)
    fig = random_robot(rng, 8)
    a = poses(rng, fig, 1)
    np.testing.assert_array_equal(K.placed_transforms(fig, a, None), previous_walk(fig, a, None))
    np.testing.assert_array_equal(K.pose_transforms(fig, a), previous_walk(fig, a, None))
    np.testing.assert_array_equal(K.pose_transforms(fig, a[0])[None], previous_walk(fig, a, None))
    # A list, a non-contiguous view and a float32 copy are all taken.
    b = np.repeat(a, 2, axis=2)[:, :, ::2]
    np.testing.assert_array_equal(K.pose_transforms(fig, b), previous_walk(fig, a, None))
    np.testing.assert_array_equal(K.pose_transforms(fig, a.tolist()), previous_walk(fig, a, None))
    f32 = a.astype(np.float32)
    np.testing.assert_array_equal(K.pose_transforms(fig, f32), previous_walk(fig, f32.astype(np.float64), None))
    many = poses(rng, fig, 30)
    np.testing.assert_array_equal(K.placed_transforms(fig, many, None), previous_walk(fig, many, None))
    np.testing.assert_array_equal(
        K.pose_transforms(fig, many.reshape(5, 6, fig.n_joints, 3))[2, 3], previous_walk(fig, many, None)[15]
    )


@pytest.mark.parametrize("frames", [1, 7, 100])
def test_each_call_returns_its_own_array(frames):
    rng = np.random.default_rng(4)
    fig = hinges(rng, 6)
    a, b = poses(rng, fig, frames), poses(rng, fig, frames)
    x = short.placed_short(fig, a, None)
    keep = x.copy()
    short.placed_short(fig, b, None)
    np.testing.assert_array_equal(x, keep)
    x[...] = 0.0  # the caller may write into it
    np.testing.assert_array_equal(short.placed_short(fig, a, None), keep)


def test_work_arrays_kept_for_batches_stay_few():
    rng = np.random.default_rng(9)
    figs = [hinges(rng, 5) for _ in range(6)]
    for fig in figs:
        for frames in range(2, 4 * short.BLOCK, 7):
            short.placed_short(fig, poses(rng, fig, frames), None)
    assert len(short._BATCH_WORK) <= 8
    assert all(key[1] <= short.BLOCK for key in short._BATCH_WORK)


def test_no_joints_and_a_single_link():
    lone = Figure((Link("ONLY", None),), ())
    np.testing.assert_array_equal(short.placed_short(lone, np.zeros((1, 0, 3)), None), np.eye(4)[None, None])
    root = np.diag([2.0, -1.0, 3.0, 1.0])[None]
    root[0, :3, 3] = (1, 2, 3)
    np.testing.assert_array_equal(short.placed_short(lone, np.zeros((1, 0, 3)), root), root[:, None])
    two = Figure((Link("A", None), Link("B", None)), (Joint(1, 0, 1, (1, 0, 0), (0, 0, 0), [(-90, 90)]),))
    for f in (two, two.with_main(1)):
        check(f, np.array([[[30.0, 0.0, 0.0]]]), None)


@pytest.mark.parametrize("frames", [1, 3])
def test_threads_never_share_a_work_array(frames):
    rng = np.random.default_rng(6)
    fig = random_robot(rng, 10)
    a = poses(rng, fig, 200)
    want = [previous_walk(fig, a[i : i + frames], None) for i in range(len(a))]
    errors: list = []

    def run(offset: int) -> None:
        for n in range(600):
            i = (n * 7 + offset) % len(a)
            if not np.array_equal(short.placed_short(fig, a[i : i + frames], None), want[i]):
                errors.append(i)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []


def test_the_library_humanoid_rooted_where_built_and_at_a_foot(tmp_path):
    from liganimate.compiler import load_program
    from liganimate.runtime.host import Posed

    path = tmp_path / "load.lig"
    path.write_text("LOAD 'humanoid'\n")
    program, _ = load_program(str(path))
    fig = program.execute("check").variables["HUMANOID"]
    fig = fig.figure if isinstance(fig, Posed) else fig
    rng = np.random.default_rng(12)
    for f in (fig, fig.with_main(fig.links_named("R_FOOT")[0])):
        for frames in [1] * 50 + [2, 32, 200]:
            check(f, poses(rng, f, frames), roots(rng, frames))
