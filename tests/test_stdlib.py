"""The standard library (stdlib/*.lig): what it offers and whether it is right.

Every library loads on its own and all of them together; every offered name
has a description; the humanoid matches the table of the posing thesis (19
limbs, 30 degrees of freedom, 561 units, its joint ranges, left mirroring
right); every library motion stays within the joint limits of the model it
is made for at every frame, so no clamping is needed; cyclic motions end
where they start and the others start and end standing; the shapes are
closed solids of the right size; and every program in docs/tutorial.md
compiles and runs.
"""

from __future__ import annotations

import functools
import math
import pathlib
import re

import numpy as np
import pytest

from liganimate.compiler import library, load_program
from liganimate.runtime.figure import kinematics as K
from liganimate.runtime.figure import pose as P

ROOT = pathlib.Path(__file__).resolve().parent.parent
STDLIB = ROOT / "stdlib"
TUTORIAL = ROOT / "docs" / "tutorial.md"

#: The libraries, each with its models and, per model, the motions made for it.
MADE_FOR = {
    "humanoid": {"HUMANOID": ["WALK", "RUN", "HOP", "SKIP", "JUMP", "SQUAT", "WAVE", "REACH", "SIT"]},
    "human": {"HUMAN": ["HUMAN_SQUAT"]},
    "robot": {"ROBOT": ["ROBOT_SQUAT", "ROBOT_WALK"]},
    "arm": {"ARM": ["GRASP", "POINT"]},
    "clock": {"CLOCK": ["CLOCK_TIME"]},
    "shapes": {},
}
#: Cycles: the last pose is the first, so REPEAT and n * m loop smoothly.
CYCLIC = {"WALK", "RUN", "ROBOT_WALK", "CLOCK_TIME"}
#: Start and end standing in the neutral pose, so any may follow any other.
FROM_NEUTRAL = {"HOP", "SKIP", "JUMP", "SQUAT", "WAVE", "REACH", "ROBOT_SQUAT", "GRASP", "POINT"}
#: Motions that are neither (the thesis' own squat goes down only).
ONE_WAY = {"HUMAN_SQUAT", "SIT"}

ALL_MOTIONS = [(lib, model, m) for lib, models in MADE_FOR.items() for model, ms in models.items() for m in ms]

#: The humanoid of seed 001 (../shared/notes/humanoid-seed001.md): per joint
#: id, the limb it moves, its parent limb and its limb vector in the thesis'
#: units, in liganimate's frame (facing +X, right side towards +Z).
HUMANOID_LIMBS = {
    30: ("R_HIP", "TOP", (0, 0, 16)),
    31: ("R_THIGH", "R_HIP", (0, -45, 0)),
    32: ("R_SHIN", "R_THIGH", (0, -55, 0)),
    33: ("R_FOOT", "R_SHIN", (30, 0, 0)),
    40: ("L_HIP", "TOP", (0, 0, -16)),
    41: ("L_THIGH", "L_HIP", (0, -45, 0)),
    42: ("L_SHIN", "L_THIGH", (0, -55, 0)),
    43: ("L_FOOT", "L_SHIN", (30, 0, 0)),
    1: ("SPINE", "TOP", (0, 50, 0)),
    10: ("R_SHOULDER", "SPINE", (0, 0, 25)),
    11: ("R_UPPERARM", "R_SHOULDER", (0, -33, 0)),
    12: ("R_FOREARM", "R_UPPERARM", (0, -25, 0)),
    13: ("R_HAND", "R_FOREARM", (0, -12, 0)),
    20: ("L_SHOULDER", "SPINE", (0, 0, -25)),
    21: ("L_UPPERARM", "L_SHOULDER", (0, -33, 0)),
    22: ("L_FOREARM", "L_UPPERARM", (0, -25, 0)),
    23: ("L_HAND", "L_FOREARM", (0, -12, 0)),
    2: ("NECK", "SPINE", (0, 17, 0)),
    3: ("HEAD", "NECK", (0, 12, 0)),
}
#: Metres per unit of the thesis' table.
HUMANOID_UNIT = 0.009
L0 = (0, 0)
#: The thesis' ranges on liganimate's axes: X pivot, Y twist, Z flexion.
HUMANOID_EXTREMES = {
    1: [(-50, 50), (-45, 45), (-70, 45)],
    2: [(-45, 45), (-90, 90), (-45, 20)],
    3: [L0, L0, L0],
    10: [L0, L0, L0],
    11: [(-180, 0), (-90, 90), (-60, 80)],
    12: [L0, L0, (0, 160)],
    13: [(-70, 70), L0, (-45, 45)],
    30: [L0, L0, L0],
    31: [(-80, 0), (-90, 90), (-20, 160)],
    32: [L0, L0, (-160, 0)],
    33: [L0, (-30, 30), (-20, 20)],
}


def _mirror(ext):
    """The left side's ranges from the right's: X and Y turn the other way, Z does not."""
    (x0, x1), (y0, y1), z = ext
    return [(-x1, -x0), (-y1, -y0), z]


for _right, _left in ((10, 20), (11, 21), (12, 22), (13, 23), (30, 40), (31, 41), (32, 42), (33, 43)):
    HUMANOID_EXTREMES[_left] = _mirror(HUMANOID_EXTREMES[_right])


@functools.cache
def values(program_text: str) -> dict:
    """The variables of a small program (compiled in a folder of its own)."""
    import tempfile

    folder = pathlib.Path(tempfile.mkdtemp(prefix="stdlib-test-"))
    path = folder / "prog.lig"
    path.write_text(program_text)
    program, warnings = load_program(str(path))
    rt = program.execute("check")
    return {"variables": rt.variables, "warnings": list(warnings) + list(rt.warnings)}


def lib_values(name: str) -> dict:
    return values(f"LOAD '{name}'\n")["variables"]


def library_of(name: str):
    return library.load(name, library.resolve(name, str(ROOT / "prog.lig")))


# ------------------------------------------------------------- loading


def test_the_standard_library_is_what_this_test_knows():
    assert sorted(library.stdlib_names()) == sorted(MADE_FOR)


@pytest.mark.parametrize("name", sorted(MADE_FOR))
def test_every_library_loads_quietly_and_describes_every_name(name):
    lib = library_of(name)
    assert not lib.scenes
    assert lib.warnings == []
    offered = lib.default_names()
    assert offered
    missing = [n for n in offered if not lib.descriptions.get(n)]
    assert missing == [], f"{name}: no {{@ NAME: description }} for {missing}"
    # Descriptions are one line and name only what the library offers.
    assert set(lib.descriptions) <= set(offered)
    result = values(f"LOAD '{name}'\n")
    assert result["warnings"] == []
    for model, motions in MADE_FOR[name].items():
        assert lib.kind_of(model) == "MODEL"
        for m in motions:
            assert lib.kind_of(m) == "MOTION"
            assert result["variables"][m].length > 0


def test_all_libraries_load_together_without_a_clash():
    text = "".join(f"LOAD '{name}'\n" for name in sorted(MADE_FOR))
    v = values(text)["variables"]
    for models in MADE_FOR.values():
        for model, motions in models.items():
            assert v[model].n_joints > 0
            for m in motions:
                assert v[m].length > 0


def test_named_loads_bring_only_the_names():
    v = values(
        "LOAD HUMANOID, WALK, WAVE FROM 'humanoid'\nLOAD CYLINDER FROM 'shapes'\n"
        "POLE :- CYLINDER RADIUS 0.05, HEIGHT 2.0\n"
    )["variables"]
    assert {"HUMANOID", "WALK", "WAVE", "POLE"} <= set(v)
    assert "RUN" not in v and "R_THIGH" not in v


# ------------------------------------------------------------- the humanoid


@pytest.fixture(scope="module")
def humanoid():
    return lib_values("humanoid")["HUMANOID"]


def test_humanoid_has_19_limbs_and_30_degrees_of_freedom(humanoid):
    fig = humanoid
    assert fig.n_joints == 19
    assert fig.n_links == 20  # the 19 limbs and the zero-length root, TOP
    assert fig.links[fig.root].name == "TOP"
    ext = fig.extremes
    free = int(np.count_nonzero(ext[..., 1] > ext[..., 0]))
    assert free == 30


def test_humanoid_joint_ids_links_and_extremes_follow_the_table(humanoid):
    fig = humanoid
    assert sorted(fig.joint_ids) == sorted(HUMANOID_LIMBS)
    for jid, (limb, parent, _) in HUMANOID_LIMBS.items():
        j = fig.joint(jid)
        assert fig.links[j.secondary].name == limb, jid
        assert fig.links[j.primary].name == parent, jid
        np.testing.assert_array_equal(j.extremes, np.array(HUMANOID_EXTREMES[jid], dtype=float), err_msg=str(jid))


def test_humanoid_limb_lengths_add_up_to_561_units(humanoid):
    fig = humanoid
    table = {limb: np.array(vec, dtype=float) for limb, _, vec in HUMANOID_LIMBS.values()}
    assert sum(np.linalg.norm(v) for v in table.values()) == pytest.approx(561.0)
    # Every joint sits at the end of its parent limb, at the limb's own origin.
    by_name = {fig.links[j.secondary].name: j for j in fig.joints}
    leaves = set(table)
    for j in fig.joints:
        np.testing.assert_allclose(j.loc2, 0.0, atol=1e-12)
        parent = fig.links[j.primary].name
        if parent == "TOP":
            np.testing.assert_allclose(j.loc1, 0.0, atol=1e-12)
            continue
        leaves.discard(parent)
        np.testing.assert_allclose(j.loc1, HUMANOID_UNIT * table[parent], atol=1e-12, err_msg=parent)
    # The limbs at the ends of the tree (feet, hands, head) reach their length:
    # the end of the limb vector lies on the drawn segment's bounding box.
    assert leaves == {"R_FOOT", "L_FOOT", "R_HAND", "L_HAND", "HEAD"}
    for name in leaves:
        link = fig.links[fig.joint(by_name[name].id).secondary]
        pts = link.shape.triangles.reshape(-1, 3) * link.scale
        end = HUMANOID_UNIT * table[name]
        assert np.all(pts.min(axis=0) <= end + 1e-12) and np.all(end <= pts.max(axis=0) + 1e-12), name
    total = sum(np.linalg.norm(v) for v in table.values()) * HUMANOID_UNIT
    assert total == pytest.approx(5.049)


def test_humanoid_stands_upright_on_level_feet(humanoid):
    fig = humanoid
    tris, _, _ = P.static_triangles(fig)
    pts = tris.reshape(-1, 3)
    assert pts[:, 1].min() == pytest.approx(-0.972)  # the soles, below the pelvis at the origin
    assert pts[:, 1].max() - pts[:, 1].min() == pytest.approx(1.782)  # 1.78 m tall
    table = P.mesh_table(fig)
    X = P.world_transforms(fig, np.zeros((1, fig.n_joints, 3)), np.eye(4)[None])
    world = P.world_triangles(table, X)[0]
    names = [l.name for l in fig.links]

    def part(name):
        return world[table.link == names.index(name)].reshape(-1, 3)

    # Both soles flat at one height; the head on top, above the shoulders.
    for foot in ("R_FOOT", "L_FOOT"):
        assert part(foot)[:, 1].min() == pytest.approx(-0.972)
    assert part("HEAD")[:, 1].max() == pytest.approx(pts[:, 1].max())
    # Upright: every part within a foot's length of the vertical through the pelvis.
    assert np.abs(pts[:, 0]).max() < 0.3
    # The hands hang at the sides, between the hips and the knees.
    for hand in ("R_HAND", "L_HAND"):
        y = part(hand)[:, 1]
        assert -0.5 < y.min() < y.max() < 0.0


def test_humanoid_left_side_mirrors_the_right(humanoid):
    fig = humanoid
    table = P.mesh_table(fig)
    X = P.world_transforms(fig, np.zeros((1, fig.n_joints, 3)), np.eye(4)[None])
    world = P.world_triangles(table, X)[0]
    names = [l.name for l in fig.links]
    for right in ("R_HIP", "R_THIGH", "R_SHIN", "R_FOOT", "R_SHOULDER", "R_UPPERARM", "R_FOREARM", "R_HAND"):
        left = "L" + right[1:]
        r = world[table.link == names.index(right)].reshape(-1, 3) * (1.0, 1.0, -1.0)
        l = world[table.link == names.index(left)].reshape(-1, 3)
        np.testing.assert_allclose(
            np.unique(r.round(9), axis=0), np.unique(l.round(9), axis=0), atol=1e-9, err_msg=right
        )


# ------------------------------------------------------------- motions


def _sample_times(length: float) -> np.ndarray:
    # Every frame and the quarters between them.
    return np.arange(0.0, length + 0.125, 0.25)


@pytest.mark.parametrize("lib,model,motion", ALL_MOTIONS, ids=[m for _, _, m in ALL_MOTIONS])
def test_motion_stays_within_its_models_limits(lib, model, motion):
    v = lib_values(lib)
    fig, m = v[model], v[motion]
    assert set(m.joints) <= set(fig.joint_ids), f"{motion} drives joints {model} lacks"
    times = _sample_times(m.length)
    angles = m.evaluate(times, m.joints)  # unclamped, as written
    free = K.free_axes(fig)
    for k, jid in enumerate(m.joints):
        ext = fig.joint(jid).extremes
        for axis in range(3):
            if free[jid][axis]:
                continue  # a full turn: every angle is allowed
            a = angles[:, k, axis]
            lo, hi = ext[axis]
            assert lo - 1e-9 <= a.min() and a.max() <= hi + 1e-9, (
                f"{motion} takes joint {jid} {'XYZ'[axis]} to [{a.min():g}, {a.max():g}], "
                f"outside {model}'s ({lo:g}, {hi:g})"
            )
    # So posing the model changes nothing: the clamped angles are the written ones.
    clamped = P.joint_angles(fig, m, times)
    cols = [fig.joint_index(j) for j in m.joints]
    fixed = [k for k, j in enumerate(m.joints) if not any(free[j])]
    np.testing.assert_allclose(clamped[:, [cols[k] for k in fixed]], angles[:, fixed], atol=1e-9)


@pytest.mark.parametrize("lib,model,motion", ALL_MOTIONS, ids=[m for _, _, m in ALL_MOTIONS])
def test_motion_ends_where_it_should(lib, model, motion):
    v = lib_values(lib)
    fig, m = v[model], v[motion]
    assert motion in CYCLIC | FROM_NEUTRAL | ONE_WAY
    first = m.evaluate([0.0])[0]
    last = m.evaluate([m.length])[0]
    if motion in CYCLIC:
        free = K.free_axes(fig)
        for k, jid in enumerate(m.joints):
            for axis in range(3):
                d = last[k, axis] - first[k, axis]
                if free[jid][axis]:
                    d = (d + 180.0) % 360.0 - 180.0
                assert abs(d) < 1e-9, f"{motion}: joint {jid} {'XYZ'[axis]} ends {d:g} from its start"
    elif motion in FROM_NEUTRAL:
        np.testing.assert_allclose(first, 0.0, atol=1e-12)
        np.testing.assert_allclose(last, 0.0, atol=1e-12)


def test_hop_skip_jump_chain_without_a_jolt():
    v = lib_values("humanoid")
    chain = 10 * (v["HOP"] + v["SKIP"] + v["JUMP"])
    single = v["HOP"].length + v["SKIP"].length + v["JUMP"].length
    assert chain.length == 10 * single
    # At every junction the pose on either side is the neutral one.
    for t in np.arange(0.0, 10 * single + 1, single):
        for side in (t - 1e-6, t, t + 1e-6):
            if 0 <= side <= chain.length:
                np.testing.assert_allclose(chain.evaluate([side]), 0.0, atol=1e-3)


def _feet(name):
    """World vertices (T, V, 3) of each foot over two cycles of a locomotion motion, on its ROOT track."""
    v = lib_values("humanoid")
    fig, motion = v["HUMANOID"], v[name]
    times = np.arange(0.0, 2 * motion.length + 1)
    angles = P.joint_angles(fig, 2 * motion, times)
    placed = np.repeat(np.asarray(fig.placement)[None], len(times), axis=0)
    X = P.world_transforms(fig, angles, P.rooted_placements(placed, 2 * motion, times))
    table = P.mesh_table(fig)
    world = P.world_triangles(table, X)
    names = [l.name for l in fig.links]
    return [world[:, table.link == names.index(foot)].reshape(len(times), -1, 3) for foot in ("R_FOOT", "L_FOOT")]


@pytest.mark.parametrize("name", ["WALK", "RUN"])
def test_locomotion_keeps_the_ground_level_and_the_planted_foot_still(name):
    # The ROOT track carries the pelvis; the lowest point of the figure, where
    # a foot is planted, stays on one level, the soles 0.972 m below the
    # standing pelvis, and a planted foot slides less than 1 mm a frame.
    feet = _feet(name)
    ground = np.minimum(*[f[..., 1].min(axis=1) for f in feet])
    assert ground.min() >= -0.972 - 1e-3  # no foot goes through the ground
    if name == "WALK":  # a walk always has a foot on it (a run has flights)
        np.testing.assert_allclose(ground, -0.972, atol=1e-3)
    for f in feet:
        planted = f[..., 1].min(axis=1) <= -0.972 + 1e-3
        both = planted[1:] & planted[:-1]
        assert both.sum() >= 4  # it does rest on the ground
        slide = np.linalg.norm((f[1:] - f[:-1])[..., [0, 2]], axis=2).max(axis=1)
        assert slide[both].max() < 1e-3, slide[both].max()
    # And it travels: 1.2 m (WALK) or 2.2 m (RUN) a cycle.
    travel = lib_values("humanoid")[name].root_offset([0.0, 1e9])
    assert travel[1, 0] - travel[0, 0] == pytest.approx({"WALK": 1.2, "RUN": 2.2}[name])


@pytest.mark.parametrize("name", ["WALK", "RUN"])
def test_locomotion_lifts_the_swinging_toe_clear_of_the_floor(name):
    # A foot that is not planted (its lowest point more than 1 mm up) is at
    # least 1 cm up: the toe never skims the floor (it skimmed it 4-5 mm up for
    # five frames while moving 150 mm a frame), and no point of a foot moves
    # more than 1 mm a frame while within 5 mm of the floor, unless the foot
    # is planted at both frames (that is the slide, above).
    for f in _feet(name):
        low = f[..., 1].min(axis=1) + 0.972  # (T,) the foot's lowest point above the floor
        swinging = low > 1e-3
        assert swinging.sum() >= 4
        assert low[swinging].min() >= 0.01, low[swinging].min()
        planted = ~swinging
        near = f[..., 1] + 0.972 < 0.005  # (T, V)
        touching = near[1:] & near[:-1] & ~(planted[1:] & planted[:-1])[:, None]
        step = np.linalg.norm((f[1:] - f[:-1])[..., [0, 2]], axis=2)
        assert not (touching & (step > 1e-3)).any(), step[touching].max()


def test_squat_rooted_at_a_foot_keeps_both_feet_planted():
    v = values(
        "LOAD HUMANOID, SQUAT FROM 'humanoid'\nLOAD ROBOT, ROBOT_SQUAT FROM 'robot'\n"
        "FIGURE HUMANOID MAIN LINK R_FOOT\nFIGURE ROBOT MAIN JOINT 7\n"
    )["variables"]
    for fig, motion in ((v["HUMANOID"], v["SQUAT"]), (v["ROBOT"], v["ROBOT_SQUAT"])):
        times = np.arange(0.0, motion.length + 1)
        angles = P.joint_angles(fig, motion, times)
        X = P.world_transforms(fig, angles, np.repeat(np.eye(4)[None], len(times), axis=0))
        table = P.mesh_table(fig)
        world = P.world_triangles(table, X)
        names = [l.name for l in fig.links]
        feet = [i for i, n in enumerate(names) if n in ("R_FOOT", "L_FOOT", "SHIN")]
        for i in feet:
            part = world[:, table.link == i]
            np.testing.assert_allclose(part, part[:1].repeat(len(times), axis=0), atol=1e-9, err_msg=names[i])
        # ... while the rest of the body goes down and comes up again.
        top = world[..., 1].max(axis=(1, 2))
        assert top[len(times) // 2] < top[0] - 0.25
        assert top[-1] == pytest.approx(top[0])


def test_sit_made_with_goals_seats_the_pelvis_and_keeps_the_feet():
    v = values("LOAD HUMANOID, SIT FROM 'humanoid'\nFIGURE HUMANOID MAIN LINK R_FOOT\n")["variables"]
    fig, sit = v["HUMANOID"], v["SIT"]
    times = np.array([0.0, sit.length])
    angles = P.joint_angles(fig, sit, times)
    X = K.pose_transforms(fig, angles)
    link = {l.name: i for i, l in enumerate(fig.links)}
    # Standing, the pelvis is 0.9 m over the ankle; seated it is on the seat.
    np.testing.assert_allclose(X[0, link["TOP"], :3, 3], [0.0, 0.9, -0.144], atol=1e-9)
    np.testing.assert_allclose(X[1, link["TOP"], :3, 3], [-0.405, 0.495, -0.144], atol=2e-3)
    for name in ("L_FOOT", "R_FOOT"):
        np.testing.assert_allclose(X[1, link[name]], X[0, link[name]], atol=2e-3, err_msg=name)
    # The back stays upright: the spine's Y axis is the world's.
    assert X[1, link["SPINE"], 1, 1] > 0.999


# ------------------------------------------------------------- shapes


SHAPE_PROGRAM = """\
LOAD CYLINDER, SPHERE, CONE FROM 'shapes'
C3 :- CYLINDER RADIUS 1.0, HEIGHT 2.0, SIDES 3
C12 :- CYLINDER AT (1.0, 2.0, 3.0), RADIUS 0.5, HEIGHT 4.0
C17 :- CYLINDER RADIUS 0.3, HEIGHT 1.0, SIDES 17, LIGHTNESS 80.0
S12 :- SPHERE RADIUS 1.0
S7 :- SPHERE AT (0.0, 1.0, 0.0), RADIUS 2.0, SIDES 7, LIGHTNESS 10.0
S48 :- SPHERE RADIUS 1.0, SIDES 48
K5 :- CONE RADIUS 1.0, HEIGHT 3.0, SIDES 5
K12 :- CONE AT (0.0, 0.0, -1.0), RADIUS 0.5, HEIGHT 1.0, LIGHTNESS 60.0
"""


def _volume(g) -> float:
    t = g.triangles
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def test_shapes_are_closed_solids_of_the_right_size():
    v = values(SHAPE_PROGRAM)["variables"]
    for name, g in v.items():
        if name[0] in "CSK" and name[1:].isdigit():
            assert g.closed.all(), f"{name} is not a closed surface"
    # Facet counts: a side quad and two cap triangles per side; a sphere has
    # n facets round and n // 2 bands, the polar bands of triangles.
    assert len(v["C3"]) == 3 * 4 and len(v["C17"]) == 17 * 4
    assert len(v["S12"]) == 12 * (2 * 4 + 2) and len(v["S7"]) == 7 * (2 * 1 + 2)
    assert len(v["K5"]) == 5 * 2
    # Sizes: prisms and pyramids inscribed in the round solids.
    n = 12
    area = 0.5 * n * math.sin(2 * math.pi / n)  # of a regular n-gon of radius 1
    assert _volume(v["C12"]) == pytest.approx(area * 0.25 * 4.0)
    assert _volume(v["K12"]) == pytest.approx(area * 0.25 * 1.0 / 3.0)
    assert _volume(v["S48"]) == pytest.approx(4.0 / 3.0 * math.pi, rel=0.01)
    pts = v["C12"].triangles.reshape(-1, 3)
    np.testing.assert_allclose(pts.min(axis=0), (0.5, 0.0, 2.5), atol=1e-12)
    np.testing.assert_allclose(pts.max(axis=0), (1.5, 4.0, 3.5), atol=1e-12)
    pts = v["K5"].triangles.reshape(-1, 3)
    assert pts[:, 1].min() == pytest.approx(-1.5) and pts[:, 1].max() == pytest.approx(1.5)
    # Shaded as BOX: LIGHTNESS facing +-Z, 1.5 times it at right angles to Z.
    light = v["C17"].lightness
    assert light.min() >= 80.0 - 1e-9 and light.max() == pytest.approx(120.0)


# ------------------------------------------------------------- the tutorial


def tutorial_programs() -> list:
    """The ```lig blocks of docs/tutorial.md, in order, as (file name, text).

    A block whose first line is a brace comment naming a file,
    ``{ walker.lig: ... }``, is saved under that name, so that later blocks
    can LOAD it; the others are tutorial_<n>.lig.
    """
    text = TUTORIAL.read_text(encoding="utf-8")
    blocks = re.findall(r"^```lig\n(.*?)^```", text, re.S | re.M)
    named = []
    for i, block in enumerate(blocks):
        m = re.match(r"\{\s*([A-Za-z0-9_-]+\.lig)\s*:", block)
        named.append((m.group(1) if m else f"tutorial_{i}.lig", block))
    return named


def test_the_tutorial_has_programs():
    assert len(tutorial_programs()) >= 6


def test_tutorial_programs_compile_and_run(tmp_path):
    programs = tutorial_programs()
    for name, text in programs:
        (tmp_path / name).write_text(text)
    for name, _ in programs:
        program, warnings = load_program(str(tmp_path / name))
        assert warnings == [], name
        rt = program.execute("check")
        assert rt.warnings == [], name
