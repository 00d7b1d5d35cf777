"""The Generator of the posing thesis' chapter IV, without a browser: limits, locks, order, seeds, undo."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.compiler import load_program
from liganimate.runtime.studio import (
    POPULATION,
    Generator,
    circle,
    joint_axes,
    sphere,
)
from liganimate.runtime.studio._genes import _limb_axis, directions, solutions, wrap

# humanoid and human come from conftest.py.


@pytest.fixture(scope="module")
def odd(tmp_path_factory):
    """A model whose limbs lie along X and Z, with a free axis and an axis locked away from 0."""
    path = tmp_path_factory.mktemp("odd") / "odd.lig"
    path.write_text(
        "      GRAPHICAL A, B, C\n"
        "      MODEL ODD\n"
        "      A :- BOX WIDTH 1.0, HEIGHT 0.2, DEPTH 0.2\n"
        "      B :- BOX AT (0.5, 0.0, 0.0), WIDTH 1.0, HEIGHT 0.2, DEPTH 0.2\n"
        "      C :- BOX AT (0.0, 0.0, 0.5), WIDTH 0.2, HEIGHT 0.2, DEPTH 1.0\n"
        "      ODD :- JOINT 1, A, (0.5, 0.0, 0.0), B, (0.0, 0.0, 0.0), (-360.0, 360.0), (-30.0, 60.0), (10.0, 80.0)\n"
        "      ODD :- JOINT 2, ODD, (1.0, 0.0, 0.0), C, (0.0, 0.0, 0.0), (20.0, 20.0), (-45.0, 45.0), (-90.0, 0.0)\n",
        encoding="utf-8",
    )
    program, _ = load_program(str(path))
    return program.execute("check").variables["ODD"]


def _within(fig, poses):
    ext = np.asarray(fig.extremes)
    lo, hi = ext[..., 0], ext[..., 1]
    return (poses >= lo - 1e-9).all() and (poses <= hi + 1e-9).all()


def _locked(fig):
    ext = np.asarray(fig.extremes)
    return ext[..., 0] == ext[..., 1], ext[..., 0]


# ------------------------------------------------------------------ spheres


def test_hyper_tessellated_sphere_levels_and_points():
    points, level = sphere()
    # Level 0 is the octahedron; each subdivision adds its edge midpoints.
    assert np.bincount(level).tolist() == [6, 12, 48, 192, 768, 3072, 12288]
    assert np.allclose(np.linalg.norm(points, axis=1), 1.0)
    assert len(np.unique(np.round(points, 9), axis=0)) == len(points)
    # Every level is spread over the whole sphere: its points' mean is (about) the centre.
    for lev in range(7):
        assert np.linalg.norm(points[level <= lev].mean(axis=0)) < 1e-9

    # Finer levels are finer: the nearest neighbour of a level-3 point is closer than of a level-1 point.
    def spacing(n):
        p = points[level <= n]
        d = p @ p.T
        np.fill_diagonal(d, -1)
        return np.degrees(np.arccos(d.max(axis=1))).max()

    assert spacing(1) > spacing(2) > spacing(3)


def test_hyper_tessellated_circle():
    angles, level = circle()
    assert np.bincount(level).tolist() == [4, 4, 8, 16, 32, 64, 128]
    assert sorted(angles[level == 0].tolist()) == [-90.0, 0.0, 90.0, 180.0]
    assert len(np.unique(angles)) == len(angles) == 256
    assert ((angles > -180) & (angles <= 180)).all()


# -------------------------------------------------------------------- genes


def test_humanoid_axes_are_those_of_the_library_table(humanoid):
    """docs/stdlib.md: flexion about Z, pivot about X (Y for the feet), twist about Y (X for the feet)."""
    axes = {a.id: a for a in joint_axes(humanoid)}
    for j in (1, 2, 11, 12, 13, 21, 22, 23, 31, 32, 41, 42):
        assert ("XYZ"[axes[j].twist], "XYZ"[axes[j].pivot], "XYZ"[axes[j].flexion]) == ("Y", "X", "Z"), j
    for j in (33, 43):
        assert ("XYZ"[axes[j].twist], "XYZ"[axes[j].pivot], "XYZ"[axes[j].flexion]) == ("X", "Y", "Z"), j
    assert axes[31].sign == -1 and axes[1].sign == 1  # the thigh hangs down, the spine goes up


@pytest.mark.parametrize("twist", [0, 1, 2])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_directions_and_their_angles_agree(humanoid, twist, sign):
    """Both Euler solutions of a direction point the limb's main axis at it."""
    from dataclasses import replace

    ax = replace(
        joint_axes(humanoid)[0],
        twist=twist,
        pivot={0: 1, 1: 0, 2: 0}[twist],
        flexion={0: 2, 1: 2, 2: 1}[twist],
        sign=sign,
    )
    points, _ = sphere()
    sol = solutions(ax, points)
    for k in (0, 1):
        back = directions(ax, sol[k, :, 0], sol[k, :, 1])
        assert np.allclose(back, points, atol=1e-7)


# --------------------------------------------------------------- generation


@pytest.mark.parametrize("seed", [0, 1, 12345, 2**32 - 1])
def test_first_generation_respects_the_extremes(humanoid, human, odd, seed):
    for fig in (humanoid, human, odd):
        g = Generator(fig, seed=seed)
        assert g.generation == 1
        assert g.candidates.shape == (POPULATION, fig.n_joints, 3)
        assert _within(fig, g.candidates)
        g.set_mode("twist")
        g.set_seed(seed)  # a new first generation, of twists
        assert _within(fig, g.candidates)


def test_first_generation_differs_from_the_standing_pose(humanoid):
    g = Generator(humanoid, seed=3)
    moved = (np.abs(g.candidates - g.current) > 1e-9).any(axis=2)  # (9, J)
    # Every joint that can flex or pivot moves in every candidate: no candidate wastes a gene.
    movable = [a.index for a in g.axes if not (a.locked[a.pivot] and a.locked[a.flexion])]
    assert moved[:, movable].all()
    assert not moved[:, [a.index for a in g.axes if a.locked.all()]].any()


def test_later_generations_may_leave_the_extremes_within_the_distance(humanoid):
    g = Generator(humanoid, seed=11, intensity=1.0)
    outside = False
    for _ in range(6):
        g.next_generation()
        outside |= not _within(humanoid, g.candidates)
        for ax in g.axes:
            here = directions(ax, [g.current[ax.index, ax.pivot]], [g.current[ax.index, ax.flexion]])[0]
            cand = directions(ax, g.candidates[:, ax.index, ax.pivot], g.candidates[:, ax.index, ax.flexion])
            assert (np.degrees(np.arccos(np.clip(cand @ here, -1, 1))) <= 180.0 + 1e-6).all()
        g.take(4, humanoid.joint_index(31))
    assert outside, "at full intensity some candidate should go beyond an extreme"
    g.set_intensity(0.1)
    g.next_generation()
    for ax in g.axes:
        if ax.locked[ax.pivot] or ax.locked[ax.flexion]:
            continue
        here = directions(ax, [g.current[ax.index, ax.pivot]], [g.current[ax.index, ax.flexion]])[0]
        cand = directions(ax, g.candidates[:, ax.index, ax.pivot], g.candidates[:, ax.index, ax.flexion])
        angle = np.degrees(np.arccos(np.clip(cand @ here, -1, 1)))
        assert (angle <= 18.0 + 1e-6).all() and (angle > 0).all()


@pytest.mark.parametrize("mode", ["flexion", "twist"])
def test_locked_axes_never_move(humanoid, human, odd, mode):
    for fig in (humanoid, human, odd):
        locked, value = _locked(fig)
        g = Generator(fig, seed=99, intensity=1.0, mode=mode)
        rng = np.random.default_rng(0)
        for _ in range(12):
            g.next_generation()
            assert (g.candidates[:, locked] == value[locked]).all()
            for _ in range(3):
                g.take(int(rng.integers(POPULATION)), int(rng.integers(fig.n_joints)))
            assert (g.current[locked] == value[locked]).all()
            g.set_mode("twist" if g.mode == "flexion" else "flexion")


def test_flexion_and_twist_are_mutated_separately(humanoid):
    g = Generator(humanoid, seed=5, intensity=0.8)
    twist = np.zeros((humanoid.n_joints, 3), dtype=bool)
    for ax in g.axes:
        twist[ax.index, ax.twist] = True
    g.next_generation()
    assert (g.candidates[:, twist] == g.current[twist]).all()
    assert (g.candidates[:, ~twist] != g.current[~twist]).any()
    g.set_mode("twist")
    g.next_generation()
    assert (g.candidates[:, ~twist] == g.current[~twist]).all()
    assert (g.candidates[:, twist] != g.current[twist]).any()


def test_candidates_come_coarse_to_fine_in_order(humanoid, human):
    for fig in (humanoid, human):
        g = Generator(fig, seed=21, intensity=0.5)
        for gen in range(4):
            for ax in g.axes:
                lev = g.levels[:, ax.index]
                if (lev < 0).all():
                    continue
                # Not shuffled: levels never get coarser along the nine (until they start over).
                starts = np.flatnonzero(np.diff(lev) < 0)
                assert len(starts) == 0 or (lev[starts[0] + 1 :] == lev[: len(lev) - starts[0] - 1]).all()
                first_run = lev[: starts[0] + 1] if len(starts) else lev
                assert (np.diff(first_run) >= 0).all(), (gen, ax.id, lev)
                # The coarsest level reachable comes first.
                assert lev[0] == lev.min()
            g.take(gen % POPULATION, 1)
            g.next_generation()


def test_first_candidates_of_a_one_axis_joint_are_the_coarsest_circle_points(humanoid):
    """The knee bends on a circle: quarter turns first, then eighths, each level nearest first."""
    g = Generator(humanoid, seed=8)
    knee = humanoid.joint_index(32)
    z = g.candidates[:, knee, 2]
    assert z[0] == -90.0  # level 0 within (-160, 0), the standing 0 excluded
    assert sorted(z[1:3].tolist()) == [-135.0, -45.0]  # level 1
    assert g.levels[:3, knee].tolist() == [0, 1, 1]
    assert set(z[3:7].tolist()) == {-22.5, -67.5, -112.5, -157.5}  # level 2, all of it fits


def test_same_seed_same_candidates(humanoid):
    def run(seed):
        g = Generator(humanoid, seed=seed)
        out = [g.candidates.copy()]
        g.take(2, humanoid.joint_index(31))
        g.take(7, humanoid.joint_index(11))
        g.set_intensity(0.4)
        for _ in range(3):
            g.next_generation()
            out.append(g.candidates.copy())
        g.set_mode("twist")
        g.next_generation()
        out.append(g.candidates.copy())
        return np.stack(out)

    a, b = run(424242), run(424242)
    assert np.array_equal(a, b)
    c = run(7)
    assert not np.array_equal(a, c)


def test_take_copies_one_joint(humanoid):
    g = Generator(humanoid, seed=2)
    before = g.current.copy()
    j = humanoid.joint_index(21)
    g.take(5, j)
    assert np.array_equal(g.current[j], g.candidates[5, j])
    others = np.ones(humanoid.n_joints, dtype=bool)
    others[j] = False
    assert np.array_equal(g.current[others], before[others])


def test_frozen_joints_keep_the_seed(humanoid):
    g = Generator(humanoid, seed=4, intensity=0.7)
    j = humanoid.joint_index(11)
    g.take(3, j)
    g.toggle_frozen(j)
    g.next_generation()
    assert (g.candidates[:, j] == g.current[j]).all()
    assert (g.levels[:, j] == -1).all()
    g.toggle_frozen(j)
    g.next_generation()
    assert (g.candidates[:, j] != g.current[j]).any()


def test_undo_goes_back_exactly(humanoid):
    g = Generator(humanoid, seed=17, intensity=0.3)
    g.take(1, 3)
    snap = (g.current.copy(), g.candidates.copy(), g.generation)
    g.next_generation()
    after = g.candidates.copy()
    g.keep()
    g.take(0, 5)
    assert g.undo() and g.undo() and g.undo()
    assert np.array_equal(g.current, snap[0]) and np.array_equal(g.candidates, snap[1])
    assert g.generation == snap[2] and g.kept == []
    g.next_generation()  # the random state came back too
    assert np.array_equal(g.candidates, after)
    g.set_seed(3)
    assert g.seed == 3 and g.generation == 1
    assert g.undo() and g.seed == 17
    while g.undo():
        pass
    assert not g.can_undo and np.array_equal(g.current, g.neutral)


def test_keep_and_stand(humanoid):
    g = Generator(humanoid, seed=1)
    g.take(0, 1)
    g.keep()
    g.stand()
    g.keep()
    assert len(g.kept) == 2
    assert not np.array_equal(g.kept[0], g.kept[1]) and np.array_equal(g.kept[1], g.neutral)
    first = g.kept[0].copy()
    g.take(3, 1)  # a kept pose is a copy: later takes do not change it
    assert np.array_equal(g.kept[0], first)


@pytest.mark.parametrize(
    "call",
    [
        lambda g: g.take(9, 0),
        lambda g: g.take(-1, 0),
        lambda g: g.take(0, 10**6),
        lambda g: g.take(True, 0),
        lambda g: g.set_seed(-1),
        lambda g: g.set_seed(2**32),
        lambda g: g.set_seed(1.5),
        lambda g: g.set_seed("1"),
        lambda g: g.set_intensity(1.01),
        lambda g: g.set_intensity(float("nan")),
        lambda g: g.set_mode("pivot"),
        lambda g: g.toggle_frozen(-3),
        lambda g: g.joint_of_link(999),
    ],
)
def test_bad_arguments_change_nothing(humanoid, call):
    g = Generator(humanoid, seed=6)
    before = (g.current.copy(), g.candidates.copy(), g.seed, g.intensity, g.mode, g.can_undo)
    with pytest.raises(ValueError):
        call(g)
    assert np.array_equal(g.current, before[0]) and np.array_equal(g.candidates, before[1])
    assert (g.seed, g.intensity, g.mode, g.can_undo) == before[2:]


def test_a_model_without_joints_is_refused():
    from liganimate.runtime.figure.tree import Figure, Link
    from liganimate.runtime.values import EMPTY

    with pytest.raises(ValueError, match="no joints"):
        Generator(Figure((Link("A", EMPTY),)))


def test_wrap():
    assert wrap(np.array([180.0, -180.0, 540.0, 181.0, -181.0])).tolist() == [180.0, 180.0, 180.0, -179.0, 179.0]


def test_a_limbs_axes_do_not_depend_on_where_the_model_is_rooted():
    """A submodel attached by the link FIGURE chose walks some joints from their secondaries;
    each limb's twist, pivot and flexion axes still come from the limb's own joints."""
    from exchange_support import GRAFTED

    program, _ = load_program(text=GRAFTED, name="grafted.lig")
    v = program.execute("check").variables
    arm, bot = v["ARM"], v["BOT"]
    assert bot.inverted.any() and not arm.inverted.any()
    mine = {a.id: a for a in joint_axes(bot)}
    for a in joint_axes(arm):
        b = mine[a.id]
        assert (b.twist, b.pivot, b.flexion, b.sign) == (a.twist, a.pivot, a.flexion, a.sign)
        assert bot.links[b.link].name == arm.links[a.link].name
    # The limb's direction itself, from the joint to the link's other joints on it: the elbow's
    # LOWER holds joints 1 and 2 in both models (BOT's HAND holds joint 3 as well, so it differs).
    np.testing.assert_array_equal(_limb_axis(bot, bot.joint_index(1)), _limb_axis(arm, arm.joint_index(1)))
