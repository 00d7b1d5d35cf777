"""The thesis' fragments (examples/thesis_fragments.lig) and the reversed squat
(examples/reversed_squat.lig): they compile, pass every runtime check, render,
and compute what chapters 3 to 5 say they compute."""

from __future__ import annotations

import os

import numpy as np
import pytest
from paths import ROOT_DIR

from liganimate.compiler import load_program
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.pose import joint_angles

ROOT = ROOT_DIR
FRAGMENTS = os.path.join(ROOT, "examples", "thesis_fragments.lig")
SQUAT = os.path.join(ROOT, "examples", "reversed_squat.lig")


def program_from_text(text: str, name: str):
    """What load_program does, from text."""
    return load_program(text=text, name=name)


@pytest.fixture(scope="module")
def fragments():
    program, warnings = load_program(FRAGMENTS)
    assert warnings == []
    runtime_warnings = program.check()
    rt = program.execute("check")
    # A motion written keyframe by keyframe (ma[j, k] := FRAME ...) is held as
    # a chain of edits until it is first used; resolve those into motions.
    variables = {
        name: rt._motion(value, 0) if type(value).__name__ == "KeyframeEdits" else value
        for name, value in rt.variables.items()
    }
    return program, runtime_warnings, variables


@pytest.fixture(scope="module")
def squat():
    program, warnings = load_program(SQUAT)
    assert warnings == []
    assert program.check() == []
    return program.execute("check").variables


def at(motion, t):
    return motion.evaluate(np.atleast_1d(np.asarray(t, dtype=float)))


# ------------------------------------------------------------ compile and check


def test_fragments_compile_and_check(fragments):
    _, warnings, variables = fragments
    # The only warning is the one the thesis asks for: the ambiguous hand of
    # section 3.4 (two segments named FINGER).
    assert len(warnings) == 1
    assert "FINGER" in warnings[0].message and "ambiguous" in warnings[0].message
    with open(FRAGMENTS, encoding="utf-8") as fh:
        line = fh.read().split("\n")[warnings[0].pos.line - 1]
    assert line.strip().startswith("JOINT 3, finger")
    for name in ("FIG1A", "FIG1B", "FIG3", "A", "B", "C", "D", "ARM", "HAND", "ROBOT", "NEW_WALK", "MY_WALK", "MB"):
        assert variables[name] is not None, name


def test_reversed_squat_compiles_and_checks_without_warnings():
    program, warnings = load_program(SQUAT)
    assert warnings == []
    assert program.check() == []


def test_the_fragments_print(fragments):
    import io

    program, _, _ = fragments
    out = io.StringIO()
    program.execute("render", stdout=out)
    text = out.getvalue()
    assert "MODEL D" in text  # PRINT d: the node relationships
    assert "Joint #" in text and "X extremes" in text  # PRINT $b: the symbol table
    assert "MOTION HOP" in text and "FRAME 4 POSITION 0, 0, 40" in text  # PRINT hop


# --------------------------------------------------------------------- chapter 3


def centre(fig, angles, link_name):
    """The origin of the (single) link called link_name, main link at the origin."""
    X = K.pose_transforms(fig, np.asarray(angles, dtype=float).reshape(1, fig.n_joints, 3))[0]
    (index,) = fig.links_named(link_name)
    return X[index, :3, 3]


def test_figure_1_joints_trade_shapes_at_plus_and_minus_90(fragments):
    """Section 3.1: both images of Figure 1 come from either joint at +90 or -90 degrees."""
    v = fragments[2]
    a, b = v["FIG1A"], v["FIG1B"]
    np.testing.assert_allclose(centre(a, [[0, 0, 0]], "OBJECT2"), [0, -4, 0], atol=1e-9)
    np.testing.assert_allclose(centre(b, [[0, 0, 0]], "OBJECT4"), [2, -2, 0], atol=1e-9)
    np.testing.assert_allclose(centre(a, [[0, 0, 90]], "OBJECT2"), centre(b, [[0, 0, 0]], "OBJECT4"), atol=1e-9)
    np.testing.assert_allclose(centre(b, [[0, 0, -90]], "OBJECT4"), centre(a, [[0, 0, 0]], "OBJECT2"), atol=1e-9)


def test_figure_3_joint_has_one_degree_of_freedom(fragments):
    fig = fragments[2]["FIG3"]
    np.testing.assert_array_equal(fig.extremes, [[[0, 0], [0, 0], [0, 135]]])


def test_submodels_are_copied_and_ids_translated(fragments):
    v = fragments[2]
    # d :- JOINT 4, a, .., b <TRANS JOINTS BY 10>, ..: a's joint, the new one, b's moved by ten.
    assert v["D"].joint_ids == (1, 4, 12, 11)
    # Model addition put b's copies (ids moved by 100 and 200) into a.
    ids = set(v["C"].joint_ids)
    assert {6, 41, 44, 52, 51}.issubset(ids)


def test_arm_with_trans_joints(fragments):
    v = fragments[2]
    assert v["FOREARM"].joint_ids == (1,)
    # arm := JOINT 2, humerus, .., forearm <TRANS JOINTS BY 10>, ..
    assert v["ELBOW_ARM"].joint_ids == (2, 11)
    assert [l.name for l in v["ELBOW_ARM"].links] == ["HUMERUS", "ULNA", "PALM"]


def test_both_startmodel_arms_are_the_same_model(fragments):
    v = fragments[2]
    seven, two = v["ARM7"], v["ARM2"]
    assert sorted(seven.joint_ids) == sorted(two.joint_ids) == [1, 2, 3, 4, 5, 6, 7]
    assert sorted(l.name for l in seven.links) == sorted(l.name for l in two.links)
    for j in range(1, 8):
        a, b = seven.joint(j), two.joint(j)
        assert seven.links[a.primary].name == two.links[b.primary].name
        assert seven.links[a.secondary].name == two.links[b.secondary].name
        np.testing.assert_array_equal(a.extremes, b.extremes)
    assert seven.links[seven.root].name == two.links[two.root].name == "HUMERUS"


def test_model_transformations(fragments):
    v = fragments[2]
    robot, a, b, b10 = v["ROBOT"], v["A"], v["B"], v["B10"]
    assert b10.joint_ids == tuple(j + 10 for j in robot.joint_ids)
    assert sorted(robot.joint_ids) == list(range(1, 9))
    # a :- a <SCALE MODEL 2.0>, then b :- a <SCALE MODEL 1.5, SCALE EXTREME 0.7>.
    np.testing.assert_allclose(a.link_scales, 2.0 * np.ones(robot.n_links))
    np.testing.assert_allclose(b.link_scales, 1.5 * a.link_scales)
    np.testing.assert_allclose(a.extremes, robot.extremes)
    np.testing.assert_allclose(b.extremes, 0.7 * a.extremes)
    assert b.joint_ids == a.joint_ids


def test_figure_main(fragments):
    v = fragments[2]
    a, b = v["A"], v["B"]
    # FIGURE b MAIN LINK chest; FIGURE a MAIN JOINT 7, then FIGURE a MAIN.
    assert b.links[b.main].name == "CHEST"
    assert a.main == a.root


# --------------------------------------------------------------------- chapter 4


def test_motion_algebra_lengths(fragments):
    v = fragments[2]
    hop, skip, jump = v["HOP"], v["SKIP"], v["JUMP"]
    assert (hop.length, skip.length, jump.length) == (8, 8, 12)
    assert v["WALK10"].length == 10 * (hop.length + skip.length + jump.length)
    assert v["NEW_WALK"].length == 3 * (hop.length + skip.length)
    # Repetition binds tighter than addition: n * hop + skip with n = 2.
    assert v["N"] == 2
    assert v["MOTION1"].length == 2 * hop.length + skip.length


def test_repetition_equals_repeated_addition(fragments):
    """(hop + skip) + (hop + skip) + (hop + skip) and 3 * (hop + skip) are the same motion."""
    v = fragments[2]
    added, repeated = v["WALK3"], v["NEW_WALK"]
    assert added.joints == repeated.joints
    t = np.linspace(0, repeated.length, 97)
    np.testing.assert_allclose(added.evaluate(t), repeated.evaluate(t), atol=1e-9)
    # and the second hop starts where the first one did
    np.testing.assert_allclose(at(repeated, 16 + 4), at(v["HOP"], 4), atol=1e-9)


def test_strip_and_synchronize(fragments):
    v = fragments[2]
    assert v["WALK"].joints == (1, 2, 3, 4, 5, 6, 7, 8)
    assert v["WALKING_LEGS"].joints == (5, 6, 7, 8)
    assert v["MY_WALK"].joints == (1, 2, 5, 6, 7, 8)
    t = np.linspace(0, 16, 33)
    legs = v["MY_WALK"].evaluate(t, joints=(5, 6, 7, 8))
    np.testing.assert_allclose(legs, v["WALK"].evaluate(t, joints=(5, 6, 7, 8)), atol=1e-9)
    arms = v["MY_WALK"].evaluate(t, joints=(1, 2))
    np.testing.assert_allclose(arms, v["SWINGING_ARMS"].evaluate(t), atol=1e-9)


def test_explicit_keyframes_in_a_loop(fragments):
    ma = fragments[2]["MA"]
    assert ma.joints == (1,)
    assert ma.length == 18
    for k in (1, 2, 3):
        np.testing.assert_allclose(at(ma, 6 * k)[0, 0], [0, 0, 30 * k], atol=1e-9)


def test_scale_frames_minus_two_doubles_and_reverses(fragments):
    v = fragments[2]
    ma, reversed_ = v["MA"], v["REVERSED"]
    assert reversed_.length == 2 * ma.length
    for t in (0.0, 3.0, 6.0, 13.5, 18.0):
        np.testing.assert_allclose(at(reversed_, 2 * t), at(ma, ma.length - t), atol=1e-9)


def test_scale_extremes_halves_the_angles(fragments):
    v = fragments[2]
    ma, mb = v["MA"], v["MB"]
    assert mb.length == ma.length
    t = np.linspace(0, ma.length, 37)
    np.testing.assert_allclose(mb.evaluate(t), 0.5 * ma.evaluate(t), atol=1e-9)


# --------------------------------------------------------------------- the squat


def test_squat_there_and_back(squat):
    squat_, both = squat["SQUAT"], squat["SQUAT_UP_DOWN"]
    assert squat_.length == 5
    assert both.length == 10
    for t in (0.0, 1.0, 2.5, 4.0, 5.0):
        np.testing.assert_allclose(at(both, t), at(both, 10 - t), atol=1e-9)
    np.testing.assert_allclose(at(both, 5), at(squat_, 5), atol=1e-9)


def _link_y(fig, motion, t, name, which=0):
    angles = joint_angles(fig, motion, np.array([float(t)]))
    X = K.pose_transforms(fig, angles)[0]
    return X[fig.links_named(name)[which], 1, 3]


def test_foot_rooted_squat_lowers_the_torso_and_torso_rooted_one_raises_the_feet(squat):
    """Figures 11 and 12: what stays still depends on the main link."""
    human, motion = squat["HUMAN"], squat["SQUAT_UP_DOWN"]
    assert human.main == human.root  # after FIGURE HUMAN MAIN
    on_foot = human.with_main_joint(4)
    assert on_foot.links[on_foot.main].name == "FOOT"
    torso = [_link_y(on_foot, motion, t, "TORSO") for t in (0, 5, 10)]
    assert torso[1] < torso[0] - 0.3
    assert torso[2] == pytest.approx(torso[0])
    foot = [_link_y(human, motion, t, "FOOT") for t in (0, 5, 10)]
    assert foot[1] > foot[0] + 0.3
    assert foot[2] == pytest.approx(foot[0])


# ---------------------------------------------------------------------- rendering


def _dark_pixels(path):
    from PIL import Image

    image = np.asarray(Image.open(path).convert("L"))
    return image, image < 128


def test_reversed_squat_renders_two_scenes(tmp_path):
    program, _ = load_program(SQUAT)
    # The thesis look: dark pixels are the figures alone (no contact shadow under them).
    program.render(str(tmp_path), size=(220, 100), quiet=True, look="thesis")
    one, two = tmp_path / "scene1" / "00000.png", tmp_path / "scene2" / "00000.png"
    assert sorted(p.name for p in (tmp_path / "scene1").iterdir()) == ["00000.png"]
    image1, dark1 = _dark_pixels(one)
    image2, dark2 = _dark_pixels(two)
    assert dark1.sum() > 500 and dark2.sum() > 500
    # The first and last stages are the neutral pose in both scenes, and the
    # middle stage differs: in scene 2 the feet are lifted off the ground.
    w = image1.shape[1]
    ys1 = np.nonzero(dark1[:, w // 2 - 8 : w // 2 + 8].any(axis=1))[0]
    ys2 = np.nonzero(dark2[:, w // 2 - 8 : w // 2 + 8].any(axis=1))[0]
    assert ys2.max() < ys1.max() - 2


def test_fragments_render(tmp_path):
    program, _ = load_program(FRAGMENTS)
    program.render(str(tmp_path), size=(64, 48), quiet=True)
    assert len(list((tmp_path / "scene1").iterdir())) == 60
    assert len(list((tmp_path / "scene2").iterdir())) == 24
    image, dark = _dark_pixels(tmp_path / "scene2" / "00023.png")
    assert dark.sum() > 50


# ------------------------------------------------------- thesis statements as written


def test_stop_keeps_the_final_variables():
    """Program.execute documents that ``variables`` hold the program's final values;
    a program that ends with STOP (Appendix A, the reversed squat) must keep them."""
    program, _ = load_program(SQUAT)
    variables = program.execute("check").variables
    assert "SQUAT_UP_DOWN" in variables


def test_motion_is_a_usable_variable_name():
    """Section 4.3 writes ``motion = 10 * hop + skip``: a variable called motion."""
    program, _ = program_from_text(
        "      STARTMOTION hop\n"
        "        JOINT 1\n"
        "          FRAME 4 POSITION 0.0, 0.0, 40.0 INTERPOLATE ACCDCC\n"
        "        ENDJOINT\n"
        "      ENDMOTION\n"
        "      skip = hop <SCALE FRAMES 2.0>\n"
        "      motion = 10 * hop + skip\n",
        "motion.lig",
    )
    variables = program.execute("check").variables
    assert variables["MOTION"].length == 10 * 4 + 8
