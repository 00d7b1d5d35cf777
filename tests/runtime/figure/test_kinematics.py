"""Rotation matrices, batched pose evaluation, re-rooting, clamping."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liganimate.runtime.figure.kinematics import (
    clamp,
    free_axes,
    invert_transform,
    joint_transforms,
    matrix_from_euler_zyx,
    pose_transforms,
    pose_transforms_reference,
    shape_transforms,
    transform_from,
)
from liganimate.runtime.figure.tree import Figure, Joint, Link, join


def rot(axis: str, deg: float) -> np.ndarray:
    """Single-axis rotation written out by hand (right-hand rule)."""
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return {
        "x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def random_figure(rng: np.random.Generator, n: int) -> Figure:
    """A random tree of ``n`` links, deliberately NOT in pre-order.

    Link and joint order are shuffled and the original and current main
    links are arbitrary, so nothing can lean on the order the figure
    operations happen to produce.
    """
    parents = [int(i - 1 if rng.random() < 0.5 else rng.integers(0, i)) for i in range(1, n)]
    perm = rng.permutation(n)  # canonical index -> stored index
    links = [None] * n
    for i in range(n):
        links[perm[i]] = Link(f"L{i}", shape=i)
    ids = rng.choice(1000, size=max(n - 1, 0), replace=False)
    joints = [
        Joint(int(ids[i - 1]), int(perm[p]), int(perm[i]), rng.normal(size=3), rng.normal(size=3), [(-180, 180)] * 3)
        for i, p in zip(range(1, n), parents)
    ]
    order = rng.permutation(len(joints))
    return Figure(tuple(links), tuple(joints[k] for k in order), root=int(perm[0]), main=int(rng.integers(n)))


def random_angles(rng: np.random.Generator, figure: Figure, frames: int) -> np.ndarray:
    return rng.uniform(-180, 180, size=(frames, figure.n_joints, 3))


def figure1() -> Figure:
    """Thesis Figure 1, first joint: object1 (0,-2,0) to object2 (0,2,0), Z free."""
    return join(1, Link("object1", "o1"), (0, -2, 0), Link("object2", "o2"), (0, 2, 0), [(0, 0), (0, 0), (-180, 180)])


# ----------------------------------------------------------------- rotations


def test_matrix_from_euler_zyx_is_rz_ry_rx():
    rng = np.random.default_rng(1)
    angles = rng.uniform(-360, 360, size=(50, 3))
    R = matrix_from_euler_zyx(angles)
    assert R.shape == (50, 3, 3)
    for a, r in zip(angles, R):
        np.testing.assert_allclose(r, rot("z", a[2]) @ rot("y", a[1]) @ rot("x", a[0]), atol=1e-12)


def test_matrix_from_euler_zyx_batch_shape_and_orthonormal():
    rng = np.random.default_rng(2)
    R = matrix_from_euler_zyx(rng.uniform(-180, 180, size=(2, 4, 5, 3)))
    assert R.shape == (2, 4, 5, 3, 3)
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0)
    with pytest.raises(ValueError):
        matrix_from_euler_zyx([1.0, 2.0])


def test_right_hand_rule():
    # +90 about Z turns X into Y; about X turns Y into Z; about Y turns Z into X.
    np.testing.assert_allclose(matrix_from_euler_zyx([0, 0, 90]) @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(matrix_from_euler_zyx([90, 0, 0]) @ [0, 1, 0], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(matrix_from_euler_zyx([0, 90, 0]) @ [0, 0, 1], [1, 0, 0], atol=1e-12)
    # X is applied first: (90, 0, 90) takes Y to Z (by X) and Z stays Z.
    np.testing.assert_allclose(matrix_from_euler_zyx([90, 0, 90]) @ [0, 1, 0], [0, 0, 1], atol=1e-12)


def test_transform_from_and_invert():
    rng = np.random.default_rng(3)
    R = matrix_from_euler_zyx(rng.uniform(-180, 180, size=(10, 3)))
    p = rng.normal(size=(10, 3))
    A = transform_from(R, p)
    assert A.shape == (10, 4, 4)
    np.testing.assert_allclose(A[:, 3], np.broadcast_to([0, 0, 0, 1.0], (10, 4)))
    np.testing.assert_allclose(invert_transform(A) @ A, np.broadcast_to(np.eye(4), A.shape), atol=1e-12)
    np.testing.assert_allclose(invert_transform(A), np.linalg.inv(A), atol=1e-12)


# ----------------------------------------------------------------- poses by hand


def test_figure1_joint_by_hand():
    # Point p of object2 is (0,-2,0) + Rz(90) (p - (0,2,0)) in object1.
    X = pose_transforms(figure1(), [[0, 0, 90]])
    assert X.shape == (2, 4, 4)
    np.testing.assert_allclose(X[0], np.eye(4))
    expected = np.array([[0, -1, 0, 2], [1, 0, 0, -2], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    np.testing.assert_allclose(X[1], expected, atol=1e-12)
    # object2's far end (0,-2,0) swings to the +X side of the joint.
    np.testing.assert_allclose(X[1] @ [0, -2, 0, 1], [4, -2, 0, 1], atol=1e-12)


def test_figure1_rooted_at_secondary_reverses_the_sign():
    # Thesis Figures 13/14: seen from object2, object1 is turned by -90, not +90.
    X = pose_transforms(figure1().with_main(1), [[0, 0, 90]])
    np.testing.assert_allclose(X[1], np.eye(4))
    np.testing.assert_allclose(X[0][:3, :3], rot("z", -90), atol=1e-12)
    # Trans(L2) Rz(-90) Trans(-L1): object1's origin lands at (2, 2, 0).
    np.testing.assert_allclose(X[0][:3, 3], [2, 2, 0], atol=1e-12)
    # Using +90 there (no sign reversal) would be the contorted Figure 14.
    assert not np.allclose(X[0][:3, :3], rot("z", 90))


def test_neutral_pose_just_lines_up_locations():
    f = join(5, Link("a", 0), (1, 2, 3), Link("b", 1), (-1, 0, 4), [(-10, 10)] * 3)
    X = pose_transforms(f, np.zeros((1, 3)))
    np.testing.assert_allclose(X[1], transform_from(np.eye(3), [2, 2, -1]))


def test_joint_transforms_shape_and_values():
    f = figure1()
    A = joint_transforms(f, np.zeros((7, 1, 3)))
    assert A.shape == (7, 1, 4, 4)
    np.testing.assert_allclose(A[3, 0][:3, 3], [0, -4, 0])


def test_single_link_figure_is_identity():
    f = Figure.from_link(Link("lonely", None))
    X = pose_transforms(f, np.zeros((4, 0, 3)))
    assert X.shape == (4, 1, 4, 4)
    np.testing.assert_allclose(X, np.broadcast_to(np.eye(4), X.shape))


def test_angle_shape_is_checked():
    with pytest.raises(ValueError, match=r"\(\.\.\., 1, 3\)"):
        pose_transforms(figure1(), np.zeros((5, 2, 3)))


# ----------------------------------------------------------------- batched vs reference


@pytest.mark.parametrize("seed", range(12))
def test_batched_pose_matches_reference(seed):
    rng = np.random.default_rng(seed)
    f = random_figure(rng, int(rng.integers(1, 14)))
    angles = random_angles(rng, f, 6)
    fast = pose_transforms(f, angles)
    slow = pose_transforms_reference(f, angles)
    assert fast.shape == slow.shape == (6, f.n_links, 4, 4)
    np.testing.assert_allclose(fast, slow, atol=1e-9)


def test_batched_pose_accepts_any_leading_shape():
    rng = np.random.default_rng(20)
    f = random_figure(rng, 6)
    angles = rng.uniform(-90, 90, size=(2, 3, f.n_joints, 3))
    X = pose_transforms(f, angles)
    assert X.shape == (2, 3, 6, 4, 4)
    np.testing.assert_allclose(X[1, 2], pose_transforms(f, angles[1, 2]))
    np.testing.assert_allclose(X, pose_transforms_reference(f, angles), atol=1e-9)


def test_current_main_is_identity_and_joint_points_coincide():
    rng = np.random.default_rng(21)
    for _ in range(5):
        f = random_figure(rng, 9)
        angles = random_angles(rng, f, 4)
        X = pose_transforms(f, angles)
        np.testing.assert_allclose(X[:, f.main], np.broadcast_to(np.eye(4), (4, 4, 4)))
        for j in f.joints:
            # The joint's two locations are the same point whatever the angles.
            p = X[:, j.primary] @ np.append(j.loc1, 1.0)
            s = X[:, j.secondary] @ np.append(j.loc2, 1.0)
            np.testing.assert_allclose(p, s, atol=1e-9)


# ----------------------------------------------------------------- re-rooting invariance


@st.composite
def figures_and_angles(draw):
    n = draw(st.integers(1, 10))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    f = random_figure(rng, n)
    return f, random_angles(rng, f, 3)


@settings(max_examples=60, deadline=None)
@given(figures_and_angles())
def test_rerooting_changes_shape_only_by_one_rigid_motion(case):
    f, angles = case
    base = pose_transforms(f.with_original_main(), angles)  # (T, n, 4, 4)
    for m in range(f.n_links):
        X = pose_transforms(f.with_main(m), angles)
        np.testing.assert_allclose(X[:, m], np.broadcast_to(np.eye(4), (len(angles), 4, 4)), atol=1e-12)
        # One rigid motion per frame (the new main link's inverse pose) maps
        # the original-rooted shape onto the re-rooted one, for every link.
        G = invert_transform(base[:, m])
        np.testing.assert_allclose(X, G[:, None] @ base, atol=1e-9)


def test_rerooting_without_sign_reversal_would_fail():
    # Guard that the invariance test can fail: re-root by flipping only the
    # tree's direction but keeping the joint's angles (thesis Figure 14).
    rng = np.random.default_rng(5)
    a, b, c = Link("a", 0), Link("b", 1), Link("c", 2)
    f = join(1, a, (0, -1, 0), join(2, b, (0, -1, 0), c, (0, 1, 0), [(-180, 180)] * 3), (0, 1, 0), [(-180, 180)] * 3)
    angles = rng.uniform(-90, 90, size=(1, 2, 3))
    rerooted = pose_transforms(f.with_main(2), angles)
    base = pose_transforms(f, angles)
    # Contorted: treat each reversed joint as if its primary were the
    # secondary with the same angles.
    contorted = join(
        2, c, (0, 1, 0), join(1, b, (0, 1, 0), a, (0, -1, 0), [(-180, 180)] * 3), (0, -1, 0), [(-180, 180)] * 3
    )
    bad = pose_transforms(contorted, angles[:, ::-1])  # links c, b, a
    good_shape = invert_transform(base[:, 2])[:, None] @ base
    np.testing.assert_allclose(rerooted, good_shape, atol=1e-9)
    assert not np.allclose(bad[:, ::-1], good_shape, atol=1e-3)


# ----------------------------------------------------------------- geometry, placement


def test_shape_transforms_apply_placement_and_scale():
    f = figure1().scale_model(-2.0)
    M = transform_from(matrix_from_euler_zyx([0, 30, 0]), [5, 0, 0])
    f = f.with_placement(M)
    angles = np.array([[[0, 0, 40]]])
    S = shape_transforms(f, angles)
    X = pose_transforms(f, angles)
    assert S.shape == (1, 2, 4, 4)
    np.testing.assert_allclose(S[0, 1] @ [1, 2, 3, 1], M @ X[0, 1] @ [-2, -4, -6, 1], atol=1e-12)
    # A negative scale makes each drawn link a mirror image.
    assert np.all(np.linalg.det(S[..., :3, :3]) < 0)


# ----------------------------------------------------------------- clamping


def clamp_figure() -> Figure:
    return join(
        3,
        Link("a", 0),
        (0, 0, 0),
        Link("b", 1),
        (0, 0, 0),
        [(-45, 45), (-180, 180), (0, 360)],
    )


def test_free_axes():
    f = join(1, clamp_figure(), (0, 0, 0), Link("c", 2), (0, 0, 0), [(0, 135), (-200, 200)])
    assert free_axes(f) == {3: (False, True, True), 1: (False, True, False)}
    assert free_axes(f.scale_extremes(0.5)) == {3: (False, False, False), 1: (False, False, False)}
    assert free_axes(f.scale_extremes(-3)) == {3: (False, True, True), 1: (True, True, False)}


def test_clamp_clips_limited_axes_and_wraps_free_ones():
    f = clamp_figure()
    angles = np.array(
        [
            [[60, 190, -10]],
            [[-50, -180, 360]],
            [[10, 180, 725]],
            [[-45, -190, -1e-14]],
        ]
    )
    out = clamp(f, angles)
    expected = np.array(
        [
            [[45, -170, 350]],
            [[-45, -180, 0]],
            [[10, -180, 5]],
            [[-45, 170, 0]],
        ]
    )
    np.testing.assert_allclose(out, expected, atol=1e-9)
    assert np.all(out[..., 2] < 360) and np.all(out[..., 2] >= 0)


def test_clamp_locks_omitted_axes():
    f = join(2, Link("humerus", 0), (0, 5, 1), Link("forearm", 1), (0, 0.5, 1), [(0, 135), (0, 180)])
    out = clamp(f, np.array([[[200, -30, 77]]]))
    np.testing.assert_allclose(out, [[[135, 0, 0]]])


def test_clamp_random_within_extremes():
    rng = np.random.default_rng(8)
    f = clamp_figure()
    out = clamp(f, rng.uniform(-1000, 1000, size=(500, 1, 3)))
    ext = f.extremes
    assert np.all(out >= ext[..., 0]) and np.all(out[..., :2] <= ext[:, :2, 1])
    assert np.all(out[..., 2] < 360)
