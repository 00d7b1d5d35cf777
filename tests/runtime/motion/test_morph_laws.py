"""Property tests: the motion algebra's laws carried through morph tracks (SCALE and SHAPE of a link).

Morph channels ride in the motion beside its joints and compose as joint
tracks do; these tests check what a figure draws from them: its segments'
scale factors and their morphed triangles.  a + b plays b's morph after a's
(a link b does not morph holds a's end shape), n * a is a + ... + a, the two
SCALEs of time stretch and reverse it, STRIP and SCALE EXTREMES leave it,
SYNCHRONIZE rejoins a split, and every in-between lies within its keyframes
(a shape within the box of its keyframe shapes, a scale between its
keyframes' factors: never zero, never inside out).
"""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from test_motion_laws import FEW, FRAME_FACTOR, METHODS, PROFILE, SEEDS

from liganimate.runtime.errors import MotionError
from liganimate.runtime.figure.morphing import target
from liganimate.runtime.figure.pose import mesh_table, morphed, world_transforms
from liganimate.runtime.figure.tree import Figure, Joint, Link
from liganimate.runtime.motion import morph as mo
from liganimate.runtime.motion.algebra import Motion, strip, synchronize
from liganimate.runtime.motion.keyframe import Keyframe
from liganimate.runtime.values import box

OWN_A = box((0, 0, 0), 1.0, 1.0, 1.0, 40.0)
OWN_B = box((0, 0.5, 0), 0.5, 1.0, 0.25, 40.0)
# Shapes the SHAPE keyframes name (None: the link's own), all of a BOX's structure.
SHAPES = [None, box((0.25, 0, 0), 2.0, 0.5, 1.0, 40.0), box((0, -1, 0.5), 0.25, 3.0, 0.5, 40.0), OWN_B]
FACTORS = [0.5, 1.0, 2.0, 0.25, 3.0]
FIG = Figure(
    (Link("A", OWN_A), Link("B", OWN_B), Link("C", OWN_A)),
    (Joint(1, 0, 1, (0, 1, 0), (0, -1, 0), [(-90, 90)] * 3), Joint(2, 0, 2, (1, 0, 0), (0, 0, 0), [(-90, 90)] * 3)),
)


@st.composite
def leaf_morphs(draw):
    """A STARTMOTION with a SCALE track on link A or C, a SHAPE track on B, and perhaps joint 1."""
    rng = np.random.default_rng(draw(SEEDS))

    def frames(n):
        return np.cumsum(rng.choice([0.0, 1.0, 2.0, 4.0, 6.0], size=n)) + rng.choice([0.0, 2.0])

    scales, shapes, joints = {}, {}, {}
    if rng.integers(0, 4):
        n = int(rng.integers(0, 4))
        keys = [Keyframe(float(f), tuple(rng.choice(FACTORS, size=3)), str(rng.choice(METHODS))) for f in frames(n)]
        start = tuple(rng.choice(FACTORS, size=3)) if rng.integers(0, 2) else None
        scales[str(rng.choice(["A", "C"]))] = (start, keys)
    if rng.integers(0, 4):
        n = int(rng.integers(0, 4))

        def pick():
            g = SHAPES[int(rng.integers(0, len(SHAPES)))]
            return None if g is None else target(g)

        keys = [mo.ShapeKey(float(f), pick(), str(rng.choice(METHODS))) for f in frames(n)]
        shapes["B"] = (pick(), keys)
    if rng.integers(0, 2):
        joints[1] = (None, [Keyframe(float(f), (0.0, 0.0, 30.0 * k), "LINEAR") for k, f in enumerate(frames(2))])
    m = Motion.from_tracks(joints)
    return m.with_morphs(mo.build(scales, shapes, m.length, Motion))


LEAVES = leaf_morphs()


@st.composite
def morph_motions(draw, depth=2):
    if depth == 0 or draw(st.integers(0, 2)) == 0:
        return draw(LEAVES)
    op = draw(st.sampled_from(["+", "*", "frames", "extremes", "strip"]))
    a = draw(morph_motions(depth - 1))
    if op == "+":
        return a + draw(morph_motions(depth - 1))
    if op == "*":
        return draw(st.integers(0, 3)) * a
    if op == "frames":
        return a.scale_frames(draw(FRAME_FACTOR))
    if op == "extremes":
        return a.scale_extremes(-0.5)
    return strip(a, [])


MOTIONS = morph_motions()


def drawn(m: Motion, t) -> tuple[np.ndarray, np.ndarray]:
    """What the figure draws: the links' scale factors (T, 3 links, 3) and its link-space triangles (T, M, 3, 3)."""
    t = np.asarray(t, dtype=float)
    X = world_transforms(FIG, np.zeros((len(t), FIG.n_joints, 3)), np.broadcast_to(np.eye(4), (len(t), 4, 4)))
    X, local = morphed(FIG, m, t, X)
    table = mesh_table(FIG)
    if local is None:
        local = np.broadcast_to(table.triangles, (len(t), *table.triangles.shape))
    return np.linalg.norm(X[..., :3, :3], axis=-2), local


def probes(m: Motion) -> np.ndarray:
    L = m.length
    rng = np.random.default_rng(7)
    return np.unique(np.concatenate([rng.uniform(-1.0, L + 2.0, 30), [-1.0, L + 1.0, L + 1e6]]))


def generic(m: Motion) -> np.ndarray:
    """Times off every keyframe and junction (frames are multiples of 1/8 after the factors used)."""
    return probes(m) + 1.0 / 1024


def channel(m: Motion, key: tuple, t) -> np.ndarray | None:
    """One morph channel's values at ``t`` (a scale's factors, a shape target's weight), None if not driven."""
    if m.morphs is None or key not in m.morphs.channels():
        return None
    return m.morphs.motion._tracks[key].sample_x(np.asarray(t, dtype=float))


@PROFILE
@given(MOTIONS, MOTIONS)
def test_concat_plays_b_after_a_and_a_before(a, b):
    """Channel by channel, as joint tracks: where a channel jumps at the junction, each side plays unchanged.

    (Where its values meet, the junction shares a velocity: the algebra's own
    test; a channel b's first operands leave undriven, a leading gap, shows
    a's end there; one only b drives shows b's first value before.)
    """
    m = a + b
    La = a.length
    t = generic(b)
    t = t[t > 0]
    s = generic(a)
    s = s[(s >= 0) & (s < La)]
    opened = set() if b.morphs is None else b.morphs.motion._open
    for key in m.morphs.channels() if m.morphs is not None else ():
        ea, sb = channel(a, key, [La + 1e9]), channel(b, key, [-1.0])
        if ea is not None and sb is not None and np.array_equal(ea, sb):
            continue
        if sb is not None and key not in opened:
            np.testing.assert_allclose(channel(m, key, La + t), channel(b, key, t), atol=1e-9)
        if ea is not None:
            np.testing.assert_allclose(channel(m, key, s), channel(a, key, s), atol=1e-9)


@PROFILE
@given(MOTIONS, MOTIONS, MOTIONS)
def test_concat_is_associative(a, b, c):
    left, right = (a + b) + c, a + (b + c)
    t = probes(left)
    for x, y in zip(drawn(left, t), drawn(right, t)):
        np.testing.assert_allclose(x, y, atol=1e-9)


@FEW
@given(MOTIONS, st.integers(1, 4))
def test_repeat_is_repeated_concat(a, n):
    # (0 * a holds a's start values, as it does a joint's: no sum of copies says that.)
    many = a
    for _ in range(n - 1):
        many = many + a
    t = probes(n * a)
    for x, y in zip(drawn(n * a, t), drawn(many, t)):
        np.testing.assert_allclose(x, y, atol=1e-9)


@FEW
@given(MOTIONS, FRAME_FACTOR)
def test_scale_frames_stretches_and_reverses_the_morphs(a, r):
    t = generic(a)
    L = a.length
    at = abs(r) * (t if r > 0 else L - t)
    for x, y in zip(drawn(a.scale_frames(r), at), drawn(a, t)):
        np.testing.assert_allclose(x, y, atol=1e-7)


@FEW
@given(MOTIONS)
def test_reversing_twice_gives_the_morphs_back(a):
    t = probes(a)
    for x, y in zip(drawn(a.scale_frames(-1).scale_frames(-1), t), drawn(a, t)):
        np.testing.assert_allclose(x, y, atol=1e-9)


@FEW
@given(MOTIONS)
def test_strip_synchronize_and_scale_extremes_leave_the_morphs(a):
    t = probes(a)
    want = drawn(a, t)
    split = synchronize(strip(a, [j for j in a.joints if j == 1]), strip(a, [j for j in a.joints if j != 1]))
    for m in (strip(a, []), a.scale_extremes(2.0), split):
        for x, y in zip(drawn(m, t), want):
            np.testing.assert_allclose(x, y, atol=1e-12)


@PROFILE
@given(MOTIONS)
def test_in_betweens_stay_within_their_keyframes(a):
    """The velocity rules never overshoot: a scale stays positive, a shape within its shapes' box."""
    scale, tris = drawn(a, probes(a))
    assert (scale > 0).all()
    assert scale.min() >= min(FACTORS) - 1e-9 and scale.max() <= max(FACTORS) + 1e-9
    rows = mesh_table(FIG).link == 1
    corners = np.stack([(g if g is not None else OWN_B).triangles for g in SHAPES])
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    assert (tris[:, rows] >= lo - 1e-9).all() and (tris[:, rows] <= hi + 1e-9).all()


def test_synchronize_refuses_one_link_morphed_by_two_operands():
    def scaled(f):
        m = Motion.empty()
        return m.with_morphs(mo.build({"A": (None, [Keyframe(4.0, (f, f, f))])}, {}, 0.0, Motion))

    try:
        synchronize(scaled(2.0), scaled(3.0))
    except MotionError as exc:
        assert "link A" in exc.message and "operand 1 and operand 2" in exc.message
    else:
        raise AssertionError("SYNCHRONIZE accepted two scale tracks of one link")


def test_a_shape_morph_in_betweens_the_corners_and_rests_at_its_keyframes():
    wide = box((0, 0, 0), 2.0, 1.0, 1.0, 40.0)
    m = Motion.empty().with_morphs(mo.build({}, {"A": (None, [mo.ShapeKey(8.0, target(wide), "LINEAR")])}, 0.0, Motion))
    _, tris = drawn(m, np.array([0.0, 4.0, 8.0, 7.999]))
    rows = mesh_table(FIG).link == 0
    np.testing.assert_allclose(tris[0, rows], OWN_A.triangles)
    np.testing.assert_allclose(tris[2, rows], wide.triangles)
    np.testing.assert_allclose(tris[1, rows], (OWN_A.triangles + wide.triangles) / 2)  # LINEAR is symmetric
    # It comes to rest at the keyframe: the last thousandth of a frame barely moves.
    assert np.abs(tris[3, rows] - wide.triangles).max() < 1e-5
