"""Prismatic joints (SLIDE) and joints with their own axes (AXIS): kinematics, clamping, SCALE MODEL,
re-rooting, the IK model and the language."""

from __future__ import annotations

import io

import numpy as np
import pytest

from liganimate.runtime.errors import FigureError
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure.tree import Figure, Joint, Link, frame_from_axis
from liganimate.runtime.ik.goals import AxisGoal, GoalStack, PlaneGoal, PointGoal
from liganimate.runtime.ik.model import IKModel
from liganimate.runtime.ik.reach import solve_pose


def random_robot(rng: np.random.Generator, n: int, slides: bool = True) -> Figure:
    """A random tree whose joints mix turns and slides, some with their own axes, any current main link."""
    parents = [int(rng.integers(0, i)) for i in range(1, n)]
    links = [Link(f"R{i}", None, scale=float(rng.choice([1.0, 2.0, -1.5]))) for i in range(n)]
    joints = []
    for i, p in zip(range(1, n), parents):
        slide = slides and rng.random() < 0.4
        axes = frame_from_axis(rng.normal(size=3)) if rng.random() < 0.6 else None
        ext = [(-2.0, 3.0), (-1.0, 1.0), (0.0, 2.0)] if slide else [(-120, 150), (-90, 60), (-170, 170)]
        joints.append(Joint(100 + i, p, i, rng.normal(size=3), rng.normal(size=3), ext, slide=slide, axes=axes))
    return Figure(tuple(links), tuple(joints), main=int(rng.integers(n)))


def random_values(rng: np.random.Generator, fig: Figure, frames: int) -> np.ndarray:
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    return rng.uniform(lo, hi, size=(frames, fig.n_joints, 3))


# ------------------------------------------------------------------ the joint's axes


@pytest.mark.parametrize("seed", range(6))
def test_frame_from_axis_is_a_rotation_taking_x_onto_the_axis(seed):
    a = np.random.default_rng(seed).normal(size=3)
    F = frame_from_axis(a * 3.0)
    np.testing.assert_allclose(F @ F.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(F) == pytest.approx(1.0)
    np.testing.assert_allclose(F[:, 0], a / np.linalg.norm(a), atol=1e-15)


def test_frame_from_axis_of_x_is_identity_and_of_minus_x_a_half_turn():
    np.testing.assert_array_equal(frame_from_axis((2, 0, 0)), np.eye(3))
    np.testing.assert_array_equal(frame_from_axis((-1, 0, 0)), np.diag([-1.0, -1.0, 1.0]))
    with pytest.raises(FigureError, match="zero vector"):
        frame_from_axis((0, 0, 0))


def test_an_axis_turns_the_joint_about_that_direction():
    # AXIS (0, 0, 1): the X angle turns about P's Z axis.
    fig = Figure(
        (Link("A", None), Link("B", None)),
        (Joint(1, 0, 1, (0, 0, 0), (0, 0, 0), [(-180, 180)], axes=frame_from_axis((0, 0, 1))),),
    )
    X = K.pose_transforms(fig, np.array([[[90.0, 0, 0]]]))[0, 1]
    np.testing.assert_allclose(X[:3, :3] @ [1, 0, 0], [0, 1, 0], atol=1e-15)


# ------------------------------------------------------------------ slides


def test_a_slide_moves_the_secondary_along_its_axis():
    fig = Figure(
        (Link("BASE", None), Link("CAR", None)),
        (Joint(1, 0, 1, (1, 0, 0), (0, 0.5, 0), [(0, 3), (0, 0), (-1, 1)], slide=True),),
    )
    X = K.pose_transforms(fig, np.array([[[2.0, 0, -0.5]]]))[0, 1]
    np.testing.assert_array_equal(X[:3, :3], np.eye(3))
    np.testing.assert_allclose(X[:3, 3], [1 + 2.0, -0.5, -0.5])
    # From the carriage, the base slides the other way.
    back = K.pose_transforms(fig.with_main(1), np.array([[[2.0, 0, -0.5]]]))[0, 0]
    np.testing.assert_allclose(back[:3, 3], [-3.0, 0.5, 0.5])


@pytest.mark.parametrize("seed", range(10))
def test_batched_pose_with_slides_and_axes_matches_the_reference(seed):
    rng = np.random.default_rng(seed)
    fig = random_robot(rng, int(rng.integers(2, 12)))
    values = random_values(rng, fig, 5)
    np.testing.assert_allclose(K.pose_transforms(fig, values), K.pose_transforms_reference(fig, values), atol=1e-12)
    # joint_transforms is the forward transform of each joint alone.
    J = K.joint_transforms(fig, values)
    for k, joint in enumerate(fig.joints):
        np.testing.assert_allclose(J[2, k], K._reference_joint(joint, values[2, k]), atol=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_re_rooting_is_one_rigid_motion_with_slides(seed):
    """FIGURE ... MAIN changes what stays still, never the shape: slides reverse as rotations do."""
    rng = np.random.default_rng(seed)
    fig = random_robot(rng, 9)
    values = random_values(rng, fig, 3)
    base = K.pose_transforms(fig.with_main(fig.root), values)
    for main in range(fig.n_links):
        X = K.pose_transforms(fig.with_main(main), values)
        np.testing.assert_allclose(X, np.linalg.inv(base[:, main])[:, None] @ base, atol=1e-9)


@pytest.mark.parametrize("r", [2.5, -0.5])
def test_scale_model_scales_slides_with_the_figure(r):
    rng = np.random.default_rng(7)
    fig = random_robot(rng, 8)
    values = random_values(rng, fig, 4)
    big = fig.scale_model(r)
    S = np.diag([r, r, r, 1.0])
    # The posed figure is r times itself: every point of every link, at every pose.
    np.testing.assert_allclose(K.shape_transforms(big, values), S @ K.shape_transforms(fig, values), atol=1e-9)
    assert all(j.slide_scale == r for j in big.joints)


def test_slides_clip_and_never_wrap():
    fig = Figure(
        (Link("A", None), Link("B", None)),
        (Joint(1, 0, 1, (0, 0, 0), (0, 0, 0), [(-400, 400), (0, 1)], slide=True),),
    )
    out = K.clamp(fig, np.array([[[500.0, -2.0, 3.0]]]))
    np.testing.assert_array_equal(out, [[[400.0, 0.0, 0.0]]])
    assert K.free_axes(fig)[1] == (False, False, False)


# ------------------------------------------------------------------ the IK model


@pytest.mark.parametrize("seed", range(4))
def test_ik_forward_axes_and_one_pose_kinematics_honour_axes(seed):
    from liganimate.runtime.ik import solvers as S

    rng = np.random.default_rng(seed)
    fig = random_robot(rng, 8, slides=False)
    model = IKModel(fig, np.ones((fig.n_joints, 3), dtype=bool), translate=True)
    angles = rng.uniform(-180, 180, size=(3, fig.n_joints, 3))
    R, p = model.forward(np.deg2rad(angles))
    X = K.pose_transforms(fig, angles)
    np.testing.assert_allclose(R, X[..., :3, :3], atol=1e-12)
    np.testing.assert_allclose(p, X[..., :3, 3], atol=1e-12)
    link = lambda: int(rng.integers(fig.n_links))  # noqa: E731
    goals = [
        PointGoal(link(), rng.normal(size=3), point=rng.normal(size=3), weight=2.0),
        PlaneGoal(link(), rng.normal(size=3), rng.normal(size=3), point=rng.normal(size=3)),
        AxisGoal(link(), rng.normal(size=3), rng.normal(size=3), weight=0.7),
    ]
    stack = GoalStack(model, goals, 1)
    base = rng.uniform(-2.5, 2.5, size=(1, fig.n_joints, 3))
    x = np.concatenate([base.reshape(-1)[model.var_flat], rng.normal(size=3)])

    def evaluate(x, jac):
        q, t = x[:, : model.n_vars], x[:, model.n_vars :] * model.length
        a = model.full_angles(q, base)
        R, p = model.forward(a)
        return stack.evaluate(R, p, t, *model.axes(a, R, p)) if jac else stack.evaluate(R, p, t)

    _, Jac, _ = evaluate(x[None], True)
    h = 1e-6
    numeric = np.empty_like(Jac)
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        numeric[0, :, i] = (evaluate((x + e)[None], False)[0] - evaluate((x - e)[None], False)[0])[0] / (2 * h)
    np.testing.assert_allclose(Jac, numeric, atol=1e-7 * max(1.0, np.abs(Jac).max()))
    prob = S._Problem(model, stack, base)
    for a, b in zip(prob.one(x), prob.evaluate(np.zeros(1, dtype=np.intp), stack, x[None])):
        np.testing.assert_allclose(a, b[0], rtol=0, atol=1e-12)


def _crane():
    return Figure(
        (Link("BASE", None), Link("CAR", None), Link("ARM", None)),
        (
            Joint(1, 0, 1, (0, 0, 0), (0, 0, 0), [(0, 3)], slide=True),
            Joint(2, 1, 2, (0, 0, 0), (0, -1, 0), [(-170, 170)], axes=frame_from_axis((0, 0, 1))),
        ),
    )


def test_reach_slides_the_carriage_when_the_arm_alone_cannot_reach():
    """A slider plus a wrist reaches further: the target is 2.3 from the carriage's start."""
    fig = _crane()
    target = np.array([2.5, 0.6, 0.0])
    sol = solve_pose(fig, [PointGoal(2, target, point=(0, 0, 0))], start=np.array([[0.5, 0, 0], [0, 0, 0]]))
    assert sol.converged
    assert 0.0 <= sol.angles[0, 0] <= 3.0 and sol.angles[0, 1] == sol.angles[0, 2] == 0.0
    X = K.pose_transforms(fig, sol.angles[None])[0]
    np.testing.assert_allclose(X[2, :3, 3], target, atol=1e-4)


def test_reach_stops_a_slide_at_the_end_of_its_rail():
    fig = _crane()
    sol = solve_pose(fig, [PointGoal(2, (5.0, 0.0, 0.0), point=(0, 0, 0))], start=np.zeros((2, 3)))
    assert not sol.converged
    assert sol.angles[0, 0] == 3.0  # the end of the rail, and the arm stretched towards the target
    X = K.pose_transforms(fig, sol.angles[None])[0]
    assert X[2, 0, 3] == pytest.approx(4.0, abs=1e-3)


def test_reach_turns_joints_with_axes_and_holds_slides_at_their_start():
    fig = Figure(
        (Link("BASE", None), Link("CAR", None), Link("ARM", None)),
        (
            Joint(1, 0, 1, (0, 0, 0), (0, 0, 0), [(0, 3)], slide=True),
            Joint(2, 1, 2, (0, 0, 0), (0, -1, 0), [(-170, 170)], axes=frame_from_axis((0, 0, 1))),
        ),
    )
    start = np.array([[1.5, 0, 0], [0, 0, 0]])
    target = np.array([1.5 - np.sin(np.radians(30)), np.cos(np.radians(30)), 0.0])
    sol = solve_pose(fig, [PointGoal(2, target, point=(0, 0, 0))], start=start)
    assert sol.converged
    np.testing.assert_array_equal(sol.angles[0], [1.5, 0, 0])
    assert sol.angles[1, 0] == pytest.approx(30.0, abs=1e-3)


# ------------------------------------------------------------------ the language


def _run(text: str):
    from liganimate.compiler import load_program

    program, warnings = load_program(text=text, name="slide.lig")
    rt = program.execute("check")
    return rt.variables, warnings + rt.warnings


CRANE = """\
GRAPHICAL BASE, CAR, ARM
REAL SLIDE, AXIS
MODEL M, N
BASE :- BOX WIDTH 4, HEIGHT 0.2, DEPTH 1
CAR :- BOX WIDTH 0.5, HEIGHT 0.5, DEPTH 0.5
ARM :- BOX WIDTH 0.2, HEIGHT 2, DEPTH 0.2
SLIDE = 3
STARTMODEL M
  JOINT 1, BASE, (-1.5, 0.1, 0), CAR, (0, -0.25, 0), SLIDE (0, SLIDE)
  JOINT 2, CAR, (0, 0.25, 0), ARM, (0, -1, 0), (-90, 90) AXIS (0, 0, 2)
ENDMODEL
N :- JOINT 1, BASE, (0, 0, 0), CAR, (0, 0, 0), SLIDE (0, 1), (0, 2) AXIS (1, 1, 0)
AXIS = 2
"""


def test_slide_and_axis_in_a_model_block_and_a_joint_expression():
    v, warnings = _run(CRANE)
    assert not warnings
    m, n = v["M"], v["N"]
    assert [j.slide for j in m.joints] == [True, False]
    np.testing.assert_array_equal(m.joints[0].extremes, [[0, 3], [0, 0], [0, 0]])
    np.testing.assert_allclose(m.joints[1].axes[:, 0], [0, 0, 1])
    assert n.joints[0].slide
    np.testing.assert_allclose(n.joints[0].axes[:, 0], [2**-0.5, 2**-0.5, 0])
    # SLIDE and AXIS stay ordinary variable names wherever they are not the JOINT's words.
    assert v["AXIS"] == 2.0 and v["SLIDE"] == 3.0


def test_print_table_names_slides_and_axes():
    from liganimate.compiler import load_program

    program, _ = load_program(text=CRANE + "PRINT $M\n", name="slide.lig")
    out = io.StringIO()
    program.execute("check", stdout=out, echo_print=True)
    out = out.getvalue()
    assert "No. 1 SLIDE" in out and "No. 2 AXIS (0, 0, 1)" in out


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("N :- JOINT 1, BASE, (0, 0, 0), CAR, (0, 0, 0), (0, 1) AXIS 3", "an axis"),
        ("N :- JOINT 1, BASE, (0, 0, 0), CAR, (0, 0, 0), (0, 1) AXIS (0, 0, 0)", "zero vector"),
        ("N :- JOINT 1, BASE, (0, 0, 0), CAR, (0, 0, 0), SLIDE (2, 1)", "above the maximum"),
    ],
)
def test_bad_axis_or_slide_is_a_positioned_error(line, message):
    from liganimate.lang.diagnostics import LigDiagnostics

    with pytest.raises(LigDiagnostics) as info:
        _run(CRANE + line + "\n")
    d = info.value.diagnostics[0]
    assert message in d.message and d.pos.line == 14


def test_a_keyframe_beyond_a_slides_extremes_is_refused_at_the_animate():
    from liganimate.lang.diagnostics import LigDiagnostics

    program = CRANE + (
        "MOTION GO\n"
        "STARTMOTION GO\n"
        "  JOINT 1\n"
        "    FRAME 5 POSITION 2, 0, 0\n"
        "    FRAME 10 POSITION 4, 0, 0\n"
        "ENDMOTION\n"
        "INITIALIZE SCENE 1\n"
        "STARTSCENE LENGTH 10\n"
        "  ANIMATE M FROM 0 TO 10 USING GO\n"
        "ENDSCENE\n"
        "SHOOTSCENES\n"
    )
    with pytest.raises(LigDiagnostics) as info:
        _run(program)
    d = info.value.diagnostics[0]
    assert d.pos.line == 22  # the ANIMATE
    assert "joint 1 slides within (0, 3) along X, but the motion puts it at 4 at frame 10" in d.message
    # Within range it runs, and in-betweens that overshoot (none do here) would be clamped.
    v, _ = _run(program.replace("POSITION 4, 0, 0", "POSITION 3, 0, 0"))
    assert "M" in v


def test_a_slide_is_one_more_gene_of_the_studio():
    """The studio's alternatives for a slide are displacements along its rail, coarsest first."""
    from liganimate.runtime.studio import _genes as G

    axes = G.joint_axes(_crane())
    assert axes[0].slide and not axes[1].slide
    first = G.alternatives(axes[0], np.array([0.5, 0.0, 0.0]), "flexion", True, 30.0)
    assert first.axes == (0,)
    assert list(first.values[:3, 0]) == [0.0, 3.0, 1.5] and list(first.level[:3]) == [0, 0, 1]
    assert np.all((first.values >= 0.0) & (first.values <= 3.0))
    later = G.alternatives(axes[0], np.array([0.5, 0.0, 0.0]), "flexion", False, 30.0)
    assert len(later.values) and np.all(np.abs(later.values - 0.5) <= 0.5 + 1e-9)
    assert G.alternatives(axes[0], np.array([0.5, 0.0, 0.0]), "twist", True, 30.0).values.size == 0
