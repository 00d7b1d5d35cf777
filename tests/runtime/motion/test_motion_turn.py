"""The root orientation under the motion algebra: the laws of docs/semantics-motion.md, "The root orientation"."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import turning as tu
from liganimate.runtime.motion.algebra import Motion, synchronize
from liganimate.runtime.motion.keyframe import Keyframe

METHODS = ["LINEAR", "ACCELERATE", "DECELERATE", "ACCDCC"]


def arc(turn=90.0, step=1.0, length=10.0, tilt=0.0) -> Motion:
    """A joint swinging, the root walking ``step`` along X and turning ``turn`` degrees about Y."""
    return Motion.from_tracks(
        {1: ((0, 0, 0), [Keyframe(length, (0, 0, 10), "LINEAR")])},
        root=((0, 0, 0), [Keyframe(length, (step, 0, 0), "LINEAR")]),
        turn=((tilt, 0, 0), [Keyframe(length, (tilt, turn, 0), "LINEAR")]),
    )


@st.composite
def turning(draw, tilted=True, fixed=False):
    n = draw(st.integers(1, 3))
    frames = sorted(draw(st.lists(st.floats(0.5, 20.0), min_size=n, max_size=n)))
    pos = st.tuples(*[st.floats(-5.0, 5.0)] * 3)
    angle = st.floats(-170.0, 170.0)
    keys = [Keyframe(f, draw(pos), draw(st.sampled_from(METHODS))) for f in frames]
    tilt = (lambda: draw(st.floats(-20.0, 20.0))) if tilted else (lambda: 0.0)
    turns = [Keyframe(draw(st.floats(0.5, 20.0)), (tilt(), draw(angle), tilt()), draw(st.sampled_from(METHODS)))]
    joint = {2: ((0, 0, 0), [Keyframe(draw(st.floats(0.5, 20.0)), (0, 0, 5), "LINEAR")])}
    start = (tilt(), draw(angle), tilt())
    if fixed:  # every operand starts at one point, facing one way
        return Motion.from_tracks(joint, root=((0.5, 0.0, -1.0), keys), turn=((3.0, 20.0, -2.0), turns))
    if draw(st.booleans()):
        return Motion.from_tracks(joint, root=(draw(pos), keys), turn=(start, turns))
    return Motion.from_tracks(joint, root=(draw(pos), keys))  # some operands do not turn


def times(*motions) -> np.ndarray:
    top = max(m.length for m in motions)
    return np.concatenate([np.linspace(-1.0, top + 2.0, 301), np.arange(0.0, np.ceil(top) + 1)])


def same_root(a: Motion, b: Motion, atol=1e-8) -> None:
    t = times(a, b)
    np.testing.assert_allclose(a.root_offset(t), b.root_offset(t), atol=atol, rtol=0)
    np.testing.assert_allclose(a.root_orientation(t), b.root_orientation(t), atol=atol, rtol=0)
    assert a.length == pytest.approx(b.length)


@settings(max_examples=30, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(turning(), turning(), turning())
def test_plus_is_associative_with_orientations(a, b, c):
    same_root((a + b) + c, a + (b + c))


@settings(max_examples=30, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(turning(), st.integers(2, 6))
def test_n_times_is_a_sum_of_turning_copies(a, n):
    total = a
    for _ in range(n - 1):
        total = total + a
    same_root(n * a, total, atol=1e-7)


@settings(max_examples=30, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(turning())
def test_reversal_twice_gives_the_path_and_orientation_back(a):
    for m in (a, 3 * a, a + a.scale_frames(2.0)):
        twice = m.scale_frames(-1.0).scale_frames(-1.0)
        t = times(m)
        np.testing.assert_array_equal(twice.root_offset(t), m.root_offset(t))
        np.testing.assert_array_equal(twice.root_orientation(t), m.root_orientation(t))


@settings(max_examples=30, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(turning(fixed=True), turning(fixed=True))
def test_reversal_of_a_sum_is_the_sum_of_the_reversals(a, b):
    """As for paths, where both operands start at one point; here also facing one way.

    Exactly at the junction a tilt that jumps shows its other side (continuity flips
    side under reversal, as a joint's does), so that instant is left out.
    """
    x, y = (a + b).scale_frames(-1.0), b.scale_frames(-1.0) + a.scale_frames(-1.0)
    t = times(x)
    t = t[np.abs(t - b.length) > 1e-9]
    np.testing.assert_allclose(x.root_offset(t), y.root_offset(t), atol=1e-7, rtol=0)
    np.testing.assert_allclose(x.root_orientation(t), y.root_orientation(t), atol=1e-7, rtol=0)


@settings(max_examples=30, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(turning(), st.floats(0.25, 4.0))
def test_scale_frames_stretches_the_path_and_the_turn(a, r):
    t = times(a)
    s = a.scale_frames(r)
    np.testing.assert_allclose(s.root_offset(t * r), a.root_offset(t), atol=1e-8)
    np.testing.assert_allclose(s.root_orientation(t * r), a.root_orientation(t), atol=1e-8)


@settings(max_examples=30, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(turning(tilted=False))
def test_a_reversed_motion_walks_back_facing_as_it_came(a):
    """Played backwards, the figure retraces the path in the world: each pose seen from its own heading is mirrored."""
    L = a.length
    back = a.scale_frames(-1.0)
    t = np.linspace(0.0, L, 41)

    # The reversed figure's pose relative to where it starts equals the original's relative to where it ends.
    def relative(m, at, ref):
        R = tu.orientation_matrix(m.root_orientation([ref])[0])
        return (m.root_offset(at) - m.root_offset([ref])) @ R, m.root_orientation(at)[:, 1] - m.root_orientation([ref])[
            0, 1
        ]

    p_back, h_back = relative(back, t, 0.0)
    p_orig, h_orig = relative(a, L - t, L)
    np.testing.assert_allclose(p_back, p_orig, atol=1e-7)
    np.testing.assert_allclose(h_back, h_orig, atol=1e-7)


def test_plus_walks_on_in_the_heading_the_previous_motion_left():
    a = arc(turn=90.0)
    two = a + a
    assert two.heading("end") == pytest.approx(180.0)
    # The second copy walks along X turned by 90 degrees about Y: along -Z.
    np.testing.assert_allclose(two.root_offset([10.0, 20.0]), [[1, 0, 0], [1, 0, -1]], atol=1e-12)
    square = 4 * a
    np.testing.assert_allclose(square.root_offset([40.0]), [[0, 0, 0]], atol=1e-9)  # back where it began
    assert square.root_orientation([40.0])[0, 1] == pytest.approx(360.0)
    # A motion that does not turn walks on in the heading it inherits.
    straight = Motion.from_tracks({}, root=((0, 0, 0), [Keyframe(5.0, (2, 0, 0), "LINEAR")]))
    np.testing.assert_allclose((a + straight).root_offset([15.0]), [[1, 0, -2]], atol=1e-12)
    np.testing.assert_allclose((a + straight).root_orientation([15.0]), [[0, 90, 0]], atol=1e-12)


def test_a_billion_turning_copies_stay_lazy_and_exact():
    a = arc(turn=90.0)
    many = 10**9 * a
    assert many.footprint().nodes < 20
    # After 4k copies the figure is back at the start: exactly periodic.
    np.testing.assert_allclose(many.root_offset([4e8 * 10]), [[0, 0, 0]], atol=1e-6)
    np.testing.assert_allclose(many.root_offset([(4e8 + 1) * 10]), [[1, 0, 0]], atol=1e-6)


def test_tilt_does_not_continue_and_strip_and_extremes_keep_the_orientation():
    a = arc(turn=30.0, tilt=5.0)
    two = a + a
    assert two.root_orientation([20.0])[0] == pytest.approx([5.0, 60.0, 0.0])
    assert a.strip([1]).turn is a.turn
    assert a.scale_extremes(2.0).turn is a.turn


def test_synchronize_keeps_one_orientation_and_refuses_two():
    a = arc()
    assert synchronize(a.strip([]), Motion.from_tracks({3: ((0, 0, 0), [])})).turn is a.turn
    with pytest.raises(MotionError, match="root orientation is driven by both operand 1 and operand 2"):
        synchronize(a, arc(turn=10.0).strip([]))


def test_turn_keyframes_list_the_continued_heading():
    start, keys = (3 * arc(turn=90.0)).turn_keyframes()
    assert start == (0.0, 0.0, 0.0)
    assert keys[-1].position == pytest.approx((0.0, 270.0, 0.0))
    # The listing fed back gives the same orientation.
    again = Motion.from_tracks({}, turn=(start, keys))
    t = np.linspace(0, 30, 61)
    np.testing.assert_allclose(again.root_orientation(t), (3 * arc(turn=90.0)).root_orientation(t), atol=1e-9)
    start, keys = (3 * arc(turn=90.0)).root_keyframes()
    assert keys[-1].position == pytest.approx((0.0, 0.0, -1.0))


def test_orientation_angles_out_of_range_are_refused():
    with pytest.raises(MotionError, match="root orientation"):
        Motion.from_tracks({}, turn=((0, 0, 0), [Keyframe(1.0, (0, float("inf"), 0), "LINEAR")]))


def test_pickled_motions_keep_their_orientation():
    a = 3 * arc()
    b = pickle.loads(pickle.dumps(a))
    same_root(a, b)


def test_orientation_matrix_puts_the_heading_outermost():
    angles = np.array([[10.0, 30.0, -20.0], [-50.0, 170.0, 80.0]])
    R = tu.orientation_matrix(angles)
    turned = tu.orientation_matrix(angles + [0.0, 25.0, 0.0])
    np.testing.assert_allclose(turned, tu.about_y(25.0) @ R, atol=1e-12)
    np.testing.assert_allclose(tu.orientation_angles(R), angles, atol=1e-9)
