"""The root-translation track under the motion algebra: the laws of docs/semantics-motion.md."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion.algebra import Motion, synchronize
from liganimate.runtime.motion.keyframe import Keyframe

METHODS = ["LINEAR", "ACCELERATE", "DECELERATE", "ACCDCC"]


def walk(step=1.6, length=16.0, start=(0.0, 0.0, 0.0), method="LINEAR") -> Motion:
    """A joint swinging and a root advancing ``step`` along X over ``length`` frames."""
    s = np.asarray(start)
    return Motion.from_tracks(
        {1: ((0, 0, 0), [Keyframe(length / 2, (0, 0, 10), "LINEAR"), Keyframe(length, (0, 0, 0), "LINEAR")])},
        root=(
            tuple(s),
            [
                Keyframe(length / 2, tuple(s + (step / 2, 0.1, 0)), method),
                Keyframe(length, tuple(s + (step, 0, 0)), method),
            ],
        ),
    )


@st.composite
def rooted(draw):
    n = draw(st.integers(1, 3))
    frames = sorted(draw(st.lists(st.floats(0.5, 20.0), min_size=n, max_size=n)))
    if draw(st.booleans()):
        frames.append(frames[-1])  # a step at the path's end: where reversal used to round
    pos = st.tuples(*[st.floats(-5.0, 5.0)] * 3)
    keys = [Keyframe(f, draw(pos), draw(st.sampled_from(METHODS))) for f in frames]
    joint = {2: ((0, 0, 0), [Keyframe(draw(st.floats(0.5, 20.0)), (0, 0, 5), "LINEAR")])}
    return Motion.from_tracks(joint, root=(draw(pos), keys))


def times(*motions) -> np.ndarray:
    top = max(m.length for m in motions)
    return np.concatenate([np.linspace(-1.0, top + 2.0, 301), np.arange(0.0, np.ceil(top) + 1)])


def same_path(a: Motion, b: Motion, atol=1e-9) -> None:
    t = times(a, b)
    np.testing.assert_allclose(a.root_offset(t), b.root_offset(t), atol=atol, rtol=0)
    assert a.length == pytest.approx(b.length)


@settings(max_examples=25, deadline=None)
@given(rooted(), rooted(), rooted())
def test_plus_is_associative_on_root_paths(a, b, c):
    same_path((a + b) + c, a + (b + c))


@settings(max_examples=25, deadline=None)
@given(rooted(), st.integers(2, 5))
def test_n_times_is_a_sum_of_copies(a, n):
    total = a
    for _ in range(n - 1):
        total = total + a
    same_path(n * a, total, atol=1e-8)


@settings(max_examples=25, deadline=None)
@given(rooted())
def test_reversal_twice_is_the_identity(a):
    for m in (a, 3 * a):
        twice = m.scale_frames(-1.0).scale_frames(-1.0)
        t = times(m)
        np.testing.assert_array_equal(twice.root_offset(t), m.root_offset(t))
        assert twice.length == m.length


def stepping(end: float, length: float) -> Motion:
    """A path that ends with a step at ``end`` (two keyframes on one frame), in a motion of ``length``."""
    keys = [
        Keyframe(end / 2, (1.0, 2.0, 0.0), "DECELERATE"),
        Keyframe(end, (3.0, 0.0, 1.0), "ACCELERATE"),
        Keyframe(end, (5.0, 1.0, 0.0), "LINEAR"),
    ]
    return Motion.from_tracks({2: ((0, 0, 0), [Keyframe(length, (0, 0, 5), "LINEAR")])}, root=((0.0, 0.0, 0.0), keys))


def around(frames) -> np.ndarray:
    """Each frame and the doubles on either side of it."""
    f = np.asarray(frames, dtype=float)
    return np.concatenate([np.nextafter(f, -np.inf), f, np.nextafter(f, np.inf)])


@pytest.mark.parametrize(
    ("n", "end", "length"),
    # 3 * 10.7 ends at 32.099999999999994: its junctions 10.7 and 21.4 mirror to 21.399999999999995
    # and 10.699999999999996, not to the reversed repeat's own 21.4 and 10.7.  1.6 in 20 frames:
    # the path holds after its step, and 20 - (20 - 1.6) is 1.6000000000000014.
    [(3, 10.7, 10.7), (5, 1.6, 1.6), (3, 12.7, 12.7), (1, 1.6, 20.0), (3, 1.6, 20.0)],
)
def test_reversing_twice_a_path_that_steps_gives_it_back_exactly(n, end, length):
    m = n * stepping(end, length)
    twice = m.scale_frames(-1.0).scale_frames(-1.0)
    # The step of every copy, the junctions and the end, and a beat either side of each.
    steps = [k * length + end for k in range(n)] + [k * length for k in range(n + 1)]
    t = np.concatenate([around(steps), times(m)])
    np.testing.assert_array_equal(twice.root_offset(t), m.root_offset(t))


def test_a_reversed_path_remembers_what_it_reversed_through_stretching_and_sums():
    m = 3 * stepping(10.7, 10.7)
    t = np.concatenate([around([10.7, 21.4, 32.1]), times(m)])
    back = m.scale_frames(-2.0).scale_frames(-0.5)  # stretched, then shrunk: the same frames
    np.testing.assert_array_equal(back.root_offset(t), m.root_offset(t))
    # Reversing a sum reverses its pieces; where the sum's reversal mirrors a reversed piece's
    # span exactly (here 48.099999999999994 - 32.099999999999994 is 16), it comes back as it was, moved.
    w = walk()
    both = (m.scale_frames(-1.0) + w).scale_frames(-1.0)
    want = w.scale_frames(-1.0) + m
    t = np.concatenate([around([both.length - k * 10.7 for k in range(4)]), times(both)])
    np.testing.assert_allclose(both.root_offset(t), want.root_offset(t), atol=1e-12, rtol=0)


@settings(max_examples=25, deadline=None)
@given(rooted(), st.floats(0.25, 4.0), st.floats(0.25, 4.0))
def test_scale_frames_stretches_the_path_and_composes(a, r, s):
    same_path(a.scale_frames(r).scale_frames(s), a.scale_frames(r * s), atol=1e-8)
    t = np.linspace(0.0, a.length, 50)
    np.testing.assert_allclose(a.scale_frames(r).root_offset(r * t), a.root_offset(t), atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(rooted())
def test_a_negative_factor_walks_back_from_the_start(a):
    L = a.length
    t = np.linspace(0.0, L, 41)
    want = a.root_offset(L - t) - a.root_offset([L]) + a.root_offset([0.0])
    np.testing.assert_allclose(a.scale_frames(-1.0).root_offset(t), want, atol=1e-9)


def test_plus_continues_the_path_where_it_ended():
    w = walk()
    both = w + w
    np.testing.assert_allclose(
        both.root_offset([16.0, 24.0, 32.0]), [[1.6, 0, 0], [2.4, 0.1, 0], [3.2, 0, 0]], atol=1e-12
    )
    ten = 10 * w
    np.testing.assert_allclose(ten.root_offset([160.0]), [[16.0, 0.0, 0.0]], atol=1e-9)
    # A cycle walks on without stopping at its junctions: the speed at frame 16 is the cruise speed.
    v = np.diff(ten.root_offset(np.arange(14.0, 19.0))[:, 0])
    assert v.min() > 0.09


def test_reversal_of_a_sum_is_the_sum_of_the_reversals():
    a, b = walk(), walk(step=-0.5, length=6.0, method="ACCDCC")
    same_path((a + b).scale_frames(-1.0), b.scale_frames(-1.0) + a.scale_frames(-1.0))


def test_a_motion_without_a_path_stands_still_where_the_neighbour_is():
    still = Motion.from_tracks({3: ((0, 0, 0), [Keyframe(5.0, (0, 0, 20), "LINEAR")])})
    w = walk(start=(1.0, 2.0, 3.0))
    np.testing.assert_allclose((still + w).root_offset([0.0, 5.0]), [[1, 2, 3], [1, 2, 3]])
    np.testing.assert_allclose((w + still).root_offset([16.0, 21.0]), [[2.6, 2, 3], [2.6, 2, 3]])
    assert (still + still).root is None
    same_path(Motion.empty() + w, w)
    same_path(w + Motion.empty(), w)


def test_strip_keeps_and_scale_extremes_leaves_the_path():
    w = walk()
    same_path(w.strip([1]), w)
    same_path(w.scale_extremes(0.5), w)
    np.testing.assert_allclose(w.scale_extremes(0.5).evaluate([8.0])[0, 0], [0, 0, 5])


def test_synchronize_keeps_one_path_and_refuses_two():
    w = walk()
    arms = Motion.from_tracks({7: ((0, 0, 0), [Keyframe(4.0, (0, 0, 9), "LINEAR")])})
    same_path(synchronize(arms, w), w)
    same_path(synchronize(w.strip([1]), w.strip([])), w)  # the same path twice is one path
    with pytest.raises(MotionError, match="root track is driven by both operand 1 and operand 2"):
        synchronize(w, walk(step=2.0).strip([]))


def test_root_keyframes_list_the_continued_path():
    start, keys = (2 * walk()).root_keyframes()
    assert start == (0.0, 0.0, 0.0)
    assert [k.frame for k in keys] == [8.0, 16.0, 24.0, 32.0]
    np.testing.assert_allclose([k.position for k in keys], [[0.8, 0.1, 0], [1.6, 0, 0], [2.4, 0.1, 0], [3.2, 0, 0]])
    rebuilt = Motion.from_tracks({}, root=(start, keys))
    np.testing.assert_allclose(
        rebuilt.root_offset(np.arange(0.0, 33.0))[::8], (2 * walk()).root_offset(np.arange(0.0, 33.0))[::8]
    )


def test_root_positions_beyond_the_geometry_limit_are_refused():
    with pytest.raises(MotionError, match="geometry limit"):
        Motion.from_tracks({}, root=((0, 0, 0), [Keyframe(1.0, (2e12, 0, 0), "LINEAR")]))


@pytest.mark.parametrize("n", [0, 1])
def test_small_repeats(n):
    w = walk(start=(0.5, 0.0, 0.0))
    m = n * w
    np.testing.assert_allclose(m.root_offset([0.0, 100.0])[0], [0.5, 0, 0])
    assert m.length == 16.0 * n


def test_pickled_motions_keep_their_path():
    import pickle

    w = 3 * walk()
    same_path(pickle.loads(pickle.dumps(w)), w)
    back = pickle.loads(pickle.dumps(w.scale_frames(-1.0)))
    same_path(back, w.scale_frames(-1.0))
    same_path(back.scale_frames(-1.0), w)


def test_every_method_interpolates_a_root_track_like_a_joint_track():
    for method in METHODS:
        keys = [Keyframe(4.0, (0.0, 0.0, 40.0), method), Keyframe(8.0, (0.0, 0.0, 80.0), method)]
        joint = Motion.from_tracks({1: ((0, 0, 0), keys)})
        root = Motion.from_tracks({}, root=((0, 0, 0), keys))
        t = np.linspace(0.0, 8.0, 33)
        np.testing.assert_array_equal(root.root_offset(t), joint.evaluate(t)[:, 0])
