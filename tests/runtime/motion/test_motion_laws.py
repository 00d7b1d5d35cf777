"""Property tests: the motion algebra's laws on random motions.

Frames, angles and factors are dyadic rationals, so junction and keyframe
times such as ``len(a) + len(b)`` or ``L - t`` are exact floats and the
tests can probe exactly-on-keyframe and exactly-on-junction times.
"""

from __future__ import annotations

import os

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

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

METHODS = ["LINEAR", "ACCELERATE", "DECELERATE", "ACCDCC"]
JOINTS = [1, 2, 3]
FRAME_STEPS = [0.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 12.5]
FRAME_FACTORS = [0.5, 2.0, 1.5, 0.25, -1.0, -2.0, -0.5, -1.5]
EXTREME_FACTORS = [2.0, 0.5, -1.0, -0.75, 0.0, 3.0]
ATOL = 1e-9

# LIGANIMATE_LAW_EXAMPLES=5000 LIGANIMATE_LAW_RANDOM=1 turns this into a long random search.
EXAMPLES = int(os.environ.get("LIGANIMATE_LAW_EXAMPLES", "100"))
PROFILE = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=not os.environ.get("LIGANIMATE_LAW_RANDOM"),
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
FEW = settings(PROFILE, max_examples=max(1, EXAMPLES * 2 // 5))

SEEDS = st.integers(0, 2**32 - 1)


@st.composite
def leaf_tracks(draw, joints=None):
    """A ``from_tracks`` spec over some joints.

    The numbers come from a numpy generator seeded by hypothesis: drawing
    them one by one through hypothesis made the suite several times slower.
    """
    rng = np.random.default_rng(draw(SEEDS))
    if joints is None:
        joints = sorted(rng.choice(JOINTS, size=rng.integers(1, 4), replace=False).tolist())
    spec = {}
    for j in joints:
        n = int(rng.integers(0, 6))
        frames = np.cumsum(rng.choice(FRAME_STEPS, size=n))
        values = rng.integers(-720, 721, size=(n, 3)) / 2.0
        methods = rng.choice(METHODS, size=n)
        start = tuple(float(x) for x in rng.integers(-720, 721, size=3) / 2.0)
        keys = [Keyframe(float(f), tuple(float(x) for x in v), str(m)) for f, v, m in zip(frames, values, methods)]
        spec[j] = (start, keys)
    return spec


@st.composite
def _leaf_motions(draw):
    return Motion.from_tracks(draw(leaf_tracks()))


OPS = st.sampled_from(["+", "*", "strip", "sync", "frames", "extremes"])
COUNTS = st.integers(0, 3)
FRAME_FACTOR = st.sampled_from(FRAME_FACTORS)
EXTREME_FACTOR = st.sampled_from(EXTREME_FACTORS)
MASKS = st.integers(1, 2 ** len(JOINTS) - 1)


def subset(draw, joints) -> list[int]:
    """A non-empty subset, drawn as one integer (cheaper than st.lists)."""
    mask = draw(MASKS) % (2 ** len(joints))
    chosen = [j for i, j in enumerate(joints) if mask >> i & 1]
    return chosen or [joints[0]]


@st.composite
def _motions(draw, depth):
    """Random expression trees over every operation of the algebra."""
    if depth == 0 or draw(COUNTS) == 0:
        return draw(LEAF_MOTIONS)
    op = draw(OPS)
    a = draw(motions(depth - 1))
    if op == "+":
        return a + draw(motions(depth - 1))
    if op == "*":
        return draw(COUNTS) * a
    if op == "frames":
        return a.scale_frames(draw(FRAME_FACTOR))
    if op == "extremes":
        return a.scale_extremes(draw(EXTREME_FACTOR))
    if not a.joints:
        return a
    kept = subset(draw, a.joints)
    others = [j for j in JOINTS if j not in kept]
    if op == "strip" or not others:
        return strip(a, kept)
    b = draw(motions(depth - 1))
    shared = [j for j in b.joints if j in others]
    b = strip(b, shared) if shared else Motion.from_tracks(draw(leaf_tracks(joints=subset(draw, others))))
    return synchronize(strip(a, kept), b)


LEAF_MOTIONS = _leaf_motions()
_BY_DEPTH = {}


def motions(depth=3):
    # Strategies are built once per depth: hypothesis validates every new strategy object.
    if depth not in _BY_DEPTH:
        _BY_DEPTH[depth] = _motions(depth)
    return _BY_DEPTH[depth]


def leaf_motions():
    return LEAF_MOTIONS


def knots(m: Motion) -> np.ndarray:
    """Every keyframe and junction frame of every joint (exact floats)."""
    frames = [0.0, m.length]
    for j in m.joints:
        _, keys = m.keyframes(j, limit=5000)
        frames += [k.frame for k in keys]
    return np.unique(frames)


def probe_times(m: Motion, extra=()) -> np.ndarray:
    """Knots, points just beside them, generic points, and times outside [0, L]."""
    k = np.concatenate([knots(m), np.asarray(extra, dtype=float)])
    L = m.length
    rng = np.random.default_rng(1234)
    generic = rng.uniform(-2.0, L + 2.0, 40)
    mids = (k[:-1] + k[1:]) / 2 if len(k) > 1 else k
    return np.unique(np.concatenate([k, k + 0.25, k - 0.25, mids, generic, [-1.0, L + 1.0, L + 1e6]]))


def assert_close(x, y, atol=ATOL):
    np.testing.assert_allclose(x, y, rtol=1e-12, atol=atol)


# -- a + b ------------------------------------------------------------------


@PROFILE
@given(motions(2), motions(2))
def test_concat_plays_b_after_a(a, b):
    m = a + b
    La, Lb = a.length, b.length
    assert m.length == La + Lb
    assert m.joints == tuple(sorted(set(a.joints) | set(b.joints)))
    t = probe_times(m, [La])
    got = m.evaluate(t)
    during_a = (t < La)[:, None]  # the junction is right-continuous: t == La already shows b
    for i, j in enumerate(m.joints):
        xa = a.evaluate(t, [j])[:, 0] if j in a.joints else b.evaluate([-1.0], [j])[:, 0]  # b's start
        a_end = a.evaluate([La + 1e9], [j])[:, 0] if j in a.joints else None
        xb = b.evaluate(t - La, [j])[:, 0] if j in b.joints else a_end
        if j in a.joints and j in b.joints and np.array_equal(a_end, b.evaluate([-1.0], [j])[:, 0]):
            continue  # the poses meet: the velocity is shared across the junction (tested elsewhere)
        if j in a.joints and j in b.joints and b.gap(j) > 0:
            # Where b does not drive j yet, j shows the previous driven value: a's end.
            xb = np.where((t - La < b.gap(j))[:, None], a_end, xb)
        assert_close(got[:, i], np.where(during_a, xa, xb))


@PROFILE
@given(motions(2), motions(2))
def test_track_ends_count_the_hold(a, b):
    m = a + b
    for j in m.joints:
        if j in a.joints and j not in b.joints:
            assert strip(m, [j]).length == a.length + b.length


# -- n * a ------------------------------------------------------------------


@PROFILE
@given(motions(2), st.integers(0, 4))
def test_repeat_equals_repeated_concat(a, n):
    m = n * a
    assert repeat(n, a).length == m.length
    if n == 0:
        assert m.length == 0
        t = probe_times(a)
        assert_close(m.evaluate(t), np.broadcast_to(a.evaluate([-1.0]), (len(t), len(a.joints), 3)))
        return
    ref = a
    for _ in range(n - 1):
        ref = ref + a
    assert m.length == ref.length == n * a.length
    t = probe_times(ref, [k * a.length for k in range(n + 1)])
    assert_close(m.evaluate(t), ref.evaluate(t))
    for x, y in zip(m.evaluate_full(t), ref.evaluate_full(t)):
        assert_close(x, y, atol=1e-7)
    # The final frame shows a's last value.
    assert_close(m.evaluate([n * a.length]), a.evaluate([a.length]))


@FEW
@given(motions(1), st.integers(1, 3), st.integers(1, 3))
def test_repeats_multiply(a, n, k):
    lhs, rhs = n * (k * a), (n * k) * a
    assert lhs.length == rhs.length
    t = probe_times(rhs)
    assert_close(lhs.evaluate(t), rhs.evaluate(t))


# -- STRIP and SYNCHRONIZE ---------------------------------------------------


@PROFILE
@given(motions(2), st.data())
def test_strip_keeps_listed_tracks(a, data):
    if not a.joints:
        return
    kept = data.draw(st.lists(st.sampled_from(a.joints), min_size=1, unique=True))
    s = strip(a, kept)
    assert s.joints == tuple(sorted(kept))
    assert s.length == max(strip(a, [j]).length for j in kept) <= a.length
    t = probe_times(a)
    assert_close(s.evaluate(t, kept), a.evaluate(t, kept))
    assert strip(a, a.joints).length == a.length


@PROFILE
@given(motions(2), st.data())
def test_synchronize_of_a_split_is_identity(m, data):
    if not m.joints:
        return
    A = data.draw(st.lists(st.sampled_from(m.joints), unique=True))
    B = [j for j in m.joints if j not in A]
    s = synchronize(strip(m, A), strip(m, B))
    assert s.joints == m.joints and s.length == m.length
    t = probe_times(m)
    assert_close(s.evaluate_full(t)[0], m.evaluate_full(t)[0])
    assert_close(s.evaluate_full(t)[1], m.evaluate_full(t)[1])


# -- SCALE FRAMES, reversal ---------------------------------------------------


@PROFILE
@given(motions())
def test_reversal_mirrors_every_frame(a):
    L = a.length
    b = a.scale_frames(-1)
    assert b.length == L
    t = probe_times(a)
    t = np.unique(np.concatenate([t, L - t]))
    x, v, _ = b.evaluate_full(t)
    x0, v0, _ = a.evaluate_full(L - t)
    assert_close(x, x0)
    # Continuity sides flip together with time, so one-sided velocities mirror too.
    assert_close(v, -v0, atol=1e-7)


@PROFILE
@given(motions())
def test_reversal_mirrors_acceleration_at_generic_times(a):
    L = a.length
    t = np.random.default_rng(7).uniform(-1.0, L + 1.0, 50)
    _, _, acc = a.scale_frames(-1).evaluate_full(t)
    _, _, acc0 = a.evaluate_full(L - t)
    assert_close(acc, acc0, atol=1e-6)


@PROFILE
@given(motions())
def test_double_reversal_is_identity(a):
    b = a.scale_frames(-1).scale_frames(-1)
    assert b.length == a.length and b.joints == a.joints
    t = probe_times(a)
    assert_close(b.evaluate(t), a.evaluate(t))
    assert_close(b.evaluate_full(t)[1], a.evaluate_full(t)[1], atol=1e-7)


@PROFILE
@given(motions(), st.sampled_from(FRAME_FACTORS))
def test_scale_frames_stretches_time(a, r):
    b = scale_frames(a, r)
    L = a.length
    assert b.length == abs(r) * L
    t = probe_times(a)
    source = t if r > 0 else L - t
    x, v, acc = b.evaluate_full(abs(r) * t)
    x0, v0, acc0 = a.evaluate_full(source)
    assert_close(x, x0)
    assert_close(v * r, v0, atol=1e-7)
    g = np.random.default_rng(3).uniform(-1, L + 1, 30)
    assert_close(b.evaluate_full(abs(r) * g)[2] * r * r, a.evaluate_full(g if r > 0 else L - g)[2], atol=1e-6)


@PROFILE
@given(motions(), st.sampled_from(EXTREME_FACTORS))
def test_scale_extremes_scales_angles(a, r):
    b = scale_extremes(a, r)
    assert b.length == a.length
    t = probe_times(a)
    for got, want in zip(b.evaluate_full(t), a.evaluate_full(t)):
        assert_close(got, r * want, atol=1e-7)


@PROFILE
@given(motions(2), st.sampled_from(FRAME_FACTORS), st.sampled_from(EXTREME_FACTORS), st.sampled_from(FRAME_FACTORS))
def test_scale_transforms_commute_and_multiply(a, f, e, g):
    lhs = a.scale_frames(f).scale_extremes(e)
    rhs = a.scale_extremes(e).scale_frames(f)
    t = probe_times(lhs)
    assert lhs.length == rhs.length
    assert_close(lhs.evaluate(t), rhs.evaluate(t))
    twice, once = a.scale_frames(f).scale_frames(g), a.scale_frames(f * g)
    assert twice.length == once.length
    assert_close(twice.evaluate(t), once.evaluate(t))


# -- leaves ---------------------------------------------------------------------


@PROFILE
@given(leaf_tracks(), st.sampled_from([1.0, 0.5, 2.0, 1.5]))
def test_keyframes_are_hit_exactly(spec, r):
    m = Motion.from_tracks(spec).scale_frames(r)
    for j, (start, keys) in spec.items():
        assert np.array_equal(m.evaluate([-0.5], [j])[0, 0], start)
        for k, key in enumerate(keys):
            f, v = key.frame, key.position
            if k + 1 < len(keys) and keys[k + 1].frame == f:
                continue  # inside a step the last keyframe at that frame wins
            assert np.array_equal(m.evaluate([f * r], [j])[0, 0], v), (j, k)


@PROFILE
@given(motions())
def test_holds_after_the_end(a):
    L = a.length
    after = np.array([L, L + 0.5, L + 3.0, L + 1e6, np.inf])
    x, v, acc = a.evaluate_full(after)
    ends = a.evaluate([L + 1e9])[0]
    assert_close(x[1:], np.broadcast_to(ends, x[1:].shape), atol=0)
    assert not v[1:].any() and not acc[1:].any()
    before = a.evaluate_full([-np.inf, -3.0, -1e-9])
    assert not before[1].any()
    assert_close(before[0], np.broadcast_to(before[0][0], before[0].shape), atol=0)


@PROFILE
@given(leaf_tracks())
def test_leaf_holds_last_keyframe(spec):
    m = Motion.from_tracks(spec)
    for j, (start, keys) in spec.items():
        want = keys[-1].position if keys else start
        assert np.array_equal(m.evaluate([m.length + 7.25], [j])[0, 0], want)
        assert strip(m, [j]).length == (keys[-1].frame if keys else 0.0)


def breakpoints(spec) -> np.ndarray:
    """Frames where a leaf's acceleration may jump: knots, ramp ends, ACCDCC middles."""
    pts = [0.0]
    for start, keys in spec.values():
        f0 = 0.0
        for key in keys:
            f = key.frame
            T = f - f0
            r = min(tr.RAMP, T / 2)
            pts += [f0, f, f0 + r, f - r, f0 + T / 2]
            f0 = f
    return np.array(pts)


@PROFILE
@given(leaf_tracks())
def test_velocity_and_acceleration_match_finite_differences(spec):
    m = Motion.from_tracks(spec)
    bp = breakpoints(spec)
    t = np.random.default_rng(11).uniform(-1.0, m.length + 1.0, 200)
    t = t[np.min(np.abs(t[:, None] - bp[None, :]), axis=1) > 1e-3]
    h = 1e-5
    x, v, acc = m.evaluate_full(t)
    xp, vp, _ = m.evaluate_full(t + h)
    xm, vm, _ = m.evaluate_full(t - h)
    np.testing.assert_allclose(v, (xp - xm) / (2 * h), atol=1e-4, rtol=1e-5)
    np.testing.assert_allclose(acc, (vp - vm) / (2 * h), atol=1e-4, rtol=1e-5)


@PROFILE
@given(leaf_tracks())
def test_velocity_is_continuous_where_linear_adjusts(spec):
    m = Motion.from_tracks(spec)
    for j, (start, keys) in spec.items():
        frames = [0.0] + [k.frame for k in keys]
        meths = [k.method for k in keys]
        for i in range(1, len(keys)):  # knot i joins segment i-1 and segment i
            T1, T2 = frames[i] - frames[i - 1], frames[i + 1] - frames[i]
            if T1 > 0 and T2 > 0 and "LINEAR" in (meths[i - 1], meths[i]):
                eps = 1e-7
                _, v, acc = m.evaluate_full([frames[i] - eps, frames[i] + eps], [j])
                slack = 2 * eps * np.abs(acc).max() + 1e-9  # how far the sides drift within eps
                np.testing.assert_allclose(v[0, 0], v[1, 0], rtol=0, atol=slack)


@PROFILE
@given(leaf_tracks())
def test_linear_chains_never_overshoot(spec):
    spec = {j: (s, [Keyframe(k.frame, k.position, "LINEAR") for k in keys]) for j, (s, keys) in spec.items()}
    m = Motion.from_tracks(spec)
    for j, (start, keys) in spec.items():
        knots_ = [(0.0, np.array(start))] + [(k.frame, np.array(k.position)) for k in keys]
        for (f0, v0), (f1, v1) in zip(knots_, knots_[1:]):
            if f1 == f0:
                continue
            t = np.linspace(f0, f1, 33)[1:-1]
            x, v, _ = m.evaluate_full(t, [j])
            lo, hi = np.minimum(v0, v1), np.maximum(v0, v1)
            assert np.all((x[:, 0] >= lo - 1e-9) & (x[:, 0] <= hi + 1e-9))
            assert np.all(v[:, 0] * np.sign(v1 - v0) >= -1e-9)


@PROFILE
@given(leaf_tracks(joints=[1]))
def test_hand_reversed_keyframes_give_the_mirrored_motion(spec):
    """The velocity adjustment is symmetric: writing the keyframes backwards is reversal."""
    start, keys = spec[1]
    m = Motion.from_tracks(spec)
    E = m.length
    rev_name = {"ACCELERATE": "DECELERATE", "DECELERATE": "ACCELERATE"}
    knots_ = [(0.0, start)] + [(k.frame, k.position) for k in keys]
    back = [
        Keyframe(E - knots_[i][0], knots_[i][1], rev_name.get(keys[i].method, keys[i].method))
        for i in range(len(keys) - 1, -1, -1)
    ]
    hand = Motion.from_tracks({1: (knots_[-1][1], back)})
    steps = {f for (f, _), (g, _) in zip(knots_, knots_[1:]) if f == g}
    t = probe_times(m)
    t = t[~np.isin(t, [E - s for s in steps])]  # a hand-written step is right-continuous
    assert_close(hand.evaluate(t), m.scale_frames(-1).evaluate(t))


@PROFILE
@given(motions())
def test_keyframe_listing_round_trips(m):
    spec = {j: m.keyframes(j, limit=5000) for j in m.joints}
    back = Motion.from_tracks(spec)
    assert back.length == m.length
    t = np.random.default_rng(5).uniform(-1.0, m.length + 1.0, 60)
    assert_close(back.evaluate(t), m.evaluate(t), atol=1e-7)


@PROFILE
@given(leaf_tracks(), st.data())
def test_unwrapping_takes_the_short_way_in_each_leaf(spec, data):
    m = Motion.from_tracks(spec)
    axes = {j: data.draw(st.tuples(st.booleans(), st.booleans(), st.booleans())) for j in m.joints}
    u = m.unwrapped(axes)
    assert u.length == m.length
    for j, (start, keys) in spec.items():
        free = np.array(axes[j])
        ustart, ukeys = u.keyframes(j)
        assert ustart == tuple(start)
        previous = np.array(start)
        for key, original in zip(ukeys, keys):
            v, d = np.array(key.position), np.subtract(key.position, original.position)
            assert key.frame == original.frame
            assert np.all(d[~free] == 0)
            assert np.all(d[free] % 360.0 == 0)
            assert np.all(np.abs(v - previous)[free] <= 180.0)
            previous = v


@FEW
@given(motions(), st.data())
def test_unwrapping_only_moves_free_axes_by_whole_turns(m, data):
    axes = {j: data.draw(st.tuples(st.booleans(), st.booleans(), st.booleans())) for j in m.joints}
    u = m.unwrapped(axes)
    assert u.length == m.length and u.joints == m.joints
    for j in m.joints:
        t = knots(strip(m, [j]))  # at its own keyframes a joint differs by whole turns only
        d = u.evaluate(t, [j])[:, 0] - m.evaluate(t, [j])[:, 0]
        free = np.array(axes[j], dtype=bool)
        assert np.all(d[:, ~free] == 0)
        turns = d[:, free] / 360.0
        np.testing.assert_allclose(turns, np.round(turns), atol=1e-9)


# -- laziness -------------------------------------------------------------------


@FEW
@given(leaf_motions())
def test_huge_repeat_is_lazy(walk):
    n = 10**9
    big = n * walk
    assert big.length == n * walk.length
    assert big.footprint().keyframes == walk.footprint().keyframes
    assert big.footprint().nodes <= 2 * walk.footprint().nodes
    ticks = np.arange(100.0)
    local = np.mod(ticks, walk.length) if walk.length else ticks
    if walk.length:
        assert_close(big.evaluate(ticks), walk.evaluate(local))
    back = big.scale_frames(-1)
    assert back.footprint().keyframes <= 2 * walk.footprint().keyframes
    assert_close(back.evaluate(ticks), big.evaluate(big.length - ticks))
