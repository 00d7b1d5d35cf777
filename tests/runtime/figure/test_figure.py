"""Model structure and model operations: JOINT, STARTMODEL, transformations, FIGURE ... MAIN, PRINT."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from liganimate.runtime.errors import FigureError
from liganimate.runtime.figure.kinematics import invert_transform, pose_transforms, shape_transforms, transform_from
from liganimate.runtime.figure.tree import Figure, Joint, JointSpec, Link, assemble, join, normalize_extremes

FREE = [(-180, 180)] * 3


def signature(f: Figure):
    """Everything that makes two figures the same model (rounded floats)."""
    r = lambda a: tuple(np.round(np.asarray(a, float).ravel(), 12) + 0.0)
    return (
        tuple((l.name, id(l.shape), round(l.scale, 12)) for l in f.links),
        tuple((j.id, j.primary, j.secondary, r(j.loc1), r(j.loc2), r(j.extremes)) for j in f.joints),
        f.root,
        f.main,
        r(f.placement),
    )


# ----------------------------------------------------------------- the Appendix A human

BOX = {
    name: ("BOX", dims)
    for name, dims in {
        "TORSO": (0.56, 1.46, 0.36),
        "FARM": (0.22, 0.48, 0.14),
        "BARM": (0.22, 0.48, 0.14),
        "FLEG": (0.30, 0.58, 0.18),
        "BLEG": (0.30, 0.40, 0.18),
        "FOOT": (0.42, 0.13, 0.10),
    }.items()
}


def link(name: str) -> Link:
    return Link(name, BOX[name])


def build_human() -> tuple[Figure, list]:
    """Appendix A's HUMAN, statement by statement."""
    rarm = join(1, link("BARM"), (0.0, -0.24, 0.0), link("FARM"), (0.0, 0.24, 0.0), [(0, 0), (0, 0), (0, 135)])
    larm = rarm.trans_joints(1)
    rleg, warnings = assemble(
        [
            (3, "BLEG", (0.00, -0.20, 0.0), "FLEG", BOX["FLEG"], (0.00, 0.29, 0.0), [(0, 0), (0, 0), (-150, 0)], 0),
            (
                4,
                "FLEG",
                (-0.05, -0.29, 0.0),
                "FOOT",
                BOX["FOOT"],
                (-0.11, 0.06, 0.0),
                [(0, 45), (-25, 25), (-50, 50)],
                1,
            ),
        ],
        BOX,
    )
    lleg = rleg.trans_joints(2)
    arm_ext = [(0, 180), (-20, 20), (-90, 180)]
    leg_ext = [(-45, 45), (-45, 45), (-90, 135)]
    human = join(7, link("TORSO"), (0.00, 0.40, -0.18), rarm, (0.0, 0.24, 0.0), arm_ext)
    human = join(8, human, (0.00, 0.40, 0.18), larm, (0.0, 0.24, 0.0), arm_ext)
    human = join(9, human, (0.00, -0.40, -0.18), rleg, (0.0, 0.24, 0.0), leg_ext)
    human = join(10, human, (0.00, -0.40, 0.18), lleg, (0.0, 0.24, 0.0), leg_ext)
    return human, warnings


def squat(human: Figure, frames: int = 6) -> np.ndarray:
    """Appendix A's SQUAT (linear here; the interpolation is not this module's business)."""
    t = np.linspace(0.0, 1.0, frames)
    z = {1: 135 + 0 * t, 2: 135 + 0 * t, 3: -135 * t, 4: 45 * t, 5: -135 * t, 6: 45 * t, 9: 90 * t, 10: 90 * t}
    angles = np.zeros((frames, human.n_joints, 3))
    for jid, values in z.items():
        angles[:, human.joint_index(jid), 2] = values
    return angles


def test_human_structure():
    human, warnings = build_human()
    assert warnings == []
    assert human.n_links == 11 and human.n_joints == 10
    assert human.joint_ids == (7, 1, 8, 2, 9, 3, 4, 10, 5, 6)
    assert human.links[human.root].name == "TORSO" and human.main == human.root
    assert [human.links[i].name for i in human.links_named("foot")] == ["FOOT", "FOOT"]
    assert human.parent_joint_of(human.root) is None
    assert [human.parent_joint_of(i).id for i in human.links_named("FOOT")] == [4, 6]
    # Operations keep links and joints in pre-order: joint k introduces link k + 1.
    assert human.preorder == tuple(range(11))
    assert all(j.secondary == k + 1 for k, j in enumerate(human.joints))


def test_figure_human_main_link_foot_warns_and_picks_the_first_foot():
    human, _ = build_human()
    on_foot, warning = human.with_main_link("FOOT", model_name="HUMAN")
    assert on_foot.parent_joint_of(on_foot.main).id == 4
    assert "joint 4" in warning and "FIGURE HUMAN MAIN JOINT 6 to choose another" in warning
    # The structure is untouched: only the current main link moved.
    assert on_foot.root == human.root and signature(on_foot)[:2] == signature(human)[:2]
    assert on_foot.with_main_joint(6).parent_joint_of(on_foot.with_main_joint(6).main).id == 6
    assert on_foot.with_original_main().main == human.root


def test_human_neutral_pose_on_foot_by_hand():
    human, _ = build_human()
    on_foot, _ = human.with_main_link("FOOT")
    X = pose_transforms(on_foot, np.zeros((human.n_joints, 3)))
    # TORSO -> BLEG -> FLEG -> FOOT offsets add up to (0.06, -1.48, -0.18).
    np.testing.assert_allclose(X[human.root], transform_from(np.eye(3), [-0.06, 1.48, 0.18]), atol=1e-12)


def test_squat_on_foot_keeps_the_feet_down_and_lowers_the_torso():
    human, _ = build_human()
    on_foot, _ = human.with_main_link("FOOT")
    angles = squat(human)
    X = pose_transforms(on_foot, angles)
    right, left = human.links_named("FOOT")
    assert on_foot.main == right
    np.testing.assert_allclose(X[:, right], np.broadcast_to(np.eye(4), (6, 4, 4)))
    # Both legs bend alike, so the other foot stays put beside the first
    # (0.36 apart along Z), at every frame: the squat of thesis Figure 11.
    np.testing.assert_allclose(
        X[:, left], np.broadcast_to(transform_from(np.eye(3), [0, 0, 0.36]), (6, 4, 4)), atol=1e-12
    )
    torso_height = X[:, human.root, 1, 3]
    assert np.all(np.diff(torso_height) < 0), torso_height
    # Rooted at the torso instead, the torso is still and the feet rise (Figure 12).
    T = pose_transforms(human, angles)
    np.testing.assert_allclose(T[:, human.root], np.broadcast_to(np.eye(4), (6, 4, 4)))
    assert np.all(np.diff(T[:, right, 1, 3]) > 0)
    # Same shape either way (no contorted leg, Figure 14): one rigid motion per frame.
    np.testing.assert_allclose(X, invert_transform(T[:, right])[:, None] @ T, atol=1e-12)


# ----------------------------------------------------------------- extremes


def test_extremes_padding_locks_omitted_axes():
    np.testing.assert_array_equal(normalize_extremes([(0, 135), (0, 180)]), [[0, 135], [0, 180], [0, 0]])
    np.testing.assert_array_equal(normalize_extremes([(-5, 5)]), [[-5, 5], [0, 0], [0, 0]])
    np.testing.assert_array_equal(normalize_extremes((-5, 5)), [[-5, 5], [0, 0], [0, 0]])
    full = normalize_extremes([(1, 2), (3, 4), (5, 6)])
    np.testing.assert_array_equal(full, [[1, 2], [3, 4], [5, 6]])
    assert not full.flags.writeable


@pytest.mark.parametrize(
    "bad, axis",
    [([(10, 0)], "X"), ([(0, 1), (30, 10)], "Y"), ([(0, 1), (0, 1), (0, -1)], "Z")],
)
def test_extremes_min_above_max_names_the_axis(bad, axis):
    with pytest.raises(FigureError, match=rf"the {axis} extremes"):
        normalize_extremes(bad)
    with pytest.raises(FigureError, match=rf"joint 12: the {axis} extremes") as info:
        join(12, Link("a", 0), (0, 0, 0), Link("b", 1), (0, 0, 0), bad)
    assert info.value.hint


@pytest.mark.parametrize("bad", [[], [(0, 1)] * 4, [(0, 1, 2)], [(0, np.nan)], "wide", [(0, 1), (2,)]])
def test_extremes_malformed(bad):
    with pytest.raises(FigureError):
        normalize_extremes(bad)


# ----------------------------------------------------------------- JOINT and figures


def test_join_attaches_a_submodel_by_its_current_main_and_keeps_primary_state():
    a, b, c, d = (Link(n, n.lower()) for n in "ABCD")
    sub = join(2, c, (1, 0, 0), d, (0, 1, 0), FREE).with_main(1).with_placement(np.diag([1, 1, 1, 1.0]) * 3)
    M = transform_from(np.eye(3), [1, 2, 3])
    prim = join(1, a, (0, 0, 0), b, (0, 0, 0), FREE).with_main(1).with_placement(M)
    f = join(3, prim, (5, 5, 5), sub, (6, 6, 6), FREE)
    j3 = f.joint(3)
    assert f.links[j3.primary].name == "A"  # the primary's ORIGINAL main link
    # The thesis (3.3): a submodel's location is "with respect to the main link in the
    # submodel", the one FIGURE chose (D), not its original main link C.
    assert f.links[j3.secondary].name == "D"
    assert f.root == 0 and f.links[f.main].name == "B"  # primary's current main
    np.testing.assert_array_equal(f.placement, M)  # the primary's; the secondary's is dropped
    assert f.joint_ids == (1, 3, 2)
    # Joint 2 keeps its definition (C primary, D secondary); hung from A it is walked backwards.
    j2 = f.joint(2)
    assert (f.links[j2.primary].name, f.links[j2.secondary].name) == ("C", "D")
    assert list(f.inverted) == [False, False, True]
    assert [f.links[i].name for i in f.preorder] == ["A", "B", "D", "C"]
    # Value semantics: the operands are untouched.
    assert prim.n_links == 2 and sub.n_links == 2 and sub.main == 1


def test_join_with_links_only():
    f = join(4, Link("X", 0), (1, 2, 3), Link("Y", 1), (4, 5, 6), [(0, 10)])
    assert f.joint_ids == (4,) and f.joint_index(4) == 0
    j = f.joint(4)
    np.testing.assert_array_equal(j.loc1, [1, 2, 3])
    np.testing.assert_array_equal(j.loc2, [4, 5, 6])
    np.testing.assert_array_equal(j.extremes, [[0, 10], [0, 0], [0, 0]])
    assert not j.loc1.flags.writeable


def test_submodel_used_twice_is_copied():
    rarm = join(1, Link("BARM", 0), (0, -0.24, 0), Link("FARM", 1), (0, 0.24, 0), FREE)
    body = join(7, Link("TORSO", 2), (0, 0, -1), rarm, (0, 0, 0), FREE)
    body = join(8, body, (0, 0, 1), rarm.trans_joints(1), (0, 0, 0), FREE)
    assert body.joint_ids == (7, 1, 8, 2)
    assert body.links_named("FARM") == (2, 4)
    assert rarm.joint_ids == (1,)


@pytest.mark.parametrize("case", ["new-in-primary", "new-in-secondary", "primary-vs-secondary"])
def test_join_duplicate_joint_id_names_it(case):
    p = join(5, Link("a", 0), (0, 0, 0), Link("b", 1), (0, 0, 0), FREE)
    s = join(6, Link("c", 0), (0, 0, 0), Link("d", 1), (0, 0, 0), FREE)
    new_id, secondary = {
        "new-in-primary": (5, s),
        "new-in-secondary": (6, s),
        "primary-vs-secondary": (9, s.trans_joints(-1)),
    }[case]
    dup = {"new-in-primary": 5, "new-in-secondary": 6, "primary-vs-secondary": 5}[case]
    with pytest.raises(FigureError, match=rf"joint identifier {dup} is used twice") as info:
        join(new_id, p, (0, 0, 0), secondary, (0, 0, 0), FREE)
    assert "TRANS JOINTS" in info.value.hint


def test_joining_a_model_to_itself_collides():
    p = join(5, Link("a", 0), (0, 0, 0), Link("b", 1), (0, 0, 0), FREE)
    with pytest.raises(FigureError, match="joint identifier 5"):
        join(6, p, (0, 0, 0), p, (0, 0, 0), FREE)


def test_join_rejects_other_operands():
    with pytest.raises(FigureError, match="secondary"):
        join(1, Link("a", 0), (0, 0, 0), "b", (0, 0, 0), FREE)
    with pytest.raises(FigureError, match="location"):
        join(1, Link("a", 0), (0, 0), Link("b", 0), (0, 0, 0), FREE)


def test_figure_constructor_rejects_non_trees():
    a, b, c = Link("a", 0), Link("b", 1), Link("c", 2)
    J = lambda i, p, s: Joint(i, p, s, (0, 0, 0), (0, 0, 0), FREE)
    with pytest.raises(FigureError, match="needs 2 joints"):
        Figure((a, b, c), (J(1, 0, 1),))
    with pytest.raises(FigureError, match="one tree"):
        Figure((a, b, c), (J(1, 0, 1), J(2, 1, 0)))  # two joints between a and b, c alone
    # A joint may point towards the root (a re-rooted submodel's): still one tree.
    rooted_at_a = Figure((a, b, c), (J(1, 0, 1), J(2, 2, 1)))
    assert rooted_at_a.preorder == (0, 1, 2) and list(rooted_at_a.inverted) == [False, True]
    assert rooted_at_a.parent_joint_of(2).id == 2 and rooted_at_a.child_of(rooted_at_a.joint(2)) == 2
    with pytest.raises(FigureError, match="one tree"):
        Figure((a, b, c), (J(1, 1, 2), J(2, 2, 1)))  # b and c in a loop, a alone
    with pytest.raises(FigureError, match="used twice"):
        Figure((a, b, c), (J(1, 0, 1), J(1, 0, 2)))
    with pytest.raises(FigureError, match="two different links"):
        Figure((a, b), (J(1, 1, 1),))
    with pytest.raises(FigureError):
        Figure(())
    with pytest.raises(FigureError, match="integer"):
        J(1.5, 0, 1)
    with pytest.raises(FigureError):
        Link("a", 0, scale=0.0)


def test_accessors_and_unknown_joint():
    human, _ = build_human()
    assert human.joint_index(10) == 7
    assert human.joint(9).id == 9
    with pytest.raises(FigureError, match="no joint 11") as info:
        human.joint_index(11)
    assert "1, 2, 3, 4, 5, 6, 7, 8, 9, 10" in info.value.hint
    assert human.links_named("nothing") == ()
    assert [j.id for j in human.child_joints_of(human.root)] == [7, 8, 9, 10]
    assert human.extremes.shape == (10, 3, 2)
    loc1, loc2 = human.locations
    assert loc1.shape == loc2.shape == (10, 3)


# ----------------------------------------------------------------- placement


def test_placement_compose_after():
    f = join(1, Link("a", 0), (0, 0, 0), Link("b", 1), (0, 0, 0), FREE)
    np.testing.assert_array_equal(f.placement, np.eye(4))
    A = transform_from(np.eye(3), [1, 0, 0])
    B = transform_from(np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]]), [0, 0, 0])
    g = f.with_placement(A).placed(B)
    np.testing.assert_allclose(g.placement, B @ A)  # B after A: (1,0,0) turned onto (0,1,0)
    np.testing.assert_allclose(g.placement[:3, 3], [0, 1, 0])
    np.testing.assert_allclose(f.with_placement(A).placed(A).placement[:3, 3], [2, 0, 0])
    # FIGURE keeps the placement; it now places the new main link.
    np.testing.assert_array_equal(g.with_main(1).placement, g.placement)
    with pytest.raises(FigureError):
        f.with_placement(np.eye(3))


# ----------------------------------------------------------------- model transformations


def arm() -> Figure:
    forearm = join(1, Link("ulna", 0), (0, -5, 1), Link("palm", 1), (0, 3, 1), [(-90, 0), (-25, 25)])
    return join(2, Link("humerus", 2), (1.0, 5.0, 1.0), forearm, (0.0, 0.5, 1.0), [(0, 135), (0, 180)])


def test_trans_joints_adds_and_accumulates():
    a = arm()
    assert a.trans_joints(10).joint_ids == (12, 11)
    assert signature(a.trans_joints(3).trans_joints(4)) == signature(a.trans_joints(7))
    assert signature(a.trans_joints(5).trans_joints(-5)) == signature(a)
    assert a.joint_ids == (2, 1)


def test_scale_model_scales_locations_and_links():
    a = arm()
    b = a.scale_model(2.0)
    assert [l.scale for l in b.links] == [2.0, 2.0, 2.0]
    np.testing.assert_allclose(b.joint(2).loc1, [2, 10, 2])
    np.testing.assert_array_equal(b.joint(2).extremes, a.joint(2).extremes)
    rng = np.random.default_rng(4)
    angles = rng.uniform(-90, 90, size=(5, 2, 3))
    Xa, Xb = pose_transforms(a, angles), pose_transforms(b, angles)
    np.testing.assert_allclose(Xb[..., :3, :3], Xa[..., :3, :3])  # same orientations
    np.testing.assert_allclose(Xb[..., :3, 3], 2 * Xa[..., :3, 3])  # twice as far apart


def test_scale_model_negative_is_a_mirror_image():
    a = arm()
    m = a.scale_model(-1.0)
    rng = np.random.default_rng(6)
    angles = rng.uniform(-90, 90, size=(5, 2, 3))
    Sa, Sm = shape_transforms(a, angles), shape_transforms(m, angles)
    # Every drawn point p goes to -(its old place): a point reflection, i.e.
    # a mirror image (up to a half turn), with the joints still meeting.
    np.testing.assert_allclose(Sm, np.diag([-1, -1, -1, 1.0]) @ Sa, atol=1e-12)
    assert np.all(np.linalg.det(Sm[..., :3, :3]) < 0)
    assert signature(m.scale_model(-1.0)) == signature(a)


@pytest.mark.parametrize("r", [0, 0.0, float("nan"), float("inf")])
def test_scale_model_rejects_zero_and_non_finite(r):
    with pytest.raises(FigureError, match="SCALE MODEL"):
        arm().scale_model(r)


def test_scale_extremes_multiplies_and_mirrors():
    a = arm()
    np.testing.assert_allclose(a.scale_extremes(2).joint(1).extremes, [[-180, 0], [-50, 50], [0, 0]])
    # (a, b) * -1 == (-b, -a), and each pair stays (min, max).
    np.testing.assert_allclose(a.scale_extremes(-1).joint(2).extremes, [[-135, 0], [-180, 0], [0, 0]])
    np.testing.assert_allclose(a.scale_extremes(-0.5).joint(1).extremes, [[0, 45], [-12.5, 12.5], [0, 0]])
    np.testing.assert_array_equal(a.scale_extremes(0).extremes, np.zeros((2, 3, 2)))
    assert signature(a.scale_extremes(2).scale_extremes(-3)) == signature(a.scale_extremes(-6))
    with pytest.raises(FigureError):
        a.scale_extremes(float("nan"))


def test_transformations_commute():
    a = arm().with_main(1)
    ops = [lambda f: f.trans_joints(10), lambda f: f.scale_model(-1.5), lambda f: f.scale_extremes(0.7)]
    results = []
    for order in itertools.permutations(ops):
        f = a
        for op in order:
            f = op(f)
        results.append(signature(f))
    assert all(r == results[0] for r in results)
    assert results[0] != signature(a)
    # ...and the structure, main link and placement survive them all.
    f = ops[0](ops[1](ops[2](a)))
    assert f.main == 1 and f.root == a.root and [l.name for l in f.links] == [l.name for l in a.links]


# ----------------------------------------------------------------- FIGURE ... MAIN


def test_with_main_link_unique_name_no_warning():
    f, warning = arm().with_main_link("palm")
    assert warning is None and f.links[f.main].name == "palm"
    f, warning = arm().with_main_link("PALM")  # identifiers are case-insensitive
    assert f.links[f.main].name == "palm"


def test_with_main_link_unknown_suggests_closest():
    with pytest.raises(FigureError, match="no link named PLAM") as info:
        arm().with_main_link("PLAM")
    assert "PALM" in info.value.hint and "HUMERUS" not in info.value.hint
    with pytest.raises(FigureError) as info:
        arm().with_main_link("zzzzzz")
    assert "HUMERUS" in info.value.hint and "ULNA" in info.value.hint


def test_with_main_link_repeated_root_name():
    f = join(3, Link("seg", 0), (0, 0, 0), Link("seg", 1), (0, 0, 0), FREE)
    g, warning = f.with_main_link("seg", model_name="chain")
    assert g.main == g.root
    assert "original main link itself" in warning and "FIGURE chain MAIN JOINT 3 to choose another" in warning
    three = join(4, f, (0, 1, 0), Link("seg", 2), (0, 0, 0), FREE)  # seg -3-> seg, seg -4-> seg
    g, warning = three.with_main_link("SEG")
    assert g.main == g.root and "3 links are named SEG" in warning
    assert "MAIN JOINT 3 (or 4) to choose another" in warning


def test_with_main_joint_unknown():
    with pytest.raises(FigureError, match="no joint 99"):
        arm().with_main_joint(99)
    assert arm().with_main_joint(1).links[arm().with_main_joint(1).main].name == "palm"


def test_anonymous_links():
    f = join(1, Link(None, 0), (0, 0, 0), Link("named", 1), (0, 0, 0), FREE)
    assert f.links_named("named") == (1,)
    with pytest.raises(FigureError):
        f.with_main_link("<anonymous>")
    assert "<anonymous>" in f.describe_tree()


# ----------------------------------------------------------------- STARTMODEL


SHAPES = {n: n.lower() for n in ["HUMERUS", "ULNA", "PALM", "LITTLE", "RING", "MIDDLE", "INDEX", "THUMB"]}


def arm_specs() -> list[JointSpec]:
    """The thesis' seven-joint STARTMODEL arm (all segment names unique)."""
    fingers = ["LITTLE", "RING", "MIDDLE", "INDEX", "THUMB"]
    specs = [
        JointSpec(1, "HUMERUS", (0.0, 5.0, 1.0), "ULNA", "ulna", (0.0, 0.5, 1.0), [(0, 35), (0, 180)], 0),
        JointSpec(2, "ULNA", (0.0, -5.0, 1.0), "PALM", "palm", (0.0, 3.0, 1.0), [(-90, 0), (-25, 25)], 1),
    ]
    for k, name in enumerate(fingers):
        specs.append(
            JointSpec(
                3 + k, "PALM", (0.0, -3.0, 1.0 + k), name, name.lower(), (0.0, 1.5, 0.5), [(-90, 45), (-45, 45)], 2 + k
            )
        )
    return specs


def by_name(f: Figure):
    """Order-free description: per link name, its parent joint's data."""
    out = {}
    for i, l in enumerate(f.links):
        j = f.parent_joint_of(i)
        out[l.name] = (
            None
            if j is None
            else (j.id, f.links[j.primary].name, tuple(j.loc1), tuple(j.loc2), tuple(j.extremes.ravel()))
        )
    return out


def test_assemble_arm():
    f, warnings = assemble(arm_specs(), SHAPES)
    assert warnings == []
    assert f.links[f.root].name == "HUMERUS" and f.links[f.root].shape == "humerus"
    assert f.joint_ids == (1, 2, 3, 4, 5, 6, 7)
    assert f.preorder == tuple(range(8))
    assert [j.id for j in f.child_joints_of(f.links_named("PALM")[0])] == [3, 4, 5, 6, 7]


def test_assemble_is_order_independent_with_unique_names():
    reference, _ = assemble(arm_specs(), SHAPES)
    rng = np.random.default_rng(11)
    for _ in range(20):
        specs = arm_specs()
        order = rng.permutation(len(specs))
        f, warnings = assemble([specs[k] for k in order], SHAPES)
        assert warnings == []
        assert by_name(f) == by_name(reference)
        # Same model: same poses per link name for the same angles per joint id.
        angles_by_id = {jid: rng.uniform(-40, 40, size=3) for jid in reference.joint_ids}
        pose = lambda g: pose_transforms(g, np.array([angles_by_id[j] for j in g.joint_ids]))
        P, Q = pose(reference), pose(f)
        for i, l in enumerate(reference.links):
            np.testing.assert_allclose(Q[f.links_named(l.name)[0]], P[i], atol=1e-12)


def test_assemble_with_a_submodel_secondary():
    hand, _ = assemble(arm_specs()[2:], SHAPES)
    specs = [
        JointSpec(2, "ULNA", (0.0, -5.0, 1.0), hand, None, (0.0, 3.0, 1.0), [(-90, 0), (-25, 25)], 0),
        JointSpec(1, "HUMERUS", (0.0, 5.0, 1.0), "ULNA", "ulna", (0.0, 0.5, 1.0), [(0, 35), (0, 180)], 1),
        # A primary inside the submodel counts; THUMB is a secondary in there too.
        JointSpec(9, "THUMB", (0, -1, 0), "NAIL", "nail", (0, 0, 0), [(0, 0)], 2),
    ]
    f, warnings = assemble(specs, SHAPES)
    assert warnings == []
    assert f.links[f.root].name == "HUMERUS"
    assert f.links[f.joint(2).secondary].name == "PALM"  # attached by the submodel's main link
    assert f.links[f.joint(9).primary].name == "THUMB"
    assert f.joint_ids == (1, 2, 3, 4, 5, 6, 7, 9)
    # The submodel's own joints come before the one the block hangs on THUMB.
    assert [j.id for j in f.child_joints_of(f.links_named("PALM")[0])] == [3, 4, 5, 6, 7]


def fingernail_specs(order=(0, 1, 2)):
    specs = [
        JointSpec(1, "palm", (0, -3, 1), "finger", "f1", (0, 1, 0), [(-90, 0)], 0),
        JointSpec(2, "palm", (0, -3, 2), "finger", "f2", (0, 1, 0), [(-90, 0)], 1),
        JointSpec(3, "finger", (0, -1, 0), "fingernail", "nail", (0, 0, 0), [(0, 0)], 2),
    ]
    return [specs[k]._replace(statement_index=i) for i, k in enumerate(order)]


def test_assemble_ambiguous_name_uses_latest_earlier_and_warns():
    f, warnings = assemble(fingernail_specs(), {"palm": "P"})
    nail = f.links_named("fingernail")[0]
    finger = f.joint(3).primary
    assert f.links[finger].shape == "f2"  # JOINT 2's finger, the latest before JOINT 3
    assert f.parent_joint_of(nail).id == 3
    assert len(warnings) == 1
    index, sentence = warnings[0]
    assert index == 2 and "ambiguous" in sentence and "JOINT 2" in sentence and "finger" in sentence
    # Put JOINT 3 between the fingers: the first finger is now the latest before it.
    f, warnings = assemble(fingernail_specs((0, 2, 1)), {"palm": "P"})
    assert f.links[f.joint(3).primary].shape == "f1"
    assert warnings[0][0] == 1 and "JOINT 1" in warnings[0][1]


def test_assemble_ambiguous_name_with_nothing_before_is_an_error():
    with pytest.raises(FigureError, match="none of them is made by an earlier statement") as info:
        assemble(fingernail_specs((2, 0, 1)), {"palm": "P"})
    assert "order" in info.value.hint


def test_assemble_main_name_reused_inside_a_submodel_is_no_main_link():
    # A name made by any statement (here inside a submodel) is a secondary
    # somewhere, so it cannot name the main link.
    specs = [
        JointSpec(1, "seg", (0, 1, 0), "other", "o", (0, 0, 0), FREE, 0),  # seg here is the main link
        JointSpec(2, "other", (0, 1, 0), fig_named("seg"), None, (0, 0, 0), FREE, 1),
        JointSpec(3, "seg", (0, 2, 0), "tip", "t", (0, 0, 0), FREE, 2),
    ]
    with pytest.raises(FigureError, match="every segment is a secondary"):
        assemble(specs, {"seg": "S"})


def fig_named(name: str) -> Figure:
    return Figure.from_link(Link(name, name))


def test_assemble_no_main_link_is_a_cycle():
    specs = [
        JointSpec(1, "a", (0, 0, 0), "b", "B", (0, 0, 0), FREE, 0),
        JointSpec(2, "b", (0, 0, 0), "a", "A", (0, 0, 0), FREE, 1),
    ]
    with pytest.raises(FigureError, match="every segment is a secondary somewhere, so the model has a cycle"):
        assemble(specs, {"a": "A", "b": "B"})


def test_assemble_two_main_links_is_not_one_tree():
    specs = [
        JointSpec(1, "a", (0, 0, 0), "b", "B", (0, 0, 0), FREE, 0),
        JointSpec(2, "c", (0, 0, 0), "d", "D", (0, 0, 0), FREE, 1),
    ]
    with pytest.raises(FigureError, match="not one tree: a, c"):
        assemble(specs, {"a": "A", "c": "C"})


def test_assemble_detached_cycle():
    specs = [
        JointSpec(1, "root", (0, 0, 0), "a", "A", (0, 0, 0), FREE, 0),
        JointSpec(2, "b", (0, 0, 0), "c", "C", (0, 0, 0), FREE, 1),
        JointSpec(3, "c", (0, 0, 0), "b", "B", (0, 0, 0), FREE, 2),
    ]
    with pytest.raises(FigureError, match="cycle: JOINT (2, JOINT 3|3, JOINT 2)"):
        assemble(specs, {"root": "R"})


def test_assemble_primary_inside_its_own_submodel_is_a_cycle():
    hand, _ = assemble(arm_specs()[2:], SHAPES)
    specs = [
        JointSpec(1, "HUMERUS", (0, 0, 0), "ULNA", "u", (0, 0, 0), FREE, 0),
        JointSpec(2, "PALM", (0, 0, 0), hand, None, (0, 0, 0), FREE, 1),
    ]
    with pytest.raises(FigureError, match="JOINT 2 hangs its primary segment PALM from its own secondary"):
        assemble(specs, SHAPES)


def test_assemble_duplicate_ids_and_missing_shapes():
    hand, _ = assemble(arm_specs()[2:], SHAPES)
    specs = [
        JointSpec(1, "HUMERUS", (0, 0, 0), "ULNA", "u", (0, 0, 0), FREE, 0),
        JointSpec(3, "ULNA", (0, 0, 0), hand, None, (0, 0, 0), FREE, 1),
    ]
    with pytest.raises(FigureError, match="joint identifier 3 is used twice"):
        assemble(specs, SHAPES)
    assert assemble([specs[0], specs[1]._replace(secondary=hand.trans_joints(10))], SHAPES)[0].n_joints == 7
    with pytest.raises(FigureError, match="no graphical object named HUMERUS"):
        assemble(specs[:1], {})
    with pytest.raises(FigureError, match="no graphical object named ULNA"):
        assemble([specs[0]._replace(secondary_shape=None)], {"HUMERUS": "h"})
    with pytest.raises(FigureError, match="at least one JOINT"):
        assemble([], {})


def test_assemble_names_are_case_insensitive():
    specs = [
        JointSpec(1, "Bleg", (0, -0.2, 0), "FLEG", "fl", (0, 0.29, 0), [(0, 0)], 0),
        JointSpec(2, "fleg", (0, -0.29, 0), "FOOT", "ft", (0, 0.06, 0), [(0, 0)], 1),
    ]
    f, _ = assemble(specs, {"BLEG": "bl"})
    assert f.links[f.root].shape == "bl" and f.joint_ids == (1, 2)


# ----------------------------------------------------------------- PRINT


def test_describe_tree_lists_node_relationships():
    human, _ = build_human()
    on_foot, _ = human.with_main_link("FOOT")
    text = on_foot.describe_tree("HUMAN")
    lines = text.splitlines()
    assert lines[0].startswith("MODEL HUMAN: 11 links, 10 joints; original main link TORSO")
    assert "current main link FOOT" in lines[0]
    assert "Node 0: TORSO  scale 1  subjoints 4  [original main link]" in text
    # BLEG's upward arc (joint 9, location on BLEG) and its downward arc (joint 3).
    block = text[text.index("Node 5: BLEG") :].splitlines()[:4]
    assert block[2].split()[:3] == ["0", "9", "0"] and block[2].endswith("(0, 0.24, 0)")
    assert block[3].split()[:3] == ["1", "3", "6"] and block[3].endswith("(0, -0.2, 0)")
    assert "[current main link]" in text


def test_describe_table_shows_the_symbol_table():
    a = arm()
    text = a.describe_table(angles=[[0, 0, 90], [10, -5, 0]], velocity=[[1, 2, 3], [0, 0, 0]])
    lines = text.splitlines()
    assert len(lines) == 3
    assert lines[0].split()[:2] == ["Joint", "#"] and "X extremes" in lines[0] and "Current acceleration" in lines[0]
    assert (
        lines[1].startswith("No. 2") and "(0, 0, 90)" in lines[1] and "(0, 135)" in lines[1] and "(1, 2, 3)" in lines[1]
    )
    assert lines[2].startswith("No. 1") and "(10, -5, 0)" in lines[2] and "(-90, 0)" in lines[2]
    zero = a.describe_table()
    assert zero.splitlines()[1].count("(0, 0, 0)") == 3
