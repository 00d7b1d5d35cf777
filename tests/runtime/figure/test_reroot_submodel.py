"""A submodel re-rooted by FIGURE attaches by its new main link (Cachola's thesis, 3.3 and 3.5).

The thesis gives a submodel's joint location "with respect to the main link
in the submodel", and FIGURE "assigns a new link as the model's main link".
So after ``FIGURE S MAIN LINK C`` a JOINT that takes S as its secondary
attaches it at C, and the joints between C and S's original main link are
walked from their secondaries.  The expected positions here are worked out
by hand, in the plane (every joint turns about Z), not with the runtime's
kinematics.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from liganimate.compiler import load_program
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.ik.goals import PointGoal
from liganimate.runtime.ik.reach import solve_pose

# Indented: a C in the first column would make a comment line.
PLANAR = """\
  GRAPHICAL A, B, C, D
  MODEL S, M, N, Q
  A :- BOX WIDTH 2.0, HEIGHT 0.2, DEPTH 0.2
  B :- BOX WIDTH 0.2, HEIGHT 2.0, DEPTH 0.2
  C :- BOX WIDTH 1.0, HEIGHT 0.2, DEPTH 0.2
  D :- BOX WIDTH 0.2, HEIGHT 1.0, DEPTH 0.2
  S :- JOINT 1, B, (0.0, -1.0, 0.0), C, (0.0, 1.0, 0.0), (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
  S :- JOINT 3, S, (0.0, 1.0, 0.0), D, (0.0, -0.5, 0.0), (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
  FIGURE S MAIN LINK C
  M :- JOINT 2, A, (1.0, 0.0, 0.0), S, (0.5, 0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
  STARTMODEL N
  JOINT 2, A, (1.0, 0.0, 0.0), S, (0.5, 0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
  ENDMODEL
  Q :- M <SCALE MODEL 2.0, TRANS JOINTS BY 10>
"""


def _rot(t: float) -> np.ndarray:
    r = math.radians(t)
    return np.array([[math.cos(r), -math.sin(r)], [math.sin(r), math.cos(r)]])


def by_hand(t1: float, t2: float, t3: float) -> dict:
    """Each link's origin (x, y) and heading (degrees) in M's frame, A at the origin.

    Joint 2 (A to C, at A's (1, 0) and C's (0.5, 0)) is walked forwards; joint 1
    was defined from B to C (B's (0, -1), C's (0, 1)), so from C it is walked
    backwards: B's origin in C is L2 - R^T L1; joint 3 (B to D) forwards again.
    """
    c = np.array([1.0, 0.0]) + _rot(t2) @ np.array([-0.5, 0.0])
    b = c + _rot(t2) @ (np.array([0.0, 1.0]) - _rot(-t1) @ np.array([0.0, -1.0]))
    d = b + _rot(t2 - t1) @ (np.array([0.0, 1.0]) - _rot(t3) @ np.array([0.0, -0.5]))
    return {"A": ((0.0, 0.0), 0.0), "C": (tuple(c), t2), "B": (tuple(b), t2 - t1), "D": (tuple(d), t2 - t1 + t3)}


def _variables(text: str):
    program, warnings = load_program(text=text, name="graft.lig")
    rt = program.execute("check")
    return rt.variables, warnings + rt.warnings


def _check_positions(fig, angles_by_id: dict, scale: float = 1.0, shift: int = 0):
    angles = np.zeros((fig.n_joints, 3))
    for jid, az in angles_by_id.items():
        angles[fig.joint_index(jid + shift), 2] = az
    X = K.pose_transforms(fig, angles[None])[0]
    expected = by_hand(angles_by_id[1], angles_by_id[2], angles_by_id[3])
    for i, link in enumerate(fig.links):
        (x, y), heading = expected[link.name]
        np.testing.assert_allclose(X[i, :3, 3], [scale * x, scale * y, 0.0], atol=1e-12, err_msg=link.name)
        R = np.eye(3)
        R[:2, :2] = _rot(heading)
        np.testing.assert_allclose(X[i, :3, :3], R, atol=1e-12, err_msg=link.name)


@pytest.mark.parametrize("angles", [(0.0, 0.0, 0.0), (30.0, 20.0, -45.0), (-70.0, 85.0, 60.0)])
def test_a_joint_takes_a_re_rooted_submodel_by_its_new_main_link(angles):
    v, warnings = _variables(PLANAR)
    assert not warnings
    t = dict(zip((1, 2, 3), angles))
    for name in ("M", "N"):  # a JOINT expression and a model block agree
        fig = v[name]
        assert fig.links[fig.root].name == "A" and fig.main == fig.root
        j2 = fig.joint(2)
        assert (fig.links[j2.primary].name, fig.links[j2.secondary].name) == ("A", "C")
        # Joint 1 keeps its definition (B primary, C secondary) and is walked from C.
        j1 = fig.joint(1)
        assert (fig.links[j1.primary].name, fig.links[j1.secondary].name) == ("B", "C")
        assert [fig.links[i].name for i in fig.preorder] == ["A", "C", "B", "D"]
        # Joint order: depth first from the root, the submodel's from the link it is held by.
        assert fig.joint_ids == (2, 1, 3) and list(fig.inverted) == [False, True, False]
        _check_positions(fig, t)
    # SCALE MODEL and TRANS JOINTS keep the structure: twice the figure, joints 11, 12, 13.
    _check_positions(v["Q"], t, scale=2.0, shift=10)
    # The operand is a value: S itself is still rooted at B, its FIGURE choice C.
    s = v["S"]
    assert s.links[s.root].name == "B" and s.links[s.main].name == "C"


def test_figure_main_on_the_assembled_model_is_a_rigid_motion_of_it():
    """FIGURE M MAIN LINK D: everything seen from D, the same shape (the thesis' Figures 11 and 12)."""
    v, _ = _variables(PLANAR + "  FIGURE M MAIN LINK D\n  FIGURE N MAIN JOINT 1\n")
    m = v["M"]
    angles = np.zeros((1, m.n_joints, 3))
    angles[0, :, 2] = [25.0, -40.0, 70.0]
    X = K.pose_transforms(m, angles)[0]
    X0 = K.pose_transforms(m.with_original_main(), angles)[0]
    d = m.links.index(next(l for l in m.links if l.name == "D"))
    np.testing.assert_allclose(X[d], np.eye(4), atol=1e-12)
    np.testing.assert_allclose(X, np.linalg.inv(X0[d]) @ X0, atol=1e-12)
    # MAIN JOINT 1 chooses joint 1's (defined) secondary, C.
    n = v["N"]
    assert n.links[n.main].name == "C"


def test_print_shows_the_reversed_arcs():
    program, _ = load_program(text=PLANAR + "  PRINT M\n", name="graft.lig")
    out = io.StringIO()
    program.execute("check", stdout=out, echo_print=True)
    text = out.getvalue()
    assert "original main link A" in text
    # C's row 1 is joint 1 towards B, marked: walked from its secondary.
    assert "1 reversed" in text and "3 reversed" not in text and "2 reversed" not in text


POSE_PROGRAM = (
    PLANAR
    + """\
MOTION GO
STARTMOTION GO
  JOINT 1 POSITION 0.0, 0.0, 0.0
    FRAME 4 POSITION 0.0, 0.0, 40.0
  JOINT 2 POSITION 0.0, 0.0, 0.0
    FRAME 4 POSITION 0.0, 0.0, -20.0
  JOINT 3 POSITION 0.0, 0.0, 0.0
    FRAME 4 POSITION 0.0, 0.0, 80.0
ENDMOTION
INITIALIZE SCENE 1
STARTSCENE LENGTH 5
  ANIMATE M FROM 0 TO 4 USING GO
  M :- M <TRANS (0.5, -1.0, 0.0)>
ENDSCENE
SHOOTSCENES
"""
)


def test_a_motion_drives_the_walked_back_joints_as_they_were_defined(tmp_path):
    """Rendered poses (the --poses record): joint 1's angle turns B the other way from C, as the thesis says."""
    from exchange_support import pose_records

    program, _ = load_program(text=POSE_PROGRAM, name="graft.lig")
    records = pose_records(program, tmp_path)
    last = records[-1]
    assert last["tick"] == 4
    expected = by_hand(40.0, -20.0, 80.0)
    for seg in last["segments"]:
        X = np.array(seg["matrix"]).reshape(4, 4)
        (x, y), heading = expected[seg["link"]]
        np.testing.assert_allclose(X[:3, 3], [x + 0.5, y - 1.0, 0.0], atol=1e-9, err_msg=seg["link"])
        np.testing.assert_allclose(X[:2, :2], _rot(heading), atol=1e-9, err_msg=seg["link"])


def test_reach_moves_the_walked_back_joints_to_a_goal():
    v, _ = _variables(PLANAR)
    m = v["M"]
    d = next(i for i, l in enumerate(m.links) if l.name == "D")
    (x, y), _ = by_hand(35.0, -25.0, 50.0)["D"]
    sol = solve_pose(m, [PointGoal(d, (x, y, 0.0))])
    X = K.pose_transforms(m, np.asarray(sol.angles)[None])[0]
    start = K.pose_transforms(m, np.zeros((1, m.n_joints, 3)))[0]
    assert np.linalg.norm(start[d, :3, 3] - [x, y, 0.0]) > 0.5  # the goal is far from the start
    # Met to the solver's own tolerance (its default stops within about 1e-5 of the goal).
    np.testing.assert_allclose(X[d, :3, 3], [x, y, 0.0], atol=1e-4)


def test_a_thesis_figure_9_chain_of_re_rooted_submodels():
    """d :- JOINT ..., a, ..., b, .. with b re-rooted twice over: a re-rooted model inside a re-rooted model."""
    text = PLANAR + (
        "  MODEL W\n"
        "  FIGURE M MAIN LINK D\n"
        "  W :- JOINT 7, A, (-1.0, 0.0, 0.0), M, (0.0, 0.5, 0.0), (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)\n"
    )
    v, _ = _variables(text)
    w = v["W"]
    assert [w.links[i].name for i in w.preorder] == ["A", "D", "B", "C", "A"]
    angles = np.zeros((1, w.n_joints, 3))
    t = {1: 30.0, 2: 20.0, 3: -45.0, 7: 15.0}
    for jid, az in t.items():
        angles[0, w.joint_index(jid), 2] = az
    X = K.pose_transforms(w, angles)[0]
    # W is M seen from D, hung from the outer A by D's (0, 0.5): each of M's links is where
    # M's own pose puts it relative to D.
    m = v["M"].with_original_main()
    am = np.zeros((1, m.n_joints, 3))
    for jid in (1, 2, 3):
        am[0, m.joint_index(jid), 2] = t[jid]
    XM = K.pose_transforms(m, am)[0]
    dm = next(i for i, l in enumerate(m.links) if l.name == "D")
    Dw = X[w.preorder[1]]
    # D sits where joint 7 puts it: A's (-1, 0) meets D's (0, 0.5) turned by 15 degrees.
    np.testing.assert_allclose(Dw[:2, 3], np.array([-1.0, 0.0]) - _rot(15.0) @ np.array([0.0, 0.5]), atol=1e-12)
    for k, name in zip(w.preorder[1:], ["D", "B", "C", "A"]):
        i = next(i for i, l in enumerate(m.links) if l.name == name)
        np.testing.assert_allclose(X[k], Dw @ np.linalg.inv(XM[dm]) @ XM[i], atol=1e-12, err_msg=name)


def test_figure_main_link_with_a_repeated_name_says_when_no_main_joint_chooses_the_other():
    """W holds two A: the root, and M's old main link, which no joint has as its secondary."""
    text = PLANAR + (
        "  MODEL W\n"
        "  FIGURE M MAIN LINK D\n"
        "  W :- JOINT 7, A, (-1.0, 0.0, 0.0), M, (0.0, 0.5, 0.0), (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)\n"
    )
    w = _variables(text)[0]["W"]
    chosen, warning = w.with_main_link("A", model_name="W")
    assert chosen.main == chosen.root
    assert warning is not None and "2 links are named A" in warning
    assert "no FIGURE MAIN JOINT chooses the others" in warning
    # D is joint 3's secondary and joint 7's: MAIN JOINT 3 and MAIN JOINT 7 both choose it.
    assert w.with_main_joint(3).main == w.with_main_joint(7).main == w.preorder[1]


@pytest.mark.parametrize("frames", [1, 40, 3000])
def test_every_batch_length_gives_the_hand_worked_positions(frames):
    """Short and long batches take different paths (short.py, folded.py): both by hand."""
    m = _variables(PLANAR)[0]["M"]
    rng = np.random.default_rng(frames)
    t = rng.uniform(-90.0, 90.0, size=(frames, 3))  # joints 1, 2, 3
    angles = np.zeros((frames, m.n_joints, 3))
    for c, jid in enumerate((1, 2, 3)):
        angles[:, m.joint_index(jid), 2] = t[:, c]
    X = K.pose_transforms(m, angles)
    for f in {0, frames // 2, frames - 1}:
        expected = by_hand(*t[f])
        for i, link in enumerate(m.links):
            (x, y), heading = expected[link.name]
            np.testing.assert_allclose(X[f, i, :2, 3], [x, y], atol=1e-12, err_msg=f"{f} {link.name}")
            np.testing.assert_allclose(X[f, i, :2, :2], _rot(heading), atol=1e-12, err_msg=f"{f} {link.name}")
