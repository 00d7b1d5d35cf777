"""Unit tests of motions: leaf semantics, the velocity adjustment, each operation and each error."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.errors import MotionError
from liganimate.runtime.motion import track as tr
from liganimate.runtime.motion.algebra import (
    Motion,
    repeat,
    scale_extremes,
    scale_frames,
    strip,
    synchronize,
)
from liganimate.runtime.motion.keyframe import Keyframe


def one(method="LINEAR", start=(0, 0, 0), *keys):
    """A single-joint motion on joint 1."""
    return Motion.from_tracks({1: (start, list(keys))})


def x(m, t, joint=1, axis=0):
    return m.evaluate(np.atleast_1d(np.asarray(t, dtype=float)), [joint])[:, 0, axis]


def vel(m, t, joint=1, axis=0):
    return m.evaluate_full(np.atleast_1d(np.asarray(t, dtype=float)), [joint])[1][:, 0, axis]


def acc(m, t, joint=1, axis=0):
    return m.evaluate_full(np.atleast_1d(np.asarray(t, dtype=float)), [joint])[2][:, 0, axis]


@pytest.fixture
def walk():
    rng = np.random.default_rng(2024)
    spec = {}
    for j in (1, 2, 3, 4):
        frames = np.cumsum(rng.choice([2.0, 4.0, 6.0], size=4))
        values = rng.uniform(-60, 60, size=(4, 3))
        methods = ["ACCDCC", "LINEAR", "LINEAR", "DECELERATE"]
        spec[j] = (values[-1], [Keyframe(f, v, m) for f, v, m in zip(frames, values, methods)])
    return Motion.from_tracks(spec, name="walk")


# -- construction and its errors ------------------------------------------------------


def test_from_tracks_basic_properties():
    m = Motion.from_tracks(
        {
            7: ((0, 0, 0), [Keyframe(4.0, (10, 0, 0), "LINEAR")]),
            2: (None, [Keyframe(1.5, (0, 5, 0), "accelerate"), Keyframe(9.0, (0, 0, 0), "ACCDCC")]),
            3: ((1, 2, 3), []),
        }
    )
    assert m.joints == (2, 3, 7)
    assert m.length == 9.0
    assert m.evaluate([0.0, 5.0]).shape == (2, 3, 3)
    assert np.array_equal(m.evaluate([100.0], [3])[0, 0], [1, 2, 3])
    assert m.evaluate(3.0).shape == (1, 3, 3)


def test_empty_motion():
    e = Motion.empty()
    assert e.length == 0 and e.joints == ()
    assert e.evaluate([0.0, 1.0]).shape == (2, 0, 3)
    assert (e + e).length == 0 and (5 * e).joints == ()


@pytest.mark.parametrize(
    "keys, words",
    [
        ([Keyframe(5.0, (0, 0, 0), "LINEAR"), Keyframe(4.0, (1, 1, 1), "LINEAR")], ["joint 3", "keyframe 2", "before"]),
        ([Keyframe(-1.0, (0, 0, 0), "LINEAR")], ["joint 3", "keyframe 1", "negative"]),
        ([Keyframe(1.0, (0, 0, 0), "LINEAR"), Keyframe(2.0, (0, 0, 0), "BOUNCE")], ["joint 3", "keyframe 2", "BOUNCE"]),
        ([Keyframe(1.0, (0, 0), "LINEAR")], ["joint 3", "keyframe 1", "position"]),
        ([Keyframe(float("nan"), (0, 0, 0), "LINEAR")], ["joint 3", "keyframe 1", "finite"]),
        ([Keyframe(1.0, (0, 0, 0), "LINEAR", 0.0)], ["joint 3", "keyframe 1", "ramp"]),
        ([(1.0, (0, 0, 0), "LINEAR")], ["joint 3", "keyframe 1", "expected a Keyframe"]),
    ],
)
def test_from_tracks_errors_name_joint_and_keyframe(keys, words):
    with pytest.raises(MotionError) as err:
        Motion.from_tracks({3: ((0, 0, 0), keys)})
    for w in words:
        assert w in err.value.message


def test_from_tracks_rejects_bad_joint_ids_and_starts():
    with pytest.raises(MotionError, match="joint id"):
        Motion.from_tracks({"hip": ((0, 0, 0), [])})
    with pytest.raises(MotionError, match="joint id"):
        Motion.from_tracks({True: ((0, 0, 0), [])})
    with pytest.raises(MotionError, match="joint 1: start"):
        Motion.from_tracks({1: ((0, np.inf, 0), [])})
    with pytest.raises(MotionError, match="joint 1"):
        Motion.from_tracks({1: "nonsense"})


def test_motions_are_immutable(walk):
    track = walk.track(1)
    with pytest.raises(ValueError):
        track.values[0, 0] = 1.0
    before = walk.evaluate(np.arange(20.0))
    _ = (walk + walk, 3 * walk, walk.scale_frames(-2), walk.scale_extremes(3), walk.strip([1]))
    assert np.array_equal(walk.evaluate(np.arange(20.0)), before)


# -- leaf semantics ---------------------------------------------------------------------


def test_before_first_keyframe_interpolates_from_the_start_and_holds_after_the_last():
    m = one("", (10, 0, 0), Keyframe(4.0, (20, 0, 0), "ACCELERATE"))
    assert x(m, -5)[0] == 10 and x(m, 0)[0] == 10
    assert x(m, 2)[0] == pytest.approx(10 + 10 * 0.25)
    assert x(m, 4)[0] == 20 and x(m, 50)[0] == 20
    assert vel(m, 50)[0] == 0 and acc(m, 50)[0] == 0


def test_equal_frames_make_a_right_continuous_step():
    m = one(
        "",
        (0, 0, 0),
        Keyframe(2.0, (10, 0, 0), "ACCDCC"),
        Keyframe(2.0, (50, 0, 0), "LINEAR"),
        Keyframe(6.0, (50, 0, 0), "LINEAR"),
    )
    assert x(m, 2.0 - 1e-12)[0] == pytest.approx(10)
    assert x(m, 2.0)[0] == 50
    assert vel(m, 2.0)[0] == 0


def test_no_wrapping_two_turns_are_two_turns():
    m = one("", (0, 0, 0), Keyframe(8.0, (720, 0, 0), "ACCDCC"))
    assert x(m, 4.0)[0] == 360.0
    assert x(m, 8.0)[0] == 720.0


def test_each_axis_is_interpolated_independently():
    m = one("", (0, 0, 0), Keyframe(4.0, (8, -4, 0), "ACCELERATE"))
    np.testing.assert_allclose(m.evaluate([2.0])[0, 0], [2, -1, 0])


# -- the velocity adjustment ------------------------------------------------------------


def test_linear_trapezoid_numbers():
    # 70 degrees in 10 frames, ramps of 3 frames at rest ends: cruise c = 70 / (10 - 3) = 10.
    m = one("", (0, 0, 0), Keyframe(10.0, (70, 0, 0), "LINEAR"))
    assert x(m, 3.0)[0] == pytest.approx(15.0)
    assert x(m, 5.0)[0] == pytest.approx(35.0)
    assert x(m, 1.5)[0] == pytest.approx(10 * 1.5**2 / 6)
    assert vel(m, 5.0)[0] == pytest.approx(10.0)
    assert acc(m, 1.0)[0] == pytest.approx(10 / 3)
    assert acc(m, 9.0)[0] == pytest.approx(-10 / 3)
    assert vel(m, 0.0)[0] == 0 and x(m, 10.0)[0] == 70


def test_short_linear_segment_ramps_over_half_its_length():
    m = one("", (0, 0, 0), Keyframe(4.0, (20, 0, 0), "LINEAR"))  # r = min(3, 2) = 2, c = 20 / (4 - 2)
    assert vel(m, 2.0)[0] == pytest.approx(10.0)
    assert x(m, 2.0)[0] == pytest.approx(10.0)


def test_linear_junction_velocity_is_the_harmonic_mean_of_slopes():
    m = one("", (0, 0, 0), Keyframe(10.0, (30, 0, 0), "LINEAR"), Keyframe(20.0, (40, 0, 0), "LINEAR"))
    assert vel(m, 10.0)[0] == pytest.approx(2 * 3 * 1 / (3 + 1))
    assert vel(m, 10.0 - 1e-9)[0] == pytest.approx(1.5, abs=1e-6)
    # Opposite slopes: the joint stops at the extreme.
    n = one("", (0, 0, 0), Keyframe(10.0, (30, 0, 0), "LINEAR"), Keyframe(20.0, (0, 0, 0), "LINEAR"))
    assert vel(n, 10.0)[0] == 0 and vel(n, 10.0 - 1e-9)[0] == pytest.approx(0, abs=1e-6)


def test_linear_meets_a_fixed_shape_neighbour_at_its_natural_velocity():
    # DECELERATE leaves its start at 2 D / T = 2 * 20 / 4 = 10 deg/frame.
    m = one("", (0, 0, 0), Keyframe(10.0, (30, 0, 0), "LINEAR"), Keyframe(14.0, (50, 0, 0), "DECELERATE"))
    assert vel(m, 10.0 - 1e-9)[0] == pytest.approx(10.0, abs=1e-6)
    assert vel(m, 10.0)[0] == pytest.approx(10.0)
    # ACCELERATE arrives at its end at 2 D / T = 2 * 30 / 10 = 6; the LINEAR after it starts there.
    n = one("", (0, 0, 0), Keyframe(10.0, (30, 0, 0), "ACCELERATE"), Keyframe(20.0, (50, 0, 0), "LINEAR"))
    assert vel(n, 10.0 - 1e-9)[0] == pytest.approx(6.0, abs=1e-6)
    assert vel(n, 10.0)[0] == pytest.approx(6.0)


def test_linear_stops_at_steps_and_at_junctions_where_the_poses_differ():
    a = one("", (0, 0, 0), Keyframe(10.0, (30, 0, 0), "LINEAR"))
    b = one("", (40, 0, 0), Keyframe(10.0, (60, 0, 0), "LINEAR"))
    assert vel(a + b, 10.0)[0] == 0  # the adjustment never crosses a junction with a jump
    assert vel(a + b, 10.0 - 1e-9)[0] == pytest.approx(0, abs=1e-6)
    assert vel(2 * a, 10.0)[0] == 0  # a does not end where it starts
    stepped = one(
        "",
        (0, 0, 0),
        Keyframe(10.0, (30, 0, 0), "LINEAR"),
        Keyframe(10.0, (30, 0, 0), "LINEAR"),
        Keyframe(20.0, (60, 0, 0), "LINEAR"),
    )
    assert vel(stepped, 10.0)[0] == 0


def test_a_junction_where_the_poses_meet_passes_through_like_one_keyframe_list():
    a = one("", (0, 0, 0), Keyframe(8.0, (80, 0, 0), "LINEAR"))
    b = one("", (80, 0, 0), Keyframe(8.0, (160, 0, 0), "LINEAR"))
    joined = one("", (0, 0, 0), Keyframe(8.0, (80, 0, 0), "LINEAR"), Keyframe(16.0, (160, 0, 0), "LINEAR"))
    t = np.linspace(-1.0, 17.0, 73)
    np.testing.assert_allclose((a + b).evaluate(t), joined.evaluate(t), atol=1e-12)
    assert vel(a + b, 8.0)[0] == pytest.approx(10.0)
    assert vel(a + b, 8.0 - 1e-9)[0] == pytest.approx(10.0, abs=1e-6)


def test_a_cycle_repeated_keeps_its_velocity_across_every_junction():
    cycle = one(
        "",
        (0, 0, 0),
        Keyframe(4.0, (20, 0, 0), "LINEAR"),
        Keyframe(8.0, (-20, 0, 0), "LINEAR"),
        Keyframe(12.0, (0, 0, 0), "LINEAR"),
    )
    m = 10 * cycle
    for k in range(1, 10):
        assert vel(m, 12.0 * k)[0] == pytest.approx(5.0)
        assert vel(m, 12.0 * k - 1e-9)[0] == pytest.approx(5.0, abs=1e-6)
    ref = cycle
    for _ in range(9):
        ref = ref + cycle
    t = np.linspace(-1.0, 121.0, 977)
    np.testing.assert_allclose(m.evaluate(t), ref.evaluate(t), atol=1e-9)
    assert vel(m, 0.0)[0] == 0  # the first copy still starts, and the last ends, at rest


def test_ramps_stretch_with_scale_frames():
    m = one("", (0, 0, 0), Keyframe(10.0, (70, 0, 0), "LINEAR"))
    s = m.scale_frames(2.5)
    _, keys = s.keyframes(1)
    assert keys[0].ramp == 7.5
    t = np.linspace(0, 10, 23)
    np.testing.assert_allclose(s.evaluate(2.5 * t), m.evaluate(t), atol=1e-12)


# -- a + b -----------------------------------------------------------------------------


def test_concat_for_joints_driven_by_one_operand():
    a = Motion.from_tracks({1: ((0, 0, 0), [Keyframe(4.0, (40, 0, 0), "LINEAR")])})
    b = Motion.from_tracks({2: ((5, 0, 0), [Keyframe(6.0, (65, 0, 0), "ACCDCC")])})
    m = a + b
    assert m.length == 10.0
    assert x(m, [0, 2, 4, 7, 10, 20], joint=1).tolist() == [0, 20, 40, 40, 40, 40]  # a's end held during b
    assert x(m, [0, 2, 4], joint=2).tolist() == [5, 5, 5]  # b's start held during a
    assert x(m, 10, joint=2)[0] == 65
    assert strip(m, [1]).length == 10.0  # the hold counts as part of joint 1's track
    assert strip(m, [2]).length == 10.0


def test_concat_junction_is_right_continuous():
    a = one("", (0, 0, 0), Keyframe(4.0, (40, 0, 0), "LINEAR"))
    b = one("", (100, 0, 0), Keyframe(4.0, (0, 0, 0), "LINEAR"))
    m = a + b
    assert x(m, 4.0)[0] == 100
    assert x(m, 4.0 - 1e-9)[0] == pytest.approx(40)
    assert x(m, 8.0)[0] == 0


def test_concat_pads_short_tracks_of_a():
    a = Motion.from_tracks(
        {1: ((0, 0, 0), [Keyframe(2.0, (10, 0, 0), "LINEAR")]), 2: ((0, 0, 0), [Keyframe(6.0, (0, 0, 6), "LINEAR")])}
    )
    b = Motion.from_tracks({1: ((50, 0, 0), [Keyframe(1.0, (60, 0, 0), "LINEAR")])})
    m = a + b
    assert x(m, [2, 4, 5.99]).tolist() == [10, 10, 10]  # joint 1 holds until len(a) = 6
    assert x(m, 6)[0] == 50 and x(m, 7)[0] == 60 and m.length == 7


# -- n * a -------------------------------------------------------------------------------


def test_repeat_zero_holds_start_values():
    a = one("", (3, 2, 1), Keyframe(4.0, (40, 0, 0), "LINEAR"))
    z = 0 * a
    assert z.length == 0 and z.joints == (1,)
    np.testing.assert_array_equal(z.evaluate([0.0, 2.0, 9.0])[:, 0], [[3, 2, 1]] * 3)


def test_repeat_final_frame_and_junctions():
    a = one("", (0, 0, 0), Keyframe(4.0, (40, 0, 0), "ACCELERATE"))
    m = 3 * a
    assert m.length == 12
    assert x(m, [4.0, 8.0, 12.0, 13.0]).tolist() == [0, 0, 40, 40]
    assert x(m, 6.0)[0] == pytest.approx(10)


@pytest.mark.parametrize("n", [-1, 2.0, 1.5, "3", True, None])
def test_repeat_count_must_be_a_non_negative_int(n, walk):
    with pytest.raises(MotionError):
        repeat(n, walk)
    with pytest.raises(MotionError):
        n * walk


def test_repeat_accepts_numpy_integers(walk):
    assert (np.int64(2) * walk).length == 2 * walk.length


def test_huge_repeat_is_lazy(walk, monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("evaluation must not materialize keyframes")

    monkeypatch.setattr(tr, "materialize", refuse)
    monkeypatch.setattr(tr._Emitter, "add", refuse)
    big = 10**9 * walk
    ticks = np.arange(100.0)
    got = big.evaluate(ticks)
    assert big.length == 10**9 * walk.length
    assert big.footprint().keyframes == walk.footprint().keyframes == 16
    assert big.footprint().nodes == walk.footprint().nodes + len(walk.joints)
    np.testing.assert_allclose(got, walk.evaluate(np.mod(ticks, walk.length)), atol=1e-9)
    back = big.scale_frames(-1)
    assert back.footprint().keyframes <= 2 * 16
    np.testing.assert_allclose(back.evaluate(ticks), big.evaluate(big.length - ticks), atol=1e-9)
    nested = 10**9 * (10**9 * walk)
    assert nested.footprint().keyframes == 16
    np.testing.assert_allclose(nested.evaluate(ticks), got, atol=1e-9)
    # Frames near 4.8e19 are 4096 apart as floats, so the reversal is compared with the
    # reversed walk (its start and end poses agree, which makes junction frames match too).
    np.testing.assert_allclose(
        nested.scale_frames(-1).evaluate(ticks),
        walk.scale_frames(-1).evaluate(np.mod(ticks, walk.length)),
        atol=1e-9,
    )


def test_huge_listing_is_refused_before_it_is_built(walk):
    big = 10**9 * walk
    with pytest.raises(MotionError, match="limit"):
        big.keyframes(1)
    with pytest.raises(MotionError, match="limit"):
        (3 * walk).keyframes(1, limit=5)
    assert "1000000000 * walk" in big.describe()


def test_doubling_sixty_times_stays_small():
    m = one("", (0, 0, 0), Keyframe(1.0, (1, 0, 0), "LINEAR"))
    for _ in range(60):
        m = m + m
    assert m.length == 2.0**60
    assert m.footprint().nodes <= 200
    t = np.array([0.0, 0.5, 2.0**40 + 0.5, 2.0**60])  # 2**59 + 0.5 would not be a float
    np.testing.assert_allclose(x(m, t), [0, 0.5, 0.5, 1.0])
    assert m.scale_frames(-1).length == m.length
    assert len(m.describe(max_chars=300)) <= 303 and m.describe(max_chars=300).endswith("...")


def test_long_chains_of_concatenation_do_not_recurse_deeply():
    step = one("", (0, 0, 0), Keyframe(1.0, (1, 0, 0), "LINEAR"))
    m = Motion.empty()
    for _ in range(3000):
        m = m + step
    assert m.length == 3000
    assert x(m, [0.5, 2999.5, 3000.0]).tolist() == pytest.approx([0.5, 0.5, 1.0])
    back = m.scale_frames(-1)
    assert x(back, 0.5)[0] == pytest.approx(0.5)


# -- STRIP and SYNCHRONIZE --------------------------------------------------------------


def test_strip_keeps_joints_and_recomputes_length(walk):
    s = strip(walk, [2, 4])
    assert s.joints == (2, 4)
    assert s.length == max(walk.track(2).end, walk.track(4).end)
    with pytest.raises(MotionError) as err:
        strip(walk, [2, 9])
    assert "joint 9" in err.value.message


def test_synchronize_merges_and_reports_overlaps(walk):
    m = synchronize(strip(walk, [1, 2]), strip(walk, [3]), strip(walk, [4]))
    assert m.joints == walk.joints and m.length == walk.length
    with pytest.raises(MotionError) as err:
        synchronize(strip(walk, [1]), strip(walk, [2]), strip(walk, [2, 3]))
    assert "joint 2" in err.value.message
    assert "operand 2" in err.value.message and "operand 3" in err.value.message
    assert synchronize().joints == ()


# -- SCALE FRAMES / EXTREMES ------------------------------------------------------------


def test_scale_frames_rejects_zero_and_non_numbers(walk):
    for r in (0, 0.0, float("nan"), float("inf"), "x"):
        with pytest.raises(MotionError):
            scale_frames(walk, r)
    for r in (float("nan"), "x"):
        with pytest.raises(MotionError):
            scale_extremes(walk, r)


def test_reversal_swaps_accelerate_and_decelerate():
    m = one(
        "",
        (0, 0, 0),
        Keyframe(4.0, (40, 0, 0), "ACCELERATE"),
        Keyframe(8.0, (0, 0, 0), "ACCDCC"),
        Keyframe(12.0, (10, 0, 0), "DECELERATE"),
    )
    start, keys = m.scale_frames(-1).keyframes(1)
    assert start == (10.0, 0.0, 0.0)
    assert [k.method for k in keys] == ["ACCELERATE", "ACCDCC", "DECELERATE"]
    assert [k.frame for k in keys] == [4.0, 8.0, 12.0]
    assert [k.position[0] for k in keys] == [0.0, 40.0, 0.0]


def test_reversal_moves_holds_to_the_start():
    m = Motion.from_tracks(
        {1: ((0, 0, 0), [Keyframe(2.0, (20, 0, 0), "LINEAR")]), 2: ((0, 0, 0), [Keyframe(10.0, (0, 0, 0), "LINEAR")])}
    )
    r = m.scale_frames(-1)
    assert x(r, [0, 4, 8]).tolist() == [20, 20, 20]  # joint 1 finished early: it now waits at the start
    assert x(r, 10)[0] == 0
    assert strip(r, [1]).length == 10


def test_reversal_flips_the_side_of_steps_and_junctions():
    m = one(
        "",
        (0, 0, 0),
        Keyframe(2.0, (10, 0, 0), "LINEAR"),
        Keyframe(2.0, (50, 0, 0), "LINEAR"),
        Keyframe(4.0, (60, 0, 0), "LINEAR"),
    )
    r = m.scale_frames(-1)
    assert x(m, 2.0)[0] == 50 and x(r, 2.0)[0] == 50  # pose(r, t) = pose(m, 4 - t) even on the step
    a = one("", (0, 0, 0), Keyframe(2.0, (10, 0, 0), "LINEAR"))
    b = one("", (90, 0, 0), Keyframe(2.0, (80, 0, 0), "LINEAR"))
    j = (a + b).scale_frames(-1)
    assert x(a + b, 2.0)[0] == 90 and x(j, 2.0)[0] == 90


def test_scale_extremes_multiplies_start_and_keyframes(walk):
    s = walk.scale_extremes(-0.5)
    t = np.linspace(-1, walk.length + 1, 57)
    np.testing.assert_allclose(s.evaluate(t), -0.5 * walk.evaluate(t))
    start, keys = s.keyframes(1)
    start0, keys0 = walk.keyframes(1)
    assert start == tuple(-0.5 * np.array(start0))


# -- evaluation and inspection ----------------------------------------------------------


def test_evaluate_orders_joints_and_checks_them(walk):
    t = np.array([1.0, 2.0])
    full = walk.evaluate(t)
    np.testing.assert_array_equal(walk.evaluate(t, [4, 1]), full[:, [3, 0]])
    with pytest.raises(MotionError, match="joint 8"):
        walk.evaluate(t, [8])
    with pytest.raises(MotionError, match="NaN"):
        walk.evaluate([np.nan])
    a, v, c = walk.evaluate_full(t)
    assert a.shape == v.shape == c.shape == (2, 4, 3)


def test_keyframe_listing_of_a_composite(walk):
    a = one("", (0, 0, 0), Keyframe(2.0, (10, 0, 0), "ACCELERATE"))
    start, keys = (a + a).keyframes(1)
    assert start == (0.0, 0.0, 0.0)
    assert keys == [
        Keyframe(2.0, (10.0, 0.0, 0.0), "ACCELERATE"),
        Keyframe(2.0, (0.0, 0.0, 0.0), "LINEAR"),  # the junction: a step back to a's start
        Keyframe(4.0, (10.0, 0.0, 0.0), "ACCELERATE"),
    ]
    with pytest.raises(MotionError, match="joint 5"):
        walk.keyframes(5)


def test_describe_renders_the_expression(walk):
    legs = strip(walk, [1, 2])
    m = 3 * (walk + legs.scale_frames(-2)) + synchronize(strip(walk, [3]), strip(walk, [4])).scale_extremes(0.5)
    assert m.describe() == (
        "3 * (walk + STRIP(walk, 1, 2) <SCALE FRAMES -2>) + "
        "SYNCHRONIZE(STRIP(walk, 3), STRIP(walk, 4)) <SCALE EXTREMES 0.5>"
    )
    assert "keyframes[1 joints, 1 keyframes]" in one("", (0, 0, 0), Keyframe(1.0, (0, 0, 0), "LINEAR")).describe()
    assert "walk" in repr(walk)


# -- unwrapping ---------------------------------------------------------------------------


def clock():
    """The thesis' clock: anglez = 6 * minute MOD 360 for the minute hand (joint 1)."""
    spec = {}
    for hand in (1, 2):
        keys = []
        for minute in range(121):
            angle = 6.0 * minute if hand == 1 else 30.0 * minute / 60.0
            keys.append(Keyframe(24.0 * minute, (0.0, 0.0, angle % 360.0), "LINEAR"))
        spec[hand] = (keys[0].position, keys[1:])
    return Motion.from_tracks(spec)


def test_unwrapping_lets_the_clock_run_forwards():
    m = clock()
    u = m.unwrapped({1: (False, False, True), 2: (False, False, True), 99: (True, True, True)})
    t = np.arange(0.0, u.length + 1, 3.0)
    z = u.evaluate(t, [1])[:, 0, 2]
    assert np.all(np.diff(z) >= 0)
    assert z[-1] == pytest.approx(720.0)
    raw = m.evaluate(t, [1])[:, 0, 2]
    assert np.any(np.diff(raw) < -10)  # without unwrapping the hand sweeps back at every hour
    assert u.evaluate([24.0 * 120], [2])[0, 0, 2] == pytest.approx(60.0)


def test_unwrapping_keeps_a_half_turn_direction_and_fixed_axes():
    m = one("", (0, 0, 0), Keyframe(1.0, (180, 350, -180), "LINEAR"), Keyframe(2.0, (-170, 10, 200), "LINEAR"))
    u = m.unwrapped({1: (True, False, True)})
    _, keys = u.keyframes(1)
    assert [k.position for k in keys] == [(180.0, 350.0, -180.0), (190.0, 10.0, -160.0)]


def test_motions_pickle_by_method_name(walk):
    import pickle

    m = 3 * walk + walk.scale_frames(-2).scale_extremes(0.5)
    back = pickle.loads(pickle.dumps(m))
    t = np.linspace(-1, m.length + 1, 101)
    np.testing.assert_array_equal(back.evaluate(t), m.evaluate(t))
    assert back.describe() == m.describe()
