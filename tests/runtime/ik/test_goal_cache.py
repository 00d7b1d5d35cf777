"""A solve reuses the packing of goals it has seen (issue 22): the same stack as packing afresh, the same checks.

``GoalStack.cached`` resolves links and packs weights and Jacobian masks once
per set of goals (kind, link, link point or axis, weight) on a model, and
only the targets, planes and directions per call.  What it returns must be
what the constructor builds, and bad targets must still be refused.
"""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.figure.tree import Figure, Joint, Link
from liganimate.runtime.ik.goals import AxisGoal, GoalError, GoalStack, PlaneGoal, PointGoal
from liganimate.runtime.ik.model import IKModel
from liganimate.runtime.ik.reach import solve_pose


def arm() -> Figure:
    links = tuple(Link(name, None) for name in ("BASE", "UPPER", "LOWER", "HAND"))
    joints = tuple(
        Joint(k, k - 1, k, (0.0, 0.4 if k > 1 else 0.0, 0.0), (0.0, 0.0, 0.0), [(-120, 120), (-90, 90), (-60, 60)])
        for k in range(1, 4)
    )
    return Figure(links, joints)


def same(a: GoalStack, b: GoalStack) -> None:
    assert a.__dict__.keys() == b.__dict__.keys()
    for name, value in a.__dict__.items():
        other = b.__dict__[name]
        if isinstance(value, np.ndarray):
            np.testing.assert_array_equal(value, other, err_msg=name)
        elif name != "model":
            assert value == other, name


def goals(rng: np.random.Generator) -> list:
    return [
        PointGoal("HAND", rng.uniform(-0.5, 0.5, 3), point=(0.0, 0.1, 0.0), weight=2.0),
        PlaneGoal("LOWER", rng.uniform(-0.5, 0.5, 3), rng.normal(size=3)),
        AxisGoal(3, (0.0, 1.0, 0.0), rng.normal(size=3), weight=0.5),
    ]


def test_a_cached_stack_is_the_stack_packed_afresh():
    fig = arm()
    model = IKModel.cached(fig, np.ones((3, 3), dtype=bool))
    rng = np.random.default_rng(4)
    for _ in range(3):  # a miss, then hits with other targets
        g = goals(rng)
        same(GoalStack.cached(model, g, 1), GoalStack(model, g, 1))
        same(GoalStack.cached(model, g[:1], 1), GoalStack(model, g[:1], 1))


def test_another_weight_or_point_is_another_packing():
    fig = arm()
    model = IKModel.cached(fig, np.ones((3, 3), dtype=bool))
    a = GoalStack.cached(model, [PointGoal("HAND", (0.1, 0.2, 0.3), weight=1.0)], 1)
    b = GoalStack.cached(
        model, [PointGoal("HAND", (0.1, 0.2, 0.3), weight=1.0), PointGoal(1, (0, 0, 0), weight=0.0)], 1
    )
    c = GoalStack.cached(model, [PointGoal("HAND", (0.1, 0.2, 0.3), point=(0.0, 1.0, 0.0), weight=1.0)], 1)
    assert not np.array_equal(a.p_local, c.p_local)
    assert b.weights.tolist() == [[1.0, 0.0]]


@pytest.mark.parametrize(
    "bad, words",
    [
        (PointGoal("HAND", (np.nan, 0.0, 0.0)), "must be finite"),
        (PointGoal("HAND", (1.0, 2.0)), "vector of three numbers"),
        (AxisGoal("HAND", (0.0, 1.0, 0.0), (0.0, 0.0, 0.0)), "zero vector"),
        (PlaneGoal("HAND", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)), "zero vector"),
    ],
)
def test_bad_targets_are_refused_on_a_hit_too(bad, words):
    fig = arm()
    good = {PointGoal: PointGoal("HAND", (0.1, 0.2, 0.3)), AxisGoal: AxisGoal("HAND", (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))}
    good[PlaneGoal] = PlaneGoal("HAND", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    solve_pose(fig, [good[type(bad)]])  # packs the structure
    with pytest.raises(GoalError, match=words):
        solve_pose(fig, [bad])


def test_single_solves_give_what_a_batch_gives():
    fig = arm()
    rng = np.random.default_rng(9)
    targets = rng.uniform(-0.4, 0.4, (6, 3))
    batch = solve_pose(fig, [PointGoal("HAND", targets)], tolerance=1e-6)
    for k, t in enumerate(targets):
        one = solve_pose(fig, [PointGoal("HAND", t)], tolerance=1e-6)
        assert one.status == batch.status[k]
        np.testing.assert_allclose(one.residuals, batch.residuals[k], atol=1e-6)


def test_options_made_from_equal_values_of_other_types_are_not_confused():
    """reach_options remembers options made from plain values, by value and type: True is no restart count."""
    from liganimate.runtime.ik.reach import reach_options

    assert reach_options(restarts=1).restarts == 1 and type(reach_options(restarts=1).restarts) is int
    assert reach_options(restarts=True).restarts is True  # (solve_pose refuses it)
    assert type(reach_options(restarts=1).restarts) is int
    assert reach_options(tolerance=1).tolerance == 1 and type(reach_options(tolerance=1.0).tolerance) is float
    assert reach_options(movable=[1, 2]).movable == [1, 2]  # not plain: made afresh
    assert reach_options(restarts=2) is reach_options(restarts=2)
