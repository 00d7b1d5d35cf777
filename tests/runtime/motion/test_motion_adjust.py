"""The velocity adjustment of every method (issue 9): continuity and no overshoot."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liganimate.runtime.motion.algebra import Motion
from liganimate.runtime.motion.keyframe import Keyframe

METHODS = ["LINEAR", "ACCELERATE", "DECELERATE", "ACCDCC"]


def track(*keys, start=0.0):
    """Joint 1 driven about Z by keyframes (frame, angle, method)."""
    return Motion.from_tracks({1: ((0, 0, start), [Keyframe(f, (0, 0, v), m) for f, v, m in keys])})


def z(m, t):
    return m.evaluate(np.asarray(t, dtype=float), [1])[:, 0, 2]


def zv(m, t):
    return m.evaluate_full(np.asarray(t, dtype=float), [1])[1][:, 0, 2]


def test_accelerate_then_accelerate_passes_the_keyframe_without_stopping():
    m = track((4.0, 40.0, "ACCELERATE"), (8.0, 80.0, "ACCELERATE"))
    before, at = zv(m, [4.0 - 1e-9, 4.0])
    assert at == pytest.approx(20.0) and before == pytest.approx(20.0, abs=1e-6)
    assert (zv(m, np.linspace(4.0, 8.0 - 1e-9, 41)) > 0).all()


def test_accelerate_into_a_keyframe_and_decelerate_out_keeps_the_natural_curves():
    m = track((4.0, 40.0, "ACCELERATE"), (8.0, 80.0, "DECELERATE"))
    t = np.linspace(0.0, 8.0, 81)
    u = t / 4.0
    want = np.where(t <= 4.0, 40.0 * u * u, 40.0 + 40.0 * (1.0 - (2.0 - u) ** 2))
    np.testing.assert_allclose(z(m, t), want, atol=1e-12)
    assert zv(m, [4.0])[0] == pytest.approx(20.0)


def test_decelerate_then_decelerate_mirrors_accelerate_then_accelerate():
    m = track((4.0, 40.0, "DECELERATE"), (8.0, 80.0, "DECELERATE"))
    rev = track((4.0, 40.0, "ACCELERATE"), (8.0, 80.0, "ACCELERATE"))
    t = np.linspace(0.0, 8.0, 33)
    np.testing.assert_allclose(z(m, t), 80.0 - z(rev, 8.0 - t), atol=1e-12)
    assert zv(m, [4.0])[0] == pytest.approx(20.0)


def test_a_small_move_after_a_fast_one_stays_between_its_keyframes():
    m = track((2.0, 100.0, "ACCELERATE"), (8.0, 101.0, "LINEAR"))
    t = np.linspace(2.0, 8.0, 601)
    x = z(m, t)
    assert x.min() >= 100.0 and x.max() <= 101.0
    assert (np.diff(z(m, np.linspace(0.0, 2.0, 201))) >= 0).all()


def test_accdcc_rests_at_its_own_ends_and_its_neighbours_meet_it_at_rest():
    m = track((4.0, 40.0, "ACCELERATE"), (8.0, 80.0, "ACCDCC"), (12.0, 120.0, "DECELERATE"))
    v = zv(m, [4.0 - 1e-9, 4.0, 8.0 - 1e-9, 8.0])
    np.testing.assert_allclose(v, 0.0, atol=1e-6)


def test_linear_then_accelerate_does_not_stop():
    m = track((10.0, 30.0, "LINEAR"), (20.0, 60.0, "ACCELERATE"))
    assert zv(m, [10.0])[0] == pytest.approx(3.0)


def test_an_extreme_stops_every_method():
    for a in METHODS:
        for b in METHODS:
            m = track((4.0, 40.0, a), (8.0, 0.0, b))
            assert zv(m, [4.0])[0] == 0 and z(m, np.linspace(0, 8, 81)).max() <= 40.0, (a, b)


keys = st.lists(
    st.tuples(st.sampled_from([0.5, 1.0, 2.0, 3.0, 7.0]), st.floats(-200, 200), st.sampled_from(METHODS)),
    min_size=1,
    max_size=7,
)


@settings(max_examples=150, deadline=None)
@given(keys, st.floats(-200, 200))
def test_every_segment_stays_within_its_two_keyframes_and_velocity_is_continuous(spec, start):
    frames = np.cumsum([d for d, _, _ in spec])
    m = track(*[(f, v, meth) for f, (_, v, meth) in zip(frames, spec)], start=start)
    knots = np.concatenate([[0.0], frames])
    vals = np.concatenate([[start], [v for _, v, _ in spec]])
    for k in range(len(spec)):
        t = np.linspace(knots[k], knots[k + 1], 50)
        x = z(m, t)
        lo, hi = min(vals[k], vals[k + 1]), max(vals[k], vals[k + 1])
        tol = 1e-9 * (1.0 + abs(hi))
        assert x.min() >= lo - tol and x.max() <= hi + tol, k
    for k in range(1, len(spec)):
        a, b = spec[k - 1][2], spec[k][2]
        if "ACCDCC" in (a, b) or (a, b) == ("DECELERATE", "ACCELERATE"):
            continue
        left, right = zv(m, [knots[k] - 1e-7, knots[k]])
        # The left side is sampled 1e-7 frames early: allow what the acceleration moves in that time.
        tol = 1e-4 * (1 + abs(right)) + 1e-6 * np.ptp(vals) / 0.25
        assert left == pytest.approx(right, abs=tol), (k, a, b)
